"""Automatic control against national references (issue 32 item 3): a CRS without an EPSG code carried through the
chain, thresholds that scale with the reference (a coarse DEM's heights weighted, not dropped), the drops counted
per reason, a block too small for the reference's cells refused by name, a pair from one strip.

Unit tests on small synthetic rasters and candidates, and one run of the synthetic block (tests/test_autocontrol.py's
epoch 2, its photos cached under build/test-cache) against its reference averaged to 0.5 m / 5 m and warped into a
transverse Mercator CRS with no EPSG code (``tests/national.py``, as benchmarks/autocontrol_national.py degrades
Toledo's).  The Toledo figures are in that benchmark.
"""
import json
import math
import os

import numpy as np
import pytest

from core.geometry.crs import crs_identifier, epsg_code, transform_points
from core.geometry.similarity import Similarity
from core.georef.autocontrol.candidates import (
    KEPT,
    Candidate,
    consistent,
    drop_counts,
    estimate_own_sigma,
    reason,
    terrain_sigma,
)
from core.georef.autocontrol.errors import AutoControlError
from core.georef.autocontrol.options import AutoControlOptions
from core.georef.autocontrol.reference import Reference, result_crs
from core.io.raster import crs_epsg, write_cog
from tests import synthetic as syn
from tests.national import degrade, has_no_epsg, national_wkt

TOLEDO = (-83.57, 41.58)


def same_crs(a, b) -> bool:
    from osgeo import osr

    sa, sb = osr.SpatialReference(), osr.SpatialReference()
    sa.SetFromUserInput(a)
    sb.SetFromUserInput(b)
    return bool(sa.IsSame(sb))


@pytest.fixture
def exceptions_on():
    """GDAL/OSR exceptions on, as the plugin's raster module turns them on (AutoIdentifyEPSG then raises)."""
    from osgeo import gdal, osr

    gdal.UseExceptions()
    osr.UseExceptions()
    yield


def test_a_national_crs_has_no_epsg_code_and_is_recorded_as_its_wkt(exceptions_on):
    from osgeo import osr

    wkt = national_wkt(*TOLEDO)
    assert has_no_epsg(wkt)
    with pytest.raises(RuntimeError, match="Unsupported SRS"):  # what the automatic control tripped on
        osr.SpatialReference(wkt=wkt).AutoIdentifyEPSG()
    assert epsg_code(wkt) is None and crs_identifier(wkt) == wkt
    assert crs_epsg(wkt) == (None, False)  # the LAS writer's question: a WKT VLR only, no error
    assert epsg_code("EPSG:32617") == 32617 and crs_identifier("32617") == "EPSG:32617"
    utm = osr.SpatialReference()
    utm.ImportFromEPSG(32633)
    assert crs_identifier(utm.ExportToWkt()) == "EPSG:32633"  # a WKT that carries its code keeps it
    proj = "+proj=tmerc +lat_0=0 +lon_0=15 +k=0.9999 +x_0=500000 +y_0=0 +ellps=GRS80 +units=m +no_defs"
    assert epsg_code(proj) is None and crs_identifier(proj) == proj


def _rasters(folder, ortho_crs, dsm_crs, res=0.5, dsm_res=2.0, size=120.0):
    """A textured orthophoto and a tilted-plane DSM (z = 100 + 0.05 x) around UTM 33N (500000, 4600000), each
    written in its CRS (the DSM's corners transformed)."""
    from osgeo import gdal

    rng = np.random.default_rng(3)
    n = int(size / res)
    img = (rng.random((n, n)) * 255).astype(np.uint8)
    x0, y0 = 500000.0, 4600000.0 + size
    if ortho_crs != "EPSG:32633":
        x0, y0 = transform_points(np.array([[x0, y0]]), "EPSG:32633", ortho_crs)[0]
    ortho = os.path.join(folder, "ortho.tif")
    ds = gdal.GetDriverByName("GTiff").Create(ortho, n, n, 1, gdal.GDT_Byte)
    ds.SetGeoTransform((x0, res, 0.0, y0, 0.0, -res))
    from core.io.raster import crs_to_wkt

    ds.SetProjection(crs_to_wkt(ortho_crs))
    ds.GetRasterBand(1).WriteArray(img)
    ds = None
    m = int(size * 1.5 / dsm_res)
    xx = 500000.0 - 0.25 * size + (np.arange(m) + 0.5) * dsm_res
    z = np.tile(100.0 + 0.05 * (xx - 500000.0), (m, 1)).astype(np.float32)
    gx, gy = 500000.0 - 0.25 * size, 4600000.0 + 1.25 * size
    dsm_utm = os.path.join(folder, "dsm_utm.tif")
    write_cog(dsm_utm, z, (gx, dsm_res, 0.0, gy, 0.0, -dsm_res), "EPSG:32633")
    if dsm_crs == "EPSG:32633":
        return ortho, dsm_utm
    res = dsm_res / 111320.0 if dsm_crs == "EPSG:4326" else dsm_res  # degrees for a geographic DSM
    return ortho, degrade(dsm_utm, os.path.join(folder, "dsm.tif"), res, crs_to_wkt(dsm_crs))


@pytest.mark.parametrize("dsm_in", ["national", "utm"])
def test_a_reference_in_a_national_crs_is_read_in_it(tmp_path, exceptions_on, dsm_in):
    wkt = national_wkt(15.0, 41.5)
    ortho, dsm = _rasters(str(tmp_path), wkt, wkt if dsm_in == "national" else "EPSG:32633")
    ref = Reference(ortho, dsm)
    try:
        assert ref.crs == ref.crs_wkt and epsg_code(ref.crs) is None  # no traceback, the WKT itself
        assert result_crs(ortho) == ref.crs and not ref.notes
        assert math.isclose(ref.gsd, 0.5)
        grey, valid, gt = ref.grey(ref.bounds, 1.0)
        assert valid.mean() > 0.9 and grey[valid].std() > 10
        # heights at points of the national CRS: the DSM's plane, wherever the DSM's CRS
        utm = np.array([[500030.0, 4600060.0], [500090.0, 4600030.0]])
        xy = transform_points(utm, "EPSG:32633", wkt)
        np.testing.assert_allclose(ref.heights(xy[:, 0], xy[:, 1]), 100.0 + 0.05 * (utm[:, 0] - 500000.0),
                                   atol=0.05)
    finally:
        ref.close()


def test_a_rough_dem_gives_a_height_sigma_not_a_rejection():
    # a 10-30 m DEM over houses: misfits of metres, which the 0.6 m limit dropped; now a sigma that grows with them
    flat, rough = terrain_sigma(0.0, 0.1, 0.3), terrain_sigma(0.05, 2.2, 0.3)
    assert flat < 0.1 and math.isclose(rough, math.hypot(0.05 * 0.3, 1.1))
    assert terrain_sigma(0.5, 0.0, 2.0) == pytest.approx(1.0)  # the slope times sigma XY


def _candidates(n=60, sigma_z=0.5, rough=None, seed=0):
    """Candidates of a 150 m block through a known similarity, heights off by N(0, sigma_z) (+ a terrain
    sigma ``rough`` on every other one, whose heights are off by that much more)."""
    rng = np.random.default_rng(seed)
    model = np.column_stack([rng.uniform(-1, 1, (n, 2)), rng.normal(0, 0.02, n)])
    sim = Similarity(75.0, np.eye(3), np.array([1000.0, 2000.0, 50.0]))
    world = sim.apply(model)
    out = []
    for i in range(n):
        t = rough if (rough and i % 2) else 0.05
        dz = rng.normal(0, math.hypot(sigma_z, t))
        out.append(Candidate(f"auto_{i:03d}", world[i, 0] + rng.normal(0, 0.2), world[i, 1] + rng.normal(0, 0.2),
                             world[i, 2] + dz, 0.3, math.hypot(t, 3.3), model_xyz=model[i], sigma_z_terrain=t))
    return out


def test_heights_from_a_coarse_dem_are_judged_by_their_sigma_and_the_dem_noise_estimated():
    g = 0.6  # the match's grid: a 0.6 m orthophoto
    cands = _candidates(sigma_z=0.5, rough=3.0)
    cands[3].x += 25.0  # a change between the epochs: far off in X, Y
    cands[8].y -= 20.0
    consistent(cands, 10.0 * g)
    dropped = [c.name for c in cands if c.status != KEPT]
    assert dropped == ["auto_003", "auto_008"]  # the rough heights (metres off) stay, weighted
    assert all(reason(c.status) == "off the similarity of the others" for c in cands if c.status != KEPT)
    assert drop_counts(cands) == {"off the similarity of the others": 2}
    # the DEM's own noise: the prior (a third of a 10 m cell, 3.3 m) tightened by the heights that agree
    own = estimate_own_sigma(cands, 0.2, 10.0 / 3.0)
    assert 0.35 < own < 0.7
    # a DEM that is as bad as its cells say keeps the prior (the data only tighten it)
    bad = _candidates(sigma_z=6.0, seed=1)
    consistent(bad, 10.0 * g)
    assert estimate_own_sigma(bad, 0.2, 10.0 / 3.0) == pytest.approx(10.0 / 3.0)
    # and fewer than 8 heights tell nothing
    few = _candidates(n=6)
    consistent(few, 10.0 * g)
    assert estimate_own_sigma(few, 0.2, 3.3) is None


def test_the_old_absolute_bound_would_have_dropped_the_coarse_dem_heights():
    """The 3-D bound max(10 g, 0.5 m) of one distance, before: heights 3 m off from a 24 m DEM fall outside it
    at a 0.1 m grid; with their own sigma they are kept (the test above would fail on the old rule)."""
    cands = _candidates(sigma_z=3.0, rough=None, seed=2)
    consistent(cands, 10.0 * 0.1)
    assert sum(c.status == KEPT for c in cands) >= 0.95 * len(cands)
    off = np.array([abs(c.z_residual) for c in cands])
    assert (off > 1.0).sum() >= 0.5 * len(cands)  # the old 1 m 3-D bound would have dropped these


def test_a_block_smaller_than_one_tile_of_the_reference_is_refused_by_name(tmp_path):
    from core.georef.autocontrol.search import check_block_pixels as _check_block_pixels

    class Ref:
        ortho_path = str(tmp_path / "naip_2m.tif")
        crs_wkt = national_wkt(*TOLEDO)
        gsd = 2.0

    opt = AutoControlOptions()
    with pytest.raises(AutoControlError, match=r"naip_2m.tif is too coarse for a block this small.*107 pixels"):
        _check_block_pixels((0.0, 0.0, 214.0, 150.0), 2.0, Ref(), 0.16, opt)
    _check_block_pixels((0.0, 0.0, 214.0, 150.0), 0.6, Ref(), 0.16, opt)  # 357 pixels at 0.6 m: fine
    with pytest.raises(AutoControlError, match="photos' ground resolution"):
        _check_block_pixels((0.0, 0.0, 214.0, 150.0), 2.0, type("R", (Ref,), {"gsd": 0.5})(), 2.0, opt)


# --- the synthetic block against a national reference ------------------------------------------------------------

@pytest.fixture(scope="module")
def national_epochs(tmp_path_factory):
    """(block, photos, orthophoto, DSM, WKT): tests/test_autocontrol.py's epochs with the reference averaged to
    0.5 m (6.5 x the photos' 0.077 m) / 5 m (20 x its DSM) in a transverse Mercator CRS without an EPSG code."""
    from tests.test_autocontrol import BLOCK, CACHE, write_reference

    block = syn.vertical_block(epoch=2, **BLOCK)
    photos_dir = os.path.join(CACHE, "photos")
    if not os.path.isfile(os.path.join(CACHE, "done")):
        os.makedirs(CACHE, exist_ok=True)
        block.render(photos_dir)
        write_reference(syn.vertical_block(epoch=1, **BLOCK).scene, CACHE)
        open(os.path.join(CACHE, "done"), "w").close()
    photos = {n: os.path.join(photos_dir, n) for n in block.names}
    lon, lat = transform_points(syn.ORIGIN[None, :2], syn.CRS, "EPSG:4326")[0]
    wkt = national_wkt(lon, lat)
    folder = str(tmp_path_factory.mktemp("national"))
    ortho = degrade(os.path.join(CACHE, "ref_ortho.tif"), os.path.join(folder, "ortho_0.5m.tif"), 0.5, wkt)
    dsm = degrade(os.path.join(CACHE, "ref_dsm.tif"), os.path.join(folder, "dsm_5m.tif"), 5.0, wkt)
    return block, photos, ortho, dsm, wkt


def _camera_errors(ws_dir, block, crs):
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    rec, tr = Layout(Workspace.open(ws_dir)).load_georef_model()
    names = sorted(im.name for im in rec.images.values())
    c = {im.name: -np.asarray(im.cam_from_world().matrix())[:, :3].T @ np.asarray(im.cam_from_world().matrix())[:, 3]
         for im in rec.images.values()}
    world = np.array([c[n] for n in names]) + tr.offset
    utm = transform_points(world, crs, syn.CRS)
    truth = np.array([block.shot(n).centre + syn.ORIGIN for n in names])
    return np.hypot(*(utm - truth)[:, :2].T), np.abs(utm - truth)[:, 2]


def test_the_synthetic_block_against_a_national_reference(tmp_path, national_epochs, exceptions_on):
    """The whole chain in a CRS with no EPSG code: the result, the workspace, the cameras layer and the report
    carry the WKT; the check points (given in UTM) are transformed into it; the candidates a 5 m DSM's relief would
    have dropped are weighted; the drops are counted per reason in the log, autocontrol.json and the report."""
    from osgeo import ogr, osr

    from core.georef.autocontrol.stage import autocontrol_workspace
    from core.project.layout import Layout
    from core.project.workspace import Workspace
    from tests.test_autocontrol import _check_points
    from tests.workspaces import synthetic_workspace

    block, photos, ortho, dsm, wkt = national_epochs
    ws_dir = synthetic_workspace(str(tmp_path / "ws"), block, block.truth_reconstruction(seed=5), photos=photos)
    cams, _ = block.camera_positions(sigma=3.0)  # rough positions in UTM: taken into the national CRS
    cams_nat = transform_points(np.array([[c.x, c.y, c.z] for c in cams]), syn.CRS, wkt)
    for c, p in zip(cams, cams_nat):
        c.x, c.y, c.z = (float(v) for v in p)
    result = autocontrol_workspace(ws_dir, AutoControlOptions(
        n_features=6000, max_candidates=60, refine_intrinsics=False, reference_ortho=ortho, reference_dsm=dsm,
        prior="gps", camera_positions=cams, check_points=_check_points(block)))
    f = result.georef.figures
    print(f"\nnational reference: {result.figures}; check XY {f['CHECK_RMSE_XY']:.3f} m, Z {f['CHECK_RMSE_Z']:.3f} m; "
          f"{result.messages}")
    assert same_crs(result.crs, wkt) and Workspace.open(ws_dir).crs == result.crs and epsg_code(result.crs) is None
    assert result.n_kept >= 12
    assert f["CHECK_RMSE_XY"] <= 1.5 * 0.5  # the tolerances, in the reference's cells
    exy, ez = _camera_errors(ws_dir, block, wkt)
    assert np.median(exy) <= 1.5 * 0.5 and np.median(ez) <= 2.0 * 0.5
    lay = Layout(Workspace.open(ws_dir))
    doc = json.load(open(lay.autocontrol_json))
    assert doc["crs"] == result.crs and doc["dropped"] == drop_counts(
        [Candidate(c["name"], 0, 0, 0, 0, 0, status=c["status"]) for c in doc["candidates"]])
    rough = [c for c in doc["candidates"] if c["status"] == KEPT and c["sigma_z_terrain"] > 0.3]
    assert rough, "no candidate on the DSM's relief was kept: the relief limit is back"
    assert any(m.startswith("reference DSM heights: sigma") for m in result.messages)
    cameras = ogr.Open(result.cameras_path.split("|")[0])
    assert cameras.GetLayer(0).GetSpatialRef().IsSame(osr.SpatialReference(wkt=wkt))
    cameras = None
    from core.report.options import ReportOptions
    from core.report.stage import build_report

    html = open(build_report(ws_dir, ReportOptions(uncertainty=False)).path, encoding="utf-8").read()
    assert "Automatic control" in html and "no EPSG code: +proj=tmerc" in html
    if doc["dropped"]:
        assert "dropped because" in html and next(iter(doc["dropped"])) in html


def test_a_pair_from_one_strip_is_placed_from_two_rough_positions(tmp_path, national_epochs):
    """Two photos of one strip (every point seen twice at most) and two rough positions: the pair's baseline and
    its tie points' plane give the prior, the candidates are seen in 2 photos, and the pair is placed."""
    from core.georef.autocontrol.stage import autocontrol_workspace
    from tests.test_autocontrol import CACHE
    from tests.workspaces import synthetic_workspace

    block, photos, _, _, wkt = national_epochs
    # a pair covers 70 m: 142 cells of 0.5 m, fewer than the match needs (refused, as the test above shows); 0.25 m
    ortho = degrade(os.path.join(CACHE, "ref_ortho.tif"), str(tmp_path / "ortho_0.25m.tif"), 0.25, wkt)
    dsm = degrade(os.path.join(CACHE, "ref_dsm.tif"), str(tmp_path / "dsm_2.5m.tif"), 2.5, wkt)
    pair = ["S1_02.jpg", "S1_03.jpg"]
    ws_dir = synthetic_workspace(str(tmp_path / "pair"), block, block.truth_reconstruction(seed=5, images=pair),
                                 photos={n: photos[n] for n in pair})
    cams, _ = block.camera_positions(sigma=3.0)
    cams = [c for c in cams if c.image in pair]
    xyz = transform_points(np.array([[c.x, c.y, c.z] for c in cams]), syn.CRS, wkt)
    for c, p in zip(cams, xyz):
        c.x, c.y, c.z = (float(v) for v in p)
    result = autocontrol_workspace(ws_dir, AutoControlOptions(
        n_features=6000, max_candidates=60, refine_intrinsics=False, reference_ortho=ortho, reference_dsm=dsm,
        prior="gps", camera_positions=cams))
    print(f"\npair: {result.figures}; {result.messages}")
    assert result.n_kept >= 6
    kept = [c for c in result.candidates if c.status == KEPT]
    assert all(len(c.observations) == 2 for c in kept)
    exy, ez = _camera_errors(ws_dir, block, wkt)
    assert np.max(exy) <= 2.0 * 0.5 and np.max(ez) <= 3.0 * 0.5


def test_a_web_mercator_or_geographic_reference_is_worked_in_metres(tmp_path, exceptions_on):
    """A Web Mercator orthophoto (its metres 1 / cos(latitude) ground metres) and a DSM in longitude / latitude:
    the control is made in the UTM zone of the orthophoto's centre, said in a note, heights unchanged."""
    ortho, dsm = _rasters(str(tmp_path), "EPSG:3857", "EPSG:4326", res=0.5, dsm_res=2.0)
    ref = Reference(ortho, dsm)
    try:
        assert ref.crs == "EPSG:32633" and any("Mercator" in n and "EPSG:32633" in n for n in ref.notes)
        assert result_crs(ortho) == "EPSG:32633"  # what the faces give check points and positions in
        lat = 41.5
        assert ref.gsd == pytest.approx(0.5 * math.cos(math.radians(lat)), rel=0.05)  # ground metres
        utm = np.array([[500030.0, 4600060.0], [500090.0, 4600030.0]])
        np.testing.assert_allclose(ref.heights(utm[:, 0], utm[:, 1]), 100.0 + 0.05 * (utm[:, 0] - 500000.0),
                                   atol=0.1)
        grey, valid, _ = ref.grey(ref.bounds, 1.0)
        assert valid.mean() > 0.5 and grey[valid].std() > 10
    finally:
        ref.close()


def test_dsm_heights_in_feet_are_read_in_the_orthophotos_unit(tmp_path, exceptions_on):
    """A DSM whose band says its heights are in feet: taken to the orthophoto's metres (a unit read, not
    assumed)."""
    from osgeo import gdal

    ortho, dsm = _rasters(str(tmp_path), "EPSG:32633", "EPSG:32633")
    ds = gdal.Open(dsm)
    feet = gdal.Translate(str(tmp_path / "dsm_ft.tif"), ds, scaleParams=[[0, 1, 0, 1 / 0.3048]], outputType=gdal.GDT_Float32)
    feet.GetRasterBand(1).SetUnitType("ft")
    feet = None
    ref = Reference(ortho, str(tmp_path / "dsm_ft.tif"))
    try:
        assert ref.z_scale == pytest.approx(0.3048) and any("ft" in n for n in ref.notes)
        np.testing.assert_allclose(ref.heights(np.array([500030.0]), np.array([4600060.0])), [101.5], atol=0.05)
    finally:
        ref.close()


def test_products_carry_a_crs_without_epsg_code(tmp_path, exceptions_on):
    """The later stages' writers with the workspace's WKT CRS: a DSM GeoTIFF keeps it, the LAS point cloud
    gets its WKT VLR (no GeoKey: there is no code), no 'Unsupported SRS' on the way."""
    from osgeo import gdal, osr

    from core.io.raster import read_las, write_las

    wkt = national_wkt(*TOLEDO)
    path = write_cog(str(tmp_path / "dsm.tif"), np.ones((4, 4), np.float32), (300000.0, 1.0, 0.0, 150000.0, 0.0, -1.0),
                     wkt)
    assert osr.SpatialReference(wkt=gdal.Open(path).GetProjection()).IsSame(osr.SpatialReference(wkt=wkt))
    n = write_las(str(tmp_path / "dense.las"), [(np.zeros((3, 3)), np.zeros((3, 3), np.uint8))],
                  (300000.0, 150000.0, 0.0), wkt)
    _, _, header = read_las(str(tmp_path / "dense.las"))
    assert n == 3 and [rid for _, rid, _ in header["vlrs"]] == [2112]
    stored = header["vlrs"][0][2].rstrip(b"\0").decode()
    assert osr.SpatialReference(wkt=stored).IsSame(osr.SpatialReference(wkt=wkt))


def test_a_virtual_reference_whose_source_is_gone_is_named_before_any_work(tmp_path):
    """Issue 36 item 10: a VRT reference whose source file was moved ended in a traceback from gdal.Warp in
    Reference.grey, after the matching had started; now the reference is refused when opened, naming both files."""
    from osgeo import gdal, osr

    from core.georef.autocontrol.errors import AutoControlError
    from core.georef.autocontrol.reference import Reference

    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    paths = {}
    for name in ("ortho", "dsm"):
        ds = gdal.GetDriverByName("GTiff").Create(str(tmp_path / f"{name}.tif"), 64, 64, 1, gdal.GDT_Float32)
        ds.SetGeoTransform((500000.0, 1.0, 0.0, 4000000.0, 0.0, -1.0))
        ds.SetProjection(srs.ExportToWkt())
        ds.GetRasterBand(1).Fill(100.0)
        ds = None
        paths[name] = str(tmp_path / f"{name}.tif")
    vrt = str(tmp_path / "ortho.vrt")
    gdal.BuildVRT(vrt, [paths["ortho"]])
    Reference(vrt, paths["dsm"]).close()  # while its source is there
    os.rename(paths["ortho"], str(tmp_path / "moved.tif"))
    with pytest.raises(AutoControlError, match=r"ortho\.vrt refers to .*ortho\.tif, which does not exist"):
        Reference(vrt, paths["dsm"])


def test_a_wrong_reference_is_named_with_what_is_wrong_before_any_work(tmp_path):
    """Issue 36 item 12: an orthophoto of 1 x 1 pixel or all nodata, a DSM that is a picture or all nodata, the two
    swapped: each said which reference is wrong and why (was '0 candidate(s) kept, 4 needed' after the work);
    nothing is written beside the user's files."""
    from osgeo import gdal, osr

    from core.georef.autocontrol.errors import AutoControlError
    from core.georef.autocontrol.reference import Reference

    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)

    def raster(name, n, bands, dtype, fill, nodata=None, unit="", rgb=False):
        path = str(tmp_path / name)
        ds = gdal.GetDriverByName("GTiff").Create(path, n, n, bands, dtype, ["PHOTOMETRIC=RGB"] if rgb else [])
        ds.SetGeoTransform((500000.0, 1.0, 0.0, 4000000.0, 0.0, -1.0))
        ds.SetProjection(srs.ExportToWkt())
        for k in range(bands):
            band = ds.GetRasterBand(k + 1)
            if nodata is not None:
                band.SetNoDataValue(nodata)
            if unit:
                band.SetUnitType(unit)
            band.Fill(fill)
        ds = None
        return path

    ortho = raster("ortho.tif", 64, 3, gdal.GDT_Byte, 120, rgb=True)
    dsm = raster("dsm.tif", 64, 1, gdal.GDT_Float32, 150.0, unit="m")
    Reference(ortho, dsm).close()  # the right ones
    cases = [
        (raster("one.tif", 1, 3, gdal.GDT_Byte, 120, rgb=True), dsm, r"one\.tif is 1 x 1 pixels: too small"),
        (raster("empty.tif", 64, 1, gdal.GDT_Byte, 0, nodata=0), dsm, r"orthophoto .*empty\.tif has no data"),
        (ortho, raster("nodsm.tif", 64, 1, gdal.GDT_Float32, -9999.0, nodata=-9999.0),
         r"DSM .*nodsm\.tif has no data"),
        (ortho, ortho, r"DSM .*ortho\.tif is an image, not heights"),
        (dsm, ortho, "the references look swapped"),
    ]
    before = sorted(os.listdir(tmp_path))
    for o, d, message in cases:
        with pytest.raises(AutoControlError, match=message):
            Reference(o, d)
    assert sorted(os.listdir(tmp_path)) == before  # no .aux.xml written beside them
