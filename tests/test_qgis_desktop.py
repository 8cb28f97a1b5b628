"""QGIS desktop under Xvfb: the plugin loads, the provider is registered once, Align images runs from
the toolbox dialog with a progress bar and its Cancel button stops the stage."""
import json
import os
import shutil
import subprocess
import sysconfig

import pytest

from tests.conftest import PLUGINS, ROOT, SAMPLE

pytestmark = pytest.mark.slow


@pytest.mark.skipif(not (shutil.which("qgis") and shutil.which("xvfb-run")), reason="needs qgis and xvfb-run")
def test_toolbox_run_and_cancel_in_qgis_desktop(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    ws = tmp_path / "ws"
    env = dict(os.environ)
    env.pop("QT_QPA_PLATFORM", None)
    env.update(
        AO_OUT=str(out), AO_IMAGES=os.path.join(SAMPLE, "images"), AO_WORKSPACE=str(ws),
        QGIS_PLUGINPATH=PLUGINS, QGIS_CUSTOM_CONFIG_PATH=os.path.join(ROOT, "build", "qgis-profile"),
        PYTHONPATH=os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")]),
    )
    script = os.path.join(ROOT, "tests", "desktop_cancel_script.py")
    subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1600x1000x24", "qgis", "--nologo", "--noversioncheck",
                    "--code", script], env=env, capture_output=True, timeout=300)
    log = dict(json.load(open(out / "log.json")))
    assert "archaeoortho" in log["plugins"], log
    assert log["providers"] == 1
    assert log["progress_before_cancel"] >= 40
    assert log["clicked"] == "Cancel"
    assert log["status"] == "cancelled"
    assert not (ws / "sfm" / "model").exists()
    for name in ("1-dialog", "2-running", "3-cancelled"):
        assert (out / f"{name}.png").stat().st_size > 10000
    keep = os.environ.get("ARCHAEOORTHO_SCREENSHOTS")
    if keep:
        shutil.copytree(out, keep, dirs_exist_ok=True)
