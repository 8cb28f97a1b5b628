"""The GCP dock's Find targets (issue 34 item 4): surveyed coordinates in, observations found on the photos out.

"Import > Find targets on the photos…" (a menu item: one more toolbar button would not fit the dock's width in
German) asks for the surveyed coordinates (a CSV ``name,x,y,z[,sigma_xy,sigma_z]`` or an ODM
gcp_list.txt; a file that names no CRS is taken in the table's CRS, else the workspace's), the target kind and,
optionally, the target's size, and runs core.georef.targets.stage.find_targets in a ui.tasks.CoreTask (progress,
cancel; the GUI stays responsive).  When it ends, the targets and the observations found fill the table as ONE
undoable step (GcpStore.merge_found): an observation the user placed by hand stays, a found one never overwrites
it.  Found observations carry a mark (GcpStore.found, saved in the dock's control.json) until the user confirms
them: drawn in blue in the photo with the detector's quality, the point's row in blue with a tooltip.

One key per found observation, in the photo view and in the table: Space or Enter confirms the found observation
shown (it becomes an ordinary observation), Delete, Backspace or R rejects it (removed, undoable); both go on to
the next found observation.  Georeference uses the found observations as they are, confirmed or not: only the
rejected ones are gone (the button's tooltip says so while some are unconfirmed).  What did not fit (names the
constellation does not take, targets not found) is listed in the dock's message area.

A mixin of ui.gcp_dock.GcpDock; its strings are in the dock's translation context.
"""
import dataclasses
import math

from qgis.core import Qgis
from qgis.gui import QgsFileWidget
from qgis.PyQt.QtCore import QCoreApplication, QEvent, QObject, Qt
from qgis.PyQt.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QVBoxLayout,
)

from ..core.project.stages import ALIGN
from ..qgisio import layers
from .tasks import CoreTask

translate = QCoreApplication.translate

CONFIRM_KEYS = (Qt.Key.Key_Space, Qt.Key.Key_Return, Qt.Key.Key_Enter)
REJECT_KEYS = (Qt.Key.Key_Delete, Qt.Key.Key_Backspace, Qt.Key.Key_R)
FOUND_COLOUR = "#1f6fd1"  # a found observation not confirmed yet: the photo's marker and the table's row


def find_targets_task(root, targets, options, progress=None):
    """In the worker thread: Find targets, and the surveyed points as the file gives them (sigmas, roles) for the
    table.  Returns (FindTargetsResult, GCPSet)."""
    from ..core.georef.targets.stage import find_targets
    from ..core.io import gcp as gcpmod

    result = find_targets(root, dataclasses.replace(options, targets=targets), progress=progress)
    return result, gcpmod.read_target_coordinates(targets, options.crs)


def found_info(o):
    """What the dock keeps of a FoundObservation (JSON-ready)."""
    res = float(o.residual_px)
    return {"x": float(o.x), "y": float(o.y), "quality": round(float(o.quality), 3), "kind": str(o.kind),
            "source": str(o.source), "residual_px": round(res, 3) if math.isfinite(res) else None}


def found_text(info):
    """One line on a found observation: its kind, quality and triangulation residual."""
    text = translate("GcpDock", "found by Find targets ({}), quality {:.2f}").format(info.get("kind", "?"),
                                                                                    float(info.get("quality", 0.0)))
    if info.get("residual_px") is not None:
        text += translate("GcpDock", ", {:.2f} px from the other photos' rays").format(float(info["residual_px"]))
    return text


class FindTargetsDialog(QDialog):
    """The surveyed coordinates file, the target kind and the target's size."""

    def __init__(self, parent=None, folder="", crs=""):
        from ..core.georef.targets.options import KINDS

        super().__init__(parent)
        self.setWindowTitle(translate("GcpDock", "Find targets"))
        lay = QVBoxLayout(self)
        form = QFormLayout()
        self.file = QgsFileWidget(self)
        self.file.setStorageMode(QgsFileWidget.StorageMode.GetFile)
        self.file.setDefaultRoot(folder or "")
        self.file.setFilter(translate("GcpDock", "Surveyed coordinates (*.csv *.txt);;All files (*)"))
        self.file.setToolTip(translate("GcpDock", "A CSV name,x,y,z[,sigma_xy,sigma_z] or an ODM gcp_list.txt (its "
                                                  "pixel columns may be absent)"))
        form.addRow(translate("GcpDock", "Surveyed coordinates:"), self.file)
        self.kind = QComboBox(self)
        for k in KINDS:
            # the kinds as Processing's Find targets shows them ("Choices": 'Schachbrett (checkerboard)')
            self.kind.addItem(translate("GcpDock", "auto (crosses, checkerboards, circles, ArUco 4x4)")
                              if k == "auto" else translate("Choices", k), k)
        form.addRow(translate("GcpDock", "Target kind:"), self.kind)
        self.size_spin = QDoubleSpinBox(self)
        self.size_spin.setRange(0.0, 100.0)
        self.size_spin.setDecimals(3)
        self.size_spin.setSuffix(" m")
        self.size_spin.setSpecialValueText(translate("GcpDock", "unknown"))
        self.size_spin.setToolTip(translate("GcpDock", "The target's side or diameter: marks of another size are left out"))
        form.addRow(translate("GcpDock", "Target size:"), self.size_spin)
        lay.addLayout(form)
        note = QLabel(translate("GcpDock", "A file that names no CRS is read in {}.").format(crs) if crs else
                      translate("GcpDock", "The file must name its CRS (the table and the workspace have none)."))
        note.setWordWrap(True)
        lay.addWidget(note)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        lay.addWidget(buttons)

    def values(self):
        """(path, kind, target size or None)."""
        return self.file.filePath(), self.kind.currentData(), (self.size_spin.value() or None)


class FoundKeys(QObject):
    """Space / Enter confirm, Delete / Backspace / R reject the found observation shown, on the widgets it is
    installed on (the photo view, the table); other keys, and these keys when no found observation is shown, go
    on to the widget (the photo view's own Space / Enter / Delete: accept a prediction, remove an observation)."""

    def __init__(self, dock, table=None):
        super().__init__(dock)
        self.dock = dock
        self.table = table

    def _action(self, obj, key):
        if key not in CONFIRM_KEYS + REJECT_KEYS:
            return None
        if self.dock.current_found() is not None:
            return self.dock.confirm_found if key in CONFIRM_KEYS else self.dock.reject_found
        if obj is self.table and self.dock.point_found_list():  # the row's found observations, none shown yet
            return self.dock.show_point_found
        return None

    def eventFilter(self, obj, event):  # noqa: N802 (Qt API)
        kind = event.type()
        if kind not in (QEvent.Type.ShortcutOverride, QEvent.Type.KeyPress) or event.modifiers() & (
                Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier):
            return super().eventFilter(obj, event)
        if self.table is not None and obj is self.table and self.table.state() == self.table.State.EditingState:
            return super().eventFilter(obj, event)
        act = self._action(obj, event.key())
        if act is None:
            return super().eventFilter(obj, event)
        event.accept()
        if kind == QEvent.Type.KeyPress:
            act()
        return True


class GcpTargets:
    """The dock's 'Find targets…' action, its task and the confirmation of what it found."""

    def _build_targets_action(self, menu):
        self.act_find_targets = menu.addAction(translate("GcpDock", "Find targets on the photos\u2026"))
        self.act_find_targets.setToolTip(translate(
            "GcpDock", "Find the surveyed targets on the aligned photos (in the background): their observations "
                       "fill the table, marked as found until you confirm them (Space or Enter) or reject them "
                       "(Delete or R)"))
        menu.setToolTipsVisible(True)
        self.act_find_targets.triggered.connect(self.choose_find_targets)
        return self.act_find_targets

    def _install_found_keys(self):
        self._found_keys = FoundKeys(self, self.table)
        for w in (self.table, self.photo_panel.view):
            w.installEventFilter(self._found_keys)
        self.photo_panel.found_info = self._found_marker
        self.model.found_info = self._found_row
        self.store.changed.connect(self._found_tooltip)

    # ------------------------------------------------------------------ the task
    def choose_find_targets(self):
        if self.store.workspace is None:
            return None
        from .gcp_table import short_crs

        dlg = FindTargetsDialog(self, self.store.root or "", short_crs(self.store.crs) if self.store.crs else "")
        if dlg.exec() != QDialog.DialogCode.Accepted:
            return None
        path, kind, size = dlg.values()
        if not path:
            return None
        return self.run_find_targets(path, kind, size)

    def run_find_targets(self, targets, kind="auto", target_size=None):
        """Find targets in a background task; never raises (messages in the dock)."""
        from ..core.georef.targets.options import FindTargetsOptions

        if self.store.workspace is None or self._busy():
            return None
        if not self.store.stage_done(ALIGN):
            self.message(translate("GcpDock", "The block is not aligned yet: run Align images first"),
                         Qgis.MessageLevel.Warning)
            return None
        options = FindTargetsOptions(kind=kind or "auto", target_size=target_size or None, crs=self.store.crs or None)
        root = self.store.root

        def done(outcome):
            self._task_ended()
            self.progress.setValue(100)
            if self.store.root != root:  # another workspace was opened meanwhile
                return
            self._found_done(*outcome)

        self.targets_result = None
        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: find targets"), find_targets_task, (root, targets, options),
                        on_done=done, on_error=self._task_failed)
        self.message(translate("GcpDock", "Looking for the targets of {} on the photos\u2026").format(targets))
        return self._start_task(task)

    def _found_done(self, result, survey):
        """The targets and the observations found into the table (one undoable step), what did not fit said."""
        self.targets_result = result
        found = {}
        for p in survey.points:
            p.observations = []
        by_name = {p.name: p for p in survey.points}
        from ..core.io import gcp as gcpmod

        for o in result.observations:
            if o.name in by_name:
                by_name[o.name].observations.append(gcpmod.Observation(o.image, float(o.x), float(o.y)))
                if o.found:  # else: the user's click in the targets file, which no mark answered: as placed by hand
                    found[(o.name, o.image)] = found_info(o)
        if not survey.crs:
            survey.crs = result.crs
        if self.store.crs and self.store.gcps.points and layers.qgs_crs(survey.crs) != layers.qgs_crs(self.store.crs):
            from ..core.geometry.crs import transform_points  # the table's CRS, as an import does (GcpImportExport)

            out = transform_points([(p.x, p.y, p.z) for p in survey.points], survey.crs, self.store.crs)
            for p, q in zip(survey.points, out):
                p.x, p.y = float(q[0]), float(q[1])
            survey.crs = self.store.crs
        lines = self.store.merge_found(survey, found, translate("GcpDock", "find targets"))
        self.load_predictor()  # the table's CRS may be the file's now (GcpPlacement)
        text = translate("GcpDock", "Find targets: {} of {} targets found, {} observations, in {:.0f} s.").format(
            result.n_targets, len(result.targets), result.n_observations, result.seconds)
        missing = [t.name for t in result.targets if not t.found]
        details = []  # what did not fit first, then what the table gained
        if missing:
            details.append(translate("GcpDock", "not found: {}").format(", ".join(missing)))
        details += list(result.reports)
        details += [f"{t.name}: {t.note}" for t in result.targets if t.found and t.note]
        details += list(lines)
        if self.store.found_list():
            details.append(translate("GcpDock", "Space or Enter: confirm the found observation shown; Delete or R: "
                                                "reject it (the keys work in the table, which has the keyboard "
                                                "focus now, and in the photo view). Georeference uses the found "
                                                "observations that are not rejected, confirmed or not."))
        level = Qgis.MessageLevel.Success if result.n_observations and not result.reports and not missing \
            else Qgis.MessageLevel.Warning
        self.message("\n".join([text] + details), level)
        if self.store.found_list():
            self.show_found(*self.store.found_list()[0])
            self._focus_found_keys()

    def _focus_found_keys(self):
        """The table takes the keyboard focus, so that Space / R act at once (they did nothing until a row was
        clicked: issue 48 item 3); not while the user types in a text field elsewhere."""
        from qgis.PyQt.QtWidgets import QAbstractSpinBox, QApplication, QLineEdit, QPlainTextEdit, QTextEdit

        if not isinstance(QApplication.focusWidget(), (QLineEdit, QAbstractSpinBox, QTextEdit, QPlainTextEdit)):
            self.table.setFocus(Qt.FocusReason.OtherFocusReason)

    # ------------------------------------------------------------------ showing and confirming
    def current_found(self):
        """(point, image) of the found observation shown in the photo view, None when it shows none."""
        name, image = self.current_name(), self.photo_panel.image
        if name and image and self.store.is_found(name, image) is not None:
            return name, image
        return None

    def point_found_list(self):
        name = self.current_name()
        return [k for k in self.store.found_list() if k[0] == name]

    def show_found(self, name, image):
        if self.current_name() != name:
            self.select_point(name)
        if self.photo_panel.image != image:
            self.show_photo(image)
        else:
            self._update_photo(zoom=True)

    def show_point_found(self):
        left = self.point_found_list()
        if left:
            self.show_found(*left[0])

    def _order(self):
        return [(p.name, o.image) for p in self.store.gcps.points for o in p.observations]

    def _next_found(self, at):
        """The found observation after position ``at`` of the table's order (wrapping round), None when none."""
        left = set(self.store.found_list())
        order = self._order()
        for k in order[at:] + order[:at]:
            if k in left:
                return k
        return None

    def _act_on_found(self, act):
        cur = self.current_found()
        if cur is None:
            return False
        at = self._order().index(cur)
        act(*cur)
        nxt = self._next_found(at)
        if nxt is not None:
            self.show_found(*nxt)
        else:
            self._update_photo()
            self.message(translate("GcpDock", "Every found observation is confirmed or rejected"))
        return True

    def confirm_found(self):
        """Space / Enter: the found observation shown becomes an ordinary one; the next one is shown."""
        return self._act_on_found(self.store.confirm_found)

    def reject_found(self):
        """Delete / R: the found observation shown goes (undoable); the next one is shown."""
        return self._act_on_found(self.store.reject_found)

    def _found_marker(self, name, image):
        """(tooltip, hint) of the photo view's marker when it is a found observation, else None."""
        info = self.store.is_found(name, image) if name and image else None
        if info is None:
            return None
        return found_text(info), translate("GcpDock", "Found by Find targets, not confirmed: Space or Enter "
                                                      "confirms it, Delete or R rejects it (then the next one); "
                                                      "the keys work in the table and in this photo view.")

    def _mark_found_thumbnails(self):
        """The strip's photos where the selected point has a found observation not confirmed: in blue, the
        tooltip with its quality."""
        from qgis.PyQt.QtGui import QColor

        name = self.current_name()
        marks = self.store.found.get(name) if name else None
        strip = self.photo_panel.thumbs
        for i in range(strip.count() if marks else 0):
            item = strip.item(i)
            info = marks.get(item.data(Qt.ItemDataRole.UserRole))
            if info is not None:
                item.setForeground(QColor(FOUND_COLOUR))
                item.setToolTip(item.toolTip() + "\n" + found_text(info))

    def _found_row(self, name):
        """The table's tooltip line for a point with found observations not confirmed, else None."""
        marks = self.store.found.get(name)
        if not marks:
            return None
        return translate("GcpDock", "{} observations found by Find targets, not confirmed: {}").format(
            len(marks), "; ".join(f"{image} {found_text(info)}" for image, info in sorted(marks.items())))

    def _found_tooltip(self):
        """The Georeference button says that it uses the found observations not confirmed yet."""
        self._autocontrol_toggled(self.auto_box.isChecked())

    def _autocontrol_toggled(self, on):
        super()._autocontrol_toggled(on)
        if hasattr(self, "btn_georef") and not on and getattr(self, "store", None) is not None \
                and self.store.found_list():
            self.btn_georef.setToolTip(self.btn_georef.toolTip() + "\n" + translate(
                "GcpDock", "{} found observations are not confirmed yet: they are used as they are (reject the "
                           "wrong ones first)").format(len(self.store.found_list())))
