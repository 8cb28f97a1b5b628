"""Image quality screening (core.screening) on the Toledo sample: blurriest first, exposure flags, decisions."""
import json
import os
import shutil

import numpy as np
import pytest

from tests.conftest import SAMPLE

cv2 = pytest.importorskip("cv2")

BLURS = {"blur_s3.0.JPG": 3.0, "blur_s1.5.JPG": 1.5, "blur_s0.8.JPG": 0.8}  # Gaussian sigma, pixels
SOURCE = "1JI_0066.JPG"  # the least sharp original of the sample: the hardest case


@pytest.fixture(scope="module")
def toledo_with_bad_copies(tmp_path_factory):
    """The 18 sample images + three blurred copies (known sigma) + one over-exposed copy."""
    d = tmp_path_factory.mktemp("screening") / "images ü"
    shutil.copytree(os.path.join(SAMPLE, "images"), d)
    img = cv2.imread(os.path.join(SAMPLE, "images", SOURCE))
    for name, sigma in BLURS.items():
        cv2.imwrite(str(d / name), cv2.GaussianBlur(img, (0, 0), sigma), [cv2.IMWRITE_JPEG_QUALITY, 95])
    over = cv2.convertScaleAbs(img, alpha=1.8, beta=60)  # a stop and a half over: highlights clip
    cv2.imwrite(str(d / "overexposed.JPG"), over, [cv2.IMWRITE_JPEG_QUALITY, 95])
    return str(d)


@pytest.fixture(scope="module")
def screened(toledo_with_bad_copies):
    from core.prepare.screening import screen_folder

    return screen_folder(toledo_with_bad_copies)


def test_blurriest_images_rank_first(screened):
    quality = screened
    ranked = sorted(quality, key=lambda q: q.blur_rank)
    print("\nblur scores (variance of the Laplacian, 90th percentile of tiles, 1024 px):")
    for q in ranked[:6]:
        print(f"  {q.blur_rank:2d} {q.name:18s} {q.blur_score:8.1f}  {100 * q.blur_relative:5.1f} % of median  {q.flags}")
    originals = [q.blur_score for q in quality if q.name in os.listdir(os.path.join(SAMPLE, "images"))]
    print(f"  originals: min {min(originals):.1f}, median {np.median(originals):.1f}, max {max(originals):.1f}")
    # the three blurred copies are the three lowest, strongest blur first
    assert [q.name for q in ranked[:3]] == sorted(BLURS, key=lambda n: -BLURS[n])
    for q in ranked[:3]:
        assert "blurry" in q.flags
    # no sharp original is flagged blurry
    assert not [q.name for q in quality if q.name in os.listdir(os.path.join(SAMPLE, "images")) and q.flags]


def test_overexposed_copy_is_flagged(screened):
    by_name = {q.name: q for q in screened}
    over = by_name["overexposed.JPG"]
    print(f"\noverexposed copy: {100 * over.highlights_clipped:.1f} % clipped, exposure score "
          f"{over.exposure_score:.2f}, flags {over.flags}; source {by_name[SOURCE].exposure_score:.2f}")
    assert "overexposed" in over.flags
    assert over.highlights_clipped > 0.05
    assert over.exposure_rank == 1
    assert by_name[SOURCE].exposure_score > 0.8 and "overexposed" not in by_name[SOURCE].flags


def test_scores_do_not_depend_on_image_size(tmp_path):
    """The same photo at 1200 px and at 2400 px (upsampled) scores alike: analysis at a fixed size."""
    from core.prepare.screening import measure_image

    img = cv2.imread(os.path.join(SAMPLE, "images", SOURCE))
    cv2.imwrite(str(tmp_path / "big.png"), cv2.resize(img, None, fx=2, fy=2, interpolation=cv2.INTER_CUBIC))
    cv2.imwrite(str(tmp_path / "small.png"), img)
    a, b = measure_image(str(tmp_path / "small.png")), measure_image(str(tmp_path / "big.png"))
    assert b.blur_score == pytest.approx(a.blur_score, rel=0.35)
    assert b.dynamic_range == pytest.approx(a.dynamic_range, abs=0.02)


def test_sky_does_not_make_a_sharp_photo_blurry():
    """Half the frame uniform (sky, water): the textured tiles decide."""
    from core.io.images import to_grey
    from core.prepare.screening import blur_score

    img = cv2.imread(os.path.join(SAMPLE, "images", SOURCE))[:, :, ::-1]
    g = to_grey(img)
    sky = g.copy()
    sky[: g.shape[0] // 2] = 0.8
    assert blur_score(sky) > 0.8 * blur_score(g)
    assert blur_score(sky) > 5 * blur_score(to_grey(cv2.GaussianBlur(img, (0, 0), 1.5)))


def test_sixteen_bit_and_grey_images(tmp_path):
    from core.io.images import full_scale
    from core.prepare.screening import measure_image

    g = cv2.imread(os.path.join(SAMPLE, "images", SOURCE), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(tmp_path / "g16.tif"), (g.astype(np.uint16) * 16))  # 12-bit data in 16-bit
    cv2.imwrite(str(tmp_path / "g8.tif"), g)
    a, b = measure_image(str(tmp_path / "g8.tif")), measure_image(str(tmp_path / "g16.tif"))
    assert full_scale(np.array([4095], np.uint16)) == 4095
    assert b.brightness == pytest.approx(a.brightness, abs=0.01)
    assert b.blur_score == pytest.approx(a.blur_score, rel=0.05)


def test_prepare_stage_records_decisions_and_excludes(toledo_with_bad_copies, tmp_path):
    from core.prepare.options import PrepareOptions, ScreeningOptions
    from core.prepare.stage import load_screening, prepare_images_workspace

    ws = str(tmp_path / "ws")
    out = str(tmp_path / "prepared")
    opts = PrepareOptions(screening=ScreeningOptions(exclude_flagged=True), output_dir=out)
    res = prepare_images_workspace(toledo_with_bad_copies, ws, opts)
    flagged = {q.name for q in res.images if q.flags}
    assert set(BLURS) | {"overexposed.JPG"} <= flagged
    assert res.excluded == len(flagged) and res.kept == 22 - len(flagged)
    kept = sorted(n for n in os.listdir(out) if not n.startswith("."))
    assert len(kept) == res.kept and not set(kept) & flagged
    doc = load_screening(ws)
    assert doc["blurriest_first"][:3] == sorted(BLURS, key=lambda n: -BLURS[n])
    rows = {r["name"]: r for r in doc["images"]}
    assert rows["blur_s3.0.JPG"]["decision"] == "exclude" and rows["blur_s3.0.JPG"]["reasons"]
    assert rows[SOURCE]["decision"] == "keep"
    manifest = json.load(open(os.path.join(ws, "workspace.json")))
    rec = manifest["stages"]["prepare"]
    assert rec["status"] == "done" and rec["results"]["excluded"] == res.excluded
    assert rec["results"]["decisions"]["overexposed.JPG"]["decision"] == "exclude"
    assert rec["outputs"]["prepared_images"] == os.path.abspath(out)
    assert not os.path.exists(os.path.join(ws, "masks"))  # no scans, no masks (COLMAP wants all or none)

    # a re-run without exclusion replaces the prepared folder as a whole
    res2 = prepare_images_workspace(toledo_with_bad_copies, ws, PrepareOptions(output_dir=out))
    assert res2.excluded == 0 and len([n for n in os.listdir(out) if not n.startswith(".")]) == 22


def test_output_folder_with_foreign_files_is_refused(tmp_path):
    from core.prepare.options import PrepareOptions
    from core.prepare.screening import ScreeningError
    from core.prepare.stage import prepare_images_workspace

    images = tmp_path / "img"
    shutil.copytree(os.path.join(SAMPLE, "images"), images, ignore=lambda d, names: names[3:])
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.docx").write_text("precious")
    with pytest.raises(ScreeningError, match="did not write"):
        prepare_images_workspace(str(images), str(tmp_path / "ws"), PrepareOptions(output_dir=str(out)))
    assert (out / "thesis.docx").exists()
    with pytest.raises(ScreeningError, match="must not be the image folder"):
        prepare_images_workspace(str(images), str(tmp_path / "ws"), PrepareOptions(output_dir=str(images)))


def _bad_files(folder) -> dict:
    """A 0-byte photo, a text file named .jpg, a truncated download in ``folder``: name -> why it is skipped."""
    data = open(os.path.join(SAMPLE, "images", SOURCE), "rb").read()
    (folder / "empty.JPG").write_bytes(b"")
    (folder / "notes.jpg").write_text("not a photo")
    (folder / "broken.JPG").write_bytes(data[: len(data) // 3])
    return {"empty.JPG": "empty file (0 bytes)", "notes.jpg": "not a readable image",
            "broken.JPG": "image data is corrupt or truncated"}


def test_unusable_files_are_skipped_with_a_warning_as_align_does(tmp_path):
    """Issue 36 item 14: Prepare images stopped at the first unreadable file (and a 0-byte one was never named)
    where Align images skips both with a warning.  One rule: each file skipped with a warning naming it and why,
    in the result and the stage's results; one usable image is prepared alone (issue 48), none is refused, naming
    the skipped files."""
    from core.io.images import scan_images
    from core.prepare.options import PrepareOptions
    from core.prepare.screening import ScreeningError
    from core.prepare.stage import prepare_images_workspace
    from core.project.workspace import Workspace

    images = tmp_path / "img"
    shutil.copytree(os.path.join(SAMPLE, "images"), images, ignore=lambda d, names: names[3:])
    bad = _bad_files(images)
    res = prepare_images_workspace(str(images), str(tmp_path / "ws"), PrepareOptions(output_dir=str(tmp_path / "out")))
    assert res.kept == 3 and sorted(os.listdir(tmp_path / "out")) == sorted(
        [n for n in os.listdir(images) if n not in bad] + [".archaeoortho-prepared"])
    for name, why in bad.items():
        assert sum(name in w and why in w for w in res.warnings) == 1, (name, res.warnings)
    _, align_rule = scan_images(str(images))  # what Align images says of the same folder
    assert [w for w in res.warnings if w in align_rule] == align_rule
    assert Workspace.open(str(tmp_path / "ws")).stage("prepare")["results"]["skipped_files"] == align_rule
    # one usable image left: prepared alone (issue 48 item 2: one archive frame is a valid input)
    first = sorted(n for n in os.listdir(images) if n not in bad)[0]
    for n in os.listdir(images):
        if n not in bad and n != first:
            os.unlink(images / n)
    one = prepare_images_workspace(str(images), str(tmp_path / "ws1"), PrepareOptions(output_dir=str(tmp_path / "o1")))
    assert one.kept == 1 and [q.name for q in one.images] == [first]
    # no usable image left: refused before any work, naming what was skipped and why
    os.unlink(images / first)
    with pytest.raises(ScreeningError, match="no usable image .* at least 1 is needed") as e:
        prepare_images_workspace(str(images), str(tmp_path / "ws2"), PrepareOptions(output_dir=str(tmp_path / "out2")))
    assert all(name in str(e.value) and why in str(e.value) for name, why in bad.items()), str(e.value)
    assert not os.path.exists(tmp_path / "out2")


def test_cancel_leaves_no_complete_looking_output(tmp_path):
    from core.common.progress import Cancelled, NullProgress
    from core.prepare.options import PrepareOptions
    from core.prepare.stage import prepare_images_workspace

    class CancelAfter(NullProgress):
        def __init__(self, n):
            self.n = n

        def is_cancelled(self):
            self.n -= 1
            return self.n < 0

    images = tmp_path / "img"
    shutil.copytree(os.path.join(SAMPLE, "images"), images, ignore=lambda d, names: names[6:])
    with pytest.raises(Cancelled):
        prepare_images_workspace(str(images), str(tmp_path / "ws"), PrepareOptions(output_dir=str(tmp_path / "out")),
                                 progress=CancelAfter(3))
    assert not os.path.exists(tmp_path / "out")
    assert not os.path.exists(tmp_path / "ws" / "screening.json")
    manifest = json.load(open(tmp_path / "ws" / "workspace.json"))
    assert manifest["stages"]["prepare"]["status"] == "cancelled"


# ---------------------------------------------------------------------------
# the Processing algorithm, as QGIS runs it (pytest-qgis)
# ---------------------------------------------------------------------------

def test_processing_prepare_images(plugin, toledo_with_bad_copies, tmp_path):
    from qgis import processing
    from qgis.core import QgsApplication, QgsProcessingFeedback

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:prepareimages")
    assert alg is not None and alg.shortHelpString()
    names = {p.name() for p in alg.parameterDefinitions()}
    assert {"IMAGES", "WORKSPACE", "BLUR_THRESHOLD", "EXCLUDE_FLAGGED", "SCANNED_FILM", "FIDUCIAL_COORDINATES",
            "FOCAL_LENGTH_MM", "OUTPUT"} <= names
    assert {"WORKSPACE", "PREPARED_IMAGES", "FLAGGED"} <= {o.name() for o in alg.outputDefinitions()}

    feedback = QgsProcessingFeedback()
    progress = []
    feedback.progressChanged.connect(progress.append)
    res = processing.run("archaeoortho:prepareimages", {
        "IMAGES": toledo_with_bad_copies, "WORKSPACE": str(tmp_path / "ws"), "EXCLUDE_FLAGGED": True,
        "OUTPUT": str(tmp_path / "prepared"),
    }, feedback=feedback)
    assert res["FLAGGED"] == 4 and res["EXCLUDED"] == 4
    assert res["PREPARED_IMAGES"] == str(tmp_path / "prepared")
    kept = [n for n in os.listdir(res["PREPARED_IMAGES"]) if not n.startswith(".")]
    assert len(kept) == 18 and not any(n.startswith(("blur_", "overexposed")) for n in kept)
    assert os.path.isfile(os.path.join(res["WORKSPACE"], "screening.json"))
    assert progress and max(progress) == pytest.approx(100.0)

    # bad input is a clear QgsProcessingException naming the problem
    from qgis.core import QgsProcessingException

    with pytest.raises(QgsProcessingException, match="did not write"):
        (tmp_path / "busy").mkdir()
        (tmp_path / "busy" / "notes.txt").write_text("mine")
        processing.run("archaeoortho:prepareimages", {
            "IMAGES": toledo_with_bad_copies, "WORKSPACE": str(tmp_path / "ws"), "OUTPUT": str(tmp_path / "busy")})


def _mentions(text: str, needle: str) -> int:
    return sum(needle in line for line in text.splitlines())


def _error_lines(text: str) -> int:
    """How many lines of a failed qgis_process run's output carry its error (the one after "ERROR:")."""
    first = next(line for line in text.splitlines() if line.startswith("ERROR:\t"))
    return _mentions(text, first[len("ERROR:\t"):].strip())


def test_qgis_process_names_each_skipped_file_once_and_adds_no_error_line(tmp_path):
    """Issue 36 item 14 through qgis_process, as a user runs it: Prepare images names each skipped file once
    (stdout and stderr together), and a refusal is printed no more often than QGIS prints any algorithm's error.
    (QGIS itself prints an error three times: QgsProcessingAlgorithm::run logs it to the message log and calls
    feedback.reportError, whose base class logs it again, and qgis_process echoes every critical message-log
    line to stderr besides its own "ERROR:" line: native:buffer does the same.)"""
    import subprocess

    from osgeo import ogr

    from tests.conftest import qgis_process

    exe, env = qgis_process()
    images = tmp_path / "img"
    shutil.copytree(os.path.join(SAMPLE, "images"), images, ignore=lambda d, names: names[2:])
    bad = _bad_files(images)

    def run(*args):
        out = subprocess.run([exe, "run", *args], env=env, capture_output=True, text=True, timeout=300)
        return out.returncode, out.stdout + out.stderr

    rc, text = run("archaeoortho:prepareimages", "--", f"IMAGES={images}", f"WORKSPACE={tmp_path / 'ws'}")
    assert rc == 0, text[-3000:]
    for name, why in bad.items():
        assert _mentions(text, f"{name}: {why}") == 1, (name, text[-3000:])
    # no usable image: refused, the message printed as often as QGIS prints a native algorithm's error
    for n in os.listdir(images):
        if n not in bad:
            os.unlink(images / n)
    rc, text = run("archaeoortho:prepareimages", "--", f"IMAGES={images}", f"WORKSPACE={tmp_path / 'ws2'}")
    assert rc != 0
    ours = _error_lines(text)
    assert "no usable image" in text
    line = str(tmp_path / "line.gpkg")
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(line)
    layer = ds.CreateLayer("l", None, ogr.wkbLineString)
    feature = ogr.Feature(layer.GetLayerDefn())
    feature.SetGeometry(ogr.CreateGeometryFromWkt("LINESTRING (0 0, 1 1)"))
    layer.CreateFeature(feature)
    ds = None
    rc, native = run("native:buffer", "--", f"INPUT={line}", "DISTANCE=1", f"OUTPUT={tmp_path / 'no' / 'b.gpkg'}")
    assert rc != 0
    baseline = _error_lines(native)
    print(f"\nan error is printed {ours} times by prepareimages, {baseline} times by native:buffer")
    assert 1 <= ours <= baseline, (ours, baseline, text[-2000:])
