"""Triangulation of ground points from their pixel observations, and of tie points with the cameras held.

Through the full camera model (``core.georef.bundle.project``): multi-view DLT on undistorted normalised
coordinates, then Gauss-Newton on pixel residuals.  Used by the georeferencing (control and check points),
the guided GCP placement and the outlier re-tests.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import check_cancel
from ..io.gcp import Observation
from .bundle import outside_image, project, project_jacobian


@dataclass
class PointView:
    """A point seen in one image: the observation, the image's camera and pose."""

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


def registered_images(reconstruction) -> Dict[str, Any]:
    out = {}
    for iid in reconstruction.reg_image_ids():
        im = reconstruction.image(iid)
        out[im.name] = im
    return out


def image_names(reconstruction) -> set:
    return {im.name for im in reconstruction.images.values()}


def collect_views(reconstruction, observations: Sequence[Observation], lookup: Dict[str, Any],
                   all_names: Optional[set] = None) -> Tuple[List[PointView], List[str]]:
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
        if outside_image(cam, ob):
            notes.append(f"observation in {ob.image} at ({ob.x:g}, {ob.y:g}) lies outside the image "
                         f"({cam.width} x {cam.height} px): skipped")
            continue
        views.append(PointView(i, ob.image, cam, np.asarray(im.cam_from_world().matrix()),
                           np.array([ob.x, ob.y], dtype=float)))
    return views, notes


def triangulate_views(views: List[PointView]) -> Optional[np.ndarray]:
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
    return refine_point(views, x)


def view_residuals(views: List[PointView], x: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Pixel residual vectors (M,2) and depths (M,) of point x in the views."""
    res = np.empty((len(views), 2))
    depth = np.empty(len(views))
    for k, v in enumerate(views):
        xc = v.cam_from_world[:, :3] @ x + v.cam_from_world[:, 3]
        depth[k] = xc[2]
        res[k] = project(v.camera, xc[None])[0] - v.xy
    return res, depth


def refine_point(views: List[PointView], x: np.ndarray, iterations: int = 15) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    res, _ = view_residuals(views, x)
    cost = float(np.sum(res ** 2))
    lam = 1e-6
    for _ in range(iterations):
        jac = np.empty((2 * len(views), 3))
        for k, v in enumerate(views):
            r = v.cam_from_world[:, :3]
            xc = r @ x + v.cam_from_world[:, 3]
            jac[2 * k:2 * k + 2] = project_jacobian(v.camera, xc[None])[0] @ r
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
            rn, _ = view_residuals(views, xn)
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


def intersection_angle(views: List[PointView], x: np.ndarray) -> float:
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
    lookup = registered_images(reconstruction) if _lookup is None else _lookup
    all_names = image_names(reconstruction) if _all_names is None else _all_names
    views, notes = collect_views(reconstruction, observations, lookup, all_names)
    n = len(observations)
    residuals = np.full(n, np.nan)
    used = np.zeros(n, dtype=bool)
    rejected: List[int] = []
    if len(views) < max(2, min_views):
        notes.append(f"{len(views)} usable observation(s), need {max(2, min_views)}")
        return Triangulation(None, residuals, used, rejected, notes)
    x = triangulate_views(views)
    while x is not None:
        res, depth = view_residuals(views, x)
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
        x = triangulate_views(views)
    if x is None:
        notes.append("triangulation failed (degenerate geometry)")
        return Triangulation(None, residuals, used, rejected, notes)
    res, depth = view_residuals(views, x)
    if np.any(depth <= 0):
        notes.append("triangulated point lies behind a camera")
        return Triangulation(None, residuals, used, rejected, notes)
    for k, v in enumerate(views):
        residuals[v.index] = float(np.linalg.norm(res[k]))
        used[v.index] = True
    angle = intersection_angle(views, x)
    if angle < 1.0:
        notes.append(f"weak intersection: largest ray angle {angle:.2f} degrees")
    return Triangulation(x, residuals, used, rejected, notes, angle)


def refine_tie_points(rec, huber_px: float, progress, iterations: int = 10) -> None:
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
            uv[m] = project(cam, xc[m])
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
        check_cancel(progress)
        jpi = np.empty((len(o_pt), 2, 3))
        for cid, cam in cams.items():
            m = o_cam == cid
            jpi[m] = project_jacobian(cam, xc[m])
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



__all__ = ["Triangulation", "PointView", "collect_views", "image_names", "intersection_angle",
           "refine_point", "refine_tie_points", "registered_images", "triangulate_observations",
           "triangulate_views", "view_residuals"]
