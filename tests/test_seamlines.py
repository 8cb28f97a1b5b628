"""No holes inside the mosaic, and editable seamlines taken back by Build orthophoto (issue 14 items 4 and 5), on a
small synthetic block (2 strips of 4 images with buildings) with the true DSM.

"Covered" is defined here without the mosaic code: a cell is covered when the DSM has a height there (bilinear
between its cell centres) and that point, projected through the block's true cameras, lands inside an image
(1 px from its border).  An edited seamline polygon is checked against the per-image orthophotos: inside it the
mosaic's pixels are those of the image it names."""
import json
import os
import shutil
import subprocess

import numpy as np
import pytest
from osgeo import gdal, ogr, osr
from scipy import ndimage

from core.ortho.options import OrthoOptions
from core.ortho.seamlines import SeamlineError, read_seamline_edits
from core.ortho.stage import build_orthophoto_workspace
from core.ortho.writer import interior_nodata
from tests import synthetic as syn
from tests.test_ortho import CAMERA, make_workspace, truth_dsm

gdal.UseExceptions()
ogr.UseExceptions()

# exact comparisons with the per-image orthophotos: no exposure gains, no radiometric correction
PLAIN = dict(exposure=False, **({"radiometry": False} if "radiometry" in OrthoOptions.__dataclass_fields__ else {}))


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("seamlines synthetic")
    block = syn.vertical_block(seed=1, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=4, forward_overlap=0.7,
                               side_overlap=0.4, gcp_grid=(3, 2), roofs=1)
    images = str(root / "images")
    block.render(images)
    dsm = truth_dsm(block, str(root / "truth_dsm.tif"))
    ws = make_workspace(str(root / "ws"), block, images)
    return block, str(root), images, dsm, ws


@pytest.fixture(scope="module")
def auto(scene):
    """The automatic mosaic with its per-image orthophotos and seamlines (no gains: exact comparisons)."""
    _block, root, _images, dsm, ws = scene
    return build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, output=os.path.join(root, "auto.tif"),
                                                       per_image_folder=os.path.join(root, "per"),
                                                       seamlines=os.path.join(root, "seamlines.gpkg"), **PLAIN))


def _per(result, name):
    """The per-image orthophoto of image ``name`` on the mosaic's grid (bands + alpha, 0 outside it)."""
    mosaic = gdal.Open(result.orthomosaic)
    gt, w, h = mosaic.GetGeoTransform(), mosaic.RasterXSize, mosaic.RasterYSize
    arr, g = _read(os.path.join(result.per_image_folder, os.path.splitext(name)[0] + ".tif"))
    dc, dr = (g[0] - gt[0]) / gt[1], (g[3] - gt[3]) / gt[5]
    assert abs(dc - round(dc)) < 1e-6 and abs(dr - round(dr)) < 1e-6 and g[1] == gt[1]
    dc, dr = int(round(dc)), int(round(dr))
    out = np.zeros((arr.shape[0], h, w), dtype=np.float32)
    r0, c0 = max(0, dr), max(0, dc)
    r1, c1 = min(h, dr + arr.shape[1]), min(w, dc + arr.shape[2])
    out[:, r0:r1, c0:c1] = arr[:, r0 - dr:r1 - dr, c0 - dc:c1 - dc]
    return out, gt


def _read(path):
    ds = gdal.Open(path)
    return ds.ReadAsArray().astype(np.float32), ds.GetGeoTransform()


def _covered(block, dsm, gt, shape):
    """Cells with a DSM height whose point lands inside at least one image (the block's true cameras)."""
    h, w = shape
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    x = gt[0] + (cols + 0.5) * gt[1]
    y = gt[3] + (rows + 0.5) * gt[5]
    d = gdal.Open(dsm)
    dg, dz = d.GetGeoTransform(), d.ReadAsArray().astype(np.float64)
    fr, fc = (y - dg[3]) / dg[5] - 0.5, (x - dg[0]) / dg[1] - 0.5
    z = ndimage.map_coordinates(dz, [fr.ravel(), fc.ravel()], order=1, mode="constant", cval=np.nan)
    xyz = np.column_stack([x.ravel() - syn.ORIGIN[0], y.ravel() - syn.ORIGIN[1], z - syn.ORIGIN[2]])
    fin = np.flatnonzero(np.isfinite(z))
    cov = np.zeros(len(z), dtype=bool)
    corner = block._corner_radius()
    for shot in block.shots:
        px, depth = block.project(shot, xyz[fin])
        ok = (depth > 0) & block.camera.inside(px, 1.0)
        ok &= np.hypot(*(block.to_camera_xy(shot, xyz[fin]).T)) <= 1.001 * corner  # no fold-back of the lens
        cov[fin[ok]] = True
    return cov.reshape(h, w)


def test_no_nodata_where_the_dsm_and_an_image_cover_the_cell(scene, auto, tmp_path):
    block, _root, _images, dsm, ws = scene
    arr, gt = _read(auto.orthomosaic)
    covered = _covered(block, dsm, gt, arr.shape[1:])
    holes = covered & (arr[-1] == 0)
    print(f"\ncovered cells {covered.sum()}, nodata among them {holes.sum()}")
    assert covered.sum() > 0.6 * covered.size
    assert holes.sum() == 0
    assert "hidden from every image" in " ".join(auto.log_lines)
    # the same block with cells hidden from every image left nodata (the strict true orthophoto): the holes
    # beside the buildings and along their walls that the test counts
    strict = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, output=str(tmp_path / "strict.tif"),
                                                         fill_hidden=False, **PLAIN))
    s_arr, s_gt = _read(strict.orthomosaic)
    assert s_gt == gt
    s_holes = covered & (s_arr[-1] == 0)
    print(f"without filling the hidden cells: {s_holes.sum()} nodata cells where an image covers the cell")
    assert s_holes.sum() > 200
    # the benchmarks' figure, nodata enclosed by data: what remains is ground beyond the images' edge behind a roof
    # at the block's border (the roof is in an image, the ground behind it in none: not covered, checked above)
    enclosed, enclosed_strict = interior_nodata(auto.orthomosaic), interior_nodata(strict.orthomosaic)
    print(f"nodata enclosed by data: {enclosed} cells, {enclosed_strict} without filling the hidden cells")
    assert enclosed < 0.4 * enclosed_strict
    # elsewhere the two mosaics agree: the fill only adds cells
    both = (s_arr[-1] > 0) & (arr[-1] > 0)
    assert np.abs(s_arr[0][both] - arr[0][both]).max() <= 1


def _layer(path):
    ds = ogr.Open(path)
    lyr = ds.GetLayer(0)
    feats = [(f.GetField("image"), f.GetGeometryRef().Clone()) for f in lyr]
    return ds, lyr, feats


def test_the_seamlines_layer_has_one_polygon_per_image(scene, auto):
    block = scene[0]
    ds, lyr, feats = _layer(auto.seamlines)
    names = [n for n, _ in feats]
    assert len(names) == len(set(names)) and set(names) <= set(block.names) and len(names) >= 6
    assert ogr.GT_Flatten(lyr.GetGeomType()) == ogr.wkbMultiPolygon
    assert lyr.GetSpatialRef().GetAuthorityCode(None) == syn.CRS.split(":")[1]
    union = feats[0][1]
    for _, g in feats[1:]:
        union = union.Union(g)
    total = sum(g.GetArea() for _, g in feats)
    assert abs(total - union.GetArea()) < 1e-6 * total  # the polygons do not overlap
    _arr, gt = _read(auto.orthomosaic)
    valid = _arr[-1] > 0
    assert abs(union.GetArea() - valid.sum() * gt[1] ** 2) < 0.05 * union.GetArea()


def _mask_of(geom, gt, shape):
    mem = gdal.GetDriverByName("MEM").Create("", shape[1], shape[0], 1, gdal.GDT_Byte)
    mem.SetGeoTransform(gt)
    vds = ogr.GetDriverByName("Memory").CreateDataSource("")
    lyr = vds.CreateLayer("p", None, ogr.wkbUnknown)
    f = ogr.Feature(lyr.GetLayerDefn())
    f.SetGeometry(geom)
    lyr.CreateFeature(f)
    gdal.PushErrorHandler("CPLQuietErrorHandler")  # no CRS on either: the same
    gdal.RasterizeLayer(mem, [1], lyr, burn_values=[1])
    gdal.PopErrorHandler()
    return mem.GetRasterBand(1).ReadAsArray() > 0


def _square(gt, r, c, half):
    x0, y0 = gt[0] + (c - half) * gt[1], gt[3] + (r - half) * gt[5]
    x1, y1 = gt[0] + (c + half) * gt[1], gt[3] + (r + half) * gt[5]
    ring = ogr.Geometry(ogr.wkbLinearRing)
    for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)):
        ring.AddPoint_2D(x, y)
    poly = ogr.Geometry(ogr.wkbPolygon)
    poly.AddGeometry(ring)
    return poly


@pytest.fixture(scope="module")
def edit(scene, auto):
    """An edited copy of the seamlines: image B's polygon reshaped to take a 48-cell square of image A's part
    (where B sees the ground), A's polygon left as it was (they overlap: the edit wins); a new polygon naming
    the image farthest away over another part of A's (it sees nothing there: automatic seams stay)."""
    _block, root, _images, _dsm, _ws = scene
    arr, gt = _read(auto.orthomosaic)
    _ds, _lyr, feats = _layer(auto.seamlines)
    area = {n: g.GetArea() for n, g in feats}
    a_name = max(area, key=area.get)
    a_mask = _mask_of(dict(feats)[a_name], gt, arr.shape[1:])
    best = None
    for b_name in area:
        if b_name == a_name:
            continue
        b_valid = _per(auto, b_name)[0][-1] > 0
        dist = ndimage.distance_transform_edt(a_mask & b_valid)
        if best is None or dist.max() > best[0]:
            best = (dist.max(), b_name, np.unravel_index(np.argmax(dist), dist.shape))
    depth, b_name, (r, c) = best
    assert depth > 30, "no part of the largest image's area is seen well by another image"
    square = _square(gt, r, c, 24)
    a_valid = _per(auto, a_name)[0][-1] > 0
    far = min((n for n in area if n not in (a_name, b_name)),
              key=lambda n: (_per(auto, n)[0][-1] > 0)[a_mask & a_valid].mean())
    far_valid = _per(auto, far)[0][-1] > 0
    dist = ndimage.distance_transform_edt(a_mask & ~far_valid & ~_mask_of(square.Buffer(10 * gt[1]), gt, a_mask.shape))
    fr, fc = np.unravel_index(np.argmax(dist), dist.shape)
    assert dist.max() > 12
    path = os.path.join(root, "seamlines-edited.gpkg")
    shutil.copyfile(auto.seamlines, path)
    ds = ogr.Open(path, 1)
    lyr = ds.GetLayer(0)
    for f in lyr:
        if f.GetField("image") == b_name:
            f.SetGeometry(f.GetGeometryRef().Union(square))
            lyr.SetFeature(f)
    f = ogr.Feature(lyr.GetLayerDefn())
    f.SetField("image", os.path.splitext(far)[0])  # the name without its extension is taken too
    f.SetGeometry(ogr.ForceToMultiPolygon(_square(gt, fr, fc, 10)))
    lyr.CreateFeature(f)
    ds = None
    return path, a_name, b_name, far, (r, c), gt


def test_an_edited_polygon_forces_its_image(scene, auto, edit, tmp_path):
    _block, root, _images, dsm, ws = scene
    path, a_name, b_name, far, (r, c), gt = edit
    res = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, output=str(tmp_path / "edited.tif"),
                                                      seamlines=str(tmp_path / "seams-out.gpkg"),
                                                      seamlines_in=path, **PLAIN))
    log = "\n".join(res.log_lines)
    print("\n" + log)
    assert f"seamlines {path}" in log and "given to the image they name" in log
    assert f"naming {far} keep the automatic seams" in log
    new, gt2 = _read(res.orthomosaic)
    old, _ = _read(auto.orthomosaic)
    a_ortho, _ = _per(auto, a_name)
    b_ortho, _ = _per(auto, b_name)
    assert gt2 == gt
    inner = (slice(r - 10, r + 10), slice(c - 10, c + 10))  # the square less the feathering ramp
    diff_b = np.abs(new[:, inner[0], inner[1]] - b_ortho[:, inner[0], inner[1]])[:3]
    print(f"inside the edited square: |mosaic - {b_name}| mean {diff_b.mean():.3f} max {diff_b.max():.0f}; before "
          f"the edit |mosaic - {b_name}| mean {np.abs(old - b_ortho)[:3, inner[0], inner[1]].mean():.3f}, "
          f"|mosaic - {a_name}| mean {np.abs(old - a_ortho)[:3, inner[0], inner[1]].mean():.3f}")
    assert (new[-1][inner] > 0).all() and diff_b.max() <= 1
    assert np.abs(old - a_ortho)[:3, inner[0], inner[1]].max() <= 1  # it was A's before
    assert np.abs(old - b_ortho)[:3, inner[0], inner[1]].mean() > 0.5  # and the two images differ there
    # away from the edits the mosaic is as before
    far_away = np.ones(new.shape[1:], dtype=bool)
    far_away[r - 40:r + 40, c - 40:c + 40] = False
    same = far_away & (old[-1] > 0)
    assert (np.abs(new - old)[:3][:, same] > 1).mean() < 0.01
    # the mosaic's own seamlines now give the square to B: one polygon per image still
    _ds, _lyr, feats = _layer(res.seamlines)
    geoms = dict(feats)
    assert len(geoms) == len(feats)
    centre = ogr.Geometry(ogr.wkbPoint)
    centre.AddPoint_2D(gt[0] + (c + 0.5) * gt[1], gt[3] + (r + 0.5) * gt[5])
    assert geoms[b_name].Contains(centre) and not geoms[a_name].Contains(centre)


def _gpkg(path, rows, field="image", crs=syn.CRS, kind=ogr.wkbPolygon):
    srs = osr.SpatialReference()
    srs.SetFromUserInput(crs)
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(str(path))
    lyr = ds.CreateLayer("edits", srs, kind)
    lyr.CreateField(ogr.FieldDefn(field, ogr.OFTString))
    for value, wkt in rows:
        f = ogr.Feature(lyr.GetLayerDefn())
        f.SetField(field, value)
        f.SetGeometry(ogr.CreateGeometryFromWkt(wkt))
        lyr.CreateFeature(f)
    ds = None
    return str(path)


def test_bad_seamlines_name_the_file_and_the_problem(scene, tmp_path):
    _block, _root, _images, dsm, ws = scene
    names = scene[0].names
    x, y = syn.ORIGIN[0], syn.ORIGIN[1]
    sq = f"POLYGON(({x} {y},{x + 5} {y},{x + 5} {y + 5},{x} {y + 5},{x} {y}))"
    cases = [
        (_gpkg(tmp_path / "field.gpkg", [("S1_02.jpg", sq)], field="photo"), r"no field 'image'.*photo"),
        (_gpkg(tmp_path / "name.gpkg", [("S1_2.jpg", sq)]), r"'S1_2.jpg'.*did you mean 'S1_02.jpg'"),
        (_gpkg(tmp_path / "crs.gpkg", [("S1_02.jpg", "POLYGON((12 45,12.1 45,12.1 45.1,12 45))")], crs="EPSG:4326"),
         r"in EPSG:4326 .*the mosaic in EPSG:32633"),
        (_gpkg(tmp_path / "points.gpkg", [("S1_02.jpg", f"POINT({x} {y})")], kind=ogr.wkbPoint), r"not a polygon"),
        (str(tmp_path / "missing.gpkg"), "does not exist"),
    ]
    for path, pattern in cases:
        with pytest.raises(SeamlineError, match=pattern) as e:
            read_seamline_edits(path, names, syn.CRS)
        assert path in str(e.value)
    # through the stage: refused before any work, the stage recorded failed with that message
    with pytest.raises(SeamlineError, match="did you mean"):
        build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, output=str(tmp_path / "x.tif"),
                                                    seamlines_in=cases[1][0]))
    assert not os.path.exists(tmp_path / "x.tif")
    # a QGIS layer source with its layer name; an empty image leaves the polygon to the automatic seams
    path = _gpkg(tmp_path / "ok.gpkg", [("s1_02.JPG", sq), (None, sq)])
    edits = read_seamline_edits(path + "|layername=edits", names, syn.CRS)
    assert [n for n, _ in edits.polygons] == ["S1_02.jpg"] and edits.skipped == 1


def test_qgis_process_takes_the_edited_seamlines(scene, auto, edit, tmp_path):
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    _block, _root, _images, dsm, ws = scene
    path, a_name, b_name, _far, (r, c), gt = edit
    ws2 = str(tmp_path / "ws")
    shutil.copytree(ws, ws2, ignore=shutil.ignore_patterns("*.tif", "*.gpkg", "ortho"))

    def run(*args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:buildorthophoto", "--", f"WORKSPACE={ws2}",
                               f"DSM={dsm}", *args], env=env, capture_output=True, text=True, timeout=600)

    out = run(f"SEAMLINES_IN={path}", f"OUTPUT={tmp_path / 'edited.tif'}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    assert "given to the image they name" in out.stdout + out.stderr
    res = json.loads(out.stdout)["results"]
    q, gq = _read(res["OUTPUT"])
    assert gq == gt  # the same origin (qgis_process's GDAL may give the grid a row or column more)
    # inside the edited square the mosaic is B's orthophoto up to the radiometric correction (a smooth gain):
    # a straight-line fit to B's pixels leaves only rounding, to A's the two images' differences
    inner = (slice(r - 10, r + 10), slice(c - 10, c + 10))

    def misfit(name):
        ref = _per(auto, name)[0][:3][:, inner[0], inner[1]].ravel()
        got = q[:3][:, inner[0], inner[1]].ravel()
        design = np.column_stack([ref, np.ones_like(ref)])
        coef, *_ = np.linalg.lstsq(design, got, rcond=None)
        return float(np.std(got - design @ coef))

    fit_b, fit_a = misfit(b_name), misfit(a_name)
    print(f"\nqgis_process mosaic in the edited square: misfit to {b_name} {fit_b:.2f}, to {a_name} {fit_a:.2f}")
    assert fit_b < 1.0 and fit_a > 3 * fit_b
    recorded = json.load(open(os.path.join(ws2, "workspace.json")))["stages"]["orthophoto"]
    assert recorded["parameters"]["options"]["seamlines_in"] == path and recorded["inputs"]["seamlines_in"]
    # a misspelt image: a clear message naming the file and the closest name, no traceback
    bad = _gpkg(tmp_path / "bad.gpkg", [(b_name.replace("_0", "_"), "POLYGON((0 0,1 0,1 1,0 0))")])
    out = run(f"SEAMLINES_IN={bad}", f"OUTPUT={tmp_path / 'bad.tif'}")
    text = out.stdout + out.stderr
    assert out.returncode != 0 and bad in text and f"did you mean '{b_name}'" in text, text[-2000:]
    assert "Traceback" not in text, text[-2000:]


def test_the_plan_spans_a_photo_in_at_most_about_300_cells():
    """The planning cell is 4 GSD for photos up to 1200 px and grows with larger photos, so a photo of the same
    ground at 2 x the pixels is planned on cells of the same size in metres (not 4 x as many)."""
    from core.ortho.pixels import ImageMeta
    from core.ortho.planning import PLANNING_GSD, PLANNING_MAX_CELLS_ACROSS, planning_gsd

    def metas(w, h, n=3):
        return [ImageMeta(w, h, 3, "uint8") for _ in range(n)]

    assert planning_gsd(metas(400, 300)) == PLANNING_GSD
    assert planning_gsd(metas(1200, 900)) == PLANNING_GSD  # toledo: 300 cells of 4 GSD
    assert planning_gsd(metas(2400, 1800)) == pytest.approx(8.0)  # toledo_2400: 300 cells of 8 GSD
    assert planning_gsd(metas(900, 4608)) == pytest.approx(4608 / PLANNING_MAX_CELLS_ACROSS)  # portrait 16 MP
    # the median photo decides: one large photo among small ones does not coarsen the plan
    assert planning_gsd(metas(1200, 900, 4) + metas(6000, 4000, 1)) == PLANNING_GSD
    assert planning_gsd([]) == PLANNING_GSD
