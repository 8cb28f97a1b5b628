"""Find targets: thin adapter over core.georef.targets.stage.find_targets."""
from qgis.core import (
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class FindTargetsAlgorithm(AlgorithmBase):
    NAME = "findtargets"
    DISPLAY = "Find targets"
    WORKSPACE = "WORKSPACE"
    TARGETS = "TARGETS"
    CRS = "CRS"
    TARGET_KIND = "TARGET_KIND"
    TARGET_SIZE = "TARGET_SIZE"
    GCPS = "GCPS"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    MARKS = "MARKS"
    TARGETS_FOUND = "TARGETS_FOUND"
    OBSERVATIONS_FOUND = "OBSERVATIONS_FOUND"
    HELP = (
        "Finds the surveyed ground targets on the photos of an aligned block and writes their observations, "
        "sub-pixel, as a gcp_list.txt that Georeference reads: no clicks. No GPS or first click is needed: marks "
        "are detected on every photo, tied across photos by triangulation in the block, and the triangulated marks "
        "are matched to the surveyed coordinates by their shape (a similarity found from triplets; scale and "
        "mirror searched; the photos' EXIF GPS, where they have it, narrows the search); then every named target is "
        "projected into every photo and the mark there joins it. "
        "Coded targets (ArUco, AprilTag) carry their names: a target named by its code or ending in it "
        "(12, T12, aruco_12).\n\n"
        "Aligned workspace: the block (its photos must still be where the alignment found them).\n"
        "Targets: the surveyed coordinates, a CSV 'name,x,y,z[,sigma_xy,sigma_z]' (CRS as a '# crs: EPSG:xxxx' "
        "line or the CRS parameter) or an OpenDroneMap gcp_list.txt whose pixel columns may be absent "
        "('x y z name') or partial: where present they are clicks that name the mark they fall on (checked against "
        "the constellation; a click on another target's mark is reported and left out).\n"
        "CRS: the coordinates' CRS where the file names none.\n"
        "Target kind: auto (crosses, checkerboards, circles and ArUco 4x4 markers), one kind, or an ArUco / "
        "AprilTag dictionary.\n"
        "Target size: the target's side or diameter in metres (0: unknown); a mark whose size on the ground (its "
        "pixels at its distance, through the scale the constellation gives) differs from it by more than a factor "
        "2 is left out.\n"
        "A target that a photo shows only in part, or covered, is left out rather than guessed; a mark that does "
        "not fit the surveyed constellation, or a naming that another fits almost as well, is reported in the log, "
        "never assigned.\n"
        "Outputs: the observations file (default georef/targets/gcp_list.txt in the workspace), a layer of the "
        "targets with what was found (georef/targets/targets.gpkg: observations, fit, residual) for review, the "
        "numbers of targets and observations found; georef/targets/targets.json lists every observation with its "
        "quality."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.georef.targets.options import KINDS

        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Aligned workspace")),
            QgsProcessingParameterFile(self.TARGETS, self.tr("Targets (surveyed coordinates)"),
                                       fileFilter=params.GCP_FILE_FILTER),
            params.target_crs(self.CRS, self.tr("CRS (where the file names none)")),
            params.choice(self.TARGET_KIND, self.tr("Target kind"), list(KINDS), 0),
            *params.advanced(params.number(self.TARGET_SIZE, self.tr("Target size (m, 0: unknown)"))),
        )
        self.addParameter(QgsProcessingParameterFileDestination(
            self.GCPS, self.tr("Observations file"), fileFilter="GCP list (*.txt)", optional=True,
            createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputVectorLayer(self.MARKS, self.tr("Targets found (for review)")))
        self.addOutput(QgsProcessingOutputNumber(self.TARGETS_FOUND, self.tr("Targets found")))
        self.addOutput(QgsProcessingOutputNumber(self.OBSERVATIONS_FOUND, self.tr("Observations found")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.georef.targets.options import KINDS, FindTargetsOptions
        from ..core.georef.targets.stage import find_targets

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        size = self.parameterAsDouble(parameters, self.TARGET_SIZE, context)
        options = FindTargetsOptions(
            targets=self.parameterAsFile(parameters, self.TARGETS, context),
            kind=KINDS[self.parameterAsEnum(parameters, self.TARGET_KIND, context)],
            target_size=size or None,
            crs=params.read_crs(self, parameters, self.CRS, context),
            output=self.parameterAsFileOutput(parameters, self.GCPS, context) or None)
        progress = FeedbackProgress(feedback)
        result = self.run_core(find_targets, workspace, options, progress)
        progress.push_result(result.reports)
        feedback.pushInfo(self.tr("{} of {} targets found, {} observations; {} candidate marks, {} tied across "
                                  "photos").format(result.n_targets, len(result.targets), result.n_observations,
                                                   result.candidates, result.marks))
        return {self.OUT_WORKSPACE: workspace, self.GCPS: result.gcps_path, self.MARKS: result.layer_path,
                self.TARGETS_FOUND: result.n_targets, self.OBSERVATIONS_FOUND: result.n_observations}
