"""core/prepare/captures.py (issue 37): a rig's captures registered and written as multi-band photos that the chain
takes as photos (bands NIR, Red, Green first, named, wavelengths in their metadata, the capture's GPS and the
registered frame's focal length in EXIF), and the orthomosaic's bands named after them (core.ortho.writer)."""
from __future__ import annotations

import glob
import os
import shutil

import numpy as np
import pytest
from osgeo import gdal

from core.io.images import read_image_info
from core.io.raster import RasterFile
from core.ortho.writer import RasterWriter, photo_band_names
from core.prepare.captures import CaptureStackOptions, photo_names, stack_captures, stack_order
from core.prepare.options import PrepareError
from tests.conftest import shared

gdal.UseExceptions()
SEQUOIA_ID = "1351F8EED82F58668D950A628B8C29BE"


def _sample_bands():
    return sorted(p for p in glob.glob(os.path.join(shared("sequoia_sample"), "*")) if p.upper().endswith((".TIF", ".JPG")))


def test_the_false_colour_bands_come_first():
    assert stack_order(["Green", "Red", "Red edge", "NIR"]) == [3, 1, 0, 2]
    assert stack_order(["Blue", "Green", "Red", "Red edge", "NIR"]) == [4, 2, 1, 0, 3]
    assert stack_order(["Green", "Red edge"]) == [0, 1]


def test_captures_never_share_a_photo_name():
    """Band folders that restart their numbering (MicaSense SET000, SET001) give two captures one file name: each then
    takes its capture id, so neither photo is written over the other."""
    from types import SimpleNamespace

    def cap(cid, path):
        return SimpleNamespace(capture_id=cid, bands=(SimpleNamespace(name=os.path.basename(path)),))

    caps = [cap("A1", "SET000/IMG_0001_1.tif"), cap("B2", "SET001/IMG_0001_1.tif"), cap("C3", "IMG_0002_1.tif"),
            cap("D/4", "band.tif")]
    assert photo_names(caps) == {"A1": "IMG_0001_A1.tif", "B2": "IMG_0001_B2.tif", "C3": "IMG_0002.tif",
                                 "D/4": "D_4.tif"}


def test_the_sequoia_capture_becomes_one_photo_the_chain_reads(tmp_path):
    """The real capture: one 4-band 16-bit photo, NIR-R-G-RE, registered to within 0.5 px (worst window), with the
    capture's GPS and the pinhole frame's focal length read back by core.io.images as the alignment reads them."""
    paths = _sample_bands()
    out = tmp_path / "stacks"
    r = stack_captures(paths, CaptureStackOptions(str(out)))
    assert [os.path.basename(p) for p in r.photos] == ["IMG_161122_163234_0000.tif"]
    assert r.bands == ("NIR", "Red", "Green", "Red edge") and r.left_out == {}
    assert set(r.worst_residual_px) == {"Red", "Red edge", "NIR"} and max(r.worst_residual_px.values()) <= 0.5
    info = read_image_info(r.photos[0])
    band = read_image_info(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_GRE.TIF"))
    assert (info.bands, info.dtype, info.width, info.height) == (4, "UInt16", 1280, 960)
    assert info.gps == pytest.approx(band.gps)
    assert info.focal_source == "exif_plane" and info.focal_px == pytest.approx(1067.5, abs=1.0)  # 2C/pi
    with RasterFile(r.photos[0]) as f:
        names = [f.band(i + 1).GetDescription() for i in range(4)]
        wl = [f.metadata(i + 1).get("wavelength") for i in range(4)]
        nir, green = f.read(1).astype(float), f.read(3).astype(float)
        assert f.metadata().get("CAPTURE") == SEQUOIA_ID
    assert names == ["NIR", "Red", "Green", "Red edge"] and wl == ["790", "660", "550", "735"]
    raw = RasterFile(os.path.join(shared("sequoia_sample"), "IMG_161122_163234_0000_NIR.TIF"))
    try:  # the NIR band's own numbers (resampled into the green frame): same range, not scaled
        assert abs(np.median(nir[nir > 0]) - np.median(raw.read(1))) < 0.1 * np.median(raw.read(1))
    finally:
        raw.close()
    assert (green > 0).mean() > 0.97  # the reference band fills its own frame


def _copy_with_capture_id(src, dst, capture_id):
    """A copy of a band file whose XMP names another capture (the rest of the file as it is)."""
    with RasterFile(src) as r:
        packet = r.metadata(domain="xml:XMP")
    ds = gdal.Translate(str(dst), src)
    ds.SetMetadata([packet[0].replace(SEQUOIA_ID, capture_id)], "xml:XMP")
    ds = None
    return str(dst)


def test_a_capture_missing_a_band_is_left_out_naming_its_files(tmp_path):
    src = tmp_path / "bands"
    src.mkdir()
    paths = [shutil.copy(p, src) for p in _sample_bands() if not p.upper().endswith(".JPG")]
    for p in list(paths):
        if not p.upper().endswith("_NIR.TIF"):
            paths.append(_copy_with_capture_id(p, src / ("B_" + os.path.basename(p)), "SECONDCAPTURE"))
    r = stack_captures(paths, CaptureStackOptions(str(tmp_path / "out")))
    assert len(r.photos) == 1 and list(r.left_out) == ["SECONDCAPTURE"]
    why = r.left_out["SECONDCAPTURE"]
    assert "lacks NIR" in why and "B_IMG_161122_163234_0000_GRE.TIF" in why
    assert any("SECONDCAPTURE" in w and "NIR" in w for w in r.warnings)


def test_the_band_folder_is_never_written_into(tmp_path):
    src = tmp_path / "bands"
    src.mkdir()
    paths = [shutil.copy(p, src) for p in _sample_bands()]
    before = sorted(os.listdir(src))
    with pytest.raises(PrepareError, match="holds the band files"):
        stack_captures(paths, CaptureStackOptions(str(src)))
    assert sorted(os.listdir(src)) == before


def _photo(path, names, wavelengths):
    ds = gdal.GetDriverByName("GTiff").Create(str(path), 8, 6, len(names), gdal.GDT_UInt16)
    for i, (n, w) in enumerate(zip(names, wavelengths)):
        ds.GetRasterBand(i + 1).SetDescription(n)
        ds.GetRasterBand(i + 1).SetMetadata({"wavelength": w})
    ds = None
    return str(path)


def test_an_item_of_one_capture_does_not_unname_the_mosaic(tmp_path):
    """Each capture's photo says how its bands were registered (refined / block, per band): the mosaic keeps the
    band names and the items every photo shares (the unit: reflectance photos are then left as they are)."""
    from core.ortho.writer import calibrated_reflectance

    paths = []
    for k, how in enumerate(("refined", "block", "refined")):
        path = _photo(tmp_path / f"{k}.tif", ["NIR", "Red"], ["790", "660"])
        ds = gdal.Open(path, gdal.GA_Update)
        for i in (1, 2):
            md = ds.GetRasterBand(i).GetMetadata()
            md.update(RADIOMETRIC_UNIT="reflectance", REGISTRATION=how if i == 1 else "reference")
            ds.GetRasterBand(i).SetMetadata(md)
        ds = None
        paths.append(path)
    names, mds = photo_band_names(paths)
    assert names == ["NIR", "Red"]
    assert mds[0] == {"wavelength": "790", "RADIOMETRIC_UNIT": "reflectance"}
    assert mds[1] == {"wavelength": "660", "RADIOMETRIC_UNIT": "reflectance", "REGISTRATION": "reference"}
    assert calibrated_reflectance(paths)
    other = _photo(tmp_path / "dn.tif", ["NIR", "Red"], ["790", "660"])  # no unit: not all reflectance
    assert not calibrated_reflectance(paths + [other])


def test_the_orthomosaic_bands_are_named_after_the_photos(tmp_path):
    a = _photo(tmp_path / "a.tif", ["NIR", "Red"], ["790", "660"])
    b = _photo(tmp_path / "b.tif", ["NIR", "Red"], ["790", "660"])
    c = _photo(tmp_path / "c.tif", ["Red", "NIR"], ["660", "790"])
    names, mds = photo_band_names([a, b])
    assert names == ["NIR", "Red"] and mds == [{"wavelength": "790"}, {"wavelength": "660"}]
    assert photo_band_names([a, c]) == ([], [])  # photos that disagree name nothing
    assert photo_band_names([_photo(tmp_path / "d.tif", ["", ""], ["", ""])])[0] == []
    w = RasterWriter(str(tmp_path / "work.tif"), 16, 12, 2, "uint16", (0, 1, 0, 12, 0, -1), None)
    w.describe(names, mds)
    w.write(0, 0, np.ones((12, 16, 2), np.float32), np.ones((12, 16), bool))
    w.finish(str(tmp_path / "mosaic.tif"), "DEFLATE", None)
    with RasterFile(str(tmp_path / "mosaic.tif")) as r:
        assert [r.band(i + 1).GetDescription() for i in range(2)] == ["NIR", "Red"]
        assert r.metadata(1).get("wavelength") == "790"


def test_the_stack_states_its_radiometry_and_corrects_the_vignetting(tmp_path):
    """The real capture in raw and irradiance radiometry (core.prepare.band_radiometry): the photo states what was
    done, per band the sun sensor's irradiance; the reference band (Green, in its own frame but undistorted) is
    brightened towards the corners by its vignetting model (0.69 at the corner against 0.98 at the centre).
    Measured: 1.13 x, 60-140 px in from the corner."""
    paths = [p for p in _sample_bands() if not p.upper().endswith(".JPG")]
    raw = stack_captures(paths, CaptureStackOptions(str(tmp_path / "raw"), radiometry="raw"))
    irr = stack_captures(paths, CaptureStackOptions(str(tmp_path / "irr"), radiometry="irradiance"))
    with RasterFile(raw.photos[0]) as a, RasterFile(irr.photos[0]) as b:
        assert a.metadata()["RADIOMETRY"].startswith("raw DN")
        md = b.metadata()
        assert "sun sensor" in md["RADIOMETRY"] and md["GREEN_VIGNETTING"] == "Camera:VignettingPolynomial2D"
        assert md["NIR_DARK_LEVEL"] == "75" and float(md["NIR_IRRADIANCE"]) > 0
        green_raw, green = a.read(3).astype(float), b.read(3).astype(float)
    h, w = green.shape
    ok = (green_raw > 200) & (green > 0)
    ratio = np.where(ok, green / np.maximum(green_raw - 74.0, 1.0), np.nan)
    centre = np.nanmedian(ratio[h // 2 - 40:h // 2 + 40, w // 2 - 40:w // 2 + 40])
    corner = np.nanmedian(ratio[60:140, 60:140])
    # the window 60-140 px in from the corner: V about 0.85-0.9 there (0.69 at the corner itself)
    assert 1.08 < corner / centre < 0.977 / 0.69
    with pytest.raises(PrepareError, match="radiometry 'reflectance'"):
        CaptureStackOptions(str(tmp_path / "x"), radiometry="reflectance")


def test_qgis_process_runs_stackcaptures(tmp_path):
    """archaeoortho:stackcaptures headless on a copy of the real capture's folder (the RGB frame in it too): one
    4-band photo in irradiance radiometry; an empty folder and the band folder as output refused with their
    messages, no traceback, nothing written."""
    import json
    import subprocess

    from tests.conftest import qgis_process

    exe, env = qgis_process()
    src = tmp_path / "bands"
    src.mkdir()
    for p in _sample_bands():
        shutil.copy(p, src)

    def run(folder, output, *args):
        return subprocess.run([exe, "--json", "run", "archaeoortho:stackcaptures", "--", f"INPUT={folder}",
                               f"OUTPUT={output}", *args], env=env, capture_output=True, text=True, timeout=300)

    out = run(src, tmp_path / "photos", "RADIOMETRY=2")
    assert out.returncode == 0, out.stderr[-3000:] + out.stdout[-3000:]
    res = json.loads(out.stdout)["results"]
    assert (res["PHOTOS"], res["LEFT_OUT"]) == (1, 0)
    photo = tmp_path / "photos" / "IMG_161122_163234_0000.tif"
    with RasterFile(str(photo)) as r:
        assert r.count == 4 and "sun sensor" in r.metadata()["RADIOMETRY"]
    empty = tmp_path / "empty"
    empty.mkdir()
    for folder, output, message in ((empty, tmp_path / "o1", "no image files"), (src, src, "holds the band files")):
        before = sorted(os.listdir(folder))
        out = run(folder, output)
        text = out.stdout + out.stderr
        assert out.returncode != 0 and message in text and "Traceback" not in text, text[-2000:]
        assert sorted(os.listdir(folder)) == before


@pytest.mark.parametrize("bands,dtype", [(1, "uint8"), (2, "uint16"), (3, "uint8"), (4, "uint16"), (5, "uint16")])
def test_only_the_mosaics_last_band_is_alpha(tmp_path, bands, dtype):
    """The orthomosaic's alpha is its last band, whatever its bands: GTiff's ALPHA=YES marks the first extra
    sample, which in a grey-interpreted multispectral mosaic (NIR, Red, ...) is band 2 -- Spectral index then
    read the Red band as a mask."""
    w = RasterWriter(str(tmp_path / "work.tif"), 16, 12, bands, dtype, (0, 1, 0, 12, 0, -1), None)
    w.write(0, 0, np.ones((12, 16, bands), np.float32), np.ones((12, 16), bool))
    w.finish(str(tmp_path / "mosaic.tif"), "DEFLATE", None)
    with RasterFile(str(tmp_path / "mosaic.tif")) as r:
        alpha = [r.band(i + 1).GetColorInterpretation() == gdal.GCI_AlphaBand for i in range(r.count)]
    assert alpha == [False] * bands + [True]


def test_a_dark_reflectance_pixel_is_not_nodata(tmp_path):
    """A reflectance photo's 0 is its nodata: a pixel below the dark level (negative after it is removed) stays a
    value, the floor; NaN (where a band does not reach) becomes 0."""
    from core.io.multispectral import REFLECTANCE_FLOOR, write_band_stack

    data = np.array([[[0.2, -0.01], [np.nan, 0.0]]], np.float32)
    path = write_band_stack(str(tmp_path / "r.tif"), data, ["NIR"], dtype="reflectance")
    ds = gdal.Open(path)
    out, nodata = ds.GetRasterBand(1).ReadAsArray(), ds.GetRasterBand(1).GetNoDataValue()
    assert nodata == 0.0 and out.dtype == np.float32
    assert out[0, 0] == np.float32(0.2) and out[0, 1] == REFLECTANCE_FLOOR and out[1, 1] == REFLECTANCE_FLOOR
    assert out[1, 0] == 0.0
