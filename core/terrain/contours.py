"""Contour lines of an elevation raster at a chosen interval (GDAL's contour generator) as a GeoPackage layer
with the elevation as attribute (the labels)."""
from __future__ import annotations

import math
import os

from ..common.files import atomic_output, refuse_overwriting_inputs
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.raster import RasterFile
from .options import TerrainError
from .rasters import read_elevation, scan

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
    """Contours of ``raster_path`` every ``interval`` metres into ``output`` (GeoPackage, layer 'contours', fields
    'id', 'elevation' in metres); returns the number of lines.  A raster whose CRS is in feet has its heights in
    feet: the interval is converted (1 m, not 1 ft), and so is the elevation field (the lines' own Z stays the
    raster's)."""
    from osgeo import gdal, ogr, osr

    gdal.UseExceptions()
    ogr.UseExceptions()
    progress = progress or NullProgress()
    if not (interval > 0 and math.isfinite(interval)):
        raise TerrainError(f"the contour interval must be a positive number of metres, got {interval}")
    refuse_overwriting_inputs({"contours": output}, {what: raster_path}, TerrainError)
    check_contours_output(output)
    elev = read_elevation(raster_path, what, whole=False)  # the checks: projected, size; then by tiles: data
    _n, zmin, zmax = scan(elev, what)
    n_levels = (zmax - zmin) / interval  # elev.z is in metres
    if n_levels > 5000:
        raise TerrainError(f"a contour interval of {interval:g} gives {n_levels:.0f} levels over the "
                           f"{zmax - zmin:.1f} m of {raster_path}: choose a larger interval")
    srs = osr.SpatialReference(wkt=elev.crs_wkt) if elev.crs_wkt else None
    os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    with RasterFile(raster_path, f"the {what}") as src, atomic_output(output) as tmp:
        band = src.band(1)
        out = ogr.GetDriverByName("GPKG").CreateDataSource(tmp)
        lyr = out.CreateLayer(LAYER, srs, ogr.wkbLineString25D)
        lyr.CreateField(ogr.FieldDefn("id", ogr.OFTInteger))
        lyr.CreateField(ogr.FieldDefn(ELEVATION_FIELD, ogr.OFTReal))
        # field indices; the interval in the raster's own height units
        opts = [f"LEVEL_INTERVAL={interval / elev.unit!r}", "ID_FIELD=0", "ELEV_FIELD=1"]
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
        if elev.unit != 1.0:
            _elevations_in_metres(out, lyr, elev.unit)
        out = band = None
    return n


def _elevations_in_metres(ds, lyr, unit: float) -> None:
    """The elevation field of every contour times ``unit`` (metres per height unit of the raster), rounded to the
    millimetre so that a 1 m interval reads 1, 2, 3."""
    ds.StartTransaction()
    lyr.ResetReading()
    for f in lyr:
        f.SetField(ELEVATION_FIELD, round(f.GetFieldAsDouble(ELEVATION_FIELD) * unit, 3))
        lyr.SetFeature(f)
    ds.CommitTransaction()
