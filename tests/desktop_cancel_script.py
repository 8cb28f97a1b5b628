"""Run inside QGIS desktop (qgis --code): open Align images from the toolbox, run, cancel, screenshot.

Driven by tests/test_qgis_desktop.py; writes a JSON log and PNG screenshots to $AO_OUT.
"""
import json
import os
import time

from qgis import processing
from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QTimer
from qgis.PyQt.QtWidgets import QApplication, QProgressBar, QPushButton
from qgis.utils import iface, plugins

OUT = os.environ["AO_OUT"]
state = {"log": []}


def save():
    with open(os.path.join(OUT, "log.json"), "w") as f:
        json.dump(state["log"], f)


def note(key, value):
    state["log"].append([key, value])
    save()


def shot(name):
    QApplication.primaryScreen().grabWindow(0).save(os.path.join(OUT, name + ".png"))


def start():
    note("plugins", sorted(plugins.keys()))
    note("providers", [p.id() for p in QgsApplication.processingRegistry().providers()].count("archaeoortho"))
    dlg = processing.createAlgorithmDialog("archaeoortho:alignimages", {
        "IMAGES": os.environ["AO_IMAGES"], "WORKSPACE": os.environ["AO_WORKSPACE"]})
    state["dlg"] = dlg
    dlg.show()
    QTimer.singleShot(1000, lambda: shot("1-dialog"))
    QTimer.singleShot(1500, run)


def run():
    state["dlg"].runAlgorithm()
    state["t_run"] = time.time()
    QTimer.singleShot(500, poll)


def poll():
    try:
        _poll()
    except Exception as e:  # a broken timer chain would hang QGIS: note it and quit
        note("error", repr(e))
        iface.actionExit().trigger()


def _poll():
    dlg = state["dlg"]
    value = max(b.value() for b in dlg.findChildren(QProgressBar))
    if value >= 40:  # matching: cancel now
        note("progress_before_cancel", value)
        shot("2-running")
        for b in dlg.findChildren(QPushButton):
            if "ancel" in b.text() and b.isVisible() and b.isEnabled():
                b.click()
                note("clicked", b.text())
        state["t_cancel"] = time.time()
        QTimer.singleShot(500, wait_cancelled)
    elif time.time() - state["t_run"] > 240:
        note("timeout", value)
        iface.actionExit().trigger()
    else:
        QTimer.singleShot(300, poll)


def wait_cancelled():
    path = os.path.join(os.environ["AO_WORKSPACE"], "workspace.json")
    status = json.load(open(path))["stages"]["align"]["status"] if os.path.exists(path) else None
    if status != "running" or time.time() - state["t_cancel"] > 30:
        note("status", status)
        note("cancel_seconds", round(time.time() - state["t_cancel"], 2))
        shot("3-cancelled")
        QTimer.singleShot(300, iface.actionExit().trigger)
    else:
        QTimer.singleShot(200, wait_cancelled)


QTimer.singleShot(3000, start)
