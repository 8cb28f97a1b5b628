"""A synthetic wide-angle rolling-shutter block over tall, sparse trees at low altitude, whose truth is known (issue
37 Must show; the real case: a Parrot Sequoia rig's RGB camera over a November park, ../shared/data/garfield_rgb_small).

- **Scene** (:class:`Woodland`, local metres, world = local + ``tests.synthetic.ORIGIN`` in EPSG:32633): gently
  rolling ground painted as a park in November -- lawn (fine grass grain, mottling, fallen leaves), soil paths, an
  asphalt car park with painted bay lines and parked cars (boxes) -- with the long shadows of a low sun; and bare
  deciduous trees in true 3-D, 10-18 m tall: a trunk and a recursive crown of thin branches (down to twigs of a
  centimetre or two), so that at 30 m above the ground a tree top is twice as near as the ground: parallax of
  hundreds of pixels between neighbouring photos, branches crossing each other at other depths, the ground seen
  through them.
- **Camera** (:data:`CAMERA`): 1200 x 900 px, horizontal field of view about 74 degrees, strong barrel distortion
  (OpenCV k1 -0.25, k2 0.08: 155 px at the corners), a rolling shutter: row ``v`` is exposed at
  ``(v - height / 2) x line_time`` from the photo's time, from the pose of that instant (the drone moving along its
  strip at ``speed`` and turning a little, :class:`Shot`); by default the frame reads out in 40 ms at 8 m/s (a
  Sequoia RGB frame: 3,456 lines in about 40-60 ms; at a third of its size tens of microseconds a line).
- **Block** (:func:`woodland_block`): strips along local x (serpentine), photos every few metres (80 % forward and
  65 % side overlap by default): every photo overlaps many others.  The truth of a photo (``Shot.centre``,
  ``Shot.rotation``) is its pose at the middle row.
- **Metadata**: each JPEG carries EXIF as the camera writes it (make, model, FocalLengthIn35mmFilm, GPS latitude,
  longitude and altitude with N(0, ``gps_sigma``) noise); ``camera_positions.csv`` beside the images folder holds
  the same noisy positions in EPSG:32633.

Rendering is vectorised NumPy/OpenCV: per photo the ground is ray-cast for every sub-pixel (``supersample`` ^ 2 per
pixel) from its row's pose, the branches are projected through the same rolling-shutter model (each point's row
found by fixed-point iteration) and drawn far to near with anti-aliased lines over it, then the image is reduced,
vignetted, given sensor noise and written.  ``WoodlandBlock.render(folder, jobs=2)`` renders in forked processes.
"""
from __future__ import annotations

import math
import multiprocessing
import os
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Dict, List, Optional, Tuple

import cv2
import numpy as np

from tests import synthetic as syn

# the Sequoia's 28 mm-equivalent lens at 1,200 px: focal 900 px (FocalLengthIn35mmFilm 26), barrel distortion
CAMERA = syn.CameraModel(1200, 900, 900.0, 900.0, 601.3, 448.2, k1=-0.25, k2=0.08, p1=0.0005, p2=-0.0003)
FRAME_READOUT_S = 0.040  # a full frame read out in 40 ms
SPEED = 8.0  # m/s along the strip
BASE_Z = 210.0  # m, the ground's mean height
MAKE, MODEL = "Synth", "WideRS"

# colours (linear 0..1 RGB) of the ground's kinds
LAWN = np.array([0.36, 0.38, 0.22], np.float32)
LEAVES = np.array([0.50, 0.33, 0.16], np.float32)
SOIL = np.array([0.42, 0.34, 0.26], np.float32)
ASPHALT = np.array([0.22, 0.22, 0.23], np.float32)
PAINT = np.array([0.85, 0.85, 0.82], np.float32)
BARK = np.array([0.30, 0.27, 0.25], np.float32)
CAR_COLOURS = np.array([[0.75, 0.75, 0.76], [0.12, 0.12, 0.14], [0.55, 0.10, 0.08], [0.15, 0.22, 0.45],
                        [0.45, 0.46, 0.48], [0.80, 0.78, 0.70]], np.float32)


# --------------------------------------------------------------------------------------------------
# poses in time: the rolling shutter
# --------------------------------------------------------------------------------------------------


def rodrigues(rotvecs: np.ndarray) -> np.ndarray:
    """Rotation matrices (N,3,3) of rotation vectors (N,3) (vectorised cv2.Rodrigues)."""
    w = np.asarray(rotvecs, dtype=np.float64).reshape(-1, 3)
    theta = np.linalg.norm(w, axis=1)
    safe = np.where(theta > 1e-12, theta, 1.0)
    k = w / safe[:, None]
    kx = np.zeros((len(w), 3, 3))
    kx[:, 0, 1], kx[:, 0, 2], kx[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    kx[:, 1, 0], kx[:, 2, 0], kx[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    return np.eye(3)[None] + s * kx + (1.0 - c) * (kx @ kx)


@dataclass
class Shot(syn.Shot):
    """One photo: ``rotation`` and ``centre`` are the pose at its middle row (time 0); row ``v`` is exposed at
    ``(v - height / 2) x line_time`` s, from centre + velocity x t, turned by angular_rate x t (camera frame)."""

    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))  # m/s, local frame
    angular_rate: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s, camera frame
    line_time: float = 0.0  # s per image row (0: a global shutter)
    height: int = 0  # image rows

    def time_of_row(self, v: np.ndarray) -> np.ndarray:
        return (np.asarray(v, dtype=np.float64) - 0.5 * self.height) * self.line_time

    def poses_at(self, t: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """(rotations (N,3,3) camera-from-world, centres (N,3)) at times ``t`` (N,)."""
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        rot = rodrigues(t[:, None] * self.angular_rate[None, :]) @ self.rotation[None]
        return rot, self.centre[None, :] + t[:, None] * self.velocity[None, :]

    def project(self, camera: syn.CameraModel, xyz: np.ndarray, iterations: int = 4
                ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pixels (N,2), depths (N,), undistorted radius (N,)) of local points through the rolling shutter: each
        point's row found by fixed-point iteration (the row exposed when the point is seen on it)."""
        xyz = np.atleast_2d(np.asarray(xyz, dtype=np.float64))
        v = np.full(len(xyz), 0.5 * self.height)
        for _ in range(iterations if self.line_time else 1):
            rot, centre = self.poses_at(self.time_of_row(v))
            xc = np.einsum("nij,nj->ni", rot, xyz - centre)
            z = np.where(np.abs(xc[:, 2]) > 1e-6, xc[:, 2], 1e-6)
            xn = xc[:, :2] / z[:, None]
            px = camera.pixel_from_normalized(camera.distort(np.clip(xn, -3.0, 3.0)))
            v = np.clip(px[:, 1], -0.5 * self.height, 1.5 * self.height)
        return px, xc[:, 2], np.hypot(xn[:, 0], xn[:, 1])


# --------------------------------------------------------------------------------------------------
# the scene
# --------------------------------------------------------------------------------------------------


@dataclass
class Car:
    cx: float
    cy: float
    half_w: float  # across the car
    half_l: float  # along it
    angle: float  # radians, its length from local x
    height: float
    colour: np.ndarray


@dataclass
class Branches:
    """Straight pieces of trunks and branches: p0, p1 (N,3) local, radius (N,), tone (N,) x BARK."""

    p0: np.ndarray
    p1: np.ndarray
    radius: np.ndarray
    tone: np.ndarray

    def __len__(self) -> int:
        return len(self.radius)


@dataclass
class Woodland:
    seed: int
    bounds: Tuple[float, float, float, float]  # xmin, ymin, xmax, ymax (local)
    hills: np.ndarray  # (K,4): x, y, amplitude, sigma
    carpark: Tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
    paths: List[Tuple[Tuple[float, float], Tuple[float, float], float]]  # p0, p1, half width
    cars: List[Car]
    trees: List[Tuple[float, float, float]]  # x, y, height of each tree
    branches: Branches
    sun: Tuple[float, float] = (215.0, 22.0)  # azimuth (degrees from local x towards y), elevation
    base_z: float = BASE_Z
    texture_res: float = 0.025  # m per texture cell
    ground_res: float = 0.5  # m per ground-height cell
    _rasters: Dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    # ---- heights
    def ground_at(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        z = np.full(np.broadcast(x, y).shape, self.base_z)
        for hx, hy, amp, sig in self.hills:
            z = z + amp * np.exp(-((x - hx) ** 2 + (y - hy) ** 2) / (2.0 * sig * sig))
        return z

    def ground_raster(self) -> np.ndarray:
        if "ground" not in self._rasters:
            xs, ys = self._grid(self.ground_res)
            gx, gy = np.meshgrid(xs, ys)
            self._rasters["ground"] = self.ground_at(gx, gy).astype(np.float32)
        return self._rasters["ground"]

    def _grid(self, res: float) -> Tuple[np.ndarray, np.ndarray]:
        xmin, ymin, xmax, ymax = self.bounds
        nx, ny = int(math.ceil((xmax - xmin) / res)), int(math.ceil((ymax - ymin) / res))
        return xmin + (np.arange(nx) + 0.5) * res, ymax - (np.arange(ny) + 0.5) * res  # row 0 north

    def raster_coords(self, x, y, res: float) -> Tuple[np.ndarray, np.ndarray]:
        xmin, _, _, ymax = self.bounds
        return ((np.asarray(x) - xmin) / res - 0.5).astype(np.float32), ((ymax - np.asarray(y)) / res - 0.5).astype(
            np.float32)

    def ground_fast(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The ground's height from its raster (bilinear), any shape."""
        mx, my = self.raster_coords(x, y, self.ground_res)
        return syn._sample(self.ground_raster(), mx, my)

    # ---- the ground's colours
    def texture(self) -> np.ndarray:
        """RGB orthoimage (uint8, row 0 north) at ``texture_res``: lawn, leaves, paths, the car park, shadows."""
        if "texture" not in self._rasters:
            self._rasters["texture"] = _paint_ground(self)
        return self._rasters["texture"]


def _noise(rng: np.random.Generator, shape: Tuple[int, int], res: float,
           octaves: Tuple[Tuple[float, float], ...]) -> np.ndarray:
    """Band-limited noise (float32) of ``shape`` cells of ``res`` m: per (wavelength m, weight) random values every
    half wavelength, cubic interpolation between."""
    ny, nx = shape
    out = np.zeros(shape, np.float32)
    for wavelength, weight in octaves:
        step = wavelength / 2.0
        gx, gy = int(math.ceil(nx * res / step)) + 4, int(math.ceil(ny * res / step)) + 4
        coarse = rng.normal(0.0, 1.0, (gy, gx)).astype(np.float32)
        fine = cv2.resize(coarse, (int(round(gx * step / res)), int(round(gy * step / res))),
                          interpolation=cv2.INTER_CUBIC)
        out += weight * fine[:ny, :nx]
    return out


def _paint_ground(scene: Woodland) -> np.ndarray:
    rng = np.random.default_rng(scene.seed + 11)
    res = scene.texture_res
    xs, ys = scene._grid(res)
    ny, nx = len(ys), len(xs)
    xmin, _, _, ymax = scene.bounds

    def cells(x, y):  # local -> texture cell (col, row) as cv2 points x 16 (shift 4)
        return (int(round(((x - xmin) / res - 0.5) * 16)), int(round(((ymax - y) / res - 0.5) * 16)))

    grain = _noise(rng, (ny, nx), res, ((0.08, 0.8), (0.16, 0.7), (0.4, 0.5), (1.0, 0.5), (3.0, 0.5), (8.0, 0.4)))
    grain /= 1.4
    kind = np.zeros((ny, nx), np.uint8)  # 0 lawn, 1 leaves, 2 path, 3 asphalt, 4 paint
    leaves = _noise(rng, (ny, nx), res, ((0.15, 1.0), (0.5, 0.8), (2.0, 0.6)))
    kind[leaves > 1.1] = 1
    for p0, p1, hw in scene.paths:
        cv2.line(kind, cells(*p0), cells(*p1), 2, thickness=int(round(2 * hw / res)), lineType=cv2.LINE_8, shift=4)
    x0, y0, x1, y1 = scene.carpark
    cv2.rectangle(kind, cells(x0, y1), cells(x1, y0), 3, thickness=-1, shift=4)
    for y_row, direction in ((y0 + 5.5, -1.0), (y1 - 5.5, 1.0)):  # two rows of bays, lines 5 m long, 2.5 m apart
        for xb in np.arange(x0 + 1.0, x1 - 0.5, 2.5):
            cv2.line(kind, cells(xb, y_row), cells(xb, y_row + direction * 5.0), 4,
                     thickness=max(1, int(round(0.12 / res))), lineType=cv2.LINE_8, shift=4)
        cv2.line(kind, cells(x0 + 1.0, y_row), cells(x1 - 1.0, y_row), 4, thickness=max(1, int(round(0.12 / res))),
                 lineType=cv2.LINE_8, shift=4)
    colours = np.stack([LAWN, LEAVES, SOIL, ASPHALT, PAINT])
    contrast = np.array([0.18, 0.28, 0.15, 0.05, 0.03], np.float32)
    rgb = colours[kind] * (1.0 + (contrast[kind] * grain)[..., None])
    for _ in range(25):  # oil stains on the asphalt
        c = cells(rng.uniform(x0 + 1, x1 - 1), rng.uniform(y0 + 1, y1 - 1))
        mask = np.zeros((ny, nx), np.uint8)
        cv2.ellipse(mask, c, (int(rng.uniform(0.2, 0.6) / res * 16), int(rng.uniform(0.2, 0.5) / res * 16)),
                    float(rng.uniform(0, 180)), 0, 360, 1, -1, shift=4)
        rgb[mask > 0] *= 0.75
    rgb *= _shadows(scene, ny, nx)[..., None]
    return np.clip(rgb * 255.0, 0, 255).astype(np.uint8)


def _shadows(scene: Woodland, ny: int, nx: int) -> np.ndarray:
    """The light (0.45..1) left on the ground by the trees' shadows (the branches cast along the sun's direction
    onto the ground, softened with the distance to what casts them) and the cars'."""
    res = scene.texture_res
    az, el = (math.radians(a) for a in scene.sun)
    travel = np.array([-math.cos(az), -math.sin(az)]) / math.tan(el)  # ground shift per metre of height
    xmin, _, _, ymax = scene.bounds
    shade = np.zeros((ny, nx), np.float32)
    b = scene.branches
    for lo, hi, blur in ((0.0, 4.0, 0.03), (4.0, 9.0, 0.08), (9.0, 99.0, 0.15)):  # near, middle and far casters
        layer = np.zeros((ny, nx), np.uint8)
        zmid = 0.5 * (b.p0[:, 2] + b.p1[:, 2]) - scene.base_z
        for k in np.flatnonzero((zmid >= lo) & (zmid < hi)):
            ends = []
            for p in (b.p0[k], b.p1[k]):
                g = p[:2] + (p[2] - scene.base_z) * travel
                ends.append((int(round(((g[0] - xmin) / res - 0.5) * 16)), int(round(((ymax - g[1]) / res - 0.5) * 16))))
            cv2.line(layer, ends[0], ends[1], 255, thickness=max(1, int(round(2 * b.radius[k] / res))),
                     lineType=cv2.LINE_AA, shift=4)
        shade = np.maximum(shade, cv2.GaussianBlur(layer.astype(np.float32) / 255.0, (0, 0), blur / res))
    layer = np.zeros((ny, nx), np.uint8)
    for car in scene.cars:
        c = np.array([car.cx, car.cy]) + 0.5 * car.height * travel
        box = cv2.boxPoints(((((c[0] - xmin) / res - 0.5), ((ymax - c[1]) / res - 0.5)),
                             (2 * car.half_l / res, 2 * car.half_w / res), -math.degrees(car.angle)))
        cv2.fillConvexPoly(layer, np.round(box * 16).astype(np.int32), 255, lineType=cv2.LINE_AA, shift=4)
    shade = np.maximum(shade, cv2.GaussianBlur(layer.astype(np.float32) / 255.0, (0, 0), 0.05 / res))
    return 1.0 - 0.55 * np.clip(shade, 0.0, 1.0)


def _grow_tree(rng: np.random.Generator, base: np.ndarray, height: float) -> Tuple[list, list, list, list]:
    """One bare tree: a trunk and a crown of branches splitting 2-4 ways for five levels, each bent a little
    (3 straight pieces), scaled so that its top is ``height`` above ``base``."""
    p0s, p1s, radii, tones = [], [], [], []
    trunk_h = rng.uniform(0.28, 0.42)  # of the height, before scaling
    work = [(base, np.array([*rng.normal(0, 0.05, 2), 1.0]), trunk_h, 0.025, 0)]  # (start, dir, length, radius, level)
    tone0 = rng.uniform(0.8, 1.2)
    while work:
        start, d, length, radius, level = work.pop()
        d = d / np.linalg.norm(d)
        p = start
        tone = tone0 * rng.uniform(0.85, 1.15)
        for _ in range(3):
            d = d + rng.normal(0.0, 0.12, 3)
            d[2] = max(d[2], 0.05)
            d = d / np.linalg.norm(d)
            q = p + d * length / 3.0
            p0s.append(p)
            p1s.append(q)
            radii.append(radius)
            tones.append(tone)
            p = q
        if level >= 5:
            continue
        n = int(rng.integers(2, 5)) if level else int(rng.integers(3, 6))
        for _ in range(n):
            axis = np.cross(d, rng.normal(0.0, 1.0, 3))
            axis /= np.linalg.norm(axis)
            angle = rng.uniform(0.35, 0.8) if level else rng.uniform(0.5, 0.95)
            child = d * math.cos(angle) + np.cross(axis, d) * math.sin(angle)
            child[2] = max(child[2] + 0.25, 0.1)  # deciduous crowns reach up
            frac = rng.uniform(0.55, 1.0) if level else 1.0
            origin = start + (p - start) * frac
            work.append((origin, child, length * rng.uniform(0.6, 0.8) * (1.5 if not level else 1.0),
                         radius * rng.uniform(0.5, 0.62), level + 1))
    p0, p1 = np.array(p0s), np.array(p1s)
    top = max(p0[:, 2].max(), p1[:, 2].max()) - base[2]
    s = height / top
    return list(base + (p0 - base) * s), list(base + (p1 - base) * s), list(np.array(radii) * s), tones


def make_woodland(seed: int, bounds: Tuple[float, float, float, float], n_trees: int = 20,
                  tree_heights: Tuple[float, float] = (10.0, 18.0), n_cars: int = 9) -> Woodland:
    """A park: gentle hills, a car park (a fifth of the area, one side) with ``n_cars`` parked cars, two paths,
    ``n_trees`` bare trees on the lawns under the flight, at least 6 m apart and 5 m from the car park."""
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = bounds
    w, h = xmax - xmin, ymax - ymin
    hills = np.array([[rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-1.0, 2.0),
                       rng.uniform(0.25, 0.45) * max(w, h)] for _ in range(4)])
    cx0 = xmin + rng.uniform(0.45, 0.55) * w
    carpark = (cx0, ymin + 0.30 * h, cx0 + 0.22 * w, ymin + 0.30 * h + 17.0)
    paths = [((xmin, ymin + rng.uniform(0.6, 0.8) * h), (xmax, ymin + rng.uniform(0.6, 0.8) * h), 1.2),
             ((xmin + rng.uniform(0.15, 0.3) * w, ymin), (xmin + rng.uniform(0.2, 0.35) * w, ymax), 1.0)]
    cars = []
    x0, y0, x1, y1 = carpark
    slots = [(xb + 1.25, y0 + 3.0) for xb in np.arange(x0 + 1.0, x1 - 3.0, 2.5)] + \
            [(xb + 1.25, y1 - 3.0) for xb in np.arange(x0 + 1.0, x1 - 3.0, 2.5)]
    for k in rng.choice(len(slots), size=min(n_cars, len(slots)), replace=False):
        sx, sy = slots[k]
        cars.append(Car(sx + rng.normal(0, 0.1), sy + rng.normal(0, 0.15), rng.uniform(0.85, 0.95),
                        rng.uniform(2.1, 2.4), math.pi / 2 + rng.normal(0, 0.03), rng.uniform(1.4, 1.6),
                        CAR_COLOURS[rng.integers(len(CAR_COLOURS))]))
    scene = Woodland(seed, bounds, hills, carpark, paths, cars, [], Branches(*(np.zeros((0, 3)),) * 2, np.zeros(0),
                                                                              np.zeros(0)))
    trees: List[Tuple[float, float, float]] = []
    inner = (xmin + 0.15 * w, xmax - 0.15 * w, ymin + 0.2 * h, ymax - 0.2 * h)  # where the photos look down
    parts: Tuple[list, list, list, list] = ([], [], [], [])
    for _ in range(2000):
        if len(trees) >= n_trees:
            break
        x, y = rng.uniform(*inner[:2]), rng.uniform(*inner[2:])
        if x0 - 5 < x < x1 + 5 and y0 - 5 < y < y1 + 5:
            continue
        if any(math.hypot(x - a, y - b) < 6.0 for a, b, _ in trees):
            continue
        height = float(rng.uniform(*tree_heights))
        base = np.array([x, y, float(scene.ground_at(x, y)) - 0.2])
        for acc, new in zip(parts, _grow_tree(rng, base, height)):
            acc.extend(new)
        trees.append((x, y, height))
    scene.trees = trees
    scene.branches = Branches(np.array(parts[0]), np.array(parts[1]), np.array(parts[2]), np.array(parts[3]))
    return scene


# --------------------------------------------------------------------------------------------------
# rendering
# --------------------------------------------------------------------------------------------------


@lru_cache(maxsize=2)
def _sub_pixels(camera: syn.CameraModel, s: int) -> Tuple[np.ndarray, np.ndarray]:
    """(undistorted normalised coordinates (H s, W s, 2) float32 of the sub-pixel centres, their rows (H s,))."""
    w, h = camera.width, camera.height
    jj, ii = np.meshgrid((np.arange(w * s) + 0.5) / s, (np.arange(h * s) + 0.5) / s)
    xu = camera.undistort(camera.normalized_from_pixel(np.stack([jj, ii], axis=-1)))
    return xu.astype(np.float32), (np.arange(h * s) + 0.5) / s


def _ground_hits(scene: Woodland, shot: Shot, camera: syn.CameraModel, s: int) -> Tuple[np.ndarray, ...]:
    """Per sub-pixel: the ray's origin and direction (its row's pose) and where it meets the ground (x, y, z)."""
    xu, rows = _sub_pixels(camera, s)
    rot, centre = shot.poses_at(shot.time_of_row(rows))
    d = np.concatenate([xu, np.ones(xu.shape[:2] + (1,), np.float32)], axis=-1)
    d = np.einsum("rwi,rij->rwj", d, rot.astype(np.float32))  # R^T d per row
    o = centre.astype(np.float32)[:, None, :]
    t = (np.float32(scene.base_z) - o[..., 2]) / d[..., 2]
    for _ in range(5):  # fixed point on the gentle ground
        x, y = o[..., 0] + t * d[..., 0], o[..., 1] + t * d[..., 1]
        t = (scene.ground_fast(x, y) - o[..., 2]) / d[..., 2]
    return o, d, t


def _car_hits(scene: Woodland, o: np.ndarray, d: np.ndarray, t: np.ndarray, rgb: np.ndarray) -> None:
    """Rays that meet a car before the ground take its colour (roof with a dark windscreen band, darker sides)."""
    for car in scene.cars:
        reach = math.hypot(car.half_w, car.half_l) + 2.5 * car.height
        x, y = o[..., 0] + t * d[..., 0], o[..., 1] + t * d[..., 1]
        near = np.flatnonzero((np.abs(x - car.cx) < reach).ravel() & (np.abs(y - car.cy) < reach).ravel())
        if not near.size:
            continue
        oo, dd = o[:, 0, :][near // d.shape[1]], d.reshape(-1, 3)[near]
        c, s_ = math.cos(car.angle), math.sin(car.angle)
        rot = np.array([[c, s_], [-s_, c]])  # local -> car (u along its length, v across)
        ou = (oo[:, :2] - [car.cx, car.cy]) @ rot.T
        du = dd[:, :2] @ rot.T
        z0 = float(scene.ground_at(car.cx, car.cy))
        lo, hi = np.full(len(near), -np.inf), np.full(len(near), np.inf)
        face = np.zeros(len(near), np.int8)
        for axis, (a, b) in enumerate(((-car.half_l, car.half_l), (-car.half_w, car.half_w), (z0, z0 + car.height))):
            oa = ou[:, axis] if axis < 2 else oo[:, 2]
            da = du[:, axis] if axis < 2 else dd[:, 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                ta, tb = (a - oa) / da, (b - oa) / da
            enter = np.minimum(ta, tb)
            face = np.where(enter > lo, axis, face)
            lo, hi = np.maximum(lo, enter), np.minimum(hi, np.maximum(ta, tb))
        hit = (lo <= hi) & (lo > 0) & (lo < t.reshape(-1)[near])
        if not hit.any():
            continue
        idx = near[hit]
        u = ou[hit, 0] + lo[hit] * du[hit, 0]
        colour = np.repeat(car.colour[None], hit.sum(), axis=0)
        roof = face[hit] == 2
        glass = roof & (np.abs(u - 0.35 * car.half_l) < 0.3 * car.half_l)
        colour[glass] = [0.08, 0.09, 0.11]
        colour[~roof] *= 0.6
        rgb.reshape(-1, 3)[idx] = colour
        t.reshape(-1)[idx] = lo[hit]


def _branch_layer(scene: Woodland, shot: Shot, camera: syn.CameraModel, s: int) -> Tuple[np.ndarray, np.ndarray]:
    """(premultiplied colour (H s, W s, 3) uint8, coverage (H s, W s) uint8) of the trees, drawn far to near."""
    b = scene.branches
    h, w = camera.height * s, camera.width * s
    colour = np.zeros((h, w, 3), np.uint8)
    alpha = np.zeros((h, w), np.uint8)
    if not len(b):
        return colour, alpha
    px0, z0, r0 = shot.project(camera, b.p0)
    px1, z1, r1 = shot.project(camera, b.p1)
    limit = 1.6  # undistorted radius beyond which a point is far outside the frame (its corners: about 1.0)
    keep = (z0 > 0.5) & (z1 > 0.5) & (r0 < limit) & (r1 < limit)
    margin = 50
    inside = lambda px: (px[:, 0] > -margin) & (px[:, 0] < camera.width + margin) & (  # noqa: E731
        px[:, 1] > -margin) & (px[:, 1] < camera.height + margin)
    keep &= inside(px0) | inside(px1)
    idx = np.flatnonzero(keep)
    depth = 0.5 * (z0 + z1)[idx]
    idx = idx[np.argsort(-depth)]
    width = 2.0 * b.radius[idx] * camera.fx / (0.5 * (z0 + z1)[idx]) * s
    thick = np.maximum(1, np.round(width)).astype(int)
    a = np.round((px0[idx] * s - 0.5) * 16).astype(np.int64)
    c = np.round((px1[idx] * s - 0.5) * 16).astype(np.int64)
    light = np.clip(b.tone[idx], 0.5, 1.5)
    for k in range(len(idx)):
        col = tuple(float(v) for v in BARK * light[k] * 255.0)
        p, q = (int(a[k, 0]), int(a[k, 1])), (int(c[k, 0]), int(c[k, 1]))
        cv2.line(colour, p, q, col, thickness=int(thick[k]), lineType=cv2.LINE_AA, shift=4)
        cv2.line(alpha, p, q, 255, thickness=int(thick[k]), lineType=cv2.LINE_AA, shift=4)
    return colour, alpha


def render_photo(scene: Woodland, camera: syn.CameraModel, shot: Shot, supersample: int = 2, noise: float = 1.5,
                 seed: int = 0) -> np.ndarray:
    """RGB uint8 (height, width, 3) of ``shot`` through its rolling shutter."""
    s = int(supersample)
    o, d, t = _ground_hits(scene, shot, camera, s)
    x, y = o[..., 0] + t * d[..., 0], o[..., 1] + t * d[..., 1]
    mx, my = scene.raster_coords(x, y, scene.texture_res)
    tex = scene.texture()
    rgb = np.stack([syn._sample(tex[..., k], mx, my) for k in range(3)], axis=-1).astype(np.float32) / 255.0
    del mx, my, x, y
    _car_hits(scene, o, d, t, rgb)
    colour, alpha = _branch_layer(scene, shot, camera, s)
    rgb = rgb * (1.0 - alpha[..., None].astype(np.float32) / 255.0) + colour.astype(np.float32) / 255.0
    rgb = cv2.GaussianBlur(rgb, (0, 0), 0.4 * s)
    img = cv2.resize(rgb, (camera.width, camera.height), interpolation=cv2.INTER_AREA)
    jj, ii = np.meshgrid(np.arange(camera.width) + 0.5, np.arange(camera.height) + 0.5)
    r2 = ((jj - camera.cx) ** 2 + (ii - camera.cy) ** 2) / (camera.cx ** 2 + camera.cy ** 2)
    img = img * (1.0 - 0.25 * r2).astype(np.float32)[..., None] * 255.0
    img += np.random.default_rng(seed).normal(0.0, noise, img.shape).astype(np.float32)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


# --------------------------------------------------------------------------------------------------
# the block
# --------------------------------------------------------------------------------------------------


@dataclass
class Flight:
    """The flight plan: strips along local x at ``altitude`` above the mean ground, ``speed`` m/s, the rolling
    shutter's ``line_time`` (s per row; 0: a global shutter), the attitude's jitter and turn rate."""

    altitude: float = 30.0
    n_strips: int = 3
    per_strip: int = 8
    forward_overlap: float = 0.8
    side_overlap: float = 0.65
    speed: float = SPEED
    line_time: float = FRAME_READOUT_S / CAMERA.height
    attitude_sigma_deg: float = 1.5
    rate_sigma_deg_s: float = 3.0  # the turn rate's N(0, this) per axis
    gps_sigma: float = 1.5  # m, EXIF GPS / camera_positions.csv noise (horizontal; twice that vertically)


_RENDERING = None  # (block, folder, supersample) while render's forked workers run


def _render_shot(k: int) -> str:
    block, folder, supersample = _RENDERING
    return block.render_one(k, folder, supersample)


@dataclass
class WoodlandBlock:
    scene: Woodland
    camera: syn.CameraModel
    shots: List[Shot]
    flight: Flight
    gps: Dict[str, np.ndarray]  # image -> the noisy position written (local)
    seed: int = 0

    @property
    def gsd(self) -> float:
        return self.flight.altitude / self.camera.fx

    @property
    def names(self) -> List[str]:
        return [s.name for s in self.shots]

    def centres(self) -> np.ndarray:
        return np.array([s.centre for s in self.shots])

    def span(self) -> float:
        """The largest distance between two camera centres (m)."""
        c = self.centres()
        return float(np.max(np.linalg.norm(c[:, None] - c[None], axis=2)))

    def render(self, folder: str, supersample: int = 2, jobs: int = 1) -> List[str]:
        """Every photo into ``folder`` (JPEG with EXIF), ``camera_positions.csv`` beside it; ``jobs`` > 1 renders
        in forked processes."""
        os.makedirs(folder, exist_ok=True)
        self.scene.texture()
        self.scene.ground_raster()
        if jobs > 1 and "fork" in multiprocessing.get_all_start_methods():
            global _RENDERING
            _RENDERING = (self, folder, supersample)
            try:
                with multiprocessing.get_context("fork").Pool(jobs) as pool:
                    paths = pool.map(_render_shot, range(len(self.shots)), chunksize=1)
                    pool.close()  # the workers end by themselves: no SIGTERM (pycolmap's handler would print it)
                    pool.join()
            finally:
                _RENDERING = None
        else:
            paths = [self.render_one(k, folder, supersample) for k in range(len(self.shots))]
        rows = []
        for s in self.shots:
            w = self.gps[s.name] + syn.ORIGIN
            rows.append(f"{s.name},{w[0]:.3f},{w[1]:.3f},{w[2]:.3f},{self.flight.gps_sigma:g}")
        with open(os.path.join(os.path.dirname(os.path.abspath(folder)), "camera_positions.csv"), "w") as f:
            f.write(f"{syn.CRS}\nimage,x,y,z,sigma\n" + "\n".join(rows) + "\n")
        return paths

    def render_one(self, k: int, folder: str, supersample: int = 2) -> str:
        s = self.shots[k]
        img = render_photo(self.scene, self.camera, s, supersample, seed=self.seed * 1000 + k)
        path = os.path.join(folder, s.name)
        write_jpeg(path, img, self.exif(k))
        return path

    def exif(self, k: int) -> Dict[str, str]:
        """The EXIF tags of photo ``k``: camera, 35 mm-equivalent focal length, time, GPS (WGS 84)."""
        from osgeo import osr

        s = self.shots[k]
        src, dst = osr.SpatialReference(), osr.SpatialReference()
        src.SetFromUserInput(syn.CRS)
        dst.ImportFromEPSG(4326)
        for ref in (src, dst):
            ref.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        w = self.gps[s.name] + syn.ORIGIN
        lon, lat, _ = osr.CoordinateTransformation(src, dst).TransformPoint(float(w[0]), float(w[1]), 0.0)
        f35 = int(round(self.camera.fx / math.hypot(self.camera.width, self.camera.height) * 43.2666))
        return {"EXIF_Make": MAKE, "EXIF_Model": MODEL, "EXIF_FocalLength": "(4.88)",
                "EXIF_FocalLengthIn35mmFilm": str(f35),
                "EXIF_DateTimeOriginal": f"2016:11:22 16:{30 + k // 60:02d}:{k % 60:02d}",
                "EXIF_GPSLatitude": _dms(lat), "EXIF_GPSLatitudeRef": "N" if lat >= 0 else "S",
                "EXIF_GPSLongitude": _dms(lon), "EXIF_GPSLongitudeRef": "E" if lon >= 0 else "W",
                "EXIF_GPSAltitude": f"({w[2]:.3f})", "EXIF_GPSAltitudeRef": "0x00"}


def _dms(value: float) -> str:
    v = abs(value)
    d = int(v)
    m = int((v - d) * 60)
    sec = (v - d - m / 60.0) * 3600.0
    return f"({d}) ({m}) ({sec:.4f})"


def write_jpeg(path: str, rgb: np.ndarray, exif: Dict[str, str], quality: int = 92) -> None:
    """An RGB uint8 array as a JPEG with the EXIF tags (GDAL writes them in the file's EXIF segment)."""
    from osgeo import gdal

    gdal.UseExceptions()
    h, w = rgb.shape[:2]
    mem = gdal.GetDriverByName("MEM").Create("", w, h, 3, gdal.GDT_Byte)
    for b in range(3):
        mem.GetRasterBand(b + 1).WriteArray(rgb[..., b])
    mem.SetMetadata(exif)
    gdal.GetDriverByName("JPEG").CreateCopy(path, mem, options=[f"QUALITY={quality}"])
    mem = None
    if os.path.exists(path + ".aux.xml"):  # GDAL's side file: the EXIF is in the JPEG itself
        os.remove(path + ".aux.xml")


def woodland_block(seed: int = 37, camera: syn.CameraModel = CAMERA, flight: Optional[Flight] = None,
                   n_trees: int = 20, image_scale: float = 1.0) -> WoodlandBlock:
    """Serpentine strips along local x over a park of ``n_trees`` bare trees; image x along the track (the rows
    read out across it), each photo turned by N(0, attitude_sigma) and turning at N(0, rate_sigma) per axis.

    ``image_scale``: the photos' size in pixels, times ``camera``'s (the same lens: field of view and distortion;
    the same flight; the frame still read out in the same time, ``flight.line_time`` being per row of ``camera``),
    with the ground's texture painted at ``Woodland.texture_res`` / ``image_scale`` (as fine for the pixel)."""
    flight = flight or Flight()
    if image_scale != 1.0:
        f = float(image_scale)
        small = camera.with_params(width=int(round(camera.width * f)), height=int(round(camera.height * f)),
                                   fx=camera.fx * f, fy=camera.fy * f, cx=camera.cx * f, cy=camera.cy * f)
        flight = replace(flight, line_time=flight.line_time * camera.height / small.height)
        camera = small
    rng = np.random.default_rng(seed)
    xu, _ = _sub_pixels(camera, 1)
    half_x = float(np.abs(xu[..., 0]).max()) * flight.altitude  # the footprint's half sizes on flat ground
    half_y = float(np.abs(xu[..., 1]).max()) * flight.altitude
    along = 2.0 * float(np.abs(xu[xu.shape[0] // 2, :, 0]).max()) * flight.altitude
    across = 2.0 * float(np.abs(xu[:, xu.shape[1] // 2, 1]).max()) * flight.altitude
    base = (1.0 - flight.forward_overlap) * along
    spacing = (1.0 - flight.side_overlap) * across
    length, width = (flight.per_strip - 1) * base, (flight.n_strips - 1) * spacing
    margin = 1.25 * max(half_x, half_y) + 4.0
    bounds = (-length / 2 - margin, -width / 2 - margin, length / 2 + margin, width / 2 + margin)
    scene = make_woodland(seed, bounds, n_trees)
    scene.texture_res /= float(image_scale)
    shots: List[Shot] = []
    gps: Dict[str, np.ndarray] = {}
    z_fly = scene.base_z + flight.altitude
    for si in range(flight.n_strips):
        y = -width / 2 + si * spacing
        heading = 1.0 if si % 2 == 0 else -1.0
        for k in range(flight.per_strip):
            c = np.array([heading * (-length / 2 + k * base), y, z_fly]) + rng.normal(0.0, 0.3, 3)
            r = syn.look_at(c, c - np.array([0.0, 0.0, 1.0]), np.array([0.0, heading, 0.0]))
            r = syn.small_rotation(rng, flight.attitude_sigma_deg) @ r
            name = f"W{si + 1}_{k + 1:02d}.JPG"
            rate = rng.normal(0.0, math.radians(flight.rate_sigma_deg_s), 3)
            shots.append(Shot(name, r, c, "vertical", si + 1, velocity=np.array([heading * flight.speed, 0.0, 0.0]),
                              angular_rate=rate, line_time=flight.line_time, height=camera.height))
            gps[name] = c + rng.normal(0.0, flight.gps_sigma, 3) * [1.0, 1.0, 2.0]
    return WoodlandBlock(scene, camera, shots, flight, gps, seed)


# --------------------------------------------------------------------------------------------------
# a model against the truth
# --------------------------------------------------------------------------------------------------


def centre_errors(block: WoodlandBlock, rec) -> Dict[str, float]:
    """The registered photos' projection centres of a pycolmap.Reconstruction against the truth (each photo's
    centre at its middle row) after the best similarity: RMSE and largest distance (m), and the photos compared."""
    est, tru = [], []
    by_name = {s.name: s for s in block.shots}
    for im in rec.images.values():
        if im.has_pose and im.name in by_name:
            est.append(np.asarray(im.projection_center()))
            tru.append(by_name[im.name].centre)
    if len(est) < 3:
        return {"photos": len(est), "rmse": float("nan"), "max": float("nan")}
    est, tru = np.array(est), np.array(tru)
    s, r, t = syn.similarity_fit(est, tru)
    d = np.linalg.norm(s * est @ r.T + t - tru, axis=1)
    return {"photos": len(est), "rmse": float(np.sqrt(np.mean(d * d))), "max": float(d.max())}
