"""Issue 47, group "positions" (items 2, 6, 11, 12, 17): camera-position and GCP files whose numbers are valid but
whose meaning is not (swapped axes, a wrong CRS, a geographic target CRS, a sigma the solver cannot hold, a
spreadsheet's ``;`` and decimal commas, duplicate rows), re-made from the demo workspace and run through
``qgis_process`` (see ``benchmarks/bad_inputs_r3.py``)."""
import json
import os

import numpy as np
from bad_inputs import Spec, case

UTM = "EPSG:32617"  # the demo's CRS (Toledo, Ohio)


def _images(ws):
    return json.load(open(os.path.join(ws, "workspace.json")))["images"]


def _utm_positions(ws, srs=None):
    """{image: (x, y, z)} of the demo's photos in EPSG:32617 (or ``srs``, an osr.SpatialReference), from their
    EXIF GPS."""
    from osgeo import osr

    ll, utm = osr.SpatialReference(), srs.Clone() if srs is not None else osr.SpatialReference()
    ll.ImportFromEPSG(4326)
    if srs is None:
        utm.ImportFromEPSG(32617)
    for s in (ll, utm):
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ct = osr.CoordinateTransformation(ll, utm)
    out = {}
    for im in _images(ws):
        lon, lat, alt = im["gps"]
        x, y, _ = ct.TransformPoint(lon, lat, 0.0)
        out[im["name"]] = (x, y, alt)
    return out


def _write(path, lines):
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def _camera_offsets(ws):
    """Median horizontal distance (m) of the georeferenced cameras from the photos' EXIF GPS."""
    from osgeo import ogr

    ds = ogr.Open(os.path.join(ws, "cameras.gpkg"))
    gps = _utm_positions(ws, ds.GetLayer(0).GetSpatialRef())  # the photos' GPS in the CRS the block was put in
    d = [np.hypot(f.GetGeometryRef().GetX() - gps[f.GetField("image")][0],
                  f.GetGeometryRef().GetY() - gps[f.GetField("image")][1])
         for f in ds.GetLayer(0) if f.GetField("image") in gps]
    return float(np.median(d)) if d else float("nan")


def _placed_near_gps(out, tmp):
    ws = os.path.join(tmp, "ws")
    off = _camera_offsets(ws)
    return off < 50.0, f"exit 0; cameras {off:,.0f} m from the photos' EXIF GPS (median)"


def _georef(ws, **params):
    return ("georeference", dict({"WORKSPACE": ws}, **params))


def _latlon_swapped(ws, tmp):
    """A camera-positions file in EPSG:4326 from the photos' own GPS with latitude in the x column."""
    rows = ["EPSG:4326", "image,x,y,z"] + [f"{im['name']},{im['gps'][1]:.8f},{im['gps'][0]:.8f},{im['gps'][2]}"
                                           for im in _images(ws)]
    return _write(os.path.join(tmp, "positions_latlon.csv"), rows)


# ---------------------------------------------------------------------------
# item 2: positions far from the photos' GPS (swapped axes, a wrong CRS)
# ---------------------------------------------------------------------------

@case(2, "camera positions in EPSG:4326 with the latitude in the x column",
      r"camera positions .*(swapped|latitude)")
def positions_latlon_swapped(ws, tmp):
    p = _latlon_swapped(ws, tmp)
    return Spec([_georef(ws, CAMERA_POSITIONS=p)], protected=[p], check=_placed_near_gps)


@case(2, "camera positions of UTM zone 17N labelled EPSG:32618 (the next zone)",
      r"camera positions .*(EPSG:32617|CRS)")
def positions_wrong_zone(ws, tmp):
    rows = ["EPSG:32618"] + [f"{n},{x:.3f},{y:.3f},{z}" for n, (x, y, z) in _utm_positions(ws).items()]
    p = _write(os.path.join(tmp, "positions_zone18.csv"), rows)
    return Spec([_georef(ws, CAMERA_POSITIONS=p)], protected=[p], check=_placed_near_gps)


def _model_gcps(ws, tmp, sigma=None, n=5, crs_line=UTM):
    """A CSV GCP pair made from the georeferenced demo model: ``n`` well-seen tie points spread over the block,
    their world coordinates and their observations (stored pixel grid); ``sigma`` in sigma_xy / sigma_z."""
    import pycolmap

    rec = pycolmap.Reconstruction(os.path.join(ws, "georef", "model"))
    off = np.asarray(json.load(open(os.path.join(ws, "georef", "transform.json")))["offset"], dtype=float)
    pts = [(pid, p) for pid, p in rec.points3D.items() if p.track.length() >= 5 and p.error < 0.8]
    xyz = np.array([p.xyz for _, p in pts])
    c = xyz.mean(axis=0)
    chosen = [int(np.argmin(np.linalg.norm(xyz[:, :2] - c[:2], axis=1)))]
    while len(chosen) < n:  # farthest-point spread
        d = np.min([np.linalg.norm(xyz[:, :2] - xyz[k, :2], axis=1) for k in chosen], axis=0)
        chosen.append(int(np.argmax(d)))
    head = "name,x,y,z" + (",sigma_xy,sigma_z" if sigma is not None else "")
    prow, orow = ([f"# crs: {crs_line}"] if crs_line else []) + [head], ["name,image,px,py"]
    for k, idx in enumerate(chosen):
        pid, p = pts[idx]
        w = p.xyz + off
        prow.append(f"P{k + 1},{w[0]:.4f},{w[1]:.4f},{w[2]:.4f}" + (f",{sigma},{sigma}" if sigma is not None else ""))
        for el in p.track.elements:
            im = rec.image(el.image_id)
            xy = im.points2D[el.point2D_idx].xy
            orow.append(f"P{k + 1},{im.name},{xy[0]:.3f},{xy[1]:.3f}")
    path = _write(os.path.join(tmp, "gcps.csv"), prow)
    _write(os.path.join(tmp, "gcps_observations.csv"), orow)
    return path


@case(2, "GCPs of UTM zone 17N labelled EPSG:32618 (the next zone)", r"(GCP|control).*(EPSG:32617|CRS)")
def gcps_wrong_zone(ws, tmp):
    p = _model_gcps(ws, tmp, crs_line="EPSG:32618")
    return Spec([_georef(ws, GCPS=p)], protected=[p], check=_placed_near_gps)


# ---------------------------------------------------------------------------
# item 6: a sigma below what the solver can hold
# ---------------------------------------------------------------------------

@case(6, "GCPs (exact: tie points of the block itself) with sigma 1e-9 m")
def gcps_nano_sigma(ws, tmp):
    p = _model_gcps(ws, tmp, sigma="1e-9")

    def check(out, _tmp):  # honoured: residuals at the image noise (2 mm with any sane sigma), and said so
        res = out.get("results", {})
        rms = max(float(res.get("GCP_RMSE_XY") or "inf"), float(res.get("GCP_RMSE_Z") or "inf"))
        said = "held fixed" in out.get("text", "")
        return rms < 0.005 and said, (f"exit 0: GCP RMSE XY {float(res.get('GCP_RMSE_XY') or 'nan'):.3f} Z "
                                      f"{float(res.get('GCP_RMSE_Z') or 'nan'):.3f} m (sigma 0.01 m: 0.002 / 0.002); "
                                      f"{'held fixed: said' if said else 'nothing said'}")
    return Spec([_georef(ws, GCPS=p)], protected=[p], check=check)


# ---------------------------------------------------------------------------
# item 11: a spreadsheet's ';' and decimal commas
# ---------------------------------------------------------------------------

@case(11, "camera positions with ';' separators and decimal commas")
def positions_semicolon_decimal_comma(ws, tmp):
    rows = [UTM, "image;x;y;z"] + [f"{n};{x:.3f};{y:.3f};{z}".replace(".", ",").replace(",JPG", ".JPG")
                                   for n, (x, y, z) in _utm_positions(ws).items()]
    p = _write(os.path.join(tmp, "positions_excel.csv"), rows)

    def check(out, _tmp):
        ok, note = _placed_near_gps(out, _tmp)
        used = json.load(open(os.path.join(ws, "workspace.json")))["stages"]["georeference"]["parameters"]
        return ok and used.get("camera_positions") == p, note
    return Spec([_georef(ws, CAMERA_POSITIONS=p)], protected=[p], check=check)


# ---------------------------------------------------------------------------
# item 12: a geographic target CRS, metres under CRS=EPSG:4326
# ---------------------------------------------------------------------------

@case(12, "camera positions in EPSG:4326 with CRS=EPSG:4326", r"CRS=EPSG:32617")
def positions_geographic_target(ws, tmp):
    rows = ["EPSG:4326"] + [f"{im['name']},{im['gps'][0]:.8f},{im['gps'][1]:.8f},{im['gps'][2]}" for im in _images(ws)]
    p = _write(os.path.join(tmp, "positions_4326.csv"), rows)
    return Spec([_georef(ws, CAMERA_POSITIONS=p, CRS="EPSG:4326")], protected=[p], check=_placed_near_gps)


@case(12, "camera positions in UTM metres, no CRS line, CRS=EPSG:4326",
      r"^(?=.*CRS=EPSG:32617)(?=.*camera positions in \S+ have no CRS line)")
def positions_utm_under_4326(ws, tmp):
    rows = [f"{n},{x:.3f},{y:.3f},{z}" for n, (x, y, z) in _utm_positions(ws).items()]
    p = _write(os.path.join(tmp, "positions_nocrs.csv"), rows)
    return Spec([_georef(ws, CAMERA_POSITIONS=p, CRS="EPSG:4326")], protected=[p], check=_placed_near_gps)


@case(12, "GCPs in UTM metres, no CRS line, CRS=EPSG:4326", r"CRS=EPSG:32617")
def gcps_utm_under_4326(ws, tmp):
    p = _model_gcps(ws, tmp, crs_line=None)
    return Spec([_georef(ws, GCPS=p, CRS="EPSG:4326")], protected=[p], check=_placed_near_gps)


# ---------------------------------------------------------------------------
# item 17: duplicate rows
# ---------------------------------------------------------------------------

def _duplicated(ws, tmp, shift):
    pos = _utm_positions(ws)
    first = sorted(pos)[0]
    rows = [UTM, "image,x,y,z,sigma"] + [f"{n},{x:.3f},{y:.3f},{z},5" for n, (x, y, z) in pos.items()]
    x, y, z = pos[first]
    rows.append(f"{first},{x + shift:.3f},{y:.3f},{z},5")
    return first, _write(os.path.join(tmp, "positions_dup.csv"), rows)


@case(17, "camera positions with a photo's row twice (the same values)")
def positions_duplicate_same(ws, tmp):
    first, p = _duplicated(ws, tmp, 0.0)

    def check(out, _tmp):
        ok, note = _placed_near_gps(out, _tmp)
        text = out.get("text", "")
        warned = any(first in ln and "line" in ln for ln in text.splitlines())
        return ok and warned, f"{note}; duplicate {'named' if warned else 'not named'} in the log"
    return Spec([_georef(ws, CAMERA_POSITIONS=p)], protected=[p], check=check)


@case(17, "camera positions with a photo's row twice, 200 m apart (sigma 5 m)",
      r"1JI_0064\.JPG.*lines? \d+ and \d+")
def positions_duplicate_disagree(ws, tmp):
    _first, p = _duplicated(ws, tmp, 200.0)
    return Spec([_georef(ws, CAMERA_POSITIONS=p)], protected=[p])  # exit 0: one of two rows taken unsaid
