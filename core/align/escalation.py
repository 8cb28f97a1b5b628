"""Escalation: the fast path's features and pairs retried, richer, only where the fast path failed.

The fast path (``features`` + ``pairs``) is tuned for speed on typical drone frames: SIFT starts at octave 0
from ``UPSAMPLE_BELOW`` px, about 4000 features per megapixel, spatial or sequential pairs; where the texture probe
(core.align.firstpass) finds the photos starved, its first pass already takes the faint settings below, and a
round starts from the first pass's budget and scale.  On other frames
(small scans, low texture, low overlap) it can leave images unregistered or split the block into components
where pycolmap's default pipeline (upsampled SIFT, 8192 features, exhaustive pairs) does not.  After the first
mapping, :func:`escalate` retries *only the images left out of the main block and their neighbours*, in
one or two rounds of two kinds, the one that fits the failure first:

- **faint** -- for images with no verified pair or in a separate component (too little texture or contrast,
  weak links): the left-out images, plus the registered images they matched best (from the database's raw
  matches) and the cameras next to those in the model ("guided by what did register"), are extracted again
  with upsampled SIFT (``first_octave = -1``), twice the features (at least 8192) and a third of SIFT's peak
  threshold (faint, low-contrast features); their old matches are removed; they are matched again on the
  original pairs plus new pairs: every pair among the left-out images and each left-out image with every
  neighbour;
- **affine** -- for images that matched others but could not be registered (too few 2D-3D correspondences:
  strong perspective change, the 65 deg views of an orbit): upsampled SIFT with affine-shape estimation
  (features that survive strong perspective and scale change) at SIFT's default threshold and at least 4096
  features, on every image with exhaustive pairs in a block of up to ``ESCALATE_ALL_MAX`` images; in a larger
  block on the left-out images and their neighbours (chosen again), each left-out image paired with every
  registered image: the cost stays that of the images that failed, not of the block.  (Domain-size pooling
  is not used: on the synthetic orbit it tripled the feature time and registered no image more than affine
  shape alone; measured in docs/measurements.md.)

An image in the main block that is tied by too few points (:func:`weak_images`: fewer than WEAK_MIN_TIES,
typically a steep view the mapping's relaxed second pass placed on 15-29 correspondences) is escalated as a
left-out one of the "affine" kind (it matched, but weakly): it stays registered whatever the round gives, and a
round is kept when it leaves fewer such images (as many registered, in as many components).

The kind most of the left-out images call for runs first; the other runs second only when images are still out
and have shared a verified pair with some image (a foreign photo is not escalated twice).

**A large block** (more than ``EXTEND_MIN_IMAGES`` images) is escalated by *extension*, so that a round costs what
its left-out images cost and not what the block costs: the same images are extracted again, but each left-out
image is matched only with its own ``spatial_neighbours`` nearest images (by camera position: EXIF GPS or the
camera positions file; else in file order) and the registered images it matched best (not every left-out image
with every other's neighbours), and the mapping continues from the main block (the registered images extracted
again taken out of it, to be registered again on their new features; core.align.mapping.run_mapping's ``start``)
instead of mapping the whole block afresh.  In the synthetic 1,000-photo block a round that matched 3,181 pairs
and mapped all 1,000 images again took 25 minutes (docs/measurements.md).

After each round the mapping runs again on the enlarged database (one merged reconstruction); a round's result
is kept only when it registers more images in the main block (or as many in fewer components); otherwise the
database goes back to its state before the round (a copy taken before it), so that it always holds the
features and matches of the result kept.  What was escalated, for which image and why, goes to the log and to
``sfm/alignment.json`` (``escalation``).
"""
from __future__ import annotations

import os
import shutil
import sqlite3
import time
from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, List, Optional, Sequence, Set, Tuple

import numpy as np

from ..common.progress import Progress, SubProgress, check_cancel
from .features import Extraction, FeatureSettings, auto_max_features, extract_features, match_pairs
from .options import FAINT_MIN_FEATURES, FAINT_PEAK_THRESHOLD, AlignOptions

ESCALATION_MIN_FEATURES = FAINT_MIN_FEATURES  # pycolmap's default SIFT budget: the escalated budget is never below it
ESCALATION_PEAK_THRESHOLD = FAINT_PEAK_THRESHOLD  # a third of SIFT's default (0.02 / octave_resolution): faint features
AFFINE_MIN_FEATURES = 4096  # the affine round's budget: as many registered as with 8192, matching ~4x cheaper
KINDS = ("faint", "affine")
ANCHORS_PER_IMAGE = 6  # registered images a left-out image matched best
MODEL_NEIGHBOURS = 3  # registered cameras next to each anchor in the model
ESCALATE_ALL_MAX = 20  # an affine round re-extracts and matches every image exhaustively in a block this small
# an image of the main block tied by fewer points than COLMAP asks of an image to register it (the mapper's
# abs_pose_min_num_inliers, 30) is "weakly tied" and escalated
WEAK_MIN_TIES = 30
# a block of more images is escalated by extension (the module's docstring): each left-out image matched with its
# own nearest images and the mapping continued from the main block; at and below it a round matches every left-out
# image with every neighbour and maps the block afresh (the kept behaviour on Toledo-57 and the small sets)
EXTEND_MIN_IMAGES = 100
PAIR_ID_BASE = 2147483647  # COLMAP: pair_id = image_id1 * 2147483647 + image_id2 (image_id1 < image_id2)


@dataclass
class EscalationRound:
    """What one escalation round did (a row of ``escalation.rounds`` in sfm/alignment.json)."""

    round: int
    reason: str
    kind: str  # "faint" or "affine" (see the module's docstring)
    left_out: Dict[str, str]  # image -> why it was outside the main block before this round
    re_extracted: List[str]
    neighbours: List[str]  # registered images re-extracted with the left-out ones
    sift: Dict[str, object]
    pairs_matched: int
    registered_before: int
    components_before: int
    registered_after: int = 0
    components_after: int = 0
    kept: bool = False
    seconds: float = 0.0
    timings: Dict[str, float] = field(default_factory=dict)
    extended: bool = False  # a large block's round: the main block continued, not mapped afresh


@dataclass
class Escalation:
    """The escalation record: why it ran, its rounds, and per image what was done and the outcome."""

    reason: str
    rounds: List[EscalationRound] = field(default_factory=list)
    images: Dict[str, Dict[str, object]] = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"reason": self.reason, "rounds": [asdict(r) for r in self.rounds], "images": self.images}


def block_state(ordered) -> Tuple[Set[str], List[List[str]]]:
    """(names registered in the largest reconstruction, the other components' images outside it).

    COLMAP may register an image in more than one model: a component whose images are all in the main block
    is no split, and the images of another component that the main block holds are not counted twice."""
    if not ordered:
        return set(), []
    main = {ordered[0].images[i].name for i in ordered[0].reg_image_ids()}
    others = []
    for rec in ordered[1:]:
        rest = sorted({rec.images[i].name for i in rec.reg_image_ids()} - main)
        if rest:
            others.append(rest)
    return main, others


def weak_images(ordered) -> Dict[str, str]:
    """The images of the main block (``ordered[0]``) tied by fewer than WEAK_MIN_TIES points: image -> why.
    Such an image is registered (by the mapping's relaxed second pass, or its points thinned by the final
    adjustment), but its pose rests on fewer points than COLMAP asks of a registration: the synthetic orbit's
    steepest view, placed by the relaxed pass on 13 tie points where the affine round gives it ~135.  Not
    relative to the block: an edge image of copr with 57 tie points in a block of median 1,389 is well placed."""
    ties = _ties(ordered)
    if len(ties) < 3:
        return {}
    median = float(np.median(list(ties.values())))
    return {n: (f"registered, but tied by only {t} points (fewer than {WEAK_MIN_TIES}; the block's median "
                f"{median:.0f})") for n, t in sorted(ties.items()) if t < WEAK_MIN_TIES}


def escalation_reason(n_images: int, registered: Set[str], others: Sequence[Sequence[str]],
                      weak: Sequence[str] = ()) -> Optional[str]:
    """Why the fast path's result needs escalation, or None when every image is in one block, well tied."""
    parts = []
    if len(registered) < n_images:
        parts.append(f"{n_images - len(registered)} of {n_images} images not in the main block")
    if others:
        parts.append(f"the block split into {len(others) + 1} components")
    if weak:
        parts.append(f"{len(weak)} image(s) of the block weakly tied")
    return "; ".join(parts) or None


def escalated_sift(options: AlignOptions, width: int, height: int, kind: str = "faint",
                   budget: Optional[int] = None) -> Dict[str, object]:
    """The SIFT settings of an escalation round of ``kind``: "faint" -- upsampled, more and fainter features;
    "affine" -- upsampled with affine-shape estimation at SIFT's default threshold.  ``budget``: the first
    pass's features per photo (core.align.firstpass), else the options' (or the automatic) budget."""
    if kind not in KINDS:
        raise ValueError(f"unknown escalation kind {kind!r}; one of {', '.join(KINDS)}")
    base = int(budget or options.max_features or auto_max_features(width, height, options.max_image_size))
    if kind == "affine":
        return {"first_octave": -1, "max_num_features": max(AFFINE_MIN_FEATURES, base),
                "estimate_affine_shape": True}
    return {"first_octave": -1, "max_num_features": max(ESCALATION_MIN_FEATURES, 2 * base),
            "peak_threshold": ESCALATION_PEAK_THRESHOLD}


def kind_order(why: Dict[str, str], left: Sequence[str]) -> Tuple[str, str]:
    """The order of the two kinds of round for the ``left`` out images, from the diagnosis ``why`` (image ->
    the reason it is outside the main block): "affine" first when most of them matched other images but could
    not be registered, or were registered weakly tied (a viewpoint problem), "faint" first otherwise (no verified
    pair, a separate component)."""
    viewpoint = sum(1 for n in left if "could not be registered" in why.get(n, "") or "tied by only" in why.get(n, ""))
    return ("affine", "faint") if viewpoint * 2 > len(left) else ("faint", "affine")


def _pair_counts(db_path: str) -> Tuple[Dict[int, str], Dict[Tuple[str, str], int]]:
    """(image_id -> name, (name, name) -> raw matches) read from the COLMAP database (SQLite)."""
    con = sqlite3.connect(db_path)
    try:
        names = {int(i): n for i, n in con.execute("SELECT image_id, name FROM images")}
        counts: Dict[Tuple[str, str], int] = {}
        for pid, rows in con.execute("SELECT pair_id, rows FROM matches"):
            a, b = names.get(int(pid) // PAIR_ID_BASE), names.get(int(pid) % PAIR_ID_BASE)
            if a and b:
                counts[(a, b)] = counts[(b, a)] = int(rows)
        return names, counts
    finally:
        con.close()


def forget_features(db_path: str, names: Sequence[str]) -> None:
    """Remove the keypoints, descriptors, matches and two-view geometries of ``names`` from the database, so
    that the next extraction and matching compute them afresh (COLMAP skips images that have features)."""
    con = sqlite3.connect(db_path)
    try:
        wanted = set(names)
        ids = [int(i) for i, n in con.execute("SELECT image_id, name FROM images") if n in wanted]
        idset = set(ids)
        with con:
            for table in ("keypoints", "descriptors"):
                con.executemany(f"DELETE FROM {table} WHERE image_id = ?", [(i,) for i in ids])
            for table in ("matches", "two_view_geometries"):
                pids = [int(p) for (p,) in con.execute(f"SELECT pair_id FROM {table}")
                        if int(p) // PAIR_ID_BASE in idset or int(p) % PAIR_ID_BASE in idset]
                con.executemany(f"DELETE FROM {table} WHERE pair_id = ?", [(p,) for p in pids])
    finally:
        con.close()


def _model_neighbours(rec, names: Sequence[str], k: int) -> Dict[str, List[str]]:
    """For each registered image of ``names``: the ``k`` registered images nearest to it in the model."""
    centres = {rec.images[i].name: np.asarray(rec.images[i].projection_center(), dtype=float)
               for i in rec.reg_image_ids()}
    keys = sorted(centres)
    if not keys:
        return {}
    xyz = np.array([centres[n] for n in keys])
    out = {}
    for n in names:
        if n in centres:
            d = np.linalg.norm(xyz - centres[n], axis=1)
            out[n] = [keys[j] for j in np.argsort(d)[1:k + 1]]
    return out


def best_matched(counts: Dict[Tuple[str, str], int], name: str, registered) -> List[str]:
    """The ANCHORS_PER_IMAGE images of ``registered`` that ``name`` has most raw matches with (``counts``:
    :func:`_pair_counts`), best first."""
    ranked = sorted(((c, r) for r in registered if (c := counts.get((name, r), 0)) > 0), reverse=True)
    return [r for _c, r in ranked[:ANCHORS_PER_IMAGE]]


def choose_neighbours(db_path: str, order: Sequence[str], registered: Set[str], left_out: Sequence[str],
                      rec) -> List[str]:
    """The registered images re-extracted and matched with the left-out ones: for each left-out image the
    registered images it has most raw matches with (or, with none, its neighbours in file order), plus the
    cameras next to those in the model."""
    _ids, counts = _pair_counts(db_path)
    index = {n: k for k, n in enumerate(order)}
    anchors: Set[str] = set()
    for w in left_out:
        mine = best_matched(counts, w, registered)
        if len(mine) < 2:  # nothing matched: the images taken just before and after it
            near = sorted(registered, key=lambda r: abs(index.get(r, 0) - index.get(w, 0)))
            mine += [r for r in near[:2] if r not in mine]
        anchors.update(mine)
    out = set(anchors)
    if rec is not None:
        for near in _model_neighbours(rec, sorted(anchors), MODEL_NEIGHBOURS).values():
            out.update(near)
    return sorted(out)


def round_pairs(original: Sequence[Tuple[str, str]], left_out: Sequence[str], neighbours: Sequence[str],
                all_names: Sequence[str], exhaustive: bool) -> List[Tuple[str, str]]:
    """The pairs an escalation round matches: the original pairs touching a re-extracted image (their old
    matches are gone), every pair among the left-out images, each left-out image with every neighbour; with
    ``exhaustive`` every pair of ``all_names``."""
    pairs: Set[Tuple[str, str]] = set()
    if exhaustive:
        for i, a in enumerate(all_names):
            for b in all_names[i + 1:]:
                pairs.add((min(a, b), max(a, b)))
        return sorted(pairs)
    touched = set(left_out) | set(neighbours)
    for a, b in original:
        if a in touched or b in touched:
            pairs.add((min(a, b), max(a, b)))
    group = list(left_out)
    for i, a in enumerate(group):
        for b in group[i + 1:] + list(neighbours):
            if a != b:
                pairs.add((min(a, b), max(a, b)))
    return sorted(pairs)


@dataclass
class EscalationContext:
    """What :func:`escalate` needs from the stage: the database, the photos and the stage's steps."""

    pycolmap: object
    job: Extraction  # the database, the photos, their cameras and masks
    settings: FeatureSettings  # the first pass's features (core.align.firstpass): a round's start from them
    work_dir: str
    order: List[str]  # every image name, in file order
    options: AlignOptions
    pairs: List[Tuple[str, str]]
    # runs the mapping on the database (continuing a given reconstruction): reconstructions, largest first
    mapping: Callable[..., list]
    diagnose: Callable[[Set[str], List[List[str]]], Dict[str, str]]  # (registered, others) -> image -> why
    partners: Callable[[], Dict[str, int]]  # image -> how many images it shares a verified pair with
    positions: Optional[Dict[str, Tuple[float, float]]] = None  # image -> horizontal position (m), where known

    @property
    def db_path(self) -> str:
        return self.job.db_path


def _better(new, old) -> bool:
    """Does the reconstruction list ``new`` beat ``old``: more images in the main block, or as many in fewer
    components, or as many in as many components with fewer weakly tied images (:func:`weak_images`)."""
    (rn, on), (ro, oo) = block_state(new), block_state(old)
    return (len(rn), -len(on), -len(weak_images(new))) > (len(ro), -len(oo), -len(weak_images(old)))


def _round_images(ctx: EscalationContext, kind: str, registered: Set[str], left: List[str], ordered):
    """(neighbours, exhaustive) of a round of ``kind``: an affine round takes every image (exhaustive pairs) in
    a block of up to ESCALATE_ALL_MAX images (features of one kind on both sides of every pair)."""
    if kind == "affine" and len(ctx.order) <= ESCALATE_ALL_MAX:
        return [n for n in ctx.order if n in registered], True
    neighbours = choose_neighbours(ctx.db_path, ctx.order, registered, left, ordered[0] if ordered else None)
    return neighbours, False


def extends(ctx: EscalationContext, ordered) -> bool:
    """Is this block escalated by extension (a large block with a main reconstruction to continue)?"""
    return bool(ordered) and len(ctx.order) > EXTEND_MIN_IMAGES


def nearest(ctx: EscalationContext, name: str, pool: Sequence[str], k: int) -> List[str]:
    """The ``k`` images of ``pool`` nearest to ``name``: by camera position where it and they have one, else in
    file order."""
    pool = [n for n in pool if n != name]
    pos = ctx.positions or {}
    placed = [n for n in pool if n in pos]
    if name in pos and placed:
        x, y = pos[name]
        return sorted(placed, key=lambda n: ((pos[n][0] - x) ** 2 + (pos[n][1] - y) ** 2, n))[:k]
    index = {n: i for i, n in enumerate(ctx.order)}
    at = index.get(name, 0)
    return sorted(pool, key=lambda n: (abs(index.get(n, 0) - at), n))[:k]


def extension_pairs(ctx: EscalationContext, left: Sequence[str], redo: Sequence[str], rec=None
                    ) -> List[Tuple[str, str]]:
    """The pairs an extension round matches (a large block): the original pairs touching an image extracted
    again (``redo``: its old matches are gone), and each left-out image with its ``spatial_neighbours`` nearest
    images (by camera position, else in file order) and the ANCHORS_PER_IMAGE registered images it had most raw
    matches with -- without camera positions also the cameras next to those in the model ``rec``.  Per image,
    not every left-out image with every other's neighbours: the count grows with the images left out, not with
    the block."""
    _ids, counts = _pair_counts(ctx.db_path)
    k = max(1, int(ctx.options.spatial_neighbours))
    touched, lset = set(redo), set(left)
    pairs: Set[Tuple[str, str]] = {(min(a, b), max(a, b)) for a, b in ctx.pairs if a in touched or b in touched}
    others = list(ctx.order)
    registered = [n for n in others if n not in lset]
    placed = ctx.positions or {}
    for w in left:
        anchors = best_matched(counts, w, registered)
        mine = set(anchors) | set(nearest(ctx, w, others, k))
        if rec is not None and w not in placed:
            for near in _model_neighbours(rec, anchors, MODEL_NEIGHBOURS).values():
                mine.update(near)
        pairs.update((min(w, m), max(w, m)) for m in mine if m != w)
    return sorted(pairs)


def _start_without(ctx: EscalationContext, rec, names: Sequence[str]):
    """A copy of the main block ``rec`` without the registered images among ``names`` (extracted again: their
    observations belong to their old features); the mapping registers them again with the new ones."""
    start = ctx.pycolmap.Reconstruction(rec)
    for n in names:
        im = start.find_image_with_name(n)
        if im is not None and im.has_pose:
            start.deregister_frame(im.frame_id)
    return start


def _run_round(ctx: EscalationContext, k: int, reason: str, ordered, left: List[str],
               progress: Progress, kind: str = "faint") -> Tuple[EscalationRound, list]:
    """Round ``k`` of ``kind``: re-extract the ``left`` out images and their neighbours, match them again, map
    again."""
    t0 = time.time()
    registered, others = block_state(ordered)
    why = {**ctx.diagnose(registered, others), **weak_images(ordered)}
    anchors = registered - set(left)  # a weakly tied image is escalated as a left-out one, not as a neighbour
    extension = extends(ctx, ordered)  # a large block: the main block continued (the module's docstring)
    neighbours, exhaustive = _round_images(ctx, kind, anchors, left, ordered)
    redo = [n for n in ctx.order if n in set(left) | set(neighbours)]
    g0 = max(ctx.job.groups, key=lambda g: g.width * g.height)
    sift = escalated_sift(ctx.options, g0.width, g0.height, kind, ctx.settings.max_features)
    extra = ", affine shape" if sift.get("estimate_affine_shape") else ""
    threshold = sift.get("peak_threshold")
    progress.info(f"escalation round {k}, {kind} ({reason}): {len(left)} image(s) to bring in, re-extracting "
                  f"{len(redo)} with upsampled SIFT (first octave -1), {sift['max_num_features']} features"
                  + (f", peak threshold {threshold:.4f}" if threshold else "") + extra)
    for n in left:
        progress.info(f"escalation round {k}: {n}: {why.get(n, 'not in the main block')}")
    forget_features(ctx.db_path, redo)
    extract_features(ctx.pycolmap, ctx.job, ctx.settings.with_sift(sift), ctx.options, SubProgress(progress, 0.0, 0.4))
    t_features = time.time() - t0
    if extension:
        pairs = extension_pairs(ctx, left, redo, ordered[0])
    else:
        pairs = round_pairs(ctx.pairs, left, neighbours, ctx.order, exhaustive)
    if kind == "affine" and not exhaustive and not extension:  # each left-out image with every registered one
        pairs = sorted(set(pairs) | {(min(a, b), max(a, b)) for a in left for b in anchors if a != b})
    progress.info(f"escalation round {k}: matching {len(pairs)} pairs")
    match_pairs(ctx.pycolmap, ctx.db_path, pairs, ctx.work_dir, ctx.options, SubProgress(progress, 0.4, 0.7))
    t_matching = time.time() - t0 - t_features
    check_cancel(progress)
    if extension:  # the main block continued; the other components stay as they were unless it takes them in
        start = _start_without(ctx, ordered[0], redo)
        new = ctx.mapping(SubProgress(progress, 0.7, 1.0), start) + list(ordered[1:])
    else:
        new = ctx.mapping(SubProgress(progress, 0.7, 1.0))
    reg_new, others_new = block_state(new)
    row = EscalationRound(k, reason, kind, {n: why.get(n, "") for n in left}, redo, [n for n in neighbours if n in redo],
                          sift, len(pairs), len(registered), (len(others) + 1) if ordered else 0, len(reg_new),
                          (len(others_new) + 1) if new else 0, kept=_better(new, ordered),
                          seconds=round(time.time() - t0, 2),
                          timings={"features": round(t_features, 2), "matching": round(t_matching, 2),
                                   "mapping": round(time.time() - t0 - t_features - t_matching, 2)},
                          extended=extension)
    return row, new


def _backup_database(db_path: str) -> str:
    """A copy of the (closed) database beside it, taken before a round: restored when the round is not kept."""
    backup = db_path + ".before-escalation"
    for suffix in ("-wal", "-shm"):  # every connection is closed: a leftover journal is checkpointed first
        if os.path.exists(db_path + suffix):
            con = sqlite3.connect(db_path)
            try:
                con.execute("PRAGMA wal_checkpoint(TRUNCATE)")
            finally:
                con.close()
            break
    shutil.copyfile(db_path, backup)
    return backup


def _hopeful(ctx: EscalationContext, registered: Set[str], others: List[List[str]], progress: Progress,
             round1: Optional[Dict[str, int]] = None) -> List[str]:
    """The images round 2 (the other kind of features) is worth running for: those still outside the
    main block that, after round 1's richer features, share a verified pair with some image or sit in another
    component.  An image without any verified pair after round 1 shares no ground with the block (a foreign
    photo, sky, water): round 2 would not change that and is not run for it.  ``round1``: the verified partners
    counted right after round 1 (its database may have been put back since, when its result was not kept)."""
    partners = dict(ctx.partners())
    for n, c in (round1 or {}).items():
        partners[n] = max(partners.get(n, 0), c)
    in_other = {n for comp in others for n in comp}
    left = [n for n in ctx.order if n not in registered]
    hopeful = [n for n in left if n in in_other or partners.get(n, 0) > 0]
    if len(hopeful) < len(left):
        rest = [n for n in left if n not in hopeful]
        progress.info(f"escalation: {len(rest)} image(s) without any verified pair after round 1, not escalated "
                      f"further (no ground shared with the block): {', '.join(rest[:10])}")
    return hopeful


def escalate(ctx: EscalationContext, ordered, progress: Progress):
    """Escalate where the fast path failed; returns (reconstructions, largest first, Escalation or None)."""
    if not ctx.options.escalate:
        return ordered, None
    registered, others = block_state(ordered)
    weak = weak_images(ordered)
    reason = escalation_reason(len(ctx.order), registered, others, list(weak))
    if reason is None:
        return ordered, None
    record = Escalation(reason)
    progress.warning(f"fast path: {reason}; escalating for the images left out" + (" or weakly tied" if weak else ""))
    first_left = [n for n in ctx.order if n not in registered or n in weak]
    left = first_left
    kinds = kind_order({**ctx.diagnose(registered, others), **weak}, first_left)
    round1_partners: Dict[str, int] = {}
    for k, kind in zip((1, 2), kinds):
        if k == 2:
            registered, others = block_state(ordered)
            weak = weak_images(ordered)
            reason = escalation_reason(len(ctx.order), registered, others, list(weak))
            if reason is None:
                break
            left = _hopeful(ctx, registered, others, progress, round1_partners)
            left += [n for n in ctx.order if n in weak]
            if not left:
                break
        backup = _backup_database(ctx.db_path)
        try:
            row, new = _run_round(ctx, k, reason, ordered, left, SubProgress(progress, (k - 1) / 2.0, k / 2.0),
                                  kind=kind)
            record.rounds.append(row)
            if k == 1:
                round1_partners = ctx.partners()  # before its database may be put back
            if row.kept:
                ordered = new
            else:  # the database goes back to the features and matches of the result kept (a re-run reuses them)
                os.replace(backup, ctx.db_path)
        except BaseException:  # a cancel or a failure in the round: the database as it was before it
            try:
                os.replace(backup, ctx.db_path)
            except OSError as err:
                progress.warning(f"escalation round {k}: could not put {ctx.db_path} back ({err}); a re-run "
                                 "extracts the features of the images of this round again")
            raise
        finally:
            if os.path.exists(backup):
                os.unlink(backup)
        progress.info(f"escalation round {k}: main block {row.registered_before} -> {row.registered_after} images, "
                      f"{row.components_before} -> {row.components_after} component(s), {row.seconds:.1f} s"
                      + ("" if row.kept else "; not better, the previous result kept"))
    final, _ = block_state(ordered)
    still_weak = weak_images(ordered)
    ties = _ties(ordered)
    for n in first_left:
        done = [r.round for r in record.rounds if n in r.left_out]
        record.images[n] = {"why": record.rounds[0].left_out.get(n, ""), "rounds": done,
                            "registered": n in final, "tie_points": ties.get(n, 0), "weak": n in still_weak,
                            "escalated": [(("upsampled SIFT (first octave -1) with affine shape" if r.kind == "affine"
                                            else "upsampled SIFT (first octave -1), more and fainter features")
                                           + f", {r.pairs_matched} pairs matched again") for r in record.rounds
                                          if n in r.left_out]}
    return ordered, record


def _ties(ordered) -> Dict[str, int]:
    """Image name -> tie points in the main block."""
    if not ordered:
        return {}
    rec = ordered[0]
    return {rec.images[i].name: int(rec.images[i].num_points3D) for i in rec.reg_image_ids()}
