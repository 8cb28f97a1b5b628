"""The first pass's features chosen from the photos' texture and size (core.align.firstpass, issue 33 item 2):
faint periodic texture at 10 megapixels gets a richer first pass than textured photos of the same size, which keep
the fast path's default; the choice is recorded and keys the database."""
import json
import math
import os

import cv2
import numpy as np
import pycolmap
import pytest

from core.align import firstpass as fp
from core.align.features import database_key, default_settings
from core.align.options import FAINT_MIN_FEATURES, FAINT_PEAK_THRESHOLD, PROBE_GRID, AlignOptions
from core.io.images import CameraGroup, ImageInfo

W, H = 3600, 2700  # the 9.7 MP photos
SIFT_PEAK_THRESHOLD = pycolmap.FeatureExtractionOptions().sift.peak_threshold


def _textured(seed: int, w: int = W, h: int = H) -> np.ndarray:
    """Blobs at several scales (a site: stones, vegetation, paths): SIFT finds features everywhere."""
    rng = np.random.default_rng(seed)
    img = np.zeros((h, w), np.float32)
    for cell, amp in ((160, 40.0), (40, 30.0), (10, 20.0)):
        small = rng.normal(0.0, 1.0, (h // cell + 2, w // cell + 2)).astype(np.float32)
        img += amp * cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
    return np.clip(128.0 + img, 0, 255).astype(np.uint8)


def _faint(seed: int, w: int = W, h: int = H, amplitude: float = 2.5) -> np.ndarray:
    """A ploughed field at low contrast: furrows 15 px apart at 30 degrees to the frame, a faint soil grain and
    sensor noise (as tests/lowtexture_scene.py's fields, at a fraction of the cost)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    a = math.radians(30.0)
    furrows = amplitude * np.sin(2.0 * math.pi * (x * math.sin(a) - y * math.cos(a)) / 15.0)
    grain = cv2.resize(rng.normal(0.0, 1.0, (h // 6, w // 6)).astype(np.float32), (w, h),
                       interpolation=cv2.INTER_CUBIC)
    img = 120.0 + furrows + 1.0 * grain + rng.normal(0.0, 1.5, (h, w)).astype(np.float32)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


def _photos(folder, frames):
    """JPEGs of ``frames`` in ``folder`` as the alignment sees them (ImageInfo)."""
    os.makedirs(folder, exist_ok=True)
    infos = []
    for k, img in enumerate(frames):
        path = os.path.join(folder, f"P{k:02d}.jpg")
        assert cv2.imwrite(path, img, [cv2.IMWRITE_JPEG_QUALITY, 92])
        infos.append(ImageInfo(os.path.basename(path), path, img.shape[1], img.shape[0], 1, "uint8"))
    return infos


@pytest.fixture(scope="module")
def textured_photos(tmp_path_factory):
    return _photos(str(tmp_path_factory.mktemp("textured")), [_textured(s) for s in range(3)])


@pytest.fixture(scope="module")
def faint_photos(tmp_path_factory):
    return _photos(str(tmp_path_factory.mktemp("faint")), [_faint(s) for s in range(3)])


def test_textured_photos_keep_the_fast_paths_default(textured_photos):
    first = fp.choose_first_pass(pycolmap, textured_photos, AlignOptions(), W, H)
    assert first.level == fp.DEFAULT
    assert first.settings == default_settings(AlignOptions(), W, H)
    # today's default: a 2-megapixel copy, at most 4,096 features, SIFT's own threshold
    assert first.settings.image_size == int(W * math.sqrt(2.0 / (W * H / 1e6)))
    assert first.settings.max_features <= 4096 and first.settings.peak_threshold is None
    assert first.key() is None  # the database key of a textured set is what it was
    assert all(not p.starved and p.level == fp.DEFAULT for p in first.probe)


def test_faint_periodic_texture_gets_a_richer_first_pass(faint_photos, textured_photos):
    faint = fp.choose_first_pass(pycolmap, faint_photos, AlignOptions(), W, H)
    textured = fp.choose_first_pass(pycolmap, textured_photos, AlignOptions(), W, H)
    assert faint.level in (fp.FAINT, fp.FAINT_FINE)
    assert faint.settings.max_features >= FAINT_MIN_FEATURES > textured.settings.max_features
    assert faint.settings.image_size >= textured.settings.image_size
    assert faint.settings.peak_threshold == pytest.approx(FAINT_PEAK_THRESHOLD)
    assert FAINT_PEAK_THRESHOLD < SIFT_PEAK_THRESHOLD
    default = [p for p in faint.probe if p.level == fp.DEFAULT]
    assert default and all(p.starved for p in default)  # why: the default starves on these fields
    record = json.loads(json.dumps(faint.to_dict()))
    assert record["level"] == faint.level and "starved" in record["reason"] and record["probe"]
    assert "first pass: faint" in faint.log_line() and "probe" in faint.log_line()


def test_the_users_settings_are_not_probed(faint_photos):
    for options in (AlignOptions(max_features=3000), AlignOptions(max_image_size=2000),
                    AlignOptions(first_octave=0), AlignOptions(texture_probe=False)):
        first = fp.choose_first_pass(pycolmap, faint_photos, options, W, H)
        assert first.level == fp.DEFAULT and not first.probe
        assert first.settings == default_settings(options, W, H)


def test_the_ladder_scales_with_the_photo():
    big = fp.levels(default_settings(AlignOptions(), W, H), W, H)
    assert [n for n, _ in big] == [fp.DEFAULT, fp.FAINT, fp.FAINT_FINE]
    assert big[2][1].image_size == min(W, 2 * big[0][1].image_size) and big[2][1].first_octave == 0
    small = fp.levels(default_settings(AlignOptions(), 640, 480), 640, 480)  # already upsampled at its own size
    assert [n for n, _ in small] == [fp.DEFAULT, fp.FAINT]
    mid = fp.levels(default_settings(AlignOptions(), 1200, 900), 1200, 900)  # its own size: upsampled last
    assert mid[-1][0] == fp.FAINT_FINE and mid[-1][1].image_size == 1200 and mid[-1][1].first_octave == -1


def test_probe_photos_are_spread_and_the_same_each_run():
    names = [f"P{k:02d}" for k in range(40)]
    picked = fp.probe_photos(names)
    assert picked == fp.probe_photos(names) and len(picked) == 6 and picked[0] == "P00" and picked[-1] == "P39"
    assert fp.probe_order(picked)[:3] == ["P00", picked[3], "P39"]  # ends and middle first
    assert fp.probe_photos(names[:4]) == names[:4]


def test_the_neighbour_is_the_nearest_by_gps_else_the_next_in_file_order():
    names = ["a", "b", "c", "d"]
    assert fp.neighbours(names, ["a", "d"]) == {"a": "b", "d": "c"}
    far = {"a": (0.0, 0.0), "b": (500.0, 0.0), "c": (10.0, 5.0), "d": (490.0, 3.0)}  # a strip's ends, side by side
    assert fp.neighbours(names, ["a", "d"], far) == {"a": "c", "d": "b"}
    assert fp.neighbours(names, ["a"], {"a": (0.0, 0.0)}) == {"a": "b"}  # not every photo located: file order
    infos = [ImageInfo(n, n, 10, 10, 1, "uint8", gps=(16.0 + 0.001 * k, 52.0, 100.0)) for k, n in enumerate(names)]
    xy = fp.gps_positions(infos)
    assert xy["a"] == (0.0, 0.0) and xy["b"][0] == pytest.approx(111320 * 0.001 * math.cos(math.radians(52)))


def test_coverage_and_the_decision():
    w, h = 800, 600
    rng = np.random.default_rng(1)
    spread = np.column_stack([rng.uniform(0, w, 2000), rng.uniform(0, h, 2000)])
    corner = np.column_stack([rng.uniform(0, w / 4, 2000), rng.uniform(0, h / 4, 2000)])
    assert fp.coverage(spread, w, h) > 0.9
    assert fp.coverage(corner, w, h) <= (PROBE_GRID / 4 + 1) * (6 / 4 + 1) / (PROBE_GRID * 6)
    assert fp.coverage(np.zeros((0, 2)), w, h) == 0.0

    def r(found, cov=1.0):
        return fp.ProbeResult("x", "default", found, 4096, cov)

    assert fp.decide([r(4000), r(4000), r(4000)], 6) is True  # the first half rich: textured, stop
    assert fp.decide([r(100), r(100)], 6) is False  # two of six starved: more than a fifth
    assert fp.decide([r(4000), r(100)], 6) is None  # not yet known
    assert fp.decide([r(4000), r(4000, 0.2)], 6) is None  # features in one corner only: starved
    assert fp.decide([r(4000)] * 5 + [r(100)], 6) is True
    sparse = fp.ProbeResult("x", "default", 200, 4096, 0.9, "y", 20)  # few features, few verified matches
    assert sparse.starved
    sparse.matches = 2 * 30  # few features, but they match its neighbour (twice COLMAP's registration minimum)
    assert not sparse.starved


def test_the_database_key_follows_the_choice(tmp_path):
    g = CameraGroup(key="k", camera_id=1, make="", model="", width=W, height=H, focal_px=3000.0,
                    focal_source="default", images=["a.jpg", "b.jpg"])
    base = default_settings(AlignOptions(), W, H)
    default = fp.FirstPass(base, fp.DEFAULT, "")
    richer = fp.FirstPass(fp.levels(base, W, H)[1][1], fp.FAINT, "")
    k0 = database_key([g], AlignOptions(), str(tmp_path))
    assert database_key([g], AlignOptions(), str(tmp_path), first_pass=default.key()) == k0  # earlier workspaces
    assert database_key([g], AlignOptions(), str(tmp_path), first_pass=richer.key()) != k0  # extracted afresh


E2E_CONTRAST = 0.3  # tests/lowtexture_scene.py's fields this faint: the fast path leaves a photo out (9/10)


@pytest.fixture(scope="module")
def faint_block():
    from tests import lowtexture_scene as lt
    from tests.workspaces import rendered_once

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    block = lt.small_block(E2E_CONTRAST)
    return block, rendered_once(block, os.path.join(root, "build", "test-cache", f"align-farmland-{E2E_CONTRAST:g}"))


@pytest.mark.slow
def test_the_first_pass_registers_a_faint_block_without_escalation(faint_block, tmp_path):
    """The small farmland block (10 photos of 640 x 480, furrows at contrast 0.3): with the default features the
    first pass leaves a photo out; the probe's choice registers every photo without escalation."""
    from core.align.stage import align

    block, images = faint_block
    focal = block.camera.fx
    before = align(images, str(tmp_path / "default"), AlignOptions(focal_px=focal, escalate=False, texture_probe=False,
                                                                   num_threads=2))
    assert before.registered < len(block.shots) or before.other_components  # the case is hard for the default
    r = align(images, str(tmp_path / "ws"), AlignOptions(focal_px=focal, escalate=False, num_threads=2))
    assert r.registered == len(block.shots) and not r.other_components and r.mean_reprojection_error < 1.0
    record = json.load(open(tmp_path / "ws" / "sfm" / "alignment.json"))
    assert record["first_pass"]["level"] == fp.FAINT and record["escalation"] is None
    assert record["first_pass"]["settings"]["max_features"] >= FAINT_MIN_FEATURES
    manifest = json.load(open(tmp_path / "ws" / "workspace.json"))
    assert manifest["stages"]["align"]["results"]["first_pass"] == fp.FAINT


@pytest.mark.slow
def test_a_large_blocks_escalation_continues_the_block(faint_block, tmp_path, monkeypatch):
    """The escalation of a large block by extension (issue 33), on the small farmland block with the size limit
    lowered: the photo the fast path leaves out is extracted again with its neighbours and registered into the
    main block continued from where the fast path left it, not mapped afresh, and the poses still fit the truth."""
    import core.align.escalation as esc
    from core.align.stage import align

    block, images = faint_block
    monkeypatch.setattr(esc, "EXTEND_MIN_IMAGES", 5)
    r = align(images, str(tmp_path / "ws"), AlignOptions(focal_px=block.camera.fx, texture_probe=False, num_threads=2))
    assert r.registered == len(block.shots) and not r.other_components and r.mean_reprojection_error < 1.0
    rounds = json.load(open(tmp_path / "ws" / "sfm" / "alignment.json"))["escalation"]["rounds"]
    assert rounds[0]["extended"] and rounds[0]["kept"] and rounds[0]["registered_after"] == len(block.shots)
    assert len(rounds[0]["re_extracted"]) < len(block.shots)  # the left-out photo and its neighbours, not all
    import pycolmap

    rec = pycolmap.Reconstruction(str(tmp_path / "ws" / "sfm" / "model"))
    est = np.array([rec.find_image_with_name(n).projection_center() for n in block.names])
    true = np.array([block.shot(n).centre for n in block.names])
    # a similarity from the model to the truth: the camera centres within a few per cent of the block's span
    ce, ct = est - est.mean(0), true - true.mean(0)
    u, sv, vt = np.linalg.svd(ce.T @ ct)
    d = np.sign(np.linalg.det(u @ vt))
    rot = u @ np.diag([1, 1, d]) @ vt
    scale = (sv * [1, 1, d]).sum() / (ce ** 2).sum()
    resid = np.linalg.norm(scale * ce @ rot - ct, axis=1)
    assert resid.max() < 0.02 * np.ptp(true[:, :2], axis=0).max()
