"""Stack multispectral captures: thin adapter over core.prepare.captures.stack_capture_folder."""
from qgis.core import (
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFile,
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
    PANEL = "PANEL"
    PANEL_REFLECTANCE = "PANEL_REFLECTANCE"
    PANEL_WINDOW = "PANEL_WINDOW"
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
        "Calibration panel folder (optional): the band files of the calibration panel's captures (one capture of "
        "the panel of known reflectance in every band, before and / or after the flight, as MicaSense, DJI and "
        "Parrot ask for), in a folder of their own. With it the photos hold reflectance (0..1, float32, 0 where a "
        "band does not reach) instead of 16-bit numbers: each band is scaled by the panel's reflectance over the "
        "panel's value after the same radiometry (normalised: the panel fixes each band under the light of its "
        "capture; irradiance: the sun sensor follows the light's changes during the flight); before and after "
        "panels are averaged, and a warning says when they differ by more than 3 %. The panel is measured in the "
        "centre of its photo: a centre that is saturated or not uniform (no panel there) stops the run before any "
        "work, naming the file; so do a panel of another camera, a panel capture missing a band, and a panel "
        "reflectance for a band the rig lacks. Panel files left among the band files are not stacked.\n"
        "Panel reflectance: the panel's reflectance from its calibration sheet: one number for every band (0.5), "
        "per band (Green=0.49,Red=0.50,Red edge=0.50,NIR=0.49), or the path of a CSV file of rows band name or "
        "wavelength in nm, reflectance (a curve of wavelengths is interpolated at each band's centre). Needed "
        "with a calibration panel folder.\n"
        "Panel window (advanced): the side of the central square the panel is measured in, a fraction of the "
        "photo's short side (default 0.25); smaller when the panel fills less of the frame.\n"
        "Reference band (advanced): the band the others are registered onto; empty: the rig's reference camera.\n"
        "Output folder: where the multi-band photos are written (one per capture, named after its band files "
        "without the band suffix); not the band folder."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.prepare.band_radiometry import MODES, PANEL_WINDOW

        params.add(
            self,
            params.folder(self.INPUT, self.tr("Band folder")),
            params.choice(self.RADIOMETRY, self.tr("Radiometry"), MODES, default=MODES.index("normalised")),
            QgsProcessingParameterFile(self.PANEL, self.tr("Calibration panel folder"),
                                       behavior=QgsProcessingParameterFile.Behavior.Folder, optional=True),
            QgsProcessingParameterString(self.PANEL_REFLECTANCE, self.tr("Panel reflectance"), optional=True),
            *params.advanced(params.number(self.PANEL_WINDOW, self.tr("Panel window"), PANEL_WINDOW, 0.02,
                                           maxValue=1.0),
                             QgsProcessingParameterString(self.REFERENCE_BAND, self.tr("Reference band"),
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
        panel = self.parameterAsFile(parameters, self.PANEL, context).strip()
        options = self.run_core(CaptureStackOptions, output, RegistrationOptions(reference=reference),
                                params.read_choice(self, parameters, self.RADIOMETRY, context, MODES),
                                (panel,) if panel else (),
                                self.parameterAsString(parameters, self.PANEL_REFLECTANCE, context).strip(),
                                self.parameterAsDouble(parameters, self.PANEL_WINDOW, context))
        progress = FeedbackProgress(feedback)
        r = self.run_core(stack_capture_folder, folder, options, progress)
        progress.push_result(r.warnings, [f"{len(r.photos)} photo(s) of bands {', '.join(r.bands)} in {output}, "
                                          f"values in {r.unit}"]
                             + [f"capture {c} left out: {why}" for c, why in r.left_out.items()])
        return {self.OUTPUT: output, self.PHOTOS: len(r.photos), self.LEFT_OUT: len(r.left_out)}
