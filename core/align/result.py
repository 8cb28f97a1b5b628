"""What the alignment stage leaves: the model written atomically, the camera positions, ``sfm/alignment.json``
(the figures, the images not registered and why, the escalation and the first pass) and the stage's record."""
from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional, Tuple

from ..common.files import atomic_output, atomic_write_text
from ..io.vector import write_cameras_gpkg
from ..project.layout import Layout
from ..project.workspace import Workspace
from .calibrated import intrinsics_record
from .escalation import Escalation
from .firstpass import FirstPass
from .inputs import Photos
from .mapping import camera_rows, camera_summary
from .record import commit


@dataclass
class AlignResult:
    workspace: str
    model_dir: str
    cameras_path: str
    images_given: int
    registered: int
    mean_reprojection_error: float
    num_points3d: int
    unregistered: Dict[str, str]  # image -> why
    other_components: List[List[str]]
    skipped_files: List[str]
    pairing_used: str
    num_pairs: int
    timings: Dict[str, float]
    cameras: List[dict]
    masked_images: int = 0
    escalation: Optional[dict] = None  # what was escalated and why (core.align.escalation), None when not needed
    intrinsics: Optional[List[dict]] = None  # per camera: mode, given values and sigmas, final values (calibrated)
    first_pass: Optional[dict] = None  # the first pass's feature settings, why, and the texture probe's figures
    # the focal length held at the photos' own because self-calibrated it drifted (core.align.mapping.map_block)
    focal_held: Optional[dict] = None


def _json(obj) -> str:
    return json.dumps(obj, indent=2, default=str)


@dataclass
class Outcome:
    """What the reconstruction gave: the main block, the images left out (why) and in other components, the pairs
    matched, the masked images, the escalation (None when not needed), the first pass's features, whether the
    final adjustment refined the principal point, and the database."""

    rec: object
    unregistered: Dict[str, str]
    others: List[List[str]]
    pairs: List[Tuple[str, str]]
    pairing_used: str
    masked: List[str]
    escalation: Optional[Escalation]
    first: FirstPass
    principal_point_refined: bool
    db_path: str  # the database the run worked in (the workspace's or a staged one)
    focal_held: Optional[dict] = None  # MappingJob.focal_held


def write_products(pycolmap, ws: Workspace, lay: Layout, run, photos: Photos, outcome: Outcome,
                   t_start: float) -> AlignResult:
    """Write the model atomically, make the new image list and database the workspace's (``run``: the stage's
    run_stage record), write the camera positions and ``sfm/alignment.json``, and finish the stage's record."""
    rec, infos = outcome.rec, photos.infos
    with atomic_output(lay.aligned_model_dir) as tmp:
        os.makedirs(tmp)
        rec.write_binary(tmp)
    commit(ws, lay, run.record, photos, outcome.db_path)
    cameras_path = write_cameras_gpkg(ws.root, camera_rows(rec), crs=None)
    mre = float(rec.compute_mean_reprojection_error())
    timings = dict(images=photos.seconds, **run.timings)
    escalation = outcome.escalation
    result = AlignResult(
        workspace=ws.root, model_dir=lay.aligned_model_dir, cameras_path=cameras_path, images_given=len(infos),
        registered=rec.num_reg_images(), mean_reprojection_error=mre, num_points3d=int(rec.num_points3D()),
        unregistered=outcome.unregistered, other_components=outcome.others, skipped_files=photos.skipped,
        pairing_used=outcome.pairing_used, num_pairs=len(outcome.pairs),
        timings={k: round(v, 3) for k, v in timings.items()}, cameras=camera_summary(rec),
        masked_images=len(outcome.masked), escalation=escalation.to_dict() if escalation else None,
        intrinsics=intrinsics_record(pycolmap, photos.groups, photos.given, rec), first_pass=outcome.first.to_dict(),
        focal_held=outcome.focal_held,
    )
    figures = {k: v for k, v in asdict(result).items() if k not in ("workspace", "model_dir", "cameras_path")}
    figures["principal_point_refined"] = outcome.principal_point_refined
    atomic_write_text(lay.alignment_json, json.dumps(figures, indent=2, default=str))
    run.finish(outputs={"model": lay.rel(lay.aligned_model_dir), "cameras": lay.rel(cameras_path)},
               results={"registered": result.registered, "images": len(infos),
                        "mean_reprojection_error": mre, "points3d": result.num_points3d,
                        "pairing": outcome.pairing_used, "pairs": len(outcome.pairs),
                        "masked_images": len(outcome.masked),
                        "escalation_rounds": len(escalation.rounds) if escalation else 0,
                        "first_pass": outcome.first.level, "skipped_files": list(photos.skipped),
                        "total_seconds": round(time.time() - t_start, 2)})
    return result
