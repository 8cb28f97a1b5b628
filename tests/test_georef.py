"""Unit tests of core/georef/ that need no rendering and no SfM: Helmert fit and RANSAC,
Similarity algebra, and the adjustment on a small exact model built directly in pycolmap
(camera positions without heights, placeholder heights, a typo in a control point)."""
import math

import numpy as np
import pytest

from core.geometry.similarity import Similarity, helmert_fit, helmert_ransac
from core.georef.adjust import georeference
from core.georef.bundle import outside_image
from core.georef.errors import GeorefError
from core.georef.options import GeorefOptions
from core.georef.results import REJECTED
from core.georef.triangulate import triangulate_observations
from core.io import gcp as gcpmod


def _rot(ax, ay, az):
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


TRUE = Similarity(37.5, _rot(0.1, -0.2, 2.5), [500123.4, 4600456.7, 312.0])


def _points(n=8, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, (n, 3)) * [1.0, 1.0, 0.1]


def test_helmert_fit_recovers_a_known_similarity():
    src = _points()
    tr = helmert_fit(src, TRUE.apply(src))
    assert tr.scale == pytest.approx(TRUE.scale, rel=1e-10)
    np.testing.assert_allclose(tr.rotation, TRUE.rotation, atol=1e-10)
    np.testing.assert_allclose(tr.translation, TRUE.translation, atol=1e-6)
    # inverse and composition are consistent
    ident = tr.inverse().compose(tr)
    np.testing.assert_allclose(ident.apply(src), src, atol=1e-9)
    back = Similarity.from_dict(tr.to_dict())
    np.testing.assert_allclose(back.matrix(), tr.matrix(), atol=1e-9)


def test_helmert_fit_never_returns_a_reflection():
    src = _points()
    mirrored = TRUE.apply(src) * np.array([1, 1, -1])
    tr = helmert_fit(src, mirrored)
    assert np.linalg.det(tr.rotation) == pytest.approx(1.0)


def test_helmert_fit_rejects_collinear_and_too_few_points():
    line = np.outer(np.arange(5.0), [1, 2, 3])
    with pytest.raises(ValueError, match="collinear"):
        helmert_fit(line, line * 2)
    with pytest.raises(ValueError, match="at least 3"):
        helmert_fit(line[:2], line[:2])


def test_helmert_ransac_finds_the_one_bad_point_and_its_residual():
    src = _points(8)
    dst = TRUE.apply(src) + np.random.default_rng(2).normal(0, 0.02, (8, 3))
    dst[5] += [100.0, 0.0, 0.0]  # a typo of 100 m in X
    res = helmert_ransac(src, dst, threshold=0.5)
    assert list(np.flatnonzero(~res.inliers)) == [5]
    assert res.residuals[5] == pytest.approx(100.0, abs=1.0)
    assert np.all(res.residuals[res.inliers] < 0.1)
    assert res.transform.scale == pytest.approx(TRUE.scale, rel=1e-3)


# ---------------------------------------------------------------------------------------------
# the adjustment on an exact little block (pycolmap objects built from known geometry)
# ---------------------------------------------------------------------------------------------

W, H, F = 800, 600, 700.0
OFFSET = np.array([500000.0, 4600000.0, 100.0])


def _ground(x, y):
    return 2.0 * np.sin(x / 15.0) * np.cos(y / 20.0)


def _block(model_from_world: Similarity, seed=0, n_tie=1500):
    """A 3 x 4 vertical block 60 m above wavy ground, exact observations, returned in the model
    frame given by ``model_from_world`` (world = local + OFFSET); also the true world centres."""
    import pycolmap

    rng = np.random.default_rng(seed)
    rec = pycolmap.Reconstruction()
    cam = pycolmap.Camera(model="SIMPLE_RADIAL", width=W, height=H, params=[F, W / 2, H / 2, 0.0], camera_id=1)
    rec.add_camera(cam)
    rig = pycolmap.Rig(rig_id=1)
    rig.add_ref_sensor(pycolmap.sensor_t(pycolmap.SensorType.CAMERA, 1))
    rec.add_rig(rig)
    r_down = np.diag([1.0, -1.0, -1.0])  # camera looks down, image x = east, image y = south
    centres = []
    iid = 0
    for row in range(3):
        for col in range(4):
            iid += 1
            c_world = np.array([col * 25.0, row * 30.0, 60.0]) + rng.normal(0, 1.0, 3)
            centres.append(c_world)
            c_model = model_from_world.apply(c_world)
            r = r_down @ model_from_world.rotation.T
            pose = pycolmap.Rigid3d(pycolmap.Rotation3d(r), -r @ c_model)
            im = pycolmap.Image(name=f"img{iid:02d}.jpg", camera_id=1, image_id=iid)
            fr = pycolmap.Frame(frame_id=iid, rig_id=1)
            fr.add_data_id(im.data_id)
            fr.rig_from_world = pose
            rec.add_frame(fr)
            im.frame_id = iid
            rec.add_image(im)
            rec.register_frame(iid)
    rec_images = {i: rec.image(i) for i in rec.reg_image_ids()}
    pts2d = {i: [] for i in rec_images}
    tracks = []
    for _ in range(n_tie):
        x, y = rng.uniform(-10, 85), rng.uniform(-10, 70)
        xw = np.array([x, y, _ground(x, y)])
        obs = []
        for i, im in rec_images.items():
            uv = _project(rec, im, model_from_world.apply(xw))
            if uv is not None:
                obs.append((i, uv))
        if len(obs) >= 2:
            tracks.append((model_from_world.apply(xw), obs))
            for i, uv in obs:
                pts2d[i].append(uv)
    for i, im in rec_images.items():
        im.points2D = pycolmap.Point2DList([pycolmap.Point2D(np.asarray(uv)) for uv in pts2d[i]])
    counters = {i: 0 for i in rec_images}
    for xyz, obs in tracks:
        track = pycolmap.Track()
        for i, _ in obs:
            track.add_element(i, counters[i])
            counters[i] += 1
        rec.add_point3D(xyz, track)
    return rec, np.array(centres)


def _project(rec, im, xyz):
    xc = np.asarray(im.cam_from_world().matrix()) @ np.append(xyz, 1.0)
    if xc[2] <= 0:
        return None
    uv = rec.cameras[im.camera_id].img_from_cam(xc)
    uv = np.asarray(uv, dtype=float).reshape(-1)[:2]
    if 0 <= uv[0] < W and 0 <= uv[1] < H:
        return uv
    return None


def _gcps(rec, model_from_world, names_xy, z_given=None, noise_px=0.0, seed=3):
    rng = np.random.default_rng(seed)
    pts = []
    for name, (x, y) in names_xy.items():
        xw = np.array([x, y, _ground(x, y)])
        obs = []
        for i in rec.reg_image_ids():
            uv = _project(rec, rec.image(i), model_from_world.apply(xw))
            if uv is not None:
                uv = uv + rng.normal(0, noise_px, 2)
                obs.append(gcpmod.Observation(image=rec.image(i).name, x=float(uv[0]), y=float(uv[1])))
        z = xw[2] if z_given is None else z_given
        pts.append(gcpmod.GroundPoint(name=name, x=x + OFFSET[0], y=y + OFFSET[1], z=z + OFFSET[2],
                                      observations=obs))
    return gcpmod.GCPSet(points=pts, crs="EPSG:32633")


MODEL_FROM_WORLD = Similarity(0.05, _rot(0.3, 0.1, 1.0), [1.0, -2.0, 3.0])
SPREAD = {"a": (2.0, 3.0), "b": (73.0, 5.0), "c": (5.0, 58.0), "d": (72.0, 57.0), "e": (38.0, 30.0)}


@pytest.fixture(scope="module")
def block():
    return _block(MODEL_FROM_WORLD)


def test_exact_block_with_gcps_lands_on_the_truth(block):
    rec, _ = block
    gcps = _gcps(rec, MODEL_FROM_WORLD, SPREAD)
    gcpmod.apply_check_points(gcps, ["e"])
    r = georeference(rec, gcps)
    chk = r.rmse("check")
    assert chk["n"] == 1
    assert chk["xy"] < 0.01 and chk["z"] < 0.01
    assert not r.outliers


def test_a_100_m_typo_is_named_and_left_out(block):
    rec, _ = block
    xy = dict(SPREAD, f=(40.0, 8.0), g=(20.0, 50.0))
    gcps = _gcps(rec, MODEL_FROM_WORLD, xy, noise_px=0.3)
    gcpmod.apply_check_points(gcps, ["e"])
    typo = next(p for p in gcps.points if p.name == "d")
    typo.x += 100.0
    r = georeference(rec, gcps)
    named = [o for o in r.outliers if o.name == "d"]
    assert named, r.outliers
    assert named[0].residual == pytest.approx(100.0, rel=0.1)
    assert "d" in " ".join(r.warnings)
    assert r.rmse("check")["xy"] < 0.05


def test_a_typo_stays_out_after_the_retest_against_the_adjusted_block(block):
    """Control points off the Helmert fit are re-tested against the adjusted block: a 100 m typo fails
    that test by far (named in a warning with its residuals); without the adjustment the Helmert
    verdict is final."""
    rec, _ = block
    xy = dict(SPREAD, f=(40.0, 8.0), g=(20.0, 50.0))
    gcps = _gcps(rec, MODEL_FROM_WORLD, xy, noise_px=0.3)
    gcpmod.apply_check_points(gcps, ["e"])
    next(p for p in gcps.points if p.name == "d").x += 100.0
    r = georeference(rec, gcps)
    assert r.statistics["readmitted_control_points"] == []
    t = r.statistics["helmert_retests"]["d"]
    assert t["sigma"] > 100 * t["threshold_sigma"] and t["free_distance_m"] == pytest.approx(100.0, rel=0.01)
    assert any("d is" in w and "adjusted block" in w and "excluded" in w for w in r.warnings)
    h = georeference(rec, gcps, options=GeorefOptions(adjust=False))
    assert [o.name for o in h.outliers if o.kind == "control point"] == ["d"]
    assert any("d is" in w and "Helmert fit" in w for w in h.warnings)
    assert next(p for p in h.points if p.name == "d").status == REJECTED


def test_observation_outside_the_image_is_skipped_in_the_triangulation(block):
    rec, _ = block
    gcps = _gcps(rec, MODEL_FROM_WORLD, {"e": SPREAD["e"]})
    obs = list(gcps.points[0].observations)
    seen = {o.image for o in obs}
    other = next(rec.image(i).name for i in rec.reg_image_ids() if rec.image(i).name not in seen)
    obs.insert(0, gcpmod.Observation(other, W + 0.5, 100.0))  # just off the right edge
    t = triangulate_observations(rec, obs)
    assert not t.used[0] and np.isnan(t.residuals_px[0]) and t.n_used == len(obs) - 1
    assert any("outside" in n and other in n for n in t.notes)
    # pixel convention: the image spans [0, width] x [0, height], edges included
    cam = rec.cameras[1]
    inside = [(0.0, 0.0), (W, H), (W / 2, H / 2)]
    outside = [(-0.01, 10.0), (10.0, H + 0.01), (W + 0.01, 10.0), (float("nan"), 10.0)]
    assert not any(outside_image(cam, gcpmod.Observation("x", x, y)) for x, y in inside)
    assert all(outside_image(cam, gcpmod.Observation("x", x, y)) for x, y in outside)


def test_camera_positions_without_heights_constrain_xy_only(block):
    rec, centres = block
    gcps = _gcps(rec, MODEL_FROM_WORLD, SPREAD)
    gcpmod.apply_check_points(gcps, ["e", "d"])  # 3 control points fix the datum
    cams = [gcpmod.CameraPosition(image=f"img{k + 1:02d}.jpg", x=c[0] + OFFSET[0], y=c[1] + OFFSET[1],
                                  z=float("nan"), sigma_xy=0.05, sigma_z=1.0) for k, c in enumerate(centres)]
    r = georeference(rec, gcps, cams)
    assert any("without a height" in w for w in r.warnings)
    assert r.rmse("check")["xy"] < 0.01
    dxy = [math.hypot(c.dx, c.dy) for c in r.cameras]
    assert max(dxy) < 0.02
    assert all(math.isnan(c.dz) for c in r.cameras)


def test_camera_positions_without_heights_alone_are_refused(block):
    rec, centres = block
    cams = [gcpmod.CameraPosition(image=f"img{k + 1:02d}.jpg", x=c[0] + OFFSET[0], y=c[1] + OFFSET[1],
                                  z=float("nan")) for k, c in enumerate(centres)]
    with pytest.raises(GeorefError, match="without a height"):
        georeference(rec, None, cams, options=GeorefOptions(crs="EPSG:32633"))


def test_camera_positions_only_land_within_their_noise(block):
    rec, centres = block
    rng = np.random.default_rng(7)
    sigma = 0.5
    noisy = centres + rng.normal(0, sigma, centres.shape)
    cams = [gcpmod.CameraPosition(image=f"img{k + 1:02d}.jpg", x=c[0] + OFFSET[0], y=c[1] + OFFSET[1],
                                  z=c[2] + OFFSET[2], sigma_xy=sigma, sigma_z=sigma) for k, c in enumerate(noisy)]
    gcps = _gcps(rec, MODEL_FROM_WORLD, SPREAD)
    gcpmod.apply_check_points(gcps, list(SPREAD))
    r = georeference(rec, gcps, cams)
    assert r.source == "camera positions"
    chk = r.rmse("check")
    # 12 positions with sigma 0.5 m fix the datum to about sigma / sqrt(12) = 0.14 m per axis
    assert chk["n"] == 5
    assert chk["xy"] < 3 * sigma / math.sqrt(12) * math.sqrt(2)
    assert chk["z"] < 3 * sigma / math.sqrt(12)


def test_placeholder_heights_are_detected_and_not_taken_as_surveyed(block):
    rec, _ = block
    gcps = _gcps(rec, MODEL_FROM_WORLD, SPREAD, z_given=0.0)
    gcpmod.apply_check_points(gcps, ["e"])
    r = georeference(rec, gcps)
    assert r.statistics["placeholder_z"] == pytest.approx(OFFSET[2])
    assert any("placeholder" in w for w in r.warnings)
    # the check point's XY stays good: the wavy ground (+-2 m) was not forced flat at 5 cm
    assert r.rmse("check")["xy"] < 0.15


def test_gcps_in_degrees_labelled_as_metres_are_refused(block):
    rec, _ = block
    gcps = _gcps(rec, MODEL_FROM_WORLD, SPREAD)
    for p in gcps.points:
        p.x, p.y = 12.5 + p.x * 1e-6, 41.5 + p.y * 1e-6
    with pytest.raises(ValueError, match="(?i)degree"):
        gcpmod.check_units(gcps, "EPSG:32633")


def test_control_points_that_disagree_with_the_block_by_metres_are_named(block):
    """COPR's pattern: most targets agree with the block to centimetres, some are metres off."""
    rec, _ = block
    xy = dict(SPREAD, f=(40.0, 8.0), g=(20.0, 50.0))
    gcps = _gcps(rec, MODEL_FROM_WORLD, xy, noise_px=0.2)
    for p in gcps.points:
        if p.name == "b":
            p.x += 1.5
        if p.name == "g":
            p.y -= 2.0
    r = georeference(rec, gcps)
    cons = r.statistics["control_consistency"]
    assert cons["suspects"] == ["g", "b"]
    assert cons["rms_m"] < 0.05
    assert cons["residuals_m"]["g"] == pytest.approx(2.0, abs=0.2)
    assert any("b (" in w and "g (" in w and "suspect" in w for w in r.warnings)


@pytest.mark.parametrize("field, value, what", [("refine_intrinsics", ("focal", "zoom"), "unknown group"),
                                                ("outlier_threshold", 0.0, "outlier_threshold must be a positive"),
                                                ("huber_px", float("nan"), "huber_px must be a positive"),
                                                ("focal_prior", -0.01, "focal_prior must be zero or a positive"),
                                                ("helmert_threshold", -2.0, "helmert_threshold must be a positive")])
def test_georef_options_refuse_a_bad_value_when_made(field, value, what):
    with pytest.raises(GeorefError, match=what):
        GeorefOptions(**{field: value})


def test_georef_options_take_one_check_point_name_as_a_list():
    assert tuple(GeorefOptions(check_points="gcp03, gcp06").check_points) == ("gcp03", "gcp06")
