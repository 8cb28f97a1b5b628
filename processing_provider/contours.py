"""Contours: thin adapter over core.terrain.contours.write_contours."""
from qgis.core import (
    QgsProcessingOutputNumber,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterRasterLayer,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class ContoursAlgorithm(AlgorithmBase):
    NAME = "contours"
    DISPLAY = "Contours"
    REQUIRES = ()
    INPUT = "INPUT"
    INTERVAL = "INTERVAL"
    OUTPUT = "OUTPUT"
    LINES = "LINES"
    OUTPUT_KINDS = {"OUTPUT": "contours"}
    HELP = (
        "Contour lines of a DTM or DSM at a chosen interval (GDAL's contour generator) into a GeoPackage layer "
        "'contours' whose 'elevation' field labels them.\n\n"
        "Elevation raster: a DTM or DSM in a projected CRS (metres).\n"
        "Interval: metres between two contour lines (e.g. 0.5).\n"
        "Contours: the GeoPackage to write."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            QgsProcessingParameterRasterLayer(self.INPUT, self.tr("Elevation raster")),
            params.number(self.INTERVAL, self.tr("Interval in metres"), 1.0, 0.001),
        )
        self.addParameter(QgsProcessingParameterFileDestination(
            self.OUTPUT, self.tr("Contours"), fileFilter="GeoPackage (*.gpkg)"))
        self.addOutput(QgsProcessingOutputNumber(self.LINES, self.tr("Contour lines")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.terrain.contours import write_contours

        layer = self.parameterAsRasterLayer(parameters, self.INPUT, context)
        path = layer.source().split("|")[0]
        output = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        n = self.run_core(write_contours, path, output, self.parameterAsDouble(parameters, self.INTERVAL, context),
                          progress=FeedbackProgress(feedback), what="elevation raster")
        return {self.OUTPUT: output, self.LINES: n}
