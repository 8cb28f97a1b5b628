"""Run inside QGIS desktop (qgis --code) with a Python that lacks pycolmap/cv2 and a fresh profile: the
message bar item, its Install button, the dialog, a real install from a local wheel folder; screenshots.

Environment: AO_OUT (where the PNGs and log.json go), AO_WHEELS (a folder with the pinned wheels, optional:
without it the dialog installs from PyPI).  Used to make docs/screenshots/dependencies-*.png.
"""
import json
import os
import time

from qgis.PyQt.QtCore import QTimer
from qgis.PyQt.QtWidgets import QPushButton
from qgis.utils import iface, plugins

OUT = os.environ["AO_OUT"]
state = {"log": {}}


def note(key, value):
    state["log"][key] = value
    with open(os.path.join(OUT, "log.json"), "w") as f:
        json.dump(state["log"], f, indent=1)


def start():
    note("plugins", sorted(plugins.keys()))
    item = iface.messageBar().currentItem()
    note("message", item.text() if item is not None else None)
    iface.mainWindow().grab().save(os.path.join(OUT, "dependencies-message.png"))
    button = item.findChild(QPushButton, "ArchaeoOrthoInstallDependencies") if item is not None else None
    if button is None:
        note("error", "no Install button")
        QTimer.singleShot(300, iface.actionExit().trigger)
        return
    button.click()
    state["dialog"] = item._archaeoortho_dialog
    QTimer.singleShot(1500, install)


def install():
    dlg = state["dialog"]
    dlg.grab().save(os.path.join(OUT, "dependencies-dialog-idle.png"))
    note("packages", dlg.packages_label.text())
    wheels = os.environ.get("AO_WHEELS")
    if wheels:
        from archaeoortho.core.common import dependencies

        dlg.command = (dlg.python, dependencies.pip_arguments(dlg.target, find_links=wheels, no_index=True))
    dlg.install_button.click()
    state["t0"] = time.time()
    QTimer.singleShot(1200, lambda: dlg.grab().save(os.path.join(OUT, "dependencies-dialog-running.png")))
    QTimer.singleShot(500, poll)


def poll():
    dlg = state["dialog"]
    if dlg.state in ("done", "failed") or time.time() - state["t0"] > 600:
        note("state", dlg.state)
        note("log_tail", dlg.log.toPlainText()[-1500:])
        note("bar_items", len(iface.messageBar().items()))
        dlg.grab().save(os.path.join(OUT, "dependencies-dialog.png"))
        QTimer.singleShot(300, iface.actionExit().trigger)
    else:
        QTimer.singleShot(300, poll)


QTimer.singleShot(4000, start)
