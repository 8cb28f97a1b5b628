"""'Open accuracy report' in the context menu of a workspace's layer group in the Layers panel (issue 48 item 5):
after a restart the Results Viewer is empty, and the group of the workspace's layers is where a user looks.

The entry opens the report the dock's Report button opens (core.report.stage.report_of: the file the report
stage recorded, else <workspace>/report.html) in the web browser; a workspace with none shows the entry
disabled, saying how to make one.  A group is a workspace's when the files of its layers (remembered by
qgisio.layers as it loads them) lie in one workspace folder, whatever the group is called.

The hook: QgsLayerTreeView.contextMenuAboutToShow (QGIS 3.32 and later); before it (3.22 to 3.30), the right
click on a workspace's group is taken on the view's viewport, and the menu QGIS's own menu provider makes is
shown with the entry added (setMenuProvider would delete QGIS's provider, so it is never replaced).
"""
import os

from qgis.core import QgsLayerTree
from qgis.PyQt.QtCore import QCoreApplication, QEvent, QObject, QUrl
from qgis.PyQt.QtGui import QDesktopServices
from qgis.PyQt.QtWidgets import QMenu

from ..qgisio import layers


def tr(text):
    return QCoreApplication.translate("WorkspaceGroupMenu", text)


def workspace_of_group(node):
    """The workspace folder whose layers the layer-tree group ``node`` holds, None for any other node (a layer,
    a group of the user's layers, a group mixing two workspaces' layers)."""
    if node is None or not QgsLayerTree.isGroup(node):
        return None
    roots = set()
    for child in node.findLayers():
        layer = child.layer()
        path = layer.customProperty(layers.PATH_PROPERTY, "") if layer is not None else ""
        root = layers.workspace_of(path) if path else None
        if root:
            roots.add(os.path.normpath(root))
    return roots.pop() if len(roots) == 1 else None


def report_of_folder(root):
    """The accuracy report of the workspace folder ``root`` on disk (as the dock's Report button finds it), None
    when it has none or ``root`` is no workspace any more."""
    from ..core.project.workspace import Workspace, WorkspaceError
    from ..core.report.stage import report_of

    try:
        return report_of(Workspace.open(root))
    except WorkspaceError:
        return None


def open_report(path, iface=None):
    """``path`` in the web browser; False (said in the message bar) when none opened."""
    if QDesktopServices.openUrl(QUrl.fromLocalFile(path)):
        return True
    if iface is not None:
        from qgis.core import Qgis

        iface.messageBar().pushMessage(tr("ArchaeoOrtho"), tr("No web browser opened {}").format(path),
                                       Qgis.MessageLevel.Warning, 8)
    return False


class WorkspaceGroupMenu(QObject):
    """Adds 'Open accuracy report' to the Layers panel's context menu of a workspace's group."""

    def __init__(self, iface):
        super().__init__()
        self.iface = iface
        self.view = None
        self.hooked = None  # "signal" (QGIS 3.32+) or "viewport" (before)

    def install(self):
        view = self.iface.layerTreeView() if self.iface is not None else None
        if view is None or not hasattr(view, "currentNode"):  # no real layer tree (a mock in tests)
            return False
        self.view = view
        if hasattr(view, "contextMenuAboutToShow"):
            view.contextMenuAboutToShow.connect(self._about_to_show)
            self.hooked = "signal"
        else:
            view.viewport().installEventFilter(self)
            self.hooked = "viewport"
        return True

    def uninstall(self):
        if self.view is None:
            return
        try:
            if self.hooked == "signal":
                self.view.contextMenuAboutToShow.disconnect(self._about_to_show)
            elif self.hooked == "viewport":
                self.view.viewport().removeEventFilter(self)
        except (TypeError, RuntimeError):  # the view is gone (QGIS closing)
            pass
        self.view = self.hooked = None

    def add_actions(self, menu, node):
        """The entry for ``node`` added to ``menu``; returns it (None for a node that is no workspace's group)."""
        root = workspace_of_group(node)
        if root is None:
            return None
        report = report_of_folder(root)
        menu.addSeparator()
        action = menu.addAction(tr("Open accuracy report"))
        action.setObjectName("ArchaeoOrthoOpenReport")
        if report is None:
            action.setEnabled(False)
            action.setText(tr("Open accuracy report (none yet: run Accuracy report or Run pipeline)"))
        else:
            action.setToolTip(report)
            action.triggered.connect(lambda _checked=False, p=report: open_report(p, self.iface))
        menu.setToolTipsVisible(True)
        return action

    def _about_to_show(self, menu):
        self.add_actions(menu, self.view.currentNode())

    def eventFilter(self, obj, event):  # noqa: N802 (Qt API)
        """QGIS before 3.32: a right click on a workspace's group shows QGIS's menu for it with the entry."""
        if self.view is None or event.type() != QEvent.Type.ContextMenu or obj is not self.view.viewport():
            return super().eventFilter(obj, event)
        index = self.view.indexAt(event.pos())
        node = self.view.index2node(index) if index.isValid() else None
        if workspace_of_group(node) is None:
            return super().eventFilter(obj, event)
        self.view.setCurrentIndex(index)
        provider = self.view.menuProvider()
        menu = provider.createContextMenu() if provider is not None else None
        menu = menu if menu is not None else QMenu(self.view)
        self.add_actions(menu, node)
        self._exec(menu, self.view.viewport().mapToGlobal(event.pos()))
        menu.deleteLater()
        return True

    @staticmethod
    def _exec(menu, pos):
        return menu.exec(pos)
