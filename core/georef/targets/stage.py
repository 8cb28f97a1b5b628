"""Find targets: the one entry point (``find_targets``) the Processing algorithm and the GCP dock call.

Surveyed coordinates in, sub-pixel observations out, no clicks:

1. candidates on every registered photo (``detect``), in parallel;
2. tied across photos by triangulation in the model frame (``tie``), the tolerance a multiple of the block's
   own reprojection error and of the detection's precision; a tie off the block's surface is dropped;
3. the triangulated marks matched to the surveyed constellation (``constellation``: a similarity from
   triplets, scale and mirror searched; coded targets carry their names, clicks in the targets file name the
   marks they fall on (``clicks``), both checked by the geometry; the photos' EXIF GPS narrows the search
   (``prior``));
4. every named target projected into every photo through the block (``found.predict``, with
   ``core.georef.guided.Predictor``: the heights of placeholder-Z surveys come from the tie points): the candidate
   at the projection joins, so a target seen in one photo only is found too;
5. each target re-triangulated from its observations (``found.observations``); an observation off the others by
   more than the tie tolerance, or (with TARGET_SIZE) of another size on the ground, is dropped.

Before any detection, ``checks`` refuses a targets file with no target or fewer than three (without codes or
clicks) and targets that land far from the photos' EXIF GPS (``core.io.control_place``, the georeference's check);
targets in degrees are matched in metres (``checks.metric_frame``) and written as given.  A run that finds no target
raises ``checks.nothing_found``, naming why (the marks' sizes against TARGET_SIZE, the kinds the photos show).

Everything that did not fit is in ``FindTargetsResult.reports`` (never assigned); each observation carries
its detector's quality, its residual and whether it was tied or projected (``FoundObservation``), each target
its status (``TargetStatus``; ``results``).

Products (``results.write_products``, paths from ``core.project.layout``): an OpenDroneMap gcp_list.txt (what
Georeference reads), a GeoPackage of the targets with what was found for review, and a JSON record with every
observation's quality.
"""
from __future__ import annotations

import math
import os
import time
from typing import List, Optional

import numpy as np

from ...common.progress import Progress
from ...geometry.crs import CRSError, linear_unit, unit_symbol
from ...project.layout import Layout
from ...project.workspace import Workspace
from ..errors import GeorefError
from .checks import check_location, code_names, metric_frame, nothing_found, read_targets, too_few
from .clicks import click_names, merge_names, unanswered
from .constellation import Marks, match_constellation
from .detect import detect_all, photo_paths
from .found import observations, predict
from .options import FindTargetsOptions
from .prior import Prior, gps_prior
from .results import TIED, FindTargetsResult, keep_clicks, write_products
from .tie import Track, on_surface, tie_candidates

__all__ = ["find_targets"]


def _prior(ws: Workspace, rec, crs: str, result: FindTargetsResult) -> Optional[Prior]:
    """The EXIF GPS prior, recorded in the result; None without GPS (or with GPS that the CRS cannot take,
    reported)."""
    try:
        prior = gps_prior(ws, rec, crs)
    except CRSError as e:
        result.reports.append(f"the photos' EXIF GPS not used: {e}")
        return None
    if prior is not None:
        result.prior = f"EXIF GPS of {prior.photos} photos, {prior.rms_xy:.3g} {unit_symbol(crs)} RMS"
    return prior


def find_targets(workspace: str, options: FindTargetsOptions, progress: Optional[Progress] = None
                 ) -> FindTargetsResult:
    """Find the surveyed targets ``options.targets`` (a CSV or gcp_list.txt of coordinates, pixel columns
    ignored) on the photos of the aligned ``workspace``; write the observations found (gcp_list.txt), the review
    layer and the record.  Targets that cannot be found (none in the file, fewer than three, far from the photos)
    are refused before any work, and a run that finds no target says why (GeorefError) rather than writing an
    empty file."""
    t0 = time.time()
    targets = options.targets
    if not targets:
        raise GeorefError("Find targets: no targets file given (the surveyed coordinates of the targets)")
    ws = Workspace.open(workspace)
    lay = Layout(ws)
    rec = lay.load_aligned_model()  # LayoutError: run 'Align images' first
    gs = read_targets(targets, options.crs)
    too_few(gs, targets, options)
    check_location(ws, gs, targets, options)
    out_path = os.path.abspath(options.output or lay.targets_gcp_list)
    if os.path.abspath(targets) == out_path:
        raise GeorefError(f"{targets}: the observations found would be written over the targets file; give "
                          "another output file")
    work = metric_frame(gs)  # the geometry in metres; the targets written as given
    unit = unit_symbol(work.crs)
    result = FindTargetsResult(gs.crs, out_path, os.path.abspath(options.layer or lay.targets_gpkg),
                               lay.targets_json, reports=list(gs.warnings))
    if work is not gs:
        result.reports.append(f"the targets are in {gs.crs} (degrees): matched in {work.crs} (metres), written as "
                              "given")
    photos = photo_paths(ws, rec)
    cands = detect_all(photos, options, progress)
    result.candidates = sum(len(v) for v in cands.values())
    mre = float(rec.compute_mean_reprojection_error()) if rec.num_points3D() else 0.5
    tol_px = 3.0 * math.hypot(mre, 0.5)  # the block's error and the detection's, both at three sigma
    result.tie_tolerance_px = tol_px
    tracks: List[Track] = [t for t in tie_candidates(rec, cands, tol_px) if on_surface(rec, t, tol_px)]
    result.marks = len(tracks)
    if progress is not None:
        progress.report(0.8, f"{result.candidates} candidate(s), {len(tracks)} tied across photos")
    names = [p.name for p in work.points]
    codes = code_names(names)
    clicks = {p.name: list(p.observations) for p in work.points if p.observations}
    zs = [p.z for p in work.points]
    xy_only = len(zs) >= 2 and max(zs) - min(zs) < 1e-6  # placeholder heights
    labels = merge_names([codes.get(t.code) if t.code is not None else None for t in tracks],
                         click_names(tracks, clicks, tol_px, result.reports), result.reports)
    prior = _prior(ws, rec, work.crs, result)
    marks = Marks(np.array([t.xyz for t in tracks]).reshape(-1, 3), labels, [len(t.candidates) for t in tracks])
    match = match_constellation(marks, np.array([[p.x, p.y, p.z] for p in work.points]), names, xy_only,
                                prior=prior.similarity if prior else None,
                                prior_tol=3.0 * prior.rms_xy if prior else 0.0, unit=unit)
    result.fit_tolerance, result.fit_rms, result.mirrored = match.tolerance, match.rms, match.mirrored
    result.reports += match.reports
    if match.similarity is None:  # no constellation: the clicked (or coded) marks keep the names they carry
        match.names = {i: n for i, n in enumerate(labels) if n is not None and labels.count(n) == 1}
    named = {match.names[i]: list(tracks[i].candidates) for i in match.names}
    sources = {id(c): TIED for v in named.values() for c in v}
    kinds = {match.names[i]: tracks[i].kind for i in match.names}
    found = predict(rec, work, named, cands, kinds, tol_px, result.reports)
    metres = linear_unit(work.crs)[1]
    result.observations, result.targets, size_dropped = observations(
        rec, work, found, sources, tol_px, match, options.target_size, metres if math.isfinite(metres) else 1.0)
    result.reports += [f"target {t.name}: {t.note}" for t in result.targets if t.found and t.note]
    given = {p.name: p for p in gs.points}
    for t in result.targets:  # the coordinates as given (the metric frame was for the geometry)
        t.x, t.y, t.z = given[t.name].x, given[t.name].y, given[t.name].z
    keep_clicks(result, unanswered(clicks, found, tol_px, result.reports))
    result.seconds = time.time() - t0
    if not any(o.found for o in result.observations):
        raise nothing_found(result, options, photos, size_dropped)
    write_products(gs, result)
    if progress is not None:
        progress.report(1.0, f"{result.n_targets} target(s), {result.n_observations} observation(s) found")
    return result
