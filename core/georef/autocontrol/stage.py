"""Automatic control of a workspace: ``autocontrol_workspace(workspace, options, progress)`` (what the
Processing algorithm calls).

1. the prior: rough camera positions (EXIF GPS, or given) in the reference CRS give a similarity model -> world;
   with none, the block's level frame is matched to the whole reference over rotations (``coarse_search``), and
   that match gives the similarity;
2. the provisional orthophoto at the common resolution, matched to the reference (``matching.match_orthos``);
3. the matches tied back to the photos, with heights from the DSM (``candidates``), spread over the block
   (steps 1 to 3: ``search.find_candidates``);
4. ``georef/autocontrol.json`` (``record``: the candidates, role ``auto``, with why each dropped one was dropped,
   and the figures), then the usual georeferencing with the kept ones as control points (``auto_NNN``) and its
   outlier rejection (``core.georef.stage.georeference_workspace``: ``georef/control.json``, the residuals, the
   cameras).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from ...common.files import remove_path
from ...common.progress import NullProgress, Progress, SubProgress
from ...project.layout import Layout, write_json
from ...project.workspace import Workspace
from ..options import GeorefOptions
from ..stage import GeorefStageResult, georeference_workspace
from . import record
from .candidates import KEPT, Candidate
from .errors import AutoControlError
from .options import AutoControlOptions
from .reference import Reference
from .search import find_candidates

FORMAT = record.FORMAT


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


def autocontrol_workspace(workspace_dir: str, options: AutoControlOptions,
                          progress: Optional[Progress] = None) -> AutoControlResult:
    """Georeference an aligned workspace with automatic control from a reference orthophoto and DSM
    (``options.reference_ortho``, ``options.reference_dsm``; the prior, rough positions, check points and the
    adjustment's options: :class:`~core.georef.autocontrol.options.AutoControlOptions`).  Raises
    AutoControlError when fewer than ``options.min_candidates`` candidates are kept."""
    opt = AutoControlOptions.of(options)
    progress = progress or NullProgress()
    ws = Workspace.open(workspace_dir)
    ws.require_writable()  # before the matching: a read-only workspace failed after it
    lay = Layout(ws)
    if not lay.has_aligned_model():
        raise AutoControlError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = lay.load_aligned_model()
    reference = Reference(opt.reference_ortho, opt.reference_dsm)
    t0 = time.time()
    try:
        found = find_candidates(ws, rec, reference, opt, SubProgress(progress, 0.0, 0.7))
    finally:
        reference.close()
    figures, messages, timings = found.figures, found.messages, found.timings
    for m in messages:
        progress.info(m)
    kept = [c for c in found.candidates if c.status == KEPT]
    crs = reference.crs
    doc = record.search_document(opt, crs, found)
    os.makedirs(lay.georef_dir, exist_ok=True)
    # the candidates go to autocontrol-failed.json until the adjustment has succeeded: autocontrol.json stays the
    # record of the control in use (a failed run must not describe a block controlled by another)
    write_json(lay.autocontrol_failed_json, doc)
    if len(kept) < opt.min_candidates and found.not_shown:
        raise AutoControlError(f"automatic control: {found.not_shown} ({len(kept)} candidate(s) kept, "
                               f"{opt.min_candidates} needed; see {lay.autocontrol_failed_json})")
    if len(kept) < opt.min_candidates:
        raise AutoControlError(f"automatic control against {opt.reference_ortho}: {len(kept)} candidate(s) kept, "
                               f"{opt.min_candidates} needed{record.coarse_hint(figures, found.gsd, opt)} "
                               f"({'; '.join(messages)}); see {lay.autocontrol_failed_json}")
    gcps = record.control_points(kept, opt.check_points, crs, lay.autocontrol_json)
    t1 = time.time()
    refine = opt.georef.refine_intrinsics if opt.georef is not None else opt.refine_intrinsics
    # suspect automatic GCPs (the adjustment's consistency check) are dropped, not only named (issue 36 item 18)
    res = georeference_workspace(ws.root, GeorefOptions.of(opt.georef, drop_suspect_control=True, gcps=gcps,
                                                           crs=crs, refine_intrinsics=refine),
                                 SubProgress(progress, 0.7, 1.0))
    remove_path(lay.autocontrol_failed_json)
    timings["adjustment"] = time.time() - t1
    timings["total"] = time.time() - t0
    n_used, suspects, msg = record.adjustment_outcome(lay, kept)
    figures["kept"] = n_used
    figures["suspect_dropped"] = len(suspects)
    progress.info(msg)
    messages.append(msg)
    doc.update(figures=figures, messages=messages, timings=timings)
    write_json(lay.autocontrol_json, doc)
    return AutoControlResult(ws.root, crs, opt.prior, found.gsd, figures, found.candidates, res, n_used,
                             res.cameras_path, timings, messages)


__all__ = ["AutoControlResult", "autocontrol_workspace"]
