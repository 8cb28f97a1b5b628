"""The textured 3-D model's OGC 3D Tiles as a tiled scene layer (QGIS 3.34+: QgsTiledSceneLayer, provider
"cesiumtiles"), in the workspace's group; older QGIS has no such layer, and nothing is loaded there.

qgis.core only (no qgis.gui), beside :mod:`.layers`, whose group and naming helpers it uses.  The layer goes to
the bottom of the workspace's group: QGIS draws a tiled scene in the 2-D map too, and there it would hide the
orthomosaic; the 3-D map view shows it whatever its place.
"""
import os

from qgis.core import (
    Qgis,
    QgsProcessingContext,
    QgsProcessingLayerPostProcessorInterface,
    QgsProject,
    QgsProviderRegistry,
)
from qgis.PyQt.QtCore import QCoreApplication

from .layers import (
    KIND_PROPERTY,
    MODEL3D,
    PATH_PROPERTY,
    add_layer,
    move_to_group,
    product_name,
    remove_loaded,
    replace_older,
    report_layer_failure,
    workspace_group_name,
    workspace_of,
)

PROVIDER = "cesiumtiles"
FIRST_VERSION = 33400  # QGIS 3.34: tiled scene layers


def tiled_scenes_supported():
    """True where this QGIS opens 3D Tiles as a tiled scene layer (3.34 or newer, with the cesiumtiles provider)."""
    return Qgis.versionInt() >= FIRST_VERSION and PROVIDER in QgsProviderRegistry.instance().providerList()


def model_layer_name(path, workspace=None):
    return product_name(QCoreApplication.translate("ResultLayers", "3-D model"), path, workspace)


def load_tiled_scene(path, project=None, group=None, name=None, workspace=None):
    """The tileset ``path`` as a tiled scene layer in ``group`` (a re-load replaces the older layer); [] where this
    QGIS has no tiled scene layers or the tileset does not open."""
    if not tiled_scenes_supported():
        return []
    from qgis.core import QgsTiledSceneLayer

    project = project or QgsProject.instance()
    remove_loaded(project, path, (MODEL3D,))
    layer = QgsTiledSceneLayer(path, name or model_layer_name(path, workspace), PROVIDER)
    if not layer.isValid():
        return []
    layer.setCustomProperty(KIND_PROPERTY, MODEL3D)
    return [layer] if add_layer(project, layer, group, path) is not None else []  # at the group's bottom: GROUP_ORDER


_KEEP = []  # the post-processors must outlive the run (QGIS keeps only a raw pointer)


class TiledScenePostProcessor(QgsProcessingLayerPostProcessorInterface):
    """Names a loaded tileset after its workspace and moves it to the bottom of the workspace's group."""

    def __init__(self, workspace=None):
        super().__init__()
        self.workspace = workspace
        _KEEP.append(self)
        del _KEEP[:-100]

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 (QGIS API name)
        """Called from C++: a failure is logged with its traceback and reported, never raised (it would abort
        QGIS); the layer stays loaded."""
        try:
            project = context.project() or QgsProject.instance()
            path = layer.source()
            replace_older(project, layer, path, MODEL3D)
            layer.setCustomProperty(KIND_PROPERTY, MODEL3D)
            layer.setCustomProperty(PATH_PROPERTY, path)
            layer.setName(model_layer_name(path, self.workspace))
            if self.workspace:
                move_to_group(project, layer, workspace_group_name(self.workspace), MODEL3D)
        except Exception:  # noqa: BLE001 - a bug here must never abort QGIS; it is logged, not hidden
            report_layer_failure("place", layer, feedback)


def register_tiled_scene(results, output_name, context, feedback=None):
    """Ask the run to load the tileset ``results[output_name]`` on completion as a tiled scene layer in its
    workspace's group: 1 when asked, 0 where this QGIS has no tiled scene layers (or there is no tileset, no
    project).  A problem here is reported to ``feedback``, never raised: it must not fail a run that worked."""
    try:
        from qgis.core import QgsProcessingUtils

        path = results.get(output_name) if isinstance(results, dict) else None
        project = context.project()
        if not path or not os.path.isfile(path) or project is None or not tiled_scenes_supported():
            return 0
        workspace = results.get("WORKSPACE") if isinstance(results.get("WORKSPACE"), str) else workspace_of(path)
        hint = getattr(QgsProcessingUtils.LayerHint, "TiledScene", None)  # QGIS 3.34+ (3.22 has no such hint)
        if hint is None:
            return 0
        details = QgsProcessingContext.LayerDetails(model_layer_name(path, workspace), project, output_name, hint)
        details.setPostProcessor(TiledScenePostProcessor(workspace))
        context.addLayerToLoadOnCompletion(path, details)
        return 1
    except Exception as e:  # noqa: BLE001 - loading must never fail an algorithm that worked
        if feedback is not None:
            feedback.pushInfo(QCoreApplication.translate("ResultLayers", "3D Tiles not loaded: {}").format(e))
        return 0
