"""Relief visualisation: thin adapter over core.terrain.stage.relief_workspace / relief."""
from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputFolder,
    QgsProcessingParameterFile,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class ReliefVisualisationAlgorithm(AlgorithmBase):
    NAME = "reliefvisualisation"
    DISPLAY = "Relief visualisation"
    REQUIRES = ()  # rvt-py, checked by the core call (its message names the pip command)
    WORKSPACE = "WORKSPACE"
    INPUT = "INPUT"
    SOURCE = "SOURCE"
    VISUALISATION = "VISUALISATION"
    OUTPUT = "OUTPUT"
    OUT_WORKSPACE = "WORKSPACE"
    SOURCES = ("dtm", "dsm")
    OUTPUT_KINDS = {"OUTPUT": "relief"}
    HELP = (
        "Relief visualisations for reading earthworks, hollow ways, ridge and furrow and field boundaries, "
        "computed with rvt-py (the Relief Visualization Toolbox's library) with RVT's default parameters, "
        "converted from the 1 m DEMs RVT was made for to this raster's cell size.\n\n"
        "Workspace folder: a workspace with a DTM (Build DTM) or DSM.\n"
        "Elevation raster: any DTM/DSM in a projected CRS instead (optional).\n"
        "Surface: the workspace's DTM (bare earth, default) or DSM.\n"
        "Visualisation: sky-view factor, openness (positive, negative), simple local relief model, multi-scale "
        "relief model, multi-direction hillshade, local dominance, or the VAT blend (visualisation for archaeological topography).\n"
        "Relief raster: where to write it (default: <workspace>/terrain/relief/<surface>-<visualisation>.tif)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.terrain.options import VISUALISATIONS

        vat = self.tr("VAT blend")  # the option's full label is too wide for the dialog
        options = [vat if key == "vat" else self.tr(label) for key, label in VISUALISATIONS]
        ws = QgsProcessingParameterFile(self.WORKSPACE, self.tr("Workspace folder"),
                                        behavior=QgsProcessingParameterFile.Behavior.Folder, optional=True)
        params.add(
            self, ws,
            QgsProcessingParameterRasterLayer(self.INPUT, self.tr("Elevation raster"),
                                              optional=True),
            params.choice(self.SOURCE, self.tr("Surface"), [self.tr("DTM"), self.tr("DSM")]),
            params.choice(self.VISUALISATION, self.tr("Visualisation"), options),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(
            self.OUTPUT, self.tr("Relief raster"), optional=True,
            createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        import os

        from ..core.terrain import products, stage
        from ..core.terrain.options import VISUALISATION_KEYS, ReliefStageOptions

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context) or None
        layer = self.parameterAsRasterLayer(parameters, self.INPUT, context)
        dem = layer.source().split("|")[0] if layer is not None else None
        source = params.read_choice(self, parameters, self.SOURCE, context, self.SOURCES)
        key = params.read_choice(self, parameters, self.VISUALISATION, context, VISUALISATION_KEYS)
        output = self.parameterAsOutputLayer(parameters, self.OUTPUT, context) or None
        progress = FeedbackProgress(feedback)
        if workspace and not dem:
            result = self.run_core(stage.relief_workspace, workspace,
                                   ReliefStageOptions([key], source=source, copy_to=output), progress)
            path = result.paths[key]
        else:
            if not dem or not output:
                raise QgsProcessingException(self.tr(
                    "Give a workspace folder, or an elevation raster and where to write the visualisation"))
            result = self.run_core(products.relief, dem, [key], os.path.dirname(output), source, progress=progress,
                                   what=source.upper(), outputs={key: output})
            path = result.paths[key]
        return {self.OUT_WORKSPACE: workspace, self.OUTPUT: path}
