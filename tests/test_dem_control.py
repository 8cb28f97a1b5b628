"""DEM control (issue 32 item 4, core/georef/demcontrol.py): a reference DEM fed back into the adjustment.

The block is tests/synthetic.py's vertical block (3 strips x 6 photos, GSD 7.7 cm), its sparse model built from the
truth; it is georeferenced from camera positions whose heights are biased as a GPS's often are: +1.5 m and a tilt
of 2 cm/m along the strips and -1 cm/m across (sigma 3 m XY / 5 m Z as given).  A similarity to those positions
tilts the whole block, which its photos cannot see: the check points (every ground mark) come out about 1.6 m off in
Z.  The reference DEM is the scene's true surface averaged onto 0.5 m cells (6.5 GSD), warped into a transverse
Mercator CRS without an EPSG code (tests/national.py) and written in feet: with it, the check points' Z error must
drop to about a GSD (compared with the truth).  Bad references (off the block, a 25 m DEM under a 150 m block, all
nodata, in degrees) are refused by name before the adjustment runs; and the Processing algorithm with a
REFERENCE_DSM alone runs the same (EXIF GPS placing the block).
"""
import json
import os

import numpy as np
import pytest

from core.common.errors import ArchaeoOrthoError
from core.georef.options import GeorefOptions
from core.georef.stage import georeference_workspace
from core.io.gcp import CHECK, CONTROL
from tests import synthetic as syn
from tests.national import degrade, national_wkt
from tests.workspaces import set_exif_gps, synthetic_workspace

FOOT = 0.3048
FINE = 0.1  # m: the true surface is sampled at this cell, then averaged onto the reference's
REF_CELL = 0.5  # m: 6.5 x the GSD
BIAS_Z, TILT_X, TILT_Y = 1.5, 0.02, -0.01  # the camera positions' height bias: offset (m) and tilt (m/m)


class Recorder:
    def __init__(self):
        self.infos, self.warnings = [], []

    def report(self, fraction, message=""):
        pass

    def is_cancelled(self):
        return False

    def info(self, message):
        self.infos.append(message)

    def warning(self, message):
        self.warnings.append(message)


def _write(path, z, gt, wkt, nodata=-9999.0, unit=""):
    from osgeo import gdal

    ds = gdal.GetDriverByName("GTiff").Create(path, z.shape[1], z.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform(gt)
    ds.SetProjection(wkt)
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(nodata)
    if unit:
        band.SetUnitType(unit)
    band.WriteArray(z.astype(np.float32))
    ds = None
    return path


def _to_feet(path):
    from osgeo import gdal

    ds = gdal.Open(path, gdal.GA_Update)
    band = ds.GetRasterBand(1)
    a, nd = band.ReadAsArray(), band.GetNoDataValue()
    band.WriteArray(np.where(a == nd, nd, a / FOOT).astype(np.float32))
    band.SetUnitType("ft")
    ds = None
    return path


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """(block, truth model, folder, fine surface file, reference DEM (national CRS, feet), biased positions)."""
    from osgeo import osr

    from core.geometry.crs import transform_points

    folder = tmp_path_factory.mktemp("demcontrol")
    block = syn.vertical_block(seed=1)
    rec = block.truth_reconstruction()
    b = block.scene.bounds
    xs = np.arange(b[0], b[2], FINE) + FINE / 2
    ys = np.arange(b[3], b[1], -FINE) - FINE / 2
    gx, gy = np.meshgrid(xs, ys)
    z = block.scene.height_at(gx.ravel(), gy.ravel()).reshape(gx.shape)
    utm = osr.SpatialReference()
    utm.ImportFromEPSG(32633)
    fine = _write(str(folder / "fine.tif"), z, (b[0] + syn.ORIGIN[0], FINE, 0.0, b[3] + syn.ORIGIN[1], 0.0, -FINE),
                  utm.ExportToWkt())
    lon, lat = transform_points(np.array([[syn.ORIGIN[0], syn.ORIGIN[1], 0.0]]), syn.CRS, "EPSG:4326")[0][:2]
    wkt = national_wkt(lon, lat)
    ref = _to_feet(degrade(fine, str(folder / "reference_ft.tif"), REF_CELL, wkt))
    positions, _ = block.camera_positions(sigma=0.3, seed=13)
    c = np.mean([[p.x, p.y] for p in positions], axis=0)
    for p in positions:
        p.z += BIAS_Z + TILT_X * (p.x - c[0]) + TILT_Y * (p.y - c[1])
    return block, rec, folder, fine, wkt, ref, positions


def _positions_file(folder, positions):
    path = str(folder / "positions.csv")
    rows = [f"{p.image},{p.x:.3f},{p.y:.3f},{p.z:.3f},3,5\n" for p in positions]
    with open(path, "w") as out:
        out.writelines([f"{syn.CRS}\nimage,x,y,z,sigma_xy,sigma_z\n", *rows])
    return path


def _run(root, scene, options=None, crs=syn.CRS):
    block, rec, folder, _, _, _, positions = scene
    ws = synthetic_workspace(root, block, rec)
    progress = Recorder()
    options = GeorefOptions.of(options, gcps=block.gcp_set([], noise_px=0.4), crs=crs,
                               camera_positions_path=_positions_file(folder, positions))
    result = georeference_workspace(ws, options, progress=progress)
    return ws, result, progress


def test_the_reference_dem_removes_the_tilt_and_offset_of_gps_heights(scene, tmp_path):
    block, _, _, _, _, ref, _ = scene
    _, plain, _ = _run(tmp_path / "plain", scene)
    ws, res, progress = _run(tmp_path / "dem", scene, GeorefOptions(reference_dem=ref))
    f0, f1 = plain.figures, res.figures
    g = block.gsd
    print(f"\nDEM control, GSD {g:.3f} m: check points (n={f1['CHECK_N']}) RMSE XY {f0['CHECK_RMSE_XY']:.3f} -> "
          f"{f1['CHECK_RMSE_XY']:.3f} m, Z {f0['CHECK_RMSE_Z']:.3f} -> {f1['CHECK_RMSE_Z']:.3f} m; "
          f"{f1['DEM_CONTROL_N']} DEM control points, NMAD {f1['DEM_NMAD_BEFORE']:.3f} -> {f1['DEM_NMAD_FINAL']:.3f} m")
    print("\n".join(progress.infos))
    assert f0["CHECK_N"] == f1["CHECK_N"] == len(block.gcps)
    assert f0["CHECK_RMSE_Z"] > 1.0  # the biased heights are there without the DEM
    assert f1["CHECK_RMSE_Z"] <= 1.5 * g and f1["CHECK_RMSE_Z"] <= 0.1 * f0["CHECK_RMSE_Z"]
    assert f1["CHECK_RMSE_XY"] <= f0["CHECK_RMSE_XY"] + g  # the XY is the positions', not made worse
    assert f1["DEM_CONTROL_N"] >= 10 and f1["DEM_NMAD_FINAL"] <= 2 * g
    # the record: the co-registration, which heights won, the points in the workspace's CRS with observations
    doc = json.load(open(os.path.join(ws, "georef", "dem_control.json")))
    assert doc["heights"] == "reference DEM" and doc["reference_dem"] == ref
    assert doc["coregistration"]["shift"][2] == pytest.approx(-BIAS_Z, abs=0.3)
    control = json.load(open(os.path.join(ws, "georef", "control.json")))
    dem = [p for p in control["points"] if p["name"].startswith("dem")]
    assert len(dem) == f1["DEM_CONTROL_N"] and all(p["role"] == CONTROL and len(p["observations"]) >= 2 for p in dem)
    truth_z = block.scene.height_at(np.array([p["x"] for p in dem]) - syn.ORIGIN[0],
                                    np.array([p["y"] for p in dem]) - syn.ORIGIN[1])
    assert np.median(np.abs(np.array([p["z"] for p in dem]) - truth_z)) < 0.2  # feet read as feet, CRS taken over
    assert sorted(p["name"] for p in control["points"] if p["role"] == CHECK) == sorted(p.name for p in block.gcps)
    rec = json.load(open(os.path.join(ws, "workspace.json")))["stages"]["georeference"]
    assert rec["parameters"]["reference_dem"] == ref and rec["results"]["DEM_CONTROL_N"] == f1["DEM_CONTROL_N"]
    assert any("heights: the reference DEM's win" in m for m in progress.infos)
    assert any("heights in ft" in m for m in progress.infos)


def _shifted(src, dst, dx):
    from osgeo import gdal

    gdal.Translate(dst, src)
    ds = gdal.Open(dst, gdal.GA_Update)
    gt = list(ds.GetGeoTransform())
    gt[0] += dx
    ds.SetGeoTransform(gt)
    ds = None
    return dst


def test_bad_references_are_refused_by_name_before_the_adjustment(scene, tmp_path, monkeypatch):
    from osgeo import gdal, osr

    import core.georef.adjustments as adjustments

    block, _, folder, fine, wkt, _, _ = scene

    def no_adjustment(*args, **kwargs):
        raise AssertionError("the adjustment ran")

    monkeypatch.setattr(adjustments, "georeference", no_adjustment)
    far = _shifted(fine, str(tmp_path / "far.tif"), 5000.0)
    coarse = degrade(fine, str(tmp_path / "coarse25.tif"), 25.0, wkt)
    empty = str(tmp_path / "empty.tif")
    ds = gdal.Open(fine)
    _write(empty, np.full((50, 60), -9999.0), ds.GetGeoTransform(), ds.GetProjection())
    wgs = osr.SpatialReference()
    wgs.ImportFromEPSG(4326)
    degrees = str(tmp_path / "degrees.tif")
    gdal.Warp(degrees, fine, dstSRS=wgs.ExportToWkt(), xRes=5e-6, yRes=5e-6)
    cases = [(far, "does not overlap|has no height over"), (coarse, "too coarse for a block this small: \\d+ cells"),
             (empty, "every cell is nodata"), (degrees, "geographic CRS"),
             (str(tmp_path / "missing.tif"), "does not exist")]
    for path, pattern in cases:
        with pytest.raises(ArchaeoOrthoError, match=pattern) as err:
            _run(tmp_path / ("ws_" + os.path.basename(path)), scene, GeorefOptions(reference_dem=path))
        assert path in str(err.value), str(err.value)
        print(f"\n{os.path.basename(path)}: {err.value}")
    # a target CRS in feet over the block (no EPSG code, so no area of use to refuse the positions by first)
    feet = "+proj=tmerc +lat_0=41.5 +lon_0=15 +k=1 +x_0=0 +y_0=0 +ellps=GRS80 +units=us-ft +no_defs"
    with pytest.raises(ArchaeoOrthoError, match="needs a target CRS in metres; .* is in units of 0.3048") as err:
        _run(tmp_path / "ws_feet", scene, GeorefOptions(reference_dem=scene[5]), crs=feet)
    print(f"\ntarget CRS in feet: {err.value}")


def _picture(path, like, bands=4, dtype=None, interp=True):
    """An image over the raster ``like``'s footprint: ``bands`` bands of bytes (red/green/blue/alpha when
    ``interp``), or of ``dtype``; the values a grey ramp."""
    from osgeo import gdal

    ref = gdal.Open(like)
    w, h = ref.RasterXSize, ref.RasterYSize
    ds = gdal.GetDriverByName("GTiff").Create(path, w, h, bands, dtype or gdal.GDT_Byte)
    ds.SetGeoTransform(ref.GetGeoTransform())
    ds.SetProjection(ref.GetProjection())
    ramp = (np.add.outer(np.arange(h), np.arange(w)) % 250).astype(np.float32)
    colours = [gdal.GCI_RedBand, gdal.GCI_GreenBand, gdal.GCI_BlueBand, gdal.GCI_AlphaBand]
    for k in range(bands):
        b = ds.GetRasterBand(k + 1)
        b.WriteArray(ramp if k < bands - 1 or bands < 2 else np.full((h, w), 255.0, np.float32))
        if interp and bands > 1:
            b.SetColorInterpretation(colours[k] if bands == 4 else (gdal.GCI_GrayIndex, gdal.GCI_AlphaBand)[k])
    ds = None
    return path


def test_a_picture_given_as_heights_is_refused_by_every_reader(scene, tmp_path, monkeypatch):
    """Issue 47 item 1: the RGBA orthomosaic given to Georeference as REFERENCE_DSM was read as heights (band 1's
    bytes: cameras raised 152 m, exit 0). One check (core.io.raster.not_heights, the terrain tools' and the
    automatic control's) for every reader of heights: DEM control refuses it before the adjustment, the
    co-registration (either side) and the DSM reader (the orthophoto, Orthorectify) refuse it by name; a band of
    heights with an alpha (mask) band still reads."""
    from osgeo import gdal

    import core.georef.adjustments as adjustments
    from core.georef.coregister import CoregError, coregister_rasters
    from core.io.raster import DsmError, open_dsm

    fine = scene[3]

    def no_adjustment(*args, **kwargs):
        raise AssertionError("the adjustment ran")

    monkeypatch.setattr(adjustments, "georeference", no_adjustment)
    rgba = _picture(str(tmp_path / "orthomosaic.tif"), fine)
    with pytest.raises(ArchaeoOrthoError, match=r"orthomosaic\.tif is an image, not heights: 4 band\(s\) of Byte "
                                                r"\(red/green/blue/alpha\)") as err:
        _run(tmp_path / "ws_rgba", scene, GeorefOptions(reference_dem=rgba))
    print(f"\nDEM control on the RGBA mosaic: {err.value}")
    for dem, ref in ((fine, rgba), (rgba, fine)):
        with pytest.raises(CoregError, match=r"orthomosaic\.tif is an image, not heights"):
            coregister_rasters(dem, ref)
    with pytest.raises(DsmError, match=r"DSM .*orthomosaic\.tif is an image, not heights"):
        open_dsm(rgba)
    grey_alpha = _picture(str(tmp_path / "grey_alpha.tif"), fine, bands=2)
    with pytest.raises(DsmError, match="is an image, not heights: 2 band\\(s\\) of Byte \\(grey/alpha\\)"):
        open_dsm(grey_alpha)
    masked = _picture(str(tmp_path / "heights_alpha.tif"), fine, bands=2, dtype=gdal.GDT_Float32)
    assert open_dsm(masked).width == gdal.Open(fine).RasterXSize  # heights with a mask band are heights


def _relabelled(src, dst, unit):
    """A copy of the raster ``src`` whose band states ``unit`` ('' : none), its values untouched."""
    from osgeo import gdal

    ds = gdal.Translate(dst, src)
    ds.GetRasterBand(1).SetUnitType(unit)
    ds = None
    return dst


def test_a_reference_dem_in_another_unit_than_it_says_is_refused_before_the_adjustment(scene, tmp_path,
                                                                                       monkeypatch):
    """Issue 47 item 4: a DEM in feet with no unit label was read as metres (the block tilted 36.6 mm/m, lifted
    40.6 m, exit 0). The reference's relief over the block against the block's own names the unit before the
    adjustment: feet without a label, metres labelled feet; the same DEM labelled right runs."""
    import core.georef.adjustments as adjustments

    _, _, _, fine, _, ref_ft, _ = scene

    def no_adjustment(*args, **kwargs):
        raise AssertionError("the adjustment ran")

    monkeypatch.setattr(adjustments, "georeference", no_adjustment)
    unlabelled = _relabelled(ref_ft, str(tmp_path / "dem_ft_nolabel.tif"), "")
    with pytest.raises(ArchaeoOrthoError, match=r"dem_ft_nolabel\.tif seems to be in feet, not metres: its relief "
                                                r"over the block .* is 3\.\d\d x the block's own") as err:
        _run(tmp_path / "ws_nolabel", scene, GeorefOptions(reference_dem=unlabelled))
    assert "gdal_edit.py -units ft" in str(err.value)
    print(f"\nfeet without a label: {err.value}")
    metres_as_feet = _relabelled(fine, str(tmp_path / "dem_m_as_ft.tif"), "ft")
    with pytest.raises(ArchaeoOrthoError, match=r"dem_m_as_ft\.tif seems to be in metres, not in ft as the band's "
                                                r"unit says: its relief over the block .* is 0\.\d\d x") as err:
        _run(tmp_path / "ws_m_as_ft", scene, GeorefOptions(reference_dem=metres_as_feet))
    print(f"metres labelled feet: {err.value}")
    for right in (ref_ft, fine):  # labelled feet, and metres without a label: past the checks, to the adjustment
        with pytest.raises(AssertionError, match="the adjustment ran"):
            _run(tmp_path / ("ws_" + os.path.basename(right)), scene, GeorefOptions(reference_dem=right))


def test_a_reference_dem_alone_without_gps_says_what_can_place_the_block(scene, tmp_path):
    """Issue 47 item 13: a reference DSM alone on photos without GPS said 'no target CRS', then, with a CRS,
    'needs at least 3 control points': say that the DEM fixes heights, tilt and dome but not where the block
    lies, and which inputs place it (EXIF GPS, camera positions, control points; or a reference orthophoto for
    the automatic control)."""
    block, rec, _, _, _, ref, _ = scene
    works = (r"(?s)reference DEM .*reference_ft\.tif fixes the block's heights, tilt and dome, not where it lies: "
             r".*EXIF GPS \(0 of 18 photos carry any\).*camera positions \(CAMERA_POSITIONS.*ground control "
             r"points \(GCPS or GCP_LAYER\).*reference orthophoto \(REFERENCE_ORTHO\)")
    for crs in (None, syn.CRS):
        ws = synthetic_workspace(tmp_path / f"ws_{crs is None}", block, rec)
        with pytest.raises(ArchaeoOrthoError, match=works) as err:
            georeference_workspace(ws, GeorefOptions(reference_dem=ref, crs=crs), progress=Recorder())
        print(f"\nCRS {crs}: {err.value}")


def test_processing_georeference_with_a_reference_dsm_alone(scene, tmp_path, qgis_app):
    """Georeference with REFERENCE_DSM and the ground marks as check points; the block placed by the photos' EXIF
    GPS (biased heights) as USE_EXIF_GPS says, compared with the same run without the DSM."""
    from archaeoortho.processing_provider.georeference import GeoreferenceAlgorithm
    from qgis.core import QgsProcessingContext, QgsProcessingFeedback, QgsProject, QgsRasterLayer

    from core.io.gcp import write_odm_gcp_list

    block, rec, _, _, _, ref, positions = scene
    gcp_file = str(tmp_path / "gcp_list.txt")
    write_odm_gcp_list(block.gcp_set([], noise_px=0.4), gcp_file)
    names = ",".join(p.name for p in block.gcps)
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    out = {}
    for label, dsm in (("plain", None), ("dem", QgsRasterLayer(ref, "national DEM in feet", "gdal"))):
        ws = synthetic_workspace(tmp_path / label, block, rec)
        set_exif_gps(ws, positions, syn.CRS)
        alg = GeoreferenceAlgorithm()
        alg.initAlgorithm()
        p = {"WORKSPACE": ws, "GCPS": gcp_file, "CHECK_POINTS": names, "USE_EXIF_GPS": True, "CRS": syn.CRS}
        if dsm is not None:
            assert dsm.isValid()
            p["REFERENCE_DSM"] = dsm
        out[label] = alg.processAlgorithm(p, context, QgsProcessingFeedback())
    print(f"\nProcessing, EXIF GPS: check Z {out['plain']['CHECK_RMSE_Z']:.3f} m without, "
          f"{out['dem']['CHECK_RMSE_Z']:.3f} m with REFERENCE_DSM ({out['dem']['DEM_CONTROL_N']} DEM control points)")
    assert out["plain"]["DEM_CONTROL_N"] is None and out["dem"]["DEM_CONTROL_N"] >= 10
    assert out["dem"]["CHECK_RMSE_Z"] <= 0.2 * out["plain"]["CHECK_RMSE_Z"]
    assert os.path.isfile(os.path.join(out["dem"]["WORKSPACE"], "georef", "dem_control.json"))


def test_control_points_heights_win_over_a_dem_in_another_vertical_datum(scene, tmp_path):
    """Four control points at the corners fix the block; the reference DEM's heights are 30 m off (another vertical
    datum): the control points' heights win, the DEM control adds only the shape and the check points stay where
    the control puts them.  The same DEM in the control's datum agrees with it: both hold the heights."""
    from osgeo import gdal

    block, rec, _, fine, _, _, _ = scene
    lifted = str(tmp_path / "lifted.tif")
    gdal.Translate(lifted, fine, scaleParams=[[0, 1, 30, 31]], outputType=gdal.GDT_Float32)
    ref = degrade(lifted, str(tmp_path / "lifted_05.tif"), REF_CELL, gdal.Open(fine).GetProjection())
    same = degrade(fine, str(tmp_path / "same_05.tif"), REF_CELL, gdal.Open(fine).GetProjection())
    control = block.spread_control(4)
    out = {}
    for label, options in (("plain", None), ("dem", GeorefOptions(reference_dem=ref)),
                           ("same", GeorefOptions(reference_dem=same))):
        ws = synthetic_workspace(tmp_path / label, block, rec)
        progress = Recorder()
        out[label] = georeference_workspace(ws, GeorefOptions.of(options, gcps=block.gcp_set(control, noise_px=0.4),
                                                                 crs=syn.CRS), progress=progress).figures
        if label == "dem":
            assert any("heights: the control points' win" in m for m in progress.infos)
    doc = json.load(open(os.path.join(tmp_path, "dem", "georef", "dem_control.json")))
    print(f"\ncontrol points' heights: check Z {out['plain']['CHECK_RMSE_Z']:.3f} m without, "
          f"{out['dem']['CHECK_RMSE_Z']:.3f} m with the DEM 30 m off (dz {doc['coregistration']['shift'][2]:.2f} m)")
    assert doc["heights"] == "control points" and doc["camera_dz"] == 0.0
    assert doc["coregistration"]["shift"][2] == pytest.approx(30.0, abs=0.3)
    assert out["dem"]["CHECK_RMSE_Z"] <= out["plain"]["CHECK_RMSE_Z"] + 0.5 * block.gsd
    assert out["dem"]["CHECK_RMSE_Z"] <= 1.5 * block.gsd
    same = json.load(open(os.path.join(tmp_path, "same", "georef", "dem_control.json")))
    print(f"the DEM in the control's datum: check Z {out['same']['CHECK_RMSE_Z']:.3f} m (dz "
          f"{same['coregistration']['shift'][2]:+.3f} m, 3 sigma {3 * same['level_sigma']:.3f} m)")
    assert same["heights"] == "control points and reference DEM" and same["camera_dz"] == 0.0
    assert out["same"]["CHECK_RMSE_Z"] <= out["plain"]["CHECK_RMSE_Z"] + 0.5 * block.gsd
    assert any("heights: the control points and the reference DEM" in m for m in progress.infos)


def test_the_shift_is_used_where_the_terrain_fixes_it_else_the_heights_alone():
    """On rugged terrain (tests/test_coregister.py's, 25 m reference) the shift of points off by (-30, 18) m is
    found and used; on a gently curved slope a tilted block's shift is not (a shift and a tilt mimic each other
    there), and the heights alone give dz, tilt and dome back (known truth)."""
    from core.georef.demcontrol import coregister_xyz, heights_only
    from tests import test_coregister as tc

    terrain = tc.Terrain(1, 40, 400.0, 150.0, 1500.0)
    ref, gt = tc.reference(terrain, noise=0.2)
    rng = np.random.default_rng(7)
    n = 8000
    x = rng.uniform(tc.BLOCK[0], tc.BLOCK[0] + tc.BLOCK[2], n)
    y = rng.uniform(tc.BLOCK[1], tc.BLOCK[1] + tc.BLOCK[2], n)
    shift, dz, tilt = (-30.0, 18.0), -4.0, (5e-4, 6e-4)
    qx, qy = x + shift[0], y + shift[1]
    z = terrain.at(qx, qy) - tc.correction(qx, qy, dz, tilt) + rng.normal(0, 0.3, n)
    res = coregister_xyz(np.column_stack([x, y, z]), ref, gt)
    assert res.horizontal_determined and np.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]) < 0.1 * tc.REF_CELL
    tc.check_correction(res, dz, tilt, tol=0.15)
    # a gently curved slope (no feature to fix a shift) under a tilted, domed block
    cell, size = 1.0, 300.0
    xs = (np.arange(int(size / cell)) + 0.5) * cell
    gx, gy = np.meshgrid(xs, size - xs)
    surface = 100.0 + 0.05 * gx + 1e-4 * (gx - 150.0) ** 2
    pts = np.column_stack([rng.uniform(20, 280, n), rng.uniform(20, 280, n)])
    truth = 100.0 + 0.05 * pts[:, 0] + 1e-4 * (pts[:, 0] - 150.0) ** 2
    u, v = pts[:, 0] - 150.0, pts[:, 1] - 150.0
    applied = 2.0 + 0.01 * u - 0.005 * v + 2e-5 * u * u  # what the reference has above the block
    block = np.column_stack([pts, truth - applied + rng.normal(0, 0.05, n)])
    gt2 = (0.0, cell, 0.0, size, 0.0, -cell)
    for res in (coregister_xyz(block, surface, gt2), heights_only(block, surface, gt2)):
        assert not res.horizontal_determined and res.shift[:2] == (0.0, 0.0)
        err = res.correction(pts[:, 0], pts[:, 1]) - applied
        assert np.max(np.abs(err)) < 0.05, np.max(np.abs(err))
        assert res.nmad_after < 0.1 and res.nmad_before > 0.5


def test_a_reference_with_many_cells_under_the_block_is_read_coarser(scene, monkeypatch):
    """Beyond MAX_WINDOW_CELLS cells under the block the reference is averaged onto a coarser grid in its own CRS
    (here 20 000: 0.5 m -> 1 m), still in feet read as feet and reprojected into the block's CRS."""
    import core.georef.demcontrol as dm

    block, _, _, _, _, ref, _ = scene
    xyz, _ = block.tie_points(3000, seed=3)
    world = xyz + syn.ORIGIN
    full, gt_full, _, n_full = dm.check_coverage(world, ref, syn.CRS)
    monkeypatch.setattr(dm, "MAX_WINDOW_CELLS", 20_000)
    arr, gt, messages, n = dm.check_coverage(world, ref, syn.CRS)
    print(f"\n{messages}: {n_full} -> {n} cells under the block, cell {gt_full[1]:.2f} -> {gt[1]:.2f} m")
    assert any("read averaged onto" in m and ref in m for m in messages) and all("reference.vrt" not in m
                                                                                   for m in messages)
    assert 1.9 <= gt[1] / gt_full[1] <= 4.0 and arr.size * 3 < full.size
    from core.io.raster import bilinear

    z = bilinear(arr, (world[:, 0] - gt[0]) / gt[1] - 0.5, (world[:, 1] - gt[3]) / gt[5] - 0.5)
    ok = np.isfinite(z)
    assert ok.mean() > 0.9 and np.median(np.abs(z[ok] - world[ok, 2])) < 0.3  # metres, on the true surface


def test_a_block_that_cannot_follow_its_dem_control_is_warned_about():
    """The warning compares the block's departure from the DEM after the second adjustment with the DEM control
    points' sigma Z (a block held by a wrong fixed calibration departs by 30 x; one within its sigmas is fine)."""
    from core.georef.coregister import CoregResult
    from core.georef.demcontrol import HEIGHTS_DEM, DemControl, after_warning
    from core.io.gcp import GroundPoint

    pts = [GroundPoint(f"dem{k:03d}", 0.0, 0.0, 0.0, 2.5, sz) for k, sz in enumerate((0.04, 0.05, 0.06), 1)]
    dc = DemControl("ref.tif", syn.CRS, CoregResult((0.0, 0.0, -1.5), nmad_before=0.9, nmad_after=0.045), pts,
                    HEIGHTS_DEM)
    assert after_warning(dc) is None  # not adjusted again yet
    dc.after = CoregResult((0.0, 0.0, 0.0), nmad_before=1.49)
    assert "could not follow" in after_warning(dc) and "0.05 m" in after_warning(dc)
    dc.after = CoregResult((0.0, 0.0, 0.0), nmad_before=0.12)
    assert after_warning(dc) is None


def test_automatic_control_with_a_reference_dsm_alone_is_dem_control(scene, tmp_path, qgis_app):
    """Issue 32 item 4: 'available from Georeference and the automatic control (a REFERENCE_DSM alone is enough)':
    the automatic control with no reference orthophoto runs the DEM control of Georeference (EXIF GPS placing the
    block); without any rough position it says what to give instead of running."""
    from archaeoortho.processing_provider.auto_control import AutoControlAlgorithm
    from archaeoortho.processing_provider.georeference import GeoreferenceAlgorithm
    from qgis.core import (
        QgsProcessingContext,
        QgsProcessingException,
        QgsProcessingFeedback,
        QgsProject,
        QgsRasterLayer,
    )

    block, rec, _, _, _, ref, positions = scene
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    dsm = QgsRasterLayer(ref, "national DEM in feet", "gdal")
    assert dsm.isValid()
    out = {}
    for label, cls, extra in (("auto", AutoControlAlgorithm, {"PRIOR": 0}),
                              ("georef", GeoreferenceAlgorithm, {"USE_EXIF_GPS": True})):
        ws = synthetic_workspace(tmp_path / label, block, rec)
        set_exif_gps(ws, positions, syn.CRS)
        alg = cls()
        alg.initAlgorithm()
        out[label] = alg.processAlgorithm({"WORKSPACE": ws, "REFERENCE_DSM": dsm, **extra}, context,
                                          QgsProcessingFeedback())
    assert out["auto"]["AUTO_GCPS"] >= 10 and out["auto"]["AUTO_GCPS"] == out["georef"]["DEM_CONTROL_N"]
    assert out["auto"]["GCP_RMSE_Z"] == pytest.approx(out["georef"]["GCP_RMSE_Z"], rel=1e-6)
    assert os.path.isfile(os.path.join(out["auto"]["WORKSPACE"], "georef", "dem_control.json"))
    alg = AutoControlAlgorithm()
    alg.initAlgorithm()
    with pytest.raises(QgsProcessingException, match="EXIF GPS"):
        alg.processAlgorithm({"WORKSPACE": out["auto"]["WORKSPACE"], "REFERENCE_DSM": dsm, "PRIOR": 2}, context,
                             QgsProcessingFeedback())
