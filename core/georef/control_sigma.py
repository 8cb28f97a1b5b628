"""Control of unknown accuracy: the sigmas of control points and camera positions that came without them,
estimated from the data.

Archive control is read off maps or derived from an old orientation and a DEM, consumer GNSS sits in the
EXIF: metre-level, and the sources carry no sigma (``GroundPoint.sigma_given`` / ``CameraPosition.sigma_given``
False).  Weighted with a placeholder (0.02 m) such control bends the block to fit its errors; weighted with its
true accuracy it leaves the block as rigid as the data say.  Two steps (``core.georef.adjust`` runs them):

1. **From the rigid fit** (before the adjustment): the residuals v of the 7-parameter similarity (Helmert) of
   the block onto the control, divided by their redundancy numbers r = 1 - diag(A (A^T A)^-1 A^T) of that fit
   (A: its 3n x 7 design matrix), give sigma^2 = sum v^2 / sum r, for XY and Z separately.  Robust: the points
   the RANSAC left out do not count, and of the rest a point whose standardised residual v / sqrt(r) exceeds
   ``ROBUST_K`` x the MAD-based scale of all of them is left out of the estimate too (a wrong coordinate the
   outlier tests will name).  The residuals hold the block's own deformation as well: a bent block gives a
   larger sigma, the safe side (the block stays rigid).  ``lmeds_sigma`` (least median of squares over
   3-point fits) gives the scale before the RANSAC, for its inlier threshold.
2. **Variance components** (Förstner; Koch, Parameter Estimation and Hypothesis Testing, 4.2.4) after the
   adjustment: per group k (the control points without sigma, the camera positions without sigma; XY and Z
   each) the factor f_k = v_k^T P_k v_k / r_k with the group's redundancy r_k = sum over its observations of
   1 - a_i^T N^-1 a_i (a_i: the observation's weighted row of the adjustment's Jacobian, N its normal
   matrix; exact, by the adjustment's own Schur complement on the points).  sigma_k <- sigma_k sqrt(f_k), the
   adjustment is solved again, up to ``VCE_ITERATIONS`` times or until every factor is within
   ``VCE_TOLERANCE`` of 1.  The image observations (tie points and GCP marks) are a group too (their share of
   the redundancy: the total less the priors'): their pixel sigma follows its factor, so the control is
   weighted against the block's real image noise (0.3 px on a good block), not the a priori 1 px; kept at
   1 px, a block three times stiffer than modelled lets the control bend it cheaply, its residuals shrink and
   its sigma came out 3 to 4 times too small on the synthetic archive blocks.  The Huber threshold stays in
   pixels.  Where the block can follow the control (a soft mode: a long strip's sag,
   free intrinsics) the control's redundancy drops with its residuals and its sigma goes down; where it
   cannot, the residuals stay and so does the sigma.

Every estimate is floored at what the block itself resolves: the precision of the control points' forward
intersection at the tie points' own pixel noise (``intersection_precision`` with ``tie_point_sigma``, the a
posteriori sigma of the aligned block's tie points, at most the adjustment's pixel sigma; for camera positions,
the ground sample distance times that sigma).  Control finer than that cannot be told from the data and would
only make the block follow the image noise.

Control given with sigmas keeps them (the adjustment warns where the rigid block misses them by far).
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.similarity import Similarity, helmert_fit, skew
from .bundle import BundleProblem, inv3, project_jacobian

CONTROL_GROUP = "control points"
CAMERA_GROUP = "camera positions"
ROBUST_K = 4.0  # standardised residual beyond this many MAD-sigmas: left out of the estimate
MAD = 1.4826  # MAD -> sigma for a normal distribution
VCE_ITERATIONS = 8
VCE_TOLERANCE = 0.05  # |sqrt(f) - 1| below this for every group and component: converged
MIN_REDUNDANCY = 0.5  # a component with less redundancy keeps its value (nothing to estimate from)
LMEDS_SAMPLES = 500


@dataclass
class SigmaEstimate:
    """The estimated sigmas of one group (control points or camera positions without given sigmas)."""

    group: str  # CONTROL_GROUP or CAMERA_GROUP
    names: List[str]  # the members (point names or image names)
    sigma_xy: float
    sigma_z: float
    prior_xy: float  # the placeholders they had
    prior_z: float
    floor_xy: float
    floor_z: float
    helmert_xy: float = float("nan")  # step 1: from the rigid fit
    helmert_z: float = float("nan")
    redundancy_xy: float = 0.0  # of the rigid fit's estimate (sum of the redundancy numbers)
    redundancy_z: float = 0.0
    excluded: List[str] = field(default_factory=list)  # left out of step 1 as suspect (robust test)
    method: str = "helmert"  # "helmert", "helmert + variance components", "residuals"
    iterations: int = 0  # variance-component iterations
    factors: List[Tuple[float, float]] = field(default_factory=list)  # (f_xy, f_z) per iteration
    vce_redundancy: Tuple[float, float] = (0.0, 0.0)  # the group's redundancy in the adjustment (last)
    pixel_sigma: float = float("nan")  # the image observations' sigma (px) the adjustment ended with (VCE)
    note: str = ""

    def to_dict(self) -> Dict[str, Any]:
        return {"group": self.group, "n": len(self.names), "names": list(self.names),
                "sigma_xy_m": self.sigma_xy, "sigma_z_m": self.sigma_z, "prior_xy_m": self.prior_xy,
                "prior_z_m": self.prior_z, "floor_xy_m": self.floor_xy, "floor_z_m": self.floor_z,
                "helmert_xy_m": self.helmert_xy, "helmert_z_m": self.helmert_z,
                "redundancy_xy": self.redundancy_xy, "redundancy_z": self.redundancy_z,
                "excluded": list(self.excluded), "method": self.method, "iterations": self.iterations,
                "factors": [list(f) for f in self.factors], "vce_redundancy": list(self.vce_redundancy),
                "pixel_sigma": self.pixel_sigma, "note": self.note}

    def message(self) -> str:
        what = "control point(s)" if self.group == CONTROL_GROUP else "camera position(s)"
        how = ("from the rigid fit's residuals" if self.method == "helmert" else
               f"from the rigid fit's residuals, refined by variance components ({self.iterations} iteration(s))"
               if self.iterations else "from their residuals")
        floor = " (the block's own precision there)" if (self.sigma_xy <= self.floor_xy * 1.0001) else ""
        text = (f"{len(self.names)} {what} without sigma: accuracy estimated {how}: sigma XY {self.sigma_xy:.3g} m"
                f"{floor}, sigma Z {self.sigma_z:.3g} m (the placeholders were {self.prior_xy:g} / {self.prior_z:g} m)")
        if self.excluded:
            text += f"; left out of the estimate as suspect: {', '.join(self.excluded)}"
        if self.note:
            text += f"; {self.note}"
        return text


# --------------------------------------------------------------------------------------------------
# step 1: the rigid fit
# --------------------------------------------------------------------------------------------------

def lmeds_sigma(model: np.ndarray, world: np.ndarray, samples: int = LMEDS_SAMPLES, seed: int = 0) -> Optional[float]:
    """A robust per-axis sigma of ``world`` about a similarity of ``model`` (least median of squares): over
    3-point similarity fits (all, or ``samples`` random ones), the smallest median squared 3-D residual of the
    other points, as a sigma (median of chi-square with 3 degrees of freedom: 2.366).  Half the points may be
    wrong.  None with fewer than 4 points."""
    src = np.asarray(model, dtype=float).reshape(-1, 3)
    dst = np.asarray(world, dtype=float).reshape(-1, 3)
    n = len(src)
    if n < 4:
        return None
    if math.comb(n, 3) <= samples:
        triples = list(itertools.combinations(range(n), 3))
    else:
        rng = np.random.default_rng(seed)
        triples = [tuple(rng.choice(n, 3, replace=False)) for _ in range(samples)]
    best = math.inf
    for t in triples:
        sel = list(t)
        try:
            tr = helmert_fit(src[sel], dst[sel])
        except ValueError:
            continue
        others = np.setdiff1d(np.arange(n), sel)
        r2 = np.sum((dst[others] - tr.apply(src[others])) ** 2, axis=1)
        best = min(best, float(np.median(r2)))
    if not math.isfinite(best):
        return None
    return math.sqrt(best / 2.366)


def helmert_redundancy(fitted: np.ndarray) -> np.ndarray:
    """Redundancy numbers (n,3) of the coordinates in an unweighted 7-parameter similarity fit, at the fitted
    positions ``fitted`` (n,3): 1 - diag(A (A^T A)^-1 A^T) with A's rows d(position)/d(translation, small
    rotation, scale) about the centroid.  They sum to 3n - 7."""
    p = np.asarray(fitted, dtype=float).reshape(-1, 3)
    n = len(p)
    c = p - p.mean(axis=0)
    a = np.zeros((3 * n, 7))
    for i in range(n):
        a[3 * i:3 * i + 3, 0:3] = np.eye(3)
        a[3 * i:3 * i + 3, 3:6] = -skew(c[i])[0]
        a[3 * i:3 * i + 3, 6] = c[i]
    h = np.einsum("ij,jk,ik->i", a, np.linalg.pinv(a.T @ a), a)
    return np.clip(1.0 - h, 0.0, 1.0).reshape(n, 3)


def robust_sigma(v: np.ndarray, r: np.ndarray, names: Sequence[str], floor: Tuple[float, float]
                 ) -> Tuple[float, float, float, float, List[str], str]:
    """sigma XY, sigma Z (unfloored) from residuals ``v`` (n,3) with redundancy numbers ``r`` (n,3), their
    redundancies, the points left out as suspect and the method.  A point whose standardised residual exceeds
    ROBUST_K x the MAD scale (at least ``floor``) in XY or Z is left out (at most a third of them)."""
    v = np.asarray(v, dtype=float).reshape(-1, 3)
    r = np.asarray(r, dtype=float).reshape(-1, 3)
    v = np.where(r > 1e-3, v, 0.0)  # a coordinate without redundancy (or without a value) says nothing
    w = v / np.sqrt(np.maximum(r, 1e-3))
    wxy, wz = np.abs(w[:, :2])[r[:, :2] > 1e-3], np.abs(w[:, 2])[r[:, 2] > 1e-3]
    s_xy = max(MAD * float(np.median(wxy)) if len(wxy) else 0.0, floor[0], 1e-12)
    s_z = max(MAD * float(np.median(wz)) if len(wz) else 0.0, floor[1], 1e-12)
    bad = (np.max(np.abs(w[:, :2]), axis=1) > ROBUST_K * s_xy) | (np.abs(w[:, 2]) > ROBUST_K * s_z)
    if 3 * int(bad.sum()) > len(v):
        bad[:] = False
    keep = ~bad
    rxy, rz = float(r[keep, :2].sum()), float(r[keep, 2].sum())
    sxy2 = float(np.sum(v[keep, :2] ** 2))
    sz2 = float(np.sum(v[keep, 2] ** 2))
    method = "helmert"
    if rxy + rz < MIN_REDUNDANCY:  # no redundancy: the residuals themselves
        m = max(int(keep.sum()), 1)
        return (math.sqrt(sxy2 / (2 * m)), math.sqrt(sz2 / m), rxy, rz,
                [nm for nm, b in zip(names, bad) if b], "residuals")
    pooled = math.sqrt((sxy2 + sz2) / (rxy + rz))
    sig_xy = math.sqrt(sxy2 / rxy) if rxy >= MIN_REDUNDANCY else pooled
    sig_z = math.sqrt(sz2 / rz) if rz >= MIN_REDUNDANCY else pooled
    return sig_xy, sig_z, rxy, rz, [nm for nm, b in zip(names, bad) if b], method


def intersection_precision(rec, lookup: Dict[str, Any], views: Sequence[Tuple[np.ndarray, Sequence[str]]],
                           pixel_sigma: float, to_local: Optional[Similarity] = None) -> Tuple[float, float]:
    """The median standard deviation (XY, Z) of points' forward intersections from their image observations
    with ``pixel_sigma``, the cameras fixed: ``views`` holds (xyz, images) per point in the model's frame;
    ``to_local``: the similarity into the frame whose XY and Z are meant (the covariance is rotated and scaled
    into it; None: the model's frame).  (nan, nan) when no point has two usable rays."""
    sxy, sz = [], []
    rot_l = np.eye(3) if to_local is None else to_local.rotation
    sc = 1.0 if to_local is None else to_local.scale
    for xyz, images in views:
        n = np.zeros((3, 3))
        k = 0
        for img in images:
            im = lookup.get(img)
            if im is None:
                continue
            cw = im.cam_from_world()
            rot = np.asarray(cw.rotation.matrix())
            xc = rot @ np.asarray(xyz, dtype=float) + np.asarray(cw.translation)
            if xc[2] <= 0:
                continue
            j = project_jacobian(rec.cameras[im.camera_id], xc[None])[0] @ rot / pixel_sigma
            if not np.all(np.isfinite(j)):
                continue
            n += j.T @ j
            k += 1
        if k < 2:
            continue
        try:
            cov = sc * sc * rot_l @ np.linalg.inv(n) @ rot_l.T
        except np.linalg.LinAlgError:
            continue
        if np.all(np.isfinite(cov)) and cov[2, 2] > 0:
            sxy.append(math.sqrt(max(0.5 * (cov[0, 0] + cov[1, 1]), 0.0)))
            sz.append(math.sqrt(cov[2, 2]))
    if not sxy:
        return float("nan"), float("nan")
    return float(np.median(sxy)), float(np.median(sz))


def tie_point_sigma(rec) -> float:
    """The a posteriori pixel sigma (per axis) of a model's tie points: sum of squared reprojection errors over
    the redundancy 2 x observations - 3 x points - 6 x images + 7 (each point's mean error standing for its
    observations').  NaN without redundancy."""
    n_obs = n_pts = 0
    ss = 0.0
    for p in rec.points3D.values():
        k = p.track.length()
        if k < 2 or not math.isfinite(p.error):
            continue
        n_obs += k
        n_pts += 1
        ss += k * float(p.error) ** 2
    red = 2 * n_obs - 3 * n_pts - 6 * rec.num_reg_images() + 7
    return math.sqrt(ss / red) if red > 0 and ss > 0 else float("nan")


def ground_sample_distance(rec, max_images: int = 30) -> float:
    """The median ground sample distance of the model (model units per pixel): the median depth of each
    image's points over its focal length, over up to ``max_images`` registered images."""
    out = []
    ids = list(rec.reg_image_ids())
    step = max(1, len(ids) // max_images)
    pts = rec.points3D
    for iid in ids[::step]:
        im = rec.image(iid)
        cw = im.cam_from_world()
        rot, t = np.asarray(cw.rotation.matrix()), np.asarray(cw.translation)
        xyz = [pts[p.point3D_id].xyz for p in im.get_observation_points2D()][:500]
        if not xyz:
            continue
        depth = (np.asarray(xyz) @ rot.T + t)[:, 2]
        depth = depth[depth > 0]
        cam = rec.cameras[im.camera_id]
        f = float(np.mean([cam.params[i] for i in cam.focal_length_idxs()]))
        if len(depth) and f > 0:
            out.append(float(np.median(depth)) / f)
    return float(np.median(out)) if out else float("nan")


def estimate_group(group: str, names: Sequence[str], row_names: Sequence[str], v: np.ndarray, r: np.ndarray,
                   floor: Tuple[float, float], prior: Tuple[float, float]) -> SigmaEstimate:
    """Step 1 for one group of members ``names``: ``v``, ``r`` (n,3) the residuals and redundancy numbers of
    those of them named in ``row_names`` (the members the rigid fit left out are not passed), floored at
    ``floor``; ``prior``: the placeholders they had."""
    if len(v) == 0:
        return SigmaEstimate(group, list(names), max(prior[0], floor[0]), max(prior[1], floor[1]), prior[0],
                             prior[1], floor[0], floor[1], method="none",
                             note="no member agrees with the rigid fit: placeholders kept")
    sxy, sz, rxy, rz, excluded, method = robust_sigma(v, r, row_names, floor)
    return SigmaEstimate(group, list(names), max(sxy, floor[0]), max(sz, floor[1]), prior[0], prior[1], floor[0],
                         floor[1], helmert_xy=sxy, helmert_z=sz, redundancy_xy=rxy, redundancy_z=rz,
                         excluded=excluded, method=method)


def fit_residuals(transform: Similarity, model: np.ndarray, world_local: np.ndarray,
                  in_fit: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Residuals (world - fitted, (n,3)) of points under ``transform`` and their redundancy numbers: those of
    the fit for the points it was fitted on (``in_fit``), 1 for the others (independent of the fit)."""
    fitted = transform.apply(np.asarray(model, dtype=float).reshape(-1, 3))
    v = np.asarray(world_local, dtype=float).reshape(-1, 3) - fitted
    r = np.ones_like(v)
    in_fit = np.asarray(in_fit, dtype=bool)
    if in_fit.sum() >= 3:
        r[in_fit] = helmert_redundancy(fitted[in_fit])
    return v, r


# --------------------------------------------------------------------------------------------------
# step 2: variance components in the adjustment
# --------------------------------------------------------------------------------------------------

def _reduced_system(prob: BundleProblem, h):
    """(V^-1 as a sparse block-diagonal matrix, H_cp, the reduced camera system S): the adjustment's Schur
    complement on the points without damping (a relative floor keeps singular blocks finite)."""
    import scipy.sparse as sp

    nc = prob.nc
    hpp = h[nc:, nc:]
    diags = {k: hpp.diagonal(k) for k in range(-2, 3)}
    blocks = np.empty((prob.npt, 3, 3))
    for i in range(3):
        for j in range(3):
            blocks[:, i, j] = diags[j - i][min(i, j)::3][:prob.npt]
    dgp = np.einsum("nii->ni", blocks)
    floor = 1e-9 * max(float(dgp.max()) if dgp.size else 1.0, 1e-12)
    vinv = inv3(blocks + floor * np.eye(3)[None])
    vinv = np.nan_to_num(vinv)
    vinv_sp = sp.bsr_matrix((vinv, np.arange(prob.npt), np.arange(prob.npt + 1)),
                            shape=(3 * prob.npt, 3 * prob.npt)).tocsr()
    hcp = h[:nc, nc:]
    hcc = h[:nc, :nc]
    dcc = hcc.diagonal()
    ridge = 1e-9 * np.maximum(dcc, 1e-12 * max(float(dcc.max()) if dcc.size else 1.0, 1e-12))
    schur = (hcc - hcp @ vinv_sp @ hcp.T).tocsr() + sp.diags(ridge)
    return vinv_sp, hcp, schur


def _solve_reduced(prob: BundleProblem, schur, b: np.ndarray) -> np.ndarray:
    import scipy.sparse.linalg as spla
    from scipy.linalg import LinAlgError, cho_factor, cho_solve

    if b.shape[1] == 0 or prob.nc == 0:
        return np.zeros_like(b)
    if prob.nc <= BundleProblem.DENSE_MAX:
        sd = schur.toarray()
        sd = 0.5 * (sd + sd.T)
        try:
            return cho_solve(cho_factor(sd), b)
        except LinAlgError:
            return np.linalg.lstsq(sd, b, rcond=None)[0]
    lu = spla.splu(schur.tocsc())
    return lu.solve(b)


@dataclass
class Redundancy:
    """The redundancy of the adjustment's groups at its current solution (``prior_redundancy``)."""

    points: np.ndarray  # (P,3) of the active point priors, rows of flatnonzero(has_pp)
    cameras: np.ndarray  # (C,3) of the active camera-position priors, rows of flatnonzero(cp_active)
    image_omega: float  # weighted squared residuals of the image observations (tie points and GCP marks)
    image_redundancy: float  # their share of the redundancy: the total less the priors'


def prior_redundancy(prob: BundleProblem) -> Redundancy:
    """Redundancy numbers of the adjustment's priors: r_i = 1 - a_i^T N^-1 a_i, a_i the prior's weighted
    Jacobian row, N = J^T J at the current solution (with its Huber weights); the image observations' share is
    the total redundancy (rows less unknowns) less the priors' sum."""
    jac, res = prob._jacobian()
    n_obs_rows = 2 * int(prob.obs.active.sum())
    pidx = np.flatnonzero(prob.has_pp)
    cidx = np.flatnonzero(prob.cp_active)
    rows = np.arange(n_obs_rows, jac.shape[0])  # every prior (points, cameras, focal lengths)
    n_rows = int(np.count_nonzero(jac.getnnz(axis=1)))
    n_unknowns = int(np.count_nonzero(jac.getnnz(axis=0)))
    omega = float(np.sum(res[:n_obs_rows] ** 2))
    if not len(rows):
        return Redundancy(np.zeros((0, 3)), np.zeros((0, 3)), omega, float(n_rows - n_unknowns))
    h = (jac.T @ jac).tocsr()
    vinv_sp, hcp, schur = _reduced_system(prob, h)
    a = jac[rows].tocsc()
    nc = prob.nc
    ac_t = a[:, :nc].T.tocsr()
    ap_t = a[:, nc:].T.tocsr()
    v_ap = vinv_sp @ ap_t  # (3P, m) sparse
    term1 = np.asarray(ap_t.multiply(v_ap).sum(axis=0)).ravel()
    b = np.asarray((ac_t - hcp @ v_ap).todense())
    x = _solve_reduced(prob, schur, b)
    term2 = np.sum(b * x, axis=0)
    red = np.clip(1.0 - (term1 + term2), 0.0, 1.0)
    n_p, n_c = 3 * len(pidx), 3 * len(cidx)
    return Redundancy(red[:n_p].reshape(-1, 3), red[n_p:n_p + n_c].reshape(-1, 3), omega,
                      float(n_rows - n_unknowns - red.sum()))


@dataclass
class VarianceGroup:
    """One group of priors whose sigma is estimated: the problem's point rows (``kind`` "point") or camera-prior
    rows ("camera") that belong to it, and its estimate (updated in place)."""

    kind: str
    rows: np.ndarray
    estimate: SigmaEstimate
    floor: Tuple[float, float]


def _group_factor(prob: BundleProblem, g: VarianceGroup, red: Redundancy
                  ) -> Tuple[Optional[float], Optional[float], float, float]:
    """(f_xy, f_z, r_xy, r_z) of a group at the current solution; a factor is None without redundancy."""
    red_p, red_c = red.points, red.cameras
    if g.kind == "point":
        active = np.flatnonzero(prob.has_pp)
        pos = {int(k): j for j, k in enumerate(active)}
        sel = [k for k in g.rows if int(k) in pos]
        if not sel:
            return None, None, 0.0, 0.0
        w = (prob.X[sel] - prob.pp[sel]) / prob.pps[sel]
        red = red_p[[pos[int(k)] for k in sel]]
    else:
        active = np.flatnonzero(prob.cp_active)
        pos = {int(k): j for j, k in enumerate(active)}
        sel = [k for k in g.rows if int(k) in pos]
        if not sel:
            return None, None, 0.0, 0.0
        cen = prob.camera_centres()[prob.cp_img[sel]]
        w = (cen - prob.cp_xyz[sel]) / prob.cp_sigma[sel]
        red = red_c[[pos[int(k)] for k in sel]].copy()
        no_z = prob.cp_sigma[sel, 2] >= 1e11  # positions without a height: Z not constrained
        w[no_z, 2] = 0.0
        red[no_z, 2] = 0.0
    rxy, rz = float(red[:, :2].sum()), float(red[:, 2].sum())
    fxy = float(np.sum(w[:, :2] ** 2)) / rxy if rxy >= MIN_REDUNDANCY else None
    fz = float(np.sum(w[:, 2] ** 2)) / rz if rz >= MIN_REDUNDANCY else None
    return fxy, fz, rxy, rz


def set_group_sigma(prob: BundleProblem, g: VarianceGroup) -> None:
    e = g.estimate
    if g.kind == "point":
        prob.pps[g.rows, 0] = prob.pps[g.rows, 1] = e.sigma_xy
        prob.pps[g.rows, 2] = e.sigma_z
    else:
        prob.cp_sigma[g.rows, 0] = prob.cp_sigma[g.rows, 1] = e.sigma_xy
        has_z = prob.cp_sigma[g.rows, 2] < 1e11
        prob.cp_sigma[g.rows[has_z], 2] = e.sigma_z


def variance_components(prob: BundleProblem, groups: Sequence[VarianceGroup], max_iterations: int = 50,
                        iterations: int = VCE_ITERATIONS, progress=None) -> int:
    """Iterate the groups' sigmas to their variance-component estimates (module notes, step 2), solving the
    adjustment after each update.  The image observations (tie points and GCP marks) are a group too: their
    pixel sigma in the problem follows their own factor (the Huber threshold kept in pixels), so that the
    other groups are weighted against the block's real image noise, not the a priori 1 px.  Returns the
    number of iterations."""
    it = 0
    for it in range(1, iterations + 1):
        red = prior_redundancy(prob)
        converged = True
        f_img = red.image_omega / red.image_redundancy if red.image_redundancy >= MIN_REDUNDANCY else None
        if f_img is not None and math.isfinite(f_img) and f_img > 0:
            k = math.sqrt(f_img)
            converged = abs(k - 1.0) <= VCE_TOLERANCE
            prob.obs.sigma = prob.obs.sigma * k
            prob.huber = prob.huber / k
        pixel = float(np.median(prob.obs.sigma[prob.obs.robust])) if np.any(prob.obs.robust) else float("nan")
        for g in groups:
            g.estimate.pixel_sigma = pixel
            fxy, fz, rxy, rz = _group_factor(prob, g, red)
            e = g.estimate
            e.factors.append((fxy if fxy is not None else float("nan"), fz if fz is not None else float("nan")))
            e.vce_redundancy = (rxy, rz)
            e.iterations = it
            e.method = "helmert + variance components"
            for comp, f, fl in (("xy", fxy, g.floor[0]), ("z", fz, g.floor[1])):
                if f is None or not math.isfinite(f):
                    continue
                old = getattr(e, f"sigma_{comp}")
                new = max(old * math.sqrt(f), fl)
                if abs(new / old - 1.0) > VCE_TOLERANCE:
                    converged = False
                setattr(e, f"sigma_{comp}", new)
            set_group_sigma(prob, g)
        prob.solve(max_iterations=max_iterations, progress=progress)
        if converged:
            break
    return it


__all__ = ["CAMERA_GROUP", "CONTROL_GROUP", "Redundancy", "SigmaEstimate", "VarianceGroup", "estimate_group", "fit_residuals",
           "ground_sample_distance", "helmert_redundancy", "intersection_precision", "lmeds_sigma",
           "prior_redundancy", "robust_sigma", "set_group_sigma", "tie_point_sigma", "variance_components"]
