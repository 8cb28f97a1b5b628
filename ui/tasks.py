"""Core stages as QgsTasks: progress in the task manager and the dock, cancel within seconds, the UI
stays responsive.  The result (or the error) is handed to callbacks in the main thread."""
import traceback

from qgis.core import Qgis, QgsApplication, QgsMessageLog, QgsTask
from qgis.PyQt.QtCore import QCoreApplication, QTimer, pyqtSignal

from ..qgisio.messages import translate_message


class TaskProgress:
    """The core Progress protocol on top of a QgsTask."""

    def __init__(self, task):
        self.task = task
        self.messages = []

    def report(self, fraction, message=""):
        self.task.setProgress(100.0 * min(max(float(fraction), 0.0), 1.0))
        if message:  # the core's English in the user's language (qgisio/messages.py)
            self.task.message.emit(translate_message(message))

    def is_cancelled(self):
        return self.task.isCanceled()

    def info(self, message):
        self.messages.append(("info", message))
        QgsMessageLog.logMessage(translate_message(message), "ArchaeoOrtho", Qgis.MessageLevel.Info)

    def warning(self, message):
        self.messages.append(("warning", message))
        QgsMessageLog.logMessage(translate_message(message), "ArchaeoOrtho", Qgis.MessageLevel.Warning)


class CoreTask(QgsTask):
    """Runs ``fn(*args, progress=..., **kwargs)`` in a worker thread.

    ``on_done(result)`` / ``on_error(message, cancelled)`` run in the main thread when it ends.
    """

    message = pyqtSignal(str)

    def __init__(self, description, fn, args=(), kwargs=None, on_done=None, on_error=None):
        super().__init__(description, QgsTask.Flag.CanCancel)
        self.fn = fn
        self.args = tuple(args)
        self.kwargs = dict(kwargs or {})
        self.on_done = on_done
        self.on_error = on_error
        self.result = None
        self.error = None
        self.was_cancelled = False
        self.progress_adapter = TaskProgress(self)

    def run(self):
        from ..core.common.errors import user_message
        from ..core.common.progress import Cancelled

        try:
            self.result = self.fn(*self.args, progress=self.progress_adapter, **self.kwargs)
            return True
        except Cancelled as e:
            self.was_cancelled = True
            self.error = str(e) or "cancelled"
        except Exception as e:  # noqa: BLE001 - every failure is reported to the user, not raised in a thread
            message = user_message(e)
            if message is None and isinstance(e, OSError) and e.filename:
                # a file the user named cannot be read or written: its message names the file, no traceback.
                # An OSError without a filename, a ValueError or a RuntimeError is a bug (every core error meant
                # for the user derives from ArchaeoOrthoError).
                message = str(e)
            if message is None:  # a bug: the traceback goes to the log, the user sees the exception
                log_traceback(self.description(), e)
                message = f"{type(e).__name__}: {e}" if not str(e) else str(e)
            self.error = message
            self.was_cancelled = self.isCanceled()
        return False

    def finished(self, ok):
        if not ok and self.isCanceled():
            self.was_cancelled = True
        if not ok and self.was_cancelled:
            # QGIS desktop tells a task that ended unsuccessfully as 'Task failed: <description>' (QgisApp's
            # notification; in the message bar where the desktop has no notification service): a user's Cancel is
            # no failure, and the dock says 'Cancelled'.  The notice comes with the task manager's statusChanged,
            # before or after this call: withdrawn now and once the event loop has turned.
            description = self.description()
            withdraw_failed_notice(description)
            QTimer.singleShot(0, lambda: withdraw_failed_notice(description))
        try:
            if ok and self.on_done is not None:
                self.on_done(self.result)
            elif not ok and self.on_error is not None:
                self.on_error(self.error or "cancelled", self.was_cancelled)
        except RuntimeError as e:  # the dock was closed (plugin unloaded) while the task ran
            QgsMessageLog.logMessage(f"{self.description()}: {e}", "ArchaeoOrtho", Qgis.MessageLevel.Warning)
        except Exception as e:  # noqa: BLE001 - an exception escaping a C++ virtual would abort QGIS
            log_traceback(self.description(), e)
            _tell_user(self.description(), e)
        finally:
            self._release()

    def _release(self):
        """Drop the inputs here, in the main thread, when the task has ended.  They may hold Qt objects made in
        the main thread (the dock's layer snapshots hold provider clones); kept, they would die with the task
        whenever Python's cycle collector gets to it (the task and its progress adapter refer to each other),
        in whatever thread happens to run Python then, and a QObject must not be deleted from another thread."""
        self.fn = None
        self.args = ()
        self.kwargs = {}
        self.on_done = self.on_error = None
        self.progress_adapter.task = None  # the cycle task <-> adapter, broken: the task dies by reference count


QGIS_TASK_FAILED = "Task failed"  # QgisApp's title of the notice (translated by QGIS's own catalogue)


def withdraw_failed_notice(description):
    """Remove QGIS's 'Task failed' message-bar notice of the task ``description`` (a cancelled task); the
    number removed."""
    from qgis.utils import iface

    bar = iface.messageBar() if iface is not None else None
    items = list(bar.items()) if bar is not None and hasattr(bar, "items") else []  # none without a desktop
    titles = {QGIS_TASK_FAILED, QCoreApplication.translate("QgisApp", QGIS_TASK_FAILED)}  # QGIS's, in its language
    gone = 0
    for item in items:
        if item.text() == description and item.title() in titles:
            bar.popWidget(item)
            gone += 1
    return gone


def log_traceback(what, error):
    """The full traceback of an unexpected exception in QGIS's message log (tab ArchaeoOrtho)."""
    text = "".join(traceback.format_exception(type(error), error, error.__traceback__))
    QgsMessageLog.logMessage(f"{what}: {text}", "ArchaeoOrtho", Qgis.MessageLevel.Critical)


def _tell_user(what, error):
    """A message bar entry where QGIS has an interface (the log has the details)."""
    try:
        from qgis.utils import iface

        if iface is not None and iface.messageBar() is not None:
            iface.messageBar().pushCritical("ArchaeoOrtho", f"{what}: {type(error).__name__}: {error}")
    except Exception:  # noqa: BLE001 - telling the user must not fail in turn
        pass


def start(task):
    """Hand a task to QGIS's task manager; returns it (keep a reference until it finishes)."""
    QgsApplication.taskManager().addTask(task)
    return task
