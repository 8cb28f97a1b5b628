"""Result layers with sensible styles: DSM (pseudocolour + hillshade), orthomosaic (RGB, nodata
transparent), cameras (labelled points + footprints), GCP residuals (exaggerated vectors).

qgis.core only (no qgis.gui): used by the Processing post-processing hook (processing_provider/base.py)
and by the GCP dock.  Never called under qgis_process.
"""
import math
import os

from qgis.core import (
    Qgis,
    QgsArrowSymbolLayer,
    QgsCategorizedSymbolRenderer,
    QgsColorRampShader,
    QgsCoordinateReferenceSystem,
    QgsFillSymbol,
    QgsGeometryGeneratorSymbolLayer,
    QgsGradientColorRamp,
    QgsGradientStop,
    QgsHillshadeRenderer,
    QgsLineSymbol,
    QgsMarkerSymbol,
    QgsMessageLog,
    QgsMultiBandColorRenderer,
    QgsPainting,
    QgsPalLayerSettings,
    QgsProcessingLayerPostProcessorInterface,
    QgsProject,
    QgsProviderRegistry,
    QgsRasterBandStats,
    QgsRasterLayer,
    QgsRasterShader,
    QgsRendererCategory,
    QgsSingleBandPseudoColorRenderer,
    QgsStyle,
    QgsSymbol,
    QgsTextBufferSettings,
    QgsTextFormat,
    QgsVectorLayer,
    QgsVectorLayerSimpleLabeling,
)
from qgis.PyQt.QtCore import QCoreApplication, QObject, pyqtSignal
from qgis.PyQt.QtGui import QColor, QFont

from .legend import translate_band_legend

KIND_PROPERTY = "archaeoortho/kind"
PATH_PROPERTY = "archaeoortho/path"

DSM = "dsm"
HILLSHADE = "hillshade"
ORTHO = "ortho"
CAMERAS = "cameras"
FOOTPRINTS = "footprints"
RESIDUALS = "residuals"
POINT_CLOUD = "pointcloud"
DTM = "dtm"
DTM_HILLSHADE = "dtmhillshade"
RELIEF = "relief"
CONTOURS = "contours"
INDEX = "index"  # a spectral index (NDVI ...): over the orthomosaic it is made from
MODEL3D = "model3d"  # the 3-D model's 3D Tiles (a tiled scene layer, QGIS 3.34+: qgisio/scene_layers.py)
TARGETS = "targets"  # Find targets' layer for review: every surveyed target, found or not

# the order of a workspace's group, top to bottom: points and lines over the pictures, the orthomosaic over the
# terrain rasters, each hillshade right over its elevation model.  A hillshade drawn with 'multiply' above the
# orthomosaic darkened it (the DTM's, loaded last, by about 19 %: issue 36 item 16); under it, it shades only
# its DSM or DTM, which the orthomosaic covers until it is switched off.
GROUP_ORDER = (TARGETS, RESIDUALS, CAMERAS, FOOTPRINTS, CONTOURS, POINT_CLOUD, INDEX, ORTHO, RELIEF, DTM_HILLSHADE, DTM, HILLSHADE,
               DSM, MODEL3D)  # the 3-D model last: in the 2-D map it would hide the orthomosaic

# residual point status (core.georef) -> colour
STATUS_COLOURS = {"used": "#1a9641", "check": "#2b83ba", "rejected": "#d7191c", "not triangulated": "#888888"}


def qgs_crs(text):
    """QgsCoordinateReferenceSystem from what core.gcp accepts: EPSG:xxxx, a proj string or WKT."""
    text = (text or "").strip()
    if not text:
        return QgsCoordinateReferenceSystem()
    crs = QgsCoordinateReferenceSystem(text)
    if not crs.isValid() and text.startswith("+"):
        crs = QgsCoordinateReferenceSystem.fromProj(text)
    if not crs.isValid():
        crs = QgsCoordinateReferenceSystem.fromWkt(text)
    return crs


def has_real_crs(crs):
    """A CRS that places data on the earth: GeoPackages written without one report "Undefined geographic
    SRS" (GDAL's srs_id 0), which QGIS takes as valid."""
    return crs.isValid() and not crs.description().lower().startswith("undefined")


def crs_text(crs):
    """The string core.gcp stores for a QGIS CRS: the authority id where there is one, else WKT."""
    if not crs.isValid():
        return ""
    return crs.authid() or crs.toWkt()


# --------------------------------------------------------------------------------------------------
# rasters
# --------------------------------------------------------------------------------------------------


def _band_range(layer, band=1):
    provider = layer.dataProvider()
    try:
        lo, hi = provider.cumulativeCut(band, 0.02, 0.98, layer.extent(), 250000)
    except Exception:  # noqa: BLE001 - fall back to plain statistics
        lo = hi = float("nan")
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        stats = provider.bandStatistics(band, QgsRasterBandStats.Stats.Min | QgsRasterBandStats.Stats.Max, layer.extent(), 250000)
        lo, hi = stats.minimumValue, stats.maximumValue
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = 0.0, 1.0
    if hi <= lo:
        hi = lo + 1.0
    return float(lo), float(hi)


def _elevation_ramp():
    ramp = QgsStyle.defaultStyle().colorRamp("Spectral") if QgsStyle.defaultStyle() else None
    if ramp is not None:
        ramp.invert()  # low = blue, high = red
        return ramp
    return QgsGradientColorRamp(QColor("#2b83ba"), QColor("#d7191c"))


def _smooth_resampling(layer):
    """Bilinear resampling in the provider, before the renderer: no stair steps in a hillshade or a colour
    ramp when zoomed in beyond the DSM's cells."""
    try:
        from qgis.core import QgsRasterDataProvider, QgsRasterPipe

        provider = layer.dataProvider()
        bilinear = QgsRasterDataProvider.ResamplingMethod.Bilinear
        if provider.setZoomedInResamplingMethod(bilinear) and provider.setZoomedOutResamplingMethod(bilinear):
            layer.setResamplingStage(QgsRasterPipe.ResamplingStage.Provider)
    except (AttributeError, ImportError):  # pragma: no cover - older QGIS
        pass


def _pseudocolour(layer, ramp, lo: float, hi: float) -> None:
    """Band 1 of ``layer`` in ``ramp``, interpolated from ``lo`` to ``hi`` (five classes)."""
    shader = QgsColorRampShader(lo, hi, ramp, QgsColorRampShader.Type.Interpolated,
                                QgsColorRampShader.ClassificationMode.Continuous)
    shader.classifyColorRamp(5, -1, layer.extent(), layer.dataProvider())
    raster_shader = QgsRasterShader(lo, hi)
    raster_shader.setRasterShaderFunction(shader)
    renderer = QgsSingleBandPseudoColorRenderer(layer.dataProvider(), 1, raster_shader)
    renderer.setClassificationMin(lo)
    renderer.setClassificationMax(hi)
    layer.setRenderer(renderer)


def style_dsm(layer):
    """Pseudocolour (Spectral, 2-98 % stretch) for a DSM layer; nodata stays transparent."""
    _smooth_resampling(layer)
    lo, hi = _band_range(layer)
    ramp = _elevation_ramp()
    _pseudocolour(layer, ramp, lo, hi)
    _mark(layer, DSM)
    layer.triggerRepaint()
    return layer


def style_hillshade(layer):
    """Multidirectional hillshade drawn with 'multiply' over the pseudocolour DSM."""
    _smooth_resampling(layer)
    renderer = QgsHillshadeRenderer(layer.dataProvider(), 1, 315.0, 45.0)
    renderer.setMultiDirectional(True)
    renderer.setZFactor(1.0)
    layer.setRenderer(renderer)
    layer.setBlendMode(QgsPainting.getCompositionMode(QgsPainting.BlendMode.BlendMultiply))
    layer.setOpacity(0.6)
    _mark(layer, HILLSHADE)
    layer.triggerRepaint()
    return layer


def style_orthomosaic(layer):
    """RGB from bands 1-3, the alpha band (4) or nodata transparent."""
    provider = layer.dataProvider()
    n = layer.bandCount()
    if n >= 3:
        renderer = QgsMultiBandColorRenderer(provider, 1, 2, 3)
        if n >= 4:
            renderer.setAlphaBand(4)
        layer.setRenderer(renderer)
    for band in range(1, n + 1):
        if provider.sourceHasNoDataValue(band):
            provider.setUseSourceNoDataValue(band, True)
    _mark(layer, ORTHO)
    layer.triggerRepaint()
    return layer


# --------------------------------------------------------------------------------------------------
# vectors
# --------------------------------------------------------------------------------------------------


# QGIS >= 3.26: the placement is Qgis.LabelPlacement (QgsPalLayerSettings.OverPoint then names a
# LabelPredefinedPointPosition, which the placement setter refuses); 3.22 has only QgsPalLayerSettings.OverPoint.
_OVER_POINT = (Qgis.LabelPlacement.OverPoint if hasattr(Qgis, "LabelPlacement")
               else QgsPalLayerSettings.Placement.OverPoint)


def _labels(layer, expression, size=8.0, colour="#202020", is_expression=True, offset=2.0):
    fmt = QgsTextFormat()
    font = QFont()
    font.setPointSizeF(size)
    fmt.setFont(font)
    fmt.setSize(size)
    fmt.setColor(QColor(colour))
    buf = QgsTextBufferSettings()
    buf.setEnabled(True)
    buf.setSize(0.8)
    buf.setColor(QColor("white"))
    fmt.setBuffer(buf)
    settings = QgsPalLayerSettings()
    settings.fieldName = expression
    settings.isExpression = is_expression
    settings.setFormat(fmt)
    settings.dist = offset
    settings.placement = _OVER_POINT if layer.geometryType() == 0 else settings.placement
    if layer.geometryType() == 0:
        settings.quadOffset = QgsPalLayerSettings.QuadrantPosition.QuadrantAboveRight
    layer.setLabeling(QgsVectorLayerSimpleLabeling(settings))
    layer.setLabelsEnabled(True)


def style_cameras(layer):
    """Camera centres: dark triangles labelled with the image name."""
    symbol = QgsMarkerSymbol.createSimple({"name": "triangle", "color": "#303030", "outline_color": "white",
                                           "size": "3.2", "outline_width": "0.3"})
    layer.renderer().setSymbol(symbol)
    _labels(layer, '"image"', size=7.5)
    _mark(layer, CAMERAS)
    layer.triggerRepaint()
    return layer


def style_footprints(layer):
    symbol = QgsFillSymbol.createSimple({"color": "0,0,0,0", "outline_color": "#e66101", "outline_width": "0.35",
                                         "outline_style": "solid"})
    layer.renderer().setSymbol(symbol)
    layer.setOpacity(0.8)
    _mark(layer, FOOTPRINTS)
    layer.triggerRepaint()
    return layer


def _nice(value):
    """The 1-2-5 number nearest below ``value`` (> 0)."""
    if not value > 0 or not math.isfinite(value):
        return 1.0
    e = math.floor(math.log10(value))
    base = value / 10 ** e
    step = 5.0 if base >= 5 else 2.0 if base >= 2 else 1.0
    return step * 10 ** e


def residual_exaggeration(layer, share=0.15):
    """A 1-2-5 factor that draws the largest horizontal residual at ``share`` of the layer's extent."""
    largest = 0.0
    for f in layer.getFeatures():
        dx, dy = f["dx"], f["dy"]
        try:
            largest = max(largest, math.hypot(float(dx), float(dy)))
        except (TypeError, ValueError):
            continue
    ext = layer.extent()
    size = max(ext.width(), ext.height())
    if not size > 0:
        size = 100.0 * largest if largest > 0 else 10.0
    if largest <= 0:
        return 1.0
    return max(1.0, _nice(share * size / largest))


def style_residuals(layer, factor=None):
    """GCP residuals: points coloured by status, the horizontal residual drawn as an arrow exaggerated by
    ``factor`` (default: see residual_exaggeration), labelled with name and residual."""
    factor = residual_exaggeration(layer) if factor is None else float(factor)
    categories = []
    arrows = True
    labels = {"used": QCoreApplication.translate("ResultLayers", "control (used)"),
              "check": QCoreApplication.translate("ResultLayers", "check point"),
              "rejected": QCoreApplication.translate("ResultLayers", "rejected (outlier)"),
              "not triangulated": QCoreApplication.translate("ResultLayers", "not triangulated")}
    for status, colour in STATUS_COLOURS.items():
        symbol = QgsMarkerSymbol.createSimple({"name": "square" if status == "check" else "circle",
                                               "color": colour, "outline_color": "white", "size": "3.0"})
        gen = QgsGeometryGeneratorSymbolLayer.create({
            "geometryModifier": (f'make_line($geometry, make_point($x + coalesce("dx", 0) * {factor:g}, '
                                 f'$y + coalesce("dy", 0) * {factor:g}))')})
        gen.setSymbolType(QgsSymbol.SymbolType.Line)
        arrow = QgsArrowSymbolLayer()
        arrow.setIsCurved(False)
        arrow.setIsRepeated(False)
        arrow.setArrowWidth(0.5)
        arrow.setArrowStartWidth(0.5)
        arrow.setHeadLength(2.0)
        arrow.setHeadThickness(1.4)
        arrow_fill = QgsFillSymbol.createSimple({"color": colour, "outline_style": "no"})
        arrow.setSubSymbol(arrow_fill)
        line = QgsLineSymbol()
        if not line.changeSymbolLayer(0, arrow):
            line = QgsLineSymbol.createSimple({"color": colour, "width": "0.5"})
        gen.setSubSymbol(line)
        arrows = symbol.appendSymbolLayer(gen) and arrows  # without the arrow the point is still drawn
        categories.append(QgsRendererCategory(status, symbol, labels[status]))
    layer.setRenderer(QgsCategorizedSymbolRenderer("status", categories))
    _labels(layer, """"name" || coalesce('  ' || format_number("dxy", 3) || ' m', '')""", size=8.0)
    layer.setCustomProperty("archaeoortho/exaggeration", factor if arrows else 0)
    _mark(layer, RESIDUALS)
    layer.triggerRepaint()
    return layer


def style_targets(layer):
    """Find targets' review layer: found targets green, the others red, labelled with name and observations."""
    categories = []
    for value, colour, label in ((1, "#1a9641", QCoreApplication.translate("ResultLayers", "found")),
                                 (0, "#d7191c", QCoreApplication.translate("ResultLayers", "not found"))):
        symbol = QgsMarkerSymbol.createSimple({"name": "cross2", "color": colour, "outline_color": colour,
                                               "size": "4.0", "outline_width": "0.6"})
        categories.append(QgsRendererCategory(value, symbol, label))
    layer.setRenderer(QgsCategorizedSymbolRenderer("found", categories))
    _labels(layer, """"name" || ' (' || coalesce("observations", 0) || ')'""", size=8.0)
    _mark(layer, TARGETS)
    layer.triggerRepaint()
    return layer


def _mark(layer, kind):
    layer.setCustomProperty(KIND_PROPERTY, kind)


# --------------------------------------------------------------------------------------------------
# terrain products: DTM, relief visualisations, contours
# --------------------------------------------------------------------------------------------------

_CURVED = (Qgis.LabelPlacement.Curved if hasattr(Qgis, "LabelPlacement") else QgsPalLayerSettings.Placement.Curved)


def _file_metadata(path):
    try:
        from osgeo import gdal

        ds = gdal.Open(path)
        return (ds.GetMetadata() or {}) if ds is not None else {}
    except (ImportError, RuntimeError):
        return {}


def style_dtm(layer):
    """A DTM as a DSM: pseudocolour (Spectral, 2-98 %); its hillshade is a second layer."""
    style_dsm(layer)
    _mark(layer, DTM)
    return layer


def style_relief(layer):
    """A relief visualisation in grey, stretched over RVT's display range of it (the file's DISPLAY_MIN /
    DISPLAY_MAX: sky-view factor 0.64-1, openness 60-95 deg, local relief -2..2 m, ...), as RVT's 8-bit files."""
    from qgis.core import QgsContrastEnhancement, QgsSingleBandGrayRenderer

    _smooth_resampling(layer)
    path = layer.source().split("|")[0]
    meta = _file_metadata(path)
    try:
        lo, hi = float(meta["DISPLAY_MIN"]), float(meta["DISPLAY_MAX"])
    except (KeyError, ValueError):
        lo, hi = _band_range(layer)
    renderer = QgsSingleBandGrayRenderer(layer.dataProvider(), 1)
    ce = QgsContrastEnhancement(layer.dataProvider().dataType(1))
    ce.setContrastEnhancementAlgorithm(QgsContrastEnhancement.ContrastEnhancementAlgorithm.StretchToMinimumMaximum)
    ce.setMinimumValue(lo)
    ce.setMaximumValue(hi)
    renderer.setContrastEnhancement(ce)
    layer.setRenderer(renderer)
    _mark(layer, RELIEF)
    layer.triggerRepaint()
    return layer


def style_index(layer):
    """A spectral index in a diverging red-yellow-green ramp (RdYlGn: bare soil and stressed crop red, healthy crop
    green) over the file's DISPLAY_MIN .. DISPLAY_MAX (-1 .. 1 for NDVI and NDRE), else its 2-98 % range; nodata
    transparent.  Named after the index (its INDEX item: NDVI, NDRE, Index)."""
    path = layer.source().split("|")[0]
    meta = _file_metadata(path)
    try:
        lo, hi = float(meta["DISPLAY_MIN"]), float(meta["DISPLAY_MAX"])
        if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
            raise ValueError
    except (KeyError, ValueError):
        lo, hi = _band_range(layer)
    ramp = QgsStyle.defaultStyle().colorRamp("RdYlGn") if QgsStyle.defaultStyle() else None
    if ramp is None:
        ramp = QgsGradientColorRamp(QColor("#d7191c"), QColor("#1a9641"))
        ramp.setStops([QgsGradientStop(0.5, QColor("#ffffbf"))])
    _pseudocolour(layer, ramp, lo, hi)
    layer.setName(product_name(meta.get("INDEX") or QCoreApplication.translate("ResultLayers", "Spectral index"),
                               path))
    _mark(layer, INDEX)
    layer.triggerRepaint()
    return layer


def style_contours(layer):
    """Contour lines: thin brown, labelled with their elevation along the line."""
    symbol = QgsLineSymbol.createSimple({"color": "#8c510a", "width": "0.25"})
    layer.renderer().setSymbol(symbol)
    _labels(layer, 'format_number("elevation", 1)', size=7.0, colour="#5a3206")
    labeling = layer.labeling()
    if labeling is not None:
        settings = labeling.settings()
        settings.placement = _CURVED
        layer.setLabeling(QgsVectorLayerSimpleLabeling(settings))
    _mark(layer, CONTOURS)
    layer.triggerRepaint()
    return layer


def workspace_of(path, levels=3):
    """The workspace folder a product file lies in (the nearest folder above it with a workspace manifest), None
    for a file outside any workspace."""
    from ..core.project.layout import MANIFEST

    folder = os.path.dirname(os.path.abspath(str(path).split("|")[0]))
    for _ in range(levels):
        if os.path.isfile(os.path.join(folder, MANIFEST)):
            return folder
        parent = os.path.dirname(folder)
        if parent == folder:
            break
        folder = parent
    return None


def product_name(label, path, workspace=None):
    """A product layer's name with its workspace's: 'DSM — toledo', so that two workspaces' DSMs, orthomosaics and
    cameras are told apart in the layer lists (the dock's reference boxes showed two 'DSM': issue 36 item 17)."""
    workspace = workspace or workspace_of(path)
    if not workspace:
        return label
    return QCoreApplication.translate("ResultLayers", "{} \u2014 {}").format(
        label, os.path.basename(os.path.normpath(workspace)))


def relief_name(path):
    """The layer name of a relief visualisation file: its visualisation and surface ('Sky-view factor (DTM)')."""
    meta = _file_metadata(path)
    key = meta.get("RELIEF") or os.path.splitext(os.path.basename(path))[0].split("-", 1)[-1]
    try:
        from ..core.terrain.options import VISUALISATIONS

        label = dict(VISUALISATIONS).get(key, key)
        label = QCoreApplication.translate("Choices", label)  # as Processing's option (params.option_label)
    except ImportError:  # pragma: no cover
        label = key
    surface = os.path.basename(path).split("-", 1)[0].upper()
    return QCoreApplication.translate("ResultLayers", "{} ({})").format(label, surface if surface in ("DTM", "DSM")
                                                                        else "DTM")


def load_dtm(path, project=None, group=None, name=None, workspace=None):
    """DTM as two layers: the pseudocolour and a multiplied hillshade above it."""
    project = project or QgsProject.instance()
    remove_loaded(project, path, (DTM, DTM_HILLSHADE))
    dtm = QgsRasterLayer(path, name or product_name(QCoreApplication.translate("ResultLayers", "DTM"), path, workspace))
    if not dtm.isValid():
        return []
    style_dtm(dtm)
    shade = QgsRasterLayer(path, product_name(QCoreApplication.translate("ResultLayers", "DTM hillshade"), path,
                                              workspace))
    style_hillshade(shade)
    _mark(shade, DTM_HILLSHADE)
    return [lyr for lyr in (add_layer(project, dtm, group, path), add_layer(project, shade, group, path))
            if lyr is not None]


def load_relief(path, project=None, group=None, name=None, workspace=None):
    project = project or QgsProject.instance()
    remove_loaded(project, path, (RELIEF,))
    layer = QgsRasterLayer(path, name or product_name(relief_name(path), path, workspace))
    if not layer.isValid():
        return []
    style_relief(layer)
    return [layer] if add_layer(project, layer, group, path) is not None else []


def load_contours(path, project=None, group=None, name=None, workspace=None):
    project = project or QgsProject.instance()
    remove_loaded(project, path, (CONTOURS,))
    layer = QgsVectorLayer(f"{path}|layername=contours", name or product_name(QCoreApplication.translate(
        "ResultLayers", "Contours"), path, workspace), "ogr")
    if not layer.isValid():
        return []
    style_contours(layer)
    return [layer] if add_layer(project, layer, group, path) is not None else []


# --------------------------------------------------------------------------------------------------
# adding to a project
# --------------------------------------------------------------------------------------------------


def _norm(path):
    return os.path.normcase(os.path.realpath(path)) if path else ""


def remove_loaded(project, path, kinds=None):
    """Remove layers earlier loaded from ``path`` (a re-run replaces its products)."""
    target = _norm(path)
    drop = []
    for layer in project.mapLayers().values():
        if _norm(layer.customProperty(PATH_PROPERTY, "")) == target and (
                kinds is None or layer.customProperty(KIND_PROPERTY, "") in kinds):
            drop.append(layer.id())
    if drop:
        project.removeMapLayers(drop)


def _group(project, name):
    if not name:
        return None
    root = project.layerTreeRoot()
    group = root.findGroup(name)
    if group is None:
        group = root.insertGroup(0, name)
    return group


def _rank(node):
    """A layer node's place in GROUP_ORDER; -1 (the top) for a layer or group of the user's."""
    layer = node.layer() if hasattr(node, "layer") else None
    kind = layer.customProperty(KIND_PROPERTY, "") if layer is not None else ""
    return GROUP_ORDER.index(kind) if kind in GROUP_ORDER else -1


def _index_in_group(group, kind, skip=None):
    """Where a layer of ``kind`` goes in ``group``: above the first of a later kind in GROUP_ORDER (the top of
    its own kind: a re-run's layer comes first), the user's layers staying on top."""
    rank = GROUP_ORDER.index(kind) if kind in GROUP_ORDER else -1
    children = [c for c in group.children() if c is not skip]
    for i, child in enumerate(children):
        if _rank(child) >= rank and rank >= 0:
            return i
    return len(children) if rank >= 0 else 0


def add_layer(project, layer, group=None, path=None):
    """Add ``layer`` to ``project`` (in ``group`` when given, at its kind's place: GROUP_ORDER) and remember
    its source."""
    layer.setCustomProperty(PATH_PROPERTY, path or layer.source().split("|")[0])
    node = _group(project, group)
    if project.addMapLayer(layer, node is None) is None:
        return None
    if node is not None:
        node.insertLayer(_index_in_group(node, layer.customProperty(KIND_PROPERTY, "")), layer)
    translate_band_legend(project, layer)  # "Band 1: DTM (bare earth)" in the user's language (issue 48 item 6)
    return layer


def load_dsm(path, project=None, group=None, name=None, workspace=None):
    """DSM as two layers: the pseudocolour and a multiplied hillshade above it."""
    project = project or QgsProject.instance()
    remove_loaded(project, path, (DSM, HILLSHADE))
    dsm = QgsRasterLayer(path, name or product_name(QCoreApplication.translate("ResultLayers", "DSM"), path, workspace))
    if not dsm.isValid():
        return []
    style_dsm(dsm)
    shade = QgsRasterLayer(path, product_name(QCoreApplication.translate("ResultLayers", "DSM hillshade"), path,
                                              workspace))
    style_hillshade(shade)
    return [lyr for lyr in (add_layer(project, dsm, group, path), add_layer(project, shade, group, path))
            if lyr is not None]


def load_orthomosaic(path, project=None, group=None, name=None, workspace=None):
    project = project or QgsProject.instance()
    remove_loaded(project, path, (ORTHO,))
    layer = QgsRasterLayer(path, name or product_name(QCoreApplication.translate("ResultLayers", "Orthomosaic"), path,
                                                      workspace))
    if not layer.isValid():
        return []
    style_orthomosaic(layer)
    return [layer] if add_layer(project, layer, group, path) is not None else []


def load_cameras(path, project=None, group=None, name=None, workspace=None, footprints=None):
    """Camera centres (only when they carry a CRS: an aligned block is in an arbitrary frame) and, for a
    georeferenced workspace, the image footprints on the mean ground height (``footprints``: the GeoPackage
    footprints_path() wrote already, in a background task; else written now)."""
    project = project or QgsProject.instance()
    layer = QgsVectorLayer(path, name or product_name(QCoreApplication.translate("ResultLayers", "Cameras"), path,
                                                      workspace), "ogr")
    if not layer.isValid() or not has_real_crs(layer.crs()):
        return []
    remove_loaded(project, path, (CAMERAS,))
    out = []
    foot = footprints or (footprints_path(workspace) if workspace else None)
    if foot:
        remove_loaded(project, foot, (FOOTPRINTS,))
        fl = QgsVectorLayer(foot, product_name(QCoreApplication.translate("ResultLayers", "Camera footprints"), foot,
                                               workspace), "ogr")
        if fl.isValid():
            style_footprints(fl)
            out.append(add_layer(project, fl, group, foot))
    style_cameras(layer)
    out.append(add_layer(project, layer, group, path))
    return [lyr for lyr in out if lyr is not None]


def workspace_layout(workspace):
    """core.project.layout.Layout of a workspace folder: its product paths (no manifest needed for them)."""
    from ..core.project.layout import Layout
    from ..core.project.workspace import Workspace

    return Layout(Workspace(workspace, {}))


def footprints_path(workspace):
    """Write <workspace>/georef/footprints.gpkg for a georeferenced workspace; None when not possible."""
    try:
        import numpy as np

        from ..core.georef import guided
        from ..core.georef.stage import load_georef_model
    except ImportError:
        return None
    from ..core.common.errors import ArchaeoOrthoError

    try:
        rec, transform = load_georef_model(workspace)
    except ArchaeoOrthoError:  # not georeferenced (yet): no footprints, nothing to say
        return None
    try:
        z = [p.xyz[2] for p in rec.points3D.values()]
        if not z:
            return None
        prints = guided.image_footprints(rec, float(np.median(z)))
        path = workspace_layout(workspace).footprints_gpkg
        return guided.write_footprints_gpkg(path, prints, transform.offset, transform.crs or None)
    except Exception as err:  # noqa: BLE001 - the footprints must not stop the loading of the rest: said, not hidden
        QgsMessageLog.logMessage(f"image footprints of {workspace} not written: {type(err).__name__}: {err}",
                                 "ArchaeoOrtho", Qgis.MessageLevel.Warning)
        return None


def load_residuals(path, project=None, group=None, name=None, workspace=None):
    project = project or QgsProject.instance()
    layer = QgsVectorLayer(path, "residuals", "ogr")
    if not layer.isValid():
        return []
    remove_loaded(project, path, (RESIDUALS,))
    style_residuals(layer)
    factor = layer.customProperty("archaeoortho/exaggeration", 1.0)
    layer.setName(name or product_name(QCoreApplication.translate("ResultLayers", "GCP residuals (vectors x{})").format(
        f"{float(factor):g}"), path, workspace))
    return [layer] if add_layer(project, layer, group, path) is not None else []


def load_point_cloud(path, project=None, group=None, name=None, workspace=None):
    """A LAS/LAZ point cloud where this QGIS build has the PDAL provider; [] otherwise."""
    if "pdal" not in QgsProviderRegistry.instance().providerList():
        return []
    from qgis.core import QgsPointCloudLayer

    project = project or QgsProject.instance()
    remove_loaded(project, path, (POINT_CLOUD,))
    layer = QgsPointCloudLayer(path, name or product_name(QCoreApplication.translate("ResultLayers", "Point cloud"),
                                                          path, workspace), "pdal")
    if not layer.isValid():
        return []
    _mark(layer, POINT_CLOUD)
    return [layer] if add_layer(project, layer, group, path) is not None else []


def load_workspace_results(workspace, project=None, group=None):
    """Every product a workspace holds, styled: DSM, orthomosaic, cameras + footprints, residuals."""
    project = project or QgsProject.instance()
    group = group or workspace_group_name(workspace)
    loaded = []
    lay = workspace_layout(workspace)
    candidates = [
        (lay.default_dsm, load_dsm, {"workspace": workspace}),
        (lay.default_orthomosaic, load_orthomosaic, {"workspace": workspace}),
        (lay.cameras_gpkg, load_cameras, {"workspace": workspace}),
        (lay.residuals_gpkg, load_residuals, {"workspace": workspace}),
        (lay.default_dtm, load_dtm, {"workspace": workspace}),
        (lay.contours_gpkg, load_contours, {"workspace": workspace}),
    ]
    relief_dir = os.path.dirname(lay.relief("x"))
    if os.path.isdir(relief_dir):
        candidates += [(os.path.join(relief_dir, n), load_relief, {"workspace": workspace})
                       for n in sorted(os.listdir(relief_dir))
                       if n.endswith(".tif")]
    for path, fn, kw in candidates:
        if os.path.exists(path):
            loaded += fn(path, project, group, **kw)
    return loaded


# --------------------------------------------------------------------------------------------------
# Processing: style outputs when the run loads them into a project
# --------------------------------------------------------------------------------------------------


def output_kind(output_name, path):
    """Which style an algorithm output gets, from its name and file; None for none of ours."""
    n = (output_name or "").upper()
    ext = os.path.splitext(str(path))[1].lower()
    if "RESIDUAL" in n:
        return RESIDUALS
    if n == "MARKS" and ext == ".gpkg":  # Find targets' layer of the targets for review
        return TARGETS
    if "CAMERA" in n:
        return CAMERAS
    if ext in (".las", ".laz", ".copc") or "POINT_CLOUD" in n:
        return POINT_CLOUD
    if "ORTHO" in n:
        return ORTHO
    if "CONTOUR" in n and ext == ".gpkg":
        return CONTOURS
    if "DTM" in n and "SOURCE" not in n:
        return DTM
    if "DSM" in n or "DEM" in n:
        return DSM
    return None


_KEEP = []  # the post-processors must outlive the run (QGIS keeps only a raw pointer)


class ResultsNotifier(QObject):
    """Says which workspace a Processing run's results came from, once its layers are loaded (main thread): the
    plugin's dock opens it (issue 48 item 4: after Run pipeline from the Toolbox the dock said 'none open')."""

    workspaceLoaded = pyqtSignal(str)  # noqa: N815 (Qt signal naming)


_NOTIFIER = []


def results_notifier():
    """The one ResultsNotifier of this QGIS session."""
    if not _NOTIFIER:
        _NOTIFIER.append(ResultsNotifier())
    return _NOTIFIER[0]


class StylePostProcessor(QgsProcessingLayerPostProcessorInterface):
    """Styles a loaded output layer; for a DSM adds the hillshade, for cameras the footprints."""

    def __init__(self, kind, workspace=None):
        super().__init__()
        self.kind = kind
        self.workspace = workspace
        _KEEP.append(self)
        del _KEEP[:-100]

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 (QGIS API name)
        """QGIS calls this from C++: an exception escaping it would abort QGIS, so every failure is logged
        with its traceback and reported to the run's feedback; the layer stays loaded, unstyled."""
        try:
            self._style(layer, context)
        except Exception:  # noqa: BLE001 - a styling bug must never abort QGIS; it is logged, not hidden
            report_layer_failure("style", layer, feedback)
        if self.workspace:  # styled or not, the layer is the workspace's: the dock follows (the plugin hears it)
            results_notifier().workspaceLoaded.emit(self.workspace)

    def _style(self, layer, context):
        project = context.project() or QgsProject.instance()
        path = layer.source().split("|")[0]
        layer.setCustomProperty(PATH_PROPERTY, path)
        group = workspace_group_name(self.workspace) if self.workspace else None
        if group:  # with the workspace's other layers (the dock's Load results puts them there too), at its kind's
            # place (GROUP_ORDER): the orthomosaic over the hillshades
            replace_older(project, layer, path, self.kind)
            move_to_group(project, layer, group, self.kind)
        if self.kind == DSM:
            style_dsm(layer)
            remove_loaded(project, path, (HILLSHADE,))
            shade = QgsRasterLayer(path, product_name(QCoreApplication.translate("ResultLayers", "DSM hillshade"),
                                                      path, self.workspace))
            if shade.isValid():
                style_hillshade(shade)
                add_layer(project, shade, group, path)
        elif self.kind == ORTHO:
            style_orthomosaic(layer)
        elif self.kind == CAMERAS:
            style_cameras(layer)
            foot = footprints_path(self.workspace) if self.workspace else None
            if foot:
                remove_loaded(project, foot, (FOOTPRINTS,))
                fl = QgsVectorLayer(foot, product_name(QCoreApplication.translate(
                    "ResultLayers", "Camera footprints"), foot, self.workspace), "ogr")
                if fl.isValid():
                    style_footprints(fl)
                    add_layer(project, fl, group, foot)
        elif self.kind == RESIDUALS:
            style_residuals(layer)
            factor = layer.customProperty("archaeoortho/exaggeration", 1.0)
            layer.setName(product_name(QCoreApplication.translate("ResultLayers", "GCP residuals (vectors x{})").format(
                f"{float(factor):g}"), path, self.workspace))
        elif self.kind == POINT_CLOUD:
            _mark(layer, POINT_CLOUD)
        elif self.kind == DTM:
            style_dtm(layer)
            translate_band_legend(project, layer)
            remove_loaded(project, path, (DTM_HILLSHADE,))
            shade = QgsRasterLayer(path, product_name(QCoreApplication.translate("ResultLayers", "DTM hillshade"),
                                                      path, self.workspace))
            if shade.isValid():
                style_hillshade(shade)
                _mark(shade, DTM_HILLSHADE)
                add_layer(project, shade, group, path)
        elif self.kind == RELIEF:
            style_relief(layer)
            layer.setName(product_name(relief_name(path), path, self.workspace))
        elif self.kind == CONTOURS:
            style_contours(layer)
        elif self.kind == INDEX:
            style_index(layer)
        elif self.kind == TARGETS:
            style_targets(layer)
        name = _output_layer_name(self.kind, path)
        if name:  # not the parameter's label ("Orthomosaic (default: <workspace>/orthomosaic.tif)")
            layer.setName(product_name(name, path, self.workspace))
        if group:  # styled: its kind known, it takes its place in the group (a hillshade under the orthomosaic)
            move_to_group(project, layer, group, self.kind)



def _output_layer_name(kind, path=""):
    if kind == ORTHO and os.path.basename(path).lower().endswith("_rgb.tif"):  # Run pipeline's mosaic of a rig's
        return QCoreApplication.translate("ResultLayers", "RGB orthomosaic")  # RGB frames, beside the bands'
    names = {DSM: QCoreApplication.translate("ResultLayers", "DSM"),
             ORTHO: QCoreApplication.translate("ResultLayers", "Orthomosaic"),
             CAMERAS: QCoreApplication.translate("ResultLayers", "Cameras"),
             POINT_CLOUD: QCoreApplication.translate("ResultLayers", "Point cloud"),
             DTM: QCoreApplication.translate("ResultLayers", "DTM"),
             CONTOURS: QCoreApplication.translate("ResultLayers", "Contours"),
             TARGETS: QCoreApplication.translate("ResultLayers", "Targets found")}
    return names.get(kind)


def workspace_group_name(workspace):
    """The layer-tree group of a workspace's layers: 'ArchaeoOrtho: <folder name>'."""
    return QCoreApplication.translate("ResultLayers", "ArchaeoOrtho: {}").format(
        os.path.basename(os.path.normpath(workspace)))


def report_layer_failure(action, layer, feedback=None):
    """Log the exception being handled (with its traceback) as ArchaeoOrtho failing to ``action`` ``layer``, and
    report it to the run's ``feedback``: a post-processor QGIS calls from C++ must never raise (it would abort
    QGIS), and must not hide what went wrong either."""
    import traceback

    text = traceback.format_exc()
    message = f"ArchaeoOrtho could not {action} the layer {layer.name()}: {text.strip().splitlines()[-1]}"
    QgsMessageLog.logMessage(f"{message}\n{text}", "ArchaeoOrtho", Qgis.MessageLevel.Critical)
    if feedback is not None:
        feedback.reportError(message, False)


def replace_older(project, layer, path, kind):
    """A re-run's product replaces the layer an earlier run (or Load results) loaded from the same file."""
    target = _norm(path)
    drop = [other.id() for other in project.mapLayers().values()
            if other.id() != layer.id() and _norm(other.customProperty(PATH_PROPERTY, "")) == target
            and other.customProperty(KIND_PROPERTY, "") == kind]
    if drop:
        project.removeMapLayers(drop)


def move_to_group(project, layer, group_name, kind=None):
    """Move ``layer``'s node into the group ``group_name`` (made when missing), at its kind's place (GROUP_ORDER;
    the top without a kind)."""
    root = project.layerTreeRoot()
    node = root.findLayer(layer.id())
    group = _group(project, group_name)
    if node is None or group is None:
        return
    index = _index_in_group(group, kind or layer.customProperty(KIND_PROPERTY, ""), skip=node)
    if node.parent() is group and group.children().index(node) == index:
        return
    parent = node.parent()
    group.insertChildNode(index, node.clone())
    parent.removeChildNode(node)


def register_outputs(alg, results, context):
    """Ask the run to load ``alg``'s layer outputs in ``results`` with our styles (see base.py).

    Layers the dialog already loads (destination parameters the user ticked) get the post-processor;
    plain outputs (QgsProcessingOutputVectorLayer / RasterLayer) and our raster destinations are added.
    Aligned blocks have no CRS: their camera layers are not loaded.
    """
    from qgis.core import QgsProcessingContext, QgsProcessingUtils

    project = context.project()
    if project is None or not isinstance(results, dict):
        return 0
    workspace = results.get("WORKSPACE") if isinstance(results.get("WORKSPACE"), str) else None
    count = 0
    loading = context.layersToLoadOnCompletion()
    for name, value in results.items():
        if not isinstance(value, str) or not value or not os.path.exists(value.split("|")[0]):
            continue
        kind = getattr(alg, "OUTPUT_KINDS", {}).get(name) or output_kind(name, value)
        if kind is None:
            continue
        out_def = alg.outputDefinition(name)
        if out_def is None:
            continue
        if kind == CAMERAS and not _has_crs(value):
            continue
        if kind == POINT_CLOUD and "pdal" not in QgsProviderRegistry.instance().providerList():
            continue
        pp = StylePostProcessor(kind, workspace)
        if value in loading:
            details = context.layerToLoadOnCompletionDetails(value)
            details.setPostProcessor(pp)
        else:
            hint = QgsProcessingUtils.LayerHint.Raster if kind in (DSM, ORTHO, DTM, RELIEF, INDEX) else (
                QgsProcessingUtils.LayerHint.Vector if kind in (CAMERAS, RESIDUALS, CONTOURS, TARGETS) else
                QgsProcessingUtils.LayerHint.UnknownType)
            details = QgsProcessingContext.LayerDetails(out_def.description() or name, project, name, hint)
            details.setPostProcessor(pp)
            context.addLayerToLoadOnCompletion(value, details)
        count += 1
    return count


def _has_crs(path):
    try:
        from osgeo import ogr
    except ImportError:
        return True
    ds = ogr.Open(path.split("|")[0])
    if ds is None or ds.GetLayerCount() == 0:
        return False
    srs = ds.GetLayer(0).GetSpatialRef()
    return srs is not None and not (srs.GetName() or "").lower().startswith("undefined")
