"""core/io/multispectral.py (issue 37): band metadata of Sequoia (real sample), MicaSense- and DJI-style files
(synthetic, from their documented tags), captures, the block's errors and warnings, the primary band.

The Sequoia values were read independently with ``gdalinfo -mdd xml:XMP`` / ``-mdd EXIF`` and the first
IrradianceList record of GRE with ``struct.unpack("<QHHHHfff", base64.b64decode(...)[:28])``."""
from __future__ import annotations

import os
from datetime import datetime

import numpy as np
import pytest
from osgeo import gdal

from core.io.multispectral import (
    INDEX_BANDS,
    NAMED_BANDS,
    MultispectralError,
    Vignetting,
    band_files,
    band_key,
    check_captures,
    group_captures,
    parse_xmp,
    primary_band,
    read_band_info,
    read_block,
)
from tests.conftest import shared

gdal.UseExceptions()

NS = {"Camera": "http://pix4d.com/camera/1.0/", "drone-dji": "http://www.dji.com/drone-dji/1.0/",
      "MicaSense": "http://micasense.com/MicaSense/1.0/"}
SEQUOIA_ID = "1351F8EED82F58668D950A628B8C29BE"


def xmp(attrs: dict, seqs: dict = None) -> str:
    """An XMP packet: ``attrs`` as attributes, ``seqs`` ({"Camera:Name": [items]}) as rdf:Seq elements."""
    decl = " ".join(f'xmlns:{p}="{u}"' for p, u in NS.items())
    att = " ".join(f'{k}="{v}"' for k, v in attrs.items())
    body = "".join(f"<{k}><rdf:Seq>" + "".join(f"<rdf:li>{i}</rdf:li>" for i in items) + f"</rdf:Seq></{k}>"
                   for k, items in (seqs or {}).items())
    return ('<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">'
            f'<rdf:Description rdf:about="" {decl} {att}>{body}</rdf:Description></rdf:RDF></x:xmpmeta>')


def write_band(path, packet: str, exif: dict = None, array=None, bands: int = 1) -> str:
    a = array if array is not None else (np.arange(48 * 64, dtype=np.uint16).reshape(48, 64) * 7)
    ds = gdal.GetDriverByName("GTiff").Create(str(path), a.shape[1], a.shape[0], bands, gdal.GDT_UInt16)
    for b in range(1, bands + 1):
        ds.GetRasterBand(b).WriteArray(a)
    if exif:
        ds.SetMetadata(exif, "EXIF")
    if packet:
        ds.SetMetadata([packet], "xml:XMP")
    ds = None
    return str(path)


def exif_at(seconds: float, exposure: str = "0.001") -> dict:
    whole = int(seconds)
    return {"EXIF_DateTimeOriginal": f"2023:05:01 10:00:{whole:02d}",
            "EXIF_SubSecTime": f"{round((seconds - whole) * 1000):03d}", "EXIF_ExposureTime": exposure,
            "EXIF_ISOSpeedRatings": "100"}


def simple_band(folder, name, band, capture_id, seconds, calibrated=True):
    attrs = {"Camera:BandName": band, "Camera:RigName": "TestRig"}
    if capture_id:
        attrs["MicaSense:CaptureId"] = capture_id
    if calibrated:
        attrs["Camera:BlackLevel"] = "4800"
    return write_band(folder / name, xmp(attrs), exif_at(seconds))


# ---------------------------------------------------------------- the real Sequoia capture
def test_sequoia_nir_read_as_gdalinfo_shows_it():
    folder = shared("sequoia_sample")
    b = read_band_info(os.path.join(folder, "IMG_161122_163234_0000_NIR.TIF"))
    assert (b.band_name, b.central_wavelength_nm, b.fwhm_nm) == ("NIR", 790.0, 40.0)
    assert (b.rig_name, b.rig_camera_index, b.capture_id) == ("Sequoia", 3, SEQUOIA_ID)
    assert b.rig_relatives == (-0.5667564232, -0.0112600465, 0.3129574125)
    assert b.timestamp == datetime(2016, 11, 22, 16, 32, 34, 430207)
    assert b.lens.kind == "fisheye"
    assert b.lens.fisheye_polynomial == (0.0, 1.0, 0.010754389, -0.147354298)
    assert b.lens.fisheye_affine == (1671.556624069, 0.0, 0.0, 1671.556624069)
    assert b.lens.principal_point_mm == (2.544297, 1.797905)
    assert b.black_level == 75.0 and b.band_gain == 1.0 and b.exposure_s == pytest.approx(0.0018)
    assert b.iso == 100 and b.line_readout_time == 23076 and b.sensor_temperature_c == pytest.approx(48.571411)
    v = b.vignetting
    assert v.model == "poly2d" and len(v.coefficients) == 15 and v.coefficients[0] == pytest.approx(0.6711373881480992)
    assert v.exponents[:3] == ((0, 0), (1, 0), (2, 0)) and v.exponents[-1] == (3, 1)
    first = b.irradiance.records[0]
    assert b.irradiance.source == "Camera:IrradianceList" and len(b.irradiance.records) == 51
    assert (first.timestamp_us, first.ch0, first.ch1, first.gain_index, first.integration_ms) == \
        (267651971, 645, 324, 1, 100)
    assert (first.yaw, first.pitch, first.roll) == pytest.approx((23.775095, -1.329787, 1.817879), abs=1e-5)
    # the records are 200 ms apart over 10 s: a sensible sunshine log, not misaligned bytes
    steps = np.diff([r.timestamp_us for r in b.irradiance.records])
    assert np.all((steps > 150_000) & (steps < 250_000))


def test_sequoia_green_is_the_rig_reference_and_its_first_irradiance_record():
    folder = shared("sequoia_sample")
    b = read_band_info(os.path.join(folder, "IMG_161122_163234_0000_GRE.TIF"))
    assert (b.band_name, b.rig_camera_index, b.rig_relatives, b.black_level) == ("Green", 0, None, 74.0)
    first = b.irradiance.records[0]
    assert (first.timestamp_us, first.ch0, first.ch1, first.gain_index, first.integration_ms) == \
        (267651971, 666, 64, 1, 100)


def test_sequoia_capture_holds_the_rgb_frame_and_rgb_is_primary():
    folder = shared("sequoia_sample")
    block = read_block(band_files(folder))
    assert len(block.captures) == 1
    cap = block.captures[0]
    assert cap.capture_id == SEQUOIA_ID
    assert cap.band_names == ("Green", "Red", "Red edge", "NIR", "RGB")
    rgb = cap.band("rgb")
    assert rgb.capture_id is None and rgb.band_names == ("Red", "Green", "Blue")
    assert rgb.lens.kind == "perspective" and rgb.lens.focal_length == 4.812073 and rgb.lens.focal_length_unit == "mm"
    assert rgb.lens.distortion == (0.178441961, -0.4745818, 0.402026402, -0.000900784, -0.000653429)
    assert (rgb.make, rgb.model, rgb.iso) == ("Parrot", "Sequoia", 125)
    assert block.warnings == ()
    assert primary_band(block).name == "RGB"
    # 68 ms after its bands: with a 50 ms tolerance it is a capture of its own
    assert len(group_captures([*cap.bands], tolerance_s=0.05)) == 2


def test_photos_of_another_camera_among_the_bands_are_named_not_taken_for_a_missing_rgb_frame():
    """Issue 47 item 16: a folder mixing the Sequoia's band files and a drone's JPEGs (no rig name, no capture id,
    taken at none of the rig's captures' times).  They are named (how many, which) as not the rig's band files and
    left out; the Sequoia capture is not said to lack an "RGB" band (the JPEGs' "band")."""
    folder = shared("sequoia_sample")
    bands = [os.path.join(folder, f"IMG_161122_163234_0000_{b}.TIF") for b in ("GRE", "RED", "REG", "NIR")]
    toledo = shared("toledo", "images")
    jpegs = [os.path.join(toledo, n) for n in sorted(os.listdir(toledo))[:3]]
    block = read_block(bands + jpegs)
    assert [c.capture_id for c in block.captures] == [SEQUOIA_ID]
    assert block.band_names == ("Green", "Red", "Red edge", "NIR")
    assert not any("lacks" in w for w in block.warnings), block.warnings
    named = [w for w in block.warnings if "3 file(s)" in w and "not band files of the rig Sequoia" in w]
    assert len(named) == 1 and all(os.path.basename(j) in named[0] for j in jpegs), block.warnings
    assert "DJI" in named[0] and "left out" in named[0]
    # the rig's own RGB frame (rig name Sequoia, 68 ms after its bands) stays in its capture, unnamed
    block = read_block(bands + [os.path.join(folder, "IMG_161122_163234_0000_RGB.JPG")] + jpegs)
    assert block.captures[0].band_names == ("Green", "Red", "Red edge", "NIR", "RGB")
    assert len([w for w in block.warnings if "3 file(s) are not band files" in w]) == 1, block.warnings
    assert not any("lacks" in w for w in block.warnings), block.warnings


# ---------------------------------------------------------------- MicaSense and DJI style (documented tags)
def test_micasense_style_tags(tmp_path):
    packet = xmp({"MicaSense:CaptureId": "mYcApTuReId0001", "Camera:BandName": "NIR", "Camera:RigCameraIndex": "3",
                  "Camera:PrincipalPoint": "2.41,1.83", "Camera:PerspectiveFocalLength": "5.45",
                  "Camera:PerspectiveFocalLengthUnits": "mm", "Camera:Irradiance": "0.917",
                  "Camera:BlackLevel": "4800", "Camera:RigRelatives": "0.1,-0.2,0.05"},
                 {"Camera:CentralWavelength": [842], "Camera:WavelengthFWHM": [57],
                  "Camera:VignettingCenter": [623.5, 492.25],
                  "Camera:VignettingPolynomial": [-1.1e-4, 1.9e-6, -1.2e-8, 3.3e-11, -4.1e-14, 1.8e-17],
                  "Camera:PerspectiveDistortion": [-0.1, 0.2, -0.05, 0.0003, -0.0004]})
    b = read_band_info(write_band(tmp_path / "IMG_0001_4.tif", packet, exif_at(1.25) | {"EXIF_Make": "MicaSense"}))
    assert (b.band_name, b.central_wavelength_nm, b.fwhm_nm, b.rig_camera_index) == ("NIR", 842, 57, 3)
    assert b.capture_id == "mYcApTuReId0001" and b.rig_relatives == (0.1, -0.2, 0.05)
    assert b.timestamp == datetime(2023, 5, 1, 10, 0, 1, 250000) and b.make == "MicaSense"
    assert b.lens.kind is None and b.lens.principal_point_mm == (2.41, 1.83)
    assert (b.lens.focal_length, b.lens.focal_length_unit) == (5.45, "mm")
    assert b.lens.distortion == (-0.1, 0.2, -0.05, 0.0003, -0.0004)
    assert b.black_level == 4800 and b.exposure_s == 0.001 and b.iso == 100 and b.band_gain is None
    assert b.vignetting == Vignetting("radial", (-1.1e-4, 1.9e-6, -1.2e-8, 3.3e-11, -4.1e-14, 1.8e-17),
                                      center_px=(623.5, 492.25), source="Camera:VignettingPolynomial")
    assert (b.irradiance.value, b.irradiance.source, b.irradiance.records) == (0.917, "Camera:Irradiance", ())


def test_dji_p4m_style_tags(tmp_path):
    packet = xmp({"drone-dji:CaptureUUID": "d1f2-capture", "Camera:BandName": "Red", "Camera:RigCameraIndex": "3",
                  "drone-dji:CalibratedOpticalCenterX": "800.5", "drone-dji:CalibratedOpticalCenterY": "650.25",
                  "drone-dji:DewarpData": "2020-02-04;1949.45,1939.77,28,-17,-0.4082,0.3418,0.00068,0.00068,-0.354",
                  "drone-dji:VignettingData": "0.000218235, 1.20722E-06, -2.8676E-09, 5.1742E-12, -4.16853E-15, "
                                              "1.36962E-18",
                  "drone-dji:Irradiance": "2000.000", "drone-dji:SensorGain": "1.5",
                  "drone-dji:SensorGainAdjustment": "1.002", "drone-dji:ExposureTime": "1000",
                  "drone-dji:BlackLevel": "4096"},
                 {"Camera:CentralWavelength": [650]})
    exif = {"EXIF_DateTimeOriginal": "2020:06:01 09:30:00", "EXIF_Make": "DJI"}  # no EXIF exposure
    b = read_band_info(write_band(tmp_path / "DJI_0013.TIF", packet, exif))
    assert (b.band_name, b.central_wavelength_nm, b.rig_camera_index, b.capture_id) == ("Red", 650, 3, "d1f2-capture")
    assert b.lens.kind == "opencv" and b.lens.dewarp == (1949.45, 1939.77, 28, -17)
    assert b.lens.distortion == (-0.4082, 0.3418, 0.00068, 0.00068, -0.354) and b.lens.dewarp_date == "2020-02-04"
    assert b.lens.optical_center_px == (800.5, 650.25)
    assert b.vignetting.model == "radial" and b.vignetting.center_px == (800.5, 650.25)
    assert b.vignetting.coefficients[1] == pytest.approx(1.20722e-06) and len(b.vignetting.coefficients) == 6
    assert (b.band_gain, b.gain_adjustment, b.black_level) == (1.5, 1.002, 4096)
    assert b.exposure_s == pytest.approx(0.001)  # drone-dji:ExposureTime is in microseconds
    assert b.irradiance.value == 2000 and b.irradiance.source == "drone-dji:Irradiance"
    assert b.fwhm_nm is None and b.sensor_temperature_c is None and b.line_readout_time is None  # never invented


def test_xmp_with_an_undeclared_prefix_is_read_for_its_attributes():
    packet = '<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF><rdf:Description Camera:BandName="NIR" ' \
             'Camera:CaptureUUID="ABC"/></rdf:RDF></x:xmpmeta>'
    assert parse_xmp(packet) == {"Camera:BandName": "NIR", "Camera:CaptureUUID": "ABC"}


# ---------------------------------------------------------------- the block's checks
def two_captures(tmp_path, names=("Green", "Red", "NIR")):
    files = []
    for k, (cid, t) in enumerate((("CAP-A", 1.0), ("CAP-B", 3.0))):
        for band in names:
            files.append(simple_band(tmp_path, f"IMG_{k}_{band}.tif", band, cid, t + 0.004 * len(files)))
    return files


def test_a_capture_without_nir_is_a_warning_naming_it(tmp_path):
    files = two_captures(tmp_path)
    os.remove(files.pop())  # CAP-B's NIR
    block = read_block(files)
    assert [c.capture_id for c in block.captures] == ["CAP-A", "CAP-B"]
    assert block.band_names == ("Green", "Red", "NIR")
    assert len(block.warnings) == 1
    w = block.warnings[0]
    assert "capture CAP-B" in w and "lacks NIR" in w and "IMG_1_Green.tif" in w and "IMG_1_Red.tif" in w
    assert "NDVI" in w and "its other bands are used" in w


def test_files_of_two_captures_under_one_id_stop_the_block(tmp_path):
    files = two_captures(tmp_path)
    stray = simple_band(tmp_path, "IMG_9_NIR.tif", "NIR", "CAP-A", 7.5)  # a later capture's file carrying CAP-A
    os.remove(files[2])
    with pytest.raises(MultispectralError) as e:
        read_block(files[:2] + files[3:] + [stray])
    msg = str(e.value)
    assert "capture id CAP-A" in msg and "IMG_9_NIR.tif" in msg and "IMG_0_Green.tif" in msg
    assert "different times" in msg


def test_a_band_twice_in_a_capture_stops_the_block(tmp_path):
    files = two_captures(tmp_path)
    copy = simple_band(tmp_path, "IMG_0_NIR copy.tif", "NIR", "CAP-A", 1.01)
    with pytest.raises(MultispectralError, match=r"capture CAP-A has band NIR twice \(") as e:
        read_block(files + [copy])
    assert "IMG_0_NIR.tif" in str(e.value) and "IMG_0_NIR copy.tif" in str(e.value)


def test_a_band_without_calibration_is_a_warning_naming_it(tmp_path):
    files = two_captures(tmp_path, names=("Green", "Red"))
    bare = simple_band(tmp_path, "IMG_0_NIR.tif", "NIR", "CAP-A", 1.02, calibrated=False)
    bare2 = simple_band(tmp_path, "IMG_1_NIR.tif", "NIR", "CAP-B", 3.02, calibrated=False)
    block = read_block(files + [bare, bare2])
    assert len(block.warnings) == 1
    w = block.warnings[0]
    assert w.startswith("band NIR: 2 file(s) carry no radiometric calibration") and "IMG_1_NIR.tif" in w
    assert "no reflectance" in w


def test_a_file_naming_no_band_or_no_capture_stops_the_block(tmp_path):
    files = two_captures(tmp_path)
    plain = write_band(tmp_path / "holiday.tif", "", exif_at(1.0))
    with pytest.raises(MultispectralError, match="holiday.tif: its XMP names no band"):
        read_block(files + [plain])
    lost = write_band(tmp_path / "lost.tif", xmp({"Camera:BandName": "NIR"}))
    with pytest.raises(MultispectralError, match="lost.tif: no capture id in the XMP and no EXIF DateTimeOriginal"):
        read_block(files + [lost])


def test_files_without_capture_id_are_grouped_by_time(tmp_path):
    files = [simple_band(tmp_path, f"t{t}_{band}.tif", band, None, t)
             for t in (1.0, 1.03, 2.0) for band in (["Green"] if t == 1.0 else ["NIR"] if t == 1.03 else
                                                    ["Green", "NIR"])]
    infos = [read_band_info(f) for f in files]
    caps = group_captures(infos)
    assert [c.band_names for c in caps] == [("Green", "NIR"), ("Green", "NIR")]
    assert check_captures(infos, caps) == []
    assert len(group_captures(infos, tolerance_s=0.01)) == 3


def test_primary_band_without_rgb_is_the_most_textured(tmp_path):
    yy, xx = np.mgrid[0:240, 0:320]
    checker = (((yy // 8) + (xx // 8)) % 2 * 30000 + 1000).astype(np.uint16)
    smooth = (xx * 100 + 1000).astype(np.uint16)
    files = []
    for cid, t in (("A", 1.0), ("B", 2.0)):
        for band, arr in (("Green", smooth), ("NIR", checker)):
            attrs = {"Camera:BandName": band, "MicaSense:CaptureId": cid, "Camera:BlackLevel": "0"}
            files.append(write_band(tmp_path / f"{cid}_{band}.tif", xmp(attrs), exif_at(t), array=arr))
    p = primary_band(read_block(files))
    assert p.name == "NIR" and p.scores["NIR"] > 10 * p.scores["Green"] and "texture" in p.reason


def test_the_band_name_table():
    """NAMED_BANDS: one entry per band, its key the band_key of its name (what band files are compared by, the keys
    INDEX_BANDS names), the wavelength ranges joining without gap or overlap; band_key itself unchanged."""
    assert [b.name for b in NAMED_BANDS] == ["REDEDGE", "NIR", "RED", "GREEN", "BLUE"]
    assert {b.key for b in NAMED_BANDS} == {"rededge", "nir", "red", "green", "blue"}
    assert all(b.key == band_key(b.name) for b in NAMED_BANDS)
    assert {k for _, needs in INDEX_BANDS for k in needs} <= {b.key for b in NAMED_BANDS}
    ranges = sorted(b.nm for b in NAMED_BANDS)
    assert all(lo < hi for lo, hi in ranges) and all(a[1] == b[0] for a, b in zip(ranges, ranges[1:]))
    assert dict((b.name, b.nm) for b in NAMED_BANDS)["REDEDGE"] == (690.0, 760.0)
    words = [w for b in NAMED_BANDS for w in b.words]
    assert len(words) == len(set(words)) and {"reg", "re", "gre"} <= set(words)
    assert (band_key("Red edge"), band_key("REG"), band_key("NIR 1"), band_key(None)) == ("rededge", "reg", "nir1", "")
