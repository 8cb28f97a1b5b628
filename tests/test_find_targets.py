"""Find targets (issue 34): the detectors against a rendered block's truth, and the targets file's errors.

The block (tests/targets_scene.py) is a tilted ground plane with checkerboard, circular and ArUco targets seen from
nadir and oblique shots; one target is covered by a pole in one photo, others are cut by photo borders.  What is
asserted here is what the detectors achieve today; the whole chain (ties, constellation, names) is not yet asserted
(see the issue's report: the constellation match still refuses the synthetic block as ambiguous).
"""
import math

import numpy as np
import pytest

from core.georef.targets.detect import detect_image
from core.io import gcp as gcpmod
from tests import targets_scene


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    return targets_scene.render(str(tmp_path_factory.mktemp("targets") / "photos"))


def _errors(scene, kind):
    kinds = {t.name: t.kind for t in scene.targets}
    found, errors, occluded = 0, [], 0
    for name, path in scene.photos.items():
        cands = detect_image(name, path, ("checkerboard", "circle", "cross"), ("DICT_4X4_50",), 8, 0.2)
        for tn in scene.visible[name]:
            if kinds[tn] != kind:
                continue
            tx, ty = scene.truth[name][tn]
            d = [math.hypot(c.x - tx, c.y - ty) for c in cands if c.kind == kind]
            found += 1
            errors.append(min(d) if d and min(d) < 2.0 else None)
        for im, tn in scene.occluded:
            if im == name:
                tx, ty = scene.truth[name][tn]
                occluded += any(math.hypot(c.x - tx, c.y - ty) < 3.0 for c in cands)
    return errors, occluded


@pytest.mark.parametrize("kind, rms_px, max_px", [("checkerboard", 0.2, 0.3), ("aruco", 0.35, 0.8)])
def test_targets_whole_in_the_photo_are_found_at_sub_pixel(scene, kind, rms_px, max_px):
    errors, occluded = _errors(scene, kind)
    assert len(errors) >= 8  # the block shows each kind whole several times
    hits = [e for e in errors if e is not None]
    assert len(hits) >= 0.95 * len(errors), f"{kind}: {len(hits)} of {len(errors)} found"
    assert math.sqrt(np.mean(np.square(hits))) <= rms_px and max(hits) <= max_px, hits
    assert occluded == 0  # the target under the pole is left out, not guessed


def test_targets_file_errors_name_the_file_and_line(tmp_path):
    p = tmp_path / "targets.txt"
    p.write_text("235269.88 3811198.11 0.0 gcp02\n")
    with pytest.raises(gcpmod.GCPError, match=r"targets.txt:1: no CRS line .*give the CRS"):
        gcpmod.read_target_coordinates(str(p))
    gs = gcpmod.read_target_coordinates(str(p), "EPSG:32611")
    assert [(q.name, q.x, q.observations) for q in gs.points] == [("gcp02", 235269.88, [])]
    p.write_text("EPSG:32611\n1 2 3 a\n1 2 3 10 20 IMG_1.jpg b\n5 6\n")
    with pytest.raises(gcpmod.GCPError, match=r"targets.txt:4: expected 'x y z name'"):
        gcpmod.read_target_coordinates(str(p))
    p.write_text("EPSG:32611\n1 2 3 a\n1 2 4 10 20 IMG_1.jpg a\n")
    with pytest.raises(gcpmod.GCPError, match=r"targets.txt:3: target a has coordinates .* on line 2"):
        gcpmod.read_target_coordinates(str(p))
