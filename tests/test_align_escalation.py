"""Alignment escalation (issue 13 item 1) and mixed-camera blocks (item 5), on real Toledo frames.

The small-frame failure: five Toledo frames (sample/toledo) cropped and downsampled to 1152 x 640 px, contrast
lowered to 12 % (a flat, hazy scan: no EXIF, the interior orientation given as FOCAL_MM / SENSOR_WIDTH_MM).
At 1152 px the fast path starts SIFT at octave 0 and finds too few features: the block does not build.
Escalation (upsampled SIFT, more and fainter features, more pairs) registers every frame in one block.
"""
import json
import os
import sqlite3

import cv2
import numpy as np
import pytest

from core.align.escalation import (
    ESCALATION_MIN_FEATURES,
    WEAK_MIN_TIES,
    block_state,
    escalated_sift,
    escalation_reason,
    forget_features,
    kind_order,
    round_pairs,
    weak_images,
)
from core.align.features import Extraction, FeatureSettings
from core.align.mapping import RELAXED_ABS_POSE_MIN_INLIERS
from core.align.options import AlignError, AlignOptions
from core.align.stage import align
from tests.conftest import SAMPLE

SMALL_FRAMES = ["1JI_0064.JPG", "1JI_0065.JPG", "1JI_0066.JPG", "1JI_0067.JPG", "1JI_0068.JPG"]
SMALL_SIZE = (1152, 640)
SMALL_CONTRAST = 0.12
# the DJI FC300X's lens, 3.61 mm on a 6.17 mm wide sensor: what a user types as FOCAL_MM / SENSOR_WIDTH_MM
FOCAL_MM, SENSOR_WIDTH_MM = 3.61, 6.17
# Toledo's two cameras over the same ground (sample/toledo): FC300X (1JI_*) and FC350 (DJI_*)
MIXED_FC300X = ["1JI_0066.JPG", "1JI_0067.JPG", "1JI_0077.JPG", "1JI_0078.JPG"]
MIXED_FC350 = ["DJI_0089.JPG", "DJI_0090.JPG", "DJI_0092.JPG", "DJI_0093.JPG"]


def small_frames(src_dir, names, dst_dir, size=SMALL_SIZE, contrast=SMALL_CONTRAST):
    """Frames cropped to the aspect of ``size``, downsampled to it (INTER_AREA) and their contrast scaled by
    ``contrast`` around the mean, written as PNG (no EXIF)."""
    os.makedirs(dst_dir, exist_ok=True)
    w, h = size
    for n in names:
        im = cv2.imread(os.path.join(src_dir, n))
        rows = int(round(im.shape[1] * h / w))
        if rows <= im.shape[0]:
            y0 = (im.shape[0] - rows) // 2
            im = im[y0:y0 + rows]
        im = cv2.resize(im, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32)
        im = np.clip(128.0 + contrast * (im - im.mean()), 0, 255).astype(np.uint8)
        assert cv2.imwrite(os.path.join(dst_dir, os.path.splitext(n)[0] + ".png"), im)
    return dst_dir


@pytest.fixture(scope="module")
def small_block(tmp_path_factory):
    d = tmp_path_factory.mktemp("small frames")
    return small_frames(os.path.join(SAMPLE, "images"), SMALL_FRAMES, str(d / "img"))


def _options(**kw):
    """The small frames' options; the texture probe off (core.align.firstpass would give these faint frames the
    escalation's features at once): the escalation is what these tests exercise."""
    return AlignOptions(focal_mm=FOCAL_MM, sensor_width_mm=SENSOR_WIDTH_MM, **{"texture_probe": False, **kw})


def _context(db, tmp_path, names, partners):
    """An escalation context over the database ``db`` whose steps do nothing (a test replaces _run_round)."""
    import core.align.escalation as esc

    return esc.EscalationContext(None, Extraction(str(db), str(tmp_path), [], {}), FeatureSettings(1000, 4096, 0),
                                 str(tmp_path), names, AlignOptions(), [], lambda p: [], lambda reg, oth: {}, partners)


class _Image:
    def __init__(self, name, ties=500):
        self.name = name
        self.num_points3D = ties


def _sql(db, *statements):
    """Run ``statements`` on the SQLite database ``db`` and commit."""
    con = sqlite3.connect(db)
    for st in statements:
        con.execute(st)
    con.commit()
    con.close()


class _Rec:
    """What block_state and weak_images read of a pycolmap.Reconstruction (``ties``: name -> tie points)."""

    def __init__(self, names, ties=None):
        self.images = {k: _Image(n, (ties or {}).get(n, 500)) for k, n in enumerate(names)}

    def reg_image_ids(self):
        return list(self.images)


def test_block_state_ignores_components_inside_the_main_block():
    main, others = block_state([_Rec(["a", "b", "c", "d"]), _Rec(["b", "c"]), _Rec(["c", "e", "f"])])
    assert main == {"a", "b", "c", "d"}
    assert others == [["e", "f"]]  # the component of b, c is no split; c is not counted twice
    assert block_state([]) == (set(), [])


def test_escalation_reason_and_settings():
    assert escalation_reason(4, {"a", "b", "c", "d"}, []) is None
    assert escalation_reason(4, {"a", "b"}, [["c", "d"]]) == ("2 of 4 images not in the main block; "
                                                              "the block split into 2 components")
    s = escalated_sift(AlignOptions(), 1152, 640)  # the fast path: ~2900 features, octave 0
    assert s["first_octave"] == -1 and s["peak_threshold"] < 0.0066 and "domain_size_pooling" not in s
    assert s["max_num_features"] == ESCALATION_MIN_FEATURES
    assert escalated_sift(AlignOptions(max_features=6000), 4000, 3000)["max_num_features"] == 12000
    s2 = escalated_sift(AlignOptions(), 1152, 640, "affine")  # affine shape at SIFT's default threshold, no DSP
    assert s2["estimate_affine_shape"] and "domain_size_pooling" not in s2 and "peak_threshold" not in s2
    assert s2["first_octave"] == -1 and s2["max_num_features"] == 4096
    assert escalated_sift(AlignOptions(max_features=6000), 4000, 3000, "affine")["max_num_features"] == 6000
    with pytest.raises(ValueError, match="unknown escalation kind"):
        escalated_sift(AlignOptions(), 1152, 640, "dsp")


def test_weakly_tied_images_are_named_with_the_figures():
    ties = {"a": 300, "b": 280, "c": 13, "d": 250, "e": 29, "f": 30, "g": 45}
    weak = weak_images([_Rec(list(ties), ties)])
    assert sorted(weak) == ["c", "e"]  # fewer than COLMAP's 30 to register; 30 and 45 are not weak
    assert "tied by only 13 points" in weak["c"] and "median 45" in weak["c"]
    assert weak_images([]) == {} and weak_images([_Rec(["a", "b"], {"a": 5, "b": 5})]) == {}  # a stereo pair
    assert escalation_reason(3, {"a", "b", "c"}, [], ["c"]) == "1 image(s) of the block weakly tied"
    assert kind_order({"c": weak["c"], "e": weak["e"]}, ["c", "e"]) == ("affine", "faint")
    assert RELAXED_ABS_POSE_MIN_INLIERS < WEAK_MIN_TIES  # what the relaxed pass registers on can be escalated


def test_a_weakly_tied_image_is_escalated_and_the_stronger_result_kept(tmp_path, monkeypatch):
    """Every image registered, one on 13 tie points: an affine round runs for it alone (it stays registered,
    not a neighbour), and its result is kept because it ties that image well; a round that leaves it weak is not."""
    import core.align.escalation as esc
    from core.common.progress import NullProgress

    db = tmp_path / "database.db"
    _sql(db, "CREATE TABLE keypoints (image_id INTEGER, rows INTEGER)")
    names = ["a", "b", "c", "d"]
    weak = _Rec(names, {"a": 300, "b": 280, "c": 13, "d": 250})
    strong = _Rec(names, {"a": 310, "b": 290, "c": 140, "d": 260})
    seen = []

    def round_(ctx, k, reason, ordered, left, progress, kind="faint"):
        seen.append((k, kind, list(left), reason))
        new = [strong] if outcome == "strong" else [_Rec(names, {"a": 300, "b": 280, "c": 20, "d": 250})]
        return esc.EscalationRound(k, reason, kind, {n: "?" for n in left}, list(left), [], {}, 1, 4, 1, 4, 1,
                                   kept=esc._better(new, ordered)), new

    monkeypatch.setattr(esc, "_run_round", round_)
    ctx = _context(db, tmp_path, names, lambda: {n: 3 for n in names})
    outcome = "strong"
    out, record = esc.escalate(ctx, [weak], NullProgress())
    assert out == [strong] and seen == [(1, "affine", ["c"], "1 image(s) of the block weakly tied")]
    assert record.images["c"] == {"why": "?", "rounds": [1], "registered": True, "tie_points": 140, "weak": False,
                                  "escalated": ["upsampled SIFT (first octave -1) with affine shape, "
                                                "1 pairs matched again"]}
    seen.clear()
    outcome = "still weak"
    out, record = esc.escalate(ctx, [weak], NullProgress())
    assert out == [weak] and [s[:3] for s in seen] == [(1, "affine", ["c"]), (2, "faint", ["c"])]
    assert record.images["c"]["registered"] and record.images["c"]["weak"] and record.images["c"]["tie_points"] == 13
    assert esc.escalate(ctx, [strong], NullProgress()) == ([strong], None)  # nothing weak: no escalation


def test_the_round_that_fits_the_failure_runs_first():
    viewpoint = "matched 7 image(s) but could not be registered (too few 2D-3D correspondences)"
    texture = "no verified matches with any other image (no overlap, blur or too little texture)"
    component = "in a separate component (#2, 3 images) that shares too few matches with the main block"
    assert kind_order({"a": viewpoint, "b": viewpoint, "c": texture}, ["a", "b", "c"]) == ("affine", "faint")
    assert kind_order({"a": texture, "b": texture}, ["a", "b"]) == ("faint", "affine")
    assert kind_order({"a": component, "b": viewpoint}, ["a", "b"]) == ("faint", "affine")  # no majority
    assert kind_order({}, ["a"]) == ("faint", "affine")


def test_round_pairs_rematch_what_changed_and_add_pairs_for_the_left_out():
    original = [("a", "b"), ("b", "c"), ("c", "d"), ("d", "e"), ("e", "f")]
    pairs = round_pairs(original, ["e", "f"], ["c"], list("abcdef"), exhaustive=False)
    # original pairs touching a re-extracted image, e-f, and each left-out image with each neighbour
    assert pairs == [("b", "c"), ("c", "d"), ("c", "e"), ("c", "f"), ("d", "e"), ("e", "f")]
    assert len(round_pairs(original, ["e"], [], list("abcdef"), exhaustive=True)) == 15


def _grid_context(tmp_path, rows, cols, raw=(), positions=True, spacing=10.0):
    """An escalation context over a ``rows`` x ``cols`` grid of photos ``spacing`` m apart (positions known or
    not), each paired in the fast path with its right and lower neighbour, ``raw`` matches (a, b, count) in its
    database."""
    import core.align.escalation as esc

    names = [f"S{r:02d}_{c:02d}" for r in range(rows) for c in range(cols)]
    db = tmp_path / f"grid{rows}x{cols}{'' if positions else '-no-gps'}-{len(raw)}.db"
    if db.exists():
        db.unlink()
    _sql(db, "CREATE TABLE images (image_id INTEGER, name TEXT)", "CREATE TABLE matches (pair_id INTEGER, rows INTEGER)",
         *[f"INSERT INTO images VALUES ({k + 1}, '{n}')" for k, n in enumerate(names)],
         *[f"INSERT INTO matches VALUES ({min(names.index(a), names.index(b)) + 1} * {esc.PAIR_ID_BASE} + "
           f"{max(names.index(a), names.index(b)) + 1}, {c})" for a, b, c in raw])
    original = [(f"S{r:02d}_{c:02d}", f"S{r:02d}_{c + 1:02d}") for r in range(rows) for c in range(cols - 1)]
    original += [(f"S{r:02d}_{c:02d}", f"S{r + 1:02d}_{c:02d}") for r in range(rows - 1) for c in range(cols)]
    xy = {f"S{r:02d}_{c:02d}": (c * spacing, r * spacing) for r in range(rows) for c in range(cols)}
    return esc.EscalationContext(None, Extraction(str(db), str(tmp_path), [], {}), FeatureSettings(1000, 4096, 0),
                                 str(tmp_path), names, AlignOptions(spatial_neighbours=8), original,
                                 lambda p, s=None: [], lambda reg, oth: {}, lambda: {},
                                 xy if positions else None)


def test_a_large_blocks_round_pairs_each_left_out_image_with_its_own_neighbours(tmp_path):
    """Issue 33: in a block of hundreds, the extension round's pairs grow with the images left out, not with the
    block: each left-out image with its nearest images (by camera position) and the images it matched best,
    never every left-out image with every other's neighbours or with every registered image."""
    import core.align.escalation as esc

    left = ["S00_00", "S00_01", "S01_00"]
    far = "S14_19"  # a raw match far away (an image of the same ground from another strip): kept as an anchor
    pairs_by_size = {}
    for rows in (15, 30):
        ctx = _grid_context(tmp_path, rows, 20, raw=[("S00_00", far, 40)])
        assert len(ctx.order) > esc.EXTEND_MIN_IMAGES and esc.extends(ctx, [object()])
        pairs = esc.extension_pairs(ctx, left, left + ["S01_01"], None)
        pairs_by_size[rows] = pairs
        assert all(a in left or b in left or "S01_01" in (a, b) for a, b in pairs)
        for w in left:
            mine = {b if a == w else a for a, b in pairs if w in (a, b)}
            assert len(mine) <= ctx.options.spatial_neighbours + esc.ANCHORS_PER_IMAGE
            assert set(esc.nearest(ctx, w, ctx.order, ctx.options.spatial_neighbours)) <= mine
            assert max(abs(int(n[1:3]) - int(w[1:3])) for n in mine - {far}) <= 3  # nothing from across the block
        assert ("S00_00", far) in pairs and ("S00_01", far) not in pairs
        assert ("S01_01", "S01_02") in pairs  # an original pair of an image extracted again: matched again
    assert pairs_by_size[15] == pairs_by_size[30]  # twice the block, the same pairs
    # no camera positions: the nearest in file order
    ctx = _grid_context(tmp_path, 15, 20, positions=False)
    assert esc.nearest(ctx, "S05_10", ctx.order, 4) == ["S05_09", "S05_11", "S05_08", "S05_12"]
    assert not esc.extends(ctx, [])  # nothing registered: no block to continue
    assert not esc.extends(_grid_context(tmp_path, 5, 20), [object()])  # 100 images: mapped afresh


@pytest.fixture(scope="module")
def fast_path(small_block, tmp_path_factory):
    """The fast path alone on the small frames: (workspace, AlignResult or the AlignError)."""
    ws = tmp_path_factory.mktemp("fast path") / "ws"
    try:
        return ws, align(small_block, str(ws), _options(escalate=False))
    except AlignError as e:
        return ws, e


@pytest.mark.slow
def test_fast_path_fails_on_small_low_contrast_frames_and_escalation_fixes_it(small_block, fast_path, tmp_path):
    # the fast path alone (octave 0 at 1152 px, ~2900 features, SIFT's default peak threshold): no block, or
    # not every frame in one block
    _ws, fast = fast_path
    if isinstance(fast, AlignError):
        assert "no reconstruction" in str(fast)
    else:
        assert fast.registered < len(SMALL_FRAMES) or fast.other_components
    ws = tmp_path / "ws"
    r = align(small_block, str(ws), _options())
    assert r.registered == len(SMALL_FRAMES) and r.other_components == [] and not r.unregistered
    assert r.mean_reprojection_error < 1.0 and r.num_points3d > 300
    record = json.load(open(ws / "sfm" / "alignment.json"))["escalation"]
    assert record["reason"].startswith("5 of 5 images not in the main block")
    first = record["rounds"][0]
    assert first["sift"]["first_octave"] == -1 and first["kept"] and first["registered_after"] == 5
    assert first["kind"] == "faint"  # no verified pair anywhere: a texture/contrast failure, fainter features first
    assert sorted(first["re_extracted"]) == sorted(n.replace(".JPG", ".png") for n in SMALL_FRAMES)
    for n in SMALL_FRAMES:  # per image: why it was escalated, what was done and the outcome
        one = record["images"][n.replace(".JPG", ".png")]
        assert one["why"] and one["registered"] is True and one["rounds"] and one["escalated"]
    assert json.load(open(ws / "workspace.json"))["stages"]["align"]["results"]["escalation_rounds"] >= 1
    assert not (ws / "sfm" / "database.db.before-escalation").exists()  # the round's backup is removed


@pytest.mark.slow
def test_forget_features_empties_only_the_named_images(fast_path):
    """The fast path's database (features of all five frames, matches): two frames forgotten."""
    ws, _ = fast_path
    db = str(ws / "sfm" / "database.db")
    con = sqlite3.connect(db)
    names = dict(con.execute("SELECT image_id, name FROM images"))
    con.close()
    gone = ["1JI_0064.png", "1JI_0066.png"]
    forget_features(db, gone)
    con = sqlite3.connect(db)
    with_kp = {names[i] for (i,) in con.execute("SELECT image_id FROM keypoints")}
    with_desc = {names[i] for (i,) in con.execute("SELECT image_id FROM descriptors")}
    paired = set()
    for table in ("matches", "two_view_geometries"):
        for (pid,) in con.execute(f"SELECT pair_id FROM {table}"):
            paired.update((names[pid // 2147483647], names[pid % 2147483647]))
    con.close()
    assert len(names) == 5 and with_kp == with_desc == set(names.values()) - set(gone)
    assert paired and not paired & set(gone)  # the other frames' pairs are kept


@pytest.mark.slow
def test_mixed_cameras_register_in_one_block(tmp_path):
    """Issue 13 item 5: Toledo's FC300X and FC350 frames over the same ground, each camera its own intrinsics
    group, register together into one component."""
    from tests.conftest import copy_images

    images = copy_images(os.path.join(SAMPLE, "images"), MIXED_FC300X + MIXED_FC350, str(tmp_path / "img"))
    r = align(images, str(tmp_path / "ws"), AlignOptions(max_image_size=640, max_features=1536))
    assert r.registered == len(MIXED_FC300X) + len(MIXED_FC350)
    assert r.other_components == [] and not r.unregistered
    assert r.mean_reprojection_error < 1.0
    assert len(r.cameras) == 2  # two intrinsics groups, one per camera
    ws = json.load(open(tmp_path / "ws" / "workspace.json"))
    groups = {g["model"]: set(g["images"]) for g in ws["camera_groups"]}
    assert groups["FC300X"] == set(MIXED_FC300X) and groups["FC350"] == set(MIXED_FC350)
    model = {c["camera_id"]: c for c in r.cameras}
    assert {m["width"] for m in model.values()} == {1200}  # the matching scale does not change the camera


def test_a_round_not_kept_puts_the_database_back(tmp_path, monkeypatch):
    """A round whose mapping is worse than the result before it: the result and the database stay as they were."""
    import core.align.escalation as esc
    from core.common.progress import NullProgress

    db = tmp_path / "database.db"
    _sql(db, "CREATE TABLE keypoints (image_id INTEGER, rows INTEGER)", "INSERT INTO keypoints VALUES (1, 10)")

    def worse_round(ctx, k, reason, ordered, left, progress, kind="faint"):
        _sql(ctx.db_path, "DELETE FROM keypoints")  # the round's new features...
        return esc.EscalationRound(k, reason, kind, {n: "?" for n in left}, list(left), [], {}, 1, 2, 1, 1, 1), []

    monkeypatch.setattr(esc, "_run_round", worse_round)
    ctx = _context(db, tmp_path, ["a", "b", "c"], lambda: {"c": 1})
    before = [_Rec(["a", "b"])]
    out, record = esc.escalate(ctx, before, NullProgress())
    assert out is before and [r.round for r in record.rounds] == [1, 2]  # c has a verified pair: round 2 ran
    assert record.images["c"]["registered"] is False and record.images["c"]["rounds"] == [1, 2]
    con = sqlite3.connect(db)
    assert con.execute("SELECT COUNT(*) FROM keypoints").fetchone()[0] == 1  # ...are gone again
    con.close()
    assert not os.path.exists(str(db) + ".before-escalation")


def test_a_cancelled_round_puts_the_database_back(tmp_path, monkeypatch):
    """A Cancel (or any failure) in the middle of a round: the exception goes on, and the database is the one
    before the round (not the round's half-changed features and matches)."""
    import core.align.escalation as esc
    from core.common.progress import Cancelled, NullProgress

    db = tmp_path / "database.db"
    _sql(db, "CREATE TABLE keypoints (image_id INTEGER, rows INTEGER)", "INSERT INTO keypoints VALUES (1, 10)")

    def cancelled_round(ctx, k, reason, ordered, left, progress, kind="faint"):
        _sql(ctx.db_path, "DELETE FROM keypoints")  # features forgotten, then the user cancels
        raise Cancelled("cancelled by the user")

    monkeypatch.setattr(esc, "_run_round", cancelled_round)
    ctx = _context(db, tmp_path, ["a", "b", "c"], lambda: {"c": 1})
    with pytest.raises(Cancelled):
        esc.escalate(ctx, [_Rec(["a", "b"])], NullProgress())
    con = sqlite3.connect(db)
    assert con.execute("SELECT COUNT(*) FROM keypoints").fetchone()[0] == 1
    con.close()
    assert not os.path.exists(str(db) + ".before-escalation")


def test_round_two_counts_the_pairs_round_one_found_even_when_its_result_was_not_kept(tmp_path, monkeypatch):
    """Round 1 verifies a pair for c but maps no better, so its database is put back (c has no pair there again):
    round 2 still runs for c, since round 1's richer features showed that c shares ground with the block."""
    import core.align.escalation as esc
    from core.common.progress import NullProgress

    db = tmp_path / "database.db"
    _sql(db, "CREATE TABLE verified (image TEXT)")
    rounds = []

    def partners():
        c = sqlite3.connect(db)
        n = c.execute("SELECT COUNT(*) FROM verified WHERE image = 'c'").fetchone()[0]
        c.close()
        return {"c": n}

    def worse_round(ctx, k, reason, ordered, left, progress, kind="faint"):
        rounds.append((k, kind, list(left)))
        if k == 1:
            _sql(ctx.db_path, "INSERT INTO verified VALUES ('c')")  # round 1's features give c a verified pair...
        return esc.EscalationRound(k, reason, kind, {n: "?" for n in left}, list(left), [], {}, 1, 2, 1, 1, 1), []

    monkeypatch.setattr(esc, "_run_round", worse_round)
    ctx = _context(db, tmp_path, ["a", "b", "c"], partners)
    esc.escalate(ctx, [_Rec(["a", "b"])], NullProgress())
    assert partners() == {"c": 0}  # ...but its database was put back (its mapping was not better)
    assert rounds == [(1, "faint", ["c"]), (2, "affine", ["c"])]  # no diagnosis: faint first
