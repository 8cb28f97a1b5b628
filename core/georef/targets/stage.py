"""Find targets: the one entry point (``find_targets``) the Processing algorithm and the GCP dock call.

Surveyed coordinates in, sub-pixel observations out, no clicks:

1. candidates on every registered photo (``detect``), in parallel;
2. tied across photos by triangulation in the model frame (``tie``), the tolerance a multiple of the block's
   own reprojection error and of the detection's precision; a tie off the block's surface is dropped;
3. the triangulated marks matched to the surveyed constellation (``constellation``: a similarity from
   triplets, scale and mirror searched; coded targets carry their names, clicks in the targets file name the
   marks they fall on (``clicks``), both checked by the geometry; the photos' EXIF GPS narrows the search
   (``prior``));
4. every named target projected into every photo through the block (``core.georef.guided.Predictor``: the
   heights of placeholder-Z surveys come from the tie points): the candidate at the projection joins, so a
   target seen in one photo only is found too;
5. each target re-triangulated from its observations; an observation off the others by more than the tie
   tolerance, or (with TARGET_SIZE) of another size on the ground, is dropped.

Everything that did not fit is in ``FindTargetsResult.reports`` (never assigned); each observation carries
its detector's quality, its residual and whether it was tied or projected (``FoundObservation``), each target
its status (``TargetStatus``).

Products (``core.project.layout``): an OpenDroneMap gcp_list.txt (what Georeference reads), a GeoPackage of the
targets with what was found for review, and a JSON record with every observation's quality.
"""
from __future__ import annotations

import math
import os
import re
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence

import numpy as np

from ...common.progress import Progress, check_cancel
from ...geometry.crs import CRSError
from ...io import gcp as gcpmod
from ...project.layout import Layout, write_json
from ...project.workspace import Workspace
from ..errors import GeorefError
from ..guided import Predictor
from ..triangulate import triangulate_observations
from .clicks import click_names, merge_names, unanswered
from .constellation import Constellation, match_constellation
from .detect import Candidate, detect_image
from .options import FindTargetsOptions
from .prior import Prior, gps_prior
from .tie import Track, on_surface, tie_candidates

TIED = "tied"  # the observation's mark was tied across photos and matched to the constellation
PROJECTED = "projected"  # found at the target's projection through the block
CLICK = "click"  # the user's click in the targets file, which no mark found answers


@dataclass
class FoundObservation:
    """One observation found: pixel (COLMAP convention), the detector's quality in [0, 1], the residual (px) of the
    target's triangulation (NaN when it is the target's only observation) and how it was found."""

    name: str
    image: str
    x: float
    y: float
    kind: str
    quality: float
    residual_px: float
    size_px: float
    source: str
    found: bool = True  # found by the machine, not placed by hand (the dock's mark)
    size_m: Optional[float] = None  # the mark's size on the ground (world units), through the constellation's scale


@dataclass
class TargetStatus:
    name: str
    x: float
    y: float
    z: float
    found: bool
    observations: int
    fit: Optional[float] = None  # distance (world units) of its mark from it after the constellation fit
    note: str = ""


@dataclass
class FindTargetsResult:
    crs: str
    gcps_path: str
    layer_path: str
    json_path: str
    observations: List[FoundObservation] = field(default_factory=list)
    targets: List[TargetStatus] = field(default_factory=list)
    candidates: int = 0
    marks: int = 0  # tracks triangulated in the block
    tie_tolerance_px: float = 0.0
    fit_tolerance: float = 0.0
    fit_rms: float = float("nan")
    mirrored: bool = False
    prior: str = ""  # what narrowed the match ("EXIF GPS of n photos, x RMS"), empty without
    reports: List[str] = field(default_factory=list)  # what did not fit, never assigned
    seconds: float = 0.0

    @property
    def n_targets(self) -> int:
        return sum(1 for t in self.targets if t.found)

    @property
    def n_observations(self) -> int:
        return len(self.observations)

    def gcpset(self) -> gcpmod.GCPSet:
        pts = []
        for t in self.targets:
            obs = [gcpmod.Observation(o.image, o.x, o.y) for o in self.observations if o.name == t.name]
            if obs:
                pts.append(gcpmod.GroundPoint(t.name, t.x, t.y, t.z, observations=obs, sigma_given=False))
        return gcpmod.GCPSet(self.crs, pts)

    def to_dict(self) -> Dict:
        d = asdict(self)
        d["n_targets"], d["n_observations"] = self.n_targets, self.n_observations
        return d


def code_names(names: Sequence[str]) -> Dict[int, str]:
    """{code: target name} for coded targets: a name that is the code or ends in it (``12``, ``T12``, ``aruco_12``),
    where one name only claims the code."""
    claims: Dict[int, List[str]] = {}
    for n in names:
        m = re.search(r"(\d+)$", n)
        if m:
            claims.setdefault(int(m.group(1)), []).append(n)
    return {k: v[0] for k, v in claims.items() if len(v) == 1}


def _photos(ws: Workspace, rec) -> Dict[str, str]:
    reg = {rec.image(i).name for i in rec.reg_image_ids()}
    out = {}
    for im in ws.data.get("images", []):
        if im["name"] in reg:
            out[im["name"]] = im.get("path") or os.path.join(ws.data.get("images_dir") or "", im["name"])
    return out


def _detect_all(photos: Dict[str, str], options: FindTargetsOptions,
                progress: Optional[Progress]) -> Dict[str, List[Candidate]]:
    plain, dictionaries = options.kinds()
    threads = options.num_threads or os.cpu_count() or 1
    names = sorted(photos)
    out: Dict[str, List[Candidate]] = {}

    def one(n):
        return detect_image(n, photos[n], plain, dictionaries, options.min_size_px, options.max_size_fraction)

    with ThreadPoolExecutor(max_workers=threads) as pool:
        for k, (n, found) in enumerate(zip(names, pool.map(one, names))):
            out[n] = found
            if progress is not None:
                check_cancel(progress)
                progress.report(0.7 * (k + 1) / max(1, len(names)), f"looking for targets: {n}")
    return out


def _predict(rec, gs: gcpmod.GCPSet, named: Dict[str, List[Candidate]], cands: Dict[str, List[Candidate]],
             kinds: Dict[str, str], tol_px: float, reports: List[str]) -> Dict[str, List[Candidate]]:
    """Every target projected into every photo; the free candidate at the projection joins its target."""
    seed = gcpmod.GCPSet(gs.crs, [gcpmod.GroundPoint(p.name, p.x, p.y, p.z, sigma_given=False,
                                                     observations=[gcpmod.Observation(c.image, c.x, c.y)
                                                                   for c in named.get(p.name, [])])
                                  for p in gs.points])
    if sum(1 for p in seed.points if len(p.observations) >= 2) < 3:
        return named
    try:
        pred = Predictor(rec, max_ray_error_px=tol_px).predict(seed)
    except GeorefError as e:
        reports.append(f"no projection of the targets into the photos: {e}")
        return named
    taken = {(c.image, round(c.x, 3), round(c.y, 3)) for v in named.values() for c in v}
    out = {k: list(v) for k, v in named.items()}
    for name, per_image in pred.items():
        have = {c.image for c in out.get(name, [])}
        for image, p in per_image.items():
            if image in have:
                continue
            free = [c for c in cands.get(image, []) if (c.image, round(c.x, 3), round(c.y, 3)) not in taken
                    and (name not in kinds or c.kind == kinds[name])]
            if not free:
                continue
            d = np.array([math.hypot(c.x - p.x, c.y - p.y) for c in free])
            k = int(np.argmin(d))
            radius = max(2.0 * tol_px, 0.3 * free[k].size_px)
            if d[k] > radius or np.sum(d < 2.0 * radius) > 1:
                continue  # nothing there, or two marks close to the projection: left out, not guessed
            out.setdefault(name, []).append(free[k])
            taken.add((image, round(free[k].x, 3), round(free[k].y, 3)))
    _loose(pred, out, cands, kinds, taken, reports)
    return out


def _loose(pred, out: Dict[str, List[Candidate]], cands: Dict[str, List[Candidate]], kinds: Dict[str, str],
           taken: set, reports: List[str]) -> None:
    """A target not tied in two photos has only the similarity's projection, off by the survey's misfit: in each
    photo, the free mark and the projection that are each other's nearest (among the free marks and all the
    targets' projections there) join, if nearer than half the distance to the next target's projection."""
    for name, per_image in pred.items():
        if len(out.get(name, [])) >= 2:
            continue  # projected through its own rays: the tight search above decides
        for image, p in per_image.items():
            if any(c.image == image for c in out.get(name, [])):
                continue
            others = [q for n, v in pred.items() if n != name and image in v for q in [v[image]]]
            free = [c for c in cands.get(image, []) if (c.image, round(c.x, 3), round(c.y, 3)) not in taken
                    and (name not in kinds or c.kind == kinds[name])]
            if not others or not free:
                continue
            spacing = min(math.hypot(q.x - p.x, q.y - p.y) for q in others)
            c = min(free, key=lambda c: math.hypot(c.x - p.x, c.y - p.y))
            d = math.hypot(c.x - p.x, c.y - p.y)
            if d < 0.5 * spacing and all(math.hypot(c.x - q.x, c.y - q.y) > d for q in others):
                out.setdefault(name, []).append(c)
                taken.add((image, round(c.x, 3), round(c.y, 3)))
                reports.append(f"target {name} in {image}: the only mark near its projection, {d:.0f} px from it "
                               f"(the survey and the block disagree there): check it")


def _ground_sizes(rec, cs: Sequence[Candidate], xyz, scale: Optional[float]) -> List[Optional[float]]:
    """Each mark's size on the ground: pixels x depth / focal length x the model's scale (None without one)."""
    if xyz is None or scale is None:
        return [None] * len(cs)
    lookup = {rec.image(i).name: rec.image(i) for i in rec.reg_image_ids()}
    out: List[Optional[float]] = []
    for c in cs:
        im = lookup[c.image]
        m = np.asarray(im.cam_from_world().matrix())
        depth = float((m[:, :3] @ np.asarray(xyz) + m[:, 3])[2])
        out.append(c.size_px * depth / float(rec.cameras[im.camera_id].mean_focal_length()) * scale)
    return out


def _finish(rec, gs, found: Dict[str, List[Candidate]], sources, tol_px: float, match: Constellation,
            target_size: Optional[float]) -> tuple:
    observations: List[FoundObservation] = []
    targets: List[TargetStatus] = []
    track_fit = {match.names[i]: match.residuals[i] for i in match.names}
    scale = match.similarity.scale if match.similarity is not None else None
    for p in gs.points:
        cs = found.get(p.name, [])
        notes = []
        res = np.full(len(cs), np.nan)
        xyz = None
        if len(cs) >= 2:
            t = triangulate_observations(rec, [gcpmod.Observation(c.image, c.x, c.y) for c in cs],
                                         max_error_px=tol_px)
            xyz = t.xyz
            if t.xyz is None:
                cs, res = [], np.zeros(0)
                notes.append("its marks do not intersect in the block")
            else:
                keep = [i for i in range(len(cs)) if t.used[i]]
                if len(cs) > len(keep):
                    notes.append(f"{len(cs) - len(keep)} mark(s) off the others by more than {tol_px:.2g} px left out")
                cs, res = [cs[i] for i in keep], t.residuals_px[keep]
        sizes = _ground_sizes(rec, cs, xyz, scale)
        if target_size:
            keep = [i for i, sz in enumerate(sizes) if sz is None or 0.5 <= sz / target_size <= 2.0]
            if len(keep) < len(cs):
                notes.append(f"{len(cs) - len(keep)} mark(s) of a size unlike the target's {target_size:g} left out")
            cs, res, sizes = [cs[i] for i in keep], res[keep], [sizes[i] for i in keep]
        for c, r, sz in zip(cs, res, sizes):
            observations.append(FoundObservation(p.name, c.image, c.x, c.y, c.kind, c.quality, float(r), c.size_px,
                                                 sources.get(id(c), PROJECTED), size_m=sz))
        targets.append(TargetStatus(p.name, p.x, p.y, p.z, bool(cs), len(cs), track_fit.get(p.name),
                                    "; ".join(notes) or ("" if cs else "not found")))
    return observations, targets


def _prior(ws: Workspace, rec, crs: str, result: FindTargetsResult) -> Optional[Prior]:
    """The EXIF GPS prior, recorded in the result; None without GPS (or with GPS that the CRS cannot take,
    reported)."""
    try:
        prior = gps_prior(ws, rec, crs)
    except CRSError as e:
        result.reports.append(f"the photos' EXIF GPS not used: {e}")
        return None
    if prior is not None:
        result.prior = f"EXIF GPS of {prior.photos} photos, {prior.rms_xy:.3g} RMS"
    return prior


def _keep_clicks(result: FindTargetsResult, clicks: Dict[str, List[gcpmod.Observation]]) -> None:
    """The user's clicks no mark answers go to the output as they are (found False: placed by hand)."""
    for n, obs in clicks.items():
        for ob in obs:
            result.observations.append(FoundObservation(n, ob.image, ob.x, ob.y, CLICK, 1.0, float("nan"), 0.0,
                                                        CLICK, found=False))
        t = next(t for t in result.targets if t.name == n)
        t.found, t.observations = True, t.observations + len(obs)


def _write(lay: Layout, gs, result: FindTargetsResult) -> None:
    from ...io.vector import write_points_gpkg

    os.makedirs(os.path.dirname(result.gcps_path) or ".", exist_ok=True)
    gcpmod.write_odm_gcp_list(result.gcpset(), result.gcps_path)
    rows = []
    for t in result.targets:
        res = [o.residual_px for o in result.observations if o.name == t.name and np.isfinite(o.residual_px)]
        rows.append({"name": t.name, "x": t.x, "y": t.y, "z": t.z, "found": int(t.found),
                     "observations": t.observations, "fit": t.fit,
                     "residual_px": float(np.sqrt(np.mean(np.square(res)))) if res else None, "note": t.note})
    write_points_gpkg(result.layer_path, "targets", rows,
                      [("name", "str"), ("found", "int"), ("observations", "int"), ("fit", "float"),
                       ("residual_px", "float"), ("note", "str")], crs=gs.crs)
    write_json(result.json_path, result.to_dict())


def find_targets(workspace: str, targets: str, options: Optional[FindTargetsOptions] = None,
                 progress: Optional[Progress] = None) -> FindTargetsResult:
    """Find the surveyed ``targets`` (a CSV or gcp_list.txt of coordinates, pixel columns ignored) on the photos of
    the aligned ``workspace``; write the observations found (gcp_list.txt), the review layer and the record."""
    t0 = time.time()
    options = options or FindTargetsOptions()
    ws = Workspace.open(workspace)
    lay = Layout(ws)
    rec = lay.load_aligned_model()  # LayoutError: run 'Align images' first
    gs = gcpmod.read_target_coordinates(targets, options.crs)
    out_path = os.path.abspath(options.output or lay.targets_gcp_list)
    if os.path.abspath(targets) == out_path:
        raise GeorefError(f"{targets}: the observations found would be written over the targets file; give "
                          "another output file")
    result = FindTargetsResult(gs.crs, out_path, os.path.abspath(options.layer or lay.targets_gpkg),
                               lay.targets_json, reports=list(gs.warnings))
    cands = _detect_all(_photos(ws, rec), options, progress)
    result.candidates = sum(len(v) for v in cands.values())
    mre = float(rec.compute_mean_reprojection_error()) if rec.num_points3D() else 0.5
    tol_px = 3.0 * math.hypot(mre, 0.5)  # the block's error and the detection's, both at three sigma
    result.tie_tolerance_px = tol_px
    tracks: List[Track] = [t for t in tie_candidates(rec, cands, tol_px) if on_surface(rec, t, tol_px)]
    result.marks = len(tracks)
    if progress is not None:
        progress.report(0.8, f"{result.candidates} candidate(s), {len(tracks)} tied across photos")
    names = [p.name for p in gs.points]
    codes = code_names(names)
    clicks = {p.name: list(p.observations) for p in gs.points if p.observations}
    zs = [p.z for p in gs.points]
    xy_only = len(zs) >= 2 and max(zs) - min(zs) < 1e-6  # placeholder heights
    labels = merge_names([codes.get(t.code) if t.code is not None else None for t in tracks],
                         click_names(tracks, clicks, tol_px, result.reports), result.reports)
    prior = _prior(ws, rec, gs.crs, result)
    match = match_constellation(np.array([t.xyz for t in tracks]).reshape(-1, 3),
                                np.array([[p.x, p.y, p.z] for p in gs.points]), names, labels, xy_only,
                                weights=[len(t.candidates) for t in tracks],
                                prior=prior.similarity if prior else None,
                                prior_tol=3.0 * prior.rms_xy if prior else 0.0)
    result.fit_tolerance, result.fit_rms, result.mirrored = match.tolerance, match.rms, match.mirrored
    result.reports += match.reports
    if match.similarity is None:  # no constellation: the clicked (or coded) marks keep the names they carry
        match.names = {i: n for i, n in enumerate(labels) if n is not None and labels.count(n) == 1}
    named = {match.names[i]: list(tracks[i].candidates) for i in match.names}
    sources = {id(c): TIED for v in named.values() for c in v}
    kinds = {match.names[i]: tracks[i].kind for i in match.names}
    found = _predict(rec, gs, named, cands, kinds, tol_px, result.reports)
    result.observations, result.targets = _finish(rec, gs, found, sources, tol_px, match, options.target_size)
    _keep_clicks(result, unanswered(clicks, found, tol_px, result.reports))
    result.seconds = time.time() - t0
    _write(lay, gs, result)
    if progress is not None:
        progress.report(1.0, f"{result.n_targets} target(s), {result.n_observations} observation(s) found")
    return result
