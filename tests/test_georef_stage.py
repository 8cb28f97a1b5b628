"""The georeference stage on a real aligned workspace (sample Toledo strip, EXIF GPS) and its bad inputs."""
import os

import numpy as np
import pytest

from core.align.options import AlignOptions
from core.align.stage import align
from core.georef import stage as georef_stage
from core.georef.options import GeorefOptions
from core.io.gcp import GCPSet, GroundPoint, Observation
from core.project.stages import StageError
from core.project.workspace import Workspace
from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def aligned(tmp_path_factory):
    d = tmp_path_factory.mktemp("georef")
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP, str(d / "img"))
    ws = str(d / "ws")
    align(images, ws, AlignOptions(max_image_size=800, max_features=2048))
    return ws


def _reference_positions():
    ref = {}
    with open(os.path.join(SAMPLE, "cameras_32617.txt")) as f:
        for line in f:
            parts = line.split()
            if len(parts) == 3:
                ref[parts[2]] = np.array([float(parts[0]), float(parts[1])])
    return ref


def test_exif_gps_georeferencing_lines_up_with_surveyed_positions(aligned):
    result = georef_stage.georeference_workspace(aligned, GeorefOptions(use_exif_gps=True, crs="EPSG:32617"))
    assert result.crs == "EPSG:32617"
    assert result.figures["CAMERA_RMSE_XYZ"] is not None and result.figures["CAMERA_RMSE_XYZ"] < 5.0
    from osgeo import ogr

    ref = _reference_positions()
    ds = ogr.Open(result.cameras_path)
    lyr = ds.GetLayer(0)
    assert lyr.GetSpatialRef().GetAuthorityCode(None) == "32617"
    dists = []
    for feat in lyr:
        g = feat.GetGeometryRef()
        dists.append(np.hypot(*(np.array([g.GetX(), g.GetY()]) - ref[feat.GetField("image")])))
    assert len(dists) == len(TOLEDO_STRIP)
    assert max(dists) < 5.0  # consumer GPS: a few metres
    ws = Workspace.open(aligned)
    assert ws.stage("georeference")["status"] == "done"
    assert ws.crs == "EPSG:32617"
    assert os.path.isfile(os.path.join(aligned, "georef", "transform.json"))
    rec, transform = georef_stage.load_georef_model(aligned)
    assert rec.num_reg_images() == len(TOLEDO_STRIP)
    # the adjusted model stays near the origin: world = local + offset
    centres = np.array([im.projection_center() for im in rec.images.values()])
    assert np.abs(centres).max() < 1000
    assert transform.offset[0] > 200000


def test_camera_positions_file_gives_the_crs(aligned, tmp_path):
    """Camera positions alone (no GCPs, no CRS parameter, EXIF GPS not used): the file's CRS line is the target,
    here Web Mercator so that it differs from the UTM zone the photos' GPS would suggest."""
    import shutil

    from core.geometry.crs import transform_points

    ws_dir = str(tmp_path / "ws")
    shutil.copytree(aligned, ws_dir)
    ws = Workspace.open(ws_dir)
    ws.crs = None
    ws.save()
    ref = _reference_positions()
    names = sorted(set(ref) & set(TOLEDO_STRIP))
    utm = np.array([[ref[n][0], ref[n][1], 0.0] for n in names])
    merc = transform_points(utm, "EPSG:32617", "EPSG:3857")
    csv = tmp_path / "positions.csv"
    csv.write_text("EPSG:3857\n" + "".join(f"{n},{x:.3f},{y:.3f},{z}\n" for n, (x, y, _), z in
                                            zip(names, merc, [250.0] * len(names))))
    result = georef_stage.georeference_workspace(ws_dir, GeorefOptions(camera_positions_path=str(csv)))
    assert result.crs == "EPSG:3857"
    assert result.figures["CAMERA_RMSE_XY"] is not None and result.figures["CAMERA_RMSE_XY"] < 5.0



def test_the_stage_saves_its_adjustment_inputs_and_the_covariance_reads_them(aligned, tmp_path):
    """georef/adjustment_inputs.json holds the camera positions with their sigmas and the target CRS; the
    covariance's priors come from it, not from the user's file (deleted here)."""
    import json
    import shutil

    from core.georef import uncertainty

    ws_dir = str(tmp_path / "ws")
    shutil.copytree(aligned, ws_dir)
    ref = _reference_positions()
    names = sorted(set(ref) & set(TOLEDO_STRIP))
    csv = tmp_path / "positions.csv"
    csv.write_text("EPSG:32617\n" + "".join(f"{n} {ref[n][0]:.3f} {ref[n][1]:.3f} 250.0 2.5 7.5\n" for n in names))
    georef_stage.georeference_workspace(ws_dir, GeorefOptions(camera_positions_path=str(csv)))
    with open(os.path.join(ws_dir, "georef", "adjustment_inputs.json"), encoding="utf-8") as f:
        inputs = json.load(f)
    assert inputs["crs"] == "EPSG:32617"
    assert inputs["camera_positions_source"] == "file"
    assert {c["image"] for c in inputs["camera_positions"]} == set(names)
    assert all((c["sigma_xy"], c["sigma_z"]) == (2.5, 7.5) for c in inputs["camera_positions"])
    os.remove(csv)
    rec, _ = georef_stage.load_georef_model(ws_dir)
    _, priors, _, _ = uncertainty.workspace_inputs(Workspace.open(ws_dir), rec)
    assert priors and all(np.allclose(p.sigma, [2.5, 2.5, 7.5]) for p in priors)

def test_too_few_control_points_is_a_clear_error(aligned):
    gcps = GCPSet(crs="EPSG:32617", points=[
        GroundPoint("A", 274900.0, 4603270.0, 180.0, observations=[Observation("1JI_0064.JPG", 500, 400),
                                                                  Observation("1JI_0065.JPG", 500, 300)]),
        GroundPoint("B", 274905.0, 4603290.0, 180.0, observations=[Observation("1JI_0066.JPG", 600, 400),
                                                                  Observation("1JI_0067.JPG", 600, 300)]),
    ])
    with pytest.raises(StageError, match="at least 3 control points.*found 2"):
        georef_stage.georeference_workspace(aligned, GeorefOptions(gcps=gcps))


def test_unaligned_workspace_is_refused(tmp_path):
    Workspace.create_or_open(str(tmp_path / "ws"))
    with pytest.raises(StageError, match="run 'Align images' first"):
        georef_stage.georeference_workspace(str(tmp_path / "ws"), GeorefOptions(use_exif_gps=True))
