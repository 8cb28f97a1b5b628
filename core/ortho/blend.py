"""Multi-band blending: Laplacian pyramids of the layers, and push-pull filling so pyramids see no holes."""
from __future__ import annotations

import math
from typing import List

import numpy as np

from ..common.errors import require


def multiband_blend(layers, fill_vals: np.ndarray, filled: np.ndarray, h: int, w: int, bands: int) -> np.ndarray:
    """Laplacian-pyramid blending of the layers (values, valid, weight) plus the hard fill."""
    cv2 = require("cv2", "orthophotos")

    levels = max(1, min(5, int(math.log2(max(2, min(h, w)))) - 3))
    items = list(layers)
    if filled.any():
        items.append((fill_vals, filled, filled.astype(np.float32)))
    if not items:
        return np.zeros((h * w, bands), dtype=np.float32)
    num = None
    den = None
    for vals, valid, wgt in items:
        img = _push_pull(vals.reshape(h, w, bands), valid.reshape(h, w), levels + 1)
        lap = _laplacian(img, levels)
        gw = [wgt.reshape(h, w).astype(np.float32)]
        for _ in range(levels):
            gw.append(cv2.pyrDown(gw[-1]))
        if num is None:
            num = [np.zeros_like(li) for li in lap]
            den = [np.zeros(g.shape, dtype=np.float32) for g in gw]
        for lv in range(levels + 1):
            num[lv] += lap[lv] * gw[lv][:, :, None]
            den[lv] += gw[lv]
    blended = [n_ / np.maximum(d_, 1e-6)[:, :, None] for n_, d_ in zip(num, den)]
    out = blended[-1]
    for lv in range(levels - 1, -1, -1):
        sz = (blended[lv].shape[1], blended[lv].shape[0])
        out = _pyr_up(out, sz) + blended[lv]
    return out.reshape(h * w, bands)


def _pyr_up(a: np.ndarray, size) -> np.ndarray:
    cv2 = require("cv2", "orthophotos")

    up = cv2.pyrUp(a, dstsize=size)
    return up if up.ndim == 3 else up[:, :, None]


def _pyr_down(a: np.ndarray) -> np.ndarray:
    cv2 = require("cv2", "orthophotos")

    d = cv2.pyrDown(a)
    return d if d.ndim == 3 else d[:, :, None]


def _laplacian(img: np.ndarray, levels: int) -> List[np.ndarray]:
    gp = [img]
    for _ in range(levels):
        gp.append(_pyr_down(gp[-1]))
    lp = []
    for lv in range(levels):
        size = (gp[lv].shape[1], gp[lv].shape[0])
        lp.append(gp[lv] - _pyr_up(gp[lv + 1], size))
    lp.append(gp[-1])
    return lp


def _push_pull(img: np.ndarray, valid: np.ndarray, levels: int) -> np.ndarray:
    """Fill invalid cells from valid neighbours at coarser scales (so pyramids see no dark holes)."""
    if valid.all():
        return img.astype(np.float32)
    wv = valid.astype(np.float32)
    pyr_v = [img.astype(np.float32) * wv[:, :, None]]
    pyr_w = [wv]
    for _ in range(levels + 4):
        if min(pyr_w[-1].shape) <= 2:
            break
        pyr_v.append(_pyr_down(pyr_v[-1]))
        pyr_w.append(_pyr_down(pyr_w[-1][:, :, None])[:, :, 0])
    est = pyr_v[-1] / np.maximum(pyr_w[-1], 1e-6)[:, :, None]
    for lv in range(len(pyr_v) - 2, -1, -1):
        size = (pyr_v[lv].shape[1], pyr_v[lv].shape[0])
        up = _pyr_up(est, size)
        wl = pyr_w[lv]
        here = pyr_v[lv] / np.maximum(wl, 1e-6)[:, :, None]
        a = np.clip(wl, 0.0, 1.0)[:, :, None]
        est = a * here + (1 - a) * up
    out = img.astype(np.float32).copy()
    out[~valid] = est[~valid]
    return out
