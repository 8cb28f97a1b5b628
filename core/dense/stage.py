"""The ``dsm`` stage: dense matching and fusion of a georeferenced workspace -> DSM GeoTIFF and point cloud.

1. **Pair selection** (:mod:`.pairs`) from the georeferenced sparse model.
2. **Per pair** (:mod:`.stereo`, the unit of work): rectify, semi-global matching, left-right check,
   triangulate -> two depth maps, cached in ``<workspace>/dense/pairs-<key>/`` so a re-run skips finished pairs.
3. **Fusion per image** (:mod:`.fusion`): a pixel that ``min_consistent`` pairs agree on becomes a point.
4. **DSM** (:mod:`.grid`): the fused points are rasterised tile by tile at RESOLUTION (default: 2 x the median
   ground sample distance, and never finer than the matching pixel) with the median of the highest height
   cluster per cell; speckles dropped, small holes filled, the holes inside the convex hull of the camera
   centres filled by a smooth 2.5-D surface up to ``fill_max_distance`` from the data; a float32
   Cloud-Optimized GeoTIFF with overviews in the workspace CRS, written atomically
   (:mod:`core.io.raster`), and beside it ``dense/dsm-source.tif`` on the same grid: 1 = measured, 2 =
   interpolated (every filled cell), 3 = removed (a blunder, :func:`.grid.find_blunders`: a cell fewer than two
   images confirm, far from the robust surface of those that are confirmed; interpolated where a fill reaches),
   0 = nodata.  Optionally a LAS 1.2 point cloud with RGB.

Engine ``cuda`` runs COLMAP's patch-match stereo and fusion instead of 2-3 (:mod:`.points`; only where
pycolmap was built with CUDA: ``pycolmap.has_cuda``); the DSM step is the same.

A workspace that is **not georeferenced is refused** with a clear message: the aligned model has an arbitrary
scale and no vertical direction, so a "DSM" in its frame would be meaningless (heights along an arbitrary
axis).  Georeference with GCPs, camera positions or the images' EXIF GPS first.
"""
from __future__ import annotations

import dataclasses
import math
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..align.photos import check_photos
from ..common.cancel import load_pycolmap
from ..common.files import clean_debris
from ..common.parallel import CANCEL_PREFIX
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io import raster
from ..io.images import ImageError
from ..prepare.masks import find_mask
from ..project.layout import Layout
from ..project.stages import DSM, GEOREFERENCE, run_stage
from ..project.workspace import Workspace
from . import grid as gridding
from .grid import PointFile
from .options import ENGINES, EXECUTION_OPTIONS, QUALITIES, DenseError, DenseOptions
from .pairs import PairInfo, View, auto_resolution, median_gsd, select_pairs, sparse_points, views_from_reconstruction
from .points import cpu_points, cuda_points


@dataclass
class DsmStageResult:
    workspace: str
    dsm_path: str
    point_cloud_path: Optional[str]
    crs: str
    resolution: float
    valid_fraction: Optional[float]
    pairs: int
    pairs_reused: int
    points: int
    timings: Dict[str, float]
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)
    source_path: str = ""  # dense/dsm-source.tif: 1 measured, 2 interpolated, 3 removed (a blunder), 0 nodata
    measured_fraction: Optional[float] = None  # of the cells inside the camera centres' hull
    interpolated_fraction: Optional[float] = None
    removed_fraction: Optional[float] = None
    removed_cells: int = 0


class _Journal:
    """The stage's timings, warnings and log lines (the log lines also go to ``progress``)."""

    def __init__(self, progress: Progress):
        self.progress = progress
        self.t_start = time.time()
        self.timings: Dict[str, float] = {}
        self.warnings: List[str] = []
        self.log: List[str] = []

    def warn(self, msg: str) -> None:
        self.warnings.append(msg)
        self.progress.warning(msg)

    def info(self, line: str) -> None:
        self.log.append(line)
        self.progress.info(line)


def build_dsm_workspace(workspace_dir: str, resolution: float = 0.0, quality: Optional[str] = None,
                        engine: str = "cpu", output_dsm: Optional[str] = None,
                        output_point_cloud: Optional[str] = None, options: Optional[DenseOptions] = None,
                        progress: Optional[Progress] = None) -> DsmStageResult:
    """The DSM stage: dense matching + fusion -> ``dsm.tif`` (COG) and optionally a LAS point cloud.

    ``quality`` None: ``options.quality`` (the options are the settings; a keyword given wins over them).
    ``options`` is not changed (the stage works on a copy with ``quality`` filled in).
    Raises DenseError (bad input, nothing matched), WorkspaceError, Cancelled."""
    progress = progress or NullProgress()
    options, engine = _checked_arguments(options, quality, engine, resolution)
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    _require_georeferenced(ws, lay)
    if engine == "cuda":
        pycolmap = load_pycolmap("dense matching on CUDA")
        if not getattr(pycolmap, "has_cuda", False):
            raise DenseError("ENGINE 'cuda' needs pycolmap built with CUDA (pycolmap.has_cuda is False here); "
                             "use ENGINE 'cpu'")
    job = _Journal(progress)
    rec, frame = lay.load_georef_model()
    offset = frame.offset
    crs = frame.crs or ws.crs
    images_dir = ws.data.get("images_dir") or ""
    views = _views(ws, rec, images_dir)
    for note in _check_photos(ws, views):
        job.info(note)

    # 1. pairs
    t_pairs = time.time()
    xyz, tracks = sparse_points(rec)
    pairs, stats = _pairs(views, xyz, tracks, options)
    gsd = median_gsd(views, xyz, tracks)
    res = float(resolution) if resolution and resolution > 0 else auto_resolution(gsd, options.scale)
    _check_resolution(resolution, gsd, xyz, auto_resolution(gsd, options.scale))
    job.timings["pair_selection"] = time.time() - t_pairs
    job.info(f"pairs: {len(pairs)} selected from {stats['candidates']} overlapping image pairs "
             f"({len(views)} images, quality {options.quality}, median GSD {gsd:.3f} m, DSM resolution {res:g} m)")

    dsm_path = os.path.abspath(output_dsm) if output_dsm else lay.default_dsm
    pc_path = os.path.abspath(output_point_cloud) if output_point_cloud else None
    model_fp = lay.model_fingerprints(prefix="")
    params = {"resolution": resolution, "quality": options.quality, "engine": engine, "output_dsm": dsm_path,
              "output_point_cloud": pc_path, "options": {k: v for k, v in dataclasses.asdict(options).items()
                                                         if k not in EXECUTION_OPTIONS}}
    with run_stage(ws, DSM, params, model_fp) as run:
        os.makedirs(lay.dense_dir, exist_ok=True)
        for debris in clean_debris(lay.dense_dir, CANCEL_PREFIX):
            job.info(f"removed {debris}, left by a killed run")
        if engine == "cuda":
            point_files, n_reused = cuda_points(views, options.scale, lay.dense_dir, lay.georef_model_dir,
                                                images_dir, model_fp, SubProgress(progress, 0.02, 0.88))
            job.timings["matching"] = time.time() - t_pairs
            n_pairs = 0
        else:
            point_files, n_pairs, n_reused, mt = cpu_points(views, pairs, xyz, options, lay.dense_dir, model_fp,
                                                            progress, job.warn, job.log)
            job.timings.update(mt)
        n_points = sum(pf.count for pf in point_files)
        if n_points == 0:
            raise DenseError("dense matching found no consistent surface point: the pairs matched but no pixel was "
                             f"confirmed by {options.min_consistent} independent pairs (too little texture or overlap?)")
        job.info(f"points: {n_points} fused from {len(point_files)} images")

        # 4. DSM
        t0 = time.time()
        meta = {"ARCHAEOORTHO_STAGE": "dsm", "RESOLUTION": res, "QUALITY": options.quality, "ENGINE": engine,
                "PAIRS": n_pairs, "POINTS": n_points}
        grid, fractions = _write_dsm(dsm_path, lay.dsm_source, point_files, views, offset, crs, res, gsd, options,
                                     meta, progress)
        valid_fraction = fractions["valid"]
        job.timings["dsm"] = time.time() - t0

        # 5. point cloud
        if pc_path:
            t0 = time.time()
            n_written = raster.write_las(pc_path, gridding.stream_point_files(point_files), offset, crs,
                                         progress=SubProgress(progress, 0.97, 1.0), total=n_points)
            job.timings["point_cloud"] = time.time() - t0
            job.log.append(f"point cloud: {n_written} points -> {pc_path}")
        job.timings["total"] = time.time() - job.t_start
        job.log.append("seconds: " + ", ".join(f"{k.replace('_', ' ')} {v:.1f}" for k, v in job.timings.items()))
        job.log.append(f"DSM {grid.width} x {grid.height} cells at {res:g} m, inside the convex hull of the camera "
                       f"centres {100 * fractions['measured']:.1f} % measured, {100 * fractions['interpolated']:.1f} % "
                       f"interpolated (filled holes), {100 * fractions['removed']:.1f} % removed as blunders "
                       f"({fractions['removed_cells']} cells in all; flagged in {lay.rel(lay.dsm_source)})")
        for line in job.log[-2:]:
            progress.info(line)
        for k, v in job.timings.items():
            if k != "total":
                ws.record_timing(DSM, k, v)
        outputs = {"dsm": lay.rel(dsm_path), "dsm_source": lay.rel(lay.dsm_source)}
        if pc_path:
            outputs["point_cloud"] = lay.rel(pc_path)
        run.finish(outputs=outputs,
                   results={"VALID_FRACTION": valid_fraction, "MEASURED_FRACTION": fractions["measured"],
                            "INTERPOLATED_FRACTION": fractions["interpolated"],
                            "REMOVED_FRACTION": fractions["removed"], "removed_cells": fractions["removed_cells"],
                            "pairs": n_pairs, "pairs_reused": n_reused,
                            "points": n_points, "resolution": res, "gsd": gsd, "width": grid.width,
                            "height": grid.height, "warnings": job.warnings})
    progress.report(1.0, "DSM done")  # its size and fractions are in the log line above (once: issue 36 item 21)
    return DsmStageResult(workspace=ws.root, dsm_path=dsm_path, point_cloud_path=pc_path, crs=crs or "",
                          resolution=res, valid_fraction=valid_fraction, pairs=n_pairs, pairs_reused=n_reused,
                          points=n_points, timings={k: round(v, 3) for k, v in job.timings.items()},
                          warnings=job.warnings, log_lines=job.log, source_path=lay.dsm_source,
                          measured_fraction=fractions["measured"], interpolated_fraction=fractions["interpolated"],
                          removed_fraction=fractions["removed"], removed_cells=fractions["removed_cells"])


def _checked_arguments(options: Optional[DenseOptions], quality: str, engine: str,
                       resolution: float) -> Tuple[DenseOptions, str]:
    """(a copy of ``options`` with the QUALITY filled in, the engine); DenseError for a bad argument."""
    options = options or DenseOptions()
    quality = (quality or options.quality).lower()
    if quality not in QUALITIES:
        raise DenseError(f"unknown QUALITY {quality!r}; choose one of {', '.join(QUALITIES)}")
    options = dataclasses.replace(options, quality=quality)
    engine = (engine or "cpu").lower()
    if engine not in ENGINES:
        raise DenseError(f"unknown ENGINE {engine!r}; choose one of {', '.join(ENGINES)}")
    if resolution is None or resolution < 0 or not math.isfinite(resolution):
        raise DenseError(f"RESOLUTION must be 0 (automatic) or a positive number of metres, got {resolution}")
    return options, engine


def _require_georeferenced(ws: Workspace, lay: Layout) -> None:
    if not lay.is_georeferenced():
        state = ws.stage(GEOREFERENCE).get("status", "pending")
        raise DenseError(
            f"workspace {ws.root} is not georeferenced (georeference stage: {state}): run 'Georeference' first, "
            "with ground control points, camera positions or the images' EXIF GPS. The aligned model alone has "
            "an arbitrary scale and no vertical direction, so no DSM is built from it.")


def _views(ws: Workspace, rec, images_dir: str) -> Dict[int, View]:
    """The model's views; DenseError for fewer than two or for images missing from ``images_dir``."""
    views = views_from_reconstruction(rec, images_dir)
    if len(views) < 2:
        raise DenseError(f"the model of {ws.root} has {len(views)} registered image(s): dense matching needs 2 or more")
    masks_dir = Layout(ws).masks_dir
    for v in views.values():  # the sky masks (and any other): no dense point from their black pixels
        v.mask_path = find_mask(masks_dir, v.name)
    missing = [v.name for v in views.values() if not os.path.isfile(v.path)]
    if missing:
        raise DenseError(f"{len(missing)} image(s) of the model are missing from {images_dir}: "
                         f"{', '.join(missing[:8])}{' ...' if len(missing) > 8 else ''}")
    return views


def _check_photos(ws: Workspace, views: Dict[int, View]) -> List[str]:
    """The photos about to be matched against the alignment's (core.align.photos); DenseError naming the missing,
    unreadable or changed ones, notes for the log of an older workspace."""
    try:
        return check_photos(ws, {v.name: v.path for v in views.values()})
    except ImageError as e:
        raise DenseError(str(e)) from e


MAX_DSM_CELLS = 50_000 * 50_000  # a RESOLUTION giving more cells over the block is refused before matching


def _check_resolution(resolution: float, gsd: float, xyz: np.ndarray, auto: float) -> None:
    """DenseError, before any matching, for a RESOLUTION that cannot make a sensible DSM of this block: finer
    than a tenth of the ground sample distance, over MAX_DSM_CELLS cells, or under 2 cells across the block
    (its extent: the 1st to 99th percentile of the tie points)."""
    if not resolution or resolution <= 0 or len(xyz) == 0:
        return  # automatic
    res = float(resolution)
    hint = f"give 0 (automatic: {auto:.3g} m here)"
    if math.isfinite(gsd) and gsd > 0 and res < gsd / 10:
        raise DenseError(f"RESOLUTION {res:g} m is finer than a tenth of the images' ground sample distance "
                         f"({gsd:.3g} m): the photos hold no detail at that scale; {hint} or {gsd / 10:.3g} m or more")
    lo, hi = np.percentile(xyz[:, :2], [1, 99], axis=0)
    width, height = (float(v) for v in hi - lo)
    cols, rows = math.ceil(width / res) + 1, math.ceil(height / res) + 1
    if cols * rows > MAX_DSM_CELLS:
        raise DenseError(f"RESOLUTION {res:g} m would make a DSM of {cols:,} x {rows:,} cells over the block's "
                         f"{width:.0f} x {height:.0f} m (more than 50,000 x 50,000); {hint} or a coarser one")
    if res > max(width, height) / 2:
        raise DenseError(f"RESOLUTION {res:g} m is coarser than half the block's extent ({width:.0f} x {height:.0f} "
                         f"m): the DSM would have fewer than 2 cells across; {hint} or a finer one")


def _pairs(views: Dict[int, View], xyz: np.ndarray, tracks: Sequence[np.ndarray],
           options: DenseOptions) -> Tuple[List[PairInfo], Dict[str, int]]:
    """The stereo pairs and the selection's counts; DenseError saying why when no pair passes."""
    pairs, stats = select_pairs(views, xyz, tracks, options)
    if not pairs:
        raise DenseError(
            f"no stereo pair passed the selection among {len(views)} images ({stats['candidates']} image pairs share "
            f"tie points: {stats['few_shared_points']} with fewer than {options.min_shared_points} shared points, "
            f"{stats['baseline_too_short']} with a baseline under {options.min_baseline_ratio:g} x depth, "
            f"{stats['baseline_too_long']} over {options.max_baseline_ratio:g} x depth, {stats['view_angle']} with "
            f"views more than {options.max_view_angle:g} degrees apart). The images need stereo overlap (60 % or more "
            "along the strip) taken from different positions.")
    return pairs, stats


def _write_dsm(dsm_path: str, source_path: str, point_files: List[PointFile], views: Dict[int, View],
               offset: np.ndarray, crs: Optional[str], res: float, gsd: float, options: DenseOptions, metadata: dict,
               progress: Progress) -> Tuple[raster.Grid, Dict[str, float]]:
    """Rasterise the points, clean the raster, fill its holes inside the cameras' hull, write the COG and its
    source raster (1 measured, 2 interpolated, 3 removed as a blunder: :func:`grid.find_blunders`); (grid,
    fractions: 'valid', 'measured', 'interpolated', 'removed' of the cells inside the cameras' hull, or of the
    raster for one strip; 'removed_cells': all the cells removed)."""
    check_cancel(progress)
    boxes = np.array([pf.robust_bbox for pf in point_files if pf.count > 0])
    xmin, ymin = boxes[:, 0].min() + offset[0], boxes[:, 1].min() + offset[1]
    xmax, ymax = boxes[:, 2].max() + offset[0], boxes[:, 3].max() + offset[1]
    grid = raster.Grid.covering(xmin, ymin, xmax, ymax, res)
    cluster_tol = max(3 * res, 4 * gsd)
    dsm, _counts = gridding.rasterize_points(point_files, grid, offset, cluster_tol=cluster_tol,
                                             progress=SubProgress(progress, 0.88, 0.92))
    del _counts
    dsm = gridding.remove_speckles(dsm, max_cells=4)
    # blunders: cells fewer than two images confirm, far from the robust surface of those that are confirmed
    views_ok = gridding.supporting_views(point_files, grid, offset, dsm, cluster_tol)
    removed = gridding.find_blunders(dsm, views_ok, gsd)
    del views_ok
    dsm[removed] = np.nan
    measured = np.isfinite(dsm)
    dsm = gridding.fill_small_holes(dsm, options.max_hole_cells)
    centres = np.array([v.centre[:2] + offset[:2] for v in views.values()])
    hull = gridding.polygon_mask(grid, gridding.convex_hull_xy(centres))
    if not hull.any():  # one strip: the hull is a line; judge (and fill) the cells the data surrounds
        hull = None
    if options.fill_max_distance > 0:
        check_cancel(progress)
        region = hull if hull is not None else gridding.enclosed_holes(dsm)
        dsm = gridding.fill_region(dsm, region, options.fill_max_distance / res,
                                   ring_cells=max(2, int(round(3.0 / res))), step=2.0)
    source = gridding.source_raster(measured, dsm, removed)
    judged = source[hull] if hull is not None else source
    have = np.isfinite(dsm[hull]) if hull is not None else np.isfinite(dsm)
    fractions = {"valid": float(have.mean()), "measured": float((judged == raster.SOURCE_MEASURED).mean()),
                 "interpolated": float((judged == raster.SOURCE_INTERPOLATED).mean()),
                 "removed": float((judged == gridding.SOURCE_REMOVED).mean()), "removed_cells": int(removed.sum())}
    check_cancel(progress)
    figures = {"VALID_FRACTION": round(fractions["valid"], 4), "MEASURED_FRACTION": round(fractions["measured"], 4),
               "INTERPOLATED_FRACTION": round(fractions["interpolated"], 4),
               "REMOVED_FRACTION": round(fractions["removed"], 4)}
    # the source first: a complete DSM always has its own beside it
    raster.write_classes(source_path, source, grid.geotransform, crs,
                         f"DSM source: {raster.SOURCE_MEASURED} measured, {raster.SOURCE_INTERPOLATED} interpolated, "
                         f"{gridding.SOURCE_REMOVED} removed (a blunder; interpolated where filled)",
                         dict(figures, ARCHAEOORTHO_PRODUCT="dsm-source", DSM=os.path.basename(dsm_path)))
    raster.write_cog(dsm_path, dsm, grid.geotransform, crs, progress=SubProgress(progress, 0.92, 0.96),
                     metadata=dict(metadata, **figures))
    return grid, fractions
