"""Band registration of one multispectral capture (issue 37): every band undistorted with its own lens model and
turned into the ideal pinhole frame of the rig's reference band, then refined by a small residual homography.

1. Model: each band's lens (``core/geometry/lens.py``: Pix4D fisheye or perspective, from the band file's tags and
   its EXIF focal plane resolution) and its rig relative rotation R_ref^T R.  The bands of a rig are a few
   centimetres apart: from flying height their baseline is a fraction of a pixel, so a band maps onto the
   reference by a pure rotation (an infinite homography), done here ray by ray through the lens models: output
   pixel -> ray of the reference pinhole -> ray of the band camera -> its pixel (one ``cv2.remap``).
2. Residual: the bands differ radiometrically (vegetation bright in NIR, dark in red), so they are compared by
   their gradient magnitude, which keeps edges whatever their sign or contrast.  Phase correlation (with an
   upsampled-DFT sub-pixel peak) over a grid of windows gives a shift per window; its median and worst magnitude
   are the registration residual reported before and after refinement.
3. Refinement: a homography of the output grid fitted robustly to the window shifts (iterated), so that
   what the rig's calibration leaves (a small rotation, the baseline's parallax at the scene's height, a lens
   model's error) is taken out; the model alone is reported beside it.  It is trusted when enough windows,
   measured again, agree with it (:meth:`RegistrationOptions.trusted_windows`): over water, snow or a blurred frame
   the windows are noise and a fit to them lands pixels off, so the band keeps the model only.
4. The rig calibrated once for the block (:func:`calibrate_rig`): the rig is rigid, so the captures' trusted
   corrections of a band agree; their median is the block's correction (reported in px, as a rotation and as
   calibrated RigRelatives, with the captures it rests on and their spread).  With it (``calibration``) a band
   that cannot be refined, or whose refinement lies beyond the block's tolerance, takes the block's correction
   (status ``block``; ``refined`` / ``model only`` otherwise).

Pure: NumPy and OpenCV; files read through ``core/io`` (band files, :func:`core.io.multispectral.write_band_stack`).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ..common.errors import ArchaeoOrthoError, require
from ..geometry.lens import (
    FisheyeLens,
    LensError,
    PerspectiveLens,
    PinholeLens,
    band_to_reference,
    fisheye_from_pix4d,
    perspective_from_pix4d,
    rig_rotation,
)
from ..io.multispectral import BandInfo, Capture, band_key, write_band_stack
from ..io.raster import RasterError, RasterFile

Lens = Union[FisheyeLens, PerspectiveLens, PinholeLens]


class BandRegistrationError(ArchaeoOrthoError, ValueError):
    """A capture whose bands cannot be registered; the message names the file and the problem."""


@dataclass(frozen=True)
class RegistrationOptions:
    """``reference``: the band the others are registered onto (None: the rig's reference camera, the band
    without rig relatives, else the first band); ``window``: side (px) of the phase-correlation windows (None:
    ``WINDOW_FRACTION`` of the frame's short side, at least ``MIN_WINDOW_PX``: :meth:`window_px`), laid on a
    ``grid`` (columns, rows) over the frame's central ``coverage`` fraction; ``iterations`` of the refinement
    (0: the model only); ``min_peak``: the phase-correlation peak below which a window is not trusted;
    ``upsample``: sub-pixel factor of the peak search."""
    # the window's side as a fraction of the frame's short side (1/6: 160 px on the Sequoia's 1280 x 960 bands,
    # the size the registration was checked with on the real capture), and the smallest window allowed
    WINDOW_FRACTION = 1 / 6
    MIN_WINDOW_PX = 32

    reference: Optional[str] = None
    window: Optional[int] = None
    grid: Tuple[int, int] = (6, 5)
    coverage: float = 0.9
    iterations: int = 2
    min_peak: float = 0.06
    upsample: int = 50

    def __post_init__(self):
        if self.window is not None and self.window < self.MIN_WINDOW_PX:
            raise BandRegistrationError(f"window {self.window} px: at least {self.MIN_WINDOW_PX}")
        if min(self.grid) < 1 or not 0.2 <= self.coverage <= 1.0:
            raise BandRegistrationError(f"grid {self.grid} / coverage {self.coverage}: a grid of at least 1 x 1 "
                                        f"windows over 0.2 .. 1 of the frame")
        if self.iterations < 0 or self.upsample < 1:
            raise BandRegistrationError(f"iterations {self.iterations} / upsample {self.upsample}: >= 0 / >= 1")

    # a band's own refinement is trusted when at least this share of the grid's windows (and MIN_TRUSTED_WINDOWS,
    # what a homography is fitted to; all of them on a smaller grid), measured again after it, agree with it within
    # AGREE_PX: over water, snow, a uniform field or a blurred frame the windows' phase-correlation peaks are
    # noise (0.06 - 0.10 on 80-px windows), their shifts random, and a fit to them lands pixels off
    TRUSTED_FRACTION = 1 / 3
    MIN_TRUSTED_WINDOWS = 8
    AGREE_PX = 0.5

    def trusted_windows(self) -> int:
        """How many windows must agree with a band's refinement for it to be trusted (``TRUSTED_FRACTION``)."""
        n = self.grid[0] * self.grid[1]
        return max(int(math.ceil(n * self.TRUSTED_FRACTION)), min(self.MIN_TRUSTED_WINDOWS, n))

    def window_px(self, shape: Tuple[int, int]) -> int:
        """The window's side (px) on a frame of ``shape`` (rows, cols): ``window`` when set, else
        ``WINDOW_FRACTION`` of the short side, at least ``MIN_WINDOW_PX``."""
        if self.window is not None:
            return int(self.window)
        return max(self.MIN_WINDOW_PX, int(round(min(shape[:2]) * self.WINDOW_FRACTION)))


# ---------------------------------------------------------------- the model
def band_lens(info: BandInfo) -> Lens:
    """The band's lens model in pixels from its tags (Pix4D fisheye / perspective) and its EXIF focal plane
    resolution; BandRegistrationError naming the file and what is missing."""
    lens, res = info.lens, info.focal_plane_px_per_mm
    if lens.kind not in ("fisheye", "perspective"):
        raise BandRegistrationError(f"{info.name}: lens model {lens.kind!r} (Camera:ModelType): only Pix4D's "
                                    f"'fisheye' and 'perspective' are known here")
    missing = [n for n, v in (("Camera:PrincipalPoint", lens.principal_point_mm),
                              ("EXIF FocalPlaneXResolution", res)) if v is None]
    if lens.kind == "fisheye":
        missing += [n for n, v in (("Camera:FisheyeAffineMatrix", lens.fisheye_affine),
                                   ("Camera:FisheyePolynomial", lens.fisheye_polynomial)) if v is None]
    elif lens.focal_length is None or (lens.focal_length_unit or "mm").lower() != "mm":
        missing.append("Camera:PerspectiveFocalLength in mm")
    if missing:
        raise BandRegistrationError(f"{info.name}: its {lens.kind} lens model lacks {', '.join(missing)}")
    try:
        if lens.kind == "fisheye":
            return fisheye_from_pix4d(lens.principal_point_mm, res, lens.fisheye_affine, lens.fisheye_polynomial)
        return perspective_from_pix4d(lens.principal_point_mm, lens.focal_length, res, lens.distortion)
    except LensError as e:
        raise BandRegistrationError(f"{info.name}: {e}") from e


@dataclass(frozen=True)
class BandCamera:
    """One band of a capture: its file, lens and the rotation of its rays into the reference camera's."""
    name: str
    path: str
    lens: Lens
    rotation: np.ndarray
    relatives: Optional[Tuple[float, ...]]

    @property
    def rotation_deg(self) -> Tuple[float, float, float]:
        """The rotation as small angles about x, y, z (degrees): what the model turns this band by."""
        r = self.rotation
        return (math.degrees(math.atan2(r[2, 1], r[2, 2])), math.degrees(math.asin(max(-1.0, min(1.0, -r[2, 0])))),
                math.degrees(math.atan2(r[1, 0], r[0, 0])))


def reference_band(capture: Capture, name: Optional[str] = None) -> BandInfo:
    """The band the others are registered onto: ``name`` when given, else the band without rig relatives (the
    rig's reference camera), else the first band; RGB frames are not bands of the rig's band cameras."""
    bands = [b for b in capture.bands if not b.is_rgb]
    if not bands:
        raise BandRegistrationError(f"capture {capture.capture_id}: no band files (only RGB frames)")
    if name is not None:
        hit = next((b for b in bands if band_key(b.band_name) == band_key(name)), None)
        if hit is None:
            raise BandRegistrationError(f"capture {capture.capture_id}: no band {name!r} "
                                        f"(bands: {', '.join(b.band_name or '?' for b in bands)})")
        return hit
    return next((b for b in bands if b.rig_relatives is None), bands[0])


def band_cameras(capture: Capture, reference: Optional[str] = None) -> Tuple[List[BandCamera], BandCamera]:
    """The capture's band cameras (RGB frames left out: another sensor, size and shutter) and the reference."""
    ref = reference_band(capture, reference)
    cams = []
    for b in capture.bands:
        if b.is_rgb:
            continue
        if (b.width, b.height) != (ref.width, ref.height):
            raise BandRegistrationError(f"{b.name}: {b.width} x {b.height} px, the reference band {ref.name} "
                                        f"{ref.width} x {ref.height}: the bands of a rig must share a frame size")
        rot = band_to_reference(b.rig_relatives, ref.rig_relatives)
        cams.append(BandCamera(b.band_name or b.name, b.path, band_lens(b), rot, b.rig_relatives))
    return cams, next(c for c in cams if c.path == ref.path)


def reference_frame(ref: BandCamera) -> PinholeLens:
    """The ideal pinhole of the reference band: its focal length at the centre and its principal point."""
    return PinholeLens(ref.lens.focal_px, ref.lens.cx, ref.lens.cy)


def band_map(cam: BandCamera, frame: PinholeLens, shape: Tuple[int, int],
             correction: Optional[np.ndarray] = None) -> Tuple[np.ndarray, np.ndarray]:
    """Where each pixel of the output frame (rows, cols) is sampled in the band's own image: the output pixel
    (moved by ``correction``, a 3 x 3 homography of output pixels, when given) -> reference pinhole ray -> band ray
    (R^T) -> band pixel.  float32 maps for ``cv2.remap``; NaN-free (out of reach: -1e6, read as outside)."""
    v, u = np.mgrid[0:shape[0], 0:shape[1]].astype(np.float64)
    if correction is not None:
        a = np.asarray(correction, dtype=np.float64)
        w = a[2, 0] * u + a[2, 1] * v + a[2, 2]
        u, v = (a[0, 0] * u + a[0, 1] * v + a[0, 2]) / w, (a[1, 0] * u + a[1, 1] * v + a[1, 2]) / w
    rays = frame.unproject(np.stack([u, v], axis=-1)) @ cam.rotation   # row-vector form of R^T ray
    px = cam.lens.project(rays)
    px = np.where(np.isfinite(px), px, -1e6)
    return px[..., 0].astype(np.float32), px[..., 1].astype(np.float32)


def warp(image: np.ndarray, maps: Tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The band resampled (bilinear) on the maps, float32, NaN where the map leaves the band's frame."""
    cv2 = require("cv2", "band registration")
    src = np.asarray(image, dtype=np.float32)
    out = cv2.remap(src, maps[0], maps[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan)
    h, w = src.shape
    inside = (maps[0] >= 0) & (maps[0] <= w - 1) & (maps[1] >= 0) & (maps[1] <= h - 1)
    out[~inside] = np.nan
    return out


# ---------------------------------------------------------------- measuring the residual
def gradient_image(image: np.ndarray, sigma: float = 1.0) -> np.ndarray:
    """Gradient magnitude of the image smoothed by a Gaussian of ``sigma`` px, NaN where the image is NaN (and
    next to it): edges whatever the band's radiometry (sign and contrast of an edge differ between bands)."""
    cv2 = require("cv2", "band registration")
    a = np.asarray(image, dtype=np.float32)
    valid = np.isfinite(a)
    fill = float(np.nanmedian(a)) if valid.any() else 0.0
    b = cv2.GaussianBlur(np.where(valid, a, fill), (0, 0), sigma)
    gx, gy = cv2.Sobel(b, cv2.CV_32F, 1, 0, ksize=3), cv2.Sobel(b, cv2.CV_32F, 0, 1, ksize=3)
    g = np.sqrt(gx * gx + gy * gy)
    grown = cv2.erode(valid.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    g[~grown] = np.nan
    return g


def _hann(shape: Tuple[int, int]) -> np.ndarray:
    return np.outer(np.hanning(shape[0]), np.hanning(shape[1]))


def phase_shift(a: np.ndarray, b: np.ndarray, upsample: int = 50) -> Tuple[float, float, float]:
    """The shift (dx, dy) with b(p + d) = a(p) by phase correlation of two equal windows (Hann-tapered, their
    means removed), the peak refined by an upsampled DFT around it (Guizar-Sicairos et al. 2008) to 1 /
    ``upsample`` px; and the peak's height (1 for identical windows, near 0 for unrelated ones)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    win = _hann(a.shape)
    fa, fb = np.fft.fft2((a - a.mean()) * win), np.fft.fft2((b - b.mean()) * win)
    cross = np.conj(fa) * fb
    cross /= np.maximum(np.abs(cross), 1e-12 * np.abs(cross).max() + 1e-30)
    corr = np.fft.ifft2(cross).real
    m, n = corr.shape
    iy, ix = np.unravel_index(int(np.argmax(corr)), corr.shape)
    py, px = (iy if iy <= m // 2 else iy - m), (ix if ix <= n // 2 else ix - n)
    if upsample > 1:
        return _refine_peak(cross, float(px), float(py), upsample)
    return float(px), float(py), float(corr[iy, ix])


COARSE_UPSAMPLE = 5  # the peak's first refinement: +-1 px at 1/5 px, then +-1/5 px at 1/upsample


def _refine_peak(cross: np.ndarray, px: float, py: float, upsample: int) -> Tuple[float, float, float]:
    """The correlation peak near (px, py) by the upsampled DFT of the normalised cross-power spectrum, in two
    steps (+-1 px at 1 / COARSE_UPSAMPLE, then +-1 / COARSE_UPSAMPLE px at 1 / ``upsample``): the same peak as
    one (2 upsample + 1)^2 grid over +-1 px, with matrices a tenth the size (the single grid through a threaded
    BLAS on busy cores: 48 ms a window; these: under 1 ms)."""
    m, n = cross.shape
    fy, fx = np.fft.fftfreq(m), np.fft.fftfreq(n)
    peak, reach = 0.0, 1.0
    for factor in (min(COARSE_UPSAMPLE, upsample), upsample):
        half = int(round(reach * factor))
        offs = np.arange(-half, half + 1) / factor
        ey = np.exp(2j * np.pi * np.outer(py + offs, fy))
        ex = np.exp(2j * np.pi * np.outer(px + offs, fx))
        # einsum, not @: these products are too small to gain from BLAS threads, which on busy cores cost a
        # scheduler slice at each product
        fine = np.einsum("ik,jk->ij", np.einsum("ik,kl->il", ey, cross), ex).real / (m * n)
        jy, jx = np.unravel_index(int(np.argmax(fine)), fine.shape)
        px, py, peak = px + offs[jx], py + offs[jy], float(fine[jy, jx])
        reach = 1.0 / factor
    return float(px), float(py), peak


@dataclass(frozen=True)
class WindowShift:
    """One window's measurement: its centre (x, y) in the output frame, the shift (dx, dy) of the band against
    the reference there (px; b(p + d) = ref(p)) and the phase-correlation peak."""
    x: float
    y: float
    dx: float
    dy: float
    peak: float


def window_centres(shape: Tuple[int, int], options: RegistrationOptions) -> List[Tuple[int, int]]:
    """Top-left corners of the grid of windows over the frame's central ``coverage``."""
    h, w = shape
    s = options.window_px(shape)
    cols, rows = options.grid
    x0, x1 = w * (1 - options.coverage) / 2, w - w * (1 - options.coverage) / 2 - s
    y0, y1 = h * (1 - options.coverage) / 2, h - h * (1 - options.coverage) / 2 - s
    xs = np.linspace(x0, max(x0, x1), cols) if cols > 1 else [0.5 * (x0 + x1)]
    ys = np.linspace(y0, max(y0, y1), rows) if rows > 1 else [0.5 * (y0 + y1)]
    return [(int(round(x)), int(round(y))) for y in ys for x in xs]


def window_shifts(ref_grad: np.ndarray, grad: np.ndarray, options: RegistrationOptions) -> List[WindowShift]:
    """Phase correlation of two gradient images over the window grid; windows with a NaN in either, or whose
    peak is under ``min_peak`` (too little shared texture), are left out."""
    s, out = options.window_px(ref_grad.shape), []
    for x, y in window_centres(ref_grad.shape, options):
        a, b = ref_grad[y:y + s, x:x + s], grad[y:y + s, x:x + s]
        if a.shape != (s, s) or not (np.isfinite(a).all() and np.isfinite(b).all()):
            continue
        dx, dy, peak = phase_shift(a, b, options.upsample)
        if peak >= options.min_peak:
            out.append(WindowShift(x + s / 2.0, y + s / 2.0, dx, dy, peak))
    return out


@dataclass(frozen=True)
class Residual:
    """The registration residual of a band: median and worst shift magnitude (px) over ``count`` windows, and the
    median shift (dx, dy)."""
    median: float
    worst: float
    count: int
    median_dx: float = 0.0
    median_dy: float = 0.0

    def __str__(self) -> str:
        if not self.count:
            return "not measured (no window with shared texture)"
        return (f"median {self.median:.3f} px, worst {self.worst:.3f} px over {self.count} windows "
                f"(median shift {self.median_dx:+.3f}, {self.median_dy:+.3f})")


def residual_of(shifts: Sequence[WindowShift]) -> Residual:
    if not shifts:
        return Residual(float("nan"), float("nan"), 0)
    d = np.array([[s.dx, s.dy] for s in shifts])
    mag = np.hypot(d[:, 0], d[:, 1])
    return Residual(float(np.median(mag)), float(mag.max()), len(shifts), float(np.median(d[:, 0])),
                    float(np.median(d[:, 1])))


def fit_correction(shifts: Sequence[WindowShift], rounds: int = 3) -> np.ndarray:
    """The 3 x 3 homography D with D p = p + d(p) fitted to the window shifts (least squares; windows beyond 3
    robust sigmas of the fit dropped each round).  A homography because what the rig's calibration leaves is
    mostly a small rotation, whose image in a pinhole frame is projective (a rotation about y by b moves x by
    f b (1 + x^2 / f^2): an affine leaves the x^2 part); under 8 windows an affine, under 4 a translation,
    the identity with none."""
    cv2 = require("cv2", "band registration")
    d = np.eye(3)
    if not shifts:
        return d
    p = np.array([[s.x, s.y] for s in shifts])
    q = p + np.array([[s.dx, s.dy] for s in shifts])
    keep = np.ones(len(shifts), bool)
    for _ in range(rounds):
        n = int(keep.sum())
        if n < 4:
            d = np.eye(3)
            d[:2, 2] = np.median(q[keep] - p[keep] if n else q - p, axis=0)
            return d
        if n < 8:
            d = np.vstack([cv2.estimateAffine2D(p[keep], q[keep], method=cv2.LMEDS)[0], [0.0, 0.0, 1.0]])
        else:
            d = cv2.findHomography(p[keep], q[keep], 0)[0]
        m = np.column_stack([p, np.ones(len(p))]) @ d.T
        res = np.hypot(*(m[:, :2] / m[:, 2:] - q).T)
        sigma = 1.4826 * np.median(res[keep]) + 0.02
        new = res <= 3 * sigma
        if (new == keep).all():
            break
        keep = new
    return d / d[2, 2]


# ---------------------------------------------------------------- one capture
REFINED, BLOCK, MODEL = "refined", "block", "model only"  # how a band was registered (BandResult.status)


@dataclass
class BandResult:
    """What the registration did to one band: its camera, the model-only and final residuals against the
    reference, the homography correcting the output grid (identity for the reference and the model only), how
    (``status``: refined by its own windows, ``block``: the block's rig calibration, ``model only``; the reference:
    ``reference``) and why (``note``), and whether its own refinement was trusted (``trusted``: enough windows agree
    with it, :meth:`RegistrationOptions.trusted_windows`) with the capture's own correction (``own``)."""
    camera: BandCamera
    model_residual: Residual
    refined_residual: Residual
    correction: np.ndarray = field(default_factory=lambda: np.eye(3))
    status: str = REFINED
    note: str = ""
    trusted: bool = True
    own: Optional[np.ndarray] = None


@dataclass
class RegisteredCapture:
    """The capture's bands in the reference pinhole frame (bands, rows, cols; float32, NaN outside a band's
    frame), their names, the frame and one :class:`BandResult` per band (reference first)."""
    names: Tuple[str, ...]
    bands: np.ndarray
    frame: PinholeLens
    reference: str
    results: List[BandResult]
    model_bands: Optional[np.ndarray] = None

    @property
    def registration(self) -> Dict[str, str]:
        """band name -> how it was registered (the reference left out)."""
        return {r.camera.name: r.status for r in self.results[1:]}


def read_band(path: str) -> np.ndarray:
    """The band file's first band as float32; BandRegistrationError naming the file when it cannot be read."""
    try:
        with RasterFile(path, "band file") as r:
            return r.read(1).astype(np.float32)
    except RasterError as e:
        raise BandRegistrationError(f"{path}: the band cannot be read ({e})") from e


def _refine(image: np.ndarray, cam: BandCamera, frame: PinholeLens, ref_grad: np.ndarray,
            options: RegistrationOptions, shifts: List[WindowShift]
            ) -> Tuple[np.ndarray, np.ndarray, List[WindowShift]]:
    """The band warped with the refinement iterated ``options.iterations`` times, starting from the
    model-only window ``shifts``: (warped, correction, the windows measured after it)."""
    shape = ref_grad.shape
    correction = np.eye(3)
    warped = None
    for _ in range(options.iterations):
        if not shifts:
            break
        correction = correction @ fit_correction(shifts)
        warped = warp(image, band_map(cam, frame, shape, correction))
        shifts = window_shifts(ref_grad, gradient_image(warped), options)
    if warped is None:
        warped = warp(image, band_map(cam, frame, shape))
    return warped, correction, shifts


def agreeing(shifts: Sequence[WindowShift], tolerance: float) -> int:
    """How many windows, measured after a refinement, are within ``tolerance`` px of it."""
    return sum(1 for s in shifts if math.hypot(s.dx, s.dy) <= tolerance)


def _register_band(image: np.ndarray, cam: BandCamera, frame: PinholeLens, ref_grad: np.ndarray,
                   options: RegistrationOptions, calibration: Optional["RigCalibration"]
                   ) -> Tuple[np.ndarray, np.ndarray, BandResult]:
    """One band onto the reference: (registered, model-only, its BandResult).  Refined by its own windows when
    they agree with the refinement (trusted) and, with a ``calibration``, it agrees with the block's; else the
    block's correction (``calibration``), else the model only."""
    shape = ref_grad.shape
    model_img = warp(image, band_map(cam, frame, shape))
    shifts = window_shifts(ref_grad, gradient_image(model_img), options)
    before = residual_of(shifts)
    if not options.iterations:
        return model_img, model_img, BandResult(cam, before, before, status=MODEL, note="no refinement asked")
    refined, correction, after = _refine(image, cam, frame, ref_grad, options, shifts)
    agree, need = agreeing(after, options.AGREE_PX), options.trusted_windows()
    trusted = agree >= need
    status, note = decide(cam.name, trusted, correction, calibration,
                          f"{agree} of {len(after)} windows agree with its refinement within "
                          f"{options.AGREE_PX:g} px, {need} needed")
    own = correction if trusted else None
    if status == REFINED:
        return refined, model_img, BandResult(cam, before, residual_of(after), correction, status, note, trusted, own)
    if status == MODEL:
        return model_img, model_img, BandResult(cam, before, before, np.eye(3), status, note, trusted, own)
    block = calibration.band(cam.name).correction
    warped = warp(image, band_map(cam, frame, shape, block))
    res = residual_of(window_shifts(ref_grad, gradient_image(warped), options))
    return warped, model_img, BandResult(cam, before, res, block.copy(), status, note, trusted, own)


def register_capture(capture: Capture, options: Optional[RegistrationOptions] = None,
                     keep_model: bool = False,
                     prepare: Optional[Callable[[str, np.ndarray], np.ndarray]] = None,
                     calibration: Optional["RigCalibration"] = None) -> RegisteredCapture:
    """Register the band files of one capture (module docstring).  ``keep_model``: keep the model-only bands
    too (for before / after pictures); ``prepare``: (band file, its pixels) -> the pixels registered, in the
    band's own frame (the radiometric correction, core.prepare.band_radiometry); ``calibration``: the block's rig
    calibration (:func:`calibrate_rig`), taken by a band whose own refinement is not trusted or disagrees with it."""
    options = options or RegistrationOptions()
    cams, ref = band_cameras(capture, options.reference)
    frame = reference_frame(ref)
    images = {c.path: (prepare(c.path, read_band(c.path)) if prepare else read_band(c.path)) for c in cams}
    shape = images[ref.path].shape
    ref_img = warp(images[ref.path], band_map(ref, frame, shape))
    ref_grad = gradient_image(ref_img)
    ordered = [ref] + [c for c in cams if c is not ref]
    zero = Residual(0.0, 0.0, 0)
    bands, model, results = [ref_img], [ref_img], [BandResult(ref, zero, zero, status="reference")]
    for cam in ordered[1:]:
        registered, model_img, result = _register_band(images[cam.path], cam, frame, ref_grad, options, calibration)
        bands.append(registered)
        model.append(model_img)
        results.append(result)
    return RegisteredCapture(tuple(c.name for c in ordered), np.stack(bands), frame, ref.name, results,
                             np.stack(model) if keep_model else None)


# ---------------------------------------------------------------- the rig calibrated once for the block
def _probes(shape: Tuple[int, int], options: RegistrationOptions, n: int = 5) -> np.ndarray:
    """(n * n, 2) points over the frame's central ``coverage``, where corrections are compared."""
    h, w = shape
    m = (1 - options.coverage) / 2
    xs, ys = np.linspace(w * m, w * (1 - m) - 1, n), np.linspace(h * m, h * (1 - m) - 1, n)
    return np.array([(x, y) for y in ys for x in xs], dtype=np.float64)


def displacement(correction: np.ndarray, points: np.ndarray) -> np.ndarray:
    """How far the homography ``correction`` moves each point (px), (n, 2)."""
    q = np.column_stack([points, np.ones(len(points))]) @ np.asarray(correction, dtype=np.float64).T
    return q[:, :2] / q[:, 2:] - points


def _rotation_part(correction: np.ndarray, frame: PinholeLens) -> np.ndarray:
    """The rotation nearest K^-1 D K (D: a correction of the output grid): the rig rotation's error it stands for."""
    k = frame.matrix
    q = np.linalg.inv(k) @ np.asarray(correction, dtype=np.float64) @ k
    q /= np.cbrt(np.linalg.det(q))
    u, _s, vt = np.linalg.svd(q)
    return u @ vt


def relatives_of(rotation: np.ndarray) -> Tuple[float, float, float]:
    """The RigRelatives angles (degrees; R = Rx Ry Rz, core.geometry.lens.rig_rotation) of a rotation."""
    r = rotation
    return (math.degrees(math.atan2(-r[1, 2], r[2, 2])), math.degrees(math.asin(max(-1.0, min(1.0, r[0, 2])))),
            math.degrees(math.atan2(-r[0, 1], r[0, 0])))


@dataclass(frozen=True)
class BandCalibration:
    """One band's block calibration: the ``correction`` (3 x 3 homography of the output grid, as a capture's own
    refinement) that the block's captures agree on (the median of their corrections' displacements at the probe
    points), how far it moves the frame (``shift_px``, the largest displacement), the rotation it stands for
    (``rotation_deg``: the turn added to the band's rig rotation, a rotation vector in degrees) and what of it is not a rotation (``remainder_px``: lens
    model, parallax), the RigRelatives told by the metadata and those with the rotation taken in
    (``relatives_calibrated``), the ``captures`` it rests on, their ``spread_px`` about it (1.4826 x the median of
    each capture's largest deviation), the ``tolerance_px`` beyond which a capture's own refinement is not
    believed, and the captures beyond it (``outliers``)."""
    name: str
    correction: np.ndarray
    shift_px: float
    rotation_deg: Tuple[float, float, float]
    remainder_px: float
    relatives: Optional[Tuple[float, ...]]
    relatives_calibrated: Tuple[float, float, float]
    captures: int
    spread_px: float
    tolerance_px: float
    outliers: Tuple[str, ...] = ()

    def __str__(self) -> str:
        told = "none" if self.relatives is None else ", ".join(f"{v:+.3f}" for v in self.relatives)
        return (f"{self.name}: {self.shift_px:.2f} px at most over the frame, a rotation of "
                f"({', '.join(f'{v:+.3f}' for v in self.rotation_deg)}) deg (remainder {self.remainder_px:.2f} px); "
                f"RigRelatives ({told}) -> ({', '.join(f'{v:+.3f}' for v in self.relatives_calibrated)}); "
                f"{self.captures} captures, spread {self.spread_px:.3f} px"
                + (f", {len(self.outliers)} beyond {self.tolerance_px:.2f} px ({', '.join(self.outliers)})"
                   if self.outliers else ""))


@dataclass(frozen=True)
class RigCalibration:
    """The rig calibrated once for the block (:func:`calibrate_rig`): per band (band_key) its
    :class:`BandCalibration`, the probe points corrections are compared at, and the bands that could not be
    calibrated, with why (``missing``)."""
    reference: str
    bands: Dict[str, BandCalibration]
    probes: np.ndarray
    missing: Dict[str, str] = field(default_factory=dict)

    def band(self, name: str) -> Optional[BandCalibration]:
        return self.bands.get(band_key(name))

    def deviation(self, name: str, correction: np.ndarray) -> float:
        """The largest distance (px) between where ``correction`` and the block's put the probe points."""
        cal = self.band(name)
        d = displacement(correction, self.probes) - displacement(cal.correction, self.probes)
        return float(np.hypot(d[:, 0], d[:, 1]).max())

    def describe(self) -> str:
        lines = [f"rig calibration of the block (onto {self.reference}; the correction of the metadata's rig model "
                 "that the captures' own refinements agree on):"] + [f"  {b}" for b in self.bands.values()]
        lines += [f"  {n}: not calibrated ({why})" for n, why in self.missing.items()]
        return "\n".join(lines)


MIN_BLOCK_CAPTURES = 3  # a median needs at least three captures to out-vote one bad fit
DISAGREE_SIGMAS = 5.0   # a capture's own refinement beyond this many of the block's spreads is not believed ...
DISAGREE_FLOOR_PX = RegistrationOptions.AGREE_PX  # ... nor under the registration's own aim (half a pixel)


def decide(name: str, trusted: bool, correction: np.ndarray, calibration: Optional[RigCalibration],
           windows: str) -> Tuple[str, str]:
    """(status, why) of a band: refined by its own windows when they are trusted (``windows`` says how many
    agree) and agree with the block's calibration; the block's correction when they are too few or disagree with
    it by more than its tolerance (a fit on repetitive texture); the model only without a calibration."""
    cal = calibration.band(name) if calibration is not None else None
    if not trusted:
        if cal is None:
            return MODEL, f"too little texture to refine ({windows}) and no rig calibration of the block"
        return BLOCK, f"too little texture to refine ({windows}): the block's rig calibration ({cal.captures} captures)"
    if cal is None:
        return REFINED, windows
    dev = calibration.deviation(name, correction)
    if dev > cal.tolerance_px:
        return BLOCK, (f"its own refinement is {dev:.2f} px from the block's rig calibration (tolerance "
                       f"{cal.tolerance_px:.2f} px, spread {cal.spread_px:.3f} px over {cal.captures} captures): "
                       "a fit on repetitive texture? The block's used")
    return REFINED, windows


def _calibrate_band(name: str, entries: Sequence[Tuple[str, BandResult]], frame: PinholeLens, probes: np.ndarray,
                    reference: Optional[Tuple[float, ...]]) -> BandCalibration:
    """One band's block calibration from its trusted captures' corrections (:class:`BandCalibration`)."""
    cv2 = require("cv2", "band registration")
    disp = np.stack([displacement(r.correction, probes) for _cid, r in entries])     # (captures, probes, 2)
    keep = np.ones(len(entries), bool)
    for _ in range(2):   # the median, the captures beyond the tolerance dropped, the median again
        med = np.median(disp[keep], axis=0)
        dev = np.hypot(*(disp - med).transpose(2, 0, 1)).max(axis=1)
        spread = 1.4826 * float(np.median(dev[keep]))
        tolerance = max(DISAGREE_SIGMAS * spread, DISAGREE_FLOOR_PX)
        new = dev <= tolerance
        if new.sum() < MIN_BLOCK_CAPTURES or (new == keep).all():
            break
        keep = new
    h = cv2.findHomography(probes, probes + med, 0)[0]
    h = h / h[2, 2]
    rot = _rotation_part(h, frame)
    k = frame.matrix
    only_rot = k @ rot @ np.linalg.inv(k)
    remainder = displacement(h, probes) - displacement(only_rot, probes)
    cam = entries[0][1].camera
    vec = cv2.Rodrigues(rot.T)[0].ravel()   # the turn added to the band's rig rotation: R' R^T = Q^T
    calibrated = rig_rotation(reference) @ rot.T @ cam.rotation   # R' = Q^T R (band_map: rays R^T Q ray)
    return BandCalibration(name, h, float(np.hypot(med[:, 0], med[:, 1]).max()),
                           tuple(float(math.degrees(v)) for v in vec), float(np.hypot(*remainder.T).max()),
                           cam.relatives, relatives_of(calibrated), int(keep.sum()), spread, tolerance,
                           tuple(cid for (cid, _r), d in zip(entries, dev) if d > tolerance))


def calibrate_rig(captures: Mapping[str, Sequence[BandResult]], frame: PinholeLens, shape: Tuple[int, int],
                  options: Optional[RegistrationOptions] = None) -> RigCalibration:
    """The rig calibrated once for the block (issue 37): the rig is rigid, so the correction each band's metadata
    model needs is the same in every capture (the bands' baseline is a fraction of a pixel from flying height).
    From the captures' registrations (capture id -> its BandResults, reference first, all in one reference frame
    ``frame`` of ``shape``) each band's trusted refinements are pooled: the median of their displacements at probe
    points over the frame, fitted by a homography; captures whose own correction lies beyond the tolerance (the
    block's spread x DISAGREE_SIGMAS, at least half a pixel) are left out of it.  A band with fewer than
    MIN_BLOCK_CAPTURES trusted captures is not calibrated (``missing`` says why)."""
    options = options or RegistrationOptions()
    probes = _probes(shape, options)
    pooled: Dict[str, List[Tuple[str, BandResult]]] = {}
    names: Dict[str, str] = {}
    reference, ref_relatives = "", None
    for cid, results in captures.items():
        if not results:
            continue
        reference, ref_relatives = results[0].camera.name, results[0].camera.relatives
        for r in results[1:]:
            names.setdefault(band_key(r.camera.name), r.camera.name)
            if r.trusted and r.own is not None:
                pooled.setdefault(band_key(r.camera.name), []).append((cid, dataclasses.replace(r, correction=r.own)))
    bands, missing = {}, {}
    for key, name in names.items():
        entries = pooled.get(key, [])
        if len(entries) < MIN_BLOCK_CAPTURES:
            missing[name] = (f"{len(entries)} capture(s) refined with trusted windows, {MIN_BLOCK_CAPTURES} "
                             "needed")
            continue
        bands[key] = _calibrate_band(name, entries, frame, probes, ref_relatives)
    return RigCalibration(reference, bands, probes, missing)


def write_registered(path: str, reg: RegisteredCapture) -> str:
    """The registered bands as one float32 plain TIFF (band names as descriptions; the reference, frame and each
    band's residuals in its metadata)."""
    md = {"REFERENCE_BAND": reg.reference,
          "PINHOLE_F_CX_CY": f"{reg.frame.f:.4f},{reg.frame.cx:.4f},{reg.frame.cy:.4f}"}
    for r in reg.results[1:]:
        key = band_key(r.camera.name).upper()
        md[f"{key}_RESIDUAL_MODEL_PX"] = f"{r.model_residual.median:.3f},{r.model_residual.worst:.3f}"
        md[f"{key}_RESIDUAL_REFINED_PX"] = f"{r.refined_residual.median:.3f},{r.refined_residual.worst:.3f}"
        md[f"{key}_REGISTRATION"] = r.status
    return write_band_stack(path, reg.bands, reg.names, md)
