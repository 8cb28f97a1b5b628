"""Candidate targets on one photo, each refined to sub-pixel, each with a quality.

Every threshold is in units of the photo (its noise, its size) or of the candidate itself (its size in
pixels), never a number of pixels tuned on one data set:

* the contrast a mark needs is a multiple of the photo's local-contrast noise (robust spread of the photo minus
  its local mean);
* sizes run from ``min_size_px`` to ``max_size_fraction`` of the shorter side.

Kinds:

``cross``
    a square of one tone crossed by two bars of the other (tarps: black with a white cross, or the inverse); the
    centre is the intersection of the two bars' centre lines, each fitted (weighted least squares) to the bar's
    pixels, so it holds under perspective (lines stay lines).
``checkerboard``
    a 2 x 2 checker (an X-junction): found as a saddle of the smoothed photo (negative Hessian determinant), checked
    by the four alternating sectors on rings around it (point-symmetric), refined by ``cv2.cornerSubPix``, and
    kept only if it fits the checker's template: its sector boundaries, followed from ring to ring, are lines
    through its centre (``checker_misfit``: within ``CHECKER_MISFIT`` of its radius; the bar of a cross also cuts
    every ring into four alternating arcs, but its edges pass half the bar's width from the centre).
``circle``
    a disc of one tone on the other: the edge found to sub-pixel along rays, an ellipse fitted to it; its
    residual keeps squares and blots out.
``aruco``
    OpenCV's ArUco/AprilTag detector (sub-pixel corners); the centre is the intersection of the diagonals
    (exact under perspective), the code names the target.

A mark that touches the photo's border, or whose own test fails (an arm of the cross missing, the checker's
sectors broken by an occluder), is left out rather than guessed.
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ...common.progress import Progress, check_cancel
from .options import ARUCO, CHECKERBOARD, CIRCLE, CROSS, FindTargetsOptions


@dataclass
class Candidate:
    """A mark on one photo: pixel centre (COLMAP convention: origin at the upper-left corner of the upper-left
    pixel, so a pixel centre sits at +0.5), its kind, its size (side or diameter, pixels), a quality in [0, 1]
    (how clearly the mark passed its own test) and, for coded targets, its code."""

    image: str
    x: float
    y: float
    kind: str
    size_px: float
    quality: float
    code: Optional[int] = None


def _cv2():
    from ..errors import GeorefError

    try:
        import cv2
    except ImportError as e:  # pragma: no cover - the plugin's dependencies include OpenCV
        raise GeorefError(f"Find targets needs OpenCV (cv2): {e}") from e
    return cv2


def local_contrast(gray: np.ndarray) -> Tuple[np.ndarray, float]:
    """(photo minus its local mean, robust noise of that difference): the unit of every contrast test."""
    cv2 = _cv2()
    k = max(15, (min(gray.shape) // 12) | 1)
    diff = gray - cv2.blur(gray, (k, k))
    med = float(np.median(diff[::4, ::4]))
    sigma = 1.4826 * float(np.median(np.abs(diff[::4, ::4] - med)))
    return diff, max(sigma, 0.5)


def _sample(gray: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Bilinear samples at array coordinates (x right, y down; pixel centres at integers); NaN outside."""
    cv2 = _cv2()
    mx, my = xs.astype(np.float32), ys.astype(np.float32)
    out = cv2.remap(gray, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan)
    h, w = gray.shape
    out[(xs < 0) | (ys < 0) | (xs > w - 1) | (ys > h - 1)] = np.nan
    return out


# --------------------------------------------------------------------------------------------------
# cross
# --------------------------------------------------------------------------------------------------

def _line_fit(px: np.ndarray, w: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Weighted total-least-squares line: (point, unit direction)."""
    c = (px * w[:, None]).sum(0) / w.sum()
    d = px - c
    cov = (d * w[:, None]).T @ d
    vals, vecs = np.linalg.eigh(cov)
    return c, vecs[:, 1]


def _bar_lines(px: np.ndarray, w: np.ndarray, size: float):
    """The two bars of a cross among bright pixels ``px`` (N, 2) weighted ``w``: [(point, direction, strip
    mask)] x 2, or None.  A Radon search (1 degree) finds each bar as the sharpest projection peak; a weighted
    line fit to the pixels of its strip refines it."""
    angles = np.deg2rad(np.arange(0.0, 180.0, 1.0))
    normals = np.stack([np.cos(angles), np.sin(angles)], 1)
    proj = px @ normals.T  # (N, A)
    lo = proj.min(0)
    bins = np.floor(proj - lo).astype(int)
    nb = int(bins.max()) + 2
    flat = (bins + np.arange(len(angles))[None, :] * nb).ravel()
    hist = np.bincount(flat, weights=np.repeat(w, len(angles)), minlength=len(angles) * nb).reshape(len(angles), nb)
    box = max(1, int(round(size / 6)))  # a bar is about a sixth of the square: score whole bars, not thin strokes
    cs = np.concatenate([np.zeros((len(angles), 1)), np.cumsum(hist, 1)], 1)
    smooth = cs[:, box:] - cs[:, :-box]
    peak = smooth.max(1)
    a1 = int(np.argmax(peak))
    sep = np.abs(((np.arange(len(angles)) - a1 + 90) % 180) - 90)
    a2 = int(np.argmax(np.where(sep >= 40, peak, -1.0)))
    lines = []
    for a in (a1, a2):
        prof = hist[a]
        k = int(np.argmax(prof))
        half = prof[k] / 2.0
        i0, i1 = k, k
        while i0 > 0 and prof[i0 - 1] >= half:
            i0 -= 1
        while i1 < nb - 1 and prof[i1 + 1] >= half:
            i1 += 1
        width = max(1.0, i1 - i0 + 1.0)
        if width > 0.4 * size:
            return None
        centre = lo[a] + 0.5 * (i0 + i1 + 1)
        strip = np.abs(proj[:, a] - centre) <= 0.5 * width + 1.0
        if strip.sum() < 4:
            return None
        p, d = _line_fit(px[strip], w[strip])
        dist = np.abs((px - p) @ np.array([-d[1], d[0]]))
        strip = dist <= 0.5 * width + 1.0
        if strip.sum() < 4:
            return None
        p, d = _line_fit(px[strip], w[strip])
        lines.append((p, d, strip, width))
    return lines


def _intersect(p1, d1, p2, d2) -> Optional[np.ndarray]:
    a = np.array([d1, -d2]).T
    if abs(np.linalg.det(a)) < 0.2:  # closer than ~12 degrees: not a cross
        return None
    s = np.linalg.solve(a, p2 - p1)
    return p1 + s[0] * d1


def _cross_in_region(gray: np.ndarray, region: np.ndarray, body: np.ndarray, sign: float, min_contrast: float):
    """Centre, quality of a cross whose square is ``region`` (bool, ROI) with body pixels ``body``; None if the
    region holds no complete cross."""
    cv2 = _cv2()
    size = math.sqrt(region.sum())
    inner = cv2.erode(region.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    g = gray * sign
    dark = float(np.median(g[body & region]))
    light = float(np.percentile(g[inner], 95)) if inner.any() else dark
    if light - dark < min_contrast:  # no bars of the other tone: a plain blot
        return None
    wmap = np.clip((g - dark) / (light - dark), 0.0, 1.0) * inner
    frac = wmap.sum() / region.sum()
    if not 0.05 <= frac <= 0.6:
        return None
    ys, xs = np.nonzero(wmap > 0.25)
    if len(xs) < 8:
        return None
    px = np.stack([xs, ys], 1).astype(float)
    w = wmap[ys, xs]
    lines = _bar_lines(px, w, size)
    if lines is None:
        return None
    (p1, d1, s1, w1), (p2, d2, s2, w2) = lines
    c = _intersect(p1, d1, p2, d2)
    if c is None:
        return None
    centroid = np.argwhere(region)[:, ::-1].mean(0)
    if np.linalg.norm(c - centroid) > 0.35 * size:
        return None
    balance = []
    for _p, d, s in ((p1, d1, s1), (p2, d2, s2)):
        t = (px[s] - c) @ d
        a, b = w[s][t > 0].sum(), w[s][t < 0].sum()
        balance.append(min(a, b) / max(a, b, 1e-9))
        if (t.max() - t.min()) < 0.6 * size:  # the bar must cross the square
            return None
    if min(balance) < 0.3:  # an arm missing: cut by the border or occluded
        return None
    return c, float(min(1.0, min(balance) / 0.7))


def find_crosses(image: str, gray: np.ndarray, diff: np.ndarray, noise: float, min_px: float,
                 max_px: float) -> List[Candidate]:
    """Crosses of both polarities (dark square, bright cross; and the inverse)."""
    cv2 = _cv2()
    h, w = gray.shape
    out: List[Candidate] = []
    kernels = [k for k in (3, 5, 9, 15, 25, 41) if k <= max(3.0, max_px / 4)]
    for sign in (-1.0, 1.0):
        body = (diff * sign > 4.0 * noise).astype(np.uint8)
        for k in kernels:
            closed = cv2.morphologyEx(body, cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
            n, lab, st, _ = cv2.connectedComponentsWithStats(closed, connectivity=8)
            for i in range(1, n):
                x0, y0, bw, bh, area = (int(v) for v in st[i])
                if not (min_px ** 2 * 0.5 <= area <= max_px ** 2) or max(bw, bh) < min_px:
                    continue
                m = 2 + k
                if x0 < m or y0 < m or x0 + bw > w - m or y0 + bh > h - m:
                    continue  # touches the border: maybe half a target
                pad = 2
                sl = (slice(y0 - pad, y0 + bh + pad), slice(x0 - pad, x0 + bw + pad))
                cnt, _ = cv2.findContours((lab[sl] == i).astype(np.uint8), cv2.RETR_EXTERNAL,
                                          cv2.CHAIN_APPROX_SIMPLE)
                outline = max(cnt, key=cv2.contourArea)
                hull = cv2.contourArea(cv2.convexHull(outline))
                (_, _), (rw, rh), _ = cv2.minAreaRect(outline)
                if hull <= 0 or area / hull < 0.8 or area < 0.7 * rw * rh or max(rw, rh) > 3 * min(rw, rh):
                    continue
                region = np.zeros(closed[sl].shape, np.uint8)
                cv2.drawContours(region, [outline], -1, 1, -1)  # holes filled: the bars' crossing included
                region = region.astype(bool)
                found = _cross_in_region(gray[sl], region, body[sl].astype(bool), -sign, 8.0 * noise)
                if found is None:
                    continue
                c, q = found
                out.append(Candidate(image, float(c[0] + x0 - pad + 0.5), float(c[1] + y0 - pad + 0.5), CROSS,
                                     math.sqrt(area), q))
    return suppress(out)


def suppress(cands: Sequence[Candidate], factor: float = 0.3) -> List[Candidate]:
    """One candidate per mark: of those closer than ``factor`` x their size, the best quality (then the
    largest) stays."""
    kept: List[Candidate] = []
    for c in sorted(cands, key=lambda c: (-c.quality, -c.size_px)):
        if all(math.hypot(c.x - k.x, c.y - k.y) > factor * max(c.size_px, k.size_px) for k in kept):
            kept.append(c)
    return kept


# --------------------------------------------------------------------------------------------------
# checkerboard
# --------------------------------------------------------------------------------------------------

def _ring_sectors(gray: np.ndarray, x: float, y: float, r: float, min_contrast: float) -> Optional[float]:
    """The ring of radius ``r`` around (x, y) (array coordinates) crosses four alternating sectors, point-symmetric
    (the checker's X): returns the ring's contrast, else None (also when the ring leaves the photo)."""
    n = max(32, int(4 * r))
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = _sample(gray, x + r * np.cos(t), y + r * np.sin(t)).ravel()
    if not np.all(np.isfinite(v)):
        return None
    srt = np.sort(v)
    lo, hi = srt[n // 10], srt[(9 * n) // 10]
    if hi - lo < min_contrast:
        return None
    b = v > 0.5 * (lo + hi)
    if int(np.count_nonzero(b != np.roll(b, 1))) != 4:
        return None
    opposite = np.roll(b, n // 2)
    if np.mean(b == opposite) < 0.85:  # opposite sectors of the same tone
        return None
    return float(hi - lo)


def _rings_pass(gray: np.ndarray, pts: np.ndarray, r: float, min_contrast: float) -> np.ndarray:
    """``_ring_sectors`` for many centres at once (a first sieve): bool per point."""
    n = max(32, int(4 * r))
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = _sample(gray, pts[:, 0:1] + r * np.cos(t)[None, :], pts[:, 1:2] + r * np.sin(t)[None, :])
    srt = np.sort(v, axis=1)
    lo, hi = srt[:, n // 10], srt[:, (9 * n) // 10]
    b = v > 0.5 * (lo + hi)[:, None]
    flips = np.count_nonzero(b != np.roll(b, 1, axis=1), axis=1)
    same = np.mean(b == np.roll(b, n // 2, axis=1), axis=1)
    return np.isfinite(v).all(1) & (hi - lo >= min_contrast) & (flips == 4) & (same >= 0.85)


def _checker_extent(gray: np.ndarray, x: float, y: float, r0: float, r_max: float,
                    min_contrast: float) -> Optional[float]:
    """Radius out to which the X pattern holds; None if it leaves the photo while still an X (cut by the
    border) or fails at the first ring."""
    r, last = r0, None
    h, w = gray.shape
    while r <= r_max:
        if x - r < 0 or y - r < 0 or x + r > w - 1 or y + r > h - 1:
            return None  # the target runs out of the photo
        if _ring_sectors(gray, x, y, r, min_contrast) is None:
            return last
        last = r
        r *= 1.25
    return last


CHECKER_MISFIT = 0.08  # the sector boundaries may pass this fraction of the mark's radius from its centre


def _ring_boundaries(gray: np.ndarray, x: float, y: float, r: float) -> Optional[np.ndarray]:
    """The angles (radians, sub-sample) of the tone changes on the ring of radius ``r`` around (x, y), sampled as
    :func:`_ring_sectors` samples it; None unless there are four."""
    n = max(32, int(4 * r))
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = _sample(gray, x + r * np.cos(t), y + r * np.sin(t)).ravel()
    if not np.all(np.isfinite(v)):
        return None
    srt = np.sort(v)
    mid = 0.5 * (srt[n // 10] + srt[(9 * n) // 10])
    b = v > mid
    k = np.nonzero(b != np.roll(b, 1))[0]
    if len(k) != 4:
        return None
    v0, v1 = v[k - 1], v[k]
    f = np.where(v1 != v0, (mid - v0) / np.where(v1 != v0, v1 - v0, 1.0), 0.5)
    return np.mod(t[k] - (1.0 - f) * (2 * np.pi / n), 2 * np.pi)


def checker_misfit(gray: np.ndarray, x: float, y: float, extent: float) -> Optional[float]:
    """How far the mark at (x, y) (array coordinates) is from a checker's template, two straight lines through its
    centre: each of its four sector boundaries followed from ring to ring (the rings :func:`_checker_extent` walks,
    out to 0.6 of the ``extent``, where the pattern is the target's and not what surrounds it), a line fitted to
    it, and the mean distance of the four lines from the centre as a fraction of the extent.  A checker's
    boundaries meet at its centre (near 0); the bar of a cross, whose two edges also cut every ring into four
    alternating arcs, gives half the bar's width over the radius.  None when a ring does not show four
    boundaries."""
    rings = []
    r = 2.5
    while r <= max(0.6 * extent, 2.5 * 1.25) * 1.0001:
        a = _ring_boundaries(gray, x, y, r)
        if a is None:
            return None
        rings.append((r, a))
        r *= 1.25
    ref = rings[-1][1]
    dist = []
    for j in range(4):
        pts = []
        for r, a in rings:
            k = int(np.argmin(np.abs(np.angle(np.exp(1j * (a - ref[j]))))))
            pts.append((r * math.cos(a[k]), r * math.sin(a[k])))
        pts = np.array(pts)
        c = pts.mean(0)
        normal = np.linalg.svd(pts - c)[2][1]
        dist.append(abs(float(c @ normal)))
    return float(np.mean(dist)) / extent


def find_checkers(image: str, gray: np.ndarray, noise: float, min_px: float, max_px: float) -> List[Candidate]:
    """2 x 2 checkers: saddles of the smoothed photo at scales (sigma) from ``min_px`` / 6 to ``max_px`` / 6, the
    larger ones on a pyramid level; each refined at full size (cornerSubPix) and kept if rings from 2.5 px out show
    the X."""
    cv2 = _cv2()
    out: List[Candidate] = []
    min_contrast = 8.0 * noise
    sigma = max(1.0, min_px / 6)
    level, step = gray, 1  # larger scales on a pyramid level (the saddle search only; refined at full size)
    while sigma <= max_px / 6:
        while sigma / step > 3.0 and min(level.shape) > 64:
            level, step = cv2.pyrDown(level), step * 2
        s = sigma / step
        g = cv2.GaussianBlur(level, (0, 0), s)
        gxx = cv2.Sobel(g, cv2.CV_32F, 2, 0, ksize=3)
        gyy = cv2.Sobel(g, cv2.CV_32F, 0, 2, ksize=3)
        gxy = cv2.Sobel(g, cv2.CV_32F, 1, 1, ksize=3) / 4.0
        resp = (gxy * gxy - gxx * gyy) * s ** 4
        thr = (min_contrast / math.pi) ** 2  # a saddle of contrast C gives about (C / pi)^2
        peaks = (resp > thr) & (resp >= cv2.dilate(resp, np.ones((5, 5), np.uint8)))
        ys, xs = np.nonzero(peaks)
        xs, ys = np.round((xs + 0.5) * step - 0.5).astype(int), np.round((ys + 0.5) * step - 0.5).astype(int)
        if len(xs):
            pts = np.stack([xs, ys], 1).astype(np.float32).reshape(-1, 1, 2)
            win = max(2, int(round(1.5 * sigma)))
            ok = (xs > win + 1) & (ys > win + 1) & (xs < gray.shape[1] - win - 2) & (ys < gray.shape[0] - win - 2)
            pts = pts[ok]
            if len(pts):
                crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 0.001)
                pts = cv2.cornerSubPix(gray, pts.copy(), (win, win), (-1, -1), crit).reshape(-1, 2)
                pts = pts[_rings_pass(gray, pts.astype(float), 2.5, min_contrast)]
            for x, y in pts.reshape(-1, 2):
                r = _checker_extent(gray, float(x), float(y), 2.5, max_px / 2, min_contrast)
                if r is None:
                    continue
                size = 2.0 * r * 1.25
                if size < min_px:
                    continue
                misfit = checker_misfit(gray, float(x), float(y), r)
                if misfit is None or misfit > CHECKER_MISFIT:
                    continue  # not a checker's X: the bar of a cross, an edge's corner
                q = min(1.0, r / (3.0 * max(2.5, sigma)))
                out.append(Candidate(image, float(x) + 0.5, float(y) + 0.5, CHECKERBOARD, size, q))
        sigma *= 1.6
    return suppress(out)


# --------------------------------------------------------------------------------------------------
# circle
# --------------------------------------------------------------------------------------------------

def _edge_points(gray: np.ndarray, ell, n: int = 72) -> Optional[np.ndarray]:
    """Sub-pixel edge of a disc seen as the ellipse ``ell`` ((cx, cy), (a, b) full axes, angle in degrees, as
    OpenCV gives it): the half-level crossing along ``n`` rays from its centre, each sampled out to 1.4 times the
    ellipse's radius in its direction; None if the disc's surround is not of one contrasting tone all round (an
    occluder, a neighbour, the border)."""
    (cx, cy), (ax, bx), ang = ell
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    c, sn = math.cos(math.radians(ang)), math.sin(math.radians(ang))
    du, dv = np.cos(t) * c + np.sin(t) * sn, -np.cos(t) * sn + np.sin(t) * c
    r_dir = 1.0 / np.sqrt((du / max(ax / 2, 0.5)) ** 2 + (dv / max(bx / 2, 0.5)) ** 2)  # ellipse radius per ray
    u = np.linspace(0.0, 1.4, max(24, int(6 * max(ax, bx) / 2)))
    s = r_dir[:, None] * u[None, :]
    prof = _sample(gray, cx + np.cos(t)[:, None] * s, cy + np.sin(t)[:, None] * s)
    if not np.all(np.isfinite(prof)):
        return None
    inside = np.median(prof[:, u < 0.5])
    outside = prof[:, u > 1.2].mean(1)
    if np.ptp(outside) > 0.35 * abs(np.median(outside) - inside):
        return None
    level = 0.5 * (inside + np.median(outside))
    sign = 1.0 if np.median(outside) > inside else -1.0
    pts = []
    for k in range(n):
        above = (prof[k] - level) * sign > 0
        j = int(np.argmax(above))
        if not above[j] or j == 0 or above[j:].mean() < 0.9:
            return None
        a, b = prof[k, j - 1] - level, prof[k, j] - level
        f = a / (a - b) if a != b else 0.5
        r = s[k, j - 1] + f * (s[k, j] - s[k, j - 1])
        pts.append((cx + r * np.cos(t[k]), cy + r * np.sin(t[k])))
    return np.array(pts)


def _moment_ellipse(lab: np.ndarray, i: int, x0: int, y0: int, bw: int, bh: int):
    """The ellipse of a component's second moments (OpenCV's form), a first guess for the edge search."""
    ys, xs = np.nonzero(lab[y0:y0 + bh, x0:x0 + bw] == i)
    pts = np.stack([xs + x0, ys + y0], 1).astype(float)
    centre = pts.mean(0)
    vals, vecs = np.linalg.eigh(np.cov((pts - centre).T) + np.eye(2) / 12.0)
    ang = math.degrees(math.atan2(vecs[1, 1], vecs[0, 1]))
    return (float(centre[0]), float(centre[1])), (4.0 * math.sqrt(vals[1]), 4.0 * math.sqrt(vals[0])), ang


def _ellipse_misfit(pts: np.ndarray, ell) -> float:
    """Largest radial misfit of points to an ellipse, relative to its mean radius."""
    (ex, ey), (a, b), ang = ell
    c, s = math.cos(math.radians(ang)), math.sin(math.radians(ang))
    d = pts - (ex, ey)
    u = (d[:, 0] * c + d[:, 1] * s) / (a / 2)
    v = (-d[:, 0] * s + d[:, 1] * c) / (b / 2)
    return float(np.abs(np.hypot(u, v) - 1.0).max())


def find_circles(image: str, gray: np.ndarray, diff: np.ndarray, noise: float, min_px: float,
                 max_px: float) -> List[Candidate]:
    """Discs of both polarities, the centre of an ellipse fitted to their sub-pixel edge."""
    cv2 = _cv2()
    h, w = gray.shape
    out: List[Candidate] = []
    for sign in (-1.0, 1.0):
        body = (diff * sign > 4.0 * noise).astype(np.uint8)
        n, lab, st, cen = cv2.connectedComponentsWithStats(body, connectivity=8)
        for i in range(1, n):
            x0, y0, bw, bh, area = (int(v) for v in st[i])
            if not (0.5 * min_px ** 2 <= area <= max_px ** 2) or max(bw, bh) > 2.5 * min(bw, bh):
                continue
            if area < 0.6 * math.pi * bw * bh / 4:
                continue
            pts = _edge_points(gray, _moment_ellipse(lab, i, x0, y0, bw, bh))
            if pts is None:
                continue
            ell = cv2.fitEllipseDirect(pts.astype(np.float32))
            pts = _edge_points(gray, ell)
            if pts is None:
                continue
            ell = cv2.fitEllipseDirect(pts.astype(np.float32))
            misfit = _ellipse_misfit(pts, ell)
            if misfit > 0.06:
                continue  # not an ellipse: a square, a blot
            size = 0.5 * (ell[1][0] + ell[1][1])
            m = 0.8 * size
            cx, cy = ell[0]
            if cx < m or cy < m or cx > w - 1 - m or cy > h - 1 - m:
                continue
            out.append(Candidate(image, float(cx) + 0.5, float(cy) + 0.5, CIRCLE, float(size),
                                 float(max(0.0, 1.0 - misfit / 0.06))))
    return suppress(out)


# --------------------------------------------------------------------------------------------------
# ArUco / AprilTag
# --------------------------------------------------------------------------------------------------

def _side_line(gray: np.ndarray, a: np.ndarray, b: np.ndarray, inward: np.ndarray, reach: float):
    """The marker's border between corners ``a`` and ``b`` as a line fitted to its sub-pixel edge: the half-level
    crossing of profiles across the side (from ``reach`` outside to ``reach`` inside), over its middle 70 %."""
    t = np.linspace(0.15, 0.85, 15)
    base = a[None, :] + t[:, None] * (b - a)[None, :]
    u = np.linspace(-reach, reach, max(9, int(4 * reach)))
    xs = base[:, 0:1] + u[None, :] * inward[0]
    ys = base[:, 1:2] + u[None, :] * inward[1]
    prof = _sample(gray, xs, ys)
    if not np.all(np.isfinite(prof)):
        return None
    pts = []
    for k in range(len(t)):
        outside, inside = prof[k, : len(u) // 4].mean(), prof[k, -(len(u) // 4):].mean()
        level = 0.5 * (outside + inside)
        below = prof[k] < level if inside < outside else prof[k] > level
        j = int(np.argmax(below))
        if j == 0 or not below[j]:
            continue
        f0, f1 = prof[k, j - 1] - level, prof[k, j] - level
        f = f0 / (f0 - f1) if f0 != f1 else 0.5
        d = u[j - 1] + f * (u[j] - u[j - 1])
        pts.append(base[k] + d * inward)
    if len(pts) < 5:
        return None
    return _line_fit(np.array(pts), np.ones(len(pts)))


def refine_quad(gray: np.ndarray, quad: np.ndarray) -> Optional[np.ndarray]:
    """A marker's four corners (array coordinates) refined as the intersections of its four sides, each a line
    fitted to the sub-pixel edge (exact under perspective, unbiased by blur, unlike a corner detector)."""
    centre = quad.mean(0)
    size = math.sqrt(abs(_cv2().contourArea(quad.astype(np.float32))))
    reach = max(1.5, size / 14.0)  # about a third of a cell of a 4 x 4 code with its border
    lines = []
    for k in range(4):
        a, b = quad[k], quad[(k + 1) % 4]
        n = np.array([-(b - a)[1], (b - a)[0]]) / max(np.linalg.norm(b - a), 1e-9)
        if n @ (centre - 0.5 * (a + b)) < 0:
            n = -n
        line = _side_line(gray, a, b, n, reach)
        if line is None:
            return None
        lines.append(line)
    out = []
    for k in range(4):
        p = _intersect(lines[k - 1][0], lines[k - 1][1], lines[k][0], lines[k][1])
        if p is None:
            return None
        out.append(p)
    return np.array(out)


def find_markers(image: str, gray_u8: np.ndarray, dictionary: str) -> List[Candidate]:
    """Coded markers of an OpenCV dictionary; the centre is the intersection of the refined corners'
    diagonals."""
    cv2 = _cv2()
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    det = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)), params)
    corners, ids, _ = det.detectMarkers(gray_u8)
    h, w = gray_u8.shape
    out: List[Candidate] = []
    for c, code in zip(corners, [] if ids is None else ids.ravel()):
        q = c.reshape(4, 2).astype(float)
        size = math.sqrt(abs(cv2.contourArea(q.astype(np.float32))))
        m = 0.25 * size  # the white quiet zone round the marker must be in the photo too
        if q[:, 0].min() < m or q[:, 1].min() < m or q[:, 0].max() > w - 1 - m or q[:, 1].max() > h - 1 - m:
            continue
        refined = refine_quad(gray_u8.astype(np.float32), q)
        if refined is None:
            continue  # a side not clean all along: partly covered
        q = refined
        centre = _intersect(q[0], q[2] - q[0], q[1], q[3] - q[1])
        if centre is None:
            continue
        q_size = min(1.0, size / 24.0)  # cells under 4 px: the border's edges blur into the code
        out.append(Candidate(image, float(centre[0]) + 0.5, float(centre[1]) + 0.5, ARUCO, size, q_size, int(code)))
    return out


def detect_image(image: str, path: str, plain: Sequence[str], dictionaries: Sequence[str], min_px: float,
                 max_size_fraction: float) -> List[Candidate]:
    """Every candidate of the asked kinds on one photo (read grey).  A plain mark inside a coded marker (its
    cells make checkers) is dropped; where two plain kinds claim one mark the better quality stays."""
    cv2 = _cv2()
    from ..errors import GeorefError

    g8 = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if g8 is None:
        raise GeorefError(f"{path}: cannot read the photo")
    gray = g8.astype(np.float32)
    max_px = max_size_fraction * min(gray.shape)
    diff, noise = local_contrast(gray)
    coded: List[Candidate] = []
    for d in dictionaries:
        coded += find_markers(image, g8, d)
    plain_found: List[Candidate] = []
    if CROSS in plain:
        plain_found += find_crosses(image, gray, diff, noise, min_px, max_px)
    if CIRCLE in plain:
        plain_found += find_circles(image, gray, diff, noise, min_px, max_px)
    if CHECKERBOARD in plain:
        plain_found += find_checkers(image, gray, noise, min_px, max_px)
    plain_found = [c for c in plain_found
                   if all(math.hypot(c.x - m.x, c.y - m.y) > 0.75 * m.size_px for m in coded)]
    return coded + suppress(plain_found, 0.5)


def photo_paths(ws, rec) -> Dict[str, str]:
    """{name: path} of the workspace's photos registered in the model ``rec``."""
    reg = {rec.image(i).name for i in rec.reg_image_ids()}
    out = {}
    for im in ws.data.get("images", []):
        if im["name"] in reg:
            out[im["name"]] = im.get("path") or os.path.join(ws.data.get("images_dir") or "", im["name"])
    return out


def detect_all(photos: Dict[str, str], options: FindTargetsOptions,
               progress: Optional[Progress]) -> Dict[str, List[Candidate]]:
    """The candidates on every photo of ``photos`` ({name: path}), detected in parallel threads."""
    plain, dictionaries = options.kinds()
    threads = options.num_threads or os.cpu_count() or 1
    names = sorted(photos)
    out: Dict[str, List[Candidate]] = {}

    def one(n):
        return detect_image(n, photos[n], plain, dictionaries, options.min_size_px, options.max_size_fraction)

    with ThreadPoolExecutor(max_workers=threads) as pool:
        for k, (n, found) in enumerate(zip(names, pool.map(one, names))):
            out[n] = found
            if progress is not None:
                check_cancel(progress)
                progress.report(0.7 * (k + 1) / max(1, len(names)), f"looking for targets: {n}")
    return out
