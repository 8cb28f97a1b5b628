"""The GCP dock's Find targets (issue 34 item 4), offscreen, on tests/targets_scene.py's rendered block (tilted ground
plane, checkerboard, circular and ArUco targets, nadir and oblique shots, an arbitrary model frame).

The task fills the table with the observations found as one undoable step, marks them as found (saved with the
dock's control and read back), never overwrites an observation placed by hand, lists what it did not find in the
message area; Space / Enter confirm and Delete / R reject the found observation shown, in the photo view and the
table, each going on to the next one.  Positions are checked against the rendered truth.
"""
import json
import math
import os
import types

import pytest

from tests import targets_scene
from tests.test_ui_dock import dock, process, wait_task  # noqa: F401 (fixtures and helpers of the dock tests)
from tests.workspaces import synthetic_workspace

pytestmark = pytest.mark.usefixtures("qgis_app")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCREENSHOT = os.path.join(ROOT, "docs", "screenshots", "dock-find-targets.png")
BLUE = "#1f6fd1"


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("dock_targets")
    sc = targets_scene.render(str(root / "photos"))
    csv = targets_scene.write_targets_csv(sc, str(root / "targets.csv"))
    return sc, targets_scene.reconstruction(sc), csv


@pytest.fixture
def ws(scene, tmp_path):
    sc, rec, _ = scene
    fake = types.SimpleNamespace(camera=types.SimpleNamespace(width=targets_scene.W, height=targets_scene.H),
                                 names=[s[0] for s in sc.shots])
    return synthetic_workspace(str(tmp_path / "ws"), fake, rec, photos=sc.photos)


def _observations(store):
    return {(p.name, o.image): (o.x, o.y) for p in store.gcps.points for o in p.observations}


def _find(dock, csv, **kw):  # noqa: F811 (the dock fixture)
    assert dock.run_find_targets(csv, **kw) is not None and dock.task is not None
    assert not dock.act_find_targets.isEnabled()  # one task at a time; the GUI runs meanwhile
    wait_task(dock, 300)
    assert dock.last_task_error is None, dock.last_task_error
    return dock.targets_result


def _hand_placed(dock, sc):  # noqa: F811
    """A target placed by hand 2 px off its truth in the first photo that shows it whole, and a point of the
    user's own: two undoable steps each."""
    image = next(i for i, v in sc.visible.items() if "ring_b" in v)
    tx, ty = sc.truth[image]["ring_b"]
    t = next(t for t in sc.targets if t.name == "ring_b")
    w = [t.x + targets_scene.OFFSET[0], t.y + targets_scene.OFFSET[1], t.z + targets_scene.OFFSET[2]]
    dock.store.add_point("ring_b", *w)
    dock.store.set_observation("ring_b", image, tx + 2.0, ty)
    dock.store.add_point("wall_corner", w[0] + 1.0, w[1], w[2])
    return image, (tx + 2.0, ty)


def test_find_targets_fills_the_table_in_one_undoable_step_and_keeps_what_was_placed_by_hand(dock, ws, scene):  # noqa: F811,E501
    sc, _, csv = scene
    assert dock.open_workspace(ws)
    hand_image, hand_xy = _hand_placed(dock, sc)
    steps = dock.store.undo_stack.count()
    r = _find(dock, csv)
    assert dock.store.undo_stack.count() == steps + 1  # the whole outcome is one step
    obs = _observations(dock.store)
    assert obs[("ring_b", hand_image)] == hand_xy  # never overwritten by the found one
    assert dock.store.is_found("ring_b", hand_image) is None
    assert {p.name for p in dock.store.gcps.points} == {t.name for t in sc.targets} | {"wall_corner"}
    found = dock.store.found_list()
    assert len(found) >= 0.95 * sum(len(v) for v in sc.visible.values()) - 1
    assert len(found) == r.n_observations - (1 if any(o.name == "ring_b" and o.image == hand_image
                                                      for o in r.observations) else 0)
    core = {(o.name, o.image): o for o in r.observations}
    for name, image in found:  # what the core found, where the truth is; marked with its quality
        x, y = obs[(name, image)]
        assert (x, y) == (float(core[(name, image)].x), float(core[(name, image)].y))
        assert math.hypot(x - sc.truth[image][name][0], y - sc.truth[image][name][1]) < 1.5, (name, image)
        assert dock.store.is_found(name, image)["quality"] == round(float(core[(name, image)].quality), 3) > 0
    text = dock.status.text()
    assert text.startswith("Find targets: 9 of 9 targets found") and "Space or Enter" in text
    # the table and the photo view show the marks: the first found observation is on screen, in blue
    assert dock.current_found() == found[0]
    assert dock.photo_panel.observation.colour.name() == BLUE and dock.photo_panel.found_note.isVisible()
    assert "quality" in dock.photo_panel.observation.toolTip()
    from qgis.PyQt.QtCore import Qt

    strip = dock.photo_panel.thumbs
    blue = {strip.item(i).data(Qt.ItemDataRole.UserRole) for i in range(strip.count())
            if strip.item(i).foreground().color().name() == BLUE}
    assert blue == {image for name, image in found if name == found[0][0]} and hand_image not in blue
    row = [p.name for p in dock.store.gcps.points].index(found[0][0])
    assert dock.model.data(dock.model.index(row, 0), Qt.ItemDataRole.ForegroundRole).name() == BLUE
    assert "found by Find targets" in dock.model.data(dock.model.index(row, 0), Qt.ItemDataRole.ToolTipRole)
    hand_row = [p.name for p in dock.store.gcps.points].index("wall_corner")
    assert dock.model.data(dock.model.index(hand_row, 0), Qt.ItemDataRole.ForegroundRole) is None
    assert "not confirmed yet" in dock.btn_georef.toolTip()
    _screenshot(dock)
    # saved with the dock's control and read back (not in the ODM file, which Georeference reads as always)
    saved = json.load(open(dock.store.layout.control_json))
    assert len(saved["found"]) == len(found)
    assert dock.open_workspace(ws)
    assert dock.store.found_list() == found and _observations(dock.store) == obs


def _screenshot(dock):  # noqa: F811
    """The dock beside its photo view, after Find targets: docs/screenshots/dock-find-targets.png."""
    from qgis.PyQt.QtGui import QPainter, QPixmap

    dock.resize(560, 720)
    dock.photo_dock.resize(760, 720)
    process(200)
    a, b = dock.grab(), dock.photo_dock.grab()
    out = QPixmap(a.width() + b.width(), max(a.height(), b.height()))
    out.fill()
    p = QPainter(out)
    p.drawPixmap(0, 0, a)
    p.drawPixmap(a.width(), 0, b)
    p.end()
    os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
    out.save(SCREENSHOT)
    assert os.path.getsize(SCREENSHOT) > 10_000


def test_undo_takes_the_found_observations_away_in_one_step(dock, ws, scene):  # noqa: F811
    sc, _, csv = scene
    assert dock.open_workspace(ws)
    hand_image, hand_xy = _hand_placed(dock, sc)
    before, steps = _observations(dock.store), dock.store.undo_stack.count()
    _find(dock, csv)
    after = _observations(dock.store)
    assert len(after) > len(before) + 20
    dock.act_undo.trigger()
    assert _observations(dock.store) == before and not dock.store.found_list()
    assert {p.name for p in dock.store.gcps.points} == {"ring_b", "wall_corner"}
    assert dock.store.undo_stack.count() == steps + 1 and dock.store.undo_stack.index() == steps
    dock.act_redo.trigger()
    found = dock.store.found_list()
    assert _observations(dock.store) == after and found
    # Georeference uses them, confirmed or not; the marks stay
    dock.btn_georef.click()
    wait_task(dock, 300)
    assert dock.last_task_error is None, dock.last_task_error
    f = dock.store.figures
    assert f["GCP_N"] == len(sc.targets) and f["GCP_RMSE_XY"] < 0.01 and f["GCP_RMSE_Z"] < 0.02, f
    assert dock.store.found_list() == found


def test_one_key_confirms_or_rejects_each_found_observation(dock, ws, scene):  # noqa: F811
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    sc, _, csv = scene
    assert dock.open_workspace(ws)
    _find(dock, csv)
    view, table = dock.photo_panel.view, dock.table
    n = len(dock.store.found_list())
    first = dock.current_found()
    xy = _observations(dock.store)[first]
    # the keys work at once, where the dock says (issue 48 item 3): the table has the keyboard focus, no row
    # needs a click first (a click in the photo would move the mark)
    focused = dock.focusWidget()
    assert focused is table, focused
    assert "the keys work in the table" in dock.status.text() and "table" in dock.photo_panel.found_note.text()
    QTest.keyClick(focused, Qt.Key.Key_Space)  # confirmed: an ordinary observation, where it was
    assert dock.store.is_found(*first) is None and _observations(dock.store)[first] == xy
    second = dock.current_found()
    assert second is not None and second != first and len(dock.store.found_list()) == n - 1
    QTest.keyClick(view, Qt.Key.Key_R)  # rejected: gone
    assert second not in _observations(dock.store) and dock.store.is_found(*second) is None
    third = dock.current_found()
    assert third is not None and third not in (first, second)
    QTest.keyClick(table, Qt.Key.Key_Return)  # the table's keys too
    assert dock.store.is_found(*third) is None and third in _observations(dock.store)
    fourth = dock.current_found()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert fourth not in _observations(dock.store)
    assert len(dock.store.found_list()) == n - 4
    dock.act_undo.trigger()  # the rejection undone: the observation is back, marked as found
    assert fourth in _observations(dock.store) and dock.store.is_found(*fourth) is not None
    dock.show_found(*fourth)
    assert dock.photo_panel.btn_confirm.isEnabled()  # the mouse's way: the photo view's Confirm button
    dock.photo_panel.btn_confirm.click()
    assert dock.store.is_found(*fourth) is None and fourth in _observations(dock.store)
    assert len(dock.store.found_list()) == n - 4
    # a hand-placed observation shown: the view's own keys (Delete removes it) are left alone
    name, image = first
    dock.select_point(name)
    dock.show_photo(image)
    assert dock.current_found() is None
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert first not in _observations(dock.store)
    # the flag survives a reload; confirmed ones stay ordinary
    left = dock.store.found_list()
    assert dock.open_workspace(ws) and dock.store.found_list() == left and dock.store.is_found(*third) is None
    # found again: what was confirmed stays confirmed; what the user removed comes back, to confirm or reject
    _find(dock, csv)
    assert dock.store.is_found(*third) is None and third in _observations(dock.store)
    assert set(dock.store.found_list()) == set(left) | {first, second} and dock.store.is_found(*fourth) is None


def test_the_dialog_the_errors_and_cancel(dock, ws, scene, tmp_path, monkeypatch):  # noqa: F811
    """The dialog's values reach the task; a file without a CRS in a block without one is refused naming the file,
    in the message area; a cancelled search changes nothing."""
    from archaeoortho.ui import gcp_targets
    from qgis.PyQt.QtWidgets import QDialog

    sc, _, csv = scene
    assert dock.open_workspace(ws)
    dlg = gcp_targets.FindTargetsDialog(dock, ws, "EPSG:32611")
    dlg.file.setFilePath(csv)
    dlg.kind.setCurrentIndex(dlg.kind.findData("checkerboard"))
    dlg.size_spin.setValue(0.5)
    assert dlg.values() == (csv, "checkerboard", 0.5)
    dlg.size_spin.setValue(0.0)
    assert dlg.values()[2] is None  # shown as "unknown"
    asked = []
    monkeypatch.setattr(gcp_targets.FindTargetsDialog, "exec", lambda self: QDialog.DialogCode.Accepted)
    monkeypatch.setattr(gcp_targets.FindTargetsDialog, "values", lambda self: (csv, "checkerboard", 0.5))
    monkeypatch.setattr(dock, "run_find_targets", lambda *a: asked.append(a))
    dock.choose_find_targets()
    assert asked == [(csv, "checkerboard", 0.5)]
    monkeypatch.undo()
    bad = tmp_path / "no_crs.txt"
    bad.write_text("1 2 3 T1\n")
    assert dock.store.crs == ""  # neither the table nor the aligned block has one
    _find_fails = dock.run_find_targets(str(bad))
    assert _find_fails is not None
    wait_task(dock, 120)
    assert str(bad) in dock.status.text() and "CRS" in dock.status.text()
    assert not dock.store.gcps.points and dock.store.undo_stack.count() == 0
    dock.run_find_targets(csv)
    dock.cancel_task()
    wait_task(dock, 120)
    assert dock.status.text() == "Cancelled" and not dock.store.gcps.points


def test_a_click_in_the_targets_file_that_no_mark_answers_is_kept_as_placed_by_hand(dock, ws, scene, tmp_path):  # noqa: F811,E501
    """A gcp_list.txt with a click (pixel columns) on a target the border cuts: the core keeps it, not found; the
    dock takes it as an observation of the user's, with no mark to confirm.  A target surveyed outside the photos
    is said not found in the message area."""
    sc, _, _ = scene
    image, name = next((i, n) for i, n in sc.cut if 0 < sc.truth[i][n][0] < targets_scene.W
                       and 0 < sc.truth[i][n][1] < targets_scene.H)
    tx, ty = sc.truth[image][name]
    path = tmp_path / "gcp_list.txt"
    with open(path, "w", encoding="utf-8") as out:
        out.write("EPSG:32611\n")
        for t in sc.targets:
            w = [t.x + targets_scene.OFFSET[0], t.y + targets_scene.OFFSET[1], t.z + targets_scene.OFFSET[2]]
            out.write(f"{w[0]:.4f} {w[1]:.4f} {w[2]:.4f} {t.name}\n")
            if t.name == name:
                out.write(f"{w[0]:.4f} {w[1]:.4f} {w[2]:.4f} {tx:.2f} {ty:.2f} {image} {t.name}\n")
        out.write(f"{w[0] + 60.0:.4f} {w[1] + 45.0:.4f} {w[2]:.4f} far_away\n")  # surveyed outside the photos
    assert dock.open_workspace(ws)
    r = _find(dock, str(path))
    assert dock.status.text().splitlines()[1] == "not found: far_away"  # what did not fit, first
    assert [(o.name, o.image) for o in r.observations if not o.found] == [(name, image)]
    assert _observations(dock.store)[(name, image)] == (round(tx, 2), round(ty, 2))
    assert dock.store.is_found(name, image) is None and (name, image) not in dock.store.found_list()
    assert len(dock.store.found_list()) == r.n_observations - 1


def test_the_targets_come_into_the_tables_crs(dock, ws, scene):  # noqa: F811
    """A table in another CRS (UTM 11 south; the file: 11 north): the targets' coordinates are transformed into
    it, as an import does; the observations are the same."""
    sc, _, csv = scene
    assert dock.open_workspace(ws)
    dock.store.set_crs("EPSG:32711")
    dock.store.add_point("wall_corner", 500001.0, 14000001.0, 100.0)
    r = _find(dock, csv)
    assert dock.store.crs == "EPSG:32711" and r.n_targets == len(sc.targets)
    for t in sc.targets:
        p = dock.store.gcps.by_name(t.name)
        assert abs(p.x - (t.x + targets_scene.OFFSET[0])) < 1e-3
        assert abs(p.y - (t.y + targets_scene.OFFSET[1] + 10_000_000.0)) < 1e-3
        assert len(p.observations) == sum(1 for o in r.observations if o.name == t.name)
