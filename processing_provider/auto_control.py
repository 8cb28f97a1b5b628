"""Automatic control: thin adapter over core.georef.autocontrol.stage.autocontrol_workspace."""
from qgis.core import (
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputVectorLayer,
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
        "Reference orthophoto: any north-up raster in a projected CRS, grey or colour; the result is in its CRS.\n"
        "Reference DSM: a DSM or DTM covering the block, heights in metres.\n"
        "Rough position: the photos' EXIF GPS when at least three carry it (auto), always (EXIF GPS), or never "
        "(none: rotation and scale are searched over the whole reference, which then should not be much larger "
        "than the block).\n"
        "Outputs: the camera centres in the reference CRS, the number of automatic GCPs the adjustment kept, the "
        "matches found; georef/autocontrol.json lists every candidate with why it was kept or dropped."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Aligned workspace")),
            QgsProcessingParameterRasterLayer(self.REFERENCE_ORTHO, self.tr("Reference orthophoto")),
            QgsProcessingParameterRasterLayer(self.REFERENCE_DSM, self.tr("Reference DSM")),
            params.choice(self.PRIOR, self.tr("Rough position"),
                          [self.tr("auto"), self.tr("EXIF GPS"), self.tr("none")], 0),
        )
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres (world)")))
        self.addOutput(QgsProcessingOutputNumber(self.AUTO_GCPS, self.tr("Automatic GCPs kept")))
        self.addOutput(QgsProcessingOutputNumber(self.MATCHES, self.tr("Matches found")))
        for n in self.NUMBERS:
            self.addOutput(QgsProcessingOutputNumber(n, n))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.georef.autocontrol.stage import autocontrol_workspace

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        ortho = self.parameterAsRasterLayer(parameters, self.REFERENCE_ORTHO, context)
        dsm = self.parameterAsRasterLayer(parameters, self.REFERENCE_DSM, context)
        prior = PRIORS[self.parameterAsEnum(parameters, self.PRIOR, context)]
        progress = FeedbackProgress(feedback)
        result = self.run_core(autocontrol_workspace, workspace, _path(ortho), _path(dsm), prior=prior,
                               progress=progress)
        progress.push_result(result.georef.warnings)
        for o in result.georef.outliers:
            feedback.pushWarning(self.tr("outlier left out: {}").format(o))
        f = result.georef.figures
        out = {self.OUT_WORKSPACE: result.workspace, self.CAMERAS: result.cameras_path,
               self.AUTO_GCPS: result.n_kept, self.MATCHES: result.figures.get("matches")}
        for n in self.NUMBERS:
            out[n] = f.get(n)
        return out


def _path(layer):
    return layer.source().split("|")[0] if layer is not None else ""
