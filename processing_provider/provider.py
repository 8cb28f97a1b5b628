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
        from .align_images import AlignImagesAlgorithm
        from .build_dsm import BuildDsmAlgorithm
        from .georeference import GeoreferenceAlgorithm
        from .prepare_images import PrepareImagesAlgorithm

        for alg in (AlignImagesAlgorithm(), GeoreferenceAlgorithm(), BuildDsmAlgorithm(), PrepareImagesAlgorithm()):
            self.addAlgorithm(alg)
        from .accuracy_report import AccuracyReportAlgorithm

        self.addAlgorithm(AccuracyReportAlgorithm())
        from .build_orthophoto import BuildOrthophotoAlgorithm
        from .orthorectify_image import OrthorectifyImageAlgorithm

        for alg in (BuildOrthophotoAlgorithm(), OrthorectifyImageAlgorithm()):
            self.addAlgorithm(alg)
        from .run_pipeline import RunPipelineAlgorithm

        self.addAlgorithm(RunPipelineAlgorithm())
