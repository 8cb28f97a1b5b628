"""Alignment with pycolmap: the names other modules, the faces and the tests import, in one place.

The stage is :func:`core.align.stage.align`; the algorithm modules are :mod:`.features` (cameras, masks for
COLMAP, SIFT extraction, matching), :mod:`.pairs` (pair selection), :mod:`.mapping` (incremental or global
mapping, final bundle adjustment) and the options in :mod:`.options`.
"""
from __future__ import annotations

from ..common.cancel import CancelWatcher
from .features import (
    auto_max_features,
    choose_camera_model,
    extract_features,
    masks_for_colmap,
    match_pairs,
    setup_database,
    sift_first_octave,
)
from .mapping import camera_rows, camera_summary, final_bundle_adjustment, run_mapping, verified_partners
from .options import (
    AUTO_EXHAUSTIVE_MAX,
    CAMERA_MODELS,
    EXTRACT_BLOCK,
    LOOP_STRIDE,
    MAPPERS,
    MATCH_BLOCK,
    MAX_LOOP_ANCHORS,
    PAIRINGS,
    SEQUENTIAL_OVERLAP,
    SPATIAL_NEIGHBOURS,
    UPSAMPLE_BELOW,
    AlignError,
    AlignOptions,
)
from .pairs import gps_to_local_xy, select_pairs
from .stage import STAGE, AlignResult, align, diagnose_unregistered, load_model

__all__ = [
    "AUTO_EXHAUSTIVE_MAX", "CAMERA_MODELS", "EXTRACT_BLOCK", "LOOP_STRIDE", "MAPPERS", "MATCH_BLOCK",
    "MAX_LOOP_ANCHORS", "PAIRINGS", "SEQUENTIAL_OVERLAP", "SPATIAL_NEIGHBOURS", "STAGE", "UPSAMPLE_BELOW",
    "AlignError", "AlignOptions", "AlignResult", "CancelWatcher", "align", "auto_max_features", "camera_rows",
    "camera_summary", "choose_camera_model", "diagnose_unregistered", "extract_features", "final_bundle_adjustment",
    "gps_to_local_xy", "load_model", "masks_for_colmap", "match_pairs", "run_mapping", "select_pairs",
    "setup_database", "sift_first_octave", "verified_partners",
]
