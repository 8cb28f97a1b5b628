"""The DSM from the fused points: rasterised, cleaned (speckles, blunders), its holes filled inside the camera
centres' hull, written as a COG with its source raster (1 measured, 2 interpolated, 3 removed as a blunder:
:func:`blunders.find_blunders`, 0 nodata) beside it."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..common.progress import Progress, SubProgress, check_cancel
from ..io import raster
from . import grid as gridding
from .blunders import find_blunders
from .grid import PointFile
from .options import DenseOptions
from .pairs import View


@dataclass
class DsmTarget:
    """Where the DSM goes and on what grid: its path and its source raster's, the CRS and the local frame's
    offset in it, the cell size, and the images' ground sample distance (the height tolerances scale with it)."""

    path: str
    source_path: str
    crs: Optional[str]
    offset: np.ndarray
    resolution: float
    gsd: float


def block_centres(centres: Dict[str, np.ndarray], boxes: np.ndarray, progress: Progress) -> np.ndarray:
    """The camera centres (name -> x, y) that span the DSM's grid and hull: those within the points' extent
    (``boxes``: the images' robust (xmin, ymin, xmax, ymax)) grown by its own size on each side.  A camera the
    alignment placed absurdly far (issue 46: one registered on 4 points, 2.3e11 m away) would otherwise ask for a
    grid of 10^11 cells and stop the stage; it is named in the log instead."""
    lo, hi = boxes[:, :2].min(axis=0), boxes[:, 2:].max(axis=0)
    size = float(max(hi - lo))
    keep = {n: c for n, c in centres.items() if np.all(c >= lo - size) and np.all(c <= hi + size)}
    far = sorted(set(centres) - set(keep))
    if far:
        progress.warning(f"{len(far)} camera(s) lie far outside the block's dense points and are left out of the DSM's "
                         f"extent: {', '.join(far[:6])}{' ...' if len(far) > 6 else ''} (check their alignment)")
    return np.array(list(keep.values()) or list(centres.values())).reshape(-1, 2)


def write_dsm(target: DsmTarget, point_files: List[PointFile], views: Dict[int, View], options: DenseOptions,
              metadata: dict, progress: Progress) -> Tuple[raster.Grid, Dict[str, float]]:
    """Rasterise the points, clean the raster, fill its holes inside the cameras' hull, write the COG and its
    source raster; (grid, fractions: 'valid', 'measured', 'interpolated', 'removed' of the cells inside the
    cameras' hull, or of the raster for one strip; 'removed_cells': all the cells removed)."""
    check_cancel(progress)
    offset, res, gsd = target.offset, target.resolution, target.gsd
    boxes = np.array([pf.robust_bbox for pf in point_files if pf.count > 0])
    centres = block_centres({v.name: v.centre[:2] + offset[:2] for v in views.values()}, boxes[:, :4] + np.tile(
        offset[:2], 2), progress)
    # the points' extent, and the whole camera centres' hull: its fractions are judged over all of it (issue 46: the
    # grid was the points' extent alone, and more points at the edge widened it over hull ground measured nowhere)
    xmin = min(boxes[:, 0].min() + offset[0], centres[:, 0].min())
    ymin = min(boxes[:, 1].min() + offset[1], centres[:, 1].min())
    xmax = max(boxes[:, 2].max() + offset[0], centres[:, 0].max())
    ymax = max(boxes[:, 3].max() + offset[1], centres[:, 1].max())
    grid = raster.Grid.covering(xmin, ymin, xmax, ymax, res)
    cluster_tol = max(3 * res, 4 * gsd)
    dsm, _counts = gridding.rasterize_points(point_files, grid, offset, cluster_tol=cluster_tol,
                                             progress=SubProgress(progress, 0.88, 0.92))
    del _counts
    dsm = gridding.remove_speckles(dsm, max_cells=4)
    # blunders: cells fewer than two images confirm, far from the robust surface or the heights of those that are
    # confirmed; small pits fewer than three confirm
    views_ok = gridding.supporting_views(point_files, grid, offset, dsm, cluster_tol)
    removed = find_blunders(dsm, views_ok, gsd, cluster_tol)
    del views_ok
    dsm[removed] = np.nan
    measured = np.isfinite(dsm)
    dsm = gridding.fill_small_holes(dsm, options.max_hole_cells)
    hull = gridding.polygon_mask(grid, gridding.convex_hull_xy(centres))
    if not hull.any():  # one strip: the hull is a line; judge (and fill) the cells the data surrounds
        hull = None
    if options.fill_max_distance > 0:
        check_cancel(progress)
        region = hull if hull is not None else gridding.enclosed_holes(dsm)
        dsm = gridding.fill_region(dsm, region, options.fill_max_distance / res,
                                   ring_cells=max(2, int(round(3.0 / res))), step=2.0)
    source = gridding.source_raster(measured, dsm, removed)
    fractions = _fractions(dsm, source, hull, removed)
    check_cancel(progress)
    _write(target, grid, dsm, source, fractions, metadata, progress)
    return grid, fractions


def describe(grid: raster.Grid, fractions: Dict[str, float], resolution: float, source_name: str) -> str:
    """The log line of a DSM written by write_dsm (``source_name``: its source raster as the user sees it)."""
    return (f"DSM {grid.width} x {grid.height} cells at {resolution:g} m, inside the convex hull of the camera "
            f"centres {100 * fractions['measured']:.1f} % measured, {100 * fractions['interpolated']:.1f} % "
            f"interpolated (filled holes), {100 * fractions['removed']:.1f} % removed as blunders "
            f"({fractions['removed_cells']} cells in all; flagged in {source_name})")


def _fractions(dsm: np.ndarray, source: np.ndarray, hull: Optional[np.ndarray],
               removed: np.ndarray) -> Dict[str, float]:
    judged = source[hull] if hull is not None else source
    have = np.isfinite(dsm[hull]) if hull is not None else np.isfinite(dsm)
    return {"valid": float(have.mean()), "measured": float((judged == raster.SOURCE_MEASURED).mean()),
            "interpolated": float((judged == raster.SOURCE_INTERPOLATED).mean()),
            "removed": float((judged == gridding.SOURCE_REMOVED).mean()), "removed_cells": int(removed.sum())}


def _write(target: DsmTarget, grid: raster.Grid, dsm: np.ndarray, source: np.ndarray, fractions: Dict[str, float],
           metadata: dict, progress: Progress) -> None:
    """The source raster first (a complete DSM always has its own beside it), then the DSM's COG."""
    figures = {"VALID_FRACTION": round(fractions["valid"], 4), "MEASURED_FRACTION": round(fractions["measured"], 4),
               "INTERPOLATED_FRACTION": round(fractions["interpolated"], 4),
               "REMOVED_FRACTION": round(fractions["removed"], 4)}
    raster.write_classes(target.source_path, source, grid.geotransform, target.crs,
                         f"DSM source: {raster.SOURCE_MEASURED} measured, {raster.SOURCE_INTERPOLATED} interpolated, "
                         f"{gridding.SOURCE_REMOVED} removed (a blunder; interpolated where filled)",
                         dict(figures, ARCHAEOORTHO_PRODUCT="dsm-source", DSM=os.path.basename(target.path)))
    raster.write_cog(target.path, dsm, grid.geotransform, target.crs,
                     raster.BandLabel(metadata=dict(metadata, **figures)), SubProgress(progress, 0.92, 0.96))
