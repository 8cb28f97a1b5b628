"""Issue 17, the runs themselves: a manifest of the wrong shape (10), a full disk (5), killed runs (6), file modes
and doubled log lines (15), SIGINT / SIGTERM under qgis_process (16).

Killed runs are real: a stage or a process pool in a child process, killed with SIGKILL; processes are looked
up in /proc (Linux)."""
import errno
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from core.common import files
from core.common.files import atomic_output, atomic_write_text, clean_debris, owned_tempdir, save_npz
from core.project.layout import Layout, write_json
from core.project.stages import DSM, FAILED, INTERRUPTED, RUNNING, STATUSES, run_stage
from core.project.workspace import MANIFEST, Workspace, WorkspaceError
from tests.conftest import ROOT

linux_only = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")


# ---------------------------------------------------------------------------------------------------------------
# helpers: processes in /proc
# ---------------------------------------------------------------------------------------------------------------

def _stat(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return fields[0], int(fields[1])  # state, ppid
    except (OSError, IndexError, ValueError):
        return None


def alive(pid):
    st = _stat(pid)
    return st is not None and st[0] not in ("Z", "X")


def workers_of(pid):
    """The live pool workers (multiprocessing spawn children) of process ``pid``."""
    out = []
    for name in os.listdir("/proc"):
        if name.isdigit():
            st = _stat(int(name))
            if st and st[1] == pid and st[0] not in ("Z", "X"):
                try:
                    with open(f"/proc/{name}/cmdline", "rb") as f:
                        if b"spawn_main" in f.read():
                            out.append(int(name))
                except OSError:
                    pass
    return out


def wait_for(predicate, timeout=120.0, what="condition"):
    """Poll until ``predicate()`` is true (the deadline only stops a hang; nothing here asserts a duration)."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def kill_all(pids):
    for p in pids:
        if alive(p):
            os.kill(p, signal.SIGKILL)


def stage_status(ws, name):
    try:
        with open(os.path.join(ws, MANIFEST)) as f:
            return json.load(f)["stages"].get(name, {}).get("status")
    except (OSError, ValueError):
        return None


def child_env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([ROOT, env.get("PYTHONPATH", "")])
    return env


# ---------------------------------------------------------------------------------------------------------------
# item 10: a manifest that is valid JSON but of the wrong shape
# ---------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("data, key", [
    ({"format_version": 1, "stages": {"align": "done"}}, '"stages" -> "align"'),
    ({"format_version": 1, "stages": ["align"]}, '"stages"'),
    ({"format_version": 1, "stages": {"align": {"status": "finished"}}}, '"status"'),
    ({"format_version": 1, "stages": {"dsm": {"status": "done", "outputs": ["dsm.tif"]}}}, '"outputs"'),
    ({"format_version": 1, "images": ["IMG_1.JPG"]}, '"images" [0]'),
    ({"format_version": 1, "images": [{"width": 10}]}, '"images" [0]'),
    ({"format_version": 1, "images": {"IMG_1.JPG": {}}}, '"images"'),
    ({"format_version": 1, "crs": 32633}, '"crs"'),
])
def test_manifest_of_the_wrong_shape_is_refused_and_left_alone(tmp_path, data, key):
    path = tmp_path / MANIFEST
    path.write_text(json.dumps(data))
    before = path.read_bytes()
    for opener in (Workspace.open, Workspace.create_or_open):
        with pytest.raises(WorkspaceError) as e:
            opener(str(tmp_path))
        assert str(path) in str(e.value) and key in str(e.value) and "damaged" in str(e.value)
    assert path.read_bytes() == before


def test_wrong_shape_is_refused_by_the_stages_too(tmp_path):
    """Build orthophoto rewrote such a manifest silently, Align died with a traceback."""
    from core.align.stage import align
    from core.ortho.stage import build_orthophoto_workspace

    path = tmp_path / MANIFEST
    path.write_text(json.dumps({"format_version": 1, "stages": {"align": "done"}, "images": []}))
    before = path.read_bytes()
    with pytest.raises(WorkspaceError, match='"align"'):
        build_orthophoto_workspace(str(tmp_path))
    images = tmp_path / "images"
    images.mkdir()  # a photo in it: an empty folder is refused before the workspace is opened
    shutil.copy(os.path.join(ROOT, "sample", "toledo", "images", "1JI_0064.JPG"), images)
    with pytest.raises(WorkspaceError, match='"align"'):
        align(str(images), str(tmp_path))
    assert path.read_bytes() == before


def test_every_status_the_code_writes_is_known(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path))
    for status in STATUSES:
        ws.data["stages"][f"s-{status}"] = {"status": status}
    ws.save()
    reopened = Workspace.open(str(tmp_path))  # all accepted, each read back as written
    assert {n: s["status"] for n, s in reopened.data["stages"].items() if n.startswith("s-")} == \
        {f"s-{status}": status for status in STATUSES}
    ws.data["stages"]["s-bogus"] = {"status": "finished"}  # and a status the code never writes is refused
    ws.save()
    with pytest.raises(WorkspaceError, match="finished"):
        Workspace.open(str(tmp_path))


# ---------------------------------------------------------------------------------------------------------------
# item 5: disk full
# ---------------------------------------------------------------------------------------------------------------

@pytest.fixture
def small_disk(tmp_path):
    """A 1 MiB tmpfs (tests run as root); skipped where mounting is not allowed."""
    mnt = tmp_path / "small"
    mnt.mkdir()
    out = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(mnt)], capture_output=True)
    if out.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {out.stderr.decode(errors='replace').strip()}")
    try:
        yield str(mnt)
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def _fill(folder):
    """Fill the file system of ``folder`` (a filler file); returns its path."""
    filler = os.path.join(folder, "filler.bin")
    fd = os.open(filler, os.O_WRONLY | os.O_CREAT, 0o644)
    try:
        while True:
            os.write(fd, b"\0" * 4096)
    except OSError as e:
        assert e.errno == errno.ENOSPC
    finally:
        os.close(fd)
    return filler


def test_disk_full_reports_the_stage_error_and_records_later(small_disk, capfd):
    ws = Workspace.create_or_open(os.path.join(small_disk, "ws"))
    fused = os.path.join(ws.root, "dense", "fused")
    os.makedirs(fused)
    filler = None
    with pytest.raises(OSError) as e:
        with run_stage(ws, DSM, {"resolution": 0.1}):
            filler = _fill(small_disk)  # another product filled the disk
            save_npz(os.path.join(fused, "1.npz"), xyz=np.zeros((100000, 3), np.float32))
    # the stage's own error, not "cannot write workspace.json", and the recording failure as a note
    assert e.value.errno == errno.ENOSPC and e.value.filename and "1.npz" in e.value.filename
    notes = " ".join(getattr(e.value, "__notes__", []))
    assert "could not be recorded failed" in notes and MANIFEST in notes
    assert "ZipFile.__del__" not in capfd.readouterr().err
    # no partial file anywhere
    leftovers = [os.path.join(dp, f) for dp, _, fs in os.walk(ws.root) for f in fs]
    assert leftovers == [ws.manifest_path, ws.manifest_path + ".lock"], leftovers  # the lock is no partial file
    assert stage_status(ws.root, DSM) == RUNNING  # what the disk holds: the recording could not be written
    # once there is room: the next open (same process) reads interrupted, and the next run records normally
    os.unlink(filler)
    again = Workspace.open(ws.root)
    rec = again.stage(DSM)
    assert rec["status"] == INTERRUPTED and "ended without recording" in rec["error"]
    with run_stage(again, DSM, {"resolution": 0.1}) as run:
        save_npz(os.path.join(fused, "1.npz"), xyz=np.zeros((10, 3), np.float32))
        run.finish(outputs={"points": "dense/fused/1.npz"})
    assert stage_status(ws.root, DSM) == "done"


def test_recording_failure_never_replaces_the_error(tmp_path, monkeypatch):
    """Simulated ENOSPC on the manifest only (any platform): the body's error is raised, unchanged."""
    ws = Workspace.create_or_open(str(tmp_path))
    original = OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "dense" / "fused" / "1.npz"))
    real_replace = os.replace

    def full(src, dst):
        if str(dst).endswith(MANIFEST):
            raise OSError(errno.ENOSPC, "No space left on device", dst)
        return real_replace(src, dst)

    with pytest.raises(OSError) as e:
        with run_stage(ws, DSM, {}):
            monkeypatch.setattr(os, "replace", full)
            raise original
    assert e.value is original
    assert "could not be recorded failed" in " ".join(e.value.__notes__)
    monkeypatch.setattr(os, "replace", real_replace)
    assert not [n for n in os.listdir(tmp_path) if n not in (MANIFEST, MANIFEST + ".lock")]  # its temp file went too
    assert Workspace.open(str(tmp_path)).stage(DSM)["status"] == INTERRUPTED
    # a failure that can be recorded is recorded as before
    with pytest.raises(ValueError):
        with run_stage(ws, DSM, {}):
            raise ValueError("bad")
    assert Workspace.open(str(tmp_path)).stage(DSM)["status"] == FAILED


def test_atomic_outputs_leave_no_partial_file_on_enospc(tmp_path, monkeypatch):
    target = str(tmp_path / "1.npz")

    def no_space(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(np.lib.format, "write_array", no_space)
    with pytest.raises(OSError):
        save_npz(target, xyz=np.zeros(3))
    monkeypatch.undo()
    with pytest.raises(OSError):
        with atomic_output(target) as tmp:
            with open(tmp, "wb") as f:
                f.write(b"x")
            no_space()
    assert os.listdir(tmp_path) == []


# ---------------------------------------------------------------------------------------------------------------
# item 15: file modes honour the umask
# ---------------------------------------------------------------------------------------------------------------

def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.mark.skipif(os.name == "nt", reason="POSIX modes")
@pytest.mark.parametrize("umask", [0o022, 0o002])
def test_products_honour_the_umask(tmp_path, monkeypatch, umask):
    old = os.umask(umask)
    try:
        monkeypatch.setattr(files, "UMASK", umask)
        want = 0o666 & ~umask
        ws = Workspace.create_or_open(str(tmp_path / "ws"))
        assert _mode(ws.manifest_path) == want  # was 0600 (mkstemp)
        lay = Layout(ws)
        os.makedirs(os.path.dirname(lay.alignment_json), exist_ok=True)
        write_json(lay.alignment_json, {"registered": 3})
        assert _mode(lay.alignment_json) == want
        cache = os.path.join(ws.root, "dense", "pairs-x", "cache.json")
        os.makedirs(os.path.dirname(cache))
        atomic_write_text(cache, "{}")
        assert _mode(cache) == want
        import tempfile

        out = os.path.join(ws.root, "product.bin")
        with atomic_output(out) as tmp:  # a writer that makes its file with mkstemp
            fd, made = tempfile.mkstemp(dir=ws.root)
            os.close(fd)
            os.replace(made, tmp)
        assert _mode(out) == want
    finally:
        os.umask(old)


def test_umask_is_read_without_changing_it():
    now = os.umask(0o027)
    os.umask(now)
    assert files._read_umask() == now and os.umask(now) == now


# ---------------------------------------------------------------------------------------------------------------
# item 6: killed runs
# ---------------------------------------------------------------------------------------------------------------

POOL_SCRIPT = textwrap.dedent("""
    import sys, time
    from core.common import parallel
    ex = parallel.make_executor(workers=2, kind="process")
    futs = [ex.submit(time.sleep, 600) for _ in range(2)]
    while len(ex._processes) < 2:
        time.sleep(0.05)
    time.sleep(1.0)
    print(" ".join(str(p) for p in ex._processes), flush=True)
    time.sleep(600)
""")


@linux_only
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_pool_workers_die_with_their_parent(tmp_path, sig):
    proc = subprocess.Popen([sys.executable, "-c", POOL_SCRIPT], cwd=ROOT, env=child_env(), stdout=subprocess.PIPE,
                            text=True)
    workers = []
    try:
        workers = [int(p) for p in proc.stdout.readline().split()]
        assert len(workers) == 2 and all(alive(p) for p in workers)
        os.kill(proc.pid, sig)
        proc.wait(timeout=60)
        wait_for(lambda: not any(alive(p) for p in workers), 60, "the workers to die with their parent")
    finally:
        kill_all(workers + [proc.pid])


def test_debris_of_a_gone_owner_goes_and_a_live_ones_stays(tmp_path):
    folder = str(tmp_path)
    child = subprocess.Popen([sys.executable, "-c", "import sys, time; from core.common.files import owned_tempdir;"
                              f"print(owned_tempdir('.ortho-work-', {folder!r}), flush=True); time.sleep(600)"],
                             cwd=ROOT, env=child_env(), stdout=subprocess.PIPE, text=True)
    try:
        theirs = child.stdout.readline().strip()
        mine = owned_tempdir(".ortho-work-", folder)
        other = owned_tempdir(".cancel-", folder)
        assert clean_debris(folder, ".ortho-work-") == []  # both owners run
        child.kill()
        child.wait()
        assert clean_debris(folder, ".ortho-work-") == [theirs]
        assert os.path.isdir(mine) and os.path.isdir(other)
        # another host sharing the folder: cannot tell, left alone; an old unowned folder: removed
        foreign = os.path.join(folder, ".ortho-work-foreign")
        os.makedirs(foreign)
        with open(os.path.join(foreign, files.OWNER_FILE), "w") as f:
            json.dump({"host": "elsewhere", "pid": 1}, f)
        unowned = os.path.join(folder, ".ortho-work-old")
        os.makedirs(unowned)
        os.utime(unowned, (time.time() - 7200, time.time() - 7200))
        assert clean_debris(folder, ".ortho-work-") == [unowned]
        assert os.path.isdir(foreign)
    finally:
        child.kill()
        child.wait()


def test_a_stage_running_in_a_live_process_is_not_started_twice(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path))
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        ws.data["stages"][DSM] = {"status": RUNNING, "started": "now",
                                  "owner": {**files.process_owner(), "pid": child.pid,
                                            "pid_started": files.process_start(child.pid)}}
        ws.save()
        again = Workspace.open(str(tmp_path))
        assert again.stage(DSM)["status"] == RUNNING
        with pytest.raises(WorkspaceError, match=f"running in another process \\(pid {child.pid}"):
            with run_stage(again, DSM, {}):
                pass
    finally:
        child.kill()
        child.wait()
    rec = Workspace.open(str(tmp_path)).stage(DSM)
    assert rec["status"] == INTERRUPTED and str(child.pid) in rec["error"]


# the synthetic DSM block of tests/test_dense.py (small camera: fast), built once for the killed-run tests
@pytest.fixture(scope="module")
def dsm_block(tmp_path_factory):
    from tests import synthetic as syn
    from tests.test_dense import CAMERA, make_workspace

    root = tmp_path_factory.mktemp("reliability block")
    block = syn.vertical_block(seed=8, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=6, forward_overlap=0.8,
                               side_overlap=0.5, gcp_grid=(2, 2), roofs=0)
    block.render(str(root / "images"))
    ws = make_workspace(str(root / "ws"), block, images_dir=str(root / "images"))
    return block, ws


def _fresh_ws(dsm_block, tmp_path):
    dst = str(tmp_path / "ws")
    shutil.copytree(dsm_block[1], dst, ignore=shutil.ignore_patterns("dense", "dsm.tif"))
    return dst


DSM_SCRIPT = textwrap.dedent("""
    import sys
    from core.dense import stage
    from core.dense.options import DenseOptions
    stage.build_dsm_workspace(sys.argv[1], DenseOptions(quality="full", workers=2, executor="process"))
""")


def _cancel_dirs(ws):
    dense = os.path.join(ws, "dense")
    return [n for n in os.listdir(dense) if n.startswith(".cancel-")] if os.path.isdir(dense) else []


@linux_only
@pytest.mark.slow
def test_killed_dsm_run_leaves_no_worker_reads_interrupted_and_is_cleaned(dsm_block, tmp_path):
    from core.dense import stage as dense
    from core.dense.options import DenseOptions
    from core.ortho.options import OrthoOptions
    from core.ortho.stage import build_orthophoto_workspace

    ws = _fresh_ws(dsm_block, tmp_path)
    proc = subprocess.Popen([sys.executable, "-c", DSM_SCRIPT, ws], cwd=ROOT, env=child_env())
    workers = []
    try:
        wait_for(lambda: stage_status(ws, DSM) == RUNNING and _cancel_dirs(ws), 300, "the DSM stage to run units")
        workers = wait_for(lambda: workers_of(proc.pid) if len(workers_of(proc.pid)) >= 2 else None, 120,
                           "workers")
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
        wait_for(lambda: not any(alive(p) for p in workers), 60, "the workers to die with their parent")
    finally:
        kill_all(workers + [proc.pid])
    debris = _cancel_dirs(ws)
    assert debris and stage_status(ws, DSM) == RUNNING  # what the killed run left
    rec = Workspace.open(ws).stage(DSM)
    assert rec["status"] == INTERRUPTED and f"pid {proc.pid}" in rec["error"]

    r = dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=1))
    assert os.path.isfile(r.dsm_path) and Workspace.open(ws).stage(DSM)["status"] == "done"
    assert _cancel_dirs(ws) == []
    assert any(d in line and "killed run" in line for d in debris for line in r.log_lines)

    # the orthophoto stage removes the work folders of its killed runs (and only those)
    dead = owned_tempdir(".ortho-work-", ws)
    with open(os.path.join(dead, files.OWNER_FILE), "w") as f:
        json.dump({**files.process_owner(), "pid": proc.pid, "pid_started": "gone"}, f)
    with open(os.path.join(dead, "dsm-gaps-filled.tif"), "wb") as f:
        f.write(b"\0" * 1000)
    live = owned_tempdir(".ortho-work-", ws)
    build_orthophoto_workspace(ws, OrthoOptions(resolution=0.5))
    assert not os.path.exists(dead) and os.path.isdir(live)


# ---------------------------------------------------------------------------------------------------------------
# item 16: SIGINT / SIGTERM under qgis_process
# ---------------------------------------------------------------------------------------------------------------

@linux_only
@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_qgis_process_cancels_on_a_signal(dsm_block, tmp_path, sig):
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    ws = _fresh_ws(dsm_block, tmp_path)
    proc = subprocess.Popen([exe, "run", "archaeoortho:builddsm", "--", f"WORKSPACE={ws}", "QUALITY=1", "WORKERS=2"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    workers = []
    try:
        wait_for(lambda: stage_status(ws, DSM) == RUNNING and _cancel_dirs(ws), 300, "the DSM stage to run units")
        workers = wait_for(lambda: workers_of(proc.pid) if len(workers_of(proc.pid)) >= 2 else None, 120,
                           "workers")
        os.kill(proc.pid, sig)
        out, _ = proc.communicate(timeout=120)
    finally:
        kill_all(workers + [proc.pid])
    assert proc.returncode != 0, out[-3000:]
    assert "Cancelled" in out, out[-3000:]
    rec = Workspace.open(ws).stage(DSM)
    assert rec["status"] == "cancelled", (rec, out[-3000:])
    wait_for(lambda: not any(alive(p) for p in workers), 60, "the workers to stop")
    assert not os.path.exists(os.path.join(ws, "dsm.tif"))
    assert _cancel_dirs(ws) == []
    assert not [os.path.join(dp, f) for dp, _, fs in os.walk(ws) for f in fs if f.startswith((".partial-", ".tmp-"))]


# ---------------------------------------------------------------------------------------------------------------
# item 15: every log line once (the core pushes it; the provider pushed the result's lines again)
# ---------------------------------------------------------------------------------------------------------------

class _Recorded:
    def __init__(self, **kw):
        self.__dict__.update(kw)


@pytest.fixture
def plugin(qgis_iface, qgis_processing):
    import archaeoortho

    p = archaeoortho.classFactory(qgis_iface)
    p.initProcessing()
    yield p
    p.unload()


def _feedback():
    from qgis.core import QgsProcessingFeedback

    class Feedback(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.lines = []

        def pushInfo(self, info):  # noqa: N802 (QGIS API name)
            self.lines.append(info)

        def pushWarning(self, warning):  # noqa: N802 (QGIS API name)
            self.lines.append(warning)

    return Feedback()


def _core(result):
    """A core entry point that logs as the real ones do (progress.info / warning while it runs) and returns
    the same lines in its result, plus one it did not push."""
    def run(*args, progress=None, **kwargs):
        progress = progress if progress is not None else args[-1]  # entered as (inputs, options, progress)
        progress.info("mosaic: 3 images")
        progress.warning("image A is dark")
        return result
    return run


def test_each_log_line_appears_once(plugin, tmp_path, monkeypatch):
    import archaeoortho.core.georef.stage as georef_stage
    import archaeoortho.core.ortho.single as single
    import archaeoortho.core.ortho.stage as ortho_stage
    from qgis import processing

    lines = ["mosaic: 3 images", "not pushed by the core"]
    warnings = ["image A is dark"]
    ortho_result = _Recorded(workspace=str(tmp_path), orthomosaic="o.tif", per_image_folder=None, seamlines=None,
                             valid_fraction=1.0, resolution=0.1, images=["a"], warnings=warnings, log_lines=lines)
    monkeypatch.setattr(ortho_stage, "build_orthophoto_workspace", _core(ortho_result))
    fb = _feedback()
    processing.run("archaeoortho:buildorthophoto", {"WORKSPACE": str(tmp_path)}, feedback=fb)
    assert [fb.lines.count(x) for x in lines + warnings] == [1, 1, 1], fb.lines

    image = tmp_path / "a.jpg"
    image.write_bytes(b"x")
    gcps = tmp_path / "gcp.txt"
    gcps.write_text("x")
    single_result = _Recorded(output="o.tif", residuals_path=None, rmse_px=0.5, planar_error=None, residuals=[],
                              warnings=warnings, log_lines=lines)
    monkeypatch.setattr(single, "orthorectify_image", _core(single_result))
    fb = _feedback()
    processing.run("archaeoortho:orthorectifyimage", {"IMAGE": str(image), "GCPS": str(gcps), "MODE": 1,  # planar: no DSM
                                                     "OUTPUT": str(tmp_path / "o.tif")}, feedback=fb)
    assert [fb.lines.count(x) for x in lines + warnings] == [1, 1, 1], fb.lines

    figures = {k: 0.01 for k in ("GCP_RMSE_XY", "GCP_RMSE_Z", "CHECK_RMSE_XY", "CHECK_RMSE_Z")}
    georef_result = _Recorded(workspace=str(tmp_path), residuals_path=None, cameras_path=None, warnings=warnings,
                              outliers=[], report_lines=["P1 control ok"], figures=figures, crs="EPSG:32633")
    monkeypatch.setattr(georef_stage, "georeference_workspace", _core(georef_result))
    fb = _feedback()
    processing.run("archaeoortho:georeference", {"WORKSPACE": str(tmp_path), "GCPS": str(gcps)}, feedback=fb)
    assert [fb.lines.count(x) for x in warnings + ["P1 control ok"]] == [1, 1], fb.lines


def test_signal_during_a_core_call_is_a_cancel_and_the_handlers_come_back(qgis_processing):
    """call_core in the main thread of a headless run: SIGTERM cancels through the Progress adapter (the stage body
    sees is_cancelled and raises Cancelled); the Python and C-level handlers before the call are back after it."""
    from archaeoortho.core.common.progress import Cancelled
    from archaeoortho.processing_provider import base
    from qgis.core import QgsProcessingException, QgsProcessingFeedback

    if not base.headless():
        pytest.skip("the QGIS application here is a desktop one")
    seen = []

    def before(signum, frame):
        seen.append(signum)

    old = signal.signal(signal.SIGTERM, before)
    c_before = bytes(base._save_sigaction(signal.SIGINT) or b"")[:8]
    try:
        feedback = QgsProcessingFeedback()

        def stage(progress):
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000):
                if progress.is_cancelled():
                    raise Cancelled("cancelled by the user")
                time.sleep(0.01)
            return "went on to the end"

        with pytest.raises(QgsProcessingException, match="Cancelled"):
            base.call_core(stage, base.FeedbackProgress(feedback))
        assert feedback.isCanceled() and seen == []
        assert signal.getsignal(signal.SIGTERM) is before
        assert bytes(base._save_sigaction(signal.SIGINT) or b"")[:8] == c_before
        assert not base.SIGNALLED.is_set()
        os.kill(os.getpid(), signal.SIGTERM)  # outside a core call: the previous handler again
        time.sleep(0.05)
        assert seen == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, old)
