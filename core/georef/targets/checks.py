"""Find targets' checks of its input and its outcome (issue 47): what is refused before any detection (a targets
file with no target or fewer than three, targets that land far from the photos), the metric frame targets in
degrees are matched in, and why a run that found nothing found nothing (``nothing_found``)."""
from __future__ import annotations

import dataclasses
import os
import re
from typing import Dict, List, Optional, Sequence

import numpy as np

from ...geometry.crs import crs_is_geographic, normalize_crs, transform_points, utm_epsg_for_lonlat
from ...io import gcp as gcpmod
from ...io.control_place import points_off, usable_gps
from ...project.workspace import Workspace
from ..errors import GeorefError
from .detect import detect_all
from .options import ARUCO, AUTO, DEFAULT_DICTIONARY, DICTIONARIES, FindTargetsOptions
from .results import FindTargetsResult


def code_names(names: Sequence[str]) -> Dict[int, str]:
    """{code: target name} for coded targets: a name that is the code or ends in it (``12``, ``T12``, ``aruco_12``),
    where one name only claims the code."""
    claims: Dict[int, List[str]] = {}
    for n in names:
        m = re.search(r"(\d+)$", n)
        if m:
            claims.setdefault(int(m.group(1)), []).append(n)
    return {k: v[0] for k, v in claims.items() if len(v) == 1}


_NOT_OF_TARGETS = ("no observations file", "no usable observation")  # the GCP reader's notes, moot for targets


def read_targets(path: str, crs: Optional[str]) -> gcpmod.GCPSet:
    """The surveyed targets (``gcp.read_target_coordinates``); a file with no target (a header only) is refused,
    and a reader's error keeps none of the GCP reader's notes about observations (a targets file has none)."""
    try:
        gs = gcpmod.read_target_coordinates(path, crs)
    except gcpmod.GCPError as e:
        lines = str(e).splitlines()
        kept = [ln for ln in lines if not any(n in ln for n in _NOT_OF_TARGETS)]
        if len(kept) == len(lines):
            raise
        if kept and kept[-1].startswith("warnings while reading"):
            kept.pop()
        raise type(e)("\n".join(kept)) from e
    if not gs.points:
        raise GeorefError(f"Find targets: {path} holds no target (a header, no row of coordinates): give one row per "
                          "surveyed target (name,x,y,z)")
    return gs


def too_few(gs: gcpmod.GCPSet, path: str, options: FindTargetsOptions) -> None:
    """GeorefError, before any work, for fewer than three targets that neither a code nor a click can name: the
    marks are named by matching the shape of the targets (a triangle at least), and Georeference needs three."""
    if len(gs.points) >= 3:
        return
    coded = options.kind in DICTIONARIES and code_names([p.name for p in gs.points])
    if coded or any(p.observations for p in gs.points):
        return
    raise GeorefError(f"Find targets: {path} holds {len(gs.points)} target(s) "
                      f"({', '.join(p.name for p in gs.points)}): the marks found are named by matching the shape of "
                      "the surveyed targets, which needs three or more (and Georeference needs three control points); "
                      "give three or more targets, or coded targets (TARGET_KIND: an ArUco dictionary, names ending "
                      "in their codes) or clicks in the file")


def check_location(ws: Workspace, gs: gcpmod.GCPSet, path: str, options: FindTargetsOptions) -> None:
    """GeorefError when the targets land far from where the photos' EXIF GPS puts them (without GPS: outside
    their CRS's area of use), naming the likely cause (swapped axes, another CRS's numbers): the check the
    georeference makes of its control (``core.io.control_place.points_off``), one check in one place."""
    gps = usable_gps((im["name"], im.get("gps")) for im in ws.data.get("images", []))
    labelled = not options.crs or gs.crs != normalize_crs(options.crs)  # the CRS is the file's, not the parameter's
    what = points_off(gps, gs.points, gs.crs, gs.crs, f"the targets file {path}", labelled)
    if what:
        raise GeorefError(f"Find targets: {what}")


def metric_frame(gs: gcpmod.GCPSet) -> gcpmod.GCPSet:
    """The targets in a CRS of metres: as they are, unless geographic (degrees, whose east and north units differ:
    no shape survives them), then in the UTM zone of their centre."""
    if not crs_is_geographic(gs.crs):
        return gs
    lonlat = np.array([[p.x, p.y] for p in gs.points], dtype=float)
    utm = f"EPSG:{utm_epsg_for_lonlat(float(np.mean(lonlat[:, 0])), float(np.mean(lonlat[:, 1])))}"
    xy = transform_points(lonlat, gs.crs, utm)
    return gcpmod.GCPSet(utm, [dataclasses.replace(p, x=float(q[0]), y=float(q[1])) for p, q in zip(gs.points, xy)],
                         source=gs.source)


def other_kinds(photos: Dict[str, str], options: FindTargetsOptions, sample: int = 8) -> str:
    """What marks a few photos (evenly spread) show of every kind, for a kind that found nothing: "cross 14,
    checkerboard 1" and the kind to try ('' when they show no other kind more than the one asked for); the coded
    markers looked for are the default dictionary's."""
    names = sorted(photos)
    pick = names[::max(1, len(names) // sample)][:sample]
    every = FindTargetsOptions(kind=AUTO, min_size_px=options.min_size_px,
                               max_size_fraction=options.max_size_fraction, num_threads=options.num_threads)
    counts: Dict[str, int] = {}
    for found in detect_all({n: photos[n] for n in pick}, every, None).values():
        for c in found:
            counts[c.kind] = counts.get(c.kind, 0) + 1
    ranked = sorted(counts.items(), key=lambda kv: -kv[1])
    if not ranked or ranked[0][0] == (ARUCO if options.kind == DEFAULT_DICTIONARY else options.kind):
        return ""  # the photos show no other kind more than this one: the kind is not what failed
    kinds = ", ".join(f"{k} {n}" for k, n in ranked)
    best = DEFAULT_DICTIONARY if ranked[0][0] == ARUCO else ranked[0][0]
    return (f"the photos show other marks ({len(pick)} of them looked at with every kind: {kinds}): "
            f"TARGET_KIND={best} (or auto)?")


def nothing_found(result: FindTargetsResult, options: FindTargetsOptions, photos: Dict[str, str],
                   size_dropped: List[float]) -> GeorefError:
    """The error for a run that found no target, naming why: the marks' sizes against TARGET_SIZE, the kind
    against what the photos show, else what was found and what did not fit."""
    what = (f"{result.candidates} candidate mark(s) of kind {options.kind} on {len(photos)} photos, "
            f"{result.marks} tied across photos")
    if size_dropped:
        why = (f"the {len(size_dropped)} mark(s) found measure {float(np.median(size_dropped)):.2g} m on the ground "
               f"(median; {min(size_dropped):.2g} to {max(size_dropped):.2g} m), unlike TARGET_SIZE "
               f"{options.target_size:g} m: give the targets' side (or diameter) in metres, or 0 when unknown")
    else:
        other = other_kinds(photos, options) if options.kind != AUTO and result.marks < 3 else ""
        why = (f"TARGET_KIND={options.kind}: {other}" if other else
               "; ".join(result.reports) or "no mark fits the surveyed targets")
    return GeorefError(f"Find targets: no target found in {os.path.basename(options.targets or '')} ({what}): {why}")
