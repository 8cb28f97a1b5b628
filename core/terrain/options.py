"""The options of the terrain stage (DTM, relief visualisations, contours): defaults in this one place, and its
error."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

from ..common.errors import ArchaeoOrthoError
from ..io import raster

# the relief visualisations (Processing enum order; file name = key)
VISUALISATIONS: Tuple[Tuple[str, str], ...] = (
    ("svf", "Sky-view factor"),
    ("openness_pos", "Openness (positive)"),
    ("openness_neg", "Openness (negative)"),
    ("slrm", "Simple local relief model"),
    ("msrm", "Multi-scale relief model"),
    ("mhs", "Multi-direction hillshade"),
    ("ld", "Local dominance"),
    ("vat", "VAT (visualisation for archaeological topography, blend)"),
)
VISUALISATION_KEYS = tuple(k for k, _ in VISUALISATIONS)

# measured ground / interpolated: the values of the DTM's source raster (terrain/dtm-source.tif), the DSM's
SOURCE_MEASURED = raster.SOURCE_MEASURED
SOURCE_INTERPOLATED = raster.SOURCE_INTERPOLATED


TILE_CELLS = 1024  # the side of the tiles the terrain products are computed and written by (memory, not result)


class TerrainError(ArchaeoOrthoError, RuntimeError):
    """The DTM, a relief visualisation or contours cannot be made from this raster; the message names the file
    and the problem."""


@dataclass
class GroundOptions:
    """The ground filter: SMRF (Pingel, Clarke & McBride 2013, the algorithm of PDAL's filters.smrf) on the DSM grid.

    Defaults are PDAL's filters.smrf defaults (slope 0.15, window 18 m, threshold 0.5 m, scalar 1.25); the
    filter grid is the DSM's, coarsened to ``filter_cell`` for the morphological opening only."""

    slope: float = 0.15  # rise over run: a terrain steeper than this between two window sizes is an object
    window: float = 18.0  # m, the largest opening radius (the half-size of the largest building to remove)
    threshold: float = 0.5  # m above the provisional ground surface: object
    scalar: float = 1.25  # threshold grows by scalar x the local slope of the provisional surface
    filter_cell: float = 0.5  # m, the grid of the morphological opening (finer DSMs are reduced to it)
    dilate: float = 0.0  # m, objects grown by this much (0 = one DSM cell: the blurred foot of a wall)
    skirt: float = 2.0  # m around the objects where the provisional surface is interpolated (blurred walls)
    tile: int = TILE_CELLS  # cells: the side of the tiles the full-resolution steps run by (memory; same result)


@dataclass
class ReliefOptions:
    """RVT's default parameters (rvt.default.DefaultValues, given in cells of a 1 m DEM), converted to metres
    and back to cells of the actual DEM: a radius of 10 cells at 1 m is 10 m, i.e. 100 cells at 0.1 m; capped at
    ``max_radius_cells`` (the run time grows with the radius)."""

    reference_cell: float = 1.0  # m: the cell size RVT's defaults are given for
    svf_directions: int = 16
    svf_radius: float = 10.0  # reference cells
    svf_noise: int = 0
    slrm_radius: float = 20.0
    msrm_feature_min: float = 0.0  # m (RVT: 0 .. 20 m, scaling factor 2)
    msrm_feature_max: float = 20.0
    msrm_scaling: int = 2
    hs_sun_elevation: float = 35.0
    mhs_directions: int = 16
    ld_min_radius: float = 10.0
    ld_max_radius: float = 20.0
    ld_observer_height: float = 1.7  # m
    max_radius_cells: int = 120
    vertical_exaggeration: float = 1.0
    tile: int = 2 * TILE_CELLS  # cells: the least side of the tiles a visualisation is computed by (memory)


@dataclass
class TerrainOptions:
    """The terrain stage (Build DTM) of a workspace: the ground filter, contours, whether the DSM stage's point
    cloud is classified, and the files that replace the workspace's (a DSM to read, where the DTM goes, a copy of
    the contours)."""

    ground: GroundOptions = None  # type: ignore[assignment]
    contour_interval: float = 0.0  # m; 0 = no contours
    classify_point_cloud: bool = True
    dsm: Optional[str] = None  # a DSM file instead of the workspace's
    output_dtm: Optional[str] = None  # the DTM there instead of <workspace>/dtm.tif
    contours_copy: Optional[str] = None  # a copy of the contours there (a .gpkg)

    def __post_init__(self):
        if self.ground is None:
            self.ground = GroundOptions()
        if not (self.contour_interval >= 0 and math.isfinite(self.contour_interval)):
            raise TerrainError(f"the contour interval must be 0 (no contours) or a positive number of metres, got "
                               f"{self.contour_interval}")


@dataclass
class ReliefStageOptions:
    """The relief stage of a workspace: the visualisations ``keys`` (:data:`VISUALISATION_KEYS`) of its DTM or DSM
    (``source``), RVT's parameters, and a copy of the one visualisation at ``copy_to``."""

    keys: Sequence[str]
    source: str = "dtm"  # dtm / dsm
    relief: ReliefOptions = None  # type: ignore[assignment]
    copy_to: Optional[str] = None

    def __post_init__(self):
        if self.relief is None:
            self.relief = ReliefOptions()
        if self.source not in ("dtm", "dsm"):
            raise TerrainError(f"relief source must be 'dtm' or 'dsm', got {self.source!r}")
        if self.copy_to and len(self.keys) != 1:
            raise TerrainError("a copy of the relief visualisation needs exactly one visualisation")
