"""Two stages of one workspace at once (issue 36, item 3): no stage record is lost (last writer used to win), and a
stage made from an earlier stage's previous products while that stage ran again is recorded stale, not done."""
from __future__ import annotations

import json
import multiprocessing
import os
import time

import pytest

from core.project.stages import DONE, RELIEF, STALE, TERRAIN, run_stage
from core.project.workspace import Workspace


def _stages(root):
    with open(os.path.join(root, "workspace.json"), encoding="utf-8") as f:
        return json.load(f)["stages"]


def test_two_workspace_objects_keep_each_others_records(tmp_path):
    """builddtm and reliefvisualisation started together: each process holds its own copy of the manifest."""
    Workspace.create_or_open(str(tmp_path)).save()
    dtm_ws, relief_ws = Workspace.open(str(tmp_path)), Workspace.open(str(tmp_path))
    dtm_ws.begin_stage(TERRAIN, {"dsm": "dsm.tif"})
    relief_ws.begin_stage(RELIEF, {"source": "dtm"})
    relief_ws.crs = "EPSG:32633"  # a top-level value changed by one of them survives the other's writes
    relief_ws.save()
    dtm_ws.end_stage(TERRAIN, DONE, outputs={"dtm": "dtm.tif"})
    dtm_ws.record_timing(TERRAIN, "extra", 1.0)
    dtm_ws.save()
    relief_ws.end_stage(RELIEF, DONE, outputs={"dtm-slrm": "terrain/relief/dtm-slrm.tif"})
    stages = _stages(tmp_path)
    assert set(stages) == {TERRAIN, RELIEF}, stages
    assert stages[TERRAIN]["status"] == DONE and stages[TERRAIN]["timings"]["extra"] == 1.0
    assert Workspace.open(str(tmp_path)).crs == "EPSG:32633"


def test_a_stage_made_while_an_earlier_one_ran_again_is_stale(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path))
    with run_stage(ws, TERRAIN, {}) as run:
        run.finish(outputs={"dtm": "dtm.tif"})
    relief_ws = Workspace.open(str(tmp_path))
    relief_ws.begin_stage(RELIEF, {"source": "dtm"})  # reads the DTM of the first run ...
    time.sleep(1.1)  # the manifest's times are whole seconds
    dtm_ws = Workspace.open(str(tmp_path))
    with run_stage(dtm_ws, TERRAIN, {}) as run:  # ... while the DTM is built again, and ends first
        run.finish(outputs={"dtm": "dtm.tif"})
    relief_ws.end_stage(RELIEF, DONE, outputs={"dtm-slrm": "terrain/relief/dtm-slrm.tif"})
    rec = _stages(tmp_path)[RELIEF]
    assert rec["status"] == STALE and "terrain" in rec["error"], rec
    # a relief run after the DTM is done as usual
    with run_stage(Workspace.open(str(tmp_path)), RELIEF, {}) as run:
        run.finish(outputs={})
    assert _stages(tmp_path)[RELIEF]["status"] == DONE


def _writer(root: str, name: str, n: int) -> None:
    ws = Workspace.open(root)
    for i in range(n):
        ws.record_timing(name, f"step{i}", float(i))
        ws.save()


@pytest.mark.skipif(os.name == "nt", reason="fork start method")
def test_processes_writing_at_once_lose_nothing(tmp_path):
    Workspace.create_or_open(str(tmp_path))
    ctx = multiprocessing.get_context("fork")
    procs = [ctx.Process(target=_writer, args=(str(tmp_path), f"stage{k}", 40)) for k in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    stages = _stages(tmp_path)
    for k in range(4):
        assert len(stages[f"stage{k}"]["timings"]) == 40, stages.get(f"stage{k}")
