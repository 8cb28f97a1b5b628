"""The on-disk project that flows between stages.

A workspace is a folder with ``workspace.json`` (the manifest) and one
sub-folder per stage.  The manifest records the format version, the CRS, the
image list and camera groups, and for every stage: parameters, fingerprints of
its inputs, status, timings and output paths.

Every write of the manifest is atomic (temporary file + ``os.replace``), and a
manifest that is damaged or written by a newer format version is never
overwritten: opening it raises :class:`WorkspaceError`.

Several processes may work on one workspace at once (two stages started together, the dock and a
``qgis_process`` run): every write is a read-modify-write under a lock (``workspace.json.lock``).  What this
object changed since it last read or wrote the manifest (a stage record, the CRS, the image list) replaces the
manifest's value; everything else comes from the manifest on disk, so no process drops another's stage record.
A stage that ends done after an earlier stage of the flow finished while it ran was made from that stage's
previous products: it is recorded stale, not done.
"""
from __future__ import annotations

import contextlib
import copy
import datetime as _dt
import json
import os
import tempfile
import time
from typing import Any, Dict, Iterator, List, Optional

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_write_text, clean_partials, owner_alive, process_owner
from .stages import DONE, INTERRUPTED, PENDING, RUNNING, STAGE_ORDER, STALE, STATUSES

FORMAT_VERSION = 1
MANIFEST = "workspace.json"
LOCK = MANIFEST + ".lock"
LOCK_TIMEOUT_S = 60.0  # a writer holds the lock for a read and a write of a small file: far less than this

# (workspace root, stage) of the stages this process runs now: a "running" record of this process that is not
# here ended without recording its outcome (the manifest could not be written: disk full)
_ACTIVE: set = set()

class WorkspaceError(ArchaeoOrthoError, RuntimeError):
    """A workspace that cannot be opened or written; the message says why."""


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


class Workspace:
    """A workspace folder.  Use :meth:`create_or_open` or :meth:`open`."""

    def __init__(self, root: str, data: Dict[str, Any]):
        self.root = os.path.abspath(root)
        self.data = data
        self._t0: Dict[str, float] = {}
        self._base: Dict[str, Any] = copy.deepcopy(data)  # the manifest as last read or written here
        self._lock_depth = 0
        self._lock_file = None

    # --- opening -------------------------------------------------------
    @classmethod
    def open(cls, root: str) -> Workspace:
        path = os.path.join(root, MANIFEST)
        if not os.path.isfile(path):
            raise WorkspaceError(f"{root} is not an ArchaeoOrtho workspace: {MANIFEST} is missing")
        try:
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise WorkspaceError(
                f"{path} is damaged and cannot be read ({e}); it was left untouched. "
                "Repair it or choose another workspace folder."
            ) from e
        if not isinstance(data, dict) or "format_version" not in data:
            raise WorkspaceError(f"{path} is not an ArchaeoOrtho manifest (no format_version); left untouched")
        version = data.get("format_version")
        if not isinstance(version, int) or version > FORMAT_VERSION:
            raise WorkspaceError(
                f"{path} was written by a newer ArchaeoOrtho (format {version}, this version reads up to "
                f"{FORMAT_VERSION}); update the plugin. The workspace was left untouched."
            )
        check_shape(path, data)
        data.setdefault("stages", {})
        data.setdefault("images", [])
        data.setdefault("camera_groups", [])
        ws = cls(root, data)
        ws._mark_interrupted()
        return ws

    def _mark_interrupted(self) -> None:
        """A stage recorded running whose process is gone (kill -9, crash, a failure that could not be recorded)
        reads as interrupted; the manifest is written with it at the next save."""
        for name, rec in self.data["stages"].items():
            if rec.get("status") != RUNNING:
                continue
            owner = rec.get("owner")
            alive = owner_alive(owner)
            if alive is None:
                continue  # cannot tell: another host, or no owner recorded (an older version)
            ours = owner.get("pid") == os.getpid()
            if alive and (not ours or (self.root, name) in _ACTIVE):
                continue  # running now, in another process or in this one
            rec["status"] = INTERRUPTED
            rec["error"] = (f"interrupted: the process that ran it (pid {owner.get('pid')} on {owner.get('host')}, "
                            f"started {rec.get('started')}) ended without recording the outcome (killed, crashed "
                            "or the workspace could not be written); run the stage again")

    @classmethod
    def create_or_open(cls, root: str) -> Workspace:
        root = os.path.abspath(root)
        if os.path.isfile(os.path.join(root, MANIFEST)):
            return cls.open(root)
        if os.path.exists(root) and not os.path.isdir(root):
            raise WorkspaceError(f"workspace path {root} exists and is not a folder")
        try:
            os.makedirs(root, exist_ok=True)
        except OSError as e:
            raise WorkspaceError(f"cannot create workspace folder {root}: {e.strerror}") from e
        check_writable(root)
        ws = cls(
            root,
            {
                "format_version": FORMAT_VERSION,
                "created": _now(),
                "crs": None,
                "images_dir": None,
                "images": [],
                "camera_groups": [],
                "stages": {},
            },
        )
        ws.save()
        return ws

    # --- paths ---------------------------------------------------------
    def path(self, *parts: str) -> str:
        return os.path.join(self.root, *parts)

    def subdir(self, *parts: str) -> str:
        p = self.path(*parts)
        os.makedirs(p, exist_ok=True)
        return p

    @property
    def manifest_path(self) -> str:
        return self.path(MANIFEST)

    # --- manifest ------------------------------------------------------
    def save(self) -> None:
        """Write the manifest: under the lock, what this object changed over what is on disk now."""
        with self.locked():
            self._merge_from_disk()
            self.data["modified"] = _now()
            try:
                atomic_write_text(self.manifest_path, json.dumps(self.data, indent=2, sort_keys=False, default=str))
            except OSError as e:
                raise WorkspaceError(f"cannot write {self.manifest_path}: {e.strerror or e}") from e
            self._base = copy.deepcopy(self.data)

    @contextlib.contextmanager
    def locked(self) -> Iterator[None]:
        """Hold the workspace's manifest lock (re-entrant within this object): other processes' saves wait."""
        if self._lock_depth:
            self._lock_depth += 1
            try:
                yield
            finally:
                self._lock_depth -= 1
            return
        try:
            f = open(self.path(LOCK), "a+b")
        except OSError as e:
            raise WorkspaceError(f"cannot write {self.path(LOCK)}: {e.strerror or e}") from e
        try:
            _lock(f, self.path(LOCK))
            self._lock_depth, self._lock_file = 1, f
            try:
                yield
            finally:
                self._lock_depth, self._lock_file = 0, None
                _unlock(f)
        finally:
            f.close()

    def _merge_from_disk(self) -> None:
        """Take into ``self.data`` what other processes wrote since this object last read or wrote the manifest:
        every top-level value and stage record this object has not changed itself (records are updated in place,
        so a record held by a running stage stays the one in the manifest)."""
        try:
            with open(self.manifest_path, encoding="utf-8") as f:
                disk = json.load(f)
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            return  # gone or damaged since it was opened: this object's view is the one to write
        if not isinstance(disk, dict) or _shape_problem(disk) or disk.get("format_version") != FORMAT_VERSION:
            return
        base = self._base
        for key, value in disk.items():
            if key in ("stages", "modified"):
                continue
            if key not in self.data or self.data.get(key) == base.get(key):
                self.data[key] = value
        ours, base_stages = self.data.setdefault("stages", {}), base.get("stages") or {}
        for name, rec in (disk.get("stages") or {}).items():
            mine = ours.get(name)
            if mine is None:
                ours[name] = rec
            elif mine == base_stages.get(name) and mine != rec:
                mine.clear()
                mine.update(rec)

    def stage(self, name: str) -> Dict[str, Any]:
        return self.data["stages"].get(name, {"status": PENDING})

    def require_writable(self) -> None:
        """WorkspaceError naming the folder when it cannot be written (read-only, another user's): the one check
        every stage makes before its work (``begin_stage``; the automatic control and the pipeline call it
        first, as they work before their stages begin)."""
        check_writable(self.root)

    def stage_done(self, name: str) -> bool:
        return self.stage(name).get("status") == DONE

    def begin_stage(self, name: str, parameters: Dict[str, Any], inputs: Optional[Dict[str, str]] = None) -> None:
        """Record ``name`` running in this process (its owner: host, pid, process start).  Refuses while another
        live process runs the same stage; otherwise the partial files of killed runs go first.  A workspace that
        cannot be written is refused here, before the stage's work (issue 36 item 13: a read-only one failed after
        it)."""
        self.require_writable()
        with self.locked():
            self._merge_from_disk()
            self._begin_stage(name, parameters, inputs)

    def _begin_stage(self, name: str, parameters: Dict[str, Any], inputs: Optional[Dict[str, str]]) -> None:
        rec = self.data["stages"].setdefault(name, {})
        self._refuse_if_running_elsewhere(name, rec)
        if not self._running_elsewhere():
            clean_partials(self.root)
        rec.update(
            {
                "status": RUNNING,
                "parameters": parameters,
                "inputs": inputs or {},
                "started": _now(),
                "finished": None,
                "error": None,
                "owner": process_owner(),
            }
        )
        rec.setdefault("timings", {})
        self._t0[name] = time.time()
        self.save()
        _ACTIVE.add((self.root, name))

    def _refuse_if_running_elsewhere(self, name: str, rec: Dict[str, Any]) -> None:
        owner = rec.get("owner")
        if rec.get("status") == RUNNING and owner_alive(owner) and owner.get("pid") != os.getpid():
            raise WorkspaceError(
                f"stage {name} of {self.root} is running in another process (pid {owner.get('pid')} on "
                f"{owner.get('host')}, since {rec.get('started')}); wait for it to end or stop it first")

    def _running_elsewhere(self) -> bool:
        """Whether another live process runs a stage of this workspace now (its partial files must stay)."""
        for rec in self.data["stages"].values():
            owner = rec.get("owner")
            if rec.get("status") == RUNNING and owner_alive(owner) is not False and (
                    not isinstance(owner, dict) or owner.get("pid") != os.getpid()):
                return True
        return False

    def record_timing(self, name: str, step: str, seconds: float) -> None:
        rec = self.data["stages"].setdefault(name, {})
        rec.setdefault("timings", {})[step] = round(float(seconds), 3)

    def end_stage(
        self,
        name: str,
        status: str,
        outputs: Optional[Dict[str, Any]] = None,
        results: Optional[Dict[str, Any]] = None,
        error: Optional[str] = None,
    ) -> None:
        with self.locked():
            self._merge_from_disk()
            rec = self.data["stages"].setdefault(name, {})
            t0 = self._t0.pop(name, None)
            _ACTIVE.discard((self.root, name))
            rec["status"] = status
            rec["finished"] = _now()
            if t0 is not None:
                rec.setdefault("timings", {})["total"] = round(time.time() - t0, 3)
            if outputs is not None:
                rec["outputs"] = outputs
            if results is not None:
                rec["results"] = results
            rec["error"] = error
            changed = self._earlier_finished_since(name, rec.get("started")) if status == DONE else None
            if changed:
                rec["status"] = STALE
                rec["error"] = (f"made while stage {changed} ran again (it finished at "
                                f"{self.data['stages'][changed].get('finished')}): its products may come from "
                                f"{changed}'s previous results; run {name} again")
            self.save()

    def _earlier_finished_since(self, name: str, started: Optional[str]) -> Optional[str]:
        """An earlier stage of the flow that finished done after ``started`` (while ``name`` ran; the times are in
        whole seconds, so a stage that began in the second another ended, as in a pipeline, does not count)."""
        if not started or name not in STAGE_ORDER:
            return None
        for earlier in STAGE_ORDER[:STAGE_ORDER.index(name)]:
            rec = self.data["stages"].get(earlier) or {}
            if rec.get("status") == DONE and isinstance(rec.get("finished"), str) and rec["finished"] > started:
                return earlier
        return None

    def invalidate_after(self, name: str, order: Optional[List[str]] = None) -> None:
        """Mark the stages after ``name`` in ``order`` (default: the stage order) as stale (inputs changed)."""
        if order is None:
            order = STAGE_ORDER
        if name not in order:
            return
        with self.locked():
            self._merge_from_disk()
            for later in order[order.index(name) + 1:]:
                rec = self.data["stages"].get(later)
                if rec and rec.get("status") == DONE:
                    rec["status"] = STALE
            self.save()

    # --- convenience ---------------------------------------------------
    @property
    def crs(self) -> Optional[str]:
        return self.data.get("crs")

    @crs.setter
    def crs(self, value: Optional[str]) -> None:
        self.data["crs"] = value


def _lock(f, path: str) -> None:
    """An exclusive lock on the open file ``f`` (fcntl on POSIX, msvcrt on Windows), waiting up to
    LOCK_TIMEOUT_S; WorkspaceError naming the lock file after that."""
    deadline = time.monotonic() + LOCK_TIMEOUT_S
    while True:
        try:
            if os.name == "nt":
                import msvcrt

                f.seek(0)
                msvcrt.locking(f.fileno(), msvcrt.LK_NBLCK, 1)
            else:
                import fcntl

                fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except OSError as e:
            if time.monotonic() > deadline:
                raise WorkspaceError(f"{path} stayed locked by another process for {LOCK_TIMEOUT_S:.0f} s ({e}): "
                                     "another stage may be writing this workspace; try again") from e
            time.sleep(0.02)


def _unlock(f) -> None:
    if os.name == "nt":
        import msvcrt

        f.seek(0)
        msvcrt.locking(f.fileno(), msvcrt.LK_UNLCK, 1)
    else:
        import fcntl

        fcntl.flock(f.fileno(), fcntl.LOCK_UN)


def _shape_problem(data: Dict[str, Any]) -> Optional[str]:
    """What is wrong with the structure of a manifest, or None (a hand-written schema of what the code reads)."""
    for key, kind, what in (("stages", dict, "an object of stage records"), ("images", list, "a list of images"),
                            ("camera_groups", list, "a list"), ("crs", (str, type(None)), "a CRS text or null"),
                            ("images_dir", (str, type(None)), "a folder or null")):
        if key in data and not isinstance(data[key], kind):
            return f'"{key}" is {type(data[key]).__name__}, not {what}'
    for name, rec in data.get("stages", {}).items():
        if not isinstance(rec, dict):
            return f'"stages" -> "{name}" is {json.dumps(rec)[:40]}, not a stage record (an object with "status")'
        status = rec.get("status", PENDING)
        if status not in STATUSES:
            return f'"stages" -> "{name}" -> "status" is {json.dumps(status)[:40]}, not one of {", ".join(STATUSES)}'
        for key in ("parameters", "inputs", "timings", "outputs", "results", "owner"):
            if rec.get(key) is not None and not isinstance(rec[key], dict):
                return f'"stages" -> "{name}" -> "{key}" is {type(rec[key]).__name__}, not an object'
        if rec.get("error") is not None and not isinstance(rec["error"], str):
            return f'"stages" -> "{name}" -> "error" is {type(rec["error"]).__name__}, not a text'
    for i, image in enumerate(data.get("images", [])):
        if not isinstance(image, dict) or not isinstance(image.get("name"), str):
            return f'"images" [{i}] is {json.dumps(image, default=str)[:40]}, not an image (an object with "name")'
    for i, group in enumerate(data.get("camera_groups", [])):
        if not isinstance(group, dict):
            return f'"camera_groups" [{i}] is {type(group).__name__}, not an object'
    return None


def check_shape(path: str, data: Dict[str, Any]) -> None:
    """WorkspaceError naming the file and the bad key when a manifest that is valid JSON has the wrong structure
    (it is refused like a damaged one and never rewritten)."""
    problem = _shape_problem(data)
    if problem:
        raise WorkspaceError(f"{path} is damaged: {problem}; it was left untouched. "
                             "Repair it or choose another workspace folder.")


def check_writable(folder: str) -> None:
    """Raise WorkspaceError if ``folder`` cannot be written (before any work starts)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".write-test-", dir=folder)
        os.close(fd)
        os.unlink(tmp)
    except OSError as e:
        raise WorkspaceError(f"workspace folder {folder} is not writable ({e.strerror or e}): nothing was done; "
                             "make it writable, or copy the workspace to a folder you can write") from e
