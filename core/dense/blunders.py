"""The DSM's blunders: the heights to remove before the holes are filled (flagged 3 = removed in
dense/dsm-source.tif, :func:`.grid.source_raster`).

Two kinds, told apart by how many images confirm a cell (:func:`.grid.supporting_views`: images whose fused
points lie within the height tolerance of the cell) and by its neighbours:

* a cell fewer than BLUNDER_MIN_VIEWS images confirm, far from a robust local surface of the confirmed cells
  (:func:`robust_surface`) or outside the heights of the confirmed cells around it (:func:`find_blunders`);
* a small pit: a cell below its neighbours in every direction (:func:`enclosed_pits`), fewer than PIT_MIN_VIEWS
  images confirm.  Two images are not enough there: the two images of one stereo pair carry that pair's match,
  and a wrong match at a crown's or a roof's edge repeats in the pairs beside it.

Walls, trees and buildings that several images see stay; every threshold is in ground sample distances, cells
or the height tolerance, none in metres.
"""
from __future__ import annotations

from typing import Tuple

import numpy as np

from ..common.errors import require
from ..io.raster import push_pull


def robust_surface(dsm: np.ndarray, block: int, band: int = 64) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a robust local surface, its local spread, where it has support) of ``dsm`` (NaN = none): the median and
    the 10-90 % range of each ``block`` x ``block`` block of cells, then per block the median of its 3 x 3 blocks'
    medians (the support is 3 ``block`` cells across: a blunder patch under half of it does not move it) and the
    largest of their ranges, upsampled bilinearly to the cells; blocks without data around take a smooth fill
    (push-pull) and are False in the third array.  Works ``band`` block rows at a time (memory: those rows)."""
    cv2 = require("cv2", "the DSM blunder filter")
    from scipy import ndimage

    h, w = dsm.shape
    bh, bw = -(-h // block), -(-w // block)
    med = np.full((bh, bw), np.nan, np.float32)
    spread = np.zeros((bh, bw), np.float32)
    for b0 in range(0, bh, band):
        b1 = min(bh, b0 + band)
        pad = np.full(((b1 - b0) * block, bw * block), np.nan, np.float32)
        rows = dsm[b0 * block:b1 * block]
        pad[:rows.shape[0], :w] = rows
        blocks = pad.reshape(b1 - b0, block, bw, block).transpose(0, 2, 1, 3).reshape(b1 - b0, bw, block * block)
        n = np.count_nonzero(np.isfinite(blocks), axis=2)
        blocks.sort(axis=2)  # NaN last; nearest-rank percentiles of the n heights (np.nanpercentile loops per block)
        q = [np.take_along_axis(blocks, np.floor(f * np.maximum(n - 1, 0) + 0.5).astype(np.int64)[..., None],
                                axis=2)[..., 0] for f in (0.1, 0.5, 0.9)]
        med[b0:b1] = np.where(n > 0, q[1], np.nan)
        spread[b0:b1] = np.where(n > 0, q[2] - q[0], 0.0)
    valid = np.isfinite(med)
    big = np.float32(1e9)
    # the median of the 3 x 3 blocks' medians, blocks without data left out: each holds -big once and +big once
    # among 18 values (their ranks cancel), each with data its median twice
    lo_p = np.pad(np.where(valid, med, -big), 1, constant_values=-big)
    hi_p = np.pad(np.where(valid, med, big), 1, constant_values=big)
    surf = np.median(np.stack([a[1 + dy:1 + dy + bh, 1 + dx:1 + dx + bw] for a in (lo_p, hi_p)
                               for dy in (-1, 0, 1) for dx in (-1, 0, 1)]), axis=0).astype(np.float32)
    supported = ndimage.maximum_filter(valid, 3) & (np.abs(surf) < big / 2)
    spread = ndimage.maximum_filter(spread, 3)
    if supported.any() and not supported.all():
        surf = push_pull(np.where(supported, surf, 0.0), supported).astype(np.float32)
    elif not supported.any():
        surf = np.full((bh, bw), np.nan, np.float32)
    size = (bw * block, bh * block)
    up = cv2.resize(surf, size, interpolation=cv2.INTER_LINEAR)[:h, :w]
    sp = cv2.resize(spread, size, interpolation=cv2.INTER_LINEAR)[:h, :w]
    sup = cv2.resize(supported.astype(np.uint8), size, interpolation=cv2.INTER_NEAREST)[:h, :w] > 0
    return up, sp, sup


BLUNDER_MIN_VIEWS = 2  # a cell that this many images' fused points confirm is kept whatever its height...
PIT_MIN_VIEWS = 3  # ... unless it is a small pit: then this many
BLUNDER_BLOCK = 5  # cells: the robust surface's blocks (support 3 x 5 = 15 cells; and 45 for the wide one)
BLUNDER_NEAR_GSD = 3.0  # a cell fewer images confirm is a blunder this far from the narrow surface (x GSD)...
BLUNDER_WIDE_GSD = 6.0  # ... or this far from the wide one (each raised to BLUNDER_SPREAD x the local 10-90 %
BLUNDER_SPREAD = 1.5  # spread: slopes, crowns and walls; at a block's edge the surface lags the slope)
BLUNDER_FAR_GSD = 60.0  # where no cell around is confirmed: this far from the surface of all cells (3 m at 5 cm)
PIT_MAX_CELLS = 64  # cells: a pit holds at most this many (8 x 8)


def find_blunders(dsm: np.ndarray, views: np.ndarray, gsd: float, tolerance: float = 0.0) -> np.ndarray:
    """The cells of ``dsm`` to remove as blunders.  A cell fewer than BLUNDER_MIN_VIEWS images confirm
    (``views``, :func:`.grid.supporting_views`) is one when it lies farther from a robust local surface of the
    confirmed cells (:func:`robust_surface`, 15 and 45 cells across) than BLUNDER_NEAR_GSD / BLUNDER_WIDE_GSD
    ground sample distances or 1.5 x the local spread, whichever is larger (rough ground, crowns and walls raise
    it); where no cell around is confirmed, farther than BLUNDER_FAR_GSD GSD (or twice the spread) from the surface
    of all cells; and, whatever the spread, when it lies more than ``tolerance`` (the height within which a view
    confirms a cell; at least BLUNDER_NEAR_GSD GSD) below the lowest or above the highest confirmed cell of its 15
    x 15 cells.  A cell within the heights of the confirmed cells of its 5 x 5 continues them (the strip beside a
    wall that one image sees, a roof's or a crown's edge) and stays.  Then the small pits (:func:`enclosed_pits`,
    deeper than ``tolerance``) that fewer than PIT_MIN_VIEWS images confirm."""
    tol = max(float(tolerance), BLUNDER_NEAR_GSD * gsd)
    have = np.isfinite(dsm)
    out = _weak_blunders(dsm, views, gsd, tol) if (have & (views < BLUNDER_MIN_VIEWS)).any() else np.zeros(
        dsm.shape, bool)
    out |= enclosed_pits(np.where(out, np.nan, dsm).astype(np.float32), tol) & (views < PIT_MIN_VIEWS)
    return out


def _weak_blunders(dsm: np.ndarray, views: np.ndarray, gsd: float, tol: float) -> np.ndarray:
    """find_blunders' cells that fewer than BLUNDER_MIN_VIEWS images confirm."""
    weak = np.isfinite(dsm) & (views < BLUNDER_MIN_VIEWS)
    out = np.zeros(dsm.shape, dtype=bool)
    confirmed = np.where(views >= BLUNDER_MIN_VIEWS, dsm, np.nan).astype(np.float32)
    if np.isfinite(confirmed).any():
        for block, k in ((BLUNDER_BLOCK, BLUNDER_NEAR_GSD), (3 * BLUNDER_BLOCK, BLUNDER_WIDE_GSD)):
            surf, spread, sup = robust_surface(confirmed, block)
            with np.errstate(invalid="ignore"):
                out |= weak & sup & (np.abs(dsm - surf) > np.maximum(k * gsd, BLUNDER_SPREAD * spread))
        lo, hi = _envelope(confirmed, 3 * BLUNDER_BLOCK)
        with np.errstate(invalid="ignore"):
            out |= weak & np.isfinite(lo) & ((dsm < lo - tol) | (dsm > hi + tol))
    surf, spread, sup = robust_surface(dsm.astype(np.float32), 3 * BLUNDER_BLOCK)
    with np.errstate(invalid="ignore"):
        out |= weak & (np.abs(dsm - surf) > np.maximum(BLUNDER_FAR_GSD * gsd, 2.0 * spread))
    lo, hi = _envelope(confirmed, 5)
    slack = np.float32(BLUNDER_NEAR_GSD * gsd)
    with np.errstate(invalid="ignore"):
        out &= ~(np.isfinite(lo) & (dsm >= lo - slack) & (dsm <= hi + slack))
    return out


def _envelope(z: np.ndarray, size: int) -> Tuple[np.ndarray, np.ndarray]:
    """The lowest and the highest height of ``z`` (NaN = none) in each cell's ``size`` x ``size`` cells; NaN
    where there is none."""
    cv2 = require("cv2", "the DSM blunder filter")
    big = np.float32(1e9)
    known = np.isfinite(z)
    kernel = np.ones((size, size), np.uint8)
    lo = cv2.erode(np.where(known, z, big).astype(np.float32), kernel)
    hi = cv2.dilate(np.where(known, z, -big).astype(np.float32), kernel)
    none = lo > big / 2
    lo[none] = np.nan
    hi[none] = np.nan
    return lo, hi


def enclosed_pits(dsm: np.ndarray, depth: float, max_cells: int = PIT_MAX_CELLS) -> np.ndarray:
    """The cells of ``dsm`` (NaN = none) in a small pit: a group of at most ``max_cells`` 8-connected cells, each
    more than ``depth`` below the robust surface around it (:func:`robust_surface`, 15 cells across), whose every
    neighbour with a height (a quarter of its neighbours or more have one: the data's edge may close the rest) stands more
    than ``depth`` above the group's highest cell.  Ground beside a wall or a crown, a ditch or a street joins
    ground as low as itself and is no pit."""
    from scipy import ndimage

    surf, _spread, _sup = robust_surface(dsm, BLUNDER_BLOCK)
    with np.errstate(invalid="ignore"):
        low = np.isfinite(dsm) & (dsm < surf - np.float32(depth))
    del surf, _spread, _sup
    lab, n = ndimage.label(low, structure=np.ones((3, 3)))
    if n == 0:
        return low
    idx = np.arange(1, n + 1)
    small = np.r_[False, ndimage.sum_labels(low, lab, idx) <= max_cells]
    lab[~small[lab]] = 0
    ring = ndimage.grey_dilation(lab, size=(3, 3))
    ring[lab > 0] = 0
    have = np.isfinite(dsm)
    z = np.where(have, dsm, np.inf)
    ring_low = np.r_[np.inf, ndimage.minimum(z, np.where(have, ring, 0), idx)]
    ring_cells = np.bincount(ring.ravel(), minlength=n + 1)
    ring_data = np.bincount(ring[have], minlength=n + 1) / np.maximum(ring_cells, 1)
    top = np.r_[np.inf, ndimage.maximum(np.where(have, dsm, -np.inf), lab, idx)]
    pit = small & (ring_low > top + depth) & (ring_data >= 0.25)
    return pit[lab]
