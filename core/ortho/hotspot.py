"""The drone's own shadow and the hot spot (issue 46 item 4): where each photo looks along the sunlight.

A photo taken from a drone shows, at its antisolar point (the view ray that runs along the sunlight), the drone's
own shadow: a small dark speck inside the hot spot, the light halo where the ground shows no shadows.  A mosaic
that takes each cell from the photo that sees it closest to nadir takes that speck wherever it is the nearest
photo, and the specks repeat with the photos across the mosaic.

Here each photo gets a *shadow zone*: the view rays within an angle of its antisolar direction.  The view cost of
:func:`core.ortho.sampling.camera_view` is raised there by SHADOW_PENALTY, so the plan (and the tiles' fill of
occluded cells) take another photo wherever one sees the ground, and the photo keeps the zone only where it is
alone.  The halo outside the zone is levelled by the radiometric model's hot spot term (core.ortho.radiometry).

The antisolar direction comes from what the data says:

1. the sun's position at the photo's time and place, where the time is unambiguous: EXIF GPSDateStamp +
   GPSTimeStamp (UTC) or DateTimeOriginal with its OffsetTimeOriginal / OffsetTime (DateTimeOriginal alone has no
   time zone and is not trusted), and the EXIF GPS position; turned into the block's frame through its CRS
   (grid north), one direction per photo;
2. else the hot spot the radiometric model found in the overlaps' brightness (one direction for the block).

The zone's angular radius scales with the data: SHADOW_FRACTION of the fitted hot spot's width (the Gaussian's
sigma; the drone's shadow sits in its centre, the halo's brightest part goes with it), DEFAULT_RADIUS_DEG where no
hot spot was fitted, plus the seam's feathering ramp and two planning cells as angles (the photo's pixel angle
1 / focal), so that no ramp reaches into the zone."""
from __future__ import annotations

import math
from datetime import UTC, datetime, timedelta, timezone
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

SHADOW_PENALTY = 1000.0  # added to the view cost inside a shadow zone (finite: the photo keeps it where alone)
# around the zone the view cost grows with the hot spot's shape, HALO_WEIGHT * exp(-theta^2 / (2 sigma^2)) (sigma: the
# hot spot's width), so that the seam around a zone falls where the two photos' halos are alike (and the seamline
# moves can move it), not on the zone's edge: a hard circle there showed the halo's skirt against the other photo
# (seneca_south: 1 levels it; 3 gave so much ground to oblique neighbours that their misregistration showed)
HALO_WEIGHT = 1.0
SHADOW_FRACTION = 0.5  # the zone's radius: this share of the fitted hot spot's width (sigma)
DEFAULT_RADIUS_DEG = 4.0  # the zone's radius where no hot spot was fitted (the sun from EXIF alone)
MIN_HOT_GAIN = 0.01  # a fitted hot spot brighter than this (1 %) gives the direction


def sun_position(lat_deg: float, lon_deg: float, when: datetime) -> Tuple[float, float]:
    """(azimuth from true north, clockwise; elevation), degrees, of the sun at ``when`` (timezone-aware) seen
    from (lat, lon): the almanac's low-precision formulas (about 0.1 deg, 1950..2050)."""
    d = (when - datetime(2000, 1, 1, 12, tzinfo=UTC)).total_seconds() / 86400.0
    g = math.radians((357.529 + 0.98560028 * d) % 360.0)
    q = (280.459 + 0.98564736 * d) % 360.0
    lam = math.radians((q + 1.915 * math.sin(g) + 0.020 * math.sin(2 * g)) % 360.0)
    eps = math.radians(23.439 - 0.00000036 * d)
    ra = math.atan2(math.cos(eps) * math.sin(lam), math.cos(lam))
    dec = math.asin(math.sin(eps) * math.sin(lam))
    gmst = (18.697374558 + 24.06570982441908 * d) % 24.0
    ha = math.radians(gmst * 15.0 + lon_deg) - ra
    lat = math.radians(lat_deg)
    elev = math.asin(math.sin(lat) * math.sin(dec) + math.cos(lat) * math.cos(dec) * math.cos(ha))
    az = math.atan2(-math.sin(ha), math.tan(dec) * math.cos(lat) - math.sin(lat) * math.cos(ha))
    return math.degrees(az) % 360.0, math.degrees(elev)


def _numbers(text: str) -> List[float]:
    """The numbers of an EXIF value as GDAL writes it ("(17) (37) (29.5)", "17:37:29", "+02:00")."""
    out = []
    for part in text.replace("(", " ").replace(")", " ").replace(":", " ").split():
        try:
            out.append(float(part))
        except ValueError:
            return []
    return out


def _degrees(value: str, ref: str) -> Optional[float]:
    """Degrees of an EXIF GPS latitude / longitude ("(41) (2) (4.8)" and its N/S/E/W reference)."""
    v = _numbers(value or "")
    if not v:
        return None
    deg = sum(x / 60.0 ** k for k, x in enumerate(v[:3]))
    return -deg if (ref or "").strip().strip("\x00").upper() in ("S", "W") else deg


def exif_utc_time(md: Dict[str, str]) -> Tuple[Optional[datetime], str]:
    """(the photo's time in UTC, where it comes from) from its EXIF metadata (GDAL's EXIF_* keys); (None, why
    not) where the data does not say the time zone: DateTimeOriginal alone is local time of an unknown zone."""
    def get(key):
        return (md.get(key) or "").strip().strip("\x00").strip()

    date, hms = get("EXIF_GPSDateStamp"), _numbers(get("EXIF_GPSTimeStamp"))
    if date and len(hms) == 3:
        try:
            day = datetime.strptime(date.replace("-", ":"), "%Y:%m:%d").replace(tzinfo=UTC)
            return day + timedelta(hours=hms[0], minutes=hms[1], seconds=hms[2]), "EXIF GPS time (UTC)"
        except ValueError:
            pass
    local = get("EXIF_DateTimeOriginal")
    offset = get("EXIF_OffsetTimeOriginal") or get("EXIF_OffsetTime")
    if local and offset:
        try:
            t = datetime.strptime(local[:19], "%Y:%m:%d %H:%M:%S")
            hm = _numbers(offset.lstrip("+-"))
            sign = -1.0 if offset.startswith("-") else 1.0
            tz = timezone(timedelta(hours=sign * hm[0], minutes=sign * (hm[1] if len(hm) > 1 else 0.0)))
            return t.replace(tzinfo=tz).astimezone(UTC), "EXIF DateTimeOriginal + OffsetTime"
        except (ValueError, IndexError):
            pass
    if local:
        return None, "EXIF DateTimeOriginal without a time zone (no OffsetTime, no GPS time)"
    return None, "no EXIF time"


def grid_north(crs: str, lon: float, lat: float) -> Optional[np.ndarray]:
    """Unit (x, y) of true north in the grid of ``crs`` at (lon, lat) (the meridian convergence); None where the
    CRS cannot be read."""
    from osgeo import osr

    try:
        dst = osr.SpatialReference()
        if dst.SetFromUserInput(crs) != 0:
            return None
        src = osr.SpatialReference()
        src.ImportFromEPSG(4326)
        for s in (src, dst):
            s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        tr = osr.CoordinateTransformation(src, dst)
        a = np.array(tr.TransformPoint(lon, lat)[:2])
        b = np.array(tr.TransformPoint(lon, lat + 1e-4)[:2])
    except (RuntimeError, TypeError):
        return None
    v = b - a
    n = float(np.hypot(*v))
    return v / n if n > 0 and np.all(np.isfinite(v)) else None


def antisolar_from_sun(azimuth_deg: float, elevation_deg: float, north: Sequence[float]) -> np.ndarray:
    """The direction the sunlight travels (unit, local frame: x, y the CRS grid, z up) from the sun's azimuth
    (from true north, clockwise) and elevation, with true north ``north`` (unit x, y) in the grid."""
    n = np.asarray(north, dtype=float)
    e = np.array([n[1], -n[0]])  # east: north turned clockwise
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    horiz = math.cos(el) * (math.sin(az) * e + math.cos(az) * n)
    return -np.array([horiz[0], horiz[1], math.sin(el)])


def exif_antisolar(path: str, crs: Optional[str]) -> Tuple[Optional[np.ndarray], str]:
    """(antisolar direction in the local frame, or None; where it comes from or why not) of one photo, from its
    EXIF time and GPS position."""
    from ..io.images import ImageError, open_image, photo_metadata

    if not crs:
        return None, "no CRS"
    try:
        with open_image(path) as r:
            md = photo_metadata(r)
    except ImageError as e:
        return None, f"EXIF unreadable ({e})"
    when, source = exif_utc_time(md)
    if when is None:
        return None, source
    lat, lon = (_degrees(md.get(f"EXIF_GPS{key}", ""), md.get(f"EXIF_GPS{key}Ref", "")) for key in ("Latitude",
                                                                                                "Longitude"))
    if lat is None or lon is None:
        return None, "no EXIF GPS position"
    north = grid_north(crs, lon, lat)
    if north is None:
        return None, f"CRS {crs} unreadable"
    az, el = sun_position(lat, lon, when)
    if el <= 0:
        return None, f"the sun below the horizon at {when.isoformat()}"
    return antisolar_from_sun(az, el, north), f"{source}, sun at {el:.0f} deg elevation, azimuth {az:.0f} deg"


def shadow_zones(cameras, crs: Optional[str], model, margin_px: float,
                 exif_source=exif_antisolar) -> Tuple[List[Optional[Tuple[float, ...]]],
                                                       Dict[str, object], List[str]]:
    """Per camera its shadow zone (antisolar x, y, z in the local frame, radius and the halo's width in radians) or
    None, the summary
    for the stage's record and lines for the log.  ``model``: the fitted RadiometryModel or None; ``margin_px``:
    added to each zone's radius in the photo's pixels (the feathering ramp and planning cells)."""
    fitted = None
    if model is not None and any(math.exp(h) - 1.0 > MIN_HOT_GAIN for h in model.hot):
        fitted = np.asarray(model.antisolar, dtype=float)
    base = SHADOW_FRACTION * model.hot_width if fitted is not None else math.radians(DEFAULT_RADIUS_DEG)
    sigma = model.hot_width if fitted is not None else 2.0 * base
    zones: List[Optional[Tuple[float, ...]]] = []
    sources: Dict[str, int] = {}
    seen = 0
    why = ""
    for cam in cameras:
        direction, source = exif_source(cam.path, crs)
        if direction is None:
            why = why or source
            direction, source = fitted, "the hot spot fitted from the overlaps' brightness"
        if direction is None:
            zones.append(None)
            continue
        radius = base + margin_px / max(cam.camera.focal, 1e-9)
        zones.append((float(direction[0]), float(direction[1]), float(direction[2]), float(radius), float(sigma)))
        sources[source.split(",")[0]] = sources.get(source.split(",")[0], 0) + 1
        _px, _d, ok = cam.project(cam.centre[None, :] + 100.0 * np.asarray(direction)[None, :])
        seen += int(ok[0])
    summary: Dict[str, object] = {"images": sum(z is not None for z in zones), "in_frame": seen,
                                  "sources": sources, "penalty": SHADOW_PENALTY, "halo_weight": HALO_WEIGHT,
                                  "halo_width_deg": round(math.degrees(sigma), 2)}
    if not sources:
        return zones, summary, [f"drone's shadow: no antisolar direction (EXIF: {why or 'none'}; no hot spot "
                                "fitted): the mosaic takes the photos as they are"]
    radii = [math.degrees(z[3]) for z in zones if z is not None]
    summary["radius_deg"] = [round(min(radii), 2), round(max(radii), 2)]
    text = "; ".join(f"{n} from {s}" for s, n in sources.items())
    lines = [f"drone's shadow: the antisolar point of {summary['images']} images ({text}"
             f"{'; EXIF: ' + why if why else ''}), {seen} of them inside their frame: a zone of "
             f"{min(radii):.1f}..{max(radii):.1f} deg around it taken from another image wherever one sees the ground, the view cost raised by the hot spot's shape "
             f"({math.degrees(sigma):.0f} deg wide) around it"]
    return zones, summary, lines


def shadow_margin_px(feather_gsd: float, planning_cell_gsd: float) -> float:
    """The zone's margin in the photo's pixels (about its GSD on the ground): half the feathering ramp and two
    planning cells."""
    return 0.5 * feather_gsd + 2.0 * planning_cell_gsd


def shadow_cost(zone: Optional[Tuple[float, ...]], centre: np.ndarray, xyz_local: np.ndarray) -> np.ndarray:
    """(N,) the view cost a photo at ``centre`` adds to local points by its shadow ``zone``: SHADOW_PENALTY within
    the zone's radius, and HALO_WEIGHT times the hot spot's shape (its width, the zone's fifth item)."""
    xyz = np.asarray(xyz_local, dtype=np.float64)
    if zone is None or not len(xyz):
        return np.zeros(len(xyz))
    d = xyz - np.asarray(centre, dtype=np.float64)
    cosang = (d @ np.asarray(zone[:3], dtype=np.float64)) / np.maximum(np.linalg.norm(d, axis=1), 1e-12)
    theta = np.arccos(np.clip(cosang, -1.0, 1.0))
    out = np.where(theta < zone[3], SHADOW_PENALTY, 0.0)
    if len(zone) > 4 and zone[4] > 0:
        out += HALO_WEIGHT * np.exp(-0.5 * (theta / zone[4]) ** 2)
    return out


def in_shadow(zone: Optional[Tuple[float, ...]], centre: np.ndarray, xyz_local: np.ndarray) -> np.ndarray:
    """(N,) bool: the local points seen by a camera at ``centre`` within its shadow ``zone``."""
    xyz = np.asarray(xyz_local, dtype=np.float64)
    if zone is None or not len(xyz):
        return np.zeros(len(xyz), dtype=bool)
    d = xyz - np.asarray(centre, dtype=np.float64)
    norm = np.maximum(np.linalg.norm(d, axis=1), 1e-12)
    return (d @ np.asarray(zone[:3], dtype=np.float64)) / norm > math.cos(zone[3])
