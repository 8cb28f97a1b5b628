"""Run pipeline: thin adapter over core.pipeline.run_pipeline (align -> georeference -> DSM -> orthomosaic -> report)."""
from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputHtml,
    QgsProcessingOutputNumber,
    QgsProcessingOutputRasterLayer,
    QgsProcessingParameterFile,
    QgsProcessingParameterString,
)
from qgis.PyQt.QtCore import QCoreApplication

from . import params
from .base import AlgorithmBase, FeedbackProgress, styling_enabled
from .params import BLENDINGS, CAMERA_MODELS, PAIRINGS, QUALITIES


class RunPipelineAlgorithm(AlgorithmBase):
    NAME = "runpipeline"
    DISPLAY = "Run pipeline"
    HELP_SECTION = "The whole chain: Run pipeline and the shipped model"
    IMAGES = "IMAGES"
    WORKSPACE = "WORKSPACE"
    GCPS = "GCPS"
    GCP_LAYER = "GCP_LAYER"
    CHECK_POINTS = "CHECK_POINTS"
    TARGETS = "TARGETS"
    TARGET_KIND = "TARGET_KIND"
    USE_EXIF_GPS = "USE_EXIF_GPS"
    CAMERA_POSITIONS = "CAMERA_POSITIONS"
    CRS = "CRS"
    PAIRING = "PAIRING"
    CAMERA_MODEL = "CAMERA_MODEL"
    MAX_IMAGE_SIZE = "MAX_IMAGE_SIZE"
    CALIBRATION = "CALIBRATION"
    INTRINSICS = "INTRINSICS"
    REFINE_INTRINSICS = "REFINE_INTRINSICS"
    DSM_RESOLUTION = "DSM_RESOLUTION"
    QUALITY = "QUALITY"
    ORTHO_RESOLUTION = "ORTHO_RESOLUTION"
    BLENDING = "BLENDING"
    REPORT_ENABLED = "MAKE_REPORT"
    DTM_ENABLED = "MAKE_DTM"
    MODEL_ENABLED = "MAKE_MODEL"
    MODEL_TILESET = "MODEL_TILESET"
    CONTOUR_INTERVAL = "CONTOUR_INTERVAL"
    RELIEF = "RELIEF"
    CAPTURE_RADIOMETRY = "CAPTURE_RADIOMETRY"
    PANEL = "PANEL"
    PANEL_REFLECTANCE = "PANEL_REFLECTANCE"
    PANEL_WINDOW = "PANEL_WINDOW"
    GCPS_UPRIGHT = "GCPS_UPRIGHT"
    SKY_MASKS = "SKY_MASKS"
    DTM = "DTM"
    WORKERS = "WORKERS"
    SCHEDULER = "DASK_SCHEDULER"
    DSM = "DSM"
    ORTHOMOSAIC = "ORTHOMOSAIC"
    ORTHOMOSAIC_RGB = "ORTHOMOSAIC_RGB"
    REPORT = "REPORT"
    NUMBERS = (("REGISTERED_IMAGES", "Registered images"), ("MEAN_REPROJECTION_ERROR", "Mean reprojection error (px)"),
               ("GCP_RMSE_XY", "Control RMSE XY (m)"), ("CHECK_RMSE_XY", "Check RMSE XY (m)"),
               ("CHECK_RMSE_Z", "Check RMSE Z (m)"), ("CAMERA_RMSE_XYZ", "Camera position RMSE XYZ (m)"),
               ("DSM_VALID_FRACTION", "DSM valid fraction"), ("ORTHO_VALID_FRACTION", "Orthomosaic valid fraction"))
    HELP = (
        "The whole chain in one call, for batch use: Align images, Georeference, Build DSM, Build orthophoto "
        "and Accuracy report on one workspace. It calls the same functions as the single algorithms, and a "
        "re-run resumes (features, matches and dense pairs already computed are reused).\n\n"
        "Folder of images: the photos; a folder of a multispectral rig's band files (Parrot Sequoia, MicaSense, "
        "DJI multispectral) is recognised, and its captures are first stacked into multi-band photos in "
        "<workspace>/captures (as 'Stack multispectral captures'), which the chain then takes. Workspace folder: "
        "where every product is written.\n"
        "Capture radiometry (advanced; with a band folder): as Radiometry in 'Stack multispectral captures': "
        "normalised (default) removes each band's dark level, corrects its vignetting from the file's model and "
        "normalises exposure time and gain to the block's; irradiance also divides by the sun sensor's irradiance "
        "for that band (values proportional to reflectance when the light changes during the flight); raw keeps "
        "the numbers as recorded. A band file lacking what the choice needs (an exposure time, a sun-sensor "
        "reading) stops the run before the alignment, naming the file. A calibration panel is corrected the same "
        "way.\n"
        "Calibration panel folder and Panel reflectance (advanced, optional; with a band folder): as in 'Stack "
        "multispectral captures': the band files of the calibration panel's captures, in a folder of their own, "
        "and the panel's reflectance (one number, per band as Green=0.49,Red=0.50, or a CSV file); the stacked "
        "photos, and so the orthomosaic, then hold reflectance (float32). A bad panel (saturated or not uniform in "
        "its centre, another camera, a band missing, a reflectance for a band the rig lacks) stops the run before "
        "the alignment, naming the file; so does a panel given with a folder of photos that is not a band folder. "
        "Panel window (advanced): the side of the central square the panel is measured in, a fraction of the "
        "photo's short side.\n"
        "Georeferencing needs ground control (a Ground control file or layer, Check points held out) and/or camera "
        "positions (a Camera positions CSV or Use EXIF GPS positions): without them the pipeline refuses, since a "
        "DSM needs a metric scale and a vertical direction. GCP pixels measured on upright photos: as in "
        "'Georeference' (the pixel coordinates measured on the photos shown upright by their EXIF orientation).\n"
        "Targets to find (instead of a ground control file or layer): the surveyed coordinates of targets laid on "
        "the ground; after the alignment 'Find targets' finds them on the photos and its observations are the "
        "ground control (Target kind, advanced: as in 'Find targets').\n"
        "Camera calibration file and Interior orientation (advanced): as in 'Align images' (a calibrated camera "
        "held fixed through the whole chain, or refined with its standard deviations).\n"
        "Sky masks (oblique photos): first a 'Prepare images' stage finds the sky and the horizon haze in each "
        "photo and masks them, so that no tie point or DSM point comes from the sky; the prepared photos are "
        "aligned (off by default: photos looking straight down need none).\n"
        "Build the DTM: after the DSM, a bare-earth DTM (as 'Build DTM'). Contour interval (advanced): contour lines "
        "of the DTM at this interval (as 'Contours'; 0 = none). Relief visualisations (advanced): those chosen "
        "are computed from the DTM (as 'Relief visualisation'). Both need the DTM.\n"
        "The other parameters are those of the single stages (see their help); 0 means automatic.\n"
        "Outputs: the DSM, the orthomosaic and the accuracy report (HTML), plus the key figures; with a band folder "
        "that also holds the rig's RGB frames, also RGB orthomosaic (a rig's RGB frames): those frames' own "
        "orthomosaic, <orthomosaic>_rgb.tif beside the captures' multi-band one (none when no RGB frame is "
        "registered)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.georef.targets.options import KINDS as TARGET_KINDS
        from ..core.prepare.band_radiometry import MODES, PANEL_WINDOW

        params.add(
            self,
            params.folder(self.IMAGES, self.tr("Folder of images")),
            params.workspace_destination(self.WORKSPACE, self.tr("Workspace folder")),
            params.gcp_file(self.GCPS, self.tr("Ground control file")),
            params.gcp_layer(self.GCP_LAYER, self.tr("Ground control layer")),
            params.gcp_file(self.TARGETS, self.tr("Targets to find")),
            params.check_points(self.CHECK_POINTS, self.tr("Check points")),
            params.flag(self.GCPS_UPRIGHT, self.tr("GCP pixels measured on upright photos")),
            params.flag(self.USE_EXIF_GPS, self.tr("Use EXIF GPS positions")),
            params.camera_positions(self.CAMERA_POSITIONS, self.tr("Camera positions (CSV)")),
            params.target_crs(self.CRS, self.tr("Target CRS")),
            params.pairing(self.PAIRING, self.tr("Pair selection")),
            params.camera_model(self.CAMERA_MODEL, self.tr("Camera model")),
            params.max_image_size(self.MAX_IMAGE_SIZE, self.tr("Matching image size (px)")),
            params.flag(self.SKY_MASKS, self.tr("Sky masks (oblique photos)")),
            params.flag(self.REFINE_INTRINSICS, self.tr("Refine camera calibration")),
            params.dsm_resolution(self.DSM_RESOLUTION, self.tr("DSM resolution (m)")),
            params.quality(self.QUALITY, self.tr("Matching quality")),
            params.number(self.ORTHO_RESOLUTION, self.tr("Orthomosaic resolution (CRS units, 0 = GSD)")),
            params.blending(self.BLENDING, self.tr("Seam blending")),
            params.flag(self.REPORT_ENABLED, self.tr("Write the accuracy report"), default=True),
            params.flag(self.DTM_ENABLED, self.tr("Build the DTM"), default=True),
            params.flag(self.MODEL_ENABLED, self.tr("Build the textured 3-D model"), default=False),
            *params.advanced(
                params.calibration_file(self.CALIBRATION, self.tr("Camera calibration file")),
                params.intrinsics(self.INTRINSICS, self.tr("Interior orientation")),
                params.choice(self.TARGET_KIND, self.tr("Target kind"), list(TARGET_KINDS), 0),
                params.workers(self.WORKERS, self.tr("Parallel workers")),
                params.scheduler(self.SCHEDULER, self.tr("Dask scheduler")),
                params.number(self.CONTOUR_INTERVAL, self.tr("Contour interval (m, 0 = none)")),
                params.relief_choice(self.RELIEF, self.tr("Relief visualisations")),
                params.choice(self.CAPTURE_RADIOMETRY, self.tr("Capture radiometry"), MODES,
                              default=MODES.index("normalised")),
                QgsProcessingParameterFile(self.PANEL, self.tr("Calibration panel folder"),
                                           behavior=QgsProcessingParameterFile.Behavior.Folder, optional=True),
                QgsProcessingParameterString(self.PANEL_REFLECTANCE, self.tr("Panel reflectance"), optional=True),
                params.number(self.PANEL_WINDOW, self.tr("Panel window"), PANEL_WINDOW, 0.02, maxValue=1.0)),
        )
        self.addOutput(QgsProcessingOutputRasterLayer(self.DTM, self.tr("DTM")))
        self.addOutput(QgsProcessingOutputRasterLayer(self.DSM, self.tr("DSM")))
        self.addOutput(QgsProcessingOutputRasterLayer(self.ORTHOMOSAIC, self.tr("Orthomosaic")))
        self.addOutput(QgsProcessingOutputRasterLayer(self.ORTHOMOSAIC_RGB,
                                                      self.tr("RGB orthomosaic (a rig's RGB frames)")))
        # an HTML output: the toolbox dialog lists it in the Results Viewer, which opens it (a plain file output
        # was nowhere in the GUI: issue 36 item 15)
        self.addOutput(QgsProcessingOutputHtml(self.REPORT, self.tr("Accuracy report (HTML)")))
        self.addOutput(QgsProcessingOutputFile(self.MODEL_TILESET, self.tr("3-D model (3D Tiles)")))
        for name, label in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(name, self.tr(label)))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core import pipeline
        from ..core.align.options import AlignOptions
        from ..core.dense.options import DenseOptions
        from ..core.georef.options import GeorefOptions
        from ..core.georef.targets.options import KINDS as TARGET_KINDS
        from ..core.georef.targets.options import FindTargetsOptions
        from ..core.ortho.options import OrthoOptions
        from ..core.report.options import ReportOptions
        from ..core.terrain.options import ReliefStageOptions, TerrainOptions
        from ..qgisio.messages import report_language

        p = parameters
        gcps = params.read_gcp_layer(self, p, self.GCP_LAYER, context, QCoreApplication.translate(
            "GeoreferenceAlgorithm", "GCP layer {} lacks the field '{}' (needs name, image, px, py)"))
        gcp_path = params.read_optional_file(self, p, self.GCPS, context)
        positions = params.read_optional_file(self, p, self.CAMERA_POSITIONS, context)
        use_gps = self.parameterAsBoolean(p, self.USE_EXIF_GPS, context)
        targets = params.read_optional_file(self, p, self.TARGETS, context)
        if not params.has_control(gcp_path, gcps, positions, use_gps) and not targets:
            raise QgsProcessingException(self.tr(
                "Give ground control (Ground control file or layer, or targets to find: GCPS, GCP_LAYER, TARGETS) "
                "and/or camera positions "
                "(Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS): the DSM and "
                "orthophoto need a georeferenced block"))
        crs_text = params.read_crs(self, p, self.CRS, context)
        checks = params.read_names(self, p, self.CHECK_POINTS, context)
        workers = self.parameterAsInt(p, self.WORKERS, context)
        scheduler = params.read_scheduler(self, p, self.SCHEDULER, context)
        progress = FeedbackProgress(feedback)
        result = self.run_core(
            pipeline.run_pipeline,
            self.parameterAsFile(p, self.IMAGES, context), self.parameterAsString(p, self.WORKSPACE, context),
            options=pipeline.PipelineOptions(
                align=AlignOptions(
                    pairing=params.read_choice(self, p, self.PAIRING, context, PAIRINGS),
                    camera_model=params.read_choice(self, p, self.CAMERA_MODEL, context, CAMERA_MODELS),
                    max_image_size=self.parameterAsInt(p, self.MAX_IMAGE_SIZE, context),
                    calibration=params.read_optional_file(self, p, self.CALIBRATION, context),
                    intrinsics=params.read_choice(self, p, self.INTRINSICS, context, params.INTRINSICS)),
                targets=FindTargetsOptions(kind=TARGET_KINDS[self.parameterAsEnum(p, self.TARGET_KIND, context)]),
                georef=GeorefOptions(refine_intrinsics=self.parameterAsBoolean(p, self.REFINE_INTRINSICS, context)),
                dense=DenseOptions(quality=params.read_choice(self, p, self.QUALITY, context, QUALITIES),
                                   resolution=self.parameterAsDouble(p, self.DSM_RESOLUTION, context),
                                   workers=workers, scheduler=scheduler),
                ortho=OrthoOptions(resolution=self.parameterAsDouble(p, self.ORTHO_RESOLUTION, context),
                                   blending=params.read_choice(self, p, self.BLENDING, context, BLENDINGS),
                                   workers=workers, scheduler=scheduler),
                make_report=self.parameterAsBoolean(p, self.REPORT_ENABLED, context),
                report=ReportOptions(language=report_language()),  # the report's headings in QGIS's language
                make_dtm=self.parameterAsBoolean(p, self.DTM_ENABLED, context),
                make_model=self.parameterAsBoolean(p, self.MODEL_ENABLED, context),
                terrain=TerrainOptions(contour_interval=self.parameterAsDouble(p, self.CONTOUR_INTERVAL, context)),
                relief=ReliefStageOptions(params.read_relief(self, p, self.RELIEF, context)),
                sky_masks=self.parameterAsBoolean(p, self.SKY_MASKS, context),
                **self._captures(p, context)),
            control=pipeline.Control(gcp_path=gcp_path, gcps=gcps, check_points=checks,
                                     camera_positions_path=positions, use_exif_gps=use_gps, crs=crs_text,
                                     targets_path=targets,
                                     gcps_upright=self.parameterAsBoolean(p, self.GCPS_UPRIGHT, context)),
            progress=progress)
        progress.push_result(result.warnings)  # those the stages did not log while they ran
        feedback.pushInfo(self.tr("Seconds per stage: {}").format(
            ", ".join(f"{k} {v:.1f}" for k, v in result.seconds.items())))
        g = result.georef.figures
        ortho, rgb = result.ortho, result.ortho_rgb  # either None where none of its photos registered (warned)
        numbers = {"REGISTERED_IMAGES": result.align.registered,
                   "MEAN_REPROJECTION_ERROR": result.align.mean_reprojection_error,
                   "GCP_RMSE_XY": g.get("GCP_RMSE_XY"), "CHECK_RMSE_XY": g.get("CHECK_RMSE_XY"),
                   "CHECK_RMSE_Z": g.get("CHECK_RMSE_Z"), "CAMERA_RMSE_XYZ": g.get("CAMERA_RMSE_XYZ"),
                   "DSM_VALID_FRACTION": result.dsm.valid_fraction,
                   "ORTHO_VALID_FRACTION": ortho.valid_fraction if ortho is not None else None}
        return dict(numbers, WORKSPACE=result.workspace, DSM=result.dsm.dsm_path,
                    ORTHOMOSAIC=ortho.orthomosaic if ortho is not None else None,
                    ORTHOMOSAIC_RGB=rgb.orthomosaic if rgb is not None else None,
                    REPORT=result.report.path if result.report else None,
                    DTM=result.dtm.dtm_path if result.dtm else None,
                    MODEL_TILESET=next((f for f in result.model.files if f.endswith("tileset.json")), None)
                    if result.model else None)

    def register_styled_outputs(self, results, context, feedback=None):
        """The styled layers, and the 3-D model's 3D Tiles as a tiled scene layer (QGIS 3.34+)."""
        count = super().register_styled_outputs(results, context, feedback)
        if not styling_enabled():
            return count
        from ..qgisio.scene_layers import register_tiled_scene

        return count + register_tiled_scene(results, self.MODEL_TILESET, context, feedback)

    def _captures(self, p, context):
        """The band folder's radiometry and calibration panel: PipelineOptions fields
        (core.prepare.captures.CaptureStackOptions checks them)."""
        from ..core.prepare.band_radiometry import MODES

        panel = self.parameterAsFile(p, self.PANEL, context).strip()
        return {"capture_radiometry": params.read_choice(self, p, self.CAPTURE_RADIOMETRY, context, MODES),
                "capture_panel": (panel,) if panel else (),
                "capture_panel_reflectance": self.parameterAsString(p, self.PANEL_REFLECTANCE, context).strip(),
                "capture_panel_window": self.parameterAsDouble(p, self.PANEL_WINDOW, context)}
