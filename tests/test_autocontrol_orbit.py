"""Automatic control of an oblique block (issue 16, "must show": an oblique registered the same way).

The synthetic orbit of the alignment issue (tests/synthetic.py ``orbit_block``: 16 views circling the site at 45
and 65 degrees off nadir, the horizon, the sky and drifting clouds in the steep ones) is rendered, its sky masked
('Prepare images') and aligned in its own arbitrary model frame; the reference is the scene's own true
orthophoto (0.1 m) and DSM (0.25 m) as tests/test_autocontrol.py writes them.  ``autocontrol_workspace`` with no
prior at all (rotation and scale searched) must georeference the block so that the true ground marks, as check
points, lie within 1.5 x the reference's resolution in X, Y and 2 x in Z (the issue's tolerances), and the camera
centres near their truth.  Rendering and alignment take a minute or two: marked slow.
"""
import os

import numpy as np
import pytest

from core.align.options import AlignOptions
from core.align.stage import align
from core.georef.autocontrol.options import AutoControlOptions
from core.georef.autocontrol.stage import autocontrol_workspace
from core.prepare.options import PrepareOptions
from core.prepare.stage import prepare_images_workspace
from core.project.layout import Layout
from core.project.workspace import Workspace
from tests import synthetic as syn
from tests.test_autocontrol import REF_GSD, write_reference

HERE = os.path.dirname(os.path.abspath(__file__))
CACHE = os.path.join(os.path.dirname(HERE), "build", "test-cache", "autocontrol-orbit-v1")
ORBIT = dict(seed=21, per_ring=8)


@pytest.fixture(scope="module")
def orbit_run(tmp_path_factory):
    """(orbit block, workspace, AutoControlResult): rendered (cached), sky-masked, aligned, then automatic
    control with no prior and the true ground marks as check points."""
    import time

    orbit = syn.orbit_block(**ORBIT)
    photos = os.path.join(CACHE, "photos")
    done = os.path.join(CACHE, "done")
    if not os.path.isfile(done):
        os.makedirs(CACHE, exist_ok=True)
        orbit.render(photos)
        write_reference(orbit.scene, CACHE)
        open(done, "w").close()
    ortho, dsm = os.path.join(CACHE, "ref_ortho.tif"), os.path.join(CACHE, "ref_dsm.tif")
    ws = str(tmp_path_factory.mktemp("orbit-auto") / "ws")
    t0 = time.time()
    prep = prepare_images_workspace(photos, ws, options=PrepareOptions(sky_masks=True))
    al = align(prep.prepared_dir, ws, AlignOptions(pairing="exhaustive", num_threads=2))
    t1, c0 = time.time(), os.times()
    checks = orbit.gcp_set([], noise_px=0.3, only=[p.name for p in orbit.gcps if p.kind == "ground"])
    result = autocontrol_workspace(ws, AutoControlOptions(reference_ortho=ortho, reference_dsm=dsm, prior="none",
                                                          check_points=checks))
    c1 = os.times()
    print(f"\n[orbit autocontrol] prepare + align {t1 - t0:.0f} s ({al.registered}/{len(orbit.shots)} registered); "
          f"autocontrol {time.time() - t1:.0f} s, {c1.user + c1.system - c0.user - c0.system:.0f} CPU s; "
          f"{result.timings}")
    for m in result.messages:
        print("  ", m)
    return orbit, ws, result, al


def _centre_errors(ws, orbit):
    rec, tr = Layout(Workspace.open(ws)).load_georef_model()
    off = tr.offset
    out = {}
    for im in rec.images.values():
        m = np.asarray(im.cam_from_world().matrix())
        out[im.name] = -m[:, :3].T @ m[:, 3] + off - (orbit.shot(im.name).centre + syn.ORIGIN)
    return out


@pytest.mark.slow
def test_orbit_georeferenced_by_automatic_control_with_no_prior(orbit_run):
    orbit, ws, result, al = orbit_run
    assert al.registered == len(orbit.shots)
    f = result.georef.figures
    err = _centre_errors(ws, orbit)
    d = np.array(list(err.values()))
    exy, ez = np.hypot(d[:, 0], d[:, 1]), np.abs(d[:, 2])
    print(f"\n{result.figures}; check points n={f['CHECK_N']}: XY {f['CHECK_RMSE_XY']:.3f} m "
          f"({f['CHECK_RMSE_XY'] / REF_GSD:.2f} x the reference GSD), Z {f['CHECK_RMSE_Z']:.3f} m "
          f"({f['CHECK_RMSE_Z'] / REF_GSD:.2f} x); camera centres XY median {np.median(exy):.3f} max {exy.max():.3f} m, "
          f"Z median {np.median(ez):.3f} max {ez.max():.3f} m")
    assert result.n_kept >= 10
    assert f["CHECK_N"] >= 6
    assert f["CHECK_RMSE_XY"] <= 1.5 * REF_GSD
    assert f["CHECK_RMSE_Z"] <= 2.0 * REF_GSD
    # the centres lie 40-86 m from the site (as test_obliques' orbit with 5 hand-picked GCPs: 2 x its nadir GSD)
    assert np.median(exy) <= 2.0 * orbit.gsd and np.median(ez) <= 4.0 * orbit.gsd
