"""Issue 17 items 1, 2, 7, 9, 12 (IMAGES a file) and 14: the photos a workspace was aligned from, the one image
check, a failed Align re-run, two-photo blocks, and inputs checked before the expensive work.

Real inputs: the Toledo sample photos (real pycolmap alignment) and a small rendered synthetic block with its
true model and height field (the DSM and orthophoto stages)."""
import hashlib
import json
import os
import shutil

import numpy as np
import pytest

from core.align.diagnosis import no_reconstruction_error as _no_reconstruction
from core.align.options import AlignError, AlignOptions
from core.align.photos import PHOTO_FINGERPRINTS
from core.align.stage import align
from core.common.progress import NullProgress
from core.dense.block import check_resolution
from core.dense.options import DenseError, DenseOptions
from core.dense.stage import build_dsm_workspace
from core.geometry.crs import CRSError
from core.io import raster as dsmmod
from core.io.gcp import GCPError
from core.io.images import ImageError, check_image, photo_fingerprint
from core.ortho.options import OrthoError, OrthoOptions, SingleImageOptions
from core.ortho.single import orthorectify_image
from core.ortho.stage import build_orthophoto_workspace
from core.pipeline import Control, run_pipeline
from core.project.layout import Layout
from core.project.stages import DONE, GEOREFERENCE, run_stage
from core.project.workspace import Workspace
from tests import synthetic as syn
from tests.conftest import SAMPLE, copy_images
from tests.workspaces import synthetic_workspace

PHOTOS = os.path.join(SAMPLE, "images")
PAIR = ["1JI_0064.JPG", "1JI_0065.JPG"]
FAST = dict(max_image_size=800, max_features=2048)
CAMERA = syn.CameraModel(400, 300, 325.0, 325.0, 201.9, 148.1, k1=-0.08, k2=0.02, p1=0.0006, p2=-0.0004)


class Log(NullProgress):
    def __init__(self):
        self.lines = []

    def info(self, message):
        self.lines.append(message)

    def warning(self, message):
        self.lines.append(message)


def _sha1(path):
    return hashlib.sha1(open(path, "rb").read()).hexdigest()


def _same_size_replacement(original, other, dst):
    """``other``'s photo padded after its end marker to ``original``'s size, with ``original``'s mtime (cp -p)."""
    a, b = open(original, "rb").read(), open(other, "rb").read()
    assert len(b) < len(a)
    st = os.stat(original)
    with open(dst, "wb") as f:
        f.write(b + b"\0" * (len(a) - len(b)))
    os.utime(dst, (st.st_atime, st.st_mtime))


# ---------------------------------------------------------------------------
# item 2: one image check (and the content fingerprint of item 1)
# ---------------------------------------------------------------------------

def test_check_image_names_the_file_and_the_problem(tmp_path):
    good = os.path.join(PHOTOS, PAIR[0])
    check_image(good)
    truncated = tmp_path / "cut.jpg"
    truncated.write_bytes(open(good, "rb").read()[:150000])
    with pytest.raises(ImageError, match=r"cut\.jpg: image data is corrupt or truncated"):
        check_image(str(truncated))
    with pytest.raises(ImageError, match="a folder, not an image file"):
        check_image(str(tmp_path))
    with pytest.raises(ImageError, match="does not exist"):
        check_image(str(tmp_path / "gone.jpg"))
    (tmp_path / "empty.jpg").write_bytes(b"")
    with pytest.raises(ImageError, match="empty file"):
        check_image(str(tmp_path / "empty.jpg"))


def test_photo_fingerprint_sees_another_photo_of_the_same_size_and_mtime(tmp_path):
    first, second = (os.path.join(PHOTOS, n) for n in ("1JI_0064.JPG", "1JI_0077.JPG"))
    if os.path.getsize(second) >= os.path.getsize(first):
        first, second = second, first
    swapped = str(tmp_path / os.path.basename(first))
    _same_size_replacement(first, second, swapped)
    assert os.path.getsize(swapped) == os.path.getsize(first)
    assert photo_fingerprint(swapped) != photo_fingerprint(first)
    copied = str(tmp_path / "copy.jpg")
    shutil.copyfile(first, copied)  # another mtime, same content: the same photo
    assert photo_fingerprint(copied) == photo_fingerprint(first)


def _flat_dsm(path, z=150.0):
    grid = np.full((200, 200), z, dtype=np.float32)
    return dsmmod.write_cog(path, grid, (syn.ORIGIN[0] - 100, 1.0, 0, syn.ORIGIN[1] + 100, 0, -1.0), syn.CRS)


def test_orthorectify_image_refuses_a_truncated_jpeg(tmp_path):
    """Before: a mostly grey orthophoto, exit 0, only GDAL's warning.  Now the alignment's check refuses it."""
    photo = tmp_path / "cut.jpg"
    photo.write_bytes(open(os.path.join(PHOTOS, PAIR[0]), "rb").read()[:150000])
    dsm = _flat_dsm(str(tmp_path / "dsm.tif"))
    orientation = {"x": syn.ORIGIN[0], "y": syn.ORIGIN[1], "z": 250.0, "omega": 0.0, "phi": 0.0, "kappa": 0.0,
                   "focal_px": 900.0, "crs": syn.CRS}
    out = tmp_path / "ortho.tif"
    with pytest.raises(OrthoError, match=r"cut\.jpg: image data is corrupt or truncated"):
        orthorectify_image(SingleImageOptions(str(photo), str(out), str(dsm), orientation=orientation))
    assert not out.exists()


# ---------------------------------------------------------------------------
# item 1: photos changed after the alignment (DSM and orthophoto of a georeferenced workspace)
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def block_ws(tmp_path_factory):
    root = tmp_path_factory.mktemp("photos block")
    block = syn.vertical_block(seed=1, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=3, forward_overlap=0.7,
                               side_overlap=0.4, gcp_grid=(3, 2), roofs=1)
    images = str(root / "images")
    block.render(images)
    sc = block.scene
    xmin, _, _, ymax = sc.bounds
    gt = (xmin + syn.ORIGIN[0], sc.height_res, 0.0, ymax + syn.ORIGIN[1], 0.0, -sc.height_res)
    dsm = dsmmod.write_cog(str(root / "truth_dsm.tif"), sc.height_raster(), gt, syn.CRS)
    return block, str(root), images, dsm


def _workspace(block, images, root, fingerprints=True):
    rec = block.truth_reconstruction(model_from_local=None, noise_px=0.2, n_points=300)
    photos = {n: os.path.join(images, n) for n in block.names}
    ws_dir = synthetic_workspace(root, block, rec, photos=photos, georeferenced=True, crs=syn.CRS,
                                 offset=syn.ORIGIN)
    if fingerprints:  # as the align stage records them
        ws = Workspace.open(ws_dir)
        ws.data["stages"]["align"][PHOTO_FINGERPRINTS] = {n: photo_fingerprint(p) for n, p in photos.items()}
        ws.save()
    return ws_dir


def test_changed_photo_is_refused_by_the_dsm_and_the_orthophoto(block_ws, tmp_path):
    """Before: both stages succeeded on the other photo without a word.  Now both refuse, naming it."""
    block, _root, images0, dsm = block_ws
    images = shutil.copytree(images0, str(tmp_path / "images"))
    ws = _workspace(block, images, str(tmp_path / "ws"))
    log = Log()
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm), progress=log)  # the photos as aligned: accepted
    assert os.path.isfile(res.orthomosaic) and not any("fingerprints" in m for m in log.lines)
    sizes = {n: os.path.getsize(os.path.join(images, n)) for n in block.names}
    target, other = max(sizes, key=sizes.get), min(sizes, key=sizes.get)
    _same_size_replacement(os.path.join(images, target), os.path.join(images0, other), os.path.join(images, target))
    with pytest.raises(OrthoError, match="changed since the alignment") as err:
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm))
    assert target in str(err.value) and other not in str(err.value) and "Align images" in str(err.value)
    with pytest.raises(DenseError, match="changed since the alignment") as err:
        build_dsm_workspace(ws)
    assert target in str(err.value)
    assert Workspace.open(ws).stage("dsm").get("status", "pending") == "pending"  # refused before the stage ran


def test_workspace_without_fingerprints_still_works_with_a_note(block_ws, tmp_path):
    block, _root, images, dsm = block_ws
    ws = _workspace(block, images, str(tmp_path / "ws"), fingerprints=False)
    log = Log()
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm), progress=log)
    assert os.path.isfile(res.orthomosaic)
    assert any("recorded no photo fingerprints" in m for m in log.lines)


def test_truncated_photo_of_an_old_workspace_is_refused(block_ws, tmp_path):
    """A workspace without fingerprints: the photos get the alignment's check (item 2) before the mosaic."""
    block, _root, images0, dsm = block_ws
    images = shutil.copytree(images0, str(tmp_path / "images"))
    ws = _workspace(block, images, str(tmp_path / "ws"), fingerprints=False)
    name = block.names[2]
    path = os.path.join(images, name)
    data = open(path, "rb").read()
    open(path, "wb").write(data[: len(data) // 3])
    with pytest.raises(OrthoError, match=f"{name}: image data is corrupt or truncated"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm))


# ---------------------------------------------------------------------------
# item 14: RESOLUTION checked before the matching
# ---------------------------------------------------------------------------

def test_absurd_dsm_resolution_is_refused_before_matching(block_ws, tmp_path):
    block, _root, images, _dsm = block_ws
    ws = _workspace(block, images, str(tmp_path / "ws"))
    for resolution, words in ((1e-5, "finer than a tenth of the images' ground sample distance"),
                              (1e4, "fewer than 2 cells across")):
        with pytest.raises(DenseError, match=words):
            build_dsm_workspace(ws, DenseOptions(resolution=resolution))
    assert not os.path.exists(os.path.join(ws, "dense"))  # no pair was matched
    assert "dsm" not in Workspace.open(ws).data["stages"]
    # over 50,000 x 50,000 cells: a 100 km block at 1 cm (GSD 5 cm)
    xyz = np.array([[0.0, 0.0, 0.0], [1e5, 1e5, 0.0]] * 50)
    with pytest.raises(DenseError, match="10,000,001 x 10,000,001 cells"):
        check_resolution(0.01, 0.05, xyz, 0.1)
    check_resolution(0.1, 0.05, xyz[:, :] / 100, 0.1)  # 1 km at 10 cm: fine


# ---------------------------------------------------------------------------
# item 14 and 12: Run pipeline reads the control and the IMAGES folder before the alignment
# ---------------------------------------------------------------------------

def test_pipeline_checks_its_inputs_before_the_alignment(tmp_path):
    images = copy_images(PHOTOS, PAIR, str(tmp_path / "img"))
    ws = str(tmp_path / "ws")
    gcp = tmp_path / "gcp_list.txt"
    gcp.write_text("EPSG:999999\n500000 4400000 700 100 200 1JI_0064.JPG gcp1\n")
    with pytest.raises(GCPError, match="999999"):
        run_pipeline(images, ws, control=Control(gcp_path=str(gcp)))
    with pytest.raises(CRSError, match="EPSG:999999"):
        run_pipeline(images, ws, control=Control(use_exif_gps=True, crs="EPSG:999999"))
    gcp.write_text("EPSG:32630\n500000 4400000 700 100 200 1JI_0064.JPG gcp1\n")
    with pytest.raises(GCPError, match="unknown check point"):
        run_pipeline(images, ws, control=Control(gcp_path=str(gcp), check_points=["nope"]))
    positions = tmp_path / "positions.txt"
    positions.write_text("EPSG:32630\n1JI_0064.JPG 500000 north 700\n")
    with pytest.raises(GCPError, match="positions.txt"):
        run_pipeline(images, ws, control=Control(camera_positions_path=str(positions)))
    assert not os.path.exists(ws)  # nothing was aligned
    with pytest.raises(ImageError, match="is a file, not a folder"):
        run_pipeline(os.path.join(images, PAIR[0]), ws, control=Control(use_exif_gps=True))


def test_images_path_that_is_a_file_says_so(tmp_path):
    photo = os.path.join(PHOTOS, PAIR[0])
    with pytest.raises(AlignError, match=r"1JI_0064\.JPG is a file, not a folder"):
        align(photo, str(tmp_path / "ws"))
    with pytest.raises(AlignError, match="does not exist"):
        align(str(tmp_path / "nowhere"), str(tmp_path / "ws"))
    assert not os.path.exists(tmp_path / "ws")


# ---------------------------------------------------------------------------
# item 9: two photos; item 7: a failed Align re-run leaves the workspace as it was
# ---------------------------------------------------------------------------

def test_the_no_reconstruction_message_is_true():
    msg = str(_no_reconstruction({"a.jpg": 1, "b.jpg": 1}, 2, 1))
    assert "share no verified matches" not in msg and "every one of the 2 images shares verified matches" in msg
    msg = str(_no_reconstruction({"a.jpg": 0, "b.jpg": 1, "c.jpg": 1}, 3, 1))
    assert "1 of 3 images share no verified matches with any other image (a.jpg)" in msg


@pytest.mark.slow
def test_two_overlapping_photos_align(tmp_path):
    """Before: 'no reconstruction ... 0 of 2 images share no verified matches' with over 1,000 inliers."""
    images = copy_images(PHOTOS, PAIR, str(tmp_path / "img"))
    for mapper in ("incremental", "global"):
        r = align(images, str(tmp_path / f"ws-{mapper}"), AlignOptions(mapper=mapper, **FAST))
        assert r.registered == 2 and r.num_points3d > 200 and r.mean_reprojection_error < 1.0
    rec = Workspace.open(str(tmp_path / "ws-incremental")).stage("align")
    assert set(rec[PHOTO_FINGERPRINTS]) == set(PAIR)
    assert rec[PHOTO_FINGERPRINTS][PAIR[0]] == photo_fingerprint(os.path.join(images, PAIR[0]))


@pytest.mark.slow
def test_failed_align_rerun_leaves_the_previous_alignment(tmp_path):
    import cv2

    images = copy_images(PHOTOS, PAIR, str(tmp_path / "img"))
    ws_dir = str(tmp_path / "ws")
    align(images, ws_dir, AlignOptions(**FAST))
    ws = Workspace.open(ws_dir)
    with run_stage(ws, GEOREFERENCE, {"synthetic": True}) as run:  # a later stage done on this alignment
        run.finish(outputs={})
    lay = Layout(ws)
    before = {"manifest": json.load(open(lay.manifest)), "db": _sha1(lay.database),
              "model": {n: _sha1(os.path.join(lay.aligned_model_dir, n)) for n in os.listdir(lay.aligned_model_dir)}}
    # the workspace's own folder, now holding three disjoint crops (nothing can be built from them): a re-alignment
    # that fails (another folder sharing no photo is refused before any work: test_align.py)
    for name in os.listdir(images):
        os.replace(os.path.join(images, name), str(tmp_path / name))
    photo = cv2.imread(os.path.join(PHOTOS, "1JI_0076.JPG"))
    for k in range(3):
        cv2.imwrite(os.path.join(images, f"crop{k}.jpg"), photo[:, k * 400:(k + 1) * 400])
    with pytest.raises(AlignError, match="no reconstruction"):
        align(images, ws_dir, AlignOptions(**FAST))
    after = json.load(open(lay.manifest))
    assert after["images"] == before["manifest"]["images"] and after["images_dir"] == images
    assert after["camera_groups"] == before["manifest"]["camera_groups"]
    assert after["stages"]["align"]["status"] == DONE
    assert after["stages"]["align"]["last_attempt"]["status"] == "failed"
    assert "no reconstruction" in after["stages"]["align"]["last_attempt"]["error"]
    assert after["stages"]["georeference"]["status"] == DONE  # not stale, not failed
    assert _sha1(lay.database) == before["db"]
    assert {n: _sha1(os.path.join(lay.aligned_model_dir, n)) for n in os.listdir(lay.aligned_model_dir)} == \
        before["model"]
    assert Layout(Workspace.open(ws_dir)).has_aligned_model()
    # the right photos again: the previous database is reused as it was, the attempt note goes
    for k in range(3):
        os.remove(os.path.join(images, f"crop{k}.jpg"))
    for name in PAIR:
        os.replace(str(tmp_path / name), os.path.join(images, name))
    log = Log()
    r = align(images, ws_dir, AlignOptions(**FAST), log)
    assert r.registered == 2 and any("already extracted, reused" in m for m in log.lines)
    rec = Workspace.open(ws_dir).stage("align")
    assert "last_attempt" not in rec and "staged_database_key" not in rec
    assert not os.path.exists(lay.staged_database)
