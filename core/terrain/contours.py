"""Contour lines of an elevation raster at a chosen interval (GDAL's contour generator) as a GeoPackage layer
with the elevation as attribute (the labels)."""
from __future__ import annotations

import math
import os

import numpy as np

from ..common.files import atomic_output, refuse_overwriting_inputs
from ..common.progress import NullProgress, Progress, check_cancel
from .options import TerrainError
from .rasters import read_elevation

LAYER = "contours"
ELEVATION_FIELD = "elevation"


CONTOUR_EXTENSIONS = (".gpkg",)


def check_contours_output(output: str) -> None:
    """TerrainError unless ``output`` names a GeoPackage (contours are written as one: a file named .shp or .tif
    holding a GeoPackage would mislead every program that opens it)."""
    ext = os.path.splitext(output)[1].lower()
    if ext not in CONTOUR_EXTENSIONS:
        raise TerrainError(f"contours are written as a GeoPackage: give an output file ending in .gpkg, not "
                           f"{ext or 'no extension'} ({output})")


def write_contours(raster_path: str, output: str, interval: float, progress: Progress = None,
                   what: str = "DTM") -> int:
    """Contours of ``raster_path`` every ``interval`` (its height units) into ``output`` (GeoPackage, layer
    'contours', fields 'id', 'elevation'); returns the number of lines."""
    from osgeo import gdal, ogr, osr

    gdal.UseExceptions()
    ogr.UseExceptions()
    progress = progress or NullProgress()
    if not (interval > 0 and math.isfinite(interval)):
        raise TerrainError(f"the contour interval must be a positive number of metres, got {interval}")
    refuse_overwriting_inputs({"contours": output}, {what: raster_path}, TerrainError)
    check_contours_output(output)
    elev = read_elevation(raster_path, what)  # the checks: projected, data, size
    zmin, zmax = float(np.nanmin(elev.z)), float(np.nanmax(elev.z))
    n_levels = (zmax - zmin) / (interval * elev.unit)
    if n_levels > 5000:
        raise TerrainError(f"a contour interval of {interval:g} gives {n_levels:.0f} levels over the "
                           f"{zmax - zmin:.1f} m of {raster_path}: choose a larger interval")
    ds = gdal.Open(raster_path)
    band = ds.GetRasterBand(1)
    srs = osr.SpatialReference(wkt=elev.crs_wkt) if elev.crs_wkt else None
    os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    with atomic_output(output) as tmp:
        out = ogr.GetDriverByName("GPKG").CreateDataSource(tmp)
        lyr = out.CreateLayer(LAYER, srs, ogr.wkbLineString25D)
        lyr.CreateField(ogr.FieldDefn("id", ogr.OFTInteger))
        lyr.CreateField(ogr.FieldDefn(ELEVATION_FIELD, ogr.OFTReal))
        opts = [f"LEVEL_INTERVAL={interval:g}", "ID_FIELD=0", "ELEV_FIELD=1"]  # field indices
        nd = band.GetNoDataValue()
        if nd is not None:
            opts.append(f"NODATA={nd:g}")

        def cb(fraction, _msg, _data):
            progress.report(fraction, "contours")
            return 0 if progress.is_cancelled() else 1

        try:
            gdal.ContourGenerateEx(band, lyr, options=opts, callback=cb)
        except RuntimeError as e:
            check_cancel(progress)
            raise TerrainError(f"cannot make contours of {raster_path}: {e}") from e
        n = lyr.GetFeatureCount()
        out = None
    ds = None
    return n
