"""Weak links of a block matched again, guided by the block's own poses (issue 46).

On faint fields SIFT finds few features, and two overlapping photos whose features do not stand out among all of
the other photo's (the global ratio test) share a few dozen matches: the mapper still carries the block across such
a link, but on a handful of points whose spread does not hold the relative orientation.  seneca_south's 12 photos
map in one block whose two halves meet through IMG_0450 + IMG_0451 (64 verified matches, 17 tie points): the stereo
pairs across that link disagreed with the others by 5-25 times the depth tolerance (the block was bent there), and
most of the ground the halves share was interpolated in the DSM.

Once the block is mapped, each pair of registered photos (neither an oblique view: :func:`steep_views`) that
overlaps on the ground (its features' rays, at the depth of their nearest tie points, land in the other photo) but
verified few matches for that overlap (LINK_WEAK_SHARE of the overlapping features) is matched again: each
feature only against the other photo's features near where the block predicts it (a radius of LINK_RADIUS_SHARE of
the image's diagonal), with a ratio test among those (LINK_RATIO), then verified by a fundamental matrix (RANSAC,
LINK_RANSAC_SHARE of the diagonal).
Where that verifies more matches than the pair had, the database's two-view geometry is replaced by it, the
block's points are triangulated again from every verified match with the poses held, and the final bundle
adjustment refines the poses on them; then again on the better poses (LINK_ROUNDS), until no link gains.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.progress import Progress, check_cancel
from ..geometry.camera import intrinsics_of

LINK_MIN_OVERLAP = 0.1  # of a photo's features that land in the other photo: the pair overlaps on the ground
LINK_WEAK_SHARE = 0.1  # verified matches under this share of the overlapping features: a weak link
LINK_RADIUS_SHARE = 0.025  # of the image's diagonal: how far from its predicted place a match may lie
LINK_RATIO = 0.9  # the nearest descriptor against the second nearest within the radius
LINK_NEIGHBOURS = 8  # candidates per feature (the nearest within the radius) and tie points per depth
LINK_RANSAC_SHARE = 0.001  # of the diagonal: the fundamental matrix's RANSAC threshold (1.9 px at 1800 x 1350)
LINK_MIN_TIES = 8  # tie points a photo needs for the depths of its features
LINK_MAX_TILT_DEG = 30.0  # views further than this from the block's mean axis are not matched again (steep_views)
LINK_ROUNDS = 3  # rounds of matching again (each on the poses the last one's adjustment gave)


def steep_views(rec) -> set:
    """The registered images whose optical axis lies more than LINK_MAX_TILT_DEG from the block's mean axis (the
    ground's "down" in a block of vertical photos, whatever its frame): an oblique view sees the ground foreshortened
    and turned, and a plain SIFT descriptor's nearest within the radius is too often another feature (the synthetic
    orbits' steep views: their poses 2-3 x worse with their links matched again)."""
    axes = {i: np.asarray(rec.images[i].cam_from_world().rotation.matrix())[2] for i in rec.reg_image_ids()}
    if not axes:
        return set()
    mean = np.mean(list(axes.values()), axis=0)
    norm = float(np.linalg.norm(mean))
    if norm < 1e-6:
        return set(axes)
    limit = math.cos(math.radians(LINK_MAX_TILT_DEG))
    return {i for i, ax in axes.items() if float(ax @ mean) / norm < limit}


@dataclass
class Link:
    """One pair matched again: names, verified matches before and after."""

    a: str
    b: str
    before: int
    after: int

    def to_dict(self) -> dict:
        return {"images": [self.a, self.b], "verified_before": self.before, "verified_after": self.after}


def feature_ground(rec, image_id: int, keypoints: np.ndarray) -> Optional[np.ndarray]:
    """The model points where the rays of ``keypoints`` (N, 2) of a registered image meet the ground: each at the
    median depth of its LINK_NEIGHBOURS nearest tie points in the image; None with fewer than LINK_MIN_TIES."""
    kdtree = require("scipy.spatial", "matching weak links").cKDTree
    im = rec.images[image_id]
    cam = intrinsics_of(rec.cameras[im.camera_id])
    pose = im.cam_from_world()
    r, t = np.asarray(pose.rotation.matrix()), np.asarray(pose.translation)
    xyz = np.array([rec.points3D[p.point3D_id].xyz for p in im.points2D if p.has_point3D()]).reshape(-1, 3)
    xc = xyz @ r.T + t
    px, ok = cam.project(xc)
    if ok.sum() < LINK_MIN_TIES:
        return None
    k = min(LINK_NEIGHBOURS, int(ok.sum()))
    _d, nn = kdtree(px[ok]).query(keypoints, k=k)
    depth = np.median(xc[ok][:, 2][np.asarray(nn).reshape(len(keypoints), k)], axis=1)
    xn = cam.unproject(keypoints)
    return (np.column_stack([xn * depth[:, None], depth]) - t) @ r


def predicted(rec, image_id: int, ground: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """(pixels, inside) of the model points ``ground`` in the registered image ``image_id``."""
    im = rec.images[image_id]
    cam = intrinsics_of(rec.cameras[im.camera_id])
    pose = im.cam_from_world()
    px, ok = cam.project(ground @ np.asarray(pose.rotation.matrix()).T + np.asarray(pose.translation))
    return px, ok & cam.inside(np.where(ok[:, None], px, -1.0))


def guided_matches(desc_a: np.ndarray, pred: np.ndarray, kp_b: np.ndarray, desc_b: np.ndarray, radius: float,
                   ratio: float = LINK_RATIO) -> np.ndarray:
    """(M, 2) indices (a, b): each feature of A whose place in B is predicted (``pred``, (N, 2), NaN where not)
    matched to the nearest descriptor of B's features within ``radius`` of it, where that one is nearer than
    ``ratio`` x the second nearest there (or is alone there); a feature of B taken twice keeps its best."""
    kdtree = require("scipy.spatial", "matching weak links").cKDTree
    ok = np.all(np.isfinite(pred), axis=1)
    ia = np.nonzero(ok)[0]
    if len(ia) == 0 or len(kp_b) == 0:
        return np.zeros((0, 2), np.int64)
    k = min(LINK_NEIGHBOURS, len(kp_b))
    dist, nb = kdtree(kp_b).query(pred[ia], k=k, distance_upper_bound=radius)
    dist, nb = dist.reshape(len(ia), k), nb.reshape(len(ia), k)
    have = np.isfinite(dist)
    da = desc_a[ia].astype(np.float32)
    db = desc_b.astype(np.float32)
    nbc = np.where(have, nb, 0)
    d2 = ((db[nbc] - da[:, None, :]) ** 2).sum(-1)
    d2[~have] = np.inf
    order = np.argsort(d2, axis=1)
    best = np.take_along_axis(d2, order[:, :1], axis=1)[:, 0]
    second = np.take_along_axis(d2, order[:, 1:2], axis=1)[:, 0] if k > 1 else np.full(len(ia), np.inf)
    keep = np.isfinite(best) & (best < ratio ** 2 * second)
    a = ia[keep]
    b = np.take_along_axis(nbc, order[:, :1], axis=1)[:, 0][keep]
    cost = best[keep]
    first = {}
    for n in np.argsort(cost):  # each feature of B once, its best match
        first.setdefault(int(b[n]), int(n))
    sel = np.array(sorted(first.values()), dtype=np.int64)
    return np.column_stack([a[sel], b[sel]]) if len(sel) else np.zeros((0, 2), np.int64)


def verified(kp_a: np.ndarray, kp_b: np.ndarray, matches: np.ndarray, threshold: float) -> Tuple[np.ndarray, np.ndarray]:
    """(inlier matches, F) of ``matches`` under a fundamental matrix (OpenCV's MAGSAC++); none under 8."""
    cv2 = require("cv2", "matching weak links")
    if len(matches) < 8:
        return np.zeros((0, 2), np.int64), np.eye(3)
    f, inl = cv2.findFundamentalMat(kp_a[matches[:, 0]], kp_b[matches[:, 1]], cv2.USAC_MAGSAC, threshold, 0.999,
                                    10000)
    if f is None or inl is None:
        return np.zeros((0, 2), np.int64), np.eye(3)
    return matches[inl.ravel() > 0], np.asarray(f[:3], dtype=float)


def weak_links(pycolmap, rec, db_path: str, pairs: Sequence[Tuple[str, str]], progress: Progress) -> List[Link]:
    """Match the weak links among ``pairs`` (image names) of the registered images of ``rec`` again (the module's
    docstring) and write what verifies more into the database ``db_path``; returns the links rewritten."""
    ids = {rec.images[i].name: i for i in rec.reg_image_ids()}
    steep = steep_views(rec)
    db = pycolmap.Database.open(db_path)
    done: List[Link] = []
    try:
        feats: Dict[int, Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]] = {}

        def features(i):
            if i not in feats:
                kp = np.asarray(db.read_keypoints(i), dtype=float)[:, :2]
                feats[i] = (kp, np.asarray(db.read_descriptors(i).data), feature_ground(rec, i, kp))
            return feats[i]

        for na, nb in pairs:
            if na not in ids or nb not in ids:
                continue
            a, b = sorted((ids[na], ids[nb]))
            if a in steep or b in steep:
                continue
            kp_a, desc_a, ground_a = features(a)
            kp_b, desc_b, _ = features(b)
            if ground_a is None:
                continue
            pred, inside = predicted(rec, b, ground_a)
            overlap = int(inside.sum())
            if overlap < LINK_MIN_OVERLAP * len(kp_a):
                continue
            before = (len(db.read_two_view_geometry(a, b).inlier_matches) if db.exists_two_view_geometry(a, b) else 0)
            if before >= LINK_WEAK_SHARE * overlap:
                continue
            check_cancel(progress)
            cam_b = rec.cameras[rec.images[b].camera_id]
            diag = math.hypot(cam_b.width, cam_b.height)
            m = guided_matches(desc_a, np.where(inside[:, None], pred, np.nan), kp_b, desc_b, LINK_RADIUS_SHARE * diag)
            if before:  # the pair's own verified matches join the guided ones (each feature of A once)
                own = np.asarray(db.read_two_view_geometry(a, b).inlier_matches, dtype=np.int64).reshape(-1, 2)
                m = np.vstack([own, m[~np.isin(m[:, 0], own[:, 0]) & ~np.isin(m[:, 1], own[:, 1])]])
            inl, f = verified(kp_a, kp_b, m, max(1.0, LINK_RANSAC_SHARE * diag))
            if len(inl) <= before:
                continue
            tvg = pycolmap.TwoViewGeometry()
            tvg.config = pycolmap.TwoViewGeometryConfiguration.UNCALIBRATED
            tvg.F = f
            tvg.inlier_matches = inl.astype(np.uint32)
            if db.exists_two_view_geometry(a, b):
                db.update_two_view_geometry(a, b, tvg)
            else:
                db.write_two_view_geometry(a, b, tvg)
            done.append(Link(rec.images[a].name, rec.images[b].name, int(before), int(len(inl))))
    finally:
        db.close()
    return done


def reinforce(pycolmap, rec, job, pairs: Sequence[Tuple[str, str]], record: dict, progress: Progress,
              adjust: Callable[[], object]) -> None:
    """The weak links of the block ``rec`` matched again (:func:`weak_links`, the database of ``job``, a
    core.align.mapping.MappingJob), in rounds of up to LINK_ROUNDS: where a round rewrote a link, the block's points
    are triangulated again from every verified match with the poses held and ``adjust`` (the stage's final bundle
    adjustment) refines the block, whose poses predict the next round's matches better (seneca_south: the relative
    orientation across its weak link 3.67 deg off after the mapping, 0.44 after one round, 0.11 after two).  What
    was done goes to ``record["links"]``."""
    from .joining import triangulated  # the join's triangulation: two-view tracks kept (a weak link's points)

    if rec is None or rec.num_reg_images() < 3:
        return
    rounds = []
    for _ in range(LINK_ROUNDS):
        links = weak_links(pycolmap, rec, job.db_path, pairs, progress)
        if not links:
            break
        triangulated(pycolmap, rec, (job.db_path, job.images_dir, job.out_dir.rstrip("/\\") + "-links"), progress)
        adjust()
        rounds.append([lk.to_dict() for lk in links])
        progress.info(f"weak links matched again, guided by the block (round {len(rounds)}): {len(links)} pair(s), "
                      + ", ".join(f"{lk.a} + {lk.b} {lk.before} -> {lk.after}" for lk in links[:6])
                      + (" ..." if len(links) > 6 else ""))
    if rounds:
        record["links"] = {"rounds": rounds, "points": int(rec.num_points3D())}
