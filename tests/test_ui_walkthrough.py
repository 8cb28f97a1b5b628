"""A person's whole COPR georeferencing in QGIS desktop (Xvfb), driven through the GCP dock with real
widget events, counting every click, key press and wheel step, with screenshots.

The simulated operator: opens the dock, makes a workspace from the photo folder and aligns it, imports the
surveyed coordinates (a points-only CSV, as a surveyor delivers them), marks two check points, then places
every target.  Where to click comes from the observations in COPR's gcp_list.txt (the clicks of the person
who made that file): a prediction within ACCEPT_PX of that click is confirmed with Enter, otherwise the
operator zooms in with the wheel and clicks the target.  Photos the dock proposes that the reference file
does not use are skipped (one click on the next thumbnail).  Finally the adjustment runs from the dock.

Opt-in (minutes, needs ../shared/data/copr, qgis and xvfb-run):
    ARCHAEOORTHO_WALKTHROUGH=1 make test PYTEST_ARGS='-s tests/test_ui_walkthrough.py'
ARCHAEOORTHO_WALKTHROUGH_REUSE=<aligned COPR workspace> reuses its features and matches (mapping and the
final adjustment still run in the dock).  Screenshots and log.json go to build/screenshots/walkthrough (or
$ARCHAEOORTHO_SCREENSHOTS/walkthrough).
"""
import json
import math
import os
import shutil
import subprocess
import sysconfig
import time

import pytest

from tests.conftest import PLUGINS, ROOT, SHARED_DATA

pytestmark = pytest.mark.slow

ACCEPT_PX = 2.0  # the operator accepts a prediction this close to where they would click
FIRST = ["gcp09", "gcp04", "gcp01"]  # three well-spread targets first
ORDER = FIRST + ["gcp02", "gcp08", "gcp07", "gcp05", "gcp03", "gcp06", "gcp00"]
CHECK = ["gcp03", "gcp06"]
OUT = os.path.join(os.environ.get("ARCHAEOORTHO_SCREENSHOTS") or os.path.join(ROOT, "build", "screenshots"),
                   "walkthrough")


@pytest.mark.skipif(os.environ.get("ARCHAEOORTHO_WALKTHROUGH") != "1", reason="opt-in: ARCHAEOORTHO_WALKTHROUGH=1")
@pytest.mark.skipif(not (shutil.which("qgis") and shutil.which("xvfb-run")), reason="needs qgis and xvfb-run")
def test_copr_georeferencing_in_qgis_desktop(tmp_path):
    copr = os.path.join(SHARED_DATA, "copr")
    if not os.path.isfile(os.path.join(copr, "gcp_list.txt")):
        pytest.skip("COPR data not available")
    from core.io import gcp as gcpmod

    ref = gcpmod.read_gcps(os.path.join(copr, "gcp_list.txt"))
    points_csv = str(tmp_path / "copr_targets.csv")
    survey = gcpmod.GCPSet(ref.crs, [gcpmod.GroundPoint(p.name, p.x, p.y, p.z) for p in ref.points])
    gcpmod.write_csv_gcps(survey, points_csv)
    os.unlink(gcpmod.default_observations_path(points_csv))  # coordinates only
    ws = str(tmp_path / "copr workspace")
    reuse = os.environ.get("ARCHAEOORTHO_WALKTHROUGH_REUSE")
    if reuse:
        os.makedirs(os.path.join(ws, "sfm"))
        shutil.copy(os.path.join(reuse, "sfm", "database.db"), os.path.join(ws, "sfm", "database.db"))
        manifest = json.load(open(os.path.join(reuse, "workspace.json")))
        key = manifest["stages"]["align"]["database_key"]
        manifest["stages"] = {"align": {"status": "pending", "database_key": key}}
        manifest["crs"] = None
        json.dump(manifest, open(os.path.join(ws, "workspace.json"), "w"))
    shutil.rmtree(OUT, ignore_errors=True)
    os.makedirs(OUT)
    launcher = tmp_path / "walkthrough_launcher.py"
    launcher.write_text(f"import sys\nsys.path.insert(0, {ROOT!r})\n"
                        "from tests.test_ui_walkthrough import desktop_main\ndesktop_main()\n")
    env = dict(os.environ)
    env.pop("QT_QPA_PLATFORM", None)
    env.update(AO_OUT=OUT, AO_IMAGES=os.path.join(copr, "images"), AO_WORKSPACE=ws, AO_POINTS=points_csv,
               AO_REFERENCE=os.path.join(copr, "gcp_list.txt"),
               QGIS_PLUGINPATH=PLUGINS, QGIS_CUSTOM_CONFIG_PATH=os.path.join(ROOT, "build", "qgis-profile"),
               PYTHONPATH=os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")]))
    t0 = time.time()
    subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1600x1000x24", "qgis", "--nologo", "--noversioncheck",
                    "--code", str(launcher)], env=env, capture_output=True, timeout=3000)
    log = json.load(open(os.path.join(OUT, "log.json")))
    log["wall_seconds"] = round(time.time() - t0, 1)
    json.dump(log, open(os.path.join(OUT, "log.json"), "w"), indent=1)
    print(json.dumps({k: v for k, v in log.items() if k != "placements"}, indent=1))
    assert "error" not in log, log.get("error")
    assert log["aligned"] >= 35
    assert log["placed_observations"] >= 26
    assert log["georeference"]["GCP_N"] >= 7
    assert log["georeference"]["CHECK_N"] == 2
    for name in ("1-docks", "2-aligned", "3-imported", "5-guided", "7-georeferenced"):
        assert os.path.getsize(os.path.join(OUT, f"{name}.png")) > 20000


# --------------------------------------------------------------------------------------------------
# inside QGIS desktop (qgis --code): a generator of steps driven by QTimer
# --------------------------------------------------------------------------------------------------


class Operator:
    """Counts what a person does: clicks, keys, wheel steps; each through real widget events."""

    def __init__(self):
        self.clicks = 0
        self.keys = 0
        self.wheel = 0
        self.log = {"placements": [], "steps": []}

    def click_widget(self, widget, pos=None):
        from qgis.PyQt.QtCore import Qt
        from qgis.PyQt.QtTest import QTest

        if pos is None:
            pos = widget.rect().center()
        QTest.mouseClick(widget, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, pos)
        self.clicks += 1

    def key(self, widget, key):
        from qgis.PyQt.QtTest import QTest

        widget.setFocus()
        QTest.keyClick(widget, key)
        self.keys += 1

    def counts(self):
        return {"clicks": self.clicks, "keys": self.keys, "wheel_steps": self.wheel}


def _save(op):
    with open(os.path.join(os.environ["AO_OUT"], "log.json"), "w") as f:
        json.dump(op.log, f, indent=1)


def _shot(name, op):
    from qgis.PyQt.QtWidgets import QApplication

    QApplication.processEvents()
    QApplication.primaryScreen().grabWindow(0).save(os.path.join(os.environ["AO_OUT"], name + ".png"))
    op.log["steps"].append({"screenshot": name, **op.counts()})
    _save(op)


def desktop_main():
    from qgis.PyQt.QtCore import QTimer

    op = Operator()
    gen = _walk(op)

    def step(value=None):
        try:
            wait = next(gen)
        except StopIteration:
            _save(op)
            _quit()
            return
        except Exception as e:  # a broken chain would hang QGIS: note it and quit
            import traceback

            op.log["error"] = repr(e)
            op.log["traceback"] = traceback.format_exc()
            _save(op)
            _quit()
            return
        if callable(wait):
            poll(wait, time.time())
        else:
            QTimer.singleShot(int(1000 * (wait or 0.05)), step)

    def poll(pred, t0):
        if pred() or time.time() - t0 > 2400:
            step()
        else:
            QTimer.singleShot(250, lambda: poll(pred, t0))

    QTimer.singleShot(4000, step)


def _quit():
    """Leave QGIS without the 'save the project?' question (the result layers made the project dirty)."""
    from qgis.core import QgsProject
    from qgis.PyQt.QtCore import QTimer
    from qgis.utils import iface

    QgsProject.instance().setDirty(False)
    QgsProject.instance().clear()
    QTimer.singleShot(500, iface.actionExit().trigger)


def _thumb_click(op, dock, name):
    from qgis.PyQt.QtCore import Qt

    panel = dock.photo_panel
    for i in range(panel.thumbs.count()):
        item = panel.thumbs.item(i)
        if item.data(Qt.ItemDataRole.UserRole) == name:
            panel.thumbs.scrollToItem(item)
            op.click_widget(panel.thumbs.viewport(), panel.thumbs.visualItemRect(item).center())
            return True
    return False


def _walk(op):
    from archaeoortho.core.io import gcp as gcpmod
    from qgis.core import QgsProject
    from qgis.PyQt.QtCore import QPoint, QPointF, Qt
    from qgis.utils import iface, plugins

    reference = gcpmod.read_gcps(os.environ["AO_REFERENCE"])
    plugin = plugins["archaeoortho"]
    win = iface.mainWindow()
    win.setGeometry(0, 0, 1600, 1000)  # no window manager under Xvfb: 'maximized' means nothing
    yield 1.0
    # 1. open the docks from the toolbar
    op.clicks += 1
    plugin.action.trigger()
    dock = plugin.dock
    yield 0.5
    win.resizeDocks([dock], [660], Qt.Orientation.Horizontal)
    win.resizeDocks([dock.photo_dock], [430], Qt.Orientation.Vertical)
    yield 0.5
    _shot("1-docks", op)

    # 2. New from photos: the button, a folder dialog for the photos and one for the workspace (choose + OK)
    op.clicks += 1 + 2 + 2
    t0 = time.time()
    task = dock.start_alignment(os.environ["AO_IMAGES"], os.environ["AO_WORKSPACE"])
    assert task is not None
    yield 20.0
    _shot("2a-aligning", op)
    yield lambda: dock.task is None
    op.log["align_seconds"] = round(time.time() - t0, 1)
    assert dock.last_task_error is None, dock.last_task_error
    op.log["aligned"] = len(dock.predictor.image_names) if dock.predictor else 0
    yield 1.0
    _shot("2-aligned", op)

    # 3. import the surveyed coordinates: Import > From file, choose the file + OK
    op.clicks += 2 + 2
    dock.import_file(os.environ["AO_POINTS"])
    # check points: double-click the role cell, open the list, choose 'check'
    from archaeoortho.ui.gcp_table import ROLE

    for name in CHECK:
        row = [p.name for p in dock.store.gcps.points].index(name)
        op.clicks += 3
        dock.model.setData(dock.model.index(row, ROLE), gcpmod.CHECK)
    yield 0.5
    _shot("3-imported", op)

    # 4. place the targets
    panel = dock.photo_panel
    view = panel.view
    placed = 0
    for k, name in enumerate(ORDER):
        row = [p.name for p in dock.store.gcps.points].index(name)
        op.click_widget(dock.table.viewport(), dock.table.visualRect(dock.model.index(row, 0)).center())
        yield 0.3
        todo = [o for o in reference.by_name(name).observations]
        while todo:
            shown = panel.image
            target = next((o for o in todo if o.image == shown), None)
            if target is None:
                target = todo[0]
                assert _thumb_click(op, dock, target.image), (name, target.image)
                yield 0.3
            todo.remove(target)
            pred, match = dock.refined_prediction(target.image)
            rec = {"point": name, "image": target.image, "prediction": pred.source if pred else None}
            if pred is not None:
                rec["prediction_px"] = round(math.hypot(pred.x - target.x, pred.y - target.y), 2)
                if match is not None:
                    rec["geometric_px"] = round(math.hypot(dock.predictions[target.image].x - target.x,
                                                           dock.predictions[target.image].y - target.y), 1)
            if pred is not None and rec["prediction_px"] <= ACCEPT_PX:
                before = op.keys
                op.key(view, Qt.Key.Key_Return)  # confirm (and show the next photo to place)
                rec["action"] = "confirm"
                rec["actions"] = op.keys - before
            else:
                # zoom in with the wheel over the target until one screen pixel is a quarter image pixel
                z = view.zoom()
                notches = max(0, math.ceil(math.log(4.0 / z) / math.log(1.25))) if z < 4.0 else 0
                op.wheel += notches
                view.set_zoom(z * 1.25 ** notches if notches else z, QPointF(target.x, target.y))
                yield 0.2
                w = view.mapFromScene(QPointF(target.x, target.y))
                before = op.clicks
                op.click_widget(view.viewport(), QPoint(w.x(), w.y()))
                rec["action"] = "click"
                rec["wheel_steps"] = notches
                rec["actions"] = op.clicks - before
                obs = next(o for o in dock.store.gcps.by_name(name).observations if o.image == target.image)
                rec["click_px"] = round(math.hypot(obs.x - target.x, obs.y - target.y), 3)
            placed += 1
            op.log["placements"].append(rec)
            yield 0.3
            if k == 3 and len(todo) == 1:
                _shot("5-guided", op)
        if k == 0:
            _shot("4-first-point", op)
    op.log["placed_observations"] = placed
    _save(op)

    # 5. adjust: the Georeference button, then look at the residuals
    op.click_widget(dock.btn_georef)
    t0 = time.time()
    yield 5.0
    _shot("6-adjusting", op)
    yield lambda: dock.task is None
    op.log["georeference_seconds"] = round(time.time() - t0, 1)
    assert dock.last_task_error is None, dock.last_task_error
    op.log["georeference"] = dict(dock.store.figures)
    op.log["residuals"] = {n: {k: r.get(k) for k in ("status", "dx", "dy", "dz")}
                           for n, r in dock.store.residuals.items()}
    layer = next((lyr for lyr in QgsProject.instance().mapLayers().values()
                  if lyr.customProperty("archaeoortho/kind") == "residuals"), None)
    if layer is not None:
        ext = layer.extent()
        ext.scale(1.6)
        iface.mapCanvas().setExtent(ext)
        iface.mapCanvas().refresh()
    yield 3.0
    dock.select_point("gcp06")
    yield 1.0
    _shot("7-georeferenced", op)
    op.log["counts"] = op.counts()
    op.log["layers"] = sorted(lyr.name() for lyr in QgsProject.instance().mapLayers().values())
    _save(op)
