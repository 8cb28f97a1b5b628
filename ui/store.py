"""The GCP dock's state: one workspace, its ground control (georef/control.json), the last adjustment's
residuals and an undo stack.  Every edit is saved at once, atomically.

Observations found by Find targets (issue 34) carry a mark until the user confirms them: ``found``
{point: {image: {x, y, quality, kind, source, residual_px}}}, saved beside the points in the dock's own
control.json (key "found"; the ODM file format does not change).  A mark holds only while its observation stays
where it was found: moved by hand, the observation is the user's; removed (rejected), the mark goes with it."""
import copy
import json
import math
import os

from qgis.PyQt.QtCore import QCoreApplication, QEvent, QObject, pyqtSignal
from qgis.PyQt.QtGui import QKeySequence

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


class UndoKeys(QObject):
    """Ctrl+Z / Ctrl+Shift+Z (QKeySequence.Undo / Redo) on a widget (the photo view, the table) undo and redo the
    store's edits.  The widget claims the keys in the ShortcutOverride phase, so that no other action with the
    same shortcut (QGIS's own Undo in its main window) makes the shortcut ambiguous and nothing happens."""

    def __init__(self, stack, parent=None):
        super().__init__(parent)
        self.stack = stack

    def _which(self, event):
        if event.matches(QKeySequence.StandardKey.Undo):
            return self.stack.undo
        if event.matches(QKeySequence.StandardKey.Redo):
            return self.stack.redo
        return None

    def eventFilter(self, obj, event):  # noqa: N802 (Qt API)
        kind = event.type()
        if kind == QEvent.Type.ShortcutOverride and self._which(event) is not None:
            event.accept()
            return True
        if kind == QEvent.Type.KeyPress:
            act = self._which(event)
            if act is not None:
                act()
                event.accept()
                return True
        return super().eventFilter(obj, event)


def _differs(a, b):
    return not (a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)))


def _pruned(gs, found):
    """The marks of ``found`` whose observation is still there, where it was found."""
    out = {}
    for name, per_image in found.items():
        p = gs.by_name(name)
        if p is None:
            continue
        here = {o.image: o for o in p.observations}
        for image, info in per_image.items():
            o = here.get(image)
            if o is not None and abs(o.x - info["x"]) < 1e-6 and abs(o.y - info["y"]) < 1e-6:
                out.setdefault(name, {})[image] = info
    return out


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
        self.diagnosis = []  # the last adjustment's warnings and outlier messages (georef/residuals.json)
        self._masks = {}  # image name -> (mask path, mtime, keep array or None)
        self._undo_keys = UndoKeys(self.undo_stack, self)
        self.last_import_report = []  # what the last import changed (GcpStore.replace_all)
        self.found = {}  # point -> image -> what Find targets said of the observation, until confirmed
        self.automatic = set()  # the automatic GCPs (auto_NNN) the automatic control measured: shown as found

    def install_undo_keys(self, *widgets):
        """Ctrl+Z / Ctrl+Shift+Z undo / redo when one of ``widgets`` has the focus."""
        for w in widgets:
            w.installEventFilter(self._undo_keys)

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
        self._reset(ws)
        self.gcps, self.found = self._load_control(ws)
        self.automatic = self._load_automatic(ws, self.gcps)
        self.settings = self._load_json(Layout(ws).editor_json) or {}
        self.load_residuals()
        self.workspaceChanged.emit()
        self.changed.emit()

    def close(self):
        """No workspace shown (a new one is being made): nothing of the previous one stays (issue 48 item 4)."""
        self._reset(None)
        self.load_residuals()
        self.workspaceChanged.emit()
        self.changed.emit()

    def _reset(self, ws):
        """Everything that belongs to a workspace, emptied: the state is the one of the workspace shown."""
        self.workspace = ws
        self.gcps = gcpmod.GCPSet(crs=(ws.crs or "") if ws is not None else "")
        self.found, self.automatic, self.settings, self.stale = {}, set(), {}, set()
        self._masks = {}
        self.last_import_report = []
        self.undo_stack.clear()

    def _load_automatic(self, ws, gs):
        """The names of the table's control points that are automatic GCPs: the candidates the automatic control
        kept (georef/autocontrol.json) that the table holds with their measured observations."""
        from ..core.georef.autocontrol.record import kept_names

        kept = kept_names(Layout(ws))
        return {p.name for p in gs.points if p.name in kept and p.role == gcpmod.CONTROL and p.observations}

    def is_automatic(self, name):
        return name in self.automatic

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
        found = {}
        for f in (data or {}).get("found", []) if isinstance((data or {}).get("found"), list) else []:
            try:
                info = {k: v for k, v in f.items() if k not in ("name", "image")}
                info["x"], info["y"] = float(f["x"]), float(f["y"])
                found.setdefault(str(f["name"]), {})[str(f["image"])] = info
            except (KeyError, TypeError, ValueError, AttributeError):
                continue  # a mark the dock cannot read: the observation stays, as one placed by hand
        return gs, _pruned(gs, found)

    def images(self):
        """[{name, path, width, height, orientation}] of the workspace's photos, in manifest order (orientation:
        the EXIF orientation the alignment recorded, None in older workspaces)."""
        if self.workspace is None:
            return []
        out = []
        base = self.workspace.data.get("images_dir") or ""
        for im in self.workspace.data.get("images", []):
            path = im.get("path") or os.path.join(base, im["name"])
            out.append({"name": im["name"], "path": path, "width": im.get("width"), "height": im.get("height"),
                        "orientation": im.get("orientation")})
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
        data["found"] = [dict(info, name=name, image=image) for name, per_image in self.found.items()
                         for image, info in per_image.items()]
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
        self.residuals, self.figures, self.diagnosis = {}, {}, []
        if self.workspace is not None and self.workspace.stage_done(GEOREFERENCE):
            data = self._load_json(self.layout.residuals_json) or {}
            self.residuals = {p["name"]: p for p in data.get("points", [])}
            self.figures = dict(self.workspace.stage(GEOREFERENCE).get("results") or {})
            lines = [str(w) for w in data.get("warnings", []) if w]
            lines += [str(o["message"]) for o in data.get("outliers", []) if o.get("message")]
            self.diagnosis = list(dict.fromkeys(lines))
        self.stale = set()
        self.residualsChanged.emit()

    # --- state and undo
    def _snapshot(self):
        return {"gcps": copy.deepcopy(self.gcps.to_dict()), "found": copy.deepcopy(self.found)}

    def _set_state(self, state):
        self.gcps = gcpmod.GCPSet.from_dict(copy.deepcopy(state["gcps"]))
        self.found = copy.deepcopy(state["found"])
        self.save()
        self.changed.emit()

    def edit(self, text, fn):
        """Apply ``fn(gcps)`` as one undoable step named ``text``; returns what ``fn`` returns.  The marks of
        found observations that ``fn`` moved or removed go (``found``)."""
        before = self._snapshot()
        result = fn(self.gcps)
        self.found = _pruned(self.gcps, self.found)
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
            # no sigma typed yet: the georeferencing estimates it from the data until the user sets one
            gs.points.append(gcpmod.GroundPoint(name, float(x), float(y), float(z), role=role, sigma_given=False))
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
            if fields.get("name", name) != name and name in self.found:
                self.found[fields["name"]] = self.found.pop(name)  # a renamed point keeps its marks
        if any(k in fields for k in ("x", "y", "z", "role")):
            self.stale.add(fields.get("name", name))
        what = ", ".join(sorted(fields))
        return self.edit(self.tr("set {} of {}").format(what, name), fn)

    def _mask_keep(self, image):
        """The keep-area (True = use) of ``image``'s mask (core.prepare.masks.find_mask), None without a mask."""
        from ..core.prepare import masks as masksmod

        path = masksmod.find_mask(self.layout.masks_dir, image) if self.workspace is not None else None
        if path is None:
            self._masks.pop(image, None)
            return None
        mtime = os.path.getmtime(path)
        hit = self._masks.get(image)
        if hit is not None and hit[0] == path and hit[1] == mtime:
            return hit[2]
        try:
            w, h = masksmod.png_size(path)
            keep = masksmod.read_keep(path, w, h)
        except (masksmod.MaskError, ImportError, OSError):
            keep = None
        self._masks[image] = (path, mtime, keep)
        while len(self._masks) > 6:
            self._masks.pop(next(iter(self._masks)))
        return keep

    def position_problem(self, image, x, y, masks=True):
        """Why (x, y) cannot be an observation in ``image`` (outside the photo, with ``masks`` inside its mask),
        None if it can."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return self.tr("no position")
        if getattr(self, "_sizes", None) is None or self._sizes[0] is not self.workspace:
            self._sizes = (self.workspace, self.image_sizes())  # per workspace record (reload_workspace: a new one)
        size = self._sizes[1].get(image)
        if size is not None and not (0.0 <= x <= size[0] and 0.0 <= y <= size[1]):
            return self.tr("({:.0f}, {:.0f}) is outside the photo {} ({} × {} px)").format(
                x, y, image, size[0], size[1])
        keep = self._mask_keep(image) if masks else None
        if keep is not None:
            col = min(max(int(math.floor(x)), 0), keep.shape[1] - 1)
            row = min(max(int(math.floor(y)), 0), keep.shape[0] - 1)
            if not keep[row, col]:
                return self.tr("({:.0f}, {:.0f}) is inside the mask of {}").format(x, y, image)
        return None

    def set_observation(self, name, image, x, y):
        """Place (or move) point ``name`` in ``image``; raises ValueError (naming why) for a position outside the
        photo or inside its mask."""
        problem = self.position_problem(image, float(x), float(y))
        if problem is not None:
            raise ValueError(self.tr("{} not placed: {}").format(name, problem))

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

    def replace_all(self, gcpset, text, merge=False, given=None):
        """Import: replace the ground control (or, with ``merge``, add points and observations by name).

        Merging keeps what the user set unless the file says otherwise: a point's role and sigmas change only
        when the file gives them (``given``: {name: {"role", "sigma_xy", "sigma_z"}} as the reader saw them;
        without it, a file gives a role when it marks the point as a check point, and a sigma that is not the
        default); observations already placed stay.  Returns the list of what changed, one line per kind."""
        self.stale.update(p.name for p in gcpset.points)
        report = self.edit(text, self._merge_fn(gcpset, merge, given))
        self.last_import_report = report
        return report

    def _merge_fn(self, gcpset, merge, given, kept_text=None):
        """The edit of ``replace_all``: ``fn(gs)`` returning the report (``kept_text``: the line naming the
        observations placed that stay, with {} for their list)."""
        defaults = gcpmod.GroundPoint("", 0.0, 0.0, 0.0)

        def says(p, field):
            if given is not None:
                return field in given.get(p.name, ())
            if field == "role":
                return p.role == gcpmod.CHECK
            return _differs(getattr(p, field), getattr(defaults, field))

        def fn(gs):
            new = copy.deepcopy(gcpset)
            if not merge:
                gs.crs = new.crs or gs.crs
                n_old = len(gs.points)
                gs.points = new.points
                return [self.tr("{} points replaced by {} from the file").format(n_old, len(new.points))]
            if not gs.crs:
                gs.crs = new.crs
            added, moved, roles, kept_roles, sigmas, kept_obs = [], [], [], [], [], []
            n_obs = 0
            for p in new.points:
                old = gs.by_name(p.name)
                if old is None:
                    gs.points.append(p)
                    added.append(p.name)
                    n_obs += len(p.observations)
                    continue
                if any(_differs(a, b) for a, b in ((old.x, p.x), (old.y, p.y), (old.z, p.z))):
                    moved.append(p.name)
                old.x, old.y, old.z = p.x, p.y, p.z
                if says(p, "role") and p.role != old.role:
                    roles.append(f"{p.name} → {p.role}")
                    old.role = p.role
                elif p.role != old.role:
                    kept_roles.append(f"{p.name} ({old.role})")
                for field in ("sigma_xy", "sigma_z"):
                    if says(p, field) and _differs(getattr(old, field), getattr(p, field)):
                        sigmas.append(p.name)
                        setattr(old, field, getattr(p, field))
                have = {o.image: o for o in old.observations}
                for o in p.observations:
                    mine = have.get(o.image)
                    if mine is None:
                        old.observations.append(o)
                        n_obs += 1
                    elif _differs(mine.x, o.x) or _differs(mine.y, o.y):
                        kept_obs.append(f"{p.name} in {o.image}")
            out = []
            if added:
                out.append(self.tr("added {} points: {}").format(len(added), ", ".join(added)))
            if moved:
                out.append(self.tr("coordinates updated from the file: {}").format(", ".join(dict.fromkeys(moved))))
            if roles:
                out.append(self.tr("role set by the file: {}").format(", ".join(roles)))
            if kept_roles:
                out.append(self.tr("role kept (the file gives none): {}").format(", ".join(kept_roles)))
            if sigmas:
                out.append(self.tr("σ set by the file: {}").format(", ".join(dict.fromkeys(sigmas))))
            if n_obs:
                out.append(self.tr("{} observations added").format(n_obs))
            if kept_obs:
                out.append((kept_text or self.tr("placed observations kept (the file has others): {}")).format(
                    ", ".join(kept_obs)))
            return out or [self.tr("nothing changed")]
        return fn

    # --- observations found by Find targets
    def merge_found(self, gcpset, found, text):
        """Find targets' outcome as one undoable step: ``gcpset`` (the surveyed targets with the observations
        found) merged as an import does (``replace_all``); ``found``: {(point, image): info} with the quality.
        An observation placed by hand (or confirmed) stays and keeps no mark; one found earlier and not confirmed
        yet moves to where it is found now.  Returns the report lines."""
        merge = self._merge_fn(gcpset, True, None, self.tr("observations placed by hand kept (found ones not "
                                                          "used there): {}"))

        def fn(gs):
            mine = set()  # observations placed by hand or confirmed: they stay, unmarked, wherever they are
            for (name, image), info in found.items():
                p = gs.by_name(name)
                old = next((o for o in p.observations if o.image == image), None) if p is not None else None
                if old is not None and image in self.found.get(name, {}):
                    old.x, old.y = float(info["x"]), float(info["y"])
                elif old is not None:
                    mine.add((name, image))
            out = merge(gs)  # observations placed by hand stay: "placed observations kept" names them
            for (name, image), info in found.items():
                obs = next((o for o in gs.by_name(name).observations if o.image == image), None)
                if (name, image) not in mine and obs is not None and not _differs(obs.x, float(info["x"])) \
                        and not _differs(obs.y, float(info["y"])):
                    self.found.setdefault(name, {})[image] = dict(info, x=float(info["x"]), y=float(info["y"]))
            return out
        self.stale.update(p.name for p in gcpset.points)
        report = self.edit(text, fn)
        self.last_import_report = report
        return report

    def is_found(self, name, image):
        """The mark of the observation of ``name`` in ``image`` found by Find targets and not confirmed yet."""
        return self.found.get(name, {}).get(image)

    def found_list(self):
        """[(point, image)] of the found observations not confirmed yet, in the table's order."""
        return [(p.name, o.image) for p in self.gcps.points for o in p.observations
                if o.image in self.found.get(p.name, {})]

    def confirm_found(self, name, image):
        """The found observation becomes an ordinary one (undoable)."""
        def fn(gs):
            marks = self.found.get(name, {})
            marks.pop(image, None)
            if not marks:
                self.found.pop(name, None)
        return self.edit(self.tr("confirm {} in {}").format(name, image), fn)

    def reject_found(self, name, image):
        """The found observation goes (undoable)."""
        def fn(gs):
            p = gs.by_name(name)
            if p is not None:
                p.observations = [o for o in p.observations if o.image != image]
        self.stale.add(name)
        return self.edit(self.tr("reject {} in {}").format(name, image), fn)

    def set_crs(self, crs):
        return self.edit(self.tr("set CRS"), lambda gs: setattr(gs, "crs", crs))

    # --- for the adjustment
    def usable_gcps(self):
        """A copy with the points that have coordinates (points still without X/Y/Z are left out)."""
        gs = copy.deepcopy(self.gcps)
        gs.points = [p for p in gs.points if all(math.isfinite(v) for v in (p.x, p.y, p.z))]
        gs.warnings = []
        return gs
