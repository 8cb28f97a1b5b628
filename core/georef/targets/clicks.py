"""The user's clicks in a targets file (a gcp_list.txt with some pixel columns): names for the marks they fall on.

A click names the tracked mark that has a candidate within reach of it in the clicked photo (the larger of twice
the tie tolerance and a third of the mark's size), like a coded target's code: the constellation match then
checks it against the geometry (a click on the wrong target is reported, never followed).  Clicks that no mark
found answers stay in the output as the user's observations.
"""
from __future__ import annotations

import math
from typing import Dict, List, Optional, Sequence

from ...io.gcp import Observation
from .tie import Track


def _near(c, ob: Observation, tol_px: float) -> bool:
    return c.image == ob.image and math.hypot(c.x - ob.x, c.y - ob.y) <= max(2.0 * tol_px, c.size_px / 3.0)


def click_names(tracks: Sequence[Track], clicks: Dict[str, List[Observation]], tol_px: float,
                reports: List[str]) -> List[Optional[str]]:
    """Per track, the target its clicks name (None: no click on it, or clicks of two targets, reported)."""
    out: List[Optional[str]] = []
    for t in tracks:
        hit = sorted({n for n, obs in clicks.items() for ob in obs for c in t.candidates if _near(c, ob, tol_px)})
        if len(hit) > 1:
            reports.append(f"one mark carries clicks of {', '.join(hit)}: the clicks do not name it")
        out.append(hit[0] if len(hit) == 1 else None)
    return out


def merge_names(coded: Sequence[Optional[str]], clicked: Sequence[Optional[str]],
                reports: List[str]) -> List[Optional[str]]:
    """A track's name from its code and its clicks: one of them, or the same from both; two that differ name
    nothing (reported)."""
    out: List[Optional[str]] = []
    for a, b in zip(coded, clicked):
        if a is not None and b is not None and a != b:
            reports.append(f"a mark coded {a} is clicked as {b}: neither names it")
            out.append(None)
        else:
            out.append(a if a is not None else b)
    return out


def unanswered(clicks: Dict[str, List[Observation]], found: Dict[str, list], tol_px: float,
               reports: List[str]) -> Dict[str, List[Observation]]:
    """The clicks no mark found in their photo answers: kept as the user's observations.  A click on the mark found
    for another target, or away from the mark found for its own in that photo, is reported and left out."""
    out: Dict[str, List[Observation]] = {}
    for n, obs in clicks.items():
        for ob in obs:
            same = [c for c in found.get(n, []) if c.image == ob.image]
            if any(_near(c, ob, tol_px) for c in same):
                continue
            other = sorted({m for m, cs in found.items() if m != n for c in cs if _near(c, ob, tol_px)})
            if other:
                reports.append(f"the click of {n} in {ob.image} is on the mark of {', '.join(other)}: left out")
                continue
            if same:
                d = min(math.hypot(c.x - ob.x, c.y - ob.y) for c in same)
                reports.append(f"the click of {n} in {ob.image} is {d:.0f} px from the mark found there: the mark "
                               "is kept")
                continue
            out.setdefault(n, []).append(ob)
    return out
