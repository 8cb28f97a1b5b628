"""Mapping: incremental (COLMAP) or global (GLOMAP) reconstruction, the final bundle adjustment, and the
figures read back from the database and the model (verified partners, camera rows, camera summary)."""
from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from typing import Callable, Collection, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.cancel import CancelWatcher
from ..common.progress import Progress, check_cancel
from .calibrated import GivenCamera, restore_held
from .options import AlignOptions


@dataclass
class MappingJob:
    """What a mapping works on: the database, the photos' folder, a scratch folder for COLMAP's models, and how
    many images were given."""

    db_path: str
    images_dir: str
    out_dir: str
    n_images: int
    # set by map_block: the self-calibrated focal length drifted from the photos' own (EXIF, calibration) and the
    # mapping that held it registered more: the final adjustment holds it too (the drift figures, for the record)
    focal_held: Optional[dict] = None


def verified_links(pycolmap, db_path, min_inliers: int):
    """(every image name, the name pairs of the database with at least ``min_inliers`` verified inliers)."""
    db = pycolmap.Database.open(db_path)
    try:
        names = {im.image_id: im.name for im in db.read_all_images()}
        pair_ids, counts = db.read_two_view_geometry_num_inliers()
        links = []
        for pid, c in zip(pair_ids, counts):
            if c >= min_inliers:
                i, j = pycolmap.pair_id_to_image_pair(pid)
                links.append((names[i], names[j]))
        return list(names.values()), links
    finally:
        db.close()


def verified_partners(pycolmap, db_path, min_inliers: int) -> Dict[str, int]:
    names, links = verified_links(pycolmap, db_path, min_inliers)
    partners = {n: 0 for n in names}
    for a, b in links:
        partners[a] += 1
        partners[b] += 1
    return partners


def verified_pairs(pycolmap, db_path, min_inliers: int) -> int:
    """How many image pairs of the database have at least ``min_inliers`` verified inliers."""
    db = pycolmap.Database.open(db_path)
    try:
        _pair_ids, counts = db.read_two_view_geometry_num_inliers()
        return int(sum(1 for c in counts if c >= min_inliers))
    finally:
        db.close()


def run_mapping(pycolmap, job: MappingJob, options: AlignOptions, progress: Progress, hold_all: bool = False,
                hold_focal: bool = False, start=None):
    """The reconstructions of the database.  ``start``: a reconstruction to continue (incremental mapping from
    it, whichever mapper the options name: the escalation's extension of a large block, core.align.escalation);
    its registered images must keep the features they were registered with.  ``hold_all``: every camera's intrinsics are given and held
    (core.align.calibrated): no adjustment of the mapping refines focal length, principal point or distortion.
    ``hold_focal``: the focal lengths stay at their priors (distortion is still refined; see map_block).
    COLMAP's switches are global: with some cameras held and some estimated the mapping refines all, and the stage
    sets the held ones back to their given values before the final bundle adjustment holds them."""
    n_images = job.n_images
    if options.mapper == "global" and n_images <= 2:
        progress.info("mapping: two images, mapped with the incremental mapper (the global mapper needs tracks of "
                      "three or more views)")
    elif options.mapper == "global" and start is None:
        return _map_global(pycolmap, job, options, progress, hold_all, hold_focal)
    opts = pycolmap.IncrementalPipelineOptions()
    if hold_all or hold_focal:
        opts.ba_refine_focal_length = False
        opts.mapper.abs_pose_refine_focal_length = False
    if hold_all:
        opts.ba_refine_extra_params = False
        opts.mapper.abs_pose_refine_extra_params = False
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.mapper.random_seed = options.seed
    opts.triangulation.random_seed = options.seed
    opts.ba_refine_principal_point = False
    # the mapper's global adjustments leave out points that add little coverage (COLMAP's pruning by coverage
    # gain): Toledo 57 at 1200 px 34.5 -> 22.6 CPU s, at 2400 px 84.5 -> 46-56 CPU s, the same 57 images and
    # points; the stage's final adjustment then refines every point (docs/measurements.md)
    opts.mapper.ba_global_ignore_redundant_points3D = True
    opts.min_model_size = min_model_size(n_images)
    if n_images <= 2:  # every track of a stereo pair has two views: COLMAP skips those by default
        opts.triangulation.ignore_two_view_tracks = False
    state = {"n": 0}

    def on_next():
        state["n"] += 1
        progress.report(min(1.0, state["n"] / max(1, n_images)), f"mapping: registered image {state['n']}")

    input_path = ""
    if start is not None:
        input_path = os.path.join(job.out_dir, "start")
        os.makedirs(input_path, exist_ok=True)
        start.write(input_path)
        opts.multiple_models = False
        progress.info(f"mapping: continuing the block of {start.num_reg_images()} images")
    with CancelWatcher(progress) as token:
        recs = pycolmap.incremental_mapping(job.db_path, job.images_dir, job.out_dir, options=opts,
                                            input_path=input_path, next_image_callback=on_next,
                                            cancellation_token=token)
    check_cancel(progress)
    if recs and n_images > 2:
        recs = _register_rest(pycolmap, recs, job, opts, progress, on_next)
    return recs


# the continuation's 2D-3D threshold (COLMAP's abs_pose_min_num_inliers is 30): a steep oblique whose few tie
# points reach the block only through one or two neighbours has 15-29 correspondences once the block is complete
RELAXED_ABS_POSE_MIN_INLIERS = 15


def _register_rest(pycolmap, recs, job: MappingJob, opts, progress: Progress, on_next):
    """Register the images the mapping left out into its largest model, continued from where it stopped, with
    the 2D-3D inlier threshold relaxed to RELAXED_ABS_POSE_MIN_INLIERS.  The first pass keeps COLMAP's threshold
    so that every image it can place is placed on the full threshold; only what is left is tried on the relaxed
    one, against the finished model (the most 2D-3D correspondences it will have).  On the synthetic orbit this
    registers 15 of 16 views where the first pass registers 13 (pycolmap's defaults: 15); poses, degenerate
    cameras and the final adjustment are checked as for any image.  Returns ``recs`` with the largest model
    replaced when the continuation registered more images."""
    db_path, images_dir, out_dir, n_images = job.db_path, job.images_dir, job.out_dir, job.n_images
    key, best = max(recs.items(), key=lambda kv: kv[1].num_reg_images())
    before = {best.images[i].name for i in best.reg_image_ids()}
    if len(before) >= n_images or len(before) < 3:
        return recs
    # only an image with a verified pair into the block can be registered: without one (a foreign photo) the pass
    # would reload the whole database for nothing
    _names, links = verified_links(pycolmap, db_path, opts.min_num_matches)
    if not any((a in before) != (b in before) for a, b in links):
        return recs
    in_dir = os.path.join(out_dir, "continue-in")
    cont_dir = os.path.join(out_dir, "continue")
    os.makedirs(in_dir, exist_ok=True)
    os.makedirs(cont_dir, exist_ok=True)
    best.write(in_dir)
    relaxed = pycolmap.IncrementalPipelineOptions(opts.todict())
    relaxed.multiple_models = False
    relaxed.mapper.abs_pose_min_num_inliers = min(RELAXED_ABS_POSE_MIN_INLIERS, opts.mapper.abs_pose_min_num_inliers)
    progress.info(f"mapping: {n_images - len(before)} image(s) outside the main block of {len(before)}; trying "
                  f"them against the finished block with {relaxed.mapper.abs_pose_min_num_inliers} 2D-3D "
                  f"inliers (first pass: {opts.mapper.abs_pose_min_num_inliers})")
    with CancelWatcher(progress) as token:
        more = pycolmap.incremental_mapping(db_path, images_dir, cont_dir, options=relaxed, input_path=in_dir,
                                            next_image_callback=on_next, cancellation_token=token)
    check_cancel(progress)
    grown = max(more.values(), key=lambda r: r.num_reg_images()) if more else None
    if grown is None or grown.num_reg_images() <= len(before):
        progress.info("mapping: no further image registered")
        return recs
    added = sorted({grown.images[i].name for i in grown.reg_image_ids()} - before)
    progress.info(f"mapping: {len(added)} more image(s) registered on the relaxed threshold: {', '.join(added)}")
    out = dict(recs)
    out[key] = grown
    return out


def min_model_size(n_images: int) -> int:
    """The smallest model the mapper keeps: 3 images (small separate components are kept so they can be
    reported by name), 2 when only two images are given (a stereo pair is a valid block)."""
    return 2 if n_images <= 2 else 3


def _map_global(pycolmap, job: MappingJob, options: AlignOptions, progress: Progress, hold_all: bool = False,
                hold_focal: bool = False):
    """GLOMAP's global pipeline (rotation averaging, global positioning, bundle adjustment).  pycolmap 4.2
    gives it no cancellation token and no progress callback: a cancel takes effect when it returns."""
    opts = pycolmap.GlobalPipelineOptions()
    if hold_all:
        opts.mapper.bundle_adjustment.refine_focal_length = False
        opts.mapper.bundle_adjustment.refine_extra_params = False
        opts.mapper.bundle_adjustment.refine_principal_point = False
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.min_model_size = min_model_size(job.n_images)
    progress.report(0.0, "mapping: global SfM (rotation averaging, global positioning, bundle adjustment)")
    check_cancel(progress)
    recs = pycolmap.global_mapping(job.db_path, job.images_dir, job.out_dir, options=opts)
    check_cancel(progress)
    progress.report(1.0, "mapping: global SfM done")
    return recs


# a registered camera whose focal length is outside these multiples of the image's long side is degenerate (COLMAP's
# own bounds for bogus cameras): a view self-calibrated from a few points can come back from the mapper with a
# focal of 10^8 px, and the bundle adjustment then diverges on it (the block's mean reprojection error 10^151)
MIN_FOCAL_RATIO, MAX_FOCAL_RATIO = 0.1, 10.0


def degenerate_camera(cam) -> str:
    """Why a camera's parameters are degenerate, or "" when they are not: non-finite values, or a focal length
    outside MIN_FOCAL_RATIO..MAX_FOCAL_RATIO times the long side (distortion is not judged: a wide lens may have
    large coefficients)."""
    params = [float(v) for v in cam.params]
    if not all(math.isfinite(v) for v in params):
        return "could not be registered: the mapper gave it non-finite camera parameters"
    if cam.has_bogus_params(MIN_FOCAL_RATIO, MAX_FOCAL_RATIO, math.inf):
        return (f"could not be registered: the mapper gave it a degenerate camera (focal "
                f"{cam.mean_focal_length():.4g} px for a {cam.width} x {cam.height} photo)")
    return ""


def drop_degenerate(rec) -> Dict[str, str]:
    """De-register the images of ``rec`` whose camera is degenerate (see :func:`degenerate_camera`); returns
    image name -> why.  Their observations go with them, so neither the bundle adjustment nor a later stage
    sees them."""
    dropped: Dict[str, str] = {}
    for image_id in list(rec.reg_image_ids()):
        im = rec.images[image_id]
        why = degenerate_camera(rec.cameras[im.camera_id])
        if why:
            dropped[im.name] = why
            rec.deregister_frame(im.frame_id)
    return dropped


# a function of the block giving the position priors of its registered images (pycolmap.PosePrior): the final
# adjustment of a block joined by the photos' positions keeps them (core.align.joining.PositionJoin)
Priors = Optional[Callable[[object], list]]


def final_bundle_adjustment(pycolmap, rec, options: AlignOptions, progress: Progress,
                            held: Collection[int] = (), hold_focal: bool = False, priors: Priors = None):
    """The final global bundle adjustment; the cameras ``held`` (ids) keep their intrinsics constant, with
    ``hold_focal`` every camera its focal length (MappingJob.focal_held); ``priors``: the position priors it keeps
    (a block joined by the photos' positions; they fix the gauge).  Returns whether the principal point was
    refined (of the cameras not held)."""
    ba = pycolmap.BundleAdjustmentOptions()
    ba.print_summary = False
    counts: Dict[int, int] = {}
    for im in rec.images.values():
        if im.has_pose:
            counts[im.camera_id] = counts.get(im.camera_id, 0) + 1
    free = {cid: n for cid, n in counts.items() if cid not in held}
    ba.refine_principal_point = bool(options.refine_principal_point and free
                                     and min(free.values()) >= options.min_images_opencv)
    ba.ceres.loss_function_type = pycolmap.LossFunctionType.CAUCHY
    ba.ceres.solver_options.max_num_iterations = 30  # the mapper's last global BA has already converged
    if hold_focal:  # the geometry that let the focal length drift cannot fix the principal point either
        ba.refine_focal_length = ba.refine_principal_point = False
    if counts and not free:  # every camera held: the adjustment's own switches (and its cancellation token)
        ba.refine_focal_length = ba.refine_extra_params = ba.refine_principal_point = False
    if priors is not None:
        _adjust_holding(pycolmap, rec, ba, [cid for cid in held if cid in counts], priors(rec))
    elif free and any(cid in counts for cid in held):
        _adjust_holding(pycolmap, rec, ba, [cid for cid in held if cid in counts])
    else:
        with CancelWatcher(progress) as token:
            pycolmap.bundle_adjustment(rec, ba, cancellation_token=token)
    check_cancel(progress)
    return ba.refine_principal_point


def _adjust_holding(pycolmap, rec, ba, held: Sequence[int], priors: Optional[list] = None) -> None:
    """pycolmap.bundle_adjustment's own steps (observations behind a camera dropped, every registered image, the
    gauge fixed on two cameras) with the ``held`` cameras' intrinsics constant; with position ``priors`` pycolmap's
    pose-prior adjuster, the gauge fixed by the priors (pycolmap gives this path no cancellation token: a cancel
    takes effect when it returns)."""
    pycolmap.ObservationManager(rec).filter_observations_with_negative_depth()
    config = pycolmap.BundleAdjustmentConfig()
    for image_id in rec.reg_image_ids():
        config.add_image(image_id)
    for cid in held:
        config.set_constant_cam_intrinsics(cid)
    if priors is not None:
        pycolmap.create_pose_prior_bundle_adjuster(ba, pycolmap.PosePriorBundleAdjustmentOptions(), config, priors,
                                                   rec).solve()
        return
    config.fix_gauge(pycolmap.BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD)
    pycolmap.create_default_bundle_adjuster(ba, config, rec).solve()


def camera_rows(rec) -> List[dict]:
    """Per registered image: name, camera id, projection centre (model frame), viewing direction."""
    rows = []
    for im in sorted(rec.images.values(), key=lambda i: i.name):
        if not im.has_pose:
            continue
        c = np.asarray(im.projection_center(), dtype=float)
        d = np.asarray(im.viewing_direction(), dtype=float)
        rows.append({"image": im.name, "camera_id": int(im.camera_id), "x": float(c[0]), "y": float(c[1]),
                     "z": float(c[2]), "dx": float(d[0]), "dy": float(d[1]), "dz": float(d[2]),
                     "points": int(im.num_points3D)})
    return rows


def camera_summary(rec) -> List[dict]:
    out = []
    for cam in rec.cameras.values():
        out.append({"camera_id": int(cam.camera_id), "model": cam.model.name, "width": int(cam.width),
                    "height": int(cam.height), "params": [float(v) for v in cam.params],
                    "params_info": cam.params_info})
    return out


def map_block(pycolmap, job: MappingJob, options: AlignOptions, progress: Progress,
              degenerate: Optional[Dict[str, str]] = None,
              held: Optional[Tuple[Dict[int, GivenCamera], bool]] = None, start=None) -> list:
    """The reconstructions, largest first, without the images the mapper gave a degenerate camera: those are added
    to ``degenerate`` (name -> why; an image's entry says why a mapping last left it out).  The mapping works in
    ``job.out_dir``, removed afterwards.  ``held``: (camera id -> given interior orientation of the cameras held,
    whether that is every camera); the held cameras come back with exactly their given values.  ``start``: a
    reconstruction the mapping continues (see run_mapping) instead of starting afresh."""
    held_ids, hold_all = held or ({}, False)
    drifted = job.focal_held is not None  # an earlier mapping of this block held the intrinsics: so does this one
    recs = _mapped(pycolmap, job, options, progress, hold_all or drifted, drifted, start)
    if not hold_all and job.focal_held is None and start is None:
        recs = _against_focal_drift(pycolmap, job, options, progress, recs)
    for rec in (recs.values() if recs else ()):
        restore_held(rec, held_ids)
    dropped: Dict[str, str] = {}
    for rec in (recs.values() if recs else ()):
        dropped.update(drop_degenerate(rec))
    for name, why in dropped.items():
        progress.warning(f"mapping: {name} {why}: left out of the block")
    if degenerate is not None:
        degenerate.update(dropped)
    kept = [r for r in (recs.values() if recs else ()) if r.num_reg_images() > 0]
    return sorted(kept, key=lambda r: r.num_reg_images(), reverse=True)


def _mapped(pycolmap, job: MappingJob, options: AlignOptions, progress: Progress, hold_all: bool,
            hold_focal: bool, start=None):
    shutil.rmtree(job.out_dir, ignore_errors=True)
    os.makedirs(job.out_dir)
    try:
        return run_mapping(pycolmap, job, options, progress, hold_all=hold_all, hold_focal=hold_focal, start=start)
    finally:
        shutil.rmtree(job.out_dir, ignore_errors=True)


# the self-calibrated focal length may leave the photos' own (EXIF, a calibration) by this factor before the
# mapping is tried again with it held: a 35 mm-equivalent focal in EXIF is within a few per cent of the lens's;
# a drift beyond a quarter is the mapper's (a flat scene under a wide lens ties the focal length to the height, and
# a block of few images takes the wrong one: garfield_rgb_small's focal went from 1,243 to 3,774 px and the block
# split in 7 components; held, all 28 photos registered)
FOCAL_DRIFT_LIMIT = 1.25


def prior_focals(pycolmap, db_path: str) -> Dict[int, float]:
    """camera id -> the focal length (px) the database was given for it, for the cameras that have a prior."""
    db = pycolmap.Database.open(db_path)
    try:
        return {c.camera_id: float(c.mean_focal_length()) for c in db.read_all_cameras() if c.has_prior_focal_length}
    finally:
        db.close()


def focal_drift(rec, priors: Dict[int, float]) -> Tuple[float, Optional[int]]:
    """The largest ratio (>= 1) between a camera's focal length in ``rec`` and its prior, and that camera."""
    worst, which = 1.0, None
    used = {im.camera_id for im in rec.images.values() if im.has_pose}
    for cid, cam in rec.cameras.items():
        f0 = priors.get(cid)
        if f0 and f0 > 0 and cid in used:
            f = float(cam.mean_focal_length())
            r = max(f / f0, f0 / f) if f > 0 and math.isfinite(f) else math.inf
            if r > worst:
                worst, which = r, cid
    return worst, which


def _against_focal_drift(pycolmap, job: MappingJob, options: AlignOptions, progress: Progress, recs):
    """When the largest model's focal length drifted more than FOCAL_DRIFT_LIMIT from the photos' own and the
    model does not hold every image, map again with the intrinsics held (the final adjustment then refines the
    distortion, the focal length still held) and keep the mapping that registers more images (``job.focal_held``
    says so).  Holding the focal length alone is not enough: on garfield_rgb_small the distortion then drifts
    instead (28/28 registered, camera centres 25 m RMSE from a rigid fit to their GPS, against 12 m with the
    intrinsics held during the mapping)."""
    models = [r for r in (recs.values() if recs else ()) if r.num_reg_images() > 0]
    if not models:
        return recs
    best = max(models, key=lambda r: r.num_reg_images())
    priors = prior_focals(pycolmap, job.db_path)
    drift, cid = focal_drift(best, priors)
    if drift <= FOCAL_DRIFT_LIMIT or best.num_reg_images() >= job.n_images:
        return recs
    f = float(best.cameras[cid].mean_focal_length())
    progress.info(f"mapping: the self-calibrated focal length went from {priors[cid]:.0f} to {f:.0f} px and "
                  f"{best.num_reg_images()} of {job.n_images} images registered; mapping again with the "
                  "photos' own focal length and the distortion held")
    held = _mapped(pycolmap, job, options, progress, True, True)
    counts = [r.num_reg_images() for r in (held.values() if held else ())]
    if max(counts or [0]) <= best.num_reg_images():
        progress.info(f"mapping: with the intrinsics held {max(counts or [0])} images registered: the "
                      "self-calibrated mapping is kept")
        return recs
    job.focal_held = {"prior_px": round(priors[cid], 2), "drifted_px": round(f, 2),
                      "registered_free": best.num_reg_images(), "registered_held": max(counts)}
    progress.warning(f"mapping: the focal length is held at the photos' own ({priors[cid]:.0f} px; the distortion "
                     "refined only by the final adjustment): "
                     f"self-calibrated it drifted to {f:.0f} px and registered {best.num_reg_images()} of "
                     f"{job.n_images} images, held {max(counts)}")
    return held


def adjust_block(pycolmap, rec, options: AlignOptions, progress: Progress, held: Collection[int],
                 degenerate: Dict[str, str], hold_focal: bool = False, priors: Priors = None) -> bool:
    """The final global bundle adjustment (the ``held`` cameras' intrinsics constant, the position ``priors`` kept
    where given: see final_bundle_adjustment); a camera with few points that the adjustment sent off goes out
    (added to ``degenerate``), and the adjustment runs again, until none.  Returns whether the principal point was
    refined."""
    pp = final_bundle_adjustment(pycolmap, rec, options, progress, held, hold_focal, priors)
    for _ in range(rec.num_reg_images()):
        diverged = drop_degenerate(rec)
        if not diverged:
            break
        for name, why in diverged.items():
            progress.warning(f"final bundle adjustment: {name} {why}: left out of the block")
        degenerate.update(diverged)
        pp = final_bundle_adjustment(pycolmap, rec, options, progress, held, hold_focal, priors)
    return pp
