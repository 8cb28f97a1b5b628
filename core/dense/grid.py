"""Points -> heights on a grid: the gridding algorithms of the DSM.

Rasterisation (:func:`rasterize_points`) works tile by tile over point files, so
memory is bounded by the points of one tile.  Per cell it takes the median of
the *highest cluster* of heights (the points within ``cluster_tol`` of the
cell's 90th percentile), so a cell on a roof edge shows the roof, not a mean of
roof and ground, and a lone low point under a crown does not pull it down.
Small holes (at most ``max_hole_cells`` cells) are filled from their borders;
larger ones inside the camera hull by a smooth surface (:func:`fill_region`), up to a
distance; every filled cell is flagged interpolated (:func:`source_raster`).  The grid itself and the GeoTIFF are
:mod:`core.io.raster`'s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.raster import SOURCE_INTERPOLATED, SOURCE_MEASURED, Grid, push_pull

TILE = 1024  # cells per tile side for rasterisation
Z_QUANTUM = 1e-4  # cell_statistic's height step, of the cluster tolerance


@dataclass
class PointFile:
    """Points of one source (one image's fused depth map) on disk, with their bounding box
    in the local frame; ``load`` returns (xyz float32 local, rgb uint8)."""

    path: str
    bbox: Tuple[float, float, float, float]  # xmin, ymin, xmax, ymax (local frame)
    count: int
    robust_bbox: Tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  # 0.5-99.5 % of x and y

    def load(self) -> Tuple[np.ndarray, np.ndarray]:
        with np.load(self.path) as d:
            return d["xyz"], d["rgb"]


def stream_point_files(files: Sequence[PointFile]) -> Iterable[Tuple[np.ndarray, np.ndarray]]:
    for pf in files:
        yield pf.load()


def footprint_valid_fraction(dsm: np.ndarray, mask: np.ndarray) -> Optional[float]:
    """Share of the cells inside ``mask`` that hold a height; None for an empty mask."""
    n = int(mask.sum())
    if n == 0:
        return None
    return float(np.isfinite(dsm[mask]).sum() / n)


def cell_statistic(cells: np.ndarray, z: np.ndarray, n_cells: int, cluster_tol: float,
                   upper_quantile: float = 0.9) -> Tuple[np.ndarray, np.ndarray]:
    """Per cell: (value, count), value = median of the points within ``cluster_tol`` below the
    cell's ``upper_quantile`` height (the highest cluster).  NaN where a cell has no point.

    The points are ordered by (cell, height) with one sort of 64-bit integers: the cell in the high bits, the
    height above the lowest one in steps of Z_QUANTUM x ``cluster_tol`` (or finer: 2^31 steps over the heights)
    in the low 32 (a lexsort of two keys costs 4-5 times as much); heights come back within half a step."""
    value = np.full(n_cells, np.nan, dtype=np.float32)
    count = np.zeros(n_cells, dtype=np.int32)
    if len(z) == 0:
        return value, count
    z = np.asarray(z, dtype=np.float64)
    zmin = float(z.min())
    span = float(z.max()) - zmin
    step = max(span / 2.0 ** 31, Z_QUANTUM * cluster_tol) if cluster_tol > 0 else span / 2.0 ** 31
    step = step if step > 0 else 1.0
    key = np.asarray(cells, dtype=np.int64) << 32
    key |= np.round((z - zmin) / step).astype(np.int64)
    key.sort()
    c = key >> 32
    zs = (key & 0xFFFFFFFF).astype(np.float64) * step + zmin
    starts = np.flatnonzero(np.r_[True, c[1:] != c[:-1]])
    ends = np.r_[starts[1:], len(c)]
    n = ends - starts
    ucell = c[starts]
    q_idx = starts + np.floor((n - 1) * upper_quantile).astype(np.int64)
    q = zs[q_idx]
    # first index in each cell with z >= q - tol: on the sorted keys (cell, height step)
    low = np.maximum(np.ceil((q - cluster_tol - zmin) / step - 1e-9), 0).astype(np.int64)
    first = np.searchsorted(key, (ucell << 32) | low, side="left")
    first = np.clip(first, starts, q_idx)
    last = np.maximum(q_idx, first)  # include up to the quantile point (higher ones are outlier candidates)
    mid_lo = (first + last) // 2
    mid_hi = (first + last + 1) // 2
    value[ucell] = (0.5 * (zs[mid_lo] + zs[mid_hi])).astype(np.float32)
    count[ucell] = n
    return value, count


def fill_small_holes(dsm: np.ndarray, max_hole_cells: int = 16, iterations: int = 0) -> np.ndarray:
    """Fill nodata holes (NaN) of at most ``max_hole_cells`` cells by averaging their valid
    neighbours inwards; holes that touch the raster edge or are larger stay NaN."""
    from scipy import ndimage

    out = dsm.copy()
    holes = ~np.isfinite(out)
    if not holes.any() or max_hole_cells <= 0:
        return out
    lab, n = ndimage.label(holes)
    if n == 0:
        return out
    sizes = np.bincount(lab.ravel())
    edge = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    small = sizes <= max_hole_cells
    small[0] = False
    small[edge] = False
    fill = small[lab]
    if not fill.any():
        return out
    iterations = iterations or int(math.ceil(math.sqrt(max_hole_cells))) + 2
    kernel = np.ones((3, 3), dtype=np.float64)
    for _ in range(iterations):
        valid = np.isfinite(out)
        vals = np.where(valid, out, 0.0).astype(np.float64)
        s = ndimage.convolve(vals, kernel, mode="constant")
        k = ndimage.convolve(valid.astype(np.float64), kernel, mode="constant")
        todo = fill & ~valid & (k > 0)
        if not todo.any():
            break
        out[todo] = (s[todo] / k[todo]).astype(out.dtype)
    return out


def raised_borders(dsm: np.ndarray, holes: np.ndarray, ring_cells: int, step: float) -> np.ndarray:
    """The cells with data within ``ring_cells`` of a hole that stand more than ``step`` above the lowest tenth
    of that hole's ring: roofs and crowns beside an occlusion (the hidden cells behind a wall are ground)."""
    from scipy import ndimage

    lab, n = ndimage.label(holes, structure=np.ones((3, 3)))
    if n == 0 or ring_cells <= 0:
        return np.zeros(dsm.shape, dtype=bool)
    near = ndimage.grey_dilation(lab, size=(2 * ring_cells + 1, 2 * ring_cells + 1))
    ring = (near > 0) & np.isfinite(dsm) & ~holes
    if not ring.any():
        return ring
    ids, z = near[ring], dsm[ring].astype(np.float64)
    order = np.lexsort((z, ids))
    ids, z = ids[order], z[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    counts = np.diff(np.r_[starts, len(ids)])
    low = np.full(n + 1, np.inf)
    low[ids[starts]] = z[starts + (counts - 1) // 10]  # the 10th percentile of each ring
    out = np.zeros(dsm.shape, dtype=bool)
    out[ring] = dsm[ring] > low[near[ring]] + step
    return out


def fill_region(dsm: np.ndarray, region: np.ndarray, max_distance_cells: float, ring_cells: int = 0,
                step: float = 2.0) -> np.ndarray:
    """``dsm`` with its nodata cells inside ``region`` filled by a smooth 2.5-D surface from the cells with data
    (push-pull: :func:`core.io.raster.push_pull`), those at most ``max_distance_cells`` from a cell with data
    (0 = any distance); the others stay NaN.  With ``ring_cells`` the surface is drawn from the low side of each
    hole: the cells within ``ring_cells`` of it more than ``step`` metres above its ring's lowest tenth (a roof
    beside the ground a wall hides) do not pull it up (:func:`raised_borders`)."""
    cv2 = require("cv2", "the DSM hole fill")
    known = np.isfinite(dsm)
    todo = region & ~known
    if not todo.any() or not known.any():
        return dsm
    if max_distance_cells > 0:  # float32 distances (SciPy's would be float64 plus indices: 3 x the memory)
        dist = cv2.distanceTransform((~known).astype(np.uint8), cv2.DIST_L2, 5)
        todo &= dist <= max_distance_cells
        del dist
    rows, cols = np.nonzero(todo)
    if len(rows) == 0:
        return dsm
    # only the window around the holes (plus a margin of data) goes through the pyramid
    pad = 64
    r0, r1 = max(0, rows.min() - pad), min(dsm.shape[0], rows.max() + pad + 1)
    c0, c1 = max(0, cols.min() - pad), min(dsm.shape[1], cols.max() + pad + 1)
    win = dsm[r0:r1, c0:c1]
    base = known[r0:r1, c0:c1] & ~raised_borders(win, todo[r0:r1, c0:c1], ring_cells, step)
    filled = push_pull(np.nan_to_num(win), base)
    out = dsm.copy()
    out[rows, cols] = filled[rows - r0, cols - c0].astype(out.dtype)
    return out


def enclosed_holes(dsm: np.ndarray) -> np.ndarray:
    """The nodata cells of holes that do not touch the raster's edge (surrounded by data)."""
    from scipy import ndimage

    lab, n = ndimage.label(~np.isfinite(dsm))
    if n == 0:
        return np.zeros(dsm.shape, dtype=bool)
    inner = np.ones(n + 1, dtype=bool)
    inner[0] = False
    inner[np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))] = False
    return inner[lab]


SOURCE_REMOVED = 3  # dense/dsm-source.tif: a measured height removed as a blunder (interpolated where a fill reached)


def source_raster(measured: np.ndarray, dsm: np.ndarray, removed: Optional[np.ndarray] = None) -> np.ndarray:
    """uint8 per cell: SOURCE_MEASURED where ``measured``, SOURCE_REMOVED where ``removed`` (a blunder taken out:
    its height in ``dsm``, if any, is interpolated), SOURCE_INTERPOLATED where ``dsm`` holds a height that was not
    measured (a filled hole), 0 = nodata."""
    out = np.where(measured, SOURCE_MEASURED, np.where(np.isfinite(dsm), SOURCE_INTERPOLATED, 0)).astype(np.uint8)
    if removed is not None:
        out[removed & ~measured] = SOURCE_REMOVED
    return out


def remove_speckles(dsm: np.ndarray, max_cells: int = 4) -> np.ndarray:
    """Drop isolated groups of at most ``max_cells`` valid cells (lone matches far from the surface
    are usually wrong); they become holes that fill_small_holes may fill."""
    from scipy import ndimage

    valid = np.isfinite(dsm)
    lab, n = ndimage.label(valid, structure=np.ones((3, 3)))
    if n == 0:
        return dsm
    sizes = np.bincount(lab.ravel())
    small = sizes <= max_cells
    small[0] = False
    out = dsm.copy()
    out[small[lab]] = np.nan
    return out


def rasterize_points(files: Sequence[PointFile], grid: Grid, offset: Sequence[float], cluster_tol: float,
                     progress: Optional[Progress] = None, tile: int = TILE) -> Tuple[np.ndarray, np.ndarray]:
    """Rasterise point files (local frame; world = local + offset) onto ``grid``: (heights float32 with NaN
    for no data, point counts int32).  Tile by tile: memory ~ the points of one tile."""
    progress = progress or NullProgress()
    off = np.asarray(offset, dtype=np.float64)
    dsm = np.full((grid.height, grid.width), np.nan, dtype=np.float32)
    counts = np.zeros((grid.height, grid.width), dtype=np.int32)
    tiles = [(r, c) for r in range(0, grid.height, tile) for c in range(0, grid.width, tile)]
    res = grid.resolution
    for k, (r0, c0) in enumerate(tiles):
        check_cancel(progress)
        h = min(tile, grid.height - r0)
        w = min(tile, grid.width - c0)
        # tile bounds in the local frame
        txmin = grid.x0 + c0 * res - off[0]
        txmax = txmin + w * res
        tymax = grid.y0 - r0 * res - off[1]
        tymin = tymax - h * res
        cells_parts, z_parts = [], []
        for pf in files:
            bx0, by0, bx1, by1 = pf.bbox
            if bx1 < txmin or bx0 > txmax or by1 < tymin or by0 > tymax:
                continue
            xyz, _ = pf.load()
            ix = np.floor((xyz[:, 0].astype(np.float64) - txmin) / res).astype(np.int64)
            iy = np.floor((tymax - xyz[:, 1].astype(np.float64)) / res).astype(np.int64)
            m = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h) & np.isfinite(xyz[:, 2])
            if m.any():
                cells_parts.append(iy[m] * w + ix[m])
                z_parts.append(xyz[m, 2].astype(np.float64) + off[2])
        if cells_parts:
            cells = np.concatenate(cells_parts)
            z = np.concatenate(z_parts)
            del cells_parts, z_parts
            val, cnt = cell_statistic(cells, z, w * h, cluster_tol)
            dsm[r0:r0 + h, c0:c0 + w] = val.reshape(h, w)
            counts[r0:r0 + h, c0:c0 + w] = cnt.reshape(h, w)
        progress.report((k + 1) / len(tiles), f"DSM tile {k + 1}/{len(tiles)}")
    return dsm, counts


def polygon_mask(grid: Grid, polygon_xy: np.ndarray) -> np.ndarray:
    """Boolean mask of the cells (centres) inside a polygon given in world coordinates."""
    cv2 = require("cv2", "the DSM footprint")
    mask = np.zeros((grid.height, grid.width), dtype=np.uint8)
    if len(polygon_xy) < 3:
        return mask.astype(bool)
    p = np.asarray(polygon_xy, dtype=np.float64)
    cols = (p[:, 0] - grid.x0) / grid.resolution - 0.5
    rows = (grid.y0 - p[:, 1]) / grid.resolution - 0.5
    pts = np.round(np.column_stack([cols, rows]) * 16).astype(np.int32)  # 4 fractional bits
    cv2.fillPoly(mask, [pts.reshape(-1, 1, 2)], 1, lineType=cv2.LINE_8, shift=4)
    return mask.astype(bool)


def convex_hull_xy(points_xy: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise vertices) of 2-D points; fewer than 3 distinct points -> as given."""
    pts = np.unique(np.asarray(points_xy, dtype=float), axis=0)
    if len(pts) < 3:
        return pts
    try:
        from scipy.spatial import ConvexHull

        hull = ConvexHull(pts)
    except Exception:  # collinear points (one strip)  # noqa: BLE001
        return pts
    return pts[hull.vertices]


def supporting_views(files: Sequence[PointFile], grid: Grid, offset: Sequence[float], dsm: np.ndarray,
                     tolerance: np.ndarray, progress: Optional[Progress] = None, tile: int = TILE) -> np.ndarray:
    """Per cell of ``dsm``: how many point files (one per image: its fused depth map) hold a point within
    ``tolerance`` (metres, a scalar or per cell) of the cell's height; uint8, 0 where the cell has none."""
    progress = progress or NullProgress()
    off = np.asarray(offset, dtype=np.float64)
    tol = np.broadcast_to(np.asarray(tolerance, dtype=np.float32), dsm.shape)
    views = np.zeros(dsm.shape, dtype=np.uint8)
    res = grid.resolution
    for r0 in range(0, grid.height, tile):
        for c0 in range(0, grid.width, tile):
            check_cancel(progress)
            h, w = min(tile, grid.height - r0), min(tile, grid.width - c0)
            txmin = grid.x0 + c0 * res - off[0]
            tymax = grid.y0 - r0 * res - off[1]
            zt = dsm[r0:r0 + h, c0:c0 + w].reshape(-1)
            tt = np.ascontiguousarray(tol[r0:r0 + h, c0:c0 + w]).reshape(-1)
            acc = views[r0:r0 + h, c0:c0 + w].reshape(-1).astype(np.int32)
            for pf in files:
                bx0, by0, bx1, by1 = pf.bbox
                if bx1 < txmin or bx0 > txmin + w * res or by1 < tymax - h * res or by0 > tymax:
                    continue
                xyz, _ = pf.load()
                ix = np.floor((xyz[:, 0].astype(np.float64) - txmin) / res).astype(np.int64)
                iy = np.floor((tymax - xyz[:, 1].astype(np.float64)) / res).astype(np.int64)
                m = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
                cell = iy[m] * w + ix[m]
                near = np.abs(xyz[m, 2].astype(np.float64) + off[2] - zt[cell]) <= tt[cell]
                hit = np.zeros(h * w, dtype=bool)
                hit[cell[near]] = True
                acc += hit
            views[r0:r0 + h, c0:c0 + w] = np.minimum(acc, 255).reshape(h, w).astype(np.uint8)
    return views
