"""Ground control: GCPs, check points, camera positions; readers and writers.

Pixel coordinates: origin at the upper-left corner of the upper-left pixel,
x to the right, y down (the same convention as COLMAP, whose pixel centres
sit at +0.5).

Formats
-------
OpenDroneMap ``gcp_list.txt``
    The first line that is neither blank nor a ``#`` comment holds the CRS: an
    EPSG code (``EPSG:32617``, or a bare ``32617``), ``WGS84 UTM 17N``, a proj
    string or one-line WKT (a WKT spread over several lines is joined until its
    brackets balance); trailing blanks and tabs are ignored.  Every further
    line is ``x y z px py image [name] [extra ...]``, fields separated by tabs
    or spaces; blank lines, ``#`` comment lines and anything from a field that
    starts with ``#`` are skipped.  Lines without a name (the older form) are
    grouped by identical coordinates: a group whose coordinates equal those of
    a named point joins it, any other group gets the name ``gcp_<n>``, where n
    is the point's position in the file (1-based).  An extra field ``check``
    right after the name marks a check point (our writer puts it there; ODM
    ignores extra fields).

CSV (a pair of files)
    Points ``name,x,y,z[,sx,sy,sz,role]`` and observations
    ``name,image,px,py``, each with a header row (column order free, names
    case-insensitive, a few aliases accepted; ``,``, ``;`` or tab separated).
    The observations file defaults to ``<points stem>_observations.csv`` next to
    the points file.  The CRS comes from the ``crs`` argument, or a comment line
    ``# crs: EPSG:32617`` (or a bare CRS line) before the header.
    ``sigma_xy`` is the larger of ``sx`` and ``sy`` (the conservative choice: a
    single horizontal sigma must not claim more precision than the worse axis);
    ``sz`` gives ``sigma_z``; empty cells keep the defaults; ``role`` is
    ``control`` (default, also ``gcp``) or ``check`` (also ``checkpoint``,
    ``cp``).

Sigmas given or not (``GroundPoint.sigma_given``, ``CameraPosition.sigma_given``)
    A gcp_list.txt carries no sigmas; a CSV row, a layer row or a camera-position row
    may leave them out.  The readers mark such points ``sigma_given=False``: their
    sigmas hold the defaults (0.02 / 0.05 m; camera positions the caller's defaults)
    only as placeholders, and the georeferencing estimates their accuracy from the
    data (``core.georef.control_sigma``).  A row with any sigma cell counts as given
    (a missing component keeps its default).  A point constructed directly
    (``GroundPoint(name, x, y, z, ...)``) is taken at its word: ``sigma_given``
    defaults to True, the defaults included; the dock marks the points a user adds
    without typing a sigma.  ``GCPSet.to_dict`` keeps the flag; a dict without it
    (an older workspace's control.json) counts as not given when its sigmas are
    exactly the defaults, which only a file without sigmas produced.  The CSV writer
    leaves the sigma cells empty for points without given sigmas, so they read back
    the same.

Camera positions (see ``read_camera_positions``)
    ``image,x,y,z[,sigma[,sigma_z]]`` rows (comma or whitespace separated, an
    optional header row), or ``x y [z] image`` rows as in OpenDroneMap's
    ``geo.txt``; optionally preceded by a CRS line.

Problems that make a file unusable raise ``GCPError`` with ``file:line: reason``;
problems that leave it usable are collected in ``GCPSet.warnings`` in the same
form.
"""
from __future__ import annotations

import csv
import difflib
import functools
import math
import os
import re
import warnings as _warnings
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

from ..geometry.crs import WKT_START, CRSError, check_coordinates_match_crs, crs_status, looks_like_crs, normalize_crs

CONTROL = "control"
CHECK = "check"

# one class for a GCP file's problems and its CRS's problems (core.geometry.crs raises it), so that callers
# catch both together: "file:line: reason"
GCPError = CRSError


@dataclass
class Observation:
    image: str
    x: float
    y: float


DEFAULT_SIGMA_XY = 0.02  # m: a ground point's sigmas when its source gives none (placeholders, see sigma_given)
DEFAULT_SIGMA_Z = 0.05


@dataclass
class GroundPoint:
    name: str
    x: float
    y: float
    z: float
    sigma_xy: float = DEFAULT_SIGMA_XY
    sigma_z: float = DEFAULT_SIGMA_Z
    role: str = CONTROL  # CONTROL or CHECK
    observations: List[Observation] = field(default_factory=list)
    dropped: List[str] = field(default_factory=list)  # why the reader dropped observations, one entry each
    # the sigmas are the source's (a file's sigma columns, a user's entry, a computed accuracy); False: the source
    # gave none, the sigmas above are placeholders and the georeferencing estimates them (module notes).  Setting
    # sigma_xy or sigma_z on a point (p.sigma_xy = 0.5: a user's entry) marks them given
    sigma_given: bool = True

    def __setattr__(self, name: str, value: Any) -> None:
        if name in ("sigma_xy", "sigma_z") and "sigma_given" in self.__dict__:  # not while __init__ runs
            object.__setattr__(self, "sigma_given", True)
        object.__setattr__(self, name, value)

    def images(self) -> List[str]:
        """Names of the images this point is observed in, in order, without repeats."""
        return list(dict.fromkeys(o.image for o in self.observations))

    def describe_observations(self) -> str:
        """'2 observations', or with the ones the reader dropped: '2 observations, both dropped: outside the
        image', '3 observations, 1 dropped: duplicate'."""
        kept, lost = len(self.observations), len(self.dropped)
        total = kept + lost
        text = f"{total} observation{'s' if total != 1 else ''}"
        if lost:
            reasons = ", ".join(f"{r} x{c}" if c > 1 and len(set(self.dropped)) > 1 else r
                                for r, c in Counter(self.dropped).items())
            which = ("both" if lost == 2 else "all" if lost > 2 else "it") if not kept else str(lost)
            text += f", {which} dropped: {reasons}"
        return text


@dataclass
class GCPSet:
    crs: str  # as given: "EPSG:xxxx", WKT or a proj string
    points: List[GroundPoint] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)
    source: str = ""  # the file it was read from, if any

    def by_name(self, name: str) -> Optional[GroundPoint]:
        for p in self.points:
            if p.name == name:
                return p
        return None

    def control_points(self) -> List[GroundPoint]:
        return [p for p in self.points if p.role == CONTROL]

    def check_points(self) -> List[GroundPoint]:
        return [p for p in self.points if p.role == CHECK]

    def n_observations(self) -> int:
        return sum(len(p.observations) for p in self.points)

    def image_names(self) -> List[str]:
        """Every image with at least one observation, in order of first appearance."""
        return list(dict.fromkeys(o.image for p in self.points for o in p.observations))

    def to_dict(self) -> Dict[str, Any]:
        """A JSON-ready dict (e.g. for georef/control.json); ``from_dict`` reads it back."""
        return {
            "crs": self.crs,
            "points": [
                {"name": p.name, "x": p.x, "y": p.y, "z": p.z, "sigma_xy": p.sigma_xy, "sigma_z": p.sigma_z,
                 "sigma_given": p.sigma_given, "role": p.role,
                 "observations": [{"image": o.image, "x": o.x, "y": o.y} for o in p.observations]}
                for p in self.points
            ],
            "warnings": list(self.warnings),
            "source": self.source,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> GCPSet:
        pts = []
        for p in d.get("points", []):
            obs = [Observation(str(o["image"]), float(o["x"]), float(o["y"]))
                   for o in p.get("observations", [])]
            sxy, sz = float(p.get("sigma_xy", DEFAULT_SIGMA_XY)), float(p.get("sigma_z", DEFAULT_SIGMA_Z))
            given = p.get("sigma_given")
            if given is None:  # an older control.json: the defaults exactly are what a file without sigmas gave
                given = (sxy, sz) != (DEFAULT_SIGMA_XY, DEFAULT_SIGMA_Z)
            pts.append(GroundPoint(str(p["name"]), float(p["x"]), float(p["y"]), float(p["z"]), sxy, sz,
                                   str(p.get("role", CONTROL)), obs, sigma_given=bool(given)))
        return cls(str(d.get("crs", "")), pts, list(d.get("warnings", [])), str(d.get("source", "")))


@dataclass
class CameraPosition:
    image: str
    x: float
    y: float
    z: float
    sigma_xy: float = 5.0
    sigma_z: float = 10.0
    sigma_given: bool = True  # False: the source gave no sigma (a positions file without them, EXIF GPS)


PathLike = Union[str, "os.PathLike[str]"]
ImageSizes = Mapping[str, Tuple[int, int]]

# --------------------------------------------------------------------------------------------------
# reading helpers
# --------------------------------------------------------------------------------------------------

def _utf16_or_32(raw: bytes) -> Optional[str]:
    """'UTF-16' / 'UTF-32' when the bytes are such text (a byte-order mark, or NUL bytes between ASCII ones:
    Windows Notepad's "Unicode"), else None."""
    if raw.startswith((b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff")):
        return "UTF-32"
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        return "UTF-16"
    head = raw[:4096]
    if len(head) >= 8 and head.count(b"\x00") > len(head) // 4:
        return "UTF-32" if head.count(b"\x00") > len(head) // 2 else "UTF-16"
    return None


def _read_lines(path: PathLike) -> List[str]:
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise GCPError(f"{path}: cannot read: {e.strerror or e}") from e
    wide = _utf16_or_32(raw)
    if wide:
        raise GCPError(f"file {path} is {wide} text; save it as UTF-8 (or plain ASCII) and read it again")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return text.splitlines()


_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$|^[+-]?\d+,$")


def _decimal(tok: str, decimal_comma: bool) -> str:
    """``tok`` with a decimal comma read as a point (``274901,848`` -> ``274901.848``) when the file's separator
    leaves the comma free for that (``;`` or tab: a spreadsheet's export in a locale that writes decimal commas)."""
    return tok.replace(",", ".") if decimal_comma and _DECIMAL_COMMA.match(tok.strip()) else tok


def _num(tok: str, what: str, path: PathLike, lineno: int, decimal_comma: bool = False) -> float:
    try:
        v = float(_decimal(tok, decimal_comma))
    except ValueError:
        raise GCPError(f"{path}:{lineno}: {what} is not a number: {tok!r}") from None
    if not math.isfinite(v):
        raise GCPError(f"{path}:{lineno}: {what} is not a finite number: {tok!r}")
    return v


def _is_number(tok: str, decimal_comma: bool = False) -> bool:
    try:
        return math.isfinite(float(_decimal(tok, decimal_comma)))
    except ValueError:
        return False


def _check_crs_for_file(crs: str, path: PathLike, lineno: Optional[int], warnings: List[str]) -> None:
    where = f"{path}:{lineno}" if lineno else f"{path}"
    ok, reason = crs_status(crs)
    if ok is False:
        raise GCPError(f"{where}: unknown or unparsable CRS {crs!r}: {reason}")
    if ok is None:
        warnings.append(f"{where}: CRS {crs!r} not validated: {reason}")


class _ImageLookup:
    """Match image names from a control file to the block's names: exactly, then by base name, then by base
    name ignoring case (only when that is unambiguous)."""

    def __init__(self, names: Optional[Iterable[str]]):
        self.names = None if names is None else list(names)
        self.exact = set(self.names or [])
        self.base: Dict[str, List[str]] = {}
        self.lower: Dict[str, List[str]] = {}
        for n in self.names or []:
            b = os.path.basename(n.replace("\\", "/"))
            self.base.setdefault(b, []).append(n)
            self.lower.setdefault(b.lower(), []).append(n)

    def find(self, image: str) -> Optional[str]:
        if self.names is None or image in self.exact:
            return image
        b = os.path.basename(image.replace("\\", "/"))
        for table, key in ((self.base, b), (self.lower, b.lower())):
            hit = table.get(key, [])
            if len(hit) == 1:
                return hit[0]
        return None


def _closest_names(image: str, names: Sequence[str], n: int = 3) -> List[str]:
    """The block's photo names closest to ``image`` (difflib on lower-case base names), best first."""
    base = {}
    for name in names:
        base.setdefault(os.path.basename(name.replace("\\", "/")).lower(), name)
    key = os.path.basename(image.replace("\\", "/")).lower()
    return [base[b] for b in difflib.get_close_matches(key, list(base), n=n, cutoff=0.5)]


def _line_list(lines: Sequence[int], unit: str) -> str:
    shown = [str(n) for n in lines if n][:12]
    if not shown:
        return ""
    more = f", ... ({len(lines)} in all)" if len(lines) > 12 else ""
    return f"{unit}{'s' if len(lines) > 1 else ''} {', '.join(shown)}{more}"


def _unknown_images(gs: GCPSet, unknown: Dict[str, List[Tuple[int, str]]], matched: int, known: Sequence[str],
                    path: PathLike, unit: str, mode: str, loc) -> None:
    """The policy for observations in photos that are not in the block (``unknown``: {image: [(line, point)]}):
    with ``mode="warn"`` they are ignored with one warning per photo naming its lines and points, unless no
    observation at all matches a photo of the block: then (and always with ``mode="error"``) GCPError, naming
    the closest photo names of the block so that a naming mistake shows."""
    n_unknown = sum(len(v) for v in unknown.values())
    if mode == "warn" and matched:
        gs.warnings.append(
            f"{path}: {n_unknown} observation(s) in {len(unknown)} photo(s) that are not in the block "
            f"({len(known)} photos) ignored: {', '.join(list(unknown)[:10])}{' ...' if len(unknown) > 10 else ''}; "
            f"{matched} observation(s) match the block's photos and are used")
        for image, rows in unknown.items():
            points = ", ".join(dict.fromkeys(pt for _, pt in rows))
            lines = _line_list([ln for ln, _ in rows], unit)
            gs.warnings.append(f"{loc(rows[0][0])}: image {image!r} is not in the block: {len(rows)} observation(s) "
                               f"ignored ({lines + '; ' if lines else ''}point(s) {points})")
        return

    def hint(image: str) -> str:
        close = _closest_names(image, known)
        return f"closest in the block: {', '.join(close)}" if close else "no similar name in the block"

    details = "; ".join(f"{image!r} ({_line_list([ln for ln, _ in rows], unit) + ', ' if rows[0][0] else ''}"
                        f"{hint(image)})" for image, rows in list(unknown.items())[:12])
    more = f"; ... ({len(unknown)} photos in all)" if len(unknown) > 12 else ""
    sample = ", ".join(list(known)[:5]) + (", ..." if len(known) > 5 else "")
    if mode == "warn":
        raise GCPError(f"{path}: none of its {n_unknown} observation(s) is in a photo of the block ({len(known)} "
                       f"photos, e.g. {sample}): the image names do not match: {details}{more}")
    shown = "; ".join(f"{unit} {ln}: {image}" if ln else image for image, rows in unknown.items()
                      for ln, _ in rows)
    raise GCPError(f"{path}: observation(s) in image(s) that are not in the block ({len(known)} images): "
                   f"{shown[:2000]}. Per photo: {details}{more}")


def _upright_table(upright: Optional[Mapping[str, int]], image_sizes: Optional[ImageSizes],
                   path: PathLike) -> Dict[str, Any]:
    """{image: (x, y) -> stored (x, y)} for the photos of ``upright`` whose orientation turns the grid."""
    from .images import upright_to_stored

    out: Dict[str, Any] = {}
    for image, orientation in (upright or {}).items():
        if int(orientation) == 1:
            continue
        size = (image_sizes or {}).get(image)
        if size is None:
            raise GCPError(f"{path}: cannot convert the upright pixel coordinates of image {image}: its stored size "
                           "is not known")
        out[image] = functools.partial(upright_to_stored, orientation=int(orientation), width=size[0], height=size[1])
    return out


def observations_to_stored(gcpset: GCPSet, image_sizes: ImageSizes, orientations: Mapping[str, int]) -> GCPSet:
    """Convert observations measured on upright photos to the stored pixel grid, in place (for a GCPSet made
    elsewhere, e.g. from a point layer; the readers take ``upright_orientations`` instead).  ``image_sizes``:
    stored sizes; ``orientations``: {image: EXIF orientation}; other images are left as they are."""
    table = _upright_table(orientations, image_sizes, gcpset.source or "ground control")
    for p in gcpset.points:
        p.observations = [Observation(o.image, *table[o.image](o.x, o.y)) if o.image in table else o
                          for o in p.observations]
    return gcpset


@dataclass
class _Photos:
    """What a reader knows of the block's photos to check observations against: ``names`` (None: any),
    ``sizes`` {image: (width, height)} of the stored grid (None: bounds unchecked), ``unknown``: "warn" (an
    observation in a photo not in the block is dropped with a warning) or "error"; ``upright``: {image: EXIF
    orientation} of photos whose observations were measured on the upright photo."""
    names: Optional[Iterable[str]]
    sizes: Optional[ImageSizes]
    unknown: str = "warn"
    upright: Optional[Mapping[str, int]] = None


def _finish(gs: GCPSet, obs_lines: Dict[int, List[int]], path: PathLike, photos: _Photos,
            point_where: Optional[Dict[int, str]] = None, unit: str = "line") -> GCPSet:
    """Shared validation: unknown images, duplicate observations, bounds, points seen in < 2 images.

    ``obs_lines[id(point)]`` holds the source line (in ``path``) of each observation of that point;
    ``point_where[id(point)]`` where the point itself is defined, when that is elsewhere ("file:line").
    ``unit``: "line" (file:line) or "row" (source: row n) in messages.  The observations of ``photos.upright``
    are converted to the stored grid (``photos.sizes`` gives the stored sizes) before the bounds check.
    """
    image_names, image_sizes, unknown_images = photos.names, photos.sizes, photos.unknown

    def loc(n: int) -> str:
        if not n:
            return f"{path}"
        return f"{path}:{n}" if unit == "line" else f"{path}: row {n}"

    if unknown_images not in ("error", "warn"):
        raise ValueError("unknown_images must be 'error' or 'warn'")
    names = _ImageLookup(image_names)
    sizes_lookup = _ImageLookup(image_sizes.keys()) if image_sizes is not None else None
    rotations = _upright_table(photos.upright, image_sizes, path)
    unknown: Dict[str, List[Tuple[int, str]]] = {}
    matched = 0
    for p in gs.points:
        lines = obs_lines.get(id(p), [0] * len(p.observations))
        kept: List[Observation] = []
        kept_lines: List[int] = []
        seen: Dict[str, int] = {}
        for o, ln in zip(p.observations, lines):
            at = loc(ln)
            img = names.find(o.image)
            if img is None:
                unknown.setdefault(o.image, []).append((ln, p.name))
                p.dropped.append("image not in the block")
                continue
            matched += 1
            o = Observation(img, o.x, o.y)
            if img in seen:
                first = f"{unit} {seen[img]}" if seen[img] else f"an earlier {unit}"
                gs.warnings.append(f"{at}: duplicate observation of point {p.name} in image {img} "
                                   f"(first on {first}); keeping the first")
                p.dropped.append("duplicate")
                continue
            if img in rotations:
                o = Observation(img, *rotations[img](o.x, o.y))
            if sizes_lookup is not None:
                key = sizes_lookup.find(img)
                if key is not None and key in image_sizes:
                    w, h = image_sizes[key]
                    if not (0.0 <= o.x <= float(w) and 0.0 <= o.y <= float(h)):
                        gs.warnings.append(
                            f"{at}: observation of point {p.name} at ({o.x:g}, {o.y:g}) lies outside image "
                            f"{img} ({w} x {h} px){' (stored grid)' if img in rotations else ''}; dropped")
                        p.dropped.append("outside the image")
                        continue
            seen[img] = ln
            kept.append(o)
            kept_lines.append(ln)
        p.observations = kept
        obs_lines[id(p)] = kept_lines
    if unknown:
        _unknown_images(gs, unknown, matched, names.names or [], path, unit, unknown_images, loc)
    for p in gs.points:
        n = len(p.images())
        first = next(iter(obs_lines.get(id(p)) or []), 0)
        at = (point_where or {}).get(id(p)) or loc(first)
        if n == 0:
            gs.warnings.append(f"{at}: point {p.name} has no usable observation ({p.describe_observations()})")
        elif n == 1:
            gs.warnings.append(f"{at}: point {p.name} is observed in only 1 image "
                               f"({p.observations[0].image}): usable only for single-image work (space "
                               "resection, orthorectifying that image), not for triangulation in the block")
    return gs


def _check_units(gs: GCPSet, path: PathLike) -> None:
    if gs.points:
        check_coordinates_match_crs(gs.crs, [(p.x, p.y) for p in gs.points], "GCP coordinates", str(path))


def with_warnings(error: Exception, warnings: Sequence[str]) -> str:
    """The message of ``error`` followed by the reader's warnings (that led to it, often: dropped lines)."""
    if not warnings:
        return str(error)
    shown = list(warnings[:20]) + ([f"... ({len(warnings)} in all)"] if len(warnings) > 20 else [])
    return f"{error}\nwarnings while reading the ground control:\n  " + "\n  ".join(shown)


def _finish_checked(gs: GCPSet, obs_lines: Dict[int, List[int]], path: PathLike, units_path: PathLike,
                    photos: _Photos, point_where: Optional[Dict[int, str]] = None) -> GCPSet:
    """_finish and _check_units; a GCPError they raise carries the warnings collected before it."""
    try:
        _finish(gs, obs_lines, path, photos, point_where)
        _check_units(gs, units_path)
    except GCPError as e:
        if not gs.warnings:
            raise
        raise GCPError(with_warnings(e, gs.warnings)) from e
    return gs


# --------------------------------------------------------------------------------------------------
# OpenDroneMap gcp_list.txt
# --------------------------------------------------------------------------------------------------

def read_odm_gcp_list(path: PathLike, image_names: Optional[Iterable[str]] = None,
                      image_sizes: Optional[ImageSizes] = None, *, unknown_images: str = "warn",
                      upright_orientations: Optional[Mapping[str, int]] = None) -> GCPSet:
    """Read an OpenDroneMap ``gcp_list.txt`` (format in the module docstring).

    ``image_names``: the block's images.  An observation in any other image is dropped with a warning that
    names its lines, photo and points (``unknown_images="warn"``, the default: a file that also lists photos
    left out of the block, or not registered, is used for what matches); GCPError only when no observation at
    all is in a photo of the block, naming the block's closest photo names so that a naming mistake shows.
    ``unknown_images="error"``: any observation in another image is a GCPError.  Names match exactly, else by
    base name, else by base name ignoring case; the block's spelling is kept.  ``image_sizes``: {image:
    (width, height)} of the stored pixel grid; observations outside [0, w] x [0, h] are dropped with a warning.
    ``upright_orientations``: {image: EXIF orientation} when the pixel coordinates were measured on photos
    shown upright (a browser, most photo viewers): they are converted to the stored grid (needs
    ``image_sizes``; see core.io.images.upright_to_stored).
    """
    lines = _read_lines(path)
    i = 0
    while i < len(lines) and (not lines[i].strip() or lines[i].lstrip().startswith("#")):
        i += 1
    if i == len(lines):
        raise GCPError(f"{path}: empty: no CRS line and no observations")
    crs_line = i + 1
    header = lines[i].strip()
    i += 1
    if WKT_START.match(header):  # WKT spread over several lines: join until the brackets balance
        def _open(t: str) -> int:
            return t.count("[") + t.count("(") - t.count("]") - t.count(")")

        while _open(header) > 0 and i < len(lines):
            header += " " + lines[i].strip()
            i += 1
    toks = header.split()
    if len(toks) >= 6 and all(_is_number(t) for t in toks[:5]):
        raise GCPError(f"{path}:{crs_line}: expected the CRS line (e.g. 'EPSG:32617', a proj string or WKT) "
                       f"before the first observation, found an observation line")
    crs = normalize_crs(header)
    gs = GCPSet(crs=crs, source=str(path))
    _check_crs_for_file(crs, path, crs_line, gs.warnings)

    # parse: (line, x, y, z, px, py, image, name or None, is_check)
    recs: List[Tuple[int, float, float, float, float, float, str, Optional[str], bool]] = []
    for ln in range(i, len(lines)):
        s = lines[ln].strip()
        if not s or s.startswith("#"):
            continue
        toks = s.split()
        for k, t in enumerate(toks):
            if t.startswith("#"):
                toks = toks[:k]
                break
        lineno = ln + 1
        if len(toks) < 6:
            raise GCPError(f"{path}:{lineno}: expected 'x y z px py image [name]', found {len(toks)} "
                           f"field(s): {s!r}")
        x, y, z = (_num(toks[k], w, path, lineno) for k, w in ((0, "x"), (1, "y"), (2, "z")))
        px = _num(toks[3], "pixel x", path, lineno)
        py = _num(toks[4], "pixel y", path, lineno)
        name = toks[6] if len(toks) > 6 else None
        is_check = len(toks) > 7 and toks[7].lower() == CHECK
        recs.append((lineno, x, y, z, px, py, toks[5], name, is_check))

    # build points in file order
    named: Dict[str, Tuple[GroundPoint, int]] = {}
    by_xyz_named: Dict[Tuple[float, float, float], List[str]] = {}
    for lineno, x, y, z, _px, _py, _img, name, _chk in recs:
        if name is None:
            continue
        if name in named:
            p, first = named[name]
            if (p.x, p.y, p.z) != (x, y, z):
                raise GCPError(f"{path}:{lineno}: point {name} has coordinates ({x}, {y}, {z}) here but "
                               f"({p.x}, {p.y}, {p.z}) on line {first}")
        else:
            named[name] = (GroundPoint(name, x, y, z, sigma_given=False), lineno)
            by_xyz_named.setdefault((x, y, z), []).append(name)
    order: List[GroundPoint] = []
    placed = set()
    groups: Dict[Tuple[float, float, float], GroundPoint] = {}
    generated: List[Tuple[GroundPoint, int]] = []
    obs_lines: Dict[int, List[int]] = {}
    for lineno, x, y, z, px, py, img, name, is_check in recs:
        if name is not None:
            p = named[name][0]
        else:
            key = (x, y, z)
            twins = by_xyz_named.get(key, [])
            if len(twins) == 1:
                p = named[twins[0]][0]
            elif key in groups:
                p = groups[key]
            else:
                p = GroundPoint("", x, y, z, sigma_given=False)
                groups[key] = p
                generated.append((p, lineno))
        if id(p) not in placed:
            placed.add(id(p))
            order.append(p)
        if is_check:
            p.role = CHECK
        p.observations.append(Observation(img, px, py))
        obs_lines.setdefault(id(p), []).append(lineno)
    used = set(named)
    for p, lineno in generated:
        n = order.index(p) + 1
        name = f"gcp_{n}"
        k = 2
        while name in used:
            name = f"gcp_{n}_{k}"
            k += 1
        p.name = name
        used.add(name)
        gs.warnings.append(f"{path}:{lineno}: observations without a point name grouped by their coordinates "
                           f"({p.x}, {p.y}, {p.z}) as point {name} ({len(p.observations)} observation(s))")
    gs.points = order
    if not order:
        gs.warnings.append(f"{path}: no observations")
    return _finish_checked(gs, obs_lines, path, path,
                           _Photos(image_names, image_sizes, unknown_images, upright_orientations))


def _fmt(v: float) -> str:
    """Shortest text that reads back as the same float."""
    return repr(float(v))


def _writable_token(s: str, what: str) -> str:
    if not s or any(c.isspace() for c in s) or s.startswith("#"):
        raise GCPError(f"cannot write {what} {s!r} to gcp_list.txt: names must be non-empty, without blanks, "
                       "and must not start with '#'")
    return s


def write_odm_gcp_list(gcpset: GCPSet, path: PathLike) -> None:
    """Write an OpenDroneMap ``gcp_list.txt``: the CRS line, then one tab-separated line per observation
    ``x y z px py image name`` (plus ``check`` for check points).  Numbers are written so that they read back
    exactly; sigmas are not part of the format (they read back as not given, ``sigma_given=False``).  Points without
    observations cannot be expressed in the format and are listed in ``#`` comments."""
    crs = " ".join(gcpset.crs.split())
    if not crs:
        raise GCPError("cannot write gcp_list.txt without a CRS")
    out = [crs]
    for p in gcpset.points:
        name = _writable_token(p.name, "point name")
        if not p.observations:
            out.append(f"# point {name} has no observations: {_fmt(p.x)} {_fmt(p.y)} {_fmt(p.z)}")
        for o in p.observations:
            fields = [_fmt(p.x), _fmt(p.y), _fmt(p.z), _fmt(o.x), _fmt(o.y),
                      _writable_token(o.image, "image name"), name]
            if p.role == CHECK:
                fields.append(CHECK)
            out.append("\t".join(fields))
    _write_text(path, "\n".join(out) + "\n")


def _write_text(path: PathLike, text: str) -> None:
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    os.replace(tmp, path)


# --------------------------------------------------------------------------------------------------
# CSV pair
# --------------------------------------------------------------------------------------------------

_POINT_COLS = {
    "name": ("name", "id", "label", "point", "gcp", "point_name", "gcp_name", "pointname"),
    "x": ("x", "easting", "east", "lon", "longitude", "map_x", "mapx"),
    "y": ("y", "northing", "north", "lat", "latitude", "map_y", "mapy"),
    "z": ("z", "elevation", "height", "h", "alt", "altitude"),
    "sx": ("sx", "sigma_x", "std_x", "stdx", "sigmax"),
    "sy": ("sy", "sigma_y", "std_y", "stdy", "sigmay"),
    "sxy": ("sigma_xy", "sxy", "sigmaxy", "std_xy"),
    "sz": ("sz", "sigma_z", "std_z", "stdz", "sigmaz"),
    "role": ("role", "type", "kind", "use"),
}
_OBS_COLS = {
    "name": _POINT_COLS["name"],
    "image": ("image", "image_name", "imagename", "photo", "file", "filename", "file_name"),
    "px": ("px", "pixel_x", "pixelx", "image_x", "col", "column", "u", "x"),
    "py": ("py", "pixel_y", "pixely", "image_y", "row", "v", "y"),
}
_ROLES = {"control": CONTROL, "gcp": CONTROL, "ctrl": CONTROL, "control point": CONTROL, "c": CONTROL,
          "": CONTROL, "check": CHECK, "checkpoint": CHECK, "check point": CHECK, "check_point": CHECK,
          "cp": CHECK,
          "chk": CHECK}
_CRS_COMMENT = re.compile(r"^#\s*crs\s*[:=]\s*(.+)$", re.IGNORECASE)


def _delimiter(line: str) -> str:
    counts = {d: line.count(d) for d in (",", ";", "\t")}
    d = max(counts, key=lambda k: counts[k])
    return d if counts[d] else ","


def _header_map(cells: Sequence[str], spec: Mapping[str, Sequence[str]]) -> Dict[str, int]:
    norm = [re.sub(r"\s+", "_", c.strip().lower()) for c in cells]
    cols: Dict[str, int] = {}
    for key, aliases in spec.items():
        for k, c in enumerate(norm):
            if c in aliases and k not in cols.values():
                cols[key] = k
                break
    return cols


def _csv_table(path: PathLike, spec: Mapping[str, Sequence[str]], required: Sequence[str], what: str):
    """-> (crs or None, crs line, column map, [(lineno, cells)], decimal comma).  Leading '#' lines and a bare CRS
    line before the header are read for a CRS; the header's separator is the file's, and a ``;`` or tab separator
    leaves the comma to decimals (a spreadsheet's export: ``274901,848``)."""
    lines = _read_lines(path)
    crs, crs_line, i = None, None, 0
    while i < len(lines):
        s = lines[i].strip()
        if not s:
            i += 1
            continue
        if s.startswith("#"):
            m = _CRS_COMMENT.match(s)
            if m and crs is None:
                crs, crs_line = normalize_crs(m.group(1)), i + 1
            i += 1
            continue
        cells = next(csv.reader([s], delimiter=_delimiter(s)))
        cols = _header_map(cells, spec)
        if all(k in cols for k in required):
            break
        if crs is None and looks_like_crs(s):
            crs, crs_line = normalize_crs(s), i + 1
            i += 1
            continue
        raise GCPError(f"{path}:{i + 1}: expected a header row naming the columns "
                       f"{', '.join(required)} of the {what} file, found {s!r}")
    if i == len(lines):
        raise GCPError(f"{path}: no header row (expected columns {', '.join(required)})")
    header_line = lines[i].strip()
    delim = _delimiter(header_line)
    cols = _header_map(next(csv.reader([header_line], delimiter=delim)), spec)
    rows = []
    for ln in range(i + 1, len(lines)):
        s = lines[ln].strip()
        if not s or s.startswith("#"):
            continue
        cells = [c.strip() for c in next(csv.reader([s], delimiter=delim))]
        rows.append((ln + 1, cells))
    return crs, crs_line, cols, rows, delim != ","


def csv_points_preview(path: PathLike) -> Tuple[Optional[str], List[Tuple[float, float]]]:
    """(the CRS the points file names or None, the (x, y) of its rows that read as numbers): a look at a CSV points
    file before its CRS is settled (``read_csv_gcps`` checks the rest)."""
    file_crs, _, cols, rows, comma = _csv_table(path, _POINT_COLS, ("name", "x", "y", "z"), "points")
    xy = []
    for _ln, cells in rows:
        x, y = (_decimal(_cell(cells, cols, k), comma) for k in ("x", "y"))
        if _is_number(x) and _is_number(y):
            xy.append((float(x), float(y)))
    return file_crs, xy


def _cell(cells: Sequence[str], cols: Mapping[str, int], key: str) -> str:
    k = cols.get(key)
    return cells[k] if k is not None and k < len(cells) else ""


def default_observations_path(points_path: PathLike) -> str:
    """``<dir>/<stem>_observations.csv`` for a points file ``<dir>/<stem>.csv``."""
    stem, _ = os.path.splitext(os.fspath(points_path))
    return f"{stem}_observations.csv"


def read_csv_gcps(points_path: PathLike, observations_path: Optional[PathLike] = None, *,
                  crs: Optional[str] = None, image_names: Optional[Iterable[str]] = None,
                  image_sizes: Optional[ImageSizes] = None, unknown_images: str = "warn",
                  default_crs: Optional[str] = None,
                  upright_orientations: Optional[Mapping[str, int]] = None) -> GCPSet:
    """Read GCPs from a points CSV and an observations CSV (format in the module docstring).

    ``crs`` overrides a CRS found in the points file; ``default_crs`` (an algorithm's CRS parameter) is the CRS
    of a points file that names none; one of the three is required.  Without
    ``observations_path`` the file ``default_observations_path(points_path)`` is read if it exists.
    Validation as for ``read_odm_gcp_list``.
    """
    file_crs, crs_line, cols, rows, comma = _csv_table(points_path, _POINT_COLS, ("name", "x", "y", "z"), "points")
    given = crs or (default_crs if not file_crs else None)
    use_crs = normalize_crs(given) if given else file_crs
    if not use_crs:
        raise GCPError(f"{points_path}: no CRS: give it as the crs argument (the algorithm's CRS parameter) or as "
                       "a line '# crs: EPSG:xxxx' before the header")
    gs = GCPSet(crs=use_crs, source=str(points_path))
    _check_crs_for_file(use_crs, points_path, crs_line if not given else None, gs.warnings)
    defaults = GroundPoint("", 0.0, 0.0, 0.0)
    first_line: Dict[str, int] = {}
    for lineno, cells in rows:
        name = _cell(cells, cols, "name")
        if not name:
            raise GCPError(f"{points_path}:{lineno}: empty point name")
        if name in first_line:
            raise GCPError(f"{points_path}:{lineno}: point {name} already defined on line {first_line[name]}")
        x, y, z = (_num(_cell(cells, cols, k), k, points_path, lineno, comma) for k in ("x", "y", "z"))
        sig = {}
        for k in ("sx", "sy", "sxy", "sz"):
            t = _cell(cells, cols, k)
            if t:
                v = _num(t, {"sx": "sx", "sy": "sy", "sxy": "sigma_xy", "sz": "sz"}[k], points_path, lineno, comma)
                if v <= 0:
                    raise GCPError(f"{points_path}:{lineno}: sigma {k} must be positive, got {t!r}")
                sig[k] = v
        if "sxy" in sig:
            sigma_xy = sig["sxy"]
        elif "sx" in sig or "sy" in sig:
            sigma_xy = max(sig.get("sx", 0.0), sig.get("sy", 0.0))
        else:
            sigma_xy = defaults.sigma_xy
        role_text = _cell(cells, cols, "role").strip().lower()
        if role_text not in _ROLES:
            raise GCPError(f"{points_path}:{lineno}: unknown role {role_text!r} for point {name} "
                           f"(use '{CONTROL}' or '{CHECK}')")
        sigma_z = sig.get("sz", defaults.sigma_z)
        gs.points.append(GroundPoint(name, x, y, z, sigma_xy, sigma_z, _ROLES[role_text], sigma_given=bool(sig)))
        first_line[name] = lineno
    if not gs.points:
        gs.warnings.append(f"{points_path}: no points")

    obs_lines: Dict[int, List[int]] = {}
    obs_path = observations_path if observations_path is not None else default_observations_path(points_path)
    if observations_path is None and not os.path.exists(obs_path):
        gs.warnings.append(f"{points_path}: no observations file ({obs_path} does not exist): the points "
                           "have no image observations")
    else:
        _, _, ocols, orows, ocomma = _csv_table(obs_path, _OBS_COLS, ("name", "image", "px", "py"), "observations")
        for lineno, cells in orows:
            name = _cell(cells, ocols, "name")
            p = gs.by_name(name)
            if p is None:
                raise GCPError(f"{obs_path}:{lineno}: observation of unknown point {name!r} "
                               f"(not in {points_path})")
            img = _cell(cells, ocols, "image")
            if not img:
                raise GCPError(f"{obs_path}:{lineno}: empty image name")
            px = _num(_cell(cells, ocols, "px"), "px", obs_path, lineno, ocomma)
            py = _num(_cell(cells, ocols, "py"), "py", obs_path, lineno, ocomma)
            p.observations.append(Observation(img, px, py))
            obs_lines.setdefault(id(p), []).append(lineno)
    where = {id(p): f"{points_path}:{first_line[p.name]}" for p in gs.points}
    return _finish_checked(gs, obs_lines, obs_path, points_path,
                           _Photos(image_names, image_sizes, unknown_images, upright_orientations), where)


def _csv_text(rows: Iterable[Sequence[Any]]) -> str:
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    for r in rows:
        w.writerow(r)
    return buf.getvalue()


def write_csv_gcps(gcpset: GCPSet, points_path: PathLike,
                   observations_path: Optional[PathLike] = None) -> Tuple[str, str]:
    """Write the CSV pair; returns (points path, observations path).  The points file starts with a
    ``# crs: ...`` comment line, then ``name,x,y,z,sx,sy,sz,role`` (sx = sy = sigma_xy; empty for a point
    whose sigmas were not given, so that it reads back the same)."""
    obs_path = os.fspath(observations_path) if observations_path is not None \
        else default_observations_path(points_path)
    head = f"# crs: {' '.join(gcpset.crs.split())}\n"
    pts = [("name", "x", "y", "z", "sx", "sy", "sz", "role")]
    obs = [("name", "image", "px", "py")]
    for p in gcpset.points:
        sig = (_fmt(p.sigma_xy), _fmt(p.sigma_xy), _fmt(p.sigma_z)) if p.sigma_given else ("", "", "")
        pts.append((p.name, _fmt(p.x), _fmt(p.y), _fmt(p.z), *sig, p.role))
        for o in p.observations:
            obs.append((p.name, o.image, _fmt(o.x), _fmt(o.y)))
    _write_text(points_path, head + _csv_text(pts))
    _write_text(obs_path, _csv_text(obs))
    return os.fspath(points_path), obs_path


# --------------------------------------------------------------------------------------------------
# dispatch
# --------------------------------------------------------------------------------------------------

def detect_gcp_format(path: PathLike) -> str:
    """'csv' or 'odm': by extension (.csv), else by content (a header row naming name, x, y columns)."""
    if os.fspath(path).lower().endswith(".csv"):
        return "csv"
    for line in _read_lines(path):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = next(csv.reader([s], delimiter=_delimiter(s)))
        if all(k in _header_map(cells, _POINT_COLS) for k in ("name", "x", "y")) and len(cells) >= 4:
            return "csv"
        if looks_like_crs(s):
            continue  # a CRS line: the next line decides
        return "odm"
    return "odm"


def read_gcps(path: PathLike, image_names: Optional[Iterable[str]] = None,
              image_sizes: Optional[ImageSizes] = None, *, observations_path: Optional[PathLike] = None,
              crs: Optional[str] = None, unknown_images: str = "warn", default_crs: Optional[str] = None,
              upright_orientations: Optional[Mapping[str, int]] = None) -> GCPSet:
    """Read ground control from an OpenDroneMap gcp_list.txt or a CSV points file (+ observations file).

    ``crs``, ``default_crs`` (the CRS of a file that names none) and ``observations_path`` apply to the CSV form
    only (a gcp_list.txt always names its CRS).  See ``read_odm_gcp_list`` for
    ``image_names``, ``image_sizes``, ``unknown_images`` and ``upright_orientations``.
    """
    if detect_gcp_format(path) == "csv":
        return read_csv_gcps(path, observations_path, crs=crs, image_names=image_names,
                             image_sizes=image_sizes, unknown_images=unknown_images, default_crs=default_crs,
                             upright_orientations=upright_orientations)
    return read_odm_gcp_list(path, image_names, image_sizes, unknown_images=unknown_images,
                             upright_orientations=upright_orientations)


def write_gcps(gcpset: GCPSet, path: PathLike, observations_path: Optional[PathLike] = None) -> None:
    """Write ``gcpset`` as CSV (``.csv``: points + observations files) or as an ODM gcp_list.txt."""
    if os.fspath(path).lower().endswith(".csv"):
        write_csv_gcps(gcpset, path, observations_path)
    else:
        write_odm_gcp_list(gcpset, path)


def gcps_from_rows(rows: Iterable[Mapping[str, Any]], crs: str, *, source_name: str = "layer",
                   image_names: Optional[Iterable[str]] = None, image_sizes: Optional[ImageSizes] = None,
                   unknown_images: str = "warn", upright_orientations: Optional[Mapping[str, int]] = None) -> GCPSet:
    """Ground control from table rows, one row per observation (e.g. the features of a QGIS point layer).

    Each row is a mapping with keys (case-insensitive) ``name``, ``x``, ``y``, ``z``, ``image``, ``px``,
    ``py`` and optionally ``sx``, ``sy``, ``sigma_xy``, ``sz``, ``role`` (same meaning as in the CSV form).
    Rows of the same name must carry the same coordinates; sigmas and role come from the point's first row.
    Messages name ``source_name`` and the row number (1-based).  Validation as for ``read_odm_gcp_list``.
    """
    gs = GCPSet(crs=normalize_crs(crs), source=source_name)
    _check_crs_for_file(gs.crs, source_name, None, gs.warnings)
    first: Dict[str, int] = {}
    obs_lines: Dict[int, List[int]] = {}
    defaults = GroundPoint("", 0.0, 0.0, 0.0)

    def num(v: Any, what: str, row: int) -> float:
        tok = "" if v is None else str(v).strip()
        try:
            return _num(tok, what, source_name, row)
        except GCPError as e:
            raise GCPError(str(e).replace(f"{source_name}:{row}:", f"{source_name}: row {row}:", 1)) from None

    for k, raw in enumerate(rows, start=1):
        # a QGIS NULL (an empty attribute, e.g. a sigma not given) is missing, as None is
        r = {str(key).strip().lower(): (None if _is_null(v) else v) for key, v in raw.items()}
        name = str(r.get("name") if r.get("name") is not None else "").strip()
        if not name:
            raise GCPError(f"{source_name}: row {k}: empty point name")
        x, y, z = (num(r.get(c), c, k) for c in ("x", "y", "z"))
        image = str(r.get("image") if r.get("image") is not None else "").strip()
        if not image:
            raise GCPError(f"{source_name}: row {k}: empty image name (point {name})")
        px, py = num(r.get("px"), "px", k), num(r.get("py"), "py", k)
        p = gs.by_name(name)
        if p is None:
            sig = {c: num(r[c], c, k) for c in ("sx", "sy", "sigma_xy", "sz")
                   if r.get(c) is not None and str(r[c]).strip() != ""}
            if any(v <= 0 for v in sig.values()):
                raise GCPError(f"{source_name}: row {k}: sigmas must be positive (point {name})")
            sxy = sig.get("sigma_xy", max(sig.get("sx", 0.0), sig.get("sy", 0.0)) or defaults.sigma_xy)
            role_text = str(r.get("role") or "").strip().lower()
            if role_text not in _ROLES:
                raise GCPError(f"{source_name}: row {k}: unknown role {role_text!r} for point {name} "
                               f"(use '{CONTROL}' or '{CHECK}')")
            p = GroundPoint(name, x, y, z, sxy, sig.get("sz", defaults.sigma_z), _ROLES[role_text],
                            sigma_given=bool(sig))
            gs.points.append(p)
            first[name] = k
        elif (p.x, p.y, p.z) != (x, y, z):
            raise GCPError(f"{source_name}: row {k}: point {name} has coordinates ({x}, {y}, {z}) here but "
                           f"({p.x}, {p.y}, {p.z}) in row {first[name]}")
        p.observations.append(Observation(image, px, py))
        obs_lines.setdefault(id(p), []).append(k)
    if not gs.points:
        gs.warnings.append(f"{source_name}: no ground control rows")
    _finish(gs, obs_lines, source_name, _Photos(image_names, image_sizes, unknown_images, upright_orientations),
            unit="row")
    _check_units(gs, source_name)
    return gs


def _is_null(v: Any) -> bool:
    """None, or a NULL attribute value of a layer (a QVariant, whose isNull() says so; no Qt import here)."""
    is_null = getattr(v, "isNull", None)
    return v is None or (callable(is_null) and bool(is_null()))


def check_units(gcpset: GCPSet, target_crs: Optional[str] = None) -> None:
    """Raise GCPError when the points' coordinates do not fit the CRS they are expressed in
    (``gcpset.crs``; ``target_crs`` only when the set has none) - degrees labelled as metres or the reverse.
    ``read_gcps`` and ``gcps_from_rows`` already run this check."""
    crs = gcpset.crs or target_crs
    if crs and gcpset.points:
        check_coordinates_match_crs(crs, [(p.x, p.y) for p in gcpset.points], "GCP coordinates",
                                    gcpset.source)


def apply_check_points(gcpset: GCPSet, names: Union[str, Iterable[str], None]) -> GCPSet:
    """Mark the named points as check points (role CHECK); ``names`` is a comma-separated string or an
    iterable of names (blanks ignored).  An unknown name raises GCPError listing the known names.  Other
    points keep their role.  Returns ``gcpset`` (changed in place)."""
    if names is None:
        return gcpset
    items = names.split(",") if isinstance(names, str) else list(names)
    wanted = [n.strip() for n in items if n and n.strip()]
    missing = [n for n in wanted if gcpset.by_name(n) is None]
    if missing:
        known = ", ".join(p.name for p in gcpset.points) or "(none)"
        raise GCPError(f"unknown check point name(s): {', '.join(missing)}; known points: {known}")
    for n in wanted:
        gcpset.by_name(n).role = CHECK
    return gcpset


# --------------------------------------------------------------------------------------------------
# camera positions
# --------------------------------------------------------------------------------------------------

_CAM_COLS = {
    "image": ("image", "image_name", "imagename", "name", "file", "filename", "file_name", "photo", "label"),
    "x": ("x", "easting", "east", "lon", "longitude"),
    "y": ("y", "northing", "north", "lat", "latitude"),
    "z": ("z", "alt", "altitude", "height", "h", "elevation", "ellipsoidal_height"),
    "sigma": ("sigma", "accuracy", "std", "sigma_xyz", "acc"),
    "sxy": ("sigma_xy", "sxy", "accuracy_xy", "std_xy", "horizontal_accuracy"),
    "sz": ("sigma_z", "sz", "accuracy_z", "std_z", "vertical_accuracy"),
}


def _split_row(s: str, sep: Optional[str] = None) -> List[str]:
    """The cells of a row: split at ``sep`` (the file's separator, ``_file_separator``; a tab: at blanks, as
    before, so that tabs and spaces mixed still split), else at the first of comma, semicolon found, else at
    blanks."""
    if sep == ";":
        return [c.strip() for c in s.split(sep)]
    if sep == "," or (sep is None and "," in s):
        return [c.strip() for c in next(csv.reader([s]))]
    if sep is None and ";" in s:
        return [c.strip() for c in s.split(";")]
    return s.split()


def _file_separator(rows: Sequence[str]) -> Optional[str]:
    """The separator of a positions file's rows (header and data, no comments or CRS line): ``;`` or a tab when
    every row holds one (then a comma in a number is a decimal comma: a spreadsheet's export in such a locale),
    else a comma when every row holds one, else None (blanks, or rows that differ: each row is split alone)."""
    for sep in (";", "\t", ","):
        if rows and all(sep in r for r in rows):
            return sep
    return None


def _same_position(a: CameraPosition, b: CameraPosition) -> Tuple[bool, float, float]:
    """(the two rows agree within their sigmas, horizontal distance, height difference)."""
    dxy = math.hypot(a.x - b.x, a.y - b.y)
    dz = abs(a.z - b.z) if math.isfinite(a.z) and math.isfinite(b.z) else 0.0
    return dxy <= max(a.sigma_xy, b.sigma_xy) and dz <= max(a.sigma_z, b.sigma_z), dxy, dz


def _position_num(tok: str, what: str, path: PathLike, lineno: int, sep: Optional[str]) -> float:
    """A number of a positions file; a cell that still holds another separator (rows split at the wrong one)
    names the separator and the decimal comma."""
    try:
        return _num(tok, what, path, lineno, sep in (";", "\t"))
    except GCPError as e:
        others = [n for c, n in ((";", "';'"), ("\t", "a tab")) if c in tok and c != sep]
        if not others:
            raise
        raise GCPError(f"{e}: the cell holds {others[0]}, which separates some rows but not all; use one separator "
                       "for the whole file (';' with decimal commas, as a spreadsheet exports them, is read)") from None


def read_camera_positions(path: PathLike, default_sigma_xy: float = 5.0, default_sigma_z: float = 10.0, *,
                          crs: Optional[str] = None, warnings: Optional[List[str]] = None
                          ) -> Tuple[Optional[str], List[CameraPosition]]:
    """Read projection-centre positions, one image per row.  Returns (crs or None, positions).

    Accepted rows (comma, semicolon or whitespace separated; blank and ``#`` lines skipped):

    * an optional first line holding the CRS (as in gcp_list.txt; e.g. ``EPSG:32617``);
    * an optional header row naming the columns (image, x, y, z, sigma | sigma_xy, sigma_z);
    * without a header: ``image x y [z [sigma [sigma_z]]]`` (image first) or ``x y [z] image`` (image last,
      OpenDroneMap's geo.txt order).

    One ``sigma`` applies to all three axes; ``sigma_xy`` / ``sigma_z`` columns set them separately; missing
    sigmas take ``default_sigma_xy`` / ``default_sigma_z`` and mark the position ``sigma_given=False`` (the
    georeferencing then estimates their accuracy).  A missing z (e.g. ``x y image`` rows) is NaN,
    meaning unknown height: a consumer must then constrain only x and y of that camera.

    The separator is the file's: ``;`` or a tab when every row holds one, and then a comma inside a number is a
    decimal comma (``274901,848``: a spreadsheet saved in a locale that writes them).

    The returned CRS is the file's CRS line, else ``crs`` (None when neither: the caller's CRS, usually the
    GCPs', is meant).  Unparsable numbers and invalid CRSs raise GCPError (file:line: reason).  An image on two
    rows: when the rows agree within their sigmas the first is used and a warning naming the image and both
    lines is added to ``warnings`` (a list you pass; a Python warning when no list is given); when they do not,
    GCPError naming the image, both lines and how far apart they are.
    """
    if not (default_sigma_xy > 0 and default_sigma_z > 0):
        raise ValueError("default sigmas must be positive")
    warn_list: List[str] = []
    lines = _read_lines(path)
    file_crs: Optional[str] = None
    crs_line = None
    cols: Optional[Dict[str, int]] = None
    out: List[CameraPosition] = []
    first_row: Dict[str, Tuple[int, CameraPosition]] = {}
    content = [(ln, raw.strip()) for ln, raw in enumerate(lines, start=1)
               if raw.strip() and not raw.strip().startswith("#")]
    if content and looks_like_crs(content[0][1]):
        file_crs, crs_line = normalize_crs(content[0][1]), content[0][0]
        content = content[1:]
    sep = _file_separator([s for _, s in content])
    comma = sep in (";", "\t")  # the comma is free for decimals
    for ln, s in content:
        cells = _split_row(s, sep)
        if cols is None and not out:
            hm = _header_map(cells, _CAM_COLS)
            if all(k in hm for k in ("image", "x", "y")) and not any(_is_number(c, comma) for c in cells):
                cols = hm
                continue
        if cols is not None:
            image = _cell(cells, cols, "image")
            vals = {k: _cell(cells, cols, k) for k in ("x", "y", "z", "sigma", "sxy", "sz")}
        else:
            nonnum = [k for k, c in enumerate(cells) if not _is_number(c, comma)]
            if len(cells) < 3:
                raise GCPError(f"{path}:{ln}: expected 'image x y [z] [sigma]' or 'x y [z] image', "
                               f"found {s!r}")
            if nonnum and nonnum[0] == 0 and len(nonnum) == 1 and 3 <= len(cells) <= 6:
                image, nums = cells[0], cells[1:]
                keys = ("x", "y", "z", "sigma", "sz")[:len(nums)]
                if len(nums) == 5:
                    keys = ("x", "y", "z", "sxy", "sz")
            elif nonnum == [len(cells) - 1] and len(cells) in (3, 4):
                image, nums = cells[-1], cells[:-1]
                keys = ("x", "y", "z")[:len(nums)]
            else:
                bad = next((cells[k] for k in nonnum if 0 < k < len(cells) - 1), None)
                if bad is not None:
                    raise GCPError(f"{path}:{ln}: not a number: {bad!r} (expected 'image x y [z] [sigma]' or "
                                   f"'x y [z] image')")
                raise GCPError(f"{path}:{ln}: cannot tell the image name from the coordinates in {s!r} "
                               "(expected 'image x y [z] [sigma]' or 'x y [z] image')")
            vals = dict(zip(keys, nums))
        if not image:
            raise GCPError(f"{path}:{ln}: empty image name")
        x = _position_num(vals.get("x", ""), "x", path, ln, sep)
        y = _position_num(vals.get("y", ""), "y", path, ln, sep)
        z = _position_num(vals["z"], "z", path, ln, sep) if vals.get("z") else float("nan")
        sig = {}
        for k in ("sigma", "sxy", "sz"):
            if vals.get(k):
                v = _position_num(vals[k], {"sigma": "sigma", "sxy": "sigma_xy", "sz": "sigma_z"}[k], path, ln, sep)
                if v <= 0:
                    raise GCPError(f"{path}:{ln}: sigma must be positive, got {vals[k]!r}")
                sig[k] = v
        sxy = sig.get("sxy", sig.get("sigma", default_sigma_xy))
        sz = sig.get("sz", sig.get("sigma", default_sigma_z))
        pos = CameraPosition(image, x, y, z, sxy, sz, sigma_given=bool(sig))
        if image in first_row:
            first_ln, first = first_row[image]
            same, dxy, dz = _same_position(first, pos)
            if not same:
                raise GCPError(f"{path}: image {image} is on lines {first_ln} and {ln} with positions {dxy:.2f} m "
                               f"apart horizontally, {dz:.2f} m in height: more than their sigmas (XY "
                               f"{max(first.sigma_xy, pos.sigma_xy):g} m, Z {max(first.sigma_z, pos.sigma_z):g} m); "
                               "keep the right row and remove the other")
            warn_list.append(f"{path}: image {image} is on lines {first_ln} and {ln} (positions {dxy:.2f} m apart, "
                             f"within their sigmas): the first (line {first_ln}) is used")
            continue
        first_row[image] = (ln, pos)
        out.append(pos)
    use_crs = file_crs or (normalize_crs(crs) if crs else None)
    if use_crs:
        _check_crs_for_file(use_crs, path, crs_line if file_crs else None, warn_list)
        if out:
            check_coordinates_match_crs(use_crs, [(c.x, c.y) for c in out], "camera positions", str(path))
    if warnings is not None:
        warnings.extend(warn_list)
    else:
        for w in warn_list:
            _warnings.warn(w, stacklevel=2)
    return use_crs, out


__all__ = [
    "CHECK", "CONTROL", "CameraPosition", "DEFAULT_SIGMA_XY", "DEFAULT_SIGMA_Z", "GCPError", "GCPSet", "GroundPoint", "Observation", "apply_check_points",
    "check_units", "csv_points_preview", "default_observations_path", "detect_gcp_format", "gcps_from_rows",
    "observations_to_stored",
    "read_camera_positions",
    "read_csv_gcps", "read_gcps", "read_odm_gcp_list", "write_csv_gcps", "write_gcps", "write_odm_gcp_list",
]


def _odm_target_line(toks: List[str], path: PathLike, lineno: int):
    """x, y, z, name and the click (an Observation, or None) of one line of a targets file in the gcp_list.txt
    form, with or without pixel columns."""
    if len(toks) < 4:
        raise GCPError(f"{path}:{lineno}: expected 'x y z name' or 'x y z px py image name', found {len(toks)} "
                       f"field(s): {' '.join(toks)!r}")
    x, y, z = (_num(toks[k], w, path, lineno) for k, w in ((0, "x"), (1, "y"), (2, "z")))
    if len(toks) in (4, 5) and not _is_number(toks[3]):
        return x, y, z, toks[3], None  # x y z name [check]
    if len(toks) >= 6 and _is_number(toks[3]) and _is_number(toks[4]):  # x y z px py image [name]
        return x, y, z, toks[6] if len(toks) > 6 else None, Observation(toks[5], float(toks[3]), float(toks[4]))
    raise GCPError(f"{path}:{lineno}: expected 'x y z name' or 'x y z px py image name', found {len(toks)} "
                   f"field(s): {' '.join(toks)!r}")


def read_target_coordinates(path: PathLike, default_crs: Optional[str] = None) -> GCPSet:
    """Surveyed targets for Find targets: a CSV points file (``name,x,y,z[,sigma_xy,sigma_z]``, with its observations
    file if there is one) or a gcp_list.txt whose pixel columns may be absent (``x y z name``) or present on some
    lines only (``x y z px py image name``).  Pixel columns, where present, are the user's clicks: kept as the
    points' observations (Find targets names the marks they fall on).  ``default_crs``: the CRS of a file that
    names none (a gcp_list.txt without its CRS line); none at all is a GCPError saying to give it.  Points without
    a name are named by their coordinates' order (``gcp_<n>``); one name with two positions is an error naming
    both lines."""
    if detect_gcp_format(path) == "csv":
        gs = read_csv_gcps(path, default_crs=default_crs)
        gs.warnings = [w for w in gs.warnings if "no observations file" not in w and "no usable observation" not in w]
        return gs
    rows: List[Tuple[int, List[str]]] = []
    for n, line in enumerate(_read_lines(path), start=1):
        s = line.split("#", 1)[0].strip()
        if s:
            rows.append((n, s.split()))
    if not rows:
        raise GCPError(f"{path}: empty: no targets")
    first_n, first = rows[0]
    if len(first) >= 4 and all(_is_number(t) for t in first[:3]):
        if not default_crs:
            raise GCPError(f"{path}:{first_n}: no CRS line before the first target: give the CRS (the "
                           "algorithm's CRS parameter) or add it as the file's first line (e.g. EPSG:32611)")
        crs = normalize_crs(default_crs)
    else:
        crs = normalize_crs(" ".join(first))
        rows = rows[1:]
    gs = GCPSet(crs=crs, source=str(path))
    _check_crs_for_file(crs, path, first_n, gs.warnings)
    seen: Dict[str, Tuple[GroundPoint, int]] = {}
    by_xyz: Dict[Tuple[float, float, float], GroundPoint] = {}
    for lineno, toks in rows:
        x, y, z, name, click = _odm_target_line(toks, path, lineno)
        if name is None:
            p = by_xyz.get((x, y, z))
            if p is None:
                name = f"gcp_{len(gs.points) + 1}"
            else:
                p.observations += [click] if click else []
                continue
        if name in seen:
            p, first_line = seen[name]
            if (p.x, p.y, p.z) != (x, y, z):
                raise GCPError(f"{path}:{lineno}: target {name} has coordinates ({x}, {y}, {z}) here but "
                               f"({p.x}, {p.y}, {p.z}) on line {first_line}")
            p.observations += [click] if click else []
            continue
        p = GroundPoint(name, x, y, z, sigma_given=False, observations=[click] if click else [])
        seen[name] = (p, lineno)
        by_xyz.setdefault((x, y, z), p)
        gs.points.append(p)
    if not gs.points:
        raise GCPError(f"{path}: no targets")
    return gs
