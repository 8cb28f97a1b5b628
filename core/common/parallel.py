"""Run independent units of work (stereo pairs, images, tiles) on an executor.

One interface, several back-ends:

- ``serial``: in this process, one unit at a time (workers=1; tests, debugging);
- ``process``: a local :class:`concurrent.futures.ProcessPoolExecutor` (the default
  for more than one worker).  Processes are *spawned*, never forked: forking a
  running QGIS (Qt threads, GDAL caches) is unsafe.  Inside QGIS or qgis_process
  ``sys.executable`` is the QGIS binary, so the pool is told which Python to start;
- ``thread``: a thread pool (OpenCV and NumPy release the GIL in the heavy parts);
- a Dask ``distributed.Client`` when a scheduler address is given (``dask`` must be
  installed; it is optional).  Its ``submit``/future API is the same as
  ``concurrent.futures``, so :func:`run_units` drives every back-end alike.

A unit is a module-level function ``fn(unit, cancel_path)`` that returns a small,
picklable result and writes anything large to disk itself, so memory is bounded
by the units in flight, not by the block.  ``cancel_path`` names a file that
appears when the user cancels: a unit may poll :func:`cancel_requested` between
its steps and raise :class:`~.progress.Cancelled` (cancel *within* a unit).
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import shutil
import sys
import tempfile
import threading
from typing import Any, Callable, Iterator, List, Optional, Sequence, Tuple

from .errors import ArchaeoOrthoError
from .files import owned_tempdir
from .progress import Cancelled, NullProgress, Progress

KINDS = ("auto", "serial", "process", "thread")
# batch use: a Dask scheduler address in this environment variable sends every stage's units to that cluster
SCHEDULER_ENV = "ARCHAEOORTHO_DASK_SCHEDULER"
# the cancel folders run_units makes in its cancel_dir (a killed run's are removed by the next: files.clean_debris)
CANCEL_PREFIX = ".cancel-"


class ParallelError(ArchaeoOrthoError, RuntimeError):
    """The executor could not be created; the message says why."""


def cpu_count() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def available_memory() -> Optional[int]:
    """Bytes of memory available to new work (Linux /proc/meminfo), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def own_memory() -> int:
    """Bytes this process holds now (its resident set, Linux /proc/self/status), 0 where unknown."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


# the automatic number of workers keeps a stage -- this process and its workers, each holding one unit -- within
# this many bytes (issue 46: at most 3 GiB a stage; the DSM's matching units of 10 MP photos at quality half hold
# 0.36 GiB each, and one per core of a 12-core machine took the stage to 4.5 GiB). A WORKERS given is not bounded.
STAGE_MEMORY = 3 * 2 ** 30
UNIT_MEMORY_MARGIN = 1.1  # the units' estimates (e.g. core.dense.points.unit_memory) lie within ~10 % of their peaks


def auto_workers(unit_memory: int = 0, max_workers: int = 0) -> int:
    """Workers for this machine: one per core, fewer when ``unit_memory`` bytes per unit would not fit in half of
    the available memory, nor beside this process's own memory within STAGE_MEMORY (:func:`memory_workers`)."""
    n = cpu_count()
    if unit_memory > 0:
        n = min(n, memory_workers(unit_memory, available_memory(), own_memory()))
    if max_workers > 0:
        n = min(n, max_workers)
    return max(1, n)


def memory_workers(unit_memory: int, available: Optional[int], own: int, budget: int = STAGE_MEMORY) -> int:
    """How many units of ``unit_memory`` bytes may be in flight at once: within half of the ``available`` memory
    (None: unknown) and, beside the ``own`` bytes of the process that waits for them, within ``budget`` (each unit
    counted UNIT_MEMORY_MARGIN times its estimate); at least one (a unit larger than the budget still runs, alone)."""
    room = budget - own
    if available:
        room = min(room, 0.5 * available)
    return max(1, int(room // (unit_memory * UNIT_MEMORY_MARGIN)))


def python_executable() -> Optional[str]:
    """The Python interpreter of *this* installation, to start pool workers with.

    Inside QGIS or qgis_process Python is embedded: ``sys.executable`` is then whatever ``python3`` comes
    first on PATH (a pyenv shim, say), another interpreter with another standard library, so it is used
    only when it lives under this interpreter's prefix; otherwise ``<exec_prefix>/bin/pythonX.Y``."""
    exe = sys.executable or ""
    prefixes = {os.path.realpath(p) + os.sep for p in (sys.prefix, sys.exec_prefix, sys.base_exec_prefix) if p}
    if exe and os.path.isfile(exe) and os.path.basename(exe).lower().startswith("python"):
        if any(exe.startswith(p) or os.path.realpath(exe).startswith(p) for p in
               prefixes | {os.path.abspath(sys.prefix) + os.sep}):
            return exe
    ver = f"{sys.version_info.major}.{sys.version_info.minor}"
    candidates = []
    for root in dict.fromkeys((sys.exec_prefix, sys.base_exec_prefix)):
        if os.name == "nt":  # pragma: no cover - QGIS on Windows ships python.exe in its apps folder
            candidates.append(os.path.join(root, "python.exe"))
        candidates += [os.path.join(root, "bin", f"python{ver}"), os.path.join(root, "bin", "python3")]
    for c in candidates:
        if os.path.isfile(c):
            return c
    return None


class SerialExecutor(cf.Executor):
    """Runs each unit at submit time in this process: no pickling, no start-up."""

    def submit(self, fn, /, *args, **kwargs):
        fut: cf.Future = cf.Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except BaseException as e:  # noqa: B036 - stored on the future, re-raised by result()
            fut.set_exception(e)
        return fut


def resolve_scheduler(scheduler: Optional[str] = None) -> Optional[str]:
    """The Dask scheduler address to use: the one given, else ``$ARCHAEOORTHO_DASK_SCHEDULER``, else None."""
    address = (scheduler or "").strip() or os.environ.get(SCHEDULER_ENV, "").strip()
    return address or None


# the whole Dask connection (connect, handshake, the first request) must be done within this many seconds
# (the connect_timeout argument; this environment variable overrides it, for batch use)
DASK_TIMEOUT_ENV = "ARCHAEOORTHO_DASK_TIMEOUT"


def _dask_deadline(connect_timeout: float) -> float:
    raw = os.environ.get(DASK_TIMEOUT_ENV, "").strip()
    try:
        value = float(raw) if raw else float(connect_timeout)
    except ValueError:
        raise ParallelError(f"${DASK_TIMEOUT_ENV} must be a number of seconds; it is {raw!r}") from None
    return value if value > 0 else 30.0


def _connect_dask(client_class, address: str, connect_timeout: float) -> _DaskExecutor:
    """Connect to the Dask scheduler at ``address`` in a thread with a hard deadline for the whole handshake: a
    service that accepts the connection but never answers like a scheduler (a web server) cannot hang the stage,
    and whatever goes wrong (refused, timed out, a garbage reply that makes the protocol decoder raise
    ValueError or MemoryError) is one ParallelError naming the address."""
    deadline = _dask_deadline(connect_timeout)
    lock, box, done = threading.Lock(), {}, threading.Event()

    def connect() -> None:
        try:
            client = client_class(address, timeout=deadline, set_as_default=False)
            executor = _DaskExecutor(client)
        except BaseException as e:  # noqa: B036 - reported as text; the exception (and its client) stay here
            box["error"] = f"{type(e).__name__}: {e}" if str(e) else type(e).__name__
            box["kind"] = "network" if isinstance(e, (OSError, TimeoutError)) else "protocol"
        else:
            with lock:
                late = box.get("abandoned", False)
                box["executor"] = executor
            if late:  # the caller gave up: do not leave a client connected
                with contextlib.suppress(Exception):
                    client.close()
        finally:
            done.set()

    threading.Thread(target=connect, name="archaeoortho-dask-connect", daemon=True).start()
    finished = done.wait(deadline + 1.0)
    with lock:
        if not finished:
            box["abandoned"] = True
    if not finished:
        raise ParallelError(f"cannot reach a Dask scheduler at {address}: no Dask handshake within {deadline:g} s "
                            "(the address answers, but not as a Dask scheduler: check the host and the port, 8786 by "
                            f"default; ${DASK_TIMEOUT_ENV} sets the time allowed)")
    if "error" in box:
        hint = ("" if box["kind"] == "network" else
                " (the reply is not Dask's protocol: is this the scheduler's port, 8786 by default?)")
        raise ParallelError(f"cannot reach a Dask scheduler at {address}: {box['error']}{hint}")
    return box["executor"]


def make_executor(workers: int = 0, kind: str = "auto", scheduler: Optional[str] = None,
                  unit_memory: int = 0, connect_timeout: float = 30.0):
    """An executor for units of work.

    ``workers`` 0 = one per core (bounded by ``unit_memory``: :func:`auto_workers`); ``kind`` auto = serial for one worker,
    else processes; ``scheduler`` = a Dask scheduler address (tcp://host:8786; default
    ``$ARCHAEOORTHO_DASK_SCHEDULER``) to use a cluster, whose workers must see the same paths (a shared
    file system) and have this plugin's ``core`` importable.  The caller shuts it down
    (``with make_executor(...) as ex:``)."""
    scheduler = resolve_scheduler(scheduler)
    if scheduler:
        try:
            from dask.distributed import Client  # optional dependency
        except ImportError as e:
            raise ParallelError(f"a Dask scheduler ({scheduler}) was given but dask.distributed is not installed "
                                "in the Python that runs ArchaeoOrtho (pip install 'dask[distributed]')") from e
        return _connect_dask(Client, scheduler, connect_timeout)
    if kind not in KINDS:
        raise ParallelError(f"unknown executor kind {kind!r}; choose one of {', '.join(KINDS)}")
    n = workers if workers and workers > 0 else auto_workers(unit_memory)
    if kind == "serial" or (kind == "auto" and n <= 1):
        return SerialExecutor()
    if kind == "thread":
        return cf.ThreadPoolExecutor(max_workers=n)
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    exe = python_executable()
    if exe is None:  # no interpreter to spawn: threads still use the cores for OpenCV work
        return cf.ThreadPoolExecutor(max_workers=n)
    if exe != sys.executable:
        ctx.set_executable(exe)
    return cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=worker_init, initargs=(os.getpid(),))


PR_SET_PDEATHSIG = 1


def worker_init(parent_pid: int) -> None:
    """Pool worker start-up: the worker dies with the process that started the pool (kill -9 of qgis_process must
    not orphan workers that keep ~100 MB each for ever).  Linux: the kernel sends SIGTERM when the parent dies
    (prctl PR_SET_PDEATHSIG); everywhere: a watchdog thread exits when the parent is gone (the parent pid
    changes: re-parented to init)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            import ctypes
            import signal

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)
    if os.getppid() != parent_pid:  # the parent died before prctl took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent_pid,), name="archaeoortho-parent-watchdog",
                     daemon=True).start()


def _watch_parent(parent_pid: int, interval: float = 1.0) -> None:
    while True:
        threading.Event().wait(interval)
        if os.getppid() != parent_pid:
            os._exit(1)


def describe_executor(executor) -> str:
    """'2 worker(s)' locally, 'Dask cluster tcp://...: 8 worker thread(s)' on a cluster."""
    n = getattr(executor, "_max_workers", 1) or 1
    if isinstance(executor, _DaskExecutor):
        return f"Dask cluster {executor.address}: {n} worker thread(s)"
    return f"{n} worker(s)"


class _DaskExecutor:
    """The concurrent.futures subset run_units needs, on a dask.distributed Client."""

    def __init__(self, client):
        self.client = client
        self.address = client.scheduler.address
        self._max_workers = max(1, sum(client.nthreads().values()))

    def submit(self, fn, *args, **kwargs):
        return _DaskFuture(self.client.submit(fn, *args, pure=False, **kwargs))

    def shutdown(self, wait=True, cancel_futures=False):
        self.client.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()
        return False


class _DaskFuture:
    def __init__(self, fut):
        self.fut = fut

    def done(self):
        return self.fut.done()

    def result(self, timeout=None):
        return self.fut.result(timeout=timeout)

    def cancel(self):
        self.fut.cancel()
        return True


def max_in_flight(executor) -> int:
    n = getattr(executor, "_max_workers", 1) or 1
    return 1 if isinstance(executor, SerialExecutor) else 2 * n


def cancel_requested(cancel_path: Optional[str]) -> bool:
    return bool(cancel_path) and os.path.exists(cancel_path)


def check_unit_cancel(cancel_path: Optional[str]) -> None:
    """For units: raise Cancelled when the cancel file exists."""
    if cancel_requested(cancel_path):
        raise Cancelled("cancelled by the user")


class _CancelFile:
    """Creates ``cancel_path`` when ``progress.is_cancelled()`` turns true (polled by a thread)."""

    def __init__(self, progress: Progress, folder: Optional[str] = None):
        self.progress = progress
        self.dir = owned_tempdir(CANCEL_PREFIX, folder) if folder else tempfile.mkdtemp(prefix=CANCEL_PREFIX)
        self.path = os.path.join(self.dir, "cancel")
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self._stop.wait(0.2):
            if self.progress.is_cancelled():
                self.set()
                return

    def set(self):
        with contextlib.suppress(OSError):
            open(self.path, "w").close()

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(timeout=1)
        shutil.rmtree(self.dir, ignore_errors=True)
        return False


def run_units(executor, fn: Callable[[Any, Optional[str]], Any], units: Sequence[Any],
              progress: Optional[Progress] = None, label: str = "unit",
              describe: Optional[Callable[[Any], str]] = None,
              cancel_dir: Optional[str] = None) -> Iterator[Tuple[int, Any]]:
    """Run ``fn(unit, cancel_path)`` for every unit; yield (index, result) as each one finishes.

    Reports progress per finished unit, hears a cancel within ~0.2 s (pending units are dropped,
    running ones see the cancel file), then raises Cancelled.  The first failing unit's
    exception is re-raised after the others are cancelled."""
    progress = progress or NullProgress()
    total = len(units)
    if total == 0:
        return
    limit = max_in_flight(executor)
    done_count = 0
    with _CancelFile(progress, cancel_dir) as cancel:
        pending: dict = {}
        next_i = 0

        def fill():
            nonlocal next_i
            while next_i < total and len(pending) < limit:
                if progress.is_cancelled():
                    return
                pending[executor.submit(fn, units[next_i], cancel.path)] = next_i
                next_i += 1

        try:
            fill()
            while pending:
                if progress.is_cancelled():
                    cancel.set()
                    raise Cancelled("cancelled by the user")
                finished = [f for f in pending if f.done()]
                if not finished:
                    _wait_any(list(pending), 0.2)
                    continue
                for f in finished:
                    i = pending.pop(f)
                    result = f.result()  # re-raises the unit's exception
                    done_count += 1
                    what = describe(units[i]) if describe else f"{label} {i + 1}"
                    progress.report(done_count / total, f"{label} {done_count}/{total}: {what}")
                    yield i, result
                fill()
            if progress.is_cancelled():
                raise Cancelled("cancelled by the user")
        except BaseException:
            cancel.set()
            for f in pending:
                f.cancel()
            _wait_all(list(pending), 30.0)
            raise


def _wait_any(futures: List[Any], timeout: float) -> None:
    cf_futs = [f for f in futures if isinstance(f, cf.Future)]
    if len(cf_futs) == len(futures):
        cf.wait(cf_futs, timeout=timeout, return_when=cf.FIRST_COMPLETED)
    else:  # Dask futures: poll
        threading.Event().wait(timeout)


def _wait_all(futures: List[Any], timeout: float) -> None:
    """Let running units see the cancel file and stop (they must not write after we return)."""
    cf_futs = [f for f in futures if isinstance(f, cf.Future)]
    if cf_futs:
        cf.wait(cf_futs, timeout=timeout)


__all__ = ["make_executor", "resolve_scheduler", "describe_executor", "SCHEDULER_ENV", "run_units", "check_unit_cancel", "cancel_requested", "auto_workers", "cpu_count",
           "ParallelError", "SerialExecutor", "python_executable", "worker_init", "CANCEL_PREFIX"]
