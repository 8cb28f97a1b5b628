"""From orthophoto matches to GCP candidates with photo observations and reference heights.

A match joins a provisional-orthophoto pixel to a reference pixel.  The orthophoto pixel came from one photo at
a known pixel (``ProvisionalOrtho.best``, ``u``, ``v``): that is the point's first observation.  The point is then
looked for in the other photos that see it, around its projection through the model (the photo patch re-projected
through the plane facing the first photo, normalised cross-correlation: ``core.georef.guided.refine_by_matching``),
and triangulated in the model; points whose rays disagree are dropped.  Its X, Y come from the reference pixel,
its Z from the reference DSM where the DSM is locally a plane (a roof edge, a wall or a tree gives no trusted
height); its sigmas from the common resolution, the match's residual against its tile's affine, the DSM's slope
and its own accuracy.  Last, the candidates must agree with one similarity model -> world (RANSAC), which drops
a change between the epochs that the 2-D match let through (a new building: its roof has no height in the DSM).
"""
from __future__ import annotations

import itertools
import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ...common.progress import NullProgress, Progress, check_cancel
from ...geometry.similarity import Similarity, helmert_fit
from ...io.gcp import Observation
from ..guided import MatchSearch, PhotoPoint, refine_by_matching
from ..triangulate import triangulate_observations
from .options import AUTO
from .provisional import Frame, ProvisionalOrtho, project, read_photo, registered

KEPT = "kept"


@dataclass
class Candidate:
    """One automatic GCP candidate (world coordinates of the reference CRS)."""

    name: str
    x: float
    y: float
    z: float
    sigma_xy: float
    sigma_z: float
    observations: List[Observation] = field(default_factory=list)
    residual_px: float = 0.0  # off its tile's affine, common-grid pixels
    score: float = 1.0  # mean normalised cross-correlation of the observations found in the other photos
    model_xyz: Optional[np.ndarray] = None
    status: str = KEPT  # or why it was dropped
    sigma_z_terrain: float = 0.0  # the part of sigma_z from the DSM's slope and roughness there
    z_residual: Optional[float] = None  # reference height - the similarity model -> world of the others

    def to_dict(self) -> Dict:
        return {"name": self.name, "role": AUTO, "x": self.x, "y": self.y, "z": self.z, "sigma_xy": self.sigma_xy,
                "sigma_z": self.sigma_z, "sigma_z_terrain": self.sigma_z_terrain,
                "residual_px": self.residual_px, "score": self.score,
                "status": self.status, "observations": [{"image": o.image, "x": o.x, "y": o.y}
                                                        for o in self.observations]}


def terrain_sigma(slope: float, misfit: float, sigma_xy: float) -> float:
    """The part of a reference height's sigma the DSM shows around the point, never a rejection: the slope times
    the point's sigma XY and the local roughness (half the 3 x 3 samples' largest distance from their plane: a
    wall, a tree, a roof edge, houses within a 10-30 m cell), in quadrature.  A point on relief then weighs little
    in Z and still fixes X, Y (a 0.6 m limit on the roughness, before, dropped 72 of 76 points against a 24 m
    DEM, 39 of 99 against Toledo's DSM averaged to 10 m)."""
    return float(math.hypot(slope * sigma_xy, 0.5 * misfit))


def own_sigma_prior(dsm_cell: float, dsm_sigma: Optional[float] = None) -> float:
    """The DSM's own height noise before the candidates tell: ``dsm_sigma`` when given, else a third of its cell
    (the height is a plane through 3 x 3 samples; the whole cell held Toledo's FC300X block domed by 0.7 m against
    a 0.63 m DSM, a third: camera centres 1.41 -> 0.88 m)."""
    return float(dsm_sigma) if dsm_sigma is not None else dsm_cell / 3.0


def estimate_own_sigma(cands: Sequence[Candidate], floor: float, cap: float, min_points: int = 8
                       ) -> Optional[float]:
    """The DSM's own height noise from the candidates that agree with one similarity (their ``z_residual``):
    what is left of those misfits after a smooth surface (a tilt and a bowl: the block's own deformation, which
    the heights are there to remove, not the DSM's noise) is taken out, weighted by 1 / (terrain sigma^2 + s^2);
    s is where the residuals over hypot(terrain sigma, s) have the median of a chi-square of 1 degree (0.455), a
    robust variance component, bounded to [``floor``, ``cap``]; None with fewer than ``min_points``.

    ``cap`` is the prior (a third of the DSM's cell): the data may only make the heights tighter; ``floor`` (the
    photos' ground resolution: the block's own precision) keeps a few heights from pinning the block.  Toledo's DSM averaged to 10 m: the prior, 3.3 m,
    let the FC300X block tilt (camera centres 1.7 m median off); its heights agree to about 0.5 m."""
    rows = [(c.x, c.y, c.z_residual, c.sigma_z_terrain) for c in cands
            if c.status == KEPT and c.z_residual is not None and math.isfinite(c.z_residual)]
    if len(rows) < min_points or not cap > 0:
        return None
    a = np.array(rows, dtype=float)
    x, y = a[:, 0] - a[:, 0].mean(), a[:, 1] - a[:, 1].mean()
    span = max(float(np.max(np.hypot(x, y))), 1e-9)
    design = np.column_stack([np.ones(len(a)), x / span, y / span, (x * x + y * y) / span ** 2])
    dz, t2 = a[:, 2], a[:, 3] ** 2
    dof = len(a) / max(len(a) - design.shape[1], 1)
    floor = min(floor, cap)
    s = cap
    for _ in range(10):
        w = 1.0 / np.sqrt(t2 + s * s)
        coef, *_ = np.linalg.lstsq(design * w[:, None], dz * w, rcond=None)
        new = _chi2_scale((dz - design @ coef) ** 2 * dof, t2, floor, cap)
        if abs(new - s) <= 1e-3 * cap:
            return new
        s = new
    return s


def _chi2_scale(r2: np.ndarray, t2: np.ndarray, floor: float, cap: float) -> float:
    """The s in [floor, cap] at which median(r2 / (t2 + s^2)) is 0.455 (the median of a chi-square of 1)."""

    def median_chi2(v: float) -> float:
        return float(np.median(r2 / np.maximum(t2 + v * v, 1e-300)))

    if median_chi2(cap) >= 0.455:
        return cap
    if median_chi2(floor) <= 0.455:
        return floor
    lo, hi = floor, cap
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if median_chi2(mid) > 0.455 else (lo, mid)
    return 0.5 * (lo + hi)


def set_own_sigma(cands: Sequence[Candidate], own: float) -> None:
    """Every candidate's sigma Z from its terrain part and the DSM's own noise ``own``."""
    for c in cands:
        if math.isfinite(c.sigma_z):
            c.sigma_z = float(math.hypot(c.sigma_z_terrain, own))


def spread(src: np.ndarray, residual: np.ndarray, n: int, shape) -> np.ndarray:
    """Indices of at most ``n`` matches spread over the image: the smallest residual per cell of a grid."""
    if len(src) <= n:
        return np.arange(len(src))
    h, w = shape
    k = max(1, int(math.ceil(math.sqrt(n * w / max(h, 1)))))
    cell = max(w / k, 1.0)
    key = (src[:, 1] // cell).astype(int) * (k + 1) + (src[:, 0] // cell).astype(int)
    order = np.lexsort((residual, key))
    first = order[np.r_[True, key[order][1:] != key[order][:-1]]]
    if len(first) > n:
        first = first[np.argsort(residual[first])[:n]]
    return np.sort(first)


class _Photos:
    """The block's photos as grey arrays, read when first needed."""

    def __init__(self, paths: Mapping[str, str]):
        self.paths = paths
        self._cache: Dict[str, np.ndarray] = {}

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            self._cache[name] = read_photo(self.paths[name])
        return self._cache[name]


@dataclass
class TiePoints:
    """Matches to tie back to the photos: ``src`` (N, 2) provisional orthophoto pixels, ``world_xy`` (N, 2) their
    places in the reference CRS, ``residual`` (N,) their fit to the tiles' affines (common-grid pixels)."""

    src: np.ndarray
    world_xy: np.ndarray
    residual: np.ndarray


def tie_back(rec, frame: Frame, prov: ProvisionalOrtho, ties: TiePoints, reference, photos: Mapping[str, str], opt,
             progress: Optional[Progress] = None) -> List[Candidate]:
    """Candidates of the matches ``ties.src`` (orthophoto pixels) -> ``ties.world_xy`` (reference CRS); every one
    is returned, those dropped with ``status`` saying why."""
    src, world_xy, residual = ties.src, ties.world_xy, ties.residual
    progress = progress or NullProgress()
    g = prov.res
    to_model = frame.model_to_frame.inverse()
    # the patches are re-projected through the ground's plane (the frame's up in the model), not the one facing
    # the first photo: the same for vertical photos, and what lets obliques seen from other sides match
    up = frame.model_to_frame.rotation.T @ np.array([0.0, 0.0, 1.0]) if opt.ground_plane else None
    lookup = {im.name: im for im in registered(rec)}
    grey = _Photos(photos)
    own = own_sigma_prior(reference.dsm_gsd, opt.dsm_sigma)
    z_ref, slope, misfit = reference.relief(world_xy[:, 0], world_xy[:, 1], max(2.0 * g, reference.dsm_gsd))
    out: List[Candidate] = []
    for i in range(len(src)):
        check_cancel(progress)
        progress.report(i / max(1, len(src)), f"automatic control: point {i + 1} of {len(src)} in the photos")
        sigma_xy = g * math.hypot(0.4, float(residual[i]))
        terrain = terrain_sigma(float(slope[i]), float(misfit[i]), sigma_xy)
        c = Candidate(f"auto_{i + 1:03d}", float(world_xy[i, 0]), float(world_xy[i, 1]), float(z_ref[i]), sigma_xy,
                      float(math.hypot(terrain, own)), residual_px=float(residual[i]), sigma_z_terrain=terrain)
        out.append(c)
        if not np.isfinite(z_ref[i]) or not np.isfinite(misfit[i]):
            c.status = "outside the reference DSM"
            continue
        col, row = float(src[i, 0]), float(src[i, 1])
        r, q = int(round(row)), int(round(col))
        k = int(prov.best[r, q]) if 0 <= r < prov.best.shape[0] and 0 <= q < prov.best.shape[1] else -1
        if k < 0:
            c.status = "outside the provisional orthophoto"
            continue
        x, y = prov.frame_xy(col, row)
        p_model = to_model.apply(np.array([[float(x), float(y), float(prov.surface.sample(x, y))]]))[0]
        _observe(rec, c, prov.names[k], p_model, lookup, grey, opt, up)
    return out


def _observe(rec, c: Candidate, first: str, p_model: np.ndarray, lookup, grey: _Photos, opt,
             up: Optional[np.ndarray] = None) -> None:
    """The candidate's observations: its pixel in the photo the orthophoto took it from, then the matches in
    the other photos; triangulated in the model (``c.model_xyz``) or dropped."""
    px, inside, _ = project(rec, lookup[first], p_model[None])
    if not inside[0]:
        c.status = "off its photo"
        return
    u0 = (float(px[0, 0]), float(px[0, 1]))
    obs = [Observation(first, u0[0], u0[1])]
    scores = []
    margin = opt.template_half + 2
    for name, im in lookup.items():
        if name == first or name not in grey.paths:
            continue
        pj, ok, _ = project(rec, im, p_model[None], margin=margin)
        if not ok[0]:
            continue
        m = refine_by_matching(rec, PhotoPoint(first, u0, grey[first]),
                               PhotoPoint(name, (float(pj[0, 0]), float(pj[0, 1])), grey[name]), p_model,
                               MatchSearch(opt.search_px, opt.template_half, opt.min_score), normal=up)
        if m is not None:
            obs.append(Observation(name, m.x, m.y))
            scores.append(m.score)
    if len(obs) < 2:
        c.status = "found in no other photo"
        return
    t = triangulate_observations(rec, obs, max_error_px=opt.max_triangulation_px)
    if t.xyz is None:
        c.status = "not triangulated: " + "; ".join(t.notes)
        return
    keep = [o for k, o in enumerate(obs) if t.used[k]]
    if len(keep) < 2 or float(np.nanmax(t.residuals_px[t.used])) > opt.max_triangulation_px:
        c.status = "rays disagree"
        return
    c.observations = keep
    c.score = float(np.mean(scores)) if scores else 0.0
    c.model_xyz = np.asarray(t.xyz, dtype=float)


def consistent(cands: Sequence[Candidate], allowance: float, k: float = 3.0, max_iterations: int = 2000,
               seed: int = 0) -> Optional[Similarity]:
    """Drop the kept candidates that disagree with one similarity model -> world (MSAC over 3-point sets, a
    refit on the inliers); returns the similarity (None when fewer than 3 are kept).

    A candidate agrees when its horizontal and vertical misfits, each over its tolerance, lie within a circle:
    ``hypot(allowance, k sigma_xy)`` and ``hypot(allowance, k sigma_z)``, ``allowance`` being what the model may
    be off beyond the candidates' own sigmas (a deformed block, relief in the provisional orthophoto: a few
    cells of the match's grid).  A height from a coarse or rough DSM (sigma Z of metres) is thus judged by its
    own sigma, not by the reference orthophoto's cell size."""
    kept = [c for c in cands if c.status == KEPT]
    if len(kept) < 3:
        return None
    src = np.array([c.model_xyz for c in kept], dtype=float)
    dst = np.array([[c.x, c.y, c.z] for c in kept], dtype=float)
    dst = dst - dst.mean(axis=0)
    tol = np.array([[math.hypot(allowance, k * c.sigma_xy), math.hypot(allowance, k * c.sigma_z)] for c in kept])

    def misfit(tr: Similarity) -> np.ndarray:
        d = dst - tr.apply(src)
        return np.hypot(np.hypot(d[:, 0], d[:, 1]) / tol[:, 0], d[:, 2] / tol[:, 1])

    n = len(kept)
    if math.comb(n, 3) <= max_iterations:
        draws = itertools.combinations(range(n), 3)
    else:
        rng = np.random.default_rng(seed)
        draws = (tuple(rng.choice(n, 3, replace=False)) for _ in range(max_iterations))
    best: Optional[Tuple[float, np.ndarray]] = None
    for sel in draws:
        try:
            tr = helmert_fit(src[list(sel)], dst[list(sel)])
        except ValueError:  # collinear
            continue
        e = misfit(tr)
        score = float(np.minimum(e, 1.0).sum())
        if best is None or score < best[0]:
            best = (score, e <= 1.0)
    if best is None or best[1].sum() < 3:
        for c in kept:
            c.status = "no similarity model -> world fits 3 of them"
        return None
    inl = best[1]
    tr = Similarity()
    for _ in range(20):
        tr = helmert_fit(src[inl], dst[inl], 1.0 / tol[inl, 0] ** 2)
        new = misfit(tr) <= 1.0
        if new.sum() < 3 or np.array_equal(new, inl):
            break
        inl = new
    e = misfit(tr)
    d = dst - tr.apply(src)
    for c, ok, ei, di in zip(kept, e <= 1.0, e, d):
        c.z_residual = float(di[2])
        if not ok:
            c.status = (f"off the similarity of the others ({math.hypot(di[0], di[1]):.2f} m XY, {di[2]:+.2f} m Z: "
                        f"{ei:.1f} x its tolerance)")
    return tr


def reason(status: str) -> str:
    """The reason of a dropped candidate's status without its figures: 'DSM not a plane there (2.2 m off)' ->
    'DSM not a plane there', 'not triangulated: ...' -> 'not triangulated'."""
    return status.split(" (")[0].split(":")[0].strip()


def drop_counts(cands: Sequence[Candidate]) -> Dict[str, int]:
    """{reason: candidates dropped for it}, the most frequent first."""
    counts = Counter(reason(c.status) for c in cands if c.status != KEPT)
    return dict(counts.most_common())


__all__ = ["KEPT", "Candidate", "consistent", "drop_counts", "estimate_own_sigma", "own_sigma_prior", "reason",
           "set_own_sigma", "spread", "terrain_sigma", "tie_back", "TiePoints"]
