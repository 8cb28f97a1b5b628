"""The one frame-camera type of every stage: COLMAP camera models in numpy (``Intrinsics``, with the
OpenCV form of its parameters), the pose (``Pose``), projection, and the photogrammetric omega-phi-kappa
convention.

Pure numpy (pycolmap only for camera models this module does not project itself): no qgis, no Qt.

Conventions
-----------
- Pixels: COLMAP's, the origin at the upper-left corner of the upper-left pixel, x right, y down (the centre
  of the first pixel is (0.5, 0.5)).  ``Intrinsics.cv_matrix`` gives OpenCV's (pixel centres at integers).
- Poses: ``cam_from_world`` rotation R and translation t (x_cam = R X + t) with COLMAP's camera axes
  (x right, y down, z along the viewing direction), in a *local* metric frame (world minus an offset, so
  UTM-size numbers never meet float32 or a badly scaled Jacobian).
- Omega-phi-kappa (photogrammetry, e.g. PATB, Pix4D, Wolf & Dewitt): M = R_kappa R_phi R_omega maps
  object-frame vectors into a camera frame with x right, y *up* and z *backwards* (out of the lens); for
  omega = phi = kappa = 0 the camera looks straight down with image x to the east and image y to the north.
  COLMAP's rotation is diag(1, -1, -1) M.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError, require

# COLMAP camera models this module projects natively: name -> parameter names
MODELS = {
    "SIMPLE_PINHOLE": ("f", "cx", "cy"),
    "PINHOLE": ("fx", "fy", "cx", "cy"),
    "SIMPLE_RADIAL": ("f", "cx", "cy", "k1"),
    "RADIAL": ("f", "cx", "cy", "k1", "k2"),
    "OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"),
    "FULL_OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
}


class CameraError(ArchaeoOrthoError, ValueError):
    """A camera cannot be built from these parameters; the message says why."""


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
            raise CameraError(f"camera model {self.model} takes {len(MODELS[self.model])} parameters "
                                 f"({', '.join(MODELS[self.model])}), got {len(self.params)}")

    # --- construction
    @classmethod
    def from_pycolmap(cls, camera) -> Intrinsics:
        return cls(str(camera.model_name), int(camera.width), int(camera.height), tuple(np.asarray(camera.params)))

    @classmethod
    def simple(cls, width: int, height: int, focal_px: float, cx: Optional[float] = None, cy: Optional[float] = None,
               distortion: Sequence[float] = (0.0, 0.0, 0.0, 0.0)) -> Intrinsics:
        """An OPENCV camera with square pixels; the principal point defaults to the image centre; ``distortion``:
        OpenCV's (k1, k2, p1, p2)."""
        cx = width / 2.0 if cx is None else cx
        cy = height / 2.0 if cy is None else cy
        k1, k2, p1, p2 = distortion
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

    def cv_matrix(self, sx: float = 1.0, sy: float = 1.0) -> Tuple[np.ndarray, np.ndarray]:
        """(K, distortion) in OpenCV's pixel convention (pixel centres at integers) for the image scaled by
        (sx, sy): COLMAP puts the origin at the corner of the first pixel, so cx_cv = cx * sx - 0.5.  The
        distortion holds OpenCV's first 4 terms, all 8 for FULL_OPENCV (native models only)."""
        d = self.dist if self.model == "FULL_OPENCV" else self.dist[:4]
        k = np.array([[self.fx * sx, 0.0, self.cx * sx - 0.5], [0.0, self.fy * sy, self.cy * sy - 0.5],
                      [0.0, 0.0, 1.0]])
        return k, d

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
        if not self.native:  # pycolmap's model: trusted where the pixel unprojects to the same ray
            px = self._pycolmap_project(xc)
            with np.errstate(invalid="ignore"):
                back = self._pycolmap_unproject(np.where(np.isfinite(px), px, 0.0))
                ok &= np.all(np.isfinite(px), axis=-1) & (np.hypot(*np.moveaxis(back - xn, -1, 0))
                                                          <= 1e-4 * (1.0 + np.hypot(xn[..., 0], xn[..., 1])))
            return px, ok
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
        pycolmap = require("pycolmap", f"projecting through a {self.model} camera")
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


@functools.lru_cache(maxsize=256)
def _intrinsics(model: str, width: int, height: int, params: Tuple[float, ...]) -> Intrinsics:
    return Intrinsics(model, width, height, params)


def intrinsics_of(camera) -> Intrinsics:
    """The :class:`Intrinsics` of a pycolmap camera, one object per distinct camera (so its trusted radius,
    ``r_limit``, is computed once however many points are projected through it)."""
    return _intrinsics(str(camera.model_name), int(camera.width), int(camera.height),
                       tuple(float(p) for p in np.asarray(camera.params)))


def project_in_image(camera, cam_from_world, xyz, margin: float = 0.0) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The one rule for where points are seen in a photo: (pixels (N, 2), seen (N,), centrality (N,)).

    ``camera``: an :class:`Intrinsics` or a pycolmap camera; ``cam_from_world``: the image's 3 x 4 matrix;
    ``xyz`` (N, 3) or (3,) in the same frame.  Seen: in front of the camera, within the lens model's trusted
    radius (:meth:`Intrinsics.project`: ``r_limit``, or the round trip for models pycolmap alone knows) and inside
    the frame by ``margin`` pixels (negative: that far outside).  Centrality: 0 at the image centre, 1 at a
    corner.  Used by guided placement, the automatic control and Find targets alike, so a point is inside a
    photo for all of them or for none."""
    cam = camera if isinstance(camera, Intrinsics) else intrinsics_of(camera)
    m = np.asarray(cam_from_world, dtype=float)
    xc = np.atleast_2d(np.asarray(xyz, dtype=float)) @ m[:, :3].T + m[:, 3]
    px, ok = cam.project(xc)
    px = np.where(ok[:, None], px, np.nan)
    with np.errstate(invalid="ignore"):
        seen = ok & cam.inside(px, margin)
    w, h = float(cam.width), float(cam.height)
    centrality = np.hypot(px[:, 0] - 0.5 * w, px[:, 1] - 0.5 * h) / (0.5 * math.hypot(w, h))
    return px, seen, centrality


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
