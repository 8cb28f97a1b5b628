"""Issue 47's "heights" group (items 1, 4, 13, 14): references and DEMs whose meaning is wrong, re-made from a copy
of the demo workspace and run through ``qgis_process`` by ``benchmarks/bad_inputs_r3.py``.

1. the RGBA orthomosaic given to Georeference as its reference DSM (DEM control);
4. the DSM given as reference DEM with its heights in feet and no unit label (and, to show the check lets a right
   one through, the same labelled 'ft');
13. a reference DSM alone on a workspace whose photos carry no GPS: first without a CRS, then with one;
14. a reference orthophoto of another place (a Caliterra, Texas photo) over the block's footprint.
"""
import glob
import json
import os

import numpy as np
from bad_inputs import ROOT, Spec, _camera_heights, _gdal, case

FOOT = 0.3048


def _dsm_in_feet(src, out, unit=""):
    """The DSM ``src`` with its heights in international feet, in its own CRS (metres), the band's unit ``unit``
    (none: nothing in the file says feet)."""
    gdal, _ = _gdal()
    ds = gdal.Translate(out, src, outputType=gdal.GDT_Float32)
    band = ds.GetRasterBand(1)
    a = band.ReadAsArray().astype(np.float64)
    nd = band.GetNoDataValue()
    ok = np.isfinite(a) if nd is None else (a != nd) & np.isfinite(a)
    band.WriteArray(np.where(ok, a / FOOT, a).astype(np.float32))
    band.SetUnitType(unit)
    ds = None
    return out


def _heights_check(ws, before):
    """(ok, note) on exit 0: the camera heights against the block's own (EXIF GPS) georeference, within 2 m."""
    def check(out, _tmp):
        from osgeo import ogr

        cams = out.get("results", {}).get("CAMERAS") or os.path.join(ws, "cameras.gpkg")
        ds = ogr.Open(cams.split("|")[0])
        dz = [f.GetGeometryRef().GetZ() - before[f.GetField("image")] for f in ds.GetLayer(0)
              if f.GetField("image") in before]
        med = float(np.median(dz)) if dz else float("nan")
        return abs(med) < 2.0, f"camera heights {med:+.2f} m against the block's own georeference (median of {len(dz)})"
    return check


@case(1, "georeference REFERENCE_DSM = the RGBA orthomosaic (DEM control)",
      r"orthomosaic\.tif is an image, not heights")
def georef_rgba_reference_dsm(ws, tmp):
    before = _camera_heights(ws)
    check = _heights_check(ws, before)

    def silently(out, tmp_):
        ok, note = check(out, tmp_)
        return False, "the RGBA mosaic used as heights: " + note
    return Spec([("georeference", {"WORKSPACE": ws, "REFERENCE_DSM": os.path.join(ws, "orthomosaic.tif")})],
                protected=[os.path.join(ws, "orthomosaic.tif")], check=silently)


@case(4, "georeference REFERENCE_DSM = the DSM in feet, no unit label", r"dsm_ft\.tif.*feet")
def georef_feet_unlabelled(ws, tmp):
    before = _camera_heights(ws)
    ft = _dsm_in_feet(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft.tif"))
    return Spec([("georeference", {"WORKSPACE": ws, "REFERENCE_DSM": ft})], protected=[ft],
                check=_heights_check(ws, before))


@case(4, "georeference REFERENCE_DSM = the DSM in feet labelled 'ft' (must run)")
def georef_feet_labelled(ws, tmp):
    before = _camera_heights(ws)
    ft = _dsm_in_feet(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft_label.tif"), unit="ft")
    return Spec([("georeference", {"WORKSPACE": ws, "REFERENCE_DSM": ft})], protected=[ft],
                check=_heights_check(ws, before))


def _no_gps(ws):
    """The workspace's photos without EXIF GPS and the workspace without a CRS (an aligned block of photos taken
    without GPS)."""
    path = os.path.join(ws, "workspace.json")
    doc = json.load(open(path))
    for im in doc["images"]:
        im.pop("gps", None)
    doc["crs"] = None
    with open(path, "w") as fh:
        json.dump(doc, fh, indent=2)


# a clean message says what the reference DSM alone cannot do and what to add: positions (GPS, a positions file) or
# control points to place the block, or a reference orthophoto for the automatic control
_COMBINATIONS = r"(?s)reference D[SE]M.*(camera positions|GPS).*(GCP|control points).*REFERENCE_ORTHO"


@case(13, "georeference REFERENCE_DSM alone, photos without GPS, no CRS", _COMBINATIONS)
def georef_dsm_no_gps_no_crs(ws, tmp):
    _no_gps(ws)
    return Spec([("georeference", {"WORKSPACE": ws, "REFERENCE_DSM": os.path.join(ws, "dsm.tif")})])


@case(13, "georeference REFERENCE_DSM alone, photos without GPS, CRS=EPSG:32617", _COMBINATIONS)
def georef_dsm_no_gps_crs(ws, tmp):
    _no_gps(ws)
    return Spec([("georeference", {"WORKSPACE": ws, "REFERENCE_DSM": os.path.join(ws, "dsm.tif"),
                                   "CRS": "EPSG:32617"})])


def _other_place(ws, out):
    """A photo of another place (Caliterra, Texas) written as an RGB GeoTIFF over the orthomosaic's footprint."""
    gdal, _ = _gdal()
    photo = sorted(glob.glob(os.path.join(ROOT, "..", "shared", "data", "caliterra", "images", "*.[jJ][pP]*[gG]")))
    if not photo:
        raise SystemExit("../shared/data/caliterra/images has no photo")
    ref = gdal.Open(os.path.join(ws, "orthomosaic.tif"))
    w, h = ref.RasterXSize, ref.RasterYSize
    src = gdal.Open(photo[len(photo) // 2])
    ds = gdal.Translate(out, src, width=w, height=h, bandList=[1, 2, 3], creationOptions=["PHOTOMETRIC=RGB"])
    ds.SetGeoTransform(ref.GetGeoTransform())
    ds.SetProjection(ref.GetProjection())
    ds = None
    return out


@case(14, "automatic control against an orthophoto of another place over the block's footprint",
      r"elsewhere\.tif.*does not (show|seem to show) the block")
def autocontrol_other_place(ws, tmp):
    o = _other_place(ws, os.path.join(tmp, "elsewhere.tif"))
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": o,
                                  "REFERENCE_DSM": os.path.join(ws, "dsm.tif")})], protected=[o])
