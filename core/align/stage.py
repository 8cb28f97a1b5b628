"""The alignment stage: images -> features -> pairs -> matches -> mapping -> final bundle adjustment.

:func:`align` reads images from a folder and writes, in the workspace (paths from
:class:`core.project.layout.Layout`):

- ``sfm/database.db``: COLMAP database (features, matches); kept between runs so
  a re-run after a cancel reuses the features and matches already computed;
- ``sfm/model/``: the largest reconstruction in COLMAP binary format, in the
  local model frame;
- ``sfm/alignment.json``: figures and the list of images not registered, with why;
- ``cameras.gpkg``: the camera positions (model frame).

The algorithm modules: :mod:`.features` (cameras, masks, extraction, matching), :mod:`.pairs` (pair
selection), :mod:`.mapping` (incremental or global mapping, bundle adjustment), :mod:`.escalation` (richer
features and more pairs for the images the fast path left out, or a split block; ``escalation`` in
``sfm/alignment.json`` says what was done per image and why); the options in :mod:`.options`.
"""
from __future__ import annotations

import copy
import json
import os
import time
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional, Tuple

from ..common.cancel import load_pycolmap
from ..common.files import atomic_output, atomic_write_text, fingerprint
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io.images import (
    CameraGroup,
    ImageError,
    ImageInfo,
    check_image_folder,
    group_cameras,
    require_images,
    scan_images,
)
from ..io.vector import write_cameras_gpkg
from ..project.layout import Layout
from ..project.stages import ALIGN, run_stage
from ..project.workspace import Workspace
from .calibrated import (
    GivenCamera,
    held_cameras,
    intrinsics_record,
    plan_cameras,
    read_calibrations,
    scan_interior,
)
from .diagnosis import diagnose_unregistered, no_reconstruction_error, report_unregistered
from .escalation import EscalationContext, block_state, escalate
from .features import (
    Extraction,
    database_key,
    extract_features,
    file_hash,
    masks_for_colmap,
    match_pairs,
    setup_database,
)
from .firstpass import FirstPass, choose_first_pass
from .mapping import (
    MappingJob,
    adjust_block,
    camera_rows,
    camera_summary,
    map_block,
    verified_pairs,
    verified_partners,
)
from .options import MIN_VERIFIED_INLIERS, AlignError, AlignOptions
from .pairs import select_pairs
from .photos import PHOTO_FINGERPRINTS, fingerprint_photos

STAGE = ALIGN
STAGED_KEY = "staged_database_key"  # the align record's key of sfm/database.staged.db (a re-run in progress)


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


def _json(obj) -> str:
    return json.dumps(obj, indent=2, default=str)


def _read_images(images_dir: str, options: AlignOptions,
                 progress: Progress) -> Tuple[List[ImageInfo], List[str], List[CameraGroup]]:
    """(usable images, warnings naming skipped files, camera groups); AlignError with fewer than 2 images."""
    infos, skipped = scan_images(images_dir, options.focal_mm, options.sensor_width_mm, options.focal_px,
                                 SubProgress(progress, 0.0, 0.02))
    for w in skipped:
        progress.warning(w)
    if len(infos) == 0:
        raise AlignError(f"no readable images in {images_dir}")
    if len(infos) < 2:
        raise AlignError(f"only one readable image in {images_dir} ({infos[0].name}): alignment needs at least 2 "
                         "overlapping images (for a single photo use 'Orthorectify image')")
    try:
        groups = group_cameras(infos, options.grouping)
    except ImageError as e:
        raise AlignError(str(e)) from e
    return infos, skipped, groups


@dataclass
class _Photos:
    """What the alignment reads from the image folder before any work."""

    images_dir: str
    infos: List[ImageInfo]
    skipped: List[str]
    groups: List[CameraGroup]
    fingerprints: Dict[str, str]  # image name -> content fingerprint (core.align.photos)
    seconds: float
    given: Dict[str, GivenCamera]  # group key -> its given interior orientation (core.align.calibrated)

    def held(self) -> Tuple[Dict[int, GivenCamera], bool]:
        """(camera id -> given, of the cameras the alignment holds; whether every camera is held)."""
        ids = held_cameras(self.groups, self.given)
        return ids, bool(ids) and len(ids) == len(self.groups)


def _database_path(lay: Layout, record: dict, key: str, keep_previous: bool) -> Tuple[str, Optional[str]]:
    """(the database this run works in, the key it was made for).  The workspace's database when it was made for
    the same images and settings (a re-run after a cancel reuses its features and matches) or when there is no
    previous alignment to keep; otherwise a staged database beside it (``sfm/database.staged.db``), swapped in
    only when the new alignment succeeds, so a failed re-run leaves the previous alignment's database as it was."""
    if not keep_previous or record.get("database_key") == key or not os.path.exists(lay.database):
        record.pop(STAGED_KEY, None)
        if os.path.exists(lay.staged_database):
            os.unlink(lay.staged_database)
        known, record["database_key"] = record.get("database_key"), key
        return lay.database, known
    known, record[STAGED_KEY] = record.get(STAGED_KEY), key
    return lay.staged_database, known


def _setup(pycolmap, lay: Layout, photos: _Photos, options: AlignOptions, record: dict, keep_previous: bool,
           first: FirstPass, progress: Progress):
    """Masks for COLMAP and the database's cameras: (what the extraction works on, image -> mask)."""
    infos, groups = photos.infos, photos.groups
    mask_path, masks = masks_for_colmap(lay.masks_dir, infos, lay.sfm_dir)
    masks_key = fingerprint(sorted((n, file_hash(p)) for n, p in masks.items())) if masks else None
    if masks:
        record["inputs"]["masks"] = masks_key
        progress.info(f"masks: {len(masks)} of {len(infos)} images have a mask ({lay.masks_dir}): "
                      "no features where they are black")
    key = database_key(groups, options, photos.images_dir, masks_key, fingerprint(photos.fingerprints), first.key())
    db_path, known_key = _database_path(lay, record, key, keep_previous)
    camera_ids = setup_database(pycolmap, db_path, groups, options, key, known_key, photos.given)
    return Extraction(db_path, photos.images_dir, groups, camera_ids, mask_path, sorted(masks)), masks


def _read_folder(pycolmap, lay: Layout, images_dir: str, options: AlignOptions, calibrations: list,
                 progress: Progress) -> _Photos:
    """The usable photos of ``images_dir``, their fingerprints and their cameras' given interior orientations
    (a calibration file's, film scans' restituted by Prepare images); AlignError with fewer than two."""
    t0 = time.time()
    infos, skipped, groups = _read_images(images_dir, options, progress)
    groups, given = plan_cameras(pycolmap, groups, infos, calibrations, scan_interior(lay.scans_json, infos),
                                 options, progress)
    return _Photos(images_dir, infos, skipped, groups, fingerprint_photos(infos), time.time() - t0, given)


def _previous_alignment(ws: Workspace, lay: Layout) -> Optional[dict]:
    """A copy of the align stage's record when the workspace holds a complete alignment (else None)."""
    return copy.deepcopy(ws.data["stages"][STAGE]) if lay.has_aligned_model() else None


def _keep_previous(ws: Workspace, previous: dict) -> None:
    """After a failed or cancelled re-run: the previous alignment stays the workspace's (its record, image list,
    database and model were not replaced); the attempt is recorded under ``last_attempt``."""
    failed = ws.data["stages"].get(STAGE, {})
    record = copy.deepcopy(previous)
    record["last_attempt"] = {k: failed.get(k) for k in ("status", "started", "finished", "error", "parameters")}
    if failed.get(STAGED_KEY):
        record[STAGED_KEY] = failed[STAGED_KEY]  # a re-run of the same attempt resumes in the staged database
    ws.data["stages"][STAGE] = record
    ws.save()


def check_options(options: AlignOptions) -> list:
    """The checks of the alignment's options that need no photo: AlignError for a choice out of its values,
    CalibrationError (file, line, field) for a calibration file that cannot be read.  Returns the
    calibrations read (core.io.calibration.CameraCalibration)."""
    options.check()
    return read_calibrations(options)


def align(images_dir: str, workspace_dir: str, options: Optional[AlignOptions] = None,
          progress: Optional[Progress] = None) -> AlignResult:
    """Run the alignment stage.  Raises AlignError / ImageError / WorkspaceError / Cancelled.

    A re-run that fails or is cancelled leaves a previous complete alignment as it was: the image list, the
    database, the model and the later stages' records are replaced only when the new alignment succeeds."""
    options = options or AlignOptions()
    progress = progress or NullProgress()
    calibrations = check_options(options)  # a mistyped choice or a bad calibration file fails before any work
    pycolmap = load_pycolmap("the alignment")
    t_start = time.time()
    images_dir = os.path.abspath(images_dir)
    try:
        check_image_folder(images_dir)  # does not exist / is a file / cannot be read: before the workspace
        require_images(images_dir)  # empty: before the workspace too (issue 36 item 21: it was created)
    except ImageError as e:
        raise AlignError(str(e)) from e
    ws = Workspace.create_or_open(workspace_dir)  # checks writability before any work
    lay = Layout(ws)
    photos = _read_folder(pycolmap, lay, images_dir, options, calibrations, progress)
    previous = _previous_alignment(ws, lay)
    try:
        return _run(pycolmap, ws, lay, photos, options, previous is not None, t_start, progress)
    except BaseException:
        if previous is not None:
            _keep_previous(ws, previous)
        raise


def _run(pycolmap, ws: Workspace, lay: Layout, photos: _Photos, options: AlignOptions, keep_previous: bool,
         t_start: float, progress: Progress) -> AlignResult:
    """The stage body inside run_stage(): features, matches, mapping, bundle adjustment, products."""
    infos, groups, images_dir = photos.infos, photos.groups, photos.images_dir
    inputs = {"images": fingerprint([(im.name, im.width, im.height) for im in infos])}
    with run_stage(ws, STAGE, asdict(options), inputs) as run:
        for g in groups:
            given = photos.given.get(g.key)
            focal = (f"focal {given.params[0]:.1f} px ({given.mode}, {os.path.basename(given.source)})" if given is not None
                     else f"focal prior {g.focal_px:.1f} px ({g.focal_source})")
            progress.info(f"camera {g.camera_id}: {g.make} {g.model} {g.width}x{g.height}, {focal}, "
                          f"{len(g.images)} images")
        os.makedirs(lay.sfm_dir, exist_ok=True)
        g0 = max(groups, key=lambda g: g.width * g.height)
        with run.step("probe", save=False):  # the first pass's features from the photos' texture and size
            first = choose_first_pass(pycolmap, infos, options, g0.width, g0.height)
        progress.info(first.log_line())
        job, masks = _setup(pycolmap, lay, photos, options, run.record, keep_previous, first, progress)
        db_path = job.db_path
        ws.save()

        # 2. features
        with run.step("features", save=False):
            extract_features(pycolmap, job, first.settings, options, SubProgress(progress, 0.02, 0.35))
        # 3. pairs + matching
        with run.step("matching", save=False):
            pairs, pairing_used, pw = select_pairs(infos, options.pairing, options.spatial_neighbours)
            for w in pw:
                progress.warning(w)
            progress.info(f"pair selection: {pairing_used}, {len(pairs)} pairs for {len(infos)} images")
            match_pairs(pycolmap, db_path, pairs, lay.sfm_dir, options, SubProgress(progress, 0.35, 0.65))
        # 4. mapping, then escalation where the fast path left images out or split the block
        degenerate: Dict[str, str] = {}  # images a mapping gave a degenerate camera: name -> why
        mapping_job = MappingJob(db_path, images_dir, os.path.join(lay.sfm_dir, ".mapping"), len(infos))
        with run.step("mapping", save=False):
            ordered = map_block(pycolmap, mapping_job, options, SubProgress(progress, 0.65, 0.90), degenerate,
                                photos.held())
        ctx = EscalationContext(pycolmap, job, first.settings, lay.sfm_dir, [im.name for im in infos], options, pairs,
                                lambda p: map_block(pycolmap, mapping_job, options, p, degenerate, photos.held()),
                                lambda reg, oth: diagnose_unregistered(
                                    infos, reg, oth, verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS),
                                    degenerate),
                                lambda: verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS))
        with run.step("escalation", save=False):
            ordered, escalation = escalate(ctx, ordered, SubProgress(progress, 0.90, 0.93))
        partners = verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS)
        if not ordered:
            raise no_reconstruction_error(partners, len(infos), verified_pairs(pycolmap, db_path, MIN_VERIFIED_INLIERS),
                                     photos.held()[0])
        rec = ordered[0]
        _registered, others = block_state(ordered)
        # 5. final global bundle adjustment (the held cameras' intrinsics constant)
        held = photos.held()[0]
        with run.step("bundle_adjustment", save=False):
            progress.report(0.94, "final bundle adjustment")
            pp = adjust_block(pycolmap, rec, options, progress, held, degenerate)
        registered = {rec.images[i].name for i in rec.reg_image_ids()}
        unregistered = diagnose_unregistered(infos, registered, others, partners, degenerate)
        report_unregistered(progress, unregistered, others, len(registered))
        check_cancel(progress)

        # 6. write the model atomically; the new image list and database become the workspace's
        with atomic_output(lay.aligned_model_dir) as tmp:
            os.makedirs(tmp)
            rec.write_binary(tmp)
        _commit(ws, lay, run.record, photos, db_path)
        cameras_path = write_cameras_gpkg(ws.root, camera_rows(rec), crs=None)
        mre = float(rec.compute_mean_reprojection_error())
        timings = dict(images=photos.seconds, **run.timings)
        result = AlignResult(
            workspace=ws.root, model_dir=lay.aligned_model_dir, cameras_path=cameras_path, images_given=len(infos),
            registered=len(registered), mean_reprojection_error=mre, num_points3d=int(rec.num_points3D()),
            unregistered=unregistered, other_components=others, skipped_files=photos.skipped,
            pairing_used=pairing_used, num_pairs=len(pairs), timings={k: round(v, 3) for k, v in timings.items()},
            cameras=camera_summary(rec), masked_images=len(masks),
            escalation=escalation.to_dict() if escalation else None,
            intrinsics=intrinsics_record(pycolmap, groups, photos.given, rec), first_pass=first.to_dict(),
        )
        figures = {k: v for k, v in asdict(result).items() if k not in ("workspace", "model_dir", "cameras_path")}
        figures["principal_point_refined"] = pp
        atomic_write_text(lay.alignment_json, _json(figures))
        run.finish(outputs={"model": lay.rel(lay.aligned_model_dir), "cameras": lay.rel(cameras_path)},
                   results={"registered": result.registered, "images": len(infos),
                            "mean_reprojection_error": mre, "points3d": result.num_points3d,
                            "pairing": pairing_used, "pairs": len(pairs), "masked_images": len(masks),
                            "escalation_rounds": len(escalation.rounds) if escalation else 0,
                            "first_pass": first.level,
                            "skipped_files": list(photos.skipped),
                            "total_seconds": round(time.time() - t_start, 2)})
    # later stages were built on the previous model: run_stage marked them stale
    progress.report(1.0, f"aligned {result.registered}/{len(infos)} images, {mre:.3f} px")
    return result


def _commit(ws: Workspace, lay: Layout, record: dict, photos: _Photos, db_path: str) -> None:
    """The new alignment succeeded: its image list, camera groups, photo fingerprints and database become the
    workspace's (the manifest is saved when run_stage records the stage done)."""
    if db_path != lay.database:
        os.replace(db_path, lay.database)
        record["database_key"] = record.pop(STAGED_KEY)
    record.pop("last_attempt", None)
    record[PHOTO_FINGERPRINTS] = photos.fingerprints
    ws.data["images_dir"] = photos.images_dir
    ws.data["images"] = [im.to_dict() for im in photos.infos]
    ws.data["camera_groups"] = [asdict(g) for g in photos.groups]


def load_model(workspace_dir: str):
    """The aligned model of a workspace as a pycolmap.Reconstruction (LayoutError, a RuntimeError, if none)."""
    load_pycolmap("reading the aligned model")
    return Layout(Workspace.open(workspace_dir)).load_aligned_model()
