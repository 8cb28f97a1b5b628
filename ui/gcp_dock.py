"""The GCP dock: ground control of a workspace, picked on the map canvas and in the photos, with guided
placement, the adjustment re-run in a task and residuals in colour.

Two dock widgets: ``GcpDock`` (table, map tool, import / export, adjustment) and its ``photo_dock``
(photo viewer + thumbnails).  Photogrammetry lives in core/ (core.guided predicts the positions,
core.pipeline adjusts); this module only translates clicks and keys into those calls.
"""
import math
import os

from qgis.core import Qgis, QgsApplication, QgsMapLayerProxyModel, QgsProject
from qgis.gui import QgsDockWidget, QgsMapLayerComboBox
from qgis.PyQt.QtCore import QCoreApplication, QSize, Qt, QTimer
from qgis.PyQt.QtGui import QColor, QKeySequence
from qgis.PyQt.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QDoubleSpinBox,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QMenu,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QTableView,
    QToolBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

try:  # Qt6 moved QAction to QtGui
    from qgis.PyQt.QtGui import QAction
except ImportError:
    from qgis.PyQt.QtWidgets import QAction

from ..core.project.stages import ALIGN
from .gcp_autocontrol import GcpAutoControl
from .gcp_io import GcpImportExport
from .gcp_placement import GcpPlacement
from .gcp_table import (
    DXY,
    DZ,
    NAME,
    OBS,
    PX,
    ROLE,
    GcpTableModel,
    RoleDelegate,
    short_crs,
)
from .gcp_targets import GcpTargets
from .gcp_tasks import GcpTasks
from .map_tool import GcpMapTool, GcpMarkers
from .message_view import FitScrollArea, MessageView
from .photo_viewer import PhotoPanel
from .store import GcpStore

KEY_COLUMNS = (NAME, OBS, DXY, DZ, PX)  # visible at the dock's default width (tests/test_ui_dock_layout.py)
DEFAULT_WIDTH = 440  # the dock's width when QGIS first shows it (its size hint)
BODY_MIN_HEIGHT = 64  # the scrolled body's least height (two rows; it scrolls): the dock fits beside QGIS's own docks
TABLE_MIN_ROWS = 4  # the GCP table never shows fewer rows (a long message squeezed it to one, issue 36 item 19)
STATUS_LINES = 5  # the status line grows to this many lines, then scrolls
DIAGNOSIS_LINES = 40  # the diagnosis is shown whole up to this many lines (it was cut at 100 characters)
DEFAULT_TOLERANCE = 0.1  # m: the residual tolerance of a workspace with no setting and no georeferenced GSD


class GcpDock(GcpPlacement, GcpImportExport, GcpTasks, GcpTargets, GcpAutoControl, QgsDockWidget):
    """Ground control of one workspace.  ``iface`` may be None (tests); ``canvas`` then is given.

    The shell: widgets, wiring, the workspace, the selection.  Placement (map and photos), import / export
    and the background tasks are its mixins (ui/gcp_placement.py, ui/gcp_io.py, ui/gcp_tasks.py; the automatic
    control, the Georeference button's other mode: ui/gcp_autocontrol.py; Find targets: ui/gcp_targets.py)."""

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
        self.unaligned = {}  # image -> why it did not align (sfm/alignment.json)
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

    def sizeHint(self):  # noqa: N802 (Qt API name)
        """The width QGIS gives the dock when it first shows it: the key columns and both toolbar rows fit."""
        hint = super().sizeHint()
        return QSize(max(DEFAULT_WIDTH, self.minimumSizeHint().width()), max(hint.height(), 600))

    # ------------------------------------------------------------------ layout
    def _build(self):
        """The body (workspace, table, settings, results) scrolls; the Georeference / Cancel row and the status
        line under it stay in view: the dock fits a 768 px screen beside the Toolbox and the Results Viewer
        (issue 36 item 20), and a long message scrolls in a few lines instead of squeezing the table (item 19)."""
        w = QWidget(self)
        outer = QVBoxLayout(w)
        outer.setContentsMargins(0, 0, 0, 2)
        outer.setSpacing(2)
        self.body_scroll = FitScrollArea(w, min_height=BODY_MIN_HEIGHT)
        body = QWidget(self.body_scroll)
        lay = QVBoxLayout(body)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.addLayout(self._build_workspace_row())
        self.align_label = QLabel()  # the alignment's result, kept on screen (not the status line's next message)
        self.align_label.setWordWrap(True)
        self.align_label.setTextFormat(Qt.TextFormat.RichText)
        self.align_label.setVisible(False)
        lay.addWidget(self.align_label)
        lay.addLayout(self._build_heights_row())
        for bar in self._build_toolbar(body):
            lay.addWidget(bar)
        lay.addWidget(self._build_table(body), 1)
        lay.addLayout(self._build_tolerance_row())
        lay.addWidget(self.tol_source)
        lay.addLayout(self._build_refine_row())
        lay.addWidget(self._build_autocontrol_box())  # ui/gcp_autocontrol.py: the Georeference button's other mode
        self.summary = QLabel()
        self.summary.setWordWrap(True)
        self.summary.setTextFormat(Qt.TextFormat.RichText)
        lay.addWidget(self.summary)
        # the adjustment's diagnosis of large residuals (GcpPlacement.show_diagnosis), every line of it
        self.diagnosis = MessageView(body, max_lines=DIAGNOSIS_LINES, min_lines=DIAGNOSIS_LINES, rich=True)
        self.diagnosis.setVisible(False)
        lay.addWidget(self.diagnosis)
        self.body_scroll.setWidget(body)
        outer.addWidget(self.body_scroll, 1)
        bottom = QVBoxLayout()
        bottom.setContentsMargins(4, 0, 4, 0)
        bottom.setSpacing(2)
        bottom.addLayout(self._build_adjustment_row())
        self.status = MessageView(w, max_lines=STATUS_LINES, min_lines=1)
        bottom.addWidget(self.status)
        outer.addLayout(bottom)
        self.setWidget(w)

    def _build_workspace_row(self):
        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Workspace:")))
        self.ws_label = QLabel(self.tr("none open"))
        self.ws_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.ws_label.setMinimumWidth(60)
        self.ws_label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)  # a long name: cut
        row.addWidget(self.ws_label, 1)
        self.btn_open = QPushButton(self.tr("Open\u2026"))
        self.btn_open.setToolTip(self.tr("Open a workspace folder (made by Align images)"))
        self.btn_new = QPushButton(self.tr("New from photos\u2026"))
        self.btn_new.setToolTip(self.tr("Choose a folder of photos and a workspace folder, and align the photos"))
        row.addWidget(self.btn_open)
        row.addWidget(self.btn_new)
        return row

    def _build_heights_row(self):
        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Heights (Z) from:")))
        self.dsm_combo = QgsMapLayerComboBox()
        self.dsm_combo.setFilters(QgsMapLayerProxyModel.Filter.RasterLayer)
        self.dsm_combo.setAllowEmptyLayer(True)
        self.dsm_combo.setLayer(None)
        self.dsm_combo.setToolTip(self.tr("A DSM or DTM raster layer (e.g. an ALS DSM): a point picked on the map "
                                          "takes its height from it (bilinear). Empty: type Z by hand. Only height rasters are "
                                          "listed (not orthophotos, hillshades or web maps)."))
        row.addWidget(self.dsm_combo, 1)
        self.crs_label = QLabel()
        row.addWidget(self.crs_label)
        return row

    def _build_toolbar(self, w):
        """Two rows, each at least as wide as its buttons (the dock cannot be made narrower): nothing ends up in a
        toolbar's >> overflow, in any language.  Row 1: the point and undo; row 2: import, export, results."""
        self.toolbar = QToolBar(w)
        self.toolbar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        self.toolbar2 = QToolBar(w)
        self.toolbar2.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
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
        self._build_targets_action(self.import_menu)  # ui/gcp_targets.py (a button more would not fit in German)
        self.export_menu = QMenu(w)
        self.act_export_file = self.export_menu.addAction(self.tr("To file (gcp_list.txt, CSV)\u2026"))
        self.act_export_layer = self.export_menu.addAction(self.tr("To a GeoPackage layer\u2026"))
        for text, menu in ((self.tr("Import"), self.import_menu), (self.tr("Export"), self.export_menu)):
            b = QToolButton(w)
            b.setText(text)
            b.setMenu(menu)
            b.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
            self.toolbar2.addWidget(b)
        self._build_undo_actions(w)
        self.act_results = self.toolbar2.addAction(self.tr("Load results"))
        self.act_results.setToolTip(self.tr("Add the workspace's products to the map as styled layers"))
        self.act_report = self.toolbar2.addAction(self.tr("Report"))
        self.act_report.setToolTip(self.tr("Open the workspace's accuracy report (report.html, made by Run pipeline "
                                           "or Accuracy report) in the web browser"))
        for bar in (self.toolbar, self.toolbar2):
            bar.setMinimumWidth(bar.sizeHint().width())
        return self.toolbar, self.toolbar2

    def _build_undo_actions(self, w):
        stack = self.store.undo_stack
        self.act_undo = QAction(self.tr("Undo"), w)
        self.act_redo = QAction(self.tr("Redo"), w)
        self.act_undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.act_redo.setShortcut(QKeySequence.StandardKey.Redo)
        self.act_undo.triggered.connect(stack.undo)
        self.act_redo.triggered.connect(stack.redo)
        stack.canUndoChanged.connect(self.act_undo.setEnabled)
        stack.canRedoChanged.connect(self.act_redo.setEnabled)
        undo_tip, redo_tip = self.tr("Undo (Ctrl+Z)"), self.tr("Redo (Ctrl+Shift+Z)")
        self.act_undo.setToolTip(undo_tip)
        self.act_redo.setToolTip(redo_tip)
        stack.undoTextChanged.connect(
            lambda t: self.act_undo.setToolTip(self.tr("Undo: {}").format(t) if t else undo_tip))
        stack.redoTextChanged.connect(
            lambda t: self.act_redo.setToolTip(self.tr("Redo: {}").format(t) if t else redo_tip))
        for a, icon in ((self.act_undo, "mActionUndo.svg"), (self.act_redo, "mActionRedo.svg")):
            a.setEnabled(False)
            a.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            a.setIcon(QgsApplication.getThemeIcon(icon))
            self.toolbar.addAction(a)
            button = self.toolbar.widgetForAction(a)
            if button is not None and not a.icon().isNull():  # the usual arrows: narrow in every language
                button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonIconOnly)

    def _build_table(self, w):
        self.model = GcpTableModel(self)
        self.table = QTableView(w)
        self.table.setModel(self.model)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setItemDelegateForColumn(ROLE, RoleDelegate(self.table))
        self.table.verticalHeader().setVisible(False)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setStretchLastSection(True)
        # compact: the name and what tells whether a point is good (photos, residuals) first, the coordinates
        # after them; the model's column numbers stay (only the view's order changes)
        for visual, column in enumerate(KEY_COLUMNS):
            header.moveSection(header.visualIndex(column), visual)
        rows = TABLE_MIN_ROWS * self.table.verticalHeader().defaultSectionSize()
        self.table.setMinimumHeight(rows + self.table.horizontalHeader().sizeHint().height() + 2 * self.table.frameWidth())
        triggers = QAbstractItemView.EditTrigger
        self.table.setEditTriggers(triggers.DoubleClicked | triggers.EditKeyPressed | triggers.AnyKeyPressed)
        return self.table

    def _build_tolerance_row(self):
        row = QHBoxLayout()
        row.addWidget(QLabel(self.tr("Residual tolerance:")))
        self.tol_spin = QDoubleSpinBox()
        self.tol_spin.setDecimals(3)
        self.tol_spin.setRange(0.001, 1000.0)
        self.tol_spin.setValue(DEFAULT_TOLERANCE)
        self.tol_spin.setSuffix(" m")
        self.tol_spin.setToolTip(self.tr("Residuals up to this are green, up to 3 times yellow, beyond red"))
        row.addWidget(self.tol_spin)
        self.tol_source = QLabel()  # where the tolerance comes from (GcpPlacement.show_tolerance_source)
        self.tol_source.setWordWrap(True)  # its own line under the row (_build): wraps instead of widening the dock
        row.addStretch(1)
        return row

    def _build_refine_row(self):
        row = QHBoxLayout()  # its own row: beside the tolerance it made the dock too wide for its default width
        self.refine_box = QCheckBox(self.tr("Refine camera calibration"))
        self.refine_box.setToolTip(self.tr("Let the adjustment refine focal length, principal point and distortion"))
        row.addWidget(self.refine_box)
        row.addStretch(1)
        return row

    def _build_adjustment_row(self):
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
        return row

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
        self.act_results.triggered.connect(self.load_results_in_background)
        self.act_report.triggered.connect(self.open_report)
        self.btn_georef.clicked.connect(self.georeference_clicked)
        self.btn_cancel.clicked.connect(self.cancel_task)
        self.tol_spin.valueChanged.connect(self._tolerance_changed)
        self.tol_spin.valueChanged.connect(lambda _v: self.show_tolerance_source())
        self.store.residualsChanged.connect(self.show_diagnosis)
        self.store.install_undo_keys(self.table, self.photo_panel.view)  # Ctrl+Z / Ctrl+Shift+Z there too
        self.dsm_combo.layerChanged.connect(self._dsm_changed)
        self.table.selectionModel().currentRowChanged.connect(lambda *a: self._row_changed())
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
        self._install_found_keys()  # ui/gcp_targets.py: one key confirms or rejects a found observation
        self._watch_height_layers()  # ui/gcp_autocontrol.py: the boxes of heights list height rasters only

    # ------------------------------------------------------------------ messages
    def message(self, text, level=Qgis.MessageLevel.Info):
        self.status.setText(text)
        if self.iface is not None and level != Qgis.MessageLevel.Info:
            self.iface.messageBar().pushMessage(self.tr("ArchaeoOrtho"), text, level, 8)

    def tolerance(self):
        return self.tol_spin.value()

    # ------------------------------------------------------------------ workspace
    def choose_workspace(self):
        folder = QFileDialog.getExistingDirectory(self, self.tr("Open an ArchaeoOrtho workspace"))
        if folder:
            self.open_workspace_in_background(folder)  # the block model is read in a task (issue 18.5)

    def open_workspace(self, folder):
        from ..core.project.workspace import WorkspaceError

        try:
            self.store.open(folder)
        except WorkspaceError as e:
            self.message(str(e), Qgis.MessageLevel.Critical)
            return False
        return True

    def report_path(self):
        """The open workspace's accuracy report on disk (report.html or the file its report stage recorded)."""
        if self.store.workspace is None:
            return None
        from ..core.report.stage import report_of

        return report_of(self.store.workspace)

    def open_report(self):
        """The workspace's accuracy report in the web browser: at hand after a restart, when the Results Viewer
        is empty (issue 48 item 5)."""
        from qgis.PyQt.QtCore import QUrl
        from qgis.PyQt.QtGui import QDesktopServices

        path = self.report_path()
        if path is None:
            self.message(self.tr("The workspace has no accuracy report yet: run Accuracy report (or Run pipeline)"),
                         Qgis.MessageLevel.Warning)
            return False
        if not QDesktopServices.openUrl(QUrl.fromLocalFile(path)):
            self.message(self.tr("No web browser opened {}").format(path), Qgis.MessageLevel.Warning)
            return False
        self.message(self.tr("Accuracy report: {}").format(path))
        return True

    def _reset_workspace_state(self):
        """What the dock showed of the previous workspace goes (issue 48 item 4): its residual tolerance and
        heights layer (each workspace's own setting, else the default), its photo, predictions and matches,
        a finished task's progress and the results of its last runs."""
        for job in list(self.__dict__.get("_refine_jobs", {}).values()):
            job.cancel()
        self.__dict__.get("_refine_jobs", {}).clear()
        self.predictions, self.matches, self._gray, self.refused = {}, {}, {}, {}
        self._gsd_tolerance = None
        self.last_task_error = self.targets_result = self.auto_result = None
        if self.task is None:
            self.progress.setValue(0)
        tol = self.store.settings.get("tolerance")
        self.tol_spin.blockSignals(True)  # shown, not saved: the workspace's own value or the default
        self.tol_spin.setValue(float(tol) if tol else DEFAULT_TOLERANCE)
        self.tol_spin.blockSignals(False)
        dsm_id = self.store.settings.get("dsm_layer")
        self.dsm_combo.blockSignals(True)
        self.dsm_combo.setLayer(QgsProject.instance().mapLayer(dsm_id) if dsm_id else None)
        self.dsm_combo.blockSignals(False)
        panel = self.photo_panel
        panel.image = None  # a photo of the same name in another workspace is another photo
        panel.view.set_pyramid(None)
        panel.set_markers(None)

    def _workspace_changed(self):
        self._reset_workspace_state()
        root = self.store.root or ""
        self.ws_label.setText(os.path.basename(os.path.normpath(root)) if root else self.tr("none open"))
        self.ws_label.setToolTip(root)
        self._show_alignment()
        photos = {im["name"]: im["path"] for im in self.store.images()}
        self.photo_panel.set_photos(photos)
        self.load_predictor()  # a georeferenced block without a setting: 3 x its GSD (GcpPlacement)
        self.show_tolerance_source()
        self.model.refresh()
        self._last_point = None  # a new workspace: its first point jumps to its photo
        if self.store.gcps.points:
            # the row only: GcpStore.open emits changed right after, and _store_changed updates the predictions,
            # the strip and the photo once (they were computed twice per opening, issue 18.5)
            self._selecting = True
            try:
                self.table.selectRow(0)
                self.table.setCurrentIndex(self.model.index(0, NAME))
            finally:
                self._selecting = False
        else:
            self._selection_changed()
        self._update_summary()
        n_img = len(photos)
        if self.store.workspace is None:
            self.message("")
        elif not self.store.stage_done(ALIGN):
            self.message(self.tr("{} photos; the block is not aligned yet: run Align images (or 'New from "
                                 "photos') to get predicted positions").format(n_img))
        else:
            self.message(self.tr("{} photos, {} ground points. {}").format(
                n_img, len(self.store.gcps.points), self.predictor_note))

    # ------------------------------------------------------------------ alignment result
    def _show_alignment(self):
        """'Aligned 38 of 41 photos' and which did not align, why: from the workspace's sfm/alignment.json, on
        screen for as long as the workspace is open."""
        figures = {}
        if self.store.workspace is not None and self.store.stage_done(ALIGN):
            try:
                figures = self.store.layout.alignment()
            except (OSError, ValueError):
                figures = {}
        self.unaligned = {str(k): str(v) for k, v in (figures.get("unregistered") or {}).items()}
        if not figures:
            self.align_label.setVisible(False)
            self.align_label.setText("")
            return
        text = self.tr("Aligned {} of {} photos, mean reprojection error {:.2f} px.").format(
            figures.get("registered", 0), figures.get("images_given", 0),
            float(figures.get("mean_reprojection_error") or 0.0))
        if self.unaligned:
            names = ", ".join(sorted(self.unaligned))
            text += " <b>" + self.tr("Not aligned ({}): {}").format(len(self.unaligned), names) + "</b> " + \
                self.tr("(marked in the photo strip; hover for the reason)")
        self.align_label.setText(text)
        self.align_label.setToolTip("\n".join(f"{n}: {why}" for n, why in sorted(self.unaligned.items())))
        self.align_label.setVisible(True)

    def visible_photos(self):
        """The strip's photos: the aligned ones first, those that did not align after them (GcpPlacement)."""
        names = super().visible_photos()
        return [n for n in names if n not in self.unaligned] + [n for n in names if n in self.unaligned]

    def _update_predictions(self):
        super()._update_predictions()
        if self.store.is_automatic(self.current_name()):
            self.predictions = {}  # measured by the automatic control, not a point to place (issue 48 item 11)

    def _update_photo(self, zoom=False):
        super()._update_photo(zoom)
        self.show_automatic_marker()  # ui/gcp_autocontrol.py

    def _update_thumbnails(self):
        super()._update_thumbnails()
        self._mark_found_thumbnails()  # ui/gcp_targets.py
        if not self.unaligned:
            return
        strip = self.photo_panel.thumbs
        for i in range(strip.count()):
            item = strip.item(i)
            name = item.data(Qt.ItemDataRole.UserRole)
            if name in self.unaligned:
                item.setText(name + "\n" + self.tr("\u2717 not aligned"))
                item.setToolTip(self.tr("{}: not aligned: {}").format(name, self.unaligned[name]))
                item.setForeground(QColor("#b00000"))

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
                self._selecting = True  # one update below, not one more per selection signal (issue 18.5)
                try:
                    self.table.selectRow(row)
                    self.table.setCurrentIndex(self.model.index(row, NAME))
                finally:
                    self._selecting = False
                self._selection_changed()
                self.table.scrollTo(self.model.index(row, NAME))  # after the update: it may resize the rows
                QTimer.singleShot(0, self._scroll_to_current)
                return True
        return False

    def _scroll_to_current(self):
        try:
            self.table.scrollTo(self.table.currentIndex())
        except RuntimeError:  # the dock was closed meanwhile
            pass

    def _row_changed(self):
        if not getattr(self, "_selecting", False):  # a click or a key in the table
            self._selection_changed()

    def _selection_changed(self):
        self._update_predictions()
        self._update_thumbnails()
        name = self.current_name()
        if name != getattr(self, "_last_point", None):
            # another point: show the photo where it is to be placed next (or its first photo)
            self._last_point = name
            # an automatic GCP: a photo where it was measured, never one where it would be placed by hand
            target = self.automatic_photo(name) if self.store.is_automatic(name) else (
                self.next_photo() if name else None)
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
        report = self.report_path()
        self.act_report.setEnabled(report is not None)
        self.act_report.setToolTip(report or self.tr("The workspace has no accuracy report yet: run Accuracy report "
                                                     "(or Run pipeline)"))
        for a in (self.act_remove,):
            a.setEnabled(has_ws and has_point)
        self.act_pick.setEnabled(has_ws and self.map_tool is not None)
        self.act_export_file.setEnabled(bool(self.store.gcps.points))
        self.act_export_layer.setEnabled(bool(self.store.gcps.points))
        self.btn_georef.setEnabled(has_ws and not busy)
        self.btn_cancel.setEnabled(busy)
        self.btn_new.setEnabled(not busy)
        self.act_find_targets.setEnabled(has_ws and not busy)
        self.crs_label.setText(self.tr("CRS: {}").format(short_crs(self.store.crs)) if self.store.crs else "")

    # ------------------------------------------------------------------ points
    def add_point(self, name=None, x=math.nan, y=math.nan, z=math.nan):
        if self.store.workspace is None:
            return None
        try:
            name = self.store.add_point(name, x, y, z)
        except ValueError as e:
            self.message(str(e), Qgis.MessageLevel.Warning)
            return None
        self.select_point(name)
        return name

    def remove_selected(self):
        name = self.current_name()
        if name:
            self.store.remove_point(name)

    def confirm_prediction(self, image=None):
        """Accept the prediction (GcpPlacement); a refinement still matching in the background ends first.  A found
        observation shown (Find targets) is confirmed instead (ui/gcp_targets.py)."""
        if self.current_found() is not None and (image is None or image == self.photo_panel.image):
            return self.confirm_found()
        self.wait_for_refinement(image or self.photo_panel.image)
        return super().confirm_prediction(image)

    # ------------------------------------------------------------------ teardown
    def cleanup(self):
        self._unwatch_height_layers()
        for job in list(self.__dict__.get("_refine_jobs", {}).values()):
            job.cancel()
        if self.task is not None:
            self.task.cancel()
        self.set_picking(False)
        if self.markers is not None:
            self.markers.clear()
