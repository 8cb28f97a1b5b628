"""The terrain products of an elevation raster on files (the stages of :mod:`.stage` call them on a workspace):

- :func:`build_dtm`: the ground filter (:mod:`.ground`, SMRF) -> the DTM, a COG on the DSM's exact grid, with its
  source raster beside it (1 = measured ground, 2 = interpolated under a removed object or in a hole of the DSM);
  a LAS point cloud copied with ASPRS classes 2 (ground) / 1 (unclassified); contours at ``contour_interval``
  (GeoPackage, :func:`.contours.write_contours`).
- :func:`relief`: rvt-py's visualisations (:mod:`.relief`) as COGs.

Any raster input is checked first (:func:`.rasters.read_elevation`): a geographic CRS (degrees), a raster under
16 x 16 cells and one without data are refused, naming the file.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field, replace
from typing import Dict, List, Optional, Sequence, Union

import numpy as np

from ..common.files import refuse_overwriting_inputs
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io.raster import BandLabel
from . import relief as rv
from .classify import classify_las
from .contours import check_contours_output, write_contours
from .ground import filter_ground
from .options import (
    SOURCE_INTERPOLATED,
    SOURCE_MEASURED,
    VISUALISATION_KEYS,
    GroundOptions,
    ReliefOptions,
    TerrainError,
)
from .rasters import check_data, read_elevation, scan, write_classes, write_float_tiles


@dataclass
class DtmResult:
    dtm_path: str
    source_path: str
    dsm_path: str
    cell: float
    ground_fraction: float  # of the DSM's valid cells
    interpolated_fraction: float  # of the DTM's cells
    contours_path: Optional[str] = None
    contour_lines: int = 0
    point_cloud_path: Optional[str] = None
    points: int = 0
    ground_points: int = 0
    workspace: Optional[str] = None
    timings: Dict[str, float] = field(default_factory=dict)
    log_lines: List[str] = field(default_factory=list)


@dataclass
class ReliefResult:
    paths: Dict[str, str]  # visualisation key -> file
    source_path: str
    cell: float
    radii: Dict[str, int]
    workspace: Optional[str] = None
    timings: Dict[str, float] = field(default_factory=dict)


@dataclass
class DtmOutputs:
    """Where the DTM products of a DSM go: the DTM; its source raster (``<dtm>-source.tif`` by default); the contours
    (``<dtm>-contours.gpkg`` by default, made when there is a contour interval); the classified point cloud (made
    when there is a point cloud to classify and this path)."""

    dtm: str
    source: Optional[str] = None
    contours: Optional[str] = None
    classified_point_cloud: Optional[str] = None


def build_dtm(dsm_path: str, outputs: Union[str, DtmOutputs], options: Optional[GroundOptions] = None,
              contour_interval: float = 0.0, point_cloud: Optional[str] = None,
              progress: Optional[Progress] = None) -> DtmResult:
    """The DTM of the DSM ``dsm_path`` (any projected elevation raster) on its grid, to ``outputs`` (the DTM's path,
    or :class:`DtmOutputs`); contours every ``contour_interval`` metres (0: none); the LAS ``point_cloud``
    classified (ground / unclassified) where ``outputs`` names where."""
    progress = progress or NullProgress()
    options = options or GroundOptions()
    outputs = DtmOutputs(outputs) if isinstance(outputs, str) else outputs
    t0 = time.time()
    output_dtm = outputs.dtm
    source_path = outputs.source or os.path.splitext(output_dtm)[0] + "-source.tif"
    contours_path = None
    if contour_interval and contour_interval > 0:
        contours_path = outputs.contours or os.path.splitext(output_dtm)[0] + "-contours.gpkg"
    classified_point_cloud = outputs.classified_point_cloud
    refuse_overwriting_inputs(
        {"DTM": output_dtm, "DTM source raster": source_path, "contours": contours_path,
         "classified point cloud": classified_point_cloud if point_cloud else None},
        {"DSM": dsm_path, "point cloud": point_cloud}, TerrainError)
    if contour_interval and contour_interval > 0:
        check_contours_output(contours_path)
    elev = read_elevation(dsm_path, "DSM", whole=False)  # read by tiles
    h, w = elev.shape
    res = filter_ground(elev, elev.cell, options, SubProgress(progress, 0.0, 0.8),
                        check_data=lambda n: check_data(dsm_path, "DSM", n, w, h))
    timings = {"ground_filter": time.time() - t0}
    check_cancel(progress)
    ground_fraction = float(np.count_nonzero(res.ground) / max(res.valid_cells, 1))
    interpolated = float(np.count_nonzero(res.source == SOURCE_INTERPOLATED) / max(np.count_nonzero(res.source), 1))
    meta = {"ARCHAEOORTHO_STAGE": "terrain", "ARCHAEOORTHO_PRODUCT": "dtm", "GROUND_FILTER": "SMRF",
            "SMRF_SLOPE": options.slope, "SMRF_WINDOW_M": options.window, "SMRF_THRESHOLD_M": options.threshold,
            "SMRF_SCALAR": options.scalar, "SOURCE_DSM": os.path.abspath(dsm_path),
            "GROUND_FRACTION": f"{ground_fraction:.4f}"}
    write_float_tiles(output_dtm, lambda r0, r1, c0, c1: res.dtm[r0:r1, c0:c1], elev,
                      BandLabel("DTM (bare earth)", metadata=meta), tile=options.tile,
                      progress=SubProgress(progress, 0.8, 0.88))
    write_classes(source_path, res.source, elev, "DTM source: 1 measured ground, 2 interpolated",
                  {"ARCHAEOORTHO_PRODUCT": "dtm-source", "VALUES": f"{SOURCE_MEASURED}=measured ground, "
                   f"{SOURCE_INTERPOLATED}=interpolated"}, tile=options.tile)
    out = DtmResult(dtm_path=output_dtm, source_path=source_path, dsm_path=dsm_path, cell=elev.cell,
                    ground_fraction=ground_fraction, interpolated_fraction=interpolated, timings=timings)
    out.log_lines.append(f"DTM {elev.shape[1]} x {elev.shape[0]} cells at {elev.cell:g} m: {ground_fraction:.1%} of "
                         f"the DSM's cells ground, {interpolated:.1%} of the DTM interpolated -> {output_dtm}")
    if point_cloud and classified_point_cloud:
        t1 = time.time()
        dtm_elev = replace(elev, path=output_dtm, z=res.dtm)  # the DTM as written (float32, metres)
        out.points, out.ground_points = classify_las(point_cloud, classified_point_cloud, dtm_elev, res.source,
                                                     options.threshold)
        out.point_cloud_path = classified_point_cloud
        timings["classify_points"] = time.time() - t1
        out.log_lines.append(f"point cloud: {out.ground_points} of {out.points} points ground (ASPRS class 2) -> "
                             f"{classified_point_cloud}")
    if contour_interval and contour_interval > 0:
        t1 = time.time()
        out.contours_path = contours_path
        out.contour_lines = write_contours(output_dtm, out.contours_path, contour_interval,
                                           SubProgress(progress, 0.9, 1.0))
        timings["contours"] = time.time() - t1
        out.log_lines.append(f"contours every {contour_interval:g} m: {out.contour_lines} lines -> {out.contours_path}")
    for line in out.log_lines:
        progress.info(line)
    timings["total"] = time.time() - t0
    out.timings = {k: round(v, 3) for k, v in timings.items()}
    return out


def relief(dem_path: str, keys: Sequence[str], output_dir: str, prefix: str = "dtm",
           options: Optional[ReliefOptions] = None, progress: Optional[Progress] = None,
           what: str = "DTM", outputs: Optional[Dict[str, str]] = None) -> ReliefResult:
    """The visualisations ``keys`` of the elevation raster ``dem_path`` as ``<output_dir>/<prefix>-<key>.tif``
    (or at ``outputs[key]``)."""
    progress = progress or NullProgress()
    options = options or ReliefOptions()
    bad = [k for k in keys if k not in VISUALISATION_KEYS]
    if bad or not keys:
        raise TerrainError(f"unknown relief visualisation(s) {bad or keys}: choose from {', '.join(VISUALISATION_KEYS)}")
    targets = {key: (outputs or {}).get(key) or os.path.join(output_dir, f"{prefix}-{key}.tif") for key in keys}
    refuse_overwriting_inputs({f"{key} visualisation": path for key, path in targets.items()}, {what: dem_path},
                              TerrainError)
    elev = read_elevation(dem_path, what, whole=False)  # read by tiles
    scan(elev, what)  # the data check by the default tiles: the visualisations' tiles may be far smaller
    paths, timings = {}, {}
    for i, key in enumerate(keys):
        t0 = time.time()
        sub = SubProgress(progress, i / len(keys), (i + 1) / len(keys))
        sub.report(0.0, f"relief visualisation: {key}")
        path = targets[key]
        lo, hi = rv.DISPLAY_RANGE[key]
        meta = {"ARCHAEOORTHO_STAGE": "relief", "ARCHAEOORTHO_PRODUCT": f"relief-{key}", "RELIEF": key,
                "DISPLAY_MIN": lo, "DISPLAY_MAX": hi, "SOURCE": os.path.abspath(dem_path),
                "RVT_REFERENCE_CELL_M": options.reference_cell}
        write_float_tiles(path, rv.tiled(key, elev, options, sub), elev,
                          BandLabel(f"{key} ({rv.UNITS[key]})", metadata=meta), heights=False,
                          tile=rv.tile_cells(key, elev.cell, options))
        paths[key] = path
        timings[key] = round(time.time() - t0, 3)
        progress.info(f"{key}: {path} ({timings[key]:.1f} s)")
    radii = {"svf": rv.cells(options, options.svf_radius, elev.cell, lo=3),
             "slrm": rv.cells(options, options.slrm_radius, elev.cell, cap=False, lo=2),
             "ld_max": rv.cells(options, options.ld_max_radius, elev.cell, lo=3)}
    return ReliefResult(paths=paths, source_path=dem_path, cell=elev.cell, radii=radii, timings=timings)


__all__ = ["build_dtm", "relief", "DtmOutputs", "DtmResult", "ReliefResult"]
