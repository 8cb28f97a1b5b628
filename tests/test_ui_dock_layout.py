"""The GCP dock as a new user meets it (issue 18): the toolbar icon where QGIS shows it, the plugin in the
language of `qgis --lang de`, every translated string reaching the .ts files as the code asks for it, the
layout at the dock's default size (nothing essential in an overflow, the key columns visible, a usable photo
viewer), the alignment result kept on screen with the photos that did not align marked, and the GUI thread
never blocked by the slow steps (timings printed, not asserted).  Screenshots in English and German go to
docs/screenshots/."""
import ast
import os
import time
import xml.etree.ElementTree as ET

import pytest

from tests import synthetic as syn
from tests.conftest import ROOT
from tests.test_ui_dock import make_workspace, process, quick_photos, wait_task

pytestmark = pytest.mark.usefixtures("qgis_processing")

I18N = os.path.join(ROOT, "i18n")


@pytest.fixture
def qgis_language():
    """Set what QGIS itself sets at start: the translation (``qgis --lang xx``) and the locale settings;
    restore both after."""
    from qgis.core import QgsApplication, QgsSettings

    s = QgsSettings()
    keys = ("locale/overrideFlag", "locale/userLocale")
    saved = {k: s.value(k) for k in keys}
    saved_translation = QgsApplication.instance().translation()

    def set_language(translation, user_locale=None, override=False):
        QgsApplication.setTranslation(translation)
        s.setValue("locale/overrideFlag", override)
        s.setValue("locale/userLocale", user_locale if user_locale is not None else translation)

    yield set_language
    QgsApplication.setTranslation(saved_translation)
    for k, v in saved.items():
        if v is None:
            s.remove(k)
        else:
            s.setValue(k, v)


# --------------------------------------------------------------------------------------------------
# item 12: the toolbar icon
# --------------------------------------------------------------------------------------------------


def test_toolbar_icon_goes_to_the_plugins_toolbar(qgis_iface, qgis_language):
    """QGIS hides the Raster toolbar by default: the icon goes on the Plugins toolbar (addToolBarIcon)."""
    import archaeoortho

    qgis_language("en")
    added, removed = [], []
    qgis_iface.addToolBarIcon = added.append
    qgis_iface.removeToolBarIcon = removed.append
    p = archaeoortho.classFactory(qgis_iface)
    try:
        p.initGui()
        action = p.action
        assert added == [action]
        image = action.icon().pixmap(24, 24).toImage()
        assert not image.isNull() and len({image.pixel(x, y) for x in range(24) for y in range(24)}) > 2
        assert action.toolTip()
        p.unload()
        assert removed == [action]
    finally:
        p.unload()
        del qgis_iface.addToolBarIcon
        del qgis_iface.removeToolBarIcon


# --------------------------------------------------------------------------------------------------
# item 8: translations
# --------------------------------------------------------------------------------------------------


def _translated_literals():
    """{(context, text)} of every tr() / translate() call with literal arguments in the plugin's sources, as
    Python reads them (escapes decoded)."""
    import subprocess

    out = set()
    files = [os.path.join(ROOT, f) for f in os.listdir(ROOT) if f.endswith(".py")]
    for folder in ("ui", "processing_provider", "qgisio"):
        files += [os.path.join(ROOT, folder, f) for f in os.listdir(os.path.join(ROOT, folder)) if f.endswith(".py")]
    listed = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode == 0 and listed.stdout:  # a checkout: the files in the repository (not a new one in work)
        tracked = {os.path.join(ROOT, p) for p in listed.stdout.split()}
        files = [f for f in files if f in tracked]
    for path in files:
        tree = ast.parse(open(path, encoding="utf-8").read())
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            args = node.args
            if name in ("translate", "QT_TRANSLATE_NOOP") and len(args) >= 2:
                ctx, text = args[0], args[1]
            elif name == "tr" and len(args) == 1:
                ctx, text = None, args[0]
            else:
                continue
            if isinstance(text, ast.Constant) and isinstance(text.value, str) and text.value:
                c = ctx.value if isinstance(ctx, ast.Constant) else None
                out.add((c, text.value, os.path.relpath(path, ROOT)))
    return out


@pytest.mark.parametrize("lang", ["de", "it"])
def test_every_translated_string_is_in_the_ts_file_as_the_code_asks_for_it(lang):
    """pylupdate5 stored "Open\\u2026" as "Openu2026": the code asks for "Open…", which the .ts never had.
    Every literal passed to tr() is a source text of the .ts file (escapes decoded), translated."""
    tree = ET.parse(os.path.join(I18N, f"archaeoortho_{lang}.ts"))
    sources = {}
    for ctx in tree.getroot().iter("context"):
        for msg in ctx.iter("message"):
            sources.setdefault(msg.find("source").text, []).append(msg.find("translation"))
    missing = sorted((f, t) for _c, t, f in _translated_literals() if t not in sources)
    assert missing == []
    assert not [s for s in sources if "u2026" in s or "u03c3" in s or "u00d7" in s]
    for text in ("Open…", "New from photos…", "From file (gcp_list.txt, CSV)…", "From a point layer…",
                 "To file (gcp_list.txt, CSV)…", "To a GeoPackage layer…", "σ XY"):
        assert all(tr.text and tr.get("type") != "unfinished" for tr in sources[text]), text


def test_the_extraction_decodes_escapes():
    """i18n/update_ts.py (make transup) hands pylupdate5 copies with the escapes decoded; raw strings, bytes and
    escaped backslashes stay as they are, and line numbers do not move."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("update_ts", os.path.join(I18N, "update_ts.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    src = ('a = tr("Open\\u2026")\nb = r"\\u2026"\nc = "x\\\\u2026"\nd = tr("\\N{GREEK SMALL LETTER SIGMA} XY")\n'
           'e = "\\x22"\n')
    out = mod.decode_escapes(src)
    assert out.splitlines()[0] == 'a = tr("Open…")'
    assert out.splitlines()[1] == 'b = r"\\u2026"'
    assert out.splitlines()[2] == 'c = "x\\\\u2026"'
    assert out.splitlines()[3] == 'd = tr("σ XY")'
    assert out.splitlines()[4] == 'e = "\\x22"'  # a quote stays escaped
    assert ast.literal_eval(out.splitlines()[0][7:-1]) == "Open…"
    for path in ("ui/gcp_dock.py", "plugin.py"):
        text = open(os.path.join(ROOT, path), encoding="utf-8").read()
        decoded = mod.decode_escapes(text)
        assert decoded.count("\n") == text.count("\n")
        ast.parse(decoded)


def _german_dock_texts(dock):
    return {
        "open": dock.btn_open.text(), "new": dock.btn_new.text(),
        "import": [a.text() for a in dock.import_menu.actions()],
        "export": [a.text() for a in dock.export_menu.actions()],
    }


def test_qgis_lang_de_speaks_german(qgis_iface, qgis_canvas, qgis_language):
    """`qgis --lang de` sets QGIS's translation and writes locale/userLocale, but not the override flag:
    QgsApplication.locale() still says the system's language.  The plugin follows QGIS's translation, read
    when QGIS sets the plugin up (initGui), so the dock and its menus are German."""
    import archaeoortho

    qgis_language("en_US")
    p = archaeoortho.classFactory(qgis_iface)  # QGIS loads the plugin ...
    qgis_language("de")  # ... the language QGIS applies is the one initGui sees
    try:
        p.initGui()
        assert p.translator is not None
        from archaeoortho.ui.gcp_dock import GcpDock

        dock = GcpDock(None, qgis_canvas)
        try:
            texts = _german_dock_texts(dock)
            assert texts["open"] == "Öffnen…"
            assert texts["new"] == "Neu aus Fotos…"
            assert texts["import"] == ["Aus Datei (gcp_list.txt, CSV)…", "Aus einem Punktlayer…",
                                     "Zielmarken auf den Fotos finden…"]
            assert texts["export"] == ["In Datei (gcp_list.txt, CSV)…", "In einen GeoPackage-Layer…"]
            assert dock.btn_georef.text() == "Georeferenzieren"
        finally:
            dock.close()
    finally:
        p.unload()


def test_override_in_the_options_wins(qgis_iface, qgis_language):
    """Options > General > Override system locale (overrideFlag + userLocale) is what QGIS runs in."""
    import archaeoortho
    from archaeoortho import plugin as plugin_module

    qgis_language("en_US", user_locale="it", override=True)
    assert plugin_module._locale() == "it"
    qgis_language("de_AT", user_locale="de_AT", override=False)
    assert plugin_module._locale() == "de"
    p = archaeoortho.classFactory(qgis_iface)
    p.unload()


# --------------------------------------------------------------------------------------------------
# the dock at its default size
# --------------------------------------------------------------------------------------------------

SHOTS = os.path.join(ROOT, "docs", "screenshots")


@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1)


@pytest.fixture(scope="module")
def photos(block, tmp_path_factory):
    return quick_photos(block, str(tmp_path_factory.mktemp("layout photos")))


@pytest.fixture(scope="module")
def georef_ws(block, photos, tmp_path_factory):
    return make_workspace(str(tmp_path_factory.mktemp("layout georef")), block, photos,
                          block.gcp_set(block.spread_control(5)))


@pytest.fixture
def default_dock(qgis_canvas, qgis_new_project):
    """The dock and the photo dock as QGIS first shows them (plugin.show_dock: ui/dock_layout.place_docks): the
    dock at its size hint in a main window's right area, the photo dock on the left."""
    from archaeoortho.ui.gcp_dock import GcpDock
    from qgis.PyQt.QtWidgets import QMainWindow

    win = QMainWindow()
    win.setCentralWidget(qgis_canvas)
    _qgis_like(win)
    win.resize(1366, 768)
    d = GcpDock(None, qgis_canvas, parent=win)
    win.show()
    process(100)
    _place(win, d)
    process(100)
    yield d
    d.cleanup()
    qgis_canvas.setParent(None)
    win.close()


def _qgis_like(win):
    """QGIS's main window gives the side dock areas the bottom corners (QgisApp: setCorner)."""
    from qgis.PyQt.QtCore import Qt

    win.setCorner(Qt.Corner.BottomLeftCorner, Qt.DockWidgetArea.LeftDockWidgetArea)
    win.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)


def _place(win, d):
    """What ArchaeoOrthoPlugin.show_dock does the first time: the docks placed and sized (ui/dock_layout)."""
    from archaeoortho.ui.dock_layout import place_docks

    place_docks(win, d, d.photo_dock)


def overflowing_actions(dock):
    """Texts of the toolbar actions that are not shown (in a >> overflow or cut off) at the dock's size."""
    from qgis.PyQt.QtWidgets import QToolBar, QToolButton

    out = []
    for bar in dock.findChildren(QToolBar):
        ext = bar.findChild(QToolButton, "qt_toolbar_ext_button")
        if ext is not None and ext.isVisible():
            out.append(f"{bar.objectName() or 'toolbar'}: >> overflow")
        for a in bar.actions():
            w = bar.widgetForAction(a)
            if w is None or a.isSeparator():
                continue
            if not w.isVisible() or w.geometry().right() > bar.width():
                out.append(a.text() or (w.text() if hasattr(w, "text") else "?"))
    return out


def hidden_key_columns(dock):
    from archaeoortho.ui.gcp_dock import KEY_COLUMNS

    header = dock.table.horizontalHeader()
    width = dock.table.viewport().width()
    out = []
    for col in KEY_COLUMNS:
        left = header.sectionViewportPosition(col)
        if header.isSectionHidden(col) or left < 0 or left + header.sectionSize(col) > width:
            out.append(dock.model.headerData(col, 1))
    return out


def test_layout_at_the_default_size(default_dock, georef_ws):
    """Nothing in the toolbar's >> overflow (Load results and Redo were), the table's Name, Obs., dXY, dZ and px
    columns visible without scrolling, and a photo viewer that is more than a strip."""
    dock = default_dock
    assert dock.open_workspace(georef_ws)
    process(100)
    print(f"\n[layout] dock {dock.width()} x {dock.height()}, photo dock {dock.photo_dock.width()} x "
          f"{dock.photo_dock.height()}, photo view {dock.photo_panel.view.height()} px high")
    assert dock.width() <= 480  # the default width, not a test's generous one
    assert overflowing_actions(dock) == []
    assert dock.act_results.isEnabled() and dock.act_redo in dock.toolbar.actions()
    assert hidden_key_columns(dock) == []
    assert dock.table.horizontalScrollBar().value() == 0
    assert dock.photo_panel.view.height() >= 200 and dock.photo_panel.view.width() >= 300


def test_layout_in_german_at_the_default_size(qgis_canvas, qgis_new_project, georef_ws):
    """German labels are longer (Rückgängig, Exportieren, Ergebnisse laden): still nothing in an overflow."""
    from archaeoortho.ui.gcp_dock import GcpDock
    from qgis.PyQt.QtCore import QCoreApplication, QTranslator
    from qgis.PyQt.QtWidgets import QMainWindow

    t = QTranslator()
    assert t.load(os.path.join(I18N, "archaeoortho_de.qm"))
    QCoreApplication.installTranslator(t)
    win = QMainWindow()
    try:
        win.setCentralWidget(qgis_canvas)
        _qgis_like(win)
        win.resize(1366, 768)
        d = GcpDock(None, qgis_canvas, parent=win)
        win.show()
        process(100)
        _place(win, d)
        process(100)
        assert d.btn_georef.text() == "Georeferenzieren"
        assert d.open_workspace(georef_ws)
        process(100)
        assert overflowing_actions(d) == []
        assert hidden_key_columns(d) == []
        assert d.width() <= 520
        os.makedirs(SHOTS, exist_ok=True)
        _screenshot(win, d, os.path.join(SHOTS, "gcp-dock-de.png"))
        d.cleanup()
    finally:
        QCoreApplication.removeTranslator(t)
        qgis_canvas.setParent(None)
        win.close()


def _screenshot(win, dock, path):
    """The main window's docks as they are (GCP dock right, photo dock below), one picture."""
    from qgis.PyQt.QtCore import QPoint
    from qgis.PyQt.QtGui import QPainter, QPixmap

    process(200)
    a, b = dock.grab(), dock.photo_dock.grab()
    out = QPixmap(max(a.width(), 1) + b.width() + 8, max(a.height(), b.height()))
    out.fill()
    painter = QPainter(out)
    painter.drawPixmap(QPoint(0, 0), b)
    painter.drawPixmap(QPoint(b.width() + 8, 0), a)
    painter.end()
    assert out.save(path)
    assert os.path.getsize(path) > 10000


def test_screenshot_english_default_size(default_dock, georef_ws, block):
    dock = default_dock
    assert dock.open_workspace(georef_ws)
    dock.select_point(block.spread_control(5)[2])
    process(200)
    os.makedirs(SHOTS, exist_ok=True)
    _screenshot(dock.parent(), dock, os.path.join(SHOTS, "gcp-dock-en.png"))


# --------------------------------------------------------------------------------------------------
# item 3: the alignment result
# --------------------------------------------------------------------------------------------------


@pytest.fixture
def partly_aligned_ws(block, photos, tmp_path):
    """An aligned workspace with two more photos, first in its image list, that did not align (in the image list,
    not in the model, named with the reason in sfm/alignment.json)."""
    import shutil

    from tests.workspaces import synthetic_workspace

    rec = block.truth_reconstruction(n_points=800, noise_px=0.3)
    first = next(iter(photos.values()))
    lost = {"AAA_blurred.jpg": "no verified matches with any other image (no overlap, blur or too little texture)",
            "AAB_sky.jpg": "matched 2 image(s) but could not be registered (too few matches in a good geometry)"}
    folder = tmp_path / "photos"
    folder.mkdir()
    all_photos = {}
    for name in list(lost) + list(photos):
        all_photos[name] = str(folder / name)
        shutil.copyfile(photos.get(name, first), all_photos[name])
    figures = {"registered": len(photos), "images_given": len(all_photos), "mean_reprojection_error": 0.61,
               "unregistered": lost}
    ws = synthetic_workspace(str(tmp_path / "partly"), block, rec, photos=all_photos, cameras_gpkg=True,
                             alignment=figures)
    return ws, lost


def test_alignment_result_stays_and_unaligned_photos_are_marked(default_dock, partly_aligned_ws, block,
                                                               monkeypatch):
    """'New from photos…' ends with the result on screen (it was overwritten 0.1 s later), kept while the user
    works; the photos that did not align are at the end of the strip, marked, with the reason."""
    from archaeoortho.core.align import stage as align_stage
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    ws, lost = partly_aligned_ws
    dock = default_dock

    class Result:  # what core.align.stage.align returns, for this workspace
        registered, images_given, mean_reprojection_error = len(block.shots), len(block.shots) + 2, 0.61
        unregistered = lost

    def fake_align(images_dir, workspace_dir, progress=None, options=None):
        progress.report(0.5, "matching")
        return Result()

    monkeypatch.setattr(align_stage, "align", fake_align)
    assert dock.start_alignment("photos", ws) is not None
    wait_task(dock)
    process(500)
    n = len(block.shots) + 2
    status = dock.status.text()
    assert f"Aligned {n - 2} of {n} photos" in status, status
    assert all(name in status for name in lost)
    assert dock.align_label.isVisible()
    assert f"Aligned {n - 2} of {n} photos" in dock.align_label.text()
    # the user works on: adding a point writes the status line, the result stays
    QTest.mouseClick(dock.toolbar.widgetForAction(dock.act_add), Qt.MouseButton.LeftButton)
    process(100)
    assert f"Aligned {n - 2} of {n} photos" in dock.align_label.text()
    assert all(name in dock.align_label.text() for name in lost)
    # the strip, all photos: the unaligned ones last, marked, the reason in the tooltip
    if dock.photo_panel.filter_box.isChecked():
        QTest.mouseClick(dock.photo_panel.filter_box, Qt.MouseButton.LeftButton)
        process(50)
    assert not dock.photo_panel.filter_box.isChecked()
    strip = dock.photo_panel.thumbnail_names()
    assert set(strip[-2:]) == set(lost)
    thumbs = dock.photo_panel.thumbs
    for i in range(thumbs.count()):
        item = thumbs.item(i)
        name = item.data(Qt.ItemDataRole.UserRole)
        if name in lost:
            assert "not aligned" in item.text() and lost[name] in item.toolTip()
        else:
            assert "not aligned" not in item.text()


# --------------------------------------------------------------------------------------------------
# item 5: nothing slow on the GUI thread
# --------------------------------------------------------------------------------------------------


def _ms(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, 1000.0 * (time.perf_counter() - t0)


def test_refining_a_prediction_runs_in_the_background(default_dock, georef_ws, block):
    """Matching a prediction (1.6-4.6 s a photo on COPR) ran on the GUI thread when a photo was shown.  With the
    plugin's setting the photo shows the geometric prediction at once, a task matches, the photo then shows the
    matched position; Confirm waits for it (events flowing).  Timings printed, not asserted."""
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    dock = default_dock
    dock.refine_in_background = True
    assert dock.open_workspace(georef_ws)
    name = block.spread_control(5)[4]
    dock.select_point(name)
    point = dock.current_point()
    keep = point.images()[0]
    for other in point.images()[1:]:  # one observation left: the others are predicted from the coordinates
        dock.store.remove_observation(name, other)
    process(50)
    img = next(n for n in sorted(dock.predictions, key=lambda n: dock.predictions[n].centrality)
               if n != keep and n in block.gcp(name).observations and dock.predictions[n].source != "rays")
    truth = block.gcp(name).observations[img]
    dock.matches.clear()
    dock.__dict__.get("_refine_jobs", {}).clear()
    _, shown_ms = _ms(lambda: dock.show_photo(img))
    assert dock.refinement_pending(img), "no matching task was started"
    geometric = dock.photo_panel.prediction.pos()
    t0 = time.perf_counter()
    dock.wait_for_refinement(img)
    match_ms = 1000.0 * (time.perf_counter() - t0)
    assert not dock.refinement_pending(img)
    pred, match = dock.refined_prediction(img)
    print(f"\n[refine] show the photo {shown_ms:.0f} ms on the GUI thread; matching in its task {match_ms:.0f} ms; "
          f"geometric ({geometric.x():.2f}, {geometric.y():.2f}) -> {pred.source} ({pred.x:.2f}, {pred.y:.2f}), "
          f"truth ({truth[0]:.2f}, {truth[1]:.2f})")
    if match is not None:
        assert pred.source == "matched"
        assert abs(dock.photo_panel.prediction.pos().x() - geometric.x()) + \
            abs(dock.photo_panel.prediction.pos().y() - geometric.y()) >= 0.0
    # Space confirms the (refined) prediction
    view = dock.photo_panel.view
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Space)
    obs = next(o for o in dock.current_point().observations if o.image == img)
    assert (obs.x, obs.y) == pytest.approx((pred.x, pred.y))


def test_gui_thread_times_of_open_results_and_georeference(default_dock, georef_ws, block, qgis_new_project):
    """The GUI-thread time of opening a workspace, Load results and the end of a georeference (its done
    callback), printed (pytest -s); the slow parts run in tasks: Load results writes the footprints in one
    (the button returns at once), the georeference task writes them before its done callback."""
    from archaeoortho.ui import gcp_tasks
    from qgis.core import QgsProject
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    dock = default_dock
    dock.refine_in_background = True
    _, open_ms = _ms(lambda: dock.open_workspace(georef_ws))
    process(50)
    _, reopen_ms = _ms(lambda: dock.open_workspace(georef_ws))  # imports done: what the user waits for
    dock.wait_for_refinement()
    # Load results: the click returns before the footprints are written; the layers come when the task ends
    written = []
    real_prepare = gcp_tasks.prepare_results

    def prepare(root, progress=None):
        written.append(root)
        return real_prepare(root, progress=progress)

    gcp_tasks.prepare_results = prepare
    try:
        button = dock.toolbar2.widgetForAction(dock.act_results)
        _, click_ms = _ms(lambda: QTest.mouseClick(button, Qt.MouseButton.LeftButton))
        assert dock._results_task is not None and not QgsProject.instance().mapLayers()
        t0 = time.perf_counter()
        while dock._results_task is not None and time.perf_counter() - t0 < 60:
            process(20)
        results_total = 1000.0 * (time.perf_counter() - t0)
    finally:
        gcp_tasks.prepare_results = real_prepare
    kinds = {lyr.customProperty("archaeoortho/kind") for lyr in QgsProject.instance().mapLayers().values()}
    assert {"cameras", "footprints", "residuals"} <= kinds and written == [georef_ws]
    _, sync_results_ms = _ms(lambda: dock.load_results())  # the old way, all on the GUI thread
    # the end of a georeference: the done callback's time
    timings = {}
    task = dock.run_georeference()
    real_done = task.on_done

    def timed_done(outcome):
        _, timings["done"] = _ms(lambda: real_done(outcome))

    task.on_done = timed_done
    wait_task(dock)
    assert dock.last_task_error is None and "done" in timings
    assert isinstance(task.result, tuple) and task.result[1]  # the footprints came from the task
    assert task.result[2] is not None and dock.__dict__.get("_prebuilt_model") is None  # so did the model
    print(f"\n[GUI thread] open workspace {open_ms:.0f} ms (first, with imports), again {reopen_ms:.0f} ms; "
          f"Load results click {click_ms:.0f} ms (layers after {results_total:.0f} ms), all on the GUI thread "
          f"{sync_results_ms:.0f} ms; georeference done callback {timings['done']:.0f} ms")


@pytest.mark.slow
def _qgis_desktop(georef_ws, tmp_path, lang, **env_extra):
    """QGIS desktop under Xvfb on a 1366 x 768 screen running tests/desktop_lang_script.py: its log and the path
    of its screenshot."""
    import json
    import shutil
    import subprocess
    import sysconfig

    from tests.conftest import PLUGINS

    if not (shutil.which("qgis") and shutil.which("xvfb-run")):
        pytest.skip("needs qgis and xvfb-run")
    if not os.path.islink(os.path.join(PLUGINS, "archaeoortho")):
        pytest.skip("plugin link missing: run 'make setup'")
    out = tmp_path / "out"
    out.mkdir()
    profile = tmp_path / "profile"
    shutil.copytree(os.path.join(ROOT, "build", "qgis-profile"), profile, symlinks=True)
    env = dict(os.environ)
    env.pop("QT_QPA_PLATFORM", None)
    env.update(AO_OUT=str(out), AO_WORKSPACE=georef_ws, QGIS_PLUGINPATH=PLUGINS, QGIS_CUSTOM_CONFIG_PATH=str(profile),
               PYTHONPATH=os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")]), **env_extra)
    script = os.path.join(ROOT, "tests", "desktop_lang_script.py")
    subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1366x768x24", "qgis", "--lang", lang, "--nologo",
                    "--noversioncheck", "--code", script], env=env, capture_output=True, timeout=300)
    keep = os.environ.get("AO_KEEP")  # a folder to keep the log and screenshots in (issue 48's walkthrough)
    if keep:
        shutil.copytree(out, os.path.join(keep, lang + ("-docks" if env_extra else "")), dirs_exist_ok=True)
    log = json.load(open(out / "log.json"))
    assert "error" not in log, log.get("error")
    return log, out / "screen.png"


def test_qgis_desktop_lang_de(georef_ws, tmp_path):
    """`qgis --lang de` under Xvfb, a copy of the test profile (QGIS writes the language into it): the plugin
    speaks German, its icon is on the (visible) Plugins toolbar, and a click on it opens the docks at their
    default sizes with nothing hidden.  The screenshot goes to docs/screenshots/qgis-desktop-de.png."""
    import json
    import shutil

    log, screen = _qgis_desktop(georef_ws, tmp_path, "de")
    print(f"\n[qgis --lang de] {json.dumps(log, ensure_ascii=False)}")
    assert "archaeoortho" in log["plugins"] and log["translator"]
    assert log["icon_on_plugins_toolbar"] and log["plugins_toolbar_visible"] and log["icon_shown"]
    assert log["texts"]["open"] == "Öffnen…" and log["texts"]["new"] == "Neu aus Fotos…"
    assert log["texts"]["import"] == ["Aus Datei (gcp_list.txt, CSV)…", "Aus einem Punktlayer…",
                                     "Zielmarken auf den Fotos finden…"]
    assert log["texts"]["georef"] == "Georeferenzieren"
    assert log["toolbar_hidden"] == [] and log["key_columns_hidden"] == []
    assert log["photo_view_height"] >= 200
    assert log["window"][0] <= 1366 and log["window"][1] <= 768  # the docks' minimum sizes fit the screen
    assert log["canvas"][1] >= 0.75 * log["window"][1]  # the map was 145 px tall (issue 48 item 7)
    os.makedirs(SHOTS, exist_ok=True)
    shutil.copyfile(screen, os.path.join(SHOTS, "qgis-desktop-de.png"))


def test_qgis_desktop_with_the_toolbox_and_results_viewer(georef_ws, tmp_path):
    """QGIS itself on a 768 px screen with the Processing Toolbox and Results Viewer shown (docked on the right,
    as QGIS puts them) before the GCP dock: the main window stays within the screen and the Georeference / Cancel
    row is on it (the dock made the window 1057 px tall on a 1000 px screen: issue 36 item 20)."""
    import json
    import shutil

    log, screen = _qgis_desktop(georef_ws, tmp_path, "en", AO_PROCESSING_DOCKS="1")
    print(f"\n[qgis, Toolbox + Results Viewer] {json.dumps({k: log.get(k) for k in ('screen', 'window', 'dock', 'dock_minimum_height', 'georef_row_bottom', 'georef_row_visible')})}")
    shot = os.path.join(ROOT, "build", "screenshots", "ui", "qgis-desktop-768-processing-docks.png")
    os.makedirs(os.path.dirname(shot), exist_ok=True)
    shutil.copyfile(screen, shot)
    assert log["window"][1] <= log["screen"][1] == 768
    assert log["georef_row_visible"] and log["georef_row_bottom"] < log["screen"][1]
    assert log["texts"]["georef"] == "Georeference"
    assert log["canvas"][1] >= 0.75 * log["window"][1]  # the map keeps the window's height (issue 48 item 7)
    assert log["toolbox_list_height"] >= 0.4 * log["window"][1]  # the Toolbox a tab: its list the column's height
    assert log["dock"][1] >= 0.6 * log["window"][1] and log["photo_view"][1] >= 200


def test_open_button_reads_the_block_model_in_a_task(default_dock, georef_ws, monkeypatch):
    """Open…: the folder is chosen, the block model (the slow part of opening) is read in a task, then the
    workspace opens with it; the click itself returns at once.  Timings printed."""
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest
    from qgis.PyQt.QtWidgets import QFileDialog

    dock = default_dock
    dock.refine_in_background = True
    monkeypatch.setattr(QFileDialog, "getExistingDirectory", staticmethod(lambda *a, **k: georef_ws))
    read = []
    from archaeoortho.ui import gcp_tasks

    real = gcp_tasks.read_block_model

    def reading(root, progress=None):
        read.append(root)
        return real(root, progress=progress)

    monkeypatch.setattr(gcp_tasks, "read_block_model", reading)
    _, click_ms = _ms(lambda: QTest.mouseClick(dock.btn_open, Qt.MouseButton.LeftButton))
    assert dock._open_task is not None and dock.store.root is None  # not opened on the GUI thread
    t0 = time.perf_counter()
    while dock._open_task is not None and time.perf_counter() - t0 < 60:
        process(20)
    total_ms = 1000.0 * (time.perf_counter() - t0)
    assert read == [georef_ws] and dock.store.root == georef_ws
    assert dock.predictor is not None and dock.predictor.georeferenced
    assert dock.__dict__.get("_prebuilt_model") is None  # used by load_predictor, not read again
    assert dock.current_name() is not None and dock.predictions
    print(f"\n[open button] click {click_ms:.0f} ms on the GUI thread; workspace open after {total_ms:.0f} ms")


# --------------------------------------------------------------------------------------------------
# issue 36 items 18-20: the dock on a small screen, long messages, the whole diagnosis
# --------------------------------------------------------------------------------------------------

SCREEN_HEIGHT = 768
WINDOW_FRAME = 30  # the window manager's title bar: the main window gets the rest of the screen


def _qgis_main_window(canvas):
    """A main window dressed as QGIS's: a menu bar, two toolbar rows and a status bar, the map canvas in the
    middle, and the Processing Toolbox and Results Viewer (QGIS's own docks) on the right."""
    from processing.gui.ProcessingToolbox import ProcessingToolbox
    from processing.gui.ResultsDock import ResultsDock
    from qgis.core import QgsApplication
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtWidgets import QLabel, QMainWindow

    win = QMainWindow()
    win.setCentralWidget(canvas)
    _qgis_like(win)
    for title in ("Project", "Edit", "View", "Layer", "Settings", "Plugins", "Vector", "Raster", "Processing",
                  "Help"):
        win.menuBar().addMenu(title)
    for row, icons in enumerate((("mActionFileNew.svg", "mActionFileOpen.svg", "mActionFileSave.svg"),
                                 ("mActionPan.svg", "mActionZoomIn.svg", "mActionZoomOut.svg"))):
        if row:
            win.addToolBarBreak()
        bar = win.addToolBar(f"toolbar {row}")
        for icon in icons:
            bar.addAction(QgsApplication.getThemeIcon(icon), icon)
    win.statusBar().addWidget(QLabel("Coordinate 500000, 4600000"))
    toolbox, results = ProcessingToolbox(), ResultsDock()
    for dock in (toolbox, results):
        win.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
    return win, (toolbox, results)


def _inside(widget, win):
    """Whether ``widget`` is shown whole inside the main window."""
    top_left = widget.mapTo(win, widget.rect().topLeft())
    bottom_right = widget.mapTo(win, widget.rect().bottomRight())
    return widget.isVisible() and top_left.y() >= 0 and bottom_right.y() < win.height() and bottom_right.x() < win.width()


def test_dock_fits_a_768_px_screen_beside_the_toolbox_and_results_viewer(qgis_canvas, qgis_new_project, georef_ws):
    """On a 1000 px screen with the Toolbox and Results Viewer docked on the right, the GCP dock made the main
    window 1057 px tall and its Georeference / Cancel row went off-screen (issue 36 item 20).  Its body scrolls
    now: with QGIS's menu, toolbars, status bar and both docks the window fits a 768 px screen, and the
    Georeference row and the status line stay in view."""
    from archaeoortho.ui.gcp_dock import GcpDock

    win, others = _qgis_main_window(qgis_canvas)
    available = SCREEN_HEIGHT - WINDOW_FRAME
    d = GcpDock(None, qgis_canvas, parent=win)
    try:
        win.resize(1366, available)
        win.show()
        process(100)
        _place(win, d)
        assert d.open_workspace(georef_ws)
        d.message("5 photos, 5 ground points. Predicted positions from the georeferenced block.")
        process(200)
        others_min = sum(o.minimumSizeHint().height() for o in others)
        print(f"\n[768 px] GCP dock minimum {d.minimumSizeHint().height()} px (Toolbox + Results Viewer "
              f"{others_min} px), main window minimum {win.minimumSizeHint().height()} px, window {win.height()} px, "
              f"dock {d.height()} px")
        assert win.minimumSizeHint().height() <= available
        assert win.height() <= available
        for w in (d.btn_georef, d.btn_cancel, d.progress, d.status):
            assert _inside(w, win), w
        assert d.table.height() >= 3 * d.table.verticalHeader().defaultSectionSize()
        # the body scrolls to what does not fit: the automatic control box
        assert d.body_scroll.verticalScrollBar().maximum() > 0 and d.auto_box.visibleRegion().isEmpty()
        d.body_scroll.ensureWidgetVisible(d.auto_box)
        process(50)
        assert not d.auto_box.visibleRegion().isEmpty()
        folded = d.auto_box.height()  # unticked: its title only; ticked: the reference boxes under it
        d.auto_box.setChecked(True)
        process(50)
        assert d.auto_ortho_combo.isVisible() and d.auto_dsm_combo.isVisible()
        assert d.auto_box.height() >= folded + 2 * d.auto_ortho_combo.height()
        d.auto_box.setChecked(False)
        process(50)
        assert not d.auto_ortho_combo.isVisible() and d.auto_box.height() == folded
        shot = os.path.join(ROOT, "build", "screenshots", "ui", "gcp-dock-768.png")
        os.makedirs(os.path.dirname(shot), exist_ok=True)
        assert win.grab().save(shot)
    finally:
        d.cleanup()
        qgis_canvas.setParent(None)
        win.close()


def test_the_map_keeps_most_of_a_768_px_window(qgis_canvas, qgis_new_project, georef_ws):
    """On a 1366 x 768 screen the photo dock at the bottom left the map 145 px tall, and the GCP dock stacked
    under the Processing Toolbox left its algorithm list a few rows (issue 48 item 7).  Each dock has a side
    column's height now (the GCP dock a tab beside the Toolbox and the Results Viewer on the right, the photos on
    the left): the map keeps the height between the toolbars and the status bar, the Toolbox's list gets the
    column when its tab is up, the photo view is a photo, and closing the photo dock gives the map its room."""
    from archaeoortho.ui.gcp_dock import GcpDock

    win, (toolbox, results) = _qgis_main_window(qgis_canvas)
    d = GcpDock(None, qgis_canvas, parent=win)
    try:
        win.resize(1366, SCREEN_HEIGHT - WINDOW_FRAME)
        win.show()
        process(100)
        _place(win, d)
        assert d.open_workspace(georef_ws)
        process(200)
        canvas, view = qgis_canvas, d.photo_panel.view
        print(f"\n[1366 x 768] window {win.width()} x {win.height()}: map {canvas.width()} x {canvas.height()}, "
              f"GCP dock {d.width()} x {d.height()}, photo view {view.width()} x {view.height()}")
        assert canvas.height() >= 0.75 * win.height()  # was 145 px of 738
        assert canvas.width() >= win.width() / 3
        assert view.height() >= 200 and view.width() >= 300
        assert d.height() >= 0.6 * win.height()  # the table is not squeezed under the Toolbox either
        assert _inside(d.btn_georef, win) and _inside(view, win)
        assert not d.visibleRegion().isEmpty()  # the GCP dock's tab is up
        toolbox.raise_()
        process(100)
        tree = toolbox.algorithmTree
        print(f"[1366 x 768] the Toolbox raised: its list {tree.height()} px high")
        assert tree.isVisible() and tree.height() >= 0.4 * win.height()
        width = canvas.width()
        d.photo_dock.close()  # collapsed: the map takes the photo column's room
        process(100)
        assert canvas.width() >= width + 300 and not view.isVisible()
    finally:
        d.cleanup()
        qgis_canvas.setParent(None)
        win.close()


def test_a_long_message_wraps_and_scrolls_and_leaves_the_table_alone(default_dock, georef_ws):
    """A failed automatic control's message (several hundred characters, file paths without a space) ran off the
    dock and squeezed the GCP table to one row (issue 36 item 19): it is wrapped inside the dock's width, at most
    a few lines high, scrolls for the rest, and the table keeps its rows."""
    from archaeoortho.ui.gcp_dock import STATUS_LINES, TABLE_MIN_ROWS

    dock = default_dock
    assert dock.open_workspace(georef_ws)
    process(100)
    width, table_height = dock.width(), dock.table.height()
    path = "/data/references/" + "national_orthophoto_tiles_" * 8 + "merged.vrt"
    text = ("Automatic control: 0 candidate(s) kept, 4 needed: the reference orthophoto " + path + " does not "
            "cover the block (its extent lies 5.2 km to the north-east of the photos' GPS positions); the reference "
            "DSM " + path.replace("orthophoto", "dsm") + " holds no height over the block. Choose references that "
            "cover the photographed area, or move the map to it when the photos carry no GPS. ") * 2
    dock.message(text)
    process(200)
    status = dock.status
    print(f"\n[long message] {len(text)} characters: status {status.width()} x {status.height()} px, table "
          f"{table_height} -> {dock.table.height()} px, dock width {width} -> {dock.width()} px")
    assert status.text() == text  # the whole message, nothing cut
    assert dock.width() == width
    right = status.mapTo(dock, status.rect().topRight()).x()
    assert right < dock.width()
    assert status.height() <= (STATUS_LINES + 1) * status.fontMetrics().lineSpacing()
    assert status.verticalScrollBar().maximum() > 0  # the rest is there, scrolled to
    rows = dock.table.verticalHeader().defaultSectionSize()
    assert dock.table.height() >= TABLE_MIN_ROWS * rows
    assert dock.table.height() >= table_height - STATUS_LINES * status.fontMetrics().lineSpacing()  # bounded


def test_the_diagnosis_is_shown_whole(default_dock, georef_ws):
    """The adjustment's diagnosis was cut at 100 characters, hiding the finding (four automatic GCPs suspect, the
    worst 1.54 m): every message is shown whole (issue 36 item 18, the dock's half)."""
    from qgis.PyQt.QtGui import QTextDocument

    dock = default_dock
    assert dock.open_workspace(georef_ws)
    lines = ["Check point residuals are 3.1 times the control residuals: the control may be biased (a shifted "
             "point, a datum mix-up); compare the control file with the survey's.",
             "4 automatic GCPs are suspect (residuals over 3 sigma): auto_017 1.54 m, auto_052 1.21 m, auto_008 "
             "0.97 m, auto_033 0.91 m; they lie on the block's edge where the reference DSM is coarsest."]
    dock.store.diagnosis = lines
    dock.show_diagnosis()
    process(100)
    doc = QTextDocument()
    doc.setHtml(dock.diagnosis.text())
    shown = " ".join(doc.toPlainText().split())
    for line in lines:
        assert line in shown
    dock.body_scroll.ensureWidgetVisible(dock.diagnosis)
    process(50)
    assert dock.diagnosis.isVisible() and dock.diagnosis.verticalScrollBar().maximum() == 0  # whole, unscrolled
