"""Issue 36, the remaining core-side items: heights in feet read through one conversion (item 4), references
that do not cover the block or are in a geographic CRS (item 12), photos moved, a geographic working CRS, a
seamline file without a CRS or naming a filtered photo, a read-only workspace (item 13), suspect automatic GCPs
(item 18), the log's units and noise (item 21).  Each test builds its bad input from synthetic data whose truth
is known."""
from __future__ import annotations

import os

import cv2
import numpy as np
import pytest
from osgeo import gdal, osr

from core.io.raster import DsmReader, read_dsm

FT_US = 1200.0 / 3937.0
UTM17 = "EPSG:32617"  # Ohio lies in UTM zone 17
OHIO_N_FT = "EPSG:3734"  # NAD83 / Ohio North (ftUS): axes and, by the rule, heights in US survey feet
X0, Y0 = 440000.0, 4590000.0  # near Cleveland


def _plane(x, y):
    """The truth: ground heights in metres at UTM 17N coordinates."""
    return 200.0 + 0.02 * (x - X0) - 0.01 * (y - Y0)


def _write(path, arr, gt, crs, unit="", nodata=-9999.0):
    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(str(path), arr.shape[1], arr.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform(gt)
    srs = osr.SpatialReference()
    srs.SetFromUserInput(crs)
    ds.SetProjection(srs.ExportToWkt())
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(nodata)
    if unit:
        band.SetUnitType(unit)
    band.WriteArray(arr.astype(np.float32))
    ds = None
    return str(path)


def _metre_dsm(path, cell=1.0, n=400):
    gt = (X0, cell, 0.0, Y0 + n * cell, 0.0, -cell)
    c = X0 + (np.arange(n) + 0.5) * cell
    r = Y0 + n * cell - (np.arange(n) + 0.5) * cell
    xx, yy = np.meshgrid(c, r)
    return _write(path, _plane(xx, yy), gt, UTM17), gt


def _feet_state_plane(path, metre_path):
    """The metre DSM warped into Ohio North (ftUS), its heights in US survey feet, no band unit: a state plane
    DEM as agencies publish them."""
    tmp = str(path) + ".m.tif"
    gdal.Warp(tmp, metre_path, dstSRS=OHIO_N_FT, resampleAlg="bilinear", dstNodata=-9999.0)
    arr, gt, _ = read_dsm(tmp)  # read in its own CRS: heights as stored (metres, nothing says otherwise yet)
    return _write(path, np.where(np.isfinite(arr), arr / FT_US, -9999.0), gt, OHIO_N_FT)


# ---------------------------------------------------------------------------
# item 4: one conversion of heights for every reader
# ---------------------------------------------------------------------------

def test_dsm_reader_converts_heights_to_the_unit_of_the_crs_it_reads_in(tmp_path):
    """A state plane DEM in feet read into UTM gives metres; read in its own CRS, feet (its axes' unit); a band
    that says 'ft' on a metric grid gives metres."""
    metre, gt = _metre_dsm(tmp_path / "m.tif")
    feet = _feet_state_plane(tmp_path / "ft.tif", metre)
    x = X0 + np.array([100.5, 200.5, 300.5])
    y = Y0 + np.array([150.5, 250.5, 120.5])
    with DsmReader(feet, target_crs=UTM17) as r:
        assert r.z_scale == pytest.approx(FT_US)
        np.testing.assert_allclose(r.sample(x, y), _plane(x, y), atol=0.05)
    with DsmReader(feet) as r:  # its own CRS in feet: heights in feet, the unit of its axes
        assert r.z_scale == 1.0
        arr = r.read_all()
        assert np.nanmedian(arr) == pytest.approx(np.nanmedian(_plane(x, y)) / FT_US, rel=0.05)
    band_ft = tmp_path / "band_ft.tif"
    arr, _, _ = read_dsm(metre)
    _write(band_ft, arr / 0.3048, gt, UTM17, unit="ft")
    with DsmReader(str(band_ft)) as r:
        np.testing.assert_allclose(r.sample(x, y), _plane(x, y), atol=0.01)
    with DsmReader(str(band_ft), target_crs=OHIO_N_FT) as r:  # metric heights as feet of the state plane
        xy = np.column_stack([x, y, np.zeros(3)])
        from core.geometry.crs import transform_points

        sp = transform_points(xy, UTM17, OHIO_N_FT)
        np.testing.assert_allclose(r.sample(sp[:, 0], sp[:, 1]) * FT_US, _plane(x, y), atol=0.02)


def test_autocontrol_reference_dsm_in_state_plane_feet_gives_metres(tmp_path):
    """The automatic control's reference: an orthophoto in UTM (metres) and a DSM in EPSG:3734 (feet): heights
    at the orthophoto's points in metres (the issue: cameras 22.7 m too high)."""
    from core.georef.autocontrol.reference import Reference

    metre, gt = _metre_dsm(tmp_path / "m.tif")
    feet = _feet_state_plane(tmp_path / "ft.tif", metre)
    rng = np.random.default_rng(0)
    img = rng.integers(0, 255, size=(3, 400, 400)).astype(np.uint8)
    ortho = str(tmp_path / "ortho.tif")
    ds = gdal.GetDriverByName("GTiff").Create(ortho, 400, 400, 3, gdal.GDT_Byte)
    ds.SetGeoTransform(gt)
    ds.SetProjection(gdal.Open(metre).GetProjection())
    for k in range(3):
        ds.GetRasterBand(k + 1).WriteArray(img[k])
    ds = None
    ref = Reference(ortho, feet)
    try:
        x = X0 + np.array([50.0, 200.0, 350.0])
        y = Y0 + np.array([60.0, 210.0, 330.0])
        np.testing.assert_allclose(ref.heights(x, y), _plane(x, y), atol=0.05)
        assert any("foot" in n.lower() for n in ref.notes), ref.notes
    finally:
        ref.close()


def _nadir_photo(path, w=400, h=300):
    rng = np.random.default_rng(3)
    img = cv2.resize(rng.integers(0, 255, size=(h // 4, w // 4, 3)).astype(np.uint8), (w, h),
                     interpolation=cv2.INTER_CUBIC)
    cv2.imwrite(str(path), img)
    return str(path)


def test_orthorectify_image_on_a_dsm_in_feet_matches_the_metre_dsm(tmp_path):
    """Orthorectify image with a known orientation on the same ground as a metre DSM and as a state plane DSM in
    feet: the same orthophoto (heights in feet read as metres put the ground 3.28 x higher: 656 m under a camera
    at 350 m, nothing of it right)."""
    from core.ortho.options import OrthoOptions, SingleImageOptions
    from core.ortho.single import orthorectify_image

    metre, _ = _metre_dsm(tmp_path / "m.tif", cell=0.5, n=800)
    feet = _feet_state_plane(tmp_path / "ft.tif", metre)
    photo = _nadir_photo(tmp_path / "photo.png")
    cx, cy = X0 + 200.0, Y0 + 200.0
    orient = {"x": cx, "y": cy, "z": float(_plane(cx, cy)) + 150.0, "omega": 0.0, "phi": 0.0, "kappa": 0.0,
              "focal_px": 400.0, "crs": UTM17}
    outs = []
    for name, dsm in (("m", metre), ("ft", feet)):
        out = str(tmp_path / f"ortho_{name}.tif")
        orthorectify_image(SingleImageOptions(photo, out, dsm, orientation=dict(orient), crs=UTM17,
                                              ortho=OrthoOptions(resolution=0.5)))
        outs.append(gdal.Open(out))
    a, b = outs
    assert a.GetGeoTransform() == pytest.approx(b.GetGeoTransform(), abs=1.0)
    ga, gb = a.GetGeoTransform(), b.GetGeoTransform()
    # the common part, cell for cell
    c0 = int(round((gb[0] - ga[0]) / ga[1]))
    r0 = int(round((gb[3] - ga[3]) / ga[5]))
    arr_a = a.ReadAsArray().astype(np.float32)
    arr_b = b.ReadAsArray().astype(np.float32)
    h = min(arr_a.shape[1] - max(r0, 0), arr_b.shape[1] - max(-r0, 0))
    w = min(arr_a.shape[2] - max(c0, 0), arr_b.shape[2] - max(-c0, 0))
    pa = arr_a[:, max(r0, 0):max(r0, 0) + h, max(c0, 0):max(c0, 0) + w]
    pb = arr_b[:, max(-r0, 0):max(-r0, 0) + h, max(-c0, 0):max(-c0, 0) + w]
    both = (pa[-1] > 0) & (pb[-1] > 0)
    assert both.sum() > 0.8 * max((pa[-1] > 0).sum(), 1)
    diff = np.abs(pa[0][both] - pb[0][both])
    assert float(np.median(diff)) < 3.0, float(np.median(diff))


# ---------------------------------------------------------------------------
# item 12: a reference that does not cover the block, or has no data over it
# ---------------------------------------------------------------------------

def _rgb(path, gt, n, crs=UTM17, hole=None):
    ds = gdal.GetDriverByName("GTiff").Create(str(path), n, n, 3, gdal.GDT_Byte, ["PHOTOMETRIC=RGB"])
    ds.SetGeoTransform(gt)
    srs = osr.SpatialReference()
    srs.SetFromUserInput(crs)
    ds.SetProjection(srs.ExportToWkt())
    rng = np.random.default_rng(1)
    for k in range(3):
        band = ds.GetRasterBand(k + 1)
        band.SetNoDataValue(0)
        arr = rng.integers(1, 255, size=(n, n)).astype(np.uint8)
        if hole is not None:
            arr[hole] = 0
        band.WriteArray(arr)
    ds = None
    return str(path)


def test_a_reference_away_from_the_block_or_empty_over_it_is_named_before_matching(tmp_path):
    """The block at (X0 + 100..300, Y0 + 100..300); references 5 km away, or covering it with nodata only there:
    each named, with where it lies (was '0 candidate(s) kept, 4 needed (... 9960 / 0 features ...)')."""
    from core.georef.autocontrol.errors import AutoControlError
    from core.georef.autocontrol.reference import Reference

    n = 400
    gt = (X0, 1.0, 0.0, Y0 + n, 0.0, -1.0)
    far_gt = (X0 + 5000.0, 1.0, 0.0, Y0 + n, 0.0, -1.0)
    ortho = _rgb(tmp_path / "ortho.tif", gt, n)
    dsm, _ = _metre_dsm(tmp_path / "dsm.tif")
    block = (X0 + 100.0, Y0 + 100.0, X0 + 300.0, Y0 + 300.0)
    far_ortho = _rgb(tmp_path / "far_ortho.tif", far_gt, n)
    arr, _, _ = read_dsm(dsm)
    far_dsm = _write(tmp_path / "far_dsm.tif", arr, far_gt, UTM17)
    holed = arr.copy()
    holed[50:350, 50:350] = -9999.0
    hole_dsm = _write(tmp_path / "hole_dsm.tif", holed, gt, UTM17)
    hole_ortho = _rgb(tmp_path / "hole_ortho.tif", gt, n, hole=(slice(50, 350), slice(50, 350)))
    ref = Reference(ortho, dsm)
    ref.check_covers(block)  # the right ones
    ref.close()
    cases = [(far_ortho, dsm, r"reference orthophoto .*far_ortho\.tif does not cover the block .* 4\.7 km away"),
             (ortho, far_dsm, r"reference DSM .*far_dsm\.tif does not cover the block .* 4\.7 km away"),
             (hole_ortho, dsm, r"reference orthophoto .*hole_ortho\.tif has no data over the block"),
             (ortho, hole_dsm, r"reference DSM .*hole_dsm\.tif has no data over the block")]
    for o, d, message in cases:
        ref = Reference(o, d)
        try:
            with pytest.raises(AutoControlError, match=message):
                ref.check_covers(block)
        finally:
            ref.close()


# ---------------------------------------------------------------------------
# item 13: photos moved, a geographic working CRS
# ---------------------------------------------------------------------------

def test_photos_moved_after_the_alignment_name_the_missing_folder(tmp_path):
    """The photos' folder renamed after Align images: the stages that read them name it (the automatic control
    left the photos out silently and its provisional orthophoto came out empty)."""
    from core.georef.autocontrol.errors import AutoControlError
    from core.georef.autocontrol.search import photo_paths as _photos
    from core.project.workspace import Workspace
    from tests import synthetic as syn
    from tests.workspaces import synthetic_workspace

    block = syn.vertical_block(seed=1, n_strips=1, per_strip=3)
    folder = tmp_path / "photos"
    folder.mkdir()
    photos = {}
    for n in block.names:
        photos[n] = _nadir_photo(folder / n)
    ws_dir = synthetic_workspace(str(tmp_path / "ws"), block, block.truth_reconstruction(), photos=photos)
    assert set(_photos(Workspace.open(ws_dir))) == set(block.names)
    os.rename(folder, tmp_path / "photos moved")
    with pytest.raises(AutoControlError, match=r"the photos' folder .*photos no longer exists \(3 photo"):
        _photos(Workspace.open(ws_dir))


def test_orthorectify_image_with_geographic_control_works_in_utm(tmp_path):
    """GCPs and DSM in EPSG:4326 (degrees): the image is oriented and orthorectified in its UTM zone, said in the
    log (was 'points lie nearly on one line': a resection in degrees); the CRS parameter asking for degrees is
    refused, naming the UTM zone to give instead."""
    from core.geometry.camera import Intrinsics, Pose, project_points, rotation_from_opk
    from core.geometry.crs import transform_points
    from core.io.gcp import GCPSet, GroundPoint, Observation
    from core.ortho.options import OrthoError, SingleImageOptions
    from core.ortho.single import orthorectify_image

    metre, _ = _metre_dsm(tmp_path / "m.tif", cell=0.5, n=800)
    dsm_ll = str(tmp_path / "dsm_4326.tif")
    gdal.Warp(dsm_ll, metre, dstSRS="EPSG:4326", resampleAlg="bilinear", dstNodata=-9999.0)
    photo = _nadir_photo(tmp_path / "photo.png")
    centre = np.array([X0 + 200.0, Y0 + 200.0, _plane(X0 + 200.0, Y0 + 200.0) + 150.0])
    cam = Intrinsics.simple(400, 300, 400.0)
    pose = Pose.from_centre(rotation_from_opk(0.0, 0.0, 0.0), centre)
    gx, gy = np.meshgrid(np.linspace(-50.0, 50.0, 3) + centre[0], np.linspace(-35.0, 35.0, 3) + centre[1])
    xyz = np.column_stack([gx.ravel(), gy.ravel(), _plane(gx.ravel(), gy.ravel())])
    px, _ = project_points(pose, cam, xyz)
    ll = transform_points(xyz, UTM17, "EPSG:4326")
    gcps = GCPSet("EPSG:4326", [GroundPoint(f"g{i}", float(a[0]), float(a[1]), float(a[2]),
                                            observations=[Observation("photo.png", float(p[0]), float(p[1]))])
                                for i, (a, p) in enumerate(zip(ll, px))])
    r = orthorectify_image(SingleImageOptions(photo, str(tmp_path / "o.tif"), dsm_ll, gcps=gcps, focal_px=400.0))
    assert r.crs == UTM17 and any("geographic" in line and "EPSG:32617" in line for line in r.log_lines)
    got = np.array([r.orientation[k] for k in "xyz"])
    assert np.linalg.norm(got - centre) < 0.5, got - centre
    with pytest.raises(OrthoError, match=r"CRS EPSG:4326 is geographic .* EPSG:32617"):
        orthorectify_image(SingleImageOptions(photo, str(tmp_path / "o2.tif"), dsm_ll, gcps=gcps, focal_px=400.0,
                                              crs="EPSG:4326"))


def test_seamlines_without_a_crs_or_naming_a_filtered_photo_are_named(tmp_path):
    """A seamlines shapefile without its .prj: its CRS is unknown, said, and refused where none of its polygons
    lies on the mosaic (the edits were ignored); a polygon naming a photo IMAGES_FILTER leaves out: said so (was
    'not one of the N images of this mosaic')."""
    from osgeo import ogr

    from core.ortho.seamlines import SeamlineError, read_seamline_edits

    shp = str(tmp_path / "edits.shp")
    ds = ogr.GetDriverByName("ESRI Shapefile").CreateDataSource(shp)
    lyr = ds.CreateLayer("edits", None, ogr.wkbPolygon)
    lyr.CreateField(ogr.FieldDefn("image", ogr.OFTString))
    for name in ("a.jpg", "c.jpg"):
        f = ogr.Feature(lyr.GetLayerDefn())
        f.SetField("image", name)
        f.SetGeometry(ogr.CreateGeometryFromWkt(f"POLYGON(({X0} {Y0},{X0 + 5} {Y0},{X0 + 5} {Y0 + 5},{X0} {Y0}))"))
        lyr.CreateFeature(f)
    ds = None
    assert not os.path.exists(str(tmp_path / "edits.prj"))
    # nowhere on the mosaic (in another CRS's numbers): its CRS is named unknown (the edits were ignored)
    with pytest.raises(SeamlineError, match=r"edits\.shp: the layer's CRS is unknown .*\.prj.* none of its 2 polygon"):
        read_seamline_edits(shp, ["a.jpg", "b.jpg", "c.jpg"], UTM17, extent=(0.0, 0.0, 100.0, 100.0))
    # on the mosaic: taken as its CRS, and the log says so
    edits = read_seamline_edits(shp, ["a.jpg", "b.jpg", "c.jpg"], UTM17, extent=(X0 - 50, Y0 - 50, X0 + 50, Y0 + 50))
    assert len(edits.polygons) == 2 and any("CRS is unknown" in n and UTM17 in n for n in edits.notes)
    srs = osr.SpatialReference()
    srs.SetFromUserInput(UTM17)
    with open(str(tmp_path / "edits.prj"), "w") as fh:
        fh.write(srs.ExportToWkt())
    with pytest.raises(SeamlineError, match=r"names the image 'c.jpg', which IMAGES_FILTER 'a\*, b\*' leaves out"):
        read_seamline_edits(shp, ["a.jpg", "b.jpg"], UTM17, left_out=["c.jpg"], images_filter="a*, b*")
    assert [n for n, _ in read_seamline_edits(shp, ["a.jpg", "b.jpg", "c.jpg"], UTM17).polygons] == ["a.jpg", "c.jpg"]


def test_a_read_only_workspace_is_refused_before_any_work(tmp_path, monkeypatch):
    """One check in core.project for every stage (Workspace.begin_stage), made first by the stages that work
    before they begin (the automatic control: a read-only workspace failed after 13 s of matching).  Root writes
    anywhere, so the folder's refusal is simulated where the check asks the file system."""
    import tempfile

    from core.georef.autocontrol.options import AutoControlOptions
    from core.georef.autocontrol.stage import autocontrol_workspace
    from core.project.workspace import Workspace, WorkspaceError
    from tests import synthetic as syn
    from tests.workspaces import synthetic_workspace

    block = syn.vertical_block(seed=1, n_strips=1, per_strip=3)
    ws_dir = synthetic_workspace(str(tmp_path / "ws"), block, block.truth_reconstruction())
    before = open(os.path.join(ws_dir, "workspace.json")).read()

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(WorkspaceError, match=r"workspace folder .*ws is not writable \(Permission denied\): nothing"):
        Workspace.open(ws_dir).begin_stage("dsm", {})
    with pytest.raises(WorkspaceError, match="is not writable"):  # before the references are even opened
        autocontrol_workspace(ws_dir, AutoControlOptions(reference_ortho=str(tmp_path / "no_ortho.tif"),
                                                         reference_dsm=str(tmp_path / "no_dsm.tif")))
    assert open(os.path.join(ws_dir, "workspace.json")).read() == before


def test_an_empty_images_folder_creates_no_workspace(tmp_path):
    """Align images and the pipeline refuse an IMAGES folder without photos before a workspace is created (issue
    36 item 21)."""
    from core import pipeline
    from core.align.options import AlignError
    from core.align.stage import align
    from core.io.images import ImageError

    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "notes.txt").write_text("flight log")
    ws = tmp_path / "ws"
    with pytest.raises(AlignError, match=r"empty holds no readable images .*notes\.txt"):
        align(str(empty), str(ws))
    assert not ws.exists()
    with pytest.raises(ImageError, match=r"IMAGES folder .*empty holds no readable images"):
        pipeline.run_pipeline(str(empty), str(ws), control=pipeline.Control(use_exif_gps=True))
    assert not ws.exists()


# ---------------------------------------------------------------------------
# item 21: log noise and units, the report's "At a glance"
# ---------------------------------------------------------------------------

def test_bundle_adjustment_prints_one_progress_text_and_a_summary():
    """The bundle adjustment's iterations share one progress text (the faces print a text when it changes: 20
    'bundle adjustment: iteration N, cost ...' lines before) and end with one summary line."""
    from core.common.progress import NullProgress
    from tests.test_bundle_solver import problem

    class Texts(NullProgress):
        def __init__(self):
            self.texts = []

        def report(self, fraction, message=""):
            if message and (not self.texts or self.texts[-1] != message):
                self.texts.append(message)

    prob, _ = problem([714.0, 714.0, 600.0, 450.0, 0.0, 0.0, 0.0, 0.0])
    rec = Texts()
    info = prob.solve(max_iterations=50, progress=rec)
    assert info["iterations"] >= 3
    assert rec.texts == ["bundle adjustment", f"bundle adjustment: {info['iterations']} iteration(s), cost "
                                              f"{info['initial_cost']:.6g} -> {info['final_cost']:.6g}"]


def test_log_units_and_the_glance_line_explaining_sigma_beside_the_camera_rmse():
    from core.geometry.crs import unit_symbol
    from core.report.page import precision_badge

    assert [unit_symbol(c) for c in (UTM17, OHIO_N_FT, "EPSG:2231", "EPSG:4326", None)] == \
        ["m", "US ft", "US ft", "deg", "model units"]
    assert unit_symbol("EPSG:2927") == "US ft" and unit_symbol("EPSG:27700") == "m"

    class Unc:
        n_control = 0

        def summary(self):
            return {"point_std_xy_median": 10.8, "point_std_z_median": 6.8}

    line = precision_badge(Unc(), 0.147, 0.54)
    assert "σXY 10.800 m" in line and "camera position RMSE (0.54 m) is how closely the block fits" in line
    assert "datum included" in line and "camera position RMSE" not in precision_badge(Unc(), 0.147)


# ---------------------------------------------------------------------------
# item 18: suspect automatic GCPs dropped and the block adjusted without them
# ---------------------------------------------------------------------------

def test_suspect_control_points_are_dropped_when_asked_and_the_block_adjusted_without_them():
    """The pattern of the issue (4 of 101 automatic GCPs suspect, the worst 1.54 m, all kept): with
    drop_suspect_control (the automatic control's setting) the suspects are rejected, named as such, and the
    check point lands where it belongs; without it they are only named, as for hand-picked control."""
    from core.georef.adjust import georeference
    from core.georef.options import GeorefOptions
    from core.io import gcp as gcpmod
    from tests.test_georef import MODEL_FROM_WORLD, SPREAD, _block, _gcps

    rec, _ = _block(MODEL_FROM_WORLD)
    xy = dict(SPREAD, f=(40.0, 8.0), g=(20.0, 50.0))

    def control():
        gcps = _gcps(rec, MODEL_FROM_WORLD, xy, noise_px=0.2)
        for p in gcps.points:
            if p.name == "b":
                p.x += 1.5
            if p.name == "g":
                p.y -= 2.0
        gcpmod.apply_check_points(gcps, ["e"])
        return gcps

    kept = georeference(rec, control())
    dropped = georeference(rec, control(), options=GeorefOptions(drop_suspect_control=True))
    status = {r.name: r.status for r in dropped.points}
    assert status["b"] == status["g"] == "rejected" and status["a"] == "used"
    assert {r.name: r.status for r in kept.points}["g"] == "used"
    assert [(o.name, o.stage) for o in dropped.outliers if o.stage == "consistency"] == [("g", "consistency"),
                                                                                       ("b", "consistency")]
    assert dropped.rmse("check")["xy"] < 0.5 * kept.rmse("check")["xy"]


def test_the_automatic_control_counts_name_the_suspects_dropped():
    """'97 of 101 automatic GCPs kept, 4 suspect dropped (auto_012 1.54 m, ...)': the suspects named by the
    adjustment's consistency check and rejected, worst first; a suspect re-admitted as used is not counted."""
    from core.georef.autocontrol.record import _count_used, _suspects_dropped

    class Lay:
        def residuals(self):
            pts = [{"name": f"auto_{i:03d}", "status": "used"} for i in range(97)]
            pts += [{"name": n, "status": "rejected"} for n in ("auto_097", "auto_098", "auto_099")]
            pts += [{"name": "auto_100", "status": "used"}, {"name": "hand", "status": "rejected"}]
            cc = {"suspects": ["auto_098", "auto_097", "auto_100", "hand"],
                  "residuals_m": {"auto_097": 0.8, "auto_098": 1.54, "auto_100": 0.7, "hand": 3.0}}
            return {"points": pts, "statistics": {"control_consistency": cc}}

    names = {f"auto_{i:03d}" for i in range(101)}
    assert _count_used(Lay(), names) == 98
    assert _suspects_dropped(Lay(), names) == [("auto_098", 1.54), ("auto_097", 0.8)]
