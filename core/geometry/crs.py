"""Coordinate reference systems: tidy, recognise, validate, classify, pick a UTM zone, transform points.

GDAL (osgeo.osr) is used when it is there, else pyproj, else nothing is validated (and a CRS's kind is
guessed from its common spellings).  Axis order is always the GIS one: x = longitude / easting,
y = latitude / northing.  Problems raise :class:`CRSError` (core.io.gcp's ``GCPError`` is the same class,
so that a GCP file's CRS problems and its other problems are caught together).
"""
from __future__ import annotations

import contextlib
import math
import os
import re
from typing import Any, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError


class CRSError(ArchaeoOrthoError, ValueError):
    """An unknown or unparsable CRS, coordinates that do not fit their CRS, or a failed transformation."""


WKT_START = re.compile(r"^\s*(PROJCS|GEOGCS|GEOCCS|COMPD_CS|LOCAL_CS|VERT_CS|PROJCRS|GEOGCRS|GEODCRS|"
                        r"GEODETICCRS|BASEGEOGCRS|COMPOUNDCRS|BOUNDCRS|ENGCRS|ENGINEERINGCRS|VERTCRS|VERTICALCRS|"
                        r"PROJECTEDCRS)\s*[\[(]", re.IGNORECASE)
_UTM_NAME = re.compile(r"^WGS\s*-?\s*84\s+UTM\s+(?:ZONE\s*)?(\d{1,2})\s*([NS])$", re.IGNORECASE)
_AUTH_CODE = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s*:\s*(\S+)$")


def _osr():
    try:
        from osgeo import osr
    except ImportError:
        return None
    return osr


def _pyproj():
    try:
        import pyproj
    except ImportError:
        return None
    return pyproj


@contextlib.contextmanager
def _quiet_gdal():
    """Silence GDAL's error printing (we report problems ourselves) and reset its last error."""
    try:
        from osgeo import gdal
    except ImportError:
        yield None
        return
    gdal.PushErrorHandler("CPLQuietErrorHandler")
    gdal.ErrorReset()
    try:
        yield gdal
    finally:
        gdal.PopErrorHandler()


def normalize_crs(text: str) -> str:
    """Tidy a CRS string: strip blanks, ``32617`` -> ``EPSG:32617``, ``epsg : 32617`` -> ``EPSG:32617``,
    ``WGS84 UTM 17N`` -> ``EPSG:32617`` (a form OpenDroneMap accepts); anything else is returned stripped
    of surrounding blanks."""
    s = (text or "").strip()
    if re.fullmatch(r"\d+", s):
        return f"EPSG:{int(s)}"
    m = re.fullmatch(r"(?i)epsg\s*:\s*(\d+)", s)
    if m:
        return f"EPSG:{int(m.group(1))}"
    m = _UTM_NAME.match(s)
    if m and 1 <= int(m.group(1)) <= 60:
        return f"EPSG:{(32600 if m.group(2).upper() == 'N' else 32700) + int(m.group(1))}"
    return s


def looks_like_crs(text: str) -> bool:
    """True when a line reads as a CRS definition (EPSG code, authority:code, proj string, WKT, UTM name)."""
    s = (text or "").strip()
    if not s:
        return False
    if re.fullmatch(r"\d+", s) or _UTM_NAME.match(s) or WKT_START.match(s):
        return True
    if s.startswith("+proj=") or s.startswith("+init=") or s.lower().startswith("urn:ogc:def:crs"):
        return True
    return bool(_AUTH_CODE.match(s))


def _srs(crs: str):
    """osr.SpatialReference with GIS axis order (x = lon/easting), or raise CRSError."""
    osr = _osr()
    ok, reason = crs_status(crs)
    if ok is False:
        raise CRSError(f"unknown or unparsable CRS {crs!r}: {reason}")
    srs = osr.SpatialReference()
    with _quiet_gdal():
        srs.SetFromUserInput(normalize_crs(crs))
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    return srs


def crs_status(crs: str) -> Tuple[Optional[bool], str]:
    """(True, '') valid; (False, reason) invalid; (None, reason) cannot be checked here."""
    s = normalize_crs(crs)
    if not s:
        return False, "empty CRS"
    if re.match(r"(?i)^(https?|ftp)://", s):
        return False, "a CRS must be given inline (EPSG code, proj string or WKT), not as a URL"
    if os.path.isfile(s):
        return False, "a CRS must be given inline (EPSG code, proj string or WKT), not as a file name"
    osr = _osr()
    if osr is not None:
        srs = osr.SpatialReference()
        with _quiet_gdal() as gdal:
            try:
                err = srs.SetFromUserInput(s)
            except RuntimeError as e:  # osr.UseExceptions() enabled elsewhere
                return False, str(e) or "not recognised by GDAL/PROJ"
            msg = gdal.GetLastErrorMsg() if gdal is not None else ""
        if err != 0:
            return False, msg or f"not recognised by GDAL/PROJ (OGRErr {err})"
        return True, ""
    pyproj = _pyproj()
    if pyproj is not None:
        try:
            pyproj.CRS.from_user_input(s)
        except Exception as e:  # pyproj.exceptions.CRSError and friends
            return False, str(e)
        return True, ""
    return None, "neither GDAL (osgeo) nor pyproj is available"


def validate_crs(crs: str) -> Optional[str]:
    """Check a CRS string with GDAL (osgeo.osr), else pyproj.

    Returns None when it is valid, a warning text when it cannot be checked (no CRS library);
    raises CRSError when it is unknown or unparsable.
    """
    ok, reason = crs_status(crs)
    if ok is False:
        raise CRSError(f"unknown or unparsable CRS {crs!r}: {reason}")
    return None if ok else reason


def _crs_kind(crs: str) -> Optional[str]:
    """'geographic', 'projected', 'other' (geocentric, local, vertical), or None when unknown."""
    s = normalize_crs(crs)
    osr = _osr()
    if osr is not None:
        ok, _ = crs_status(s)
        if not ok:
            return None
        srs = osr.SpatialReference()
        with _quiet_gdal():
            srs.SetFromUserInput(s)
        if srs.IsProjected():
            return "projected"
        if srs.IsGeographic():
            return "geographic"
        return "other"
    pyproj = _pyproj()
    if pyproj is not None:
        try:
            c = pyproj.CRS.from_user_input(s)
        except Exception:
            return None
        if c.is_projected:
            return "projected"
        if c.is_geographic:
            return "geographic"
        return "other"
    low = s.lower()  # last resort: recognise the common spellings
    if low in ("epsg:4326", "epsg:4979", "epsg:4258", "epsg:4269", "ogc:crs84") or "+proj=longlat" in low \
            or "+proj=latlong" in low or low.startswith(("geogcs[", "geogcrs[")):
        return "geographic"
    if low.startswith(("epsg:326", "epsg:327", "projcs[", "projcrs[")) or "+proj=utm" in low:
        return "projected"
    return None


def crs_is_geographic(crs_string: str) -> bool:
    """True for a geographic (longitude/latitude, degrees) CRS, 2-D or 3-D, also as the horizontal part of a
    compound CRS.  Raises CRSError for an unknown CRS."""
    validate_crs(crs_string)
    return _crs_kind(crs_string) == "geographic"


def check_coordinates_match_crs(crs: str, xy: Any, what: str = "coordinates", source: str = "") -> None:
    """Catch coordinates given in the wrong units for their CRS; raise CRSError with a clear message.

    * projected CRS but every |x| <= 180 and |y| <= 90 and the points span less than 1 unit: these are
      degrees (longitude/latitude) labelled with a metric CRS.  (A real block in a projected CRS spans
      more than one metre; the spread test keeps small local grids near the origin from tripping it.)
    * geographic CRS but some |x| > 180 or |y| > 90: these are projected metres (or latitude and
      longitude swapped) labelled as degrees.

    Nothing is checked when the CRS kind cannot be determined (no CRS library).
    """
    a = np.asarray(xy, dtype=float)
    if a.size == 0:
        return
    a = a.reshape(-1, a.shape[-1])[:, :2]
    a = a[np.all(np.isfinite(a), axis=1)]
    if len(a) == 0:
        return
    kind = _crs_kind(crs)
    where = f"{source}: " if source else ""
    x, y = a[:, 0], a[:, 1]
    if kind == "projected":
        degree_like = bool(np.all(np.abs(x) <= 180.0) and np.all(np.abs(y) <= 90.0))
        span = float(max(np.ptp(x), np.ptp(y)))
        if degree_like and span < 1.0:
            raise CRSError(
                f"{where}{what} look like degrees (longitude/latitude, e.g. x={x[0]:.6f}, y={y[0]:.6f}) "
                f"but the CRS {crs!r} is projected (metres or feet): give the coordinates in that CRS, or "
                f"declare the geographic CRS they are in (e.g. EPSG:4326)")
    elif kind == "geographic":
        bad_x = np.abs(x) > 180.0
        bad_y = np.abs(y) > 90.0
        if np.any(bad_x | bad_y):
            i = int(np.argmax(bad_x | bad_y))
            if not np.any(bad_x) and np.all(np.abs(y) <= 180.0) and np.all(np.abs(x) <= 90.0):
                hint = ("latitude and longitude look swapped: x must be the longitude (east), "
                        "y the latitude (north)")
            else:
                hint = ("they look like projected coordinates (e.g. UTM metres): declare the projected CRS "
                        "they are in (e.g. EPSG:326xx for UTM north)")
            raise CRSError(
                f"{where}{what} out of range for the geographic CRS {crs!r} (degrees): x={x[i]:.3f}, "
                f"y={y[i]:.3f}; {hint}")


def utm_epsg_for_lonlat(lon: float, lat: float) -> int:
    """EPSG code of the WGS 84 / UTM zone holding (lon, lat) in degrees: 326zz north, 327zz south.

    Follows the UTM grid's exceptions (zone 32V over south-west Norway, zones 31X/33X/35X/37X over
    Svalbard).  Beyond the UTM latitude range (north of 84 N, south of 80 S) returns the polar
    stereographic UPS codes 32661 (north) and 32761 (south).
    """
    lon = float(lon)
    lat = float(lat)
    if not (math.isfinite(lon) and math.isfinite(lat)) or abs(lat) > 90.0 or abs(lon) > 360.0:
        raise ValueError(f"not a longitude/latitude in degrees: {lon}, {lat}")
    if lat > 84.0:
        return 32661
    if lat < -80.0:
        return 32761
    lon = (lon + 180.0) % 360.0 - 180.0  # wrap to [-180, 180)
    zone = int(math.floor((lon + 180.0) / 6.0)) + 1
    zone = min(max(zone, 1), 60)
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        zone = 32
    elif 72.0 <= lat <= 84.0 and 0.0 <= lon < 42.0:
        zone = 31 if lon < 9.0 else 33 if lon < 21.0 else 35 if lon < 33.0 else 37
    return (32600 if lat >= 0.0 else 32700) + zone


def transform_points(xyz: Any, src_crs: str, dst_crs: str) -> np.ndarray:
    """Transform an (N, 2) or (N, 3) array of points between CRSs; returns float64 of the same shape.

    Axis order is the GIS one on both sides (x = longitude / easting, y = latitude / northing), whatever
    the CRS's official axis order.  Heights follow PROJ's rules: for EXIF GPS give
    EPSG:4979 (WGS 84 lon/lat + ellipsoidal height) as source; a 2-D projected target (e.g. EPSG:32617)
    keeps that ellipsoidal height unchanged.  A NaN height (unknown) stays NaN; x and y are still
    transformed.  Uses GDAL (osr), else pyproj; raises CRSError if a point cannot be transformed.
    """
    a = np.array(xyz, dtype=float)
    if a.ndim == 1:
        a = a.reshape(1, -1)
        squeeze = True
    else:
        squeeze = False
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(f"expected an (N, 2) or (N, 3) array of points, got shape {np.shape(xyz)}")
    if len(a) == 0:
        return a
    three = a.shape[1] == 3
    z = a[:, 2].copy() if three else np.zeros(len(a))
    z_nan = ~np.isfinite(z)
    z_in = np.where(z_nan, 0.0, z)
    osr = _osr()
    if osr is not None:
        src, dst = _srs(src_crs), _srs(dst_crs)
        with _quiet_gdal() as gdal:
            try:
                ct = osr.CoordinateTransformation(src, dst)
            except RuntimeError as e:
                ct = None
                msg = str(e)
            else:
                msg = gdal.GetLastErrorMsg() if gdal is not None else ""
            if ct is None:
                raise CRSError(f"no transformation from {src_crs!r} to {dst_crs!r}: {msg}")
            pts = np.column_stack([a[:, 0], a[:, 1], z_in]).tolist()
            try:
                out = np.array(ct.TransformPoints(pts), dtype=float)
            except RuntimeError:  # exceptions enabled (osr.UseExceptions) and some point failed: one by one
                out = np.array([_transform_one(ct, p) for p in pts], dtype=float)
    else:
        pyproj = _pyproj()
        if pyproj is None:
            raise CRSError("transforming coordinates needs GDAL (osgeo) or pyproj; neither is installed")
        try:
            tr = pyproj.Transformer.from_crs(normalize_crs(src_crs), normalize_crs(dst_crs), always_xy=True)
            ox, oy, oz = tr.transform(a[:, 0], a[:, 1], z_in)
        except Exception as e:
            raise CRSError(f"no transformation from {src_crs!r} to {dst_crs!r}: {e}") from e
        out = np.column_stack([ox, oy, oz]).astype(float)
    bad = ~np.all(np.isfinite(out[:, :2]), axis=1)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise CRSError(f"point {i} ({a[i, 0]}, {a[i, 1]}) cannot be transformed from {src_crs!r} to "
                       f"{dst_crs!r} (outside the CRS's domain?)")
    out[z_nan, 2] = np.nan
    res = out if three else out[:, :2]
    return res[0] if squeeze else res


def _transform_one(ct, p: Sequence[float]) -> Tuple[float, float, float]:
    try:
        return tuple(ct.TransformPoint(*p))[:3]
    except RuntimeError:
        return (math.inf, math.inf, math.inf)


def _srs_quiet(crs: str):
    """osr.SpatialReference of ``crs`` (GIS axis order) or None when it does not parse; never raises."""
    osr = _osr()
    if osr is None or not crs:
        return None
    srs = osr.SpatialReference()
    with _quiet_gdal():
        try:
            if srs.SetFromUserInput(normalize_crs(crs)) != 0:
                return None
        except RuntimeError:
            return None
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    return srs


def epsg_code(crs: Optional[str]) -> Optional[int]:
    """The EPSG code a CRS carries (``EPSG:n``, a WKT whose root has ``AUTHORITY["EPSG", n]`` / ``ID``) or that
    GDAL identifies with certainty (a UTM zone written as a PROJ string); None for a CRS that has none, such as a
    national transverse Mercator given by its parameters.  Never raises: GDAL's ``AutoIdentifyEPSG`` fails with
    "Unsupported SRS" on such a CRS when exceptions are on, which is an answer (no code), not an error."""
    if not crs:
        return None
    srs = _srs_quiet(crs)
    if srs is None:
        pyproj = _pyproj()
        if pyproj is None:
            m = re.fullmatch(r"EPSG:(\d+)", normalize_crs(crs))
            return int(m.group(1)) if m else None
        try:
            code = pyproj.CRS.from_user_input(normalize_crs(crs)).to_epsg(min_confidence=100)
        except Exception:  # noqa: BLE001 - pyproj's CRSError and friends: no code
            return None
        return int(code) if code else None
    with _quiet_gdal():
        name, code = srs.GetAuthorityName(None), srs.GetAuthorityCode(None)
        if not code:
            try:
                if srs.AutoIdentifyEPSG() == 0:
                    name, code = srs.GetAuthorityName(None), srs.GetAuthorityCode(None)
            except RuntimeError:  # "OGR Error: Unsupported SRS" with exceptions enabled
                code = None
    if code and (name or "EPSG").upper() == "EPSG" and str(code).isdigit():
        return int(code)
    return None


def crs_identifier(crs: Optional[str]) -> str:
    """How the plugin records a CRS: ``EPSG:n`` when it has an EPSG code (:func:`epsg_code`), else the CRS as
    given (a raster's WKT, a PROJ string), which every reader here accepts; '' for none."""
    if not crs:
        return ""
    code = epsg_code(crs)
    return f"EPSG:{code}" if code else str(crs).strip()


def linear_unit(crs: str) -> Tuple[str, float]:
    """(unit name, metres per unit) of a projected CRS's axes ('degree', NaN for a geographic one); ('', NaN)
    when it cannot be read."""
    srs = _srs_quiet(crs)
    if srs is None:
        return "", math.nan
    if srs.IsGeographic():
        return "degree", math.nan
    name = srs.GetLinearUnitsName() or ""
    return name, float(srs.GetLinearUnits() or math.nan)


def unit_symbol(crs: Optional[str]) -> str:
    """The unit of a CRS's horizontal axes for log lines: 'm', 'ft' (international foot), 'US ft', 'deg', else its
    name; 'model units' without a CRS (a local frame)."""
    if not crs:
        return "model units"
    name, metres = linear_unit(crs)
    if name == "degree":
        return "deg"
    if metres == 1.0:
        return "m"
    if metres == metres and abs(metres - 0.3048) < 1e-9:
        return "ft"
    if metres == metres and abs(metres - 1200.0 / 3937.0) < 1e-9:
        return "US ft"
    return name or "units"


def is_mercator(crs: str) -> bool:
    """True for a (Web) Mercator projection: its scale grows as 1 / cos(latitude) (1.3 at 40 degrees), so its
    metres are not ground metres away from the equator."""
    srs = _srs_quiet(crs)
    if srs is None or not srs.IsProjected():
        return False
    method = (srs.GetAttrValue("PROJECTION") or "").lower()
    return method.startswith("mercator") or "pseudo" in method and "mercator" in method


__all__ = ["CRSError", "WKT_START", "check_coordinates_match_crs", "crs_identifier", "crs_is_geographic",
           "crs_status", "epsg_code", "is_mercator", "linear_unit", "looks_like_crs", "normalize_crs",
           "transform_points", "unit_symbol", "utm_epsg_for_lonlat", "validate_crs"]
