"""Build orthophoto: thin adapter over core.ortho.stage.build_orthophoto_workspace."""
from qgis.core import (
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorDestination,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class BuildOrthophotoAlgorithm(AlgorithmBase):
    NAME = "buildorthophoto"
    DISPLAY = "Build orthophoto"
    WORKSPACE = "WORKSPACE"
    DSM = "DSM"
    IMAGES_FILTER = "IMAGES_FILTER"
    RESOLUTION = "RESOLUTION"
    BLENDING = "BLENDING"
    INTERPOLATION = "INTERPOLATION"
    GSD_FACTOR = "GSD_FACTOR"
    WORKERS = "WORKERS"
    SCHEDULER = "DASK_SCHEDULER"
    OUTPUT = "OUTPUT"
    PER_IMAGE_FOLDER = "PER_IMAGE_FOLDER"
    SEAMLINES = "SEAMLINES"
    SEAMLINES_IN = "SEAMLINES_IN"
    RADIOMETRY = "RADIOMETRY"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    VALID_FRACTION = "VALID_FRACTION"
    RESOLUTION_USED = "RESOLUTION_USED"
    IMAGES_USED = "IMAGES_USED"
    BLENDINGS = params.BLENDINGS
    OUTPUT_KINDS = {OUTPUT: "ortho"}  # the output's style and layer name (qgisio/layers.py): its id does not say
    INTERPOLATIONS = params.INTERPOLATIONS
    HELP = (
        "True orthophotos and the orthomosaic of a georeferenced workspace.\n\n"
        "Every cell takes its height from the DSM and is projected through the full camera model (pose, focal "
        "length, principal point, lens distortion) into the images. A cell hidden from an image by higher surface "
        "(a wall, a tree, a hill) is left out of that image, so buildings do not lean and nothing appears twice; "
        "the mosaic fills it from an image that sees it. Each part of the mosaic comes from the image that looks "
        "at it most vertically and closest to its centre; seamlines go around buildings and trees; brightness "
        "differences between images are evened out and seams blended.\n\n"
        "Georeferenced workspace: a workspace with a DSM (run 'Build DSM' first), or give a DSM.\n"
        "DSM: optional raster (e.g. an ALS DSM, in any CRS: reprojected on the fly); default the workspace DSM.\n"
        "Images: a subset, e.g. 'DJI_00*.JPG', 'IMG_0012.tif, IMG_0013.tif', 'group:2' or 'group:NIR' "
        "(a camera group by id or by make/model), '!name' to leave one out. Empty: all images.\n"
        "Resolution: cell size in CRS units; 0 = the images' ground sample distance.\n"
        "Seam blending: feather (a ramp across seams), multiband (Laplacian pyramid: no visible seam in brightness "
        "and no ghosting), none (hard cut).\n"
        "Even out vignetting and hot spot: the darkening towards the photos' corners, the bright patch opposite the "
        "sun and the exposure of each photo are measured where the photos overlap and removed, then a smooth gain "
        "per photo levels the seams, so photos taken at different times meet without a brightness step (used only "
        "where it makes the overlaps agree better; off: one exposure gain per photo).\n"
        "Far-field limit (advanced): each image is used only where its ground resolution is within this factor of "
        "its best, so the stretched far field of an oblique (towards the horizon) is left out and the mosaic takes "
        "those cells from a nearer view; cells no image sees finely enough stay empty. 0 = off (default 3).\n"
        "Orthomosaic: Cloud-Optimized GeoTIFF with overviews, the images' bands and data type (8/16 bit kept) plus "
        "an alpha band (default <workspace>/orthomosaic.tif).\n"
        "Per-image orthophotos folder: optional folder for one true orthophoto per image (COG).\n"
        "Seamlines: optional GeoPackage of polygons naming the image each part of the mosaic comes from (one "
        "polygon per image, its name in the field 'image'); edit it to move a seam.\n"
        "Seamlines to follow: optional edited seamlines (polygons with the field 'image', in the mosaic's CRS): "
        "where a polygon names an image, the mosaic takes that image where it sees the ground (the log says where "
        "it does not); automatic seams elsewhere. Reshape a polygon, or draw one and name its image, to move a "
        "seam off a crop mark or a moving car, and run again.\n"
        "Dask scheduler (advanced): render the tiles on a Dask cluster (tcp://host:8786) whose workers see the "
        "workspace path; empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Georeferenced workspace")),
            QgsProcessingParameterRasterLayer(self.DSM, self.tr("DSM"), optional=True),
            QgsProcessingParameterString(
                self.IMAGES_FILTER, self.tr("Images"),
                defaultValue="", optional=True),
            params.number(self.RESOLUTION, self.tr("Resolution (CRS units, 0 = GSD)")),
            params.blending(self.BLENDING, self.tr("Seam blending")),
            params.flag(self.RADIOMETRY, self.tr("Even out vignetting and hot spot"), default=True),
            QgsProcessingParameterFeatureSource(
                self.SEAMLINES_IN, self.tr("Seamlines to follow"), [QgsProcessing.SourceType.TypeVectorPolygon],
                optional=True),
            *params.advanced(
                params.choice(self.INTERPOLATION, self.tr("Resampling"), self.INTERPOLATIONS),
                params.number(self.GSD_FACTOR, self.tr(
                    "Far-field limit (× best ground resolution, 0 = off)"), default=3.0),
                params.workers(self.WORKERS, self.tr("Parallel tile workers"), default=1),
                params.scheduler(self.SCHEDULER, self.tr("Dask scheduler"))),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(
            self.OUTPUT, self.tr("Orthomosaic"), optional=True,
            createByDefault=False))
        self.addParameter(QgsProcessingParameterFolderDestination(
            self.PER_IMAGE_FOLDER, self.tr("Per-image orthophotos folder"), optional=True,
            createByDefault=False))
        self.addParameter(QgsProcessingParameterVectorDestination(
            self.SEAMLINES, self.tr("Seamlines"), optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputNumber(self.VALID_FRACTION, self.tr("Share of mosaic cells with data")))
        self.addOutput(QgsProcessingOutputNumber(self.RESOLUTION_USED, self.tr("Resolution used")))
        self.addOutput(QgsProcessingOutputNumber(self.IMAGES_USED, self.tr("Images in the mosaic")))

    def seamlines_in(self, parameters, context, feedback):
        """The edited seamlines as a file the core reads ('path|layername=...'; a layer that is not a file is
        written to a temporary GeoPackage first); None when not given."""
        if not parameters.get(self.SEAMLINES_IN):
            return None
        path, layer = self.parameterAsCompatibleSourceLayerPathAndLayerName(
            parameters, self.SEAMLINES_IN, context, ["gpkg", "shp", "geojson", "fgb"], "gpkg", feedback)
        if not path:
            return None
        return f"{path}|layername={layer}" if layer else path

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.ortho.options import OrthoOptions
        from ..core.ortho.stage import build_orthophoto_workspace

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        dsm_layer = self.parameterAsRasterLayer(parameters, self.DSM, context)
        dsm_path = dsm_layer.source() if dsm_layer is not None else None
        output = self.parameterAsOutputLayer(parameters, self.OUTPUT, context) or None
        per_image = None
        if parameters.get(self.PER_IMAGE_FOLDER):
            per_image = self.parameterAsFileOutput(parameters, self.PER_IMAGE_FOLDER, context) or None
        seamlines = self.parameterAsOutputLayer(parameters, self.SEAMLINES, context) or None
        if seamlines and not seamlines.lower().endswith(".gpkg"):
            raise QgsProcessingException(self.tr("Seamlines must be a GeoPackage (.gpkg) file, got {}").format(
                seamlines))
        options = self.run_core(
            OrthoOptions, dsm_path=dsm_path,
            images_filter=self.parameterAsString(parameters, self.IMAGES_FILTER, context).strip() or None,
            resolution=self.parameterAsDouble(parameters, self.RESOLUTION, context),
            blending=params.read_choice(self, parameters, self.BLENDING, context, self.BLENDINGS),
            output=output, per_image_folder=per_image, seamlines=seamlines,
            interpolation=params.read_choice(self, parameters, self.INTERPOLATION, context, self.INTERPOLATIONS),
            gsd_factor=self.parameterAsDouble(parameters, self.GSD_FACTOR, context),
            radiometry=self.parameterAsBoolean(parameters, self.RADIOMETRY, context),
            workers=self.parameterAsInt(parameters, self.WORKERS, context),
            scheduler=params.read_scheduler(self, parameters, self.SCHEDULER, context),
            seamlines_in=self.seamlines_in(parameters, context, feedback))
        progress = FeedbackProgress(feedback)
        result = self.run_core(build_orthophoto_workspace, workspace, options, progress)
        progress.push_result(result.warnings, result.log_lines)
        return {self.OUT_WORKSPACE: result.workspace, self.OUTPUT: result.orthomosaic,
                self.PER_IMAGE_FOLDER: result.per_image_folder, self.SEAMLINES: result.seamlines,
                self.VALID_FRACTION: result.valid_fraction, self.RESOLUTION_USED: result.resolution,
                self.IMAGES_USED: len(result.images)}
