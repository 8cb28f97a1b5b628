"""Automatic control of single photos (issue 16 item 3): one photo, no GCP, a rough location -> matches against a
reference orthophoto + DSM -> space resection -> a true orthophoto on the reference DSM.

The reference is epoch 1 of the synthetic scene rendered from its truth (orthophoto 0.1 m, DSM 0.25 m, EPSG:32633,
as tests/test_autocontrol.py writes it); the photos are of epoch 2 (new crop marks, the car moved, a new building,
another sun): one oblique 45 degrees off nadir (30 m above the ground, 42 m from the ground it looks at) and one
vertical with an arbitrary heading (50 m), both rendered once and cached under build/test-cache.  The rough
location is 20 m off the ground the photo shows; heading and focal length are unknown (the photos have no EXIF).

Tolerances: the camera centre within 0.5 m (5 x the reference's 0.1 m).  The ground matches are good to ~0.3
reference pixels, but the focal length is estimated, and focal length and distance trade off along the viewing
axis: 1 % of focal length (what the estimate is off on these photos, whose k2 is not modelled) is 0.4 m at 42 m.  What the user needs,
the orthophoto's ground marks (the true ground points, compared with the truth's texture by phase correlation),
must sit within 1.5 output cells (RMSE).
"""
import json
import math
import os
import subprocess
import time

import cv2
import numpy as np
import pytest
from osgeo import gdal

from core.georef.autocontrol.single import PhotoControlOptions
from core.ortho.options import OrthoError, OrthoOptions, SingleImageOptions
from core.ortho.single import orthorectify_image
from tests import synthetic as syn
from tests.test_autocontrol import write_reference

HERE = os.path.dirname(os.path.abspath(__file__))
CACHE = os.path.join(os.path.dirname(HERE), "build", "test-cache", "single-autocontrol-v1")
BLOCK = dict(seed=1, n_strips=2, per_strip=5)
REF_GSD = 0.1
OUT_GSD = 0.1
CAMERA = syn.DEFAULT_CAMERA
FAST = PhotoControlOptions(passes=1, n_features=6000, max_points=150)


def _shots(scene):
    """{name: (shot, ground point it looks at)}: the oblique (45 deg off nadir, azimuth 200 deg) and the vertical
    (heading 137 deg)."""
    t = np.array([5.0, 3.0, float(scene.ground_at(5.0, 3.0))])
    az, alt = math.radians(200.0), 30.0
    c = t + np.array([alt * math.cos(az), alt * math.sin(az), alt])
    oblique = syn.Shot("oblique.jpg", syn.look_at(c, t, np.array([0.0, 0.0, 1.0])), c, "oblique")
    g = np.array([-12.0, 6.0, float(scene.ground_at(-12.0, 6.0))])
    c = g + np.array([0.0, 0.0, 50.0])
    h = math.radians(137.0)
    vertical = syn.Shot("vertical.jpg", syn.look_at(c, g, np.array([math.cos(h), math.sin(h), 0.0])), c)
    return {"oblique.jpg": (oblique, t), "vertical.jpg": (vertical, g)}


@pytest.fixture(scope="module")
def setup():
    """(epoch-2 scene, shots, photo paths, reference orthophoto, reference DSM), rendered once."""
    scene = syn.vertical_block(epoch=2, **BLOCK).scene
    shots = _shots(scene)
    done = os.path.join(CACHE, "done")
    if not os.path.isfile(done):
        os.makedirs(CACHE, exist_ok=True)
        for name, (shot, _) in shots.items():
            if shot.kind == "oblique":
                img = cv2.cvtColor(syn.render_oblique_image(scene, CAMERA, shot, supersample=1, seed=7),
                                   cv2.COLOR_RGB2BGR)
            else:
                img = syn.render_image(scene, CAMERA, shot, supersample=1, seed=8)
            cv2.imwrite(os.path.join(CACHE, name), img, [cv2.IMWRITE_JPEG_QUALITY, 95])
        write_reference(syn.vertical_block(epoch=1, **BLOCK).scene, CACHE)
        open(done, "w").close()
    photos = {n: os.path.join(CACHE, n) for n in shots}
    return scene, shots, photos, os.path.join(CACHE, "ref_ortho.tif"), os.path.join(CACHE, "ref_dsm.tif")


def _rough_location(ground, bearing_deg):
    """World (x, y) 20 m from the ground point the photo shows."""
    b = math.radians(bearing_deg)
    return (float(ground[0] + 20.0 * math.cos(b) + syn.ORIGIN[0]), float(ground[1] + 20.0 * math.sin(b) + syn.ORIGIN[1]))


def _mark_shifts(scene, path, shot, n=32):
    """(dx, dy) in cells of the orthophoto at ground points (the 12 block GCP marks and a grid of ground points
    away from buildings and the ditch) against the truth's texture, where the orthophoto has data."""
    ds = gdal.Open(path)
    arr = ds.ReadAsArray().astype(np.float32)
    gt = ds.GetGeoTransform()
    grey, alpha = arr[0], arr[-1]
    tex = scene.texture_raster()
    xs, ys = np.meshgrid(np.arange(-60.0, 61.0, 6.0), np.arange(-50.0, 51.0, 6.0))
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    pts = pts[~scene.near_feature(pts[:, 0], pts[:, 1], 3.0)]
    out = []
    for x, y in pts:
        c = int((x + syn.ORIGIN[0] - gt[0]) / gt[1]) - n // 2
        r = int((y + syn.ORIGIN[1] - gt[3]) / gt[5]) - n // 2
        if r < 0 or c < 0 or r + n > grey.shape[0] or c + n > grey.shape[1] or (alpha[r:r + n, c:c + n] == 0).any():
            continue
        gx = gt[0] + (c + np.arange(n) + 0.5) * gt[1] - syn.ORIGIN[0]
        gy = gt[3] + (r + np.arange(n) + 0.5) * gt[5] - syn.ORIGIN[1]
        mx, my = scene.raster_coords(*np.meshgrid(gx, gy), scene.texture_res)
        truth = syn._sample(tex, mx, my)
        win = cv2.createHanningWindow((n, n), cv2.CV_64F)
        (dx, dy), resp = cv2.phaseCorrelate(truth.astype(np.float64), grey[r:r + n, c:c + n].astype(np.float64), win)
        if resp > 0.2:
            out.append((dx, dy))
    return np.array(out).reshape(-1, 2)


@pytest.mark.parametrize("name", ["oblique.jpg", "vertical.jpg"])
def test_single_photo_is_oriented_and_orthorectified_by_automatic_control(setup, tmp_path, name):
    """The oblique with no focal length (estimated); the vertical with its focal length (as from EXIF: over
    gentle relief a vertical photo cannot tell its focal length from its height)."""
    scene, shots, photos, ortho, dsm = setup
    shot, ground = shots[name]
    focal = CAMERA.fx if shot.kind == "vertical" else None
    out = str(tmp_path / "ortho.tif")
    res_path = str(tmp_path / "res.gpkg")
    t0 = time.time()
    options = SingleImageOptions(photos[name], out, dsm, reference_ortho=ortho, location=_rough_location(ground, 60.0),
                                 search_radius=30.0, focal_px=focal, ortho=OrthoOptions(resolution=OUT_GSD),
                                 residuals_path=res_path, control=FAST)
    r = orthorectify_image(options)
    assert options.camera is None and options.crs is None  # what the automatic control found went into a copy
    seconds = time.time() - t0
    centre = np.array([r.orientation[k] for k in "xyz"])
    err = float(np.linalg.norm(centre - (shot.centre + syn.ORIGIN)))
    print(f"\n{name}: {r.auto_control}; centre error {err:.3f} m, focal {r.orientation['focal_px']:.1f} px (truth "
          f"{CAMERA.fx}), {seconds:.1f} s")
    assert r.source == "resection" and r.crs == syn.CRS
    assert r.auto_control["kept"] >= 30 and r.rmse_px < 1.0
    assert err <= 0.5
    assert abs(r.orientation["focal_px"] - CAMERA.fx) < 0.02 * CAMERA.fx
    assert any("automatic GCPs" in m for m in r.log_lines)
    layer_ds = gdal.OpenEx(res_path)  # kept alive while its layer is read
    feats = list(layer_ds.GetLayer(0))
    assert len(feats) == r.auto_control["kept"] and all(f.GetField("name").startswith("auto_") for f in feats)
    assert all(f.GetField("image") == name for f in feats)
    shifts = _mark_shifts(scene, out, shot)
    rmse = float(np.sqrt(np.mean(np.sum(shifts ** 2, axis=1))))
    print(f"{name}: orthophoto ground marks: {len(shifts)}, RMSE {rmse:.2f} cells of {OUT_GSD} m, max "
          f"{np.max(np.hypot(*shifts.T)):.2f}")
    assert len(shifts) >= 8
    assert rmse <= 1.5


def test_single_image_options_refuse_a_bad_combination_when_made(tmp_path):
    """The checks that need no file run when the options are made (Processing refuses before any work)."""
    photo, out = str(tmp_path / "p.jpg"), str(tmp_path / "o.tif")
    with pytest.raises(OrthoError, match="unknown MODE 'oblique'"):
        SingleImageOptions(photo, out, "dsm.tif", orientation={}, mode="oblique")
    with pytest.raises(OrthoError, match=r"GCPS\), its orientation \(ORIENTATION\), or a reference orthophoto"):
        SingleImageOptions(photo, out, "dsm.tif")
    with pytest.raises(OrthoError, match="ref.tif needs the reference DSM too"):
        SingleImageOptions(photo, out, None, reference_ortho="ref.tif")
    with pytest.raises(OrthoError, match="planar rectification needs at least 4 ground control points"):
        SingleImageOptions(photo, out, "dsm.tif", orientation={}, mode="planar")
    with pytest.raises(OrthoError, match="RESOLUTION must be 0"):
        SingleImageOptions(photo, out, "dsm.tif", orientation={}, ortho=OrthoOptions(resolution=-1.0))
    assert SingleImageOptions(photo, out, None, gcps="g.csv", mode="PLANAR").mode == "planar"


def test_a_location_far_off_is_refused_naming_the_photo_and_the_reference(setup, tmp_path):
    _, shots, photos, ortho, dsm = setup
    far = _rough_location(shots["oblique.jpg"][1], 0.0)
    far = (far[0] + 5000.0, far[1])
    with pytest.raises(OrthoError, match="oblique.jpg") as e:
        orthorectify_image(SingleImageOptions(photos["oblique.jpg"], str(tmp_path / "o.tif"), dsm,
                                              reference_ortho=ortho, location=far, search_radius=30.0, control=FAST))
    assert "ref_ortho.tif" in str(e.value)
    with pytest.raises(OrthoError, match="reference DSM"):
        orthorectify_image(SingleImageOptions(photos["oblique.jpg"], str(tmp_path / "o.tif"), None,
                                              reference_ortho=ortho, location=far))


def test_qgis_process_orthorectifies_with_automatic_control(setup, tmp_path):
    """archaeoortho:orthorectifyimage headless with REFERENCE_ORTHO + LOCATION (in WGS 84: reprojected into the
    reference's CRS) + SEARCH_RADIUS and no GCP: the orthophoto, the automatic GCPs' residuals and their count."""
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    _, shots, photos, ortho, dsm = setup
    x, y = _rough_location(shots["vertical.jpg"][1], 200.0)
    from core.geometry.crs import transform_points

    lon, lat = transform_points(np.array([[x, y]]), syn.CRS, "EPSG:4326")[0]
    out, res = str(tmp_path / "ortho.tif"), str(tmp_path / "res.gpkg")
    run = subprocess.run([exe, "--json", "run", "archaeoortho:orthorectifyimage", "--", f"IMAGE={photos['vertical.jpg']}",
                          f"DSM={dsm}", f"REFERENCE_ORTHO={ortho}", f"LOCATION={lon:.8f},{lat:.8f} [EPSG:4326]",
                          "SEARCH_RADIUS=30", "FOCAL_MM=6.5", "SENSOR_WIDTH_MM=8", "RESOLUTION=0.2", f"OUTPUT={out}", f"RESIDUALS={res}"],
                         env=env, capture_output=True, text=True, timeout=1200)
    assert run.returncode == 0, run.stderr[-3000:] + run.stdout[-3000:]
    results = json.loads(run.stdout)["results"]
    assert os.path.isfile(results["OUTPUT"]) and results["AUTO_GCPS"] >= 30 and results["RMSE_PX"] < 1.0
    layer_ds = gdal.OpenEx(results["RESIDUALS"])
    assert len(list(layer_ds.GetLayer(0))) == results["AUTO_GCPS"]
