"""Camera calibrations from files: a metric camera's certificate, or another program's calibration.

``read_calibration(path)`` returns one :class:`CameraCalibration` per camera in the file; the format is told
from the content (and the extension where the content could be two things).  docs/calibration.md is the
user's description of every format; this docstring is the implementer's summary.

Pixels: COLMAP's convention everywhere in the result -- (0, 0) is the upper-left corner of the upper-left
pixel, x right, y down, so the centre of a w x h image is (w/2, h/2).  Distortion: OpenCV's Brown model on
normalised coordinates (x = X/Z, y = Y/Z with COLMAP's camera axes): radial k1, k2, k3 and tangential p1, p2
(x' = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2), y' likewise with p1 and p2 swapped).

Formats and how each one's principal point is converted (w, h: the image size in pixels)
--------------------------------------------------------------------------------------
ArchaeoOrtho YAML / JSON (ours)
    ``principal_point_mm: [x0, y0]`` from the image centre (taken as the fiducial centre), x right and
    *y up* as in a calibration certificate: cx = w/2 + x0/px, cy = h/2 - y0/py (px, py: pixel size in mm);
    ``principal_point_px: [cx, cy]`` is already in our convention.  A radial distortion table
    (radius mm -> distortion um, positive outward) is fitted with k1..k3 by least squares.
Orthority interior parameters (YAML)
    ``cx, cy`` are offsets from the centre normalised by max(w, h), y down, and Orthority puts pixel
    centres at integers: cx = (w - 1)/2 + 0.5 + max(w, h) cx_o = w/2 + max(w, h) cx_o.  ``focal_len`` with
    ``sensor_size`` is in the sensor's units (fx = focal_len w / sensor_w, fy = focal_len h / sensor_h);
    without it, Orthority's code multiplies by the image width (its docs say max(w, h): a note is added when
    the two differ, i.e. for a portrait image).
OpenCV FileStorage (YAML / XML: camera_matrix, distortion_coefficients, image_width, image_height)
    OpenCV puts pixel centres at integers: cx = cx_cv + 0.5, cy = cy_cv + 0.5.
COLMAP cameras.txt
    Our convention already.
Metashape calibration XML (Tools > Camera Calibration > Save; or a cameras export's sensors)
    ``cx, cy`` are offsets from the image centre in pixels, y down: cx = w/2 + cx_m, cy = h/2 + cy_m.
    Metashape's model (manual, appendix C): u = w/2 + cx + x'(f + B1) + y' B2, v = h/2 + cy + y' f, its
    tangential terms are x' += P1 (r^2 + 2x^2) + 2 P2 x y, so OpenCV's p1 = P2 and p2 = P1, and
    fx = f + B1, fy = f.  B2 (skew) has no COLMAP counterpart: dropped with a note when it moves the frame's
    edge by less than half a pixel, an error otherwise.

Every problem is a :class:`CalibrationError` whose message names the file, the line where the format gives
one, and the field.
"""
from __future__ import annotations

import fnmatch
import json
import json.decoder
import json.scanner
import math
import os
import re
from dataclasses import dataclass, field, fields
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError, MissingDependencyError
from ..geometry.camera import MODELS

ADJUST_MODES = ("fixed", "refined", "estimated")

# the parameters a calibration holds (OpenCV / Brown order of the distortion terms)
DISTORTION_TERMS = ("k1", "k2", "k3", "p1", "p2")
# a scaled image may differ from the calibrated one's aspect ratio by this much (rounding of a resampled scan)
ASPECT_TOLERANCE = 0.01
# focal lengths this close are one focal (floating-point noise of unit conversions, not a tolerance on data)
_SAME_FOCAL = 1e-9
# Metashape's skew B2 is dropped when it moves the frame's edge by less than half a pixel (it cannot move any
# point out of its pixel); beyond that the camera is not one COLMAP can hold
SKEW_LIMIT_PX = 0.5
# a radial distortion table needs at least as many radii (> 0) as the coefficients it determines
_TABLE_TERMS = 3


class CalibrationError(ArchaeoOrthoError, ValueError):
    """A camera calibration file cannot be used; the message names the file, the line and the field.

    ``CalibrationError(file, line, field, problem)`` gives "file.yaml, line 7: problem" (``file``, ``line`` and
    ``field`` kept as attributes); ``CalibrationError(message)`` is a plain message."""

    def __init__(self, file: str, line: Optional[int] = None, fieldname: str = "", problem: Optional[str] = None):
        if problem is None:  # a plain message
            file, problem = "", file
        self.file = file
        self.line = line
        self.field = fieldname
        self.problem = problem
        where = os.path.basename(file) if file else ""
        if where and line:
            where += f", line {line}"
        super().__init__(f"{where}: {problem}" if where else problem)

    def __reduce__(self):  # pickled across process pools with its attributes
        return type(self), (self.file, self.line, self.field, self.problem)


@dataclass
class CameraCalibration:
    """One camera's interior orientation, in pixels of a ``width`` x ``height`` image (COLMAP's convention).

    ``focal_y_px`` is None for square pixels; ``sigmas`` holds a priori standard deviations under the names
    focal_px, cx_px, cy_px (pixels) and k1..p2; ``pixel_size_mm`` is the x pixel size (y's is
    pixel_size_mm * fy / fx); ``fiducials_mm`` are x right, y up from the fiducial centre; ``notes`` say what
    the reader assumed or dropped (for the log)."""

    name: str
    source: str
    width: int
    height: int
    focal_px: float
    focal_y_px: Optional[float]
    cx_px: float
    cy_px: float
    k1: float = 0.0
    k2: float = 0.0
    k3: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    sigmas: Dict[str, float] = field(default_factory=dict)
    adjust: Optional[str] = None
    images: List[str] = field(default_factory=list)
    pixel_size_mm: Optional[float] = None
    fiducials_mm: Dict[str, Tuple[float, float]] = field(default_factory=dict)
    focal_mm: Optional[float] = None
    notes: List[str] = field(default_factory=list)  # what the reader assumed or dropped (the caller names the camera)
    warnings: List[str] = field(default_factory=list)  # assumptions that may well be wrong (the log warns)
    size_field: str = ""  # the field that gave the image size and its line (for messages about the size)
    size_line: Optional[int] = None

    @property
    def fx(self) -> float:
        return self.focal_px

    @property
    def fy(self) -> float:
        return self.focal_px if self.focal_y_px is None else self.focal_y_px

    @property
    def has_distortion(self) -> bool:
        return any(getattr(self, t) != 0.0 for t in DISTORTION_TERMS)

    def label(self) -> str:
        return f"camera '{self.name}'" if self.name else "the camera"

    def applies_to(self, image_name: str) -> bool:
        """Whether ``image_name`` (a file name; folders are ignored) matches one of ``images`` (case-insensitive
        globs).  A calibration without patterns applies to no image by itself: the caller decides."""
        base = os.path.basename(image_name.replace("\\", "/")).lower()
        return any(fnmatch.fnmatchcase(base, p.lower()) or fnmatch.fnmatchcase(image_name.lower(), p.lower())
                   for p in self.images)

    def scaled_to(self, width: int, height: int, image_name: str = "") -> CameraCalibration:
        """The same camera for an image of ``width`` x ``height`` pixels (a scan at another resolution, a
        downscaled copy): pixel values scale about the image corner, millimetre values stay.  ``image_name``
        names the image in the message of a size that does not fit (another aspect ratio)."""
        if width <= 0 or height <= 0:
            raise CalibrationError(self.source, None, "width",
                                   f"{self.label()}: the image size must be positive, got {width} x {height}")
        sx, sy = width / self.width, height / self.height
        if abs(sx / sy - 1.0) > ASPECT_TOLERANCE:
            what = f"the photo {image_name}" if image_name else "an image"
            given = f" ({self.size_field})" if self.size_field else ""
            raise CalibrationError(
                self.source, self.size_line, self.size_field or "image_size_px",
                f"{self.label()} is calibrated for {self.width} x {self.height} px images{given}; {what} of "
                f"{width} x {height} px has another aspect ratio ({self.width / self.height:.4f} against "
                f"{width / height:.4f}): is it cropped or turned, or is the calibration's image size wrong?")
        fx, fy = self.fx * sx, self.fy * sy
        sig = dict(self.sigmas)
        for key, s in (("focal_px", sx), ("cx_px", sx), ("cy_px", sy)):
            if key in sig:
                sig[key] = sig[key] * s
        return _replace(self, width=int(width), height=int(height), focal_px=fx,
                        focal_y_px=None if _same(fx, fy) else fy, cx_px=self.cx_px * sx, cy_px=self.cy_px * sy,
                        sigmas=sig, pixel_size_mm=None if self.pixel_size_mm is None else self.pixel_size_mm / sx)

    @property
    def principal_point_mm(self) -> Optional[Tuple[float, float]]:
        """(x0, y0) mm from the image centre, x right, y up (the certificate's convention); None without a
        pixel size."""
        if self.pixel_size_mm is None:
            return None
        py = self.pixel_size_mm * self.fx / self.fy
        return (self.cx_px - self.width / 2.0) * self.pixel_size_mm, (self.height / 2.0 - self.cy_px) * py

    def for_resampled_frame(self, width: int, height: int, pixel_size_mm: float) -> CameraCalibration:
        """The camera of images resampled into the calibrated frame with the principal point at their centre
        and square pixels of ``pixel_size_mm`` (what core.prepare.scans writes when given
        :meth:`fiducial_coordinates_text`): focal = focal_mm / pixel size, (cx, cy) = (width/2, height/2); the
        distortion (on normalised coordinates) is unchanged."""
        if self.focal_mm is None or self.pixel_size_mm is None:
            raise CalibrationError(self.source, None, "focal_length_mm",
                                   f"{self.label()}: resampling into the calibrated frame needs the focal "
                                   f"length in mm and the pixel size")
        if width <= 0 or height <= 0 or not pixel_size_mm > 0:
            raise CalibrationError(self.source, None, "pixel_size_mm",
                                   f"{self.label()}: the resampled frame needs a positive size and pixel size, "
                                   f"got {width} x {height} px of {pixel_size_mm} mm")
        sx, sy = self.pixel_size_mm / pixel_size_mm, self.pixel_size_mm * self.fx / self.fy / pixel_size_mm
        sig = dict(self.sigmas)
        for key, s in (("focal_px", sx), ("cx_px", sx), ("cy_px", sy)):
            if key in sig:
                sig[key] = sig[key] * s
        return _replace(self, width=int(width), height=int(height), focal_px=self.focal_mm / pixel_size_mm,
                        focal_y_px=None, cx_px=width / 2.0, cy_px=height / 2.0, sigmas=sig,
                        pixel_size_mm=float(pixel_size_mm))

    def fiducial_coordinates_text(self) -> str:
        """The fiducials, principal point and focal length as core.prepare.scans reads them
        (ScanOptions.fiducial_coordinates): "id x y" lines in mm, "PP x0 y0", "focal f"."""
        if not self.fiducials_mm:
            raise CalibrationError(self.source, None, "fiducials_mm", f"{self.label()} has no fiducials_mm")
        lines = [f"{re.sub(r'[^0-9A-Za-z_.-]+', '_', k)} {x!r} {y!r}" for k, (x, y) in self.fiducials_mm.items()]
        pp = self.principal_point_mm
        if pp is not None:  # to the nanometre: the pixel round trip's float noise (0.011999999999989087) is no value
            lines.append(f"PP {round(pp[0], 9)!r} {round(pp[1], 9)!r}")
        if self.focal_mm is not None:
            lines.append(f"focal {self.focal_mm!r}")
        return "\n".join(lines) + "\n"

    def colmap_model(self) -> Tuple[str, List[float]]:
        """The simplest COLMAP model that holds this camera exactly, and its parameters (pycolmap's order).

        No distortion: PINHOLE (fx, fy, cx, cy; fx = fy for square pixels, the principal point kept).  Radial
        k1 (and k2) only with square pixels: SIMPLE_RADIAL (f, cx, cy, k) / RADIAL (f, cx, cy, k1, k2).
        Otherwise OPENCV (fx, fy, cx, cy, k1, k2, p1, p2), or FULL_OPENCV (..., k3, k4, k5, k6 with k4..k6 = 0)
        when k3 is not zero."""
        fx, fy, cx, cy = float(self.fx), float(self.fy), float(self.cx_px), float(self.cy_px)
        k1, k2, k3, p1, p2 = (float(getattr(self, t)) for t in DISTORTION_TERMS)
        if not self.has_distortion:
            return "PINHOLE", [fx, fy, cx, cy]
        if k3 == 0.0 and p1 == 0.0 and p2 == 0.0 and _same(fx, fy):
            if k2 == 0.0:
                return "SIMPLE_RADIAL", [fx, cx, cy, k1]
            return "RADIAL", [fx, cx, cy, k1, k2]
        if k3 == 0.0:
            return "OPENCV", [fx, fy, cx, cy, k1, k2, p1, p2]
        return "FULL_OPENCV", [fx, fy, cx, cy, k1, k2, p1, p2, k3, 0.0, 0.0, 0.0]

    def to_intrinsics(self):
        """The camera as ``core.geometry.camera.Intrinsics`` (its colmap_model())."""
        from ..geometry.camera import Intrinsics
        model, params = self.colmap_model()
        return Intrinsics(model, self.width, self.height, tuple(params))

    def to_dict(self) -> dict:
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "fiducials_mm":
                v = {k: [float(x), float(y)] for k, (x, y) in v.items()}
            elif isinstance(v, (list, dict)):
                v = type(v)(v)
            out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, d: dict) -> CameraCalibration:
        """The inverse of to_dict (unknown keys are ignored: a newer workspace read by an older plugin)."""
        names = {f.name for f in fields(cls)}
        kw = {k: v for k, v in d.items() if k in names}
        missing = [n for n in ("name", "source", "width", "height", "focal_px", "cx_px", "cy_px") if n not in kw]
        if missing:
            raise CalibrationError(str(d.get("source", "")), None, missing[0],
                                   f"the calibration record lacks {', '.join(missing)}")
        kw.setdefault("focal_y_px", None)
        kw["fiducials_mm"] = {str(k): (float(v[0]), float(v[1])) for k, v in (kw.get("fiducials_mm") or {}).items()}
        kw["sigmas"] = {str(k): float(v) for k, v in (kw.get("sigmas") or {}).items()}
        kw["images"] = [str(p) for p in (kw.get("images") or [])]
        kw["notes"] = [str(n) for n in (kw.get("notes") or [])]
        kw["warnings"] = [str(n) for n in (kw.get("warnings") or [])]
        return cls(**kw)


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= _SAME_FOCAL * max(abs(a), abs(b))


def _replace(cal: CameraCalibration, **changes) -> CameraCalibration:
    d = {f.name: getattr(cal, f.name) for f in fields(cal)}
    d.update(changes)
    for key in ("sigmas", "fiducials_mm"):
        d[key] = dict(d[key])
    for key in ("images", "notes", "warnings"):
        d[key] = list(d[key])
    return CameraCalibration(**d)


def calibration_for_image(calibrations: Sequence[CameraCalibration], image_name: str
                          ) -> Optional[CameraCalibration]:
    """The calibration whose ``images`` patterns match ``image_name``; a single calibration without patterns
    applies to every image; None when none applies.  Two that match is an error naming both."""
    hits = [c for c in calibrations if c.applies_to(image_name)]
    if len(hits) > 1:
        raise CalibrationError(hits[0].source, None, "images",
                               f"the image '{image_name}' matches the images patterns of both "
                               f"{hits[0].label()} and {hits[1].label()}")
    if hits:
        return hits[0]
    if len(calibrations) == 1 and not calibrations[0].images:
        return calibrations[0]
    return None


# ---------------------------------------------------------------------------
# reading: detection
# ---------------------------------------------------------------------------

def read_calibration(path: str) -> List[CameraCalibration]:
    """The cameras of a calibration file (ours in YAML or JSON, Orthority, OpenCV YAML/XML, COLMAP
    cameras.txt, Metashape XML), told apart by their content.  A camera no lens can be (a focal length of no
    camera's field of view, a distortion that folds the image) is refused here, before any work
    (:func:`check_plausible`)."""
    cals = _read_calibration(os.fspath(path))
    for cal in cals:
        check_plausible(cal)
    return cals


def check_plausible(cal: CameraCalibration) -> None:
    """CalibrationError naming the file, the camera and the value when ``cal`` cannot be a camera's: its field of
    view outside what a camera has, or its radial distortion folding the image or moving its corner beyond what a
    lens does (core.geometry.plausible).  Thresholds are ratios to the image (focal length / long side,
    normalised radii), never pixels."""
    from ..geometry import plausible

    for f in {cal.fx, cal.fy}:
        problem = plausible.focal_problem(f, cal.width, cal.height)
        if problem:
            raise CalibrationError(cal.source, None, "focal", f"{cal.label()}: {problem}")
    problem = plausible.distortion_problem(cal.fx, cal.fy, cal.cx_px, cal.cy_px, cal.width, cal.height,
                                           (cal.k1, cal.k2, cal.k3))
    if problem:
        raise CalibrationError(cal.source, None, "k1", f"{cal.label()}: {problem}")


def _read_calibration(path: str) -> List[CameraCalibration]:
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except FileNotFoundError as e:
        raise CalibrationError(path, None, "", "the calibration file does not exist") from e
    except OSError as e:
        raise CalibrationError(path, None, "", f"cannot read the file: {e.strerror or e}") from e
    if b"\0" in raw:
        raise CalibrationError(path, None, "", "the file is not a text file: is it a calibration file?")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:  # a certificate typed on Windows (a 'µ' in a comment): Windows-1252 / Latin-1
        text = raw.decode("cp1252", errors="replace")
    stripped = text.lstrip()
    if not stripped:
        raise CalibrationError(path, None, "", "the file is empty")
    if stripped.startswith("<"):
        return _read_xml(path, text)
    if re.match(r"%YAML[: ]1\.0", stripped) or "!!opencv-matrix" in text:
        return _read_opencv_mapping(path, _load_yaml(path, _opencv_yaml_text(text)))
    if _looks_like_colmap(text):
        return _read_colmap_txt(path, text)
    if stripped.startswith(("{", "[")) or path.lower().endswith(".json"):
        data = _load_json(path, text)
    else:
        data = _load_yaml(path, text)
    return _read_mapping(path, data)


_NOT_A_CALIBRATION = ("not a camera calibration this plugin reads: expected ArchaeoOrtho's format (cameras: / "
                      "focal_length_mm ...), Orthority interior parameters (im_size, focal_len ...), OpenCV "
                      "(camera_matrix ...), COLMAP cameras.txt or Metashape XML; see docs/calibration.md")


def _read_mapping(path: str, data: Any) -> List[CameraCalibration]:
    if not isinstance(data, (dict, list)):  # plain text (a CSV, a note) reads as one YAML value
        raise CalibrationError(path, None, "", _NOT_A_CALIBRATION)
    if not isinstance(data, dict):
        raise CalibrationError(path, _line_of(data), "", "the file must hold a mapping of fields (a calibration "
                                                         "of one or more cameras), not a list or a single value")
    keys = set(data)
    if keys & set(_CV_MATRIX):
        return _read_opencv_mapping(path, data)
    if "cameras" in keys or keys & {"image_size_px", "focal_length_mm", "focal_length_px"}:
        return _read_own(path, data)
    if "im_size" in keys or isinstance(data.get("camera"), dict) or (
            data and all(isinstance(v, dict) and ("im_size" in v or "type" in v) for v in data.values())):
        return _read_orthority(path, data)
    raise CalibrationError(path, _line_of(data), "", _NOT_A_CALIBRATION)


# ---------------------------------------------------------------------------
# parsed values that remember their lines
# ---------------------------------------------------------------------------

class _Map(dict):
    """A mapping from the file, with the line of each value (``lines``) and its own (``line``)."""

    line: Optional[int] = None

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.lines: Dict[Any, int] = {}


class _Seq(list):
    line: Optional[int] = None

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.lines: List[int] = []


def _line_of(obj: Any, key: Any = None) -> Optional[int]:
    if key is not None and isinstance(obj, _Map) and key in obj.lines:
        return obj.lines[key]
    if key is not None and isinstance(obj, _Seq) and isinstance(key, int) and key < len(obj.lines):
        return obj.lines[key]
    return getattr(obj, "line", None)


def _yaml():
    try:
        import yaml
    except ImportError as e:
        raise MissingDependencyError("PyYAML", "reading YAML camera calibrations (JSON files need no extra "
                                               "package)", str(e)) from e
    return yaml


def _load_yaml(path: str, text: str) -> Any:
    yaml = _yaml()

    class Loader(yaml.SafeLoader):
        pass

    def mapping(loader, node):
        m = _Map()
        m.line = node.start_mark.line + 1
        yield m
        for k_node, v_node in node.value:
            key = loader.construct_object(k_node, deep=True)
            try:
                hash(key)
            except TypeError:
                raise CalibrationError(path, k_node.start_mark.line + 1, "", "a key must be a name") from None
            if key in m:
                raise CalibrationError(path, k_node.start_mark.line + 1, str(key),
                                       f"'{key}' is given twice (first on line {m.lines[key]})")
            m[key] = loader.construct_object(v_node, deep=True)
            m.lines[key] = k_node.start_mark.line + 1  # the key's line (a block value starts below it)

    def sequence(loader, node):
        s = _Seq()
        s.line = node.start_mark.line + 1
        yield s
        for v_node in node.value:
            s.append(loader.construct_object(v_node, deep=True))
            s.lines.append(v_node.start_mark.line + 1)

    Loader.add_constructor("tag:yaml.org,2002:map", mapping)
    Loader.add_constructor("tag:yaml.org,2002:seq", sequence)
    try:
        return yaml.load(text, Loader=Loader)  # a SafeLoader: no Python objects
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        line = mark.line + 1 if mark is not None else None
        raise CalibrationError(path, line, "", f"not valid YAML: {e.problem or e}") from None
    except yaml.YAMLError as e:
        raise CalibrationError(path, None, "", f"not valid YAML: {e}") from None


def _load_json(path: str, text: str) -> Any:
    """JSON with line numbers (the pure-Python scanner, whose object and array parsers are wrapped)."""
    def line_at(s: str, idx: int) -> int:
        return s.count("\n", 0, idx) + 1

    def parse_object(s_and_end, strict, scan_once, object_hook, object_pairs_hook, memo=None, _w=None):
        s, end = s_and_end
        starts: List[int] = []

        def scan(string, idx):
            starts.append(idx)
            return scan_once(string, idx)

        def build(pairs):
            m = _Map()
            m.line = line_at(s, end)
            for (k, v), idx in zip(pairs, starts):
                if k in m:
                    raise CalibrationError(path, line_at(s, idx), k, f"'{k}' is given twice")
                m[k] = v
                m.lines[k] = line_at(s, idx)
            return m
        return json.decoder.JSONObject((s, end), strict, scan, None, build, memo if memo is not None else {})

    def parse_array(s_and_end, scan_once, _w=None):
        s, end = s_and_end
        starts: List[int] = []

        def scan(string, idx):
            starts.append(idx)
            return scan_once(string, idx)
        values, new_end = json.decoder.JSONArray((s, end), scan)
        seq = _Seq(values)
        seq.line = line_at(s, end)
        seq.lines = [line_at(s, i) for i in starts]
        return seq, new_end

    decoder = json.JSONDecoder()
    decoder.parse_object = parse_object
    decoder.parse_array = parse_array
    decoder.scan_once = json.scanner.py_make_scanner(decoder)
    try:
        try:
            return decoder.decode(text)
        except (TypeError, AttributeError):  # the json module's internals changed: values without lines
            return json.loads(text)
    except json.JSONDecodeError as e:
        raise CalibrationError(path, e.lineno, "", f"not valid JSON: {e.msg} (column {e.colno})") from None


# ---------------------------------------------------------------------------
# field readers (messages name the file, the line and the field)
# ---------------------------------------------------------------------------

class _Fields:
    """Reads the fields of one camera's mapping; ``who`` names the camera in messages."""

    def __init__(self, path: str, data: dict, who: str = ""):
        self.path, self.data, self.who = path, data, who

    def fail(self, key: str, problem: str, line: Optional[int] = None) -> CalibrationError:
        line = line if line is not None else _line_of(self.data, key)
        prefix = f"{self.who}: " if self.who else ""
        return CalibrationError(self.path, line, key, prefix + problem)

    def has(self, key: str) -> bool:
        return key in self.data and self.data[key] is not None

    def number(self, key: str, positive: bool = False, default: Optional[float] = None) -> Optional[float]:
        if not self.has(key):
            return default
        return self._as_number(key, self.data[key], positive, key)

    def _as_number(self, key: str, value: Any, positive: bool, label: str, line: Optional[int] = None) -> float:
        x = None
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            x = float(value)
        elif isinstance(value, str):
            try:
                x = float(value.strip())
            except ValueError:
                x = None
        if x is None or not math.isfinite(x) or (positive and x <= 0):
            what = "a positive number" if positive else "a number"
            raise self.fail(key, f"{label} must be {what}, got {value!r}", line)
        return x

    def numbers(self, key: str, count: Optional[int] = None, positive: bool = False) -> Optional[List[float]]:
        if not self.has(key):
            return None
        value = self.data[key]
        if not isinstance(value, (list, tuple)) or (count is not None and len(value) != count):
            n = f"{count} numbers [x, y]" if count == 2 else (f"{count} numbers" if count else "a list of numbers")
            raise self.fail(key, f"{key} must be {n}, got {value!r}")
        return [self._as_number(key, v, positive, f"{key}[{i}]", _line_of(value, i)) for i, v in enumerate(value)]

    def size(self, key: str) -> Optional[Tuple[int, int]]:
        v = self.numbers(key, 2, positive=True)
        if v is None:
            return None
        if any(x != int(x) for x in v):
            raise self.fail(key, f"{key} must be whole numbers of pixels [width, height], got {self.data[key]!r}")
        return int(v[0]), int(v[1])

    def text(self, key: str, default: Optional[str] = None) -> Optional[str]:
        if not self.has(key):
            return default
        v = self.data[key]
        if isinstance(v, (dict, list)):
            raise self.fail(key, f"{key} must be a single value, got {v!r}")
        return str(v)

    def check_known(self, known: Sequence[str], what: str) -> None:
        for key in self.data:
            if key not in known:
                close = [k for k in known if k.split("_")[0] == str(key).split("_")[0]]
                hint = f" (did you mean {' or '.join(close[:3])}?)" if close else ""
                where = f" in {what}" if what else ""
                raise self.fail(str(key), f"unknown field '{key}'{where}{hint}; see docs/calibration.md")


def _adjust(fl: _Fields, key: str = "adjust", default: Optional[str] = None) -> Optional[str]:
    v = fl.text(key)
    if v is None:
        return default
    v = v.strip().lower()
    if v not in ADJUST_MODES:
        raise fl.fail(key, f"adjust must be one of {', '.join(ADJUST_MODES)}, got {fl.data[key]!r}")
    return v


def _check_principal_point(fl: _Fields, key: str, cx: float, cy: float, w: int, h: int) -> None:
    if not (0.0 <= cx <= w and 0.0 <= cy <= h):
        raise fl.fail(key, f"the principal point ({cx:.2f}, {cy:.2f}) px lies outside the {w} x {h} px image: "
                           f"check its units and origin")


# ---------------------------------------------------------------------------
# ArchaeoOrtho's own format
# ---------------------------------------------------------------------------

_OWN_TOP_KEYS = {"cameras", "format", "version"}
_OWN_CAMERA_KEYS = {"name", "images", "adjust", "image_size_px", "pixel_size_mm", "frame_size_mm",
                    "focal_length_mm", "focal_length_px", "principal_point_mm", "principal_point_px",
                    "k1", "k2", "k3", "p1", "p2", "radial_distortion_table", "fiducials_mm", "sigmas", "comment"}
_SIGMA_KEYS = ("focal_length_mm", "focal_length_px", "principal_point_mm", "principal_point_px", "cx_px", "cy_px",
               "k1", "k2", "k3", "p1", "p2")


def _read_own(path: str, data: dict) -> List[CameraCalibration]:
    top = _Fields(path, data)
    if "cameras" in data:
        top.check_known(sorted(_OWN_TOP_KEYS | {"adjust", "comment"}), "the file's top level")
        cams = data["cameras"]
        if not isinstance(cams, list) or not cams:
            raise top.fail("cameras", "cameras must be a list of one or more cameras (each starting with '- ')")
        default_adjust = _adjust(top)
        out = []
        for i, cam in enumerate(cams):
            if not isinstance(cam, dict):
                raise top.fail("cameras", f"cameras[{i + 1}] must be a mapping of fields, got {cam!r}",
                               _line_of(cams, i))
            out.append(_own_camera(path, cam, default_adjust, f"cameras[{i + 1}]"))
        _check_unique_names(path, out, [_line_of(c) for c in cams])
        return out
    single = {k: v for k, v in data.items() if k not in ("format", "version")}
    return [_own_camera(path, _submap(data, single), None, "")]


def _submap(data: dict, items: dict) -> _Map:
    m = _Map(items)
    m.line = _line_of(data)
    m.lines = {k: v for k, v in getattr(data, "lines", {}).items() if k in items}
    return m


def _check_unique_names(path: str, cams: List[CameraCalibration], lines: List[Optional[int]]) -> None:
    seen: Dict[str, int] = {}
    for i, c in enumerate(cams):
        if c.name in seen:
            raise CalibrationError(path, lines[i], "name", f"two cameras are named '{c.name}' (cameras "
                                                           f"{seen[c.name] + 1} and {i + 1}); names must differ")
        seen[c.name] = i


def _own_camera(path: str, data: dict, default_adjust: Optional[str], index: str) -> CameraCalibration:
    name = str(data.get("name") or "")
    fl = _Fields(path, data, f"camera '{name}'" if name else index)
    fl.check_known(sorted(_OWN_CAMERA_KEYS), "")  # the message's prefix names the camera
    size = fl.size("image_size_px")
    if size is None:
        raise fl.fail("image_size_px", "image_size_px [width, height] is missing: the size of the images (px) "
                                       "the calibration refers to")
    w, h = size
    px, py = _own_pixel_size(fl, w, h)
    focal_mm = fl.number("focal_length_mm", positive=True)
    focal_px_given = fl.number("focal_length_px", positive=True)
    if (focal_mm is None) == (focal_px_given is None):
        raise fl.fail("focal_length_mm", "give the focal length once: focal_length_mm (with pixel_size_mm or "
                                         "frame_size_mm) or focal_length_px")
    if focal_mm is not None:
        if px is None:
            raise fl.fail("focal_length_mm", "focal_length_mm needs the pixel size: add pixel_size_mm, or "
                                             "frame_size_mm [width, height] of the imaged frame")
        fx, fy = focal_mm / px, focal_mm / py
    else:
        fx = fy = focal_px_given
        focal_mm = focal_px_given * px if px is not None and _same(px, py) else None
    cx, cy = _own_principal_point(fl, w, h, px, py)
    dist, notes = _own_distortion(fl, focal_mm)
    return CameraCalibration(
        name=name, source=path, width=w, height=h, focal_px=fx, focal_y_px=None if _same(fx, fy) else fy,
        cx_px=cx, cy_px=cy, **dist, sigmas=_own_sigmas(fl, px, py), adjust=_adjust(fl, default=default_adjust),
        images=_own_images(fl), pixel_size_mm=px, fiducials_mm=_own_fiducials(fl), focal_mm=focal_mm, notes=notes,
        size_field="image_size_px", size_line=_line_of(data, "image_size_px"))


def _own_pixel_size(fl: _Fields, w: int, h: int) -> Tuple[Optional[float], Optional[float]]:
    if fl.has("pixel_size_mm") and fl.has("frame_size_mm"):
        raise fl.fail("frame_size_mm", "give the pixel size once: pixel_size_mm or frame_size_mm, not both")
    if fl.has("pixel_size_mm"):
        v = fl.data["pixel_size_mm"]
        if isinstance(v, (list, tuple)):
            a, b = fl.numbers("pixel_size_mm", 2, positive=True)
            return a, b
        p = fl.number("pixel_size_mm", positive=True)
        return p, p
    frame = fl.numbers("frame_size_mm", 2, positive=True)
    if frame is not None:
        return frame[0] / w, frame[1] / h
    return None, None


def _own_principal_point(fl: _Fields, w: int, h: int, px: Optional[float], py: Optional[float]
                         ) -> Tuple[float, float]:
    if fl.has("principal_point_mm") and fl.has("principal_point_px"):
        raise fl.fail("principal_point_px", "give the principal point once: principal_point_mm or "
                                            "principal_point_px")
    if fl.has("principal_point_mm"):
        x0, y0 = fl.numbers("principal_point_mm", 2)
        if px is None:
            raise fl.fail("principal_point_mm", "principal_point_mm needs the pixel size: add pixel_size_mm or "
                                                "frame_size_mm")
        cx, cy, key = w / 2.0 + x0 / px, h / 2.0 - y0 / py, "principal_point_mm"
    elif fl.has("principal_point_px"):
        cx, cy = fl.numbers("principal_point_px", 2)
        key = "principal_point_px"
    else:
        return w / 2.0, h / 2.0
    _check_principal_point(fl, key, cx, cy, w, h)
    return cx, cy


def _own_distortion(fl: _Fields, focal_mm: Optional[float]) -> Tuple[Dict[str, float], List[str]]:
    dist = {t: fl.number(t, default=0.0) for t in DISTORTION_TERMS}
    if not fl.has("radial_distortion_table"):
        return dist, []
    given = [t for t in ("k1", "k2", "k3") if fl.has(t)]
    if given:
        raise fl.fail("radial_distortion_table", f"give the radial distortion once: {', '.join(given)} or "
                                                 f"radial_distortion_table")
    if focal_mm is None:
        raise fl.fail("radial_distortion_table", "radial_distortion_table (radius mm) needs the focal length in "
                                                 "mm: give focal_length_mm, or the pixel size")
    radii, values = _own_table(fl)
    (k1, k2, k3), rms, worst = fit_radial_distortion(radii, values, focal_mm)
    dist.update(k1=k1, k2=k2, k3=k3)
    note = (f"k1..k3 fitted to {len(radii)} rows of the radial distortion table, "
            f"residual rms {rms:.3f} um, largest {worst:.3f} um")
    return dist, [note]


def _own_table(fl: _Fields) -> Tuple[List[float], List[float]]:
    table = fl.data["radial_distortion_table"]
    key = "radial_distortion_table"
    if not isinstance(table, list):
        raise fl.fail(key, "radial_distortion_table must be a list of [radius_mm, distortion_um] rows")
    radii, values = [], []
    for i, row in enumerate(table):
        line = _line_of(table, i)
        if not isinstance(row, (list, tuple)) or len(row) != 2:
            raise fl.fail(key, f"row {i + 1} of radial_distortion_table must be [radius_mm, distortion_um], "
                               f"got {row!r}", line)
        r = fl._as_number(key, row[0], False, f"radial_distortion_table row {i + 1} radius_mm", line)
        d = fl._as_number(key, row[1], False, f"radial_distortion_table row {i + 1} distortion_um", line)
        if r < 0:
            raise fl.fail(key, f"radial_distortion_table row {i + 1}: the radius must not be negative, got {r}",
                          line)
        radii.append(r)
        values.append(d)
    if len({r for r in radii if r > 0}) < _TABLE_TERMS:
        raise fl.fail(key, f"radial_distortion_table needs at least {_TABLE_TERMS} different radii above 0 to "
                           f"determine k1..k3, got {len({r for r in radii if r > 0})}")
    return radii, values


def fit_radial_distortion(radius_mm: Sequence[float], distortion_um: Sequence[float], focal_mm: float
                          ) -> Tuple[Tuple[float, float, float], float, float]:
    """k1..k3 (Brown / OpenCV, normalised coordinates) from a calibration report's radial distortion table.

    The table gives, at the radius r (mm, from the principal point, of the undistorted image point), the
    radial displacement dr (um) of the imaged point, positive outward.  In normalised coordinates (rho = r/f)
    the model's displacement is rho (k1 rho^2 + k2 rho^4 + k3 rho^6) = dr / f: linear in k1..k3, solved by
    least squares.  Returns ((k1, k2, k3), rms residual um, largest residual um)."""
    r = np.asarray(radius_mm, dtype=float)
    d = np.asarray(distortion_um, dtype=float) * 1e-3  # mm
    rho = r / focal_mm
    a = np.stack([rho ** 3, rho ** 5, rho ** 7], axis=1)
    k, *_ = np.linalg.lstsq(a, d / focal_mm, rcond=None)
    resid_um = (a @ k * focal_mm - d) * 1e3
    rms, worst = float(np.sqrt(np.mean(resid_um ** 2))), float(np.max(np.abs(resid_um)))
    return (float(k[0]), float(k[1]), float(k[2])), rms, worst


def _own_sigmas(fl: _Fields, px: Optional[float], py: Optional[float]) -> Dict[str, float]:
    if not fl.has("sigmas"):
        return {}
    data = fl.data["sigmas"]
    if not isinstance(data, dict):
        raise fl.fail("sigmas", "sigmas must be a mapping of parameter: a priori standard deviation")
    sf = _Fields(fl.path, data, fl.who)
    sf.check_known(_SIGMA_KEYS, "sigmas")
    out: Dict[str, float] = {}
    for key in _SIGMA_KEYS:
        v = sf.number(key, positive=True)
        if v is None:
            continue
        if key.endswith("_mm") and px is None:
            raise sf.fail(key, f"sigmas.{key} needs the pixel size: add pixel_size_mm or frame_size_mm")
        if key == "focal_length_mm":
            out["focal_px"] = v / px
        elif key == "focal_length_px":
            out["focal_px"] = v
        elif key == "principal_point_mm":
            out["cx_px"], out["cy_px"] = v / px, v / py
        elif key == "principal_point_px":
            out["cx_px"] = out["cy_px"] = v
        else:
            out[key] = v
    return out


def _own_images(fl: _Fields) -> List[str]:
    if not fl.has("images"):
        return []
    v = fl.data["images"]
    items = [v] if isinstance(v, str) else v
    if not isinstance(items, list) or not all(isinstance(p, str) and p.strip() for p in items):
        raise fl.fail("images", f"images must be a file name pattern or a list of them (e.g. ['1971_*.tif']), "
                                f"got {v!r}")
    return [p.strip() for p in items]


def _own_fiducials(fl: _Fields) -> Dict[str, Tuple[float, float]]:
    if not fl.has("fiducials_mm"):
        return {}
    data = fl.data["fiducials_mm"]
    if not isinstance(data, dict):
        raise fl.fail("fiducials_mm", "fiducials_mm must map each fiducial's name to its [x, y] in mm")
    ff = _Fields(fl.path, data, fl.who)
    return {str(k): tuple(ff.numbers(k, 2)) for k in data}


# ---------------------------------------------------------------------------
# Orthority interior parameters
# ---------------------------------------------------------------------------

_ORTHORITY_TYPES = ("pinhole", "brown", "opencv", "fisheye")
_ORTHORITY_KEYS = ("type", "im_size", "focal_len", "sensor_size", "cx", "cy", "name") + DISTORTION_TERMS
_ORTHORITY_EXTRA = ("k4", "k5", "k6", "s1", "s2", "s3", "s4", "tx", "ty")


def _read_orthority(path: str, data: dict) -> List[CameraCalibration]:
    if "camera" in data and isinstance(data["camera"], dict):  # the legacy simple-ortho config.yaml
        data = data["camera"]
    if "im_size" in data:  # the flat form: one camera
        return [_orthority_camera(path, str(data.get("name") or ""), data)]
    out = []
    for cam_id, params in data.items():
        if not isinstance(params, dict):
            raise CalibrationError(path, _line_of(data, cam_id), str(cam_id),
                                   f"camera '{cam_id}': its interior parameters must be a mapping")
        out.append(_orthority_camera(path, str(cam_id), params))
    return out


def _orthority_camera(path: str, name: str, data: dict) -> CameraCalibration:
    fl = _Fields(path, data, f"camera '{name}'" if name else "")
    cam_type = (fl.text("type") or "").strip().lower()
    if not cam_type:
        raise fl.fail("type", "type (pinhole, brown, opencv) is missing", _line_of(data))
    if cam_type == "fisheye":
        raise fl.fail("type", "fisheye cameras are not supported yet (COLMAP's fisheye models are not read by "
                              "the alignment): use a pinhole / brown / opencv calibration")
    if cam_type not in _ORTHORITY_TYPES:
        raise fl.fail("type", f"unknown camera type {data['type']!r}: Orthority's frame types are "
                              f"{', '.join(_ORTHORITY_TYPES)}")
    fl.check_known(_ORTHORITY_KEYS + (_ORTHORITY_EXTRA if cam_type == "opencv" else ()),
                   f"an Orthority {cam_type} camera")
    for key in _ORTHORITY_EXTRA:
        if fl.number(key, default=0.0) != 0.0:
            raise fl.fail(key, f"{key} is not supported (only k1, k2, k3, p1, p2 of OpenCV's model are)")
    size = fl.size("im_size")
    if size is None:
        raise fl.fail("im_size", "im_size [width, height] is missing", _line_of(data))
    w, h = size
    fx, fy, warnings = _orthority_focal(fl, w, h)
    cx = w / 2.0 + max(w, h) * fl.number("cx", default=0.0)
    cy = h / 2.0 + max(w, h) * fl.number("cy", default=0.0)
    _check_principal_point(fl, "cx", cx, cy, w, h)
    dist = {t: (fl.number(t, default=0.0) if cam_type != "pinhole" else 0.0) for t in DISTORTION_TERMS}
    if cam_type == "pinhole" and any(fl.has(t) for t in DISTORTION_TERMS):
        raise fl.fail(next(t for t in DISTORTION_TERMS if fl.has(t)),
                      "a pinhole camera has no distortion coefficients: use type brown or opencv")
    return CameraCalibration(name=name, source=path, width=w, height=h, focal_px=fx,
                             focal_y_px=None if _same(fx, fy) else fy, cx_px=cx, cy_px=cy, **dist, warnings=warnings,
                             size_field="im_size", size_line=_line_of(data, "im_size"))


def _orthority_focal(fl: _Fields, w: int, h: int) -> Tuple[float, float, List[str]]:
    if not fl.has("focal_len"):
        raise fl.fail("focal_len", "focal_len is missing", _line_of(fl.data))
    raw = fl.data["focal_len"]
    f = fl.numbers("focal_len", 2, positive=True) if isinstance(raw, list) else [fl.number("focal_len", True)] * 2
    sensor = fl.numbers("sensor_size", 2, positive=True)
    if sensor is not None:
        return f[0] * w / sensor[0], f[1] * h / sensor[1], []
    warnings = []
    if h > w:  # the two readings differ by h / w: a portrait image's focal length is in doubt
        warnings.append(f"focal_len {f[0]:g} without sensor_size is taken as normalised by the image width: "
                        f"{f[0] * w:.1f} px ({w} px wide), as Orthority's code does; its documentation says by the "
                        f"larger side, which would be {f[0] * h:.1f} px ({h} px): give sensor_size to remove the "
                        f"doubt")
    return f[0] * w, f[1] * w, warnings


# ---------------------------------------------------------------------------
# OpenCV FileStorage (YAML or XML)
# ---------------------------------------------------------------------------

def _opencv_yaml_text(text: str) -> str:
    """OpenCV's YAML 1.0 made readable by PyYAML, line numbers kept: the %YAML:1.0 directive commented out
    and the !!opencv-matrix tags removed (the matrices stay mappings of rows, cols, dt, data)."""
    text = re.sub(r"^(\s*)%YAML[: ]1\.0", r"\1# YAML 1.0", text, count=1)
    return re.sub(r"!!opencv-[A-Za-z-]+", "", text)


_CV_MATRIX = ("camera_matrix", "cameraMatrix", "K")
_CV_DIST = ("distortion_coefficients", "dist_coeffs", "distCoeffs", "D")


def _read_opencv_mapping(path: str, data: Any) -> List[CameraCalibration]:
    if not isinstance(data, dict):
        raise CalibrationError(path, _line_of(data), "", "an OpenCV calibration must be a mapping of fields")
    fl = _Fields(path, data)
    mkey = next((k for k in _CV_MATRIX if k in data), None)
    if mkey is None:
        raise fl.fail("camera_matrix", "camera_matrix is missing (an OpenCV calibration file)", _line_of(data))
    k = _cv_matrix_values(fl, mkey, data[mkey])
    if len(k) != 9 or k[1] != 0.0 or k[3] != 0.0 or k[6:] != [0.0, 0.0, 1.0]:
        raise fl.fail(mkey, f"{mkey} must be a 3 x 3 camera matrix [fx 0 cx; 0 fy cy; 0 0 1] (no skew), got {k}")
    dkey = next((d for d in _CV_DIST if d in data), None)
    dist = _cv_matrix_values(fl, dkey, data[dkey]) if dkey else []
    if len(dist) not in (0, 4, 5, 8, 12, 14):
        raise fl.fail(dkey, f"{dkey} must hold 4, 5, 8, 12 or 14 coefficients, got {len(dist)}")
    if any(v != 0.0 for v in dist[5:]):
        raise fl.fail(dkey, f"{dkey}: only k1, k2, p1, p2, k3 are supported; the rational / thin-prism terms "
                            f"(from the 6th on) must be 0")
    dist = (dist + [0.0] * 5)[:5]
    w = fl.number("image_width", positive=True)
    h = fl.number("image_height", positive=True)
    if w is None or h is None:
        raise fl.fail("image_width", "image_width and image_height are needed: the size of the images the "
                                     "calibration refers to", _line_of(data))
    if w != int(w) or h != int(h):
        raise fl.fail("image_width", f"image_width and image_height must be whole numbers, got {w} x {h}")
    w, h = int(w), int(h)
    cx, cy = k[2] + 0.5, k[5] + 0.5  # OpenCV: pixel centres at integers
    _check_principal_point(fl, mkey, cx, cy, w, h)
    if k[0] <= 0 or k[4] <= 0:
        raise fl.fail(mkey, f"{mkey}: the focal lengths must be positive, got fx {k[0]}, fy {k[4]}")
    return [CameraCalibration(name="", source=path, width=w, height=h, focal_px=k[0],
                              focal_y_px=None if _same(k[0], k[4]) else k[4], cx_px=cx, cy_px=cy,
                              k1=dist[0], k2=dist[1], p1=dist[2], p2=dist[3], k3=dist[4],
                              size_field="image_width", size_line=_line_of(data, "image_width"))]


def _cv_matrix_values(fl: _Fields, key: str, value: Any) -> List[float]:
    if isinstance(value, dict):
        sub = _Fields(fl.path, value, fl.who)
        rows, cols = sub.number("rows", True), sub.number("cols", True)
        data = sub.numbers("data")
        if data is None:
            raise fl.fail(key, f"{key}: the matrix has no data")
        if rows is not None and cols is not None and rows * cols != len(data):
            raise sub.fail("data", f"{key}: {int(rows)} x {int(cols)} matrix with {len(data)} values")
        return data
    if isinstance(value, list):
        flat = []
        for i, v in enumerate(value):
            flat += [fl._as_number(key, x, False, f"{key}[{i}]", _line_of(value, i))
                     for x in (v if isinstance(v, list) else [v])]
        return flat
    raise fl.fail(key, f"{key} must be a matrix, got {value!r}")


class _Element:
    """An XML element with its line (expat): tag, attributes, text, children."""

    def __init__(self, tag: str, attrib: dict, line: int):
        self.tag, self.attrib, self.line = tag, attrib, line
        self.text = ""
        self.children: List[_Element] = []

    def find(self, tag: str) -> Optional[_Element]:
        return next((c for c in self.children if c.tag == tag), None)

    def iter(self, tag: str):
        for c in self.children:
            if c.tag == tag:
                yield c
            yield from c.iter(tag)


def _parse_xml(path: str, text: str) -> _Element:
    from xml.parsers import expat
    parser = expat.ParserCreate()
    stack: List[_Element] = []
    root: List[_Element] = []

    def start(tag, attrib):
        el = _Element(tag, attrib, parser.CurrentLineNumber)
        (stack[-1].children if stack else root).append(el)
        stack.append(el)

    def end(tag):
        stack.pop()

    def chars(data):
        if stack:
            stack[-1].text += data

    parser.StartElementHandler, parser.EndElementHandler, parser.CharacterDataHandler = start, end, chars
    try:
        parser.Parse(text.encode("utf-8"), True)
    except expat.ExpatError as e:
        raise CalibrationError(path, e.lineno, "", f"not valid XML: {expat.ErrorString(e.code)}") from None
    return root[0]


def _read_xml(path: str, text: str) -> List[CameraCalibration]:
    root = _parse_xml(path, re.sub(r"^\s*<\?xml[^>]*\?>", lambda m: "\n" * m.group(0).count("\n"), text))
    if root.tag == "opencv_storage":
        return _read_opencv_mapping(path, _xml_opencv_mapping(root))
    if root.tag == "calibration":
        return [_metashape_camera(path, root, "")]
    sensors = [s for s in root.iter("sensor") if s.find("calibration") is not None]
    if root.tag == "document" or sensors:
        if not sensors:
            raise CalibrationError(path, root.line, "sensor", "the Metashape file holds no sensor with a "
                                                              "calibration")
        cams = []
        for s in sensors:
            cals = list(s.iter("calibration"))
            cal = next((c for c in cals if c.attrib.get("class") == "adjusted"), cals[0])
            cam = _metashape_camera(path, cal, s.attrib.get("label", s.attrib.get("id", "")), s)
            if cal.attrib.get("class", "adjusted") != "adjusted":
                cam.notes.append(f"the file holds no adjusted calibration for it; its "
                                 f"{cal.attrib['class']} one (line {cal.line}) is used")
            cams.append(cam)
        return cams
    raise CalibrationError(path, root.line, root.tag, f"an XML file with root <{root.tag}> is not a calibration "
                           "this plugin reads: expected OpenCV's <opencv_storage> or Metashape's <calibration>")


def _xml_opencv_mapping(root: _Element) -> _Map:
    m = _Map()
    m.line = root.line
    for el in root.children:
        if el.attrib.get("type_id") == "opencv-matrix" or el.find("data") is not None:
            sub = _Map()
            sub.line = el.line
            for c in el.children:
                sub[c.tag] = c.text.split() if c.tag == "data" else c.text.strip()
                sub.lines[c.tag] = c.line
            m[el.tag] = sub
        else:
            m[el.tag] = el.text.strip()
        m.lines[el.tag] = el.line
    return m


# ---------------------------------------------------------------------------
# Metashape
# ---------------------------------------------------------------------------

_METASHAPE_TERMS = ("f", "cx", "cy", "b1", "b2", "k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4")


def _metashape_camera(path: str, cal: _Element, name: str, sensor: Optional[_Element] = None) -> CameraCalibration:
    m = _Map()
    m.line = cal.line
    for c in cal.children:
        m[c.tag] = c.text.strip()
        m.lines[c.tag] = c.line
    fl = _Fields(path, m, f"sensor '{name}'" if name else "")
    projection = (fl.text("projection") or cal.attrib.get("type") or "frame").strip().lower()
    if projection != "frame":
        raise fl.fail("projection", f"Metashape's {projection} camera is not supported: only frame cameras are")
    res = cal.find("resolution") or (sensor.find("resolution") if sensor is not None else None)
    if res is not None and "width" in res.attrib:
        m["width"], m["height"] = res.attrib.get("width"), res.attrib.get("height")
        m.lines["width"] = m.lines["height"] = res.line
    w, h = fl.number("width", True), fl.number("height", True)
    if w is None or h is None:
        raise fl.fail("width", "the image width and height are missing", cal.line)
    w, h = int(w), int(h)
    v = {t: fl.number(t, positive=(t == "f"), default=0.0) for t in _METASHAPE_TERMS}
    if not fl.has("f"):
        raise fl.fail("f", "the focal length f (px) is missing", cal.line)
    for t in ("k4", "p3", "p4"):
        if v[t] != 0.0:
            raise fl.fail(t, f"{t} is not supported (COLMAP's OpenCV models hold k1..k3, p1, p2): recalibrate "
                             f"without {t}")
    notes = []
    if v["b2"] != 0.0:
        shift = abs(v["b2"]) * (h / 2.0) / v["f"]  # y' at the frame's edge times B2
        if shift > SKEW_LIMIT_PX:
            raise fl.fail("b2", f"the skew b2 = {v['b2']} moves the frame's edge by {shift:.2f} px; COLMAP has no "
                                f"skew: recalibrate with b2 fixed at 0")
        notes.append(f"skew b2 = {v['b2']} dropped (moves the frame's edge by "
                     f"{shift:.3f} px)")
    fx, fy = v["f"] + v["b1"], v["f"]
    cx, cy = w / 2.0 + v["cx"], h / 2.0 + v["cy"]
    _check_principal_point(fl, "cx", cx, cy, w, h)
    return CameraCalibration(name=name, source=path, width=w, height=h, focal_px=fx,
                             focal_y_px=None if _same(fx, fy) else fy, cx_px=cx, cy_px=cy, k1=v["k1"], k2=v["k2"],
                             k3=v["k3"], p1=v["p2"], p2=v["p1"], notes=notes, size_field="width",
                             size_line=_line_of(m, "width"))


# ---------------------------------------------------------------------------
# COLMAP cameras.txt
# ---------------------------------------------------------------------------

_COLMAP_LINE = re.compile(r"^\s*\d+\s+[A-Z0-9_]+\s+\d+\s+\d+(\s+\S+)+\s*$")


def _looks_like_colmap(text: str) -> bool:
    rows = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return bool(rows) and all(_COLMAP_LINE.match(ln) for ln in rows)


def _read_colmap_txt(path: str, text: str) -> List[CameraCalibration]:
    out = []
    for n, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        parts = line.split()
        cam_id, model = parts[0], parts[1]
        if model not in MODELS:
            raise CalibrationError(path, n, "MODEL", f"camera {cam_id}: the COLMAP model {model} is not supported "
                                   f"(supported: {', '.join(MODELS)})")
        names = MODELS[model]
        if len(parts) - 4 != len(names):
            raise CalibrationError(path, n, "PARAMS", f"camera {cam_id}: {model} takes {len(names)} parameters "
                                   f"({', '.join(names)}), got {len(parts) - 4}")
        try:
            p = dict(zip(names, (float(x) for x in parts[4:])))
        except ValueError:
            raise CalibrationError(path, n, "PARAMS", f"camera {cam_id}: the parameters must be numbers, got "
                                   f"{' '.join(parts[4:])}") from None
        if any(p.get(k, 0.0) != 0.0 for k in ("k4", "k5", "k6")):
            raise CalibrationError(path, n, "PARAMS", f"camera {cam_id}: FULL_OPENCV's k4..k6 (the rational "
                                   "model) are not supported: they must be 0")
        w, h = int(parts[2]), int(parts[3])
        fx, fy = p.get("fx", p.get("f")), p.get("fy", p.get("f"))
        if fx <= 0 or fy <= 0 or w <= 0 or h <= 0:
            raise CalibrationError(path, n, "PARAMS", f"camera {cam_id}: the focal length and image size must be "
                                   "positive")
        if not (0.0 <= p["cx"] <= w and 0.0 <= p["cy"] <= h):
            raise CalibrationError(path, n, "PARAMS", f"camera {cam_id}: the principal point ({p['cx']:.2f}, "
                                   f"{p['cy']:.2f}) px lies outside the {w} x {h} px image: check its units and "
                                   f"origin")
        out.append(CameraCalibration(name=cam_id, source=path, width=w, height=h, focal_px=fx,
                                     focal_y_px=None if _same(fx, fy) else fy, cx_px=p["cx"], cy_px=p["cy"],
                                     **{t: p.get(t, 0.0) for t in DISTORTION_TERMS}, size_field="WIDTH HEIGHT",
                                     size_line=n))
    if not out:
        raise CalibrationError(path, None, "", "the COLMAP cameras file lists no camera")
    _check_unique_names(path, out, [None] * len(out))
    return out
