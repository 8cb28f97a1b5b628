"""Does the ground control mean what it says?  The checks a surveyor makes by eye before trusting control
(issue 47 items 2 and 12), run by the georeference stage around ``read_control``, before the adjustment:

:func:`read_checked_control` is ``read_control`` with these checks around it, and the readers' warnings put in the
stage's log:

* :func:`check_crs_parameter` (before reading): a geographic CRS parameter (``CRS=EPSG:4326``) is refused at
  once, naming the UTM zone of the photos' EXIF GPS that fixes it (the adjustment needs metres; GCPs and camera
  positions in degrees are reprojected into it); files without a CRS line whose numbers are metres are named.
* :func:`check_target_crs` (after reading): a target CRS that came out geographic because a GCP or camera
  position file is in degrees and no CRS was given: the same advice, naming the file.
* :func:`check_control_location`: control that lands far from where the photos' own EXIF GPS puts them
  (``FAR_FACTOR`` x the GPS positions' spread plus their error: thousands of km for lat/lon in the wrong columns,
  hundreds for the wrong UTM zone), or, without GPS, outside the target CRS's area of use, is refused naming the
  likely cause: axes swapped, the coordinates of another CRS (tried: the UTM zone of the photos, EPSG:4326).
"""
from __future__ import annotations

import math
import warnings
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Progress
from ..geometry.crs import CRSError, crs_is_geographic, transform_points, utm_epsg_for_lonlat
from ..io import gcp as gcpmod
from ..project.stages import StageError
from ..project.workspace import Workspace
from .control_input import read_control
from .options import EXIF_SIGMA_XY, GeorefOptions

FAR_FACTOR = 20.0  # control farther than this many times (the GPS positions' spread + their error): refused
AREA_MARGIN = 0.5  # a CRS's area of use is widened by this share of its size (at least 1 degree) on each side


def _gps(ws: Workspace) -> List[Tuple[str, float, float]]:
    """(image, lon, lat) of the workspace's photos with EXIF GPS."""
    return [(im["name"], float(im["gps"][0]), float(im["gps"][1])) for im in ws.data.get("images", [])
            if im.get("gps") and all(math.isfinite(float(v)) for v in im["gps"][:2])]


def photos_utm(ws: Workspace) -> Optional[str]:
    """The WGS 84 / UTM zone of the photos' EXIF GPS (their mean), e.g. 'EPSG:32617'; None without GPS."""
    gps = _gps(ws)
    if not gps:
        return None
    return f"EPSG:{utm_epsg_for_lonlat(float(np.mean([g[1] for g in gps])), float(np.mean([g[2] for g in gps])))}"


def _projected_advice(ws: Workspace) -> str:
    utm = photos_utm(ws)
    if utm:
        return f"CRS={utm} (the UTM zone of the photos' EXIF GPS)"
    return "CRS=<a projected CRS in metres>, e.g. the block's UTM zone (EPSG:326zz north, EPSG:327zz south)"


def _degree_like(xy: np.ndarray) -> bool:
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    return len(xy) > 0 and bool(np.all(np.abs(xy[:, 0]) <= 180.0) and np.all(np.abs(xy[:, 1]) <= 90.0))


def _unlabelled_metres(opt: GeorefOptions, utm: Optional[str]) -> List[str]:
    """Sentences naming the control files that carry no CRS line and hold numbers that are not degrees (read in the
    CRS parameter's CRS they would be refused or misplaced)."""
    out = []
    if opt.camera_positions_path:
        crs, cams = gcpmod.read_camera_positions(opt.camera_positions_path, warnings=[])
        xy = np.array([[c.x, c.y] for c in cams], dtype=float).reshape(-1, 2)
        if crs is None and len(xy) and not _degree_like(xy):
            zone = f" ({utm} if they are UTM coordinates of the photos' zone)" if utm else ""
            out.append(f"the camera positions in {opt.camera_positions_path} have no CRS line and hold metres, not "
                       f"degrees (x={xy[0, 0]:.3f}, y={xy[0, 1]:.3f}): a file without a CRS line is read in the CRS "
                       f"parameter's CRS, so that projected CRS{zone} is theirs")
    if opt.gcp_path and gcpmod.detect_gcp_format(opt.gcp_path) == "csv":
        file_crs, pts = gcpmod.csv_points_preview(opt.gcp_path)
        xy = np.array(pts, dtype=float).reshape(-1, 2)
        if file_crs is None and len(xy) and not _degree_like(xy):
            out.append(f"the GCP file {opt.gcp_path} has no CRS line and holds metres, not degrees "
                       f"(x={xy[0, 0]:.3f}, y={xy[0, 1]:.3f})")
    return out


def check_crs_parameter(ws: Workspace, opt: GeorefOptions) -> None:
    """StageError when the CRS parameter is geographic (degrees): the adjustment needs metres; name the CRS that
    fixes it (the UTM zone of the photos' GPS) and the control files that hold metres without a CRS line."""
    if not opt.crs or not crs_is_geographic(opt.crs):
        return
    utm = photos_utm(ws)
    files = _unlabelled_metres(opt, utm)
    raise StageError(
        f"CRS={opt.crs} (the CRS parameter) is geographic (degrees); georeferencing needs a projected CRS in metres: "
        f"give {_projected_advice(ws)}. GCPs and camera positions whose files name their CRS (EPSG:4326 included) "
        "are reprojected into it" + (f"; {'; '.join(files)}" if files else ""))


def check_target_crs(ws: Workspace, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet], target: str) -> None:
    """StageError when the target CRS came out geographic: no CRS parameter, and the GCP or camera position file
    it was taken from is in degrees.  Names that file and the CRS parameter that fixes it."""
    if not crs_is_geographic(target):
        return
    if opt.crs:  # check_crs_parameter has said it
        check_crs_parameter(ws, opt)
    if gcps is not None and gcps.crs == target:
        src = f"the GCP file {opt.gcp_path}" if opt.gcp_path else "the GCP layer"
        what = "ground control points"
    else:
        src, what = f"the camera positions file {opt.camera_positions_path}", "camera positions"
    raise StageError(
        f"{src} is in {target}, a geographic CRS (degrees), and no CRS was given to georeference in: the "
        f"adjustment needs a projected CRS in metres: give {_projected_advice(ws)}; the {what} are reprojected "
        "into it")


# ---------------------------------------------------------------------------------------------------------------
# where the control lands
# ---------------------------------------------------------------------------------------------------------------

def _to(xy: np.ndarray, src: str, dst: str) -> np.ndarray:
    """``xy`` (N,2) from ``src`` into ``dst``; rows that cannot be transformed are inf."""
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


class _Place:
    """Where the photos are (their EXIF GPS in the target CRS) and how far control may be from them."""

    def __init__(self, ws: Workspace, target: str):
        self.target = target
        gps = _gps(ws)
        self.xy = np.zeros((0, 2))
        if gps:
            try:
                self.xy = transform_points(np.array([[g[1], g[2]] for g in gps]), "EPSG:4326", target)
            except CRSError:  # a local or engineering CRS: no way from the GPS into it, nothing to compare
                gps = []
        self.names = [g[0] for g in gps]
        self.spread = float(max(np.ptp(self.xy[:, 0]), np.ptp(self.xy[:, 1]))) if len(self.xy) else math.nan
        self.limit = FAR_FACTOR * (self.spread + EXIF_SIGMA_XY) if len(self.xy) else math.nan
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

    def far(self, xy: np.ndarray, images: Optional[Sequence[str]] = None, noun: str = "points") -> Optional[str]:
        """'' when the points (the median one) land where the photos are, else what is wrong (with GPS: how far
        from it; without: outside the target CRS's area of use); None when nothing can be said."""
        if len(self.xy):
            d = self.distance(xy, images)
            med = float(np.median(d))
            if med <= self.limit:
                return ""
            how = "from the same photos' EXIF GPS" if images is not None else "from the photos' EXIF GPS positions"
            return (f"land {_km(med)} {how} (median over {len(d)} {noun}; the photos' GPS positions span {self.spread:,.0f} m, "
                    f"so more than {_km(self.limit)} is not a GPS error)")
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


def _km(m: float) -> str:
    if not math.isfinite(m):
        return "infinitely far (outside the CRS's domain)"
    return f"{m / 1000.0:,.0f} km" if m >= 10000.0 else f"{m:,.0f} m"


def _cause(place: _Place, raw: np.ndarray, src: str, images: Optional[Sequence[str]], utm: Optional[str],
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
    return (f"check the coordinates and their CRS ({src}); if they are right, the photos' EXIF GPS is what is wrong: "
            "georeference without it (camera positions or GCPs only are used, the GPS only for this check)")


def check_control_location(ws: Workspace, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet],
                           cams: Sequence[gcpmod.CameraPosition], target: str) -> None:
    """StageError when the camera positions file's positions, or the control points, land far from the photos'
    own EXIF GPS (without GPS: outside the target CRS's area of use), naming the likely cause.  ``gcps`` and
    ``cams`` are in ``target`` (``read_control``'s output); camera positions from the EXIF GPS are not checked
    (they are the reference)."""
    utm = photos_utm(ws)
    measure = target
    if crs_is_geographic(target):  # measured in metres, in the photos' UTM zone (check_target_crs refuses later)
        if not utm:
            return
        measure = utm
    place = _Place(ws, measure)

    def there(xy: np.ndarray) -> np.ndarray:
        return xy if measure == target else _to(xy, target, measure)

    if opt.camera_positions_path and cams:
        xy = there(np.array([[c.x, c.y] for c in cams], dtype=float))
        images = [c.image for c in cams]
        what = place.far(xy, images, "photos")
        if what:
            file_crs, raw_cams = gcpmod.read_camera_positions(opt.camera_positions_path, warnings=[])
            src = file_crs or target
            raw = np.array([[c.x, c.y] for c in raw_cams], dtype=float)
            raise StageError(f"the camera positions in {opt.camera_positions_path} ({src}) {what}: "
                             f"{_cause(place, raw, src, [c.image for c in raw_cams], utm, bool(file_crs))}")
    if gcps is not None:
        pts = [p for p in gcps.points if p.role == gcpmod.CONTROL] or list(gcps.points)
        if not pts:
            return
        xy = there(np.array([[p.x, p.y] for p in pts], dtype=float))
        what = place.far(xy)
        if what:
            src, raw, labelled = target, xy, True
            if opt.gcp_path:
                again = gcpmod.read_gcps(opt.gcp_path, default_crs=opt.crs)
                src = again.crs or target
                raw = np.array([[p.x, p.y] for p in again.points if p.name in {q.name for q in pts}], dtype=float)
                labelled = not opt.crs or again.crs != opt.crs
            name = f"the GCP file {opt.gcp_path}" if opt.gcp_path else "the GCP layer"
            raise StageError(f"the control points of {name} ({src}) {what}: {_cause(place, raw, src, None, utm, labelled)}")


def _read_control(ws: Workspace, opt: GeorefOptions, progress: Progress, required: bool):
    """``read_control``, with the warnings the control readers issue (a camera position file's duplicate rows) put
    in the stage's log, where the user reads them (a Python warning reaches a console at best); other warnings
    go on as they came."""
    caught: List[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            return read_control(ws, opt, progress, required)
    finally:
        said = set()
        for w in caught:
            text = str(w.message)
            if w.category is UserWarning:  # what the readers say (warnings.warn(text))
                if text not in said:  # read_control reads the positions file twice
                    said.add(text)
                    progress.warning(text)
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)


def read_checked_control(ws: Workspace, opt: GeorefOptions, progress: Progress, required: bool = True):
    """``read_control``'s (GCPs, camera positions, target CRS), checked: a geographic CRS parameter refused
    before reading, control far from the photos' GPS and a geographic target after (StageError each); the
    readers' warnings in the stage's log.  The one reader of control files: the georeference stage and the
    automatic control (its check points and rough positions: ``required`` False, no minimum) read through it."""
    check_crs_parameter(ws, opt)  # CRS=EPSG:4326: refused before reading, naming the UTM zone
    gcps, cams, target = _read_control(ws, opt, progress, required)
    check_control_location(ws, opt, gcps, cams, target)  # lands where the photos' GPS says?
    check_target_crs(ws, opt, gcps, target)
    return gcps, cams, target


__all__ = ["AREA_MARGIN", "FAR_FACTOR", "check_control_location", "check_crs_parameter", "check_target_crs",
           "photos_utm", "read_checked_control"]
