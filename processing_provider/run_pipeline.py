"""Run pipeline: thin adapter over core.pipeline.run_pipeline (align -> georeference -> DSM -> orthomosaic -> report)."""
from qgis.core import (
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputNumber,
    QgsProcessingOutputRasterLayer,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
)

from .align_images import CAMERA_MODELS, PAIRINGS
from .base import AlgorithmBase, FeedbackProgress
from .build_dsm import BuildDsmAlgorithm
from .build_orthophoto import BuildOrthophotoAlgorithm
from .georeference import GeoreferenceAlgorithm


class RunPipelineAlgorithm(AlgorithmBase):
    NAME = "runpipeline"
    DISPLAY = "Run pipeline"
    IMAGES = "IMAGES"
    WORKSPACE = "WORKSPACE"
    GCPS = "GCPS"
    GCP_LAYER = "GCP_LAYER"
    CHECK_POINTS = "CHECK_POINTS"
    USE_EXIF_GPS = "USE_EXIF_GPS"
    CAMERA_POSITIONS = "CAMERA_POSITIONS"
    CRS = "CRS"
    PAIRING = "PAIRING"
    CAMERA_MODEL = "CAMERA_MODEL"
    MAX_IMAGE_SIZE = "MAX_IMAGE_SIZE"
    REFINE_INTRINSICS = "REFINE_INTRINSICS"
    DSM_RESOLUTION = "DSM_RESOLUTION"
    QUALITY = "QUALITY"
    ORTHO_RESOLUTION = "ORTHO_RESOLUTION"
    BLENDING = "BLENDING"
    REPORT_ENABLED = "MAKE_REPORT"
    WORKERS = "WORKERS"
    SCHEDULER = "DASK_SCHEDULER"
    DSM = "DSM"
    ORTHOMOSAIC = "ORTHOMOSAIC"
    REPORT = "REPORT"
    NUMBERS = (("REGISTERED_IMAGES", "Registered images"), ("MEAN_REPROJECTION_ERROR", "Mean reprojection error (px)"),
               ("GCP_RMSE_XY", "Control RMSE XY (m)"), ("CHECK_RMSE_XY", "Check RMSE XY (m)"),
               ("CHECK_RMSE_Z", "Check RMSE Z (m)"), ("CAMERA_RMSE_XYZ", "Camera position RMSE XYZ (m)"),
               ("DSM_VALID_FRACTION", "DSM valid fraction"), ("ORTHO_VALID_FRACTION", "Orthomosaic valid fraction"))
    HELP = (
        "The whole chain in one call, for batch use: Align images, Georeference, Build DSM, Build orthophoto "
        "and Accuracy report on one workspace. It calls the same functions as the single algorithms, and a "
        "re-run resumes (features, matches and dense pairs already computed are reused).\n\n"
        "IMAGES: folder of photos. WORKSPACE: the workspace folder.\n"
        "Georeferencing needs ground control (GCPS file or GCP_LAYER, CHECK_POINTS held out) and/or camera "
        "positions (CAMERA_POSITIONS CSV or USE_EXIF_GPS): without them the pipeline refuses, since a DSM needs a "
        "metric scale and a vertical direction.\n"
        "The other parameters are those of the single stages (see their help); 0 means automatic.\n"
        "Outputs: DSM, ORTHOMOSAIC and REPORT (HTML), plus the key figures."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        self.addParameter(QgsProcessingParameterFile(
            self.IMAGES, self.tr("Folder of images"), behavior=QgsProcessingParameterFile.Folder))
        self.addParameter(QgsProcessingParameterFolderDestination(self.WORKSPACE, self.tr("Workspace folder")))
        self.addParameter(QgsProcessingParameterFile(
            self.GCPS, self.tr("Ground control file (gcp_list.txt or CSV)"), optional=True,
            fileFilter="GCP files (*.txt *.csv);;All files (*)"))
        self.addParameter(QgsProcessingParameterFeatureSource(
            self.GCP_LAYER, self.tr("Ground control point layer (one feature per observation)"),
            [QgsProcessing.TypeVectorPoint], optional=True))
        self.addParameter(QgsProcessingParameterString(
            self.CHECK_POINTS, self.tr("Check points (comma-separated names)"), defaultValue="", optional=True))
        self.addParameter(QgsProcessingParameterBoolean(
            self.USE_EXIF_GPS, self.tr("Use EXIF GPS camera positions"), defaultValue=False))
        self.addParameter(QgsProcessingParameterFile(
            self.CAMERA_POSITIONS, self.tr("Camera positions (CSV)"), optional=True,
            fileFilter="CSV/text (*.csv *.txt);;All files (*)"))
        self.addParameter(QgsProcessingParameterCrs(
            self.CRS, self.tr("Target CRS (default: the GCP file's, or the UTM zone of the GPS)"), optional=True))
        self.addParameter(QgsProcessingParameterEnum(
            self.PAIRING, self.tr("Pair selection"), options=PAIRINGS, defaultValue=0))
        self.addParameter(QgsProcessingParameterEnum(
            self.CAMERA_MODEL, self.tr("Camera model"), options=CAMERA_MODELS, defaultValue=0))
        self.addParameter(QgsProcessingParameterNumber(
            self.MAX_IMAGE_SIZE, self.tr("Largest image side for matching (0 = full size)"),
            type=QgsProcessingParameterNumber.Integer, defaultValue=0, minValue=0))
        self.addParameter(QgsProcessingParameterBoolean(
            self.REFINE_INTRINSICS, self.tr("Refine camera calibration in the adjustment"), defaultValue=False))
        self.addParameter(QgsProcessingParameterNumber(
            self.DSM_RESOLUTION, self.tr("DSM resolution in metres (0 = automatic)"),
            type=QgsProcessingParameterNumber.Double, defaultValue=0.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterEnum(
            self.QUALITY, self.tr("Matching quality (image scale)"), options=list(BuildDsmAlgorithm.QUALITIES),
            defaultValue=1))
        self.addParameter(QgsProcessingParameterNumber(
            self.ORTHO_RESOLUTION, self.tr("Orthomosaic resolution (0 = ground sample distance)"),
            type=QgsProcessingParameterNumber.Double, defaultValue=0.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterEnum(
            self.BLENDING, self.tr("Blending across seamlines"), options=list(BuildOrthophotoAlgorithm.BLENDINGS),
            defaultValue=0))
        self.addParameter(QgsProcessingParameterBoolean(
            self.REPORT_ENABLED, self.tr("Write the accuracy report"), defaultValue=True))
        workers = QgsProcessingParameterNumber(
            self.WORKERS, self.tr("Parallel workers for dense matching and tiles (0 = one per core)"),
            type=QgsProcessingParameterNumber.Integer, defaultValue=0, minValue=0)
        scheduler = QgsProcessingParameterString(
            self.SCHEDULER, self.tr("Dask scheduler address (empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER)"), defaultValue="", optional=True)
        for p in (workers, scheduler):
            p.setFlags(p.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
            self.addParameter(p)
        self.addOutput(QgsProcessingOutputRasterLayer(self.DSM, self.tr("DSM")))
        self.addOutput(QgsProcessingOutputRasterLayer(self.ORTHOMOSAIC, self.tr("Orthomosaic")))
        self.addOutput(QgsProcessingOutputFile(self.REPORT, self.tr("Accuracy report (HTML)")))
        for name, label in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(name, self.tr(label)))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core import pipeline
        from ..core.align import sfm
        from ..core.dense import stage as dense
        from ..core.io import gcp as gcpmod
        from ..core.ortho import options as ortho

        p = parameters
        gcps = None
        source = self.parameterAsSource(p, self.GCP_LAYER, context)
        if source is not None:
            gcps = GeoreferenceAlgorithm()._gcps_from_layer(source, gcpmod)
        gcp_path = self.parameterAsFile(p, self.GCPS, context) or None
        positions = self.parameterAsFile(p, self.CAMERA_POSITIONS, context) or None
        use_gps = self.parameterAsBoolean(p, self.USE_EXIF_GPS, context)
        if gcp_path is None and gcps is None and not positions and not use_gps:
            raise QgsProcessingException(self.tr(
                "Give ground control (GCPS or GCP_LAYER) and/or camera positions (CAMERA_POSITIONS or USE_EXIF_GPS): "
                "the DSM and orthophoto need a georeferenced block"))
        crs = self.parameterAsCrs(p, self.CRS, context)
        workers = self.parameterAsInt(p, self.WORKERS, context)
        scheduler = self.parameterAsString(p, self.SCHEDULER, context).strip() or None
        result = self.run_core(
            pipeline.run_pipeline,
            self.parameterAsFile(p, self.IMAGES, context), self.parameterAsString(p, self.WORKSPACE, context),
            align_options=sfm.AlignOptions(
                pairing=PAIRINGS[self.parameterAsEnum(p, self.PAIRING, context)],
                camera_model=CAMERA_MODELS[self.parameterAsEnum(p, self.CAMERA_MODEL, context)],
                max_image_size=self.parameterAsInt(p, self.MAX_IMAGE_SIZE, context)),
            gcp_path=gcp_path, gcps=gcps,
            check_points=[s.strip() for s in self.parameterAsString(p, self.CHECK_POINTS, context).split(",")
                          if s.strip()],
            camera_positions_path=positions, use_exif_gps=use_gps,
            crs=(crs.authid() or crs.toWkt()) if crs.isValid() else None,
            refine_intrinsics=self.parameterAsBoolean(p, self.REFINE_INTRINSICS, context),
            dsm_resolution=self.parameterAsDouble(p, self.DSM_RESOLUTION, context),
            dsm_quality=BuildDsmAlgorithm.QUALITIES[self.parameterAsEnum(p, self.QUALITY, context)],
            dense_options=dense.DenseOptions(workers=workers, scheduler=scheduler),
            ortho_resolution=self.parameterAsDouble(p, self.ORTHO_RESOLUTION, context),
            blending=BuildOrthophotoAlgorithm.BLENDINGS[self.parameterAsEnum(p, self.BLENDING, context)],
            ortho_options=ortho.OrthoOptions(workers=workers, scheduler=scheduler),
            report=self.parameterAsBoolean(p, self.REPORT_ENABLED, context),
            progress=FeedbackProgress(feedback))
        for w in result.warnings:
            feedback.pushWarning(w)
        feedback.pushInfo(self.tr("Seconds per stage: {}").format(
            ", ".join(f"{k} {v:.1f}" for k, v in result.seconds.items())))
        g = result.georef.figures
        numbers = {"REGISTERED_IMAGES": result.align.registered,
                   "MEAN_REPROJECTION_ERROR": result.align.mean_reprojection_error,
                   "GCP_RMSE_XY": g.get("GCP_RMSE_XY"), "CHECK_RMSE_XY": g.get("CHECK_RMSE_XY"),
                   "CHECK_RMSE_Z": g.get("CHECK_RMSE_Z"), "CAMERA_RMSE_XYZ": g.get("CAMERA_RMSE_XYZ"),
                   "DSM_VALID_FRACTION": result.dsm.valid_fraction,
                   "ORTHO_VALID_FRACTION": result.ortho.valid_fraction}
        return dict(numbers, WORKSPACE=result.workspace, DSM=result.dsm.dsm_path,
                    ORTHOMOSAIC=result.ortho.orthomosaic, REPORT=result.report.path if result.report else None)
