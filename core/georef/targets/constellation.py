"""The triangulated marks (model frame) matched to the surveyed targets (world): names without a prior needed.

Every triangle of marks is compared by shape (its sides' ratios, free of scale) with every triangle of
targets; each pair of similar triangles gives a similarity (Umeyama, scale free), tried as it is and with the
survey mirrored (x negated: swapped or flipped axes) when it does not fit as given (a planar constellation fits
its mirror image too, turned over); the hypothesis that brings the most marks within the
tolerance of a distinct target wins, refitted on them.  A mark is named only when its nearest target is within
the tolerance and clearly nearer than the next; a coded mark whose code names another target, or a named
mark left outside the tolerance after the refit, is reported, never assigned.

The tolerance scales with the survey: a fraction of the median distance between neighbouring targets (names
closer than that cannot be told apart by position alone).  Placeholder heights (every target at one Z) are
matched in X, Y only (``xy_only``).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ...geometry.similarity import Similarity, fit_similarity, helmert_fit

MIRROR = np.diag([-1.0, 1.0, 1.0])


@dataclass
class Constellation:
    """The match: ``names`` {mark index: target name}; ``residuals`` {mark index: distance to its target (world
    units)}; ``similarity`` model -> world (of the mirrored survey when ``mirrored``); ``reports``: what did
    not fit."""

    names: Dict[int, str] = field(default_factory=dict)
    residuals: Dict[int, float] = field(default_factory=dict)
    similarity: Optional[Similarity] = None
    mirrored: bool = False
    tolerance: float = 0.0
    rms: float = float("nan")
    reports: List[str] = field(default_factory=list)


def _signatures(p: np.ndarray, idx: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Per triangle: shape (shortest / longest, middle / longest) and its vertices ordered by the opposite side
    (vertex opposite the shortest side first)."""
    a, b, c = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
    sides = np.stack([np.linalg.norm(b - c, axis=1), np.linalg.norm(a - c, axis=1),
                      np.linalg.norm(a - b, axis=1)], 1)  # opposite vertex 0, 1, 2
    order = np.argsort(sides, axis=1)
    s = np.take_along_axis(sides, order, 1)
    sig = np.stack([s[:, 0] / np.maximum(s[:, 2], 1e-12), s[:, 1] / np.maximum(s[:, 2], 1e-12)], 1)
    return sig, np.take_along_axis(idx, order, 1)


def _assign(model_w: np.ndarray, world: np.ndarray, tol: float, xy_only: bool) -> Dict[int, Tuple[int, float]]:
    """{mark: (target, distance)}: nearest target within ``tol``, clearly nearer than the second, one mark per
    target (the nearest)."""
    d = model_w[:, None, :] - world[None, :, :]
    dist = np.linalg.norm(d[..., :2] if xy_only else d, axis=2)
    out: Dict[int, Tuple[int, float]] = {}
    best: Dict[int, Tuple[int, float]] = {}
    for i in range(len(model_w)):
        order = np.argsort(dist[i])
        j = int(order[0])
        second = dist[i, order[1]] if len(order) > 1 else np.inf
        if dist[i, j] <= tol and second > max(2.0 * dist[i, j], tol):
            if j not in best or dist[i, j] < best[j][1]:
                best[j] = (i, float(dist[i, j]))
    for j, (i, dd) in best.items():
        out[i] = (j, dd)
    return out


def _hypotheses(model: np.ndarray, world: np.ndarray, shape_tol: float, limit: int, wts: np.ndarray):
    """Pairs (mark triangle, target triangle) of like shape, best-evidenced mark triangles first."""
    m_idx = np.array(list(itertools.combinations(range(len(model)), 3)))
    w_idx = np.array(list(itertools.combinations(range(len(world)), 3)))
    m_sig, m_ord = _signatures(model, m_idx)
    w_sig, w_ord = _signatures(world, w_idx)
    keep_m = m_sig[:, 0] > 0.15  # thin triangles fix no rotation
    keep_w = w_sig[:, 0] > 0.15
    m_sig, m_ord, w_sig, w_ord = m_sig[keep_m], m_ord[keep_m], w_sig[keep_w], w_ord[keep_w]
    if not len(m_sig) or not len(w_sig):
        return []
    diff = np.abs(m_sig[:, None, :] - w_sig[None, :, :]).max(2)
    mi, wi = np.nonzero(diff < shape_tol)
    evidence = wts[m_ord].sum(1)
    order = np.lexsort((diff[mi, wi], -evidence[mi]))[:limit]
    return [(m_ord[mi[k]], w_ord[wi[k]]) for k in order]


@dataclass
class Marks:
    """Marks found on the photos and triangulated: ``xyz`` (M, 3) in the model; ``codes``: per mark, the target
    name its code (coded targets) or a click gives, or None; ``weights``: per mark, its evidence (the number of
    photos it was tied in; None: 1 each)."""

    xyz: np.ndarray
    codes: Optional[Sequence[Optional[str]]] = None
    weights: Optional[Sequence[float]] = None


TOL_FRACTION = 0.3  # the match's tolerance: this fraction of the median distance between neighbouring targets
MIN_MARKS = 4  # marks that must agree (three always fit some triangle)


def match_constellation(marks: Marks, world: np.ndarray, names: Sequence[str], xy_only: bool = False,
                        prior: Optional[Similarity] = None, prior_tol: float = 0.0, unit: str = "") -> Constellation:
    """Name the marks ``marks.xyz`` (M, 3) after the targets ``world`` (K, 3) called ``names``; a mark with a
    code names no other target.  Needs at least ``MIN_MARKS`` marks to agree (three always fit some triangle);
    fewer, or two hypotheses equally good with different names, name nothing.  Triangles are drawn from the
    best-evidenced marks (``marks.weights``: twice as many as targets, and four more) and a hypothesis scores
    the evidence it brings onto targets.  ``prior``: a rough model -> world similarity (EXIF GPS): a hypothesis
    that puts one of its triangle's marks further than ``prior_tol`` plus the tolerance (horizontally) from where
    the prior puts it is not tried, nor the mirror.  ``unit``: the targets' unit (m, ft), said with every
    distance reported.  Fewer than three targets form no triangle: reported, nothing named."""
    model = np.asarray(marks.xyz, dtype=float).reshape(-1, 3)
    world = np.asarray(world, dtype=float).reshape(-1, 3)
    codes = list(marks.codes) if marks.codes is not None else [None] * len(model)
    weights = marks.weights
    out = Constellation()
    u = f" {unit}" if unit else ""
    if len(world) < 3:
        out.reports.append(f"{len(world)} target(s): the marks are matched to the shape of three targets or more; "
                           "nothing named by position")
        return out
    if len(model) < 3:
        out.reports.append(f"{len(model)} mark(s) triangulated and {len(world)} target(s): too few to match")
        return out
    xy = world[:, :2]
    nn = np.sort(np.linalg.norm(xy[:, None] - xy[None], axis=2), axis=1)[:, 1]
    tol = TOL_FRACTION * float(np.median(nn))
    out.tolerance = tol
    centre = world.mean(0)
    wts = np.ones(len(model)) if weights is None else np.asarray(weights, dtype=float)
    top = np.argsort(-wts, kind="stable")[:2 * len(world) + 4]
    best, second = None, None
    guess = prior.apply(model) - centre if prior is not None else None
    for mirrored in (False, True):
        if mirrored and guess is not None:
            break  # the GPS fixes the handedness
        if mirrored and best is not None and len(best[2]) >= min(MIN_MARKS, len(world)):
            break  # the mirror only when the survey as given does not fit: a planar constellation fits both
        w = (world - centre) @ MIRROR.T if mirrored else world - centre
        for mt, wt in _hypotheses(model[top], w, 0.03, 4000, wts[top]):
            mt = top[mt]
            if guess is not None and np.linalg.norm(guess[mt, :2] - w[wt, :2], axis=1).max() > prior_tol + tol:
                continue
            try:
                sim = helmert_fit(model[mt], w[wt])
            except ValueError:
                continue
            a = _assign(sim.apply(model), w, tol, xy_only)
            agree = sum(wts[i] for i, (j, _) in a.items() if codes[i] in (None, names[j]))
            score = (agree, -sum(d for _, d in a.values()))
            key = frozenset((i, j) for i, (j, _) in a.items())
            if best is None or score > best[0]:
                if best is not None and best[2] != key:
                    second = best
                best = (score, mirrored, key, sim)
            elif key != best[2] and (second is None or score > second[0]):
                second = (score, mirrored, key, sim)
    if best is None or len(best[2]) < min(MIN_MARKS, len(world)):
        out.reports.append(f"no similarity brings {min(MIN_MARKS, len(world))} or more of the {len(model)} "
                           f"triangulated marks onto distinct targets within {tol:.3g}{u}: no name given")
        return out
    margin = 0.5 * float(np.median([wts[i] for i, _ in best[2]]))  # half a typical mark's evidence
    if second is not None and _conflict(best[2], second[2]) and second[0][0] > best[0][0] - margin:
        out.reports.append(f"two ways of naming the marks fit almost equally well ({best[0][0]:.0f} and "
                           f"{second[0][0]:.0f} tied observations on targets within {tol:.3g}{u}): no name given, "
                           "rather than a wrong one (a regular constellation, or coordinates that disagree with the "
                           "block by about the targets' spacing); give coded targets or check the coordinates")
        return out
    return _refit(out, Marks(model, codes, wts), world - centre, names, best, xy_only, tol, u)


def _mutual(model_w: np.ndarray, world: np.ndarray, taken: Dict[int, Tuple[int, float]], xy_only: bool,
            evidence: np.ndarray) -> Dict[int, Tuple[int, float]]:
    """Beyond the tolerance (a survey or a block off by metres): a mark (tied in two photos or more, on the
    block's surface) and a target that are each other's nearest among the ones left, the mark nearer to the target than the
    target's nearest neighbouring target is (each such naming is reported)."""
    used = {j for j, _ in taken.values()}
    free_m = [i for i in range(len(model_w)) if i not in taken and evidence[i] >= 2]
    free_w = [j for j in range(len(world)) if j not in used]
    if not free_m or not free_w:
        return {}
    d = model_w[free_m][:, None, :] - world[free_w][None, :, :]
    dist = np.linalg.norm(d[..., :2] if xy_only else d, axis=2)
    xy = world[:, :2]
    nn = np.sort(np.linalg.norm(xy[:, None] - xy[None], axis=2), axis=1)[:, 1]
    out = {}
    for a, i in enumerate(free_m):
        b = int(np.argmin(dist[a]))
        if int(np.argmin(dist[:, b])) == a and dist[a, b] < nn[free_w[b]]:
            out[i] = (free_w[b], float(dist[a, b]))
    return out


def _conflict(a: frozenset, b: frozenset) -> bool:
    """Two matches give a mark different names (two marks at one target, the same naming otherwise, is one
    similarity: not a conflict)."""
    mb = dict(b)
    return any(mb.get(i, j) != j for i, j in a)


def _refit(out: Constellation, marks: Marks, world_c: np.ndarray, names, best, xy_only, tol,
           u: str = "") -> Constellation:
    """The best hypothesis's similarity fitted to all its pairs (``world_c``: the targets about their centre), the
    marks named after the targets it brings them onto."""
    model, codes, evidence = marks.xyz, marks.codes, np.asarray(marks.weights, dtype=float)
    _, mirrored, key, sim = best
    w = world_c @ MIRROR.T if mirrored else world_c
    pairs = sorted(key)
    if len(pairs) >= 3:
        sim, _ = fit_similarity(model[[i for i, _ in pairs]], w[[j for _, j in pairs]], xy_only=xy_only)
    a = _assign(sim.apply(model), w, tol, xy_only)
    a.update(_mutual(sim.apply(model), w, a, xy_only, evidence))
    res = [d for _, d in a.values()]
    out.rms = float(np.sqrt(np.mean(np.square(res)))) if res else float("nan")
    out.similarity, out.mirrored = sim, mirrored
    if mirrored:
        out.reports.append("the marks fit the survey mirrored (x and y swapped, or one axis flipped?): check the "
                           "coordinates' axis order and CRS")
    for i, (j, d) in sorted(a.items()):
        if codes[i] is not None and codes[i] != names[j]:
            out.reports.append(f"a mark coded or clicked as {codes[i]} sits at target {names[j]} ({d:.3g}{u} from "
                               "it): not assigned")
            continue
        out.names[i] = names[j]
        out.residuals[i] = d
        if d > tol:
            out.reports.append(f"target {names[j]} is {d:.3g}{u} from its mark after the fit (more than "
                               f"{tol:.3g}{u}): named as the only mark near it; check its coordinates")
    return out
