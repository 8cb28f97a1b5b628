"""Similarity transforms (7-parameter Helmert): the type, least-squares and RANSAC fits, and small rotation helpers.

``Similarity`` is x' = scale * R @ x + t.  ``helmert_fit`` is the (weighted) Umeyama least-squares fit,
``helmert_ransac`` the robust one over minimal 3-point sets, ``fit_similarity`` the least-squares fit that can
ignore the target Z (unknown heights).  Pure numpy (scipy for the XY-only fit); pycolmap only to convert to a
``pycolmap.Sim3d``.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, Iterator, Optional, Tuple

import numpy as np

from ..common.errors import require


@dataclass
class Similarity:
    """x' = scale * R @ x + t."""

    scale: float = 1.0
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        self.scale = float(self.scale)
        self.rotation = np.asarray(self.rotation, dtype=float).reshape(3, 3)
        self.translation = np.asarray(self.translation, dtype=float).reshape(3)

    def apply(self, xyz) -> np.ndarray:
        xyz = np.asarray(xyz, dtype=float)
        return self.scale * xyz @ self.rotation.T + self.translation

    __call__ = apply

    def inverse(self) -> "Similarity":
        s = 1.0 / self.scale
        rt = self.rotation.T
        return Similarity(s, rt, -s * rt @ self.translation)

    def compose(self, other: "Similarity") -> "Similarity":
        """self after other: x -> self(other(x))."""
        return Similarity(self.scale * other.scale, self.rotation @ other.rotation,
                          self.scale * self.rotation @ other.translation + self.translation)

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.scale * self.rotation
        m[:3, 3] = self.translation
        return m

    def to_sim3d(self):
        pycolmap = require("pycolmap", "moving the sparse model")
        return pycolmap.Sim3d(self.scale, pycolmap.Rotation3d(self.rotation), self.translation)

    @classmethod
    def translation_only(cls, t) -> "Similarity":
        return cls(1.0, np.eye(3), t)

    def to_dict(self) -> Dict[str, Any]:
        return {"scale": self.scale, "rotation": self.rotation.tolist(),
                "translation": self.translation.tolist(), "matrix": self.matrix().tolist()}

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "Similarity":
        if "rotation" in d:
            return cls(d["scale"], d["rotation"], d["translation"])
        m = np.asarray(d["matrix"], dtype=float)
        s = float(np.cbrt(np.linalg.det(m[:3, :3])))
        return cls(s, m[:3, :3] / s, m[:3, 3])


@dataclass
class HelmertResult:
    transform: Similarity
    inliers: np.ndarray  # bool (N,)
    residuals: np.ndarray  # (N,) 3-D distance |dst - T(src)|
    residual_vectors: np.ndarray  # (N, 3) dst - T(src)

    def __iter__(self) -> Iterator[Any]:  # transform, inliers, residuals = helmert_ransac(...)
        yield self.transform
        yield self.inliers
        yield self.residuals


def helmert_fit(src, dst, weights=None) -> Similarity:
    """Least-squares similarity dst ~ s R src + t (Umeyama 1991), optionally weighted."""
    src = np.asarray(src, dtype=float).reshape(-1, 3)
    dst = np.asarray(dst, dtype=float).reshape(-1, 3)
    if len(src) != len(dst):
        raise ValueError(f"helmert_fit: {len(src)} source points but {len(dst)} target points")
    if len(src) < 3:
        raise ValueError(f"helmert_fit needs at least 3 points, got {len(src)}")
    w = np.ones(len(src)) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    if len(w) != len(src) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError("helmert_fit: weights must be non-negative, one per point, not all zero")
    w = w / w.sum()
    mu_s = w @ src
    mu_d = w @ dst
    a = src - mu_s
    b = dst - mu_d
    cov = (b * w[:, None]).T @ a
    u, d, vt = np.linalg.svd(cov)
    var_s = float(w @ np.sum(a * a, axis=1))
    if var_s <= 0 or d[1] <= 1e-12 * max(d[0], 1e-300):
        raise ValueError("helmert_fit: the points are coincident or collinear")
    sign = np.ones(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2] = -1.0
    r = (u * sign) @ vt
    s = float(np.sum(d * sign) / var_s)
    t = mu_d - s * r @ mu_s
    return Similarity(s, r, t)


def _non_degenerate(p: np.ndarray, min_ratio: float = 1e-3) -> bool:
    """Three points span a triangle whose area is not negligible against its longest side."""
    e1, e2 = p[1] - p[0], p[2] - p[0]
    longest = max(np.linalg.norm(e1), np.linalg.norm(e2), np.linalg.norm(p[2] - p[1]))
    if longest <= 0:
        return False
    return float(np.linalg.norm(np.cross(e1, e2))) > min_ratio * longest ** 2


def _draws_needed(inlier_ratio: float, confidence: float, sample: int = 3, floor: int = 50) -> int:
    """Random minimal samples after which one all-inlier sample has been drawn with ``confidence``:
    log(1 - confidence) / log(1 - w^sample) (Fischler & Bolles; Hartley & Zisserman 4.7), at least ``floor``."""
    p = min(max(inlier_ratio, 0.0), 1.0) ** sample
    if p >= 1.0:
        return floor
    if p <= 0.0:
        return 2 ** 31
    return max(floor, int(math.ceil(math.log(1.0 - confidence) / math.log(1.0 - p))))


def helmert_ransac(src, dst, threshold: float, max_iterations: int = 2000, seed: int = 0,
                   min_inliers: int = 3, weights=None, confidence: float = 0.9999) -> HelmertResult:
    """Robust similarity: RANSAC (MSAC score) over minimal 3-point sets + LO refit on the inliers.

    ``threshold`` is the largest 3-D distance (target units) at which a point counts
    as an inlier.  All 3-point sets are tried when there are at most
    ``max_iterations`` of them, random ones otherwise, until one all-inlier set has been drawn
    with ``confidence`` at the best inlier ratio found so far (at most ``max_iterations``; 1: all of them).
    """
    src = np.asarray(src, dtype=float).reshape(-1, 3)
    dst = np.asarray(dst, dtype=float).reshape(-1, 3)
    n = len(src)
    if n != len(dst):
        raise ValueError(f"helmert_ransac: {n} source points but {len(dst)} target points")
    if n < 3:
        raise ValueError(f"helmert_ransac needs at least 3 points, got {n}")
    if not threshold > 0:
        raise ValueError("helmert_ransac: threshold must be positive")
    thr2 = threshold ** 2

    def score(tr: Similarity) -> Tuple[float, np.ndarray]:
        r2 = np.sum((dst - tr.apply(src)) ** 2, axis=1)
        return float(np.minimum(r2, thr2).sum()), r2 < thr2

    exhaustive = math.comb(n, 3) <= max_iterations
    if exhaustive:
        samples: Iterable[Tuple[int, ...]] = itertools.combinations(range(n), 3)
    else:
        rng = np.random.default_rng(seed)
        samples = (tuple(rng.choice(n, 3, replace=False)) for _ in range(max_iterations))
    best: Optional[Tuple[float, np.ndarray]] = None
    needed = max_iterations
    for k, idx in enumerate(samples):
        if k >= needed:
            break  # random draws: enough for the inlier ratio found so far (the adaptive RANSAC bound)
        sel = list(idx)
        if not (_non_degenerate(src[sel]) and _non_degenerate(dst[sel])):
            continue
        try:
            tr = helmert_fit(src[sel], dst[sel])
        except ValueError:
            continue
        sc, inl = score(tr)
        if best is None or sc < best[0]:
            best = (sc, inl)
            if not exhaustive and confidence < 1.0:  # 1: every draw, as before the bound
                needed = min(max_iterations, _draws_needed(int(inl.sum()) / n, confidence))
    if best is None or best[1].sum() < max(3, min_inliers):
        found = 0 if best is None else int(best[1].sum())
        raise ValueError(f"helmert_ransac: no similarity fits {max(3, min_inliers)} of the {n} points "
                         f"within {threshold:g} (best: {found}); are the points collinear or wrong?")
    inliers = best[1]
    w = None if weights is None else np.asarray(weights, dtype=float)
    tr = Similarity()
    for _ in range(20):  # local optimisation: refit on the inliers until the set is stable
        tr = helmert_fit(src[inliers], dst[inliers], None if w is None else w[inliers])
        _, new = score(tr)
        if new.sum() < 3 or np.array_equal(new, inliers):
            break
        inliers = new
    vec = dst - tr.apply(src)
    return HelmertResult(tr, inliers.copy(), np.linalg.norm(vec, axis=1), vec)


def fit_similarity(src: np.ndarray, dst: np.ndarray, xy_only: bool = False) -> Tuple[Similarity, np.ndarray]:
    """Similarity and per-point residual distances; ``xy_only`` ignores the target Z (unknown heights)."""
    tr = helmert_fit(src, dst)
    if not xy_only:
        return tr, np.linalg.norm(dst - tr.apply(src), axis=1)
    from scipy.optimize import least_squares

    mu = src.mean(axis=0)
    sc = src - mu
    t0 = tr.apply(mu)

    def parts(v):
        r = rodrigues(v[1:4])[0] @ tr.rotation
        return math.exp(v[0]), r, np.array([v[4], v[5], t0[2]])

    def res(v):
        s_, r, t = parts(v)
        return (s_ * sc @ r.T + t)[:, :2].ravel() - dst[:, :2].ravel()

    v0 = np.r_[math.log(tr.scale), 0.0, 0.0, 0.0, t0[:2]]
    sol = least_squares(res, v0, method="trf")
    s_, r, t = parts(sol.x)
    tr2 = Similarity(s_, r, t - s_ * r @ mu)
    return tr2, np.linalg.norm(tr2.apply(src)[:, :2] - dst[:, :2], axis=1)


def rodrigues(w: np.ndarray) -> np.ndarray:
    """Rotation matrices (N,3,3) from rotation vectors (N,3)."""
    w = np.asarray(w, dtype=float).reshape(-1, 3)
    th = np.linalg.norm(w, axis=1)
    small = th < 1e-12
    k = w / np.where(small, 1.0, th)[:, None]
    kx = skew(k)
    s = np.sin(th)[:, None, None]
    c = (1 - np.cos(th))[:, None, None]
    r = np.eye(3)[None] + s * kx + c * (kx @ kx)
    if np.any(small):
        r[small] = np.eye(3)[None] + skew(w[small])
    return r


def skew(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float).reshape(-1, 3)
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], -1),
                     np.stack([v[:, 2], z, -v[:, 0]], -1),
                     np.stack([-v[:, 1], v[:, 0], z], -1)], axis=1)



__all__ = ["HelmertResult", "Similarity", "fit_similarity", "helmert_fit", "helmert_ransac", "rodrigues", "skew"]
