"""Spectral index: thin adapter over core.spectral.index.spectral_index."""
from qgis.core import (
    QgsProcessingOutputNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterString,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class SpectralIndexAlgorithm(AlgorithmBase):
    NAME = "spectralindex"
    DISPLAY = "Spectral index"
    REQUIRES = ()
    INPUT = "INPUT"
    INDEX = "INDEX"
    EXPRESSION = "EXPRESSION"
    NIR_BAND = "NIR_BAND"
    RED_BAND = "RED_BAND"
    RED_EDGE_BAND = "RED_EDGE_BAND"
    OUTPUT = "OUTPUT"
    VALID_CELLS = "VALID_CELLS"
    MINIMUM = "MINIMUM"
    MAXIMUM = "MAXIMUM"
    MEAN = "MEAN"
    OUTPUT_KINDS = {"OUTPUT": "index"}  # the output's style (qgisio/layers.py): red-yellow-green
    HELP = (
        "A vegetation index of a multispectral orthomosaic or any multi-band raster (a satellite scene), to see "
        "crop marks: over a buried ditch the crop grows greener (a higher index), over a buried wall it is stressed "
        "(a lower one). NDVI is (NIR - RED) / (NIR + RED), NDRE (NIR - REDEDGE) / (NIR + REDEDGE). A cell is nodata "
        "where a band used is nodata or masked (alpha band, mask) or the denominator is zero. The raster is read "
        "in blocks, so a large one needs little memory.\n\n"
        "Which band is NIR, red or red edge is read from the raster: the band's description (NIR, Red, Red edge / "
        "REG / RE, Green / GRE, Blue), a name or wavelength in its metadata (790 nm is NIR: red 600-690 nm, red edge 690-760 nm, NIR "
        "760-1000 nm) or its colour interpretation; the log says which band was taken for each name and why, and "
        "a missing name lists the bands the raster has.\n\n"
        "Input raster: the multi-band raster.\n"
        "Index: NDVI, NDRE or the expression below.\n"
        "Expression: a formula of the bands, by number (b1 is the first band) or by name, e.g. "
        "(b4 - b3) / (b4 + b3) or 2.5 * (NIR - RED) / (NIR + 2.4 * RED + 1); numbers, + - * / ** and parentheses, "
        "and the functions sqrt, abs, log, exp, min, max, clip(x, low, high).\n"
        "NIR band number, Red band number, Red-edge band number (advanced): the band to take for that name when "
        "the raster's band names do not say it or say it wrongly; 0 reads it from the names.\n"
        "Index raster: where to write the float32 Cloud-Optimized GeoTIFF (nodata -9999, the band described by "
        "the index and its formula)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            QgsProcessingParameterRasterLayer(self.INPUT, self.tr("Input raster")),
            params.choice(self.INDEX, self.tr("Index"), [self.tr("NDVI"), self.tr("NDRE"), self.tr("Expression")]),
            QgsProcessingParameterString(self.EXPRESSION, self.tr("Expression"), optional=True),
            *params.advanced(
                params.integer(self.NIR_BAND, self.tr("NIR band number")),
                params.integer(self.RED_BAND, self.tr("Red band number")),
                params.integer(self.RED_EDGE_BAND, self.tr("Red-edge band number"))),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(self.OUTPUT, self.tr("Index raster")))
        self.addOutput(QgsProcessingOutputNumber(self.VALID_CELLS, self.tr("Cells with a value")))
        self.addOutput(QgsProcessingOutputNumber(self.MINIMUM, self.tr("Lowest value")))
        self.addOutput(QgsProcessingOutputNumber(self.MAXIMUM, self.tr("Highest value")))
        self.addOutput(QgsProcessingOutputNumber(self.MEAN, self.tr("Mean value")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.spectral.index import spectral_index
        from ..core.spectral.options import INDEX_CHOICES, BandOverrides, IndexOptions

        layer = self.parameterAsRasterLayer(parameters, self.INPUT, context)
        options = IndexOptions(
            input=layer.source().split("|")[0],
            output=self.parameterAsOutputLayer(parameters, self.OUTPUT, context),
            index=params.read_choice(self, parameters, self.INDEX, context, INDEX_CHOICES),
            expression=self.parameterAsString(parameters, self.EXPRESSION, context) or "",
            bands=BandOverrides(nir=self.parameterAsInt(parameters, self.NIR_BAND, context),
                                red=self.parameterAsInt(parameters, self.RED_BAND, context),
                                red_edge=self.parameterAsInt(parameters, self.RED_EDGE_BAND, context)))
        r = self.run_core(spectral_index, options, FeedbackProgress(feedback))
        return {self.OUTPUT: r.path, self.VALID_CELLS: r.valid, self.MINIMUM: r.minimum, self.MAXIMUM: r.maximum,
                self.MEAN: r.mean}
