"""Dense matching and the DSM stage: geometry units, a synthetic block with exact truth, cancel/resume,
bad input, the point cloud, and the Processing algorithm on the sample strip."""
import json
import os
import shutil
import time

import numpy as np
import pytest

from core.common import parallel
from core.common.progress import Cancelled, NullProgress
from core.dense import fusion, stereo
from core.dense import grid as gridding
from core.dense import stage as dense
from core.dense.options import DenseError, DenseOptions
from core.dense.pairs import View
from core.io import raster as dsm
from core.project.workspace import Workspace
from tests import synthetic as syn
from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images
from tests.workspaces import synthetic_workspace

# a small camera keeps rendering and matching fast; the block: 2 strips of 6, 80 % / 50 % overlap (seed 8 puts
# two buildings where at least four photos see their roofs)
CAMERA = syn.CameraModel(400, 300, 325.0, 325.0, 201.9, 148.1, k1=-0.08, k2=0.02, p1=0.0006, p2=-0.0004)


def make_workspace(root, block, names=None, georeferenced=True, images_dir=None):
    """A workspace holding the true (local-frame) model of a synthetic block, as if aligned + georeferenced."""
    rec = block.truth_reconstruction(model_from_local=None, noise_px=0.2, n_points=1500, images=names)
    return synthetic_workspace(root, block, rec, names=names, images_dir=images_dir, georeferenced=georeferenced,
                               crs=syn.CRS, offset=syn.ORIGIN)

@pytest.fixture(scope="module")
def block_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("dense synthetic")
    block = syn.vertical_block(seed=8, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=6, forward_overlap=0.8,
                               side_overlap=0.5, gcp_grid=(2, 2), roofs=0)
    block.render(str(root / "images"))
    return block, str(root)


@pytest.fixture(scope="module")
def built(block_dir):
    """The DSM stage on the synthetic block at full quality (the images are small), with a point cloud."""
    block, root = block_dir
    ws = make_workspace(os.path.join(root, "ws"), block, images_dir=os.path.join(root, "images"))
    result = dense.build_dsm_workspace(ws, DenseOptions(
        quality="full", output_point_cloud=os.path.join(root, "ws", "points.las"), workers=1))
    return block, result


def _copy_ws(root, tmp_path):
    """A fresh copy of the synthetic workspace without dense results."""
    dst = str(tmp_path / "ws")
    shutil.copytree(os.path.join(root, "ws"), dst, ignore=shutil.ignore_patterns("dense", "dsm.tif", "*.las"))
    return dst


def _truth_grid(block, path):
    z, gt, wkt = dsm.read_dsm(path)
    h, w = z.shape
    xs = gt[0] + (np.arange(w) + 0.5) * gt[1] - syn.ORIGIN[0]
    ys = gt[3] + (np.arange(h) + 0.5) * gt[5] - syn.ORIGIN[1]
    x, y = np.meshgrid(xs, ys)
    return z, gt, wkt, x, y, block.scene.height_at(x, y)


# ---------------------------------------------------------------------------
# units
# ---------------------------------------------------------------------------

def _view(name, rot, centre, cam):
    return View(0, name, "", cam.width, cam.height, "OPENCV", tuple(cam.params), rot, -rot @ centre)


def test_rectification_maps_follow_the_camera_model():
    """A ground point lands on one row in both rectified images, and the maps lead back to its true
    (distorted, COLMAP-convention) pixels in both photos."""
    rng = np.random.default_rng(0)
    down = syn.look_at(np.array([0.0, 0, 50]), np.array([0.0, 0, 0]), np.array([0.0, 1, 0]))
    ri = syn.small_rotation(rng, 2.0) @ down
    rj = syn.small_rotation(rng, 2.0) @ down
    ci, cj = np.array([0.0, 0, 50]), np.array([12.0, 3, 51])
    vi, vj = _view("a", ri, ci, CAMERA), _view("b", rj, cj, CAMERA)
    ki, di = vi.camera_matrix(1.0, 1.0)
    kj, dj = vj.camera_matrix(1.0, 1.0)
    size = (CAMERA.width, CAMERA.height)
    rect = stereo.rectify_pair(stereo.ScaledCamera(vi, ki, di, size), stereo.ScaledCamera(vj, kj, dj, size))
    pts = np.column_stack([rng.uniform(-3, 15, 40), rng.uniform(-8, 8, 40), rng.uniform(-2, 6, 40)])
    pi = stereo.rect_project(pts, ci, rect, rect.cx_i)
    pj = stereo.rect_project(pts, cj, rect, rect.cx_j)
    assert np.allclose(pi[:, 1], pj[:, 1], atol=1e-6)  # same row
    assert (pi[:, 0] - pj[:, 0] - rect.cx_i + rect.cx_j > 0).all()  # positive disparity
    for p, shot_r, c, maps in ((pi, ri, ci, rect.maps_i), (pj, rj, cj, rect.maps_j)):
        truth = CAMERA.image_from_camera((pts - c) @ shot_r.T) - 0.5  # COLMAP corner -> OpenCV centre convention
        inside = (p[:, 0] > 1) & (p[:, 0] < rect.width - 2) & (p[:, 1] > 1) & (p[:, 1] < rect.height - 2)
        assert inside.sum() > 20
        for k in np.flatnonzero(inside):
            x, y = p[k, 0], p[k, 1]
            x0, y0 = int(x), int(y)
            tx, ty = x - x0, y - y0
            got = [(1 - tx) * (1 - ty) * m[y0, x0] + tx * (1 - ty) * m[y0, x0 + 1] + (1 - tx) * ty * m[y0 + 1, x0]
                   + tx * ty * m[y0 + 1, x0 + 1] for m in maps]
            assert np.allclose(got, truth[k], atol=0.02)


def test_fusion_keeps_what_two_pairs_confirm():
    z = np.full((4, 4), 50.0, dtype=np.float32)
    maps = np.stack([z, z * 1.001, z.copy(), z.copy()])
    maps[2, 0, 0] = 60.0  # one pair disagrees here: the other two still confirm 50
    maps[3, 0, 0] = np.nan
    maps[1, 1, 1] = 70.0  # only one pair left that says 50 -> dropped
    maps[2, 1, 1] = np.nan
    maps[3, 1, 1] = np.nan
    maps[:, 2, 2] = [50.0, 55.0, 60.0, 65.0]  # nobody agrees
    fused, n = fusion.fuse_depth_maps(maps, np.full(4, 0.005), 2)
    assert fused[0, 0] == pytest.approx(50.025, abs=1e-3)
    assert np.isnan(fused[1, 1]) and np.isnan(fused[2, 2])
    assert fused[3, 3] == pytest.approx(50.0125, abs=1e-3) and n[3, 3] == 4


def test_the_quick_horizon_test_never_skips_a_mask_that_drops_pixels():
    """_all_below_horizon lets fusion skip the full-size horizon mask: it may say so only where that mask keeps
    every pixel (a sweep of tilts from nadir to past the horizon, the camera rolled too)."""
    from core.prepare.sky import horizon_keep

    quick_true = 0
    for tilt in np.arange(0.0, 95.0, 2.5):
        for roll in (0.0, 20.0):
            t, r = np.radians(tilt), np.radians(roll)
            # nadir camera (looking down -z, image y towards -y), tilted about the world x axis, rolled about its axis
            nadir = np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]])
            rx = np.array([[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])
            rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
            rot = rz @ nadir @ rx.T
            v = View(1, "a.jpg", "", CAMERA.width, CAMERA.height, "OPENCV", tuple(CAMERA.params), rot, np.zeros(3))
            full = horizon_keep(v.camera, rot, (0.0, 0.0, 1.0), 1.0)
            quick = fusion._all_below_horizon(v, 1.0)
            assert not quick or full.all(), (tilt, roll)
            quick_true += quick
            if tilt == 0.0:
                assert quick  # a vertical photo skips the mask
            if tilt >= 70.0:
                assert not full.all() and not quick  # its view (half field 25 degrees) reaches the horizon
    assert quick_true >= 8


def test_depth_edges_are_walls_not_weak_texture_streaks():
    """The finest level is matched both ways only at the coarser level's depth edges (stereo.edge_mask): a wall's
    step marks them along its outline, more than a tile needs; weak texture's streaks (2.8 px jumps on a disparity
    of 100) do not, unless the pair's geometric disparity is small (the same jump is then a real step)."""
    rng = np.random.default_rng(5)
    ground = np.full((200, 300), 100.0, np.float32)
    streaks = ground.copy()
    for r in rng.integers(0, 200, 40):
        streaks[r, :] += 1.4 * rng.choice([-1.0, 1.0])  # up to 2.8 px between neighbouring streaks
    assert not stereo.edge_mask(streaks).any()
    wall = streaks.copy()
    wall[60:120, 100:160] += 12.0  # a roof 12 coarse px above the ground
    edge = stereo.edge_mask(wall)
    assert edge[56:124, 96:164].sum() >= stereo.EDGE_MIN_PIXELS and not edge[140:, :].any()
    assert not edge[75:105, 115:145].any()  # inside the roof: no edge
    # the same streaks with the disparity mostly the rectification's shift (cx_i - cx_j = 180: 10 px geometric)
    assert stereo.edge_mask(streaks, shift=180.0).sum() > 1000
    holes = wall.copy()
    holes[:, :40] = np.nan  # no data: no edge from it
    assert not stereo.edge_mask(holes)[:, :38].any()


def test_pair_depth_maps_round_trip_within_their_uint16_steps(tmp_path):
    rng = np.random.default_rng(3)
    m = rng.uniform(20.0, 400.0, (30, 40)).astype(np.float32)
    m[5:9, 3:30] = np.nan
    m[0, 0] = 0.01  # a depth far below the others keeps its absolute precision
    path = str(tmp_path / "1-2.npz")
    stereo._save_pair(path, m, m[::-1].copy(), 0.01, {"key": "1-2"})
    got = stereo.read_depth(path, "i")
    assert got.dtype == np.float32 and np.array_equal(np.isnan(got), np.isnan(m))
    err = np.abs(got - m)[np.isfinite(m)]
    assert err.max() <= 1.01 * np.nanmax(m) / (2 * stereo.DEPTH_LEVELS)  # half a step: 3 mm at 400 m
    assert got[0, 0] > 0
    assert np.allclose(stereo.read_depth(path, "j"), m[::-1], atol=0.004, rtol=0, equal_nan=True)
    assert stereo.read_pair_summary(path)["key"] == "1-2"
    stereo._save_pair(path, None, None, 0.0, {"key": "1-2", "skipped": "x"})
    assert stereo.read_depth(path, "i").size == 0


def test_cell_statistic_takes_the_highest_cluster():
    cells = np.array([0, 0, 0, 0, 0, 1, 1, 1, 2])
    z = np.array([10.0, 10.1, 15.0, 15.1, 15.2, 3.0, 3.1, 2.9, 7.0])
    val, cnt = gridding.cell_statistic(cells, z, 4, cluster_tol=0.5)
    assert val[0] == pytest.approx(15.1, abs=0.06)  # the roof, not the mean of roof and ground
    assert val[1] == pytest.approx(3.0, abs=0.06)
    assert val[2] == pytest.approx(7.0) and np.isnan(val[3])
    assert list(cnt) == [5, 3, 1, 0]


def test_small_holes_filled_large_ones_kept():
    a = np.full((40, 40), 5.0, dtype=np.float32)
    a[5:7, 5:7] = np.nan  # 4 cells
    a[20:32, 20:32] = np.nan  # 144 cells
    out = gridding.fill_small_holes(a, max_hole_cells=16)
    assert np.isfinite(out[5:7, 5:7]).all() and np.allclose(out[5:7, 5:7], 5.0)
    assert np.isnan(out[20:32, 20:32]).all()


def _square(x, cancel_path=None):
    return x * x


def _slow(x, cancel_path=None):
    for _ in range(100):
        parallel.check_unit_cancel(cancel_path)
        time.sleep(0.05)
    return x


class _CancelAfter(NullProgress):
    def __init__(self, n=None, when=None):
        self.n, self.when, self.reports, self.cancelled = n, when, 0, False

    def report(self, fraction, message=""):
        if message.startswith("pair "):
            self.reports += 1
        if (self.n is not None and self.reports >= self.n) or (self.when and self.when in message):
            self.cancelled = True

    def is_cancelled(self):
        return self.cancelled


def test_process_pool_runs_units():
    with parallel.make_executor(workers=2, kind="process") as ex:
        assert isinstance(ex, parallel.cf.ProcessPoolExecutor)
        assert sorted(r for _, r in parallel.run_units(ex, _square, list(range(6)))) == [0, 1, 4, 9, 16, 25]
    with parallel.make_executor(workers=1) as ex:
        assert isinstance(ex, parallel.SerialExecutor)


def test_process_pool_cancel_within_a_unit():
    prog = _CancelAfter()
    with parallel.make_executor(workers=2, kind="thread") as ex:
        t0 = time.time()
        it = parallel.run_units(ex, _slow, [1, 2], prog)
        prog.cancelled = True
        with pytest.raises(Cancelled):
            list(it)
    assert time.time() - t0 < 3.0  # running units saw the cancel file and stopped (5 s otherwise)


# ---------------------------------------------------------------------------
# the synthetic block
# ---------------------------------------------------------------------------

def test_synthetic_dsm_accuracy(built):
    block, r = built
    gsd = block.gsd
    z, gt, wkt, x, y, truth = _truth_grid(block, r.dsm_path)
    res = gt[1]
    assert res == pytest.approx(r.resolution) and res < 2.5 * gsd
    covered = np.isfinite(z)
    walls = np.zeros_like(covered)
    for b in block.scene.buildings:  # a band of 2 cells either side of every wall
        walls |= b.contains(x, y, 2 * res) & ~b.contains(x, y, -2 * res)
    judged = covered & ~walls
    assert judged.sum() >= 0.9 * covered.sum()
    err = z - truth
    rmse = float(np.sqrt(np.mean(err[judged] ** 2)))
    assert rmse <= 1.5 * gsd, f"RMSE {rmse:.3f} m > 1.5 GSD ({1.5 * gsd:.3f} m)"
    assert np.mean(np.abs(err[judged]) > 5 * gsd) < 0.005  # hardly any blunders
    assert r.valid_fraction >= 0.85
    assert r.pairs >= 15 and r.points > 100000


def wall_offsets(block, z, x, y, truth):
    """Per building the block sees whole, (building, how far in cells the DSM's farthest cell on the wrong side of
    the roof's half height lies from the roof's true outline; 0 when none is wrong)."""
    from scipy import ndimage

    covered = np.isfinite(z)
    out = []
    for b in block.scene.buildings:
        inside = b.contains(x, y)
        if inside.sum() == 0 or (inside & covered).sum() < 0.9 * inside.sum():
            continue  # not (fully) seen by the block
        near = b.contains(x, y, 6.0)
        ground = float(np.median(truth[near & ~b.contains(x, y, 1.0)]))
        mid = 0.5 * (b.roof + ground)
        high = truth > mid  # this roof (and a neighbour's, if one is this close)
        wrong = near & covered & ((z > mid) != high)
        # distance of each wrongly classified cell from the true outline, in cells
        outline = high ^ ndimage.binary_erosion(high)
        dist = ndimage.distance_transform_edt(~outline)
        out.append((b, float(dist[wrong].max()) if wrong.any() else 0.0))
    return out


def test_synthetic_building_walls_are_sharp(built):
    block, r = built
    z, gt, _, x, y, truth = _truth_grid(block, r.dsm_path)
    offsets = wall_offsets(block, z, x, y, truth)
    for b, cells in offsets:
        assert cells <= 2.0, f"building at ({b.cx:.0f}, {b.cy:.0f}): edge cells up to {cells:.1f} cells off"
    assert len(offsets) >= 2


def test_dsm_file_is_a_cog_with_crs_and_nodata(built):
    from osgeo import gdal

    block, r = built
    ds = gdal.Open(r.dsm_path)
    band = ds.GetRasterBand(1)
    assert band.DataType == gdal.GDT_Float32
    assert band.GetNoDataValue() == dsm.NODATA
    assert band.GetOverviewCount() >= 1
    assert ds.GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE") == "COG"
    assert "32633" in ds.GetProjection()
    info = dsm.open_dsm(r.dsm_path)
    assert syn.ORIGIN[0] - 200 < info.bounds[0] < syn.ORIGIN[0] + 200
    # the reader samples heights in world coordinates, and reprojects on the fly (ALS in another CRS)
    x0, y0 = syn.ORIGIN[0] + 1.0, syn.ORIGIN[1] + 1.0
    with dsm.DsmReader(r.dsm_path) as rd:
        h = rd.sample(np.array([x0]), np.array([y0]))[0]
    assert h == pytest.approx(float(block.scene.height_at(1.0, 1.0)), abs=0.5)
    with dsm.DsmReader(r.dsm_path, target_crs="EPSG:3857") as rd:
        assert rd.width > 0 and "3857" in rd.crs_wkt or "Pseudo" in rd.crs_wkt
    ws = Workspace.open(r.workspace)
    st = ws.stage("dsm")
    assert st["status"] == "done" and st["outputs"]["dsm"] == "dsm.tif"
    assert st["results"]["VALID_FRACTION"] == pytest.approx(r.valid_fraction)
    assert {"matching", "fusion", "dsm", "total"} <= set(st["timings"])


def test_dsm_source_raster_says_measured_or_interpolated(built):
    """dense/dsm-source.tif: the DSM's grid, 1 where a height was measured, 2 where a hole was filled, 0 = nodata;
    the accuracy against the synthetic truth, measured and interpolated cells apart."""
    from osgeo import gdal

    block, r = built
    z, gt, _, x, y, truth = _truth_grid(block, r.dsm_path)
    assert r.source_path == os.path.join(r.workspace, "dense", "dsm-source.tif")
    src_ds = gdal.Open(r.source_path)
    assert (src_ds.RasterXSize, src_ds.RasterYSize) == (z.shape[1], z.shape[0])
    assert np.allclose(src_ds.GetGeoTransform(), gt) and "32633" in src_ds.GetProjection()
    assert src_ds.GetMetadataItem("ARCHAEOORTHO_PRODUCT") == "dsm-source"
    src = src_ds.GetRasterBand(1).ReadAsArray()
    from core.dense.grid import SOURCE_REMOVED

    assert set(np.unique(src)) <= {0, dsm.SOURCE_MEASURED, dsm.SOURCE_INTERPOLATED, SOURCE_REMOVED}
    assert (np.isin(src, (dsm.SOURCE_MEASURED, dsm.SOURCE_INTERPOLATED)) <= np.isfinite(z)).all()
    assert (np.isfinite(z) <= (src > 0)).all()  # a height: measured, interpolated or removed (and filled)
    assert r.measured_fraction + r.interpolated_fraction <= r.valid_fraction + 1e-6
    assert r.measured_fraction >= 0.9 and r.valid_fraction >= 0.99  # the holes inside the cameras' hull are filled
    st = Workspace.open(r.workspace).stage("dsm")
    assert st["outputs"]["dsm_source"] == "dense/dsm-source.tif"
    assert st["results"]["MEASURED_FRACTION"] == pytest.approx(r.measured_fraction)
    walls = np.zeros(z.shape, dtype=bool)
    for b in block.scene.buildings:
        walls |= b.contains(x, y, 2 * gt[1]) & ~b.contains(x, y, -2 * gt[1])
    err = z - truth
    measured = (src == dsm.SOURCE_MEASURED) & ~walls
    rmse = float(np.sqrt(np.mean(err[measured] ** 2)))
    assert rmse <= 1.5 * block.gsd, f"measured cells: RMSE {rmse:.3f} m > 1.5 GSD"
    interp = src == dsm.SOURCE_INTERPOLATED
    assert interp.sum() > 0  # the occlusions beside the walls: filled, and said so
    # an interpolated cell is a guess from its borders (mostly the ground a wall hides: drawn from the hole's low
    # side): within the building heights, and mostly within a metre or two (1.25 m median here)
    assert np.abs(err[interp]).max() <= max(b.roof for b in block.scene.buildings) - truth[np.isfinite(truth)].min()
    assert np.median(np.abs(err[interp])) <= 2.0
    print(f"measured {100 * r.measured_fraction:.1f} % (RMSE {rmse:.3f} m), interpolated "
          f"{100 * r.interpolated_fraction:.1f} % (RMSE {float(np.sqrt(np.mean(err[interp] ** 2))):.2f} m)")


def test_point_cloud_las_in_world_coordinates(built):
    block, r = built
    xyz, rgb, header = dsm.read_las(r.point_cloud_path)
    assert header["version"] == "1.2" and header["point_format"] == 2 and header["count"] == r.points
    assert any(rid == 34735 for _, rid, _ in header["vlrs"])  # GeoKeyDirectory (EPSG:32633)
    geokeys = next(d for _, rid, d in header["vlrs"] if rid == 34735)
    assert 32633 in np.frombuffer(geokeys, dtype="<u2")
    assert abs(np.median(xyz[:, 0]) - syn.ORIGIN[0]) < 200
    sample = xyz[:: max(1, len(xyz) // 5000)]
    err = sample[:, 2] - block.scene.height_at(sample[:, 0] - syn.ORIGIN[0], sample[:, 1] - syn.ORIGIN[1])
    assert np.median(np.abs(err)) < block.gsd
    assert rgb.max() > 0 and (rgb[:, 0] == rgb[:, 1]).all()  # grey images: grey points
    mx, mn = header["max_min"][0], header["max_min"][1]
    assert mn <= xyz[:, 0].min() + 1e-3 and mx >= xyz[:, 0].max() - 1e-3


def test_cancel_leaves_no_dsm_and_resume_skips_finished_pairs(block_dir, tmp_path):
    block, root = block_dir
    ws = _copy_ws(root, tmp_path)
    prog = _CancelAfter(n=4)
    with pytest.raises(Cancelled):
        dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=1), progress=prog)
    assert not os.path.exists(os.path.join(ws, "dsm.tif"))
    assert Workspace.open(ws).stage("dsm")["status"] == "cancelled"

    def pair_files():
        return sorted(os.path.join(dp, f) for dp, _, fs in os.walk(os.path.join(ws, "dense")) for f in fs
                      if f.endswith(".npz") and "-" in f and "partial" not in f)

    first = pair_files()
    assert 4 <= len(first) < 20
    mtimes = {p: os.stat(p).st_mtime_ns for p in first}

    # resume on a process pool of two; cancel while the GeoTIFF is written: no dsm.tif, no partial file
    prog = _CancelAfter(when="writing Cloud-Optimized GeoTIFF")
    with pytest.raises(Cancelled):
        dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=2, executor="process"), progress=prog)
    assert not [f for f in os.listdir(ws) if "dsm" in f and f.endswith(".tif")]
    assert Workspace.open(ws).stage("dsm")["status"] == "cancelled"
    everything = pair_files()
    assert len(everything) > len(first)
    for p, m in mtimes.items():
        assert os.stat(p).st_mtime_ns == m  # the finished pairs were not matched again

    # the third run reuses every pair; the DSM's size is said once (it was printed twice: issue 36 item 21)
    said = []

    class Said(NullProgress):
        def report(self, fraction, message=""):
            said.append(message)

        def info(self, message):
            said.append(message)

    r = dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=1), progress=Said())
    assert sum(f"{r.resolution:g} m" in m and " cells at " in m for m in said) == 1, said
    assert r.pairs_reused == len(everything) == r.pairs
    assert os.path.isfile(r.dsm_path) and r.valid_fraction > 0.8
    assert any(f"{len(everything)} reused" in line for line in r.log_lines)


def test_no_stereo_pair_is_a_clear_error(block_dir, tmp_path):
    block, root = block_dir
    # the two photos farthest apart (opposite corners of the block): they share no ground
    c = np.array([s.centre for s in block.shots])
    i, j = np.unravel_index(np.argmax(np.linalg.norm(c[:, None] - c[None], axis=2)), (len(c), len(c)))
    names = [block.names[i], block.names[j]]
    ws = make_workspace(str(tmp_path / "ws"), block, names=names, images_dir=os.path.join(root, "images"))
    with pytest.raises(DenseError, match="no stereo pair passed the selection"):
        dense.build_dsm_workspace(ws)
    assert Workspace.open(ws).stage("dsm")["status"] == "pending"  # refused before the stage began


def test_not_georeferenced_is_refused(block_dir, tmp_path):
    block, root = block_dir
    ws = make_workspace(str(tmp_path / "ws"), block, georeferenced=False, images_dir=os.path.join(root, "images"))
    with pytest.raises(DenseError, match="not georeferenced.*Georeference"):
        dense.build_dsm_workspace(ws)


def test_bad_parameters_are_clear(block_dir, tmp_path):
    import pycolmap

    block, root = block_dir
    ws = _copy_ws(root, tmp_path)
    with pytest.raises(DenseError, match="QUALITY"):
        DenseOptions(quality="ultra")
    with pytest.raises(DenseError, match="RESOLUTION"):
        DenseOptions(resolution=-1)
    with pytest.raises(DenseError, match="ENGINE 'gpu'"):
        DenseOptions(engine="gpu")
    with pytest.raises(DenseError, match="RESOLUTION"):
        DenseOptions(resolution=float("nan"))
    # the options are the settings, checked and normalised when made (Processing and the pipeline build them)
    made = DenseOptions(quality="FULL", engine="CPU", resolution=1, output_dsm="rel/dsm.tif")
    assert (made.quality, made.engine, made.resolution) == ("full", "cpu", 1.0)
    assert made.output_dsm == os.path.abspath("rel/dsm.tif") and made.output_point_cloud is None
    recorded = made.stage_parameters("/ws/dsm.tif")  # the recorded parameters keep their shape
    assert set(recorded) == {"resolution", "quality", "engine", "output_dsm", "output_point_cloud", "options"}
    assert not {"resolution", "engine", "output_dsm", "workers", "scheduler"} & set(recorded["options"])
    if not pycolmap.has_cuda:
        with pytest.raises(DenseError, match="CUDA"):
            dense.build_dsm_workspace(ws, DenseOptions(engine="cuda"))


# ---------------------------------------------------------------------------
# Processing, on the sample strip (aligned + georeferenced with EXIF GPS)
# ---------------------------------------------------------------------------

@pytest.mark.slow
def test_processing_build_dsm_on_the_sample_strip(qgis_processing, qgis_iface, tmp_path):
    import archaeoortho
    from qgis import processing
    from qgis.core import QgsApplication, QgsProcessingException, QgsRasterLayer

    plugin = archaeoortho.classFactory(qgis_iface)
    plugin.initProcessing()
    try:
        alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:builddsm")
        assert alg is not None and alg.shortHelpString()
        assert {"WORKSPACE", "RESOLUTION", "QUALITY", "ENGINE", "OUTPUT_DSM", "OUTPUT_POINT_CLOUD"} <= {
            p.name() for p in alg.parameterDefinitions()}
        assert {"VALID_FRACTION", "OUTPUT_DSM", "WORKSPACE"} <= {o.name() for o in alg.outputDefinitions()}
        images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:5], str(tmp_path / "img"))
        ws = processing.run("archaeoortho:alignimages", {
            "IMAGES": images, "WORKSPACE": str(tmp_path / "ws"), "MAX_IMAGE_SIZE": 800, "MAX_FEATURES": 2048,
        })["WORKSPACE"]
        with pytest.raises(QgsProcessingException, match="not georeferenced"):
            processing.run("archaeoortho:builddsm", {"WORKSPACE": ws})
        processing.run("archaeoortho:georeference", {"WORKSPACE": ws, "USE_EXIF_GPS": True, "CRS": "EPSG:32617"})
        res = processing.run("archaeoortho:builddsm", {
            "WORKSPACE": ws, "QUALITY": 2, "OUTPUT_POINT_CLOUD": str(tmp_path / "points.las")})
        assert res["WORKSPACE"] == ws
        assert os.path.samefile(res["OUTPUT_DSM"], os.path.join(ws, "dsm.tif"))
        assert res["PAIRS"] >= 3 and res["POINTS"] > 1000
        assert 0.3 < res["VALID_FRACTION"] <= 1.0
        layer = QgsRasterLayer(res["OUTPUT_DSM"], "dsm")
        assert layer.isValid() and layer.crs().authid() == "EPSG:32617"
        assert 274700 < layer.extent().center().x() < 275200
        assert os.path.getsize(res["OUTPUT_POINT_CLOUD"]) > 227 + 26 * 1000
    finally:
        plugin.unload()


def test_pool_python_is_this_installation(monkeypatch):
    """Embedded in QGIS, sys.executable is whatever python3 is first on PATH: never spawn that one."""
    import sys

    monkeypatch.setattr(sys, "executable", "/nonexistent/shims/python3")
    exe = parallel.python_executable()
    assert exe and (exe.startswith(sys.exec_prefix) or exe.startswith(sys.base_exec_prefix))
    assert "shims" not in exe


@pytest.mark.slow
def test_qgis_process_builds_a_dsm_with_a_process_pool(built, tmp_path):
    """Headless, as a user runs it: qgis_process (embedded Python) spawning pool workers."""
    import subprocess

    from tests.conftest import qgis_process

    exe, env = qgis_process()
    block, r = built
    ws = _copy_ws(os.path.dirname(r.workspace), tmp_path)
    out = subprocess.run([exe, "--json", "run", "archaeoortho:builddsm", "--", f"WORKSPACE={ws}", "QUALITY=1",
                          "WORKERS=2"], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    res = json.loads(out.stdout)["results"]
    assert os.path.samefile(res["OUTPUT_DSM"], os.path.join(ws, "dsm.tif"))
    assert res["PAIRS"] >= 10 and res["VALID_FRACTION"] > 0.8
    assert "2 worker(s)" in out.stdout


def test_the_cuda_engine_is_dispatched_with_the_blocks_views_and_the_layouts_folders(monkeypatch, tmp_path):
    """points.dense_points with ENGINE cuda: COLMAP's driver gets the block's views, the QUALITY scale, the
    workspace's dense and georeferenced model folders and the block's images folder; its points are the result
    (no pair matched by the OpenCV engine), and none at all is the clear DenseError. Runs without CUDA: the
    driver is replaced."""
    import types

    from core.dense import points
    from core.dense.block import DenseBlock
    from core.dense.journal import Journal

    seen = {}

    def fake_cuda(views, scale, dense_dir, model_dir, images_dir, model_fp, progress):
        seen.update(views=views, scale=scale, dense_dir=dense_dir, model_dir=model_dir, images_dir=images_dir,
                    model_fp=model_fp)
        return [gridding.PointFile(str(tmp_path / "cuda.npz"), (0.0, 0.0, 1.0, 1.0), n_points)], 0

    monkeypatch.setattr(points, "cuda_points", fake_cuda)
    views = {1: "view 1", 2: "view 2"}
    block = DenseBlock(views, np.zeros((0, 3)), [], 0, 0.05, 0.1, np.zeros(3), "EPSG:32633", "/photos", 0.0)
    lay = types.SimpleNamespace(dense_dir=str(tmp_path / "dense"), georef_model_dir=str(tmp_path / "model"))
    job = Journal(NullProgress())
    n_points = 7
    got = points.dense_points(block, DenseOptions(engine="cuda", quality="quarter"), lay, {"m": "1"},
                              NullProgress(), job)
    assert (got.count, got.pairs, got.reused) == (7, 0, 0) and "matching" in job.timings
    assert seen == dict(views=views, scale=0.25, dense_dir=lay.dense_dir, model_dir=lay.georef_model_dir,
                        images_dir="/photos", model_fp={"m": "1"})
    n_points = 0
    with pytest.raises(DenseError, match="no consistent surface point"):
        points.dense_points(block, DenseOptions(engine="cuda"), lay, {}, NullProgress(), job)


def test_a_camera_placed_absurdly_far_does_not_span_the_dsm():
    """Issue 46: a photo registered on 4 points with its centre 2.3e11 m away asked for a DSM grid of 10^11 cells
    and stopped the stage; it is left out of the grid's extent and named."""
    from core.common.progress import NullProgress
    from core.dense.dsm import block_centres

    warnings = []

    class Noting(NullProgress):
        def warning(self, message):
            warnings.append(message)

    boxes = np.array([[0.0, 0.0, 100.0, 80.0], [20.0, 10.0, 130.0, 90.0]])
    centres = {"a.jpg": np.array([50.0, 40.0]), "b.jpg": np.array([90.0, 45.0]), "c.jpg": np.array([-60.0, 40.0]),
               "far.jpg": np.array([2.3e11, -4.0e10])}
    kept = block_centres(centres, boxes, Noting())
    assert len(kept) == 3 and np.abs(kept).max() < 1000  # c.jpg, beside the block, still spans it
    assert len(warnings) == 1 and "far.jpg" in warnings[0]
