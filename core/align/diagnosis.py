"""What the alignment tells the user when photos are left out or nothing is built: per image why it is not
registered (``diagnose_unregistered``, ``report_unregistered``) and the error of a mapping that built nothing
(``no_reconstruction_error``: no overlap, no initial pair, or a held calibration that is wrong)."""
from __future__ import annotations

from typing import Dict, Optional, Sequence, Set, Tuple

from ..common.progress import Progress
from ..io.images import ImageInfo
from .calibrated import GivenCamera, source_label
from .options import MIN_VERIFIED_INLIERS, AlignError


def component_link(component: Sequence[str], registered: Set[str], links: Sequence[Tuple[str, str]]) -> str:
    """How a separate ``component`` is tied to the main block (``registered``) by the verified pairs ``links``:
    the words that follow "in a separate component (...)".  Incremental mapping carries a block on from photo to
    photo through points seen by three photos: a photo of the component with verified pairs to two photos of the
    block that are themselves a verified pair (a *triple*) can join it; where the component meets the block only
    in pairs (seneca_south: forward overlap of 52-74 % between neighbours, so two photos apart overlap 15-46 % on
    the ground, and there on bare field), no point of the block is seen by a photo of the component and the
    block splits there (docs/notes_issue46_align.md)."""
    comp, main = set(component), set(registered)
    adj: Dict[str, Set[str]] = {}
    for a, b in links:
        adj.setdefault(a, set()).add(b)
        adj.setdefault(b, set()).add(a)
    across = sorted({(a, b) if a in comp else (b, a) for a, b in links
                     if (a in comp and b in main) or (b in comp and a in main)})
    if not across:
        return "that shares no verified pair with the main block (no common ground matched)"
    shown = ", ".join(f"{a}-{b}" for a, b in across[:4]) + (" ..." if len(across) > 4 else "")
    for a, b in across:  # a triple: a pair across closed by a third photo (of either side) matched with both
        third = sorted((adj.get(a, set()) & adj.get(b, set())) - {a, b})
        if third:
            return (f"that shares {len(across)} verified pair(s) with the main block ({shown}) and photo triples "
                    f"({a}, {b}, {third[0]}), but too few points seen by three photos to join it")
    return (f"that meets the main block only in pairs ({len(across)} verified: {shown}): no three photos "
            "across it match each other, so no point is seen by three photos (forward overlap under half a "
            "frame on common ground with too little texture)")


def diagnose_unregistered(infos: Sequence[ImageInfo], registered: Set[str], others: Sequence[Sequence[str]],
                          partners: Dict[str, int], degenerate: Optional[Dict[str, str]] = None,
                          links: Optional[Sequence[Tuple[str, str]]] = None) -> Dict[str, str]:
    """Why each image outside the main block is not registered: image -> reason.  ``degenerate``: the images
    de-registered for a degenerate camera (mapping.drop_degenerate), with why.  ``links``: the verified pairs
    (mapping.verified_links); with them a separate component's reason says how it meets the main block
    (:func:`component_link`)."""
    in_other = {n: k for k, comp in enumerate(others, start=2) for n in comp}
    unregistered: Dict[str, str] = {}
    for im in infos:
        if im.name in registered:
            continue
        if im.name in in_other:
            k = in_other[im.name]
            how = ("that shares too few matches with the main block" if links is None
                   else component_link(others[k - 2], registered, links))
            unregistered[im.name] = f"in a separate component (#{k}, {len(others[k - 2])} images) {how}"
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
        cams = "; ".join(f"camera {cid}: focal {g.params[0]:.1f} px from {source_label(g.source)}"
                         for cid, g in sorted(held.items()))
        calibration = (f". The interior orientation was held as given ({cams}): a wrong focal length, pixel size "
                       "or image size in the calibration also leaves no pair to triangulate; check it, or run with "
                       "Interior orientation 'estimated' to see what the photos say")
    return AlignError(
        f"no reconstruction could be built: every one of the {n_images} images shares verified matches "
        f"({n_pairs} image pair(s) with {MIN_VERIFIED_INLIERS} or more inliers), but the mapper found no initial "
        "pair it could triangulate (baseline too short for the distance, e.g. photos taken from one spot, or "
        "matches on a repeated pattern); add photos taken from other positions" + calibration)


__all__ = ["component_link", "diagnose_unregistered", "no_reconstruction_error", "report_unregistered"]
