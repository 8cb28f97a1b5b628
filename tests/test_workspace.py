import json
import os
import stat

import pytest

from core.common.files import atomic_output
from core.project import workspace as wsmod
from core.project.stages import DONE, STAGE_ORDER
from core.project.workspace import Workspace, WorkspaceError


def test_create_reopen_and_stage_records(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    ws.begin_stage("align", {"pairing": "auto"}, {"images": "abc"})
    ws.record_timing("align", "features", 1.25)
    ws.end_stage("align", DONE, outputs={"model": "sfm/model"}, results={"registered": 5})
    again = Workspace.open(str(tmp_path / "ws"))
    rec = again.stage("align")
    assert rec["status"] == "done"
    assert rec["parameters"] == {"pairing": "auto"}
    assert rec["timings"]["features"] == 1.25 and "total" in rec["timings"]
    assert rec["outputs"]["model"] == "sfm/model"
    assert again.data["format_version"] == wsmod.FORMAT_VERSION
    # no temp files left beside the manifest
    assert sorted(os.listdir(tmp_path / "ws")) == ["workspace.json", wsmod.LOCK]  # the lock stays (flock)


def test_invalidate_later_stages(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path))
    for s in ("align", "georeference", "dsm"):
        ws.begin_stage(s, {})
        ws.end_stage(s, DONE)
    ws.invalidate_after("align", STAGE_ORDER)
    assert ws.stage("align")["status"] == "done"
    assert ws.stage("georeference")["status"] == "stale"
    assert ws.stage("dsm")["status"] == "stale"


def test_damaged_manifest_is_reported_and_left_alone(tmp_path):
    path = tmp_path / "workspace.json"
    path.write_text('{"format_version": 1, "images": [')
    before = path.read_bytes()
    with pytest.raises(WorkspaceError, match="damaged"):
        Workspace.create_or_open(str(tmp_path))
    assert path.read_bytes() == before


def test_newer_format_is_refused_and_left_alone(tmp_path):
    path = tmp_path / "workspace.json"
    path.write_text(json.dumps({"format_version": wsmod.FORMAT_VERSION + 1, "stages": {}}))
    before = path.read_bytes()
    with pytest.raises(WorkspaceError, match="newer"):
        Workspace.open(str(tmp_path))
    assert path.read_bytes() == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root ignores directory permissions")
def test_read_only_folder_refused_before_work(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        with pytest.raises(WorkspaceError, match="not writable"):
            Workspace.create_or_open(str(ro))
    finally:
        ro.chmod(stat.S_IRWXU)


def test_atomic_output_keeps_old_product_on_failure(tmp_path):
    target = tmp_path / "dsm.tif"
    target.write_text("complete old product")
    with pytest.raises(RuntimeError):
        with atomic_output(str(target)) as tmp:
            with open(tmp, "w") as f:
                f.write("half")
            raise RuntimeError("cancelled in the middle")
    assert target.read_text() == "complete old product"
    assert os.listdir(tmp_path) == ["dsm.tif"]
    with atomic_output(str(target)) as tmp:
        with open(tmp, "w") as f:
            f.write("new")
    assert target.read_text() == "new"


def test_atomic_output_replaces_folders(tmp_path):
    target = tmp_path / "model"
    target.mkdir()
    (target / "old.bin").write_text("x")
    with atomic_output(str(target)) as tmp:
        os.makedirs(tmp)
        with open(os.path.join(tmp, "new.bin"), "w") as f:
            f.write("y")
    assert os.listdir(target) == ["new.bin"]
    assert sorted(os.listdir(tmp_path)) == ["model"]


def test_stage_records_missing_read_as_none_damaged_name_the_file(tmp_path):
    """A record that is not there yet (before its stage) is None; one that is there but damaged or not UTF-8
    raises the caller's error naming the file -- never mistaken for a missing record."""
    from core.common.files import read_json_record
    from core.prepare.stage import load_screening
    from core.report.errors import ReportError

    assert read_json_record(str(tmp_path / "absent.json"), ReportError) is None
    assert load_screening(str(tmp_path)) is None
    good = tmp_path / "good.json"
    good.write_text('{"a": [1, 2]}', encoding="utf-8")
    assert read_json_record(str(good), ReportError) == {"a": [1, 2]}
    for name, data in (("cut.json", b'{"a": [1, 2'), ("latin.json", b'{"a": "\xe9"}')):
        p = tmp_path / name
        p.write_bytes(data)
        with pytest.raises(ReportError) as e:
            read_json_record(str(p), ReportError)
        assert str(p) in str(e.value) and "cannot be read" in str(e.value)
    from core.project.layout import SCREENING_JSON
    (tmp_path / SCREENING_JSON).parent.mkdir(parents=True, exist_ok=True)
    (tmp_path / SCREENING_JSON).write_text("{", encoding="utf-8")
    with pytest.raises(WorkspaceError) as e:
        load_screening(str(tmp_path))
    assert SCREENING_JSON.split("/")[-1] in str(e.value)
