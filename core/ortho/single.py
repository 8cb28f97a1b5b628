"""One image on an existing DSM: space resection or known orientation; true orthophoto or planar rectification."""
from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass, field, replace
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..common.files import clean_debris, owned_tempdir
from ..common.progress import NullProgress, Progress, SubProgress
from ..geometry import resection as rs
from ..geometry.camera import Intrinsics, Pose, opk_from_rotation, project_points, rotation_from_opk
from ..geometry.crs import transform_points
from ..io import gcp as gcpmod
from ..io import raster as dsmmod
from ..io.control_place import points_off
from ..io.images import ImageError, check_image, photo_gps, read_image_info
from ..io.vector import write_points_gpkg
from .block import prepare_block, write_camera_ortho
from .cameras import OrthoCamera
from .imagecontrol import ImageControl, ImageRun
from .mosaic import WORK_PREFIX
from .options import OrthoError, SingleImageOptions
from .orientation import normalise_orientation, read_orientation
from .pixels import PHOTO_CACHE, ImageMeta, image_meta
from .planar import PlanarOutput, rectify_planar
from .surface import Dsm
from .writer import gdal_cache


@dataclass
class SingleImageResult:
    output: str
    mode: str
    crs: Optional[str]
    resolution: float
    valid_fraction: float
    orientation: Dict[str, float]  # x, y, z (world), omega, phi, kappa (degrees), focal_px, k1
    source: str  # "resection" or "orientation"
    rmse_px: Optional[float] = None
    residuals: List[Dict[str, Any]] = field(default_factory=list)
    outliers: List[str] = field(default_factory=list)
    estimated_intrinsics: bool = False
    planar_rmse_m: Optional[float] = None
    planar_error: Optional[Dict[str, float]] = None  # how far planar rectification is off given the DSM
    residuals_path: Optional[str] = None
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)
    auto_control: Optional[Dict[str, Any]] = None  # the automatic control's figures (matches, GCPs kept)


def _image_observations(gcps, name: str) -> List[Tuple[Any, Any]]:
    """(point, observation) pairs of the GCP set observed in image ``name`` (by name, base name, stem)."""
    base = os.path.basename(name).lower()
    stem = os.path.splitext(base)[0]
    out = []
    for p in gcps.points:
        for o in p.observations:
            ob = os.path.basename(o.image.replace("\\", "/")).lower()
            if ob == base or os.path.splitext(ob)[0] == stem:
                out.append((p, o))
                break
    return out


def _focal(meta: ImageMeta, image_path: str, focal_px, focal_mm, sensor_width_mm, orient: Optional[dict]
           ) -> Tuple[Optional[float], str]:
    long_side = max(meta.width, meta.height)
    if focal_px:
        return float(focal_px), "FOCAL_PX"
    if focal_mm and sensor_width_mm:
        return float(focal_mm) / float(sensor_width_mm) * long_side, "FOCAL_MM / SENSOR_WIDTH_MM"
    if focal_mm or sensor_width_mm:
        raise OrthoError("give both FOCAL_MM and SENSOR_WIDTH_MM (the sensor's long side in mm), or neither")
    if orient:
        if orient.get("focal_px"):
            return float(orient["focal_px"]), "orientation file"
        if orient.get("focal_mm") and orient.get("sensor_width_mm"):
            return float(orient["focal_mm"]) / float(orient["sensor_width_mm"]) * long_side, "orientation file"
    try:
        info = read_image_info(image_path)
    except ImageError:
        return None, "none"
    if info.focal_source != "default" and info.focal_px:
        return float(info.focal_px), f"EXIF ({info.focal_source})"
    return None, "none"


def orthorectify_image(options: SingleImageOptions, progress: Optional[Progress] = None) -> SingleImageResult:
    """Orthorectify one image (even one outside any block) on an existing DSM, as ``options`` say.

    Orientation from the GCPs observed in the image (space resection) or from a known orientation; or, with a
    reference orthophoto and no GCP, by automatic control: :func:`core.georef.autocontrol.single.control_photo`
    finds GCPs (``auto_001`` ...) by matching the photo to the reference, and the space resection uses them.
    Mode "ortho": true orthophoto on the DSM (reprojected on the fly when in another CRS); "planar": projective
    rectification through the control points onto a plane, and, when a DSM is given, how far that is off.  A
    calibrated ``camera`` is kept as it is unless ``estimate_intrinsics`` is True.  Writes a COG at
    ``options.output`` and optionally the GCP residuals to the GeoPackage ``options.residuals_path``.  ``options``
    is not modified (what the automatic control finds goes into a copy)."""
    progress = progress or NullProgress()
    single = replace(options)
    image_path = single.image_path
    if not image_path or not os.path.isfile(image_path):
        raise OrthoError(f"image {image_path} does not exist")
    try:
        check_image(image_path)  # the alignment's check: a truncated or corrupt photo is refused, named
    except ImageError as e:
        raise OrthoError(str(e)) from e
    run = ImageRun(os.path.basename(image_path), image_meta(image_path), progress)
    orient, single.camera = _orientation_input(single.orientation, single.gcps is None, run, image_path,
                                               single.camera)
    gcps, auto_figures = single.gcps, None
    if single.auto_control:
        gcps, auto_figures = _auto_control(single, run, SubProgress(progress, 0, 0.1))
    if isinstance(gcps, str):
        try:
            gcps = gcpmod.read_gcps(gcps, default_crs=single.crs)  # a CSV without a CRS line: the CRS parameter
        except gcpmod.GCPError as e:
            raise OrthoError(str(e)) from e
    work_crs = _working_crs(single.crs, single.dsm_path, gcps, orient, run)
    ctl = _ground_control(gcps, orient, work_crs, run)
    _check_place(options.gcps, gcps, ctl, work_crs, single.crs, image_path)
    offset, c_world = _local_frame(orient, ctl, work_crs)
    cam0, estimate = _interior(single, orient, ctl, run, image_path)
    ext = _exterior(orient, ctl, cam0, estimate, c_world, offset, run)
    centre_w = ext.pose.centre + offset
    om, ph, ka = opk_from_rotation(ext.pose.rotation)
    orientation_out = {"x": float(centre_w[0]), "y": float(centre_w[1]), "z": float(centre_w[2]), "omega": om,
                       "phi": ph, "kappa": ka, "focal_px": float(ext.cam.focal), "k1": float(ext.cam.dist[0])}
    run.info(f"camera at X {centre_w[0]:.2f} Y {centre_w[1]:.2f} Z {centre_w[2]:.2f}, omega {om:.3f} phi {ph:.3f} "
             f"kappa {ka:.3f} deg")
    progress.report(0.1, "oriented")
    ocam = OrthoCamera(run.name, os.path.abspath(image_path), ext.cam, ext.pose, 0, single.mask_path)
    result = SingleImageResult(single.output, single.mode, work_crs, 0.0, 0.0, orientation_out, ext.source,
                               ext.rmse, ext.residuals, ext.outliers, ext.estimated, warnings=run.warnings,
                               log_lines=run.log, auto_control=auto_figures)
    _rectify(result, ocam, run, ctl, offset, single)
    return result


@dataclass
class _Exterior:
    pose: Pose
    cam: Intrinsics
    source: str  # "resection" or "orientation"
    rmse: Optional[float] = None
    residuals: List[Dict[str, Any]] = field(default_factory=list)
    outliers: List[str] = field(default_factory=list)
    estimated: bool = False


def _orientation_input(orientation, exterior: bool, run: ImageRun, image_path: str, camera: Optional[Intrinsics]
                       ) -> Tuple[Optional[Dict[str, Any]], Optional[Intrinsics]]:
    """(exterior orientation or None, camera): an orientation without x..kappa is interior orientation only."""
    if orientation is None:
        return None, camera
    orient = (read_orientation(orientation, run.name, exterior=exterior) if isinstance(orientation, str)
              else normalise_orientation(dict(orientation), "ORIENTATION", exterior=exterior))
    if "omega" in orient:
        return orient, camera
    interior, meta = orient, run.meta
    if camera is None:
        f_i, _src = _focal(meta, image_path, None, None, None, interior)
        camera = Intrinsics.simple(meta.width, meta.height, f_i, interior.get("cx"), interior.get("cy"),
                                   tuple(interior.get(k, 0.0) for k in ("k1", "k2", "p1", "p2")))
    return None, camera


def _auto_control(single: SingleImageOptions, run: ImageRun, progress: Progress) -> Tuple[Any, Dict[str, Any]]:
    """(GCP set of the automatic control, its figures): the photo matched to the reference orthophoto and DSM;
    the camera it estimates becomes the interior orientation unless one was given."""
    from ..georef.autocontrol.errors import AutoControlError
    from ..georef.autocontrol.single import KnownCamera, SearchArea, control_photo

    focal = None
    if single.camera is None:
        focal, f_source = _focal(run.meta, single.image_path, single.focal_px, single.focal_mm,
                                 single.sensor_width_mm, None)
        run.info(f"automatic control of {run.name} against {single.reference_ortho}: focal length "
                 + (f"{focal:.1f} px ({f_source})" if focal else "unknown, estimated"))
    try:
        pc = control_photo(single.image_path, single.reference_ortho, single.dsm_path,
                           SearchArea(single.location, single.search_radius, single.location_crs),
                           KnownCamera(single.camera, focal, single.estimate_intrinsics), single.control, progress)
    except AutoControlError as e:
        raise OrthoError(str(e)) from e
    for m in pc.messages:
        run.info(m)
    for w_ in pc.warnings:
        run.warn(w_)
    if single.camera is None:
        single.camera = pc.camera
    if single.crs is None:
        single.crs = pc.crs
    figures = dict(pc.figures, centre=[float(v) for v in pc.centre], crs=pc.crs)
    return pc.gcps, figures


def _working_crs(crs: Optional[str], dsm_path: Optional[str], gcps, orient: Optional[dict], run: ImageRun
                 ) -> Optional[str]:
    dsm_info = dsmmod.open_dsm(dsm_path) if dsm_path else None
    work_crs = crs or (gcps.crs if gcps is not None and gcps.crs else None) or (orient or {}).get("crs")
    if not work_crs and dsm_info is not None and dsm_info.crs_wkt:
        work_crs = dsm_info.crs_wkt
    if not work_crs:
        run.warn("no CRS given: coordinates are taken as they are (no CRS written)")
    elif _geographic(work_crs):
        work_crs = _projected_crs(crs, work_crs, dsm_info, gcps, orient, run)
    return work_crs


def _geographic(crs: str) -> bool:
    from ..geometry.crs import CRSError, crs_is_geographic

    try:
        return crs_is_geographic(crs)
    except CRSError:
        return False


def _projected_crs(crs: Optional[str], work_crs: str, dsm_info, gcps, orient: Optional[dict], run: ImageRun) -> str:
    """A geographic working CRS (degrees; issue 36 item 13: the resection then said 'points lie nearly on one
    line'): OrthoError when the CRS parameter asked for it, else the UTM zone of the control (or the orientation,
    or the DSM), said in the log."""
    from ..geometry.crs import utm_epsg_for_lonlat

    if gcps is not None and gcps.points:
        src = gcps.crs or work_crs
        xy = np.array([[np.mean([p.x for p in gcps.points]), np.mean([p.y for p in gcps.points])]])
    elif orient is not None and "x" in orient:
        src, xy = orient.get("crs") or work_crs, np.array([[orient["x"], orient["y"]]])
    else:
        b = dsm_info.bounds
        src, xy = dsm_info.crs_wkt, np.array([[0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])]])
    lon, lat = transform_points(xy, src, "EPSG:4326")[0]
    code = utm_epsg_for_lonlat(float(lon), float(lat))
    if crs:
        raise OrthoError(f"CRS {crs} is geographic (degrees): a space resection and an orthophoto need a projected "
                         f"CRS in metres; give a projected CRS, e.g. EPSG:{code} (the UTM zone of the image)")
    run.info(f"the control / DSM CRS is geographic (degrees): {run.name} is oriented and orthorectified in "
             f"EPSG:{code} (the UTM zone of the image), and the orthophoto is written in it")
    return f"EPSG:{code}"


def _ground_control(gcps, orient: Optional[dict], work_crs: Optional[str], run: ImageRun) -> ImageControl:
    """The GCPs observed in this image, in the working CRS (OrthoError if a resection has too few)."""
    if gcps is None:
        return ImageControl()
    name, meta = run.name, run.meta
    for w_ in getattr(gcps, "warnings", []):
        run.warn(w_)
    pairs = _image_observations(gcps, name)
    xyz = np.array([[p.x, p.y, p.z] for p, _ in pairs], dtype=float).reshape(-1, 3)
    if gcps.crs and work_crs and not _crs_equal(gcps.crs, work_crs):
        xyz = transform_points(xyz, gcps.crs, work_crs)
    control = [i for i, (p, _) in enumerate(pairs) if p.role == gcpmod.CONTROL]
    checks = [i for i, (p, _) in enumerate(pairs) if p.role != gcpmod.CONTROL]
    need = rs.MIN_RESECTION_POINTS if orient is None else 0
    if len(control) < need:
        images = ", ".join(gcps.image_names()[:6]) if hasattr(gcps, "image_names") else ""
        raise OrthoError(
            f"space resection needs at least {rs.MIN_RESECTION_POINTS} ground control points observed in {name} "
            f"({rs.MIN_INTRINSICS_POINTS} to also estimate the focal length and k1); found {len(control)}"
            + (f" (and {len(checks)} check points, which are not used)" if checks else "")
            + (f". The control file names the images {images}" if not pairs and images else ""))
    px_all = np.array([[o.x, o.y] for _, o in pairs], dtype=float).reshape(-1, 2)
    outside = [pairs[i][0].name for i in range(len(pairs))
               if not (0 <= px_all[i, 0] <= meta.width and 0 <= px_all[i, 1] <= meta.height)]
    if outside:
        run.warn(f"GCP observation(s) outside the {meta.width} x {meta.height} image {name}: {', '.join(outside)}")
    return ImageControl(pairs, xyz, px_all, control)


def _check_place(given, gcps, ctl: ImageControl, work_crs: Optional[str], crs_param: Optional[str],
                 image_path: str) -> None:
    """OrthoError when the ground control points ``given`` (a file or a set; not the automatic control's) land far
    from the photo's own EXIF GPS (``core.io.control_place``, the georeference stage's check: another UTM zone,
    swapped axes), naming the likely cause; nothing to compare without GPS or a working CRS."""
    if given is None or not work_crs or not ctl.pairs:
        return
    gps = photo_gps(image_path)  # the photo was opened when the run began (check_image)
    if gps is None:
        return
    pts = [p for p, _ in ctl.pairs if p.role == gcpmod.CONTROL] or [p for p, _ in ctl.pairs]
    name = f"the GCP file {given}" if isinstance(given, str) else "the ground control points given"
    what = points_off([(os.path.basename(image_path), gps[0], gps[1])], pts, gcps.crs or work_crs, work_crs, name,
                      labelled=not crs_param or gcps.crs != crs_param)
    if what:
        raise OrthoError(what)


def _local_frame(orient: Optional[dict], ctl: ImageControl, work_crs: Optional[str]
                 ) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """(offset of the local frame, camera centre in the working CRS when the orientation is given)."""
    if orient is None:
        xyz, control = ctl.xyz, ctl.control
        return np.array([round(float(np.mean(xyz[control, 0]))), round(float(np.mean(xyz[control, 1]))), 0.0]), None
    c_world = np.array([orient["x"], orient["y"], orient["z"]], dtype=float)
    ocrs = orient.get("crs")
    if ocrs and work_crs and not _crs_equal(ocrs, work_crs):
        c_world = transform_points(c_world[None], ocrs, work_crs)[0]
    return np.array([round(c_world[0]), round(c_world[1]), 0.0]), c_world


def _interior(single: SingleImageOptions, orient: Optional[dict], ctl: ImageControl, run: ImageRun, image_path: str
              ) -> Tuple[Intrinsics, Any]:
    """(the starting interior orientation, whether the resection estimates focal length and k1)."""
    name, meta, camera = run.name, run.meta, single.camera
    estimate_intrinsics = single.estimate_intrinsics
    if camera is not None:
        if (camera.width, camera.height) != (meta.width, meta.height):
            raise OrthoError(f"the camera model is {camera.width} x {camera.height} pixels but {name} is "
                             f"{meta.width} x {meta.height}")
        f_px, f_source = camera.focal, "calibrated camera"
        if estimate_intrinsics == "auto":
            estimate_intrinsics = False
    else:
        f_px, f_source = _focal(meta, image_path, single.focal_px, single.focal_mm, single.sensor_width_mm, orient)
    n_control = len(ctl.control)
    if f_px is None:
        if orient is None and n_control >= rs.MIN_INTRINSICS_POINTS:
            f_px = 1.2 * max(meta.width, meta.height)
            estimate_intrinsics = True
            run.warn(f"the focal length of {name} is unknown (no EXIF, none given): it is estimated from the "
                     f"{n_control} control points")
        else:
            raise OrthoError(
                f"the focal length of {name} is unknown (no EXIF focal length): give FOCAL_MM and SENSOR_WIDTH_MM "
                f"(or a focal length in the orientation file), or at least {rs.MIN_INTRINSICS_POINTS} GCPs to "
                "estimate it")
    o = orient or {}
    cam0 = camera.as_opencv() if camera is not None else Intrinsics.simple(
        meta.width, meta.height, f_px, o.get("cx"), o.get("cy"), tuple(o.get(k, 0.0) for k in ("k1", "k2", "p1", "p2")))
    run.log.append(f"{name}: {meta.width} x {meta.height} px, {meta.bands} band(s) {meta.dtype}, focal {f_px:.1f} "
                   f"px ({f_source})")
    return cam0, estimate_intrinsics


def _exterior(orient: Optional[dict], ctl: ImageControl, cam0: Intrinsics, estimate_intrinsics, c_world, offset,
              run: ImageRun) -> _Exterior:
    """The pose: from the orientation given (the GCPs then check it), else by space resection."""
    name, pairs, xyz, control = run.name, ctl.pairs, ctl.xyz, ctl.control
    if orient is not None:
        rot = rotation_from_opk(orient["omega"], orient["phi"], orient["kappa"])
        ext = _Exterior(Pose.from_centre(rot, c_world - offset), cam0, "orientation")
        if pairs:
            proj, ok = project_points(ext.pose, ext.cam, xyz - offset)
            for i, (p, ob) in enumerate(pairs):
                ext.residuals.append(_residual_row(p, ob, name, xyz[i], proj[i], True, "check (orientation given)"))
            r = np.array([row["res_px"] for row in ext.residuals])
            ext.rmse = float(np.sqrt(np.mean(r ** 2)))
        return ext
    try:
        res = rs.space_resection(xyz[control] - offset, ctl.px[control], cam0,
                                 names=[pairs[i][0].name for i in control],
                                 estimate_intrinsics=estimate_intrinsics, image=name)
    except rs.ResectionError as e:
        raise OrthoError(str(e)) from e
    ext = _Exterior(res.pose, res.camera, "resection", res.rmse_px, [], res.outliers, res.estimated_intrinsics)
    for w_ in res.warnings:
        run.warn(w_)
    proj, ok = project_points(ext.pose, ext.cam, xyz - offset)
    used = {r.name: r.used for r in res.residuals}
    for i, (p, ob) in enumerate(pairs):
        role = "control" if i in control else "check"
        ext.residuals.append(_residual_row(p, ob, name, xyz[i], proj[i], used.get(p.name, False) if i in control
                                           else False, role if used.get(p.name, True) else "outlier"))
    chk = [row["res_px"] for row in ext.residuals if row["role"] == "check"]
    cam, outliers = ext.cam, ext.outliers
    run.info(f"space resection from {res.n_used} of {len(control)} control points: RMSE {ext.rmse:.2f} px"
             + (f", check points RMSE {float(np.sqrt(np.mean(np.square(chk)))):.2f} px ({len(chk)})" if chk else "")
             + (f"; estimated {' and '.join(res.estimated_params)}: focal length {cam.focal:.1f} px, k1 "
                f"{cam.dist[0]:+.4f}" if ext.estimated else "")
             + (f"; left out: {', '.join(outliers)}" if outliers else ""))
    return ext


def _rectify(result: SingleImageResult, ocam: OrthoCamera, run: ImageRun, ctl: ImageControl, offset: np.ndarray,
             single: SingleImageOptions) -> None:
    """Write the true orthophoto (or the planar rectification) and the residuals layer; fills ``result``."""
    progress, name, mode, work_crs = run.progress, run.name, result.mode, result.crs
    out_dir = os.path.dirname(os.path.abspath(result.output))
    os.makedirs(out_dir, exist_ok=True)
    clean_debris(out_dir, WORK_PREFIX)
    workdir = owned_tempdir(WORK_PREFIX, out_dir)
    options, dsm_path, residuals_path = single.ortho, single.dsm_path, single.residuals_path
    PHOTO_CACHE.max_bytes = options.cache_mb << 20
    dsm = Dsm(dsm_path, work_crs) if dsm_path else None
    try:
        with gdal_cache(64):
            if dsm is not None and dsm.reprojected:
                run.info(f"DSM {dsm_path} reprojected on the fly into the working CRS")
            if mode == "ortho":
                prep = prepare_block([ocam], dsm, offset, replace(options, gsd_factor=0.0), workdir,
                                     SubProgress(progress, 0.1, 0.3))
                for w_ in prep.warnings:
                    run.warn(w_)
                info = write_camera_ortho(prep, 0, dsm, offset, result.output, options,
                                          SubProgress(progress, 0.3, 1.0))
                if info is None:
                    raise OrthoError(f"the DSM does not cover the ground seen by {name}")
                result.resolution = prep.grid.resolution
                result.valid_fraction = info["valid_fraction"]
                if info["valid_fraction"] == 0.0:
                    raise OrthoError(f"no cell of the orthophoto of {name} has data: the DSM has no valid height "
                                     "where the image looks")
            else:
                pr = rectify_planar(ocam, run, ctl, offset, dsm, options, PlanarOutput(result.output, work_crs),
                                    SubProgress(progress, 0.1, 1.0))
                for row in result.residuals:  # the residuals on the plane
                    if row["name"] in pr.plane_residuals:
                        row["dx_m"], row["dy_m"], row["res_m"] = pr.plane_residuals[row["name"]]
                result.planar_rmse_m, result.planar_error = pr.rmse_m, pr.error
                result.resolution, result.valid_fraction = pr.resolution, pr.valid_fraction
        run.info(f"{mode} orthophoto {result.output}: {result.resolution:g} per cell, "
                 f"{100 * result.valid_fraction:.1f} % of its cells with data")
        if residuals_path and result.residuals:
            fields = [("name", "str"), ("role", "str"), ("image", "str"), ("px", "float"), ("py", "float"),
                      ("dx_px", "float"), ("dy_px", "float"), ("res_px", "float"), ("used", "int"),
                      ("dx_m", "float"), ("dy_m", "float"), ("res_m", "float")]
            write_points_gpkg(residuals_path, "gcp_residuals", result.residuals, fields, work_crs)
            result.residuals_path = residuals_path
        progress.report(1.0, "done")
    finally:
        if dsm is not None:
            dsm.close()
        PHOTO_CACHE.clear()
        shutil.rmtree(workdir, ignore_errors=True)


def _crs_equal(a: str, b: str) -> bool:
    from osgeo import osr

    sa, sb = osr.SpatialReference(), osr.SpatialReference()
    try:
        sa.SetFromUserInput(a)
        sb.SetFromUserInput(b)
    except RuntimeError:
        return a == b
    return bool(sa.IsSame(sb))


def _residual_row(p, ob, image: str, xyz_w, proj, used: bool, role: str) -> Dict[str, Any]:
    dx, dy = float(proj[0] - ob.x), float(proj[1] - ob.y)
    return {"name": p.name, "role": role, "image": image, "px": float(ob.x), "py": float(ob.y), "dx_px": dx,
            "dy_px": dy, "res_px": math.hypot(dx, dy), "used": int(bool(used)), "x": float(xyz_w[0]),
            "y": float(xyz_w[1]), "z": float(xyz_w[2])}
