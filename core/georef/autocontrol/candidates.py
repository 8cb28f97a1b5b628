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

import math
from dataclasses import dataclass, field
from typing import Dict, List, Mapping, Optional, Sequence

import numpy as np

from ...common.progress import NullProgress, Progress, check_cancel
from ...geometry.similarity import helmert_ransac
from ...io.gcp import Observation
from ..guided import refine_by_matching
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

    def to_dict(self) -> Dict:
        return {"name": self.name, "role": AUTO, "x": self.x, "y": self.y, "z": self.z, "sigma_xy": self.sigma_xy,
                "sigma_z": self.sigma_z, "residual_px": self.residual_px, "score": self.score,
                "status": self.status, "observations": [{"image": o.image, "x": o.x, "y": o.y}
                                                        for o in self.observations]}


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


def tie_back(rec, frame: Frame, prov: ProvisionalOrtho, src: np.ndarray, world_xy: np.ndarray,
             residual: np.ndarray, reference, photos: Mapping[str, str], opt, progress: Optional[Progress] = None
             ) -> List[Candidate]:
    """Candidates of the matches ``src`` (orthophoto pixels) -> ``world_xy`` (reference CRS); every one is
    returned, those dropped with ``status`` saying why."""
    progress = progress or NullProgress()
    g = prov.res
    to_model = frame.model_to_frame.inverse()
    # the patches are re-projected through the ground's plane (the frame's up in the model), not the one facing
    # the first photo: the same for vertical photos, and what lets obliques seen from other sides match
    up = frame.model_to_frame.rotation.T @ np.array([0.0, 0.0, 1.0]) if opt.ground_plane else None
    lookup = {im.name: im for im in registered(rec)}
    grey = _Photos(photos)
    # the DSM's own height noise: the height is a plane through 3 x 3 samples, a third of one sample's, taken as
    # the cell size (the whole cell size held Toledo's FC300X block domed by 0.7 m against the DSM, its camera
    # centres 1.41 m median off; a third: 0.88 m)
    dsm_sigma = opt.dsm_sigma if opt.dsm_sigma is not None else reference.dsm_gsd / 3.0
    z_ref, slope, misfit = reference.relief(world_xy[:, 0], world_xy[:, 1], max(2.0 * g, reference.dsm_gsd))
    out: List[Candidate] = []
    for i in range(len(src)):
        check_cancel(progress)
        progress.report(i / max(1, len(src)), f"automatic control: point {i + 1} of {len(src)} in the photos")
        sigma_xy = g * math.hypot(0.4, float(residual[i]))
        c = Candidate(f"auto_{i + 1:03d}", float(world_xy[i, 0]), float(world_xy[i, 1]), float(z_ref[i]), sigma_xy,
                      float(math.hypot(dsm_sigma, slope[i] * sigma_xy) + 0.5 * min(misfit[i], 1e3)),
                      residual_px=float(residual[i]))
        out.append(c)
        if not np.isfinite(z_ref[i]):
            c.status = "outside the reference DSM"
            continue
        if misfit[i] > opt.max_relief:
            c.status = f"DSM not a plane there ({misfit[i]:.2f} m off)"
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
        m = refine_by_matching(rec, first, u0, grey[first], name, (float(pj[0, 0]), float(pj[0, 1])), grey[name],
                               p_model, radius=opt.search_px, half=opt.template_half, min_score=opt.min_score,
                               normal=up)
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


def consistent(cands: Sequence[Candidate], threshold: float) -> Optional[object]:
    """Drop the kept candidates that disagree with one similarity model -> world (RANSAC, ``threshold``
    metres); returns the similarity (None when fewer than 3 are kept)."""
    kept = [c for c in cands if c.status == KEPT]
    if len(kept) < 3:
        return None
    src = np.array([c.model_xyz for c in kept])
    dst = np.array([[c.x, c.y, c.z] for c in kept])
    off = dst.mean(axis=0)
    fit = helmert_ransac(src, dst - off, threshold)
    for c, ok, r in zip(kept, fit.inliers, fit.residuals):
        if not ok:
            c.status = f"off the similarity of the others ({r:.2f} m)"
    return fit


__all__ = ["KEPT", "Candidate", "consistent", "spread", "tie_back"]
