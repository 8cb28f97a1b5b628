"""The GCP dock: ground control of a workspace, picked on the map canvas and in the photos, with guided
placement, the adjustment re-run in a task and residuals in colour.

Two dock widgets: ``GcpDock`` (table, map tool, import / export, adjustment) and its ``photo_dock``
(photo viewer + thumbnails).  Photogrammetry lives in core/ (core.guided predicts the positions,
core.pipeline adjusts); this module only translates clicks and keys into those calls.
"""
import math
import os

import numpy as np
from qgis.core import (
    Qgis,
    QgsCoordinateTransform,
    QgsFeature,
    QgsGeometry,
    QgsMapLayerProxyModel,
    QgsPoint,
    QgsPointXY,
    QgsProject,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.gui import QgsDockWidget, QgsMapLayerComboBox
from qgis.PyQt.QtCore import QAbstractTableModel, QCoreApplication, QModelIndex, Qt, QVariant
from qgis.PyQt.QtGui import QColor, QFont, QKeySequence
from qgis.PyQt.QtWidgets import (
    QAbstractItemView,
    QAction,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QInputDialog,
    QLabel,
    QMenu,
    QMessageBox,
    QProgressBar,
    QPushButton,
    QStyledItemDelegate,
    QTableView,
    QToolBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.io import gcp as gcpmod
from . import layers
from .map_tool import GcpMapTool, GcpMarkers
from .photo_viewer import PhotoPanel
from .raster import sample_height
from .store import GcpStore
from .tasks import CoreTask, start

NAME, X, Y, Z, SXY, SZ, ROLE, OBS, DXY, DZ, PX = range(11)
EDITABLE = {NAME, X, Y, Z, SXY, SZ, ROLE}
GOOD, FAIR, BAD, NONE = QColor("#b8e6b0"), QColor("#ffe08a"), QColor("#f4a3a3"), QColor("#dddddd")


def _fmt(v, digits=3):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "\u2014"
    return f"{v:.{digits}f}"


class GcpTableModel(QAbstractTableModel):
    """The GCP table: coordinates and sigmas editable, residuals of the last adjustment in colour."""

    def __init__(self, dock):
        super().__init__(dock)
        self.dock = dock
        self.store = dock.store

    def tr(self, text):
        return QCoreApplication.translate("GcpTableModel", text)

    def headers(self):
        return [self.tr("Name"), self.tr("X"), self.tr("Y"), self.tr("Z"), self.tr("\u03c3 XY"), self.tr("\u03c3 Z"),
                self.tr("Role"), self.tr("Obs."), self.tr("dXY (m)"), self.tr("dZ (m)"), self.tr("px")]

    def role_text(self, role):
        return self.tr("check") if role == gcpmod.CHECK else self.tr("control")

    def rowCount(self, parent=QModelIndex()):  # noqa: N802, B008 (Qt API)
        return 0 if parent.isValid() else len(self.store.gcps.points)

    def columnCount(self, parent=QModelIndex()):  # noqa: N802, B008 (Qt API)
        return 0 if parent.isValid() else 11

    def headerData(self, section, orientation, role=Qt.ItemDataRole.DisplayRole):  # noqa: N802 (Qt API)
        if orientation == Qt.Orientation.Horizontal and role == Qt.ItemDataRole.DisplayRole:
            return self.headers()[section]
        if orientation == Qt.Orientation.Horizontal and role == Qt.ItemDataRole.ToolTipRole:
            tips = {DXY: self.tr("Horizontal residual after the adjustment (estimated from the photos minus given)"),
                    DZ: self.tr("Vertical residual after the adjustment"),
                    PX: self.tr("Mean reprojection error of the point's observations (pixels)"),
                    OBS: self.tr("Number of photos the point is placed in")}
            return tips.get(section)
        return None

    def residual(self, name):
        return self.store.residuals.get(name)

    def quality(self, name):
        """(colour, text) of a point's residual against the dock's tolerance."""
        r = self.residual(name)
        if r is None:
            return None, ""
        if r.get("status") == "rejected":
            return BAD, self.tr("rejected as an outlier")
        if r.get("dx") is None:
            return NONE, self.tr("not triangulated (fewer than 2 usable observations)")
        tol = max(self.dock.tolerance(), 1e-9)
        ratio = math.hypot(r["dx"], r["dy"]) / tol
        if not self.store.figures.get("PLACEHOLDER_Z") and r.get("dz") is not None:
            ratio = max(ratio, abs(r["dz"]) / (1.5 * tol))
        if ratio <= 1.0:
            return GOOD, self.tr("within the tolerance")
        if ratio <= 3.0:
            return FAIR, self.tr("up to 3 times the tolerance")
        return BAD, self.tr("more than 3 times the tolerance")

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid():
            return None
        p = self.store.gcps.points[index.row()]
        col = index.column()
        r = self.residual(p.name)
        if role in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.EditRole):
            if col == NAME:
                return p.name
            if col in (X, Y, Z):
                v = {X: p.x, Y: p.y, Z: p.z}[col]
                if role == Qt.ItemDataRole.EditRole:
                    return None if not math.isfinite(v) else v
                return _fmt(v, 3)
            if col == SXY:
                return p.sigma_xy if role == Qt.ItemDataRole.EditRole else _fmt(p.sigma_xy, 3)
            if col == SZ:
                return p.sigma_z if role == Qt.ItemDataRole.EditRole else _fmt(p.sigma_z, 3)
            if col == ROLE:
                return p.role if role == Qt.ItemDataRole.EditRole else self.role_text(p.role)
            if col == OBS:
                return len(p.observations)
            if r is None:
                return "" if col in (DXY, DZ, PX) else None
            if col == DXY:
                return _fmt(None if r.get("dx") is None else math.hypot(r["dx"], r["dy"]), 3)
            if col == DZ:
                return _fmt(r.get("dz"), 3)
            if col == PX:
                px = [o.get("px") for o in r.get("observations", []) if o.get("px") is not None]
                return _fmt(sum(px) / len(px), 2) if px else "\u2014"
        if role == Qt.BackgroundRole and col in (NAME, DXY, DZ, PX):
            colour, _ = self.quality(p.name)
            return colour
        if role == Qt.ItemDataRole.ToolTipRole:
            colour, text = self.quality(p.name)
            lines = [text] if text else []
            if r is not None:
                lines += r.get("notes", [])
            if p.name in self.store.stale and r is not None:
                lines.append(self.tr("edited since the last adjustment: run Georeference to update"))
            return "\n".join(lines) or None
        if role == Qt.ItemDataRole.FontRole and p.name in self.store.stale and col in (DXY, DZ, PX):
            f = QFont()
            f.setItalic(True)
            return f
        if role == Qt.ForegroundRole and p.name in self.store.stale and col in (DXY, DZ, PX):
            return QColor("#777777")
        if role == Qt.ItemDataRole.TextAlignmentRole and col not in (NAME, ROLE):
            return int(Qt.AlignRight | Qt.AlignVCenter)
        return None

    def flags(self, index):
        f = super().flags(index)
        if index.isValid() and index.column() in EDITABLE:
            f |= Qt.ItemIsEditable
        return f

    def setData(self, index, value, role=Qt.ItemDataRole.EditRole):  # noqa: N802 (Qt API)
        if role != Qt.ItemDataRole.EditRole or not index.isValid():
            return False
        p = self.store.gcps.points[index.row()]
        col = index.column()
        try:
            if col == NAME:
                name = str(value).strip()
                if not name or name == p.name:
                    return False
                self.store.set_point(p.name, name=name)
            elif col in (X, Y, Z, SXY, SZ):
                v = float(str(value).replace(",", "."))
                if col in (SXY, SZ) and not v > 0:
                    return False
                key = {X: "x", Y: "y", Z: "z", SXY: "sigma_xy", SZ: "sigma_z"}[col]
                self.store.set_point(p.name, **{key: v})
            elif col == ROLE:
                self.store.set_point(p.name, role=gcpmod.CHECK if value == gcpmod.CHECK else gcpmod.CONTROL)
        except ValueError as e:
            self.dock.message(str(e), Qgis.Warning)
            return False
        return True

    def refresh(self):
        self.beginResetModel()
        self.endResetModel()

    def repaint_all(self):
        """Values changed, rows did not: keeps the selection."""
        if self.rowCount():
            self.dataChanged.emit(self.index(0, 0), self.index(self.rowCount() - 1, self.columnCount() - 1))


class RoleDelegate(QStyledItemDelegate):
    def createEditor(self, parent, option, index):  # noqa: N802 (Qt API)
        combo = QComboBox(parent)
        model = index.model()
        combo.addItem(model.role_text(gcpmod.CONTROL), gcpmod.CONTROL)
        combo.addItem(model.role_text(gcpmod.CHECK), gcpmod.CHECK)
        return combo

    def setEditorData(self, editor, index):  # noqa: N802 (Qt API)
        editor.setCurrentIndex(1 if index.data(Qt.ItemDataRole.EditRole) == gcpmod.CHECK else 0)

    def setModelData(self, editor, model, index):  # noqa: N802 (Qt API)
        model.setData(index, editor.currentData(), Qt.ItemDataRole.EditRole)


class GcpDock(QgsDockWidget):
    """Ground control of one workspace.  ``iface`` may be None (tests); ``canvas`` then is given."""

    def __init__(self, iface=None, canvas=None, parent=None):
        super().__init__(parent)
        self.iface = iface
        self.canvas = canvas if canvas is not None else (iface.mapCanvas() if iface is not None else None)
        self.setObjectName("ArchaeoOrthoGcpDock")
        self.setWindowTitle(self.tr("ArchaeoOrtho ground control"))
        self.store = GcpStore(self)
        self.predictor = None
        self.predictor_note = ""
        self.predictions = {}  # image -> core.guided.Prediction for the selected point
        self._last_point = None
        self.matches = {}  # (point, image, observations) -> core.guided.Match or None: refined predictions
        self._gray = {}  # image name -> grey array for matching (a few, most recent last)
        self.task = None
        self.last_task_error = None
        self.prev_tool = None
        self.map_tool = GcpMapTool(self.canvas) if self.canvas is not None else None
        self.markers = GcpMarkers(self.canvas) if self.canvas is not None else None
        self.photo_panel = PhotoPanel()
        self.photo_dock = QgsDockWidget(parent)
        self.photo_dock.setObjectName("ArchaeoOrthoPhotoDock")
        self.photo_dock.setWindowTitle(self.tr("ArchaeoOrtho photos"))
        self.photo_dock.setWidget(self.photo_panel)
        self._build()
        self._connect()
        self._update_enabled()

    def tr(self, text):
        return QCoreApplication.translate("GcpDock", text)

    # ------------------------------------------------------------------ layout
    def _build(self):
        w = QWidget(self)
        lay = QVBoxLayout(w)
        lay.setContentsMargins(4, 4, 4, 4)

        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Workspace:")))
        self.ws_label = QLabel(self.tr("none open"))
        self.ws_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.ws_label.setMinimumWidth(60)
        row.addWidget(self.ws_label, 1)
        self.btn_open = QPushButton(self.tr("Open\u2026"))
        self.btn_open.setToolTip(self.tr("Open a workspace folder (made by Align images)"))
        self.btn_new = QPushButton(self.tr("New from photos\u2026"))
        self.btn_new.setToolTip(self.tr("Choose a folder of photos and a workspace folder, and align the photos"))
        row.addWidget(self.btn_open)
        row.addWidget(self.btn_new)
        lay.addLayout(row)

        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Heights (Z) from:")))
        self.dsm_combo = QgsMapLayerComboBox()
        self.dsm_combo.setFilters(QgsMapLayerProxyModel.RasterLayer)
        self.dsm_combo.setAllowEmptyLayer(True)
        self.dsm_combo.setLayer(None)
        self.dsm_combo.setToolTip(self.tr("A DSM or DTM raster layer (e.g. an ALS DSM): a point picked on the map "
                                          "takes its height from it (bilinear). Empty: type Z by hand."))
        row.addWidget(self.dsm_combo, 1)
        self.crs_label = QLabel()
        row.addWidget(self.crs_label)
        lay.addLayout(row)

        self.toolbar = QToolBar(w)
        self.toolbar.setToolButtonStyle(Qt.ToolButtonTextOnly)
        self.act_add = self.toolbar.addAction(self.tr("Add"))
        self.act_add.setToolTip(self.tr("Add a ground point"))
        self.act_remove = self.toolbar.addAction(self.tr("Remove"))
        self.act_remove.setToolTip(self.tr("Remove the selected ground point and its observations"))
        self.act_pick = self.toolbar.addAction(self.tr("Pick on map"))
        self.act_pick.setCheckable(True)
        self.act_pick.setToolTip(self.tr("Click on the map canvas to set X and Y of the selected point "
                                         "(Z from the heights layer)"))
        self.import_menu = QMenu(w)
        self.act_import_file = self.import_menu.addAction(self.tr("From file (gcp_list.txt, CSV)\u2026"))
        self.act_import_layer = self.import_menu.addAction(self.tr("From a point layer\u2026"))
        self.export_menu = QMenu(w)
        self.act_export_file = self.export_menu.addAction(self.tr("To file (gcp_list.txt, CSV)\u2026"))
        self.act_export_layer = self.export_menu.addAction(self.tr("To a GeoPackage layer\u2026"))
        for text, menu in ((self.tr("Import"), self.import_menu), (self.tr("Export"), self.export_menu)):
            b = QToolButton(w)
            b.setText(text)
            b.setMenu(menu)
            b.setPopupMode(QToolButton.InstantPopup)
            self.toolbar.addWidget(b)
        stack = self.store.undo_stack
        self.act_undo = QAction(self.tr("Undo"), w)
        self.act_redo = QAction(self.tr("Redo"), w)
        self.act_undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.act_redo.setShortcut(QKeySequence.StandardKey.Redo)
        self.act_undo.triggered.connect(stack.undo)
        self.act_redo.triggered.connect(stack.redo)
        stack.canUndoChanged.connect(self.act_undo.setEnabled)
        stack.canRedoChanged.connect(self.act_redo.setEnabled)
        stack.undoTextChanged.connect(lambda t: self.act_undo.setToolTip(self.tr("Undo: {}").format(t) if t else ""))
        stack.redoTextChanged.connect(lambda t: self.act_redo.setToolTip(self.tr("Redo: {}").format(t) if t else ""))
        for a in (self.act_undo, self.act_redo):
            a.setEnabled(False)
            a.setShortcutContext(Qt.WidgetWithChildrenShortcut)
            self.toolbar.addAction(a)
        self.act_results = self.toolbar.addAction(self.tr("Load results"))
        self.act_results.setToolTip(self.tr("Add the workspace's products to the map as styled layers"))
        lay.addWidget(self.toolbar)

        self.model = GcpTableModel(self)
        self.table = QTableView(w)
        self.table.setModel(self.model)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setItemDelegateForColumn(ROLE, RoleDelegate(self.table))
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.setEditTriggers(QAbstractItemView.DoubleClicked | QAbstractItemView.EditKeyPressed
                                   | QAbstractItemView.AnyKeyPressed)
        lay.addWidget(self.table, 1)

        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Residual tolerance:")))
        self.tol_spin = QDoubleSpinBox()
        self.tol_spin.setDecimals(3)
        self.tol_spin.setRange(0.001, 1000.0)
        self.tol_spin.setValue(0.1)
        self.tol_spin.setSuffix(" m")
        self.tol_spin.setToolTip(self.tr("Residuals up to this are green, up to 3 times yellow, beyond red"))
        row.addWidget(self.tol_spin)
        self.refine_box = QCheckBox(self.tr("Refine camera calibration"))
        self.refine_box.setToolTip(self.tr("Let the adjustment refine focal length, principal point and distortion"))
        row.addWidget(self.refine_box)
        row.addStretch(1)
        lay.addLayout(row)

        row = QHBoxLayout()
        self.btn_georef = QPushButton(self.tr("Georeference"))
        self.btn_georef.setToolTip(self.tr("Run the adjustment with these points (in the background)"))
        self.btn_cancel = QPushButton(self.tr("Cancel"))
        self.progress = QProgressBar()
        self.progress.setRange(0, 100)
        self.progress.setValue(0)
        self.progress.setTextVisible(True)
        row.addWidget(self.btn_georef)
        row.addWidget(self.progress, 1)
        row.addWidget(self.btn_cancel)
        lay.addLayout(row)

        self.summary = QLabel()
        self.summary.setWordWrap(True)
        self.summary.setTextFormat(Qt.TextFormat.RichText)
        lay.addWidget(self.summary)
        self.status = QLabel()
        self.status.setWordWrap(True)
        lay.addWidget(self.status)
        self.setWidget(w)

    def _connect(self):
        self.btn_open.clicked.connect(self.choose_workspace)
        self.btn_new.clicked.connect(self.choose_photos)
        self.act_add.triggered.connect(lambda: self.add_point())
        self.act_remove.triggered.connect(self.remove_selected)
        self.act_pick.toggled.connect(self.set_picking)
        self.act_import_file.triggered.connect(self.choose_import_file)
        self.act_import_layer.triggered.connect(self.choose_import_layer)
        self.act_export_file.triggered.connect(self.choose_export_file)
        self.act_export_layer.triggered.connect(self.choose_export_layer)
        self.act_results.triggered.connect(self.load_results)
        self.btn_georef.clicked.connect(self.run_georeference)
        self.btn_cancel.clicked.connect(self.cancel_task)
        self.tol_spin.valueChanged.connect(self._tolerance_changed)
        self.dsm_combo.layerChanged.connect(self._dsm_changed)
        self.table.selectionModel().currentRowChanged.connect(lambda *a: self._selection_changed())
        self.store.changed.connect(self._store_changed)
        self.store.residualsChanged.connect(self._residuals_changed)
        self.store.workspaceChanged.connect(self._workspace_changed)
        if self.map_tool is not None:
            self.map_tool.picked.connect(self.map_picked)
            self.map_tool.escaped.connect(lambda: self.act_pick.setChecked(False))
            self.map_tool.deactivated.connect(lambda: self.act_pick.setChecked(False))
        if self.canvas is not None:
            self.canvas.destinationCrsChanged.connect(self._update_markers)
        p = self.photo_panel
        p.photoSelected.connect(self.show_photo)
        p.placed.connect(self.place_observation)
        p.removeRequested.connect(self.remove_observation)
        p.confirmRequested.connect(self.confirm_prediction)
        p.nextRequested.connect(self.confirm_and_next)
        p.filterChanged.connect(lambda _on: self._update_thumbnails())

    # ------------------------------------------------------------------ messages
    def message(self, text, level=Qgis.Info):
        self.status.setText(text)
        if self.iface is not None and level != Qgis.Info:
            self.iface.messageBar().pushMessage(self.tr("ArchaeoOrtho"), text, level, 8)

    def tolerance(self):
        return self.tol_spin.value()

    # ------------------------------------------------------------------ workspace
    def choose_workspace(self):
        folder = QFileDialog.getExistingDirectory(self, self.tr("Open an ArchaeoOrtho workspace"))
        if folder:
            self.open_workspace(folder)

    def open_workspace(self, folder):
        from ..core.project.workspace import WorkspaceError

        try:
            self.store.open(folder)
        except WorkspaceError as e:
            self.message(str(e), Qgis.Critical)
            return False
        return True

    def _workspace_changed(self):
        root = self.store.root or ""
        self.ws_label.setText(os.path.basename(os.path.normpath(root)) if root else self.tr("none open"))
        self.ws_label.setToolTip(root)
        photos = {im["name"]: im["path"] for im in self.store.images()}
        self.photo_panel.set_photos(photos)
        tol = self.store.settings.get("tolerance")
        self.load_predictor()
        if tol:
            self.tol_spin.blockSignals(True)
            self.tol_spin.setValue(float(tol))
            self.tol_spin.blockSignals(False)
        dsm_id = self.store.settings.get("dsm_layer")
        if dsm_id and QgsProject.instance().mapLayer(dsm_id) is not None:
            self.dsm_combo.setLayer(QgsProject.instance().mapLayer(dsm_id))
        self.model.refresh()
        if self.store.gcps.points:
            self.select_point(self.store.gcps.points[0].name)
        else:
            self._selection_changed()
        self._update_summary()
        n_img = len(photos)
        if not self.store.stage_done("align"):
            self.message(self.tr("{} photos; the block is not aligned yet: run Align images (or 'New from "
                                 "photos') to get predicted positions").format(n_img))
        else:
            self.message(self.tr("{} photos, {} ground points. {}").format(
                n_img, len(self.store.gcps.points), self.predictor_note))

    def load_predictor(self):
        """Load the block model for guided placement: the georeferenced model when its CRS is the GCPs',
        else the aligned one (positions then come from rays and a Helmert fit of the placed points)."""
        self.predictor = None
        self.predictor_note = ""
        if self.store.workspace is None or not self.store.stage_done("align"):
            return
        try:
            from ..core.align import sfm
            from ..core.georef import guided
            from ..core.pipeline import load_georef_model
        except ImportError as e:
            self.predictor_note = self.tr("no predicted positions: {}").format(e)
            return
        ws = self.store.root
        try:
            if self.store.stage_done("georeference") and os.path.isdir(os.path.join(ws, "georef", "model")):
                rec, transform = load_georef_model(ws)
                same = layers.qgs_crs(transform.get("crs", "")) == layers.qgs_crs(self.store.crs)
                self.predictor = guided.Predictor(rec, transform.get("offset") if same else None)
            else:
                self.predictor = guided.Predictor(sfm.load_model(ws))
            gsd = guided.ground_sample_distance(self.predictor.rec)
            if gsd and self.predictor.georeferenced and not self.store.settings.get("tolerance"):
                self.tol_spin.blockSignals(True)  # a default, not the user's choice: not saved
                self.tol_spin.setValue(max(0.001, round(3.0 * gsd, 3)))
                self.tol_spin.blockSignals(False)
        except Exception as e:  # noqa: BLE001 - a broken model must not break the dock
            self.predictor = None
            self.predictor_note = self.tr("no predicted positions: {}").format(e)
            return
        self.predictor_note = (self.tr("Predicted positions from the georeferenced block.")
                               if self.predictor.georeferenced else
                               self.tr("Predicted positions once a point is placed in 2 photos, and for every "
                                       "point once 3 points are placed."))

    def choose_photos(self):
        images = QFileDialog.getExistingDirectory(self, self.tr("Folder of photos"))
        if not images:
            return
        ws = QFileDialog.getExistingDirectory(self, self.tr("Workspace folder (new or existing)"))
        if ws:
            self.start_alignment(images, ws)

    def start_alignment(self, images_dir, workspace_dir, options=None):
        from ..core.align import sfm

        if self._busy():
            return None

        def done(result):
            self._task_ended()
            self.message(self.tr("Aligned {} of {} photos, mean reprojection error {:.2f} px").format(
                result.registered, result.images_given, result.mean_reprojection_error))
            self.open_workspace(workspace_dir)

        task = CoreTask(self.tr("ArchaeoOrtho: align photos"), sfm.align, (images_dir, workspace_dir),
                        {"options": options}, on_done=done, on_error=self._task_failed)
        return self._start_task(task)

    # ------------------------------------------------------------------ selection
    def current_name(self):
        idx = self.table.selectionModel().currentIndex()
        if not idx.isValid() or idx.row() >= len(self.store.gcps.points):
            return None
        return self.store.gcps.points[idx.row()].name

    def current_point(self):
        name = self.current_name()
        return self.store.gcps.by_name(name) if name else None

    def select_point(self, name):
        for row, p in enumerate(self.store.gcps.points):
            if p.name == name:
                self.table.selectRow(row)
                self.table.setCurrentIndex(self.model.index(row, NAME))
                self._selection_changed()
                return True
        return False

    def _selection_changed(self):
        self._update_predictions()
        self._update_thumbnails()
        name = self.current_name()
        if name != getattr(self, "_last_point", None):
            # another point: show the photo where it is to be placed next (or its first photo)
            self._last_point = name
            target = self.next_photo() if name else None
            strip = self.photo_panel.thumbnail_names()
            target = target or (strip[0] if name and strip and self.predictions else None)
            if target and target != self.photo_panel.image and self.photo_panel.show_photo(target):
                self._update_photo(zoom=True)
                self._update_markers()
                self._update_enabled()
                return
        self._update_photo()
        self._update_markers()
        self._update_enabled()

    def _store_changed(self):
        name = self.current_name()
        self.model.refresh()
        if name and self.store.gcps.by_name(name) is not None:
            self.select_point(name)
        elif self.store.gcps.points:
            self.select_point(self.store.gcps.points[min(len(self.store.gcps.points) - 1, 0)].name)
        else:
            self._selection_changed()
        self._update_summary()

    def _residuals_changed(self):
        self.model.repaint_all()
        self._update_summary()

    def _tolerance_changed(self, value):
        self.store.save_settings(tolerance=value)
        self.model.repaint_all()

    def _dsm_changed(self, layer):
        self.store.save_settings(dsm_layer=layer.id() if layer is not None else None)

    def _update_enabled(self):
        has_ws = self.store.workspace is not None
        has_point = self.current_name() is not None
        busy = self.task is not None
        for a in (self.act_add, self.act_import_file, self.act_import_layer, self.act_results):
            a.setEnabled(has_ws)
        for a in (self.act_remove,):
            a.setEnabled(has_ws and has_point)
        self.act_pick.setEnabled(has_ws and self.map_tool is not None)
        self.act_export_file.setEnabled(bool(self.store.gcps.points))
        self.act_export_layer.setEnabled(bool(self.store.gcps.points))
        self.btn_georef.setEnabled(has_ws and not busy)
        self.btn_cancel.setEnabled(busy)
        self.btn_new.setEnabled(not busy)
        self.crs_label.setText(self.tr("CRS: {}").format(_short_crs(self.store.crs)) if self.store.crs else "")

    # ------------------------------------------------------------------ points
    def add_point(self, name=None, x=math.nan, y=math.nan, z=math.nan):
        if self.store.workspace is None:
            return None
        try:
            name = self.store.add_point(name, x, y, z)
        except ValueError as e:
            self.message(str(e), Qgis.Warning)
            return None
        self.select_point(name)
        return name

    def remove_selected(self):
        name = self.current_name()
        if name:
            self.store.remove_point(name)

    # ------------------------------------------------------------------ map tool
    def set_picking(self, on):
        if self.map_tool is None or self.canvas is None:
            return
        if on:
            if self.canvas.mapTool() is not self.map_tool:
                self.prev_tool = self.canvas.mapTool()
            self.canvas.setMapTool(self.map_tool)
            self.message(self.tr("Click on the map at the selected point's position (Esc to stop)"))
        elif self.canvas.mapTool() is self.map_tool:
            self.canvas.unsetMapTool(self.map_tool)
            if self.prev_tool is not None:
                self.canvas.setMapTool(self.prev_tool)
            self.prev_tool = None
        if self.act_pick.isChecked() != on:
            self.act_pick.setChecked(on)

    def _project_crs(self):
        if self.canvas is not None:
            return self.canvas.mapSettings().destinationCrs()
        return QgsProject.instance().crs()

    def map_picked(self, point):
        """A canvas click at ``point`` (canvas CRS): X, Y of the selected point (a new one when none is
        selected) in the GCP CRS, Z from the heights layer."""
        if self.store.workspace is None:
            return
        canvas_crs = self._project_crs()
        if not self.store.crs:
            self.store.set_crs(layers.crs_text(canvas_crs))
        gcp_crs = layers.qgs_crs(self.store.crs)
        p = QgsPointXY(point)
        if gcp_crs.isValid() and canvas_crs.isValid() and gcp_crs != canvas_crs:
            p = QgsCoordinateTransform(canvas_crs, gcp_crs, QgsProject.instance()).transform(p)
        z = None
        dsm = self.dsm_combo.currentLayer()
        if dsm is not None:
            z = sample_height(dsm, QgsPointXY(point), canvas_crs)
        name = self.current_name()
        if name is None:
            name = self.add_point(x=p.x(), y=p.y(), z=z if z is not None else math.nan)
        else:
            fields = {"x": p.x(), "y": p.y()}
            if z is not None:
                fields["z"] = z
            self.store.set_point(name, **fields)
        if z is not None:
            self.message(self.tr("{}: X {:.3f}, Y {:.3f}, Z {:.3f} (from {})").format(
                name, p.x(), p.y(), z, dsm.name()))
        elif dsm is not None:
            self.message(self.tr("{}: X {:.3f}, Y {:.3f}. No height at this place in {}: Z left as it was").format(
                name, p.x(), p.y(), dsm.name()), Qgis.Warning)
        else:
            self.message(self.tr("{}: X {:.3f}, Y {:.3f}").format(name, p.x(), p.y()))
        return name

    def _update_markers(self):
        if self.markers is None:
            return
        gcp_crs = layers.qgs_crs(self.store.crs)
        canvas_crs = self._project_crs()
        tr = None
        if gcp_crs.isValid() and canvas_crs.isValid() and gcp_crs != canvas_crs:
            tr = QgsCoordinateTransform(gcp_crs, canvas_crs, QgsProject.instance())
        pts = {}
        for p in self.store.gcps.points:
            if not (math.isfinite(p.x) and math.isfinite(p.y)):
                continue
            q = QgsPointXY(p.x, p.y)
            if tr is not None:
                try:
                    q = tr.transform(q)
                except Exception:  # noqa: BLE001 - QgsCsException: not drawable in this CRS
                    continue
            pts[p.name] = q
        self.markers.update(pts, self.current_name())

    # ------------------------------------------------------------------ photos and predictions
    def _update_predictions(self):
        self.predictions = {}
        point = self.current_point()
        if point is None or self.predictor is None:
            return
        try:
            self.predictor.fit(self.store.gcps)
            preds = self.predictor.predict_point(point)
            if any(p.source != "rays" for p in preds.values()):
                # positions from world coordinates can be off by the block's misfit to the control: offer
                # the photos where the point lands near the frame too (matching may find it inside)
                slack = -0.15 * max(self.predictor.rec.cameras[c].width for c in self.predictor.rec.cameras)
                preds = self.predictor.predict_point(point, margin=slack)
            self.predictions = preds
        except Exception as e:  # noqa: BLE001 - degenerate geometry: no predictions, say why
            self.message(self.tr("no predicted positions: {}").format(e), Qgis.Warning)
            self.predictions = {}

    def _gray_image(self, name):
        from ..core.georef.guided import read_gray

        if name not in self._gray:
            path = next((im["path"] for im in self.store.images() if im["name"] == name), None)
            if path is None:
                return None
            self._gray[name] = read_gray(path)
            while len(self._gray) > 6:
                self._gray.pop(next(iter(self._gray)))
        return self._gray[name]

    def refined_prediction(self, image):
        """The prediction in ``image``, refined by matching the point's look in a photo where it is placed
        (core.guided.refine_by_matching); the geometric prediction when matching finds nothing sure."""
        from ..core.georef import guided

        pred = self.predictions.get(image)
        point = self.current_point()
        if pred is None or point is None or pred.source == guided.RAYS or not point.observations \
                or self.predictor is None:
            return pred, None
        key = (point.name, image, tuple((o.image, round(o.x, 3), round(o.y, 3)) for o in point.observations),
               round(pred.x, 2), round(pred.y, 2))
        if key not in self.matches:
            match = None
            try:
                xyz, _ = self.predictor.model_point(point)
                cam = self.predictor.rec.cameras
                size = max(max(c.width, c.height) for c in cam.values())
                tgt = self._gray_image(image)
                refs = sorted(point.observations, key=lambda o: self._baseline(o.image, image))
                for ref in refs[:2]:
                    match = guided.refine_by_matching(
                        self.predictor.rec, ref.image, (ref.x, ref.y), self._gray_image(ref.image), image,
                        pred.xy, tgt, xyz, radius=min(600.0, 0.3 * size))
                    if match is not None:
                        break
            except Exception:  # noqa: BLE001 - matching is a help, never an obstacle
                match = None
            self.matches[key] = match
        match = self.matches[key]
        if match is None:
            return pred, None
        return guided.Prediction(pred.name, image, match.x, match.y, "matched", pred.centrality), match

    def _baseline(self, a, b):
        """Distance between two photos' projection centres (nearer photos look more alike)."""
        try:
            lookup = self.predictor._lookup
            ca = np.asarray(lookup[a].projection_center())
            cb = np.asarray(lookup[b].projection_center())
            return float(np.linalg.norm(ca - cb))
        except (KeyError, AttributeError):
            return float("inf")

    def visible_photos(self):
        """Photos for the strip: all, or (filter on) the observed ones and those predicted to see the point."""
        from ..core.georef.guided import images_seeing

        names = [im["name"] for im in self.store.images()]
        point = self.current_point()
        if point is None or not self.photo_panel.filter_box.isChecked():
            return names
        observed = point.images()
        if not self.predictions:
            return observed + [n for n in names if n not in observed]
        return [n for n in images_seeing(self.predictions, observed) if n in set(names)]

    def _update_thumbnails(self):
        point = self.current_point()
        marks = {}
        if point is not None:
            # placed photos: how far the click is from where the point's other photos put it
            loo = self.predictor.leave_one_out(point) if self.predictor is not None else {}
            for o in point.observations:
                d = loo.get(o.image)
                marks[o.image] = "\u2713" + (" " + self.tr("{:.1f} px").format(d) if d is not None else "")
            for n in self.predictions:
                marks.setdefault(n, self.tr("predicted"))
        self.photo_panel.set_thumbnails(self.visible_photos(), marks)

    def show_photo(self, name):
        if self.photo_panel.show_photo(name):
            self._update_photo(zoom=True)

    def _update_photo(self, zoom=False):
        panel = self.photo_panel
        point = self.current_point()
        image = panel.image
        if point is None or image is None:
            panel.set_markers(None)
            panel.set_next_available(False)
            panel.title.setText(f"<b>{image or ''}</b>")
            panel.hint.setText(self.tr("Select or add a ground point in the table, then click on it in the photo.")
                               if self.store.workspace is not None else "")
            return
        obs = next((o for o in point.observations if o.image == image), None)
        pred, match = self.refined_prediction(image) if obs is None else (self.predictions.get(image), None)
        source = {"rays": self.tr("from the point's other observations"),
                  "georef": self.tr("from the georeferenced block"),
                  "helmert": self.tr("from the points already placed (similarity fit)"),
                  "matched": self.tr("by matching its look in another photo")}.get(pred.source if pred else "", "")
        if match is not None:
            source += " " + self.tr("(correlation {:.2f}, {:.0f} px from the geometric prediction)").format(
                match.score, match.shift)
        panel.set_markers(point.name, (obs.x, obs.y) if obs else None, (pred.x, pred.y) if pred else None, source)
        panel.set_next_available(self.next_photo() is not None)
        panel.title.setText(f"<b>{point.name}</b> \u2014 {image}")
        if obs is not None:
            panel.hint.setText(self.tr("Placed at x {:.2f}, y {:.2f}. Click to move it, drag it, or press Delete "
                                       "to remove it.").format(obs.x, obs.y))
        elif pred is not None:
            panel.hint.setText(self.tr("Predicted {}. Press Enter to accept it and go on (Space: accept), drag "
                                       "it, or click where the point really is.").format(source))
        else:
            panel.hint.setText(self.tr("Click where {} is in this photo.").format(point.name))
        if zoom:
            if obs is not None or pred is not None:
                panel.zoom_to_point(max(2.0, panel.view.zoom()))
            else:
                panel.view.fit()

    def place_observation(self, image, x, y):
        name = self.current_name()
        if name is None:
            self.message(self.tr("Select or add a ground point first"), Qgis.Warning)
            return
        self.store.set_observation(name, image, x, y)

    def remove_observation(self, image):
        name = self.current_name()
        if name is not None:
            self.store.remove_observation(name, image)

    def confirm_prediction(self, image=None):
        image = image or self.photo_panel.image
        pred, _ = self.refined_prediction(image)
        name = self.current_name()
        if pred is None or name is None:
            return False
        self.store.set_observation(name, image, pred.x, pred.y)
        return True

    def next_photo(self):
        """The next photo in the strip where the selected point is predicted but not yet placed."""
        point = self.current_point()
        if point is None:
            return None
        observed = set(point.images())
        names = self.photo_panel.thumbnail_names()
        cur = self.photo_panel.image
        start = names.index(cur) + 1 if cur in names else 0
        for n in names[start:] + names[:start]:
            if n not in observed and n in self.predictions:
                return n
        return None

    def confirm_and_next(self):
        """Accept the prediction in the photo shown (if any) and show the next photo still to place."""
        self.confirm_prediction()
        nxt = self.next_photo()
        if nxt is not None:
            self.show_photo(nxt)
        else:
            self.message(self.tr("{}: every photo predicted to see it has an observation").format(
                self.current_name() or ""))

    # ------------------------------------------------------------------ import / export
    def choose_import_file(self):
        path, _ = QFileDialog.getOpenFileName(self, self.tr("Import ground control"), self.store.root or "",
                                              self.tr("Ground control (*.txt *.csv);;All files (*)"))
        if path:
            self.import_file(path, merge=self._ask_merge())

    def _ask_merge(self):
        if not self.store.gcps.points:
            return False
        box = QMessageBox(QMessageBox.Icon.Question, self.tr("Import ground control"),
                          self.tr("Replace the current points, or add the imported ones to them (same names are "
                                  "updated)?"), parent=self)
        replace = box.addButton(self.tr("Replace"), QMessageBox.AcceptRole)
        box.addButton(self.tr("Add"), QMessageBox.AcceptRole)
        box.exec()
        return box.clickedButton() is not replace

    def import_file(self, path, merge=False):
        """Read an ODM gcp_list.txt or a CSV points file (+ observations) into the workspace's control."""
        try:
            gs = gcpmod.read_gcps(path, image_names=[im["name"] for im in self.store.images()] or None,
                                  image_sizes=self.store.image_sizes() or None, unknown_images="warn")
        except (gcpmod.GCPError, OSError, ValueError) as e:
            self.message(str(e), Qgis.Critical)
            return None
        return self._import(gs, os.path.basename(path), merge)

    def _import(self, gs, source, merge):
        if self.store.crs and gs.crs and layers.qgs_crs(gs.crs) != layers.qgs_crs(self.store.crs) \
                and self.store.gcps.points:
            xyz = [(p.x, p.y, p.z) for p in gs.points]
            out = gcpmod.transform_points(xyz, gs.crs, self.store.crs) if xyz else []
            for p, q in zip(gs.points, out):
                p.x, p.y = float(q[0]), float(q[1])
            gs.crs = self.store.crs
        n_obs = gs.n_observations()
        if n_obs == 0:  # coordinates only (a surveyor's list): that the points have no observations is the point
            gs.warnings = [w for w in gs.warnings
                           if "no usable observation" not in w and "no observations file" not in w]
        self.store.replace_all(gs, self.tr("import {}").format(source), merge=merge)
        warn = f" ({len(gs.warnings)} " + self.tr("warnings") + ")" if gs.warnings else ""
        self.message(self.tr("Imported {} points and {} observations from {}").format(
            len(gs.points), n_obs, source) + warn, Qgis.Warning if gs.warnings else Qgis.Info)
        if gs.warnings:
            self.status.setToolTip("\n".join(gs.warnings))
        self.load_predictor()
        self._selection_changed()
        return gs

    def choose_import_layer(self):
        candidates = [lyr for lyr in QgsProject.instance().mapLayers().values()
                      if isinstance(lyr, QgsVectorLayer) and lyr.geometryType() == QgsWkbTypes.PointGeometry]
        if not candidates:
            self.message(self.tr("No point layer in the project"), Qgis.Warning)
            return
        names = [lyr.name() for lyr in candidates]
        name, ok = QInputDialog.getItem(self, self.tr("Import ground control"),
                                        self.tr("Point layer (one feature per observation: name, image, px, py)"),
                                        names, 0, False)
        if ok:
            self.import_layer(candidates[names.index(name)], merge=self._ask_merge())

    def import_layer(self, layer, merge=False):
        """A point layer with one feature per observation (fields name, image, px, py; z, sx, sy, sz, role
        optional), as the Georeference algorithm's GCP_LAYER."""
        fields = [f.name() for f in layer.fields()]
        lower = [f.lower() for f in fields]
        for need in ("name", "image", "px", "py"):
            if need not in lower:
                self.message(self.tr("Layer {} lacks the field '{}' (needs name, image, px, py)").format(
                    layer.name(), need), Qgis.Critical)
                return None
        rows = []
        for feat in layer.getFeatures():
            attrs = {k.lower(): feat[k] for k in fields}
            attrs = {k: (None if isinstance(v, QVariant) and v.isNull() else v) for k, v in attrs.items()}
            geom = feat.geometry()
            if geom.isNull():
                continue
            pt = geom.constGet()
            z = attrs.get("z")
            if z in (None, "") and pt.is3D():
                z = pt.z()
            rows.append(dict(attrs, x=pt.x(), y=pt.y(), z=z if z not in (None, "") else 0.0))
        crs = layers.crs_text(layer.crs())
        try:
            gs = gcpmod.gcps_from_rows(rows, crs, source_name=layer.name(),
                                       image_names=[im["name"] for im in self.store.images()] or None,
                                       image_sizes=self.store.image_sizes() or None, unknown_images="warn")
        except (gcpmod.GCPError, ValueError) as e:
            self.message(str(e), Qgis.Critical)
            return None
        return self._import(gs, layer.name(), merge)

    def choose_export_file(self):
        odm, csv_ = self.tr("OpenDroneMap gcp_list (*.txt)"), self.tr("CSV points + observations (*.csv)")
        path, chosen = QFileDialog.getSaveFileName(self, self.tr("Export ground control"),
                                                   os.path.join(self.store.root or "", "gcp_list.txt"),
                                                   f"{odm};;{csv_}")
        if path:
            if chosen == csv_ and not path.lower().endswith(".csv"):
                path += ".csv"
            self.export_file(path)

    def export_file(self, path):
        gs = self.store.usable_gcps()
        if not gs.crs:
            self.message(self.tr("The points have no CRS yet: pick one on the map or import a file first"),
                         Qgis.Warning)
            return None
        try:
            gcpmod.write_gcps(gs, path)
        except (gcpmod.GCPError, OSError) as e:
            self.message(str(e), Qgis.Critical)
            return None
        left = len(self.store.gcps.points) - len(gs.points)
        self.message(self.tr("Exported {} points to {}").format(len(gs.points), path)
                     + (self.tr(" ({} without coordinates left out)").format(left) if left else ""))
        return path

    def choose_export_layer(self):
        path, _ = QFileDialog.getSaveFileName(self, self.tr("Export ground control as a layer"),
                                              os.path.join(self.store.root or "", "gcp_observations.gpkg"),
                                              self.tr("GeoPackage (*.gpkg)"))
        if path:
            self.export_layer(path if path.lower().endswith(".gpkg") else path + ".gpkg", add_to_project=True)

    def export_layer(self, path, add_to_project=False):
        """One PointZ feature per observation (name, image, px, py, z, sx, sy, sz, role): readable by
        'Import from a point layer' and by the Georeference algorithm's GCP_LAYER."""
        gs = self.store.usable_gcps()
        crs = layers.qgs_crs(gs.crs)
        fields = "&".join(f"field={n}:{t}" for n, t in (
            ("name", "string"), ("image", "string"), ("px", "double(0,0)"), ("py", "double(0,0)"), ("z", "double(0,0)"),
            ("sx", "double(0,0)"), ("sy", "double(0,0)"), ("sz", "double(0,0)"), ("role", "string")))
        mem = QgsVectorLayer(f"PointZ?{fields}", "gcp_observations", "memory")
        if crs.isValid():
            mem.setCrs(crs)
        pr = mem.dataProvider()
        feats = []
        for p in gs.points:
            for o in p.observations:
                f = QgsFeature(mem.fields())
                f.setGeometry(QgsGeometry(QgsPoint(p.x, p.y, p.z)))
                f.setAttributes([p.name, o.image, o.x, o.y, p.z, p.sigma_xy, p.sigma_xy, p.sigma_z, p.role])
                feats.append(f)
        pr.addFeatures(feats)
        opts = QgsVectorFileWriter.SaveVectorOptions()
        opts.driverName = "GPKG"
        opts.layerName = "gcp_observations"
        res = QgsVectorFileWriter.writeAsVectorFormatV2(mem, path, QgsProject.instance().transformContext(), opts)
        if res[0] != QgsVectorFileWriter.NoError:
            self.message(self.tr("Cannot write {}: {}").format(path, res[1]), Qgis.Critical)
            return None
        skipped = [p.name for p in gs.points if not p.observations]
        self.message(self.tr("Exported {} observations to {}").format(len(feats), path)
                     + (self.tr(" (points without observations left out: {})").format(", ".join(skipped))
                        if skipped else ""))
        if add_to_project:
            added = QgsProject.instance().addMapLayer(QgsVectorLayer(path, self.tr("GCP observations"), "ogr"))
            if added is None:
                self.message(self.tr("Cannot add {} to the project").format(path), Qgis.Warning)
        return path

    # ------------------------------------------------------------------ adjustment
    def _busy(self):
        if self.task is not None:
            self.message(self.tr("A task of this dock is still running"), Qgis.Warning)
            return True
        return False

    def _start_task(self, task):
        self.task = task
        self.last_task_error = None
        self.progress.setValue(0)
        task.progressChanged.connect(lambda v: self.progress.setValue(int(round(v))))
        task.message.connect(self.status.setText)
        start(task)
        self._update_enabled()
        return task

    def _task_ended(self):
        self.task = None
        self._update_enabled()

    def _task_failed(self, message, cancelled):
        self._task_ended()
        self.last_task_error = message
        self.progress.setValue(0)
        if cancelled:
            self.message(self.tr("Cancelled"), Qgis.Info)
        else:
            self.message(message, Qgis.Critical)
        self.store.reload_workspace()

    def cancel_task(self):
        if self.task is not None:
            self.task.cancel()
            self.message(self.tr("Cancelling\u2026"))

    def run_georeference(self):
        """Adjust the block with the current points in a background task; residuals update when it ends."""
        from ..core import pipeline

        if self.store.workspace is None or self._busy():
            return None
        if not self.store.stage_done("align"):
            self.message(self.tr("The block is not aligned yet: run Align images first"), Qgis.Warning)
            return None
        gs = self.store.usable_gcps()
        n_control = sum(1 for p in gs.points if p.role == gcpmod.CONTROL and len(p.observations) >= 1)
        if n_control < 3:
            self.message(self.tr("The adjustment needs at least 3 control points with coordinates and "
                                 "observations; there are {}").format(n_control), Qgis.Warning)
            return None
        root = self.store.root

        def done(result):
            self._task_ended()
            self.progress.setValue(100)
            self.store.reload_workspace()
            self.store.save()  # the stage wrote the points it used to control.json: keep all of the dock's
            self.store.load_residuals()
            self.load_predictor()
            self._selection_changed()
            self.load_results(kinds=("cameras", "residuals"))
            extra = ""
            if result.outliers:
                extra = " " + self.tr("Outliers left out: {}").format("; ".join(result.outliers))
            self.message(self.tr("Georeferenced in {}.").format(_short_crs(result.crs)) + extra,
                         Qgis.Warning if result.outliers else Qgis.Success)

        task = CoreTask(self.tr("ArchaeoOrtho: georeference"), pipeline.georeference_workspace, (root,),
                        {"gcps": gs, "refine_intrinsics": self.refine_box.isChecked()},
                        on_done=done, on_error=self._task_failed)
        self.message(self.tr("Georeferencing with {} control points\u2026").format(n_control))
        return self._start_task(task)

    def _update_summary(self):
        f = self.store.figures
        if not f:
            self.summary.setText(self.tr("Not georeferenced yet.") if self.store.workspace is not None else "")
            return
        parts = [self.tr("Control: RMSE XY {} m, Z {} m (n = {})").format(
            _fmt(f.get("GCP_RMSE_XY")), _fmt(f.get("GCP_RMSE_Z")), f.get("GCP_N", 0))]
        if f.get("CHECK_N"):
            parts.append(self.tr("Check: RMSE XY {} m, Z {} m (n = {})").format(
                _fmt(f.get("CHECK_RMSE_XY")), _fmt(f.get("CHECK_RMSE_Z")), f.get("CHECK_N")))
        if f.get("PLACEHOLDER_Z"):
            parts.append(self.tr("heights are placeholders: no vertical accuracy"))
        if f.get("MEAN_REPROJECTION_ERROR") is not None:
            parts.append(self.tr("tie points {} px").format(_fmt(f.get("MEAN_REPROJECTION_ERROR"), 2)))
        if self.store.stale:
            parts.append("<i>" + self.tr("edited since: re-run to update") + "</i>")
        self.summary.setText("<br>".join(parts))

    # ------------------------------------------------------------------ result layers
    def load_results(self, kinds=None):
        """Add the workspace's products as styled layers (DSM + hillshade, orthomosaic, cameras +
        footprints, residuals)."""
        if self.store.root is None:
            return []
        root = self.store.root
        group = self.tr("ArchaeoOrtho: {}").format(os.path.basename(os.path.normpath(root)))
        project = QgsProject.instance()
        out = []
        kinds = kinds or ("dsm", "ortho", "cameras", "residuals")
        if "dsm" in kinds and os.path.exists(os.path.join(root, "dsm.tif")):
            out += layers.load_dsm(os.path.join(root, "dsm.tif"), project, group)
        if "ortho" in kinds and os.path.exists(os.path.join(root, "orthomosaic.tif")):
            out += layers.load_orthomosaic(os.path.join(root, "orthomosaic.tif"), project, group)
        if "cameras" in kinds and os.path.exists(os.path.join(root, "cameras.gpkg")):
            out += layers.load_cameras(os.path.join(root, "cameras.gpkg"), project, group, workspace=root)
        res = os.path.join(root, "georef", "residuals.gpkg")
        if "residuals" in kinds and os.path.exists(res) and self.store.stage_done("georeference"):
            out += layers.load_residuals(res, project, group)
        return out

    # ------------------------------------------------------------------ teardown
    def cleanup(self):
        if self.task is not None:
            self.task.cancel()
        self.set_picking(False)
        if self.markers is not None:
            self.markers.clear()


def _short_crs(text):
    crs = layers.qgs_crs(text)
    if crs.isValid():
        return crs.authid() or crs.description() or text[:40]
    return text[:40]

