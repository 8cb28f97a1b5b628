"""A rig's RGB camera and its bands aligned as one block (issue 37 item 1): tests/rig_scene.py's 10 captures, each
with the rig's RGB frame (1.5 x the bands' size, another lens, fired 0.3 m further along the track and turned by
under a degree: its own pose), through Run pipeline on the band folder:

- the captures are stacked, the RGB frames put beside them, and all 20 photos aligned in one block: the stacks
  matched on their band nearest green (PRIMARY_BAND, from 8-bit images of it: sfm/feature_images);
- one DSM; two orthomosaics, the captures' multi-band one (orthomosaic.tif, the bands named) and the RGB frames'
  (orthomosaic_rgb.tif);
- both mosaics where the truth puts the scene: the median shift of their green against the true green
  reflectance (phase correlation on gradients, windows over open ground) within half a band cell, the two within
  a third of a band cell of each other; the bands on Green within 0.3 px.
The bands at 320 x 240 px (18 cm cells; the windows 32 cells, the ground of 64 of 9 cm at 640 px), 1024 features a
photo and 4 spatial neighbours, a quarter-quality DSM, the mosaics without their radiometry and seam moves (the
test is where they put the scene).  Measured: 20/20 registered; shifts (0.4, 5.4) and (2.0, 5.1) cm, 0.30 band
cell each, 0.09 cell apart (161 and 338 windows); bands on Green p90 <= 0.057 px; 18 cm band cells, 13 cm RGB cells
(at 640 px: shifts (0.0, 5.4) and (0.0, 5.3) mm, 0.06 of a 9 cm cell)."""
from __future__ import annotations

import math
import os

import pytest

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def rgb_run(tmp_path_factory):
    from core import pipeline
    from core.align.options import AlignOptions
    from core.dense.options import DenseOptions
    from core.ortho.options import OrthoOptions
    from tests import rig_scene as rs

    root = tmp_path_factory.mktemp("rigrgb")
    rig = rs.rig_block(n_strips=2, per_strip=5, width=320, height=240)
    rs.render(rig, str(root / "bands"), supersample=1, rgb=True)
    result = pipeline.run_pipeline(str(root / "bands"), str(root / "ws"), pipeline.PipelineOptions(
        align=AlignOptions(num_threads=2, max_features=1024, spatial_neighbours=4),
        dense=DenseOptions(quality="quarter"),
        ortho=OrthoOptions(radiometry=False, seam_iterations=0, avoid_shadow=False),
        make_report=False, make_dtm=False, capture_radiometry="irradiance"),
        pipeline.Control(camera_positions_path=str(root / "camera_positions.csv")))
    return rig, result


def test_the_rgb_frames_and_the_captures_align_as_one_block(rgb_run):
    from core.align.features import FEATURE_IMAGES
    from core.io.images import primary_band

    rig, result = rgb_run
    n = len(rig.block.shots)
    assert len(result.captures.photos) == n and len(result.rgb_frames) == n
    assert all(f.endswith("_RGB.TIF") for f in result.rgb_frames)
    assert result.align.registered == 2 * n
    for photo in result.captures.photos:  # Green (550 nm) is the band nearest an RGB photo's grey
        assert primary_band(photo) == 3
    proxies = os.listdir(os.path.join(result.workspace, "sfm", FEATURE_IMAGES))
    assert sorted(proxies) == sorted(os.path.basename(p) for p in result.captures.photos)


def test_two_orthomosaics_on_one_dsm_where_the_truth_is(rgb_run):
    from core.io.raster import RasterFile
    from tests import rig_scene as rs

    rig, result = rgb_run
    assert result.ortho_rgb.orthomosaic == os.path.join(result.workspace, "orthomosaic_rgb.tif")
    assert sorted(result.ortho_rgb.images) == sorted(result.rgb_frames)
    assert len(result.ortho.images) == len(result.captures.photos)
    with RasterFile(result.ortho.orthomosaic) as r:
        assert [r.band(i + 1).GetDescription() for i in range(4)] == ["NIR", "Red", "Green", "Red edge"]
    with RasterFile(result.ortho_rgb.orthomosaic) as r:
        assert r.count in (3, 4) and r.band(1).DataType == 1  # 8-bit colour (+ alpha)
    bands = rs.shift_to_truth(rig, result.ortho.orthomosaic, 3, window=32)
    rgb = rs.shift_to_truth(rig, result.ortho_rgb.orthomosaic, 2, window=32)
    cell = bands["cell"]
    assert bands["windows"] > 50 and rgb["windows"] > 50
    assert math.hypot(*bands["shift_m"]) < 0.5 * cell and math.hypot(*rgb["shift_m"]) < 0.5 * cell
    apart = math.hypot(bands["shift_m"][0] - rgb["shift_m"][0], bands["shift_m"][1] - rgb["shift_m"][1])
    assert apart < cell / 3
    reg = rs.evaluate(rig, result.ortho.orthomosaic, window=32)["registration_px"]
    assert all(v["p90"] is not None and v["p90"] <= 0.3 for v in reg.values())


def test_the_other_kind_is_excluded_by_names_taken_literally():
    """The orthomosaic of one kind leaves the other kind's photos out by name, whatever characters they hold."""
    from core import pipeline
    from core.ortho.cameras import select_cameras

    class Cam:
        def __init__(self, name):
            self.name, self.camera_id = name, 1

    cams = [Cam(n) for n in ("IMG_1.tif", "IMG_2.tif", "IMG_?.tif", "IMG[1]_RGB.TIF", "IMG_1_RGB.TIF")]
    chosen = select_cameras(cams, pipeline._excluding(["IMG[1]_RGB.TIF", "IMG_1_RGB.TIF"]))
    assert [c.name for c in chosen] == ["IMG_1.tif", "IMG_2.tif", "IMG_?.tif"]
    chosen = select_cameras(cams, pipeline._excluding(["IMG_?.tif", "IMG_1.tif", "IMG_2.tif"]))
    assert [c.name for c in chosen] == ["IMG[1]_RGB.TIF", "IMG_1_RGB.TIF"]


def test_only_the_stacked_captures_rgb_frames_are_aligned(tmp_path):
    """A capture left out (a band missing: a calibration panel's shot, a misfire) brings no RGB frame into the
    block; its frame is named in a warning; a frame named like a stacked photo is refused before the alignment."""
    from core import pipeline
    from core.prepare.captures import CaptureStackOptions, stack_capture_folder
    from core.project.stages import StageError
    from tests import rig_scene as rs

    rig = rs.rig_block(n_strips=1, per_strip=3)
    bands = tmp_path / "bands"
    rs.render(rig, str(bands), supersample=1, rgb=True)
    os.unlink(bands / "IMG_0002_NIR.TIF")
    stack = stack_capture_folder(str(bands), CaptureStackOptions(str(tmp_path / "out")))
    assert len(stack.photos) == 2
    frames, others = pipeline.rig_rgb_frames(str(bands), stack.photos)
    assert [os.path.basename(p) for p in frames] == ["IMG_0000_RGB.TIF", "IMG_0001_RGB.TIF"]
    assert [os.path.basename(p) for p in others] == ["IMG_0002_RGB.TIF"]

    class Log:
        warnings = []

        def warning(self, m):
            self.warnings.append(m)

    log = Log()
    placed = pipeline._frames_beside(str(bands), str(tmp_path / "out"), stack.photos, log)
    assert placed == ["IMG_0000_RGB.TIF", "IMG_0001_RGB.TIF"] and "IMG_0002_RGB.TIF" in log.warnings[0]
    assert os.path.samefile(tmp_path / "out" / "IMG_0000_RGB.TIF", bands / "IMG_0000_RGB.TIF")
    os.rename(bands / "IMG_0001_RGB.TIF", bands / "IMG_0001.tif")  # the stacked photo's name
    with pytest.raises(StageError, match="has the name of the stacked photo"):
        pipeline._frames_beside(str(bands), str(tmp_path / "out"), stack.photos, log)
