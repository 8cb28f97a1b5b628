"""What the alignment tells the user when photos are left out or nothing is built: per image why it is not
registered (``diagnose_unregistered``, ``report_unregistered``) and the error of a mapping that built nothing
(``no_reconstruction_error``: no overlap, no initial pair, or a held calibration that is wrong)."""
from __future__ import annotations

import os
from typing import Dict, Optional, Sequence, Set

from ..common.progress import Progress
from ..io.images import ImageInfo
from .calibrated import GivenCamera
from .options import MIN_VERIFIED_INLIERS, AlignError


def diagnose_unregistered(infos: Sequence[ImageInfo], registered: Set[str], others: Sequence[Sequence[str]],
                          partners: Dict[str, int], degenerate: Optional[Dict[str, str]] = None) -> Dict[str, str]:
    """Why each image outside the main block is not registered: image -> reason.  ``degenerate``: the images
    de-registered for a degenerate camera (mapping.drop_degenerate), with why."""
    in_other = {n: k for k, comp in enumerate(others, start=2) for n in comp}
    unregistered: Dict[str, str] = {}
    for im in infos:
        if im.name in registered:
            continue
        if im.name in in_other:
            k = in_other[im.name]
            unregistered[im.name] = (f"in a separate component (#{k}, {len(others[k - 2])} images) that "
                                     "shares too few matches with the main block")
        elif im.name in (degenerate or {}):
            unregistered[im.name] = f"matched {partners.get(im.name, 0)} image(s) but {degenerate[im.name]}"
        elif partners.get(im.name, 0) == 0:
            unregistered[im.name] = "no verified matches with any other image (no overlap, blur or too little texture)"
        else:
            unregistered[im.name] = (f"matched {partners[im.name]} image(s) but could not be registered "
                                     "(too few 2D-3D correspondences)")
    return unregistered


def report_unregistered(progress: Progress, unregistered: Dict[str, str], others: Sequence[Sequence[str]],
                         n_registered: int) -> None:
    for n, why in unregistered.items():
        progress.warning(f"not registered: {n}: {why}")
    if others:
        progress.warning(
            f"the images form {len(others) + 1} separate components; kept the largest ({n_registered} "
            "images); others: " + "; ".join(f"#{k}: {', '.join(c)}" for k, c in enumerate(others, start=2))
        )


def no_reconstruction_error(partners: Dict[str, int], n_images: int, n_pairs: int,
                       held: Optional[Dict[int, GivenCamera]] = None) -> AlignError:
    """The error of a mapping that built nothing; ``held``: the cameras whose given interior orientation the
    mapping held (a wrong calibration makes every initial pair fail too, which the message then says)."""
    isolated = [n for n, c in partners.items() if c == 0]
    if isolated:
        return AlignError(
            "no reconstruction could be built: the images do not overlap enough. "
            f"{len(isolated)} of {n_images} images share no verified matches with any other image"
            f" ({', '.join(isolated[:10])}{' ...' if len(isolated) > 10 else ''})")
    calibration = ""
    if held:
        cams = "; ".join(f"camera {cid}: focal {g.params[0]:.1f} px from {os.path.basename(g.source)}"
                         for cid, g in sorted(held.items()))
        calibration = (f". The interior orientation was held as given ({cams}): a wrong focal length, pixel size "
                       "or image size in the calibration also leaves no pair to triangulate; check it, or run with "
                       "Interior orientation 'estimated' to see what the photos say")
    return AlignError(
        f"no reconstruction could be built: every one of the {n_images} images shares verified matches "
        f"({n_pairs} image pair(s) with {MIN_VERIFIED_INLIERS} or more inliers), but the mapper found no initial "
        "pair it could triangulate (baseline too short for the distance, e.g. photos taken from one spot, or "
        "matches on a repeated pattern); add photos taken from other positions" + calibration)


__all__ = ["diagnose_unregistered", "no_reconstruction_error", "report_unregistered"]
