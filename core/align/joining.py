"""Components of a split block joined by the photos' positions (EXIF GPS or a camera positions file; issue 46 item 2).

COLMAP's incremental mapper carries a block on through photo *triples*: a photo is registered on points that two
registered photos already see.  A strip whose photos two apart share no texture (bare fields at 50-60 % forward
overlap: seneca_south) therefore splits into components although every photo matches its neighbours; the
components share photos (the mapper does not merge models that share one) or verified pairs, but never three
photos' points.  Two-view points alone do not fix the scale of one component against another (a component scaled
about the camera of a shared pair leaves that pair's rays as they were: the global mapper's 12/12 on seneca_south
drifted 28.6 m RMS from GPS), the photos' positions do:

1. each component with at least JOIN_MIN_CAMERAS positioned cameras is placed by a similarity to their
   positions (:func:`place`): the camera centres, plus a point below each camera along its viewing direction
   matched to a point below its position (a strip's centres are nearly collinear: the roll about the strip
   comes from the viewing directions, i.e. the frames look down on average); a component whose cameras do not
   fit their positions within JOIN_MAX_FIT (of the median spacing of neighbouring photos) is not joined;
2. the placed components become one reconstruction (the main block's intrinsics; a photo in two components keeps
   the larger one's pose), whose points are triangulated again from every verified match of the database with
   the poses held (``pycolmap.triangulate_points``, two-view tracks kept: the pairs across the splits);
3. a bundle adjustment with the positions as priors (``pycolmap.create_pose_prior_bundle_adjuster``: GPS sigma
   JOIN_SIGMA_H horizontally, JOIN_SIGMA_Z vertically) refines every pose, point and the intrinsics;
4. the join is kept only when its camera centres fit their positions after a similarity within JOIN_MAX_FIT
   of the spacing (a drifting join shows here) and its reprojection error stays under JOIN_MAX_REPROJECTION px.

The joined reconstruction is in a local metric frame (x east, y north, z the altitude where known), which later
stages treat as any model frame.
"""
from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass, field
from typing import Collection, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.cancel import CancelWatcher
from ..common.progress import Progress, check_cancel

JOIN_MIN_CAMERAS = 3  # positioned cameras a component needs to be placed by its positions
JOIN_MAX_FIT = 0.35  # RMS of the centres against their positions after a similarity, of the median photo spacing
JOIN_SIGMA_H = 3.0  # m: the positions' horizontal standard deviation in the prior adjustment (consumer GPS)
JOIN_SIGMA_Z = 10.0  # m: vertical (barometric / GPS altitude)
JOIN_MAX_REPROJECTION = 2.0  # px: the joined block's mean reprojection error at most
JOIN_FIRST_ANGLE = 10.0  # deg: the first triangulation's angle between a ray and its point (COLMAP's 2 after it)
JOIN_MIN_INLIERS = 15  # 2D-3D inliers for an image registered on the joined block (the mapping's relaxed pass)
# what the join's adjustments hold of the cameras (as core.align.mapping.adjust_block does): (the ids of the cameras
# whose intrinsics are given and held, core.align.calibrated; whether every camera's focal length is held, the
# mapping's focal drift, MappingJob.focal_held)
Hold = Tuple[Collection[int], bool]
NO_HOLD: Hold = ((), False)


@dataclass
class Join:
    """What the join did (``join`` in sfm/alignment.json)."""

    components: List[List[str]]  # the components joined (image names), the main block first
    placed_rms_m: List[float]  # each component's fit to its positions before the join
    joined_rms_m: float = math.nan  # the joined block's fit to the positions
    spacing_m: float = math.nan  # the median distance between neighbouring photos' positions
    reprojection_px: float = math.nan
    kept: bool = False
    reason: str = ""
    left_out: List[List[str]] = field(default_factory=list)  # components not placed (too few positioned cameras)
    left_out_rms_m: List[Optional[float]] = field(default_factory=list)  # their fits (None: too few cameras)

    def to_dict(self) -> dict:
        r = lambda v: None if v is None or not math.isfinite(v) else round(float(v), 3)  # noqa: E731
        return {"components": self.components, "placed_rms_m": [r(v) for v in self.placed_rms_m],
                "joined_rms_m": r(self.joined_rms_m), "spacing_m": r(self.spacing_m),
                "reprojection_px": r(self.reprojection_px), "kept": self.kept, "reason": self.reason,
                "left_out": self.left_out,
                "left_out_rms_m": [None if v is None else r(v) for v in self.left_out_rms_m]}


def similarity(a: np.ndarray, b: np.ndarray) -> Tuple[float, np.ndarray, np.ndarray]:
    """(s, R, t) with b ~ s R a + t in the least squares (Umeyama; ``a``, ``b``: (n, 3), n >= 3)."""
    a0, b0 = a - a.mean(0), b - b.mean(0)
    u, s, vt = np.linalg.svd(b0.T @ a0 / len(a))
    d = np.eye(3)
    d[2, 2] = np.sign(np.linalg.det(u @ vt)) or 1.0
    r = u @ d @ vt
    scale = float(np.trace(np.diag(s) @ d) / max((a0 ** 2).sum() / len(a), 1e-300))
    return scale, r, b.mean(0) - scale * r @ a.mean(0)


def fit_rms(centres: np.ndarray, targets: np.ndarray) -> float:
    """Horizontal RMS (target units) of ``targets`` against ``centres`` after a similarity fit."""
    if len(centres) < 3:
        return math.nan
    s, r, t = similarity(centres, targets)
    res = targets - (s * (r @ centres.T).T + t)
    return float(math.sqrt((res[:, :2] ** 2).sum(1).mean()))


def spacing(targets: Dict[str, np.ndarray]) -> float:
    """The median horizontal distance from each positioned photo to its nearest other."""
    p = np.array(list(targets.values()), dtype=float)[:, :2]
    if len(p) < 2:
        return math.nan
    d = np.sqrt(((p[:, None, :] - p[None, :, :]) ** 2).sum(-1))
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(1)))


def _centres(rec, targets: Dict[str, np.ndarray]) -> Tuple[List[str], np.ndarray, np.ndarray, np.ndarray]:
    """(names, centres, viewing directions, targets) of the registered images of ``rec`` that have a position."""
    names, c, v = [], [], []
    for i in rec.reg_image_ids():
        im = rec.images[i]
        if im.name in targets:
            names.append(im.name)
            c.append(np.asarray(im.projection_center(), dtype=float))
            v.append(np.asarray(im.viewing_direction(), dtype=float))
    t = np.array([targets[n] for n in names], dtype=float).reshape(-1, 3)
    return names, np.array(c).reshape(-1, 3), np.array(v).reshape(-1, 3), t


def place(rec, targets: Dict[str, np.ndarray]) -> Optional[Tuple[float, np.ndarray, np.ndarray, float]]:
    """The similarity (s, R, t) that places ``rec`` on the positions ``targets`` (name -> x, y, z), and the fit's
    horizontal RMS; None with fewer than JOIN_MIN_CAMERAS positioned cameras or no spread among them."""
    names, c, v, t = _centres(rec, targets)
    if len(names) < JOIN_MIN_CAMERAS:
        return None
    spread_model = math.sqrt(((c - c.mean(0)) ** 2).sum(1).mean())
    spread_world = math.sqrt(((t[:, :2] - t[:, :2].mean(0)) ** 2).sum(1).mean())
    if spread_model <= 0 or spread_world <= 0:
        return None
    scale = spread_world / spread_model  # the horizontal spread sets the depth of the points below the cameras
    depth = spread_model  # model units below each camera, along its viewing direction
    below_model = c + depth * v
    below_world = t - np.array([0.0, 0.0, depth * scale])
    s, r, tr = similarity(np.vstack([c, below_model]), np.vstack([t, below_world]))
    res = t - (s * (r @ c.T).T + tr)
    return s, r, tr, float(math.sqrt((res[:, :2] ** 2).sum(1).mean()))


def _transformed(pycolmap, rec, sim: Tuple[float, np.ndarray, np.ndarray]):
    out = pycolmap.Reconstruction(rec)
    s, r, t = sim
    out.transform(pycolmap.Sim3d(s, pycolmap.Rotation3d(r), t))
    return out


def merged(pycolmap, placed: Sequence[Tuple[object, Tuple[float, np.ndarray, np.ndarray]]]):
    """One reconstruction of the placed components (the first's cameras and points, then every other component's
    registered images not already in it, with their placed poses)."""
    joined = _transformed(pycolmap, placed[0][0], placed[0][1])
    inside = {im.name for im in joined.images.values()}
    for rec, sim in placed[1:]:
        other = _transformed(pycolmap, rec, sim)
        for i in other.reg_image_ids():
            im = other.images[i]
            if im.name in inside or joined.exists_image(im.image_id):
                continue
            if not joined.exists_camera(im.camera_id):
                joined.add_camera_with_trivial_rig(other.cameras[im.camera_id])
            xy = np.array([p.xy for p in im.points2D], dtype=float).reshape(-1, 2)
            joined.add_image_with_trivial_frame(
                pycolmap.Image(name=im.name, keypoints=xy, camera_id=im.camera_id, image_id=im.image_id),
                im.cam_from_world())
            inside.add(im.name)
    return joined


def pose_priors(pycolmap, rec, targets: Dict[str, np.ndarray], altitude: bool) -> list:
    """A position prior per registered image of ``rec`` with a position (JOIN_SIGMA_H, JOIN_SIGMA_Z; without
    ``altitude`` the height is left nearly free)."""
    sz = JOIN_SIGMA_Z if altitude else 1e3
    cov = np.diag([JOIN_SIGMA_H ** 2, JOIN_SIGMA_H ** 2, sz ** 2])
    out = []
    for i in rec.reg_image_ids():
        im = rec.images[i]
        if im.name in targets:
            out.append(pycolmap.PosePrior(corr_data_id=im.data_id, position=np.asarray(targets[im.name], float),
                                          position_covariance=cov,
                                          coordinate_system=pycolmap.PosePriorCoordinateSystem.CARTESIAN))
    return out


def prior_adjustment(pycolmap, rec, priors: list, hold: Hold = NO_HOLD,
                     progress: Optional[Progress] = None) -> None:
    """Bundle adjustment of every registered image and point of ``rec`` with the position ``priors``; the cameras
    ``hold[0]`` keep their intrinsics, with ``hold[1]`` every camera its focal length (the distortion of the
    others refined), the principal point is not refined."""
    held, hold_focal = hold
    ba = pycolmap.BundleAdjustmentOptions()
    ba.print_summary = False
    ba.refine_principal_point = False
    ba.refine_focal_length = not hold_focal
    ba.ceres.loss_function_type = pycolmap.LossFunctionType.CAUCHY
    ba.ceres.solver_options.max_num_iterations = 50
    config = pycolmap.BundleAdjustmentConfig()
    for image_id in rec.reg_image_ids():
        config.add_image(image_id)
    used = {rec.images[i].camera_id for i in rec.reg_image_ids()}
    for cid in sorted(used & set(held)):
        config.set_constant_cam_intrinsics(cid)
    pycolmap.ObservationManager(rec).filter_observations_with_negative_depth()
    prior_options = pycolmap.PosePriorBundleAdjustmentOptions()
    pycolmap.create_pose_prior_bundle_adjuster(ba, prior_options, config, priors, rec).solve()
    if progress is not None:
        check_cancel(progress)


def triangulated(pycolmap, rec, paths: Tuple[str, str, str], progress: Progress, angle: float = 2.0, seed: int = 1):
    """``rec``'s points triangulated afresh from every verified match of the database (``paths``: database, images
    folder, a scratch folder), the poses held, two-view tracks kept; ``angle``: the largest angle (deg) between a
    ray and its point (COLMAP's 2; wider while components placed by their positions do not yet meet exactly),
    the reprojection limits in proportion."""
    db_path, images_dir, out_dir = paths
    opts = pycolmap.IncrementalPipelineOptions()
    opts.triangulation.ignore_two_view_tracks = False
    opts.triangulation.create_max_angle_error = opts.triangulation.continue_max_angle_error = angle
    opts.triangulation.merge_max_reproj_error = opts.triangulation.complete_max_reproj_error = 2.0 * angle
    opts.mapper.filter_max_reproj_error = 2.0 * angle
    opts.random_seed = seed
    opts.triangulation.random_seed = seed
    opts.ba_refine_focal_length = opts.ba_refine_extra_params = opts.ba_refine_principal_point = False
    shutil.rmtree(out_dir, ignore_errors=True)
    os.makedirs(out_dir)
    try:
        with CancelWatcher(progress) as token:
            out = pycolmap.triangulate_points(rec, db_path, images_dir, out_dir, clear_points=True, options=opts,
                                              refine_intrinsics=False, cancellation_token=token)
    finally:
        shutil.rmtree(out_dir, ignore_errors=True)
    check_cancel(progress)
    return out


def adjusted(pycolmap, rec, targets: Dict[str, np.ndarray], altitude: bool, paths: Tuple[str, str, str],
             progress: Progress, angles: Sequence[float] = (JOIN_FIRST_ANGLE, 2.0), hold: Hold = NO_HOLD) -> None:
    """``rec``'s points triangulated again and adjusted with the position priors, once per angle of ``angles``
    (the first wide: the components placed by their positions meet only within a few degrees); ``hold``: what the
    adjustments hold of the cameras (:func:`prior_adjustment`)."""
    for angle in angles:
        triangulated(pycolmap, rec, paths, progress, angle)
        prior_adjustment(pycolmap, rec, pose_priors(pycolmap, rec, targets, altitude), hold, progress)


def _correspondences(pycolmap, db, rec, image_id: int) -> Tuple[np.ndarray, np.ndarray]:
    """2D-3D correspondences of the database's image ``image_id`` with ``rec``'s points, through the verified
    matches with its registered images."""
    kp = np.asarray(db.read_keypoints(image_id), dtype=float)[:, :2]
    xy, xyz = [], []
    for j in rec.reg_image_ids():
        if j == image_id or not db.exists_two_view_geometry(image_id, j):
            continue
        m = np.asarray(db.read_two_view_geometry(image_id, j).inlier_matches).reshape(-1, 2)
        points2d = rec.images[j].points2D
        for a, b in m:
            p = points2d[int(b)]
            if p.has_point3D():
                xy.append(kp[int(a)])
                xyz.append(rec.points3D[p.point3D_id].xyz)
    return np.array(xy, float).reshape(-1, 2), np.array(xyz, float).reshape(-1, 3)


def register_rest(pycolmap, rec, db_path: str, targets: Dict[str, np.ndarray], max_offset: float) -> List[str]:
    """Register in ``rec`` (placed on the positions) the images of the database it lacks, each on its verified
    matches with the registered images' points (two-view points too): at least JOIN_MIN_INLIERS 2D-3D inliers, and
    its centre within ``max_offset`` of its position (when it has one).  Returns the names added."""
    db = pycolmap.Database.open(db_path)
    added = []
    try:
        for im in db.read_all_images():
            if rec.exists_image(im.image_id) and rec.images[im.image_id].has_pose:
                continue
            xy, xyz = _correspondences(pycolmap, db, rec, im.image_id)
            if len(xy) < JOIN_MIN_INLIERS:
                continue
            camera = rec.cameras[im.camera_id] if rec.exists_camera(im.camera_id) else db.read_camera(im.camera_id)
            est = pycolmap.AbsolutePoseEstimationOptions()
            est.ransac.random_seed = 1
            ans = pycolmap.estimate_and_refine_absolute_pose(xy, xyz, camera, est)
            if not ans or int(ans["num_inliers"]) < JOIN_MIN_INLIERS:
                continue
            pose = ans["cam_from_world"]
            centre = np.asarray(pose.tgt_origin_in_src(), float)
            if im.name in targets and np.linalg.norm(centre[:2] - targets[im.name][:2]) > max_offset:
                continue
            if not rec.exists_camera(im.camera_id):
                rec.add_camera_with_trivial_rig(camera)
            kp = np.asarray(db.read_keypoints(im.image_id), dtype=float)[:, :2]
            if rec.exists_image(im.image_id):
                continue  # an unregistered image of the model: left as it is (the mapper's own frames)
            rec.add_image_with_trivial_frame(pycolmap.Image(name=im.name, keypoints=kp, camera_id=im.camera_id,
                                                            image_id=im.image_id), pose)
            added.append(im.name)
    finally:
        db.close()
    return added


def join_components(pycolmap, ordered: list, targets: Dict[str, np.ndarray], altitude: bool,
                    paths: Tuple[str, str, str], progress: Progress, hold: Hold = NO_HOLD
                    ) -> Tuple[list, Optional[Join]]:
    """``ordered`` (reconstructions, largest first) with its components joined into the first where the positions
    ``targets`` (name -> x, y, z metres) place them (the module's docstring); ``paths``: (database, images folder,
    a scratch folder); ``hold``: what the adjustments hold of the cameras (:func:`prior_adjustment`; the held
    cameras' intrinsics come back as they went in).  Returns (the reconstructions, largest first, the Join or None
    when nothing was tried)."""
    if len(ordered) < 2 or len(targets) < JOIN_MIN_CAMERAS:
        return ordered, None
    gap = spacing(targets)
    placed, rms, comps, rest, rest_rms = [], [], [], [], []
    for k, rec in enumerate(ordered):
        names = sorted(rec.images[i].name for i in rec.reg_image_ids())
        p = place(rec, targets)
        if p is None or not p[3] <= JOIN_MAX_FIT * gap:
            if k == 0:
                return ordered, None  # the main block itself cannot be placed: nothing to join it to
            rest.append(names)
            rest_rms.append(None if p is None else p[3])
            continue
        placed.append((rec, p[:3]))
        rms.append(p[3])
        comps.append(names)
    join = Join(comps, rms, spacing_m=gap, left_out=rest, left_out_rms_m=rest_rms)
    if len(placed) < 2:
        join.reason = "fewer than two components could be placed by their positions"
        return ordered, join
    fits = ", ".join(f"{v:.1f}" for v in rms)
    progress.info(f"joining {len(placed)} components by the photos' positions (fits {fits} m, photo spacing "
                  f"{gap:.1f} m)")
    joined = merged(pycolmap, placed)
    adjusted(pycolmap, joined, targets, altitude, paths, progress, hold=hold)
    added = register_rest(pycolmap, joined, paths[0], targets, JOIN_MAX_FIT * gap)
    if added:
        progress.info(f"join: registered on the joined block's points: {', '.join(added)}")
        adjusted(pycolmap, joined, targets, altitude, paths, progress, angles=(2.0,), hold=hold)
    names, c, _v, t = _centres(joined, targets)
    join.joined_rms_m = fit_rms(c, t)
    join.reprojection_px = float(joined.compute_mean_reprojection_error())
    if not (join.joined_rms_m <= JOIN_MAX_FIT * gap and join.reprojection_px <= JOIN_MAX_REPROJECTION):
        join.reason = (f"the joined block fits the positions {join.joined_rms_m:.1f} m RMS (limit "
                       f"{JOIN_MAX_FIT * gap:.1f} m), reprojection {join.reprojection_px:.2f} px: not kept")
        progress.warning(f"join: {join.reason}")
        return ordered, join
    join.kept = True
    join.reason = (f"{len(placed)} components joined: {joined.num_reg_images()} images, camera centres "
                   f"{join.joined_rms_m:.1f} m RMS from their positions, {join.reprojection_px:.2f} px")
    progress.info(f"join: {join.reason}")
    inside = {joined.images[i].name for i in joined.reg_image_ids()}
    others = [r for r in ordered if r not in [p[0] for p in placed]
              and not {r.images[i].name for i in r.reg_image_ids()} <= inside]
    return [joined] + others, join


def position_targets(infos, positions: Dict[str, Tuple[float, float]], from_file: bool
                     ) -> Tuple[Dict[str, np.ndarray], bool]:
    """(image name -> x, y, z of its position, whether z is a measured altitude): x, y from ``positions``
    (core.align.pairs.photo_positions), z the EXIF GPS altitude where every positioned photo has one and the
    positions are EXIF's (``from_file``: a camera positions file, no altitude), else 0."""
    alt = {im.name: im.gps[2] for im in infos if im.gps and len(im.gps) > 2 and im.gps[2] is not None}
    altitude = not from_file and bool(positions) and all(n in alt and math.isfinite(alt[n]) for n in positions)
    return ({n: np.array([x, y, float(alt[n]) if altitude else 0.0]) for n, (x, y) in positions.items()},
            altitude)


class PositionJoin:
    """The stage's join (:func:`join_components`) on the positions of ``photos`` (core.align.inputs.Photos) and the
    database of ``job`` (core.align.mapping.MappingJob), for the first mapping and for each escalation round's
    (a round maps the block afresh: its components are joined as the first mapping's were), holding what the stage
    holds of the cameras (the given cameras; the focal length where it drifted in the mapping).  What a join did
    goes to ``record["join"]`` (the first mapping's) or ``record["join_escalation"]`` (the rounds'); the blocks it
    joined are remembered for the final adjustment's position priors (:meth:`priors`)."""

    def __init__(self, pycolmap, photos, options, job, record: dict):
        self.pycolmap, self.photos, self.job, self.record = pycolmap, photos, job, record
        self.targets, self.altitude = position_targets(photos.infos, photos.positions, bool(options.camera_positions))
        self.joined: list = []  # (the joined reconstruction, its record)

    def __call__(self, ordered: list, progress: Progress) -> list:
        """``ordered`` (reconstructions, largest first) with its components joined where the positions place them."""
        job = self.job
        paths = (job.db_path, job.images_dir, job.out_dir.rstrip(os.sep) + "-join")
        hold = (set(self.photos.held()[0]), job.focal_held is not None)
        ordered, join = join_components(self.pycolmap, ordered, self.targets, self.altitude, paths, progress, hold)
        if join is None:
            return ordered
        row = join.to_dict()
        if "join" not in self.record:
            self.record["join"] = row
        else:
            self.record.setdefault("join_escalation", []).append(row)
        if join.kept:
            self.joined.append((ordered[0], row))
        return ordered

    def priors(self, rec):
        """For the final adjustment of ``rec``: a function of the reconstruction giving its position priors (the
        join's sigmas, JOIN_SIGMA_H and JOIN_SIGMA_Z) when ``rec`` is a block this join made, else None (a block
        mapped in one component is in the mapper's own frame)."""
        row = next((r for block, r in self.joined if block is rec), None)
        if row is None:
            return None
        row["final_adjustment_priors"] = True
        return lambda r: pose_priors(self.pycolmap, r, self.targets, self.altitude)
