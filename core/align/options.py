"""The options of the alignment stage and its constants: every default in one place."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from ..common.errors import ArchaeoOrthoError
from ..io.images import GROUP_AUTO

PAIRINGS = ("auto", "exhaustive", "sequential", "spatial")
CAMERA_MODELS = ("AUTO", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV")

SPATIAL_NEIGHBOURS = 12
SEQUENTIAL_OVERLAP = 12
LOOP_STRIDE = 10
MAX_LOOP_ANCHORS = 30
AUTO_EXHAUSTIVE_MAX = 100
UPSAMPLE_BELOW = 1000  # long side (px, at the matching scale) below which SIFT starts on a 2x upsampled image
MATCH_BLOCK = 24  # pairs per matching call: the unit of progress and cancel
EXTRACT_BLOCK = 2  # images per extraction call: the unit of progress and cancel
MAPPERS = ("incremental", "global")
MIN_VERIFIED_INLIERS = 15  # a pair with fewer inliers does not count as "matched" in the diagnosis


class AlignError(ArchaeoOrthoError, RuntimeError):
    """Alignment cannot start or produced nothing usable; the message says why."""


@dataclass
class AlignOptions:
    pairing: str = "auto"
    camera_model: str = "AUTO"
    max_image_size: int = 0  # 0 = full size; downscale for feature extraction only
    max_features: int = 0  # 0 = auto: about 4000 per megapixel, between 2048 and 8192
    affine_features: bool = False  # affine-shape SIFT + domain-size pooling (oblique sets)
    grouping: str = GROUP_AUTO  # auto / single / per_image
    focal_mm: Optional[float] = None
    sensor_width_mm: Optional[float] = None
    focal_px: Optional[float] = None
    spatial_neighbours: int = SPATIAL_NEIGHBOURS
    num_threads: int = -1
    refine_principal_point: bool = True  # in the final global BA, when the camera has enough images
    min_images_opencv: int = 10  # AUTO picks OPENCV from this many images per camera, RADIAL below
    mapper: str = "incremental"  # incremental (COLMAP) or global (GLOMAP: rotation averaging + global positioning)
    first_octave: Optional[int] = None  # SIFT's first octave; None = auto (-1, upsampled, below UPSAMPLE_BELOW px)
    seed: int = 1
    escalate: bool = True  # retry images left out / a split block with richer features and pairs (escalation.py)
