"""Per-band radiometry (core/prepare/band_radiometry.py, issue 37 item 2) against a synthetic truth: band files
made from a known reflectance field with the forward model the module inverts (dark level + reflectance x sun
irradiance x exposure x gain x vignetting, plus sensor noise), in Sequoia, MicaSense and DJI form.  After the
correction the values divided by the true reflectance must be one constant per band, over the frame (vignetting
gone) and over captures taken with other exposures, gains and light (irradiance mode): within 2 %."""
from __future__ import annotations

import base64
import struct

import numpy as np
import pytest

from core.io.multispectral import read_band_info
from core.prepare.band_radiometry import (
    BandRadiometryError,
    band_factors,
    block_scales,
    check_bands,
    correct,
    sun_irradiance,
    vignetting_falloff,
)
from tests.test_multispectral import write_band, xmp

H, W = 120, 160
# the real Sequoia NIR band's vignetting (sequoia_sample, IMG_161122_163234_0000_NIR.TIF): 0.67 at a corner
SEQ_POWERS = "0,0,1,0,2,0,3,0,4,0,0,1,0,2,0,3,0,4,1,1,1,2,1,3,2,1,2,2,3,1"
SEQ_CALIBRATION = "0,600,35,17,1,600,857,437,2,600,14302,7152,3,600,65535,65535"
SUN_PER_MS = {0: 35 / 600, 1: 857 / 600, 2: 14302 / 600}  # the calibration light, ch0 per ms at each gain index


def _sequoia_coefficients():
    import os

    from tests.conftest import shared

    info = read_band_info(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_NIR.TIF"))
    return info.vignetting.coefficients


def _reflectance(seed=0):
    """A smooth field of reflectance 0.05 .. 0.6 (a field with crop marks, as far as radiometry cares)."""
    rng = np.random.default_rng(seed)
    small = rng.uniform(0.05, 0.6, (7, 9))
    import cv2

    return cv2.resize(small, (W, H), interpolation=cv2.INTER_CUBIC).clip(0.05, 0.6)


def _irradiance_list(irradiance, gain_index=1, integration_ms=100, n=5):
    """Sequoia IrradianceList records whose ch0 is ``irradiance`` times the calibration light."""
    ch0 = int(round(irradiance * SUN_PER_MS[gain_index] * integration_ms))
    raw = b"".join(struct.pack("<QHHHHfff", 1000 * k, ch0, ch0 // 3, gain_index, integration_ms, 0.0, 0.0, 0.0)
                   for k in range(n))
    return base64.b64encode(raw).decode()


def _dn(truth, falloff, dark, k, irradiance, exposure, gain, seed):
    rng = np.random.default_rng(seed)
    signal = k * truth * irradiance * exposure * gain * falloff
    return np.clip(np.round(dark + signal + rng.normal(0, 1.0, truth.shape)), 0, 65535).astype(np.uint16)


def _sequoia_band(path, truth, irradiance, exposure, iso, seed, sun=True):
    coeffs = _sequoia_coefficients()
    attrs = {"Camera:BandName": "NIR", "Camera:RigName": "Sequoia", "Camera:CaptureUUID": f"C{seed}"}
    seqs = {"Camera:BlackCurrent": [75], "Camera:VignettingPolynomial2DName": [SEQ_POWERS],
            "Camera:VignettingPolynomial2D": [",".join(repr(c) for c in coeffs)]}
    if sun:
        attrs["Camera:IrradianceList"] = _irradiance_list(irradiance)
        attrs["Camera:IrradianceCalibrationMeasurement"] = SEQ_CALIBRATION
    falloff = vignetting_falloff(read_band_info(write_band(path, xmp(attrs, seqs), _exif(exposure, iso),
                                                           np.zeros((H, W), np.uint16))), (H, W))
    dn = _dn(truth, falloff, 75, 2.0e7, irradiance, exposure, iso / 100.0, seed)
    return read_band_info(write_band(path, xmp(attrs, seqs), _exif(exposure, iso), dn))


def _exif(exposure, iso):
    return {"EXIF_DateTimeOriginal": "2023:05:01 10:00:00", "EXIF_ExposureTime": f"{exposure:.6g}",
            "EXIF_ISOSpeedRatings": f"{iso:g}", "EXIF_FNumber": "2.2"}


def _flat_and_steady(values, truths, tolerance=0.02):
    """The corrected values over the truth: one constant (within ``tolerance``) over every pixel of every capture
    (the darkest pixels, where noise dominates, left out)."""
    ratios = np.concatenate([(v / t)[t > 0.1].ravel() for v, t in zip(values, truths)])
    centre = np.median(ratios)
    assert np.percentile(np.abs(ratios / centre - 1.0), 99) < tolerance
    per_capture = [np.median((v / t)[t > 0.1]) for v, t in zip(values, truths)]
    assert max(per_capture) / min(per_capture) - 1.0 < tolerance
    return centre


def test_sequoia_bands_become_proportional_to_reflectance(tmp_path):
    """Three captures of one field under light changing by 40 %, with other exposures and gains: in irradiance
    mode the corrected values are reflectance times one constant, over the frame and across captures."""
    truth = _reflectance()
    shots = [(1.0, 0.0018, 100), (0.7, 0.0026, 100), (1.4, 0.0012, 200)]  # irradiance, exposure, ISO
    infos = [_sequoia_band(tmp_path / f"IMG_{k}_NIR.TIF", truth, *s, seed=k) for k, s in enumerate(shots)]
    factors = check_bands(infos, "irradiance")
    for info, (irr, exposure, iso) in zip(infos, shots):
        f = factors[info.path]
        assert f.dark_level == 75 and f.vignetting == "Camera:VignettingPolynomial2D"
        assert f.exposure_gain == pytest.approx(exposure * iso / 100.0)
        assert f.irradiance == pytest.approx(irr, rel=0.01)  # the calibration light's units
    scales = block_scales(infos, factors)
    values = [correct(read(i.path), i, factors[i.path], scales["NIR"]) for i in infos]
    _flat_and_steady(values, [truth] * 3)
    # the raw DN is neither flat (vignetting: 0.67 at the corners) nor steady (light, exposure): the test can fail
    raw = [read(i.path).astype(float) - 75 for i in infos]
    with pytest.raises(AssertionError):
        _flat_and_steady(raw, [truth] * 3)
    # normalised mode: flat over the frame, but each capture keeps its light (1.0, 0.7, 1.4)
    norm = check_bands(infos, "normalised")
    values = [correct(read(i.path), i, norm[i.path]) for i in infos]
    level = [np.median((v / truth)[truth > 0.1]) for v in values]
    assert level[1] / level[0] == pytest.approx(0.7, rel=0.02) and level[2] / level[0] == pytest.approx(1.4, rel=0.02)


def read(path):
    from core.prepare.bands import read_band

    return read_band(path)


def test_micasense_and_dji_vignetting_and_irradiance(tmp_path):
    """MicaSense: V = 1 + k1 r + k2 r^2 about VignettingCenter, corrected = p / V, irradiance from
    HorizontalIrradiance; DJI: corrected = p x (1 + k1 r + ...), irradiance over SensorGainAdjustment."""
    truth = _reflectance(1)
    k = (-1.0e-3, -4.0e-6)
    y, x = np.mgrid[0:H, 0:W]
    r = np.hypot(x - 82.5, y - 58.0)
    poly = 1 + k[0] * r + k[1] * r ** 2
    values, truths = [], []
    for n, (irr, exposure, iso) in enumerate([(1.1, 0.001, 100), (0.8, 0.0015, 200)]):
        attrs = {"Camera:BandName": "Red", "MicaSense:CaptureId": f"M{n}", "Camera:BlackLevel": "4800",
                 "Camera:HorizontalIrradiance": f"{irr}", "Camera:Irradiance": "9.9"}
        seqs = {"Camera:VignettingCenter": [82.5, 58.0], "Camera:VignettingPolynomial": list(k)}
        dn = _dn(truth, poly, 4800, 3.0e7, irr, exposure, iso / 100.0, 10 + n)
        info = read_band_info(write_band(tmp_path / f"IMG_000{n}_3.tif", xmp(attrs, seqs), _exif(exposure, iso), dn))
        assert sun_irradiance(info) == pytest.approx(irr)  # the horizontal irradiance before the sensor's own
        f = band_factors(info, "irradiance")
        values.append(correct(read(info.path), info, f))
        truths.append(truth)
    _flat_and_steady(values, truths)
    # DJI: the polynomial multiplies: the falloff is its inverse
    attrs = {"Camera:BandName": "NIR", "drone-dji:CaptureUUID": "d1", "drone-dji:BlackLevel": "4096",
             "drone-dji:CalibratedOpticalCenterX": "82.5", "drone-dji:CalibratedOpticalCenterY": "58.0",
             "drone-dji:VignettingData": "0.001, 4e-06", "drone-dji:Irradiance": "2000",
             "drone-dji:SensorGainAdjustment": "1.25", "drone-dji:SensorGain": "2", "drone-dji:ExposureTime": "1000"}
    dji = read_band_info(write_band(tmp_path / "DJI_0015.TIF", xmp(attrs), {}, np.full((H, W), 5000, np.uint16)))
    falloff = vignetting_falloff(dji, (H, W))
    assert falloff[58, 82] == pytest.approx(1.0, abs=1e-3)
    assert falloff[0, 0] == pytest.approx(1.0 / (1 + 0.001 * np.hypot(82.5, 58) + 4e-6 * (82.5 ** 2 + 58 ** 2)))
    f = band_factors(dji, "irradiance")
    assert f.exposure_gain == pytest.approx(0.001 * 2) and f.irradiance == pytest.approx(2000 / 1.25)


def test_a_band_without_what_the_radiometry_needs_is_named_before_work(tmp_path):
    truth = _reflectance(2)
    good = _sequoia_band(tmp_path / "IMG_1_NIR.TIF", truth, 1.0, 0.0018, 100, seed=1)
    dark = _sequoia_band(tmp_path / "IMG_2_NIR.TIF", truth, 1.0, 0.0018, 100, seed=2, sun=False)
    no_exposure = read_band_info(write_band(tmp_path / "IMG_3_NIR.TIF", xmp({"Camera:BandName": "NIR"}), {}))
    with pytest.raises(BandRadiometryError, match=r"IMG_2_NIR\.TIF: no usable sun-sensor irradiance.*normalised"):
        check_bands([good, dark], "irradiance")
    assert set(check_bands([good, dark], "normalised")) == {good.path, dark.path}  # what can still be built
    with pytest.raises(BandRadiometryError, match=r"IMG_3_NIR\.TIF: no exposure time.*raw DN"):
        check_bands([good, no_exposure], "normalised")
    assert check_bands([no_exposure], "raw") == {}


def test_a_panel_reflectance_row_that_is_not_a_number_is_named_with_its_line(tmp_path):
    """Issue 47 item 16: a panel sheet's row 'Red,abc' was skipped as if it were a header (then the band had no
    reflectance, or the sheet's other rows were used silently); it is named: file, line, value."""
    from core.prepare.band_radiometry import parse_panel_reflectance

    sheet = tmp_path / "panel.csv"
    sheet.write_text("# RP04\nband,reflectance\nGreen,0.49\nRed,abc\nRed edge,0.50\nNIR,0.49\n")
    with pytest.raises(BandRadiometryError, match=r"panel\.csv:4: .*Red, 'abc', is not a number"):
        parse_panel_reflectance(str(sheet))
    sheet.write_text("Green,0.49\nRed\nNIR,0.49\n")  # a row without its value
    with pytest.raises(BandRadiometryError, match=r"panel\.csv:2: 'Red'.* no reflectance"):
        parse_panel_reflectance(str(sheet))
    sheet.write_text("band,reflectance\nGreen,0.49\nRed,0.5\n")  # the header row is still skipped
    assert parse_panel_reflectance(str(sheet)).for_band("Red", None) == 0.5
