"""Precision of a bundle-adjusted block: covariance from the Jacobian of the adjustment.

For the report (``core.report``) and its GeoPackage layers.  The model is linearised at the adjusted
solution (the georeferenced model ``georef/model`` in the local frame, or the aligned model) with the
same observations and weights the georeferencing adjustment used (``core.georef``):

- tie-point observations, sigma ``tie_sigma_px`` (1 px), Huber weights beyond ``huber_px`` (2 px) (the fields of
  :class:`CovarianceOptions`);
- control-point observations, sigma ``gcp_sigma_px`` (1 px), and the control coordinates as priors with
  their sigma XY / Z (raised to 1 m in Z for placeholder heights, as ``core.georef`` does);
- camera projection-centre priors with their sigmas (EXIF GPS: 3 m / 5 m; a positions file: its sigmas).

Unknowns: per image a rotation increment (camera axes) and its projection centre; per camera (group) the
refined intrinsic parameters; per point its position.  The normal matrix is reduced to the camera
parameters by a Schur complement on the 3x3 point blocks, inverted densely, and the point covariances are
recovered from it (``Q_pp = N_pp^-1 + N_pp^-1 N_pc Q_cc N_cp N_pp^-1``).  Everything is scaled by the a
posteriori variance factor sigma0^2 (weighted residual sum of squares / redundancy).

Datum: with control points or camera positions the datum is the control's (absolute precision in the
CRS).  Without them (an aligned block only) the 7-parameter datum defect is removed by a generalised
inverse (the eigenvectors of the 7 smallest eigenvalues of the scaled reduced system are dropped): the
intrinsic parameters' standard deviations are then datum-free, positions are in the arbitrary model
frame and units ("free network").

Why not ``pycolmap.estimate_ba_covariance``: it needs a Ceres problem built by pycolmap's own bundle
adjusters, which have no prior on a 3-D point (GCPs), so it cannot give the precision of a
GCP-controlled block.  Without control the two agree (tests/test_report.py compares the intrinsics'
standard deviations with ``estimate_ba_covariance`` to 0.1 %).  The projection, its derivatives (analytic for
the rigid part, central differences through pycolmap's camera model, ``Camera.img_from_cam``, so every COLMAP
camera model works) and the Huber weights are the adjustment's own (``core.georef.bundle``).

Simplifications, stated in the result's ``notes``: each image has its own pose (rigs are treated as
independent cameras), the intrinsics' covariance is that of the parameters marked free, and beyond
``max_observations`` tie-point observations only the best-observed points enter (every image covered):
the precision is then slightly pessimistic and the points left out get no covariance.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.gcp import read_camera_positions
from ..io.vector import write_points_gpkg
from ..project.layout import Layout, read_json
from ..project.stages import GEOREFERENCE
from .bundle import huber_weights, intrinsics_jacobian, inv3, pose_point_jacobians, project, project_jacobian
from .options import EXIF_SIGMA_XY, EXIF_SIGMA_Z, FILE_POSITION_SIGMAS, PLACEHOLDER_SIGMA_Z

DATUM_CONTROL = "control"
DATUM_FREE = "free network"
FREE_DATUM_DEFECT = 7


class UncertaintyError(ArchaeoOrthoError, RuntimeError):
    """The covariance cannot be computed; the message says why."""


@dataclass
class ControlInput:
    """A control point in the adjustment: adjusted position (local frame), sigma XYZ and observations."""

    name: str
    xyz: np.ndarray
    sigma: np.ndarray  # (3,)
    given: np.ndarray  # given coordinates (local frame), for the prior residual
    observations: List[Tuple[str, float, float]]  # (image name, x px, y px)


@dataclass(frozen=True)
class CovarianceOptions:
    """The observations' precision and the problem's limits: tie point and control point observations' sigmas
    (pixels), the Huber threshold (pixels), at most ``max_observations`` tie point observations (the best observed
    points), at most ``max_unknowns`` camera unknowns (the reduced system is dense)."""

    tie_sigma_px: float = 1.0
    gcp_sigma_px: float = 1.0
    huber_px: float = 2.0
    max_observations: int = 300_000
    max_unknowns: int = 6000


@dataclass
class CameraPrior:
    image: str
    xyz: np.ndarray  # given projection centre (local frame); NaN z = XY only
    sigma: np.ndarray  # (3,)


@dataclass
class Observations:
    """Every tie-point observation of a reconstruction with its reprojection residual."""

    image_ids: np.ndarray  # (I,) registered image ids, sorted
    image_names: List[str]
    img: np.ndarray  # (O,) index into image_ids
    pt: np.ndarray  # (O,) index into point_ids
    xy: np.ndarray  # (O, 2) observed pixel
    residual: np.ndarray  # (O, 2) projected - observed, pixels (NaN behind the camera)
    point_ids: np.ndarray  # (P,) point3D ids
    xyz: np.ndarray  # (P, 3)
    track_length: np.ndarray  # (P,)

    @property
    def error(self) -> np.ndarray:
        return np.linalg.norm(self.residual, axis=1)


@dataclass
class UncertaintyResult:
    datum: str
    sigma0: float  # a posteriori standard deviation of unit weight
    redundancy: int
    n_observations: int  # image observations (tie + control) used
    n_points: int
    cameras: List[Dict[str, Any]]  # image, camera_id, x, y, z, sx, sy, sz (m), s_rx, s_ry, s_rz (deg)
    intrinsics: Dict[int, Dict[str, Any]]  # camera_id -> model, names, values, std (None = held fixed)
    point_ids: np.ndarray
    point_xyz: np.ndarray  # (P, 3) local frame (or model frame)
    point_std: np.ndarray  # (P, 3)
    control: List[Dict[str, Any]]  # name, sx, sy, sz
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))
    notes: List[str] = field(default_factory=list)
    seconds: float = 0.0
    n_control: int = 0  # control points that entered as priors
    n_camera_priors: int = 0  # cameras with a position prior

    def datum_text(self) -> str:
        if self.datum == DATUM_FREE and not (self.n_control or self.n_camera_priors):
            return "free network (no control): positions in the arbitrary model frame"
        src = []
        if self.n_control:
            src.append(f"{self.n_control} control point(s)")
        if self.n_camera_priors:
            src.append(f"{self.n_camera_priors} camera position(s)")
        return " and ".join(src) + (" (singular: generalised inverse)" if self.datum == DATUM_FREE else "")

    def summary(self) -> Dict[str, Any]:
        cs = np.array([[c["sx"], c["sy"], c["sz"]] for c in self.cameras], dtype=float).reshape(-1, 3)
        ps = self.point_std
        h = np.hypot(ps[:, 0], ps[:, 1]) if len(ps) else np.zeros(0)
        return {
            "datum": self.datum, "sigma0": self.sigma0, "redundancy": self.redundancy,
            "camera_std_xy_median": float(np.median(np.hypot(cs[:, 0], cs[:, 1]))) if len(cs) else None,
            "camera_std_z_median": float(np.median(cs[:, 2])) if len(cs) else None,
            "point_std_xy_median": float(np.median(h)) if len(h) else None,
            "point_std_z_median": float(np.median(ps[:, 2])) if len(ps) else None,
            "point_std_xy_p95": float(np.percentile(h, 95)) if len(h) else None,
            "point_std_z_p95": float(np.percentile(ps[:, 2], 95)) if len(ps) else None,
            "points": int(len(ps)), "seconds": self.seconds,
        }


# --------------------------------------------------------------------------------------------------
# observations and residuals
# --------------------------------------------------------------------------------------------------

def collect_observations(rec) -> Observations:
    """Tie-point observations of every registered image of a pycolmap.Reconstruction, with residuals."""
    image_ids = np.array(sorted(int(i) for i in rec.reg_image_ids()), dtype=np.int64)
    names = [rec.image(int(i)).name for i in image_ids]
    pids, xyz, tl = [], [], []
    for pid, p in rec.points3D.items():
        pids.append(int(pid))
        xyz.append(np.asarray(p.xyz, dtype=float))
        tl.append(int(p.track.length()))
    index = {pid: k for k, pid in enumerate(pids)}
    o_img, o_pt, o_xy, o_res = [], [], [], []
    xyz_a = np.asarray(xyz, dtype=float).reshape(-1, 3)
    for k, iid in enumerate(image_ids):
        im = rec.image(int(iid))
        obs = im.get_observation_points2D()
        if not len(obs):
            continue
        pt = np.array([index[int(p2.point3D_id)] for p2 in obs], dtype=np.int64)
        xy = np.array([p2.xy for p2 in obs], dtype=float).reshape(-1, 2)
        m = np.asarray(im.cam_from_world().matrix())
        xc = xyz_a[pt] @ m[:, :3].T + m[:, 3]
        uv = project(rec.cameras[im.camera_id], xc)
        res = uv - xy
        res[xc[:, 2] <= 0] = np.nan
        o_img.append(np.full(len(pt), k, dtype=np.int64))
        o_pt.append(pt)
        o_xy.append(xy)
        o_res.append(res)

    def cat(parts, shape):
        return np.concatenate(parts) if parts else np.zeros(shape)

    return Observations(image_ids, names, cat(o_img, (0,)).astype(np.int64), cat(o_pt, (0,)).astype(np.int64),
                        cat(o_xy, (0, 2)), cat(o_res, (0, 2)), np.asarray(pids, dtype=np.int64), xyz_a,
                        np.asarray(tl, dtype=np.int64))


# --------------------------------------------------------------------------------------------------
# the covariance
# --------------------------------------------------------------------------------------------------

def default_free_intrinsics(rec, principal_point: bool = False) -> Dict[int, List[int]]:
    """Focal length(s) and distortion of every camera; the principal point too when it was refined."""
    out = {}
    for cid, cam in rec.cameras.items():
        idx = list(cam.focal_length_idxs()) + list(cam.extra_params_idxs())
        if principal_point:
            idx += list(cam.principal_point_idxs())
        out[int(cid)] = sorted(set(int(i) for i in idx))
    return out


def _select_points(obs: Observations, ok: np.ndarray, max_observations: int) -> np.ndarray:
    """Mask of points kept: all when few enough observations, else longest tracks first, every image kept."""
    n_obs_pt = np.bincount(obs.pt[ok], minlength=len(obs.point_ids))
    keep = n_obs_pt >= 2
    if int(n_obs_pt[keep].sum()) <= max_observations:
        return keep
    order = np.argsort(-n_obs_pt, kind="stable")
    chosen = np.zeros(len(keep), dtype=bool)
    total = 0
    for k in order:
        if n_obs_pt[k] < 2 or total + n_obs_pt[k] > max_observations:
            continue
        chosen[k] = True
        total += int(n_obs_pt[k])
    return chosen


@dataclass
class _Rows:
    """The observations that enter the covariance: tie points (selected) and control points with priors."""

    img: np.ndarray  # (O,) index into the images
    pt: np.ndarray  # (O,) index into xyz
    res: np.ndarray  # (O, 2) pixel residuals
    sigma: np.ndarray  # (O,)
    robust: np.ndarray  # (O,) Huber (tie points)
    xyz: np.ndarray  # (P, 3): the tie points, then the control points
    n_tie: int
    keep_pt: np.ndarray  # mask of the tie points of the Observations that entered
    prior_idx: List[int] = field(default_factory=list)
    prior_xyz: List[np.ndarray] = field(default_factory=list)
    prior_sig: List[np.ndarray] = field(default_factory=list)
    control_rows: List[Tuple[str, int]] = field(default_factory=list)  # (name, row in xyz)


def _tie_rows(obs: Observations, max_observations: int, tie_sigma_px: float, notes: List[str]) -> _Rows:
    """Tie observations with finite residuals, of the points selected (all, or the best observed)."""
    ok = np.isfinite(obs.error)
    keep_pt = _select_points(obs, ok, max_observations)
    if not keep_pt.all():
        notes.append(f"{int(keep_pt.sum())} of {len(keep_pt)} tie points (the best observed) entered the "
                     "covariance; the others have no standard deviation")
    sel = ok & keep_pt[obs.pt]
    pt_new = np.full(len(obs.point_ids), -1, dtype=np.int64)
    pt_new[keep_pt] = np.arange(int(keep_pt.sum()))
    o_img = obs.img[sel]
    xyz = obs.xyz[keep_pt].copy()
    return _Rows(o_img, pt_new[obs.pt[sel]], obs.residual[sel], np.full(len(o_img), float(tie_sigma_px)),
                 np.ones(len(o_img), dtype=bool), xyz, len(xyz), keep_pt)


def _add_control(rec, rows: _Rows, control: Sequence[ControlInput], images, img_index: Dict[str, int],
                 gcp_sigma_px: float) -> None:
    """Control points: extra points with priors and their own observations (those not connected: left out)."""
    c_img, c_pt, c_res = [], [], []
    for c in control:
        k = len(rows.xyz)
        own = []
        for name, x, y in c.observations:
            j = img_index.get(name)
            if j is None:
                continue
            im = images[j]
            m = np.asarray(im.cam_from_world().matrix())
            xc = m[:, :3] @ c.xyz + m[:, 3]
            if xc[2] <= 0:
                continue
            uv = project(rec.cameras[im.camera_id], xc[None])[0]
            own.append((j, uv - np.array([x, y])))
        if not own:  # not connected to the block
            continue
        rows.xyz = np.vstack([rows.xyz, np.asarray(c.xyz, dtype=float)[None]])
        for j, r in own:
            c_img.append(j)
            c_pt.append(k)
            c_res.append(r)
        rows.prior_idx.append(k)
        rows.prior_xyz.append(np.asarray(c.given, dtype=float))
        rows.prior_sig.append(np.asarray(c.sigma, dtype=float))
        rows.control_rows.append((c.name, k))
    if c_img:
        rows.img = np.concatenate([rows.img, np.asarray(c_img, dtype=np.int64)])
        rows.pt = np.concatenate([rows.pt, np.asarray(c_pt, dtype=np.int64)])
        rows.res = np.vstack([rows.res, np.asarray(c_res, dtype=float)])
        rows.sigma = np.concatenate([rows.sigma, np.full(len(c_img), float(gcp_sigma_px))])
        rows.robust = np.concatenate([rows.robust, np.zeros(len(c_img), dtype=bool)])


def _weights(rows: _Rows, huber_px: float) -> Tuple[np.ndarray, np.ndarray]:
    """(Huber weight, sqrt of the weight of each residual component) per observation, as in the adjustment."""
    s = np.linalg.norm(rows.res, axis=1) / rows.sigma
    w = huber_weights(s, rows.robust, huber_px)
    return w, np.sqrt(w) / rows.sigma


def _jacobians(rec, images, rows: _Rows, free: Dict[int, List[int]], intr_off: Dict[int, int], sw: np.ndarray,
               progress: Progress):
    """Weighted Jacobian blocks per observation (the bundle problem's, core.georef.bundle): camera
    (pose + intrinsics, with their columns) and point."""
    n_o, n_img = len(rows.img), len(images)
    q_max = max((len(v) for v in free.values()), default=0)
    jc = np.zeros((n_o, 2, 6 + q_max))
    jp = np.zeros((n_o, 2, 3))
    cam_cols = np.zeros((n_o, 6 + q_max), dtype=np.int64)
    n_cols = np.zeros(n_o, dtype=np.int64)
    order = np.argsort(rows.img, kind="stable")
    bounds = np.searchsorted(rows.img[order], np.arange(n_img + 1))
    for j in range(n_img):
        sel = order[bounds[j]:bounds[j + 1]]
        if not len(sel):
            continue
        check_cancel(progress)
        im = images[j]
        cam = rec.cameras[im.camera_id]
        m = np.asarray(im.cam_from_world().matrix())
        r = m[:, :3]
        xc = rows.xyz[rows.pt[sel]] @ r.T + m[:, 3]
        jpi = project_jacobian(cam, xc)
        # each image its own pose (sensor = rig): the camera-frame point is the rig-frame point
        n = len(sel)
        j_rot, j_c, j_pt = pose_point_jacobians(jpi, np.broadcast_to(np.eye(3), (n, 3, 3)),
                                                np.broadcast_to(r, (n, 3, 3)), xc)
        jc[sel, :, 0:3] = j_rot
        jc[sel, :, 3:6] = j_c
        jp[sel] = j_pt
        fr = free[int(im.camera_id)]
        cols = list(range(6 * j, 6 * j + 6))
        if fr:
            jc[sel, :, 6:6 + len(fr)] = intrinsics_jacobian(cam, xc, fr)
            cols += list(range(intr_off[int(im.camera_id)], intr_off[int(im.camera_id)] + len(fr)))
        cam_cols[sel, :len(cols)] = cols
        n_cols[sel] = len(cols)
    jc *= sw[:, None, None]
    jp *= sw[:, None, None]
    return _Jacobians(jc, jp, cam_cols, n_cols)


@dataclass
class _Jacobians:
    """The weighted observation Jacobian: camera part (O, 2, width) with each row's camera columns and their
    number, point part (O, 2, 3)."""

    jc: np.ndarray
    jp: np.ndarray
    cam_cols: np.ndarray
    n_cols: np.ndarray


@dataclass
class _Normals:
    ncc: np.ndarray  # (nc, nc) dense
    ncp: Any  # (nc, 3P) sparse
    npp: np.ndarray  # (P, 3, 3)
    prior_res: List[np.ndarray]
    n_cam_prior_comp: int
    cams_with_prior: set
    centres: np.ndarray  # (I, 3) projection centres


def _normals(rows: _Rows, images, img_index, jac: _Jacobians, nc: int, camera_priors: Sequence[CameraPrior]
             ) -> _Normals:
    """The normal equations, with the control-point and camera-position priors."""
    import scipy.sparse as sp

    jc, jp, cam_cols, n_cols = jac.jc, jac.jp, jac.cam_cols, jac.n_cols
    n_o, n_pts = len(rows.img), len(rows.xyz)
    width = jc.shape[2]
    valid = np.arange(width)[None, :] < n_cols[:, None]  # (O, width)
    row_id = (2 * np.arange(n_o))[:, None, None] + np.arange(2)[None, :, None]
    rr = np.broadcast_to(row_id, (n_o, 2, width))
    cc = np.broadcast_to(cam_cols[:, None, :], (n_o, 2, width))
    vm = np.broadcast_to(valid[:, None, :], (n_o, 2, width))
    jc_s = sp.csr_matrix((jc[vm], (rr[vm], cc[vm])), shape=(2 * n_o, nc))
    pr = np.broadcast_to(row_id, (n_o, 2, 3))
    pc = np.broadcast_to((3 * rows.pt)[:, None, None] + np.arange(3)[None, None, :], (n_o, 2, 3))
    jp_s = sp.csr_matrix((jp.ravel(), (pr.ravel(), pc.ravel())), shape=(2 * n_o, 3 * n_pts))
    ncc = (jc_s.T @ jc_s).toarray()
    ncp = (jc_s.T @ jp_s).tocsr()
    npp = np.zeros((n_pts, 3, 3))
    np.add.at(npp, rows.pt, np.einsum("nki,nkj->nij", jp, jp))
    prior_res = []
    if rows.prior_idx:
        pi = np.asarray(rows.prior_idx)
        ps = np.asarray(rows.prior_sig)
        npp[pi] += np.einsum("ni,ij->nij", 1.0 / ps ** 2, np.eye(3))
        prior_res.append(((rows.xyz[pi] - np.asarray(rows.prior_xyz)) / ps).ravel())
    n_cam_prior_comp = 0
    cams_with_prior = set()
    centres = np.array([np.asarray(im.projection_center(), dtype=float) for im in images])
    for cp in camera_priors:
        j = img_index.get(cp.image)
        if j is None:
            continue
        for a in range(3):
            if math.isfinite(float(cp.xyz[a])) and math.isfinite(float(cp.sigma[a])) and cp.sigma[a] > 0:
                ncc[6 * j + 3 + a, 6 * j + 3 + a] += 1.0 / cp.sigma[a] ** 2
                prior_res.append(np.array([(centres[j, a] - cp.xyz[a]) / cp.sigma[a]]))
                n_cam_prior_comp += 1
                cams_with_prior.add(j)
    return _Normals(ncc, ncp, npp, prior_res, n_cam_prior_comp, cams_with_prior, centres)


def _reduce(nrm: _Normals):
    """Schur complement on the 3x3 point blocks: (reduced camera system, N_pp^-1, points that cannot be
    estimated: seen only once and without a prior)."""
    import scipy.sparse as sp

    n_pts = len(nrm.npp)
    npp_inv = inv3(nrm.npp)
    bad = ~np.all(np.isfinite(npp_inv.reshape(n_pts, -1)), axis=1)
    if np.any(bad):
        npp_inv[bad] = 0.0
    bi = (3 * np.arange(n_pts))[:, None, None] + np.arange(3)[None, :, None] + np.zeros((1, 1, 3), dtype=np.int64)
    nppi_s = sp.csr_matrix((npp_inv.ravel(), (bi.ravel(), np.swapaxes(bi, 1, 2).ravel())),
                           shape=(3 * n_pts, 3 * n_pts))
    s_mat = nrm.ncc - (nrm.ncp @ nppi_s @ nrm.ncp.T).toarray()
    return 0.5 * (s_mat + s_mat.T), npp_inv, bad


def _invert(s_mat: np.ndarray, has_datum: bool, notes: List[str]) -> Tuple[np.ndarray, str, int]:
    """(Q_cc, datum, datum defect): Cholesky with the control's datum, else a generalised inverse."""
    nc = len(s_mat)
    d = np.sqrt(np.maximum(np.diag(s_mat), 1e-300))
    s_scaled = s_mat / d[:, None] / d[None, :]
    datum = DATUM_CONTROL
    defect = 0
    q_cc = None
    if has_datum:
        try:
            from scipy.linalg import cho_factor, cho_solve

            f = cho_factor(s_scaled, lower=True)
            q_cc = cho_solve(f, np.eye(nc))
        except np.linalg.LinAlgError:
            notes.append("the reduced normal matrix is singular with the control given: free-network inverse")
    if q_cc is None:
        evals, evecs = np.linalg.eigh(s_scaled)
        defect = FREE_DATUM_DEFECT if not has_datum else int(np.sum(evals < 1e-10 * evals[-1]))
        keep = np.arange(nc) >= defect
        q_cc = (evecs[:, keep] / evals[keep]) @ evecs[:, keep].T
        datum = DATUM_FREE
        if not has_datum:
            notes.append("no control points or camera positions: free-network precision (datum defect 7 removed "
                         "by a generalised inverse); positions are in the model frame")
    return q_cc / d[:, None] / d[None, :], datum, defect


def _camera_rows(images, centres: np.ndarray, q_cc: np.ndarray, var0: float) -> List[Dict[str, Any]]:
    cameras = []
    for j, im in enumerate(images):
        blk = q_cc[6 * j:6 * j + 6, 6 * j:6 * j + 6] * var0
        sd = np.sqrt(np.maximum(np.diag(blk), 0.0))
        c = centres[j]
        cameras.append({"image": im.name, "camera_id": int(im.camera_id), "x": float(c[0]), "y": float(c[1]),
                        "z": float(c[2]), "sx": float(sd[3]), "sy": float(sd[4]), "sz": float(sd[5]),
                        "s_rx": math.degrees(sd[0]), "s_ry": math.degrees(sd[1]), "s_rz": math.degrees(sd[2])})
    return cameras


def _intrinsic_rows(rec, images, cam_ids, free, intr_off, q_cc: np.ndarray, var0: float) -> Dict[int, Dict[str, Any]]:
    intr = {}
    for cid in cam_ids:
        cam = rec.cameras[cid]
        names = [n.strip() for n in str(cam.params_info).split(",")]
        std: List[Optional[float]] = [None] * len(cam.params)
        o = intr_off[cid]
        for k, pidx in enumerate(free[cid]):
            std[pidx] = float(math.sqrt(max(q_cc[o + k, o + k] * var0, 0.0)))
        intr[cid] = {"model": cam.model.name, "width": int(cam.width), "height": int(cam.height),
                     "names": names, "values": [float(v) for v in cam.params], "std": std,
                     "images": sum(1 for im in images if int(im.camera_id) == cid)}
    return intr


def _point_std(nrm: _Normals, npp_inv: np.ndarray, bad: np.ndarray, q_cc: np.ndarray, var0: float,
               progress: Progress) -> np.ndarray:
    """Q_pp = N^-1 + N^-1 T^T Q_cc T N^-1 with T = N_cp columns of the point, in chunks."""
    n_pts, nc = len(npp_inv), len(q_cc)
    pstd = np.full((n_pts, 3), np.nan)
    chunk = max(50, int(3e6 // max(nc, 1)) // 3)
    ncp_csc = nrm.ncp.tocsc()
    for a in range(0, n_pts, chunk):
        check_cancel(progress)
        b = min(n_pts, a + chunk)
        t = ncp_csc[:, 3 * a:3 * b].toarray()  # (nc, 3m)
        g = q_cc @ t
        m_ = b - a
        core = np.einsum("kmi,kmj->mij", t.reshape(nc, m_, 3), g.reshape(nc, m_, 3))
        ni = npp_inv[a:b]
        q = ni + ni @ core @ ni
        pstd[a:b] = np.sqrt(np.maximum(np.einsum("nii->ni", q), 0.0) * var0)
    pstd[bad] = np.nan
    return pstd


def _camera_unknowns(cam_ids, free: Dict[int, List[int]], n_img: int) -> Tuple[int, Dict[int, int]]:
    """Number of camera unknowns (6 per image, then the free intrinsics per camera) and each camera's column."""
    intr_off = {}
    nc = 6 * n_img
    for cid in cam_ids:
        intr_off[cid] = nc
        nc += len(free[cid])
    return nc, intr_off


def estimate(rec, control: Sequence[ControlInput] = (), camera_priors: Sequence[CameraPrior] = (),
             free_intrinsics: Optional[Dict[int, List[int]]] = None, options: Optional[CovarianceOptions] = None,
             offset=None, progress: Optional[Progress] = None, observations: Optional[Observations] = None
             ) -> UncertaintyResult:
    """Covariance of the cameras, intrinsics and points of an adjusted block (see the module docstring)."""
    t0 = time.time()
    progress = progress or NullProgress()
    opt = options or CovarianceOptions()
    notes: List[str] = []
    obs = observations if observations is not None else collect_observations(rec)
    n_img = len(obs.image_ids)
    if n_img < 2:
        raise UncertaintyError("the model has fewer than 2 registered images")
    img_index = {name: k for k, name in enumerate(obs.image_names)}
    images = [rec.image(int(i)) for i in obs.image_ids]
    cam_ids = sorted({int(im.camera_id) for im in images})
    free = free_intrinsics if free_intrinsics is not None else default_free_intrinsics(rec)
    free = {cid: list(free.get(cid, [])) for cid in cam_ids}
    nc, intr_off = _camera_unknowns(cam_ids, free, n_img)
    if nc > opt.max_unknowns:
        raise UncertaintyError(f"{nc} camera unknowns: more than the dense covariance handles here "
                               f"({opt.max_unknowns})")
    rows = _tie_rows(obs, opt.max_observations, opt.tie_sigma_px, notes)
    _add_control(rec, rows, control, images, img_index, opt.gcp_sigma_px)
    n_pts, n_o = len(rows.xyz), len(rows.img)
    w, sw = _weights(rows, opt.huber_px)
    progress.report(0.05, "covariance: Jacobian")
    jac = _jacobians(rec, images, rows, free, intr_off, sw, progress)
    progress.report(0.4, "covariance: normal equations")
    nrm = _normals(rows, images, img_index, jac, nc, camera_priors)
    s_mat, npp_inv, bad = _reduce(nrm)
    n_ctl = len(rows.prior_idx)
    ncp_comp = nrm.n_cam_prior_comp
    has_datum = n_ctl >= 3 or ncp_comp >= 7 or (n_ctl >= 1 and n_ctl * 3 + ncp_comp >= 7)
    progress.report(0.6, "covariance: inverting the reduced system")
    q_cc, datum, defect = _invert(s_mat, has_datum, notes)

    # variance factor
    wrss = float(np.sum(w * (np.linalg.norm(rows.res, axis=1) / rows.sigma) ** 2))
    if nrm.prior_res:
        wrss += float(np.sum(np.concatenate(nrm.prior_res) ** 2))
    n_eq = 2 * n_o + 3 * n_ctl + ncp_comp
    redundancy = int(n_eq - (nc + 3 * n_pts - 3 * int(bad.sum())) + defect)
    sigma0 = math.sqrt(wrss / redundancy) if redundancy > 0 else float("nan")
    var0 = sigma0 ** 2 if math.isfinite(sigma0) else 1.0
    if not math.isfinite(sigma0):
        notes.append("no redundancy: a priori precision (sigma0 = 1)")

    cameras = _camera_rows(images, nrm.centres, q_cc, var0)
    intr = _intrinsic_rows(rec, images, cam_ids, free, intr_off, q_cc, var0)
    progress.report(0.75, "covariance: points")
    pstd = _point_std(nrm, npp_inv, bad, q_cc, var0, progress)
    control_rows = [{"name": name, "sx": float(pstd[k, 0]), "sy": float(pstd[k, 1]), "sz": float(pstd[k, 2])}
                    for name, k in rows.control_rows]
    if any(len(free[c]) for c in cam_ids):
        notes.append("intrinsic parameters free: " + "; ".join(
            f"camera {c}: {', '.join(intr[c]['names'][i] for i in free[c]) or 'none'}" for c in cam_ids))
    if any(r.num_sensors() > 1 for r in rec.rigs.values()):
        notes.append("multi-camera rigs are treated as independent cameras")
    progress.report(1.0, "covariance done")
    n_tie = rows.n_tie
    return UncertaintyResult(
        datum=datum, sigma0=sigma0, redundancy=redundancy, n_observations=n_o, n_points=n_tie,
        cameras=cameras, intrinsics=intr, point_ids=obs.point_ids[rows.keep_pt], point_xyz=rows.xyz[:n_tie],
        point_std=pstd[:n_tie], control=control_rows,
        offset=np.zeros(3) if offset is None else np.asarray(offset, dtype=float), notes=notes,
        seconds=round(time.time() - t0, 3), n_control=n_ctl, n_camera_priors=len(nrm.cams_with_prior))


# --------------------------------------------------------------------------------------------------
# workspaces
# --------------------------------------------------------------------------------------------------

def workspace_inputs(ws, rec) -> Tuple[List[ControlInput], List[CameraPrior], Dict[int, List[int]], np.ndarray]:
    """Control, camera priors, free intrinsics and the local->world offset of a workspace's newest model.

    The georeferenced model when the georeference stage is done (priors from georef/residuals.json, their
    sigmas from the adjustment inputs the stage saved, georef/adjustment_inputs.json; a workspace from before
    that file: georef/control.json and the camera-positions file), else the aligned model without priors."""
    lay = Layout(ws)
    pp = bool(lay.alignment().get("principal_point_refined"))
    if not lay.is_georeferenced():
        return [], [], default_free_intrinsics(rec, pp), np.zeros(3)
    params = ws.stage(GEOREFERENCE).get("parameters", {}) or {}
    refine = params.get("refine_intrinsics")
    offset = lay.load_transform().offset
    residuals = lay.residuals() or {}
    inputs = read_json(lay.adjustment_inputs_json)
    control = _control_inputs(residuals, _control_sigmas(lay, inputs), offset)
    priors = _camera_priors(residuals, _camera_sigmas(inputs, params), offset)
    if refine == "all" or (isinstance(refine, (list, tuple)) and "principal_point" in refine):
        pp = True
    # intrinsics that stayed at their alignment values still get their precision in this block; a calibration
    # held fixed (core.align.calibrated) has none to get
    free = default_free_intrinsics(rec, pp)
    for cid, record in lay.camera_intrinsics().items():
        if record.get("mode") == "fixed" and cid in free:
            free[cid] = []
    return control, priors, free, offset


def _control_sigmas(lay: Layout, inputs: Optional[Dict[str, Any]]) -> Dict[str, Tuple[float, float]]:
    """name -> (sigma XY, sigma Z) of the ground control the adjustment used."""
    if inputs is not None:
        doc = inputs.get("gcps") or {}
    else:  # a workspace from before adjustment_inputs.json
        doc = read_json(lay.control_json) or {}
    return {p["name"]: (float(p.get("sigma_xy", 0.02)), float(p.get("sigma_z", 0.05)))
            for p in doc.get("points", [])}


def _camera_sigmas(inputs: Optional[Dict[str, Any]], params: Dict[str, Any]):
    """(image -> (sigma XY, sigma Z), default) of the camera positions the adjustment used."""
    default = FILE_POSITION_SIGMAS if params.get("camera_positions") else (EXIF_SIGMA_XY, EXIF_SIGMA_Z)
    if inputs is not None:
        return {c["image"]: (float(c["sigma_xy"]), float(c["sigma_z"]))
                for c in inputs.get("camera_positions") or []}, default
    sig: Dict[str, Tuple[float, float]] = {}
    if params.get("camera_positions"):  # a workspace from before adjustment_inputs.json: the user's file
        try:
            _, cps = read_camera_positions(params["camera_positions"])
            sig = {c.image: (c.sigma_xy, c.sigma_z) for c in cps}
        except (OSError, ValueError):
            sig = {}
    return sig, default


def _control_inputs(residuals: Dict[str, Any], sigmas: Dict[str, Tuple[float, float]],
                    offset: np.ndarray) -> List[ControlInput]:
    placeholder = (residuals.get("statistics") or {}).get("placeholder_z") is not None
    control = []
    for p in residuals.get("points", []):
        if p.get("status") != "used" or p.get("dx") is None:
            continue
        sxy, sz = sigmas.get(p["name"], (0.02, 0.05))
        if p.get("sigma_xy") is not None and p.get("sigma_z") is not None:  # the adjustment's (given or estimated)
            sxy, sz = float(p["sigma_xy"]), float(p["sigma_z"])
        if placeholder:
            sz = max(sz, PLACEHOLDER_SIGMA_Z)
        given = np.array([p["x"], p["y"], p["z"]], dtype=float) - offset
        adj = given + np.array([p["dx"], p["dy"], p["dz"]], dtype=float)
        obs = [(o["image"], float(o["x"]), float(o["y"])) for o in p.get("observations", [])
               if o.get("px") is not None]
        control.append(ControlInput(p["name"], adj, np.array([sxy, sxy, sz]), given, obs))
    return control


def _camera_priors(residuals: Dict[str, Any], sigmas, offset: np.ndarray) -> List[CameraPrior]:
    sig, default = sigmas
    priors = []
    for c in residuals.get("cameras", []):
        if not c.get("used", True):
            continue
        z = c.get("z")
        sxy, sz = sig.get(c["image"], default)
        if c.get("sigma_xy") is not None:  # the adjustment's (given, or estimated where the source gave none)
            sxy, sz = float(c["sigma_xy"]), float(c["sigma_z"]) if c.get("sigma_z") is not None else sz
        xyz = np.array([c["x"], c["y"], np.nan if z is None else z], dtype=float) - offset
        priors.append(CameraPrior(c["image"], xyz, np.array([sxy, sxy, sz], dtype=float)))
    return priors


def write_layers(result: UncertaintyResult, folder: str, crs: Optional[str]) -> Dict[str, str]:
    """cameras.gpkg and points.gpkg (standard deviations in metres / degrees) in ``folder``."""
    os.makedirs(folder, exist_ok=True)
    off = result.offset
    cam_rows = [dict(c, x=c["x"] + off[0], y=c["y"] + off[1], z=c["z"] + off[2]) for c in result.cameras]
    for r in cam_rows:
        r["sxy"] = float(math.hypot(r["sx"], r["sy"]))
    cam_fields = [("image", "str"), ("camera_id", "int"), ("sx", "float"), ("sy", "float"), ("sz", "float"),
                  ("sxy", "float"), ("s_rx", "float"), ("s_ry", "float"), ("s_rz", "float")]
    paths = {"cameras": write_points_gpkg(os.path.join(folder, "cameras.gpkg"), "camera_precision", cam_rows,
                                          cam_fields, crs)}
    xyz = result.point_xyz + off
    std = result.point_std
    ok = np.all(np.isfinite(std), axis=1)
    rows = [{"point_id": int(pid), "x": float(p[0]), "y": float(p[1]), "z": float(p[2]), "sx": float(s[0]),
             "sy": float(s[1]), "sz": float(s[2]), "sxy": float(math.hypot(s[0], s[1]))}
            for pid, p, s in zip(result.point_ids[ok], xyz[ok], std[ok])]
    pt_fields = [("point_id", "int"), ("sx", "float"), ("sy", "float"), ("sz", "float"), ("sxy", "float")]
    paths["points"] = write_points_gpkg(os.path.join(folder, "points.gpkg"), "point_precision", rows, pt_fields,
                                        crs)
    return paths


__all__ = ["CameraPrior", "ControlInput", "CovarianceOptions", "DATUM_CONTROL", "DATUM_FREE", "Observations",
           "UncertaintyError", "UncertaintyResult", "collect_observations", "default_free_intrinsics", "estimate",
           "workspace_inputs", "write_layers"]
