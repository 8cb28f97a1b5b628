"""Georeference: thin adapter over core.georef.stage.georeference_workspace."""
from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputVectorLayer,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class GeoreferenceAlgorithm(AlgorithmBase):
    NAME = "georeference"
    DISPLAY = "Georeference"
    WORKSPACE = "WORKSPACE"
    GCPS = "GCPS"
    GCP_LAYER = "GCP_LAYER"
    CHECK_POINTS = "CHECK_POINTS"
    CAMERA_POSITIONS = "CAMERA_POSITIONS"
    USE_EXIF_GPS = "USE_EXIF_GPS"
    CRS = "CRS"
    REFINE_INTRINSICS = "REFINE_INTRINSICS"
    GCPS_UPRIGHT = "GCPS_UPRIGHT"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    RESIDUALS = "RESIDUALS"
    CAMERAS = "CAMERAS"
    NUMBERS = ("GCP_RMSE_XY", "GCP_RMSE_Z", "CHECK_RMSE_XY", "CHECK_RMSE_Z", "CAMERA_RMSE_XYZ", "CAMERA_RMSE_XY",
               "NSSDA_H", "NSSDA_V")
    HELP = (
        "Fixes the aligned block in a real coordinate reference system with ground control points (GCPs) "
        "and/or camera positions, used inside the bundle adjustment so that they also remove the block's "
        "drift and bending, which a 7-parameter (Helmert) transform cannot. Check points take no part in the "
        "adjustment: they are triangulated afterwards and compared with their surveyed coordinates.\n\n"
        "Ground control file: an OpenDroneMap gcp_list.txt (CRS line, then 'x y z px py image [name]') or a CSV points file "
        "with a matching '<name>_observations.csv'. Ground control layer: alternatively a point layer with one feature per "
        "observation and fields name, image, px, py (optional z, sx, sy, sz, role).\n"
        "Check points: comma-separated names that become check points.\n"
        "Camera positions: CSV 'image,x,y,z[,sigma]' (optional CRS line). Use EXIF GPS positions: use the photos' "
        "GPS.\n"
        "Target CRS: default the ground control file's. Refine camera calibration: let the adjustment refine "
        "focal length, principal point and distortion.\n"
        "GCP pixels measured on upright photos: tick when the pixel coordinates were measured on the photos shown "
        "upright by their EXIF orientation, as web browsers and photo viewers show them; they are turned into the "
        "stored pixel grid of each photo (photos stored without a turn are unchanged).\n"
        "Outliers (a wrong observation, a typo in a coordinate) are detected, named in the log and left out."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Aligned workspace")),
            params.gcp_file(self.GCPS, self.tr("Ground control file")),
            params.gcp_layer(self.GCP_LAYER, self.tr("Ground control layer")),
            params.check_points(self.CHECK_POINTS, self.tr("Check points")),
            params.camera_positions(self.CAMERA_POSITIONS, self.tr("Camera positions (CSV)")),
            params.flag(self.USE_EXIF_GPS, self.tr("Use EXIF GPS positions")),
            params.target_crs(self.CRS, self.tr("Target CRS")),
            params.flag(self.REFINE_INTRINSICS, self.tr("Refine camera calibration")),
            params.flag(self.GCPS_UPRIGHT, self.tr("GCP pixels measured on upright photos")),
        )
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.RESIDUALS, self.tr("GCP residuals")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres (world)")))
        for n in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(n, n))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.georef.stage import georeference_workspace

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        gcp_path = params.read_optional_file(self, parameters, self.GCPS, context)
        checks = params.read_names(self, parameters, self.CHECK_POINTS, context)
        positions = params.read_optional_file(self, parameters, self.CAMERA_POSITIONS, context)
        crs_text = params.read_crs(self, parameters, self.CRS, context)
        gcps = params.read_gcp_layer(self, parameters, self.GCP_LAYER, context, self.tr(
            "GCP layer {} lacks the field '{}' (needs name, image, px, py)"))
        if not params.has_control(gcp_path, gcps, positions, self.parameterAsBoolean(
                parameters, self.USE_EXIF_GPS, context)):
            raise QgsProcessingException(self.tr(
                "Give ground control (Ground control file or layer: GCPS, GCP_LAYER) and/or camera positions "
                "(Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS)"))
        progress = FeedbackProgress(feedback)
        result = self.run_core(
            georeference_workspace, workspace, gcp_path=gcp_path, gcps=gcps, check_points=checks,
            camera_positions_path=positions,
            use_exif_gps=self.parameterAsBoolean(parameters, self.USE_EXIF_GPS, context),
            crs=crs_text, refine_intrinsics=self.parameterAsBoolean(parameters, self.REFINE_INTRINSICS, context),
            progress=progress, gcps_upright=self.parameterAsBoolean(parameters, self.GCPS_UPRIGHT, context))
        progress.push_result(result.warnings)
        for o in result.outliers:
            feedback.pushWarning(self.tr("outlier left out: {}").format(o))
        for line in result.report_lines:
            feedback.pushInfo(line)
        f = result.figures
        feedback.pushInfo(self.tr("CRS {}; control RMSE XY {} m, Z {} m; check RMSE XY {} m, Z {} m").format(
            result.crs, _fmt(f["GCP_RMSE_XY"]), _fmt(f["GCP_RMSE_Z"]), _fmt(f["CHECK_RMSE_XY"]),
            _fmt(f["CHECK_RMSE_Z"])))
        out = {self.OUT_WORKSPACE: result.workspace, self.RESIDUALS: result.residuals_path,
               self.CAMERAS: result.cameras_path}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out


def _fmt(v):
    return "n/a" if v is None else f"{v:.3f}"
