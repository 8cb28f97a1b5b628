"""The georeference stage of a workspace: read the control, adjust, save the products.

``georeference_workspace(workspace, options, progress)`` is what the Processing algorithm, the dock and the
pipeline call; :class:`~core.georef.options.GeorefOptions` carries the inputs (GCP file or set, check points,
camera positions, EXIF GPS, CRS) and the adjustment's settings.  It reads the aligned model and the ground
control (``core.georef.control_input``, checked by ``core.georef.control_checks``: a geographic CRS, control far
from the photos' EXIF GPS), runs the adjustment inside ``run_stage()`` (``core.georef.adjustments``)
and saves the products through ``core.project.layout`` (``core.georef.products``: ``georef/model`` in the local
frame, ``transform.json``, the residuals, ``control.json``, the camera layer, ``adjustment_inputs.json``).  With
``GeorefOptions.reference_dem`` the block is co-registered on that DEM after the adjustment and adjusted again
with DEM control points (``core.georef.demcontrol``): ``dem_control.json`` records the co-registration and the
points.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

from ..common.files import file_fingerprint
from ..common.progress import NullProgress, Progress, SubProgress
from ..project.layout import Layout, write_json
from ..project.stages import GEOREFERENCE, StageError, run_stage
from ..project.workspace import Workspace
from . import demcontrol as demmod
from . import products
from .adjustments import adjust_block, adjust_on_dem
from .control_checks import read_checked_control
from .options import GeorefOptions

GEOREF = GEOREFERENCE


@dataclass
class GeorefStageResult:
    workspace: str
    crs: str
    figures: Dict[str, Optional[float]]
    residuals_path: str
    cameras_path: str
    warnings: List[str] = field(default_factory=list)
    outliers: List[str] = field(default_factory=list)
    report_lines: List[str] = field(default_factory=list)
    dem_control: Optional[Dict[str, Any]] = None  # georef/dem_control.json's content, with a reference DEM


def model_path(ws: Workspace) -> str:
    """The newest sparse model of a workspace: georeferenced (local frame) if present, else aligned."""
    return Layout(ws).newest_model_dir()


def load_georef_model(workspace_dir: str):
    """(pycolmap.Reconstruction in the local frame, its core.project.frame.GeorefFrame) of a
    georeferenced workspace.  Raises StageError when the workspace is not georeferenced."""
    ws = Workspace.open(workspace_dir)
    if not ws.stage_done(GEOREF):
        raise StageError(f"workspace {ws.root} is not georeferenced: run 'Georeference' first")
    return Layout(ws).load_georef_model()


def _with_exif_for_dem(opt: GeorefOptions, progress: Progress) -> GeorefOptions:
    """A reference DEM given alone (no GCPs, no camera positions): the photos' EXIF GPS place the block."""
    if opt.reference_dem and not (opt.gcp_path or opt.gcps is not None or opt.camera_positions_path
                                  or opt.use_exif_gps):
        progress.info(f"reference DEM {opt.reference_dem} without ground control or camera positions: the photos' "
                      "EXIF GPS place the block, the DEM fixes its heights, tilt and dome")
        return dataclasses.replace(opt, use_exif_gps=True)
    return opt


def _recorded(opt: GeorefOptions, target: str):
    """(parameters, input fingerprints) the stage's manifest records."""
    params = {"gcps": opt.gcp_path, "check_points": list(opt.check_points),
              "camera_positions": opt.camera_positions_path, "use_exif_gps": opt.use_exif_gps, "crs": target,
              "refine_intrinsics": opt.refine_intrinsics}
    if opt.gcps_upright:
        params["gcps_upright"] = True
    inputs = {k: file_fingerprint(v) for k, v in (("gcps", opt.gcp_path), ("positions", opt.camera_positions_path))
              if v}
    if opt.reference_dem:
        params["reference_dem"] = os.path.abspath(opt.reference_dem)
        inputs["reference_dem"] = file_fingerprint(opt.reference_dem)
    return params, inputs


def georeference_workspace(workspace_dir: str, options: Optional[GeorefOptions] = None,
                           progress: Optional[Progress] = None) -> GeorefStageResult:
    """Georeference an aligned workspace with GCPs and/or camera positions (see core.georef.adjust).

    GCP pixel coordinates are in the stored pixel grid (COLMAP's, EXIF orientation not applied), unless
    ``options.gcps_upright``: then they were measured on the photos shown upright (a browser, most photo viewers)
    and are converted to the stored grid with each photo's EXIF orientation.  ``options.reference_dem`` adds DEM
    control (core.georef.demcontrol); given alone (no GCPs, no camera positions), the photos' EXIF GPS place the
    block."""
    progress = progress or NullProgress()
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    if not lay.has_aligned_model():
        raise StageError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = lay.load_aligned_model()
    opt = _with_exif_for_dem(options if options is not None else GeorefOptions(), progress)
    gcps, cams, target = read_checked_control(ws, opt, progress)
    opt = dataclasses.replace(opt, crs=target)
    if opt.camera_intrinsics is None:  # the alignment's calibrated cameras: fixed ones stay, refined ones get priors
        opt = dataclasses.replace(opt, camera_intrinsics=lay.camera_intrinsics())
    dem_path = opt.reference_dem
    if dem_path:  # a reference off the block or too coarse for it is refused before the adjustment
        progress.report(0.0, "checking the reference DEM against the block")
        demmod.precheck(rec, gcps, cams, opt, dem_path, target)
    params, inputs = _recorded(opt, target)
    dem = None
    with run_stage(ws, GEOREF, params, inputs) as run:
        with run.step("adjustment", save=False):
            result = adjust_block(rec, gcps, cams, opt, SubProgress(progress, 0.0, 0.45 if dem_path else 0.9))
        if dem_path:
            with run.step("dem control", save=False):
                result, gcps, cams, dem = adjust_on_dem(rec, result, gcps, cams, opt, progress)
        source = "file" if opt.camera_positions_path else ("exif" if cams else None)
        outputs, residuals_path, cameras_path = products.save_products(lay, result, gcps, cams, source, target, opt)
        figures = products.figures(result)
        if dem is not None:
            write_json(lay.dem_control_json, dem.as_dict())
            outputs["dem_control"] = lay.rel(lay.dem_control_json)
            figures.update(products.dem_figures(dem))
        ws.crs = target
        run.finish(outputs=outputs, results=figures)
    progress.report(1.0, "georeferenced")
    return GeorefStageResult(workspace=ws.root, crs=target, figures=figures,
                             residuals_path=residuals_path, cameras_path=cameras_path, warnings=list(result.warnings),
                             outliers=[o.message or f"{o.kind} {o.name}: {o.residual:.3g} {o.unit}"
                                       for o in result.outliers],
                             report_lines=products.report_lines(result),
                             dem_control=dem.as_dict() if dem is not None else None)


__all__ = ["GeorefStageResult", "georeference_workspace", "load_georef_model", "model_path"]
