"""Sky masks for high obliques: a colour/texture sky detector before alignment, the horizon of a pose after it.

Photos from a light aircraft orbiting a site (30-70 degrees off nadir) often show the horizon and the sky.  No
tie point and no dense point may come from there: the sky has no fixed position (clouds move, its texture is
noise) and the haze along the horizon matches anything.

- :func:`detect_sky` (before alignment, from the pixels alone): the sky is a bright, smooth region, bluish or a
  pale grey-white, connected to the upper edge of the upright photo (its EXIF orientation is applied first).
  The detector marks the pixels of low local texture (standard deviation in a 7 x 7 window, at an analysis size
  of ``SkyOptions.analysis_size``) that are bright and bluish or pale, keeps the connected regions of them that
  touch the upper edge and do not reach the lower one (a smooth field or road running across a vertical photo
  does) and together span at least ``min_top_cover`` of it, fills their holes (clouds, a bird: what the lower
  edge cannot reach without crossing the sky), and widens the result by
  ``SkyOptions.margin`` of the image height downwards to take the horizon's mixed pixels.  A region under
  ``min_fraction`` of the image is no sky (a pale roof at the upper edge of a vertical photo).
- :func:`write_sky_masks` writes those masks through the mask machinery of :mod:`core.prepare.masks`
  (``masks/<image>.png``, white = use, merged with a mask the image already has): the alignment's feature
  extraction then ignores the sky (COLMAP's ``mask_path``), as it ignores a scan's film border.
- :func:`horizon_keep` (after alignment, from the adjusted pose): the pixels whose ray points less than
  ``margin_deg`` below the horizontal (and everything above it).  The vertical is the georeferenced frame's z, or
  :func:`estimate_up` from an aligned, not yet georeferenced model (the normal of the tie points' best plane,
  on the cameras' side).  Dense matching drops what it finds there (:mod:`core.dense.fusion`);
  :func:`write_horizon_masks` merges it into ``masks/`` for a later alignment.

A terrain that rises above the cameras (a valley flown below the ridges) really is above the horizon: turn the
pose mask off there (``DenseOptions.sky_margin_deg = None``).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, check_cancel
from ..geometry.camera import Intrinsics
from ..io.images import ORIENTATION_STEPS, exif_orientation, full_scale, read_image, to_upright
from .masks import find_mask, mask_file_name, read_keep, write_keep
from .options import SkyOptions

__all__ = ["SkyResult", "detect_sky", "estimate_up", "horizon_keep", "sky_keep", "write_horizon_masks",
           "write_sky_masks"]


@dataclass
class SkyResult:
    masks: Dict[str, str] = field(default_factory=dict)  # image -> mask file written
    sky_fraction: Dict[str, float] = field(default_factory=dict)  # image -> share of its pixels hidden as sky
    warnings: List[str] = field(default_factory=list)


# ---------------------------------------------------------------------------
# before alignment: the pixels
# ---------------------------------------------------------------------------

def _from_upright(arr: np.ndarray, orientation: int) -> np.ndarray:
    """The inverse of core.io.images.to_upright: an upright raster back into the stored grid."""
    turn, mirror_lr, mirror_tb = ORIENTATION_STEPS[orientation]
    out = arr
    if mirror_tb:
        out = out[::-1]
    if mirror_lr:
        out = out[:, ::-1]
    if turn:
        out = np.rot90(out, k=turn // 90, axes=(0, 1))
    return np.ascontiguousarray(out)


def _candidates(img: np.ndarray, options: SkyOptions) -> np.ndarray:
    """Pixels that may be sky: smooth, bright, and bluish or pale (colour); smooth and bright (grey)."""
    cv2 = require("cv2", "sky masks")
    a = img.astype(np.float32) * np.float32(255.0 / full_scale(img))
    colour = a.shape[2] >= 3 and float(np.abs(a[:, :, 0] - a[:, :, 2]).mean()) > 1.0
    grey = (0.299 * a[:, :, 0] + 0.587 * a[:, :, 1] + 0.114 * a[:, :, 2]) if a.shape[2] >= 3 else a[:, :, 0]
    grey = np.ascontiguousarray(grey, dtype=np.float32)
    mean = cv2.boxFilter(grey, -1, (7, 7))
    sq = cv2.boxFilter(grey * grey, -1, (7, 7))
    texture = np.sqrt(np.maximum(sq - mean * mean, 0.0))
    smooth = texture <= options.max_texture
    bright = mean >= 255.0 * options.min_brightness
    if not colour:
        return smooth & bright
    r, g, b = (cv2.boxFilter(np.ascontiguousarray(a[:, :, k]), -1, (7, 7)) for k in range(3))
    bluish = (b - r) >= 255.0 * options.min_blueness
    hi, lo = np.maximum(np.maximum(r, g), b), np.minimum(np.minimum(r, g), b)
    pale = (hi - lo) <= 255.0 * options.max_pale_saturation
    return smooth & bright & (bluish | pale)


def _down_to_the_ground(cand: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """In the ``columns`` that have sky at the top: every row above the first run of non-sky pixels longer than 4 %
    of the height (the ground; a cloud's edge or a bird is shorter), unless no such run reaches down (no ground)."""
    h = cand.shape[0]
    need = max(3, int(round(0.04 * h)))
    run = np.zeros(cand.shape, np.int32)
    acc = np.zeros(cand.shape[1], np.int32)
    for r in range(h - 1, -1, -1):
        acc = np.where(cand[r], 0, acc + 1)
        run[r] = acc
    hit = run >= need
    first = np.where(hit.any(axis=0), hit.argmax(axis=0), h)
    ok = columns & (first < h)
    return (np.arange(h)[:, None] < first[None, :]) & ok[None, :]


def sky_keep(img: np.ndarray, options: Optional[SkyOptions] = None, orientation: int = 1) -> np.ndarray:
    """(height, width) bool of an image array (rows, cols[, bands]): True = use, False = sky.

    ``orientation``: the photo's EXIF orientation (the sky is searched at the upper edge of the upright photo)."""
    cv2 = require("cv2", "sky masks")
    options = options or SkyOptions()
    img = img if img.ndim == 3 else img[:, :, None]
    height, width = img.shape[:2]
    up = to_upright(img, orientation)
    uh, uw = up.shape[:2]
    s = min(1.0, options.analysis_size / float(max(uh, uw)))
    small = up if s >= 1.0 else cv2.resize(up, (max(1, round(uw * s)), max(1, round(uh * s))),
                                           interpolation=cv2.INTER_AREA)
    small = small if small.ndim == 3 else small[:, :, None]
    cand = _candidates(small, options).astype(np.uint8)
    cand = cv2.morphologyEx(cand, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    n, labels = cv2.connectedComponents(cand, connectivity=4)
    # the sky: regions spanning a good part of the upper edge (min_top_cover) that do not reach the lower one (a
    # smooth field or road running across a vertical photo does)
    # (clouds may split it: the regions touching the upper edge count together, over the top 5 % of the rows)
    bottom = set(np.unique(labels[-1]).tolist())
    ids = [i for i in np.unique(labels[0][cand[0] > 0]) if i not in bottom]
    sky = np.isin(labels, ids) if n > 1 and ids else np.zeros(cand.shape, bool)
    band = max(1, int(round(0.05 * sky.shape[0])))
    if sky[:band].any(axis=0).mean() < options.min_top_cover:
        sky[:] = False
    sky |= _down_to_the_ground(cand > 0, sky[:band].any(axis=0))
    if sky.mean() < options.min_fraction:
        return np.ones((height, width), bool)
    # holes (clouds, a bird): what the lower edge cannot reach without crossing the sky is sky too
    ground = (~sky).astype(np.uint8)
    n, labels = cv2.connectedComponents(ground, connectivity=4)
    edge = np.unique(labels[-1])
    sky = ~np.isin(labels, edge[edge > 0])
    m = max(1, int(round(options.margin * sky.shape[0])))
    sky = cv2.dilate(sky.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * m + 1, 2 * m + 1))) > 0
    full = cv2.resize(sky.astype(np.uint8), (uw, uh), interpolation=cv2.INTER_NEAREST) > 0
    return ~_from_upright(full, orientation).reshape(height, width)


def detect_sky(path: str, options: Optional[SkyOptions] = None) -> np.ndarray:
    """The sky detector on one photo file: (height, width) bool in the stored pixel grid, True = use."""
    options = options or SkyOptions()
    orientation = exif_orientation(path)
    from osgeo import gdal

    ds = gdal.Open(path)
    width, height = ds.RasterXSize, ds.RasterYSize
    ds = None
    img = read_image(path, max(2 * options.analysis_size, 64))
    keep = sky_keep(img, options, orientation)
    if keep.shape != (height, width):
        cv2 = require("cv2", "sky masks")
        keep = cv2.resize(keep.astype(np.uint8), (width, height), interpolation=cv2.INTER_NEAREST) > 0
    return keep


def write_sky_masks(images_dir: str, names: Sequence[str], out_dir: str, options: Optional[SkyOptions] = None,
                    base_masks: Optional[Mapping[str, Optional[str]]] = None,
                    progress: Optional[Progress] = None) -> SkyResult:
    """Detect the sky in every image of ``names`` and write ``<out_dir>/<image>.png`` for those that show some,
    merged (logical AND of the areas to use) with ``base_masks[name]`` or, without one, the mask
    :func:`core.prepare.masks.find_mask` finds in ``out_dir``.  Images without sky get no new mask."""
    options = options or SkyOptions()
    progress = progress or NullProgress()
    base_masks = dict(base_masks or {})
    res = SkyResult()
    os.makedirs(out_dir, exist_ok=True)
    for i, n in enumerate(names):
        check_cancel(progress)
        keep = detect_sky(os.path.join(images_dir, n), options)
        progress.report((i + 1) / max(1, len(names)), f"sky: {n}")
        if keep.all():
            continue
        base = base_masks.get(n) or find_mask(out_dir, n)
        if base:
            keep &= read_keep(base, keep.shape[1], keep.shape[0])
        path = os.path.join(out_dir, mask_file_name(n))
        write_keep(path, keep)
        res.masks[n] = path
        res.sky_fraction[n] = round(1.0 - float(keep.mean()), 4)
        if not keep.any():
            res.warnings.append(f"the sky mask of {n} hides the whole image: no feature can be found in it")
    return res


# ---------------------------------------------------------------------------
# after alignment: the horizon of the pose
# ---------------------------------------------------------------------------

def horizon_keep(camera: Intrinsics, rotation: np.ndarray, up: Sequence[float] = (0.0, 0.0, 1.0),
                 margin_deg: float = 1.0, shape: Optional[Tuple[int, int]] = None, step: int = 4) -> np.ndarray:
    """(rows, cols) bool, True = below the horizon by more than ``margin_deg``: the pixels of a camera
    (cam_from_world ``rotation``) whose ray points that far below the plane normal to ``up``.

    ``shape``: the (rows, cols) of the grid wanted (a downscaled image; default the camera's size); the
    elevation is computed every ``step`` pixels of the camera and interpolated (it is smooth)."""
    cv2 = require("cv2", "sky masks")
    w, h = camera.width, camera.height
    rows, cols = shape or (h, w)
    xs = np.arange(0.0, w + step, step)
    ys = np.arange(0.0, h + step, step)
    gx, gy = np.meshgrid(np.minimum(xs, w), np.minimum(ys, h))
    xn = camera.unproject(np.stack([gx, gy], axis=-1))
    d = np.concatenate([xn, np.ones(xn.shape[:-1] + (1,))], axis=-1) @ np.asarray(rotation, dtype=float)
    u = np.asarray(up, dtype=float)
    u = u / np.linalg.norm(u)
    with np.errstate(invalid="ignore"):
        elev = np.degrees(np.arcsin(np.clip((d @ u) / np.linalg.norm(d, axis=-1), -1.0, 1.0)))
    # a pixel whose ray the lens model cannot give (beyond a strong distortion's valid radius) is kept: it says
    # nothing of the horizon, and the corners of a vertical photo are ground
    elev = np.where(np.isfinite(elev), elev, -90.0).astype(np.float32)
    # pixel centres of the wanted grid in camera pixels, then in the coarse grid's cells
    px = (np.arange(cols) + 0.5) * (w / cols) / step
    py = (np.arange(rows) + 0.5) * (h / rows) / step
    mx, my = np.meshgrid(px.astype(np.float32), py.astype(np.float32))
    fine = cv2.remap(elev, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return fine < -float(margin_deg)


def _plane_normal(xyz: np.ndarray) -> Tuple[np.ndarray, float]:
    """(normal of the best plane through the points, flatness: smallest / middle singular value)."""
    c = xyz.mean(axis=0)
    _, sv, vt = np.linalg.svd(xyz - c, full_matrices=False)
    return vt[-1], float(sv[-1] / max(sv[1], 1e-12))


def estimate_up(rec) -> np.ndarray:
    """The vertical of an aligned (not georeferenced) pycolmap model: the normal of the plane of the camera centres
    when they span one (a flight at constant height: strips, an orbit), else of the best plane through the tie
    points (the ground); turned to the side of the cameras."""
    xyz = np.array([p.xyz for p in rec.points3D.values()], dtype=float)
    centres = np.array([np.asarray(im.projection_center(), dtype=float) for im in rec.images.values()
                        if im.has_pose])
    if len(xyz) < 3 or not len(centres):
        return np.array([0.0, 0.0, 1.0])
    lo, hi = np.percentile(xyz, [2, 98], axis=0)
    inl = xyz[np.all((xyz >= lo) & (xyz <= hi), axis=1)]
    inl = inl if len(inl) >= 3 else xyz
    n, _ = _plane_normal(inl)
    if len(centres) >= 4:
        nc, flat = _plane_normal(centres)
        if flat < 0.1 and abs(float(nc @ n)) > math.cos(math.radians(20.0)):  # a plane, and roughly the ground's
            n = nc
    return n if float(np.mean(centres @ n) - inl.mean(axis=0) @ n) >= 0 else -n


def write_horizon_masks(rec, masks_dir: str, up: Optional[Sequence[float]] = None,
                        margin_deg: float = 1.0) -> SkyResult:
    """Merge the horizon of every registered image's pose into ``masks_dir`` (``masks/<image>.png``, AND with
    the mask it has); ``up`` default :func:`estimate_up`.  Images whose every pixel is below the horizon keep
    their mask as it is."""
    up = estimate_up(rec) if up is None else np.asarray(up, dtype=float)
    res = SkyResult()
    os.makedirs(masks_dir, exist_ok=True)
    for im in sorted(rec.images.values(), key=lambda i: i.name):
        if not im.has_pose:
            continue
        cam = Intrinsics.from_pycolmap(rec.cameras[im.camera_id])
        rot = np.asarray(im.cam_from_world().rotation.matrix(), dtype=float)
        keep = horizon_keep(cam, rot, up, margin_deg)
        if keep.all():
            continue
        base = find_mask(masks_dir, im.name)
        if base:
            keep &= read_keep(base, cam.width, cam.height)
        path = os.path.join(masks_dir, mask_file_name(im.name))
        write_keep(path, keep)
        res.masks[im.name] = path
        res.sky_fraction[im.name] = round(1.0 - float(keep.mean()), 4)
    return res
