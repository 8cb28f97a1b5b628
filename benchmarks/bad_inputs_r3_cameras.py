"""Issue 47's "cameras" group (items 3, 8, 9, 10): interior orientations and photo folders whose meaning is wrong,
re-made from a copy of the demo workspace and run through ``qgis_process`` by ``benchmarks/bad_inputs_r3.py``.

3. FOCAL_MM=20 SENSOR_WIDTH_MM=6.17 INTRINSICS=fixed on the demo's photos, whose EXIF says 3.61 mm (20 mm is their
   35 mm equivalent); an Orthority file with the focal length in mm and no sensor_size (read as 4,332 px);
8. Align images on the finished workspace with another survey's photos (six Caliterra photos);
9. calibrations no camera can have: distortion k1 50, k2 -300; focal lengths of 0.7 px and 702,061 px;
10. a COLMAP cameras file with two cameras of the photos' size.
"""
import json
import math
import os
import shutil

from bad_inputs import ROOT, Spec, case

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")
INTRINSICS_FIXED = 1  # processing_provider.params.INTRINSICS: auto, fixed, refined, estimated
# the demo's photos: 1200 x 900 px, EXIF 3.61 mm, 20 mm in 35 mm film: 20 / 43.27 x 1500 px
EXIF_FOCAL_PX = 20.0 / math.hypot(36.0, 24.0) * math.hypot(1200.0, 900.0)


def _photos(ws):
    return json.load(open(os.path.join(ws, "workspace.json")))["images_dir"]


def _focal_check(ws):
    """(ok, note) on exit 0: the aligned cameras' focal lengths against the EXIF's (693 px), within 10 %."""
    def check(_out, _tmp):
        rows = json.load(open(os.path.join(ws, "sfm", "alignment.json"))).get("intrinsics") or []
        f = [float(r["final"].get("f", r["final"].get("fx"))) for r in rows if r.get("final")]
        ok = bool(f) and all(abs(v / EXIF_FOCAL_PX - 1.0) < 0.10 for v in f)
        return ok, (f"aligned with focal length(s) {', '.join(f'{v:.0f}' for v in f)} px "
                    f"({', '.join(str(r.get('mode')) for r in rows)}); the EXIF's is {EXIF_FOCAL_PX:.0f} px")
    return check


def _calibration(tmp, name, text):
    path = os.path.join(tmp, name)
    with open(path, "w") as fh:
        fh.write(text)
    return path


@case(3, "alignimages FOCAL_MM=20 (the 35 mm equivalent) SENSOR_WIDTH_MM=6.17 INTRINSICS=fixed",
      r"20 mm is the photos' 35 mm equivalent focal length.*FOCAL_MM=3\.61")
def focal_35mm_equivalent(ws, tmp):
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "FOCAL_MM": 20, "SENSOR_WIDTH_MM": 6.17,
                                  "INTRINSICS": INTRINSICS_FIXED})], check=_focal_check(ws))


@case(3, "alignimages CALIBRATION = an Orthority file, focal_len 3.61 (mm) without sensor_size",
      r"int_param\.yaml.*4332\.0 px.*EXIF focal length in mm.*sensor_size")
def orthority_focal_in_mm(ws, tmp):
    cal = _calibration(tmp, "int_param.yaml", "type: pinhole\nim_size: [1200, 900]\nfocal_len: 3.61\n")
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "CALIBRATION": cal})], protected=[cal],
                check=_focal_check(ws))


@case(8, "alignimages on the finished workspace with another survey's photo folder",
      r"was aligned from the photos of .*toledo.*holds none of them.*IMAGES=.*new WORKSPACE")
def another_photo_folder(ws, tmp):
    other = os.path.join(tmp, "caliterra")
    os.makedirs(other)
    src = os.path.join(SHARED, "caliterra", "images")
    for n in sorted(os.listdir(src))[:6]:
        shutil.copy2(os.path.join(src, n), other)
    keep = [os.path.join(ws, p) for p in ("workspace.json", "dsm.tif", "orthomosaic.tif",
                                          os.path.join("sfm", "model", "images.bin"))]
    return Spec([("alignimages", {"IMAGES": other, "WORKSPACE": ws})], protected=keep)


def _own(tmp, name, **values):
    doc = {"name": "FC300X", "image_size_px": [1200, 900], "principal_point_px": [600.0, 450.0], **values}
    return _calibration(tmp, name, json.dumps(doc))


@case(9, "alignimages CALIBRATION with distortion k1 50, k2 -300", r"absurd_k\.json.*k1 = 50, k2 = -300\) folds")
def absurd_distortion(ws, tmp):
    cal = _own(tmp, "absurd_k.json", focal_length_px=700.0, k1=50.0, k2=-300.0)
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "CALIBRATION": cal})],
                check=_focal_check(ws))


@case(9, "alignimages CALIBRATION with a focal length of 0.7 px", r"focal_07\.json.*0\.7 px.*field of view")
def focal_tiny(ws, tmp):
    cal = _own(tmp, "focal_07.json", focal_length_px=0.7)
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "CALIBRATION": cal})],
                check=_focal_check(ws))


@case(9, "alignimages CALIBRATION with a focal length of 702,061 px",
      r"focal_huge\.json.*702,061 px.*field of view")
def focal_huge(ws, tmp):
    cal = _own(tmp, "focal_huge.json", focal_length_px=702061.0)
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "CALIBRATION": cal})],
                check=_focal_check(ws))


@case(10, "alignimages CALIBRATION = a COLMAP cameras.txt with two cameras of the photos' size",
      r"cameras\.txt: 2 of its cameras fit the photo .*camera '1'.*camera '2'.*delete the others")
def colmap_two_cameras(ws, tmp):
    cal = _calibration(tmp, "cameras.txt", "# two cameras, both 1200 x 900 px\n"
                                           "1 RADIAL 1200 900 702 600 450 -0.11 0.09\n"
                                           "2 OPENCV 1200 900 708 708 600 450 0.007 0.019 0 0\n")
    return Spec([("alignimages", {"IMAGES": _photos(ws), "WORKSPACE": ws, "CALIBRATION": cal})],
                check=_focal_check(ws))
