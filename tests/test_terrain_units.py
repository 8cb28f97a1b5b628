"""Heights in feet (issue 36 item 4): contours asked every metre of a DSM in a CRS in US survey feet are drawn every
metre (were every foot), and their elevation field is in metres."""
from __future__ import annotations

import numpy as np
from osgeo import gdal, ogr, osr

from core.terrain.contours import ELEVATION_FIELD, LAYER, write_contours

US_FOOT = 1200.0 / 3937.0


def _dsm_in_feet(path: str) -> float:
    """A tilted plane from 100 to 130 m, written in feet in EPSG:3734 (Ohio North, US survey feet); its range (m)."""
    n = 64
    z_m = np.tile(np.linspace(100.0, 130.0, n), (n, 1))
    ds = gdal.GetDriverByName("GTiff").Create(path, n, n, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((2200000.0, 3.0, 0.0, 700000.0, 0.0, -3.0))  # 3 ft cells
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(3734)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).WriteArray((z_m / US_FOOT).astype(np.float32))
    ds = None
    return 30.0


def test_contours_of_a_dsm_in_feet_are_every_metre_in_metres(tmp_path):
    path = str(tmp_path / "dsm_ft.tif")
    _dsm_in_feet(path)
    out = str(tmp_path / "c.gpkg")
    n = write_contours(path, out, 1.0, what="DSM")
    ds = ogr.Open(out)
    levels = sorted({round(f.GetField(ELEVATION_FIELD), 3) for f in ds.GetLayerByName(LAYER)})
    # every metre from 101 to 129 (1-ft contours were 3.28 x as many, at 328.084 ft ...)
    assert 28 <= len(levels) <= 31 and n == len(levels), levels
    assert np.allclose(levels, np.round(levels), atol=0.002), levels
    assert 100.0 <= levels[0] <= 101.0 and 129.0 <= levels[-1] <= 130.0, levels


def test_the_difference_of_a_dsm_in_feet_and_one_in_metres_is_in_metres(tmp_path):
    """dsmdifference of a metre DSM and the same surface in feet reported 22 m of change everywhere."""
    from core.io.raster import height_unit
    from core.terrain.difference import dsm_difference

    feet = str(tmp_path / "dsm_ft.tif")
    _dsm_in_feet(feet)
    metres = str(tmp_path / "dsm_m.tif")
    gdal.Translate(metres, feet)
    ds = gdal.Open(metres, gdal.GA_Update)
    band = ds.GetRasterBand(1)
    band.WriteArray(band.ReadAsArray() * US_FOOT + 0.5)  # the same surface in metres, 0.5 m higher
    band.SetUnitType("m")
    ds = None
    assert abs(height_unit(feet)[1] - US_FOOT) < 1e-12 and height_unit(metres)[1] == 1.0
    out = str(tmp_path / "diff.tif")
    r = dsm_difference(feet, metres, out)
    assert abs(r.median - 0.5) < 0.01 and r.p95 - r.p5 < 0.02, r
    assert height_unit(out)[1] == 1.0  # the difference says it is in metres, on the grid in feet


def test_a_dsm_too_large_for_the_memory_is_refused_before_reading(tmp_path, monkeypatch):
    """Issue 36 item 11: a 60,000 x 60,000 sparse DSM ended in a MemoryError after allocating; now the size is
    checked against the memory available before anything is read, and the message says what to do."""
    import pytest

    from core.terrain import rasters
    from core.terrain.difference import dsm_difference
    from core.terrain.options import TerrainError
    from core.terrain.products import build_dtm

    path = str(tmp_path / "huge.tif")
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds = gdal.GetDriverByName("GTiff").Create(path, 60000, 60000, 1, gdal.GDT_Float32,
                                              ["TILED=YES", "SPARSE_OK=TRUE", "COMPRESS=DEFLATE"])
    ds.SetGeoTransform((500000.0, 0.1, 0.0, 4000000.0, 0.0, -0.1))
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).SetNoDataValue(-9999.0)
    ds = None
    monkeypatch.setattr(rasters, "available_memory", lambda: 16 * 2 ** 30)  # a 16 GiB laptop
    with pytest.raises(TerrainError, match=r"huge\.tif is 60000 x 60000 cells: its terrain products need about "
                                           r"\d+\.\d GiB of memory, 16\.0 GiB is available; resample"):
        build_dtm(path, str(tmp_path / "dtm.tif"))
    with pytest.raises(TerrainError, match="60000 x 60000 cells"):
        dsm_difference(path, path, str(tmp_path / "diff.tif"))
    # a DSM that fits is read as before
    small = str(tmp_path / "dsm_ft.tif")
    _dsm_in_feet(small)
    assert rasters.read_elevation(small).z.shape == (64, 64)
