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
   spline fitted to the ring of ground around each object (SciPy's RBFInterpolator), push-pull of the ground
   around it for the tiny ones.

Steps 1, 4 and 5 run on the DSM's full resolution by tiles (``GroundOptions.tile``; issue 33: the whole raster
as float64 copies took 6 GiB for 44 M cells): the block medians by tiles of whole blocks, the classification on
each tile with a margin its slope and dilation reach, each object filled from its own box; what is held whole
is one byte a cell of masks, the object labels and the float32 DTM.  The result does not depend on the tiles.

Negative features (ditches, hollow ways) are kept: an opening removes only what stands up.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Tuple

import numpy as np

from ..common.progress import NullProgress, Progress, check_cancel
from ..io.raster import push_pull
from .options import SOURCE_INTERPOLATED, SOURCE_MEASURED, TILE_CELLS, GroundOptions
from .rasters import tiles


@dataclass
class GroundResult:
    dtm: np.ndarray  # float32, NaN where no ground can be given (outside the DSM's data)
    ground: np.ndarray  # bool: the DSM cell is measured ground
    source: np.ndarray  # uint8: SOURCE_MEASURED, SOURCE_INTERPOLATED, 0 = nodata
    valid_cells: int = 0  # cells of the DSM with data


class _InMemory:
    """A DSM array (metres, NaN = nodata) read by windows like a raster file (core.terrain.rasters.Elevation)."""

    def __init__(self, z: np.ndarray):
        self.z = z
        self.shape = z.shape

    def read(self, r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        return np.array(self.z[r0:r1, c0:c1], dtype=np.float64)


def _windowed(dsm):
    return _InMemory(dsm) if isinstance(dsm, np.ndarray) else dsm


# ---------------------------------------------------------------- filling holes

def resample_to(coarse: np.ndarray, factor: int, h: int, w: int, r0: int = 0, c0: int = 0) -> np.ndarray:
    """Bilinear values of a grid ``factor`` x coarser (block-aligned) at the centres of an h x w grid (the
    window of a finer grid starting at row ``r0``, column ``c0``)."""
    ch, cw = coarse.shape
    fr = np.clip((np.arange(r0, r0 + h) + 0.5) / factor - 0.5, 0, ch - 1)
    fc = np.clip((np.arange(c0, c0 + w) + 0.5) / factor - 0.5, 0, cw - 1)
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


def _coarse_surface(dsm, factor: int, tile: int, valid: np.ndarray) -> np.ndarray:
    """The block medians of the DSM (:func:`_block_surface`) read tile by tile (tiles of whole blocks);
    ``valid`` (the DSM's data mask, whole) is filled on the way."""
    h, w = dsm.shape
    out = np.full((-(-h // factor), -(-w // factor)), np.nan)
    step = factor * max(1, tile // factor)
    for r0, r1, c0, c1 in tiles(h, w, step):
        z = dsm.read(r0, r1, c0, c1)
        valid[r0:r1, c0:c1] = np.isfinite(z)
        out[r0 // factor:-(-r1 // factor), c0 // factor:-(-c1 // factor)] = _block_surface(z, factor)
    return out


def _classify_tile(dsm, provisional_c: np.ndarray, factor: int, window: Tuple[int, int, int, int], margin: int,
                   cell: float, options: GroundOptions, grow: int) -> Tuple[np.ndarray, np.ndarray]:
    """(ground, heights) of the tile ``window`` (r0, r1, c0, c1): steps 3-4 on the tile and a ``margin`` around it
    (the slope's differences and the dilation by ``grow`` cells reach that far: the tile's cells come out as on
    the whole raster)."""
    from scipy import ndimage

    h, w = dsm.shape
    r0, r1, c0, c1 = window
    a0, a1, b0, b1 = max(0, r0 - margin), min(h, r1 + margin), max(0, c0 - margin), min(w, c1 + margin)
    z = dsm.read(a0, a1, b0, b1)
    provisional = resample_to(provisional_c, factor, a1 - a0, b1 - b0, a0, b0)
    gy, gx = np.gradient(provisional, cell)
    slope = np.hypot(gx, gy)
    del gx, gy
    valid = np.isfinite(z)
    dz = z - provisional
    del provisional
    with np.errstate(invalid="ignore"):
        ground = valid & (dz <= options.threshold + options.scalar * slope) & (dz >= -2.0 * options.threshold)
    ground &= ~ndimage.binary_dilation(valid & ~ground, iterations=grow)  # the blurred feet of walls and crowns
    core = (slice(r0 - a0, r1 - a0), slice(c0 - b0, c1 - b0))
    return ground[core], z[core]


def filter_ground(dsm, cell: float, options: GroundOptions, progress: Progress = None,
                  tile: Optional[int] = None, check_data: Optional[Callable[[int], None]] = None) -> GroundResult:
    """Ground cells and the DTM of a DSM (NaN = nodata) with square cells of ``cell`` metres.  ``dsm``: an array
    or a raster read by windows (core.terrain.rasters.Elevation); the full-resolution steps run by tiles of
    ``tile`` cells (``options.tile``; the result does not depend on it), so only masks, labels and the DTM are
    ever whole.  ``check_data``: called with the number of cells with data once it is known (it may raise)."""
    from scipy import ndimage

    progress = progress or NullProgress()
    dsm = _windowed(dsm)
    tile = int(tile or options.tile)
    h, w = dsm.shape
    valid = np.zeros((h, w), dtype=bool)
    factor = max(1, int(round(options.filter_cell / cell)))
    coarse_cell = cell * factor
    zmin = _coarse_surface(dsm, factor, tile, valid)
    n_valid = int(np.count_nonzero(valid))
    if check_data is not None:
        check_data(n_valid)
    coarse_valid = np.isfinite(zmin)
    coarse_valid &= ~low_outliers(push_pull(np.nan_to_num(zmin), coarse_valid), coarse_valid, 2 * options.threshold)
    zfill = push_pull(np.nan_to_num(zmin), coarse_valid)
    objects = smrf_objects(zfill, coarse_cell, options, progress) | ~coarse_valid
    # the provisional surface is drawn under the objects and their skirts: a DSM blurs a wall into a slope
    # that an opening keeps (it keeps every ramp), and the skirt would then pass for ground
    skirt = int(np.ceil(options.skirt / coarse_cell))
    grown = ndimage.binary_dilation(objects, iterations=skirt) if skirt else objects
    provisional_c = push_pull(zfill, ~grown) if (~grown).any() else zfill
    grow = max(1, int(round(options.dilate / cell))) if options.dilate > 0 else 1
    ground = np.zeros((h, w), dtype=bool)
    dtm = np.full((h, w), np.nan, dtype=np.float32)
    n_tiles = -(-h // tile) * -(-w // tile)
    for i, (r0, r1, c0, c1) in enumerate(tiles(h, w, tile)):
        check_cancel(progress)
        progress.report(0.5 + 0.1 * i / n_tiles, f"ground filter: tile {i + 1} of {n_tiles}")
        g, z = _classify_tile(dsm, provisional_c, factor, (r0, r1, c0, c1), grow + 2, cell, options, grow)
        ground[r0:r1, c0:c1] = g
        dtm[r0:r1, c0:c1] = np.where(g, z, np.nan)
    progress.report(0.6, "ground filter: interpolating under the objects")
    source = interpolate_ground(dsm, ground, valid, cell, progress, tile=tile, dtm=dtm)[1]
    return GroundResult(dtm=dtm, ground=ground, source=source, valid_cells=n_valid)


# ---------------------------------------------------------------- interpolation under the objects

def _outside(valid: np.ndarray) -> np.ndarray:
    """Nodata cells connected to the raster's edge (outside the DSM's data: the DTM stays nodata there)."""
    from scipy import ndimage

    lab, _ = ndimage.label(~valid)
    edge = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    return np.isin(lab, edge[edge > 0])


def interpolate_ground(dsm, ground: np.ndarray, valid: np.ndarray, cell: float, progress: Progress = None,
                       tile: int = TILE_CELLS, dtm: Optional[np.ndarray] = None) -> Tuple[np.ndarray, np.ndarray]:
    """(DTM, source): ground cells measured; every other cell inside the data interpolated, object by object from
    the ground around it only (the result does not depend on ``tile``, the side of the tiles the DSM is read by).
    ``dtm``: the measured ground already in place (float32, filled in place); else made from ``dsm``."""
    from scipy import ndimage

    progress = progress or NullProgress()
    dsm = _windowed(dsm)
    h, w = ground.shape
    if dtm is None:
        dtm = np.full((h, w), np.nan, dtype=np.float32)
        for r0, r1, c0, c1 in tiles(h, w, tile):
            dtm[r0:r1, c0:c1] = np.where(ground[r0:r1, c0:c1], dsm.read(r0, r1, c0, c1), np.nan)
    holes = ~ground & ~_outside(valid)
    source = holes.astype(np.uint8) * np.uint8(SOURCE_INTERPOLATED)
    source[ground] = SOURCE_MEASURED
    lab, n = ndimage.label(holes, structure=np.ones((3, 3)))
    del holes
    objects = ndimage.find_objects(lab)
    ring = max(3, int(round(1.5 / cell)))
    tile = max(1, int(tile))
    margin = 4 * ring  # an object whose box and ring fit in its tile and this margin is done from the tile's read
    by_tile: Dict[Tuple[int, int], List[int]] = {}
    for i, sl in enumerate(objects):
        by_tile.setdefault((sl[0].start // tile, sl[1].start // tile), []).append(i)
    done = 0
    for (ti, tj), members in sorted(by_tile.items()):
        r0, c0 = ti * tile, tj * tile
        win = (max(0, r0 - margin), min(h, r0 + tile + margin), max(0, c0 - margin), min(w, c0 + tile + margin))
        z = None
        for i in members:
            if done % 64 == 0:
                check_cancel(progress)
                progress.report(0.6 + 0.35 * done / max(n, 1), f"ground filter: object {done + 1} of {n}")
            done += 1
            box = _box(objects[i], ring, h, w)
            if win[0] <= box[0] and box[1] <= win[1] and win[2] <= box[2] and box[3] <= win[3]:
                if z is None:
                    z = dsm.read(*win)
                part = z[box[0] - win[0]:box[1] - win[0], box[2] - win[2]:box[3] - win[2]]
            else:  # larger than the margin: its own read
                part = dsm.read(*box)
            _fill_object(dtm, part, ground, lab, i + 1, box, ring)
    dtm[source == 0] = np.nan
    return dtm, source


def _box(sl, ring: int, h: int, w: int) -> Tuple[int, int, int, int]:
    """The bounding box ``sl`` of an object grown by ``ring`` cells, clipped to the raster: (r0, r1, c0, c1)."""
    return (max(0, sl[0].start - ring), min(h, sl[0].stop + ring), max(0, sl[1].start - ring),
            min(w, sl[1].stop + ring))


def _fill_object(dtm, z, ground, lab, label, box, ring) -> None:
    """The DTM under object ``label`` from the DSM ``z`` of ``box`` (its bounding box grown by ``ring`` cells): a thin-plate spline through the ground ring, or for a small object (or too little ring) the membrane
    (push-pull) of the ground in the box."""
    r0, r1, c0, c1 = box
    comp = lab[r0:r1, c0:c1] == label
    known = ground[r0:r1, c0:c1]
    values = None
    if comp.sum() >= 16:
        values = _spline_fill(z, known, comp, label, ring)
    if values is None:
        values = push_pull(np.nan_to_num(z), known)[comp] if known.any() else np.nan
    dtm[r0:r1, c0:c1][comp] = values


def _spline_fill(z, known, comp, label, ring) -> Optional[np.ndarray]:
    """A thin-plate spline through the ground ring around the object ``comp`` (all in its grown box), at its
    cells; None when the ring has too few points or the spline cannot be solved."""
    from scipy import ndimage
    from scipy.interpolate import RBFInterpolator

    around = ndimage.binary_dilation(comp, iterations=ring) & known & ~comp
    rr, cc = np.nonzero(around)
    inside_r, inside_c = np.nonzero(comp)
    if len(rr) < 10:
        return None
    if len(rr) > 600:
        pick = np.random.default_rng(label).choice(len(rr), 600, replace=False)
        rr, cc = rr[pick], cc[pick]
    pts = np.column_stack([rr, cc]).astype(np.float64)
    vals = z[rr, cc]
    scale = max(comp.shape)
    try:
        rbf = RBFInterpolator(pts / scale, vals, kernel="thin_plate_spline", smoothing=1e-3 * len(pts), degree=1)
        q = np.column_stack([inside_r, inside_c]).astype(np.float64) / scale
        out = np.concatenate([rbf(q[i:i + 200_000]) for i in range(0, len(q), 200_000)])
    except (np.linalg.LinAlgError, ValueError):
        return None
    return np.clip(out, vals.min(), vals.max())  # a spline may overshoot between noisy ring points: never above
