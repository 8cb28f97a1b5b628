"""The align stage's record in the workspace: which database a run works in (the workspace's, or a staged one
beside it while a re-run must keep the previous alignment), the previous alignment kept after a failed re-run, and
the new alignment made the workspace's when it succeeds."""
from __future__ import annotations

import copy
import os
from dataclasses import asdict
from typing import Optional, Tuple

from ..common.files import fingerprint
from ..common.progress import Progress
from ..project.layout import Layout
from ..project.stages import ALIGN
from ..project.workspace import Workspace
from .features import (
    FEATURE_IMAGES_VERSION,
    Extraction,
    database_key,
    feature_images,
    file_hash,
    masks_for_colmap,
    setup_database,
)
from .firstpass import FirstPass
from .inputs import Photos
from .options import AlignOptions
from .photos import PHOTO_FINGERPRINTS

STAGE = ALIGN
STAGED_KEY = "staged_database_key"  # the align record's key of sfm/database.staged.db (a re-run in progress)


def database_path(lay: Layout, record: dict, key: str, keep_previous: bool) -> Tuple[str, Optional[str]]:
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


def prepare_database(pycolmap, lay: Layout, photos: Photos, options: AlignOptions, record: dict, keep_previous: bool,
           first: FirstPass, progress: Progress):
    """Masks for COLMAP and the database's cameras: (what the extraction works on, image -> mask)."""
    infos, groups = photos.infos, photos.groups
    mask_path, masks = masks_for_colmap(lay.masks_dir, infos, lay.sfm_dir)
    masks_key = fingerprint(sorted((n, file_hash(p)) for n, p in masks.items())) if masks else None
    if masks:
        record["inputs"]["masks"] = masks_key
        progress.info(f"masks: {len(masks)} of {len(infos)} images have a mask ({lay.masks_dir}): "
                      "no features where they are black")
    proxy_path, proxied = feature_images(infos, lay.sfm_dir)
    if proxied:  # their features come from the 8-bit images: a workspace's features from the photos are not reused
        progress.info(f"features: {len(proxied)} photo(s) matched on an 8-bit image of their primary band or grey "
                      f"({proxy_path})")
    photos_key = fingerprint(photos.fingerprints) if not proxied else \
        fingerprint([photos.fingerprints, FEATURE_IMAGES_VERSION, proxied])
    key = database_key(groups, options, photos.images_dir, masks_key, photos_key, first.key())
    db_path, known_key = database_path(lay, record, key, keep_previous)
    camera_ids = setup_database(pycolmap, db_path, groups, options, key, known_key, photos.given)
    return Extraction(db_path, photos.images_dir, groups, camera_ids, mask_path, sorted(masks), proxy_path,
                      proxied), masks


def previous_alignment(ws: Workspace, lay: Layout) -> Optional[dict]:
    """A copy of the align stage's record when the workspace holds a complete alignment (else None)."""
    return copy.deepcopy(ws.data["stages"][STAGE]) if lay.has_aligned_model() else None


def keep_previous(ws: Workspace, previous: dict) -> None:
    """After a failed or cancelled re-run: the previous alignment stays the workspace's (its record, image list,
    database and model were not replaced); the attempt is recorded under ``last_attempt``."""
    failed = ws.data["stages"].get(STAGE, {})
    record = copy.deepcopy(previous)
    record["last_attempt"] = {k: failed.get(k) for k in ("status", "started", "finished", "error", "parameters")}
    if failed.get(STAGED_KEY):
        record[STAGED_KEY] = failed[STAGED_KEY]  # a re-run of the same attempt resumes in the staged database
    ws.data["stages"][STAGE] = record
    ws.save()


def commit(ws: Workspace, lay: Layout, record: dict, photos: Photos, db_path: str) -> None:
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
