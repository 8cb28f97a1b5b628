"""DSM difference: thin adapter over core.terrain.difference.dsm_difference."""
from qgis.core import (
    QgsProcessingOutputNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress


class DsmDifferenceAlgorithm(AlgorithmBase):
    NAME = "dsmdifference"
    DISPLAY = "DSM difference"
    REQUIRES = ()
    DSM_A = "DSM_A"
    DSM_B = "DSM_B"
    OUTPUT = "OUTPUT"
    MEDIAN = "MEDIAN"
    STD = "STD"
    CELLS = "CELLS"
    CHANGED = "CHANGED"
    HELP = (
        "The later DSM minus the earlier one, on the earlier one's grid, shows what changed between two epochs "
        "of a site (the later DSM is warped there with GDAL, bilinear, from any CRS). A cell is nodata where either "
        "DSM has none. The log gives the cells compared, the median, mean and standard deviation of the "
        "difference, its 5th and 95th percentiles and the cells that changed by more than 1 m; a median near 0 "
        "says the two epochs are registered on each other.\n\n"
        "Earlier DSM: the DSM the difference is measured from (its grid is the output's).\n"
        "Later DSM: the DSM of the other epoch (e.g. a block registered to the earlier one with Automatic "
        "control).\n"
        "Difference: where to write the float32 Cloud-Optimized GeoTIFF of later minus earlier (metres)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            QgsProcessingParameterRasterLayer(self.DSM_A, self.tr("Earlier DSM")),
            QgsProcessingParameterRasterLayer(self.DSM_B, self.tr("Later DSM")),
        )
        self.addParameter(QgsProcessingParameterRasterDestination(self.OUTPUT, self.tr("Difference")))
        self.addOutput(QgsProcessingOutputNumber(self.MEDIAN, self.tr("Median difference (m)")))
        self.addOutput(QgsProcessingOutputNumber(self.STD, self.tr("Standard deviation of the difference (m)")))
        self.addOutput(QgsProcessingOutputNumber(self.CELLS, self.tr("Cells compared")))
        self.addOutput(QgsProcessingOutputNumber(self.CHANGED, self.tr("Cells changed by more than 1 m")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.terrain.difference import dsm_difference

        a = self.parameterAsRasterLayer(parameters, self.DSM_A, context).source().split("|")[0]
        b = self.parameterAsRasterLayer(parameters, self.DSM_B, context).source().split("|")[0]
        output = self.parameterAsOutputLayer(parameters, self.OUTPUT, context)
        progress = FeedbackProgress(feedback)
        r = self.run_core(dsm_difference, a, b, output, progress=progress)
        progress.info(self.tr("{} cells compared: median {:.3f} m, mean {:.3f} m, std {:.3f} m, 5-95 % {:.3f} .. "
                              "{:.3f} m; {} cells changed by more than {:g} m").format(
            r.cells, r.median, r.mean, r.std, r.p5, r.p95, r.changed, r.threshold))
        return {self.OUTPUT: r.path, self.MEDIAN: r.median, self.STD: r.std, self.CELLS: r.cells,
                self.CHANGED: r.changed}
