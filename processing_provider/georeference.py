"""Georeference: thin adapter over core.georef.stage.georeference_workspace."""
import dataclasses

from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterExtent,
    QgsProcessingParameterRasterLayer,
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
    REFERENCE_ORTHO = "REFERENCE_ORTHO"
    REFERENCE_DSM = "REFERENCE_DSM"
    REFERENCE_GSD = "REFERENCE_GSD"
    REFERENCE_EXTENT = "REFERENCE_EXTENT"
    AUTO_GCPS = "AUTO_GCPS"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    RESIDUALS = "RESIDUALS"
    CAMERAS = "CAMERAS"
    NUMBERS = ("GCP_RMSE_XY", "GCP_RMSE_Z", "CHECK_RMSE_XY", "CHECK_RMSE_Z", "CAMERA_RMSE_XYZ", "CAMERA_RMSE_XY",
               "NSSDA_H", "NSSDA_V", "DEM_CONTROL_N")
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
        "Outliers (a wrong observation, a typo in a coordinate) are detected, named in the log and left out.\n\n"
        "Given a reference orthophoto and a reference DSM (any raster layer: a file, or a WMS, "
        "XYZ or WCS layer, which is saved for the block's extent to georef/reference-ortho.tif and "
        "georef/reference-dsm.tif), the block is georeferenced with no hand-picked GCP, as 'Automatic control "
        "from a reference orthophoto' does; the result is in the reference orthophoto's CRS (a Web Mercator or "
        "geographic layer is saved in the DSM's CRS, else in the UTM zone). Ground control given as well is not "
        "used to fix the block: all its points become check points, an independent measure of the automatic "
        "control. Camera positions or Use EXIF GPS positions give the rough position (else EXIF GPS when three "
        "photos carry it, else rotation and scale are searched). The calibration is refined in any case "
        "(focal length and distortion: the automatic GCPs determine them).\n"
        "A reference DSM given alone (a DEM file in any projected CRS, heights in metres or feet) adds DEM control: "
        "after the adjustment the block's sparse points are co-registered on it (shift, tilt, dome) and the block "
        "is adjusted again with DEM-derived control points (dem001, ...), which remove tilt, height offset and doming "
        "the photos cannot see; the co-registration is logged and saved to georef/dem_control.json. Heights: the "
        "control points' when there are any, else the DEM's (camera positions' heights are moved onto it). Without "
        "GCPs or camera positions the photos' EXIF GPS place the block. A DEM off the block or too coarse for it is "
        "refused before the adjustment.\n"
        "Reference resolution: metres per pixel a web layer is saved at (0: 0.25 m; the DSM at twice that, at "
        "least 0.5 m). Area to fetch: the extent a web layer is saved for; empty: the photos' EXIF GPS positions "
        "plus a margin, else the other reference's extent.\n"
        "Outputs: besides the usual ones, the number of automatic GCPs the adjustment kept (none without "
        "automatic control)."
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
            QgsProcessingParameterRasterLayer(self.REFERENCE_ORTHO, self.tr("Reference orthophoto"), optional=True),
            QgsProcessingParameterRasterLayer(self.REFERENCE_DSM, self.tr("Reference DSM"), optional=True),
            *params.advanced(
                params.number(self.REFERENCE_GSD, self.tr("Reference resolution for web layers (m, 0: auto)")),
                QgsProcessingParameterExtent(self.REFERENCE_EXTENT, self.tr("Area to fetch from web layers"),
                                             optional=True)),
        )
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.RESIDUALS, self.tr("GCP residuals")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres (world)")))
        self.addOutput(QgsProcessingOutputNumber(self.AUTO_GCPS, self.tr("Automatic GCPs kept")))
        for n in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(n, n))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.georef.options import GeorefOptions
        from ..core.georef.stage import georeference_workspace

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        gcp_path = params.read_optional_file(self, parameters, self.GCPS, context)
        checks = params.read_names(self, parameters, self.CHECK_POINTS, context)
        positions = params.read_optional_file(self, parameters, self.CAMERA_POSITIONS, context)
        crs_text = params.read_crs(self, parameters, self.CRS, context)
        gcps = params.read_gcp_layer(self, parameters, self.GCP_LAYER, context, self.tr(
            "GCP layer {} lacks the field '{}' (needs name, image, px, py)"))
        ortho = self.parameterAsRasterLayer(parameters, self.REFERENCE_ORTHO, context)
        dsm = self.parameterAsRasterLayer(parameters, self.REFERENCE_DSM, context)
        if ortho is not None:
            return self._automatic(parameters, context, feedback, workspace, ortho, dsm, gcp_path, gcps, checks,
                                   positions, crs_text)
        options = GeorefOptions(gcp_path=gcp_path, gcps=gcps, check_points=checks, camera_positions_path=positions,
                                use_exif_gps=self.parameterAsBoolean(parameters, self.USE_EXIF_GPS, context), crs=crs_text,
                                refine_intrinsics=self.parameterAsBoolean(parameters, self.REFINE_INTRINSICS, context),
                                gcps_upright=self.parameterAsBoolean(parameters, self.GCPS_UPRIGHT, context))
        if dsm is not None:  # DEM control: the reference DSM alone
            from ..qgisio.reference_layers import describe, local_file

            if local_file(dsm) is None:
                raise QgsProcessingException(self.tr(
                    "Reference DSM {} given alone (DEM control) must be a raster file on disk; a web layer is "
                    "fetched only for the automatic control, with a reference orthophoto").format(describe(dsm)))
            options = dataclasses.replace(options, reference_dem=local_file(dsm))
        elif not params.has_control(gcp_path, gcps, positions, options.use_exif_gps):
            raise QgsProcessingException(self.tr(
                "Give ground control (Ground control file or layer: GCPS, GCP_LAYER) and/or camera positions "
                "(Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS)"))
        progress = FeedbackProgress(feedback)
        result = self.run_core(georeference_workspace, workspace, options, progress=progress)
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
               self.CAMERAS: result.cameras_path, self.AUTO_GCPS: None}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out

    def _automatic(self, parameters, context, feedback, workspace, ortho, dsm, gcp_path, gcps, checks, positions,
                   crs_text):
        """Automatic control (core autocontrol_workspace) from the reference layers; the given ground control
        becomes check points."""
        from ..core.georef.autocontrol.options import PRIOR_AUTO, PRIOR_GPS, AutoControlOptions
        from ..core.georef.autocontrol.stage import autocontrol_workspace
        from ..core.georef.options import GeorefOptions
        from ..qgisio import reference_layers as refs

        if ortho is None or dsm is None:
            raise QgsProcessingException(self.tr("Automatic control needs both a reference orthophoto and a "
                                                 "reference DSM (REFERENCE_ORTHO, REFERENCE_DSM); {} is missing")
                                         .format("REFERENCE_ORTHO" if ortho is None else "REFERENCE_DSM"))
        progress = FeedbackProgress(feedback)
        extent = self.parameterAsExtent(parameters, self.REFERENCE_EXTENT, context)
        extent_crs = self.parameterAsExtentCrs(parameters, self.REFERENCE_EXTENT, context)
        ortho_path, dsm_path = self.run_core(
            refs.resolve_references, ortho, dsm, workspace,
            gsd=self.parameterAsDouble(parameters, self.REFERENCE_GSD, context) or None,
            extent=extent if not extent.isNull() else None, extent_crs=extent_crs,
            progress=FeedbackProgress(feedback, 0.0, 0.1), context=context.transformContext())
        crs = self.run_core(refs.reference_crs, ortho_path)
        if crs_text and crs_text != crs:
            feedback.pushWarning(self.tr("Target CRS {} is not used: automatic control georeferences in the "
                                         "reference orthophoto's CRS {}").format(crs_text, crs))
        # the given control is read and checked by core, as Georeference reads it: the points become check points
        control = GeorefOptions(gcp_path=gcp_path, gcps=gcps, check_points=checks, camera_positions_path=positions,
                                gcps_upright=self.parameterAsBoolean(parameters, self.GCPS_UPRIGHT, context))
        prior = PRIOR_GPS if self.parameterAsBoolean(parameters, self.USE_EXIF_GPS, context) and not positions \
            else PRIOR_AUTO
        result = self.run_core(autocontrol_workspace, workspace, AutoControlOptions(
            reference_ortho=ortho_path, reference_dsm=dsm_path, prior=prior, control=control),
            progress=FeedbackProgress(feedback, 0.1, 1.0))
        georef = result.georef
        progress.push_result(georef.warnings)
        for o in georef.outliers:
            feedback.pushWarning(self.tr("outlier left out: {}").format(o))
        for line in georef.report_lines:
            feedback.pushInfo(line)
        f = georef.figures
        feedback.pushInfo(self.tr("Automatic control: {} automatic GCPs kept; CRS {}; check RMSE XY {} m, Z {} m")
                          .format(result.n_kept, result.crs, _fmt(f.get("CHECK_RMSE_XY")),
                                  _fmt(f.get("CHECK_RMSE_Z"))))
        out = {self.OUT_WORKSPACE: result.workspace, self.RESIDUALS: georef.residuals_path,
               self.CAMERAS: result.cameras_path, self.AUTO_GCPS: result.n_kept}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out


def _fmt(v):
    return "n/a" if v is None else f"{v:.3f}"
