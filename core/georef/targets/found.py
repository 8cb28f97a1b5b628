"""The observations of the named targets (steps 4 and 5 of Find targets): every named target projected into every
photo through the block, the free mark at its projection joining it (:func:`predict`), then each target
re-triangulated from its marks, the marks off the others or (with TARGET_SIZE) of another size on the ground
dropped (:func:`observations`)."""
from __future__ import annotations

import math
from typing import Dict, List, Optional, Sequence

import numpy as np

from ...io import gcp as gcpmod
from ..errors import GeorefError
from ..guided import Predictor
from ..triangulate import triangulate_observations
from .constellation import Constellation
from .detect import Candidate
from .results import PROJECTED, FoundObservation, TargetStatus


def predict(rec, gs: gcpmod.GCPSet, named: Dict[str, List[Candidate]], cands: Dict[str, List[Candidate]],
             kinds: Dict[str, str], tol_px: float, reports: List[str]) -> Dict[str, List[Candidate]]:
    """Every target projected into every photo; the free candidate at the projection joins its target."""
    seed = gcpmod.GCPSet(gs.crs, [gcpmod.GroundPoint(p.name, p.x, p.y, p.z, sigma_given=False,
                                                     observations=[gcpmod.Observation(c.image, c.x, c.y)
                                                                   for c in named.get(p.name, [])])
                                  for p in gs.points])
    if sum(1 for p in seed.points if len(p.observations) >= 2) < 3:
        return named
    try:
        pred = Predictor(rec, max_ray_error_px=tol_px).predict(seed)
    except GeorefError as e:
        reports.append(f"no projection of the targets into the photos: {e}")
        return named
    taken = {(c.image, round(c.x, 3), round(c.y, 3)) for v in named.values() for c in v}
    out = {k: list(v) for k, v in named.items()}
    for name, per_image in pred.items():
        have = {c.image for c in out.get(name, [])}
        for image, p in per_image.items():
            if image in have:
                continue
            free = [c for c in cands.get(image, []) if (c.image, round(c.x, 3), round(c.y, 3)) not in taken
                    and (name not in kinds or c.kind == kinds[name])]
            if not free:
                continue
            d = np.array([math.hypot(c.x - p.x, c.y - p.y) for c in free])
            k = int(np.argmin(d))
            radius = max(2.0 * tol_px, 0.3 * free[k].size_px)
            if d[k] > radius or np.sum(d < 2.0 * radius) > 1:
                continue  # nothing there, or two marks close to the projection: left out, not guessed
            out.setdefault(name, []).append(free[k])
            taken.add((image, round(free[k].x, 3), round(free[k].y, 3)))
    _loose(pred, out, cands, kinds, taken, reports)
    return out


def _loose(pred, out: Dict[str, List[Candidate]], cands: Dict[str, List[Candidate]], kinds: Dict[str, str],
           taken: set, reports: List[str]) -> None:
    """A target not tied in two photos has only the similarity's projection, off by the survey's misfit: in each
    photo, the free mark and the projection that are each other's nearest (among the free marks and all the
    targets' projections there) join, if nearer than half the distance to the next target's projection."""
    for name, per_image in pred.items():
        if len(out.get(name, [])) >= 2:
            continue  # projected through its own rays: the tight search above decides
        for image, p in per_image.items():
            if any(c.image == image for c in out.get(name, [])):
                continue
            others = [q for n, v in pred.items() if n != name and image in v for q in [v[image]]]
            free = [c for c in cands.get(image, []) if (c.image, round(c.x, 3), round(c.y, 3)) not in taken
                    and (name not in kinds or c.kind == kinds[name])]
            if not others or not free:
                continue
            spacing = min(math.hypot(q.x - p.x, q.y - p.y) for q in others)
            c = min(free, key=lambda c: math.hypot(c.x - p.x, c.y - p.y))
            d = math.hypot(c.x - p.x, c.y - p.y)
            if d < 0.5 * spacing and all(math.hypot(c.x - q.x, c.y - q.y) > d for q in others):
                out.setdefault(name, []).append(c)
                taken.add((image, round(c.x, 3), round(c.y, 3)))
                reports.append(f"target {name} in {image}: the only mark near its projection, {d:.0f} px from it "
                               f"(the survey and the block disagree there): check it")


def _depth_near(rec, im, c: Candidate) -> Optional[float]:
    """The depth in photo ``im`` of the ground under the mark ``c`` (seen in that photo only): the median depth of
    the tie points that project within three mark sizes of it, else of all the photo's tie points."""
    m = np.asarray(im.cam_from_world().matrix())
    pts = np.array([rec.points3D[p.point3D_id].xyz for p in im.points2D if p.has_point3D()], dtype=float)
    if not len(pts):
        return None
    xc = pts @ m[:, :3].T + m[:, 3]
    xc = xc[xc[:, 2] > 0]
    if not len(xc):
        return None
    cam = rec.cameras[im.camera_id]
    f = float(cam.mean_focal_length())
    cn = np.asarray(cam.cam_from_img(np.array([[c.x, c.y]])), dtype=float)[0, :2]
    near = np.linalg.norm(xc[:, :2] / xc[:, 2:3] - cn, axis=1) * f < 3.0 * max(c.size_px, 4.0)
    return float(np.median(xc[near, 2] if near.sum() >= 3 else xc[:, 2]))


def _ground_sizes(rec, cs: Sequence[Candidate], xyz, scale: Optional[float]) -> List[Optional[float]]:
    """Each mark's size on the ground: pixels x depth / focal length x the model's scale (to metres; None without
    one).  The depth is the target's triangulated point's, or for a mark seen in one photo the ground's there."""
    if scale is None or (xyz is None and len(cs) != 1):
        return [None] * len(cs)
    lookup = {rec.image(i).name: rec.image(i) for i in rec.reg_image_ids()}
    out: List[Optional[float]] = []
    for c in cs:
        im = lookup[c.image]
        m = np.asarray(im.cam_from_world().matrix())
        depth = float((m[:, :3] @ np.asarray(xyz) + m[:, 3])[2]) if xyz is not None else _depth_near(rec, im, c)
        out.append(None if depth is None
                   else c.size_px * depth / float(rec.cameras[im.camera_id].mean_focal_length()) * scale)
    return out


def observations(rec, gs, found: Dict[str, List[Candidate]], sources, tol_px: float, match: Constellation,
                 target_size: Optional[float], metres_per_unit: float = 1.0) -> tuple:
    """(FoundObservation list, TargetStatus list, the sizes of the marks left out for their size) of the targets
    ``gs``: each re-triangulated from its marks ``found``; ``sources``: {id(mark): how it was found} (projected
    where absent).  The marks' sizes on the ground are in metres (``metres_per_unit``: of the targets' CRS), as
    ``target_size`` is."""
    observations: List[FoundObservation] = []
    targets: List[TargetStatus] = []
    size_dropped: List[float] = []
    track_fit = {match.names[i]: match.residuals[i] for i in match.names}
    scale = match.similarity.scale * metres_per_unit if match.similarity is not None else None
    for p in gs.points:
        cs = found.get(p.name, [])
        notes = []
        res = np.full(len(cs), np.nan)
        xyz = None
        if len(cs) >= 2:
            t = triangulate_observations(rec, [gcpmod.Observation(c.image, c.x, c.y) for c in cs],
                                         max_error_px=tol_px)
            xyz = t.xyz
            if t.xyz is None:
                cs, res = [], np.zeros(0)
                notes.append("its marks do not intersect in the block")
            else:
                keep = [i for i in range(len(cs)) if t.used[i]]
                if len(cs) > len(keep):
                    notes.append(f"{len(cs) - len(keep)} mark(s) off the others by more than {tol_px:.2g} px left out")
                cs, res = [cs[i] for i in keep], t.residuals_px[keep]
        sizes = _ground_sizes(rec, cs, xyz, scale)
        if target_size:
            keep = [i for i, sz in enumerate(sizes) if sz is None or 0.5 <= sz / target_size <= 2.0]
            if len(keep) < len(cs):
                gone = [sizes[i] for i in range(len(cs)) if i not in keep]
                notes.append(f"{len(cs) - len(keep)} mark(s) of {float(np.median(gone)):.2g} m (median) on the "
                             f"ground, unlike the target's {target_size:g} m, left out")
                size_dropped += gone
            cs, res, sizes = [cs[i] for i in keep], res[keep], [sizes[i] for i in keep]
        for c, r, sz in zip(cs, res, sizes):
            observations.append(FoundObservation(p.name, c.image, c.x, c.y, c.kind, c.quality, float(r), c.size_px,
                                                 sources.get(id(c), PROJECTED), size_m=sz))
        targets.append(TargetStatus(p.name, p.x, p.y, p.z, bool(cs), len(cs), track_fit.get(p.name),
                                    "; ".join(notes) or ("" if cs else "not found")))
    return observations, targets, size_dropped


__all__ = ["observations", "predict"]
