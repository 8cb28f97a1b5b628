"""OGC 3D Tiles 1.1 from a :class:`~.types.TexturedMesh`: ``tileset.json`` and binary glTF (GLB) tile contents.

- **Placement**: the root tile's ``transform`` takes a local east-north-up (ENU) frame at the model's centre to
  ECEF (EPSG:4978, WGS 84 geocentric).  Every vertex goes world (the mesh's CRS) -> ECEF through GDAL/PROJ
  (:func:`core.geometry.crs.transform_points`) -> that ENU frame, so the map projection's grid convergence and
  scale factor are handled exactly, not approximated by one rotation.  The GLB stores ENU as glTF's y-up axes
  (x = east, y = up, z = -north): 3D Tiles turns glTF content from y-up to z-up before the tile's transform.
- **Levels of detail**: a quadtree over the footprint; the leaves hold the full mesh, each parent level the mesh
  simplified by vertex clustering on a grid twice as coarse as the level below (the cell size is the level's
  geometric error), with its own texture: the atlas' pieces under its charts, packed and downscaled to match;
  ``refine`` REPLACE.
  Vertex clustering is written here (NumPy, no dependency) because it keeps the texture right: vertices merge
  only inside one UV chart (a connected part of the mesh; the writers duplicate vertices at chart seams), all
  vertices of a grid cell share one position, so the seams do not open, and each chart's uv is carried to that
  position along the chart's own uv gradient.
- A block in a model frame (no CRS) has no place on the globe: :class:`TilesError` before any work.

The whole tileset is written into a temporary folder beside ``folder`` and swapped in on success
(:func:`core.common.files.atomic_output`): a failed or cancelled run leaves the previous tileset as it was.

For the model stage: :func:`check_georeferenced` (before any work, when 3D Tiles are asked for) and
:func:`write_model_tiles` (``<model folder>/tiles/tileset.json``, whose path the stage lists in its files: Build
3-D model loads it as a tiled scene layer on QGIS 3.34+).
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output
from ..common.progress import Progress, check_cancel
from ..geometry.crs import transform_points
from .types import MeshPart, TexturedMesh
from .writers import encode_image, glb_bytes

ECEF = "EPSG:4978"
MAX_LEVELS = 6  # a 64 x 64 quadtree of leaves: far more than a site needs
LEAF_FACES = 20000  # faces a tile holds at most, about: a viewer draws a few hundred such tiles fluidly
TILES_DIR = "tiles"  # the model stage's tileset: <model folder>/tiles/tileset.json


class TilesError(ArchaeoOrthoError, ValueError):
    """A model that cannot be written as 3D Tiles (no CRS, no faces, bad settings)."""


@dataclass
class TilesetResult:
    tileset: str  # path of tileset.json
    tiles: int  # tiles with content
    levels: int  # quadtree levels (1 = the root alone)
    content: List[str] = field(default_factory=list)  # the GLB files, relative to the tileset's folder
    geometric_errors: List[float] = field(default_factory=list)  # per level, root first (metres)


@dataclass
class EnuFrame:
    """A local east-north-up frame: ``ecef = centre + rotation @ enu`` (rotation's columns: east, north, up)."""

    centre: np.ndarray  # (3,) ECEF metres
    rotation: np.ndarray  # (3, 3)

    def to_enu(self, ecef: np.ndarray) -> np.ndarray:
        return (np.asarray(ecef, dtype=np.float64) - self.centre[None, :]) @ self.rotation

    def matrix(self) -> List[float]:
        """The 4 x 4 ENU -> ECEF transform, column-major, as 3D Tiles' ``transform`` wants it."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.centre
        return [float(v) for v in m.T.ravel()]


def geodetic_lonlat(ecef: np.ndarray) -> Tuple[float, float]:
    """(longitude, latitude) in radians on the WGS 84 ellipsoid of an ECEF point (Bowring's iteration)."""
    a, f = 6378137.0, 1.0 / 298.257223563
    e2 = f * (2.0 - f)
    x, y, z = (float(v) for v in ecef)
    p = math.hypot(x, y)
    lat = math.atan2(z, p * (1.0 - e2))
    for _ in range(5):
        n = a / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
        h = p / math.cos(lat) - n
        lat = math.atan2(z, p * (1.0 - e2 * n / (n + h)))
    return math.atan2(y, x), lat


def enu_frame(mesh: TexturedMesh) -> EnuFrame:
    """The ENU frame at the centre of the model's bounding box (world coordinates -> ECEF through its CRS)."""
    lo = np.min([p.vertices.min(axis=0) for p in mesh.parts if len(p.vertices)], axis=0).astype(np.float64)
    hi = np.max([p.vertices.max(axis=0) for p in mesh.parts if len(p.vertices)], axis=0).astype(np.float64)
    centre = transform_points(np.asarray(mesh.origin, np.float64) + (lo + hi) / 2.0, mesh.crs_wkt, ECEF)
    lon, lat = geodetic_lonlat(centre)
    sl, cl, sp, cp = math.sin(lon), math.cos(lon), math.sin(lat), math.cos(lat)
    rot = np.array([[-sl, -sp * cl, cp * cl],
                    [cl, -sp * sl, cp * sl],
                    [0.0, cp, sp]])
    return EnuFrame(centre=np.asarray(centre, np.float64), rotation=rot)


def check_georeferenced(crs: Optional[str]) -> None:
    """TilesError for a block in a model frame (no CRS): 3D Tiles are placed on the globe.  The stage calls it
    before any work when 3D Tiles are asked for."""
    if not crs:
        raise TilesError(
            "3D Tiles need a georeferenced model: this block is in a model frame (no CRS: it was not "
            "georeferenced with control points or GPS), so it has no place on the globe. Leave 3D Tiles out of "
            "the files (OBJ, GLB and PLY are written in the model frame), or run Georeference first")


def check_tileable(mesh: TexturedMesh, leaf_faces: int, max_texture: int) -> None:
    """TilesError for a model 3D Tiles cannot hold, before any work."""
    check_georeferenced(mesh.crs_wkt)
    if mesh.face_count == 0:
        raise TilesError("the model has no faces: nothing to write as 3D Tiles")
    if leaf_faces < 100:
        raise TilesError(f"faces per tile must be at least 100 (got {leaf_faces})")
    if max_texture < 64:
        raise TilesError(f"the largest tile texture must be at least 64 pixels (got {max_texture})")


# ---------------------------------------------------------------------------------------------------- geometry

@dataclass
class _Level:
    """One part at one level of detail, in ENU: vertices (float64), faces, uv and the faces' centroids (e, n)."""

    vertices: np.ndarray
    faces: np.ndarray
    uv: Optional[np.ndarray]
    centroids: np.ndarray


def chart_ids(n_vertices: int, faces: np.ndarray) -> np.ndarray:
    """Connected component of every vertex through the faces (a UV chart: seams have duplicated vertices)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = np.asarray(faces, dtype=np.int64)
    rows = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    cols = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    graph = coo_matrix((np.ones(len(rows), np.int8), (rows, cols)), shape=(n_vertices, n_vertices))
    return connected_components(graph, directed=False)[1]


def uv_gradients(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(N, 2, 3): per vertex, how its chart's uv changes with position (the mean over its faces of each face's
    linear map, least-norm: no change along the face's normal)."""
    p, t = vertices[faces], uv[faces]
    e = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2)  # (M, 3, 2)
    d = np.stack([t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]], axis=2)  # (M, 2, 2)
    g = np.einsum("mki,mkj->mij", e, e)
    det = g[:, 0, 0] * g[:, 1, 1] - g[:, 0, 1] * g[:, 1, 0]
    ok = np.abs(det) > 1e-12 * np.maximum(g[:, 0, 0] * g[:, 1, 1], 1e-300)
    inv = np.zeros_like(g)
    inv[ok, 0, 0], inv[ok, 1, 1] = g[ok, 1, 1] / det[ok], g[ok, 0, 0] / det[ok]
    inv[ok, 0, 1], inv[ok, 1, 0] = -g[ok, 0, 1] / det[ok], -g[ok, 1, 0] / det[ok]
    jac = np.einsum("mij,mjk,mlk->mil", d, inv, e)  # d (E^T E)^-1 E^T: (M, 2, 3)
    out = np.zeros((len(vertices), 2, 3))
    count = np.zeros(len(vertices))
    for k in range(3):
        np.add.at(out, faces[ok, k], jac[ok])
        np.add.at(count, faces[ok, k], 1.0)
    return out / np.maximum(count, 1.0)[:, None, None]


def _seam_vertices(vertices: np.ndarray, charts: np.ndarray) -> np.ndarray:
    """True for the vertices whose position another chart's vertex shares (a seam: duplicated by the texturer)."""
    key = np.round(vertices / 1e-4).astype(np.int64)
    _, at = np.unique(key, axis=0, return_inverse=True)
    at = at.ravel()
    pairs = np.unique(np.column_stack([at, charts]), axis=0)
    return np.bincount(pairs[:, 0], minlength=int(at.max()) + 1)[at] > 1


def cluster(vertices: np.ndarray, faces: np.ndarray, uv: Optional[np.ndarray], charts: np.ndarray,
            cell: float, gradients: Optional[np.ndarray] = None) -> Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]:
    """Vertex clustering on a grid of ``cell`` metres.  A cell's vertices all move to one of them, the nearest to
    their mean, a seam vertex where the cell has one: so the seams between charts stay closed, and every chart
    meeting there has a vertex at that very place.  They merge into one vertex per UV chart, whose uv is the
    chart's at that position (its vertices' uv carried there along ``gradients``, :func:`uv_gradients`; without
    them, their mean).  Faces that collapse, and repeated faces, are dropped."""
    q = np.floor((vertices - vertices.min(axis=0)) / cell).astype(np.int64)
    q = (q[:, 0] << 42) | (q[:, 1] << 21) | q[:, 2]  # < 2**21 cells an axis: far more than any level has
    _, cell_of = np.unique(q, return_inverse=True)
    cell_of = cell_of.ravel()
    n_cells = int(cell_of.max()) + 1
    counts = np.bincount(cell_of, minlength=n_cells).astype(np.float64)
    mean = np.stack([np.bincount(cell_of, vertices[:, k], n_cells) for k in range(3)], axis=1) / counts[:, None]
    score = np.linalg.norm(vertices - mean[cell_of], axis=1) + np.where(_seam_vertices(vertices, charts), 0.0, 4 * cell)
    order = np.lexsort((score, cell_of))
    first = np.ones(len(order), bool)
    first[1:] = cell_of[order][1:] != cell_of[order][:-1]
    pos = vertices[order[first]]  # one per cell, in cell order
    n_charts = int(charts.max()) + 1
    uniq, new_of = np.unique(cell_of.astype(np.int64) * n_charts + charts, return_inverse=True)
    new_of = new_of.ravel()
    new_vertices = pos[uniq // n_charts]
    new_uv = None
    if uv is not None:
        carried = uv if gradients is None else uv + np.einsum("nij,nj->ni", gradients, pos[cell_of] - vertices)
        n_new = len(uniq)
        c = np.bincount(new_of, minlength=n_new).astype(np.float64)
        new_uv = np.stack([np.bincount(new_of, carried[:, k], n_new) for k in range(2)], axis=1) / c[:, None]
    f = new_of[faces]
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f = f[keep]
    _, firsts = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
    return new_vertices, f[np.sort(firsts)], new_uv


def _median_edge(parts: List[Tuple[np.ndarray, np.ndarray]]) -> float:
    edges = [np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1) for v, f in parts if len(f)]
    e = np.concatenate(edges)
    e = e[e > 0]
    return float(np.median(e)) if len(e) else 1.0


def _levels(parts_enu: List[Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]], n_levels: int,
            edge: float) -> Tuple[List[List[_Level]], List[float]]:
    """Per level (root first) the parts' meshes, and the level's geometric error (0 for the leaves)."""
    charts = [chart_ids(len(v), f) for v, f, _ in parts_enu]
    grads = [uv_gradients(v, f, uv) if uv is not None and n_levels > 1 else None for v, f, uv in parts_enu]
    levels, errors = [], []
    for d in range(n_levels):
        cell = edge * 2.0 ** (n_levels - 1 - d)
        level = []
        for (v, f, uv), ch, grad in zip(parts_enu, charts, grads):
            if d < n_levels - 1:
                v, f, uv = cluster(v, f, uv, ch, cell, grad)
            level.append(_Level(v, f, uv, v[f].mean(axis=1)[:, :2] if len(f) else np.zeros((0, 2))))
        levels.append(level)
        errors.append(cell if d < n_levels - 1 else 0.0)
    return levels, errors


# ---------------------------------------------------------------------------------------------------- textures

def _shelves(sizes: np.ndarray, order: np.ndarray, width: int) -> Tuple[np.ndarray, int, int]:
    corners = np.zeros_like(sizes)
    x = y = shelf = used = 0
    for i in order:
        w, h = int(sizes[i, 0]), int(sizes[i, 1])
        if x + w > width:
            x, y, shelf = 0, y + shelf, 0
        corners[i] = (x, y)
        x += w
        used = max(used, x)
        shelf = max(shelf, h)
    return corners, used, y + shelf


def _pack(sizes: np.ndarray) -> Tuple[np.ndarray, int, int]:
    """Shelf packing of rectangles (w, h), tallest first, on the canvas width (of a few tried) that gives the
    smallest canvas: their top-left corners and the canvas' width and height."""
    order = np.argsort(-sizes[:, 1], kind="stable")
    root = math.sqrt(float((sizes[:, 0] * sizes[:, 1]).sum()))
    widths = {int(sizes[:, 0].max()), int(sizes[:, 0].sum())} | {int(math.ceil(root * k)) for k in (1.0, 1.2, 1.5, 2.0)}
    best = None
    for width in sorted(w for w in widths if w >= sizes[:, 0].max()):
        corners, w, h = _shelves(sizes, order, width)
        if best is None or (w * h, max(w, h)) < (best[1] * best[2], max(best[1], best[2])):
            best = (corners, w, h)
    return best


def _tile_texture(atlas: np.ndarray, uv: np.ndarray, faces: np.ndarray, shrink: float, max_texture: int
                  ) -> Tuple[np.ndarray, np.ndarray]:
    """A tile's own texture: the atlas' rectangles under the tile's charts (each with a margin of 2 pixels of the
    tile's texture), packed side by side, scaled down by ``shrink`` (and to at most ``max_texture`` pixels a side);
    the uv remapped to it.  Charts lie anywhere in the model's atlas, so a crop of the tile's uv bounding box could
    be the whole atlas for a small tile."""
    import cv2

    h, w = atlas.shape[:2]
    px = uv * np.array([w, h], np.float64)
    charts = chart_ids(len(uv), faces)
    n = int(charts.max()) + 1
    lo = np.full((n, 2), np.inf)
    hi = np.full((n, 2), -np.inf)
    np.minimum.at(lo, charts, px)
    np.maximum.at(hi, charts, px)
    margin = int(math.ceil(2 * max(shrink, 1.0)))
    lo = np.clip(np.floor(lo).astype(np.int64) - margin, 0, [w - 1, h - 1])
    hi = np.clip(np.ceil(hi).astype(np.int64) + margin, lo + 1, [w, h])
    corners, cw, ch = _pack(hi - lo)
    canvas = np.zeros((ch, cw, atlas.shape[2]), atlas.dtype)
    for (x0, y0), (x1, y1), (cx, cy) in zip(lo, hi, corners):
        canvas[cy:cy + y1 - y0, cx:cx + x1 - x0] = atlas[y0:y1, x0:x1]
    new_px = px - lo[charts] + corners[charts]
    scale = min(1.0 / shrink, max_texture / max(cw, ch))
    if scale < 1.0:
        size = (max(int(round(cw * scale)), 1), max(int(round(ch * scale)), 1))
        canvas = cv2.resize(canvas, size, interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(canvas), new_px / np.array([cw, ch], np.float64)


# ---------------------------------------------------------------------------------------------------- tileset

def _enu_parts(mesh: TexturedMesh, frame: EnuFrame) -> List[Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]]:
    out = []
    for part in mesh.parts:
        if not len(part.faces):
            continue
        ecef = transform_points(mesh.world_vertices(part), mesh.crs_wkt, ECEF)
        uv = part.uv.astype(np.float64) if part.uv is not None and part.atlas is not None else None
        out.append((frame.to_enu(ecef), np.asarray(part.faces, dtype=np.int64), uv))
    return out


def _tile_content(level: List[_Level], picks: List[np.ndarray], atlases: List[Optional[np.ndarray]], shrink: float,
                  max_texture: int, quality: int) -> Tuple[Optional[bytes], Optional[np.ndarray]]:
    """GLB of the faces selected by ``picks`` (face indices, one array per part), and their ENU bounds (2, 3);
    (None, None) if empty."""
    parts, images, lo, hi = [], [], [], []
    for lv, pick, atlas in zip(level, picks, atlases):
        if not len(pick):
            continue
        used, inverse = np.unique(lv.faces[pick], return_inverse=True)
        enu = lv.vertices[used]
        lo.append(enu.min(axis=0))
        hi.append(enu.max(axis=0))
        part = MeshPart(vertices=enu.astype(np.float32), faces=inverse.reshape(-1, 3).astype(np.uint32))
        images.append(None)
        if lv.uv is not None and atlas is not None:
            part.atlas, uv = _tile_texture(atlas, lv.uv[used], part.faces, shrink, max_texture)
            part.uv = uv.astype(np.float32)
            images[-1] = encode_image(part.atlas, "jpeg", quality)
        parts.append(part)
    if not parts:
        return None, None
    return glb_bytes(parts, y_up=True, images=images), np.array([np.min(lo, axis=0), np.max(hi, axis=0)])


def _by_cell(centroids: np.ndarray, lo: np.ndarray, span: np.ndarray, n: int) -> Tuple[np.ndarray, np.ndarray]:
    """The faces grouped by the n x n grid cell their centroid is in: (face indices sorted by cell, where each
    cell's run starts: cell k = iy * n + ix holds order[starts[k]:starts[k + 1]])."""
    cell = np.clip(np.floor((centroids - lo) / span * n).astype(np.int64), 0, n - 1)
    key = cell[:, 1] * n + cell[:, 0] if len(cell) else np.zeros(0, np.int64)
    order = np.argsort(key, kind="stable")
    return order, np.searchsorted(key[order], np.arange(n * n + 1))


def _box(bounds: np.ndarray) -> List[float]:
    c = bounds.mean(axis=0)
    h = np.maximum((bounds[1] - bounds[0]) / 2.0, 0.01)  # a flat model still gets a box with thickness
    return [float(c[0]), float(c[1]), float(c[2]), float(h[0]), 0.0, 0.0, 0.0, float(h[1]), 0.0, 0.0, 0.0,
            float(h[2])]


def write_tiles(mesh: TexturedMesh, folder: str, leaf_faces: int = LEAF_FACES, max_texture: int = 2048,
                quality: int = 90, progress: Optional[Progress] = None) -> TilesetResult:
    """Write ``folder``/tileset.json and ``folder``/content/<level>/<x>_<y>.glb (see the module's docstring).
    ``leaf_faces``: about how many faces a tile holds (sets the quadtree's depth); ``max_texture``: the largest
    side of a tile's texture in pixels; ``quality``: the textures' JPEG quality."""
    check_tileable(mesh, leaf_faces, max_texture)
    frame = enu_frame(mesh)
    parts_enu = _enu_parts(mesh, frame)
    atlases = [p.atlas if p.uv is not None else None for p in mesh.parts if len(p.faces)]
    n_levels = min(max(int(math.ceil(math.log(max(mesh.face_count / leaf_faces, 1.0), 4))), 0), MAX_LEVELS - 1) + 1
    levels, errors = _levels(parts_enu, n_levels, _median_edge([(v, f) for v, f, _ in parts_enu]))
    lo = np.min([v.min(axis=0) for v, _, _ in parts_enu], axis=0)
    hi = np.max([v.max(axis=0) for v, _, _ in parts_enu], axis=0)
    span = np.maximum(hi[:2] - lo[:2], 1e-6)
    result = TilesetResult(tileset=os.path.join(folder, "tileset.json"), tiles=0, levels=n_levels,
                           geometric_errors=errors)
    groups = [[_by_cell(lv.centroids, lo[:2], span, 2 ** d) for lv in level] for d, level in enumerate(levels)]
    total = sum(4 ** d for d in range(n_levels))
    done = [0]
    with atomic_output(folder) as tmp:
        def build(d: int, ix: int, iy: int) -> Optional[Tuple[Dict, np.ndarray]]:
            check_cancel(progress)
            n = 2 ** d
            picks = [order[starts[iy * n + ix]:starts[iy * n + ix + 1]] for order, starts in groups[d]]
            children = [c for c in (build(d + 1, 2 * ix + a, 2 * iy + b) for b in (0, 1) for a in (0, 1))
                        if c is not None] if d + 1 < n_levels else []
            glb, bounds = _tile_content(levels[d], picks, atlases, 2.0 ** (n_levels - 1 - d), max_texture,
                                         quality)
            done[0] += 1
            if progress is not None:
                progress.report(done[0] / total, f"3D Tiles: level {d + 1} of {n_levels}")
            if glb is None and not children:
                return None
            tile: Dict = {"geometricError": errors[d], "refine": "REPLACE"}
            all_bounds = [b for b in [bounds] + [c[1] for c in children] if b is not None]
            box = np.array([np.min([b[0] for b in all_bounds], axis=0), np.max([b[1] for b in all_bounds], axis=0)])
            tile["boundingVolume"] = {"box": _box(box)}
            if glb is not None:
                uri = f"content/{d}/{ix}_{iy}.glb"
                os.makedirs(os.path.join(tmp, "content", str(d)), exist_ok=True)
                with open(os.path.join(tmp, uri), "wb") as f:
                    f.write(glb)
                tile["content"] = {"uri": uri}
                result.content.append(uri)
            if children:
                tile["children"] = [c[0] for c in children]
            return tile, box

        os.makedirs(tmp, exist_ok=True)
        root, box = build(0, 0, 0)
        root["transform"] = frame.matrix()
        diagonal = float(np.linalg.norm(box[1] - box[0]))
        tileset = {"asset": {"version": "1.1", "generator": "ArchaeoOrtho"},
                   "geometricError": max(diagonal, errors[0] * 2.0, 1.0), "root": root}
        with open(os.path.join(tmp, "tileset.json"), "w", encoding="utf-8") as f:
            json.dump(tileset, f, indent=1)
    result.tiles = len(result.content)
    result.content.sort()
    return result


def write_model_tiles(mesh: TexturedMesh, folder: str, max_texture: int = 2048, quality: int = 90,
                      progress: Optional[Progress] = None) -> List[str]:
    """The model stage's 3D Tiles: ``folder``/tiles/tileset.json (and its content/), about LEAF_FACES faces a tile,
    textures of at most ``max_texture`` pixels (the stage's atlas size); returns [the tileset's path], which is
    ``tiles/tileset.json`` under ``folder`` (a stage writing into a temporary folder maps it by its path relative
    to that folder, not by its base name).  Call :func:`check_georeferenced` before any work."""
    result = write_tiles(mesh, os.path.join(folder, TILES_DIR), LEAF_FACES, max_texture, quality, progress)
    return [result.tileset]


__all__ = ["ECEF", "LEAF_FACES", "TILES_DIR", "EnuFrame", "TilesError", "TilesetResult", "check_georeferenced",
           "check_tileable", "chart_ids", "cluster", "enu_frame", "geodetic_lonlat", "uv_gradients", "write_model_tiles",
           "write_tiles"]
