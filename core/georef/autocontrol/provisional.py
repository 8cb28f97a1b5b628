"""A provisional orthophoto of an aligned block, made in the model's own geometry.

``Frame``: the model moved into a level frame (z up): through a prior (rough camera positions, or a similarity
guess) into the reference CRS (world = frame + offset), or, with no prior at all, the frame of the sparse
points' plane (unknown scale, rotation and position: the match finds them).  ``rough_surface``: the sparse points'
median height per cell (holes filled).  ``provisional_ortho``: every cell of a grid over the block, on the rough
surface, projected into the photos (full camera model) and sampled from the most central view; each cell keeps
which photo and which pixel it came from, so that a match in the orthophoto leads back to a photo observation
exactly (an error of the rough surface moves where a thing appears in the orthophoto, not what it is).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Mapping, Optional, Sequence

import numpy as np

from ...common.errors import require
from ...common.progress import NullProgress, Progress, check_cancel
from ...geometry.camera import project_in_image
from ...geometry.similarity import Similarity, helmert_ransac
from ...io.gcp import CameraPosition
from ...io.raster import push_pull
from .errors import AutoControlError


@dataclass
class Frame:
    """``model_to_frame``: the model into a level frame (z up); ``offset``: world = frame + offset when the frame
    is the reference CRS (a prior), None for a level frame of unknown scale, rotation and position."""

    model_to_frame: Similarity
    offset: Optional[np.ndarray] = None

    @property
    def metric(self) -> bool:
        return self.offset is not None


def registered(rec) -> List:
    return sorted((rec.image(i) for i in rec.reg_image_ids()), key=lambda im: im.name)


def camera_centres(rec) -> Dict[str, np.ndarray]:
    out = {}
    for im in registered(rec):
        m = np.asarray(im.cam_from_world().matrix())
        out[im.name] = -m[:, :3].T @ m[:, 3]
    return out


def sparse_points(rec) -> np.ndarray:
    return np.array([p.xyz for p in rec.points3D.values()], dtype=float).reshape(-1, 3)


def level_frame(rec) -> Frame:
    """The frame of the sparse points' best plane: origin at their centroid, z along its normal towards the
    cameras, scale and the azimuth of x unknown (those of the model)."""
    pts = sparse_points(rec)
    if len(pts) < 10:
        raise AutoControlError(f"the aligned model has {len(pts)} tie points: too few to make an orthophoto of")
    c = np.median(pts, axis=0)
    _, _, vt = np.linalg.svd(pts - c, full_matrices=False)
    n = vt[2]
    cams = np.array(list(camera_centres(rec).values()))
    if (cams.mean(axis=0) - c) @ n < 0:
        n = -n
    e1 = vt[0] - (vt[0] @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    r = np.vstack([e1, e2, n])
    return Frame(Similarity(1.0, r, -r @ c), None)


def frame_from_positions(rec, positions: Sequence[CameraPosition], threshold: Optional[float] = None) -> Frame:
    """The prior of rough camera positions (world coordinates of the reference CRS, e.g. EXIF GPS): a robust
    similarity model -> world - offset of the camera centres; a position is an inlier within ``threshold`` (None:
    3 x the positions' median 3-D sigma, 33.5 m for EXIF GPS's 5 m / 10 m; was 30 m whatever the positions)."""
    centres = camera_centres(rec)
    rows = [(centres[p.image], np.array([p.x, p.y, p.z], dtype=float)) for p in positions if p.image in centres]
    if len(rows) < 2:
        raise AutoControlError(f"a prior from camera positions needs 2 of the block's photos; {len(rows)} matched")
    src = np.array([a for a, _ in rows])
    dst = np.array([b for _, b in rows])
    offset = np.round(dst.mean(axis=0), 0)
    if len(rows) == 2:  # a pair: its baseline gives scale and azimuth, the tie points' plane the vertical
        return _frame_from_pair(rec, src, dst - offset, offset)
    if threshold is None:
        threshold = 3.0 * float(np.median([math.hypot(p.sigma_xy, p.sigma_z) for p in positions
                                           if p.image in centres]))
    fit = helmert_ransac(src, dst - offset, threshold)
    return Frame(fit.transform, offset)


def _frame_from_pair(rec, src: np.ndarray, dst: np.ndarray, offset: np.ndarray) -> Frame:
    """The prior of two camera positions: the level frame (z along the tie points' plane normal) turned, scaled
    and moved so that the two cameras' horizontal baseline lands on theirs, heights on their mean."""
    lev = level_frame(rec)
    a = lev.model_to_frame.apply(src)
    da, db = a[1, :2] - a[0, :2], dst[1, :2] - dst[0, :2]
    la, lb = float(np.hypot(*da)), float(np.hypot(*db))
    if la <= 0 or lb <= 0:
        raise AutoControlError("a prior from two camera positions needs them apart (the two photos' positions "
                               "coincide)")
    scale = lb / la
    turn = math.atan2(db[1], db[0]) - math.atan2(da[1], da[0])
    r = np.array([[math.cos(turn), -math.sin(turn), 0.0], [math.sin(turn), math.cos(turn), 0.0], [0.0, 0.0, 1.0]])
    moved = scale * a @ r.T
    t = (dst - moved).mean(axis=0)
    if not np.all(np.isfinite(dst[:, 2])):
        t[2] = 0.0
    return Frame(Similarity(scale, r, t).compose(lev.model_to_frame), offset)


@dataclass
class Surface:
    """Heights of the frame on a grid: x0, y0 the upper-left corner, ``cell`` the cell size."""

    x0: float
    y0: float
    cell: float
    z: np.ndarray

    def sample(self, x, y) -> np.ndarray:
        cv2 = require("cv2", "the automatic control")
        mx = ((np.asarray(x, dtype=float) - self.x0) / self.cell - 0.5).astype(np.float32)
        my = ((self.y0 - np.asarray(y, dtype=float)) / self.cell - 0.5).astype(np.float32)
        return _remap(cv2, self.z.astype(np.float32), mx, my).astype(np.float64)


def _remap(cv2, img: np.ndarray, mx: np.ndarray, my: np.ndarray, interpolation=None, border=None) -> np.ndarray:
    """cv2.remap of maps of any shape (flattened into rows of 1024: OpenCV limits a map's size)."""
    shape = mx.shape
    n = mx.size
    rows = max(1, -(-n // 1024))
    pad = rows * 1024 - n
    fx = np.pad(mx.reshape(-1), (0, pad), constant_values=-1e4).reshape(rows, 1024).astype(np.float32)
    fy = np.pad(my.reshape(-1), (0, pad), constant_values=-1e4).reshape(rows, 1024).astype(np.float32)
    out = cv2.remap(img, fx, fy, cv2.INTER_LINEAR if interpolation is None else interpolation,
                    borderMode=cv2.BORDER_REPLICATE if border is None else border)
    return out.reshape(-1)[:n].reshape(shape)


def rough_surface(rec, frame: Frame, cell: float) -> Surface:
    """The sparse points' median frame height per ``cell``, holes filled (``push_pull``), a 3 x 3 median."""
    cv2 = require("cv2", "the automatic control")
    p = frame.model_to_frame.apply(sparse_points(rec))
    lo, hi = np.percentile(p[:, :2], 0.5, axis=0), np.percentile(p[:, :2], 99.5, axis=0)
    pad = 0.25 * (hi - lo) + cell
    lo, hi = lo - pad, hi + pad
    nx, ny = int(math.ceil((hi[0] - lo[0]) / cell)), int(math.ceil((hi[1] - lo[1]) / cell))
    col = np.clip(((p[:, 0] - lo[0]) / cell).astype(int), 0, nx - 1)
    row = np.clip(((hi[1] - p[:, 1]) / cell).astype(int), 0, ny - 1)
    idx = row * nx + col
    order = np.lexsort((p[:, 2], idx))
    idx_s, z_s = idx[order], p[order, 2]
    starts = np.flatnonzero(np.r_[True, idx_s[1:] != idx_s[:-1]])
    counts = np.diff(np.r_[starts, len(idx_s)])
    grid = np.zeros(nx * ny)
    known = np.zeros(nx * ny, dtype=bool)
    grid[idx_s[starts]] = z_s[starts + counts // 2]
    known[idx_s[starts]] = True
    z = push_pull(grid.reshape(ny, nx), known.reshape(ny, nx)).astype(np.float32)
    z = cv2.medianBlur(z, 3) if min(z.shape) >= 3 else z
    return Surface(float(lo[0]), float(hi[1]), float(cell), z)


@dataclass
class ProvisionalOrtho:
    """The provisional orthophoto: ``grey`` (uint8), ``valid``; the grid (upper-left x0, y0 and ``res`` in the
    frame); per cell the photo it came from (``best``: index into ``names``, -1 none) and that photo's pixel
    (``u``, ``v``, COLMAP convention); the ``surface`` it was made on."""

    grey: np.ndarray
    valid: np.ndarray
    x0: float
    y0: float
    res: float
    best: np.ndarray
    u: np.ndarray
    v: np.ndarray
    names: List[str]
    surface: Surface

    def frame_xy(self, col, row):
        """Frame x, y of OpenCV pixel coordinates (the centre of pixel (0, 0) at (0, 0))."""
        return self.x0 + (np.asarray(col) + 0.5) * self.res, self.y0 - (np.asarray(row) + 0.5) * self.res


def project(rec, im, xyz_model: np.ndarray, margin: float = 0.0):
    """(pixels (N, 2), inside (N,), centrality (N,)) of model points in image ``im``: the one rule of
    ``geometry.camera.project_in_image`` (in front, within the lens model's trusted radius, inside the frame by
    ``margin`` pixels; centrality 0 at the centre, 1 at a corner)."""
    return project_in_image(rec.cameras[im.camera_id], im.cam_from_world().matrix(), xyz_model, margin)


def block_extent(rec, frame: Frame):
    p = frame.model_to_frame.apply(sparse_points(rec))
    lo, hi = np.percentile(p[:, :2], 1.0, axis=0), np.percentile(p[:, :2], 99.0, axis=0)
    pad = 0.08 * (hi - lo)
    return float(lo[0] - pad[0]), float(lo[1] - pad[1]), float(hi[0] + pad[0]), float(hi[1] + pad[1])


def read_photo(path: str) -> np.ndarray:
    cv2 = require("cv2", "the automatic control")
    img = cv2.imread(path, cv2.IMREAD_GRAYSCALE | cv2.IMREAD_IGNORE_ORIENTATION) if path else None
    if img is None:
        raise AutoControlError(f"cannot read photo {path}: missing, or not an image OpenCV reads")
    return img


@dataclass(frozen=True)
class _Grid:
    """A north-up grid of the frame: upper-left corner (``x0``, ``y0``), cells ``res`` wide, ``nx`` x ``ny``."""

    x0: float
    y0: float
    res: float
    nx: int
    ny: int

    def xy(self, cols, rows):
        """Frame x, y of the centres of cells (``cols``, ``rows``)."""
        return self.x0 + (cols + 0.5) * self.res, self.y0 - (rows + 0.5) * self.res


def provisional_ortho(rec, frame: Frame, photos: Mapping[str, str], res: float,
                      progress: Optional[Progress] = None, extent=None) -> ProvisionalOrtho:
    """The provisional orthophoto of the block at ``res`` frame units per pixel (see the module notes);
    ``photos``: {image name: path}."""
    cv2 = require("cv2", "the automatic control")
    progress = progress or NullProgress()
    xmin, ymin, xmax, ymax = extent or block_extent(rec, frame)
    nx, ny = max(8, int(math.ceil((xmax - xmin) / res))), max(8, int(math.ceil((ymax - ymin) / res)))
    surface = rough_surface(rec, frame, max(res * 16, (xmax - xmin) / 200.0))
    to_model = frame.model_to_frame.inverse()
    images = [im for im in registered(rec) if im.name in photos]
    if not images:
        raise AutoControlError("none of the aligned photos is in the workspace's image list with a path")
    best = np.full((ny, nx), -1, dtype=np.int16)
    score = np.full((ny, nx), np.inf, dtype=np.float32)
    u = np.zeros((ny, nx), dtype=np.float32)
    v = np.zeros((ny, nx), dtype=np.float32)
    step = 8
    for k, im in enumerate(images):
        check_cancel(progress)
        progress.report(0.5 * k / len(images), f"provisional orthophoto: projecting {im.name}")
        rows, cols = _footprint(rec, im, to_model, surface, _Grid(xmin, ymax, res, nx, ny), step)
        if rows is None:
            continue
        cc, rr = np.meshgrid(np.arange(cols.start, cols.stop), np.arange(rows.start, rows.stop))
        x, y = xmin + (cc + 0.5) * res, ymax - (rr + 0.5) * res
        z = surface.sample(x, y)
        px, inside, cen = project(rec, im, to_model.apply(np.column_stack([x.ravel(), y.ravel(), z.ravel()])))
        cen = np.where(inside, cen, np.inf).reshape(cc.shape).astype(np.float32)
        sub = score[rows, cols]
        better = cen < sub
        sub[better] = cen[better]
        best[rows, cols][better] = k
        u[rows, cols][better] = px[:, 0].reshape(cc.shape)[better]
        v[rows, cols][better] = px[:, 1].reshape(cc.shape)[better]
    grey = np.zeros((ny, nx), dtype=np.uint8)
    for k, im in enumerate(images):
        check_cancel(progress)
        progress.report(0.5 + 0.5 * k / len(images), f"provisional orthophoto: sampling {im.name}")
        sel = best == k
        if not sel.any():
            continue
        img = read_photo(photos[im.name])
        grey[sel] = _remap(cv2, img, u[sel] - 0.5, v[sel] - 0.5)
    return ProvisionalOrtho(grey, best >= 0, xmin, ymax, res, best, u, v, [im.name for im in images], surface)


def _footprint(rec, im, to_model: Similarity, surface: Surface, grid: _Grid, step: int):
    """The (rows, cols) slices of ``grid`` that image ``im`` sees (from a grid ``step`` cells apart), or None."""
    nx, ny = grid.nx, grid.ny
    cc, rr = np.meshgrid(np.arange(0, nx + step, step), np.arange(0, ny + step, step))
    x, y = grid.xy(cc, rr)
    z = surface.sample(x, y)
    _, inside, _ = project(rec, im, to_model.apply(np.column_stack([x.ravel(), y.ravel(), z.ravel()])))
    if not inside.any():
        return None, None
    r_in, c_in = rr.ravel()[inside], cc.ravel()[inside]
    r0, r1 = max(0, int(r_in.min()) - step), min(ny, int(r_in.max()) + step + 1)
    c0, c1 = max(0, int(c_in.min()) - step), min(nx, int(c_in.max()) + step + 1)
    if r1 <= r0 or c1 <= c0:
        return None, None
    return slice(r0, r1), slice(c0, c1)


__all__ = ["Frame", "ProvisionalOrtho", "Surface", "block_extent", "camera_centres", "frame_from_positions",
           "level_frame", "project", "provisional_ortho", "read_photo", "registered", "rough_surface"]
