"""Calibrated cameras (issue 32, item 1): a given interior orientation is held fixed, refined with priors or
estimated, through the alignment, the georeference and the report (core.align.calibrated).

End to end on a small rendered vertical block (2 strips x 5 photos of 800 x 600 px, tests/synthetic.py's camera:
650 px, OPENCV distortion), the photos cached under build/test-cache.  Measured on this block (5 control points,
camera centres against the truth after the georeference; docs/measurements.md has the table): fixed at the true
calibration the focal length stays 650.000 px and the centres are off by 0.050 m XY / 0.016 m Z RMS; estimated
from the same start it drifts to 651.41 px (+0.22 %) and the centres by 0.157 / 0.097 m (0.097 / 0.070 with
refine_intrinsics); self-calibrated without any calibration 652.24 px (+0.35 %), 0.165 / 0.156 m.
"""
import json
import os
from types import SimpleNamespace

import numpy as np
import pytest

from core.align.calibrated import plan_cameras, scan_interior
from core.align.options import AlignError, AlignOptions
from core.align.stage import align, load_model
from core.common.errors import ArchaeoOrthoError
from core.common.progress import NullProgress
from core.georef.adjust import georeference
from core.georef.options import GeorefOptions
from core.georef.stage import georeference_workspace, load_georef_model
from core.io.gcp import CHECK
from core.io.images import CameraGroup, ImageInfo
from core.project.layout import Layout
from core.project.workspace import Workspace
from core.report.sections.orientation import interior_orientation
from tests import synthetic as syn
from tests.test_align_relaxed import _Log  # a progress that keeps the log lines
from tests.test_autocontrol import epochs  # noqa: F401 - the automatic control's two epochs, rendered once
from tests.workspaces import rendered_once

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "build", "test-cache", "calibrated-v1")
NAMES = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"]


@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1, n_strips=2, per_strip=5)


@pytest.fixture(scope="module")
def images(block):
    return rendered_once(block, CACHE)


def write_calibration(path, cam, focal=None, **extra):
    """ArchaeoOrtho's own calibration format (JSON) of a tests/synthetic.py CameraModel."""
    doc = {"name": "synthetic", "image_size_px": [cam.width, cam.height], "focal_length_px": focal or cam.fx,
           "principal_point_px": [cam.cx, cam.cy], "k1": cam.k1, "k2": cam.k2, "p1": cam.p1, "p2": cam.p2}
    doc.update(extra)
    with open(path, "w") as f:
        json.dump(doc, f)
    return str(path)


def _options(**kw):
    return AlignOptions(num_threads=2, pairing="exhaustive", **kw)


def _centre_errors(block, ws):
    rec, transform = load_georef_model(ws)
    offset = transform.offset
    return np.array([np.asarray(im.projection_center()) + offset - (block.shot(im.name).centre + syn.ORIGIN)
                     for im in rec.images.values() if im.has_pose])


@pytest.fixture(scope="module")
def fixed_ws(block, images, tmp_path_factory):
    root = tmp_path_factory.mktemp("calibrated")
    cal = write_calibration(root / "camera.json", block.camera)
    log = _Log()
    result = align(images, str(root / "ws"), _options(calibration=cal), log)
    return str(root / "ws"), cal, result, log


def test_a_fixed_calibration_is_held_through_alignment_and_georeference(block, fixed_ws):
    ws, cal, result, log = fixed_ws
    assert result.registered == len(block.shots)
    (cam,) = load_model(ws).cameras.values()
    assert cam.model.name == "OPENCV"
    assert np.max(np.abs(np.asarray(cam.params) - block.camera.params)) <= 1e-9
    # the record: mode, source, given values, final values; and the log names the camera's calibration
    (record,) = Layout(Workspace.open(ws)).camera_intrinsics().values()
    assert record["mode"] == "fixed" and record["source"] == cal and record["matched_by"] == "the only calibration"
    assert record["given"]["fx"] == block.camera.fx and record["final"]["fx"] == block.camera.fx
    assert any("interior orientation fixed, OPENCV from" in ln for ln in log.lines), log.lines
    # the camera line states the calibration's focal length, not the EXIF / default prior the group had
    assert any(ln.startswith("camera 1: ") and f"focal {block.camera.fx:.1f} px (fixed, camera.json)" in ln
               for ln in log.lines), log.lines
    assert not any("focal prior" in ln for ln in log.lines), log.lines
    # the georeference asked to refine everything keeps it, and says so once
    gcps = block.gcp_set(block.spread_control(5), noise_px=0.4)
    glog = _Log()
    res = georeference_workspace(ws, GeorefOptions(gcps=gcps, crs=syn.CRS, refine_intrinsics="all"), progress=glog)
    rec, _ = load_georef_model(ws)
    (cam,) = rec.cameras.values()
    assert np.max(np.abs(np.asarray(cam.params) - block.camera.params)) <= 1e-9
    assert len([ln for ln in glog.lines if "calibrated interior orientation fixed" in ln]) == 1, glog.lines
    err = _centre_errors(block, ws)
    rmse_xy, rmse_z = float(np.sqrt(np.mean(np.sum(err[:, :2] ** 2, axis=1)))), float(np.sqrt(np.mean(err[:, 2] ** 2)))
    print(f"\n[fixed] focal {cam.params[0]:.6f} px; camera centres RMSE XY {rmse_xy:.3f} m Z {rmse_z:.3f} m; "
          f"check XY {res.figures['CHECK_RMSE_XY']:.3f} Z {res.figures['CHECK_RMSE_Z']:.3f} m")
    assert rmse_xy <= 1.0 * block.gsd and rmse_z <= 1.0 * block.gsd  # measured 0.050 / 0.016 m, GSD 0.077 m
    # the report's table: fixed, nothing moved
    ctx = SimpleNamespace(d=SimpleNamespace(layout=Layout(Workspace.open(ws)), rec=rec), warnings=[], glance=[])
    html = interior_orientation(ctx)
    assert "camera 1: fixed" in html and not ctx.warnings


def test_a_wrong_start_value_moves_when_estimated(block, images, tmp_path):
    """The same block from a calibration 8 % off, intrinsics estimated: the self-calibration moves the focal
    length back towards the truth (this is what a fixed camera must not do, so the test above can fail)."""
    given = block.camera.fx * 1.08
    cal = write_calibration(tmp_path / "wrong.json", block.camera, focal=given)
    align(images, str(tmp_path / "ws"), _options(calibration=cal, intrinsics="estimated"))
    (cam,) = load_model(str(tmp_path / "ws")).cameras.values()
    print(f"\n[estimated from {given:.1f} px] focal after alignment {cam.params[0]:.3f} px (truth {block.camera.fx})")
    assert abs(cam.params[0] - given) > 0.5 * (given - block.camera.fx)
    assert abs(cam.params[0] - block.camera.fx) < 0.01 * block.camera.fx
    (record,) = Layout(Workspace.open(str(tmp_path / "ws"))).camera_intrinsics().values()
    assert record["mode"] == "estimated" and record["given"]["fx"] == pytest.approx(given)


def _refined_record(cam, sigmas, **changes):
    given = dict(zip(NAMES, cam.with_params(**changes).params))
    return {1: {"camera_id": 1, "mode": "refined", "model": "OPENCV", "given": given, "sigmas": sigmas,
                "source": "camera.json"}}


def test_a_refined_camera_stays_within_its_sigmas_where_the_data_agree(block):
    rec = block.truth_reconstruction()
    sigmas = {"fx": 2.0, "fy": 2.0, "cx": 2.0, "cy": 2.0, "k1": 0.005}
    record = _refined_record(block.camera, sigmas)
    gcps = block.gcp_set(block.spread_control(5), noise_px=0.4)
    result = georeference(rec, gcps, options=GeorefOptions(camera_intrinsics=record))
    assert result.statistics["prior_cameras"] == [1]
    cam = result.reconstruction.cameras[1]
    moved = {n: (float(v) - record[1]["given"][n]) for n, v in zip(NAMES, cam.params)}
    print("\n[refined] moved: " + ", ".join(f"{n} {m:+.4g}" for n, m in moved.items()))
    assert any(abs(m) > 0 for m in moved.values())  # refined, not held
    for n in ("fx", "fy", "cx", "cy", "k1"):
        assert abs(moved[n]) < 3 * sigmas[n], (n, moved[n])
    assert result.rmse(CHECK)["xy"] <= block.gsd
    # the estimated camera of the same call without a record follows refine_intrinsics (off: held as aligned)
    plain = georeference(block.truth_reconstruction(), gcps)
    assert plain.statistics["prior_cameras"] == [] and not plain.refined_intrinsics


def test_the_report_warns_when_a_refined_parameter_moved_beyond_three_sigma(block):
    rec = block.truth_reconstruction(n_points=50)
    record = _refined_record(block.camera, {"fx": 1.0}, fx=block.camera.fx - 10.0)  # the model's is 10 sigma off
    layout = SimpleNamespace(camera_intrinsics=lambda: record)
    ctx = SimpleNamespace(d=SimpleNamespace(layout=layout, rec=rec), warnings=[], glance=[])
    html = interior_orientation(ctx)
    assert "+10.0 σ" in ctx.warnings[0] and "camera 1 fx" in ctx.warnings[0]
    assert "moved (σ)" in html
    record[1]["given"]["fx"] = block.camera.fx - 2.0  # 2 sigma: no warning
    ctx.warnings.clear()
    interior_orientation(ctx)
    assert not ctx.warnings


def test_the_report_reads_like_the_certificate(tmp_path):
    """The report's camera table for a certificate (focal length in mm, pixel size, principal point offset, a
    distortion table: FULL_OPENCV): the parameters in a certificate's order with their names, FULL_OPENCV's k4..k6
    (zero by construction) left out, a line per camera in mm (focal length, principal point from the centre, x right
    y up) and the radial distortion at the corner; an estimated focal length's move also in percent."""
    import re

    import pycolmap

    path = tmp_path / "camera.yaml"
    path.write_text("name: DMC120\nimage_size_px: [640, 1152]\npixel_size_mm: 0.144\nfocal_length_mm: 120.0\n"
                    "principal_point_mm: [0.05, -0.03]\nk1: -0.01\nk2: 0.002\nk3: -0.0003\n")
    infos = [_info("a.tif", width=640, height=1152), _info("b.tif", width=640, height=1152)]
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), NullProgress())
    cam = pycolmap.Camera.create_from_model_name(1, "FULL_OPENCV", 1.0, 640, 1152)
    cam.params = plan["g"].params
    rec = SimpleNamespace(cameras={1: cam})
    groups = [_group(infos)]
    groups[0] = CameraGroup(**{**groups[0].__dict__, "camera_id": 1})
    from core.align.calibrated import intrinsics_record

    (record,) = intrinsics_record(pycolmap, groups, plan, rec)
    assert record["pixel_size_mm"] == 0.144
    layout = SimpleNamespace(camera_intrinsics=lambda: {1: record})
    ctx = SimpleNamespace(d=SimpleNamespace(layout=layout, rec=rec), warnings=[], glance=[])
    html = interior_orientation(ctx)
    labels = re.findall(r"<tr><td>1</td><td>fixed</td><td>([^<]+)</td>", html)
    assert labels == ["focal length fx (px)", "focal length fy (px)", "principal point cx (px)",
                      "principal point cy (px)", "radial k1", "radial k2", "radial k3", "tangential p1",
                      "tangential p2"], labels
    assert ("camera 1 'DMC120' (camera.yaml), fixed; focal length 120.000 mm given, 120.000 mm final; principal "
            "point (+0.050, -0.030) mm given, (+0.050, -0.030) mm final") in html, html
    assert "radial distortion at the image corner -3.66 px given, -3.66 px final" in html
    assert "core.georef.options" not in html and not ctx.warnings
    # the summary's camera table leaves FULL_OPENCV's zero k4..k6 out too
    from core.report.sections.summary import _cameras

    sctx = SimpleNamespace(d=SimpleNamespace(rec=SimpleNamespace(cameras={1: cam}, image=None),
                                             obs=SimpleNamespace(image_ids=[])), unc=None, unc_error="")
    summary = _cameras(sctx)
    assert "<b>k3</b> -0.000300" in summary and "<b>k4</b>" not in summary, summary
    assert "Flying height" not in html  # not georeferenced
    ctx.d.georeferenced = True
    ctx.d.centres = lambda: np.array([[0.0, 0.0, 5000.0], [1.0, 0.0, 5010.0]])
    ctx.d.tie_xyz = lambda: np.array([[0.0, 0.0, 400.0], [0.0, 0.0, 420.0], [0.0, 0.0, 410.0]])
    html = interior_orientation(ctx)
    assert ("Flying height above the ground: 4,595 m (the camera centres' median height less the tie points'); "
            "camera 1: focal length 120.000 mm, photo scale 1:38,292.") in html, html
    # estimated: the focal length moved -1.73 %
    cam.params = [819.0, 819.0] + list(plan["g"].params[2:])
    record["mode"] = "estimated"
    html = interior_orientation(ctx)
    assert "-14.333333 (-1.72 %)" in html and "117.936 mm final" in html, html


def test_a_fixed_camera_is_not_refined_whatever_refine_intrinsics_says(block):
    wrong = block.camera.with_params(fx=block.camera.fx * 1.02, fy=block.camera.fy * 1.02)
    gcps = block.gcp_set(block.spread_control(5), noise_px=0.4)
    record = {1: {"camera_id": 1, "mode": "fixed", "model": "OPENCV", "given": dict(zip(NAMES, wrong.params))}}
    for refine in (True, "all", ("focal",)):
        result = georeference(block.truth_reconstruction(camera=wrong), gcps,
                              options=GeorefOptions(refine_intrinsics=refine, camera_intrinsics=record))
        assert list(result.reconstruction.cameras[1].params) == list(wrong.params)
        assert result.statistics["fixed_cameras"] == [1]
    moved = georeference(block.truth_reconstruction(camera=wrong), gcps, options=GeorefOptions(refine_intrinsics=True))
    assert moved.reconstruction.cameras[1].params[0] != wrong.params[0]  # without the record it is refined


# ------------------------------------------------------------------------------------------------------------
# which camera takes which calibration
# ------------------------------------------------------------------------------------------------------------

def _info(name, model="", width=800, height=600, focal_px=None, source="default"):
    return ImageInfo(name=name, path=name, width=width, height=height, bands=1, dtype="Byte", model=model,
                     focal_px=focal_px or 0.85 * max(width, height), focal_source=source)


def _group(infos, key="g"):
    im = infos[0]
    return CameraGroup(camera_id=1, key=key, make="", model=im.model, width=im.width, height=im.height,
                       focal_px=im.focal_px, focal_source=im.focal_source, images=[i.name for i in infos])


def _read(path):
    from core.io.calibration import read_calibration

    return read_calibration(str(path))


def test_several_calibrations_match_by_pattern_model_and_size_and_scale_to_a_scan(tmp_path):
    import pycolmap

    doc = {"cameras": [
        {"name": "RC30", "image_size_px": [800, 600], "focal_length_px": 650.0, "images": ["strip1_*"]},
        {"name": "DMC", "image_size_px": [800, 600], "focal_length_px": 700.0},
        {"name": "other", "image_size_px": [400, 400], "focal_length_px": 300.0, "adjust": "refined"},
    ]}
    path = tmp_path / "cams.json"
    path.write_text(json.dumps(doc))
    cals = _read(path)
    infos = [_info("strip1_01.tif"), _info("strip1_02.tif"), _info("b.jpg", model="DMC"),
             _info("c.jpg", width=400, height=400), _info("d.jpg", width=1600, height=1600),
             _info("e.jpg", width=640, height=480)]
    groups = [_group(infos[:3], "a"), _group(infos[3:4], "c"), _group(infos[4:5], "d"), _group(infos[5:], "e")]
    log = _Log()
    out, plan = plan_cameras(pycolmap, groups, infos, cals, {}, AlignOptions(), log)
    by_image = {n: plan.get(g.key) for g in out for n in g.images}
    assert by_image["strip1_01.tif"].name == "RC30" and by_image["strip1_01.tif"].mode == "fixed"
    assert by_image["b.jpg"].name == "DMC" and by_image["b.jpg"].matched_by == "the EXIF camera model"
    assert by_image["c.jpg"].name == "other" and by_image["c.jpg"].mode == "refined"  # the file's adjust
    assert by_image["e.jpg"] is None  # no calibration fits: estimated, as today
    assert len(out) == 5 and [g.camera_id for g in out] == [1, 2, 3, 4, 5]  # group a split in two
    # 1600 x 1600 matches no calibration by size; one calibration alone applies to every photo, scaled
    out1, plan1 = plan_cameras(pycolmap, [_group(infos[4:5], "d")], infos[4:5], cals[2:], {}, AlignOptions(), log)
    given = plan1["d"]
    assert given.scaled_from == (400, 400) and given.params[0] == pytest.approx(1200.0)
    assert by_image["d.jpg"] is None
    assert any(ln.startswith("camera 5 (1 image(s), 640 x 480 px)") and "estimated" in ln for ln in log.lines)


def test_a_calibration_that_matches_no_photo_is_refused_and_an_unused_camera_warned(tmp_path):
    """A file given for the block whose camera misses every photo (images patterns that match no name) was
    silently ignored under auto ('no calibration given' in the log, self-calibrated) and under fixed refused as if
    no file had been given; now an error naming the file, the camera, its patterns and the photos.  A camera of a
    several-camera file that no photo takes is a warning."""
    import pycolmap

    path = tmp_path / "camx.json"
    path.write_text(json.dumps({"name": "X", "images": ["X_*.tif"], "image_size_px": [640, 1152],
                                "focal_length_px": 833.3}))
    infos = [_info("D1_01.tif", width=640, height=1152), _info("D1_02.tif", width=640, height=1152)]
    for mode in ("auto", "fixed", "estimated"):
        with pytest.raises(AlignError, match=r"camx\.json: no photo matches camera 'X' \(images X_\*\.tif\)"
                                             r".* 2 photo\(s\): D1_01\.tif, D1_02\.tif; 640 x 1152 px"):
            plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(intrinsics=mode),
                         NullProgress())
    path.write_text(json.dumps({"cameras": [
        {"name": "X", "images": ["X_*.tif"], "image_size_px": [640, 1152], "focal_length_px": 833.3},
        {"name": "DMC", "image_size_px": [640, 1152], "focal_length_px": 833.3}]}))
    log = _Log()
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), log)
    assert plan["g"].name == "DMC"
    assert any("camx.json: no photo matches camera 'X' (images X_*.tif); it is not used" in ln
               for ln in log.lines), log.lines


def test_a_calibration_with_k3_never_frees_the_rational_terms(tmp_path):
    """A calibration with k3 (every certificate's distortion table fits one) is COLMAP's FULL_OPENCV, whose k4..k6
    are zero by construction.  Estimated, the alignment's self-calibration freed them with k1..k3 (4 archive frames:
    k1 = 55, k4 = 55, k2 = -113, k5 = -113): it now starts RADIAL (square pixels, no p1, p2) or OPENCV from the
    calibration, k3 left out and said so;
    fixed and refined keep FULL_OPENCV, and the georeference refines k1..k3, p1, p2 but never k4..k6."""
    import pycolmap

    from core.georef.bundle import _free_intrinsics

    path = tmp_path / "cam.json"
    path.write_text(json.dumps({"name": "DMC", "image_size_px": [640, 1152], "focal_length_px": 833.3,
                                "k1": -0.01, "k2": 0.002, "k3": -0.0003}))
    infos = [_info("a.tif", width=640, height=1152), _info("b.tif", width=640, height=1152)]
    log = _Log()
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(intrinsics="estimated"),
                           log)
    # square pixels, no tangential terms: RADIAL (one focal length; OPENCV's fx, fy came out -1.73 / -2.13 % and the
    # centres 82 m low, RADIAL's f -1.72 % and 73 m on the archive block)
    assert plan["g"].model == "RADIAL" and plan["g"].params == [833.3, 320.0, 576.0, -0.01, 0.002]
    assert any("k3 = -0.0003 of the calibration left out of the self-calibration (RADIAL" in ln for ln in log.lines)
    tangential = tmp_path / "tangential.json"
    tangential.write_text(json.dumps({"name": "DMC", "image_size_px": [640, 1152], "focal_length_px": 833.3,
                                      "k1": -0.01, "k2": 0.002, "k3": -0.0003, "p1": 1e-4}))
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(tangential), {},
                           AlignOptions(intrinsics="estimated"), NullProgress())
    assert plan["g"].model == "OPENCV" and plan["g"].params == [833.3, 833.3, 320.0, 576.0, -0.01, 0.002, 1e-4, 0.0]
    for mode in ("fixed", "refined"):
        _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(intrinsics=mode),
                               NullProgress())
        assert plan["g"].model == "FULL_OPENCV" and plan["g"].params[8] == -0.0003
    given = plan["g"]
    cam = pycolmap.Camera.create_from_model_name(1, "FULL_OPENCV", 833.3, 640, 1152)
    cam.params = given.params
    names = [n.strip() for n in cam.params_info.split(",")]
    images = SimpleNamespace(camera_ids=[1], images_per_cam={1: 4})
    record = {"mode": "refined", "model": "FULL_OPENCV", "given": dict(zip(names, given.params))}
    for mode, expect in (("refined", ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"]),
                         ("estimated", ["fx", "fy", "k1", "k2", "p1", "p2", "k3"])):
        _, free, _, _, _ = _free_intrinsics(SimpleNamespace(cameras={1: cam}), images, ("focal", "extra"), 1,
                                            log.warning, {1: dict(record, mode=mode)})
        assert [names[i] for i in free[0]] == expect, mode


def test_a_focal_length_given_besides_the_calibration_that_disagrees_is_warned(tmp_path):
    """CALIBRATION (120 mm: 833.3 px) with FOCAL_MM 150 mm (1041.7 px): the calibration wins, as before, but no
    longer silently; a focal length within 2 % (or none given) says nothing."""
    import pycolmap

    path = tmp_path / "cam.json"
    path.write_text(json.dumps({"name": "DMC", "image_size_px": [640, 1152], "focal_length_px": 833.3}))
    for focal, warned in ((1041.7, True), (840.0, False)):
        infos = [_info(n, width=640, height=1152, focal_px=focal, source="manual") for n in ("a.tif", "b.tif")]
        log = _Log()
        _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), log)
        assert plan["g"].params[0] == 833.3
        hits = [ln for ln in log.lines if "focal length given (FOCAL_MM / SENSOR_WIDTH_MM) 1041.7 px (+25.0 %)" in ln]
        assert bool(hits) == warned, log.lines
    # EXIF (a rounded 35 mm equivalent as a rule): 5 % off says nothing, 25 % does
    for focal, warned in ((875.0, False), (1041.7, True)):
        infos = [_info(n, width=640, height=1152, focal_px=focal, source="exif35") for n in ("a.tif", "b.tif")]
        log = _Log()
        plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), log)
        assert any("the photos' EXIF focal length" in ln for ln in log.lines) == warned, log.lines


def test_a_certificate_given_for_prepared_film_scans_takes_the_prepared_frame(tmp_path):
    """A film certificate (image_size_px of the raw 1300 px scans at 0.2 mm, focal 152.82 mm) given with the scans
    Prepare images cut to the 1240 px fiducial frame at 0.200029 mm: the camera is the certificate's millimetres
    in the prepared frame (763.99 px, principal point at the centre), as docs/calibration.md says; it was scaled
    as if the scan had been resampled to 1240 px (728.8 px: -4.6 %, held fixed; the reprojection error 0.251 px
    against 0.250 px did not show it).  Without millimetres the pixel values are scaled as before."""
    import pycolmap

    path = tmp_path / "film.yaml"
    path.write_text("name: RC-152\nimage_size_px: [1300, 1300]\npixel_size_mm: 0.2\nfocal_length_mm: 152.82\n"
                    "principal_point_mm: [0.012, -0.008]\nk1: -0.001\n")
    scans = tmp_path / "scans.json"
    scans.write_text(json.dumps({"interior_orientation": {
        "frame_units": "mm", "calibrated_fiducials": True, "pixel_size": 0.2000289800162121, "width": 1240,
        "height": 1240, "principal_point_px": [620.0, 620.0], "focal_length_mm": None, "focal_px": None},
        "scans": [{"prepared_name": "F1_01.tif"}, {"prepared_name": "F1_02.tif"}]}))
    infos = [_info(n, width=1240, height=1240, focal_px=763.99, source="exif35") for n in ("F1_01.tif", "F1_02.tif")]
    log = _Log()
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), scan_interior(str(scans), infos),
                           AlignOptions(), log)
    given = plan["g"]
    assert given.params[0] == pytest.approx(152.82 / 0.2000289800162121) and given.params[1:3] == [620.0, 620.0]
    assert given.params[3] == -0.001 and given.scaled_from is None and given.mode == "fixed"
    assert "in the frame Prepare images restituted (0.200029 mm pixels: 152.82 mm = 763.99 px)" in given.matched_by
    assert not [ln for ln in log.lines if "focal length of" in ln], log.lines  # agrees with the prepared focal
    # a calibration in pixels only (no mm) is scaled as before
    path.write_text("name: px\nimage_size_px: [1300, 1300]\nfocal_length_px: 764.1\n")
    _, plan = plan_cameras(pycolmap, [_group(infos)], infos, _read(path), scan_interior(str(scans), infos),
                           AlignOptions(), NullProgress())
    assert plan["g"].scaled_from == (1300, 1300) and plan["g"].params[0] == pytest.approx(764.1 * 1240 / 1300)


def test_no_reconstruction_with_a_held_camera_points_at_the_calibration():
    """A 120 mm frame held at a 12 mm calibration (83.3 px instead of 833.3) leaves the mapper no initial pair:
    the error said only 'baseline too short ... add photos taken from other positions'; it now names the held
    camera and its file.  Without a held camera the message is unchanged."""
    from core.align.calibrated import GivenCamera
    from core.align.diagnosis import no_reconstruction_error as _no_reconstruction

    held = {1: GivenCamera("fixed", "/x/focal12.yaml", "DMC120", "PINHOLE", [83.33, 83.33, 320.0, 576.0])}
    msg = str(_no_reconstruction({"a.tif": 3, "b.tif": 3}, 4, 5, held))
    assert "add photos taken from other positions. The interior orientation was held as given (camera 1: focal " \
           "83.3 px from focal12.yaml)" in msg and "Interior orientation 'estimated'" in msg
    assert "held as given" not in str(_no_reconstruction({"a.tif": 3, "b.tif": 3}, 4, 5))


def test_focal_length_and_film_scans_as_given_interior_orientations(tmp_path):
    import pycolmap

    manual = [_info("a.tif", focal_px=1000.0, source="manual"), _info("b.tif", focal_px=1000.0, source="manual")]
    g = _group(manual)
    _, plan = plan_cameras(pycolmap, [g], manual, [], {}, AlignOptions(), NullProgress())
    assert plan == {}  # auto: FOCAL_MM / SENSOR_WIDTH_MM work as before
    _, plan = plan_cameras(pycolmap, [g], manual, [], {}, AlignOptions(intrinsics="fixed"), NullProgress())
    assert plan["g"].mode == "fixed" and plan["g"].params == [1000.0, 400.0, 300.0, 0.0]
    with pytest.raises(AlignError, match="needs a given interior orientation"):
        plan_cameras(pycolmap, [_group([_info("c.jpg")])], [_info("c.jpg")], [], {}, AlignOptions(intrinsics="refined"),
                     NullProgress())
    # Prepare images' restituted film scans: fixed under auto
    scans = tmp_path / "scans.json"
    scans.write_text(json.dumps({"interior_orientation": {"focal_px": 1234.5, "width": 800, "height": 600,
                                                          "principal_point_px": [400.0, 300.0]},
                                 "scans": [{"prepared_name": "a.tif"}, {"prepared_name": "b.tif"}]}))
    io = scan_interior(str(scans), manual)
    _, plan = plan_cameras(pycolmap, [g], manual, [], io, AlignOptions(), NullProgress())
    assert plan["g"].mode == "fixed" and plan["g"].source == "scans.json" and plan["g"].params[0] == 1234.5


# ------------------------------------------------------------------------------------------------------------
# bad input: before any work
# ------------------------------------------------------------------------------------------------------------

def test_a_bad_calibration_file_or_choice_fails_before_feature_extraction(images, tmp_path):
    bad = tmp_path / "camera.json"
    bad.write_text('{"name": "x", "image_size_px": [800, 600],\n "focal_length_px": -5}\n')
    ws = tmp_path / "ws"
    with pytest.raises(ArchaeoOrthoError) as e:
        align(images, str(ws), _options(calibration=str(bad)))
    assert "camera.json" in str(e.value) and "line 2" in str(e.value) and "focal_length_px" in str(e.value)
    assert not ws.exists()  # nothing done: no workspace, no database
    with pytest.raises(AlignError, match="calibration file .*missing.json does not exist"):
        align(images, str(ws), _options(calibration=str(tmp_path / "missing.json")))
    with pytest.raises(AlignError, match="unknown intrinsics choice 'fixd'"):
        align(images, str(ws), _options(intrinsics="fixd"))
    assert not ws.exists()
    # the pipeline checks it before its first stage (here the prepare stage of sky masks)
    from core.pipeline import Control, PipelineOptions, run_pipeline

    with pytest.raises(ArchaeoOrthoError, match="camera.json, line 2"):
        run_pipeline(images, str(ws), PipelineOptions(align=_options(calibration=str(bad)), sky_masks=True),
                     Control(use_exif_gps=True))
    assert not ws.exists()


# ------------------------------------------------------------------------------------------------------------
# Processing
# ------------------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def align_algorithm(plugin):
    from qgis.core import QgsApplication

    return QgsApplication.processingRegistry().algorithmById("archaeoortho:alignimages").create()


def _run(alg, parameters):
    from qgis.core import QgsProcessingContext, QgsProcessingFeedback

    context, feedback = QgsProcessingContext(), QgsProcessingFeedback()
    ok, why = alg.checkParameterValues(parameters, context)
    if not ok:
        raise ValueError(why)
    return alg.processAlgorithm(parameters, context, feedback)


def test_align_images_with_a_calibration_for_one_strip_holds_that_camera(align_algorithm, block, images, tmp_path):
    """Processing's Align images with CALIBRATION for the photos of strip 1 only: they become a camera held at
    exactly the given values, strip 2 a camera self-calibrated as today (mixed cameras: the mapping refines both,
    the held one is set back and kept constant in the final adjustment); the record says which is which."""
    cal = write_calibration(tmp_path / "strip1.json", block.camera, images=["S1_*"])
    out = _run(align_algorithm, {"IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "CALIBRATION": cal,
                                 "PAIRING": 1, "MAX_FEATURES": 2048})
    assert out["REGISTERED_IMAGES"] == len(block.shots)
    records = Layout(Workspace.open(str(tmp_path / "ws"))).camera_intrinsics()
    modes = {r["mode"]: r for r in records.values()}
    assert set(modes) == {"fixed", "estimated"}
    rec = load_model(str(tmp_path / "ws"))
    held = rec.cameras[modes["fixed"]["camera_id"]]
    assert np.max(np.abs(np.asarray(held.params) - block.camera.params)) <= 1e-9
    other = rec.cameras[modes["estimated"]["camera_id"]]
    assert other.model.name != "OPENCV" or list(other.params) != list(held.params)
    print(f"\n[mixed] held {held.params[0]:.6f} px; strip 2 self-calibrated {other.model.name} {other.params[0]:.2f} px")


def test_align_images_refuses_a_mistyped_interior_orientation_and_a_bad_file(align_algorithm, images, tmp_path):
    from qgis.core import QgsProcessingException

    with pytest.raises(ValueError, match="INTRINSICS|Interior orientation"):
        _run(align_algorithm, {"IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "INTRINSICS": "fixd"})
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nimage_size_px: [800, 600]\nfocal_length_px: none\n")
    with pytest.raises(QgsProcessingException, match="bad.yaml"):
        _run(align_algorithm, {"IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "CALIBRATION": str(bad)})
    assert not (tmp_path / "ws").exists()
    assert align_algorithm.parameterDefinition("INTRINSICS").options() == ["auto", "fixed", "refined", "estimated"]
    # a valid choice reaches the core: 'fixed' with nothing given is refused before the features
    with pytest.raises(QgsProcessingException, match="intrinsics 'fixed' needs a given interior orientation"):
        _run(align_algorithm, {"IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "INTRINSICS": 1})
    assert not (tmp_path / "ws" / "sfm").exists()


def test_run_pipeline_passes_the_calibration_through_its_align_options(plugin, tmp_path, monkeypatch):
    from archaeoortho.core import pipeline
    from qgis.core import QgsApplication, QgsProcessingException

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:runpipeline").create()
    seen = {}

    def fake_run_pipeline(images, workspace, options=None, control=None, progress=None):
        seen["align"] = options.align
        raise RuntimeError("stop")

    monkeypatch.setattr(pipeline, "run_pipeline", fake_run_pipeline)
    cal = tmp_path / "camera.json"
    cal.write_text("{}")
    (tmp_path / "images").mkdir()
    with pytest.raises(QgsProcessingException):
        _run(alg, {"IMAGES": str(tmp_path / "images"), "WORKSPACE": str(tmp_path / "ws"), "USE_EXIF_GPS": True,
                   "CALIBRATION": str(cal), "INTRINSICS": 2})
    assert seen["align"].calibration == str(cal) and seen["align"].intrinsics == "refined"


# ------------------------------------------------------------------------------------------------------------
# the issue's case: four frames of a 120 mm digital metric camera at 5000 m (tests/archive_scene.py)
# ------------------------------------------------------------------------------------------------------------

def _archive_gcps(block):
    from core.io.gcp import CONTROL, GCPSet, GroundPoint, Observation
    from tests import archive_scene as arch

    pts = []
    for p in block.points:
        obs = [Observation(k, float(v[0]), float(v[1])) for k, v in sorted(p.noisy_observations.items())]
        pts.append(GroundPoint(p.name, *(float(v) for v in p.xyz), 0.02, 0.05,
                               CONTROL if p.role == "control" else CHECK, obs))
    return GCPSet(arch.ARCHIVE_PROJ, pts)


def test_four_archive_frames_keep_their_calibrated_focal_length_and_their_height(tmp_path):
    """Four 640 x 1152 px frames of a 120 mm lens (833.33 px) from about 4600 m above the ground: self-calibrated
    from FOCAL_MM + SENSOR_WIDTH_MM (today's behaviour) the focal length drifts (measured -1.76 %, 818.65 px) and
    the georeferenced camera centres come out 80 m low; with the calibration held fixed they stay within a GSD
    (measured 1.42 m Z, 5.0 m XY RMS at a 5.5 m GSD)."""
    from tests import archive_scene as arch

    block = arch.archive_block("digital", 4, seed=2, reference=False,  # a cache of its own (no race with others')
                               out_dir=os.path.join(ROOT, "build", "test-cache", f"calibrated-{arch.VERSION}-digital4"))
    cam = block.camera
    cal = tmp_path / "camera.json"
    cal.write_text(json.dumps({"name": "120 mm", "image_size_px": list(cam.size_px), "focal_length_mm": cam.focal_mm,
                               "pixel_size_mm": cam.pixel_mm, "principal_point_mm": list(cam.ppa_mm)}))
    given = cam.focal_mm / cam.pixel_mm
    runs = {"fixed": dict(calibration=str(cal)),
            "estimated": dict(focal_mm=cam.focal_mm, sensor_width_mm=2 * cam.half_mm[1])}
    out = {}
    for label, kw in runs.items():
        ws = str(tmp_path / label)
        align(block.paths["images"], ws, _options(**kw))
        georeference_workspace(ws, GeorefOptions(gcps=_archive_gcps(block), crs=arch.ARCHIVE_PROJ))
        rec, transform = load_georef_model(ws)
        offset = transform.offset
        err = np.array([np.asarray(im.projection_center()) + offset - block.frame(im.name).centre_world
                        for im in rec.images.values() if im.has_pose])
        (camera,) = rec.cameras.values()
        out[label] = (float(camera.params[0]), float(np.sqrt(np.mean(err[:, 2] ** 2))), len(err))
        print(f"\n[archive, {label}] focal {camera.params[0]:.3f} px (given {given:.3f}), camera centres RMSE Z "
              f"{out[label][1]:.2f} m, XY {np.sqrt(np.mean(np.sum(err[:, :2] ** 2, axis=1))):.2f} m (GSD {block.gsd:.2f})")
    assert out["fixed"][2] == out["estimated"][2] == 4
    assert abs(out["fixed"][0] - given) <= 1e-9
    assert out["fixed"][1] <= block.gsd
    assert abs(out["estimated"][0] - given) > 1.0  # what the fixed camera is kept from (this test can fail)
    assert out["estimated"][1] > 3 * out["fixed"][1]


@pytest.mark.slow
def test_film_scans_restituted_by_prepare_images_keep_their_interior_orientation(tmp_path):
    """Four 152.82 mm film frames scanned with skew and film affinity (tests/archive_scene.py), restituted by
    Prepare images with the calibrated fiducial coordinates and focal length: under 'auto' the alignment holds
    the restituted interior orientation (scans.json: 763.99 px, the principal point at the frame's centre).
    Measured: camera centres 3.5 m XY / 2.3 m Z RMS; self-calibrated from the same start ('estimated') the focal
    drifts to 813.7 px (+6.5 %) and the centres come out 43 m / 296 m off."""
    from core.prepare.options import PrepareOptions, ScanOptions
    from core.prepare.stage import prepare_images_workspace
    from tests import archive_scene as arch

    block = arch.archive_block("film", 4, seed=1, reference=False,
                               out_dir=os.path.join(ROOT, "build", "test-cache", f"calibrated-{arch.VERSION}-film4"))
    cam = block.camera
    fiducials = "".join(f"{k} {x} {y}\n" for k, x, y in cam.fiducials_mm) + f"PP {cam.ppa_mm[0]} {cam.ppa_mm[1]}\n"
    ws = str(tmp_path / "ws")
    prepared = prepare_images_workspace(block.paths["images"], ws, options=PrepareOptions(
        scanned_film=True, scan=ScanOptions(fiducial_coordinates=fiducials, focal_length_mm=cam.focal_mm)))
    log = _Log()
    align(prepared.prepared_dir, ws, _options(), log)
    scans = json.load(open(Layout(Workspace.open(ws)).scans_json))
    io = scans["interior_orientation"]
    (record,) = Layout(Workspace.open(ws)).camera_intrinsics().values()
    assert record["mode"] == "fixed" and record["source"] == "scans.json"
    (camera,) = load_model(ws).cameras.values()
    assert abs(camera.params[0] - io["focal_px"]) <= 1e-9
    assert list(camera.params[1:3]) == io["principal_point_px"]
    # the control's pixels are in the scans: through each scan's affine into the prepared frame
    from core.io.gcp import CONTROL, GCPSet, GroundPoint, Observation

    by_scan = {s["name"]: s for s in scans["scans"]}
    pts = []
    for p in block.points:
        obs = []
        for img, px in sorted(p.noisy_observations.items()):
            a = np.vstack([np.array(by_scan[img]["affine"]), [0.0, 0.0, 1.0]])  # frame mm -> scan px
            x, y = np.linalg.solve(a, [px[0], px[1], 1.0])[:2] / io["pixel_size"]
            obs.append(Observation(by_scan[img]["prepared_name"], float(x + io["width"] / 2.0),
                                   float(io["height"] / 2.0 - y)))
        pts.append(GroundPoint(p.name, *(float(v) for v in p.xyz), 0.02, 0.05,
                               CONTROL if p.role == "control" else CHECK, obs))
    georeference_workspace(ws, GeorefOptions(gcps=GCPSet(arch.ARCHIVE_PROJ, pts), crs=arch.ARCHIVE_PROJ,
                                         refine_intrinsics=True))
    rec, transform = load_georef_model(ws)
    (camera,) = rec.cameras.values()
    assert abs(camera.params[0] - io["focal_px"]) <= 1e-9
    offset = transform.offset
    original = {s["prepared_name"]: s["name"] for s in scans["scans"]}
    err = np.array([np.asarray(im.projection_center()) + offset - block.frame(original[im.name]).centre_world
                    for im in rec.images.values() if im.has_pose])
    rmse_xy, rmse_z = np.sqrt(np.mean(np.sum(err[:, :2] ** 2, axis=1))), np.sqrt(np.mean(err[:, 2] ** 2))
    print(f"\n[film, scans.json fixed] focal {camera.params[0]:.3f} px; centres RMSE XY {rmse_xy:.2f} m, Z {rmse_z:.2f} m "
          f"(GSD {block.gsd:.2f} m)")
    assert len(err) == 4 and rmse_xy <= block.gsd and rmse_z <= block.gsd


def test_the_automatic_control_keeps_a_fixed_camera(tmp_path, epochs):  # noqa: F811 - the fixture imported above
    """The automatic control refines focal length and distortion by default (AutoControlOptions.refine_intrinsics);
    a camera the alignment recorded as fixed comes out of it with exactly its values (the same run without the
    record moves them: the test can fail)."""
    from core.georef.autocontrol.options import AutoControlOptions
    from core.georef.autocontrol.stage import autocontrol_workspace
    from tests.workspaces import synthetic_workspace

    block, photos, ortho, dsm = epochs
    options = AutoControlOptions(n_features=6000, max_candidates=60)  # refine_intrinsics: its default (True)
    assert options.refine_intrinsics
    record = {"camera_id": 1, "mode": "fixed", "model": "OPENCV", "source": "camera.json",
              "given": dict(zip(NAMES, block.camera.params))}
    params = {}
    for label, alignment in (("fixed", {"intrinsics": [record]}), ("estimated", None)):
        ws = synthetic_workspace(str(tmp_path / label), block, block.truth_reconstruction(seed=5), photos=photos,
                                 alignment=alignment)
        cams, _ = block.camera_positions(sigma=3.0)
        autocontrol_workspace(ws, AutoControlOptions.of(options, reference_ortho=ortho, reference_dsm=dsm,
                                                        prior="gps", camera_positions=cams))
        (cam,) = Layout(Workspace.open(ws)).load_georef_model()[0].cameras.values()
        params[label] = np.asarray(cam.params, dtype=float)
    assert np.array_equal(params["fixed"], np.asarray(block.camera.params, dtype=float))
    assert not np.array_equal(params["estimated"], np.asarray(block.camera.params, dtype=float))


# ------------------------------------------------------------------------------------------------------------
# issue 47: a given focal length far from the photos' EXIF, a calibration of two cameras that fit, the log line
# ------------------------------------------------------------------------------------------------------------

def _drone(name, focal_px, source, focal_mm=3.61, focal_35mm=20.0):
    """A DJI FC300X photo as the demo's (1200 x 900 px, EXIF 3.61 mm, 20 mm in 35 mm film)."""
    return ImageInfo(name=name, path=name, width=1200, height=900, bands=3, dtype="Byte", make="DJI", model="FC300X",
                     focal_mm=focal_mm, focal_35mm=focal_35mm, focal_px=focal_px, focal_source=source)


def test_a_focal_length_far_from_the_exif_one_is_refused_naming_its_35_mm_equivalent():
    """FOCAL_MM=20 SENSOR_WIDTH_MM=6.17 INTRINSICS=fixed on photos whose EXIF says 3.61 mm (20 is the 35 mm
    equivalent) was held fixed, the cameras 16 m off, exit 0; now refused before the alignment, naming the EXIF
    values and the 35 mm equivalent.  The right values pass; a wrong sensor width is named; without EXIF a focal
    length of no camera's field of view is refused."""
    import pycolmap

    def plan(focal_mm=None, sensor=None, focal_px=None, exif=True, intrinsics="fixed"):
        px = focal_px or focal_mm / sensor * 1200.0
        kw = {} if exif else dict(focal_mm=None, focal_35mm=None)
        infos = [_drone(n, px, "manual", **kw) for n in ("a.jpg", "b.jpg")]
        opts = AlignOptions(focal_mm=focal_mm, sensor_width_mm=sensor, focal_px=focal_px, intrinsics=intrinsics)
        return plan_cameras(pycolmap, [_group(infos)], infos, [], {}, opts, NullProgress())

    for mode in ("fixed", "auto"):
        with pytest.raises(AlignError, match=r"FOCAL_MM 20 mm .*SENSOR_WIDTH_MM 6\.17 mm.* 3890 px.*5\.61 times .*"
                                             r"EXIF focal length of a\.jpg \(3\.61 mm; 693 px from its 35 mm "
                                             r"equivalent 20 mm; camera DJI FC300X\).*20 mm is the photos' 35 mm equivalent focal "
                                             r"length.*FOCAL_MM=3\.61"):
            plan(20.0, 6.17, intrinsics=mode)
    _, given = plan(3.61, 6.17)  # the real focal length: held
    assert given["g"].params[0] == pytest.approx(702.1, abs=0.1)
    with pytest.raises(AlignError, match=r"FOCAL_MM 3\.61 mm agrees with the EXIF.*SENSOR_WIDTH_MM 36 mm .*sensor "
                                         r"about 6\.25 mm"):
        plan(3.61, 36.0)
    with pytest.raises(AlignError, match=r"focal length of 0\.7 px on 1200 x 900 px images .*field of view"):
        plan(focal_px=0.7, exif=False)
    plan(focal_px=700.0, exif=False)


def test_an_orthority_focal_in_mm_without_sensor_size_is_refused_against_the_exif(tmp_path):
    """Orthority's focal_len 3.61 (mm) without sensor_size reads as normalised by the image width: 4,332 px on the
    1200 px wide photos, only warned; now refused against the photos' EXIF (693 px), naming the file, the value
    and sensor_size."""
    import pycolmap

    path = tmp_path / "int_param.yaml"
    path.write_text("FC300X:\n  type: pinhole\n  im_size: [1200, 900]\n  focal_len: 3.61\n")
    infos = [_drone(n, 693.3, "exif35") for n in ("a.jpg", "b.jpg")]
    with pytest.raises(AlignError, match=r"int_param\.yaml: camera 'FC300X' gives a focal length of 4332\.0 px, "
                                         r"6\.25 times the photos' EXIF focal length \(693\.3 px.*3\.61 mm\).*"
                                         r"the photos' EXIF focal length in mm.*sensor_size"):
        plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), NullProgress())


def test_a_colmap_file_with_two_cameras_of_the_photos_size_names_the_ambiguity(tmp_path):
    """Two cameras of the photos' size in a COLMAP cameras.txt: 'no photo matches any of its cameras'; now the
    message names both cameras and how to choose."""
    import pycolmap

    path = tmp_path / "cameras.txt"
    path.write_text("1 PINHOLE 800 600 650 650 400 300\n2 PINHOLE 800 600 700 700 400 300\n")
    infos = [_info("a.tif"), _info("b.tif")]
    with pytest.raises(AlignError, match=r"cameras\.txt: 2 of its cameras fit the photo a\.tif \(800 x 600 px\): "
                                         r"camera '1'.* and camera '2'.*which one .*delete the others"):
        plan_cameras(pycolmap, [_group(infos)], infos, _read(path), {}, AlignOptions(), NullProgress())


def test_the_log_names_a_focal_length_given_as_the_options_that_gave_it():
    """The camera line read '(fixed,  SENSOR_WIDTH_MM)': the basename of 'FOCAL_MM / SENSOR_WIDTH_MM'."""
    from core.align.calibrated import FOCAL_SOURCE, GivenCamera
    from core.align.diagnosis import no_reconstruction_error as _no_reconstruction
    from core.align.inputs import Photos

    infos = [_info("a.tif", focal_px=1000.0, source="manual"), _info("b.tif", focal_px=1000.0, source="manual")]
    given = GivenCamera("fixed", FOCAL_SOURCE, "focal length given", "SIMPLE_RADIAL", [1000.0, 400.0, 300.0, 0.0])
    photos = Photos("/x", infos, [], [_group(infos)], {}, 0.0, {"g": given}, {})
    log = _Log()
    photos.log_cameras(log)
    assert any("focal 1000.0 px (fixed, FOCAL_MM / SENSOR_WIDTH_MM)" in ln for ln in log.lines), log.lines
    assert "focal 1000.0 px from FOCAL_MM / SENSOR_WIDTH_MM" in str(_no_reconstruction({"a.tif": 3}, 2, 1,
                                                                                       {1: given}))
