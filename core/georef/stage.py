"""The georeference stage of a workspace: read the control, adjust, save the products.

``georeference_workspace`` is what the Processing algorithm, the dock and the pipeline call.  It reads the
aligned model and the ground control, runs :func:`core.georef.adjust.georeference` inside ``run_stage()``
and saves, through ``core.project.layout``: ``georef/model`` (local frame), ``transform.json``,
``residuals.json``, ``residuals.gpkg``, ``control.json``, the camera layer, and ``adjustment_inputs.json``
(the GCPs with roles and sigmas, the camera positions with sigmas and the target CRS the adjustment used,
which ``core.georef.uncertainty`` reads back).  With ``GeorefOptions.reference_dem`` the block is co-registered on
that DEM after the adjustment and adjusted again with DEM control points (``core.georef.demcontrol``):
``dem_control.json`` records the co-registration and the points.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..align.mapping import camera_rows
from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output, atomic_write_text, file_fingerprint
from ..common.progress import NullProgress, Progress, SubProgress
from ..geometry.crs import transform_points, utm_epsg_for_lonlat
from ..io import gcp as gcpmod
from ..io.images import exif_orientation
from ..io.vector import write_cameras_gpkg, write_points_gpkg
from ..project.layout import Layout, write_json
from ..project.stages import GEOREFERENCE, StageError, run_stage
from ..project.workspace import Workspace
from . import accuracy
from . import demcontrol as demmod
from .adjust import georeference
from .coregister import CoregError
from .options import EXIF_SIGMA_XY, EXIF_SIGMA_Z, GeorefOptions
from .results import GeorefResult

GEOREF = GEOREFERENCE
ADJUSTMENT_INPUTS_FORMAT = "archaeoortho-adjustment-inputs"


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


def _exif_positions(ws: Workspace, crs: str) -> List[gcpmod.CameraPosition]:
    rows = [(im["name"], im["gps"]) for im in ws.data.get("images", []) if im.get("gps")]
    if not rows:
        return []
    lonlat = np.array([[g[0], g[1], 0.0] for _, g in rows], dtype=float)
    xy = transform_points(lonlat, "EPSG:4326", crs)
    # EXIF altitude is kept as it is (normally above mean sea level): only X and Y are transformed
    return [gcpmod.CameraPosition(image=n, x=float(p[0]), y=float(p[1]), z=float(g[2]),
                                  sigma_xy=EXIF_SIGMA_XY, sigma_z=EXIF_SIGMA_Z, sigma_given=False)
            for (n, g), p in zip(rows, xy)]


def _file_positions(path: str, crs: str) -> List[gcpmod.CameraPosition]:
    src_crs, cams = gcpmod.read_camera_positions(path)
    if src_crs and crs and src_crs != crs:
        xyz = np.array([[c.x, c.y, 0.0] for c in cams], dtype=float)
        out = transform_points(xyz, src_crs, crs)
        for c, p in zip(cams, out):
            c.x, c.y = float(p[0]), float(p[1])
    return cams


def _default_crs(ws: Workspace) -> Optional[str]:
    gps = [im["gps"] for im in ws.data.get("images", []) if im.get("gps")]
    if not gps:
        return None
    lon = float(np.mean([g[0] for g in gps]))
    lat = float(np.mean([g[1] for g in gps]))
    return f"EPSG:{utm_epsg_for_lonlat(lon, lat)}"


def photo_orientations(ws: Workspace) -> Dict[str, int]:
    """{image: EXIF orientation} of the workspace's photos that a photo viewer shows turned (not 1): as the
    alignment recorded it, else read from the photo's header."""
    out: Dict[str, int] = {}
    for im in ws.data.get("images", []):
        o = im.get("orientation")
        if o is None:
            path = im.get("path") or os.path.join(ws.data.get("images_dir") or "", im["name"])
            o = exif_orientation(path) if os.path.isfile(path) else 1
        if int(o) != 1:
            out[im["name"]] = int(o)
    return out


def _read_control(ws: Workspace, gcp_path: Optional[str], gcps: Optional[gcpmod.GCPSet], check_points: Sequence[str],
                  camera_positions_path: Optional[str], use_exif_gps: bool, crs: Optional[str],
                  progress: Progress, gcps_upright: bool = False
                  ) -> Tuple[Optional[gcpmod.GCPSet], List[gcpmod.CameraPosition], str]:
    """The ground control in the target CRS: (GCPs, camera positions, target CRS); StageError when it is
    not enough to georeference.  Observations in photos that are not in the workspace are left out with a
    warning (an error when none is in one of its photos); ``gcps_upright``: the pixel coordinates were measured
    on upright photos (EXIF orientation applied) and are converted to the stored grid."""
    sizes = {im["name"]: (im["width"], im["height"]) for im in ws.data.get("images", [])}
    upright = photo_orientations(ws) if gcps_upright else None
    if gcps_upright and not upright:
        progress.info("GCP coordinates measured on upright photos: no photo of the block is stored turned (EXIF "
                      "orientation 1 or none), nothing to convert")
    if gcp_path:
        # a CSV points file without a CRS line takes the CRS parameter
        gcps = gcpmod.read_gcps(gcp_path, image_names=list(sizes), image_sizes=sizes, default_crs=crs,
                                upright_orientations=upright)
    elif gcps is not None and upright:
        gcps = gcpmod.observations_to_stored(copy.deepcopy(gcps), sizes, upright)
    if gcps is not None and check_points:
        gcpmod.apply_check_points(gcps, list(check_points))
    positions_crs = gcpmod.read_camera_positions(camera_positions_path)[0] if camera_positions_path else None
    target = (crs or (gcps.crs if gcps is not None else None) or ws.crs or positions_crs or _default_crs(ws))
    if not target:
        raise StageError("no target CRS: give CRS, or GCPs or camera positions with a CRS line, or images with "
                         "EXIF GPS")
    if gcps is not None:
        gcpmod.check_units(gcps, target)
        if gcps.crs and crs and gcps.crs != crs:
            xyz = np.array([[p.x, p.y, p.z] for p in gcps.points], dtype=float)
            out = transform_points(xyz, gcps.crs, crs)
            for p, q in zip(gcps.points, out):
                p.x, p.y = float(q[0]), float(q[1])
            gcps.crs = crs
    cams: List[gcpmod.CameraPosition] = []
    if camera_positions_path:
        cams = _file_positions(camera_positions_path, target)
    elif use_exif_gps:
        cams = _exif_positions(ws, target)
        if not cams:
            progress.warning("USE_EXIF_GPS is set but no image carries EXIF GPS")
    # a control point whose observations were all dropped (outside the image, unknown image) controls nothing
    n_control = sum(1 for p in gcps.points if p.role == gcpmod.CONTROL and p.observations) if gcps else 0
    if n_control < 3 and len(cams) < 3:
        found = "; ".join(f"{p.name} ({p.role}, {p.describe_observations()})" for p in gcps.points) if gcps else "none"
        raise StageError(gcpmod.with_warnings(
            f"georeferencing needs at least 3 control points (or 3 camera positions); found {n_control} control "
            f"point(s) with observations and {len(cams)} camera position(s). Points: {found}", gcps.warnings if gcps else []))
    return gcps, cams, target


def georeference_workspace(workspace_dir: str, gcp_path: Optional[str] = None,
                           gcps: Optional[gcpmod.GCPSet] = None, check_points: Sequence[str] = (),
                           camera_positions_path: Optional[str] = None, use_exif_gps: bool = False,
                           crs: Optional[str] = None, refine_intrinsics: bool = False,
                           progress: Optional[Progress] = None,
                           options: Optional[GeorefOptions] = None, gcps_upright: bool = False) -> GeorefStageResult:
    """Georeference an aligned workspace with GCPs and/or camera positions (see core.georef.adjust).

    GCP pixel coordinates are in the stored pixel grid (COLMAP's, EXIF orientation not applied), unless
    ``gcps_upright``: then they were measured on the photos shown upright (a browser, most photo viewers) and
    are converted to the stored grid with each photo's EXIF orientation.

    ``options``: further :class:`~core.georef.options.GeorefOptions` of the adjustment (``refine_intrinsics``
    and the target CRS come from the keywords).  Its ``reference_dem`` adds DEM control (core.georef.demcontrol);
    given alone (no GCPs, no camera positions), the photos' EXIF GPS place the block."""
    progress = progress or NullProgress()
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    if not lay.has_aligned_model():
        raise StageError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = lay.load_aligned_model()
    dem_path = options.reference_dem if options is not None else None
    if dem_path and not (gcp_path or gcps is not None or camera_positions_path or use_exif_gps):
        use_exif_gps = True
        progress.info(f"reference DEM {dem_path} without ground control or camera positions: the photos' EXIF GPS "
                      "place the block, the DEM fixes its heights, tilt and dome")
    gcps, cams, target = _read_control(ws, gcp_path, gcps, check_points, camera_positions_path, use_exif_gps, crs,
                                       progress, gcps_upright=gcps_upright)
    params = {"gcps": gcp_path, "check_points": list(check_points), "camera_positions": camera_positions_path,
              "use_exif_gps": use_exif_gps, "crs": target, "refine_intrinsics": refine_intrinsics}
    if gcps_upright:
        params["gcps_upright"] = True
    inputs = {k: file_fingerprint(v) for k, v in (("gcps", gcp_path), ("positions", camera_positions_path)) if v}
    opt = GeorefOptions.of(options, refine_intrinsics=refine_intrinsics, crs=target)
    if opt.camera_intrinsics is None:  # the alignment's calibrated cameras: fixed ones stay, refined ones get priors
        opt = dataclasses.replace(opt, camera_intrinsics=lay.camera_intrinsics())
    if dem_path:  # a reference off the block or too coarse for it is refused before the adjustment
        progress.report(0.0, "checking the reference DEM against the block")
        demmod.precheck(rec, gcps, cams, opt, dem_path, target)
        params["reference_dem"] = os.path.abspath(dem_path)
        inputs["reference_dem"] = file_fingerprint(dem_path)
    dem = None
    with run_stage(ws, GEOREF, params, inputs) as run:
        with run.step("adjustment", save=False):
            result = _adjust(rec, gcps, cams, opt, SubProgress(progress, 0.0, 0.45 if dem_path else 0.9))
        if dem_path:
            with run.step("dem control", save=False):
                result, gcps, cams, dem = _dem_control(rec, result, gcps, cams, opt, target, progress)
        source = "file" if camera_positions_path else ("exif" if cams else None)
        outputs, residuals_path, cameras_path = _save_products(lay, result, gcps, cams, source, target, opt)
        figures = _figures(result)
        if dem is not None:
            write_json(lay.dem_control_json, dem.as_dict())
            outputs["dem_control"] = lay.rel(lay.dem_control_json)
            figures.update(_dem_figures(dem))
        ws.crs = target
        run.finish(outputs=outputs, results=figures)
    progress.report(1.0, "georeferenced")
    return GeorefStageResult(workspace=ws.root, crs=target, figures=figures,
                             residuals_path=residuals_path, cameras_path=cameras_path, warnings=list(result.warnings),
                             outliers=[o.message or f"{o.kind} {o.name}: {o.residual:.3g} {o.unit}"
                                       for o in result.outliers],
                             report_lines=_report_lines(result),
                             dem_control=dem.as_dict() if dem is not None else None)


def _adjust(rec, gcps: Optional[gcpmod.GCPSet], cams: Sequence[gcpmod.CameraPosition], opt: GeorefOptions,
            progress: Progress) -> GeorefResult:
    try:
        return georeference(rec, gcps, list(cams) or None, progress=progress, options=opt)
    except ArchaeoOrthoError:  # the GCP file's warnings reach the user in this outcome too
        for w in gcps.warnings if gcps is not None else []:
            progress.warning(w)
        raise


def _dem_control(rec, first: GeorefResult, gcps: Optional[gcpmod.GCPSet], cams: List[gcpmod.CameraPosition],
                 opt: GeorefOptions, target: str, progress: Progress):
    """The adjusted block co-registered on the reference DEM and adjusted again with DEM control points:
    (result, ground control, camera positions, DemControl)."""
    placeholder = first.statistics.get("placeholder_z") is not None
    ctl = first.rmse(gcpmod.CONTROL)
    control = ((float(ctl["z"]), int(ctl["n"])) if demmod.has_height_control(gcps) and not placeholder and ctl["n"]
               and ctl["z"] is not None else None)
    dc = demmod.dem_control(first.reconstruction, first.offset, opt, control=control,
                            taken=[p.name for p in gcps.points] if gcps is not None else (),
                            progress=SubProgress(progress, 0.45, 0.5))
    for m in dc.messages:
        progress.info(m)
    gcps2, cams2 = demmod.with_dem_control(gcps, cams, dc)
    try:
        result = _adjust(rec, gcps2, cams2, opt, SubProgress(progress, 0.5, 0.9))
    except ArchaeoOrthoError as e:  # say which adjustment failed: the block adjusted without them was fine
        raise demmod.DemControlError(f"the adjustment with the {len(dc.points)} DEM control points from "
                                     f"{opt.reference_dem} failed: {e}") from e
    try:
        dc.after = demmod.coregister_block(result.reconstruction, result.offset, opt.reference_dem, target)[0]
    except CoregError as e:
        progress.warning(f"the block adjusted with the DEM control could not be co-registered again: {e}")
    for m in demmod.after_messages(dc, _figures(first), _figures(result)):
        progress.info(m)
    warning = demmod.after_warning(dc)
    if warning:
        result.warnings.append(warning)
        progress.warning(warning)
    return result, gcps2, cams2, dc


def _dem_figures(dc) -> Dict[str, Optional[float]]:
    co, after = dc.coregistration, dc.after
    return {"DEM_CONTROL_N": len(dc.points), "DEM_SHIFT_DZ": float(co.shift[2]),
            "DEM_NMAD_BEFORE": float(co.nmad_before), "DEM_NMAD_AFTER": float(co.nmad_after),
            "DEM_NMAD_FINAL": float(after.nmad_before) if after is not None else None}


def _save_products(lay: Layout, result: GeorefResult, gcps: Optional[gcpmod.GCPSet],
                   cams: List[gcpmod.CameraPosition], source: Optional[str], target: str,
                   opt: GeorefOptions) -> Tuple[Dict[str, str], str, str]:
    """Write the stage's products; returns the outputs the manifest records, the residual and camera layers."""
    folder = lay.ws.subdir("georef")
    with atomic_output(lay.georef_model_dir) as tmp:
        os.makedirs(tmp)
        result.reconstruction.write_binary(tmp)
    result.save(folder)
    if gcps is not None:
        atomic_write_text(lay.control_json, json.dumps(gcps.to_dict(), indent=1))
    write_json(lay.adjustment_inputs_json, adjustment_inputs(gcps, cams, source, target, opt))
    residuals_path = _write_residual_layer(lay, result, target)
    offset = np.asarray(result.offset, dtype=float)
    rows = camera_rows(result.reconstruction)
    for r in rows:
        r["x"] += offset[0]
        r["y"] += offset[1]
        r["z"] += offset[2]
    cameras_path = write_cameras_gpkg(lay.root, rows, crs=target)
    outputs = {"model": "georef/model", "transform": "georef/transform.json",
               "residuals": os.path.relpath(residuals_path, lay.root),
               "cameras": os.path.relpath(cameras_path, lay.root)}
    return outputs, residuals_path, cameras_path


def adjustment_inputs(gcps: Optional[gcpmod.GCPSet], cams: Sequence[gcpmod.CameraPosition], source: Optional[str],
                      target: str, opt: GeorefOptions) -> Dict[str, Any]:
    """What georef/adjustment_inputs.json holds: the inputs of the adjustment, in the target CRS."""
    return {"format": ADJUSTMENT_INPUTS_FORMAT, "version": 1, "crs": target,
            "gcps": gcps.to_dict() if gcps is not None else None,
            "camera_positions": [dataclasses.asdict(c) for c in cams],
            "camera_positions_source": source,
            "refine_intrinsics": opt.refine_intrinsics,
            "intrinsics_modes": {str(cid): r.get("mode") for cid, r in (opt.camera_intrinsics or {}).items()}}


def _figures(result: GeorefResult) -> Dict[str, Optional[float]]:
    ctl = result.rmse(gcpmod.CONTROL)
    chk = result.rmse(gcpmod.CHECK)
    cam = [c for c in result.cameras if c.used]
    cam_xy = [c.dx ** 2 + c.dy ** 2 for c in cam]
    cam_z = [c.dz ** 2 for c in cam if np.isfinite(c.dz)]
    cam_rmse_xy = float(np.sqrt(np.mean(cam_xy))) if cam_xy else None
    cam_rmse_z = float(np.sqrt(np.mean(cam_z))) if cam_z else None
    cam_rmse = (float(np.sqrt(np.mean(cam_xy) + np.mean(cam_z))) if cam_xy and len(cam_z) == len(cam_xy)
                else None)
    ref = chk if chk["n"] else ctl
    nssda_h = nssda_v = None
    if ref["n"]:
        nssda_h = accuracy.nssda_horizontal(ref["x"], ref["y"])
        # against placeholder heights there is no vertical accuracy to state
        if result.statistics.get("placeholder_z") is None:
            nssda_v = accuracy.nssda_vertical(ref["z"])
    return {
        "GCP_RMSE_XY": ctl["xy"], "GCP_RMSE_Z": ctl["z"], "GCP_N": ctl["n"],
        "CHECK_RMSE_XY": chk["xy"], "CHECK_RMSE_Z": chk["z"], "CHECK_N": chk["n"],
        "CHECK_RMSE_X": chk["x"], "CHECK_RMSE_Y": chk["y"],
        "CAMERA_RMSE_XYZ": cam_rmse, "CAMERA_RMSE_XY": cam_rmse_xy, "CAMERA_RMSE_Z": cam_rmse_z,
        "PLACEHOLDER_Z": result.statistics.get("placeholder_z") is not None,
        "NSSDA_H": nssda_h, "NSSDA_V": nssda_v,
        "MEAN_REPROJECTION_ERROR": float(result.mean_reprojection_error),
        "HELMERT_CHECK_RMSE_XY": result.rmse(gcpmod.CHECK, helmert=True)["xy"],
        # the sigmas estimated for control given without them (core.georef.control_sigma); None where given
        **{f"{key}_SIGMA_{axis.upper()}": next((e[f"sigma_{axis}_m"] for e in result.sigma_estimates
                                                if e["group"] == group), None)
           for key, group in (("CONTROL", "control points"), ("CAMERA_POSITION", "camera positions"))
           for axis in ("xy", "z")},
    }


def _report_lines(result: GeorefResult) -> List[str]:
    lines = []
    for p in result.points:
        if p.dx is None:
            lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} not triangulated")
            continue
        px = [o.get("px") for o in p.observations if o.get("px") is not None]
        lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} dX {p.dx:+8.3f} dY {p.dy:+8.3f} dZ {p.dz:+8.3f} m"
                     f"  {p.n_obs} obs, max {max(px) if px else float('nan'):.2f} px")
    return lines


def _write_residual_layer(lay: Layout, result: GeorefResult, crs: str) -> str:
    rows = []
    for p in result.points:
        px = [o.get("px") for o in p.observations if o.get("px") is not None]
        rows.append({"name": p.name, "role": p.role, "status": p.status, "x": p.x, "y": p.y, "z": p.z,
                     "dx": p.dx, "dy": p.dy, "dz": p.dz,
                     "dxy": None if p.dx is None else float(np.hypot(p.dx, p.dy)),
                     "n_obs": p.n_obs, "reprojection_px": float(np.mean(px)) if px else None,
                     "max_px": float(np.max(px)) if px else None})
    fields = [("name", "str"), ("role", "str"), ("status", "str"), ("dx", "float"), ("dy", "float"),
              ("dz", "float"), ("dxy", "float"), ("n_obs", "int"), ("reprojection_px", "float"),
              ("max_px", "float")]
    return write_points_gpkg(lay.residuals_gpkg, "residuals", rows, fields, crs)


__all__ = ["GeorefStageResult", "adjustment_inputs", "georeference_workspace", "load_georef_model",
           "model_path"]
