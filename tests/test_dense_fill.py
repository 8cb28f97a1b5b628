"""The DSM's honesty and completeness: holes inside the cameras' hull filled by a 2.5-D surface and flagged
interpolated (dense/dsm-source.tif), and a synthetic block with a low-texture ground patch (bare soil, uniform
crops) measured, its accuracy against the truth reported apart for measured and interpolated cells."""
import os

import numpy as np
import pytest

from core.dense import grid as gridding
from core.dense import stage as dense
from core.dense.options import DenseOptions
from core.io import raster
from tests import synthetic as syn
from tests.conftest import ROOT
from tests.test_dense import CAMERA, _truth_grid, make_workspace
from tests.workspaces import rendered_once

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


def test_lr_check_and_coarse_to_fine():
    from core.dense import stereo

    h, w = 40, 60
    truth = np.full((h, w), 10.0, dtype=np.float32)
    truth[:, 30:] = 20.0  # a jump (a roof edge) at x = 30
    left = truth.copy()
    right = np.full((h, w), np.nan, dtype=np.float32)
    for x in range(w):  # the right image's disparity at x - d
        xr = int(x - left[0, x])
        if xr >= 0:
            right[:, xr] = left[:, x]
    left[5, 40] = 25.0  # inconsistent with the right map: dropped by the left-right check
    checked = stereo.lr_checked(left, right, 1.0)
    assert np.isnan(checked[5, 40]) and checked[6, 40] == 20.0
    coarse = truth[::2, ::2] / 2.0  # the same surface matched at half the resolution
    fine = truth.copy()
    fine[10:14, 4:8] = np.nan  # a hole on the flat part: completed from the coarse map
    fine[20:24, 28:33] = np.nan  # a hole on the edge: left for the fill (no blurred coarse edge)
    fine[30, 10] = 17.0  # outside the coarse neighbourhood's range: a blunder, replaced by the coarse value
    out = stereo.coarse_to_fine(fine, coarse)
    assert np.allclose(out[10:14, 4:8], 10.0) and out[30, 10] == pytest.approx(10.0)
    assert np.isnan(out[20:24, 29:32]).all()
    assert np.array_equal(out[:, 30:35][np.isfinite(fine[:, 30:35])], fine[:, 30:35][np.isfinite(fine[:, 30:35])])


# ---------------------------------------------------------------------------
# a synthetic block with a low-texture ground patch (its west: 3 % of the texture's contrast)
# ---------------------------------------------------------------------------

CACHE = os.path.join(ROOT, "build", "test-cache", "dense-lowtex-v1")
PATCH = (0.0, 0.0, 0.41, 1.0)  # fractions of the scene: the west, a third of the cameras' hull, no building checked


def _block():
    return syn.vertical_block(seed=8, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=6, forward_overlap=0.8,
                              side_overlap=0.5, gcp_grid=(2, 2), roofs=0, low_texture=PATCH,
                              low_texture_contrast=0.03)


@pytest.fixture(scope="module")
def lowtex(tmp_path_factory):
    """The DSM stage on the low-texture block (images rendered once, cached under build/)."""
    block = _block()
    images = rendered_once(block, CACHE)
    root = tmp_path_factory.mktemp("dense lowtex")
    ws = make_workspace(str(root / "ws"), block, images_dir=images)
    r = dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=1))
    z, gt, _, x, y, truth = _truth_grid(block, r.dsm_path)
    src, _, _ = raster.read_dsm(r.source_path)
    src = np.nan_to_num(src).astype(np.uint8)
    centres = np.array([s.centre[:2] for s in block.shots]) + np.asarray(syn.ORIGIN[:2])
    grid = raster.Grid(gt[0], gt[3], gt[1], z.shape[1], z.shape[0])
    hull = gridding.polygon_mask(grid, gridding.convex_hull_xy(centres))
    x0, y0, x1, y1 = block.scene.low_texture
    patch = hull & (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    walls = np.zeros(z.shape, dtype=bool)
    for b in block.scene.buildings:
        walls |= b.contains(x, y, 2 * gt[1]) & ~b.contains(x, y, -2 * gt[1])
    return dict(block=block, r=r, z=z, x=x, y=y, truth=truth, src=src, hull=hull, patch=patch, walls=walls)


def test_low_texture_ground_is_measured(lowtex):
    """>= 90 % of the low-texture patch inside the cameras' hull measured (83.9 % before the coarse-to-fine
    matching), its heights within a GSD (median; few blunders), the textured rest as accurate as ever."""
    t = lowtex
    src, err, gsd, patch = t["src"], t["z"] - t["truth"], t["block"].gsd, t["patch"]
    assert patch.sum() > 0.25 * t["hull"].sum()
    measured = float(np.mean(src[patch] == raster.SOURCE_MEASURED))
    assert measured >= 0.9, f"only {100 * measured:.1f} % of the low-texture patch measured"
    assert (src[t["hull"]] > 0).all()  # the rest filled, and flagged so
    m = patch & (src == raster.SOURCE_MEASURED) & ~t["walls"]
    assert np.median(np.abs(err[m])) <= gsd
    assert np.mean(np.abs(err[m]) > 5 * gsd) < 0.02
    rest = t["hull"] & ~patch & (src == raster.SOURCE_MEASURED) & ~t["walls"]
    rmse_rest = float(np.sqrt(np.mean(err[rest] ** 2)))
    assert rmse_rest <= 1.5 * gsd
    interp = t["hull"] & (src == raster.SOURCE_INTERPOLATED)
    print(f"low-texture patch: {100 * measured:.1f} % measured (median error {np.median(np.abs(err[m])):.3f} m, "
          f"RMSE {np.sqrt(np.mean(err[m] ** 2)):.2f} m), textured rest RMSE {rmse_rest:.3f} m; interpolated "
          f"{100 * interp.sum() / t['hull'].sum():.1f} % of the hull, median error {np.median(np.abs(err[interp])):.2f} m")
    assert np.median(np.abs(err[interp])) <= 1.0


def test_low_texture_block_keeps_building_edges_sharp(lowtex):
    """A DSM cell on the wrong side of a roof edge (above or below half the building's height) lies at most 2 cells
    from the true outline, for every building the block sees whole."""
    from scipy import ndimage

    t = lowtex
    z, x, y, truth = t["z"], t["x"], t["y"], t["truth"]
    covered = np.isfinite(z)
    checked = 0
    for b in t["block"].scene.buildings:
        inside = b.contains(x, y)
        if inside.sum() == 0 or (inside & covered).sum() < 0.9 * inside.sum():
            continue
        near = b.contains(x, y, 6.0)
        ground = float(np.median(truth[near & ~b.contains(x, y, 1.0)]))
        mid = 0.5 * (b.roof + ground)
        high = truth > mid
        wrong = near & covered & ((z > mid) != high)
        dist = ndimage.distance_transform_edt(~(high ^ ndimage.binary_erosion(high)))
        assert wrong.sum() == 0 or dist[wrong].max() <= 2.0, (
            f"building at ({b.cx:.0f}, {b.cy:.0f}): edge cells up to {dist[wrong].max():.1f} cells off")
        checked += 1
    assert checked >= 2
