"""One projection rule (issue 35 item 2): guided placement, the automatic control and Find targets judge 'this
point is seen in that photo' by geometry.camera.project_in_image, the lens model trusted within its radius."""
import numpy as np
import pytest


def _block(params, model="OPENCV", w=1200, h=900):
    pycolmap = pytest.importorskip("pycolmap")
    rec = pycolmap.Reconstruction()
    cam = pycolmap.Camera.create_from_model_name(1, model, 1000.0, w, h)
    cam.params = np.asarray(params, dtype=float)
    rec.add_camera_with_trivial_rig(cam)
    im = pycolmap.Image(name="a.jpg", camera_id=1, image_id=1)
    rec.add_image_with_trivial_frame(im, pycolmap.Rigid3d())  # looking down +z from the origin
    return rec, rec.image(1)


def test_guided_and_autocontrol_agree_and_reject_the_wrap_around():
    from core.geometry.camera import intrinsics_of, project_in_image
    from core.georef.autocontrol.provisional import project
    from core.georef.guided import project_point

    # a strong barrel distortion (k1 -0.35): the polynomial turns back beyond the frame, so ground far outside the
    # picture would land inside it
    rec, im = _block([1000.0, 1000.0, 600.0, 450.0, -0.35, 0.0, 0.0, 0.0])
    cam = intrinsics_of(rec.cameras[1])
    assert cam is intrinsics_of(rec.cameras[1])  # one object per camera: r_limit computed once
    rs = np.linspace(0.0, 3.0, 301)
    xyz = np.column_stack([rs, 0.2 * rs, np.ones_like(rs)])  # rays from the centre outwards
    px, seen, centrality = project_in_image(rec.cameras[1], im.cam_from_world().matrix(), xyz)
    raw = np.asarray(rec.cameras[1].img_from_cam(xyz), dtype=float)
    inside_raw = (raw[:, 0] >= 0) & (raw[:, 0] <= 1200) & (raw[:, 1] >= 0) & (raw[:, 1] <= 900)
    wrapped = inside_raw & (rs > cam.r_limit)
    assert wrapped.any()  # the raw model maps far-away rays into the picture ...
    assert not seen[wrapped].any()  # ... which the rule rejects
    assert seen[rs < 0.5].all() and np.all(np.diff(np.flatnonzero(seen)) == 1)  # seen: one run from the centre
    assert centrality[0] == pytest.approx(0.0, abs=1e-9)
    px2, seen2, _ = project(rec, im, xyz)
    assert np.array_equal(seen, seen2)
    for k in range(len(rs)):
        got = project_point(rec, xyz[k], margin=0.0)
        assert ("a.jpg" in got) == bool(seen[k]), rs[k]
        if seen[k]:
            assert got["a.jpg"][:2] == pytest.approx(tuple(px[k]), abs=1e-9)


def test_a_model_only_pycolmap_knows_is_trusted_where_it_round_trips():
    from core.geometry.camera import project_in_image

    # FOV (a model the numpy formulas do not carry): projected through pycolmap, trusted where it round-trips
    rec, im = _block([1000.0, 1000.0, 600.0, 450.0, 0.9], model="FOV")
    xyz = np.array([[0.0, 0.0, 1.0], [0.3, 0.2, 1.0], [0.0, 0.0, -1.0]])
    px, seen, _ = project_in_image(rec.cameras[1], im.cam_from_world().matrix(), xyz)
    assert seen.tolist() == [True, True, False]  # behind the camera: not seen
    assert px[0] == pytest.approx([600.0, 450.0])
