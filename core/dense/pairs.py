"""The views of a georeferenced model and the stereo pairs chosen among them.

A :class:`View` is one registered image with its camera (:class:`core.geometry.camera.Intrinsics`) and pose in
the local frame.  :func:`select_pairs` scores every two images that share tie points: the baseline-to-depth
ratio B/Z, the angle between the optical axes and the number of shared points; each image then keeps the pairs
that bring the most of its tie points to two-fold coverage.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.camera import Intrinsics, Pose
from ..io.images import primary_band, read_image
from .options import DenseError, DenseOptions


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
    mask_path: Optional[str] = None  # masks/<image>.png (white = use): no dense point from its black pixels

    @property
    def centre(self) -> np.ndarray:
        return -self.R.T @ self.t

    @property
    def camera(self) -> Intrinsics:
        return Intrinsics(self.model, self.width, self.height, self.params)

    @property
    def pose(self) -> Pose:
        return Pose(self.R, self.t)

    def camera_matrix(self, sx: float = 1.0, sy: float = 1.0) -> Tuple[np.ndarray, np.ndarray]:
        """(K, distortion) in OpenCV's convention for the image scaled by (sx, sy) (``Intrinsics.cv_matrix``)."""
        cam = self.camera
        if not cam.native:
            raise DenseError(f"camera model {self.model} is not supported by dense matching "
                             "(use SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV)")
        return cam.cv_matrix(sx, sy)

    @property
    def focal(self) -> float:
        return float(np.mean(self.camera_matrix()[0][[0, 1], [0, 1]]))


@dataclass
class PairInfo:
    i: int  # image ids (i < j)
    j: int
    shared: int
    baseline_ratio: float
    view_angle: float  # degrees
    score: float
    point_idx: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, np.int64))


def views_from_reconstruction(rec, images_dir: str) -> Dict[int, View]:
    """The registered images of a reconstruction (pycolmap) as views, by image id."""
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


def auto_resolution(gsd: float, scale: float) -> float:
    """2 x the median GSD, never finer than the matching pixel (GSD / scale); rounded to 3 digits."""
    res = gsd * max(2.0, 1.0 / scale)
    digits = 2 - int(math.floor(math.log10(res)))
    return float(round(res, max(0, digits)))


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
    chosen = _greedy_cover(cands, options.partners)
    pairs = sorted(chosen.values(), key=lambda p: (p.i, p.j))
    stats["kept"] = len(pairs)
    return pairs, stats


def _greedy_cover(cands: List[PairInfo], partners: int) -> Dict[Tuple[int, int], PairInfo]:
    """The pairs each image takes: a greedy cover of its tie points (see :func:`select_pairs`)."""
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
        for _ in range(max(1, partners)):
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
    return chosen


def load_scaled(view: View, scale: float) -> Tuple[np.ndarray, float, float]:
    """Image pixels at ``scale`` and the exact (sx, sy) factors of the array obtained; of a photo that names a
    primary band (a multispectral capture's, core.io.images.primary_band) that band alone, the one its features
    were matched on."""
    if not os.path.isfile(view.path):
        raise DenseError(f"image {view.path} is missing (moved since alignment?)")
    size = None if scale >= 1.0 else max(1, int(round(max(view.width, view.height) * scale)))
    img = read_image(view.path, size)
    band = primary_band(view.path) if img.shape[2] > 1 else 0
    if band:
        img = img[:, :, band - 1:band]
    h, w = img.shape[:2]
    return img, w / view.width, h / view.height
