"""The bundle problem: projection through the camera model, its Jacobians, and the adjustment's problem.

One module for the georeferencing solver (``core.georef.adjust``) and the covariance
(``core.georef.uncertainty``): both project through pycolmap's camera model (``Camera.img_from_cam``) with
the same derivatives: analytic for the rigid part (:func:`pose_point_jacobians`), central differences for
the camera model (:func:`project_jacobian`, :func:`intrinsics_jacobian`).

``BundleProblem`` is the sparse Levenberg-Marquardt adjustment with priors; ``build_problem`` assembles it
from a reconstruction in the local frame, the control points and the camera positions.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, check_cancel
from ..geometry.similarity import rodrigues, skew
from ..io.gcp import Observation
from .errors import GeorefError
from .options import (
    REFINED_FOCAL_SIGMA,
    REFINED_PP_SIGMA,
    REFINED_RADIAL_SIGMA,
    REFINED_TANGENTIAL_SIGMA,
    GeorefOptions,
)

# ----------------------------------------------------------------------------
# projection and its derivatives
# ----------------------------------------------------------------------------


def project(camera, xc: np.ndarray) -> np.ndarray:
    """Pixel coordinates of camera-frame points (M,3) through the full camera model."""
    if len(xc) == 0:
        return np.zeros((0, 2))
    return np.asarray(camera.img_from_cam(np.ascontiguousarray(xc, dtype=float), check_cheirality=False))


def project_jacobian(camera, xc: np.ndarray) -> np.ndarray:
    """d(pixel)/d(camera-frame point) (M,2,3), central differences scaled by depth."""
    h = 1e-6 * np.maximum(np.abs(xc[:, 2]), 1e-9)
    jac = np.empty((len(xc), 2, 3))
    for k in range(3):
        d = np.zeros_like(xc)
        d[:, k] = h
        jac[:, :, k] = (project(camera, xc + d) - project(camera, xc - d)) / (2 * h)[:, None]
    return jac


def intrinsics_jacobian(camera, xc: np.ndarray, free: Sequence[int], floor: float = 1.0) -> np.ndarray:
    """d(pixel)/d(free camera parameters) (M,2,len(free)), central differences with a step of
    1e-6 x max(floor, |parameter|)."""
    out = np.empty((len(xc), 2, len(free)))
    base = np.array(camera.params, dtype=float)
    cam = copy.copy(camera)
    for j, k in enumerate(free):
        h = 1e-6 * max(floor, abs(base[k]))
        p = base.copy()
        p[k] += h
        cam.params = p
        up = project(cam, xc)
        p[k] -= 2 * h
        cam.params = p
        dn = project(cam, xc)
        out[:, :, j] = (up - dn) / (2 * h)
    return out


def pose_point_jacobians(jpi: np.ndarray, sensor_rotation: np.ndarray, rotation: np.ndarray,
                         xr: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rigid part of the observation Jacobian for Xc = R_s (R (X - C)) + t_s, Xr = R (X - C).

    ``jpi``: d(pixel)/d(Xc) (M,2,3); ``sensor_rotation`` R_s and ``rotation`` R (M,3,3); ``xr`` (M,3).
    Returns d(pixel)/d(rotation increment, left, 3), d(pixel)/d(centre C) and d(pixel)/d(point X), each
    (M,2,3)."""
    jrs = np.einsum("nij,njk->nik", jpi, sensor_rotation)  # d pixel / d Xr
    j_rot = -np.einsum("nij,njk->nik", jrs, skew(xr))
    j_pt = np.einsum("nij,njk->nik", jrs, rotation)
    return j_rot, -j_pt, j_pt


def huber_weights(s: np.ndarray, robust: np.ndarray, huber: float) -> np.ndarray:
    """Iteratively-reweighted Huber weights of normalised residuals ``s``: 1, or huber / s beyond ``huber``
    where ``robust`` (tie points; GCP observations are not robust)."""
    w = np.ones_like(s)
    big = robust & (s > huber)
    w[big] = huber / s[big]
    return w


def inv3(m: np.ndarray) -> np.ndarray:
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
    det = np.where(np.abs(det) > 1e-300, det, np.nan)  # singular block: NaN, not a division by zero
    return co / det[:, None, None]


def outside_image(camera, ob: Observation) -> bool:
    """The observation lies off the image: the pixel origin is the upper-left corner of the upper-left
    pixel, x right, y down, so valid is 0 <= x <= width and 0 <= y <= height (NaN is outside).  A camera
    without a size (0) is not checked."""
    w, h = float(camera.width), float(camera.height)
    if w <= 0 or h <= 0:
        return False
    return not (0.0 <= float(ob.x) <= w and 0.0 <= float(ob.y) <= h)


FIELD_MARGIN = 1.25
# FULL_OPENCV's rational terms: a calibration file's FULL_OPENCV camera (one with k3) holds them at 0 by
# construction (core.io.calibration.CameraCalibration.colmap_model), so they are never free for such a camera
CALIBRATION_ZERO_TERMS = ("k4", "k5", "k6")


def field_radius(camera, margin: float = FIELD_MARGIN) -> float:
    """The largest normalised image-plane radius (x/z, y/z) an observation of ``camera`` may have: the image
    corners' undistorted radius times ``margin``.  A polynomial distortion model turns back on itself beyond
    its range, so a point far outside the field of view (one triangulated close to the camera's plane) can
    reproject into the image; such an observation's distortion derivatives grow with r^5 and freeze the
    distortion parameters.  Infinite for a camera without a size."""
    w, h = float(camera.width), float(camera.height)
    if w <= 0 or h <= 0:
        return float("inf")
    corners = np.array([[0.0, 0.0], [w, 0.0], [0.0, h], [w, h], [w / 2, 0.0], [0.0, h / 2], [w, h / 2],
                        [w / 2, h]])
    xy = np.asarray(camera.cam_from_img(corners), dtype=float)
    r = np.hypot(xy[:, 0], xy[:, 1])
    r = r[np.isfinite(r)]
    return float(margin * r.max()) if len(r) else float("inf")


@dataclass
class Observations:
    """Observation arrays of the adjustment (one row per 2-D observation)."""

    img: np.ndarray  # (O,) index into images
    pt: np.ndarray  # (O,) index into points
    xy: np.ndarray  # (O,2)
    sigma: np.ndarray  # (O,) pixels
    robust: np.ndarray  # (O,) bool: Huber loss (tie points)
    active: np.ndarray  # (O,) bool


@dataclass
class Frames:
    """The exterior orientation the adjustment starts from: the rig frames (rig_from_world rotation, centre in
    world) and each image's frame, camera and fixed sensor_from_rig (identity for ordinary single cameras)."""

    rotation: Any  # (F,3,3)
    centre: Any  # (F,3)
    img_frame: Any  # (I,) index into the frames
    img_cam: Any  # (I,) index into the cameras
    sensor_rotation: Any  # (I,3,3)
    sensor_translation: Any  # (I,3)


@dataclass
class Intrinsics:
    """The cameras (pycolmap.Camera copies, updated in place), the indices of each one's free parameters, and
    their priors: ``focal_prior`` (sigma = focal_prior x the starting focal length, 0: none) and
    ``given_priors``: camera index -> (parameter index, given value, sigma) of a camera refined from a given
    calibration (instead of the focal prior)."""

    cameras: List[Any]
    free: List[Sequence[int]]
    focal_prior: float = 0.0
    given_priors: Optional[Dict[int, List[Tuple[int, float, float]]]] = None


@dataclass
class Points:
    """The points of the adjustment (P,3) and their position priors (P,3, NaN where none) with sigmas (P,3)."""

    xyz: Any
    prior: Any
    prior_sigma: Any


@dataclass
class CameraPriors:
    """Priors on projection centres: the image rows (K,), the positions (K,3) and their sigmas (K,3)."""

    img: Any
    xyz: Any
    sigma: Any


class BundleProblem:
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

    def __init__(self, frames: Frames, intrinsics: Intrinsics, points: Points, obs: Observations,
                 camera_priors: CameraPriors, huber_px: float = 2.0):
        self.R = np.asarray(frames.rotation, dtype=float).copy()  # (F,3,3) rig_from_world rotation
        self.C = np.asarray(frames.centre, dtype=float).copy()  # (F,3) rig centre in world
        self.img_frame = np.asarray(frames.img_frame, dtype=int)
        self.img_cam = np.asarray(frames.img_cam, dtype=int)
        self.Rs = np.asarray(frames.sensor_rotation, dtype=float)
        self.ts = np.asarray(frames.sensor_translation, dtype=float)
        self.cs = -np.einsum("nji,nj->ni", self.Rs, self.ts)  # sensor centre in the rig frame
        cameras = intrinsics.cameras
        self.cameras = cameras  # list of pycolmap.Camera copies (updated in place)
        self.cam_free = [np.asarray(f, dtype=int) for f in intrinsics.free]
        self.intr_offset = np.cumsum([0] + [len(f) for f in self.cam_free])
        self.X = np.asarray(points.xyz, dtype=float).copy()
        self.obs = obs
        self.pp = np.asarray(points.prior, dtype=float)  # (P,3), NaN where no prior
        self.pps = np.asarray(points.prior_sigma, dtype=float)  # (P,3)
        self.has_pp = np.all(np.isfinite(self.pp), axis=1)
        self.cp_img = np.asarray(camera_priors.img, dtype=int)
        self.cp_xyz = np.asarray(camera_priors.xyz, dtype=float).reshape(-1, 3)
        self.cp_sigma = np.asarray(camera_priors.sigma, dtype=float).reshape(-1, 3)
        self.cp_active = np.ones(len(self.cp_img), dtype=bool)
        self.huber = huber_px
        self.nf = len(self.R)
        self.nc = 6 * self.nf + int(self.intr_offset[-1])
        self.npt = len(self.X)
        self.iterations = 0
        self.field = np.array([field_radius(c) for c in cameras], dtype=float)  # per camera, see field_radius
        # a prior on each free focal length parameter: its starting value (the alignment's self-calibration),
        # sigma = focal_prior x that value (0: none).  On flat ground the focal length and the flying height
        # trade against each other almost freely; the prior keeps the calibration where nothing in the data
        # says otherwise instead of letting it wander along that valley.  ``intrinsic_priors``: camera index ->
        # (parameter index, given value, sigma) of a camera refined from a given calibration, in its place
        self.fp_col, self.fp_value, self.fp_sigma = [], [], []
        own = intrinsics.given_priors or {}
        focal_prior = intrinsics.focal_prior
        for k, rows in own.items():
            free_k = [int(i) for i in self.cam_free[k]]
            for idx, value, sigma in rows:
                if int(idx) in free_k:
                    self.fp_col.append((k, free_k.index(int(idx)), int(idx)))
                    self.fp_value.append(float(value))
                    self.fp_sigma.append(float(sigma))
        if focal_prior > 0:
            for k, cam in enumerate(self.cameras):
                if k in own:
                    continue
                fidx = set(int(i) for i in cam.focal_length_idxs())
                for j, idx in enumerate(self.cam_free[k]):
                    if int(idx) in fidx:
                        v = float(cam.params[idx])
                        self.fp_col.append((k, j, int(idx)))
                        self.fp_value.append(v)
                        self.fp_sigma.append(focal_prior * abs(v))
        self.fp_value = np.asarray(self.fp_value, dtype=float)
        self.fp_sigma = np.asarray(self.fp_sigma, dtype=float)

    # --- state -------------------------------------------------------------
    def state(self):
        return (self.R.copy(), self.C.copy(), [c.params.copy() for c in self.cameras], self.X.copy())

    def restore(self, st) -> None:
        self.R, self.C, params, self.X = st[0].copy(), st[1].copy(), st[2], st[3].copy()
        for cam, p in zip(self.cameras, params):
            cam.params = p.copy()

    def apply_step(self, dc: np.ndarray, dp: np.ndarray) -> None:
        d = dc[:6 * self.nf].reshape(-1, 6)
        self.R = rodrigues(d[:, :3]) @ self.R
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

    def _in_field(self, img: np.ndarray, xc: np.ndarray) -> np.ndarray:
        """In front of the camera and inside its field of view (``field_radius``)."""
        z = xc[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.hypot(xc[:, 0], xc[:, 1]) / z
        return (z > 0) & (r <= self.field[self.img_cam[img]])

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
                uv[m] = project(cam, xc[m])
        return uv - o.xy[sel], self._in_field(img, xc)

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

    def focal_prior_residuals(self) -> np.ndarray:
        if not len(self.fp_col):
            return np.zeros(0)
        now = np.array([self.cameras[k].params[idx] for k, _, idx in self.fp_col], dtype=float)
        return (now - self.fp_value) / self.fp_sigma

    def _huber_weights(self, s: np.ndarray, robust: np.ndarray) -> np.ndarray:
        return huber_weights(s, robust, self.huber)

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
        c += float(np.sum(self.focal_prior_residuals() ** 2))
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
                uv[mk] = project(cam, xc[mk])
                jpi[mk] = project_jacobian(cam, xc[mk])
        res = uv - o.xy[sel]
        front = self._in_field(img, xc) & np.all(np.isfinite(res), axis=1) & np.all(np.isfinite(jpi), axis=(1, 2))
        s = np.linalg.norm(np.where(front[:, None], res, 0.0), axis=1) / o.sigma[sel]
        sw = np.sqrt(self._huber_weights(s, o.robust[sel])) / o.sigma[sel] * front
        res = np.where(front[:, None], res, 0.0) * sw[:, None]
        j_rot, j_c, j_pt = pose_point_jacobians(jpi, self.Rs[img], self.R[f], xr)
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
            jk = intrinsics_jacobian(cam, xc[mk], free, floor=1e-2)
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
            d_rot = np.einsum("nji,njk->nik", self.R[fr], skew(self.cs[im]))  # R_f^T [c_s]x
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
        # focal length priors
        if len(self.fp_col):
            rows_r.append(nrow + np.arange(len(self.fp_col)))
            cols_r.append(np.array([6 * self.nf + self.intr_offset[k] + j for k, j, _ in self.fp_col]))
            vals_r.append(1.0 / self.fp_sigma)
            r_all.append(self.focal_prior_residuals())
            nrow += len(self.fp_col)
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
        # the damping floor relative to each point's own diagonal: one relative to the largest of all (a control
        # point held by a sigma of 1e-9 m has 1e18 there) put a ridge on every tie point that held the block
        # still (issue 47 item 6: residuals of 1 to 3 cm on exact control, the block as far off)
        own = dgp.max(axis=1) if dgp.size else np.ones(0)
        floor = (1e-9 * np.maximum(own, 1e-12 * max(float(own.max()) if own.size else 1.0, 1e-12)))[:, None]
        blocks = blocks + (lam * np.maximum(dgp, floor) + floor)[:, :, None] * np.eye(3)[None]
        vinv = inv3(blocks)
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
        # Marquardt damping on each column's own diagonal, with a floor relative to that column: the camera
        # unknowns mix radians, metres, pixels and distortion coefficients, and a floor relative to the largest
        # diagonal (a rotation's) put a ridge on the weak ones (focal length, k2) that held them for hundreds of
        # iterations
        damp = (lam + 1e-9) * np.maximum(dcc, 1e-12 * max(float(dcc.max()), 1e-12))
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
        progress = progress or NullProgress()
        lam = 1e-4
        cost = self.cost()
        cost0 = cost
        it = 0
        stalled = 0
        for it in range(1, max_iterations + 1):
            check_cancel(progress)
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
            # one progress text for the whole loop (the log printed each iteration's line: 20 alike), the figures
            # in the summary below
            progress.report(min(1.0, it / max_iterations), "bundle adjustment")
            if not accepted:
                break
            stalled = stalled + 1 if rel < tolerance else 0
            if stalled >= 2:
                break
        self.iterations += it
        progress.report(1.0, f"bundle adjustment: {it} iteration(s), cost {cost0:.6g} -> {cost:.6g}")
        return {"iterations": it, "initial_cost": cost0, "final_cost": cost}


def select_tie_points(point_tracks: Dict[int, np.ndarray], point_err: Dict[int, float], n_images: int,
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


@dataclass
class _Images:
    """The registered images of a reconstruction as the problem indexes them (frames, cameras, sensors)."""

    reg_ids: List[int]
    img_index: Dict[int, int]  # image id -> row
    frame_ids: List[int]
    frames_r: List[np.ndarray]
    frames_c: List[np.ndarray]
    img_frame: List[int]
    img_cam: List[int]
    img_rs: List[np.ndarray]
    img_ts: List[np.ndarray]
    camera_ids: List[int]
    images_per_cam: Dict[int, int]


def _index_images(rec) -> _Images:
    reg_ids = list(rec.reg_image_ids())
    out = _Images(reg_ids, {}, [], [], [], [], [], [], [], [], {})
    frame_index: Dict[int, int] = {}
    cam_index: Dict[int, int] = {}
    for iid in reg_ids:
        im = rec.image(iid)
        fid = im.frame_id
        if fid not in frame_index:
            fr = rec.frame(fid)
            m = np.asarray(fr.rig_from_world.matrix())
            frame_index[fid] = len(out.frame_ids)
            out.frame_ids.append(fid)
            out.frames_r.append(m[:, :3])
            out.frames_c.append(-m[:, :3].T @ m[:, 3])
        cid = im.camera_id
        if cid not in cam_index:
            cam_index[cid] = len(out.camera_ids)
            out.camera_ids.append(cid)
        out.images_per_cam[cid] = out.images_per_cam.get(cid, 0) + 1
        fr_m = np.asarray(rec.frame(fid).rig_from_world.matrix())
        cw = np.asarray(im.cam_from_world().matrix())
        rs = cw[:, :3] @ fr_m[:, :3].T
        ts = cw[:, 3] - rs @ fr_m[:, 3]
        out.img_index[iid] = len(out.img_frame)
        out.img_frame.append(frame_index[fid])
        out.img_cam.append(cam_index[cid])
        out.img_rs.append(rs)
        out.img_ts.append(ts)
    return out


def given_priors(cam, record: Dict[str, Any]) -> List[Tuple[int, float, float]]:
    """(parameter index, given value, sigma) of every parameter of ``cam``, a camera the alignment recorded as
    ``refined`` (``record``: core.align.calibrated.intrinsics_record's row): the given sigma where the calibration
    has one, else REFINED_*_SIGMA (core.georef.options)."""
    names = [n.strip() for n in cam.params_info.split(",")]
    given = record.get("given") or {}
    sigmas = record.get("sigmas") or {}
    long_side = float(max(cam.width, cam.height))
    out = []
    for idx, name in enumerate(names):
        value = float(given.get(name, cam.params[idx]))
        sigma = sigmas.get(name)
        if sigma is None or not sigma > 0:
            if name in ("f", "fx", "fy"):
                sigma = REFINED_FOCAL_SIGMA * abs(value)
            elif name in ("cx", "cy"):
                sigma = REFINED_PP_SIGMA * long_side
            elif name in ("p1", "p2"):
                sigma = REFINED_TANGENTIAL_SIGMA
            else:
                sigma = REFINED_RADIAL_SIGMA
        out.append((idx, value, float(sigma)))
    return out


def _free_intrinsics(rec, images: _Images, groups, min_intrinsics_images: int, warn: Callable[[str], None],
                     given: Optional[Dict[int, Dict[str, Any]]] = None):
    """Copies of the cameras, the indices of their free parameters, the ids of the refined ones, the priors of
    those refined from a given calibration (camera index -> given_priors) and the ids of the fixed ones.

    ``given``: camera id -> the alignment's record of its interior orientation (GeorefOptions.camera_intrinsics):
    ``fixed`` is never refined, ``refined`` is refined (every parameter) with priors at its given values,
    ``estimated`` (or no record) follows ``groups``."""
    cameras = [copy.copy(rec.cameras[cid]) for cid in images.camera_ids]
    cam_free = []
    refined = []
    priors: Dict[int, List[Tuple[int, float, float]]] = {}
    fixed: List[int] = []
    for k, (cid, cam) in enumerate(zip(images.camera_ids, cameras)):
        free: List[int] = []
        record = (given or {}).get(cid) or {}
        mode = record.get("mode", "estimated")
        if mode == "refined" and record.get("model") not in (None, cam.model.name):
            warn(f"camera {cid}: the calibration's model {record.get('model')} is not the model's "
                 f"{cam.model.name}: its intrinsics follow refine_intrinsics")
            mode = "estimated"
        if mode == "fixed":
            fixed.append(cid)
        elif mode == "refined":
            priors[k] = given_priors(cam, record)
            free = [idx for idx, _, _ in priors[k]]
            refined.append(cid)
        elif groups and images.images_per_cam[cid] >= min_intrinsics_images:
            if "focal" in groups:
                free += list(cam.focal_length_idxs())
            if "principal_point" in groups:
                free += list(cam.principal_point_idxs())
            if "extra" in groups:
                free += list(cam.extra_params_idxs())
            refined.append(cid)
        elif groups:
            warn(f"camera {cid}: only {images.images_per_cam[cid]} image(s), intrinsics kept fixed")
        if record.get("given") and free:  # a calibration file's camera: its structural zeros stay 0
            names = [n.strip() for n in cam.params_info.split(",")]
            free = [idx for idx in free if names[idx] not in CALIBRATION_ZERO_TERMS]
        cam_free.append(sorted(set(free)))
    return cameras, cam_free, refined, priors, fixed


@dataclass
class _ObservationRows:
    """The observation rows of the problem while it is assembled."""

    img: List[int]
    pt: List[int]
    xy: List[Any]
    sigma: List[float]
    robust: List[bool]


def _tie_points(rec, images: _Images, max_observations: int, tie_pixel_sigma: float):
    """The tie points that enter (all, or the best observed ones) and their observations."""
    tracks: Dict[int, np.ndarray] = {}
    errs: Dict[int, float] = {}
    for pid, p in rec.points3D.items():
        el = p.track.elements
        tracks[pid] = np.array([e.image_id for e in el if e.image_id in images.img_index], dtype=int)
        errs[pid] = float(p.error)
    tracks = {k: v for k, v in tracks.items() if len(v) >= 2}
    chosen = select_tie_points(tracks, errs, len(images.reg_ids), max_observations)
    tie_ids = np.asarray(chosen, dtype=np.int64)
    pt_index = {int(pid): k for k, pid in enumerate(tie_ids)}
    xyz = [np.asarray(rec.points3D[int(pid)].xyz) for pid in tie_ids]
    rows = _ObservationRows([], [], [], [], [])
    for iid in images.reg_ids:
        im = rec.image(iid)
        for p2 in im.get_observation_points2D():
            k = pt_index.get(p2.point3D_id)
            if k is not None:
                rows.img.append(images.img_index[iid])
                rows.pt.append(k)
                rows.xy.append(p2.xy)
    rows.sigma = [tie_pixel_sigma] * len(rows.img)
    rows.robust = [True] * len(rows.img)
    return tracks, tie_ids, xyz, rows


@dataclass
class Control:
    """What ties the adjustment to the ground, in the local frame (world = local + ``offset``): the control points
    that enter (GroundPoints), their model-frame triangulations by name (core.georef.triangulate), the camera
    positions matched to their images ((CameraPosition, pycolmap.Image) pairs), and ``model_to_local``, the
    similarity that took the model into the local frame."""

    points: List[Any]
    triangulations: Dict[str, Any]
    camera_positions: List[Tuple[Any, Any]]
    offset: np.ndarray
    model_to_local: Any


def _control_points(rec, lookup, images: _Images, control: Control, xyz, rows: _ObservationRows,
                    gcp_pixel_sigma: float):
    """Append the control points (position priors and their observations) to the points and rows."""
    ba_points, tri, offset = control.points, control.triangulations, control.offset
    n_tie = len(xyz)
    prior = np.full((n_tie + len(ba_points), 3), np.nan)
    prior_s = np.ones((n_tie + len(ba_points), 3))
    gcp_index: Dict[str, int] = {}
    gcp_obs_rows: Dict[str, List[Tuple[int, str]]] = {}
    for p in ba_points:
        k = len(xyz)
        gcp_index[p.name] = k
        xyz.append(control.model_to_local.apply(tri[p.name].xyz))
        prior[k] = np.array([p.x, p.y, p.z]) - offset
        prior_s[k] = [p.sigma_xy, p.sigma_xy, p.sigma_z]
        own = []
        t = tri[p.name]
        for j, ob in enumerate(p.observations):
            im = lookup.get(ob.image)
            if im is None or j in t.rejected or outside_image(rec.cameras[im.camera_id], ob):
                continue
            own.append((len(rows.img), ob.image))
            rows.img.append(images.img_index[im.image_id])
            rows.pt.append(k)
            rows.xy.append([ob.x, ob.y])
            rows.sigma.append(gcp_pixel_sigma)
            rows.robust.append(False)
        gcp_obs_rows[p.name] = own
    if np.any(prior_s <= 0):
        raise GeorefError("control point sigmas must be positive")
    return prior, prior_s, gcp_index, gcp_obs_rows


def _camera_priors(images: _Images, cam_pos, offset):
    cp_img = [images.img_index[im.image_id] for _, im in cam_pos]
    # a position without a height: Z residual 0 with a huge sigma, i.e. X and Y only
    cp_xyz = [np.array([cp.x, cp.y, cp.z if math.isfinite(cp.z) else offset[2]]) - offset for cp, _ in cam_pos]
    cp_sig = [[cp.sigma_xy, cp.sigma_xy, cp.sigma_z if math.isfinite(cp.z) else 1e12] for cp, _ in cam_pos]
    if np.any(np.asarray(cp_sig, dtype=float) <= 0):
        raise GeorefError("camera position sigmas must be positive")
    return cp_img, np.asarray(cp_xyz).reshape(-1, 3), np.asarray(cp_sig).reshape(-1, 3)


def build_problem(rec, lookup, control: Control, opt: GeorefOptions, warn: Callable[[str], None], progress=None):
    """The adjustment of ``rec`` (local frame) with the control points and camera positions of ``control``, the
    sigmas, robust loss, tie point budget and intrinsics to refine of ``opt`` (its ``camera_intrinsics``: camera
    id -> the alignment's record of its interior orientation, see _free_intrinsics).  Returns the problem, the
    tie point ids (rows of ``prob.X``), each control point's row and observation rows, and figures of the
    problem."""
    progress = progress or NullProgress()
    groups = opt.intrinsic_groups()
    ba_points, cam_pos = control.points, control.camera_positions
    images = _index_images(rec)
    cameras, cam_free, refined, priors, fixed = _free_intrinsics(rec, images, groups, opt.min_intrinsics_images, warn,
                                                                 opt.camera_intrinsics)
    if fixed:
        progress.info(f"camera(s) {', '.join(str(c) for c in fixed)}: calibrated interior orientation fixed, not "
                      f"refined{' (whatever refine_intrinsics says)' if groups else ''}")
    if priors:
        progress.info(f"camera(s) {', '.join(str(images.camera_ids[k]) for k in priors)}: interior orientation "
                      "refined with priors at the calibration's values (weighted by its sigmas)")
    tracks, tie_ids, xyz, rows = _tie_points(rec, images, opt.max_observations, opt.tie_pixel_sigma)
    n_tie, n_tie_obs = len(xyz), len(rows.img)
    total_obs = sum(len(v) for v in tracks.values())
    prior, prior_s, gcp_index, gcp_obs_rows = _control_points(rec, lookup, images, control, xyz, rows,
                                                              opt.gcp_pixel_sigma)
    obs = Observations(np.asarray(rows.img, dtype=int), np.asarray(rows.pt, dtype=int),
                       np.asarray(rows.xy, dtype=float).reshape(-1, 2), np.asarray(rows.sigma, dtype=float),
                       np.asarray(rows.robust, dtype=bool), np.ones(len(rows.img), dtype=bool))
    frames = Frames(np.asarray(images.frames_r).reshape(-1, 3, 3), np.asarray(images.frames_c).reshape(-1, 3),
                    images.img_frame, images.img_cam, np.asarray(images.img_rs).reshape(-1, 3, 3),
                    np.asarray(images.img_ts).reshape(-1, 3))
    prob = BundleProblem(frames, Intrinsics(cameras, cam_free, opt.focal_prior, priors),
                         Points(np.asarray(xyz).reshape(-1, 3), prior, prior_s), obs,
                         CameraPriors(*_camera_priors(images, cam_pos, control.offset)), opt.huber_px)
    prob.cam_pos_images = [cp.image for cp, _ in cam_pos]
    info = {"images": len(images.reg_ids), "frames": len(images.frame_ids), "cameras": len(images.camera_ids),
            "tie_points_total": len(tracks), "tie_observations_total": total_obs,
            "tie_points_adjusted": n_tie, "tie_observations_adjusted": n_tie_obs,
            "control_points_adjusted": len(ba_points), "camera_priors": len(cam_pos),
            "subsampled": n_tie < len(tracks), "refined_cameras": refined, "fixed_cameras": fixed,
            "prior_cameras": [images.camera_ids[k] for k in priors],
            "_frame_ids": images.frame_ids, "_camera_ids": images.camera_ids}
    if n_tie < len(tracks):
        progress.info(f"adjusting {n_tie} of {len(tracks)} tie points ({n_tie_obs} of {total_obs} "
                      "observations); the others are re-triangulated afterwards")
    return prob, tie_ids, gcp_index, gcp_obs_rows, info


def set_point_active(prob: BundleProblem, k: int, rows, active: bool) -> None:
    """Switch a GCP (its position prior and its observations) on or off in the adjustment."""
    prob.has_pp[k] = active and bool(np.all(np.isfinite(prob.pp[k])))
    for r, _ in rows:
        prob.obs.active[r] = active


def write_back(rec, prob: BundleProblem, tie_ids, frame_ids, camera_ids) -> None:
    pycolmap = require("pycolmap", "writing the adjusted model")
    for k, fid in enumerate(frame_ids):
        r = prob.R[k]
        rec.frame(fid).rig_from_world = pycolmap.Rigid3d(pycolmap.Rotation3d(r), -r @ prob.C[k])
    for cid, cam in zip(camera_ids, prob.cameras):
        rec.cameras[cid].params = np.asarray(cam.params, dtype=float)
    pts = rec.points3D
    for k, pid in enumerate(tie_ids):
        pts[int(pid)].xyz = prob.X[k]



__all__ = ["BundleProblem", "CameraPriors", "Control", "Frames", "Intrinsics", "Observations", "Points",
           "build_problem", "huber_weights", "intrinsics_jacobian", "inv3",
           "outside_image", "pose_point_jacobians", "project", "project_jacobian", "select_tie_points",
           "set_point_active", "write_back"]
