"""The ``terrain`` and ``relief`` stages: DTM (+ classified point cloud, contours) from the DSM, and relief
visualisations of the DTM (or DSM).

- :func:`build_dtm` / :func:`build_dtm_workspace`: the ground filter (:mod:`.ground`, SMRF) -> ``dtm.tif``, a COG
  on the DSM's exact grid, with ``terrain/dtm-source.tif`` beside it (1 = measured ground, 2 = interpolated under
  a removed object or in a hole of the DSM); the DSM stage's LAS point cloud copied with ASPRS classes 2 (ground)
  / 1 (unclassified) to ``terrain/points-classified.las``; contours at ``contour_interval`` (GeoPackage).
- :func:`relief` / :func:`relief_workspace`: rvt-py's visualisations (:mod:`.relief`) as COGs in
  ``terrain/relief/<dtm|dsm>-<name>.tif``.
- :func:`.contours.write_contours` for any elevation raster.

Any raster input is checked first (:func:`.rasters.read_elevation`): a geographic CRS (degrees), a raster under
16 x 16 cells and one without data are refused, naming the file.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field, replace
from typing import Dict, List, Optional, Sequence

import numpy as np

from ..common.files import atomic_copy, file_fingerprint, refuse_overwriting_inputs, same_path
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..project.layout import Layout
from ..project.stages import DSM, RELIEF, STALE, TERRAIN, run_stage
from ..project.workspace import Workspace
from . import relief as rv
from .classify import classify_las
from .contours import check_contours_output, write_contours
from .ground import filter_ground
from .options import (
    SOURCE_INTERPOLATED,
    SOURCE_MEASURED,
    VISUALISATION_KEYS,
    GroundOptions,
    ReliefOptions,
    TerrainError,
)
from .rasters import check_data, read_elevation, scan, write_classes, write_float_tiles


@dataclass
class DtmResult:
    dtm_path: str
    source_path: str
    dsm_path: str
    cell: float
    ground_fraction: float  # of the DSM's valid cells
    interpolated_fraction: float  # of the DTM's cells
    contours_path: Optional[str] = None
    contour_lines: int = 0
    point_cloud_path: Optional[str] = None
    points: int = 0
    ground_points: int = 0
    workspace: Optional[str] = None
    timings: Dict[str, float] = field(default_factory=dict)
    log_lines: List[str] = field(default_factory=list)


@dataclass
class ReliefResult:
    paths: Dict[str, str]  # visualisation key -> file
    source_path: str
    cell: float
    radii: Dict[str, int]
    workspace: Optional[str] = None
    timings: Dict[str, float] = field(default_factory=dict)


def build_dtm(dsm_path: str, output_dtm: str, options: Optional[GroundOptions] = None,
              source_path: Optional[str] = None, contour_interval: float = 0.0, contours_path: Optional[str] = None,
              point_cloud: Optional[str] = None, classified_point_cloud: Optional[str] = None,
              progress: Optional[Progress] = None) -> DtmResult:
    """The DTM of the DSM ``dsm_path`` (any projected elevation raster) on its grid."""
    progress = progress or NullProgress()
    options = options or GroundOptions()
    t0 = time.time()
    source_path = source_path or os.path.splitext(output_dtm)[0] + "-source.tif"
    if contour_interval and contour_interval > 0:
        contours_path = contours_path or os.path.splitext(output_dtm)[0] + "-contours.gpkg"
    refuse_overwriting_inputs(
        {"DTM": output_dtm, "DTM source raster": source_path,
         "contours": contours_path if contour_interval and contour_interval > 0 else None,
         "classified point cloud": classified_point_cloud if point_cloud else None},
        {"DSM": dsm_path, "point cloud": point_cloud}, TerrainError)
    if contour_interval and contour_interval > 0:
        check_contours_output(contours_path)
    elev = read_elevation(dsm_path, "DSM", whole=False)  # read by tiles
    h, w = elev.shape
    res = filter_ground(elev, elev.cell, options, SubProgress(progress, 0.0, 0.8),
                        check_data=lambda n: check_data(dsm_path, "DSM", n, w, h))
    timings = {"ground_filter": time.time() - t0}
    check_cancel(progress)
    ground_fraction = float(np.count_nonzero(res.ground) / max(res.valid_cells, 1))
    interpolated = float(np.count_nonzero(res.source == SOURCE_INTERPOLATED) / max(np.count_nonzero(res.source), 1))
    meta = {"ARCHAEOORTHO_STAGE": "terrain", "ARCHAEOORTHO_PRODUCT": "dtm", "GROUND_FILTER": "SMRF",
            "SMRF_SLOPE": options.slope, "SMRF_WINDOW_M": options.window, "SMRF_THRESHOLD_M": options.threshold,
            "SMRF_SCALAR": options.scalar, "SOURCE_DSM": os.path.abspath(dsm_path),
            "GROUND_FRACTION": f"{ground_fraction:.4f}"}
    write_float_tiles(output_dtm, lambda r0, r1, c0, c1: res.dtm[r0:r1, c0:c1], elev, "DTM (bare earth)", meta,
                      tile=options.tile, progress=SubProgress(progress, 0.8, 0.88))
    write_classes(source_path, res.source, elev, "DTM source: 1 measured ground, 2 interpolated",
                  {"ARCHAEOORTHO_PRODUCT": "dtm-source", "VALUES": f"{SOURCE_MEASURED}=measured ground, "
                   f"{SOURCE_INTERPOLATED}=interpolated"}, tile=options.tile)
    out = DtmResult(dtm_path=output_dtm, source_path=source_path, dsm_path=dsm_path, cell=elev.cell,
                    ground_fraction=ground_fraction, interpolated_fraction=interpolated, timings=timings)
    out.log_lines.append(f"DTM {elev.shape[1]} x {elev.shape[0]} cells at {elev.cell:g} m: {ground_fraction:.1%} of "
                         f"the DSM's cells ground, {interpolated:.1%} of the DTM interpolated -> {output_dtm}")
    if point_cloud and classified_point_cloud:
        t1 = time.time()
        dtm_elev = replace(elev, path=output_dtm, z=res.dtm)  # the DTM as written (float32, metres)
        out.points, out.ground_points = classify_las(point_cloud, classified_point_cloud, dtm_elev, res.source,
                                                     options.threshold)
        out.point_cloud_path = classified_point_cloud
        timings["classify_points"] = time.time() - t1
        out.log_lines.append(f"point cloud: {out.ground_points} of {out.points} points ground (ASPRS class 2) -> "
                             f"{classified_point_cloud}")
    if contour_interval and contour_interval > 0:
        t1 = time.time()
        out.contours_path = contours_path
        out.contour_lines = write_contours(output_dtm, out.contours_path, contour_interval,
                                           SubProgress(progress, 0.9, 1.0))
        timings["contours"] = time.time() - t1
        out.log_lines.append(f"contours every {contour_interval:g} m: {out.contour_lines} lines -> {out.contours_path}")
    for line in out.log_lines:
        progress.info(line)
    timings["total"] = time.time() - t0
    out.timings = {k: round(v, 3) for k, v in timings.items()}
    return out


def _result_options(options) -> dict:
    """The options a stage's products depend on (its record's parameters): all but the tile size."""
    return {k: v for k, v in vars(options).items() if k != "tile"}


def _refuse_stale(ws: Workspace, stage: str, what: str, run_hint: str) -> None:
    """TerrainError when the workspace's ``what`` (the product of ``stage``) is stale: an earlier stage ran again
    after it was made (a re-georeference into another CRS leaves the old DSM on disk), so a product made from it
    would describe the old block."""
    rec = ws.stage(stage)
    if rec.get("status") == STALE:
        why = f" ({rec['error']})" if rec.get("error") else ""
        raise TerrainError(f"the {what} of workspace {ws.root} is stale: an earlier stage ran again after it was "
                           f"made{why}; run '{run_hint}' again first, or give a {what} file")


def build_dtm_workspace(workspace_dir: str, dsm: Optional[str] = None, output_dtm: Optional[str] = None,
                        contour_interval: float = 0.0, options: Optional[GroundOptions] = None,
                        classify_points: bool = True, progress: Optional[Progress] = None,
                        contours_copy: Optional[str] = None) -> DtmResult:
    """The terrain stage of a workspace: its DSM (or ``dsm``) -> DTM, source, classified points, contours (and a
    copy of the contours at ``contours_copy``).  No output may be an input (checked before any work)."""
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    dsm_path = os.path.abspath(dsm) if dsm else lay.dsm()
    if not dsm_path:
        raise TerrainError(f"workspace {ws.root} has no DSM: run 'Build DSM' first (or give a DSM file)")
    if not dsm or (lay.dsm() and same_path(dsm_path, lay.dsm())):
        _refuse_stale(ws, DSM, "DSM", "Build DSM")
    options = options or GroundOptions()
    dtm_path = os.path.abspath(output_dtm) if output_dtm else lay.default_dtm
    pc = lay.point_cloud() if classify_points else None
    refuse_overwriting_inputs({"DTM": dtm_path, "contours": contours_copy}, {"DSM": dsm_path, "point cloud": pc},
                              TerrainError)
    if contours_copy:
        check_contours_output(contours_copy)
    params = {"dsm": dsm_path, "output_dtm": dtm_path, "contour_interval": contour_interval,
              "options": _result_options(options)}
    with run_stage(ws, TERRAIN, params, {"dsm": file_fingerprint(dsm_path)}) as run:
        r = build_dtm(dsm_path, dtm_path, options, source_path=lay.dtm_source, contour_interval=contour_interval,
                      contours_path=lay.contours_gpkg, point_cloud=pc,
                      classified_point_cloud=lay.classified_point_cloud if pc else None, progress=progress)
        for k, v in r.timings.items():
            if k != "total":
                ws.record_timing(TERRAIN, k, v)
        outputs = {"dtm": lay.rel(dtm_path), "dtm_source": lay.rel(r.source_path)}
        if r.contours_path:
            outputs["contours"] = lay.rel(r.contours_path)
        if r.point_cloud_path:
            outputs["point_cloud"] = lay.rel(r.point_cloud_path)
        run.finish(outputs=outputs, results={"ground_fraction": r.ground_fraction, "cell": r.cell,
                                             "interpolated_fraction": r.interpolated_fraction,
                                             "contour_interval": contour_interval, "contour_lines": r.contour_lines,
                                             "points": r.points, "ground_points": r.ground_points})
    r.workspace = ws.root
    if contours_copy and r.contours_path:
        r.contours_path = atomic_copy(r.contours_path, contours_copy)
    return r


def relief(dem_path: str, keys: Sequence[str], output_dir: str, prefix: str = "dtm",
           options: Optional[ReliefOptions] = None, progress: Optional[Progress] = None,
           what: str = "DTM", outputs: Optional[Dict[str, str]] = None) -> ReliefResult:
    """The visualisations ``keys`` of the elevation raster ``dem_path`` as ``<output_dir>/<prefix>-<key>.tif``
    (or at ``outputs[key]``)."""
    progress = progress or NullProgress()
    options = options or ReliefOptions()
    bad = [k for k in keys if k not in VISUALISATION_KEYS]
    if bad or not keys:
        raise TerrainError(f"unknown relief visualisation(s) {bad or keys}: choose from {', '.join(VISUALISATION_KEYS)}")
    targets = {key: (outputs or {}).get(key) or os.path.join(output_dir, f"{prefix}-{key}.tif") for key in keys}
    refuse_overwriting_inputs({f"{key} visualisation": path for key, path in targets.items()}, {what: dem_path},
                              TerrainError)
    elev = read_elevation(dem_path, what, whole=False)  # read by tiles
    scan(elev, what, options.tile)
    paths, timings = {}, {}
    for i, key in enumerate(keys):
        t0 = time.time()
        sub = SubProgress(progress, i / len(keys), (i + 1) / len(keys))
        sub.report(0.0, f"relief visualisation: {key}")
        path = targets[key]
        lo, hi = rv.DISPLAY_RANGE[key]
        write_float_tiles(path, rv.tiled(key, elev, options, sub), elev, f"{key} ({rv.UNITS[key]})",
                          {"ARCHAEOORTHO_STAGE": "relief", "ARCHAEOORTHO_PRODUCT": f"relief-{key}", "RELIEF": key,
                           "DISPLAY_MIN": lo, "DISPLAY_MAX": hi, "SOURCE": os.path.abspath(dem_path),
                           "RVT_REFERENCE_CELL_M": options.reference_cell},
                          heights=False, tile=rv.tile_cells(key, elev.cell, options))
        paths[key] = path
        timings[key] = round(time.time() - t0, 3)
        progress.info(f"{key}: {path} ({timings[key]:.1f} s)")
    radii = {"svf": rv.cells(options, options.svf_radius, elev.cell, lo=3),
             "slrm": rv.cells(options, options.slrm_radius, elev.cell, cap=False, lo=2),
             "ld_max": rv.cells(options, options.ld_max_radius, elev.cell, lo=3)}
    return ReliefResult(paths=paths, source_path=dem_path, cell=elev.cell, radii=radii, timings=timings)


def relief_workspace(workspace_dir: str, keys: Sequence[str], source: str = "dtm",
                     options: Optional[ReliefOptions] = None, progress: Optional[Progress] = None,
                     copy_to: Optional[str] = None) -> ReliefResult:
    """The relief stage: visualisations of the workspace's DTM (``source`` 'dtm') or DSM ('dsm'); with
    ``copy_to`` (one visualisation), a copy of it there as well (never over the DTM or DSM it is made from)."""
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    if source not in ("dtm", "dsm"):
        raise TerrainError(f"relief source must be 'dtm' or 'dsm', got {source!r}")
    dem = lay.dtm() if source == "dtm" else lay.dsm()
    if not dem:
        stage = "Build DTM" if source == "dtm" else "Build DSM"
        raise TerrainError(f"workspace {ws.root} has no {source.upper()}: run '{stage}' first")
    _refuse_stale(ws, TERRAIN if source == "dtm" else DSM, source.upper(),
                  "Build DTM" if source == "dtm" else "Build DSM")
    if copy_to and len(keys) != 1:
        raise TerrainError("a copy of the relief visualisation needs exactly one visualisation")
    refuse_overwriting_inputs({f"{keys[0]} visualisation" if keys else "visualisation": copy_to},
                              {source.upper(): dem}, TerrainError)
    params = {"source": source, "keys": list(keys), "options": _result_options(options or ReliefOptions())}
    inputs = {source: file_fingerprint(dem)}
    recorded = {k: v for k, v in (ws.stage(RELIEF).get("outputs") or {}).items()  # the others made before
                if os.path.isfile(lay.resolve(v))}
    with run_stage(ws, RELIEF, params, inputs) as run:
        r = relief(dem, keys, os.path.dirname(lay.relief("x", source)), source, options, progress, source.upper())
        recorded.update({f"{source}-{k}": lay.rel(p) for k, p in r.paths.items()})
        for k, v in r.timings.items():
            ws.record_timing(RELIEF, f"{source}-{k}", v)
        run.finish(outputs=recorded, results={"cell": r.cell, "radii": r.radii, "source": source})
    r.workspace = ws.root
    if copy_to and not same_path(copy_to, r.paths[keys[0]]):
        r.paths[keys[0]] = atomic_copy(r.paths[keys[0]], copy_to)
    return r


__all__ = ["build_dtm", "build_dtm_workspace", "relief", "relief_workspace", "DtmResult", "ReliefResult"]
