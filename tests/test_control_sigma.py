"""Control of unknown accuracy (issue 32, item 2): control points and camera positions given without sigmas get
their sigmas estimated from the data (core.georef.control_sigma), against synthetic truth (tests/synthetic.py).

The rule: on the same check points the constrained adjustment is never worse than the Helmert-only solution by
more than 10 %; where the data do not support bending the block it stays (nearly) rigid, where they do (precise
control on a sagging strip) it bends.  Figures are printed (pytest -s)."""
import dataclasses
import os

import numpy as np
import pytest

from core.georef.adjust import georeference
from core.georef.control_sigma import (
    CAMERA_GROUP,
    CONTROL_GROUP,
    helmert_redundancy,
    lmeds_sigma,
    robust_sigma,
)
from core.georef.results import REJECTED, USED
from core.io.gcp import (
    CHECK,
    CONTROL,
    GCPSet,
    GroundPoint,
    gcps_from_rows,
    read_camera_positions,
    read_gcps,
    write_csv_gcps,
    write_odm_gcp_list,
)
from tests import synthetic as syn

GCP_NOISE_PX = 0.4


@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1)


@pytest.fixture(scope="module")
def rec(block):
    return block.truth_reconstruction()


def _noisy(gcps: GCPSet, noise: float, seed: int) -> GCPSet:
    """The control points' coordinates with N(0, noise) on each axis (check points keep the truth)."""
    rng = np.random.default_rng(seed)
    pts = []
    for p in gcps.points:
        if p.role == CONTROL:
            e = rng.normal(0.0, noise, 3)
            p = dataclasses.replace(p, x=p.x + e[0], y=p.y + e[1], z=p.z + e[2])
        pts.append(p)
    return dataclasses.replace(gcps, points=pts)


def _through_gcp_list(gcps: GCPSet, tmp_path, name="gcp_list.txt") -> GCPSet:
    """Written as an OpenDroneMap gcp_list.txt (a format without sigmas) and read back, as a user's file is."""
    path = str(tmp_path / name)
    write_odm_gcp_list(gcps, path)
    return read_gcps(path)


def _estimate(result, group=CONTROL_GROUP):
    found = [e for e in result.sigma_estimates if e["group"] == group]
    assert len(found) == 1, result.sigma_estimates
    return found[0]


def _not_worse(chk, hel, gsd):
    """The rule: the adjusted check points no worse than the Helmert-only ones by more than 10 % (3-D RMSE);
    per axis the same, plus one GSD of noise (an axis whose error is a few GSD can differ by that either way)."""
    assert chk["xyz"] <= 1.10 * hel["xyz"], (chk, hel)
    assert chk["xy"] <= 1.10 * hel["xy"] + gsd and chk["z"] <= 1.10 * hel["z"] + gsd, (chk, hel)


def _compare(label, result):
    chk, hel = result.rmse(CHECK), result.rmse(CHECK, helmert=True)
    ests = "; ".join(f"{e['group']}: sigma XY {e['sigma_xy_m']:.3f} Z {e['sigma_z_m']:.3f} m (rigid fit "
                     f"{e['helmert_xy_m']:.3f} / {e['helmert_z_m']:.3f}, floor {e['floor_xy_m']:.3f} / "
                     f"{e['floor_z_m']:.3f}, {e['iterations']} VCE it.)" for e in result.sigma_estimates)
    print(f"\n[{label}] check n={chk['n']}: adjusted XY {chk['xy']:.3f} Z {chk['z']:.3f} m | Helmert only XY "
          f"{hel['xy']:.3f} Z {hel['z']:.3f} m | {ests or 'sigmas given'}")
    return chk, hel


# ----------------------------------------------------------------------------------------------
# the estimators against known truth
# ----------------------------------------------------------------------------------------------


def test_helmert_redundancy_numbers_sum_to_the_fits_redundancy():
    rng = np.random.default_rng(1)
    for n in (3, 4, 9):
        r = helmert_redundancy(rng.normal(0, 50.0, (n, 3)))
        assert r.shape == (n, 3)
        assert abs(r.sum() - (3 * n - 7)) < 1e-9
        assert np.all((r >= 0) & (r <= 1))


def test_sigma_from_a_similarity_fit_of_noisy_points():
    """Points moved by a similarity plus N(0, 2 m): the least median of squares scale and the redundancy-weighted
    estimate find 2 m; a third of the points 100 m off does not move them."""
    rng = np.random.default_rng(4)
    n = 12
    model = rng.uniform(-300, 300, (n, 3)) * [1, 1, 0.1]
    tr = syn.look_at(np.zeros(3), np.array([0.3, 0.2, -1.0]), np.array([0.0, 1.0, 0.0]))
    world = 0.5 * model @ tr.T + [1000.0, 2000.0, 50.0] + rng.normal(0, 2.0, (n, 3))
    s0 = lmeds_sigma(model, world)
    assert 1.0 < s0 < 4.0, s0
    bad = world.copy()
    bad[:4, 0] += 100.0
    s_bad = lmeds_sigma(model, bad)
    assert 1.0 < s_bad < 4.0, s_bad
    from core.geometry.similarity import helmert_fit

    fit = helmert_fit(model, world)
    fitted = fit.apply(model)
    sxy, sz, rxy, rz, excluded, _ = robust_sigma(world - fitted, helmert_redundancy(fitted),
                                                 [f"p{k}" for k in range(n)], (0.01, 0.01))
    assert 1.3 < sxy < 3.0 and 1.0 < sz < 4.0, (sxy, sz)
    assert abs(rxy + rz - (3 * n - 7)) < 1e-6 and not excluded
    # one point 30 m off among them: named, and the others' sigma stays
    world2 = world.copy()
    world2[5, 1] += 30.0
    fit = helmert_fit(model, world2)
    fitted = fit.apply(model)
    sxy, sz, _, _, excluded, _ = robust_sigma(world2 - fitted, helmert_redundancy(fitted),
                                              [f"p{k}" for k in range(n)], (0.01, 0.01))
    assert excluded == ["p5"] and sxy < 4.0, (excluded, sxy)


# ----------------------------------------------------------------------------------------------
# which sigmas a source gave
# ----------------------------------------------------------------------------------------------


def test_readers_mark_the_points_that_came_without_sigmas(tmp_path, block):
    gcps = block.gcp_set(block.spread_control(5), noise_px=GCP_NOISE_PX)
    read = _through_gcp_list(gcps, tmp_path)
    assert read.points and not any(p.sigma_given for p in read.points)  # gcp_list.txt has no sigmas
    # CSV: a row with a sigma cell gives its sigmas, an empty one does not; the writer keeps that apart
    pts = tmp_path / "p.csv"
    pts.write_text("# crs: EPSG:32633\nname,x,y,z,sx,sy,sz\nA,500000,5000000,100,0.5,0.5,1.0\n"
                   "B,500010,5000000,100,,,\nC,500000,5000010,100,,,\n")
    (tmp_path / "p_observations.csv").write_text("name,image,px,py\nA,a.jpg,1,2\nA,b.jpg,3,4\nB,a.jpg,5,6\n"
                                                 "B,b.jpg,7,8\nC,a.jpg,9,9\nC,b.jpg,8,8\n")
    gs = read_gcps(str(pts))
    assert [(p.name, p.sigma_given, p.sigma_xy) for p in gs.points] == [("A", True, 0.5), ("B", False, 0.02),
                                                                         ("C", False, 0.02)]
    gs.by_name("C").sigma_xy = 2.0  # a user's entry: given from now on
    p2, _ = write_csv_gcps(gs, str(tmp_path / "back.csv"))
    back = read_gcps(p2)
    assert [(p.name, p.sigma_given, p.sigma_xy) for p in back.points] == [("A", True, 0.5), ("B", False, 0.02),
                                                                           ("C", True, 2.0)]
    # the workspace's JSON keeps the flag; an older one without it: the defaults exactly mean "none given"
    d = back.to_dict()
    assert [p.sigma_given for p in GCPSet.from_dict(d).points] == [True, False, True]
    for p in d["points"]:
        del p["sigma_given"]
    assert [p.sigma_given for p in GCPSet.from_dict(d).points] == [True, False, True]
    # a layer's rows
    rows = [{"name": "A", "x": 500000, "y": 5000000, "z": 100, "image": "a.jpg", "px": 1, "py": 2, "sx": 0.3},
            {"name": "B", "x": 500010, "y": 5000000, "z": 100, "image": "a.jpg", "px": 5, "py": 6, "sx": None}]
    assert [p.sigma_given for p in gcps_from_rows(rows, "EPSG:32633").points] == [True, False]

    class Null:  # a layer's NULL attribute as PyQGIS hands it over (QVariant)
        def isNull(self):
            return True

    rows[1]["sx"] = Null()
    assert [p.sigma_given for p in gcps_from_rows(rows, "EPSG:32633").points] == [True, False]
    # constructed directly: taken at its word (backwards compatible)
    assert GroundPoint("x", 0.0, 0.0, 0.0).sigma_given
    # camera positions: rows without a sigma are marked
    cams = tmp_path / "cams.txt"
    cams.write_text("EPSG:32633\nimage,x,y,z,sigma\na.jpg,500000,5000000,150,0.5\nb.jpg,500010,5000000,150,\n")
    _, cps = read_camera_positions(str(cams))
    assert [(c.image, c.sigma_given) for c in cps] == [("a.jpg", True), ("b.jpg", False)]


# ----------------------------------------------------------------------------------------------
# the adjustment with control of unknown accuracy
# ----------------------------------------------------------------------------------------------


def test_three_metre_control_without_sigma_is_estimated_and_keeps_the_block_rigid(block, rec, tmp_path):
    """Control of 3 m accuracy in a gcp_list.txt (no sigmas): the estimated sigma is within a factor 2 of 3 m,
    the adjustment weights the control with it and the check points are no worse than the Helmert-only
    solution's (10 %).  With the placeholder 0.02 m stated as the points' sigma, correct points would be thrown
    out as outliers (each metres off the others' fit: hundreds of sigmas)."""
    control = block.spread_control(8)
    gcps = _noisy(block.gcp_set(control, noise_px=GCP_NOISE_PX), 3.0, seed=7)
    result = georeference(rec, _through_gcp_list(gcps, tmp_path))
    chk, hel = _compare("3 m control without sigma", result)
    e = _estimate(result)
    assert e["n"] == len(control) and not e["excluded"]
    assert 1.5 <= e["sigma_xy_m"] <= 6.0 and 1.5 <= e["sigma_z_m"] <= 6.0, e
    assert e["floor_xy_m"] < 0.1 * e["sigma_xy_m"]  # well above what the block resolves
    assert chk["n"] >= 5
    _not_worse(chk, hel, block.gsd)
    assert not [o for o in result.outliers if o.kind == "control point"], result.outliers
    # the control was weighted with the estimate, and the files say so
    used = [r for r in result.points if r.status == USED]
    assert used and all(r.sigma_xy == pytest.approx(e["sigma_xy_m"]) for r in used)
    d = result.residuals_dict()
    assert d["sigma_estimates"] == result.sigma_estimates
    assert d["points"][0]["sigma_xy"] is not None or d["points"][0]["status"] != USED
    assert not [w for w in result.warnings if "sigma XY" in w]  # the estimate replaces the warning
    # the same points with their placeholder stated as their sigma (a file with 0.02 m sigma columns)
    stated = dataclasses.replace(gcps, points=[dataclasses.replace(p, sigma_given=True) for p in gcps.points])
    forced = georeference(rec, stated)
    _compare("3 m control stated at 0.02 m", forced)
    assert not forced.sigma_estimates
    assert len([o for o in forced.outliers if o.kind == "control point"]) >= 2


def test_precise_control_without_sigma_lets_a_sagging_strip_bend(tmp_path):
    """A long strip whose model sags by 1.5 m, control of 0.02 m accuracy without sigmas: the estimate comes
    down to the block's own precision and the adjustment removes the sag, as it does with the sigma given."""
    strip = syn.single_strip(seed=3, n=12)
    xs = np.array([s.centre[0] for s in strip.shots])
    bend = syn.dome(1.5, (float(xs.mean()), 0.0), 0.5 * (xs.max() - xs.min()) + 10.0)
    rec = strip.truth_reconstruction(deform=bend)
    ground = sorted((p for p in strip.gcps if p.kind == "ground"), key=lambda p: p.xyz[0])
    control = [ground[0].name, ground[1].name, ground[-1].name, ground[-2].name, ground[len(ground) // 2].name]
    gcps = _noisy(strip.gcp_set(control, noise_px=GCP_NOISE_PX), 0.02, seed=7)
    result = georeference(rec, _through_gcp_list(gcps, tmp_path))
    chk, hel = _compare("sagging strip, 0.02 m control without sigma", result)
    e = _estimate(result)
    assert e["helmert_z_m"] > 0.2  # the rigid fit sees the sag...
    assert e["iterations"] >= 1 and e["sigma_z_m"] < 0.5 * e["helmert_z_m"]  # ...the adjustment removes it
    assert e["sigma_xy_m"] <= 1.5 * strip.gsd and e["sigma_z_m"] <= 2.0 * strip.gsd, e
    assert hel["xyz"] > 0.3
    assert chk["xyz"] <= hel["xyz"] / 4
    assert chk["xy"] <= 1.0 * strip.gsd and chk["z"] <= 1.5 * strip.gsd


def test_control_with_sigma_columns_keeps_its_sigma(block, rec, tmp_path):
    """A CSV with sigma columns: those sigmas are used as they are (nothing estimated); a file that gives
    sigmas for some points only gets the others' estimated."""
    control = block.spread_control(8)
    gcps = _noisy(block.gcp_set(control, noise_px=GCP_NOISE_PX, sigma_xy=3.0, sigma_z=3.0), 3.0, seed=7)
    path = str(tmp_path / "pts.csv")
    write_csv_gcps(gcps, path)
    read = read_gcps(path)
    assert all(p.sigma_given for p in read.points)
    result = georeference(rec, read)
    chk, hel = _compare("3 m control with sigma 3 m given", result)
    assert not result.sigma_estimates
    used = [r for r in result.points if r.status == USED]
    assert len(used) == len(control) and all((r.sigma_xy, r.sigma_z) == (3.0, 3.0) for r in used)
    _not_worse(chk, hel, block.gsd)
    # mixed: two points keep their given sigma, the other six are estimated
    mixed = dataclasses.replace(read, points=[dataclasses.replace(p, sigma_given=p.name in control[:2])
                                              for p in read.points])
    result = georeference(rec, mixed)
    e = _estimate(result)
    assert sorted(e["names"]) == sorted(control[2:])
    sig = {r.name: r.sigma_xy for r in result.points if r.status == USED}
    assert sig[control[0]] == sig[control[1]] == 3.0
    assert all(sig[n] == pytest.approx(e["sigma_xy_m"]) for n in control[2:])


def test_a_control_point_with_a_100_m_typo_is_named_and_does_not_inflate_the_estimate(block, rec, tmp_path):
    control = block.spread_control(8)
    extra = next(p.name for p in block.gcps if p.kind == "ground" and p.name not in control)
    gcps = _noisy(block.gcp_set(control + [extra], noise_px=GCP_NOISE_PX), 3.0, seed=7)
    gcps.by_name(extra).x += 100.0
    result = georeference(rec, _through_gcp_list(gcps, tmp_path))
    chk, hel = _compare("3 m control without sigma, one 100 m typo", result)
    assert [o.name for o in result.outliers if o.kind == "control point"] == [extra]
    assert any(extra in w for w in result.warnings)
    row = next(r for r in result.points if r.name == extra)
    assert row.status == REJECTED and abs(abs(row.dx) - 100.0) < 10.0
    e = _estimate(result)
    assert 1.5 <= e["sigma_xy_m"] <= 6.0 and 1.5 <= e["sigma_z_m"] <= 6.0, e
    _not_worse(chk, hel, block.gsd)


def test_camera_positions_without_sigma_are_estimated(block, rec, tmp_path):
    """Camera positions of 2 m accuracy from a file without sigma columns (read with the 5 / 10 m defaults):
    their sigma is estimated within a factor 2 and the check points stay within 10 % of the Helmert-only
    solution's."""
    positions, _ = block.camera_positions(sigma=2.0, seed=13)
    path = tmp_path / "positions.txt"
    path.write_text(syn.CRS + "\n" + "".join(f"{c.image} {c.x!r} {c.y!r} {c.z!r}\n" for c in positions))
    _, cps = read_camera_positions(str(path))
    assert not any(c.sigma_given for c in cps) and cps[0].sigma_xy == 5.0
    result = georeference(rec, block.gcp_set([], noise_px=GCP_NOISE_PX), cps)
    chk, hel = _compare("camera positions of 2 m without sigma", result)
    e = _estimate(result, CAMERA_GROUP)
    assert e["n"] == len(cps)
    assert 1.0 <= e["sigma_xy_m"] <= 4.0 and 1.0 <= e["sigma_z_m"] <= 4.0, e
    assert all(c.sigma_xy == pytest.approx(e["sigma_xy_m"]) for c in result.cameras)
    _not_worse(chk, hel, block.gsd)


def test_the_stage_records_the_estimate_and_the_report_and_the_precision_use_it(block, tmp_path):
    """Through the workspace: georef/residuals.json holds the estimate and each control point's sigma, the run's
    results the figures, the report's georeferencing section shows it (keyed numbers equal to the file's), and
    the precision (core.georef.uncertainty) weights the control with it rather than the placeholder."""
    import json
    import re

    import pycolmap

    from core.georef import uncertainty
    from core.georef.options import GeorefOptions
    from core.georef.stage import georeference_workspace
    from core.project.workspace import Workspace
    from core.report import stage as report
    from tests.workspaces import synthetic_workspace

    rec = block.truth_reconstruction(n_points=800)
    ws = synthetic_workspace(str(tmp_path / "ws"), block, rec, images_dir="/synthetic/images")
    control = block.spread_control(8)
    gcps = _noisy(block.gcp_set(control, noise_px=GCP_NOISE_PX), 3.0, seed=7)
    path = str(tmp_path / "gcp_list.txt")
    write_odm_gcp_list(gcps, path)
    georeference_workspace(ws, GeorefOptions(gcp_path=path))
    with open(os.path.join(ws, "georef", "residuals.json"), encoding="utf-8") as f:
        res = json.load(f)
    (e,) = res["sigma_estimates"]
    assert 1.5 <= e["sigma_xy_m"] <= 6.0
    used = [p for p in res["points"] if p["status"] == "used"]
    assert len(used) == len(control) and all(p["sigma_xy"] == e["sigma_xy_m"] for p in used)
    from core.project.stages import GEOREFERENCE

    figures = Workspace.open(ws).stage(GEOREFERENCE)["results"]  # the georef record
    assert figures["CONTROL_SIGMA_XY"] == e["sigma_xy_m"] and figures["CONTROL_SIGMA_Z"] == e["sigma_z_m"]
    assert figures["CAMERA_POSITION_SIGMA_XY"] is None
    # the precision weights the control with the estimate
    w = Workspace.open(ws)
    model = pycolmap.Reconstruction()
    model.read_binary(w.path("georef", "model"))
    ctl, _, _, _ = uncertainty.workspace_inputs(w, model)
    assert ctl and all(c.sigma[0] == e["sigma_xy_m"] and c.sigma[2] == e["sigma_z_m"] for c in ctl)
    # the report
    built = report.build_report(ws)
    with open(built.path, encoding="utf-8") as f:
        text = f.read()
    assert "estimated from the data" in text
    m = re.search(r'data-key="sigma\.control\.xy" data-value="([^"]+)"', text)
    assert m and float(m.group(1)) == pytest.approx(e["sigma_xy_m"], rel=1e-6)


def test_camera_positions_without_sigma_or_heights_estimate_xy_only(block, rec, tmp_path):
    positions, _ = block.camera_positions(sigma=2.0, seed=13)
    cps = [dataclasses.replace(c, z=float("nan"), sigma_given=False) for c in positions]
    gcps = block.gcp_set(block.spread_control(3), noise_px=GCP_NOISE_PX)
    result = georeference(rec, gcps, cps)
    e = _estimate(result, CAMERA_GROUP)
    assert 1.0 <= e["sigma_xy_m"] <= 4.0, e
    assert e["sigma_z_m"] == cps[0].sigma_z and "no heights" in e["note"]
    assert all(c.sigma_z is None for c in result.cameras)
    assert all(os.path.getsize(p) for p in result.save(str(tmp_path)).values())  # written: no NaN in the files


def test_a_sigma_of_a_nanometre_is_honoured_and_said(block):
    """Issue 47 item 6: control given sigma 1e-9 m is held as given (the points fixed), not stalled: on a block
    bent by a 1 m dome the exact control unbends it as well as with sigma 1 mm (the damping floor of every
    tie point had been set by the largest diagonal, 1e18 for such a point, and held the block still: check
    points 2.1 m off instead of 0.07 m); the warning names the points and the sigma."""
    control = block.spread_control(8)
    out = {}
    for s in (1e-3, 1e-9):
        rec = block.truth_reconstruction(deform=syn.dome(1.0, (0.0, 0.0), 40.0))
        out[s] = georeference(rec, block.gcp_set(control, noise_px=GCP_NOISE_PX, sigma_xy=s, sigma_z=s))
    fine, mm = out[1e-9], out[1e-3]
    assert fine.rmse(CHECK)["xyz"] <= 1.1 * mm.rmse(CHECK)["xyz"] + 0.1 * block.gsd, (fine.rmse(CHECK), mm.rmse(CHECK))
    assert fine.rmse(CONTROL)["xyz"] <= 1.1 * mm.rmse(CONTROL)["xyz"] + 0.1 * block.gsd
    said = [w for w in fine.warnings if "held fixed" in w]
    assert said and "1e-09 m" in said[0] and all(n in said[0] for n in control), fine.warnings
    assert not any("held fixed" in w for w in mm.warnings)
