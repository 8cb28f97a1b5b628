"""Per-image masks: user polygons rasterised (core.masks), the Prepare images stage, and alignment honouring
the masks (pycolmap finds no keypoint where a mask is black)."""
import json
import os

import numpy as np
import pytest

from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images

cv2 = pytest.importorskip("cv2")

W, H = 40, 30  # synthetic image size for the rasterisation tests
SQUARE = [(10, 5), (20, 5), (20, 15), (10, 15)]  # pixels 10..19 x 5..14 (centres inside)


def _read(path):
    m = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    assert m is not None, path
    return m


def _expected(*boxes, base=None):
    """Mask (0/255) with the given (x0, y0, x1, y1) pixel boxes black."""
    m = np.full((H, W), 255, np.uint8) if base is None else base.copy()
    for x0, y0, x1, y1 in boxes:
        m[y0:y1, x0:x1] = 0
    return m


# ---------------------------------------------------------------------------
# core rasterisation
# ---------------------------------------------------------------------------

def test_square_polygon_y_down_for_one_image(tmp_path):
    from core.prepare.masks import write_user_masks

    res = write_user_masks([("a.JPG", [SQUARE])], {"a.JPG": (W, H), "b.JPG": (W, H)}, str(tmp_path))
    assert res.y_axis == "down" and set(res.masks) == {"a.JPG"}
    assert sorted(os.listdir(tmp_path)) == ["a.JPG.png"]  # COLMAP's name: <image name>.png, nothing else left
    m = _read(tmp_path / "a.JPG.png")
    assert m.dtype == np.uint8 and m.shape == (H, W)
    np.testing.assert_array_equal(m, _expected((10, 5, 20, 15)))
    assert res.ignored_fraction["a.JPG"] == pytest.approx(100 / (W * H))


def test_y_negative_georeferencer_form_gives_the_same_mask(tmp_path):
    from core.prepare.masks import write_user_masks

    closed = [(x, -y) for x, y in SQUARE] + [(SQUARE[0][0], -SQUARE[0][1])]  # y = -row, ring closed
    res = write_user_masks([("a.JPG", [closed])], {"a.JPG": (W, H)}, str(tmp_path))
    assert res.y_axis == "up"
    np.testing.assert_array_equal(_read(tmp_path / "a.JPG.png"), _expected((10, 5, 20, 15)))


def test_polygon_for_every_image_and_holes(tmp_path):
    from core.prepare.masks import write_user_masks

    outer = [(0, 0), (8, 0), (8, 8), (0, 8)]
    hole = [(2, 2), (6, 2), (6, 6), (2, 6)]
    items = [(None, [SQUARE], "all"), ("", [outer, hole], "with a hole")]  # empty name: every image too
    res = write_user_masks(items, {"a.JPG": (W, H), "b.tif": (W, H)}, str(tmp_path))
    assert set(res.masks) == {"a.JPG", "b.tif"} and res.polygons == {"a.JPG": 2, "b.tif": 2}
    expected = _expected((10, 5, 20, 15), (0, 0, 8, 8))
    expected[2:6, 2:6] = 255  # the hole stays usable
    for n in ("a.JPG", "b.tif"):
        np.testing.assert_array_equal(_read(tmp_path / f"{n}.png"), expected)


def test_merge_with_an_existing_mask(tmp_path):
    """Logical AND of the areas to use: the scan's (or a hand-made) mask stays, the polygon is added."""
    from core.prepare.masks import find_mask, write_user_masks

    base = _expected((0, 0, 5, H))  # left border black
    cv2.imwrite(str(tmp_path / "a.JPG.png"), base)
    cv2.imwrite(str(tmp_path / "b.png"), _expected((0, 0, W, 3)))  # stem-named mask of b.JPG (core.ortho accepts it)
    res = write_user_masks([(None, [SQUARE])], {"a.JPG": (W, H), "b.JPG": (W, H)}, str(tmp_path))
    np.testing.assert_array_equal(_read(res.masks["a.JPG"]), _expected((10, 5, 20, 15), base=base))
    np.testing.assert_array_equal(_read(res.masks["b.JPG"]), _expected((0, 0, W, 3), (10, 5, 20, 15)))
    assert find_mask(str(tmp_path), "b.JPG") == str(tmp_path / "b.JPG.png")  # the merged one comes first
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")]  # written atomically, nothing left over
    # same polygon again: unchanged (AND is idempotent)
    write_user_masks([(None, [SQUARE])], {"a.JPG": (W, H)}, str(tmp_path))
    np.testing.assert_array_equal(_read(tmp_path / "a.JPG.png"), _expected((10, 5, 20, 15), base=base))


def test_existing_mask_of_another_size_is_refused(tmp_path):
    from core.prepare.masks import MaskError, write_user_masks

    cv2.imwrite(str(tmp_path / "a.JPG.png"), np.full((10, 10), 255, np.uint8))
    with pytest.raises(MaskError, match=r"a\.JPG\.png is 10 x 10 px but its image is 40 x 30"):
        write_user_masks([("a.JPG", [SQUARE])], {"a.JPG": (W, H)}, str(tmp_path))


def test_rasterisation_is_the_pixel_centre_rule():
    """Against a brute-force point-in-polygon test of every pixel centre (random concave polygons)."""
    from core.prepare.masks import polygons_by_image, rasterise

    def inside(x, y, poly):
        c = False
        for i in range(len(poly)):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
            if (y0 <= y) != (y1 <= y) and x >= x0 + (y - y0) * (x1 - x0) / (y1 - y0):
                c = not c
        return c

    rng = np.random.default_rng(7)
    for _ in range(4):
        pts = rng.uniform(-10, 50, (7, 2)).tolist()
        by_image, _ = polygons_by_image([(None, [pts])], ["a"], y_axis="down")
        got = rasterise(by_image["a"], W, H)
        ref = np.array([[inside(c + 0.5, r + 0.5, pts) for c in range(W)] for r in range(H)])
        np.testing.assert_array_equal(got, ref)


def test_errors_name_the_polygon_and_the_problem(tmp_path):
    from core.prepare.masks import MaskError, write_user_masks

    sizes = {"a.JPG": (W, H), "b.JPG": (W, H)}
    with pytest.raises(MaskError, match=r"masks\.gpkg: feature 7: unknown image 'c\.JPG'.*a\.JPG, b\.JPG"):
        write_user_masks([("c.JPG", [SQUARE], "feature 7")], sizes, str(tmp_path), source="masks.gpkg")
    with pytest.raises(MaskError, match=r"feature 3: the polygon lies entirely outside image a\.JPG \(40 x 30 px\)"):
        write_user_masks([("a.JPG", [[(100, 5), (120, 5), (120, 15)]], "feature 3")], sizes, str(tmp_path))
    with pytest.raises(MaskError, match="outside every image"):
        write_user_masks([(None, [[(5, 100), (20, 100), (20, 120)]])], sizes, str(tmp_path))
    with pytest.raises(MaskError, match=r"feature 2: not a polygon.*a point or a line"):
        write_user_masks([("a.JPG", [[(0, 0), (10, 10), (0, 0)]], "feature 2")], sizes, str(tmp_path))
    with pytest.raises(MaskError, match="not a polygon: expected a list of rings"):
        write_user_masks([("a.JPG", SQUARE)], sizes, str(tmp_path))  # a ring where a list of rings belongs
    with pytest.raises(MaskError, match="no area"):
        write_user_masks([("a.JPG", [[(0, 0), (5, 5), (10, 10)]])], sizes, str(tmp_path))
    assert not os.listdir(tmp_path)  # nothing written by a failed call
    # a polygon for every image that misses only some of them is a warning, not an error
    res = write_user_masks([(None, [[(30, 5), (38, 5), (38, 15)]])], {"a.JPG": (W, H), "small.JPG": (20, 20)},
                           str(tmp_path))
    assert "outside 1 of 2 images (small.JPG)" in res.warnings[0]


# ---------------------------------------------------------------------------
# the Prepare images stage
# ---------------------------------------------------------------------------

IMG_W, IMG_H = 1200, 900  # the Toledo sample images
LEFT_HALF = [(0, 0), (IMG_W / 2, 0), (IMG_W / 2, IMG_H), (0, IMG_H)]
RIGHT_HALF = [(IMG_W / 2, 0), (IMG_W, 0), (IMG_W, IMG_H), (IMG_W / 2, IMG_H)]


def test_prepare_stage_writes_merges_and_rewrites_user_masks(tmp_path):
    from core.prepare.options import PrepareOptions
    from core.prepare.screening import measure_image
    from core.prepare.stage import prepare_images_workspace

    names = TOLEDO_STRIP[:2]
    images = copy_images(os.path.join(SAMPLE, "images"), names, str(tmp_path / "images"))
    ws = tmp_path / "ws"
    (ws / "masks").mkdir(parents=True)
    hand = np.full((IMG_H, IMG_W), 255, np.uint8)
    hand[:100] = 0  # a mask made by hand: the top strip
    cv2.imwrite(str(ws / "masks" / f"{names[0]}.png"), hand)

    corner = [(1100, 800), (1200, 800), (1200, 900), (1100, 900)]
    opts = PrepareOptions(mask_polygons=[(names[0], [LEFT_HALF], "feature 1"), (None, [corner], "feature 2")])
    r = prepare_images_workspace(images, str(ws), options=opts)
    m0, m1 = _read(ws / "masks" / f"{names[0]}.png"), _read(ws / "masks" / f"{names[1]}.png")
    assert (m0[:100] == 0).all() and (m0[:, :600] == 0).all() and (m0[800:, 1100:] == 0).all()
    assert (m0[100:800, 600:] == 255).all()
    assert (m1[800:, 1100:] == 0).all() and (m1 == 0).sum() == 100 * 100
    assert r.user_masked == {names[0]: 2, names[1]: 1}
    rec = json.load(open(ws / "workspace.json"))["stages"]["prepare"]
    assert sorted(rec["outputs"]["masks"]) == [f"masks/{n}.png" for n in names]
    assert rec["parameters"]["mask_polygons"]["count"] == 2
    assert os.path.isfile(ws / "masks" / ".originals" / f"{names[0]}.png")  # the hand-made mask, kept aside
    # screening measured inside the keep-area only
    by_name = {q.name: q for q in r.images}
    alone = measure_image(os.path.join(images, names[0]), mask_path=str(ws / "masks" / f"{names[0]}.png"))
    assert by_name[names[0]].blur_score == pytest.approx(alone.blur_score)
    assert by_name[names[0]].brightness == pytest.approx(alone.brightness)
    assert by_name[names[0]].brightness != pytest.approx(measure_image(os.path.join(images, names[0])).brightness)

    # another polygon: merged with the hand-made mask again, not with the previous result
    prepare_images_workspace(images, str(ws), options=PrepareOptions(mask_polygons=[(names[0], [RIGHT_HALF])]))
    m0 = _read(ws / "masks" / f"{names[0]}.png")
    assert (m0[:100] == 0).all() and (m0[:, 600:] == 0).all() and (m0[100:, :600] == 255).all()
    assert not os.path.exists(ws / "masks" / f"{names[1]}.png")

    # no polygons: the hand-made mask is back in its place, nothing else remains
    prepare_images_workspace(images, str(ws))
    assert os.listdir(ws / "masks") == [f"{names[0]}.png"]
    np.testing.assert_array_equal(_read(ws / "masks" / f"{names[0]}.png"), hand)


def test_prepare_stage_refuses_an_unknown_image_name(tmp_path):
    from core.prepare.masks import MaskError
    from core.prepare.options import PrepareOptions
    from core.prepare.stage import prepare_images_workspace

    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:2], str(tmp_path / "images"))
    with pytest.raises(MaskError, match="my layer: feature 4: unknown image 'IMG_9999.JPG'"):
        prepare_images_workspace(images, str(tmp_path / "ws"), options=PrepareOptions(
            mask_polygons=[("IMG_9999.JPG", [LEFT_HALF], "feature 4")], mask_source="my layer"))
    rec = json.load(open(tmp_path / "ws" / "workspace.json"))["stages"]["prepare"]
    assert rec["status"] == "failed" and "IMG_9999.JPG" in rec["error"]
    assert not os.path.exists(tmp_path / "ws" / "masks")


def test_prepare_scanned_film_merges_polygons_with_the_scan_masks(tmp_path):
    """Scanned film: a polygon named by the original scan (frame_002.tiff, prepared as frame_002.tif), in the
    prepared frame, ANDed with the scan's mask."""
    from core.prepare.options import PrepareOptions, ScanOptions
    from core.prepare.stage import prepare_images_workspace
    from tests.test_scans import SCAN_SETUP, calibration_text, make_scan

    folder = tmp_path / "scans"
    folder.mkdir()
    for i, (photo, res, ang, off) in enumerate(SCAN_SETUP[:3], start=1):
        make_scan(os.path.join(SAMPLE, "images", photo), str(folder / f"frame_{i:03d}.tiff"), i, res, ang, off)
    scan = ScanOptions(fiducial_coordinates=calibration_text())
    plain = prepare_images_workspace(str(folder), str(tmp_path / "ws1"),
                                     PrepareOptions(scanned_film=True, scan=scan, output_dir=str(tmp_path / "p1")))
    scan_mask = _read(os.path.join(plain.workspace, "masks", "frame_002.tif.png"))
    h, w = scan_mask.shape
    box = [(w * 0.4, h * 0.4), (w * 0.6, h * 0.4), (w * 0.6, h * 0.6), (w * 0.4, h * 0.6)]
    r = prepare_images_workspace(str(folder), str(tmp_path / "ws2"), PrepareOptions(
        scanned_film=True, scan=scan, mask_polygons=[("frame_002.tiff", [box], "feature 1")],
        output_dir=str(tmp_path / "p2")))  # the scan's own name
    assert r.user_masked == {"frame_002.tif": 1}
    masks = os.path.join(r.workspace, "masks")
    assert sorted(os.listdir(masks)) == ["frame_001.tif.png", "frame_002.tif.png", "frame_003.tif.png"]
    m = _read(os.path.join(masks, "frame_002.tif.png"))
    from core.prepare.masks import polygons_by_image, rasterise

    by_image, _ = polygons_by_image([(None, [box])], ["x"])
    expected = np.where((scan_mask >= 128) & ~rasterise(by_image["x"], w, h), 255, 0)
    np.testing.assert_array_equal(m, expected)
    np.testing.assert_array_equal(_read(os.path.join(masks, "frame_001.tif.png")),
                                  _read(os.path.join(plain.workspace, "masks", "frame_001.tif.png")))


# ---------------------------------------------------------------------------
# alignment: pycolmap finds no keypoint where the mask is black
# ---------------------------------------------------------------------------

def _keypoints(db_path):
    import pycolmap

    db = pycolmap.Database.open(db_path)
    try:
        return {im.name: np.asarray(db.read_keypoints(im.image_id))[:, :2] for im in db.read_all_images()}
    finally:
        db.close()


def test_align_extracts_no_keypoints_under_the_masks(tmp_path):
    pytest.importorskip("pycolmap")
    from core.align.options import AlignOptions
    from core.align.stage import align
    from core.prepare.masks import image_sizes, write_user_masks
    from tests.test_align import FAST, Recorder

    names = TOLEDO_STRIP[:3]
    images = copy_images(os.path.join(SAMPLE, "images"), names, str(tmp_path / "images"))
    ws = tmp_path / "ws"
    masks = str(ws / "masks")
    sizes = image_sizes(images)
    write_user_masks([(n, [LEFT_HALF]) for n in names[:2]], sizes, masks)

    rec = Recorder()
    r = align(images, str(ws), AlignOptions(**FAST), rec)
    assert r.masked_images == 2
    assert any(m.startswith("masks: 2 of 3 images have a mask") for m in rec.messages)
    kp = _keypoints(str(ws / "sfm" / "database.db"))
    for n in names[:2]:  # COLMAP drops keypoints in pixels of value 0: x < 600 (pixel index int(x))
        assert len(kp[n]) > 200 and kp[n][:, 0].min() >= IMG_W / 2, n
    assert (kp[names[2]][:, 0] < IMG_W / 2).sum() > 200  # the unmasked image has features there
    manifest = json.load(open(ws / "workspace.json"))
    key1 = manifest["stages"]["align"]["database_key"]
    assert manifest["stages"]["align"]["inputs"]["masks"]

    # other masks: the right half, one of them named <stem>.png: the features are extracted afresh
    for n in names[:2]:
        os.unlink(os.path.join(masks, n + ".png"))
    write_user_masks([(n, [RIGHT_HALF]) for n in names[:2]], sizes, masks)
    stem = os.path.splitext(names[1])[0] + ".png"
    os.replace(os.path.join(masks, names[1] + ".png"), os.path.join(masks, stem))
    rec2 = Recorder()
    r2 = align(images, str(ws), AlignOptions(**FAST), rec2)
    assert r2.masked_images == 2
    assert not any("already extracted" in m for m in rec2.messages)
    assert json.load(open(ws / "workspace.json"))["stages"]["align"]["database_key"] != key1
    kp = _keypoints(str(ws / "sfm" / "database.db"))
    for n in names[:2]:
        assert len(kp[n]) > 200 and kp[n][:, 0].max() < IMG_W / 2, n
    # the stem-named mask reached COLMAP under COLMAP's name
    assert sorted(os.listdir(ws / "sfm" / "masks")) == sorted(n + ".png" for n in names[:2])


# ---------------------------------------------------------------------------
# the Processing algorithm, as QGIS runs it (pytest-qgis)
# ---------------------------------------------------------------------------

def _polygon_layer(features):
    from qgis.core import QgsFeature, QgsGeometry, QgsPointXY, QgsVectorLayer

    layer = QgsVectorLayer("Polygon?field=image:string", "user masks", "memory")
    feats = []
    for image, ring in features:
        f = QgsFeature(layer.fields())
        f.setAttribute("image", image)
        f.setGeometry(QgsGeometry.fromPolygonXY([[QgsPointXY(x, y) for x, y in ring]]))
        feats.append(f)
    assert layer.dataProvider().addFeatures(feats)
    return layer


def test_processing_prepare_images_with_mask_polygons(plugin, tmp_path):
    from qgis import processing
    from qgis.core import NULL, QgsApplication, QgsProcessingException

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:prepareimages")
    assert "MASKS" in {p.name() for p in alg.parameterDefinitions()} and "Mask polygons:" in alg.shortHelpString()
    names = TOLEDO_STRIP[:2]
    images = copy_images(os.path.join(SAMPLE, "images"), names, str(tmp_path / "images"))
    # georeferencer style (y = -row): the left half of the first image, a corner of every image
    layer = _polygon_layer([(names[0], [(x, -y) for x, y in LEFT_HALF]),
                            (NULL, [(1100, -800), (1200, -800), (1200, -900), (1100, -900)])])
    res = processing.run("archaeoortho:prepareimages", {
        "IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "MASKS": layer, "OUTPUT": str(tmp_path / "prepared")})
    masks = os.path.join(res["WORKSPACE"], "masks")
    assert sorted(os.listdir(masks)) == sorted(n + ".png" for n in names)
    m0, m1 = _read(os.path.join(masks, names[0] + ".png")), _read(os.path.join(masks, names[1] + ".png"))
    assert (m0[:, :600] == 0).all() and (m0[:800, 600:] == 255).all() and (m0[800:, 1100:] == 0).all()
    assert (m1 == 0).sum() == 100 * 100 and (m1[800:, 1100:] == 0).all()

    bad = _polygon_layer([("IMG_9999.JPG", LEFT_HALF)])
    with pytest.raises(QgsProcessingException, match="MASKS layer 'user masks': feature .*: unknown image 'IMG_9999"):
        processing.run("archaeoortho:prepareimages", {
            "IMAGES": images, "WORKSPACE": str(tmp_path / "ws2"), "MASKS": bad})
