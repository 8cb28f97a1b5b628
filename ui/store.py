"""The GCP dock's state: one workspace, its ground control (georef/control.json), the last adjustment's
residuals and an undo stack.  Every edit is saved at once, atomically."""
import copy
import json
import math
import os

from qgis.PyQt.QtCore import QCoreApplication, QObject, pyqtSignal

try:  # Qt6 moved the undo framework to QtGui
    from qgis.PyQt.QtGui import QUndoCommand, QUndoStack
except ImportError:
    from qgis.PyQt.QtWidgets import QUndoCommand, QUndoStack

from ..core.common.files import atomic_write_text
from ..core.io import gcp as gcpmod
from ..core.project.layout import Layout
from ..core.project.stages import GEOREFERENCE
from ..core.project.workspace import Workspace


class _Snapshot(QUndoCommand):
    def __init__(self, store, before, after, text):
        super().__init__(text)
        self.store = store
        self.before = before
        self.after = after
        self._first = True

    def redo(self):
        if self._first:  # the edit is already applied when the command is pushed
            self._first = False
            return
        self.store._set_state(self.after)

    def undo(self):
        self.store._set_state(self.before)


class GcpStore(QObject):
    """Ground control of one workspace with undo; emits ``changed`` after every edit."""

    changed = pyqtSignal()
    workspaceChanged = pyqtSignal()  # noqa: N815 (Qt signal naming)
    residualsChanged = pyqtSignal()  # noqa: N815

    def __init__(self, parent=None):
        super().__init__(parent)
        self.workspace = None
        self.gcps = gcpmod.GCPSet(crs="")
        self.residuals = {}  # point name -> residual row of georef/residuals.json
        self.figures = {}
        self.stale = set()  # points edited since the last adjustment
        self.undo_stack = QUndoStack(self)
        self.settings = {}

    def tr(self, text):
        return QCoreApplication.translate("GcpStore", text)

    # --- workspace
    @property
    def root(self):
        return self.workspace.root if self.workspace is not None else None

    @property
    def layout(self):
        """Where the workspace's products live (core.project.layout.Layout), None without a workspace."""
        return Layout(self.workspace) if self.workspace is not None else None

    def open(self, path):
        """Open a workspace folder (raises core.workspace.WorkspaceError)."""
        ws = Workspace.open(path)
        self.workspace = ws
        self.gcps = self._load_control(ws)
        self.settings = self._load_json(Layout(ws).editor_json) or {}
        self.undo_stack.clear()
        self.stale = set()
        self.load_residuals()
        self.workspaceChanged.emit()
        self.changed.emit()

    def reload_workspace(self):
        """Re-read workspace.json (after a stage ran) without touching the GCPs."""
        if self.workspace is not None:
            self.workspace = Workspace.open(self.workspace.root)

    @staticmethod
    def _load_json(path):
        if not os.path.isfile(path):
            return None
        try:
            with open(path, encoding="utf-8") as f:
                return json.load(f)
        except (OSError, ValueError):
            return None

    def _load_control(self, ws):
        data = self._load_json(Layout(ws).control_json)
        if data:
            gs = gcpmod.GCPSet.from_dict(data)
        else:
            gs = gcpmod.GCPSet(crs=ws.crs or "")
        if not gs.crs:
            gs.crs = ws.crs or ""
        return gs

    def images(self):
        """[{name, path, width, height}] of the workspace's photos, in manifest order."""
        if self.workspace is None:
            return []
        out = []
        base = self.workspace.data.get("images_dir") or ""
        for im in self.workspace.data.get("images", []):
            path = im.get("path") or os.path.join(base, im["name"])
            out.append({"name": im["name"], "path": path, "width": im.get("width"), "height": im.get("height")})
        return out

    def image_sizes(self):
        return {im["name"]: (im["width"], im["height"]) for im in self.images() if im["width"] and im["height"]}

    @property
    def crs(self):
        return self.gcps.crs or (self.workspace.crs if self.workspace is not None else "") or ""

    def stage_done(self, stage):
        return self.workspace is not None and self.workspace.stage_done(stage)

    # --- saving
    def save(self):
        if self.workspace is None:
            return
        lay = self.layout
        os.makedirs(lay.georef_dir, exist_ok=True)
        data = self.gcps.to_dict()
        data["warnings"] = []
        atomic_write_text(lay.control_json, json.dumps(data, indent=1))

    def save_settings(self, **values):
        self.settings.update(values)
        if self.workspace is None:
            return
        lay = self.layout
        os.makedirs(lay.georef_dir, exist_ok=True)
        atomic_write_text(lay.editor_json, json.dumps(self.settings, indent=1))

    # --- residuals of the last adjustment
    def load_residuals(self):
        self.residuals, self.figures = {}, {}
        if self.workspace is not None and self.workspace.stage_done(GEOREFERENCE):
            data = self._load_json(self.layout.residuals_json) or {}
            self.residuals = {p["name"]: p for p in data.get("points", [])}
            self.figures = dict(self.workspace.stage(GEOREFERENCE).get("results") or {})
        self.stale = set()
        self.residualsChanged.emit()

    # --- state and undo
    def _snapshot(self):
        return copy.deepcopy(self.gcps.to_dict())

    def _set_state(self, state):
        self.gcps = gcpmod.GCPSet.from_dict(copy.deepcopy(state))
        self.save()
        self.changed.emit()

    def edit(self, text, fn):
        """Apply ``fn(gcps)`` as one undoable step named ``text``; returns what ``fn`` returns."""
        before = self._snapshot()
        result = fn(self.gcps)
        after = self._snapshot()
        if after == before:
            return result
        self.save()
        self.undo_stack.push(_Snapshot(self, before, after, text))
        self.changed.emit()
        return result

    # --- edits
    def new_name(self):
        names = {p.name for p in self.gcps.points}
        k = len(self.gcps.points) + 1
        while f"gcp{k:02d}" in names:
            k += 1
        return f"gcp{k:02d}"

    def add_point(self, name=None, x=math.nan, y=math.nan, z=math.nan, role=gcpmod.CONTROL):
        name = name or self.new_name()
        if self.gcps.by_name(name) is not None:
            raise ValueError(self.tr("a point named {} exists already").format(name))

        def fn(gs):
            gs.points.append(gcpmod.GroundPoint(name, float(x), float(y), float(z), role=role))
            return name
        return self.edit(self.tr("add point {}").format(name), fn)

    def remove_point(self, name):
        self.stale.discard(name)

        def fn(gs):
            gs.points = [p for p in gs.points if p.name != name]
        return self.edit(self.tr("remove point {}").format(name), fn)

    def set_point(self, name, **fields):
        """Change name, x, y, z, sigma_xy, sigma_z or role of one point."""
        if "name" in fields and fields["name"] != name and self.gcps.by_name(fields["name"]) is not None:
            raise ValueError(self.tr("a point named {} exists already").format(fields["name"]))

        def fn(gs):
            p = gs.by_name(name)
            if p is None:
                return
            for k, v in fields.items():
                setattr(p, k, v)
        if any(k in fields for k in ("x", "y", "z", "role")):
            self.stale.add(fields.get("name", name))
        what = ", ".join(sorted(fields))
        return self.edit(self.tr("set {} of {}").format(what, name), fn)

    def set_observation(self, name, image, x, y):
        def fn(gs):
            p = gs.by_name(name)
            if p is None:
                return
            for o in p.observations:
                if o.image == image:
                    o.x, o.y = float(x), float(y)
                    return
            p.observations.append(gcpmod.Observation(image, float(x), float(y)))
        self.stale.add(name)
        return self.edit(self.tr("place {} in {}").format(name, image), fn)

    def remove_observation(self, name, image):
        def fn(gs):
            p = gs.by_name(name)
            if p is not None:
                p.observations = [o for o in p.observations if o.image != image]
        self.stale.add(name)
        return self.edit(self.tr("remove {} from {}").format(name, image), fn)

    def replace_all(self, gcpset, text, merge=False):
        """Import: replace the ground control (or, with ``merge``, add points and observations by name)."""
        def fn(gs):
            new = copy.deepcopy(gcpset)
            if not merge:
                gs.crs = new.crs or gs.crs
                gs.points = new.points
                return
            if not gs.crs:
                gs.crs = new.crs
            for p in new.points:
                old = gs.by_name(p.name)
                if old is None:
                    gs.points.append(p)
                    continue
                old.x, old.y, old.z = p.x, p.y, p.z
                old.sigma_xy, old.sigma_z, old.role = p.sigma_xy, p.sigma_z, p.role
                have = {o.image for o in old.observations}
                old.observations += [o for o in p.observations if o.image not in have]
        self.stale.update(p.name for p in gcpset.points)
        return self.edit(text, fn)

    def set_crs(self, crs):
        return self.edit(self.tr("set CRS"), lambda gs: setattr(gs, "crs", crs))

    # --- for the adjustment
    def usable_gcps(self):
        """A copy with the points that have coordinates (points still without X/Y/Z are left out)."""
        gs = copy.deepcopy(self.gcps)
        gs.points = [p for p in gs.points if all(math.isfinite(v) for v in (p.x, p.y, p.z))]
        gs.warnings = []
        return gs
