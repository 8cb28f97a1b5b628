"""Automatic control: thin adapter over core.georef.autocontrol.stage.autocontrol_workspace."""
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

PRIORS = ("auto", "gps", "none")


class AutoControlAlgorithm(AlgorithmBase):
    NAME = "autocontrol"
    DISPLAY = "Automatic control from a reference orthophoto"
    WORKSPACE = "WORKSPACE"
    REFERENCE_ORTHO = "REFERENCE_ORTHO"
    REFERENCE_DSM = "REFERENCE_DSM"
    PRIOR = "PRIOR"
    REFERENCE_GSD = "REFERENCE_GSD"
    REFERENCE_EXTENT = "REFERENCE_EXTENT"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    CAMERAS = "CAMERAS"
    AUTO_GCPS = "AUTO_GCPS"
    MATCHES = "MATCHES"
    NUMBERS = ("GCP_RMSE_XY", "GCP_RMSE_Z", "CHECK_RMSE_XY", "CHECK_RMSE_Z")
    HELP = (
        "Georeferences an aligned block with no hand-picked ground control: a provisional orthophoto of the block "
        "is matched to a reference orthophoto (a national orthophoto, an earlier block's orthomosaic) at a common "
        "resolution, each match is found again in the photos and takes its height from the reference DSM, and "
        "these automatic GCPs enter the usual GCP-constrained adjustment, which leaves out the outliers. Changes "
        "between the two dates (crops, cars, new buildings, another sun) are tolerated: what stays is used, and "
        "the log says how many matches survived each step.\n\n"
        "Aligned workspace: the block to georeference (its photos must still be where the alignment found them).\n"
        "Reference orthophoto: any north-up raster, grey or colour, in any CRS (a national one without an EPSG "
        "code too); the result is in its CRS (a geographic or Web Mercator file: in the UTM zone of its centre). "
        "A layer that is no local file (WMS, XYZ, WCS, a virtual raster) is saved for the block's extent to "
        "georef/reference-ortho.tif (a Web Mercator or geographic one in the DSM's CRS, else the UTM zone's).\n"
        "Reference DSM: a DSM or DTM covering the block, in any CRS and resolution (a 10-30 m DEM too: each "
        "height weighs by the DEM's slope and roughness there), heights in metres or in the unit the raster "
        "declares (a WCS layer is saved to "
        "georef/reference-dsm.tif).\n"
        "A reference DSM alone (no orthophoto, a raster file on disk) is enough: the block is placed by the photos' "
        "EXIF GPS, then co-registered to the DSM (shift, tilt, dome: Nuth & Kääb on the sparse points), and "
        "DEM-derived control points enter the adjustment (georef/dem_control.json; the same as Georeference with "
        "a reference DSM alone).\n"
        "Rough position: the photos' EXIF GPS when at least two carry it (auto), always (EXIF GPS), or never "
        "(none: rotation and scale are searched over the whole reference, which then should not be much larger "
        "than the block).\n"
        "Reference resolution: metres per pixel a web layer is saved at (0: 0.25 m; the DSM at twice that, at least "
        "0.5 m). Area to fetch: the extent a web layer is saved for; empty: the photos' EXIF GPS positions plus a "
        "margin, else the other reference's extent.\n"
        "Outputs: the camera centres in the reference CRS, the number of automatic GCPs the adjustment kept, the "
        "matches found; georef/autocontrol.json lists every candidate with why it was kept or dropped."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Aligned workspace")),
            QgsProcessingParameterRasterLayer(self.REFERENCE_ORTHO, self.tr("Reference orthophoto"), optional=True),
            QgsProcessingParameterRasterLayer(self.REFERENCE_DSM, self.tr("Reference DSM")),
            params.choice(self.PRIOR, self.tr("Rough position"),
                          [self.tr("auto"), self.tr("EXIF GPS"), self.tr("none")], 0),
            *params.advanced(
                params.number(self.REFERENCE_GSD, self.tr("Reference resolution for web layers (m, 0: auto)")),
                QgsProcessingParameterExtent(self.REFERENCE_EXTENT, self.tr("Area to fetch from web layers"),
                                             optional=True)),
        )
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres (world)")))
        self.addOutput(QgsProcessingOutputNumber(self.AUTO_GCPS, self.tr("Automatic GCPs kept")))
        self.addOutput(QgsProcessingOutputNumber(self.MATCHES, self.tr("Matches found")))
        for n in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(n, n))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.georef.autocontrol.options import AutoControlOptions
        from ..core.georef.autocontrol.stage import autocontrol_workspace
        from ..qgisio.reference_layers import resolve_references

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        ortho = self.parameterAsRasterLayer(parameters, self.REFERENCE_ORTHO, context)
        dsm = self.parameterAsRasterLayer(parameters, self.REFERENCE_DSM, context)
        prior = PRIORS[self.parameterAsEnum(parameters, self.PRIOR, context)]
        if ortho is None and dsm is not None:
            return self._dem_control(workspace, dsm, prior, feedback)
        progress = FeedbackProgress(feedback)
        extent = self.parameterAsExtent(parameters, self.REFERENCE_EXTENT, context)
        ortho_path, dsm_path = self.run_core(
            resolve_references, ortho, dsm, workspace,
            gsd=self.parameterAsDouble(parameters, self.REFERENCE_GSD, context) or None,
            extent=extent if not extent.isNull() else None,
            extent_crs=self.parameterAsExtentCrs(parameters, self.REFERENCE_EXTENT, context),
            progress=FeedbackProgress(feedback, 0.0, 0.1), context=context.transformContext())
        result = self.run_core(autocontrol_workspace, workspace,
                               AutoControlOptions(reference_ortho=ortho_path, reference_dsm=dsm_path, prior=prior),
                               progress=FeedbackProgress(feedback, 0.1, 1.0))
        progress.push_result(result.georef.warnings)
        for o in result.georef.outliers:
            feedback.pushWarning(self.tr("outlier left out: {}").format(o))
        f = result.georef.figures
        out = {self.OUT_WORKSPACE: result.workspace, self.CAMERAS: result.cameras_path,
               self.AUTO_GCPS: result.n_kept, self.MATCHES: result.figures.get("matches")}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out

    def _dem_control(self, workspace, dsm, prior, feedback):
        """A reference DSM alone: the block placed by EXIF GPS and co-registered to the DSM (DEM control: core
        georeference_workspace with GeorefOptions.reference_dem)."""
        from ..core.georef.options import GeorefOptions
        from ..core.georef.stage import georeference_workspace
        from ..qgisio.reference_layers import describe, local_file

        if local_file(dsm) is None:
            raise QgsProcessingException(self.tr(
                "Reference DSM {} given without a reference orthophoto (DEM control) must be a raster file on disk; "
                "a web layer is fetched only with a reference orthophoto").format(describe(dsm)))
        if prior == "none":
            raise QgsProcessingException(self.tr(
                "A reference DSM alone (DEM control) places the block by the photos' EXIF GPS: choose Rough "
                "position auto or EXIF GPS, or give a reference orthophoto as well"))
        progress = FeedbackProgress(feedback)
        result = self.run_core(georeference_workspace, workspace,
                               GeorefOptions(use_exif_gps=True, reference_dem=local_file(dsm)), progress=progress)
        progress.push_result(result.warnings)
        for o in result.outliers:
            feedback.pushWarning(self.tr("outlier left out: {}").format(o))
        f = result.figures
        out = {self.OUT_WORKSPACE: result.workspace, self.CAMERAS: result.cameras_path,
               self.AUTO_GCPS: f.get("DEM_CONTROL_N"), self.MATCHES: None}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out
