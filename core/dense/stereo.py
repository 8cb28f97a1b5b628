"""One stereo pair, the unit of work of dense matching: rectify, semi-global matching, left-right check,
triangulation -> two depth maps.

Both images are read at the QUALITY downscale, lens distortion removed and the pair rectified in one remap from
the known poses (both cameras turned to a common orientation whose x axis is the baseline, so the epipolar lines
are rows); the disparity range comes from the shared sparse points (0.5-99.5 % plus a margin); OpenCV
semi-global matching (StereoSGBM, Hirschmüller 2008) runs coarse to fine: the pair halved until that range is
about 64 disparities wide, matched there over all of it (left->right and right->left, left-right check), and each
finer level piece by piece over the disparities its coarser level found there (so the search does not grow with
the resolution), checked and completed by it; a match is triangulated and written into two depth maps, one on
each image's own (distorted, downscaled) pixel grid, saved as one ``.npz`` per pair (the cache a re-run reuses).
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ..common.errors import require
from ..common.files import save_npz
from ..common.parallel import check_unit_cancel
from ..io.images import matching_grey8
from .options import DenseError
from .pairs import View, load_scaled


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
    coarse: bool = True  # coarse to fine (a pyramid, see _disparity); False: one matching over the whole range
    fine_uniqueness: int = 3  # SGBM's uniqueness ratio on the finer levels (DenseOptions.fine_uniqueness)
    equalize: bool = True  # local contrast equalisation of the rectified pair (:func:`equalized`)
    flat_block: int = 0  # SGBM's block away from the coarser level's depth edges and at the coarsest level (0: block_size)


CLAHE_TILE_PX = 80  # equalisation tiles of about this side (the matching scale's pixels)
CLAHE_CLIP = 2.0  # OpenCV's clip limit: contrast raised at most about this much where the texture is faint


def equalized(img: np.ndarray) -> np.ndarray:
    """``img`` (uint8, a rectified image) with its local contrast equalised (CLAHE, tiles of CLAHE_TILE_PX):
    the faint texture of bare soil and crops (a grey level or two) gets a cost that SGBM's smoothness penalties
    (fixed multiples of the block) no longer flatten; strong texture is limited by the clip.  Measured on
    tests/lowtexture_scene.py's fields at 0.12 of their contrast: 77.8 -> 83.0 % of the DSM measured, the RMSE
    of the measured fields halved."""
    cv2 = require("cv2", "dense matching")
    h, w = img.shape[:2]
    grid = (max(1, int(round(w / CLAHE_TILE_PX))), max(1, int(round(h / CLAHE_TILE_PX))))
    return cv2.createCLAHE(clipLimit=CLAHE_CLIP, tileGridSize=grid).apply(np.ascontiguousarray(img))


def _to_gray8(img: np.ndarray) -> np.ndarray:
    cv2 = require("cv2", "dense matching")
    if img.shape[2] >= 3 and img.dtype == np.uint8:
        return np.ascontiguousarray(cv2.cvtColor(np.ascontiguousarray(img[:, :, :3]), cv2.COLOR_RGB2GRAY))
    return matching_grey8(img)  # 16-bit, float (NaN-safe): stretched from the 0.5 to the 99.5 percentile


def _rect_bounds(k: np.ndarray, dist: np.ndarray, rot: np.ndarray, f: float, w: int, h: int) -> np.ndarray:
    """x/y bounds (xmin, xmax, ymin, ymax) of an image's border after undistortion and rotation ``rot``
    (old camera -> rectified camera), projected with focal ``f`` and no principal point."""
    cv2 = require("cv2", "dense matching")
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


@dataclass
class ScaledCamera:
    """A view as read for matching: its OpenCV camera matrix and distortion at the QUALITY downscale and the
    image's (width, height)."""

    view: View
    k: np.ndarray
    dist: np.ndarray
    size: Tuple[int, int]


def rectify_pair(ci: ScaledCamera, cj: ScaledCamera, max_growth: float = 3.0) -> Rectification:
    """Rectify two calibrated views (Fusiello-style, from the known poses) into row-aligned images.

    Both rectified cameras share the rotation ``rn`` (x axis = the baseline from i to j) and focal f,
    so a point's disparity is d = x_i - x_j = f B / Z + cx_i - cx_j > 0."""
    cv2 = require("cv2", "dense matching")
    vi, vj, ki, di, kj, dj, size_i, size_j = ci.view, cj.view, ci.k, ci.dist, cj.k, cj.dist, ci.size, cj.size
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


def _sgbm(block: int, dmin: int, num: int, uniqueness: int, disp12: int = -1):
    cv2 = require("cv2", "dense matching")
    return cv2.StereoSGBM_create(minDisparity=dmin, numDisparities=num, blockSize=block,
                                 P1=8 * block * block, P2=32 * block * block, disp12MaxDiff=disp12,
                                 preFilterCap=63, uniquenessRatio=uniqueness, speckleWindowSize=100,
                                 speckleRange=2, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY)


def _sample_rows(arr: np.ndarray, rows: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Linear interpolation of arr[rows, xs] along x (xs float, inside [0, width - 1])."""
    w = arr.shape[1]
    x0 = np.minimum(xs.astype(np.int64), w - 2)  # xs >= 0: truncation is the floor
    t = (xs - x0).astype(np.float32)
    flat = arr.reshape(-1)
    idx = rows.astype(np.int64) * w + x0
    a = flat[idx]
    idx += 1
    return a + t * (flat[idx] - a)


def _zbuffer(shape: Tuple[int, int], px: np.ndarray, py: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """The nearest depth per pixel of ``shape`` (NaN where none): written in any order, then rewritten where a
    point is nearer than what its pixel holds until none is (a few rounds: few points share a pixel); no sort."""
    c = np.round(px).astype(np.int64)
    r = np.round(py).astype(np.int64)
    ok = (c >= 0) & (c < shape[1]) & (r >= 0) & (r < shape[0]) & (depth > 0)
    lin = r[ok] * shape[1] + c[ok]
    d = depth[ok].astype(np.float32)
    flat = np.full(shape[0] * shape[1], np.inf, dtype=np.float32)
    while len(lin):
        flat[lin] = d
        nearer = d < flat[lin]
        lin, d = lin[nearer], d[nearer]
    flat[np.isinf(flat)] = np.nan
    return flat.reshape(shape)


def _match_lr(left: np.ndarray, right: np.ndarray, block: int, dmin: int, num: int, uniqueness: int,
              cancel_path: Optional[str] = None) -> Tuple[np.ndarray, np.ndarray]:
    """SGBM both ways on two row-aligned images of one size: (disparity indexed by the left image's x, disparity
    indexed by the right image's x), float32 pixels, NaN where SGBM found none."""
    cv2 = require("cv2", "dense matching")
    w = left.shape[1]
    # pad both sides so SGBM's invalid bands (the first maxD columns, and the last |minD|) hold no image
    pad = int(max(abs(dmin), abs(dmin + num))) + 1
    lp = cv2.copyMakeBorder(left, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    rp = cv2.copyMakeBorder(right, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    sgbm = _sgbm(block, dmin, num, uniqueness)
    check_unit_cancel(cancel_path)
    disp_l = (sgbm.compute(lp, rp).astype(np.float32) / 16.0)[:, pad:pad + w]
    check_unit_cancel(cancel_path)
    disp_r = sgbm.compute(np.ascontiguousarray(rp[:, ::-1]), np.ascontiguousarray(lp[:, ::-1]))
    disp_r = (disp_r.astype(np.float32) / 16.0)[:, ::-1][:, pad:pad + w]
    # SGBM's invalid value (below dmin) and a minimum at either end of the range (the true one lies beyond it:
    # ground the other photo does not see, matched to whatever lies at the range's end)
    with np.errstate(invalid="ignore"):
        for d in (disp_l, disp_r):
            d[(d < dmin + WINDOW_END_PX) | (d > dmin + num - 1 - WINDOW_END_PX)] = np.nan
    return np.ascontiguousarray(disp_l), np.ascontiguousarray(disp_r)


def lr_checked(disp_l: np.ndarray, disp_r: np.ndarray, tolerance: float) -> np.ndarray:
    """``disp_l`` where the right image's disparity at the matched pixel agrees within ``tolerance``, else NaN."""
    w = disp_l.shape[1]
    with np.errstate(invalid="ignore"):
        xr = np.round(np.arange(w, dtype=np.float32)[None, :] - disp_l)
        ok = np.isfinite(disp_l) & (xr >= 0) & (xr <= w - 1)
        xri = np.clip(np.nan_to_num(xr), 0, w - 1).astype(np.int64)
        back = np.take_along_axis(disp_r, xri, axis=1)
        ok &= np.abs(back - disp_l) <= tolerance
    return np.where(ok, disp_l, np.nan).astype(np.float32)


WINDOW_END_PX = 1.0  # a disparity this close to either end of its search window is a boundary minimum (issue 46:
# the ground one photo of a pair does not see, beside the overlap, matched at the window's end: streaks of rows)
COARSE_AGREEMENT_PX = 2.0  # a fine disparity this far outside its coarse neighbourhood's range is a blunder
COARSE_FLAT_PX = 3.0  # a fine hole takes the coarse disparity where the coarse neighbourhood spans at most this
# (fine pixels; under EDGE_JUMP_PX: no wall; 2 until issue 33: the coarse level's noise on faint fields exceeded it
# and the fine level, which loses faint texture, kept its holes: farmland 88.2 -> 90.7 % measured, RMSE inside the
# cameras' hull unchanged at 1.5 GSD)


STREAK_ROWS = 5  # matches in runs fewer rows tall than this are dropped (no surface is a one-row streak) ...
STREAK_STEP_PX = 1.0  # ... a run: matches each within this many disparities of the one above or below


def without_streaks(disp: np.ndarray) -> np.ndarray:
    """``disp`` without the matches that no STREAK_ROWS rows of agreeing matches hold (a vertical opening of the
    matches that agree with the one above or below within STREAK_STEP_PX): SGBM aggregates along the rows, and where a pair's ground is not in the other photo (beside the
    overlap, a frame's corner) its wrong matches form streaks a row or two tall (issue 46: seneca_south's streaks
    of heights out of the block)."""
    cv2 = require("cv2", "dense matching")
    with np.errstate(invalid="ignore"):
        link = np.abs(disp[1:] - disp[:-1]) <= STREAK_STEP_PX  # a match and the one below it agree
    valid = np.zeros(disp.shape, np.uint8)
    valid[1:] |= link
    valid[:-1] |= link
    kernel = np.ones((STREAK_ROWS, 1), np.uint8)
    held = cv2.dilate(cv2.erode(valid, kernel), kernel) > 0
    out = disp.copy()
    out[~held] = np.nan
    return out


def coarse_to_fine(fine: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """The fine (left, LR-checked) disparity map completed and checked by a map matched at half the resolution
    (``coarse``, LR-checked, in its own pixels): a fine disparity outside the range of the coarse ones around it
    (3 x 3 coarse pixels, x 2, +- COARSE_AGREEMENT_PX) is dropped (a streak, a wrong minimum on weak texture); a
    fine pixel without a disparity takes the coarse one where the coarse neighbourhood (5 x 5) is smooth (not
    near a roof edge: edges stay the fine matching's)."""
    cv2 = require("cv2", "dense matching")
    h, w = fine.shape
    valid_c = np.isfinite(coarse)
    big = np.float32(1e6)
    lo = cv2.erode(np.where(valid_c, coarse, big).astype(np.float32), np.ones((3, 3), np.uint8))
    hi = cv2.dilate(np.where(valid_c, coarse, -big).astype(np.float32), np.ones((3, 3), np.uint8))
    have = (lo < big / 2) & (hi > -big / 2)
    # coarse pixel c covers fine pixels 2c, 2c + 1 (pyrDown): nearest-neighbour upsampling, disparities x 2
    rows = np.minimum(np.arange(h) // 2, coarse.shape[0] - 1)
    cols = np.minimum(np.arange(w) // 2, coarse.shape[1] - 1)

    def up(a):
        return a[rows][:, cols]

    lo_f, hi_f, have_f = 2.0 * up(lo), 2.0 * up(hi), up(have)
    out = fine.copy()
    with np.errstate(invalid="ignore"):
        blunder = np.isfinite(out) & have_f & ((out < lo_f - COARSE_AGREEMENT_PX) | (out > hi_f + COARSE_AGREEMENT_PX))
    out[blunder] = np.nan
    # the coarse value itself, bilinear (pixel centres: fine x = 2 c + 0.5), where the coarse neighbourhood is smooth
    k5 = np.ones((5, 5), np.uint8)  # wider: no coarse value within 2 coarse pixels of a jump (its blurred edge)
    lo5 = cv2.erode(np.where(valid_c, coarse, big).astype(np.float32), k5)
    hi5 = cv2.dilate(np.where(valid_c, coarse, -big).astype(np.float32), k5)
    all_valid = cv2.erode(valid_c.astype(np.uint8), k5) > 0  # and no coarse hole there (an edge's occlusion)
    smooth = up(all_valid & (hi5 - lo5 <= COARSE_FLAT_PX / 2.0))
    val = 2.0 * cv2.resize(np.nan_to_num(coarse).astype(np.float32), (w, h), interpolation=cv2.INTER_LINEAR)
    take = ~np.isfinite(out) & smooth
    out[take] = val[take]
    return out


PYRAMID_MAX_DISPARITIES = 64  # the coarsest level searches the whole range; go down until it is about this wide
PYRAMID_MIN_SIDE = 96  # px: no level smaller than this on its short side
TILE_PX = 384  # the finer levels match tiles of this side, each over the disparities its coarser level found there
TILE_CONTEXT_PX = 24  # rows and columns of context around a tile (SGBM's path aggregation; dropped after)
TILE_RANGE_MARGIN_PX = 3  # disparities searched beyond twice the coarser level's range around the tile
EDGE_JUMP_PX = 3.0  # a disparity step this large between neighbours of the coarser level marks a depth edge
EDGE_JUMP_REL = 0.03  # ... and at least this share of the pair's disparity (3 % of the camera's height: the noise
# of weak texture grows with the disparity, a wall's step too; 1.2 m at 40 m)
EDGE_MIN_PIXELS = 200  # ... on this many coarser pixels around a tile (a wall: its 5 px band along 40 rows; specks less)
TILE_MIN_PRIOR = 16  # coarser disparities a tile's window needs; fewer -> the window grows, then the whole range


@dataclass
class LevelPair:
    """A rectified pair at one pyramid level and its disparity search: the row-aligned images (uint8), the lowest
    disparity and how many are searched, and the principal points' offset cx_i - cx_j at this level."""

    left: np.ndarray
    right: np.ndarray
    dmin: int
    num: int
    shift: float = 0.0


def pyramid_levels(num: int, shape: Tuple[int, int]) -> int:
    """How many times the rectified pair is halved so that its coarsest level searches about
    PYRAMID_MAX_DISPARITIES (at least 1: the half-resolution level also checks and completes the fine one)."""
    k = 1
    while num / 2 ** k > PYRAMID_MAX_DISPARITIES and min(shape) / 2 ** (k + 1) >= PYRAMID_MIN_SIDE and k < 6:
        k += 1
    return k


def _tile_range(prior: np.ndarray, y0: int, y1: int, x0: int, x1: int, dmin: int, num: int) -> Optional[Tuple[int, int]]:
    """(lowest, highest) disparity to search in fine tile [y0:y1, x0:x1] from the coarser level's map ``prior``
    (half the size, half the disparities): twice its range over the tile and its context, +- the margin; the window
    grows where the coarser level has (almost) nothing; None = nothing anywhere near (search the whole range)."""
    ph, pw = prior.shape
    grow = TILE_CONTEXT_PX
    while True:
        win = prior[max(0, (y0 - grow) // 2):min(ph, (y1 + grow) // 2 + 1),
                    max(0, (x0 - grow) // 2):min(pw, (x1 + grow) // 2 + 1)]
        vals = win[np.isfinite(win)]
        if vals.size >= TILE_MIN_PRIOR:
            break
        if win.shape == prior.shape or grow > 4 * TILE_PX:
            return None
        grow *= 2
    lo = max(dmin, int(math.floor(2.0 * float(vals.min()))) - TILE_RANGE_MARGIN_PX)
    hi = min(dmin + num - 1, int(math.ceil(2.0 * float(vals.max()))) + TILE_RANGE_MARGIN_PX)
    if hi <= lo:
        return None
    return lo, hi


def _runs(cells: list, ctx: int, height: int) -> list:
    """Split one band's cells (None = nothing to match, else (x0, x1, lo, hi, two_way)) into runs matched by one
    SGBM call each, at the least estimated cost: a run costs (width + context + its disparities, twice for two
    passes) x its rows x its disparities; joining cells widens the search, splitting repeats the margins."""
    n = len(cells)

    def cost(i, j):  # cells i..j-1 as one run; None if it holds nothing
        live = [c for c in cells[i:j] if c is not None]
        if not live:
            return 0.0, None
        lo, hi = min(c[2] for c in live), max(c[3] for c in live)
        tw = any(c[4] for c in live)
        tn = int(16 * math.ceil((hi - lo + 1) / 16.0))
        width = live[-1][1] - live[0][0]
        ways = 2 if tw else 1
        return ways * (width + 2 * ctx + ways * tn) * (height + 2 * ctx) * tn, (live[0][0], live[-1][1], lo, hi, tw)

    best = [0.0] + [math.inf] * n
    back = [0] * (n + 1)
    for j in range(1, n + 1):
        for i in range(j - 1, -1, -1):
            c, _ = cost(i, j)
            if best[i] + c < best[j]:
                best[j], back[j] = best[i] + c, i
    runs, j = [], n
    while j > 0:
        i = back[j]
        run = cost(i, j)[1]
        if run is not None:
            runs.append(run)
        j = i
    return runs[::-1]


def edge_mask(prior: np.ndarray, shift: float = 0.0) -> np.ndarray:
    """The coarser level's depth edges: pixels whose 5 x 5 disparity range (across an occlusion's hole too) exceeds
    EDGE_JUMP_PX / 2 (the coarser level's pixels) and EDGE_JUMP_REL of the median geometric disparity (the prior
    less ``shift`` / 2, the finer level's cx_i - cx_j at this level)."""
    cv2 = require("cv2", "dense matching")
    valid = np.isfinite(prior)
    k5 = np.ones((5, 5), np.uint8)
    big = np.float32(1e6)
    lo5 = cv2.erode(np.where(valid, prior, big).astype(np.float32), k5)
    hi5 = cv2.dilate(np.where(valid, prior, -big).astype(np.float32), k5)
    geo = prior[valid] - shift / 2.0
    jump = max(EDGE_JUMP_PX / 2.0, EDGE_JUMP_REL * float(np.median(geo))) if geo.size else EDGE_JUMP_PX / 2.0
    return (lo5 < big / 2) & (hi5 - lo5 > jump)


def _match_tiled(level: LevelPair, prior: np.ndarray, unit: "PairUnit", cancel_path: Optional[str],
                 edges_two_way: bool = False) -> Tuple[np.ndarray, dict]:
    """Left-right checked disparity of a rectified pair matched piece by piece, each piece over the disparities the
    coarser level (``prior``) found around it: the search no longer grows with the resolution.

    The pair is cut into bands of TILE_PX rows and each band into cells of TILE_PX / 2 columns; a cell's range is
    twice the coarser level's around it (``_tile_range``); neighbouring cells are joined into runs where one wider
    search costs less than repeating the margins (``_runs``); cells with no image in either view are skipped. A run
    is matched once, with OpenCV's own left-right check (disp12MaxDiff: the right image's disparities from the same
    aggregated costs), or, with ``edges_two_way`` where the coarser level shows a depth edge (EDGE_MIN_PIXELS of
    its pixels span EDGE_JUMP_PX, and EDGE_JUMP_REL of the median geometric disparity, the prior less ``shift``
    (``level.shift``), over 5 x 5), both ways with a full second pass, which keeps the occluded side of a
    wall out (one pass fattens a roof by a cell or two). Returns the map and {tiles: runs matched, skipped cells,
    two-way runs, mean disparities searched}."""
    cv2 = require("cv2", "dense matching")
    left, right, dmin, num, shift, block = level.left, level.right, level.dmin, level.num, level.shift, unit.block_size
    h, w = left.shape
    out = np.full((h, w), np.nan, np.float32)
    ctx = TILE_CONTEXT_PX
    pad = ctx + 2 * num + max(abs(dmin), abs(dmin + num)) + 16
    lp = cv2.copyMakeBorder(left, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    rp = cv2.copyMakeBorder(right, 0, 0, pad, pad, cv2.BORDER_CONSTANT, value=0)
    edge = edge_mask(prior, shift) if edges_two_way else np.zeros(prior.shape, bool)
    ph, pw = prior.shape
    cell = max(32, TILE_PX // 2)
    runs_done = skipped = searched = two_ways = 0
    for y0 in range(0, h, TILE_PX):
        y1 = min(h, y0 + TILE_PX)
        ya, yb = max(0, y0 - ctx), min(h, y1 + ctx)
        cells = []
        for x0 in range(0, w, cell):
            x1 = min(w, x0 + cell)
            if not left[y0:y1, x0:x1].any():
                cells.append(None)
                skipped += 1
                continue
            rng = _tile_range(prior, y0, y1, x0, x1, dmin, num)
            lo, hi = rng if rng is not None else (dmin, dmin + num - 1)
            if not right[y0:y1, max(0, x0 - hi):max(0, min(w, x1 - lo))].any():
                cells.append(None)  # the cell's ground is outside the other image
                skipped += 1
                continue
            tw = int(np.count_nonzero(edge[max(0, (y0 - ctx) // 2):min(ph, (y1 + ctx) // 2 + 1),
                                           max(0, (x0 - ctx) // 2):min(pw, (x1 + ctx) // 2 + 1)])) >= EDGE_MIN_PIXELS
            cells.append((x0, x1, lo, hi, tw))
        for x0, x1, lo, hi, tw in _runs(cells, ctx, y1 - y0):
            check_unit_cancel(cancel_path)
            tn = int(16 * math.ceil((hi - lo + 1) / 16.0))
            # crop disparity dd = d - lo in [0, tn): the left crop starts tn + ctx before the run (SGBM's first tn
            # columns have no full range); the right crop is the left one shifted by lo (and for two passes ends
            # tn + ctx after the run, for the right-to-left pass's own first columns)
            xa, xb = x0 - ctx - tn, x1 + ctx + (tn if tw else 0)
            lc = lp[ya:yb, xa + pad:xb + pad]
            rc = rp[ya:yb, xa + pad - lo:xb + pad - lo]
            # the lower uniqueness ratio away from depth edges only: beside a wall the occluded ground's second
            # minimum is real and the test keeps it out
            uq = unit.uniqueness if tw else unit.fine_uniqueness
            if tw:
                sgbm = _sgbm(block, 0, tn, uq)
                dl = sgbm.compute(lc, rc).astype(np.float32) / 16.0
                dr = sgbm.compute(np.ascontiguousarray(rc[:, ::-1]), np.ascontiguousarray(lc[:, ::-1]))
                dr = np.ascontiguousarray((dr.astype(np.float32) / 16.0)[:, ::-1])
                dl[dl < -0.5] = np.nan
                dr[dr < -0.5] = np.nan
                chk = lr_checked(dl, dr, unit.lr_tolerance)
                two_ways += 1
            else:
                sgbm = _sgbm(unit.flat_block or block, 0, tn, uq, max(1, int(round(unit.lr_tolerance))))
                chk = sgbm.compute(lc, rc).astype(np.float32) / 16.0
                chk[chk < -0.5] = np.nan
            piece = chk[y0 - ya:y1 - ya, x0 - xa:x1 - xa]
            with np.errstate(invalid="ignore"):  # a minimum at the window's end: the true one lies beyond it
                piece[(piece < WINDOW_END_PX) | (piece > hi - lo - WINDOW_END_PX)] = np.nan
            out[y0:y1, x0:x1] = piece + lo
            runs_done += 1
            searched += tn
    return out, {"tiles": runs_done, "skipped": skipped, "two_way": two_ways,
                 "disparities": searched / max(1, runs_done)}


def _disparity(pair: LevelPair, unit: "PairUnit", cancel_path: Optional[str],
               stats: Optional[dict] = None) -> np.ndarray:
    """The left image's disparity map (NaN = none), coarse to fine: the pair halved ``pyramid_levels`` times, the
    coarsest level matched over the whole range (SGBM both ways + left-right check), each finer level tile by tile
    over the range its coarser level found there, then checked and completed by it (``coarse_to_fine``)."""
    cv2 = require("cv2", "dense matching")
    li, rj, dmin, num, shift, block = pair.left, pair.right, pair.dmin, pair.num, pair.shift, unit.block_size
    if not unit.coarse or min(li.shape) < 64:
        disp_l, disp_r = _match_lr(li, rj, block, dmin, num, unit.uniqueness, cancel_path)
        return lr_checked(disp_l, disp_r, unit.lr_tolerance)
    levels = pyramid_levels(num, li.shape)
    pyr = [(li, rj)]
    for _ in range(levels):
        pyr.append((cv2.pyrDown(pyr[-1][0]), cv2.pyrDown(pyr[-1][1])))

    def level_range(k):
        lo = int(math.floor(dmin / 2.0 ** k)) - (1 if k else 0)
        hi = int(math.ceil((dmin + num) / 2.0 ** k)) + (1 if k else 0)
        return lo, int(16 * math.ceil(max(16, hi - lo) / 16.0))

    lo, n = level_range(levels)
    cl, cr = _match_lr(pyr[levels][0], pyr[levels][1], unit.flat_block or block, lo, n, unit.uniqueness, cancel_path)
    disp = lr_checked(cl, cr, unit.lr_tolerance)
    del cl, cr
    info = {"levels": levels, "coarsest_disparities": n, "coarsest_map": np.isfinite(disp)}
    for k in range(levels - 1, -1, -1):
        lo, n = level_range(k)
        fine, tinfo = _match_tiled(LevelPair(pyr[k][0], pyr[k][1], lo, n, shift / 2.0 ** k), disp, unit, cancel_path,
                                   edges_two_way=k == 0)
        disp = coarse_to_fine(fine, disp)
        if k == 0:
            disp = without_streaks(disp)
            info.update(tiles=tinfo["tiles"], tiles_skipped=tinfo["skipped"], tiles_two_way=tinfo["two_way"],
                        disparities_searched=round(tinfo["disparities"], 1))
    if stats is not None:
        stats.update(info)
    return disp


def _matched_shares(disp: np.ndarray, coarsest: Optional[np.ndarray], mi: np.ndarray, mj: np.ndarray,
                    dmid: float) -> dict:
    """The per-pair diagnosis (issue 33): of the left image's pixels whose ground the right image sees (at the
    middle of the disparity range), the share matched at the coarsest pyramid level (over the whole range: where
    a periodic texture's repeats compete) and in the end."""
    h, w = disp.shape
    shift = int(round(dmid))
    overlap = np.zeros((h, w), bool)
    if 0 <= shift < w:
        overlap[:, shift:] = mi[:, shift:] & mj[:, :w - shift]
    elif -w < shift < 0:
        overlap[:, :w + shift] = mi[:, :w + shift] & mj[:, -shift:]
    n = int(overlap.sum())
    out = {"overlap_matched": round(float(np.isfinite(disp)[overlap].mean()), 4) if n else 0.0}
    if coarsest is not None and n:
        step_y, step_x = -(-h // coarsest.shape[0]), -(-w // coarsest.shape[1])
        ov = overlap[::step_y, ::step_x][:coarsest.shape[0], :coarsest.shape[1]]
        out["coarsest_matched"] = round(float(coarsest[:ov.shape[0], :ov.shape[1]][ov].mean()), 4) if ov.any() else 0.0
    return out


def match_pair(unit: PairUnit, cancel_path: Optional[str] = None) -> dict:
    """The unit of work: one stereo pair -> depth maps of both images, saved to ``unit.out_path``."""
    cv2 = require("cv2", "dense matching")
    t0, c0 = time.time(), time.process_time()
    cv2.setNumThreads(max(1, unit.threads))
    check_unit_cancel(cancel_path)
    img_i, sxi, syi = load_scaled(unit.vi, unit.scale)
    img_j, sxj, syj = load_scaled(unit.vj, unit.scale)
    ki, di = unit.vi.camera_matrix(sxi, syi)
    kj, dj = unit.vj.camera_matrix(sxj, syj)
    hi_, wi_ = img_i.shape[:2]
    hj_, wj_ = img_j.shape[:2]
    summary = {"key": unit.key, "i": unit.vi.name, "j": unit.vj.name, "valid": 0, "megapixels": 0.0}
    try:
        rect = rectify_pair(ScaledCamera(unit.vi, ki, di, (wi_, hi_)), ScaledCamera(unit.vj, kj, dj, (wj_, hj_)))
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
    if unit.equalize:
        li, rj = equalized(li), equalized(rj)
    pyramid: dict = {}
    disp = _disparity(LevelPair(li, rj, dmin, num, rect.cx_i - rect.cx_j), unit, cancel_path, pyramid)
    check_unit_cancel(cancel_path)
    pyramid.update(_matched_shares(disp, pyramid.pop("coarsest_map", None), mi, mj, dmin + 0.5 * num))
    rows, xs = np.nonzero(np.isfinite(disp) & mi)
    d = disp[rows, xs]
    xr = xs - d
    ok = (xr >= 0) & (xr <= w - 1)
    rows, xs, d, xr = rows[ok], xs[ok], d[ok], xr[ok]
    ok = mj[rows, np.clip(np.round(xr).astype(np.int64), 0, w - 1)]
    denom = d - rect.cx_i + rect.cx_j
    ok &= denom > 0.05
    rows, xs, d, xr, denom = rows[ok], xs[ok], d[ok], xr[ok], denom[ok]
    # triangulate in the rectified frame of camera i, then to the local frame
    z = rect.f * rect.baseline / denom
    x_r = (xs - rect.cx_i) * z / rect.f
    y_r = (rows - rect.cy) * z / rect.f
    # depth along each camera's axis: world = [x_r, y_r, z] @ rn + centre_i, so depth = [x_r, y_r, z] @ (rn @ R[2])
    # (+ the centres' offset along camera j's axis); no N x 3 world array
    ai = rect.rn @ unit.vi.R[2]
    aj = rect.rn @ unit.vj.R[2]
    depth_i = ai[0] * x_r + ai[1] * y_r + ai[2] * z
    depth_j = aj[0] * x_r + aj[1] * y_r + aj[2] * z + float((unit.vi.centre - unit.vj.centre) @ unit.vj.R[2])
    # where each match came from in the (distorted, scaled) images
    px_i = rect.maps_i[0][rows, xs]
    py_i = rect.maps_i[1][rows, xs]
    px_j = _sample_rows(rect.maps_j[0], rows, xr)
    py_j = _sample_rows(rect.maps_j[1], rows, xr)
    map_i = _zbuffer((hi_, wi_), px_i, py_i, depth_i)
    map_j = _zbuffer((hj_, wj_), px_j, py_j, depth_j)
    zmed = float(np.median(z)) if len(z) else float("nan")
    rel_err = zmed / (rect.f * rect.baseline) if len(z) else 0.0
    base = unit.vj.centre - unit.vi.centre
    summary.update(valid=int(len(z)), valid_fraction=float(len(z) / max(1, int(mi.sum()))),
                   baseline_azimuth=round(math.degrees(math.atan2(base[1], base[0])), 1),
                   megapixels=(wi_ * hi_ + wj_ * hj_) / 1e6, rectified=[w, h], disparities=[dmin, num],
                   pyramid=pyramid,
                   rel_err=rel_err, seconds=time.time() - t0, cpu_seconds=time.process_time() - c0)
    check_unit_cancel(cancel_path)
    _save_pair(unit.out_path, map_i, map_j, rel_err, summary)
    return summary


def _save_npz(path: str, **arrays) -> None:
    """np.savez, stored (no deflate: uint16 depth maps are as small as deflated float32 ones, and deflating cost
    a tenth of a pair's matching), written to a temporary name and renamed: a cancelled or killed unit leaves no
    file that looks done."""
    save_npz(path, **arrays)


DEPTH_LEVELS = 65534  # a depth map is stored as uint16: 0 = none, 1..65535 = depth / depth_step


def _pack_depth(m: Optional[np.ndarray]) -> Tuple[np.ndarray, float]:
    """(uint16 map, depth_step): steps of the map's largest depth / DEPTH_LEVELS (a depth within 1 / 131,000 of the
    largest: 1.5 mm at 200 m, far inside the matching's own error and fusion's tolerance), 0 where none."""
    if m is None or m.size == 0:
        return np.zeros((0, 0), np.uint16), 1.0
    finite = np.isfinite(m)
    top = float(m[finite].max()) if finite.any() else 0.0
    step = top / DEPTH_LEVELS if top > 0 else 1.0
    q = np.zeros(m.shape, np.uint16)
    q[finite] = np.clip(np.round(m[finite] / np.float32(step)), 1, DEPTH_LEVELS + 1).astype(np.uint16)
    return q, step


def _save_pair(path: str, map_i, map_j, rel_err: float, summary: dict) -> None:
    qi, si = _pack_depth(map_i)
    qj, sj = _pack_depth(map_j)
    _save_npz(path, depth_i=qi, depth_j=qj, step_i=np.float64(si), step_j=np.float64(sj),
              rel_err=np.float64(rel_err), summary=np.array(json.dumps(summary)))


def read_depth(path: str, role: str) -> np.ndarray:
    """The depth map (float32, NaN = none) of image ``role`` ('i' or 'j') of a pair file written by match_pair."""
    with np.load(path) as d:
        q = d["depth_" + role]
        step = float(d["step_" + role])
    out = q.astype(np.float32) * np.float32(step)
    out[q == 0] = np.nan
    return out


def read_pair_summary(path: str) -> dict:
    with np.load(path) as d:
        return json.loads(str(d["summary"]))
