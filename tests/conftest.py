"""Shared fixtures.  Core tests need no QGIS; QGIS tests use pytest-qgis (offscreen)."""
import os
import shutil
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED_DATA = os.environ.get("ARCHAEOORTHO_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
SAMPLE = os.path.join(ROOT, "sample", "toledo")
PLUGINS = os.path.join(ROOT, "build", "qgis-plugins")

for p in (ROOT, PLUGINS, "/usr/share/qgis/python/plugins"):
    if os.path.isdir(p) and p not in sys.path:
        sys.path.insert(0 if p == ROOT else len(sys.path), p)

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


def shared(*parts):
    path = os.path.join(SHARED_DATA, *parts)
    if not os.path.exists(path):
        pytest.skip(f"shared data not available: {path}")
    return path


def copy_images(src_dir, names, dst_dir):
    os.makedirs(dst_dir, exist_ok=True)
    for n in names:
        shutil.copyfile(os.path.join(src_dir, n), os.path.join(dst_dir, n))
    return dst_dir


# A strip of overlapping Toledo images (shipped in sample/ so tests never depend on ../shared)
TOLEDO_STRIP = ["1JI_0064.JPG", "1JI_0065.JPG", "1JI_0066.JPG", "1JI_0067.JPG", "1JI_0068.JPG", "1JI_0076.JPG"]


_ENABLED = {}


def qgis_process():
    """(qgis_process executable, environment) exactly as a user runs it headless: the venv's packages on
    PYTHONPATH, the plugin folder, the private profile, and the plugin enabled in that profile (checked once a
    session: a profile that QGIS rewrote, or one made fresh, must not hide the provider).  Skips without
    qgis_process or the plugin link ('make setup' makes both)."""
    import subprocess
    import sysconfig

    exe = os.environ.get("QGIS_PROCESS") or "/usr/bin/qgis_process.bin"
    if not os.path.exists(exe):
        pytest.skip("qgis_process not installed")
    if not os.path.islink(os.path.join(PLUGINS, "archaeoortho")):
        pytest.skip("plugin link missing: run 'make setup'")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")])
    env["QGIS_PLUGINPATH"] = PLUGINS
    env["QT_QPA_PLATFORM"] = "offscreen"
    env.setdefault("QGIS_CUSTOM_CONFIG_PATH", os.path.join(ROOT, "build", "qgis-profile"))
    key = env["QGIS_CUSTOM_CONFIG_PATH"]
    if key not in _ENABLED:
        out = subprocess.run([exe, "plugins", "enable", "archaeoortho"], env=env, capture_output=True, text=True,
                             timeout=300)
        listing = subprocess.run([exe, "plugins"], env=env, capture_output=True, text=True, timeout=300)
        assert "* archaeoortho" in listing.stdout, (
            f"qgis_process did not enable the plugin: {out.stdout[-1500:]} {out.stderr[-1500:]} {listing.stdout}")
        _ENABLED[key] = True
    return exe, env


@pytest.fixture(scope="module")
def plugin(qgis_iface, qgis_processing):
    """The plugin loaded and its Processing provider registered, once per test module (a module may define its
    own)."""
    import archaeoortho

    _real_layer_tree_view(qgis_iface)
    p = archaeoortho.classFactory(qgis_iface)
    p.initProcessing()
    yield p
    p.unload()


_VIEWS = []


def _real_layer_tree_view(iface):
    """From QGIS 3.44 the toolbox dialog's end of a run hands ``iface.layerTreeView()`` to C++
    (QgsProcessingGuiUtils.addResultLayers), which refuses pytest-qgis's mock: a real view of the project's tree."""
    from unittest import mock

    if not isinstance(iface.layerTreeView(), mock.Mock):
        return
    from qgis.core import QgsLayerTreeModel, QgsProject
    from qgis.gui import QgsLayerTreeView

    view = QgsLayerTreeView()
    model = QgsLayerTreeModel(QgsProject.instance().layerTreeRoot())
    view.setModel(model)
    _VIEWS.append((view, model))
    iface.layerTreeView = lambda: view


@pytest.fixture(scope="session")
def toledo_strip(tmp_path_factory):
    d = tmp_path_factory.mktemp("toledo strip")
    return copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP, str(d / "imáges ü"))


# QGIS 3.22's Python bindings can crash while the interpreter tears itself down after
# exitQgis() (a known teardown-order problem of sip-wrapped singletons): every test has
# passed and been reported, yet the process dies with SIGSEGV and make fails.  Once pytest
# has written all its reports, leave without running the interpreter's finalisers.
_EXIT_STATUS = {}


def pytest_sessionstart(session):
    """A crash in C++ (SIGSEGV, SIGABRT) prints every thread's Python stack to stderr: enabled again here, after
    QGIS has started (pytest-qgis starts it at configure time), so a handler set meanwhile cannot hide it (an
    intermittent SIGSEGV of the QGIS 3.40 leg at test_dock_automatic_control left no trace)."""
    import faulthandler

    # the real stderr: pytest's fd capture has fd 2 point at a temporary file, lost when the process dies
    capman = session.config.pluginmanager.getplugin("capturemanager")
    err = getattr(getattr(capman, "_global_capturing", None), "err", None)
    fd = getattr(err, "targetfd_save", None)
    _FAULT_FILE["file"] = os.fdopen(os.dup(fd), "w") if isinstance(fd, int) else sys.__stderr__
    faulthandler.enable(file=_FAULT_FILE["file"], all_threads=True)


_FAULT_FILE = {}


def pytest_collection_modifyitems(config, items):
    """Marks each test ``every_leg`` unless tests/legs.py names it one-leg: the chroot legs of CI run
    ``-m every_leg`` (tests/legs.py says why each test runs where); the costliest files first (pytest-xdist then
    ends both workers together)."""
    from tests import legs

    for item in items:
        if not legs.one_leg(item.nodeid):
            item.add_marker(pytest.mark.every_leg)
        if legs.in_edit_loop(item.nodeid):
            item.add_marker(pytest.mark.fast)
    items.sort(key=lambda item: legs.slowest_first(item.nodeid))  # stable: a file's tests keep their order


def pytest_sessionfinish(session, exitstatus):
    _EXIT_STATUS["status"] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    if "status" in _EXIT_STATUS and os.environ.get("ARCHAEOORTHO_HARD_EXIT", "1") == "1":
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_EXIT_STATUS["status"])
