"""Degenerate cameras out of the block (core.align.mapping.drop_degenerate).

Found on the synthetic orbit with one camera per image: the mapper registered a 65 deg view self-calibrated from
ten points with a focal length of 1.7e8 px; the final bundle adjustment then diverged on it (focal -8e7 px, the
block's mean reprojection error 4e151 px) and the stage reported it as registered.  Such an image is now
de-registered, with its observations, and reported as unregistered with the reason.
"""
import math

import pytest

from core.align.diagnosis import diagnose_unregistered
from core.align.mapping import MAX_FOCAL_RATIO, degenerate_camera, drop_degenerate
from core.io.images import ImageInfo

pycolmap = pytest.importorskip("pycolmap")


def _block(focals, width=480, height=360):
    """A reconstruction with one registered image per focal length (one camera each) and a point seen by all."""
    rec = pycolmap.Reconstruction()
    for k, f in enumerate(focals, start=1):
        cam = pycolmap.Camera.create_from_model_name(k, "SIMPLE_RADIAL", 1.0, width, height)
        cam.params = [f, width / 2.0, height / 2.0, 0.0]
        rec.add_camera_with_trivial_rig(cam)
        im = pycolmap.Image(name=f"im{k}.jpg", camera_id=k, image_id=k,
                            points2D=[pycolmap.Point2D([width / 2.0, height / 2.0])])
        rec.add_image_with_trivial_frame(im, pycolmap.Rigid3d(pycolmap.Rotation3d(), [0.1 * k, 0.0, 5.0]))
    track = pycolmap.Track()
    for k in range(1, len(focals) + 1):
        track.add_element(k, 0)
    rec.add_point3D([0.0, 0.0, 0.0], track)
    return rec


def test_degenerate_camera_judges_the_focal_not_the_distortion():
    ok = pycolmap.Camera.create_from_model_name(1, "SIMPLE_RADIAL", 576.0, 480, 360)
    assert degenerate_camera(ok) == ""
    wide = pycolmap.Camera.create_from_model_name(2, "OPENCV", 300.0, 480, 360)
    wide.params = [300.0, 300.0, 240.0, 180.0, 1.8, -0.9, 0.0, 0.0]  # a large distortion is not judged
    assert degenerate_camera(wide) == ""
    for f in (1.67e8, -8.07e7, 480 * MAX_FOCAL_RATIO * 1.01, 10.0):
        cam = pycolmap.Camera.create_from_model_name(3, "SIMPLE_RADIAL", 1.0, 480, 360)
        cam.params = [f, 240.0, 180.0, 0.0]
        why = degenerate_camera(cam)
        assert "degenerate camera" in why and "480 x 360" in why, (f, why)
    nan = pycolmap.Camera.create_from_model_name(4, "SIMPLE_RADIAL", 576.0, 480, 360)
    nan.params = [576.0, 240.0, 180.0, math.nan]
    assert "non-finite camera parameters" in degenerate_camera(nan)


def test_drop_degenerate_deregisters_the_image_and_its_observations():
    rec = _block([576.0, 1.67e8, 580.0])
    assert rec.num_reg_images() == 3 and rec.points3D[next(iter(rec.points3D))].track.length() == 3
    dropped = drop_degenerate(rec)
    assert list(dropped) == ["im2.jpg"] and "1.67e+08" in dropped["im2.jpg"]
    assert sorted(rec.images[i].name for i in rec.reg_image_ids()) == ["im1.jpg", "im3.jpg"]
    assert all(p.track.length() == 2 for p in rec.points3D.values())  # its observation went with it
    assert drop_degenerate(rec) == {}  # nothing left to drop


def test_a_dropped_image_is_reported_with_the_reason():
    infos = [ImageInfo(name=n, path=n, width=480, height=360, bands=3, dtype="Byte") for n in ("a.jpg", "b.jpg", "c.jpg")]
    why = diagnose_unregistered(infos, {"a.jpg"}, [], {"a.jpg": 2, "b.jpg": 5, "c.jpg": 0},
                                {"b.jpg": "could not be registered: the mapper gave it a degenerate camera (...)"})
    assert why["b.jpg"].startswith("matched 5 image(s) but could not be registered: the mapper gave it a degenerate")
    assert why["c.jpg"].startswith("no verified matches")
