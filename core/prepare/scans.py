"""Scanned historical film: fiducial marks, affine restitution to a common frame, crop, masks.

A set of scanned aerial photographs differs from scan to scan: scan size and
resolution, a rotation of a few degrees on the scanner bed, film shrinkage,
the film border and a data strip (clock, altimeter, frame number) around the
picture.  The fiducial marks, exposed on every frame by the camera body, define
the camera's frame: this module finds them and resamples every scan into that
one frame, so all prepared images have identical dimensions, the principal
point at their centre, and can share one camera in the bundle adjustment.

Steps (:func:`prepare_scans`):

1. **Detection** (:func:`detect_fiducials`): on a reduced copy of each scan,
   normalised cross-correlation with procedurally drawn templates (``cross``,
   ``dot``, ``ring_dot`` = dot in a circle, ``cross_ring``) at a range of sizes
   and both polarities, or with a user-provided template image, in eight
   search windows (four corners, four side middles; with calibrated
   coordinates only the windows of the calibrated marks).  Each window keeps
   its hits of every kind at a few places; geometry chooses among them before
   correlation does: the hits that fit the calibrated coordinates under one
   similarity, or without them, opposite hits around one common midpoint
   (:func:`_choose_marks`).  Each chosen hit is refined in
   the full-resolution scan: correlation peak, then, for the point-symmetric
   built-in marks, the centre of symmetry (phase correlation of the patch with
   its 180-degree rotation, iterated), which is sub-pixel and insensitive to
   blur, grain and the mark's exact drawing.
2. **Frame**: the calibrated fiducial coordinates (mm, x right, y up, origin at
   the principal point) when given; otherwise the mean layout of the set
   (generalised Procrustes) with its origin at the fiducial centre, in mm when
   the scan resolution is known (TIFF resolution tags or ``scan_pixel_size_mm``)
   and in pixels of the median scan otherwise.  Marks whose position is not
   consistent across the set (a tree crown that looks like a dot) are dropped.
3. **Affine restitution**: per scan a 6-parameter affine from frame to scan
   pixels (least squares; residuals reported, outliers dropped when five or
   more marks are found; a scan whose fit cannot be a film's is left out
   with a warning, see :func:`prepare_scans`), then every scan is resampled (bicubic, after an
   anti-alias filter when shrinking) strip by strip into an image of identical
   size centred on the principal point, written as a lossless tiled GeoTIFF-
   less TIFF with the interior orientation in its metadata (``EXIF_FocalLength``
   and the focal-plane resolution, which :mod:`core.images` reads).
4. **Masks**: ``<name>.png`` beside the prepared image's name, white = use,
   black = ignore (COLMAP's convention, ``<image name>.png``): the area outside
   the scanned film, the film border and data strips outside the picture area
   (found from texture: the border is uniform, the median over the set decides)
   and a disc over every fiducial mark.

Pixel coordinates follow COLMAP: origin at the upper-left corner of the
upper-left pixel, x right, y down (a pixel centre is at i + 0.5).  No qgis here.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io.images import ImageError, open_image, read_image, to_grey
from ..io.raster import RasterFile
from .options import FIDUCIAL_TYPES, MARK_KINDS, ScanError, ScanOptions

SCANS_JSON = "scans.json"

# slot -> ideal position in the frame (x right, y up)
SLOTS: Dict[str, Tuple[int, int]] = {
    "TL": (-1, 1), "T": (0, 1), "TR": (1, 1), "R": (1, 0),
    "BR": (1, -1), "B": (0, -1), "BL": (-1, -1), "L": (-1, 0),
}
CORNER_SLOTS = ("TL", "TR", "BR", "BL")
SIDE_SLOTS = ("T", "R", "B", "L")
LAYOUTS = {"auto": tuple(SLOTS), "corners": CORNER_SLOTS, "sides": SIDE_SLOTS, "eight": tuple(SLOTS)}
OPPOSITE = {"TL": "BR", "TR": "BL", "T": "B", "L": "R"}


@dataclass
class Fiducial:
    slot: str
    x: float  # full-resolution scan pixels, corner convention
    y: float
    score: float
    kind: str
    size_px: float  # outer size of the mark in scan pixels
    polarity: int  # +1 bright mark on a dark ground, -1 dark on bright
    residual_px: Optional[float] = None
    note: Optional[str] = None  # a refinement's warning, reported only when the mark is used

    def to_dict(self) -> dict:
        d = asdict(self)
        d.pop("note")
        for k in ("x", "y"):
            d[k] = round(d[k], 3)
        d["score"] = round(d["score"], 3)
        d["size_px"] = round(d["size_px"], 2)
        if d["residual_px"] is not None:
            d["residual_px"] = round(d["residual_px"], 3)
        return d


@dataclass
class CalibratedFiducials:
    points: Dict[str, Tuple[float, float]]  # slot -> (x, y) mm relative to the principal point
    ids: Dict[str, str]  # slot -> id in the certificate
    focal_length_mm: Optional[float] = None


@dataclass
class PreparedScan:
    name: str
    prepared_name: str
    mask_name: str
    scan_width: int
    scan_height: int
    fiducials: List[Fiducial]
    affine: List[List[float]]  # frame (x, y, 1) -> scan pixel (x, y), 2 x 3
    rms_px: float
    max_residual_px: float
    rotation_deg: float
    scan_pixel_size: float  # frame units per scan pixel (geometric mean)
    dropped: List[str] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["fiducials"] = [f.to_dict() for f in self.fiducials]
        d["affine"] = [[round(v, 9) for v in row] for row in self.affine]
        for k in ("rms_px", "max_residual_px", "rotation_deg"):
            d[k] = round(d[k], 4)
        d["scan_pixel_size"] = round(d["scan_pixel_size"], 8)
        return d


@dataclass
class ScanSet:
    scans: List[PreparedScan]
    frame: Dict[str, Tuple[float, float]]  # slot -> frame coordinates
    units: str  # "mm" or "px"
    calibrated: bool
    width: int
    height: int
    pixel_size: float  # frame units per output pixel
    image_area: Optional[Tuple[float, float, float, float]]  # x0, y0, x1, y1 output pixels
    interior_orientation: dict
    warnings: List[str] = field(default_factory=list)
    left_out: Dict[str, str] = field(default_factory=dict)  # scan name -> why it was not restituted

    def to_dict(self) -> dict:
        return {
            "left_out": self.left_out,
            "frame": {k: [round(v[0], 5), round(v[1], 5)] for k, v in self.frame.items()},
            "units": self.units, "calibrated": self.calibrated, "width": self.width, "height": self.height,
            "pixel_size": self.pixel_size,
            "image_area": [round(v, 2) for v in self.image_area] if self.image_area else None,
            "interior_orientation": self.interior_orientation,
            "scans": [s.to_dict() for s in self.scans], "warnings": self.warnings,
        }


# ---------------------------------------------------------------------------
# marks and templates
# ---------------------------------------------------------------------------

def mark_coverage(kind: str, dx: np.ndarray, dy: np.ndarray, size: float) -> np.ndarray:
    """1 inside a mark of outer ``size`` centred at (0, 0), 0 outside (any units, any rotation applied)."""
    r = np.hypot(dx, dy)
    half = 0.5 * size
    if kind == "dot":
        return r <= half
    if kind == "cross":
        t = max(0.5 * size / 8.0, 0.0)
        return ((np.abs(dx) <= half) & (np.abs(dy) <= t)) | ((np.abs(dy) <= half) & (np.abs(dx) <= t))
    if kind == "ring_dot":
        w = 0.05 * size
        return (np.abs(r - 0.45 * size) <= w) | (r <= 0.15 * size)
    if kind == "cross_ring":
        t = 0.5 * size / 10.0
        arm = 0.35 * size
        cross = ((np.abs(dx) <= arm) & (np.abs(dy) <= t)) | ((np.abs(dy) <= arm) & (np.abs(dx) <= t))
        return cross | (np.abs(r - 0.45 * size) <= 0.04 * size)
    raise ScanError(f"unknown fiducial type {kind!r}; choose one of {', '.join(FIDUCIAL_TYPES)}")


def render_mark(kind: str, size: float, angle_deg: float = 0.0, canvas: Optional[int] = None,
                supersample: int = 4) -> np.ndarray:
    """An anti-aliased mark (1 = mark, 0 = ground) centred in an odd canvas of about 1.6 x size pixels.

    ``angle_deg`` rotates the mark as an image rotates on the scanner (x right, y down).
    """
    n = canvas or int(math.ceil(1.6 * size + 2))
    n += 1 - n % 2
    c = (n - 1) / 2.0
    s = supersample
    off = (np.arange(s) + 0.5) / s - 0.5
    yy, xx = np.mgrid[0:n, 0:n].astype(np.float64)
    acc = np.zeros((n, n), np.float64)
    ca, sa = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    for oy in off:
        for ox in off:
            dx, dy = xx + ox - c, yy + oy - c
            u, v = ca * dx + sa * dy, -sa * dx + ca * dy  # into the mark's own axes
            acc += mark_coverage(kind, u, v, size)
    return (acc / (s * s)).astype(np.float32)


def load_template(path: str) -> np.ndarray:
    """A user's template image (one mark, any polarity) as grey in [0, 1]."""
    try:
        arr = read_image(path)
    except (RuntimeError, AttributeError) as e:
        raise ScanError(f"{path}: fiducial template cannot be read ({e})") from e
    g = to_grey(arr)
    if min(g.shape) < 5:
        raise ScanError(f"{path}: fiducial template is too small ({g.shape[1]}x{g.shape[0]} px)")
    return g


# ---------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------

def _gdal():
    from osgeo import gdal

    gdal.UseExceptions()
    return gdal


def _read_window(scan: RasterFile, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    return np.moveaxis(scan.read_bands(window=(int(x0), int(y0), int(w), int(h))), 0, -1)


def _grey_window(scan: RasterFile, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    arr = _read_window(scan, x0, y0, w, h)
    return to_grey(arr, 255.0 if arr.dtype == np.uint8 else 65535.0 if arr.dtype == np.uint16 else 1.0)


def scan_resolution_mm(scan: RasterFile) -> Optional[float]:
    """Scan pixel size in mm from the file's resolution tags (TIFF or EXIF), when plausible (>= 300 dpi)."""
    md = scan.metadata()
    for key, unit_key in (("TIFFTAG_XRESOLUTION", "TIFFTAG_RESOLUTIONUNIT"), ("EXIF_XResolution", "EXIF_ResolutionUnit")):
        if key in md:
            nums = re.findall(r"[-+]?\d*\.?\d+", md.get(key, ""))
            if not nums or float(nums[0]) <= 0:
                continue
            unit = md.get(unit_key, "2").strip()
            per_inch = float(nums[0]) * (2.54 if unit.startswith("3") or "cm" in unit else 1.0)
            if per_inch >= 300:  # 72/96 dpi are defaults written by software, not scanner resolutions
                return 25.4 / per_inch
    return None


# ---------------------------------------------------------------------------
# detection
# ---------------------------------------------------------------------------

def _windows(h: int, w: int, slots: Sequence[str]) -> Dict[str, Tuple[int, int, int, int]]:
    """Search window (x0, y0, x1, y1) per slot on an image of h x w: a 3 x 3 grid, 30/40/30 %."""
    xs = [0, int(0.3 * w), int(0.7 * w), w]
    ys = [0, int(0.3 * h), int(0.7 * h), h]
    out = {}
    for s in slots:
        u, v = SLOTS[s]
        i, j = u + 1, 1 - v  # column band, row band (y down)
        out[s] = (xs[i], ys[j], xs[i + 1], ys[j + 1])
    return out


def _best_match(img: np.ndarray, win: Tuple[int, int, int, int], tpl: np.ndarray, polarities=(1, -1)):
    """Best normalised correlation of ``tpl`` whose centre lies in ``win``: (score, cx, cy, polarity)."""
    cv2 = require("cv2", "scanned film")

    th, tw = tpl.shape
    h, w = img.shape
    x0, y0, x1, y1 = win
    # the template may reach beyond the window, but its centre stays inside it
    ax0, ay0 = max(0, x0 - tw // 2), max(0, y0 - th // 2)
    ax1, ay1 = min(w, x1 + tw // 2 + 1), min(h, y1 + th // 2 + 1)
    sub = img[ay0:ay1, ax0:ax1]
    if sub.shape[0] < th or sub.shape[1] < tw:
        return (-1.0, 0.0, 0.0, 1)
    r = cv2.matchTemplate(sub, tpl, cv2.TM_CCOEFF_NORMED)
    r[~np.isfinite(r)] = 0
    # centres of result cells
    cx0 = ax0 + (tw - 1) / 2.0
    cy0 = ay0 + (th - 1) / 2.0
    jx = np.arange(r.shape[1]) + cx0
    iy = np.arange(r.shape[0]) + cy0
    okx = (jx >= x0) & (jx < x1)
    oky = (iy >= y0) & (iy < y1)
    if not okx.any() or not oky.any():
        return (-1.0, 0.0, 0.0, 1)
    rr = r[np.ix_(oky, okx)]
    best = (-1.0, 0.0, 0.0, 1)
    for pol in polarities:
        rp = rr * pol
        k = int(np.argmax(rp))
        i, j = divmod(k, rp.shape[1])
        sc = float(rp[i, j])
        if sc > best[0]:
            best = (sc, float(jx[okx][j]), float(iy[oky][i]), pol)
    return best


def _sizes(short_side: int) -> List[float]:
    lo, hi = max(5.0, 0.004 * short_side), max(8.0, 0.06 * short_side)
    out, s = [], lo
    while s <= hi * 1.0001:
        out.append(s)
        s *= 1.25
    return out


def _rotation_deg(points: Dict[str, Tuple[float, float]]) -> float:
    """Rotation of a scan (image axes, y down) from pairs of opposite marks; 0 when unknown."""
    angles = []
    for a, b in (("TL", "TR"), ("L", "R"), ("BL", "BR")):
        if a in points and b in points:
            dx, dy = points[b][0] - points[a][0], points[b][1] - points[a][1]
            angles.append(math.atan2(dy, dx))
    for a, b in (("TL", "BL"), ("T", "B"), ("TR", "BR")):
        if a in points and b in points:
            dx, dy = points[b][0] - points[a][0], points[b][1] - points[a][1]
            angles.append(math.atan2(-dx, dy))
    if not angles:
        return 0.0
    return math.degrees(math.atan2(np.mean(np.sin(angles)), np.mean(np.cos(angles))))


def refine_symmetric(grey: np.ndarray, x: float, y: float, size: float, iterations: int = 12) -> Tuple[float, float, bool]:
    """Centre of point symmetry of a mark near (x, y) (OpenCV pixel-centre coordinates of ``grey``).

    Gauss-Newton on sum w(u) (I(c + u) - I(c - u))^2 over a patch of about 1.5
    mark sizes (Gaussian weights, bicubic sampling): at the true centre a
    point-symmetric mark (cross, dot, ring) equals its 180-degree rotation.
    Returns (x, y, converged).
    """
    cv2 = require("cv2", "scanned film")

    g = np.ascontiguousarray(grey, dtype=np.float32)
    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=3, scale=0.125)
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=3, scale=0.125)
    n = int(math.ceil(1.5 * size + 4))
    n += 1 - n % 2
    n = max(n, 15)
    half = (n - 1) / 2.0
    u = np.arange(n, dtype=np.float32) - np.float32(half)
    uu, vv = np.meshgrid(u, u)
    w = np.exp(-(uu ** 2 + vv ** 2) / (2 * (0.45 * n) ** 2)).astype(np.float32)
    converged = False
    track = []
    for _ in range(iterations):
        mx, my = (uu + np.float32(x)), (vv + np.float32(y))
        p = cv2.remap(g, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
        px = cv2.remap(gx, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
        py = cv2.remap(gy, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
        r = p - p[::-1, ::-1]
        jx = px - px[::-1, ::-1]
        jy = py - py[::-1, ::-1]
        h = np.array([[float((w * jx * jx).sum()), float((w * jx * jy).sum())],
                      [float((w * jx * jy).sum()), float((w * jy * jy).sum())]])
        b = np.array([float((w * jx * r).sum()), float((w * jy * r).sum())])
        if np.linalg.cond(h) > 1e8:
            return x, y, False
        dx, dy = -np.linalg.solve(h, b)
        step = math.hypot(dx, dy)
        if step > 0.25 * size:  # diverging: keep the previous estimate
            return x, y, False
        x, y = x + float(dx), y + float(dy)
        track.append((x, y, step))
        if step < 0.005:
            converged = True
            break
    if not converged and len(track) >= 4:
        # grain makes the last steps wander by a few hundredths of a pixel: take their mean
        last = np.array([t[:2] for t in track[-4:]])
        x, y = float(last[:, 0].mean()), float(last[:, 1].mean())
        converged = float(np.hypot(*(last - last.mean(0)).T).max()) < 0.1
    return x, y, converged


def is_point_symmetric(img: np.ndarray, min_corr: float = 0.85) -> bool:
    """True when an image (a mark's template) looks the same turned by 180 degrees about its centre."""
    a = np.asarray(img, np.float64) - float(np.mean(img))
    b = a[::-1, ::-1]
    den = math.sqrt(float((a * a).sum()) * float((b * b).sum()))
    return den > 0 and float((a * b).sum()) / den >= min_corr


def _mark_fraction(template: np.ndarray) -> float:
    """Extent of the mark in a template image as a fraction of the template's longer side."""
    t = np.asarray(template, np.float32)
    edge = np.concatenate([t[0], t[-1], t[:, 0], t[:, -1]])
    dev = np.abs(t - float(np.median(edge)))
    ys, xs = np.nonzero(dev > 0.5 * float(dev.max()))
    if len(xs) == 0:
        return 1.0
    return float(min(1.0, (max(np.ptp(xs), np.ptp(ys)) + 1) / max(t.shape)))


def _quadratic_peak(r: np.ndarray, i: int, j: int) -> Tuple[float, float]:
    """Sub-pixel offset of a correlation peak at (i, j) by separable parabola fits."""
    def off(a, b, c):
        d = a - 2 * b + c
        return 0.0 if abs(d) < 1e-12 else float(np.clip(0.5 * (a - c) / d, -0.5, 0.5))
    ox = off(r[i, j - 1], r[i, j], r[i, j + 1]) if 0 < j < r.shape[1] - 1 else 0.0
    oy = off(r[i - 1, j], r[i, j], r[i + 1, j]) if 0 < i < r.shape[0] - 1 else 0.0
    return ox, oy


def detect_fiducials(path: str, options: Optional[ScanOptions] = None,
                     template: Optional[np.ndarray] = None,
                     hints: Optional[Dict[str, str]] = None,
                     frame: Optional[Dict[str, Tuple[float, float]]] = None) -> Tuple[List[Fiducial], List[str]]:
    """Find the fiducial marks of one scan.  Returns (marks with a score >= min_score, warnings).

    Positions are sub-pixel, in full-resolution pixels of the scan (corner convention).
    ``hints`` (slot -> mark kind, from an earlier scan of the set) narrows the
    search to that kind; a slot where it fails is searched with every kind.

    Every search window keeps its hits of each mark kind at up to three places;
    which hit is the mark is decided by geometry before correlation (:func:`_choose_marks`):
    with ``frame`` (the calibrated fiducial coordinates, slot -> (x, y) mm, y
    up) the hits that fit it under one similarity transform win, and only the
    windows of the frame's slots are searched; without it, the hits whose
    opposite pairs share one midpoint (a fiducial layout is point-symmetric and
    an affine scan keeps midpoints).  Correlation then only ranks the hits at
    one place.  A large dot template in the picture can correlate better than
    a real mark whose ring touches the picture; it must not win.
    """
    options = options or ScanOptions()
    if options.layout not in LAYOUTS:
        raise ScanError(f"unknown fiducial layout {options.layout!r}; choose one of {', '.join(LAYOUTS)}")
    if options.fiducial_type not in FIDUCIAL_TYPES:
        raise ScanError(f"unknown fiducial type {options.fiducial_type!r}; choose one of {', '.join(FIDUCIAL_TYPES)}")
    with open_image(path) as scan:
        return _detect_in(scan, options, template, hints, frame)


def _detect_in(scan: RasterFile, options: ScanOptions, template: Optional[np.ndarray], hints: Optional[Dict[str, str]],
               frame: Optional[Dict[str, Tuple[float, float]]]) -> Tuple[List[Fiducial], List[str]]:
    """:func:`detect_fiducials` in the opened scan."""
    path = scan.path
    full_w, full_h = scan.width, scan.height
    try:
        small = read_image(path, max_size=options.detect_size)
    except RuntimeError as e:
        raise ImageError(f"{path}: image data cannot be read ({str(e).strip()})") from e
    g = to_grey(small)
    h, w = g.shape
    kx, ky = full_w / w, full_h / h
    slots = [s for s in LAYOUTS[options.layout] if frame is None or s in frame]
    windows = _windows(h, w, slots)
    kinds = MARK_KINDS if options.fiducial_type == "auto" else (options.fiducial_type,)
    groups = _coarse_templates(template, kinds, min(h, w), 0.5 * (kx + ky))
    frame_px = None if frame is None else {k: (v[0], -v[1]) for k, v in frame.items()}  # y down, as the image
    hints = hints or {}
    cands = _coarse_search(g, windows, groups, hints, options.min_score)
    coarse, left = _choose_marks(cands, frame_px)
    if any(s in hints for s in cands) and (any(s in hints and s not in coarse for s in cands) or len(coarse) < 3):
        # a hinted kind that does not fit: every kind in every window
        cands = _coarse_search(g, windows, groups, {}, options.min_score)
        coarse, left = _choose_marks(cands, frame_px)
    name = os.path.basename(path)
    warnings: List[str] = [f"{name}: fiducial {s}: the marks found there do not fit the "
                           f"{'calibrated coordinates' if frame else 'other marks'}; left out" for s in left]
    if not coarse:
        return [], warnings
    angle = _rotation_deg({k: (v[1], v[2]) for k, v in coarse.items()})
    user = _UserTemplate.of(template)
    out: List[Fiducial] = []
    for slot, hit in coarse.items():
        f = _refine_mark(scan, slot, hit, user, angle, (kx, ky))
        if f is not None:
            out.append(f)
    warnings.extend(f.note for f in out if f.note)
    return out, warnings


def _coarse_templates(template: Optional[np.ndarray], kinds: Sequence[str], short_side: int,
                      base: float) -> Dict[str, List[Tuple[float, np.ndarray]]]:
    """kind -> [(size, template)] searched on the reduced scan: the user's template at five scales, or the
    built-in marks at a range of sizes.  ``base``: scan pixels per reduced pixel."""
    cv2 = require("cv2", "scanned film")

    if template is None:
        return {kind: [(s, render_mark(kind, s)) for s in _sizes(short_side)] for kind in kinds}
    scaled = []
    for f in (0.8, 0.9, 1.0, 1.1, 1.25):
        th = max(5, int(round(template.shape[0] / base * f)))
        tw = max(5, int(round(template.shape[1] / base * f)))
        scaled.append((max(tw, th), cv2.resize(template, (tw, th), interpolation=cv2.INTER_AREA)))
    return {"template": scaled}


def _coarse_search(g: np.ndarray, windows: Dict[str, Tuple[int, int, int, int]],
                   groups: Dict[str, List[Tuple[float, np.ndarray]]], hints: Dict[str, str],
                   min_score: float) -> Dict[str, List[tuple]]:
    """Per window, the hits (score, x, y, polarity, kind, size, z) of every kind that reach ``min_score`` on the
    reduced scan, at up to three distinct places per kind, strongest first (z: the correlation's evidence, below);
    windows without a hit are left out.
    A window with a hint is searched with the hinted kind only, unless it has no hit there."""
    def z_of(sc, tpl):
        # a large template that correlates well is stronger evidence than a small one (a dot of
        # five pixels also fits every full stop of a data strip): rank by atanh(r) * sqrt(side)
        return math.atanh(min(max(sc, 0.0), 0.999)) * math.sqrt(max(tpl.shape))

    def local(win, cx, cy, r):  # a small window around a place, inside the search window
        return (max(win[0], int(cx - r)), max(win[1], int(cy - r)), min(win[2], int(cx + r) + 1),
                min(win[3], int(cy + r) + 1))

    def search(win, kinds_here):
        hits = []
        for kind in kinds_here:
            tried = [(_best_match(g, win, tpl), s, tpl) for s, tpl in groups[kind]]
            # distinct places, the strongest evidence first; a place a little under min_score may reach it at
            # the mark's own size (a ring cut by the picture edge correlates less at the grid's sizes)
            places: List[Tuple[float, float, float, tuple]] = []
            for (sc, cx, cy, pol), s, tpl in sorted(tried, key=lambda t: -z_of(t[0][0], t[2])):
                if sc < 0.85 * min_score or any(math.hypot(cx - x, cy - y) <= 0.5 * max(s, q) for x, y, q, _ in places):
                    continue
                places.append((cx, cy, s, (sc, cx, cy, pol, kind, s, z_of(sc, tpl))))
                if len(places) == 3:
                    break
            for cx, cy, s0, first in places:
                best = first if first[0] >= min_score else None
                if kind != "template":  # thin rings and bars are sensitive to scale: refine the size here
                    for f in (0.88, 0.94, 1.06, 1.12):
                        tpl = render_mark(kind, s0 * f)
                        sc, x, y, pol = _best_match(g, local(win, cx, cy, max(2.0, 0.25 * s0)), tpl)
                        z = z_of(sc, tpl)
                        if sc >= min_score and (best is None or z > best[6]):
                            best = (sc, x, y, pol, kind, s0 * f, z)
                if best is not None:
                    hits.append(best)
        return sorted(hits, key=lambda t: -t[6])

    out = {}
    for slot, win in windows.items():
        hits = search(win, [hints[slot]]) if hints.get(slot) in groups else []
        if not hits:
            hits = search(win, list(groups))
        if hits:
            out[slot] = hits
    return out


def _hit_tolerance(hit: tuple, radius: float) -> float:
    """How far (reduced pixels) a coarse hit may lie from its predicted place and still be the mark: a quarter of
    the mark, 1 % of the layout's radius (film shrinkage, a scanner's affinity, the similarity's simplification),
    at least 2 pixels (the coarse grid)."""
    return max(2.0, 0.25 * hit[5], 0.01 * radius)


def _choose_marks(cands: Dict[str, List[tuple]], frame: Optional[Dict[str, Tuple[float, float]]]
                  ) -> Tuple[Dict[str, tuple], List[str]]:
    """One hit per window, chosen by geometry first: returns (slot -> hit, slots whose hits fit nothing).

    ``frame`` (slot -> (x, y), y down, any unit): every pair of hits in two windows gives a similarity frame ->
    reduced scan; the one under which most windows have a hit at their predicted place wins (then the smaller
    RMS of its refit); each of those windows takes its strongest hit at that place, the others none.  Without a
    frame: the midpoint of the opposite pairs (TL-BR, T-B, ...) that most pairs of hits share is the fiducial
    centre; a pair of windows with hits around it takes its strongest such pair (see :func:`_choose_symmetric`).
    With fewer than two windows (or no agreement) the strongest hit of each window is kept.
    """
    best = {s: h[0] for s, h in cands.items() if h}
    if len(best) < 2:
        return best, []
    if frame is None:
        return _choose_symmetric(cands), []
    slots = [s for s in best if s in frame]
    hits = [(s, h) for s in slots for h in cands[s]]
    fr = {s: np.array(frame[s], float) for s in slots}
    radius_fr = max(float(np.hypot(*(fr[s] - np.mean(list(fr.values()), axis=0)))) for s in slots)

    def assign(sc, rot, t):
        pred = {s: sc * rot @ fr[s] + t for s in slots}
        tol_r = sc * radius_fr
        chosen = {}
        for s in slots:
            near = [h for h in cands[s] if math.hypot(h[1] - pred[s][0], h[2] - pred[s][1]) <= _hit_tolerance(h, tol_r)]
            if near:
                chosen[s] = max(near, key=lambda h: h[6])
        return chosen

    top, top_key = {}, (0, 0.0)
    for i, (sa, ha) in enumerate(hits):
        for sb, hb in hits[i + 1:]:
            if sa == sb:
                continue
            sc, rot, t = _similarity(np.array([fr[sa], fr[sb]]), np.array([ha[1:3], hb[1:3]], float))
            if not sc > 0:
                continue
            chosen = assign(sc, rot, t)
            if len(chosen) < 2:
                continue
            src = np.array([fr[s] for s in chosen])
            dst = np.array([chosen[s][1:3] for s in chosen], float)
            sc2, rot2, t2 = _similarity(src, dst)
            chosen = assign(sc2, rot2, t2) or chosen  # the refit's own choice
            src = np.array([fr[s] for s in chosen])
            dst = np.array([chosen[s][1:3] for s in chosen], float)
            sc2, rot2, t2 = _similarity(src, dst)
            rms = float(np.sqrt(np.mean(np.sum((src @ (sc2 * rot2).T + t2 - dst) ** 2, axis=1))))
            key = (len(chosen), -rms)
            if key > top_key:
                top, top_key = chosen, key
    if len(top) < 2:
        return best, []
    return top, [s for s in slots if s not in top]


def _choose_symmetric(cands: Dict[str, List[tuple]]) -> Dict[str, tuple]:
    """Without calibrated coordinates: hits of opposite windows around one common midpoint (see _choose_marks).

    A pair of hits counts when its midpoint lies within a tenth of the mark (2 px at least: the coarse grid) of
    the centre and it runs along its slots' direction: within 10 degrees for T-B and L-R (a scan lies nearly
    upright, or the windows would not hold the marks), 20 for the diagonals (the frame's aspect ratio).  When
    two pairs or more agree, a pair of windows whose hits do not is left out without a word: the camera has no
    marks there (the corners of a camera with side marks only); a window whose opposite has no hit keeps its
    strongest hit."""
    best = {s: h[0] for s, h in cands.items() if h}
    pairs = [(a, b) for a, b in OPPOSITE.items() if a in best and b in best]
    if len(pairs) < 2:
        return best
    mids = []
    for a, b in pairs:
        ideal = math.atan2(-(SLOTS[b][1] - SLOTS[a][1]), SLOTS[b][0] - SLOTS[a][0])  # image y down
        limit = math.radians(10.0 if 0 in SLOTS[a] else 20.0)
        for ha in cands[a]:
            for hb in cands[b]:
                turn = math.atan2(hb[2] - ha[2], hb[1] - ha[1]) - ideal
                if abs((turn + math.pi) % (2 * math.pi) - math.pi) <= limit:
                    mids.append((a, b, ha, hb, 0.5 * (ha[1] + hb[1]), 0.5 * (ha[2] + hb[2]),
                                 max(2.0, 0.1 * max(ha[5], hb[5]))))
    top, top_key = {}, (0, 0.0)
    for _a, _b, _ha, _hb, mx, my, _tol in mids:
        chosen = {}
        for a, b, ha, hb, x, y, tol in mids:
            if math.hypot(x - mx, y - my) <= tol and ((a, b) not in chosen or ha[6] + hb[6] > chosen[(a, b)][0]):
                chosen[(a, b)] = (ha[6] + hb[6], ha, hb)
        key = (len(chosen), sum(v[0] for v in chosen.values()))
        if key > top_key:
            top, top_key = chosen, key
    if len(top) < 2:
        return best
    out = {s: h for s, h in best.items() if not any(s in p for p in pairs)}  # no opposite hit to test it with
    for (a, b), (_z, ha, hb) in top.items():
        out[a], out[b] = ha, hb
    return out


@dataclass
class _UserTemplate:
    """The user's template image of one mark (None: the marks are rendered), whether it is point-symmetric (its
    centre of symmetry refines the position) and the share of it the mark fills (the rest is margin)."""

    image: Optional[np.ndarray]
    symmetric: bool = False
    mark_frac: float = 1.0

    @classmethod
    def of(cls, template: Optional[np.ndarray]) -> _UserTemplate:
        if template is None:
            return cls(None)
        return cls(template, is_point_symmetric(template), _mark_fraction(template))


def _refine_mark(scan: RasterFile, slot: str, hit: tuple, user: _UserTemplate, angle: float,
                 k: Tuple[float, float]) -> Optional[Fiducial]:
    """A coarse hit refined in the full-resolution scan: correlation peak, then the centre of symmetry."""
    cv2 = require("cv2", "scanned film")

    sc, cx, cy, pol, kind, s = hit[:6]
    kx, ky = k
    note = None
    path, template = scan.path, user.image
    full_w, full_h = scan.width, scan.height
    fx, fy = (cx + 0.5) * kx - 0.5, (cy + 0.5) * ky - 0.5  # full-res pixel-centre coordinates
    size_full = s * 0.5 * (kx + ky)
    red = max(1.0, size_full / 96.0)  # correlate at most ~96 px marks; refine at full resolution
    if template is not None:
        f = size_full / max(template.shape) / red  # the user's template at this scan's scale
        t = cv2.resize(template, (max(5, int(round(template.shape[1] * f))), max(5, int(round(template.shape[0] * f)))),
                       interpolation=cv2.INTER_AREA if f < 1 else cv2.INTER_CUBIC)
        if abs(angle) > 0.3:
            c = ((t.shape[1] - 1) / 2.0, (t.shape[0] - 1) / 2.0)
            t = cv2.warpAffine(t, cv2.getRotationMatrix2D(c, -angle, 1.0), (t.shape[1], t.shape[0]),
                               borderMode=cv2.BORDER_REPLICATE)
    else:
        t = render_mark(kind, size_full / red, angle)
    search = 2.0 * max(kx, ky) + 3.0 * red
    half = int(math.ceil(0.8 * size_full + search + 0.8 * max(t.shape) * red + 8))
    x0, y0 = max(0, int(fx) - half), max(0, int(fy) - half)
    x1, y1 = min(full_w, int(fx) + half + 1), min(full_h, int(fy) + half + 1)
    if x1 - x0 < 8 or y1 - y0 < 8:
        return None
    gw = _grey_window(scan, x0, y0, x1 - x0, y1 - y0)
    gs = gw if red == 1.0 else cv2.resize(gw, (max(8, int(round(gw.shape[1] / red))),
                                                max(8, int(round(gw.shape[0] / red)))),
                                          interpolation=cv2.INTER_AREA)
    sx_, sy_ = gw.shape[1] / gs.shape[1], gw.shape[0] / gs.shape[0]
    if gs.shape[0] <= t.shape[0] or gs.shape[1] <= t.shape[1]:
        return None
    r = cv2.matchTemplate(gs, t, cv2.TM_CCOEFF_NORMED) * pol
    r[~np.isfinite(r)] = -1
    # keep the peak near the coarse position
    ex, ey = (fx - x0 + 0.5) / sx_ - 0.5 - (t.shape[1] - 1) / 2.0, (fy - y0 + 0.5) / sy_ - 0.5 - (t.shape[0] - 1) / 2.0
    yy, xx = np.mgrid[0:r.shape[0], 0:r.shape[1]]
    r[np.hypot(xx - ex, yy - ey) > search / red + 1] = -1
    i, j = divmod(int(np.argmax(r)), r.shape[1])
    fine_score = float(r[i, j])
    ox, oy = _quadratic_peak(r, i, j)
    px = ((j + ox + (t.shape[1] - 1) / 2.0) + 0.5) * sx_ - 0.5  # window pixel-centre coordinates
    py = ((i + oy + (t.shape[0] - 1) / 2.0) + 0.5) * sy_ - 0.5
    if template is not None:
        size_full *= user.mark_frac  # the mark itself, without the template's margin
    if template is None or user.symmetric:
        qx, qy, ok = refine_symmetric(gw, px, py, size_full)
        if ok and math.hypot(qx - px, qy - py) <= max(2.0 * red, 0.25 * size_full):
            px, py = qx, qy
        else:
            note = f"{os.path.basename(path)}: fiducial {slot}: centre of symmetry not found, correlation peak used"
    cx_full, cy_full = x0 + px + 0.5, y0 + py + 0.5
    extent = _mark_extent(scan, cx_full, cy_full, size_full)
    if kind in ("cross", "ring_dot", "cross_ring"):  # the template is the whole mark (a cross at least 0.7 of a ring)
        extent = min(extent, 1.5 * size_full)  # a ring touching the picture does not make the picture the mark
    return Fiducial(slot=slot, x=cx_full, y=cy_full, score=min(sc, fine_score) if fine_score > 0 else sc,
                    kind=kind, size_px=max(size_full, extent), polarity=int(pol), note=note)


def _mark_extent(scan: RasterFile, x: float, y: float, size: float) -> float:
    """Diameter (scan pixels) of the mark at (x, y): out to where its contrast with the ground ends.

    Guards the masks against a mark classified by its inner part only (the
    dot of a dot-in-circle).  Stops at the first gap, so a data strip or the
    picture beyond the ground does not count.
    """
    r = int(min(max(3.0 * size, 12.0), 400.0))
    xi, yi = int(x), int(y)
    x0, y0 = max(0, xi - r), max(0, yi - r)
    x1, y1 = min(scan.width, xi + r + 1), min(scan.height, yi + r + 1)
    g = _grey_window(scan, x0, y0, x1 - x0, y1 - y0)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    d = np.hypot(xx + 0.5 - x, yy + 0.5 - y)
    core = d <= 0.5 * size
    ring = (d > 0.75 * size) & (d <= 1.0 * size)
    if not ring.any() or not core.any():
        return size
    ground = float(np.median(g[ring]))
    dev = np.abs(g - ground)
    noise = 1.4826 * float(np.median(np.abs(g[ring] - ground))) + 1e-6
    thr = max(5.0 * noise, 0.25 * float(np.percentile(dev[core], 99)))
    radius, gap = 0.0, 0
    for k in range(int(r)):
        ann = (d >= k) & (d < k + 1)
        if not ann.any():
            break
        if float(np.percentile(dev[ann], 95)) > thr:
            radius, gap = k + 1.0, 0
        else:
            gap += 1
            if gap >= 3 and k > 0.25 * size:
                break
    return 2.0 * radius


# ---------------------------------------------------------------------------
# calibrated coordinates, frames, affine fits
# ---------------------------------------------------------------------------

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


CALIBRATION_FILE_EXTENSIONS = (".yaml", ".yml", ".json", ".xml")  # a camera calibration (core.io.calibration)


def _fiducials_of_calibration(path: str) -> str:
    """The fiducial coordinates (and principal point, focal length) of the one camera of a calibration file that
    has them, as parse_fiducial_coordinates' text; ScanError naming the file when none or several have them."""
    from ..io.calibration import CalibrationError, read_calibration

    try:
        cams = [c for c in read_calibration(path) if c.fiducials_mm]
    except CalibrationError as e:
        raise ScanError(str(e)) from e
    if len(cams) != 1:
        which = "no camera of this calibration file gives" if not cams else f"{len(cams)} cameras of it give"
        raise ScanError(f"{path}: {which} fiducial coordinates; the scans need exactly one camera's (or give the "
                        "marks as text: 'id x y' per line, in mm)")
    return cams[0].fiducial_coordinates_text()


def parse_fiducial_coordinates(spec: str) -> CalibratedFiducials:
    """Calibrated fiducial coordinates from a file path or text; a camera calibration file (.yaml, .yml, .json,
    .xml: core.io.calibration, the one its Align images reads) gives its camera's fiducials, principal point and
    focal length.

    One mark per line: ``id x y`` (or ``x y``), in mm, x right, y up (the
    calibration certificate's photo coordinates); separators: spaces, commas,
    semicolons, tabs; ``#`` starts a comment; header lines are ignored.  A line
    ``PP x y`` (also ``PPA``, ``PPS``, ``principal_point``) gives the principal
    point in the same system (default 0 0); a line ``focal f`` (also ``f``,
    ``c``, ``focal_length``) the calibrated focal length in mm.  Marks are
    assigned to the slots TL T TR R BR B BL L by their direction from the
    centre of all marks.
    """
    text = spec
    if spec and os.path.isfile(spec) and spec.lower().endswith(CALIBRATION_FILE_EXTENSIONS):
        text = _fiducials_of_calibration(spec)
    elif spec and os.path.isfile(spec):
        try:
            with open(spec, encoding="utf-8-sig") as f:
                text = f.read()
        except (OSError, UnicodeDecodeError) as e:
            raise ScanError(f"{spec}: fiducial coordinates cannot be read ({e})") from e
    where = spec if spec and os.path.isfile(spec) else "fiducial coordinates"
    pts: List[Tuple[str, float, float]] = []
    pp = (0.0, 0.0)
    focal = None
    for ln, raw in enumerate((text or "").splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = [p for p in re.split(r"[\s,;]+", line) if p]
        key = parts[0].lower()
        nums = [p for p in parts if re.fullmatch(_NUM, p)]
        if key in ("pp", "ppa", "pps", "principal_point", "principalpoint"):
            if len(nums) < 2:
                raise ScanError(f"{where}, line {ln}: principal point needs x and y: {raw.strip()!r}")
            pp = (float(nums[-2]), float(nums[-1]))
            continue
        if key in ("focal", "f", "c", "focal_length", "focallength", "ck"):
            if not nums:
                raise ScanError(f"{where}, line {ln}: focal length needs a value: {raw.strip()!r}")
            focal = float(nums[-1])
            continue
        if len(nums) == len(parts) and len(nums) in (2, 3):
            ident = nums[0] if len(nums) == 3 else str(len(pts) + 1)
            pts.append((ident, float(nums[-2]), float(nums[-1])))
        elif len(parts) == 3 and len(nums) == 2:  # "F1 -106.0 106.0"
            pts.append((parts[0], float(nums[0]), float(nums[1])))
        elif nums:
            raise ScanError(f"{where}, line {ln}: expected 'id x y' in mm: {raw.strip()!r}")
    if len(pts) < 3:
        raise ScanError(f"{where}: at least 3 fiducial marks are needed, found {len(pts)}")
    c = np.mean([[p[1], p[2]] for p in pts], axis=0)
    slots: Dict[str, Tuple[float, float]] = {}
    ids: Dict[str, str] = {}
    for ident, x, y in pts:
        a = math.degrees(math.atan2(y - c[1], x - c[0]))
        slot = min(SLOTS, key=lambda s: abs((a - math.degrees(math.atan2(SLOTS[s][1], SLOTS[s][0])) + 180) % 360 - 180))
        if slot in slots:
            raise ScanError(f"{where}: marks {ids[slot]} and {ident} both lie in the {slot} direction; "
                            "give at most one mark per corner and side")
        slots[slot] = (x - pp[0], y - pp[1])
        ids[slot] = ident
    return CalibratedFiducials(points=slots, ids=ids, focal_length_mm=focal)


def fit_affine(frame_pts: np.ndarray, pixel_pts: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Least-squares affine frame (x, y) -> pixel (x, y); returns (2 x 3 matrix, residual vectors n x 2)."""
    a = np.column_stack([frame_pts, np.ones(len(frame_pts))])
    m, *_ = np.linalg.lstsq(a, pixel_pts, rcond=None)
    m = m.T
    return m, pixel_pts - a @ m.T


def _similarity(src: np.ndarray, dst: np.ndarray) -> Tuple[float, np.ndarray, np.ndarray]:
    """Umeyama similarity dst ~ s R src + t; returns (s, R, t)."""
    mu_s, mu_d = src.mean(0), dst.mean(0)
    a, b = src - mu_s, dst - mu_d
    u, sig, vt = np.linalg.svd(b.T @ a)
    d = np.eye(2)
    if np.linalg.det(u @ vt) < 0:
        d[1, 1] = -1
    r = u @ d @ vt
    var = (a ** 2).sum()
    s = float((sig * np.diag(d)).sum() / var) if var > 0 else 1.0
    return s, r, mu_d - s * r @ mu_s


def mean_frame(detections: Sequence[Dict[str, Tuple[float, float]]]) -> Dict[str, Tuple[float, float]]:
    """Mean fiducial layout of a set (generalised Procrustes), x right, y up, origin at the fiducial centre,
    scaled to the median scan's pixels and turned upright."""
    slots = sorted(set().union(*[d.keys() for d in detections]), key=list(SLOTS).index)
    # image (y down) -> y up
    sets = [{k: np.array([v[0], -v[1]]) for k, v in d.items()} for d in detections]
    ref = max(sets, key=len)
    mean = {k: v.copy() for k, v in ref.items()}
    for _ in range(5):
        acc: Dict[str, List[np.ndarray]] = {k: [] for k in slots}
        for d in sets:
            common = [k for k in d if k in mean]
            if len(common) < 2:
                continue
            s, r, t = _similarity(np.array([d[k] for k in common]), np.array([mean[k] for k in common]))
            for k, v in d.items():
                acc[k].append(s * r @ v + t)
        mean = {k: np.mean(v, axis=0) for k, v in acc.items() if v}
    # size: median of the scans' RMS radii; origin: fiducial centre; upright
    def rms(d):
        p = np.array(list(d.values()))
        return float(np.sqrt(((p - p.mean(0)) ** 2).sum(1).mean()))
    scale = float(np.median([rms(d) for d in sets if len(d) >= 2])) / max(rms(mean), 1e-12)
    centre = _fiducial_centre(mean)
    pts = {k: (v - centre) * scale for k, v in mean.items()}
    ideal = np.array([SLOTS[k] for k in pts], float)
    got = np.array(list(pts.values()))
    # rotation only: best angle taking ideal directions onto the mean layout
    ang = math.atan2(float((ideal[:, 0] * got[:, 1] - ideal[:, 1] * got[:, 0]).sum()),
                     float((ideal * got).sum()))
    c, s_ = math.cos(-ang), math.sin(-ang)
    rot = np.array([[c, -s_], [s_, c]])
    return {k: tuple(float(x) for x in rot @ v) for k, v in pts.items()}


def _fiducial_centre(points: Dict[str, np.ndarray]) -> np.ndarray:
    """Mean of the midpoints of opposite marks (their lines' crossing for symmetric layouts)."""
    mids = [(np.asarray(points[a]) + np.asarray(points[b])) / 2 for a, b in OPPOSITE.items()
            if a in points and b in points]
    if mids:
        return np.mean(mids, axis=0)
    return np.mean([np.asarray(v) for v in points.values()], axis=0)


def _fit_scan(frame: Dict[str, Tuple[float, float]], fids: List[Fiducial], max_residual: float,
              name: str) -> Tuple[np.ndarray, List[Fiducial], List[str], List[str]]:
    """Affine frame -> scan for one scan with outlier removal; returns (matrix, used marks, dropped, warnings)."""
    use = [f for f in fids if f.slot in frame]
    dropped, warnings = [], []
    while True:
        if len(use) < 3:
            raise ScanError(f"{name}: only {len(use)} fiducial mark(s) found "
                            f"({', '.join(f.slot for f in use) or 'none'}); at least 3 are needed. Check the "
                            "fiducial type and layout, or give a template of one mark")
        fp = np.array([frame[f.slot] for f in use], float)
        pp = np.array([[f.x, f.y] for f in use], float)
        m, res = fit_affine(fp, pp)
        err = np.hypot(res[:, 0], res[:, 1])
        for f, e in zip(use, err):
            f.residual_px = float(e)
        k = int(np.argmax(err))
        if len(use) >= 5 and err[k] > max_residual:
            dropped.append(use[k].slot)
            warnings.append(f"{name}: fiducial {use[k].slot} dropped: {err[k]:.1f} px from the affine fit "
                            "of the others")
            use = use[:k] + use[k + 1:]
            continue
        if err.max() > max_residual:
            warnings.append(f"{name}: fiducial residuals up to {err.max():.1f} px (limit {max_residual:g}): "
                            "check the marks or the calibrated coordinates")
        return m, use, dropped, warnings


def _implausible_fits(fits: Dict[str, tuple], calibrated: bool, res_mm: Dict[str, Optional[float]],
                      max_residual: float) -> Dict[str, str]:
    """Scans whose affine cannot be a restitution: scan name -> the warning that names it and says why.

    Residuals a little over ``max_residual`` are a warning (a worn mark, a scratch); a scan is left out when

    - a residual exceeds 4 x ``max_residual`` (with four marks the affine keeps only two redundancies, so a mark
      found tens of pixels from the real one shows as a fraction of that: something else was found);
    - the affine is not a film's: x and y scales more than 2 % apart or axes more than 2 degrees from square
      (shrinkage and scanners stay well under 0.5 %); with three scans or more, measured from the set's median,
      with two from their mean when they agree (a scanner with non-square pixels gives the whole set one shape);
    - with three scans or more of known resolution (file tags or ``scan_pixel_size_mm``): its scan pixel in
      frame units, over that resolution, is more than 5 % off the set's median (film shrinkage differs by
      tenths of a percent; a wrong resolution given for the whole set moves them all alike).

    A wrong restitution would otherwise travel silently into the alignment (wrong pixel size, a rotated
    frame); a user expects the set's good scans prepared and the bad one named, so it is left out with a
    warning, and the stage fails when fewer than two scans remain (:func:`prepare_scans`).
    """
    shape = {}
    for n, (m, _used, _d, _w) in fits.items():
        ex, ey = m[:, 0], m[:, 1]  # the frame's axes in the scan
        cos = float(ex @ ey) / float(np.linalg.norm(ex) * np.linalg.norm(ey))
        shape[n] = (float(np.linalg.norm(ex) / np.linalg.norm(ey)) - 1.0, math.degrees(math.asin(max(-1.0, min(1.0, cos)))))
    ref = np.median(np.array(list(shape.values())), axis=0) if len(fits) >= 3 else np.zeros(2)
    if len(fits) == 2:  # two scans of one shape (a scanner's non-square pixels) are that shape
        a, b = shape.values()
        if abs(a[0] - b[0]) <= 0.02 and abs(a[1] - b[1]) <= 2.0:
            ref = 0.5 * (np.array(a) + np.array(b))
    # frame units per scan pixel over the file's resolution: one value for the set whatever the scans' dpi
    ratio = {n: 1.0 / math.sqrt(abs(np.linalg.det(f[0][:, :2]))) / res_mm[n] for n, f in fits.items() if res_mm.get(n)}
    ref_ratio = float(np.median(list(ratio.values()))) if len(ratio) >= 3 else None
    out = {}
    for n, (_m, used, _d, _w) in fits.items():
        worst = max(used, key=lambda f: f.residual_px or 0.0)
        aniso, skew = shape[n]
        if worst.residual_px > 4.0 * max_residual:
            why = (f"fiducial {worst.slot} lies {worst.residual_px:.1f} px from the affine fit (limit {max_residual:g}, "
                   f"{4 * max_residual:g} at most): the marks found do not fit the "
                   f"{'calibrated coordinates' if calibrated else 'set'}")
        elif abs(aniso - ref[0]) > 0.02 or abs(skew - ref[1]) > 2.0:
            why = (f"the fiducial fit scales x and y {100 * aniso:+.1f} % apart and skews the axes by {skew:.1f} deg"
                   + (f" (the set: {100 * ref[0]:+.1f} %, {ref[1]:.1f} deg)" if ref.any() else "")
                   + ": not a film's shrinkage")
        elif ref_ratio and n in ratio and abs(ratio[n] / ref_ratio - 1.0) > 0.05:
            why = (f"the fiducial fit gives {ratio[n] * res_mm[n]:.4f} mm scan pixels at a resolution of "
                   f"{res_mm[n]:.4f} mm, {100 * (ratio[n] / ref_ratio - 1):+.1f} % off the set's other scans")
        else:
            continue
        out[n] = f"{n}: left out: {why}; check the marks (fiducial type, template) or the coordinates"
    return out


def _consistent_slots(dets: Dict[str, List[Fiducial]], tol_frac: float = 0.01) -> Tuple[List[str], List[str]]:
    """Slots found in at least half of the scans and at a consistent frame position across them."""
    n = len(dets)
    counts: Dict[str, int] = {}
    for fids in dets.values():
        for f in fids:
            counts[f.slot] = counts.get(f.slot, 0) + 1
    slots = [s for s in SLOTS if counts.get(s, 0) * 2 >= n]
    warnings = []
    if n < 3:
        return slots, warnings
    while len(slots) > 3:
        sets = [{f.slot: (f.x, f.y) for f in fids if f.slot in slots} for fids in dets.values()]
        sets = [d for d in sets if len(d) >= 3]
        frame = mean_frame(sets)
        size = max(np.hypot(*v) for v in frame.values())
        spread = {s: [] for s in slots}
        for d in sets:
            y_up = {k: (v[0], -v[1]) for k, v in d.items()}
            common = [k for k in d if k in frame]
            sc, r, t = _similarity(np.array([y_up[k] for k in common]), np.array([frame[k] for k in common]))
            for k in common:
                spread[k].append(float(np.hypot(*(sc * r @ np.array(y_up[k]) + t - np.array(frame[k])))))
        worst = max(slots, key=lambda s: np.median(spread[s]))
        if np.median(spread[worst]) <= tol_frac * size:
            break
        warnings.append(f"fiducial position {worst} left out: the marks found there are not at one place "
                        f"of the frame across the scans (median deviation {np.median(spread[worst]):.1f} px)")
        slots.remove(worst)
    return slots, warnings


# ---------------------------------------------------------------------------
# restitution and masks
# ---------------------------------------------------------------------------

def _cv_matrix(m: np.ndarray) -> np.ndarray:
    """A 2 x 3 map between corner-convention coordinates as a map between OpenCV pixel-centre coordinates."""
    out = m.astype(np.float64).copy()
    out[:, 2] = m[:, 2] + m[:, :2] @ np.array([0.5, 0.5]) - 0.5
    return out


def restitute(path: str, out_to_scan: np.ndarray, width: int, height: int, out_path: str,
              metadata: Optional[Dict[str, str]] = None, progress: Optional[Progress] = None,
              strip_rows: int = 512) -> None:
    """Resample a scan into the output grid, strip by strip (bicubic, anti-aliased when shrinking).

    ``out_to_scan``: 2 x 3, output pixel (corner convention) -> scan pixel.  Writes
    a tiled, DEFLATE-compressed TIFF of the scan's bands and data type.
    """
    cv2 = require("cv2", "scanned film")

    gdal = _gdal()
    progress = progress or NullProgress()
    scan = open_image(path)
    sw, sh, nb = scan.width, scan.height, scan.count
    dtype = scan.band(1).DataType
    shrink = math.sqrt(abs(np.linalg.det(out_to_scan[:, :2])))  # scan pixels per output pixel
    sigma = 0.5 * math.sqrt(shrink ** 2 - 1.0) if shrink > 1.05 else 0.0
    opts = ["TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=2", "BIGTIFF=IF_SAFER"]
    if nb in (3, 4) and dtype in (gdal.GDT_Byte, gdal.GDT_UInt16):
        opts.append("PHOTOMETRIC=RGB")
    out = gdal.GetDriverByName("GTiff").Create(out_path, width, height, nb, dtype, options=opts)
    if out is None:
        raise ScanError(f"{out_path}: cannot be created")
    try:
        if metadata:
            out.SetMetadata(metadata)
        if nb in (3, 4):
            for b, ci in zip(range(1, nb + 1), (gdal.GCI_RedBand, gdal.GCI_GreenBand, gdal.GCI_BlueBand,
                                                gdal.GCI_AlphaBand)):
                out.GetRasterBand(b).SetColorInterpretation(ci)
        mcv = _cv_matrix(out_to_scan)
        pad = 4 + int(math.ceil(3 * sigma))
        for r0 in range(0, height, strip_rows):
            check_cancel(progress)
            r1 = min(height, r0 + strip_rows)
            corners = np.array([[0, r0], [width, r0], [0, r1], [width, r1]], float)
            src = corners @ out_to_scan[:, :2].T + out_to_scan[:, 2]
            x0 = max(0, int(math.floor(src[:, 0].min())) - pad)
            y0 = max(0, int(math.floor(src[:, 1].min())) - pad)
            x1 = min(sw, int(math.ceil(src[:, 0].max())) + pad)
            y1 = min(sh, int(math.ceil(src[:, 1].max())) + pad)
            if x1 <= x0 or y1 <= y0:
                block = np.zeros((r1 - r0, width, nb), dtype=_np_dtype(dtype))
            else:
                win = _read_window(scan, x0, y0, x1 - x0, y1 - y0)
                m = mcv.copy()
                m[:, 2] = mcv[:, :2] @ np.array([0.0, r0]) + mcv[:, 2] - np.array([x0, y0])
                chans = []
                for b in range(nb):
                    ch = np.ascontiguousarray(win[:, :, b])
                    if sigma > 0:
                        ch = cv2.GaussianBlur(ch.astype(np.float32), (0, 0), sigma).astype(ch.dtype) \
                            if ch.dtype not in (np.uint8, np.uint16) else cv2.GaussianBlur(ch, (0, 0), sigma)
                    chans.append(cv2.warpAffine(ch, m, (width, r1 - r0),
                                                flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP,
                                                borderMode=cv2.BORDER_CONSTANT, borderValue=0))
                block = np.stack(chans, axis=-1)
            for b in range(nb):
                out.GetRasterBand(b + 1).WriteArray(block[:, :, b], 0, r0)
            progress.report(r1 / height, f"resampling {os.path.basename(path)}")
        out.FlushCache()
    finally:
        out = None
        scan.close()


def _np_dtype(gdal_type):
    from osgeo import gdal_array

    return gdal_array.GDALTypeCodeToNumericTypeCode(gdal_type)


def _image_area_edges(grey: np.ndarray, valid: np.ndarray) -> Optional[Tuple[float, float, float, float]]:
    """Edges (x0, y0, x1, y1, in pixels of ``grey``) of the picture area inside a uniform film border.

    The border is what looks like the outer ring of the image: the same grey
    level and no texture beyond grain.  From the centre outwards, the first
    columns (rows) that are mostly border end the picture; a data strip or the
    film edge further out does not matter.
    """
    cv2 = require("cv2", "scanned film")

    g = grey.astype(np.float32)
    k = (5, 5)
    mu = cv2.blur(g, k)
    sd = np.sqrt(np.maximum(cv2.blur(g * g, k) - mu * mu, 0))
    v = cv2.erode(valid.astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
    h, w = g.shape
    centre = np.zeros_like(v)
    centre[int(0.3 * h):int(0.7 * h), int(0.3 * w):int(0.7 * w)] = True
    ring = np.ones_like(v)
    ring[int(0.06 * h):int(0.94 * h), int(0.06 * w):int(0.94 * w)] = False
    if not (centre & v).any() or not (ring & v).any():
        return None
    level = float(np.median(mu[ring & v]))
    noise = float(np.median(sd[ring & v]))
    border = (np.abs(mu - level) < max(5.0 * noise, 0.03)) & (sd < max(3.0 * noise, 0.01))
    if border[ring & v].mean() < 0.4 or border[centre & v].mean() > 0.5:
        return None  # no uniform border around the picture
    content = ~border & v
    rows = slice(int(0.3 * h), int(0.7 * h))
    cols = slice(int(0.3 * w), int(0.7 * w))
    fx = content[rows, :].mean(axis=0)
    fy = content[:, cols].mean(axis=1)

    def edge(frac, start, step):
        i, run = start, 0
        while 0 <= i < len(frac):
            run = run + 1 if frac[i] < 0.5 else 0
            if run >= 3:
                return i - step * 2  # first column of the run
            i += step
        return None

    left, right = edge(fx, w // 2, -1), edge(fx, w // 2, 1)
    top, bottom = edge(fy, h // 2, -1), edge(fy, h // 2, 1)
    return (float(left + 1) if left is not None else 0.0, float(top + 1) if top is not None else 0.0,
            float(right) if right is not None else float(w), float(bottom) if bottom is not None else float(h))


@dataclass
class MaskLayout:
    """What the masks of a scan set share, in output pixels: the output size, the picture area (x0, y0, x1, y1;
    None: the whole frame), the fiducial marks (x, y, radius) and the margin kept from each."""

    width: int
    height: int
    image_area: Optional[Tuple[float, float, float, float]]
    marks: Sequence[Tuple[float, float, float]]
    margin: float


def write_mask(path: str, layout: MaskLayout, scan_to_out: np.ndarray, scan_size: Tuple[int, int]) -> None:
    """Mask PNG, white = use, black = ignore: outside the scan (``scan_size`` (width, height) pixels, put on the
    output grid by ``scan_to_out``), outside the picture area, over the marks."""
    cv2 = require("cv2", "scanned film")

    width, height, image_area, margin = layout.width, layout.height, layout.image_area, layout.margin
    scan_w, scan_h = scan_size
    m = np.zeros((height, width), np.uint8)
    inset = margin + 2.0
    # the scan's rectangle, pulled in by ``inset`` output pixels, in output pixels
    sc = math.sqrt(abs(np.linalg.det(scan_to_out[:, :2])))  # output px per scan px
    d = inset / max(sc, 1e-9)
    corners = np.array([[d, d], [scan_w - d, d], [scan_w - d, scan_h - d], [d, scan_h - d]], float)
    poly = corners @ scan_to_out[:, :2].T + scan_to_out[:, 2] - 0.5  # to pixel-centre coordinates
    shift = 4
    cv2.fillConvexPoly(m, np.round(poly * (1 << shift)).astype(np.int32), 255, lineType=cv2.LINE_8, shift=shift)
    if image_area is not None:
        x0, y0, x1, y1 = image_area
        ix0, iy0 = max(0, int(math.ceil(x0 + margin))), max(0, int(math.ceil(y0 + margin)))
        ix1, iy1 = min(width, int(math.floor(x1 - margin))), min(height, int(math.floor(y1 - margin)))
        keep = np.zeros_like(m)
        if ix1 > ix0 and iy1 > iy0:
            keep[iy0:iy1, ix0:ix1] = 255
        m &= keep
    for x, y, r in layout.marks:
        cv2.circle(m, (int(round(x * 16 - 8)), int(round(y * 16 - 8))), int(round((r + margin) * 16)), 0, -1,
                   lineType=cv2.LINE_8, shift=4)
    if not cv2.imwrite(path, m):
        raise ScanError(f"{path}: mask cannot be written")


# ---------------------------------------------------------------------------
# the whole set
# ---------------------------------------------------------------------------

def _prepared_names(paths: Sequence[str]) -> List[str]:
    stems = [os.path.splitext(os.path.basename(p))[0] for p in paths]
    out = []
    for p, s in zip(paths, stems):
        base = s if stems.count(s) == 1 else os.path.basename(p).replace(".", "_")
        out.append(base + ".tif")
    return out


def prepare_scans(paths: Sequence[str], out_dir: str, masks_dir: str, options: Optional[ScanOptions] = None,
                  progress: Optional[Progress] = None) -> ScanSet:
    """Detect fiducials in every scan, resample all into one frame, write prepared images and masks.

    A scan whose fiducial fit cannot be a restitution (residuals over 4 x ``max_residual_px``, a shape or scale
    unlike a film's or the set's: :func:`_implausible_fits`) is left out: no prepared image, no mask, a warning
    that names it and says why, and ``ScanSet.left_out``; the good scans of the set are prepared.  ScanError when
    fewer than 2 scans would remain (the message names each scan left out and why): never a restitution that
    is silently wrong.  Residuals over ``max_residual_px`` but under that are warnings.
    """
    options = options or ScanOptions()
    progress = progress or NullProgress()
    if not paths:
        raise ScanError("no scans given")
    calib = parse_fiducial_coordinates(options.fiducial_coordinates) if options.fiducial_coordinates else None
    focal_mm = options.focal_length_mm or (calib.focal_length_mm if calib else None)
    warnings: List[str] = []
    names = [os.path.basename(p) for p in paths]

    # 1. detection
    dets, sizes, res_mm = _detect_set(paths, names, options, calib, SubProgress(progress, 0.0, 0.35), progress,
                                      warnings)
    # 2. the frame
    frame, units, calibrated = _set_frame(dets, res_mm, calib, options, warnings)

    # 3. per-scan affine; a scan whose marks do not fit the frame is left out
    fits: Dict[str, Tuple[np.ndarray, List[Fiducial], List[str], List[str]]] = {}
    for n in names:
        fits[n] = _fit_scan(frame, dets[n], options.max_residual_px, n)
    left_out = _implausible_fits(fits, calibrated, {n: options.scan_pixel_size_mm or res_mm[n] for n in names},
                                 options.max_residual_px)
    if left_out and len(names) - len(left_out) < 2:
        raise ScanError("fewer than 2 scans can be restituted: " + "; ".join(left_out.values()))
    warnings.extend(left_out.values())
    paths = [p_ for p_, n in zip(paths, names) if n not in left_out]
    names = [n for n in names if n not in left_out]
    for n in names:
        warnings.extend(fits[n][3])
        warnings.extend(f.note for f in fits[n][1] if f.note)
    scan_px = {n: 1.0 / math.sqrt(abs(np.linalg.det(fits[n][0][:, :2]))) for n in names}  # frame units / scan px
    p = float(options.output_pixel_size or np.median(list(scan_px.values())))
    mark_size = float(np.median([f.size_px * scan_px[n] for n in names for f in fits[n][1]]))
    margin = options.margin if options.margin is not None else mark_size
    hx = max(abs(v[0]) for v in frame.values()) + margin
    hy = max(abs(v[1]) for v in frame.values()) + margin
    width, height = 2 * int(math.ceil(hx / p)), 2 * int(math.ceil(hy / p))
    # output pixel (corner convention) -> frame: x = (qx - W/2) p, y = (H/2 - qy) p
    out_to_frame = np.array([[p, 0.0, -0.5 * width * p], [0.0, -p, 0.5 * height * p], [0.0, 0.0, 1.0]])
    io, metadata = _interior_orientation(units, calibrated, p, width, height, focal_mm, warnings)

    # 4. resampling
    prepared = _prepared_names(paths)
    scans: List[PreparedScan] = []
    rp = SubProgress(progress, 0.35, 0.9)
    for i, (path, n, pn) in enumerate(zip(paths, names, prepared)):
        check_cancel(progress)
        m, used, dropped, w = fits[n]
        out_to_scan = m @ out_to_frame
        restitute(path, out_to_scan, width, height, os.path.join(out_dir, pn), metadata,
                  SubProgress(rp, i / len(paths), (i + 1) / len(paths)))
        a = m[:, :2]
        rot = math.degrees(math.atan2(a[1, 0], a[0, 0]))  # frame x axis in the scan: clockwise on screen
        res = [f.residual_px for f in used]
        scans.append(PreparedScan(
            name=n, prepared_name=pn, mask_name=pn + ".png", scan_width=sizes[n][0], scan_height=sizes[n][1],
            fiducials=sorted(dets[n], key=lambda f: list(SLOTS).index(f.slot)), affine=m.tolist(),
            rms_px=float(np.sqrt(np.mean(np.square(res)))), max_residual_px=float(max(res)),
            rotation_deg=rot, scan_pixel_size=scan_px[n], dropped=dropped, warnings=w))

    # 5. masks
    check_cancel(progress)
    out_to_scans = {s.name: fits[s.name][0] @ out_to_frame for s in scans}
    image_area = None
    if options.mask_border:
        image_area = _set_image_area([os.path.join(out_dir, s.prepared_name) for s in scans],
                                     [out_to_scans[s.name] for s in scans],
                                     [sizes[s.name] for s in scans], width, height, warnings)
    marks_out = [((v[0] / p) + width / 2.0, height / 2.0 - v[1] / p, 0.75 * mark_size / p + 2.0)
                 for v in frame.values()]
    layout = MaskLayout(width, height, image_area, marks_out, options.mask_margin_px)
    for i, s in enumerate(scans):
        check_cancel(progress)
        scan_to_out = np.linalg.inv(np.vstack([out_to_scans[s.name], [0, 0, 1]]))[:2]
        write_mask(os.path.join(masks_dir, s.mask_name), layout, scan_to_out, (s.scan_width, s.scan_height))
        progress.report(0.9 + 0.1 * (i + 1) / len(scans), f"masks: {i + 1}/{len(scans)}")
    return ScanSet(scans=scans, frame={k: (float(v[0]), float(v[1])) for k, v in frame.items()}, units=units,
                   calibrated=calibrated, width=width, height=height, pixel_size=p, image_area=image_area,
                   interior_orientation=io, warnings=warnings, left_out=left_out)


def _detect_set(paths: Sequence[str], names: Sequence[str], options: ScanOptions,
                calib: Optional[CalibratedFiducials], sp: Progress, progress: Progress, warnings: List[str]):
    """Fiducials, size and resolution (mm, from the file) of every scan; ScanError when one has fewer than 3."""
    template = load_template(options.template_path) if options.template_path else None
    dets: Dict[str, List[Fiducial]] = {}
    sizes: Dict[str, Tuple[int, int]] = {}
    res_mm: Dict[str, Optional[float]] = {}
    hints: Dict[str, str] = {}
    for i, (p, n) in enumerate(zip(paths, names)):
        check_cancel(progress)
        fids, w = detect_fiducials(p, options, template, hints, calib.points if calib is not None else None)
        for f in fids:
            hints.setdefault(f.slot, f.kind)
        notes = {f.note for f in fids}
        warnings.extend(x for x in w if x not in notes)  # a mark's note only when it is used (prepare_scans)
        if calib is not None:
            fids = [f for f in fids if f.slot in calib.points]
        if len(fids) < 3:
            misfit = "".join(f"; {x.split(': ', 1)[1]}" for x in w if x not in notes)
            raise ScanError(f"{p}: only {len(fids)} fiducial mark(s) found "
                            f"({', '.join(f.slot for f in fids) or 'none'}; best correlation must reach "
                            f"{options.min_score:g}{misfit}); at least 3 are needed. Check the fiducial type and "
                            "layout, or give a template image of one mark")
        dets[n] = fids
        with open_image(p) as scan:
            sizes[n] = (scan.width, scan.height)
            res_mm[n] = scan_resolution_mm(scan)
        sp.report((i + 1) / len(paths), f"fiducials: {i + 1}/{len(paths)} scans ({n}: {len(fids)} marks)")
    return dets, sizes, res_mm


def _set_frame(dets: Dict[str, List[Fiducial]], res_mm: Dict[str, Optional[float]],
               calib: Optional[CalibratedFiducials], options: ScanOptions, warnings: List[str]):
    """(frame: slot -> coordinates, units "mm" or "px", calibrated): the certificate's, or the set's mean."""
    if calib is not None:
        return dict(calib.points), "mm", True
    slots, w = _consistent_slots(dets)
    warnings.extend(w)
    if len(slots) < 3:
        raise ScanError("fewer than 3 fiducial positions were found consistently across the scans "
                        f"({', '.join(slots) or 'none'}); check the fiducial type and layout")
    frame_px = mean_frame([{f.slot: (f.x, f.y) for f in fids if f.slot in slots} for fids in dets.values()])
    px_mm = options.scan_pixel_size_mm or _median([r for r in res_mm.values() if r])
    if px_mm:
        return {k: (v[0] * px_mm, v[1] * px_mm) for k, v in frame_px.items()}, "mm", False
    return frame_px, "px", False


def _interior_orientation(units: str, calibrated: bool, p: float, width: int, height: int,
                          focal_mm: Optional[float], warnings: List[str]) -> Tuple[dict, Dict[str, str]]:
    """The prepared images' interior orientation and the TIFF metadata that carries it to core.io.images."""
    pixel_size_mm = p if units == "mm" else None
    io = {
        "frame_units": units, "calibrated_fiducials": calibrated, "pixel_size": p,
        "pixel_size_mm": pixel_size_mm, "width": width, "height": height,
        "principal_point_px": [width / 2.0, height / 2.0],
        "principal_point_from": "calibrated fiducial coordinates" if calibrated else "fiducial centre",
        "focal_length_mm": focal_mm,
        "focal_px": (focal_mm / pixel_size_mm) if (focal_mm and pixel_size_mm) else None,
    }
    if focal_mm and not pixel_size_mm:
        warnings.append("the focal length in mm cannot be turned into pixels: give calibrated fiducial "
                        "coordinates (mm) or the scan resolution")
    metadata = {"ARCHAEOORTHO_FRAME": units, "ARCHAEOORTHO_PIXEL_SIZE": f"{p:.9g}"}
    if io["focal_px"]:
        px_per_cm = 10.0 / pixel_size_mm
        metadata.update({
            "EXIF_FocalLength": f"({focal_mm:.6g})", "EXIF_FocalPlaneXResolution": f"({px_per_cm:.9g})",
            "EXIF_FocalPlaneYResolution": f"({px_per_cm:.9g})", "EXIF_FocalPlaneResolutionUnit": "3",
            "EXIF_PixelXDimension": str(width), "EXIF_PixelYDimension": str(height),
            "EXIF_Model": "scanned film",
        })
    return io, metadata


def _median(values):
    return float(np.median(values)) if values else None


def _set_image_area(paths, out_to_scans, scan_sizes, width, height, warnings, size=640):
    """The picture area common to the set: median of the per-scan edges found from texture."""
    edges = []
    for path, m, (sw, sh) in zip(paths, out_to_scans, scan_sizes):
        arr = read_image(path, max_size=size)
        g = to_grey(arr)
        h, w = g.shape
        # valid: low-res pixel centres that map inside the scan
        yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
        qx, qy = (xx + 0.5) * width / w, (yy + 0.5) * height / h
        sx = m[0, 0] * qx + m[0, 1] * qy + m[0, 2]
        sy = m[1, 0] * qx + m[1, 1] * qy + m[1, 2]
        valid = (sx >= 0) & (sx <= sw) & (sy >= 0) & (sy <= sh)
        e = _image_area_edges(g, valid)
        if e is not None:
            fx, fy = width / w, height / h
            edges.append((e[0] * fx, e[1] * fy, e[2] * fx, e[3] * fy))
    if len(edges) * 2 < len(paths) or not edges:
        warnings.append("no uniform film border found around the picture area: the masks cover the "
                        "fiducial marks and the area outside the scans only")
        return None
    e = np.median(np.array(edges), axis=0)
    # low-res edge uncertainty: pull in by 2 low-res pixels
    pad = 2.0 * max(width, height) / size
    return (float(e[0] + pad), float(e[1] + pad), float(e[2] - pad), float(e[3] - pad))
