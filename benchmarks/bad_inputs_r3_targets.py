"""Issue 47's "targets" group (items 5, 7, 15, 16): Find targets given targets whose meaning is wrong, and Stack
multispectral captures given a folder that is not only the rig's, re-made and run through ``qgis_process`` by
``benchmarks/bad_inputs_r3.py``.

Find targets on the demo workspace (Toledo: no targets on the photos, but EXIF GPS to check coordinates against):
degrees under a UTM CRS, a lat/lon CSV of another place under ``CRS=EPSG:4326``, a header-only file, targets
3,000 km off (item 15).  On COPR (``../shared/data/copr``: cross targets, no GPS; the block aligned once into
``build/bench-find-targets/copr``, as ``benchmarks/find_targets.py`` does, and reused): two of its targets (item 7:
the marks tied there are three or more), the checkerboard detector on cross targets (item 5), a kind the photos do
not show, a target size ten times too large (item 15), and the right inputs, which must still find the hand file's
observations.  Stack multispectral captures on the Sequoia's bands with three DJI JPEGs beside them, and with a
panel sheet holding ``Red,abc`` (item 16).
"""
import glob
import json
import math
import os
import shutil

from bad_inputs import ROOT, Spec, case

DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
COPR_WS = os.path.join(ROOT, "build", "bench-find-targets", "copr")
COPR_HAND = os.path.join(DATA, "copr", "gcp_list.txt")
UTM = "EPSG:32617"  # the demo's CRS (Toledo, Ohio)


def _write(path, lines):
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def _gps_utm(ws, n=6):
    """[(lon, lat, x, y)] of the first ``n`` photos' EXIF GPS, x and y in the demo's UTM zone."""
    from osgeo import osr

    ll, utm = osr.SpatialReference(), osr.SpatialReference()
    ll.ImportFromEPSG(4326)
    utm.ImportFromEPSG(32617)
    for s in (ll, utm):
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ct = osr.CoordinateTransformation(ll, utm)
    out = []
    for im in json.load(open(os.path.join(ws, "workspace.json")))["images"][:n]:
        lon, lat = im["gps"][:2]
        x, y, _ = ct.TransformPoint(lon, lat, 0.0)
        out.append((lon, lat, x, y))
    return out


def _find(ws, targets, **params):
    return ("findtargets", dict({"WORKSPACE": ws, "TARGETS": targets}, **params))


# ---------------------------------------------------------------------------
# item 7: two targets
# ---------------------------------------------------------------------------

@case(7, "findtargets on COPR with two of its targets (a constellation needs three)",
      r"holds 2 target\(s\).*three or more")
def targets_two(ws, tmp):
    p = _copr(ws, tmp)
    lines = open(p).read().splitlines()
    two = _write(os.path.join(tmp, "two_targets.txt"), lines[:3])
    return Spec([_find(ws, two, GCPS=os.path.join(tmp, "found.txt"))], protected=[two])


# ---------------------------------------------------------------------------
# item 15: coordinates that are not where the photos are, a file without targets
# ---------------------------------------------------------------------------

@case(15, "findtargets: longitude/latitude numbers under '# crs: EPSG:32617'", r"look like degrees")
def targets_degrees_under_utm(ws, tmp):
    rows = [f"t{k},{lon:.8f},{lat:.8f},180" for k, (lon, lat, _, _) in enumerate(_gps_utm(ws))]
    p = _write(os.path.join(tmp, "degrees_under_utm.csv"), [f"# crs: {UTM}", "name,x,y,z"] + rows)
    return Spec([_find(ws, p)], protected=[p])


def _copr_lonlat():
    """COPR's targets (Santa Barbara, California) as (name, lon, lat)."""
    from osgeo import osr

    src, ll = osr.SpatialReference(), osr.SpatialReference()
    src.ImportFromEPSG(32611)
    ll.ImportFromEPSG(4326)
    for s in (src, ll):
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ct = osr.CoordinateTransformation(src, ll)
    seen = {}
    for line in open(COPR_HAND):
        t = line.split()
        if len(t) >= 7 and t[6] not in seen:
            lon, lat, _ = ct.TransformPoint(float(t[0]), float(t[1]), 0.0)
            seen[t[6]] = (t[6], lon, lat)
    return list(seen.values())


@case(15, "findtargets: a lon/lat CSV of another place (California) with CRS=EPSG:4326",
      r"targets.*land [\d,]+ km from the photos")
def targets_lonlat_elsewhere(ws, tmp):
    rows = [f"{n},{lon:.8f},{lat:.8f},0" for n, lon, lat in _copr_lonlat()]
    p = _write(os.path.join(tmp, "copr_lonlat.csv"), ["name,x,y,z"] + rows)
    return Spec([_find(ws, p, CRS="EPSG:4326")], protected=[p])


@case(15, "findtargets: a targets CSV with its header and no row", r"holds no target")
def targets_header_only(ws, tmp):
    p = _write(os.path.join(tmp, "header_only.csv"), [f"# crs: {UTM}", "name,x,y,z"])
    return Spec([_find(ws, p)], protected=[p])


@case(15, "findtargets: targets 3,000 km east of the photos", r"targets.*land [\d,]+ km from the photos")
def targets_far(ws, tmp):
    rows = [f"t{k},{x + 3.0e6:.3f},{y:.3f},180" for k, (_, _, x, y) in enumerate(_gps_utm(ws))]
    p = _write(os.path.join(tmp, "far.csv"), [f"# crs: {UTM}", "name,x,y,z"] + rows)
    return Spec([_find(ws, p)], protected=[p])


# ---------------------------------------------------------------------------
# COPR: cross targets (items 5 and 15)
# ---------------------------------------------------------------------------

def _copr(ws, tmp):
    """The demo copy ``ws`` replaced by the aligned COPR block (aligned once, then reused); the targets file: the
    hand gcp_list.txt reduced to its coordinates."""
    if not os.path.isfile(os.path.join(COPR_WS, "workspace.json")):
        import find_targets

        find_targets.ensure_aligned(os.path.join(DATA, "copr", "images"), COPR_WS)
    shutil.rmtree(ws)
    shutil.copytree(COPR_WS, ws, ignore=shutil.ignore_patterns("*.lock", "georef"))
    lines = [ln for ln in open(COPR_HAND) if ln.strip()]
    seen = {}
    for ln in lines[1:]:
        t = ln.split()
        seen.setdefault(t[6], f"{t[0]} {t[1]} {t[2]} {t[6]}")
    return _write(os.path.join(tmp, "copr_targets.txt"), [lines[0].strip()] + list(seen.values()))


def _against_hand(out, _tmp):
    """(ok, note) on exit 0: the observations written against the hand file's (same photo): within 1.5 px of the
    same target's click, of another target's, or of none."""
    from osgeo import ogr  # noqa: F401 - GDAL's Python, as the other checks

    path = out.get("results", {}).get("GCPS")
    hand = {}
    for ln in open(COPR_HAND).read().splitlines()[1:]:
        t = ln.split()
        if len(t) >= 7:
            hand.setdefault(t[5], []).append((float(t[3]), float(t[4]), t[6]))
    rows = [ln.split() for ln in open(path).read().splitlines()[1:] if ln.strip() and not ln.startswith("#")]
    right = wrong = unknown = 0
    for t in rows:
        x, y, im, name = float(t[3]), float(t[4]), t[5], t[6]
        near = [n for hx, hy, n in hand.get(im, []) if math.hypot(x - hx, y - hy) <= 1.5]
        if name in near:
            right += 1
        elif near:
            wrong += 1
        elif any(n == name for _, _, n in hand.get(im, [])):
            wrong += 1  # the hand file has this target elsewhere in that photo
        else:
            unknown += 1
    return (wrong == 0 and right >= 20), (f"{len(rows)} observations: {right} at the hand file's click of the same "
                                          f"target, {wrong} off it or at another target's, {unknown} the hand file "
                                          "does not have")


@case(5, "findtargets TARGET_KIND=checkerboard on COPR's cross targets", r"no target found.*TARGET_KIND=cross")
def copr_checkerboard_on_crosses(ws, tmp):
    p = _copr(ws, tmp)
    return Spec([_find(ws, p, TARGET_KIND=2, GCPS=os.path.join(tmp, "found.txt"))], protected=[p],
                check=_against_hand)


@case(15, "findtargets TARGET_KIND=circle on COPR's cross targets", r"no target found.*TARGET_KIND=cross")
def copr_circle_on_crosses(ws, tmp):
    p = _copr(ws, tmp)
    return Spec([_find(ws, p, TARGET_KIND=3, GCPS=os.path.join(tmp, "found.txt"))], protected=[p],
                check=_against_hand)


@case(15, "findtargets TARGET_SIZE=5 (m) on COPR's targets (about 0.5 m)",
      r"measure 0\.\d+ m on the ground.*TARGET_SIZE 5 m")
def copr_target_size_off(ws, tmp):
    p = _copr(ws, tmp)
    return Spec([_find(ws, p, TARGET_SIZE=5, GCPS=os.path.join(tmp, "found.txt"))], protected=[p],
                check=_against_hand)


@case(15, "findtargets on COPR with the right inputs (must run: the hand file's observations found)")
def copr_right(ws, tmp):
    p = _copr(ws, tmp)
    return Spec([_find(ws, p, GCPS=os.path.join(tmp, "found.txt"))], protected=[p], check=_against_hand)


# ---------------------------------------------------------------------------
# item 16: Stack multispectral captures
# ---------------------------------------------------------------------------

def _sequoia_bands(folder):
    os.makedirs(folder, exist_ok=True)
    for f in glob.glob(os.path.join(DATA, "sequoia_sample", "*.TIF")):
        shutil.copy(f, folder)
    return folder


@case(16, "stackcaptures on a folder of Sequoia bands and three DJI JPEGs (must run, naming the JPEGs)")
def stack_mixed_folder(ws, tmp):
    folder = _sequoia_bands(os.path.join(tmp, "bands"))
    jpegs = sorted(glob.glob(os.path.join(ROOT, "sample", "toledo", "images", "*.JPG")))[:3]
    for j in jpegs:
        shutil.copy(j, folder)
    names = [os.path.basename(j) for j in jpegs]

    def check(out, _tmp):
        text = out.get("text", "")
        photos = out.get("results", {}).get("PHOTOS")
        named = all(n in text for n in names) and "3 file(s) are not band files" in text
        lacks = "lacks RGB" in text
        return (named and not lacks and photos == 1), (f"PHOTOS {photos}; the JPEGs named: {named}; a capture said "
                                                       f"to lack RGB: {lacks}")
    return Spec([("stackcaptures", {"INPUT": folder, "OUTPUT": os.path.join(tmp, "stacked")})], check=check)


@case(16, "stackcaptures with a panel sheet holding the row 'Red,abc'", r"panel\.csv:3: .*Red, 'abc'")
def stack_panel_bad_row(ws, tmp):
    folder = _sequoia_bands(os.path.join(tmp, "bands"))
    panel = _sequoia_bands(os.path.join(tmp, "panel"))
    sheet = _write(os.path.join(tmp, "panel.csv"), ["band,reflectance", "Green,0.49", "Red,abc", "Red edge,0.50",
                                                    "NIR,0.49"])
    return Spec([("stackcaptures", {"INPUT": folder, "OUTPUT": os.path.join(tmp, "stacked"), "PANEL": panel,
                                    "PANEL_REFLECTANCE": sheet})], protected=[sheet])
