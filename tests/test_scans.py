"""Scanned historical film (core.scans): synthetic scans built from real photos, exact truth.

Each synthetic scan is a Toledo photo printed on a "film" (mm, x right, y up,
origin at the principal point): a dark film border, eight fiducial marks
(crosses in the corners, dots in circles at the sides), a data strip with
text, then "scanned": placed on a light scanner bed at a rotation of a few
degrees, with film shrinkage, a little shear, a smooth non-linear warp and
grain, at different scan resolutions and sizes.  The forward map film -> scan
pixel is known exactly, so every fiducial's true scan position is known.
"""
import json
import math
import os

import numpy as np
import pytest

from tests.conftest import SAMPLE, TOLEDO_STRIP

cv2 = pytest.importorskip("cv2")

FILM_W, FILM_H = 140.0, 110.0  # film piece, mm
AREA_W, AREA_H = 120.0, 90.0  # picture area, mm
PP = (0.12, -0.08)  # principal point relative to the fiducial centre, mm
MARKS = {  # slot -> (kind, x, y) in mm relative to the fiducial centre
    "TL": ("cross", -65.0, 50.0), "TR": ("cross", 65.0, 50.0),
    "BR": ("cross", 65.0, -50.0), "BL": ("cross", -65.0, -50.0),
    "T": ("ring_dot", 0.0, 50.5), "B": ("ring_dot", 0.0, -50.5),
    "L": ("ring_dot", -65.5, 0.0), "R": ("ring_dot", 65.5, 0.0),
}
MARK_MM = 4.0
STRIP = (-58.0, -54.0, -8.0, -46.0)  # data strip x0, y0, x1, y1 (mm, fiducial-centre system)
RASTER = 12.0  # film raster, pixels per mm
# the Toledo FC300X photos have a focal length of about 693 px over 1200 px; printed 120 mm wide:
FOCAL_MM = 693.375 * AREA_W / 1200.0


def calibration_text(pp=PP, slots=tuple(MARKS)):
    """A calibration certificate: fiducial coordinates (mm) in the fiducial-centre system, plus the PP."""
    lines = ["# camera calibration certificate (synthetic)", "id x_mm y_mm"]
    for i, s in enumerate(slots, start=1):
        _, x, y = MARKS[s]
        lines.append(f"{i} {x:.3f} {y:.3f}")
    lines.append(f"PP {pp[0]:.3f} {pp[1]:.3f}")
    lines.append(f"focal {FOCAL_MM:.3f}")
    return "\n".join(lines) + "\n"


def _film(photo_path, frame_no, slots):
    """The film raster (float32 0..1, y down) and the mapping mm -> raster pixel (OpenCV centres)."""
    from core.prepare.scans import mark_coverage

    w, h = int(round(FILM_W * RASTER)), int(round(FILM_H * RASTER))
    rng = np.random.default_rng(frame_no)
    film = np.full((h, w), 0.07, np.float32) + rng.normal(0, 0.01, (h, w)).astype(np.float32)
    photo = cv2.imread(photo_path, cv2.IMREAD_GRAYSCALE).astype(np.float32) / 255.0
    aw, ah = int(round(AREA_W * RASTER)), int(round(AREA_H * RASTER))
    photo = cv2.resize(photo, (aw, ah), interpolation=cv2.INTER_CUBIC)
    x0, y0 = (w - aw) // 2, (h - ah) // 2
    film[y0:y0 + ah, x0:x0 + aw] = 0.1 + 0.85 * np.clip(photo, 0, 1)

    def to_raster(x, y):
        return (x + FILM_W / 2) * RASTER - 0.5, (FILM_H / 2 - y) * RASTER - 0.5

    # data strip: frame number, clock, altimeter
    sx0, sy0 = to_raster(STRIP[0], STRIP[3])
    sx1, sy1 = to_raster(STRIP[2], STRIP[1])
    text = f"No {frame_no:04d}  14:{20 + frame_no:02d}:07  ALT 1450"
    strip = np.zeros((int(sy1 - sy0), int(sx1 - sx0)), np.uint8)
    cv2.putText(strip, text, (4, int(0.75 * strip.shape[0])), cv2.FONT_HERSHEY_SIMPLEX,
                strip.shape[0] / 40.0, 255, 2, cv2.LINE_AA)
    film[int(sy0):int(sy0) + strip.shape[0], int(sx0):int(sx0) + strip.shape[1]] += strip.astype(np.float32) / 255 * 0.8
    # marks, analytic with 4 x 4 supersampling, bright on the dark border
    half = int(MARK_MM * RASTER)
    off = (np.arange(4) + 0.5) / 4 - 0.5
    for s in slots:
        kind, mx, my = MARKS[s]
        cu, cv_ = to_raster(mx, my)
        iu, iv = int(round(cu)), int(round(cv_))
        yy, xx = np.mgrid[iv - half:iv + half + 1, iu - half:iu + half + 1].astype(np.float64)
        cov = np.zeros(xx.shape)
        for oy in off:
            for ox in off:
                cov += mark_coverage(kind, (xx + ox - cu) / RASTER, (yy + oy - cv_) / RASTER, MARK_MM)
        cov /= 16
        patch = film[iv - half:iv + half + 1, iu - half:iu + half + 1]
        patch[:] = patch * (1 - cov) + 0.92 * cov
    return np.clip(film, 0, 1), to_raster


def make_scan(photo_path, out_path, frame_no, res_px_mm, angle_deg, offset=(0.0, 0.0), margin_mm=(6.0, 5.0),
              shrink=(0.9985, 0.9972), shear=0.0006, warp_px=0.25, noise=0.012, slots=tuple(MARKS)):
    """Write a synthetic grey 8-bit TIFF scan; returns the true fiducial positions (scan px, corner convention)."""
    film, to_raster = _film(photo_path, frame_no, slots)
    th = math.radians(angle_deg)
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])  # y down: clockwise on screen
    lin = res_px_mm * rot @ np.array([[shrink[0], shear], [0.0, shrink[1]]]) @ np.diag([1.0, -1.0])
    sw = int(math.ceil((FILM_W + 2 * margin_mm[0]) * res_px_mm))
    sh = int(math.ceil((FILM_H + 2 * margin_mm[1]) * res_px_mm))
    t = np.array([sw / 2 + offset[0], sh / 2 + offset[1]])
    inv = np.linalg.inv(lin)

    def warp(p):  # smooth scanner non-linearity, scan pixels
        return np.stack([warp_px * np.sin(2 * np.pi * p[..., 1] / 350.0),
                         warp_px * np.cos(2 * np.pi * p[..., 0] / 420.0)], axis=-1)

    def forward(x):  # film mm (fiducial-centre system) -> scan pixel (corner convention)
        g = x @ lin.T + t
        return g + warp(g)

    yy, xx = np.mgrid[0:sh, 0:sw].astype(np.float64)
    p = np.stack([xx + 0.5, yy + 0.5], axis=-1)
    x = (p - t) @ inv.T
    for _ in range(4):
        x = (p - warp(x @ lin.T + t) - t) @ inv.T
    u, v = to_raster(x[..., 0], x[..., 1])
    sigma = 0.5 * math.sqrt(max((RASTER / res_px_mm) ** 2 - 1, 0))
    src = cv2.GaussianBlur(film, (0, 0), sigma) if sigma > 0 else film
    scan = cv2.remap(src, u.astype(np.float32), v.astype(np.float32), cv2.INTER_LINEAR,
                     borderMode=cv2.BORDER_CONSTANT, borderValue=0.78)
    scan += np.random.default_rng(100 + frame_no).normal(0, noise, scan.shape).astype(np.float32)
    cv2.imwrite(out_path, np.clip(scan * 255 + 0.5, 0, 255).astype(np.uint8))
    truth = {s: forward(np.array([MARKS[s][1], MARKS[s][2]])) for s in slots}
    return truth, forward


# five frames of the Toledo strip, scanned at different resolutions, sizes and rotations
SCAN_SETUP = [  # photo, resolution px/mm, rotation deg, offset px
    (TOLEDO_STRIP[0], 7.4, 2.6, (12.0, -7.0)),
    (TOLEDO_STRIP[1], 8.1, -1.9, (-9.0, 5.0)),
    (TOLEDO_STRIP[2], 6.9, 3.4, (4.0, 11.0)),
    (TOLEDO_STRIP[3], 7.8, -3.1, (-14.0, -3.0)),
    (TOLEDO_STRIP[4], 7.1, 1.2, (0.0, 0.0)),
]


@pytest.fixture(scope="module")
def synthetic_scans(tmp_path_factory):
    d = tmp_path_factory.mktemp("scans") / "scans ä"
    d.mkdir()
    truth = {}
    for i, (photo, res, ang, off) in enumerate(SCAN_SETUP, start=1):
        name = f"frame_{i:03d}.tif"
        truth[name], _ = make_scan(os.path.join(SAMPLE, "images", photo), str(d / name), i, res, ang, off)
    return str(d), truth


# ---------------------------------------------------------------------------
# unit tests
# ---------------------------------------------------------------------------

def test_parse_fiducial_coordinates_assigns_slots_and_pp(tmp_path):
    from core.prepare.options import ScanError
    from core.prepare.scans import parse_fiducial_coordinates

    cal = parse_fiducial_coordinates(calibration_text())
    assert set(cal.points) == set(MARKS)
    assert cal.points["TR"] == pytest.approx((65.0 - PP[0], 50.0 - PP[1]))
    assert cal.focal_length_mm == pytest.approx(FOCAL_MM, abs=1e-3)
    f = tmp_path / "fid.csv"
    f.write_text("id,x,y\nF1,-106.0,106.0\nF2,106.0,106.0\nF3,106.0,-106.0\nF4,-106.0,-106.0\n")
    cal = parse_fiducial_coordinates(str(f))
    assert cal.ids == {"TL": "F1", "TR": "F2", "BR": "F3", "BL": "F4"}
    with pytest.raises(ScanError, match="at least 3"):
        parse_fiducial_coordinates("1 0 0\n2 1 1\n")
    with pytest.raises(ScanError, match="line 2"):
        parse_fiducial_coordinates("1 0 0\n2 abc 1 4 5\n3 1 1\n")


def test_symmetric_refinement_is_sub_pixel():
    from core.prepare.scans import refine_symmetric, render_mark

    rng = np.random.default_rng(3)
    for kind in ("cross", "ring_dot", "dot"):
        for _ in range(3):
            cx, cy = 40 + rng.uniform(-1, 1), 38 + rng.uniform(-1, 1)
            big = np.zeros((80, 80), np.float32)
            m = render_mark(kind, 24.0, angle_deg=2.0, canvas=41)
            # place the mark at a sub-pixel position by warping
            mat = np.float32([[1, 0, cx - 20], [0, 1, cy - 20]])
            big = cv2.warpAffine(m, mat, (80, 80), flags=cv2.INTER_CUBIC) + rng.normal(0, 0.03, (80, 80)).astype(np.float32)
            x, y, ok = refine_symmetric(big, round(cx) + 1.0, round(cy) - 1.0, 24.0)
            assert ok
            assert math.hypot(x - cx, y - cy) < 0.05, (kind, x - cx, y - cy)


@pytest.fixture(scope="module")
def prepared(synthetic_scans, tmp_path_factory):
    """The whole "prepare" stage on the five scans, with the calibration certificate."""
    from core.prepare.options import PrepareOptions, ScanOptions
    from core.prepare.stage import prepare_images_workspace

    folder, truth = synthetic_scans
    root = tmp_path_factory.mktemp("prepared")
    opts = PrepareOptions(scanned_film=True, scan=ScanOptions(fiducial_coordinates=calibration_text()),
                          output_dir=str(root / "prepared images"))
    result = prepare_images_workspace(folder, str(root / "ws"), opts)
    return result, truth


def test_recovered_fiducials_within_half_a_pixel(prepared):
    result, truth = prepared
    doc = json.load(open(result.scans_path))
    errors = []
    for scan in doc["scans"]:
        found = {f["slot"]: f for f in scan["fiducials"]}
        assert set(found) == set(MARKS), (scan["name"], sorted(found))
        for s, f in found.items():
            assert f["kind"] == MARKS[s][0], (scan["name"], s, f["kind"])
            t = truth[scan["name"]][s]
            errors.append(math.hypot(f["x"] - t[0], f["y"] - t[1]))
        assert scan["rms_px"] < 0.5 and not scan["dropped"]
    errors = np.array(errors)
    print(f"\nfiducial errors over {len(errors)} marks: mean {errors.mean():.3f} px, max {errors.max():.3f} px")
    assert errors.max() <= 0.5


def test_prepared_scans_share_one_frame_centred_on_the_principal_point(prepared):
    """Identical sizes; a mark re-found in a prepared image sits where the calibrated frame puts it."""
    from core.io.images import read_image_info
    from core.prepare.options import ScanOptions
    from core.prepare.scans import detect_fiducials

    result, _ = prepared
    io = result.interior_orientation
    names = sorted(n for n in os.listdir(result.prepared_dir) if n.endswith(".tif"))
    assert len(names) == 5
    for n in names:
        info = read_image_info(os.path.join(result.prepared_dir, n))
        assert (info.width, info.height) == (io["width"], io["height"])
        # the interior orientation travels in the file: core.images reads it as the focal prior
        assert info.focal_source == "exif_plane"
        assert info.focal_px == pytest.approx(FOCAL_MM / io["pixel_size_mm"], rel=1e-4)
    assert io["principal_point_px"] == [io["width"] / 2, io["height"] / 2]
    p = io["pixel_size_mm"]
    for n in names[:2]:
        fids, _ = detect_fiducials(os.path.join(result.prepared_dir, n), ScanOptions(),
                                   hints={k: v[0] for k, v in MARKS.items()})
        for f in fids:
            _, mx, my = MARKS[f.slot]
            ex = (mx - PP[0]) / p + io["width"] / 2
            ey = io["height"] / 2 - (my - PP[1]) / p
            assert math.hypot(f.x - ex, f.y - ey) < 0.4, (n, f.slot, f.x - ex, f.y - ey)


def test_masks_hide_border_strip_and_marks(prepared):
    result, _ = prepared
    io = result.interior_orientation
    p = io["pixel_size_mm"]
    w, h = io["width"], io["height"]

    def px(x, y):
        return int((x - PP[0]) / p + w / 2), int(h / 2 - (y - PP[1]) / p)

    assert len(result.masks) == 5
    for path in result.masks:
        assert os.path.dirname(path) == os.path.join(result.workspace, "masks")
        assert path.endswith(".tif.png")  # COLMAP: <image name>.png
        m = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        assert m.shape == (h, w)
        assert set(np.unique(m)) <= {0, 255}
        x, y = px(0.0, 0.0)
        assert m[y - 50:y + 50, x - 50:x + 50].min() == 255  # the picture is used
        x, y = px(-50.0, -50.0)  # the data strip
        assert m[y - 3:y + 3, x - 3:x + 3].max() == 0
        for _, mx, my in MARKS.values():  # every mark
            x, y = px(mx, my)
            assert m[y, x] == 0
        x, y = px(-62.0, 20.0)  # film border left of the picture
        assert m[y, x] == 0
        # the picture area fills most of the mask
        assert 0.75 * (AREA_W * AREA_H) / p ** 2 < (m > 0).sum() <= (AREA_W * AREA_H) / p ** 2


def test_workspace_records_the_prepare_stage(prepared):
    result, _ = prepared
    manifest = json.load(open(os.path.join(result.workspace, "workspace.json")))
    rec = manifest["stages"]["prepare"]
    assert rec["status"] == "done"
    assert rec["outputs"]["scans"] == "scans.json" and len(rec["outputs"]["masks"]) == 5
    assert rec["results"]["interior_orientation"]["focal_length_mm"] == pytest.approx(FOCAL_MM, abs=1e-3)
    doc = json.load(open(result.screening_path))
    assert {q["name"] for q in doc["images"]} == {f"frame_{i:03d}.tif" for i in range(1, 6)}
    assert not os.path.exists(os.path.join(result.workspace, ".partial-masks-prepare"))


def test_colmap_honours_the_masks(prepared, tmp_path):
    """pycolmap extracts no feature where a written mask is black."""
    pycolmap = pytest.importorskip("pycolmap")
    pycolmap.logging.minloglevel = 2
    result, _ = prepared
    name = sorted(n for n in os.listdir(result.prepared_dir) if n.endswith(".tif"))[0]
    db = str(tmp_path / "db.db")
    ro = pycolmap.ImageReaderOptions()
    ro.mask_path = os.path.join(result.workspace, "masks")
    eo = pycolmap.FeatureExtractionOptions()
    eo.sift.max_num_features = 2048
    eo.num_threads = 2
    pycolmap.extract_features(db, result.prepared_dir, image_names=[name], reader_options=ro,
                              extraction_options=eo, device=pycolmap.Device.cpu)
    d = pycolmap.Database.open(db)
    try:
        im = d.read_all_images()[0]
        kp = np.asarray(d.read_keypoints(im.image_id))[:, :2]
    finally:
        d.close()
    m = cv2.imread(os.path.join(result.workspace, "masks", name + ".png"), cv2.IMREAD_GRAYSCALE)
    assert len(kp) > 200
    inside = m[np.clip(kp[:, 1].astype(int), 0, m.shape[0] - 1), np.clip(kp[:, 0].astype(int), 0, m.shape[1] - 1)]
    assert (inside == 255).mean() > 0.99


@pytest.mark.slow
def test_prepared_scans_align(prepared, tmp_path):
    """The prepared set aligns: core.align.stage.align registers all five scans in one block."""
    from core.align.options import AlignOptions
    from core.align.stage import align

    result, _ = prepared
    r = align(result.prepared_dir, str(tmp_path / "ws"), AlignOptions(max_features=2048))
    print(f"\naligned {r.registered}/{r.images_given}, {r.mean_reprojection_error:.3f} px, {r.timings}")
    assert r.registered == 5 and not r.unregistered
    assert r.mean_reprojection_error < 1.0
    cam = r.cameras[0]
    assert (cam["width"], cam["height"]) == (result.interior_orientation["width"], result.interior_orientation["height"])
    assert len(r.cameras) == 1  # identical sizes and interior orientation: one camera for the set


def test_uncalibrated_corner_marks_mean_frame(tmp_path):
    """Four corner crosses, no certificate: the mean frame of the set, in pixels, PP at the fiducial centre."""
    from core.prepare.options import ScanOptions
    from core.prepare.scans import prepare_scans

    folder = tmp_path / "scans"
    folder.mkdir()
    truth, paths = {}, []
    corners = ("TL", "TR", "BR", "BL")
    for i, (photo, res, ang, off) in enumerate(SCAN_SETUP[:3], start=1):
        p = str(folder / f"s{i}.tif")
        truth[f"s{i}.tif"], _ = make_scan(os.path.join(SAMPLE, "images", photo), p, i, res * 0.8, -ang, off,
                                          slots=corners)
        paths.append(p)
    (tmp_path / "out").mkdir()
    (tmp_path / "masks").mkdir()
    res = prepare_scans(paths, str(tmp_path / "out"), str(tmp_path / "masks"), ScanOptions(layout="corners"))
    assert res.units == "px" and not res.calibrated
    assert set(res.frame) == set(corners)
    for s in res.scans:
        for f in s.fiducials:
            t = truth[s.name][f.slot]
            assert math.hypot(f.x - t[0], f.y - t[1]) <= 0.5
    # the frame is upright and centred on the fiducial centre
    fr = res.frame
    assert fr["TL"][0] < 0 < fr["TR"][0] and fr["BL"][1] < 0 < fr["TL"][1]
    assert abs(fr["TL"][1] - fr["TR"][1]) < 0.5 and abs(sum(v[0] for v in fr.values())) < 0.5
    sizes = {cv2.imread(str(tmp_path / "out" / s.prepared_name), cv2.IMREAD_UNCHANGED).shape for s in res.scans}
    assert sizes == {(res.height, res.width)}


def test_too_few_marks_is_a_clear_error(tmp_path):
    from core.prepare.options import ScanError, ScanOptions
    from core.prepare.scans import prepare_scans

    img = os.path.join(SAMPLE, "images", TOLEDO_STRIP[0])  # a photo without any fiducial mark
    with pytest.raises(ScanError, match=TOLEDO_STRIP[0]):
        prepare_scans([img], str(tmp_path), str(tmp_path), ScanOptions(fiducial_type="ring_dot", min_score=0.8))


def test_user_template_of_one_mark(synthetic_scans, tmp_path):
    """A crop of one mark from one scan finds the marks of the others (other resolutions and rotations)."""
    from core.prepare.options import ScanOptions
    from core.prepare.scans import detect_fiducials, load_template

    folder, truth = synthetic_scans
    img = cv2.imread(os.path.join(folder, "frame_001.tif"), cv2.IMREAD_GRAYSCALE)
    x, y = (int(v) for v in truth["frame_001.tif"]["TL"])
    cv2.imwrite(str(tmp_path / "mark.png"), img[y - 22:y + 23, x - 22:x + 23])
    opts = ScanOptions(layout="corners", template_path=str(tmp_path / "mark.png"))
    for name in ("frame_002.tif", "frame_003.tif"):
        fids, _ = detect_fiducials(os.path.join(folder, name), opts, load_template(opts.template_path))
        assert {f.slot for f in fids} == {"TL", "TR", "BR", "BL"}
        for f in fids:
            t = truth[name][f.slot]
            assert math.hypot(f.x - t[0], f.y - t[1]) <= 0.5, (name, f.slot)


def test_processing_prepare_scanned_film(synthetic_scans, qgis_processing, qgis_iface, tmp_path):
    """archaeoortho:prepareimages with SCANNED_FILM, the certificate pasted as text, as QGIS runs it."""
    import shutil

    import archaeoortho
    from qgis import processing

    folder, _ = synthetic_scans
    images = tmp_path / "three scans"
    images.mkdir()
    for n in ("frame_001.tif", "frame_002.tif", "frame_003.tif"):
        shutil.copyfile(os.path.join(folder, n), images / n)
    plugin = archaeoortho.classFactory(qgis_iface)
    plugin.initProcessing()
    try:
        res = processing.run("archaeoortho:prepareimages", {
            "IMAGES": str(images), "WORKSPACE": str(tmp_path / "ws"), "SCANNED_FILM": True,
            "FIDUCIAL_COORDINATES": calibration_text(), "FIDUCIAL_TYPE": 0, "OUTPUT": str(tmp_path / "out"),
        })
    finally:
        plugin.unload()
    assert res["FLAGGED"] == 0
    assert sorted(n for n in os.listdir(res["PREPARED_IMAGES"]) if not n.startswith(".")) == \
        ["frame_001.tif", "frame_002.tif", "frame_003.tif"]
    assert sorted(os.listdir(os.path.join(res["WORKSPACE"], "masks"))) == \
        ["frame_001.tif.png", "frame_002.tif.png", "frame_003.tif.png"]
    doc = json.load(open(os.path.join(res["WORKSPACE"], "scans.json")))
    assert doc["calibrated"] and doc["interior_orientation"]["focal_length_mm"] == pytest.approx(FOCAL_MM, abs=1e-3)


# ---------------------------------------------------------------------------
# a 4-mark camera whose side marks' rings touch the picture (tests/archive_scene.py, side_mm=117)
# ---------------------------------------------------------------------------

CACHE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "build", "test-cache")
CORNERS = ("TL", "TR", "BR", "BL")


@pytest.fixture(scope="module")
def touching_block():
    """Four 1300 px scans of the archive film camera with 4 side marks (cross in a ring) whose rings touch the
    picture: large "dot" templates correlate better inside the picture than the real marks do.  Rendered once
    (about 10 s) and cached under build/test-cache."""
    from tests import archive_scene as arch

    return arch.archive_block("film", 4, seed=1, out_dir=os.path.join(CACHE, f"{arch.VERSION}-film4-fid4-side117"),
                              fiducials=4, side_mm=117, reference=False)


def _calibrated_text(cam, shift=None):
    """The camera's fiducial coordinates as "id x y" lines, PP and focal; ``shift``: (id, dx, dy) mm added."""
    lines = []
    for k, x, y in cam.fiducials_mm:
        if shift and shift[0] == k:
            x, y = x + shift[1], y + shift[2]
        lines.append(f"{k} {x} {y}")
    return "\n".join(lines) + f"\nPP {cam.ppa_mm[0]} {cam.ppa_mm[1]}\nfocal {cam.focal_mm}\n"


def _mark_errors(block, res, ids=None):
    """Distance (scan px) of every used mark from its true place; slot -> certificate id by direction."""
    from core.prepare.scans import parse_fiducial_coordinates

    ids = ids or parse_fiducial_coordinates(_calibrated_text(block.camera)).ids
    out = {}
    for s in res.scans:
        truth = block.fiducials_scan(s.name)
        for f in s.fiducials:
            if f.slot in res.frame:
                t = truth[ids[f.slot]]
                out[(s.name, f.slot)] = math.hypot(f.x - t[0], f.y - t[1])
    return out


def _paths(block, names=None):
    return [os.path.join(block.paths["images"], n) for n in (names or block.names)]


def test_side_marks_touching_the_picture_found_with_calibrated_coordinates(touching_block, tmp_path):
    """The geometry, not the correlation, picks the marks: all four at their true place, the restitution's pixel
    and rotation right, and no warning about a mark (not even about corners this camera does not have)."""
    from core.prepare.options import ScanOptions
    from core.prepare.scans import prepare_scans

    block = touching_block
    res = prepare_scans(_paths(block), str(tmp_path), str(tmp_path),
                        ScanOptions(fiducial_coordinates=_calibrated_text(block.camera), scan_pixel_size_mm=0.2))
    errors = _mark_errors(block, res)
    assert len(errors) == 16 and max(errors.values()) < 0.5, errors
    assert not res.left_out and len(res.scans) == 4
    for s in res.scans:
        assert {f.slot for f in s.fiducials} == {"T", "R", "B", "L"}, s.name
        assert s.rms_px < 0.3 and s.scan_pixel_size == pytest.approx(0.2, rel=2e-3)
        assert s.rotation_deg == pytest.approx(block.frame(s.name).scan.rotation_deg, abs=0.02)
    assert res.pixel_size == pytest.approx(0.2, rel=2e-3)
    assert not [w for w in res.warnings if "fiducial" in w], res.warnings
    # the marks' size (masks, margin) is the 4 mm ring's, not the picture it touches (was 116 px, 23 mm)
    mark_px = block.camera.mark_mm / block.camera.pixel_mm
    assert all(f.size_px <= 2.0 * mark_px for s in res.scans for f in s.fiducials)
    assert res.width <= 2 * math.ceil((117.0 + 2.0 * block.camera.mark_mm) / 0.2)


def test_side_marks_touching_the_picture_found_without_calibrated_coordinates(touching_block, tmp_path):
    """Without coordinates the set's own geometry decides (opposite marks share one midpoint): the four side
    marks, and not a word about the corner windows where the camera has no marks."""
    from core.prepare.options import ScanOptions
    from core.prepare.scans import prepare_scans

    block = touching_block
    res = prepare_scans(_paths(block), str(tmp_path), str(tmp_path), ScanOptions())
    assert set(res.frame) == {"T", "R", "B", "L"} and not res.left_out
    errors = _mark_errors(block, res)
    assert len(errors) == 16 and max(errors.values()) < 0.5, errors
    assert not [w for w in res.warnings if "fiducial" in w], res.warnings
    assert not any(f.slot in CORNERS for s in res.scans for f in s.fiducials)


def test_detection_searches_only_the_calibrated_positions(touching_block):
    from core.prepare.options import ScanOptions
    from core.prepare.scans import detect_fiducials, parse_fiducial_coordinates

    block = touching_block
    cal = parse_fiducial_coordinates(_calibrated_text(block.camera))
    fids, warnings = detect_fiducials(_paths(block)[0], ScanOptions(), frame=cal.points)
    assert {f.slot for f in fids} == {"T", "R", "B", "L"} and not warnings


def _displace_mark(block, name, mark_id, dx, out_dir):
    """A copy of the scan with the mark ``mark_id`` moved ``dx`` px to the right (its patch of 2 marks)."""
    img = cv2.imread(os.path.join(block.paths["images"], name), cv2.IMREAD_UNCHANGED)
    x, y = (int(round(v)) for v in block.fiducials_scan(name)[mark_id])
    r = int(2 * block.camera.mark_mm / block.camera.pixel_mm)
    patch = img[y - r:y + r, x - r:x + r].copy()
    img[y - r:y + r, x - r + dx:x + r + dx] = patch
    path = os.path.join(out_dir, name)
    assert cv2.imwrite(path, img)
    return path


def test_a_scan_whose_marks_do_not_fit_is_left_out(touching_block, tmp_path):
    """A mark 3 px off in one scan leaves 0.75 px residuals on its four marks: over 4 x the limit (0.1 px here),
    so that scan is left out by name, the others prepared; with one scan left the stage fails, naming it."""
    from core.prepare.options import ScanError, ScanOptions
    from core.prepare.scans import prepare_scans

    block = touching_block
    bad = block.names[1]
    (tmp_path / "scans").mkdir()
    (tmp_path / "out").mkdir()
    paths = _paths(block)
    paths[1] = _displace_mark(block, bad, "1", 3, str(tmp_path / "scans"))
    opts = ScanOptions(fiducial_coordinates=_calibrated_text(block.camera), max_residual_px=0.1)
    res = prepare_scans(paths, str(tmp_path / "out"), str(tmp_path / "out"), opts)
    assert [s.name for s in res.scans] == [n for n in block.names if n != bad]
    assert list(res.left_out) == [bad] and "fiducial" in res.left_out[bad]
    assert not os.path.exists(tmp_path / "out" / bad)
    assert any(w.startswith(f"{bad}: left out: fiducial") for w in res.warnings), res.warnings
    with pytest.raises(ScanError, match=rf"fewer than 2 scans.*{bad}: left out"):
        prepare_scans(paths[:2], str(tmp_path / "out"), str(tmp_path / "out"), opts)


def test_implausible_fits_by_shape_and_scale():
    """Film shrinkage keeps x and y scales within tenths of a percent and the axes square; the scan pixel over
    the file's resolution is one value for the set.  A fit 10 % anisotropic or 30 % off in scale is left out."""
    from core.prepare.scans import Fiducial, _implausible_fits

    def fit(sx, sy, skew=0.0):
        m = np.array([[sx, skew, 650.0], [0.0, -sy, 650.0]])
        used = [Fiducial(s, 0.0, 0.0, 0.9, "cross_ring", 20.0, 1, residual_px=0.05) for s in ("T", "R", "B", "L")]
        return m, used, [], []

    fits = {"a": fit(5.0, 4.99), "b": fit(5.01, 5.0), "c": fit(4.0, 4.0), "d": fit(5.5, 5.0),
            "e": fit(3.6, 3.6), "f": fit(5.0, 5.0, skew=0.5)}
    res = {"a": 0.2, "b": 0.2, "c": 0.25, "d": 0.2, "e": 0.2, "f": 0.2}  # c: scanned at a coarser resolution
    out = _implausible_fits(fits, True, res, 3.0)
    assert set(out) == {"d", "e", "f"}, out
    assert "x and y +10.0 % apart" in out["d"] and "off the set's other scans" in out["e"]
    assert all(v.startswith(f"{k}: left out: ") for k, v in out.items())
    assert _implausible_fits(fits, True, {}, 3.0).keys() == {"d", "f"}  # resolution unknown: no scale test


def test_prepare_stage_with_a_scan_left_out(touching_block, tmp_path):
    """The stage reports the prepared scans under their own names when one scan is left out (the screening
    record was matched to the originals by position), and records which scan and why."""
    import shutil

    from core.prepare.options import PrepareOptions, ScanOptions
    from core.prepare.stage import prepare_images_workspace

    block = touching_block
    folder = tmp_path / "scans"
    folder.mkdir()
    bad = block.names[1]
    for n in block.names:
        if n != bad:
            shutil.copyfile(os.path.join(block.paths["images"], n), folder / n)
    _displace_mark(block, bad, "1", 3, str(folder))
    opts = PrepareOptions(scanned_film=True, scan=ScanOptions(fiducial_coordinates=_calibrated_text(block.camera),
                                                              max_residual_px=0.1), output_dir=str(tmp_path / "prepared"))
    res = prepare_images_workspace(str(folder), str(tmp_path / "ws"), opts)
    good = [n for n in block.names if n != bad]
    assert sorted(q.name for q in res.images) == good
    assert sorted(n for n in os.listdir(res.prepared_dir) if n.endswith(".tif")) == good
    assert any(w.startswith(f"{bad}: left out") for w in res.warnings)
    rec = json.load(open(os.path.join(res.workspace, "workspace.json")))["stages"]["prepare"]["results"]
    assert list(rec["left_out_scans"]) == [bad] and sorted(rec["decisions"]) == good


def test_scan_options_refuse_a_bad_choice_when_made():
    """Issue 35: the choices are checked when the options are made, before any scan is read; the layouts the
    options accept are the ones the detector knows."""
    from core.prepare.options import LAYOUT_NAMES, PrepareError, PrepareOptions, ScanError, ScanOptions
    from core.prepare.scans import LAYOUTS

    assert set(LAYOUT_NAMES) == set(LAYOUTS)
    with pytest.raises(ScanError, match="unknown fiducial layout 'corner'"):
        ScanOptions(layout="corner")
    with pytest.raises(ScanError, match="unknown fiducial type 'ring'"):
        ScanOptions(fiducial_type="ring")
    with pytest.raises(ScanError, match="focal_length_mm must be a positive number"):
        ScanOptions(focal_length_mm=-152.0)
    with pytest.raises(PrepareError, match="unknown y axis 'upward'"):
        PrepareOptions(mask_y_axis="upward")
    assert ScanOptions(fiducial_type="Cross", layout="CORNERS").layout == "corners"


@pytest.fixture(scope="module")
def film8_block():
    """The archive film camera with 8 marks (corner crosses, side marks), four scans; cached as in
    tests/test_archive_scene.py."""
    from tests import archive_scene as arch

    return arch.archive_block("film", 4, seed=1, out_dir=os.path.join(CACHE, f"{arch.VERSION}-film4"))


@pytest.mark.parametrize("calibrated", [True, False], ids=["certificate", "no-certificate"])
def test_one_scan_is_prepared_alone(film8_block, calibrated, tmp_path):
    """Issue 48 item 2: a folder with one film scan (the commonest archive case: one photo -> Orthorectify image)
    is prepared as a set's scans are: its fiducials found within the multi-scan tests' half pixel, restituted into
    the fiducial frame, masked; the log says that one photo is screened without a set to compare with."""
    import shutil

    from core.common.progress import NullProgress
    from core.prepare.options import PrepareOptions, ScanOptions
    from core.prepare.stage import prepare_images_workspace

    class Log(NullProgress):
        def __init__(self):
            self.lines = []

        def info(self, message):
            self.lines.append(message)

        def warning(self, message):
            self.lines.append(message)

    block = film8_block
    name = block.names[2]
    folder = tmp_path / "one scan"
    folder.mkdir()
    shutil.copyfile(os.path.join(block.paths["images"], name), folder / name)
    scan = ScanOptions(fiducial_coordinates=_calibrated_text(block.camera) if calibrated else "")
    log = Log()
    res = prepare_images_workspace(str(folder), str(tmp_path / "ws"),
                                   PrepareOptions(scanned_film=True, scan=scan,
                                                  output_dir=str(tmp_path / "prepared")), log)
    assert [q.name for q in res.images] == [name] and res.kept == 1
    assert [n for n in os.listdir(res.prepared_dir) if n.endswith(".tif")] == [name]
    assert len(res.masks) == 1
    assert any("one photo" in line and "no set to compare" in line for line in log.lines + res.warnings), log.lines
    doc = json.load(open(res.scans_path))
    assert [s["name"] for s in doc["scans"]] == [name]
    truth = block.fiducials_scan(name)
    found = doc["scans"][0]["fiducials"]
    if calibrated:
        from core.prepare.scans import parse_fiducial_coordinates

        ids = parse_fiducial_coordinates(_calibrated_text(block.camera)).ids
        errors = {f["slot"]: math.hypot(f["x"] - truth[ids[f["slot"]]][0], f["y"] - truth[ids[f["slot"]]][1])
                  for f in found}
    else:  # no certificate: each found mark against the nearest true one
        errors = {f["slot"]: min(math.hypot(f["x"] - x, f["y"] - y) for x, y in truth.values()) for f in found}
    assert len(errors) == len(truth) == 8, (sorted(errors), sorted(truth))
    print(f"\none scan ({'certificate' if calibrated else 'no certificate'}): fiducial errors mean "
          f"{np.mean(list(errors.values())):.3f} px, max {max(errors.values()):.3f} px")
    assert max(errors.values()) <= 0.5, errors
