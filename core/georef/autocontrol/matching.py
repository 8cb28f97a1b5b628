"""Matching the provisional orthophoto to the reference orthophoto at a common ground resolution.

RootSIFT (SIFT descriptors L1-normalised and square-rooted: Arandjelovic & Zisserman 2012) on both images after a
local contrast equalisation (CLAHE: another sun, another season), Lowe's ratio test, a RANSAC similarity over the
whole block, then an affine per tile with a tight threshold (a block is not a rigid plane: relief, a deformed
model; and a change that happens to fit the similarity loosely is dropped here).  With no prior at all,
``coarse_search`` finds the rotation and scale first at a coarse level: the features are rotation and scale
invariant, and the provisional orthophoto is also tried turned by a few angles; the one with most RANSAC inliers
wins.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ...common.errors import require


@dataclass
class Features:
    xy: np.ndarray  # (N, 2) OpenCV pixel coordinates (the centre of pixel (0, 0) at (0, 0))
    desc: np.ndarray  # (N, 128) RootSIFT
    size: np.ndarray  # (N,) keypoint diameters, pixels


def rootsift(grey: np.ndarray, valid: Optional[np.ndarray] = None, n_features: int = 20000) -> Features:
    """RootSIFT features of an 8-bit image (only where ``valid``, away from its border)."""
    cv2 = require("cv2", "the automatic control")
    img = cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8)).apply(grey)
    mask = None
    if valid is not None:
        mask = cv2.erode(valid.astype(np.uint8) * 255, np.ones((9, 9), np.uint8))
    sift = cv2.SIFT_create(nfeatures=int(n_features))
    kps, desc = sift.detectAndCompute(img, mask)
    return root_features(kps, desc)


def root_features(kps, desc) -> "Features":
    """OpenCV SIFT keypoints + descriptors as RootSIFT Features (L1-normalised, square-rooted)."""
    if desc is None or not len(kps):
        return Features(np.zeros((0, 2), np.float32), np.zeros((0, 128), np.float32), np.zeros(0, np.float32))
    desc = desc.astype(np.float32)
    desc /= np.maximum(desc.sum(axis=1, keepdims=True), 1e-9)
    desc = np.sqrt(desc)
    xy = np.array([k.pt for k in kps], dtype=np.float32)
    return Features(xy, desc, np.array([k.size for k in kps], dtype=np.float32))


def ratio_matches(a: Features, b: Features, ratio: float) -> Tuple[np.ndarray, np.ndarray]:
    """Indices (ia, ib) of the matches a -> b that pass Lowe's ratio test."""
    cv2 = require("cv2", "the automatic control")
    if len(a.xy) < 2 or len(b.xy) < 2:
        return np.zeros(0, int), np.zeros(0, int)
    if len(a.xy) * len(b.xy) <= 36_000_000:  # exact, and the same matches every run (0.8 s at 5000 x 5000)
        knn = cv2.BFMatcher(cv2.NORM_L2).knnMatch(a.desc, b.desc, k=2)
    else:  # approximate nearest neighbours (randomised KD-trees, whose draws run on from call to call)
        flann = cv2.FlannBasedMatcher({"algorithm": 1, "trees": 4}, {"checks": 64})
        knn = flann.knnMatch(a.desc, b.desc, k=2)
    ia, ib = [], []
    for m in knn:
        if len(m) == 2 and m[0].distance < ratio * m[1].distance:
            ia.append(m[0].queryIdx)
            ib.append(m[0].trainIdx)
    return np.array(ia, dtype=int), np.array(ib, dtype=int)


def similarity_ransac(src: np.ndarray, dst: np.ndarray, threshold: float) -> Tuple[Optional[np.ndarray], np.ndarray]:
    """(2 x 3 similarity src -> dst or None, inlier mask) by RANSAC."""
    cv2 = require("cv2", "the automatic control")
    if len(src) < 3:
        return None, np.zeros(len(src), dtype=bool)
    m, inl = cv2.estimateAffinePartial2D(src.astype(np.float32), dst.astype(np.float32), method=cv2.RANSAC,
                                         ransacReprojThreshold=float(threshold), maxIters=20000, confidence=0.999,
                                         refineIters=10)
    if m is None:
        return None, np.zeros(len(src), dtype=bool)
    return m, inl.ravel().astype(bool)


def apply2(m: np.ndarray, xy: np.ndarray) -> np.ndarray:
    return np.asarray(xy, dtype=float) @ m[:, :2].T + m[:, 2]


@dataclass
class MatchSet:
    """Matches ortho pixel ``src`` -> reference pixel ``dst`` kept by the similarity and the tiles; ``residual``:
    pixels off the tile's affine; ``n_found``: ratio-test matches; ``n_similarity``: the similarity's inliers."""

    src: np.ndarray
    dst: np.ndarray
    residual: np.ndarray
    similarity: Optional[np.ndarray]
    n_found: int
    n_similarity: int
    n_features: Tuple[int, int]


def tile_refine(src: np.ndarray, dst: np.ndarray, tile: int, threshold: float, min_matches: int
                ) -> Tuple[np.ndarray, np.ndarray]:
    """(keep mask, residual pixels): an affine by RANSAC per ``tile`` x ``tile`` cell of the source, and the
    matches within ``threshold`` of it; cells with fewer than ``min_matches`` matches keep none."""
    cv2 = require("cv2", "the automatic control")
    keep = np.zeros(len(src), dtype=bool)
    res = np.full(len(src), np.inf)
    cell = np.floor(src / tile).astype(int)
    key = cell[:, 0] * 100003 + cell[:, 1]
    for k in np.unique(key):
        idx = np.flatnonzero(key == k)
        if len(idx) < min_matches:
            continue
        a, inl = cv2.estimateAffine2D(src[idx].astype(np.float32), dst[idx].astype(np.float32), method=cv2.RANSAC,
                                      ransacReprojThreshold=float(threshold), maxIters=2000, confidence=0.995)
        if a is None or int(inl.sum()) < min_matches:
            continue
        r = np.linalg.norm(apply2(a, src[idx]) - dst[idx], axis=1)
        res[idx] = r
        keep[idx] = r <= threshold
    return keep, res


def match_orthos(ortho: np.ndarray, ortho_valid: np.ndarray, ref: np.ndarray, ref_valid: np.ndarray, opt,
                 ortho_features: Optional[Features] = None) -> MatchSet:
    """Matches between the provisional orthophoto and the reference at the same resolution (``opt``: the
    :class:`~core.georef.autocontrol.options.AutoControlOptions`)."""
    fa = ortho_features if ortho_features is not None else rootsift(ortho, ortho_valid, opt.n_features)
    fb = rootsift(ref, ref_valid, opt.n_features)
    ia, ib = ratio_matches(fa, fb, opt.ratio)
    src, dst = fa.xy[ia].astype(float), fb.xy[ib].astype(float)
    m, inl = similarity_ransac(src, dst, opt.ransac_px)
    empty = np.zeros((0, 2))
    if m is None or inl.sum() < 3:
        return MatchSet(empty, empty, np.zeros(0), None, len(ia), 0, (len(fa.xy), len(fb.xy)))
    # the tiles take the matches near the similarity (a looser bound: relief and a deformed block)
    near = np.linalg.norm(apply2(m, src) - dst, axis=1) <= 3.0 * opt.ransac_px
    keep, res = tile_refine(src[near], dst[near], opt.tile_px, opt.tile_ransac_px, opt.min_tile_matches)
    s, d, r = src[near][keep], dst[near][keep], res[keep]
    # SIFT gives a keypoint one descriptor per dominant orientation: the same match twice is one point, not two
    _, first = np.unique(np.round(np.column_stack([s, d]), 1), axis=0, return_index=True)
    first = np.sort(first)
    return MatchSet(s[first], d[first], r[first], m, len(ia), int(inl.sum()), (len(fa.xy), len(fb.xy)))


def _turned(cv2, img: np.ndarray, valid: np.ndarray, angle: float):
    """``img`` turned by ``angle`` degrees (counter-clockwise) on a canvas that holds it, and the 2 x 3 map of
    the original pixels into the turned ones."""
    h, w = img.shape
    m = cv2.getRotationMatrix2D((0.5 * (w - 1), 0.5 * (h - 1)), angle, 1.0)
    c, s = abs(m[0, 0]), abs(m[0, 1])
    nw, nh = int(math.ceil(h * s + w * c)), int(math.ceil(h * c + w * s))
    m[0, 2] += 0.5 * (nw - w)
    m[1, 2] += 0.5 * (nh - h)
    out = cv2.warpAffine(img, m, (nw, nh), flags=cv2.INTER_LINEAR, borderValue=0)
    val = cv2.warpAffine(valid.astype(np.uint8), m, (nw, nh), flags=cv2.INTER_NEAREST, borderValue=0) > 0
    return out, val, m


def coarse_search(ortho: np.ndarray, ortho_valid: np.ndarray, ref: np.ndarray, ref_valid: np.ndarray, opt
                  ) -> Tuple[Optional[np.ndarray], int, float]:
    """(2 x 3 similarity ortho pixel -> reference pixel, its inlier count, the angle tried) over the rotations
    ``opt.rotations`` of the provisional orthophoto (scale: the features' own invariance), stopping at the first
    with ``opt.coarse_enough`` inliers."""
    cv2 = require("cv2", "the automatic control")
    n_features = max(2000, opt.n_features // 2)
    fb = rootsift(ref, ref_valid, n_features)
    best: Tuple[Optional[np.ndarray], int, float] = (None, 0, 0.0)
    for angle in opt.rotations:
        if best[1] >= opt.coarse_enough:
            break  # a clear winner: the features are rotation invariant, the other angles only cost time
        img, val, t = _turned(cv2, ortho, ortho_valid, angle)
        fa = rootsift(img, val, n_features)
        ia, ib = ratio_matches(fa, fb, opt.ratio)
        m, inl = similarity_ransac(fa.xy[ia].astype(float), fb.xy[ib].astype(float), opt.ransac_px)
        n = int(inl.sum())
        if m is not None and n > best[1]:
            t3 = np.vstack([t, [0.0, 0.0, 1.0]])
            best = ((np.vstack([m, [0.0, 0.0, 1.0]]) @ t3)[:2], n, float(angle))
    return best


__all__ = ["Features", "MatchSet", "apply2", "coarse_search", "match_orthos", "ratio_matches", "root_features", "rootsift",
           "similarity_ransac", "tile_refine"]
