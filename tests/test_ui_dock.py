"""The GCP dock under pytest-qgis (offscreen): a workspace opens, a canvas click sets X/Y and samples Z
from a DSM layer, a photo click adds an observation, guided placement, undo, import/export round trips,
the adjustment in a task, screenshots of the dock and the photo viewer.

The workspace is built from tests/synthetic.py's exact block: a sparse model from the truth (arbitrary
model frame, as an alignment gives) and quick photos (the scene's texture draped on the ground plane with
the GCP targets drawn at their exact pixel positions): seconds instead of the minute a full rendering
takes.  Helpers here are imported by the other tests/test_ui_*.py modules.
"""
import json
import math
import os
import shutil
import time

import numpy as np
import pytest

from tests import synthetic as syn
from tests.conftest import ROOT
from tests.workspaces import synthetic_workspace

pytestmark = pytest.mark.usefixtures("qgis_app")

SCREENSHOTS = os.environ.get("ARCHAEOORTHO_SCREENSHOTS") or os.path.join(ROOT, "build", "screenshots", "ui")


# --------------------------------------------------------------------------------------------------
# a synthetic workspace
# --------------------------------------------------------------------------------------------------


def _texture(blk, res, seed=0):
    import cv2

    xmin, ymin, xmax, ymax = blk.scene.bounds
    nx, ny = int(math.ceil((xmax - xmin) / res)), int(math.ceil((ymax - ymin) / res))
    rng = np.random.default_rng(seed)
    tex = np.zeros((ny, nx), np.float32)
    for k, w in ((128, 0.45), (32, 0.3), (8, 0.15), (2, 0.1)):
        small = rng.random((max(2, ny // k), max(2, nx // k))).astype(np.float32)
        tex += w * cv2.resize(small, (nx, ny), interpolation=cv2.INTER_CUBIC)
    tex = (tex - tex.min()) / max(float(np.ptp(tex)), 1e-6)
    return (60 + 150 * tex).astype(np.uint8)


def quick_photos(blk, folder, res=0.05, step=8):
    """Photos of the block: texture draped on the ground (buildings flat), GCP targets (a black square with a
    white cross, centred on the exact projection) drawn on top.  Returns {name: path}."""
    import cv2

    os.makedirs(folder, exist_ok=True)
    tex = _texture(blk, res)
    cam = blk.camera
    us = np.arange(0, cam.width + step, step, dtype=float)
    vs = np.arange(0, cam.height + step, step, dtype=float)
    uu, vv = np.meshgrid(us, vs)
    px = np.stack([uu, vv], axis=-1).reshape(-1, 2)
    paths = {}
    for shot in blk.shots:
        d = shot.rays(cam.undistort(cam.normalized_from_pixel(px)))
        z = np.full(len(d), blk.scene.base_z)
        for _ in range(3):
            t = (z - shot.centre[2]) / d[:, 2]
            xy = shot.centre[:2] + t[:, None] * d[:, :2]
            z = blk.scene.ground_at(xy[:, 0], xy[:, 1])
        mx, my = blk.scene.raster_coords(xy[:, 0], xy[:, 1], res)
        mx = cv2.resize(mx.reshape(uu.shape), (cam.width, cam.height), interpolation=cv2.INTER_LINEAR)
        my = cv2.resize(my.reshape(uu.shape), (cam.width, cam.height), interpolation=cv2.INTER_LINEAR)
        img = cv2.remap(tex, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
        img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
        for p in blk.gcps:
            if shot.name not in p.observations:
                continue
            x, y = p.observations[shot.name] - 0.5  # cv2 draws on pixel centres at integers
            s = 16  # 1/16 px
            cx, cy = int(round(x * s)), int(round(y * s))
            cv2.rectangle(img, (cx - 7 * s, cy - 7 * s), (cx + 7 * s, cy + 7 * s), (20, 20, 20), -1, cv2.LINE_AA, 4)
            cv2.line(img, (cx - 6 * s, cy), (cx + 6 * s, cy), (250, 250, 250), 2, cv2.LINE_AA, 4)
            cv2.line(img, (cx, cy - 6 * s), (cx, cy + 6 * s), (250, 250, 250), 2, cv2.LINE_AA, 4)
        path = os.path.join(folder, shot.name)
        cv2.imwrite(path, img, [cv2.IMWRITE_JPEG_QUALITY, 92])
        paths[shot.name] = path
    return paths


def make_workspace(root, blk, photos, georeference_with=None, name="ws"):
    """An aligned workspace from the block's truth (model in an arbitrary frame); georeferenced with the
    GCPSet ``georeference_with`` when given.  Returns the workspace path."""
    from archaeoortho.core.georef.options import GeorefOptions
    from archaeoortho.core.georef.stage import georeference_workspace

    rec = blk.truth_reconstruction(n_points=800, noise_px=0.3)
    ws = synthetic_workspace(os.path.join(root, name), blk, rec, photos=photos, cameras_gpkg=True)
    if georeference_with is not None:
        georeference_workspace(ws, GeorefOptions(gcps=georeference_with))
    return ws

@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1)


@pytest.fixture(scope="module")
def photos(block, tmp_path_factory):
    return quick_photos(block, str(tmp_path_factory.mktemp("synthetic photos")))


@pytest.fixture(scope="module")
def georef_ws(block, photos, tmp_path_factory):
    control = block.spread_control(5)
    return make_workspace(str(tmp_path_factory.mktemp("georef")), block, photos, block.gcp_set(control))


@pytest.fixture
def aligned_ws(block, photos, tmp_path):
    return make_workspace(str(tmp_path), block, photos)


@pytest.fixture
def dock(qgis_canvas, qgis_new_project):
    from archaeoortho.ui.gcp_dock import GcpDock

    d = GcpDock(None, qgis_canvas)
    d.resize(760, 620)
    d.photo_dock.resize(1000, 640)
    d.show()
    d.photo_dock.show()
    yield d
    d.cleanup()
    d.photo_dock.close()
    d.close()


def process(ms=50):
    from qgis.PyQt.QtCore import QCoreApplication

    end = time.time() + ms / 1000.0
    while True:
        QCoreApplication.processEvents()
        if time.time() >= end:
            break


def wait_task(dock, timeout=240):
    t0 = time.time()
    while dock.task is not None and time.time() - t0 < timeout:
        process(50)
    assert dock.task is None, "the task did not end in time"


# --------------------------------------------------------------------------------------------------
# tests
# --------------------------------------------------------------------------------------------------


def test_dock_opens_with_a_workspace(dock, georef_ws, block):
    assert dock.open_workspace(georef_ws)
    names = [p.name for p in dock.store.gcps.points]
    assert sorted(names) == sorted(p.name for p in block.gcps)
    assert dock.model.rowCount() == len(names)
    assert dock.store.crs == syn.CRS
    assert dock.predictor is not None and dock.predictor.georeferenced
    assert dock.current_name() == names[0]
    # residuals of the adjustment are shown, with a colour
    from archaeoortho.ui.gcp_table import DXY, NAME
    from qgis.PyQt.QtCore import Qt

    assert dock.model.index(0, DXY).data() not in ("", None)
    assert dock.model.index(0, NAME).data(Qt.ItemDataRole.BackgroundRole) is not None
    assert "RMSE" in dock.summary.text()
    # the strip shows the photos that see the point, observed first
    point = dock.current_point()
    strip = dock.photo_panel.thumbnail_names()
    assert strip[:len(point.observations)] == point.images()
    assert set(strip) >= set(block.gcp(point.name).observations)
    assert len(strip) < len(block.shots)


def test_canvas_click_sets_xy_and_samples_z_from_a_dsm(dock, aligned_ws, tmp_path, qgis_canvas):
    """The canvas is in Web Mercator, the GCPs in UTM 33N, the DSM in UTM 33N: a click at a canvas pixel
    gives the transformed X/Y and the bilinear height of a plane (exact for bilinear interpolation)."""
    from osgeo import gdal, osr
    from qgis.core import (
        QgsCoordinateReferenceSystem,
        QgsCoordinateTransform,
        QgsPointXY,
        QgsProject,
        QgsRasterLayer,
        QgsRectangle,
    )
    from qgis.gui import QgsMapMouseEvent
    from qgis.PyQt.QtCore import QEvent, QPoint, Qt

    # a DSM: z = 150 + 0.02 (x - x0) - 0.01 (y - y0), 0.5 m cells
    x0, y0, res, n = 499950.0, 4600050.0, 0.5, 200
    path = str(tmp_path / "dsm.tif")
    ds = gdal.GetDriverByName("GTiff").Create(path, n, n, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((x0, res, 0, y0, 0, -res))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    cx = x0 + (np.arange(n) + 0.5) * res
    cy = y0 - (np.arange(n) + 0.5) * res
    xx, yy = np.meshgrid(cx, cy)
    ds.GetRasterBand(1).WriteArray((150 + 0.02 * (xx - x0) - 0.01 * (yy - y0)).astype(np.float32))
    ds.GetRasterBand(1).SetNoDataValue(-9999)
    ds = None
    dsm = QgsRasterLayer(path, "ALS DSM")
    assert dsm.isValid()
    assert QgsProject.instance().addMapLayer(dsm)

    assert dock.open_workspace(aligned_ws)
    dock.store.set_crs(syn.CRS)
    dock.dsm_combo.setLayer(dsm)
    merc = QgsCoordinateReferenceSystem("EPSG:3857")
    qgis_canvas.setDestinationCrs(merc)
    utm = QgsCoordinateReferenceSystem("EPSG:32633")
    to_merc = QgsCoordinateTransform(utm, merc, QgsProject.instance())
    qgis_canvas.setExtent(to_merc.transformBoundingBox(QgsRectangle(x0 + 10, y0 - 90, x0 + 90, y0 - 10)))
    qgis_canvas.refresh()
    process(100)

    n_before = len(dock.store.gcps.points)
    dock.act_pick.setChecked(True)
    assert qgis_canvas.mapTool() is dock.map_tool
    target = to_merc.transform(QgsPointXY(x0 + 43.21, y0 - 57.89))
    dev = qgis_canvas.getCoordinateTransform().transform(target)
    pixel = QPoint(int(dev.x()), int(dev.y()))
    event = QgsMapMouseEvent(qgis_canvas, QEvent.Type.MouseButtonRelease, pixel, Qt.MouseButton.LeftButton)
    dock.map_tool.canvasReleaseEvent(event)
    # no point was selected: the click made one
    assert len(dock.store.gcps.points) == n_before + 1
    p = dock.current_point()
    expected = QgsCoordinateTransform(merc, utm, QgsProject.instance()).transform(
        qgis_canvas.getCoordinateTransform().toMapCoordinates(pixel))
    assert p.x == pytest.approx(expected.x(), abs=1e-6)
    assert p.y == pytest.approx(expected.y(), abs=1e-6)
    assert p.z == pytest.approx(150 + 0.02 * (p.x - x0) - 0.01 * (p.y - y0), abs=1e-4)
    # a second click moves the selected point; off the DSM, Z stays and the user is told
    outside = QPoint(2, 2)
    qgis_canvas.setExtent(to_merc.transformBoundingBox(QgsRectangle(x0 - 400, y0 - 300, x0 + 300, y0 + 300)))
    process(50)
    z_before = p.z
    dock.map_tool.canvasReleaseEvent(
        QgsMapMouseEvent(qgis_canvas, QEvent.Type.MouseButtonRelease, outside, Qt.MouseButton.LeftButton))
    p = dock.current_point()
    assert p.z == z_before
    assert "No height" in dock.status.text()
    # Z by hand, and undo twice restores the first click
    from archaeoortho.ui.gcp_table import Z

    dock.model.setData(dock.model.index(dock.store.gcps.points.index(p), Z), "123.5")
    assert dock.current_point().z == 123.5
    dock.store.undo_stack.undo()
    dock.store.undo_stack.undo()
    q = dock.store.gcps.by_name(p.name)
    assert q.x == pytest.approx(expected.x(), abs=1e-6)
    dock.act_pick.setChecked(False)
    assert qgis_canvas.mapTool() is not dock.map_tool
    # saved in the workspace
    saved = json.load(open(os.path.join(aligned_ws, "georef", "control.json")))
    assert any(abs(s["x"] - expected.x()) < 1e-6 for s in saved["points"])


def test_bilinear_weights_and_nodata():
    from archaeoortho.ui.raster import bilinear

    v = [[1.0, 2.0], [3.0, 4.0]]
    assert bilinear(v, 0.0, 0.0) == 1.0
    assert bilinear(v, 1.0, 1.0) == 4.0
    assert bilinear(v, 0.5, 0.5) == pytest.approx(2.5)
    assert bilinear(v, 0.25, 0.75) == pytest.approx(0.75 * 0.25 * 1 + 0.25 * 0.25 * 2 + 0.75 * 0.75 * 3 + 0.25 * 0.75 * 4)
    assert bilinear([[1.0, None], [3.0, 4.0]], 0.0, 0.0) == 1.0  # the missing cell has no weight here
    assert bilinear([[None, None], [None, 4.0]], 0.1, 0.1) is None  # mostly in a hole


def _click(view, scene_xy):
    """Left click at the screen pixel showing scene point ``scene_xy``; returns the scene position the view
    computes for that pixel (the expected observation)."""
    from qgis.PyQt.QtCore import QPoint, QPointF, Qt
    from qgis.PyQt.QtTest import QTest

    w = view.mapFromScene(QPointF(*scene_xy))
    pos = QPoint(w.x(), w.y())
    expected = view.scene_pos(pos)
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, pos)
    return expected


def drag(widget, start, end, steps=5):
    """A left-button drag (QTest.mouseMove sends no button state, so the events are made here)."""
    from qgis.PyQt.QtCore import QEvent, QPointF, Qt
    from qgis.PyQt.QtGui import QMouseEvent
    from qgis.PyQt.QtWidgets import QApplication

    left, none = Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier

    def send(kind, pos, button, buttons):
        local = QPointF(pos)
        screen = QPointF(widget.mapToGlobal(pos))
        window = QPointF(widget.mapTo(widget.window(), pos))
        QApplication.sendEvent(widget, QMouseEvent(kind, local, window, screen, button, buttons, none))

    send(QEvent.Type.MouseButtonPress, start, left, left)
    for k in range(1, steps + 1):
        p = start + (end - start) * k / steps
        send(QEvent.Type.MouseMove, p, Qt.MouseButton.NoButton, left)
    send(QEvent.Type.MouseButtonRelease, end, left, Qt.MouseButton.NoButton)


def test_photo_click_adds_an_observation_with_subpixel_precision(dock, aligned_ws, block):
    from qgis.PyQt.QtCore import QPointF, Qt
    from qgis.PyQt.QtTest import QTest

    assert dock.open_workspace(aligned_ws)
    name = dock.add_point("T1", 500000.0, 4600000.0, 150.0)
    image = block.shots[3].name
    dock.show_photo(image)
    view = dock.photo_panel.view
    view.set_zoom(8.0, QPointF(300.3, 200.7))
    process(50)
    expected = _click(view, (300.3, 200.7))
    obs = dock.store.gcps.by_name(name).observations
    assert len(obs) == 1 and obs[0].image == image
    assert obs[0].x == pytest.approx(expected.x(), abs=1e-9)
    assert obs[0].y == pytest.approx(expected.y(), abs=1e-9)
    assert abs(obs[0].x - 300.3) <= 1.0 / 8 and abs(obs[0].y - 200.7) <= 1.0 / 8  # one screen pixel at 8x
    assert obs[0].x != round(obs[0].x)  # sub-pixel
    assert dock.photo_panel.observation is not None
    # a second click moves it
    expected = _click(view, (302.0, 199.0))
    obs = dock.store.gcps.by_name(name).observations
    assert len(obs) == 1 and obs[0].x == pytest.approx(expected.x())
    # dragging the marker moves it too
    marker = dock.photo_panel.observation
    start = view.mapFromScene(marker.pos())
    drag(view.viewport(), start, start + type(start)(20, 10))
    process(50)
    moved = dock.store.gcps.by_name(name).observations[0]
    assert moved.x == pytest.approx(expected.x() + 20 / 8.0, abs=0.2)
    assert moved.y == pytest.approx(expected.y() + 10 / 8.0, abs=0.2)
    # Delete removes it, undo brings it back
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert dock.store.gcps.by_name(name).observations == []
    dock.store.undo_stack.undo()
    assert len(dock.store.gcps.by_name(name).observations) == 1
    # everything is in the workspace
    saved = json.load(open(os.path.join(aligned_ws, "georef", "control.json")))
    assert saved["points"][0]["observations"][0]["image"] == image


def test_guided_placement_three_points_then_confirm(dock, aligned_ws, block):
    """Aligned block, points with coordinates: after 3 points are placed in 2 photos each, every other
    point is predicted in every photo that sees it, within 2 px; Enter confirms, 'Confirm & next' walks on."""
    from qgis.PyQt.QtCore import QPointF, Qt
    from qgis.PyQt.QtTest import QTest

    assert dock.open_workspace(aligned_ws)
    truth = block.gcp_set(block.spread_control(5), noise_px=0.0)
    for p in truth.points:
        p.observations = []
    dock.store.replace_all(truth, "coordinates")
    dock.load_predictor()
    first = block.spread_control(5)[:3]
    clicks = 0
    view = dock.photo_panel.view
    for name in first:
        dock.select_point(name)
        assert dock.predictions == {} or name != first[0]
        for img in list(block.gcp(name).observations)[:2]:
            dock.show_photo(img)
            xy = block.gcp(name).observations[img]
            view.set_zoom(8.0, QPointF(*xy))
            process(20)
            _click(view, xy)
            clicks += 1
    # the fourth point: predicted everywhere, within 2 px of the truth
    fourth = next(p.name for p in block.gcps if p.name not in first)
    dock.select_point(fourth)
    true_obs = block.gcp(fourth).observations
    assert set(true_obs) <= set(dock.predictions)
    for img, xy in true_obs.items():
        assert math.hypot(*(np.array(dock.predictions[img].xy) - xy)) < 2.0
    assert dock.predictions[next(iter(true_obs))].source == "helmert"
    strip = dock.photo_panel.thumbnail_names()
    assert set(strip) >= set(true_obs)
    # Space confirms the prediction in the photo shown, Enter confirms and moves on
    img0 = strip[0]
    dock.show_photo(img0)
    assert dock.photo_panel.prediction is not None
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Space)
    obs = dock.store.gcps.by_name(fourth).observations
    assert [o.image for o in obs] == [img0]
    assert dock.photo_panel.image == img0
    QTest.keyClick(view, Qt.Key.Key_Return)  # nothing to confirm here: on to the next photo
    assert dock.photo_panel.image != img0 and dock.photo_panel.prediction is not None
    QTest.keyClick(view, Qt.Key.Key_Return)
    assert len(dock.store.gcps.by_name(fourth).observations) == 2
    # 'Confirm & next' walks through the rest: one click per photo
    while dock.photo_panel.btn_next.isEnabled():
        dock.photo_panel.btn_next.click()
        clicks += 1
        process(10)
    placed = {o.image for o in dock.store.gcps.by_name(fourth).observations}
    assert placed >= set(true_obs) - {img0}
    for o in dock.store.gcps.by_name(fourth).observations:
        if o.image in true_obs:
            assert math.hypot(o.x - true_obs[o.image][0], o.y - true_obs[o.image][1]) < 2.0
    # each confirmed observation is one undo step
    n = len(dock.store.gcps.by_name(fourth).observations)
    dock.act_undo.trigger()
    assert len(dock.store.gcps.by_name(fourth).observations) == n - 1


def _same(a, b, sigmas=True):
    assert a.crs.split() == b.crs.split() or a.crs == b.crs
    pa = {p.name: p for p in a.points}
    pb = {p.name: p for p in b.points}
    assert set(pa) == set(pb)
    for n, p in pa.items():
        q = pb[n]
        assert p.x == pytest.approx(q.x, abs=1e-9) and p.y == pytest.approx(q.y, abs=1e-9)
        assert p.z == pytest.approx(q.z, abs=1e-9)
        assert p.role == q.role
        if sigmas:
            assert p.sigma_xy == pytest.approx(q.sigma_xy) and p.sigma_z == pytest.approx(q.sigma_z)
        oa = sorted((o.image, o.x, o.y) for o in p.observations)
        ob = sorted((o.image, o.x, o.y) for o in q.observations)
        assert len(oa) == len(ob)
        for u, v in zip(oa, ob):
            assert u[0] == v[0] and u[1] == pytest.approx(v[1], abs=1e-9) and u[2] == pytest.approx(v[2], abs=1e-9)


def test_import_export_round_trips(dock, aligned_ws, block, tmp_path):
    """ODM gcp_list.txt, CSV pair and a GeoPackage point layer: export, import into a fresh workspace, compare."""
    import copy

    from archaeoortho.core.io import gcp as gcpmod
    from qgis.core import QgsProject, QgsVectorLayer

    assert dock.open_workspace(aligned_ws)
    gs = block.gcp_set(block.spread_control(5), noise_px=0.3)
    gs = gcpmod.GCPSet.from_dict(gs.to_dict())
    gs.points[0].sigma_xy, gs.points[0].sigma_z = 0.5, 0.7
    dock.store.replace_all(gs, "test set")
    reference = copy.deepcopy(dock.store.gcps)
    # ODM: sigmas are not part of the format
    odm = dock.export_file(str(tmp_path / "gcp_list.txt"))
    assert odm and os.path.isfile(odm)
    dock.store.replace_all(gcpmod.GCPSet(crs=""), "clear")
    assert dock.import_file(odm) is not None
    _same(dock.store.gcps, reference, sigmas=False)
    # CSV keeps sigmas and roles
    csv_path = dock.export_file(str(tmp_path / "points.csv"))
    assert os.path.isfile(str(tmp_path / "points_observations.csv"))
    dock.store.replace_all(reference, "reference")
    csv_path = dock.export_file(str(tmp_path / "points.csv"))
    dock.store.replace_all(gcpmod.GCPSet(crs=""), "clear")
    dock.import_file(csv_path)
    _same(dock.store.gcps, reference)
    # GeoPackage layer (one feature per observation), read back as a point layer
    gpkg = dock.export_layer(str(tmp_path / "obs.gpkg"))
    layer = QgsVectorLayer(gpkg, "obs", "ogr")
    assert layer.isValid() and layer.featureCount() == reference.n_observations()
    assert QgsProject.instance().addMapLayer(layer)
    dock.store.replace_all(gcpmod.GCPSet(crs=""), "clear")
    assert dock.import_layer(layer) is not None
    _same(dock.store.gcps, reference)
    # merge: a second import of the same file changes nothing (and adds no undo step)
    steps = dock.store.undo_stack.count()
    dock.import_file(csv_path, merge=True)
    _same(dock.store.gcps, reference)
    assert dock.store.undo_stack.count() == steps
    # an import is one undo step
    dock.store.undo_stack.undo()
    assert dock.store.gcps.points == []


def test_georeference_task_updates_residuals_and_loads_styled_layers(dock, aligned_ws, block):
    from qgis.core import QgsProject

    assert dock.open_workspace(aligned_ws)
    control = block.spread_control(5)
    dock.store.replace_all(block.gcp_set(control, noise_px=0.4), "control")
    assert not dock.store.residuals
    progress = []
    task = dock.run_georeference()
    assert task is not None
    task.progressChanged.connect(progress.append)
    assert dock.btn_cancel.isEnabled() and not dock.btn_georef.isEnabled()
    wait_task(dock)
    assert dock.last_task_error is None
    assert dock.progress.value() == 100
    assert dock.store.residuals and dock.store.figures["CHECK_N"] >= 5
    assert dock.store.figures["CHECK_RMSE_XY"] < 2 * block.gsd
    assert dock.predictor is not None and dock.predictor.georeferenced
    kinds = {lyr.customProperty("archaeoortho/kind") for lyr in QgsProject.instance().mapLayers().values()}
    assert {"cameras", "footprints", "residuals"} <= kinds
    assert "Check: RMSE" in dock.summary.text()
    # a point edited after the run is marked stale
    dock.place_observation(block.shots[0].name, 10.0, 10.0)
    assert dock.current_name() in dock.store.stale


def test_georeference_task_cancel(dock, aligned_ws, block):
    import json as _json

    assert dock.open_workspace(aligned_ws)
    dock.store.replace_all(block.gcp_set(block.spread_control(5), noise_px=0.4), "control")
    task = dock.run_georeference()
    assert task is not None
    process(30)
    dock.btn_cancel.click()
    wait_task(dock, 60)
    status = _json.load(open(os.path.join(aligned_ws, "workspace.json")))["stages"]["georeference"]["status"]
    assert status in ("cancelled", "done")  # done when the adjustment finished before the cancel arrived
    if status == "cancelled":
        assert "Cancel" in dock.status.text()
    assert dock.btn_georef.isEnabled()


def test_screenshots_of_the_dock_and_the_photo_viewer(dock, georef_ws, block):
    """Saved to build/screenshots/ui (or $ARCHAEOORTHO_SCREENSHOTS): look at them."""
    from qgis.PyQt.QtCore import QPointF

    assert dock.open_workspace(georef_ws)
    os.makedirs(SCREENSHOTS, exist_ok=True)
    name = block.spread_control(5)[4]
    dock.select_point(name)
    # remove the most central observation so that the photo shows a prediction to confirm
    point = dock.current_point()
    img = min(point.images(), key=lambda n: dock.predictions[n].centrality)
    dock.store.remove_observation(name, img)
    dock.photo_panel.load_all_thumbnails()
    dock.show_photo(img)
    process(100)
    dock.grab().save(os.path.join(SCREENSHOTS, "dock.png"))
    dock.photo_dock.grab().save(os.path.join(SCREENSHOTS, "photo-viewer-prediction.png"))
    assert dock.photo_panel.prediction is not None
    dock.confirm_prediction()
    obs = next(o for o in dock.current_point().observations if o.image == img)
    dock.photo_panel.view.set_zoom(6.0, QPointF(obs.x, obs.y))
    process(100)
    dock.photo_dock.grab().save(os.path.join(SCREENSHOTS, "photo-viewer-zoomed.png"))
    for f in ("dock.png", "photo-viewer-prediction.png", "photo-viewer-zoomed.png"):
        assert os.path.getsize(os.path.join(SCREENSHOTS, f)) > 10000
    shutil.copy(os.path.join(georef_ws, "georef", "control.json"), os.path.join(SCREENSHOTS, "control.json"))


def test_twenty_megapixel_photo_is_drawn_from_pyramid_tiles(tmp_path):
    """A 5472 x 3648 photo: decoded once, drawn from the pyramid level that fits the zoom and only the
    tiles in view; figures printed (pytest -s), no timing asserted."""
    import cv2
    from archaeoortho.ui.photo_viewer import TILE, PhotoPanel
    from qgis.PyQt.QtCore import QPointF

    rng = np.random.default_rng(3)
    small = rng.integers(0, 255, (456, 684, 3), dtype=np.uint8)
    img = cv2.resize(small, (5472, 3648), interpolation=cv2.INTER_CUBIC)
    path = str(tmp_path / "big.jpg")
    cv2.imwrite(path, img, [cv2.IMWRITE_JPEG_QUALITY, 90])
    panel = PhotoPanel()
    panel.resize(1000, 700)
    panel.show()
    process(100)
    panel.set_photos({"big.jpg": path})
    t0 = time.time()
    assert panel.show_photo("big.jpg")
    t_open = time.time() - t0
    pyr = panel.pyramid("big.jpg")
    assert (pyr.width, pyr.height) == (5472, 3648)
    assert len(pyr.levels) >= 4
    view = panel.view
    process(100)
    view.fit()
    t0 = time.time()
    view.viewport().repaint()
    t_fit = time.time() - t0
    level_fit = view.pyramid_item.last_level
    tiles_fit = pyr.tiles_made
    assert level_fit >= 2  # a coarse level for the whole photo
    view.set_zoom(1.0, QPointF(2736.0, 1824.0))
    t0 = time.time()
    view.viewport().repaint()
    t_full = time.time() - t0
    assert view.pyramid_item.last_level == 0
    visible = math.ceil(view.viewport().width() / TILE + 1) * math.ceil(view.viewport().height() / TILE + 1)
    assert pyr.tiles_made - tiles_fit <= visible  # only the tiles in view, never the whole level
    t0 = time.time()
    for dx in range(10):  # panning: tiles come from the cache
        view.horizontalScrollBar().setValue(view.horizontalScrollBar().value() + 40)
        view.viewport().grab()
    t_pan = (time.time() - t0) / 10
    print(f"\n[20 MP photo] open (decode + pyramid) {t_open:.2f} s; repaint at fit {1000 * t_fit:.0f} ms "
          f"(level {level_fit}); at 1:1 {1000 * t_full:.0f} ms; pan step {1000 * t_pan:.0f} ms; "
          f"tiles made {pyr.tiles_made}")
    panel.close()


def test_reference_dsm_pickers_list_height_rasters_only(dock, aligned_ws, tmp_path):
    """The Reference DSM box (automatic control) and the 'Heights (Z) from' box list height rasters only: not an
    orthophoto (RGB bytes), a hillshade (a picture of its DSM), a web map, nor the open workspace's own products
    in the reference box; the one check of core/io/raster.py (not_heights) judges the files (issue 48 item 10)."""
    from archaeoortho.qgisio import layers
    from qgis.core import QgsProject, QgsRasterLayer

    from tests.test_ui_layers import _raster

    assert dock.open_workspace(aligned_ws)
    project = QgsProject.instance()
    layers.load_dsm(_raster(str(tmp_path / "als_dsm.tif"), 1, nodata=-9999), project, name="ALS DSM")
    layers.load_orthomosaic(_raster(str(tmp_path / "ortho.tif"), 4, alpha=True), project, name="Reference ortho")
    own = layers.workspace_layout(aligned_ws).default_dsm  # the workspace's own DSM
    os.makedirs(os.path.dirname(own), exist_ok=True)
    layers.load_dsm(_raster(own, 1, nodata=-9999), project, name="Own DSM")
    process(50)
    later = QgsRasterLayer(_raster(str(tmp_path / "scan.tif"), 3), "RGB added later")  # added after the dock opened
    assert project.addMapLayer(later)
    process(50)

    def listed(combo):
        return [combo.itemText(i) for i in range(combo.count()) if combo.itemText(i)]

    assert listed(dock.auto_dsm_combo) == ["ALS DSM"], listed(dock.auto_dsm_combo)
    assert sorted(listed(dock.dsm_combo)) == ["ALS DSM", "Own DSM"], listed(dock.dsm_combo)
    assert "Reference ortho" in listed(dock.auto_ortho_combo)  # the orthophoto box still lists every raster
    assert "height" in dock.auto_dsm_combo.toolTip()


def test_a_cancelled_task_is_not_reported_failed_in_the_message_bar(qgis_iface, monkeypatch):
    """QGIS desktop tells every task that ends unsuccessfully as 'Task failed: <description>' (a system
    notification, in the message bar where the desktop has none): a user's Cancel was shown as a failure while
    the dock said 'Cancelled' (issue 48 item 9).  QGIS's handler is emulated here on the same signal; a cancel
    leaves no 'failed' notice behind, a real failure keeps it."""
    from archaeoortho.core.common.progress import Cancelled
    from archaeoortho.ui.tasks import CoreTask, start
    from qgis.core import QgsApplication, QgsTask
    from qgis.gui import QgsMessageBar

    manager = QgsApplication.taskManager()
    bar = QgsMessageBar()  # a real one: pytest-qgis's is a mock
    monkeypatch.setattr(qgis_iface, "messageBar", lambda: bar)

    def notify(task_id, status):  # what QgisApp::onTaskCompleteShowNotify does with no notification daemon
        task = manager.task(task_id)
        if task is not None and status == QgsTask.TaskStatus.Terminated:
            bar.pushInfo("Task failed", task.description())

    def wait_for_cancel(progress=None):
        t0 = time.time()
        while not progress.is_cancelled() and time.time() - t0 < 20:
            time.sleep(0.02)
        raise Cancelled("cancelled by the user")

    def broken(progress=None):
        raise ValueError("a bug")

    ended = []
    manager.statusChanged.connect(notify)
    try:
        for fn, description in ((wait_for_cancel, "ArchaeoOrtho: cancel test"), (broken, "ArchaeoOrtho: bug test")):
            task = CoreTask(description, fn, on_error=lambda message, cancelled: ended.append(cancelled))
            start(task)
            process(200)
            task.cancel() if fn is wait_for_cancel else None
            t0 = time.time()
            while len(ended) < (1 if fn is wait_for_cancel else 2) and time.time() - t0 < 20:
                process(50)
            process(100)
    finally:
        manager.statusChanged.disconnect(notify)
    notices = [(item.title(), item.text()) for item in bar.items()]
    assert ended == [True, False]
    assert ("Task failed", "ArchaeoOrtho: cancel test") not in notices, notices
    assert ("Task failed", "ArchaeoOrtho: bug test") in notices, notices


def test_the_workspace_folder_dialog_takes_a_new_folder_name(tmp_path, monkeypatch):
    """'Workspace folder (new or existing)' (New from photos...) takes a typed new folder name: Qt's folder
    dialog said 'Directory not found' (issue 48 item 9); an existing folder is taken as before."""
    from archaeoortho.ui.folder_dialog import FolderDialog
    from qgis.PyQt.QtCore import QTimer
    from qgis.PyQt.QtWidgets import QApplication, QDialog, QFileDialog, QLineEdit, QMessageBox

    warned = []

    def close_warning():  # Qt's C++ dialog shows its own modal QMessageBox: read and closed
        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox):
            warned.append(box.text())
            box.close()

    def typed(dialog, text):
        dialog.setDirectory(str(tmp_path))
        dialog.show()
        process(50)
        edit = dialog.findChild(QLineEdit, "fileNameEdit")
        edit.setText(text)
        QTimer.singleShot(300, close_warning)
        button = dialog.choose_button() if hasattr(dialog, "choose_button") else None
        if button is not None:  # what the user does: click Choose (Qt disabled it for a name that is no folder)
            assert button.isEnabled(), text
            button.click()
        else:
            dialog.accept()
        process(400)
        return dialog

    plain = QFileDialog(None, "plain")  # what the dock used: a new name is refused
    plain.setFileMode(QFileDialog.FileMode.Directory)
    plain.setOption(QFileDialog.Option.DontUseNativeDialog, True)
    assert typed(plain, "site_a").result() != QDialog.DialogCode.Accepted
    assert warned and "Directory not found" in warned[0], warned
    warned.clear()
    d = typed(FolderDialog(None, "Workspace folder (new or existing)"), "site_b")
    assert d.result() == QDialog.DialogCode.Accepted and not warned
    assert os.path.normpath(d.selectedFiles()[0]) == os.path.normpath(str(tmp_path / "site_b"))
    assert os.path.isdir(tmp_path / "site_b")
    os.makedirs(tmp_path / "old")
    d = typed(FolderDialog(None, "Workspace folder (new or existing)"), "old")
    assert d.result() == QDialog.DialogCode.Accepted and not warned
    assert os.path.normpath(d.selectedFiles()[0]) == os.path.normpath(str(tmp_path / "old"))


def test_open_report_from_the_dock_after_a_restart(dock, aligned_ws, tmp_path, monkeypatch):
    """The accuracy report is always at hand (issue 48 item 5): after a restart the Results Viewer is empty; the
    dock's 'Open report' opens the workspace's report.html (or the file the report stage recorded), enabled only
    when the workspace has one."""
    from archaeoortho.core.project.workspace import Workspace
    from archaeoortho.core.report.stage import report_of
    from archaeoortho.qgisio import layers
    from qgis.PyQt.QtGui import QDesktopServices

    opened = []
    monkeypatch.setattr(QDesktopServices, "openUrl", lambda url: opened.append(url.toLocalFile()) or True)
    assert dock.open_workspace(aligned_ws)
    assert not dock.act_report.isEnabled() and report_of(Workspace.open(aligned_ws)) is None
    report = layers.workspace_layout(aligned_ws).default_report
    with open(report, "w", encoding="utf-8") as fh:
        print("<html><body>report</body></html>", file=fh)
    assert dock.open_workspace(aligned_ws)  # as after a restart: the workspace opened again
    assert dock.act_report.isEnabled()
    dock.act_report.trigger()
    assert [os.path.normpath(p) for p in opened] == [os.path.normpath(report)]
    ws = Workspace.open(aligned_ws)  # a report written elsewhere (Accuracy report's OUTPUT_HTML) is found too
    elsewhere = str(tmp_path / "site-report.html")
    open(elsewhere, "w").close()
    ws.data["stages"]["report"] = {"status": "done", "outputs": {"report": elsewhere}}
    assert os.path.normpath(report_of(ws)) == os.path.normpath(elsewhere)


def test_the_dock_shows_only_the_workspace_open(dock, georef_ws, aligned_ws, monkeypatch):
    """State belongs to the workspace shown (issue 48 item 4): another workspace opened shows its own residual
    tolerance (the previous one's 3 x GSD stayed, labelled 'default'), none of the previous photo; 'New from
    photos' shows the workspace being made while it aligns: not the previous one's name, table or 'Cancelled'."""
    from archaeoortho.core.align import stage as align_stage
    from archaeoortho.core.common.progress import Cancelled
    from archaeoortho.ui.gcp_dock import DEFAULT_TOLERANCE

    assert dock.open_workspace(georef_ws)
    gsd_default = dock.tol_spin.value()
    assert abs(gsd_default - DEFAULT_TOLERANCE) > 1e-3 and "GSD" in dock.tol_source.text()  # 3 x GSD
    assert dock.photo_panel.image is not None  # the first point's photo
    assert dock.open_workspace(aligned_ws)  # not georeferenced, no setting: the default, not the previous value
    assert dock.tol_spin.value() == DEFAULT_TOLERANCE and dock.tol_source.text() == "(default)"
    assert dock.photo_panel.image is None and dock.photo_panel.view.pyramid_item is None
    dock.store.save_settings(tolerance=0.25)  # the workspace's own setting comes back with it
    assert dock.open_workspace(georef_ws) and dock.tol_spin.value() == gsd_default
    assert dock.open_workspace(aligned_ws) and dock.tol_spin.value() == 0.25

    def waiting_align(images_dir, workspace_dir, options=None, progress=None):
        while not progress.is_cancelled():
            time.sleep(0.02)
        raise Cancelled("cancelled")

    monkeypatch.setattr(align_stage, "align", waiting_align)
    assert dock.open_workspace(georef_ws) and dock.model.rowCount() > 0
    dock.message("Cancelled")  # a cancelled run's message
    new_ws = os.path.join(os.path.dirname(aligned_ws), "new-site")
    assert dock.start_alignment(os.path.dirname(dock.store.images()[0]["path"]), new_ws) is not None
    try:
        process(100)
        assert dock.store.workspace is None and dock.model.rowCount() == 0
        assert dock.ws_label.text().startswith("new-site") and "Cancelled" not in dock.status.text()
        assert os.path.basename(os.path.normpath(georef_ws)) not in dock.ws_label.text()
    finally:
        dock.cancel_task()
        wait_task(dock, 30)
    assert "Cancelled" in dock.status.text()


def test_automatic_gcps_are_shown_as_found_not_as_predictions_to_place(dock, georef_ws, block, tmp_path):
    """After automatic control the photo view showed 'auto_001 (predicted)' in a photo where it was not measured
    (issue 48 item 11): an automatic GCP is shown where the automatic control measured it, labelled automatic,
    and no prediction is offered to place it by hand."""
    ws = shutil.copytree(georef_ws, str(tmp_path / "auto"))
    path = os.path.join(ws, "georef", "control.json")
    data = json.load(open(path))
    auto = data["points"][0]  # a control point measured in two photos only: the others would be predictions
    auto["name"] = "auto_001"
    auto["observations"] = auto["observations"][-2:]
    with open(path, "w") as f:
        json.dump(data, f)
    candidates = [{"name": "auto_001", "status": "kept"}, {"name": "auto_002", "status": "too few photos"}]
    with open(os.path.join(ws, "georef", "autocontrol.json"), "w") as f:
        json.dump({"format": "archaeoortho-autocontrol", "candidates": candidates}, f)
    assert dock.open_workspace(ws)
    assert dock.store.automatic == {"auto_001"}
    assert dock.select_point("auto_001")
    measured = {o["image"]: (o["x"], o["y"]) for o in auto["observations"]}
    panel = dock.photo_panel
    assert panel.image in measured, panel.image
    assert dock.predictions == {} and panel.prediction is None and dock.next_photo() is None
    assert panel.observation is not None and panel.observation.label == "auto_001 (automatic)"
    assert "automatic GCP" in panel.hint.text() and "not a prediction" in panel.hint.text()
    assert not panel.btn_confirm.isEnabled()
    # an ordinary point is still predicted in the photos where it is not placed yet
    other = dock.store.gcps.points[1].name
    assert dock.select_point(other) and dock.predictions
