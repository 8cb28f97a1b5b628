"""Walls at full resolution (issue 14 item 1: "edges of buildings kept sharp"): the synthetic block of
tests/test_dense.py rendered at 4 x the linear size (1600 x 1200 px, 16 x the pixels), matched at full quality.

At this size the pair pyramid has 2-3 levels and the finest level matches the runs along depth edges both ways
(the path a 400 x 300 block reaches only at one level).  The walls are judged in metres: every DSM cell on the
wrong side of a roof's half height lies within WALL_TOLERANCE_M of the roof's true outline.  Measured 3 Dec:
the worst wall 5.4 cells of 0.058 m (0.31 m) off the outline, one blob of 119 cells there; at 400 x 300 the
worst is 1.4 cells of 0.23 m (0.32 m).  So the walls are as sharp in metres as at the small size, not in cells
(5.4 against 1.4): a regression guard, not the issue's goal.  With the two-way matching switched off they are
0.29 m off: on this block it does not sharpen them.
The photos are rendered once and cached under build/test-cache (about a minute).
"""
import glob
import json
import os

import numpy as np
import pytest

from core.dense import stage as dense
from core.dense.options import DenseOptions
from tests import synthetic as syn
from tests.test_dense import _truth_grid, make_workspace, wall_offsets
from tests.workspaces import rendered_once

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "build", "test-cache", "dense-walls-x4-v1")
SCALE = 4
WALL_TOLERANCE_M = 0.35  # measured 0.31 m (5.4 cells); 0.29 m with the two-way matching switched off

pytestmark = pytest.mark.slow


def _block():
    f = SCALE
    camera = syn.CameraModel(400 * f, 300 * f, 325.0 * f, 325.0 * f, 201.9 * f, 148.1 * f, k1=-0.08, k2=0.02,
                             p1=0.0006, p2=-0.0004)
    return syn.vertical_block(seed=8, camera=camera, altitude=40.0, n_strips=2, per_strip=6, forward_overlap=0.8,
                              side_overlap=0.5, gcp_grid=(2, 2), roofs=0)


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
    _, ws, r = walls
    pyramids = _pyramids(ws)
    assert len(pyramids) == r.pairs >= 15
    assert min(p["levels"] for p in pyramids) >= 2  # coarse to fine over at least two halvings
    assert sum(p["tiles_two_way"] for p in pyramids) >= 20  # the edges' runs matched both ways


def test_walls_stay_sharp_at_full_resolution(walls):
    block, _, r = walls
    z, gt, _, x, y, truth = _truth_grid(block, r.dsm_path)
    cell = abs(gt[1])
    assert cell < 0.07  # the full-resolution grid (the 400 x 300 block's is 0.23 m)
    offsets = wall_offsets(block, z, x, y, truth)
    assert len(offsets) >= 2
    worst = {(round(b.cx), round(b.cy)): cells * cell for b, cells in offsets}  # metres from the true outline
    assert max(worst.values()) <= WALL_TOLERANCE_M, worst
