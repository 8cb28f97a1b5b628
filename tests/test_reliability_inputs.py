"""Issue 17: bad inputs that used to give a silent wrong product or a misleading message - weak resection
geometry (item 3), a DASK_SCHEDULER that is no Dask scheduler (4), gap filling of a DSM in degrees (8), GCP reader
warnings in every outcome (11), messages that name the right thing (12), the CRS parameter of a CSV GCP file (13)."""
import math
import os

import numpy as np
import pytest

from core.geometry import camera as cm
from core.geometry import resection as rs
from tests import synthetic as syn

CAM = syn.DEFAULT_CAMERA


def _intrinsics():
    return cm.Intrinsics("OPENCV", CAM.width, CAM.height, CAM.params)


# ---------------------------------------------------------------------------
# item 3: space resection from (nearly) collinear control
# ---------------------------------------------------------------------------

def _road(across=0.0, z_spread=0.1, noise=0.3, seed=0, n=6):
    """n GCPs along a straight road under a camera 50 m up (omega -1.3 deg); returns (xyz, pixels, pose)."""
    rng = np.random.default_rng(seed)
    pose = cm.Pose.from_centre(cm.rotation_from_opk(-1.3, 2.0, 30.0), [3.0, -2.0, 50.0])
    t = np.linspace(-25, 25, n)
    xyz = np.column_stack([t, 0.3 * t + rng.uniform(-across / 2, across / 2, n), rng.uniform(0, z_spread, n)])
    px, ok = cm.project_points(pose, _intrinsics(), xyz)
    assert ok.all()
    return xyz, px + rng.normal(0, noise, px.shape), pose


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_nearly_collinear_gcps_are_refused_with_the_numbers(seed):
    xyz, px, _ = _road(seed=seed)
    with pytest.raises(rs.ResectionError) as e:
        rs.space_resection(xyz, px, _intrinsics(), names=list("ABCDEF"), estimate_intrinsics=False,
                           image="IMG_7.JPG")
    msg = str(e.value)
    assert "IMG_7.JPG" in msg and "undetermined" in msg and "collinear" in msg
    # the numbers: the position's and the angles' uncertainty, the condition number, the image coverage
    sig_m = float(msg.split(" m in the camera position")[0].rsplit(" ", 1)[1])
    sig_deg = float(msg.split(" deg in its angles")[0].rsplit(" ", 1)[1])
    assert sig_m > 5.0 and sig_deg > 5.0 and "condition number" in msg and "% of the image" in msg


def test_exactly_collinear_gcps_say_collinear():
    xyz, px, _ = _road(z_spread=0.0, noise=0.0)
    with pytest.raises(rs.ResectionError, match="are collinear") as e:
        rs.space_resection(xyz, px, _intrinsics(), estimate_intrinsics=False, image="IMG_7.JPG")
    assert "vertical datum" not in str(e.value) and "IMG_7.JPG" in str(e.value)


def test_well_spread_gcps_give_a_tight_pose_and_no_geometry_warning():
    rng = np.random.default_rng(4)
    pose = cm.Pose.from_centre(cm.rotation_from_opk(-1.3, 2.0, 30.0), [3.0, -2.0, 50.0])
    xyz = np.column_stack([rng.uniform(-30, 30, 12), rng.uniform(-20, 20, 12), rng.uniform(0, 0.1, 12)])
    px, ok = cm.project_points(pose, _intrinsics(), xyz)
    xyz, px = xyz[ok & _intrinsics().inside(px, 20)], px[ok & _intrinsics().inside(px, 20)]
    assert len(xyz) >= 8
    r = rs.space_resection(xyz, px + rng.normal(0, 0.3, px.shape), _intrinsics(), estimate_intrinsics=False)
    g = r.geometry
    assert g is not None and g.sigma_angle_deg < rs.WEAK_ANGLE_DEG and g.image_coverage > 0.1
    assert np.linalg.norm(r.pose.centre - pose.centre) < 3 * g.sigma_centre_m + 0.05
    assert not [w for w in r.warnings if "weakly" in w or "cover only" in w]


def test_a_road_a_few_metres_wide_warns_about_the_weak_pose():
    xyz, px, _ = _road(across=3.0, seed=1)
    r = rs.space_resection(xyz, px, _intrinsics(), estimate_intrinsics=False, image="IMG_7.JPG")
    weak = [w for w in r.warnings if "weakly determined" in w]
    assert weak and "IMG_7.JPG" in weak[0] and "deg in its angles" in weak[0]
    assert rs.WEAK_ANGLE_DEG < r.geometry.sigma_angle_deg < rs.BAD_ANGLE_DEG
    assert math.isfinite(r.geometry.condition)


# ---------------------------------------------------------------------------
# item 4: a DASK_SCHEDULER that is not a Dask scheduler (loopback only)
# ---------------------------------------------------------------------------

def _free_port():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _connect_error(address, connect_timeout, ceiling=90.0):
    """make_executor(scheduler=address) in a thread; the ParallelError it raises (fails if it is still running after
    ``ceiling`` s: a generous bound, far above the deadline, not a speed test)."""
    import threading

    from core.common import parallel

    out = {}

    def go():
        try:
            out["executor"] = parallel.make_executor(scheduler=address, connect_timeout=connect_timeout)
        except BaseException as e:  # noqa: B036 - inspected by the test
            out["error"] = e

    t = threading.Thread(target=go, daemon=True)
    t.start()
    t.join(ceiling)
    assert not t.is_alive(), f"make_executor({address}) still hangs after {ceiling} s"
    assert "executor" not in out
    return out["error"]


def test_a_web_server_as_dask_scheduler_fails_within_the_deadline_naming_the_address():
    pytest.importorskip("distributed")
    import subprocess
    import sys
    import time

    from core.common import parallel

    port = _free_port()
    srv = subprocess.Popen([sys.executable, "-m", "http.server", str(port), "--bind", "127.0.0.1"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(100):  # wait until it listens
            try:
                import socket

                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)
        err = _connect_error(f"tcp://127.0.0.1:{port}", connect_timeout=3)
    finally:
        srv.terminate()
        srv.wait(10)
    assert isinstance(err, parallel.ParallelError), repr(err)
    assert f"cannot reach a Dask scheduler at tcp://127.0.0.1:{port}" in str(err)
    # the web server either keeps quiet (no handshake within the deadline) or answers the handshake with HTTP,
    # which Dask reads as a frame of absurd length (Python 3.14's http.server answers at once): both say the
    # address answers, but not as a Dask scheduler
    assert "handshake" in str(err) or "not Dask's protocol" in str(err), str(err)


@pytest.mark.parametrize("garbage", [b"\xff" * 16 + b"garbage" * 100,  # a length no decoder accepts
                                     (1 << 40).to_bytes(8, "little") * 3])  # a 1 TB frame: MemoryError
def test_a_service_that_answers_garbage_is_one_clear_error(garbage):
    pytest.importorskip("distributed")
    import socket
    import threading

    from core.common import parallel

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    port = server.getsockname()[1]
    stop = threading.Event()

    def serve():
        server.settimeout(0.2)
        conns = []
        while not stop.is_set():
            try:
                c, _ = server.accept()
            except OSError:
                continue
            try:
                c.sendall(garbage)
            except OSError:
                pass
            conns.append(c)
        for c in conns:
            c.close()

    t = threading.Thread(target=serve, daemon=True)
    t.start()
    try:
        err = _connect_error(f"tcp://127.0.0.1:{port}", connect_timeout=5)
    finally:
        stop.set()
        t.join(5)
        server.close()
    assert isinstance(err, parallel.ParallelError), repr(err)
    assert f"cannot reach a Dask scheduler at tcp://127.0.0.1:{port}" in str(err)


# ---------------------------------------------------------------------------
# item 8: gap filling of a DSM in a geographic CRS (the distance is metres, not degrees)
# ---------------------------------------------------------------------------

def _gappy_dsm(path, crs, cell, origin):
    """A 240 x 240 tilted-plane DSM with a big gap (100 x 100 cells) and a small one (4 x 4 cells)."""
    from core.io import raster

    rr, cc = np.mgrid[0:240, 0:240]
    z = (100.0 + 0.05 * rr + 0.02 * cc).astype(np.float32)
    z[70:170, 70:170] = np.nan  # big: its centre is 50 cells from a height
    z[20:24, 20:24] = np.nan  # small
    gt = (origin[0], cell[0], 0.0, origin[1], 0.0, -cell[1])
    raster.write_cog(str(path), z, gt, crs)
    return z


def _filled(path, tmp_path, distance):
    from osgeo import gdal

    from core.ortho.surface import fill_dsm_gaps

    out, n = fill_dsm_gaps(str(path), str(tmp_path / "filled.tif"), distance)
    ds = gdal.Open(out)
    band = ds.GetRasterBand(1)
    z = band.ReadAsArray().astype(float)
    nd = band.GetNoDataValue()
    if nd is not None:
        z[z == nd] = np.nan
    return z, n


def test_gap_filling_of_a_dsm_in_degrees_uses_metres(tmp_path):
    # 1e-5 deg cells at 48 N: 0.74 m east-west, 1.11 m north-south; the big gap is 74 m x 111 m wide
    lat = 48.0
    _gappy_dsm(tmp_path / "dsm4326.tif", "EPSG:4326", (1e-5, 1e-5), (11.0, lat))
    z, n = _filled(tmp_path / "dsm4326.tif", tmp_path, 25.0)
    assert np.isfinite(z[20:24, 20:24]).all()  # the small gap (4 m) is filled
    assert np.isnan(z[120, 120])  # the centre of the big one (> 37 m from a height) stays a gap
    # cells within 25 m of a height are filled, those beyond stay empty (25 m = 22 cells at 1.11 m, 33 at 0.74 m)
    assert np.isfinite(z[70:170, 70:170][:, :15]).all()
    assert np.isnan(z[70:170, 70:170][40:60, 40:60]).all()
    assert 0 < n < 100 * 100 + 16


def test_gap_filling_of_a_projected_dsm_in_feet_uses_metres(tmp_path):
    # EPSG:2249 (NAD83 / Massachusetts Mainland, US survey feet): 1 ft cells; 25 m = 82 ft
    _gappy_dsm(tmp_path / "dsmft.tif", "EPSG:2249", (1.0, 1.0), (700000.0, 3000000.0))
    z, _ = _filled(tmp_path / "dsmft.tif", tmp_path, 25.0)
    assert np.isfinite(z[20:24, 20:24]).all()
    assert np.isfinite(z[120, 120])  # 50 ft = 15 m from a height: within 25 m
    _gappy_dsm(tmp_path / "dsmm.tif", "EPSG:32632", (1.0, 1.0), (700000.0, 5300000.0))
    z, _ = _filled(tmp_path / "dsmm.tif", tmp_path, 25.0)
    assert np.isnan(z[120, 120])  # 50 m from a height: beyond 25 m


# ---------------------------------------------------------------------------
# item 12: messages name the user's files, not internal ones
# ---------------------------------------------------------------------------

def test_a_dsm_beside_the_images_is_named_not_its_gap_filled_work_copy(tmp_path):
    from core.ortho.cameras import OrthoCamera
    from core.ortho.mosaic import build_orthomosaic
    from core.ortho.options import OrthoError, OrthoOptions

    dsm = tmp_path / "my dsm.tif"
    _gappy_dsm(dsm, "EPSG:32632", (1.0, 1.0), (700000.0, 5300000.0))  # has gaps: a filled work copy is made
    cam = OrthoCamera("IMG_1.JPG", str(tmp_path / "IMG_1.JPG"), cm.Intrinsics.simple(800, 600, 650.0),
                      cm.Pose.from_centre(cm.rotation_from_opk(0, 0, 0), [0.0, 0.0, 50.0]))
    with pytest.raises(OrthoError, match="does not cover the images") as e:
        build_orthomosaic([cam], "EPSG:32632", [0.0, 0.0, 0.0],
                          OrthoOptions(dsm_path=str(dsm), output=str(tmp_path / "out" / "mosaic.tif")))
    assert str(dsm) in str(e.value)
    assert ".ortho-work-" not in str(e.value) and "gaps-filled" not in str(e.value)


# ---------------------------------------------------------------------------
# items 11 and 13: the GCP reader's warnings in every outcome; a CSV file's CRS from the CRS parameter
# ---------------------------------------------------------------------------

class _Recorder:
    def __init__(self):
        self.warnings, self.infos = [], []

    def report(self, fraction, message=""):
        pass

    def is_cancelled(self):
        return False

    def info(self, message):
        self.infos.append(message)

    def warning(self, message):
        self.warnings.append(message)


def _workspace_with_images(tmp_path, n=3, size=(4000, 3000)):
    from core.project.workspace import Workspace

    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    ws.data["images"] = [{"name": f"IMG_{i}.JPG", "width": size[0], "height": size[1]} for i in range(1, n + 1)]
    ws.save()
    return ws


def _csv_gcps(tmp_path, crs_line, rows, obs):
    pts = tmp_path / "gcps.csv"
    pts.write_text((crs_line + "\n" if crs_line else "") + "name,x,y,z\n" + "".join(f"{r}\n" for r in rows))
    (tmp_path / "gcps_observations.csv").write_text("name,image,px,py\n" + "".join(f"{o}\n" for o in obs))
    return str(pts)


_UTM_ROWS = ["A,500000,4000000,100", "B,500100,4000000,101", "C,500000,4000100,102", "D,500100,4000100,103"]


def test_gcp_warnings_reach_the_user_when_georeferencing_fails_and_counts_are_honest(tmp_path):
    from core.georef.control_input import read_control
    from core.georef.options import GeorefOptions
    from core.project.stages import StageError

    ws = _workspace_with_images(tmp_path)
    # px and py swapped for A, B and C (py beyond the 3000 px height): their lines are dropped
    obs = [f"{p},IMG_{i}.JPG,{2000 + 10 * i},{3500 + 10 * i}" for p in "ABC" for i in (1, 2)] + \
          [f"D,IMG_{i}.JPG,{1000 + 10 * i},{800 + 10 * i}" for i in (1, 2)]
    path = _csv_gcps(tmp_path, "# crs: EPSG:32617", _UTM_ROWS, obs)
    with pytest.raises(StageError) as e:
        read_control(ws, GeorefOptions(gcp_path=path), _Recorder())
    msg = str(e.value)
    assert "A (control, 2 observations, both dropped: outside the image)" in msg
    assert "D (control, 2 observations)" in msg
    assert "lies outside image IMG_1" in msg and "dropped" in msg  # the reader's warnings, with the lines
    assert "gcps_observations.csv:2" in msg


def test_gcp_warnings_are_kept_when_the_reader_itself_fails(tmp_path):
    from core.io import gcp

    obs = ["A,IMG_1.JPG,100,5000", "A,IMG_2.JPG,100,200", "A,IMG_9.JPG,1,1"]
    path = _csv_gcps(tmp_path, "# crs: EPSG:32617", _UTM_ROWS[:1], obs)
    sizes = {f"IMG_{i}.JPG": (4000, 3000) for i in (1, 2)}
    with pytest.raises(gcp.GCPError, match="not in the block") as e:
        gcp.read_gcps(path, image_names=list(sizes), image_sizes=sizes, unknown_images="error")
    assert "lies outside image IMG_1.JPG" in str(e.value)


def test_a_csv_gcp_file_without_crs_takes_the_crs_parameter(tmp_path):
    from core.georef.control_input import read_control
    from core.georef.options import GeorefOptions

    ws = _workspace_with_images(tmp_path)
    obs = [f"{p},IMG_{i}.JPG,{1000 + 100 * k},{800 + 50 * i}" for k, p in enumerate("ABCD") for i in (1, 2)]
    path = _csv_gcps(tmp_path, None, _UTM_ROWS, obs)
    gcps, _, target = read_control(ws, GeorefOptions(gcp_path=path, crs="EPSG:32617"), _Recorder())
    assert gcps.crs == "EPSG:32617" and target == "EPSG:32617"
    assert [p.x for p in gcps.points] == [500000, 500100, 500000, 500100]
    # a file that names its CRS keeps it; the CRS parameter is then the target it is transformed into
    lonlat = ["A,-81.0,36.14,100", "B,-80.999,36.14,101", "C,-81.0,36.141,102", "D,-80.999,36.141,103"]
    path = _csv_gcps(tmp_path, "# crs: EPSG:4326", lonlat, obs)
    gcps, _, target = read_control(ws, GeorefOptions(gcp_path=path, crs="EPSG:32617"), _Recorder())
    assert target == "EPSG:32617" and 499000 < gcps.points[0].x < 501000 and 3.99e6 < gcps.points[0].y < 4.01e6
    # neither: the message says where the CRS can come from
    from core.io import gcp

    path = _csv_gcps(tmp_path, None, _UTM_ROWS, obs)
    with pytest.raises(gcp.GCPError, match="CRS parameter"):
        read_control(ws, GeorefOptions(gcp_path=path), _Recorder())


def _damaged_geotiff(path):
    """A tiled, DEFLATE-compressed RGB GeoTIFF whose tiles' bytes are overwritten with garbage."""
    from osgeo import gdal, osr

    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(str(path), 512, 512, 3, gdal.GDT_Byte, ["TILED=YES", "COMPRESS=DEFLATE", "BLOCKXSIZE=256",
                                                            "BLOCKYSIZE=256"])
    ds.SetGeoTransform((500000.0, 0.1, 0.0, 4000000.0, 0.0, -0.1))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32617)
    ds.SetProjection(srs.ExportToWkt())
    rng = np.random.default_rng(0)
    for b in range(3):
        ds.GetRasterBand(b + 1).WriteArray(rng.integers(0, 255, (512, 512), dtype=np.uint8))
    ds = None
    size = path.stat().st_size
    with open(path, "r+b") as f:  # the header stays, the compressed tiles become garbage
        f.seek(size // 3)
        f.write(b"\x00\xff" * (size // 6))


def test_a_damaged_orthomosaic_in_the_report_is_a_report_error_naming_the_file(tmp_path):
    from types import SimpleNamespace

    from core.report.errors import ReportError
    from core.report.sections import products

    path = tmp_path / "orthomosaic.tif"
    _damaged_geotiff(path)
    ctx = SimpleNamespace(d=SimpleNamespace(ws=SimpleNamespace(root=str(tmp_path)), manifest={}), figures={})
    with pytest.raises(ReportError) as e:
        products._raster(ctx, str(path), "Orthomosaic", dem=False)
    assert str(path) in str(e.value) and "damaged" in str(e.value)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be"])  # with a byte-order mark, without
def test_a_utf16_gcp_file_names_the_encoding_instead_of_printing_garbage_as_a_crs(tmp_path, encoding):
    from core.io import gcp

    text = "EPSG:32617\n500000 4000000 100 1000 800 IMG_1.JPG A\n500000 4000000 100 1010 810 IMG_2.JPG A\n"
    for name in ("gcp_list.txt", "gcps.csv"):
        path = tmp_path / name
        path.write_bytes(text.encode(encoding))
        with pytest.raises(gcp.GCPError) as e:
            gcp.read_gcps(str(path))
        assert f"file {path} is UTF-16" in str(e.value) and "save it as UTF-8" in str(e.value)
        assert "\x00" not in str(e.value) and "ÿþ" not in str(e.value)


def test_a_too_fine_orthophoto_grid_names_the_orthophoto_not_a_dsm(tmp_path):
    import cv2

    from core.common.errors import ArchaeoOrthoError
    from core.ortho.cameras import OrthoCamera
    from core.ortho.mosaic import build_orthomosaic
    from core.ortho.options import OrthoOptions

    dsm = tmp_path / "dsm.tif"
    _gappy_dsm(dsm, "EPSG:32632", (1.0, 1.0), (700000.0, 5300000.0))
    img = tmp_path / "IMG_1.png"
    cv2.imwrite(str(img), np.random.default_rng(0).integers(0, 255, (600, 800, 3), dtype=np.uint8))
    cam = OrthoCamera("IMG_1.png", str(img), cm.Intrinsics.simple(800, 600, 650.0),
                      cm.Pose.from_centre(cm.rotation_from_opk(0, 0, 0), [0.0, 0.0, 150.0]))
    with pytest.raises(ArchaeoOrthoError) as e:
        build_orthomosaic([cam], "EPSG:32632", [700120.0, 5299880.0, 0.0],
                          OrthoOptions(dsm_path=str(dsm), output=str(tmp_path / "o" / "m.tif"), resolution=1e-4))
    msg = str(e.value)
    assert "orthophoto" in msg and "DSM" not in msg.split("too large")[0], msg
    assert "RESOLUTION" in msg


def test_run_pipeline_checks_a_csv_gcp_file_with_the_crs_parameter_as_its_default(tmp_path):
    """Run pipeline's up-front check reads the CSV as the Georeference stage does: the CRS parameter is the CRS of
    a file without a CRS line, and the target of one with (a lon/lat file and a UTM target are fine)."""
    from core.io import gcp
    from core.pipeline import Control, check_inputs
    from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images

    images = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:2], str(tmp_path / "img"))
    names = sorted(os.listdir(images))
    obs = [f"{p},{n},{100 + 10 * k},{200 + 10 * k}" for k, p in enumerate("ABCD") for n in names]
    # where the photos are (their EXIF GPS: the up-front check also compares the points with it)
    lonlat = ["A,-83.699,41.549,100", "B,-83.698,41.549,101", "C,-83.699,41.550,102", "D,-83.698,41.550,103"]
    utm = ["A,274900,4603200,100", "B,275000,4603200,101", "C,274900,4603300,102", "D,275000,4603300,103"]
    check_inputs(images, Control(gcp_path=_csv_gcps(tmp_path, "# crs: EPSG:4326", lonlat, obs), crs="EPSG:32617"))
    check_inputs(images, Control(gcp_path=_csv_gcps(tmp_path, None, utm, obs), crs="EPSG:32617"))
    with pytest.raises(gcp.GCPError, match="CRS parameter"):
        check_inputs(images, Control(gcp_path=_csv_gcps(tmp_path, None, utm, obs)))
