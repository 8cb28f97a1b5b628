"""What the automatic control records and reports: ``georef/autocontrol.json``'s document (:func:`search_document`),
the control points it hands the adjustment (:func:`control_points`: the kept candidates and the user's check
points in the reference CRS), the hint when the reference is too coarse (:func:`coarse_hint`) and what the
adjustment made of the automatic GCPs (:func:`adjustment_outcome`)."""
from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ...geometry.crs import transform_points
from ...io.gcp import CHECK, CONTROL, GCPSet, GroundPoint
from ...project.layout import Layout, read_json
from .candidates import KEPT, Candidate, drop_counts
from .options import AutoControlOptions

FORMAT = "archaeoortho-autocontrol"


def search_document(opt: AutoControlOptions, crs: str, found) -> Dict[str, Any]:
    """georef/autocontrol.json of a search (``found``: search.CandidateSearch): the references, the candidates,
    role ``auto``, with why each dropped one was dropped, and the figures."""
    cands = found.candidates
    return {"format": FORMAT, "version": 1, "reference_ortho": os.path.abspath(opt.reference_ortho),
            "reference_dsm": os.path.abspath(opt.reference_dsm), "crs": crs, "prior": opt.prior, "gsd": found.gsd,
            "figures": found.figures, "dropped": drop_counts(cands), "messages": found.messages,
            "candidates": [c.to_dict() for c in cands]}


def control_points(kept: Sequence[Candidate], check_points: Optional[GCPSet], crs: str, source: str) -> GCPSet:
    """The kept candidates as control points, with the user's check points (role check) in the reference CRS."""
    gcps = GCPSet(crs, [GroundPoint(c.name, c.x, c.y, c.z, c.sigma_xy, c.sigma_z, CONTROL, list(c.observations))
                        for c in kept], source=source)
    gcps.points.extend(_checks_in(check_points, crs))
    return gcps


def _checks_in(check_points: Optional[GCPSet], crs: str) -> List[GroundPoint]:
    """The check points as role check, taken from their set's CRS into the reference's ``crs`` (a national one
    without an EPSG code: the user's points are usually in another)."""
    pts = list(check_points.points) if check_points is not None else []
    if not pts:
        return []
    xyz = np.array([[p.x, p.y, p.z] for p in pts], dtype=float)
    if check_points.crs and check_points.crs != crs:
        xyz = transform_points(xyz, check_points.crs, crs)
    return [GroundPoint(p.name, float(a[0]), float(a[1]), float(a[2]), p.sigma_xy, p.sigma_z, CHECK,
                        list(p.observations)) for p, a in zip(pts, xyz)]


def coarse_hint(figures: Dict, match_gsd: float, opt: AutoControlOptions) -> str:
    """': the reference is too coarse for a block this small ...' when the block spans fewer reference pixels
    than one matching tile (the per-tile affine, the spread of the candidates: the block is a handful of the
    reference's features), else ''."""
    px = float(figures.get("block_reference_pixels") or 0.0)
    if not 0.0 < px < opt.tile_px:
        return ""
    return (f": the reference is too coarse for a block this small (the block spans {px:.0f} of its pixels, the "
            f"match ran at {match_gsd:.3g} per pixel; a reference with cells {opt.tile_px / px:.1f} x finer, or a larger "
            "block, gives enough matches)")


def adjustment_outcome(lay: Layout, kept: Sequence[Candidate]) -> Tuple[int, List[tuple], str]:
    """(automatic GCPs the adjustment used, (name, metres off) of the suspects it dropped, the message saying so)."""
    names = {c.name for c in kept}
    n_used = _count_used(lay, names)
    suspects = _suspects_dropped(lay, names)
    msg = f"automatic control: {n_used} of {len(kept)} automatic GCPs kept by the adjustment"
    if suspects:
        msg += (f", {len(suspects)} suspect dropped (they disagree with the others through the block: "
                + ", ".join(f"{n} {r:.2f} m" for n, r in suspects[:6]) + (" ..." if len(suspects) > 6 else "") + ")")
    others = len(kept) - n_used - len(suspects)
    if others > 0:
        msg += f", {others} rejected as outliers by the adjustment"
    return n_used, suspects, msg


def _suspects_dropped(lay: Layout, names) -> List[tuple]:
    """(name, metres off) of the automatic GCPs the adjustment's consistency check dropped as suspect, worst first."""
    res = lay.residuals() or {}
    cc = (res.get("statistics") or {}).get("control_consistency") or {}
    rejected = {r.get("name") for r in res.get("points", []) if r.get("status") == "rejected"}
    off = cc.get("residuals_m") or {}
    return sorted(((n, float(off.get(n, float("nan")))) for n in cc.get("suspects") or []
                   if n in names and n in rejected), key=lambda t: -t[1])


def _count_used(lay: Layout, names) -> int:
    rows = (lay.residuals() or {}).get("points", [])
    return sum(1 for r in rows if r.get("name") in names and r.get("status") == "used")


__all__ = ["FORMAT", "adjustment_outcome", "coarse_hint", "control_points", "search_document"]


def kept_names(lay: Layout) -> set:
    """The names of the candidates the workspace's last automatic control kept as ground control
    (georef/autocontrol.json); empty where it never ran or the record cannot be read."""
    doc = read_json(lay.autocontrol_json)
    cands = doc.get("candidates") if isinstance(doc, dict) else None
    return {str(c.get("name")) for c in cands or [] if isinstance(c, dict) and c.get("status") == KEPT}
