"""GCP files that also list observations in photos outside the block (issue 13, item 2).

A real file often names photos the user left out of the aligned subset, or that did not register: the reader
uses what matches, with a warning naming the lines and photos left out; an error only when no observation at
all is in a photo of the block, and then the error names the block's closest photo names, so that a naming
mistake (a renamed folder, a lost zero) is obvious.  On the shared COPR file (27 observations, 10 targets),
on the CSV and point-layer forms, and through the georeference stage.
"""
import os
import re

import pytest

from core.io import gcp as gcpmod
from tests.conftest import shared

COPR_LEFT_OUT = ("IMG_0031.jpg", "IMG_0052.jpg", "IMG_0121.jpg")


def _copr_lines():
    """[(line number, image, point)] of the shared COPR gcp_list.txt, parsed here independently."""
    out = []
    with open(shared("copr", "gcp_list.txt")) as f:
        for n, line in enumerate(f, start=1):
            t = line.split()
            if n > 1 and len(t) >= 7 and not t[0].startswith("#"):
                out.append((n, t[5], t[6]))
    return out


def _copr_block(left_out=COPR_LEFT_OUT):
    names = sorted(os.listdir(shared("copr", "images")))
    return [n for n in names if n not in left_out]


def test_observations_in_photos_left_out_of_the_block_are_ignored_with_a_warning_naming_them():
    path = shared("copr", "gcp_list.txt")
    rows = _copr_lines()
    assert len(rows) == 27
    block = _copr_block()
    gs = gcpmod.read_gcps(path, image_names=block, image_sizes={n: (1200, 800) for n in block})
    kept = [r for r in rows if r[1] not in COPR_LEFT_OUT]
    gone = [r for r in rows if r[1] in COPR_LEFT_OUT]
    assert gs.n_observations() == len(kept) and len(gone) == 6
    for n, image, point in kept:
        assert image in gs.by_name(point).images()
    assert all(image not in COPR_LEFT_OUT for image in gs.image_names())
    summary = [w for w in gs.warnings if "that are not in the block" in w]
    assert len(summary) == 1
    assert f"{len(gone)} observation(s) in 3 photo(s)" in summary[0]
    assert all(image in summary[0] for image in COPR_LEFT_OUT) and f"{len(kept)} observation(s) match" in summary[0]
    for image in COPR_LEFT_OUT:
        lines = [n for n, im, _ in gone if im == image]
        points = [p for _, im, p in gone if im == image]
        w = next(w for w in gs.warnings if f"image {image!r} is not in the block" in w)
        assert w.startswith(f"{path}:{lines[0]}: ")  # file:line of the first
        assert re.search(r"lines? " + ", ".join(map(str, lines)) + r";", w), w
        assert all(p in w for p in points)
    # a point seen only in left-out photos says so (gcp00 is seen in IMG_0031 only)
    assert gs.by_name("gcp00").observations == [] and "image not in the block" in gs.by_name("gcp00").dropped
    assert any("point gcp00 has no usable observation" in w for w in gs.warnings)


def test_no_matching_photo_at_all_is_an_error_that_names_the_closest_photo_names(tmp_path):
    # the photos were renamed (a lost zero): nothing matches, and the message shows the naming mistake
    src = open(shared("copr", "gcp_list.txt")).read().splitlines()
    bad = [src[0]] + [re.sub(r"IMG_0(\d\d\d)", r"IMG_\1", line) for line in src[1:]]
    path = tmp_path / "gcp_list.txt"
    path.write_text("\n".join(bad) + "\n")
    block = _copr_block(())
    with pytest.raises(gcpmod.GCPError) as e:
        gcpmod.read_gcps(str(path), image_names=block)
    msg = str(e.value)
    assert msg.startswith(f"{path}: none of its 27 observation(s) is in a photo of the block (41 photos")
    assert "'IMG_052.jpg' (lines 5, 22, closest in the block: IMG_0052.jpg" in msg  # lines and best guess
    m = re.search(r"'IMG_037\.jpg' \(line 2, closest in the block: ([^)]*)\)", msg)
    assert m and m.group(1).split(", ")[0] == "IMG_0037.jpg", msg
    # a name with nothing like it in the block says so
    path.write_text(src[0] + "\n235269.88 3811198.11 0.0 10 20 holiday.png gcp02\n")
    with pytest.raises(gcpmod.GCPError, match=r"'holiday.png' \(line 2, no similar name in the block\)"):
        gcpmod.read_gcps(str(path), image_names=block)
    # the strict mode still refuses any unknown photo, with the same hints
    with pytest.raises(gcpmod.GCPError, match=r"not in the block.*line 2: holiday\.png"):
        gcpmod.read_gcps(str(path), image_names=block, unknown_images="error")
    strict = shared("copr", "gcp_list.txt")
    with pytest.raises(gcpmod.GCPError, match=r"'IMG_0031\.jpg' \(lines 6, 23, 25, closest in the block: IMG_"):
        gcpmod.read_gcps(strict, image_names=_copr_block(), unknown_images="error")


def test_csv_and_point_layer_rows_follow_the_same_policy(tmp_path):
    pts = tmp_path / "g.csv"
    pts.write_text("# crs: EPSG:32611\nname,x,y,z\nA,235269.88,3811198.11,0\nB,235262.54,3811203.5,0\n")
    (tmp_path / "g_observations.csv").write_text(
        "name,image,px,py\nA,IMG_0037.jpg,10,20\nA,IMG_9999.jpg,11,21\nB,IMG_0043.jpg,30,40\nB,IMG_9999.jpg,1,2\n")
    gs = gcpmod.read_gcps(str(pts), image_names=["IMG_0037.jpg", "IMG_0043.jpg"])
    assert gs.n_observations() == 2
    w = next(w for w in gs.warnings if "IMG_9999.jpg" in w and "is not in the block" in w)
    assert w.startswith(f"{tmp_path / 'g_observations.csv'}:3: ") and "lines 3, 5;" in w and "A, B" in w
    rows = [{"name": "A", "x": 235269.88, "y": 3811198.11, "z": 0, "image": im, "px": 5, "py": 6}
            for im in ("IMG_0037.jpg", "img_0043.JPG", "IMG_7.jpg")]
    gs = gcpmod.gcps_from_rows(rows, "EPSG:32611", source_name="gcp layer",
                               image_names=["IMG_0037.jpg", "IMG_0043.jpg"])
    assert gs.by_name("A").images() == ["IMG_0037.jpg", "IMG_0043.jpg"]
    assert any(w.startswith("gcp layer: row 3: image 'IMG_7.jpg' is not in the block") and "row 3;" in w
               for w in gs.warnings)
    with pytest.raises(gcpmod.GCPError, match=r"gcp layer: none of its 1 observation\(s\).*'IMG_7.jpg' \(row 1"):
        gcpmod.gcps_from_rows(rows[2:], "EPSG:32611", source_name="gcp layer", image_names=["IMG_0037.jpg"])


def test_the_georeference_stage_uses_a_file_that_names_photos_outside_the_aligned_subset(tmp_path):
    """A synthetic block of which only a subset was aligned; its GCP file lists observations in every photo.
    The stage georeferences with the observations in the subset and reports the ones left out."""
    from core.georef.options import GeorefOptions
    from core.georef.stage import georeference_workspace
    from core.project.layout import Layout
    from core.project.workspace import Workspace
    from tests import synthetic as syn
    from tests.workspaces import synthetic_workspace

    block = syn.vertical_block(seed=1)
    subset = block.names[: len(block.names) - 4]
    outside = block.names[len(block.names) - 4:]
    full = block.gcp_set(block.spread_control(5), noise_px=0.3)
    in_subset = sum(1 for p in full.points for o in p.observations if o.image in subset)
    left_out = sum(1 for p in full.points for o in p.observations if o.image in outside)
    assert in_subset and left_out
    path = str(tmp_path / "gcp_list.txt")
    gcpmod.write_odm_gcp_list(full, path)
    rec = block.truth_reconstruction(n_points=600, noise_px=0.3, images=subset)
    ws = synthetic_workspace(str(tmp_path / "ws"), block, rec, names=subset)
    result = georeference_workspace(ws, GeorefOptions(gcp_path=path))
    lay = Layout(Workspace.open(ws))
    import json

    with open(lay.control_json) as f:
        control = json.load(f)
    used = [o["image"] for p in control["points"] for o in p["observations"]]
    assert len(used) == in_subset and not set(used) & set(outside)
    summary = next(w for w in result.warnings if "that are not in the block" in w)
    assert f"{left_out} observation(s) in" in summary and all(n in summary for n in outside
                                                               if any(n in p.images() for p in full.points))
    assert result.figures["GCP_N"] >= 4
    assert result.figures["GCP_RMSE_XY"] < 0.1
