"""The options of the automatic control (``core.georef.autocontrol``): defaults in one place."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Optional, Sequence

from ...io.gcp import CameraPosition, GCPSet
from ..options import GeorefOptions

AUTO = "auto"  # the role of an automatic GCP candidate in georef/autocontrol.json
# where the block is first placed: EXIF GPS when 2 photos carry it (else none), the GPS, or a search over rotations
PRIOR_AUTO, PRIOR_GPS, PRIOR_NONE = "auto", "gps", "none"


@dataclass
class AutoControlOptions:
    """``gsd``: the common ground resolution of the match (None: the coarser of the reference's and the photos');
    ``max_pixels``: the provisional orthophoto's largest side (the resolution is made coarser beyond it);
    ``ratio``: Lowe's ratio test; ``ransac_px``: the similarity's inlier distance (common-grid pixels);
    ``tile_px``, ``tile_ransac_px``: the per-tile affine refinement (a block that spans fewer pixels of
    the common grid than one tile is refused before the match: too coarse a reference for a block this small); ``max_candidates``: matches tied back to
    the photos (the best of a grid over the block); ``search_px``: how far a point is searched in the other
    photos around its prediction through the model; ``min_score``: their normalised cross-correlation;
    ``ground_plane``: the patches compared through the ground's plane (else the plane facing the first photo);
    ``dsm_sigma``: the DSM's own height noise in a point's sigma Z, in its units (None: a third of the DSM's cell
    size, as the height comes from a plane through 3 x 3 samples); the plane's slope and misfit (walls, trees,
    roof edges, houses within a coarse DEM's cell) are added to it: a weight, never a rejection
    (``candidates.height_sigma``); ``rotations``:
    degrees tried when there is no prior (the features are rotation invariant; these help at a coarse level), until
    one gives ``coarse_enough`` inliers; ``coarse_pixels``: the provisional orthophoto's side at that level;
    ``refine_intrinsics``: what the adjustment refines of the cameras (as ``GeorefOptions``): by default focal
    length and distortion, which dozens of automatic GCPs over the block determine (on Toledo's FC300X photos the
    camera centres' median error falls from 1.75 m to 0.85 m).

    The inputs of ``autocontrol_workspace``: ``reference_ortho``, ``reference_dsm``: the reference orthophoto and
    DSM files; ``prior``: "auto" (EXIF GPS when 2 photos carry it, else none), "gps", or "none" (search rotation
    and scale); ``control``: the ground control given beside the reference, as ``GeorefOptions`` holds it (a GCP
    file ``gcp_path`` or a set ``gcps``, ``check_points`` names, ``camera_positions_path``, ``gcps_upright``):
    read and checked in the reference's CRS by the georeference stage's own reader
    (``core.georef.control_checks.read_checked_control``: positions far from the photos' GPS, swapped axes,
    duplicate rows), before the matching; its points become check points, its camera positions the rough
    position; ``camera_positions``: rough positions already in the reference's CRS instead of EXIF GPS;
    ``check_points``: ground points evaluated as check points (role check; taken from their set's CRS into the
    reference's); ``georef``: the adjustment's options (its ``refine_intrinsics`` replaces
    ``refine_intrinsics``)."""

    gsd: Optional[float] = None
    max_pixels: int = 3000
    n_features: int = 10000
    ratio: float = 0.85
    ransac_px: float = 4.0
    tile_px: int = 192
    tile_ransac_px: float = 1.5
    min_tile_matches: int = 6
    max_candidates: int = 120
    search_px: float = 25.0
    template_half: int = 15
    min_score: float = 0.7
    ground_plane: bool = True
    max_triangulation_px: float = 2.0
    dsm_sigma: Optional[float] = None
    min_candidates: int = 4
    rotations: tuple = (0.0, 90.0, 180.0, 270.0)
    coarse_pixels: int = 1000
    coarse_enough: int = 150
    refine_intrinsics: Any = True
    reference_ortho: Optional[str] = None
    reference_dsm: Optional[str] = None
    prior: str = PRIOR_AUTO
    camera_positions: Optional[Sequence[CameraPosition]] = None
    check_points: Optional[GCPSet] = None
    control: Optional[GeorefOptions] = None
    georef: Optional[GeorefOptions] = None

    @classmethod
    def of(cls, options: Optional["AutoControlOptions"] = None, **kwargs: Any) -> "AutoControlOptions":
        base = options if options is not None else cls()
        return dataclasses.replace(base, **kwargs) if kwargs else base


__all__ = ["AUTO", "PRIOR_AUTO", "PRIOR_GPS", "PRIOR_NONE", "AutoControlOptions"]
