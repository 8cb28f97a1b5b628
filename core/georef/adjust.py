"""Georeferencing: Helmert (7-parameter similarity), GCP- and position-constrained
bundle adjustment, check points.

Frames (DESIGN.md section 2):

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
   complement on the points, see ``_BundleProblem``): tie-point reprojection
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

Pixel convention: origin at the upper-left corner of the upper-left pixel, x
right, y down: the same as COLMAP, so observations go in unchanged.
"""
from __future__ import annotations

import copy
import itertools
import json
import math
import os
import time
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple

import numpy as np

from ..io.gcp import CHECK, CONTROL, CameraPosition, GCPSet, GroundPoint, Observation

try:  # the lead's Progress protocol; Cancelled must be the shared class
    from ..common.progress import Cancelled
except ImportError:  # pragma: no cover - fallback while core/progress.py is missing

    class Cancelled(Exception):  # type: ignore[no-redef]
        """Raised when the user asked to stop."""


TRANSFORM_FILE = "transform.json"
RESIDUALS_FILE = "residuals.json"
FORMAT_VERSION = 1

# point status values in residual rows
USED = "used"  # control point that took part in the adjustment
REJECTED = "rejected"  # control point removed as an outlier (evaluated like a check point)
CHECKED = "check"  # check point
NOT_TRIANGULATED = "not triangulated"

INTRINSIC_GROUPS = ("focal", "principal_point", "extra")


class GeorefError(ValueError):
    """Georeferencing cannot run with the given input; the message says what was found."""


# ----------------------------------------------------------------------------
# similarity
# ----------------------------------------------------------------------------


@dataclass
class Similarity:
    """x' = scale * R @ x + t."""

    scale: float = 1.0
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        self.scale = float(self.scale)
        self.rotation = np.asarray(self.rotation, dtype=float).reshape(3, 3)
        self.translation = np.asarray(self.translation, dtype=float).reshape(3)

    def apply(self, xyz) -> np.ndarray:
        xyz = np.asarray(xyz, dtype=float)
        return self.scale * xyz @ self.rotation.T + self.translation

    __call__ = apply

    def inverse(self) -> "Similarity":
        s = 1.0 / self.scale
        rt = self.rotation.T
        return Similarity(s, rt, -s * rt @ self.translation)

    def compose(self, other: "Similarity") -> "Similarity":
        """self after other: x -> self(other(x))."""
        return Similarity(self.scale * other.scale, self.rotation @ other.rotation,
                          self.scale * self.rotation @ other.translation + self.translation)

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.scale * self.rotation
        m[:3, 3] = self.translation
        return m

    def to_sim3d(self):
        import pycolmap

        return pycolmap.Sim3d(self.scale, pycolmap.Rotation3d(self.rotation), self.translation)

    @classmethod
    def from_sim3d(cls, sim) -> "Similarity":
        return cls(float(np.asarray(sim.scale)), np.asarray(sim.rotation.matrix()), np.asarray(sim.translation))

    @classmethod
    def translation_only(cls, t) -> "Similarity":
        return cls(1.0, np.eye(3), t)

    def to_dict(self) -> Dict[str, Any]:
        return {"scale": self.scale, "rotation": self.rotation.tolist(),
                "translation": self.translation.tolist(), "matrix": self.matrix().tolist()}

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "Similarity":
        if "rotation" in d:
            return cls(d["scale"], d["rotation"], d["translation"])
        m = np.asarray(d["matrix"], dtype=float)
        s = float(np.cbrt(np.linalg.det(m[:3, :3])))
        return cls(s, m[:3, :3] / s, m[:3, 3])


@dataclass
class HelmertResult:
    transform: Similarity
    inliers: np.ndarray  # bool (N,)
    residuals: np.ndarray  # (N,) 3-D distance |dst - T(src)|
    residual_vectors: np.ndarray  # (N, 3) dst - T(src)

    def __iter__(self) -> Iterator[Any]:  # transform, inliers, residuals = helmert_ransac(...)
        yield self.transform
        yield self.inliers
        yield self.residuals


def helmert_fit(src, dst, weights=None) -> Similarity:
    """Least-squares similarity dst ~ s R src + t (Umeyama 1991), optionally weighted."""
    src = np.asarray(src, dtype=float).reshape(-1, 3)
    dst = np.asarray(dst, dtype=float).reshape(-1, 3)
    if len(src) != len(dst):
        raise ValueError(f"helmert_fit: {len(src)} source points but {len(dst)} target points")
    if len(src) < 3:
        raise ValueError(f"helmert_fit needs at least 3 points, got {len(src)}")
    w = np.ones(len(src)) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    if len(w) != len(src) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError("helmert_fit: weights must be non-negative, one per point, not all zero")
    w = w / w.sum()
    mu_s = w @ src
    mu_d = w @ dst
    a = src - mu_s
    b = dst - mu_d
    cov = (b * w[:, None]).T @ a
    u, d, vt = np.linalg.svd(cov)
    var_s = float(w @ np.sum(a * a, axis=1))
    if var_s <= 0 or d[1] <= 1e-12 * max(d[0], 1e-300):
        raise ValueError("helmert_fit: the points are coincident or collinear")
    sign = np.ones(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2] = -1.0
    r = (u * sign) @ vt
    s = float(np.sum(d * sign) / var_s)
    t = mu_d - s * r @ mu_s
    return Similarity(s, r, t)


def _non_degenerate(p: np.ndarray, min_ratio: float = 1e-3) -> bool:
    """Three points span a triangle whose area is not negligible against its longest side."""
    e1, e2 = p[1] - p[0], p[2] - p[0]
    longest = max(np.linalg.norm(e1), np.linalg.norm(e2), np.linalg.norm(p[2] - p[1]))
    if longest <= 0:
        return False
    return float(np.linalg.norm(np.cross(e1, e2))) > min_ratio * longest ** 2


def helmert_ransac(src, dst, threshold: float, max_iterations: int = 2000, seed: int = 0,
                   min_inliers: int = 3, weights=None) -> HelmertResult:
    """Robust similarity: RANSAC (MSAC score) over minimal 3-point sets + LO refit on the inliers.

    ``threshold`` is the largest 3-D distance (target units) at which a point counts
    as an inlier.  All 3-point sets are tried when there are at most
    ``max_iterations`` of them, random ones otherwise.
    """
    src = np.asarray(src, dtype=float).reshape(-1, 3)
    dst = np.asarray(dst, dtype=float).reshape(-1, 3)
    n = len(src)
    if n != len(dst):
        raise ValueError(f"helmert_ransac: {n} source points but {len(dst)} target points")
    if n < 3:
        raise ValueError(f"helmert_ransac needs at least 3 points, got {n}")
    if not threshold > 0:
        raise ValueError("helmert_ransac: threshold must be positive")
    thr2 = threshold ** 2

    def score(tr: Similarity) -> Tuple[float, np.ndarray]:
        r2 = np.sum((dst - tr.apply(src)) ** 2, axis=1)
        return float(np.minimum(r2, thr2).sum()), r2 < thr2

    if math.comb(n, 3) <= max_iterations:
        samples: Iterable[Tuple[int, ...]] = itertools.combinations(range(n), 3)
    else:
        rng = np.random.default_rng(seed)
        samples = (tuple(rng.choice(n, 3, replace=False)) for _ in range(max_iterations))
    best: Optional[Tuple[float, np.ndarray]] = None
    for idx in samples:
        sel = list(idx)
        if not (_non_degenerate(src[sel]) and _non_degenerate(dst[sel])):
            continue
        try:
            tr = helmert_fit(src[sel], dst[sel])
        except ValueError:
            continue
        sc, inl = score(tr)
        if best is None or sc < best[0]:
            best = (sc, inl)
    if best is None or best[1].sum() < max(3, min_inliers):
        found = 0 if best is None else int(best[1].sum())
        raise ValueError(f"helmert_ransac: no similarity fits {max(3, min_inliers)} of the {n} points "
                         f"within {threshold:g} (best: {found}); are the points collinear or wrong?")
    inliers = best[1]
    w = None if weights is None else np.asarray(weights, dtype=float)
    tr = Similarity()
    for _ in range(20):  # local optimisation: refit on the inliers until the set is stable
        tr = helmert_fit(src[inliers], dst[inliers], None if w is None else w[inliers])
        _, new = score(tr)
        if new.sum() < 3 or np.array_equal(new, inliers):
            break
        inliers = new
    vec = dst - tr.apply(src)
    return HelmertResult(tr, inliers.copy(), np.linalg.norm(vec, axis=1), vec)


@dataclass
class Consistency:
    """Which control points agree with each other through the (rigid) model."""

    consistent: List[str]  # the largest subset whose similarity fit has RMS <= tolerance
    rms: float  # RMS residual of that subset (m)
    tolerance: float
    residuals: Dict[str, float]  # every point's distance (m; XY when xy_only) from that subset's fit
    xy_only: bool

    @property
    def suspects(self) -> List[str]:
        return sorted((n for n in self.residuals if n not in self.consistent), key=lambda n: -self.residuals[n])

    def to_dict(self) -> Dict[str, Any]:
        return {"consistent": self.consistent, "rms_m": self.rms, "tolerance_m": self.tolerance,
                "residuals_m": self.residuals, "xy_only": self.xy_only, "suspects": self.suspects}


def _fit_similarity(src: np.ndarray, dst: np.ndarray, xy_only: bool) -> Tuple[Similarity, np.ndarray]:
    """Similarity and per-point residual distances; ``xy_only`` ignores the target Z (unknown heights)."""
    tr = helmert_fit(src, dst)
    if not xy_only:
        return tr, np.linalg.norm(dst - tr.apply(src), axis=1)
    from scipy.optimize import least_squares

    mu = src.mean(axis=0)
    sc = src - mu
    t0 = tr.apply(mu)

    def parts(v):
        r = _rodrigues(v[1:4])[0] @ tr.rotation
        return math.exp(v[0]), r, np.array([v[4], v[5], t0[2]])

    def res(v):
        s_, r, t = parts(v)
        return (s_ * sc @ r.T + t)[:, :2].ravel() - dst[:, :2].ravel()

    v0 = np.r_[math.log(tr.scale), 0.0, 0.0, 0.0, t0[:2]]
    sol = least_squares(res, v0, method="trf")
    s_, r, t = parts(sol.x)
    tr2 = Similarity(s_, r, t - s_ * r @ mu)
    return tr2, np.linalg.norm(tr2.apply(src)[:, :2] - dst[:, :2], axis=1)


def control_consistency(model_xyz, world_xyz, names: Sequence[str], tolerance: float,
                        xy_only: bool = False, max_exhaustive: int = 10) -> Optional[Consistency]:
    """The largest set of control points that one similarity maps onto their coordinates within
    ``tolerance`` RMS, found by trying subsets (all of them for up to ``max_exhaustive`` points,
    else by dropping the worst point repeatedly).  A correct block cannot move one surveyed point
    by metres against the others: points outside that set have wrong coordinates, wrong labels or
    observations on the wrong mark.  None when fewer than 4 points."""
    src = np.asarray(model_xyz, dtype=float).reshape(-1, 3)
    dst = np.asarray(world_xyz, dtype=float).reshape(-1, 3)
    n = len(src)
    if n < 4:
        return None
    dst = dst - dst.mean(axis=0)
    best: Optional[Tuple[float, Tuple[int, ...]]] = None
    if n <= max_exhaustive:
        for k in range(n, 3, -1):
            found = []
            for idx in itertools.combinations(range(n), k):
                sel = list(idx)
                try:
                    _, r = _fit_similarity(src[sel], dst[sel], xy_only)
                except ValueError:
                    continue
                rms = float(np.sqrt(np.mean(r ** 2)))
                if rms <= tolerance:
                    found.append((rms, idx))
            if found:
                best = min(found)
                break
    else:
        idx = list(range(n))
        while len(idx) >= 4:
            _, r = _fit_similarity(src[idx], dst[idx], xy_only)
            rms = float(np.sqrt(np.mean(r ** 2)))
            if rms <= tolerance:
                best = (rms, tuple(idx))
                break
            idx.pop(int(np.argmax(r)))
    if best is None:  # nothing agrees: report against the fit of all
        tr, r = _fit_similarity(src, dst, xy_only)
        return Consistency([], float(np.sqrt(np.mean(r ** 2))), tolerance,
                           {names[i]: float(r[i]) for i in range(n)}, xy_only)
    sel = list(best[1])
    tr, _ = _fit_similarity(src[sel], dst[sel], xy_only)
    p = tr.apply(src)
    d = (p[:, :2] - dst[:, :2]) if xy_only else (p - dst)
    r_all = np.linalg.norm(d, axis=1)
    return Consistency([names[i] for i in sel], best[0], tolerance, {names[i]: float(r_all[i]) for i in range(n)},
                       xy_only)


# ----------------------------------------------------------------------------
# small geometry helpers
# ----------------------------------------------------------------------------


def _inv3(m: np.ndarray) -> np.ndarray:
    """Inverse of a stack of 3x3 matrices by the adjugate (numpy's batched inv calls LAPACK per
    matrix, through BLAS threads: 100x slower on busy cores)."""
    a, b, c = m[:, 0, 0], m[:, 0, 1], m[:, 0, 2]
    d, e, f = m[:, 1, 0], m[:, 1, 1], m[:, 1, 2]
    g, h, i = m[:, 2, 0], m[:, 2, 1], m[:, 2, 2]
    co = np.empty_like(m)
    co[:, 0, 0] = e * i - f * h
    co[:, 0, 1] = c * h - b * i
    co[:, 0, 2] = b * f - c * e
    co[:, 1, 0] = f * g - d * i
    co[:, 1, 1] = a * i - c * g
    co[:, 1, 2] = c * d - a * f
    co[:, 2, 0] = d * h - e * g
    co[:, 2, 1] = b * g - a * h
    co[:, 2, 2] = a * e - b * d
    det = a * co[:, 0, 0] + b * co[:, 1, 0] + c * co[:, 2, 0]
    return co / det[:, None, None]


def _rodrigues(w: np.ndarray) -> np.ndarray:
    """Rotation matrices (N,3,3) from rotation vectors (N,3)."""
    w = np.asarray(w, dtype=float).reshape(-1, 3)
    th = np.linalg.norm(w, axis=1)
    small = th < 1e-12
    k = w / np.where(small, 1.0, th)[:, None]
    kx = _skew(k)
    s = np.sin(th)[:, None, None]
    c = (1 - np.cos(th))[:, None, None]
    r = np.eye(3)[None] + s * kx + c * (kx @ kx)
    if np.any(small):
        r[small] = np.eye(3)[None] + _skew(w[small])
    return r


def _skew(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float).reshape(-1, 3)
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], -1),
                     np.stack([v[:, 2], z, -v[:, 0]], -1),
                     np.stack([-v[:, 1], v[:, 0], z], -1)], axis=1)


def _project(camera, xc: np.ndarray) -> np.ndarray:
    """Pixel coordinates of camera-frame points (M,3) through the full camera model."""
    if len(xc) == 0:
        return np.zeros((0, 2))
    return np.asarray(camera.img_from_cam(np.ascontiguousarray(xc, dtype=float), check_cheirality=False))


def _project_jacobian(camera, xc: np.ndarray) -> np.ndarray:
    """d(pixel)/d(camera-frame point) (M,2,3), central differences scaled by depth."""
    h = 1e-6 * np.maximum(np.abs(xc[:, 2]), 1e-9)
    jac = np.empty((len(xc), 2, 3))
    for k in range(3):
        d = np.zeros_like(xc)
        d[:, k] = h
        jac[:, :, k] = (_project(camera, xc + d) - _project(camera, xc - d)) / (2 * h)[:, None]
    return jac


def _info(progress, message: str) -> None:
    fn = getattr(progress, "info", None) if progress is not None else None
    if callable(fn):
        fn(message)


def _progress_call(progress, fraction: float, message: str) -> None:
    if progress is not None:
        progress.report(min(max(fraction, 0.0), 1.0), message)


def _check_cancel(progress) -> None:
    if progress is not None and progress.is_cancelled():
        raise Cancelled("georeferencing cancelled")


def _warn(progress, warnings: List[str], message: str) -> None:
    warnings.append(message)
    fn = getattr(progress, "warning", None) if progress is not None else None
    if callable(fn):
        fn(message)


# ----------------------------------------------------------------------------
# triangulation of ground points from pixel observations
# ----------------------------------------------------------------------------


@dataclass
class _View:
    index: int  # index into the observation list
    image: str
    camera: Any
    cam_from_world: np.ndarray  # (3,4)
    xy: np.ndarray  # (2,)


@dataclass
class Triangulation:
    """A point triangulated from its observations.

    ``xyz`` is None when it could not be triangulated (see ``notes``).
    ``residuals_px`` has one entry per given observation, NaN for observations
    that were skipped (unknown / unregistered image) or rejected.
    Unpacks as ``xyz, residuals_px = triangulate_observations(...)``.
    """

    xyz: Optional[np.ndarray]
    residuals_px: np.ndarray
    used: np.ndarray  # bool, observation took part in the final solution
    rejected: List[int] = field(default_factory=list)  # indices of observations dropped as outliers
    notes: List[str] = field(default_factory=list)
    angle_deg: float = 0.0  # largest intersection angle between the used rays

    def __iter__(self) -> Iterator[Any]:
        yield self.xyz
        yield self.residuals_px

    @property
    def n_used(self) -> int:
        return int(self.used.sum())


def _registered_images(reconstruction) -> Dict[str, Any]:
    out = {}
    for iid in reconstruction.reg_image_ids():
        im = reconstruction.image(iid)
        out[im.name] = im
    return out


def _image_names(reconstruction) -> set:
    return {im.name for im in reconstruction.images.values()}


def _outside_image(camera, ob: Observation) -> bool:
    """The observation lies off the image: the pixel origin is the upper-left corner of the upper-left
    pixel, x right, y down, so valid is 0 <= x <= width and 0 <= y <= height (NaN is outside).  A camera
    without a size (0) is not checked."""
    w, h = float(camera.width), float(camera.height)
    if w <= 0 or h <= 0:
        return False
    return not (0.0 <= float(ob.x) <= w and 0.0 <= float(ob.y) <= h)


def _collect_views(reconstruction, observations: Sequence[Observation], lookup: Dict[str, Any],
                   all_names: Optional[set] = None) -> Tuple[List[_View], List[str]]:
    views, notes = [], []
    for i, ob in enumerate(observations):
        im = lookup.get(ob.image)
        if im is None:
            if all_names is not None and ob.image in all_names:
                notes.append(f"image {ob.image} is not registered in the model: observation skipped")
            else:
                notes.append(f"image {ob.image} is not in the model: observation skipped")
            continue
        cam = reconstruction.cameras[im.camera_id]
        if _outside_image(cam, ob):
            notes.append(f"observation in {ob.image} at ({ob.x:g}, {ob.y:g}) lies outside the image "
                         f"({cam.width} x {cam.height} px): skipped")
            continue
        views.append(_View(i, ob.image, cam, np.asarray(im.cam_from_world().matrix()),
                           np.array([ob.x, ob.y], dtype=float)))
    return views, notes


def _triangulate_views(views: List[_View]) -> Optional[np.ndarray]:
    """Linear (DLT on undistorted normalised coordinates) + Gauss-Newton on pixel residuals."""
    if len(views) < 2:
        return None
    rows = []
    for v in views:
        n = np.asarray(v.camera.cam_from_img(v.xy.reshape(1, 2))).reshape(2)
        if not np.all(np.isfinite(n)):
            return None
        p = v.cam_from_world
        rows.append(n[0] * p[2] - p[0])
        rows.append(n[1] * p[2] - p[1])
    a = np.asarray(rows)
    # condition: translate to the mean camera centre, scale by the mean distance
    centres = np.array([-v.cam_from_world[:, :3].T @ v.cam_from_world[:, 3] for v in views])
    c0 = centres.mean(axis=0)
    sc = max(float(np.mean(np.linalg.norm(centres - c0, axis=1))), 1e-9)
    tmat = np.eye(4)
    tmat[:3, :3] *= sc
    tmat[:3, 3] = c0
    _, _, vt = np.linalg.svd(a @ tmat)
    xh = tmat @ vt[-1]
    if abs(xh[3]) < 1e-14:
        return None
    x = xh[:3] / xh[3]
    return _refine_point(views, x)


def _view_residuals(views: List[_View], x: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Pixel residual vectors (M,2) and depths (M,) of point x in the views."""
    res = np.empty((len(views), 2))
    depth = np.empty(len(views))
    for k, v in enumerate(views):
        xc = v.cam_from_world[:, :3] @ x + v.cam_from_world[:, 3]
        depth[k] = xc[2]
        res[k] = _project(v.camera, xc[None])[0] - v.xy
    return res, depth


def _refine_point(views: List[_View], x: np.ndarray, iterations: int = 15) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    res, _ = _view_residuals(views, x)
    cost = float(np.sum(res ** 2))
    lam = 1e-6
    for _ in range(iterations):
        jac = np.empty((2 * len(views), 3))
        for k, v in enumerate(views):
            r = v.cam_from_world[:, :3]
            xc = r @ x + v.cam_from_world[:, 3]
            jac[2 * k:2 * k + 2] = _project_jacobian(v.camera, xc[None])[0] @ r
        h = jac.T @ jac
        g = jac.T @ res.reshape(-1)
        improved = False
        for _ in range(10):
            try:
                dx = -np.linalg.solve(h + lam * np.diag(np.diag(h) + 1e-12), g)
            except np.linalg.LinAlgError:
                lam *= 10
                continue
            xn = x + dx
            rn, _ = _view_residuals(views, xn)
            cn = float(np.sum(rn ** 2))
            if np.isfinite(cn) and cn <= cost:
                x, res, lam, improved = xn, rn, max(lam / 10, 1e-12), True
                done = cost - cn < 1e-12 * max(cost, 1e-12) or np.linalg.norm(dx) < 1e-12 * (1 + np.linalg.norm(x))
                cost = cn
                break
            lam *= 10
        if not improved or done:
            break
    return x


def _intersection_angle(views: List[_View], x: np.ndarray) -> float:
    dirs = []
    for v in views:
        c = -v.cam_from_world[:, :3].T @ v.cam_from_world[:, 3]
        d = x - c
        dirs.append(d / max(np.linalg.norm(d), 1e-300))
    best = 0.0
    for a, b in itertools.combinations(dirs, 2):
        best = max(best, math.degrees(math.acos(float(np.clip(a @ b, -1.0, 1.0)))))
    return best


def triangulate_observations(reconstruction, observations: Sequence[Observation], min_views: int = 2,
                             max_error_px: Optional[float] = None, _lookup: Optional[Dict[str, Any]] = None,
                             _all_names: Optional[set] = None) -> Triangulation:
    """Triangulate one ground point from pixel observations in registered images.

    Multi-view DLT on observations undistorted with the full camera model
    (``Camera.cam_from_img``), then Gauss-Newton on pixel residuals through
    ``Camera.img_from_cam``.  Observations in unknown or unregistered images are
    skipped with a note.  With ``max_error_px`` and at least 3 views, the
    observation with the largest residual is dropped while it exceeds the
    threshold and at least 2 views remain (indices in ``rejected``).
    """
    lookup = _registered_images(reconstruction) if _lookup is None else _lookup
    all_names = _image_names(reconstruction) if _all_names is None else _all_names
    views, notes = _collect_views(reconstruction, observations, lookup, all_names)
    n = len(observations)
    residuals = np.full(n, np.nan)
    used = np.zeros(n, dtype=bool)
    rejected: List[int] = []
    if len(views) < max(2, min_views):
        notes.append(f"{len(views)} usable observation(s), need {max(2, min_views)}")
        return Triangulation(None, residuals, used, rejected, notes)
    x = _triangulate_views(views)
    while x is not None:
        res, depth = _view_residuals(views, x)
        err = np.linalg.norm(res, axis=1)
        bad_depth = depth <= 0
        if np.any(bad_depth) and len(views) > 2:
            k = int(np.argmin(depth))
        elif max_error_px is not None and len(views) >= 3 and err.max() > max_error_px:
            k = int(np.argmax(err))
        else:
            break
        rejected.append(views[k].index)
        notes.append(f"observation in {views[k].image} rejected: "
                     + ("point behind the camera" if bad_depth[k] else f"{err[k]:.1f} px off the other rays"))
        views = views[:k] + views[k + 1:]
        x = _triangulate_views(views)
    if x is None:
        notes.append("triangulation failed (degenerate geometry)")
        return Triangulation(None, residuals, used, rejected, notes)
    res, depth = _view_residuals(views, x)
    if np.any(depth <= 0):
        notes.append("triangulated point lies behind a camera")
        return Triangulation(None, residuals, used, rejected, notes)
    for k, v in enumerate(views):
        residuals[v.index] = float(np.linalg.norm(res[k]))
        used[v.index] = True
    angle = _intersection_angle(views, x)
    if angle < 1.0:
        notes.append(f"weak intersection: largest ray angle {angle:.2f} degrees")
    return Triangulation(x, residuals, used, rejected, notes, angle)


# ----------------------------------------------------------------------------
# constrained bundle adjustment
# ----------------------------------------------------------------------------


@dataclass
class _Obs:
    """Observation arrays of the adjustment (one row per 2-D observation)."""

    img: np.ndarray  # (O,) index into images
    pt: np.ndarray  # (O,) index into points
    xy: np.ndarray  # (O,2)
    sigma: np.ndarray  # (O,) pixels
    robust: np.ndarray  # (O,) bool: Huber loss (tie points)
    active: np.ndarray  # (O,) bool


class _BundleProblem:
    """Sparse Levenberg-Marquardt bundle adjustment with priors.

    Parameters: per frame a rotation increment (left, 3) and the projection
    centre C (3) of the rig; per camera the refined intrinsic parameters; per
    point its position.  Camera-frame point: Xc = R_s (R_f (X - C_f)) + t_s with
    the fixed sensor_from_rig (R_s, t_s) (identity for ordinary single cameras).

    Each iteration builds the weighted sparse Jacobian, eliminates the points
    (3x3 blocks) with a Schur complement and solves the reduced camera system
    densely (Cholesky) up to ``DENSE_MAX`` unknowns, sparsely (SuperLU) beyond.
    Huber loss on tie-point observations by iteratively reweighting.
    """

    DENSE_MAX = 6000

    def __init__(self, frames_r, frames_c, img_frame, img_cam, img_rs, img_ts, cameras, cam_free,
                 points, obs: _Obs, point_prior, point_prior_sigma, cam_prior_img, cam_prior_xyz,
                 cam_prior_sigma, huber_px: float = 2.0):
        self.R = np.asarray(frames_r, dtype=float).copy()  # (F,3,3) rig_from_world rotation
        self.C = np.asarray(frames_c, dtype=float).copy()  # (F,3) rig centre in world
        self.img_frame = np.asarray(img_frame, dtype=int)
        self.img_cam = np.asarray(img_cam, dtype=int)
        self.Rs = np.asarray(img_rs, dtype=float)
        self.ts = np.asarray(img_ts, dtype=float)
        self.cs = -np.einsum("nji,nj->ni", self.Rs, self.ts)  # sensor centre in the rig frame
        self.cameras = cameras  # list of pycolmap.Camera copies (updated in place)
        self.cam_free = [np.asarray(f, dtype=int) for f in cam_free]
        self.intr_offset = np.cumsum([0] + [len(f) for f in self.cam_free])
        self.X = np.asarray(points, dtype=float).copy()
        self.obs = obs
        self.pp = np.asarray(point_prior, dtype=float)  # (P,3), NaN where no prior
        self.pps = np.asarray(point_prior_sigma, dtype=float)  # (P,3)
        self.has_pp = np.all(np.isfinite(self.pp), axis=1)
        self.cp_img = np.asarray(cam_prior_img, dtype=int)
        self.cp_xyz = np.asarray(cam_prior_xyz, dtype=float).reshape(-1, 3)
        self.cp_sigma = np.asarray(cam_prior_sigma, dtype=float).reshape(-1, 3)
        self.cp_active = np.ones(len(self.cp_img), dtype=bool)
        self.huber = huber_px
        self.nf = len(self.R)
        self.nc = 6 * self.nf + int(self.intr_offset[-1])
        self.npt = len(self.X)
        self.iterations = 0

    # --- state -------------------------------------------------------------
    def state(self):
        return (self.R.copy(), self.C.copy(), [c.params.copy() for c in self.cameras], self.X.copy())

    def restore(self, st) -> None:
        self.R, self.C, params, self.X = st[0].copy(), st[1].copy(), st[2], st[3].copy()
        for cam, p in zip(self.cameras, params):
            cam.params = p.copy()

    def apply_step(self, dc: np.ndarray, dp: np.ndarray) -> None:
        d = dc[:6 * self.nf].reshape(-1, 6)
        self.R = _rodrigues(d[:, :3]) @ self.R
        self.C = self.C + d[:, 3:]
        for k, cam in enumerate(self.cameras):
            free = self.cam_free[k]
            if len(free):
                p = np.array(cam.params, dtype=float)
                p[free] += dc[6 * self.nf + self.intr_offset[k]:6 * self.nf + self.intr_offset[k + 1]]
                cam.params = p
        self.X = self.X + dp.reshape(-1, 3)

    # --- residuals ------------------------------------------------------------
    def _camera_points(self, sel: np.ndarray):
        o = self.obs
        img = o.img[sel]
        f = self.img_frame[img]
        xr = np.einsum("nij,nj->ni", self.R[f], self.X[o.pt[sel]] - self.C[f])
        xc = np.einsum("nij,nj->ni", self.Rs[img], xr) + self.ts[img]
        return img, f, xr, xc

    def reprojection(self, sel: Optional[np.ndarray] = None) -> Tuple[np.ndarray, np.ndarray]:
        """Pixel residual vectors (M,2) of the selected observations, and whether in front."""
        o = self.obs
        sel = np.flatnonzero(o.active) if sel is None else sel
        img, _, _, xc = self._camera_points(sel)
        uv = np.empty((len(sel), 2))
        cams = self.img_cam[img]
        for k, cam in enumerate(self.cameras):
            m = cams == k
            if np.any(m):
                uv[m] = _project(cam, xc[m])
        return uv - o.xy[sel], xc[:, 2] > 0

    def camera_centres(self) -> np.ndarray:
        """Projection centres (per image) in world."""
        f = self.img_frame
        return self.C[f] + np.einsum("nji,nj->ni", self.R[f], self.cs)

    def point_prior_residuals(self) -> np.ndarray:
        idx = np.flatnonzero(self.has_pp)
        return (self.X[idx] - self.pp[idx]) / self.pps[idx]

    def camera_prior_residuals(self) -> np.ndarray:
        idx = np.flatnonzero(self.cp_active)
        return (self.camera_centres()[self.cp_img[idx]] - self.cp_xyz[idx]) / self.cp_sigma[idx]

    def _huber_weights(self, s: np.ndarray, robust: np.ndarray) -> np.ndarray:
        w = np.ones_like(s)
        big = robust & (s > self.huber)
        w[big] = self.huber / s[big]
        return w

    def cost(self) -> float:
        o = self.obs
        sel = np.flatnonzero(o.active)
        res, front = self.reprojection(sel)
        s = np.linalg.norm(res, axis=1) / o.sigma[sel]
        rob = o.robust[sel]
        k = self.huber
        rho = np.where(rob & (s > k), 2 * k * s - k * k, s * s)
        rho = np.where(front & np.isfinite(rho), rho, 0.0)
        c = float(rho.sum())
        c += float(np.sum(self.point_prior_residuals() ** 2))
        c += float(np.sum(self.camera_prior_residuals() ** 2))
        return 0.5 * c

    # --- linear system ------------------------------------------------------
    def _jacobian(self):
        import scipy.sparse as sp

        o = self.obs
        sel = np.flatnonzero(o.active)
        img, f, xr, xc = self._camera_points(sel)
        cams = self.img_cam[img]
        m = len(sel)
        uv = np.empty((m, 2))
        jpi = np.empty((m, 2, 3))
        for k, cam in enumerate(self.cameras):
            mk = cams == k
            if np.any(mk):
                uv[mk] = _project(cam, xc[mk])
                jpi[mk] = _project_jacobian(cam, xc[mk])
        res = uv - o.xy[sel]
        front = (xc[:, 2] > 0) & np.all(np.isfinite(res), axis=1) & np.all(np.isfinite(jpi), axis=(1, 2))
        s = np.linalg.norm(np.where(front[:, None], res, 0.0), axis=1) / o.sigma[sel]
        sw = np.sqrt(self._huber_weights(s, o.robust[sel])) / o.sigma[sel] * front
        res = np.where(front[:, None], res, 0.0) * sw[:, None]
        jrs = np.einsum("nij,njk->nik", jpi, self.Rs[img])  # d pixel / d Xr
        j_rot = -np.einsum("nij,njk->nik", jrs, _skew(xr))
        j_pt = np.einsum("nij,njk->nik", jrs, self.R[f])
        j_c = -j_pt
        rows_r, cols_r, vals_r = [], [], []
        base = 2 * np.arange(m)
        pose_cols = 6 * f[:, None] + np.arange(6)[None]
        jpose = np.concatenate([j_rot, j_c], axis=2) * sw[:, None, None]
        for a in range(2):
            rows_r.append(np.repeat(base + a, 6))
            cols_r.append(pose_cols.reshape(-1))
            vals_r.append(jpose[:, a, :].reshape(-1))
        pt_cols = self.nc + 3 * o.pt[sel][:, None] + np.arange(3)[None]
        jp = j_pt * sw[:, None, None]
        for a in range(2):
            rows_r.append(np.repeat(base + a, 3))
            cols_r.append(pt_cols.reshape(-1))
            vals_r.append(jp[:, a, :].reshape(-1))
        # intrinsics by central differences on the camera parameters
        for k, cam in enumerate(self.cameras):
            free = self.cam_free[k]
            mk = np.flatnonzero(cams == k)
            if not len(free) or not len(mk):
                continue
            p0 = np.array(cam.params, dtype=float)
            tmp = copy.copy(cam)
            jk = np.empty((len(mk), 2, len(free)))
            for q, idx in enumerate(free):
                h = 1e-6 * max(abs(p0[idx]), 1e-2)
                pp, pm = p0.copy(), p0.copy()
                pp[idx] += h
                pm[idx] -= h
                tmp.params = pp
                up = _project(tmp, xc[mk])
                tmp.params = pm
                um = _project(tmp, xc[mk])
                jk[:, :, q] = (up - um) / (2 * h)
            jk *= sw[mk][:, None, None]
            col0 = 6 * self.nf + self.intr_offset[k]
            cols = col0 + np.arange(len(free))
            for a in range(2):
                rows_r.append(np.repeat(base[mk] + a, len(free)))
                cols_r.append(np.tile(cols, len(mk)))
                vals_r.append(np.nan_to_num(jk[:, a, :]).reshape(-1))
        nrow = 2 * m
        r_all = [res.reshape(-1)]
        # point priors
        pidx = np.flatnonzero(self.has_pp)
        if len(pidx):
            rp = (self.X[pidx] - self.pp[pidx]) / self.pps[pidx]
            rows = nrow + np.arange(3 * len(pidx))
            rows_r.append(rows)
            cols_r.append((self.nc + 3 * pidx[:, None] + np.arange(3)[None]).reshape(-1))
            vals_r.append((1.0 / self.pps[pidx]).reshape(-1))
            r_all.append(rp.reshape(-1))
            nrow += 3 * len(pidx)
        # camera position priors
        cidx = np.flatnonzero(self.cp_active)
        if len(cidx):
            im = self.cp_img[cidx]
            fr = self.img_frame[im]
            centres = self.camera_centres()[im]
            rc = (centres - self.cp_xyz[cidx]) / self.cp_sigma[cidx]
            d_rot = np.einsum("nji,njk->nik", self.R[fr], _skew(self.cs[im]))  # R_f^T [c_s]x
            inv_s = 1.0 / self.cp_sigma[cidx]
            for a in range(3):
                row = nrow + 3 * np.arange(len(cidx)) + a
                rows_r.append(np.repeat(row, 3))
                cols_r.append((6 * fr[:, None] + np.arange(3)[None]).reshape(-1))
                vals_r.append((d_rot[:, a, :] * inv_s[:, a:a + 1]).reshape(-1))
                rows_r.append(row)
                cols_r.append(6 * fr + 3 + a)
                vals_r.append(inv_s[:, a])
            r_all.append(rc.reshape(-1))
            nrow += 3 * len(cidx)
        jac = sp.csr_matrix((np.concatenate(vals_r), (np.concatenate(rows_r), np.concatenate(cols_r))),
                            shape=(nrow, self.nc + 3 * self.npt))
        return jac, np.concatenate(r_all)

    def _solve(self, h, g, lam: float, fixed_cameras: bool = False):
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla
        from scipy.linalg import LinAlgError, cho_factor, cho_solve

        nc = self.nc
        hpp = h[nc:, nc:]
        diags = {k: hpp.diagonal(k) for k in range(-2, 3)}
        blocks = np.empty((self.npt, 3, 3))
        for i in range(3):
            for j in range(3):
                blocks[:, i, j] = diags[j - i][min(i, j)::3][:self.npt]
        dgp = np.einsum("nii->ni", blocks)
        floor = 1e-9 * max(float(dgp.max()) if dgp.size else 1.0, 1e-12)
        blocks = blocks + (lam * np.maximum(dgp, floor) + floor)[:, :, None] * np.eye(3)[None]
        vinv = _inv3(blocks)
        gc, gp = g[:nc], g[nc:]
        vinv_sp = sp.bsr_matrix((vinv, np.arange(self.npt), np.arange(self.npt + 1)),
                                shape=(3 * self.npt, 3 * self.npt)).tocsr()
        if fixed_cameras or nc == 0:
            return np.zeros(nc), -(vinv_sp @ gp)
        hcp = h[:nc, nc:]
        w_vinv = hcp @ vinv_sp
        rhs = -gc + w_vinv @ gp
        hcc = h[:nc, :nc]
        dcc = hcc.diagonal()
        fl = 1e-9 * max(float(dcc.max()), 1e-12)
        damp = lam * np.maximum(dcc, fl) + fl
        schur = (hcc - w_vinv @ hcp.T).tocsr() + sp.diags(damp)
        if nc <= self.DENSE_MAX:
            sd = schur.toarray()
            sd = 0.5 * (sd + sd.T)
            try:
                dc = cho_solve(cho_factor(sd), rhs)
            except LinAlgError:
                dc = np.linalg.lstsq(sd, rhs, rcond=None)[0]
        else:
            dc = spla.spsolve(schur.tocsc(), rhs)
        dp = vinv_sp @ (-gp - hcp.T @ dc)
        return dc, dp

    def solve(self, max_iterations: int = 50, progress=None, fixed_cameras: bool = False,
              tolerance: float = 1e-8) -> Dict[str, Any]:
        lam = 1e-4
        cost = self.cost()
        cost0 = cost
        it = 0
        stalled = 0
        for it in range(1, max_iterations + 1):
            _check_cancel(progress)
            jac, r = self._jacobian()
            h = (jac.T @ jac).tocsr()
            g = jac.T @ r
            accepted = False
            while lam < 1e12:
                st = self.state()
                dc, dp = self._solve(h, g, lam, fixed_cameras)
                if not (np.all(np.isfinite(dc)) and np.all(np.isfinite(dp))):
                    lam *= 10
                    continue
                self.apply_step(dc, dp)
                new = self.cost()
                if np.isfinite(new) and new <= cost:
                    rel = (cost - new) / max(cost, 1e-300)
                    cost = new
                    lam = max(lam / 3, 1e-12)
                    accepted = True
                    break
                self.restore(st)
                lam *= 5
            _progress_call(progress, min(1.0, it / max_iterations), f"bundle adjustment: iteration {it}, "
                           f"cost {cost:.6g}")
            if not accepted:
                break
            stalled = stalled + 1 if rel < tolerance else 0
            if stalled >= 2:
                break
        self.iterations += it
        return {"iterations": it, "initial_cost": cost0, "final_cost": cost}


# ----------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------


@dataclass
class PointResidual:
    """One ground point: estimated (from the images, world) minus given coordinates."""

    name: str
    role: str  # CONTROL / CHECK
    status: str  # USED / REJECTED / CHECKED / NOT_TRIANGULATED
    x: float
    y: float
    z: float
    dx: Optional[float] = None
    dy: Optional[float] = None
    dz: Optional[float] = None
    n_obs: int = 0  # observations used in the triangulation
    observations: List[Dict[str, Any]] = field(default_factory=list)  # {"image", "px"} (px None: not used)
    notes: List[str] = field(default_factory=list)

    @property
    def error_3d(self) -> Optional[float]:
        if self.dx is None:
            return None
        return math.sqrt(self.dx ** 2 + self.dy ** 2 + self.dz ** 2)

    def to_dict(self) -> Dict[str, Any]:
        return {"name": self.name, "role": self.role, "status": self.status, "x": self.x, "y": self.y,
                "z": self.z, "dx": self.dx, "dy": self.dy, "dz": self.dz, "n_obs": self.n_obs,
                "observations": self.observations, "notes": self.notes}


@dataclass
class CameraResidual:
    image: str
    x: float
    y: float
    z: float
    dx: float
    dy: float
    dz: float
    used: bool = True

    def to_dict(self) -> Dict[str, Any]:
        return dict(self.__dict__)


@dataclass
class Outlier:
    kind: str  # "control point", "observation", "camera position"
    name: str  # point name or image name (camera position)
    residual: float
    unit: str  # "m", "px", "sigma"
    stage: str  # "triangulation", "helmert", "adjustment"
    image: Optional[str] = None  # for observations
    message: str = ""

    def to_dict(self) -> Dict[str, Any]:
        return dict(self.__dict__)


def _rmse(rows: Sequence[PointResidual]) -> Dict[str, Optional[float]]:
    d = np.array([[r.dx, r.dy, r.dz] for r in rows if r.dx is not None], dtype=float).reshape(-1, 3)
    if len(d) == 0:
        return {"n": 0, "x": None, "y": None, "z": None, "xy": None, "xyz": None}
    m = np.sqrt(np.mean(d ** 2, axis=0))
    return {"n": int(len(d)), "x": float(m[0]), "y": float(m[1]), "z": float(m[2]),
            "xy": float(math.sqrt(m[0] ** 2 + m[1] ** 2)), "xyz": float(np.sqrt(np.sum(m ** 2)))}


@dataclass
class GeorefResult:
    reconstruction: Any  # adjusted pycolmap.Reconstruction in the local frame (world - offset)
    model_to_local: Similarity  # initial Helmert: sparse model frame -> local frame
    offset: np.ndarray  # (3,) world = local + offset
    crs: str
    source: str  # "control points" or "camera positions"
    points: List[PointResidual] = field(default_factory=list)  # after the adjustment
    helmert_points: List[PointResidual] = field(default_factory=list)  # after the Helmert step only
    cameras: List[CameraResidual] = field(default_factory=list)
    mean_reprojection_error: float = float("nan")  # tie points, px, after the adjustment
    gcp_reprojection_error: float = float("nan")  # GCP observations used, px (mean)
    warnings: List[str] = field(default_factory=list)
    outliers: List[Outlier] = field(default_factory=list)
    adjusted: bool = True
    refined_intrinsics: Dict[int, List[float]] = field(default_factory=dict)
    statistics: Dict[str, Any] = field(default_factory=dict)  # iterations, sizes, timings

    @property
    def similarity(self) -> Similarity:
        return self.model_to_local

    @property
    def local_to_world(self) -> Similarity:
        return Similarity.translation_only(self.offset)

    def to_world(self, xyz_local) -> np.ndarray:
        return np.asarray(xyz_local, dtype=float) + self.offset

    def to_local(self, xyz_world) -> np.ndarray:
        return np.asarray(xyz_world, dtype=float) - self.offset

    def rmse(self, role: str = CHECK, helmert: bool = False) -> Dict[str, Optional[float]]:
        rows = self.helmert_points if helmert else self.points
        if role == CHECK:
            rows = [r for r in rows if r.status == CHECKED]
        else:
            rows = [r for r in rows if r.role == role and r.status == USED]
        return _rmse(rows)

    def transform_dict(self) -> Dict[str, Any]:
        return {
            "format": "archaeoortho-georef-transform",
            "version": FORMAT_VERSION,
            "crs": self.crs,
            "offset": [float(v) for v in self.offset],
            "note": "the adjusted model is in the local frame: world = local + offset; "
                    "model_to_local maps the unadjusted alignment model into the local frame",
            "local_to_world": self.local_to_world.to_dict(),
            "model_to_local": self.model_to_local.to_dict(),
            "model_to_world": Similarity.translation_only(self.offset).compose(self.model_to_local).to_dict(),
            "source": self.source,
            "adjusted": self.adjusted,
        }

    def residuals_dict(self) -> Dict[str, Any]:
        return {
            "format": "archaeoortho-georef-residuals",
            "version": FORMAT_VERSION,
            "crs": self.crs,
            "points": [p.to_dict() for p in self.points],
            "helmert_points": [p.to_dict() for p in self.helmert_points],
            "cameras": [c.to_dict() for c in self.cameras],
            "rmse": {"control": self.rmse(CONTROL), "check": self.rmse(CHECK),
                     "check_helmert_only": self.rmse(CHECK, helmert=True)},
            "mean_reprojection_error_px": _finite_or_none(self.mean_reprojection_error),
            "gcp_reprojection_error_px": _finite_or_none(self.gcp_reprojection_error),
            "refined_intrinsics": {str(k): v for k, v in self.refined_intrinsics.items()},
            "warnings": list(self.warnings),
            "outliers": [o.to_dict() for o in self.outliers],
            "statistics": self.statistics,
        }

    def to_dict(self) -> Dict[str, Any]:
        return {"transform": self.transform_dict(), "residuals": self.residuals_dict()}

    def to_json(self, indent: int = 1) -> str:
        return json.dumps(_jsonable(self.to_dict()), indent=indent, allow_nan=False)

    def save(self, folder: str) -> Dict[str, str]:
        """Write transform.json and residuals.json into ``folder`` (atomically); returns the paths."""
        os.makedirs(folder, exist_ok=True)
        paths = {}
        for name, data in ((TRANSFORM_FILE, self.transform_dict()), (RESIDUALS_FILE, self.residuals_dict())):
            path = os.path.join(folder, name)
            _atomic_write(path, json.dumps(_jsonable(data), indent=1, allow_nan=False))
            paths[name] = path
        return paths


def _finite_or_none(v) -> Optional[float]:
    return float(v) if v is not None and np.isfinite(v) else None


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def _atomic_write(path: str, text: str) -> None:
    try:
        from ..project.workspace import atomic_write_text
    except ImportError:  # pragma: no cover
        tmp = path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
        return
    atomic_write_text(path, text)


def load_transform(path: str) -> Dict[str, Any]:
    """Read transform.json (a file or the folder holding it): crs, offset, and the Similarity objects."""
    if os.path.isdir(path):
        path = os.path.join(path, TRANSFORM_FILE)
    with open(path, encoding="utf-8") as f:
        d = json.load(f)
    out = dict(d)
    out["offset"] = np.asarray(d["offset"], dtype=float)
    for k in ("local_to_world", "model_to_local", "model_to_world"):
        if k in d:
            out[k] = Similarity.from_dict(d[k])
    return out


# ----------------------------------------------------------------------------
# georeference
# ----------------------------------------------------------------------------


def _check_crs(crs: str, warnings: List[str], progress) -> None:
    if not crs:
        _warn(progress, warnings, "no CRS given for the ground control")
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
        _warn(progress, warnings, f"CRS {crs!r} not recognised; assuming metric, right-handed coordinates")
        return
    if srs.IsGeographic():
        raise GeorefError(f"the ground control is in a geographic CRS ({crs}); the adjustment needs metric "
                          "coordinates: reproject the points to a projected CRS (e.g. the UTM zone)")


def _round_offset(xyz: np.ndarray) -> np.ndarray:
    """Offset for the local frame: the mean rounded to 100 m horizontally, 0 vertically (heights stay true)."""
    m = np.mean(np.asarray(xyz, dtype=float).reshape(-1, 3), axis=0)
    return np.array([round(m[0] / 100.0) * 100.0, round(m[1] / 100.0) * 100.0, 0.0])


def _intrinsic_groups(refine) -> Tuple[str, ...]:
    if not refine:
        return ()
    if refine is True:
        return ("focal", "extra")
    if isinstance(refine, str):
        refine = ("focal", "principal_point", "extra") if refine == "all" else (refine,)
    groups = tuple(refine)
    bad = [g for g in groups if g not in INTRINSIC_GROUPS]
    if bad:
        raise ValueError(f"refine_intrinsics: unknown group(s) {bad}; use True, 'all' or a subset of "
                         f"{INTRINSIC_GROUPS}")
    return groups


def _select_tie_points(point_tracks: Dict[int, np.ndarray], point_err: Dict[int, float], n_images: int,
                       max_observations: int) -> List[int]:
    """Best-observed tie points: long tracks and small errors first, every image covered."""
    total = sum(len(t) for t in point_tracks.values())
    ids = list(point_tracks)
    if total <= max_observations:
        return ids
    ids.sort(key=lambda p: (-len(point_tracks[p]), point_err.get(p, 0.0)))
    quota = max(30, max_observations // max(1, 3 * n_images))
    count: Dict[int, int] = {}
    chosen, rest = [], []
    n_obs = 0
    for p in ids:  # pass 1: coverage
        imgs = point_tracks[p]
        if any(count.get(int(i), 0) < quota for i in imgs):
            chosen.append(p)
            n_obs += len(imgs)
            for i in imgs:
                count[int(i)] = count.get(int(i), 0) + 1
        else:
            rest.append(p)
    for p in rest:  # pass 2: fill the budget
        if n_obs >= max_observations:
            break
        chosen.append(p)
        n_obs += len(point_tracks[p])
    return chosen


def georeference(reconstruction, gcps: Optional[GCPSet], camera_positions: Optional[Sequence[CameraPosition]] = None,
                 refine_intrinsics=False, progress=None, outlier_threshold: float = 5.0,
                 outlier_sigma: float = 5.0, helmert_threshold: Optional[float] = None,
                 gcp_pixel_sigma: float = 1.0, tie_pixel_sigma: float = 1.0, huber_px: float = 2.0,
                 max_observations: int = 200_000, max_iterations: int = 50, max_outlier_rounds: int = 10,
                 min_intrinsics_images: int = 3, adjust: bool = True, crs: Optional[str] = None,
                 copy_model: bool = True, placeholder_sigma_z: float = 1.0) -> GeorefResult:
    """Georeference a sparse model with GCPs and/or camera positions.

    ``reconstruction``: pycolmap.Reconstruction in the model frame (copied unless
    ``copy_model`` is False).  ``gcps``: control points (role CONTROL) enter the
    adjustment, check points (role CHECK) are only evaluated.
    ``camera_positions``: projection centres (same CRS as the GCPs) with sigmas.
    ``refine_intrinsics``: False; True (focal + distortion); "all" (also the
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
    import pycolmap

    t_start = time.time()
    timings: Dict[str, float] = {}
    warnings: List[str] = []
    outliers: List[Outlier] = []
    crs = crs if crs is not None else (gcps.crs if gcps is not None else "")
    if gcps is not None:
        warnings.extend(gcps.warnings)
    _check_crs(crs, warnings, progress)
    groups = _intrinsic_groups(refine_intrinsics)
    rec = pycolmap.Reconstruction(reconstruction) if copy_model else reconstruction
    lookup = _registered_images(rec)
    all_names = _image_names(rec)
    if not lookup:
        raise GeorefError("the model has no registered images")
    points = list(gcps.points) if gcps is not None else []
    names = [p.name for p in points]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise GeorefError(f"ground point names must be unique; repeated: {', '.join(dup)}")
    for p in points:
        if p.role not in (CONTROL, CHECK):
            raise GeorefError(f"ground point {p.name}: unknown role {p.role!r} (use {CONTROL!r} or {CHECK!r})")
    control = [p for p in points if p.role == CONTROL]
    # observations off their image (GCPs picked in QGIS come here directly, without the file readers'
    # check): named and ignored, in the triangulation, the adjustment and the evaluation alike
    by_name = {im.name: im for im in rec.images.values()}
    for p in points:
        for ob in p.observations:
            im = by_name.get(ob.image)
            if im is not None and _outside_image(rec.cameras[im.camera_id], ob):
                cam = rec.cameras[im.camera_id]
                _warn(progress, warnings, f"{'control' if p.role == CONTROL else 'check'} point {p.name}: observation "
                                          f"at ({ob.x:g}, {ob.y:g}) lies outside image {ob.image} ({cam.width} x "
                                          f"{cam.height} px); ignored")
    _progress_call(progress, 0.0, "triangulating control points")

    # 1. triangulate control points in the model frame
    tri: Dict[str, Triangulation] = {}
    usable: List[GroundPoint] = []
    problems: List[str] = []
    for p in control:
        _check_cancel(progress)
        t = triangulate_observations(rec, p.observations, max_error_px=max(outlier_threshold, 1.0) * 4,
                                     _lookup=lookup, _all_names=all_names)
        tri[p.name] = t
        for k in t.rejected:
            ob = p.observations[k]
            outliers.append(Outlier("observation", p.name, float("nan"), "px", "triangulation", ob.image,
                                    f"control point {p.name}: observation in {ob.image} inconsistent with the "
                                    "other rays, excluded"))
            _warn(progress, warnings, outliers[-1].message)
        if t.xyz is None:
            n_reg = sum(1 for ob in p.observations if ob.image in lookup)
            problems.append(f"{p.name} ({len(p.observations)} observation(s), {n_reg} in registered images"
                            + (f": {t.notes[-1]}" if t.notes else "") + ")")
        else:
            usable.append(p)
    for name in problems:
        _warn(progress, warnings, f"control point not usable: {name}")

    # camera positions matched to registered images
    cam_pos: List[Tuple[CameraPosition, Any]] = []
    unmatched = []
    for cp in camera_positions or []:
        if not (math.isfinite(cp.x) and math.isfinite(cp.y)):
            raise GeorefError(f"camera position of {cp.image}: X or Y is not a number")
        im = lookup.get(cp.image)
        if im is None:
            unmatched.append(cp.image)
        else:
            cam_pos.append((cp, im))
    if unmatched:
        _warn(progress, warnings, f"{len(unmatched)} camera position(s) for images not registered in the model, "
                                  f"ignored: {', '.join(unmatched[:10])}" + (" ..." if len(unmatched) > 10 else ""))
    no_height = [cp.image for cp, _ in cam_pos if not math.isfinite(cp.z)]
    if no_height:
        _warn(progress, warnings, f"{len(no_height)} camera position(s) without a height (Z): they constrain "
                                  "X and Y only")

    # placeholder heights: every control point at the same Z (e.g. 0 when heights were not surveyed)
    placeholder_z = None
    if len(usable) >= 3 and len({float(p.z) for p in usable}) == 1:
        placeholder_z = float(usable[0].z)
        loose = [p for p in usable if p.sigma_z < placeholder_sigma_z]
        _warn(progress, warnings,
              f"every control point has Z = {placeholder_z:g}: treated as a placeholder, not a surveyed height; "
              f"the points are taken to lie near one level surface (sigma Z {placeholder_sigma_z:g} m) and the "
              "Z figures measure the departure from that level, not height accuracy")
        if loose:
            import dataclasses

            repl = {p.name: dataclasses.replace(p, sigma_z=placeholder_sigma_z) for p in loose}
            usable = [repl.get(p.name, p) for p in usable]

    # 2. initial similarity model -> local
    if len(usable) >= 3:
        source = "control points"
        world = np.array([[p.x, p.y, p.z] for p in usable])
        model = np.array([tri[p.name].xyz for p in usable])
        sig = np.array([max(p.sigma_xy, p.sigma_z) for p in usable])
        objs = usable
    elif len(cam_pos) - len(no_height) >= 3:
        source = "camera positions"
        with_z = [(cp, im) for cp, im in cam_pos if math.isfinite(cp.z)]
        world = np.array([[cp.x, cp.y, cp.z] for cp, _ in with_z])
        model = np.array([im.projection_center() for _, im in with_z])
        sig = np.array([max(cp.sigma_xy, cp.sigma_z) for cp, _ in with_z])
        objs = [cp for cp, _ in with_z]
    else:
        msg = (f"georeferencing needs at least 3 control points, each seen in at least 2 registered images, "
               f"or camera positions for at least 3 registered images; found {len(control)} control point(s), "
               f"{len(usable)} usable" + (f" ({', '.join(p.name for p in usable)})" if usable else ""))
        if problems:
            msg += "; not usable: " + "; ".join(problems)
        msg += f"; {len(cam_pos)} camera position(s) matched to registered images"
        if camera_positions:
            msg += f" (of {len(camera_positions)} given)"
        if no_height and len(cam_pos) >= 3:
            msg += (f", {len(no_height)} of them without a height (Z): positions without heights cannot fix the "
                    "block's vertical datum; give Z or add control points")
        raise GeorefError(msg)
    offset = _round_offset(world)
    world_local = world - offset
    extent = float(np.max(np.linalg.norm(world_local - world_local.mean(axis=0), axis=1)))
    thr = helmert_threshold or max(0.05 * extent, 10.0 * float(np.median(sig)), 0.05)
    try:
        hel = helmert_ransac(model, world_local, thr)
    except ValueError as e:
        raise GeorefError(f"no consistent similarity between the model and the {source}: {e}") from e
    rejected_ctrl: set = set()
    # control points off the Helmert fit are only provisional outliers when the adjustment follows: on a
    # deformed block (a long strip, a wrong calibration) a correct point can lie metres off the similarity
    # of the others.  They are re-tested against the adjusted block (_retest_provisional) and re-admitted
    # when consistent with it; those that are not (a typo) are named in a warning then.
    provisional: Dict[str, Outlier] = {}
    for k in np.flatnonzero(~hel.inliers):
        o = objs[k]
        nm = o.name if source == "control points" else o.image
        outliers.append(Outlier("control point" if source == "control points" else "camera position", nm,
                                float(hel.residuals[k]), "m", "helmert",
                                message=f"{source[:-1]} {nm} is {hel.residuals[k]:.2f} m off the Helmert fit of "
                                        f"the others (threshold {thr:.2f} m): excluded; check its coordinates"))
        if source == "control points":
            rejected_ctrl.add(nm)
        if source == "control points" and adjust:
            provisional[nm] = outliers[-1]
            _info(progress, f"control point {nm} is {hel.residuals[k]:.2f} m off the Helmert fit of the others "
                            f"(threshold {thr:.2f} m): left out of the first adjustment, then re-tested against "
                            "the adjusted block")
        else:
            _warn(progress, warnings, outliers[-1].message)
    if source == "camera positions":
        bad = {objs[k].image for k in np.flatnonzero(~hel.inliers)}
        cam_pos = [(cp, im) for cp, im in cam_pos if cp.image not in bad]
    consistency = None
    if source == "control points" and len(usable) >= 4:
        tol = max(3.0 * float(np.median([p.sigma_xy for p in usable])), 0.05)
        consistency = control_consistency(model, world_local, [p.name for p in usable], tol,
                                          xy_only=placeholder_z is not None)
        if consistency is not None and consistency.suspects and len(consistency.consistent) >= 3:
            _warn(progress, warnings,
                  f"control points {', '.join(consistency.consistent)} agree with the block within "
                  f"{consistency.rms:.3f} m RMS, but " + ", ".join(
                      f"{n} ({consistency.residuals[n]:.2f} m)" for n in consistency.suspects) +
                  " do not: their coordinates, labels or image marks are suspect")
        elif consistency is not None and not consistency.consistent:
            _warn(progress, warnings, f"no 4 control points agree with the block within {tol:.3f} m: either the "
                                      "block is deformed or several coordinates are wrong")
    timings["helmert"] = time.time() - t_start
    _progress_call(progress, 0.08, f"Helmert from {int(hel.inliers.sum())} {source}")

    # 3. the model into the local frame
    model_to_local = hel.transform
    rec.transform(model_to_local.to_sim3d())
    lookup = _registered_images(rec)

    helmert_rows = _evaluate_points(rec, points, offset, rejected_ctrl, lookup, all_names, outlier_threshold)

    result = GeorefResult(rec, model_to_local, offset, crs, source, helmert_points=helmert_rows,
                          warnings=warnings, outliers=outliers, adjusted=False)
    stats: Dict[str, Any] = {"helmert_threshold_m": thr, "helmert_inliers": int(hel.inliers.sum()),
                             "helmert_scale": model_to_local.scale, "placeholder_z": placeholder_z,
                             "control_consistency": consistency.to_dict() if consistency else None}
    if not adjust:
        result.points = helmert_rows
        result.cameras = _camera_rows(rec, cam_pos, offset, lookup)
        result.mean_reprojection_error = _mean_tie_error(rec)
        timings["total"] = time.time() - t_start
        stats["timings"] = timings
        result.statistics = stats
        return result

    # 4. constrained bundle adjustment
    _check_cancel(progress)
    t0 = time.time()
    # the provisional outliers are part of the problem from the start, switched off until re-admitted
    ba_points = [p for p in usable if p.name not in rejected_ctrl or p.name in provisional]
    prob, tie_ids, gcp_index, gcp_obs_rows, sel_info = _build_problem(
        rec, lookup, ba_points, tri, cam_pos, offset, model_to_local, groups, gcp_pixel_sigma,
        tie_pixel_sigma, huber_px, max_observations, min_intrinsics_images, warnings, progress)
    removed_points: set = set()
    for nm in provisional:
        _set_point_active(prob, gcp_index[nm], gcp_obs_rows[nm], False)
        removed_points.add(nm)
    stats.update(sel_info)
    timings["build"] = time.time() - t0
    t0 = time.time()
    total_iterations = 0
    rounds = 0  # rounds over all passes (the progress fractions keep growing)
    readmitted: List[str] = []
    retests: Dict[str, Dict[str, Any]] = {}
    while True:
        for pass_round in range(1, max_outlier_rounds + 2):
            rounds += 1
            _check_cancel(progress)
            sub = _SubProgress(progress, 0.12 + 0.7 * (1 - 0.5 ** (rounds - 1)), 0.12 + 0.7 * (1 - 0.5 ** rounds))
            info = prob.solve(max_iterations=max_iterations, progress=sub)
            total_iterations += info["iterations"]
            if pass_round > max_outlier_rounds:
                break
            min_left = 0 if cam_pos else 3
            found = _find_outlier(prob, ba_points, gcp_index, gcp_obs_rows, removed_points, outlier_threshold,
                                  outlier_sigma, len(ba_points) - len(removed_points), min_left)
            if found is None:
                break
            outliers.append(found)
            _warn(progress, warnings, found.message)
            if found.kind == "control point":
                rejected_ctrl.add(found.name)
                removed_points.add(found.name)
        # re-test the provisional outliers against the adjusted block; re-admit the consistent ones and adjust
        # again (a point re-admitted can make another one consistent: repeat until none comes back)
        back = []
        if provisional:
            thr_px, thr_z = _control_thresholds(prob, ba_points, gcp_index, gcp_obs_rows, removed_points,
                                                outlier_threshold, outlier_sigma)
            for nm in provisional:
                t = _retest_provisional(prob, gcp_index[nm], gcp_obs_rows[nm])
                t.update({"threshold_px": thr_px, "threshold_sigma": thr_z})
                retests[nm] = t
                if t["sigma"] <= thr_z and t["px"] <= thr_px:
                    back.append(nm)
        if not back:
            break
        for nm in back:
            out = provisional.pop(nm)
            outliers.remove(out)
            rejected_ctrl.discard(nm)
            removed_points.discard(nm)
            k = gcp_index[nm]
            prob.X[k] = retests[nm]["xyz"]
            _set_point_active(prob, k, gcp_obs_rows[nm], True)
            readmitted.append(nm)
            t = retests[nm]
            _info(progress, f"control point {nm}: {out.residual:.2f} m off the Helmert fit of the others, but "
                            f"consistent with the adjusted block ({t['sigma']:.1f} sigma, image residuals up to "
                            f"{t['px']:.1f} px): re-admitted; the block was deformed")
    for nm, out in provisional.items():  # still off the adjusted block: outliers for good
        t = retests.get(nm)
        if t is not None and np.isfinite(t["sigma"]):
            rays = (f"its rays meet {t['free_distance_m']:.2f} m from its coordinates in the adjusted block; "
                    if t.get("free_distance_m") is not None else "")
            out.message = (f"control point {nm} is {out.residual:.2f} m off the Helmert fit of the others; {rays}"
                           f"held to its coordinates it stays {t['sigma']:.1f} sigma off with image residuals up to "
                           f"{t['px']:.1f} px (thresholds {t['threshold_sigma']:.1f} sigma, {t['threshold_px']:.1f} "
                           "px): excluded; check its coordinates")
        _warn(progress, warnings, out.message)
    timings["adjustment"] = time.time() - t0
    stats.update({"adjustment_iterations": total_iterations, "outlier_rounds": rounds,
                  "control_points_adjusted": len(ba_points) - len(provisional),
                  "readmitted_control_points": readmitted,
                  "helmert_retests": {nm: {k: v for k, v in t.items() if k != "xyz"} for nm, t in retests.items()}})

    # 5. write back, re-triangulate the tie points left out, evaluate
    t0 = time.time()
    _progress_call(progress, 0.85, "updating the model")
    _write_back(rec, prob, tie_ids, sel_info.get("_frame_ids"), sel_info.get("_camera_ids"))
    stats.pop("_frame_ids", None)
    stats.pop("_camera_ids", None)
    if sel_info.get("subsampled"):
        _refine_all_points(rec, huber_px, progress)
    rec.update_point_3d_errors()
    timings["update"] = time.time() - t0
    lookup = _registered_images(rec)
    _check_cancel(progress)
    _progress_call(progress, 0.95, "check points")
    result.points = _evaluate_points(rec, points, offset, rejected_ctrl, lookup, all_names, outlier_threshold)
    result.cameras = _camera_rows(rec, [(cp, lookup.get(cp.image)) for cp in camera_positions or []
                                        if cp.image in lookup], offset, lookup,
                                  used={cp.image for cp, _ in cam_pos} - _removed_cameras(outliers))
    result.mean_reprojection_error = _mean_tie_error(rec)
    gres = []
    for p in ba_points:
        if p.name in removed_points:
            continue
        rows = [r for r, _ in gcp_obs_rows[p.name] if prob.obs.active[r]]
        if rows:
            res, _ = prob.reprojection(np.asarray(rows))
            gres.extend(np.linalg.norm(res, axis=1).tolist())
    result.gcp_reprojection_error = float(np.mean(gres)) if gres else float("nan")
    result.refined_intrinsics = {int(cid): [float(v) for v in rec.cameras[cid].params]
                                 for cid in sel_info.get("refined_cameras", [])}
    result.adjusted = True
    timings["total"] = time.time() - t_start
    stats["timings"] = timings
    stats.pop("refined_cameras", None)
    result.statistics = stats
    _progress_call(progress, 1.0, "georeferencing done")
    return result


class _SubProgress:
    def __init__(self, parent, start: float, end: float):
        self.parent, self.start, self.end = parent, start, end

    def report(self, fraction: float, message: str = "") -> None:
        if self.parent is not None:
            self.parent.report(self.start + (self.end - self.start) * min(max(fraction, 0.0), 1.0), message)

    def is_cancelled(self) -> bool:
        return self.parent is not None and self.parent.is_cancelled()


def _removed_cameras(outliers: List[Outlier]) -> set:
    return {o.name for o in outliers if o.kind == "camera position"}


def _build_problem(rec, lookup, ba_points, tri, cam_pos, offset, model_to_local, groups, gcp_pixel_sigma,
                   tie_pixel_sigma, huber_px, max_observations, min_intrinsics_images, warnings, progress):
    # frames and images
    reg_ids = list(rec.reg_image_ids())
    frame_ids: List[int] = []
    frame_index: Dict[int, int] = {}
    img_index: Dict[int, int] = {}
    img_frame, img_cam, img_rs, img_ts = [], [], [], []
    camera_ids: List[int] = []
    cam_index: Dict[int, int] = {}
    frames_r, frames_c = [], []
    images_per_cam: Dict[int, int] = {}
    for iid in reg_ids:
        im = rec.image(iid)
        fid = im.frame_id
        if fid not in frame_index:
            fr = rec.frame(fid)
            m = np.asarray(fr.rig_from_world.matrix())
            frame_index[fid] = len(frame_ids)
            frame_ids.append(fid)
            frames_r.append(m[:, :3])
            frames_c.append(-m[:, :3].T @ m[:, 3])
        cid = im.camera_id
        if cid not in cam_index:
            cam_index[cid] = len(camera_ids)
            camera_ids.append(cid)
        images_per_cam[cid] = images_per_cam.get(cid, 0) + 1
        fr_m = np.asarray(rec.frame(fid).rig_from_world.matrix())
        cw = np.asarray(im.cam_from_world().matrix())
        rs = cw[:, :3] @ fr_m[:, :3].T
        ts = cw[:, 3] - rs @ fr_m[:, 3]
        img_index[iid] = len(img_frame)
        img_frame.append(frame_index[fid])
        img_cam.append(cam_index[cid])
        img_rs.append(rs)
        img_ts.append(ts)
    cameras = [copy.copy(rec.cameras[cid]) for cid in camera_ids]
    cam_free = []
    refined = []
    for cid, cam in zip(camera_ids, cameras):
        free: List[int] = []
        if groups and images_per_cam[cid] >= min_intrinsics_images:
            if "focal" in groups:
                free += list(cam.focal_length_idxs())
            if "principal_point" in groups:
                free += list(cam.principal_point_idxs())
            if "extra" in groups:
                free += list(cam.extra_params_idxs())
            refined.append(cid)
        elif groups:
            _warn(progress, warnings, f"camera {cid}: only {images_per_cam[cid]} image(s), intrinsics kept fixed")
        cam_free.append(sorted(set(free)))

    # tie points
    tracks: Dict[int, np.ndarray] = {}
    errs: Dict[int, float] = {}
    for pid, p in rec.points3D.items():
        el = p.track.elements
        tracks[pid] = np.array([e.image_id for e in el if e.image_id in img_index], dtype=int)
        errs[pid] = float(p.error)
    tracks = {k: v for k, v in tracks.items() if len(v) >= 2}
    total_obs = sum(len(v) for v in tracks.values())
    chosen = _select_tie_points(tracks, errs, len(reg_ids), max_observations)
    tie_ids = np.asarray(chosen, dtype=np.int64)
    pt_index = {int(pid): k for k, pid in enumerate(tie_ids)}
    xyz = [np.asarray(rec.points3D[int(pid)].xyz) for pid in tie_ids]
    o_img, o_pt, o_xy = [], [], []
    for iid in reg_ids:
        im = rec.image(iid)
        for p2 in im.get_observation_points2D():
            k = pt_index.get(p2.point3D_id)
            if k is not None:
                o_img.append(img_index[iid])
                o_pt.append(k)
                o_xy.append(p2.xy)
    n_tie_obs = len(o_img)
    o_sigma = [tie_pixel_sigma] * n_tie_obs
    o_robust = [True] * n_tie_obs
    # GCP points
    n_tie = len(xyz)
    prior = np.full((n_tie + len(ba_points), 3), np.nan)
    prior_s = np.ones((n_tie + len(ba_points), 3))
    gcp_index: Dict[str, int] = {}
    gcp_obs_rows: Dict[str, List[Tuple[int, str]]] = {}
    for p in ba_points:
        k = len(xyz)
        gcp_index[p.name] = k
        xyz.append(model_to_local.apply(tri[p.name].xyz))
        prior[k] = np.array([p.x, p.y, p.z]) - offset
        prior_s[k] = [p.sigma_xy, p.sigma_xy, p.sigma_z]
        rows = []
        t = tri[p.name]
        for j, ob in enumerate(p.observations):
            im = lookup.get(ob.image)
            if im is None or j in t.rejected or _outside_image(rec.cameras[im.camera_id], ob):
                continue
            rows.append((len(o_img), ob.image))
            o_img.append(img_index[im.image_id])
            o_pt.append(k)
            o_xy.append([ob.x, ob.y])
            o_sigma.append(gcp_pixel_sigma)
            o_robust.append(False)
        gcp_obs_rows[p.name] = rows
    if np.any(prior_s <= 0):
        raise GeorefError("control point sigmas must be positive")
    obs = _Obs(np.asarray(o_img, dtype=int), np.asarray(o_pt, dtype=int), np.asarray(o_xy, dtype=float).reshape(-1, 2),
               np.asarray(o_sigma, dtype=float), np.asarray(o_robust, dtype=bool), np.ones(len(o_img), dtype=bool))
    cp_img = [img_index[im.image_id] for _, im in cam_pos]
    # a position without a height: Z residual 0 with a huge sigma, i.e. X and Y only
    cp_xyz = [np.array([cp.x, cp.y, cp.z if math.isfinite(cp.z) else offset[2]]) - offset for cp, _ in cam_pos]
    cp_sig = [[cp.sigma_xy, cp.sigma_xy, cp.sigma_z if math.isfinite(cp.z) else 1e12] for cp, _ in cam_pos]
    if np.any(np.asarray(cp_sig, dtype=float) <= 0):
        raise GeorefError("camera position sigmas must be positive")
    prob = _BundleProblem(np.asarray(frames_r).reshape(-1, 3, 3), np.asarray(frames_c).reshape(-1, 3), img_frame,
                          img_cam, np.asarray(img_rs).reshape(-1, 3, 3), np.asarray(img_ts).reshape(-1, 3), cameras,
                          cam_free, np.asarray(xyz).reshape(-1, 3), obs, prior, prior_s, cp_img,
                          np.asarray(cp_xyz).reshape(-1, 3), np.asarray(cp_sig).reshape(-1, 3), huber_px)
    prob.cam_pos_images = [cp.image for cp, _ in cam_pos]
    info = {"images": len(reg_ids), "frames": len(frame_ids), "cameras": len(camera_ids),
            "tie_points_total": len(tracks), "tie_observations_total": total_obs,
            "tie_points_adjusted": n_tie, "tie_observations_adjusted": n_tie_obs,
            "control_points_adjusted": len(ba_points), "camera_priors": len(cam_pos),
            "subsampled": n_tie < len(tracks), "refined_cameras": refined,
            "_frame_ids": frame_ids, "_camera_ids": camera_ids}
    if n_tie < len(tracks):
        _info(progress, f"adjusting {n_tie} of {len(tracks)} tie points ({n_tie_obs} of {total_obs} "
                            "observations); the others are re-triangulated afterwards")
    return prob, tie_ids, gcp_index, gcp_obs_rows, info


def _set_point_active(prob: _BundleProblem, k: int, rows, active: bool) -> None:
    """Switch a GCP (its position prior and its observations) on or off in the adjustment."""
    prob.has_pp[k] = active and bool(np.all(np.isfinite(prob.pp[k])))
    for r, _ in rows:
        prob.obs.active[r] = active


def _gcp_residuals(prob: _BundleProblem, ba_points, gcp_index, gcp_obs_rows, removed_points,
                   px_threshold, sigma_threshold):
    """Residuals of the GCPs in the adjustment and the thresholds of the outlier tests: the pixel
    residuals of their active observations (thr_px = max(px_threshold, 5 x median)) and the largest
    normalised coordinate residual of each point (thr_z = max(sigma_threshold, 5 x median))."""
    obs = prob.obs
    all_rows, owner = [], []
    for p in ba_points:
        if p.name in removed_points:
            continue
        for r, img in gcp_obs_rows[p.name]:
            if obs.active[r]:
                all_rows.append(r)
                owner.append((p, img))
    px = np.zeros(0)
    if all_rows:
        res, _ = prob.reprojection(np.asarray(all_rows))
        px = np.linalg.norm(res, axis=1)
    thr_px = max(px_threshold, 5.0 * float(np.median(px))) if len(px) else px_threshold
    bad_obs_per_point: Dict[str, int] = {}
    n_obs_per_point: Dict[str, int] = {}
    for (p, _), e in zip(owner, px):
        n_obs_per_point[p.name] = n_obs_per_point.get(p.name, 0) + 1
        if e > thr_px:
            bad_obs_per_point[p.name] = bad_obs_per_point.get(p.name, 0) + 1
    # control points: normalised residual of the adjusted position against the given one
    names, z = [], []
    for p in ba_points:
        if p.name in removed_points:
            continue
        k = gcp_index[p.name]
        d = (prob.X[k] - prob.pp[k]) / prob.pps[k]
        names.append((p, prob.X[k] - prob.pp[k]))
        z.append(float(np.max(np.abs(d))))
    z = np.asarray(z)
    thr_z = max(sigma_threshold, 5.0 * float(np.median(z))) if len(z) else sigma_threshold
    return all_rows, owner, px, thr_px, bad_obs_per_point, n_obs_per_point, names, z, thr_z


def _control_thresholds(prob: _BundleProblem, ba_points, gcp_index, gcp_obs_rows, removed_points,
                        px_threshold, sigma_threshold) -> Tuple[float, float]:
    """(thr_px, thr_z) of the adjustment's outlier tests for the current state (see _gcp_residuals)."""
    res = _gcp_residuals(prob, ba_points, gcp_index, gcp_obs_rows, removed_points, px_threshold, sigma_threshold)
    return res[3], res[8]


def _retest_provisional(prob: _BundleProblem, k: int, rows) -> Dict[str, Any]:
    """A control point left out of the adjustment, against the adjusted block held fixed: the position
    that best agrees with both its image observations (pixel sigma) and its given coordinates (sigma),
    i.e. the point's own part of the adjustment.  Returns that position (``xyz``), its largest normalised
    coordinate residual (``sigma``) and distance (``distance_m``) from the given coordinates, and its
    largest image residual (``px``).  Conservative: admitted, the point could also bend the block its way.
    A point that cannot be placed (fewer than 2 observations, behind the cameras) gets infinite figures."""
    from scipy.optimize import least_squares

    inf = {"xyz": None, "sigma": float("inf"), "distance_m": float("inf"), "px": float("inf"), "n_obs": 0}
    o = prob.obs
    views = []
    for r, img in rows:
        i = o.img[r]
        f = prob.img_frame[i]
        rot = prob.Rs[i] @ prob.R[f]
        m = np.column_stack([rot, prob.ts[i] - rot @ prob.C[f]])
        views.append((_View(int(r), img, prob.cameras[prob.img_cam[i]], m, o.xy[r].copy()), float(o.sigma[r])))
    if len(views) < 2 or not np.all(np.isfinite(prob.pp[k])):
        return inf
    prior, ps = prob.pp[k], prob.pps[k]
    x_free = _triangulate_views([v for v, _ in views])
    if x_free is not None and not np.all(np.isfinite(x_free)):
        x_free = None
    x0 = x_free if x_free is not None else prior.copy()
    vs = [v for v, _ in views]
    sig = np.array([s for _, s in views])

    def res(x):
        r, depth = _view_residuals(vs, x)
        r = r / sig[:, None]
        r = np.where(np.isfinite(r) & (depth[:, None] > 0), r, 1e6)
        return np.concatenate([r.ravel(), (x - prior) / ps])

    try:
        sol = least_squares(res, x0, method="lm", x_scale=np.maximum(ps, 1e-6))
    except (ValueError, np.linalg.LinAlgError):
        return inf
    x = sol.x
    r, depth = _view_residuals(vs, x)
    px = np.linalg.norm(r, axis=1)
    if not (np.all(depth > 0) and np.all(np.isfinite(px))):
        return inf
    d = x - prior
    return {"xyz": x, "sigma": float(np.max(np.abs(d / ps))), "distance_m": float(np.linalg.norm(d)),
            "px": float(px.max()), "n_obs": len(vs),
            "free_distance_m": float(np.linalg.norm(x_free - prior)) if x_free is not None else None}


def _find_outlier(prob: _BundleProblem, ba_points, gcp_index, gcp_obs_rows, removed_points,
                  px_threshold, sigma_threshold, n_control_left: int, min_left: int) -> Optional[Outlier]:
    """The single worst GCP observation, control point or camera position beyond its threshold, removed."""
    obs = prob.obs
    cands: List[Tuple[float, Outlier, Any]] = []
    all_rows, owner, px, thr_px, bad_obs_per_point, n_obs_per_point, names, z, thr_z = _gcp_residuals(
        prob, ba_points, gcp_index, gcp_obs_rows, removed_points, px_threshold, sigma_threshold)
    for (p, d), zz in zip(names, z):
        nb, nt = bad_obs_per_point.get(p.name, 0), n_obs_per_point.get(p.name, 0)
        if zz > thr_z and (nb == 0 or 2 * nb >= nt) and n_control_left > min_left:
            msg = (f"control point {p.name}: adjusted position differs from the given one by dx={d[0]:.3f} "
                   f"dy={d[1]:.3f} dz={d[2]:.3f} m ({zz:.1f} sigma, threshold {thr_z:.1f}): excluded; "
                   "check its coordinates")
            cands.append((zz / thr_z, Outlier("control point", p.name, float(np.linalg.norm(d)), "m",
                                              "adjustment", message=msg), ("point", p.name)))
    for (p, img), e, r in zip(owner, px, all_rows):
        if e > thr_px:
            if n_obs_per_point.get(p.name, 0) <= 1 and n_control_left <= min_left:
                continue
            msg = (f"control point {p.name}: observation in image {img} is {e:.1f} px off "
                   f"(threshold {thr_px:.1f} px): excluded; check the marking")
            cands.append((e / thr_px, Outlier("observation", p.name, float(e), "px", "adjustment", img, msg),
                          ("obs", r, p.name)))
    # camera positions
    act = np.flatnonzero(prob.cp_active)
    if len(act):
        cr = prob.camera_centres()[prob.cp_img[act]] - prob.cp_xyz[act]
        zc = np.max(np.abs(cr / prob.cp_sigma[act]), axis=1)
        thr_c = max(sigma_threshold, 5.0 * float(np.median(zc)))
        for j, k in enumerate(act):
            if zc[j] > thr_c and len(act) > 3:
                img = prob.cam_pos_images[k]
                msg = (f"camera position of {img}: {np.linalg.norm(cr[j]):.2f} m from the adjusted projection "
                       f"centre ({zc[j]:.1f} sigma, threshold {thr_c:.1f}): excluded")
                cands.append((zc[j] / thr_c, Outlier("camera position", img, float(np.linalg.norm(cr[j])), "m",
                                                     "adjustment", message=msg), ("cam", k)))
    if not cands:
        return None
    cands.sort(key=lambda c: -c[0])
    _, out, what = cands[0]
    if what[0] == "point":
        k = gcp_index[what[1]]
        prob.has_pp[k] = False
        for r, _ in gcp_obs_rows[what[1]]:
            obs.active[r] = False
    elif what[0] == "obs":
        obs.active[what[1]] = False
        left = [r for r, _ in gcp_obs_rows[what[2]] if obs.active[r]]
        if len(left) < 1:
            prob.has_pp[gcp_index[what[2]]] = False
    else:
        prob.cp_active[what[1]] = False
    return out


def _write_back(rec, prob: _BundleProblem, tie_ids, frame_ids, camera_ids) -> None:
    import pycolmap

    for k, fid in enumerate(frame_ids):
        r = prob.R[k]
        rec.frame(fid).rig_from_world = pycolmap.Rigid3d(pycolmap.Rotation3d(r), -r @ prob.C[k])
    for cid, cam in zip(camera_ids, prob.cameras):
        rec.cameras[cid].params = np.asarray(cam.params, dtype=float)
    pts = rec.points3D
    for k, pid in enumerate(tie_ids):
        pts[int(pid)].xyz = prob.X[k]


def _refine_all_points(rec, huber_px: float, progress, iterations: int = 10) -> None:
    """Re-estimate every tie point with the cameras fixed (after a subsampled adjustment)."""
    img_ids = list(rec.reg_image_ids())
    cams = {cid: rec.cameras[cid] for cid in {rec.image(i).camera_id for i in img_ids}}
    pids, xyz = [], []
    for pid, p in rec.points3D.items():
        pids.append(pid)
        xyz.append(p.xyz)
    if not pids:
        return
    index = {pid: k for k, pid in enumerate(pids)}
    x = np.asarray(xyz, dtype=float)
    o_pt, o_xy, o_cam, o_r, o_t = [], [], [], [], []
    for iid in img_ids:
        im = rec.image(iid)
        m = np.asarray(im.cam_from_world().matrix())
        for p2 in im.get_observation_points2D():
            o_pt.append(index[p2.point3D_id])
            o_xy.append(p2.xy)
            o_cam.append(im.camera_id)
            o_r.append(m[:, :3])
            o_t.append(m[:, 3])
    o_pt = np.asarray(o_pt)
    o_xy = np.asarray(o_xy, dtype=float)
    o_cam = np.asarray(o_cam)
    o_r = np.asarray(o_r)
    o_t = np.asarray(o_t)

    def residuals(xx):
        xc = np.einsum("nij,nj->ni", o_r, xx[o_pt]) + o_t
        uv = np.empty((len(o_pt), 2))
        for cid, cam in cams.items():
            m = o_cam == cid
            uv[m] = _project(cam, xc[m])
        return uv - o_xy, xc

    def point_cost(res):
        s = np.linalg.norm(res, axis=1)
        rho = np.where(s > huber_px, 2 * huber_px * s - huber_px ** 2, s * s)
        rho = np.where(np.isfinite(rho), rho, 1e30)
        return np.bincount(o_pt, weights=rho, minlength=len(x))

    res, xc = residuals(x)
    cost = point_cost(res)
    lam = np.full(len(x), 1e-4)
    for _ in range(iterations):
        _check_cancel(progress)
        jpi = np.empty((len(o_pt), 2, 3))
        for cid, cam in cams.items():
            m = o_cam == cid
            jpi[m] = _project_jacobian(cam, xc[m])
        j = np.einsum("nij,njk->nik", jpi, o_r)
        s = np.linalg.norm(res, axis=1)
        w = np.where(s > huber_px, huber_px / np.maximum(s, 1e-300), 1.0)
        w = np.where(np.isfinite(s), w, 0.0)
        jw = j * w[:, None, None]
        h = np.zeros((len(x), 3, 3))
        g = np.zeros((len(x), 3))
        np.add.at(h, o_pt, np.einsum("nki,nkj->nij", jw, j))
        np.add.at(g, o_pt, np.einsum("nki,nk->ni", jw, np.nan_to_num(res)))
        dg = np.einsum("nii->ni", h)
        hd = h + (lam[:, None] * np.maximum(dg, 1e-12) + 1e-12)[:, :, None] * np.eye(3)[None]
        try:
            dx = -np.linalg.solve(hd, g[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            break
        dx = np.nan_to_num(dx)
        xn = x + dx
        rn, xcn = residuals(xn)
        cn = point_cost(rn)
        better = cn < cost
        x[better] = xn[better]
        cost[better] = cn[better]
        lam = np.where(better, lam / 3, lam * 5)
        res, xc = residuals(x)
        if np.all(np.abs(dx[better]) < 1e-10 * (1 + np.abs(x[better]))):
            break
    pts = rec.points3D
    for k, pid in enumerate(pids):
        pts[pid].xyz = x[k]


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
