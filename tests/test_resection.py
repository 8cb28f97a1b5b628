"""core.geometry.camera and core.geometry.resection: the camera model against pycolmap and the synthetic
renderer's, omega-phi-kappa, space resection (exact, noisy, one wrong point, too few points, focal length + k1),
planar homography."""
import math

import numpy as np
import pytest

from core.geometry import camera as cm
from core.geometry import resection as rs
from tests import synthetic as syn

CAM = syn.DEFAULT_CAMERA


def _intrinsics(cam=CAM):
    return cm.Intrinsics("OPENCV", cam.width, cam.height, cam.params)


@pytest.mark.parametrize("model,params", [
    ("OPENCV", [650.0, 655.0, 403.7, 296.2, -0.08, 0.02, 0.0006, -0.0004]),
    ("FULL_OPENCV", [650.0, 655.0, 403.7, 296.2, -0.08, 0.02, 0.0006, -0.0004, 0.01, 0.02, 0.001, 0.003]),
    ("SIMPLE_RADIAL", [650.0, 400.0, 300.0, -0.05]),
    ("RADIAL", [650.0, 400.0, 300.0, -0.05, 0.01]),
    ("PINHOLE", [650.0, 640.0, 400.0, 300.0]),
])
def test_projection_matches_pycolmap(model, params):
    import pycolmap

    pc = pycolmap.Camera.create_from_model_name(1, model, 650.0, 800, 600)
    pc.params = np.array(params)
    cam = cm.Intrinsics.from_pycolmap(pc)
    rng = np.random.default_rng(0)
    xc = np.column_stack([rng.uniform(-0.55, 0.55, (200, 2)), rng.uniform(1.0, 30.0, 200)])
    xc[:, :2] *= xc[:, 2:3]
    px, ok = cam.project(xc)
    assert ok.all()
    np.testing.assert_allclose(px, np.asarray(pc.img_from_cam(xc)), atol=1e-6)
    xn = cam.unproject(px)
    np.testing.assert_allclose(xn, xc[:, :2] / xc[:, 2:3], atol=1e-9)


def test_projection_matches_the_synthetic_camera_and_rejects_fold_back():
    cam = _intrinsics()
    xc = np.column_stack([np.random.default_rng(1).uniform(-0.6, 0.6, (100, 2)), np.ones(100)])
    px, ok = cam.project(xc)
    np.testing.assert_allclose(px, CAM.image_from_camera(xc), atol=1e-9)
    # a strong barrel distortion turns back beyond the image: far-off points must not land inside it
    strong = cm.Intrinsics("OPENCV", 800, 600, (400.0, 400.0, 400.0, 300.0, -0.35, 0.0, 0.0, 0.0))
    far = np.array([[3.0, 0.0, 1.0], [0.0, 2.5, 1.0], [0.2, 0.1, 1.0], [0.0, 0.0, -1.0]])
    px, ok = strong.project(far)
    assert list(ok) == [False, False, True, False]
    assert strong.r_limit < 1 / math.sqrt(3 * 0.35)  # below the radius where r(1 + k1 r^2) turns


def test_omega_phi_kappa_convention():
    # zero angles: looking straight down, image x to the east, image y (down) to the south
    r = cm.rotation_from_opk(0, 0, 0)
    np.testing.assert_allclose(r @ [0, 0, -1], [0, 0, 1])  # down is the viewing direction
    np.testing.assert_allclose(r @ [1, 0, 0], [1, 0, 0])
    np.testing.assert_allclose(r @ [0, 1, 0], [0, -1, 0])
    # kappa 90: image x points north
    np.testing.assert_allclose(cm.rotation_from_opk(0, 0, 90) @ [0, 1, 0], [1, 0, 0], atol=1e-12)
    # omega tilts about the X (east) axis: positive omega looks towards +Y (north) in this convention
    d = cm.rotation_from_opk(10, 0, 0).T @ [0, 0, 1]  # viewing direction in the world
    assert d[1] > 0.17 and abs(d[0]) < 1e-12
    for angles in [(3.0, -2.0, 47.0), (-20.0, 15.0, -170.0), (0.5, 0.2, 179.9)]:
        np.testing.assert_allclose(cm.opk_from_rotation(cm.rotation_from_opk(*angles)), angles, atol=1e-9)
    # the matrix is the classic photogrammetric M (Wolf & Dewitt): m31 = sin(phi), m32 = -sin(omega) cos(phi)
    m = cm.opk_matrix(12.0, -7.0, 33.0)
    w, p = math.radians(12.0), math.radians(-7.0)
    assert m[2, 0] == pytest.approx(math.sin(p)) and m[2, 1] == pytest.approx(-math.sin(w) * math.cos(p))


def _scene(n, seed=0, relief=0.0, noise=0.0):
    """n ground points under a camera 50 m up, tilted a little; returns (xyz, pixels, pose)."""
    rng = np.random.default_rng(seed)
    rot = cm.rotation_from_opk(2.0, -3.0, 30.0)
    pose = cm.Pose.from_centre(rot, [3.0, -2.0, 50.0])
    cam = _intrinsics()
    xyz = []
    while len(xyz) < n:
        p = np.array([rng.uniform(-30, 30), rng.uniform(-22, 22), rng.uniform(0, relief)])
        px, ok = cm.project_points(pose, cam, p[None])
        if ok[0] and cam.inside(px[0], 20):
            xyz.append(p)
    xyz = np.array(xyz)
    px, _ = cm.project_points(pose, cam, xyz)
    return xyz, px + rng.normal(0, noise, px.shape), pose


def test_resection_exact_and_noisy():
    xyz, px, pose = _scene(6)
    r = rs.space_resection(xyz, px, _intrinsics(), estimate_intrinsics=False)
    np.testing.assert_allclose(r.pose.centre, pose.centre, atol=1e-5)
    np.testing.assert_allclose(r.pose.rotation, pose.rotation, atol=1e-7)
    assert r.rmse_px < 1e-4 and not r.outliers
    xyz, px, pose = _scene(10, seed=2, noise=0.5)
    r = rs.space_resection(xyz, px, _intrinsics(), estimate_intrinsics=False)
    assert np.linalg.norm(r.pose.centre - pose.centre) < 0.5
    assert 0.2 < r.rmse_px < 0.8
    assert len(r.residuals) == 10 and all(p.used for p in r.residuals)


def test_one_wrong_gcp_is_named_and_left_out():
    xyz, px, pose = _scene(6, seed=3, noise=0.3)
    px[2] += [18.0, -9.0]
    r = rs.space_resection(xyz, px, _intrinsics(), names=list("ABCDEF"), estimate_intrinsics=False)
    assert r.outliers == ["C"]
    assert r.residuals[2].residual > 15
    assert any("GCP C" in w for w in r.warnings)
    assert np.linalg.norm(r.pose.centre - pose.centre) < 0.5 and r.rmse_px < 1.0


def test_too_few_points_name_the_number_needed():
    xyz, px, _ = _scene(3)
    with pytest.raises(rs.ResectionError, match=r"at least 4 ground control points observed in IMG_1\.JPG.*found 3"):
        rs.space_resection(xyz, px, _intrinsics(), names=["a", "b", "c"], image="IMG_1.JPG")
    xyz, px, _ = _scene(5)
    with pytest.raises(rs.ResectionError, match="at least 6 .* found 5"):
        rs.space_resection(xyz, px, _intrinsics(), estimate_intrinsics=True)


def test_focal_length_and_k1_are_estimated_from_six_points_with_relief():
    true = cm.Intrinsics("OPENCV", 800, 600, (650.0, 650.0, 400.0, 300.0, -0.08, 0.0, 0.0, 0.0))
    rng = np.random.default_rng(5)
    rot = cm.rotation_from_opk(8.0, -6.0, 30.0)
    pose = cm.Pose.from_centre(rot, [3.0, -2.0, 50.0])
    xyz = []
    while len(xyz) < 10:
        p = np.array([rng.uniform(-35, 35), rng.uniform(-30, 30), rng.uniform(0, 25)])
        px, ok = cm.project_points(pose, true, p[None])
        if ok[0] and true.inside(px[0], 10):
            xyz.append(p)
    xyz = np.array(xyz)
    px, _ = cm.project_points(pose, true, xyz)
    px += rng.normal(0, 0.2, px.shape)
    prior = cm.Intrinsics.simple(800, 600, 650.0 * 1.06)
    r = rs.space_resection(xyz, px, prior)
    assert r.estimated_intrinsics and r.estimated_params == ["focal", "k1"]
    assert r.camera.focal == pytest.approx(650.0, rel=0.01)
    assert r.camera.dist[0] == pytest.approx(-0.08, abs=0.01)
    assert r.rmse_px < 0.5


def test_flat_control_keeps_the_focal_length_and_says_so():
    xyz, px, _ = _scene(8, seed=7, noise=0.3)
    r = rs.space_resection(xyz, px, cm.Intrinsics.simple(800, 600, 660.0))
    assert "focal" not in r.estimated_params
    assert r.camera.focal == pytest.approx(660.0)
    assert any("focal length" in w and "not estimated" in w for w in r.warnings)


def test_planar_homography_with_one_bad_point():
    rng = np.random.default_rng(3)
    h = np.array([[0.08, 0.01, -30.0], [-0.005, -0.079, 25.0], [1e-5, 2e-5, 1.0]])
    px = rng.uniform([0, 0], [800, 600], (7, 2))
    hom = rs.Homography(h, [], 0.0)
    world = hom.world_from_pixel(px)
    np.testing.assert_allclose(hom.pixel_from_world(world), px, atol=1e-8)
    world_bad = world.copy()
    world_bad[4] += [3.0, 0.0]
    fit = rs.fit_homography(px, world_bad, names=list("ABCDEFG"))
    assert [r.name for r in fit.residuals if not r.used] == ["E"]
    assert fit.rmse_m < 1e-6
    np.testing.assert_allclose(fit.world_from_pixel(px[:4]), world[:4], atol=1e-6)
    with pytest.raises(rs.ResectionError, match="at least 4 .* found 3"):
        rs.fit_homography(px[:3], world[:3])
