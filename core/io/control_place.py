"""Does control land where the photos are?  Camera positions and ground control points compared with the photos'
own EXIF GPS (issue 47 items 2 and 12): the one check, made wherever a control file is read, each room raising its
own error with the message returned here:

* the georeference stage and the automatic control (``core.georef.control_checks.read_checked_control``), on the
  workspace's photos;
* Run pipeline before the alignment (``core.georef.control_checks.check_control_files``) and Align images given
  camera positions (``core.align.inputs``), on the photos' EXIF GPS read from the image files;
* Orthorectify image (``core.ortho.single``), on the one photo's EXIF GPS.

Control farther than ``FAR_FACTOR`` x (the GPS positions' spread + their error) from them is refused (thousands of
km for lat/lon in the wrong columns, hundreds for the wrong UTM zone); with one photo the spread is that of the
points compared (what the photo sees).  Without GPS, control outside the CRS's area of use is refused.  The message
names the likely cause: axes swapped, the coordinates of another CRS (tried: the UTM zone of the photos, EPSG:4326).
"""
from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.crs import CRSError, crs_is_geographic, transform_points, utm_epsg_for_lonlat
from .gcp import GroundPoint, read_camera_positions
from .images import EXIF_GPS_SIGMA_XY

FAR_FACTOR = 20.0  # control farther than this many times (the GPS positions' spread + their error): refused
AREA_MARGIN = 0.5  # a CRS's area of use is widened by this share of its size (at least 1 degree) on each side

Gps = Sequence[Tuple[str, float, float]]  # (photo name, lon, lat) of the photos with EXIF GPS


def usable_gps(rows) -> List[Tuple[str, float, float]]:
    """(name, lon, lat) of ``rows`` ((name, gps or None) with gps (lon, lat[, alt])) whose GPS is finite."""
    return [(n, float(g[0]), float(g[1])) for n, g in rows
            if g and all(math.isfinite(float(v)) for v in g[:2])]


def photos_utm(gps: Gps) -> Optional[str]:
    """The WGS 84 / UTM zone of the photos' EXIF GPS (their mean), e.g. 'EPSG:32617'; None without GPS."""
    if not gps:
        return None
    return f"EPSG:{utm_epsg_for_lonlat(float(np.mean([g[1] for g in gps])), float(np.mean([g[2] for g in gps])))}"


def _to(xy: np.ndarray, src: str, dst: str) -> np.ndarray:
    """``xy`` (N,2) from ``src`` into ``dst``; rows that cannot be transformed are inf."""
    if src == dst:
        return np.asarray(xy, dtype=float)
    try:
        return transform_points(xy, src, dst)
    except CRSError:
        pass  # some point outside the CRS's domain: one by one below
    out = np.full(xy.shape, np.inf)
    for k, p in enumerate(xy):
        try:
            out[k] = transform_points(p[None], src, dst)[0]
        except CRSError:
            pass  # outside the CRS's domain: infinitely far
    return out


def _area_of_use(crs: str) -> Optional[Tuple[float, float, float, float]]:
    """(west, south, east, north) in degrees of where ``crs`` is meant to be used; None when unknown or global."""
    try:
        from osgeo import osr
    except ImportError:  # pragma: no cover - GDAL is a dependency of the plugin
        return None
    srs = osr.SpatialReference()
    if srs.SetFromUserInput(crs) != 0:
        return None
    a = srs.GetAreaOfUse()
    if a is None or a.west_lon_degree < -1000:
        return None
    box = (a.west_lon_degree, a.south_lat_degree, a.east_lon_degree, a.north_lat_degree)
    if box[2] - box[0] >= 359.0 and box[3] - box[1] >= 179.0:
        return None
    return box


def _in_area(lonlat: np.ndarray, box: Tuple[float, float, float, float]) -> np.ndarray:
    w, s, e, n = box
    mx, my = max(1.0, AREA_MARGIN * (e - w)), max(1.0, AREA_MARGIN * (n - s))
    return ((lonlat[:, 0] >= w - mx) & (lonlat[:, 0] <= e + mx) & (lonlat[:, 1] >= s - my) & (lonlat[:, 1] <= n + my))


def _km(m: float) -> str:
    if not math.isfinite(m):
        return "infinitely far (outside the CRS's domain)"
    return f"{m / 1000.0:,.0f} km" if m >= 10000.0 else f"{m:,.0f} m"


def _spread(xy: np.ndarray) -> float:
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    return float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]))) if len(xy) else 0.0


class Place:
    """Where the photos are (their EXIF GPS in ``target``, a metric CRS) and how far control may be from them."""

    def __init__(self, gps: Gps, target: str):
        self.target = target
        gps = list(gps)
        self.xy = np.zeros((0, 2))
        if gps:
            try:
                self.xy = transform_points(np.array([[g[1], g[2]] for g in gps]), "EPSG:4326", target)
            except CRSError:  # a local or engineering CRS: no way from the GPS into it, nothing to compare
                gps = []
        self.names = [g[0] for g in gps]
        self.spread = _spread(self.xy) if len(self.xy) else math.nan
        self.area = _area_of_use(target)

    def distance(self, xy: np.ndarray, images: Optional[Sequence[str]] = None) -> np.ndarray:
        """Horizontal distance of each point from the photo of the same name (``images``), else from the box of the
        photos' GPS positions."""
        d = np.full(len(xy), np.inf)
        own = {n: k for k, n in enumerate(self.names)}
        lo, hi = self.xy.min(axis=0), self.xy.max(axis=0)
        for k, p in enumerate(xy):
            if not np.all(np.isfinite(p)):
                continue
            j = own.get(images[k]) if images is not None else None
            if j is not None:
                d[k] = float(np.hypot(*(p - self.xy[j])))
            else:
                d[k] = float(np.hypot(*np.maximum(0.0, np.maximum(lo - p, p - hi))))
        return d

    def _near_gps(self, xy: np.ndarray, images: Optional[Sequence[str]], noun: str) -> str:
        """'' when the points (the median one) land where the photos' GPS is, else how far off they are.  With one
        photo, the points' own spread (what the photo sees) stands for the photos' spread."""
        one = len(self.xy) == 1
        spread = _spread(xy) if one else self.spread
        limit = FAR_FACTOR * (spread + EXIF_GPS_SIGMA_XY)
        d = self.distance(xy, images)
        med = float(np.median(d))
        if med <= limit:
            return ""
        if one:
            return (f"land {_km(med)} from the photo's EXIF GPS (median over {len(d)} {noun}; they span "
                    f"{spread:,.0f} m, so more than {_km(limit)} is neither a GPS error nor what the photo sees)")
        how = "from the same photos' EXIF GPS" if images is not None else "from the photos' EXIF GPS positions"
        return (f"land {_km(med)} {how} (median over {len(d)} {noun}; the photos' GPS positions span "
                f"{self.spread:,.0f} m, so more than {_km(limit)} is not a GPS error)")

    def far(self, xy: np.ndarray, images: Optional[Sequence[str]] = None, noun: str = "points") -> Optional[str]:
        """'' when the points (the median one) land where the photos are, else what is wrong (with GPS: how far
        from it; without: outside the target CRS's area of use); None when nothing can be said."""
        if len(self.xy):
            return self._near_gps(xy, images, noun)
        if self.area is None:
            return None
        lonlat = _to(xy, self.target, "EPSG:4326")
        inside = _in_area(lonlat, self.area)
        if 2 * int(inside.sum()) >= len(inside):
            return ""
        w, s, e, n = self.area
        k = int(np.argmin(inside))
        where = (f"lon {lonlat[k, 0]:.3f}, lat {lonlat[k, 1]:.3f}" if np.all(np.isfinite(lonlat[k]))
                 else "outside its domain")
        return (f"lie outside the area where {self.target} is used (lon {w:g} to {e:g}, lat {s:g} to {n:g}): "
                f"e.g. at {where}")

    def near(self, xy: np.ndarray, src: str, images: Optional[Sequence[str]]) -> bool:
        """Whether ``xy`` in ``src`` would land where the photos are."""
        try:
            t = _to(xy, src, self.target)
        except CRSError:
            return False
        return self.far(t, images) == ""  # noqa: PLC1901 - '' (near) and None (cannot tell) differ


def _cause(place: Place, raw: np.ndarray, src: str, images: Optional[Sequence[str]], utm: Optional[str],
           labelled: bool) -> str:
    """The likely cause of control that lands far off, tried on its raw coordinates ``raw`` in ``src``: axes
    swapped, the numbers of the photos' UTM zone or of EPSG:4326 under another CRS."""
    where = "the file's CRS line says" if labelled else "read in"
    geographic = crs_is_geographic(src)
    if place.near(raw[:, ::-1], src, images):
        if geographic:
            return ("latitude and longitude look swapped: x must be the longitude (east), y the latitude (north); "
                    "swap the columns")
        return "x and y look swapped: x must be the easting, y the northing; swap the columns"
    if utm and utm != src and place.near(raw, utm, images):
        return (f"the numbers are {utm} coordinates (the UTM zone of the photos' GPS) but {where} {src}: wrong CRS; "
                f"give {utm}" + (" as the file's CRS line" if labelled else " (its CRS line, or CRS=" + utm + ")"))
    if not geographic and src != "EPSG:4326":
        for cand in ("EPSG:4326",):
            if place.near(raw, cand, images):
                return (f"the numbers are longitude/latitude degrees ({cand}) but {where} {src}: wrong CRS; "
                        f"give {cand} as the file's CRS line")
            if place.near(raw[:, ::-1], cand, images):
                return (f"the numbers are latitude/longitude degrees, latitude first, but {where} {src}: give "
                        f"{cand} as the file's CRS line and put the longitude in x")
    if len(place.xy) == 1:
        return (f"check the coordinates and their CRS ({src}); if they are right, the photo's EXIF GPS is what is "
                "wrong: remove its GPS tags (e.g. exiftool -gps:all= on a copy), it is used only for this check")
    return (f"check the coordinates and their CRS ({src}); if they are right, the photos' EXIF GPS is what is wrong: "
            "georeference without it (camera positions or GCPs only are used, the GPS only for this check)")


def _place(gps: Gps, target: str) -> Optional[Place]:
    """The photos' place measured in ``target``, or in the photos' UTM zone when ``target`` is geographic (the
    caller refuses a geographic target itself); None when nothing can be compared."""
    if crs_is_geographic(target):
        utm = photos_utm(gps)
        return Place(gps, utm) if utm else None
    return Place(gps, target)


def positions_off(gps: Gps, path: str, target: str) -> Optional[str]:
    """What is wrong with the camera positions of the file ``path`` (read in ``target`` where it has no CRS line):
    they land far from the same photos' EXIF GPS (without GPS: outside the target CRS's area of use), with the
    likely cause; None when they land there or nothing can be said."""
    file_crs, rows = read_camera_positions(path, warnings=[])
    place = _place(gps, target)
    if not rows or place is None:
        return None
    src = file_crs or target
    raw = np.array([[c.x, c.y] for c in rows], dtype=float)
    images = [c.image for c in rows]
    what = place.far(_to(raw, src, place.target), images, "photos")
    if not what:
        return None
    return f"the camera positions in {path} ({src}) {what}: {_cause(place, raw, src, images, photos_utm(gps), bool(file_crs))}"


def points_off(gps: Gps, points: Sequence[GroundPoint], src: str, target: str, name: str,
               labelled: bool) -> Optional[str]:
    """What is wrong with the control ``points`` (their coordinates in ``src``, ``labelled``: the CRS their file
    names, not the CRS parameter) of ``name`` (the GCP file, the GCP layer) used in ``target``: they land far from
    the photos' EXIF GPS (without GPS: outside the target CRS's area of use), with the likely cause; None when
    they land there or nothing can be said."""
    place = _place(gps, target)
    if not points or place is None:
        return None
    raw = np.array([[p.x, p.y] for p in points], dtype=float)
    what = place.far(_to(raw, src, place.target))
    if not what:
        return None
    return f"the control points of {name} ({src}) {what}: {_cause(place, raw, src, None, photos_utm(gps), labelled)}"


__all__ = ["AREA_MARGIN", "FAR_FACTOR", "Gps", "Place", "photos_utm", "points_off", "positions_off", "usable_gps"]
