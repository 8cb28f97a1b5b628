"""Workspace-level stages: what a Processing algorithm calls, one function per stage.

``sfm.align`` is the alignment stage; this module holds the stages built on it
(georeference, ...).  Each function opens the workspace, records parameters,
status and timings, writes its products atomically and returns a result object.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence

import numpy as np

from .common.progress import Cancelled, NullProgress, Progress, SubProgress
from .io import gcp as gcpmod
from .io.vector import write_points_gpkg
from .project.workspace import (
    CANCELLED,
    DONE,
    FAILED,
    Workspace,
    WorkspaceError,
    atomic_output,
    file_fingerprint,
)

GEOREF = "georeference"
EXIF_SIGMA_XY = 3.0  # m: consumer GNSS in EXIF
EXIF_SIGMA_Z = 5.0


class StageError(RuntimeError):
    """A stage cannot run with these inputs; the message says why."""


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


def model_path(ws: Workspace) -> str:
    """The newest sparse model of a workspace: georeferenced (local frame) if present, else aligned."""
    geo = ws.path("georef", "model")
    if ws.stage_done(GEOREF) and os.path.isdir(geo):
        return geo
    return ws.path("sfm", "model")


def load_georef_model(workspace_dir: str):
    """(pycolmap.Reconstruction in the local frame, transform dict with 'offset' and 'crs') of a
    georeferenced workspace.  Raises StageError when the workspace is not georeferenced."""
    import pycolmap

    ws = Workspace.open(workspace_dir)
    if not ws.stage_done(GEOREF):
        raise StageError(f"workspace {ws.root} is not georeferenced: run 'Georeference' first")
    rec = pycolmap.Reconstruction()
    rec.read_binary(ws.path("georef", "model"))
    with open(ws.path("georef", "transform.json"), encoding="utf-8") as f:
        transform = json.load(f)
    return rec, transform


def _exif_positions(ws: Workspace, crs: str) -> List[gcpmod.CameraPosition]:
    rows = [(im["name"], im["gps"]) for im in ws.data.get("images", []) if im.get("gps")]
    if not rows:
        return []
    lonlat = np.array([[g[0], g[1], 0.0] for _, g in rows], dtype=float)
    xy = gcpmod.transform_points(lonlat, "EPSG:4326", crs)
    # EXIF altitude is kept as it is (normally above mean sea level): only X and Y are transformed
    return [gcpmod.CameraPosition(image=n, x=float(p[0]), y=float(p[1]), z=float(g[2]),
                                  sigma_xy=EXIF_SIGMA_XY, sigma_z=EXIF_SIGMA_Z)
            for (n, g), p in zip(rows, xy)]


def _file_positions(path: str, crs: str) -> List[gcpmod.CameraPosition]:
    src_crs, cams = gcpmod.read_camera_positions(path)
    if src_crs and crs and src_crs != crs:
        xyz = np.array([[c.x, c.y, 0.0] for c in cams], dtype=float)
        out = gcpmod.transform_points(xyz, src_crs, crs)
        for c, p in zip(cams, out):
            c.x, c.y = float(p[0]), float(p[1])
    return cams


def _default_crs(ws: Workspace) -> Optional[str]:
    gps = [im["gps"] for im in ws.data.get("images", []) if im.get("gps")]
    if not gps:
        return None
    lon = float(np.mean([g[0] for g in gps]))
    lat = float(np.mean([g[1] for g in gps]))
    return f"EPSG:{gcpmod.utm_epsg_for_lonlat(lon, lat)}"


def georeference_workspace(workspace_dir: str, gcp_path: Optional[str] = None,
                           gcps: Optional[gcpmod.GCPSet] = None, check_points: Sequence[str] = (),
                           camera_positions_path: Optional[str] = None, use_exif_gps: bool = False,
                           crs: Optional[str] = None, refine_intrinsics: bool = False,
                           progress: Optional[Progress] = None) -> GeorefStageResult:
    """Georeference an aligned workspace with GCPs and/or camera positions (see core.georef)."""
    import pycolmap

    from .align.sfm import STAGE as ALIGN
    from .align.sfm import camera_rows
    from .georef import accuracy
    from .georef import adjust as georef

    progress = progress or NullProgress()
    ws = Workspace.open(workspace_dir)
    if not ws.stage_done(ALIGN) or not os.path.isdir(ws.path("sfm", "model")):
        raise StageError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = pycolmap.Reconstruction()
    rec.read_binary(ws.path("sfm", "model"))
    sizes = {im["name"]: (im["width"], im["height"]) for im in ws.data.get("images", [])}

    # ground control
    if gcp_path:
        gcps = gcpmod.read_gcps(gcp_path, image_names=list(sizes), image_sizes=sizes)
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
            out = gcpmod.transform_points(xyz, gcps.crs, crs)
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
    n_control = sum(1 for p in gcps.points if p.role == gcpmod.CONTROL) if gcps else 0
    if n_control < 3 and len(cams) < 3:
        found = ", ".join(f"{p.name} ({p.role}, {len(p.observations)} obs.)" for p in gcps.points) if gcps else "none"
        raise StageError(
            f"georeferencing needs at least 3 control points (or 3 camera positions); found {n_control} control "
            f"point(s) and {len(cams)} camera position(s). Points: {found}")

    params = {"gcps": gcp_path, "check_points": list(check_points), "camera_positions": camera_positions_path,
              "use_exif_gps": use_exif_gps, "crs": target, "refine_intrinsics": refine_intrinsics}
    inputs = {k: file_fingerprint(v) for k, v in (("gcps", gcp_path), ("positions", camera_positions_path)) if v}
    ws.begin_stage(GEOREF, params, inputs)
    t0 = time.time()
    try:
        result = georef.georeference(rec, gcps, cams or None, refine_intrinsics=refine_intrinsics,
                                     progress=SubProgress(progress, 0.0, 0.9), crs=target)
        ws.record_timing(GEOREF, "adjustment", time.time() - t0)
        folder = ws.subdir("georef")
        with atomic_output(os.path.join(folder, "model")) as tmp:
            os.makedirs(tmp)
            result.reconstruction.write_binary(tmp)
        result.save(folder)
        if gcps is not None:
            with atomic_output(os.path.join(folder, "control.json")) as tmp:
                with open(tmp, "w", encoding="utf-8") as f:
                    json.dump(gcps.to_dict(), f, indent=1)
        residuals_path = _write_residual_layer(ws, result, target)
        offset = np.asarray(result.offset, dtype=float)
        rows = camera_rows(result.reconstruction)
        for r in rows:
            r["x"] += offset[0]
            r["y"] += offset[1]
            r["z"] += offset[2]
        from .io.vector import write_cameras_gpkg

        cameras_path = write_cameras_gpkg(ws.root, rows, crs=target)
        figures = _figures(result, accuracy)
        ws.crs = target
        ws.end_stage(GEOREF, DONE, outputs={"model": "georef/model", "transform": "georef/transform.json",
                                            "residuals": os.path.relpath(residuals_path, ws.root),
                                            "cameras": os.path.relpath(cameras_path, ws.root)},
                     results=figures)
        ws.invalidate_after(GEOREF, ["align", GEOREF, "dsm", "orthophoto", "report"])
        progress.report(1.0, "georeferenced")
        return GeorefStageResult(workspace=ws.root, crs=target, figures=figures, residuals_path=residuals_path,
                                 cameras_path=cameras_path, warnings=list(result.warnings),
                                 outliers=[o.message or f"{o.kind} {o.name}: {o.residual:.3g} {o.unit}"
                                           for o in result.outliers],
                                 report_lines=_report_lines(result))
    except Cancelled:
        ws.end_stage(GEOREF, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        ws.end_stage(GEOREF, FAILED, error=str(e))
        raise


def _figures(result, accuracy) -> Dict[str, Optional[float]]:
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
    }


def _report_lines(result) -> List[str]:
    lines = []
    for p in result.points:
        if p.dx is None:
            lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} not triangulated")
            continue
        px = [o.get("px") for o in p.observations if o.get("px") is not None]
        lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} dX {p.dx:+8.3f} dY {p.dy:+8.3f} dZ {p.dz:+8.3f} m"
                     f"  {p.n_obs} obs, max {max(px) if px else float('nan'):.2f} px")
    return lines


def _write_residual_layer(ws: Workspace, result, crs: str) -> str:
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
    return write_points_gpkg(ws.path("georef", "residuals.gpkg"), "residuals", rows, fields, crs)


@dataclass
class PipelineResult:
    """What ``run_pipeline`` did: each stage's own result object (None where the stage did not run)."""
    workspace: str
    align: object
    georef: Optional[GeorefStageResult]
    dsm: object = None
    ortho: object = None
    report: object = None
    seconds: Dict[str, float] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)


def run_pipeline(images_dir: str, workspace_dir: str, *, align_options=None, gcp_path: Optional[str] = None,
                 gcps: Optional[gcpmod.GCPSet] = None, check_points: Sequence[str] = (),
                 camera_positions_path: Optional[str] = None, use_exif_gps: bool = False, crs: Optional[str] = None,
                 refine_intrinsics: bool = False, dsm_resolution: float = 0.0, dsm_quality: str = "half",
                 dense_options=None, ortho_resolution: float = 0.0, blending: str = "feather",
                 images_filter: Optional[str] = None, ortho_options=None, report: bool = True,
                 uncertainty: bool = True, progress: Optional[Progress] = None) -> PipelineResult:
    """The whole chain in one call: align -> georeference -> DSM -> orthomosaic -> report.

    The same stage functions the single Processing algorithms call, in order, on one workspace; every
    stage records itself in workspace.json as when run alone, so a re-run resumes (features, matches and
    dense pairs already computed are reused).  Without ground control or camera positions the chain stops
    after the alignment: a DSM and an orthophoto need a metric scale and a vertical direction, so that is a
    StageError naming what to give."""
    from .align import sfm
    from .dense import stage as dense
    from .ortho import stage as ortho
    from .report import stage as reportmod

    progress = progress or NullProgress()
    if gcp_path is None and gcps is None and not camera_positions_path and not use_exif_gps:
        raise StageError("the pipeline needs ground control (GCPS) and/or camera positions (CAMERA_POSITIONS or "
                         "USE_EXIF_GPS) to georeference the block before the DSM and orthophoto; to align only, "
                         "run 'Align images'")
    seconds: Dict[str, float] = {}
    spans = {"align": (0.0, 0.40), "georeference": (0.40, 0.45), "dsm": (0.45, 0.75),
             "orthophoto": (0.75, 0.93), "report": (0.93, 1.0)}

    def run(name, fn, *args, **kwargs):
        lo, hi = spans[name]
        progress.info(f"--- stage {name} ---")
        t0 = time.time()
        out = fn(*args, progress=SubProgress(progress, lo, hi), **kwargs)
        seconds[name] = round(time.time() - t0, 2)
        return out

    res = PipelineResult(workspace=os.path.abspath(workspace_dir), align=None, georef=None, seconds=seconds)
    res.align = run("align", sfm.align, images_dir, workspace_dir, align_options)
    res.georef = run("georeference", georeference_workspace, workspace_dir, gcp_path=gcp_path, gcps=gcps,
                     check_points=check_points, camera_positions_path=camera_positions_path,
                     use_exif_gps=use_exif_gps, crs=crs, refine_intrinsics=refine_intrinsics)
    res.warnings += res.georef.warnings
    res.dsm = run("dsm", dense.build_dsm_workspace, workspace_dir, resolution=dsm_resolution, quality=dsm_quality,
                  options=dense_options)
    res.warnings += res.dsm.warnings
    res.ortho = run("orthophoto", ortho.build_orthophoto_workspace, workspace_dir, images_filter=images_filter,
                    resolution=ortho_resolution, blending=blending, options=ortho_options)
    res.warnings += res.ortho.warnings
    if report:
        res.report = run("report", reportmod.build_report, workspace_dir, uncertainty=uncertainty)
        res.warnings += res.report.warnings
    progress.report(1.0, "pipeline done")
    return res


__all__ = ["georeference_workspace", "load_georef_model", "model_path", "run_pipeline", "PipelineResult",
           "StageError", "WorkspaceError"]
