"""The archive test scene (tests/archive_scene.py) is consistent with its own truth.

The film block (4 scans) and its modern reference are rendered once and cached under build/test-cache (about half a
minute); the digital block (4 frames, no reference) too.  Every check compares the rendered files against the truth
the generator states: projected control lands on the same texture in two frames (and not 10 px beside it), the
fiducial marks sit where the truth says, the reference rasters carry a CRS without an EPSG code and cover the block,
the modern orthophoto differs from the archive's texture where the fields changed and only there.
"""
import math
import os

import cv2
import numpy as np
import pytest

from tests import archive_scene as arch

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "build", "test-cache")


@pytest.fixture(scope="module")
def film():
    return arch.archive_block("film", 4, seed=1, out_dir=os.path.join(CACHE, f"{arch.VERSION}-film4"))


@pytest.fixture(scope="module")
def digital():
    return arch.archive_block("digital", 4, seed=2, out_dir=os.path.join(CACHE, f"{arch.VERSION}-digital4"),
                              reference=False)


def _read(block, name):
    img = cv2.imread(os.path.join(block.paths["images"], name), cv2.IMREAD_GRAYSCALE)
    assert img is not None, name
    return img.astype(np.float32)


def _ncc(a, b):
    a = a - a.mean()
    b = b - b.mean()
    den = math.sqrt(float((a * a).sum() * (b * b).sum()))
    return float((a * b).sum() / den) if den > 0 else 0.0


def _patch_pair(block, point, name_a, name_b, images, half=20, offset=(0.0, 0.0)):
    """The patch of frame A around the point's stated observation (+ offset, px) and the patch of frame B around
    its stated observation, resampled into A's patch geometry by the linear part of the local affine A -> B of the
    true ground around the point (projected into both)."""
    t = block.terrain
    local = point.xyz - arch.ORIGIN
    d = np.array([(dx, dy) for dx in (-150.0, 0.0, 150.0) for dy in (-150.0, 0.0, 150.0)])
    xy = local[:2] + d
    ground = np.column_stack([xy, t.ground_at(xy[:, 0], xy[:, 1])]) + arch.ORIGIN
    pa, _ = block.project(name_a, ground)
    pb, _ = block.project(name_b, ground)
    aff, *_ = np.linalg.lstsq(np.column_stack([pa, np.ones(len(pa))]), pb, rcond=None)  # (3, 2)
    ca = point.observations[name_a] + np.asarray(offset)
    cb = point.observations[name_b]  # each frame's own stated position; the affine gives only the patch's shape
    u, v = np.meshgrid(np.arange(-half, half + 1, dtype=np.float64), np.arange(-half, half + 1, dtype=np.float64))
    # OpenCV samples at pixel centres: a COLMAP pixel coordinate p is OpenCV p - 0.5
    a = cv2.remap(images[name_a], (ca[0] + u - 0.5).astype(np.float32), (ca[1] + v - 0.5).astype(np.float32),
                  cv2.INTER_LINEAR)
    bu = cb[0] + u * aff[0, 0] + v * aff[1, 0]
    bv = cb[1] + u * aff[0, 1] + v * aff[1, 1]
    b = cv2.remap(images[name_b], (bu - 0.5).astype(np.float32), (bv - 0.5).astype(np.float32), cv2.INTER_LINEAR)
    return a, b


def _correlations(block):
    images = {n: _read(block, n) for n in block.names}
    truth, beside = [], []
    for p in block.points:
        seen = sorted(p.observations)
        assert len(seen) >= 2, p.name
        a, b = _patch_pair(block, p, seen[0], seen[1], images)
        truth.append(_ncc(a, b))
        best_off = -1.0
        for k in range(8):
            ang = k * math.pi / 4
            a_off, _ = _patch_pair(block, p, seen[0], seen[1], images, offset=(10 * math.cos(ang), 10 * math.sin(ang)))
            best_off = max(best_off, _ncc(a_off, b))
        beside.append(best_off)
    return np.array(truth), np.array(beside)


@pytest.mark.parametrize("which", ["film", "digital"])
def test_projected_points_land_on_the_same_texture(which, request):
    block = request.getfixturevalue(which)
    truth, beside = _correlations(block)
    # the truth correlates better than any of 8 positions 10 px away, for every point, and well in general (a stated
    # position 1 px off in one frame brings the film block's median to 0.87, 2 px to 0.68; the truth gives 0.98)
    assert np.all(truth > beside), list(zip([p.name for p in block.points], truth.round(2), beside.round(2)))
    assert np.median(truth) > 0.9, truth.round(2)
    assert truth.min() > 0.75, truth.round(2)
    assert np.median(beside) < np.median(truth) - 0.3, (truth.round(2), beside.round(2))


def test_block_geometry_as_stated(film, digital):
    for block, kind in ((film, "film"), (digital, "digital")):
        hr = block.terrain.height_raster()
        assert 300.0 <= float(hr.max() - hr.min()) <= 650.0
        assert 3.0 < block.gsd < 9.0
        assert len(block.control) == 6 and len(block.check) >= 4
        for f in block.frames:  # the camera 4-6 km above the ground, looking down
            assert 4000.0 < f.centre_world[2] - float(block.terrain.ground_at(*f.shot.centre[:2])) < 6000.0
            assert f.shot.rotation[2, 2] < -0.99
        img = _read(block, block.names[0])
        assert img.shape == (block.camera.size_px[1], block.camera.size_px[0]), kind
    assert film.camera.calibration()["focal_mm"] == pytest.approx(152.82)
    assert len(film.camera.fiducials_mm) == 8
    io = film.interior(film.names[0])
    assert io["focal_px"] == pytest.approx(152.82 / 0.2)
    # the film affinity: x and y scales differ by 0.1-0.3 %
    fx, fy = io["focal_px_xy"]
    assert 0.001 < abs(fx / fy - 1.0) < 0.003


def _find_mark(img, x, y, size_px, search=6):
    """Sub-pixel position (COLMAP convention) of a cross-in-ring mark near (x, y) by normalised cross-correlation
    with an upright template (parabola through the peak)."""
    n = int(math.ceil(1.3 * size_px)) | 1
    c = (n - 1) / 2.0
    ss = 4
    acc = np.zeros((n, n), np.float32)
    for oy in (np.arange(ss) + 0.5) / ss - 0.5:
        for ox in (np.arange(ss) + 0.5) / ss - 0.5:
            jj, ii = np.meshgrid(np.arange(n) + ox - c, np.arange(n) + oy - c)
            acc += arch.mark_coverage(jj, -ii, size_px)
    tpl = acc / (ss * ss)
    r = int(c) + search + 2
    x0, y0 = int(round(x - 0.5)) - r, int(round(y - 0.5)) - r
    win = img[y0:y0 + 2 * r + 1, x0:x0 + 2 * r + 1]
    res = cv2.matchTemplate(win, tpl, cv2.TM_CCOEFF_NORMED)
    i, j = np.unravel_index(int(np.argmax(res)), res.shape)

    def par(a, b, cc):
        den = a - 2 * b + cc
        return 0.0 if abs(den) < 1e-9 else 0.5 * (a - cc) / den

    dj = par(res[i, j - 1], res[i, j], res[i, j + 1])
    di = par(res[i - 1, j], res[i, j], res[i + 1, j])
    return x0 + j + dj + c + 0.5, y0 + i + di + c + 0.5, float(res[i, j])


def test_fiducials_found_at_their_stated_scan_positions(film):
    size_px = film.camera.mark_mm / film.camera.pixel_mm
    errors, rotations = [], []
    for name in film.names:
        img = _read(film, name)
        stated = film.fiducials_scan(name)
        for k, (x, y) in stated.items():
            fx, fy, score = _find_mark(img, x, y, size_px)
            assert score > 0.7, (name, k, score)
            errors.append(math.hypot(fx - x, fy - y))
        io = film.interior(name)
        rotations.append(io["scan_rotation_deg"])
    errors = np.array(errors)
    # the template is upright and the scans are turned by up to ~1 deg: a few tenths of a pixel at most
    assert np.median(errors) < 0.15 and errors.max() < 0.4, errors.round(3)
    assert np.ptp(rotations) > 0.05  # every scan has its own skew


def test_reference_crs_has_no_epsg_and_covers_the_block(film):
    from osgeo import gdal, osr

    gdal.UseExceptions()
    ortho = gdal.Open(film.paths["ortho"])
    dem = gdal.Open(film.paths["dem"])
    for ds, res in ((ortho, 2.0), (dem, 25.0)):
        srs = osr.SpatialReference(wkt=ds.GetProjection())
        try:
            identified = srs.AutoIdentifyEPSG() == 0
        except RuntimeError:
            identified = False
        assert not identified
        assert srs.GetAuthorityCode(None) is None and srs.GetAuthorityCode("PROJCS") is None
        ref = osr.SpatialReference()
        ref.ImportFromProj4(arch.ARCHIVE_PROJ)
        assert srs.IsSame(ref)
        gt = ds.GetGeoTransform()
        assert gt[1] == pytest.approx(res) and gt[5] == pytest.approx(-res)
    assert ortho.RasterCount == 3
    # every frame's footprint (rays through the picture area's edge, cast into the terrain) inside both rasters
    from tests.synthetic import _ray_cast

    cam = film.camera
    hx, hy = cam.half_mm
    edge = np.array([(sx * hx, sy * hy) for sx in np.linspace(-1, 1, 5) for sy in (-1, 1)]
                    + [(sx * hx, sy * hy) for sy in np.linspace(-1, 1, 5) for sx in (-1, 1)])
    for f in film.frames:
        rays = cam.rays_from_film(edge) @ f.shot.rotation
        xyz = _ray_cast(film.terrain, f.shot.centre, rays[None].astype(np.float64), step=5.0)[0] + arch.ORIGIN
        for ds in (ortho, dem):
            gt = ds.GetGeoTransform()
            x0, y1 = gt[0], gt[3]
            x1, y0 = x0 + gt[1] * ds.RasterXSize, y1 + gt[5] * ds.RasterYSize
            assert np.all((xyz[:, 0] > x0) & (xyz[:, 0] < x1) & (xyz[:, 1] > y0) & (xyz[:, 1] < y1)), f.name
    # the DEM is the truth's ground
    gt = dem.GetGeoTransform()
    z = dem.GetRasterBand(1).ReadAsArray()
    rows, cols = np.array([10, z.shape[0] // 2, z.shape[0] - 5]), np.array([7, z.shape[1] // 3, z.shape[1] - 9])
    rr, cc = np.meshgrid(rows, cols)
    x = gt[0] + (cc + 0.5) * gt[1] - arch.ORIGIN[0]
    y = gt[3] + (rr + 0.5) * gt[5] - arch.ORIGIN[1]
    assert np.allclose(z[rr, cc], film.terrain.ground_at(x, y), atol=0.01)


def test_modern_ortho_differs_where_the_fields_changed(film):
    from osgeo import gdal

    gdal.UseExceptions()
    ds = gdal.Open(film.paths["ortho"])
    gt = ds.GetGeoTransform()
    t = film.terrain
    rng = np.random.default_rng(5)
    n = 48  # windows of 96 m
    changed, same = [], []
    while min(len(changed), len(same)) < 12 and len(changed) + len(same) < 400:
        c0 = int(rng.integers(0, ds.RasterXSize - n))
        r0 = int(rng.integers(0, ds.RasterYSize - n))
        xs = gt[0] + (c0 + np.arange(n) + 0.5) * gt[1] - arch.ORIGIN[0]
        ys = gt[3] + (r0 + np.arange(n) + 0.5) * gt[5] - arch.ORIGIN[1]
        xx, yy = np.meshgrid(xs, ys)
        flags = t.changed_at(xx, yy)
        if flags.any() and not flags.all():
            continue  # a window across a zone boundary
        new = ds.ReadAsArray(c0, r0, n, n).astype(np.float32).mean(axis=0)
        old = t.texture(xs, ys, epoch=0)
        (changed if flags.all() else same).append(_ncc(new, old))
    assert len(changed) >= 12 and len(same) >= 12
    changed, same = np.array(changed), np.array(same)
    assert np.median(same) > 0.75, same.round(2)
    assert np.median(changed) < 0.35, changed.round(2)
    assert np.median(same) - np.median(changed) > 0.4


def test_control_files_read_by_the_plugin(film):
    from core.io.gcp import read_gcps

    gs = read_gcps(film.paths["control_csv"], image_names=film.names)
    assert {p.name for p in gs.points} == {p.name for p in film.control}
    assert "tmerc" in gs.crs.lower() or "transverse_mercator" in gs.crs.lower()
    diffs, obs_err = [], []
    for p in gs.points:
        truth = next(q for q in film.control if q.name == p.name)
        assert p.sigma_xy == pytest.approx(0.02)  # no sigma columns: the reader's defaults
        diffs.append(np.array([p.x, p.y, p.z]) - truth.xyz)
        assert {o.image for o in p.observations} == set(truth.observations)
        for o in p.observations:
            obs_err.append(math.hypot(o.x - truth.observations[o.image][0], o.y - truth.observations[o.image][1]))
    diffs = np.array(diffs)
    # the "3 m" control: N(0, 3 m) per axis (18 values), not the truth
    assert 1.5 < float(np.sqrt(np.mean(diffs ** 2))) < 4.5
    assert np.max(obs_err) < 1.5 and 0.15 < np.sqrt(np.mean(np.square(obs_err))) / math.sqrt(2) < 0.5
    chk = read_gcps(film.paths["check_csv"], image_names=film.names)
    for p in chk.points:
        truth = next(q for q in film.check if q.name == p.name)
        assert np.allclose([p.x, p.y, p.z], truth.xyz, atol=1e-3)
