"""The stages, their order, and the one epilogue every stage shares.

``run_stage()`` is the only place that records a stage's begin / timings / done / cancelled / failed in the
manifest and marks the later stages stale when a stage produced new results::

    with run_stage(ws, ALIGN, parameters, inputs) as run:
        with run.step("features"):
            ...
        run.finish(outputs={...}, results={...})

A stage body that raises :class:`~core.common.progress.Cancelled` is recorded ``cancelled``; any other
exception ``failed`` with its message, and is re-raised unchanged.  Leaving the block without calling
``finish()`` is recorded ``done`` with no outputs.  When the outcome cannot be written (the disk that made the stage
fail is full) the stage's own error is still the one raised, with the recording failure as a note.

The record names its owner (host, pid, process start); a stage found ``running`` whose owner is gone (killed,
crashed, or its outcome could not be written) reads ``interrupted`` on the next open, and a stage running in
another live process is not started twice (``Workspace.begin_stage``).
"""
from __future__ import annotations

import contextlib
import logging
import time
from typing import Any, Dict, Iterator, List, Optional

from ..common.errors import ArchaeoOrthoError
from ..common.progress import Cancelled

log = logging.getLogger("archaeoortho")

# stage status values (the manifest's "status" of a stage)
PENDING = "pending"
RUNNING = "running"
DONE = "done"
FAILED = "failed"
CANCELLED = "cancelled"
STALE = "stale"
INTERRUPTED = "interrupted"  # found running whose process is gone (killed, crashed, power cut)
STATUSES = (PENDING, RUNNING, DONE, FAILED, CANCELLED, STALE, INTERRUPTED)

PREPARE = "prepare"
ALIGN = "align"
GEOREFERENCE = "georeference"
DSM = "dsm"
ORTHOPHOTO = "orthophoto"
REPORT = "report"
TERRAIN = "terrain"  # DTM (+ contours) from the DSM
RELIEF = "relief"  # relief visualisations of the DTM or DSM
MODEL = "model"  # the textured 3-D model (core.model)

# the order data flows in; a stage that finishes marks the done stages after it stale
STAGE_ORDER: List[str] = [PREPARE, ALIGN, GEOREFERENCE, DSM, ORTHOPHOTO, TERRAIN, RELIEF, MODEL, REPORT]


class StageError(ArchaeoOrthoError, RuntimeError):
    """A stage cannot run yet with these inputs (a product of an earlier stage missing, no ground control
    given, ...); the message says why and what to run or give."""


class StageRun:
    """What a stage body records while it runs (see :func:`run_stage`)."""

    def __init__(self, ws: "Workspace", name: str):  # noqa: F821 (project.workspace.Workspace)
        self.ws = ws
        self.name = name
        self.timings: Dict[str, float] = {}
        self.outputs: Optional[Dict[str, Any]] = None
        self.results: Optional[Dict[str, Any]] = None
        self.t_start = time.time()

    @property
    def record(self) -> Dict[str, Any]:
        """The stage's manifest record (for stage-specific keys)."""
        return self.ws.data["stages"][self.name]

    @contextlib.contextmanager
    def step(self, step: str, save: bool = True) -> Iterator[None]:
        """Time a step; the seconds go into the manifest's timings for this stage."""
        t0 = time.time()
        yield
        self.timings[step] = time.time() - t0
        self.ws.record_timing(self.name, step, self.timings[step])
        if save:
            self.ws.save()

    def elapsed(self) -> float:
        return time.time() - self.t_start

    def finish(self, outputs: Optional[Dict[str, Any]] = None, results: Optional[Dict[str, Any]] = None) -> None:
        """The outputs (paths relative to the workspace) and key results to record when the stage ends."""
        self.outputs = outputs
        self.results = results


def _record_end(ws, name: str, status: str, error: BaseException, message: str) -> None:
    """Record a stage's cancel or failure; when that cannot be written either (the disk that made the stage fail
    is full), the stage's own error stays the one raised: the recording failure becomes a note on it and a log
    line, and the record is left running, read as interrupted on the next open (its process is gone then)."""
    try:
        ws.end_stage(name, status, error=message)
    except Exception as record_error:  # noqa: BLE001 - never hide the stage's own error behind this one
        note = f"(the stage could not be recorded {status} in the workspace either: {record_error})"
        log.warning("%s: %s %s", name, message, note)
        if hasattr(error, "add_note"):
            error.add_note(note)


@contextlib.contextmanager
def run_stage(ws: "Workspace",  # noqa: F821 (project.workspace.Workspace)
              name: str, parameters: Dict[str, Any], inputs: Optional[Dict[str, str]] = None,
              invalidate: bool = True) -> Iterator[StageRun]:
    """Run a stage body and record its outcome in the workspace manifest (see the module docstring)."""
    ws.begin_stage(name, parameters, inputs)
    run = StageRun(ws, name)
    try:
        yield run
    except Cancelled as e:
        _record_end(ws, name, CANCELLED, e, "cancelled by the user")
        raise
    except BaseException as e:
        _record_end(ws, name, FAILED, e, str(e) or type(e).__name__)
        raise
    ws.end_stage(name, DONE, outputs=run.outputs, results=run.results)
    if invalidate:
        ws.invalidate_after(name, STAGE_ORDER)
