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

import copy
import dataclasses
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from ...common.files import remove_path
from ...common.progress import NullProgress, Progress, SubProgress
from ...project.layout import Layout, write_json
from ...project.workspace import Workspace
from ..control_checks import read_checked_control
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
        opt = _with_given_control(ws, opt, reference.crs, progress)  # read and checked before the matching
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


def _with_given_control(ws: Workspace, opt: AutoControlOptions, crs: str, progress: Progress) -> AutoControlOptions:
    """``opt`` with the ground control given beside the reference (``opt.control``) read, in the reference's CRS
    ``crs``, by the georeference stage's reader and checks (``read_checked_control``: the same refusals and
    warnings as Georeference without a reference): its points as ``check_points``, its camera positions
    (a file) as ``camera_positions``."""
    given = opt.control
    if given is None:
        return opt
    if given.camera_positions_path and opt.camera_positions is not None:
        raise AutoControlError("automatic control: camera positions given twice (a file and a list): give one")
    if (given.gcp_path or given.gcps is not None) and opt.check_points is not None:
        raise AutoControlError("automatic control: ground control given twice (as control and as check points): "
                               "give one")
    has_points = bool(given.gcp_path) or (given.gcps is not None and bool(given.gcps.points))
    if not has_points and not given.camera_positions_path:
        return opt
    # the given set is the caller's (the dock's table): read into a copy, never moved into the reference's CRS
    read = dataclasses.replace(given, gcps=copy.deepcopy(given.gcps), crs=crs, use_exif_gps=False,
                               reference_dem=None)
    gcps, cams, _ = read_checked_control(ws, read, progress, required=False)
    for w in gcps.warnings if gcps is not None else []:
        progress.warning(w)
    return AutoControlOptions.of(opt, check_points=gcps if gcps is not None and gcps.points else opt.check_points,
                                 camera_positions=cams if given.camera_positions_path else opt.camera_positions)


__all__ = ["AutoControlResult", "autocontrol_workspace"]
