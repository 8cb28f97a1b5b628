"""A multispectral capture's stacked photo is matched on its primary band (issue 37 item 1): the stack names it
(PRIMARY_BAND), the photo's info reads it, Align images extracts the features from an 8-bit image of that band
(sfm/feature_images) and dense matching reads that band alone."""
from __future__ import annotations

import os

import numpy as np


def _stack(path, bands, names, primary, dtype="uint16"):
    from core.io.multispectral import write_band_stack

    md = {"PRIMARY_BAND": primary} if primary else {}
    write_band_stack(path, bands, names, md, dtype=dtype)
    return path


def _bands(h=60, w=80):
    rng = np.random.default_rng(3)
    nir = rng.uniform(20000, 30000, (h, w))
    green = np.zeros((h, w)) + 1000.0
    green[:, w // 2:] = 3000.0  # an edge only the green band has
    red = rng.uniform(500, 800, (h, w))
    return np.stack([nir, red, green]), ("NIR", "Red", "Green")


def test_the_photo_names_its_primary_band_and_its_info_reads_it(tmp_path):
    from core.io.images import primary_band, read_image_info

    bands, names = _bands()
    p = _stack(str(tmp_path / "a.tif"), bands, names, "Green")
    assert primary_band(p) == 3 and read_image_info(p).primary_band == 3
    q = _stack(str(tmp_path / "b.tif"), bands, names, "Blue")  # a band the photo does not have
    assert primary_band(q) == 0
    r = _stack(str(tmp_path / "c.tif"), bands, names, None)
    assert read_image_info(r).primary_band == 0


def test_matching_grey_takes_the_primary_band_stretched_to_8_bit():
    from core.io.images import matching_grey8

    bands, _names = _bands()
    arr = np.moveaxis(bands, 0, -1).astype(np.uint16)
    g = matching_grey8(arr, 3)
    assert g.dtype == np.uint8
    left, right = g[:, :30].mean(), g[:, 50:].mean()
    assert left < 10 and right > 245  # the green band's edge, stretched over 0..255
    lum = matching_grey8(arr)  # no primary band: luminance of the first three bands (NIR dominates)
    assert abs(float(lum[:, :30].mean()) - float(lum[:, 50:].mean())) < 0.5 * (right - left)
    rgb = np.dstack([np.full((4, 4), 200, np.uint8)] * 3)
    assert (matching_grey8(rgb) == 200).all()


def test_align_extracts_the_stacks_features_from_their_primary_band(tmp_path):
    from core.align.features import FEATURE_IMAGES, Extraction, FeatureSettings, _extraction_blocks, feature_images
    from core.io.images import CameraGroup, read_image, read_image_info
    from core.io.raster import RasterFile

    bands, names = _bands()
    folder = tmp_path / "photos"
    folder.mkdir()
    p = _stack(str(folder / "a.tif"), bands, names, "Green")
    q = str(folder / "b.tif")  # a plain 8-bit photo: COLMAP reads it as it is
    from osgeo import gdal

    ds = gdal.GetDriverByName("GTiff").Create(q, 80, 60, 1, gdal.GDT_Byte)
    ds.GetRasterBand(1).WriteArray(np.full((60, 80), 90, np.uint8))
    ds = None
    c = _stack(str(folder / "c.tif"), bands[2:3] / 20.0, ("Green",), None)  # 16-bit, values 50..150 of 65535
    infos = [read_image_info(p), read_image_info(q), read_image_info(c)]
    sfm = str(tmp_path / "sfm")
    path, proxied = feature_images(infos, sfm)
    assert path == os.path.join(sfm, FEATURE_IMAGES) and proxied == ["a.tif", "c.tif"]
    dim = read_image(os.path.join(path, "c.tif"))[:, :, 0]  # stretched, not the 16-bit range's 0..0
    assert dim[:, 50:].mean() - dim[:, :30].mean() > 200
    with RasterFile(os.path.join(path, "a.tif")) as r:
        assert (r.count, r.width, r.height) == (1, 80, 60)
    grey = read_image(os.path.join(path, "a.tif"))[:, :, 0]
    assert grey[:, 50:].mean() - grey[:, :30].mean() > 200
    # the proxied photo goes into its own extraction block (read from the proxy folder)
    group = CameraGroup(1, "k", "m", "m", 80, 60, 50.0, "default", ["a.tif", "b.tif", "c.tif"])
    job = Extraction("db", str(folder), [group], {"k": 1}, proxy_path=path, proxied=proxied)
    blocks = [b for _g, b in _extraction_blocks(job, set(), FeatureSettings(80, 100, 0))]
    assert blocks == [["a.tif"], ["b.tif"], ["c.tif"]]
    # another photo under the same name, older than the image made from the first: the image is made again
    stamp = os.path.getmtime(os.path.join(path, "c.tif")) - 3600
    _stack(c, bands[2:3, :, ::-1] / 20.0, ("Green",), None)  # its edge the other way round
    os.utime(c, (stamp, stamp))
    feature_images(infos, sfm)
    again = read_image(os.path.join(path, "c.tif"))[:, :, 0]
    assert again[:, :30].mean() - again[:, 50:].mean() > 200
    # only plain 8-bit photos: no folder
    assert feature_images(infos[1:2], sfm) == (None, []) and not os.path.exists(path)


def test_a_stacked_photo_pair_matches_on_its_primary_band(tmp_path):
    """The dense stage reads a stacked photo's primary band alone."""
    from core.dense.pairs import View, load_scaled

    bands, names = _bands()
    p = _stack(str(tmp_path / "a.tif"), bands, names, "Green")
    view = View(1, "a.tif", p, 80, 60, "PINHOLE", (50.0, 50.0, 40.0, 30.0), np.eye(3), np.zeros(3))
    img, sx, sy = load_scaled(view, 1.0)
    assert img.shape == (60, 80, 1) and (sx, sy) == (1.0, 1.0)
    assert np.array_equal(img[:, :, 0], np.round(bands[2]).astype(np.uint16))


def test_dense_greys_of_a_float_photo_with_no_data_keep_its_contrast():
    """A float32 reflectance photo's NaN (no data): np.percentile over it made every pixel 0."""
    from core.dense.fusion import _to_rgb8
    from core.dense.stereo import _to_gray8

    img = np.zeros((40, 40, 1), np.float32) + 0.1
    img[:, 20:] = 0.4
    img[:5] = np.nan
    for grey in (_to_gray8(img), _to_rgb8(img)[:, :, 0]):
        assert grey[10:, 25:].mean() - grey[10:, :15].mean() > 200


def test_the_first_pass_reads_a_stacked_photo_on_its_primary_band(tmp_path):
    """Align images' first pass (texture probe) sees what COLMAP sees: the primary band, also of a float photo."""
    from core.align.firstpass import _Photos
    from core.io.images import read_image_info

    bands, names = _bands()
    p = _stack(str(tmp_path / "a.tif"), bands.astype(np.float32) / 65535.0, names, "Green", dtype="float32")
    info = read_image_info(p)
    assert info.dtype == "Float32" and info.primary_band == 3
    grey = _Photos(None, [info], 64).image("a.tif")
    assert grey.dtype == np.uint8 and grey.shape == (48, 64)
    assert grey[:, 34:].mean() - grey[:, :28].mean() > 200
