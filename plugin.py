"""Wires the faces into QGIS: the Processing provider (always) and, with a GUI, the docks."""
import os

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QCoreApplication, QTranslator

PLUGIN_DIR = os.path.dirname(__file__)


def _locale() -> str:
    """The two-letter language QGIS runs in (qgisio/messages.qgis_language: the plugin's translator and the
    report's language follow the same reading)."""
    from .qgisio.messages import qgis_language

    return qgis_language()


class ArchaeoOrthoPlugin:
    """QGIS plugin object.  ``iface`` is None under qgis_process: nothing GUI-only runs then."""

    def __init__(self, iface):
        self.iface = iface
        self.provider = None
        self.translator = None
        self._language = None
        self.action = None
        self.dock = None
        self.dependencies_dir = None
        self.dependencies_message = None
        self.results_workspace = None  # the workspace a Processing run just loaded layers of (the dock follows)
        self.group_menu = None  # "Open accuracy report" in the context menu of a workspace's layer group
        self._install_translator()
        self._activate_dependencies()

    def tr(self, text):
        return QCoreApplication.translate("ArchaeoOrthoPlugin", text)

    def _install_translator(self):
        """The translation of the language QGIS runs in; called again by initProcessing / initGui (QGIS has
        applied ``--lang`` and the Options override by then): a changed language swaps the translator."""
        lang = _locale()
        if lang == self._language:
            return
        if self.translator is not None:
            QCoreApplication.removeTranslator(self.translator)
            self.translator = None
        self._language = None
        self._language = lang
        qm = os.path.join(PLUGIN_DIR, "i18n", f"archaeoortho_{lang}.qm")
        if os.path.exists(qm):
            self.translator = QTranslator()
            if self.translator.load(qm):
                QCoreApplication.installTranslator(self.translator)
            else:
                self.translator = None

    def _activate_dependencies(self):
        """pycolmap / OpenCV installed by the plugin live in its folder in the QGIS profile: on sys.path now."""
        from .core.common import dependencies

        try:
            self.dependencies_dir = dependencies.activate(QgsApplication.qgisSettingsDirPath())
        except Exception as e:  # noqa: BLE001 - never fail the plugin's load over this
            from qgis.core import Qgis, QgsMessageLog

            QgsMessageLog.logMessage(f"ArchaeoOrtho: dependency folder not added: {e}", "ArchaeoOrtho",
                                     Qgis.MessageLevel.Warning)

    def _offer_dependencies(self):
        """ONE message bar item (with an Install button) when pycolmap / OpenCV are missing or unusable."""
        from .core.common import dependencies

        bad = dependencies.problems(dependencies.check())
        if bad:
            from .ui.dependencies import push_missing_message

            self.dependencies_message = push_missing_message(self.iface, bad,
                                                             QgsApplication.qgisSettingsDirPath())

    def initProcessing(self):  # noqa: N802 (QGIS API name)
        if self.provider is not None:
            return
        self._install_translator()  # before the algorithms' labels are made
        from .processing_provider.provider import ArchaeoOrthoProvider

        self.provider = ArchaeoOrthoProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802 (QGIS API name)
        self._install_translator()
        self.initProcessing()
        if self.iface is None:
            return
        from qgis.PyQt.QtGui import QIcon

        try:  # Qt6 moved QAction to QtGui
            from qgis.PyQt.QtGui import QAction
        except ImportError:
            from qgis.PyQt.QtWidgets import QAction

        self.action = QAction(QIcon(os.path.join(PLUGIN_DIR, "icon.svg")), self.tr("Ground control (GCP dock)"),
                              self.iface.mainWindow())
        self.action.setObjectName("ArchaeoOrthoGcpAction")
        self.action.setCheckable(True)
        self.action.setToolTip(self.tr("ArchaeoOrtho: pick ground control points on the map and in the photos"))
        self.action.toggled.connect(self.show_dock)
        self.iface.addPluginToRasterMenu(self.tr("&ArchaeoOrtho"), self.action)
        # the Plugins toolbar is shown by default (the Raster toolbar is not)
        self.iface.addToolBarIcon(self.action)
        from .qgisio.layers import results_notifier

        results_notifier().workspaceLoaded.connect(self._workspace_from_results)
        self._install_group_menu()
        self._offer_dependencies()

    def _install_group_menu(self):
        from .ui.workspace_menu import WorkspaceGroupMenu

        self.group_menu = WorkspaceGroupMenu(self.iface)
        self.group_menu.install()

    def _workspace_from_results(self, root):
        """A Processing run (Run pipeline from the Toolbox) loaded the layers of workspace ``root``: the dock shows
        it (issue 48 item 4), once after the run's last layer, when the dock is next shown if it is not yet."""
        from qgis.PyQt.QtCore import QTimer

        first = self.results_workspace is None
        self.results_workspace = root
        if first:
            QTimer.singleShot(0, self._follow_results_workspace)

    def _follow_results_workspace(self):
        if self.dock is not None and self.results_workspace:
            self.dock.follow_workspace(self.results_workspace)
            self.results_workspace = None

    def show_dock(self, visible=True):
        """Create the GCP dock (and its photo dock) on first use and show or hide both."""
        if self.iface is None:
            return None
        if self.dock is None:
            if not visible:
                return None
            from .ui.dock_layout import place_docks
            from .ui.gcp_dock import GcpDock

            self.dock = GcpDock(self.iface, parent=self.iface.mainWindow())
            self.dock.refine_in_background = True  # matching a prediction never blocks QGIS (issue 18.5)
            # each a side column's height: the GCP dock a tab beside the Toolbox on the right, the photos a tab
            # beside the Layers panel on the left; the map keeps the window's height (issue 48 item 7)
            place_docks(self.iface.mainWindow(), self.dock, self.dock.photo_dock, add=self.iface.addDockWidget)
            self.dock.visibilityChanged.connect(self._dock_visibility)
            self.dock.setUserVisible(visible)
            self.dock.photo_dock.setUserVisible(visible)
            self._follow_results_workspace()  # a run's workspace from before the dock was first shown
        self.dock.setUserVisible(visible)
        self.dock.photo_dock.setUserVisible(visible)
        if self.action is not None and self.action.isChecked() != visible:
            self.action.setChecked(visible)
        return self.dock

    def _dock_visibility(self, visible):
        if self.action is not None and not visible and self.dock is not None and not self.dock.isUserVisible():
            self.action.blockSignals(True)
            self.action.setChecked(False)
            self.action.blockSignals(False)

    def unload(self):
        if self.iface is not None and self.action is not None:
            from .qgisio.layers import results_notifier

            try:
                results_notifier().workspaceLoaded.disconnect(self._workspace_from_results)
            except (TypeError, RuntimeError):  # not connected
                pass
        if self.group_menu is not None:
            self.group_menu.uninstall()
            self.group_menu = None
        if self.dock is not None:
            self.dock.cleanup()
            if self.iface is not None:
                self.iface.removeDockWidget(self.dock)
                self.iface.removeDockWidget(self.dock.photo_dock)
            self.dock.photo_dock.deleteLater()
            self.dock.deleteLater()
            self.dock = None
        if self.action is not None and self.iface is not None:
            self.iface.removePluginRasterMenu(self.tr("&ArchaeoOrtho"), self.action)
            self.iface.removeToolBarIcon(self.action)
            self.action.deleteLater()
            self.action = None
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
        if self.translator is not None:
            QCoreApplication.removeTranslator(self.translator)
            self.translator = None
        self._language = None
