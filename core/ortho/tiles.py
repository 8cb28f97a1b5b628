"""One mosaic tile: the picklable unit a worker (process pool or Dask) renders, and its blending."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import Cancelled
from ..io import raster as dsmmod
from .blend import multiband_blend
from .cameras import OrthoCamera
from .grid import cell_centre_coords
from .pixels import PHOTO_CACHE, ImageMeta
from .radiometry import RadiometryModel, point_gains
from .sampling import camera_view, sample_camera
from .surface import Dsm
from .visibility import Visibility, visibility_table


@dataclass
class TileUnit:
    """Everything one mosaic tile needs (picklable: runs in a pool worker or on a Dask cluster)."""

    index: int
    r0: int  # tile rows/cols in output cells (without halo)
    c0: int
    h: int
    w: int
    halo: int
    grid: Dict[str, Any]
    dsm_path: str
    crs: Optional[str]
    offset: List[float]
    cameras: List[OrthoCamera]
    metas: List[ImageMeta]
    visibility: List[Optional[Visibility]]
    primary: List[int]  # indices into cameras (labels present near the tile)
    secondary: List[int]  # other images over the tile, best first (fill occlusions)
    gains: List[float]
    labels_path: str
    k: int
    plan_shape: Tuple[int, int]
    feather_cells: int
    blending: str
    interpolation: str
    cache_mb: int
    radiometry: Optional[RadiometryModel] = None  # the per-point correction (replaces ``gains``)
    fill_hidden: bool = True  # a cell hidden from every image takes the least hidden one (no holes)


@dataclass
class _Cells:
    """The cells of a tile (with its halo) on the ground: world x, y, the DSM's z (NaN: no height), flat, and the
    block's local frame offset."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    offset: np.ndarray


DSM_CACHE: Dict[Tuple[str, Optional[str]], Dsm] = {}


def _dsm_for(path: str, crs: Optional[str]) -> Dsm:
    key = (path, crs)
    if key not in DSM_CACHE:
        DSM_CACHE.clear()
        DSM_CACHE[key] = Dsm(path, crs)
    return DSM_CACHE[key]


def render_tile(unit: TileUnit, cancel_path: Optional[str] = None) -> Dict[str, Any]:
    """Blend one mosaic tile: returns values (h, w, bands) float32, valid (h, w) and which-image counts."""
    cv2 = require("cv2", "orthophotos")

    PHOTO_CACHE.max_bytes = unit.cache_mb << 20
    grid = dsmmod.Grid(**unit.grid)
    dsm = _dsm_for(unit.dsm_path, unit.crs)
    off = np.asarray(unit.offset, dtype=float)
    halo = unit.halo
    # rows/cols with halo, clipped to the grid
    ar0, ac0 = max(0, unit.r0 - halo), max(0, unit.c0 - halo)
    ar1, ac1 = min(grid.height, unit.r0 + unit.h + halo), min(grid.width, unit.c0 + unit.w + halo)
    hh, ww = ar1 - ar0, ac1 - ac0
    x, y = cell_centre_coords(grid, ar0, ac0, hh, ww)
    z = dsm.sample(x, y)
    cells = _Cells(x, y, z, off)
    bands = unit.metas[0].bands
    labels_all = np.load(unit.labels_path, mmap_mode="r")
    k = unit.k
    ph, pw = unit.plan_shape
    # planning window around the tile (margin for the feathering blur)
    m = unit.feather_cells + 1
    pr0, pc0 = max(0, ar0 // k - m), max(0, ac0 // k - m)
    pr1, pc1 = min(ph, (ar1 - 1) // k + 1 + m), min(pw, (ac1 - 1) // k + 1 + m)
    lab = np.asarray(labels_all[pr0:pr1, pc0:pc1])
    rows = np.arange(ar0, ar1)
    cols = np.arange(ac0, ac1)
    # planning coordinates of the output cells (for soft weights), nearest planning cell (for hard labels)
    fr = ((rows + 0.5) / k - 0.5 - pr0).astype(np.float32)
    fc = ((cols + 0.5) / k - 0.5 - pc0).astype(np.float32)
    map_x, map_y = np.meshgrid(fc, fr)
    hard = lab[(rows // k - pr0)[:, None], (cols // k - pc0)[None, :]]

    acc = np.zeros((hh * ww, bands), dtype=np.float64) if unit.blending != "multiband" else None
    wsum = np.zeros(hh * ww, dtype=np.float64)
    layers = []  # multiband: (values, weight)
    counts: Dict[int, int] = {}
    for ci in unit.primary:
        if cancel_path and os.path.exists(cancel_path):
            raise Cancelled("cancelled by the user")
        cam = unit.cameras[ci]
        if unit.blending == "feather" and unit.feather_cells > 0:
            onehot = (lab == ci).astype(np.float32)
            ksz = 2 * unit.feather_cells + 1
            soft = cv2.blur(onehot, (ksz, ksz), borderType=cv2.BORDER_REPLICATE)
            wgt = cv2.remap(soft, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).ravel()
        else:
            wgt = (hard == ci).astype(np.float32).ravel()
        if unit.blending == "multiband":  # the pyramids see the whole image (push-pull fills its holes)
            s = sample_camera(cam, unit.metas[ci], off, x, y, z, unit.visibility[ci], unit.interpolation)
            if not s.valid.any():
                continue
            vals = s.values * point_gains(unit.radiometry, unit.gains[ci], ci, cam, s.xyz, s.valid)
            wgt = np.where(s.valid, wgt, 0.0)
            layers.append((vals, s.valid, wgt))
            wsum += wgt
            continue
        # feather / none: only the cells this image weighs in on (its label's cells and the feathering ramp)
        sel = np.flatnonzero(wgt > 0)
        if not len(sel):
            continue
        s = sample_camera(cam, unit.metas[ci], off, x[sel], y[sel], z[sel], unit.visibility[ci], unit.interpolation)
        if not s.valid.any():
            continue
        sel, vals = sel[s.valid], s.values[s.valid]
        w_sel = wgt[sel]
        vals = vals * point_gains(unit.radiometry, unit.gains[ci], ci, cam, s.xyz[s.valid], np.ones(len(sel), bool),
                                  s.px[s.valid])
        acc[sel] += vals * w_sel[:, None]
        wsum[sel] += w_sel
    # cells whose planned image cannot see them: the best image that does (primary first, then the others)
    need = wsum <= 1e-6
    fill_vals = np.zeros((hh * ww, bands), dtype=np.float32)
    fill_cost = np.full(hh * ww, np.inf, dtype=np.float32)
    if need.any():
        # the view cost of every image first (no pixels), then the values of each cell from its best image only
        idx = np.flatnonzero(need & np.isfinite(z))  # no height: no image can give the cell a value
        best = np.full(len(idx), -1, dtype=np.int64)
        for ci in list(unit.primary) + list(unit.secondary):
            if not len(idx):
                break
            s = camera_view(unit.cameras[ci], unit.metas[ci], off, x[idx], y[idx], z[idx], unit.visibility[ci])
            better = s.valid & (s.cost < fill_cost[idx])
            if better.any():
                fill_cost[idx[better]] = s.cost[better]
                best[better] = ci
        _fill_values(unit, cells, idx, best, unit.visibility, fill_vals, counts)
        filled = need & np.isfinite(fill_cost)
    else:
        filled = need
    hidden = np.zeros(hh * ww, dtype=bool)
    if unit.fill_hidden:
        hidden = _fill_hidden(unit, cells, need & ~filled, fill_vals, counts)
        filled |= hidden
    valid = (wsum > 1e-6) | filled
    if unit.blending == "multiband":
        out = multiband_blend(layers, fill_vals, filled, hh, ww, bands)
    else:
        out = np.zeros((hh * ww, bands), dtype=np.float32)
        ok = wsum > 1e-6
        out[ok] = (acc[ok] / wsum[ok, None]).astype(np.float32)
        out[filled] = fill_vals[filled]
    # crop the halo
    rr0, cc0 = unit.r0 - ar0, unit.c0 - ac0
    out = out.reshape(hh, ww, bands)[rr0:rr0 + unit.h, cc0:cc0 + unit.w]
    valid = valid.reshape(hh, ww)[rr0:rr0 + unit.h, cc0:cc0 + unit.w]
    return {"index": unit.index, "r0": unit.r0, "c0": unit.c0, "values": out, "valid": valid,
            "fill_cells": int(filled.reshape(hh, ww)[rr0:rr0 + unit.h, cc0:cc0 + unit.w].sum()),
            "hidden_cells": int(hidden.reshape(hh, ww)[rr0:rr0 + unit.h, cc0:cc0 + unit.w].sum())}


def _fill_hidden(unit: TileUnit, cells: _Cells, left: np.ndarray, fill_vals: np.ndarray,
                 counts: Dict[int, int]) -> np.ndarray:
    """Cells with a height that no image sees (each has them hidden) but that lie inside an image (its frame,
    mask and far-field limit): the value of the image that hides them least (Visibility.hidden_by), so the
    mosaic has no holes where the ground is photographed: the specks and cracks a noisy DSM (tree crowns, the
    ramp of a wall) cuts out of every image.  Writes ``fill_vals``; returns the cells filled."""
    off, x, y, z = cells.offset, cells.x, cells.y, cells.z
    idx = np.flatnonzero(left & np.isfinite(z))
    out = np.zeros(left.shape, dtype=bool)
    if not len(idx):
        return out
    best = np.full(len(idx), np.inf)
    winner = np.full(len(idx), -1, dtype=np.int64)
    for ci in list(unit.primary) + list(unit.secondary):
        vis = unit.visibility[ci]
        if vis is None:
            continue
        s = camera_view(unit.cameras[ci], unit.metas[ci], off, x[idx], y[idx], z[idx], None)
        if not s.valid.any():
            continue
        sel = np.flatnonzero(s.valid)
        depth = np.full(len(idx), np.inf)
        depth[sel] = vis.hidden_by(x[idx[sel]], y[idx[sel]], z[idx[sel]], visibility_table(vis)) + 1e-3 * s.cost[sel]
        better = depth < best
        if better.any():
            best[better] = depth[better]
            winner[better] = ci
    _fill_values(unit, cells, idx, winner, [None] * len(unit.cameras), fill_vals, counts)
    out[idx[np.isfinite(best)]] = True
    return out


def _fill_values(unit: TileUnit, cells: _Cells, idx: np.ndarray, winner: np.ndarray,
                 visibility: List[Optional[Visibility]], fill_vals: np.ndarray, counts: Dict[int, int]) -> None:
    """The values (with their radiometric gains) of the cells ``idx`` from the image ``winner`` picked for each
    (-1: none), sampled once per image and cell, into ``fill_vals``."""
    off, x, y, z = cells.offset, cells.x, cells.y, cells.z
    for ci in np.unique(winner[winner >= 0]):
        ci = int(ci)
        sel = idx[winner == ci]
        s = sample_camera(unit.cameras[ci], unit.metas[ci], off, x[sel], y[sel], z[sel], visibility[ci],
                          unit.interpolation)
        sel, vals = sel[s.valid], s.values[s.valid]  # all of them: the same test that picked the image
        fill_vals[sel] = vals * point_gains(unit.radiometry, unit.gains[ci], ci, unit.cameras[ci], s.xyz[s.valid],
                                            np.ones(len(sel), bool), s.px[s.valid])
        counts[ci] = counts.get(ci, 0) + len(sel)
