"""Run pipeline with a calibration panel (issue 37): the band folder's captures stacked with the panel's captures
and its reflectance (PipelineOptions.capture_panel / capture_panel_reflectance / capture_panel_window, Processing's
Calibration panel folder / Panel reflectance / Panel window) give a float32 reflectance orthomosaic; a bad panel is
refused before the alignment, naming what is wrong, nothing aligned.

The synthetic rig of tests/rig_scene.py flies two strips of three captures under light changing by +-30 %, with
a panel of reflectance 0.5 photographed before (light 1.25) and after (light 0.8) the flight (tests/panel_scene.py);
irradiance radiometry, so the sun sensor follows the light.  The orthomosaic's bands are within 2 % of the true
reflectance over open ground (tests/test_panel_calibration.py has the ten-capture chain through Stack captures)."""
from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

from tests import panel_scene as ps
from tests import rig_scene as rs


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    root = tmp_path_factory.mktemp("pipepanel")
    rig = rs.rig_block(n_strips=2, per_strip=3)
    rs.render(rig, str(root / "bands"), supersample=1)
    ps.render_panel(rig, str(root / "panel"), "0", 0.5, light=1.25, seed=0)  # before the flight
    ps.render_panel(rig, str(root / "panel"), "1", 0.5, light=0.8, seed=1)  # after: the light changed
    return rig, root


def _options(**kw):
    from core import pipeline
    from core.align.options import AlignOptions
    from core.dense.options import DenseOptions

    return pipeline.PipelineOptions(align=AlignOptions(num_threads=2), dense=DenseOptions(quality="quarter"),
                                    make_report=False, make_dtm=False, capture_radiometry="irradiance", **kw)


def _control(root):
    from core import pipeline

    return pipeline.Control(camera_positions_path=str(root / "camera_positions.csv"))


@pytest.mark.slow
def test_run_pipeline_with_the_panel_gives_a_reflectance_orthomosaic(flight):
    from core import pipeline
    from core.io.raster import RasterFile
    from tests import synthetic as syn

    rig, root = flight
    result = pipeline.run_pipeline(str(root / "bands"), str(root / "ws"), _options(
        capture_panel=str(root / "panel"), capture_panel_reflectance="0.5", capture_panel_window=0.2),
        _control(root))
    assert result.captures.unit == "reflectance" and set(result.captures.panel) == set(rs.BANDS)
    assert result.align.registered == len(rig.block.shots) == 6
    with RasterFile(result.ortho.orthomosaic) as r:
        assert r.count == 4 and r.band(1).DataType == 6  # float32
        assert all(r.metadata(i + 1)["RADIOMETRIC_UNIT"] == "reflectance" for i in range(4))
        assert r.metadata(1)["PANEL_REFLECTANCE"] == "0.5"
    data, x, y, valid = rs._ortho_bands(result.ortho.orthomosaic)
    ground = valid & ~rig.block.scene.near_feature(x - syn.ORIGIN[0], y - syn.ORIGIN[1], 1.5)
    assert ground.sum() > 5000
    errors = {b: float(np.median(v[ground] / rig.reflectance(b, x, y)[ground]) - 1.0) for b, v in data.items()}
    assert set(errors) == set(rs.BANDS) and max(abs(e) for e in errors.values()) < 0.02, errors
    print("reflectance errors", {b: f"{100 * e:+.2f} %" for b, e in errors.items()}, int(ground.sum()), "cells")


def test_a_bad_panel_is_refused_before_the_alignment_naming_it(flight, tmp_path):
    from core import pipeline
    from core.prepare.band_radiometry import BandRadiometryError
    from core.prepare.options import PrepareError
    from core.project.stages import StageError

    _rig, root = flight
    bands, panel = str(root / "bands"), str(root / "panel")

    def refused(error, message, images=bands, **kw):
        ws = tmp_path / f"ws{len(os.listdir(tmp_path))}"
        with pytest.raises(error, match=message):
            pipeline.run_pipeline(images, str(ws), _options(**kw), _control(root))
        assert not (ws / "sfm").exists() and not (ws / "captures").exists()  # nothing aligned, nothing stacked
        return ws

    # a reflectance for a band the rig lacks: the stacking's first check, before any capture is registered
    given = "Blue=0.5,Green=0.5,Red=0.5,NIR=0.5"
    refused(BandRadiometryError, rf"panel reflectance '{given}': the rig has no band Blue \(its bands: Green",
            capture_panel=panel, capture_panel_reflectance=given)
    # checked up front, before the workspace is made
    for kw, error, message in (
            ({"capture_panel": str(tmp_path / "nowhere"), "capture_panel_reflectance": "0.5"}, PrepareError,
             r"calibration panel .*nowhere: no such file or folder"),
            ({"capture_panel": panel}, PrepareError, "without the panel's reflectance"),
            ({"capture_panel_reflectance": "0.5"}, PrepareError, "without the panel's captures"),
            ({"capture_panel": panel, "capture_panel_reflectance": "1.7"}, BandRadiometryError, "1.7"),
            ({"capture_panel": panel, "capture_panel_reflectance": "0.5", "capture_panel_window": 0}, PrepareError,
             "panel window 0"),
            ({"capture_panel": panel, "capture_panel_reflectance": "0.5", "captures": "off"}, StageError,
             "captures is off"),
    ):
        assert not refused(error, message, **kw).exists(), kw
    photos = tmp_path / "photos"  # a folder of photos (one band's files) is not stacked: its panel is refused
    photos.mkdir()
    for name in sorted(n for n in os.listdir(bands) if n.endswith("_GRE.TIF"))[:2]:  # two: a block (issue 48)
        os.link(os.path.join(bands, name), photos / name)
    assert not refused(StageError, "is not a folder of a rig's band files", str(photos), capture_panel=panel,
                       capture_panel_reflectance="0.5").exists()


def test_qgis_process_run_pipeline_refuses_a_bad_panel(flight, tmp_path):
    """archaeoortho:runpipeline headless with Capture radiometry, Calibration panel folder, Panel reflectance and
    Panel window: a reflectance for a band the rig lacks is refused with its message, no traceback, nothing
    aligned; Capture radiometry is the form's (advanced, normalised by default) and an unknown choice is refused
    before the run."""
    import json

    from tests.conftest import qgis_process

    _rig, root = flight
    exe, env = qgis_process()
    ws = tmp_path / "ws"
    out = subprocess.run([exe, "--json", "help", "archaeoortho:runpipeline"], env=env, capture_output=True,
                         text=True, timeout=300)
    radiometry = json.loads(out.stdout)["parameters"]["CAPTURE_RADIOMETRY"]
    assert radiometry["description"] == "Capture radiometry" and radiometry["is_advanced"], radiometry
    assert radiometry["raw_definition"]["options"] == ["raw", "normalised", "irradiance"]
    assert radiometry["default_value"] == 1, radiometry
    out = subprocess.run([exe, "--json", "run", "archaeoortho:runpipeline", "--", f"IMAGES={root / 'bands'}",
                          f"WORKSPACE={ws}", f"CAMERA_POSITIONS={root / 'camera_positions.csv'}",
                          "CAPTURE_RADIOMETRY=3"], env=env, capture_output=True, text=True, timeout=300)
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "Incorrect parameter value for CAPTURE_RADIOMETRY" in text, text[-3000:]
    assert not ws.exists()
    out = subprocess.run([exe, "--json", "run", "archaeoortho:runpipeline", "--", f"IMAGES={root / 'bands'}",
                          f"WORKSPACE={ws}", f"CAMERA_POSITIONS={root / 'camera_positions.csv'}",
                          f"PANEL={root / 'panel'}", "PANEL_REFLECTANCE=Blue=0.5", "PANEL_WINDOW=0.2",
                          "CAPTURE_RADIOMETRY=2"],
                         env=env, capture_output=True, text=True, timeout=300)
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "the rig has no band Blue" in text and "Traceback" not in text, text[-3000:]
    assert not (ws / "sfm").exists()
    # without a reflectance the panel is refused by its options, naming the parameter's meaning
    out = subprocess.run([exe, "--json", "run", "archaeoortho:runpipeline", "--", f"IMAGES={root / 'bands'}",
                          f"WORKSPACE={ws}", f"CAMERA_POSITIONS={root / 'camera_positions.csv'}",
                          f"PANEL={root / 'panel'}"], env=env, capture_output=True, text=True, timeout=300)
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "without the panel's reflectance" in text and "Traceback" not in text, text[-3000:]
    assert not (ws / "sfm").exists()
