"""Stack multispectral captures: thin adapter over core.prepare.captures.stack_capture_folder."""
from qgis.core import (
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterString,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class StackCapturesAlgorithm(AlgorithmBase):
    NAME = "stackcaptures"
    DISPLAY = "Stack multispectral captures"
    REQUIRES = ()
    INPUT = "INPUT"
    RADIOMETRY = "RADIOMETRY"
    REFERENCE_BAND = "REFERENCE_BAND"
    OUTPUT = "OUTPUT"
    PHOTOS = "PHOTOS"
    LEFT_OUT = "LEFT_OUT"
    STYLE_OUTPUTS = False
    HELP = (
        "Turns the band files of a multispectral rig (Parrot Sequoia, MicaSense RedEdge / Altum, DJI P4 "
        "Multispectral / Mavic 3M: one 16-bit TIFF per band per capture) into one multi-band photo per capture, "
        "which Align images, Run pipeline and Build orthophoto take like any photo: the orthomosaic then has every "
        "band, and Spectral index makes NDVI or NDRE of it. The files of one capture are grouped by their capture "
        "id (else rig name and time); each band is undistorted with its own lens model from its metadata, turned "
        "by its rig rotation and registered onto the reference band by phase correlation on gradients. The photo's "
        "bands are NIR, Red, Green first (QGIS shows them as a false-colour NIR-R-G view), each named with its "
        "wavelength; the capture's GPS is in its EXIF. A capture missing a band is left out and named in the log; "
        "the band folder is never written into.\n\n"
        "Band folder: the folder of band files (the RGB camera's frames in it are not stacked).\n"
        "Radiometry: normalised (default) removes each band's dark level, corrects its vignetting from the "
        "file's model and normalises exposure time and gain to the block's; irradiance also divides by the sun "
        "sensor's irradiance for that band (values proportional to reflectance when the light changes during the "
        "flight); raw keeps the numbers as recorded. A band file lacking what the choice needs (an exposure time, "
        "a sun-sensor reading) stops the run before any work, naming the file. The photo's metadata says what was "
        "done (and per band the vignetting model, dark level and scale).\n"
        "Reference band (advanced): the band the others are registered onto; empty: the rig's reference camera.\n"
        "Output folder: where the multi-band photos are written (one per capture, named after its band files "
        "without the band suffix); not the band folder."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.prepare.band_radiometry import MODES

        params.add(
            self,
            params.folder(self.INPUT, self.tr("Band folder")),
            params.choice(self.RADIOMETRY, self.tr("Radiometry"), MODES, default=MODES.index("normalised")),
            *params.advanced(QgsProcessingParameterString(self.REFERENCE_BAND, self.tr("Reference band"),
                                                          optional=True)),
        )
        self.addParameter(QgsProcessingParameterFolderDestination(self.OUTPUT, self.tr("Output folder")))
        self.addOutput(QgsProcessingOutputFolder(self.OUTPUT, self.tr("Output folder")))
        self.addOutput(QgsProcessingOutputNumber(self.PHOTOS, self.tr("Photos written")))
        self.addOutput(QgsProcessingOutputNumber(self.LEFT_OUT, self.tr("Captures left out")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.prepare.band_radiometry import MODES
        from ..core.prepare.bands import RegistrationOptions
        from ..core.prepare.captures import CaptureStackOptions, stack_capture_folder

        folder = self.parameterAsFile(parameters, self.INPUT, context)
        output = self.parameterAsString(parameters, self.OUTPUT, context)
        reference = self.parameterAsString(parameters, self.REFERENCE_BAND, context).strip() or None
        options = self.run_core(CaptureStackOptions, output, RegistrationOptions(reference=reference),
                                params.read_choice(self, parameters, self.RADIOMETRY, context, MODES))
        progress = FeedbackProgress(feedback)
        r = self.run_core(stack_capture_folder, folder, options, progress)
        progress.push_result(r.warnings, [f"{len(r.photos)} photo(s) of bands {', '.join(r.bands)} in {output}"]
                             + [f"capture {c} left out: {why}" for c, why in r.left_out.items()])
        return {self.OUTPUT: output, self.PHOTOS: len(r.photos), self.LEFT_OUT: len(r.left_out)}
