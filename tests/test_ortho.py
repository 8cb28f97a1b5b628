"""True orthophotos and the orthomosaic on a synthetic block with exact truth (the true height field as DSM,
the true cameras), single-image orthorectification, bad input, cancel, and the two Processing algorithms.

Positions are measured by phase correlation of 32 x 32-cell patches of an orthophoto against the scene's true
orthoimage (its texture, sampled at the same cells)."""
import json
import math
import os
import shutil

import cv2
import numpy as np
import pytest
from osgeo import gdal

from core.common.progress import Cancelled, NullProgress
from core.geometry import camera as gcam
from core.io import gcp as gcpmod
from core.io import raster as dsmmod
from core.ortho import planning
from core.ortho.cameras import OrthoCamera, select_cameras
from core.ortho.options import OrthoError, OrthoOptions, SingleImageOptions
from core.ortho.orientation import read_orientation
from core.ortho.single import orthorectify_image
from core.ortho.stage import build_orthophoto_workspace
from core.ortho.surface import fill_dsm_gaps
from core.project.stages import DONE
from core.project.workspace import Workspace
from tests import synthetic as syn
from tests.workspaces import synthetic_workspace

# a small camera keeps rendering fast; 3 strips of 5 images, 70 % / 40 % overlap, 40 m above ground
CAMERA = syn.CameraModel(400, 300, 325.0, 325.0, 201.9, 148.1, k1=-0.08, k2=0.02, p1=0.0006, p2=-0.0004)
SINGLE = "S2_02.jpg"


def make_workspace(root, block, images_dir, names=None):
    """A workspace holding the true (local-frame) model of a synthetic block, as if aligned + georeferenced."""
    rec = block.truth_reconstruction(model_from_local=None, noise_px=0.2, n_points=400, images=names)
    groups = [{"camera_id": 1, "key": "synthetic|400x300", "make": "synthetic", "model": "NIR-less",
               "images": list(names or block.names)}]
    return synthetic_workspace(root, block, rec, names=names, images_dir=images_dir, camera_groups=groups,
                               georeferenced=True, crs=syn.CRS, offset=syn.ORIGIN)

def truth_dsm(block, path):
    """The renderer's own height raster (bilinear between cell centres) as a DSM in world coordinates."""
    sc = block.scene
    xmin, _, _, ymax = sc.bounds
    gt = (xmin + syn.ORIGIN[0], sc.height_res, 0.0, ymax + syn.ORIGIN[1], 0.0, -sc.height_res)
    return dsmmod.write_cog(path, sc.height_raster(), gt, syn.CRS)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("ortho synthetic")
    block = syn.vertical_block(seed=1, camera=CAMERA, altitude=40.0, n_strips=3, per_strip=5, forward_overlap=0.7,
                               side_overlap=0.4, gcp_grid=(4, 3), roofs=2)
    images = str(root / "images")
    block.render(images)
    dsm = truth_dsm(block, str(root / "truth_dsm.tif"))
    ws = make_workspace(str(root / "ws"), block, images)
    return block, str(root), images, dsm, ws


@pytest.fixture(scope="module")
def mosaic(scene):
    block, root, _images, dsm, ws = scene
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, blending="feather",
                                                      per_image_folder=os.path.join(ws, "ortho"),
                                                      seamlines=os.path.join(ws, "seamlines.gpkg")))
    return res


# ---------------------------------------------------------------------------
# measuring positions against the truth
# ---------------------------------------------------------------------------

def _read(path):
    ds = gdal.Open(path)
    a = ds.ReadAsArray().astype(np.float32)
    if a.ndim == 2:
        a = a[None]
    return a, ds.GetGeoTransform()


def _truth_patch(block, gt, r0, c0, n):
    xs = gt[0] + (c0 + np.arange(n) + 0.5) * gt[1] - syn.ORIGIN[0]
    ys = gt[3] + (r0 + np.arange(n) + 0.5) * gt[5] - syn.ORIGIN[1]
    x, y = np.meshgrid(xs, ys)
    mx, my = block.scene.raster_coords(x, y, block.scene.texture_res)
    return syn._sample(block.scene.texture_raster(), mx, my)


def _shift(a, b):
    win = cv2.createHanningWindow((a.shape[1], a.shape[0]), cv2.CV_64F)
    (dx, dy), resp = cv2.phaseCorrelate(a.astype(np.float64), b.astype(np.float64), win)
    return dx, dy, resp


def _shift_vs_truth(block, arr, gt, xw, yw, n=32, max_nodata=0.05):
    """(dx, dy, response) in cells of the orthophoto's content at world (xw, yw) against the truth."""
    c = int((xw - gt[0]) / gt[1])
    r = int((yw - gt[3]) / gt[5])
    r0, c0 = r - n // 2, c - n // 2
    if r0 < 0 or c0 < 0 or r0 + n > arr.shape[1] or c0 + n > arr.shape[2]:
        return None
    alpha = arr[-1, r0:r0 + n, c0:c0 + n]
    if (alpha == 0).mean() > max_nodata:
        return None
    return _shift(_truth_patch(block, gt, r0, c0, n), arr[0, r0:r0 + n, c0:c0 + n])


def _ground_shifts(block, path, count=120, n=32, seed=1):
    arr, gt = _read(path)
    rng = np.random.default_rng(seed)
    h, w = arr.shape[1:]
    out = []
    for _ in range(count * 4):
        if len(out) >= count:
            break
        r, c = rng.integers(n, h - n), rng.integers(n, w - n)
        x, y = gt[0] + (c + 0.5) * gt[1], gt[3] + (r + 0.5) * gt[5]
        if block.scene.near_feature(np.array(x - syn.ORIGIN[0]), np.array(y - syn.ORIGIN[1]), 3.0):
            continue
        s = _shift_vs_truth(block, arr, gt, x, y, n)
        if s and s[2] > 0.3:
            out.append(s)
    return np.array(out), gt[1]


def _rmse(v):
    return float(np.sqrt(np.mean(v[:, 0] ** 2 + v[:, 1] ** 2)))


def _roof_corners(block):
    for b in block.scene.buildings:
        c, s = math.cos(b.angle), math.sin(b.angle)
        for su in (-1, 1):
            for sv in (-1, 1):
                u, v = su * b.half_w, sv * b.half_l
                yield b.cx + c * u - s * v + syn.ORIGIN[0], b.cy + s * u + c * v + syn.ORIGIN[1]


# ---------------------------------------------------------------------------
# the orthomosaic on the synthetic block
# ---------------------------------------------------------------------------

def test_mosaic_is_a_cog_with_alpha_in_the_workspace(scene, mosaic):
    _block, _root, _images, _dsm, ws = scene
    assert os.path.samefile(mosaic.orthomosaic, os.path.join(ws, "orthomosaic.tif"))
    ds = gdal.Open(mosaic.orthomosaic)
    assert ds.GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE") == "COG"
    assert ds.RasterCount == 4 and ds.GetRasterBand(1).DataType == gdal.GDT_Byte
    assert ds.GetRasterBand(4).GetColorInterpretation() == gdal.GCI_AlphaBand
    assert ds.GetRasterBand(1).GetOverviewCount() >= 1
    assert "32633" in ds.GetProjection() or "UTM zone 33N" in ds.GetProjection()
    assert 0.5 < mosaic.valid_fraction <= 1.0
    rec = Workspace.open(ws).stage("orthophoto")
    assert rec["status"] == DONE and rec["outputs"]["orthomosaic"] == "orthomosaic.tif"
    assert rec["results"]["images"] == 15
    assert not [n for n in os.listdir(ws) if n.startswith((".partial-", ".work-", ".ortho-work-"))]


def test_mosaic_ground_marks_within_one_gsd(scene, mosaic):
    """The GCP marks (and 120 ground points) sit where they belong: RMSE within 1 GSD (in fact ~0.2 cell)."""
    block = scene[0]
    arr, gt = _read(mosaic.orthomosaic)
    res = gt[1]
    marks = [_shift_vs_truth(block, arr, gt, p.world[0], p.world[1]) for p in block.gcps if p.kind == "ground"]
    marks = np.array([m for m in marks if m])
    assert len(marks) >= 5
    print(f"\nground marks: {len(marks)}, RMSE {_rmse(marks) * res / block.gsd:.2f} GSD")
    assert _rmse(marks) * res <= block.gsd, marks
    ground, _ = _ground_shifts(block, mosaic.orthomosaic)
    assert len(ground) >= 80
    print(f"ground points: {len(ground)}, RMSE {_rmse(ground) * res / block.gsd:.2f} GSD, mean "
          f"{ground[:, :2].mean(axis=0).round(3)} cells")
    assert _rmse(ground) * res <= 0.5 * block.gsd
    assert np.all(np.abs(ground[:, :2].mean(axis=0)) < 0.15)  # no systematic offset


def test_roof_corners_do_not_lean(scene, mosaic):
    """Roof corners of the box buildings at their true position: RMSE within 1.5 GSD."""
    block = scene[0]
    arr, gt = _read(mosaic.orthomosaic)
    s = [_shift_vs_truth(block, arr, gt, x, y, 24, 0.1) for x, y in _roof_corners(block)]
    s = np.array([v for v in s if v and v[2] > 0.3])
    assert len(s) >= 8, s
    print(f"\nroof corners: {len(s)}, RMSE {_rmse(s) * gt[1] / block.gsd:.2f} GSD")
    assert _rmse(s) * gt[1] <= 1.5 * block.gsd, s


def _seam_points(mosaic, count=30):
    """Cells on the borders between the which-image polygons: (x, y, image a, image b)."""
    ds = gdal.OpenEx(mosaic.seamlines)
    lyr = ds.GetLayer(0)
    names = {}
    for f in lyr:
        names[f.GetField("label")] = f.GetField("image")
    ref = gdal.Open(mosaic.orthomosaic)
    gt = ref.GetGeoTransform()
    mem = gdal.GetDriverByName("MEM").Create("", ref.RasterXSize, ref.RasterYSize, 1, gdal.GDT_Int32)
    mem.SetGeoTransform(gt)
    mem.SetProjection(ref.GetProjection())
    mem.GetRasterBand(1).Fill(-1)
    gdal.Rasterize(mem, mosaic.seamlines, attribute="label")
    lab = mem.ReadAsArray()
    edge = (lab[:, 1:] != lab[:, :-1]) & (lab[:, 1:] >= 0) & (lab[:, :-1] >= 0)
    rr, cc = np.nonzero(edge)
    rng = np.random.default_rng(2)
    pick = rng.permutation(len(rr))[:count * 4]
    pts = []
    for k in pick:
        r, c = rr[k], cc[k]
        pts.append((gt[0] + (c + 0.5) * gt[1], gt[3] + (r + 0.5) * gt[5], names[lab[r, c]], names[lab[r, c + 1]]))
    return pts


def test_no_seam_step(scene, mosaic):
    """Across every sampled seamline the two images' true orthophotos agree within 1 px, and the mosaic there
    is where the truth is."""
    block = scene[0]
    folder = mosaic.per_image_folder
    arr, gt = _read(mosaic.orthomosaic)
    steps, trueish = [], []
    cache = {}
    for x, y, a, b in _seam_points(mosaic):
        pair = []
        for name in (a, b):
            if name not in cache:
                cache[name] = _read(os.path.join(folder, os.path.splitext(name)[0] + ".tif"))
            pair.append(cache[name])
        patches = []
        for pa, pg in pair:
            c = int(round((x - pg[0]) / pg[1] - 0.5)) - 16  # the same cells in both (sub-grids of one grid)
            r = int(round((y - pg[3]) / pg[5] - 0.5)) - 16
            if r < 0 or c < 0 or r + 32 > pa.shape[1] or c + 32 > pa.shape[2] or (pa[-1, r:r + 32, c:c + 32] == 0).any():
                break
            patches.append(pa[0, r:r + 32, c:c + 32])
        if len(patches) == 2:
            dx, dy, resp = _shift(patches[0], patches[1])
            if resp > 0.3:
                steps.append(math.hypot(dx, dy))
        s = _shift_vs_truth(block, arr, gt, x, y)
        if s and s[2] > 0.3:
            trueish.append(s)
        if len(steps) >= 25:
            break
    assert len(steps) >= 10
    print(f"\nseam steps: {len(steps)} points, median {np.median(steps):.2f} px, max {max(steps):.2f} px; mosaic at "
          f"the seams vs truth RMSE {_rmse(np.array(trueish)):.2f} px")
    assert max(steps) <= 1.0, steps
    assert _rmse(np.array(trueish)) <= 0.5


def test_hidden_cells_are_nodata_in_the_per_image_orthophoto(scene, mosaic):
    """Around the buildings, what the truth says a camera cannot see is nodata in its orthophoto, and what it
    sees is there: no doubled roofs, no holes beyond the occluded ground."""
    block = scene[0]
    arr, gt = _read(os.path.join(mosaic.per_image_folder, "S2_02.tif"))
    shot = block.shot("S2_02.jpg")
    h, w = arr.shape[1:]
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    x = gt[0] + (cols + 0.5) * gt[1] - syn.ORIGIN[0]
    y = gt[3] + (rows + 0.5) * gt[5] - syn.ORIGIN[1]
    near = np.zeros(x.shape, dtype=bool)
    for b in block.scene.buildings:
        near |= b.contains(x, y, 6.0) & ~b.contains(x, y, -0.3)  # around and on the walls, not the roof inside
    # away from the roof edges (the DSM's ramp between roof and ground is one DSM cell wide)
    edge = np.zeros(x.shape, dtype=bool)
    for b in block.scene.buildings:
        edge |= b.contains(x, y, 0.25) & ~b.contains(x, y, -0.25)
    sel = near & ~edge
    xs, ys = x[sel], y[sel]
    xyz = np.column_stack([xs, ys, block.scene.height_at(xs, ys)])
    truth_ok, px = block.visible(shot, xyz, margin=1.0)
    inside = CAMERA.inside(px, 1.0)
    ortho_ok = arr[-1][sel] > 0
    hidden = ~truth_ok & inside
    assert hidden.sum() > 200  # the scene has occlusions for this camera
    print(f"\nhidden cells shown {(ortho_ok & hidden).sum()} / {hidden.sum()}, visible cells lost "
          f"{(~ortho_ok & truth_ok & inside).sum()} / {(truth_ok & inside).sum()}")
    assert (ortho_ok & hidden).mean() / hidden.mean() < 0.05  # hidden cells shown: < 5 %
    seen = truth_ok & inside
    assert (~ortho_ok & seen).sum() / seen.sum() < 0.03  # visible cells lost: < 3 %


def test_masked_pixels_stay_nodata(scene, tmp_path):
    """<workspace>/masks/<image>.png (white = use, as core.scans writes them): masked pixels give no data."""
    block, _root, images, dsm, _ws = scene
    ws = make_workspace(str(tmp_path / "ws"), block, images, names=["S2_02.jpg", "S2_03.jpg"])
    os.makedirs(os.path.join(ws, "masks"))
    mask = np.full((CAMERA.height, CAMERA.width), 255, np.uint8)
    mask[:, : CAMERA.width // 2] = 0
    cv2.imwrite(os.path.join(ws, "masks", "S2_02.jpg.png"), mask)
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, resolution=0.2, images_filter="S2_02.jpg",
                                                      per_image_folder=str(tmp_path / "per")))
    a, gt = _read(os.path.join(str(tmp_path / "per"), "S2_02.tif"))
    h, w = a.shape[1:]
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    x = gt[0] + (cols + 0.5) * gt[1] - syn.ORIGIN[0]
    y = gt[3] + (rows + 0.5) * gt[5] - syn.ORIGIN[1]
    xyz = np.column_stack([x.ravel(), y.ravel(), block.scene.height_at(x.ravel(), y.ravel())])
    px, depth = block.project(block.shot("S2_02.jpg"), xyz)
    valid = a[-1].ravel() > 0
    left = CAMERA.inside(px, 2.0) & (px[:, 0] < CAMERA.width / 2 - 2)
    right = CAMERA.inside(px, 2.0) & (px[:, 0] > CAMERA.width / 2 + 2)
    assert left.sum() > 1000 and not valid[left].any()
    assert valid[right].mean() > 0.9
    assert 0.2 < res.valid_fraction < 0.7


def test_which_image_layer_names_images(scene, mosaic):
    ds = gdal.OpenEx(mosaic.seamlines)
    lyr = ds.GetLayer(0)
    images = {f.GetField("image") for f in lyr}
    assert images <= set(scene[0].names) and len(images) >= 8
    assert lyr.GetSpatialRef() is not None and lyr.GetGeomType() in (6, -2147483642)  # one MultiPolygon per image


def test_subset_multiband_and_options(scene, tmp_path):
    """A subset by wildcard, multi-band blending, coarser resolution; all-images filter errors are clear."""
    block, _root, _images, dsm, ws = scene
    out = str(tmp_path / "strip2.tif")
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, images_filter="S2_*, !S2_05.jpg", resolution=0.25,
                                                      blending="multiband", output=out))
    assert sorted(res.images) == [f"S2_0{i}.jpg" for i in range(1, 5)]
    assert res.resolution == 0.25
    ground, cell = _ground_shifts(block, out, count=40, n=16)
    assert len(ground) >= 20 and _rmse(ground) * cell <= block.gsd
    with pytest.raises(OrthoError, match="matches none"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, images_filter="NIR_*", output=str(tmp_path / "x.tif")))


def test_select_cameras_by_name_wildcard_and_group():
    cams = [OrthoCamera(n, n, gcam.Intrinsics.simple(10, 10, 10), gcam.Pose(np.eye(3), np.zeros(3)), cid)
            for n, cid in (("a1.jpg", 1), ("a2.jpg", 1), ("n1.tif", 2), ("n2.tif", 2))]
    groups = [{"camera_id": 1, "model": "FC300X", "images": ["a1.jpg", "a2.jpg"]},
              {"camera_id": 2, "model": "Sequoia NIR", "images": ["n1.tif", "n2.tif"]}]
    names = lambda f: [c.name for c in select_cameras(cams, f, groups)]  # noqa: E731
    assert names("") == ["a1.jpg", "a2.jpg", "n1.tif", "n2.tif"]
    assert names("A*.JPG") == ["a1.jpg", "a2.jpg"]
    assert names("group:nir") == ["n1.tif", "n2.tif"]
    assert names("group:1; n2.tif") == ["a1.jpg", "a2.jpg", "n2.tif"]
    assert names("*, !a2.jpg") == ["a1.jpg", "n1.tif", "n2.tif"]
    with pytest.raises(OrthoError, match="matches none"):
        names("zzz*")


def test_ortho_options_are_checked_when_made_and_carry_the_paths(tmp_path):
    """OrthoOptions are the orthophoto stage's only settings (issue 35): a bad value is refused when they are
    made, naming the setting; the mosaic takes its DSM and output from them and names the one missing."""
    from core.ortho.mosaic import build_orthomosaic

    with pytest.raises(OrthoError, match="BLENDING 'smooth'"):
        OrthoOptions(blending="smooth")
    with pytest.raises(OrthoError, match="RESOLUTION"):
        OrthoOptions(resolution=-1.0)
    with pytest.raises(OrthoError, match="tile size"):
        OrthoOptions(tile=16)
    opt = OrthoOptions(blending="MultiBand", resolution=1)
    assert opt.blending == "multiband" and isinstance(opt.resolution, float)
    with pytest.raises(OrthoError, match="output path"):
        build_orthomosaic([], "EPSG:32632", [0.0, 0.0, 0.0], OrthoOptions(dsm_path=str(tmp_path / "dsm.tif")))
    assert not os.listdir(tmp_path)


def test_seamlines_move_to_where_the_images_agree():
    """Two images, equal view cost at column 20, but they disagree (a moving object) on columns 17-23: the seam
    leaves that band."""
    h, w = 20, 40
    x = np.arange(w, dtype=np.float32)[None, :].repeat(h, 0)
    costs = [0.005 * x, 0.005 * (w - x)]
    rng = np.random.default_rng(0)
    base = (100 + 20 * rng.random((h, w))).astype(np.float32)
    other = base.copy()
    other[:, 17:24] += 80.0
    labels = np.where(x < 20, 0, 1).astype(np.int32)
    windows = [(0, 0, h, w), (0, 0, h, w)]
    before = planning._seam_disagreement(labels, windows, [base, other], 255.0)
    moved = planning._refine_seams(labels, windows, costs, [base, other], 255.0, 10)
    after = planning._seam_disagreement(moved, windows, [base, other], 255.0)
    cols = [int(np.flatnonzero(row == 1)[0]) for row in moved]
    assert all(c <= 17 or c >= 24 for c in cols), cols
    assert after < 0.2 * before


# ---------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------

def _shifted_dsm(src, dst, dx=0.0, fill=None, crs=None):
    z, gt, _wkt = dsmmod.read_dsm(src)
    if fill is not None:
        z[:] = fill
    gt = (gt[0] + dx, gt[1], gt[2], gt[3], gt[4], gt[5])
    return dsmmod.write_cog(dst, z, gt, crs or syn.CRS)


def test_dsm_that_does_not_cover_the_images_is_refused(scene, tmp_path):
    _block, _root, _images, dsm, ws = scene
    far = _shifted_dsm(dsm, str(tmp_path / "far.tif"), dx=20000.0)
    with pytest.raises(OrthoError, match="does not cover"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=far, output=str(tmp_path / "m.tif")))
    assert Workspace.open(ws).stage("orthophoto")["status"] == "failed"
    assert not os.path.exists(tmp_path / "m.tif")


def test_all_nodata_dsm_is_refused(scene, tmp_path):
    _block, _root, _images, dsm, ws = scene
    empty = _shifted_dsm(dsm, str(tmp_path / "empty.tif"), fill=np.nan)
    with pytest.raises(OrthoError, match="no valid height"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=empty, output=str(tmp_path / "m.tif")))


def test_partial_dsm_warns_and_leaves_nodata(scene, tmp_path):
    block, _root, _images, dsm, _ws = scene
    z, gt, _ = dsmmod.read_dsm(dsm)
    z[:, : z.shape[1] // 2] = np.nan  # the western half has no height
    half = dsmmod.write_cog(str(tmp_path / "half.tif"), z, gt, syn.CRS)
    ws2 = make_workspace(str(tmp_path / "ws"), block, scene[2], names=["S2_01.jpg", "S2_02.jpg", "S2_05.jpg"])
    res = build_orthophoto_workspace(ws2, OrthoOptions(dsm_path=half, resolution=0.3))
    assert any("less than half" in w for w in res.warnings)
    assert 0.05 < res.valid_fraction < 0.9


def test_dsm_gaps_inside_the_data_are_filled_for_the_orthophoto(scene, tmp_path):
    """A hole in the DSM (a tree crown the dense matching missed) takes interpolated heights, so the mosaic has
    no hole there; with the fill switched off the hole stays nodata.  The DSM file is not changed."""
    from osgeo import gdal

    block, _root, _images, dsm, _ws = scene
    z, gt, _ = dsmmod.read_dsm(dsm)
    h, w = z.shape
    yy, xx = np.mgrid[0:h, 0:w]
    hole = (yy - h / 2) ** 2 + (xx - w / 2) ** 2 < (min(h, w) / 8) ** 2
    z[hole] = np.nan
    holed = dsmmod.write_cog(str(tmp_path / "holed.tif"), z, gt, syn.CRS)
    before = open(holed, "rb").read()
    ws2 = make_workspace(str(tmp_path / "ws"), block, scene[2], names=["S2_01.jpg", "S2_02.jpg", "S2_05.jpg"])
    centre_x, centre_y = gt[0] + (w / 2) * gt[1], gt[3] + (h / 2) * gt[5]

    def alpha_at_centre(path):
        ds = gdal.Open(path)
        g = ds.GetGeoTransform()
        c, r = int((centre_x - g[0]) / g[1]), int((centre_y - g[3]) / g[5])
        return ds.GetRasterBand(ds.RasterCount).ReadAsArray(c - 2, r - 2, 5, 5)

    res = build_orthophoto_workspace(ws2, OrthoOptions(dsm_path=holed, resolution=0.3, output=str(tmp_path / "filled.tif")))
    assert any("DSM gaps" in line and "interpolated" in line for line in res.log_lines), res.log_lines
    assert (alpha_at_centre(res.orthomosaic) > 0).all()
    off = build_orthophoto_workspace(ws2, OrthoOptions(dsm_path=holed, resolution=0.3, output=str(tmp_path / "off.tif"),
                                                       fill_dsm_gaps_m=0.0))
    assert (alpha_at_centre(off.orthomosaic) == 0).all()
    assert open(holed, "rb").read() == before
    # the hull rule: a DSM covering half of the area is not extended (test_partial_dsm_warns_and_leaves_nodata)
    path, n = fill_dsm_gaps(holed, str(tmp_path / "f.tif"), 25.0)
    assert n == int(hole.sum()) and path != holed


def test_gap_fill_writes_nothing_into_the_current_directory(tmp_path, monkeypatch):
    """GDAL FillNodata's work rasters stay in memory: run from a read-only current directory (root ignores the
    mode, so it must also stay empty) and from one that no longer exists (where any relative write fails, even
    for root), the gaps are filled all the same."""
    h = w = 200
    yy, xx = np.mgrid[0:h, 0:w]
    z = (10.0 + 0.01 * xx + 0.02 * yy).astype(np.float32)
    hole = (yy - 100) ** 2 + (xx - 100) ** 2 < 20 ** 2
    z[hole] = np.nan
    gt = (500000.0, 0.5, 0.0, 4000000.0, 0.0, -0.5)
    holed = dsmmod.write_cog(str(tmp_path / "holed.tif"), z, gt, syn.CRS)
    truth = (10.0 + 0.01 * xx + 0.02 * yy)[hole]
    readonly = tmp_path / "readonly"
    readonly.mkdir()
    readonly.chmod(0o555)
    monkeypatch.chdir(readonly)
    path, n = fill_dsm_gaps(holed, str(tmp_path / "filled.tif"), 25.0)
    assert n == int(hole.sum()) and path == str(tmp_path / "filled.tif")
    assert os.listdir(readonly) == []
    filled, _, _ = dsmmod.read_dsm(path)
    assert np.abs(filled[hole] - truth).max() < 0.5  # a plane: inverse-distance heights stay near it
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    path, n = fill_dsm_gaps(holed, str(tmp_path / "filled2.tif"), 25.0)
    assert n == int(hole.sum())
    readonly.chmod(0o755)


def test_workspace_without_georeference_or_dsm_is_refused(scene, tmp_path):
    block = scene[0]
    ws = make_workspace(str(tmp_path / "ws"), block, scene[2], names=["S2_01.jpg", "S2_02.jpg"])
    with pytest.raises(OrthoError, match="no DSM"):
        build_orthophoto_workspace(ws)
    w = Workspace.open(ws)
    w.data["stages"]["georeference"] = {"status": "pending"}
    w.save()
    with pytest.raises(OrthoError, match="not georeferenced"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=scene[3]))


class _CancelAfter(NullProgress):
    def __init__(self, n):
        self.n = n
        self.calls = 0

    def report(self, fraction, message=""):
        if message.startswith("tile"):
            self.calls += 1

    def is_cancelled(self):
        return self.calls >= self.n


def test_cancel_leaves_no_mosaic(scene, tmp_path):
    block, _root, images, dsm, _ws = scene
    ws = make_workspace(str(tmp_path / "ws"), block, images, names=["S2_02.jpg", "S2_03.jpg", "S2_04.jpg"])
    with pytest.raises(Cancelled):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, resolution=0.2, tile=64), progress=_CancelAfter(2))
    assert Workspace.open(ws).stage("orthophoto")["status"] == "cancelled"
    assert not [n for n in os.listdir(ws) if n.endswith(".tif") or n.startswith(".")]


# ---------------------------------------------------------------------------
# one image on an existing DSM
# ---------------------------------------------------------------------------

def _image_gcps(block, name, n, seed=3, noise=0.3, bad=None):
    """n ground control points seen in one image (world, EPSG:32633) with noisy observations."""
    shot = block.shot(name)
    rng = np.random.default_rng(seed)
    xy = shot.centre[:2] + rng.uniform(-22, 22, (600, 2))
    xyz = np.column_stack([xy, block.scene.height_at(xy[:, 0], xy[:, 1])])
    ok, px = block.visible(shot, xyz, margin=8.0)
    ok &= ~block.scene.near_feature(xyz[:, 0], xyz[:, 1], 0.5, buildings=False)
    xyz, px = xyz[ok], px[ok]
    # well spread: farthest-point order
    order = [int(np.argmin(np.hypot(*(px - [200, 150]).T)))]
    while len(order) < n:
        d = np.min(np.hypot(px[:, None, 0] - px[order][None, :, 0], px[:, None, 1] - px[order][None, :, 1]), axis=1)
        order.append(int(np.argmax(d)))
    pts = []
    for k, i in enumerate(order):
        w = xyz[i] + syn.ORIGIN
        o = px[i] + rng.normal(0.0, noise, 2)
        pts.append(gcpmod.GroundPoint(f"T{k + 1}", float(w[0]), float(w[1]), float(w[2]),
                                      observations=[gcpmod.Observation(name, float(o[0]), float(o[1]))]))
    if bad is not None:
        pts[bad].x += 2.5  # a typo of 2.5 m (~20 px)
    return gcpmod.GCPSet(syn.CRS, pts)


def test_single_image_by_resection_registers_to_the_truth_and_the_mosaic(scene, mosaic, tmp_path):
    """One image alone, 12 GCPs (one of them wrong), the focal length 2 % off and the lens distortion unknown:
    the bad GCP is named, k1 estimated, and the orthophoto registers to the truth and to the mosaic."""
    block, _root, images, dsm, _ws = scene
    gcps = _image_gcps(block, SINGLE, 12, bad=4)
    out = str(tmp_path / "single.tif")
    r = orthorectify_image(SingleImageOptions(os.path.join(images, SINGLE), out, dsm, gcps=gcps, focal_px=331.0,
                                              residuals_path=str(tmp_path / "res.gpkg")))
    assert r.source == "resection" and r.outliers == ["T5"]
    assert r.rmse_px < 0.8
    assert r.estimated_intrinsics and abs(r.orientation["k1"] - CAMERA.k1) < 0.02
    ground, cell = _ground_shifts(block, out, count=80)
    assert len(ground) >= 50
    print(f"\nsingle image by resection: GCP RMSE {r.rmse_px:.2f} px, outliers {r.outliers}, k1 "
          f"{r.orientation['k1']:+.4f}; vs truth RMSE {_rmse(ground) * cell / block.gsd:.2f} GSD")
    assert _rmse(ground) * cell <= 0.6 * block.gsd
    # against the mosaic (both measured in the same grid cells)
    a, ga = _read(out)
    m, gm = _read(mosaic.orthomosaic)
    shifts = []
    rng = np.random.default_rng(4)
    for _ in range(200):
        r_, c_ = rng.integers(20, a.shape[1] - 52), rng.integers(20, a.shape[2] - 52)
        x, y = ga[0] + c_ * ga[1], ga[3] + r_ * ga[5]
        cm, rm = int(round((x - gm[0]) / gm[1])), int(round((y - gm[3]) / gm[5]))
        if (a[-1, r_:r_ + 32, c_:c_ + 32] == 0).any() or rm < 0 or cm < 0 or rm + 32 > m.shape[1] or \
                cm + 32 > m.shape[2] or (m[-1, rm:rm + 32, cm:cm + 32] == 0).any():
            continue
        dx, dy, resp = _shift(m[0, rm:rm + 32, cm:cm + 32], a[0, r_:r_ + 32, c_:c_ + 32])
        if resp > 0.3:
            shifts.append(math.hypot(dx, dy))
    print(f"single image vs mosaic: {len(shifts)} windows, median {np.median(shifts):.2f} px, 90 % "
          f"{np.percentile(shifts, 90):.2f} px")
    assert len(shifts) >= 30 and float(np.median(shifts)) < 0.6 and np.percentile(shifts, 90) < 1.5
    ds = gdal.OpenEx(str(tmp_path / "res.gpkg"))
    feats = list(ds.GetLayer(0))
    assert len(feats) == 12
    bad = next(f for f in feats if f.GetField("name") == "T5")
    assert bad.GetField("used") == 0 and bad.GetField("res_px") > 10


def test_single_image_with_known_orientation_and_a_dsm_in_another_crs(scene, tmp_path):
    """x y z omega phi kappa + interior orientation (Pix4D-style table); the DSM in EPSG:3035 is reprojected
    on the fly; the 16-bit single-band image stays 16-bit single-band."""
    block, _root, images, dsm, _ws = scene
    shot = block.shot(SINGLE)
    om, ph, ka = gcam.opk_from_rotation(shot.rotation)
    c = shot.centre + syn.ORIGIN
    orient = tmp_path / "opk.txt"
    orient.write_text("# crs: EPSG:32633\nimageName X Y Z Omega Phi Kappa focal_px cx cy k1 k2 p1 p2\n"
                      f"other.jpg 0 0 0 0 0 0 1 1 1 0 0 0 0\n"
                      f"{os.path.splitext(SINGLE)[0]}.tif {c[0]:.4f} {c[1]:.4f} {c[2]:.4f} {om:.6f} {ph:.6f} {ka:.6f} "
                      f"{CAMERA.fx} {CAMERA.cx} {CAMERA.cy} {CAMERA.k1} {CAMERA.k2} {CAMERA.p1} {CAMERA.p2}\n")
    grey = cv2.imread(os.path.join(images, SINGLE), cv2.IMREAD_GRAYSCALE).astype(np.uint16) * 257
    img16 = str(tmp_path / (os.path.splitext(SINGLE)[0] + ".tif"))
    cv2.imwrite(img16, grey)
    dsm3035 = str(tmp_path / "dsm_3035.tif")
    gdal.Warp(dsm3035, dsm, dstSRS="EPSG:3035", resampleAlg="bilinear")
    out = str(tmp_path / "single16.tif")
    r = orthorectify_image(SingleImageOptions(img16, out, dsm3035, orientation=str(orient)))
    assert r.source == "orientation" and any("reprojected" in line for line in r.log_lines)
    ds = gdal.Open(out)
    assert ds.RasterCount == 2 and ds.GetRasterBand(1).DataType == gdal.GDT_UInt16
    assert ds.GetRasterBand(2).GetColorInterpretation() == gdal.GCI_AlphaBand
    assert ds.GetRasterBand(1).ReadAsArray().max() > 255
    assert "32633" in ds.GetProjection() or "UTM zone 33N" in ds.GetProjection()
    ground, cell = _ground_shifts(block, out, count=80)
    print(f"\nknown orientation, DSM in EPSG:3035: vs truth RMSE {_rmse(ground) * cell / block.gsd:.2f} GSD")
    assert len(ground) >= 50 and _rmse(ground) * cell <= 0.4 * block.gsd


def test_planar_rectification_and_how_far_it_is_off(scene, tmp_path):
    block, _root, images, dsm, _ws = scene
    gcps = _image_gcps(block, SINGLE, 8)
    r = orthorectify_image(SingleImageOptions(os.path.join(images, SINGLE), str(tmp_path / "planar.tif"), dsm,
                                              gcps=gcps, focal_px=325.0, mode="planar",
                                              residuals_path=str(tmp_path / "res.gpkg")))
    assert r.mode == "planar" and r.planar_rmse_m < 0.5
    pe = r.planar_error
    # the roofs stand 4-8 m high: a plane through ground points misplaces them by metres
    assert pe["max_m"] > 0.8 and pe["relief_m"] > 4.0 and pe["mean_m"] < pe["p95_m"] <= pe["max_m"]
    assert any("planar rectification is off" in line for line in r.log_lines)
    print("\n" + r.log_lines[-2])
    assert os.path.isfile(tmp_path / "planar.tif")


def test_too_few_gcps_name_how_many_are_needed(scene, tmp_path):
    _block, _root, images, dsm, _ws = scene
    gcps = _image_gcps(scene[0], SINGLE, 3)
    with pytest.raises(OrthoError, match=r"at least 4 ground control points .* found 3"):
        orthorectify_image(SingleImageOptions(os.path.join(images, SINGLE), str(tmp_path / "o.tif"), dsm, gcps=gcps,
                                              focal_px=325.0))
    with pytest.raises(OrthoError, match="needs a DSM"):
        orthorectify_image(SingleImageOptions(os.path.join(images, SINGLE), str(tmp_path / "o.tif"), None,
                                              gcps=gcps))
    gcps.points[0].observations[0].image = "another.jpg"
    with pytest.raises(OrthoError, match="found 2"):
        orthorectify_image(SingleImageOptions(os.path.join(images, SINGLE), str(tmp_path / "o.tif"), dsm, gcps=gcps,
                                              focal_px=325.0, mode="planar"))
    assert not os.path.exists(tmp_path / "o.tif")


def test_orientation_files_are_read(tmp_path):
    p = tmp_path / "o.json"
    p.write_text(json.dumps({"images": {"A.JPG": {"X": 1, "Y": 2, "Z": 3, "omega": 0.5, "phi": 1, "kappa": 90}},
                             "crs": "EPSG:32617", "focal_mm": 8.8, "sensor_width_mm": 13.2}))
    o = read_orientation(str(p), "a.jpg")
    assert o["x"] == 1 and o["kappa"] == 90 and o["crs"] == "EPSG:32617" and o["focal_mm"] == 8.8
    q = tmp_path / "o.txt"
    q.write_text("EPSG:32617\n500000, 4600000, 150, 1, 2, 3\n")
    o = read_orientation(str(q), "whatever.jpg")
    assert o["z"] == 150 and o["phi"] == 2 and o["crs"] == "EPSG:32617"
    q.write_text("x y z omega\n1 2 3 4\n")
    with pytest.raises(OrthoError, match="lacks phi, kappa"):
        read_orientation(str(q), "a.jpg")


# ---------------------------------------------------------------------------
# Processing (pytest-qgis, offscreen)
# ---------------------------------------------------------------------------

def test_processing_algorithms(scene, plugin, tmp_path):
    from qgis import processing
    from qgis.core import QgsApplication, QgsProcessingException, QgsRasterLayer, QgsVectorLayer

    block, _root, images, dsm, ws = scene
    reg = QgsApplication.processingRegistry()
    alg = reg.algorithmById("archaeoortho:buildorthophoto")
    assert alg is not None and alg.shortHelpString()
    assert {"WORKSPACE", "DSM", "IMAGES_FILTER", "RESOLUTION", "BLENDING", "OUTPUT", "PER_IMAGE_FOLDER",
            "SEAMLINES"} <= {p.name() for p in alg.parameterDefinitions()}
    alg2 = reg.algorithmById("archaeoortho:orthorectifyimage")
    assert {"IMAGE", "DSM", "GCPS", "ORIENTATION", "FOCAL_MM", "SENSOR_WIDTH_MM", "MODE", "OUTPUT", "RESIDUALS"} <= {
        p.name() for p in alg2.parameterDefinitions()}

    ws2 = str(tmp_path / "ws")
    shutil.copytree(ws, ws2, ignore=shutil.ignore_patterns("ortho", "*.tif", "*.gpkg"))
    res = processing.run("archaeoortho:buildorthophoto", {
        "WORKSPACE": ws2, "DSM": dsm, "IMAGES_FILTER": "S2_0[234]*", "RESOLUTION": 0.3, "BLENDING": 2,
        "SEAMLINES": str(tmp_path / "seams.gpkg"), "PER_IMAGE_FOLDER": str(tmp_path / "per")})
    assert res["WORKSPACE"] == ws2 and res["IMAGES_USED"] == 3
    assert os.path.samefile(res["OUTPUT"], os.path.join(ws2, "orthomosaic.tif"))
    layer = QgsRasterLayer(res["OUTPUT"], "mosaic")
    assert layer.isValid() and layer.crs().authid() == "EPSG:32633"
    assert QgsVectorLayer(res["SEAMLINES"], "s").featureCount() >= 3
    assert len(os.listdir(res["PER_IMAGE_FOLDER"])) == 3
    with pytest.raises(QgsProcessingException, match="matches none"):
        processing.run("archaeoortho:buildorthophoto", {"WORKSPACE": ws2, "DSM": dsm, "IMAGES_FILTER": "X*"})

    gcps = _image_gcps(block, SINGLE, 6)
    gcp_file = str(tmp_path / "gcp_list.txt")
    gcpmod.write_gcps(gcps, gcp_file)
    res = processing.run("archaeoortho:orthorectifyimage", {
        "IMAGE": os.path.join(images, SINGLE), "DSM": dsm, "GCPS": gcp_file, "FOCAL_MM": 3.25,
        "SENSOR_WIDTH_MM": 4.0, "OUTPUT": str(tmp_path / "single.tif"), "RESIDUALS": str(tmp_path / "res.gpkg")})
    assert QgsRasterLayer(res["OUTPUT"], "o").isValid()
    assert res["RMSE_PX"] < 1.5
    assert QgsVectorLayer(res["RESIDUALS"], "r").featureCount() == 6
    few = _image_gcps(block, SINGLE, 3)
    gcpmod.write_gcps(few, gcp_file)
    with pytest.raises(QgsProcessingException, match="at least 4"):
        processing.run("archaeoortho:orthorectifyimage", {
            "IMAGE": os.path.join(images, SINGLE), "DSM": dsm, "GCPS": gcp_file, "FOCAL_MM": 3.25,
            "SENSOR_WIDTH_MM": 4.0, "OUTPUT": str(tmp_path / "few.tif")})


def test_image_window_reads_pixel_interleaved_and_remaps_views(tmp_path):
    """_read_window gives (rows, cols, bands) as the file holds them (1, 3 and 5 bands, 8 and 16 bit), and remap_photo
    of a window view (not contiguous: no copy is made of it) equals that of a copy, pixel for pixel."""
    from core.ortho.pixels import _read_window, remap_photo

    rng = np.random.default_rng(3)
    for bands, dtype, gdt in ((1, np.uint8, gdal.GDT_Byte), (3, np.uint8, gdal.GDT_Byte),
                              (5, np.uint16, gdal.GDT_UInt16)):
        a = rng.integers(0, 250, (bands, 40, 60)).astype(dtype) * (1 + 200 * (dtype == np.uint16))
        path = str(tmp_path / f"im{bands}.tif")
        ds = gdal.GetDriverByName("GTiff").Create(path, 60, 40, bands, gdt)
        for b in range(bands):
            ds.GetRasterBand(b + 1).WriteArray(a[b])
        ds = None
        win = _read_window(path, 7, 5, 50, 31)
        assert win.shape == (26, 43, bands) and win.dtype == dtype
        assert np.array_equal(win, np.moveaxis(a, 0, -1)[5:31, 7:50])
        view = _read_window(path, 0, 0, 60, 40)[5:31, 7:50]
        assert not view.flags["C_CONTIGUOUS"]
        mx, my = rng.uniform(0, 42, 500), rng.uniform(0, 25, 500)
        assert np.array_equal(remap_photo(view, mx, my, "bilinear"), remap_photo(np.ascontiguousarray(view), mx, my, "bilinear"))
        got = remap_photo(view, np.array([3.0, 40.0]), np.array([2.0, 20.0]), "nearest")
        assert np.array_equal(got, np.stack([view[2, 3], view[20, 40]]).astype(np.float32))
