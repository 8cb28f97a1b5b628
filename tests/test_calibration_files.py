"""core.io.calibration: camera calibrations read from every supported format, against known truth.

tests/data/calibration/same_camera* hold one camera (a 120 mm lens on a 92.16 x 165.888 mm frame, images of
640 x 1152 px, principal point 0.288 mm right and 0.432 mm down of the centre, k1..k3, p1, p2) written by
hand in each format with that format's own conventions; every reader must give the same COLMAP camera, and
that camera must project like the certificate's own formula.  rc20_certificate.yaml is a film camera whose
radial distortion table was generated from known k1..k3."""
import json
import math
import os
import re

import numpy as np
import pytest

from core.common.errors import ArchaeoOrthoError
from core.io.calibration import (
    ADJUST_MODES,
    CalibrationError,
    CameraCalibration,
    calibration_for_image,
    fit_radial_distortion,
    read_calibration,
)

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "calibration")

# the certificate of the camera in same_camera*: what every file says, in the units a certificate uses
F_MM, PIXEL_MM, W, H = 120.0, 0.144, 640, 1152
PP_MM = (0.288, -0.432)  # x right, y up, from the image centre
K1, K2, K3, P1, P2 = -0.05, 0.01, 0.002, 1e-4, -5e-5
TRUTH = ("FULL_OPENCV", [F_MM / PIXEL_MM, F_MM / PIXEL_MM, W / 2 + PP_MM[0] / PIXEL_MM, H / 2 - PP_MM[1] / PIXEL_MM,
                         K1, K2, P1, P2, K3, 0.0, 0.0, 0.0])
SAME_CAMERA_FILES = ["same_camera.yaml", "same_camera.json", "same_camera_orthority.yaml", "same_camera_opencv.yml",
                     "same_camera_opencv.xml", "same_camera_cameras.txt", "same_camera_metashape.xml"]

# RC20 certificate: the distortion table was generated from these
RC20_K = (1.2e-4, -1.5e-4, 6e-5)
RC20_F_MM = 152.817


def _data(name):
    return os.path.join(DATA, name)


def _points():
    """Camera-frame points (COLMAP axes: x right, y down, z forward) spread over the 640 x 1152 frame."""
    rng = np.random.default_rng(7)
    xy = rng.uniform([-0.35, -0.62], [0.35, 0.62], size=(12, 2))
    z = rng.uniform(50.0, 400.0, size=(12, 1))
    return np.hstack([xy * z, z])


def _pycolmap_project(cal, xyz):
    pycolmap = pytest.importorskip("pycolmap")
    model, params = cal.colmap_model()
    cam = pycolmap.Camera(model=model, width=cal.width, height=cal.height, params=params)
    return np.asarray(cam.img_from_cam(xyz))


def _brown(xn, yn, k1, k2, k3, p1, p2):
    """OpenCV's Brown model on normalised coordinates (y down)."""
    r2 = xn ** 2 + yn ** 2
    radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
    return (xn * radial + 2 * p1 * xn * yn + p2 * (r2 + 2 * xn ** 2),
            yn * radial + p1 * (r2 + 2 * yn ** 2) + 2 * p2 * xn * yn)


def _certificate_projection(xyz):
    """The certificate's formula, in mm on the film/sensor plane: image coordinates x right, y up from the
    principal point, distorted, shifted by the principal point's offset from the frame centre, then scanned at
    PIXEL_MM with the frame centre at the image centre."""
    xn, yn = xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]
    xd, yd = _brown(xn, yn, K1, K2, K3, P1, P2)
    x_mm, y_mm = F_MM * xd + PP_MM[0], -F_MM * yd + PP_MM[1]  # y up on the frame
    return np.stack([W / 2 + x_mm / PIXEL_MM, H / 2 - y_mm / PIXEL_MM], axis=1)


# ---------------------------------------------------------------------------
# one camera, every format
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("name", SAME_CAMERA_FILES)
def test_every_format_gives_the_certificates_colmap_camera(name):
    cams = read_calibration(_data(name))
    assert len(cams) == 1
    model, params = cams[0].colmap_model()
    assert model == TRUTH[0]
    np.testing.assert_allclose(params, TRUTH[1], rtol=0, atol=1e-6)
    assert (cams[0].width, cams[0].height) == (W, H)
    assert cams[0].source == _data(name)


def test_all_formats_agree_with_each_other():
    models = {name: read_calibration(_data(name))[0].colmap_model() for name in SAME_CAMERA_FILES}
    first_model, first = models[SAME_CAMERA_FILES[0]]
    for name, (model, params) in models.items():
        assert model == first_model, name
        np.testing.assert_allclose(params, first, rtol=0, atol=1e-6, err_msg=name)


@pytest.mark.parametrize("name", SAME_CAMERA_FILES)
def test_pycolmap_projects_like_the_certificate(name):
    xyz = _points()
    cal = read_calibration(_data(name))[0]
    expected = _certificate_projection(xyz)
    assert np.ptp(expected[:, 0]) > 300 and np.ptp(expected[:, 1]) > 600  # the points span the frame
    np.testing.assert_allclose(_pycolmap_project(cal, xyz), expected, rtol=0, atol=1e-6)


def test_opencv_file_projects_like_cv2_with_its_half_pixel():
    cv2 = pytest.importorskip("cv2")
    xyz = _points()
    cal = read_calibration(_data("same_camera_opencv.yml"))[0]
    k = np.array([[833.3333333333334, 0, 321.5], [0, 833.3333333333334, 578.5], [0, 0, 1.0]])  # the file's values
    dist = np.array([K1, K2, P1, P2, K3])
    uv, _ = cv2.projectPoints(xyz, np.zeros(3), np.zeros(3), k, dist)
    np.testing.assert_allclose(_pycolmap_project(cal, xyz), uv[:, 0, :] + 0.5, atol=1e-6)


def test_orthority_file_projects_like_orthoritys_formula():
    xyz = _points()
    cal = read_calibration(_data("same_camera_orthority.yaml"))[0]
    # Orthority (camera.py): K = [f w/sensor_w, f h/sensor_h; (w-1)/2 + max(w,h) cx, (h-1)/2 + max(w,h) cy],
    # pixel centres at integers; its Brown model is OpenCV's
    fx, fy = 120.0 * W / 92.16, 120.0 * H / 165.888
    cx0, cy0 = (W - 1) / 2 + max(W, H) * 0.001736111111111111, (H - 1) / 2 + max(W, H) * 0.0026041666666666665
    xd, yd = _brown(xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2], K1, K2, K3, P1, P2)
    expected = np.stack([fx * xd + cx0 + 0.5, fy * yd + cy0 + 0.5], axis=1)
    np.testing.assert_allclose(_pycolmap_project(cal, xyz), expected, atol=1e-6)


def _metashape_projection(xyz, w, h, f, cx, cy, b1, b2, k1, k2, k3, p1, p2):
    """Metashape's frame model (manual, appendix C), its own P1/P2 and B1/B2."""
    x, y = xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
    xp = x * radial + p1 * (r2 + 2 * x * x) + 2 * p2 * x * y
    yp = y * radial + p2 * (r2 + 2 * y * y) + 2 * p1 * x * y
    return np.stack([w * 0.5 + cx + xp * f + xp * b1 + yp * b2, h * 0.5 + cy + yp * f], axis=1)


def test_metashape_files_project_like_metashapes_formula():
    xyz = _points()
    cal = read_calibration(_data("same_camera_metashape.xml"))[0]
    expected = _metashape_projection(xyz, W, H, 833.3333333333334, 2, 3, 0, 0, K1, K2, K3, -5e-05, 1e-4)
    np.testing.assert_allclose(_pycolmap_project(cal, xyz), expected, atol=1e-6)
    # an affinity b1: fx = f + b1, fy = f
    nikon, canon = read_calibration(_data("two_cameras_metashape.xml"))
    assert nikon.name == "Nikon D800 (50mm)" and canon.name == "Canon 5D (24mm)"
    assert (nikon.width, nikon.height, nikon.fx, nikon.fy) == (7360, 4912, 10432.0, 10430.5)
    rng = np.random.default_rng(3)
    pts = np.hstack([rng.uniform(-0.3, 0.3, (10, 2)) * 20, np.full((10, 1), 20.0)])
    expected = _metashape_projection(pts, 7360, 4912, 10430.5, -12.25, 8.5, 1.5, 0, -0.02, 0.1, 0, 0, 0)
    np.testing.assert_allclose(_pycolmap_project(nikon, pts), expected, atol=1e-6)
    # the adjusted calibration is read, not the initial one
    assert nikon.k1 == -0.02
    # a small skew is dropped with a note that says how much it moved
    assert canon.colmap_model()[0] == "PINHOLE" and "b2" in canon.notes[0] and "0.091 px" in canon.notes[0]


def test_the_120_mm_digital_frame_is_833_px():
    cal = read_calibration(_data("same_camera.yaml"))[0]
    assert cal.focal_px == pytest.approx(833.3333333, abs=1e-6)
    assert cal.focal_y_px is None
    assert cal.pixel_size_mm == pytest.approx(0.144) and cal.focal_mm == 120.0
    assert (cal.cx_px, cal.cy_px) == pytest.approx((322.0, 579.0))
    assert cal.adjust == "fixed" and cal.images == ["dmc_*.tif", "DMC-*.jpg"]
    assert cal.sigmas == pytest.approx({"focal_px": 0.1, "cx_px": 0.02, "cy_px": 0.02})


# ---------------------------------------------------------------------------
# the radial distortion table
# ---------------------------------------------------------------------------

def _table(k, f_mm, radii):
    rho = np.asarray(radii, dtype=float) / f_mm
    return f_mm * rho * (k[0] * rho ** 2 + k[1] * rho ** 4 + k[2] * rho ** 6) * 1e3  # um


@pytest.mark.parametrize("k", [(1.2e-4, -1.5e-4, 6e-5), (-3e-3, 2e-3, -4e-4), (5e-4, 0.0, 0.0)])
def test_distortion_table_fit_recovers_the_coefficients(k):
    radii = np.arange(5.0, 151.0, 5.0)
    (k1, k2, k3), rms, worst = fit_radial_distortion(radii, _table(k, 152.8, radii), 152.8)
    np.testing.assert_allclose([k1, k2, k3], k, rtol=1e-8, atol=1e-12)
    assert rms < 1e-9 and worst < 1e-9


def test_certificate_table_gives_known_k_and_reproduces_the_table():
    cal = read_calibration(_data("rc20_certificate.yaml"))[0]
    # the table is written to 1e-6 um: the coefficients come back to that precision
    np.testing.assert_allclose([cal.k1, cal.k2, cal.k3], RC20_K, rtol=1e-3)
    radii = np.arange(10.0, 151.0, 10.0)
    rho = radii / RC20_F_MM
    fitted = RC20_F_MM * rho * (cal.k1 * rho ** 2 + cal.k2 * rho ** 4 + cal.k3 * rho ** 6) * 1e3
    np.testing.assert_allclose(fitted, _table(RC20_K, RC20_F_MM, radii), atol=2e-6)
    assert "16 rows" in cal.notes[0]
    # a positive (outward) displacement moves a point away from the principal point
    pts = np.array([[0.5 * 10, 0.0, 10.0]])
    u = _pycolmap_project(cal, pts)[0, 0]
    assert u - cal.cx_px > 0.5 * cal.focal_px


def test_certificate_principal_point_fiducials_and_sigmas():
    cal = read_calibration(_data("rc20_certificate.yaml"))[0]
    assert (cal.width, cal.height) == (11500, 11500)
    assert cal.focal_px == pytest.approx(152.817 / 0.02)
    # PBS x = -0.004 mm (left), y = +0.011 mm (up): 0.2 px left of and 0.55 px above the centre
    assert (cal.cx_px, cal.cy_px) == pytest.approx((5750 - 0.2, 5750 - 0.55))
    assert cal.fiducials_mm["2"] == (106.002, 105.995) and len(cal.fiducials_mm) == 4
    assert cal.sigmas == pytest.approx({"focal_px": 0.15, "cx_px": 0.1, "cy_px": 0.1})
    assert cal.adjust == "refined" and cal.images == ["1971_*.tif"] and cal.name == "RC20_15UAG"


# ---------------------------------------------------------------------------
# scaled_to, colmap_model, records
# ---------------------------------------------------------------------------

def test_scaled_to_halves_pixel_values_and_keeps_mm():
    cal = read_calibration(_data("rc20_certificate.yaml"))[0]
    half = cal.scaled_to(5750, 5750)
    assert (half.width, half.height) == (5750, 5750)
    assert half.focal_px == pytest.approx(cal.focal_px / 2)
    assert (half.cx_px, half.cy_px) == pytest.approx((cal.cx_px / 2, cal.cy_px / 2))
    assert half.sigmas == pytest.approx({k: v / 2 for k, v in cal.sigmas.items()})
    assert half.pixel_size_mm == pytest.approx(0.04) and half.focal_mm == cal.focal_mm
    assert (half.k1, half.k2, half.k3) == (cal.k1, cal.k2, cal.k3)
    assert half.fiducials_mm == cal.fiducials_mm and cal.width == 11500  # the original is untouched
    # the same ray lands on the same place of the frame (pixel-corner convention: exactly half the pixel)
    pts = _points()
    np.testing.assert_allclose(_pycolmap_project(half, pts), _pycolmap_project(cal, pts) / 2, atol=1e-6)
    # a scan a few pixels off the exact ratio is still the camera; a cropped or turned one is not
    assert cal.scaled_to(5752, 5749).focal_y_px is not None
    with pytest.raises(CalibrationError, match="aspect ratio"):
        cal.scaled_to(5750, 5000)


def test_a_photo_of_another_aspect_ratio_names_the_file_the_line_and_the_photo(tmp_path):
    """A calibration for 1152 x 1152 px given for 640 x 1152 px photos: the message names the file, the line of
    the image size and its field, and the photo (was: no line, the file and the camera named twice)."""
    own = tmp_path / "aspect.yaml"
    own.write_text("name: DMC120\nfocal_length_px: 833.3\nimage_size_px: [1152, 1152]\n")
    cols = tmp_path / "cameras.txt"
    cols.write_text("# COLMAP\n1 PINHOLE 640 480 500 500 320 240\n2 PINHOLE 1152 1152 833.3 833.3 576 576\n")
    for path, line, fld, cam in ((own, 3, "image_size_px", "camera 'DMC120'"), (cols, 3, "WIDTH HEIGHT", "camera '2'")):
        cal = read_calibration(str(path))[-1]
        with pytest.raises(CalibrationError) as e:
            cal.scaled_to(640, 1152, "D1_01.tif")
        assert (e.value.line, e.value.field) == (line, fld)
        assert str(e.value) == (f"{path.name}, line {line}: {cam} is calibrated for 1152 x 1152 px images ({fld}); "
                                f"the photo D1_01.tif of 640 x 1152 px has another aspect ratio (1.0000 against "
                                f"0.5556): is it cropped or turned, or is the calibration's image size wrong?")


def _cal(**kw):
    base = dict(name="c", source="x.yaml", width=400, height=300, focal_px=500.0, focal_y_px=None,
                cx_px=201.0, cy_px=149.0)
    base.update(kw)
    return CameraCalibration(**base)


@pytest.mark.parametrize("kw, model", [
    ({}, "PINHOLE"),
    ({"focal_y_px": 510.0}, "PINHOLE"),
    ({"k1": -0.1}, "SIMPLE_RADIAL"),
    ({"k1": -0.1, "k2": 0.02}, "RADIAL"),
    ({"k1": -0.1, "focal_y_px": 510.0}, "OPENCV"),
    ({"k1": -0.1, "p2": 1e-4}, "OPENCV"),
    ({"k1": -0.1, "k3": 0.01}, "FULL_OPENCV"),
])
def test_colmap_model_is_the_simplest_that_holds_the_camera(kw, model):
    pycolmap = pytest.importorskip("pycolmap")
    cal = _cal(**kw)
    name, params = cal.colmap_model()
    assert name == model
    cam = pycolmap.Camera(model=name, width=cal.width, height=cal.height, params=params)
    # pycolmap reads the parameters in the order given
    assert cam.focal_length_x == cal.fx and cam.focal_length_y == cal.fy
    assert (cam.principal_point_x, cam.principal_point_y) == (cal.cx_px, cal.cy_px)
    # and projects like the Brown model with these values
    xyz = _points()
    xd, yd = _brown(xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2], cal.k1, cal.k2, cal.k3, cal.p1, cal.p2)
    expected = np.stack([cal.fx * xd + cal.cx_px, cal.fy * yd + cal.cy_px], axis=1)
    np.testing.assert_allclose(np.asarray(cam.img_from_cam(xyz)), expected, atol=1e-6)
    assert cal.to_intrinsics().model == model


def test_record_round_trip_through_json():
    cal = read_calibration(_data("rc20_certificate.yaml"))[0]
    back = CameraCalibration.from_dict(json.loads(json.dumps(cal.to_dict())))
    assert back == cal
    assert CameraCalibration.from_dict({**cal.to_dict(), "a_newer_field": 1}) == cal
    with pytest.raises(CalibrationError, match="focal_px"):
        CameraCalibration.from_dict({"name": "", "source": "w.json", "width": 1, "height": 1})


def test_images_patterns_pick_the_camera(tmp_path):
    p = tmp_path / "two.yaml"
    p.write_text("adjust: refined\ncameras:\n"
                 "  - name: left\n    images: ['L_*.jpg']\n    image_size_px: [400, 300]\n    focal_length_px: 500\n"
                 "  - name: right\n    images: ['R_*.jpg', 'r_*.JPG']\n    image_size_px: [400, 300]\n"
                 "    focal_length_px: 510\n    adjust: estimated\n")
    cams = read_calibration(str(p))
    assert [c.name for c in cams] == ["left", "right"] and [c.adjust for c in cams] == ["refined", "estimated"]
    assert calibration_for_image(cams, "photos/l_0001.JPG").name == "left"
    assert calibration_for_image(cams, "R_7.jpg").name == "right"
    assert calibration_for_image(cams, "other.jpg") is None
    single = read_calibration(_data("same_camera.json"))
    assert single[0].images == [] and calibration_for_image(single, "anything.tif") is single[0]
    assert set(ADJUST_MODES) == {"fixed", "refined", "estimated"}


def test_orthority_normalised_focal_and_flat_form(tmp_path):
    p = tmp_path / "int_param.yaml"
    p.write_text("name: drone\ntype: pinhole\nim_size: [1000, 750]\nfocal_len: 0.8\ncx: -0.01\ncy: 0.02\n")
    (cal,) = read_calibration(str(p))
    assert cal.name == "drone" and cal.colmap_model() == ("PINHOLE", [800.0, 800.0, 490.0, 395.0])
    assert cal.notes == [] and cal.warnings == []
    p.write_text("cam:\n  type: opencv\n  im_size: [750, 1000]\n  focal_len: 0.8\n  k1: -0.1\n")
    (cal,) = read_calibration(str(p))
    assert cal.focal_px == 600.0 and "width" in cal.warnings[0]  # Orthority's code: focal_len x image width
    # the doubt is a warning that gives both readings (a 44 % difference on a 640 x 1152 frame)
    assert "600.0 px (750 px wide)" in cal.warnings[0] and "would be 800.0 px (1000 px)" in cal.warnings[0]
    assert cal.colmap_model()[0] == "SIMPLE_RADIAL"


# ---------------------------------------------------------------------------
# bad files: the message names the file, the line and the field
# ---------------------------------------------------------------------------

_GOOD_CAMERA = "image_size_px: [640, 480]\npixel_size_mm: 0.005\nfocal_length_mm: 4.0\n"

BAD = [
    ("calib.yaml", "# a camera\nname: x\nimage_size_px: [640, 480]\npixel_size_mm: 0.005\n\n\nfocal_length_mm: abc\n",
     ["calib.yaml, line 7", "focal_length_mm must be a positive number, got 'abc'"]),
    ("calib.yaml", "image_size_px: [640, 480]\nfocal_length_mm: 4.0\n",
     ["calib.yaml, line 2", "focal_length_mm needs the pixel size", "pixel_size_mm"]),
    ("calib.yaml", "image_size_px: [640, 480]\npixel_size_mm: -0.005\nfocal_length_mm: 4.0\n",
     ["calib.yaml, line 2", "pixel_size_mm must be a positive number, got -0.005"]),
    ("calib.yaml", _GOOD_CAMERA + "adjust: free\n",
     ["calib.yaml, line 4", "adjust must be one of fixed, refined, estimated, got 'free'"]),
    ("calib.yaml", _GOOD_CAMERA + "focal_lenght_mm: 4\n",
     ["calib.yaml, line 4", "unknown field 'focal_lenght_mm'", "did you mean"]),
    ("calib.yaml", "cameras:\n  - name: a\n    " + _GOOD_CAMERA.replace("\n", "\n    ") + "focal_lenght_mm: 4\n",
     ["calib.yaml, line 6: camera 'a': unknown field 'focal_lenght_mm' (did you mean focal_length_mm"]),
    ("gcp.csv", "# crs: EPSG:32633\nname,x,y,z\nG01,404293.4,403841.5,448.6\n",
     ["gcp.csv: not a camera calibration this plugin reads"]),
    ("cameras.txt", "1 PINHOLE 640 480 500 500 3200 240\n",
     ["cameras.txt, line 1", "camera 1: the principal point (3200.00, 240.00) px lies outside the 640 x 480"]),
    ("calib.yaml", "cameras:\n  - name: a\n    " + _GOOD_CAMERA.replace("\n", "\n    ")
     + "principal_point_px: [3200, 240]\n",
     ["calib.yaml, line 6", "camera 'a'", "principal point", "outside"]),
    ("calib.yaml", "cameras:\n  - name: a\n    " + _GOOD_CAMERA.replace("\n", "\n    ") + "\n  - name: a\n    "
     + _GOOD_CAMERA.replace("\n", "\n    "), ["calib.yaml, line 7", "two cameras are named 'a'"]),
    ("calib.yaml", _GOOD_CAMERA + "radial_distortion_table:\n  - [10, 1.0]\n  - [20, 2.0]\n",
     ["calib.yaml, line 4", "radial_distortion_table needs at least 3 different radii"]),
    ("calib.yaml", _GOOD_CAMERA + "radial_distortion_table:\n  - [10, 1.0]\n  - [20]\n  - [30, 2.0]\n",
     ["calib.yaml, line 6", "row 2 of radial_distortion_table"]),
    ("calib.yaml", _GOOD_CAMERA + "sigmas:\n  focal_length_mm: 0\n",
     ["calib.yaml, line 5", "focal_length_mm must be a positive number"]),
    ("calib.yaml", "image_size_px: [640, 480\nfocal_length_px: 500\n", ["calib.yaml, line", "not valid YAML"]),
    ("calib.json", '{\n  "image_size_px": [640, 480],\n  "focal_length_px": 500,\n  "k1": "x"\n}\n',
     ["calib.json, line 4", "k1 must be a number, got 'x'"]),
    ("calib.json", '{\n  "image_size_px": [640, 480],\n  "focal_length_px": 500,}\n',  # Python 3.11 and 3.13 say
     ["calib.json, line 3", "not valid JSON"]),  # the same line when the comma and the brace share it
    ("cameras.txt", "# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n1 PINHOLE 640 480 500 500 320 240\n"
     "2 OPENCV_FISHEYE 640 480 500 500 320 240 0.1 0 0 0\n",
     ["cameras.txt, line 3", "OPENCV_FISHEYE is not supported"]),
    ("cameras.txt", "1 OPENCV 640 480 500 500 320 240 0.1\n", ["cameras.txt, line 1", "OPENCV takes 8 parameters"]),
    ("oty.yaml", "cam_a:\n  type: pinhole\n  im_size: [640, 480]\n  focal_len: 0.8\n"
     "cam_b:\n  type: fisheye\n  im_size: [640, 480]\n  focal_len: 0.5\n",
     ["oty.yaml, line 6", "camera 'cam_b'", "fisheye cameras are not supported yet"]),
    ("oty.yaml", "cam_a:\n  type: brown\n  im_size: [640, 480]\n", ["oty.yaml, line 2", "focal_len is missing"]),
    ("opencv.yml", "%YAML:1.0\ncamera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
     "  data: [500., 0., 319.5, 0., 500., 239.5, 0., 0., 1.]\n",
     ["opencv.yml, line 2", "image_width and image_height are needed"]),
    ("opencv.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n  rows: 3\n"
     "  cols: 3\n  dt: d\n  data: [500., 0., 319.5, 0., 500., 239.5, 0., 0.]\n",
     ["opencv.yml, line 8", "3 x 3 matrix with 8 values"]),
    ("ms.xml", "<?xml version='1.0'?>\n<calibration>\n  <projection>fisheye</projection>\n  <width>640</width>\n"
     "  <height>480</height>\n  <f>300</f>\n</calibration>\n",
     ["ms.xml, line 3", "fisheye camera is not supported"]),
    ("ms.xml", "<calibration>\n  <projection>frame</projection>\n  <width>640</width>\n  <height>480</height>\n"
     "  <f>300</f>\n  <b2>2.5</b2>\n</calibration>\n", ["ms.xml, line 6", "skew b2 = 2.5", "2.00 px"]),
    ("ms.xml", "<calibration>\n  <width>640</width>\n  <height>480</height>\n  <f>300</f>\n"
     "  <k4>0.01</k4>\n</calibration>\n", ["ms.xml, line 5", "k4 is not supported"]),
    ("ms.xml", "<calibration>\n  <width>640</width>\n  <height>480</height>\n  <f>300\n</calibration>\n",
     ["ms.xml, line 5", "not valid XML"]),
    ("other.xml", "<svg>\n</svg>\n", ["other.xml, line 1", "<svg>"]),
    ("oty.yaml", "c:\n  type: opencv\n  im_size: [640, 480]\n  focal_len: 0.8\n  k4: 0.1\n",
     ["oty.yaml, line 5", "camera 'c'", "k4 is not supported"]),
    ("opencv.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n  rows: 3\n"
     "  cols: 3\n  dt: d\n  data: [500., 0., 319.5, 0., 500., 239.5, 0., 0., 1.]\n"
     "distortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: 8\n  dt: d\n"
     "  data: [0.1, 0., 0., 0., 0., 0.2, 0., 0.]\n",
     ["opencv.yml, line 9", "distortion_coefficients: only k1, k2, p1, p2, k3 are supported"]),
    ("calib.yaml", "focal: 50\n", ["calib.yaml, line 1", "not a camera calibration"]),
    ("calib.yaml", "\n\n", ["calib.yaml", "empty"]),
]


@pytest.mark.parametrize("filename, content, expected", BAD, ids=[f"{i}-{b[0]}" for i, b in enumerate(BAD)])
def test_bad_files_name_file_line_and_field(tmp_path, filename, content, expected):
    path = tmp_path / filename
    path.write_text(content, encoding="utf-8")
    with pytest.raises(CalibrationError) as err:
        read_calibration(str(path))
    message = str(err.value)
    for part in expected:
        assert part in message, message
    assert isinstance(err.value, ArchaeoOrthoError) and isinstance(err.value, ValueError)
    assert err.value.file == str(path)


def test_a_missing_file_is_a_calibration_error(tmp_path):
    with pytest.raises(CalibrationError, match="does not exist"):
        read_calibration(str(tmp_path / "nothing.yaml"))


def test_error_carries_line_and_field(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(_GOOD_CAMERA + "k2: [1, 2]\n")
    with pytest.raises(CalibrationError) as err:
        read_calibration(str(path))
    assert (err.value.line, err.value.field) == (4, "k2")
    assert math.isclose(read_calibration(_data("same_camera.yaml"))[0].k2, 0.01)


def test_yaml_exponents_without_a_dot_are_numbers(tmp_path):
    # PyYAML (YAML 1.1) reads 5e-05 as a string; a certificate copied by hand has such values
    path = tmp_path / "c.yaml"
    path.write_text(_GOOD_CAMERA + "p2: -5e-05\nk1: '1.5E-3'\n")
    (cal,) = read_calibration(str(path))
    assert (cal.p2, cal.k1) == (-5e-05, 1.5e-3)


def test_metashape_without_adjusted_calibration_says_so(tmp_path):
    path = tmp_path / "cams.xml"
    path.write_text('<document>\n <chunk>\n  <sensors>\n   <sensor id="0" label="s">\n'
                    '    <calibration type="frame" class="initial">\n     <resolution width="400" height="300"/>\n'
                    '     <f>500</f>\n    </calibration>\n   </sensor>\n  </sensors>\n </chunk>\n</document>\n')
    (cal,) = read_calibration(str(path))
    assert cal.colmap_model() == ("PINHOLE", [500.0, 500.0, 200.0, 150.0])
    assert "initial one (line 5)" in cal.notes[0]


def test_the_documented_example_reads(tmp_path):
    doc = os.path.join(os.path.dirname(DATA), "..", "..", "docs", "calibration.md")
    with open(doc, encoding="utf-8") as fh:
        text = fh.read()
    example = text.split("```yaml\n", 1)[1].split("```", 1)[0]
    path = tmp_path / "camera.yaml"
    path.write_text(example, encoding="utf-8")
    (cal,) = read_calibration(str(path))
    assert (cal.name, cal.adjust, cal.images) == ("RC20_15UAG", "fixed", ["1971_*.tif"])
    assert (cal.cx_px, cal.cy_px) == pytest.approx((5749.8, 5749.45))  # as the table of fields says
    np.testing.assert_allclose([cal.k1, cal.k2, cal.k3], RC20_K, rtol=2e-3)  # its table is rounded to 1 nm


def test_error_forms_and_pickling():
    import pickle
    err = CalibrationError("/data/c.yaml", 3, "k1", "k1 must be a number")
    assert str(err) == "c.yaml, line 3: k1 must be a number"
    back = pickle.loads(pickle.dumps(err))
    assert (str(back), back.file, back.line, back.field) == (str(err), "/data/c.yaml", 3, "k1")
    plain = CalibrationError("the camera does not fit")
    assert str(plain) == "the camera does not fit" and plain.file == "" and plain.line is None
    assert str(pickle.loads(pickle.dumps(plain))) == str(plain)


def test_resampled_frame_and_the_scan_preparations_fiducials():
    from core.prepare.scans import parse_fiducial_coordinates
    cal = read_calibration(_data("rc20_certificate.yaml"))[0]
    assert cal.principal_point_mm == pytest.approx((-0.004, 0.011))
    # the scan preparation reads the certificate's marks relative to the principal point
    spec = parse_fiducial_coordinates(cal.fiducial_coordinates_text())
    assert "\nPP -0.004 0.011\n" in cal.fiducial_coordinates_text()  # as typed, not 0.010999999999967258
    assert spec.focal_length_mm == pytest.approx(152.817)
    by_id = {spec.ids[s]: spec.points[s] for s in spec.points}
    for name, (x, y) in cal.fiducials_mm.items():
        assert by_id[name] == pytest.approx((x + 0.004, y - 0.011))
    # the camera of images resampled to 25 um pixels with the principal point at their centre
    frame = cal.for_resampled_frame(9000, 9000, 0.025)
    assert frame.focal_px == pytest.approx(152.817 / 0.025) and (frame.cx_px, frame.cy_px) == (4500.0, 4500.0)
    assert frame.sigmas["focal_px"] == pytest.approx(0.003 / 0.025)
    # a ray lands where the certificate puts it: mm from the principal point (y up) over the pixel size
    xyz = np.array([[0.0, 0.0, 1.0], [0.3, -0.2, 1.0], [-0.5, 0.45, 2.0]])
    xn, yn = xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]
    xd, yd = _brown(xn, yn, cal.k1, cal.k2, cal.k3, 0, 0)
    expected = np.stack([4500 + 152.817 * xd / 0.025, 4500 + 152.817 * yd / 0.025], axis=1)
    np.testing.assert_allclose(_pycolmap_project(frame, xyz), expected, atol=1e-6)
    with pytest.raises(CalibrationError, match="focal length in mm"):
        read_calibration(_data("same_camera_cameras.txt"))[0].for_resampled_frame(100, 100, 0.1)


def test_a_certificate_typed_in_windows_1252_reads_and_a_binary_file_does_not(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_bytes(("# pixel 5 \u00b5m\n" + _GOOD_CAMERA).encode("cp1252"))
    assert read_calibration(str(path))[0].pixel_size_mm == 0.005
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    with pytest.raises(CalibrationError, match="not a text file"):
        read_calibration(str(path))


def test_prepare_images_reads_the_fiducials_of_a_calibration_file():
    """The certificate typed once: Prepare images' fiducial coordinates may be the calibration file Align images
    reads (was refused: 'expected id x y'); a calibration without fiducials says so, naming the file."""
    from core.prepare.options import ScanError
    from core.prepare.scans import parse_fiducial_coordinates

    path = _data("rc20_certificate.yaml")
    cal = read_calibration(path)[0]
    from_file = parse_fiducial_coordinates(path)
    from_text = parse_fiducial_coordinates(cal.fiducial_coordinates_text())
    assert from_file.focal_length_mm == pytest.approx(152.817)
    assert from_file.points == from_text.points and from_file.ids == from_text.ids and len(from_file.points) == 4
    with pytest.raises(ScanError, match=r"same_camera\.yaml: no camera of this calibration file gives fiducial"):
        parse_fiducial_coordinates(_data("same_camera.yaml"))


# ---------------------------------------------------------------------------
# issue 47 item 9: a calibration no camera can have is refused when read, before any work
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("extra, expected", [
    # k1 50, k2 -300 on a 1200 x 900 frame of 1000 px: the distorted radius turns back before the corner (it ran
    # 221 s and two escalation rounds, then blamed the focal length)
    ({"focal_length_px": 1000.0, "k1": 50.0, "k2": -300.0}, r"k1 = 50, k2 = -300\) folds the image"),
    # monotonic but the corner 29 times as far: no lens
    ({"focal_length_px": 1000.0, "k1": 50.0}, r"k1 = 50\) moves the farthest image corner 29\.1 times"),
    # 0.7 px and 702,061 px (44-70 s before the message)
    ({"focal_length_px": 0.7}, r"focal length of 0\.7 px on 1200 x 900 px images .*field of view of 180"),
    ({"focal_length_px": 702061.0}, r"focal length of 702,061 px .*field of view of 0\.0979 degrees"),
])
def test_an_implausible_calibration_is_refused_naming_the_file_and_the_value(tmp_path, extra, expected):
    p = tmp_path / "absurd.json"
    p.write_text(json.dumps({"name": "FC300X", "image_size_px": [1200, 900], "principal_point_px": [600, 450],
                             **extra}))
    with pytest.raises(CalibrationError, match=r"^absurd\.json.*: camera 'FC300X': ") as e:
        read_calibration(str(p))
    assert re.search(expected, str(e.value)), str(e.value)
    # a real wide angle's barrel (DJI Phantom 4 as Metashape gives it) and a 20 mm equivalent read
    p.write_text(json.dumps({"name": "P4", "image_size_px": [5472, 3648], "focal_length_px": 3650.0,
                             "k1": -0.27, "k2": 0.11, "k3": -0.03}))
    assert read_calibration(str(p))[0].k1 == -0.27
