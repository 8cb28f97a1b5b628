"""Build DSM: thin adapter over core.dense.stage.build_dsm_workspace."""
from qgis.core import (
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterRasterDestination,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class BuildDsmAlgorithm(AlgorithmBase):
    NAME = "builddsm"
    DISPLAY = "Build DSM"
    WORKSPACE = "WORKSPACE"
    RESOLUTION = "RESOLUTION"
    QUALITY = "QUALITY"
    ENGINE = "ENGINE"
    WORKERS = "WORKERS"
    SCHEDULER = "DASK_SCHEDULER"
    OUTPUT_DSM = "OUTPUT_DSM"
    OUTPUT_POINT_CLOUD = "OUTPUT_POINT_CLOUD"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    VALID_FRACTION = "VALID_FRACTION"
    PAIRS = "PAIRS"
    POINTS = "POINTS"
    QUALITIES = params.QUALITIES
    ENGINES = params.ENGINES
    HELP = (
        "Dense matching of the georeferenced block and a digital surface model (DSM).\n\n"
        "Stereo pairs are chosen from the sparse model (shared tie points, baseline-to-depth ratio, viewing "
        "angle); each pair is undistorted and rectified from the known poses and matched with semi-global "
        "matching (OpenCV SGBM) with a left-right check; a pixel is kept where at least two independent pairs "
        "agree. The fused points are rasterised (median of the highest height cluster per cell), small holes "
        "are filled and large ones left nodata.\n\n"
        "Workspace folder: a georeferenced workspace (run 'Georeference' first: a DSM needs a metric scale and a "
        "vertical direction, so a workspace that is only aligned is refused).\n"
        "DSM resolution: DSM cell size in metres; 0 = about twice the median ground sample distance.\n"
        "Matching quality: image scale for matching (full, half, quarter): half is four times faster than full.\n"
        "Engine: cpu (default); cuda runs COLMAP patch-match stereo where pycolmap was built with CUDA.\n"
        "DSM: Cloud-Optimized GeoTIFF, float32 with nodata (default: <workspace>/dsm.tif).\n"
        "Point cloud: optional LAS file (XYZ + RGB, workspace CRS).\n"
        "Dask scheduler (advanced): run the stereo pairs on a Dask cluster (tcp://host:8786) whose workers see the workspace "
        "path; empty = this computer (or the ARCHAEOORTHO_DASK_SCHEDULER environment variable).\n\n"
        "A re-run after a cancel resumes, reusing the pairs already matched in <workspace>/dense/."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Workspace folder (georeferenced)")),
            params.dsm_resolution(self.RESOLUTION, self.tr("DSM resolution in metres (0 = automatic)")),
            params.quality(self.QUALITY, self.tr("Matching quality (image scale)")),
            params.choice(self.ENGINE, self.tr("Engine"), self.ENGINES),
            *params.advanced(
                params.workers(self.WORKERS, self.tr("Parallel workers (0 = one per core)")),
                params.scheduler(self.SCHEDULER, self.tr(
                    "Dask scheduler address (empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER)"))),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(
            self.OUTPUT_DSM, self.tr("DSM"), optional=True, createByDefault=False))
        self.addParameter(QgsProcessingParameterFileDestination(
            self.OUTPUT_POINT_CLOUD, self.tr("Point cloud (LAS)"), fileFilter="LAS point cloud (*.las)",
            optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputNumber(self.VALID_FRACTION, self.tr(
            "Share of DSM cells with data inside the camera centres' convex hull")))
        self.addOutput(QgsProcessingOutputNumber(self.PAIRS, self.tr("Stereo pairs matched")))
        self.addOutput(QgsProcessingOutputNumber(self.POINTS, self.tr("Fused points")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.dense import stage as dense
        from ..core.dense.options import DenseOptions

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        output_dsm = self.parameterAsOutputLayer(parameters, self.OUTPUT_DSM, context) or None
        output_pc = self.parameterAsFileOutput(parameters, self.OUTPUT_POINT_CLOUD, context) or None
        options = self.run_core(
            DenseOptions, resolution=self.parameterAsDouble(parameters, self.RESOLUTION, context),
            quality=params.read_choice(self, parameters, self.QUALITY, context, self.QUALITIES),
            engine=params.read_choice(self, parameters, self.ENGINE, context, self.ENGINES),
            output_dsm=output_dsm, output_point_cloud=output_pc,
            workers=self.parameterAsInt(parameters, self.WORKERS, context),
            scheduler=params.read_scheduler(self, parameters, self.SCHEDULER, context))
        result = self.run_core(dense.build_dsm_workspace, workspace, options, FeedbackProgress(feedback))
        feedback.pushInfo(self.tr("DSM {} ({} m cells), valid fraction {}").format(
            result.dsm_path, result.resolution,
            "n/a" if result.valid_fraction is None else f"{result.valid_fraction:.3f}"))
        return {self.OUT_WORKSPACE: result.workspace, self.OUTPUT_DSM: result.dsm_path,
                self.OUTPUT_POINT_CLOUD: result.point_cloud_path, self.VALID_FRACTION: result.valid_fraction,
                self.PAIRS: result.pairs, self.POINTS: result.points}
