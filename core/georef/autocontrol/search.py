"""The search for automatic control points of an aligned block against a reference orthophoto and DSM
(``find_candidates``): the prior that places the block, the provisional orthophoto matched to the reference, the
matches tied back to the photos with their heights, and the heights' own sigma.  What the stage records and adjusts
is in ``stage.py``."""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

import numpy as np

from ...common.progress import NullProgress, Progress, SubProgress
from ...geometry.crs import linear_unit, transform_points, unit_symbol
from ...geometry.similarity import Similarity
from ...io.gcp import CameraPosition
from ...project.workspace import Workspace
from .candidates import (
    KEPT,
    Candidate,
    TiePoints,
    consistent,
    drop_counts,
    estimate_own_sigma,
    own_sigma_prior,
    set_own_sigma,
    spread,
    tie_back,
)
from .errors import AutoControlError
from .matching import apply2, coarse_search, match_orthos
from .options import PRIOR_AUTO, PRIOR_GPS, PRIOR_NONE, AutoControlOptions
from .provisional import (
    Frame,
    block_extent,
    camera_centres,
    frame_from_positions,
    level_frame,
    provisional_ortho,
    registered,
    sparse_points,
)
from .reference import Reference


@dataclass
class CandidateSearch:
    """What ``find_candidates`` found: the candidates (each with its status and why), the figures of the search,
    the messages for the log, the common resolution of the matching (reference CRS units) and the timings."""
    candidates: List[Candidate]
    figures: Dict[str, float]
    messages: List[str]
    gsd: float
    timings: Dict[str, float] = field(default_factory=dict)
    not_shown: str = ""  # why the reference seems not to show the block (no match holds locally), else ''


def photo_paths(ws: Workspace, rec=None) -> Dict[str, str]:
    """{name: path} of the photos of the aligned model ``rec`` (all the workspace's without it); AutoControlError
    naming the folder when they were moved after the alignment (they were left out silently, and the provisional
    orthophoto came out empty)."""
    from ...align.photos import check_photos
    from ...io.images import ImageError

    out = {}
    names = {im.name for im in registered(rec)} if rec is not None else None
    for im in ws.data.get("images", []):
        if names is not None and im["name"] not in names:
            continue
        out[im["name"]] = im.get("path") or os.path.join(ws.data.get("images_dir") or "", im["name"])
    try:
        check_photos(ws, out)
    except ImageError as e:
        raise AutoControlError(str(e)) from e
    return out


def _gps_positions(ws: Workspace, crs: str) -> List[CameraPosition]:
    rows = [(im["name"], im["gps"]) for im in ws.data.get("images", []) if im.get("gps")]
    if not rows:
        return []
    xyz = transform_points(np.array([[g[0], g[1], g[2] if len(g) > 2 and g[2] is not None else 0.0]
                                     for _, g in rows], dtype=float), "EPSG:4326", crs)
    return [CameraPosition(n, float(p[0]), float(p[1]), float(p[2])) for (n, _), p in zip(rows, xyz)]


def _photo_gsd(rec, frame: Frame) -> float:
    """The photos' median ground resolution in frame units: height above the sparse points over the focal."""
    z = float(np.median(frame.model_to_frame.apply(sparse_points(rec))[:, 2]))
    out = []
    for name, c in camera_centres(rec).items():
        im = next(i for i in registered(rec) if i.name == name)
        cam = rec.cameras[im.camera_id]
        f = float(cam.mean_focal_length())
        out.append(abs(frame.model_to_frame.apply(c[None])[0, 2] - z) / max(f, 1e-9))
    return float(np.median(out))


def _coarse_prior(rec, photos, reference: Reference, opt: AutoControlOptions, progress: Progress,
                  messages: List[str]) -> Frame:
    """No prior: the block's level frame matched to the whole reference over rotations; the similarity it gives
    (its height from the DSM at the matches) becomes the prior."""
    lev = level_frame(rec)
    ext = block_extent(rec, lev)
    res0 = max(ext[2] - ext[0], ext[3] - ext[1]) / opt.coarse_pixels
    prov = provisional_ortho(rec, lev, photos, res0, SubProgress(progress, 0.0, 0.5), ext)
    b = reference.bounds
    res_r = max(reference.gsd, max(b[2] - b[0], b[3] - b[1]) / (2 * opt.coarse_pixels))
    ref, valid, gt = reference.grey(b, res_r)
    m, n, angle = coarse_search(prov.grey, prov.valid, ref, valid, opt)
    messages.append(f"no prior: the coarse search over {len(opt.rotations)} rotations found {n} matches "
                    f"(best with the orthophoto turned {angle:g} degrees)")
    if m is None or n < 8:
        raise AutoControlError(f"no prior and the reference orthophoto {reference.ortho_path} does not match the "
                               f"block at a coarse level ({n} matches agree): give rough camera positions or a "
                               "reference that covers the block more tightly")
    # frame xy -> ortho pixel -> reference pixel -> world xy: an affine that is a similarity
    to_px = np.array([[1.0 / res0, 0.0, -ext[0] / res0 - 0.5], [0.0, -1.0 / res0, prov.y0 / res0 - 0.5]])
    to_world = np.array([[gt[1], 0.0, gt[0] + 0.5 * gt[1]], [0.0, gt[5], gt[3] + 0.5 * gt[5]]])
    a3 = np.vstack([to_world, [0, 0, 1]]) @ np.vstack([m, [0, 0, 1]]) @ np.vstack([to_px, [0, 0, 1]])
    s = math.sqrt(abs(np.linalg.det(a3[:2, :2])))
    r2 = a3[:2, :2] / s
    r3 = np.eye(3)
    r3[:2, :2] = r2
    xy = np.array([[0.5 * (ext[0] + ext[2]), 0.5 * (ext[1] + ext[3])]])
    centre_world = apply2(a3[:2], xy)[0]
    pts = lev.model_to_frame.apply(sparse_points(rec))
    zw = reference.heights(*apply2(a3[:2], pts[::max(1, len(pts) // 500), :2]).T)
    z0 = float(np.nanmedian(zw)) - s * float(np.median(pts[:, 2])) if np.isfinite(zw).any() else 0.0
    frame_to_world = Similarity(s, r3, np.r_[a3[:2, 2], z0])
    offset = np.round(np.r_[centre_world, 0.0], 0)
    world = Similarity.translation_only(-offset).compose(frame_to_world).compose(lev.model_to_frame)
    return Frame(world, offset)


def _prior(ws, rec, photos, reference, opt: AutoControlOptions, progress, messages) -> Frame:
    """The block's frame in the reference CRS: from rough camera positions (``opt.camera_positions``, else the
    photos' EXIF GPS unless ``opt.prior`` is "none"), else by the coarse search."""
    crs = reference.crs
    prior, positions = opt.prior, opt.camera_positions
    if positions is None and prior in (PRIOR_AUTO, PRIOR_GPS):
        positions = _gps_positions(ws, crs)
        if prior == PRIOR_GPS and len(positions) < 2:
            raise AutoControlError(f"prior 'gps': {len(positions)} photo(s) of workspace {ws.root} carry EXIF GPS, "
                                   "2 are needed")
    if positions is not None and len(positions) >= 2 and prior != PRIOR_NONE:
        messages.append(f"prior: {len(positions)} rough camera positions")
        return frame_from_positions(rec, positions)
    messages.append("prior: none (searching rotation and scale)")
    return _coarse_prior(rec, photos, reference, opt, progress, messages)


def check_block_pixels(ext, match_gsd: float, reference: Reference, photo_gsd: float, opt: AutoControlOptions) -> None:
    """AutoControlError, before the match, when the block spans fewer pixels of the match's grid than one tile
    of the per-tile affine (``opt.tile_px``): a handful of the reference's features, too few to place the block
    (Toledo's 150 m FC300X block against a 2 m orthophoto: 107 pixels, 16 matches, and a block placed 67 m off
    by a repeated pattern of houses, or 2 candidates)."""
    side = max(ext[2] - ext[0], ext[3] - ext[1])
    px = side / match_gsd
    if px >= opt.tile_px:
        return
    name, metres = linear_unit(reference.crs_wkt)
    unit = "m" if metres == 1.0 else name or "units"
    what = (f"the reference orthophoto {reference.ortho_path} is too coarse for a block this small"
            if match_gsd <= reference.gsd * 1.0001 else
            f"the photos' ground resolution ({photo_gsd:.3g} {unit}) is too coarse for a block this small")
    raise AutoControlError(f"{what}: the block spans {side:.0f} {unit}, {px:.0f} pixels of {match_gsd:.3g} {unit}, and the "
                           f"automatic control needs at least {opt.tile_px} (one tile of its per-tile match); use a "
                           f"reference with cells of {side / opt.tile_px:.2g} {unit} or finer, a larger block, or "
                           "hand-picked control points")


def not_shown(reference: Reference, box, placed: str, ms, g: float, opt: AutoControlOptions) -> str:
    """'the reference orthophoto ... does not seem to show the block: ...' when fewer than ``opt.min_candidates``
    matches hold locally (the per-tile affine) between the block's provisional orthophoto and the reference over the
    block's footprint (``box``, which the reference covers: ``Reference.check_covers`` ran), else '' (issue 47
    item 14: an orthophoto of another place ended in '0 candidate(s) kept, 4 needed').  The evidence: the matches,
    how many agree with one placement and, for that placement, the scale and turn it would give the block, which
    its rough positions place at scale 1, unturned, at the common resolution ``g``."""
    if len(ms.src) >= opt.min_candidates:
        return ""
    unit = unit_symbol(reference.crs_wkt)
    best = ""
    if ms.similarity is not None and ms.n_similarity:
        a = np.asarray(ms.similarity, dtype=float)[:, :2]
        scale = math.sqrt(abs(float(np.linalg.det(a))))
        turn = math.degrees(math.atan2(a[1, 0], a[0, 0]))
        best = (f" (that placement would scale the block by {scale:.2f} and turn it {turn:.0f} degrees, where its "
                f"{placed} place it at scale 1, unturned)")
    return (f"the reference orthophoto {reference.ortho_path} does not seem to show the block: over the block's "
            f"footprint placed by its {placed} ({box[0]:.0f}..{box[2]:.0f}, {box[1]:.0f}..{box[3]:.0f} {unit}), "
            f"which it covers, {ms.n_found} feature matches with the block's provisional orthophoto at {g:.3g} {unit} "
            f"per pixel, {ms.n_similarity} agree with one placement{best} and {len(ms.src)} hold locally (at least "
            f"{opt.min_candidates} needed): is it an orthophoto of this site, and of a time when the ground looked "
            "alike? Open it with the photos' positions in QGIS; when it shows another place, are its georeferencing "
            "and the photos' GPS (or the rough positions given) right?")


def _own_height_sigma(cands, reference: Reference, photo_gsd: float, opt: AutoControlOptions,
                      messages: List[str]) -> float:
    """The reference DSM's own height noise in the candidates' sigma Z: ``opt.dsm_sigma`` when given, else
    estimated from the candidates that agree with one similarity (``candidates.estimate_own_sigma``: between the
    photos' ground resolution, the block's own precision, and the prior, a third of the DSM's cell); the
    candidates' sigma Z are set from it."""
    prior = own_sigma_prior(reference.dsm_gsd, opt.dsm_sigma)
    if opt.dsm_sigma is not None:
        return prior
    own = estimate_own_sigma(cands, photo_gsd, prior)
    if own is None:
        return prior
    set_own_sigma(cands, own)
    messages.append(f"reference DSM heights: sigma {own:.3g} from the candidates that agree (at most a third of "
                    f"its {reference.dsm_gsd:.3g} cell, {prior:.3g}; at least the photos' ground resolution, "
                    f"{photo_gsd:.3g}), plus each point's slope and roughness")
    return own


def find_candidates(ws: Workspace, rec, reference: Reference, options: Optional[AutoControlOptions] = None,
                    progress: Optional[Progress] = None) -> CandidateSearch:
    """The candidates of an aligned block against the reference, with the search's figures and messages (the
    block placed by ``options.prior`` and ``options.camera_positions``)."""
    opt = AutoControlOptions.of(options)
    progress = progress or NullProgress()
    photos = photo_paths(ws, rec)
    messages: List[str] = list(reference.notes)
    t = {"start": time.time()}
    frame = _prior(ws, rec, photos, reference, opt, SubProgress(progress, 0.0, 0.2), messages)
    t["prior"] = time.time()
    ext = block_extent(rec, frame)
    photo_gsd = _photo_gsd(rec, frame)
    g = opt.gsd or max(reference.gsd, photo_gsd, max(ext[2] - ext[0], ext[3] - ext[1]) / opt.max_pixels)
    check_block_pixels(ext, g, reference, photo_gsd, opt)
    margin = 0.15 * max(ext[2] - ext[0], ext[3] - ext[1]) + 10.0 * g
    off = frame.offset
    box = (ext[0] + off[0] - margin, ext[1] + off[1] - margin, ext[2] + off[0] + margin, ext[3] + off[1] + margin)
    placed = "coarse match" if any(m.startswith("prior: none") for m in messages) else "rough camera positions"
    footprint = (ext[0] + off[0], ext[1] + off[1], ext[2] + off[0], ext[3] + off[1])
    reference.check_covers(footprint, f"the block placed by its {placed}")
    prov = provisional_ortho(rec, frame, photos, g, SubProgress(progress, 0.2, 0.4), ext)
    t["orthophoto"] = time.time()
    ref, valid, gt = reference.grey(box, g)
    ms = match_orthos(prov.grey, prov.valid, ref, valid, opt)
    t["matching"] = time.time()
    messages.append(f"matching at {g:.3g} {unit_symbol(reference.crs_wkt)} per pixel: {ms.n_features[0]} / "
                    f"{ms.n_features[1]} features, "
                    f"{ms.n_found} matches, {ms.n_similarity} fit one similarity, {len(ms.src)} fit their tiles")
    sel = spread(ms.src, ms.residual, opt.max_candidates, prov.grey.shape)
    world_xy = np.column_stack([gt[0] + (ms.dst[sel, 0] + 0.5) * gt[1], gt[3] + (ms.dst[sel, 1] + 0.5) * gt[5]])
    cands = tie_back(rec, frame, prov, TiePoints(ms.src[sel], world_xy, ms.residual[sel]), reference, photos, opt,
                     SubProgress(progress, 0.4, 0.9))
    t["photos"] = time.time()
    n_obs = sum(1 for c in cands if c.status == KEPT)
    # what the block may be off beyond each candidate's own sigmas: a few cells of the match's grid (was 10 g but
    # at least 0.5 m, one 3-D distance: a height from a 10-30 m DEM was judged by the orthophoto's cell)
    consistent(cands, 10.0 * g)
    n_kept = sum(1 for c in cands if c.status == KEPT)
    messages.append(f"{len(cands)} candidates tied back to the photos: {n_obs} seen in at least 2 photos with a "
                    f"DSM height, {n_kept} agree with one similarity")
    own = _own_height_sigma(cands, reference, photo_gsd, opt, messages)
    dropped = drop_counts(cands)
    if dropped:
        messages.append("candidates dropped: " + "; ".join(f"{n} {r}" for r, n in dropped.items()))
    figures = {"features_ortho": ms.n_features[0], "features_reference": ms.n_features[1], "matches": ms.n_found,
               "similarity_inliers": ms.n_similarity, "tile_inliers": int(len(ms.src)), "candidates": len(cands),
               "observed": n_obs, "consistent": n_kept,
               "block_reference_pixels": round(max(ext[2] - ext[0], ext[3] - ext[1]) / reference.gsd, 1),
               "dsm_sigma": own}
    timings = {k: t[k] - t["start"] for k in ("prior", "orthophoto", "matching", "photos")}
    return CandidateSearch(cands, figures, messages, g, timings, not_shown(reference, footprint, placed, ms, g, opt))


__all__ = ["CandidateSearch", "check_block_pixels", "find_candidates", "not_shown", "photo_paths"]
