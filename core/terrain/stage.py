"""The ``terrain`` and ``relief`` stages on a workspace: entry, options, checks and records; the products are
made on files by :mod:`.products` (:func:`.products.build_dtm`, :func:`.products.relief`).

- :func:`build_dtm_workspace`: the workspace's DSM (or :attr:`TerrainOptions.dsm`) -> ``dtm.tif`` with
  ``terrain/dtm-source.tif`` beside it, the DSM stage's LAS point cloud classified to
  ``terrain/points-classified.las``, contours at ``contour_interval`` (GeoPackage).
- :func:`relief_workspace`: rvt-py's visualisations as COGs in ``terrain/relief/<dtm|dsm>-<name>.tif``.
"""
from __future__ import annotations

import os
from typing import Optional

from ..common.files import atomic_copy, file_fingerprint, refuse_overwriting_inputs, same_path
from ..common.progress import Progress
from ..project.layout import Layout
from ..project.stages import DSM, RELIEF, STALE, TERRAIN, run_stage
from ..project.workspace import Workspace
from .contours import check_contours_output
from .options import ReliefStageOptions, TerrainError, TerrainOptions
from .products import DtmOutputs, DtmResult, ReliefResult, build_dtm, relief


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


def build_dtm_workspace(workspace_dir: str, options: Optional[TerrainOptions] = None,
                        progress: Optional[Progress] = None) -> DtmResult:
    """The terrain stage of a workspace: its DSM (or ``options.dsm``) -> DTM, source, classified points, contours
    (and a copy of the contours at ``options.contours_copy``).  No output may be an input (checked before any
    work)."""
    options = options or TerrainOptions()
    dsm, output_dtm, contour_interval = options.dsm, options.output_dtm, options.contour_interval
    contours_copy = options.contours_copy
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    dsm_path = os.path.abspath(dsm) if dsm else lay.dsm()
    if not dsm_path:
        raise TerrainError(f"workspace {ws.root} has no DSM: run 'Build DSM' first (or give a DSM file)")
    if not dsm or (lay.dsm() and same_path(dsm_path, lay.dsm())):
        _refuse_stale(ws, DSM, "DSM", "Build DSM")
    dtm_path = os.path.abspath(output_dtm) if output_dtm else lay.default_dtm
    pc = lay.point_cloud() if options.classify_point_cloud else None
    refuse_overwriting_inputs({"DTM": dtm_path, "contours": contours_copy}, {"DSM": dsm_path, "point cloud": pc},
                              TerrainError)
    if contours_copy:
        check_contours_output(contours_copy)
    params = {"dsm": dsm_path, "output_dtm": dtm_path, "contour_interval": contour_interval,
              "options": _result_options(options.ground)}
    with run_stage(ws, TERRAIN, params, {"dsm": file_fingerprint(dsm_path)}) as run:
        targets = DtmOutputs(dtm_path, lay.dtm_source, lay.contours_gpkg, lay.classified_point_cloud if pc else None)
        r = build_dtm(dsm_path, targets, options.ground, contour_interval, pc, progress)
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


def relief_workspace(workspace_dir: str, options: ReliefStageOptions,
                     progress: Optional[Progress] = None) -> ReliefResult:
    """The relief stage: the visualisations ``options.keys`` of the workspace's DTM (``options.source`` 'dtm') or
    DSM ('dsm'); with ``options.copy_to`` (one visualisation), a copy of it there as well (never over the DTM or
    DSM it is made from)."""
    keys, source, copy_to = list(options.keys), options.source, options.copy_to
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    dem = lay.dtm() if source == "dtm" else lay.dsm()
    if not dem:
        stage = "Build DTM" if source == "dtm" else "Build DSM"
        raise TerrainError(f"workspace {ws.root} has no {source.upper()}: run '{stage}' first")
    _refuse_stale(ws, TERRAIN if source == "dtm" else DSM, source.upper(),
                  "Build DTM" if source == "dtm" else "Build DSM")
    refuse_overwriting_inputs({f"{keys[0]} visualisation" if keys else "visualisation": copy_to},
                              {source.upper(): dem}, TerrainError)
    params = {"source": source, "keys": keys, "options": _result_options(options.relief)}
    inputs = {source: file_fingerprint(dem)}
    recorded = {k: v for k, v in (ws.stage(RELIEF).get("outputs") or {}).items()  # the others made before
                if os.path.isfile(lay.resolve(v))}
    with run_stage(ws, RELIEF, params, inputs) as run:
        r = relief(dem, keys, os.path.dirname(lay.relief("x", source)), source, options.relief, progress,
                   source.upper())
        recorded.update({f"{source}-{k}": lay.rel(p) for k, p in r.paths.items()})
        for k, v in r.timings.items():
            ws.record_timing(RELIEF, f"{source}-{k}", v)
        run.finish(outputs=recorded, results={"cell": r.cell, "radii": r.radii, "source": source})
    r.workspace = ws.root
    if copy_to and not same_path(copy_to, r.paths[keys[0]]):
        r.paths[keys[0]] = atomic_copy(r.paths[keys[0]], copy_to)
    return r


__all__ = ["build_dtm_workspace", "relief_workspace"]
