"""The DSM's honesty and completeness: holes inside the cameras' hull filled by a 2.5-D surface and flagged
interpolated (dense/dsm-source.tif), and a synthetic block with a low-texture ground patch (bare soil, uniform
crops) measured, its accuracy against the truth reported apart for measured and interpolated cells."""
import numpy as np
import pytest

from core.dense import grid as gridding
from core.io import raster

# ---------------------------------------------------------------------------
# units: the fill and the source raster
# ---------------------------------------------------------------------------


def _surface(h=120, w=160):
    r, c = np.mgrid[0:h, 0:w].astype(np.float64)
    return (100.0 + 0.05 * c - 0.03 * r + 2.0 * np.sin(c / 25.0) * np.cos(r / 30.0)).astype(np.float32)


def test_fill_region_fills_a_hole_smoothly_and_only_inside_the_region():
    truth = _surface()
    dsm = truth.copy()
    dsm[40:70, 50:90] = np.nan  # a 30 x 40 cell hole inside the region
    dsm[5:15, 140:155] = np.nan  # a hole outside the region
    region = np.zeros(dsm.shape, dtype=bool)
    region[20:100, 20:120] = True
    out = gridding.fill_region(dsm, region, max_distance_cells=0)
    hole = np.isnan(dsm) & region
    assert np.isfinite(out[hole]).all()
    err = out[hole] - truth[hole]
    # a smooth membrane through the borders of a smooth surface: within 0.5 m here (2 m of relief, 40-cell hole)
    assert np.sqrt(np.mean(err ** 2)) < 0.5 and np.abs(err).max() < 1.0
    assert np.isnan(out[5:15, 140:155]).all()  # outside the region: left alone
    assert np.array_equal(out[np.isfinite(dsm)], dsm[np.isfinite(dsm)])  # data unchanged


def test_fill_region_stops_at_the_maximum_distance():
    dsm = _surface()
    dsm[30:90, 30:130] = np.nan  # 60 cells across: its centre is 30 cells from the data
    out = gridding.fill_region(dsm, np.ones(dsm.shape, dtype=bool), max_distance_cells=10)
    assert np.isfinite(out[30:40, 60:100]).all()  # within 10 cells of the border
    assert np.isnan(out[45:75, 45:115]).all()  # farther than 10 cells: still nodata


def test_source_raster_and_enclosed_holes():
    dsm = _surface(40, 40)
    dsm[10:14, 10:14] = np.nan  # enclosed
    dsm[0:5, 30:40] = np.nan  # touches the edge
    inner = gridding.enclosed_holes(dsm)
    assert inner[10:14, 10:14].all() and inner.sum() == 16
    measured = np.isfinite(dsm)
    filled = gridding.fill_region(dsm, inner, 0)
    src = gridding.source_raster(measured, filled)
    assert (src[10:14, 10:14] == raster.SOURCE_INTERPOLATED).all()
    assert (src[0:5, 30:40] == 0).all()
    assert (src[measured] == raster.SOURCE_MEASURED).all()


def test_write_classes_is_a_cog_with_nodata_zero(tmp_path):
    from osgeo import gdal

    src = np.array([[0, 1, 2], [2, 1, 0]], dtype=np.uint8)
    path = raster.write_classes(str(tmp_path / "s.tif"), src, (500000, 1, 0, 5000000, 0, -1), "EPSG:32633",
                                "DSM source", {"ARCHAEOORTHO_PRODUCT": "dsm-source"})
    ds = gdal.Open(path)
    assert ds.GetRasterBand(1).GetNoDataValue() == 0
    assert np.array_equal(ds.GetRasterBand(1).ReadAsArray(), src)
    assert ds.GetMetadataItem("ARCHAEOORTHO_PRODUCT") == "dsm-source"


@pytest.mark.parametrize("shape", [(1, 1), (3, 5), (64, 33)])
def test_push_pull_keeps_the_known_cells(shape):
    rng = np.random.default_rng(1)
    z = rng.normal(10, 1, shape)
    known = rng.random(shape) > 0.3
    known.flat[0] = True
    out = raster.push_pull(z, known)
    assert np.allclose(out[known], z[known]) and np.isfinite(out).all()
