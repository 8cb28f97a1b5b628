"""The on-disk project that flows between stages (DESIGN.md §2).

A workspace is a folder with ``workspace.json`` (the manifest) and one
sub-folder per stage.  The manifest records the format version, the CRS, the
image list and camera groups, and for every stage: parameters, fingerprints of
its inputs, status, timings and output paths.

Every write of the manifest is atomic (temporary file + ``os.replace``), and a
manifest that is damaged or written by a newer format version is never
overwritten: opening it raises :class:`WorkspaceError`.
"""
from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile
import time
from typing import Any, Dict, List, Optional

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_write_text
from .stages import DONE, PENDING, RUNNING, STAGE_ORDER, STALE

FORMAT_VERSION = 1
MANIFEST = "workspace.json"



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
        data.setdefault("stages", {})
        data.setdefault("images", [])
        data.setdefault("camera_groups", [])
        return cls(root, data)

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
        self.data["modified"] = _now()
        try:
            atomic_write_text(self.manifest_path, json.dumps(self.data, indent=2, sort_keys=False, default=str))
        except OSError as e:
            raise WorkspaceError(f"cannot write {self.manifest_path}: {e.strerror or e}") from e

    def stage(self, name: str) -> Dict[str, Any]:
        return self.data["stages"].get(name, {"status": PENDING})

    def stage_done(self, name: str) -> bool:
        return self.stage(name).get("status") == DONE

    def begin_stage(self, name: str, parameters: Dict[str, Any], inputs: Optional[Dict[str, str]] = None) -> None:
        rec = self.data["stages"].setdefault(name, {})
        rec.update(
            {
                "status": RUNNING,
                "parameters": parameters,
                "inputs": inputs or {},
                "started": _now(),
                "finished": None,
                "error": None,
            }
        )
        rec.setdefault("timings", {})
        self._t0[name] = time.time()
        self.save()

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
        rec = self.data["stages"].setdefault(name, {})
        t0 = self._t0.pop(name, None)
        rec["status"] = status
        rec["finished"] = _now()
        if t0 is not None:
            rec.setdefault("timings", {})["total"] = round(time.time() - t0, 3)
        if outputs is not None:
            rec["outputs"] = outputs
        if results is not None:
            rec["results"] = results
        rec["error"] = error
        self.save()

    def invalidate_after(self, name: str, order: Optional[List[str]] = None) -> None:
        """Mark the stages after ``name`` in ``order`` (default: the stage order) as stale (inputs changed)."""
        if order is None:
            order = STAGE_ORDER
        if name not in order:
            return
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



def check_writable(folder: str) -> None:
    """Raise WorkspaceError if ``folder`` cannot be written (before any work starts)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".write-test-", dir=folder)
        os.close(fd)
        os.unlink(tmp)
    except OSError as e:
        raise WorkspaceError(f"workspace folder {folder} is not writable: {e.strerror or e}") from e
