"""A reference degraded as a national one: resampled (average) to a national product's cell size and warped into
a transverse Mercator CRS that has no EPSG code (as many national grids are written in a raster: a WKT of
parameters, no authority), e.g. Toledo's FC350 orthophoto at 0.6 m as NAIP and its DSM at 10 m as 3DEP.

``national_wkt(lon, lat)``: such a CRS centred near (lon, lat) (WGS 84 datum, so that no datum shift enters a
comparison with UTM; false easting / northing unlike any UTM zone's); ``degrade(src, dst, res, wkt)``: the warp.
Used by tests/test_autocontrol_national.py and benchmarks/autocontrol_national.py.
"""
import math
import os

NAME = "ArchaeoOrtho test national grid (transverse Mercator)"


def national_wkt(lon: float, lat: float) -> str:
    """WKT of a transverse Mercator CRS with no EPSG code, its central meridian on the half degree west of
    ``lon`` (so the block is not on it) and its origin at ``lat`` rounded down; GDAL's AutoIdentifyEPSG fails on
    it ("Unsupported SRS") and its FindMatches finds nothing above 25 % confidence."""
    from osgeo import osr

    lon0 = math.floor(lon * 2.0) / 2.0
    lat0 = float(math.floor(lat))
    srs = osr.SpatialReference()
    srs.SetFromUserInput(f"+proj=tmerc +lat_0={lat0:g} +lon_0={lon0:g} +k=0.9999 +x_0=300000 +y_0=150000 "
                         "+datum=WGS84 +units=m +no_defs")
    srs.SetProjCS(NAME)
    return srs.ExportToWkt()


def has_no_epsg(wkt: str) -> bool:
    """True when GDAL finds no EPSG code for ``wkt`` (AutoIdentifyEPSG fails or leaves none)."""
    from osgeo import osr

    srs = osr.SpatialReference(wkt=wkt)
    try:
        failed = srs.AutoIdentifyEPSG() != 0
    except RuntimeError:  # "OGR Error: Unsupported SRS" with exceptions on
        failed = True
    return failed and not srs.GetAuthorityCode(None)


def degrade(src: str, dst: str, res: float, wkt: str) -> str:
    """``src`` warped into ``wkt`` at ``res`` CRS units per pixel, cells averaged (as a national product is made
    from finer data); nodata and alpha carried; written as a tiled GeoTIFF.  Returns ``dst``."""
    from osgeo import gdal

    gdal.UseExceptions()
    ds = gdal.Open(src)
    band = ds.GetRasterBand(1)
    nodata = band.GetNoDataValue()
    float_data = band.DataType in (gdal.GDT_Float32, gdal.GDT_Float64)
    os.makedirs(os.path.dirname(os.path.abspath(dst)), exist_ok=True)
    kw = dict(dstSRS=wkt, xRes=res, yRes=res, targetAlignedPixels=True, resampleAlg="average",
              creationOptions=["TILED=YES", "COMPRESS=DEFLATE"], multithread=False)
    if float_data:
        kw.update(srcNodata=nodata, dstNodata=nodata if nodata is not None else -9999.0)
    elif ds.RasterCount in (1, 3):  # an opaque colour / grey image: mark what lies outside it
        kw.update(dstAlpha=True)
    out = gdal.Warp(dst, ds, **kw)
    if out is None:
        raise RuntimeError(f"cannot warp {src} to {res:g} m in the national CRS")
    out.FlushCache()
    return dst


__all__ = ["NAME", "degrade", "has_no_epsg", "national_wkt"]
