"""The options of the "prepare" stage (screening, scanned film, user masks): every default in one place."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

ANALYSIS_SIZE = 1024  # long side (px) at which screening measures every image


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
    max_residual_px: float = 3.0  # a mark further than this from the affine fit is dropped (>= 5 marks)
    mask_border: bool = True  # mask the film border and data strips outside the picture area
    mask_margin_px: float = 4.0  # extra inward margin of the masks, output pixels


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
