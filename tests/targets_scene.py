"""A small synthetic block with ground targets (Find targets, issue 34): the rendered truth of every mark.

A tilted ground plane (sand-like texture, 5 mm texels) with checkerboard, circular, ArUco and cross targets, photographed
by a 640 x 480 pinhole camera from a grid of nadir shots and a few obliques.  The plane makes every photo an exact
homography of the texture (rendered 2x supersampled, then averaged), so the truth of a target's centre is its
projection.  One target is covered by an occluder in one photo; targets cut by a photo's border are there
naturally.  ``visible`` says, per photo, which targets a machine should find: whole in the frame (with a margin
of a pixel), not covered, and at least ``MIN_SIDE_PX`` on its shortest side (``small`` lists the
whole ones under that: the far side of the obliques, 12 px markers whose cells are 2 px).

The aligned model is built from the truth (poses, camera, tie points on the plane), moved into an arbitrary
model frame (a similarity), as an alignment would give it.
"""
import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Tuple

import cv2
import numpy as np

RES = 0.005  # m per texel
EXTENT = (16.0, 12.0)  # m
SLOPE = (0.03, -0.02)  # ground z = a x + b y
OFFSET = np.array([500000.0, 4000000.0, 100.0])  # local -> world (EPSG:32611)
SIZE = 0.5  # target side (m)
W, H, F = 640, 480, 560.0
MIN_SIDE_PX = 20.0  # a target whose shortest side is smaller in a photo is not asked for (the far side of obliques)


@dataclass
class Target:
    name: str
    kind: str  # checkerboard, circle, aruco, cross
    x: float
    y: float
    code: int = -1

    @property
    def z(self) -> float:
        return SLOPE[0] * self.x + SLOPE[1] * self.y


@dataclass
class Scene:
    targets: List[Target]
    shots: List[Tuple[str, np.ndarray, np.ndarray]]  # name, R (cam from world), centre
    photos: Dict[str, str] = field(default_factory=dict)
    truth: Dict[str, Dict[str, Tuple[float, float]]] = field(default_factory=dict)  # image -> name -> px
    visible: Dict[str, List[str]] = field(default_factory=dict)
    occluded: List[Tuple[str, str]] = field(default_factory=list)
    small: List[Tuple[str, str]] = field(default_factory=list)  # whole but under MIN_SIDE_PX: not asked for
    cut: List[Tuple[str, str]] = field(default_factory=list)  # the target's central half not all in the photo


def _targets(seed: int, crosses: bool) -> List[Target]:
    rng = np.random.default_rng(seed)
    kinds = [("checkerboard", "chk_" + c, -1) for c in "abc"] + [("circle", "ring_" + c, -1) for c in "abc"] \
        + [("aruco", f"aruco_{k}", k) for k in (3, 7, 11)] + ([("cross", "cross_" + c, -1) for c in "ab"]
                                                             if crosses else [])
    pos: List[Tuple[float, float]] = []
    while len(pos) < len(kinds):
        p = (float(rng.uniform(2.0, EXTENT[0] - 2.0)), float(rng.uniform(2.0, EXTENT[1] - 2.0)))
        if all(math.hypot(p[0] - q[0], p[1] - q[1]) > 2.5 for q in pos):
            pos.append(p)
    return [Target(n, k, x, y, c) for (k, n, c), (x, y) in zip(kinds, pos)]


def _paint(tex: np.ndarray, t: Target) -> None:
    n = int(round(SIZE / RES))
    u0, v0 = int(round(t.x / RES)) - n // 2, int(round(t.y / RES)) - n // 2
    patch = np.full((n, n), 235.0, np.float32)
    if t.kind == "checkerboard":
        patch[: n // 2, : n // 2] = 20.0
        patch[n // 2:, n // 2:] = 20.0
    elif t.kind == "circle":
        yy, xx = np.mgrid[0:n, 0:n] + 0.5
        r = 0.3 * n
        d = np.hypot(xx - n / 2, yy - n / 2)
        patch = np.where(d < r, 20.0, 235.0).astype(np.float32)
    elif t.kind == "cross":  # a black tarp with a white cross (COPR's kind), bars a sixth of the side
        patch[:] = 20.0
        w = n // 6
        patch[n // 2 - w // 2:n // 2 + w - w // 2, :] = 235.0
        patch[:, n // 2 - w // 2:n // 2 + w - w // 2] = 235.0
    else:
        side = int(round(0.8 * n))
        marker = cv2.aruco.generateImageMarker(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50), t.code, side)
        b = (n - side) // 2
        # the texture is seen from above with its rows flipped (x east, y north, z up): paint the code mirrored
        patch[b:b + side, b:b + side] = np.where(marker[::-1] > 127, 235.0, 20.0)
    tex[v0:v0 + n, u0:u0 + n] = patch
    # the truth is the centre of the painted patch, in texels: u0 + n / 2 (texel edges at integers)
    t.x, t.y = (u0 + n / 2) * RES, (v0 + n / 2) * RES


def _texture(seed: int, targets: List[Target]) -> np.ndarray:
    rng = np.random.default_rng(seed + 7)
    h, w = int(EXTENT[1] / RES), int(EXTENT[0] / RES)
    low = cv2.resize(rng.normal(0, 1, (h // 200, w // 200)).astype(np.float32), (w, h), interpolation=cv2.INTER_CUBIC)
    mid = cv2.resize(rng.normal(0, 1, (h // 8, w // 8)).astype(np.float32), (w, h), interpolation=cv2.INTER_LINEAR)
    tex = 140.0 + 18.0 * low + 10.0 * mid + 6.0 * rng.normal(0, 1, (h, w)).astype(np.float32)
    for t in targets:
        _paint(tex, t)
    return np.clip(tex, 0, 255).astype(np.float32)


def _look(centre: np.ndarray, target: np.ndarray) -> np.ndarray:
    z = target - centre
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 1.0, 0.0])
    if np.linalg.norm(x) < 1e-6:
        x = np.array([1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.array([x, y, z])


def _shots() -> List[Tuple[str, np.ndarray, np.ndarray]]:
    out = []
    k = 0
    for cy in (3.5, 6.0, 8.5):
        for cx in (4.0, 8.0, 12.0):
            c = np.array([cx, cy, 7.0])
            out.append((f"IMG_{k:03d}.png", _look(c, np.array([cx, cy, 0.0]) + [0.01, 0.0, 0.0]), c))
            k += 1
    for c, aim in (((1.0, 6.0, 6.0), (6.0, 6.0, 0.0)), ((15.0, 6.0, 6.0), (10.0, 6.0, 0.0)),
                   ((8.0, -0.5, 6.0), (8.0, 4.5, 0.0)), ((8.0, 12.5, 6.0), (8.0, 7.5, 0.0))):
        out.append((f"IMG_{k:03d}.png", _look(np.array(c), np.array(aim)), np.array(c, dtype=float)))
        k += 1
    return out


def _homography(rot: np.ndarray, centre: np.ndarray, s: int) -> np.ndarray:
    """Texture array coordinates -> supersampled photo array coordinates."""
    k = np.array([[F, 0, W / 2], [0, F, H / 2], [0, 0, 1.0]])
    t = -rot @ centre
    plane = np.c_[rot[:, 0] + SLOPE[0] * rot[:, 2], rot[:, 1] + SLOPE[1] * rot[:, 2], t]
    a = np.array([[RES, 0, 0.5 * RES], [0, RES, 0.5 * RES], [0, 0, 1.0]])  # texel index -> x, y (centre +0.5)
    out = np.array([[s, 0, -0.5], [0, s, -0.5], [0, 0, 1.0]])
    return out @ k @ plane @ a


def project(rot: np.ndarray, centre: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """COLMAP pixel coordinates of local points."""
    xc = (np.asarray(xyz, dtype=float) - centre) @ rot.T
    return np.c_[F * xc[:, 0] / xc[:, 2] + W / 2, F * xc[:, 1] / xc[:, 2] + H / 2]


def render(folder: str, seed: int = 5, crosses: bool = False) -> Scene:
    """Render the block into ``folder``; returns the scene with its truth.  ``crosses``: two cross targets as well
    (the nine others stay where they are)."""
    targets = _targets(seed, crosses)
    tex = _texture(seed, targets)
    scene = Scene(targets, _shots())
    rng = np.random.default_rng(seed + 11)
    os.makedirs(folder, exist_ok=True)
    s = 2
    for k, (name, rot, centre) in enumerate(scene.shots):
        big = cv2.warpPerspective(tex, _homography(rot, centre, s), (W * s, H * s), flags=cv2.INTER_LINEAR,
                                  borderMode=cv2.BORDER_REFLECT)
        img = cv2.resize(big, (W, H), interpolation=cv2.INTER_AREA) + rng.normal(0, 1.5, (H, W))
        scene.truth[name], scene.visible[name] = {}, []
        for t in targets:
            c = project(rot, centre, [[t.x, t.y, t.z]])[0]
            half = 0.5 * SIZE
            corners = project(rot, centre, [[t.x + dx, t.y + dy, t.z + SLOPE[0] * dx + SLOPE[1] * dy]
                                            for dx in (-half, half) for dy in (-half, half)])
            scene.truth[name][t.name] = (float(c[0]), float(c[1]))
            whole = bool(np.all((corners >= 1) & (corners <= [W - 1, H - 1])))
            if whole and not scene.occluded and k >= 1:
                # the first whole target of the second photo gets a pole laid over its centre from one side
                x, y = int(c[0]), int(c[1])
                img[y - 3:y + 4, max(0, x - 40):x + 4] = 90.0
                scene.occluded.append((name, t.name))
                continue
            quad = corners[[0, 1, 3, 2]]
            side = min(np.linalg.norm(quad - np.roll(quad, 1, axis=0), axis=1))
            if whole and side >= MIN_SIDE_PX:
                scene.visible[name].append(t.name)
            elif whole:
                scene.small.append((name, t.name))
            else:
                inner = project(rot, centre, [[t.x + dx, t.y + dy, t.z + SLOPE[0] * dx + SLOPE[1] * dy]
                                              for dx in (-SIZE / 4, SIZE / 4) for dy in (-SIZE / 4, SIZE / 4)])
                if not np.all((inner >= 0) & (inner <= [W, H])):
                    scene.cut.append((name, t.name))
        path = os.path.join(folder, name)
        cv2.imwrite(path, np.clip(img, 0, 255).astype(np.uint8))
        scene.photos[name] = path
    return scene


def reconstruction(scene: Scene, seed: int = 5):
    """The aligned model from the truth in an arbitrary model frame (pycolmap.Reconstruction)."""
    import pycolmap

    rec = pycolmap.Reconstruction()
    cam = pycolmap.Camera.create_from_model_name(1, "PINHOLE", F, W, H)
    cam.params = np.array([F, F, W / 2, H / 2])
    rec.add_camera_with_trivial_rig(cam)
    gx, gy = np.meshgrid(np.arange(0.25, EXTENT[0], 0.5), np.arange(0.25, EXTENT[1], 0.5))
    pts = np.c_[gx.ravel(), gy.ravel(), SLOPE[0] * gx.ravel() + SLOPE[1] * gy.ravel()]
    obs: Dict[int, List[Tuple[int, int]]] = {}
    for k, (name, rot, centre) in enumerate(scene.shots, start=1):
        px = project(rot, centre, pts)
        inside = np.nonzero((px[:, 0] > 0) & (px[:, 0] < W) & (px[:, 1] > 0) & (px[:, 1] < H))[0]
        im = pycolmap.Image(name=name, keypoints=px[inside], camera_id=1, image_id=k)
        rec.add_image_with_trivial_frame(im, pycolmap.Rigid3d(pycolmap.Rotation3d(rot), -rot @ centre))
        for j, i in enumerate(inside):
            obs.setdefault(int(i), []).append((k, j))
    for i, els in obs.items():
        if len(els) >= 2:
            track = pycolmap.Track()
            for k, j in els:
                track.add_element(k, j)
            rec.add_point3D(pts[i], track, np.array([128, 128, 128], dtype=np.uint8))
    rng = np.random.default_rng(seed + 3)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    rec.transform(pycolmap.Sim3d(0.2, pycolmap.Rotation3d(q), rng.normal(0, 5.0, 3)))
    rec.update_point_3d_errors()
    return rec


def write_targets_csv(scene: Scene, path: str) -> str:
    with open(path, "w", encoding="utf-8") as out:
        out.write("# crs: EPSG:32611\nname,x,y,z\n")
        for t in scene.targets:
            w = np.array([t.x, t.y, t.z]) + OFFSET
            out.write(f"{t.name},{w[0]:.4f},{w[1]:.4f},{w[2]:.4f}\n")
    return path
