"""The rig calibrated once for the block (issue 37 item 1, core/prepare/bands.py calibrate_rig): tests/rig_scene.py's
rig block rendered with its true rig rotations, its band files telling RigRelatives off by 0.3 - 0.4 degrees (2 - 4
px over the frame), stacked by core/prepare/captures.py stack_captures:

- the block's calibration recovers each band's true rig rotation (measured: within 0.01 degrees);
- a capture over uniform ground (every band flattened to its median plus noise) cannot be refined (its windows'
  peaks are noise and their shifts random: a fit to them lands 9 - 17 px off): it takes the block's correction
  and lands within 0.3 px of the truth (measured 0.02 - 0.04 px), where the model alone leaves 2 - 3 px;
- a capture whose NIR band is moved by 4 px (a fit that locks on a wrong period of repetitive texture) disagrees
  with the block beyond its tolerance: it takes the block's correction, and the warning names it."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from osgeo import gdal

from core.geometry.lens import band_to_reference, rig_rotation
from core.io.multispectral import band_files, read_block
from core.prepare.bands import BLOCK, MODEL, REFINED, band_map, register_capture
from core.prepare.captures import CaptureStackOptions, stack_captures
from tests import rig_scene as rs

gdal.UseExceptions()

TOLD = {"Red": (0.35 + 0.3, -0.2, 0.1), "Red edge": (-0.3, 0.25 - 0.35, -0.15), "NIR": (0.2, 0.4, 0.05 + 0.4)}
UNIFORM, MOVED = 3, 5   # the capture over uniform ground, the capture whose NIR is moved
MOVE_PX = 4


def _flatten(path: str, seed: int) -> None:
    ds = gdal.Open(path, gdal.GA_Update)
    a = ds.GetRasterBand(1).ReadAsArray().astype(np.float64)
    flat = np.median(a) + np.random.default_rng(seed).normal(0.0, 3.0, a.shape)
    ds.GetRasterBand(1).WriteArray(np.clip(np.round(flat), 0, 65535).astype(np.uint16))
    ds = None


def _move(path: str, px: int) -> None:
    ds = gdal.Open(path, gdal.GA_Update)
    ds.GetRasterBand(1).WriteArray(np.roll(ds.GetRasterBand(1).ReadAsArray(), px, axis=1))
    ds = None


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """(captures, the stack's result) of 8 captures whose files tell the TOLD relatives, one over uniform ground and
    one with its NIR moved."""
    root = tmp_path_factory.mktemp("rigcal")
    rig = rs.rig_block(n_strips=2, per_strip=4)
    original = rs._xmp

    def told_xmp(rig_, band, *args):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(rs, "RELATIVES", TOLD)
            return original(rig_, band, *args)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(rs, "_xmp", told_xmp)
        rs.render(rig, str(root / "bands"), supersample=1)
    captures = read_block(band_files(str(root / "bands"))).captures
    for i, b in enumerate(captures[UNIFORM].bands):
        _flatten(b.path, 100 + i)
    _move(captures[MOVED].band("NIR").path, MOVE_PX)
    result = stack_captures(band_files(str(root / "bands")), CaptureStackOptions(str(root / "photos")))
    return captures, result


def _error_px(reg, band: str) -> float:
    """The largest distance (band px, frame's central 0.9) between where the registration samples ``band`` and where
    the true rig rotation puts it."""
    r = next(r for r in reg.results if r.camera.name == band)
    shape = reg.bands.shape[1:]
    truth = dataclasses.replace(r.camera, rotation=band_to_reference(rs.RELATIVES[band]))
    used, true = band_map(r.camera, reg.frame, shape, r.correction), band_map(truth, reg.frame, shape)
    h, w = shape
    e = np.hypot(used[0] - true[0], used[1] - true[1])[h // 20:-h // 20, w // 20:-w // 20]
    return float(e.max())


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(a.T @ b) - 1.0) / 2.0))))


def test_the_block_calibration_recovers_the_true_rig_rotations(block):
    _captures, result = block
    rig = result.rig
    assert rig is not None and rig.reference == "Green" and not rig.missing
    for band in TOLD:
        cal = rig.band(band)
        truth = rig_rotation(rs.RELATIVES[band])
        assert _angle_deg(truth, rig_rotation(cal.relatives)) > 0.29                       # the metadata's
        assert _angle_deg(truth, rig_rotation(cal.relatives_calibrated)) < 0.03, str(cal)   # the block's
        assert cal.captures >= 6 and cal.spread_px < 0.1 and cal.shift_px > 2.0, str(cal)
    assert "rig calibration of the block" in rig.describe()


def test_a_capture_over_uniform_ground_takes_the_block_s_correction(block):
    captures, result = block
    cap = captures[UNIFORM]
    assert set(result.registration[cap.capture_id].values()) == {BLOCK}
    assert any(w.startswith(f"capture {cap.capture_id}:") and "too little texture" in w for w in result.warnings)
    ds = gdal.Open(next(p for p in result.photos if p.endswith(f"IMG_{UNIFORM:04d}.tif")))
    assert "NIR: block" in ds.GetMetadataItem("REGISTRATION")
    nir = next(i + 1 for i in range(ds.RasterCount) if ds.GetRasterBand(i + 1).GetDescription() == "NIR")
    assert ds.GetRasterBand(nir).GetMetadataItem("REGISTRATION") == BLOCK
    ds = None
    alone = register_capture(cap)                                 # no block: the model only, not a fit to noise
    calibrated = register_capture(cap, calibration=result.rig)
    for band in TOLD:
        assert dict(alone.registration)[band] == MODEL and _error_px(alone, band) > 2.0
        assert _error_px(calibrated, band) < 0.3, band
    # the others refined by their own windows, as exact
    other = register_capture(captures[0], calibration=result.rig)
    assert set(other.registration.values()) == {REFINED}
    assert max(_error_px(other, b) for b in TOLD) < 0.3


def test_a_capture_disagreeing_with_the_block_takes_its_correction_and_is_named(block):
    captures, result = block
    cid = captures[MOVED].capture_id
    assert result.registration[cid] == {"Red": REFINED, "Red edge": REFINED, "NIR": BLOCK}
    assert any(w.startswith(f"capture {cid}: NIR block") and "repetitive texture" in w for w in result.warnings)
    assert cid in result.rig.band("NIR").outliers
    others = {c for c, how in result.registration.items() if set(how.values()) != {REFINED}}
    assert others == {cid, captures[UNIFORM].capture_id}
    assert set(result.worst_residual_px) == set(TOLD) and max(result.worst_residual_px.values()) < 0.3
