"""The options of the "prepare" stage (screening, scanned film, user masks): every default in one place."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

from ..common.errors import ArchaeoOrthoError

ANALYSIS_SIZE = 1024  # long side (px) at which screening measures every image
FIDUCIAL_TYPES = ("auto", "cross", "dot", "ring_dot", "cross_ring")  # literal: i18n/make_catalog.py reads it
MARK_KINDS = FIDUCIAL_TYPES[1:]  # the fiducial marks core.prepare.scans finds
LAYOUT_NAMES = ("auto", "corners", "sides", "eight")  # where the marks are (core.prepare.scans.LAYOUTS)
Y_AXES = ("auto", "down", "up")  # the mask polygons' y axis: rows down, or y = -row (the QGIS georeferencer)


class PrepareError(ArchaeoOrthoError, ValueError):
    """The prepare stage's options refuse a value; the message names the option."""


class ScanError(PrepareError):
    """Scanned film cannot be prepared; the message names the file and the problem."""


@dataclass
class ScreeningOptions:
    blur_threshold: float = 0.0  # absolute minimum blur score (0 = no absolute threshold)
    blur_relative: float = 0.4  # flag images scoring below this fraction of the set's median
    clip_max: float = 0.05  # largest fraction of clipped shadows or highlights
    brightness_tolerance: float = 0.25  # largest |mean brightness - set median| (fraction of full scale)
    min_dynamic_range: float = 0.10  # smallest 1-99 % range (fraction of full scale)
    exclude_flagged: bool = False
    analysis_size: int = ANALYSIS_SIZE


@dataclass
class ScanOptions:
    fiducial_type: str = "auto"  # auto / cross / dot / ring_dot / cross_ring
    layout: str = "auto"  # auto / corners / sides / eight
    template_path: Optional[str] = None  # an image of one fiducial mark, at the scans' resolution
    fiducial_coordinates: Optional[str] = None  # file path or text: "id x y" lines in mm, optional "PP x y"
    focal_length_mm: Optional[float] = None
    scan_pixel_size_mm: Optional[float] = None  # scan resolution when not in the file (25.4 / dpi)
    output_pixel_size: Optional[float] = None  # in frame units (mm or px); default: the median scan's
    margin: Optional[float] = None  # frame units beyond the outermost fiducial centres; default 1 mark size
    detect_size: int = 1200  # long side of the reduced scan used for the coarse search
    min_score: float = 0.6  # smallest correlation accepted for a mark
    # a mark further than this from the affine fit is dropped (>= 5 marks), else a warning; a scan with a mark over
    # 4 x this is left out (core.prepare.scans.prepare_scans)
    max_residual_px: float = 3.0
    mask_border: bool = True  # mask the film border and data strips outside the picture area
    mask_margin_px: float = 4.0  # extra inward margin of the masks, output pixels

    def __post_init__(self) -> None:
        """ScanError naming the option for a choice or value out of range (before any scan is read)."""
        self.fiducial_type = str(self.fiducial_type or "auto").lower()
        self.layout = str(self.layout or "auto").lower()
        if self.fiducial_type not in FIDUCIAL_TYPES:
            raise ScanError(f"unknown fiducial type {self.fiducial_type!r}; choose one of {', '.join(FIDUCIAL_TYPES)}")
        if self.layout not in LAYOUT_NAMES:
            raise ScanError(f"unknown fiducial layout {self.layout!r}; choose one of {', '.join(LAYOUT_NAMES)}")
        for name in ("focal_length_mm", "scan_pixel_size_mm", "output_pixel_size"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ScanError(f"ScanOptions.{name} must be a positive number or none, not {value!r}")
        if not 0 < self.min_score <= 1:
            raise ScanError(f"ScanOptions.min_score must be in (0, 1], not {self.min_score!r}")


@dataclass
class PrepareOptions:
    screening: ScreeningOptions = field(default_factory=ScreeningOptions)
    scanned_film: bool = False
    scan: Optional[ScanOptions] = None  # when scanned_film (None = ScanOptions())
    # user masks: "ignore" polygons, (image name or None for every image, [exterior, hole, ...][, label])
    # with rings of (x, y) image pixel coordinates (core.prepare.masks); for scanned film in the prepared
    # images' frame
    mask_polygons: Optional[Sequence] = None
    mask_source: str = "mask polygons"  # names the polygons' origin (a layer, a file) in messages
    mask_y_axis: str = "auto"  # auto / down / up (y = -row, the QGIS georeferencer)
    # sky masks (core.prepare.sky): high obliques showing the horizon; the sky is hidden from the alignment
    sky_masks: bool = False
    sky: Optional["SkyOptions"] = None  # when sky_masks (None = SkyOptions())
    output_dir: Optional[str] = None  # the folder of prepared images (None = <workspace>/prepared)

    def __post_init__(self) -> None:
        self.mask_y_axis = str(self.mask_y_axis or "auto").lower()
        if self.mask_y_axis not in Y_AXES:
            raise PrepareError(f"unknown y axis {self.mask_y_axis!r} of the mask polygons; choose one of "
                            f"{', '.join(Y_AXES)}")


@dataclass
class SkyOptions:
    """The sky detector of core.prepare.sky (before alignment): smooth, bright, bluish or pale regions connected
    to the upper edge of the upright photo."""

    analysis_size: int = 640  # long side (px) at which the sky is searched
    max_texture: float = 4.0  # largest local standard deviation (grey levels of 255, 7 x 7 window) of the sky
    min_brightness: float = 0.45  # smallest mean brightness of the sky (fraction of full scale)
    min_blueness: float = 0.03  # blue minus red (fraction of full scale) of a blue sky...
    max_pale_saturation: float = 0.12  # ...or at most this spread between the channels (haze, overcast white)
    min_fraction: float = 0.005  # a smaller region at the upper edge is no sky
    min_top_cover: float = 0.25  # the sky spans at least this share of the upper edge (and never reaches the lower)
    margin: float = 0.015  # the mask reaches this fraction of the image height beyond the sky (the horizon's haze)
    # the horizon: the sky's lower edge follows one smooth line (a straight horizon, bent by the lens) within this
    # fraction of the image height over at least min_horizon_cover of the width; the mask stops there
    horizon_tolerance: float = 0.015
    min_horizon_cover: float = 0.7
    # where the photo records its camera's pitch (a drone's XMP): no sky more than this far below the horizon the
    # pitch and the focal length give (the gimbal's accuracy, a guessed focal length, a small roll)
    pitch_slack_deg: float = 5.0
