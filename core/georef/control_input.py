"""The ground control of the georeference stage, read and checked in the target CRS.

:func:`read_control` turns the stage's inputs (``GeorefOptions``: a GCP file or a GCP set, check point names, a
camera positions file, EXIF GPS, the CRS, photos measured upright) into the GCPs and camera positions the
adjustment takes, and the target CRS; :func:`exif_positions` reads the photos' EXIF GPS as camera positions;
:func:`photo_orientations` says which photos a viewer shows turned.
"""
from __future__ import annotations

import copy
import os
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..common.progress import Progress
from ..geometry.crs import transform_points, utm_epsg_for_lonlat
from ..io import gcp as gcpmod
from ..io.images import exif_orientation
from ..project.stages import StageError
from ..project.workspace import Workspace
from .options import EXIF_SIGMA_XY, EXIF_SIGMA_Z, GeorefOptions


def exif_positions(ws: Workspace, crs: str) -> List[gcpmod.CameraPosition]:
    """The photos' EXIF GPS positions as camera positions in ``crs`` (consumer GNSS sigmas)."""
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


def target_crs(crs: Optional[str], gcps: Optional[gcpmod.GCPSet], workspace_crs: Optional[str],
               positions_crs: Optional[str], photos_utm: Optional[str]) -> Optional[str]:
    """The CRS the block is georeferenced in: the CRS parameter, else the GCPs', else the workspace's (a re-run),
    else the camera positions file's, else the UTM zone of the photos' EXIF GPS; None when none is known."""
    return crs or (gcps.crs if gcps is not None else None) or workspace_crs or positions_crs or photos_utm


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


def _gcps(ws: Workspace, opt: GeorefOptions, progress: Progress) -> Optional[gcpmod.GCPSet]:
    """The GCPs of ``opt`` (its file, else its set) in the stored pixel grid, with the check points named."""
    sizes = {im["name"]: (im["width"], im["height"]) for im in ws.data.get("images", [])}
    upright = photo_orientations(ws) if opt.gcps_upright else None
    if opt.gcps_upright and not upright:
        progress.info("GCP coordinates measured on upright photos: no photo of the block is stored turned (EXIF "
                      "orientation 1 or none), nothing to convert")
    gcps = opt.gcps
    if opt.gcp_path:
        # a CSV points file without a CRS line takes the CRS parameter
        gcps = gcpmod.read_gcps(opt.gcp_path, image_names=list(sizes), image_sizes=sizes, default_crs=opt.crs,
                                upright_orientations=upright)
    elif gcps is not None and upright:
        gcps = gcpmod.observations_to_stored(copy.deepcopy(gcps), sizes, upright)
    if gcps is not None and opt.check_points:
        gcpmod.apply_check_points(gcps, list(opt.check_points))
    return gcps


def dem_alone_hint(ws: Workspace, opt: GeorefOptions) -> str:
    """What a reference DEM given without enough to place the block needs (issue 47 item 13: 'no target CRS',
    then 'at least 3 control points'): the inputs that work with it, and the automatic control."""
    images = ws.data.get("images", [])
    gps = sum(1 for im in images if im.get("gps"))
    return (f"the reference DEM {opt.reference_dem} fixes the block's heights, tilt and dome, not where it lies: "
            f"give what places the block with it: the photos' EXIF GPS ({gps} of {len(images)} photos carry any), "
            "camera positions (CAMERA_POSITIONS: a file of x, y, z per photo), or 3 or more ground control points "
            "(GCPS or GCP_LAYER), with CRS when they have no CRS line; or give a reference orthophoto (REFERENCE_ORTHO) "
            "with the DEM: the automatic control then finds the block on the orthophoto itself, no position needed")


def read_control(ws: Workspace, opt: GeorefOptions, progress: Progress, required: bool = True
                 ) -> Tuple[Optional[gcpmod.GCPSet], List[gcpmod.CameraPosition], str]:
    """The ground control in the target CRS: (GCPs, camera positions, target CRS); StageError when it is
    not enough to georeference (``required`` False: any amount, for the automatic control, whose own candidates
    fix the block and which takes the given points as check points and the positions as a rough position).
    Observations in photos that are not in the workspace are left out with a warning (an error when none is in
    one of its photos); ``opt.gcps_upright``: the pixel coordinates were measured on upright photos (EXIF
    orientation applied) and are converted to the stored grid."""
    crs = opt.crs
    gcps = _gcps(ws, opt, progress)
    positions_path = opt.camera_positions_path
    positions_crs = gcpmod.read_camera_positions(positions_path)[0] if positions_path else None
    target = target_crs(crs, gcps, ws.crs, positions_crs, _default_crs(ws))
    if not target:
        if opt.reference_dem:
            raise StageError(f"no target CRS and nothing to place the block: {dem_alone_hint(ws, opt)}")
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
    if positions_path:
        cams = _file_positions(positions_path, target)
    elif opt.use_exif_gps:
        cams = exif_positions(ws, target)
        if not cams:
            progress.warning("USE_EXIF_GPS is set but no image carries EXIF GPS")
    # a control point whose observations were all dropped (outside the image, unknown image) controls nothing
    n_control = sum(1 for p in gcps.points if p.role == gcpmod.CONTROL and p.observations) if gcps else 0
    if required and n_control < 3 and len(cams) < 3:
        found = "; ".join(f"{p.name} ({p.role}, {p.describe_observations()})" for p in gcps.points) if gcps else "none"
        hint = f"; {dem_alone_hint(ws, opt)}" if opt.reference_dem else ""
        raise StageError(gcpmod.with_warnings(
            f"georeferencing needs at least 3 control points (or 3 camera positions); found {n_control} control "
            f"point(s) with observations and {len(cams)} camera position(s). Points: {found}{hint}",
            gcps.warnings if gcps else []))
    return gcps, cams, target


__all__ = ["dem_alone_hint", "exif_positions", "photo_orientations", "read_control", "target_crs"]
