"""DEM co-registration (core/georef/coregister.py, issue 32 item 4) against known truth.

Synthetic terrain: a sum of Gaussian hills and hollows (150 m to 1.5 km wide) in UTM-sized coordinates,
~550 m of relief (rugged) or ~80 m (gentle).  The reference is a 25 m DEM averaged from the terrain at 5 m (as an
ALS or national DEM is); the "block DSM" is the terrain at 5 m over the inner 6 km, its coordinates off by a known
(dx, dy), its heights by a known dz and plane (and dome), with 0.5 m noise, a forest (+18 m), buildings (+6 to
15 m) and a hole of nodata: the outliers the co-registration must leave out.  Truth in the module's convention:
DSM(p) = H(p + s) - correction(p + s), so the result must give shift = s and correction = the applied one.
"""
import json
import math

import numpy as np
import pytest

from core.common.errors import ArchaeoOrthoError
from core.geometry.similarity import helmert_fit
from core.georef.coregister import (
    CoregError,
    CoregOptions,
    HeightGrid,
    control_points_from_coregistration,
    coregister_dems,
    coregister_points,
    coregister_points_file,
    coregister_rasters,
    nmad,
    reference_window,
)

X0, Y0 = 500000.0, 4600000.0  # lower-left corner of the reference
EXTENT = 8000.0
FINE = 5.0
REF_CELL = 25.0
BLOCK = (X0 + 1000.0, Y0 + 1000.0, 6000.0)  # lower-left corner and size of the DSM
CENTRE = (X0 + EXTENT / 2, Y0 + EXTENT / 2)


class Terrain:
    """Sum of Gaussians; ``grid`` is separable (fast), ``at`` for scattered points."""

    def __init__(self, seed, n, amplitude, smin, smax):
        rng = np.random.default_rng(seed)
        self.cx = X0 + rng.uniform(-0.2, 1.2, n) * EXTENT
        self.cy = Y0 + rng.uniform(-0.2, 1.2, n) * EXTENT
        self.s = np.exp(rng.uniform(np.log(smin), np.log(smax), n))
        self.a = rng.uniform(-1, 1, n) * amplitude * np.sqrt(self.s / smax)

    def grid(self, xs, ys):
        z = np.full((ys.size, xs.size), 500.0)
        for cx, cy, s, a in zip(self.cx, self.cy, self.s, self.a):
            z += a * np.outer(np.exp(-(ys - cy) ** 2 / (2 * s * s)), np.exp(-(xs - cx) ** 2 / (2 * s * s)))
        return z

    def at(self, x, y):
        z = np.full(np.shape(x), 500.0)
        for cx, cy, s, a in zip(self.cx, self.cy, self.s, self.a):
            z += a * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s))
        return z


def correction(x, y, dz, tilt=(0.0, 0.0), dome=(0.0, 0.0, 0.0)):
    u, v = x - CENTRE[0], y - CENTRE[1]
    return dz + tilt[0] * u + tilt[1] * v + dome[0] * u * u + dome[1] * u * v + dome[2] * v * v


def reference(terrain, noise=0.0, seed=0):
    n = int(EXTENT / FINE)
    xs = X0 + (np.arange(n) + 0.5) * FINE
    ys = Y0 + EXTENT - (np.arange(n) + 0.5) * FINE
    k = int(REF_CELL / FINE)
    ref = terrain.grid(xs, ys).reshape(n // k, k, n // k, k).mean(axis=(1, 3))
    ref += np.random.default_rng(seed).normal(0, noise, ref.shape) if noise else 0.0
    return ref, (X0, REF_CELL, 0.0, Y0 + EXTENT, 0.0, -REF_CELL)


def block_dsm(terrain, shift, dz, tilt=(0.0, 0.0), dome=(0.0, 0.0, 0.0), noise=0.5, outliers=True, seed=5):
    """The DSM (float32) and its geotransform; NaN in a hole."""
    bx, by, size = BLOCK
    m = int(size / FINE)
    xs = bx + (np.arange(m) + 0.5) * FINE
    ys = by + size - (np.arange(m) + 0.5) * FINE
    qx, qy = xs + shift[0], ys + shift[1]
    z = terrain.grid(qx, qy) - correction(qx[None, :], qy[:, None], dz, tilt, dome)
    rng = np.random.default_rng(seed)
    z += rng.normal(0, noise, z.shape)
    if outliers:
        z[200:500, 300:700] += 18.0  # a forest
        for _ in range(80):  # buildings
            r, c = rng.integers(0, m - 20, 2)
            z[r:r + 6, c:c + 8] += rng.uniform(6, 15)
        z[800:900, 100:300] = np.nan  # a hole
    return z.astype(np.float32), (bx, FINE, 0.0, by + size, 0.0, -FINE)


@pytest.fixture(scope="module")
def rugged():
    return Terrain(1, 40, 400.0, 150.0, 1500.0)


@pytest.fixture(scope="module")
def rugged_ref(rugged):
    return reference(rugged, noise=0.2)


def check_correction(result, dz, tilt=(0.0, 0.0), dome=(0.0, 0.0, 0.0), tol=0.1):
    """The recovered height correction against the applied one over the block (corners and centre)."""
    bx, by, size = BLOCK
    x = np.array([bx, bx + size, bx, bx + size, bx + size / 2])
    y = np.array([by, by, by + size, by + size, by + size / 2])
    err = result.correction(x, y) - correction(x, y, dz, tilt, dome)
    assert np.max(np.abs(err)) < tol, err
    return err


def test_rugged_shift_tilt_and_outliers(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (37.0, -21.0), 3.2, (8e-4, -5e-4)  # 1.5 and 0.8 reference cells; 4.8 m / 3 m over 6 km
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert res.converged and res.horizontal_determined, res.messages
    assert abs(res.shift[0] - shift[0]) < 0.1 * REF_CELL and abs(res.shift[1] - shift[1]) < 0.1 * REF_CELL
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.5  # measured 0.02 m
    check_correction(res, dz, tilt, tol=0.1)
    assert abs(res.tilt[0] - tilt[0]) < 0.05 * abs(tilt[0]) and abs(res.tilt[1] - tilt[1]) < 0.05 * abs(tilt[1])
    # the forest and the buildings (about 7 % of the block) are left out; noise 0.5 m at 5 m -> ~0.1 m at 25 m
    assert 0.75 < res.stable_fraction < 0.97, res.stable_fraction
    assert res.nmad_after < 0.3 < res.nmad_before
    assert abs(res.median_after) < 0.1
    assert res.cell == REF_CELL and 2 <= res.iterations <= 10
    assert json.loads(json.dumps(res.as_dict()))["shift"] == list(res.shift)
    # apply_to_grid(): the DSM moved and corrected lies on the terrain (away from the forest and buildings)
    fixed, fixed_gt = res.apply_to_grid(dsm, gt)
    assert fixed.dtype == np.float32 and fixed_gt[0] == pytest.approx(gt[0] + res.shift[0])
    xs = fixed_gt[0] + (np.arange(600, 1200) + 0.5) * FINE
    ys = fixed_gt[3] - (np.arange(600, 1200) + 0.5) * FINE
    assert nmad(fixed[600:, 600:] - rugged.grid(xs, ys)) < 0.75  # the 0.5 m noise
    assert abs(np.median(fixed[600:, 600:] - rugged.grid(xs, ys))) < 0.1
    # apply(): a DSM point lands on the terrain
    p = np.array([[BLOCK[0] + 2000.0, BLOCK[1] + 3000.0, 0.0]])
    q = p[0, :2] + shift
    p[0, 2] = rugged.at(q[0], q[1]) - correction(q[0], q[1], dz, tilt)
    out = res.apply(p)[0]
    assert abs(out[2] - rugged.at(out[0], out[1])) < 0.1


def test_finer_reference_and_much_forest(rugged):
    """A 5 m reference (ALS) against a 25 m DSM (the DSM's grid is then the comparison grid, the reference is
    averaged onto it), with 40 % of the DSM under forest (+18 m): still the shift to a tenth of a cell."""
    n = int(EXTENT / FINE)
    xs = X0 + (np.arange(n) + 0.5) * FINE
    ys = Y0 + EXTENT - (np.arange(n) + 0.5) * FINE
    ref = rugged.grid(xs, ys).astype(np.float32)
    ref_gt = (X0, FINE, 0.0, Y0 + EXTENT, 0.0, -FINE)
    shift, dz, tilt = (-33.0, 14.0), 0.8, (-6e-4, 3e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt, outliers=False)
    m, k = dsm.shape[0], int(REF_CELL / FINE)
    coarse = dsm.reshape(m // k, k, m // k, k).mean(axis=(1, 3))
    coarse[:, : int(0.4 * coarse.shape[1])] += 18.0  # the west 40 % is forest
    res = coregister_dems(HeightGrid(coarse, (gt[0], REF_CELL, 0.0, gt[3], 0.0, -REF_CELL)), HeightGrid(ref, ref_gt))
    assert res.cell == REF_CELL and res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, tol=0.1)
    assert res.stable_fraction < 0.65


def test_large_shift_vertical_datum_and_forest_on_one_side(rugged, rugged_ref):
    """75 m off (3 cells), 45 m of vertical datum, a 1.2 mm/m tilt and the west third under forest: while the shift
    is large the forest cannot be told from the terrain by its residual, and least squares alone followed it (the
    shift came out 0, 'too flat'); the search for the start on whole cells finds it."""
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (60.0, -45.0), -45.3, (1.2e-3, 4e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    dsm[:, :400] += 18.0
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert res.converged and res.horizontal_determined
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, tol=0.1)
    assert 0.5 < res.stable_fraction < 0.65


def test_without_tilt_term_the_tilt_stays_in_the_residuals(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    dsm, gt = block_dsm(rugged, (10.0, 5.0), 1.0, (8e-4, -5e-4))
    flat = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), options=CoregOptions(tilt=False))
    tilted = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert flat.tilt == (0.0, 0.0)
    assert flat.nmad_after > 5 * tilted.nmad_after  # +-2.4 m of plane against ~0.1 m noise


def test_gentle_terrain_subcell_shift():
    terrain = Terrain(2, 25, 60.0, 300.0, 2000.0)  # ~80 m of relief
    ref, ref_gt = reference(terrain, noise=0.1)
    shift, dz, tilt = (-8.0, 12.5), -1.7, (-3e-4, 2e-4)
    dsm, gt = block_dsm(terrain, shift, dz, tilt, noise=0.3)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL, res.shift
    check_correction(res, dz, tilt, tol=0.1)


def test_dome(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    dome = (-2e-7, 0.5e-7, -1.5e-7)  # -1.8 m / -1.35 m at the block's corners
    shift, dz, tilt = (15.0, 30.0), 2.0, (2e-4, 1e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt, dome)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), options=CoregOptions(dome=True))
    assert res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, dome, tol=0.15)
    plane_only = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert plane_only.nmad_after > 2 * res.nmad_after


def test_large_grids_are_compared_coarser(rugged, rugged_ref, monkeypatch):
    """Beyond MAX_GRID_CELLS the comparison grid takes a coarser multiple of the cell (bounded memory); the
    shift is still found to a tenth of that cell."""
    import core.georef.coregister as coregister

    monkeypatch.setattr(coregister, "MAX_GRID_CELLS", 20000)  # the 6 km overlap has 57600 cells at 25 m
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (37.0, -21.0), 3.2, (8e-4, -5e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert res.cell == 2 * REF_CELL and any("compared on a 50 grid" in m for m in res.messages)
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * res.cell
    check_correction(res, dz, tilt, tol=0.15)


def test_flat_terrain_holds_the_horizontal_shift():
    terrain = Terrain(3, 0, 0.0, 100.0, 200.0)  # a plain at 500 m
    ref, ref_gt = reference(terrain, noise=0.05)
    dsm, gt = block_dsm(terrain, (40.0, 0.0), 2.5, (1e-4, 0.0), noise=0.2)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert not res.horizontal_determined and res.shift[:2] == (0.0, 0.0)
    assert any("too flat" in m for m in res.messages)
    check_correction(res, 2.5, (1e-4, 0.0), tol=0.05)


def test_not_converged_is_flagged(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    dsm, gt = block_dsm(rugged, (300.0, -200.0), 0.0)  # beyond the start's search (4 cells)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), options=CoregOptions(max_iterations=1))
    assert not res.converged and res.iterations <= 2  # one with the shift alone, one with the tilt
    assert any("not converged" in m for m in res.messages)
    full = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    assert full.converged and math.hypot(full.shift[0] - 300, full.shift[1] + 200) < 0.1 * REF_CELL


def test_stable_mask_and_nodata_value(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    shift = (20.0, 20.0)
    dsm, gt = block_dsm(rugged, shift, 1.0)
    dsm = np.where(np.isnan(dsm), -9999.0, dsm).astype(np.float32)
    stable = np.ones(ref.shape, bool)
    stable[:, : ref.shape[1] // 2] = False  # only the east half is stable
    res = coregister_dems(HeightGrid(dsm, gt, -9999.0), HeightGrid(ref, ref_gt), stable_mask=stable)
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    assert res.origin[0] > CENTRE[0]  # the compared cells are the east half
    with pytest.raises(CoregError, match="shape"):
        coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), stable_mask=stable[:10])


def test_points(rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (-30.0, 18.0), -4.0, (5e-4, 6e-4)
    rng = np.random.default_rng(7)
    n = 20000
    x = rng.uniform(BLOCK[0], BLOCK[0] + BLOCK[2], n)
    y = rng.uniform(BLOCK[1], BLOCK[1] + BLOCK[2], n)
    qx, qy = x + shift[0], y + shift[1]
    z = rugged.at(qx, qy) - correction(qx, qy, dz, tilt) + rng.normal(0, 0.3, n)
    z[:2000] += rng.uniform(5, 20, 2000)  # trees and roofs
    pts = np.column_stack([x, y, z])
    res = coregister_points(pts, HeightGrid(ref, ref_gt))
    assert res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, tol=0.1)
    assert res.stable_fraction < 0.95  # the 10 % raised points are left out
    pc = control_points_from_coregistration(res, HeightGrid(ref, ref_gt), points=pts, n=16)
    assert 12 <= len(pc) <= 16 and pc.index is not None
    assert np.all(pc.index >= 2000)  # never a raised point
    np.testing.assert_allclose(pc.block_xyz, pts[pc.index])


def test_points_against_a_file_in_another_crs(tmp_path, rugged, rugged_ref):
    """The sparse cloud in EPSG:32633 against a reference file in EPSG:25833 with heights in feet, read over the
    points only and reprojected into the points' CRS."""
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (12.0, -25.0), 1.5, (-4e-4, 2e-4)
    rng = np.random.default_rng(8)
    n = 5000
    x = rng.uniform(BLOCK[0], BLOCK[0] + 3000.0, n)  # a quarter of the block: the window is smaller than the file
    y = rng.uniform(BLOCK[1], BLOCK[1] + 3000.0, n)
    qx, qy = x + shift[0], y + shift[1]
    z = rugged.at(qx, qy) - correction(qx, qy, dz, tilt) + rng.normal(0, 0.3, n)
    ref_path = write(tmp_path / "ref.tif", ref / 0.3048, ref_gt, "EPSG:25833", unit="ft")
    res = coregister_points_file(np.column_stack([x, y, z]), ref_path, crs="EPSG:32633")
    assert res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    err = res.correction(qx[:50], qy[:50]) - correction(qx[:50], qy[:50], dz, tilt)
    assert np.max(np.abs(err)) < 0.1
    win, gt, _ = reference_window(ref_path, x.min(), y.min(), x.max(), y.max(), crs="EPSG:32633")
    assert win.size < ref.size / 2 and win.dtype == np.float32
    with pytest.raises(CoregError, match="ref.tif has no height over"):
        reference_window(ref_path, 0.0, 0.0, 10.0, 10.0, crs="EPSG:32633")
    with pytest.raises(CoregError, match="not in metres"):
        coregister_points_file(np.column_stack([x, y, z]), ref_path, crs="EPSG:4326")


def test_control_points_remove_the_tilt(rugged, rugged_ref):
    """Pseudo control points from a shifted, tilted DSM, applied with a Helmert fit (as the adjustment's first
    step would), put the block's points back on the terrain: the tilt is gone."""
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (37.0, -21.0), 3.2, (8e-4, -5e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    res = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt))
    pc = control_points_from_coregistration(res, HeightGrid(ref, ref_gt), dem=HeightGrid(dsm, gt), n=25)
    assert 20 <= len(pc) <= 25
    # well distributed: every quadrant of the block has some
    bx, by, size = BLOCK
    quad = (pc.block_xyz[:, 0] > bx + size / 2).astype(int) + 2 * (pc.block_xyz[:, 1] > by + size / 2)
    assert set(quad.tolist()) == {0, 1, 2, 3}
    # sigmas scale with the data: a quarter of the 25 m cell; about the residual NMAD in height on flat cells
    assert np.allclose(pc.sigma_xy, REF_CELL / 4)
    assert np.all(pc.sigma_z >= res.nmad_after) and np.median(pc.sigma_z) < 3 * res.nmad_after + 0.1
    stated = control_points_from_coregistration(res, HeightGrid(ref, ref_gt), dem=HeightGrid(dsm, gt), n=25,
                                                ref_sigma_z=2.0)
    np.testing.assert_allclose(stated.sigma_z, np.hypot(pc.sigma_z, 2.0))
    # the reference coordinates are the truth (the terrain at the shifted position)
    assert np.all(np.abs(pc.xyz[:, :2] - pc.block_xyz[:, :2] - shift) < 0.5)
    assert np.max(np.abs(pc.xyz[:, 2] - rugged.at(pc.xyz[:, 0], pc.xyz[:, 1]))) < 0.5
    t = helmert_fit(pc.block_xyz, pc.xyz)
    rng = np.random.default_rng(11)
    x = rng.uniform(bx, bx + size, 500)
    y = rng.uniform(by, by + size, 500)
    z = rugged.at(x + shift[0], y + shift[1]) - correction(x + shift[0], y + shift[1], dz, tilt)
    out = t.apply(np.column_stack([x, y, z]))
    dh = out[:, 2] - rugged.at(out[:, 0], out[:, 1])
    before = z - rugged.at(x, y)
    a = np.column_stack([np.ones_like(x), x - CENTRE[0], y - CENTRE[1]])
    left_tilt = np.linalg.lstsq(a, dh, rcond=None)[0][1:]
    assert np.all(np.abs(left_tilt) < 0.05 * np.abs(tilt)), left_tilt
    assert np.sqrt(np.mean(dh ** 2)) < 0.3 < nmad(before)
    assert np.max(np.hypot(out[:, 0] - x - shift[0], out[:, 1] - y - shift[1])) < 0.1 * REF_CELL


# ---------------------------------------------------------------------------
# files
# ---------------------------------------------------------------------------

# a transverse Mercator without an EPSG code (the national kind): UTM 33N's projection, another name
TM_WKT = ('PROJCS["Local TM",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],'
          'PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],'
          'PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],'
          'PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1]]')


def write(path, z, gt, crs, nodata=-9999.0, unit=""):
    from osgeo import gdal, osr

    gdal.UseExceptions()
    ds = gdal.GetDriverByName("GTiff").Create(str(path), z.shape[1], z.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform(gt)
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        ds.SetProjection(srs.ExportToWkt())
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(nodata)
    if unit:
        band.SetUnitType(unit)
    band.WriteArray(np.where(np.isfinite(z), z, nodata))
    ds = None
    return str(path)


def test_rasters_other_crs_and_feet(tmp_path, rugged, rugged_ref):
    """The reference in a TM CRS without an EPSG code (UTM 33N's projection on WGS 84), the DSM in EPSG:25833
    (ETRS89 / UTM 33N: another CRS, so the DSM is reprojected; PROJ maps one onto the other within 0.1 mm here,
    so the truth holds) with heights in feet."""
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (37.0, -21.0), 3.2, (8e-4, -5e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    ref_path = write(tmp_path / "ref.tif", ref, ref_gt, TM_WKT)
    dsm_path = write(tmp_path / "dsm.tif", dsm / 0.3048, gt, "EPSG:25833", unit="ft")
    res = coregister_rasters(dsm_path, ref_path)
    assert res.converged
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, tol=0.1)
    assert any("converted to metres" in m for m in res.messages)


def test_rasters_in_feet_with_a_stable_mask(tmp_path, rugged, rugged_ref):
    """A CRS in US survey feet (EPSG:2263) for both, heights in feet: the result is in metres; a stable-terrain
    mask file (1 = stable) on its own grid keeps the fit to the east half."""
    ref, ref_gt = rugged_ref
    shift, dz, tilt = (20.0, 30.0), -2.0, (3e-4, 4e-4)
    dsm, gt = block_dsm(rugged, shift, dz, tilt)
    ft = 1200.0 / 3937.0
    to_ft = lambda g: tuple(v / ft for v in g)  # noqa: E731
    ref_path = write(tmp_path / "ref.tif", ref / ft, to_ft(ref_gt), "EPSG:2263", unit="US survey foot")
    dsm_path = write(tmp_path / "dsm.tif", dsm / ft, to_ft(gt), "EPSG:2263", unit="ftUS")
    mask = np.zeros((80, 80))
    mask[:, 40:] = 1.0
    mask_gt = (X0, EXTENT / 80, 0.0, Y0 + EXTENT, 0.0, -EXTENT / 80)
    mask_path = write(tmp_path / "stable.tif", mask, to_ft(mask_gt), "EPSG:2263", nodata=255)
    res = coregister_rasters(dsm_path, ref_path, stable_mask_path=mask_path)
    assert res.converged and res.cell == pytest.approx(REF_CELL)
    assert math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * REF_CELL
    check_correction(res, dz, tilt, tol=0.1)
    assert res.origin[0] > CENTRE[0] + 500  # the east half only


def test_cancel(rugged, rugged_ref):
    from core.common.progress import Cancelled, NullProgress

    class Stop(NullProgress):
        def is_cancelled(self):
            return True

    ref, ref_gt = rugged_ref
    dsm, gt = block_dsm(rugged, (10.0, 10.0), 0.0, outliers=False)
    with pytest.raises(Cancelled):
        coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), progress=Stop())


def test_errors(tmp_path, rugged, rugged_ref):
    ref, ref_gt = rugged_ref
    dsm, gt = block_dsm(rugged, (0.0, 0.0), 0.0, outliers=False)
    far = (gt[0] + 50000.0,) + gt[1:]
    with pytest.raises(CoregError, match="do not overlap"):
        coregister_dems(HeightGrid(dsm, far), HeightGrid(ref, ref_gt))
    with pytest.raises(CoregError, match="every cell is nodata"):
        coregister_dems(HeightGrid(np.full((50, 50), np.nan), gt, name="DSM"), HeightGrid(ref, ref_gt))
    with pytest.raises(CoregError, match="too few cells"):  # overlaps by 4 x 4 reference cells
        corner = (X0 + EXTENT - 100.0, FINE, 0.0, Y0 + 100.0, 0.0, -FINE)
        coregister_dems(HeightGrid(dsm, corner), HeightGrid(ref, ref_gt))
    with pytest.raises(CoregError, match="too few cells"):
        coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), stable_mask=np.zeros(ref.shape, bool))
    with pytest.raises(CoregError, match="rotated"):
        coregister_dems(HeightGrid(dsm, (gt[0], FINE, 0.1, gt[3], 0.0, -FINE)), HeightGrid(ref, ref_gt))
    with pytest.raises(CoregError, match="do not overlap"):
        coregister_points(np.array([[0.0, 0.0, 0.0]] * 200), HeightGrid(ref, ref_gt))
    # files: each message names the file
    ref_path = write(tmp_path / "ref.tif", ref, ref_gt, "EPSG:32633")
    dsm_path = write(tmp_path / "dsm.tif", dsm, gt, "EPSG:32633")
    missing = str(tmp_path / "missing.tif")
    with pytest.raises(CoregError, match="missing.tif does not exist"):
        coregister_rasters(missing, ref_path)
    no_crs = write(tmp_path / "nocrs.tif", dsm, gt, "")
    with pytest.raises(CoregError, match="nocrs.tif has no CRS"):
        coregister_rasters(no_crs, ref_path)
    geo = write(tmp_path / "geo.tif", ref, (15.0, 0.0003, 0.0, 41.5, 0.0, -0.0003), "EPSG:4326")
    with pytest.raises(CoregError, match="geo.tif is in a geographic CRS"):
        coregister_rasters(dsm_path, geo)
    empty = write(tmp_path / "empty.tif", np.full((60, 60), np.nan), gt, "EPSG:32633")
    with pytest.raises(CoregError, match="empty.tif has no height"):
        coregister_rasters(empty, ref_path)
    other = write(tmp_path / "other.tif", ref, (X0 + 90000.0,) + ref_gt[1:], "EPSG:32633")
    with pytest.raises(CoregError, match="other.tif do not overlap"):
        coregister_rasters(dsm_path, other)
    feet = write(tmp_path / "furlong.tif", dsm, gt, "EPSG:32633", unit="furlong")
    with pytest.raises(CoregError, match="furlong.tif: the band's height unit"):
        coregister_rasters(feet, ref_path)
    assert issubclass(CoregError, ArchaeoOrthoError)


def test_agrees_with_xdem_nuthkaab(rugged, rugged_ref):
    """Against xdem's NuthKaab on the same pair (no tilt: xdem's Nuth & Kääb fits the shift alone) where xdem is
    installed.  xdem is not in requirements-dev.txt (rasterio, pyproj, geopandas, pandas with their own GDAL/PROJ;
    rasterio 1.4.4 breaks with affine 3): run it from a throw-away venv, see benchmarks/coregister.py."""
    xdem = pytest.importorskip("xdem")
    rasterio = pytest.importorskip("rasterio")
    from affine import Affine
    from osgeo import gdal

    ref, ref_gt = rugged_ref
    shift, dz = (37.0, -21.0), 3.2
    dsm, gt = block_dsm(rugged, shift, dz)
    ours = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), options=CoregOptions(tilt=False))
    mem = gdal.GetDriverByName("MEM").Create("", dsm.shape[1], dsm.shape[0], 1, gdal.GDT_Float32)
    mem.SetGeoTransform(gt)
    mem.GetRasterBand(1).SetNoDataValue(float("nan"))
    mem.GetRasterBand(1).WriteArray(dsm)
    bounds = (X0, Y0, X0 + ref.shape[1] * REF_CELL, Y0 + ref.shape[0] * REF_CELL)
    on_ref = gdal.Warp("", mem, format="MEM", outputBounds=bounds, width=ref.shape[1], height=ref.shape[0],
                       resampleAlg="average", dstNodata=float("nan")).ReadAsArray()
    nk = xdem.coreg.NuthKaab()
    nk.fit(ref.astype(np.float32), on_ref, transform=Affine.from_gdal(*ref_gt),
           crs=rasterio.crs.CRS.from_epsg(32633), random_state=42)
    aff = nk.meta["outputs"]["affine"]
    theirs = np.array([aff["shift_x"], aff["shift_y"], aff["shift_z"]])
    assert np.hypot(*(theirs[:2] - shift)) < 0.1 * REF_CELL  # xdem 0.2.3: 0.66 m
    assert np.hypot(*(np.array(ours.shift[:2]) - theirs[:2])) < 0.1 * REF_CELL
    assert abs(ours.shift[2] - theirs[2]) < 0.1
