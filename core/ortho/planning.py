"""Mosaic planning: which image each planning cell takes (closest to nadir), seamlines moved to where the images
agree (minimum cut), kept off raised objects, and one exposure gain per image."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import Progress, check_cancel
from ..io import raster as dsmmod
from .block import PreparedBlock
from .grid import cell_centre_coords, subgrid
from .options import OrthoOptions
from .sampling import sample_camera
from .seamlines import SeamlineEdits, force_edits
from .surface import Dsm

PLANNING_GSD = 4.0  # planning cell = 4 x GSD ...
# ... and a photo spans at most about this many planning cells (its long side): the plan (which image, seams, raised
# objects) is about the scene's objects, not the photo's pixels, so a larger photo of the same ground gets no finer
# plan (2400 px photos plan at 8 GSD, the same cells on the ground as their 1200 px copies at 4 GSD; the figures
# are in docs/measurements.md); the tiles still feather and sample every cell
PLANNING_MAX_CELLS_ACROSS = 300
MAX_PLANNING_CELLS = 4096 * 4096


@dataclass
class MosaicPlan:
    k: int  # planning cell = k output cells
    width: int
    height: int
    labels_path: str  # int32 (height, width), -1 = no image
    gains: List[float]
    windows: List[Optional[Tuple[int, int, int, int]]]  # per camera: (r0, c0, h, w) in planning cells
    feather_cells: int
    relief_blobs: int
    relief_reassigned: int
    seam_before: float = float("nan")  # mean brightness disagreement of the two images along the seams
    seam_after: float = float("nan")
    hidden_cells: int = 0  # mosaic cells hidden from every image, taken from the least hidden one (tiles)
    forced_cells: int = 0  # planning cells given to the image an edited seamline polygon names (SEAMLINES_IN)
    notes: List[str] = field(default_factory=list)  # lines for the log (the edited seamlines' outcome)


def planning_gsd(metas) -> float:
    """The planning cell in GSD: PLANNING_GSD, coarser where the photos' median long side exceeds
    PLANNING_MAX_CELLS_ACROSS of those cells."""
    sides = [max(m.width, m.height) for m in metas]
    if not sides:
        return PLANNING_GSD
    return max(PLANNING_GSD, float(np.median(sides)) / PLANNING_MAX_CELLS_ACROSS)


def plan_mosaic(prep: PreparedBlock, dsm: Dsm, offset: np.ndarray, options: OrthoOptions, workdir: str,
                 progress: Progress, edits: Optional[SeamlineEdits] = None) -> MosaicPlan:
    grid = prep.grid
    k = max(1, int(round(planning_gsd(prep.metas) * prep.gsd / grid.resolution)))
    while math.ceil(grid.width / k) * math.ceil(grid.height / k) > MAX_PLANNING_CELLS:
        k += 1
    pw, ph = int(math.ceil(grid.width / k)), int(math.ceil(grid.height / k))
    p = k * grid.resolution
    pgrid = dsmmod.Grid(grid.x0, grid.y0, p, pw, ph)
    # DSM at planning cells
    zp = np.full((ph, pw), np.nan, dtype=np.float32)
    rows = max(1, 1_000_000 // pw)
    for r0 in range(0, ph, rows):
        h = min(rows, ph - r0)
        x, y = cell_centre_coords(pgrid, r0, 0, h, pw)
        zp[r0:r0 + h] = dsm.sample(x, y).reshape(h, pw)
    best = np.full((ph, pw), np.inf, dtype=np.float32)
    labels = np.full((ph, pw), -1, dtype=np.int32)
    windows: List[Optional[Tuple[int, int, int, int]]] = []
    costs: List[Optional[np.ndarray]] = []
    greys: List[Optional[np.ndarray]] = []
    n = len(prep.cameras)
    for i, (cam, meta, fp, vis) in enumerate(zip(prep.cameras, prep.metas, prep.footprints, prep.visibility)):
        check_cancel(progress)
        sub = subgrid(pgrid, fp.bbox)
        windows.append(sub)
        if sub is None:
            costs.append(None)
            greys.append(None)
            continue
        r0, c0, h, w = sub
        x, y = cell_centre_coords(pgrid, r0, c0, h, w)
        z = zp[r0:r0 + h, c0:c0 + w].ravel().astype(np.float64)
        s = sample_camera(cam, meta, offset, x, y, z, vis, "bilinear")
        cost = s.cost.reshape(h, w)
        costs.append(cost)
        greys.append(s.values.mean(axis=1).reshape(h, w).astype(np.float32))
        win_best = best[r0:r0 + h, c0:c0 + w]
        better = cost < win_best
        win_best[better] = cost[better]
        labels[r0:r0 + h, c0:c0 + w][better] = i
        progress.report(0.7 * (i + 1) / n, f"planning the mosaic: {i + 1}/{n}")

    # exposure gains (OpenCV's gain compensator: overlaps' mean intensities)
    gains = [1.0] * n
    if options.exposure:
        gains = _exposure_gains(windows, costs, greys, prep.metas[0].dtype)
    greys = [None if g is None else g * np.float32(gi) for g, gi in zip(greys, gains)]

    # seamlines where the overlapping images agree and the scene is smooth (not across edges or moving things)
    scale = float(np.iinfo(np.dtype(prep.metas[0].dtype)).max) if np.dtype(prep.metas[0].dtype).kind in "ui" else 1.0
    seam_before = _seam_disagreement(labels, windows, greys, scale)
    if options.seam_iterations > 0:
        labels = _refine_seams(labels, windows, costs, greys, scale, options.seam_iterations, options.seam_alpha)
    seam_after = _seam_disagreement(labels, windows, greys, scale)

    # relief: objects above their surroundings go whole to one image
    blobs = reassigned = 0
    if options.avoid_relief and np.isfinite(zp).any():
        blobs, reassigned = _avoid_relief(labels, zp, p, windows, costs, options.relief_height)
    forced, notes = 0, []
    if edits is not None:  # edited seamlines: the image each polygon names, where it sees the ground
        forced, notes = force_edits(labels, pgrid, edits, [c.name for c in prep.cameras], costs, windows)
    np.save(os.path.join(workdir, "labels.npy"), labels)
    progress.report(1.0, "mosaic planned")
    feather = max(1, int(round(options.feather_gsd * prep.gsd / (2 * p)))) if options.blending == "feather" else 0
    return MosaicPlan(k, pw, ph, os.path.join(workdir, "labels.npy"), gains, windows, feather, blobs, reassigned,
                 seam_before, seam_after, forced_cells=forced, notes=notes)


def _avoid_relief(labels: np.ndarray, zp: np.ndarray, p: float, windows, costs, relief_height: float
                  ) -> Tuple[int, int]:
    """Give each object standing more than ``relief_height`` above its surroundings (a morphological top-hat of
    the planning DSM ``zp``, cells of ``p`` metres) whole to one image that sees all of it, so no seam cuts a
    roof or a crown.  Changes ``labels`` in place; returns (raised objects, objects reassigned)."""
    cv2 = require("cv2", "orthophotos")
    reassigned = 0
    zf = np.where(np.isfinite(zp), zp, np.nanmin(zp)).astype(np.float32)
    radius = max(1, int(math.ceil(12.0 / p)))  # objects up to ~24 m across
    ker = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * radius + 1, 2 * radius + 1))
    opened = cv2.dilate(cv2.erode(zf, ker), ker)
    core = (zf - opened) > relief_height
    margin = max(1, int(math.ceil(1.0 / p)))
    tall = cv2.dilate(core.astype(np.uint8), cv2.getStructuringElement(
        cv2.MORPH_ELLIPSE, (2 * margin + 1, 2 * margin + 1))) > 0
    from scipy import ndimage

    lab, nb = ndimage.label(tall)
    blobs = int(nb)
    if nb:
        slices = ndimage.find_objects(lab)
        for b, sl in enumerate(slices, start=1):
            if sl is None:
                continue
            region = lab[sl] == b
            region_core = core[sl][region]
            current = labels[sl][region]
            present = np.unique(current[current >= 0])
            if len(present) <= 1:
                continue
            br0, bc0 = sl[0].start, sl[1].start
            choice, choice_key = None, None
            for cid in present:
                win = windows[cid]
                if win is None:
                    continue
                wr0, wc0, wh, ww = win
                rr, cc = np.nonzero(region)
                rr = rr + br0 - wr0
                cc = cc + bc0 - wc0
                inwin = (rr >= 0) & (rr < wh) & (cc >= 0) & (cc < ww)
                vals = np.full(len(rr), np.inf, dtype=np.float32)
                vals[inwin] = costs[cid][rr[inwin], cc[inwin]]
                frac = float(np.isfinite(vals[region_core]).mean()) if region_core.any() else 0.0
                key = (frac >= 0.97, -float(np.mean(vals[np.isfinite(vals)])) if np.isfinite(vals).any() else -1e9)
                if choice_key is None or key > choice_key:
                    choice, choice_key, choice_vals = cid, key, vals
            if choice is None or not choice_key[0]:
                continue
            sub_labels = labels[sl]
            put = region.copy()
            put[region] = np.isfinite(choice_vals)
            sub_labels[put] = choice
            reassigned += 1
    return blobs, reassigned


def _gather(arrays: Sequence[Optional[np.ndarray]], windows, lab: np.ndarray, rr: np.ndarray, cc: np.ndarray,
            fill: float = np.inf) -> np.ndarray:
    """arrays[lab[k]][rr[k], cc[k]] in planning coordinates (each array covers its image's window)."""
    out = np.full(len(rr), fill, dtype=np.float32)
    for i in np.unique(lab):
        if i < 0 or windows[i] is None or arrays[i] is None:
            continue
        sel = np.flatnonzero(lab == i)
        r0, c0, h, w = windows[i]
        r, c = rr[sel] - r0, cc[sel] - c0
        ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        out[sel[ok]] = arrays[i][r[ok], c[ok]]
    return out


_NEIGHBOURS = ((-1, 0), (1, 0), (0, -1), (0, 1))


def _seam_cells(labels: np.ndarray, parity: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
    h, w = labels.shape
    b = np.zeros_like(labels, dtype=bool)
    b[1:] |= labels[1:] != labels[:-1]
    b[:-1] |= labels[:-1] != labels[1:]
    b[:, 1:] |= labels[:, 1:] != labels[:, :-1]
    b[:, :-1] |= labels[:, :-1] != labels[:, 1:]
    b &= labels >= 0
    if parity is not None:
        rr, cc = np.indices((h, w))
        b &= (rr + cc) % 2 == parity
    return np.nonzero(b)


def _seam_disagreement(labels: np.ndarray, windows, greys, scale: float) -> float:
    """Mean |difference| (fraction of full scale) of the two images on either side of the seams."""
    rr, cc = _seam_cells(labels)
    if not len(rr):
        return 0.0
    h, w = labels.shape
    own = labels[rr, cc]
    tot, n = 0.0, 0
    ga = _gather(greys, windows, own, rr, cc, np.nan)
    for dr, dc in _NEIGHBOURS:
        qr, qc = np.clip(rr + dr, 0, h - 1), np.clip(cc + dc, 0, w - 1)
        other = labels[qr, qc]
        m = (other != own) & (other >= 0)
        if m.any():
            gb = _gather(greys, windows, other[m], rr[m], cc[m], np.nan)
            d = np.abs(ga[m] - gb)
            d = d[np.isfinite(d)]
            tot += float(d.sum())
            n += len(d)
    return tot / n / scale if n else 0.0


# seamline moves (_refine_seams): how far a seam may move, in planning cells, and the brightness difference (a
# fraction of full scale) that costs a seam edge as much as crossing it
SEAM_BAND = 8
SEAM_TOL = 0.05


def _refine_seams(labels: np.ndarray, windows, costs, greys, scale: float, iterations: int = 1,
                  alpha: float = 5.0) -> np.ndarray:
    """Move the seamline between every two adjacent images within a band of SEAM_BAND planning cells to where the
    two images agree and the scene has no edges: a minimum cut (scipy max-flow) of the band with the cost
    alpha * view cost per cell and, per seam edge, 1 + |grey_a - grey_b| / tol + mean gradient / tol
    (brightness as a fraction of full scale, tol = SEAM_TOL).  Cells outside the band, or seen by only one of the
    two, stay."""
    tol, band = SEAM_TOL, SEAM_BAND
    cv2 = require("cv2", "orthophotos")
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, maximum_flow

    grads = []
    for g in greys:
        if g is None:
            grads.append(None)
            continue
        gf = np.where(np.isfinite(g), g, 0.0).astype(np.float32) / scale
        gx = cv2.Sobel(gf, cv2.CV_32F, 1, 0, ksize=3) / 8.0
        gy = cv2.Sobel(gf, cv2.CV_32F, 0, 1, ksize=3) / 8.0
        grads.append(np.hypot(gx, gy))
    norm = [None if g is None else g / scale for g in greys]
    labels = labels.copy()
    h, w = labels.shape
    kernel = np.ones((2 * band + 1, 2 * band + 1), np.uint8)
    for _ in range(max(1, iterations)):
        pairs = set()
        for a_, b_ in ((labels[:, 1:], labels[:, :-1]), (labels[1:], labels[:-1])):
            m = (a_ != b_) & (a_ >= 0) & (b_ >= 0)
            for u, v in zip(a_[m].tolist(), b_[m].tolist()):
                pairs.add((min(u, v), max(u, v)))
        changed = 0
        for la, lb in sorted(pairs):
            in_a, in_b = labels == la, labels == lb
            seam = np.zeros_like(in_a)
            seam[:, 1:] |= (in_a[:, 1:] & in_b[:, :-1]) | (in_b[:, 1:] & in_a[:, :-1])
            seam[:, :-1] |= (in_a[:, :-1] & in_b[:, 1:]) | (in_b[:, :-1] & in_a[:, 1:])
            seam[1:] |= (in_a[1:] & in_b[:-1]) | (in_b[1:] & in_a[:-1])
            seam[:-1] |= (in_a[:-1] & in_b[1:]) | (in_b[:-1] & in_a[1:])
            if not seam.any():
                continue
            rows, cols = np.nonzero(seam)
            r0, r1 = max(0, rows.min() - band - 1), min(h, rows.max() + band + 2)
            c0, c1 = max(0, cols.min() - band - 1), min(w, cols.max() + band + 2)
            sub = labels[r0:r1, c0:c1]
            near = cv2.dilate(seam[r0:r1, c0:c1].astype(np.uint8), kernel) > 0
            cand = near & ((sub == la) | (sub == lb))
            rr, cc = np.nonzero(cand)
            gr, gc = rr + r0, cc + c0
            ca = _gather(costs, windows, np.full(len(rr), la), gr, gc)
            cb = _gather(costs, windows, np.full(len(rr), lb), gr, gc)
            ok = np.isfinite(ca) & np.isfinite(cb)
            if ok.sum() < 4:
                continue
            rr, cc, gr, gc, ca, cb = rr[ok], cc[ok], gr[ok], gc[ok], ca[ok], cb[ok]
            n = len(rr)
            index = np.full(sub.shape, -1, dtype=np.int64)
            index[rr, cc] = np.arange(n)
            ga = _gather(norm, windows, np.full(n, la), gr, gc, np.nan)
            gb = _gather(norm, windows, np.full(n, lb), gr, gc, np.nan)
            diff = np.nan_to_num(np.abs(ga - gb), nan=0.2)
            edge = (_gather(grads, windows, np.full(n, la), gr, gc, 0.0)
                    + _gather(grads, windows, np.full(n, lb), gr, gc, 0.0)) / 2.0
            unit = diff / tol + edge / tol  # per cell; an edge costs 1 + the mean of its two cells
            d_a = alpha * ca.astype(np.float64)  # cost of giving the cell to la
            d_b = alpha * cb.astype(np.float64)
            src, dst, cap = [], [], []
            for dr, dc in ((0, 1), (1, 0), (0, -1), (-1, 0)):
                qr, qc = rr + dr, cc + dc
                inside = (qr >= 0) & (qr < sub.shape[0]) & (qc >= 0) & (qc < sub.shape[1])
                q = np.full(n, -1, dtype=np.int64)
                q[inside] = index[qr[inside], qc[inside]]
                lq = np.full(n, -1, dtype=labels.dtype)
                lq[inside] = sub[qr[inside], qc[inside]]
                fixed = inside & (q < 0) & (lq >= 0)  # a neighbour that keeps its label
                wgt = 1.0 + unit
                d_a += np.where(fixed & (lq != la), wgt, 0.0)
                d_b += np.where(fixed & (lq != lb), wgt, 0.0)
                if dr >= 0 and dc >= 0:  # each free-free edge once, both directions
                    both = q >= 0
                    if both.any():
                        wq = 1.0 + 0.5 * (unit[both] + unit[q[both]])
                        src += [np.arange(n)[both], q[both]]
                        dst += [q[both], np.arange(n)[both]]
                        cap += [wq, wq]
            s_node, t_node = n, n + 1
            lo = np.minimum(d_a, d_b)
            src += [np.full(n, s_node), np.arange(n)]
            dst += [np.arange(n), np.full(n, t_node)]
            cap += [d_b - lo, d_a - lo]  # cutting s->p puts p on lb's side (pays d_b), p->t on la's side
            cap_i = np.maximum(0, np.rint(np.concatenate(cap) * 100.0)).astype(np.int32)
            si, di = np.concatenate(src), np.concatenate(dst)
            keep = cap_i > 0
            graph = coo_matrix((cap_i[keep], (si[keep], di[keep])), shape=(n + 2, n + 2)).tocsr()
            flow = maximum_flow(graph, s_node, t_node).flow
            residual = (graph - flow).tocsr()
            residual.data = (residual.data > 0).astype(np.int8)
            residual.eliminate_zeros()
            reach = breadth_first_order(residual, s_node, directed=True, return_predecessors=False)
            side_a = np.zeros(n + 2, dtype=bool)
            side_a[reach] = True
            new = np.where(side_a[:n], la, lb)
            moved = new != sub[rr, cc]
            sub[rr[moved], cc[moved]] = new[moved]
            changed += int(moved.sum())
        if changed == 0:
            break
    return labels


def _exposure_gains(windows, costs, greys, dtype: str) -> List[float]:
    n = len(windows)
    scale = float(np.iinfo(np.dtype(dtype)).max) if np.dtype(dtype).kind in "ui" else 1.0
    sigma_n, sigma_g = 10.0 / 255.0, 0.1
    a = np.zeros((n, n))
    b = np.zeros(n)
    for i in range(n):
        wi = windows[i]
        if wi is None or greys[i] is None:
            continue
        for j in range(i + 1, n):
            wj = windows[j]
            if wj is None or greys[j] is None:
                continue
            r0, c0 = max(wi[0], wj[0]), max(wi[1], wj[1])
            r1, c1 = min(wi[0] + wi[2], wj[0] + wj[2]), min(wi[1] + wi[3], wj[1] + wj[3])
            if r1 <= r0 or c1 <= c0:
                continue
            si = (slice(r0 - wi[0], r1 - wi[0]), slice(c0 - wi[1], c1 - wi[1]))
            sj = (slice(r0 - wj[0], r1 - wj[0]), slice(c0 - wj[1], c1 - wj[1]))
            both = np.isfinite(costs[i][si]) & np.isfinite(costs[j][sj])
            nij = int(both.sum())
            if nij < 16:
                continue
            iij = float(greys[i][si][both].mean()) / scale
            iji = float(greys[j][sj][both].mean()) / scale
            for p, q, ip, iq in ((i, j, iij, iji), (j, i, iji, iij)):
                a[p, p] += nij * (ip * ip / sigma_n ** 2 + 1.0 / sigma_g ** 2)
                a[p, q] -= nij * ip * iq / sigma_n ** 2
                b[p] += nij / sigma_g ** 2
    gains = np.ones(n)
    used = np.flatnonzero(np.diag(a) > 0)
    if len(used):
        try:
            g = np.linalg.solve(a[np.ix_(used, used)], b[used])
            gains[used] = np.clip(g, 0.5, 2.0)
        except np.linalg.LinAlgError:
            pass
    return [float(v) for v in gains]
