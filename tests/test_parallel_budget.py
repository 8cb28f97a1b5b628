"""The automatic number of workers keeps a stage within core.common.parallel.STAGE_MEMORY (issue 46 item 3): the
DSM's matching units of 40 photos of 3600 x 2700 at quality half on a many-core machine, beside the stage's own
process, stay within 3 GiB; a small machine keeps one worker per core."""
import numpy as np

from core.common import parallel
from core.dense.options import DenseOptions
from core.dense.pairs import View
from core.dense.points import unit_memory

GIB = 2 ** 30


def _views(n=40, width=3600, height=2700):
    return {i: View(i, f"IMG_{i:04d}.jpg", "", width, height, "SIMPLE_RADIAL", (3000.0, width / 2, height / 2, 0.0),
                    np.eye(3), np.zeros(3)) for i in range(n)}


def _machine(monkeypatch, cores, available_gib, own_gib):
    monkeypatch.setattr(parallel, "cpu_count", lambda: cores)
    monkeypatch.setattr(parallel, "available_memory", lambda: int(available_gib * GIB))
    monkeypatch.setattr(parallel, "own_memory", lambda: int(own_gib * GIB), raising=False)


def test_dsm_workers_stay_within_the_stage_budget(monkeypatch):
    unit = unit_memory(_views(), DenseOptions().scale)  # quality half: 1800 x 1350 matched, ~0.36 GiB a unit
    _machine(monkeypatch, cores=16, available_gib=100.0, own_gib=0.25)
    n = parallel.auto_workers(unit)
    assert 5 <= n < 16  # as many as fit (7 at most), no more
    assert 0.25 * GIB + n * unit * parallel.UNIT_MEMORY_MARGIN <= parallel.STAGE_MEMORY


def test_small_machine_keeps_a_worker_per_core(monkeypatch):
    unit = unit_memory(_views(), DenseOptions().scale)
    _machine(monkeypatch, cores=2, available_gib=6.0, own_gib=0.25)
    assert parallel.auto_workers(unit) == 2


def test_memory_workers_bounds():
    unit = int(GIB / parallel.UNIT_MEMORY_MARGIN)  # a unit of 1 GiB with its margin
    assert parallel.memory_workers(unit, None, 0, budget=3 * GIB) == 3
    assert parallel.memory_workers(unit, 4 * GIB, 0, budget=3 * GIB) == 2  # half of what is available
    assert parallel.memory_workers(5 * unit, 100 * GIB, GIB, budget=3 * GIB) == 1  # too large: still one, alone
    assert parallel.memory_workers(unit // 2, None, 2 * GIB, budget=3 * GIB) == 2  # beside what the stage holds


def test_sift_threads_of_an_escalation_stay_within_the_stage_budget(monkeypatch):
    from core.align.features import SIFT_BYTES_PER_PX, FeatureSettings, extraction_threads

    _machine(monkeypatch, cores=16, available_gib=100.0, own_gib=0.5)
    upsampled = FeatureSettings(1632, 8192, -1)  # 2 MP of a 3600 x 2700 photo, first octave -1: 4 x the pixels
    n = extraction_threads(-1, upsampled)
    per_thread = SIFT_BYTES_PER_PX * 1632 ** 2 * 4
    assert 1 <= n < 16 and 0.5 * GIB + n * per_thread * parallel.UNIT_MEMORY_MARGIN <= parallel.STAGE_MEMORY
    assert extraction_threads(-1, FeatureSettings(1632, 4096, 0)) >= 12  # the first pass's SIFT: (nearly) every core
    assert extraction_threads(3, upsampled) == 3  # the user's NUM_THREADS is kept
