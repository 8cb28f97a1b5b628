import math
import os

import numpy as np
import pytest

from core.io.images import (
    GROUP_PER_IMAGE,
    GROUP_SINGLE,
    ImageError,
    group_cameras,
    read_image,
    read_image_info,
    scan_images,
)
from tests.conftest import SAMPLE, shared


def test_exif_focal_and_gps_toledo():
    info = read_image_info(os.path.join(SAMPLE, "images", "1JI_0064.JPG"))
    assert (info.width, info.height, info.bands) == (1200, 900, 3)
    assert info.make == "DJI" and info.model == "FC300X"
    assert info.focal_mm == pytest.approx(3.61)
    # 20 mm (35 mm equivalent) over the full-frame diagonal, times this image's diagonal (1500 px)
    assert info.focal_px == pytest.approx(20 / math.hypot(36, 24) * 1500, rel=1e-6)
    assert info.focal_source == "exif35"
    lon, lat, alt = info.gps
    assert lat == pytest.approx(41 + 32 / 60 + 57.8681 / 3600)
    assert lon == pytest.approx(-(83 + 41 / 60 + 56.1111 / 3600))
    assert alt == pytest.approx(122.3)


def _tiff_with_exif(path, exif):
    """A 16-bit single-band TIFF (a multispectral band file) whose EXIF tags GDAL keeps in its EXIF domain."""
    from osgeo import gdal

    ds = gdal.GetDriverByName("GTiff").Create(str(path), 64, 48, 1, gdal.GDT_UInt16)
    ds.GetRasterBand(1).WriteArray(np.full((48, 64), 1000, np.uint16))
    ds.SetMetadata(exif, "EXIF")
    ds = None
    return str(path)


def test_exif_of_a_tiff_band_file(tmp_path):
    """GDAL shows a TIFF's EXIF only in its EXIF domain: the GPS and focal length of a band TIFF are read (issue 37:
    a Sequoia band folder through Run pipeline stopped with 'no target CRS' although every band carries GPS)."""
    path = _tiff_with_exif(tmp_path / "IMG_0000_NIR.TIF", {
        "EXIF_GPSLatitude": "(41) (25) (43.2518)", "EXIF_GPSLatitudeRef": "N", "EXIF_GPSLongitude": "(81) (36) (21.1874)",
        "EXIF_GPSLongitudeRef": "W", "EXIF_GPSAltitude": "(347.723)", "EXIF_GPSAltitudeRef": "0x00",
        "EXIF_FocalLength": "(3.98)", "EXIF_Orientation": "1"})
    info = read_image_info(path)
    assert (info.bands, info.dtype) == (1, "UInt16")
    assert info.focal_mm == pytest.approx(3.98)
    lon, lat, alt = info.gps
    assert lat == pytest.approx(41 + 25 / 60 + 43.2518 / 3600)
    assert lon == pytest.approx(-(81 + 36 / 60 + 21.1874 / 3600))
    assert alt == pytest.approx(347.723)
    assert read_image_info(_tiff_with_exif(tmp_path / "none.tif", {})).gps is None


def test_exif_of_the_real_sequoia_bands():
    """The four band TIFFs of the Sequoia capture: each carries the capture's GPS in its TIFF EXIF IFD."""
    folder = shared("sequoia_sample")
    for band in ("GRE", "RED", "REG", "NIR"):
        info = read_image_info(os.path.join(folder, f"IMG_161122_163234_0000_{band}.TIF"))
        assert (info.width, info.height, info.dtype) == (1280, 960, "UInt16")
        lon, lat, alt = info.gps
        assert lat == pytest.approx(41 + 25 / 60 + 43.2518 / 3600, abs=2e-5), band
        assert lon == pytest.approx(-(81 + 36 / 60 + 21.1874 / 3600), abs=2e-5), band
        assert info.focal_mm == pytest.approx(3.98)


def test_exif_focal_plane_resolution_copr():
    info = read_image_info(shared("copr", "images", "IMG_0037.jpg"))
    # 30 mm x 4865.6 px/inch / 25.4, scaled from 4272 px to 1200 px wide
    assert info.focal_px == pytest.approx(30 * 4865.6 / 25.4 * 1200 / 4272, rel=1e-6)
    assert info.gps is None


def test_manual_interior_orientation(tmp_path):
    info = read_image_info(os.path.join(SAMPLE, "images", "1JI_0064.JPG"), manual_focal_mm=152.0,
                           manual_sensor_width_mm=230.0)
    assert info.focal_source == "manual"
    assert info.focal_px == pytest.approx(152.0 / 230.0 * 1200)


def test_bad_files_are_named(tmp_path):
    good = open(os.path.join(SAMPLE, "images", "1JI_0064.JPG"), "rb").read()
    (tmp_path / "a_good.jpg").write_bytes(good)
    (tmp_path / "b_truncated.jpg").write_bytes(good[: len(good) // 3])
    (tmp_path / "c_empty.jpg").write_bytes(b"")
    (tmp_path / "d_text.jpg").write_text("this is not a JPEG")
    (tmp_path / "notes.txt").write_text("hello")
    infos, warnings = scan_images(str(tmp_path))
    assert [i.name for i in infos] == ["a_good.jpg"]
    text = "\n".join(warnings)
    for name in ("b_truncated.jpg", "c_empty.jpg", "d_text.jpg", "notes.txt"):
        assert name in text
    assert "0 bytes" in text


def test_sixteen_bit_and_single_band(tmp_path):
    from osgeo import gdal

    path = str(tmp_path / "nir16.tif")
    ds = gdal.GetDriverByName("GTiff").Create(path, 64, 48, 1, gdal.GDT_UInt16)
    arr = (np.arange(64 * 48).reshape(48, 64) * 17).astype(np.uint16)
    ds.GetRasterBand(1).WriteArray(arr)
    ds = None
    info = read_image_info(path)
    assert info.bands == 1 and info.dtype == "UInt16"
    pix = read_image(path)
    assert pix.shape == (48, 64, 1) and pix.dtype == np.uint16
    assert np.array_equal(pix[:, :, 0], arr)
    small = read_image(path, max_size=32)
    assert small.shape[:2] == (24, 32)


def test_camera_groups():
    infos, _ = scan_images(os.path.join(SAMPLE, "images"))
    auto = group_cameras(infos)
    assert sorted(g.model for g in auto) == ["FC300X", "FC350"]
    assert sum(len(g.images) for g in auto) == len(infos)
    assert len(group_cameras(infos, GROUP_SINGLE)) == 1
    assert len(group_cameras(infos, GROUP_PER_IMAGE)) == len(infos)


def test_missing_folder():
    with pytest.raises(ImageError, match="does not exist"):
        scan_images("/nonexistent/folder")
