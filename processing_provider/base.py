"""Small in-house base class for the algorithms, and the QgsFeedback <-> Progress adapter."""
from qgis.core import QgsProcessingAlgorithm, QgsProcessingException
from qgis.PyQt.QtCore import QCoreApplication


class FeedbackProgress:
    """The core Progress protocol on top of a QgsProcessingFeedback."""

    def __init__(self, feedback, start: float = 0.0, end: float = 1.0):
        self.feedback = feedback
        self.start = start
        self.end = end
        self._last_message = None

    def report(self, fraction, message=""):
        if self.feedback is None:
            return
        f = min(max(float(fraction), 0.0), 1.0)
        self.feedback.setProgress(100.0 * (self.start + (self.end - self.start) * f))
        if message and message != self._last_message:
            self._last_message = message
            self.feedback.setProgressText(message)

    def is_cancelled(self):
        return bool(self.feedback is not None and self.feedback.isCanceled())

    def info(self, message):
        if self.feedback is not None:
            self.feedback.pushInfo(message)

    def warning(self, message):
        if self.feedback is None:
            return
        if hasattr(self.feedback, "pushWarning"):
            self.feedback.pushWarning(message)
        else:  # pragma: no cover - QGIS < 3.16
            self.feedback.reportError(message, False)


class AlgorithmBase(QgsProcessingAlgorithm):
    """tr(), createInstance(), groups, help; subclasses set NAME, DISPLAY, GROUP, HELP."""

    NAME = ""
    DISPLAY = ""
    HELP = ""
    GROUP_ID = "photogrammetry"
    GROUP = "Photogrammetry"

    def tr(self, text):
        return QCoreApplication.translate(type(self).__name__, text)

    def name(self):
        return self.NAME

    def displayName(self):  # noqa: N802 (QGIS API name)
        return self.tr(self.DISPLAY)

    def group(self):
        return QCoreApplication.translate("AlgorithmBase", self.GROUP)

    def groupId(self):  # noqa: N802 (QGIS API name)
        return self.GROUP_ID

    def shortHelpString(self):  # noqa: N802 (QGIS API name)
        return self.tr(self.HELP)

    def createInstance(self):  # noqa: N802 (QGIS API name)
        return type(self)()

    @staticmethod
    def run_core(func, *args, **kwargs):
        """Call a core function; turn its clear errors into QgsProcessingException."""
        from ..core.progress import Cancelled

        try:
            return func(*args, **kwargs)
        except Cancelled as e:
            raise QgsProcessingException(
                QCoreApplication.translate("AlgorithmBase", "Cancelled: {}").format(e)) from e
        except (ValueError, RuntimeError, OSError) as e:
            raise QgsProcessingException(str(e)) from e
