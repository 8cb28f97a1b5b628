"""Automatic control of a workspace: ``autocontrol_workspace`` (what the Processing algorithm calls).

1. the prior: rough camera positions (EXIF GPS, or given) in the reference CRS give a similarity model -> world;
   with none, the block's level frame is matched to the whole reference over rotations (``coarse_search``), and
   that match gives the similarity;
2. the provisional orthophoto at the common resolution, matched to the reference (``matching.match_orthos``);
3. the matches tied back to the photos, with heights from the DSM (``candidates``), spread over the block;
4. ``georef/autocontrol.json`` (the candidates, role ``auto``, with why each dropped one was dropped, and the
   figures), then the usual georeferencing with the kept ones as control points (``auto_NNN``) and its outlier
   rejection (``core.georef.stage.georeference_workspace``: ``georef/control.json``, the residuals, the cameras).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence

import numpy as np

from ...common.files import remove_path
from ...common.progress import NullProgress, Progress, SubProgress
from ...geometry.crs import transform_points
from ...io.gcp import CHECK, CONTROL, CameraPosition, GCPSet, GroundPoint
from ...project.layout import Layout, write_json
from ...project.workspace import Workspace
from ..options import GeorefOptions
from ..stage import GeorefStageResult, georeference_workspace
from .candidates import (
    KEPT,
    Candidate,
    drop_counts,
)
from .errors import AutoControlError
from .options import PRIOR_AUTO, AutoControlOptions
from .reference import Reference
from .search import find_candidates

FORMAT = "archaeoortho-autocontrol"


@dataclass
class AutoControlResult:
    workspace: str
    crs: str
    prior: str
    gsd: float
    figures: Dict[str, float]
    candidates: List[Candidate]
    georef: Optional[GeorefStageResult]
    n_kept: int  # automatic GCPs the adjustment kept
    cameras_path: Optional[str]
    timings: Dict[str, float] = field(default_factory=dict)
    messages: List[str] = field(default_factory=list)


def autocontrol_workspace(workspace_dir: str, reference_ortho: str, reference_dsm: str, prior: str = PRIOR_AUTO,
                          camera_positions: Optional[Sequence[CameraPosition]] = None,
                          check_points: Optional[GCPSet] = None, options: Optional[AutoControlOptions] = None,
                          georef_options: Optional[GeorefOptions] = None,
                          progress: Optional[Progress] = None) -> AutoControlResult:
    """Georeference an aligned workspace with automatic control from a reference orthophoto and DSM.

    ``prior``: "auto" (EXIF GPS when 2 photos carry it, else none), "gps", or "none" (search rotation and scale);
    ``camera_positions``: rough positions in the reference's CRS instead of EXIF GPS; ``check_points``: ground
    points evaluated as check points (role check; taken from their set's CRS into the reference's); ``georef_options``: the adjustment's
    options (its ``refine_intrinsics`` replaces ``options.refine_intrinsics``).  Raises AutoControlError when fewer
    than ``options.min_candidates`` candidates are kept."""
    opt = AutoControlOptions.of(options)
    progress = progress or NullProgress()
    ws = Workspace.open(workspace_dir)
    ws.require_writable()  # before the matching: a read-only workspace failed after it
    lay = Layout(ws)
    if not lay.has_aligned_model():
        raise AutoControlError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = lay.load_aligned_model()
    reference = Reference(reference_ortho, reference_dsm)
    t0 = time.time()
    try:
        found = find_candidates(ws, rec, reference, prior, camera_positions, opt, SubProgress(progress, 0.0, 0.7))
    finally:
        reference.close()
    cands, figures, messages, g, timings = found.candidates, found.figures, found.messages, found.gsd, found.timings
    for m in messages:
        progress.info(m)
    kept = [c for c in cands if c.status == KEPT]
    crs = reference.crs
    doc = {"format": FORMAT, "version": 1, "reference_ortho": os.path.abspath(reference_ortho),
           "reference_dsm": os.path.abspath(reference_dsm), "crs": crs, "prior": prior, "gsd": g,
           "figures": figures, "dropped": drop_counts(cands), "messages": messages,
           "candidates": [c.to_dict() for c in cands]}
    os.makedirs(lay.georef_dir, exist_ok=True)
    # the candidates go to autocontrol-failed.json until the adjustment has succeeded: autocontrol.json stays the
    # record of the control in use (a failed run must not describe a block controlled by another)
    write_json(lay.autocontrol_failed_json, doc)
    if len(kept) < opt.min_candidates:
        raise AutoControlError(f"automatic control against {reference_ortho}: {len(kept)} candidate(s) kept, "
                               f"{opt.min_candidates} needed{_coarse_hint(figures, g, opt)} "
                               f"({'; '.join(messages)}); see {lay.autocontrol_failed_json}")
    gcps = GCPSet(crs, [GroundPoint(c.name, c.x, c.y, c.z, c.sigma_xy, c.sigma_z, CONTROL, list(c.observations))
                        for c in kept], source=lay.autocontrol_json)
    gcps.points.extend(_checks_in(check_points, crs))
    t1 = time.time()
    refine = georef_options.refine_intrinsics if georef_options is not None else opt.refine_intrinsics
    # suspect automatic GCPs (the adjustment's consistency check) are dropped, not only named (issue 36 item 18)
    res = georeference_workspace(ws.root, gcps=gcps, crs=crs,
                                 options=GeorefOptions.of(georef_options, drop_suspect_control=True),
                                 refine_intrinsics=refine, progress=SubProgress(progress, 0.7, 1.0))
    remove_path(lay.autocontrol_failed_json)
    timings["adjustment"] = time.time() - t1
    timings["total"] = time.time() - t0
    n_used = _count_used(lay, {c.name for c in kept})
    suspects = _suspects_dropped(lay, {c.name for c in kept})
    figures["kept"] = n_used
    figures["suspect_dropped"] = len(suspects)
    msg = f"automatic control: {n_used} of {len(kept)} automatic GCPs kept by the adjustment"
    if suspects:
        msg += (f", {len(suspects)} suspect dropped (they disagree with the others through the block: "
                + ", ".join(f"{n} {r:.2f} m" for n, r in suspects[:6]) + (" ..." if len(suspects) > 6 else "") + ")")
    others = len(kept) - n_used - len(suspects)
    if others > 0:
        msg += f", {others} rejected as outliers by the adjustment"
    progress.info(msg)
    messages.append(msg)
    doc.update(figures=figures, messages=messages, timings=timings)
    write_json(lay.autocontrol_json, doc)
    return AutoControlResult(ws.root, crs, prior, g, figures, cands, res, n_used, res.cameras_path, timings, messages)


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


def _coarse_hint(figures: Dict, g: float, opt: AutoControlOptions) -> str:
    """': the reference is too coarse for a block this small ...' when the block spans fewer reference pixels
    than one matching tile (the per-tile affine, the spread of the candidates: the block is a handful of the
    reference's features), else ''."""
    px = float(figures.get("block_reference_pixels") or 0.0)
    if not 0.0 < px < opt.tile_px:
        return ""
    return (f": the reference is too coarse for a block this small (the block spans {px:.0f} of its pixels, the "
            f"match ran at {g:.3g} per pixel; a reference with cells {opt.tile_px / px:.1f} x finer, or a larger "
            "block, gives enough matches)")


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


__all__ = ["AutoControlResult", "autocontrol_workspace"]
