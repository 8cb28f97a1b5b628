"""Pair selection: which image pairs are matched (exhaustive, sequential + loop pairs, spatial by EXIF GPS).

- ``exhaustive``: every pair (n(n-1)/2);
- ``sequential``: each image with the next ``SEQUENTIAL_OVERLAP`` images in file
  order (flight order), plus vocabulary-free loop pairs: every image with
  every ``LOOP_STRIDE``-th image, which closes loops between strips (at most
  ``MAX_LOOP_ANCHORS`` such anchor images: the stride grows with the set, so the
  pair count grows linearly, not quadratically, with the number of images);
- ``spatial``: each image with its ``SPATIAL_NEIGHBOURS`` nearest neighbours by
  EXIF GPS (horizontal distance), plus a sequential overlap of 3 as a safety
  net; falls back to exhaustive with a warning when images lack GPS;
- ``auto``: spatial when at least 80 % of the images carry GPS; otherwise
  exhaustive up to ``AUTO_EXHAUSTIVE_MAX`` images and sequential+loop beyond.
"""
from __future__ import annotations

import math
from typing import List, Sequence, Tuple

import numpy as np

from ..io.images import ImageInfo
from .options import (
    AUTO_EXHAUSTIVE_MAX,
    LOOP_STRIDE,
    MAX_LOOP_ANCHORS,
    PAIRINGS,
    SEQUENTIAL_OVERLAP,
    SPATIAL_NEIGHBOURS,
    AlignError,
)


def gps_to_local_xy(gps: Sequence[Tuple[float, float, float]]) -> np.ndarray:
    """EXIF lon/lat to a local metric plane around their mean (enough for neighbour search)."""
    a = np.asarray(gps, dtype=float)
    lon0, lat0 = a[:, 0].mean(), a[:, 1].mean()
    x = (a[:, 0] - lon0) * 111320.0 * math.cos(math.radians(lat0))
    y = (a[:, 1] - lat0) * 110540.0
    return np.column_stack([x, y])


def select_pairs(images: Sequence[ImageInfo], pairing: str,
                 spatial_neighbours: int = SPATIAL_NEIGHBOURS) -> Tuple[List[Tuple[str, str]], str, List[str]]:
    """Returns (pairs of image names, the pairing actually used, warnings)."""
    pairing = (pairing or "auto").lower()
    if pairing not in PAIRINGS:
        raise AlignError(f"unknown pairing {pairing!r}; choose one of {', '.join(PAIRINGS)}")
    warnings: List[str] = []
    n = len(images)
    names = [im.name for im in images]
    with_gps = sum(1 for im in images if im.gps)
    if pairing == "auto":
        if with_gps >= 0.8 * n and n > spatial_neighbours + 1:
            pairing = "spatial"
        elif with_gps >= 0.8 * n or n <= AUTO_EXHAUSTIVE_MAX:
            pairing = "exhaustive"
        else:
            pairing = "sequential"
    if pairing == "spatial" and with_gps < n:
        missing = [im.name for im in images if not im.gps]
        warnings.append(
            f"spatial pairing needs EXIF GPS on every image; {len(missing)} lack it "
            f"({', '.join(missing[:5])}{'…' if len(missing) > 5 else ''}): falling back to exhaustive"
        )
        pairing = "exhaustive"
    pairs = set()

    def add(i, j):
        if i != j:
            pairs.add((min(i, j), max(i, j)))

    if pairing == "exhaustive":
        for i in range(n):
            for j in range(i + 1, n):
                add(i, j)
    elif pairing == "sequential":
        stride = max(LOOP_STRIDE, -(-n // MAX_LOOP_ANCHORS))
        for i in range(n):
            for k in range(1, SEQUENTIAL_OVERLAP + 1):
                if i + k < n:
                    add(i, i + k)
            for j in range(0, n, stride):
                add(i, j)
    else:  # spatial
        xy = gps_to_local_xy([im.gps for im in images])
        d = np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=2)
        k = min(spatial_neighbours, n - 1)
        for i in range(n):
            for j in np.argsort(d[i])[1:k + 1]:
                add(i, int(j))
            for s in range(1, 4):
                if i + s < n:
                    add(i, i + s)
    return [(names[i], names[j]) for i, j in sorted(pairs)], pairing, warnings
