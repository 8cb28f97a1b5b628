"""Alignment stage in plain Python (no QGIS): real pycolmap on real images."""
import json
import os
import re
import shutil

import pytest

from core.align.features import choose_camera_model, sift_first_octave
from core.align.options import MAX_LOOP_ANCHORS, SEQUENTIAL_OVERLAP, AlignError, AlignOptions
from core.align.pairs import photo_positions, select_pairs
from core.align.stage import align, load_model
from core.common.progress import Cancelled, NullProgress
from core.io.images import ImageInfo
from core.project.workspace import Workspace, WorkspaceError
from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images, shared

FAST = dict(max_image_size=800, max_features=2048)


class Recorder(NullProgress):
    def __init__(self, cancel_on=None):
        self.messages, self.warnings, self.fractions = [], [], []
        self.cancel_on = cancel_on
        self.cancelled = False

    def report(self, fraction, message=""):
        self.fractions.append(fraction)
        self.messages.append(message)
        if self.cancel_on and message.startswith(self.cancel_on):
            self.cancelled = True

    def info(self, message):
        self.messages.append(message)

    def warning(self, message):
        self.warnings.append(message)

    def is_cancelled(self):
        return self.cancelled


def _info(name, gps=None):
    return ImageInfo(name=name, path=name, width=100, height=100, bands=3, dtype="Byte", gps=gps)


def test_pair_selection_spatial_and_fallback():
    # a 2 x 10 grid of GPS positions ~20 m apart
    imgs = [_info(f"i{r}{c:02d}.jpg", (10 + c * 0.00025, 50 + r * 0.00018, 100)) for r in range(2) for c in range(10)]
    pairs, used, warnings = select_pairs(imgs, "auto", spatial_neighbours=4)
    assert used == "spatial" and not warnings
    assert ("i000.jpg", "i001.jpg") in pairs
    assert ("i000.jpg", "i009.jpg") not in pairs  # far apart: not paired
    assert len(pairs) < 20 * 19 // 2
    imgs[3].gps = None
    pairs, used, warnings = select_pairs(imgs, "spatial", spatial_neighbours=4)
    assert used == "exhaustive" and "falling back to exhaustive" in warnings[0]
    assert len(pairs) == 190


def _positions_file(tmp_path, rows, crs_line):
    path = tmp_path / "camera_positions.csv"
    path.write_text((crs_line + "\n" if crs_line else "") + "image,x,y,z,sigma\n"
                    + "".join(f"{n},{x},{y},120,2\n" for n, x, y in rows))
    return str(path)


@pytest.mark.parametrize("crs_line, step", [("EPSG:32633", (20.0, 15.0)), ("EPSG:4326", (0.00025, 0.00018)),
                                            ("", (65.6, 49.2))])  # metres, degrees, a file's own units (feet)
def test_camera_positions_choose_spatial_pairs_for_photos_without_gps(tmp_path, crs_line, step):
    """Photos without EXIF GPS and a camera positions file (a GNSS log): spatial pairs by the file's positions
    (nearest neighbours in a 2 x 10 strip block, not the far ends), the probe's neighbours from it too; the file
    and EXIF GPS are not mixed; a file naming none of the photos, or one that cannot be read, fails when the
    options are made, naming the file."""
    from core.align.firstpass import neighbours
    from core.io.gcp import GCPError

    imgs = [_info(f"i{r}{c:02d}.jpg") for r in range(2) for c in range(10)]
    x0, y0 = (500000.0, 4600000.0) if crs_line == "EPSG:32633" else ((10.0, 50.0) if crs_line else (0.0, 0.0))
    # the file lists the photos in another order than the folder: the second strip first
    rows = [(f"i{r}{c:02d}.jpg", x0 + c * step[0], y0 + r * step[1]) for r in (1, 0) for c in range(10)]
    path = _positions_file(tmp_path, rows, crs_line)
    options = AlignOptions(camera_positions=path)
    positions = photo_positions(imgs, options.camera_positions)
    assert sorted(positions) == sorted(im.name for im in imgs)
    pairs, used, warnings = select_pairs(imgs, "auto", 4, positions)
    assert used == "spatial" and not warnings
    assert ("i000.jpg", "i001.jpg") in pairs and ("i000.jpg", "i100.jpg") in pairs
    assert ("i000.jpg", "i009.jpg") not in pairs and ("i005.jpg", "i109.jpg") not in pairs
    assert len(pairs) < 190
    assert select_pairs(imgs, "auto", 4)[1] == "exhaustive"  # without the file: no positions, every pair
    near = neighbours([im.name for im in imgs], ["i105.jpg"], positions)
    assert near["i105.jpg"] in ("i104.jpg", "i106.jpg", "i005.jpg")  # by position, not i106 by file order alone
    # EXIF GPS on the photos is not mixed with the file's frame: the file wins for every photo it names
    imgs[0].gps = (10.0, 50.0, 100.0)
    assert photo_positions(imgs, path)["i000.jpg"] == positions["i000.jpg"]
    other = _positions_file(tmp_path, [("DSC_1.jpg", x0 + 1.0, y0 + 2.0)], crs_line)
    with pytest.raises(AlignError, match="camera_positions.csv: no row names a photo"):
        photo_positions(imgs, other)
    (tmp_path / "bad.csv").write_text("image,x,y,z\ni000.jpg,abc,2,3\n")
    with pytest.raises(GCPError, match="bad.csv"):
        AlignOptions(camera_positions=str(tmp_path / "bad.csv"))
    with pytest.raises(AlignError, match="camera_positions"):
        AlignOptions(camera_positions=str(tmp_path / "none.csv"))


def test_pair_selection_sequential_has_loop_pairs():
    from collections import Counter

    imgs = [_info(f"{i:03d}.jpg") for i in range(150)]
    pairs, used, _ = select_pairs(imgs, "auto")
    assert used == "sequential"
    assert ("000.jpg", "001.jpg") in pairs and ("000.jpg", "012.jpg") in pairs
    assert ("005.jpg", "140.jpg") in pairs  # loop pair to every 10th image
    assert len(pairs) < 150 * 149 // 4
    # a large set: the loop anchors are bounded, so the pairs grow linearly with the images
    counts = {}
    for n in (1000, 2000):
        pairs, used, _ = select_pairs([_info(f"{i:04d}.jpg") for i in range(n)], "sequential")
        counts[n] = len(pairs)
        far = Counter()
        for a, b in pairs:
            if int(b[:4]) - int(a[:4]) > SEQUENTIAL_OVERLAP:
                far[a] += 1
                far[b] += 1
        anchors = [k for k, v in far.items() if v > n // 4]  # paired with a large share of the set
        assert 0 < len(anchors) <= MAX_LOOP_ANCHORS
    assert counts[2000] < 2.1 * counts[1000]


def test_camera_model_choice():
    assert choose_camera_model("AUTO", 20) == "OPENCV"
    assert choose_camera_model("AUTO", 5) == "RADIAL"
    assert choose_camera_model("full_opencv", 2) == "FULL_OPENCV"
    with pytest.raises(AlignError, match="unknown camera model"):
        choose_camera_model("FISHEYE9", 5)


@pytest.mark.slow
def test_align_skips_bad_files_in_unicode_path(tmp_path):
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP, str(tmp_path / "fotos äö ü"))
    good = open(os.path.join(images, TOLEDO_STRIP[0]), "rb").read()
    with open(os.path.join(images, "broken.jpg"), "wb") as f:
        f.write(good[: len(good) // 4])
    open(os.path.join(images, "zero.JPG"), "wb").close()
    with open(os.path.join(images, "readme.txt"), "w") as f:
        f.write("flight notes")
    rec = Recorder()
    ws_dir = str(tmp_path / "work space ø")
    result = align(images, ws_dir, AlignOptions(**FAST), rec)
    assert result.registered == len(TOLEDO_STRIP)
    assert result.mean_reprojection_error < 1.0
    warned = "\n".join(rec.warnings)
    for bad in ("broken.jpg", "zero.JPG", "readme.txt"):
        assert bad in warned
    ws = Workspace.open(ws_dir)
    assert ws.stage("align")["status"] == "done"
    assert ws.stage("align")["results"]["registered"] == len(TOLEDO_STRIP)
    assert set(ws.stage("align")["timings"]) >= {"features", "matching", "mapping", "total"}
    figures = json.load(open(os.path.join(ws_dir, "sfm", "alignment.json")))
    assert figures["registered"] == len(TOLEDO_STRIP)
    model = load_model(ws_dir)
    assert model.num_reg_images() == len(TOLEDO_STRIP)
    from osgeo import ogr

    ds = ogr.Open(result.cameras_path)
    assert ds.GetLayer(0).GetFeatureCount() == len(TOLEDO_STRIP)
    # progress was reported per image, per matching block and per registered image
    assert any(m.startswith("features:") for m in rec.messages)
    assert any(m.startswith("matching:") for m in rec.messages)
    assert any(m.startswith("mapping:") for m in rec.messages)
    assert rec.fractions == sorted(rec.fractions)


@pytest.mark.slow
def test_cancel_leaves_no_model_and_rerun_resumes(tmp_path):
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:5], str(tmp_path / "img"))
    ws_dir = str(tmp_path / "ws")
    rec = Recorder(cancel_on="mapping")
    with pytest.raises(Cancelled):
        align(images, ws_dir, AlignOptions(**FAST), rec)
    ws = Workspace.open(ws_dir)
    assert ws.stage("align")["status"] == "cancelled"
    assert not os.path.exists(os.path.join(ws_dir, "sfm", "model"))
    assert os.path.exists(os.path.join(ws_dir, "sfm", "database.db"))
    rec2 = Recorder()
    result = align(images, ws_dir, AlignOptions(**FAST), rec2)
    assert result.registered == 5
    assert any("already extracted, reused" in m for m in rec2.messages)
    assert any("already matched, reused" in m for m in rec2.messages)
    assert not any(re.match(r"features: \d+/\d+ images", m) for m in rec2.messages)


def test_one_image_or_empty_folder_is_a_clear_error(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(AlignError, match="no readable images"):
        align(str(empty), str(tmp_path / "ws1"))
    one = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:1], str(tmp_path / "one"))
    with pytest.raises(AlignError, match="only one readable image.*1JI_0064.JPG"):
        align(one, str(tmp_path / "ws2"))


def test_unwritable_workspace_fails_before_work(tmp_path):
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:2], str(tmp_path / "img"))
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(WorkspaceError, match="not a folder"):
        align(images, str(blocker))
    with pytest.raises(WorkspaceError, match="cannot create workspace folder"):
        align(images, "/proc/archaeoortho-workspace")


@pytest.mark.slow
def test_images_without_overlap_are_named(tmp_path):
    # three disjoint crops of one photo: they share no ground, nothing can be built
    import cv2

    photo = cv2.imread(os.path.join(SAMPLE, "images", "1JI_0064.JPG"))
    images = tmp_path / "img"
    images.mkdir()
    for k in range(3):
        cv2.imwrite(str(images / f"crop{k}.jpg"), photo[:, k * 400:(k + 1) * 400])
    with pytest.raises(AlignError, match="do not overlap") as err:
        align(str(images), str(tmp_path / "ws"), AlignOptions(**FAST))
    assert "crop0.jpg" in str(err.value) and "crop2.jpg" in str(err.value)


@pytest.mark.slow
def test_foreign_images_are_reported_not_registered(tmp_path):
    copr = shared("copr", "images")
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:5], str(tmp_path / "img"))
    shutil.copyfile(os.path.join(copr, "IMG_0037.jpg"), os.path.join(images, "IMG_0037.jpg"))
    rec = Recorder()
    result = align(images, str(tmp_path / "ws"), AlignOptions(**FAST), rec)
    assert result.registered == 5
    assert "IMG_0037.jpg" in result.unregistered
    assert any("IMG_0037.jpg" in w for w in rec.warnings)


@pytest.mark.slow
def test_global_mapper_aligns_the_strip(toledo_strip, tmp_path):
    """MAPPER=global (GLOMAP through pycolmap) on the sample strip: every image registered, sub-pixel."""
    r = align(toledo_strip, str(tmp_path / "ws"),
              AlignOptions(mapper="global", max_image_size=800, max_features=2048))
    assert r.registered == len(TOLEDO_STRIP)
    assert r.mean_reprojection_error < 1.0
    assert json.load(open(tmp_path / "ws" / "workspace.json"))["stages"]["align"]["parameters"]["mapper"] == "global"


def test_unknown_mapper_is_a_clear_error(toledo_strip, tmp_path):
    with pytest.raises(AlignError, match="unknown mapper 'magic'"):
        align(toledo_strip, str(tmp_path / "ws"), AlignOptions(mapper="magic"))
    assert not (tmp_path / "ws").exists()


def test_sift_first_octave_upsamples_only_small_images():
    o = AlignOptions()
    assert sift_first_octave(o, 800, 600) == -1  # small: upsampled for enough small-scale features
    assert sift_first_octave(o, 1200, 900) == 0  # the image itself has features enough
    assert sift_first_octave(AlignOptions(max_image_size=800), 4000, 3000) == -1  # matched at 800 px
    assert sift_first_octave(AlignOptions(first_octave=-1), 4000, 3000) == -1  # the user's choice


@pytest.mark.parametrize("field, value, what", [("pairing", "exhaustiv", "unknown pairing 'exhaustiv'"),
                                                ("camera_model", "opencv_fish", "unknown camera_model 'OPENCV_FISH'"),
                                                ("grouping", "per-image", "unknown grouping 'per-image'"),
                                                ("max_features", -1, "max_features must be a whole number"),
                                                ("focal_mm", 0.0, "focal_mm must be a positive number"),
                                                ("mapper", "glomap", "unknown mapper 'glomap'")])
def test_align_options_refuse_a_bad_value_when_made(field, value, what):
    """Issue 35: a mistyped choice fails when the options are made, before any feature extraction."""
    with pytest.raises(AlignError, match=what):
        AlignOptions(**{field: value})


def test_align_options_normalise_the_case_of_choices():
    o = AlignOptions(pairing="Spatial", camera_model="opencv", grouping="SINGLE")
    assert (o.pairing, o.camera_model, o.grouping) == ("spatial", "OPENCV", "single")


def _finished_alignment(ws_dir, images):
    """A workspace as 'Align images' leaves it on ``images`` (record, image list, fingerprints, a model folder),
    without the seconds of a real alignment: the check below reads only these."""
    from core.align.photos import PHOTO_FINGERPRINTS, fingerprint_photos
    from core.io.images import scan_images
    from core.project.layout import Layout
    from core.project.stages import ALIGN, run_stage

    ws = Workspace.create_or_open(ws_dir)
    infos, _ = scan_images(images)
    with run_stage(ws, ALIGN, {}) as run:
        os.makedirs(Layout(ws).aligned_model_dir)
        run.record[PHOTO_FINGERPRINTS] = fingerprint_photos(infos)
        ws.data["images_dir"] = os.path.abspath(images)
        ws.data["images"] = [im.to_dict() for im in infos]
        run.finish(outputs={"model": "sfm/model"})
    return ws_dir


def _tree(root):
    out = {}
    for d, _, files in os.walk(root):
        for f in files:
            p = os.path.join(d, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = fh.read()
    return out


def test_another_photo_folder_on_a_finished_workspace_is_refused_and_changes_nothing(tmp_path):
    """Issue 47 item 8: 'alignimages' on a finished workspace with another folder of other photos replaced the
    alignment without a word (the DSM, mosaic and DTM then stale); now refused before any work, naming the folder
    the workspace belongs to and both ways on (that folder again, or a new workspace); nothing of the workspace
    changes.  The same photos in a moved folder are the same block (allowed)."""
    from core.align.photos import check_same_photos

    mine = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:3], str(tmp_path / "site A"))
    other = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[3:], str(tmp_path / "site B"))
    ws_dir = _finished_alignment(str(tmp_path / "ws"), mine)
    before = _tree(ws_dir)
    with pytest.raises(AlignError, match=r"workspace .*ws was aligned from the photos of .*site A \(3 photos\); "
                                         r".*site B holds none of them.*IMAGES=.*site A.*new WORKSPACE") as e:
        align(other, ws_dir, AlignOptions(**FAST))
    assert "replace" in str(e.value)
    assert _tree(ws_dir) == before
    moved = shutil.copytree(mine, str(tmp_path / "site A moved"))
    os.remove(os.path.join(moved, TOLEDO_STRIP[0]))
    from core.align.photos import fingerprint_photos
    from core.io.images import scan_images

    prints = fingerprint_photos(scan_images(moved)[0])
    check_same_photos(Workspace.open(ws_dir), moved, prints)  # the same photos, moved (one left out): allowed
    check_same_photos(Workspace.open(ws_dir), mine, {})  # the workspace's folder: allowed whatever it holds now
