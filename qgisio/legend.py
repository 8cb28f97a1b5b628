"""Band legends in the user's language (issue 48 item 6).

QGIS's legend of a raster names its band by the file's band description: "Band 1: DTM (bare earth)" in a German
QGIS too, since the description is the file's (English, the same for every reader of the file).  The layer tree
node of a layer the plugin loads gets a user label with the description translated (context "ResultLayers"):
"Kanal 1: DGM (Gelände)".  The file keeps its description."""
from qgis.core import QgsMapLayerLegendUtils, QgsRasterLayer
from qgis.PyQt.QtCore import QT_TRANSLATE_NOOP, QCoreApplication, Qt

# the band descriptions of the core's products (core/terrain/products.py), marked for the .ts files
DESCRIPTIONS = (QT_TRANSLATE_NOOP("ResultLayers", "DTM (bare earth)"),)


def translate_band_legend(project, layer):
    """Give ``layer``'s legend nodes in ``project``'s layer tree the translation of its band descriptions; the
    number of labels changed."""
    if not isinstance(layer, QgsRasterLayer) or project is None or layer.legend() is None:
        return 0
    node = project.layerTreeRoot().findLayer(layer.id())
    if node is None:
        return 0
    changed = 0
    for index, legend_node in enumerate(layer.legend().createLayerTreeModelLegendNodes(node)):
        text = str(legend_node.data(Qt.ItemDataRole.DisplayRole) or "")
        label = text
        for english in DESCRIPTIONS:
            translated = QCoreApplication.translate("ResultLayers", english)
            if english in label and translated != english:
                label = label.replace(english, translated)
        if label != text:
            QgsMapLayerLegendUtils.setLegendNodeUserLabel(node, index, label)
            changed += 1
    return changed
