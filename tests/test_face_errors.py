"""The faces' error policy (processing_provider/base.py call_core, ui/tasks.py CoreTask.run): an
ArchaeoOrthoError, and an OSError that names a file, are shown as their message; a ValueError, a RuntimeError
or an OSError without a filename is a bug: its traceback goes to the log."""
import errno
import os

import pytest

pytestmark = pytest.mark.usefixtures("qgis_app")


def fail(error, progress=None):
    raise error


def _processing_log():
    from qgis.core import QgsProcessingFeedback

    class Log(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.errors = []

        def reportError(self, error, fatalError=False):  # noqa: N802, N803 (QGIS API names)
            self.errors.append(error)

    return Log()


def test_call_core_shows_a_named_file_and_logs_bare_value_and_runtime_errors(tmp_path):
    from archaeoortho.processing_provider.base import AlgorithmBase, FeedbackProgress
    from qgis.core import QgsProcessingException

    missing = str(tmp_path / "dsm.tif")
    feedback = _processing_log()
    progress = FeedbackProgress(feedback)
    with pytest.raises(QgsProcessingException) as e:
        AlgorithmBase.run_core(fail, OSError(errno.ENOENT, os.strerror(errno.ENOENT), missing), progress=progress)
    assert missing in str(e.value) and "OSError" not in str(e.value)
    assert feedback.errors == []

    for error in (ValueError("bad shape"), RuntimeError("solver diverged"), OSError("no space left")):
        feedback.errors.clear()
        with pytest.raises(QgsProcessingException, match=f"^{type(error).__name__}: {error}$"):
            AlgorithmBase.run_core(fail, error, progress=progress)
        assert len(feedback.errors) == 1 and "Traceback" in feedback.errors[0], type(error)


def test_core_task_shows_a_named_file_and_logs_a_bare_value_error(tmp_path):
    from archaeoortho.ui.tasks import CoreTask
    from qgis.core import QgsApplication

    logged, errors = [], []
    log = QgsApplication.messageLog()

    def keep(message, tag, level):
        logged.append(message)

    log.messageReceived.connect(keep)
    try:
        missing = str(tmp_path / "photo.jpg")
        task = CoreTask("t", fail, (FileNotFoundError(errno.ENOENT, "No such file or directory", missing),),
                        on_error=lambda message, cancelled: errors.append(message))
        assert task.run() is False
        task.finished(False)
        task = CoreTask("t2", fail, (ValueError("bad shape"),), on_error=lambda message, cancelled: errors.append(message))
        assert task.run() is False
        task.finished(False)
    finally:
        log.messageReceived.disconnect(keep)
    assert len(errors) == 2 and missing in errors[0] and errors[1] == "bad shape"
    assert not any(missing in m for m in logged), logged
    assert any("Traceback" in m and "ValueError: bad shape" in m for m in logged), logged


def test_guided_read_gray_names_the_unreadable_photo(tmp_path):
    from core.common.errors import ArchaeoOrthoError
    from core.georef.guided import read_gray

    bad = tmp_path / "not_a_photo.jpg"
    bad.write_text("text, not JPEG")
    with pytest.raises(ArchaeoOrthoError, match="not_a_photo.jpg"):
        read_gray(str(bad))


def test_core_task_releases_its_inputs_in_the_main_thread_when_it_ends():
    """A CoreTask's inputs (the dock's layer snapshots hold provider clones, Qt objects of the main thread) are
    released when it ends, in the main thread, by reference count: not left to Python's cycle collector, which
    would free them later in whatever thread runs Python then.  The task runs in QGIS's task manager here."""
    import gc
    import threading
    import time

    from archaeoortho.ui.tasks import CoreTask
    from qgis.core import QgsApplication
    from qgis.PyQt.QtCore import QCoreApplication

    freed = []

    class Input:
        def __del__(self):
            freed.append(threading.current_thread() is threading.main_thread())

    def work(thing, progress=None):
        progress.report(0.5, "half way")
        return "done"

    done = []
    gc.disable()  # only reference counts free things in this test
    try:
        task = CoreTask("release", work, (Input(),), on_done=done.append)
        QgsApplication.taskManager().addTask(task)
        t0 = time.time()
        while not done and time.time() - t0 < 30:
            QCoreApplication.processEvents()
            time.sleep(0.01)
        assert done == ["done"]
        assert freed == [True]  # freed already, and in the main thread
        assert task.progress_adapter.task is None  # no task <-> adapter cycle left
    finally:
        gc.enable()


def test_each_warning_reaches_the_log_once_whichever_progress_pushed_it():
    """Issue 36 item 14: warnings appeared twice in the log of Georeference with automatic control and of
    Automatic control: their core call pushed each warning through its own FeedbackProgress (a share of the
    progress bar) and the algorithm then pushed the result's warnings through another, whose record of what was
    already pushed was empty.  The record is the feedback's, shared by every FeedbackProgress on it."""
    from archaeoortho.processing_provider.base import FeedbackProgress
    from qgis.core import QgsProcessingFeedback

    class Log(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.lines = []

        def pushWarning(self, warning):  # noqa: N802 (QGIS API name)
            self.lines.append(("warning", warning))

        def pushInfo(self, info):  # noqa: N802 (QGIS API name)
            self.lines.append(("info", info))

    feedback = Log()
    progress = FeedbackProgress(feedback)
    core = FeedbackProgress(feedback, 0.1, 1.0)  # as georeference.py / auto_control.py give their core call
    core.warning("outlier A12 left out")
    core.info("12 automatic GCPs")
    progress.push_result(["outlier A12 left out", "weak geometry"], ["12 automatic GCPs", "done"])
    assert feedback.lines == [("warning", "outlier A12 left out"), ("info", "12 automatic GCPs"),
                              ("warning", "weak geometry"), ("info", "done")]
    # another run (another feedback) starts with an empty record
    other = Log()
    FeedbackProgress(other).push_result(["outlier A12 left out"])
    assert other.lines == [("warning", "outlier A12 left out")]


def test_options_refused_when_made_in_process_algorithm_are_a_message():
    """A stage's options check their values when made (issue 35): made in processAlgorithm before run_core, a
    refusal is the run's message, not a traceback; a bug there still propagates as itself."""
    from archaeoortho.core.georef.options import GeorefOptions
    from archaeoortho.processing_provider.base import AlgorithmBase
    from qgis.core import QgsProcessingException

    class Bad(AlgorithmBase):
        NAME = "bad"
        REQUIRES = ()

        def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
            GeorefOptions(outlier_threshold=parameters["t"])
            return {}

    with pytest.raises(QgsProcessingException, match=r"GeorefOptions.outlier_threshold must be a positive number"):
        Bad().processAlgorithm({"t": -1.0}, None, None)
    with pytest.raises(KeyError):  # a bug is not turned into a user message
        Bad().processAlgorithm({}, None, None)
