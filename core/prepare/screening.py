"""Image quality screening (blur, exposure) and the "prepare" workspace stage.

Screening measures every image on a grey version read at a fixed analysis size
(``analysis_size`` pixels on the long side, GDAL average downsampling), so the
scores of a 1,200 px and of a 6,000 px image describe the same ground detail
at the same scale:

- **blur score**: variance of the Laplacian (3x3, grey levels 0-255), computed
  per tile of an 8 x 6 grid and summarised by the 90th percentile of the
  tiles.  A sharp photo with sky, water or a uniform field in part of the
  frame keeps a high score because its textured tiles decide; a blurred or
  shaken photo loses high frequencies everywhere.  Higher is sharper.  The
  score is compared with the set's median (``blur_relative``): absolute values
  depend on the scene (sand and fields score far lower than roofs), so a fixed
  absolute threshold (``blur_threshold``) is off by default.
- **exposure**: fraction of clipped shadows (<= 1 % of full scale in the grey
  image) and clipped highlights (any colour channel >= 99.6 % of full scale),
  dynamic range (1st to 99th percentile, as a fraction of full scale) and mean
  brightness.  ``exposure_score`` = (1 - min(1, 10 x clipped fraction)) x
  min(1, dynamic range / 0.25): 1 is well exposed, 0 is unusable.

Flags: ``blurry`` (below the absolute threshold or below ``blur_relative`` x
the set's median), ``overexposed`` / ``underexposed`` (clipped fraction above
``clip_max``, or mean brightness more than ``brightness_tolerance`` away from
the set's median), ``low_contrast`` (dynamic range below ``min_dynamic_range``
or below half the set's median).  Flagged images are kept unless
``exclude_flagged`` is set; the decision and its reasons are recorded per image
in ``<workspace>/screening.json`` and in the workspace's ``prepare`` stage.

Blur and exposure are measured inside each image's mask only.  The "prepare"
stage that runs the screening, the scanned-film restitution and the user masks
is :func:`core.prepare.stage.prepare_images_workspace`.
"""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError, require
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.images import ImageError, full_scale, image_size, list_images, read_image, read_image_info, to_grey
from .options import ANALYSIS_SIZE, ScreeningOptions

__all__ = ["EXCLUDE", "KEEP", "ImageQuality", "ScreeningError", "blur_score", "exposure_figures", "measure_image",
           "read_for_analysis", "screen", "screen_folder"]

TILES = (8, 6)  # columns x rows of the blur grid (long side x short side)
TILE_PERCENTILE = 90.0

KEEP = "keep"
EXCLUDE = "exclude"


class ScreeningError(ArchaeoOrthoError, ValueError):
    """Screening cannot run; the message says why (and names the file when one is at fault)."""


@dataclass
class ImageQuality:
    name: str
    blur_score: float
    shadows_clipped: float
    highlights_clipped: float
    dynamic_range: float
    brightness: float
    exposure_score: float
    width: int = 0
    height: int = 0
    blur_relative: float = 1.0  # blur score / the set's median
    blur_rank: int = 0  # 1 = blurriest image of the set
    exposure_rank: int = 0  # 1 = worst exposed image of the set
    flags: List[str] = field(default_factory=list)
    reasons: List[str] = field(default_factory=list)
    decision: str = KEEP
    prepared_name: Optional[str] = None

    def to_dict(self) -> dict:
        d = asdict(self)
        for k in ("blur_score", "blur_relative"):
            d[k] = round(float(d[k]), 3)
        for k in ("shadows_clipped", "highlights_clipped", "dynamic_range", "brightness", "exposure_score"):
            d[k] = round(float(d[k]), 5)
        return d


# ---------------------------------------------------------------------------
# measurements
# ---------------------------------------------------------------------------

def _tiles(shape: Tuple[int, int], tiles: Tuple[int, int] = TILES):
    h, w = shape
    tx, ty = tiles if w >= h else (tiles[1], tiles[0])
    for i in range(ty):
        for j in range(tx):
            yield slice(i * h // ty, (i + 1) * h // ty), slice(j * w // tx, (j + 1) * w // tx)


def blur_score(grey: np.ndarray, mask: Optional[np.ndarray] = None, tiles: Tuple[int, int] = TILES,
               percentile: float = TILE_PERCENTILE) -> float:
    """Variance of the Laplacian (grey levels 0-255), 90th percentile over tiles.  Higher is sharper.

    ``grey`` in [0, 1] at the analysis size; ``mask`` (True = use) leaves out
    film borders, fiducials and the zero fill around resampled scans: a tile
    counts only where at least half of it is usable.
    """
    cv2 = require("cv2", "image screening")

    g = np.ascontiguousarray(grey, dtype=np.float32) * np.float32(255.0)
    lap = cv2.Laplacian(g, cv2.CV_32F, ksize=1)
    use = None
    if mask is not None:
        # a Laplacian that touches an unusable pixel measures the mask edge, not the photo
        m = (np.asarray(mask) > 0).astype(np.uint8)
        use = cv2.erode(m, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=0) > 0
    values = []
    for sy, sx in _tiles(lap.shape, tiles):
        t = lap[sy, sx]
        if use is not None:
            u = use[sy, sx]
            if u.sum() < 0.5 * u.size:
                continue
            t = t[u]
        if t.size >= 16:
            values.append(float(np.var(t)))
    if not values:
        return 0.0
    return float(np.percentile(values, percentile))


def exposure_figures(pixels: np.ndarray, mask: Optional[np.ndarray] = None,
                     scale: Optional[float] = None) -> Dict[str, float]:
    """Clipped shadows / highlights, dynamic range, brightness and the exposure score of one image."""
    a = np.asarray(pixels)
    scale = float(scale or full_scale(a))
    grey = to_grey(a, scale)
    sel = np.ones(grey.shape, bool) if mask is None else (np.asarray(mask) > 0)
    n = int(sel.sum())
    if n == 0:
        return {"shadows_clipped": 0.0, "highlights_clipped": 0.0, "dynamic_range": 0.0,
                "brightness": 0.0, "exposure_score": 0.0}
    g = grey[sel]
    shadows = float(np.count_nonzero(g <= 0.01)) / n
    if a.ndim == 3 and a.shape[2] >= 3:
        chan_max = a[:, :, :3].max(axis=2).astype(np.float32) / np.float32(scale)
        highlights = float(np.count_nonzero(chan_max[sel] >= 0.996)) / n
    else:
        highlights = float(np.count_nonzero(g >= 0.996)) / n
    p1, p99 = np.percentile(g, [1.0, 99.0])
    dr = float(max(0.0, p99 - p1))
    score = (1.0 - min(1.0, 10.0 * (shadows + highlights))) * min(1.0, dr / 0.25)
    return {"shadows_clipped": shadows, "highlights_clipped": highlights, "dynamic_range": dr,
            "brightness": float(g.mean()), "exposure_score": float(score)}


def read_for_analysis(path: str, size: int = ANALYSIS_SIZE) -> np.ndarray:
    """Pixels at ``size`` on the long side (GDAL average); raises ImageError naming the file."""
    try:
        arr = read_image(path, max_size=size)
    except (RuntimeError, AttributeError, ValueError) as e:
        raise ImageError(f"{path}: image data cannot be read ({str(e).strip() or type(e).__name__})") from e
    if arr is None or arr.size == 0:
        raise ImageError(f"{path}: image data cannot be read")
    return arr


def measure_image(path: str, name: Optional[str] = None, mask_path: Optional[str] = None,
                  analysis_size: int = ANALYSIS_SIZE, check: bool = True) -> ImageQuality:
    """Blur and exposure figures of one image file (optionally only where its mask is white).

    ``check`` first decodes the file's last rows (core.images.read_image_info), so
    that a truncated file fails with a clear ImageError naming it; callers that
    have just checked the file pass False.
    """
    cv2 = require("cv2", "image screening")

    name = name or os.path.basename(path)
    if check:
        info = read_image_info(path, name)  # clear ImageError for empty, corrupt or truncated files
        size = (info.width, info.height)
    else:
        size = image_size(path)
    arr = read_for_analysis(path, analysis_size)
    scale = full_scale(arr)
    mask = None
    if mask_path:
        m = cv2.imread(mask_path, cv2.IMREAD_GRAYSCALE)
        if m is None:
            raise ImageError(f"{mask_path}: mask cannot be read")
        mask = cv2.resize(m, (arr.shape[1], arr.shape[0]), interpolation=cv2.INTER_NEAREST) > 127
    grey = to_grey(arr, scale)
    exp = exposure_figures(arr, mask, scale)
    return ImageQuality(name=name, blur_score=blur_score(grey, mask), width=size[0], height=size[1], **exp)


# ---------------------------------------------------------------------------
# ranking and decisions (pure)
# ---------------------------------------------------------------------------

def screen(measured: Sequence[ImageQuality], options: Optional[ScreeningOptions] = None) -> List[ImageQuality]:
    """Rank, flag and decide; fills blur_relative, ranks, flags, reasons and decision in place."""
    options = options or ScreeningOptions()
    items = list(measured)
    if not items:
        return items
    med_blur = float(np.median([q.blur_score for q in items]))
    med_bright = float(np.median([q.brightness for q in items]))
    med_dr = float(np.median([q.dynamic_range for q in items]))
    for rank, q in enumerate(sorted(items, key=lambda q: (q.blur_score, q.name)), start=1):
        q.blur_rank = rank
    for rank, q in enumerate(sorted(items, key=lambda q: (q.exposure_score, q.name)), start=1):
        q.exposure_rank = rank
    for q in items:
        q.flags, q.reasons = [], []
        q.blur_relative = q.blur_score / med_blur if med_blur > 0 else 1.0
        if options.blur_threshold and q.blur_score < options.blur_threshold:
            q.flags.append("blurry")
            q.reasons.append(f"blur score {q.blur_score:.1f} below the threshold {options.blur_threshold:g}")
        elif len(items) >= 3 and options.blur_relative and q.blur_relative < options.blur_relative:
            q.flags.append("blurry")
            q.reasons.append(f"blur score {q.blur_score:.1f} is {100 * q.blur_relative:.0f} % of the set's "
                             f"median {med_blur:.1f} (limit {100 * options.blur_relative:.0f} %)")
        if q.highlights_clipped > options.clip_max:
            q.flags.append("overexposed")
            q.reasons.append(f"{100 * q.highlights_clipped:.1f} % of pixels clipped white "
                             f"(limit {100 * options.clip_max:.1f} %)")
        elif len(items) >= 3 and q.brightness - med_bright > options.brightness_tolerance:
            q.flags.append("overexposed")
            q.reasons.append(f"mean brightness {q.brightness:.2f} against the set's median {med_bright:.2f}")
        if q.shadows_clipped > options.clip_max:
            q.flags.append("underexposed")
            q.reasons.append(f"{100 * q.shadows_clipped:.1f} % of pixels clipped black "
                             f"(limit {100 * options.clip_max:.1f} %)")
        elif len(items) >= 3 and med_bright - q.brightness > options.brightness_tolerance:
            q.flags.append("underexposed")
            q.reasons.append(f"mean brightness {q.brightness:.2f} against the set's median {med_bright:.2f}")
        low_dr = max(options.min_dynamic_range, 0.5 * med_dr if len(items) >= 3 else 0.0)
        if q.dynamic_range < low_dr:
            q.flags.append("low_contrast")
            q.reasons.append(f"dynamic range {q.dynamic_range:.2f} below {low_dr:.2f}")
        q.decision = EXCLUDE if (q.flags and options.exclude_flagged) else KEEP
    return items


def screen_folder(images_dir: str, options: Optional[ScreeningOptions] = None,
                  progress: Optional[Progress] = None, names: Optional[Sequence[str]] = None,
                  masks: Optional[Dict[str, str]] = None, check: bool = True) -> List[ImageQuality]:
    """Measure and screen every image of a folder; raises ImageError naming a corrupt file."""
    options = options or ScreeningOptions()
    progress = progress or NullProgress()
    names = list(names) if names is not None else list_images(images_dir)
    measured = []
    for i, n in enumerate(names):
        check_cancel(progress)
        measured.append(measure_image(os.path.join(images_dir, n), n, (masks or {}).get(n), options.analysis_size,
                                      check))
        progress.report((i + 1) / max(1, len(names)), f"screening: {i + 1}/{len(names)} images ({n})")
    return screen(measured, options)
