"""The alignment stage: images -> features -> pairs -> matches -> mapping -> final bundle adjustment.

:func:`align` reads images from a folder and writes, in the workspace (paths from :class:`core.project.layout.Layout`):

- ``sfm/database.db``: COLMAP database (features, matches); kept so a re-run after a cancel reuses them;
- ``sfm/model/``: the largest reconstruction in COLMAP binary format, in the local model frame;
- ``sfm/alignment.json``: figures, the images not registered and why; ``cameras.gpkg``: camera positions.

The algorithm modules: :mod:`.inputs` (photos), :mod:`.firstpass` (the first pass's features from the photos'
texture), :mod:`.features` (cameras, masks, extraction, matching), :mod:`.pairs`, :mod:`.mapping` (mapping, bundle
adjustment), :mod:`.joining` (a split block joined by the photos' positions), :mod:`.escalation` (richer features
and pairs where the fast path left images out), :mod:`.links` (weak links matched again, guided by the block),
:mod:`.diagnosis` (why an image is not registered), :mod:`.record`, :mod:`.result`; options in :mod:`.options`.
"""
from __future__ import annotations

import os
import time
from dataclasses import asdict
from functools import partial
from typing import Dict, Optional

from ..common.cancel import load_pycolmap
from ..common.files import fingerprint
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io.images import ImageError, check_image_folder, require_images
from ..project.layout import Layout
from ..project.stages import run_stage
from ..project.workspace import Workspace
from .calibrated import read_calibrations
from .diagnosis import diagnose_unregistered, no_reconstruction_error, report_unregistered
from .escalation import EscalationContext, block_state, escalate
from .features import extract_features, match_pairs
from .firstpass import choose_first_pass
from .inputs import Photos, read_folder
from .joining import PositionJoin
from .links import reinforce
from .mapping import MappingJob, adjust_block, map_block, verified_links, verified_pairs, verified_partners
from .options import MIN_VERIFIED_INLIERS, AlignError, AlignOptions
from .pairs import select_pairs
from .record import STAGE, keep_previous, prepare_database, previous_alignment
from .result import AlignResult, Outcome, write_products


def check_options(options: AlignOptions) -> list:
    """The checks of the options that need no photo: AlignError for a choice out of its values, CalibrationError
    (file, line, field) for a calibration file that cannot be read.  Returns the calibrations read."""
    options.check()
    return read_calibrations(options)


def align(images_dir: str, workspace_dir: str, options: Optional[AlignOptions] = None,
          progress: Optional[Progress] = None) -> AlignResult:
    """Run the alignment stage.  Raises AlignError / ImageError / WorkspaceError / Cancelled.

    A re-run that fails or is cancelled leaves a previous complete alignment as it was: the image list, database,
    model and the later stages' records are replaced only when the new alignment succeeds."""
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
    lay = Layout(ws := Workspace.create_or_open(workspace_dir))  # checks writability before any work
    photos = read_folder(pycolmap, lay, images_dir, options, calibrations, progress)
    previous = previous_alignment(ws, lay)
    try:
        return _run(pycolmap, ws, lay, photos, options, previous is not None, t_start, progress)
    except BaseException:
        if previous is not None:
            keep_previous(ws, previous)
        raise


def _run(pycolmap, ws: Workspace, lay: Layout, photos: Photos, options: AlignOptions, keep_previous: bool,
         t_start: float, progress: Progress) -> AlignResult:
    """The stage body inside run_stage(): features, matches, mapping, bundle adjustment, products."""
    infos, groups, images_dir = photos.infos, photos.groups, photos.images_dir
    inputs = {"images": fingerprint([(im.name, im.width, im.height) for im in infos])}
    with run_stage(ws, STAGE, asdict(options), inputs) as run:
        photos.log_cameras(progress)
        os.makedirs(lay.sfm_dir, exist_ok=True)
        g0 = max(groups, key=lambda g: g.width * g.height)
        with run.step("probe", save=False):  # the first pass's features from the photos' texture and size
            first = choose_first_pass(pycolmap, infos, options, g0.width, g0.height, photos.positions)
        progress.info(first.log_line())
        job, masks = prepare_database(pycolmap, lay, photos, options, run.record, keep_previous, first, progress)
        db_path = job.db_path
        ws.save()
        with run.step("features", save=False):  # 2. features
            extract_features(pycolmap, job, first.settings, options, SubProgress(progress, 0.02, 0.35))
        with run.step("matching", save=False):  # 3. pairs + matching
            pairs, pairing_used, pw = select_pairs(infos, options.pairing, options.spatial_neighbours, photos.positions)
            for w in pw:
                progress.warning(w)
            progress.info(f"pair selection: {pairing_used}, {len(pairs)} pairs for {len(infos)} images")
            match_pairs(pycolmap, db_path, pairs, lay.sfm_dir, options, SubProgress(progress, 0.35, 0.65))
        # 4. mapping, components joined by the photos' positions, escalation where images are left out
        degenerate: Dict[str, str] = {}  # images a mapping gave a degenerate camera: name -> why
        mapping_job = MappingJob(db_path, images_dir, os.path.join(lay.sfm_dir, ".mapping"), len(infos))
        with run.step("mapping", save=False):
            ordered = map_block(pycolmap, mapping_job, options, SubProgress(progress, .65, .9), degenerate,
                                photos.held())
        join = PositionJoin(pycolmap, photos, options, mapping_job, run.record)  # also each escalation round's
        with run.step("join", save=False):
            ordered = join(ordered, progress)
        ctx = EscalationContext(pycolmap, job, first.settings, lay.sfm_dir, [im.name for im in infos], options, pairs,
                                lambda p, s=None: join(map_block(pycolmap, mapping_job, options, p, degenerate,
                                                                 photos.held(), s), p),
                                lambda reg, oth: diagnose_unregistered(
                                    infos, reg, oth, verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS),
                                    degenerate, verified_links(pycolmap, db_path, MIN_VERIFIED_INLIERS)[1]),
                                lambda: verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS), photos.positions)
        with run.step("escalation", save=False):
            ordered, escalation = escalate(ctx, ordered, SubProgress(progress, 0.90, 0.93))
        partners = verified_partners(pycolmap, db_path, MIN_VERIFIED_INLIERS)
        if not ordered:
            raise no_reconstruction_error(partners, len(infos), verified_pairs(pycolmap, db_path, MIN_VERIFIED_INLIERS),
                                     photos.held()[0])
        rec, others = ordered[0], block_state(ordered)[1]
        # 5. final bundle adjustment (held cameras constant; the focal held if it drifted), also after each links round
        adjust = partial(adjust_block, pycolmap, rec, options, progress, photos.held()[0], degenerate,
                         hold_focal=mapping_job.focal_held is not None, priors=join.priors(rec))
        with run.step("links", save=False):
            reinforce(pycolmap, rec, mapping_job, pairs, run.record, progress, adjust)
        with run.step("bundle_adjustment", save=False):
            progress.report(0.94, "final bundle adjustment")
            pp = adjust()
        registered = {rec.images[i].name for i in rec.reg_image_ids()}
        unregistered = diagnose_unregistered(infos, registered, others, partners, degenerate,
                                             verified_links(pycolmap, db_path, MIN_VERIFIED_INLIERS)[1])
        report_unregistered(progress, unregistered, others, len(registered))
        check_cancel(progress)
        outcome = Outcome(rec, unregistered, others, pairs, pairing_used, sorted(masks), escalation, first, pp,
                          db_path, mapping_job.focal_held)
        result = write_products(pycolmap, ws, lay, run, photos, outcome, t_start)
    # later stages were built on the previous model: run_stage marked them stale
    progress.report(1.0, f"aligned {result.registered}/{len(infos)} images, {result.mean_reprojection_error:.3f} px")
    return result


def load_model(workspace_dir: str):
    """The aligned model of a workspace as a pycolmap.Reconstruction (LayoutError, a RuntimeError, if none)."""
    load_pycolmap("reading the aligned model")
    return Layout(Workspace.open(workspace_dir)).load_aligned_model()
