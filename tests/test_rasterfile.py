"""core.io.raster.RasterFile: the one raster reader of core/ (issue 35): errors name the file, windows and
resampled reads return what is in the file."""
import numpy as np
import pytest
from osgeo import gdal

from core.io.raster import DsmError, RasterError, RasterFile, open_dsm


def _tif(path, arr, gt=(100.0, 2.0, 0.0, 500.0, 0.0, -2.0), nodata=None):
    drv = gdal.GetDriverByName("GTiff")
    bands = arr if arr.ndim == 3 else arr[None]
    ds = drv.Create(str(path), bands.shape[2], bands.shape[1], bands.shape[0], gdal.GDT_Float32)
    if gt is not None:
        ds.SetGeoTransform(gt)
    for i, b in enumerate(bands, 1):
        ds.GetRasterBand(i).WriteArray(b)
        if nodata is not None:
            ds.GetRasterBand(i).SetNoDataValue(nodata)
    ds = None
    return str(path)


def test_reads_windows_bands_and_resampled(tmp_path):
    a = np.arange(3 * 8 * 10, dtype=np.float32).reshape(3, 8, 10)
    p = _tif(tmp_path / "r.tif", a, nodata=-1)
    with RasterFile(p, "orthophoto") as r:
        assert (r.width, r.height, r.count) == (10, 8, 3)
        assert r.require_georeferenced() == (100.0, 2.0, 0.0, 500.0, 0.0, -2.0)
        assert r.nodata(2) == -1
        np.testing.assert_array_equal(r.read(2), a[1])
        np.testing.assert_array_equal(r.read(3, window=(2, 1, 4, 3)), a[2, 1:4, 2:6])
        np.testing.assert_array_equal(r.read_bands([1, 3]), a[[0, 2]])
        half = r.read(1, out_shape=(4, 5), resampling="average")
        np.testing.assert_allclose(half, a[0].reshape(4, 2, 5, 2).mean(axis=(1, 3)))
        with pytest.raises(RasterError, match=r"orthophoto .*r\.tif has 3 band\(s\), not band 4"):
            r.read(4)


def test_errors_name_the_file(tmp_path):
    with pytest.raises(RasterError, match=r"reference DSM .*missing\.tif does not exist"):
        RasterFile(str(tmp_path / "missing.tif"), "reference DSM")
    bad = tmp_path / "bad.tif"
    bad.write_bytes(b"not a tiff at all")
    with pytest.raises(RasterError, match=r"photo .*bad\.tif is not a raster GDAL can read"):
        RasterFile(str(bad), "photo")
    p = _tif(tmp_path / "plain.tif", np.zeros((4, 4), np.float32), gt=None)
    with RasterFile(p, "mask") as r, pytest.raises(RasterError, match=r"mask .*plain\.tif has no georeferencing"):
        r.require_georeferenced()
    with pytest.raises(DsmError, match=r"plain\.tif has no georeferencing"):
        open_dsm(p)
    rot = _tif(tmp_path / "rot.tif", np.zeros((4, 4), np.float32), gt=(0, 1, 0.2, 0, 0.1, -1))
    with pytest.raises(DsmError, match="rotated"):
        open_dsm(rot)


def test_the_crs_is_read_when_asked_also_after_close(tmp_path):
    """RasterFile reads the CRS's WKT on first use (a reader of many small windows opens the file for each), and
    gives it after the file was closed too."""
    from osgeo import gdal, osr

    from core.io.raster import RasterFile

    path = str(tmp_path / "utm.tif")
    ds = gdal.GetDriverByName("GTiff").Create(path, 4, 3, 1, gdal.GDT_Float32)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    ds.SetGeoTransform((500000.0, 1.0, 0.0, 4600000.0, 0.0, -1.0))
    ds = None
    with RasterFile(path) as r:
        inside = r.crs_wkt
    with RasterFile(path) as r:
        pass
    after = r.crs_wkt
    assert "32633" in inside and after == inside
