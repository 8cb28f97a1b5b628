"""Multi-epoch registration (issue 16 item 2): a second epoch registered to an earlier, georeferenced block with
no GCP and no prior, its orthophoto on the earlier block's DSM, and the difference of the two epochs' DSMs.

The earlier block is epoch 1 of the synthetic scene as a georeferenced workspace whose products are the scene's
truth (a true orthophoto at 0.1 m and a DSM at 0.25 m, EPSG:32633: the reference rasters tests/test_autocontrol.py
caches); the later block is epoch 2 (new crop marks, the car parked elsewhere, a new building, the sun from the
other side), its photos rendered once (the same cache) and aligned in an arbitrary model frame.  The difference
is taken against epoch 2's truth DSM on another grid (the figures exactly) and against its own DSM built from the
registered photos (the chain).
"""
import json
import os
import re
import shutil
import subprocess

import cv2
import numpy as np
import pytest
from osgeo import gdal, osr

from core.georef.autocontrol.epochs import register_epoch
from core.georef.autocontrol.errors import AutoControlError
from core.georef.autocontrol.options import AutoControlOptions
from core.io.raster import read_dsm, write_cog
from core.ortho.options import OrthoOptions
from core.ortho.stage import build_orthophoto_workspace
from core.project.layout import Layout
from core.project.workspace import Workspace
from core.terrain.difference import dsm_difference
from core.terrain.options import TerrainError
from tests import synthetic as syn
from tests.test_autocontrol import BLOCK, CACHE, FAST, REF_GSD, write_reference
from tests.workspaces import synthetic_workspace

DSM_B_GSD = 0.3  # the later epoch's DSM on another grid than the earlier one's (0.25 m)


def _photos(block):
    """The epoch-2 photos and the epoch-1 reference rasters of tests/test_autocontrol.py's cache (made here if
    absent, the same way)."""
    photos_dir = os.path.join(CACHE, "photos")
    done = os.path.join(CACHE, "done")
    if not os.path.isfile(done):
        os.makedirs(CACHE, exist_ok=True)
        block.render(photos_dir)
        write_reference(syn.vertical_block(epoch=1, **BLOCK).scene, CACHE)
        open(done, "w").close()
    return {n: os.path.join(photos_dir, n) for n in block.names}


def _earlier_workspace(root, block, ortho=True, dsm=True, georeferenced=True):
    """Epoch 1 as a georeferenced workspace (its truth model in the local frame) with the truth orthophoto and
    DSM as its products (each optional)."""
    ws = synthetic_workspace(root, block, block.truth_reconstruction(seed=5, model_from_local=None, n_points=300),
                             georeferenced=georeferenced, crs=syn.CRS, offset=syn.ORIGIN)
    lay = Layout(Workspace.open(ws))
    if ortho:
        shutil.copy(os.path.join(CACHE, "ref_ortho.tif"), lay.default_orthomosaic)
    if dsm:
        shutil.copy(os.path.join(CACHE, "ref_dsm.tif"), lay.default_dsm)
    return ws


@pytest.fixture(scope="module")
def registered(tmp_path_factory):
    """(epoch-1 block, epoch-2 block, earlier workspace, later workspace, the AutoControlResult): the later epoch
    registered with no GCP and no prior (unknown rotation and scale)."""
    b1, b2 = syn.vertical_block(epoch=1, **BLOCK), syn.vertical_block(epoch=2, **BLOCK)
    photos = _photos(b2)
    root = tmp_path_factory.mktemp("epochs")
    ws1 = _earlier_workspace(str(root / "epoch1"), b1)
    ws2 = synthetic_workspace(str(root / "epoch2"), b2, b2.truth_reconstruction(seed=5), photos=photos)
    checks = b2.gcp_set([], noise_px=0.3, only=[p.name for p in b2.gcps if p.kind == "ground"])
    result = register_epoch(ws2, ws1, AutoControlOptions.of(FAST, prior="none", check_points=checks))
    return b1, b2, ws1, ws2, result


def test_second_epoch_registered_on_the_earlier_block_with_no_gcp_and_no_prior(registered):
    _b1, _b2, ws1, ws2, result = registered
    f = result.georef.figures
    print(f"\nepoch 2 on epoch 1: {result.n_kept} automatic GCPs kept; check points XY {f['CHECK_RMSE_XY']:.3f} m, "
          f"Z {f['CHECK_RMSE_Z']:.3f} m (n={f['CHECK_N']}); {result.figures}")
    assert result.prior == "none" and any("coarse search" in m for m in result.messages)
    assert f["CHECK_N"] >= 6
    assert f["CHECK_RMSE_XY"] <= 1.5 * REF_GSD
    assert f["CHECK_RMSE_Z"] <= 2.0 * REF_GSD
    assert result.n_kept >= 20
    assert Workspace.open(ws2).crs == syn.CRS
    # autocontrol.json says which workspace was the reference, beside its two rasters (the report reads those)
    lay1 = Layout(Workspace.open(ws1))
    doc = json.load(open(Layout(Workspace.open(ws2)).autocontrol_json))
    assert os.path.samefile(doc["reference_workspace"], ws1)
    assert os.path.samefile(doc["reference_ortho"], lay1.orthomosaic())
    assert os.path.samefile(doc["reference_dsm"], lay1.dsm())
    assert doc["figures"]["kept"] == result.n_kept


def _mark_shift(block, arr, gt, xw, yw, n=32):
    """(dx, dy, response) in cells of the mosaic at world (xw, yw) against the scene's true orthoimage (phase
    correlation of n x n cells, as tests/test_ortho.py measures them); None near nodata."""
    c, r = int((xw - gt[0]) / gt[1]), int((yw - gt[3]) / gt[5])
    r0, c0 = r - n // 2, c - n // 2
    if r0 < 0 or c0 < 0 or r0 + n > arr.shape[1] or c0 + n > arr.shape[2]:
        return None
    if (arr[-1, r0:r0 + n, c0:c0 + n] == 0).mean() > 0.05:
        return None
    xs = gt[0] + (c0 + np.arange(n) + 0.5) * gt[1] - syn.ORIGIN[0]
    ys = gt[3] + (r0 + np.arange(n) + 0.5) * gt[5] - syn.ORIGIN[1]
    x, y = np.meshgrid(xs, ys)
    truth = syn._sample(block.scene.texture_raster(), *block.scene.raster_coords(x, y, block.scene.texture_res))
    grey = arr[:3, r0:r0 + n, c0:c0 + n].mean(axis=0)
    win = cv2.createHanningWindow((n, n), cv2.CV_64F)
    (dx, dy), resp = cv2.phaseCorrelate(truth.astype(np.float64), grey.astype(np.float64), win)
    return dx, dy, resp


def test_orthophoto_of_the_second_epoch_on_the_earlier_dsm(registered):
    """Both epochs on one surface: epoch 2's orthophoto built on epoch 1's DSM puts the true ground marks where
    they belong, within 1.5 GSD."""
    _b1, b2, ws1, ws2, _ = registered
    dsm1 = Layout(Workspace.open(ws1)).dsm()
    out = build_orthophoto_workspace(ws2, OrthoOptions(dsm_path=dsm1, radiometry=False))
    assert Workspace.open(ws2).stage("orthophoto")["parameters"]["dsm"] == os.path.abspath(dsm1)
    ds = gdal.Open(out.orthomosaic)
    arr = ds.ReadAsArray().astype(np.float32)
    gt = ds.GetGeoTransform()
    marks = [_mark_shift(b2, arr, gt, *p.world[:2]) for p in b2.gcps if p.kind == "ground"]
    marks = np.array([m for m in marks if m and m[2] > 0.2])
    rmse = float(np.sqrt(np.mean(marks[:, 0] ** 2 + marks[:, 1] ** 2))) * gt[1]
    print(f"\nepoch 2 on epoch 1's DSM: ground marks {len(marks)}, RMSE {rmse:.3f} m = {rmse / b2.gsd:.2f} GSD "
          f"(cells of {gt[1]:g} m)")
    assert len(marks) >= 6, marks
    assert rmse <= 1.5 * b2.gsd


def _write_truth_dsm(scene, path, res, shift=(0.0, 0.0)):
    """The scene's surface on a ``res`` grid whose corner is off the reference's cells by ``shift`` metres."""
    xmin, ymin, xmax, ymax = scene.bounds
    nx, ny = int((xmax - xmin) / res) - 2, int((ymax - ymin) / res) - 2
    x0, y0 = xmin + res + shift[0], ymax - res + shift[1]
    yy, xx = np.meshgrid(y0 - (np.arange(ny) + 0.5) * res, x0 + (np.arange(nx) + 0.5) * res, indexing="ij")
    gt = (x0 + syn.ORIGIN[0], res, 0.0, y0 + syn.ORIGIN[1], 0.0, -res)
    return write_cog(path, scene.height_at(xx, yy).astype(np.float32), gt, syn.CRS)


def test_dsm_difference_shows_the_new_building_and_the_moved_car(registered, tmp_path):
    b1, b2, ws1, _ws2, _ = registered
    dsm1 = Layout(Workspace.open(ws1)).dsm()
    dsm2 = _write_truth_dsm(b2.scene, str(tmp_path / "epoch2-dsm.tif"), DSM_B_GSD, shift=(0.11, -0.07))
    out = str(tmp_path / "difference.tif")
    r = dsm_difference(dsm1, dsm2, out)
    d, gt, wkt = read_dsm(out)
    ds = gdal.Open(out)
    assert ds.GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE") == "COG"
    assert ds.GetRasterBand(1).DataType == gdal.GDT_Float32
    a_ds = gdal.Open(dsm1)
    assert gt == a_ds.GetGeoTransform() and d.shape == (a_ds.RasterYSize, a_ds.RasterXSize)  # a's grid
    assert osr.SpatialReference(wkt=wkt).IsSame(osr.SpatialReference(wkt=a_ds.GetProjection()))
    assert np.isnan(d[0]).all() and np.isnan(d[:, 0]).all()  # b does not reach a's first row and column
    assert r.cells == int(np.isfinite(d).sum()) > 0.9 * d.size
    xs = gt[0] + (np.arange(d.shape[1]) + 0.5) * gt[1] - syn.ORIGIN[0]
    ys = gt[3] + (np.arange(d.shape[0]) + 0.5) * gt[5] - syn.ORIGIN[1]
    x, y = np.meshgrid(xs, ys)
    new = b2.scene.buildings[6]
    car1, car2 = b1.scene.buildings[5], b2.scene.buildings[5]
    inside = {name: b.contains(x, y, margin=-0.5) & np.isfinite(d) for name, b in
              (("building", new), ("car, new place", car2), ("car, old place", car1))}
    near = np.zeros(d.shape, bool)
    for b in b1.scene.buildings + b2.scene.buildings:
        near |= b.contains(x, y, margin=1.0)
    rest = np.isfinite(d) & ~near
    height = new.roof - float(b2.scene.ground_at(new.cx, new.cy))
    print(f"\nDSM difference: {r.figures()}; building min {d[inside['building']].min():.2f} m "
          f"(height {height:.2f} m), car new place min {d[inside['car, new place']].min():.2f} m, old place max "
          f"{d[inside['car, old place']].max():.2f} m; elsewhere median {np.median(d[rest]):.4f} m, "
          f"95 % |d| {np.percentile(np.abs(d[rest]), 95):.4f} m")
    assert all(m.sum() >= 10 for m in inside.values()), {k: int(m.sum()) for k, m in inside.items()}
    assert (d[inside["building"]] > height / 2).all()
    assert (d[inside["car, new place"]] > 0.75).all()  # the car: 1.5 m tall
    assert (d[inside["car, old place"]] < -0.75).all()
    assert abs(np.median(d[rest])) < 0.1 and np.percentile(np.abs(d[rest]), 95) < 0.1
    # the figures are those of the raster; changed: the building and the car (twice), nothing away from the
    # buildings (at a roof's edge the bilinear warp of b's coarser cells mixes roof and ground)
    v = d[np.isfinite(d)]
    assert r.median == pytest.approx(np.median(v), abs=1e-4) and r.std == pytest.approx(v.std(), rel=1e-4)
    assert r.p5 <= r.median <= r.p95 and r.changed == int((np.abs(v) > 1.0).sum())
    assert sum(m.sum() for m in inside.values()) <= r.changed and not (np.abs(d[rest]) > 1.0).any()


def test_dsm_difference_against_the_second_epochs_own_dsm(registered, tmp_path):
    """The chain: epoch 2's DSM built from its photos as registered (Build DSM), minus epoch 1's: the new building
    and the moved car stand out, and where nothing changed the two surfaces agree (the registration's Z)."""
    from core.dense.stage import build_dsm_workspace

    b1, b2, ws1, ws2, _ = registered
    dsm2 = build_dsm_workspace(ws2).dsm_path
    r = dsm_difference(Layout(Workspace.open(ws1)).dsm(), dsm2, str(tmp_path / "difference.tif"))
    d, gt, _ = read_dsm(r.path)
    x, y = np.meshgrid(gt[0] + (np.arange(d.shape[1]) + 0.5) * gt[1] - syn.ORIGIN[0],
                       gt[3] + (np.arange(d.shape[0]) + 0.5) * gt[5] - syn.ORIGIN[1])
    new, car1, car2 = b2.scene.buildings[6], b1.scene.buildings[5], b2.scene.buildings[5]
    inside = [b.contains(x, y, margin=-0.5) & np.isfinite(d) for b in (new, car2, car1)]
    near = np.zeros(d.shape, bool)
    for b in b1.scene.buildings + b2.scene.buildings:
        near |= b.contains(x, y, margin=1.0)
    rest = np.isfinite(d) & ~near
    height = new.roof - float(b2.scene.ground_at(new.cx, new.cy))
    print(f"\nepoch 2's own DSM - epoch 1's: {r.cells} cells, building min {d[inside[0]].min():.2f} m, car new place "
          f"min {d[inside[1]].min():.2f} m, old place max {d[inside[2]].max():.2f} m; elsewhere median "
          f"{np.median(d[rest]):.4f} m, 95 % |d| {np.percentile(np.abs(d[rest]), 95):.3f} m")
    assert all(m.sum() >= 10 for m in inside) and rest.sum() > 10000
    assert (d[inside[0]] > height / 2).all()
    assert (d[inside[1]] > 0.75).all() and (d[inside[2]] < -0.75).all()
    assert abs(np.median(d[rest])) < 0.1 and np.percentile(np.abs(d[rest]), 95) < 0.2


# ---------------------------------------------------------------------------------------------------------------
# small rasters: another CRS, bad input, qgis_process
# ---------------------------------------------------------------------------------------------------------------

def _plane(x, y):
    return 200.0 + 0.02 * (x - 500000.0) - 0.01 * (y - 4600000.0)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """(a, b, box): a plane on a 1 m grid in UTM 33N; b the same plane 0.3 m higher with a 3 m box on it, on a
    0.7 m grid in ETRS89-LAEA (EPSG:3035) over part of a; box (xmin, ymin, xmax, ymax) in UTM."""
    folder = tmp_path_factory.mktemp("pair")
    n = 80
    gt = (500000.0, 1.0, 0.0, 4600000.0 + n, 0.0, -1.0)
    x, y = np.meshgrid(500000.0 + np.arange(n) + 0.5, 4600000.0 + n - np.arange(n) - 0.5)
    a = write_cog(str(folder / "a.tif"), _plane(x, y).astype(np.float32), gt, syn.CRS)
    box = (500030.0, 4600030.0, 500045.0, 4600050.0)
    big = 0.3 * np.ones_like(x)
    big[(x > box[0]) & (x < box[2]) & (y > box[1]) & (y < box[3])] += 3.0
    fine = write_cog(str(folder / "b-utm.tif"), (_plane(x, y) + big).astype(np.float32), gt, syn.CRS)
    b = str(folder / "b.tif")
    gdal.Warp(b, fine, dstSRS="EPSG:3035", xRes=0.7, yRes=0.7, resampleAlg="near", format="GTiff",
              dstNodata=-9999.0, outputBoundsSRS=syn.CRS, outputBounds=(500010.0, 4600005.0, 500070.0, 4600075.0))
    return a, b, box


def test_difference_across_crs_on_the_grid_of_a(pair, tmp_path):
    a, b, box = pair
    r = dsm_difference(a, b, str(tmp_path / "d.tif"))
    d, gt, _ = read_dsm(r.path)
    x, y = np.meshgrid(gt[0] + np.arange(d.shape[1]) + 0.5, gt[3] - np.arange(d.shape[0]) - 0.5)
    print(f"\nacross CRS: {r.figures()}")
    assert gt == gdal.Open(a).GetGeoTransform()
    assert np.isnan(d[:, :3]).all() and np.isnan(d[:, -3:]).all() and r.cells < 0.8 * d.size  # b covers part of a
    flat = np.isfinite(d) & ~((x > box[0] - 2) & (x < box[2] + 2) & (y > box[1] - 2) & (y < box[3] + 2))
    assert flat.sum() > 1500
    assert np.abs(d[flat] - 0.3).max() < 0.05
    assert r.median == pytest.approx(0.3, abs=0.01)
    inner = (x > box[0] + 2) & (x < box[2] - 2) & (y > box[1] + 2) & (y < box[3] - 2)
    assert np.abs(d[inner] - 3.3).max() < 0.05
    assert 0.8 * 15 * 20 <= r.changed <= 1.2 * 15 * 20  # the box
    coarse = dsm_difference(a, b, str(tmp_path / "d2.tif"), resolution=2.0)  # a's extent, 2 m cells
    dc, gtc, _ = read_dsm(coarse.path)
    assert gtc[1] == 2.0 and dc.shape == (40, 40) and (gtc[0], gtc[3]) == (gt[0], gt[3])
    assert coarse.median == pytest.approx(0.3, abs=0.01)


def test_bad_inputs_are_named(pair, tmp_path):
    a, b, _ = pair
    arr, gt, _ = read_dsm(a)
    far = write_cog(str(tmp_path / "far.tif"), arr, (gt[0] + 5000.0,) + gt[1:], syn.CRS)
    with pytest.raises(TerrainError, match="do not overlap.*far.tif|far.tif.*do not overlap"):
        dsm_difference(a, far, str(tmp_path / "d.tif"))
    local = write_cog(str(tmp_path / "local.tif"), arr, gt, None)
    with pytest.raises(TerrainError, match="local.tif has no CRS"):
        dsm_difference(local, b, str(tmp_path / "d.tif"))
    text = tmp_path / "notes.tif"
    text.write_text("not a raster")
    with pytest.raises(TerrainError, match="notes.tif is not a raster"):
        dsm_difference(a, str(text), str(tmp_path / "d.tif"))
    with pytest.raises(TerrainError, match="missing.tif does not exist"):
        dsm_difference(str(tmp_path / "missing.tif"), b, str(tmp_path / "d.tif"))
    empty = write_cog(str(tmp_path / "empty.tif"), np.full_like(arr, np.nan), gt, syn.CRS)
    with pytest.raises(TerrainError, match="share no cell"):
        dsm_difference(empty, b, str(tmp_path / "d.tif"))
    with pytest.raises(TerrainError, match="overwrite its input"):
        dsm_difference(a, b, a)
    assert not os.path.exists(tmp_path / "d.tif")


def test_a_reference_workspace_without_its_products_is_refused_by_name(tmp_path):
    b1 = syn.vertical_block(epoch=1, **BLOCK)
    later = synthetic_workspace(str(tmp_path / "later"), b1, b1.truth_reconstruction(seed=5, n_points=300))
    if not os.path.isfile(os.path.join(CACHE, "done")):
        _photos(syn.vertical_block(epoch=2, **BLOCK))
    cases = [(dict(dsm=False), "has no DSM"), (dict(ortho=False), "has no orthomosaic"),
             (dict(georeferenced=False), "is not georeferenced")]
    for k, (kw, message) in enumerate(cases):
        ws = _earlier_workspace(str(tmp_path / f"earlier{k}"), b1, **kw)
        with pytest.raises(AutoControlError, match=re.escape(f"reference workspace {ws} {message}")):
            register_epoch(later, ws)
    with pytest.raises(AutoControlError, match="nowhere is not an ArchaeoOrtho workspace"):
        register_epoch(later, str(tmp_path / "nowhere"))
    full = _earlier_workspace(str(tmp_path / "full"), b1)
    with pytest.raises(AutoControlError, match="registered to itself"):
        register_epoch(full, full)


def test_qgis_process_runs_dsmdifference(pair, tmp_path):
    """archaeoortho:dsmdifference headless: the difference raster and its figures; non-overlapping rasters named,
    no traceback."""
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    a, b, _ = pair

    def run(*args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:dsmdifference", "--", *args], env=env,
                              capture_output=True, text=True, timeout=300)

    out_path = str(tmp_path / "diff.tif")
    out = run(f"DSM_A={a}", f"DSM_B={b}", f"OUTPUT={out_path}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    res = json.loads(out.stdout)["results"]
    assert res["MEDIAN"] == pytest.approx(0.3, abs=0.01) and res["STD"] > 0.1
    assert res["CELLS"] > 1500 and 0 < res["CHANGED"] < res["CELLS"]
    assert os.path.samefile(res["OUTPUT"], out_path)
    d, _, _ = read_dsm(out_path)
    assert int(np.isfinite(d).sum()) == res["CELLS"]
    arr, gt, _ = read_dsm(a)
    far = write_cog(str(tmp_path / "far.tif"), arr, (gt[0] + 5000.0,) + gt[1:], syn.CRS)
    out = run(f"DSM_A={a}", f"DSM_B={far}", f"OUTPUT={tmp_path / 'diff2.tif'}")
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "Traceback" not in text and "far.tif" in text, text[-2000:]
