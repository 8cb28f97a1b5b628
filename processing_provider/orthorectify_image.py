"""Orthorectify image: thin adapter over core.ortho.single.orthorectify_image."""
from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFile,
    QgsProcessingParameterPoint,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterVectorDestination,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class OrthorectifyImageAlgorithm(AlgorithmBase):
    NAME = "orthorectifyimage"
    DISPLAY = "Orthorectify image"
    IMAGE = "IMAGE"
    DSM = "DSM"
    GCPS = "GCPS"
    GCP_LAYER = "GCP_LAYER"
    ORIENTATION = "ORIENTATION"
    REFERENCE_ORTHO = "REFERENCE_ORTHO"
    LOCATION = "LOCATION"
    SEARCH_RADIUS = "SEARCH_RADIUS"
    AUTO_GCPS = "AUTO_GCPS"
    FOCAL_MM = "FOCAL_MM"
    SENSOR_WIDTH_MM = "SENSOR_WIDTH_MM"
    MODE = "MODE"
    RESOLUTION = "RESOLUTION"
    CRS = "CRS"
    OUTPUT = "OUTPUT"
    RESIDUALS = "RESIDUALS"
    RMSE_PX = "RMSE_PX"
    PLANAR_OFFSET_P95 = "PLANAR_OFFSET_P95"
    MODES = ("ortho", "planar")
    HELP = (
        "Orthorectifies one photograph — also one that is not part of any block, such as a single oblique or an "
        "old print — on an existing DSM, for example an airborne laser scanning (ALS) DSM in any CRS (it is "
        "reprojected on the fly).\n\n"
        "The camera's position and attitude come from ground control points observed in the photo (space "
        "resection: at least 4 points; one wrong point among 5 or more is found and left out; with 6 or more the "
        "focal length and the radial distortion k1 are estimated too where the points determine them), or from a "
        "known orientation.\n\n"
        "Image: the photo. DSM: height raster (needed for a true orthophoto).\n"
        "Ground control file: an OpenDroneMap gcp_list.txt or CSV points file with observations in this image; "
        "or Ground control point layer: a "
        "point layer with one feature per observation and fields name, image, px, py (optional z, role; pixel "
        "origin at the upper-left corner, y down).\n"
        "Known orientation: instead of GCPs, a file with x y z omega phi kappa (degrees, photogrammetric convention; "
        "a header row as Pix4D writes it, or JSON), optionally focal_mm, sensor_width_mm, cx, cy, k1, k2, p1, p2 "
        "and a CRS line.\n"
        "Reference orthophoto (automatic control): with no GCPs and no known orientation, the photo is matched to "
        "this orthophoto (any CRS, any resolution; the DSM is then the reference DSM) and the matches become "
        "automatic GCPs (auto_001, ...) for the space resection: no hand-picked point, the heading need not be "
        "known, obliques work too, and the focal length is estimated when the photo has none. Rough location: a "
        "point on the ground the photo shows (any CRS; empty = anywhere on the reference); Search radius: how far "
        "off it may be (metres). The log says how many matches survived each step; the GCP residuals list the "
        "automatic GCPs.\n"
        "Focal length and Sensor width: interior orientation in mm (the sensor's long side); 0 or empty = the "
        "EXIF focal length.\n"
        "Mode: a true orthophoto on the DSM, or a planar (projective) rectification through the GCPs for "
        "comparison on flat ground; with a DSM the log and the output "
        "'Planar rectification: 95th percentile of its offset' say how far the planar result is "
        "off because of relief.\n"
        "Resolution: cell size in CRS units (0 = the ground sample distance).\n"
        "Output CRS: default the CRS of the GCPs or of the known orientation.\n"
        "GCP residuals: GeoPackage of the GCPs with their residuals in pixels (and metres on the plane)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        self.addParameter(QgsProcessingParameterFile(
            self.IMAGE, self.tr("Image"), fileFilter="Images (*.jpg *.jpeg *.tif *.tiff *.png);;All files (*)"))
        params.add(
            self,
            QgsProcessingParameterRasterLayer(self.DSM, self.tr("DSM"), optional=True),
            params.gcp_file(self.GCPS, self.tr("Ground control file")),
            params.gcp_layer(self.GCP_LAYER, self.tr("Ground control point layer")),
            QgsProcessingParameterFile(
                self.ORIENTATION, self.tr("Known orientation"), optional=True,
                fileFilter="Orientation (*.txt *.csv *.json);;All files (*)"),
            QgsProcessingParameterRasterLayer(
                self.REFERENCE_ORTHO, self.tr("Reference orthophoto"), optional=True),
            QgsProcessingParameterPoint(self.LOCATION, self.tr("Rough location"), optional=True),
            params.number(self.SEARCH_RADIUS, self.tr("Search radius (m)"), default=50.0),
            params.number(self.FOCAL_MM, self.tr("Focal length (mm)"), optional=True),
            params.number(self.SENSOR_WIDTH_MM, self.tr("Sensor width (mm)"), optional=True),
            params.choice(self.MODE, self.tr("Mode"), (self.tr("True orthophoto on the DSM"),
                                                        self.tr("Planar rectification (flat ground)"))),
            params.number(self.RESOLUTION, self.tr("Resolution (0 = automatic)")),
            params.target_crs(self.CRS, self.tr("Output CRS")),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(self.OUTPUT, self.tr("Orthophoto")))
        self.addParameter(QgsProcessingParameterVectorDestination(
            self.RESIDUALS, self.tr("GCP residuals"), optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputNumber(self.RMSE_PX, self.tr("GCP residual RMSE (pixels)")))
        self.addOutput(QgsProcessingOutputNumber(self.AUTO_GCPS, self.tr("Automatic GCPs used")))
        self.addOutput(QgsProcessingOutputNumber(self.PLANAR_OFFSET_P95, self.tr(
            "Planar rectification: 95th percentile of its offset from the true position (CRS units)")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.ortho import single as ortho
        from ..core.ortho.options import OrthoOptions, SingleImageOptions

        image = self.parameterAsFile(parameters, self.IMAGE, context)
        dsm_layer = self.parameterAsRasterLayer(parameters, self.DSM, context)
        dsm_path = dsm_layer.source() if dsm_layer is not None else None
        gcps = params.read_optional_file(self, parameters, self.GCPS, context)
        layer_gcps = params.read_gcp_layer(self, parameters, self.GCP_LAYER, context, self.tr(
            "GCP layer {} lacks the field '{}' (needs name, image, px, py)"))
        if layer_gcps is not None:
            gcps = layer_gcps
        orientation = params.read_optional_file(self, parameters, self.ORIENTATION, context)
        ref_layer = self.parameterAsRasterLayer(parameters, self.REFERENCE_ORTHO, context)
        if gcps is None and orientation is None and ref_layer is None:
            raise QgsProcessingException(self.tr(
                "Give ground control points observed in the image (Ground control file or Ground control point layer: "
                "GCPS, GCP_LAYER), its Known orientation (ORIENTATION) or a Reference orthophoto for automatic "
                "control (REFERENCE_ORTHO)"))
        location = None
        if ref_layer is not None and parameters.get(self.LOCATION) not in (None, ""):
            p = self.parameterAsPoint(parameters, self.LOCATION, context, ref_layer.crs())  # in the reference's CRS
            location = (p.x(), p.y())
        crs_text = params.read_crs(self, parameters, self.CRS, context)
        residuals = self.parameterAsOutputLayer(parameters, self.RESIDUALS, context) or None
        if residuals and not residuals.lower().endswith(".gpkg"):
            raise QgsProcessingException(self.tr("RESIDUALS must be a GeoPackage (.gpkg) file, got {}").format(
                residuals))
        progress = FeedbackProgress(feedback)
        options = self.run_core(
            SingleImageOptions, image, self.parameterAsOutputLayer(parameters, self.OUTPUT, context),
            dsm_path=dsm_path, gcps=gcps, orientation=orientation,
            focal_mm=self.parameterAsDouble(parameters, self.FOCAL_MM, context) or None,
            sensor_width_mm=self.parameterAsDouble(parameters, self.SENSOR_WIDTH_MM, context) or None,
            mode=params.read_choice(self, parameters, self.MODE, context, self.MODES), crs=crs_text,
            ortho=OrthoOptions(resolution=self.parameterAsDouble(parameters, self.RESOLUTION, context)),
            residuals_path=residuals, reference_ortho=ref_layer.source() if ref_layer is not None else None,
            location=location, search_radius=self.parameterAsDouble(parameters, self.SEARCH_RADIUS, context) or 50.0)
        result = self.run_core(ortho.orthorectify_image, options, progress=progress)
        progress.push_result(result.warnings, result.log_lines)
        for r in result.residuals:
            feedback.pushInfo(self.tr("{} ({}): {:.2f} px").format(r["name"], r["role"], r["res_px"]))
        auto = getattr(result, "auto_control", None)
        return {self.OUTPUT: result.output, self.RESIDUALS: result.residuals_path, self.RMSE_PX: result.rmse_px,
                self.AUTO_GCPS: auto["kept"] if auto else 0,
                self.PLANAR_OFFSET_P95: (result.planar_error or {}).get("p95_m")}
