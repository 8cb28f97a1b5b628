"""Walls at full resolution (issue 14 item 1: "edges of buildings kept sharp"): the scene of tests/test_dense.py
photographed at 3 x the linear size, matched at full quality.

What decides the path a pair takes through ``core.dense.stereo``: ``pyramid_levels`` halves a rectified pair while
its search is wider than PYRAMID_MAX_DISPARITIES and a level's short side stays >= PYRAMID_MIN_SIDE (96 px), so a
300 px tall photo (test_dense's 400 x 300 block) gets one level (300 / 4 < 96); the finest level is matched in
tiles of TILE_PX rows; and a tile is matched both ways where EDGE_MIN_PIXELS (200) pixels of the coarser level
mark a depth edge, which a wall's band reaches only on larger photos (test_dense's walls test, at 400 x 300, does
not reach it: docs/measurements.md).  The photos here are 1200 px wide and 720 tall, past all three: the test
asserts the size and that every pair took 2-3 levels and matched runs both ways.

To keep it cheap the block is six of the twelve photos, three of each strip, around the building at (18, -11)
(the one whose wall was the worst at 4 x, 1600 x 1200 px: 0.29-0.31 m), each cropped to the sensor's top 720 of
900 rows (the same lens, cx and cy kept; the rows dropped show ground far from that building in both strips).  The
walls are judged in metres: every DSM cell on the wrong side of the roof's half height lies within
WALL_TOLERANCE_M of the roof's true outline.  Measured (7 Dec, 3 x, six photos of 1200 x 720): 10 pairs, 2-3
levels each, 39 of 96 finest-level runs both ways (2-7 per pair), cells of 0.077 m (1.87 GSD), the building's wall
3.0 cells (0.23 m) off its outline.  Earlier at 4 x (twelve photos of 1600 x 1200, 24 pairs, 97 of 406 runs both
ways, 0.058 m cells): 0.29 m (5.1 cells); at 400 x 300 the worst is 1.4 cells of 0.23 m (0.32 m).  So the walls are
as sharp in metres as at the small size, not in cells: a regression guard, not the issue's goal.  (At 4 x with the
two-way matching switched off they were 0.29 m too: on this block it does not sharpen them.)
The photos are rendered once and cached under build/test-cache (about 20 CPU s).
"""
import dataclasses
import glob
import json
import os

import numpy as np
import pytest

from core.dense import stage as dense
from core.dense import stereo
from core.dense.options import DenseOptions
from tests import synthetic as syn
from tests.test_dense import _truth_grid, make_workspace, wall_offsets
from tests.workspaces import rendered_once

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "build", "test-cache", "dense-walls-x3-crop720-v2")
SCALE = 3
ROWS = 720  # the sensor's top rows kept (of 300 x SCALE)
PHOTOS = ("S1_04.jpg", "S1_05.jpg", "S1_06.jpg", "S2_01.jpg", "S2_02.jpg", "S2_03.jpg")  # around the building
BUILDING = (18, -11)  # the building the six photos see whole (its centre, rounded)
WALL_TOLERANCE_M = 0.35  # measured 0.23 m (3.0 cells) here; 0.29 m at 4 x, 0.32 m at 1 x

pytestmark = pytest.mark.slow


def _block():
    """test_dense's block at SCALE (the same scene and poses), six of its photos, their sensor cropped to ROWS."""
    f = SCALE
    camera = syn.CameraModel(400 * f, 300 * f, 325.0 * f, 325.0 * f, 201.9 * f, 148.1 * f, k1=-0.08, k2=0.02,
                             p1=0.0006, p2=-0.0004)
    block = syn.vertical_block(seed=8, camera=camera, altitude=40.0, n_strips=2, per_strip=6, forward_overlap=0.8,
                               side_overlap=0.5, gcp_grid=(2, 2), roofs=0)
    return dataclasses.replace(block, camera=camera.with_params(height=ROWS),
                               shots=[s for s in block.shots if s.name in PHOTOS])


@pytest.fixture(scope="module")
def walls(tmp_path_factory):
    block = _block()
    images = rendered_once(block, CACHE)
    root = tmp_path_factory.mktemp("dense walls")
    ws = make_workspace(str(root / "ws"), block, images_dir=images)
    r = dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=1))
    return block, ws, r


def _pyramids(ws):
    """The pyramid summary of every matched pair (the pair cache's own record)."""
    out = []
    for path in glob.glob(os.path.join(ws, "dense", "pairs-*", "*.npz")):
        s = np.load(path, allow_pickle=True)["summary"]
        s = s.item() if s.dtype == object else json.loads(str(s))
        out.append(s["pyramid"])
    return out


def test_full_resolution_pairs_reach_the_two_way_path(walls):
    block, ws, r = walls
    assert len(block.shots) == len(PHOTOS)
    # the size is past the thresholds (at 400 x 300: 300 // 4 < PYRAMID_MIN_SIDE, one band of tiles)
    assert min(block.camera.width, block.camera.height) // 4 >= stereo.PYRAMID_MIN_SIDE  # room for two halvings
    assert block.camera.height > stereo.TILE_PX  # the finest level is matched in more than one band of tiles
    pyramids = _pyramids(ws)
    assert len(pyramids) == r.pairs >= 8  # 10 among the six photos (24 among twelve at 4 x)
    assert min(p["levels"] for p in pyramids) >= 2  # coarse to fine over at least two halvings
    assert min(p["tiles_two_way"] for p in pyramids) >= 1  # every pair crosses EDGE_MIN_PIXELS somewhere
    assert sum(p["tiles_two_way"] for p in pyramids) >= 20  # the edges' runs matched both ways


def test_walls_stay_sharp_at_full_resolution(walls):
    block, _, r = walls
    z, gt, _, x, y, truth = _truth_grid(block, r.dsm_path)
    cell = abs(gt[1])
    assert cell < 2.3 * block.gsd  # the full-quality grid, 2 x the GSD (0.077 m; half quality's would be 4 x)
    offsets = wall_offsets(block, z, x, y, truth)
    worst = {(round(b.cx), round(b.cy)): cells * cell for b, cells in offsets}  # metres from the true outline
    assert BUILDING in worst, worst  # seen whole and judged
    assert max(worst.values()) <= WALL_TOLERANCE_M, worst
