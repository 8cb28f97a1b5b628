"""The automatic control's faces (issue 16 item 1): a reference orthophoto served as a web layer (XYZ tiles) saved
for the block's extent, Georeference's automatic-control mode headless, the dock's automatic control.

The block and the reference are tests/test_autocontrol.py's (epoch 2 photos against epoch 1's true orthophoto and
DSM, cached under build/test-cache); the XYZ tiles are written here from that orthophoto (Web Mercator, zoom 20,
a file:// URL template): the layer goes through QGIS's XYZ provider and a QgsRasterPipe exactly as a web layer
does, offline.
"""
import json
import os
import subprocess

import numpy as np
import pytest

from tests import synthetic as syn
from tests.test_autocontrol import BLOCK, CACHE, write_reference
from tests.test_ui_dock import dock, process, wait_task  # noqa: F401 (fixtures and helpers of the dock tests)
from tests.workspaces import set_exif_gps, synthetic_workspace, write_flat_reference

pytestmark = pytest.mark.usefixtures("qgis_app")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCREENSHOT = os.path.join(ROOT, "docs", "screenshots", "dock-autocontrol.png")
ZOOM = 20
R = 20037508.342789244  # Web Mercator's half width
GSD = 0.25  # the saved reference's resolution (the default for web layers)
NAMES = ["S1_01.jpg", "S1_02.jpg", "S1_03.jpg", "S2_01.jpg", "S2_02.jpg", "S2_03.jpg"]


@pytest.fixture(scope="module")
def epochs():
    """(epoch-2 block, its photos, reference orthophoto, reference DSM): tests/test_autocontrol.py's cache."""
    block = syn.vertical_block(epoch=2, **BLOCK)
    photos_dir = os.path.join(CACHE, "photos")
    done = os.path.join(CACHE, "done")
    if not os.path.isfile(done):
        os.makedirs(CACHE, exist_ok=True)
        block.render(photos_dir)
        write_reference(syn.vertical_block(epoch=1, **BLOCK).scene, CACHE)
        open(done, "w").close()
    photos = {n: os.path.join(photos_dir, n) for n in block.names}
    return block, photos, os.path.join(CACHE, "ref_ortho.tif"), os.path.join(CACHE, "ref_dsm.tif")


def write_xyz_tiles(src, folder, zoom=ZOOM):
    """XYZ tiles {zoom}/{x}/{y}.png of the raster ``src`` (Web Mercator, 256 px); returns the layer URI."""
    from osgeo import gdal

    ds = gdal.Open(src)
    merc = gdal.Warp("", ds, format="MEM", dstSRS="EPSG:3857")
    gt = merc.GetGeoTransform()
    x0, x1 = gt[0], gt[0] + merc.RasterXSize * gt[1]
    y0, y1 = gt[3] + merc.RasterYSize * gt[5], gt[3]
    size = 2 * R / 2 ** zoom
    for tx in range(int((x0 + R) // size), int((x1 + R) // size) + 1):
        for ty in range(int((R - y1) // size), int((R - y0) // size) + 1):
            box = (-R + tx * size, R - (ty + 1) * size, -R + (tx + 1) * size, R - ty * size)
            tile = gdal.Warp("", ds, format="MEM", dstSRS="EPSG:3857", outputBounds=box, width=256, height=256,
                             dstAlpha=True, outputType=gdal.GDT_Byte)
            os.makedirs(os.path.join(folder, str(zoom), str(tx)), exist_ok=True)
            gdal.Translate(os.path.join(folder, str(zoom), str(tx), f"{ty}.png"), tile, format="PNG")
    return f"type=xyz&url=file://{folder}/{{z}}/{{x}}/{{y}}.png&zmin={zoom}&zmax={zoom}"


@pytest.fixture(scope="module")
def xyz_uri(epochs, tmp_path_factory):
    return write_xyz_tiles(epochs[2], str(tmp_path_factory.mktemp("xyz")))


def xyz_layer(uri, name="synthetic XYZ orthophoto"):
    from qgis.core import QgsRasterLayer

    layer = QgsRasterLayer(uri, name, "wms")
    assert layer.isValid() and layer.crs().authid() == "EPSG:3857" and layer.providerType() == "wms"
    return layer


class Recorder:
    """The core Progress protocol, recording; ``cancel_at``: is_cancelled() from that report on."""

    def __init__(self, cancel_at=None):
        self.fractions, self.infos, self.warnings = [], [], []
        self.cancel_at = cancel_at

    def report(self, fraction, message=""):
        self.fractions.append(fraction)

    def is_cancelled(self):
        return self.cancel_at is not None and len(self.fractions) >= self.cancel_at

    def info(self, message):
        self.infos.append(message)

    def warning(self, message):
        self.warnings.append(message)


def _warped(src, gt, shape):
    from osgeo import gdal

    w, h = shape[1], shape[0]
    out = gdal.Warp("", gdal.Open(src), format="MEM", outputBounds=(gt[0], gt[3] + h * gt[5], gt[0] + w * gt[1],
                                                                     gt[3]), width=w, height=h, resampleAlg="average")
    return out.GetRasterBand(1).ReadAsArray().astype(np.float32)


def test_an_xyz_layer_is_saved_for_the_requested_extent(epochs, xyz_uri, tmp_path):
    import cv2
    from archaeoortho.qgisio.reference_layers import save_layer
    from osgeo import gdal, osr
    from qgis.core import QgsCoordinateReferenceSystem, QgsRectangle

    layer = xyz_layer(xyz_uri)
    utm = QgsCoordinateReferenceSystem(syn.CRS)
    x0, y0 = syn.ORIGIN[0], syn.ORIGIN[1]
    asked = QgsRectangle(x0 - 40.0, y0 - 30.0, x0 + 45.0, y0 + 30.0)  # on the 0.25 m grid
    progress = Recorder()
    path, grid, res = save_layer(layer, str(tmp_path / "ref.tif"), asked, utm, GSD, progress=progress)
    assert res == GSD and grid == asked
    ds = gdal.Open(path)
    assert ds.GetGeoTransform() == pytest.approx((x0 - 40.0, GSD, 0.0, y0 + 30.0, 0.0, -GSD))
    assert (ds.RasterXSize, ds.RasterYSize) == (340, 240)
    srs = osr.SpatialReference(wkt=ds.GetProjection())
    srs.AutoIdentifyEPSG()
    assert srs.GetAuthorityCode(None) == syn.CRS.split(":")[1]
    assert ds.RasterCount == 4 and (ds.GetRasterBand(4).ReadAsArray() > 0).all()  # RGBA, all of it has data
    grey = ds.GetRasterBand(1).ReadAsArray().astype(np.float32)
    truth = _warped(epochs[2], ds.GetGeoTransform(), grey.shape)
    assert np.corrcoef(grey.ravel(), truth.ravel())[0, 1] > 0.9
    (dx, dy), _ = cv2.phaseCorrelate(truth.astype(np.float64), grey.astype(np.float64))
    assert abs(dx) < 0.3 and abs(dy) < 0.3  # pixels: where the tiles say, after two resamplings
    assert progress.fractions and max(progress.fractions) == pytest.approx(1.0)
    assert any("EPSG:32633" in m for m in progress.infos)


def test_a_failed_fetch_a_cancel_and_the_pixel_cap(epochs, xyz_uri, tmp_path, monkeypatch):
    from archaeoortho.core.common.progress import Cancelled
    from archaeoortho.qgisio import reference_layers as refs
    from qgis.core import QgsCoordinateReferenceSystem, QgsRectangle

    utm = QgsCoordinateReferenceSystem(syn.CRS)
    x0, y0 = syn.ORIGIN[0], syn.ORIGIN[1]
    asked = QgsRectangle(x0 - 40.0, y0 - 30.0, x0 + 40.0, y0 + 30.0)
    nowhere = xyz_layer(f"type=xyz&url=file://{tmp_path}/none/{{z}}/{{x}}/{{y}}.png&zmin=20&zmax=20", "empty tiles")
    with pytest.raises(refs.ReferenceLayerError, match=r"'empty tiles'.*returned no data over 499960\.00,"):
        refs.save_layer(nowhere, str(tmp_path / "a.tif"), asked, utm, GSD)
    assert not (tmp_path / "a.tif").exists() and not (tmp_path / "a.tif.part.tif").exists()
    with pytest.raises(Cancelled):
        refs.save_layer(xyz_layer(xyz_uri), str(tmp_path / "b.tif"), asked, utm, 0.05, progress=Recorder(1))
    assert not (tmp_path / "b.tif").exists()
    with pytest.raises(refs.ReferenceLayerError, match="rendered image"):
        refs.save_layer(xyz_layer(xyz_uri), str(tmp_path / "c.tif"), asked, utm, GSD, what="DSM")
    monkeypatch.setattr(refs, "MAX_PIXELS", 10_000)
    progress = Recorder()
    _, grid, res = refs.save_layer(xyz_layer(xyz_uri), str(tmp_path / "d.tif"), asked, utm, GSD, progress=progress)
    assert res == pytest.approx(np.sqrt(80.0 * 60.0 / 10_000)) and progress.warnings
    assert grid.contains(asked)


def _gps_workspace(root, block, photos, sigma=3.0):
    """An aligned workspace of six of the ten photos (two strips of three: the run costs half), their EXIF GPS
    ``sigma`` metres off."""
    photos = {n: photos[n] for n in NAMES}
    rec = block.truth_reconstruction(seed=5, n_points=600, images=NAMES)
    ws = synthetic_workspace(str(root), block, rec, photos=photos)
    return set_exif_gps(ws, block.camera_positions(sigma=sigma, images=NAMES)[0], syn.CRS)


def test_the_extent_comes_from_the_photos_gps(epochs, xyz_uri, tmp_path):
    """A web orthophoto beside a DSM file: saved in the DSM's CRS (not Web Mercator) over the photos' GPS box plus
    the margin; the DSM file is used as it is."""
    from archaeoortho.core.project.layout import Layout
    from archaeoortho.core.project.workspace import Workspace
    from archaeoortho.qgisio import reference_layers as refs
    from osgeo import gdal
    from qgis.core import QgsRasterLayer

    block, photos, _, dsm = epochs
    ws = _gps_workspace(tmp_path / "ws", block, photos)
    dsm_layer = QgsRasterLayer(dsm, "dsm", "gdal")
    ortho, dsm_path = refs.resolve_references(xyz_layer(xyz_uri), dsm_layer, ws)
    assert dsm_path == dsm and ortho == Layout(Workspace.open(ws)).reference_ortho_tif
    ds = gdal.Open(ortho)
    gt = ds.GetGeoTransform()
    cams = np.array([[c.x, c.y] for c in block.camera_positions(sigma=3.0, images=NAMES)[0]])
    lo, hi = cams.min(axis=0), cams.max(axis=0)
    m = max(refs.MIN_MARGIN, 0.5 * float((hi - lo).max()))
    assert gt[1] == GSD and "32633" in ds.GetProjection()
    assert gt[0] == pytest.approx(lo[0] - m, abs=GSD + 0.05) and gt[3] == pytest.approx(hi[1] + m, abs=GSD + 0.05)
    assert gt[0] + ds.RasterXSize * gt[1] == pytest.approx(hi[0] + m, abs=GSD + 0.05)
    assert gt[3] + ds.RasterYSize * gt[5] == pytest.approx(lo[1] - m, abs=GSD + 0.05)


def test_georeference_needs_both_references(epochs, xyz_uri, tmp_path):
    """One reference layer alone is refused, naming the missing one (before any work)."""
    from archaeoortho.processing_provider.georeference import GeoreferenceAlgorithm
    from qgis.core import QgsProcessingContext, QgsProcessingException, QgsProcessingFeedback, QgsProject

    block, photos, _, _ = epochs
    ws = _gps_workspace(tmp_path / "ws", block, photos)
    alg = GeoreferenceAlgorithm()
    alg.initAlgorithm()
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    with pytest.raises(QgsProcessingException, match="REFERENCE_DSM"):
        alg.processAlgorithm({"WORKSPACE": ws, "REFERENCE_ORTHO": xyz_layer(xyz_uri)}, context,
                             QgsProcessingFeedback())
    assert not os.path.exists(os.path.join(ws, "georef", "reference-ortho.tif"))


def test_georeference_with_a_reference_checks_camera_positions_as_without(tmp_path):
    """Georeference's automatic-control mode reads the camera positions through the georeference stage's checks
    (issue 47 item 2, issue 49: one place reads and checks control): a file with the latitude in the x column is
    refused before the matching, with the message Georeference gives without a reference."""
    from archaeoortho.core.geometry.crs import transform_points
    from archaeoortho.processing_provider.georeference import GeoreferenceAlgorithm
    from qgis.core import (
        QgsProcessingContext,
        QgsProcessingException,
        QgsProcessingFeedback,
        QgsProject,
        QgsRasterLayer,
    )

    block = syn.vertical_block(seed=1)
    ws = synthetic_workspace(str(tmp_path / "ws"), block, block.truth_reconstruction())
    cams, _ = block.camera_positions(sigma=0.5)
    set_exif_gps(ws, cams, syn.CRS)
    lonlat = transform_points(np.array([[c.x, c.y, c.z] for c in cams]), syn.CRS, "EPSG:4326")
    positions = tmp_path / "latlon.csv"
    positions.write_text("EPSG:4326\nimage,x,y,z\n" + "".join(
        f"{c.image},{p[1]:.8f},{p[0]:.8f},{c.z:.3f}\n" for c, p in zip(cams, lonlat)))
    ortho, dsm = write_flat_reference(tmp_path / "ref", cams, syn.CRS)
    alg = GeoreferenceAlgorithm()
    alg.initAlgorithm()
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())

    def refused(**more):
        with pytest.raises(QgsProcessingException) as e:
            alg.processAlgorithm({"WORKSPACE": ws, "CAMERA_POSITIONS": str(positions), **more}, context,
                                 QgsProcessingFeedback())
        return str(e.value)

    plain = refused()
    assert "latitude and longitude look swapped" in plain
    assert refused(REFERENCE_ORTHO=QgsRasterLayer(ortho, "ortho", "gdal"),
                   REFERENCE_DSM=QgsRasterLayer(dsm, "dsm", "gdal")) == plain
    assert not os.path.exists(os.path.join(ws, "georef", "autocontrol-failed.json"))  # before the matching


def test_qgis_process_georeference_with_a_web_reference(epochs, xyz_uri, tmp_path):
    """archaeoortho:georeference headless with REFERENCE_ORTHO an XYZ layer of a project (and REFERENCE_DSM a
    file): the automatic control georeferences the block; the GCP file's ground marks are its check points."""
    from archaeoortho.core.io.gcp import write_gcps
    from qgis.core import QgsProject

    from tests.conftest import qgis_process

    exe, env = qgis_process()
    block, photos, _, dsm = epochs
    ws = _gps_workspace(tmp_path / "ws", block, photos)
    marks = block.gcp_set([], noise_px=0.3, only=[p.name for p in block.gcps if p.kind == "ground"], images=NAMES)
    marks.points = [p for p in marks.points if len(p.observations) >= 2]
    gcp_file = str(tmp_path / "gcp_list.txt")
    write_gcps(marks, gcp_file)
    project = QgsProject()
    layer = xyz_layer(xyz_uri, "web orthophoto")
    assert project.addMapLayer(layer) is not None
    assert project.write(str(tmp_path / "web.qgs"))

    def run(*args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:georeference", f"--PROJECT_PATH={tmp_path}/web.qgs",
                               "--", f"WORKSPACE={ws}", *args], env=env, capture_output=True, text=True, timeout=600)

    out = run(f"REFERENCE_ORTHO={layer.id()}", f"REFERENCE_DSM={dsm}", f"GCPS={gcp_file}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    res = json.loads(out.stdout)["results"]
    print(f"\nGeoreference, automatic control against XYZ tiles: {res}")
    assert res["AUTO_GCPS"] >= 10
    assert res["CHECK_RMSE_XY"] <= 1.5 * GSD and res["CHECK_RMSE_Z"] <= 2.0 * GSD
    control = json.load(open(os.path.join(ws, "georef", "control.json")))
    roles = {p["name"]: p["role"] for p in control["points"]}
    assert all(roles[p.name] == "check" for p in marks.points)  # the user's points checked, not used
    assert sum(1 for n in roles if n.startswith("auto_")) >= res["AUTO_GCPS"]
    assert os.path.isfile(os.path.join(ws, "georef", "reference-ortho.tif"))
    # the photos' EXIF GPS (3 m per axis) only fixed the search area: USE_EXIF_GPS was not given, so no camera
    # position is in the adjustment and none is reported
    assert res["CAMERA_RMSE_XY"] is None and res["CAMERA_RMSE_XYZ"] is None


def test_dock_automatic_control(dock, epochs, xyz_uri, tmp_path):  # noqa: F811 (the dock fixture)
    """The dock's georeference panel in its automatic-control mode: the XYZ layer and the DSM picked from the
    project, the task runs (the GUI stays responsive), the automatic GCPs fill the table and the map."""
    from qgis.core import QgsProject, QgsRasterLayer

    block, photos, _, dsm = epochs
    ws = _gps_workspace(tmp_path / "ws", block, photos)
    assert dock.open_workspace(ws)
    ortho_layer = xyz_layer(xyz_uri, "web orthophoto")
    dsm_layer = QgsRasterLayer(dsm, "reference DSM", "gdal")
    assert len(QgsProject.instance().addMapLayers([ortho_layer, dsm_layer])) == 2
    dock.auto_box.setChecked(True)
    assert dock.auto_ortho_combo.isVisible()
    assert dock.run_autocontrol() is None and "reference orthophoto" in dock.status.text()  # nothing chosen yet
    dock.auto_ortho_combo.setLayer(ortho_layer)
    dock.auto_dsm_combo.setLayer(dsm_layer)
    dock.btn_georef.click()
    assert dock.task is not None and not dock.btn_georef.isEnabled()
    # the user removes the reference layers while the task runs: the worker reads snapshots the dock took on the
    # GUI thread, never the project's layers (which the canvas renders, and which are gone now)
    QgsProject.instance().removeMapLayers([ortho_layer.id(), dsm_layer.id()])
    wait_task(dock, 1200)  # about a minute on 2 idle cores; much longer under a benchmark's load
    assert dock.last_task_error is None, dock.last_task_error
    result = dock.auto_result
    assert result is not None and result.n_kept >= 10
    assert "Automatic control:" in dock.status.text()
    names = [p.name for p in dock.store.gcps.points]
    assert sum(1 for n in names if n.startswith("auto_")) >= result.n_kept
    names_on_map = [lyr.name() for lyr in QgsProject.instance().mapLayers().values()]
    assert "Automatic GCPs (residuals)" in names_on_map
    assert dock.store.figures.get("GCP_N", 0) >= 10
    os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
    dock.resize(760, 800)  # a few more rows of the table
    process(100)
    dock.grab().save(SCREENSHOT)
    assert os.path.getsize(SCREENSHOT) > 10_000
