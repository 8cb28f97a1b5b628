"""Space resection of one image (PnP + least squares, optionally the focal length and k1/k2) and planar
(projective) rectification through ground control points.

The camera model, poses, projection and omega-phi-kappa live in :mod:`core.geometry.camera` (its conventions
apply here: COLMAP pixels, cam_from_world poses in a local metric frame).

Pure numpy + OpenCV + scipy: no qgis, no Qt.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from ..common.errors import require
from .camera import MODELS, CameraError, Intrinsics, Pose, project_points

MIN_RESECTION_POINTS = 4
MIN_INTRINSICS_POINTS = 6  # focal length + k1 on top of the pose
MIN_K2_POINTS = 10  # k2 as well
MIN_PLANAR_POINTS = 4


class ResectionError(CameraError):
    """Space resection or rectification cannot run with this input; the message says why."""


# ---------------------------------------------------------------------------
# space resection
# ---------------------------------------------------------------------------

@dataclass
class PointResidual:
    name: str
    px: float
    py: float
    dx: float  # projected minus observed, pixels
    dy: float
    used: bool

    @property
    def residual(self) -> float:
        return math.hypot(self.dx, self.dy)


@dataclass
class ResectionResult:
    pose: Pose
    camera: Intrinsics
    residuals: List[PointResidual]
    rmse_px: float  # over the points used
    estimated_intrinsics: bool
    focal_sigma_px: Optional[float] = None
    warnings: List[str] = field(default_factory=list)
    estimated_params: List[str] = field(default_factory=list)  # "focal", "k1"
    geometry: Optional["PoseGeometry"] = None  # how well the points determine the pose

    @property
    def outliers(self) -> List[str]:
        return [r.name for r in self.residuals if not r.used]

    @property
    def n_used(self) -> int:
        return sum(1 for r in self.residuals if r.used)


def _rvec(r: np.ndarray) -> np.ndarray:
    cv2 = require("cv2", "space resection")
    return cv2.Rodrigues(np.asarray(r, dtype=np.float64))[0].ravel()


def _rmat(v: np.ndarray) -> np.ndarray:
    cv2 = require("cv2", "space resection")
    return cv2.Rodrigues(np.asarray(v, dtype=np.float64).reshape(3, 1))[0]


def _errors(pose: Pose, cam: Intrinsics, xyz: np.ndarray, px: np.ndarray) -> np.ndarray:
    proj, ok = project_points(pose, cam, xyz)
    err = np.hypot(*(proj - px).T)
    return np.where(ok & np.isfinite(err), err, np.inf)


def _pnp(xyz: np.ndarray, xn: np.ndarray) -> List[Pose]:
    """Pose hypotheses from 4+ points (undistorted normalised image coordinates)."""
    cv2 = require("cv2", "space resection")
    k = np.eye(3)
    out = []
    obj = np.ascontiguousarray(xyz, dtype=np.float64).reshape(-1, 1, 3)
    img = np.ascontiguousarray(xn, dtype=np.float64).reshape(-1, 1, 2)
    flags = [cv2.SOLVEPNP_SQPNP, cv2.SOLVEPNP_EPNP] + ([cv2.SOLVEPNP_AP3P] if len(xyz) == 4 else [])
    for flag in flags:
        try:
            ok, rvec, tvec = cv2.solvePnP(obj, img, k, None, flags=flag)
        except cv2.error:
            continue
        if ok and np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec)):
            out.append(Pose(_rmat(rvec), np.asarray(tvec, dtype=float).ravel()))
    return out


def _refine(xyz: np.ndarray, px: np.ndarray, pose: Pose, cam: Intrinsics, free: str = ""
            ) -> Tuple[Pose, Intrinsics, Optional[float], Optional[float]]:
    """Least-squares (Levenberg-Marquardt) refinement of the pose and, with ``free`` "fk1", the focal length and
    k1, with "k1" k1 alone.  Returns (pose, camera, sigma of the focal length px, sigma of k1)."""
    from scipy.optimize import least_squares

    base = cam.as_opencv()
    names = MODELS[base.model]
    p0 = list(base.params)
    i_fx, i_fy, i_k1 = names.index("fx"), names.index("fy"), names.index("k1")
    f0 = base.focal
    ratio = base.fy / base.fx

    def unpack(v):
        pose_ = Pose(_rmat(v[:3]), v[3:6])
        if not free:
            return pose_, base
        p = list(p0)
        if free == "fk1":
            p[i_fx] = v[6] * f0
            p[i_fy] = v[6] * f0 * ratio
            p[i_k1] = v[7]
        elif free == "k1k2":
            p[i_k1], p[i_k1 + 1] = v[6], v[7]
        else:
            p[i_k1] = v[6]
        return pose_, Intrinsics(base.model, base.width, base.height, tuple(p))

    def fun(v):
        pose_, cam_ = unpack(v)
        xc = pose_.to_camera(xyz)
        z = np.where(xc[:, 2] > 1e-9, xc[:, 2], 1e-9)
        xd = cam_.distort(xc[:, :2] / z[:, None])
        proj = np.column_stack([cam_.fx * xd[:, 0] + cam_.cx, cam_.fy * xd[:, 1] + cam_.cy])
        return (proj - px).ravel()

    v0 = np.concatenate([_rvec(pose.rotation), pose.translation])
    if free == "fk1":
        v0 = np.concatenate([v0, [1.0, p0[i_k1]]])
    elif free == "k1":
        v0 = np.concatenate([v0, [p0[i_k1]]])
    elif free == "k1k2":
        v0 = np.concatenate([v0, [p0[i_k1], p0[i_k1 + 1]]])
    res = least_squares(fun, v0, method="lm", x_scale="jac", max_nfev=2000)
    pose_, cam_ = unpack(res.x)
    sigma_f = sigma_k = None
    if free:
        dof = max(1, res.fun.size - res.x.size)
        s0 = float(res.fun @ res.fun) / dof
        try:
            cov = np.linalg.inv(res.jac.T @ res.jac) * max(s0, 0.25)  # at least 0.5 px a priori
            d = np.sqrt(np.maximum(np.diag(cov), 0.0))
        except np.linalg.LinAlgError:
            d = np.full(res.x.size, np.inf)
        if free == "fk1":
            sigma_f, sigma_k = float(d[6]) * f0, float(d[7])
        else:
            sigma_k = float(d[6])  # k1 (with k1k2: k1's)
    return pose_, cam_, sigma_f, sigma_k


# thresholds of the pose's strength (1-sigma, from the least-squares covariance)
WEAK_ANGLE_DEG = 2.0  # warn
BAD_ANGLE_DEG = 5.0  # refuse
WEAK_CENTRE_FRACTION = 0.04  # of the distance to the ground points: warn
BAD_CENTRE_FRACTION = 0.10  # refuse
NEAR_LINE_RATIO = 0.05  # below: "nearly on one line"
COLLINEAR_RATIO = 1e-6  # second over first singular value of the centred ground points
WEAK_COVERAGE = 0.10  # convex hull of the points over the image's area: warn below


@dataclass
class PoseGeometry:
    """How well the control points determine a resected pose."""

    sigma_centre_m: float  # 1-sigma of the projection centre (largest axis), metres
    sigma_angle_deg: float  # 1-sigma of the rotation (largest axis), degrees
    condition: float  # of the normal matrix, angle-scaled (centre columns times the distance)
    image_coverage: float  # convex hull of the points / image area
    spread_3d: Tuple[float, float, float]  # singular values of the centred ground points / sqrt(n), metres
    distance_m: float  # median camera-to-point distance


def _hull_area(p: np.ndarray) -> float:
    if len(p) < 3:
        return 0.0
    try:
        from scipy.spatial import ConvexHull, QhullError
    except ImportError:  # scipy < 1.8
        from scipy.spatial import ConvexHull
        from scipy.spatial.qhull import QhullError
    try:
        return float(ConvexHull(p).volume)
    except (QhullError, ValueError):
        return 0.0


def pose_geometry(xyz: np.ndarray, pixels: np.ndarray, pose: Pose, cam: Intrinsics,
                  sigma_px: float = 0.5) -> PoseGeometry:
    """Covariance of the 6 pose parameters, (J^T J)^-1 sigma^2 with sigma the residuals' (at least ``sigma_px``),
    with J the pixels' derivatives by a small rotation and the centre; the points' spread in the image and in 3-D."""
    xyz = np.asarray(xyz, dtype=float).reshape(-1, 3)
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    centred = xyz - xyz.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False) / math.sqrt(max(1, len(xyz)))
    sv = np.concatenate([sv, np.zeros(3 - len(sv))])
    c0, r0 = pose.centre, pose.rotation
    dist = float(np.median(np.linalg.norm(xyz - c0, axis=1))) or 1.0

    def fun(v):
        p = Pose.from_centre(_rmat(v[:3]) @ r0, c0 + v[3:] * dist)
        proj, _ = project_points(p, cam, xyz)
        return (proj - pixels).ravel()

    f0 = fun(np.zeros(6))
    jac = np.empty((f0.size, 6))
    h = 1e-6
    for k in range(6):
        dv = np.zeros(6)
        dv[k] = h
        jac[:, k] = (fun(dv) - fun(-dv)) / (2 * h)
    dof = max(1, f0.size - 6)
    s2 = max(float(f0 @ f0) / dof, sigma_px ** 2)
    n = jac.T @ jac
    ev = np.linalg.eigvalsh(n)
    cond = float(ev[-1] / ev[0]) if ev[0] > ev[-1] * 1e-15 and ev[0] > 0 else float("inf")
    if math.isfinite(cond):
        d = np.sqrt(np.maximum(np.diag(np.linalg.inv(n) * s2), 0.0))
        sig_a, sig_c = math.degrees(float(d[:3].max())), float(d[3:].max()) * dist
    else:
        sig_a = sig_c = float("inf")
    cover = _hull_area(pixels) / float(cam.width * cam.height)
    return PoseGeometry(sig_c, sig_a, cond, cover, (float(sv[0]), float(sv[1]), float(sv[2])), dist)


def _collinear_message(xyz: np.ndarray, image: str, names: Sequence[str]) -> Optional[str]:
    """The message when the ground points lie exactly on one line (or on one point), else None."""
    sv = np.linalg.svd(xyz - xyz.mean(axis=0), compute_uv=False)
    if sv[0] <= 1e-9 * max(1.0, float(np.abs(xyz).max())):
        return (f"space resection of {image} is impossible: the {len(xyz)} ground control points "
                f"({', '.join(names)}) all have the same coordinates")
    if len(sv) > 1 and sv[1] > COLLINEAR_RATIO * sv[0]:
        return None
    return (f"space resection of {image} is impossible: the {len(xyz)} ground control points ({', '.join(names)}) "
            "are collinear (they lie on one straight line in 3-D, so the camera may turn freely about that line). "
            "Add control points off the line, spread across the image")


def _geometry_verdict(g: PoseGeometry, n: int, image: str, warnings: List[str]) -> None:
    """Refuse (ResectionError) an undetermined pose, warn about a weak one; both with the numbers."""
    along, across, depth = g.spread_3d
    near_line = across < NEAR_LINE_RATIO * along
    numbers = (f"pose uncertainty (1 sigma) {g.sigma_centre_m:.2f} m in the camera position and {g.sigma_angle_deg:.2f}"
               f" deg in its angles at {g.distance_m:.0f} m from the points, condition number {g.condition:.3g}; the "
               f"points cover {100 * g.image_coverage:.1f} % of the image and spread {along:.2f} / {across:.2f} / "
               f"{depth:.2f} m (RMS along their three axes)")
    why = (f"the {n} control points lie nearly on one line (nearly collinear: {across:.2f} m across it, {along:.2f} m"
           " along it)" if near_line else f"the {n} control points are too few or too clustered")
    bad = (g.sigma_angle_deg > BAD_ANGLE_DEG or g.sigma_centre_m > BAD_CENTRE_FRACTION * g.distance_m
           or not math.isfinite(g.condition))
    if bad:
        raise ResectionError(f"space resection of {image} is undetermined: {why} to fix the camera's pose ({numbers})."
                             " Add control points away from the others, spread across the image")
    if g.sigma_angle_deg > WEAK_ANGLE_DEG or g.sigma_centre_m > WEAK_CENTRE_FRACTION * g.distance_m:
        warnings.append(f"the pose of {image} is weakly determined: {why} ({numbers}); "
                        "check the orthophoto away from the GCPs, or add GCPs spread across the image")
    elif g.image_coverage < WEAK_COVERAGE:
        warnings.append(f"the control points cover only {100 * g.image_coverage:.1f} % of {image}: the orthophoto "
                        "far from them is extrapolated; spread GCPs across the image")


def space_resection(xyz: np.ndarray, pixels: np.ndarray, camera: Intrinsics, names: Optional[Sequence[str]] = None,
                    estimate_intrinsics: Union[bool, str] = "auto", max_residual_px: Optional[float] = None,
                    image: str = "the image") -> ResectionResult:
    """Pose of one image from ground points (N, 3, local metric frame) and their pixels (N, 2).

    PnP on every 4-point subset (all of them up to 8 points, 400 random ones beyond) gives hypotheses; the one
    that agrees with the most points (residual under ``max_residual_px``) is refined by least squares on those
    points, so one wrong GCP among 5 or more is named and left out.  With 6 or more points the focal length and
    k1 are estimated too (``estimate_intrinsics`` True, or "auto": only when the points' geometry determines
    them to better than 2 %).  Raises ResectionError with the number of points needed when there are too few."""
    xyz = np.asarray(xyz, dtype=float).reshape(-1, 3)
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    n = len(xyz)
    names = list(names) if names is not None else [f"P{i + 1}" for i in range(n)]
    if n < MIN_RESECTION_POINTS:
        listed = f" ({', '.join(names)})" if names else ""
        raise ResectionError(
            f"space resection needs at least {MIN_RESECTION_POINTS} ground control points observed in {image} "
            f"(and {MIN_INTRINSICS_POINTS} to also estimate the focal length and k1); found {n}{listed}")
    if estimate_intrinsics is True and n < MIN_INTRINSICS_POINTS:
        raise ResectionError(
            f"estimating the focal length and k1 needs at least {MIN_INTRINSICS_POINTS} ground control points in "
            f"{image}; found {n}. Give the focal length (FOCAL_MM and SENSOR_WIDTH_MM) and leave the estimate off")
    if not np.all(np.isfinite(xyz)) or not np.all(np.isfinite(pixels)):
        raise ResectionError(f"ground control for {image} holds non-finite coordinates")
    collinear = _collinear_message(xyz, image, names)
    if collinear:
        raise ResectionError(collinear)
    diag = math.hypot(camera.width, camera.height)
    thr = float(max_residual_px) if max_residual_px else max(4.0, 0.003 * diag)
    warnings: List[str] = []
    xn = camera.unproject(pixels)

    # hypotheses from 4-point subsets
    subsets = list(itertools.combinations(range(n), 4)) if n <= 8 else None
    if subsets is None:
        rng = np.random.default_rng(0)
        subsets = [tuple(rng.choice(n, 4, replace=False)) for _ in range(400)]
    best = None  # (inlier count, -rms, pose)
    for s in subsets:
        idx = np.array(s)
        for pose in _pnp(xyz[idx], xn[idx]):
            err = _errors(pose, camera, xyz, pixels)
            inl = err < thr
            key = (int(inl.sum()), -float(np.sqrt(np.mean(err[inl] ** 2))) if inl.any() else -1e9)
            if best is None or key > best[0]:
                best = (key, pose)
    if best is None:
        raise ResectionError(f"space resection failed for {image}: the ground control points are degenerate "
                             "(all on one line, or repeated)")
    pose = best[1]
    used = _errors(pose, camera, xyz, pixels) < thr
    if used.sum() < MIN_RESECTION_POINTS:
        used = np.ones(n, dtype=bool)  # nothing agrees well: use all and report
    cam = camera
    for _ in range(3):
        pose, cam, _sf, _sk = _refine(xyz[used], pixels[used], pose, camera)
        new_used = _errors(pose, cam, xyz, pixels) < thr
        if new_used.sum() < MIN_RESECTION_POINTS or np.array_equal(new_used, used):
            break
        used = new_used

    estimated = False
    est_params: List[str] = []
    sigma_f = None
    n_used = int(used.sum())
    want = estimate_intrinsics is True or (estimate_intrinsics == "auto" and n_used >= MIN_INTRINSICS_POINTS)
    if want and n_used >= MIN_INTRINSICS_POINTS:
        p2, c2, sf, sk = _refine(xyz[used], pixels[used], pose, camera, "fk1")
        rel = sf / c2.focal if sf is not None and c2.focal > 0 else float("inf")
        sane = 0.5 < c2.focal / camera.focal < 2.0 and abs(c2.dist[0]) < 1.0
        if sane and (estimate_intrinsics is True or rel < 0.02):
            pose, cam, estimated, sigma_f = p2, c2, True, sf
            est_params = ["focal", "k1"]
            if rel >= 0.02:
                warnings.append(f"the focal length of {image} is poorly determined by these points "
                                f"(sigma {100 * rel:.1f} %): spread GCPs over more relief or give the focal length")
        else:
            sigma_f = sf
            # flat control fixes k1 (a radial pattern) even where the focal length trades off against the height
            p3, c3, _sf3, sk3 = _refine(xyz[used], pixels[used], pose, camera, "k1")
            k1_ok = sk3 is not None and sk3 < 0.02 and abs(c3.dist[0]) < 1.0
            if k1_ok:
                pose, cam = p3, c3
                est_params = ["k1"]
                if n_used >= MIN_K2_POINTS:  # many points: k2 too, where it lowers the residuals clearly
                    p4, c4, _sf4, _sk4 = _refine(xyz[used], pixels[used], p3, c3, "k1k2")
                    e3 = _errors(p3, c3, xyz[used], pixels[used])
                    e4 = _errors(p4, c4, xyz[used], pixels[used])
                    if np.sqrt(np.mean(e4 ** 2)) < 0.8 * np.sqrt(np.mean(e3 ** 2)) and abs(c4.dist[1]) < 1.0:
                        pose, cam = p4, c4
                        est_params = ["k1", "k2"]
            warnings.append(f"the focal length of {image} was not estimated: the {n_used} points do not determine "
                            f"it (sigma {100 * rel:.0f} %; flat or clustered GCPs); the given focal length was kept"
                            + (f", {' and '.join(est_params)} estimated ({', '.join(f'{v:+.4f}' for v in cam.dist[:len(est_params)])})"
                               if k1_ok else ", and k1 too"))
            estimated = k1_ok
    elif estimate_intrinsics == "auto" and n >= MIN_INTRINSICS_POINTS and n_used < MIN_INTRINSICS_POINTS:
        warnings.append(f"focal length and k1 of {image} were not estimated: only {n_used} points agree "
                        f"({MIN_INTRINSICS_POINTS} needed)")

    geometry = pose_geometry(xyz[used], pixels[used], pose, cam)
    _geometry_verdict(geometry, n_used, image, warnings)
    proj, ok = project_points(pose, cam, xyz)
    residuals = [PointResidual(nm, float(p[0]), float(p[1]), float(q[0] - p[0]), float(q[1] - p[1]), bool(u))
                 for nm, p, q, u in zip(names, pixels, proj, used)]
    r_used = np.array([r.residual for r in residuals if r.used])
    rmse = float(np.sqrt(np.mean(r_used ** 2))) if len(r_used) else float("nan")
    if (~used).any():
        for r in residuals:
            if not r.used:
                warnings.append(f"GCP {r.name} disagrees with the others by {r.residual:.1f} px in {image}: left out "
                                "(check its coordinates and where it was clicked)")
    if n == MIN_RESECTION_POINTS and rmse > thr / 2:
        warnings.append(f"with only {n} GCPs a wrong one cannot be told apart; RMSE {rmse:.1f} px: add GCPs")
    if not camera.dist.any() and not estimated and rmse > 3.0:
        warnings.append(f"residuals of {rmse:.1f} px: lens distortion may be unmodelled (6 or more GCPs estimate k1)")
    return ResectionResult(pose, cam, residuals, rmse, estimated, sigma_f, warnings, est_params, geometry)


# ---------------------------------------------------------------------------
# planar (projective) rectification
# ---------------------------------------------------------------------------

@dataclass
class Homography:
    """world XY (local frame) = H (undistorted pixel); ``residuals`` in metres per point."""

    matrix: np.ndarray
    residuals: List[PointResidual]  # dx, dy in metres (world), px/py the pixel observed
    rmse_m: float
    warnings: List[str] = field(default_factory=list)

    def world_from_pixel(self, px: np.ndarray) -> np.ndarray:
        p = np.concatenate([np.asarray(px, dtype=float), np.ones(np.shape(px)[:-1] + (1,))], axis=-1)
        w = p @ self.matrix.T
        return w[..., :2] / w[..., 2:3]

    def pixel_from_world(self, xy: np.ndarray) -> np.ndarray:
        inv = np.linalg.inv(self.matrix)
        p = np.concatenate([np.asarray(xy, dtype=float), np.ones(np.shape(xy)[:-1] + (1,))], axis=-1)
        w = p @ inv.T
        return w[..., :2] / w[..., 2:3]


def _dlt_homography(src: np.ndarray, dst: np.ndarray) -> Optional[np.ndarray]:
    cv2 = require("cv2", "planar rectification")
    h, _ = cv2.findHomography(src.astype(np.float64), dst.astype(np.float64), 0)
    return h if h is not None and np.all(np.isfinite(h)) else None


def fit_homography(pixels: np.ndarray, world_xy: np.ndarray, names: Optional[Sequence[str]] = None,
                   max_residual_m: Optional[float] = None, image: str = "the image") -> Homography:
    """Projective transform from (undistorted) pixels to world XY (local frame) through >= 4 points; with 5 or
    more, the subset that agrees best is kept and a disagreeing point named."""
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    world_xy = np.asarray(world_xy, dtype=float).reshape(-1, 2)
    n = len(pixels)
    names = list(names) if names is not None else [f"P{i + 1}" for i in range(n)]
    if n < MIN_PLANAR_POINTS:
        raise ResectionError(f"planar rectification needs at least {MIN_PLANAR_POINTS} ground control points "
                             f"observed in {image}; found {n}")
    if max_residual_m is None:
        span = float(np.max(np.ptp(world_xy, axis=0))) or 1.0
        max_residual_m = 0.02 * span
    best = None
    subsets = list(itertools.combinations(range(n), 4)) if n <= 8 else [
        tuple(np.random.default_rng(0).choice(n, 4, replace=False)) for _ in range(400)]
    for s in subsets:
        idx = np.array(s)
        h = _dlt_homography(pixels[idx], world_xy[idx])
        if h is None:
            continue
        hom = Homography(h, [], 0.0)
        err = np.hypot(*(hom.world_from_pixel(pixels) - world_xy).T)
        inl = err < max_residual_m
        key = (int(inl.sum()), -float(np.sqrt(np.mean(err[inl] ** 2))) if inl.any() else -1e9)
        if best is None or key > best[0]:
            best = (key, inl)
    if best is None:
        raise ResectionError(f"planar rectification failed for {image}: the points are degenerate (collinear?)")
    used = best[1] if best[1].sum() >= MIN_PLANAR_POINTS else np.ones(n, dtype=bool)
    h = _dlt_homography(pixels[used], world_xy[used])
    if h is None:
        raise ResectionError(f"planar rectification failed for {image}: the points are degenerate (collinear?)")
    hom = Homography(h, [], 0.0)
    d = hom.world_from_pixel(pixels) - world_xy
    hom.residuals = [PointResidual(nm, float(p[0]), float(p[1]), float(q[0]), float(q[1]), bool(u))
                     for nm, p, q, u in zip(names, pixels, d, used)]
    r = np.hypot(*d[used].T)
    hom.rmse_m = float(np.sqrt(np.mean(r ** 2)))
    for rr in hom.residuals:
        if not rr.used:
            hom.warnings.append(f"GCP {rr.name} disagrees with the plane through the others by {rr.residual:.2f} m: "
                                "left out")
    return hom
