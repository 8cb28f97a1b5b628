"""What the georeference stage writes and reports: the products of an adjustment and its figures.

:func:`save_products` writes ``georef/model`` (local frame), ``transform.json``, ``residuals.json``,
``residuals.gpkg``, ``control.json``, the camera layer and ``adjustment_inputs.json`` (:func:`adjustment_inputs`:
the GCPs with roles and sigmas, the camera positions with sigmas and the target CRS the adjustment used, which
``core.georef.uncertainty`` reads back), through ``core.project.layout``; :func:`figures`,
:func:`dem_figures` and :func:`report_lines` are what the stage reports.
"""
from __future__ import annotations

import dataclasses
import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..align.mapping import camera_rows
from ..common.files import atomic_output, atomic_write_text
from ..io import gcp as gcpmod
from ..io.vector import write_cameras_gpkg, write_points_gpkg
from ..project.layout import Layout, write_json
from . import accuracy
from .options import GeorefOptions
from .results import GeorefResult

ADJUSTMENT_INPUTS_FORMAT = "archaeoortho-adjustment-inputs"


def save_products(lay: Layout, result: GeorefResult, gcps: Optional[gcpmod.GCPSet],
                   cams: List[gcpmod.CameraPosition], source: Optional[str], target: str,
                   opt: GeorefOptions) -> Tuple[Dict[str, str], str, str]:
    """Write the stage's products (the model in the local frame, transform.json, residuals.json, control.json,
    adjustment_inputs.json, the residual and camera layers); returns the outputs the manifest records, the residual and camera layers."""
    folder = lay.ws.subdir("georef")
    with atomic_output(lay.georef_model_dir) as tmp:
        os.makedirs(tmp)
        result.reconstruction.write_binary(tmp)
    result.save(folder)
    if gcps is not None:
        atomic_write_text(lay.control_json, json.dumps(gcps.to_dict(), indent=1))
    write_json(lay.adjustment_inputs_json, adjustment_inputs(gcps, cams, source, target, opt))
    residuals_path = _residual_layer(lay, result, target)
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


def figures(result: GeorefResult) -> Dict[str, Optional[float]]:
    """The stage's figures (the Processing outputs, the manifest's results): RMSEs of control, check points and
    camera positions, NSSDA accuracies, the mean reprojection error, the estimated sigmas."""
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


def dem_figures(dc) -> Dict[str, Optional[float]]:
    """The figures of the DEM control (core.georef.demcontrol.DemControl): its points, shift and spreads."""
    co, after = dc.coregistration, dc.after
    return {"DEM_CONTROL_N": len(dc.points), "DEM_SHIFT_DZ": float(co.shift[2]),
            "DEM_NMAD_BEFORE": float(co.nmad_before), "DEM_NMAD_AFTER": float(co.nmad_after),
            "DEM_NMAD_FINAL": float(after.nmad_before) if after is not None else None}


def report_lines(result: GeorefResult) -> List[str]:
    """One line per ground point: its role, status, residuals and reprojection errors."""
    lines = []
    for p in result.points:
        if p.dx is None:
            lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} not triangulated")
            continue
        px = [o.get("px") for o in p.observations if o.get("px") is not None]
        lines.append(f"{p.name:>10} {p.role:<8} {p.status:<16} dX {p.dx:+8.3f} dY {p.dy:+8.3f} dZ {p.dz:+8.3f} m"
                     f"  {p.n_obs} obs, max {max(px) if px else float('nan'):.2f} px")
    return lines


def _residual_layer(lay: Layout, result: GeorefResult, crs: str) -> str:
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


__all__ = ["ADJUSTMENT_INPUTS_FORMAT", "adjustment_inputs", "dem_figures", "figures", "report_lines",
           "save_products"]
