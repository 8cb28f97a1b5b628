"""Small in-house base class for the algorithms, and the QgsFeedback <-> Progress adapter.

Every algorithm's outputs are offered to the project as styled layers when the run loads layers (the
toolbox dialog, processing.runAndLoadResults): see ``AlgorithmBase.register_styled_outputs``.  Under
qgis_process (and QGIS Server) nothing of that runs.
"""
import functools
import os
import signal
import sys
import threading
import traceback
import weakref

from qgis.core import Qgis, QgsApplication, QgsMessageLog, QgsProcessingAlgorithm, QgsProcessingException
from qgis.PyQt.QtCore import QCoreApplication

HEADLESS_PLATFORMS = ("qgis_process", "server")


def styling_enabled():
    """True where loaded outputs get our styles: QGIS desktop and Python scripts, not qgis_process."""
    try:
        return QgsApplication.platform() not in HEADLESS_PLATFORMS
    except Exception:  # noqa: BLE001 - no application object: nothing to load into
        return False


def _with_styled_outputs(process):
    """Wrap a subclass's processAlgorithm: after it returns, register its layer outputs for styling."""

    @functools.wraps(process)
    def wrapper(self, parameters, context, feedback):
        from ..core.common.errors import ArchaeoOrthoError, user_message

        check_dependencies(self.REQUIRES, self.displayName())
        try:
            results = process(self, parameters, context, feedback)
        except ArchaeoOrthoError as e:  # a stage's options refusing a value when made, before run_core
            raise QgsProcessingException(user_message(e) or str(e)) from e
        self.register_styled_outputs(results, context, feedback)
        return results

    wrapper._archaeoortho_styled = True
    return wrapper


def check_dependencies(modules, purpose=""):
    """Fail fast (before any work) when pycolmap / OpenCV are missing or of a version that does not work:
    the message names the exact pip command for this machine (core.common.dependencies)."""
    from ..core.common import dependencies
    from ..core.common.errors import MissingDependencyError

    bad = dependencies.problems(dependencies.check([r for r in dependencies.REQUIREMENTS if r.module in modules]))
    if not bad:
        return
    message = str(MissingDependencyError(bad[0].requirement.dist, purpose))
    found = [f.describe() for f in bad if f.state != "missing"]
    if found:
        message += ". Found: " + "; ".join(found)
    raise QgsProcessingException(message)


# feedback -> the (kind, message) lines pushed to it: shared by every FeedbackProgress of that feedback, since an
# algorithm may give its core calls their own (a share of the progress bar each, georeference and autocontrol do)
# and push the result's lines through another at the end: each line reaches the log once all the same
_PUSHED_TO = weakref.WeakKeyDictionary()


class FeedbackProgress:
    """The core Progress protocol on top of a QgsProcessingFeedback."""

    def __init__(self, feedback, start: float = 0.0, end: float = 1.0):
        self.feedback = feedback
        self.start = start
        self.end = end
        self._last_message = None
        # (kind, message) already in this feedback's log: a result's lines are not pushed twice
        self._pushed = set() if feedback is None else _PUSHED_TO.setdefault(feedback, set())

    def report(self, fraction, message=""):
        if self.feedback is None:
            return
        f = min(max(float(fraction), 0.0), 1.0)
        self.feedback.setProgress(100.0 * (self.start + (self.end - self.start) * f))
        if message and message != self._last_message:
            self._last_message = message
            self.feedback.setProgressText(message)

    def is_cancelled(self):
        return SIGNALLED.is_set() or bool(self.feedback is not None and self.feedback.isCanceled())

    def info(self, message):
        self._pushed.add(("info", message))
        if self.feedback is not None:
            self.feedback.pushInfo(message)

    def push_result(self, warnings=(), lines=()):
        """After the core call: its result's warnings and log lines that the core did not push while it ran
        (the core pushes most of them through :meth:`info` / :meth:`warning` already, of this FeedbackProgress
        or another on the same feedback; each appears once)."""
        for w in warnings:
            if ("warning", w) not in self._pushed:
                self.warning(w)
        for line in lines:
            if ("info", line) not in self._pushed:
                self.info(line)

    def warning(self, message):
        self._pushed.add(("warning", message))
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
    STYLE_OUTPUTS = True  # a subclass sets False to leave its outputs as QGIS loads them
    REQUIRES = ("pycolmap", "cv2")  # import names checked before processAlgorithm runs (fail fast, headless too)
    HELP_SECTION = ""  # the README heading of the algorithm's section; default: the one naming `archaeoortho:NAME`

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        process = cls.__dict__.get("processAlgorithm")
        if process is not None and not getattr(process, "_archaeoortho_styled", False):
            cls.processAlgorithm = _with_styled_outputs(process)

    def register_styled_outputs(self, results, context, feedback=None):
        """Post-processing hook: outputs that are ours (DSM, orthomosaic, cameras, residuals, point cloud)
        are loaded on completion with their styles (qgisio/layers.py: qgis.core only).  Never under
        qgis_process; a problem here is a warning, never a failed run."""
        if not self.STYLE_OUTPUTS or not styling_enabled():
            return 0
        try:
            from ..qgisio.layers import register_outputs

            return register_outputs(self, results, context)
        except Exception as e:  # noqa: BLE001 - styling must never fail an algorithm that worked
            if feedback is not None:
                feedback.pushInfo(QCoreApplication.translate("AlgorithmBase", "Outputs not styled: {}").format(e))
            return 0

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

    def helpUrl(self):  # noqa: N802 (QGIS API name)
        """The README section of this algorithm on the project page (the dialog's Help button)."""
        return help_url(self.NAME, self.HELP_SECTION)

    def createInstance(self):  # noqa: N802 (QGIS API name)
        return type(self)()

    @staticmethod
    def run_core(func, *args, **kwargs):
        """Call a core function; turn its errors into QgsProcessingException.

        A user-facing error (core.common.errors.ArchaeoOrthoError, a missing package) becomes its message;
        anything else is a bug: its traceback goes to the log first, then it fails the run (never QGIS)."""
        return call_core(func, *args, **kwargs)


PLUGIN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_HOMEPAGE = "https://github.com/archaeoortho/archaeoortho"


def _homepage():
    import configparser

    parser = configparser.ConfigParser(interpolation=None)
    try:
        parser.read(os.path.join(PLUGIN_DIR, "metadata.txt"), encoding="utf-8")
        return parser.get("general", "homepage", fallback=DEFAULT_HOMEPAGE).rstrip("/")
    except (OSError, configparser.Error):
        return DEFAULT_HOMEPAGE


def heading_anchor(heading):
    """The anchor GitHub gives a Markdown heading: lower case, punctuation dropped, spaces as hyphens."""
    import re

    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def readme_headings():
    try:
        with open(os.path.join(PLUGIN_DIR, "README.md"), encoding="utf-8") as f:
            return [line.lstrip("#").strip() for line in f if line.startswith("## ")]
    except OSError:
        return []


def help_url(name, section=""):
    """``<homepage>#<anchor>`` of the README section ``section`` (default: the heading naming
    `archaeoortho:<name>`); the README's top when there is none."""
    headings = readme_headings()
    heading = section if section in headings else next(
        (h for h in headings if f"`archaeoortho:{name}`" in h), "")
    base = _homepage()
    return f"{base}#{heading_anchor(heading)}" if heading else f"{base}#readme"


def call_core(func, *args, **kwargs):
    """Call ``func(*args, **kwargs)``: Cancelled, user errors and bugs all end as QgsProcessingException.

    The Processing log of a bug's traceback is the feedback of the FeedbackProgress passed to ``func``."""
    from ..core.common.errors import user_message
    from ..core.common.progress import Cancelled

    try:
        with SignalCancel(_feedbacks_of(args, kwargs)):
            return func(*args, **kwargs)
    except QgsProcessingException:
        raise
    except Cancelled as e:
        raise QgsProcessingException(
            QCoreApplication.translate("AlgorithmBase", "Cancelled: {}").format(e)) from e
    except Exception as e:  # noqa: BLE001 - every failure becomes a failed run, never an abort of QGIS
        message = user_message(e)
        if message is None and isinstance(e, OSError) and e.filename:
            # a file the user named cannot be read or written (missing, no permission, disk full): its message
            # names the file, shown without a traceback.  An OSError without a filename, a ValueError or a
            # RuntimeError is a bug (every core error meant for the user derives from ArchaeoOrthoError).
            message = str(e)
        if message is not None:
            raise QgsProcessingException(message) from e
        report_bug(e, _feedback_of(args, kwargs))
        raise QgsProcessingException(f"{type(e).__name__}: {e}") from e


# set while a SIGINT / SIGTERM asks the running core call to stop (FeedbackProgress.is_cancelled reads it)
SIGNALLED = threading.Event()


class SignalCancel:
    """SIGINT and SIGTERM as a cancel while a core call runs in the main thread of a headless process
    (qgis_process, a standalone script): the same path as the GUI's Cancel (the stage is recorded cancelled by
    run_stage, pool workers see the cancel file, nothing half-written stays).  A second signal gets what the
    signal did before (qgis_process's or glog's handler, else the default action: stop at once).  The previous
    handlers, C ones included (saved with sigaction where libc has it), are back when the call returns."""

    SIGNALS = ("SIGINT", "SIGTERM")

    def __init__(self, feedbacks=()):
        self.feedbacks = list(feedbacks)
        self.previous = {}  # signal -> (Python handler or None for a C one, saved C sigaction or None)

    def __enter__(self):
        if threading.current_thread() is not threading.main_thread() or not headless():
            return self
        SIGNALLED.clear()
        _import_pycolmap_first()
        for name in self.SIGNALS:
            sig = getattr(signal, name, None)
            if sig is None:
                continue
            saved = _save_sigaction(sig)
            try:
                previous = signal.getsignal(sig)
                signal.signal(sig, self._handle)
            except (ValueError, OSError, TypeError):  # not the main interpreter, or a signal it cannot catch
                continue
            self.previous[sig] = (previous, saved)
        return self

    def _handle(self, signum, frame):
        if SIGNALLED.is_set():  # asked twice: what the signal did before
            previous = self.previous.get(signum, (signal.SIG_DFL, None))[0]
            self._restore()
            if callable(previous):
                previous(signum, frame)
            else:
                os.kill(os.getpid(), signum)
            return
        SIGNALLED.set()
        for feedback in self.feedbacks:
            try:
                feedback.pushWarning(f"{signal.Signals(signum).name}: cancelling (send it again to stop at once)")
                feedback.cancel()
            except Exception:  # noqa: BLE001,S110 - the flag alone cancels the core call
                pass

    def _restore(self):
        for sig, (handler, saved) in self.previous.items():
            try:
                signal.signal(sig, signal.SIG_DFL if handler is None else handler)
            except (ValueError, OSError, TypeError):
                pass
            if saved is not None:
                _restore_sigaction(sig, saved)
        self.previous = {}

    def __exit__(self, *exc):
        self._restore()
        SIGNALLED.clear()
        return False


def _libc():
    import ctypes

    return ctypes.CDLL(None, use_errno=True)


def _save_sigaction(sig):
    """The C-level action of ``sig`` (an opaque struct sigaction), or None where libc has no sigaction."""
    if os.name == "nt":
        return None
    try:
        import ctypes

        buf = ctypes.create_string_buffer(512)  # larger than struct sigaction on every libc
        return buf if _libc().sigaction(int(sig), None, buf) == 0 else None
    except (OSError, AttributeError):
        return None


def _restore_sigaction(sig, saved):
    try:
        _libc().sigaction(int(sig), saved, None)
    except (OSError, AttributeError):
        pass


def _import_pycolmap_first():
    """pycolmap's import installs glog's failure handler for SIGTERM (a stack trace, then death): import it
    before our handlers go in, so that they are the ones that hear the signal."""
    import importlib.util

    try:
        if "pycolmap" not in sys.modules and importlib.util.find_spec("pycolmap") is not None:
            importlib.import_module("pycolmap")
    except Exception:  # noqa: BLE001,S110 - a broken pycolmap is reported by the core call itself
        pass


def headless():
    """True without a QGIS desktop GUI (qgis_process, QGIS Server, a standalone script)."""
    try:
        return QgsApplication.platform() != "desktop"
    except Exception:  # noqa: BLE001 - no application object
        return True


def _feedbacks_of(args, kwargs):
    return [v.feedback for v in list(args) + list(kwargs.values())
            if isinstance(v, FeedbackProgress) and v.feedback is not None]


def _feedback_of(args, kwargs):
    for value in list(args) + list(kwargs.values()):
        if isinstance(value, FeedbackProgress):
            return value.feedback
    return None


def report_bug(error, feedback=None):
    """Put the traceback of an unexpected exception in the Processing log (or QGIS's message log)."""
    text = "".join(traceback.format_exception(type(error), error, error.__traceback__))
    if feedback is not None:
        feedback.reportError(text, False)
    else:
        QgsMessageLog.logMessage(text, "ArchaeoOrtho", Qgis.MessageLevel.Critical)
