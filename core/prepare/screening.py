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

The stage :func:`prepare_images_workspace` also runs the scanned-film
restitution of :mod:`core.scans` (fiducials, affine resampling, masks) when
asked, rasterises the user's "ignore" polygons into the per-image masks
(:mod:`core.masks`), and writes the folder of prepared images that "Align
images" takes.  Blur and exposure are measured inside each image's mask only.

Masks live in ``<workspace>/masks/<prepared image name>.png``.  The stage
rewrites the masks it wrote last time; a mask it did not write (put there by
hand) is merged into the new mask of its image and kept aside in
``masks/.originals/`` so that the next run merges it again instead of the
previous result.
"""
from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Cancelled, NullProgress, Progress, SubProgress, check_cancel
from ..io.images import ImageError, list_images, read_image_info
from ..project.workspace import (
    CANCELLED,
    DONE,
    FAILED,
    Workspace,
    WorkspaceError,
    atomic_output,
    atomic_write_text,
    file_fingerprint,
)

STAGE = "prepare"
SCREENING_JSON = "screening.json"
OUTPUT_MARKER = ".archaeoortho-prepared"
ANALYSIS_SIZE = 1024
TILES = (8, 6)  # columns x rows of the blur grid (long side x short side)
TILE_PERCENTILE = 90.0

KEEP = "keep"
EXCLUDE = "exclude"


class ScreeningError(ValueError):
    """Screening cannot run; the message says why (and names the file when one is at fault)."""


@dataclass
class ScreeningOptions:
    blur_threshold: float = 0.0  # absolute minimum blur score (0 = no absolute threshold)
    blur_relative: float = 0.4  # flag images scoring below this fraction of the set's median
    clip_max: float = 0.05  # largest fraction of clipped shadows or highlights
    brightness_tolerance: float = 0.25  # largest |mean brightness - set median| (fraction of full scale)
    min_dynamic_range: float = 0.10  # smallest 1-99 % range (fraction of full scale)
    exclude_flagged: bool = False
    analysis_size: int = ANALYSIS_SIZE


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

def full_scale(arr: np.ndarray) -> float:
    """The value that means "white" for this array: 255 for 8-bit, 2^k - 1 for 16-bit, 1 for floats <= 1."""
    if arr.dtype == np.uint8:
        return 255.0
    mx = float(np.nanmax(arr)) if arr.size else 1.0
    if np.issubdtype(arr.dtype, np.integer):
        bits = max(8, int(np.ceil(np.log2(mx + 1.0)))) if mx > 0 else 8
        for b in (8, 10, 12, 14, 16):  # camera and scanner bit depths
            if bits <= b:
                return float(2 ** b - 1)
        return float(2 ** bits - 1)
    return 1.0 if mx <= 1.0 else mx


def to_grey(arr: np.ndarray, scale: Optional[float] = None) -> np.ndarray:
    """(rows, cols[, bands]) pixels -> float32 grey in [0, 1].

    Three or more bands are read as R, G, B (GDAL band order) with Rec. 601
    weights; one or two bands use the first band (grey, NIR).
    """
    a = np.asarray(arr)
    scale = float(scale or full_scale(a))
    if a.ndim == 3 and a.shape[2] >= 3:
        g = (0.299 * a[:, :, 0].astype(np.float32) + 0.587 * a[:, :, 1].astype(np.float32)
             + 0.114 * a[:, :, 2].astype(np.float32))
    elif a.ndim == 3:
        g = a[:, :, 0].astype(np.float32)
    else:
        g = a.astype(np.float32)
    return g / np.float32(scale)


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
    import cv2

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
    from ..io.images import read_image

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
    import cv2

    name = name or os.path.basename(path)
    if check:
        info = read_image_info(path, name)  # clear ImageError for empty, corrupt or truncated files
        size = (info.width, info.height)
    else:
        from osgeo import gdal

        gdal.UseExceptions()
        try:
            ds = gdal.Open(path)
            size = (ds.RasterXSize, ds.RasterYSize)
            ds = None
        except RuntimeError as e:
            raise ImageError(f"{path}: not a readable image ({str(e).strip()})") from e
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


# ---------------------------------------------------------------------------
# the "prepare" stage
# ---------------------------------------------------------------------------

@dataclass
class PrepareOptions:
    screening: ScreeningOptions = field(default_factory=ScreeningOptions)
    scanned_film: bool = False
    scan: Optional[object] = None  # core.scans.ScanOptions when scanned_film
    # user masks: "ignore" polygons, (image name or None for every image, [exterior, hole, ...][, label])
    # with rings of (x, y) image pixel coordinates (core.masks); for scanned film in the prepared images' frame
    mask_polygons: Optional[Sequence] = None
    mask_source: str = "mask polygons"  # names the polygons' origin (a layer, a file) in messages
    mask_y_axis: str = "auto"  # auto / down / up (y = -row, the QGIS georeferencer)


@dataclass
class PrepareResult:
    workspace: str
    prepared_dir: str
    screening_path: str
    images: List[ImageQuality]
    flagged: int
    excluded: int
    kept: int
    scans_path: Optional[str]
    masks: List[str]
    interior_orientation: Optional[dict]
    warnings: List[str]
    timings: Dict[str, float]
    user_masked: Dict[str, int] = field(default_factory=dict)  # image -> user polygons applied


def _link_or_copy(src: str, dst: str) -> None:
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _check_output_dir(output_dir: str, images_dir: str, ws_root: str) -> None:
    out = os.path.realpath(output_dir)
    src = os.path.realpath(images_dir)
    if out == src or src.startswith(out + os.sep):
        raise ScreeningError(f"the output folder {output_dir} must not be the image folder or hold it: "
                             "choose a new folder for the prepared images")
    if out == os.path.realpath(ws_root) or os.path.realpath(ws_root).startswith(out + os.sep):
        raise ScreeningError(f"the output folder {output_dir} must not be the workspace or hold it")
    if os.path.isfile(output_dir):
        raise ScreeningError(f"the output folder {output_dir} exists and is a file")
    if os.path.isdir(output_dir) and os.listdir(output_dir) and \
            not os.path.exists(os.path.join(output_dir, OUTPUT_MARKER)):
        raise ScreeningError(f"the output folder {output_dir} already holds files that 'Prepare images' did not "
                             "write; choose an empty or new folder (it is replaced as a whole)")


def _json(obj) -> str:
    return json.dumps(obj, indent=2, default=str)


ORIGINALS = ".originals"  # masks/<this>/: masks this stage did not write, kept aside while it replaces them


def _foreign_mask(ws: Workspace, name: str, ours: Sequence[str]) -> Optional[str]:
    """A mask of ``name`` that this stage did not write (by hand, another tool), or None."""
    from .masks import mask_file_name

    kept = ws.path("masks", ORIGINALS, mask_file_name(name))
    if os.path.isfile(kept):
        return kept
    ours = {os.path.normpath(r) for r in ours}
    for cand in (mask_file_name(name), os.path.splitext(name)[0] + ".png"):
        p = ws.path("masks", cand)
        if os.path.isfile(p) and os.path.normpath(os.path.relpath(p, ws.root)) not in ours:
            return p
    return None


def _polygon_record(polygons: Sequence, source: str) -> dict:
    """JSON-able digest of the user polygons for the stage parameters; raises MaskError for a malformed one."""
    from ..project.workspace import fingerprint
    from .masks import to_polygons

    polys = to_polygons(polygons, source)
    return {"count": len(polys), "images": sorted({p.image or "*" for p in polys}),
            "fingerprint": fingerprint([(p.image, [np.round(r, 3).tolist() for r in p.rings]) for p in polys])}


def prepare_images_workspace(images_dir: str, workspace_dir: str, output_dir: Optional[str] = None,
                             options: Optional[PrepareOptions] = None,
                             progress: Optional[Progress] = None) -> PrepareResult:
    """The "prepare" stage: screening, optional scanned-film restitution, the folder of prepared images.

    Writes ``output_dir`` (default ``<workspace>/prepared``; replaced as a whole
    and renamed into place only when complete), ``<workspace>/screening.json``,
    for scanned film ``<workspace>/scans.json`` and ``<workspace>/masks/<prepared
    image name>.png`` (COLMAP's convention: white = use, black = ignore), and
    the stage record.  Raises ImageError (naming the file), ScreeningError,
    core.scans.ScanError, WorkspaceError or Cancelled.
    """
    options = options or PrepareOptions()
    sopt = options.screening
    progress = progress or NullProgress()
    t_start = time.time()
    images_dir = os.path.abspath(images_dir)
    names = list_images(images_dir)  # ImageError when the folder is missing
    if not names:
        raise ScreeningError(f"no images (.jpg, .tif, .png) in {images_dir}")
    ws = Workspace.create_or_open(workspace_dir)
    output_dir = os.path.abspath(output_dir or ws.path("prepared"))
    _check_output_dir(output_dir, images_dir, ws.root)
    timings: Dict[str, float] = {}
    warnings: List[str] = []

    # header check of every file first: a corrupt file stops the stage before any work, by name
    t0 = time.time()
    sizes: Dict[str, Tuple[int, int]] = {}
    for i, n in enumerate(names):
        info = read_image_info(os.path.join(images_dir, n), n)
        sizes[n] = (info.width, info.height)
        progress.report(0.03 * (i + 1) / len(names), f"checking {n}")
    timings["check"] = time.time() - t0
    polygons = list(options.mask_polygons or [])
    params = {"screening": asdict(sopt), "scanned_film": options.scanned_film,
              "scan": asdict(options.scan) if options.scanned_film and options.scan is not None else None,
              "output_dir": output_dir}
    if polygons:  # a malformed polygon fails here, before the stage starts, by name
        params["mask_polygons"] = dict(_polygon_record(polygons, options.mask_source), source=options.mask_source,
                                       y_axis=options.mask_y_axis)
    ws.begin_stage(STAGE, params, {
        "images": _fingerprint_files(images_dir, names)})
    previous_masks = list((ws.data["stages"][STAGE].get("outputs") or {}).get("masks") or [])
    try:
        scan_set = None
        with atomic_output(output_dir) as tmp:
            os.makedirs(tmp)
            masks_staging = ws.path(".partial-masks-prepare")
            shutil.rmtree(masks_staging, ignore_errors=True)
            mask_files: Dict[str, str] = {}
            if options.scanned_film:
                from . import scans

                t0 = time.time()
                os.makedirs(masks_staging)
                scan_set = scans.prepare_scans(
                    [os.path.join(images_dir, n) for n in names], tmp, masks_staging,
                    options.scan or scans.ScanOptions(), SubProgress(progress, 0.03, 0.75))
                warnings.extend(scan_set.warnings)
                timings["scans"] = time.time() - t0
                ws.record_timing(STAGE, "scans", timings["scans"])
                screen_dir = tmp
                screen_names = [s.prepared_name for s in scan_set.scans]
                mask_files = {s.prepared_name: os.path.join(masks_staging, s.mask_name) for s in scan_set.scans}
                screen_sizes = {s.prepared_name: (scan_set.width, scan_set.height) for s in scan_set.scans}
                aliases = {s.name: s.prepared_name for s in scan_set.scans}
                sp = SubProgress(progress, 0.75, 0.95)
            else:
                screen_dir, screen_names = images_dir, names
                screen_sizes, aliases = sizes, {}
                sp = SubProgress(progress, 0.03, 0.90)
            # masks: the scans', the user's polygons and masks put in <workspace>/masks by hand, merged
            foreign = {n: p for n in screen_names for p in [_foreign_mask(ws, n, previous_masks)] if p}
            user_masked: Dict[str, int] = {}
            if polygons or (mask_files and foreign):
                from . import masks as masksmod

                t0 = time.time()
                by_image, axis = masksmod.polygons_by_image(polygons, screen_names, aliases, options.mask_source,
                                                            options.mask_y_axis)
                bases = {n: [p for p in (mask_files.get(n), foreign.get(n)) if p]
                         for n in screen_names if n in mask_files or n in by_image}
                os.makedirs(masks_staging, exist_ok=True)
                mres = masksmod.build_masks(by_image, screen_sizes, masks_staging, bases, options.mask_source)
                mask_files.update(mres.masks)
                warnings.extend(mres.warnings)
                user_masked = {n: c for n, c in mres.polygons.items() if c}
                if polygons:
                    progress.info(f"masks: {len(polygons)} polygons ({options.mask_source}, y "
                                  f"{'= -row' if axis == 'up' else 'down'}) hide parts of {len(user_masked)} "
                                  f"of {len(screen_names)} images")
                timings["masks"] = time.time() - t0
                ws.record_timing(STAGE, "masks", timings["masks"])
            screen_masks = dict(foreign)
            screen_masks.update(mask_files)
            t0 = time.time()
            quality = screen_folder(screen_dir, sopt, sp, screen_names, screen_masks, check=False)
            timings["screening"] = time.time() - t0
            ws.record_timing(STAGE, "screening", timings["screening"])
            # screening measured prepared scans: report under the original names
            for orig, q in zip(names, quality):
                q.prepared_name = q.name
                q.name = orig
            check_cancel(progress)

            # the prepared folder: kept images only
            kept = [q for q in quality if q.decision == KEEP]
            if not kept:
                raise ScreeningError("every image was flagged and excluded; lower the thresholds or keep "
                                     "flagged images")
            for q in quality:
                if options.scanned_film:
                    if q.decision == EXCLUDE:
                        os.unlink(os.path.join(tmp, q.prepared_name))
                elif q.decision == KEEP:
                    _link_or_copy(os.path.join(images_dir, q.name), os.path.join(tmp, q.name))
            with open(os.path.join(tmp, OUTPUT_MARKER), "w", encoding="utf-8") as f:
                f.write(f"prepared by ArchaeoOrtho from {images_dir}\n")
            check_cancel(progress)
            progress.report(0.96, "writing the screening record")
            # last step inside the atomic block: nothing below can be cancelled
            masks_dir = ws.path("masks")
            for rel in previous_masks:  # masks this stage wrote last time
                p = ws.path(rel)
                if os.path.isfile(p) and os.path.dirname(os.path.abspath(p)) == masks_dir:
                    os.unlink(p)
            originals = os.path.join(masks_dir, ORIGINALS)
            if os.path.isdir(originals):  # masks set aside last time go back to their place
                for f in os.listdir(originals):
                    src, dst = os.path.join(originals, f), os.path.join(masks_dir, f)
                    if os.path.exists(dst):
                        os.unlink(src)  # replaced by hand since: the newer one stays
                    else:
                        os.replace(src, dst)
                shutil.rmtree(originals, ignore_errors=True)
            written_masks = []
            for q in quality:
                src = mask_files.get(q.prepared_name)
                if q.decision == KEEP and src and os.path.isfile(src):
                    os.makedirs(masks_dir, exist_ok=True)
                    dst = os.path.join(masks_dir, os.path.basename(src))
                    if os.path.isfile(dst):  # not ours: merged into the new mask, kept aside for the next run
                        os.makedirs(originals, exist_ok=True)
                        os.replace(dst, os.path.join(originals, os.path.basename(dst)))
                    os.replace(src, dst)
                    written_masks.append(os.path.relpath(dst, ws.root))
            shutil.rmtree(masks_staging, ignore_errors=True)
            summary = _summary(quality)
            doc = {
                "images_dir": images_dir, "prepared_dir": output_dir, "options": asdict(sopt),
                "scanned_film": options.scanned_film, "median": summary["median"],
                "flagged": summary["flagged"], "excluded": summary["excluded"], "kept": summary["kept"],
                "blurriest_first": [q.name for q in sorted(quality, key=lambda q: q.blur_rank)],
                "images": [q.to_dict() for q in quality],
            }
            screening_path = ws.path(SCREENING_JSON)
            atomic_write_text(screening_path, _json(doc))
            scans_path = None
            if scan_set is not None:
                scans_path = ws.path(scans.SCANS_JSON)
                atomic_write_text(scans_path, _json(scan_set.to_dict()))
        timings = {k: round(v, 3) for k, v in timings.items()}
        outputs = {"prepared_images": output_dir, "screening": SCREENING_JSON, "masks": written_masks}
        if scans_path:
            outputs["scans"] = os.path.basename(scans_path)
        io = scan_set.interior_orientation if scan_set is not None else None
        ws.end_stage(STAGE, DONE, outputs=outputs, results={
            "images": len(quality), "flagged": summary["flagged"], "excluded": summary["excluded"],
            "kept": summary["kept"], "median_blur_score": summary["median"]["blur_score"],
            "decisions": {q.name: {"decision": q.decision, "flags": q.flags} for q in quality},
            "interior_orientation": io, "masks": len(written_masks),
            "user_masked_images": {n: user_masked[n] for n in sorted(user_masked)},
            "total_seconds": round(time.time() - t_start, 2)})
        ws.invalidate_after(STAGE)
        progress.report(1.0, f"screened {len(quality)} images: {summary['flagged']} flagged, "
                             f"{summary['excluded']} excluded")
        return PrepareResult(
            workspace=ws.root, prepared_dir=output_dir, screening_path=screening_path, images=quality,
            flagged=summary["flagged"], excluded=summary["excluded"], kept=summary["kept"],
            scans_path=scans_path, masks=[ws.path(m) for m in written_masks], interior_orientation=io,
            warnings=warnings, timings=timings, user_masked=user_masked)
    except Cancelled:
        shutil.rmtree(ws.path(".partial-masks-prepare"), ignore_errors=True)
        ws.end_stage(STAGE, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        shutil.rmtree(ws.path(".partial-masks-prepare"), ignore_errors=True)
        ws.end_stage(STAGE, FAILED, error=str(e))
        raise


def _fingerprint_files(folder: str, names: Sequence[str]) -> str:
    from ..project.workspace import fingerprint

    return fingerprint([(n, file_fingerprint(os.path.join(folder, n))) for n in names])


def _summary(quality: Sequence[ImageQuality]) -> dict:
    return {
        "flagged": sum(1 for q in quality if q.flags),
        "excluded": sum(1 for q in quality if q.decision == EXCLUDE),
        "kept": sum(1 for q in quality if q.decision == KEEP),
        "median": {k: round(float(np.median([getattr(q, k) for q in quality])), 5) for k in
                   ("blur_score", "dynamic_range", "brightness", "exposure_score")},
    }


def load_screening(workspace_dir: str) -> Optional[dict]:
    """The screening record of a workspace (for the report), or None before 'Prepare images'."""
    path = os.path.join(workspace_dir, SCREENING_JSON)
    if not os.path.isfile(path):
        return None
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        raise WorkspaceError(f"{path} cannot be read: {e}") from e
