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
   interpolated (every filled cell), 3 = removed (a blunder, :func:`.blunders.find_blunders`: a cell fewer than two
   images confirm, far from the robust surface of those that are confirmed, or a small pit fewer than three
   confirm; interpolated where a fill reaches),
   0 = nodata.  Optionally a LAS 1.2 point cloud with RGB.

Engine ``cuda`` runs COLMAP's patch-match stereo and fusion instead of 2-3 (:mod:`.points`; only where
pycolmap was built with CUDA: ``pycolmap.has_cuda``); the DSM step is the same.

A workspace that is **not georeferenced is refused** with a clear message: the aligned model has an arbitrary
scale and no vertical direction, so a "DSM" in its frame would be meaningless (heights along an arbitrary
axis).  Georeference with GCPs, camera positions or the images' EXIF GPS first.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from ..common.cancel import load_pycolmap
from ..common.files import clean_debris
from ..common.parallel import CANCEL_PREFIX
from ..common.progress import NullProgress, Progress, SubProgress
from ..project.layout import Layout
from ..project.stages import DSM, GEOREFERENCE, run_stage
from ..project.workspace import Workspace
from .block import load_block
from .dsm import DsmTarget, describe, write_dsm
from .journal import Journal
from .options import DenseError, DenseOptions
from .points import dense_points


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


def build_dsm_workspace(workspace_dir: str, options: Optional[DenseOptions] = None,
                        progress: Optional[Progress] = None) -> DsmStageResult:
    """The DSM stage: dense matching + fusion -> ``dsm.tif`` (COG) and optionally a LAS point cloud, as
    ``options`` say (quality, resolution, engine, outputs; checked when the options are made).
    Raises DenseError (bad input, nothing matched), WorkspaceError, Cancelled."""
    progress = progress or NullProgress()
    options = options or DenseOptions()
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    _require_georeferenced(ws, lay)
    if options.engine == "cuda":
        _require_cuda()
    job = Journal(progress)
    block = load_block(lay, options, job.info)
    res = block.resolution
    job.timings["pair_selection"] = block.seconds
    job.info(f"pairs: {len(block.pairs)} selected from {block.candidates} overlapping image pairs "
             f"({len(block.views)} images, quality {options.quality}, median GSD {block.gsd:.3f} m, DSM resolution "
             f"{res:g} m)")
    dsm_path = options.output_dsm or lay.default_dsm
    pc_path = options.output_point_cloud
    model_fp = lay.model_fingerprints(prefix="")
    with run_stage(ws, DSM, options.stage_parameters(dsm_path), model_fp) as run:
        os.makedirs(lay.dense_dir, exist_ok=True)
        for debris in clean_debris(lay.dense_dir, CANCEL_PREFIX):
            job.info(f"removed {debris}, left by a killed run")
        points = dense_points(block, options, lay, model_fp, progress, job)
        n_points = points.count
        job.info(f"points: {n_points} fused from {len(points.files)} images")

        # 4. DSM
        t0 = time.time()
        meta = {"ARCHAEOORTHO_STAGE": "dsm", "RESOLUTION": res, "QUALITY": options.quality, "ENGINE": options.engine,
                "PAIRS": points.pairs, "POINTS": n_points}
        target = DsmTarget(dsm_path, lay.dsm_source, block.crs, block.offset, res, block.gsd)
        grid, fractions = write_dsm(target, points.files, block.views, options, meta, progress)
        job.timings["dsm"] = time.time() - t0

        # 5. point cloud
        if pc_path:
            t0 = time.time()
            n_written = points.write_las(pc_path, block.offset, block.crs, SubProgress(progress, 0.97, 1.0))
            job.timings["point_cloud"] = time.time() - t0
            job.note(f"point cloud: {n_written} points -> {pc_path}")
        job.close()
        job.note(describe(grid, fractions, res, lay.rel(lay.dsm_source)))
        for line in job.log[-2:]:
            progress.info(line)
        job.record_timings(ws, DSM)
        outputs = {"dsm": lay.rel(dsm_path), "dsm_source": lay.rel(lay.dsm_source)}
        if pc_path:
            outputs["point_cloud"] = lay.rel(pc_path)
        run.finish(outputs=outputs,
                   results={"VALID_FRACTION": fractions["valid"], "MEASURED_FRACTION": fractions["measured"],
                            "INTERPOLATED_FRACTION": fractions["interpolated"],
                            "REMOVED_FRACTION": fractions["removed"], "removed_cells": fractions["removed_cells"],
                            "pairs": points.pairs, "pairs_reused": points.reused,
                            "points": n_points, "resolution": res, "gsd": block.gsd, "width": grid.width,
                            "height": grid.height, "warnings": job.warnings})
    progress.report(1.0, "DSM done")  # its size and fractions are in the log line above (once: issue 36 item 21)
    return DsmStageResult(workspace=ws.root, dsm_path=dsm_path, point_cloud_path=pc_path, crs=block.crs or "",
                          resolution=res, valid_fraction=fractions["valid"], pairs=points.pairs,
                          pairs_reused=points.reused, points=n_points,
                          timings={k: round(v, 3) for k, v in job.timings.items()}, warnings=job.warnings,
                          log_lines=job.log, source_path=lay.dsm_source, measured_fraction=fractions["measured"],
                          interpolated_fraction=fractions["interpolated"], removed_fraction=fractions["removed"],
                          removed_cells=fractions["removed_cells"])


def _require_georeferenced(ws: Workspace, lay: Layout) -> None:
    if not lay.is_georeferenced():
        state = ws.stage(GEOREFERENCE).get("status", "pending")
        raise DenseError(
            f"workspace {ws.root} is not georeferenced (georeference stage: {state}): run 'Georeference' first, "
            "with ground control points, camera positions or the images' EXIF GPS. The aligned model alone has "
            "an arbitrary scale and no vertical direction, so no DSM is built from it.")


def _require_cuda() -> None:
    pycolmap = load_pycolmap("dense matching on CUDA")
    if not getattr(pycolmap, "has_cuda", False):
        raise DenseError("ENGINE 'cuda' needs pycolmap built with CUDA (pycolmap.has_cuda is False here); "
                         "use ENGINE 'cpu'")
