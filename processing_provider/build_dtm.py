"""Build DTM: thin adapter over core.terrain.stage.build_dtm_workspace / build_dtm."""
from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputRasterLayer,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class BuildDtmAlgorithm(AlgorithmBase):
    NAME = "builddtm"
    DISPLAY = "Build DTM"
    REQUIRES = ()  # NumPy, SciPy and GDAL only
    WORKSPACE = "WORKSPACE"
    DSM = "DSM"
    CONTOUR_INTERVAL = "CONTOUR_INTERVAL"
    SLOPE = "SLOPE"
    WINDOW = "WINDOW"
    THRESHOLD = "THRESHOLD"
    OUTPUT_DTM = "OUTPUT_DTM"
    OUTPUT_CONTOURS = "OUTPUT_CONTOURS"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    OUTPUT_SOURCE = "OUTPUT_DTM_SOURCE"
    OUTPUT_POINT_CLOUD = "OUTPUT_POINT_CLOUD"
    GROUND_FRACTION = "GROUND_FRACTION"
    INTERPOLATED_FRACTION = "INTERPOLATED_FRACTION"
    OUTPUT_KINDS = {"OUTPUT_DTM": "dtm", "OUTPUT_CONTOURS": "contours"}
    HELP = (
        "A digital terrain model (bare earth) from the DSM: buildings, trees and crops removed, the ground "
        "interpolated under them.\n\n"
        "The ground filter is SMRF (Pingel et al. 2013, the algorithm of PDAL's filters.smrf) on the DSM's grid; "
        "under each removed object the ground is a thin-plate spline through the ground around it. The DTM is a "
        "Cloud-Optimized GeoTIFF on the DSM's exact grid; beside it terrain/dtm-source.tif says which cells are "
        "measured ground (1) and which interpolated (2). The DSM stage's point cloud, if it wrote one, is copied "
        "with ASPRS classes 2 (ground) and 1 (unclassified) to terrain/points-classified.las.\n\n"
        "Workspace folder: a workspace with a DSM (optional when a DSM file is given).\n"
        "DSM file: any DSM in a projected CRS (metres); default: the workspace's.\n"
        "Contour interval: contour lines every this many metres into a GeoPackage (0 = none).\n"
        "Slope, largest object radius and height threshold (advanced): SMRF's parameters (PDAL's defaults).\n"
        "DTM: where to write it (default: <workspace>/dtm.tif).\n"
        "Contours: where to write the contour lines (default: <workspace>/terrain/contours.gpkg)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        ws = QgsProcessingParameterFile(self.WORKSPACE, self.tr("Workspace folder"),
                                        behavior=QgsProcessingParameterFile.Behavior.Folder, optional=True)
        params.add(
            self, ws,
            QgsProcessingParameterRasterLayer(self.DSM, self.tr("DSM file"),
                                              optional=True),
            params.number(self.CONTOUR_INTERVAL, self.tr("Contour interval in metres (0 = none)"), 0.0),
            *params.advanced(
                params.number(self.SLOPE, self.tr("Ground filter slope (rise over run)"), 0.15, 0.01),
                params.number(self.WINDOW, self.tr("Largest object radius in metres"), 18.0, 1.0),
                params.number(self.THRESHOLD, self.tr("Height above ground of an object in metres"), 0.5, 0.05)),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(
            self.OUTPUT_DTM, self.tr("DTM"), optional=True, createByDefault=False))
        self.addParameter(QgsProcessingParameterFileDestination(
            self.OUTPUT_CONTOURS, self.tr("Contours"),
            fileFilter="GeoPackage (*.gpkg)", optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputRasterLayer(self.OUTPUT_SOURCE, self.tr("DTM source")))
        self.addOutput(QgsProcessingOutputFile(self.OUTPUT_POINT_CLOUD, self.tr("Classified point cloud")))
        self.addOutput(QgsProcessingOutputNumber(self.GROUND_FRACTION, self.tr("Share of DSM cells on the ground")))
        self.addOutput(QgsProcessingOutputNumber(self.INTERPOLATED_FRACTION, self.tr(
            "Share of DTM cells interpolated")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.terrain import products, stage
        from ..core.terrain.options import GroundOptions, TerrainOptions

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context) or None
        layer = self.parameterAsRasterLayer(parameters, self.DSM, context)
        dsm = layer.source().split("|")[0] if layer is not None else None
        output_dtm = self.parameterAsOutputLayer(parameters, self.OUTPUT_DTM, context) or None
        contours = self.parameterAsFileOutput(parameters, self.OUTPUT_CONTOURS, context) or None
        interval = self.parameterAsDouble(parameters, self.CONTOUR_INTERVAL, context)
        options = GroundOptions(slope=self.parameterAsDouble(parameters, self.SLOPE, context),
                                window=self.parameterAsDouble(parameters, self.WINDOW, context),
                                threshold=self.parameterAsDouble(parameters, self.THRESHOLD, context))
        progress = FeedbackProgress(feedback)
        if workspace:
            terrain = TerrainOptions(ground=options, contour_interval=interval, dsm=dsm, output_dtm=output_dtm,
                                     contours_copy=contours)
            result = self.run_core(stage.build_dtm_workspace, workspace, terrain, progress)
        else:
            if not dsm or not output_dtm:
                raise QgsProcessingException(self.tr(
                    "Give a workspace folder, or a DSM file and where to write the DTM"))
            result = self.run_core(products.build_dtm, dsm, products.DtmOutputs(output_dtm, contours=contours), options,
                                   interval, progress=progress)
        return {self.OUT_WORKSPACE: result.workspace, self.OUTPUT_DTM: result.dtm_path,
                self.OUTPUT_SOURCE: result.source_path, self.OUTPUT_POINT_CLOUD: result.point_cloud_path,
                self.OUTPUT_CONTOURS: result.contours_path,
                self.GROUND_FRACTION: result.ground_fraction,
                self.INTERPOLATED_FRACTION: result.interpolated_fraction}
