"""Pair selection: which image pairs are matched (exhaustive, sequential + loop pairs, spatial by EXIF GPS).

- ``exhaustive``: every pair (n(n-1)/2);
- ``sequential``: each image with the next ``SEQUENTIAL_OVERLAP`` images in file
  order (flight order), plus vocabulary-free loop pairs: every image with
  every ``LOOP_STRIDE``-th image, which closes loops between strips (at most
  ``MAX_LOOP_ANCHORS`` such anchor images: the stride grows with the set, so the
  pair count grows linearly, not quadratically, with the number of images);
- ``spatial``: each image with its ``SPATIAL_NEIGHBOURS`` nearest neighbours by
  position (horizontal distance), plus a sequential overlap of 3 as a safety
  net; falls back to exhaustive with a warning when images lack a position;
- ``auto``: spatial when at least 80 % of the images have a position; otherwise
  exhaustive up to ``AUTO_EXHAUSTIVE_MAX`` images and sequential+loop beyond.

A photo's position (:func:`photo_positions`) is its row in a camera positions file where one is given
(``AlignOptions.camera_positions``: a GNSS log beside photos without EXIF GPS, in the georeference's format), else
its EXIF GPS.
"""
from __future__ import annotations

import math
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.crs import crs_is_geographic
from ..io.gcp import read_camera_positions
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


def photo_positions(images: Sequence[ImageInfo], camera_positions: Optional[str] = None
                    ) -> Dict[str, Tuple[float, float]]:
    """Image name -> horizontal position on a local plane (only distances between photos are used: metres for
    EXIF GPS and a geographic file, the file's own units for a projected one or one without a CRS line).  With
    ``camera_positions`` (a file :func:`core.io.gcp.read_camera_positions` reads; GCPError naming the file and
    line when it cannot) the file's rows for photos of ``images`` and nothing else: a file and EXIF GPS are not
    mixed, their frames differ.  AlignError when the file names none of the photos."""
    if not camera_positions:
        located = [im for im in images if im.gps]
        xy = gps_to_local_xy([im.gps for im in located]) if located else []
        return {im.name: (float(p[0]), float(p[1])) for im, p in zip(located, xy)}
    crs, rows = read_camera_positions(camera_positions, warnings=[])
    names = {im.name for im in images}
    rows = [r for r in rows if r.image in names]
    if not rows:
        some = ", ".join(sorted(names)[:3])
        raise AlignError(f"camera positions {camera_positions}: no row names a photo of the folder (photos such as "
                         f"{some}); the image column must hold the photos' file names")
    if crs and crs_is_geographic(crs):
        xy = gps_to_local_xy([(r.x, r.y, 0.0) for r in rows])
    else:
        xy = np.array([(r.x, r.y) for r in rows], dtype=float)
    return {r.image: (float(p[0]), float(p[1])) for r, p in zip(rows, xy)}


def select_pairs(images: Sequence[ImageInfo], pairing: str, spatial_neighbours: int = SPATIAL_NEIGHBOURS,
                 positions: Optional[Dict[str, Tuple[float, float]]] = None
                 ) -> Tuple[List[Tuple[str, str]], str, List[str]]:
    """Returns (pairs of image names, the pairing actually used, warnings).  ``positions``: the photos'
    horizontal positions (:func:`photo_positions`); None: their EXIF GPS."""
    pairing = (pairing or "auto").lower()
    if pairing not in PAIRINGS:
        raise AlignError(f"unknown pairing {pairing!r}; choose one of {', '.join(PAIRINGS)}")
    positions = photo_positions(images) if positions is None else positions
    warnings: List[str] = []
    n = len(images)
    names = [im.name for im in images]
    with_gps = sum(1 for im in images if im.name in positions)
    if pairing == "auto":
        if with_gps >= 0.8 * n and n > spatial_neighbours + 1:
            pairing = "spatial"
        elif with_gps >= 0.8 * n or n <= AUTO_EXHAUSTIVE_MAX:
            pairing = "exhaustive"
        else:
            pairing = "sequential"
    if pairing == "spatial" and with_gps < n:
        missing = [im.name for im in images if im.name not in positions]
        warnings.append(
            f"spatial pairing needs a position (EXIF GPS or a camera positions file) for every image; "
            f"{len(missing)} lack it "
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
        xy = np.array([positions[m] for m in names], dtype=float)
        d = np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=2)
        k = min(spatial_neighbours, n - 1)
        for i in range(n):
            for j in np.argsort(d[i])[1:k + 1]:
                add(i, int(j))
            for s in range(1, 4):
                if i + s < n:
                    add(i, i + s)
    return [(names[i], names[j]) for i, j in sorted(pairs)], pairing, warnings
