"""Georeferencing: Helmert (7-parameter similarity), GCP- and position-constrained
bundle adjustment, check points.

Frames:

- *model frame*: the frame of the sparse model as alignment wrote it (arbitrary
  origin, orientation and scale);
- *local frame*: world coordinates minus ``offset`` (metres, near the origin);
  the adjusted reconstruction lives here, so no UTM-size number ever enters the
  adjustment or the sparse model;
- *world*: ``local + offset`` in the CRS of the ground control.

``georeference`` proceeds in five steps:

1. triangulate every control point from its pixel observations in the model
   (full camera model, robust to one wrong observation);
2. fit a similarity model -> local frame by RANSAC over minimal 3-point sets
   (control points, or camera projection centres when there are fewer than 3
   usable control points) with a least-squares refit on the inliers; control
   points far off that fit are left out of the first adjustment (step 4) only:
   a deformed block (a long strip, a wrong calibration) can put a correct point
   metres off a similarity of the others;
3. move the reconstruction into the local frame (``Reconstruction.transform``);
4. constrained bundle adjustment (own sparse Levenberg-Marquardt with a Schur
   complement on the points, see ``core.georef.bundle``): tie-point reprojection
   (Huber loss) + GCP observation reprojection + GCP positions as priors weighted
   by sigma_xy / sigma_z + camera projection-centre priors weighted by their sigma,
   optionally intrinsics; check points take no part.  After each run, the worst
   GCP observation or GCP / camera position far off its residual threshold is
   removed by name and the adjustment is re-run.  Then each control point left
   out at step 2 is re-tested against the adjusted block, held fixed: placed
   where its image observations and its coordinates agree best (weighted by
   their sigmas), it must pass the adjustment's own thresholds (normalised
   coordinate residual, pixel residuals).  Those that pass are re-admitted and
   the adjustment is run again (repeated while points come back); the others (a
   typo of 100 m) are named with their residuals and stay out;
5. check points (and rejected control points) are triangulated in the adjusted
   model and compared with their given coordinates.

Why not pycolmap's bundle adjuster: pycolmap 4.2.1 offers camera position
priors with covariance (``create_pose_prior_bundle_adjuster``) and constant
points (``BundleAdjustmentConfig.add_constant_point``), but no weighted prior on
a 3-D point and no access to the Ceres problem without pyceres; GCPs with a
sigma, the per-observation residuals needed for outlier tests, and ground points
that are not part of the sparse model need the own solver here.  Projection
itself is pycolmap's (``Camera.img_from_cam``), so every COLMAP camera model
works; the derivatives are analytic for the rigid part and central differences
for the camera model.

Modules: ``core.geometry.similarity`` (Helmert), ``triangulate`` (ground points from pixels), ``bundle``
(the adjustment problem, shared with ``uncertainty``), ``outliers`` (consistency and outlier tests),
``results`` (the residual rows and ``GeorefResult``), ``options`` (``GeorefOptions``); this module is the
driver.

Pixel convention: origin at the upper-left corner of the upper-left pixel, x
right, y down: the same as COLMAP, so observations go in unchanged.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..geometry.similarity import HelmertResult, helmert_ransac
from ..io.gcp import CHECK, CONTROL, CameraPosition, GCPSet, GroundPoint
from .bundle import BundleProblem, Control, build_problem, outside_image, set_point_active, write_back
from .control_sigma import (
    CAMERA_GROUP,
    CONTROL_GROUP,
    SigmaEstimate,
    VarianceGroup,
    estimate_group,
    fit_residuals,
    ground_sample_distance,
    intersection_precision,
    lmeds_sigma,
    tie_point_sigma,
    variance_components,
)
from .errors import GeorefError
from .options import GeorefOptions
from .outliers import (
    Consistency,
    ControlRows,
    control_consistency,
    control_thresholds,
    find_outlier,
    removed_cameras,
    retest_provisional,
)
from .results import (
    CHECKED,
    NOT_TRIANGULATED,
    REJECTED,
    USED,
    CameraResidual,
    GeorefResult,
    Outlier,
    PointResidual,
)
from .triangulate import Triangulation, image_names, refine_tie_points, registered_images, triangulate_observations


@dataclass
class _Run:
    """The state of one georeferencing while its steps run."""

    rec: Any
    opt: GeorefOptions
    progress: Progress
    crs: str
    points: List[GroundPoint]
    lookup: Dict[str, Any]
    all_names: set
    t_start: float
    warnings: List[str] = field(default_factory=list)
    outliers: List[Outlier] = field(default_factory=list)
    timings: Dict[str, float] = field(default_factory=dict)
    tri: Dict[str, Triangulation] = field(default_factory=dict)
    usable: List[GroundPoint] = field(default_factory=list)
    problems: List[str] = field(default_factory=list)
    cam_pos: List[Tuple[CameraPosition, Any]] = field(default_factory=list)
    no_height: List[str] = field(default_factory=list)
    placeholder_z: Optional[float] = None
    rejected_ctrl: set = field(default_factory=set)
    # control points off the Helmert fit, left out of the first adjustment and re-tested against the adjusted block
    provisional: Dict[str, Outlier] = field(default_factory=dict)
    # sigmas estimated for control points / camera positions given without them (core.georef.control_sigma)
    sigma_estimates: Dict[str, SigmaEstimate] = field(default_factory=dict)

    @property
    def control(self) -> List[GroundPoint]:
        return [p for p in self.points if p.role == CONTROL]

    def warn(self, message: str) -> None:
        self.warnings.append(message)
        self.progress.warning(message)


@dataclass
class _Fit:
    """The initial similarity model -> local frame and what it was fitted on."""

    source: str  # "control points" or "camera positions"
    model: np.ndarray
    world_local: np.ndarray
    objs: list  # the GroundPoints or CameraPositions, one per row
    offset: np.ndarray
    threshold: float
    helmert: HelmertResult


def georeference(reconstruction, gcps: Optional[GCPSet], camera_positions: Optional[Sequence[CameraPosition]] = None,
                 options: Optional[GeorefOptions] = None, progress: Optional[Progress] = None) -> GeorefResult:
    """Georeference a sparse model with GCPs and/or camera positions.

    ``reconstruction``: pycolmap.Reconstruction in the model frame (copied unless
    ``copy_model`` is False).  ``gcps``: control points (role CONTROL) enter the
    adjustment, check points (role CHECK) are only evaluated.
    ``camera_positions``: projection centres (same CRS as the GCPs) with sigmas.
    ``options``: a :class:`~core.georef.options.GeorefOptions` (None: the defaults), the only carrier of the
    settings; its ``refine_intrinsics``: False; True (focal + distortion); "all" (also the
    principal point); or a subset of ("focal", "principal_point", "extra").
    ``outlier_threshold``: pixels; a GCP observation whose residual exceeds
    max(outlier_threshold, 5 x median) is removed.  ``outlier_sigma``: a control
    point or camera position whose largest normalised coordinate residual exceeds
    max(outlier_sigma, 5 x median) is removed.  ``helmert_threshold``: metres
    (RANSAC inlier distance; default from the point spread and sigmas).
    ``max_observations``: tie-point observations in the adjustment; beyond it the
    best-observed tie points are kept (every image covered) and the others are
    re-triangulated with the adjusted cameras afterwards.
    ``adjust=False`` stops after the Helmert step (its outliers are then final; with the adjustment,
    control points off the Helmert fit are re-tested against the adjusted block, see the module notes).
    GCP observations outside their image (valid: 0 <= x <= width, 0 <= y <= height, COLMAP's pixel
    convention) are named in a warning and ignored (their ``px`` in the residual rows is None).
    Camera positions with a non-finite ``z`` constrain X and Y only.  When every control
    point has the same Z (a placeholder such as 0), their sigma Z is raised to
    ``placeholder_sigma_z`` and a warning says so (``statistics["placeholder_z"]``).
    Returns a GeorefResult whose reconstruction lies in the local frame world - offset.
    """
    opt = options if options is not None else GeorefOptions()
    run = _start(reconstruction, gcps, opt, progress or NullProgress())
    _triangulate_control(run)
    _match_camera_positions(run, camera_positions)
    _placeholder_heights(run)
    fit = _initial_similarity(run, camera_positions)
    _helmert_outliers(run, fit)
    _estimate_sigmas(run, fit)
    _given_sigmas_held_fixed(run, fit)
    consistency = _consistency(run, fit)
    run.timings["helmert"] = time.time() - run.t_start
    run.progress.report(0.08, f"Helmert from {int(fit.helmert.inliers.sum())} {fit.source}")

    # 3. the model into the local frame
    model_to_local = fit.helmert.transform
    run.rec.transform(model_to_local.to_sim3d())
    run.lookup = registered_images(run.rec)
    helmert_rows = _evaluate_points(run.rec, run.points, fit.offset, run.rejected_ctrl, run.lookup, run.all_names,
                                    opt.outlier_threshold)
    result = GeorefResult(run.rec, model_to_local, fit.offset, run.crs, fit.source, helmert_points=helmert_rows,
                          warnings=run.warnings, outliers=run.outliers, adjusted=False,
                          sigma_estimates=[e.to_dict() for e in run.sigma_estimates.values()])
    stats: Dict[str, Any] = {"helmert_threshold_m": fit.threshold, "helmert_inliers": int(fit.helmert.inliers.sum()),
                             "helmert_scale": model_to_local.scale, "placeholder_z": run.placeholder_z,
                             "control_consistency": consistency.to_dict() if consistency else None}
    stats["sigma_estimates"] = result.sigma_estimates
    if not opt.adjust:
        result.points = helmert_rows
        result.cameras = _camera_rows(run.rec, run.cam_pos, fit.offset, run.lookup)
        result.mean_reprojection_error = _mean_tie_error(run.rec)
        run.timings["total"] = time.time() - run.t_start
        stats["timings"] = run.timings
        result.statistics = stats
        return result
    adj = _adjust(run, fit, stats)
    _update_and_evaluate(run, adj, result, camera_positions, stats)
    return result


def _start(reconstruction, gcps: Optional[GCPSet], opt: GeorefOptions, progress: Progress) -> _Run:
    """Check the input, copy the model, and name the observations that lie off their image."""
    pycolmap = require("pycolmap", "georeferencing")
    crs = opt.crs if opt.crs is not None else (gcps.crs if gcps is not None else "")
    warnings: List[str] = list(gcps.warnings) if gcps is not None else []
    points = list(gcps.points) if gcps is not None else []
    rec = pycolmap.Reconstruction(reconstruction) if opt.copy_model else reconstruction
    run = _Run(rec, opt, progress, crs, points, registered_images(rec), image_names(rec), time.time(),
               warnings=warnings)
    _check_crs(crs, run.warn)
    opt.intrinsic_groups()  # an unknown group is refused before any work
    if not run.lookup:
        raise GeorefError("the model has no registered images")
    names = [p.name for p in points]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise GeorefError(f"ground point names must be unique; repeated: {', '.join(dup)}")
    for p in points:
        if p.role not in (CONTROL, CHECK):
            raise GeorefError(f"ground point {p.name}: unknown role {p.role!r} (use {CONTROL!r} or {CHECK!r})")
    # observations off their image (GCPs picked in QGIS come here directly, without the file readers'
    # check): named and ignored, in the triangulation, the adjustment and the evaluation alike
    by_name = {im.name: im for im in rec.images.values()}
    for p in points:
        for ob in p.observations:
            im = by_name.get(ob.image)
            if im is not None and outside_image(rec.cameras[im.camera_id], ob):
                cam = rec.cameras[im.camera_id]
                run.warn(f"{'control' if p.role == CONTROL else 'check'} point {p.name}: observation "
                         f"at ({ob.x:g}, {ob.y:g}) lies outside image {ob.image} ({cam.width} x "
                         f"{cam.height} px); ignored")
    progress.report(0.0, "triangulating control points")
    return run


def _triangulate_control(run: _Run) -> None:
    """1. triangulate the control points in the model frame; those that cannot be are named."""
    for p in run.control:
        check_cancel(run.progress)
        t = triangulate_observations(run.rec, p.observations, max_error_px=max(run.opt.outlier_threshold, 1.0) * 4,
                                     _lookup=run.lookup, _all_names=run.all_names)
        run.tri[p.name] = t
        for k in t.rejected:
            ob = p.observations[k]
            run.outliers.append(Outlier("observation", p.name, float("nan"), "px", "triangulation", ob.image,
                                        f"control point {p.name}: observation in {ob.image} inconsistent with the "
                                        "other rays, excluded"))
            run.warn(run.outliers[-1].message)
        if t.xyz is None:
            n_reg = sum(1 for ob in p.observations if ob.image in run.lookup)
            run.problems.append(f"{p.name} ({len(p.observations)} observation(s), {n_reg} in registered images"
                                + (f": {t.notes[-1]}" if t.notes else "") + ")")
        else:
            run.usable.append(p)
    for name in run.problems:
        run.warn(f"control point not usable: {name}")


def _match_camera_positions(run: _Run, camera_positions: Optional[Sequence[CameraPosition]]) -> None:
    """The camera positions of registered images (the others are named and ignored)."""
    unmatched = []
    for cp in camera_positions or []:
        if not (math.isfinite(cp.x) and math.isfinite(cp.y)):
            raise GeorefError(f"camera position of {cp.image}: X or Y is not a number")
        im = run.lookup.get(cp.image)
        if im is None:
            unmatched.append(cp.image)
        else:
            run.cam_pos.append((cp, im))
    if unmatched:
        run.warn(f"{len(unmatched)} camera position(s) for images not registered in the model, "
                 f"ignored: {', '.join(unmatched[:10])}" + (" ..." if len(unmatched) > 10 else ""))
    run.no_height = [cp.image for cp, _ in run.cam_pos if not math.isfinite(cp.z)]
    if run.no_height:
        run.warn(f"{len(run.no_height)} camera position(s) without a height (Z): they constrain X and Y only")


def _placeholder_heights(run: _Run) -> None:
    """Every control point at the same Z (e.g. 0 when heights were not surveyed): a placeholder, loosened."""
    usable = run.usable
    if not (len(usable) >= 3 and len({float(p.z) for p in usable}) == 1):
        return
    sz = run.opt.placeholder_sigma_z
    run.placeholder_z = float(usable[0].z)
    loose = [p for p in usable if p.sigma_z < sz]
    run.warn(f"every control point has Z = {run.placeholder_z:g}: treated as a placeholder, not a surveyed height; "
             f"the points are taken to lie near one level surface (sigma Z {sz:g} m) and the "
             "Z figures measure the departure from that level, not height accuracy")
    if loose:
        repl = {p.name: dataclasses.replace(p, sigma_z=sz) for p in loose}
        run.usable = [repl.get(p.name, p) for p in usable]


def _initial_similarity(run: _Run, camera_positions) -> _Fit:
    """2. the similarity model -> local frame, by RANSAC on the control points (or the camera positions)."""
    if len(run.usable) >= 3:
        source = "control points"
        world = np.array([[p.x, p.y, p.z] for p in run.usable])
        model = np.array([run.tri[p.name].xyz for p in run.usable])
        sig = np.array([max(p.sigma_xy, p.sigma_z) for p in run.usable])
        objs: list = run.usable
    elif len(run.cam_pos) - len(run.no_height) >= 3:
        source = "camera positions"
        with_z = [(cp, im) for cp, im in run.cam_pos if math.isfinite(cp.z)]
        world = np.array([[cp.x, cp.y, cp.z] for cp, _ in with_z])
        model = np.array([im.projection_center() for _, im in with_z])
        sig = np.array([max(cp.sigma_xy, cp.sigma_z) for cp, _ in with_z])
        objs = [cp for cp, _ in with_z]
    else:
        raise GeorefError(_too_little_control(run, camera_positions))
    offset = _round_offset(world)
    world_local = world - offset
    free = np.array([not o.sigma_given for o in objs])
    if free.any():  # sigmas not given: the RANSAC threshold from a robust scale of the data instead
        s0 = lmeds_sigma(model, world_local)
        if s0 is not None:
            if source == "control points" and run.placeholder_z is not None:
                s0 = max(s0, run.opt.placeholder_sigma_z)
            sig[free] = s0
    extent = float(np.max(np.linalg.norm(world_local - world_local.mean(axis=0), axis=1)))
    thr = run.opt.helmert_threshold or max(0.05 * extent, 10.0 * float(np.median(sig)), 0.05)
    try:
        hel = helmert_ransac(model, world_local, thr)
    except ValueError as e:
        raise GeorefError(f"no consistent similarity between the model and the {source}: {e}") from e
    return _Fit(source, model, world_local, objs, offset, thr, hel)


def _too_little_control(run: _Run, camera_positions) -> str:
    usable, control = run.usable, run.control
    msg = (f"georeferencing needs at least 3 control points, each seen in at least 2 registered images, "
           f"or camera positions for at least 3 registered images; found {len(control)} control point(s), "
           f"{len(usable)} usable" + (f" ({', '.join(p.name for p in usable)})" if usable else ""))
    if run.problems:
        msg += "; not usable: " + "; ".join(run.problems)
    msg += f"; {len(run.cam_pos)} camera position(s) matched to registered images"
    if camera_positions:
        msg += f" (of {len(camera_positions)} given)"
    if run.no_height and len(run.cam_pos) >= 3:
        msg += (f", {len(run.no_height)} of them without a height (Z): positions without heights cannot fix the "
                "block's vertical datum; give Z or add control points")
    return msg


def _helmert_outliers(run: _Run, fit: _Fit) -> None:
    """Points off the Helmert fit.  Control points are only provisional outliers when the adjustment
    follows: on a deformed block (a long strip, a wrong calibration) a correct point can lie metres off the
    similarity of the others.  They are re-tested against the adjusted block (retest_provisional) and
    re-admitted when consistent with it; those that are not (a typo) are named in a warning then."""
    hel, source, thr = fit.helmert, fit.source, fit.threshold
    for k in np.flatnonzero(~hel.inliers):
        o = fit.objs[k]
        nm = o.name if source == "control points" else o.image
        run.outliers.append(Outlier("control point" if source == "control points" else "camera position", nm,
                                    float(hel.residuals[k]), "m", "helmert",
                                    message=f"{source[:-1]} {nm} is {hel.residuals[k]:.2f} m off the Helmert fit "
                                            f"of the others (threshold {thr:.2f} m): excluded; check its coordinates"))
        if source == "control points":
            run.rejected_ctrl.add(nm)
        if source == "control points" and run.opt.adjust:
            run.provisional[nm] = run.outliers[-1]
            run.progress.info(f"control point {nm} is {hel.residuals[k]:.2f} m off the Helmert fit of the others "
                              f"(threshold {thr:.2f} m): left out of the first adjustment, then re-tested against "
                              "the adjusted block")
        else:
            run.warn(run.outliers[-1].message)
    if source == "camera positions":
        bad = {fit.objs[k].image for k in np.flatnonzero(~hel.inliers)}
        run.cam_pos = [(cp, im) for cp, im in run.cam_pos if cp.image not in bad]


def _estimate_sigmas(run: _Run, fit: _Fit) -> None:
    """Step 1 of core.georef.control_sigma: the control points and camera positions given without sigmas get
    sigmas from the rigid fit's residuals (robust, floored at what the block resolves), in place of their
    placeholders; the adjustment refines them (``_variance_components``)."""
    free_pts = [p for p in run.usable if not p.sigma_given]
    free_cams = [cp for cp, _ in run.cam_pos if not cp.sigma_given]
    if not free_pts and not free_cams:
        return
    tr = fit.helmert.transform
    # the floor's pixel sigma: the tie points' own noise (what the block resolves), at most the adjustment's
    px = run.opt.gcp_pixel_sigma
    s0 = tie_point_sigma(run.rec)
    if math.isfinite(s0) and s0 > 0:
        px = min(px, s0)
    v_fit, r_fit = fit_residuals(tr, fit.model, fit.world_local, fit.helmert.inliers)
    in_fit = {(o.name if fit.source == "control points" else o.image): k for k, o in enumerate(fit.objs)
              if fit.helmert.inliers[k]}
    gsd = ground_sample_distance(run.rec) * tr.scale * px
    if free_pts:
        views = [(run.tri[p.name].xyz, [ob.image for k, ob in enumerate(p.observations) if run.tri[p.name].used[k]])
                 for p in free_pts]
        fxy, fz = intersection_precision(run.rec, run.lookup, views, px, tr)
        floor = (fxy, fz) if math.isfinite(fxy) else (gsd, gsd)
        if run.placeholder_z is not None:
            floor = (floor[0], max(floor[1], run.opt.placeholder_sigma_z))
        rows = []
        for p in free_pts:
            if fit.source == "control points":
                if p.name in in_fit:
                    rows.append((p.name, v_fit[in_fit[p.name]], r_fit[in_fit[p.name]]))
            else:
                d = np.array([p.x, p.y, p.z]) - fit.offset - tr.apply(run.tri[p.name].xyz)
                rows.append((p.name, d, np.ones(3)))
        prior = (float(np.median([p.sigma_xy for p in free_pts])), float(np.median([p.sigma_z for p in free_pts])))
        est = _group_estimate(CONTROL_GROUP, [p.name for p in free_pts], rows, floor, prior)
        run.sigma_estimates[CONTROL_GROUP] = est
        names = set(est.names)
        run.usable = [dataclasses.replace(p, sigma_xy=est.sigma_xy, sigma_z=est.sigma_z) if p.name in names else p
                      for p in run.usable]
    if free_cams:
        rows = []
        for cp, im in run.cam_pos:
            if cp.sigma_given:
                continue
            if fit.source == "camera positions":
                if cp.image in in_fit:
                    rows.append((cp.image, v_fit[in_fit[cp.image]], r_fit[in_fit[cp.image]]))
                continue
            d = np.array([cp.x, cp.y, cp.z]) - fit.offset - tr.apply(np.asarray(im.projection_center()))
            rows.append((cp.image, np.nan_to_num(d), np.array([1.0, 1.0, 1.0 if math.isfinite(cp.z) else 0.0])))
        prior = (float(np.median([c.sigma_xy for c in free_cams])), float(np.median([c.sigma_z for c in free_cams])))
        est = _group_estimate(CAMERA_GROUP, [c.image for c in free_cams], rows, (gsd, gsd), prior)
        if not any(math.isfinite(c.z) for c in free_cams):  # positions without heights: no Z to estimate
            est.sigma_z, est.helmert_z = prior[1], float("nan")
            est.note = "no heights: sigma Z not estimated"
        run.sigma_estimates[CAMERA_GROUP] = est
        run.cam_pos = [(dataclasses.replace(cp, sigma_xy=est.sigma_xy, sigma_z=est.sigma_z), im)
                       if not cp.sigma_given else (cp, im) for cp, im in run.cam_pos]
    for est in run.sigma_estimates.values():
        run.progress.info(est.message())


FIXED_SIGMA_RATIO = 100.0  # a given sigma this many times finer than the block resolves: the point is held fixed


def _given_sigmas_held_fixed(run: _Run, fit: _Fit) -> None:
    """Say so where control points were given sigmas far finer (``FIXED_SIGMA_RATIO``) than the block resolves at
    them (their forward intersection at the tie points' pixel noise): the adjustment honours them, i.e. holds
    those points fixed at their coordinates, which a sigma of 1e-9 m typed for "exact" means but a unit slip does
    not."""
    given = [p for p in run.usable if p.sigma_given]
    if not given:
        return
    px = run.opt.gcp_pixel_sigma
    s0 = tie_point_sigma(run.rec)
    if math.isfinite(s0) and s0 > 0:
        px = min(px, s0)
    tr = fit.helmert.transform
    views = [(run.tri[p.name].xyz, [ob.image for k, ob in enumerate(p.observations) if run.tri[p.name].used[k]])
             for p in given]
    fxy, fz = intersection_precision(run.rec, run.lookup, views, px, tr)
    if not (math.isfinite(fxy) and math.isfinite(fz)):
        return
    fine = [p for p in given if p.sigma_xy * FIXED_SIGMA_RATIO < fxy or p.sigma_z * FIXED_SIGMA_RATIO < fz]
    if not fine:
        return
    groups: Dict[Tuple[float, float], List[str]] = {}
    for p in fine:
        groups.setdefault((p.sigma_xy, p.sigma_z), []).append(p.name)
    said = "; ".join(f"{', '.join(n[:8])}{f' and {len(n) - 8} more' if len(n) > 8 else ''}: sigma XY {sxy:g} m, "
                     f"Z {sz:g} m" for (sxy, sz), n in groups.items())
    run.warn(f"control points given sigmas far finer than the block resolves at them (about {fxy:.3f} m XY, "
             f"{fz:.3f} m Z) - {said}: honoured as given, i.e. these points are held fixed at their coordinates; "
             "if they are not exact to that level give their real accuracy (e.g. 0.01 m for RTK)")


def _group_estimate(group: str, names: List[str], rows, floor, prior) -> SigmaEstimate:
    v = np.array([r[1] for r in rows], dtype=float).reshape(-1, 3)
    r = np.array([r[2] for r in rows], dtype=float).reshape(-1, 3)
    return estimate_group(group, names, [r[0] for r in rows], v, r, floor, prior)


def _consistency(run: _Run, fit: _Fit) -> Optional[Consistency]:
    """Which control points agree with each other through the model (a warning names the others)."""
    usable = run.usable
    if not (fit.source == "control points" and len(usable) >= 4):
        return None
    tol = max(3.0 * float(np.median([p.sigma_xy for p in usable])), 0.05)
    consistency = control_consistency(fit.model, fit.world_local, [p.name for p in usable], tol,
                                      xy_only=run.placeholder_z is not None)
    if consistency is not None and consistency.suspects and len(consistency.consistent) >= 3:
        run.warn(f"control points {', '.join(consistency.consistent)} agree with the block within "
                 f"{consistency.rms:.3f} m RMS, but " + ", ".join(
                     f"{n} ({consistency.residuals[n]:.2f} m)" for n in consistency.suspects) +
                 " do not: their coordinates, labels or image marks are suspect")
    elif consistency is not None and not consistency.consistent:
        run.warn(f"no 4 control points agree with the block within {tol:.3f} m: either the "
                 "block is deformed or several coordinates are wrong")
    if consistency is not None and run.opt.drop_suspect_control:
        _drop_suspects(run, consistency)
    return consistency


def _drop_suspects(run: _Run, consistency: Consistency) -> None:
    """The suspect control points left out of the adjustment for good (``drop_suspect_control``: automatic
    control), when the ones that agree are at least 3 and outnumber them."""
    agree, suspects = consistency.consistent, [n for n in consistency.suspects if n not in run.rejected_ctrl]
    if not suspects or len(agree) < 3 or len(suspects) >= len(agree):
        return
    for n in suspects:
        r = float(consistency.residuals.get(n, float("nan")))
        run.outliers.append(Outlier("control point", n, r, "m", "consistency",
                                    message=f"control point {n} disagrees with the others through the block "
                                            f"({r:.2f} m): suspect, dropped from the adjustment"))
        run.rejected_ctrl.add(n)
    run.progress.info(f"{len(suspects)} suspect control point(s) dropped from the adjustment: "
                      + ", ".join(f"{n} ({consistency.residuals.get(n, float('nan')):.2f} m)" for n in suspects))


@dataclass
class _Adjustment:
    """The bundle problem of step 4 and its bookkeeping."""

    prob: BundleProblem
    tie_ids: np.ndarray
    gcp_index: Dict[str, int]
    gcp_obs_rows: Dict[str, List[Tuple[int, str]]]
    sel_info: Dict[str, Any]
    ba_points: List[GroundPoint]
    removed_points: set = field(default_factory=set)
    iterations: int = 0
    rounds: int = 0  # rounds over all passes (the progress fractions keep growing)
    readmitted: List[str] = field(default_factory=list)
    retests: Dict[str, Dict[str, Any]] = field(default_factory=dict)

    @property
    def control(self) -> ControlRows:
        """The control points in the problem (sharing this bookkeeping's index, rows and removed set)."""
        return ControlRows(self.ba_points, self.gcp_index, self.gcp_obs_rows, self.removed_points)


def _adjust(run: _Run, fit: _Fit, stats: Dict[str, Any]) -> _Adjustment:
    """4. the constrained bundle adjustment, its outlier rounds and the re-tests of the provisional outliers."""
    check_cancel(run.progress)
    t0 = time.time()
    # the provisional outliers are part of the problem from the start, switched off until re-admitted
    ba_points = [p for p in run.usable if p.name not in run.rejected_ctrl or p.name in run.provisional]
    control = Control(ba_points, run.tri, run.cam_pos, fit.offset, fit.helmert.transform)
    built = build_problem(run.rec, run.lookup, control, run.opt, run.warn, run.progress)
    adj = _Adjustment(*built, ba_points=ba_points)
    for nm in run.provisional:
        set_point_active(adj.prob, adj.gcp_index[nm], adj.gcp_obs_rows[nm], False)
        adj.removed_points.add(nm)
    stats.update(adj.sel_info)
    run.timings["build"] = time.time() - t0
    t0 = time.time()
    while True:
        _outlier_rounds(run, adj)
        if not _readmit(run, adj):
            break
    if _variance_components(run, adj):
        while True:  # the outlier tests again, at the estimated sigmas
            _outlier_rounds(run, adj)
            if not _readmit(run, adj):
                break
    _final_provisional_messages(run, adj)
    run.timings["adjustment"] = time.time() - t0
    stats.update({"adjustment_iterations": adj.iterations, "outlier_rounds": adj.rounds,
                  "control_points_adjusted": len(ba_points) - len(run.provisional),
                  "readmitted_control_points": adj.readmitted,
                  "helmert_retests": {nm: {k: v for k, v in t.items() if k != "xyz"}
                                      for nm, t in adj.retests.items()}})
    return adj


def _variance_components(run: _Run, adj: _Adjustment) -> bool:
    """Step 2 of core.georef.control_sigma: the estimated sigmas refined by variance components in the
    adjustment, the problem solved at them.  True if there was anything to estimate."""
    prob = adj.prob
    groups = []
    est = run.sigma_estimates.get(CONTROL_GROUP)
    if est is not None:
        rows = np.array([adj.gcp_index[nm] for nm in est.names if nm in adj.gcp_index], dtype=int)
        if len(rows):
            groups.append(VarianceGroup("point", rows, est, (est.floor_xy, est.floor_z)))
    est = run.sigma_estimates.get(CAMERA_GROUP)
    if est is not None:
        names = set(est.names)
        rows = np.array([k for k, img in enumerate(prob.cam_pos_images) if img in names], dtype=int)
        if len(rows):
            groups.append(VarianceGroup("camera", rows, est, (est.floor_xy, est.floor_z)))
    if not groups:
        return False
    run.progress.report(0.8, "estimating the accuracy of the control given without sigmas")
    variance_components(prob, groups, max_iterations=run.opt.max_iterations)
    for g in groups:
        run.progress.info(g.estimate.message())
    return True


def _outlier_rounds(run: _Run, adj: _Adjustment) -> None:
    """Solve; remove the worst GCP observation / control point / camera position beyond its threshold; repeat."""
    opt = run.opt
    for pass_round in range(1, opt.max_outlier_rounds + 2):
        adj.rounds += 1
        check_cancel(run.progress)
        lo, hi = 0.12 + 0.7 * (1 - 0.5 ** (adj.rounds - 1)), 0.12 + 0.7 * (1 - 0.5 ** adj.rounds)
        sub = SubProgress(run.progress, lo, hi)
        info = adj.prob.solve(max_iterations=opt.max_iterations, progress=sub)
        adj.iterations += info["iterations"]
        if pass_round > opt.max_outlier_rounds:
            break
        min_left = 0 if run.cam_pos else 3
        found = find_outlier(adj.prob, adj.control, opt.outlier_threshold, opt.outlier_sigma, min_left)
        if found is None:
            break
        run.outliers.append(found)
        run.warn(found.message)
        if found.kind == "control point":
            run.rejected_ctrl.add(found.name)
            adj.removed_points.add(found.name)


def _readmit(run: _Run, adj: _Adjustment) -> bool:
    """Re-test the provisional outliers against the adjusted block and re-admit the consistent ones (the
    caller adjusts again: a point re-admitted can make another one consistent).  True if any came back."""
    if not run.provisional:
        return False
    prob = adj.prob
    thr_px, thr_z = control_thresholds(prob, adj.control, run.opt.outlier_threshold, run.opt.outlier_sigma)
    back = []
    for nm in run.provisional:
        t = retest_provisional(prob, adj.gcp_index[nm], adj.gcp_obs_rows[nm])
        t.update({"threshold_px": thr_px, "threshold_sigma": thr_z})
        adj.retests[nm] = t
        if t["sigma"] <= thr_z and t["px"] <= thr_px:
            back.append(nm)
    for nm in back:
        out = run.provisional.pop(nm)
        run.outliers.remove(out)
        run.rejected_ctrl.discard(nm)
        adj.removed_points.discard(nm)
        k = adj.gcp_index[nm]
        prob.X[k] = adj.retests[nm]["xyz"]
        set_point_active(prob, k, adj.gcp_obs_rows[nm], True)
        adj.readmitted.append(nm)
        t = adj.retests[nm]
        run.progress.info(f"control point {nm}: {out.residual:.2f} m off the Helmert fit of the others, but "
                          f"consistent with the adjusted block ({t['sigma']:.1f} sigma, image residuals up to "
                          f"{t['px']:.1f} px): re-admitted; the block was deformed")
    return bool(back)


def _final_provisional_messages(run: _Run, adj: _Adjustment) -> None:
    for nm, out in run.provisional.items():  # still off the adjusted block: outliers for good
        t = adj.retests.get(nm)
        if t is not None and np.isfinite(t["sigma"]):
            rays = (f"its rays meet {t['free_distance_m']:.2f} m from its coordinates in the adjusted block; "
                    if t.get("free_distance_m") is not None else "")
            out.message = (f"control point {nm} is {out.residual:.2f} m off the Helmert fit of the others; {rays}"
                           f"held to its coordinates it stays {t['sigma']:.1f} sigma off with image residuals up to "
                           f"{t['px']:.1f} px (thresholds {t['threshold_sigma']:.1f} sigma, {t['threshold_px']:.1f} "
                           "px): excluded; check its coordinates")
        run.warn(out.message)


SIGMA_CHECK_FACTOR = 10.0  # the rigid block misses the control points by more than this many sigmas: say so


def _sigma_check(run: _Run, result: GeorefResult, consistency: Optional[Dict[str, Any]] = None) -> None:
    """Warn where the control points' stated accuracy is far better than the block can agree with: the rigid
    block (the Helmert step) misses the control points used by more than SIGMA_CHECK_FACTOR x their sigma XY
    (the median point, so that one wrong coordinate, which the outlier tests name, does not count; at least 4
    points, at least 0.1 m), and no more than half of them agree with each other through the rigid block (the
    consistency test: then a few wrong coordinates, named by it, are the cause, not the sigma).  With such sigmas
    the adjustment bends the block to fit the points (handheld GPS read as survey grade).  Only points whose
    sigmas were given: the others' sigmas are estimated from the data (``_estimate_sigmas``)."""
    given = {p.name: p for p in run.points if p.sigma_given}
    rows = [r for r in result.helmert_points if r.status == USED and r.role == CONTROL and r.dx is not None
            and r.name in given and r.name not in run.rejected_ctrl and math.isfinite(r.dx) and math.isfinite(r.dy)]
    if len(rows) < 4:
        return
    miss = float(np.median([math.hypot(r.dx, r.dy) for r in rows]))
    sig = float(np.median([given[r.name].sigma_xy for r in rows]))
    if miss < 0.1 or miss < SIGMA_CHECK_FACTOR * sig:
        return
    if consistency and 2 * len(consistency.get("consistent") or ()) > len(rows):
        return
    run.warn(f"the control points' sigma XY ({sig:g} m) is far below how well the block fits them: "
             f"{len(rows)} control points miss the rigid block by {miss:.2f} m (median, {miss / sig:.0f} sigma), "
             f"and the adjustment bends the block to fit them; if their coordinates are metre-level (handheld "
             f"GPS, read off a map) give the file sigma columns of that size, or none: without sigmas their "
             f"accuracy is estimated from the data")


def _update_and_evaluate(run: _Run, adj: _Adjustment, result: GeorefResult, camera_positions,
                         stats: Dict[str, Any]) -> None:
    """5. write back, re-triangulate the tie points left out, evaluate the ground points and cameras."""
    t0 = time.time()
    rec, prob, progress = run.rec, adj.prob, run.progress
    progress.report(0.85, "updating the model")
    write_back(rec, prob, adj.tie_ids, adj.sel_info.get("_frame_ids"), adj.sel_info.get("_camera_ids"))
    stats.pop("_frame_ids", None)
    stats.pop("_camera_ids", None)
    if adj.sel_info.get("subsampled"):
        refine_tie_points(rec, run.opt.huber_px, progress)
    rec.update_point_3d_errors()
    run.timings["update"] = time.time() - t0
    lookup = registered_images(rec)
    check_cancel(progress)
    progress.report(0.95, "check points")
    result.points = _evaluate_points(rec, run.points, result.offset, run.rejected_ctrl, lookup, run.all_names,
                                     run.opt.outlier_threshold)
    result.cameras = _camera_rows(rec, [(cp, lookup.get(cp.image)) for cp in camera_positions or []
                                        if cp.image in lookup], result.offset, lookup,
                                  used={cp.image for cp, _ in run.cam_pos} - removed_cameras(run.outliers))
    result.mean_reprojection_error = _mean_tie_error(rec)
    gres = []
    for p in adj.ba_points:
        if p.name in adj.removed_points:
            continue
        rows = [r for r, _ in adj.gcp_obs_rows[p.name] if prob.obs.active[r]]
        if rows:
            res, _ = prob.reprojection(np.asarray(rows))
            gres.extend(np.linalg.norm(res, axis=1).tolist())
    result.gcp_reprojection_error = float(np.mean(gres)) if gres else float("nan")
    result.refined_intrinsics = {int(cid): [float(v) for v in rec.cameras[cid].params]
                                 for cid in adj.sel_info.get("refined_cameras", [])}
    result.adjusted = True
    result.sigma_estimates = stats["sigma_estimates"] = [e.to_dict() for e in run.sigma_estimates.values()]
    _set_used_sigmas(adj, result)
    _sigma_check(run, result, stats.get("control_consistency"))
    run.timings["total"] = time.time() - run.t_start
    stats["timings"] = run.timings
    stats.pop("refined_cameras", None)
    result.statistics = stats
    progress.report(1.0, "georeferencing done")


def _set_used_sigmas(adj: _Adjustment, result: GeorefResult) -> None:
    """The sigmas each control point and camera position had in the adjustment (given or estimated), on their
    residual rows."""
    prob = adj.prob
    for r in result.points:
        k = adj.gcp_index.get(r.name)
        if r.role == CONTROL and k is not None:
            r.sigma_xy, r.sigma_z = float(prob.pps[k, 0]), float(prob.pps[k, 2])
    sig = {img: prob.cp_sigma[k] for k, img in enumerate(prob.cam_pos_images)}
    for c in result.cameras:
        if c.image in sig:
            c.sigma_xy = float(sig[c.image][0])
            c.sigma_z = float(sig[c.image][2]) if sig[c.image][2] < 1e11 else None


def _check_crs(crs: str, warn: Callable[[str], None]) -> None:
    if not crs:
        warn("no CRS given for the ground control")
        return
    try:
        from osgeo import osr
    except ImportError:  # pragma: no cover
        return
    srs = osr.SpatialReference()
    try:
        ok = srs.SetFromUserInput(crs) == 0
    except Exception:  # noqa: BLE001 - GDAL raises or returns an error code, depending on UseExceptions
        ok = False
    if not ok:
        warn(f"CRS {crs!r} not recognised; assuming metric, right-handed coordinates")
        return
    if srs.IsGeographic():
        raise GeorefError(f"the control (GCPs or camera positions) is in a geographic CRS ({crs}); the adjustment "
                          "needs metric coordinates: give a projected CRS to georeference in (e.g. the block's UTM "
                          "zone, EPSG:326zz north / EPSG:327zz south); the control is reprojected into it")


def _round_offset(xyz: np.ndarray) -> np.ndarray:
    """Offset for the local frame: the mean rounded to 100 m horizontally, 0 vertically (heights stay true)."""
    m = np.mean(np.asarray(xyz, dtype=float).reshape(-1, 3), axis=0)
    return np.array([round(m[0] / 100.0) * 100.0, round(m[1] / 100.0) * 100.0, 0.0])


def _mean_tie_error(rec) -> float:
    rec.update_point_3d_errors()
    try:
        return float(rec.compute_mean_reprojection_error())
    except Exception:  # noqa: BLE001
        return float("nan")


def _evaluate_points(rec, points: Sequence[GroundPoint], offset, rejected: set, lookup, all_names,
                     outlier_threshold: float) -> List[PointResidual]:
    rows = []
    for p in points:
        t = triangulate_observations(rec, p.observations, max_error_px=max(outlier_threshold, 1.0) * 4,
                                     _lookup=lookup, _all_names=all_names)
        if p.role == CHECK:
            status = CHECKED
        elif p.name in rejected:
            status = REJECTED
        else:
            status = USED
        obs_rows = [{"image": ob.image, "x": ob.x, "y": ob.y,
                     "px": (float(t.residuals_px[k]) if np.isfinite(t.residuals_px[k]) else None)}
                    for k, ob in enumerate(p.observations)]
        if t.xyz is None and status != REJECTED:
            status = NOT_TRIANGULATED
        row = PointResidual(p.name, p.role, status, p.x, p.y, p.z, n_obs=t.n_used, observations=obs_rows,
                            notes=list(t.notes))
        if t.xyz is not None:
            d = (t.xyz + offset) - np.array([p.x, p.y, p.z])
            row.dx, row.dy, row.dz = float(d[0]), float(d[1]), float(d[2])
        rows.append(row)
    return rows


def _camera_rows(rec, cam_pos, offset, lookup, used: Optional[set] = None) -> List[CameraResidual]:
    rows = []
    for cp, im in cam_pos:
        im = lookup.get(cp.image)
        if im is None:
            continue
        c = np.asarray(im.projection_center()) + offset
        d = c - np.array([cp.x, cp.y, cp.z])
        rows.append(CameraResidual(cp.image, cp.x, cp.y, cp.z, float(d[0]), float(d[1]), float(d[2]),
                                   True if used is None else cp.image in used))
    return rows


__all__ = ["georeference"]
