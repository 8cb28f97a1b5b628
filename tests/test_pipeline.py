"""The whole chain: the shipped Processing model (.model3) and archaeoortho:runpipeline, run by qgis_process as a
user runs them, on a strip of the bundled Toledo sample georeferenced with its EXIF GPS."""
import json
import os
import re
import subprocess

import numpy as np
import pytest

from tests.conftest import ROOT, SAMPLE, TOLEDO_STRIP, copy_images, qgis_process

MODEL = os.path.join(ROOT, "processing_provider", "models", "orthophoto_chain.model3")


def _raster(path):
    from osgeo import gdal

    ds = gdal.Open(path)
    assert ds is not None, path
    band = ds.GetRasterBand(1)
    return ds, band.ReadAsArray().astype(float), band.GetNoDataValue()


def _check_products(dsm, mosaic, report):
    from osgeo import osr

    ds, z, nodata = _raster(dsm)
    srs = osr.SpatialReference(wkt=ds.GetProjection())
    assert srs.GetAuthorityCode(None) == "32617"  # the UTM zone of the photos' GPS
    valid = z != nodata
    assert valid.mean() > 0.8
    # houses and trees stand above the ground: a real surface, not a plane
    lo, hi = np.percentile(z[valid], [5, 95])
    assert 3.0 < hi - lo < 60.0, (lo, hi)
    ms, band1, _ = _raster(mosaic)
    assert ms.RasterCount == 4  # RGB + alpha
    alpha = ms.GetRasterBand(4).ReadAsArray()
    assert (alpha > 0).mean() > 0.6
    gt_d, gt_m = ds.GetGeoTransform(), ms.GetGeoTransform()
    # the mosaic lies over the DSM (same place on the ground, within a DSM cell)
    assert abs(gt_d[0] - gt_m[0]) < 5 * gt_d[1] and abs(gt_d[3] - gt_m[3]) < 5 * gt_d[1]
    html = open(report, encoding="utf-8").read()
    assert "data:image/png;base64" in html and "EPSG:32617" in html


@pytest.fixture(scope="module")
def strip(tmp_path_factory):
    d = tmp_path_factory.mktemp("chain")
    return copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP, str(d / "photos"))


@pytest.mark.slow
def test_shipped_model_chains_the_stages_through_the_workspace(strip, tmp_path):
    """qgis_process run <model file>: Align -> Georeference -> Build DSM -> Build orthophoto -> Accuracy report."""
    exe, env = qgis_process()
    ws = str(tmp_path / "model ws")
    out = subprocess.run([exe, "--json", "run", MODEL, "--", f"IMAGES={strip}", "USE_EXIF_GPS=true", "QUALITY=2",
                          f"align:Workspace={ws}"], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    res = json.loads(out.stdout)["results"]
    assert os.path.samefile(res["align:Workspace"], ws)
    assert os.path.samefile(res["dsm:DSM"], os.path.join(ws, "dsm.tif"))
    _check_products(res["dsm:DSM"], res["ortho:Orthomosaic"], res["report:Report"])
    stages = json.load(open(os.path.join(ws, "workspace.json")))["stages"]
    for s in ("align", "georeference", "dsm", "orthophoto", "report"):
        assert stages[s]["status"] == "done", (s, stages[s].get("status"))


@pytest.mark.slow
def test_runpipeline_from_qgis_process_and_resume(strip, tmp_path):
    exe, env = qgis_process()
    ws = str(tmp_path / "pipe ws")
    args = [exe, "--json", "run", "archaeoortho:runpipeline", "--", f"IMAGES={strip}", f"WORKSPACE={ws}",
            "USE_EXIF_GPS=true", "QUALITY=2", "MAX_IMAGE_SIZE=800"]
    out = subprocess.run(args, env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    doc = json.loads(out.stdout)
    res = doc["results"]
    assert res["REGISTERED_IMAGES"] == len(TOLEDO_STRIP)
    assert res["MEAN_REPROJECTION_ERROR"] < 1.0
    assert res["CAMERA_RMSE_XYZ"] is not None and res["CAMERA_RMSE_XYZ"] < 10.0  # consumer GPS
    assert res["DSM_VALID_FRACTION"] > 0.8 and res["ORTHO_VALID_FRACTION"] > 0.6
    _check_products(res["DSM"], res["ORTHOMOSAIC"], res["REPORT"])
    assert any("Seconds per stage" in line for line in doc["log"]["info"])
    warnings = doc["log"].get("warning", [])  # each once: the stages log them as they run, the end adds none again
    assert len(warnings) == len(set(warnings)), warnings
    # a second run resumes: features and matches are reused, the products are rewritten whole
    before = os.path.getmtime(res["DSM"])
    out2 = subprocess.run(args, env=env, capture_output=True, text=True, timeout=900)
    assert out2.returncode == 0, out2.stderr[-3000:]
    log2 = "\n".join(json.loads(out2.stdout)["log"]["info"])
    assert re.search(r"features: \d+ images already extracted, reused", log2), log2
    assert re.search(r"matching: (\d+) of \1 pairs already matched, reused", log2), log2
    assert os.path.getmtime(res["DSM"]) >= before


@pytest.mark.slow
def test_runpipeline_without_control_refuses_before_any_work(strip, tmp_path):
    exe, env = qgis_process()
    ws = tmp_path / "no control"
    out = subprocess.run([exe, "run", "archaeoortho:runpipeline", "--", f"IMAGES={strip}", f"WORKSPACE={ws}"],
                         env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert "camera positions" in out.stdout + out.stderr
    assert not (ws / "workspace.json").exists()


def test_core_run_pipeline_refuses_without_control(tmp_path):
    from core.pipeline import run_pipeline
    from core.project.stages import StageError

    with pytest.raises(StageError, match="ground control"):
        run_pipeline(str(tmp_path / "photos"), str(tmp_path / "ws"))
    assert not (tmp_path / "ws").exists()


def test_the_stage_options_are_the_settings(tmp_path, monkeypatch):
    """PipelineOptions(dense=DenseOptions(quality="full"), ortho=OrthoOptions(blending="multiband")) ran at half
    quality with feather blending: the pipeline's own dsm_quality / blending fields won (issue 35). Now the stages
    get each stage's options once, and a stage's keyword left out means the options' value."""
    import types

    from core import pipeline
    from core.dense.options import DenseError, DenseOptions
    from core.ortho.options import OrthoError, OrthoOptions
    from core.ortho.stage import build_orthophoto_workspace

    calls = {}

    def spy(name):
        def stage(*args, **kwargs):
            calls[name] = (args, kwargs)
            return types.SimpleNamespace(warnings=[])
        return stage

    for name in ("align", "georeference_workspace", "build_dsm_workspace", "build_orthophoto_workspace"):
        monkeypatch.setattr(pipeline, name, spy(name))
    monkeypatch.setattr(pipeline, "check_inputs", lambda *a: None)
    dense, ortho = DenseOptions(quality="full"), OrthoOptions(blending="multiband", resolution=0.25)
    pipeline.run_pipeline(str(tmp_path / "photos"), str(tmp_path / "ws"),
                          pipeline.PipelineOptions(dense=dense, ortho=ortho, make_dtm=False, make_report=False),
                          pipeline.Control(use_exif_gps=True))
    # (workspace, options, progress): nothing beside the options
    assert calls["build_dsm_workspace"][0][1] is dense and len(calls["build_dsm_workspace"][0]) == 3
    assert calls["build_orthophoto_workspace"][0][1] is ortho and len(calls["build_orthophoto_workspace"][0]) == 3
    assert not calls["build_dsm_workspace"][1] and not calls["build_orthophoto_workspace"][1]
    # the stages themselves: no keyword = the options' value; a keyword given wins (the DSM stage takes none)
    with pytest.raises(DenseError, match="QUALITY"):
        DenseOptions(quality="fine")
    with pytest.raises(OrthoError, match="BLENDING"):  # the options' blending is checked, not a default's
        build_orthophoto_workspace(str(tmp_path / "no-ws"), options=OrthoOptions(blending="smooth"))


def test_the_pipeline_chains_find_targets_into_the_georeference(tmp_path, monkeypatch):
    """Control(targets_path=...): after the alignment Find targets runs, and its observations file is the
    georeference's ground control (issue 34: 'Run pipeline can chain both'); targets and GCPs together are
    refused before any work, and a targets file that cannot be read is named before the alignment."""
    import types

    from core import pipeline
    from core.geometry.crs import CRSError
    from core.project.stages import StageError

    calls = []

    def spy(name, result=None):
        def stage(*args, **kwargs):
            calls.append((name, args, kwargs))
            return result or types.SimpleNamespace(warnings=[])
        return stage

    found = types.SimpleNamespace(gcps_path=str(tmp_path / "ws" / "found.txt"), reports=["T9: fits no mark"],
                                  n_targets=3, n_observations=9, targets=[1, 2, 3, 4], crs="EPSG:32611")
    for name in ("align", "georeference_workspace", "build_dsm_workspace", "build_orthophoto_workspace"):
        monkeypatch.setattr(pipeline, name, spy(name))
    monkeypatch.setattr(pipeline, "find_targets", spy("find_targets", found))
    targets = tmp_path / "targets.csv"
    targets.write_text("# crs: EPSG:32611\nname,x,y,z\nT1,500000,4000000,10\nT2,500010,4000000,11\n"
                       "T3,500000,4000010,12\nT4,500010,4000010,10\n")
    photos = tmp_path / "photos"
    photos.mkdir()
    monkeypatch.setattr(pipeline, "require_images", lambda *a: None)
    monkeypatch.setattr(pipeline, "check_block_size", lambda *a: None)  # no photos here: the stages are spies
    monkeypatch.setattr(pipeline, "list_images", lambda *a: [])
    res = pipeline.run_pipeline(str(photos), str(tmp_path / "ws"), pipeline.PipelineOptions(
        make_dtm=False, make_report=False), pipeline.Control(targets_path=str(targets)))
    order = [c[0] for c in calls]
    assert order == ["align", "find_targets", "georeference_workspace", "build_dsm_workspace",
                     "build_orthophoto_workspace"]
    assert calls[1][1][1].targets == str(targets) and res.targets is found
    assert calls[2][1][1].gcp_path == found.gcps_path and calls[2][1][1].gcps is None
    with pytest.raises(StageError, match="not both"):
        pipeline.run_pipeline(str(photos), str(tmp_path / "ws2"), control=pipeline.Control(
            targets_path=str(targets), gcp_path=str(targets)))
    bad = tmp_path / "bad.csv"
    bad.write_text("name,x,y,z\nT1,500000,north,10\n")
    calls.clear()
    with pytest.raises(CRSError, match="bad.csv"):  # core.io.gcp.GCPError is this class
        pipeline.run_pipeline(str(photos), str(tmp_path / "ws3"), control=pipeline.Control(
            targets_path=str(bad), crs="EPSG:32611"))
    assert not calls  # nothing ran


def test_the_camera_positions_also_choose_the_alignments_pairs(tmp_path, monkeypatch):
    """Control(camera_positions_path=...) reaches the alignment as AlignOptions.camera_positions (spatial pairs
    for photos without EXIF GPS, issue 33) and the georeference as before; an alignment's own file is kept."""
    import types

    from core import pipeline
    from core.align.options import AlignOptions

    calls = {}

    def spy(name):
        def stage(*args, **kwargs):
            calls[name] = args
            return types.SimpleNamespace(warnings=[])
        return stage

    for name in ("align", "georeference_workspace", "build_dsm_workspace", "build_orthophoto_workspace"):
        monkeypatch.setattr(pipeline, name, spy(name))
    monkeypatch.setattr(pipeline, "check_inputs", lambda *a: None)
    log, own = tmp_path / "gnss.csv", tmp_path / "own.csv"
    for f in (log, own):
        f.write_text("EPSG:32633\nimage,x,y,z,sigma\na.jpg,500000,4600000,120,2\nb.jpg,500020,4600000,120,2\n")
    for given, expected in ((AlignOptions(), str(log)), (AlignOptions(camera_positions=str(own)), str(own))):
        pipeline.run_pipeline(str(tmp_path / "photos"), str(tmp_path / "ws"),
                              pipeline.PipelineOptions(align=given, make_dtm=False, make_report=False),
                              pipeline.Control(camera_positions_path=str(log)))
        assert calls["align"][2].camera_positions == expected
        assert calls["georeference_workspace"][1].camera_positions_path == str(log)


def test_one_capture_or_one_photo_is_not_a_block(tmp_path, monkeypatch):
    """Issue 48 item 1: a folder holding one multispectral capture (the Sequoia sample: four bands and the RGB
    frame, taken from one position) was stacked and escalated for 21.6 s before 'no initial pair'; one photo went
    as far as the alignment.  Both are refused before any stacking or alignment, naming the folder and the count."""
    import shutil

    from core import pipeline
    from core.project.stages import StageError
    from tests.conftest import shared

    def no_work(*a, **k):
        raise AssertionError("a stage ran")

    monkeypatch.setattr(pipeline, "stack_capture_folder", no_work)
    monkeypatch.setattr(pipeline, "align", no_work)
    capture = tmp_path / "one capture"
    shutil.copytree(shared("sequoia_sample"), capture)
    with pytest.raises(StageError, match=r"one capture .* at least 2 captures") as e:
        pipeline.run_pipeline(str(capture), str(tmp_path / "ws"), control=pipeline.Control(use_exif_gps=True))
    assert str(capture) in str(e.value)
    assert not (tmp_path / "ws").exists()
    photo = tmp_path / "one photo"
    copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:1], str(photo))
    with pytest.raises(StageError, match=r"one photo .* at least 2 photos") as e:
        pipeline.run_pipeline(str(photo), str(tmp_path / "ws"), control=pipeline.Control(use_exif_gps=True))
    assert str(photo) in str(e.value) and TOLEDO_STRIP[0] in str(e.value)
    assert not (tmp_path / "ws").exists()
