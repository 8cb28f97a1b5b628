"""Mapping: incremental (COLMAP) or global (GLOMAP) reconstruction, the final bundle adjustment, and the
figures read back from the database and the model (verified partners, camera rows, camera summary)."""
from __future__ import annotations

import math
from typing import Dict, List

import numpy as np

from ..common.cancel import CancelWatcher
from ..common.progress import Progress, check_cancel
from .options import AlignOptions


def verified_partners(pycolmap, db_path, min_inliers: int) -> Dict[str, int]:
    db = pycolmap.Database.open(db_path)
    try:
        names = {im.image_id: im.name for im in db.read_all_images()}
        pair_ids, counts = db.read_two_view_geometry_num_inliers()
        partners = {n: 0 for n in names.values()}
        for pid, c in zip(pair_ids, counts):
            if c >= min_inliers:
                i, j = pycolmap.pair_id_to_image_pair(pid)
                partners[names[i]] += 1
                partners[names[j]] += 1
        return partners
    finally:
        db.close()


def verified_pairs(pycolmap, db_path, min_inliers: int) -> int:
    """How many image pairs of the database have at least ``min_inliers`` verified inliers."""
    db = pycolmap.Database.open(db_path)
    try:
        _pair_ids, counts = db.read_two_view_geometry_num_inliers()
        return int(sum(1 for c in counts if c >= min_inliers))
    finally:
        db.close()


def run_mapping(pycolmap, db_path, images_dir, out_dir, n_images, options, progress: Progress):
    if options.mapper == "global" and n_images <= 2:
        progress.info("mapping: two images, mapped with the incremental mapper (the global mapper needs tracks of "
                      "three or more views)")
    elif options.mapper == "global":
        return _map_global(pycolmap, db_path, images_dir, out_dir, n_images, options, progress)
    opts = pycolmap.IncrementalPipelineOptions()
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.mapper.random_seed = options.seed
    opts.triangulation.random_seed = options.seed
    opts.ba_refine_principal_point = False
    opts.min_model_size = min_model_size(n_images)
    if n_images <= 2:  # every track of a stereo pair has two views: COLMAP skips those by default
        opts.triangulation.ignore_two_view_tracks = False
    state = {"n": 0}

    def on_next():
        state["n"] += 1
        progress.report(min(1.0, state["n"] / max(1, n_images)), f"mapping: registered image {state['n']}")

    with CancelWatcher(progress) as token:
        recs = pycolmap.incremental_mapping(db_path, images_dir, out_dir, options=opts,
                                            next_image_callback=on_next, cancellation_token=token)
    check_cancel(progress)
    return recs


def min_model_size(n_images: int) -> int:
    """The smallest model the mapper keeps: 3 images (small separate components are kept so they can be
    reported by name), 2 when only two images are given (a stereo pair is a valid block)."""
    return 2 if n_images <= 2 else 3


def _map_global(pycolmap, db_path, images_dir, out_dir, n_images, options, progress: Progress):
    """GLOMAP's global pipeline (rotation averaging, global positioning, bundle adjustment).  pycolmap 4.2
    gives it no cancellation token and no progress callback: a cancel takes effect when it returns."""
    opts = pycolmap.GlobalPipelineOptions()
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.min_model_size = min_model_size(n_images)
    progress.report(0.0, "mapping: global SfM (rotation averaging, global positioning, bundle adjustment)")
    check_cancel(progress)
    recs = pycolmap.global_mapping(db_path, images_dir, out_dir, options=opts)
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


def final_bundle_adjustment(pycolmap, rec, options: AlignOptions, progress: Progress):
    ba = pycolmap.BundleAdjustmentOptions()
    ba.print_summary = False
    counts: Dict[int, int] = {}
    for im in rec.images.values():
        if im.has_pose:
            counts[im.camera_id] = counts.get(im.camera_id, 0) + 1
    ba.refine_principal_point = bool(options.refine_principal_point and counts
                                     and min(counts.values()) >= options.min_images_opencv)
    ba.ceres.loss_function_type = pycolmap.LossFunctionType.CAUCHY
    ba.ceres.solver_options.max_num_iterations = 30  # the mapper's last global BA has already converged
    with CancelWatcher(progress) as token:
        pycolmap.bundle_adjustment(rec, ba, cancellation_token=token)
    check_cancel(progress)
    return ba.refine_principal_point


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
