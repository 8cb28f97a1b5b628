"""Fusion per image, the unit of work after matching: the depth maps an image received from its pairs ->
coloured points.

The depth maps are compared pixel by pixel; a pixel is kept where at least ``min_consistent`` independent
pairs agree within a tolerance (about one disparity pixel of the weakest pair, relative to depth), its depth is
the mean of the agreeing ones, and it is back-projected with the camera model and coloured from the image.

Where only one of the image's pairs covers the ground (:func:`pair_cover`: the hull of what that pair matched;
ground that two photos alone see, as along a strip flown at 60 % forward overlap, or a pair chosen for a part of
the frame no other pair reaches) no second pair can confirm a pixel: there the one pair's depth is kept where it
matched densely around the pixel, and so it is where the other pairs matched nothing and it lies near the depths
two pairs confirmed around it (:func:`sole_pair_depth`; issue 46: 17 % of seneca_south's hull was such ground
and all of it was interpolated); under the block only (the camera centres' hull).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

from ..common.errors import require
from ..common.files import save_npz
from ..common.parallel import check_unit_cancel
from ..io.images import stretch8
from ..prepare.masks import read_keep
from ..prepare.sky import horizon_keep
from .options import DenseError
from .pairs import View, load_scaled
from .stereo import read_depth


@dataclass
class FuseUnit:
    view: View
    scale: float
    maps: List[Tuple[str, str, float]]  # (pair file, role 'i' or 'j', relative depth error per px)
    tolerance_px: float
    min_consistent: int
    out_path: str
    threads: int
    sky_margin_deg: Optional[float] = None  # drop pixels less than this far below the horizon (None: keep)
    sole_pair: bool = True  # keep one pair's depth where no other pair of the image covers the ground ...
    sole_region: Optional[np.ndarray] = None  # ... inside this convex polygon (local x, y; counter-clockwise): the
    # camera centres' hull, under the block; beyond it (the block's edge, frame borders) two pairs must agree


def sky_free(view: View, depth: np.ndarray, sky_margin_deg: Optional[float]) -> np.ndarray:
    """``depth`` (an image's map at any scale) without the pixels of the sky: those less than ``sky_margin_deg``
    below the horizon of the pose (the georeferenced frame's z is up; core.prepare.sky.horizon_keep) and the black
    pixels of the image's mask."""
    cv2 = require("cv2", "depth fusion")
    out = depth.copy()
    if sky_margin_deg is not None and not _all_below_horizon(view, sky_margin_deg):
        out[~horizon_keep(view.camera, view.R, (0.0, 0.0, 1.0), sky_margin_deg, shape=depth.shape)] = np.nan
    if view.mask_path:
        keep = read_keep(view.mask_path, view.width, view.height).astype(np.uint8)
        keep = cv2.resize(keep, (depth.shape[1], depth.shape[0]), interpolation=cv2.INTER_NEAREST) > 0
        out[~keep] = np.nan
    return out


HORIZON_PROBE_PX = 64  # the quick test of a whole image below the horizon samples its rays this far apart


def _all_below_horizon(view: View, margin_deg: float) -> bool:
    """True when every pixel of ``view`` looks more than ``margin_deg`` below the horizon (a vertical photo: no
    full-size horizon mask needed), judged on rays HORIZON_PROBE_PX apart with that margin raised by three times
    the angle such a step spans (the elevation between two probes cannot climb more)."""
    slack = 3.0 * math.degrees(HORIZON_PROBE_PX / max(1.0, min(view.camera_matrix()[0][[0, 1], [0, 1]])))
    probe = (max(2, view.height // HORIZON_PROBE_PX + 1), max(2, view.width // HORIZON_PROBE_PX + 1))
    return bool(horizon_keep(view.camera, view.R, (0.0, 0.0, 1.0), margin_deg + slack, shape=probe,
                             step=HORIZON_PROBE_PX).all())


def fuse_depth_maps(maps: np.ndarray, rel_tol: np.ndarray, min_consistent: int) -> Tuple[np.ndarray, np.ndarray]:
    """Fuse k depth maps (k, h, w) of one image: per pixel the candidate most others agree with
    (|d_l - d_m| <= rel_tol * d_m); kept where at least ``min_consistent`` maps agree; value = their mean.
    Returns (depth with NaN, number of agreeing maps)."""
    k = maps.shape[0]
    maps = np.asarray(maps, dtype=np.float32)
    shape = maps.shape[1:]
    best_n = np.zeros(shape, dtype=np.int16)
    best_v = np.full(shape, np.nan, dtype=np.float32)
    tol_l = [np.float32(t) for t in np.asarray(rel_tol, dtype=np.float64)]
    diff = np.empty(shape, np.float32)
    lim = np.empty(shape, np.float32)
    a = np.empty(shape, bool)
    agree = np.empty(shape, np.int16)
    total = np.empty(shape, np.float32)
    better = np.empty(shape, bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        for m in range(k):
            ref = maps[m]
            agree.fill(0)
            total.fill(0.0)
            for ll in range(k):  # all in place: float32, no temporaries (the maps are float32 anyway)
                np.subtract(maps[ll], ref, out=diff)
                np.abs(diff, out=diff)
                np.multiply(ref, max(tol_l[m], tol_l[ll]), out=lim)
                np.less_equal(diff, lim, out=a)
                agree += a
                np.add(total, maps[ll], out=total, where=a)
            np.greater(agree, best_n, out=better)
            np.copyto(best_n, agree, where=better)
            np.divide(total, agree, out=best_v, where=better)
    keep = best_n >= max(1, min_consistent)
    return np.where(keep, best_v, np.nan).astype(np.float32), best_n


COVER_STEP = 8  # a pair's cover is found on a grid of this many pixels (its hull is coarse anyway)
COVER_SOLID = 0.25  # ... of cells at least this share matched (a streak of lone matches makes no cover)
SOLE_WINDOW_SHARE = 1.0 / 64  # a sole pair's pixel needs SOLE_DENSITY of its window (this share of the image's
SOLE_DENSITY = 0.5  # short side) matched: the edge of a pair's overlap and its stray matches are not kept
# where other pairs cover a pixel but none of them matched it, one pair's depth is kept if it lies this many of its
# disparities from the mean of the depths two pairs confirmed in a window of SUPPORT_WINDOW_SHARE of the short side
# (SUPPORT_SHARE of that window confirmed)
UNOPPOSED_TOLERANCE_PX = 3.0
SUPPORT_WINDOW_SHARE = 1.0 / 32
SUPPORT_SHARE = 0.2


def pair_cover(depth: np.ndarray) -> np.ndarray:
    """Where a pair's depth map (NaN = none) covers its image: the convex hull of its densely matched cells
    (COVER_STEP pixels, COVER_SOLID of them matched), the ground its two photos both see as far as the matching
    shows; a map with no such cell covers nothing."""
    cv2 = require("cv2", "depth fusion")
    h, w = depth.shape
    hs, ws = -(-h // COVER_STEP), -(-w // COVER_STEP)
    valid = np.zeros((hs * COVER_STEP, ws * COVER_STEP), np.float32)
    valid[:h, :w] = np.isfinite(depth)
    cells = valid.reshape(hs, COVER_STEP, ws, COVER_STEP).mean(axis=(1, 3)) >= COVER_SOLID
    pts = np.argwhere(cells)[:, ::-1].astype(np.int32)
    cover = np.zeros((hs, ws), np.uint8)
    if len(pts) >= 3:
        cv2.fillConvexPoly(cover, cv2.convexHull(pts), 1)
    else:
        cover[cells] = 1
    return np.repeat(np.repeat(cover, COVER_STEP, axis=0), COVER_STEP, axis=1)[:h, :w] > 0


def sole_pair_depth(maps: np.ndarray, confirmed: np.ndarray, rel_err: np.ndarray) -> np.ndarray:
    """Per pixel the depth of the one map that holds one where no other map does, where that map matched SOLE_DENSITY
    of a window of SOLE_WINDOW_SHARE of the image's short side around it, and where either its pair alone covers the
    pixel (:func:`pair_cover`: no second pair could confirm it) or the depth lies within UNOPPOSED_TOLERANCE_PX
    disparities of that pair (``rel_err``: its relative depth error per disparity) of the depths two pairs confirmed
    around it (``confirmed``, NaN = none; their mean over a window of SUPPORT_WINDOW_SHARE of the short side, where
    SUPPORT_SHARE of it is confirmed): a periodic texture's wrong minimum lies a period away and is not kept.  NaN
    elsewhere (no map, two or more that hold a depth: there they must agree)."""
    cv2 = require("cv2", "depth fusion")
    k, h, w = maps.shape
    win = max(5, int(round(min(h, w) * SOLE_WINDOW_SHARE)) | 1)
    covers = np.stack([pair_cover(m) for m in maps])
    n_cover = covers.sum(axis=0)
    finite = np.isfinite(maps)
    unopposed = finite.sum(axis=0) == 1
    have = np.isfinite(confirmed)
    swin = max(5, int(round(min(h, w) * SUPPORT_WINDOW_SHARE)) | 1)
    share = cv2.blur(have.astype(np.float32), (swin, swin))
    local = cv2.blur(np.where(have, confirmed, 0.0).astype(np.float32), (swin, swin)) / np.maximum(share, 1e-6)
    supported = share >= SUPPORT_SHARE
    out = np.full((h, w), np.nan, np.float32)
    for m in range(k):
        cand = unopposed & finite[m]
        if not cand.any():
            continue
        dense = cv2.blur(finite[m].astype(np.float32), (win, win)) >= SOLE_DENSITY
        with np.errstate(invalid="ignore"):
            near = supported & (np.abs(maps[m] - local) <= UNOPPOSED_TOLERANCE_PX * float(rel_err[m]) * maps[m])
        take = cand & dense & ((covers[m] & (n_cover == 1)) | near)
        out[take] = maps[m][take]
    return out


def inside_convex(xy: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Which points ``xy`` (N, 2) lie inside the convex ``polygon`` (counter-clockwise vertices); a polygon of fewer
    than 3 vertices holds none."""
    poly = np.asarray(polygon, dtype=np.float64)
    if len(poly) < 3:
        return np.zeros(len(xy), bool)
    inside = np.ones(len(xy), bool)
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        inside &= (b[0] - a[0]) * (xy[:, 1] - a[1]) - (b[1] - a[1]) * (xy[:, 0] - a[0]) >= 0
    return inside


def backproject(view: View, k: np.ndarray, dist: np.ndarray, depth: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Local-frame points of the valid pixels of a depth map (z along the optical axis) and their (rows, cols)."""
    cv2 = require("cv2", "depth fusion")
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
    cv2 = require("cv2", "depth fusion")
    cv2.setNumThreads(max(1, unit.threads))
    check_unit_cancel(cancel_path)
    maps, errs = [], []
    for path, role, rel_err in unit.maps:
        m = read_depth(path, role)
        if m.size:
            maps.append(m)
            errs.append(rel_err)
    out = {"image": unit.view.name, "points": 0, "path": unit.out_path, "bbox": None}
    if len(maps) < (1 if unit.sole_pair else unit.min_consistent):
        out["note"] = f"{len(maps)} usable pair(s), {unit.min_consistent} needed"
        return out
    shapes = {m.shape for m in maps}
    if len(shapes) != 1:
        raise DenseError(f"depth maps of {unit.view.name} differ in size: {shapes}")
    stack = np.stack(maps)
    rel_tol = np.clip(unit.tolerance_px * np.asarray(errs, dtype=np.float64), 0.002, 0.05)
    fused, _n = fuse_depth_maps(stack, rel_tol, unit.min_consistent)
    if unit.sole_pair:
        sole = sole_pair_depth(stack, fused, np.asarray(errs, dtype=np.float64))
        take = ~np.isfinite(fused) & np.isfinite(sole)
        if unit.sole_region is not None and take.any():
            k0, dist0 = unit.view.camera_matrix(fused.shape[1] / unit.view.width, fused.shape[0] / unit.view.height)
            xyz, (rows, cols) = backproject(unit.view, k0, dist0, np.where(take, sole, np.nan))
            out_of = ~inside_convex(xyz[:, :2], unit.sole_region)
            take[rows[out_of], cols[out_of]] = False
            del xyz, rows, cols, out_of
        fused[take] = sole[take]
        out["sole_pair_pixels"] = int(take.sum())
        del sole, take
    del stack, maps
    if unit.sky_margin_deg is not None or unit.view.mask_path:
        fused = sky_free(unit.view, fused, unit.sky_margin_deg)
    check_unit_cancel(cancel_path)
    img, sx, sy = load_scaled(unit.view, unit.scale)
    k, dist = unit.view.camera_matrix(sx, sy)
    xyz, (rows, cols) = backproject(unit.view, k, dist, fused)
    rgb = _to_rgb8(img)[rows, cols]
    if len(xyz):
        lo = np.percentile(xyz[:, :2], 0.5, axis=0)
        hi = np.percentile(xyz[:, :2], 99.5, axis=0)
        out["bbox"] = [float(v) for v in (*xyz[:, 0:2].min(axis=0), *xyz[:, 0:2].max(axis=0))]
        out["robust_bbox"] = [float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])]
    save_npz(unit.out_path, xyz=xyz.astype(np.float32), rgb=rgb.astype(np.uint8))
    out["points"] = int(len(xyz))
    return out


def _to_rgb8(img: np.ndarray) -> np.ndarray:
    if img.shape[2] >= 3:
        rgb = img[:, :, :3]
    else:
        rgb = np.repeat(img[:, :, :1], 3, axis=2)
    if rgb.dtype != np.uint8:
        return stretch8(rgb)  # 16-bit, float (its NaN no data left out of the stretch)
    return np.ascontiguousarray(rgb)
