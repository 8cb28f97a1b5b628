"""The plugin as QGIS loads it: classFactory, provider registration, processing.run (pytest-qgis)."""
import json
import os
import subprocess
import sys

import pytest

from tests.conftest import PLUGINS, SAMPLE, TOLEDO_STRIP, copy_images, qgis_process

pytestmark = pytest.mark.usefixtures("qgis_processing")


def _providers():
    from qgis.core import QgsApplication

    return [p for p in QgsApplication.processingRegistry().providers() if p.id() == "archaeoortho"]


@pytest.fixture(scope="module")
def plugin(qgis_iface, qgis_processing):
    import archaeoortho

    p = archaeoortho.classFactory(qgis_iface)
    p.initProcessing()
    p.initGui()
    yield p
    p.unload()


def test_provider_registered_once(plugin):
    plugin.initProcessing()  # QGIS may call both initProcessing and initGui
    provs = _providers()
    assert len(provs) == 1
    assert provs[0].name() == "ArchaeoOrtho"
    assert "archaeoortho:alignimages" in [a.id() for a in provs[0].algorithms()]


def test_algorithm_parameters_are_the_interface(plugin):
    from qgis.core import QgsApplication

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:alignimages")
    names = {p.name() for p in alg.parameterDefinitions()}
    assert {"IMAGES", "WORKSPACE", "PAIRING", "CAMERA_MODEL", "MAX_IMAGE_SIZE", "FOCAL_MM",
            "SENSOR_WIDTH_MM", "SINGLE_CAMERA"} <= names
    outs = {o.name() for o in alg.outputDefinitions()}
    assert {"WORKSPACE", "CAMERAS", "REGISTERED_IMAGES", "MEAN_REPROJECTION_ERROR"} <= outs
    assert alg.shortHelpString()


@pytest.mark.slow
def test_processing_run_align(plugin, tmp_path):
    from qgis import processing
    from qgis.core import QgsProcessingFeedback, QgsVectorLayer

    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:4], str(tmp_path / "img"))
    feedback = QgsProcessingFeedback()
    progress = []
    feedback.progressChanged.connect(progress.append)
    res = processing.run("archaeoortho:alignimages", {
        "IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "MAX_IMAGE_SIZE": 800, "MAX_FEATURES": 2048,
    }, feedback=feedback)
    assert res["REGISTERED_IMAGES"] == 4
    assert 0 < res["MEAN_REPROJECTION_ERROR"] < 1.0
    assert os.path.isfile(os.path.join(res["WORKSPACE"], "workspace.json"))
    layer = QgsVectorLayer(res["CAMERAS"], "cameras", "ogr")
    assert layer.isValid() and layer.featureCount() == 4
    assert progress and max(progress) == pytest.approx(100.0)


@pytest.mark.slow
def test_cancel_button_stops_the_stage(plugin, tmp_path):
    from qgis import processing
    from qgis.core import QgsProcessingException, QgsProcessingFeedback

    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:4], str(tmp_path / "img"))
    feedback = QgsProcessingFeedback()

    def maybe_cancel(value):
        if value > 40:  # matching has started
            feedback.cancel()

    feedback.progressChanged.connect(maybe_cancel)
    with pytest.raises(QgsProcessingException, match="[Cc]ancel"):
        processing.run("archaeoortho:alignimages", {
            "IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "MAX_IMAGE_SIZE": 800, "MAX_FEATURES": 2048,
        }, feedback=feedback)
    manifest = json.load(open(tmp_path / "ws" / "workspace.json"))
    assert manifest["stages"]["align"]["status"] == "cancelled"
    assert not os.path.exists(tmp_path / "ws" / "sfm" / "model")


@pytest.mark.slow
def test_qgis_process_cli_end_to_end(tmp_path):
    """Exactly as a user runs it headless: qgis_process --json run archaeoortho:alignimages."""
    exe, env = qgis_process()
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:4], str(tmp_path / "my photos ä"))
    ws = str(tmp_path / "work space")
    out = subprocess.run([exe, "--json", "run", "archaeoortho:alignimages", "--", f"IMAGES={images}",
                          f"WORKSPACE={ws}", "MAX_IMAGE_SIZE=800", "MAX_FEATURES=2048"],
                         env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    result = json.loads(out.stdout)["results"]
    assert result["REGISTERED_IMAGES"] == 4
    assert result["MEAN_REPROJECTION_ERROR"] < 1.0
    assert os.path.samefile(result["WORKSPACE"], ws)
    # a bad input gives a clear message and a non-zero exit
    bad = subprocess.run([exe, "run", "archaeoortho:alignimages", "--", f"IMAGES={tmp_path}/nothing-here",
                          f"WORKSPACE={tmp_path}/ws2"], env=env, capture_output=True, text=True, timeout=300)
    assert bad.returncode != 0
    assert "nothing-here" in (bad.stdout + bad.stderr)


def test_plugin_imports_nothing_gui_only_headless():
    """Importing the plugin and its provider in plain Python pulls in none of the plugin's ui modules (docks, map tools)."""
    code = (f"import sys; sys.path.insert(0, {PLUGINS!r}); import archaeoortho, archaeoortho.processing_provider.provider;"
            "import archaeoortho.processing_provider.align_images;"
            "bad=[m for m in sys.modules if m.startswith('archaeoortho.ui')];"
            "print(bad); sys.exit(1 if bad else 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.slow
def test_processing_align_then_georeference_with_exif_gps(plugin, tmp_path):
    from qgis import processing
    from qgis.core import QgsProcessingException, QgsVectorLayer

    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:5], str(tmp_path / "img"))
    ws = processing.run("archaeoortho:alignimages", {
        "IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "MAX_IMAGE_SIZE": 800, "MAX_FEATURES": 2048,
    })["WORKSPACE"]
    with pytest.raises(QgsProcessingException, match="Give ground control"):
        processing.run("archaeoortho:georeference", {"WORKSPACE": ws})
    res = processing.run("archaeoortho:georeference", {"WORKSPACE": ws, "USE_EXIF_GPS": True, "CRS": "EPSG:32617"})
    assert res["WORKSPACE"] == ws
    assert res["CAMERA_RMSE_XYZ"] < 5.0
    cams = QgsVectorLayer(res["CAMERAS"], "cameras", "ogr")
    assert cams.isValid() and cams.featureCount() == 5
    assert cams.crs().authid() == "EPSG:32617"
    x = [f.geometry().asPoint().x() for f in cams.getFeatures()]
    assert all(274800 < v < 275100 for v in x)


def test_run_core_turns_errors_into_processing_exceptions():
    """User errors show their message, a missing package names itself and how to install it, and a bug keeps
    its traceback in the log before it fails the run (never escaping as a raw exception)."""
    from archaeoortho.core.common.errors import ArchaeoOrthoError, MissingDependencyError
    from archaeoortho.core.common.progress import Cancelled
    from archaeoortho.processing_provider.base import AlgorithmBase, FeedbackProgress
    from qgis.core import QgsProcessingException, QgsProcessingFeedback

    class Log(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.errors = []

        def reportError(self, error, fatalError=False):
            self.errors.append(error)

    def fail(error, progress=None):
        raise error

    feedback = Log()
    progress = FeedbackProgress(feedback)
    with pytest.raises(QgsProcessingException, match="^the workspace is broken$"):
        AlgorithmBase.run_core(fail, ArchaeoOrthoError("the workspace is broken"), progress=progress)
    with pytest.raises(QgsProcessingException, match="pycolmap.*pip install"):
        AlgorithmBase.run_core(fail, MissingDependencyError("pycolmap", "alignment"), progress=progress)
    with pytest.raises(QgsProcessingException, match="opencv-python-headless.*pip install"):
        AlgorithmBase.run_core(fail, ModuleNotFoundError("No module named 'cv2'", name="cv2"), progress=progress)
    with pytest.raises(QgsProcessingException, match="Cancelled"):
        AlgorithmBase.run_core(fail, Cancelled("stop"), progress=progress)
    assert feedback.errors == []
    with pytest.raises(QgsProcessingException, match="KeyError"):
        AlgorithmBase.run_core(fail, KeyError("focal"), progress=progress)
    assert len(feedback.errors) == 1 and "Traceback" in feedback.errors[0] and "KeyError" in feedback.errors[0]


def test_core_task_reports_user_errors_and_survives_failing_callbacks(qgis_app):
    """CoreTask: a user error's message goes to on_error; an exception raised by a callback is logged with
    its traceback instead of escaping into QGIS's C++ (which would abort it)."""
    from archaeoortho.core.common.errors import ArchaeoOrthoError
    from archaeoortho.ui.tasks import CoreTask
    from qgis.core import QgsApplication

    logged = []
    log = QgsApplication.messageLog()

    def keep(message, tag, level):
        logged.append(message)
    log.messageReceived.connect(keep)
    errors = []

    def user_error(progress=None):
        raise ArchaeoOrthoError("no control points")

    task = CoreTask("t", user_error, on_error=lambda message, cancelled: errors.append((message, cancelled)))
    assert task.run() is False
    task.finished(False)
    assert errors == [("no control points", False)]

    def broken_callback(result):
        raise TypeError("a bug in the dock")

    task = CoreTask("t2", lambda progress=None: 42, on_done=broken_callback)
    assert task.run() is True
    task.finished(True)  # must not raise
    log.messageReceived.disconnect(keep)
    assert any("TypeError: a bug in the dock" in m and "Traceback" in m for m in logged), logged
