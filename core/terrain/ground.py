"""Ground filter and DTM: SMRF on the DSM grid, ground interpolated under the removed objects.

The filter is the Simple Morphological Filter (Pingel, Clarke & McBride 2013, ISPRS J. 77: 21-30), the
algorithm behind PDAL's ``filters.smrf``, here on the DSM raster (NumPy/SciPy, no extra package):

1. the DSM's median per ``filter_cell`` (0.5 m) block, pits (1 m below their neighbours) and nodata filled
   (push-pull);
2. a progressive opening (square windows of radius 1 .. ``window`` m): a cell whose opened height drops by more
   than ``slope`` x the window radius from one window to the next is an object (a building, a tree);
3. the provisional ground surface: the non-object blocks, the objects filled in between, back on the DSM grid;
4. a DSM cell is ground when it lies within ``threshold + scalar x local slope`` of that surface;
5. the DTM: measured ground where ground, and under the objects (and in the DSM's inner holes) a thin-plate
   spline fitted to the ring of ground around each object (SciPy's RBFInterpolator), push-pull for the tiny ones.

Negative features (ditches, hollow ways) are kept: an opening removes only what stands up.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Tuple

import numpy as np

from ..common.progress import NullProgress, Progress, check_cancel
from ..io.raster import push_pull
from .options import SOURCE_INTERPOLATED, SOURCE_MEASURED, GroundOptions


@dataclass
class GroundResult:
    dtm: np.ndarray  # float64, NaN where no ground can be given (outside the DSM's data)
    ground: np.ndarray  # bool: the DSM cell is measured ground
    source: np.ndarray  # uint8: SOURCE_MEASURED, SOURCE_INTERPOLATED, 0 = nodata
    provisional: np.ndarray  # the provisional ground surface (for diagnostics)


# ---------------------------------------------------------------- filling holes

def resample_to(coarse: np.ndarray, factor: int, h: int, w: int) -> np.ndarray:
    """Bilinear values of a grid ``factor`` x coarser (block-aligned) at the centres of an h x w grid."""
    ch, cw = coarse.shape
    fr = np.clip((np.arange(h) + 0.5) / factor - 0.5, 0, ch - 1)
    fc = np.clip((np.arange(w) + 0.5) / factor - 0.5, 0, cw - 1)
    r0 = np.minimum(np.floor(fr).astype(int), max(ch - 2, 0))
    c0 = np.minimum(np.floor(fc).astype(int), max(cw - 2, 0))
    r1 = np.minimum(r0 + 1, ch - 1)
    c1 = np.minimum(c0 + 1, cw - 1)
    ty = np.clip(fr - r0, 0, 1)[:, None]
    tx = np.clip(fc - c0, 0, 1)[None, :]
    return ((1 - ty) * ((1 - tx) * coarse[np.ix_(r0, c0)] + tx * coarse[np.ix_(r0, c1)])
            + ty * ((1 - tx) * coarse[np.ix_(r1, c0)] + tx * coarse[np.ix_(r1, c1)]))


# ---------------------------------------------------------------- SMRF

def _block_surface(dsm: np.ndarray, factor: int) -> np.ndarray:
    """The DSM on the filter grid: the median of each block (SMRF takes the minimum of lidar returns; a
    photogrammetric DSM has one surface, whose lowest cells are matching noise)."""
    import warnings

    h, w = dsm.shape
    hp, wp = -(-h // factor) * factor, -(-w // factor) * factor
    pad = np.full((hp, wp), np.nan)
    pad[:h, :w] = dsm
    blocks = pad.reshape(hp // factor, factor, wp // factor, factor).transpose(0, 2, 1, 3).reshape(
        hp // factor, wp // factor, factor * factor)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks
        return np.nanmedian(blocks, axis=2)


def low_outliers(z: np.ndarray, known: np.ndarray, depth: float) -> np.ndarray:
    """Cells more than ``depth`` below the median of their 3 x 3 neighbourhood (matching pits: a pit pulls the
    opening down and the ground around it becomes 'object').  A ditch wider than two cells is no outlier."""
    from scipy import ndimage

    med = ndimage.median_filter(z, size=3, mode="nearest")
    return known & (z < med - depth)


def smrf_objects(zmin: np.ndarray, cell: float, options: GroundOptions, progress: Progress) -> np.ndarray:
    """The object cells of a (filled) minimum surface: SMRF's progressive opening with square windows."""
    from scipy import ndimage

    objects = np.zeros(zmin.shape, dtype=bool)
    last = zmin
    radii = max(1, int(np.ceil(options.window / cell)))
    for r in range(1, radii + 1):
        check_cancel(progress)
        size = 2 * r + 1
        opened = ndimage.maximum_filter(ndimage.minimum_filter(zmin, size=size, mode="nearest"), size=size,
                                        mode="nearest")
        objects |= (last - opened) > options.slope * r * cell
        last = opened
        progress.report(0.5 * r / radii, f"ground filter: window {r * cell:.1f} m")
    return objects


def filter_ground(dsm: np.ndarray, cell: float, options: GroundOptions,
                  progress: Progress = None) -> GroundResult:
    """Ground cells and the DTM of a DSM (NaN = nodata) with square cells of ``cell`` metres."""
    from scipy import ndimage

    progress = progress or NullProgress()
    valid = np.isfinite(dsm)
    h, w = dsm.shape
    factor = max(1, int(round(options.filter_cell / cell)))
    coarse_cell = cell * factor
    zmin = _block_surface(dsm, factor)
    coarse_valid = np.isfinite(zmin)
    coarse_valid &= ~low_outliers(push_pull(np.nan_to_num(zmin), coarse_valid), coarse_valid, 2 * options.threshold)
    zfill = push_pull(np.nan_to_num(zmin), coarse_valid)
    objects = smrf_objects(zfill, coarse_cell, options, progress) | ~coarse_valid
    # the provisional surface is drawn under the objects and their skirts: a DSM blurs a wall into a slope
    # that an opening keeps (it keeps every ramp), and the skirt would then pass for ground
    skirt = int(np.ceil(options.skirt / coarse_cell))
    grown = ndimage.binary_dilation(objects, iterations=skirt) if skirt else objects
    provisional_c = push_pull(zfill, ~grown) if (~grown).any() else zfill
    provisional = resample_to(provisional_c, factor, h, w)
    gy, gx = np.gradient(provisional, cell)
    slope = np.hypot(gx, gy)
    dz = dsm - provisional
    with np.errstate(invalid="ignore"):
        ground = valid & (dz <= options.threshold + options.scalar * slope) & (dz >= -2.0 * options.threshold)
    grow = max(1, int(round(options.dilate / cell))) if options.dilate > 0 else 1
    ground &= ~ndimage.binary_dilation(valid & ~ground, iterations=grow)  # the blurred feet of walls and crowns
    progress.report(0.6, "ground filter: interpolating under the objects")
    dtm, source = interpolate_ground(dsm, ground, valid, cell, progress)
    return GroundResult(dtm=dtm, ground=ground, source=source, provisional=provisional)


# ---------------------------------------------------------------- interpolation under the objects

def _outside(valid: np.ndarray) -> np.ndarray:
    """Nodata cells connected to the raster's edge (outside the DSM's data: the DTM stays nodata there)."""
    from scipy import ndimage

    lab, _ = ndimage.label(~valid)
    edge = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    return np.isin(lab, edge[edge > 0])


def interpolate_ground(dsm: np.ndarray, ground: np.ndarray, valid: np.ndarray, cell: float,
                       progress: Progress) -> Tuple[np.ndarray, np.ndarray]:
    """(DTM, source): ground cells measured; every other cell inside the data interpolated."""
    from scipy import ndimage

    outside = _outside(valid)
    dtm = np.where(ground, dsm, np.nan)
    fill = push_pull(np.nan_to_num(dsm), ground)
    holes = ~ground & ~outside
    lab, n = ndimage.label(holes, structure=np.ones((3, 3)))
    ring = max(3, int(round(1.5 / cell)))
    for i, sl in enumerate(ndimage.find_objects(lab)):
        if i % 64 == 0:
            check_cancel(progress)
            progress.report(0.6 + 0.35 * i / max(n, 1), f"ground filter: object {i + 1} of {n}")
        comp = lab[sl] == i + 1
        if comp.sum() < 16:
            dtm[sl][comp] = fill[sl][comp]
            continue
        dtm[sl][comp] = _spline_fill(dsm, ground, lab, i + 1, sl, ring, fill)
    source = np.where(ground, SOURCE_MEASURED, np.where(holes, SOURCE_INTERPOLATED, 0)).astype(np.uint8)
    dtm[outside] = np.nan
    return dtm, source


def _spline_fill(dsm, ground, lab, label, sl, ring, fill) -> np.ndarray:
    """A thin-plate spline through the ground ring around component ``label`` (bbox ``sl``), at its cells."""
    from scipy import ndimage
    from scipy.interpolate import RBFInterpolator

    h, w = dsm.shape
    r0, r1 = max(0, sl[0].start - ring), min(h, sl[0].stop + ring)
    c0, c1 = max(0, sl[1].start - ring), min(w, sl[1].stop + ring)
    comp = lab[r0:r1, c0:c1] == label
    around = ndimage.binary_dilation(comp, iterations=ring) & ground[r0:r1, c0:c1] & ~comp
    rr, cc = np.nonzero(around)
    inside_r, inside_c = np.nonzero(comp)
    if len(rr) < 10:
        return fill[r0:r1, c0:c1][comp]
    if len(rr) > 600:
        pick = np.random.default_rng(label).choice(len(rr), 600, replace=False)
        rr, cc = rr[pick], cc[pick]
    pts = np.column_stack([rr, cc]).astype(np.float64)
    vals = dsm[r0:r1, c0:c1][rr, cc]
    scale = max(comp.shape)
    try:
        rbf = RBFInterpolator(pts / scale, vals, kernel="thin_plate_spline", smoothing=1e-3 * len(pts), degree=1)
        q = np.column_stack([inside_r, inside_c]).astype(np.float64) / scale
        out = np.concatenate([rbf(q[i:i + 200_000]) for i in range(0, len(q), 200_000)])
    except (np.linalg.LinAlgError, ValueError):
        return fill[r0:r1, c0:c1][comp]
    return np.clip(out, vals.min(), vals.max())  # a spline may overshoot between noisy ring points: never above
