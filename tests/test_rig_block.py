"""A synthetic multispectral rig block through the whole chain (issue 37, tests/rig_scene.py): 10 captures of four
fisheye bands (Sequoia form, rig rotations, per-band vignetting, light changing by +-30 % between captures, the
exposure following it, the red edge at ISO 200 on every other capture) -> Stack multispectral captures
(irradiance radiometry; Run pipeline does it on the band folder) -> the chain -> Spectral index (NDVI), against the
scene's truth:

- every capture registered; the mosaic keeps the four bands, named;
- band-to-band registration in the mosaic (phase correlation on gradients, NIR / Red / Red edge on Green): median
  and 90th percentile within 0.3 px;
- reflectance: the mosaic over the true reflectance is one constant per band (what a calibration panel fixes)
  within 2 % over 1.4 m patches (12 x 12 cells; 95th percentile) -- light, exposure, gain and vignetting taken out;
- the ring ditch's crop mark in the NDVI raster: the truth's contrast within 15 %.
The bands at 480 x 360 px (12 cm cells; the registration and patch windows of the same ground as 64 and 16 cells
of 9 cm at 640 px), 1024 features a photo and 6 spatial neighbours, the seams not moved, no DTM.  Measured (10
captures): every band stacked within 0.24 px, 10/10 registered; registration medians 0.02 px, p90 <= 0.045 px (95
windows); patch deviation 0.7-1.6 %; ring contrast 0.0698 against the truth's 0.0709 (at 640 px: 0.16 px stacked, p90 <=
0.028 px, 0.75-1.66 %, 0.0701); benchmarks/rig_block.py prints the figures for 40 captures."""
from __future__ import annotations

import os

import numpy as np
import pytest

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def rig_run(tmp_path_factory):
    from core import pipeline
    from core.align.options import AlignOptions
    from core.ortho.options import OrthoOptions
    from tests import rig_scene as rs

    root = tmp_path_factory.mktemp("rig")
    rig = rs.rig_block(n_strips=2, per_strip=5, width=480, height=360)
    bands = str(root / "bands")
    rs.render(rig, bands, supersample=1)
    # the band folder itself: Run pipeline stacks its captures first (PipelineOptions.captures "auto")
    result = pipeline.run_pipeline(bands, str(root / "ws"), pipeline.PipelineOptions(
        align=AlignOptions(num_threads=2, max_features=1024, spatial_neighbours=6),
        ortho=OrthoOptions(seam_iterations=0, avoid_shadow=False), make_report=False, make_dtm=False,
        capture_radiometry="irradiance"),
        pipeline.Control(camera_positions_path=str(root / "camera_positions.csv")))
    return rig, result.captures, result, root


def test_the_rig_block_is_stacked_aligned_and_mosaicked_with_every_band(rig_run):
    from core.io.raster import RasterFile

    rig, stack, result, _root = rig_run
    assert len(stack.photos) == len(rig.block.shots) and stack.left_out == {}
    assert all(os.path.dirname(p) == os.path.join(result.workspace, "captures") for p in stack.photos)
    assert "captures" in result.cpu_seconds
    assert stack.bands == ("NIR", "Red", "Green", "Red edge") and max(stack.worst_residual_px.values()) < 0.3
    assert result.align.registered == len(rig.block.shots)
    with RasterFile(result.ortho.orthomosaic) as r:
        names = [r.band(i + 1).GetDescription() for i in range(r.count)]
    assert names[:4] == ["NIR", "Red", "Green", "Red edge"]


def test_bands_registered_and_reflectance_steady_in_the_mosaic(rig_run):
    from tests import rig_scene as rs

    rig, _stack, result, _root = rig_run
    ev = rs.evaluate(rig, result.ortho.orthomosaic, window=48)  # 5.8 m windows, 1.4 m patches
    for band, reg in ev["registration_px"].items():
        assert reg["windows"] >= 20, (band, reg)
        assert reg["median"] <= 0.3 and reg["p90"] <= 0.3, (band, reg)
    for band, refl in ev["reflectance"].items():
        assert refl["patches"] >= 100 and refl["patch_p95_dev"] <= 0.02, (band, refl)


def test_the_crop_mark_shows_in_ndvi_as_in_the_truth(rig_run):
    from core.io.raster import RasterFile
    from core.spectral.index import spectral_index
    from core.spectral.options import IndexOptions
    from tests import synthetic as syn

    rig, _stack, result, root = rig_run
    out = spectral_index(IndexOptions(input=result.ortho.orthomosaic, output=str(root / "ndvi.tif")))
    assert out.bands == {"NIR": 1, "RED": 2}
    with RasterFile(out.path) as r:
        ndvi, gt, nodata = r.read(1).astype(float), r.geotransform, r.nodata(1)
    rows, cols = ndvi.shape
    jj, ii = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    x, y = gt[0] + jj * gt[1], gt[3] + ii * gt[5]
    lx, ly = x - syn.ORIGIN[0], y - syn.ORIGIN[1]
    ok = (ndvi != nodata) & np.isfinite(ndvi) & ~rig.block.scene.near_feature(lx, ly, 1.5)
    cx, cy, radius = rig.ring
    dist = np.abs(np.hypot(lx - cx, ly - cy) - radius)
    on, beside = ok & (rig.mark(lx, ly) > 0.8), ok & (dist > 2.0) & (dist < 4.0)
    assert on.sum() > 500 and beside.sum() > 500
    truth = rig.ndvi(x, y)
    measured = ndvi[on].mean() - ndvi[beside].mean()
    expected = truth[on].mean() - truth[beside].mean()
    assert expected > 0.05 and measured == pytest.approx(expected, rel=0.15)


def test_only_a_band_folder_is_stacked(tmp_path):
    """Run pipeline stacks a folder of a rig's band files, never a folder of photos: the Sequoia capture's folder
    (its band TIFFs first) is one; Toledo's JPEGs, the capture's RGB frame alone and a folder of one band's files
    (a block of NIR photos) are not."""
    import shutil

    from core.prepare.captures import is_band_folder
    from tests.conftest import SAMPLE, shared

    assert is_band_folder(shared("sequoia_sample"))
    assert not is_band_folder(os.path.join(SAMPLE, "images"))
    rgb = tmp_path / "rgb"
    rgb.mkdir()
    shutil.copy(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_RGB.JPG"), rgb)
    assert not is_band_folder(str(rgb)) and not is_band_folder(str(tmp_path / "empty-or-missing"))
    nir = tmp_path / "nir"  # one band's files: photos, aligned as they are
    nir.mkdir()
    shutil.copy(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_NIR.TIF"), nir)
    shutil.copy(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_NIR.TIF"), nir / "IMG_2_NIR.TIF")
    assert not is_band_folder(str(nir))
