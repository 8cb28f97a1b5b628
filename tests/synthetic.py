"""Synthetic aerial blocks with exact ground truth (pure numpy + OpenCV, no QGIS).

A seeded scene in a projected CRS (EPSG:32633, world = local + ``ORIGIN`` so
UTM-size numbers are exercised): a height field with gentle hills, a ditch and
box buildings with vertical walls, painted with a multi-scale band-limited
texture; cameras on a flight plan (vertical strips, optionally an oblique
orbit); a frame camera with known focal length, principal point and OPENCV
distortion (k1, k2, p1, p2).

What it gives:

- ``SyntheticBlock.render(folder)``: the images, rendered by ray casting each
  pixel of a super-sampled *undistorted* canvas into the height field (first
  surface along the ray, so buildings occlude correctly and nothing is left
  empty), then the lens distortion applied with ``cv2.remap``;
- ground truth: poses, intrinsics, ``height_at(x, y)``, GCPs with exact pixel
  observations (true distorted camera model, visibility tested, optional pixel
  noise), camera positions with noise, the GSD;
- ``truth_reconstruction(...)``: a pycolmap.Reconstruction built directly from
  the truth (poses + projected tie points), in an arbitrary model frame, with an
  optional controlled deformation or wrong intrinsics: fast tests without
  rendering and SfM.

Pixel convention everywhere: COLMAP's, the origin at the upper-left corner of
the upper-left pixel, so the centre of the first pixel is (0.5, 0.5); pixel =
f * distorted normalised coordinate + c.
"""
from __future__ import annotations

import math
import multiprocessing
import os
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Callable, Dict, List, Optional, Sequence, Tuple, Union

import cv2
import numpy as np

CRS = "EPSG:32633"
ORIGIN = np.array([500000.0, 4600000.0, 0.0])  # world = local + ORIGIN


# --------------------------------------------------------------------------------------------------
# camera model (OPENCV: fx, fy, cx, cy, k1, k2, p1, p2)
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CameraModel:
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    k1: float = 0.0
    k2: float = 0.0
    p1: float = 0.0
    p2: float = 0.0

    @property
    def params(self) -> List[float]:
        return [self.fx, self.fy, self.cx, self.cy, self.k1, self.k2, self.p1, self.p2]

    def with_params(self, **changes) -> "CameraModel":
        return replace(self, **changes)

    def distort(self, xn: np.ndarray) -> np.ndarray:
        """Undistorted -> distorted normalised coordinates (N,2), OpenCV / COLMAP OPENCV formula."""
        x, y = xn[..., 0], xn[..., 1]
        r2 = x * x + y * y
        radial = 1.0 + self.k1 * r2 + self.k2 * r2 * r2
        xd = x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x)
        yd = y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y
        return np.stack([xd, yd], axis=-1)

    def undistort(self, xd: np.ndarray, iterations: int = 20) -> np.ndarray:
        """Distorted -> undistorted normalised coordinates by Newton's method (to ~1e-14)."""
        xd = np.asarray(xd, dtype=float)
        x = xd.copy()
        for _ in range(iterations):
            u, v = x[..., 0], x[..., 1]
            r2 = u * u + v * v
            radial = 1.0 + self.k1 * r2 + self.k2 * r2 * r2
            dr = 2.0 * (self.k1 + 2.0 * self.k2 * r2)  # d radial / d r2 * 2
            a11 = radial + u * u * dr + 2.0 * self.p1 * v + 6.0 * self.p2 * u
            a12 = u * v * dr + 2.0 * self.p1 * u + 2.0 * self.p2 * v
            a21 = u * v * dr + 2.0 * self.p1 * u + 2.0 * self.p2 * v
            a22 = radial + v * v * dr + 6.0 * self.p1 * v + 2.0 * self.p2 * u
            f = self.distort(x) - xd
            det = a11 * a22 - a12 * a21
            dx = (a22 * f[..., 0] - a12 * f[..., 1]) / det
            dy = (-a21 * f[..., 0] + a11 * f[..., 1]) / det
            x = x - np.stack([dx, dy], axis=-1)
            if np.nanmax(np.abs(dx)) < 1e-15 and np.nanmax(np.abs(dy)) < 1e-15:
                break
        return x

    def pixel_from_normalized(self, xd: np.ndarray) -> np.ndarray:
        return np.stack([self.fx * xd[..., 0] + self.cx, self.fy * xd[..., 1] + self.cy], axis=-1)

    def normalized_from_pixel(self, px: np.ndarray) -> np.ndarray:
        px = np.asarray(px, dtype=float)
        return np.stack([(px[..., 0] - self.cx) / self.fx, (px[..., 1] - self.cy) / self.fy], axis=-1)

    def image_from_camera(self, xc: np.ndarray) -> np.ndarray:
        """Camera-frame points (N,3) -> pixels (N,2) through the distorted model."""
        xc = np.asarray(xc, dtype=float)
        xn = xc[..., :2] / xc[..., 2:3]
        return self.pixel_from_normalized(self.distort(xn))

    def inside(self, px: np.ndarray, margin: float = 0.0) -> np.ndarray:
        return ((px[..., 0] >= margin) & (px[..., 0] <= self.width - margin)
                & (px[..., 1] >= margin) & (px[..., 1] <= self.height - margin))

    def pycolmap_camera(self, camera_id: int = 1):
        import pycolmap

        cam = pycolmap.Camera.create_from_model_name(camera_id, "OPENCV", self.fx, self.width, self.height)
        cam.params = np.array(self.params, dtype=float)
        return cam


# --------------------------------------------------------------------------------------------------
# poses
# --------------------------------------------------------------------------------------------------


@dataclass
class Shot:
    """One exposure: ``cam_from_world`` rotation R and projection centre C, both in the local frame."""

    name: str
    rotation: np.ndarray  # (3,3) camera-from-world
    centre: np.ndarray  # (3,) local metres
    kind: str = "vertical"  # vertical / oblique
    strip: int = 0

    @property
    def translation(self) -> np.ndarray:
        return -self.rotation @ self.centre

    def to_camera(self, xyz: np.ndarray) -> np.ndarray:
        return (np.asarray(xyz, dtype=float) - self.centre) @ self.rotation.T

    def rays(self, xn: np.ndarray) -> np.ndarray:
        """World directions (N,3) of undistorted normalised image coordinates (N,2)."""
        d = np.concatenate([xn, np.ones(xn.shape[:-1] + (1,))], axis=-1)
        return d @ self.rotation  # R^T d for row vectors


def look_at(centre: np.ndarray, target: np.ndarray, up_hint: np.ndarray) -> np.ndarray:
    """camera-from-world rotation looking from ``centre`` at ``target``; ``up_hint`` appears up in the image."""
    z = np.asarray(target, dtype=float) - np.asarray(centre, dtype=float)
    z /= np.linalg.norm(z)
    up = np.asarray(up_hint, dtype=float)
    y = -(up - (up @ z) * z)
    y /= np.linalg.norm(y)
    x = np.cross(y, z)
    return np.vstack([x, y, z])


def small_rotation(rng: np.random.Generator, sigma_deg: float) -> np.ndarray:
    w = rng.normal(0.0, math.radians(sigma_deg), 3)
    r, _ = cv2.Rodrigues(w)
    return r


# --------------------------------------------------------------------------------------------------
# scene: height field + texture
# --------------------------------------------------------------------------------------------------


@dataclass
class Building:
    cx: float
    cy: float
    half_w: float  # along the building's own x axis
    half_l: float
    angle: float  # radians, own x axis from local east
    roof: float  # roof height (local Z = world Z)

    def local_uv(self, x, y):
        c, s = math.cos(self.angle), math.sin(self.angle)
        dx, dy = np.asarray(x) - self.cx, np.asarray(y) - self.cy
        return c * dx + s * dy, -s * dx + c * dy

    def contains(self, x, y, margin: float = 0.0):
        u, v = self.local_uv(x, y)
        return (np.abs(u) <= self.half_w + margin) & (np.abs(v) <= self.half_l + margin)


@dataclass
class Scene:
    """The terrain in the local frame (x east, y north, z up; world = local + ORIGIN)."""

    seed: int
    bounds: Tuple[float, float, float, float]  # xmin, ymin, xmax, ymax (local)
    base_z: float
    hills: np.ndarray  # (K,4): x, y, amplitude, sigma
    ramp: Tuple[float, float]  # linear slope dz/dx, dz/dy
    ditch: Tuple[Tuple[float, float], Tuple[float, float], float, float]  # p0, p1, half width, depth
    buildings: List[Building]
    texture_res: float = 0.04  # m per texture cell
    height_res: float = 0.06  # m per height-raster cell
    epoch: int = 0  # 0: the scene as always; 1, 2: two epochs of it (see make_scene(epoch=...))
    _rasters: Dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    # a low-texture patch (bare soil, uniform crops, sand): inside this local box (xmin, ymin, xmax, ymax) the
    # ground's texture keeps only ``low_texture_contrast`` of its contrast (roofs keep theirs); None = none
    low_texture: Optional[Tuple[float, float, float, float]] = None
    low_texture_contrast: float = 0.1

    # ---- analytic truth
    def ground_at(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        z = self.base_z + self.ramp[0] * x + self.ramp[1] * y
        for hx, hy, amp, sig in self.hills:
            z = z + amp * np.exp(-((x - hx) ** 2 + (y - hy) ** 2) / (2.0 * sig * sig))
        (x0, y0), (x1, y1), hw, depth = self.ditch
        d = np.array([x1 - x0, y1 - y0])
        length = float(np.linalg.norm(d))
        d /= length
        along = (x - x0) * d[0] + (y - y0) * d[1]
        across = np.abs(-(x - x0) * d[1] + (y - y0) * d[0])
        inside = (across < hw) & (along > 0) & (along < length)
        profile = 0.5 * (1.0 + np.cos(np.pi * np.clip(across / hw, 0.0, 1.0)))
        return z - np.where(inside, depth * profile, 0.0)

    def height_at(self, x, y) -> np.ndarray:
        """Surface height (ground, or roof inside a building) at local x, y."""
        z = self.ground_at(x, y)
        for b in self.buildings:
            z = np.where(b.contains(x, y), np.maximum(z, b.roof), z)
        return z

    def world_height_at(self, x_world, y_world) -> np.ndarray:
        return self.height_at(np.asarray(x_world) - ORIGIN[0], np.asarray(y_world) - ORIGIN[1])

    def near_feature(self, x, y, margin: float, buildings: bool = True) -> np.ndarray:
        """True within ``margin`` of a building or the ditch (no ground point goes there)."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        out = np.zeros(np.broadcast(x, y).shape, dtype=bool)
        for b in self.buildings if buildings else ():
            out |= b.contains(x, y, margin)
        (x0, y0), (x1, y1), hw, _ = self.ditch
        d = np.array([x1 - x0, y1 - y0])
        length = float(np.linalg.norm(d))
        d /= length
        along = (x - x0) * d[0] + (y - y0) * d[1]
        across = np.abs(-(x - x0) * d[1] + (y - y0) * d[0])
        out |= (across < hw + margin) & (along > -margin) & (along < length + margin)
        return out

    def max_height(self) -> float:
        hills = float(np.sum(np.clip(self.hills[:, 2], 0, None)))
        xmin, ymin, xmax, ymax = self.bounds
        ramp = abs(self.ramp[0]) * max(abs(xmin), abs(xmax)) + abs(self.ramp[1]) * max(abs(ymin), abs(ymax))
        roofs = max((b.roof for b in self.buildings), default=-1e9)
        return max(self.base_z + hills + ramp, roofs) + 0.01

    def min_height(self) -> float:
        xmin, ymin, xmax, ymax = self.bounds
        ramp = abs(self.ramp[0]) * max(abs(xmin), abs(xmax)) + abs(self.ramp[1]) * max(abs(ymin), abs(ymax))
        neg = float(np.sum(np.clip(self.hills[:, 2], None, 0)))
        return self.base_z + neg - ramp - self.ditch[3] - 0.01

    # ---- rasters (for rendering)
    def _grid(self, res: float) -> Tuple[np.ndarray, np.ndarray]:
        xmin, ymin, xmax, ymax = self.bounds
        nx = int(math.ceil((xmax - xmin) / res))
        ny = int(math.ceil((ymax - ymin) / res))
        xs = xmin + (np.arange(nx) + 0.5) * res
        ys = ymax - (np.arange(ny) + 0.5) * res  # row 0 at the north edge
        return xs, ys

    def _window(self, x0: float, y0: float, x1: float, y1: float, res: float) -> Tuple[slice, slice]:
        """(rows, cols) slices of the raster cells of ``res`` covering the local box x0..x1, y0..y1."""
        xmin, ymin, xmax, ymax = self.bounds
        nx = int(math.ceil((xmax - xmin) / res))
        ny = int(math.ceil((ymax - ymin) / res))
        c0, c1 = max(0, int((x0 - xmin) / res) - 1), min(nx, int((x1 - xmin) / res) + 2)
        r0, r1 = max(0, int((ymax - y1) / res) - 1), min(ny, int((ymax - y0) / res) + 2)
        return slice(r0, r1), slice(c0, c1)

    def raster_coords(self, x: np.ndarray, y: np.ndarray, res: float) -> Tuple[np.ndarray, np.ndarray]:
        """cv2.remap coordinates (col, row; cell centres at integers) of local x, y in a raster of ``res``."""
        xmin, _, _, ymax = self.bounds
        return ((x - xmin) / res - 0.5).astype(np.float32), ((ymax - y) / res - 0.5).astype(np.float32)

    def height_raster(self) -> np.ndarray:
        if "height" not in self._rasters:
            xs, ys = self._grid(self.height_res)
            out = np.empty((len(ys), len(xs)), dtype=np.float32)
            for i0 in range(0, len(ys), 256):
                yy, xx = np.meshgrid(ys[i0:i0 + 256], xs, indexing="ij")
                out[i0:i0 + 256] = self.height_at(xx, yy)
            self._rasters["height"] = out
        return self._rasters["height"]

    def texture_raster(self) -> np.ndarray:
        """Grey orthoimage (float32, about 0..1) at ``texture_res``: band-limited noise at several
        scales, field edges and tracks, roofs with their own pattern, a darker ditch, hill shading."""
        if "texture" in self._rasters:
            return self._rasters["texture"]
        rng = np.random.default_rng(self.seed + 101)
        xs, ys = self._grid(self.texture_res)
        ny, nx = len(ys), len(xs)
        tex = np.zeros((ny, nx), dtype=np.float32)
        for wavelength, weight in ((0.3, 0.9), (0.6, 1.0), (1.2, 1.0), (2.5, 0.9), (5.0, 0.8), (12.0, 0.7),
                                   (30.0, 0.6)):
            step = wavelength / 2.0  # random values every half wavelength, cubic interpolation between
            gx = int(math.ceil(nx * self.texture_res / step)) + 4
            gy = int(math.ceil(ny * self.texture_res / step)) + 4
            coarse = rng.normal(0.0, 1.0, (gy, gx)).astype(np.float32)
            fine = cv2.resize(coarse, (int(round(gx * step / self.texture_res)), int(round(gy * step / self.texture_res))),
                              interpolation=cv2.INTER_CUBIC)
            tex += weight * fine[:ny, :nx]
        tex /= 3.0
        # fields with different brightness and straight edges, tracks (lines)
        edges = np.zeros((ny, nx), dtype=np.float32)
        xmin, ymin, xmax, ymax = self.bounds
        for _ in range(40):
            cxy = rng.uniform([0, 0], [nx, ny])
            half = rng.uniform(1.5, 12.0, 2) / self.texture_res
            ang = rng.uniform(0, 180)
            box = cv2.boxPoints(((float(cxy[0]), float(cxy[1])), (float(2 * half[0]), float(2 * half[1])), float(ang)))
            cv2.fillConvexPoly(edges, np.round(box * 16).astype(np.int32), float(rng.uniform(-1.0, 1.0)),
                               lineType=cv2.LINE_AA, shift=4)
        for _ in range(12):
            p = rng.uniform([0, 0], [nx, ny], (2, 2))
            cv2.line(edges, tuple(int(v) for v in np.round(p[0] * 16)), tuple(int(v) for v in np.round(p[1] * 16)),
                     float(rng.choice([-1.2, 1.2])), thickness=int(rng.uniform(0.3, 1.0) / self.texture_res),
                     lineType=cv2.LINE_AA, shift=4)
        if self.epoch == 2:  # another season: new crop marks (patches and lines) over the old fields
            rng2 = np.random.default_rng(self.seed + 303)
            for _ in range(25):
                cxy = rng2.uniform([0, 0], [nx, ny])
                half = rng2.uniform(1.0, 8.0, 2) / self.texture_res
                box = cv2.boxPoints(((float(cxy[0]), float(cxy[1])), (float(2 * half[0]), float(2 * half[1])),
                                     float(rng2.uniform(0, 180))))
                cv2.fillConvexPoly(edges, np.round(box * 16).astype(np.int32), float(rng2.uniform(-1.0, 1.0)),
                                   lineType=cv2.LINE_AA, shift=4)
        edges = cv2.GaussianBlur(edges, (0, 0), 0.08 / self.texture_res)
        tex += 0.8 * edges
        # scene features: roofs (stripes), ditch (darker), shading from the height field
        for b in self.buildings:
            r = math.hypot(b.half_w, b.half_l) + 0.1
            win = self._window(b.cx - r, b.cy - r, b.cx + r, b.cy + r, self.texture_res)
            yy, xx = np.meshgrid(ys[win[0]], xs[win[1]], indexing="ij")
            inside = b.contains(xx, yy)
            u, _ = b.local_uv(xx[inside], yy[inside])
            sub = tex[win]
            sub[inside] = 0.8 * sub[inside] + 0.35 * np.sin(2 * np.pi * u / 0.9).astype(np.float32) + 0.6
        (x0, y0), (x1, y1), hw, _ = self.ditch
        win = self._window(min(x0, x1) - hw, min(y0, y1) - hw, max(x0, x1) + hw, max(y0, y1) + hw,
                           self.texture_res)
        for r0 in range(win[0].start, win[0].stop, 512):
            rows = slice(r0, min(r0 + 512, win[0].stop))
            yy, xx = np.meshgrid(ys[rows], xs[win[1]], indexing="ij")
            ditch = self.near_feature(xx, yy, 0.0, buildings=False)
            for b in self.buildings:
                ditch &= ~b.contains(xx, yy)
            tex[rows, win[1]][ditch] -= 0.8
        h = self.height_raster()
        gy_, gx_ = np.gradient(h.astype(np.float64), self.height_res)
        gx_ = np.clip(gx_, -2, 2)
        gy_ = np.clip(gy_, -2, 2)
        sun = (-0.4, 0.45) if self.epoch == 2 else (0.5, 0.3)  # epoch 2: the sun from another side
        shade = (1.0 + sun[0] * gx_ + sun[1] * gy_) / np.sqrt(1.0 + gx_ ** 2 + gy_ ** 2)
        shade = cv2.resize(shade.astype(np.float32), (nx, ny), interpolation=cv2.INTER_LINEAR)
        if self.low_texture is not None:
            _flatten_texture(self, tex, xs, ys)
        tex = 0.5 + 0.16 * tex
        tex *= np.clip(shade, 0.3, 1.3)
        self._rasters["texture"] = np.clip(tex, 0.02, 0.98).astype(np.float32)
        return self._rasters["texture"]


def _flatten_texture(scene: Scene, tex: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> None:
    """Scale the texture (around its mean) inside ``scene.low_texture`` by its contrast factor, roofs excepted."""
    x0, y0, x1, y1 = scene.low_texture
    win = scene._window(x0, y0, x1, y1, scene.texture_res)
    yy, xx = np.meshgrid(ys[win[0]], xs[win[1]], indexing="ij")
    inside = (xx >= x0) & (xx <= x1) & (yy >= y0) & (yy <= y1)
    for b in scene.buildings:
        inside &= ~b.contains(xx, yy)
    sub = tex[win]
    mean = float(sub[inside].mean()) if inside.any() else 0.0
    sub[inside] = mean + scene.low_texture_contrast * (sub[inside] - mean)


def make_scene(seed: int, bounds: Tuple[float, float, float, float], base_z: float = 150.0,
               n_buildings: int = 5, epoch: int = 0) -> Scene:
    """Hills, a ditch across the area and ``n_buildings`` boxes (4-8 m tall) at seeded random places."""
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = bounds
    w, h = xmax - xmin, ymax - ymin
    hills = []
    for _ in range(5):
        hills.append([rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-2.0, 5.0),
                      rng.uniform(0.15, 0.35) * max(w, h)])
    ramp = (float(rng.uniform(-0.03, 0.03)), float(rng.uniform(-0.03, 0.03)))
    p0 = (xmin + 0.1 * w, ymin + rng.uniform(0.3, 0.45) * h)
    p1 = (xmax - 0.1 * w, ymin + rng.uniform(0.55, 0.7) * h)
    scene = Scene(seed, bounds, base_z, np.array(hills), ramp, (p0, p1, 1.6, 1.5), [])
    buildings: List[Building] = []
    tries = 0
    while len(buildings) < n_buildings and tries < 500:
        tries += 1
        cx = rng.uniform(xmin + 0.15 * w, xmax - 0.15 * w)
        cy = rng.uniform(ymin + 0.15 * h, ymax - 0.15 * h)
        hw, hl = rng.uniform(3.0, 7.0), rng.uniform(3.0, 6.0)
        if scene.near_feature(cx, cy, max(hw, hl) + 4.0):
            continue
        if any(math.hypot(cx - b.cx, cy - b.cy) < max(hw, hl) + max(b.half_w, b.half_l) + 6.0 for b in buildings):
            continue
        corners = [(cx + sx * hw, cy + sy * hl) for sx in (-1, 1) for sy in (-1, 1)]
        ground = max(float(scene.ground_at(*c)) for c in corners)
        b = Building(cx, cy, hw, hl, float(rng.uniform(0, math.pi)), ground + float(rng.uniform(4.0, 8.0)))
        buildings.append(b)
        scene.buildings = list(buildings)
    scene.buildings = buildings
    if epoch:
        _epoch_changes(scene, epoch)
    return scene


def _epoch_changes(scene: Scene, epoch: int) -> None:
    """Epochs 1 and 2 of a scene (the same terrain, ``make_scene(epoch=...)``): a car (a 2 x 4.5 m box, 1.5 m
    tall) parked at one place in epoch 1 and at another in epoch 2; in epoch 2 also a new building, new crop
    marks and the sun from another side (``Scene.texture_raster``)."""
    scene.epoch = int(epoch)
    rng = np.random.default_rng(scene.seed + 404)
    xmin, ymin, xmax, ymax = scene.bounds
    w, h = xmax - xmin, ymax - ymin
    spots = []
    for _ in range(400):
        cx, cy = rng.uniform(xmin + 0.2 * w, xmax - 0.2 * w), rng.uniform(ymin + 0.2 * h, ymax - 0.2 * h)
        if not scene.near_feature(cx, cy, 9.0) and all(math.hypot(cx - a, cy - b) > 15.0 for a, b in spots):
            spots.append((cx, cy))
        if len(spots) == 3:
            break
    (c1, c2, c3) = spots
    car = c1 if epoch == 1 else c2
    ang = float(rng.uniform(0, math.pi))
    ground = float(scene.ground_at(*car))
    scene.buildings.append(Building(car[0], car[1], 1.0, 2.25, ang, ground + 1.5))
    if epoch == 2:
        ground = float(scene.ground_at(*c3))
        scene.buildings.append(Building(c3[0], c3[1], 4.0, 3.0, ang + 0.5, ground + 5.0))


# --------------------------------------------------------------------------------------------------
# rendering
# --------------------------------------------------------------------------------------------------


_RENDERING = None  # (block, render arguments) while Block.render's forked workers run


def _render_shot(k: int) -> str:
    block, args = _RENDERING
    return block._render_one(k, *args)


def _sample(raster: np.ndarray, mx: np.ndarray, my: np.ndarray, interpolation=cv2.INTER_LINEAR) -> np.ndarray:
    """cv2.remap of any-shaped coordinate arrays (flattened into rows of 1024)."""
    shape = mx.shape
    n = mx.size
    rows = max(1, -(-n // 1024))
    pad = rows * 1024 - n
    fx = np.pad(mx.reshape(-1).astype(np.float32), (0, pad)).reshape(rows, 1024)
    fy = np.pad(my.reshape(-1).astype(np.float32), (0, pad)).reshape(rows, 1024)
    # cv2.remap takes maps and sources of fewer than 32767 rows and columns: 16 MP photos rendered supersampled
    # have more map rows, the texture of a 1,000-photo block more source columns (then each run of 16 map rows,
    # neighbouring pixels of one photo, is sampled from the window of the texture it covers)
    big = max(raster.shape[:2]) >= _REMAP_LIMIT
    step = 16 if big else 32000
    out = np.concatenate([_remap(raster, fx[r:r + step], fy[r:r + step], interpolation, big)
                          for r in range(0, rows, step)])
    return out.reshape(-1)[:n].reshape(shape)


_REMAP_LIMIT = 32767


def _remap(raster: np.ndarray, fx: np.ndarray, fy: np.ndarray, interpolation, windowed: bool) -> np.ndarray:
    if not windowed:
        return cv2.remap(raster, fx, fy, interpolation, borderMode=cv2.BORDER_REPLICATE)
    h, w = raster.shape[:2]
    ok = np.isfinite(fx) & np.isfinite(fy)
    if not ok.any():
        return cv2.remap(raster[:2, :2], fx, fy, interpolation, borderMode=cv2.BORDER_REPLICATE)
    x0 = int(np.clip(np.floor(fx[ok].min()) - 2, 0, w - 1))
    x1 = int(np.clip(np.ceil(fx[ok].max()) + 3, x0 + 1, w))
    y0 = int(np.clip(np.floor(fy[ok].min()) - 2, 0, h - 1))
    y1 = int(np.clip(np.ceil(fy[ok].max()) + 3, y0 + 1, h))
    if x1 - x0 >= _REMAP_LIMIT or y1 - y0 >= _REMAP_LIMIT:
        if len(fx) > 1:  # the map rows span too much of the texture: one row at a time
            return np.concatenate([_remap(raster, fx[i:i + 1], fy[i:i + 1], interpolation, True)
                                   for i in range(len(fx))])
        half = fx.shape[1] // 2
        if half == 0:
            raise ValueError("a texture window over cv2.remap's limit for one pixel")
        return np.concatenate([_remap(raster, fx[:, :half], fy[:, :half], interpolation, True),
                               _remap(raster, fx[:, half:], fy[:, half:], interpolation, True)], axis=1)
    window = np.ascontiguousarray(raster[y0:y1, x0:x1])
    return cv2.remap(window, fx - np.float32(x0), fy - np.float32(y0), interpolation, borderMode=cv2.BORDER_REPLICATE)


def _ray_cast(scene: Scene, centre: np.ndarray, dirs: np.ndarray, step: float = 0.4,
              bisections: int = 6) -> np.ndarray:
    """First intersection (..., 3) of rays centre + t * dirs (pointing down) with the surface.

    Each ray starts at a safe height (the highest surface within its horizontal travel, from a
    max-pooled coarse raster), marches down in ``step`` metres until it is below the surface (only the
    rays still above it are evaluated), bisects the last step and ends with a secant step."""
    hr = scene.height_raster()
    zmax, zmin = float(hr.max()) + 0.01, float(hr.min()) - 0.01
    shape = dirs.shape[:-1]
    d = np.asarray(dirs, dtype=np.float64)
    if np.any(d[..., 2] >= -1e-6):
        raise ValueError("a ray points upward: the camera sees the horizon")
    res = scene.height_res
    xmin, _, _, ymax = scene.bounds
    cx, cy, cz = (float(v) for v in centre)
    # raster coordinates along a ray: col = ax + dz * bx, row = ay - dz * by with dz = z - cz
    bx = (d[..., 0] / d[..., 2] / res).astype(np.float32)
    by = (d[..., 1] / d[..., 2] / res).astype(np.float32)
    ax = np.float32((cx - xmin) / res - 0.5)
    ay = np.float32((ymax - cy) / res - 0.5)

    def gap(dz, bx_, by_):  # ray height minus surface height (> 0: above the surface)
        if dz.ndim == 2:
            h = cv2.remap(hr, ax + dz * bx_, ay - dz * by_, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        else:
            h = _sample(hr, ax + dz * bx_, ay - dz * by_)
        return dz + np.float32(cz) - h

    # safe start: max of the surface within the ray's horizontal travel over [zmin, zmax]
    travel = (zmax - zmin) * float(np.max(np.hypot(bx, by))) * res + 1.0
    k = max(1, int(round(1.0 / res)))  # 1 m cells
    ny, nx = hr.shape[0] // k * k, hr.shape[1] // k * k
    coarse = hr[:ny, :nx].reshape(ny // k, k, nx // k, k).max(axis=(1, 3))
    coarse = np.pad(coarse, ((0, 1), (0, 1)), mode="edge")
    r = int(math.ceil(travel / (k * res))) + 1
    pooled = cv2.dilate(coarse, np.ones((2 * r + 1, 2 * r + 1), np.uint8), borderType=cv2.BORDER_REPLICATE)
    dzmid = np.float32(0.5 * (zmax + zmin) - cz)
    start = cv2.remap(pooled, (ax + dzmid * bx + 0.5) / k - 0.5, (ay - dzmid * by + 0.5) / k - 0.5,
                      cv2.INTER_NEAREST, borderMode=cv2.BORDER_REPLICATE)
    dz_top, dz_bottom = np.float32(zmax - cz), np.float32(zmin - cz)
    hi = np.minimum(start.reshape(-1) - np.float32(cz) + np.float32(0.01), dz_top)  # dz above the surface
    lo = np.full(hi.shape, dz_bottom, dtype=np.float32)
    f_hi = np.full(hi.shape, 1.0, dtype=np.float32)
    f_lo = np.full(hi.shape, -1.0, dtype=np.float32)
    bxf, byf = bx.reshape(-1), by.reshape(-1)
    idx = np.arange(hi.size)
    z, fz, bxa, bya = hi.copy(), f_hi.copy(), bxf, byf
    while idx.size:
        zn = np.maximum(z - np.float32(step), dz_bottom)
        fn = gap(zn, bxa, bya)
        done = (fn <= 0) | (zn <= dz_bottom)
        di = idx[done]
        lo[di], f_lo[di] = zn[done], fn[done]
        hi[di], f_hi[di] = z[done], fz[done]
        keep = ~done
        idx, z, fz, bxa, bya = idx[keep], zn[keep], fn[keep], bxa[keep], bya[keep]
    lo, hi, f_lo, f_hi = (a.reshape(shape) for a in (lo, hi, f_lo, f_hi))
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        fm = gap(mid, bx, by)
        above = fm > 0
        hi, f_hi = np.where(above, mid, hi), np.where(above, fm, f_hi)
        lo, f_lo = np.where(above, lo, mid), np.where(above, f_lo, fm)
    denom = f_hi - f_lo
    w = np.where(denom > 1e-6, -f_lo / np.maximum(denom, 1e-6), 0.5)
    dz = (lo + np.clip(w, 0.0, 1.0) * (hi - lo)).astype(np.float64)
    t = dz / d[..., 2]
    return np.stack([cx + t * d[..., 0], cy + t * d[..., 1], cz + dz], axis=-1)


def _surface_value(scene: Scene, xyz: np.ndarray) -> np.ndarray:
    """Grey value of surface points: the orthoimage on ground and roofs, a pattern of (along, z) on walls."""
    tex = scene.texture_raster()
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    mx, my = scene.raster_coords(x, y, scene.texture_res)
    val = _sample(tex, mx, my)
    for b in scene.buildings:
        rad = math.hypot(b.half_w, b.half_l) + 0.1
        near = (np.abs(x - b.cx) < rad) & (np.abs(y - b.cy) < rad) & (z < b.roof - 0.03)
        if not np.any(near):
            continue
        xs, ys, zs = x[near], y[near], z[near]
        u, v = b.local_uv(xs, ys)
        on_u = np.abs(np.abs(u) - b.half_w) < 0.08
        on_wall = ((on_u & (np.abs(v) <= b.half_l + 0.08))
                   | ((np.abs(np.abs(v) - b.half_l) < 0.08) & (np.abs(u) <= b.half_w + 0.08)))
        if np.any(on_wall):
            along = np.where(on_u, v, u)[on_wall]
            zw = zs[on_wall]
            wx, wy = scene.raster_coords(b.cx + along * 0.7, b.cy + (zw - b.roof) * 0.7, scene.texture_res)
            sub = val[near]
            sub[on_wall] = 0.55 * _sample(tex, wx, wy) + 0.1 * ((np.floor(zw * 2.0) % 2) - 0.5)
            val[near] = sub
    return val


@lru_cache(maxsize=4)
def _canvas_geometry(camera: CameraModel, s: int):
    """Per camera model: rays of the undistorted canvas and the remap from it to the distorted image."""
    w, h = camera.width, camera.height
    jj, ii = np.meshgrid(np.arange(w, dtype=float) + 0.5, np.arange(h, dtype=float) + 0.5)
    xu = camera.undistort(camera.normalized_from_pixel(np.stack([jj, ii], axis=-1)))
    pad = 3.0 / (camera.fx * s)
    ux0, uy0 = xu[..., 0].min() - pad, xu[..., 1].min() - pad
    ux1, uy1 = xu[..., 0].max() + pad, xu[..., 1].max() + pad
    du, dv = 1.0 / (camera.fx * s), 1.0 / (camera.fy * s)  # canvas pixel size in normalised units
    cw, ch = int(math.ceil((ux1 - ux0) / du)), int(math.ceil((uy1 - uy0) / dv))
    cu, cv_ = np.meshgrid(ux0 + (np.arange(cw) + 0.5) * du, uy0 + (np.arange(ch) + 0.5) * dv)
    canvas_xn = np.stack([cu, cv_], axis=-1)
    map_x = ((xu[..., 0] - ux0) / du - 0.5).astype(np.float32)
    map_y = ((xu[..., 1] - uy0) / dv - 0.5).astype(np.float32)
    r2 = ((jj - w / 2) ** 2 + (ii - h / 2) ** 2) / (0.25 * (w * w + h * h))
    vignetting = (1.0 - 0.12 * r2).astype(np.float32)
    return canvas_xn, map_x, map_y, vignetting


@dataclass(frozen=True)
class Radiometry:
    """A known radiometric model for :func:`render_image` (issue 14): instead of the fixed vignetting, the radial
    fall-off ``1 + k1 r^2 + k2 r^4`` (r = distance from the principal point / the half diagonal), a hot spot
    ``1 + hot * exp(-theta^2 / (2 hot_width^2))`` (theta = angle between the view ray and the direction the
    sunlight travels: the sun at ``sun_azimuth_deg`` (from local +x towards +y) and ``sun_elevation_deg``), and
    per image an exposure gain exp(N(0, exposure_sigma)) times a linear ramp of +-``ramp`` across the image in a
    random direction (light that changed between the photos), and with ``bend`` a soft edge of light across it."""

    k1: float = -0.25
    k2: float = 0.05
    hot: float = 0.12
    hot_width_deg: float = 10.0
    sun_azimuth_deg: float = 200.0
    sun_elevation_deg: float = 65.0
    exposure_sigma: float = 0.08
    ramp: float = 0.03
    bend: float = 0.0  # per image a soft edge of light, 1 + bend * tanh(2 t), in another random direction

    def falloff(self, r: np.ndarray) -> np.ndarray:
        r2 = np.asarray(r, dtype=float) ** 2
        return 1.0 + self.k1 * r2 + self.k2 * r2 * r2

    def antisolar(self) -> np.ndarray:
        """The direction the sunlight travels (local frame, z up): a view ray along it sees the hot spot."""
        a, e = math.radians(self.sun_azimuth_deg), math.radians(self.sun_elevation_deg)
        return -np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])

    def hot_spot(self, rays: np.ndarray) -> np.ndarray:
        d = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
        theta = np.arccos(np.clip(d @ self.antisolar(), -1.0, 1.0))
        return 1.0 + self.hot * np.exp(-0.5 * (theta / math.radians(self.hot_width_deg)) ** 2)

    def image_gain(self, camera: CameraModel, seed: int) -> np.ndarray:
        """(height, width) exposure gain x ramp of one image (seeded)."""
        rng = np.random.default_rng(10_007 + seed)
        g = math.exp(rng.normal(0.0, self.exposure_sigma))
        a = rng.uniform(0.0, 2 * math.pi)
        jj, ii = np.meshgrid(np.arange(camera.width) + 0.5, np.arange(camera.height) + 0.5)
        t = ((jj - camera.width / 2) * math.cos(a) + (ii - camera.height / 2) * math.sin(a)) / (0.5 * math.hypot(
            camera.width, camera.height))
        gain = g * (1.0 + self.ramp * t)
        if self.bend:  # a cloud's soft shadow edge across the photo: not a ramp, not a quadratic
            b = rng.uniform(0.0, 2 * math.pi)
            t2 = ((jj - camera.width / 2) * math.cos(b) + (ii - camera.height / 2) * math.sin(b)) / (0.5 * math.hypot(
                camera.width, camera.height))
            gain = gain * (1.0 + self.bend * np.tanh(2.0 * t2))
        return gain.astype(np.float32)

    def pixel_falloff(self, camera: CameraModel) -> np.ndarray:
        jj, ii = np.meshgrid(np.arange(camera.width) + 0.5, np.arange(camera.height) + 0.5)
        r = np.hypot(jj - camera.cx, ii - camera.cy) / (0.5 * math.hypot(camera.width, camera.height))
        return self.falloff(r).astype(np.float32)


def render_image(scene: Scene, camera: CameraModel, shot: Shot, supersample: int = 2, noise: float = 1.5,
                 seed: int = 0, radiometry: Optional[Radiometry] = None) -> np.ndarray:
    """Grey uint8 image (height, width) of ``shot``: the undistorted canvas (``supersample`` x the pixel
    density) is ray-cast into the height field, blurred a little (optics, anti-aliasing), and the lens
    distortion is applied with cv2.remap: each distorted pixel takes the canvas value at its undistorted
    position.  Vignetting and sensor noise added; with ``radiometry`` its fall-off, hot spot and per-image gain
    instead of the fixed vignetting."""
    s = int(supersample)
    canvas_xn, map_x, map_y, vignetting = _canvas_geometry(camera, s)
    rays = shot.rays(canvas_xn)
    xyz = _ray_cast(scene, shot.centre, rays)
    canvas = _surface_value(scene, xyz).astype(np.float32)
    del xyz
    if radiometry is not None:
        canvas = canvas * radiometry.hot_spot(rays).astype(np.float32)
        vignetting = radiometry.pixel_falloff(camera) * radiometry.image_gain(camera, seed)
    canvas = cv2.GaussianBlur(canvas, (0, 0), 0.45 * s)
    img = cv2.remap(canvas, map_x, map_y, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
    img = img * vignetting * 255.0
    img += np.random.default_rng(seed).normal(0.0, noise, img.shape).astype(np.float32)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


# --------------------------------------------------------------------------------------------------
# the block: scene + camera + flight plan + ground control
# --------------------------------------------------------------------------------------------------


@dataclass
class TruePoint:
    name: str
    xyz: np.ndarray  # local
    kind: str  # ground / roof
    observations: Dict[str, np.ndarray] = field(default_factory=dict)  # image -> exact pixel (no noise)

    @property
    def world(self) -> np.ndarray:
        return self.xyz + ORIGIN


@dataclass
class SyntheticBlock:
    scene: Scene
    camera: CameraModel
    shots: List[Shot]
    altitude: float  # above base_z
    gcps: List[TruePoint] = field(default_factory=list)
    seed: int = 0

    @property
    def gsd(self) -> float:
        """Nominal ground sample distance (m/pixel) at the base height, vertical shots."""
        return self.altitude / self.camera.fx

    @property
    def names(self) -> List[str]:
        return [s.name for s in self.shots]

    def shot(self, name: str) -> Shot:
        return next(s for s in self.shots if s.name == name)

    def project(self, shot: Shot, xyz_local: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Pixels (N,2) through the true distorted camera and depths (N,)."""
        xc = shot.to_camera(np.atleast_2d(xyz_local))
        return self.camera.image_from_camera(xc), xc[:, 2]

    def visible(self, shot: Shot, xyz_local: np.ndarray, margin: float = 2.0) -> Tuple[np.ndarray, np.ndarray]:
        """(visible mask, pixels): in front, inside the image (``margin`` px), not occluded by the surface."""
        xyz = np.atleast_2d(np.asarray(xyz_local, dtype=float))
        px, depth = self.project(shot, xyz)
        ok = (depth > 0) & self.camera.inside(px, margin)
        # a distortion polynomial can fold far-off points back into the image: keep only points whose
        # undistorted radius is within that of the image corners
        with np.errstate(divide="ignore", invalid="ignore"):
            r_u = np.hypot(*(self.to_camera_xy(shot, xyz).T))
        ok &= np.isfinite(r_u) & (r_u <= 1.001 * self._corner_radius())
        if np.any(ok):
            ok[ok] &= ~self._occluded(shot.centre, xyz[ok])
        return ok, px

    @staticmethod
    def to_camera_xy(shot: Shot, xyz: np.ndarray) -> np.ndarray:
        """Undistorted normalised image coordinates (N,2) of local points."""
        xc = shot.to_camera(xyz)
        return xc[:, :2] / xc[:, 2:3]

    def _corner_radius(self) -> float:
        c = self.camera
        corners = np.array([[0.0, 0.0], [c.width, 0.0], [0.0, c.height], [c.width, c.height]])
        return float(np.max(np.hypot(*c.undistort(c.normalized_from_pixel(corners)).T)))

    def _occluded(self, centre: np.ndarray, xyz: np.ndarray, step: float = 0.2) -> np.ndarray:
        zmax = self.scene.max_height()
        seg = centre[None, :] - xyz
        length = np.linalg.norm(seg, axis=1)
        # only the part of the segment below the highest surface can be blocked
        frac_top = np.clip((zmax - xyz[:, 2]) / np.maximum(seg[:, 2], 1e-9), 0.0, 1.0)
        n = int(np.ceil((frac_top * length).max() / step)) + 1
        s = np.linspace(0.0, 1.0, n + 1)[1:]
        blocked = np.zeros(len(xyz), dtype=bool)
        for si in s:
            f = si * frac_top
            p = xyz + f[:, None] * seg
            clear = 0.03  # ignore the surface right at the point itself
            far = f * length > clear
            blocked |= far & (p[:, 2] < self.scene.height_at(p[:, 0], p[:, 1]) - 1e-3)
        return blocked

    # ---- ground control
    def add_gcps(self, n_ground_x: int = 4, n_ground_y: int = 3, roofs: int = 2, min_views: int = 3,
                 inset: float = 0.05) -> List[TruePoint]:
        """Ground points on a jittered grid over the covered area (away from buildings and the ditch),
        plus points on ``roofs`` building roofs; each kept only where it is seen in >= ``min_views`` images."""
        rng = np.random.default_rng(self.seed + 7)
        cover = np.array([s.centre[:2] for s in self.shots if s.kind == "vertical"])
        x0, y0 = cover.min(axis=0)
        x1, y1 = cover.max(axis=0)
        across = self.camera.height / self.camera.fy * self.altitude
        if y1 - y0 < 0.5 * across:  # a single strip: spread across its footprint
            y0, y1 = y0 - 0.3 * across, y1 + 0.3 * across
        wx, wy = x1 - x0, y1 - y0
        pts: List[TruePoint] = []
        for j in range(n_ground_y):
            for i in range(n_ground_x):
                fx_ = inset + (1 - 2 * inset) * (i / max(1, n_ground_x - 1))
                fy_ = inset + (1 - 2 * inset) * (j / max(1, n_ground_y - 1))
                cand = np.column_stack([x0 + fx_ * wx + rng.normal(0, 0.04 * wx, 40),
                                        y0 + fy_ * wy + rng.normal(0, 0.04 * wy, 40)])
                cand = cand[~self.scene.near_feature(cand[:, 0], cand[:, 1], 3.0)]
                if not len(cand):
                    continue
                xyz = np.column_stack([cand, self.scene.ground_at(cand[:, 0], cand[:, 1])])
                views = np.zeros(len(xyz), dtype=int)
                for s in self.shots:
                    views += self.visible(s, xyz)[0]
                best = int(np.argmax(views))  # the first of the best seen
                if views[best] < min_views:
                    continue
                p = TruePoint(f"G{len(pts) + 1:02d}", xyz[best], "ground")
                self._observe(p, min_views)
                pts.append(p)
        n_roof = 0
        for b in sorted(self.scene.buildings, key=lambda b: -(b.half_w * b.half_l)):
            if n_roof >= roofs:
                break
            u, v = rng.uniform(-0.4, 0.4, 2) * [b.half_w, b.half_l]
            c, s = math.cos(b.angle), math.sin(b.angle)
            x, y = b.cx + c * u - s * v, b.cy + s * u + c * v
            p = TruePoint(f"R{n_roof + 1:02d}", np.array([x, y, b.roof]), "roof")
            if self._observe(p, min_views):
                pts.append(p)
                n_roof += 1
        self.gcps = pts
        return pts

    def _observe(self, p: TruePoint, min_views: int) -> bool:
        obs = {}
        for s in self.shots:
            ok, px = self.visible(s, p.xyz[None])
            if ok[0]:
                obs[s.name] = px[0]
        p.observations = obs
        return len(obs) >= min_views

    def gcp(self, name: str) -> TruePoint:
        return next(p for p in self.gcps if p.name == name)

    def spread_control(self, n: int = 5) -> List[str]:
        """Names of ``n`` well-spread ground points: the four corners of the area and the centre first."""
        ground = [p for p in self.gcps if p.kind == "ground"]
        xy = np.array([p.xyz[:2] for p in ground])
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        targets = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]], 0.5 * (lo + hi)]
        chosen: List[str] = []
        for t in targets[:n]:
            d = np.linalg.norm(xy - np.asarray(t), axis=1)
            for k in np.argsort(d):
                if ground[k].name not in chosen:
                    chosen.append(ground[k].name)
                    break
        rest = [p for p in ground if p.name not in chosen]
        while len(chosen) < n and rest:  # farthest-point fill
            sel = np.array([self.gcp(c).xyz[:2] for c in chosen])
            far = max(rest, key=lambda p: np.min(np.linalg.norm(sel - p.xyz[:2], axis=1)))
            chosen.append(far.name)
            rest.remove(far)
        return chosen

    def gcp_set(self, control: Sequence[str], noise_px: float = 0.4, seed: int = 11,
                sigma_xy: float = 0.02, sigma_z: float = 0.05, only: Optional[Sequence[str]] = None,
                images: Optional[Sequence[str]] = None):
        """core.gcp.GCPSet in world coordinates (EPSG:32633): ``control`` names are CONTROL, the others
        CHECK; observations are the exact pixels plus N(0, noise_px) noise."""
        from core.io.gcp import CHECK, CONTROL, GCPSet, GroundPoint, Observation

        rng = np.random.default_rng(seed)
        pts = []
        keep = set(images) if images is not None else None
        for p in self.gcps:
            if only is not None and p.name not in only:
                continue
            obs = []
            for img in sorted(p.observations):
                if keep is not None and img not in keep:
                    continue
                xy = p.observations[img] + rng.normal(0.0, noise_px, 2)
                obs.append(Observation(img, float(xy[0]), float(xy[1])))
            w = p.world
            pts.append(GroundPoint(p.name, float(w[0]), float(w[1]), float(w[2]), sigma_xy, sigma_z,
                                   CONTROL if p.name in control else CHECK, obs))
        return GCPSet(CRS, pts)

    def camera_positions(self, sigma: float = 0.5, seed: int = 13, images: Optional[Sequence[str]] = None):
        """core.gcp.CameraPosition list (world) with N(0, sigma) noise on X, Y and Z; the noise is returned too."""
        from core.io.gcp import CameraPosition

        rng = np.random.default_rng(seed)
        out, noise = [], {}
        for s in self.shots:
            e = rng.normal(0.0, sigma, 3)
            if images is not None and s.name not in images:
                continue
            w = s.centre + ORIGIN + e
            noise[s.name] = e
            out.append(CameraPosition(s.name, float(w[0]), float(w[1]), float(w[2]), sigma, sigma))
        return out, noise

    # ---- images
    def render(self, folder: str, supersample: int = 2, ext: str = ".jpg", quality: int = 95,
               radiometry: Optional["Radiometry"] = None, jobs: int = 1) -> List[str]:
        """Render every shot into ``folder``; ``jobs`` > 1 renders in that many forked processes (POSIX), which
        share the scene without copying it: the same images, written in any order."""
        os.makedirs(folder, exist_ok=True)
        args = (folder, supersample, ext, quality, radiometry)
        if jobs > 1 and len(self.shots) > 1 and "fork" in multiprocessing.get_all_start_methods():
            global _RENDERING
            _RENDERING = (self, args)
            try:
                with multiprocessing.get_context("fork").Pool(jobs) as pool:
                    return pool.map(_render_shot, range(len(self.shots)), chunksize=1)
            finally:
                _RENDERING = None
        return [self._render_one(k, *args) for k in range(len(self.shots))]

    def _render_one(self, k: int, folder: str, supersample: int, ext: str, quality: int,
                    radiometry: Optional["Radiometry"]) -> str:
        s = self.shots[k]
        img = render_image(self.scene, self.camera, s, supersample, seed=self.seed * 1000 + k, radiometry=radiometry)
        path = os.path.join(folder, s.name if s.name.lower().endswith(ext) else s.name + ext)
        params = [cv2.IMWRITE_JPEG_QUALITY, quality] if ext.lower() in (".jpg", ".jpeg") else []
        if not cv2.imwrite(path, cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), params):
            raise OSError(f"cannot write {path}")
        return path

    # ---- tie points and a reconstruction built from the truth
    def tie_points(self, n: int = 2000, seed: int = 5, min_views: int = 2,
                   noise_px: float = 0.3) -> Tuple[np.ndarray, List[Dict[str, np.ndarray]]]:
        """``n`` random surface points over the covered area with their (noisy) observations."""
        rng = np.random.default_rng(seed)
        cover = np.array([s.centre[:2] for s in self.shots])
        lo, hi = cover.min(axis=0) - 0.3 * self.altitude, cover.max(axis=0) + 0.3 * self.altitude
        xy = rng.uniform(lo, hi, (n, 2))
        xyz = np.column_stack([xy, self.scene.height_at(xy[:, 0], xy[:, 1])])
        obs: List[Dict[str, np.ndarray]] = [dict() for _ in range(n)]
        for s in self.shots:
            ok, px = self.visible(s, xyz, margin=1.0)
            px = px + rng.normal(0.0, noise_px, px.shape)
            for i in np.flatnonzero(ok):
                obs[i][s.name] = px[i]
        keep = [i for i in range(n) if len(obs[i]) >= min_views]
        return xyz[keep], [obs[i] for i in keep]

    def truth_reconstruction(self, *, n_points: int = 2000, noise_px: float = 0.3, seed: int = 5,
                             camera: Optional[CameraModel] = None,
                             deform: Optional[Callable[[np.ndarray], np.ndarray]] = None,
                             model_from_local: Union[str, Tuple[float, np.ndarray, np.ndarray], None] = "random",
                             images: Optional[Sequence[str]] = None):
        """A pycolmap.Reconstruction from the truth, like an alignment would give.

        Observations are the true projections (plus ``noise_px``); the camera written into the model is
        ``camera`` (default the true one: give a wrong one to simulate a mis-calibrated block); poses and
        points are the truth, moved through ``deform`` (local xyz (N,3) -> (N,3); cameras follow the local
        rotation of the deformation) and then through the similarity ``model_from_local`` (scale, R, t;
        "random" for a seeded arbitrary one, None to stay in the local frame)."""
        import pycolmap

        rng = np.random.default_rng(seed + 1)
        shots = [s for s in self.shots if images is None or s.name in images]
        names = {s.name for s in shots}
        xyz, obs = self.tie_points(n_points, seed=seed, noise_px=noise_px)
        keep = [i for i in range(len(xyz)) if sum(1 for k in obs[i] if k in names) >= 2]
        xyz, obs = xyz[keep], [{k: v for k, v in obs[i].items() if k in names} for i in keep]
        rec = pycolmap.Reconstruction()
        cam = (camera or self.camera).pycolmap_camera(1)
        rec.add_camera_with_trivial_rig(cam)
        pts_model = deform(xyz) if deform is not None else xyz
        per_image: Dict[str, List[Tuple[int, np.ndarray]]] = {s.name: [] for s in shots}
        for i, o in enumerate(obs):
            for name, px in o.items():
                per_image[name].append((i, px))
        image_ids: Dict[str, int] = {}
        point2d_index: Dict[Tuple[str, int], int] = {}
        for k, s in enumerate(shots, start=1):
            rot, centre = s.rotation, s.centre
            if deform is not None:
                rot, centre = _deformed_pose(deform, rot, centre)
            rows = per_image[s.name]
            kps = np.array([px for _, px in rows], dtype=float).reshape(-1, 2)
            im = pycolmap.Image(name=s.name, keypoints=kps, camera_id=1, image_id=k)
            pose = pycolmap.Rigid3d(pycolmap.Rotation3d(rot), -rot @ centre)
            rec.add_image_with_trivial_frame(im, pose)
            image_ids[s.name] = k
            for j, (i, _) in enumerate(rows):
                point2d_index[(s.name, i)] = j
        for i, o in enumerate(obs):
            track = pycolmap.Track()
            for name in o:
                track.add_element(image_ids[name], point2d_index[(name, i)])
            rec.add_point3D(pts_model[i], track, np.array([128, 128, 128], dtype=np.uint8))
        if isinstance(model_from_local, str) and model_from_local == "random":
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            rotm = pycolmap.Rotation3d(q).matrix()  # xyzw
            model_from_local = (float(rng.uniform(0.05, 0.3)), np.asarray(rotm), rng.normal(0, 20.0, 3))
        if model_from_local is not None:
            sc, r, t = model_from_local
            rec.transform(pycolmap.Sim3d(sc, pycolmap.Rotation3d(np.asarray(r)), np.asarray(t, dtype=float)))
        rec.update_point_3d_errors()
        return rec


def _deformed_pose(deform, rot: np.ndarray, centre: np.ndarray, h: float = 0.5):
    c2 = deform(centre[None])[0]
    jac = np.empty((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        jac[:, k] = (deform((centre + e)[None])[0] - deform((centre - e)[None])[0]) / (2 * h)
    u, _, vt = np.linalg.svd(jac)
    q = u @ vt
    if np.linalg.det(q) < 0:
        u[:, -1] *= -1
        q = u @ vt
    return rot @ q.T, c2


def dome(amplitude: float, centre_xy: Sequence[float], radius: float) -> Callable[[np.ndarray], np.ndarray]:
    """A smooth vertical bending: z += amplitude * (1 - (d / radius)^2) with d the distance from ``centre_xy``
    (a long strip that sags or bows: no similarity removes it)."""
    c = np.asarray(centre_xy, dtype=float)

    def f(xyz: np.ndarray) -> np.ndarray:
        xyz = np.array(xyz, dtype=float, copy=True)
        d2 = np.sum((xyz[:, :2] - c) ** 2, axis=1) / (radius * radius)
        xyz[:, 2] += amplitude * (1.0 - d2)
        return xyz

    return f


def similarity_fit(src: np.ndarray, dst: np.ndarray) -> Tuple[float, np.ndarray, np.ndarray]:
    """Least-squares similarity dst ~ s * R @ src + t (Umeyama), independent of core.georef."""
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    u, sv, vt = np.linalg.svd(b.T @ a / len(src))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    r = u @ d @ vt
    sc = float(np.trace(np.diag(sv) @ d) / np.mean(np.sum(a * a, axis=1)))
    return sc, r, md - sc * r @ ms


# --------------------------------------------------------------------------------------------------
# ready-made blocks
# --------------------------------------------------------------------------------------------------

DEFAULT_CAMERA = CameraModel(800, 600, 650.0, 650.0, 403.7, 296.2, k1=-0.08, k2=0.02, p1=0.0006, p2=-0.0004)


def vertical_block(seed: int = 1, camera: CameraModel = DEFAULT_CAMERA, altitude: float = 50.0,
                   n_strips: int = 3, per_strip: int = 6, forward_overlap: float = 0.75,
                   side_overlap: float = 0.35, attitude_sigma_deg: float = 1.0, position_jitter: float = 0.5,
                   orbit: int = 0, orbit_tilt_deg: float = 30.0, n_buildings: int = 5,
                   gcp_grid: Tuple[int, int] = (4, 3), roofs: int = 2, epoch: int = 0,
                   low_texture: Optional[Tuple[float, float, float, float]] = None,
                   low_texture_contrast: float = 0.1) -> SyntheticBlock:
    """Parallel strips along local x (serpentine: every other strip flown the other way), image x along
    track; optionally ``orbit`` oblique shots on a circle around the centre looking at it.  ``low_texture``:
    a low-texture patch (Scene.low_texture) as fractions (x0, y0, x1, y1) of the scene's bounds.  ``epoch`` 1 or 2:
    the same terrain in two epochs (``make_scene(epoch=...)``: a car that moved, a new building, new crop marks,
    another sun); 0 (default): the scene as always."""
    rng = np.random.default_rng(seed)
    along = camera.width * altitude / camera.fx
    across = camera.height * altitude / camera.fy
    base = (1.0 - forward_overlap) * along
    spacing = (1.0 - side_overlap) * across
    length = (per_strip - 1) * base
    widthy = (n_strips - 1) * spacing
    margin = 0.6 * max(along, across) + 5.0
    bounds = (-length / 2 - margin, -widthy / 2 - margin, length / 2 + margin, widthy / 2 + margin)
    scene = make_scene(seed, bounds, n_buildings=n_buildings, epoch=epoch)
    if low_texture is not None:
        fx0, fy0, fx1, fy1 = low_texture
        bw, bh = bounds[2] - bounds[0], bounds[3] - bounds[1]
        scene.low_texture = (bounds[0] + fx0 * bw, bounds[1] + fy0 * bh, bounds[0] + fx1 * bw, bounds[1] + fy1 * bh)
        scene.low_texture_contrast = low_texture_contrast
    z_fly = scene.base_z + altitude
    shots: List[Shot] = []
    for si in range(n_strips):
        y = -widthy / 2 + si * spacing
        heading = 1.0 if si % 2 == 0 else -1.0
        for k in range(per_strip):
            x = heading * (-length / 2 + k * base)
            c = np.array([x, y, z_fly]) + rng.normal(0.0, position_jitter, 3)
            r = look_at(c, c - np.array([0.0, 0.0, 1.0]), np.array([0.0, heading, 0.0]))
            # image x along the flight direction: up hint = left of track
            r = small_rotation(rng, attitude_sigma_deg) @ r
            shots.append(Shot(f"S{si + 1}_{k + 1:02d}.jpg", r, c, "vertical", si + 1))
    if orbit:
        radius = max(length, widthy) / 2 + 0.0
        for k in range(orbit):
            a = 2 * math.pi * k / orbit
            dist = altitude * math.tan(math.radians(orbit_tilt_deg))
            target = np.array([radius * 0.2 * math.cos(a), radius * 0.2 * math.sin(a), scene.base_z])
            c = target + np.array([dist * math.cos(a), dist * math.sin(a), altitude])
            r = small_rotation(rng, attitude_sigma_deg) @ look_at(c, target, np.array([0.0, 0.0, 1.0]))
            shots.append(Shot(f"O_{k + 1:02d}.jpg", r, c, "oblique", 0))
    block = SyntheticBlock(scene, camera, shots, altitude, seed=seed)
    block.add_gcps(gcp_grid[0], gcp_grid[1], roofs)
    return block


def single_strip(seed: int = 3, camera: CameraModel = DEFAULT_CAMERA, altitude: float = 50.0, n: int = 12,
                 forward_overlap: float = 0.7, **kw) -> SyntheticBlock:
    """One long strip (the classic case where a block bends)."""
    return vertical_block(seed, camera, altitude, n_strips=1, per_strip=n, forward_overlap=forward_overlap,
                          gcp_grid=kw.pop("gcp_grid", (6, 2)), **kw)


# --------------------------------------------------------------------------------------------------
# high obliques: an orbit around the site with the far field, the horizon and the sky in view (issue 13)
# --------------------------------------------------------------------------------------------------

# a small wide-angle frame (vertical half angle ~31 deg): at 65 deg off nadir the top rows look above the horizon
ORBIT_CAMERA = CameraModel(480, 360, 300.0, 300.0, 241.3, 178.6, k1=-0.05, k2=0.01, p1=0.0004, p2=-0.0003)
GROUND_TINT = np.array([1.06, 1.0, 0.74], dtype=np.float32)  # RGB factors of the grey ground (brownish fields)
SKY_ZENITH = np.array([0.52, 0.66, 0.92], dtype=np.float32)  # RGB of the sky well above the horizon
HAZE = np.array([0.80, 0.82, 0.86], dtype=np.float32)  # RGB of the haze the far field fades into
HAZE_DISTANCE = 1500.0  # m: the ground keeps exp(-distance / this) of its contrast
FAR_PERIOD = 512.0  # m: the far-field texture repeats with this period (the ground goes on to the horizon)
FAR_RES = 0.5  # m per far-field texture cell


@lru_cache(maxsize=2)
def _far_texture(seed: int) -> np.ndarray:
    """Periodic grey texture (FAR_PERIOD square at FAR_RES) of the ground beyond the scene: band-limited noise
    (FFT, so it wraps) and soft-edged fields."""
    n = int(round(FAR_PERIOD / FAR_RES))
    rng = np.random.default_rng(seed + 202)
    f = np.fft.fftfreq(n, d=FAR_RES)
    fr = np.hypot(f[None, :], f[:, None])
    tex = np.zeros((n, n))
    for wavelength, weight in ((1.5, 0.8), (4.0, 1.0), (12.0, 0.9), (40.0, 0.7)):
        band = np.exp(-0.5 * ((fr - 1.0 / wavelength) / (0.35 / wavelength)) ** 2)
        noise = np.real(np.fft.ifft2(np.fft.fft2(rng.normal(0.0, 1.0, (n, n))) * band))
        tex += weight * noise / max(noise.std(), 1e-9)
    fields = np.real(np.fft.ifft2(np.fft.fft2(rng.normal(0.0, 1.0, (n, n))) * np.exp(-0.5 * (fr * 60.0) ** 2)))
    tex = tex / 3.0 + 1.2 * np.tanh(fields / max(fields.std(), 1e-9) * 3.0)
    return np.clip(0.5 + 0.12 * tex, 0.05, 0.95).astype(np.float32)


CLOUD_CELL = (360.0 / 512, 0.5)  # degrees of azimuth and of elevation per cloud texture cell (clouds far away)


@lru_cache(maxsize=2)
def _cloud_texture(seed: int) -> Tuple[np.ndarray, np.ndarray]:
    """(density 0..1, shading 0.8..1) periodic tiles of the clouds: band-limited noise, thresholded."""
    n = 512
    rng = np.random.default_rng(seed + 303)
    f = np.fft.fftfreq(n)
    fr = np.hypot(f[None, :], f[:, None])
    out = []
    for wavelength in (20.0, 5.0):  # cells
        band = np.exp(-0.5 * (fr * wavelength / 2.0) ** 2) - np.exp(-0.5 * (fr * wavelength) ** 2)
        noise = np.real(np.fft.ifft2(np.fft.fft2(rng.normal(0.0, 1.0, (n, n))) * band))
        out.append(noise / max(noise.std(), 1e-9))
    density = np.clip((out[0] + 0.3 * out[1] - 0.2) * 3.0, 0.0, 1.0).astype(np.float32)
    shading = (0.92 + 0.03 * np.tanh(out[1])).astype(np.float32)
    return density, shading


def _wrap_bilinear(tex: np.ndarray, mx: np.ndarray, my: np.ndarray) -> np.ndarray:
    """Bilinear samples of a periodic tile at cell coordinates (any size, wrapping around)."""
    n0, n1 = tex.shape
    c0, r0 = np.floor(mx).astype(np.int64), np.floor(my).astype(np.int64)
    fx_, fy_ = (mx - c0).astype(np.float32), (my - r0).astype(np.float32)
    c0, r0, c1, r1 = c0 % n1, r0 % n0, (c0 + 1) % n1, (r0 + 1) % n0
    return ((1 - fy_) * ((1 - fx_) * tex[r0, c0] + fx_ * tex[r0, c1])
            + fy_ * ((1 - fx_) * tex[r1, c0] + fx_ * tex[r1, c1]))


def _far_hit(scene: Scene, centre: np.ndarray, d: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Intersections (N,3) of downward rays with the smooth analytic ground (no buildings; ramp and hills as
    ``scene.ground_at``), by Newton's method from the plane z = base_z."""
    t = (scene.base_z - centre[2]) / d[:, 2]
    h = 0.05
    for _ in range(iterations):
        p = centre[None, :] + t[:, None] * d
        f = p[:, 2] - scene.ground_at(p[:, 0], p[:, 1])
        q = p + h * d
        fq = q[:, 2] - scene.ground_at(q[:, 0], q[:, 1])
        slope = (fq - f) / h
        t = np.maximum(t - f / np.where(slope < -1e-6, slope, d[:, 2]), 1e-3)
    return centre[None, :] + t[:, None] * d


def _enters_scene(scene: Scene, centre: np.ndarray, d: np.ndarray) -> np.ndarray:
    """True for rays whose part between the scene's highest and lowest surface crosses its bounds (Liang-Barsky)."""
    zmax, zmin = scene.max_height(), scene.min_height()
    t0 = np.maximum((zmax - centre[2]) / d[:, 2], 0.0)
    t1 = (zmin - centre[2]) / d[:, 2]
    xmin, ymin, xmax, ymax = scene.bounds
    lo, hi = t0.copy(), t1.copy()
    for k, (a, b) in enumerate(((xmin, xmax), (ymin, ymax))):
        dk = d[:, k]
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = (a - centre[k]) / dk
            tb = (b - centre[k]) / dk
        still = np.abs(dk) < 1e-12
        inside = (centre[k] >= a) & (centre[k] <= b)
        lo = np.where(still, np.where(inside, lo, np.inf), np.maximum(lo, np.minimum(ta, tb)))
        hi = np.where(still, np.where(inside, hi, -np.inf), np.minimum(hi, np.maximum(ta, tb)))
    return lo <= hi


def render_oblique_image(scene: Scene, camera: CameraModel, shot: Shot, supersample: int = 2, noise: float = 1.5,
                         seed: int = 0, clouds: float = 0.0,
                         cloud_drift: Tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """RGB uint8 image (height, width, 3) of a shot that may see beyond the scene and above the horizon.

    Rays that cross the scene are cast into its height field as in :func:`render_image`; rays that miss it meet
    the smooth analytic ground beyond (a periodic far-field texture, so the ground goes on to the horizon); rays
    at or above the horizontal are sky (blue, paler towards the horizon).  Everything fades into haze with
    distance (``HAZE_DISTANCE``).  Ground grey values are tinted brownish (``GROUND_TINT``).  ``clouds`` > 0: white
    clouds of that opacity far away (a pattern of azimuth and elevation), more than 2-4 degrees above the horizon,
    moved by ``cloud_drift`` (degrees of azimuth and elevation: they drift between exposures, so matching them
    would be wrong)."""
    s = int(supersample)
    canvas_xn, map_x, map_y, vignetting = _canvas_geometry(camera, s)
    d = shot.rays(canvas_xn).reshape(-1, 3)
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    sky = d[:, 2] > -1e-4
    ground = ~sky
    xyz = np.zeros((len(d), 3))
    near = ground & _enters_scene(scene, shot.centre, np.where(ground[:, None], d, [[0.0, 0.0, -1.0]]))
    if near.any():
        dn = d[near]
        pad = -len(dn) % 1024  # _ray_cast remaps 2-D arrays: rows of 1024 rays (padded with nadir rays)
        dn = np.concatenate([dn, np.tile([[0.0, 0.0, -1.0]], (pad, 1))]).reshape(-1, 1024, 3)
        xyz[near] = _ray_cast(scene, shot.centre, dn, step=0.25).reshape(-1, 3)[:len(d[near].reshape(-1, 3))]
    xmin, ymin, xmax, ymax = scene.bounds
    inset = 2 * scene.height_res
    far = ground & ~(near & (xyz[:, 0] > xmin + inset) & (xyz[:, 0] < xmax - inset)
                     & (xyz[:, 1] > ymin + inset) & (xyz[:, 1] < ymax - inset))
    if far.any():
        xyz[far] = _far_hit(scene, shot.centre, d[far])
    grey = np.zeros(len(d), dtype=np.float32)
    inner = ground & ~far
    if inner.any():
        grey[inner] = _surface_value(scene, xyz[inner])
    if far.any():
        tex = _far_texture(scene.seed)
        n = tex.shape[0]
        grey[far] = _wrap_bilinear(tex, np.mod(xyz[far, 0] / FAR_RES, n), np.mod(-xyz[far, 1] / FAR_RES, n))
    rgb = np.clip(grey[:, None] * GROUND_TINT[None, :], 0.0, 1.0)
    dist = np.linalg.norm(xyz - shot.centre[None, :], axis=1)
    keep = np.exp(-dist / HAZE_DISTANCE).astype(np.float32)[:, None]
    rgb = rgb * keep + HAZE[None, :] * (1.0 - keep)
    elev = np.clip(d[sky, 2], 0.0, 1.0)
    w = np.exp(-elev / 0.12)[:, None].astype(np.float32)
    rgb[sky] = SKY_ZENITH[None, :] * (1.0 - w) + HAZE[None, :] * w
    if clouds > 0 and sky.any():
        ds = d[sky]
        elev_deg = np.degrees(np.arcsin(np.clip(ds[:, 2], -1.0, 1.0)))
        cx = (np.degrees(np.arctan2(ds[:, 1], ds[:, 0])) + cloud_drift[0]) / CLOUD_CELL[0]
        cy = (elev_deg + cloud_drift[1]) / CLOUD_CELL[1]
        density_t, shading_t = _cloud_texture(scene.seed)
        fade = np.clip((elev_deg - 2.0) / 2.0, 0.0, 1.0).astype(np.float32)
        a = (clouds * fade * _wrap_bilinear(density_t, cx, cy))[:, None]
        white = _wrap_bilinear(shading_t, cx, cy)[:, None] * np.array([0.97, 0.97, 0.98], np.float32)[None, :]
        rgb[sky] = rgb[sky] * (1.0 - a) + white * a
    canvas = rgb.reshape(canvas_xn.shape[:2] + (3,)).astype(np.float32)
    canvas = cv2.GaussianBlur(canvas, (0, 0), 0.45 * s)
    img = cv2.remap(canvas, map_x, map_y, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
    img = img * vignetting[:, :, None] * 255.0
    img += np.random.default_rng(seed).normal(0.0, noise, img.shape).astype(np.float32)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


@dataclass
class ObliqueBlock(SyntheticBlock):
    """A block of high obliques: rendered in colour with the far field, the horizon and the sky
    (:func:`render_oblique_image`); ``sky_mask`` is the truth of which pixels see the sky."""

    tilts: Dict[str, float] = field(default_factory=dict)  # image -> degrees off nadir
    clouds: float = 0.0  # opacity of the clouds (render_oblique_image)
    cloud_drift: Tuple[float, float] = (2.0, 0.1)  # degrees (azimuth, elevation) the clouds move per exposure

    def render(self, folder: str, supersample: int = 2, ext: str = ".jpg", quality: int = 95) -> List[str]:
        os.makedirs(folder, exist_ok=True)
        paths = []
        for k, s in enumerate(self.shots):
            img = render_oblique_image(self.scene, self.camera, s, supersample, seed=self.seed * 1000 + k,
                                       clouds=self.clouds,
                                       cloud_drift=(k * self.cloud_drift[0], k * self.cloud_drift[1]))
            path = os.path.join(folder, s.name if s.name.lower().endswith(ext) else s.name + ext)
            params = [cv2.IMWRITE_JPEG_QUALITY, quality] if ext.lower() in (".jpg", ".jpeg") else []
            if not cv2.imwrite(path, cv2.cvtColor(img, cv2.COLOR_RGB2BGR), params):
                raise OSError(f"cannot write {path}")
            paths.append(path)
        return paths

    def sky_mask(self, shot: Union[Shot, str], margin_deg: float = 0.0) -> np.ndarray:
        """(height, width) bool: True where the pixel's ray (through the true distorted camera) points at or above
        the horizontal, i.e. at the sky (``margin_deg`` > 0 counts that much below the horizon too)."""
        shot = self.shot(shot) if isinstance(shot, str) else shot
        c = self.camera
        jj, ii = np.meshgrid(np.arange(c.width, dtype=float) + 0.5, np.arange(c.height, dtype=float) + 0.5)
        xu = c.undistort(c.normalized_from_pixel(np.stack([jj, ii], axis=-1)))
        d = shot.rays(xu)
        elev = np.degrees(np.arcsin(d[..., 2] / np.linalg.norm(d, axis=-1)))
        return elev >= -margin_deg

    def in_sky(self, shot: Union[Shot, str], px: np.ndarray, margin_deg: float = 0.0) -> np.ndarray:
        """For pixels (N,2) of ``shot`` (COLMAP convention): True where they see the sky (as ``sky_mask``)."""
        shot = self.shot(shot) if isinstance(shot, str) else shot
        c = self.camera
        xu = c.undistort(c.normalized_from_pixel(np.atleast_2d(np.asarray(px, dtype=float))))
        d = shot.rays(xu)
        return np.degrees(np.arcsin(d[:, 2] / np.linalg.norm(d, axis=1))) >= -margin_deg

    def _observe(self, p: TruePoint, min_views: int) -> bool:
        """As ``SyntheticBlock._observe`` (the same views, the same pixels), with the occlusion of the point
        marched for all the views that see it at once (the same samples along each ray, so the same GCPs):
        obliques' rays run long below the highest surface, and marched one view at a time they took 5 of the
        6 CPU seconds of ``orbit_block`` (now 0.1)."""
        xyz = np.atleast_2d(np.asarray(p.xyz, dtype=float))
        seen = []
        for s in self.shots:
            px, depth = self.project(s, xyz)
            ok = (depth > 0) & self.camera.inside(px, 2.0)
            with np.errstate(divide="ignore", invalid="ignore"):
                r_u = np.hypot(*(self.to_camera_xy(s, xyz).T))
            ok &= np.isfinite(r_u) & (r_u <= 1.001 * self._corner_radius())
            if ok[0]:
                seen.append((s, px[0]))
        blocked = self._occluded_views(np.array([s.centre for s, _ in seen]).reshape(-1, 3), xyz[0])
        p.observations = {s.name: px for (s, px), b in zip(seen, blocked) if not b}
        return len(p.observations) >= min_views

    def _occluded_views(self, centres: np.ndarray, point: np.ndarray, step: float = 0.2) -> np.ndarray:
        """``_occluded(centre, point)`` for each of ``centres`` (M,3), in one march: each ray sampled where
        ``_occluded`` samples it (its own number of steps; the shorter rays padded and their padding ignored)."""
        if not len(centres):
            return np.zeros(0, dtype=bool)
        zmax = self.scene.max_height()
        xyz = point[None, :]
        seg = centres - xyz
        length = np.linalg.norm(seg, axis=1)
        frac_top = np.clip((zmax - xyz[:, 2]) / np.maximum(seg[:, 2], 1e-9), 0.0, 1.0)
        counts = [int(np.ceil((ft * ln) / step)) + 1 for ft, ln in zip(frac_top, length)]
        width = max(counts)
        si = np.zeros((len(centres), width))
        valid = np.zeros((len(centres), width), dtype=bool)
        for k, n in enumerate(counts):
            si[k, :n] = np.linspace(0.0, 1.0, n + 1)[1:]
            valid[k, :n] = True
        f = si * frac_top[:, None]
        q = xyz[:, None, :] + f[:, :, None] * seg[:, None, :]
        far = f * length[:, None] > 0.03  # as _occluded: the surface right at the point itself is ignored
        under = q[..., 2] < self.scene.height_at(q[..., 0], q[..., 1]) - 1e-3
        return np.any(valid & far & under, axis=1)

    def add_site_gcps(self, half: float, n: int = 4, roofs: int = 2, min_views: int = 3) -> List[TruePoint]:
        """Ground points on a jittered n x n grid over the square of ``half`` metres around the site's centre
        (away from buildings and the ditch), plus points on ``roofs`` roofs; kept where seen in >= ``min_views``."""
        rng = np.random.default_rng(self.seed + 7)
        pts: List[TruePoint] = []
        for j in range(n):
            for i in range(n):
                fx_, fy_ = -1.0 + 2.0 * i / max(1, n - 1), -1.0 + 2.0 * j / max(1, n - 1)
                cand = np.column_stack([fx_ * half + rng.normal(0, 0.06 * half, 40),
                                        fy_ * half + rng.normal(0, 0.06 * half, 40)])
                cand = cand[~self.scene.near_feature(cand[:, 0], cand[:, 1], 3.0)]
                for xy in cand[:8]:
                    p = TruePoint(f"G{len(pts) + 1:02d}", np.array([xy[0], xy[1], float(self.scene.ground_at(*xy))]),
                                  "ground")
                    if self._observe(p, min_views):
                        pts.append(p)
                        break
        n_roof = 0
        for b in sorted(self.scene.buildings, key=lambda b: -(b.half_w * b.half_l)):
            if n_roof >= roofs:
                break
            p = TruePoint(f"R{n_roof + 1:02d}", np.array([b.cx, b.cy, b.roof]), "roof")
            if self._observe(p, min_views):
                pts.append(p)
                n_roof += 1
        self.gcps = pts
        return pts


def scaled_camera(camera: CameraModel, factor: float) -> CameraModel:
    """``camera`` with its image ``factor`` times the size (width and height rounded), the same field of view and
    distortion: focal lengths and principal point scaled with it (pixel coordinates from the image's corner)."""
    w, h = int(round(camera.width * factor)), int(round(camera.height * factor))
    return replace(camera, width=w, height=h, fx=camera.fx * w / camera.width, fy=camera.fy * h / camera.height,
                   cx=camera.cx * w / camera.width, cy=camera.cy * h / camera.height)


def orbit_block(seed: int = 21, camera: CameraModel = ORBIT_CAMERA, altitude: float = 40.0,
                tilts: Sequence[float] = (45.0, 65.0), per_ring: int = 8, half_size: float = 65.0,
                attitude_sigma_deg: float = 1.0, position_jitter: float = 0.5, target_jitter: float = 3.0,
                n_buildings: int = 5, gcp_half: float = 22.0, ring_offset: float = 0.5,
                clouds: float = 0.8, image_scale: float = 1.0) -> ObliqueBlock:
    """Cameras circling the site, ``per_ring`` per tilt (degrees off nadir), all ``altitude`` above the base and
    looking at (near) the centre, image up = world up (the horizon at the top of the steep ones; at 65 deg with
    ORBIT_CAMERA the top ~40 rows are sky).  The rings are offset by ``ring_offset`` of a step in azimuth.  The scene is
    ``half_size`` m either side of the centre (no ramp, so the ground beyond it continues smoothly); ``clouds``: their
    opacity in the sky (drifting between exposures), 0 for a clear sky.  ``image_scale``: the photos that much
    smaller (or larger) than ``camera``'s, the same field of view and distortion (at the same ``altitude`` the GSD
    grows by 1 / image_scale; ``altitude`` and the jitters in metres scaled with it: the same views at the same
    GSD)."""
    if image_scale != 1.0:
        camera = scaled_camera(camera, image_scale)
    rng = np.random.default_rng(seed)
    scene = make_scene(seed, (-half_size, -half_size, half_size, half_size), n_buildings=n_buildings)
    scene.ramp = (0.0, 0.0)
    scene._rasters.clear()
    shots: List[Shot] = []
    tilt_of: Dict[str, float] = {}
    for ri, tilt in enumerate(tilts):
        dist = altitude * math.tan(math.radians(tilt))
        for k in range(per_ring):
            a = 2 * math.pi * (k + ring_offset * ri) / per_ring
            target = np.array([*rng.normal(0.0, target_jitter, 2), scene.base_z])
            c = np.array([dist * math.cos(a), dist * math.sin(a), scene.base_z + altitude])
            c = c + rng.normal(0.0, position_jitter, 3)
            r = small_rotation(rng, attitude_sigma_deg) @ look_at(c, target, np.array([0.0, 0.0, 1.0]))
            name = f"T{int(round(tilt))}_{k + 1:02d}.jpg"
            shots.append(Shot(name, r, c, "oblique", ri + 1))
            tilt_of[name] = float(tilt)
    block = ObliqueBlock(scene, camera, shots, altitude, seed=seed, tilts=tilt_of, clouds=clouds)
    block.add_site_gcps(gcp_half)
    return block
