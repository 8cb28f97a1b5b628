"""Spectral indices (issue 37 item 3: crop marks): NDVI, NDRE and band expressions of any multi-band raster, against
a synthetic 4-band raster whose reflectances are known per region; the bands found by their descriptions, their
wavelength metadata or their numbers; nodata, alpha and zero denominators; the expression parser refusing what is
not a formula; blocks giving the result of one block; bad input refused before any work; qgis_process."""
from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest
from osgeo import gdal, osr

from core.common.progress import Cancelled, NullProgress
from core.io.multispectral import NAMED_BANDS
from core.spectral import bands as spectral_bands
from core.spectral.bands import WAVELENGTH_RANGES_NM, name_from_text, wavelength_name, wavelength_nm
from core.spectral.errors import SpectralError
from core.spectral.expression import parse
from core.spectral.index import blocks, spectral_index
from core.spectral.options import BandOverrides, IndexOptions

gdal.UseExceptions()

W, H = 60, 40
GT = (500000.0, 0.5, 0.0, 4600020.0, 0.0, -0.5)
EPSG = 32633
ND = -9999.0
# region -> reflectance of (green, red, red edge, NIR)
REGIONS = {
    "field": (0.08, 0.05, 0.25, 0.45),  # healthy crop: NDVI 0.8
    "cropmark": (0.08, 0.05, 0.28, 0.60),  # over a buried ditch: the crop greener, NIR higher
    "wall": (0.09, 0.08, 0.20, 0.30),  # over a buried wall: stressed
    "soil": (0.12, 0.20, 0.22, 0.25),  # bare soil
    "dark": (0.01, 0.0, 0.0, 0.0),  # red and NIR zero: NDVI's and NDRE's denominator zero
}
DESCRIPTIONS = ("Green", "Red", "Red edge", "NIR")
WAVELENGTHS = ("550", "660", "735", "790")


def _regions():
    """Region name -> boolean mask of the W x H grid; the field everywhere else."""
    rows, cols = np.mgrid[0:H, 0:W]
    out = {"cropmark": (cols >= 20) & (cols < 24),  # a ditch: a strip 4 cells wide across the field
           "wall": (rows >= 5) & (rows < 8) & (cols >= 30),
           "soil": (rows >= 30) & (cols < 10),
           "dark": (rows >= 30) & (cols >= 50)}
    out["field"] = ~np.logical_or.reduce(list(out.values()))
    return out


HOLE_RED = (slice(12, 15), slice(40, 45))  # red is nodata here
HOLE_NIR = (slice(20, 22), slice(2, 5))  # NIR is NaN here (finite nodata elsewhere)


def _write(path, n_bands=4, descriptions=DESCRIPTIONS, band_meta=None, alpha=None, dataset_meta=None):
    """The synthetic raster: float32 reflectances per region, nodata -9999 (red's hole) and NaN (NIR's); an alpha band
    (0 where ``alpha`` is False) when given.  Returns the reflectances (bands, H, W) as float64 with NaN holes."""
    data = np.zeros((4, H, W))
    for name, mask in _regions().items():
        for b in range(4):
            data[b][mask] = REGIONS[name][b]
    data = data.astype(np.float32)
    data[1][HOLE_RED] = ND
    data[3][HOLE_NIR] = np.nan
    ds = gdal.GetDriverByName("GTiff").Create(path, W, H, n_bands + (alpha is not None), gdal.GDT_Float32)
    ds.SetGeoTransform(GT)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(EPSG)
    ds.SetProjection(srs.ExportToWkt())
    for b in range(n_bands):
        band = ds.GetRasterBand(b + 1)
        band.WriteArray(data[b])
        band.SetNoDataValue(ND)
        if descriptions:
            band.SetDescription(descriptions[b])
        if band_meta:
            band.SetMetadata(band_meta[b])
    if alpha is not None:
        a = ds.GetRasterBand(n_bands + 1)
        a.SetColorInterpretation(gdal.GCI_AlphaBand)
        a.WriteArray(np.where(alpha, 255, 0).astype(np.float32))
    if dataset_meta:
        ds.SetMetadata(dataset_meta)
    ds = None
    out = data.astype(np.float64)
    out[out == ND] = np.nan
    return out


def _truth(nir, other):
    with np.errstate(all="ignore"):
        v = (nir - other) / (nir + other)
    v[(nir + other) == 0] = np.nan
    return v


def _read(path):
    ds = gdal.Open(path)
    b = ds.GetRasterBand(1)
    v = b.ReadAsArray().astype(np.float64)
    v[v == b.GetNoDataValue()] = np.nan
    return v


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("spectral")
    path = str(folder / "rgn4.tif")
    data = _write(path)
    return path, data


def test_ndvi_of_known_reflectances(scene, tmp_path):
    path, data = scene
    out = str(tmp_path / "ndvi.tif")
    r = spectral_index(IndexOptions(path, out))
    v = _read(out)
    truth = _truth(data[3], data[1])
    regions = _regions()
    print(f"\nNDVI: {r.bands} {r.how}; field {v[regions['field']][0]:.6f}, crop mark {v[regions['cropmark']][0]:.6f}, "
          f"wall {v[regions['wall']][0]:.6f}, soil {v[regions['soil']][0]:.6f}; {r.log_lines}")
    assert r.bands == {"NIR": 4, "RED": 2} and "description 'NIR'" in r.how["NIR"]
    for name, (_, red, _, nir) in REGIONS.items():  # the value of each region from its reflectances (float32 exact)
        if name == "dark":
            continue
        mask = regions[name] & np.isfinite(truth)
        expect = (np.float32(nir) - np.float64(np.float32(red))) / (np.float64(np.float32(nir)) + np.float32(red))
        assert np.abs(v[mask] - expect).max() < 1e-6, name
    assert v[regions["field"]][0] == pytest.approx(0.8, abs=1e-6)
    assert v[regions["cropmark"]][0] - v[regions["field"]][0] > 0.03  # the crop mark stands out
    assert v[regions["wall"]][0] < v[regions["field"]][0] - 0.1
    assert np.array_equal(np.isnan(v), np.isnan(truth))  # nodata: red's hole, NIR's NaN hole, the zero denominator
    assert np.isnan(v[HOLE_RED]).all() and np.isnan(v[HOLE_NIR]).all() and np.isnan(v[regions["dark"]]).all()
    assert np.nanmax(np.abs(v - truth)) < 1e-6
    assert r.valid == int(np.isfinite(truth).sum()) and r.minimum == pytest.approx(np.nanmin(truth), abs=1e-6)
    ds = gdal.Open(out)
    band = ds.GetRasterBand(1)
    assert band.DataType == gdal.GDT_Float32 and band.GetNoDataValue() == -9999.0
    assert band.GetDescription() == "NDVI = (NIR - RED) / (NIR + RED)"
    assert ds.GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE") == "COG"
    assert ds.GetMetadataItem("COMPRESSION", "IMAGE_STRUCTURE") == "DEFLATE"
    assert band.GetBlockSize() == [256, 256] or min(W, H) < 256  # tiled (a raster smaller than a tile: one)
    assert ds.GetGeoTransform() == GT
    assert osr.SpatialReference(wkt=ds.GetProjection()).GetAuthorityCode(None) == str(EPSG)
    assert ds.GetMetadataItem("DISPLAY_MIN") == "-1" and ds.GetMetadataItem("INDEX") == "NDVI"
    assert not [f for f in os.listdir(tmp_path) if f != "ndvi.tif"]  # no temporary file left


def test_ndre_and_the_same_index_by_band_numbers(scene, tmp_path):
    path, data = scene
    r = spectral_index(IndexOptions(path, str(tmp_path / "ndre.tif"), "ndre"))
    assert r.bands == {"NIR": 4, "REDEDGE": 3}
    v = _read(r.path)
    truth = _truth(data[3], data[2])
    assert np.array_equal(np.isnan(v), np.isnan(truth)) and np.nanmax(np.abs(v - truth)) < 1e-6
    by_number = spectral_index(IndexOptions(path, str(tmp_path / "e.tif"), "expression", "(b4 - b3) / (b4 + b3)"))
    assert np.array_equal(_read(by_number.path), v, equal_nan=True)
    named = spectral_index(IndexOptions(path, str(tmp_path / "n.tif"), "expression", "(nir - REG) / (NIR + re)"))
    assert np.array_equal(_read(named.path), v, equal_nan=True)
    assert gdal.Open(named.path).GetRasterBand(1).GetDescription() == "Index = (nir - REG) / (NIR + re)"


def test_expression_functions(scene, tmp_path):
    path, data = scene
    r = spectral_index(IndexOptions(path, str(tmp_path / "f.tif"), "expression",
                                    "clip(sqrt(abs(NIR - RED)) * 2 - min(GRE, 0.05) + max(b1, b2, 0) ** 2, -1, 1)"))
    v = _read(r.path)
    g, red, nir = data[0], data[1], data[3]
    truth = np.clip(np.sqrt(np.abs(nir - red)) * 2 - np.minimum(g, 0.05) + np.maximum(np.maximum(g, red), 0) ** 2,
                    -1, 1)
    assert np.array_equal(np.isnan(v), np.isnan(truth)) and np.nanmax(np.abs(v - truth)) < 1e-6


def test_alpha_band_and_mask_honoured(tmp_path):
    path = str(tmp_path / "rgn-alpha.tif")
    alpha = np.ones((H, W), bool)
    alpha[:, :6] = False  # the mosaic's edge
    data = _write(path, alpha=alpha)
    r = spectral_index(IndexOptions(path, str(tmp_path / "a.tif")))
    v = _read(r.path)
    truth = _truth(data[3], data[1])
    truth[~alpha] = np.nan
    assert np.isnan(v[:, :6]).all() and np.array_equal(np.isnan(v), np.isnan(truth))
    assert np.nanmax(np.abs(v - truth)) < 1e-6
    # without nodata values the alpha band is GDAL's mask of every band (GMF_PER_DATASET): honoured the same way
    ds = gdal.Open(path, gdal.GA_Update)
    for b in range(1, 5):
        ds.GetRasterBand(b).DeleteNoDataValue()
    ds = None
    v2 = _read(spectral_index(IndexOptions(path, str(tmp_path / "b.tif"), "expression", "b4 - b3")).path)
    assert np.isnan(v2[:, :6]).all() and np.isfinite(v2[:, 6:][np.isfinite(data[3][:, 6:])]).all()


def test_per_dataset_mask_honoured(tmp_path):
    """A raster without alpha band but with an internal mask (GDAL's GMF_PER_DATASET, as gdal_translate -mask
    writes): masked cells are nodata."""
    path = str(tmp_path / "masked.tif")
    data = _write(path)
    ds = gdal.Open(path, gdal.GA_Update)
    for b in range(1, 5):
        ds.GetRasterBand(b).DeleteNoDataValue()
    ds.CreateMaskBand(gdal.GMF_PER_DATASET)
    keep = np.ones((H, W), np.uint8) * 255
    keep[-4:, :] = 0
    ds.GetRasterBand(1).GetMaskBand().WriteArray(keep)
    ds = None
    v = _read(spectral_index(IndexOptions(path, str(tmp_path / "m.tif"), "expression", "b4 - b3")).path)
    assert np.isnan(v[-4:]).all()
    assert np.isfinite(v[:-4][np.isfinite(data[3][:-4])]).all()


def test_bands_found_by_wavelength_metadata(tmp_path):
    """No descriptions: the bands' wavelength items say which is which (nm, and µm with wavelength_units)."""
    path = str(tmp_path / "wl.tif")
    meta = [{"wavelength": w} for w in WAVELENGTHS]
    meta[3] = {"wavelength": "0.79", "wavelength_units": "Micrometers"}
    data = _write(path, descriptions=None, band_meta=meta)
    r = spectral_index(IndexOptions(path, str(tmp_path / "ndvi.tif")))
    assert r.bands == {"NIR": 4, "RED": 2}
    assert "790 nm" in r.how["NIR"] and "660 nm" in r.how["RED"], r.how
    v = _read(r.path)
    assert np.nanmax(np.abs(v - _truth(data[3], data[1]))) < 1e-6
    r2 = spectral_index(IndexOptions(path, str(tmp_path / "ndre.tif"), "ndre"))
    assert r2.bands == {"NIR": 4, "REDEDGE": 3}
    # GDAL >= 3.10's IMAGERY items (CENTRAL_WAVELENGTH_UM) read the same
    ds = gdal.Open(path, gdal.GA_Update)
    for b, w in enumerate(WAVELENGTHS):
        ds.GetRasterBand(b + 1).SetMetadata({})
        ds.GetRasterBand(b + 1).SetMetadata({"CENTRAL_WAVELENGTH_UM": f"{float(w) / 1000:g}"}, "IMAGERY")
    ds = None
    assert spectral_index(IndexOptions(path, str(tmp_path / "n3.tif"))).bands == {"NIR": 4, "RED": 2}


@pytest.mark.parametrize("text, name", [
    ("NIR", "NIR"), ("nir1", "NIR"), ("Near infrared", "NIR"), ("Near-IR (840 nm)", "NIR"), ("Red", "RED"),
    ("Band 3 - Red", "RED"), ("Red edge", "REDEDGE"), ("RedEdge", "REDEDGE"), ("REG", "REDEDGE"), ("re", "REDEDGE"),
    ("GRE", "GREEN"), ("green", "GREEN"), ("Blue", "BLUE"), ("Band 4", ""), ("Shortwave infrared", ""),
    ("Alpha", ""), ("", ""), ("Infrared", "NIR"), ("Thermal infrared", ""), ("RE2", "REDEDGE"),
    ("NIR red edge", "REDEDGE"), ("Red NIR", "NIR"), ("Green blue", "GREEN"), ("Red green", "RED")])
def test_band_names_from_descriptions(text, name):
    assert name_from_text(text) == name


def test_wavelength_ranges():
    assert [wavelength_name(nm) for nm in (475, 560, 668, 717, 735, 790, 842, 1600)] == [
        "BLUE", "GREEN", "RED", "REDEDGE", "REDEDGE", "NIR", "NIR", ""]
    assert [n for n, _, _ in WAVELENGTH_RANGES_NM] == ["BLUE", "GREEN", "RED", "REDEDGE", "NIR"]
    assert wavelength_nm("wavelength", "790") == 790 and wavelength_nm("wavelength", "0.79") == pytest.approx(790)
    assert wavelength_nm("wavelength", "790 nm") == 790 and wavelength_nm("CENTRAL_WAVELENGTH_UM", "0.842") == 842
    # the algorithm's help states the ranges the code uses
    import ast

    source = open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "processing_provider",
                               "spectral_index.py"), encoding="utf-8").read()
    help_text = next(node.value.value for node in ast.walk(ast.parse(source)) if isinstance(node, ast.Assign)
                     and getattr(node.targets[0], "id", "") == "HELP")
    ranges = {n: (lo, hi) for n, lo, hi in WAVELENGTH_RANGES_NM}
    for label, name in (("red", "RED"), ("red edge", "REDEDGE"), ("NIR", "NIR")):
        assert f"{label} {ranges[name][0]:g}-{ranges[name][1]:g} nm" in help_text, label


def test_band_numbers_set_by_the_user(tmp_path):
    path = str(tmp_path / "plain.tif")
    data = _write(path, descriptions=None)
    with pytest.raises(SpectralError) as e:
        spectral_index(IndexOptions(path, str(tmp_path / "x.tif")))
    assert "no band named NIR" in str(e.value) and "band 4: no name found" in str(e.value) and path in str(e.value)
    r = spectral_index(IndexOptions(path, str(tmp_path / "o.tif"), bands=BandOverrides(nir=4, red=2)))
    assert r.bands == {"NIR": 4, "RED": 2} and r.how["NIR"] == "the NIR band set to 4"
    assert np.nanmax(np.abs(_read(r.path) - _truth(data[3], data[1]))) < 1e-6
    with pytest.raises(SpectralError, match="set as both the NIR and the RED band"):
        spectral_index(IndexOptions(path, str(tmp_path / "y.tif"), bands=BandOverrides(nir=4, red=4)))
    with pytest.raises(SpectralError, match="set to band 7, but the raster .* has 4 band"):
        spectral_index(IndexOptions(path, str(tmp_path / "y.tif"), bands=BandOverrides(nir=7, red=2)))
    assert not os.path.exists(tmp_path / "y.tif") and not os.path.exists(tmp_path / "x.tif")


def test_two_bands_claiming_nir_are_refused_by_name(tmp_path):
    path = str(tmp_path / "s2.tif")
    _write(path, descriptions=None, band_meta=[{"wavelength": w} for w in ("660", "740", "783", "842")])
    with pytest.raises(SpectralError) as e:
        spectral_index(IndexOptions(path, str(tmp_path / "x.tif")))
    assert "2 bands that are NIR (bands 3, 4, each by its wavelength)" in str(e.value), str(e.value)
    assert spectral_index(IndexOptions(path, str(tmp_path / "o.tif"), bands=BandOverrides(nir=4))).bands["NIR"] == 4


@pytest.mark.parametrize("expression, part", [
    ("__import__('os')", "__import__('os')"),
    ("__import__('os').system('true')", "__import__('os').system('true')"),
    ("b1.real", "b1.real"),
    ("NIR.__class__", "NIR.__class__"),
    ("().__class__", "().__class__"),
    ("open('/etc/passwd')", "open('/etc/passwd')"),
    ("b1 if b2 else b3", "b1 if b2 else b3"),
    ("[b1][0]", "[b1][0]"),
    ("'b1'", "'b1'"),
    ("b1 < b2", "b1 < b2"),
    ("True * b1", "True"),
    ("sqrt(b1, b2)", "sqrt(b1, b2)"),
    ("clip(b1, a_min=0, a_max=1)", "clip(b1, a_min=0, a_max=1)"),
    ("b1 // b2", "b1 // b2"),
    ("b1 % 2", "b1 % 2"),
    ("lambda: b1", "lambda: b1"),
    ("foo + b1", "foo"),
    ("b0 + b1", "b0"),
])
def test_the_expression_parser_refuses_what_is_not_a_formula(expression, part):
    with pytest.raises(SpectralError) as e:
        IndexOptions("in.tif", "out.tif", "expression", expression)
    message = str(e.value)
    assert repr(expression) in message and repr(part) in message, message


@pytest.mark.parametrize("expression", ["(b1", "b1 +", "import os", "b1; b2", "", "1 + 2"])
def test_the_expression_parser_refuses_non_formulas(expression):
    with pytest.raises(SpectralError):
        IndexOptions("in.tif", "out.tif", "expression", expression)


def test_parser_names_and_safe_evaluation():
    e = parse("(Nir - red) / (NIR + RED) + b2 * 0")
    assert e.names == ("NIR", "RED", "B2")
    v = e.evaluate({"NIR": np.array([0.5, 0.0, 1.0]), "RED": np.array([0.1, 0.0, -1.0]), "B2": np.ones(3)})
    assert v[0] == pytest.approx(0.4 / 0.6) and np.isnan(v[1]) and np.isnan(v[2])  # 0 / 0 and x / 0: nodata
    assert np.isnan(parse("sqrt(b1)").evaluate({"B1": np.array([-1.0])})[0])
    assert np.isnan(parse("b1 ** 10 ** 400").evaluate({"B1": np.array([2.0])})[0])  # overflow: nodata, no hang


@pytest.mark.parametrize("block_cells", [50, 20, 7])
def test_blocks_give_the_result_of_one_block(scene, tmp_path, block_cells):
    path, _ = scene
    whole = _read(spectral_index(IndexOptions(path, str(tmp_path / "one.tif"), block_cells=10 ** 9)).path)
    windows = list(blocks(H, W, block_cells))
    assert len(windows) > 20 and all(w * h <= block_cells for _, _, w, h in windows)
    covered = np.zeros((H, W), int)
    for c0, r0, w, h in windows:
        covered[r0:r0 + h, c0:c0 + w] += 1
    assert (covered == 1).all()
    tiled = _read(spectral_index(IndexOptions(path, str(tmp_path / "tiled.tif"), block_cells=block_cells)).path)
    assert np.array_equal(whole, tiled, equal_nan=True)


def test_strips_are_multiples_of_256_rows():
    windows = list(blocks(10_000, 10_000, 4_000_000))
    assert windows[0] == (0, 0, 10_000, 256) and len(windows) == 40


class _CancelAfter(NullProgress):
    def __init__(self, n):
        self.n = n

    def report(self, fraction, message=""):
        self.n -= 1

    def is_cancelled(self):
        return self.n <= 0


def test_cancel_leaves_no_file(scene, tmp_path):
    path, _ = scene
    out = tmp_path / "c.tif"
    with pytest.raises(Cancelled):
        spectral_index(IndexOptions(path, str(out), block_cells=100), _CancelAfter(3))
    assert os.listdir(tmp_path) == []


def test_bad_input_refused_before_any_work(scene, tmp_path):
    path, _ = scene
    out = tmp_path / "o.tif"
    missing = str(tmp_path / "nothere.tif")
    with pytest.raises(SpectralError, match=f"{missing}.* does not exist"):
        spectral_index(IndexOptions(missing, str(out)))
    before = open(path, "rb").read()
    with pytest.raises(SpectralError, match="would overwrite its input"):
        spectral_index(IndexOptions(path, path))
    assert open(path, "rb").read() == before
    with pytest.raises(SpectralError) as e:
        spectral_index(IndexOptions(path, str(out), "expression", "(NIR - RED) / (NIR + RED - BLUE)"))
    message = str(e.value)
    assert "has no band named BLUE" in message and path in message
    assert "band 1 'Green': GREEN from its description 'Green'" in message and "band 4 'NIR': NIR from" in message
    with pytest.raises(SpectralError, match="has 4 band.*no b5"):
        spectral_index(IndexOptions(path, str(out), "expression", "b5 - b1"))
    with pytest.raises(SpectralError, match="unknown name: 'NDVI'"):
        IndexOptions(path, str(out), "expression", "NDVI * 2")
    with pytest.raises(SpectralError, match="unknown spectral index 'evi'"):
        IndexOptions(path, str(out), "evi")
    with pytest.raises(SpectralError, match="needs an expression"):
        IndexOptions(path, str(out), "expression")
    one = str(tmp_path / "one-band.tif")
    _write(one, n_bands=1, descriptions=("NIR",))
    with pytest.raises(SpectralError, match=r"NDVI needs two bands \(NIR and RED\), the raster .*one-band.tif has 1"):
        spectral_index(IndexOptions(one, str(out)))
    assert sorted(os.listdir(tmp_path)) == ["one-band.tif"]  # nothing written


def test_qgis_process_runs_spectralindex(scene, tmp_path):
    """archaeoortho:spectralindex headless: NDVI from the band names, an expression with a band number set, and a
    bad expression refused with its message, no traceback."""
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    path, data = scene

    def run(*args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:spectralindex", "--", f"INPUT={path}", *args],
                              env=env, capture_output=True, text=True, timeout=300)

    out_path = str(tmp_path / "ndvi.tif")
    out = run("INDEX=0", f"OUTPUT={out_path}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    res = json.loads(out.stdout)["results"]
    truth = _truth(data[3], data[1])
    assert os.path.samefile(res["OUTPUT"], out_path) and res["VALID_CELLS"] == int(np.isfinite(truth).sum())
    assert np.nanmax(np.abs(_read(out_path) - truth)) < 1e-6
    expr_path = str(tmp_path / "e.tif")
    out = run("INDEX=2", "EXPRESSION=(NIR - b3) / (NIR + b3)", "NIR_BAND=4", f"OUTPUT={expr_path}")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    assert np.nanmax(np.abs(_read(expr_path) - _truth(data[3], data[2]))) < 1e-6
    out = run("INDEX=2", "EXPRESSION=__import__('os').getcwd()", f"OUTPUT={tmp_path / 'bad.tif'}")
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "Traceback" not in text and "not an allowed function" in text, text[-2000:]
    assert not os.path.exists(tmp_path / "bad.tif")


def test_processing_run_loads_the_index_styled(plugin, scene, tmp_path, qgis_new_project):
    """Through the QGIS Processing API as the toolbox runs it: the index layer is loaded named 'NDVI', in a
    red-yellow-green pseudocolour from -1 to 1; a log line names the bands taken and why."""
    from archaeoortho.qgisio import layers
    from processing.gui.Postprocessing import handleAlgorithmResults
    from qgis.core import (
        QgsApplication,
        QgsProcessingContext,
        QgsProcessingFeedback,
        QgsProject,
        QgsRasterLayer,
    )

    class Feedback(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.infos = []

        def pushInfo(self, info):  # noqa: N802 (QGIS API name)
            self.infos.append(info)

    path, data = scene
    project = QgsProject.instance()
    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:spectralindex").create()
    ctx = QgsProcessingContext()
    ctx.setProject(project)
    feedback = Feedback()
    out = str(tmp_path / "ndvi.tif")
    results, ok = alg.run({"INPUT": path, "INDEX": 0, "OUTPUT": out}, ctx, feedback)
    assert ok, feedback.infos
    assert results["VALID_CELLS"] == int(np.isfinite(_truth(data[3], data[1])).sum())
    assert results["MAXIMUM"] == pytest.approx(0.55 / 0.65, abs=1e-6)  # the crop mark
    assert any("NIR = band 4 (its description 'NIR')" in line for line in feedback.infos), feedback.infos
    assert handleAlgorithmResults(alg, ctx, QgsProcessingFeedback(), parameters={"OUTPUT": out})
    loaded = [lyr for lyr in project.mapLayers().values() if isinstance(lyr, QgsRasterLayer)]
    assert [lyr.name() for lyr in loaded] == ["NDVI"]
    lyr = loaded[0]
    assert lyr.customProperty(layers.KIND_PROPERTY) == layers.INDEX
    r = lyr.renderer()
    assert r.type() == "singlebandpseudocolor"
    assert (r.classificationMin(), r.classificationMax()) == (-1.0, 1.0)
    items = r.shader().rasterShaderFunction().colorRampItemList()
    low, high = items[0].color, items[-1].color
    assert low.red() > 150 and low.green() < 100 and high.green() > 100 and high.red() < 100  # red .. green


def test_band_names_and_ranges_come_from_the_one_table():
    """core.spectral reads names and wavelengths with core.io.multispectral's NAMED_BANDS: every word and phrase of
    the table names its band, every range's middle is its band, the colour interpretations are its keys."""
    assert spectral_bands.BAND_NAMES == ("BLUE", "GREEN", "RED", "REDEDGE", "NIR")
    assert WAVELENGTH_RANGES_NM == (("BLUE", 400.0, 500.0), ("GREEN", 500.0, 600.0), ("RED", 600.0, 690.0),
                                    ("REDEDGE", 690.0, 760.0), ("NIR", 760.0, 1000.0))
    for band in NAMED_BANDS:
        for text in band.words + band.phrases + (band.name, band.key, f"Band 2 - {band.name.title()}"):
            assert name_from_text(text) == band.name, text
        assert wavelength_name(sum(band.nm) / 2) == band.name
        assert spectral_bands.COLOURS[band.key] == band.name
    assert spectral_bands.identify("", {}, "RedEdge")[:1] == ("REDEDGE",)
    assert spectral_bands.identify("", {}, "Green")[:1] == ("GREEN",)
