"""The georeference stage's adjustments: the block adjusted on its ground control (:func:`adjust_block`), and
with a reference DEM (``GeorefOptions.reference_dem``) co-registered on it and adjusted again with DEM control
points (:func:`adjust_on_dem`, core.georef.demcontrol)."""
from __future__ import annotations

from typing import List, Optional, Sequence

from ..common.errors import ArchaeoOrthoError
from ..common.progress import Progress, SubProgress
from ..io import gcp as gcpmod
from . import demcontrol as demmod
from .adjust import georeference
from .coregister import CoregError
from .options import GeorefOptions
from .products import figures
from .results import GeorefResult


def adjust_block(rec, gcps: Optional[gcpmod.GCPSet], cams: Sequence[gcpmod.CameraPosition], opt: GeorefOptions,
                 progress: Progress) -> GeorefResult:
    """The adjustment (core.georef.adjust.georeference) of the aligned model ``rec`` on the ground control; the
    GCP file's warnings reach the user when it fails too."""
    try:
        return georeference(rec, gcps, list(cams) or None, progress=progress, options=opt)
    except ArchaeoOrthoError:  # the GCP file's warnings reach the user in this outcome too
        for w in gcps.warnings if gcps is not None else []:
            progress.warning(w)
        raise


def adjust_on_dem(rec, first: GeorefResult, gcps: Optional[gcpmod.GCPSet], cams: List[gcpmod.CameraPosition],
                  opt: GeorefOptions, progress: Progress):
    """The adjusted block co-registered on the reference DEM and adjusted again with DEM control points:
    (result, ground control, camera positions, DemControl); ``opt.crs`` is the target CRS."""
    target = opt.crs
    placeholder = first.statistics.get("placeholder_z") is not None
    ctl = first.rmse(gcpmod.CONTROL)
    control = ((float(ctl["z"]), int(ctl["n"])) if demmod.has_height_control(gcps) and not placeholder and ctl["n"]
               and ctl["z"] is not None else None)
    dc = demmod.dem_control(first.reconstruction, first.offset, opt, control=control,
                            taken=[p.name for p in gcps.points] if gcps is not None else (),
                            progress=SubProgress(progress, 0.45, 0.5))
    for m in dc.messages:
        progress.info(m)
    gcps2, cams2 = demmod.with_dem_control(gcps, cams, dc)
    try:
        result = adjust_block(rec, gcps2, cams2, opt, SubProgress(progress, 0.5, 0.9))
    except ArchaeoOrthoError as e:  # say which adjustment failed: the block adjusted without them was fine
        raise demmod.DemControlError(f"the adjustment with the {len(dc.points)} DEM control points from "
                                     f"{opt.reference_dem} failed: {e}") from e
    try:
        dc.after = demmod.coregister_block(result.reconstruction, result.offset, opt.reference_dem, target)[0]
    except CoregError as e:
        progress.warning(f"the block adjusted with the DEM control could not be co-registered again: {e}")
    for m in demmod.after_messages(dc, figures(first), figures(result)):
        progress.info(m)
    warning = demmod.after_warning(dc)
    if warning:
        result.warnings.append(warning)
        progress.warning(warning)
    return result, gcps2, cams2, dc


__all__ = ["adjust_block", "adjust_on_dem"]
