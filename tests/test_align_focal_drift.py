"""The mapping against a drifting self-calibration (core.align.mapping._against_focal_drift): when the focal length
the mapper refines leaves the photos' own (EXIF, a calibration) by more than FOCAL_DRIFT_LIMIT and the block is
incomplete, the block is mapped again with the intrinsics held and the mapping that registers more is kept; the
final adjustment then holds the focal length.  garfield_rgb_small (28 wide-angle, rolling-shutter photos over a
park) is the real case: self-calibrated its focal went from 1,243 to 2,577-3,774 px and 9-14 of 28 registered."""
import glob
import os
from types import SimpleNamespace

import numpy as np
import pytest

from core.align import mapping
from core.align.mapping import FOCAL_DRIFT_LIMIT, MappingJob, focal_drift
from core.common.progress import NullProgress
from tests.conftest import shared


class _Cam:
    def __init__(self, f):
        self.f = f

    def mean_focal_length(self):
        return self.f


def _rec(n_reg, f, cid=1):
    images = {i: SimpleNamespace(camera_id=cid, has_pose=i < n_reg, name=f"i{i}") for i in range(max(n_reg, 1))}
    return SimpleNamespace(cameras={cid: _Cam(f)}, images=images, num_reg_images=lambda: n_reg)


class _Progress(NullProgress):
    def __init__(self):
        self.lines = []

    def info(self, text):
        self.lines.append(text)

    def warning(self, text):
        self.lines.append("WARNING " + text)


def _run(monkeypatch, free, held_count, n_images=28, prior=1242.5):
    calls = []

    def mapped(pycolmap, job, options, progress, hold_all, hold_focal):
        calls.append((hold_all, hold_focal))
        return {0: _rec(held_count, prior)}

    monkeypatch.setattr(mapping, "_mapped", mapped)
    monkeypatch.setattr(mapping, "prior_focals", lambda pycolmap, db: {1: prior})
    job = MappingJob("db", "images", "out", n_images)
    progress = _Progress()
    out = mapping._against_focal_drift(None, job, None, progress, {0: free})
    return out, job, calls, progress


def test_the_drift_is_the_largest_ratio_either_way():
    assert focal_drift(_rec(5, 2500.0), {1: 1250.0}) == (pytest.approx(2.0), 1)
    assert focal_drift(_rec(5, 625.0), {1: 1250.0}) == (pytest.approx(2.0), 1)
    assert focal_drift(_rec(5, 1300.0), {}) == (1.0, None)  # no prior (no EXIF): nothing to drift from


def test_a_drifted_incomplete_block_is_mapped_again_holding_the_intrinsics(monkeypatch):
    free = _rec(12, 2577.0)
    out, job, calls, progress = _run(monkeypatch, free, held_count=28)
    assert calls == [(True, True)]
    assert out[0].num_reg_images() == 28
    assert job.focal_held == {"prior_px": 1242.5, "drifted_px": 2577.0, "registered_free": 12, "registered_held": 28}
    assert any(line.startswith("WARNING") and "2577" in line and "held 28" in line for line in progress.lines)


def test_the_free_mapping_stays_when_holding_registers_no_more(monkeypatch):
    free = _rec(12, 2577.0)
    out, job, calls, _ = _run(monkeypatch, free, held_count=12)
    assert calls == [(True, True)] and out[0] is free and job.focal_held is None


@pytest.mark.parametrize("n_reg, f", [(12, 1242.5 * FOCAL_DRIFT_LIMIT * 0.99), (28, 3774.0)])
def test_no_second_mapping_within_the_limit_or_with_every_image(monkeypatch, n_reg, f):
    free = _rec(n_reg, f)
    out, job, calls, _ = _run(monkeypatch, free, held_count=28)
    assert calls == [] and out[0] is free and job.focal_held is None


def test_garfield_registers_every_photo_and_holds_its_shape(tmp_path):
    """The real block: all 28 photos registered (without the guard 5-14), the focal length held at EXIF's.  The
    shape is printed, not asserted: the camera centres lie 15.0 m RMSE (XY) from a rigid fit to their EXIF GPS
    over the 100 x 180 m block (12-27 m with the full-size features, varying between runs of the two-threaded
    mapper; the 9-photo block of the old path: 46 m); a rolling shutter and bare trees leave it weak (issue 37
    item 4 stays open on it).  Measured at these settings: self-calibrated the focal went from 1,243 to 5,474 px
    with 5 of 28 registered, held 28 (the same each run); two threads instead, 4 runs: 1,660-2,639 px with 6-14
    registered, held 28 every time (the full-size features: 1,701-3,774 px, 6-14, held 28)."""
    pycolmap = pytest.importorskip("pycolmap")
    from core.align.options import AlignOptions
    from core.align.stage import align
    from core.io.images import read_image_info

    images = shared("garfield_rgb_small", "images")
    # issue 45: features from the photos at 1024 px (not their 1536) and 1,024 of them (not the auto 4,096), one
    # thread (the same mapping every run): 28 - 31 CPU s against 81; the guard's case all the same
    r = align(images, str(tmp_path / "ws"), AlignOptions(escalate=False, max_image_size=1024, max_features=1024,
                                                         num_threads=1))
    assert r.registered == 28, r.unregistered
    assert r.focal_held and r.focal_held["registered_held"] == 28
    assert r.cameras[0]["params"][0] == pytest.approx(r.focal_held["prior_px"], abs=0.01)
    rec = pycolmap.Reconstruction(r.model_dir)
    gps = {os.path.basename(p): read_image_info(p).gps for p in glob.glob(os.path.join(images, "*"))}
    lat0 = np.mean([g[1] for g in gps.values()])
    a, b = [], []
    for im in rec.images.values():
        lon, lat, alt = gps[im.name]
        a.append(im.projection_center())
        b.append((lon * 111320 * np.cos(np.radians(lat0)), lat * 110540, alt))
    a, b = np.array(a), np.array(b)
    a, b = a - a.mean(0), b - b.mean(0)
    s = np.sqrt((b ** 2).sum() / (a ** 2).sum())
    u, _, vt = np.linalg.svd(b.T @ a)
    rot = u @ np.diag([1, 1, np.sign(np.linalg.det(u @ vt))]) @ vt
    res = s * a @ rot.T - b
    rmse_xy = float(np.sqrt((res[:, :2] ** 2).sum(1).mean()))
    print(f"\ngarfield: 28/28, {r.mean_reprojection_error:.3f} px, centres {rmse_xy:.1f} m RMSE XY from EXIF GPS")
    assert np.isfinite(rmse_xy) and len(a) == 28
