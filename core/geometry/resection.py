"""Frame-camera geometry for one image: the camera model in numpy, space resection (PnP + least squares),
the photogrammetric omega-phi-kappa convention, and planar (projective) rectification.

Pure numpy + OpenCV + scipy: no qgis, no Qt.

Conventions
-----------
- Pixels: COLMAP's, the origin at the upper-left corner of the upper-left pixel, x right, y down (the centre
  of the first pixel is (0.5, 0.5)).
- Poses: ``cam_from_world`` rotation R and translation t (x_cam = R X + t) with COLMAP's camera axes
  (x right, y down, z along the viewing direction), in a *local* metric frame (world minus an offset, so
  UTM-size numbers never meet float32 or a badly scaled Jacobian).
- Omega-phi-kappa (photogrammetry, e.g. PATB, Pix4D, Wolf & Dewitt): M = R_kappa R_phi R_omega maps
  object-frame vectors into a camera frame with x right, y *up* and z *backwards* (out of the lens); for
  omega = phi = kappa = 0 the camera looks straight down with image x to the east and image y to the north.
  COLMAP's rotation is diag(1, -1, -1) M.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

MIN_RESECTION_POINTS = 4
MIN_INTRINSICS_POINTS = 6  # focal length + k1 on top of the pose
MIN_K2_POINTS = 10  # k2 as well
MIN_PLANAR_POINTS = 4

# COLMAP camera models this module projects natively: name -> parameter names
MODELS = {
    "SIMPLE_PINHOLE": ("f", "cx", "cy"),
    "PINHOLE": ("fx", "fy", "cx", "cy"),
    "SIMPLE_RADIAL": ("f", "cx", "cy", "k1"),
    "RADIAL": ("f", "cx", "cy", "k1", "k2"),
    "OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"),
    "FULL_OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
}


class ResectionError(ValueError):
    """Space resection or rectification cannot run with this input; the message says why."""


# ---------------------------------------------------------------------------
# camera model
# ---------------------------------------------------------------------------

@dataclass
class Intrinsics:
    """A frame camera: COLMAP model name and parameters, image size in pixels.

    Projection (``project``) and its inverse (``unproject``) are vectorised numpy.  Points whose undistorted
    radius lies beyond what the image itself shows (plus 5 %) are rejected by ``valid_normalized``: a
    distortion polynomial folds back outside the calibrated area and would map far-away ground into the
    picture."""

    model: str
    width: int
    height: int
    params: Tuple[float, ...]
    _r_limit: Optional[float] = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        self.model = self.model.upper()
        self.params = tuple(float(p) for p in self.params)
        if self.model in MODELS and len(self.params) != len(MODELS[self.model]):
            raise ResectionError(f"camera model {self.model} takes {len(MODELS[self.model])} parameters "
                                 f"({', '.join(MODELS[self.model])}), got {len(self.params)}")

    # --- construction
    @classmethod
    def from_pycolmap(cls, camera) -> Intrinsics:
        return cls(str(camera.model_name), int(camera.width), int(camera.height), tuple(np.asarray(camera.params)))

    @classmethod
    def simple(cls, width: int, height: int, focal_px: float, cx: Optional[float] = None, cy: Optional[float] = None,
               k1: float = 0.0, k2: float = 0.0, p1: float = 0.0, p2: float = 0.0) -> Intrinsics:
        """An OPENCV camera with square pixels; the principal point defaults to the image centre."""
        cx = width / 2.0 if cx is None else cx
        cy = height / 2.0 if cy is None else cy
        return cls("OPENCV", int(width), int(height), (focal_px, focal_px, cx, cy, k1, k2, p1, p2))

    # --- parameters in OpenCV form
    @property
    def native(self) -> bool:
        return self.model in MODELS

    def _named(self) -> dict:
        return dict(zip(MODELS[self.model], self.params))

    @property
    def fx(self) -> float:
        d = self._named()
        return d.get("fx", d.get("f"))

    @property
    def fy(self) -> float:
        d = self._named()
        return d.get("fy", d.get("f"))

    @property
    def cx(self) -> float:
        return self._named()["cx"]

    @property
    def cy(self) -> float:
        return self._named()["cy"]

    @property
    def focal(self) -> float:
        return 0.5 * (self.fx + self.fy)

    @property
    def dist(self) -> np.ndarray:
        """(k1, k2, p1, p2, k3, k4, k5, k6) as OpenCV orders them (zeros for absent terms)."""
        d = self._named()
        return np.array([d.get("k1", d.get("k", 0.0)), d.get("k2", 0.0), d.get("p1", 0.0), d.get("p2", 0.0),
                         d.get("k3", 0.0), d.get("k4", 0.0), d.get("k5", 0.0), d.get("k6", 0.0)], dtype=float)

    @property
    def matrix(self) -> np.ndarray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def as_opencv(self) -> Intrinsics:
        """The same camera as an OPENCV / FULL_OPENCV model."""
        d = self.dist
        if np.any(d[4:] != 0):
            return Intrinsics("FULL_OPENCV", self.width, self.height, (self.fx, self.fy, self.cx, self.cy, *d))
        return Intrinsics("OPENCV", self.width, self.height, (self.fx, self.fy, self.cx, self.cy, *d[:4]))

    def to_dict(self) -> dict:
        return {"model": self.model, "width": self.width, "height": self.height, "params": list(self.params)}

    # --- distortion
    def distort(self, xn: np.ndarray) -> np.ndarray:
        """Undistorted -> distorted normalised coordinates (..., 2)."""
        k1, k2, p1, p2, k3, k4, k5, k6 = self.dist
        x, y = xn[..., 0], xn[..., 1]
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        if k4 or k5 or k6:
            radial = radial / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)))
        xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
        yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
        return np.stack([xd, yd], axis=-1)

    def undistort(self, xd: np.ndarray, iterations: int = 30) -> np.ndarray:
        """Distorted -> undistorted normalised coordinates (fixed-point iteration with a Newton step on the
        radial part; exact to ~1e-12 inside the image for ordinary lenses)."""
        xd = np.asarray(xd, dtype=float)
        if not np.any(self.dist):
            return xd.copy()
        x = xd.copy()
        for _ in range(iterations):
            # numeric Jacobian of distort (2x2 per point), Newton step
            f = self.distort(x) - xd
            h = 1e-7
            fx = (self.distort(x + np.array([h, 0.0])) - self.distort(x - np.array([h, 0.0]))) / (2 * h)
            fy = (self.distort(x + np.array([0.0, h])) - self.distort(x - np.array([0.0, h]))) / (2 * h)
            a11, a21 = fx[..., 0], fx[..., 1]
            a12, a22 = fy[..., 0], fy[..., 1]
            det = a11 * a22 - a12 * a21
            det = np.where(np.abs(det) < 1e-12, 1e-12, det)
            dx = (a22 * f[..., 0] - a12 * f[..., 1]) / det
            dy = (-a21 * f[..., 0] + a11 * f[..., 1]) / det
            x = x - np.stack([dx, dy], axis=-1)
            if np.nanmax(np.abs(f)) < 1e-13:
                break
        return x

    @property
    def r_limit(self) -> float:
        """Largest undistorted normalised radius that is trusted: 5 % beyond the image corners, and below
        the radius where the radial distortion turns back."""
        if self._r_limit is None:
            w, h = self.width, self.height
            t = np.linspace(0.0, 1.0, 65)
            border = np.concatenate([np.column_stack([t * w, np.zeros_like(t)]), np.column_stack([t * w, np.full_like(t, h)]),
                                     np.column_stack([np.zeros_like(t), t * h]), np.column_stack([np.full_like(t, w), t * h])])
            xn = self.unproject(border)
            r = float(np.nanmax(np.hypot(xn[:, 0], xn[:, 1]))) * 1.05
            # monotonic radial mapping up to r
            rs = np.linspace(1e-4, max(r, 1e-3) * 1.5, 600)
            rd = np.hypot(*np.moveaxis(self.distort(np.column_stack([rs, np.zeros_like(rs)])), -1, 0))
            turn = np.flatnonzero(np.diff(rd) <= 0)
            if len(turn):
                r = min(r, float(rs[turn[0]]) * 0.98)
            self._r_limit = r if math.isfinite(r) and r > 0 else float("inf")
        return self._r_limit

    def valid_normalized(self, xn: np.ndarray) -> np.ndarray:
        return np.hypot(xn[..., 0], xn[..., 1]) <= self.r_limit

    # --- projection
    def project(self, xc: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Camera-frame points (N, 3) -> (pixels (N, 2), ok (N,)): ok = in front and within the trusted radius."""
        xc = np.asarray(xc, dtype=float)
        z = xc[..., 2]
        ok = z > 1e-9
        zs = np.where(ok, z, 1.0)
        xn = xc[..., :2] / zs[..., None]
        if not self.native:
            return self._pycolmap_project(xc), ok
        ok &= self.valid_normalized(xn)
        xd = self.distort(xn)
        px = np.stack([self.fx * xd[..., 0] + self.cx, self.fy * xd[..., 1] + self.cy], axis=-1)
        return px, ok

    def unproject(self, px: np.ndarray) -> np.ndarray:
        """Pixels (N, 2) -> undistorted normalised coordinates (N, 2)."""
        px = np.asarray(px, dtype=float)
        if not self.native:
            return self._pycolmap_unproject(px)
        xd = np.stack([(px[..., 0] - self.cx) / self.fx, (px[..., 1] - self.cy) / self.fy], axis=-1)
        return self.undistort(xd)

    def inside(self, px: np.ndarray, margin: float = 0.0) -> np.ndarray:
        return ((px[..., 0] >= margin) & (px[..., 0] <= self.width - margin)
                & (px[..., 1] >= margin) & (px[..., 1] <= self.height - margin))

    def _pycolmap_camera(self):
        import pycolmap

        cam = pycolmap.Camera.create_from_model_name(1, self.model, 1.0, self.width, self.height)
        cam.params = np.asarray(self.params, dtype=float)
        return cam

    def _pycolmap_project(self, xc: np.ndarray) -> np.ndarray:
        shape = xc.shape[:-1]
        out = np.asarray(self._pycolmap_camera().img_from_cam(xc.reshape(-1, 3)), dtype=float)
        return out.reshape(shape + (2,))

    def _pycolmap_unproject(self, px: np.ndarray) -> np.ndarray:
        shape = px.shape[:-1]
        out = np.asarray(self._pycolmap_camera().cam_from_img(px.reshape(-1, 2)), dtype=float)
        return out[:, :2].reshape(shape + (2,))


@dataclass
class Pose:
    """cam_from_world in a local frame: x_cam = R X + t."""

    rotation: np.ndarray
    translation: np.ndarray

    @property
    def centre(self) -> np.ndarray:
        return -self.rotation.T @ self.translation

    @classmethod
    def from_centre(cls, rotation: np.ndarray, centre: Sequence[float]) -> Pose:
        r = np.asarray(rotation, dtype=float)
        return cls(r, -r @ np.asarray(centre, dtype=float))

    def to_camera(self, xyz: np.ndarray) -> np.ndarray:
        return np.asarray(xyz, dtype=float) @ self.rotation.T + self.translation


def project_points(pose: Pose, cam: Intrinsics, xyz: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    return cam.project(pose.to_camera(xyz))


# ---------------------------------------------------------------------------
# omega, phi, kappa
# ---------------------------------------------------------------------------

_FLIP = np.diag([1.0, -1.0, -1.0])


def opk_matrix(omega: float, phi: float, kappa: float, degrees: bool = True) -> np.ndarray:
    """The photogrammetric rotation M = R_kappa R_phi R_omega (object -> image, image z backwards)."""
    if degrees:
        omega, phi, kappa = (math.radians(v) for v in (omega, phi, kappa))
    cw, sw = math.cos(omega), math.sin(omega)
    cp, sp = math.cos(phi), math.sin(phi)
    ck, sk = math.cos(kappa), math.sin(kappa)
    r_omega = np.array([[1.0, 0.0, 0.0], [0.0, cw, sw], [0.0, -sw, cw]])
    r_phi = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])
    r_kappa = np.array([[ck, sk, 0.0], [-sk, ck, 0.0], [0.0, 0.0, 1.0]])
    return r_kappa @ r_phi @ r_omega


def rotation_from_opk(omega: float, phi: float, kappa: float, degrees: bool = True) -> np.ndarray:
    """COLMAP cam_from_world rotation (x right, y down, z forward) of omega, phi, kappa."""
    return _FLIP @ opk_matrix(omega, phi, kappa, degrees)


def opk_from_rotation(rotation: np.ndarray, degrees: bool = True) -> Tuple[float, float, float]:
    """(omega, phi, kappa) of a COLMAP cam_from_world rotation."""
    m = _FLIP @ np.asarray(rotation, dtype=float)
    phi = math.asin(max(-1.0, min(1.0, m[2, 0])))
    omega = math.atan2(-m[2, 1], m[2, 2])
    kappa = math.atan2(-m[1, 0], m[0, 0])
    if degrees:
        return math.degrees(omega), math.degrees(phi), math.degrees(kappa)
    return omega, phi, kappa


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

    @property
    def outliers(self) -> List[str]:
        return [r.name for r in self.residuals if not r.used]

    @property
    def n_used(self) -> int:
        return sum(1 for r in self.residuals if r.used)


def _rvec(r: np.ndarray) -> np.ndarray:
    import cv2

    return cv2.Rodrigues(np.asarray(r, dtype=np.float64))[0].ravel()


def _rmat(v: np.ndarray) -> np.ndarray:
    import cv2

    return cv2.Rodrigues(np.asarray(v, dtype=np.float64).reshape(3, 1))[0]


def _errors(pose: Pose, cam: Intrinsics, xyz: np.ndarray, px: np.ndarray) -> np.ndarray:
    proj, ok = project_points(pose, cam, xyz)
    err = np.hypot(*(proj - px).T)
    return np.where(ok & np.isfinite(err), err, np.inf)


def _pnp(xyz: np.ndarray, xn: np.ndarray) -> List[Pose]:
    """Pose hypotheses from 4+ points (undistorted normalised image coordinates)."""
    import cv2

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
    return ResectionResult(pose, cam, residuals, rmse, estimated, sigma_f, warnings, est_params)


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
    import cv2

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
