"""Values of ground points in one image: projection through the camera model, occlusion, mask, view cost and
interpolation."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .cameras import OrthoCamera
from .hotspot import shadow_cost
from .pixels import ImageMeta, image_window, photo_mask, remap_photo
from .visibility import Visibility, visibility_table


@dataclass
class Sampled:
    values: np.ndarray  # (N, bands) float32 (only rows where valid are meaningful)
    valid: np.ndarray  # (N,) bool
    cost: np.ndarray  # (N,) float32, inf where not valid
    xyz: Optional[np.ndarray] = None  # (N, 3) the points in the local frame (height 0 where it is not finite)
    px: Optional[np.ndarray] = None  # (N, 2) their pixels (meaningful where valid)


def camera_view(cam: OrthoCamera, meta: ImageMeta, offset: np.ndarray, x: np.ndarray, y: np.ndarray,
                z: np.ndarray, vis: Optional[Visibility]) -> Sampled:
    """Where ground points (world, 1-D arrays) fall in one image, with validity (in front, inside, seen, not in
    the far field, not masked) and the view cost; no pixel is read (``values`` stay 0)."""
    n = x.size
    finite = np.isfinite(z)
    xyz = np.column_stack([x - offset[0], y - offset[1], np.where(finite, z, 0.0) - offset[2]])
    px, depth, ok = cam.project(xyz)
    ok &= finite
    if vis is not None and ok.any():
        idx = np.flatnonzero(ok)
        ok[idx] = vis.visible(x[idx], y[idx], z[idx], visibility_table(vis))
    if cam.max_gsd and ok.any():  # the stretched far field of an oblique: left to the images that see it nearer
        idx = np.flatnonzero(ok)
        ok[idx] = cam.ground_resolution(xyz[idx], (px[idx], depth[idx])) <= cam.max_gsd
    mask = photo_mask(cam.mask_path)
    if mask is not None and ok.any():
        idx = np.flatnonzero(ok)
        mc = np.clip(px[idx, 0].astype(np.int64), 0, mask.shape[1] - 1)
        mr = np.clip(px[idx, 1].astype(np.int64), 0, mask.shape[0] - 1)
        ok[idx] = mask[mr, mc] >= 128
    cost = np.full(n, np.inf, dtype=np.float32)
    values = np.zeros((n, meta.bands), dtype=np.float32)
    if not ok.any():
        return Sampled(values, ok, cost, xyz, px)
    idx = np.flatnonzero(ok)
    c = cam.centre
    dxy = np.hypot(xyz[idx, 0] - c[0], xyz[idx, 1] - c[1])
    dz = np.maximum(c[2] - xyz[idx, 2], 1e-6)
    half_diag = 0.5 * math.hypot(cam.camera.width, cam.camera.height)
    rho = np.hypot(px[idx, 0] - cam.camera.cx, px[idx, 1] - cam.camera.cy) / half_diag
    cost[idx] = (rho * rho + (dxy / dz) ** 2).astype(np.float32)
    if cam.shadow is not None:  # the drone's shadow and the hot spot's core: another image's where one sees it
        cost[idx] += shadow_cost(cam.shadow, c, xyz[idx]).astype(np.float32)
    return Sampled(values, ok, cost, xyz, px)


def sample_camera(cam: OrthoCamera, meta: ImageMeta, offset: np.ndarray, x: np.ndarray, y: np.ndarray,
                  z: np.ndarray, vis: Optional[Visibility], interpolation: str = "bilinear") -> Sampled:
    """Values of ground points (world, 1-D arrays) in one image, with validity and the view cost
    (:func:`camera_view`, then the pixels read with ``interpolation``)."""
    s = camera_view(cam, meta, offset, x, y, z, vis)
    idx = np.flatnonzero(s.valid)
    if len(idx):
        u = s.px[idx, 0] - 0.5
        v = s.px[idx, 1] - 0.5
        pad = 3
        x0 = max(0, int(math.floor(u.min())) - pad)
        y0 = max(0, int(math.floor(v.min())) - pad)
        x1 = min(meta.width, int(math.ceil(u.max())) + pad + 1)
        y1 = min(meta.height, int(math.ceil(v.max())) + pad + 1)
        win = image_window(cam.path, meta, x0, y0, x1, y1)
        s.values[idx] = remap_photo(win, u - x0, v - y0, interpolation)
        if np.dtype(meta.dtype).kind == "f":  # a float photo's no data (NaN, or its nodata read as NaN): not valid
            bad = idx[~np.isfinite(s.values[idx]).all(axis=1)]
            s.valid[bad] = False
            s.cost[bad] = np.inf
            s.values[bad] = 0.0
    return s
