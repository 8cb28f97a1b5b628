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
  edge cannot reach without crossing the sky).  The sky stops at the horizon: its lower edge must follow one
  smooth line (a straight horizon bent by the lens, fitted robustly) within ``horizon_tolerance`` of the height
  over ``min_horizon_cover`` of the width, and the mask is cut there; a region whose lower edge follows no such
  line is no sky (a pale or over-exposed band over the top of a vertical photo, whose lower edge is ragged, and
  a road running down from it).  Where the photo records its camera's pitch (a drone's XMP) the mask stops where
  the geometry puts the horizon too, and a camera looking down too steeply to see it gets none.  The result is
  widened by ``SkyOptions.margin`` of the image height downwards to take the horizon's mixed pixels.  A region
  under ``min_fraction`` of the image is no sky (a pale roof at the upper edge of a vertical photo).
- :func:`write_sky_masks` writes those masks through the mask machinery of :mod:`core.prepare.masks`
  (``masks/<image>.png``, white = use, merged with a mask the image already has): the alignment's feature
  extraction then ignores the sky (COLMAP's ``mask_path``), as it ignores a scan's film border; the log says, per
  photo, how much the mask took ("sky mask: IMG_1.jpg: 12.3 % of the photo (rows 0–214)").
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
from itertools import combinations
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, check_cancel
from ..geometry.camera import Intrinsics
from ..io.images import (
    ORIENTATION_STEPS,
    exif_orientation,
    full_scale,
    image_size,
    read_image,
    read_image_info,
    to_upright,
    upright_size,
    xmp_camera_pitch,
)
from .masks import find_mask, mask_file_name, read_keep, write_keep
from .options import SkyOptions

__all__ = ["SkyResult", "detect_sky", "estimate_up", "horizon_keep", "horizon_row_of_pitch", "masked_rows",
           "sky_keep", "write_horizon_masks", "write_sky_masks"]


WIDEST_FOCAL_FACTOR = 0.5  # focal length / long side of the widest usual lens (about 90 degrees across)


@dataclass
class SkyResult:
    masks: Dict[str, str] = field(default_factory=dict)  # image -> mask file written
    sky_fraction: Dict[str, float] = field(default_factory=dict)  # image -> share of its pixels hidden as sky
    sky_rows: Dict[str, Tuple[int, int]] = field(default_factory=dict)  # image -> first, last row of its sky (upright)
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


def _sky_region(small: np.ndarray, options: SkyOptions) -> np.ndarray:
    """The sky candidates of an upright analysis-size image: the smooth, bright, bluish or pale regions touching
    the upper edge, spanning ``min_top_cover`` of it, never reaching the lower edge, down to the ground in their
    columns, with their holes (clouds, a bird: what the lower edge cannot reach without crossing them) filled.
    All False when there are none.  Not yet limited to a horizon (:func:`_horizon_line`)."""
    cv2 = require("cv2", "sky masks")
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
        return np.zeros(cand.shape, bool)
    sky |= _down_to_the_ground(cand > 0, sky[:band].any(axis=0))
    ground = (~sky).astype(np.uint8)
    n, labels = cv2.connectedComponents(ground, connectivity=4)
    edge = np.unique(labels[-1])
    return ~np.isin(labels, edge[edge > 0])


def _horizon_line(sky: np.ndarray, tol: float, min_cover: float) -> Optional[np.ndarray]:
    """The horizon under a sky region (rows, cols): per column, the row (float, may be < 0 where it leaves
    through the upper edge) of one smooth curve (a parabola: a straight horizon bent by the lens) that the lower
    edge of the sky follows within ``tol`` rows over at least ``min_cover`` of the width; None when it follows
    none (a pale band over a field, a road running down the photo: their lower edge is ragged or deep in a few
    columns).  Columns above the curve (a tree or a roof on the skyline) are allowed, as are columns below it
    (haze, a pale field beyond the horizon): the caller stops the sky at the curve."""
    h, w = sky.shape
    ground = ~sky
    low = np.where(ground.any(axis=0), ground.argmax(axis=0), h).astype(float)  # first ground row per column
    x = (np.arange(w) + 0.5) / w - 0.5
    basis = np.vander(x, 3)
    # RANSAC over every triple of 32 columns spread over the width (4960 candidates, deterministic)
    idx = np.unique(np.linspace(0, w - 1, min(32, w)).round().astype(int))
    if len(idx) < 3:
        return None
    triples = np.array(list(combinations(idx, 3)))
    a, b = basis[triples], low[triples]
    ok = np.abs(np.linalg.det(a)) > 1e-12
    coef = np.linalg.solve(a[ok], b[ok][..., None])[..., 0]
    coef = coef[np.abs(coef[:, 0]) <= 0.3 * h]  # a lens bends a horizon by a few % of the height, not more

    def inliers(c: np.ndarray) -> np.ndarray:
        fit = basis @ c.T  # (w, k)
        return (np.abs(low[:, None] - fit) <= tol) & ((low[:, None] > 0) | (fit < 0))

    if not len(coef):
        return None
    best = coef[int(np.argmax(inliers(coef).sum(axis=0)))]
    inl = inliers(best[None])[:, 0]
    if inl.sum() >= 3:  # least squares on the inliers of the best candidate
        best = np.linalg.lstsq(basis[inl], low[inl], rcond=None)[0]
        inl = inliers(best[None])[:, 0]
    if inl.mean() < min_cover:
        return None
    return basis @ best


NO_HORIZON = "a smooth bright region along the upper edge, but its lower edge follows no horizon line across the " \
    "photo (a pale or over-exposed band, haze, a hilly skyline): not masked"


def sky_keep(img: np.ndarray, options: Optional[SkyOptions] = None, orientation: int = 1,
             horizon_row: Optional[float] = None) -> np.ndarray:
    """(height, width) bool of an image array (rows, cols[, bands]): True = use, False = sky (see
    :func:`_sky_verdict`)."""
    return _sky_verdict(img, options, orientation, horizon_row)[0]


def _sky_verdict(img: np.ndarray, options: Optional[SkyOptions] = None, orientation: int = 1,
                 horizon_row: Optional[float] = None) -> Tuple[np.ndarray, str]:
    """((height, width) bool of an image array (rows, cols[, bands]): True = use, False = sky; why a sky-like
    region was not masked, "" when it was or there was none).

    ``orientation``: the photo's EXIF orientation (the sky is searched at the upper edge of the upright photo).
    The sky stops at the horizon: the smooth line its lower edge follows across the photo; a bright smooth region
    at the upper edge whose lower edge follows no such line (a pale or over-exposed band over a field, a road
    running down a vertical photo) is no sky.  ``horizon_row``: where the camera's geometry puts the horizon
    (a row of the upright photo at this size, :func:`horizon_row_of_pitch`; -inf: out of view), when known: no
    mask reaches more than ``SkyOptions.horizon_tolerance`` below it."""
    cv2 = require("cv2", "sky masks")
    options = options or SkyOptions()
    img = img if img.ndim == 3 else img[:, :, None]
    height, width = img.shape[:2]
    up = to_upright(img, orientation)
    uh, uw = up.shape[:2]
    if horizon_row is not None and horizon_row + options.horizon_tolerance * uh < 0:
        return np.ones((height, width), bool), ""  # the camera cannot see the horizon (a vertical photo)
    s = min(1.0, options.analysis_size / float(max(uh, uw)))
    small = up if s >= 1.0 else cv2.resize(up, (max(1, round(uw * s)), max(1, round(uh * s))),
                                           interpolation=cv2.INTER_AREA)
    small = small if small.ndim == 3 else small[:, :, None]
    sky = _sky_region(small, options)
    if sky.mean() < options.min_fraction:
        return np.ones((height, width), bool), ""
    sh = sky.shape[0]
    tol = max(2.0, options.horizon_tolerance * sh)
    line = _horizon_line(sky, tol, options.min_horizon_cover)
    if line is None:
        return np.ones((height, width), bool), NO_HORIZON
    if horizon_row is not None:
        line = np.minimum(line, horizon_row * sh / uh)
    sky &= np.arange(sh)[:, None] < (line + tol)[None, :]
    if sky.mean() < options.min_fraction:
        return np.ones((height, width), bool), ""
    m = max(1, int(round(options.margin * sh)))
    sky = cv2.dilate(sky.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * m + 1, 2 * m + 1))) > 0
    full = cv2.resize(sky.astype(np.uint8), (uw, uh), interpolation=cv2.INTER_NEAREST) > 0
    return ~_from_upright(full, orientation).reshape(height, width), ""


def horizon_row_of_pitch(pitch_deg: float, focal_px: float, height: int, below_deg: float = 0.0) -> float:
    """The row of the upright photo (``height`` rows, principal point at its centre) where a camera pitched
    ``pitch_deg`` above the horizontal (-90: straight down) sees the directions ``below_deg`` under the horizon;
    -inf when they lie beyond the upper edge's side of the view (a vertical photo sees no horizon)."""
    above_axis = -float(below_deg) - float(pitch_deg)  # degrees above the optical axis
    if above_axis >= 89.9:
        return -math.inf
    if above_axis <= -89.9:
        return math.inf
    return height / 2.0 - focal_px * math.tan(math.radians(above_axis))


def _geometry_horizon(path: str, orientation: int, options: SkyOptions) -> Tuple[Optional[float], Optional[float]]:
    """(the row of the upright photo below which no sky can be (``pitch_slack_deg`` under the horizon: the gimbal's
    accuracy, a small roll), the camera's pitch), both None when the pitch is unknown.  The pitch from the drone's XMP
    (:func:`core.io.images.xmp_camera_pitch`), the focal length from EXIF (without one, the widest usual lens)."""
    pitch = xmp_camera_pitch(path)
    if pitch is None:
        return None, None
    info = read_image_info(path)
    _, uh = upright_size(orientation, info.width, info.height)
    # without a focal length in EXIF, the widest usual lens (the horizon comes into view soonest)
    focal = float(info.focal_px) if info.focal_px and info.focal_source != "default" else \
        WIDEST_FOCAL_FACTOR * max(info.width, info.height)
    return horizon_row_of_pitch(pitch, focal, uh, options.pitch_slack_deg), pitch


def detect_sky(path: str, options: Optional[SkyOptions] = None) -> np.ndarray:
    """The sky detector on one photo file: (height, width) bool in the stored pixel grid, True = use.  Where the
    photo records its camera's pitch (a drone's XMP) the sky stops where the geometry puts the horizon, and a
    camera looking down too steeply to see it gets no mask."""
    return _detect(path, options or SkyOptions())[0]


def _detect(path: str, options: SkyOptions) -> Tuple[np.ndarray, str]:
    """:func:`detect_sky` and why a sky-like region was not masked ("" when it was, or there was none)."""
    orientation = exif_orientation(path)
    width, height = image_size(path)
    row, pitch = _geometry_horizon(path, orientation, options)
    img = read_image(path, max(2 * options.analysis_size, 64))
    if row is not None:
        _, uh = upright_size(orientation, width, height)
        _, ih = upright_size(orientation, img.shape[1], img.shape[0])
        row = row * ih / uh
    keep, note = _sky_verdict(img, options, orientation, horizon_row=row)
    if note and pitch is not None:
        note = f"{note} (camera pitch {pitch:+.1f} deg in the photo's XMP)"
    if keep.shape != (height, width):
        cv2 = require("cv2", "sky masks")
        keep = cv2.resize(keep.astype(np.uint8), (width, height), interpolation=cv2.INTER_NEAREST) > 0
    return keep, note


def masked_rows(keep: np.ndarray, orientation: int = 1) -> Tuple[int, int]:
    """(first, last) row of the upright photo holding a masked pixel of ``keep`` (stored grid); (-1, -1): none."""
    rows = np.flatnonzero((~to_upright(keep, orientation)).any(axis=1))
    return (int(rows[0]), int(rows[-1])) if len(rows) else (-1, -1)


def write_sky_masks(images_dir: str, names: Sequence[str], out_dir: str, options: Optional[SkyOptions] = None,
                    base_masks: Optional[Mapping[str, Optional[str]]] = None,
                    progress: Optional[Progress] = None) -> SkyResult:
    """Detect the sky in every image of ``names`` and write ``<out_dir>/<image>.png`` for those that show some,
    merged (logical AND of the areas to use) with ``base_masks[name]`` or, without one, the mask
    :func:`core.prepare.masks.find_mask` finds in ``out_dir``.  Images without sky get no new mask.  Logs, per
    masked image, the share of the photo the sky took and its rows (of the upright photo), and why an image whose
    upper edge looked like sky got none."""
    options = options or SkyOptions()
    progress = progress or NullProgress()
    base_masks = dict(base_masks or {})
    res = SkyResult()
    os.makedirs(out_dir, exist_ok=True)
    for i, n in enumerate(names):
        check_cancel(progress)
        path = os.path.join(images_dir, n)
        keep, note = _detect(path, options)
        progress.report((i + 1) / max(1, len(names)), f"sky: {n}")
        if keep.all():
            if note:
                progress.info(f"sky mask: {n}: none, {note}")
            continue
        fraction = 1.0 - float(keep.mean())
        first, last = masked_rows(keep, exif_orientation(path))
        res.sky_rows[n] = (first, last)
        progress.info(f"sky mask: {n}: {100.0 * fraction:.1f} % of the photo (rows {first}\u2013{last})")
        base = base_masks.get(n) or find_mask(out_dir, n)
        if base:
            keep &= read_keep(base, keep.shape[1], keep.shape[0])
        out = os.path.join(out_dir, mask_file_name(n))
        write_keep(out, keep)
        res.masks[n] = out
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
