"""Results as styled layers: the Processing post-processing hook (toolbox runs load outputs styled), the
style functions (DSM pseudocolour + hillshade, orthomosaic, cameras + footprints, residual vectors), and
nothing of it under qgis_process."""
import os
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import PLUGINS
from tests.test_ui_dock import SCREENSHOTS, make_workspace, quick_photos

pytestmark = pytest.mark.usefixtures("qgis_processing")


@pytest.fixture(scope="module")
def plugin(qgis_iface, qgis_processing):
    import archaeoortho

    from tests.conftest import _real_layer_tree_view

    _real_layer_tree_view(qgis_iface)  # QGIS 3.44's result loading hands it to C++
    p = archaeoortho.classFactory(qgis_iface)
    p.initProcessing()
    p.initGui()
    yield p
    p.unload()


@pytest.fixture(scope="module")
def block():
    from tests import synthetic as syn

    return syn.vertical_block(seed=1)


@pytest.fixture(scope="module")
def photos(block, tmp_path_factory):
    return quick_photos(block, str(tmp_path_factory.mktemp("layers") / "photos"))


@pytest.fixture
def aligned(block, photos, tmp_path):
    from archaeoortho.core.io.gcp import write_odm_gcp_list

    root = tmp_path
    ws = make_workspace(str(root), block, photos)
    gcp_file = str(root / "gcp_list.txt")
    write_odm_gcp_list(block.gcp_set(block.spread_control(5), noise_px=0.4), gcp_file)
    return ws, gcp_file


def _raster(path, bands, nodata=None, alpha=False):
    from osgeo import gdal, osr

    n = 64
    ds = gdal.GetDriverByName("GTiff").Create(path, n, n, bands, gdal.GDT_Float32 if bands == 1 else gdal.GDT_Byte)
    ds.SetGeoTransform((500000.0, 0.5, 0, 4600000.0, 0, -0.5))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    yy, xx = np.mgrid[0:n, 0:n]
    for b in range(1, bands + 1):
        if bands == 1:
            data = 150 + 5 * np.sin(xx / 9.0) * np.cos(yy / 7.0)
            data[:4, :4] = -9999
        else:
            data = (40 * b + 2 * xx) % 255
            if alpha and b == bands:
                data = np.where(xx < 8, 0, 255)
        ds.GetRasterBand(b).WriteArray(data)
        if nodata is not None:
            ds.GetRasterBand(b).SetNoDataValue(nodata)
    if alpha:
        ds.GetRasterBand(bands).SetColorInterpretation(gdal.GCI_AlphaBand)
    ds = None
    return path


def test_georeference_from_the_toolbox_loads_styled_layers(plugin, aligned, qgis_new_project):
    """processing.runAndLoadResults runs the same loading as the toolbox dialog: residuals and cameras come
    in styled, with the camera footprints."""
    from processing import runAndLoadResults
    from qgis.core import QgsCategorizedSymbolRenderer, QgsProject

    ws, gcp_file = aligned
    res = runAndLoadResults("archaeoortho:georeference", {"WORKSPACE": ws, "GCPS": gcp_file})
    assert res and os.path.isfile(res["RESIDUALS"])
    layers = {lyr.customProperty("archaeoortho/kind"): lyr for lyr in QgsProject.instance().mapLayers().values()}
    assert {"residuals", "cameras", "footprints"} <= set(layers)
    residuals = layers["residuals"]
    assert isinstance(residuals.renderer(), QgsCategorizedSymbolRenderer)
    assert residuals.renderer().classAttribute() == "status"
    assert residuals.labelsEnabled()
    assert float(residuals.customProperty("archaeoortho/exaggeration")) >= 1.0
    assert "x" in residuals.name()
    cams = layers["cameras"]
    assert cams.labelsEnabled() and cams.labeling().settings().fieldName == '"image"'
    # labels sit over the points on every QGIS version (3.26+ take Qgis.LabelPlacement: the old
    # QgsPalLayerSettings.OverPoint there is another enum and raised TypeError, leaving the layers unstyled)
    from qgis.core import Qgis, QgsPalLayerSettings

    over_point = getattr(getattr(Qgis, "LabelPlacement", None), "OverPoint", None)
    if over_point is None:
        over_point = QgsPalLayerSettings.OverPoint
    for layer in (cams, residuals):
        assert layer.labeling().settings().placement == over_point, layer.name()
    assert layers["footprints"].featureCount() == cams.featureCount()
    site = os.path.basename(os.path.normpath(ws))  # named after their workspace (issue 36 item 17)
    assert cams.name() == f"Cameras \u2014 {site}" and residuals.name().endswith(f" \u2014 {site}")
    assert layers["footprints"].name() == f"Camera footprints \u2014 {site}"
    _render(QgsProject.instance(), [residuals, cams, layers["footprints"]], "toolbox-georeference-layers.png")


def test_footprints_not_written_say_why(plugin, aligned, monkeypatch):
    """No footprints before the georeference, silently (nothing to draw yet); a failure to write them after it
    is said in the message log with the reason (it used to be swallowed), and the loading goes on (None)."""
    from archaeoortho.core.georef.options import GeorefOptions
    from archaeoortho.core.georef.stage import georeference_workspace
    from archaeoortho.core.project.layout import Layout
    from archaeoortho.core.project.workspace import Workspace
    from archaeoortho.qgisio import layers
    from qgis.core import QgsApplication

    ws, gcp_file = aligned
    logged = []

    def on_message(text, tag, level):
        if tag == "ArchaeoOrtho":
            logged.append(text)

    log = QgsApplication.messageLog()
    log.messageReceived.connect(on_message)
    try:
        assert layers.footprints_path(ws) is None and not logged  # not georeferenced yet
        georeference_workspace(ws, GeorefOptions(gcp_path=gcp_file))
        path = Layout(Workspace.open(ws)).footprints_gpkg
        assert layers.footprints_path(ws) == path and os.path.isfile(path)
        from archaeoortho.core.georef import guided

        def disk_full(path, *args, **kwargs):
            raise OSError(28, "No space left on device", path)

        monkeypatch.setattr(guided, "write_footprints_gpkg", disk_full)
        assert layers.footprints_path(ws) is None
    finally:
        log.messageReceived.disconnect(on_message)
    assert any("footprints" in m and "not written" in m and "No space left" in m for m in logged), logged


def test_hook_registers_only_our_outputs(plugin, aligned):
    from qgis.core import QgsApplication, QgsProcessingContext, QgsProcessingFeedback, QgsProject

    ws, _ = aligned
    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:georeference")
    ctx = QgsProcessingContext()
    ctx.setProject(QgsProject.instance())
    n = alg.register_styled_outputs({"WORKSPACE": ws, "CAMERAS": os.path.join(ws, "cameras.gpkg"),
                                     "GCP_RMSE_XY": 0.1}, ctx, QgsProcessingFeedback())
    # the aligned workspace's cameras have no CRS (model frame): not loaded onto a map
    assert n == 0 and not ctx.layersToLoadOnCompletion()
    ctx.setProject(None)
    assert alg.register_styled_outputs({"CAMERAS": os.path.join(ws, "cameras.gpkg")}, ctx) == 0


def test_dsm_pseudocolour_and_hillshade(tmp_path, qgis_new_project):
    from archaeoortho.qgisio import layers
    from qgis.core import QgsProject

    path = _raster(str(tmp_path / "dsm.tif"), 1, nodata=-9999)
    loaded = layers.load_dsm(path, QgsProject.instance(), "DSM group")
    assert [lyr.renderer().type() for lyr in loaded] == ["singlebandpseudocolor", "hillshade"]
    lo, hi = loaded[0].renderer().classificationMin(), loaded[0].renderer().classificationMax()
    assert 144 < lo < hi < 156  # stretched on the data, nodata left out
    assert loaded[1].blendMode() != 0
    # loading again replaces instead of stacking duplicates
    loaded = layers.load_dsm(path, QgsProject.instance(), "DSM group")
    assert len(QgsProject.instance().mapLayers()) == 2
    assert layers.output_kind("OUTPUT_DSM", path) == layers.DSM
    _render(QgsProject.instance(), list(reversed(loaded)), "dsm-styled.png")


def test_a_failing_style_step_is_logged_and_reported_not_raised(tmp_path, qgis_new_project, monkeypatch):
    """QGIS calls postProcessLayer from C++: an exception escaping it would abort QGIS.  A styling bug is
    caught, logged with its traceback and reported to the run's feedback; the layer stays loaded."""
    from archaeoortho.qgisio import layers
    from qgis.core import QgsApplication, QgsProcessingContext, QgsProcessingFeedback, QgsProject, QgsRasterLayer

    path = _raster(str(tmp_path / "o.tif"), 3, nodata=0)
    layer = QgsRasterLayer(path, "orthomosaic")
    assert layer.isValid()
    assert QgsProject.instance().addMapLayer(layer) is not None

    def broken(_layer):
        raise ZeroDivisionError("a bug in a style function")

    monkeypatch.setattr(layers, "style_orthomosaic", broken)
    logged = []

    def on_message(message, tag, level):
        logged.append((tag, message))

    QgsApplication.messageLog().messageReceived.connect(on_message)

    class Feedback(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.errors = []

        def reportError(self, error, fatal=False):  # noqa: N802 (QGIS API name)
            self.errors.append(error)

    feedback = Feedback()
    ctx = QgsProcessingContext()
    ctx.setProject(QgsProject.instance())
    try:
        layers.StylePostProcessor(layers.ORTHO).postProcessLayer(layer, ctx, feedback)  # must not raise
    finally:
        QgsApplication.messageLog().messageReceived.disconnect(on_message)
    assert feedback.errors and "a bug in a style function" in feedback.errors[0]
    assert "orthomosaic" in feedback.errors[0]
    assert any(tag == "ArchaeoOrtho" and "Traceback" in m and "ZeroDivisionError" in m for tag, m in logged)
    assert layer.id() in QgsProject.instance().mapLayers()


def test_orthomosaic_rgb_with_transparent_alpha_or_nodata(tmp_path, qgis_new_project):
    from archaeoortho.qgisio import layers
    from qgis.core import QgsProject

    with_alpha = layers.load_orthomosaic(_raster(str(tmp_path / "a.tif"), 4, alpha=True), QgsProject.instance())[0]
    assert with_alpha.renderer().type() == "multibandcolor"
    assert with_alpha.renderer().alphaBand() == 4
    rgb = layers.load_orthomosaic(_raster(str(tmp_path / "b.tif"), 3, nodata=0), QgsProject.instance())[0]
    assert rgb.renderer().type() == "multibandcolor"
    assert rgb.dataProvider().useSourceNoDataValue(1)
    assert layers.output_kind("ORTHOMOSAIC", "x.tif") == layers.ORTHO
    assert layers.output_kind("OUTPUT_POINT_CLOUD", "x.las") == layers.POINT_CLOUD
    assert layers.output_kind("VALID_FRACTION", "") is None


def _products(folder):
    """A workspace folder with a DSM, an orthomosaic (RGBA) and a DTM where its Layout puts them."""
    from archaeoortho.qgisio import layers

    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "workspace.json"), "w", encoding="utf-8") as fh:
        fh.writelines(["{}"])
    lay = layers.workspace_layout(folder)
    for path, bands in ((lay.default_dsm, 1), (lay.default_orthomosaic, 4), (lay.default_dtm, 1)):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        _raster(path, bands, nodata=-9999 if bands == 1 else None, alpha=bands == 4)
    return folder


def _rendered(layer_list, extent):
    """The layers (first on top) drawn over white, 200 x 200 px, as an (n, n, 3) array."""
    from qgis.core import QgsMapRendererSequentialJob, QgsMapSettings
    from qgis.PyQt.QtCore import QSize
    from qgis.PyQt.QtGui import QColor

    settings = QgsMapSettings()
    settings.setLayers(layer_list)
    settings.setExtent(extent)
    settings.setDestinationCrs(layer_list[0].crs())
    settings.setOutputSize(QSize(200, 200))
    settings.setBackgroundColor(QColor("white"))
    job = QgsMapRendererSequentialJob(settings)
    job.start()
    job.waitForFinished()
    image = job.renderedImage()
    return np.array([[QColor(image.pixel(x, y)).getRgb()[:3] for x in range(200)] for y in range(200)], float)


def test_orthomosaic_reads_true_over_the_terrain_layers(tmp_path, qgis_new_project):
    """A workspace's group: points over the orthomosaic, the orthomosaic over the DTM and DSM and their hillshades
    (the DTM's multiplied hillshade, loaded last, lay over the orthomosaic and darkened it by ~19 %: issue 36 item
    16).  The group as drawn shows the orthomosaic's own colours."""
    from archaeoortho.qgisio import layers
    from qgis.core import QgsProject

    ws = _products(str(tmp_path / "site"))
    loaded = layers.load_workspace_results(ws, QgsProject.instance())
    by_kind = {lyr.customProperty(layers.KIND_PROPERTY): lyr for lyr in loaded}
    assert {"dsm", "hillshade", "ortho", "dtm", "dtmhillshade"} <= set(by_kind)
    root = QgsProject.instance().layerTreeRoot()
    group = root.findGroup(layers.workspace_group_name(ws))
    order = [c.layer().customProperty(layers.KIND_PROPERTY) for c in group.children()]
    assert order == ["ortho", "dtmhillshade", "dtm", "hillshade", "dsm"], order
    ortho = by_kind["ortho"]
    extent = ortho.extent()
    extent.scale(0.8)  # inside the mosaic, its transparent left edge included
    alone = _rendered([ortho], extent)
    drawn = _rendered(root.checkedLayers(), extent)  # as the canvas draws the project, top first
    valid = alone.sum(axis=2) < 3 * 255  # where the mosaic covers the white background
    assert valid.mean() > 0.5
    change = np.abs(drawn[valid] - alone[valid]).mean() / alone[valid].mean()
    print(f"\n[layers] the orthomosaic as the group draws it differs from it alone by {100 * change:.1f} %")
    assert change < 0.01


def test_layers_named_after_their_workspace(tmp_path, qgis_new_project):
    """Two workspaces loaded: their DSMs and orthomosaics are told apart by name in a raster layer box (the dock's
    reference boxes listed 'DSM' and 'DSM': issue 36 item 17)."""
    from archaeoortho.qgisio import layers
    from qgis.core import QgsMapLayerProxyModel, QgsProject
    from qgis.gui import QgsMapLayerComboBox

    for name in ("toledo", "ochota"):
        layers.load_workspace_results(_products(str(tmp_path / name)), QgsProject.instance())
    combo = QgsMapLayerComboBox()
    combo.setFilters(QgsMapLayerProxyModel.Filter.RasterLayer)
    names = [combo.itemText(i) for i in range(combo.count())]
    assert len(names) == len(set(names)) == 10, names
    assert {"DSM \u2014 toledo", "DSM \u2014 ochota", "Orthomosaic \u2014 toledo", "Orthomosaic \u2014 ochota",
            "DTM hillshade \u2014 ochota"} <= set(names), names
    outside = _raster(str(tmp_path / "loose.tif"), 4, alpha=True)  # a file of no workspace keeps the plain name
    assert [lyr.name() for lyr in layers.load_orthomosaic(outside, QgsProject.instance())] == ["Orthomosaic"]


def test_nothing_styled_under_qgis_process_platform():
    """With QGIS's platform reported as qgis_process the hook does nothing and imports no ui module."""
    code = (
        f"import sys; sys.path.insert(0, {PLUGINS!r});"
        "from qgis.core import QgsApplication; app = QgsApplication([], False); app.initQgis();"
        "QgsApplication.platform = staticmethod(lambda: 'qgis_process');"
        "import archaeoortho.processing_provider.georeference as g;"
        "from qgis.core import QgsProcessingContext, QgsProject;"
        "ctx = QgsProcessingContext(); ctx.setProject(QgsProject.instance());"
        "n = g.GeoreferenceAlgorithm().register_styled_outputs({'RESIDUALS': sys.executable}, ctx);"
        "bad = [m for m in sys.modules if m.startswith('archaeoortho.ui')];"
        "print(n, bad); import os; os._exit(1 if (n or bad) else 0)"
    )
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.slow
def test_qgis_process_runs_headless_with_the_dock_code_present(aligned, tmp_path):
    """qgis_process (no iface, platform qgis_process) runs Georeference; the hook stays out of the way."""
    import json

    from tests.conftest import qgis_process

    exe, env = qgis_process()
    ws, gcp_file = aligned
    out = subprocess.run([exe, "--json", "run", "archaeoortho:georeference", "--", f"WORKSPACE={ws}",
                          f"GCPS={gcp_file}"], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    result = json.loads(out.stdout)["results"]
    assert result["CHECK_RMSE_XY"] < 0.2
    assert "Outputs not styled" not in out.stdout + out.stderr


def _render(project, layer_list, name):
    """Render layers to build/screenshots/ui/<name> (to look at) and check something was drawn."""
    from qgis.core import QgsMapRendererSequentialJob, QgsMapSettings, QgsRectangle
    from qgis.PyQt.QtCore import QSize
    from qgis.PyQt.QtGui import QColor

    settings = QgsMapSettings()
    settings.setLayers(layer_list)
    ext = QgsRectangle(layer_list[0].extent())
    for lyr in layer_list[1:]:
        ext.combineExtentWith(lyr.extent())
    ext.scale(1.15)
    settings.setExtent(ext)
    settings.setDestinationCrs(layer_list[0].crs())
    settings.setOutputSize(QSize(900, 700))
    settings.setBackgroundColor(QColor("white"))
    job = QgsMapRendererSequentialJob(settings)
    job.start()
    job.waitForFinished()
    image = job.renderedImage()
    os.makedirs(SCREENSHOTS, exist_ok=True)
    image.save(os.path.join(SCREENSHOTS, name))
    colours = {image.pixel(x, y) for x in range(0, 900, 7) for y in range(0, 700, 7)}
    assert len(colours) > 5


def test_the_rgb_frames_mosaic_is_named_apart_from_the_bands(tmp_path, qgis_new_project):
    """Run pipeline's two mosaics of a rig (the bands' and the RGB frames', <stem>_rgb.tif) load under two names."""
    from archaeoortho.qgisio import layers

    assert layers._output_layer_name(layers.ORTHO, str(tmp_path / "orthomosaic_rgb.tif")) == "RGB orthomosaic"
    assert layers._output_layer_name(layers.ORTHO, str(tmp_path / "orthomosaic.tif")) == "Orthomosaic"
    assert layers._output_layer_name(layers.DSM, str(tmp_path / "dsm_rgb.tif")) == "DSM"


def test_find_targets_from_the_toolbox_loads_the_targets_layer(plugin, tmp_path, qgis_new_project, monkeypatch):
    """Find targets run as a Processing algorithm (runAndLoadResults: what the toolbox dialog does) loads its
    'Targets found (for review)' layer into the workspace's group, styled: the log said 'Loading resulting layers'
    and no layer came (issue 48 item 8).  The core call is replaced by one that writes the layer (cheap)."""
    from archaeoortho.core.georef.targets import stage
    from archaeoortho.core.georef.targets.results import FindTargetsResult, TargetStatus, write_products
    from processing import runAndLoadResults
    from qgis.core import QgsProject

    ws = tmp_path / "site"
    (ws / "georef" / "targets").mkdir(parents=True)
    targets_csv = tmp_path / "targets.csv"
    targets_csv.write_text("# crs: EPSG:32633\nname,x,y,z\nA,500010,4600010,100\nB,500030,4600020,101\n"
                           "C,500020,4600040,99\n")

    class _GS:
        crs = "EPSG:32633"

    def fake_find_targets(workspace, options, progress=None):
        out = os.path.join(workspace, "georef", "targets")
        result = FindTargetsResult("EPSG:32633", os.path.join(out, "gcp_list.txt"), os.path.join(out, "targets.gpkg"),
                                   os.path.join(out, "targets.json"),
                                   targets=[TargetStatus("A", 500010, 4600010, 100, True, 4, 0.01),
                                            TargetStatus("B", 500030, 4600020, 101, True, 3, 0.02),
                                            TargetStatus("C", 500020, 4600040, 99, False, 0, note="covered")])
        write_products(_GS(), result)
        return result

    monkeypatch.setattr(stage, "find_targets", fake_find_targets)
    res = runAndLoadResults("archaeoortho:findtargets", {"WORKSPACE": str(ws), "TARGETS": str(targets_csv)})
    assert res and os.path.isfile(res["MARKS"])
    loaded = [lyr for lyr in QgsProject.instance().mapLayers().values()
              if os.path.normpath(lyr.source().split("|")[0]) == os.path.normpath(res["MARKS"])]
    assert len(loaded) == 1, [lyr.name() for lyr in QgsProject.instance().mapLayers().values()]
    layer = loaded[0]
    assert layer.featureCount() == 3 and layer.labelsEnabled()
    assert layer.name() == "Targets found \u2014 site"
    node = QgsProject.instance().layerTreeRoot().findLayer(layer.id())
    assert node.parent().name() == "ArchaeoOrtho: site"
    _render(QgsProject.instance(), [layer], "toolbox-find-targets-layer.png")


def test_run_pipelines_workspace_opens_in_the_dock(plugin, aligned, qgis_new_project):
    """After Run pipeline from the Toolbox the dock said 'none open' (issue 48 item 4): the run's layers, loaded
    as the Toolbox dialog loads them (with our post-processor), make the dock open the run's workspace."""
    from qgis.core import QgsProcessingContext, QgsProcessingFeedback, QgsProject, QgsRasterLayer

    from tests.test_ui_dock import process

    ws, _ = aligned
    dock = plugin.show_dock(True)
    try:
        assert dock.store.workspace is None and dock.ws_label.text() == "none open"
        alg = plugin.provider.algorithm("runpipeline")
        dsm = _raster(os.path.join(ws, "dsm.tif"), 1, nodata=-9999)
        ctx = QgsProcessingContext()
        ctx.setProject(QgsProject.instance())
        feedback = QgsProcessingFeedback()
        assert alg.register_styled_outputs({"WORKSPACE": ws, "DSM": dsm}, ctx, feedback) == 1
        details = ctx.layerToLoadOnCompletionDetails(dsm)
        layer = QgsRasterLayer(dsm, details.name)
        assert QgsProject.instance().addMapLayer(layer) is not None
        details.postProcessor().postProcessLayer(layer, ctx, feedback)  # what the dialog does at the run's end
        for _ in range(200):
            process(50)
            if dock.store.workspace is not None and dock.__dict__.get("_open_task") is None:
                break
        assert dock.store.root is not None and os.path.normpath(dock.store.root) == os.path.normpath(ws)
        assert dock.ws_label.text() == os.path.basename(os.path.normpath(ws))
    finally:
        plugin.show_dock(False)


def test_a_workspace_group_offers_its_accuracy_report(plugin, aligned, qgis_new_project, qgis_iface, monkeypatch):
    """The workspace's layer group in the Layers panel has 'Open accuracy report' in its context menu (issue 48
    item 5), opening the report the dock's Report button opens; disabled while there is none; other groups and
    layers get nothing.  The right click itself on QGIS before 3.32, the menu's signal after."""
    from archaeoortho.core.project.workspace import Workspace
    from archaeoortho.core.report.stage import report_of
    from archaeoortho.qgisio import layers
    from archaeoortho.ui.workspace_menu import WorkspaceGroupMenu
    from qgis.core import QgsProject
    from qgis.PyQt.QtGui import QContextMenuEvent, QDesktopServices
    from qgis.PyQt.QtWidgets import QApplication, QMenu

    ws, _ = aligned
    project = QgsProject.instance()
    group_name = layers.workspace_group_name(ws)
    loaded = layers.load_dsm(_raster(os.path.join(ws, "dsm.tif"), 1, nodata=-9999), project, group_name, workspace=ws)
    assert loaded
    user_group = project.layerTreeRoot().addGroup("my layers")
    view = qgis_iface.layerTreeView()
    menu_hook = plugin.group_menu
    assert menu_hook is not None and menu_hook.view is view and menu_hook.hooked in ("signal", "viewport")
    opened = []
    monkeypatch.setattr(QDesktopServices, "openUrl", lambda url: opened.append(url.toLocalFile()) or True)
    shown = []

    def right_click(node):
        """The context menu of ``node`` as QGIS shows it: its entries' (text, enabled)."""
        index = view.node2index(node)
        view.setCurrentIndex(index)
        shown.clear()
        if menu_hook.hooked == "signal":
            menu = QMenu()
            view.contextMenuAboutToShow.emit(menu)
        else:
            monkeypatch.setattr(WorkspaceGroupMenu, "_exec", staticmethod(lambda m, pos: shown.append(m)))
            pos = view.visualRect(index).center()
            event = QContextMenuEvent(QContextMenuEvent.Reason.Mouse, pos, view.viewport().mapToGlobal(pos))
            QApplication.sendEvent(view.viewport(), event)
            menu = shown[0] if shown else QMenu()
        return menu, [(a.text(), a.isEnabled()) for a in menu.actions() if a.text()]

    group = project.layerTreeRoot().findGroup(group_name)
    _menu, entries = right_click(group)
    assert entries == [("Open accuracy report (none yet: run Accuracy report or Run pipeline)", False)]
    report = layers.workspace_layout(ws).default_report
    with open(report, "w", encoding="utf-8") as fh:
        print("<html><body>report</body></html>", file=fh)
    menu, entries = right_click(group)
    assert entries == [("Open accuracy report", True)]
    next(a for a in menu.actions() if a.text() == "Open accuracy report").trigger()
    assert [os.path.normpath(p) for p in opened] == [os.path.normpath(report_of(Workspace.open(ws)))]
    assert right_click(user_group)[1] == [] and right_click(group.findLayers()[0])[1] == []
