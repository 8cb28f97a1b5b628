"""The options of the georeferencing (``core.georef.adjust.georeference``) and of its stage: defaults in one place."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Dict, Optional, Sequence, Tuple

from ..io.gcp import GCPSet
from ..io.images import EXIF_GPS_SIGMA_XY

INTRINSIC_GROUPS = ("focal", "principal_point", "extra")

EXIF_SIGMA_XY = EXIF_GPS_SIGMA_XY  # m: consumer GNSS in EXIF, the a priori sigmas of EXIF GPS camera positions
EXIF_SIGMA_Z = 5.0
FILE_POSITION_SIGMAS = (5.0, 10.0)  # m: a positions file's sigmas when the workspace did not save them
PLACEHOLDER_SIGMA_Z = 1.0  # m: sigma Z of control points whose heights are all the same placeholder
# a camera the alignment recorded as "refined" (a calibration given with its sigmas, core.align.calibrated) is refined
# with a prior on each parameter at its given value; where the calibration gives no sigma for a parameter:
REFINED_FOCAL_SIGMA = 0.01  # relative to the focal length (1 %)
REFINED_PP_SIGMA = 0.005  # relative to the image's long side (0.5 %: 5 px on a 1000 px photo)
REFINED_RADIAL_SIGMA = 0.02  # k1, k2, k3 ... (normalised image coordinates)
REFINED_TANGENTIAL_SIGMA = 0.002  # p1, p2


@dataclass
class GeorefOptions:
    """How ``georeference`` adjusts a block (see its docstring for each option's meaning).

    ``refine_intrinsics``: False; True (focal + distortion); "all" (also the principal point); or a subset of
    ("focal", "principal_point", "extra").  ``outlier_threshold``: pixels; ``outlier_sigma``: normalised
    coordinate residual; ``helmert_threshold``: metres (None: from the point spread and sigmas).
    ``focal_prior``: where the focal length is refined, the standard deviation of a prior on it at the
    alignment's value, relative to that value (0.01: 1 %; 0: none).
    ``camera_intrinsics``: camera id -> what the alignment recorded of its interior orientation
    (core.project.layout.Layout.camera_intrinsics; None: read from the workspace by the stage, {}: none): a
    ``fixed`` camera is never refined, whatever ``refine_intrinsics`` says; a ``refined`` one is refined (every
    parameter) with priors at its given values weighted by its given sigmas (REFINED_*_SIGMA where the
    calibration gives none); an ``estimated`` one follows ``refine_intrinsics`` and ``focal_prior``.

    ``reference_dem``: a reference DEM file (any projected CRS, heights in metres or feet): the georeference stage
    co-registers the adjusted block's sparse points on it and adjusts again with up to ``reference_dem_points`` DEM
    control points (core.georef.demcontrol); ``reference_dem_sigma_z``: the reference's stated height accuracy
    (metres, 0: unknown), added to their sigma Z.  The adjustment itself (``georeference``) ignores these.

    ``drop_suspect_control``: control points the consistency check names as suspect (they disagree with the
    others through the block) are dropped before the adjustment, not only named in a warning; the automatic
    control sets it (its points are many and a suspect one is a wrong match far more often than a sign of a
    deformed block: 4 of 101 flagged, the worst 1.54 m off, were kept and bent the block before).

    The georeference stage's inputs (``core.georef.stage.georeference_workspace``; the adjustment ignores them):
    ``gcp_path``: a GCP file (core.io.gcp.read_gcps), else ``gcps``: a ``core.io.gcp.GCPSet``; ``check_points``:
    names of GCPs evaluated as check points; ``camera_positions_path``: a camera positions file, else
    ``use_exif_gps``: the photos' EXIF GPS as camera positions; ``gcps_upright``: the GCP pixel coordinates were
    measured on the photos shown upright (EXIF orientation applied), not in the stored grid.  ``crs``: the target
    CRS (None: the GCPs', the workspace's, the positions', else the UTM zone of the photos' GPS)."""

    refine_intrinsics: Any = False
    outlier_threshold: float = 5.0
    outlier_sigma: float = 5.0
    helmert_threshold: Optional[float] = None
    gcp_pixel_sigma: float = 1.0
    tie_pixel_sigma: float = 1.0
    huber_px: float = 2.0
    max_observations: int = 200_000
    max_iterations: int = 50
    max_outlier_rounds: int = 10
    min_intrinsics_images: int = 3
    adjust: bool = True
    crs: Optional[str] = None
    copy_model: bool = True
    placeholder_sigma_z: float = PLACEHOLDER_SIGMA_Z
    focal_prior: float = 0.01
    camera_intrinsics: Optional[Dict[int, Dict[str, Any]]] = None
    reference_dem: Optional[str] = None
    reference_dem_points: int = 25
    reference_dem_sigma_z: float = 0.0
    drop_suspect_control: bool = False
    gcp_path: Optional[str] = None
    gcps: Optional[GCPSet] = None
    check_points: Sequence[str] = ()
    camera_positions_path: Optional[str] = None
    use_exif_gps: bool = False
    gcps_upright: bool = False

    def __post_init__(self) -> None:
        """GeorefError naming the option for a value out of its range or choices (before any work)."""
        from .errors import GeorefError

        try:
            self.intrinsic_groups()
        except ValueError as e:
            raise GeorefError(str(e)) from e
        positive = ("outlier_threshold", "outlier_sigma", "gcp_pixel_sigma", "tie_pixel_sigma", "huber_px",
                    "max_observations", "max_iterations", "placeholder_sigma_z", "reference_dem_points")
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise GeorefError(f"GeorefOptions.{name} must be a positive number, not {value!r}")
        for name in ("focal_prior", "reference_dem_sigma_z", "max_outlier_rounds"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise GeorefError(f"GeorefOptions.{name} must be zero or a positive number, not {value!r}")
        if self.helmert_threshold is not None and not (math.isfinite(self.helmert_threshold)
                                                       and self.helmert_threshold > 0):
            raise GeorefError(f"GeorefOptions.helmert_threshold must be a positive distance or None, not "
                              f"{self.helmert_threshold!r}")
        if isinstance(self.check_points, str):  # one name given as a string would be taken letter by letter
            self.check_points = tuple(n.strip() for n in self.check_points.split(",") if n.strip())

    @classmethod
    def of(cls, options: Optional["GeorefOptions"] = None, **kwargs: Any) -> "GeorefOptions":
        """``options`` (or the defaults) with the keyword options given one by one replacing its fields;
        TypeError for a keyword that is not an option."""
        base = options if options is not None else cls()
        names = {f.name for f in dataclasses.fields(cls)}
        bad = sorted(k for k in kwargs if k not in names)
        if bad:
            raise TypeError(f"georeference() got unexpected keyword argument(s): {', '.join(bad)}")
        return dataclasses.replace(base, **kwargs) if kwargs else base

    def intrinsic_groups(self) -> Tuple[str, ...]:
        """The groups of intrinsic parameters to refine (ValueError for an unknown group)."""
        refine = self.refine_intrinsics
        if not refine:
            return ()
        if refine is True:
            return ("focal", "extra")
        if isinstance(refine, str):
            refine = ("focal", "principal_point", "extra") if refine == "all" else (refine,)
        groups = tuple(refine)
        bad = [g for g in groups if g not in INTRINSIC_GROUPS]
        if bad:
            raise ValueError(f"refine_intrinsics: unknown group(s) {bad}; use True, 'all' or a subset of "
                             f"{INTRINSIC_GROUPS}")
        return groups


__all__ = ["EXIF_SIGMA_XY", "EXIF_SIGMA_Z", "FILE_POSITION_SIGMAS", "GeorefOptions", "INTRINSIC_GROUPS",
           "PLACEHOLDER_SIGMA_Z", "REFINED_FOCAL_SIGMA", "REFINED_PP_SIGMA", "REFINED_RADIAL_SIGMA",
           "REFINED_TANGENTIAL_SIGMA"]
