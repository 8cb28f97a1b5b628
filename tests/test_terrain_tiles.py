"""The terrain products computed by tiles (issue 33 item 1: Build DTM held the whole DSM as float64 copies, 6 GiB
for 44 M cells) equal the products computed in one piece: the ground filter's tiles with a margin its slope and
dilation reach, each object filled from its own box, the rasters written tile by tile."""
from __future__ import annotations

import numpy as np
import pytest
from osgeo import gdal, osr

from core.terrain.ground import filter_ground
from core.terrain.options import GroundOptions

CELL = 0.1


def _dsm(h=230, w=310, seed=5):
    """Hills, furrows, three buildings (one across many tiles), trees, noise, nodata holes and a ragged edge."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w] * CELL
    z = 50.0 + 0.02 * x + 1.5 * np.exp(-((x - 12) ** 2 + (y - 9) ** 2) / 60.0) + 0.03 * np.sin(x / 0.4)
    for x0, y0, hw, hh, bh in ((8, 6, 4.0, 2.5, 5.0), (24, 16, 1.5, 1.0, 3.0), (27, 4, 2.0, 1.5, 6.0)):
        z[(np.abs(x - x0) < hw) & (np.abs(y - y0) < hh)] += bh
    for _ in range(12):
        tx, ty, r = rng.uniform(2, w * CELL - 2), rng.uniform(2, h * CELL - 2), rng.uniform(0.4, 1.2)
        d2 = (x - tx) ** 2 + (y - ty) ** 2
        z += np.where(d2 < r * r, 4.0 * np.sqrt(np.clip(1 - d2 / (r * r), 0, 1)), 0.0)
    z += rng.normal(0, 0.02, z.shape)
    z[rng.uniform(size=z.shape) < 0.003] = np.nan  # single holes
    z[100:112, 40:47] = np.nan  # an inner hole
    z[:, :3] = np.nan
    z[np.arange(h) % 17 < 5, :6] = np.nan  # a ragged edge
    return z


@pytest.fixture(scope="module")
def untiled():
    return filter_ground(_dsm(), CELL, GroundOptions(tile=100_000))


@pytest.mark.parametrize("tile", [32, 77])
def test_tiled_ground_filter_equals_the_untiled_one(untiled, tile):
    tiled = filter_ground(_dsm(), CELL, GroundOptions(tile=tile))
    assert untiled.ground.sum() > 0.5 * np.isfinite(_dsm()).sum()  # a real case: mostly ground, objects removed
    assert (untiled.source == 2).sum() > 2000
    assert np.array_equal(tiled.ground, untiled.ground)
    assert np.array_equal(tiled.source, untiled.source)
    assert np.array_equal(np.isnan(tiled.dtm), np.isnan(untiled.dtm))
    ok = np.isfinite(untiled.dtm)
    assert np.array_equal(tiled.dtm[ok], untiled.dtm[ok])
    assert tiled.valid_cells == untiled.valid_cells == int(np.isfinite(_dsm()).sum())


def test_build_dtm_by_small_tiles_writes_the_same_rasters(tmp_path):
    """The stage reads the DSM file by windows and writes the DTM and its source raster tile by tile."""
    from core.terrain.products import build_dtm

    z = _dsm()
    path = str(tmp_path / "dsm.tif")
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds = gdal.GetDriverByName("GTiff").Create(path, z.shape[1], z.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform((500000.0, CELL, 0.0, 4600000.0, 0.0, -CELL))
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).SetNoDataValue(-9999.0)
    ds.GetRasterBand(1).WriteArray(np.where(np.isfinite(z), z, -9999.0))
    ds = None
    out = {}
    for tile in (40, 100_000):
        r = build_dtm(path, str(tmp_path / f"dtm{tile}.tif"), GroundOptions(tile=tile))
        out[tile] = [gdal.Open(p).ReadAsArray() for p in (r.dtm_path, r.source_path)]
        assert 0.5 < r.ground_fraction < 1.0 and 0.0 < r.interpolated_fraction < 0.5
    assert np.array_equal(out[40][0], out[100_000][0])
    assert np.array_equal(out[40][1], out[100_000][1])
    dtm = out[40][0]
    assert ((dtm == -9999.0) == (out[40][1] == 0)).all()  # nodata exactly outside the data
    # the in-memory filter gives what the file gives
    mem = filter_ground(z.astype(np.float32).astype(np.float64), CELL, GroundOptions())
    assert np.array_equal(np.where(np.isfinite(mem.dtm), mem.dtm, -9999.0).astype(np.float32), dtm)


def _write(path, z):
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds = gdal.GetDriverByName("GTiff").Create(path, z.shape[1], z.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform((500000.0, CELL, 0.0, 4600000.0, 0.0, -CELL))
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).SetNoDataValue(-9999.0)
    ds.GetRasterBand(1).WriteArray(np.where(np.isfinite(z), z, -9999.0))
    ds = None
    return path


def test_relief_by_small_tiles_equals_the_whole_raster(tmp_path):
    """Each visualisation computed by tiles with the margin its radius reaches (radii shortened so that the
    230 x 310 raster holds several tiles) is the one computed on the whole raster."""
    pytest.importorskip("rvt.vis")
    from core.terrain import relief as rv
    from core.terrain.options import VISUALISATION_KEYS, ReliefOptions
    from core.terrain.products import relief

    dem = _write(str(tmp_path / "dem.tif"), _dsm())
    short = dict(svf_radius=0.6, slrm_radius=0.8, msrm_feature_max=1.5, ld_min_radius=0.3, ld_max_radius=0.6,
                 svf_directions=8, mhs_directions=4)
    small, whole = ReliefOptions(tile=1, **short), ReliefOptions(tile=100_000, **short)
    assert all(rv.tile_cells(k, CELL, small) < 150 for k in VISUALISATION_KEYS)  # several tiles each
    a = relief(dem, VISUALISATION_KEYS, str(tmp_path / "tiled"), options=small)
    b = relief(dem, VISUALISATION_KEYS, str(tmp_path / "whole"), options=whole)
    for key in VISUALISATION_KEYS:
        x, y = (gdal.Open(r.paths[key]).ReadAsArray() for r in (a, b))
        assert np.array_equal(x == -9999.0, y == -9999.0), key
        lo, hi = rv.DISPLAY_RANGE[key]
        assert np.abs(x - y).max() <= 1e-5 * (hi - lo), (key, np.abs(x - y).max())
