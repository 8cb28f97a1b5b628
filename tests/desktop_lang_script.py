"""Run inside QGIS desktop (qgis --lang de --code ...): the plugin's toolbar icon, its language, the docks'
default sizes and a workspace opened in the GCP dock, as a new user meets them; a screenshot of the window.

Driven by tests/test_ui_dock_layout.py (test_qgis_desktop_lang_de); writes log.json and screen.png to $AO_OUT.
With AO_PROCESSING_DOCKS=1 the Processing Toolbox and Results Viewer are shown first (docked on the right, where
the GCP dock goes too: issue 36 item 20).
"""
import json
import os
import traceback

from qgis.PyQt.QtCore import QTimer
from qgis.PyQt.QtWidgets import QApplication, QToolBar, QToolButton
from qgis.utils import iface, plugins

OUT = os.environ["AO_OUT"]
log = {}


def save():
    with open(os.path.join(OUT, "log.json"), "w") as f:
        json.dump(log, f, indent=1, ensure_ascii=False)


def guarded(fn):
    def run():
        try:
            fn()
        except Exception:  # a broken timer chain would hang QGIS: note it and quit
            log["error"] = traceback.format_exc()
            save()
            iface.actionExit().trigger()
    return run


@guarded
def start():
    from qgis.core import QgsApplication

    win = iface.mainWindow()  # the whole screen, as a maximised window (Xvfb has no window manager to do it)
    win.move(0, 0)
    win.resize(QApplication.primaryScreen().size())
    log["plugins"] = sorted(plugins)
    log["translation"] = QgsApplication.instance().translation()
    p = plugins["archaeoortho"]
    log["translator"] = p.translator is not None
    bar = iface.pluginToolBar()
    log["plugins_toolbar_visible"] = bar.isVisible()
    log["icon_on_plugins_toolbar"] = p.action in bar.actions()
    w = bar.widgetForAction(p.action)
    log["icon_shown"] = bool(w is not None and w.isVisible())
    if os.environ.get("AO_PROCESSING_DOCKS"):
        processing = plugins["processing"]
        for dock in (processing.toolbox, processing.resultsDock):
            dock.setUserVisible(True)
    QTimer.singleShot(1500, click)


@guarded
def click():
    plugins["archaeoortho"].action.trigger()  # a click on the icon
    QTimer.singleShot(1500, opened)


@guarded
def opened():
    d = plugins["archaeoortho"].dock
    d.open_workspace(os.environ["AO_WORKSPACE"])
    QTimer.singleShot(2500, look)


@guarded
def look():
    d = plugins["archaeoortho"].dock
    log["texts"] = {"open": d.btn_open.text(), "new": d.btn_new.text(), "georef": d.btn_georef.text(),
                    "import": [a.text() for a in d.import_menu.actions()],
                    "export": [a.text() for a in d.export_menu.actions()]}
    log["window"] = [iface.mainWindow().width(), iface.mainWindow().height()]
    log["dock"] = [d.width(), d.height()]
    log["photo_dock"] = [d.photo_dock.width(), d.photo_dock.height()]
    log["photo_view_height"] = d.photo_panel.view.height()
    log["screen"] = [QApplication.primaryScreen().size().width(), QApplication.primaryScreen().size().height()]
    log["dock_minimum_height"] = d.minimumSizeHint().height()
    # room left to the map: the main window's central area, where the map canvas is (or QGIS's welcome page, which
    # it shows instead until a layer is loaded): 145 px high with the photo dock at the bottom (issue 48 item 7)
    central = iface.mainWindow().centralWidget()
    log["canvas"] = [central.width(), central.height()]
    log["photo_view"] = [d.photo_panel.view.width(), d.photo_panel.view.height()]
    toolbox = plugins["processing"].toolbox
    log["toolbox_shown"] = toolbox.isVisible()
    log["georef_row_bottom"] = max(w.mapToGlobal(w.rect().bottomLeft()).y() for w in (d.btn_georef, d.btn_cancel))
    log["georef_row_visible"] = d.btn_georef.isVisible() and d.btn_cancel.isVisible()
    hidden = []
    for bar in d.findChildren(QToolBar):
        ext = bar.findChild(QToolButton, "qt_toolbar_ext_button")
        if ext is not None and ext.isVisible():
            hidden.append(">>")
        for a in bar.actions():
            w = bar.widgetForAction(a)
            if w is not None and (not w.isVisible() or w.geometry().right() > bar.width()):
                hidden.append(a.text())
    log["toolbar_hidden"] = hidden
    header, width = d.table.horizontalHeader(), d.table.viewport().width()
    from archaeoortho.ui.gcp_dock import KEY_COLUMNS

    log["key_columns_hidden"] = [c for c in KEY_COLUMNS if header.sectionViewportPosition(c) < 0
                                 or header.sectionViewportPosition(c) + header.sectionSize(c) > width]
    QApplication.primaryScreen().grabWindow(0).save(os.path.join(OUT, "screen.png"))
    save()
    if not os.environ.get("AO_PROCESSING_DOCKS"):
        QTimer.singleShot(300, iface.actionExit().trigger)
        return
    toolbox.raise_()  # the Toolbox in a tab beside the GCP dock: its list when the user brings it up
    QTimer.singleShot(500, toolbox_raised)


@guarded
def toolbox_raised():
    tree = plugins["processing"].toolbox.algorithmTree
    log["toolbox_list_height"] = tree.height() if tree.isVisible() else 0
    QApplication.primaryScreen().grabWindow(0).save(os.path.join(OUT, "screen-toolbox.png"))
    save()
    QTimer.singleShot(300, iface.actionExit().trigger)


QTimer.singleShot(4000, start)
