"""A rough model -> world similarity from the photos' EXIF GPS: it narrows the constellation match.

The registered photos' centres (model frame) against their EXIF positions (longitude, latitude to the targets'
CRS; EXIF altitude as it is): a similarity (Umeyama) fitted robustly (the worst photos left out while they are
off by more than three times the others' RMS).  Its horizontal misfit (RMS over the photos kept) says how far
to trust it: a constellation hypothesis that puts a mark further from where the GPS puts it than three times that
misfit plus the match tolerance is not tried.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ...geometry.crs import transform_points
from ...geometry.similarity import Similarity, helmert_fit


@dataclass
class Prior:
    similarity: Similarity  # model -> world (the targets' CRS)
    rms_xy: float  # horizontal misfit of the photos kept (world units)
    photos: int


def gps_prior(ws, rec, crs: str) -> Optional[Prior]:
    """The EXIF GPS prior of the aligned block ``rec`` in ``crs``; None with fewer than 3 registered photos with
    GPS, or photos in a line."""
    gps = {im["name"]: im["gps"] for im in ws.data.get("images", []) if im.get("gps")}
    centres, pos = [], []
    for i in rec.reg_image_ids():
        im = rec.image(i)
        if im.name in gps:
            centres.append(np.asarray(im.projection_center(), dtype=float))
            pos.append(gps[im.name])
    if len(centres) < 3:
        return None
    lonlat = np.array([[g[0], g[1], 0.0] for g in pos], dtype=float)
    world = transform_points(lonlat, "EPSG:4326", crs)
    world[:, 2] = [g[2] for g in pos]
    src = np.array(centres)
    keep = np.ones(len(src), dtype=bool)
    for _ in range(5):
        try:
            sim = helmert_fit(src[keep], world[keep])
        except ValueError:
            return None
        err = np.linalg.norm(sim.apply(src)[:, :2] - world[:, :2], axis=1)
        rms = float(np.sqrt(np.mean(err[keep] ** 2)))
        bad = keep & (err > 3.0 * max(rms, 1e-9))
        if not bad.any() or keep.sum() - bad.sum() < 3:
            break
        keep &= ~bad
    return Prior(sim, rms, int(keep.sum()))
