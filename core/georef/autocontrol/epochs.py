"""Multi-epoch registration (issue 16 item 2): photos of another year or season registered to an earlier,
georeferenced block by the automatic control, with no GCP.

The earlier block is a workspace: its orthomosaic and its DSM (where ``core.project.layout.Layout`` finds them)
are the reference of ``autocontrol_workspace``; ``georef/autocontrol.json`` of the new workspace then records
that workspace as ``reference_workspace`` beside the two rasters.  Both epochs' orthophotos can afterwards be
built on one DSM (Build orthophoto's external DSM: the earlier block's) and their DSMs differenced
(``core.terrain.difference.dsm_difference``).
"""
from __future__ import annotations

import os
from typing import Optional, Tuple

from ...common.progress import Progress
from ...project.layout import Layout, read_json, write_json
from ...project.workspace import Workspace, WorkspaceError
from .errors import AutoControlError
from .options import AutoControlOptions
from .stage import AutoControlResult, autocontrol_workspace


def reference_products(reference_workspace_dir: str) -> Tuple[str, str]:
    """(orthomosaic, DSM) of an earlier, georeferenced workspace; AutoControlError naming the workspace and the
    missing product (and the step that makes it) otherwise."""
    try:
        ws = Workspace.open(reference_workspace_dir)
    except WorkspaceError as e:
        raise AutoControlError(f"reference workspace: {e}") from e
    lay = Layout(ws)
    if not lay.is_georeferenced():
        raise AutoControlError(f"reference workspace {ws.root} is not georeferenced: run 'Georeference' on it first "
                               "(its orthomosaic and DSM must be in a map CRS)")
    dsm = lay.dsm()
    if dsm is None:
        raise AutoControlError(f"reference workspace {ws.root} has no DSM ({lay.default_dsm} is missing): run "
                               "'Build DSM' on it first")
    ortho = lay.orthomosaic()
    if ortho is None:
        raise AutoControlError(f"reference workspace {ws.root} has no orthomosaic ({lay.default_orthomosaic} is "
                               "missing): run 'Build orthophoto' on it first")
    return ortho, dsm


def register_epoch(workspace_dir: str, reference_workspace_dir: str, options: Optional[AutoControlOptions] = None,
                   progress: Optional[Progress] = None) -> AutoControlResult:
    """Georeference the aligned workspace ``workspace_dir`` (another epoch: a second block or single photos) on
    the orthomosaic and DSM of the earlier, georeferenced workspace ``reference_workspace_dir``, with no GCP.

    ``options``: as :func:`~core.georef.autocontrol.stage.autocontrol_workspace` (its references are the
    earlier workspace's orthomosaic and DSM).  Raises AutoControlError for a reference
    workspace without those products (named), the same workspace twice, or too few automatic GCPs."""
    ortho, dsm = reference_products(reference_workspace_dir)
    ref_root = os.path.abspath(reference_workspace_dir)
    if os.path.isdir(workspace_dir) and os.path.samefile(workspace_dir, ref_root):
        raise AutoControlError(f"workspace {ref_root} cannot be registered to itself: choose the earlier epoch's "
                               "workspace as the reference")
    lay = Layout(Workspace.open(workspace_dir))
    try:
        return autocontrol_workspace(workspace_dir, AutoControlOptions.of(options, reference_ortho=ortho,
                                                                          reference_dsm=dsm), progress)
    finally:  # also after a failure: autocontrol.json then tells which reference was tried
        doc = read_json(lay.autocontrol_json)
        if isinstance(doc, dict) and doc.get("reference_ortho") == os.path.abspath(ortho):
            doc["reference_workspace"] = ref_root
            write_json(lay.autocontrol_json, doc)


__all__ = ["reference_products", "register_epoch"]
