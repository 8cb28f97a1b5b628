"""Outliers in the ground control: which control points agree with each other, and the tests of the
adjustment that remove the worst GCP observation, control point or camera position one at a time.

``control_consistency`` works on the model before the adjustment (subsets of control points that one
similarity maps onto their coordinates).  ``find_outlier`` and ``retest_provisional`` work on a solved
``core.georef.bundle.BundleProblem``.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.similarity import fit_similarity
from .bundle import BundleProblem
from .results import Outlier
from .triangulate import PointView, triangulate_views, view_residuals


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
                    _, r = fit_similarity(src[sel], dst[sel], xy_only)
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
            _, r = fit_similarity(src[idx], dst[idx], xy_only)
            rms = float(np.sqrt(np.mean(r ** 2)))
            if rms <= tolerance:
                best = (rms, tuple(idx))
                break
            idx.pop(int(np.argmax(r)))
    if best is None:  # nothing agrees: report against the fit of all
        tr, r = fit_similarity(src, dst, xy_only)
        return Consistency([], float(np.sqrt(np.mean(r ** 2))), tolerance,
                           {names[i]: float(r[i]) for i in range(n)}, xy_only)
    sel = list(best[1])
    tr, _ = fit_similarity(src[sel], dst[sel], xy_only)
    p = tr.apply(src)
    d = (p[:, :2] - dst[:, :2]) if xy_only else (p - dst)
    r_all = np.linalg.norm(d, axis=1)
    return Consistency([names[i] for i in sel], best[0], tolerance, {names[i]: float(r_all[i]) for i in range(n)},
                       xy_only)


@dataclass
class ControlRows:
    """The control points in a bundle problem: the GroundPoints that entered it (``points``), each one's row of
    ``prob.X`` (``index``) and its observation rows with their images (``obs_rows``), and the names taken out of
    the adjustment since (``removed``)."""

    points: List[Any]
    index: Dict[str, int]
    obs_rows: Dict[str, List[Tuple[int, str]]]
    removed: set

    @property
    def left(self) -> int:
        """How many control points are still in the adjustment."""
        return len(self.points) - len(self.removed)


def gcp_residuals(prob: BundleProblem, control: ControlRows, px_threshold, sigma_threshold):
    """Residuals of the GCPs in the adjustment and the thresholds of the outlier tests: the pixel
    residuals of their active observations (thr_px = max(px_threshold, 5 x median)) and the largest
    normalised coordinate residual of each point (thr_z = max(sigma_threshold, 5 x median))."""
    ba_points, gcp_index, gcp_obs_rows = control.points, control.index, control.obs_rows
    removed_points = control.removed
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


def control_thresholds(prob: BundleProblem, control: ControlRows, px_threshold, sigma_threshold
                       ) -> Tuple[float, float]:
    """(thr_px, thr_z) of the adjustment's outlier tests for the current state (see gcp_residuals)."""
    res = gcp_residuals(prob, control, px_threshold, sigma_threshold)
    return res[3], res[8]


def retest_provisional(prob: BundleProblem, k: int, rows) -> Dict[str, Any]:
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
        views.append((PointView(int(r), img, prob.cameras[prob.img_cam[i]], m, o.xy[r].copy()), float(o.sigma[r])))
    if len(views) < 2 or not np.all(np.isfinite(prob.pp[k])):
        return inf
    prior, ps = prob.pp[k], prob.pps[k]
    x_free = triangulate_views([v for v, _ in views])
    if x_free is not None and not np.all(np.isfinite(x_free)):
        x_free = None
    x0 = x_free if x_free is not None else prior.copy()
    vs = [v for v, _ in views]
    sig = np.array([s for _, s in views])

    def res(x):
        r, depth = view_residuals(vs, x)
        r = r / sig[:, None]
        r = np.where(np.isfinite(r) & (depth[:, None] > 0), r, 1e6)
        return np.concatenate([r.ravel(), (x - prior) / ps])

    try:
        sol = least_squares(res, x0, method="lm", x_scale=np.maximum(ps, 1e-6))
    except (ValueError, np.linalg.LinAlgError):
        return inf
    x = sol.x
    r, depth = view_residuals(vs, x)
    px = np.linalg.norm(r, axis=1)
    if not (np.all(depth > 0) and np.all(np.isfinite(px))):
        return inf
    d = x - prior
    return {"xyz": x, "sigma": float(np.max(np.abs(d / ps))), "distance_m": float(np.linalg.norm(d)),
            "px": float(px.max()), "n_obs": len(vs),
            "free_distance_m": float(np.linalg.norm(x_free - prior)) if x_free is not None else None}


def find_outlier(prob: BundleProblem, control: ControlRows, px_threshold, sigma_threshold, min_left: int
                 ) -> Optional[Outlier]:
    """The single worst GCP observation, control point or camera position beyond its threshold, removed; a control
    point (or its last observation) only while more than ``min_left`` control points are left."""
    obs = prob.obs
    gcp_index, gcp_obs_rows, n_control_left = control.index, control.obs_rows, control.left
    cands: List[Tuple[float, Outlier, Any]] = []
    all_rows, owner, px, thr_px, bad_obs_per_point, n_obs_per_point, names, z, thr_z = gcp_residuals(
        prob, control, px_threshold, sigma_threshold)
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


def removed_cameras(outliers: List[Outlier]) -> set:
    return {o.name for o in outliers if o.kind == "camera position"}



__all__ = ["Consistency", "ControlRows", "control_consistency", "control_thresholds", "find_outlier", "gcp_residuals",
           "removed_cameras", "retest_provisional"]
