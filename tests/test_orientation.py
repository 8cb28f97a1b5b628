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



def test_the_georef_stage_reads_upright_gcps_of_a_turned_photo_into_the_stored_grid(copr_rotated, tmp_path):
    """The workspace lists the turned copy (its orientation read from the photo, as for a workspace aligned
    before orientations were recorded) and the original photo: with ``gcps_upright`` only the turned photo's
    observations move; without it nothing moves."""
    from core.common.progress import NullProgress
    from core.georef import control_input
    from core.georef.options import GeorefOptions
    from core.project.workspace import Workspace

    _, path, obs, gcp_file = copr_rotated
    original = os.path.join(shared("copr", "images"), COPR_PHOTO)
    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    ws.data["images"] = [{"name": ROTATED, "path": path, "width": 800, "height": 1200},
                         {"name": COPR_PHOTO, "path": original, "width": 1200, "height": 800, "orientation": 1}]
    ws.save()
    assert control_input.photo_orientations(ws) == {ROTATED: 6}
    both = tmp_path / "both.txt"
    text = open(gcp_file).read()
    both.write_text(text + "".join(f"{line.replace(ROTATED, COPR_PHOTO)}\n" for line in text.splitlines()[1:]))
    for upright in (True, False):
        gcps = control_input.read_control(ws, GeorefOptions(gcp_path=str(both), gcps_upright=upright),
                                          NullProgress())[0]
        for name, ox, oy in obs:
            p = gcps.by_name(name)
            at = {o.image: (o.x, o.y) for o in p.observations}
            assert at[COPR_PHOTO] == (ox, oy)
            if upright:
                assert at[ROTATED] == pytest.approx(upright_to_stored(ox, oy, 6, 800, 1200))
            else:
                assert at.get(ROTATED, (ox, oy)) == (ox, oy)  # taken as stored (or dropped outside the photo)


def test_the_georeference_algorithm_has_the_upright_parameter(qgis_app):
    from archaeoortho.processing_provider.georeference import GeoreferenceAlgorithm

    alg = GeoreferenceAlgorithm()
    alg.initAlgorithm()
    p = alg.parameterDefinition("GCPS_UPRIGHT")
    assert p is not None and p.type() == "boolean" and p.defaultValue() is False

# --------------------------------------------------------------------------------------------------
# the GCP dock: an orientation-6 photo shown upright, clicks and imports mapped to the stored grid
# --------------------------------------------------------------------------------------------------

OCHOTA_PHOTO = "img_3006.jpg"
# a white object in the middle of the fenced field, in the upright 1/4-scale copy (864 x 1152 upright)
OCHOTA_TARGET = (481.0, 545.0)


@pytest.fixture(scope="module")
def ochota_quarter(tmp_path_factory):
    """A 1/4-scale copy of an ochota_kap photo (the JPEG's own 1/4 decode: 1152 x 864 stored) that keeps its
    EXIF orientation 6."""
    from osgeo import gdal

    src = os.path.join(shared("ochota_kap", "images"), OCHOTA_PHOTO)
    ds = gdal.Open(src)
    assert ds.GetMetadataItem("EXIF_Orientation") == "6"
    ov = [ds.GetRasterBand(b + 1).GetOverview(1) for b in range(3)]
    d = tmp_path_factory.mktemp("ochota quarter")
    os.makedirs(d / "images")
    mem = gdal.GetDriverByName("MEM").Create("", ov[0].XSize, ov[0].YSize, 3, gdal.GDT_Byte)
    for b in range(3):
        mem.GetRasterBand(b + 1).WriteArray(ov[b].ReadAsArray())
    mem.SetMetadataItem("EXIF_Orientation", "6")
    path = str(d / "images" / OCHOTA_PHOTO)
    gdal.GetDriverByName("JPEG").CreateCopy(path, mem, options=["QUALITY=95"])
    return path


def _ochota_workspace(root, path):
    """A workspace listing the copy (not aligned: the dock only shows photos here)."""
    from core.project.workspace import Workspace

    ws = Workspace.create_or_open(str(root))
    ws.data["images_dir"] = os.path.dirname(path)
    ws.data["images"] = [{"name": OCHOTA_PHOTO, "path": path, "width": 1152, "height": 864, "orientation": 6}]
    ws.data["crs"] = "EPSG:2180"
    ws.save()
    return ws.root


@pytest.fixture
def dock(qgis_canvas, qgis_new_project):
    from archaeoortho.ui.gcp_dock import GcpDock

    d = GcpDock(None, qgis_canvas)
    d.resize(700, 600)
    d.photo_dock.resize(760, 900)
    d.show()
    d.photo_dock.show()
    yield d
    d.cleanup()
    d.photo_dock.close()
    d.close()


def _qimage_grey_patch(image, x, y, r=6):
    from qgis.PyQt.QtGui import QColor

    c, rr = int(np.floor(x)), int(np.floor(y))
    def grey(i, j):
        q = QColor(image.pixel(i, j))
        return (q.red() + q.green() + q.blue()) / 3.0

    return np.array([[grey(i, j) for i in range(c - r, c + r + 1)] for j in range(rr - r, rr + r + 1)])


def _near_brightest(arr, x, y, r=10):
    grey = arr.astype(float).mean(axis=2)
    c, rr = int(x), int(y)
    win = grey[rr - r:rr + r + 1, c - r:c + r + 1]
    j, i = np.unravel_index(np.argmax(win), win.shape)
    return c - r + i + 0.5, rr - r + j + 0.5


def test_the_dock_shows_an_orientation_6_photo_upright_and_maps_a_click_to_the_stored_grid(
        dock, ochota_quarter, tmp_path, qgis_app):
    from qgis.PyQt.QtCore import QPointF

    from tests.test_ui_dock import SCREENSHOTS, _click, process

    path = ochota_quarter
    ws = _ochota_workspace(tmp_path / "ws", path)

    assert dock.open_workspace(ws)
    name = dock.add_point("W1", 630500.0, 485200.0, 100.0)
    dock.show_photo(OCHOTA_PHOTO)
    panel = dock.photo_panel
    assert panel.image == OCHOTA_PHOTO
    pyr = panel.pyramid(OCHOTA_PHOTO)
    assert (pyr.stored_width, pyr.stored_height, pyr.orientation) == (1152, 864, 6)
    assert (pyr.width, pyr.height) == (864, 1152)  # upright, portrait, as a photo viewer shows it
    assert panel.orientation_note.isVisibleTo(panel) and "EXIF orientation 6" in panel.orientation_note.text()
    stored = _read_rgb(path)
    # what the dock draws is the stored raster turned as core.io.images turns it (Qt and GDAL decode alike)
    upright = to_upright(stored, 6)
    target = _near_brightest(upright, *OCHOTA_TARGET)
    shown = _qimage_grey_patch(pyr.levels[0], *target)
    want = _patch(upright, *target, r=6)
    assert np.abs(shown - want).mean() < 3.0
    assert _correlation(shown, want) > 0.95
    # a click on the target: the scene position is upright, the observation is stored
    view = panel.view
    view.set_zoom(4.0, QPointF(*target))
    process(50)
    expected = _click(view, target)
    obs = dock.store.gcps.by_name(name).observations
    assert len(obs) == 1 and obs[0].image == OCHOTA_PHOTO
    sx, sy = upright_to_stored(expected.x(), expected.y(), 6, 1152, 864)
    assert (obs[0].x, obs[0].y) == (pytest.approx(sx, abs=1e-9), pytest.approx(sy, abs=1e-9))
    assert (obs[0].x, obs[0].y) == pytest.approx((expected.y(), 864.0 - expected.x()), abs=1e-9)
    assert abs(expected.x() - target[0]) <= 0.25 and abs(expected.y() - target[1]) <= 0.25
    # the stored pixels at the stored observation are the target the user clicked on
    assert _correlation(np.rot90(_patch(stored, obs[0].x, obs[0].y, r=6), k=-1), want) > 0.95
    # and the marker is drawn where it was clicked (stored -> upright)
    marker = panel.observation
    assert marker is not None
    assert (marker.pos().x(), marker.pos().y()) == pytest.approx((expected.x(), expected.y()), abs=1e-9)
    # the thumbnail is upright too (portrait)
    from archaeoortho.ui.photo_viewer import read_thumbnail

    thumb = read_thumbnail(path)
    assert thumb.height() > thumb.width()
    view.fit()
    process(150)
    os.makedirs(SCREENSHOTS, exist_ok=True)
    shot = os.path.join(SCREENSHOTS, "photo-viewer-orientation-6.png")
    dock.photo_dock.grab().save(shot)
    dock.grab().save(os.path.join(SCREENSHOTS, "dock-orientation-6.png"))
    assert os.path.getsize(shot) > 10000


def test_the_dock_imports_gcp_coordinates_measured_on_the_upright_photo(dock, ochota_quarter, tmp_path, qgis_app):
    ws = _ochota_workspace(tmp_path / "ws", ochota_quarter)
    u, v = OCHOTA_TARGET
    path = tmp_path / "gcp_list.txt"
    path.write_text(f"EPSG:2180\n630500.0 485200.0 100.0 {u} {v} {OCHOTA_PHOTO} W1\n"
                    f"630510.0 485210.0 100.0 5.0 6.0 not_in_the_workspace.jpg W2\n")
    assert dock.open_workspace(ws)
    assert dock.photo_orientations() == {OCHOTA_PHOTO: 6}
    # a workspace aligned today records the orientation: the import does not open the photos for it
    for im in dock.store.workspace.data["images"]:
        im["orientation"] = 6
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("archaeoortho.ui.gcp_io.exif_orientation", None)  # would raise if called
        assert dock.photo_orientations() == {OCHOTA_PHOTO: 6}
    gs = dock.import_file(str(path), upright=True)
    assert gs is not None
    o = dock.store.gcps.by_name("W1").observations
    assert len(o) == 1 and (o[0].x, o[0].y) == pytest.approx(upright_to_stored(u, v, 6, 1152, 864))
    assert any("not_in_the_workspace.jpg" in w for w in gs.warnings)  # the photo outside the block is named
    assert "not_in_the_workspace.jpg" in dock.status.text()  # in the dock's message too
    dock.select_point("W1")
    dock.show_photo(OCHOTA_PHOTO)
    marker = dock.photo_panel.observation
    assert marker is not None and (marker.pos().x(), marker.pos().y()) == pytest.approx((u, v))
    # the same file taken as stored coordinates: (481, 545) fits the stored 1152 x 864 grid but is elsewhere
    gs = dock.import_file(str(path), upright=False)
    o = dock.store.gcps.by_name("W1").observations
    assert (o[0].x, o[0].y) == (u, v)
    # a file whose photos are all outside the workspace: an error naming the closest photo names
    bad = tmp_path / "bad.txt"
    bad.write_text("EPSG:2180\n630500.0 485200.0 100.0 10 20 img_306.jpg W1\n")
    assert dock.import_file(str(bad)) is None
    assert "none of its 1 observation(s)" in dock.status.text()
    assert f"'img_306.jpg' (line 2, closest in the block: {OCHOTA_PHOTO})" in dock.status.text()
