"""High obliques (issue 13, item 4): sky masks before and after alignment, no tie point and no dense point from the
sky, per-image orthophotos limited to where their ground resolution is within a factor of their best, and a
synthetic orbit (tests/synthetic.py: cameras circling the site at 45 and 65 degrees off nadir, the horizon and
the sky in view at 65) aligned, georeferenced, matched and mosaicked end to end against its truth (in photos of
320 x 240 over an orbit 2/3 the size: ORBIT_E2E).

Fast tests first (one or two rendered images, analytic cameras); the orbit end to end is marked slow."""
import math
import os

import cv2
import numpy as np
import pytest
from osgeo import gdal

from core.common.progress import NullProgress
from core.geometry.camera import Intrinsics, Pose
from core.io import raster as rastermod
from core.ortho.cameras import OrthoCamera
from core.ortho.mosaic import build_orthomosaic
from core.ortho.options import OrthoError, OrthoOptions
from core.prepare import sky
from core.prepare.masks import find_mask, read_keep
from core.prepare.options import PrepareOptions, SkyOptions
from tests import synthetic as syn

ORBIT = dict(seed=21, per_ring=8)
CAM = syn.ORBIT_CAMERA
# the orbit end to end: ORBIT in photos of 320 x 240 (2/3 of ORBIT_CAMERA's side, the same field of view), the
# orbit 2/3 the size (26.7 m high, the cameras' jitter and the ground marks' square in metres scaled with it: the
# same view angles, horizons and sky): the GSD of the full-size orbit (0.133 m) over less of the site, less than
# half the rendering, features and dense matching of the full-size photos
ORBIT_E2E = dict(ORBIT, image_scale=2 / 3, altitude=40.0 * 2 / 3, position_jitter=0.5 * 2 / 3,
                 target_jitter=3.0 * 2 / 3, gcp_half=22.0 * 2 / 3)


def _intrinsics(c=CAM):
    return Intrinsics("OPENCV", c.width, c.height, tuple(c.params))


@pytest.fixture(scope="module")
def orbit():
    return syn.orbit_block(**ORBIT)


@pytest.fixture(scope="module")
def two_renders(orbit, tmp_path_factory):
    """One 65 degree and one 45 degree image of the orbit, rendered (about 4 s)."""
    root = tmp_path_factory.mktemp("two obliques")
    steep = next(s for s in orbit.shots if orbit.tilts[s.name] == 65.0)
    mild = next(s for s in orbit.shots if orbit.tilts[s.name] == 45.0)
    paths = {}
    for k, s in enumerate((steep, mild)):
        img = syn.render_oblique_image(orbit.scene, orbit.camera, s, seed=k, clouds=orbit.clouds)
        paths[s.name] = str(root / s.name)
        cv2.imwrite(paths[s.name], cv2.cvtColor(img, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 95])
    return steep, mild, paths


# ---------------------------------------------------------------------------
# the synthetic orbit itself
# ---------------------------------------------------------------------------

def test_orbit_has_sky_in_the_steep_views_only(orbit):
    assert len(orbit.shots) == 16
    for s in orbit.shots:
        frac = orbit.sky_mask(s).mean()
        if orbit.tilts[s.name] == 65.0:
            assert 0.02 < frac < 0.25, (s.name, frac)
        else:
            assert frac == 0.0, s.name
    assert sum(p.kind == "ground" for p in orbit.gcps) >= 10
    assert all(len(p.observations) >= 3 for p in orbit.gcps)


def test_render_shows_sky_where_the_truth_says(orbit, two_renders):
    steep, mild, paths = two_renders
    img = cv2.cvtColor(cv2.imread(paths[steep.name]), cv2.COLOR_BGR2RGB).astype(float)
    truth = orbit.sky_mask(steep, margin_deg=-1.0)  # 1 degree above the horizon: clear sky
    ground = ~orbit.sky_mask(steep, margin_deg=8.0)  # 8 degrees below it: the scene
    assert truth.any() and ground.any()
    assert img[truth][:, 2].mean() > img[truth][:, 0].mean() + 15  # blue sky (with white clouds)
    assert img[ground][:, 2].mean() < img[ground][:, 0].mean()  # brownish ground
    assert img[ground].std(axis=0).min() > 15
    # the clouds give SIFT something to find in the sky: without a mask there would be keypoints there
    kp = cv2.SIFT_create().detect(cv2.cvtColor(img.astype(np.uint8), cv2.COLOR_RGB2GRAY), None)
    assert orbit.in_sky(steep, np.array([k.pt for k in kp])).sum() >= 1


# ---------------------------------------------------------------------------
# the sky detector (before alignment) and the pose's horizon (after)
# ---------------------------------------------------------------------------

def test_sky_detector_masks_the_sky_and_keeps_the_ground(orbit, two_renders, tmp_path):
    steep, mild, paths = two_renders
    keep = sky.detect_sky(paths[steep.name])
    truth = orbit.sky_mask(steep)
    assert keep.shape == truth.shape
    assert not (truth & keep).any(), "a sky pixel is left for the features"
    masked_ground = ~keep & ~truth
    print(f"\nsky {truth.mean():.3f} of the image, masked {1 - keep.mean():.3f}, ground masked "
          f"{masked_ground.mean():.3f}")
    # what is hidden beyond the sky is the hazy band along the horizon: within 3 degrees below it
    assert not (masked_ground & ~orbit.sky_mask(steep, margin_deg=3.0)).any()
    assert masked_ground.mean() < 0.04
    # the 45 degree view shows no sky: no mask
    assert sky.detect_sky(paths[mild.name]).all()
    # written through the mask machinery, merged with a mask the image already has
    images = os.path.dirname(paths[steep.name])
    masks = str(tmp_path / "masks")
    os.makedirs(masks)
    prior = np.ones(truth.shape, bool)
    prior[-20:, :] = False  # e.g. a date stamp at the bottom
    cv2.imwrite(os.path.join(masks, steep.name + ".png"), np.where(prior, 255, 0).astype(np.uint8))
    infos = []

    class Log(NullProgress):
        def info(self, message):
            infos.append(message)

    res = sky.write_sky_masks(images, [steep.name, mild.name], masks, progress=Log())
    assert set(res.masks) == {steep.name}
    # the log says how much each mask took (issue 36 item 7)
    last = int(np.flatnonzero((~keep).any(axis=1))[-1])
    assert infos == [f"sky mask: {steep.name}: {100 * (1 - keep.mean()):.1f} % of the photo (rows 0\u2013{last})"]
    assert res.sky_rows[steep.name] == (0, last)
    written = read_keep(find_mask(masks, steep.name), CAM.width, CAM.height)
    assert np.array_equal(written, keep & prior)
    assert find_mask(masks, mild.name) is None
    assert abs(res.sky_fraction[steep.name] - (1 - written.mean())) < 1e-3


def test_sky_detector_follows_the_exif_orientation(orbit, two_renders):
    """A portrait-held camera (EXIF 6: shown turned 90 degrees clockwise): the sky is at the upright top, i.e. the
    stored grid's left edge."""
    steep, _, paths = two_renders
    img = cv2.cvtColor(cv2.imread(paths[steep.name]), cv2.COLOR_BGR2RGB)
    stored = np.ascontiguousarray(np.rot90(img, k=1))  # what a camera held in portrait stores (orientation 6)
    keep6 = sky.sky_keep(stored, orientation=6)
    keep1 = sky.sky_keep(img)
    assert np.array_equal(keep6, np.rot90(keep1, k=1))
    assert not keep6[:, :5].any() and keep6[:, -5:].all()  # the sky along the stored grid's left edge


def test_sky_detector_finds_no_sky_in_vertical_photos():
    """Real vertical photos (the Toledo strip: bright roads and roofs at the upper edge) and a rendered vertical."""
    from tests.conftest import SAMPLE, TOLEDO_STRIP

    for name in TOLEDO_STRIP[:3]:
        keep = sky.detect_sky(os.path.join(SAMPLE, "images", name))
        assert keep.all(), (name, 1 - keep.mean())
    blk = syn.vertical_block(seed=2, camera=syn.CameraModel(400, 300, 325.0, 325.0, 200.0, 150.0), n_strips=1,
                             per_strip=2, gcp_grid=(2, 2), roofs=0)
    grey = syn.render_image(blk.scene, blk.camera, blk.shots[0])
    assert sky.sky_keep(grey).all()


def _pale_band(img: np.ndarray, depth: float = 0.35, alpha: float = 0.75, colour=(228, 228, 226)) -> np.ndarray:
    """``img`` (RGB) with a pale band over its upper part (over-exposure, haze): ``alpha`` at the upper edge,
    fading out at ``depth`` of the height."""
    h = img.shape[0]
    a = np.clip(alpha * (1.0 - (np.arange(h) / h) / depth), 0.0, 1.0)[:, None, None]
    out = img.astype(np.float32) * (1.0 - a) + np.asarray(colour, np.float32) * a
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def _paint_road(img: np.ndarray, top: np.ndarray, bottom: float, x0: float, slope: float, half: float,
                grey=(200, 200, 198)) -> np.ndarray:
    """``img`` with a smooth pale road (RGB ``grey``) from row ``top[col]`` down to ``bottom`` of the height,
    centred at ``x0`` of the width and drifting ``slope`` of it over the height, ``half`` of the width wide."""
    h, w = img.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w]
    road = (np.abs(xx - (x0 + slope * yy / h) * w) < half * w) & (yy >= top[None, :]) & (yy < bottom * h)
    out = img.copy()
    out[road] = (np.asarray(grey, np.float32)
                 + np.random.default_rng(1).normal(0.0, 1.0, (int(road.sum()), 3))).clip(0, 255).astype(np.uint8)
    return out


@pytest.fixture(scope="module")
def nadir_pale(orbit):
    """A nadir-ish photo of the orbit's site (11 degrees off nadir: no sky at all) with a pale band over its upper
    part (over-exposed, hazy field) and a smooth pale road from the upper edge down to 93 % of the height, as in
    issue 36 item 7 (about 2 s)."""
    base = orbit.scene.base_z
    c = np.array([3.0, -8.0, base + 40.0])
    shot = syn.Shot("NADIR.jpg", syn.look_at(c, np.array([3.0, 0.0, base]), np.array([0.0, 0.0, 1.0])), c)
    img = syn.render_oblique_image(orbit.scene, orbit.camera, shot, seed=5)
    assert not orbit.sky_mask(shot).any()
    img = _paint_road(img, np.zeros(img.shape[1], int), 0.93, 0.3, 0.08, 0.025, grey=(178, 174, 168))
    return _pale_band(img)


def test_sky_mask_stops_at_the_horizon(orbit, two_renders, nadir_pale, tmp_path):
    """Issue 36 item 7: a pale band over the top of a nadir-ish photo and the smooth road below it were masked
    as sky down to near the lower edge (row 336 of 360 here; row 877 of 900 on the Toledo photos).  The sky's lower
    edge must follow a horizon (one smooth line across the photo) and the mask stops there."""
    from tests.conftest import SAMPLE, TOLEDO_STRIP

    keep = sky.sky_keep(nadir_pale)
    assert (~keep).mean() < 0.005, f"nadir-ish photo masked {(~keep).mean():.1%}"
    # the log says why the bright band at its top got no mask
    infos = []

    class Log(NullProgress):
        def info(self, message):
            infos.append(message)

    images = tmp_path / "images"
    images.mkdir()
    cv2.imwrite(str(images / "NADIR.jpg"), cv2.cvtColor(nadir_pale, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 95])
    res = sky.write_sky_masks(str(images), ["NADIR.jpg"], str(tmp_path / "masks"), progress=Log())
    assert not res.masks and infos == [f"sky mask: NADIR.jpg: none, {sky.NO_HORIZON}"]
    # three real vertical photos under a pale band (the case)
    for name in TOLEDO_STRIP[:3]:
        img = cv2.cvtColor(cv2.imread(os.path.join(SAMPLE, "images", name)), cv2.COLOR_BGR2RGB)
        for depth, alpha, grey in ((0.3, 0.7, 220), (0.25, 0.85, 235)):
            keep = sky.sky_keep(_pale_band(img, depth, alpha, (grey,) * 3))
            assert (~keep).mean() < 0.005, (name, depth, alpha, (~keep).mean())
    # the oblique, and the oblique with a pale road from the horizon down: the mask stops at the true horizon
    steep, _, paths = two_renders
    img = cv2.cvtColor(cv2.imread(paths[steep.name]), cv2.COLOR_BGR2RGB)
    truth = orbit.sky_mask(steep)
    h = truth.shape[0]
    horizon = truth.sum(axis=0)  # rows of sky per column
    road = _paint_road(img, horizon, 0.85, 0.6, -0.15, 0.03)
    tol = SkyOptions().horizon_tolerance + SkyOptions().margin + 0.01  # of the height: the band and the haze
    for label, im in (("oblique", img), ("oblique and a pale road", road)):
        keep = sky.sky_keep(im)
        below = (~keep).sum(axis=0) - horizon  # rows masked below the true horizon, per column
        print(f"\n{label}: masked {(~keep).mean():.3f}, below the horizon {below.min()}..{below.max()} rows")
        assert not (truth & keep).any(), label
        assert below.min() >= 0 and below.max() <= tol * h, (label, below.min(), below.max())


def _with_xmp_pitch(src: str, dst: str, pitch: float) -> None:
    """A copy of the JPEG ``src`` with a DJI XMP packet (APP1) giving the gimbal pitch."""
    xmp = (b'<?xpacket begin="" id="W5M0MpCehiHzreSzNTczkc9d"?><x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF '
           b'xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"><rdf:Description '
           b'xmlns:drone-dji="http://www.dji.com/drone-dji/1.0/" drone-dji:GimbalRollDegree="+0.00" '
           b'drone-dji:GimbalPitchDegree="%+.2f"/></rdf:RDF></x:xmpmeta><?xpacket end="w"?>' % pitch)
    payload = b"http://ns.adobe.com/xap/1.0/\x00" + xmp
    data = open(src, "rb").read()
    assert data[:2] == b"\xff\xd8"
    with open(dst, "wb") as f:
        f.write(data[:2] + b"\xff\xe1" + (len(payload) + 2).to_bytes(2, "big") + payload + data[2:])


def test_sky_mask_follows_the_camera_pitch(orbit, two_renders, tmp_path):
    """Where the photo records its camera's pitch (a drone's XMP), a camera looking down too steeply to see the
    horizon gets no mask whatever its pixels look like, and one that sees it keeps the mask of its pixels."""
    from core.io.images import xmp_camera_pitch

    steep, _, paths = two_renders
    nadir, tilted = str(tmp_path / "nadir.jpg"), str(tmp_path / "tilted.jpg")
    _with_xmp_pitch(paths[steep.name], nadir, -90.0)
    _with_xmp_pitch(paths[steep.name], tilted, -25.0)  # 65 degrees off nadir: the truth
    assert xmp_camera_pitch(nadir) == -90.0 and xmp_camera_pitch(tilted) == -25.0
    assert xmp_camera_pitch(paths[steep.name]) is None
    assert sky.detect_sky(nadir).all()
    assert np.array_equal(sky.detect_sky(tilted), sky.detect_sky(paths[steep.name]))
    # the geometry: 25 degrees above the axis (f = 300 px, 360 rows) is row 180 - 300 tan 25 = 40.1
    assert sky.horizon_row_of_pitch(-25.0, 300.0, 360) == pytest.approx(180 - 300 * math.tan(math.radians(25)))
    assert sky.horizon_row_of_pitch(-90.0, 300.0, 360, below_deg=5.0) < -1000
    assert sky.horizon_row_of_pitch(-89.95, 300.0, 360) == -math.inf


def test_horizon_of_the_pose_is_the_true_horizon(orbit):
    cam = _intrinsics()
    for s in orbit.shots[7:10]:
        keep = sky.horizon_keep(cam, s.rotation, margin_deg=0.0)
        truth = orbit.sky_mask(s)
        # the same pixels but for the interpolated band along the line (a row or so)
        differ = keep != ~truth
        assert differ.sum() <= 2 * CAM.width, (s.name, differ.sum())
        band = orbit.sky_mask(s, margin_deg=0.3) & ~orbit.sky_mask(s, margin_deg=-0.3)  # within 0.3 degrees
        assert not (differ & ~band).any()
        # a margin hides that much below the horizon as well
        keep2 = sky.horizon_keep(cam, s.rotation, margin_deg=2.0)
        assert not (keep2 & orbit.sky_mask(s, margin_deg=1.8)).any()
        assert (~keep2).sum() >= (~keep).sum()
    # at reduced size (a dense-matching scale)
    s = orbit.shots[8]
    half = sky.horizon_keep(cam, s.rotation, margin_deg=0.0, shape=(CAM.height // 2, CAM.width // 2))
    assert abs(half.mean() - (~orbit.sky_mask(s)).mean()) < 0.01


def test_up_of_an_aligned_model_from_its_tie_points(orbit):
    rec = orbit.truth_reconstruction(n_points=800, model_from_local="random", seed=3)
    im = next(iter(rec.images.values()))
    r_model = np.asarray(im.cam_from_world().rotation.matrix())
    r_true = orbit.shot(im.name).rotation
    model_from_local = r_model.T @ r_true  # rotation part of the random similarity
    up = sky.estimate_up(rec)
    expected = model_from_local @ np.array([0.0, 0.0, 1.0])
    angle = math.degrees(math.acos(np.clip(up @ expected, -1, 1)))
    print(f"\nup estimated within {angle:.2f} degrees")
    assert angle < 3.0  # hills of a few metres over 130 m: the best plane is nearly level


def test_horizon_masks_after_alignment(orbit, tmp_path):
    rec = orbit.truth_reconstruction(n_points=800, model_from_local="random", seed=3)
    res = sky.write_horizon_masks(rec, str(tmp_path / "masks"), margin_deg=1.0)
    steep = {n for n, t in orbit.tilts.items() if t == 65.0}
    assert set(res.masks) == steep
    for n in steep:
        keep = read_keep(res.masks[n], CAM.width, CAM.height)
        assert not (keep & orbit.sky_mask(n)).any(), n


def test_prepare_stage_writes_sky_masks(two_renders, tmp_path):
    from core.prepare.stage import prepare_images_workspace
    from core.project.workspace import Workspace

    steep, mild, paths = two_renders
    images = os.path.dirname(paths[steep.name])
    ws = str(tmp_path / "ws")
    res = prepare_images_workspace(images, ws, options=PrepareOptions(sky_masks=True, sky=SkyOptions()))
    assert [os.path.basename(m) for m in res.masks] == [steep.name + ".png"]
    rec = Workspace.open(ws).stage("prepare")
    assert set(rec["results"]["sky_masked_images"]) == {steep.name}
    assert rec["parameters"]["sky"]["max_texture"] == SkyOptions().max_texture
    # off by default: no mask
    res2 = prepare_images_workspace(images, str(tmp_path / "ws2"))
    assert not res2.masks


def test_processing_exposes_sky_masks_and_the_gsd_factor(plugin, two_renders, tmp_path):
    from qgis import processing
    from qgis.core import QgsApplication

    ortho = QgsApplication.processingRegistry().algorithmById("archaeoortho:buildorthophoto")
    assert ortho.parameterDefinition("GSD_FACTOR").defaultValue() == OrthoOptions().gsd_factor == 3.0
    steep, mild, paths = two_renders
    images = str(tmp_path / "images")
    os.makedirs(images)
    for p in paths.values():
        os.link(p, os.path.join(images, os.path.basename(p)))
    res = processing.run("archaeoortho:prepareimages", {"IMAGES": images, "WORKSPACE": str(tmp_path / "ws"),
                                                         "SKY_MASKS": True})
    assert os.listdir(os.path.join(res["WORKSPACE"], "masks")) == [steep.name + ".png"]


# ---------------------------------------------------------------------------
# dense matching: nothing from the sky
# ---------------------------------------------------------------------------

def test_fusion_drops_the_sky_of_the_pose_and_the_masked_pixels(orbit, tmp_path):
    from core.dense.fusion import sky_free
    from core.dense.pairs import View

    s = next(s for s in orbit.shots if orbit.tilts[s.name] == 65.0)
    v = View(1, s.name, "", CAM.width, CAM.height, "OPENCV", tuple(CAM.params), s.rotation, -s.rotation @ s.centre)
    depth = np.full((CAM.height // 2, CAM.width // 2), 50.0, np.float32)
    out = sky_free(v, depth, 1.0)

    def small(m):
        return cv2.resize(m.astype(np.uint8), depth.shape[::-1], interpolation=cv2.INTER_NEAREST) > 0

    assert np.isnan(out[small(orbit.sky_mask(s, margin_deg=0.8))]).all()  # the sky and 1 degree below the horizon
    assert np.isfinite(out[~small(orbit.sky_mask(s, margin_deg=1.2))]).all()  # the rest
    mask = np.full((CAM.height, CAM.width), 255, np.uint8)
    mask[:, :40] = 0
    cv2.imwrite(str(tmp_path / "m.png"), mask)
    v.mask_path = str(tmp_path / "m.png")
    out = sky_free(v, depth, None)
    assert np.isnan(out[:, :20]).all() and np.isfinite(out[:, 20:]).all()


# ---------------------------------------------------------------------------
# orthophotos: each image only within GSD_FACTOR of its best ground resolution
# ---------------------------------------------------------------------------

def _pinhole(w=400, h=300, f=300.0):
    return Intrinsics("PINHOLE", w, h, (f, f, w / 2, h / 2))


def test_ground_resolution_of_nadir_and_oblique_views():
    cam = _pinhole()
    nadir = OrthoCamera("n", "", cam, Pose.from_centre(syn.look_at([0, 0, 50.0], [0, 0, 0.0], [0, 1.0, 0]),
                                                         [0, 0, 50.0]))
    assert abs(nadir.ground_resolution(np.array([[0.0, 0.0, 0.0]]))[0] - 50.0 / 300.0) < 1e-3
    for tilt in (30.0, 45.0, 65.0):
        d = 50.0 * math.tan(math.radians(tilt))
        c = [-d, 0.0, 50.0]
        ob = OrthoCamera("o", "", cam, Pose.from_centre(syn.look_at(c, [0, 0, 0.0], [0, 0, 1.0]), c))
        # on the optical axis: the along-range footprint of a pixel, H / (f cos^2 tilt)
        expected = 50.0 / (300.0 * math.cos(math.radians(tilt)) ** 2)
        got = ob.ground_resolution(np.array([[0.0, 0.0, 0.0]]))[0]
        assert abs(got / expected - 1) < 0.01, (tilt, got, expected)
        assert not np.isfinite(ob.ground_resolution(np.array([[-2 * d, 0.0, 0.0]]))[0])  # behind it


def test_gsd_factor_is_checked():
    for bad in (0.5, -1.0, float("nan")):
        with pytest.raises(OrthoError, match="GSD_FACTOR"):
            OrthoOptions(gsd_factor=bad).check()
    OrthoOptions(gsd_factor=0).check()
    OrthoOptions(gsd_factor=1.0).check()


def _flat_pair(root):
    """A flat DSM (z = 100) and two uniformly grey images: A (value 60), a 65 degree oblique from the west looking
    east, whose far field reaches over B (value 200), a vertical 160 m east of it."""
    crs = syn.CRS
    offset = np.array(syn.ORIGIN)
    res = 1.0
    xs0, ys0 = -150.0, 150.0
    dsm = np.full((300, 400), 100.0, np.float32)
    gt = (xs0 + offset[0], res, 0.0, ys0 + offset[1], 0.0, -res)
    dsm_path = rastermod.write_cog(os.path.join(root, "dsm.tif"), dsm, gt, crs)
    cam = _pinhole()
    ca = np.array([-100.0, 0.0, 150.0])
    ta = ca + np.array([math.sin(math.radians(65.0)), 0.0, -math.cos(math.radians(65.0))])
    cb = np.array([60.0, 0.0, 150.0])
    cams = []
    for name, c, target, up, value in (("A.tif", ca, ta, [0, 0, 1.0], 60), ("B.tif", cb, cb - [0, 0, 1.0], [0, 1.0, 0], 200)):
        path = os.path.join(root, name)
        cv2.imwrite(path, np.full((cam.height, cam.width, 3), value, np.uint8))
        cams.append(OrthoCamera(name, path, cam, Pose.from_centre(syn.look_at(c, target, np.array(up)), c)))
    return cams, dsm_path, crs, offset


def _values_along_x(path, offset):
    ds = gdal.Open(path)
    a = ds.ReadAsArray().astype(float)
    gt = ds.GetGeoTransform()
    row = int(round((offset[1] - gt[3]) / gt[5]))  # the line y = 0 (local)
    xs = gt[0] + (np.arange(a.shape[2]) + 0.5) * gt[1] - offset[0]
    return xs, a[0, row], a[-1, row] > 0


def test_far_field_of_an_oblique_is_left_to_the_near_view(tmp_path):
    """Along the line between the two cameras: A's near field, A's far field (coarser than 3 x A's best), B's
    footprint.  With GSD_FACTOR 3 the far field stays out of A's own orthophoto and out of the mosaic, B fills its
    footprint; without a limit A's far field is in both."""
    cams, dsm, crs, offset = _flat_pair(str(tmp_path))
    a = cams[0]
    # A's best ground resolution: over its whole image (pixels met with the ground plane), at a lower corner
    gx, gy = np.meshgrid(np.linspace(0, 400, 81), np.linspace(0, 300, 61))
    rays = np.column_stack([a.camera.unproject(np.column_stack([gx.ravel(), gy.ravel()])), np.ones(gx.size)])
    rays = rays @ a.pose.rotation
    rays = rays[rays[:, 2] < 0]
    ground = a.centre + ((100.0 - a.centre[2]) / rays[:, 2])[:, None] * rays
    best = float(np.min(a.ground_resolution(ground)))
    assert 0.2 < best < 0.23  # 50 m / 300 px, stretched 38 degrees off nadir, shrunk off the optical axis
    xs_line = np.linspace(-100, 150, 2501)
    g = a.ground_resolution(np.column_stack([xs_line, np.zeros_like(xs_line), np.full_like(xs_line, 100.0)]))
    first = np.flatnonzero(np.isfinite(g))[0]  # the image's lower edge
    x_limit = float(xs_line[first + np.flatnonzero(g[first:] > 3 * best)[0]])
    assert -20 < x_limit < 20  # the far field starts about where A's optical axis meets the ground
    results = {}
    for factor in (3.0, 0.0):
        out = str(tmp_path / f"mosaic_{factor:g}.tif")
        per = str(tmp_path / f"per_{factor:g}")
        build_orthomosaic(cams, crs, offset, OrthoOptions(dsm_path=dsm, output=out, per_image_folder=per,
                                                          gsd_factor=factor, blending="none", exposure=False,
                                                          radiometry=False, resolution=0.5))
        results[factor] = (_values_along_x(out, offset), _values_along_x(os.path.join(per, "A.tif"), offset))
    (xs, val, ok), (xa, _va, oka) = results[3.0]
    b_lo, b_hi = 60 - 50.0 * 200 / 300.0, 60 + 50.0 * 200 / 300.0  # B's footprint on the line
    in_b = (xs > b_lo + 1) & (xs < b_hi - 1)
    assert ok[in_b].all() and np.all(np.abs(val[in_b] - 200) < 1)  # B there, not A's far field
    a_only = (xs > x_limit + 2) & (xs < b_lo - 1)
    assert a_only.any() and not ok[a_only].any()  # A's far field and nothing nearer: nodata
    near_a = (xs > -55) & (xs < x_limit - 2)
    assert ok[near_a].all() and np.all(np.abs(val[near_a] - 60) < 1)
    # A's own orthophoto ends where its resolution passes 3 x its best (within a cell or two)
    assert abs(float(xa[oka].max()) - x_limit) < 1.5
    (xs0, val0, ok0), (xa0, _, oka0) = results[0.0]
    far = (xs0 > x_limit + 2) & (xs0 < b_lo - 1)
    assert ok0[far].all() and np.all(np.abs(val0[far] - 60) < 1)  # without a limit A's far field is used
    assert float(xa0[oka0].max()) > b_hi  # ... and reaches past B in its own orthophoto


def test_only_images_that_reach_past_the_limit_are_tested_cell_by_cell(tmp_path):
    """The far-field limit per mosaic cell costs two more projections of every cell: an image whose coarsest ground
    resolution is well within 3 x its best (the vertical B) is not tested, the oblique A (its far field reaches
    past the limit) is, and its footprint is trimmed; the limit is what the test above checks cell by cell."""
    from core.ortho.block import UNLIMITED_MARGIN, _limit_resolution
    from core.ortho.visibility import camera_footprint, resolution_limited

    cams, _dsm, _crs, offset = _flat_pair(str(tmp_path))
    fps = [camera_footprint(c, offset, 100.0, 100.0) for c in cams]
    out_c, out_f = _limit_resolution(cams, fps, offset, 100.0, 100.0, 3.0)
    a, b = out_c
    assert a.max_gsd is not None and b.max_gsd is None
    _, best_a, worst_a = resolution_limited(cams[0], offset, fps[0], 100.0, 100.0, 3.0)
    assert worst_a > 3.0 * best_a  # the far field A leaves out
    _, best_b, worst_b = resolution_limited(cams[1], offset, fps[1], 100.0, 100.0, 3.0)
    assert 1.0 <= worst_b / best_b < 3.0 / UNLIMITED_MARGIN  # a vertical: within the margin, nothing to test
    assert out_f[0].bbox[2] < fps[0].bbox[2] - 50  # A's footprint trimmed where it passes the limit


def test_far_field_limit_keeps_the_ground_of_a_vertical_beside_tall_objects(tmp_path):
    """A vertical photo 30 m over flat ground with a 22 m tower (a tree line) beside its footprint: the image
    resolves the tower's top far finer than any ground, and a limit taken from that best would cut all its
    ground.  The best is taken on the ground: the footprint is filled as without a limit."""
    crs, offset, res = syn.CRS, np.array(syn.ORIGIN), 1.0
    dsm = np.full((300, 400), 100.0, np.float32)
    xs0, ys0 = -150.0, 150.0
    dsm[150 - 5:150 + 5, 150 + 25:150 + 35] = 122.0  # local x 25..35, y -5..5: outside the 40 x 30 m footprint
    gt = (xs0 + offset[0], res, 0.0, ys0 + offset[1], 0.0, -res)
    dsm_path = rastermod.write_cog(os.path.join(str(tmp_path), "dsm.tif"), dsm, gt, crs)
    cam = _pinhole()
    c = np.array([0.0, 0.0, 130.0])
    path = os.path.join(str(tmp_path), "V.tif")
    cv2.imwrite(path, np.full((cam.height, cam.width, 3), 200, np.uint8))
    cams = [OrthoCamera("V.tif", path, cam, Pose.from_centre(syn.look_at(c, c - [0, 0, 1.0], np.array([0, 1.0, 0])), c))]
    filled = {}
    for factor in (3.0, 0.0):
        out = str(tmp_path / f"mosaic_{factor:g}.tif")
        build_orthomosaic(cams, crs, offset, OrthoOptions(dsm_path=dsm_path, output=out, gsd_factor=factor,
                                                          blending="none", exposure=False, radiometry=False,
                                                          resolution=0.5))
        xs, _val, ok = _values_along_x(out, offset)
        inside = (xs > -18) & (xs < 18)  # the footprint is x -20..20 m on the line y = 0
        filled[factor] = float(ok[inside].mean())
    assert filled[0.0] == 1.0
    assert filled[3.0] == 1.0, filled


# ---------------------------------------------------------------------------
# the orbit end to end: prepare (sky masks) -> align -> georeference -> DSM -> orthomosaic, against the truth
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def e2e_orbit():
    """The orbit of the end-to-end tests: ``orbit``'s cameras and scene in photos of 320 x 240 (ORBIT_E2E)."""
    return syn.orbit_block(**ORBIT_E2E)


@pytest.fixture(scope="module")
def orbit_run(e2e_orbit, tmp_path_factory):
    """The 16 orbit images (320 x 240) rendered and put through the pipeline with sky masks (as Run pipeline's
    SKY_MASKS): 'Prepare images' masks the sky, the prepared photos are aligned (default options: the fast path,
    then escalation's affine-shape round for the views it leaves out), georeferenced with 5 control points, matched
    (half quality) and mosaicked at the nominal GSD (0.133 m) without the radiometric correction (the vignetting
    and hot-spot fit, not what these tests look at; the exposure gains stay).  31-34 CPU seconds: rendering 10,
    alignment 16-17 (the fast path leaves 5 steep views out, the affine round brings them in), the rest 6-7.

    Measured (2 runs): 16/16 registered, 8 sky masks, the steep views' tie points 36..193 (none in the sky); check
    points (11) xy 0.071 m (0.53 GSD), z 0.068-0.070 m (0.51-0.52 GSD); camera centres RMSE x 0.095-0.098, y
    0.092-0.098, z 0.23-0.25 m, attitude max 0.53-0.56 deg; the true marks reprojected RMS 0.16 px, max 0.64-0.65
    px; 92,000 dense points, none from the sky, |dz| median 0.089-0.092 m; 14 ground marks in the mosaic, RMSE
    0.020-0.025 m (0.15-0.18 GSD).  (The full-size orbit, 480 x 360 photos 40 m high, full quality, 100 CPU s:
    check points xy 0.26, z 0.30 GSD; centres RMSE 0.07 / 0.09 / 0.23 m; 824,000 dense points, |dz| median
    0.046 m; marks 0.20 GSD.)
    """
    import time

    from core.align.options import AlignOptions
    from core.dense.options import DenseOptions
    from core.pipeline import Control, PipelineOptions, run_pipeline

    orbit = e2e_orbit
    root = tmp_path_factory.mktemp("orbit")
    ws = str(root / "ws")
    t0, c0 = time.time(), os.times()
    orbit.render(str(root / "photos"))
    render, c1 = time.time() - t0, os.times()
    control = orbit.spread_control(5)
    res = run_pipeline(str(root / "photos"), ws, PipelineOptions(
        align=AlignOptions(pairing="exhaustive", num_threads=2), dense=DenseOptions(quality="half"),
        ortho=OrthoOptions(resolution=orbit.gsd, radiometry=False), make_report=False, make_dtm=False,
        sky_masks=True), Control(gcps=orbit.gcp_set(control, noise_px=0.4)))
    prep, aligned, dsm, ortho = res.prepare, res.align, res.dsm, res.ortho
    print(f"\n[orbit] render {render:.0f} s ({c1.user + c1.system - c0.user - c0.system:.1f} CPU s), "
          + ", ".join(f"{k} {v:.0f} s ({res.cpu_seconds.get(k, 0):.1f} CPU s)" for k, v in res.seconds.items())
          + f"; registered {aligned.registered}/{len(orbit.shots)}, {aligned.num_points3d} points, reprojection "
          f"{aligned.mean_reprojection_error:.3f} px; sky masks {len(prep.masks)}; DSM {dsm.points} points; "
          f"mosaic at {ortho.resolution:g} m")
    return dict(ws=ws, prep=prep, aligned=aligned, geo=res.georef, dsm=dsm, ortho=ortho, control=control)


@pytest.mark.slow
def test_orbit_sky_masks_before_alignment(e2e_orbit, orbit_run):
    orbit = e2e_orbit
    prep = orbit_run["prep"]
    steep = sorted(n for n, t in orbit.tilts.items() if t == 65.0)
    assert sorted(os.path.basename(m)[:-4] for m in prep.masks) == steep
    for m in prep.masks:
        name = os.path.basename(m)[:-4]
        assert not (read_keep(m, orbit.camera.width, orbit.camera.height) & orbit.sky_mask(name)).any(), name


@pytest.mark.slow
def test_orbit_every_camera_registered_and_no_sky_tie_point(e2e_orbit, orbit_run):
    from core.align.stage import load_model

    orbit = e2e_orbit
    assert orbit_run["aligned"].registered == len(orbit.shots)
    esc = orbit_run["aligned"].escalation  # where the fast path left views out, the affine round brought them in
    assert esc is None or any(r["kind"] == "affine" and r["kept"] for r in esc["rounds"]), esc
    rec = load_model(orbit_run["ws"])
    # the steep views keep tie points on the ground, up to the hazy band below the horizon: 50 in photos of 480 x 360,
    # as many per pixel in these (22 in 320 x 240)
    min_ties = round(50 * orbit.camera.width * orbit.camera.height / (480 * 360))
    n_kp = n_tie = 0
    steep_ties = {}
    for im in rec.images.values():
        xy = np.array([p.xy for p in im.points2D])
        tie = np.array([p.has_point3D() for p in im.points2D])
        n_kp += len(xy)
        n_tie += int(tie.sum())
        in_sky = orbit.in_sky(im.name, xy)
        assert not in_sky.any(), f"{im.name}: {int(in_sky.sum())} keypoints in the sky"
        if orbit.tilts[im.name] == 65.0:
            steep_ties[im.name] = int(tie.sum())
    print(f"\n{n_kp} keypoints, {n_tie} observations of tie points, none in the sky; the steep views' tie points "
          f"{min(steep_ties.values())}..{max(steep_ties.values())}")
    assert min(steep_ties.values()) >= min_ties, steep_ties


@pytest.mark.slow
def test_orbit_poses_within_the_nadir_tolerances(e2e_orbit, orbit_run):
    """As the vertical block's end-to-end test (tests/test_georef_synthetic.py): 5 control points, check points
    within 1 GSD (xy) and 1.5 GSD (z), GSD the nominal 26.7 m / 200 px = 0.133 m (the finest these obliques see);
    the camera centres and attitudes against the truth as well."""
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    orbit = e2e_orbit
    geo = orbit_run["geo"]
    gsd = orbit.gsd
    f = geo.figures
    print(f"\ncheck points: n={f['CHECK_N']} xy {f['CHECK_RMSE_XY']:.3f} m ({f['CHECK_RMSE_XY'] / gsd:.2f} GSD), "
          f"z {f['CHECK_RMSE_Z']:.3f} m ({f['CHECK_RMSE_Z'] / gsd:.2f} GSD)")
    assert f["CHECK_N"] >= 5
    assert f["CHECK_RMSE_XY"] <= 1.0 * gsd and f["CHECK_RMSE_Z"] <= 1.5 * gsd
    rec, transform = Layout(Workspace.open(orbit_run["ws"])).load_georef_model()
    offset = transform.offset
    err = np.array([np.asarray(im.projection_center()) + offset - syn.ORIGIN - orbit.shot(im.name).centre
                    for im in rec.images.values()])
    rmse = np.sqrt(np.mean(err ** 2, axis=0))
    rot = [math.degrees(math.acos(np.clip((np.trace(np.asarray(im.cam_from_world().rotation.matrix())
                                                    @ orbit.shot(im.name).rotation.T) - 1) / 2, -1, 1)))
           for im in rec.images.values()]
    print(f"camera centres: RMSE x {rmse[0]:.3f} y {rmse[1]:.3f} z {rmse[2]:.3f} m; attitude max {max(rot):.3f} deg")
    # the true ground marks through the adjusted cameras (pose and the intrinsics refined with it: an attitude
    # off by a few tenths of a degree comes with a principal point that makes up for it) land on their pixels
    res_px = []
    for im in rec.images.values():
        cam = Intrinsics.from_pycolmap(rec.cameras[im.camera_id])
        m = np.asarray(im.cam_from_world().matrix())
        for p in orbit.gcps:
            if im.name in p.observations:
                px, _ = cam.project((m[:, :3] @ (p.world - offset) + m[:, 3])[None])
                res_px.append(np.linalg.norm(px[0] - p.observations[im.name]))
    res_px = np.array(res_px)
    print(f"true marks reprojected: {len(res_px)} observations, RMS {np.sqrt(np.mean(res_px ** 2)):.3f} px, "
          f"max {res_px.max():.3f} px")
    # the centres lie 38-63 m from the site and their height trades off against the focal length: 4 GSD (0.53 m)
    # is 0.8-1.4 % of that distance
    assert np.hypot(rmse[0], rmse[1]) <= 2.0 * gsd and float(np.linalg.norm(rmse)) <= 4.0 * gsd
    assert np.sqrt(np.mean(res_px ** 2)) <= 1.0 and res_px.max() <= 3.0


@pytest.mark.slow
def test_orbit_no_dense_point_from_the_sky(e2e_orbit, orbit_run):
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    orbit = e2e_orbit

    lay = Layout(Workspace.open(orbit_run["ws"]))
    rec, transform = lay.load_georef_model()
    shift = transform.offset - syn.ORIGIN  # georef local -> synthetic local
    fused = os.path.join(lay.dense_dir, "fused")
    total, near = 0, []
    for f in os.listdir(fused):
        image_id = int(os.path.splitext(f)[0])
        with np.load(os.path.join(fused, f)) as d:
            xyz = d["xyz"].astype(float) + shift
        shot = orbit.shot(rec.images[image_id].name)
        ray = xyz - shot.centre
        elev = np.degrees(np.arcsin(ray[:, 2] / np.linalg.norm(ray, axis=1)))
        assert elev.max() < -0.5, f"{shot.name}: a dense point {elev.max():.2f} degrees from the horizon"
        total += len(xyz)
        near.append(np.abs(xyz[:, 2] - orbit.scene.height_at(xyz[:, 0], xyz[:, 1])))
    dz = np.concatenate(near)
    print(f"\n{total} dense points, none from the sky; |dz| median {np.median(dz):.3f} m, 95 % {np.percentile(dz, 95):.3f} m")
    assert total > 20000
    assert np.median(dz) < orbit.gsd


def _mark_shift(orbit, arr, gt, xw, yw, n=32):
    """(dx, dy, response) in cells of the mosaic at world (xw, yw) against the scene's true orthoimage (phase
    correlation of n x n cells, as tests/test_ortho.py measures them); None near nodata."""
    c, r = int((xw - gt[0]) / gt[1]), int((yw - gt[3]) / gt[5])
    r0, c0 = r - n // 2, c - n // 2
    if r0 < 0 or c0 < 0 or r0 + n > arr.shape[1] or c0 + n > arr.shape[2] or (arr[-1, r0:r0 + n, c0:c0 + n] == 0).mean() > 0.05:
        return None
    xs = gt[0] + (c0 + np.arange(n) + 0.5) * gt[1] - syn.ORIGIN[0]
    ys = gt[3] + (r0 + np.arange(n) + 0.5) * gt[5] - syn.ORIGIN[1]
    x, y = np.meshgrid(xs, ys)
    truth = syn._sample(orbit.scene.texture_raster(), *orbit.scene.raster_coords(x, y, orbit.scene.texture_res))
    grey = arr[:3, r0:r0 + n, c0:c0 + n].mean(axis=0)
    win = cv2.createHanningWindow((n, n), cv2.CV_64F)
    (dx, dy), resp = cv2.phaseCorrelate(truth.astype(np.float64), grey.astype(np.float64), win)
    return dx, dy, resp


@pytest.mark.slow
def test_orbit_mosaic_ground_marks_within_one_and_a_half_gsd(e2e_orbit, orbit_run):
    orbit = e2e_orbit
    ortho = orbit_run["ortho"]
    ds = gdal.Open(ortho.orthomosaic)
    arr = ds.ReadAsArray().astype(np.float32)
    gt = ds.GetGeoTransform()
    marks = [_mark_shift(orbit, arr, gt, *p.world[:2]) for p in orbit.gcps if p.kind == "ground"]
    marks = np.array([m for m in marks if m and m[2] > 0.2])
    assert len(marks) >= 8, marks
    rmse = float(np.sqrt(np.mean(marks[:, 0] ** 2 + marks[:, 1] ** 2))) * gt[1]
    print(f"\nground marks: {len(marks)}, RMSE {rmse:.3f} m = {rmse / orbit.gsd:.2f} GSD (cells of {gt[1]:g} m)")
    assert rmse <= 1.5 * orbit.gsd
