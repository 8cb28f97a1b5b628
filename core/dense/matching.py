"""Dense matching on the CPU and depth fusion -> DSM GeoTIFF and point cloud (the ``dsm`` stage).

Method (engine ``cpu``, the default and the tested one):

1. **Pair selection** from the georeferenced sparse model: for every two images
   the tie points they share, the baseline-to-depth ratio B/Z and the angle
   between the optical axes.  Pairs with too few shared points, B/Z outside
   [``min_baseline_ratio``, ``max_baseline_ratio``] or axes more than
   ``max_view_angle`` apart are dropped; each image keeps its ``partners`` best
   pairs (score: shared points, B/Z near ``ideal_baseline_ratio``, similar view).
2. **Per pair** (the unit of work, run through :mod:`core.parallel`): both images
   read at the QUALITY downscale (full 1, half 1/2, quarter 1/4), lens distortion
   removed and the pair rectified in one remap from the known poses (both
   cameras turned to a common orientation whose x axis is the baseline, so the
   epipolar lines are rows); the disparity range comes from the shared sparse
   points (1-99 % plus a margin); OpenCV semi-global matching (StereoSGBM,
   Hirschmüller 2008) left->right and right->left; a left-right consistency
   check (1 px); triangulation; the result is two depth maps, one on each
   image's own (distorted, downscaled) pixel grid, cached in
   ``<workspace>/dense/pairs-<key>/`` so a re-run skips finished pairs.
3. **Fusion per image**: the depth maps an image received from its pairs are
   compared pixel by pixel; a pixel is kept where at least ``min_consistent``
   independent pairs agree within a tolerance (about one disparity pixel of the
   weakest pair, relative to depth), its depth is the mean of the agreeing ones,
   and it is back-projected with the camera model and coloured from the image.
4. **DSM** (:mod:`core.dsm`): the fused points are rasterised tile by tile at
   RESOLUTION (default: 2 x the median ground sample distance, and never finer
   than the matching pixel) with the median of the highest height cluster per
   cell; speckles dropped, small holes filled, large holes left nodata; a
   float32 Cloud-Optimized GeoTIFF with overviews in the workspace CRS,
   written atomically.  Optionally a LAS 1.2 point cloud with RGB.

Engine ``cuda`` runs COLMAP's patch-match stereo and fusion instead (only where
pycolmap was built with CUDA: ``pycolmap.has_cuda``); the DSM step is the same.

A workspace that is **not georeferenced is refused** with a clear message: the
aligned model has an arbitrary scale and no vertical direction, so a "DSM" in
its frame would be meaningless (heights along an arbitrary axis).  Georeference
with GCPs, camera positions or the images' EXIF GPS first.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import time
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.parallel import check_unit_cancel, cpu_count, describe_executor, make_executor, run_units
from ..common.progress import Cancelled, NullProgress, Progress, SubProgress, check_cancel
from ..io import raster as dsmmod
from ..project.workspace import (
    CANCELLED,
    DONE,
    FAILED,
    Workspace,
    atomic_write_text,
    file_fingerprint,
    fingerprint,
)

STAGE = "dsm"
GEOREF = "georeference"
QUALITIES = {"full": 1.0, "half": 0.5, "quarter": 0.25}
ENGINES = ("cpu", "cuda")
CACHE_VERSION = 1


class DenseError(RuntimeError):
    """Dense matching cannot run with these inputs; the message says why."""


@dataclass
class DenseOptions:
    quality: str = "half"
    partners: int = 5  # at most this many pairs chosen per image (greedy two-fold cover of its tie points)
    min_shared_points: int = 15
    min_baseline_ratio: float = 0.03
    max_baseline_ratio: float = 1.2
    ideal_baseline_ratio: float = 0.3
    max_view_angle: float = 40.0  # degrees between the optical axes
    block_size: int = 0  # SGBM block; 0 = auto (5 at full/half, 3 at quarter)
    uniqueness: int = 10
    lr_tolerance: float = 1.0  # px
    min_consistent: int = 2  # pairs that must agree on a pixel
    depth_tolerance_px: float = 1.0  # agreement tolerance, in disparity pixels of the weakest pair
    max_hole_cells: int = 16
    workers: int = 0  # 0 = one per core (bounded by memory)
    executor: str = "auto"  # auto / serial / process / thread
    scheduler: Optional[str] = None  # Dask scheduler address


@dataclass
class View:
    """One image with its camera and pose (cam_from_world: x_cam = R x_world + t), in the local frame."""

    image_id: int
    name: str
    path: str
    width: int
    height: int
    model: str
    params: Tuple[float, ...]
    R: np.ndarray
    t: np.ndarray

    @property
    def centre(self) -> np.ndarray:
        return -self.R.T @ self.t

    @property
    def focal(self) -> float:
        return float(np.mean(camera_matrix(self.model, self.params, 1.0, 1.0)[0][[0, 1], [0, 1]]))


@dataclass
class PairInfo:
    i: int  # image ids (i < j)
    j: int
    shared: int
    baseline_ratio: float
    view_angle: float  # degrees
    score: float
    point_idx: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, np.int64))


@dataclass
class PairUnit:
    key: str
    out_path: str
    vi: View
    vj: View
    scale: float
    points: np.ndarray  # shared sparse points (local frame), for the disparity range
    block_size: int
    uniqueness: int
    lr_tolerance: float
    threads: int


@dataclass
class FuseUnit:
    view: View
    scale: float
    maps: List[Tuple[str, str, float]]  # (pair file, role 'i' or 'j', relative depth error per px)
    tolerance_px: float
    min_consistent: int
    out_path: str
    threads: int


@dataclass
class DsmStageResult:
    workspace: str
    dsm_path: str
    point_cloud_path: Optional[str]
    crs: str
    resolution: float
    valid_fraction: Optional[float]
    pairs: int
    pairs_reused: int
    points: int
    timings: Dict[str, float]
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)


# ---------------------------------------------------------------------------
# cameras
# ---------------------------------------------------------------------------

def camera_matrix(model: str, params: Sequence[float], sx: float, sy: float) -> Tuple[np.ndarray, np.ndarray]:
    """(K, distortion) in OpenCV's convention (pixel centres at integers) for a COLMAP camera whose image
    is scaled by (sx, sy).  COLMAP puts the origin at the corner of the first pixel: cx_cv = cx * s - 0.5."""
    p = [float(v) for v in params]
    m = model.upper()
    if m == "SIMPLE_PINHOLE":
        fx = fy = p[0]
        cx, cy = p[1], p[2]
        dist = np.zeros(4)
    elif m == "PINHOLE":
        fx, fy, cx, cy = p[:4]
        dist = np.zeros(4)
    elif m == "SIMPLE_RADIAL":
        fx = fy = p[0]
        cx, cy = p[1], p[2]
        dist = np.array([p[3], 0.0, 0.0, 0.0])
    elif m == "RADIAL":
        fx = fy = p[0]
        cx, cy = p[1], p[2]
        dist = np.array([p[3], p[4], 0.0, 0.0])
    elif m == "OPENCV":
        fx, fy, cx, cy = p[:4]
        dist = np.array(p[4:8])
    elif m == "FULL_OPENCV":
        fx, fy, cx, cy = p[:4]
        dist = np.array(p[4:12])
    else:
        raise DenseError(f"camera model {model} is not supported by dense matching "
                         "(use SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV)")
    k = np.array([[fx * sx, 0.0, cx * sx - 0.5], [0.0, fy * sy, cy * sy - 0.5], [0.0, 0.0, 1.0]])
    return k, dist


def views_from_reconstruction(rec, images_dir: str) -> Dict[int, View]:
    views = {}
    for iid in sorted(rec.reg_image_ids()):
        im = rec.images[iid]
        cam = im.camera
        m = np.asarray(im.cam_from_world().matrix(), dtype=np.float64)
        views[int(iid)] = View(int(iid), im.name, os.path.join(images_dir, im.name), int(cam.width), int(cam.height),
                               cam.model.name, tuple(float(v) for v in cam.params), m[:, :3].copy(), m[:, 3].copy())
    return views


def sparse_points(rec) -> Tuple[np.ndarray, List[np.ndarray]]:
    """(xyz (N, 3), tracks: image ids per point) of a reconstruction."""
    xyz, tracks = [], []
    for _, p in rec.points3D.items():
        ids = np.unique([int(el.image_id) for el in p.track.elements])
        if len(ids) >= 2:
            xyz.append(np.asarray(p.xyz, dtype=np.float64))
            tracks.append(ids)
    return (np.array(xyz).reshape(-1, 3), tracks)


def median_gsd(views: Dict[int, View], xyz: np.ndarray, tracks: Sequence[np.ndarray]) -> float:
    """Median ground sample distance (m per full-resolution pixel) from the sparse points' depths."""
    per_image: Dict[int, List[int]] = {}
    for k, ids in enumerate(tracks):
        for i in ids:
            per_image.setdefault(int(i), []).append(k)
    gsd = []
    for iid, idx in per_image.items():
        v = views.get(iid)
        if v is None or len(idx) < 3:
            continue
        z = (xyz[idx] @ v.R.T + v.t)[:, 2]
        z = z[z > 0]
        if len(z):
            gsd.append(float(np.median(z)) / v.focal)
    if not gsd:
        raise DenseError("cannot estimate the ground sample distance: no sparse point lies in front of the cameras")
    return float(np.median(gsd))


# ---------------------------------------------------------------------------
# pair selection
# ---------------------------------------------------------------------------

def select_pairs(views: Dict[int, View], xyz: np.ndarray, tracks: Sequence[np.ndarray],
                 options: DenseOptions) -> Tuple[List[PairInfo], Dict[str, int]]:
    """Stereo pairs for dense matching and counts of why candidates were dropped."""
    shared: Dict[Tuple[int, int], List[int]] = {}
    for k, ids in enumerate(tracks):
        ids = [i for i in ids if i in views]
        for a in range(len(ids)):
            for b in range(a + 1, len(ids)):
                shared.setdefault((ids[a], ids[b]), []).append(k)
    stats = {"candidates": len(shared), "few_shared_points": 0, "baseline_too_short": 0,
             "baseline_too_long": 0, "view_angle": 0, "kept": 0}
    cands: List[PairInfo] = []
    for (i, j), idx in shared.items():
        if len(idx) < options.min_shared_points:
            stats["few_shared_points"] += 1
            continue
        vi, vj = views[i], views[j]
        pts = xyz[idx]
        zi = (pts @ vi.R.T + vi.t)[:, 2]
        zj = (pts @ vj.R.T + vj.t)[:, 2]
        ok = (zi > 0) & (zj > 0)
        if ok.sum() < options.min_shared_points:
            stats["few_shared_points"] += 1
            continue
        depth = float(np.median(np.minimum(zi[ok], zj[ok])))
        base = float(np.linalg.norm(vi.centre - vj.centre))
        ratio = base / depth if depth > 0 else 0.0
        cosang = float(np.clip(vi.R[2] @ vj.R[2], -1.0, 1.0))
        angle = math.degrees(math.acos(cosang))
        if ratio < options.min_baseline_ratio:
            stats["baseline_too_short"] += 1
            continue
        if ratio > options.max_baseline_ratio:
            stats["baseline_too_long"] += 1
            continue
        if angle > options.max_view_angle:
            stats["view_angle"] += 1
            continue
        score = (min(1.0, len(idx) / 100.0) * math.exp(-0.5 * (math.log(ratio / options.ideal_baseline_ratio) / 0.7) ** 2)
                 * math.cos(math.radians(angle)))
        cands.append(PairInfo(i, j, len(idx), ratio, angle, score, np.asarray(idx, dtype=np.int64)[ok]))
    # per image, greedy cover: fusion keeps a pixel that two pairs confirm, so each image takes the pairs that
    # bring the most of its tie points to two-fold coverage (weighted by the pair's geometry score)
    best: Dict[int, List[PairInfo]] = {}
    for p in cands:
        best.setdefault(p.i, []).append(p)
        best.setdefault(p.j, []).append(p)
    chosen: Dict[Tuple[int, int], PairInfo] = {}
    for _iid, lst in best.items():
        n_pts = len(np.unique(np.concatenate([p.point_idx for p in lst])))
        cover: Dict[int, int] = {}
        left = list(lst)
        for _ in range(max(1, options.partners)):
            gains = [p.score * sum(1 for k in p.point_idx if cover.get(int(k), 0) < 2) for p in left]
            if not gains:
                break
            k_best = int(np.argmax(gains))
            if chosen and gains[k_best] < 0.03 * n_pts * max(p.score for p in left) and len(cover) > 0:
                break
            p = left.pop(k_best)
            chosen[(p.i, p.j)] = p
            for k in p.point_idx:
                cover[int(k)] = cover.get(int(k), 0) + 1
    pairs = sorted(chosen.values(), key=lambda p: (p.i, p.j))
    stats["kept"] = len(pairs)
    return pairs, stats


# ---------------------------------------------------------------------------
# one pair: rectify, SGM, left-right check, triangulate -> two depth maps
# ---------------------------------------------------------------------------

def _to_gray8(img: np.ndarray) -> np.ndarray:
    import cv2

    if img.shape[2] >= 3:
        g = cv2.cvtColor(np.ascontiguousarray(img[:, :, :3]), cv2.COLOR_RGB2GRAY) if img.dtype == np.uint8 else \
            (0.299 * img[:, :, 0] + 0.587 * img[:, :, 1] + 0.114 * img[:, :, 2])
    else:
        g = img[:, :, 0]
    if g.dtype != np.uint8:
        g = g.astype(np.float32)
        lo, hi = np.percentile(g, [0.5, 99.5])
        g = np.clip((g - lo) * (255.0 / max(hi - lo, 1e-6)), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(g)


def _to_rgb8(img: np.ndarray) -> np.ndarray:
    if img.shape[2] >= 3:
        rgb = img[:, :, :3]
    else:
        rgb = np.repeat(img[:, :, :1], 3, axis=2)
    if rgb.dtype != np.uint8:
        rgb = rgb.astype(np.float32)
        lo, hi = np.percentile(rgb, [0.5, 99.5])
        rgb = np.clip((rgb - lo) * (255.0 / max(hi - lo, 1e-6)), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(rgb)


def load_scaled(view: View, scale: float) -> Tuple[np.ndarray, float, float]:
    """Image pixels at ``scale`` and the exact (sx, sy) factors of the array obtained."""
    from ..io.images import read_image

    if not os.path.isfile(view.path):
        raise DenseError(f"image {view.path} is missing (moved since alignment?)")
    size = None if scale >= 1.0 else max(1, int(round(max(view.width, view.height) * scale)))
    img = read_image(view.path, size)
    h, w = img.shape[:2]
    return img, w / view.width, h / view.height


def _rect_bounds(k: np.ndarray, dist: np.ndarray, rot: np.ndarray, f: float, w: int, h: int) -> np.ndarray:
    """x/y bounds (xmin, xmax, ymin, ymax) of an image's border after undistortion and rotation ``rot``
    (old camera -> rectified camera), projected with focal ``f`` and no principal point."""
    import cv2

    n = 16
    xs = np.linspace(-0.5, w - 0.5, n)
    ys = np.linspace(-0.5, h - 0.5, n)
    border = np.concatenate([np.column_stack([xs, np.full(n, -0.5)]), np.column_stack([xs, np.full(n, h - 0.5)]),
                             np.column_stack([np.full(n, -0.5), ys]), np.column_stack([np.full(n, w - 0.5), ys])])
    und = cv2.undistortPoints(border.reshape(-1, 1, 2), k, dist).reshape(-1, 2)
    rays = np.column_stack([und, np.ones(len(und))]) @ rot.T
    if (rays[:, 2] <= 1e-3).any():
        raise DenseError("rectification would turn the image edge behind the camera (views too oblique)")
    px = f * rays[:, :2] / rays[:, 2:3]
    return np.array([px[:, 0].min(), px[:, 0].max(), px[:, 1].min(), px[:, 1].max()])


@dataclass
class Rectification:
    rn: np.ndarray  # world -> rectified camera rotation (shared)
    f: float
    cx_i: float
    cx_j: float
    cy: float
    width: int
    height: int
    baseline: float
    maps_i: Tuple[np.ndarray, np.ndarray]
    maps_j: Tuple[np.ndarray, np.ndarray]


def rectify_pair(vi: View, vj: View, ki, di, kj, dj, size_i: Tuple[int, int], size_j: Tuple[int, int],
                 max_growth: float = 3.0) -> Rectification:
    """Rectify two calibrated views (Fusiello-style, from the known poses) into row-aligned images.

    Both rectified cameras share the rotation ``rn`` (x axis = the baseline from i to j) and focal f,
    so a point's disparity is d = x_i - x_j = f B / Z + cx_i - cx_j > 0."""
    import cv2

    b = vj.centre - vi.centre
    base = float(np.linalg.norm(b))
    if base <= 0:
        raise DenseError(f"{vi.name} and {vj.name} share one camera centre: no stereo baseline")
    x = b / base
    z = vi.R[2] + vj.R[2]
    z = z - x * (x @ z)
    nz = np.linalg.norm(z)
    if nz < 1e-6:
        raise DenseError(f"{vi.name} and {vj.name}: the baseline is along the viewing direction")
    z /= nz
    y = np.cross(z, x)
    rn = np.stack([x, y, z])
    f = float(np.mean([ki[0, 0], ki[1, 1], kj[0, 0], kj[1, 1]]))
    rot_i = rn @ vi.R.T
    rot_j = rn @ vj.R.T
    bi = _rect_bounds(ki, di, rot_i, f, *size_i)
    bj = _rect_bounds(kj, dj, rot_j, f, *size_j)
    ymin = max(bi[2], bj[2])
    ymax = min(bi[3], bj[3])
    if ymax - ymin < 8:
        raise DenseError(f"{vi.name} and {vj.name} do not overlap after rectification")
    width = int(math.ceil(max(bi[1] - bi[0], bj[1] - bj[0])))
    height = int(math.ceil(ymax - ymin))
    area = size_i[0] * size_i[1]
    if width * height > max_growth * area:
        raise DenseError(f"{vi.name} and {vj.name}: rectified images would be {width}x{height} px, "
                         f"{width * height / area:.1f} times the input (views too oblique for this pair)")
    cx_i, cx_j, cy = -bi[0], -bj[0], -ymin
    kn_i = np.array([[f, 0, cx_i], [0, f, cy], [0, 0, 1.0]])
    kn_j = np.array([[f, 0, cx_j], [0, f, cy], [0, 0, 1.0]])
    maps_i = cv2.initUndistortRectifyMap(ki, di, rot_i, kn_i, (width, height), cv2.CV_32FC1)
    maps_j = cv2.initUndistortRectifyMap(kj, dj, rot_j, kn_j, (width, height), cv2.CV_32FC1)
    return Rectification(rn, f, cx_i, cx_j, cy, width, height, base, maps_i, maps_j)


def rect_project(pts: np.ndarray, centre: np.ndarray, rect: Rectification, cx: float) -> np.ndarray:
    pc = (pts - centre) @ rect.rn.T
    return np.column_stack([rect.f * pc[:, 0] / pc[:, 2] + cx, rect.f * pc[:, 1] / pc[:, 2] + rect.cy, pc[:, 2]])


NEAR_MARGIN = 0.25  # disparity search beyond the sparse points: 25 % more disparity (surfaces ~20 % closer:
FAR_MARGIN = 0.10  # roofs and crowns with few tie points) and 10 % less (ditches, pits)


def disparity_range(unit: PairUnit, rect: Rectification) -> Tuple[int, int]:
    """(minDisparity, numDisparities) for SGBM from the shared sparse points (0.5-99.5 %), widened by
    NEAR_MARGIN / FAR_MARGIN of the geometric disparity f B / Z."""
    pi = rect_project(unit.points, unit.vi.centre, rect, rect.cx_i)
    pj = rect_project(unit.points, unit.vj.centre, rect, rect.cx_j)
    ok = (pi[:, 2] > 0) & (pj[:, 2] > 0)
    if ok.sum() < 3:
        raise DenseError(f"{unit.vi.name} + {unit.vj.name}: too few shared points in front of both cameras")
    g = rect.f * rect.baseline / pi[ok, 2]  # geometric disparity; the images' disparity is g + cx_i - cx_j
    lo, hi = np.percentile(g, [0.5, 99.5])
    shift = rect.cx_i - rect.cx_j
    dmin = int(math.floor(lo * (1.0 - FAR_MARGIN) - 3 + shift))
    dmax = int(math.ceil(hi * (1.0 + NEAR_MARGIN) + 3 + shift))
    num = int(16 * math.ceil(max(16, dmax - dmin) / 16.0))
    return dmin, num


def _sgbm(block: int, dmin: int, num: int, uniqueness: int):
    import cv2

    return cv2.StereoSGBM_create(minDisparity=dmin, numDisparities=num, blockSize=block,
                                 P1=8 * block * block, P2=32 * block * block, disp12MaxDiff=-1,
                                 preFilterCap=63, uniquenessRatio=uniqueness, speckleWindowSize=100,
                                 speckleRange=2, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY)


def _sample_rows(arr: np.ndarray, rows: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Linear interpolation of arr[rows, xs] along x (xs float, inside [0, width - 1])."""
    x0 = np.floor(xs).astype(np.int64)
    x0 = np.clip(x0, 0, arr.shape[1] - 2)
    t = xs - x0
    return (1 - t) * arr[rows, x0] + t * arr[rows, x0 + 1]


def _zbuffer(shape: Tuple[int, int], px: np.ndarray, py: np.ndarray, depth: np.ndarray) -> np.ndarray:
    out = np.full(shape, np.nan, dtype=np.float32)
    c = np.round(px).astype(np.int64)
    r = np.round(py).astype(np.int64)
    ok = (c >= 0) & (c < shape[1]) & (r >= 0) & (r < shape[0]) & (depth > 0)
    c, r, d = c[ok], r[ok], depth[ok]
    order = np.argsort(-d.astype(np.float32))  # nearest written last: it wins
    out[r[order], c[order]] = d[order]
    return out


def match_pair(unit: PairUnit, cancel_path: Optional[str] = None) -> dict:
    """The unit of work: one stereo pair -> depth maps of both images, saved to ``unit.out_path``."""
    import cv2

    t0, c0 = time.time(), time.process_time()
    cv2.setNumThreads(max(1, unit.threads))
    check_unit_cancel(cancel_path)
    img_i, sxi, syi = load_scaled(unit.vi, unit.scale)
    img_j, sxj, syj = load_scaled(unit.vj, unit.scale)
    ki, di = camera_matrix(unit.vi.model, unit.vi.params, sxi, syi)
    kj, dj = camera_matrix(unit.vj.model, unit.vj.params, sxj, syj)
    hi_, wi_ = img_i.shape[:2]
    hj_, wj_ = img_j.shape[:2]
    summary = {"key": unit.key, "i": unit.vi.name, "j": unit.vj.name, "valid": 0, "megapixels": 0.0}
    try:
        rect = rectify_pair(unit.vi, unit.vj, ki, di, kj, dj, (wi_, hi_), (wj_, hj_))
        dmin, num = disparity_range(unit, rect)
    except DenseError as e:
        summary.update(skipped=str(e), seconds=time.time() - t0)
        _save_pair(unit.out_path, None, None, 0.0, summary)
        return summary
    gi, gj = _to_gray8(img_i), _to_gray8(img_j)
    w, h = rect.width, rect.height
    li = cv2.remap(gi, rect.maps_i[0], rect.maps_i[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    rj = cv2.remap(gj, rect.maps_j[0], rect.maps_j[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    ones_i = np.full(gi.shape, 255, np.uint8)
    ones_j = np.full(gj.shape, 255, np.uint8)
    mi = cv2.remap(ones_i, rect.maps_i[0], rect.maps_i[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT) == 255
    mj = cv2.remap(ones_j, rect.maps_j[0], rect.maps_j[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT) == 255
    del ones_i, ones_j
    # pad both sides so SGBM's invalid bands (the first maxD columns, and the last |minD|) hold no image
    pad = int(max(abs(dmin), abs(dmin + num))) + 1
    lp = cv2.copyMakeBorder(li, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    rp = cv2.copyMakeBorder(rj, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    sgbm = _sgbm(unit.block_size, dmin, num, unit.uniqueness)
    check_unit_cancel(cancel_path)
    disp_l = sgbm.compute(lp, rp).astype(np.float32) / 16.0
    check_unit_cancel(cancel_path)
    disp_r = sgbm.compute(np.ascontiguousarray(rp[:, ::-1]), np.ascontiguousarray(lp[:, ::-1]))
    disp_r = (disp_r.astype(np.float32) / 16.0)[:, ::-1]
    check_unit_cancel(cancel_path)
    disp_l = disp_l[:, pad:pad + w]
    disp_r = disp_r[:, pad:pad + w]  # indexed by the right image's x
    invalid = dmin - 0.5
    valid = (disp_l > invalid) & mi
    rows, xs = np.nonzero(valid)
    d = disp_l[rows, xs]
    xr = xs - d
    ok = (xr >= 0) & (xr <= w - 1)
    rows, xs, d, xr = rows[ok], xs[ok], d[ok], xr[ok]
    xri = np.round(xr).astype(np.int64)
    dr = disp_r[rows, np.clip(xri, 0, w - 1)]
    ok = (dr > invalid) & mj[rows, np.clip(xri, 0, w - 1)] & (np.abs(dr - d) <= unit.lr_tolerance)
    denom = d - rect.cx_i + rect.cx_j
    ok &= denom > 0.05
    rows, xs, d, xr, denom = rows[ok], xs[ok], d[ok], xr[ok], denom[ok]
    # triangulate in the rectified frame of camera i, then to the local frame
    z = rect.f * rect.baseline / denom
    x_r = (xs - rect.cx_i) * z / rect.f
    y_r = (rows - rect.cy) * z / rect.f
    world = np.column_stack([x_r, y_r, z]) @ rect.rn + unit.vi.centre
    depth_i = (world - unit.vi.centre) @ unit.vi.R[2]
    depth_j = (world - unit.vj.centre) @ unit.vj.R[2]
    # where each match came from in the (distorted, scaled) images
    px_i = rect.maps_i[0][rows, xs]
    py_i = rect.maps_i[1][rows, xs]
    px_j = _sample_rows(rect.maps_j[0], rows, xr)
    py_j = _sample_rows(rect.maps_j[1], rows, xr)
    map_i = _zbuffer((hi_, wi_), px_i, py_i, depth_i)
    map_j = _zbuffer((hj_, wj_), px_j, py_j, depth_j)
    zmed = float(np.median(z)) if len(z) else float("nan")
    rel_err = zmed / (rect.f * rect.baseline) if len(z) else 0.0
    summary.update(valid=int(len(z)), valid_fraction=float(len(z) / max(1, int(mi.sum()))),
                   megapixels=(wi_ * hi_ + wj_ * hj_) / 1e6, rectified=[w, h], disparities=[dmin, num],
                   rel_err=rel_err, seconds=time.time() - t0, cpu_seconds=time.process_time() - c0)
    check_unit_cancel(cancel_path)
    _save_pair(unit.out_path, map_i, map_j, rel_err, summary)
    return summary


def _save_npz(path: str, **arrays) -> None:
    """np.savez with fast deflate (level 1: depth maps with holes shrink ~3x at a fraction of savez_compressed's
    time), written to a temporary name and renamed: a cancelled or killed unit leaves no file that looks done."""
    import zipfile

    tmp = path + ".partial.npz"
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as zf:
        for name, arr in arrays.items():
            with zf.open(name + ".npy", "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(arr), allow_pickle=False)
    os.replace(tmp, path)


def _save_pair(path: str, map_i, map_j, rel_err: float, summary: dict) -> None:
    empty = np.zeros((0, 0), np.float32)
    _save_npz(path, depth_i=map_i if map_i is not None else empty, depth_j=map_j if map_j is not None else empty,
              rel_err=np.float64(rel_err), summary=np.array(json.dumps(summary)))


def read_pair_summary(path: str) -> dict:
    with np.load(path) as d:
        return json.loads(str(d["summary"]))


# ---------------------------------------------------------------------------
# fusion per image
# ---------------------------------------------------------------------------

def fuse_depth_maps(maps: np.ndarray, rel_tol: np.ndarray, min_consistent: int) -> Tuple[np.ndarray, np.ndarray]:
    """Fuse k depth maps (k, h, w) of one image: per pixel the candidate most others agree with
    (|d_l - d_m| <= rel_tol * d_m); kept where at least ``min_consistent`` maps agree; value = their mean.
    Returns (depth with NaN, number of agreeing maps)."""
    k = maps.shape[0]
    best_n = np.zeros(maps.shape[1:], dtype=np.int16)
    best_v = np.full(maps.shape[1:], np.nan, dtype=np.float32)
    for m in range(k):
        ref = maps[m]
        tol = rel_tol[m] * ref
        agree = np.zeros(maps.shape[1:], dtype=np.int16)
        total = np.zeros(maps.shape[1:], dtype=np.float64)
        for ll in range(k):
            with np.errstate(invalid="ignore"):
                a = np.abs(maps[ll] - ref) <= np.maximum(tol, rel_tol[ll] * ref)
            agree += a
            total += np.where(a, maps[ll], 0.0)
        better = agree > best_n
        best_n = np.where(better, agree, best_n)
        with np.errstate(invalid="ignore", divide="ignore"):
            best_v = np.where(better, (total / np.maximum(agree, 1)).astype(np.float32), best_v)
    keep = best_n >= max(1, min_consistent)
    return np.where(keep, best_v, np.nan).astype(np.float32), best_n


def backproject(view: View, k: np.ndarray, dist: np.ndarray, depth: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Local-frame points of the valid pixels of a depth map (z along the optical axis) and their (rows, cols)."""
    import cv2

    rows, cols = np.nonzero(np.isfinite(depth))
    if len(rows) == 0:
        return np.zeros((0, 3)), (rows, cols)
    pix = np.column_stack([cols, rows]).astype(np.float64).reshape(-1, 1, 2)
    und = cv2.undistortPoints(pix, k, dist).reshape(-1, 2)
    z = depth[rows, cols].astype(np.float64)
    pc = np.column_stack([und[:, 0] * z, und[:, 1] * z, z])
    return pc @ view.R + view.centre, (rows, cols)


def fuse_image(unit: FuseUnit, cancel_path: Optional[str] = None) -> dict:
    """The unit of fusion: one image's depth maps -> coloured points (local frame) in ``unit.out_path``."""
    import cv2

    cv2.setNumThreads(max(1, unit.threads))
    check_unit_cancel(cancel_path)
    maps, errs = [], []
    for path, role, rel_err in unit.maps:
        with np.load(path) as d:
            m = d["depth_" + role]
        if m.size:
            maps.append(m)
            errs.append(rel_err)
    out = {"image": unit.view.name, "points": 0, "path": unit.out_path, "bbox": None}
    if len(maps) < unit.min_consistent:
        out["note"] = f"{len(maps)} usable pair(s), {unit.min_consistent} needed"
        return out
    shapes = {m.shape for m in maps}
    if len(shapes) != 1:
        raise DenseError(f"depth maps of {unit.view.name} differ in size: {shapes}")
    stack = np.stack(maps)
    rel_tol = np.clip(unit.tolerance_px * np.asarray(errs, dtype=np.float64), 0.002, 0.05)
    fused, _n = fuse_depth_maps(stack, rel_tol, unit.min_consistent)
    del stack, maps
    check_unit_cancel(cancel_path)
    img, sx, sy = load_scaled(unit.view, unit.scale)
    k, dist = camera_matrix(unit.view.model, unit.view.params, sx, sy)
    xyz, (rows, cols) = backproject(unit.view, k, dist, fused)
    rgb = _to_rgb8(img)[rows, cols]
    if len(xyz):
        lo = np.percentile(xyz[:, :2], 0.5, axis=0)
        hi = np.percentile(xyz[:, :2], 99.5, axis=0)
        out["bbox"] = [float(v) for v in (*xyz[:, 0:2].min(axis=0), *xyz[:, 0:2].max(axis=0))]
        out["robust_bbox"] = [float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])]
    tmp = unit.out_path + ".partial.npz"
    np.savez(tmp, xyz=xyz.astype(np.float32), rgb=rgb.astype(np.uint8))
    os.replace(tmp, unit.out_path)
    out["points"] = int(len(xyz))
    return out


# ---------------------------------------------------------------------------
# the stage
# ---------------------------------------------------------------------------

def auto_resolution(gsd: float, scale: float) -> float:
    """2 x the median GSD, never finer than the matching pixel (GSD / scale); rounded to 3 digits."""
    res = gsd * max(2.0, 1.0 / scale)
    digits = 2 - int(math.floor(math.log10(res)))
    return float(round(res, max(0, digits)))


def _workspace_model(ws: Workspace):
    import pycolmap

    rec = pycolmap.Reconstruction()
    rec.read_binary(ws.path("georef", "model"))
    with open(ws.path("georef", "transform.json"), encoding="utf-8") as f:
        transform = json.load(f)
    return rec, transform


def _model_fingerprint(ws: Workspace) -> Dict[str, str]:
    folder = ws.path("georef", "model")
    return {n: file_fingerprint(os.path.join(folder, n)) for n in sorted(os.listdir(folder))
            if n.endswith(".bin")}


def _unit_memory(views: Dict[int, View], scale: float) -> int:
    px = max(v.width * v.height for v in views.values()) * scale * scale
    return int(px * 160)  # both images, rectified copies, maps, SGBM buffers, disparities, depth maps


def _threads_per_unit(workers: int) -> int:
    return max(1, cpu_count() // max(1, workers))


def build_dsm_workspace(workspace_dir: str, resolution: float = 0.0, quality: str = "half", engine: str = "cpu",
                        output_dsm: Optional[str] = None, output_point_cloud: Optional[str] = None,
                        options: Optional[DenseOptions] = None,
                        progress: Optional[Progress] = None) -> DsmStageResult:
    """The DSM stage: dense matching + fusion -> ``dsm.tif`` (COG) and optionally a LAS point cloud.

    Raises DenseError (bad input, nothing matched), WorkspaceError, Cancelled."""
    progress = progress or NullProgress()
    options = options or DenseOptions()
    quality = (quality or options.quality).lower()
    if quality not in QUALITIES:
        raise DenseError(f"unknown QUALITY {quality!r}; choose one of {', '.join(QUALITIES)}")
    options.quality = quality
    engine = (engine or "cpu").lower()
    if engine not in ENGINES:
        raise DenseError(f"unknown ENGINE {engine!r}; choose one of {', '.join(ENGINES)}")
    if resolution is None or resolution < 0 or not math.isfinite(resolution):
        raise DenseError(f"RESOLUTION must be 0 (automatic) or a positive number of metres, got {resolution}")
    ws = Workspace.open(workspace_dir)
    if not ws.stage_done(GEOREF) or not os.path.isdir(ws.path("georef", "model")):
        state = ws.stage(GEOREF).get("status", "pending")
        raise DenseError(
            f"workspace {ws.root} is not georeferenced (georeference stage: {state}): run 'Georeference' first, "
            "with ground control points, camera positions or the images' EXIF GPS. The aligned model alone has "
            "an arbitrary scale and no vertical direction, so no DSM is built from it.")
    if engine == "cuda":
        import pycolmap

        if not getattr(pycolmap, "has_cuda", False):
            raise DenseError("ENGINE 'cuda' needs pycolmap built with CUDA (pycolmap.has_cuda is False here); "
                             "use ENGINE 'cpu'")
    scale = QUALITIES[quality]
    t_start = time.time()
    timings: Dict[str, float] = {}
    warnings: List[str] = []
    log: List[str] = []

    def warn(msg: str) -> None:
        warnings.append(msg)
        progress.warning(msg)

    rec, transform = _workspace_model(ws)
    offset = np.asarray(transform.get("offset", [0.0, 0.0, 0.0]), dtype=np.float64)
    crs = transform.get("crs") or ws.crs
    images_dir = ws.data.get("images_dir") or ""
    views = views_from_reconstruction(rec, images_dir)
    if len(views) < 2:
        raise DenseError(f"the model of {ws.root} has {len(views)} registered image(s): dense matching needs 2 or more")
    missing = [v.name for v in views.values() if not os.path.isfile(v.path)]
    if missing:
        raise DenseError(f"{len(missing)} image(s) of the model are missing from {images_dir}: "
                         f"{', '.join(missing[:8])}{' ...' if len(missing) > 8 else ''}")

    # 1. pairs
    t0 = time.time()
    xyz, tracks = sparse_points(rec)
    pairs, stats = select_pairs(views, xyz, tracks, options)
    if not pairs:
        raise DenseError(
            f"no stereo pair passed the selection among {len(views)} images ({stats['candidates']} image pairs share "
            f"tie points: {stats['few_shared_points']} with fewer than {options.min_shared_points} shared points, "
            f"{stats['baseline_too_short']} with a baseline under {options.min_baseline_ratio:g} x depth, "
            f"{stats['baseline_too_long']} over {options.max_baseline_ratio:g} x depth, {stats['view_angle']} with "
            f"views more than {options.max_view_angle:g} degrees apart). The images need stereo overlap (60 % or more "
            "along the strip) taken from different positions.")
    gsd = median_gsd(views, xyz, tracks)
    res = float(resolution) if resolution and resolution > 0 else auto_resolution(gsd, scale)
    timings["pair_selection"] = time.time() - t0
    log.append(f"pairs: {len(pairs)} selected from {stats['candidates']} overlapping image pairs "
               f"({len(views)} images, quality {quality}, median GSD {gsd:.3f} m, DSM resolution {res:g} m)")
    progress.info(log[-1])

    dsm_path = os.path.abspath(output_dsm) if output_dsm else ws.path("dsm.tif")
    pc_path = os.path.abspath(output_point_cloud) if output_point_cloud else None
    model_fp = _model_fingerprint(ws)
    params = {"resolution": resolution, "quality": quality, "engine": engine, "output_dsm": dsm_path,
              "output_point_cloud": pc_path, "options": {k: v for k, v in asdict(options).items()
                                                         if k not in ("workers", "executor", "scheduler")}}
    ws.begin_stage(STAGE, params, model_fp)
    try:
        dense_dir = ws.subdir("dense")
        if engine == "cuda":
            point_files, n_reused = _cuda_points(ws, rec, views, scale, dense_dir, SubProgress(progress, 0.02, 0.88))
            timings["matching"] = time.time() - t0
            n_pairs = 0
        else:
            point_files, n_pairs, n_reused, mt = _cpu_points(views, pairs, xyz, scale, options, dense_dir, model_fp,
                                                             progress, warn, log)
            timings.update(mt)
        n_points = sum(pf.count for pf in point_files)
        if n_points == 0:
            raise DenseError("dense matching found no consistent surface point: the pairs matched but no pixel was "
                             f"confirmed by {options.min_consistent} independent pairs (too little texture or overlap?)")
        log.append(f"points: {n_points} fused from {len(point_files)} images")
        progress.info(log[-1])

        # 4. DSM
        t0 = time.time()
        check_cancel(progress)
        boxes = np.array([pf.robust_bbox for pf in point_files if pf.count > 0])
        xmin, ymin = boxes[:, 0].min() + offset[0], boxes[:, 1].min() + offset[1]
        xmax, ymax = boxes[:, 2].max() + offset[0], boxes[:, 3].max() + offset[1]
        grid = dsmmod.Grid.covering(xmin, ymin, xmax, ymax, res)
        raster, counts = dsmmod.rasterize_points(point_files, grid, offset, cluster_tol=max(3 * res, 4 * gsd),
                                                 progress=SubProgress(progress, 0.88, 0.93))
        raster = dsmmod.remove_speckles(raster, max_cells=4)
        raster = dsmmod.fill_small_holes(raster, options.max_hole_cells)
        centres = np.array([v.centre[:2] + offset[:2] for v in views.values()])
        hull = dsmmod.convex_hull_xy(centres)
        valid_fraction = dsmmod.footprint_valid_fraction(raster, dsmmod.polygon_mask(grid, hull))
        if valid_fraction is None:  # one strip: the hull is a line; use the cells the points cover
            valid_fraction = float(np.isfinite(raster).mean())
        check_cancel(progress)
        dsmmod.write_cog(dsm_path, raster, grid.geotransform, crs, progress=SubProgress(progress, 0.93, 0.97),
                         metadata={"ARCHAEOORTHO_STAGE": "dsm", "RESOLUTION": res, "QUALITY": quality,
                                   "ENGINE": engine, "PAIRS": n_pairs, "POINTS": n_points,
                                   "VALID_FRACTION": round(valid_fraction, 4)})
        timings["dsm"] = time.time() - t0
        del counts

        # 5. point cloud
        if pc_path:
            t0 = time.time()
            n_written = dsmmod.write_las(pc_path, dsmmod.stream_point_files(point_files), offset, crs,
                                         progress=SubProgress(progress, 0.97, 1.0), total=n_points)
            timings["point_cloud"] = time.time() - t0
            log.append(f"point cloud: {n_written} points -> {pc_path}")
        timings["total"] = time.time() - t_start
        log.append("seconds: " + ", ".join(f"{k.replace('_', ' ')} {v:.1f}" for k, v in timings.items()))
        log.append(f"DSM {grid.width} x {grid.height} cells at {res:g} m, valid fraction {valid_fraction:.3f} "
                   "inside the convex hull of the camera centres")
        for line in log[-2:]:
            progress.info(line)
        for k, v in timings.items():
            if k != "total":
                ws.record_timing(STAGE, k, v)
        outputs = {"dsm": _rel(ws, dsm_path)}
        if pc_path:
            outputs["point_cloud"] = _rel(ws, pc_path)
        ws.end_stage(STAGE, DONE, outputs=outputs,
                     results={"VALID_FRACTION": valid_fraction, "pairs": n_pairs, "pairs_reused": n_reused,
                              "points": n_points, "resolution": res, "gsd": gsd, "width": grid.width,
                              "height": grid.height, "warnings": warnings})
        ws.invalidate_after(STAGE)
        progress.report(1.0, f"DSM: {grid.width} x {grid.height} cells at {res:g} m")
        return DsmStageResult(workspace=ws.root, dsm_path=dsm_path, point_cloud_path=pc_path, crs=crs or "",
                              resolution=res, valid_fraction=valid_fraction, pairs=n_pairs, pairs_reused=n_reused,
                              points=n_points, timings={k: round(v, 3) for k, v in timings.items()},
                              warnings=warnings, log_lines=log)
    except Cancelled:
        ws.end_stage(STAGE, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        ws.end_stage(STAGE, FAILED, error=str(e))
        raise


def _rel(ws: Workspace, path: str) -> str:
    rel = os.path.relpath(path, ws.root)
    return path if rel.startswith("..") else rel


@dataclass
class _PointFile(dsmmod.PointFile):
    robust_bbox: Tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)


def _cpu_points(views, pairs: List[PairInfo], xyz, scale, options: DenseOptions, dense_dir: str,
                model_fp: Dict[str, str], progress: Progress, warn, log) -> Tuple[List[_PointFile], int, int, dict]:
    timings = {}
    block = options.block_size or (3 if scale <= 0.25 else 5)
    if block % 2 == 0:
        block += 1
    key = fingerprint({"v": CACHE_VERSION, "model": model_fp, "scale": scale, "block": block,
                       "uniq": options.uniqueness, "lr": options.lr_tolerance})
    pair_dir = os.path.join(dense_dir, f"pairs-{key}")
    for name in os.listdir(dense_dir):  # caches of other models / settings
        if name.startswith("pairs-") and name != f"pairs-{key}":
            shutil.rmtree(os.path.join(dense_dir, name), ignore_errors=True)
    os.makedirs(pair_dir, exist_ok=True)
    for name in os.listdir(pair_dir):
        if ".partial" in name:
            os.unlink(os.path.join(pair_dir, name))
    atomic_write_text(os.path.join(pair_dir, "cache.json"),
                      json.dumps({"model": model_fp, "scale": scale, "block": block}, indent=1))

    unit_mem = _unit_memory(views, scale)
    executor = make_executor(options.workers, options.executor, options.scheduler, unit_memory=unit_mem)
    workers = getattr(executor, "_max_workers", 1) or 1
    where = describe_executor(executor)
    threads = _threads_per_unit(workers)

    # 2. matching, pair by pair
    t0 = time.time()
    units, done_pairs = [], []
    for p in pairs:
        out = os.path.join(pair_dir, f"{p.i}-{p.j}.npz")
        if os.path.isfile(out):
            done_pairs.append((p, out))
            continue
        units.append(PairUnit(f"{p.i}-{p.j}", out, views[p.i], views[p.j], scale, xyz[p.point_idx], block,
                              options.uniqueness, options.lr_tolerance, threads))
    n_reused = len(done_pairs)
    if n_reused:
        progress.info(f"resuming: {n_reused} of {len(pairs)} pairs already matched")
    summaries = []
    for p, out in done_pairs:
        try:
            summaries.append(read_pair_summary(out))
        except (OSError, ValueError, KeyError):  # damaged cache file: match again
            os.unlink(out)
            units.append(PairUnit(f"{p.i}-{p.j}", out, views[p.i], views[p.j], scale, xyz[p.point_idx], block,
                                  options.uniqueness, options.lr_tolerance, threads))
            n_reused -= 1
    sub = SubProgress(progress, 0.02 + 0.73 * (n_reused / len(pairs)), 0.75)
    with executor:
        for _i, summary in run_units(executor, match_pair, units, sub, label="pair",
                                     describe=lambda u: f"{u.vi.name} + {u.vj.name}", cancel_dir=dense_dir):
            summaries.append(summary)
    timings["matching"] = time.time() - t0
    skipped = [s for s in summaries if s.get("skipped")]
    for s in skipped:
        warn(f"pair {s['i']} + {s['j']} skipped: {s['skipped']}")
    matched = [s for s in summaries if not s.get("skipped")]
    if not matched:
        raise DenseError("no stereo pair could be rectified and matched: " + "; ".join(
            s["skipped"] for s in skipped[:5]))
    secs = [s["seconds"] for s in matched if "seconds" in s]
    mp = sum(s.get("megapixels", 0.0) for s in matched)
    log.append(f"matching: {len(matched)} pairs ({n_reused} reused from a previous run), "
               f"{np.mean(secs) if secs else 0:.2f} s per pair, {sum(secs) / max(mp, 1e-9):.2f} s per megapixel, "
               f"{where}")
    progress.info(log[-1])

    # 3. fusion, image by image
    t0 = time.time()
    by_key = {s["key"]: s for s in summaries}
    per_image: Dict[int, List[Tuple[str, str, float]]] = {}
    for p in pairs:
        s = by_key.get(f"{p.i}-{p.j}")
        if s is None or s.get("skipped"):
            continue
        path = os.path.join(pair_dir, f"{p.i}-{p.j}.npz")
        per_image.setdefault(p.i, []).append((path, "i", float(s.get("rel_err", 0.01))))
        per_image.setdefault(p.j, []).append((path, "j", float(s.get("rel_err", 0.01))))
    fused_dir = os.path.join(dense_dir, "fused")
    shutil.rmtree(fused_dir, ignore_errors=True)
    os.makedirs(fused_dir)
    lonely = [views[i].name for i, m in per_image.items() if len(m) < options.min_consistent]
    if lonely:
        progress.info(f"{len(lonely)} image(s) are in fewer than {options.min_consistent} matched pairs and add no "
                      f"points of their own: {', '.join(lonely[:6])}{' ...' if len(lonely) > 6 else ''}")
    funits = [FuseUnit(views[i], scale, maps, options.depth_tolerance_px, options.min_consistent,
                       os.path.join(fused_dir, f"{i}.npz"), threads)
              for i, maps in sorted(per_image.items()) if len(maps) >= options.min_consistent]
    files: List[_PointFile] = []
    executor = make_executor(options.workers, options.executor, options.scheduler, unit_memory=unit_mem)
    with executor:
        for _i, r in run_units(executor, fuse_image, funits, SubProgress(progress, 0.75, 0.88), label="fusion",
                               describe=lambda u: u.view.name, cancel_dir=dense_dir):
            if r["points"] > 0:
                files.append(_PointFile(r["path"], tuple(r["bbox"]), r["points"], tuple(r["robust_bbox"])))
    timings["fusion"] = time.time() - t0
    return files, len(matched), n_reused, timings


def _cuda_points(ws: Workspace, rec, views, scale: float, dense_dir: str, progress: Progress):
    """COLMAP patch-match stereo + fusion (CUDA builds of pycolmap only); points as one point file."""
    import pycolmap

    from ..align.sfm import _CancelWatcher

    mvs = os.path.join(dense_dir, "mvs")
    key = fingerprint({"model": _model_fingerprint(ws), "scale": scale})
    key_file = os.path.join(mvs, "archaeoortho-key.txt")
    if os.path.isdir(mvs) and (not os.path.isfile(key_file) or open(key_file).read().strip() != key):
        shutil.rmtree(mvs, ignore_errors=True)  # built from another model or scale
    fused_dir = os.path.join(dense_dir, "fused")
    shutil.rmtree(fused_dir, ignore_errors=True)
    os.makedirs(fused_dir)
    model_dir = ws.path("georef", "model")
    images_dir = ws.data.get("images_dir") or ""
    max_size = int(max(max(v.width, v.height) for v in views.values()) * scale)
    with _CancelWatcher(progress) as token:
        progress.report(0.0, "undistorting images (COLMAP)")
        if not os.path.isdir(os.path.join(mvs, "stereo")):
            uo = pycolmap.UndistortCameraOptions()
            uo.max_image_size = max_size
            pycolmap.undistort_images(mvs, model_dir, images_dir, undistort_options=uo, cancellation_token=token)
            atomic_write_text(key_file, key)
        progress.report(0.1, "patch-match stereo (COLMAP, CUDA)")
        pm = pycolmap.PatchMatchOptions()
        pm.max_image_size = max_size
        pm.geom_consistency = True
        pycolmap.patch_match_stereo(mvs, options=pm, cancellation_token=token)
        progress.report(0.8, "stereo fusion (COLMAP)")
        fo = pycolmap.StereoFusionOptions()
        fo.max_image_size = max_size
        fused = pycolmap.stereo_fusion(os.path.join(mvs, "fused.ply"), mvs, options=fo, output_type="PLY",
                                       cancellation_token=token)
    pts = [(np.asarray(p.xyz), np.asarray(p.color)) for p in fused.points3D.values()]
    xyz = np.array([p[0] for p in pts], dtype=np.float32).reshape(-1, 3)
    rgb = np.array([p[1] for p in pts], dtype=np.uint8).reshape(-1, 3)
    path = os.path.join(fused_dir, "cuda.npz")
    np.savez(path, xyz=xyz, rgb=rgb)
    if len(xyz) == 0:
        return [], 0
    lo = np.percentile(xyz[:, :2], 0.5, axis=0)
    hi = np.percentile(xyz[:, :2], 99.5, axis=0)
    bbox = (*xyz[:, :2].min(axis=0), *xyz[:, :2].max(axis=0))
    return [_PointFile(path, tuple(float(v) for v in bbox), len(xyz), (lo[0], lo[1], hi[0], hi[1]))], 0


__all__ = ["build_dsm_workspace", "DenseOptions", "DenseError", "DsmStageResult", "select_pairs", "match_pair",
           "fuse_image", "rectify_pair", "camera_matrix", "views_from_reconstruction", "QUALITIES", "ENGINES"]
