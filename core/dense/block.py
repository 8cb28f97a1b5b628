"""The block the DSM stage matches: the georeferenced model's views (their photos and masks found and checked),
its sparse points, the stereo pairs chosen among them and the DSM's cell size; DenseError saying why when the
block cannot make a DSM (fewer than two views, missing or changed photos, no stereo pair, an absurd RESOLUTION)."""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..align.photos import check_photos
from ..io.images import ImageError
from ..prepare.masks import find_mask
from ..project.layout import Layout
from .options import DenseError, DenseOptions
from .pairs import PairInfo, View, auto_resolution, median_gsd, select_pairs, sparse_points, views_from_reconstruction


@dataclass
class DenseBlock:
    """The views, sparse points and stereo pairs of a georeferenced model, and the DSM's cell size over them."""

    views: Dict[int, View]
    xyz: np.ndarray  # the sparse points, local frame
    pairs: List[PairInfo]
    candidates: int  # image pairs sharing tie points, among which ``pairs`` were chosen
    gsd: float  # the images' median ground sample distance (m)
    resolution: float  # the DSM's cell size: RESOLUTION, or automatic (pairs.auto_resolution)
    offset: np.ndarray  # of the local frame in the CRS
    crs: Optional[str]
    images_dir: str
    seconds: float  # spent choosing the pairs


def load_block(lay: Layout, options: DenseOptions, info: Callable[[str], None]) -> DenseBlock:
    """The block of the georeferenced workspace ``lay`` (notes on its photos go to ``info``); DenseError for one
    that cannot make a DSM with these options."""
    ws = lay.ws
    rec, frame = lay.load_georef_model()
    images_dir = ws.data.get("images_dir") or ""
    views = _views(lay, rec, images_dir)
    for note in _check_photos(lay, views):
        info(note)
    t0 = time.time()
    xyz, tracks = sparse_points(rec)
    pairs, stats = _pairs(views, xyz, tracks, options)
    gsd = median_gsd(views, xyz, tracks)
    auto = auto_resolution(gsd, options.scale)
    check_resolution(options.resolution, gsd, xyz, auto)
    return DenseBlock(views, xyz, pairs, stats["candidates"], gsd, options.resolution or auto, frame.offset,
                      frame.crs or ws.crs, images_dir, time.time() - t0)


def _views(lay: Layout, rec, images_dir: str) -> Dict[int, View]:
    """The model's views; DenseError for fewer than two or for images missing from ``images_dir``."""
    views = views_from_reconstruction(rec, images_dir)
    if len(views) < 2:
        raise DenseError(f"the model of {lay.root} has {len(views)} registered image(s): dense matching needs 2 or "
                         "more")
    for v in views.values():  # the sky masks (and any other): no dense point from their black pixels
        v.mask_path = find_mask(lay.masks_dir, v.name)
    missing = [v.name for v in views.values() if not os.path.isfile(v.path)]
    if missing:
        raise DenseError(f"{len(missing)} image(s) of the model are missing from {images_dir}: "
                         f"{', '.join(missing[:8])}{' ...' if len(missing) > 8 else ''}")
    return views


def _check_photos(lay: Layout, views: Dict[int, View]) -> List[str]:
    """The photos about to be matched against the alignment's (core.align.photos); DenseError naming the missing,
    unreadable or changed ones, notes for the log of an older workspace."""
    try:
        return check_photos(lay.ws, {v.name: v.path for v in views.values()})
    except ImageError as e:
        raise DenseError(str(e)) from e


MAX_DSM_CELLS = 50_000 * 50_000  # a RESOLUTION giving more cells over the block is refused before matching


def check_resolution(resolution: float, gsd: float, xyz: np.ndarray, auto: float) -> None:
    """DenseError, before any matching, for a RESOLUTION that cannot make a sensible DSM of this block: finer
    than a tenth of the ground sample distance, over MAX_DSM_CELLS cells, or under 2 cells across the block
    (its extent: the 1st to 99th percentile of the tie points)."""
    if not resolution or resolution <= 0 or len(xyz) == 0:
        return  # automatic
    res = float(resolution)
    hint = f"give 0 (automatic: {auto:.3g} m here)"
    if math.isfinite(gsd) and gsd > 0 and res < gsd / 10:
        raise DenseError(f"RESOLUTION {res:g} m is finer than a tenth of the images' ground sample distance "
                         f"({gsd:.3g} m): the photos hold no detail at that scale; {hint} or {gsd / 10:.3g} m or more")
    lo, hi = np.percentile(xyz[:, :2], [1, 99], axis=0)
    width, height = (float(v) for v in hi - lo)
    cols, rows = math.ceil(width / res) + 1, math.ceil(height / res) + 1
    if cols * rows > MAX_DSM_CELLS:
        raise DenseError(f"RESOLUTION {res:g} m would make a DSM of {cols:,} x {rows:,} cells over the block's "
                         f"{width:.0f} x {height:.0f} m (more than 50,000 x 50,000); {hint} or a coarser one")
    if res > max(width, height) / 2:
        raise DenseError(f"RESOLUTION {res:g} m is coarser than half the block's extent ({width:.0f} x {height:.0f} "
                         f"m): the DSM would have fewer than 2 cells across; {hint} or a finer one")


def _pairs(views: Dict[int, View], xyz: np.ndarray, tracks: Sequence[np.ndarray],
           options: DenseOptions) -> Tuple[List[PairInfo], Dict[str, int]]:
    """The stereo pairs and the selection's counts; DenseError saying why when no pair passes."""
    pairs, stats = select_pairs(views, xyz, tracks, options)
    if not pairs:
        raise DenseError(
            f"no stereo pair passed the selection among {len(views)} images ({stats['candidates']} image pairs share "
            f"tie points: {stats['few_shared_points']} with fewer than {options.min_shared_points} shared points, "
            f"{stats['baseline_too_short']} with a baseline under {options.min_baseline_ratio:g} x depth, "
            f"{stats['baseline_too_long']} over {options.max_baseline_ratio:g} x depth, {stats['view_angle']} with "
            f"views more than {options.max_view_angle:g} degrees apart). The images need stereo overlap (60 % or more "
            "along the strip) taken from different positions.")
    return pairs, stats
