"""Prepare images: thin adapter over core.prepare.stage.prepare_images_workspace (screening, scans, masks)."""
from qgis.core import (
    NULL,
    QgsGeometry,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterString,
    QgsWkbTypes,
)

from ..core.prepare import options as options_module
from . import params
from .base import AlgorithmBase, FeedbackProgress

FIDUCIAL_TYPES = list(options_module.FIDUCIAL_TYPES)  # the choices, defined once in core.prepare.options
FIDUCIAL_LAYOUTS = list(options_module.LAYOUT_NAMES)


class PrepareImagesAlgorithm(AlgorithmBase):
    NAME = "prepareimages"
    DISPLAY = "Prepare images"
    IMAGES = "IMAGES"
    WORKSPACE = "WORKSPACE"
    OUTPUT = "OUTPUT"
    BLUR_THRESHOLD = "BLUR_THRESHOLD"
    BLUR_RELATIVE = "BLUR_RELATIVE"
    EXCLUDE_FLAGGED = "EXCLUDE_FLAGGED"
    SKY_MASKS = "SKY_MASKS"
    MASKS = "MASKS"
    SCANNED_FILM = "SCANNED_FILM"
    FIDUCIAL_COORDINATES = "FIDUCIAL_COORDINATES"
    FOCAL_LENGTH_MM = "FOCAL_LENGTH_MM"
    FIDUCIAL_TYPE = "FIDUCIAL_TYPE"
    FIDUCIAL_LAYOUT = "FIDUCIAL_LAYOUT"
    FIDUCIAL_TEMPLATE = "FIDUCIAL_TEMPLATE"
    SCAN_DPI = "SCAN_DPI"
    PREPARED_IMAGES = "PREPARED_IMAGES"
    FLAGGED = "FLAGGED"
    EXCLUDED = "EXCLUDED"
    SCREENING = "SCREENING"
    HELP = (
        "Screens a folder of photographs for blur and exposure and, for scanned historical film, finds the "
        "fiducial marks and resamples every scan into one camera frame. The result is a folder of prepared "
        "images for 'Align images', and the Workspace folder, which records a decision per image (screening.json) "
        "for the accuracy report.\n\n"
        "The blur score is the variance of the Laplacian on a grey copy 1024 px wide, 90th percentile of an 8 x 6 grid of "
        "tiles (sky or water in part of a frame does not count against it). Higher is sharper. An image is "
        "flagged 'blurry' below a fraction of the median of the set (Flag images below this fraction of the "
        "set's median blur score, advanced), or below the Smallest blur score when that is set (0 = only relative "
        "to the set; absolute scores depend on the scene: sand scores far lower than roofs).\n"
        "Images with more than 5 % clipped highlights or shadows, a mean brightness far from the set's, or a "
        "very small dynamic range are flagged for their exposure. With 'Leave flagged images out' ticked they are "
        "left out of the prepared folder; otherwise they are kept and only reported.\n\n"
        "Mask polygons: optional polygon layer of areas to ignore in the alignment and the orthophoto (a boom, the drone's shadow, a date stamp, a frame "
        "border), in the image's pixel coordinates: origin at the upper-left corner of the image, x right, y "
        "down, or y = -row as the QGIS georeferencer shows a photo (detected when every y is <= 0). A text field "
        "'image' names the image a polygon belongs to; empty (or no such field) applies it to every image. "
        "The polygons are written into the per-image masks (workspace/masks/<image>.png, merged with any mask "
        "already there): 'Align images' finds no features under them, the orthophoto does not use those pixels, "
        "and blur and exposure are measured outside them. For scanned film the coordinates are those of the "
        "prepared images (the common fiducial frame, so one polygon fits every frame).\n"
        "Sky masks for oblique photos: the sky (clouds included) and the haze along the horizon are found "
        "automatically and written into the per-image masks, so that 'Align images' takes no tie points from "
        "clouds that move between shots; a photo without sky (looking straight down) gets no sky mask.\n\n"
        "Scanned film (fiducial marks): fiducial marks (crosses, dots, dots in circles; in the corners and/or the side "
        "middles, or like a template image of one mark) are found to a fraction of a pixel, each scan is "
        "resampled by an affine transform into the common fiducial frame, all with the same size and the "
        "principal point at the centre, and masks (workspace/masks) hide the film border, data strips and "
        "the marks from matching. Fiducial coordinates: the calibration certificate's calibrated fiducial "
        "coordinates in mm, as a file path or pasted text, one 'id x y' line per mark (x right, y up), optionally 'PP x y' "
        "(principal point) and 'focal f'. Without them the mean layout of the set is used, centred on the "
        "fiducial centre. With the Calibrated focal length (0 = unknown; or 'focal' in the certificate) the prepared images carry "
        "the focal length in pixels for the alignment.\n\n"
        "Prepared images: the folder of prepared images (replaced as a whole; it must be new, empty or written by an "
        "earlier run); when skipped, <workspace>/prepared."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.IMAGES, self.tr("Folder of images")),
            params.workspace_destination(self.WORKSPACE, self.tr("Workspace folder")),
            params.number(self.BLUR_THRESHOLD, self.tr("Smallest blur score (0 = relative only)")),
            params.flag(self.EXCLUDE_FLAGGED, self.tr("Leave flagged images out")),
        )
        self.addParameter(QgsProcessingParameterFeatureSource(
            self.MASKS, self.tr("Mask polygons"),
            [QgsProcessing.SourceType.TypeVectorPolygon], optional=True))
        self.addParameter(params.flag(self.SKY_MASKS, self.tr("Sky masks for oblique photos")))
        self.addParameter(params.flag(self.SCANNED_FILM, self.tr("Scanned film (fiducial marks)")))
        self.addParameter(QgsProcessingParameterString(
            self.FIDUCIAL_COORDINATES, self.tr("Fiducial coordinates (mm)"),
            multiLine=True, optional=True))
        params.add(
            self,
            params.number(self.FOCAL_LENGTH_MM, self.tr("Calibrated focal length (mm)")),
            *params.advanced(
                params.number(self.BLUR_RELATIVE, self.tr(
                    "Flag images below this fraction of the set's median blur score"), default=0.4, maxValue=1.0),
                params.choice(self.FIDUCIAL_TYPE, self.tr("Fiducial mark type"), FIDUCIAL_TYPES),
                params.choice(self.FIDUCIAL_LAYOUT, self.tr("Fiducial positions"), FIDUCIAL_LAYOUTS),
                QgsProcessingParameterFile(
                    self.FIDUCIAL_TEMPLATE, self.tr("Template image of one fiducial mark"), optional=True),
                params.number(self.SCAN_DPI, self.tr(
                    "Scan resolution in dpi when not in the files (0 = from the files)"))),
        )
        self.addParameter(QgsProcessingParameterFolderDestination(
            self.OUTPUT, self.tr("Prepared images"), optional=True,
            createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.PREPARED_IMAGES, self.tr("Folder of prepared images")))
        self.addOutput(QgsProcessingOutputNumber(self.FLAGGED, self.tr("Flagged images")))
        self.addOutput(QgsProcessingOutputNumber(self.EXCLUDED, self.tr("Excluded images")))
        self.addOutput(QgsProcessingOutputFile(self.SCREENING, self.tr("Screening record (JSON)")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.prepare.options import PrepareOptions, ScanOptions, ScreeningOptions
        from ..core.prepare.stage import prepare_images_workspace

        images = self.parameterAsFile(parameters, self.IMAGES, context)
        workspace = self.parameterAsString(parameters, self.WORKSPACE, context)
        output = self.parameterAsString(parameters, self.OUTPUT, context)
        dpi = self.parameterAsDouble(parameters, self.SCAN_DPI, context)
        scanned = self.parameterAsBoolean(parameters, self.SCANNED_FILM, context)
        options = PrepareOptions(
            screening=ScreeningOptions(
                blur_threshold=self.parameterAsDouble(parameters, self.BLUR_THRESHOLD, context),
                blur_relative=self.parameterAsDouble(parameters, self.BLUR_RELATIVE, context),
                exclude_flagged=self.parameterAsBoolean(parameters, self.EXCLUDE_FLAGGED, context),
            ),
            scanned_film=scanned,
            sky_masks=self.parameterAsBoolean(parameters, self.SKY_MASKS, context),
            scan=ScanOptions(
                fiducial_type=params.read_choice(self, parameters, self.FIDUCIAL_TYPE, context, FIDUCIAL_TYPES),
                layout=params.read_choice(self, parameters, self.FIDUCIAL_LAYOUT, context, FIDUCIAL_LAYOUTS),
                template_path=self.parameterAsFile(parameters, self.FIDUCIAL_TEMPLATE, context) or None,
                fiducial_coordinates=(self.parameterAsString(parameters, self.FIDUCIAL_COORDINATES, context)
                                      or "").strip() or None,
                focal_length_mm=self.parameterAsDouble(parameters, self.FOCAL_LENGTH_MM, context) or None,
                scan_pixel_size_mm=(25.4 / dpi) if dpi > 0 else None,
            ) if scanned else None,
        )
        source = self.parameterAsSource(parameters, self.MASKS, context)
        if source is not None:
            options.mask_polygons = self.mask_polygons(source, feedback)
            options.mask_source = self.tr("MASKS layer '{}'").format(source.sourceName())
        progress = FeedbackProgress(feedback)
        options.output_dir = output or None
        result = self.run_core(prepare_images_workspace, images, workspace, options, progress)
        progress.push_result(result.warnings)
        feedback.pushInfo(self.tr("{} images: {} flagged, {} excluded, {} in the prepared folder").format(
            len(result.images), result.flagged, result.excluded, result.kept))
        feedback.pushInfo(self.tr("Blurriest first (blur score, % of the set's median):"))
        for q in sorted(result.images, key=lambda q: q.blur_rank)[:10]:
            flags = ", ".join(q.flags) if q.flags else "ok"
            feedback.pushInfo(f"  {q.blur_rank:3d}. {q.name}: {q.blur_score:.1f} ({100 * q.blur_relative:.0f} %) "
                              f"{flags} -> {q.decision}")
        io = result.interior_orientation
        if io:
            focal = f", focal {io['focal_px']:.2f} px" if io.get("focal_px") else ""
            feedback.pushInfo(self.tr("Prepared scans: {} x {} px, pixel size {:.6g} {}{}").format(
                io["width"], io["height"], io["pixel_size"], io["frame_units"], focal))
        return {
            self.WORKSPACE: result.workspace,
            self.OUTPUT: result.prepared_dir,
            self.PREPARED_IMAGES: result.prepared_dir,
            self.FLAGGED: result.flagged,
            self.EXCLUDED: result.excluded,
            self.SCREENING: result.screening_path,
        }

    def mask_polygons(self, source, feedback=None):
        """The features of a polygon source as plain (image or None, [exterior, hole, ...], label) items."""
        fields = source.fields()
        image_field = next((i for i in range(fields.count()) if fields.at(i).name().lower() == "image"), -1)
        layer = source.sourceName()
        out = []
        for feature in source.getFeatures():
            if feedback is not None and feedback.isCanceled():
                break
            label = self.tr("feature {}").format(feature.id())
            geom = feature.geometry()
            if geom is None or geom.isNull() or geom.isEmpty():
                if feedback is not None:
                    feedback.pushWarning(self.tr("MASKS layer '{}': {} has no geometry: skipped").format(layer, label))
                continue
            if geom.type() != QgsWkbTypes.GeometryType.PolygonGeometry:
                raise QgsProcessingException(self.tr("MASKS layer '{}': {} is a {} geometry, not a polygon").format(
                    layer, label, QgsWkbTypes.displayString(geom.wkbType())))
            if QgsWkbTypes.isCurvedType(geom.wkbType()):
                geom = QgsGeometry(geom.constGet().segmentize())
            image = None
            if image_field >= 0:
                value = feature.attribute(image_field)
                image = None if value is None or value == NULL else (str(value).strip() or None)
            parts = geom.asMultiPolygon() if geom.isMultipart() else [geom.asPolygon()]
            for part in parts:
                rings = [[(p.x(), p.y()) for p in ring] for ring in part]
                if rings:
                    out.append((image, rings, label))
        return out
