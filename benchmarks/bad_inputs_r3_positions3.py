"""Issue 47, group "positions3" (items 2, 12 and 17 before any long work; issue 49: one check of where control
lands): camera positions and GCPs whose numbers are valid but whose meaning is not (latitude in the x column, the
next UTM zone, a photo's row twice) given to Run pipeline and Align images, which read the positions file before
the alignment, and to Orthorectify image.  The check (``core.io.control_place``, the georeference stage's) compares
them with the photos' EXIF GPS read from the image files, so a refusal comes before the alignment's minutes, not
after; run through ``qgis_process`` by ``benchmarks/bad_inputs_r3.py``."""
import json
import os

from bad_inputs import Spec, case
from bad_inputs_r3_positions import _images, _model_gcps, _utm_positions, _write


def _photos(ws):
    """The demo's photo folder (the workspace's images_dir)."""
    return json.load(open(os.path.join(ws, "workspace.json")))["images_dir"]


def _latlon_swapped(ws, tmp):
    rows = ["EPSG:4326", "image,x,y,z"] + [f"{im['name']},{im['gps'][1]:.8f},{im['gps'][0]:.8f},{im['gps'][2]}"
                                           for im in _images(ws)]
    return _write(os.path.join(tmp, "positions_latlon.csv"), rows)


def _zone18(ws, tmp):
    rows = ["EPSG:32618", "image,x,y,z"] + [f"{n},{x:.3f},{y:.3f},{z}" for n, (x, y, z) in _utm_positions(ws).items()]
    return _write(os.path.join(tmp, "positions_zone18.csv"), rows)


def _nothing_aligned(out, tmp):
    """A refusal before the alignment: the new workspace holds no sfm/ folder."""
    sfm = os.path.join(tmp, "new", "sfm")
    return not os.path.exists(sfm), "refused only after the alignment (new/sfm written)"


def _pipeline(ws, tmp, **params):
    return ("runpipeline", dict({"IMAGES": _photos(ws), "WORKSPACE": os.path.join(tmp, "new"), "MAKE_REPORT": False,
                                 "MAKE_DTM": False}, **params))


def _align(ws, tmp, **params):
    return ("alignimages", dict({"IMAGES": _photos(ws), "WORKSPACE": os.path.join(tmp, "new")}, **params))


def _aligned_unsaid(what):
    def check(out, _tmp):
        return False, f"exit 0: aligned with {what}, nothing said"
    return check


@case(2, "Run pipeline with camera positions in EPSG:4326, latitude in the x column",
      r"camera positions in \S+ \(EPSG:4326\) land .* latitude and longitude look swapped")
def pipeline_positions_latlon_swapped(ws, tmp):
    p = _latlon_swapped(ws, tmp)
    return Spec([_pipeline(ws, tmp, CAMERA_POSITIONS=p)], protected=[p], refused_check=_nothing_aligned)


@case(2, "Run pipeline with camera positions of UTM zone 17N labelled EPSG:32618 (the next zone)",
      r"camera positions in \S+ \(EPSG:32618\) land .*EPSG:32617")
def pipeline_positions_wrong_zone(ws, tmp):
    p = _zone18(ws, tmp)
    return Spec([_pipeline(ws, tmp, CAMERA_POSITIONS=p)], protected=[p], refused_check=_nothing_aligned)


@case(12, "Run pipeline with camera positions in UTM and CRS=EPSG:4326",
      r"CRS=EPSG:4326 \(the CRS parameter\) is geographic.*CRS=EPSG:32617")
def pipeline_geographic_crs(ws, tmp):
    rows = ["EPSG:32617", "image,x,y,z"] + [f"{n},{x:.3f},{y:.3f},{z}" for n, (x, y, z) in _utm_positions(ws).items()]
    p = _write(os.path.join(tmp, "positions_utm.csv"), rows)
    return Spec([_pipeline(ws, tmp, CAMERA_POSITIONS=p, CRS="EPSG:4326")], protected=[p],
                refused_check=_nothing_aligned)


@case(2, "Align images with camera positions in EPSG:4326, latitude in the x column",
      r"camera positions in \S+ \(EPSG:4326\) land .* latitude and longitude look swapped")
def align_positions_latlon_swapped(ws, tmp):
    p = _latlon_swapped(ws, tmp)
    return Spec([_align(ws, tmp, CAMERA_POSITIONS=p)], protected=[p], refused_check=_nothing_aligned,
                check=_aligned_unsaid("the pairs of positions 15,000 km from the photos' GPS"))


@case(2, "Align images with camera positions of UTM zone 17N labelled EPSG:32618 (the next zone)",
      r"camera positions in \S+ \(EPSG:32618\) land .*EPSG:32617")
def align_positions_wrong_zone(ws, tmp):
    p = _zone18(ws, tmp)
    return Spec([_align(ws, tmp, CAMERA_POSITIONS=p)], protected=[p], refused_check=_nothing_aligned,
                check=_aligned_unsaid("positions 500 km from the photos' GPS"))


@case(17, "Align images with camera positions holding a photo's row twice")
def align_positions_duplicate(ws, tmp):
    pos = _utm_positions(ws)
    first = sorted(pos)[0]
    x, y, z = pos[first]
    rows = ["EPSG:32617", "image,x,y,z"] + [f"{n},{a:.3f},{b:.3f},{c}" for n, (a, b, c) in pos.items()]
    p = _write(os.path.join(tmp, "positions_dup.csv"), rows + [f"{first},{x:.3f},{y:.3f},{z}"])

    def check(out, _tmp):
        warned = any(first in ln and "line" in ln for ln in out.get("text", "").splitlines())
        return warned, f"exit 0; duplicate {'named' if warned else 'not named'} in the log"
    return Spec([_align(ws, tmp, CAMERA_POSITIONS=p)], protected=[p], check=check)


@case(2, "Orthorectify image with GCPs of UTM zone 17N labelled EPSG:32618 (the next zone)",
      r"control points of the GCP file \S+ \(EPSG:32618\) land .*EPSG:32617")
def single_gcps_wrong_zone(ws, tmp):
    p = _model_gcps(ws, tmp, n=8, crs_line="EPSG:32618")
    seen = {}
    for line in open(os.path.join(tmp, "gcps_observations.csv")).read().splitlines()[1:]:
        seen.setdefault(line.split(",")[1], set()).add(line.split(",")[0])
    photo = max(seen, key=lambda n: len(seen[n]))  # the photo that sees most of the points

    def check(out, _tmp):
        return False, "exit 0: orthorectified in EPSG:32618, 500 km from the photo's GPS, nothing said"
    return Spec([("orthorectifyimage", {"IMAGE": os.path.join(_photos(ws), photo), "DSM": os.path.join(ws, "dsm.tif"),
                                        "GCPS": p, "OUTPUT": os.path.join(tmp, "single.tif")})],
                protected=[p], check=check)
