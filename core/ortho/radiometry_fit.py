"""The fit of the radiometric model (:mod:`core.ortho.radiometry`) from the overlaps of the images: grey values
sampled on a coarse grid of the mosaic, the log differences of every two images at a cell, iteratively reweighted
least squares for the fall-off, the hot spot (its direction and width by a grid search) and the exposures, then
the per-image gain fields; and the brightness step across the seamlines of the plan, before and after."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Progress, check_cancel
from ..io import raster as dsmmod
from .block import PreparedBlock
from .grid import cell_centre_coords, subgrid
from .radiometry import (
    RadiometryModel,
    chunk_disagreement,
    field_count,
    field_terms,
    hot_spot_shape,
    observation_geometry,
    sample_grey,
    seam_steps,
)
from .surface import Dsm

SAMPLE_GSD = 4.0  # sample cell = 4 x GSD (at least)
MAX_SAMPLE_CELLS = 100_000
MAX_PAIRS = 300_000
SEARCH_PAIRS = 30_000  # pairs the hot spot's direction is searched on
MIN_PAIRS = 2000
PRIOR_FALLOFF, PRIOR_HOT, PRIOR_EXPOSURE = 1.0, 0.5, 0.5  # prior sigmas (log), all centred on 0
FIELD_ORDER = 3  # the gain fields' polynomial degree in u, v (2 before issue 33 item 4)
PRIOR_FIELD = (0.05, 0.02, 0.01, 0.005)  # per degree of the field (constant, linear, quadratic, cubic): gentle
FIELD_GAIN = 0.9  # the fields are kept only if they cut the overlaps' disagreement to this share of it
HOT_WIDTHS_DEG = (6.0, 10.0, 16.0)


@dataclass
class _Obs:
    cell: np.ndarray  # (N,) int64 flat index of the sample cell
    image: np.ndarray  # (N,) int64
    logv: np.ndarray  # (N,) float64 log grey value
    r: np.ndarray
    u: np.ndarray
    v: np.ndarray
    rays: np.ndarray  # (N, 3) unit view rays, local frame
    shape: Tuple[int, int]  # the sample grid (rows, cols)


def sample_overlaps(prep: PreparedBlock, dsm: Dsm, offset: np.ndarray, progress: Progress,
                    max_cells: int = MAX_SAMPLE_CELLS) -> _Obs:
    """Grey values of every image on a coarse grid of the mosaic, with their image geometry."""
    grid = prep.grid
    step = max(1, int(round(SAMPLE_GSD * prep.gsd / grid.resolution)),
               int(math.ceil(math.sqrt(grid.width * grid.height / float(max_cells)))))
    sw, sh = int(math.ceil(grid.width / step)), int(math.ceil(grid.height / step))
    sgrid = dsmmod.Grid(grid.x0, grid.y0, step * grid.resolution, sw, sh)
    x, y = cell_centre_coords(sgrid, 0, 0, sh, sw)
    zs = dsm.sample(x, y).reshape(sh, sw)
    level = level_cells(zs, sgrid.resolution)
    parts: List[Tuple] = []
    n = len(prep.cameras)
    for i, (cam, meta, fp, vis) in enumerate(zip(prep.cameras, prep.metas, prep.footprints, prep.visibility)):
        check_cancel(progress)
        sub = subgrid(sgrid, fp.bbox)
        if sub is None:
            continue
        r0, c0, h, w = sub
        xi, yi = cell_centre_coords(sgrid, r0, c0, h, w)
        zi = zs[r0:r0 + h, c0:c0 + w].ravel().astype(np.float64)
        grey, ok = sample_grey(cam, meta, offset, xi, yi, zi, vis, sgrid.resolution)
        idx = np.flatnonzero(ok & level[r0:r0 + h, c0:c0 + w].ravel())
        if len(idx):
            xyz = np.column_stack([xi[idx] - offset[0], yi[idx] - offset[1], zi[idx] - offset[2]])
            _ok, r, u, v, rays = observation_geometry(cam, xyz)
            rr, cc = np.divmod(idx, w)
            cell = (rr + r0).astype(np.int64) * sw + (cc + c0)
            parts.append((cell, np.full(len(idx), i, np.int64), np.log(np.maximum(grey[idx], 1e-6)), r, u, v,
                          rays.astype(np.float32)))
        progress.report((i + 1) / n, f"radiometry: sampling {i + 1}/{n}")
    if not parts:
        e = np.zeros(0)
        return _Obs(e.astype(np.int64), e.astype(np.int64), e, e, e, e, np.zeros((0, 3), np.float32), (sh, sw))
    cols = [np.concatenate([p[k] for p in parts]) for k in range(7)]
    return _Obs(cols[0], cols[1], cols[2].astype(np.float64), cols[3], cols[4], cols[5], cols[6], (sh, sw))


def level_cells(zs: np.ndarray, cell: float) -> np.ndarray:
    """(rows, cols) bool: the sample cells on level ground, where the DSM's heights over the cell and its eight
    neighbours span at most one cell (a slope up to 1 in 3), or, where fewer than half of the cells with a height
    are that level, the more level half of them.  Tree crowns, walls and roof edges are left out of the fit: there
    two photos differ by what each sees of the relief (the crown's sunlit or shaded side, the wall, a
    misregistration by the DSM's error), not by their brightness (issue 33 item 4: on toledo the seam step over
    level ground was 1.5 %, at relief 4.2 %, and the fit bent to the relief)."""
    from scipy import ndimage

    finite = np.isfinite(zs)
    if not finite.any():
        return finite
    span = ndimage.maximum_filter(np.where(finite, zs, -np.inf), 3) - ndimage.minimum_filter(
        np.where(finite, zs, np.inf), 3)
    span = np.where(finite, span, np.inf)
    limit = max(cell, float(np.median(span[finite])))
    return span <= limit


def make_pairs(obs: _Obs, seed: int = 0, max_pairs: int = MAX_PAIRS) -> Tuple[np.ndarray, np.ndarray]:
    """(first, second) observation indices of every two images seeing one cell (at most 8 images a cell)."""
    order = np.argsort(obs.cell, kind="stable")
    cell = obs.cell[order]
    firsts, seconds = [], []
    for d in range(1, 8):
        same = np.flatnonzero(cell[:-d] == cell[d:])
        if not len(same):
            break
        firsts.append(order[same])
        seconds.append(order[same + d])
    if not firsts:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    a, b = np.concatenate(firsts), np.concatenate(seconds)
    keep = obs.image[a] != obs.image[b]
    a, b = a[keep], b[keep]
    if len(a) > max_pairs:
        pick = np.random.default_rng(seed).choice(len(a), max_pairs, replace=False)
        a, b = a[pick], b[pick]
    return a, b


def _sparse_rows(n_rows: int, cols_a, vals_a, cols_b, vals_b, n_cols: int):
    """Sparse (n_rows, n_cols) matrix: per row + vals_a at cols_a minus vals_b at cols_b (lists of columns)."""
    from scipy import sparse

    rows = np.arange(n_rows)
    r = np.concatenate([rows] * (len(cols_a) + len(cols_b)))
    c = np.concatenate(list(cols_a) + list(cols_b))
    v = np.concatenate(list(vals_a) + [-x for x in vals_b])
    return sparse.coo_matrix((v, (r, c)), shape=(n_rows, n_cols)).tocsr()


def _base_design(obs: _Obs, a: np.ndarray, b: np.ndarray, groups: np.ndarray, n_groups: int, n_images: int):
    """Columns: fall-off a1..a3 per group, then one exposure per image."""
    ca, va, cb, vb = [], [], [], []
    for idx, cl, vl in ((a, ca, va), (b, cb, vb)):
        g = groups[obs.image[idx]]
        r2 = obs.r[idx].astype(np.float64) ** 2
        for k in range(3):
            cl.append(3 * g + k)
            vl.append(r2 ** (k + 1))
        cl.append(3 * n_groups + obs.image[idx])
        vl.append(np.ones(len(idx)))
    return _sparse_rows(len(a), ca, va, cb, vb, 3 * n_groups + n_images)


def _hot_columns(e: np.ndarray, obs: _Obs, a, b, groups: np.ndarray, n_groups: int) -> np.ndarray:
    """(pairs, groups) differences of the hot-spot shape ``e`` (per observation)."""
    if n_groups == 1:
        return (e[a] - e[b])[:, None]
    out = np.zeros((len(a), n_groups))
    ga, gb = groups[obs.image[a]], groups[obs.image[b]]
    for g in range(n_groups):
        out[:, g] = np.where(ga == g, e[a], 0.0) - np.where(gb == g, e[b], 0.0)
    return out


def _robust_sigma(res: np.ndarray) -> float:
    return max(1.4826 * float(np.median(np.abs(res))), 1e-4)


def _irls(x, y: np.ndarray, prior: np.ndarray, iterations: int = 4, w: Optional[np.ndarray] = None,
          dense: bool = True):
    """Cauchy-weighted least squares of x @ p = y with the prior p ~ N(0, prior^2): (p, weights, sigma)."""
    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    w = np.ones(len(y)) if w is None else w
    sigma = _robust_sigma(y)
    p = np.zeros(x.shape[1])
    for _ in range(iterations):
        wt = w / sigma ** 2
        xw = x.multiply(wt[:, None]).tocsr() if sparse.issparse(x) else x * wt[:, None]
        m = x.T @ xw
        rhs = x.T @ (wt * y)
        if dense:
            m = m.toarray() if sparse.issparse(m) else np.asarray(m)
            p = np.linalg.solve(m + np.diag(1.0 / prior ** 2), rhs)
        else:
            p = spsolve((m + sparse.diags(1.0 / prior ** 2)).tocsc(), rhs)
        res = y - x @ p
        sigma = _robust_sigma(res)
        w = 1.0 / (1.0 + (res / (2.385 * sigma)) ** 2)
    return p, w, sigma


def _antisolar(azimuth: float, off_nadir: float) -> np.ndarray:
    return np.array([math.sin(off_nadir) * math.cos(azimuth), math.sin(off_nadir) * math.sin(azimuth),
                     -math.cos(off_nadir)])


@dataclass
class _BaseFit:
    """The fall-off and exposure fit of the pairs' log differences that the hot spot is searched against."""

    design: Any  # (pairs, unknowns) sparse design matrix
    prior: np.ndarray  # the unknowns' prior sigmas
    weights: np.ndarray  # the pairs' robust (IRLS) weights
    sigma: float  # the residuals' robust sigma


def _search_hot_spot(obs: _Obs, a, b, y, base: _BaseFit, groups, n_groups) -> Optional[Tuple]:
    """The hot spot's (antisolar direction, width, RSS with / without it) minimising the weighted residual of
    the ``base`` model plus a hot-spot column per group on a subsample of the pairs; None if it does not help."""
    xa, w, sigma, prior_a = base.design, base.weights, base.sigma, base.prior
    rng = np.random.default_rng(1)
    sel = rng.choice(len(a), min(len(a), SEARCH_PAIRS), replace=False)
    a_s, b_s, y_s = a[sel], b[sel], y[sel]
    x_s = xa[sel]
    wt = w[sel] / sigma ** 2
    m_aa = (x_s.T @ x_s.multiply(wt[:, None])).toarray() + np.diag(1.0 / prior_a ** 2)
    v_a = x_s.T @ (wt * y_s)
    yy = float(np.sum(wt * y_s * y_s))
    base_rss = yy - float(np.linalg.solve(m_aa, v_a) @ v_a)
    used = np.unique(np.concatenate([a_s, b_s]))
    rays = obs.rays[used].astype(np.float64)

    def rss_of(theta: np.ndarray, width: float) -> float:
        e = np.zeros(len(obs.logv))
        e[used] = np.exp(-0.5 * (theta / width) ** 2)
        ecol = _hot_columns(e, obs, a_s, b_s, groups, n_groups)
        m_ae = x_s.T @ (ecol * wt[:, None])
        m_ee = ecol.T @ (ecol * wt[:, None]) + np.eye(n_groups) / PRIOR_HOT ** 2
        v_e = ecol.T @ (wt * y_s)
        m = np.block([[m_aa, m_ae], [m_ae.T, m_ee]])
        v = np.concatenate([v_a, v_e])
        try:
            p = np.linalg.solve(m, v)
        except np.linalg.LinAlgError:
            return np.inf
        if np.max(p[-n_groups:]) <= 0.0:  # a hot spot brightens
            return np.inf
        return yy - float(p @ v)

    def search(directions, widths, best):
        for az, beta in directions:
            theta = np.arccos(np.clip(rays @ _antisolar(az, beta), -1.0, 1.0))
            for width in widths:
                rss = rss_of(theta, width)
                if rss < best[0]:
                    best = (rss, (az, beta, width))
        return best

    coarse = [(0.0, 0.0)] + [(az, beta) for az in np.radians(np.arange(0.0, 360.0, 30.0))
                             for beta in np.radians(np.arange(8.0, 57.0, 8.0))]  # at nadir no azimuth
    best = search(coarse, np.radians(HOT_WIDTHS_DEG), (np.inf, None))
    if best[1] is None:
        return None
    for step_az, step_beta, factors in ((10.0, 3.0, (0.8, 1.0, 1.25)), (4.0, 1.0, (0.9, 1.0, 1.1))):
        az0, beta0, w0 = best[1]
        near = [(az0 + math.radians(da), max(0.0, beta0 + math.radians(db)))
                for da in (-step_az, 0.0, step_az) for db in (-step_beta, 0.0, step_beta)]
        best = search(near, [w0 * f for f in factors], best)
    if not best[0] < 0.98 * base_rss:  # not worth a hot spot
        return None
    az, beta, width = best[1]
    return _antisolar(az, beta), width, best[0], base_rss


def _fit_model(obs: _Obs, a, b, groups: np.ndarray, n_groups: int, n_images: int, hot_spot: bool,
               progress: Progress) -> Tuple[RadiometryModel, np.ndarray]:
    """Fall-off, hot spot, exposures, then the fields: the model and the pairs' final residuals."""
    y = obs.logv[a] - obs.logv[b]
    xa = _base_design(obs, a, b, groups, n_groups, n_images)
    prior_a = np.concatenate([np.full(3 * n_groups, PRIOR_FALLOFF), np.full(n_images, PRIOR_EXPOSURE)])
    p, w, sigma = _irls(xa, y, prior_a)
    check_cancel(progress)
    progress.report(0.3, "radiometry: fall-off fitted")
    antisolar, width, hot = np.array([0.0, 0.0, -1.0]), math.radians(10.0), np.zeros(n_groups)
    found = _search_hot_spot(obs, a, b, y, _BaseFit(xa, prior_a, w, sigma), groups, n_groups) if hot_spot else None
    check_cancel(progress)
    progress.report(0.6, "radiometry: hot spot searched")
    e = np.zeros(len(obs.logv))
    if found is not None:
        from scipy import sparse

        antisolar, width = found[0], found[1]
        e = hot_spot_shape(obs.rays.astype(np.float64), antisolar, width)
        x1 = sparse.hstack([xa, sparse.csr_matrix(_hot_columns(e, obs, a, b, groups, n_groups))]).tocsr()
        p1, w, sigma = _irls(x1, y, np.concatenate([prior_a, np.full(n_groups, PRIOR_HOT)]), iterations=3, w=w)
        p, hot = p1[:-n_groups], p1[-n_groups:]
        x1p = x1 @ p1
    else:
        x1p = xa @ p
    falloff = p[:3 * n_groups].reshape(n_groups, 3)
    exposure = p[3 * n_groups:]
    # the per-image fields, on what is left
    y2 = y - x1p
    order = FIELD_ORDER
    nt = field_count(order)
    fa, fb = field_terms(obs.u[a], obs.v[a], order), field_terms(obs.u[b], obs.v[b], order)
    ia, ib = obs.image[a] * nt, obs.image[b] * nt
    x2 = _sparse_rows(len(a), [ia + k for k in range(nt)], [fa[:, k] for k in range(nt)],
                      [ib + k for k in range(nt)], [fb[:, k] for k in range(nt)], nt * n_images)
    prior_f = np.tile([PRIOR_FIELD[d] for d in range(order + 1) for _ in range(d + 1)], n_images)
    p2, w, sigma = _irls(x2, y2, prior_f, iterations=2, w=w, dense=len(prior_f) <= 2000)
    ia, ib, cells = obs.image[a], obs.image[b], obs.cell[a]
    if not chunk_disagreement(ia, ib, cells, obs.shape[1], y2 - x2 @ p2) < \
            FIELD_GAIN * chunk_disagreement(ia, ib, cells, obs.shape[1], y2):
        p2 = np.zeros_like(p2)  # the fields would only fit noise (weak overlaps): left out
    progress.report(0.9, "radiometry: gain fields fitted")
    model = RadiometryModel(groups=[int(g) for g in groups], falloff=falloff.tolist(), hot=hot.tolist(),
                            antisolar=[float(v) for v in antisolar], hot_width=float(width),
                            exposure=exposure.tolist(), fields=p2.reshape(n_images, nt).tolist())
    model.norm = float(np.mean(model.log_model(obs.image, obs.r, obs.u, obs.v, obs.rays)))
    return model, y2 - x2 @ p2


def camera_groups(prep: PreparedBlock) -> Tuple[np.ndarray, List[int]]:
    """(group index per image, the camera ids of the groups)."""
    ids = sorted({int(c.camera_id) for c in prep.cameras})
    return np.array([ids.index(int(c.camera_id)) for c in prep.cameras], dtype=np.int64), ids


def fit_from_samples(obs: _Obs, prep: PreparedBlock, hot_spot: bool, progress: Progress
                     ) -> Tuple[Optional[RadiometryModel], Dict[str, object]]:
    """The model fitted on sampled observations, with the overlaps' disagreement before and after; None (and
    the reason in the summary) when the overlaps are too few or the fit does not make them agree better."""
    groups, ids = camera_groups(prep)
    a, b = make_pairs(obs)
    summary: Dict[str, object] = {"pairs": int(len(a)), "observations": int(len(obs.logv))}
    if len(a) < MIN_PAIRS:
        summary["skipped"] = f"only {len(a)} overlapping samples (at least {MIN_PAIRS} needed)"
        return None, summary
    model, res = _fit_model(obs, a, b, groups, len(ids), len(prep.cameras), hot_spot, progress)
    cols = obs.shape[1]
    before = chunk_disagreement(obs.image[a], obs.image[b], obs.cell[a], cols, obs.logv[a] - obs.logv[b])
    after = chunk_disagreement(obs.image[a], obs.image[b], obs.cell[a], cols, res)
    summary.update({"overlap_step_before": before, "overlap_step_after": after, "camera_ids": ids,
                    "falloff": {str(cid): [round(float(model.falloff_at(g, r)), 4) for r in (0.25, 0.5, 0.75, 1.0)]
                                for g, cid in enumerate(ids)},
                    "hot_spot": [round(h, 4) for h in model.hot], "antisolar": [round(v, 5) for v in model.antisolar],
                    "hot_width_deg": round(math.degrees(model.hot_width), 2)})
    if not (after < before):
        summary["skipped"] = (f"the fit does not make the overlaps agree better ({100 * before:.1f} % before, "
                              f"{100 * after:.1f} % after)")
        return None, summary
    return model, summary


def fit_radiometry_model(prep: PreparedBlock, dsm: Dsm, offset: np.ndarray, hot_spot: bool, progress: Progress
                         ) -> Tuple[Optional[RadiometryModel], Dict[str, object]]:
    """The radiometric model fitted from the overlaps (None where it is not applied) and its summary: before the
    mosaic is planned (the plan keeps each photo's hot spot core out where another photo sees that ground:
    core.ortho.hotspot)."""
    from ..common.progress import SubProgress

    obs = sample_overlaps(prep, dsm, offset, SubProgress(progress, 0.0, 0.45))
    return fit_from_samples(obs, prep, hot_spot, SubProgress(progress, 0.45, 1.0))


def radiometry_lines(model: Optional[RadiometryModel], summary: Dict[str, object], prep: PreparedBlock, dsm: Dsm,
                     offset: np.ndarray, labels: np.ndarray, k: int, gains: Sequence[float]
                     ) -> Tuple[Optional[RadiometryModel], List[str]]:
    """The seam steps of the plan (``labels``) before and after the model, and the model (None where it makes the
    seams worse) with its lines for the log; the model's ``summary`` holds the figures."""
    summary.update(seam_steps(model, labels, k, prep, dsm, offset, gains))
    before, after = summary["seam_step_before"], summary["seam_step_after"]
    if model is None:
        return None, [f"radiometry left as it is: {summary.get('skipped')}; brightness step across the seams "
                      f"{100 * before:.1f} % (median)"]
    if after > before:
        summary["skipped"] = f"the seams' brightness step would grow ({100 * before:.1f} % -> {100 * after:.1f} %)"
        return None, [f"radiometry left as it is: {summary['skipped']}"]
    model.summary = summary
    fall = "; ".join(f"camera {cid}: " + ", ".join(f"{v:.3f}" for v in vals)
                     for cid, vals in summary["falloff"].items())
    lines = [f"radiometry: vignetting (fall-off at r = 0.25, 0.5, 0.75, 1 of the half diagonal) {fall}"]
    if any(h != 0.0 for h in model.hot):
        d = model.antisolar
        elev = math.degrees(math.asin(min(1.0, max(-1.0, -d[2]))))
        az = math.degrees(math.atan2(-d[1], -d[0])) % 360.0
        lines.append(f"radiometry: hot spot +{100 * (math.exp(max(model.hot)) - 1):.1f} %, "
                     f"{math.degrees(model.hot_width):.0f} deg wide, sun at {elev:.0f} deg elevation, "
                     f"azimuth {az:.0f} deg from the x axis")
    lines.append(f"radiometry: brightness step across the seams {100 * before:.1f} % before, {100 * after:.1f} % "
                 f"after (median; on level ground, {100 * summary['seam_level_fraction']:.0f} % of the seam, "
                 f"{100 * summary['seam_step_level_before']:.1f} % -> {100 * summary['seam_step_level_after']:.1f} %)"
                 f"; between overlapping images {100 * summary['overlap_step_before']:.1f} % -> "
                 f"{100 * summary['overlap_step_after']:.1f} %")
    return model, lines


def fit_radiometry(prep: PreparedBlock, dsm: Dsm, offset: np.ndarray, labels: np.ndarray, k: int,
                   gains: Sequence[float], hot_spot: bool, progress: Progress
                   ) -> Tuple[Optional[RadiometryModel], List[str]]:
    """The radiometric model of the mosaic (None when it is not applied) and its lines for the log; the model's
    ``summary`` (also on a skip: in the log) holds the figures: the seam step before and after, the fitted
    fall-off at r = 0.25, 0.5, 0.75, 1 per camera, the hot spot."""
    model, summary = fit_radiometry_model(prep, dsm, offset, hot_spot, progress)
    return radiometry_lines(model, summary, prep, dsm, offset, labels, k, gains)
