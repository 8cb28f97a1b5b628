"""Output grids: tiles, cell centres, the cells under a box, and the resolution derived from the GSD."""
from __future__ import annotations

import math
from typing import Iterable, List, Optional, Tuple

import numpy as np

from ..io import raster as dsmmod
from .options import OrthoError


def grid_tiles(width: int, height: int, tile: int) -> List[Tuple[int, int, int, int]]:
    return [(r, c, min(tile, height - r), min(tile, width - c)) for r in range(0, height, tile)
            for c in range(0, width, tile)]


def cell_centre_coords(grid: dsmmod.Grid, r0: int, c0: int, h: int, w: int) -> Tuple[np.ndarray, np.ndarray]:
    xs = grid.x0 + (c0 + np.arange(w) + 0.5) * grid.resolution
    ys = grid.y0 - (r0 + np.arange(h) + 0.5) * grid.resolution
    gx, gy = np.meshgrid(xs, ys)
    return gx.ravel(), gy.ravel()


def subgrid(grid: dsmmod.Grid, bbox: Tuple[float, float, float, float]) -> Optional[Tuple[int, int, int, int]]:
    """(row0, col0, height, width) of the cells of ``grid`` covering ``bbox``, clipped; None if disjoint."""
    res = grid.resolution
    c0 = max(0, int(math.floor((bbox[0] - grid.x0) / res)))
    c1 = min(grid.width, int(math.ceil((bbox[2] - grid.x0) / res)))
    r0 = max(0, int(math.floor((grid.y0 - bbox[3]) / res)))
    r1 = min(grid.height, int(math.ceil((grid.y0 - bbox[1]) / res)))
    if c1 <= c0 or r1 <= r0:
        return None
    return r0, c0, r1 - r0, c1 - c0


def box_intersects(a, b) -> bool:
    return not (a[2] <= b[0] or a[0] >= b[2] or a[3] <= b[1] or a[1] >= b[3])


def nice_number(gsd: float) -> float:
    """GSD rounded to 2 significant digits."""
    if gsd <= 0 or not math.isfinite(gsd):
        raise OrthoError(f"cannot derive a resolution from a ground sample distance of {gsd}")
    e = math.floor(math.log10(gsd)) - 1
    return round(gsd / 10 ** e) * 10 ** e


def box_union(boxes: Iterable[Tuple[float, float, float, float]]) -> Tuple[float, float, float, float]:
    b = np.array(list(boxes), dtype=float)
    return float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()), float(b[:, 3].max())


def format_box(b) -> str:
    return f"[{b[0]:.1f}, {b[1]:.1f}] - [{b[2]:.1f}, {b[3]:.1f}]"
