"""Lens models of multispectral band cameras (issue 37): Pix4D's fisheye and perspective models, an ideal pinhole,
and the rig's relative rotation; rays to pixels and back.

Conventions (every function here): a ray is a 3-vector in the camera frame of OpenCV / COLMAP (x right, y down,
z forward, along the optical axis); a pixel is (x, y) with (0, 0) the centre of the top-left pixel, x right, y
down.  Numbers only: the readers (``core/io/multispectral.py``) give the tags, :func:`fisheye_from_pix4d` and
:func:`perspective_from_pix4d` turn them into pixels.

Pix4D fisheye (Pix4D "How are the internal and external camera parameters defined?", section 2.2, and Pix4D's
note "Camera internals for fisheye lens"; used the same way by the Sequoia band handlers that build an undistortion
map from ``FisheyePolynomial`` / ``FisheyeAffineMatrix``; a variation of Scaramuzza's omnidirectional model)::

    theta = 2/pi * atan(sqrt(X^2 + Y^2) / Z)             (0 on the axis, 1 at 90 degrees)
    rho   = p0 + p1 theta + p2 theta^2 + p3 theta^3       (p1 = 1: the others are normalised by it)
    (xh, yh) = rho * (X, Y) / sqrt(X^2 + Y^2)
    (x, y)   = [[C, D], [E, F]] (xh, yh) + (cx, cy)       (C, D, E, F in pixels)

so that the focal length at the centre is F = 2 C / pi (Pix4D's note).  The Sequoia writes the principal point
in millimetres on the sensor (``Camera:PrincipalPoint``) and the affine matrix in pixels: the principal point in
pixels is PrincipalPoint * EXIF FocalPlaneXResolution (px per mm; the Sequoia's 266.667 px/mm is a 3.75 um pitch,
its 1280 x 960 sensor 4.8 x 3.6 mm; its 2.488, 1.755 mm give (663, 468) px near the frame's centre, and C / (2/pi)
= 1067 px agrees with its EXIF focal length 3.98 mm = 1061 px).

Pix4D perspective (same article, section 2.1.2), on normalised coordinates (x, y) = (X / Z, Y / Z),
r^2 = x^2 + y^2::

    xd = x (1 + R1 r^2 + R2 r^4 + R3 r^6) + 2 T1 x y + T2 (r^2 + 2 x^2)
    yd = y (1 + R1 r^2 + R2 r^4 + R3 r^6) + T1 (r^2 + 2 y^2) + 2 T2 x y
    (u, v) = f (xd, yd) + (cx, cy)

which is OpenCV's model with (k1, k2, p1, p2, k3) = (R1, R2, T1, T2, R3): T1 is OpenCV's p1, T2 its p2, the order
MicaSense's ``imageprocessing`` and OpenDroneMap (``Photo.cv2_distortion_coeff``: PerspectiveDistortion items
[0, 1, 3, 4, 2]) use for the files that MicaSense writes.

Rig relatives (``Camera:RigRelatives``, degrees, the rotation of a band camera relative to the rig's reference
camera): R = Rx(a0) Ry(a1) Rz(a2), and a ray of the band camera seen from the reference camera is
R_ref^T R ray (MicaSense ``imageprocessing``, OpenDroneMap ``Photo.get_homography``: the homography of a band
onto the reference is K_ref R_ref^T R K^-1).  Checked on the real Sequoia capture, whose band files follow
Pix4D's tags (``benchmarks/band_registration.py --conventions``, model-only median residual against the green
band): this convention 0.4 - 0.8 px; the rotation transposed 5.6 - 22.7 px; no rotation 3.1 - 11.8 px; the
principal point's y read from the bottom edge (Pix4D's figures put the image origin at the lower left) 9.8 -
45.9 px, so the Sequoia's PrincipalPoint is measured from the top-left corner, y down.

Pure NumPy; no qgis, no Qt, no GDAL.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError

NEWTON_STEPS = 30


class LensError(ArchaeoOrthoError, ValueError):
    """Lens numbers that make no model; the message names the parameter and the problem."""


def _rays(rays) -> np.ndarray:
    a = np.asarray(rays, dtype=np.float64)
    if a.shape[-1] != 3:
        raise ValueError(f"rays must have 3 components, got shape {a.shape}")
    return a


def _pixels(px) -> np.ndarray:
    a = np.asarray(px, dtype=np.float64)
    if a.shape[-1] != 2:
        raise ValueError(f"pixels must have 2 components, got shape {a.shape}")
    return a


def _unit(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    n = np.sqrt(x * x + y * y + z * z)
    return np.stack([x / n, y / n, z / n], axis=-1)


@dataclass(frozen=True)
class PinholeLens:
    """An ideal pinhole: u = f X / Z + cx, v = f Y / Z + cy (pixels)."""
    f: float
    cx: float
    cy: float

    @property
    def matrix(self) -> np.ndarray:
        return np.array([[self.f, 0.0, self.cx], [0.0, self.f, self.cy], [0.0, 0.0, 1.0]])

    def project(self, rays) -> np.ndarray:
        r = _rays(rays)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(r[..., 2] > 0, r[..., 2], np.nan)
            return np.stack([self.f * r[..., 0] / z + self.cx, self.f * r[..., 1] / z + self.cy], axis=-1)

    def unproject(self, px) -> np.ndarray:
        p = _pixels(px)
        return _unit((p[..., 0] - self.cx) / self.f, (p[..., 1] - self.cy) / self.f, np.ones(p.shape[:-1]))


@dataclass(frozen=True)
class FisheyeLens:
    """Pix4D's fisheye model in pixels (module docstring): principal point (cx, cy), ``affine`` (C, D, E, F),
    ``polynomial`` (p0, p1, p2, p3, ...: rho as a polynomial of theta)."""
    cx: float
    cy: float
    affine: Tuple[float, float, float, float]
    polynomial: Tuple[float, ...]

    def __post_init__(self):
        if len(self.affine) != 4:
            raise LensError(f"fisheye affine matrix: 4 numbers (C, D, E, F) expected, got {len(self.affine)}")
        c, d, e, f = self.affine
        if abs(c * f - d * e) < 1e-9:
            raise LensError(f"fisheye affine matrix {tuple(self.affine)} is singular")
        if len(self.polynomial) < 2 or self.polynomial[1] <= 0:
            raise LensError(f"fisheye polynomial {tuple(self.polynomial)}: p1 (the linear term) must be > 0")

    @property
    def focal_px(self) -> float:
        """The focal length at the centre, pixels: 2 / pi * p1 * (C + F) / 2."""
        c, _, _, f = self.affine
        return 2.0 / math.pi * self.polynomial[1] * 0.5 * (c + f)

    def _rho(self, theta: np.ndarray) -> np.ndarray:
        return np.polynomial.polynomial.polyval(theta, self.polynomial)

    def _drho(self, theta: np.ndarray) -> np.ndarray:
        return np.polynomial.polynomial.polyval(theta, np.polynomial.polynomial.polyder(self.polynomial))

    def project(self, rays) -> np.ndarray:
        r = _rays(rays)
        x, y, z = r[..., 0], r[..., 1], r[..., 2]
        radial = np.hypot(x, y)
        theta = 2.0 / math.pi * np.arctan2(radial, z)
        rho = self._rho(theta)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(radial > 0, rho / radial, 0.0)
        xh, yh = scale * x, scale * y
        c, d, e, f = self.affine
        return np.stack([c * xh + d * yh + self.cx, e * xh + f * yh + self.cy], axis=-1)

    def theta_of_rho(self, rho: np.ndarray) -> np.ndarray:
        """The inverse of the polynomial by Newton's method from theta = rho / p1; NaN where it does not
        converge to a root on the rising part of the polynomial (beyond the lens's field)."""
        theta = rho / self.polynomial[1]
        for _ in range(NEWTON_STEPS):
            slope = self._drho(theta)
            step = (self._rho(theta) - rho) / np.where(slope > 1e-6, slope, np.nan)
            theta = theta - step
            if np.all(~np.isfinite(step) | (np.abs(step) < 1e-13)):
                break
        bad = ~np.isfinite(theta) | (self._drho(theta) <= 0) | (np.abs(self._rho(theta) - rho) > 1e-9) | (theta < 0)
        return np.where(bad, np.nan, theta)

    def unproject(self, px) -> np.ndarray:
        p = _pixels(px)
        c, d, e, f = self.affine
        inv = np.linalg.inv(np.array([[c, d], [e, f]], dtype=np.float64))
        u, v = p[..., 0] - self.cx, p[..., 1] - self.cy
        xh, yh = inv[0, 0] * u + inv[0, 1] * v, inv[1, 0] * u + inv[1, 1] * v
        rho = np.hypot(xh, yh)
        alpha = self.theta_of_rho(rho) * (math.pi / 2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(rho > 0, np.sin(alpha) / rho, 0.0)
        return np.stack([s * xh, s * yh, np.cos(alpha)], axis=-1)


@dataclass(frozen=True)
class PerspectiveLens:
    """Pix4D's perspective model in pixels (module docstring): focal ``f``, principal point (cx, cy), ``radial``
    (R1, R2, R3), ``tangential`` (T1, T2) = OpenCV's (p1, p2)."""
    f: float
    cx: float
    cy: float
    radial: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    tangential: Tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        if not self.f > 0:
            raise LensError(f"perspective focal length {self.f} px: must be > 0")

    @property
    def focal_px(self) -> float:
        return self.f

    def distort(self, x: np.ndarray, y: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Normalised ideal coordinates -> normalised distorted coordinates."""
        r1, r2, r3 = self.radial
        t1, t2 = self.tangential
        r2_ = x * x + y * y
        k = 1.0 + r2_ * (r1 + r2_ * (r2 + r2_ * r3))
        return (x * k + 2.0 * t1 * x * y + t2 * (r2_ + 2.0 * x * x),
                y * k + t1 * (r2_ + 2.0 * y * y) + 2.0 * t2 * x * y)

    def _jacobian(self, x: np.ndarray, y: np.ndarray):
        r1, r2, r3 = self.radial
        t1, t2 = self.tangential
        s = x * x + y * y
        k = 1.0 + s * (r1 + s * (r2 + s * r3))
        dk = r1 + s * (2.0 * r2 + 3.0 * r3 * s)   # dk/ds
        a = k + 2.0 * x * x * dk + 2.0 * t1 * y + 6.0 * t2 * x
        b = 2.0 * x * y * dk + 2.0 * t1 * x + 2.0 * t2 * y
        c = 2.0 * x * y * dk + 2.0 * t1 * x + 2.0 * t2 * y
        d = k + 2.0 * y * y * dk + 6.0 * t1 * y + 2.0 * t2 * x
        return a, b, c, d

    def project(self, rays) -> np.ndarray:
        r = _rays(rays)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(r[..., 2] > 0, r[..., 2], np.nan)
            xd, yd = self.distort(r[..., 0] / z, r[..., 1] / z)
        return np.stack([self.f * xd + self.cx, self.f * yd + self.cy], axis=-1)

    def undistort(self, xd: np.ndarray, yd: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Normalised distorted -> ideal coordinates by Newton's method (2 x 2 Jacobian per point); NaN where
        it does not converge (outside the region where the model is invertible)."""
        x, y = xd.copy(), yd.copy()
        for _ in range(NEWTON_STEPS):
            fx, fy = self.distort(x, y)
            ex, ey = fx - xd, fy - yd
            a, b, c, d = self._jacobian(x, y)
            det = a * d - b * c
            with np.errstate(divide="ignore", invalid="ignore"):
                dx, dy = (d * ex - b * ey) / det, (a * ey - c * ex) / det
            x, y = x - dx, y - dy
            if np.all(~np.isfinite(dx) | (np.hypot(dx, dy) < 1e-14)):
                break
        fx, fy = self.distort(x, y)
        bad = ~(np.hypot(fx - xd, fy - yd) < 1e-10)
        return np.where(bad, np.nan, x), np.where(bad, np.nan, y)

    def unproject(self, px) -> np.ndarray:
        p = _pixels(px)
        x, y = self.undistort((p[..., 0] - self.cx) / self.f, (p[..., 1] - self.cy) / self.f)
        return _unit(x, y, np.ones_like(x))


def fisheye_from_pix4d(principal_point_mm: Sequence[float], px_per_mm: Sequence[float],
                       affine: Sequence[float], polynomial: Sequence[float]) -> FisheyeLens:
    """A :class:`FisheyeLens` from the tags as written: ``PrincipalPoint`` (mm), the focal plane resolution (px
    per mm, x and y), ``FisheyeAffineMatrix`` (C, D, E, F, px), ``FisheyePolynomial``."""
    pp, res = _pair(principal_point_mm, "principal point (mm)"), _pair(px_per_mm, "focal plane resolution")
    return FisheyeLens(pp[0] * res[0], pp[1] * res[1], tuple(float(v) for v in affine),
                       tuple(float(v) for v in polynomial))


def perspective_from_pix4d(principal_point_mm: Sequence[float], focal_mm: float, px_per_mm: Sequence[float],
                           distortion: Optional[Sequence[float]] = None) -> PerspectiveLens:
    """A :class:`PerspectiveLens` from ``PrincipalPoint`` (mm), ``PerspectiveFocalLength`` (mm), the focal plane
    resolution (px per mm) and ``PerspectiveDistortion`` (R1, R2, R3, T1, T2; None: no distortion).  The focal
    length in pixels is focal_mm times the mean of the x and y resolutions."""
    pp, res = _pair(principal_point_mm, "principal point (mm)"), _pair(px_per_mm, "focal plane resolution")
    k = tuple(float(v) for v in (distortion or ())) + (0.0,) * 5
    if distortion is not None and len(distortion) not in (3, 5):
        raise LensError(f"perspective distortion {tuple(distortion)}: 5 numbers (R1, R2, R3, T1, T2) expected")
    return PerspectiveLens(float(focal_mm) * 0.5 * (res[0] + res[1]), pp[0] * res[0], pp[1] * res[1],
                           k[:3], k[3:5])


def _pair(values: Sequence[float], what: str) -> Tuple[float, float]:
    v = tuple(float(x) for x in values or ())
    if len(v) != 2 or not all(math.isfinite(x) for x in v):
        raise LensError(f"{what}: two numbers expected, got {values}")
    return v[0], v[1]


def rig_rotation(relatives_deg: Optional[Sequence[float]]) -> np.ndarray:
    """The rotation of ``Camera:RigRelatives`` (degrees about x, y, z): Rx Ry Rz; identity for None (the rig's
    reference camera carries none)."""
    if relatives_deg is None:
        return np.eye(3)
    if len(relatives_deg) != 3:
        raise LensError(f"rig relatives {tuple(relatives_deg)}: three angles (degrees) expected")
    a, b, c = (math.radians(float(v)) for v in relatives_deg)
    rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    return rx @ ry @ rz


def band_to_reference(relatives_deg: Optional[Sequence[float]],
                      reference_relatives_deg: Optional[Sequence[float]] = None) -> np.ndarray:
    """The rotation that turns a band camera's ray into the reference camera's: R_ref^T R (module docstring)."""
    return rig_rotation(reference_relatives_deg).T @ rig_rotation(relatives_deg)
