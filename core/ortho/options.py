"""The options of the orthophoto stage and of single-image orthorectification (defaults in one place),
and the error they raise."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional, Tuple

from ..common.errors import ArchaeoOrthoError
from ..geometry.camera import Intrinsics


class OrthoError(ArchaeoOrthoError, RuntimeError):
    """Orthophoto production cannot run with this input; the message says why."""


BLENDINGS = ("feather", "multiband", "none")
INTERPOLATIONS = ("bilinear", "cubic", "nearest")
MODES = ("ortho", "planar")


@dataclass
class OrthoOptions:
    """Options of the orthophoto stage (one dataclass, as OpenSfM's config): its inputs and outputs, and how the
    mosaic is made.  Checked when made (OrthoError naming the setting)."""

    dsm_path: Optional[str] = None  # the DSM; None = the workspace's (the DSM stage's output, else <workspace>/dsm.tif)
    # which oriented images (core.ortho.cameras.select_cameras: names, globs, !exclusions, group:<camera>); None = all
    images_filter: Optional[str] = None
    output: Optional[str] = None  # the orthomosaic (a COG); None = <workspace>/orthomosaic.tif
    per_image_folder: Optional[str] = None  # one true orthophoto per image written there; None = none
    seamlines: Optional[str] = None  # the which-image polygons written to this GeoPackage; None = none
    resolution: float = 0.0  # output cell size in CRS units; 0 = the images' median ground sample distance
    blending: str = "feather"  # feather / multiband / none
    interpolation: str = "bilinear"  # bilinear / cubic / nearest
    tile: int = 512  # output cells per tile side
    feather_gsd: float = 16.0  # width of the feathering ramp across a seam, in GSD
    occlusion: bool = True  # leave cells hidden from a camera nodata (true orthophoto)
    height_tolerance: float = 0.0  # m below the sight line still counted visible; 0 = max(0.1, DSM cell)
    fill_dsm_gaps_m: float = 25.0  # DSM gaps inside the data's hull, up to this far from a height, interpolated
    exposure: bool = True  # per-image gain compensation in the mosaic
    # a mosaic cell every image has hidden (by the DSM: often a spike of a noisy crown) but inside an image takes
    # the image that hides it least, so the mosaic has no holes; False: such cells stay nodata
    fill_hidden: bool = True
    # edited seamlines (a GeoPackage, path[|layername=...]: polygons with an 'image' field): where a polygon names
    # an image the mosaic takes that image (where it sees the ground), automatic seams elsewhere
    seamlines_in: Optional[str] = None
    # vignetting and hot spot fitted from the overlaps and removed, seams levelled by a smooth gain field per image
    # (core.ortho.radiometry; applied only where it makes the overlaps agree better); replaces the exposure gains
    radiometry: bool = True
    hot_spot: bool = True  # with radiometry: also the sun-relative hot spot
    # the drone's shadow: around each photo's antisolar point (the sun from EXIF time and GPS, else the hot spot the
    # radiometry found) the mosaic takes another photo wherever one sees the ground (core.ortho.hotspot)
    avoid_shadow: bool = True
    avoid_relief: bool = True  # keep seamlines off buildings and trees
    seam_iterations: int = 2  # passes moving the seamlines towards where the images agree (0 = off)
    seam_alpha: float = 5.0  # weight of the view cost against the seam cost in those moves
    relief_height: float = 1.5  # m above the surroundings that makes an object seams go around
    # each image only where it resolves the ground within this factor of its best ground resolution (the far field
    # of a high oblique stays out of the mosaic and of its own orthophoto); 0 = no limit
    gsd_factor: float = 3.0
    compress: str = "DEFLATE"
    # decoded images kept in memory per tile worker (the visibility tables are memory-mapped from their files,
    # core.ortho.visibility.visibility_table): 768 MB holds toledo_2400's 57 photos
    # (13 MB each decoded); at 256 they pushed each other out (orthomosaic 308 -> 255 CPU s, tree peak 1,153 ->
    # 1,735 MiB); small photos never fill it
    cache_mb: int = 768
    workers: int = 1  # tile workers (core.parallel); 0 = one per core
    scheduler: Optional[str] = None  # Dask scheduler address

    def __post_init__(self) -> None:
        self.blending = (self.blending or "").lower()
        if isinstance(self.resolution, (int, float)):
            self.resolution = float(self.resolution)
        self.check()

    def check(self) -> None:
        if self.blending not in BLENDINGS:
            raise OrthoError(f"unknown BLENDING {self.blending!r}; choose one of {', '.join(BLENDINGS)}")
        if self.interpolation not in INTERPOLATIONS:
            raise OrthoError(f"unknown interpolation {self.interpolation!r}; choose one of {', '.join(INTERPOLATIONS)}")
        if self.resolution is None or not math.isfinite(self.resolution) or self.resolution < 0:
            raise OrthoError(f"RESOLUTION must be 0 (the ground sample distance) or a positive number of metres, "
                             f"got {self.resolution}")
        if self.gsd_factor is None or not math.isfinite(self.gsd_factor) or \
                (self.gsd_factor != 0 and self.gsd_factor < 1.0):
            raise OrthoError(f"GSD_FACTOR must be 0 (no limit) or at least 1 (each image only where its ground "
                             f"resolution is within that factor of its best), got {self.gsd_factor}")
        if self.tile < 64:
            raise OrthoError(f"tile size must be at least 64 cells, got {self.tile}")


@dataclass
class SingleImageOptions:
    """What :func:`core.ortho.single.orthorectify_image` does with one image (even one outside any block): the
    image, where the orthophoto goes, the DSM, how the image is oriented and how it is rectified.  ``ortho`` holds
    the rest (resolution, interpolation, occlusion, compression ...).  The checks that need no file run here.

    Orientation from ``gcps`` (a GCP file path or a core.io.gcp.GCPSet with observations in this image: space
    resection, >= 4 control points, >= 6 to also estimate focal length and k1) or from ``orientation`` (a file for
    :func:`core.ortho.orientation.read_orientation` or a dict with x, y, z, omega, phi, kappa; one without x..kappa
    is interior orientation only).  Automatic control (no GCP, no orientation): ``reference_ortho`` (an orthophoto
    raster) with ``dsm_path`` as the reference DSM, ``location`` (rough x, y of the ground the photo shows, in
    ``location_crs``, default the reference's CRS; None: anywhere on the reference), ``search_radius`` (how far off
    it may be) and ``control`` (a :class:`core.georef.autocontrol.single.PhotoControlOptions`, None: its
    defaults)."""

    image_path: str
    output: str  # the orthophoto (Cloud-Optimized GeoTIFF)
    dsm_path: Optional[str] = None  # required for mode "ortho" and automatic control
    gcps: Any = None  # a GCP file path or a GCPSet
    orientation: Any = None  # an orientation file path or a dict
    mode: str = "ortho"  # ortho: true orthophoto on the DSM / planar: projective, through the control points
    crs: Optional[str] = None  # working CRS; None = the GCPs', else the orientation's, else the DSM's
    focal_mm: Optional[float] = None  # with sensor_width_mm (the sensor's long side): the focal length
    sensor_width_mm: Optional[float] = None
    focal_px: Optional[float] = None
    estimate_intrinsics: Any = "auto"  # True / False / "auto" (not with a calibrated camera)
    mask_path: Optional[str] = None  # white = use
    camera: Optional[Intrinsics] = None  # a calibrated interior orientation, kept unless estimate_intrinsics
    residuals_path: Optional[str] = None  # GeoPackage of the GCP residuals
    reference_ortho: Optional[str] = None  # automatic control: the reference orthophoto
    location: Optional[Tuple[float, float]] = None  # automatic control: rough x, y of the photo's ground
    search_radius: float = 50.0  # automatic control: how far off ``location`` may be
    location_crs: Optional[str] = None  # the CRS of ``location``; None: the reference's
    control: Any = None  # automatic control: PhotoControlOptions
    ortho: OrthoOptions = field(default_factory=OrthoOptions)  # resolution (0 = the image's GSD), interpolation ...

    def __post_init__(self) -> None:
        self.mode = (self.mode or "ortho").lower()
        self.ortho.check()
        if self.mode not in MODES:
            raise OrthoError(f"unknown MODE {self.mode!r}; choose one of {', '.join(MODES)}")
        if self.gcps is None and self.orientation is None and self.reference_ortho is None:
            raise OrthoError("give ground control points observed in the image (GCPS), its orientation "
                             "(ORIENTATION), or a reference orthophoto for automatic control (REFERENCE_ORTHO)")
        if self.auto_control:
            if not self.dsm_path:
                raise OrthoError(f"automatic control against {self.reference_ortho} needs the reference DSM too: "
                                 "give DSM")
            return
        if self.mode == "ortho" and not self.dsm_path:
            raise OrthoError("a true orthophoto needs a DSM; give DSM, or choose MODE planar for flat ground")
        if self.mode == "planar" and self.gcps is None:
            raise OrthoError("planar rectification needs at least 4 ground control points observed in the image "
                             "(GCPS)")

    @property
    def auto_control(self) -> bool:
        """Whether the image is controlled automatically against ``reference_ortho`` (no GCP, no orientation)."""
        return self.reference_ortho is not None and self.gcps is None and self.orientation is None
