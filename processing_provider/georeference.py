"""Georeference: thin adapter over core.pipeline.georeference_workspace."""
from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFile,
    QgsProcessingParameterString,
)

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
        "GCPS: an OpenDroneMap gcp_list.txt (CRS line, then 'x y z px py image [name]') or a CSV points file "
        "with a matching '<name>_observations.csv'. GCP_LAYER: alternatively a point layer with one feature per "
        "observation and fields name, image, px, py (optional z, sx, sy, sz, role).\n"
        "CHECK_POINTS: comma-separated names that become check points.\n"
        "CAMERA_POSITIONS: CSV 'image,x,y,z[,sigma]' (optional CRS line). USE_EXIF_GPS: use the photos' GPS.\n"
        "Outliers (a wrong observation, a typo in a coordinate) are detected, named in the log and left out."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        self.addParameter(QgsProcessingParameterFile(
            self.WORKSPACE, self.tr("Workspace folder (aligned)"), behavior=QgsProcessingParameterFile.Folder))
        self.addParameter(QgsProcessingParameterFile(
            self.GCPS, self.tr("Ground control file (gcp_list.txt or CSV)"), optional=True,
            fileFilter="GCP files (*.txt *.csv);;All files (*)"))
        self.addParameter(QgsProcessingParameterFeatureSource(
            self.GCP_LAYER, self.tr("Ground control point layer (one feature per observation)"),
            [QgsProcessing.TypeVectorPoint], optional=True))
        self.addParameter(QgsProcessingParameterString(
            self.CHECK_POINTS, self.tr("Check points (comma-separated names)"), defaultValue="", optional=True))
        self.addParameter(QgsProcessingParameterFile(
            self.CAMERA_POSITIONS, self.tr("Camera positions (CSV)"), optional=True,
            fileFilter="CSV/text (*.csv *.txt);;All files (*)"))
        self.addParameter(QgsProcessingParameterBoolean(
            self.USE_EXIF_GPS, self.tr("Use EXIF GPS camera positions"), defaultValue=False))
        self.addParameter(QgsProcessingParameterCrs(
            self.CRS, self.tr("Target CRS (default: the GCP file's)"), optional=True))
        self.addParameter(QgsProcessingParameterBoolean(
            self.REFINE_INTRINSICS, self.tr("Refine camera calibration in the adjustment"), defaultValue=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.RESIDUALS, self.tr("GCP residuals")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres (world)")))
        for n in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(n, n))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core import pipeline
        from ..core.io import gcp as gcpmod

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        gcp_path = self.parameterAsFile(parameters, self.GCPS, context) or None
        checks = [s.strip() for s in self.parameterAsString(parameters, self.CHECK_POINTS, context).split(",")
                  if s.strip()]
        positions = self.parameterAsFile(parameters, self.CAMERA_POSITIONS, context) or None
        crs = self.parameterAsCrs(parameters, self.CRS, context)
        crs_text = crs.authid() or crs.toWkt() if crs.isValid() else None
        gcps = None
        source = self.parameterAsSource(parameters, self.GCP_LAYER, context)
        if source is not None:
            gcps = self._gcps_from_layer(source, gcpmod)
        if gcp_path is None and gcps is None and not positions and not self.parameterAsBoolean(
                parameters, self.USE_EXIF_GPS, context):
            raise QgsProcessingException(self.tr(
                "Give ground control (GCPS or GCP_LAYER) and/or camera positions (CAMERA_POSITIONS or USE_EXIF_GPS)"))
        result = self.run_core(
            pipeline.georeference_workspace, workspace, gcp_path=gcp_path, gcps=gcps, check_points=checks,
            camera_positions_path=positions,
            use_exif_gps=self.parameterAsBoolean(parameters, self.USE_EXIF_GPS, context),
            crs=crs_text, refine_intrinsics=self.parameterAsBoolean(parameters, self.REFINE_INTRINSICS, context),
            progress=FeedbackProgress(feedback))
        for w in result.warnings:
            feedback.pushWarning(w)
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

    def _gcps_from_layer(self, source, gcpmod):
        fields = [f.name().lower() for f in source.fields()]
        for need in ("name", "image", "px", "py"):
            if need not in fields:
                raise QgsProcessingException(self.tr(
                    "GCP layer {} lacks the field '{}' (needs name, image, px, py)").format(source.sourceName(), need))
        rows = []
        for feat in source.getFeatures():
            attrs = {k.lower(): feat[k] for k in source.fields().names()}
            pt = feat.geometry().constGet()
            z = attrs.get("z")
            if z in (None, "") and pt is not None and pt.is3D():
                z = pt.z()
            rows.append(dict(attrs, x=pt.x(), y=pt.y(), z=z or 0.0))
        crs = source.sourceCrs().authid() or source.sourceCrs().toWkt()
        return gcpmod.gcps_from_rows(rows, crs, source_name=source.sourceName())


def _fmt(v):
    return "n/a" if v is None else f"{v:.3f}"


_ = QgsCoordinateReferenceSystem  # re-exported for models that build CRS values
