"""The "prepare" stage: screening, optional scanned-film restitution, user masks, the folder of prepared images.

:func:`prepare_images_workspace` checks, runs and records the steps of :mod:`.folder`: the scanned-film
restitution (:mod:`core.prepare.scans`), the user's "ignore" polygons and the sky rasterised into the per-image
masks (:mod:`core.prepare.masks`, :mod:`core.prepare.sky`), the screening (:mod:`core.prepare.screening`) and
the folder of prepared images that "Align images" takes.
"""
from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from ..common.files import atomic_output, atomic_write_text, read_json_record
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.images import list_images
from ..project.layout import SCREENING_JSON, Layout
from ..project.stages import PREPARE, run_stage
from ..project.workspace import Workspace, WorkspaceError
from . import folder
from .options import PrepareOptions
from .screening import ImageQuality, ScreeningError

__all__ = ["PrepareResult", "STAGE", "load_screening", "prepare_images_workspace"]

STAGE = PREPARE


@dataclass
class PrepareResult:
    workspace: str
    prepared_dir: str
    screening_path: str
    images: List[ImageQuality]
    flagged: int
    excluded: int
    kept: int
    scans_path: Optional[str]
    masks: List[str]
    interior_orientation: Optional[dict]
    warnings: List[str]
    timings: Dict[str, float]
    user_masked: Dict[str, int] = field(default_factory=dict)  # image -> user polygons applied


def _json(obj) -> str:
    return json.dumps(obj, indent=2, default=str)


def prepare_images_workspace(images_dir: str, workspace_dir: str, options: Optional[PrepareOptions] = None,
                             progress: Optional[Progress] = None) -> PrepareResult:
    """The "prepare" stage: screening, optional scanned-film restitution, the folder of prepared images.

    Writes ``options.output_dir`` (default ``<workspace>/prepared``; replaced as a whole and renamed into place
    only when complete), ``<workspace>/screening.json``, for scanned film ``<workspace>/scans.json`` and
    ``<workspace>/masks/<prepared image name>.png`` (COLMAP's convention: white = use, black = ignore), and the
    stage record.  Raises ImageError (naming the file), ScreeningError, core.prepare.scans.ScanError,
    WorkspaceError or Cancelled.  A file that cannot be used (empty, not an image, truncated) is skipped with a
    warning naming it and why (in ``warnings`` and the stage's ``skipped_files``), as 'Align images' skips it;
    fewer than 2 usable images is a ScreeningError.  A scan whose fiducial marks cannot give its restitution is
    left out the same way (a warning naming it and why, the stage's ``left_out_scans``).
    """
    options = options or PrepareOptions()
    progress = progress or NullProgress()
    t_start = time.time()
    images_dir = os.path.abspath(images_dir)
    if not list_images(images_dir):  # ImageError when the folder is missing
        raise ScreeningError(f"no images (.jpg, .tif, .png) in {images_dir}")
    ws = Workspace.create_or_open(workspace_dir)
    lay = Layout(ws)
    output_dir = os.path.abspath(options.output_dir or lay.prepared_dir)
    folder.check_output_dir(output_dir, images_dir, ws.root)
    t0 = time.time()
    names, sizes, skipped = folder.check_images(images_dir, progress)
    warnings: List[str] = list(skipped)
    check_seconds = time.time() - t0
    params = folder.parameters(options, output_dir)
    staging = lay.path(folder.MASKS_STAGING)
    try:
        with run_stage(ws, STAGE, params, {"images": folder.fingerprint_files(images_dir, names)}) as run:
            place = folder.MaskPlace(lay, list((run.record.get("outputs") or {}).get("masks") or []), staging)
            with atomic_output(output_dir) as tmp:
                os.makedirs(tmp)
                shutil.rmtree(staging, ignore_errors=True)
                found = folder.screen_images(folder.Screened(images_dir, list(names), sizes, {}), tmp, place,
                                             options, progress, run.step, warnings)
                sc, quality = found.images, found.quality
                check_cancel(progress)
                folder.fill_prepared(tmp, images_dir, quality, options.scanned_film)
                check_cancel(progress)
                progress.report(0.96, "writing the screening record")
                # last step inside the atomic block: nothing below can be cancelled
                written_masks = folder.place_masks(lay, place.previous, quality, sc.mask_files)
                shutil.rmtree(staging, ignore_errors=True)
                summary = folder.screening_summary(quality)
                atomic_write_text(lay.screening_json, _json(folder.screening_doc(images_dir, output_dir, options,
                                                                                 quality, summary)))
                if sc.scan_set is not None:
                    atomic_write_text(lay.scans_json, _json(sc.scan_set.to_dict()))
            scans_path = lay.scans_json if sc.scan_set is not None else None
            outputs = {"prepared_images": output_dir, "screening": lay.rel(lay.screening_json),
                       "masks": written_masks, **({"scans": os.path.basename(scans_path)} if scans_path else {})}
            io = sc.scan_set.interior_orientation if sc.scan_set is not None else None
            run.finish(outputs=outputs, results={
                "images": len(quality), "flagged": summary["flagged"], "excluded": summary["excluded"],
                "kept": summary["kept"], "median_blur_score": summary["median"]["blur_score"],
                "decisions": {q.name: {"decision": q.decision, "flags": q.flags} for q in quality},
                "interior_orientation": io, "masks": len(written_masks),
                "user_masked_images": {n: found.user_masked[n] for n in sorted(found.user_masked)},
                "skipped_files": list(skipped),
                **({"left_out_scans": dict(sc.scan_set.left_out)} if sc.scan_set is not None and sc.scan_set.left_out
                   else {}),
                **({"sky_masked_images": {n: found.sky_masked[n] for n in sorted(found.sky_masked)}}
                   if options.sky_masks else {}),
                "total_seconds": round(time.time() - t_start, 2)})
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    progress.report(1.0, f"screened {len(quality)} images: {summary['flagged']} flagged, "
                         f"{summary['excluded']} excluded")
    timings = {k: round(v, 3) for k, v in dict(check=check_seconds, **run.timings).items()}
    return PrepareResult(
        workspace=ws.root, prepared_dir=output_dir, screening_path=lay.screening_json, images=quality,
        flagged=summary["flagged"], excluded=summary["excluded"], kept=summary["kept"],
        scans_path=scans_path, masks=[ws.path(m) for m in written_masks], interior_orientation=io,
        warnings=warnings, timings=timings, user_masked=found.user_masked)


def load_screening(workspace_dir: str) -> Optional[dict]:
    """The screening record of a workspace (for the report), or None before 'Prepare images'."""
    return read_json_record(os.path.join(workspace_dir, SCREENING_JSON), WorkspaceError)
