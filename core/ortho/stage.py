"""The orthophoto stage of a workspace: reads the georeferenced model and the DSM through the layout, runs the
mosaic inside run_stage() and records its outputs."""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..align.photos import check_photos
from ..common.files import clean_debris, file_fingerprint, fingerprint
from ..common.progress import NullProgress, Progress
from ..io.images import ImageError
from ..project.layout import Layout, LayoutError, write_json
from ..project.stages import ORTHOPHOTO, run_stage
from ..project.workspace import Workspace
from .cameras import OrthoCamera, cameras_from_reconstruction, select_cameras
from .mosaic import WORK_PREFIX, build_orthomosaic
from .options import OrthoError, OrthoOptions
from .radiometry import seam_figures
from .radiometry_record import radiometry_record
from .seamlines import dsm_extent, edits_fingerprint, read_seamline_edits

STAGE = ORTHOPHOTO
# options left out of the stage's recorded parameters: how it runs (not what it makes), and the paths the
# parameters record under their own names
_NOT_RECORDED = ("workers", "scheduler", "cache_mb", "dsm_path", "images_filter", "output", "per_image_folder",
                 "seamlines")


@dataclass
class OrthoStageResult:
    workspace: str
    orthomosaic: str
    crs: Optional[str]
    resolution: float
    images: List[str]
    valid_fraction: float
    per_image_folder: Optional[str]
    seamlines: Optional[str]
    timings: Dict[str, float]
    warnings: List[str]
    log_lines: List[str]
    radiometry: Dict[str, Any] = field(default_factory=dict)  # the radiometric correction's figures (if applied)


def workspace_dsm(ws: Workspace) -> Optional[str]:
    """The workspace's DSM: the DSM stage's output if recorded, else <workspace>/dsm.tif; None if absent."""
    return Layout(ws).dsm()


def build_orthophoto_workspace(workspace_dir: str, options: Optional[OrthoOptions] = None,
                               progress: Optional[Progress] = None) -> OrthoStageResult:
    """The orthophoto stage of a georeferenced workspace: orthomosaic (default <workspace>/orthomosaic.tif),
    optional per-image true orthophotos and the which-image layer, as the options say (they are the settings:
    the DSM, the images filter and the outputs included).  Records the stage in workspace.json.

    ``options`` is not modified (the paths resolved go into a copy).
    Raises OrthoError (bad input), WorkspaceError, Cancelled."""
    progress = progress or NullProgress()
    lay = Layout(Workspace.open(workspace_dir))
    options, crs, offset, cams = _inputs(lay, options or OrthoOptions())
    for note in _check_photos(lay.ws, cams):
        progress.info(note)
    params = {"dsm": options.dsm_path, "images_filter": options.images_filter or "", "resolution": options.resolution,
              "blending": options.blending, "output": options.output, "per_image_folder": options.per_image_folder,
              "seamlines": options.seamlines, "options": {k: v for k, v in asdict(options).items()
                                                          if k not in _NOT_RECORDED}}
    inputs = {"dsm": file_fingerprint(options.dsm_path), "images": fingerprint(sorted(c.name for c in cams)),
              **lay.model_fingerprints()}
    if options.seamlines_in:  # edited seamlines (SEAMLINES_IN): a changed file re-runs the stage
        inputs["seamlines_in"] = edits_fingerprint(options.seamlines_in)
    with run_stage(lay.ws, STAGE, params, inputs) as run:
        if options.seamlines_in:  # before any work: a polygon naming an image the filter leaves out is named so
            read_seamline_edits(options.seamlines_in, [c.name for c in cams], crs, left_out=_left_out(lay, cams),
                                images_filter=options.images_filter, extent=dsm_extent(options.dsm_path, crs))
        for debris in clean_debris(os.path.dirname(options.output), WORK_PREFIX):
            progress.info(f"removed {debris}, left by a killed run")
        result = build_orthomosaic(cams, crs, offset, options, progress)
        for k_, v in result.timings.items():
            if k_ != "total":
                lay.ws.record_timing(STAGE, k_, v)
        write_json(lay.ortho_radiometry_json, radiometry_record(result.images, result.gains, result.radiometry_model))
        outputs = {key: lay.rel(path) for key, path in (("orthomosaic", options.output), ("per_image_folder",
                   options.per_image_folder), ("seamlines", options.seamlines)) if path}
        run.finish(outputs=outputs, results={
            "resolution": result.resolution, "gsd": result.gsd, "width": result.width, "height": result.height,
            "images": len(result.images), "valid_fraction": result.valid_fraction, "warnings": result.warnings,
            **seam_figures(result.radiometry),
            **({"drone_shadow": result.radiometry["shadow"]} if "shadow" in (result.radiometry or {}) else {})})
    return OrthoStageResult(lay.root, options.output, crs, result.resolution, result.images, result.valid_fraction,
                            options.per_image_folder, options.seamlines, result.timings, result.warnings,
                            result.log_lines, result.radiometry)


def _left_out(lay: Layout, cams: List[OrthoCamera]) -> List[str]:
    """The oriented images of the model that IMAGES_FILTER left out of the mosaic."""
    chosen = {c.name for c in cams}
    rec, _ = lay.load_georef_model()
    return sorted(rec.image(i).name for i in rec.reg_image_ids() if rec.image(i).name not in chosen)


def _check_photos(ws: Workspace, cams: List[OrthoCamera]) -> List[str]:
    """The photos of the mosaic against the alignment's (core.align.photos); OrthoError naming the missing,
    unreadable or changed ones, notes for the log of an older workspace."""
    try:
        return check_photos(ws, {c.name: c.path for c in cams})
    except ImageError as e:
        raise OrthoError(str(e)) from e


def _inputs(lay: Layout, options: OrthoOptions
            ) -> Tuple[OrthoOptions, Optional[str], np.ndarray, List[OrthoCamera]]:
    """(the options with the DSM and output paths resolved and absolute, CRS, local frame offset, the chosen
    cameras) of a georeferenced workspace; OrthoError if unusable."""
    ws = lay.ws
    try:
        lay.require_georeferenced("an orthophoto needs the images in a map CRS")
    except LayoutError as e:
        raise OrthoError(str(e)) from e
    dsm_path = os.path.abspath(options.dsm_path) if options.dsm_path else lay.dsm()
    if not dsm_path:
        raise OrthoError(f"workspace {ws.root} has no DSM: run 'Build DSM' first or give a DSM raster")
    if not os.path.isfile(dsm_path):
        raise OrthoError(f"DSM {dsm_path} does not exist")
    rec, frame = lay.load_georef_model()
    cams = cameras_from_reconstruction(rec, ws.data.get("images_dir") or "", lay.masks_dir)
    if not cams:
        raise OrthoError(f"the model of {ws.root} has no oriented image")
    cams = select_cameras(cams, options.images_filter, ws.data.get("camera_groups", []))
    options = replace(options, dsm_path=dsm_path, output=_absolute(options.output) or lay.default_orthomosaic,
                      per_image_folder=_absolute(options.per_image_folder), seamlines=_absolute(options.seamlines))
    return options, frame.crs or ws.crs, frame.offset, cams


def _absolute(path: Optional[str]) -> Optional[str]:
    return os.path.abspath(path) if path else None
