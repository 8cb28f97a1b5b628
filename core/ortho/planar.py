"""Planar rectification of one image through its control points, and how far it is off given a DSM."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

import numpy as np

from ..common.progress import Progress, SubProgress, check_cancel
from ..geometry import resection as rs
from ..geometry.camera import Intrinsics
from ..io import raster as dsmmod
from .cameras import OrthoCamera
from .grid import cell_centre_coords, grid_tiles, nice_number
from .imagecontrol import ImageControl, ImageRun
from .options import OrthoError, OrthoOptions
from .pixels import ImageMeta, image_window, photo_mask, remap_photo
from .surface import Dsm
from .writer import RasterWriter


@dataclass
class PlanarResult:
    resolution: float
    valid_fraction: float
    rmse_m: float  # of the control points on the plane
    error: Optional[Dict[str, float]] = None  # how far planar rectification is off given the DSM
    # each control point's residual on the plane: name -> (dx_m, dy_m, res_m)
    plane_residuals: Dict[str, Tuple[float, float, float]] = field(default_factory=dict)


@dataclass
class PlanarOutput:
    """Where the planar rectification goes: the Cloud-Optimized GeoTIFF's path and its CRS (None: none written)."""

    path: str
    crs: Optional[str]


def _undistorted_px(cam: Intrinsics, px: np.ndarray) -> np.ndarray:
    xn = cam.unproject(px)
    return np.stack([cam.fx * xn[..., 0] + cam.cx, cam.fy * xn[..., 1] + cam.cy], axis=-1)


def rectify_planar(ocam: OrthoCamera, run: ImageRun, ctl: ImageControl, offset: np.ndarray, dsm: Optional[Dsm],
                   options: OrthoOptions, output: PlanarOutput, progress: Progress) -> PlanarResult:
    """Projective rectification through the control points; with a DSM, how far it is off from the truth.
    The residuals on the plane (dx_m, dy_m, res_m) come back in ``plane_residuals``."""
    cam, control, warn = ocam.camera, ctl.control, run.warn
    try:
        hom = rs.fit_homography(_undistorted_px(cam, ctl.px[control]), (ctl.xyz[control, :2] - offset[:2]),
                                [ctl.pairs[i][0].name for i in control], image=ocam.name)
    except rs.ResectionError as e:
        raise OrthoError(str(e)) from e
    for w_ in hom.warnings:
        warn(w_)
    plane_residuals = {r.name: (r.dx, r.dy, r.residual) for r in hom.residuals}
    grid = _planar_grid(hom, cam, ocam.name, offset, options.resolution)
    n_valid = _write_planar(hom, ocam, run.meta, grid, offset, options, output, progress)
    out = PlanarResult(grid.resolution, n_valid / float(grid.width * grid.height), hom.rmse_m,
                       plane_residuals=plane_residuals)
    run.log.append(f"planar rectification through {sum(r.used for r in hom.residuals)} control points: RMSE "
                   f"{hom.rmse_m:.3f} m on the plane")
    if dsm is None:
        warn("no DSM given: how far planar rectification is off because of relief cannot be measured")
        return out
    out.error = _planar_error(hom, ocam, grid, offset, dsm)
    if out.error is None:
        warn("the DSM does not cover the image's ground: planar displacement not measured")
        return out
    pe = out.error
    run.log.append(f"planar rectification is off by {pe['mean_m']:.2f} m on average, {pe['p95_m']:.2f} m at the "
                   f"95th percentile and {pe['max_m']:.2f} m at most ({pe['p95_px']:.1f} cells at 95 %) over "
                   f"{pe['relief_m']:.1f} m of relief in the DSM")
    return out


def _planar_grid(hom, cam: Intrinsics, name: str, offset: np.ndarray, resolution: float) -> dsmmod.Grid:
    """The output grid covering the image's border on the plane (OrthoError if the plane reaches the horizon)."""
    # which side of the horizon the image is on: the sign of w at the image centre
    hmat = hom.matrix
    w_c = (hmat @ np.array([cam.cx, cam.cy, 1.0]))[2]
    t = np.linspace(0.0, 1.0, 33)
    border = np.concatenate([np.column_stack([t * cam.width, np.zeros_like(t)]),
                             np.column_stack([np.full_like(t, cam.width), t * cam.height]),
                             np.column_stack([(1 - t) * cam.width, np.full_like(t, cam.height)]),
                             np.column_stack([np.zeros_like(t), (1 - t) * cam.height])])
    ub = _undistorted_px(cam, border)
    wb = np.column_stack([ub, np.ones(len(ub))]) @ hmat.T
    if np.any(wb[:, 2] * w_c <= 0):
        raise OrthoError(f"the plane through the control points reaches the horizon in {name}: planar "
                         "rectification of an oblique view this steep has no bounded result; use MODE ortho")
    corners = wb[:, :2] / wb[:, 2:3] + offset[:2]
    jac_d = 1.0
    c0 = hom.world_from_pixel(np.array([[cam.cx, cam.cy], [cam.cx + jac_d, cam.cy], [cam.cx, cam.cy + jac_d]]))
    gsd = math.sqrt(abs(np.cross(c0[1] - c0[0], c0[2] - c0[0])))
    res = resolution if resolution > 0 else nice_number(gsd)
    grid = dsmmod.Grid.covering(float(corners[:, 0].min()), float(corners[:, 1].min()), float(corners[:, 0].max()),
                                float(corners[:, 1].max()), res, what="planar rectification")
    if grid.width * grid.height > 400_000_000:
        raise OrthoError(f"a {grid.width} x {grid.height} planar rectification at {res:g} is too large")
    return grid


def _write_planar(hom, ocam: OrthoCamera, meta: ImageMeta, grid: dsmmod.Grid, offset: np.ndarray,
                  options: OrthoOptions, output: PlanarOutput, progress: Progress) -> int:
    """Write the rectified image as a COG at ``output.path``; returns the number of cells with data."""
    cam = ocam.camera
    work = os.path.join(os.path.dirname(os.path.abspath(output.path)), ".work-" + os.path.basename(output.path))
    writer = RasterWriter(work, grid.width, grid.height, meta.bands, meta.dtype, grid.geotransform, output.crs)
    n_valid = 0
    try:
        tiles = grid_tiles(grid.width, grid.height, options.tile)
        for k, (r0, c0_, h, w) in enumerate(tiles):
            check_cancel(progress)
            x, y = cell_centre_coords(grid, r0, c0_, h, w)
            pu = hom.pixel_from_world(np.column_stack([x - offset[0], y - offset[1]]))
            xn = np.column_stack([(pu[:, 0] - cam.cx) / cam.fx, (pu[:, 1] - cam.cy) / cam.fy])
            ok = cam.valid_normalized(xn)
            xd = cam.distort(xn)
            px = np.column_stack([cam.fx * xd[:, 0] + cam.cx, cam.fy * xd[:, 1] + cam.cy])
            ok &= cam.inside(px) & np.all(np.isfinite(px), axis=1)
            vals = np.zeros((len(x), meta.bands), dtype=np.float32)
            if ok.any():
                idx = np.flatnonzero(ok)
                u, v = px[idx, 0] - 0.5, px[idx, 1] - 0.5
                xa, ya = max(0, int(u.min()) - 3), max(0, int(v.min()) - 3)
                xb, yb = min(meta.width, int(u.max()) + 4), min(meta.height, int(v.max()) + 4)
                win = image_window(ocam.path, meta, xa, ya, xb, yb)
                vals[idx] = remap_photo(win, u - xa, v - ya, options.interpolation)
                mask = photo_mask(ocam.mask_path)
                if mask is not None:
                    ok[idx] &= mask[np.clip(px[idx, 1].astype(int), 0, mask.shape[0] - 1),
                                    np.clip(px[idx, 0].astype(int), 0, mask.shape[1] - 1)] >= 128
            writer.write(r0, c0_, vals.reshape(h, w, -1), ok.reshape(h, w))
            n_valid += int(ok.sum())
            progress.report(0.8 * (k + 1) / len(tiles), f"planar rectification: tile {k + 1}/{len(tiles)}")
        writer.finish(output.path, options.compress, SubProgress(progress, 0.8, 0.95),
                      metadata={"ARCHAEOORTHO_STAGE": "planar rectification", "IMAGE": ocam.name})
    except BaseException:
        writer.abort()
        raise
    return n_valid


def _planar_error(hom, ocam: OrthoCamera, grid: dsmmod.Grid, offset: np.ndarray, dsm: Dsm
                  ) -> Optional[Dict[str, float]]:
    """Displacement of planar rectification against the true geometry: ground (X, Y, DSM) -> image (pose) ->
    plane (homography); the difference is where the plane puts what truly lies at (X, Y).  None if the DSM
    does not cover the image's ground."""
    res = grid.resolution
    n = 200
    xs = np.linspace(grid.x0, grid.x0 + grid.width * res, n)
    ys = np.linspace(grid.y0, grid.y0 - grid.height * res, n)
    gx, gy = np.meshgrid(xs, ys)
    gx, gy = gx.ravel(), gy.ravel()
    gz = dsm.sample(gx, gy)
    fin = np.isfinite(gz)
    xyz_l = np.column_stack([gx - offset[0], gy - offset[1], np.where(fin, gz, 0.0) - offset[2]])
    px, _d, ok = ocam.project(xyz_l)
    ok &= fin
    if not ok.any():
        return None
    planar = hom.world_from_pixel(_undistorted_px(ocam.camera, px[ok]))
    d = np.hypot(planar[:, 0] - xyz_l[ok, 0], planar[:, 1] - xyz_l[ok, 1])
    relief = float(np.nanpercentile(gz[ok], 99) - np.nanpercentile(gz[ok], 1))
    return {"mean_m": float(d.mean()), "p95_m": float(np.percentile(d, 95)), "max_m": float(d.max()),
            "mean_px": float(d.mean() / res), "p95_px": float(np.percentile(d, 95) / res),
            "max_px": float(d.max() / res), "relief_m": relief, "samples": int(ok.sum())}
