"""EXIF orientation (issue 13, item 3): one convention.

Stored pixel coordinates (GCP observations, COLMAP) stay in the stored grid; photo viewers (and the GCP dock)
show the photo upright.  core.io.images converts between the two; GCP import takes coordinates measured on
upright photos and converts them.  Checked against Pillow's ImageOps.exif_transpose (what photo viewers do), on
the real orientation-6 photos of ochota_kap (header and 1/8-scale reads only) and on a copy of a COPR photo
stored turned by 90 degrees with orientation 6, whose GCPs must land on the same targets as the original's.
"""
import os

import numpy as np
import pytest

from core.io import gcp as gcpmod
from core.io.images import (
    ORIENTATION_STEPS,
    exif_orientation,
    read_image_info,
    stored_to_upright,
    to_upright,
    upright_size,
    upright_to_stored,
)
from tests.conftest import shared

ALL = sorted(ORIENTATION_STEPS)


def _pil_upright(arr, orientation):
    """What a photo viewer shows: Pillow's exif_transpose of ``arr`` tagged with ``orientation``."""
    pil = pytest.importorskip("PIL")
    del pil
    from PIL import Image, ImageOps

    im = Image.fromarray(arr)
    im.getexif()[0x0112] = orientation
    return np.asarray(ImageOps.exif_transpose(im))


@pytest.mark.parametrize("orientation", ALL)
def test_the_pixel_transforms_agree_with_what_photo_viewers_show(orientation):
    """Every stored pixel centre maps to the centre of the upright pixel holding the same value, for all 8
    orientations; to_upright turns the raster as Pillow does; the transforms are exact inverses."""
    h, w = 5, 7
    arr = np.arange(h * w, dtype=np.uint8).reshape(h, w)
    up = _pil_upright(arr, orientation)
    assert (up.shape[1], up.shape[0]) == upright_size(orientation, w, h)
    assert np.array_equal(to_upright(arr, orientation), up)
    rows, cols = np.mgrid[0:h, 0:w]
    u, v = stored_to_upright(cols.ravel() + 0.5, rows.ravel() + 0.5, orientation, w, h)
    iu, iv = np.floor(u).astype(int), np.floor(v).astype(int)
    assert np.allclose(u - iu, 0.5) and np.allclose(v - iv, 0.5)  # centres to centres
    assert np.array_equal(up[iv, iu], arr.ravel())
    # corners: the stored frame maps onto the upright frame
    uw, uh = upright_size(orientation, w, h)
    cu, cv = stored_to_upright(np.array([0.0, w, 0.0, w]), np.array([0.0, 0.0, h, h]), orientation, w, h)
    assert sorted(set(np.round(cu, 9))) == [0.0, float(uw)] and sorted(set(np.round(cv, 9))) == [0.0, float(uh)]
    # round trip, on arbitrary sub-pixel positions
    rng = np.random.default_rng(orientation)
    x, y = rng.uniform(0, w, 50), rng.uniform(0, h, 50)
    bx, by = upright_to_stored(*stored_to_upright(x, y, orientation, w, h), orientation, w, h)
    assert np.allclose(bx, x, atol=1e-12) and np.allclose(by, y, atol=1e-12)
    sx, sy = stored_to_upright(1.25, 3.5, orientation, w, h)
    assert isinstance(sx, float) and isinstance(sy, float)


def test_orientation_6_is_a_quarter_turn_clockwise():
    # a portrait camera's frame stored 4608 x 3456: the stored top-left corner is the upright top-right one
    assert upright_size(6, 4608, 3456) == (3456, 4608)
    assert stored_to_upright(0.0, 0.0, 6, 4608, 3456) == (3456.0, 0.0)
    assert stored_to_upright(0.0, 3456.0, 6, 4608, 3456) == (0.0, 0.0)
    assert upright_to_stored(0.0, 0.0, 6, 4608, 3456) == (0.0, 3456.0)
    assert stored_to_upright(4608.0, 0.0, 8, 4608, 3456) == (0.0, 0.0)
    with pytest.raises(ValueError, match="1-8"):
        stored_to_upright(1.0, 1.0, 9, 10, 10)


def test_ochota_kap_photos_are_orientation_6_and_turn_as_a_viewer_turns_them():
    """All 16 photos carry orientation 6 (read from the header); the upright 1/8-scale read of one equals
    Pillow's upright decode at 1/8 (and does not equal the other quarter turn)."""
    folder = shared("ochota_kap", "images")
    names = sorted(n for n in os.listdir(folder) if n.lower().endswith(".jpg"))
    assert len(names) == 16
    assert {exif_orientation(os.path.join(folder, n)) for n in names} == {6}
    pytest.importorskip("PIL")
    from osgeo import gdal
    from PIL import Image, ImageOps

    path = os.path.join(folder, names[0])
    ds = gdal.Open(path)
    assert (ds.RasterXSize, ds.RasterYSize) == (4608, 3456)
    assert upright_size(exif_orientation(path), ds.RasterXSize, ds.RasterYSize) == (3456, 4608)
    ov = [ds.GetRasterBand(b + 1).GetOverview(2) for b in range(3)]  # the JPEG's 1/8-scale decode
    small = np.dstack([o.ReadAsArray() for o in ov])
    assert small.shape == (432, 576, 3)
    im = Image.open(path)
    im.draft("RGB", (576, 432))
    viewer = np.asarray(ImageOps.exif_transpose(im)).astype(float)
    assert viewer.shape == (576, 432, 3)
    ours = to_upright(small, 6).astype(float)
    wrong = to_upright(small, 8).astype(float)
    err, err_wrong = np.abs(ours - viewer).mean(), np.abs(wrong - viewer).mean()
    print(f"\n[ochota_kap 1/8 upright] mean |ours - Pillow| {err:.2f} DN, other quarter turn {err_wrong:.1f} DN")
    assert err < 2.0 and err_wrong > 10 * err


# --------------------------------------------------------------------------------------------------
# a COPR photo stored turned, with its GCPs
# --------------------------------------------------------------------------------------------------

COPR_PHOTO = "IMG_0031.jpg"  # 3 observations (gcp04, gcp01, gcp00) in the shared gcp_list.txt
ROTATED = "IMG_0031_portrait.jpg"


def _read_rgb(path):
    from osgeo import gdal

    ds = gdal.Open(path)
    return np.dstack([ds.GetRasterBand(b + 1).ReadAsArray() for b in range(ds.RasterCount)])


@pytest.fixture(scope="module")
def copr_rotated(tmp_path_factory):
    """(original photo, rotated copy path, original observations [(name, x, y)], GCP file in upright
    coordinates of the copy).  The copy stores the photo turned 90 degrees anticlockwise (800 x 1200) with
    EXIF orientation 6, so that a viewer shows it exactly as the original; a user measuring on it in a browser
    writes the original's coordinates."""
    from osgeo import gdal

    folder = shared("copr")
    src = os.path.join(folder, "images", COPR_PHOTO)
    original = _read_rgb(src)
    assert original.shape[:2] == (800, 1200)
    stored = np.ascontiguousarray(np.rot90(original, k=1))  # anticlockwise: 1200 rows x 800 columns
    d = tmp_path_factory.mktemp("copr rotated")
    mem = gdal.GetDriverByName("MEM").Create("", stored.shape[1], stored.shape[0], 3, gdal.GDT_Byte)
    for b in range(3):
        mem.GetRasterBand(b + 1).WriteArray(stored[:, :, b])
    mem.SetMetadataItem("EXIF_Orientation", "6")
    path = str(d / ROTATED)
    gdal.GetDriverByName("JPEG").CreateCopy(path, mem, options=["QUALITY=97"])
    ref = gcpmod.read_gcps(os.path.join(folder, "gcp_list.txt"))
    obs = [(p.name, o.x, o.y) for p in ref.points for o in p.observations if o.image == COPR_PHOTO]
    assert len(obs) == 3
    lines = [ref.crs] + [f"{p.x} {p.y} {p.z} {o.x} {o.y} {ROTATED} {p.name}"
                         for p in ref.points for o in p.observations if o.image == COPR_PHOTO]
    gcp_file = d / "gcp_upright.txt"
    gcp_file.write_text("\n".join(lines) + "\n")
    return original, path, obs, str(gcp_file)


def _patch(arr, x, y, r=12):
    c, rr = int(np.floor(x)), int(np.floor(y))
    return arr[rr - r:rr + r + 1, c - r:c + r + 1].astype(float).mean(axis=2)


def _correlation(a, b):
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))


def test_a_turned_copy_of_a_copr_photo_displays_as_the_original(copr_rotated):
    original, path, _, _ = copr_rotated
    assert exif_orientation(path) == 6
    info = read_image_info(path)
    assert (info.width, info.height, info.orientation) == (800, 1200, 6)
    assert info.to_dict()["orientation"] == 6
    assert upright_size(6, info.width, info.height) == (1200, 800)
    upright = to_upright(_read_rgb(path), 6).astype(float)
    assert upright.shape == original.shape
    assert np.abs(upright - original).mean() < 3.0  # the same picture, up to the JPEG re-encoding
    assert exif_orientation(os.path.join(shared("copr", "images"), COPR_PHOTO)) == 1


def test_gcps_measured_on_the_upright_copy_land_on_the_original_targets(copr_rotated):
    """Read with the upright option, the observations move to the copy's stored grid; the round trip gives the
    measured values back; the stored pixels there are the original's target (alignment-free check); read
    without the option they point elsewhere or fall outside the photo."""
    original, path, obs, gcp_file = copr_rotated
    stored = _read_rgb(path)
    sizes = {ROTATED: (800, 1200)}
    gs = gcpmod.read_gcps(gcp_file, image_names=[ROTATED], image_sizes=sizes, upright_orientations={ROTATED: 6})
    assert gs.n_observations() == 3
    for name, ox, oy in obs:
        o = gs.by_name(name).observations[0]
        assert (o.x, o.y) == pytest.approx(upright_to_stored(ox, oy, 6, 800, 1200))
        assert (o.x, o.y) == pytest.approx((oy, 1200.0 - ox))  # a quarter turn back: x = upright y
        assert stored_to_upright(o.x, o.y, 6, 800, 1200) == pytest.approx((ox, oy), abs=1e-9)
        want = _patch(original, ox, oy)
        got = np.rot90(_patch(stored, o.x, o.y), k=-1)  # the stored patch, turned upright
        corr = _correlation(want, got)
        assert corr > 0.97, (name, corr)
        print(f"\n[COPR turned copy] {name}: stored ({o.x:.1f}, {o.y:.1f}) <- upright ({ox:.1f}, {oy:.1f}); "
              f"patch correlation with the original target {corr:.3f}")
    # the same file read as stored coordinates: the targets are missed (dropped outside, or elsewhere)
    naive = gcpmod.read_gcps(gcp_file, image_names=[ROTATED], image_sizes=sizes)
    for name, ox, oy in obs:
        p = naive.by_name(name)
        if not p.observations:
            assert "outside the image" in p.dropped
            continue
        o = p.observations[0]
        assert (o.x, o.y) == (ox, oy)
        assert _correlation(_patch(original, ox, oy), np.rot90(_patch(stored, o.x, o.y), k=-1)) < 0.5


def test_upright_conversion_of_a_gcp_set_and_its_errors(copr_rotated):
    _, _, obs, gcp_file = copr_rotated
    plain = gcpmod.read_gcps(gcp_file)
    conv = gcpmod.observations_to_stored(plain, {ROTATED: (800, 1200)}, {ROTATED: 6})
    for name, ox, oy in obs:
        o = conv.by_name(name).observations[0]
        assert (o.x, o.y) == pytest.approx(upright_to_stored(ox, oy, 6, 800, 1200))
    with pytest.raises(gcpmod.GCPError, match=f"{ROTATED}: its stored size is not known"):
        gcpmod.read_gcps(gcp_file, upright_orientations={ROTATED: 6})
    # orientation 1 photos are left as they are
    same = gcpmod.read_gcps(gcp_file, image_sizes={ROTATED: (1200, 800)}, upright_orientations={ROTATED: 1})
    assert [(o.x, o.y) for p in same.points for o in p.observations] == [(x, y) for _, x, y in obs]
