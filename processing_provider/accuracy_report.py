"""Accuracy report: thin adapter over core.report.build_report."""
from qgis.core import (
    QgsProcessingOutputFile,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterFileDestination,
)

from ..qgisio.messages import report_language
from . import params
from .base import AlgorithmBase, FeedbackProgress


class AccuracyReportAlgorithm(AlgorithmBase):
    NAME = "accuracyreport"
    DISPLAY = "Accuracy report"
    WORKSPACE = "WORKSPACE"
    UNCERTAINTY = "UNCERTAINTY"
    OUTPUT_HTML = "OUTPUT_HTML"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    CAMERA_PRECISION = "CAMERA_PRECISION"
    POINT_PRECISION = "POINT_PRECISION"
    SECTIONS_SKIPPED = "SECTIONS_SKIPPED"
    # key figures (None where the workspace has no such figure)
    NUMBERS = (
        ("IMAGES", "Images given"),
        ("REGISTERED_IMAGES", "Images aligned"),
        ("MEAN_REPROJECTION_ERROR", "Mean reprojection error (px)"),
        ("GSD", "Ground sample distance (m)"),
        ("AREA_M2", "Area covered by tie points (m²)"),
        ("CHECK_N", "Check points evaluated"),
        ("CHECK_RMSE_X", "Check RMSE X (m)"),
        ("CHECK_RMSE_Y", "Check RMSE Y (m)"),
        ("CHECK_RMSE_Z", "Check RMSE Z (m)"),
        ("CHECK_RMSE_XY", "Check RMSE XY, radial (m)"),
        ("CONTROL_RMSE_XY", "Control RMSE XY (m)"),
        ("CONTROL_RMSE_Z", "Control RMSE Z (m)"),
        ("NSSDA_H", "NSSDA horizontal accuracy at 95 % (m)"),
        ("NSSDA_V", "NSSDA vertical accuracy at 95 % (m)"),
        ("ASPRS_2014_H_CLASS_CM", "ASPRS 2014 horizontal class (cm)"),
        ("ASPRS_2014_V_CLASS_CM", "ASPRS 2014 vertical class (cm)"),
        ("ASPRS_2023_H_CLASS_CM", "ASPRS 2023 horizontal class (cm)"),
        ("ASPRS_2023_V_CLASS_CM", "ASPRS 2023 vertical class (cm)"),
        ("CAMERA_RMSE_XY", "Camera position RMSE XY (m)"),
        ("CAMERA_RMSE_Z", "Camera position RMSE Z (m)"),
        ("SIGMA0", "Sigma0 of the adjustment"),
        ("POINT_STD_XY_MEDIAN", "Tie point sigma XY, median (m)"),
        ("POINT_STD_Z_MEDIAN", "Tie point sigma Z, median (m)"),
        ("DSM_VALID_FRACTION", "DSM valid fraction"),
    )
    HELP = (
        "Writes one self-contained HTML report of a workspace (plots embedded, readable offline) and returns its "
        "key figures.\n\n"
        "Sections of the report. Summary — images given / aligned / not aligned and why, image screening, cameras with their calibrated "
        "parameters and standard deviations, GSD, area, CRS, processing times and parameters. Orientation quality: "
        "reprojection errors, tie-point track lengths, image connectivity, camera positions with residuals. "
        "Georeferencing: control and check points with dX dY dZ and image residuals, residual vectors, RMSE per "
        "set, NSSDA (FGDC-STD-007.3-1998) accuracy statements at 95 % confidence, ASPRS 2014 and 2023 accuracy "
        "classes, camera-position residuals, outliers. Uncertainty: standard deviations of cameras and tie points "
        "from the bundle adjustment covariance. Products: DSM and orthomosaic previews, resolution, valid "
        "fraction. Sections whose stage has not run are skipped with a note.\n\n"
        "Workspace folder: a workspace folder (at least aligned).\n"
        "Compute uncertainty: computes the bundle adjustment covariance (seconds for hundreds of images) for the "
        "uncertainty section and writes "
        "<workspace>/uncertainty/cameras.gpkg and points.gpkg.\n"
        "Report: the report file (default: <workspace>/report.html). It is written under a temporary name and "
        "renamed when complete."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Workspace folder")),
            params.flag(self.UNCERTAINTY, self.tr("Compute uncertainty"), default=True),
        )
        self.addParameter(QgsProcessingParameterFileDestination(
            self.OUTPUT_HTML, self.tr("Report"), fileFilter="HTML files (*.html)",
            optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputFile(self.CAMERA_PRECISION, self.tr("Camera precision (GeoPackage)")))
        self.addOutput(QgsProcessingOutputFile(self.POINT_PRECISION, self.tr("Tie point precision (GeoPackage)")))
        self.addOutput(QgsProcessingOutputString(self.SECTIONS_SKIPPED, self.tr("Sections skipped")))
        for name, label in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(name, self.tr(label)))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.report import stage as report
        from ..core.report.options import ReportOptions

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        output = self.parameterAsFileOutput(parameters, self.OUTPUT_HTML, context) or None
        progress = FeedbackProgress(feedback)
        options = ReportOptions(uncertainty=self.parameterAsBoolean(parameters, self.UNCERTAINTY, context),
                                output_html=output, language=report_language())  # headings in QGIS's language
        result = self.run_core(report.build_report, workspace, options, progress)
        progress.push_result(result.warnings)
        skipped = {k: v for k, v in result.sections.items() if v != "ok"}
        for k, v in skipped.items():
            feedback.pushInfo(self.tr("section {} skipped: {}").format(k, v))
        f = result.figures
        feedback.pushInfo(self.tr("report written: {} ({} s)").format(result.path, result.seconds))
        out = {self.OUT_WORKSPACE: result.workspace, self.OUTPUT_HTML: result.path,
               self.CAMERA_PRECISION: result.layers.get("cameras"), self.POINT_PRECISION: result.layers.get("points"),
               self.SECTIONS_SKIPPED: ", ".join(sorted(skipped))}
        for name, _label in self.NUMBERS:
            out[name] = f.get(name)
        return out
