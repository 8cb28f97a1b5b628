"""The "ArchaeoOrtho" Processing provider (id ``archaeoortho``)."""
import os

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon


class ArchaeoOrthoProvider(QgsProcessingProvider):
    def id(self):
        return "archaeoortho"

    def name(self):
        return "ArchaeoOrtho"

    def longName(self):  # noqa: N802 (QGIS API name)
        return QCoreApplication.translate("ArchaeoOrthoProvider", "ArchaeoOrtho photogrammetry")

    def icon(self):
        return QIcon(os.path.join(os.path.dirname(os.path.dirname(__file__)), "icon.svg"))

    def loadAlgorithms(self):  # noqa: N802 (QGIS API name)
        for alg in algorithms():
            self.addAlgorithm(alg)


def algorithms():
    """One instance of every algorithm, in toolbox order: the one list of them."""
    from .accuracy_report import AccuracyReportAlgorithm
    from .align_images import AlignImagesAlgorithm
    from .auto_control import AutoControlAlgorithm
    from .build_dsm import BuildDsmAlgorithm
    from .build_dtm import BuildDtmAlgorithm
    from .build_model import BuildModelAlgorithm
    from .build_orthophoto import BuildOrthophotoAlgorithm
    from .contours import ContoursAlgorithm
    from .dsm_difference import DsmDifferenceAlgorithm
    from .find_targets import FindTargetsAlgorithm
    from .georeference import GeoreferenceAlgorithm
    from .orthorectify_image import OrthorectifyImageAlgorithm
    from .prepare_images import PrepareImagesAlgorithm
    from .relief_visualisation import ReliefVisualisationAlgorithm
    from .run_pipeline import RunPipelineAlgorithm
    from .spectral_index import SpectralIndexAlgorithm
    from .stack_captures import StackCapturesAlgorithm

    return [AlignImagesAlgorithm(), GeoreferenceAlgorithm(), BuildDsmAlgorithm(), PrepareImagesAlgorithm(),
            AccuracyReportAlgorithm(), BuildOrthophotoAlgorithm(), OrthorectifyImageAlgorithm(),
            RunPipelineAlgorithm(), BuildDtmAlgorithm(), ReliefVisualisationAlgorithm(), ContoursAlgorithm(),
            AutoControlAlgorithm(), DsmDifferenceAlgorithm(), FindTargetsAlgorithm(), SpectralIndexAlgorithm(),
            StackCapturesAlgorithm(), BuildModelAlgorithm()]
