"""Reflectance from a calibration panel (issue 37 item 2, core.prepare.band_radiometry / core.prepare.captures)
against a known truth: the synthetic rig of tests/rig_scene.py flies three captures under light changing by
+-30 %, and photographs a panel of reflectance 0.5 before (light 1.25) and after (light 0.8) the flight
(tests/panel_scene.py).  Stacked with the panel, the photos are float32 reflectance, within 2 % of the scene's
true reflectance in absolute terms (irradiance radiometry; measured: within 0.3 %); the same stack without the
panel's factor is not.  The panel's bad inputs are refused before any work, naming the files."""
from __future__ import annotations

import os
import shutil

import numpy as np
import pytest

from core.io.multispectral import read_band_info
from core.io.raster import RasterFile
from core.prepare.band_radiometry import (
    BandRadiometryError,
    PanelBand,
    measure_panel,
    panel_for_bands,
    panel_warnings,
    parse_panel_reflectance,
)
from core.prepare.captures import CaptureStackOptions, stack_captures
from core.prepare.options import PrepareError
from tests import panel_scene as ps
from tests import rig_scene as rs
from tests.conftest import shared


# ---------------------------------------------------------------- the panel's reflectance as given
def test_the_panel_reflectance_is_read_as_users_give_it(tmp_path):
    assert parse_panel_reflectance("0.5").for_band("NIR", 790) == 0.5
    p = parse_panel_reflectance("Green=0.49, Red=0.50; Red edge: 0.51,NIR=0.48")
    assert [p.for_band(n, None) for n in ("green", "RED", "RedEdge", "NIR", "Blue")] == [0.49, 0.5, 0.51, 0.48, None]
    sheet = tmp_path / "panel.csv"  # a panel's calibration sheet by wavelength, with a header and a comment
    sheet.write_text("# RP04 panel\nwavelength_nm,reflectance\n450,0.50\n550,0.52\n850,0.46\n")
    curve = parse_panel_reflectance(str(sheet))
    assert curve.for_band("Green", 550) == pytest.approx(0.52) and curve.for_band("NIR", 790) == pytest.approx(0.472)
    assert curve.for_band("x", 1000) is None  # beyond the curve by more than 10 nm
    names = tmp_path / "bands.csv"
    names.write_text("band;reflectance\nGreen;0.49\nNIR;0.47\n")
    assert parse_panel_reflectance(str(names)).for_band("NIR", None) == 0.47
    for text, message in (("49", r"49 % is 0.49"), ("Green=0.5,Green=0.4", "given twice"), ("", "no panel"),
                          ("Green=0.5,550=0.4", "either all by name or all by wavelength"),
                          ("bright", "not 'band=value'"), ("Green=1.2", "between 0 and 1")):
        with pytest.raises(BandRadiometryError, match=message):
            parse_panel_reflectance(text)


def test_a_band_the_rig_lacks_or_lacking_a_reflectance_is_named(tmp_path):
    from tests.test_multispectral import write_band, xmp

    infos = [read_band_info(write_band(tmp_path / f"IMG_{n}.TIF", xmp({"Camera:BandName": n},
                                                                         {"Camera:CentralWavelength": [nm]}), {}))
             for n, nm in (("Green", 550), ("NIR", 790))]
    assert panel_for_bands(parse_panel_reflectance("Green=0.49,NIR=0.47"), infos) == {"Green": 0.49, "NIR": 0.47}
    with pytest.raises(BandRadiometryError, match=r"the rig has no band Blue \(its bands: Green, NIR\)"):
        panel_for_bands(parse_panel_reflectance("Blue=0.5,Green=0.49,NIR=0.47"), infos)
    with pytest.raises(BandRadiometryError, match="gives none for band NIR: give every band's"):
        panel_for_bands(parse_panel_reflectance("Green=0.49"), infos)
    sheet = tmp_path / "short.csv"
    sheet.write_text("500,0.5\n600,0.5\n")
    with pytest.raises(BandRadiometryError, match=r"500..600 nm\) gives none for band NIR \(790 nm\)"):
        panel_for_bands(parse_panel_reflectance(str(sheet)), infos)


# ---------------------------------------------------------------- the panel measured
def _frame(panel=0.5, fraction=0.5, noise=0.005, shape=(240, 320), seed=0):
    rng = np.random.default_rng(seed)
    img = np.full(shape, 0.06) + rng.normal(0, 0.01, shape)  # textured ground
    side = int(fraction * min(shape))
    r0, c0 = (shape[0] - side) // 2, (shape[1] - side) // 2
    img[r0:r0 + side, c0:c0 + side] = panel * (1 + rng.normal(0, noise, (side, side)))
    return img


def test_the_panel_is_measured_in_its_central_window_and_refused_where_it_is_not_a_panel():
    img = _frame()
    raw = np.round(75 + 60000 * img).astype(np.uint16)
    assert measure_panel(img, raw, "P.TIF") == pytest.approx(0.5, rel=0.002)
    # a noisy band (5 % noise, 4 sigma beyond the 10 % tolerance) is still a panel: the tolerance follows the noise
    noisy = _frame(noise=0.05)
    assert measure_panel(noisy, np.round(75 + 60000 * noisy).astype(np.uint16), "P.TIF") == pytest.approx(0.5, rel=0.01)
    small = _frame(fraction=0.15)  # smaller than the window: ground in it
    with pytest.raises(BandRadiometryError, match=r"P\.TIF: the panel window .* is not uniform .* smaller panel window"):
        measure_panel(small, raw, "P.TIF")
    assert measure_panel(small, raw, "P.TIF", window=0.1) == pytest.approx(0.5, rel=0.002)
    with pytest.raises(BandRadiometryError, match=r"P\.TIF: .* is saturated \(100\.0 % of its pixels at 65535\)"):
        measure_panel(img, np.full(img.shape, 65535, np.uint16), "P.TIF")
    twelve = np.where(img > 0.3, 4095, 300).astype(np.uint16)  # 12-bit data clipped at 4095
    with pytest.raises(BandRadiometryError, match="saturated .* at 4095"):
        measure_panel(img, twelve, "P.TIF")
    with pytest.raises(BandRadiometryError, match="dark"):
        measure_panel(np.zeros((60, 80)), np.zeros((60, 80), np.uint16), "P.TIF")


def test_panel_captures_that_disagree_are_warned_of():
    same = PanelBand("NIR", 0.5, ("a", "b"), (100.0, 101.0))
    apart = PanelBand("Red", 0.5, ("PANEL0_RED.TIF", "PANEL1_RED.TIF"), (100.0, 110.0))
    assert same.factor == pytest.approx(0.5 / 100.5) and apart.disagreement == pytest.approx(0.1)
    warnings = panel_warnings([same, apart], "normalised")
    assert len(warnings) == 1 and "band Red: its captures differ by 10.0 %" in warnings[0]
    assert "irradiance radiometry" in warnings[0]


# ---------------------------------------------------------------- a block stacked with its panel
@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    root = tmp_path_factory.mktemp("panel")
    rig = rs.rig_block(n_strips=1, per_strip=3)
    bands = rs.render(rig, str(root / "bands"), supersample=1)
    panel = root / "panel"
    ps.render_panel(rig, str(panel), "0", 0.5, light=1.25, seed=0)  # before the flight
    ps.render_panel(rig, str(panel), "1", 0.5, light=0.8, seed=1)  # after: the light changed
    return rig, bands, panel, root


def _folder_state(folder):
    return sorted((n, os.path.getmtime(os.path.join(folder, n))) for n in os.listdir(folder))


def test_the_stacked_photos_hold_reflectance_within_2_percent_of_the_truth(flight, tmp_path):
    rig, bands, panel, _root = flight
    r = stack_captures(bands, CaptureStackOptions(str(tmp_path / "refl"), radiometry="irradiance",
                                                  panel=(str(panel),), panel_reflectance="0.5"))
    assert len(r.photos) == 3 and r.unit == "reflectance" and r.warnings == []
    assert set(r.panel) == {"Green", "Red", "Red edge", "NIR"}
    assert all(p.disagreement < 0.01 for p in r.panel.values())  # the sun sensor follows the light's change
    errors = [ps.reflectance_error(p, rig, k) for k, p in enumerate(r.photos)]
    for k, e in enumerate(errors):
        assert set(e) == set(rs.BANDS) and max(abs(v) for v in e.values()) < 0.02, (k, e)
    with RasterFile(r.photos[0]) as f:
        assert f.band(1).DataType == 6 and f.nodata(1) == 0.0  # float32, 0 = no data
        band_md = f.metadata(1)
        md = f.metadata()
        nir = f.read(1)
    assert band_md["RADIOMETRIC_UNIT"] == "reflectance" and band_md["PANEL_REFLECTANCE"] == "0.5"
    assert "calibration panel and the sun sensor" in band_md["RADIOMETRY"] and band_md["wavelength"] == "790"
    assert md["NIR_PANEL_REFLECTANCE"] == "0.5" and md["NIR_PANEL_FILES"] == "PANEL0_NIR.TIF,PANEL1_NIR.TIF"
    assert float(md["NIR_PANEL_FACTOR"]) == pytest.approx(r.panel["NIR"].factor, rel=1e-5)
    assert 0.25 < np.median(nir[nir > 0]) < 0.5  # NIR reflectance 0.30 .. 0.48 in the scene
    # the same stack without the panel's factor: DN proportional to reflectance, not reflectance
    plain = stack_captures(bands, CaptureStackOptions(str(tmp_path / "dn"), radiometry="irradiance"))
    assert plain.unit == "DN proportional to reflectance"
    assert min(abs(v) for v in ps.reflectance_error(plain.photos[0], rig, 0).values()) > 0.5


def test_a_normalised_stack_takes_the_light_of_its_panel(flight, tmp_path):
    """Normalised radiometry (no sun sensor): the panel fixes each band's constant under the panel's light, so a
    capture under that light is right within 2 %, the others off by their light's ratio; panel captures taken
    under different light are warned of and their mean used."""
    rig, bands, panel, _root = flight
    one = tmp_path / "one"
    one.mkdir()
    for p in os.listdir(panel):
        if p.startswith("PANEL0"):
            shutil.copy(panel / p, one)
    light = rs.light(1)
    ps.render_panel(rig, str(tmp_path / "at1"), "L", 0.5, light=light, seed=3)
    r = stack_captures(bands, CaptureStackOptions(str(tmp_path / "n"), radiometry="normalised",
                                                  panel=(str(tmp_path / "at1"),), panel_reflectance="0.5"))
    e = ps.reflectance_error(r.photos[1], rig, 1)
    assert max(abs(v) for v in e.values()) < 0.02, e
    e0 = ps.reflectance_error(r.photos[0], rig, 0)
    assert all(v == pytest.approx(rs.light(0) / light - 1, abs=0.01) for v in e0.values()), e0
    both = stack_captures(bands, CaptureStackOptions(str(tmp_path / "b"), radiometry="normalised",
                                                     panel=(str(panel),), panel_reflectance="0.5"))
    assert len(both.warnings) == 4 and all("differ by 56" in w for w in both.warnings)


def test_panel_files_among_the_band_files_are_not_stacked(flight, tmp_path):
    """The panel's capture left in the band folder: given as the panel (the same files) or as a copy elsewhere
    (the same capture id), it is the panel, not a photo of the block, and the warnings say so."""
    rig, bands, panel, _root = flight
    folder = tmp_path / "bands"
    folder.mkdir()
    for p in bands:
        shutil.copy(p, folder)
    mine = [shutil.copy(panel / n, folder) for n in sorted(os.listdir(panel)) if n.startswith("PANEL0")]
    from core.io.multispectral import band_files

    r = stack_captures(band_files(str(folder)), CaptureStackOptions(str(tmp_path / "a"), panel=tuple(mine),
                                                                     panel_reflectance="0.5"))
    assert len(r.photos) == 3 and any("4 band file(s) of the calibration panel" in w for w in r.warnings)
    r = stack_captures(band_files(str(folder)), CaptureStackOptions(str(tmp_path / "b"), panel=(str(panel),),
                                                                     panel_reflectance="0.5"))
    assert len(r.photos) == 3 and any("PANELCAPTURE0 among the band files" in w for w in r.warnings)


def test_bad_panels_are_refused_before_any_work_naming_the_files(flight, tmp_path):
    rig, bands, panel, _root = flight
    out = tmp_path / "out"
    before = _folder_state(os.path.dirname(bands[0])), _folder_state(panel)

    def refused(error, message, panel_paths, reflectance="0.5", **kw):
        with pytest.raises(error, match=message):
            stack_captures(bands, CaptureStackOptions(str(out), panel=tuple(map(str, panel_paths)),
                                                      panel_reflectance=reflectance, **kw))
        assert not out.exists()

    lacking = tmp_path / "lacking"
    lacking.mkdir()
    for n in os.listdir(panel):
        if n.startswith("PANEL0") and not n.endswith("_NIR.TIF"):
            shutil.copy(panel / n, lacking)
    refused(PrepareError, r"panel capture PANELCAPTURE0 lacks band NIR \(files: PANEL0_GRE.TIF", [lacking])
    sequoia = [os.path.join(shared("sequoia_sample"), n) for n in os.listdir(shared("sequoia_sample"))
               if n.upper().endswith(".TIF")]
    refused(PrepareError, r"IMG_161122_163234_0000_GRE.TIF \(band Green, 1280 x 960 px, rig Sequoia\).* not of the "
                          r"flight's camera \(bands Green, Red, Red edge, NIR, 640 x 480 px, rig SynthRig\)", sequoia)
    refused(BandRadiometryError, r"the rig has no band Blue", [panel], "Blue=0.5,Green=0.5,Red=0.5,NIR=0.5")
    refused(BandRadiometryError, r"gives none for band Red edge", [panel], "Green=0.5,Red=0.5,NIR=0.5")
    bright = tmp_path / "bright"
    ps.render_panel(rig, str(bright), "S", 0.95, seed=4)
    refused(BandRadiometryError, r"in 4 file\(s\): .*PANELS_GRE.TIF: the panel window .* is saturated", [bright])
    small = tmp_path / "small"
    ps.render_panel(rig, str(small), "T", 0.5, fraction=0.15, seed=5)
    refused(BandRadiometryError, r"PANELT_GRE.TIF: the panel window \(the central 120 x 120 px.* is not uniform",
            [small])
    refused(PrepareError, "no such file or folder", [tmp_path / "nowhere"])
    refused(PrepareError, "raw DN cannot be calibrated", [panel], radiometry="raw")
    with pytest.raises(PrepareError, match="without the panel's reflectance"):
        CaptureStackOptions(str(out), panel=(str(panel),))
    with pytest.raises(PrepareError, match=r"a panel reflectance \(0.5\) without the panel's captures"):
        CaptureStackOptions(str(out), panel_reflectance="0.5")
    with pytest.raises(PrepareError, match="holds the band files"):  # nor is the panel's folder written into
        stack_captures(bands, CaptureStackOptions(str(panel), panel=(str(panel),), panel_reflectance="0.5"))
    assert (_folder_state(os.path.dirname(bands[0])), _folder_state(panel)) == before
    # the small panel is measured in a smaller window
    r = stack_captures(bands[:4], CaptureStackOptions(str(out), panel=(str(small),), panel_reflectance="0.5",
                                                      panel_window=0.1))
    assert len(r.photos) == 1 and r.unit == "reflectance"


def test_qgis_process_stacks_with_the_panel(flight, tmp_path):
    """archaeoortho:stackcaptures headless with Calibration panel folder and Panel reflectance: reflectance photos;
    a panel reflectance for a band the rig lacks refused with its message, no traceback, nothing written."""
    import json
    import subprocess

    from tests.conftest import qgis_process

    _rig, bands, panel, _root = flight
    exe, env = qgis_process()

    def run(output, *args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:stackcaptures", "--",
                               f"INPUT={os.path.dirname(bands[0])}", f"OUTPUT={output}", f"PANEL={panel}", *args],
                              env=env, capture_output=True, text=True, timeout=300)

    out = run(tmp_path / "photos", "RADIOMETRY=2", "PANEL_REFLECTANCE=Green=0.5,Red=0.5,Red edge=0.5,NIR=0.5",
              "PANEL_WINDOW=0.2")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    assert json.loads(out.stdout)["results"]["PHOTOS"] == 3
    with RasterFile(str(tmp_path / "photos" / "IMG_0000.tif")) as r:
        assert r.metadata(1)["RADIOMETRIC_UNIT"] == "reflectance"
    out = run(tmp_path / "refused", "PANEL_REFLECTANCE=Blue=0.5")
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "the rig has no band Blue" in text and "Traceback" not in text, text[-2000:]
    assert not (tmp_path / "refused").exists() or not os.listdir(tmp_path / "refused")


# ---------------------------------------------------------------- through the chain
@pytest.mark.slow
def test_the_orthomosaic_of_reflectance_photos_is_reflectance(tmp_path):
    """Ten captures stacked with the panel (irradiance radiometry) -> Run pipeline on the photos -> the
    orthomosaic: float32, each band stating reflectance, within 2 % of the true reflectance over open ground (the
    ortho leaves the values as they are: no exposure gains, no radiometric model); NDVI of it against the truth's.
    The bands at half the rig's size (320 x 240 px, 19 cm cells), the DSM at quarter quality and no DTM: the
    reflectance is the product, not the surface.  Measured: reflectance within 0.05 % in every band, NDVI's
    median error 0.005, 134 000 cells of open ground."""
    from core import pipeline
    from core.align.options import AlignOptions
    from core.dense.options import DenseOptions
    from core.spectral.index import spectral_index
    from core.spectral.options import IndexOptions
    from tests import synthetic as syn

    rig = rs.rig_block(n_strips=2, per_strip=5, width=320, height=240)
    bands = rs.render(rig, str(tmp_path / "bands"), supersample=1)
    ps.render_panel(rig, str(tmp_path / "panel"), "0", 0.5, light=1.25, seed=0)
    ps.render_panel(rig, str(tmp_path / "panel"), "1", 0.5, light=0.8, seed=1)
    stack = stack_captures(bands, CaptureStackOptions(str(tmp_path / "photos"), radiometry="irradiance",
                                                      panel=(str(tmp_path / "panel"),), panel_reflectance="0.5"))
    assert len(stack.photos) == 10
    result = pipeline.run_pipeline(str(tmp_path / "photos"), str(tmp_path / "ws"), pipeline.PipelineOptions(
        align=AlignOptions(num_threads=2), dense=DenseOptions(quality="quarter"), make_report=False, make_dtm=False),
        pipeline.Control(camera_positions_path=str(tmp_path / "camera_positions.csv")))
    assert result.align.registered == 10
    assert any("calibrated reflectance" in line for line in result.ortho.log_lines)
    with RasterFile(result.ortho.orthomosaic) as r:
        assert r.count == 4 and r.band(1).DataType == 6  # float32, NaN = no data (no alpha band)
        assert [r.band(i + 1).GetDescription() for i in range(4)] == ["NIR", "Red", "Green", "Red edge"]
        assert all(r.metadata(i + 1)["RADIOMETRIC_UNIT"] == "reflectance" for i in range(4))
    data, x, y, valid = rs._ortho_bands(result.ortho.orthomosaic)
    ground = valid & ~rig.block.scene.near_feature(x - syn.ORIGIN[0], y - syn.ORIGIN[1], 1.5)
    assert ground.sum() > 20000
    errors = {b: float(np.median(v[ground] / rig.reflectance(b, x, y)[ground]) - 1.0) for b, v in data.items()}
    assert max(abs(e) for e in errors.values()) < 0.02, errors
    out = spectral_index(IndexOptions(input=result.ortho.orthomosaic, output=str(tmp_path / "ndvi.tif")))
    with RasterFile(out.path) as r:
        ndvi = r.read(1).astype(float)
    ok = ground & np.isfinite(ndvi)
    truth = rig.ndvi(x, y)
    assert np.median(np.abs(ndvi[ok] - truth[ok])) < 0.01
