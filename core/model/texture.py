"""Texture of the model: each face from the photo that sees it best, the photos' crops packed into atlases.

1. For each photo (:class:`~core.ortho.cameras.OrthoCamera`, the orthophoto's projection): the faces it sees are
   those in front, inside the frame, facing it, not masked, and not hidden: a depth buffer of the mesh rendered
   from the photo (faces splatted at about one sample per buffer pixel, the nearest kept) is compared with the
   depth of each face's centre, within the depth one buffer pixel spans on that face.
2. The cost of a face in a photo is the size of a photo pixel on the face (depth / focal / cos of the incidence)
   grown towards the frame's corners (lens fall-off and distortion); each face takes its cheapest photo, then a
   few passes hand a face to the photo most of its neighbours use when that costs at most ``SMOOTH_COST`` x its
   own (fewer, larger charts: fewer seams).
3. Charts (connected faces with one photo) get the UVs of their vertices' projection into that photo; their crops
   (one common scale, so that all fit in the atlases allowed) are packed on shelves into square atlases.
Faces that no photo sees stay untextured (a grey part of their own).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..ortho.cameras import OrthoCamera
from ..ortho.pixels import image_meta, image_window, photo_mask
from .geometry import face_normals
from .options import ModelError
from .types import MeshPart

ZBUFFER_SIDE = 1024  # px, the long side of the depth buffer of a photo
MAX_INCIDENCE_COS = 0.1  # faces seen at more than ~84 degrees from their normal are not textured from that photo
SMOOTH_COST = 1.5
SMOOTH_PASSES = 3
PAD = 2  # atlas px around each chart (no bleeding under bilinear filtering)
SHELF_FILL = 0.85  # the share of an atlas shelf packing fills, for the first guess of the scale


@dataclass
class TextureResult:
    parts: List[MeshPart]
    labels: np.ndarray  # (M,) the photo of each face (-1: none)
    textured_faces: int
    seen_faces: int  # textured from a photo that sees them (the others: from a neighbour's photo, see fill_unseen)
    charts: int
    scale: float  # atlas px per photo px
    atlas_sizes: List[Tuple[int, int]] = field(default_factory=list)


def read_rgb(cam: OrthoCamera) -> np.ndarray:
    """The photo of ``cam`` as (H, W, 3) uint8 (a grey photo repeated; 16-bit and float scaled by their range)."""
    meta = image_meta(cam.path)
    img = image_window(cam.path, meta, 0, 0, meta.width, meta.height)
    if img.shape[2] < 3:
        img = np.repeat(img[:, :, :1], 3, axis=2)
    img = img[:, :, :3]
    if img.dtype != np.uint8:
        f = np.nan_to_num(img.astype(np.float32))
        top = float(np.iinfo(img.dtype).max) if img.dtype.kind in "ui" else max(float(np.percentile(f, 99.9)), 1e-6)
        img = np.clip(f * (255.0 / top), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(img)


def corrected_reader(reader: Callable[[OrthoCamera], np.ndarray],
                     correction: Optional[Callable[[OrthoCamera, np.ndarray], np.ndarray]], step: int = 16
                     ) -> Callable[[OrthoCamera], np.ndarray]:
    """``reader`` with the photos multiplied by ``correction`` (the orthophoto's radiometric correction,
    :func:`core.ortho.radiometry_record.photo_correction`), evaluated every ``step`` px and interpolated (it is
    smooth across a photo)."""
    if correction is None:
        return reader

    def read(cam: OrthoCamera) -> np.ndarray:
        import cv2

        img = reader(cam)
        h, w = img.shape[:2]
        gx, gy = np.meshgrid(np.linspace(0, w, max(2, w // step + 1)), np.linspace(0, h, max(2, h // step + 1)))
        f = correction(cam, np.column_stack([gx.ravel(), gy.ravel()])).reshape(gx.shape).astype(np.float32)
        f = cv2.resize(f, (w, h), interpolation=cv2.INTER_LINEAR)
        return np.clip(img.astype(np.float32) * f[:, :, None] + 0.5, 0, 255).astype(np.uint8)
    return read


def _depth_buffer(px: np.ndarray, depth: np.ndarray, faces: np.ndarray, shape: Tuple[int, int]) -> np.ndarray:
    """The nearest depth per pixel of faces splatted (px in buffer pixels, per vertex; faces with all vertices in
    front)."""
    h, w = shape
    buf = np.full(h * w, np.inf, dtype=np.float32)
    p = px[faces].astype(np.float32)  # (F, 3, 2)
    lo, hi = p.min(axis=1), p.max(axis=1)
    inside = (hi[:, 0] >= 0) & (lo[:, 0] < w) & (hi[:, 1] >= 0) & (lo[:, 1] < h)  # only what falls in the buffer
    p, d = p[inside], depth[faces[inside]].astype(np.float32)
    size = np.max(hi[inside] - lo[inside], axis=1)
    n_sub = np.clip(np.ceil(size), 1, 64).astype(np.int64)  # samples about 1 px apart
    cells, depths = [], []
    for n in np.unique(n_sub):
        sel = n_sub == n
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        bary = np.column_stack([i[keep], j[keep], n - i[keep] - j[keep]]).astype(np.float32) / n  # (S, 3)
        ps, ds = p[sel], d[sel]
        fx = ps[:, None, 0, 0] * bary[None, :, 0] + ps[:, None, 1, 0] * bary[None, :, 1] + ps[:, None, 2, 0] * bary[None, :, 2]
        fy = ps[:, None, 0, 1] * bary[None, :, 0] + ps[:, None, 1, 1] * bary[None, :, 1] + ps[:, None, 2, 1] * bary[None, :, 2]
        z = (ds @ bary.T).ravel()
        fx, fy = fx.ravel(), fy.ravel()
        c, r = fx.astype(np.int64), fy.astype(np.int64)
        ok = (fx >= 0) & (c < w) & (fy >= 0) & (r < h)
        cells.append(r[ok] * w + c[ok])
        depths.append(z[ok])
    if cells:
        np.minimum.at(buf, np.concatenate(cells), np.concatenate(depths))
    return buf.reshape(h, w)


def face_costs(verts: np.ndarray, faces: np.ndarray, cams: Sequence[OrthoCamera],
               progress: Optional[Progress] = None) -> Tuple[np.ndarray, np.ndarray]:
    """((M, photos) float32: the cost of each face in each photo, inf where the photo does not see it; (M, photos)
    bool: the face is inside the photo's frame, seen or not)."""
    progress = progress or NullProgress()
    normals, _area = face_normals(verts, faces)
    centres = verts[faces].mean(axis=1)
    out = np.full((len(faces), len(cams)), np.inf, dtype=np.float32)
    inframe = np.zeros((len(faces), len(cams)), dtype=bool)
    for k, cam in enumerate(cams):
        check_cancel(progress)
        out[:, k], inframe[:, k] = _costs_in(cam, verts, faces, centres, normals)
        progress.report((k + 1) / len(cams), f"visibility in {cam.name}")
    return out, inframe


def _costs_in(cam: OrthoCamera, verts, faces, centres, normals) -> Tuple[np.ndarray, np.ndarray]:
    """(cost (M,), in the frame (M,): the face's corners are inside the photo, seen or not)."""
    cost = np.full(len(faces), np.inf, dtype=np.float32)
    px, depth, ok = cam.project(verts)
    front = (depth > 0) & np.all(np.isfinite(px), axis=1)
    inframe = ok[faces].all(axis=1)
    mask = photo_mask(cam.mask_path)  # masked (the boom, the sky): not in the frame at all, not even to fill
    if mask is not None and inframe.any():
        j = np.flatnonzero(inframe)
        mh, mw = mask.shape[:2]
        for p in (px[faces[j]].mean(axis=1), *(px[faces[j, k]] for k in range(3))):
            inframe[j] &= mask[np.clip(p[:, 1].astype(np.int64), 0, mh - 1),
                               np.clip(p[:, 0].astype(np.int64), 0, mw - 1)] >= 128
    seen = inframe.copy()
    view = cam.centre[None, :] - centres
    dist = np.linalg.norm(view, axis=1)
    cos = np.einsum("ij,ij->i", normals, view) / np.maximum(dist, 1e-12)
    seen &= cos > MAX_INCIDENCE_COS
    if not seen.any():
        return cost, inframe
    w, h = cam.camera.width, cam.camera.height
    # the buffer's pixel: about 2/3 of the median edge (finer adds samples, not a better test), at most the
    # photo's, its long side at most ZBUFFER_SIDE
    edge = np.linalg.norm(px[faces[seen, 0]] - px[faces[seen, 1]], axis=1)
    s = min(1.0, ZBUFFER_SIDE / max(w, h), 1.5 / max(float(np.median(edge)), 1e-6))
    shape = (max(1, int(math.ceil(h * s))), max(1, int(math.ceil(w * s))))
    occluders = faces[front[faces].all(axis=1)]
    zbuf = _depth_buffer(np.where(front[:, None], px * s, 0.0), depth, occluders, shape)
    idx = np.flatnonzero(seen)
    cpx = px[faces[idx]].mean(axis=1)
    cd = depth[faces[idx]].mean(axis=1)
    r = np.clip((cpx[:, 1] * s).astype(np.int64), 0, shape[0] - 1)
    c = np.clip((cpx[:, 0] * s).astype(np.int64), 0, shape[1] - 1)
    focal = 0.5 * (cam.camera.fx + cam.camera.fy)
    pixel = cd / (focal * s)  # the size across of one buffer pixel at the face (m)
    tol = 2.0 * pixel / np.maximum(cos[idx], 0.2)
    vis = cd <= zbuf[r, c] + tol
    half_diag = 0.5 * math.hypot(w, h)
    rho = np.hypot(cpx[:, 0] - cam.camera.cx, cpx[:, 1] - cam.camera.cy) / half_diag
    cost[idx] = np.where(vis, cd / (focal * cos[idx]) * (1.0 + 0.5 * rho * rho), np.inf)
    return cost, inframe


def face_adjacency(faces: np.ndarray) -> np.ndarray:
    """(K, 2) pairs of faces that share an edge."""
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    f = np.tile(np.arange(len(faces)), 3)
    key = e[:, 0].astype(np.int64) * (int(faces.max()) + 1 if len(faces) else 1) + e[:, 1]
    order = np.argsort(key, kind="stable")
    key, f = key[order], f[order]
    same = key[1:] == key[:-1]
    return np.column_stack([f[:-1][same], f[1:][same]])


def choose_photos(costs: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(M,) the photo of each face (-1: seen by none): the cheapest, then smoothed towards the neighbours'."""
    best = np.argmin(costs, axis=1)
    rows = np.arange(len(costs))
    label = np.where(np.isfinite(costs[rows, best]), best, -1)
    if not len(pairs):
        return label
    a = np.concatenate([pairs[:, 0], pairs[:, 1]])
    b = np.concatenate([pairs[:, 1], pairs[:, 0]])
    for _ in range(SMOOTH_PASSES):
        lb = label[b]
        ok = lb >= 0
        aa, lb = a[ok], lb[ok]
        # votes per (face, label): the label most neighbours have, where it is cheap enough
        key = aa.astype(np.int64) * costs.shape[1] + lb
        uk, counts = np.unique(key, return_counts=True)
        face, lab = uk // costs.shape[1], uk % costs.shape[1]
        order = np.lexsort((-counts, face))
        face, lab, counts = face[order], lab[order], counts[order]
        first = np.concatenate([[True], face[1:] != face[:-1]])
        face, lab, counts = face[first], lab[first], counts[first]
        cur = label[face]
        cheap = costs[face, lab] <= SMOOTH_COST * np.where(cur >= 0, costs[face, np.maximum(cur, 0)], np.inf)
        change = (counts >= 2) & (lab != cur) & cheap & (cur >= 0)
        if not change.any():
            break
        label[face[change]] = lab[change]
    return label


def fill_unseen(label: np.ndarray, inframe: np.ndarray, pairs: np.ndarray, passes: int = 8) -> np.ndarray:
    """The faces no photo sees (a steep facet of a noisy DSM turned away from every photo, a face hidden under
    another) given the photo of a neighbour whose frame holds them, spreading ``passes`` faces deep: no speck of
    grey inside a textured surface.  They are counted apart (not seen)."""
    label = label.copy()
    if not len(pairs):
        return label
    for _ in range(passes):
        a = np.concatenate([pairs[:, 0], pairs[:, 1]])
        b = np.concatenate([pairs[:, 1], pairs[:, 0]])
        ok = (label[a] < 0) & (label[b] >= 0)
        a, b = a[ok], b[ok]
        ok = inframe[a, label[b]]
        if not ok.any():
            break
        label[a[ok]] = label[b[ok]]
    return label


def charts_of(label: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(M,) chart id per face (-1 where label is -1): connected faces with the same photo."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = len(label)
    same = (label[pairs[:, 0]] == label[pairs[:, 1]]) & (label[pairs[:, 0]] >= 0) if len(pairs) else np.zeros(0, bool)
    p = pairs[same]
    g = coo_matrix((np.ones(len(p)), (p[:, 0], p[:, 1])), shape=(m, m))
    _n, comp = connected_components(g, directed=False)
    out = np.full(m, -1, dtype=np.int64)
    lab = label >= 0
    out[lab] = np.unique(comp[lab], return_inverse=True)[1].ravel()
    return out


@dataclass
class _Chart:
    photo: int
    box: Tuple[int, int, int, int]  # x0, y0, x1, y1 in photo px
    size: Tuple[int, int] = (0, 0)  # w, h in atlas px (margins included)
    place: Tuple[int, int, int] = (0, 0, 0)  # atlas, x, y


def face_pixels(verts: np.ndarray, faces: np.ndarray, label: np.ndarray, cams: Sequence[OrthoCamera]) -> np.ndarray:
    """(M, 3, 2) the pixels of each face's corners in its photo (NaN where it has none)."""
    out = np.full((len(faces), 3, 2), np.nan)
    for k in np.unique(label[label >= 0]):
        sel = label == k
        used, inv = np.unique(faces[sel].ravel(), return_inverse=True)
        out[sel] = cams[int(k)].project(verts[used])[0][inv.ravel()].reshape(-1, 3, 2)
    return out


def split_charts(chart: np.ndarray, fpx: np.ndarray, limit: float) -> np.ndarray:
    """The charts cut into cells of ``limit`` photo px (by the faces' centres): pieces that fit an atlas."""
    lab = np.flatnonzero(chart >= 0)
    if not len(lab):
        return chart
    c = fpx[lab].mean(axis=1)
    lo = np.full((int(chart.max()) + 1, 2), np.inf)
    np.minimum.at(lo, chart[lab], c)
    cell = np.floor((c - lo[chart[lab]]) / limit).astype(np.int64)
    key = np.column_stack([chart[lab], cell])
    out = chart.copy()
    out[lab] = np.unique(key, axis=0, return_inverse=True)[1].ravel()
    return out


def _make_charts(label: np.ndarray, chart: np.ndarray, fpx: np.ndarray) -> List[_Chart]:
    """The charts (their photo and box in it, from their faces' corners)."""
    lab = np.flatnonzero(chart >= 0)
    n = int(chart.max()) + 1 if len(lab) else 0
    lo, hi = np.full((n, 2), np.inf), np.full((n, 2), -np.inf)
    ids = np.repeat(chart[lab], 3)
    corners = fpx[lab].reshape(-1, 2)
    np.minimum.at(lo, ids, corners)
    np.maximum.at(hi, ids, corners)
    photo = np.zeros(n, dtype=np.int64)
    photo[chart[lab]] = label[lab]
    lo, hi = np.floor(lo).astype(np.int64), np.ceil(hi).astype(np.int64)
    return [_Chart(int(photo[i]), (int(lo[i, 0]), int(lo[i, 1]), int(hi[i, 0]), int(hi[i, 1]))) for i in range(n)]


def _pack(charts: List[_Chart], scale: float, atlas: int, max_atlases: int) -> bool:
    """Shelf packing of the charts' crops at ``scale`` (tallest first); False if more atlases than allowed."""
    for ch in charts:
        w, h = ch.box[2] - ch.box[0], ch.box[3] - ch.box[1]
        ch.size = (max(1, int(math.ceil(w * scale))) + 2 * PAD, max(1, int(math.ceil(h * scale))) + 2 * PAD)
        if max(ch.size) > atlas:
            return False
    a, x, y, shelf = 0, 0, 0, 0
    for ch in sorted(charts, key=lambda c: -c.size[1]):
        w, h = ch.size
        if x + w > atlas:
            x, y, shelf = 0, y + shelf, 0
        if y + h > atlas:
            a, x, y, shelf = a + 1, 0, 0, 0
            if a >= max_atlases:
                return False
        ch.place = (a, x, y)
        x += w
        shelf = max(shelf, h)
    return True


def texture_mesh(verts: np.ndarray, faces: np.ndarray, normals: Optional[np.ndarray], cams: Sequence[OrthoCamera],
                 atlas: int, max_atlases: int, progress: Optional[Progress] = None,
                 reader: Callable[[OrthoCamera], np.ndarray] = read_rgb) -> TextureResult:
    """The textured parts of a mesh (``verts`` local float64, ``faces``): one part per atlas, and a grey one of
    the faces no photo sees."""
    progress = progress or NullProgress()
    if not len(faces):
        raise ModelError("the mesh has no face to texture")
    costs, inframe = face_costs(verts, faces, cams, SubProgress(progress, 0.0, 0.5))
    pairs = face_adjacency(faces)
    seen = choose_photos(costs, pairs)
    del costs
    label = fill_unseen(seen, inframe, pairs)
    fpx = face_pixels(verts, faces, label, cams)
    chart = split_charts(charts_of(label, pairs), fpx, atlas / 2 - 2 * PAD)
    charts = _make_charts(label, chart, fpx)
    area = sum((c.box[2] - c.box[0] + 2 * PAD) * (c.box[3] - c.box[1] + 2 * PAD) for c in charts)
    scale = min(1.0, math.sqrt(SHELF_FILL * max_atlases * atlas * atlas / max(area, 1)))
    while charts and not _pack(charts, scale, atlas, max_atlases):
        scale *= 0.9
        if scale < 1e-3:
            raise ModelError(f"the texture does not fit in {max_atlases} atlases of {atlas} px: allow more atlases")
    n_atlas = 1 + max((c.place[0] for c in charts), default=-1)
    images = []
    for a in range(n_atlas):  # the last atlas only as tall as it is filled (a power of two)
        hh = max(c.place[2] + c.size[1] for c in charts if c.place[0] == a)
        images.append(np.zeros((min(atlas, 1 << int(math.ceil(math.log2(max(hh, 1))))), atlas, 3), dtype=np.uint8))
    _fill_atlases(charts, cams, images, scale, reader, SubProgress(progress, 0.5, 0.95))
    parts = _parts(verts, faces, normals, chart, fpx, charts, images, scale)
    return TextureResult(parts, label, int((label >= 0).sum()), int((seen >= 0).sum()), len(charts), scale,
                         [(im.shape[1], im.shape[0]) for im in images])


def _fill_atlases(charts: List[_Chart], cams, images: List[np.ndarray], scale: float, reader, progress) -> None:
    """Each chart's crop of its photo, at ``scale``, into its place (the photos read one at a time).

    A chart's atlas coordinate is ``place + PAD + (photo coordinate - box corner) x scale`` (coordinates from the
    pixels' corners, as the UVs): in pixel indices (centres), one affine map per chart."""
    import cv2

    photos = sorted({c.photo for c in charts})
    blur = max(1, int(round(1.0 / scale))) if scale < 0.75 else 1  # no aliasing where the photo is reduced
    for n, k in enumerate(photos):
        check_cancel(progress)
        img = reader(cams[k])
        if blur > 1:
            img = cv2.blur(img, (blur, blur))
        ih, iw = img.shape[:2]
        for ch in (c for c in charts if c.photo == k):
            x0, y0 = ch.box[0], ch.box[1]
            w, h = ch.size
            bx0 = min(max(0, int(math.floor(x0 - PAD / scale)) - 1), iw - 1)
            by0 = min(max(0, int(math.floor(y0 - PAD / scale)) - 1), ih - 1)
            bx1 = max(min(iw, int(math.ceil(x0 + (w - PAD) / scale)) + 2), bx0 + 1)
            by1 = max(min(ih, int(math.ceil(y0 + (h - PAD) / scale)) + 2), by0 + 1)
            tx = PAD + (bx0 + 0.5 - x0) * scale - 0.5
            ty = PAD + (by0 + 0.5 - y0) * scale - 0.5
            mat = np.array([[scale, 0.0, tx], [0.0, scale, ty]])
            out = cv2.warpAffine(np.ascontiguousarray(img[by0:by1, bx0:bx1]), mat, (w, h), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_REPLICATE)
            a, ax, ay = ch.place
            images[a][ay:ay + h, ax:ax + w] = out.reshape(h, w, -1)[:, :, :3]
        progress.report((n + 1) / len(photos), f"texture from {cams[k].name}")


def _parts(verts, faces, normals, chart, fpx, charts: List[_Chart], images, scale: float) -> List[MeshPart]:
    """One part per atlas (a vertex per chart that uses it, its UV from its pixel in the chart's photo), and the
    grey part of the faces without a photo."""
    parts: List[MeshPart] = []
    nv = len(verts)
    place = np.array([c.place for c in charts], dtype=np.float64).reshape(-1, 3)
    box = np.array([c.box for c in charts], dtype=np.float64).reshape(-1, 4)
    atlas_of = np.where(chart >= 0, place[np.maximum(chart, 0), 0], -1)
    for a, img in enumerate(images):
        sel = np.flatnonzero(atlas_of == a)
        ch = chart[sel]
        keys = ch[:, None].astype(np.int64) * nv + faces[sel]
        uk, first, inv = np.unique(keys.ravel(), return_index=True, return_inverse=True)
        corner = place[np.repeat(ch, 3), 1:] + PAD + (fpx[sel].reshape(-1, 2) - box[np.repeat(ch, 3), :2]) * scale
        uv = corner[first] / np.array([img.shape[1], img.shape[0]], dtype=np.float64)
        vid = uk % nv
        parts.append(MeshPart(verts[vid].astype(np.float32), inv.reshape(-1, 3).astype(np.uint32),
                              uv.astype(np.float32), img, None if normals is None else normals[vid]))
    grey = np.flatnonzero(chart < 0)
    if len(grey):
        used, inv = np.unique(faces[grey].ravel(), return_inverse=True)
        parts.append(MeshPart(verts[used].astype(np.float32), inv.reshape(-1, 3).astype(np.uint32), None, None,
                              None if normals is None else normals[used]))
    return parts
