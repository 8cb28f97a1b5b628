"""Issue 36's bad inputs, re-run: each made from a finished workspace (the demo's 18 Toledo photos, ``make demo``),
run through ``qgis_process`` as a user would, on a fresh copy, and classified:

- clean: refused with a message that names the file or the problem (no traceback), nothing lost;
- ok: the run succeeded and its figures are right (checked against what is known: a DSM in feet against the same
  DSM in metres, contours' heights, camera heights);
- unclear: refused without a traceback but the message does not say what is wrong (the case's pattern);
- traceback: a Python traceback reached the user;
- silently wrong: exit 0 with wrong figures (checked);
- unclean: refused, but after leaving something behind (a workspace created for an empty folder);
- refused: an input the run should take (a photo to skip with a warning) stopped it;
- lost data: an input or a recorded product changed (fingerprints before / after), whatever the exit.

    python benchmarks/bad_inputs.py [--workspace build/demo-workspace] [--before /tmp/wt-before] [--cases a,b]

``--before`` is a checkout of an earlier commit (``git worktree add /tmp/wt-before <commit>``, with a ``.venv``
link to this one's): both are run and the table gives the class of each case before and after.  Every case runs
on its own copy of the workspace under a temporary folder; nothing is written into the workspace given.
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
QGIS_PROCESS = shutil.which("qgis_process.bin") or shutil.which("qgis_process") or "/usr/bin/qgis_process.bin"
FT_US = 1200.0 / 3937.0
TMERC = ("+proj=tmerc +lat_0=41 +lon_0=-83.7 +k=0.9999 +x_0=500000 +y_0=200000 +ellps=GRS80 +units=m +no_defs")
CASES = []


def case(item, name, expect=None):
    """A bad input: ``expect``, the pattern a clean refusal's message matches (None: the run must succeed)."""
    def wrap(fn):
        CASES.append({"id": fn.__name__, "item": item, "name": name, "expect": expect, "make": fn})
        return fn
    return wrap


class Spec:
    """What to run: ``runs``, (algorithm, {param: value}) run one after the other (two at once with
    ``parallel``); ``protected``: files that must not change; ``check(out, tmp) -> (ok, note)`` on exit 0."""

    def __init__(self, runs, protected=(), check=None, parallel=False, user=None, refused_check=None):
        self.runs, self.protected, self.check, self.parallel, self.user = runs, list(protected), check, parallel, user
        self.refused_check = refused_check  # (ok, note) after a refusal: what it must not have left behind


# ---------------------------------------------------------------------------
# rasters made from the workspace's own products
# ---------------------------------------------------------------------------

def _gdal():
    from osgeo import gdal, osr

    gdal.UseExceptions()
    return gdal, osr


def _feet_dsm(src, out):
    """The DSM warped into EPSG:3734 (Ohio North, US survey feet), heights in feet: a state plane DEM."""
    gdal, _ = _gdal()
    tmp = out + ".m.tif"
    gdal.Warp(tmp, src, dstSRS="EPSG:3734", resampleAlg="bilinear", dstNodata=-9999.0)
    ds = gdal.Open(tmp)
    a = ds.GetRasterBand(1).ReadAsArray().astype(np.float64)
    nd = ds.GetRasterBand(1).GetNoDataValue()
    a = np.where(a == nd, -9999.0, a / FT_US)
    drv = gdal.GetDriverByName("GTiff")
    o = drv.Create(out, ds.RasterXSize, ds.RasterYSize, 1, gdal.GDT_Float32)
    o.SetGeoTransform(ds.GetGeoTransform())
    o.SetProjection(ds.GetProjection())
    o.GetRasterBand(1).SetNoDataValue(-9999.0)
    o.GetRasterBand(1).WriteArray(a.astype(np.float32))
    o = None
    os.remove(tmp)
    return out


def _shifted(src, out, dx):
    gdal, _ = _gdal()
    ds = gdal.Translate(out, src)
    gt = list(ds.GetGeoTransform())
    gt[0] += dx
    ds.SetGeoTransform(gt)
    ds = None
    return out


def _noise_like(src, out):
    gdal, _ = _gdal()
    ds = gdal.Open(src)
    rng = np.random.default_rng(5)
    o = gdal.GetDriverByName("GTiff").Create(out, ds.RasterXSize, ds.RasterYSize, 3, gdal.GDT_Byte,
                                             ["PHOTOMETRIC=RGB"])
    o.SetGeoTransform(ds.GetGeoTransform())
    o.SetProjection(ds.GetProjection())
    for k in range(3):
        o.GetRasterBand(k + 1).WriteArray(rng.integers(1, 255, (ds.RasterYSize, ds.RasterXSize)).astype(np.uint8))
    o = None
    return out


def _all_nodata(src, out):
    gdal, _ = _gdal()
    ds = gdal.Translate(out, src, noData=-9999.0)
    b = ds.GetRasterBand(1)
    b.Fill(-9999.0)
    ds = None
    return out


# ---------------------------------------------------------------------------
# the cases
# ---------------------------------------------------------------------------

@case(1, "builddtm OUTPUT_DTM = its DSM", r"dsm\.tif")
def dtm_over_dsm(ws, tmp):
    dsm = os.path.join(ws, "dsm.tif")
    return Spec([("builddtm", {"WORKSPACE": ws, "DSM": dsm, "OUTPUT_DTM": dsm})], protected=[dsm])


@case(1, "reliefvisualisation OUTPUT = INPUT", r"x\.tif")
def relief_over_input(ws, tmp):
    x = shutil.copy(os.path.join(ws, "dtm.tif"), os.path.join(tmp, "x.tif"))
    return Spec([("reliefvisualisation", {"INPUT": x, "VISUALISATION": 0, "OUTPUT": x})], protected=[x])


@case(1, "contours OUTPUT = INPUT", r"x\.tif")
def contours_over_input(ws, tmp):
    x = shutil.copy(os.path.join(ws, "dtm.tif"), os.path.join(tmp, "x.tif"))
    return Spec([("contours", {"INPUT": x, "INTERVAL": 1, "OUTPUT": x})], protected=[x])


@case(2, "a failed automatic control keeps the record of the control in use", r"candidate")
def autocontrol_failed_keeps_record(ws, tmp):
    rec = os.path.join(ws, "georef", "autocontrol.json")
    with open(rec, "w") as fh:
        fh.write('{"format": "archaeoortho-autocontrol", "the control": "in use"}')
    noise = _noise_like(os.path.join(ws, "orthomosaic.tif"), os.path.join(tmp, "noise.tif"))
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": noise,
                                  "REFERENCE_DSM": os.path.join(ws, "dsm.tif")})], protected=[rec])


@case(3, "builddtm and reliefvisualisation at once on one workspace")
def two_terrain_stages_at_once(ws, tmp):
    def check(out, tmp_):
        st = json.load(open(os.path.join(ws, "workspace.json")))["stages"]
        have = {k: (st.get(k) or {}).get("status") for k in ("terrain", "relief")}
        # both ended: each record done (or stale: the relief made from a DTM the other replaced); 'running' or
        # missing is a record lost to the other's write
        return all(v in ("done", "stale") for v in have.values()), f"stage records after both: {have}"
    return Spec([("builddtm", {"WORKSPACE": ws}),
                 ("reliefvisualisation", {"WORKSPACE": ws, "SOURCE": 0, "VISUALISATION": 0})],
                parallel=True, check=check)


def _median_output(out, _tmp):
    m = out.get("results", {}).get("MEDIAN")
    return (m is not None and abs(float(m)) < 0.5), f"median change {m} m (truth 0)"


@case(4, "dsmdifference of a DSM in metres and the same in US feet (EPSG:3734)")
def difference_metres_feet(ws, tmp):
    ft = _feet_dsm(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft.tif"))
    return Spec([("dsmdifference", {"DSM_A": os.path.join(ws, "dsm.tif"), "DSM_B": ft,
                                    "OUTPUT": os.path.join(tmp, "diff.tif")})], protected=[ft],
                check=_median_output)


@case(4, "contours of a DSM in US feet, interval 1 m")
def contours_feet(ws, tmp):
    ft = _feet_dsm(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft.tif"))
    out_path = os.path.join(tmp, "c.gpkg")

    def check(out, _tmp):
        from osgeo import ogr

        gdal, _ = _gdal()
        dsm = gdal.Open(os.path.join(ws, "dsm.tif"))  # kept: a band outliving its dataset crashes GDAL
        z = dsm.GetRasterBand(1).ComputeRasterMinMax(False)
        ds = ogr.Open(out_path)
        lyr = ds.GetLayer(0)
        vals = sorted({round(f.GetField("elevation"), 3) for f in lyr})
        steps = np.diff(vals)
        ok = abs(vals[-1] - z[1]) < 2.0 and len(steps) and abs(float(np.median(steps)) - 1.0) < 0.01
        return ok, (f"{len(vals)} levels {vals[0]:.1f}..{vals[-1]:.1f} (step {float(np.median(steps)):.3f}); the DSM "
                    f"spans {z[0]:.1f}..{z[1]:.1f} m")
    return Spec([("contours", {"INPUT": ft, "INTERVAL": 1, "OUTPUT": out_path})], protected=[ft], check=check)


def _camera_heights(ws):
    from osgeo import ogr

    ds = ogr.Open(os.path.join(ws, "cameras.gpkg"))
    out = {}
    for f in ds.GetLayer(0):
        g = f.GetGeometryRef()
        out[f.GetField("image") if f.GetFieldIndex("image") >= 0 else f.GetFID()] = g.GetZ()
    return out


@case(4, "automatic control with a reference DSM in US feet (EPSG:3734)")
def autocontrol_feet_dsm(ws, tmp):
    before = _camera_heights(ws)
    ft = _feet_dsm(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft.tif"))
    ortho = shutil.copy(os.path.join(ws, "orthomosaic.tif"), os.path.join(tmp, "ref_ortho.tif"))

    def check(out, _tmp):
        cams = out.get("results", {}).get("CAMERAS") or os.path.join(ws, "cameras.gpkg")
        from osgeo import ogr

        ds = ogr.Open(cams.split("|")[0])
        dz = [f.GetGeometryRef().GetZ() - before[f.GetField("image")] for f in ds.GetLayer(0)
              if f.GetField("image") in before]
        med = float(np.median(dz)) if dz else float("nan")
        return abs(med) < 2.0, f"camera heights {med:+.2f} m against the block's own control (median of {len(dz)})"
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": ortho, "REFERENCE_DSM": ft})],
                protected=[ft, ortho], check=check)


def _orientation(ws, tmp):
    """(photo path, orientation JSON) of a photo of the block's RADIAL camera, from the georeferenced model."""
    import pycolmap

    sys.path.insert(0, ROOT)
    from core.geometry.camera import opk_from_rotation

    rec = pycolmap.Reconstruction(os.path.join(ws, "georef", "model"))
    tf = json.load(open(os.path.join(ws, "georef", "transform.json")))
    paths = {im["name"]: im["path"] for im in json.load(open(os.path.join(ws, "workspace.json")))["images"]}
    for i in sorted(rec.reg_image_ids()):
        im = rec.image(i)
        cam = rec.cameras[im.camera_id]
        if cam.model.name != "RADIAL":
            continue
        m = np.asarray(im.cam_from_world().matrix())
        c = -m[:, :3].T @ m[:, 3] + np.asarray(tf["offset"], dtype=float)
        om, ph, ka = opk_from_rotation(m[:, :3])
        f, cx, cy, k1, k2 = (float(v) for v in cam.params)
        doc = {"x": c[0], "y": c[1], "z": c[2], "omega": om, "phi": ph, "kappa": ka, "focal_px": f, "cx": cx,
               "cy": cy, "k1": k1, "k2": k2, "crs": tf["crs"]}
        path = os.path.join(tmp, "orientation.json")
        with open(path, "w") as fh:
            json.dump(doc, fh)
        return paths[im.name], path
    raise SystemExit("no photo of a RADIAL camera in the demo workspace")


@case(4, "Orthorectify image (known orientation) on a DSM in US feet against the DSM in metres")
def orthorectify_feet_dsm(ws, tmp):
    photo, orient = _orientation(ws, tmp)
    ft = _feet_dsm(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "dsm_ft.tif"))
    outs = [os.path.join(tmp, "single_m.tif"), os.path.join(tmp, "single_ft.tif")]

    def check(out, _tmp):
        gdal, _ = _gdal()
        a, b = gdal.Open(outs[0]), gdal.Open(outs[1])
        b = gdal.Warp("", b, format="MEM", outputBounds=_bounds(a), width=a.RasterXSize, height=a.RasterYSize)
        pa, pb = a.ReadAsArray().astype(np.float32), b.ReadAsArray().astype(np.float32)
        both = (pa[-1] > 0) & (pb[-1] > 0)
        share = both.sum() / max(1, (pa[-1] > 0).sum())
        diff = float(np.median(np.abs(pa[0][both] - pb[0][both]))) if both.any() else float("inf")
        return share > 0.9 and diff < 4.0, (f"against the metre DSM's orthophoto: {100 * share:.0f} % of its cells, "
                                            f"median grey difference {diff:.1f}")
    return Spec([("orthorectifyimage", {"IMAGE": photo, "DSM": os.path.join(ws, "dsm.tif"), "ORIENTATION": orient,
                                        "OUTPUT": outs[0]}),
                 ("orthorectifyimage", {"IMAGE": photo, "DSM": ft, "ORIENTATION": orient, "OUTPUT": outs[1]})],
                protected=[ft], check=check)


def _bounds(ds):
    gt = ds.GetGeoTransform()
    return (gt[0], gt[3] + ds.RasterYSize * gt[5], gt[0] + ds.RasterXSize * gt[1], gt[3])


@case(5, "builddtm of the RGBA orthomosaic as DSM", r"orthomosaic\.tif.*(band|colou?r|RGB|picture)")
def rgba_as_dsm(ws, tmp):
    return Spec([("builddtm", {"WORKSPACE": ws, "DSM": os.path.join(ws, "orthomosaic.tif"),
                               "OUTPUT_DTM": os.path.join(tmp, "dtm.tif")})],
                protected=[os.path.join(ws, "orthomosaic.tif"), os.path.join(ws, "dtm.tif")])


@case(5, "dsmdifference with the orthomosaic as DSM B", r"orthomosaic\.tif.*(band|colou?r|RGB|picture)")
def rgba_difference(ws, tmp):
    return Spec([("dsmdifference", {"DSM_A": os.path.join(ws, "dsm.tif"), "DSM_B": os.path.join(ws, "orthomosaic.tif"),
                                    "OUTPUT": os.path.join(tmp, "diff.tif")})])


@case(6, "builddtm after a re-georeference into another CRS (EPSG:3734), the DSM not rebuilt", r"stale")
def stale_dsm(ws, tmp):
    def check(out, _tmp):
        st = json.load(open(os.path.join(ws, "workspace.json")))["stages"]
        return False, f"built from the old CRS's DSM, terrain stage {st.get('terrain', {}).get('status')}"
    return Spec([("georeference", {"WORKSPACE": ws, "USE_EXIF_GPS": "true", "CRS": "EPSG:3734"}),
                 ("builddtm", {"WORKSPACE": ws})], check=check)


@case(8, "contours OUTPUT=x.shp", r"(\.shp|GeoPackage|\.gpkg)")
def contours_shp(ws, tmp):
    out_path = os.path.join(tmp, "x.shp")

    def check(out, _tmp):
        from osgeo import ogr

        ds = ogr.Open(out_path)
        drv = ds.GetDriver().GetName() if ds is not None else None
        return drv == "ESRI Shapefile", f"{out_path} written by {drv}"
    return Spec([("contours", {"INPUT": os.path.join(ws, "dtm.tif"), "INTERVAL": 1, "OUTPUT": out_path})], check=check)


def _auto_ok(out, _tmp):
    n = out.get("results", {}).get("AUTO_GCPS")
    return n is not None and int(n) >= 4, f"{n} automatic GCPs"


@case(9, "automatic control against references in a transverse Mercator CRS without EPSG code")
def autocontrol_national_crs(ws, tmp):
    gdal, _ = _gdal()
    o = os.path.join(tmp, "ortho_tm.tif")
    d = os.path.join(tmp, "dsm_tm.tif")
    gdal.Warp(o, os.path.join(ws, "orthomosaic.tif"), dstSRS=TMERC)
    gdal.Warp(d, os.path.join(ws, "dsm.tif"), dstSRS=TMERC, dstNodata=-9999.0)
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": o, "REFERENCE_DSM": d})], check=_auto_ok)


@case(10, "a VRT reference whose source file is missing", r"ortho\.vrt.*(ortho_src\.tif|does not exist)")
def autocontrol_vrt_missing(ws, tmp):
    gdal, _ = _gdal()
    src = shutil.copy(os.path.join(ws, "orthomosaic.tif"), os.path.join(tmp, "ortho_src.tif"))
    vrt = os.path.join(tmp, "ortho.vrt")
    gdal.BuildVRT(vrt, [src])
    os.remove(src)
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": vrt,
                                  "REFERENCE_DSM": os.path.join(ws, "dsm.tif")})])


@case(11, "builddtm of a 60,000 x 60,000 sparse DSM", r"(memory|too large|GiB)")
def huge_sparse_dsm(ws, tmp):
    gdal, osr = _gdal()
    p = os.path.join(tmp, "huge.tif")
    ds = gdal.GetDriverByName("GTiff").Create(p, 60000, 60000, 1, gdal.GDT_Float32,
                                              ["SPARSE_OK=TRUE", "TILED=YES", "BIGTIFF=YES", "COMPRESS=DEFLATE"])
    ref = gdal.Open(os.path.join(ws, "dsm.tif"))
    gt = ref.GetGeoTransform()
    ds.SetGeoTransform((gt[0], 0.01, 0.0, gt[3], 0.0, -0.01))
    ds.SetProjection(ref.GetProjection())
    ds.GetRasterBand(1).SetNoDataValue(-9999.0)
    ds.GetRasterBand(1).WriteArray(np.full((64, 64), 180.0, np.float32), 30000, 30000)
    ds = None
    return Spec([("builddtm", {"WORKSPACE": ws, "DSM": p, "OUTPUT_DTM": os.path.join(tmp, "dtm.tif")})])


@case(12, "automatic control: the reference orthophoto and DSM 5 km away", r"^reference (orthophoto|DSM) \S+ does not cover")
def autocontrol_far(ws, tmp):
    o = _shifted(os.path.join(ws, "orthomosaic.tif"), os.path.join(tmp, "far_ortho.tif"), 5000.0)
    d = _shifted(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "far_dsm.tif"), 5000.0)
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": o, "REFERENCE_DSM": d})])


@case(12, "automatic control: the reference DSM all nodata", r"^reference DSM \S+ has no data")
def autocontrol_dsm_nodata(ws, tmp):
    d = _all_nodata(os.path.join(ws, "dsm.tif"), os.path.join(tmp, "nodata_dsm.tif"))
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": os.path.join(ws, "orthomosaic.tif"),
                                  "REFERENCE_DSM": d})])


@case(12, "automatic control: the references swapped", r"^(the references look swapped|reference DSM \S+ is a picture)")
def autocontrol_swapped(ws, tmp):
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": os.path.join(ws, "dsm.tif"),
                                  "REFERENCE_DSM": os.path.join(ws, "orthomosaic.tif")})])


@case(12, "automatic control: the reference orthophoto in EPSG:4326 (geographic)")
def autocontrol_geographic(ws, tmp):
    gdal, _ = _gdal()
    o = os.path.join(tmp, "ortho_4326.tif")
    gdal.Warp(o, os.path.join(ws, "orthomosaic.tif"), dstSRS="EPSG:4326")
    return Spec([("autocontrol", {"WORKSPACE": ws, "REFERENCE_ORTHO": o,
                                  "REFERENCE_DSM": os.path.join(ws, "dsm.tif")})], check=_auto_ok)


def _moved_photos(ws, tmp):
    """The workspace's photos copied to tmp/photos and the workspace pointed at them."""
    folder = os.path.join(tmp, "photos")
    os.makedirs(folder)
    path = os.path.join(ws, "workspace.json")
    doc = json.load(open(path))
    for im in doc["images"]:
        im["path"] = shutil.copy2(im["path"], os.path.join(folder, im["name"]))
    doc["images_dir"] = folder
    with open(path, "w") as fh:
        json.dump(doc, fh, indent=2)
    return folder


@case(13, "photos moved after the alignment (Build orthophoto)", r"(missing from|folder) \S*photos\b")
def photos_moved(ws, tmp):
    folder = _moved_photos(ws, tmp)
    os.rename(folder, folder + "_moved")
    return Spec([("buildorthophoto", {"WORKSPACE": ws, "OUTPUT": os.path.join(tmp, "o.tif")})],
                protected=[os.path.join(ws, "orthomosaic.tif")])


def _seamline_file(ws, tmp, driver, name, crs=True, lonlat=False):
    from osgeo import ogr, osr

    gdal, _ = _gdal()
    ds = gdal.Open(os.path.join(ws, "orthomosaic.tif"))
    gt = ds.GetGeoTransform()
    cx, cy = gt[0] + 0.5 * ds.RasterXSize * gt[1], gt[3] + 0.5 * ds.RasterYSize * gt[5]
    doc = json.load(open(os.path.join(ws, "workspace.json")))
    srs = osr.SpatialReference()
    srs.SetFromUserInput(doc["crs"])
    if lonlat:  # saved in EPSG:4326 and its .prj lost: numbers of another CRS
        from osgeo import osr as _osr

        ll = _osr.SpatialReference()
        ll.ImportFromEPSG(4326)
        ll.SetAxisMappingStrategy(_osr.OAMS_TRADITIONAL_GIS_ORDER)
        srs.SetAxisMappingStrategy(_osr.OAMS_TRADITIONAL_GIS_ORDER)
        cx, cy, _ = _osr.CoordinateTransformation(srs, ll).TransformPoint(cx, cy)
    half = 1e-4 if lonlat else 10.0
    path = os.path.join(tmp, "edits" + (".shp" if driver == "ESRI Shapefile" else ".gpkg"))
    out = ogr.GetDriverByName(driver).CreateDataSource(path)
    lyr = out.CreateLayer("edits", srs if crs else None, ogr.wkbPolygon)
    lyr.CreateField(ogr.FieldDefn("image", ogr.OFTString))
    f = ogr.Feature(lyr.GetLayerDefn())
    f.SetField("image", name)
    f.SetGeometry(ogr.CreateGeometryFromWkt(
        f"POLYGON(({cx - half} {cy - half},{cx + half} {cy - half},{cx + half} {cy + half},{cx - half} {cy + half},"
        f"{cx - half} {cy - half}))"))
    lyr.CreateFeature(f)
    out = None
    return path


def _first_photo(ws):
    return sorted(im["name"] for im in json.load(open(os.path.join(ws, "workspace.json")))["images"])[0]


@case(13, "seamlines shapefile saved in EPSG:4326, its .prj lost", r"(CRS is unknown|\.prj)")
def seamlines_no_prj(ws, tmp):
    shp = _seamline_file(ws, tmp, "ESRI Shapefile", _first_photo(ws), crs=False, lonlat=True)

    def check(out, _tmp):
        text = out.get("text", "")
        m = re.search(r"(\d+) polygon\(s\) name an image, (\d+) planning cells", text)
        return bool(m and int(m.group(2)) > 0), (m.group(0) if m else "no line on the seamlines edits in the log")
    return Spec([("buildorthophoto", {"WORKSPACE": ws, "OUTPUT": os.path.join(tmp, "o.tif"), "SEAMLINES_IN": shp})],
                protected=[shp], check=check)


@case(13, "seamlines naming a photo IMAGES_FILTER leaves out", r"IMAGES_FILTER .* leaves (it )?out")
def seamlines_filtered(ws, tmp):
    first = _first_photo(ws)
    gpkg = _seamline_file(ws, tmp, "GPKG", first)
    return Spec([("buildorthophoto", {"WORKSPACE": ws, "OUTPUT": os.path.join(tmp, "o.tif"), "SEAMLINES_IN": gpkg,
                                      "IMAGES_FILTER": f"!{first}"})], protected=[gpkg])


@case(13, "a read-only workspace (Build DTM as another user)", r"(not writable|read-only|Permission denied)")
def read_only(ws, tmp):
    for dirpath, _dirs, files in os.walk(tmp):
        os.chmod(dirpath, 0o555)
        for f in files:
            os.chmod(os.path.join(dirpath, f), 0o444)
    os.chmod(tmp, 0o755)
    return Spec([("builddtm", {"WORKSPACE": ws})], protected=[os.path.join(ws, "dtm.tif")], user="nobody")


@case(14, "Prepare images on a folder with a 0-byte photo and a text file named .jpg")
def prepare_unreadable(ws, tmp):
    folder = os.path.join(tmp, "photos")
    os.makedirs(folder)
    for im in json.load(open(os.path.join(ws, "workspace.json")))["images"][:6]:
        shutil.copy2(im["path"], folder)
    open(os.path.join(folder, "empty.jpg"), "wb").close()
    with open(os.path.join(folder, "notes.jpg"), "w") as fh:
        fh.write("not a photo")

    def check(out, _tmp):  # one rule with Align images: both skipped, each named once in a warning
        text = out.get("text", "")
        named = [n for n in ("empty.jpg", "notes.jpg") if n in text]
        return len(named) == 2, f"skipped and named: {', '.join(named) or 'neither'}"
    return Spec([("prepareimages", {"IMAGES": folder, "WORKSPACE": os.path.join(tmp, "new_ws"),
                                    "OUTPUT": os.path.join(tmp, "prepared")})], check=check)


@case(21, "an empty IMAGES folder", r"(no readable images|no images|holds no)")
def empty_images(ws, tmp):
    empty = os.path.join(tmp, "empty")
    os.makedirs(empty)
    new = os.path.join(tmp, "new_ws")

    def created(_out, _tmp):
        return not os.path.exists(new), ("a workspace was created" if os.path.exists(new) else "no workspace created")
    return Spec([("alignimages", {"IMAGES": empty, "WORKSPACE": new})], check=created, refused_check=created)


# ---------------------------------------------------------------------------
# running and classifying
# ---------------------------------------------------------------------------

def _fingerprint(path):
    if not os.path.exists(path):
        return None
    h = hashlib.sha1()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _env(repo, build):
    plugins = os.path.join(tempfile.gettempdir(), "bad-inputs-plugins", hashlib.sha1(repo.encode()).hexdigest()[:8])
    os.makedirs(plugins, exist_ok=True)
    link = os.path.join(plugins, "archaeoortho")
    if not os.path.islink(link):
        os.symlink(repo, link)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")])
    env["QGIS_PLUGINPATH"] = plugins
    env["QGIS_CUSTOM_CONFIG_PATH"] = os.path.join(build, "qgis-profile")
    env["QT_QPA_PLATFORM"] = "offscreen"
    return env


def _command(alg, params, user):
    cmd = [QGIS_PROCESS, "--json", "run", f"archaeoortho:{alg}", "--"] + [f"{k}={v}" for k, v in params.items()]
    if user:
        cmd = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"] + cmd
    return cmd


def _run(spec, env, cwd):
    procs, outs = [], []
    cmds = [_command(a, p, spec.user) for a, p in spec.runs]
    if spec.parallel:
        procs = [subprocess.Popen(c, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for c in cmds]
        outs = [(p.wait(), *p.communicate()) for p in procs]
    else:
        for c in cmds:
            p = subprocess.run(c, env=env, cwd=cwd, capture_output=True, text=True)
            outs.append((p.returncode, p.stdout, p.stderr))
    rc = max(o[0] for o in outs)
    text = "\n".join(o[1] + o[2] for o in outs)
    errors = [ln for o in outs for ln in o[2].splitlines() if ln.strip() and not ln.startswith(NOISE)]
    result = {}
    for o in outs:
        try:
            result = json.loads(o[1])
        except (json.JSONDecodeError, ValueError):
            pass
    log = result.get("log", {}) if isinstance(result, dict) else {}
    result = dict(result) if isinstance(result, dict) else {}
    result["text"] = text + "\n".join(log.get("info", []) if isinstance(log, dict) else [])
    result["errors"] = errors
    return rc, text, result


# what qgis_process prints on stderr whatever the algorithm does
NOISE = ("QStandardPaths", "<string>:", "Problem with SAGA", "Warning 1:", "ERROR 4:", "ERROR 1:")


def run_case(c, base, repo, build, keep):
    tmp = tempfile.mkdtemp(prefix=f"bad-{c['id']}-")
    os.chmod(tmp, 0o755)
    ws = os.path.join(tmp, "ws")
    shutil.copytree(base, ws, ignore=shutil.ignore_patterns("fused", "pairs-*", "database.db", "*.lock"))
    spec = c["make"](ws, tmp)
    before = {p: _fingerprint(p) for p in spec.protected}
    t0 = time.time()
    rc, text, result = _run(spec, _env(repo, build), tmp)
    seconds = time.time() - t0
    after = {p: _fingerprint(p) for p in spec.protected}
    changed = [os.path.basename(p) for p in spec.protected if before[p] != after[p]]
    note = ""
    if changed:
        cls, note = "lost data", f"changed: {', '.join(changed)}"
    elif "Traceback (most recent call last)" in text:
        cls, note = "traceback", [ln for ln in text.splitlines() if re.match(r"^\w*(Error|Exception)\b", ln)][-1:] or ""
        note = note[0] if note else ""
    elif rc != 0:  # the user's message: the error lines (QGIS prints each one more than once)
        errors = list(dict.fromkeys(result.get("errors") or []))
        cls = "clean" if c["expect"] and any(re.search(c["expect"], ln, re.I) for ln in errors) else "unclear"
        if c["expect"] is None:  # an input the run should take (skip, convert, reproject): refusing it is wrong
            cls = "refused"
        note = errors[-1][:300] if errors else "(no message)"
        if spec.refused_check is not None:
            ok, left = spec.refused_check(result, tmp)
            if not ok:
                cls, note = "unclean", f"{left}; {note}"
    elif spec.check is not None:
        try:
            ok, note = spec.check(result, tmp)
            cls = "ok" if ok else "silently wrong"
        except Exception as e:  # noqa: BLE001 - an output the check cannot read is a wrong output
            cls, note = "silently wrong", f"exit 0, but the output cannot be checked: {type(e).__name__}: {e}"
    else:
        cls = "ok" if c["expect"] is None else "silently wrong"
        note = "exit 0" if c["expect"] is None else "exit 0: the bad input was taken"
    for dirpath, _dirs, _files in os.walk(tmp):
        os.chmod(dirpath, 0o755)
    if not keep:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"id": c["id"], "item": c["item"], "name": c["name"], "class": cls, "note": str(note),
            "exit": rc, "seconds": round(seconds, 1)}


def run_all(repo, base, build, only, keep):
    rows = []
    for c in CASES:
        if only and c["id"] not in only:
            continue
        r = run_case(c, base, repo, build, keep)
        print(f"  [{os.path.basename(repo)}] item {r['item']:>2} {r['id']:<34} {r['class']:<15} {r['seconds']:6.1f} s  "
              f"{r['note'][:140]}", flush=True)
        rows.append(r)
    return rows


def table(before, after):
    b = {r["id"]: r for r in before}
    print("\n| item | case | before | after | after: what the user reads / the figures |")
    print("|---|---|---|---|---|")
    for r in after:
        prev = b.get(r["id"], {}).get("class", "–")
        print(f"| {r['item']} | {r['name']} | {prev} | {r['class']} | {r['note'][:160].replace('|', '/')} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workspace", default=os.path.join(ROOT, "build", "demo-workspace"))
    ap.add_argument("--repo", default=ROOT)
    ap.add_argument("--before", default=None, help="a checkout of the commit before the fixes")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--cases", default="")
    ap.add_argument("--json", default=None, help="write the rows here")
    ap.add_argument("--keep", action="store_true", help="keep each case's folder")
    a = ap.parse_args()
    if not os.path.isfile(os.path.join(a.workspace, "workspace.json")):
        sys.exit(f"{a.workspace} is no finished workspace: run 'make demo' first")
    only = {s for s in a.cases.split(",") if s}
    out = {}
    if a.before:
        print(f"before: {a.before}")
        out["before"] = run_all(os.path.abspath(a.before), a.workspace, a.build, only, a.keep)
    print(f"after: {a.repo}")
    out["after"] = run_all(os.path.abspath(a.repo), a.workspace, a.build, only, a.keep)
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=1)
    table(out.get("before", []), out["after"])


if __name__ == "__main__":
    main()
