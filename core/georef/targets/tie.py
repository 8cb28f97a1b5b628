"""Candidates tied across photos through the block: tracks triangulated in the model frame.

Every pair of candidates of the same kind (and code) in two photos is triangulated (closest point of the two
rays); a pair whose point reprojects within ``tol_px`` of both and whose rays meet at a usable angle seeds a
track.  Seeds are taken best first: the point is projected into every photo, the nearest free candidate of the
same kind within ``tol_px`` joins, the point is re-triangulated from all of them (twice).  Rays are compared
in undistorted normalised coordinates (the full camera model, ``Camera.cam_from_img``), errors in pixels through
the focal length.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from .detect import Candidate


@dataclass
class Track:
    """One mark seen in several photos: its candidates, model-frame point and per-candidate residual (px)."""

    candidates: List[Candidate]
    xyz: np.ndarray
    residuals_px: np.ndarray

    @property
    def kind(self) -> str:
        return self.candidates[0].kind

    @property
    def code(self) -> Optional[int]:
        return self.candidates[0].code

    @property
    def size_px(self) -> float:
        return float(np.median([c.size_px for c in self.candidates]))


@dataclass
class _Rays:
    cands: List[Candidate]
    image: np.ndarray  # (N,) index into the photos
    xn: np.ndarray  # (N, 2) undistorted normalised
    d: np.ndarray  # (N, 3) unit ray in the model frame
    rot: np.ndarray  # (P, 3, 3) per photo
    t: np.ndarray  # (P, 3)
    centre: np.ndarray  # (P, 3)
    focal: np.ndarray  # (P,)
    label: List[Tuple[str, Optional[int]]]


def _rays(rec, cands: Dict[str, List[Candidate]]) -> _Rays:
    lookup = {rec.image(i).name: rec.image(i) for i in rec.reg_image_ids()}
    names = [n for n in cands if n in lookup and cands[n]]
    rot, tr, centre, focal = [], [], [], []
    flat: List[Candidate] = []
    idx, xn = [], []
    for k, n in enumerate(names):
        im = lookup[n]
        m = np.asarray(im.cam_from_world().matrix())
        rot.append(m[:, :3])
        tr.append(m[:, 3])
        centre.append(-m[:, :3].T @ m[:, 3])
        cam = rec.cameras[im.camera_id]
        focal.append(float(cam.mean_focal_length()))
        px = np.array([[c.x, c.y] for c in cands[n]], dtype=float)
        xn.append(np.asarray(cam.cam_from_img(px), dtype=float)[:, :2])
        flat += cands[n]
        idx += [k] * len(cands[n])
    rot_a = np.array(rot).reshape(-1, 3, 3)
    xn_a = np.vstack(xn) if xn else np.zeros((0, 2))
    idx_a = np.array(idx, dtype=int)
    d = np.einsum("nji,nj->ni", rot_a[idx_a], np.c_[xn_a, np.ones(len(xn_a))]) if len(idx_a) else np.zeros((0, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True) if len(d) else 1.0
    return _Rays(flat, idx_a, xn_a, d, rot_a, np.array(tr).reshape(-1, 3), np.array(centre).reshape(-1, 3),
                 np.array(focal), [(c.kind, c.code) for c in flat])


def _midpoints(c1, d1, c2, d2):
    """Closest points of ray pairs (broadcast): (X (..., 3), sine of the angle between the rays)."""
    w = c1 - c2
    b = np.sum(d1 * d2, -1)
    den = np.maximum(1.0 - b * b, 1e-12)
    s = (b * np.sum(d2 * w, -1) - np.sum(d1 * w, -1)) / den
    u = (np.sum(d2 * w, -1) - b * np.sum(d1 * w, -1)) / den
    x = 0.5 * ((c1 + s[..., None] * d1) + (c2 + u[..., None] * d2))
    return x, np.sqrt(den), s, u


def _errors(r: _Rays, x: np.ndarray, photo: int) -> Tuple[np.ndarray, np.ndarray]:
    """Projection of points ``x`` (M, 3) into ``photo``: (normalised (M, 2), depth (M,))."""
    xc = x @ r.rot[photo].T + r.t[photo]
    z = xc[:, 2]
    return xc[:, :2] / np.where(np.abs(z) > 1e-12, z, 1e-12)[:, None], z


def _seeds(r: _Rays, tol_px: float, min_angle: float) -> List[Tuple[float, int, int, np.ndarray]]:
    seeds = []
    n_photos = len(r.rot)
    by_photo = [np.nonzero(r.image == p)[0] for p in range(n_photos)]
    for p in range(n_photos):
        a = by_photo[p]
        for q in range(p + 1, n_photos):
            b = by_photo[q]
            if not len(a) or not len(b):
                continue
            same = np.array([[r.label[i] == r.label[j] for j in b] for i in a])
            x, sin, s, u = _midpoints(r.centre[p], r.d[a][:, None, :], r.centre[q], r.d[b][None, :, :])
            ok = same & (sin > min_angle) & (s > 0) & (u > 0)
            if not ok.any():
                continue
            ia, ib = np.nonzero(ok)
            pts = x[ia, ib]
            xa, za = _errors(r, pts, p)
            xb, zb = _errors(r, pts, q)
            ea = r.focal[p] * np.linalg.norm(xa - r.xn[a[ia]], axis=1)
            eb = r.focal[q] * np.linalg.norm(xb - r.xn[b[ib]], axis=1)
            good = (ea < tol_px) & (eb < tol_px) & (za > 0) & (zb > 0)
            for k in np.nonzero(good)[0]:
                seeds.append((float(max(ea[k], eb[k])), int(a[ia[k]]), int(b[ib[k]]), pts[k]))
    seeds.sort(key=lambda s: s[0])
    return seeds


def _triangulate(r: _Rays, members: Sequence[int]) -> np.ndarray:
    """Least-squares point nearest to the rays (sum of squared perpendicular distances)."""
    a = np.zeros((3, 3))
    b = np.zeros(3)
    for i in members:
        d = r.d[i]
        m = np.eye(3) - np.outer(d, d)
        a += m
        b += m @ r.centre[r.image[i]]
    return np.linalg.lstsq(a, b, rcond=None)[0]


def _grow(r: _Rays, x: np.ndarray, label, used: np.ndarray, tol_px: float) -> Tuple[List[int], np.ndarray]:
    members: List[int] = []
    for _ in range(2):
        members = []
        for p in range(len(r.rot)):
            idx = np.nonzero((r.image == p) & ~used)[0]
            idx = [i for i in idx if r.label[i] == label]
            if not idx:
                continue
            xn, z = _errors(r, x[None, :], p)
            if z[0] <= 0:
                continue
            e = r.focal[p] * np.linalg.norm(r.xn[idx] - xn[0], axis=1)
            k = int(np.argmin(e))
            if e[k] < tol_px:
                members.append(idx[k])
        if len(members) < 2:
            return members, x
        x = _triangulate(r, members)
    res = np.array([r.focal[r.image[i]] * np.linalg.norm(_errors(r, x[None, :], r.image[i])[0][0] - r.xn[i])
                    for i in members])
    return members, res


def tie_candidates(rec, cands: Dict[str, List[Candidate]], tol_px: float, min_angle_deg: float = 2.0) -> List[Track]:
    """Tracks of candidates across the registered photos of ``rec`` (pycolmap.Reconstruction), largest first."""
    r = _rays(rec, cands)
    used = np.zeros(len(r.cands), dtype=bool)
    tracks: List[Track] = []
    for _err, i, j, x in _seeds(r, tol_px, math.sin(math.radians(min_angle_deg))):
        if used[i] or used[j]:
            continue
        members, res = _grow(r, x, r.label[i], used, tol_px)
        if len(members) < 2 or i not in members and j not in members:
            continue
        xyz = _triangulate(r, members)
        used[members] = True
        tracks.append(Track([r.cands[m] for m in members], xyz, np.asarray(res, dtype=float)))
    tracks.sort(key=lambda t: -len(t.candidates))
    return tracks


def on_surface(rec, track: Track, tol_px: float, min_points: int = 5) -> bool:
    """Whether the track's point lies on the block's surface: its depth in the first photo against the depths of
    the tie points that project near the mark there (within three mark sizes).  Two rays tied by chance along an
    epipolar line meet anywhere in depth; a target lies on the ground.  Allowed: three times the depth precision
    of the intersection (pixel precision ``tol_px`` / 3 over the rays' angle) plus three robust spreads of the local
    depths.  With fewer than ``min_points`` tie points near the mark there is nothing to judge against: kept."""
    c = track.candidates[0]
    im = next(rec.image(i) for i in rec.reg_image_ids() if rec.image(i).name == c.image)
    cam = rec.cameras[im.camera_id]
    m = np.asarray(im.cam_from_world().matrix())
    pts = getattr(rec, "_targets_xyz", None)
    if pts is None:
        pts = np.array([p.xyz for p in rec.points3D.values()], dtype=float).reshape(-1, 3)
        setattr(rec, "_targets_xyz", pts) if hasattr(rec, "__dict__") else None
    if len(pts) < min_points:
        return True
    xc = pts @ m[:, :3].T + m[:, 3]
    front = xc[:, 2] > 0
    xn = xc[front, :2] / xc[front, 2:3]
    z = xc[front, 2]
    f = float(cam.mean_focal_length())
    cn = np.asarray(cam.cam_from_img(np.array([[c.x, c.y]])), dtype=float)[0, :2]
    near = np.linalg.norm(xn - cn, axis=1) * f < 3.0 * max(c.size_px, 4.0)
    if near.sum() < min_points:
        return True
    local = z[near]
    med = float(np.median(local))
    spread = 1.4826 * float(np.median(np.abs(local - med)))
    d = float((m[:, :3] @ track.xyz + m[:, 3])[2])
    centres = [-np.asarray(rec.image(i).cam_from_world().matrix())[:, :3].T
               @ np.asarray(rec.image(i).cam_from_world().matrix())[:, 3]
               for i in rec.reg_image_ids() if rec.image(i).name in {k.image for k in track.candidates}]
    rays = [(track.xyz - cc) / np.linalg.norm(track.xyz - cc) for cc in centres]
    sin = max(float(np.linalg.norm(np.cross(a, b))) for a in rays for b in rays) if len(rays) > 1 else 0.0
    precision = d * (tol_px / 3.0) / f / max(sin, 1e-3)
    return abs(d - med) <= 3.0 * precision + 3.0 * spread
