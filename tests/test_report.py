"""The accuracy report (core.report) and the covariance behind its uncertainty section (core.uncertainty).

A small georeferenced workspace is built from a synthetic block in seconds (the truth model written as the
aligned model, georeferenced with 5 control points, 6 check points and camera positions), so nothing here
runs SfM.  The numbers the report shows are parsed back and compared with core.accuracy."""
import base64
import io
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from core.common.progress import Cancelled, NullProgress
from core.georef import accuracy, uncertainty
from core.georef.options import GeorefOptions
from core.georef.stage import georeference_workspace
from core.project.workspace import Workspace, WorkspaceError
from core.report import stage as report
from core.report.figures import hillshade
from core.report.html import esc
from core.report.options import ReportOptions
from core.report.page import read_report_data
from tests import synthetic as syn
from tests.workspaces import synthetic_workspace

IMG_RE = re.compile(r'<img alt="([^"]*)" src="data:image/png;base64,([A-Za-z0-9+/=]+)">')


# --------------------------------------------------------------------------------------------------
# fixtures
# --------------------------------------------------------------------------------------------------

def _aligned_workspace(path, block, rec, unregistered=None):
    n = len(block.shots)
    alignment = {"images_given": n + len(unregistered or {}), "registered": n,
                 "unregistered": unregistered or {}, "skipped_files": [], "other_components": [],
                 "principal_point_refined": False}
    return synthetic_workspace(path, block, rec, names=[s.name for s in block.shots], images_dir="/synthetic/images",
                               align_parameters={"pairing": "synthetic"}, alignment=alignment,
                               align_timings={"features": 1.5}, align_results={"registered": n})

@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1, n_strips=2, per_strip=5, n_buildings=3, gcp_grid=(4, 3), roofs=1)


@pytest.fixture(scope="module")
def aligned(block, tmp_path_factory):
    rec = block.truth_reconstruction(n_points=800)
    return _aligned_workspace(tmp_path_factory.mktemp("aligned") / "ws", block, rec,
                              unregistered={"ghost.jpg": "no verified matches with any other image"})


@pytest.fixture(scope="module")
def georeferenced(block, aligned, tmp_path_factory):
    root = str(tmp_path_factory.mktemp("georef") / "ws")
    shutil.copytree(aligned, root)
    cams, _ = block.camera_positions(sigma=0.5)
    csv = os.path.join(os.path.dirname(root), "positions.csv")
    with open(csv, "w", encoding="utf-8") as f:
        f.write(f"{syn.CRS}\nimage,x,y,z,sigma\n")
        for c in cams:
            f.write(f"{c.image},{c.x:.3f},{c.y:.3f},{c.z:.3f},0.5\n")
    gcps = block.gcp_set(block.spread_control(5), noise_px=0.4)
    georeference_workspace(root, GeorefOptions(gcps=gcps, camera_positions_path=csv))
    return root


@pytest.fixture(scope="module")
def built(georeferenced):
    result = report.build_report(georeferenced)
    with open(result.path, encoding="utf-8") as f:
        text = f.read()
    return result, text


def _residuals(ws):
    with open(os.path.join(ws, "georef", "residuals.json"), encoding="utf-8") as f:
        return json.load(f)


def _keyed(text):
    """data-key -> (displayed text, data-value) for every keyed number in the report."""
    out = {}
    for m in re.finditer(r'<(td|span|li|div)[^>]*data-key="([^"]+)"(?: data-value="([^"]*)")?[^>]*>(.*?)</\1>',
                         text, re.S):
        out[m.group(2)] = (re.sub(r"<[^>]+>", "", m.group(4)).strip(), m.group(3))
    return out


# --------------------------------------------------------------------------------------------------
# the numbers
# --------------------------------------------------------------------------------------------------

def test_report_numbers_are_core_accuracy_figures(built, georeferenced):
    result, text = built
    assert os.path.samefile(result.path, os.path.join(georeferenced, "report.html"))
    assert result.sections == {"summary": "ok", "orientation": "ok", "georeferencing": "ok", "uncertainty": "ok",
                               "products": result.sections["products"]}
    res = _residuals(georeferenced)
    keyed = _keyed(text)
    for role, status in (("check", "check"), ("control", "used")):
        rows = [p for p in res["points"] if p["status"] == status and p["dx"] is not None]
        assert rows
        st = accuracy.residual_stats([p["dx"] for p in rows], [p["dy"] for p in rows], [p["dz"] for p in rows])
        for k in ("rmse_x", "rmse_y", "rmse_z", "rmse_r", "rmse_xyz"):
            shown, value = keyed[f"{role}.{k}"]
            assert float(value) == pytest.approx(st[k], rel=1e-12)  # the exact figure, for machines
            assert abs(float(shown) - st[k]) <= 0.0005 + 1e-9  # the figure a person reads, in mm
    chk = [p for p in res["points"] if p["status"] == "check"]
    st = accuracy.residual_stats([p["dx"] for p in chk], [p["dy"] for p in chk], [p["dz"] for p in chk])
    h = accuracy.nssda_horizontal(st["rmse_x"], st["rmse_y"])
    v = accuracy.nssda_vertical(st["rmse_z"])
    # the standard's own sentences, with the value from core.accuracy
    assert accuracy.nssda_statement(h, "horizontal") in text
    assert accuracy.nssda_statement(v, "vertical") in text
    assert re.search(r"Tested \d+\.\d{3} meters horizontal accuracy at 95% confidence level", text)
    assert float(keyed["nssda.horizontal"][1]) == pytest.approx(h, rel=1e-12)
    # the same figure the georeference stage gives Processing
    stage = Workspace.open(georeferenced).stage("georeference")["results"]
    assert result.figures["NSSDA_H"] == pytest.approx(stage["NSSDA_H"], rel=1e-9)
    assert result.figures["NSSDA_V"] == pytest.approx(stage["NSSDA_V"], rel=1e-9)
    assert result.figures["CHECK_RMSE_XY"] == pytest.approx(stage["CHECK_RMSE_XY"], rel=1e-9)
    for ed in (2014, 2023):
        a = accuracy.asprs_horizontal_class(st["rmse_x"], st["rmse_y"], result.figures["GSD"], edition=ed)
        assert float(keyed[f"asprs.{ed}.h"][1]) == a["class_cm"]
        assert esc(a["statement"]) in text
        vz = accuracy.asprs_vertical_class(st["rmse_z"], edition=ed)
        assert float(keyed[f"asprs.{ed}.v"][1]) == vz["class_cm"]
    # per-point residuals, and the camera-position residuals
    for p in chk:
        assert float(keyed[f"pt.{p['name']}.dx"][1]) == pytest.approx(p["dx"], rel=1e-12)
    cams = [c for c in res["cameras"] if c["used"]]
    cst = accuracy.residual_stats([c["dx"] for c in cams], [c["dy"] for c in cams], [c["dz"] for c in cams])
    assert float(keyed["cam.rmse_r"][1]) == pytest.approx(cst["rmse_r"], rel=1e-12)
    # images given / aligned / not aligned, with why
    assert keyed["images.given"][0] == "11" and keyed["images.aligned"][0] == "10"
    assert "ghost.jpg" in text and "no verified matches with any other image" in text
    # the embedded machine-readable copy agrees
    data = read_report_data(result.path)
    assert data["figures"]["NSSDA_H"] == pytest.approx(h, rel=1e-12)
    assert data["sections"]["georeferencing"] == "ok"


def test_every_plot_is_an_embedded_png_and_nothing_is_fetched(built):
    from PIL import Image

    _, text = built
    imgs = IMG_RE.findall(text)
    assert len(imgs) >= 6  # histograms, per image, connectivity, cameras, residual vectors, uncertainty
    assert len(imgs) == text.count("<img ")
    for alt, data in imgs:
        raw = base64.b64decode(data, validate=True)
        assert raw[:8] == b"\x89PNG\r\n\x1a\n", alt
        im = Image.open(io.BytesIO(raw))
        im.load()
        assert im.width > 200 and im.height > 100, alt
        assert np.asarray(im.convert("L")).std() > 5, f"{alt}: blank plot"
    low = text.lower()
    assert "http://" not in low and "https://" not in low
    assert "<link" not in low and "url(" not in low and "@import" not in low
    assert not re.search(r"<script(?![^>]*application/json)", low)  # only the inert data block
    assert not re.search(r'(src|href)="(?!data:|#)', low)


def test_calibrated_parameters_have_standard_deviations(built):
    _, text = built
    assert re.search(r"<b>fx</b> 650\.\d\d ± \d+\.\d\d", text)
    assert re.search(r"<b>k1</b> -0\.0\d{5} ± 0\.00\d{4}", text)
    assert "<b>cx</b> 403.70 (fixed)" in text


# --------------------------------------------------------------------------------------------------
# missing stages, products, cancel
# --------------------------------------------------------------------------------------------------

def test_sections_are_skipped_cleanly_when_stages_are_missing(aligned, tmp_path):
    ws = str(tmp_path / "aligned")
    shutil.copytree(aligned, ws)
    screening = {"flagged": 1, "excluded": 0, "kept": 10, "median": {"blur_score": 40.0},
                 "images": [{"name": f"S1_0{k}.jpg", "blur_score": 10.0 + 10 * k, "blur_relative": 0.3 + 0.2 * k,
                             "exposure_score": 0.9, "dynamic_range": 0.6, "flags": ["blurry"] if k == 1 else [],
                             "decision": "keep", "blur_rank": k} for k in range(1, 4)]}
    with open(os.path.join(ws, "screening.json"), "w", encoding="utf-8") as f:
        json.dump(screening, f)
    result = report.build_report(ws, ReportOptions(uncertainty=True, write_layers=False))
    text = open(result.path, encoding="utf-8").read()
    assert result.sections["summary"] == "ok" and result.sections["orientation"] == "ok"
    assert "not georeferenced" in result.sections["georeferencing"]
    assert "no DSM" in result.sections["products"]
    assert result.sections["uncertainty"] == "ok"  # free network: intrinsics still have their precision
    assert "free network" in text and "±" in text
    assert text.count('class="skipped"') == 2
    assert "Tested" not in text and result.figures.get("NSSDA_H") is None
    assert "S1_01.jpg" in text and "blurry" in text  # screening decisions shown
    assert not os.path.exists(os.path.join(ws, "uncertainty"))
    # a workspace with no stage at all still gets a (short) report
    empty = Workspace.create_or_open(str(tmp_path / "empty")).root
    result = report.build_report(empty)
    assert result.sections["summary"] == "ok"
    assert all(result.sections[k] != "ok" for k in ("orientation", "georeferencing", "uncertainty", "products"))
    assert "run 'Align images'" in open(result.path, encoding="utf-8").read()


def _write_raster(path, arr, gt, nodata=None, alpha=None):
    from osgeo import gdal, osr

    bands = arr.shape[2] if arr.ndim == 3 else 1
    dt = gdal.GDT_Float32 if arr.dtype.kind == "f" else gdal.GDT_Byte
    ds = gdal.GetDriverByName("GTiff").Create(path, arr.shape[1], arr.shape[0], bands + (alpha is not None), dt)
    ds.SetGeoTransform(gt)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    for b in range(bands):
        band = ds.GetRasterBand(b + 1)
        band.WriteArray(arr[..., b] if arr.ndim == 3 else arr)
        if nodata is not None:
            band.SetNoDataValue(nodata)
    if alpha is not None:
        band = ds.GetRasterBand(bands + 1)
        band.SetColorInterpretation(gdal.GCI_AlphaBand)
        band.WriteArray(alpha)
    ds = None


def test_products_previews_with_resolution_and_valid_fraction(georeferenced, tmp_path):
    ws = str(tmp_path / "ws")
    shutil.copytree(georeferenced, ws)
    yy, xx = np.mgrid[0:200, 0:300]
    z = (150 + 3 * np.sin(xx / 20.0) + 0.02 * yy).astype(np.float32)
    z[:50, :] = -9999.0  # a quarter without data
    gt = (499950.0, 0.25, 0.0, 4600030.0, 0.0, -0.25)
    _write_raster(os.path.join(ws, "dsm.tif"), z, gt, nodata=-9999.0)
    rgb = np.dstack([(xx % 256), (yy % 256), np.full_like(xx, 128)]).astype(np.uint8)
    alpha = np.where(xx < 240, 255, 0).astype(np.uint8)  # 80 % valid
    _write_raster(os.path.join(ws, "orthomosaic.tif"), rgb, gt, alpha=alpha)
    result = report.build_report(ws, ReportOptions(uncertainty=False))
    text = open(result.path, encoding="utf-8").read()
    assert result.sections["products"] == "ok"
    assert result.figures["DSM_VALID_FRACTION"] == pytest.approx(0.75, abs=1e-9)
    assert result.figures["ORTHO_VALID_FRACTION"] == pytest.approx(0.80, abs=1e-9)
    assert result.figures["DSM_RESOLUTION"] == pytest.approx(0.25)
    assert "0.25 × 0.25 m" in text
    alts = [a for a, _ in IMG_RE.findall(text)]
    assert "DSM preview" in alts and "Orthomosaic preview" in alts
    assert result.sections["uncertainty"] != "ok"  # not requested: skipped with its reason
    hs = hillshade(z.astype(float), 0.25, 0.25)
    assert hs.shape == z.shape and 0.0 <= hs.min() and hs.max() <= 1.0
    # with the DSM stage's own figure (inside the camera centres' hull) the key figure is that one, the same
    # number as the Processing output VALID_FRACTION; the whole raster's share stays in the products section
    manifest = json.load(open(os.path.join(ws, "workspace.json")))
    manifest["stages"]["dsm"] = {"status": "done", "results": {"VALID_FRACTION": 0.93}}
    json.dump(manifest, open(os.path.join(ws, "workspace.json"), "w"))
    result = report.build_report(ws, ReportOptions(uncertainty=False))
    assert result.figures["DSM_VALID_FRACTION"] == pytest.approx(0.93)
    assert '<span data-key="dsm.valid">0.750</span>' in open(result.path, encoding="utf-8").read()
    assert "ortho.seam_step" not in open(result.path, encoding="utf-8").read()  # no correction recorded: no row
    # the orthophoto stage's seam figures (core.ortho.radiometry.seam_figures): the whole seam and level ground
    manifest["stages"]["orthophoto"] = {"status": "done", "results": {
        "seam_step_before": 0.0365, "seam_step_after": 0.0241, "seam_step_level_before": 0.0238,
        "seam_step_level_after": 0.0140, "seam_level_fraction": 0.583}}
    json.dump(manifest, open(os.path.join(ws, "workspace.json"), "w"))
    text = open(report.build_report(ws, ReportOptions(uncertainty=False)).path, encoding="utf-8").read()
    assert '3.6 % → <span data-key="ortho.seam_step">2.4</span> %' in text
    assert '2.4 % → <span data-key="ortho.seam_step_level">1.4</span> %' in text
    assert "level ground (58 % of the seams" in text


class _CancelAt(NullProgress):
    """The user presses Cancel when the progress message names ``what``."""

    def __init__(self, what):
        self.what = what
        self.pressed = False

    def report(self, fraction, message=""):
        self.pressed = self.pressed or self.what in message

    def is_cancelled(self):
        return self.pressed


def test_cancel_never_leaves_a_report_that_looks_complete(georeferenced, tmp_path):
    ws = str(tmp_path / "ws")
    shutil.copytree(georeferenced, ws)
    out = os.path.join(ws, "report.html")
    if os.path.exists(out):
        os.unlink(out)
    with pytest.raises(Cancelled):
        report.build_report(ws, ReportOptions(uncertainty=False), _CancelAt("products"))  # the last section
    assert not os.path.exists(out)
    assert not [f for f in os.listdir(ws) if f.startswith(".partial")]
    assert Workspace.open(ws).stage("report")["status"] == "cancelled"
    # a previous complete report stays as it was
    with open(out, "w", encoding="utf-8") as f:
        f.write("previous")
    with pytest.raises(Cancelled):
        report.build_report(ws, progress=_CancelAt("covariance"))  # in the covariance
    assert open(out, encoding="utf-8").read() == "previous"


def test_not_a_workspace_is_a_clear_error(tmp_path):
    with pytest.raises(WorkspaceError, match="not an ArchaeoOrtho workspace"):
        report.build_report(str(tmp_path))


# --------------------------------------------------------------------------------------------------
# uncertainty
# --------------------------------------------------------------------------------------------------

def test_free_network_covariance_agrees_with_pycolmap(aligned):
    """Intrinsics are datum-free: our generalised inverse gives what pycolmap.estimate_ba_covariance gives."""
    import pycolmap

    rec = pycolmap.Reconstruction()
    rec.read_binary(os.path.join(aligned, "sfm", "model"))
    ours = uncertainty.estimate(rec, free_intrinsics=uncertainty.default_free_intrinsics(rec))
    assert ours.datum == uncertainty.DATUM_FREE
    options = pycolmap.BundleAdjustmentOptions()
    options.refine_principal_point = False
    config = pycolmap.BundleAdjustmentConfig()
    for i in rec.reg_image_ids():
        config.add_image(i)
    config.fix_gauge(pycolmap.BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD)
    adjuster = pycolmap.create_default_ceres_bundle_adjuster(options, config, rec)
    cov = pycolmap.estimate_ba_covariance(pycolmap.BACovarianceOptions(), rec, adjuster)
    theirs = np.sqrt(np.diag(cov.get_other_params_cov(rec.cameras[1].params)))
    mine = np.array([s for s in ours.intrinsics[1]["std"] if s is not None]) / ours.sigma0  # unit weight 1 px
    np.testing.assert_allclose(mine, theirs, rtol=1e-3)


def test_control_gives_absolute_precision_and_layers(built, georeferenced, block):
    from osgeo import ogr

    result, _ = built
    ws = Workspace.open(georeferenced)
    import pycolmap

    rec = pycolmap.Reconstruction()
    rec.read_binary(ws.path("georef", "model"))
    control, priors, _, offset = uncertainty.workspace_inputs(ws, rec)
    assert len(control) == 5 and len(priors) == len(block.shots) and offset[0] == 500000.0
    u = uncertainty.estimate(rec, control, priors, offset=offset)
    assert u.datum == uncertainty.DATUM_CONTROL and u.n_control == 5
    assert 0.2 < u.sigma0 < 0.6  # 0.3-0.4 px of noise against a priori 1 px
    s = u.summary()
    gsd = block.gsd
    assert 0.05 * gsd < s["point_std_xy_median"] < 2 * gsd and s["point_std_z_median"] < 4 * gsd
    # layers
    for name, n in (("cameras", len(block.shots)), ("points", u.n_points)):
        path = result.layers[name]
        assert os.path.isfile(path) and path.startswith(os.path.join(georeferenced, "uncertainty"))
        ds = ogr.Open(path)
        lyr = ds.GetLayer(0)
        assert lyr.GetFeatureCount() == n
        assert lyr.GetSpatialRef().GetAuthorityCode(None) == "32633"
        f = lyr.GetNextFeature()
        assert f.GetField("sx") > 0 and f.GetGeometryRef().GetX() > 499000


# --------------------------------------------------------------------------------------------------
# a person looks at it: headless Chromium
# --------------------------------------------------------------------------------------------------

def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def test_report_renders_in_headless_chromium(built, tmp_path):
    from PIL import Image

    exe = _chromium()
    if exe is None:
        pytest.skip("headless screenshot needs Chromium: Debian package 'chromium' (make setup installs it)")
    result, _ = built
    shot = str(tmp_path / "report.png")
    proc = subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                           "--no-first-run", f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={shot}",
                           "--window-size=1280,2400", "file://" + result.path],
                          capture_output=True, text=True, timeout=120)
    assert os.path.isfile(shot), proc.stderr[-2000:]
    im = np.asarray(Image.open(shot).convert("RGB")).astype(float)
    assert im.shape[:2] == (2400, 1280)
    grey = im.mean(axis=2)
    assert grey.std() > 20  # not a blank page
    # the title bar and the "at a glance" cards are drawn: dark text in the top band
    assert (grey[:200] < 80).mean() > 0.002
    # the embedded plots were decoded and drawn: blue histogram bars (#4477aa) somewhere on the page
    blue = (np.abs(im[..., 0] - 0x44) < 25) & (np.abs(im[..., 1] - 0x77) < 25) & (np.abs(im[..., 2] - 0xAA) < 25)
    assert blue.sum() > 500


# --------------------------------------------------------------------------------------------------
# Processing
# --------------------------------------------------------------------------------------------------

def test_processing_accuracy_report(qgis_processing, qgis_iface, georeferenced, tmp_path):
    import archaeoortho
    from qgis import processing
    from qgis.core import QgsApplication

    ws = str(tmp_path / "ws")
    shutil.copytree(georeferenced, ws)
    plugin = archaeoortho.classFactory(qgis_iface)
    plugin.initProcessing()
    try:
        alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:accuracyreport")
        assert alg is not None and alg.shortHelpString()
        assert {"WORKSPACE", "UNCERTAINTY", "OUTPUT_HTML"} <= {p.name() for p in alg.parameterDefinitions()}
        assert {"OUTPUT_HTML", "WORKSPACE", "NSSDA_H", "CHECK_RMSE_XY", "ASPRS_2014_H_CLASS_CM"} <= {
            o.name() for o in alg.outputDefinitions()}
        res = processing.run("archaeoortho:accuracyreport", {"WORKSPACE": ws, "UNCERTAINTY": False})
        assert os.path.samefile(res["OUTPUT_HTML"], os.path.join(ws, "report.html"))
        assert res["WORKSPACE"] == ws
        stage = Workspace.open(ws).stage("georeference")["results"]
        assert res["NSSDA_H"] == pytest.approx(stage["NSSDA_H"], rel=1e-9)
        assert res["CHECK_RMSE_XY"] == pytest.approx(stage["CHECK_RMSE_XY"], rel=1e-9)
        other = str(tmp_path / "out" / "mine.html")
        res = processing.run("archaeoortho:accuracyreport", {"WORKSPACE": ws, "OUTPUT_HTML": other,
                                                              "UNCERTAINTY": False})
        assert res["OUTPUT_HTML"] == other and os.path.isfile(other)
        assert "products" in res["SECTIONS_SKIPPED"]
    finally:
        plugin.unload()
