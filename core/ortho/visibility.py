"""What a camera sees: its ground footprint and the polar occlusion table (radial sweep from the nadir point,
see the package docstring)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Tuple

import numpy as np

from ..dense.grid import convex_hull_xy
from .cameras import OrthoCamera
from .surface import Dsm

MAX_POLAR_CELLS = 12_000_000


@dataclass
class Footprint:
    polygon: np.ndarray  # (K, 2) world XY, convex, counter-clockwise
    bbox: Tuple[float, float, float, float]
    gsd: float  # ground sample distance at the nadir-most view, metres per pixel
    z_ref: float


def camera_footprint(cam: OrthoCamera, offset: np.ndarray, z_lo: float, z_hi: float,
                     max_range_factor: float = 15.0) -> Optional[Footprint]:
    """Ground area the image can see between heights z_lo and z_hi (world): the image border's rays
    intersected with both planes (rays near the horizon clipped at ``max_range_factor`` x the height)."""
    w, h = cam.camera.width, cam.camera.height
    t = np.linspace(0.0, 1.0, 17)
    border = np.concatenate([np.column_stack([t * w, np.zeros_like(t)]), np.column_stack([np.full_like(t, w), t * h]),
                             np.column_stack([(1 - t) * w, np.full_like(t, h)]), np.column_stack([np.zeros_like(t), (1 - t) * h])])
    xn = cam.camera.unproject(border)
    d = np.column_stack([xn, np.ones(len(xn))]) @ cam.pose.rotation  # world directions (R^T d)
    c = cam.centre + offset
    pts = []
    for z in (z_lo, z_hi):
        height = c[2] - z
        if height <= 0:
            continue
        max_h = max_range_factor * height
        for di in d:
            horiz = math.hypot(di[0], di[1])
            if di[2] < -1e-9:
                s = (z - c[2]) / di[2]
                if s * horiz > max_h:
                    s = max_h / max(horiz, 1e-12)
            elif horiz > 1e-12:
                s = max_h / horiz
            else:
                continue
            pts.append((c[0] + s * di[0], c[1] + s * di[1]))
    if len(pts) < 3:
        return None
    poly = convex_hull_xy(np.array(pts))
    if len(poly) < 3:
        return None
    xmin, ymin = poly.min(axis=0)
    xmax, ymax = poly.max(axis=0)
    z_ref = 0.5 * (z_lo + z_hi)
    gsd = max(c[2] - z_ref, 1e-6) / cam.camera.focal
    return Footprint(poly, (float(xmin), float(ymin), float(xmax), float(ymax)), float(gsd), float(z_ref))


GSD_SAMPLES = (41, 31)  # image points (across, down) at which an image's ground resolution is sampled
GSD_MARGIN = 1.3  # the trimmed footprint reaches this much beyond the limit (the exact test is per cell)


def resolution_limited(cam: OrthoCamera, offset: np.ndarray, fp: Footprint, z_lo: float, z_hi: float,
                       factor: float) -> Tuple[Footprint, float, float]:
    """(the footprint trimmed to where the image resolves the ground within ``factor`` x its best, its best ground
    resolution, its worst): the image sampled on a GSD_SAMPLES grid (border included), the rays met with the planes
    z_lo and z_hi, the ground resolution there (OrthoCamera.ground_resolution); the best is taken on the z_lo plane
    (the ground), the footprint is the convex hull of the points of both planes within GSD_MARGIN x the limit.
    The worst is the coarsest on the z_lo plane (along a ray the ground resolution grows with the distance, so no
    ground between the planes is resolved coarser), inf where a sampled ray misses that plane (the horizon of an
    oblique).  ``fp``, nan and nan when nothing is sampled."""
    w, h = cam.camera.width, cam.camera.height
    gx, gy = np.meshgrid(np.linspace(0.0, w, GSD_SAMPLES[0]), np.linspace(0.0, h, GSD_SAMPLES[1]))
    xn = cam.camera.unproject(np.column_stack([gx.ravel(), gy.ravel()]))
    d = np.column_stack([xn, np.ones(len(xn))]) @ cam.pose.rotation
    n_rays = len(d)
    d = d[np.isfinite(d).all(axis=1) & (d[:, 2] < -1e-9)]
    c = cam.centre
    pts, gsd = [], []
    for z in (z_lo, z_hi):
        s = (z - offset[2] - c[2]) / d[:, 2]
        p = c[None, :] + s[s > 0, None] * d[s > 0]
        pts.append(p[:, :2])
        gsd.append(cam.ground_resolution(p))
    pts_a, gsd_a = np.concatenate(pts), np.concatenate(gsd)
    fin = np.isfinite(gsd_a)
    low = np.isfinite(gsd[0])
    if not fin.any() or not low.any():
        return fp, float("nan"), float("nan")
    # the best on the low plane (the ground): on z_hi (tree tops, roofs, a hill beside the flight) an image
    # resolves finer than anywhere on the ground, and that limit would cut the ground of every image there
    best = float(gsd[0][low].min())
    worst = float(gsd[0][low].max()) if len(gsd[0]) == n_rays else float("inf")  # every ray meets the ground
    sel = fin & (gsd_a <= GSD_MARGIN * factor * best)
    if sel.sum() < 3:
        return fp, best, worst
    poly = convex_hull_xy(pts_a[sel] + offset[:2])
    if len(poly) < 3:
        return fp, best, worst
    xmin, ymin = np.maximum(poly.min(axis=0), fp.bbox[:2])
    xmax, ymax = np.minimum(poly.max(axis=0), fp.bbox[2:])
    if xmax <= xmin or ymax <= ymin:
        return fp, best, worst
    best_all = float(gsd_a[fin].min())  # the footprint's resolution: as without the limit (the mosaic's cell)
    gsd_fp = best_all if best_all > 1.05 * fp.gsd else fp.gsd  # an oblique's best view, not the nadir it misses
    return (Footprint(poly, (float(xmin), float(ymin), float(xmax), float(ymax)), float(gsd_fp), fp.z_ref), best,
            worst)


def _point_in_polygon(poly: np.ndarray, x: float, y: float) -> bool:
    """Whether (x, y) lies inside the closed polygon ``poly`` (N, 2), by the even-odd rule: a ray towards +x
    crosses its edges an odd number of times.  Plain NumPy: matplotlib's Path did this, and its first import from
    the stage's worker threads raced ("partially initialized module 'matplotlib'", QGIS 3.40 leg)."""
    px, py = poly[:, 0], poly[:, 1]
    qx, qy = np.roll(px, -1), np.roll(py, -1)
    straddle = (py > y) != (qy > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = px + (y - py) * (qx - px) / (qy - py)
    return bool(np.count_nonzero(straddle & (x < cross)) % 2)


@dataclass
class Visibility:
    """Polar occlusion table of one camera (see the module docstring).  ``table`` holds, per angle row and
    radius bin k, the largest t = r / (H - z) of the surface in bins < k."""

    nadir: Tuple[float, float]
    height: float  # camera Z (world)
    dr: float
    phi0: float
    dphi: float
    n_phi: int
    n_r: int
    full_circle: bool
    tolerance: float
    path: str = ""
    table: Optional[np.ndarray] = field(default=None, repr=False)

    def load(self) -> np.ndarray:
        if self.table is None:
            self.table = np.load(self.path)
        return self.table

    def visible(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, table: Optional[np.ndarray] = None) -> np.ndarray:
        tab = self.load() if table is None else table
        dx = x - self.nadir[0]
        dy = y - self.nadir[1]
        r = np.hypot(dx, dy)
        a = np.arctan2(dy, dx) - self.phi0
        a = np.mod(a, 2 * np.pi)
        j = np.rint(a / self.dphi).astype(np.int64)
        if self.full_circle:
            j %= self.n_phi
            inside = np.ones(j.shape, dtype=bool)
        else:
            inside = (j >= 0) & (j < self.n_phi)
            j = np.clip(j, 0, self.n_phi - 1)
        k = np.clip(np.floor(r / self.dr).astype(np.int64) - 1, 0, self.n_r - 1)
        m = tab[j, k]
        vis = (self.height - z - self.tolerance) * m <= r
        return vis | ~inside

    def hidden_by(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, table: Optional[np.ndarray] = None
                  ) -> np.ndarray:
        """How far (m) the surface rises above the sight line from each ground point to the camera: how much the
        point would have to be raised to be seen (0 where it is visible).  The mosaic takes a cell that every image
        has hidden from the least hidden one (a spike of a noisy DSM hides as little as a few cm)."""
        tab = self.load() if table is None else table
        dx = x - self.nadir[0]
        dy = y - self.nadir[1]
        r = np.hypot(dx, dy)
        a = np.mod(np.arctan2(dy, dx) - self.phi0, 2 * np.pi)
        j = np.rint(a / self.dphi).astype(np.int64)
        inside = np.ones(j.shape, dtype=bool) if self.full_circle else (j >= 0) & (j < self.n_phi)
        j = j % self.n_phi if self.full_circle else np.clip(j, 0, self.n_phi - 1)
        k = np.clip(np.floor(r / self.dr).astype(np.int64) - 1, 0, self.n_r - 1)
        m = tab[j, k].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            need = np.where(m > 0, (self.height - z - self.tolerance) - r / np.where(m > 0, m, 1.0), 0.0)
        return np.where(inside, np.maximum(need, 0.0), 0.0)


def build_visibility(cam: OrthoCamera, offset: np.ndarray, fp: Footprint, dsm: Dsm, tolerance: float,
                     path: str = "") -> Visibility:
    """The polar occlusion table of ``cam`` over its footprint (saved to ``path`` when given)."""
    c = cam.centre + offset
    nx, ny, hz = float(c[0]), float(c[1]), float(c[2])
    poly = fp.polygon
    rel = poly - [nx, ny]
    r_max = float(np.max(np.hypot(rel[:, 0], rel[:, 1])))
    dr = max(0.5 * dsm.res, 0.5 * fp.gsd, 1e-3)  # finer than the DSM or the image resolves is wasted
    full = _point_in_polygon(poly, nx, ny) or r_max < 4 * dr
    if full:
        phi0, span = -math.pi, 2 * math.pi
    else:
        ang = np.arctan2(rel[:, 1], rel[:, 0])
        centre_dir = math.atan2(float(np.mean(rel[:, 1])), float(np.mean(rel[:, 0])))
        da = np.mod(ang - centre_dir + np.pi, 2 * np.pi) - np.pi
        lo, hi = float(da.min()), float(da.max())
        pad = 0.02
        phi0, span = centre_dir + lo - pad, (hi - lo) + 2 * pad
        if span >= 2 * math.pi - 1e-6:
            full, phi0, span = True, -math.pi, 2 * math.pi
    r_max += 2 * dr
    n_r = int(math.ceil(r_max / dr)) + 1
    n_phi = max(8, int(math.ceil(span * r_max / dr)))
    while n_r * n_phi > MAX_POLAR_CELLS:
        dr *= 1.25
        n_r = int(math.ceil(r_max / dr)) + 1
        n_phi = max(8, int(math.ceil(span * r_max / dr)))
    dphi = span / n_phi
    sampler = dsm.window_sampler((nx - r_max, ny - r_max, nx + r_max, ny + r_max) if full else
                                 (min(nx, poly[:, 0].min()), min(ny, poly[:, 1].min()),
                                  max(nx, poly[:, 0].max()), max(ny, poly[:, 1].max())))
    table = np.empty((n_phi, n_r), dtype=np.float32)
    radii = (np.arange(n_r) + 0.5) * dr
    rows = max(1, 2_000_000 // n_r)
    for j0 in range(0, n_phi, rows):
        phis = phi0 + np.arange(j0, min(n_phi, j0 + rows)) * dphi
        xx = nx + np.cos(phis)[:, None] * radii[None, :]
        yy = ny + np.sin(phis)[:, None] * radii[None, :]
        z = sampler(xx, yy)
        depth = hz - z
        t = np.where(np.isfinite(z), np.where(depth > 1e-6, radii[None, :] / np.maximum(depth, 1e-6), np.inf), 0.0)
        cm = np.maximum.accumulate(t, axis=1)
        table[j0:j0 + len(phis), 0] = 0.0
        table[j0:j0 + len(phis), 1:] = cm[:, :-1]
    vis = Visibility((nx, ny), hz, dr, phi0, dphi, n_phi, n_r, full, tolerance, path)
    if path:
        np.save(path, table)
    else:
        vis.table = table
    return vis


def visibility_table(vis: Visibility) -> np.ndarray:
    """The table, memory-mapped from its file (a mosaic tile reads only the rows of the angles it spans; the
    pages stay in the system's file cache, not in this process, and the image cache keeps the decoded photos:
    toledo_2400's 57 tables are 2.3 GB, loaded whole they pushed the photos and each other out of the cache,
    2,400 table loads and 2,400 photo decodes for 80 tiles)."""
    if vis.table is not None:
        return vis.table
    return np.load(vis.path, mmap_mode="r")
