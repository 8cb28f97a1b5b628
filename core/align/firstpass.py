"""The first pass's feature settings, chosen from the photos' texture and size before any extraction (issue 33).

The fast path takes SIFT features from a copy of at most AUTO_FEATURE_MEGAPIXELS with at most
AUTO_FEATURES_RANGE[1] per photo: textured photos fill that budget many times over. Faint, periodic texture (a
ploughed field at low contrast) does not: at SIFT's default peak threshold such a photo yields a few hundred
features, the first mapping leaves most photos out, and the escalation (core.align.escalation) re-extracts and
rematches nearly the whole block -- most of the alignment's time. :func:`choose_first_pass` runs pycolmap's own
SIFT, at the settings of each level in turn, on up to PROBE_PHOTOS photos spread over the block (the same ones each
run) and measures per photo its **yield** (features found / the level's budget) and **coverage** (the share of the
cells of a PROBE_GRID grid over the frame holding at least a quarter of their even share of the features found). A
photo with a yield under PROBE_MIN_YIELD or a coverage under PROBE_MIN_COVERAGE is matched with its neighbour (the
nearest by EXIF GPS, else the next photo in file order) as COLMAP would (ratio test, mutual best, a RANSAC fundamental matrix): it is starved
when fewer than PROBE_MIN_MATCHES matches verify (few features that match are enough: the synthetic farmland at
contrast 0.4 registers every photo with ~230 features each). The first level at which at most
PROBE_STARVED_SHARE of the probed photos starve is the first pass's (the last level otherwise, without a probe):

1. ``default`` -- today's settings (where textured photos stay: the probe is then the only cost);
2. ``faint`` -- the same scale, FAINT_MIN_FEATURES features and a third of SIFT's peak threshold
   (FAINT_PEAK_THRESHOLD);
3. ``faint-fine`` -- also twice the scale: the photo's own pixels up to twice the default's long side, or, where
   the photo is no larger than that, SIFT's first octave -1 (the image upsampled): the escalation's "faint"
   settings.

Scaling up at SIFT's default threshold is not a level: on tests/lowtexture_scene.py's 3600 x 2700 farmland it
found 66 -> 115 features (contrast 0.15) and 234 -> 412 (contrast 0.4) from 2 to 9.7 megapixels, a yield under
0.06 at every scale, where a third of the threshold at 2 megapixels found 590 and 8,029 (docs/measurements.md).

The settings the user gave (a feature image size, a budget or a first octave) are kept as they are: no probe
(nor with ``AlignOptions.texture_probe`` off).
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import cv2
import numpy as np

from ..io.images import ImageInfo, read_matching_grey8
from .features import FeatureSettings, default_settings, feature_image_needed, sift_first_octave
from .options import (
    FAINT_MIN_FEATURES,
    FAINT_PEAK_THRESHOLD,
    PROBE_GRID,
    PROBE_MIN_COVERAGE,
    PROBE_MIN_MATCHES,
    PROBE_MIN_YIELD,
    PROBE_PHOTOS,
    PROBE_STARVED_SHARE,
    AlignOptions,
)

DEFAULT = "default"
FAINT = "faint"
FAINT_FINE = "faint-fine"


@dataclass
class ProbeResult:
    """One probed photo at one level's settings."""

    image: str
    level: str
    found: int
    budget: int
    coverage: float
    neighbour: Optional[str] = None  # the photo matched with it (a photo short of features or coverage)
    matches: Optional[int] = None  # verified matches with ``neighbour``

    @property
    def yield_(self) -> float:
        return self.found / max(1, self.budget)

    @property
    def starved(self) -> bool:
        """Short of features or coverage, and (where it was matched) fewer verified matches with its neighbour
        than PROBE_MIN_MATCHES."""
        if _rich(self.found, self.coverage, self.budget):
            return False
        return self.matches is None or self.matches < PROBE_MIN_MATCHES

    def to_dict(self) -> dict:
        return {**asdict(self), "yield": round(self.yield_, 3), "coverage": round(self.coverage, 3),
                "starved": self.starved}


@dataclass
class FirstPass:
    """The first pass's settings, the level they come from, why, and what the probe measured."""

    settings: FeatureSettings
    level: str
    reason: str
    probe: List[ProbeResult] = field(default_factory=list)
    seconds: float = 0.0

    def key(self) -> Optional[Dict[str, object]]:
        """What the database key holds of the choice: None for the default (the key of earlier workspaces)."""
        return None if self.level == DEFAULT else {"level": self.level, **self.settings.to_dict()}

    def to_dict(self) -> dict:
        return {"level": self.level, "reason": self.reason, "settings": self.settings.to_dict(),
                "probe_seconds": round(self.seconds, 2), "probe": [p.to_dict() for p in self.probe]}

    def log_line(self) -> str:
        s = self.settings
        threshold = f", peak threshold {s.peak_threshold:.4f}" if s.peak_threshold is not None else ""
        return (f"first pass: {self.level} features ({s.image_size} px long side, {s.max_features} per photo, "
                f"first octave {s.first_octave}{threshold}): {self.reason}; probe {self.seconds:.1f} s")


def levels(base: FeatureSettings, width: int, height: int) -> List[Tuple[str, FeatureSettings]]:
    """The ladder of settings the probe tries, from the default (``base``) on (see the module's docstring)."""
    side = max(width, height)
    budget = max(FAINT_MIN_FEATURES, base.max_features)
    out = [(DEFAULT, base),
           (FAINT, FeatureSettings(base.image_size, budget, base.first_octave, FAINT_PEAK_THRESHOLD))]
    if side > base.image_size:  # the photo's own pixels, up to twice the default's long side
        fine = min(side, 2 * base.image_size)
        octave = sift_first_octave(AlignOptions(max_image_size=fine), width, height)
        out.append((FAINT_FINE, FeatureSettings(fine, budget, octave, FAINT_PEAK_THRESHOLD)))
    elif base.first_octave >= 0:  # as large as it is: upsampled
        out.append((FAINT_FINE, FeatureSettings(base.image_size, budget, -1, FAINT_PEAK_THRESHOLD)))
    return out


def probe_photos(names: Sequence[str], count: int = PROBE_PHOTOS) -> List[str]:
    """Up to ``count`` of ``names`` (in their order) spread evenly over it, both ends included."""
    names = list(names)
    if len(names) <= count:
        return names
    picks = sorted({int(round(k * (len(names) - 1) / (count - 1))) for k in range(count)})
    return [names[k] for k in picks]


def read_grey(path: str, side: int, long_side: int) -> Optional[np.ndarray]:
    """The photo at ``path`` (``side`` px on its long side) as 8-bit grey with ``long_side`` px on its long side
    at most (None when OpenCV cannot read it); decoded at a reduced size (a JPEG's DCT scaling) where that is
    still as large."""
    flag = cv2.IMREAD_GRAYSCALE
    for r, f in ((4, cv2.IMREAD_REDUCED_GRAYSCALE_4), (2, cv2.IMREAD_REDUCED_GRAYSCALE_2)):
        if side // r >= long_side:
            flag = f
            break
    img = cv2.imread(path, flag | cv2.IMREAD_IGNORE_ORIENTATION)
    if img is None:
        return None
    return shrink(img, long_side)


def shrink(img: np.ndarray, long_side: int) -> np.ndarray:
    """``img`` scaled down (area averaging) to ``long_side`` px on its long side; as it is when not larger."""
    h, w = img.shape[:2]
    if max(h, w) <= long_side:
        return np.ascontiguousarray(img)
    s = long_side / max(h, w)
    return cv2.resize(img, (max(1, int(round(w * s))), max(1, int(round(h * s)))), interpolation=cv2.INTER_AREA)


def coverage(xy: np.ndarray, width: int, height: int, cells: int = PROBE_GRID) -> float:
    """The share of the cells of a grid (``cells`` along the long side) holding at least a quarter of their even
    share of the features at ``xy`` (pixel positions in a ``width`` x ``height`` frame)."""
    nx, ny = (cells, max(1, round(cells * height / width))) if width >= height else \
        (max(1, round(cells * width / height)), cells)
    if len(xy) == 0:
        return 0.0
    gx = np.clip((xy[:, 0] / width * nx).astype(int), 0, nx - 1)
    gy = np.clip((xy[:, 1] / height * ny).astype(int), 0, ny - 1)
    counts = np.bincount(gy * nx + gx, minlength=nx * ny)
    return float(np.mean(counts >= 0.25 * len(xy) / (nx * ny)))


def sift_features(pycolmap, grey: np.ndarray, settings: FeatureSettings) -> Tuple[np.ndarray, np.ndarray]:
    """pycolmap's SIFT with ``settings`` on the 8-bit image ``grey`` (already at the settings' size): (n, 2)
    keypoint positions in its pixels, (n, 128) descriptors."""
    eo = pycolmap.FeatureExtractionOptions()
    eo.num_threads = 1
    eo.max_image_size = max(grey.shape)
    eo.sift.max_num_features = int(settings.max_features)
    eo.sift.first_octave = int(settings.first_octave)
    if settings.peak_threshold is not None:
        eo.sift.peak_threshold = float(settings.peak_threshold)
    extractor = pycolmap.FeatureExtractor.create(eo, pycolmap.Device.cpu)
    keypoints, descriptors = extractor.extract_from_uint8_array(np.ascontiguousarray(grey))
    xy = np.array([(k.x, k.y) for k in keypoints], dtype=np.float64).reshape(-1, 2)
    desc = np.asarray(descriptors.data, dtype=np.float32)
    return xy, (desc.reshape(len(xy), -1) if len(xy) else np.zeros((0, 128), np.float32))


def verified_matches(a: Tuple[np.ndarray, np.ndarray], b: Tuple[np.ndarray, np.ndarray]) -> int:
    """The matches of two photos' features (``(xy, descriptors)``) that a fundamental matrix verifies, as COLMAP
    counts them: mutual nearest neighbours passing the ratio test (0.8), RANSAC with 4 px."""
    (xa, da), (xb, db) = a, b
    if len(xa) < 8 or len(xb) < 8:
        return 0
    matcher = cv2.BFMatcher(cv2.NORM_L2)
    ab = matcher.knnMatch(da, db, k=2)
    ba = {m[0].queryIdx: m[0].trainIdx for m in matcher.knnMatch(db, da, k=1) if m}
    pairs = [(m[0].queryIdx, m[0].trainIdx) for m in ab
             if len(m) == 2 and m[0].distance < 0.8 * m[1].distance and ba.get(m[0].trainIdx) == m[0].queryIdx]
    if len(pairs) < 8:
        return 0
    ia, ib = np.array(pairs).T
    _f, mask = cv2.findFundamentalMat(xa[ia], xb[ib], cv2.FM_RANSAC, 4.0, 0.999)
    return int(mask.sum()) if mask is not None else 0


class _Photos:
    """The probe photos' grey images (read once, at the largest size a probed level needs) and their features
    per level."""

    def __init__(self, pycolmap, infos: Sequence[ImageInfo], long_side: int):
        self.pycolmap = pycolmap
        self.by_name = {im.name: im for im in infos}
        self.long_side = long_side
        self.grey: Dict[str, Optional[np.ndarray]] = {}
        self.features: Dict[Tuple[str, str], Tuple[np.ndarray, np.ndarray, Tuple[int, int]]] = {}

    def image(self, name: str) -> Optional[np.ndarray]:
        if name not in self.grey:
            im = self.by_name[name]
            # as COLMAP sees it (core.align.features.feature_images): a photo other than 8-bit, or a capture's,
            # stretched to 8 bits (its primary band)
            if feature_image_needed(im):
                self.grey[name] = read_matching_grey8(im.path, im.primary_band, self.long_side)
            else:
                self.grey[name] = read_grey(im.path, max(im.width, im.height), self.long_side)
        return self.grey[name]

    def sift(self, name: str, level: str, settings: FeatureSettings):
        """(xy, descriptors, (width, height) of the image SIFT ran on) of photo ``name`` at ``settings``."""
        if (name, level) not in self.features:
            img = shrink(self.image(name), settings.image_size)
            xy, desc = sift_features(self.pycolmap, img, settings)
            self.features[(name, level)] = (xy, desc, (img.shape[1], img.shape[0]))
        return self.features[(name, level)]


def _rich(found: int, cover: float, budget: int) -> bool:
    return found >= PROBE_MIN_YIELD * budget and cover >= PROBE_MIN_COVERAGE


def probe(photos: _Photos, name: str, neighbour: Optional[str], settings: FeatureSettings,
          level: str) -> ProbeResult:
    """Yield, coverage and (for a photo short of either) verified matches with its ``neighbour`` at ``settings``.
    SIFT is run from its first octave 1 down to the settings' first octave, stopping at the first that finds the
    photo rich: a finer first octave only adds features to a coarser one's (COLMAP keeps the coarsest within the
    budget), so a photo rich without the finer octaves is rich with them, at a quarter of the cost per octave
    left out (a textured 2 MP photo fills a fifth of its budget from octave 1 on)."""
    for octave in range(max(settings.first_octave, 1), settings.first_octave - 1, -1):
        s = FeatureSettings(settings.image_size, settings.max_features, octave, settings.peak_threshold)
        key = f"{level}@{octave}"
        xy, desc, (w, h) = photos.sift(name, key, s)
        result = ProbeResult(name, level, len(xy), int(s.max_features), coverage(xy, w, h))
        if _rich(result.found, result.coverage, result.budget):
            return result
    if neighbour is not None and photos.image(neighbour) is not None:
        other = photos.sift(neighbour, key, s)
        result.neighbour = neighbour
        result.matches = verified_matches((xy, desc), other[:2])
    return result


def decide(results: Sequence[ProbeResult], total: int) -> Optional[bool]:
    """Whether a level is good enough from the ``results`` so far of ``total`` photos to probe: False as soon as
    more than PROBE_STARVED_SHARE of them starved, True when all are probed and no more starved or when the first
    half of them starved none (the rest is not probed), None while undecided."""
    starved = sum(1 for r in results if r.starved)
    if starved > PROBE_STARVED_SHARE * total:
        return False
    if len(results) == total or (starved == 0 and 2 * len(results) >= total):
        return True
    return None


def probe_order(names: Sequence[str]) -> List[str]:
    """``names`` (spread over the block) reordered so that the first half spans it: ends and middle first."""
    names = list(names)
    if len(names) <= 2:
        return names
    first = [names[0], names[len(names) // 2], names[-1]]
    return first + [n for n in names if n not in first]


def neighbours(names: Sequence[str], picked: Sequence[str],
               positions: Optional[Dict[str, Tuple[float, float]]] = None) -> Dict[str, Optional[str]]:
    """Each picked photo's neighbour: the nearest other photo by ``positions`` (x, y in metres, from EXIF GPS) where
    every photo has one, else the next photo in ``names`` (file order: the order of a flight), the one before for
    the last."""
    index = {n: k for k, n in enumerate(names)}
    out: Dict[str, Optional[str]] = {}
    for n in picked:
        if positions and len(positions) == len(names) and len(names) > 1:
            x, y = positions[n]
            out[n] = min((m for m in names if m != n),
                         key=lambda m: (positions[m][0] - x) ** 2 + (positions[m][1] - y) ** 2)
            continue
        k = index[n]
        out[n] = names[k + 1] if k + 1 < len(names) else (names[k - 1] if k > 0 else None)
    return out


def gps_positions(infos: Sequence[ImageInfo]) -> Dict[str, Tuple[float, float]]:
    """Local x, y (metres, equirectangular about the first) of the photos with EXIF GPS."""
    located = [im for im in infos if im.gps]
    if not located:
        return {}
    lon0, lat0 = located[0].gps[0], located[0].gps[1]
    k = math.cos(math.radians(lat0))
    return {im.name: ((im.gps[0] - lon0) * 111320.0 * k, (im.gps[1] - lat0) * 110540.0) for im in located}


def _summary(level: str, results: Sequence[ProbeResult]) -> str:
    starved = sum(1 for r in results if r.starved)
    y = np.median([r.yield_ for r in results])
    c = np.median([r.coverage for r in results])
    matched = [r.matches for r in results if r.matches is not None]
    m = f", verified matches with a neighbour {int(np.median(matched))}" if matched else ""
    return (f"{level}: {starved} of {len(results)} probed photos starved (median yield {y:.2f}, coverage {c:.2f}"
            f"{m})")


def choose_first_pass(pycolmap, infos: Sequence[ImageInfo], options: AlignOptions, width: int, height: int,
                      positions: Optional[Dict[str, Tuple[float, float]]] = None) -> FirstPass:
    """The first pass's settings for the photos ``infos`` of the largest camera (``width`` x ``height``): the
    first level of :func:`levels` the probe finds good enough (:func:`decide`), else the last, which is taken
    without a probe (the richest the first pass gets).  ``positions``: the photos' horizontal positions
    (:func:`.pairs.photo_positions`) for the probed photos' neighbours; None: their EXIF GPS."""
    base = default_settings(options, width, height)
    if options.max_image_size or options.max_features or options.first_octave is not None:
        return FirstPass(base, DEFAULT, "the feature size, budget or first octave set in the options")
    if not options.texture_probe:
        return FirstPass(base, DEFAULT, "the texture probe switched off in the options")
    t0 = time.time()
    ladder = levels(base, width, height)
    same = [im for im in infos if (im.width, im.height) == (width, height)]
    names = [im.name for im in same]
    chosen = probe_order(probe_photos(names))
    near = neighbours(names, chosen, gps_positions(same) if positions is None
                      else {n: positions[n] for n in names if n in positions})
    photos = _Photos(pycolmap, same, max(s.image_size for _, s in ladder[:-1]))
    readable = [n for n in chosen if photos.image(n) is not None]  # OpenCV cannot read it: probed without it
    if not readable:
        return FirstPass(base, DEFAULT, "no photo could be probed", seconds=time.time() - t0)
    measured: List[ProbeResult] = []
    why: List[str] = []
    for level, settings in ladder[:-1]:
        results: List[ProbeResult] = []
        for n in readable:
            results.append(probe(photos, n, near[n], settings, level))
            verdict = decide(results, len(readable))
            if verdict is not None:
                break
        measured += results
        why.append(_summary(level, results))
        if verdict:
            return FirstPass(settings, level, "; ".join(why), measured, time.time() - t0)
    level, settings = ladder[-1]
    why.append(f"{level} taken (the richest level)")
    return FirstPass(settings, level, "; ".join(why), measured, time.time() - t0)
