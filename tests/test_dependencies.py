"""Installing pycolmap / OpenCV from QGIS (core.common.dependencies + ui/dependencies.py).

End to end on Linux: a Python WITHOUT pycolmap/cv2 (a venv of Debian's /usr/bin/python3), a fresh QGIS
profile, the installer's own pip command against a local wheel folder (build/wheels, downloaded once), then a
real alignment in that Python with the plugin folder put on sys.path by core.common.dependencies, and
qgis_process (whose Python is the system one) before and after the install.  The dialog is driven with a
tiny local wheel and with commands that fail or hang.
"""
import base64
import glob
import hashlib
import os
import re
import subprocess
import sys
import time
import zipfile

import pytest

from core.common import dependencies as deps
from tests.conftest import PLUGINS, ROOT, SAMPLE, TOLEDO_STRIP, copy_images

SYSPY = "/usr/bin/python3"
WHEELS = os.path.join(ROOT, "build", "wheels")


# ---------------------------------------------------------------- the pure part

def test_pins_match_requirements_txt():
    with open(os.path.join(ROOT, "requirements.txt")) as f:
        lines = {line.split("#")[0].strip() for line in f}
    for r in deps.REQUIREMENTS:
        assert r.pin in lines, f"{r.pin} is not pinned in requirements.txt"


def test_find_python_per_platform():
    have = {r"C:\OSGeo4W\apps\Python312\python.exe", "/Applications/QGIS.app/Contents/MacOS/bin/python3",
            "/usr/bin/python3"}
    assert deps.find_python(r"C:\OSGeo4W\bin\qgis-bin.exe", r"C:\OSGeo4W\apps\Python312", "win32", (3, 12),
                            have.__contains__) == r"C:\OSGeo4W\apps\Python312\python.exe"
    assert deps.find_python("/Applications/QGIS.app/Contents/MacOS/QGIS",
                            "/Applications/QGIS.app/Contents/Frameworks", "darwin", (3, 11),
                            have.__contains__) == "/Applications/QGIS.app/Contents/MacOS/bin/python3"
    assert deps.find_python("/usr/bin/qgis", "/usr", "linux", (3, 11), have.__contains__) == "/usr/bin/python3"
    assert deps.find_python("/opt/conda/bin/python3.11", "/opt/conda", "linux", (3, 11),
                            lambda p: False) == "/opt/conda/bin/python3.11"
    # qgis_process embeds Python: sys.executable is the first python3 on PATH, here not QGIS's
    assert deps.find_python("/root/.pyenv/shims/python3", "/usr", "linux", (3, 11),
                            have.__contains__) == "/usr/bin/python3"


def test_unsupported_platforms():
    assert deps.unsupported_platform("win32", "AMD64", (3, 12)) is None
    assert deps.unsupported_platform("darwin", "arm64", (3, 12), mac_release="14.5") is None
    assert "Intel Mac" in deps.unsupported_platform("darwin", "x86_64", (3, 12), mac_release="14.5")
    assert "macOS 14" in deps.unsupported_platform("darwin", "arm64", (3, 12), mac_release="13.6")
    assert deps.unsupported_platform("linux", "x86_64", (3, 11), glibc="2.36") is None
    assert "glibc 2.28" in deps.unsupported_platform("linux", "x86_64", (3, 11), glibc="2.17")
    assert "aarch64" in deps.unsupported_platform("linux", "aarch64", (3, 11), glibc="2.36")
    assert "Python 3.9" in deps.unsupported_platform("linux", "x86_64", (3, 9), glibc="2.36")


def test_pip_command_never_installs_numpy_and_names_the_plugin_folder(tmp_path):
    target = deps.target_dir(str(tmp_path / "profiles" / "default"))
    assert target.startswith(str(tmp_path)) and target.endswith(os.path.join("archaeoortho", deps.python_tag()))
    args = deps.pip_arguments(target)
    assert args[:3] == ["-m", "pip", "install"] and "--no-deps" in args and "--only-binary=:all:" in args
    assert args[args.index("--target") + 1] == target
    assert args[-2:] == ["pycolmap==4.2.1", "opencv-python-headless==4.10.0.84"]
    assert not any("numpy" in a for a in args)
    old = deps.configured_target()
    try:
        deps.configure(str(tmp_path / "profiles" / "default"))
        from core.common.errors import MissingDependencyError

        message = str(MissingDependencyError("pycolmap", "the alignment"))
        assert f"-m pip install --upgrade --no-deps --only-binary=:all: --target {target} pycolmap==4.2.1 " \
               "opencv-python-headless==4.10.0.84" in message
        assert "pip install dask" in str(MissingDependencyError("dask"))
    finally:
        deps._TARGET = old


def _fake_dist(folder, name, version, requires=(), module=None):
    info = os.path.join(folder, f"{name}-{version}.dist-info")
    os.makedirs(info)
    meta = ["Metadata-Version: 2.1", f"Name: {name}", f"Version: {version}"] + [f"Requires-Dist: {r}" for r in
                                                                                 requires]
    with open(os.path.join(info, "METADATA"), "w") as f:
        f.write("\n".join(meta) + "\n")
    if module:
        os.makedirs(os.path.join(folder, module))
        with open(os.path.join(folder, module, "__init__.py"), "w") as f:
            f.write(f"__version__ = {version!r}\n")
        with open(os.path.join(info, "top_level.txt"), "w") as f:
            f.write(module + "\n")


def test_activate_only_after_an_install(tmp_path, monkeypatch):
    monkeypatch.setattr(deps, "_TARGET", None)
    profile = str(tmp_path / "profile")
    path = ["/usr/lib/python3/dist-packages"]
    assert deps.activate(profile, path) is None and path == ["/usr/lib/python3/dist-packages"]
    target = deps.target_dir(profile)
    assert deps.configured_target() == target  # the messages name it even before an install
    _fake_dist(target, "pycolmap", "4.2.1")
    assert deps.activate(profile, path) == target
    assert deps.activate(profile, path) == target and path == [target, "/usr/lib/python3/dist-packages"]


def test_found_states_and_unmet_requirements(tmp_path):
    pyc = deps.REQUIREMENTS[0]
    assert deps.Found(pyc).state == "missing"
    assert deps.Found(pyc, "4.2.1", "/x").state == "ok"
    assert deps.Found(pyc, "4.3.0", "/x").state == "untested"  # a newer working install is left alone
    assert deps.Found(pyc, "3.11.1", "/x").state == "unsupported"
    assert "3.11.1" in deps.Found(pyc, "3.11.1", "/x").describe()
    assert deps.Found(deps.REQUIREMENTS[1], "4.10.0", "/x").state == "ok"  # cv2.__version__
    target = str(tmp_path / "t")
    _fake_dist(target, "pycolmap", "4.2.1", ["numpy>=1.23", 'pillow; extra == "panorama"'])
    _fake_dist(target, "opencv-python-headless", "4.10.0.84", ['numpy>=1.26.0; python_version >= "3.0"'])
    have = {"numpy": "1.24.2"}.get
    unmet = deps.unmet_requirements(target, installed=have)
    assert len(unmet) == 1 and "numpy>=1.26.0" in unmet[0] and "1.24.2" in unmet[0]
    assert deps.unmet_requirements(target, installed={"numpy": "2.2.4"}.get) == []
    # probe() reads the version from the .dist-info next to the package, without importing it
    site = str(tmp_path / "site")
    _fake_dist(site, "aoprobe", "1.5", module="aoprobe")
    sys.path.insert(0, site)
    try:
        found = deps.probe(deps.Requirement("aoprobe", "aoprobe", "1.5", "probe", "1", "2"))
        assert (found.state, found.version, found.location) == ("ok", "1.5", site) and "aoprobe" not in sys.modules
    finally:
        sys.path.remove(site)


# ---------------------------------------------------------------- end to end: pip, the folder, an alignment

@pytest.fixture(scope="session")
def wheels():
    """The pinned wheels for this machine, downloaded once into build/wheels."""
    os.makedirs(WHEELS, exist_ok=True)
    want = {"pycolmap-4.2.1-", "opencv_python_headless-4.10.0.84-"}

    tag = f"-cp{sys.version_info[0]}{sys.version_info[1]}-"  # build/wheels may hold another Python's wheels too

    def have():
        return all(any(n.startswith(w) and (tag in n or "-abi3-" in n) for n in os.listdir(WHEELS)) for w in want)

    if not have():
        out = subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:", "-d",
                              WHEELS] + [r.pin for r in deps.REQUIREMENTS], capture_output=True, text=True,
                             timeout=900)
        if not have():
            pytest.skip(f"the pinned wheels cannot be downloaded into {WHEELS}: {out.stderr[-800:]}")
    return WHEELS


@pytest.fixture(scope="module")
def bare_python(tmp_path_factory):
    """A Python like QGIS's on Debian: the system packages (NumPy, GDAL, QGIS), no pycolmap, no cv2."""
    if not os.path.exists(SYSPY):
        pytest.skip(f"{SYSPY} not found")
    venv = str(tmp_path_factory.mktemp("bare venv"))
    subprocess.run([SYSPY, "-m", "venv", "--system-site-packages", "--without-pip", venv], check=True, timeout=300)
    py = os.path.join(venv, "bin", "python")
    probe = subprocess.run([py, "-c", "import importlib.util as u; print(u.find_spec('pycolmap'), "
                            "u.find_spec('cv2'), u.find_spec('pip') is not None)"],
                           capture_output=True, text=True, timeout=60, env=_clean_env())
    if probe.stdout.split()[:2] != ["None", "None"]:
        pytest.skip(f"{SYSPY} already has pycolmap or cv2: {probe.stdout}")
    if probe.stdout.split()[2] != "True":
        pytest.skip(f"{SYSPY} has no pip (Debian package python3-pip)")
    return py


def _clean_env(**extra):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(extra)
    return env


@pytest.fixture(scope="module")
def installed_profile(bare_python, wheels, tmp_path_factory):
    """A fresh QGIS profile into whose plugin folder the installer's pip command put the pinned wheels."""
    config = str(tmp_path_factory.mktemp("qgis config"))
    profile = os.path.join(config, "profiles", "default")
    target = deps.target_dir(profile)
    args = deps.pip_arguments(target, find_links=wheels, no_index=True)
    out = subprocess.run([bare_python, *args], capture_output=True, text=True, timeout=900,
                         env=deps.pip_environment(_clean_env()))
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    return config, profile, target, out.stdout


@pytest.mark.slow
def test_install_into_the_plugin_folder_leaves_numpy_alone(installed_profile, bare_python):
    config, profile, target, log = installed_profile
    names = os.listdir(target)
    assert {"pycolmap", "cv2"} <= set(names), names
    assert not [n for n in names if n.lower().startswith("numpy")], names  # --no-deps: QGIS's NumPy stays
    assert sorted(deps.installed_here(target)) == ["opencv-python-headless", "pycolmap"]
    check = subprocess.run([bare_python, *deps.verify_arguments(target)], capture_output=True, text=True,
                           timeout=300, env=_clean_env())
    assert check.returncode == 0, check.stdout + check.stderr
    assert "pycolmap 4.2.1" in check.stdout and "/usr/lib/python3/dist-packages/numpy" in check.stdout
    unmet = subprocess.run([bare_python, "-c", "import sys; sys.path.insert(0, sys.argv[1]); "
                            "from core.common import dependencies as d; print(d.unmet_requirements(sys.argv[2]))",
                            ROOT, target], capture_output=True, text=True, timeout=120, env=_clean_env())
    assert unmet.stdout.strip() == "[]", unmet.stdout + unmet.stderr


ALIGN_SCRIPT = """
import json, sys
sys.path.insert(0, sys.argv[1])
from core.common import dependencies
added = dependencies.activate(sys.argv[2])
import pycolmap
from core.align.options import AlignOptions
from core.align.stage import align
r = align(sys.argv[3], sys.argv[4], AlignOptions(max_image_size=800, max_features=2048))
print(json.dumps({"added": added, "pycolmap": pycolmap.__file__, "registered": r.registered,
                  "given": r.images_given, "error": r.mean_reprojection_error}))
"""


@pytest.mark.slow
def test_alignment_with_the_installed_packages(installed_profile, bare_python, tmp_path):
    import json

    config, profile, target, _ = installed_profile
    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:4], str(tmp_path / "images"))
    out = subprocess.run([bare_python, "-c", ALIGN_SCRIPT, ROOT, profile, images, str(tmp_path / "ws")],
                         capture_output=True, text=True, timeout=1200, env=_clean_env(OMP_NUM_THREADS="2"))
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["added"] == target and result["pycolmap"].startswith(target)
    assert result["given"] == 4 and result["registered"] == 4, result
    assert 0 < result["error"] < 2.0, result


def _qgis_process_env(config):
    """qgis_process as a user without pycolmap runs it: the system Python only, a fresh profile."""
    exe = os.environ.get("QGIS_PROCESS") or "/usr/bin/qgis_process.bin"
    if not os.path.exists(exe):
        pytest.skip("qgis_process not installed")
    if not os.path.islink(os.path.join(PLUGINS, "archaeoortho")):
        pytest.skip("plugin link missing: run 'make setup'")
    env = _clean_env(QGIS_CUSTOM_CONFIG_PATH=config, QGIS_PLUGINPATH=PLUGINS, QT_QPA_PLATFORM="offscreen")
    out = subprocess.run([exe, "plugins", "enable", "archaeoortho"], env=env, capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0 or "already enabled" in out.stdout + out.stderr, out.stdout + out.stderr
    return exe, env


def _run_align(exe, env, images, ws):
    return subprocess.run([exe, "run", "archaeoortho:alignimages", "--", f"IMAGES={images}", f"WORKSPACE={ws}"],
                          env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_qgis_process_without_pycolmap_lists_and_names_the_command(tmp_path):
    config = str(tmp_path / "config")
    exe, env = _qgis_process_env(config)
    listing = subprocess.run([exe, "list"], env=env, capture_output=True, text=True, timeout=300)
    assert "archaeoortho:alignimages" in listing.stdout and "archaeoortho:runpipeline" in listing.stdout
    empty = tmp_path / "no images"
    empty.mkdir()
    t0 = time.time()
    out = _run_align(exe, env, str(empty), str(tmp_path / "ws"))
    text = out.stdout + out.stderr
    assert out.returncode != 0
    target = deps.target_dir(os.path.join(config, "profiles", "default"))
    assert "pycolmap" in text and f"--target {target} pycolmap==4.2.1 opencv-python-headless==4.10.0.84" in text, \
        text[-3000:]
    python = re.search(r"(\S+) -m pip install", text).group(1)
    assert os.path.realpath(python) == os.path.realpath(SYSPY), text[-3000:]  # QGIS's Python, not one on PATH
    assert not os.path.exists(tmp_path / "ws"), "the run did work before failing"
    assert time.time() - t0 < 600


@pytest.mark.slow
def test_qgis_process_finds_the_installed_packages(installed_profile, tmp_path):
    config, profile, target, _ = installed_profile
    exe, env = _qgis_process_env(config)
    empty = tmp_path / "no images"
    empty.mkdir()
    out = _run_align(exe, env, str(empty), str(tmp_path / "ws"))
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "is missing" not in text, text[-3000:]
    assert "no readable images" in text, text[-3000:]  # past the dependency check: the empty folder is the problem


# ---------------------------------------------------------------- the dialog (pytest-qgis)

def _wheel(folder, name="aofake", version="1.0"):
    """A tiny pure-Python wheel (so the dialog's pip run needs no network)."""
    os.makedirs(folder, exist_ok=True)
    files = {f"{name}/__init__.py": f"__version__ = {version!r}\n",
             f"{name}-{version}.dist-info/METADATA": f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n",
             f"{name}-{version}.dist-info/WHEEL": "Wheel-Version: 1.0\nGenerator: test\nRoot-Is-Purelib: true\n"
                                                  "Tag: py3-none-any\n",
             f"{name}-{version}.dist-info/top_level.txt": f"{name}\n"}
    record = []
    for path, text in files.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(text.encode()).digest()).rstrip(b"=").decode()
        record.append(f"{path},sha256={digest},{len(text.encode())}")
    record.append(f"{name}-{version}.dist-info/RECORD,,")
    files[f"{name}-{version}.dist-info/RECORD"] = "\n".join(record) + "\n"
    path = os.path.join(folder, f"{name}-{version}-py3-none-any.whl")
    with zipfile.ZipFile(path, "w") as z:
        for p, text in files.items():
            z.writestr(p, text)
    return path


FAKE = deps.Requirement("aofake", "aofake", "1.0", "aofake (a test package)", "1.0", "2")


def _wait(dialog, states, seconds=300):
    from qgis.PyQt.QtCore import QCoreApplication

    deadline = time.time() + seconds
    while dialog.state not in states and time.time() < deadline:
        QCoreApplication.processEvents()
        time.sleep(0.02)
    assert dialog.state in states, (dialog.state, dialog.log.toPlainText()[-2000:])


def test_dialog_fails_shows_the_log_then_retry_installs(qgis_app, tmp_path):
    from archaeoortho.ui.dependencies import DependenciesDialog

    links = str(tmp_path / "wheels")
    os.makedirs(links)
    dialog = DependenciesDialog(str(tmp_path / "profile"), requirements=(FAKE,), find_links=links, no_index=True,
                                python=sys.executable)
    assert "aofake" in dialog.packages_label.text() and "not installed" in dialog.packages_label.text()
    assert dialog.target in dialog.command_edit.text() and "--no-deps" in dialog.command_edit.text()
    assert not dialog.log.isVisibleTo(dialog) and not dialog.cancel_button.isEnabled()
    dialog.install_button.click()
    assert dialog.state == "running" and dialog.cancel_button.isEnabled() and dialog.progress.maximum() == 0
    _wait(dialog, ("failed",))
    assert dialog.log.isVisibleTo(dialog) and "aofake==1.0" in dialog.log.toPlainText()
    assert "No matching distribution" in dialog.log.toPlainText() or "ERROR" in dialog.log.toPlainText()
    assert dialog.install_button.text() == "Retry" and dialog.install_button.isEnabled()
    assert "failed" in dialog.status_label.text()
    _wheel(links)  # the cause fixed: Retry
    done = []
    dialog.installed.connect(lambda: done.append(True))
    dialog.install_button.click()
    _wait(dialog, ("done",))
    assert done == [True]
    assert os.path.exists(os.path.join(dialog.target, "aofake", "__init__.py"))
    log = dialog.log.toPlainText()
    assert "Successfully installed aofake-1.0" in log and "aofake 1.0 " + dialog.target in log  # import check
    assert "<import check>" in log
    try:
        assert sys.path[0] == dialog.target  # on sys.path at once: usable without a restart
        assert "[ok]" in dialog.packages_label.text() and "aofake (a test package): 1.0" in dialog.packages_label.text()
        assert dialog.install_button.text() == "Reinstall" and dialog.progress.value() == 1
    finally:
        sys.path.remove(dialog.target)
    dialog.deleteLater()


def test_dialog_cancel_kills_pip(qgis_app, tmp_path):
    from archaeoortho.ui.dependencies import DependenciesDialog
    from qgis.PyQt.QtCore import QProcess

    dialog = DependenciesDialog(str(tmp_path / "profile"), requirements=(FAKE,), python=sys.executable)
    dialog.command = (sys.executable, ["-c", "import time; print('pip pretends', flush=True); time.sleep(300)"])
    dialog.install_button.click()
    deadline = time.time() + 60
    while "pip pretends" not in dialog.log.toPlainText() and time.time() < deadline:
        qgis_app.processEvents()
        time.sleep(0.02)
    assert "pip pretends" in dialog.log.toPlainText()
    pid = dialog.process.processId()
    dialog.cancel_button.click()
    assert dialog.state == "cancelled"
    assert dialog.process.state() == QProcess.ProcessState.NotRunning
    assert not os.path.exists(f"/proc/{pid}") or "zombie" in open(f"/proc/{pid}/status").read().lower()
    assert dialog.install_button.text() == "Retry" and not dialog.cancel_button.isEnabled()
    dialog.deleteLater()


def test_message_bar_offers_the_dialog(qgis_iface, tmp_path):
    from archaeoortho.ui.dependencies import push_missing_message

    bad = [deps.Found(deps.REQUIREMENTS[0]), deps.Found(deps.REQUIREMENTS[1], "3.4.0", "/old")]
    item = push_missing_message(qgis_iface, bad, str(tmp_path / "profile"))
    text = item.text()
    assert text == "needs pycolmap (not installed); OpenCV 3.4.0 (wrong version)", text
    assert qgis_iface.messageBar().currentItem() is item
    from qgis.PyQt.QtWidgets import QPushButton

    button = item.findChild(QPushButton, "ArchaeoOrthoInstallDependencies")
    assert "pycolmap==4.2.1" in button.toolTip() and "opencv-python-headless==4.10.0.84" in button.toolTip()
    button.click()
    dialog = item._archaeoortho_dialog
    assert dialog.isVisible() and dialog.target == deps.target_dir(str(tmp_path / "profile"))
    dialog.close()
    qgis_iface.messageBar().popWidget(item)


def test_faces_never_import_pycolmap_at_module_import():
    """The plugin never imports pycolmap/cv2 at module import: the provider loads without them (above, in
    qgis_process) and no module of processing_provider/ or ui/ imports them at top level."""
    for path in glob.glob(os.path.join(ROOT, "processing_provider", "*.py")) + \
            glob.glob(os.path.join(ROOT, "ui", "*.py")) + [os.path.join(ROOT, "plugin.py")]:
        with open(path, encoding="utf-8") as f:
            for line in f:
                assert not line.startswith(("import pycolmap", "import cv2", "from pycolmap", "from cv2")), path
