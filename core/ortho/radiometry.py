"""Radiometry of the mosaic (issue 14): per camera the radial fall-off (vignetting) and the hot spot, fitted from
the overlaps of the photos and removed, then a smooth gain field per image that levels the seams.

The model, in the log of the grey value of ground point p in image i of camera group g:

    log I_i(p) = log L(p) + f_g(r) + h_g * exp(-theta^2 / (2 s^2)) + b_i + c_i . phi(u, v)

with f_g(r) = a1 r^2 + a2 r^4 + a3 r^6 (r: distance from the principal point / the half diagonal), theta the angle
between the view ray and the direction the sunlight travels (one direction and width s for the block, found by a
grid search), b_i one exposure per image, and phi = (1, u, v, u^2, uv, v^2, u^3, u^2 v, u v^2, v^3) a low-order
field over the image (u, v in -1..1; the cubic terms since issue 33 item 4: light that changes across a photo is
not always a ramp), fitted last and held near 1.  The unknown ground L(p) cancels in the differences of two images
at one cell, which are fitted by iteratively reweighted least squares (Cauchy weights: moving things, shadows
and misregistration count little).  The correction divides the model out; its mean over the sampled cells is 1,
so the mosaic keeps its overall brightness.  The fit lives in :mod:`core.ortho.radiometry_fit`."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from .block import PreparedBlock
from .cameras import OrthoCamera
from .sampling import camera_view, sample_camera
from .surface import Dsm

MAX_CORRECTION = 2.0  # the correction stays within 1 / this .. this
CHUNK = 8  # cells of a chunk in which the disagreement of two images is one median


@dataclass
class RadiometryModel:
    """The fitted model (picklable: it travels with each mosaic tile to the workers)."""

    groups: List[int]  # per image: its camera group (index into falloff / hot)
    falloff: List[List[float]]  # per group: a1, a2, a3 of f(r) (log)
    hot: List[float]  # per group: amplitude (log)
    antisolar: List[float]  # unit vector, local frame: the direction the sunlight travels
    hot_width: float  # radians
    exposure: List[float]  # per image: b_i (log)
    fields: List[List[float]]  # per image: field_count(order) coefficients (log), the order's monomials
    norm: float = 0.0  # added to every log correction (the mean correction over the samples is 1)
    summary: Dict[str, object] = field(default_factory=dict)

    def falloff_at(self, group: int, r) -> np.ndarray:
        """The fitted fall-off V(r) = exp(f(r)) of a camera group (1 at the principal point)."""
        r2 = np.asarray(r, dtype=float) ** 2
        a1, a2, a3 = self.falloff[group]
        return np.exp(a1 * r2 + a2 * r2 ** 2 + a3 * r2 ** 3)

    def log_model(self, images: np.ndarray, r: np.ndarray, u: np.ndarray, v: np.ndarray, rays: np.ndarray,
                  terms: str = "vhef") -> np.ndarray:
        """The model's log brightness factor of observations (image index, r, u, v, unit view rays (N, 3)):
        ``terms`` any of v (fall-off), h (hot spot), e (exposure), f (field)."""
        images = np.asarray(images, dtype=np.int64)
        out = np.zeros(len(images), dtype=np.float64)
        g = np.asarray(self.groups, dtype=np.int64)[images]
        if "v" in terms:
            a = np.asarray(self.falloff, dtype=np.float64)[g]
            r2 = np.asarray(r, dtype=np.float64) ** 2
            out += a[:, 0] * r2 + a[:, 1] * r2 ** 2 + a[:, 2] * r2 ** 3
        if "h" in terms and any(h != 0.0 for h in self.hot):
            out += np.asarray(self.hot, dtype=np.float64)[g] * hot_spot_shape(rays, self.antisolar, self.hot_width)
        if "e" in terms:
            out += np.asarray(self.exposure, dtype=np.float64)[images]
        if "f" in terms:
            c = np.asarray(self.fields, dtype=np.float64)[images]
            order = next(d for d in range(8) if field_count(d) >= c.shape[1])
            out += np.einsum("nk,nk->n", c, field_terms(u, v, order))
        return out

    def correction(self, images, r, u, v, rays) -> np.ndarray:
        """Multiplicative correction (N,) float32 of observations: exp(norm - model), within the bounds."""
        lc = self.norm - self.log_model(images, r, u, v, rays)
        return np.exp(np.clip(lc, -math.log(MAX_CORRECTION), math.log(MAX_CORRECTION))).astype(np.float32)

    def scalar_gain(self, image: int) -> float:
        """The correction of an image at its principal point (for the which-image layer's gain field)."""
        return float(math.exp(self.norm - self.exposure[image] - self.fields[image][0]))


def field_count(order: int) -> int:
    """The number of terms of a polynomial field of degree ``order`` in u, v."""
    return (order + 1) * (order + 2) // 2


def field_terms(u, v, order: int) -> np.ndarray:
    """(..., field_count(order)) the monomials u^(d-j) v^j, degree d = 0 .. order (1, u, v, u^2, uv, v^2, ...)."""
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    return np.stack([u ** (d - j) * v ** j for d in range(order + 1) for j in range(d + 1)], axis=-1)


def hot_spot_shape(rays: np.ndarray, antisolar: Sequence[float], width: float) -> np.ndarray:
    """exp(-theta^2 / (2 width^2)) of unit rays (N, 3) against the antisolar direction."""
    cosang = np.clip(np.asarray(rays, dtype=np.float64) @ np.asarray(antisolar, dtype=np.float64), -1.0, 1.0)
    theta = np.arccos(cosang)
    return np.exp(-0.5 * (theta / width) ** 2)


def observation_geometry(cam: OrthoCamera, xyz_local: np.ndarray, px: Optional[np.ndarray] = None):
    """(ok, r, u, v, unit rays) of local ground points in one image: r from the principal point / the half
    diagonal, u and v from the image centre / the half width and height (-1..1).  ``px``: the points' pixels
    where the caller has projected them already (ok is then all true)."""
    if px is None:
        px, _depth, ok = cam.project(xyz_local)
    else:
        ok = np.ones(len(px), dtype=bool)
    w, h = cam.camera.width, cam.camera.height
    r = np.hypot(px[:, 0] - cam.camera.cx, px[:, 1] - cam.camera.cy) / (0.5 * math.hypot(w, h))
    u = (px[:, 0] - 0.5 * w) / (0.5 * w)
    v = (px[:, 1] - 0.5 * h) / (0.5 * h)
    d = np.asarray(xyz_local, dtype=np.float64) - cam.centre
    rays = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    return ok, r, u, v, rays


def point_gains(model: Optional[RadiometryModel], gain: float, index: int, cam: OrthoCamera, xyz: np.ndarray,
                valid: np.ndarray, px: Optional[np.ndarray] = None) -> np.ndarray:
    """(N, 1) float32 factors of ground points of image ``index`` in the mosaic (``xyz``: (N, 3) in the local
    frame, as Sampled.xyz): the radiometric correction where ``valid`` (1 elsewhere), or the scalar exposure
    ``gain`` without a model.  ``px``: their pixels (N, 2) where the caller has them (Sampled.px), else
    projected here."""
    n = len(xyz)
    if model is None:
        return np.full((n, 1), gain, dtype=np.float32)
    out = np.ones((n, 1), dtype=np.float32)
    idx = np.flatnonzero(valid)
    if not len(idx):
        return out
    _ok, r, u, v, rays = observation_geometry(cam, xyz[idx], None if px is None else px[idx])
    out[idx, 0] = model.correction(np.full(len(idx), index), r, u, v, rays)
    return out


def dtype_scale(dtype: str) -> float:
    dt = np.dtype(dtype)
    return float(np.iinfo(dt).max) if dt.kind in "ui" else 0.0


def _grey_ok(values: np.ndarray, valid: np.ndarray, scale: float) -> Tuple[np.ndarray, np.ndarray]:
    """(grey, usable): the band mean, usable where valid, not dark (3 % of full scale) and no band saturated."""
    grey = values.mean(axis=1)
    ok = valid & (grey > (0.03 * scale if scale else 0.0))
    if scale:
        ok &= values.max(axis=1) < 0.97 * scale
    return grey, ok


FOOTPRINT_POINTS = 3  # per side: a grey value for the fit and the seam step is the mean of 3 x 3 ground points


def _reduced(cam: OrthoCamera, meta, factor: float) -> np.ndarray:
    """The photo reduced ``factor`` x by area (cv2.INTER_AREA: each pixel the mean of the photo's pixels it
    covers), kept in the image cache."""
    from ..common.errors import require
    from .pixels import PHOTO_CACHE, image_window

    def make():
        cv2 = require("cv2", "orthophotos")
        whole = image_window(cam.path, meta, 0, 0, meta.width, meta.height)
        w, h = max(1, int(round(meta.width / factor))), max(1, int(round(meta.height / factor)))
        if whole.dtype not in (np.uint8, np.uint16, np.float32):  # the photo's own type where cv2 takes it
            whole = whole.astype(np.float32)
        small = cv2.resize(np.ascontiguousarray(whole), (w, h), interpolation=cv2.INTER_AREA)
        small = small.reshape(h, w, -1)
        return small, small.nbytes

    return PHOTO_CACHE.get(("reduced", cam.path, factor), make)


def sample_grey(cam: OrthoCamera, meta, offset: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray, vis,
                footprint: float) -> Tuple[np.ndarray, np.ndarray]:
    """(grey, usable) of ground points: the mean grey value over a square of ``footprint`` metres around each point
    (FOOTPRINT_POINTS x FOOTPRINT_POINTS points at the point's height, on the photo reduced by area to about a
    third of the footprint a pixel where its pixels are finer), usable where every point is.  The brightness of an
    area of the ground, the same whatever the photos' resolution: one bilinear pixel of a full-resolution photo is
    the texture under it, and two photos misregistered by a pixel disagree there by the texture's contrast, not by
    their brightness (issue 33 item 4: the seam step of toledo_2400's 2400 px photos read 6.1 %, of their 1200 px
    copies 5.2 %; now 3.2 and 3.3 %).  Dark and saturated: against the full scale of the image's data type."""
    from .pixels import remap_photo

    scale = dtype_scale(meta.dtype)
    n = FOOTPRINT_POINTS if footprint > 0 else 1
    offs = ((np.arange(n) + 0.5) / n - 0.5) * footprint
    acc = np.zeros(len(x), dtype=np.float64)
    good = np.ones(len(x), dtype=bool)
    src = None
    if footprint > 0:  # the photo's ground pixel at these points: reduced to a third of the footprint
        s = camera_view(cam, meta, offset, x, y, z, vis)
        idx = np.flatnonzero(s.valid)
        gsd = float(np.median(cam.pose.to_camera(s.xyz[idx])[:, 2])) / max(cam.camera.focal, 1e-9) if len(idx) \
            else 0.0
        want = footprint / (n * gsd) if gsd > 0 else 1.0
        factor = 2.0 ** (math.floor(4.0 * math.log2(want)) / 4.0) if want > 1.0 else 1.0  # few sizes: the cache
        if factor > 1.0:
            src = _reduced(cam, meta, factor)
    for dy in offs:
        for dx in offs:
            s = (sample_camera(cam, meta, offset, x + dx, y + dy, z, vis, "bilinear") if src is None
                 else camera_view(cam, meta, offset, x + dx, y + dy, z, vis))
            values = s.values
            idx = np.flatnonzero(s.valid)
            if src is not None and len(idx):
                sx, sy = src.shape[1] / meta.width, src.shape[0] / meta.height
                values[idx] = remap_photo(src, s.px[idx, 0] * sx - 0.5, s.px[idx, 1] * sy - 0.5, "bilinear")
            grey, ok = _grey_ok(values, s.valid, scale)
            acc += np.where(ok, grey, 0.0)
            good &= ok
    return acc / (n * n), good


def chunk_disagreement(images_a: np.ndarray, images_b: np.ndarray, cells: np.ndarray, cols: int,
                       diff: np.ndarray, min_count: int = 4) -> float:
    """Median over chunks (two images, CHUNK x CHUNK cells) of |the chunk's median log difference|, as a
    fraction (exp - 1); nan without a chunk."""
    if not len(diff):
        return float("nan")
    lo, hi = np.minimum(images_a, images_b), np.maximum(images_a, images_b)
    sign = np.where(images_a <= images_b, 1.0, -1.0)
    rr, cc = np.divmod(cells, cols)
    n_img, br, bc = int(hi.max()) + 1, int(rr.max()) // CHUNK + 1, int(cols) // CHUNK + 1
    key = ((lo.astype(np.int64) * n_img + hi) * br + rr // CHUNK) * bc + cc // CHUNK
    d = sign * diff
    order = np.lexsort((d, key))
    key, d = key[order], d[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(key)])
    starts, counts = starts[counts >= min_count], counts[counts >= min_count]
    if not len(starts):
        return float("nan")
    meds = np.abs(0.5 * (d[starts + (counts - 1) // 2] + d[starts + counts // 2]))
    return float(math.exp(np.median(meds)) - 1.0)


def seam_steps(model: Optional[RadiometryModel], labels: np.ndarray, k: int, prep: PreparedBlock, dsm: Dsm,
               offset: np.ndarray, gains: Sequence[float], max_points: int = 60_000) -> Dict[str, float]:
    """The median brightness step across the seamlines of the plan (``labels``: planning cells of ``k`` output
    cells): at the middle of every edge between two images' cells both images are sampled; per chunk of the
    seam the median log ratio, the median of its size over the chunks (a fraction).  ``seam_step_before`` with the
    exposure ``gains``, ``seam_step_after`` with the model (the same without one); nan where there is no seam.
    The same over the seam points on level ground (``seam_step_level_before`` / ``_after``: the DSM spans at most
    one planning cell over the planning cells around the point, a slope up to 1 in 2) and their share
    (``seam_level_fraction``): at crowns, walls and roof edges two photos differ by what each sees of the relief,
    which no brightness model levels (issue 33 item 4: on toledo 1.5 % on level ground, 4.2 % at relief)."""
    grid = prep.grid
    p = k * grid.resolution
    footprint = p  # the planning cells on either side of the edge, half each
    pts = []
    for horizontal in (True, False):
        la, lb = (labels[:, :-1], labels[:, 1:]) if horizontal else (labels[:-1], labels[1:])
        rr, cc = np.nonzero((la != lb) & (la >= 0) & (lb >= 0))
        xs = grid.x0 + (cc + (1.0 if horizontal else 0.5)) * p
        ys = grid.y0 - (rr + (0.5 if horizontal else 1.0)) * p
        pts.append((xs, ys, la[rr, cc], lb[rr, cc], rr * labels.shape[1] + cc))
    x, y, ia, ib, cell = (np.concatenate([q[j] for q in pts]) for j in range(5))
    nan = float("nan")
    if not len(x):
        return {"seam_step_before": nan, "seam_step_after": nan, "seam_step_level_before": nan,
                "seam_step_level_after": nan, "seam_level_fraction": nan}
    if len(x) > max_points:
        pick = np.random.default_rng(3).choice(len(x), max_points, replace=False)
        x, y, ia, ib, cell = x[pick], y[pick], ia[pick], ib[pick], cell[pick]
    z = dsm.sample(x, y).astype(np.float64)
    around = np.stack([dsm.sample(x + dx * p, y + dy * p) for dx in (-1, 0, 1) for dy in (-1, 0, 1)])
    with np.errstate(invalid="ignore"):
        level = np.all(np.isfinite(around), axis=0) & (np.ptp(around, axis=0) <= p)
    raw = {0: np.full(len(x), np.nan), 1: np.full(len(x), np.nan)}
    cor = {0: np.full(len(x), np.nan), 1: np.full(len(x), np.nan)}
    for i in np.unique(np.concatenate([ia, ib])):
        cam = prep.cameras[i]
        for side, lab in ((0, ia), (1, ib)):
            sel = np.flatnonzero(lab == i)
            if not len(sel):
                continue
            grey, ok = sample_grey(cam, prep.metas[i], offset, x[sel], y[sel], z[sel], prep.visibility[i], footprint)
            sel, grey = sel[ok], grey[ok]
            if not len(sel):
                continue
            raw[side][sel] = np.log(np.maximum(grey, 1e-6)) + math.log(max(gains[i], 1e-6))
            if model is not None:
                xyz = np.column_stack([x[sel] - offset[0], y[sel] - offset[1], z[sel] - offset[2]])
                _ok, r, u, v, rays = observation_geometry(cam, xyz)
                corr = model.correction(np.full(len(sel), i), r, u, v, rays)
                cor[side][sel] = np.log(np.maximum(grey, 1e-6)) + np.log(corr)
    out = {}
    for name, logs in (("before", raw), ("after", cor if model is not None else raw)):
        ok = np.isfinite(logs[0]) & np.isfinite(logs[1])
        for key, sel in ((f"seam_step_{name}", ok), (f"seam_step_level_{name}", ok & level)):
            out[key] = chunk_disagreement(ia[sel], ib[sel], cell[sel], labels.shape[1], (logs[0] - logs[1])[sel], 3)
    ok = np.isfinite(raw[0]) & np.isfinite(raw[1])
    out["seam_level_fraction"] = float(np.mean(level[ok])) if ok.any() else nan
    return out


# the radiometric correction's figures the record keeps (the report shows them): the median brightness step
# across the seamlines before and after it, the same over level ground, and level ground's share of the seams
SEAM_FIGURES = ("seam_step_before", "seam_step_after", "seam_step_level_before", "seam_step_level_after",
                "seam_level_fraction")


def seam_figures(radiometry: Dict[str, Any]) -> Dict[str, float]:
    """The seam figures of the radiometric correction's summary that are numbers (none without a correction)."""
    out = {}
    for key in SEAM_FIGURES:
        v = (radiometry or {}).get(key)
        if isinstance(v, (int, float)) and math.isfinite(v):
            out[key] = float(v)
    return out
