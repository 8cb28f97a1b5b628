"""Wires the faces into QGIS: the Processing provider (always) and, with a GUI, the docks."""
import os

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QCoreApplication, QLocale, QSettings, QTranslator

PLUGIN_DIR = os.path.dirname(__file__)


def _locale() -> str:
    value = QSettings().value("locale/userLocale", "") or QLocale.system().name()
    return str(value)[:2]


class ArchaeoOrthoPlugin:
    """QGIS plugin object.  ``iface`` is None under qgis_process: nothing GUI-only runs then."""

    def __init__(self, iface):
        self.iface = iface
        self.provider = None
        self.translator = None
        self._install_translator()

    def _install_translator(self):
        qm = os.path.join(PLUGIN_DIR, "i18n", f"archaeoortho_{_locale()}.qm")
        if os.path.exists(qm):
            self.translator = QTranslator()
            if self.translator.load(qm):
                QCoreApplication.installTranslator(self.translator)

    def initProcessing(self):  # noqa: N802 (QGIS API name)
        if self.provider is not None:
            return
        from .processing_provider.provider import ArchaeoOrthoProvider

        self.provider = ArchaeoOrthoProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802 (QGIS API name)
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
        if self.translator is not None:
            QCoreApplication.removeTranslator(self.translator)
            self.translator = None
