"""Terrain products: DTM (SMRF ground filter), classified point cloud, relief visualisations (rvt-py), contours.

The scene is the synthetic one (tests/synthetic.py: hills, a ditch 3.2 m wide and 1.5 m deep, box buildings 4-8 m
tall) with trees added here (crowns 6-12 m tall, 2-4 m radius), as the DSM stage sees it at 2 x the block's GSD
blurred (walls become 1 m slopes) with 5 cm of noise; the truth is the scene's ground_at().
"""
import importlib.util
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

from core.io import raster
from core.project.layout import Layout
from core.project.stages import DSM, RELIEF, TERRAIN, run_stage
from core.project.workspace import Workspace
from core.terrain.contours import write_contours
from core.terrain.options import SOURCE_INTERPOLATED, SOURCE_MEASURED, ReliefStageOptions, TerrainError, TerrainOptions
from core.terrain.products import build_dtm, relief
from core.terrain.rasters import same_grid
from core.terrain.stage import build_dtm_workspace, relief_workspace
from tests import synthetic as syn

GSD = 40.0 / 325.0  # m: the synthetic block of tests/test_dense.py (altitude 40 m, fx 325 px)
CELL = 0.25  # m: the DSM at 2 x GSD, as the DSM stage makes it
BOUNDS = (-60.0, -45.0, 60.0, 45.0)


def _grid(cell=CELL):
    xmin, ymin, xmax, ymax = BOUNDS
    xs = xmin + (np.arange(int((xmax - xmin) / cell)) + 0.5) * cell
    ys = ymax - (np.arange(int((ymax - ymin) / cell)) + 0.5) * cell
    return np.meshgrid(xs, ys)


def add_trees(scene, x, y, dsm, n=25, seed=1):
    """``dsm`` with ``n`` tree crowns (half ellipsoids 6-12 m tall, radius 2-4 m) away from the buildings and the
    ditch; returns (dsm, crown mask)."""
    rng = np.random.default_rng(seed)
    ground = scene.ground_at(x, y)
    crowns = np.zeros(dsm.shape, dtype=bool)
    placed = 0
    while placed < n:
        tx, ty = rng.uniform(BOUNDS[0] + 5, BOUNDS[2] - 5), rng.uniform(BOUNDS[1] + 5, BOUNDS[3] - 5)
        if scene.near_feature(tx, ty, 5.0):
            continue
        r, top = rng.uniform(2.0, 4.0), rng.uniform(6.0, 12.0)
        d = np.hypot(x - tx, y - ty)
        inside = d < r
        crown = ground + np.maximum(0.5, top * np.sqrt(np.clip(1 - (d / r) ** 2, 0, 1)))
        dsm = np.where(inside, np.maximum(dsm, crown), dsm)
        crowns |= inside
        placed += 1
    return dsm, crowns


def synthetic_dsm():
    """(scene, x, y local cell centres, DSM array, geotransform, building mask, tree mask): the scene as the DSM
    stage sees it (also used by benchmarks/terrain.py --compare-csf)."""
    scene = syn.make_scene(3, BOUNDS)
    x, y = _grid()
    dsm, trees = add_trees(scene, x, y, scene.height_at(x, y))
    from scipy import ndimage

    # dense matching blurs walls into slopes (the skirts a ground filter must not take for ground), plus noise
    dsm = ndimage.gaussian_filter(dsm, 1.5) + np.random.default_rng(2).normal(0.0, 0.05, dsm.shape)
    dsm[10:14, 200:230] = np.nan  # a small hole the matcher left
    dsm[:, :3] = np.nan  # and the edge outside the block
    buildings = np.zeros(dsm.shape, dtype=bool)
    for b in scene.buildings:
        buildings |= b.contains(x, y)
    gt = (BOUNDS[0] + syn.ORIGIN[0], CELL, 0.0, BOUNDS[3] + syn.ORIGIN[1], 0.0, -CELL)
    return scene, x, y, dsm, gt, buildings, trees


@pytest.fixture(scope="module")
def scene_dsm(tmp_path_factory):
    """(scene, x, y local cell centres, DSM path, building mask, tree mask)."""
    root = tmp_path_factory.mktemp("terrain")
    scene, x, y, dsm, gt, buildings, trees = synthetic_dsm()
    path = str(root / "dsm.tif")
    raster.write_cog(path, dsm, gt, syn.CRS)
    return scene, x, y, path, buildings, trees


@pytest.fixture(scope="module")
def dtm(scene_dsm, tmp_path_factory):
    scene, x, y, path, buildings, trees = scene_dsm
    out = str(tmp_path_factory.mktemp("dtm") / "dtm.tif")
    result = build_dtm(path, out, contour_interval=0.5)
    z, gt, wkt = raster.read_dsm(out)
    source, _, _ = raster.read_dsm(result.source_path)
    return result, z, source


def _ditch_cells(scene, x, y, across_lo, across_hi, margin=8.0):
    """Cells of the ditch's middle part (away from its ends and the buildings) at |across| in [lo, hi)."""
    (x0, y0), (x1, y1), hw, _ = scene.ditch
    d = np.array([x1 - x0, y1 - y0])
    length = float(np.linalg.norm(d))
    d /= length
    along = (x - x0) * d[0] + (y - y0) * d[1]
    across = np.abs(-(x - x0) * d[1] + (y - y0) * d[0])
    sel = (along > 0.2 * length) & (along < 0.8 * length) & (across >= across_lo) & (across < across_hi)
    for b in scene.buildings:
        sel &= ~b.contains(x, y, margin)
    return sel


# ---------------------------------------------------------------------------
# DTM against the truth
# ---------------------------------------------------------------------------

def test_dtm_matches_the_true_ground(scene_dsm, dtm):
    scene, x, y, path, buildings, trees = scene_dsm
    result, z, source = dtm
    truth = scene.ground_at(x, y)
    err = z - truth
    objects = buildings | trees
    data = np.isfinite(z)
    open_ground = ~objects & data
    rmse_open = float(np.sqrt(np.mean(err[open_ground] ** 2)))
    rmse_buildings = float(np.sqrt(np.mean(err[buildings & data] ** 2)))
    rmse_trees = float(np.sqrt(np.mean(err[trees & data] ** 2)))
    print(f"DTM RMSE: open {rmse_open:.3f} m, under buildings {rmse_buildings:.3f} m, under trees {rmse_trees:.3f} m "
          f"(GSD {GSD:.3f} m)")
    assert rmse_open <= 1.5 * GSD
    assert rmse_buildings <= 3 * GSD and rmse_trees <= 3 * GSD
    # no object left standing: the worst cell under a building or a tree is far below the lowest (4 m) roof
    assert np.nanmax(np.abs(err[objects])) < 1.0


def test_buildings_and_trees_are_not_ground(scene_dsm, dtm):
    scene, x, y, path, buildings, trees = scene_dsm
    result, z, source = dtm
    for name, mask in (("buildings", buildings), ("trees", trees)):
        removed = float(np.mean(source[mask] == SOURCE_INTERPOLATED))
        print(f"{name}: {removed:.1%} of their cells non-ground (interpolated)")
        assert removed >= 0.95, name
    open_ground = ~(buildings | trees) & np.isfinite(z)
    assert np.mean(source[open_ground] == SOURCE_MEASURED) > 0.9  # the open ground stays measured
    # the ditch is ground: a negative feature survives the opening
    assert np.mean(source[_ditch_cells(scene, x, y, 0.0, 1.0)] == SOURCE_MEASURED) > 0.95


def test_dtm_is_on_the_dsm_grid_with_its_source_band(scene_dsm, dtm):
    scene, x, y, path, buildings, trees = scene_dsm
    result, z, source = dtm
    assert same_grid(path, result.dtm_path) is None
    assert same_grid(path, result.source_path) is None
    info = raster.open_dsm(result.dtm_path)
    assert info.metadata.get("GROUND_FILTER") == "SMRF"
    from osgeo import gdal

    ds = gdal.Open(result.dtm_path)
    assert ds.GetMetadata("IMAGE_STRUCTURE").get("LAYOUT") == "COG"
    assert ds.GetSpatialRef().GetAuthorityCode(None) == "32633"
    # outside the DSM's data the DTM is nodata, inside holes it is interpolated
    assert np.isnan(z[:, :3]).all() and np.isfinite(z[10:14, 200:230]).all()
    assert (source[10:14, 200:230] == SOURCE_INTERPOLATED).all()
    assert set(np.unique(np.nan_to_num(source)).astype(int)) <= {0, SOURCE_MEASURED, SOURCE_INTERPOLATED}


def test_contours_at_the_interval_with_their_elevation(dtm):
    from osgeo import ogr

    result, z, source = dtm
    assert result.contour_lines > 10
    ds = ogr.Open(result.contours_path)
    lyr = ds.GetLayerByName("contours")
    assert lyr.GetFeatureCount() == result.contour_lines
    levels = {round(f.GetField("elevation"), 6) for f in lyr}
    assert all(abs(v / 0.5 - round(v / 0.5)) < 1e-6 for v in levels)
    lo, hi = np.nanmin(z), np.nanmax(z)
    assert min(levels) >= lo - 0.5 and max(levels) <= hi + 0.5 and len(levels) >= int((hi - lo) / 0.5) - 1
    assert lyr.GetSpatialRef().GetAuthorityCode(None) == "32633"


# ---------------------------------------------------------------------------
# relief visualisations
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def reliefs(dtm, tmp_path_factory):
    pytest.importorskip("rvt.vis")
    result, z, source = dtm
    out = str(tmp_path_factory.mktemp("relief"))
    return relief(result.dtm_path, ["slrm", "svf", "openness_pos", "openness_neg", "msrm", "mhs", "ld", "vat"], out)


def test_ditch_visible_in_the_local_relief_model(scene_dsm, reliefs):
    scene, x, y, path, buildings, trees = scene_dsm
    slrm, _, _ = raster.read_dsm(reliefs.paths["slrm"])
    hw = scene.ditch[2]
    bottom = np.nanmedian(slrm[_ditch_cells(scene, x, y, 0.0, 0.25)])
    banks = np.nanmedian(slrm[_ditch_cells(scene, x, y, hw + 1.0, hw + 3.0)])
    depth = banks - bottom
    print(f"ditch depth in the local relief model: {depth:.3f} m (true {scene.ditch[3]} m)")
    assert abs(depth - scene.ditch[3]) <= 0.2 * scene.ditch[3]
    # and the ditch is what stands out: lower than 99.5 % of the ground away from it (hills, ramp)
    far = ~scene.near_feature(x, y, 10.0) & np.isfinite(slrm)
    assert bottom < np.percentile(slrm[far], 0.5)


def test_every_visualisation_in_its_range(scene_dsm, reliefs):
    scene, x, y, path, buildings, trees = scene_dsm
    ranges = {"svf": (0, 1), "openness_pos": (0, 180), "openness_neg": (0, 180), "mhs": (0, 1), "vat": (0, 1),
              "slrm": (-20, 20), "msrm": (-20, 20), "ld": (0, 50)}
    ditch = _ditch_cells(scene, x, y, 0.0, 0.5)
    flat = ~scene.near_feature(x, y, 15.0)
    for key, p in reliefs.paths.items():
        assert same_grid(path, p) is None, key
        img, _, _ = raster.read_dsm(p)
        lo, hi = ranges[key]
        good = img[np.isfinite(img)]
        assert good.size > 0.9 * np.isfinite(raster.read_dsm(path)[0]).sum(), key
        assert lo <= good.min() and good.max() <= hi, (key, good.min(), good.max())
        if key in ("svf", "openness_pos", "vat"):  # a ditch sees less sky than open ground: darker
            assert np.nanmedian(img[ditch]) < np.nanmedian(img[flat]) - 0.02 * (hi - lo), key
    assert reliefs.radii["svf"] == 40 and reliefs.radii["slrm"] == 80  # RVT's 10 and 20 cells of 1 m at 0.25 m


# ---------------------------------------------------------------------------
# the workspace: stage records, classified point cloud
# ---------------------------------------------------------------------------

def _workspace_with_dsm(root, dsm_path, scene):
    """A workspace whose DSM stage recorded ``dsm_path`` and a LAS point cloud of its cells."""
    ws = Workspace.create_or_open(str(root))
    ws.crs = syn.CRS
    lay = Layout(ws)
    z, gt, _ = raster.read_dsm(dsm_path)
    h, w = z.shape
    cx = gt[0] + (np.arange(w) + 0.5) * gt[1]
    cy = gt[3] + (np.arange(h) + 0.5) * gt[5]
    xx, yy = np.meshgrid(cx, cy)
    ok = np.isfinite(z)
    xyz = np.column_stack([xx[ok] - syn.ORIGIN[0], yy[ok] - syn.ORIGIN[1], z[ok]])
    pc = os.path.join(ws.root, "points.las")
    raster.write_las(pc, [(xyz, np.full((len(xyz), 3), 128, np.uint8))], syn.ORIGIN, syn.CRS)
    import shutil

    shutil.copy(dsm_path, lay.default_dsm)
    with run_stage(ws, DSM, {"synthetic": True}) as run:
        run.finish(outputs={"dsm": lay.rel(lay.default_dsm), "point_cloud": lay.rel(pc)})
    return ws.root, xyz


def test_workspace_stage_classifies_the_point_cloud(scene_dsm, tmp_path):
    scene, x, y, path, buildings, trees = scene_dsm
    root, xyz = _workspace_with_dsm(tmp_path / "ws", path, scene)
    r = build_dtm_workspace(root, TerrainOptions(contour_interval=1.0))
    ws = Workspace.open(root)
    lay = Layout(ws)
    assert ws.stage_done(TERRAIN) and os.path.samefile(lay.dtm(), lay.default_dtm)
    assert os.path.samefile(r.point_cloud_path, lay.classified_point_cloud)
    assert os.path.isfile(lay.contours_gpkg) and os.path.isfile(lay.dtm_source)
    _, _, header = raster.read_las(r.point_cloud_path)
    with open(r.point_cloud_path, "rb") as f:
        data = f.read()
    n, rec = header["count"], header["record_length"]
    off = len(data) - n * rec
    classes = np.frombuffer(data, np.uint8, count=n * rec, offset=off).reshape(n, rec)[:, 15]
    on_object = np.zeros(n, dtype=bool)
    for b in scene.buildings:
        on_object |= b.contains(xyz[:, 0], xyz[:, 1])
    print(f"point cloud: {np.mean(classes[on_object] == 1):.1%} of the roof points class 1, "
          f"{np.mean(classes[~on_object] == 2):.1%} of the others class 2")
    assert np.mean(classes[on_object] == 1) >= 0.95
    assert np.mean(classes[~on_object] == 2) > 0.8  # trees are among the others
    assert r.points == n and 0 < r.ground_points < n
    # patched in chunks: the same file whatever the chunk size
    from core.terrain.classify import classify_las
    from core.terrain.rasters import read_elevation

    src, _, _ = raster.read_dsm(lay.dtm_source)
    again = str(tmp_path / "again.las")
    classify_las(lay.point_cloud(), again, read_elevation(lay.dtm(), "DTM"), np.nan_to_num(src).astype(np.uint8),
                 0.5, chunk=1000)
    with open(again, "rb") as f:
        assert f.read() == data

    rr = relief_workspace(root, ReliefStageOptions(["slrm"], source="dtm"))
    assert os.path.samefile(rr.paths["slrm"], lay.relief("slrm", "dtm"))
    relief_workspace(root, ReliefStageOptions(["slrm"], source="dsm"))
    rec = Workspace.open(root).stage(RELIEF)
    assert rec["status"] == "done" and {"dtm-slrm", "dsm-slrm"} <= set(rec["outputs"])

    # the report lists and previews them
    from core.report.options import ReportOptions
    from core.report.stage import build_report

    rep = build_report(root, ReportOptions(uncertainty=False))
    with open(rep.path, encoding="utf-8") as f:
        html = f.read()
    assert rep.sections["products"] == "ok"
    for text in ("Terrain (DTM)", "dtm.tif", "points-classified.las", "contours.gpkg",
                 "Simple local relief model (DTM)", "Simple local relief model (DSM)", 'alt="DTM preview"',
                 'alt="Relief visualisations"'):
        assert text in html, text
    assert rep.figures["DTM_GROUND_FRACTION"] == pytest.approx(r.ground_fraction)


def test_workspace_without_dsm_says_what_to_run(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    with pytest.raises(TerrainError, match="Build DSM"):
        build_dtm_workspace(ws.root)
    with pytest.raises(TerrainError, match="Build DTM"):
        relief_workspace(ws.root, ReliefStageOptions(["svf"]))


# ---------------------------------------------------------------------------
# bad input: every entry point names the file and the problem
# ---------------------------------------------------------------------------

def _bad_rasters(root):
    gt = (500000.0, 0.5, 0.0, 4600000.0, 0.0, -0.5)
    empty = str(root / "all-nodata.tif")
    raster.write_cog(empty, np.full((64, 64), np.nan), gt, syn.CRS)
    degrees = str(root / "degrees.tif")
    raster.write_cog(degrees, np.random.default_rng(0).normal(100, 1, (64, 64)), (14.0, 1e-5, 0, 45.0, 0, -1e-5),
                     "EPSG:4326")
    tiny = str(root / "tiny.tif")
    raster.write_cog(tiny, np.ones((8, 8)), gt, syn.CRS)
    text = root / "notes.tif"
    text.write_text("not a raster")
    return {empty: "no data", degrees: "geographic CRS", tiny: "too small", str(text): "not a raster GDAL can read",
            str(root / "missing.tif"): "does not exist"}


@pytest.mark.parametrize("entry", ["dtm", "relief", "contours"])
def test_bad_rasters_are_refused_naming_the_file(entry, tmp_path):
    for path, problem in _bad_rasters(tmp_path).items():
        with pytest.raises(TerrainError, match=problem) as e:
            if entry == "dtm":
                build_dtm(path, str(tmp_path / "out.tif"))
            elif entry == "relief":
                relief(path, ["svf"], str(tmp_path / "relief"))
            else:
                write_contours(path, str(tmp_path / "c.gpkg"), 1.0)
        assert path in str(e.value)
    assert not os.path.exists(tmp_path / "out.tif") and not os.path.exists(tmp_path / "c.gpkg")


def test_bad_options_are_refused(dtm, tmp_path):
    result, _, _ = dtm
    with pytest.raises(TerrainError, match="unknown relief"):
        relief(result.dtm_path, ["hillshade3d"], str(tmp_path))
    with pytest.raises(TerrainError, match="interval"):
        write_contours(result.dtm_path, str(tmp_path / "c.gpkg"), 0.0)
    with pytest.raises(TerrainError, match="larger interval"):
        write_contours(result.dtm_path, str(tmp_path / "c.gpkg"), 0.0001)


# ---------------------------------------------------------------------------
# Processing, headless as a user runs it
# ---------------------------------------------------------------------------

def test_qgis_process_runs_the_terrain_algorithms(scene_dsm, tmp_path):
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    scene, x, y, path, buildings, trees = scene_dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)

    def run(alg, *args):
        return subprocess.run([exe, "--json", "run", f"archaeoortho:{alg}", "--", *args], env=env,
                              capture_output=True, text=True, timeout=600)

    # the contours asked for at the workspace's own path: the same file, nothing to copy (was SameFileError)
    out = run("builddtm", f"WORKSPACE={root}", "CONTOUR_INTERVAL=1",
              f"OUTPUT_CONTOURS={os.path.join(root, 'terrain', 'contours.gpkg')}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    res = json.loads(out.stdout)["results"]
    assert os.path.samefile(res["OUTPUT_DTM"], os.path.join(root, "dtm.tif"))
    assert 0.5 < res["GROUND_FRACTION"] < 1.0 and os.path.isfile(res["OUTPUT_CONTOURS"])
    if importlib.util.find_spec("rvt") is not None:  # the rest runs without rvt-py too
        out = run("reliefvisualisation", f"WORKSPACE={root}", "VISUALISATION=3")  # simple local relief model
        assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
        res = json.loads(out.stdout)["results"]
        assert os.path.samefile(res["OUTPUT"], os.path.join(root, "terrain", "relief", "dtm-slrm.tif"))
    out = run("contours", f"INPUT={os.path.join(root, 'dtm.tif')}", "INTERVAL=2",
              f"OUTPUT={tmp_path / 'c2.gpkg'}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    assert os.path.isfile(tmp_path / "c2.gpkg")
    # bad input: a clear message, no traceback
    bad = next(p for p, what in _bad_rasters(tmp_path).items() if what == "geographic CRS")
    for alg, args in (("builddtm", [f"DSM={bad}", f"OUTPUT_DTM={tmp_path / 'x.tif'}"]),
                      ("contours", [f"INPUT={bad}", "INTERVAL=1", f"OUTPUT={tmp_path / 'x.gpkg'}"]),
                      ("reliefvisualisation", [f"INPUT={bad}", f"OUTPUT={tmp_path / 'r.tif'}"])):
        out = run(alg, *args)
        text = out.stdout + out.stderr
        assert out.returncode != 0 and "geographic CRS" in text and bad in text, text[-2000:]
        assert "Traceback" not in text, text[-2000:]


@pytest.mark.usefixtures("qgis_processing")
def test_products_load_styled_in_qgis(scene_dsm, tmp_path, qgis_new_project):
    pytest.importorskip("rvt.vis")
    from archaeoortho.qgisio import layers
    from qgis.core import QgsProject, QgsSingleBandGrayRenderer

    scene, x, y, path, buildings, trees = scene_dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)
    build_dtm_workspace(root, TerrainOptions(contour_interval=1.0))
    relief_workspace(root, ReliefStageOptions(["svf", "openness_neg"]))
    loaded = layers.load_workspace_results(root, QgsProject.instance())
    by_kind = {lyr.customProperty(layers.KIND_PROPERTY): lyr for lyr in loaded}
    assert by_kind["dtm"].renderer().type() == "singlebandpseudocolor"
    assert by_kind["dtmhillshade"].renderer().type() == "hillshade"
    assert by_kind["contours"].labelsEnabled() and by_kind["contours"].featureCount() > 10
    reliefs = [lyr for lyr in loaded if lyr.customProperty(layers.KIND_PROPERTY) == "relief"]
    names = sorted(lyr.name() for lyr in reliefs)
    assert names == ["Openness (negative) (DTM) \u2014 ws", "Sky-view factor (DTM) \u2014 ws"], names
    for lyr in reliefs:
        r = lyr.renderer()
        assert r.type() == "singlebandgray"
        ce = r.contrastEnhancement()
        assert r.gradient() == QgsSingleBandGrayRenderer.Gradient.BlackToWhite
        # RVT's display ranges (rvt.default: svf_bytscl, neg_opns_bytscl)
        expected = (0.6375, 1.0) if "Sky-view" in lyr.name() else (60.0, 95.0)
        assert (ce.minimumValue(), ce.maximumValue()) == pytest.approx(expected)
    assert layers.output_kind("OUTPUT_DTM", "x/dtm.tif") == layers.DTM
    assert layers.output_kind("OUTPUT_CONTOURS", "x/c.gpkg") == layers.CONTOURS


def test_without_rvt_the_message_names_the_pip_command(dtm, tmp_path, monkeypatch):
    import sys

    from core.common.errors import MissingDependencyError

    result, _, _ = dtm
    monkeypatch.setitem(sys.modules, "rvt.vis", None)  # as if rvt-py were not installed
    with pytest.raises(MissingDependencyError, match=r"rvt-py.*relief visualisations.*pip install --no-deps "
                                                     r"--ignore-requires-python rvt-py==2\.2\.3"):
        relief(result.dtm_path, ["svf"], str(tmp_path))
    # the DTM and contours do not need it
    build_dtm(result.dsm_path, str(tmp_path / "dtm.tif"), contour_interval=2.0)


def test_dependency_dialog_lists_rvt_as_optional(qgis_app, monkeypatch):
    from archaeoortho.core.common import dependencies
    from archaeoortho.ui.dependencies import optional_packages_html

    html = optional_packages_html()
    assert "Optional" in html and "rvt-py (relief visualisations)" in html
    monkeypatch.setattr(dependencies, "check", lambda reqs: [dependencies.Found(r) for r in reqs])  # missing
    assert "--ignore-requires-python rvt-py==2.2.3" in optional_packages_html()


def test_products_are_copied_atomically(tmp_path, monkeypatch):
    """A product copied to the user's path (Build DTM's contours, a relief raster): the same file is left alone,
    and a copy that fails leaves the existing output as it was, with no partial file beside it."""
    import shutil

    from core.common.files import atomic_copy

    src, dst = tmp_path / "a.gpkg", tmp_path / "b.gpkg"
    src.write_bytes(b"new product")
    assert atomic_copy(str(src), str(src)) == str(src) and src.read_bytes() == b"new product"
    dst.write_bytes(b"the user's earlier output")

    def broken(a, b):
        pathlib.Path(b).write_bytes(b"half")
        raise OSError("disk full")

    monkeypatch.setattr(shutil, "copyfile", broken)
    with pytest.raises(OSError, match="disk full"):
        atomic_copy(str(src), str(dst))
    assert dst.read_bytes() == b"the user's earlier output"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gpkg", "b.gpkg"]
    monkeypatch.undo()
    atomic_copy(str(src), str(dst))
    assert dst.read_bytes() == b"new product"
