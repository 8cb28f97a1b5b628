"""The model's surface: a 2.5-D triangle mesh of a DSM, decimated to a face budget.

The DSM's cells become the vertices of a regular triangulation (two triangles per square of four cells with
heights: no face over a hole, no skirt).  The grid is first reduced by block means so that it has at most
``PRE_DECIMATION`` x the budget of faces (memory and time), then fast-simplification (quadric edge collapse,
Garland & Heckbert; wheels for Linux, Windows and macOS) takes it to the budget, keeping the detail where the
surface bends.  Without fast-simplification the grid is reduced to the budget directly (the same surface, coarser
where it is flat as well as where it bends)."""
from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

PRE_DECIMATION = 8  # faces of the reduced grid, times the budget, handed to the quadric decimation


def _simplifier():
    try:
        import fast_simplification
    except ImportError:
        return None
    return fast_simplification


def reduce_grid(z: np.ndarray, step: int) -> np.ndarray:
    """Block means of ``step`` x ``step`` cells (NaN = no height; a block with fewer than half its cells measured
    has none)."""
    if step <= 1:
        return z
    h, w = z.shape
    hh, ww = -(-h // step), -(-w // step)
    pad = np.full((hh * step, ww * step), np.nan)
    pad[:h, :w] = z
    blocks = pad.reshape(hh, step, ww, step)
    ok = np.isfinite(blocks)
    n = ok.sum(axis=(1, 3))
    s = np.where(ok, blocks, 0.0).sum(axis=(1, 3))
    cells = np.minimum(step, h - np.arange(hh)[:, None] * step) * np.minimum(step, w - np.arange(ww) * step)[None, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(2 * n >= cells, s / np.maximum(n, 1), np.nan)


def grid_mesh(z: np.ndarray, x0: float, y0: float, dx: float, dy: float) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices (N, 3) float64, faces (M, 3) int64) of a height grid whose cell (r, c) centre is at
    (x0 + c dx, y0 + r dy): two triangles per square of four heights, counter-clockwise seen from above."""
    h, w = z.shape
    ok = np.isfinite(z)
    index = np.full(z.shape, -1, dtype=np.int64)
    index[ok] = np.arange(int(ok.sum()))
    rr, cc = np.nonzero(ok)
    verts = np.column_stack([x0 + cc * dx, y0 + rr * dy, z[ok]])
    a, b = index[:-1, :-1], index[:-1, 1:]
    c, d = index[1:, :-1], index[1:, 1:]
    quad = (a >= 0) & (b >= 0) & (c >= 0) & (d >= 0)
    a, b, c, d = a[quad], b[quad], c[quad], d[quad]
    if dx * dy < 0:  # rows go south (a north-up raster): a b / c d is NW NE / SW SE
        faces = np.concatenate([np.column_stack([a, c, b]), np.column_stack([b, c, d])])
    else:
        faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([b, d, c])])
    return verts, faces


def compact(vertices: np.ndarray, faces: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The vertices that faces use, and the faces renumbered."""
    used, inverse = np.unique(faces.ravel(), return_inverse=True)
    return vertices[used], inverse.reshape(faces.shape).astype(np.int64)


def dsm_mesh(z: np.ndarray, geotransform, origin: np.ndarray, budget: int,
             cap: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray, int]:
    """(vertices local (N, 3) float64 = world - origin, faces (M, 3) int64, the grid step in cells) of a DSM
    (``z`` heights with NaN, its GDAL geotransform, north-up), at most ``budget`` faces.  ``cap``: the faces
    handed to the decimation at most (default ``PRE_DECIMATION`` x budget; 0 or no fast-simplification: the grid
    alone meets the budget)."""
    gt = geotransform
    simplify = _simplifier()
    cap = PRE_DECIMATION * budget if cap is None else cap
    target = cap if (simplify is not None and cap > budget) else budget
    n_cells = int(np.isfinite(z).sum())
    step = 1
    while 2 * n_cells / (step * step) > target * 1.02 and step < max(z.shape):
        step = max(step + 1, int(math.floor(step * math.sqrt(2 * n_cells / (step * step) / target))))
    while True:
        zr = reduce_grid(z, step)
        x0 = gt[0] + 0.5 * step * gt[1] - origin[0]
        y0 = gt[3] + 0.5 * step * gt[5] - origin[1]
        verts, faces = grid_mesh(zr - origin[2], x0, y0, step * gt[1], step * gt[5])
        if len(faces) <= target or step >= max(z.shape):
            break
        step += 1
    if len(faces) > budget and simplify is not None:
        pts, tri = simplify.simplify(verts, faces.astype(np.int32), target_count=budget, agg=7.0)
        verts, faces = np.asarray(pts, dtype=np.float64), np.asarray(tri, dtype=np.int64)
        keep = _non_degenerate(verts, faces)
        verts, faces = compact(verts, faces[keep])
    return verts, faces, step


def _non_degenerate(verts: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return (area2 > 1e-12) & (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])


def face_normals(verts: np.ndarray, faces: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """(unit normals (M, 3), areas (M,)) of the faces (counter-clockwise: the normal points out / up)."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    n = np.cross(b - a, c - a)
    norm = np.linalg.norm(n, axis=1)
    return n / np.maximum(norm, 1e-30)[:, None], 0.5 * norm


def vertex_normals(verts: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit normals (N, 3) float32 of the vertices: the area-weighted mean of their faces'."""
    fn, area = face_normals(verts, faces)
    out = np.zeros_like(verts, dtype=np.float64)
    for k in range(3):
        np.add.at(out, faces[:, k], fn * area[:, None])
    norm = np.linalg.norm(out, axis=1, keepdims=True)
    out = np.where(norm > 0, out / np.maximum(norm, 1e-30), np.array([0.0, 0.0, 1.0]))
    return out.astype(np.float32)
