"""The options of the alignment stage and its constants: every default in one place."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Optional

from ..common.errors import ArchaeoOrthoError
from ..io.gcp import read_camera_positions
from ..io.images import GROUP_AUTO, GROUP_PER_IMAGE, GROUP_SINGLE

PAIRINGS = ("auto", "exhaustive", "sequential", "spatial")
GROUPINGS = (GROUP_AUTO, GROUP_SINGLE, GROUP_PER_IMAGE)
CAMERA_MODELS = ("AUTO", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV")

SPATIAL_NEIGHBOURS = 12
SEQUENTIAL_OVERLAP = 12
LOOP_STRIDE = 10
MAX_LOOP_ANCHORS = 30
AUTO_EXHAUSTIVE_MAX = 100
UPSAMPLE_BELOW = 1000  # long side (px, at the matching scale) below which SIFT starts on a 2x upsampled image
# MAX_IMAGE_SIZE 0 (auto): larger photos are scaled to this many megapixels for the features only (the DSM and the
# orthophotos use every pixel): SIFT's finest octave on a 4-16 MP photo costs 4-16 x for features the budget
# below drops anyway (COLMAP keeps the largest-scale ones)
AUTO_FEATURE_MEGAPIXELS = 2.0
AUTO_FEATURES_PER_MP = 4000  # MAX_FEATURES 0 (auto): this many per megapixel of the image the features come from,
AUTO_FEATURES_RANGE = (2048, 4096)  # within these bounds (matching and mapping grow with the count, the model not)
# Faint features (the escalation's "faint" round, and the first pass where the texture probe finds the photos
# starved): pycolmap's default budget at least, and a third of SIFT's default peak threshold (0.02 / octave
# resolution 3)
FAINT_MIN_FEATURES = 8192
FAINT_PEAK_THRESHOLD = 0.02 / 3 / 3
# The texture probe (core.align.firstpass): SIFT at the planned settings on up to PROBE_PHOTOS photos spread over
# the block; a photo is starved when it fills less than PROBE_MIN_YIELD of the budget or its features hold less
# than PROBE_MIN_COVERAGE of a PROBE_GRID-cell grid over the frame (a cell holds features when it has a quarter of
# its even share of them) and verifies fewer than PROBE_MIN_MATCHES matches with its neighbour; a setting is kept
# when at most PROBE_STARVED_SHARE of the probed photos starve
PROBE_PHOTOS = 6
PROBE_MIN_YIELD = 0.2  # caliterra's 1 MP photos fill 0.32 of 3,000 and all register; faint farmland 0.0-0.06
PROBE_MIN_COVERAGE = 0.5
PROBE_GRID = 8  # cells along the long side (the short side in proportion)
PROBE_STARVED_SHARE = 0.2
# a photo short of features or coverage is still not starved when it verifies this many matches with its neighbour
# (twice COLMAP's 30 2D-3D inliers to register an image): the synthetic farmland at contrast 0.4 registers every
# photo with 234 features per photo (a yield of 0.06), at 0.15 with 3-67 it does not
PROBE_MIN_MATCHES = 60
# The calls to COLMAP are made in blocks, the unit of progress (a cancel acts within a call, through its token).
# Each call has a fixed cost (threads, reading the database): blocks are sized by the work in them, so that small
# frames do not pay it per image or per pair (the synthetic orbit's 16 frames of 480 x 360: 10.3 -> 8.3 CPU s)
MATCH_BLOCK = 24  # pairs per matching call at MATCH_BLOCK_KEYPOINTS keypoints per image (and at least this many)
MATCH_BLOCK_KEYPOINTS = 6000  # matching a pair costs about the product of the two images' keypoint counts
MAX_MATCH_BLOCK = 240
EXTRACT_BLOCK = 2  # images per extraction call at least
EXTRACT_BLOCK_MEGAPIXELS = 8.0  # megapixels SIFT works through per extraction call (an upsampled image counts 4 x)
MAX_EXTRACT_BLOCK = 64
MAPPERS = ("incremental", "global")
# what the adjustments may change of a camera's interior orientation (core.align.calibrated): "auto" = fixed where a
# calibration (file, or a film scan's restituted interior orientation) is given, estimated elsewhere
INTRINSICS = ("auto", "fixed", "refined", "estimated")
HELD = ("fixed", "refined")  # modes whose intrinsics the alignment keeps constant (refined: with priors in georef)
MIN_VERIFIED_INLIERS = 15  # a pair with fewer inliers does not count as "matched" in the diagnosis


class AlignError(ArchaeoOrthoError, RuntimeError):
    """Alignment cannot start or produced nothing usable; the message says why."""


@dataclass
class AlignOptions:
    pairing: str = "auto"
    camera_model: str = "AUTO"
    max_image_size: int = 0  # long side for the features only; 0 = auto (at most AUTO_FEATURE_MEGAPIXELS)
    max_features: int = 0  # 0 = auto: AUTO_FEATURES_PER_MP per megapixel within AUTO_FEATURES_RANGE
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
    texture_probe: bool = True  # choose the first pass's features from the photos' texture (firstpass.py)
    escalate: bool = True  # retry images left out / a split block with richer features and pairs (escalation.py)
    calibration: Optional[str] = None  # a camera calibration file (core.io.calibration), None: none
    intrinsics: str = "auto"  # one of INTRINSICS; a camera's own ``adjust`` in the calibration file overrides it
    # a camera positions file (the georeference's format, e.g. a GNSS log): where given, its positions choose the
    # pairs (spatial) and the probe's neighbours instead of EXIF GPS; it does not georeference the block
    camera_positions: Optional[str] = None

    def __post_init__(self) -> None:
        """The choices normalised (case) and every value checked when the options are made: a mistyped choice or
        a value out of range fails before any work, naming the option."""
        self.pairing = str(self.pairing or "auto").lower()
        self.camera_model = str(self.camera_model or "AUTO").upper()
        self.grouping = str(self.grouping or GROUP_AUTO).lower()
        self.mapper = str(self.mapper or "incremental").lower()
        self.intrinsics = str(self.intrinsics or "auto").lower()
        self.check()

    def check(self) -> None:
        """AlignError for a value out of its choices or range (before any work)."""
        for name, value, choices in (("pairing", self.pairing, PAIRINGS), ("camera_model", self.camera_model,
                                                                           CAMERA_MODELS),
                                     ("grouping", self.grouping, GROUPINGS)):
            if value not in choices:
                raise AlignError(f"unknown {name} {value!r}; choose one of {', '.join(choices)}")
        for name in ("max_image_size", "max_features"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise AlignError(f"AlignOptions.{name} must be a whole number >= 0 (0: automatic), not {value!r}")
        if not isinstance(self.spatial_neighbours, int) or self.spatial_neighbours < 1:
            raise AlignError(f"AlignOptions.spatial_neighbours must be a whole number >= 1, not "
                             f"{self.spatial_neighbours!r}")
        for name in ("focal_mm", "sensor_width_mm", "focal_px"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise AlignError(f"AlignOptions.{name} must be a positive number or None, not {value!r}")
        if self.camera_positions is not None:  # GCPError naming the file and the line it cannot read
            if not (isinstance(self.camera_positions, str) and os.path.isfile(self.camera_positions)):
                raise AlignError(f"AlignOptions.camera_positions: {self.camera_positions!r} is not a file")
            read_camera_positions(self.camera_positions, warnings=[])
        if self.mapper not in MAPPERS:
            raise AlignError(f"unknown mapper {self.mapper!r}; choose one of {', '.join(MAPPERS)}")
        if self.intrinsics not in INTRINSICS:
            raise AlignError(f"unknown intrinsics choice {self.intrinsics!r}; choose one of {', '.join(INTRINSICS)} "
                             "(auto: fixed where a calibration is given, estimated elsewhere)")
