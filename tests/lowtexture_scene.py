"""A synthetic low-texture farmland block with a known DSM (issue 33): ploughed fields with faint periodic furrows
at about 30 degrees to the flight strips, a field of crop rows, stubble, a gravel road, a few trees and one
building, on gently rolling ground.

The texture is procedural (a function of the ground position: furrows are sinusoids, soil grain a tiled noise
raster sampled by position), so a 10-megapixel photo is rendered without a texture raster over the whole block;
the heights are a raster (``Scene.height_raster``, at ``height_res``) ray-cast as in :mod:`tests.synthetic`.

- :func:`farm_block` ``(camera, gsd, n_strips, per_strip)``: the flight (strips along local x, 80 % forward and
  60 % side overlap by default) at the altitude that gives ``gsd``; the scene scales with the block, the furrows
  and crop rows do not (they are metres on the ground: 0.75 m and 0.5 m);
- :func:`small_block` (the fast test's: 640 x 480 px, 2 strips of 5) and :func:`full_block` (the benchmark's:
  3600 x 2700 px, 9.7 MP);
- the truth: ``block.scene.height_at(x, y)``; ``block.scene.field_mask(x, y)``: the cells on the fields (away
  from the road, the trees and the building), where "RMSE over the fields" is judged.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from functools import lru_cache
from typing import List, Optional, Tuple

import cv2
import numpy as np

from tests import synthetic as syn

FURROW_PERIOD = 0.75  # m, ploughed fields
FURROW_ANGLE_DEG = 30.0  # the furrows' lines to the flight strips (local x)
CROP_PERIOD = 0.5  # m, crop rows
CROP_ANGLE_DEG = 95.0  # the rows' lines to the strips
GRAIN_RES = 0.02  # m per cell of the tiled soil-grain noise


@dataclass
class Tree:
    cx: float
    cy: float
    radius: float
    height: float  # crown top above the ground


@dataclass
class FarmScene(syn.Scene):
    """Fields (Voronoi cells of ``field_seeds``, each a kind: 0 furrows, 1 crop rows, 2 stubble), a road along
    ``road`` (p0, p1, half width), ``trees`` (round crowns) and ``buildings`` (boxes)."""

    field_seeds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    field_kind: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    field_tone: np.ndarray = field(default_factory=lambda: np.zeros(0))
    field_angle: np.ndarray = field(default_factory=lambda: np.zeros(0))  # of the furrows' / rows' lines, from x
    road: Tuple[Tuple[float, float], Tuple[float, float], float] = ((0.0, 0.0), (1.0, 0.0), 2.5)
    trees: List[Tree] = field(default_factory=list)
    contrast: float = 1.0  # scales every texture amplitude of the fields

    # ---- heights
    def ground_at(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        z = self.base_z + self.ramp[0] * x + self.ramp[1] * y
        for hx, hy, amp, sig in self.hills:
            z = z + amp * np.exp(-((x - hx) ** 2 + (y - hy) ** 2) / (2.0 * sig * sig))
        return z

    def height_at(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        z = self.ground_at(x, y)
        for t in self.trees:
            r2 = ((x - t.cx) ** 2 + (y - t.cy) ** 2) / (t.radius * t.radius)
            crown = t.height * np.sqrt(np.clip(1.0 - r2, 0.0, None)) ** 0.5
            z = np.where(r2 < 1.0, np.maximum(z, self.ground_at(t.cx, t.cy) + 0.35 * t.height + 0.65 * crown), z)
        for b in self.buildings:
            z = np.where(b.contains(x, y), np.maximum(z, b.roof), z)
        return z

    def max_height(self) -> float:
        hills = float(np.sum(np.clip(self.hills[:, 2], 0, None)))
        xmin, ymin, xmax, ymax = self.bounds
        ramp = abs(self.ramp[0]) * max(abs(xmin), abs(xmax)) + abs(self.ramp[1]) * max(abs(ymin), abs(ymax))
        tops = [b.roof for b in self.buildings] + [self.base_z + hills + ramp + t.height for t in self.trees]
        return max([self.base_z + hills + ramp] + tops) + 0.01

    def min_height(self) -> float:
        xmin, ymin, xmax, ymax = self.bounds
        ramp = abs(self.ramp[0]) * max(abs(xmin), abs(xmax)) + abs(self.ramp[1]) * max(abs(ymin), abs(ymax))
        return self.base_z + float(np.sum(np.clip(self.hills[:, 2], None, 0))) - ramp - 0.01

    # ---- what is where
    def road_distance(self, x, y) -> np.ndarray:
        (x0, y0), (x1, y1), _ = self.road
        d = np.array([x1 - x0, y1 - y0], dtype=float)
        d /= np.linalg.norm(d)
        return np.abs(-(np.asarray(x) - x0) * d[1] + (np.asarray(y) - y0) * d[0])

    def field_index(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=np.float32)
        y = np.asarray(y, dtype=np.float32)
        best = np.full(x.shape, np.inf, np.float32)
        idx = np.zeros(x.shape, np.int32)
        for k, (sx, sy) in enumerate(self.field_seeds):
            d = (x - np.float32(sx)) ** 2 + (y - np.float32(sy)) ** 2
            closer = d < best
            best[closer] = d[closer]
            idx[closer] = k
        return idx

    def field_mask(self, x, y, margin: float = 1.0) -> np.ndarray:
        """True on the fields: farther than ``margin`` from the road, a tree crown and the building."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        out = self.road_distance(x, y) > self.road[2] + margin
        for t in self.trees:
            out &= np.hypot(x - t.cx, y - t.cy) > t.radius + margin
        for b in self.buildings:
            out &= ~b.contains(x, y, margin)
        return out

    # ---- grey value of ground points
    def grey(self, xyz: np.ndarray) -> np.ndarray:
        """Grey value (about 0..1) of surface points (..., 3): fields, road, crowns, roof and walls, shaded."""
        x = xyz[..., 0].astype(np.float32)
        y = xyz[..., 1].astype(np.float32)
        z = xyz[..., 2].astype(np.float32)
        fi = self.field_index(x, y)
        tone = self.field_tone.astype(np.float32)[fi]
        ang = self.field_angle.astype(np.float32)[fi]
        kind = self.field_kind[fi]
        along = y * np.cos(ang) - x * np.sin(ang)  # across the lines
        grain = _grain(self.seed, x, y)  # soil grain: faint, fine
        moist = _grain(self.seed + 7, x / 40.0, y / 40.0)  # broad soil moisture / crop marks
        c = np.float32(self.contrast)
        furrow = np.where(kind == 0, 0.025 * np.sin(2 * np.pi * along / FURROW_PERIOD), 0.0)
        rows = np.where(kind == 1, 0.03 * np.clip(np.sin(2 * np.pi * along / CROP_PERIOD) * 3.0, -1, 1), 0.0)
        val = tone + c * (furrow + rows + 0.012 * grain + 0.05 * moist)
        rd = self.road_distance(x, y)
        half = self.road[2]
        road = rd < half
        val = np.where(road, 0.72 + 0.05 * _grain(self.seed + 3, x * 0.5, y * 0.5), val)
        val = np.where((rd >= half) & (rd < half + 0.4), 0.45, val)  # its verge
        for t in self.trees:
            r = np.hypot(x - t.cx, y - t.cy)
            crown = r < t.radius
            leaves = 0.22 + 0.08 * _grain(self.seed + 11, x * 2.0, y * 2.0) + 0.05 * (r / t.radius)
            val = np.where(crown, leaves, val)
            shadow = (~crown) & (np.hypot(x - t.cx - 0.6 * t.radius, y - t.cy + 0.4 * t.radius) < t.radius)
            val = np.where(shadow, 0.7 * val, val)
        for b in self.buildings:
            inside = b.contains(x, y)
            u, v = b.local_uv(x, y)
            roof = (z >= b.roof - 0.03) & inside
            val = np.where(roof, 0.55 + 0.15 * np.sign(np.sin(2 * np.pi * u / 0.9)), val)
            wall = (z < b.roof - 0.03) & b.contains(x, y, 0.1)
            val = np.where(wall, 0.4 + 0.1 * ((np.floor(z * 2.0) % 2) - 0.5) + 0.05 * np.sin(v + u), val)
        return np.clip(val * self._shade(x, y), 0.02, 0.98).astype(np.float32)

    def _shade(self, x, y) -> np.ndarray:
        h = self.height_raster()
        if "shade" not in self._rasters:
            gy, gx = np.gradient(h.astype(np.float32), self.height_res)
            gx, gy = np.clip(gx, -2, 2), np.clip(-gy, -2, 2)
            self._rasters["shade"] = np.clip((1.0 + 0.5 * gx + 0.3 * gy) / np.sqrt(1.0 + gx ** 2 + gy ** 2),
                                             0.3, 1.3).astype(np.float32)
        mx, my = self.raster_coords(x, y, self.height_res)
        return syn._sample(self._rasters["shade"], mx, my)


@lru_cache(maxsize=4)
def _grain_tile(seed: int) -> np.ndarray:
    """A periodic tile (1024 x 1024 cells) of band-limited noise (wavelengths of 3 to 12 cells), std 1."""
    n = 1024
    rng = np.random.default_rng(seed + 505)
    f = np.fft.fftfreq(n)
    fr = np.hypot(f[None, :], f[:, None])
    band = np.exp(-0.5 * (fr * 3.0) ** 2) - np.exp(-0.5 * (fr * 12.0) ** 2)
    noise = np.real(np.fft.ifft2(np.fft.fft2(rng.normal(0.0, 1.0, (n, n))) * band))
    return (noise / max(noise.std(), 1e-9)).astype(np.float32)


def _grain(seed: int, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The grain tile sampled at ground position (x, y) (GRAIN_RES m per cell, wrapping every 20 m)."""
    return syn._wrap_bilinear(_grain_tile(seed), np.asarray(x) / GRAIN_RES, -np.asarray(y) / GRAIN_RES)


def render_farm_image(scene: FarmScene, camera: syn.CameraModel, shot: syn.Shot, supersample: int = 1,
                      noise: float = 1.5, seed: int = 0) -> np.ndarray:
    """Grey uint8 image of ``shot`` (as :func:`tests.synthetic.render_image`, with the procedural texture)."""
    s = int(supersample)
    canvas_xn, map_x, map_y, vignetting = syn._canvas_geometry(camera, s)
    canvas = np.empty(canvas_xn.shape[:2], np.float32)
    for r0 in range(0, canvas.shape[0], 512):  # in bands: the rays of a 10 MP canvas take GiB at once
        rays = shot.rays(canvas_xn[r0:r0 + 512])
        canvas[r0:r0 + 512] = scene.grey(syn._ray_cast(scene, shot.centre, rays))
    del canvas_xn
    canvas = cv2.GaussianBlur(canvas, (0, 0), 0.45 * s)
    img = cv2.remap(canvas, map_x, map_y, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
    img = img * vignetting * 255.0
    img += np.random.default_rng(seed).normal(0.0, noise, img.shape).astype(np.float32)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


class FarmBlock(syn.SyntheticBlock):
    def render(self, folder: str, supersample: int = 1, ext: str = ".jpg", quality: Optional[int] = None,
               radiometry=None, keep_existing: bool = False) -> List[str]:
        """The photos as JPEG in ``folder`` (``quality``: the block's ``jpeg_quality``, else 92); ``keep_existing``:
        those already there are not rendered again (an interrupted rendering of a large block resumed)."""
        quality = quality or getattr(self, "jpeg_quality", None) or 92
        os.makedirs(folder, exist_ok=True)
        paths = []
        for k, s in enumerate(self.shots):
            path = os.path.join(folder, s.name)
            if keep_existing and os.path.isfile(path) and cv2.imread(path, cv2.IMREAD_GRAYSCALE) is not None:
                paths.append(path)
                continue
            img = render_farm_image(self.scene, self.camera, s, supersample, seed=self.seed * 1000 + k)
            if not cv2.imwrite(path, cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality]):
                raise OSError(f"cannot write {path}")
            paths.append(path)
        return paths


def farm_scene(seed: int, bounds: Tuple[float, float, float, float], contrast: float = 1.0,
               height_res: float = 0.06, object_scale: float = 1.0) -> FarmScene:
    """Rolling ground (hills of -1.5 to 3 m over a quarter of the block), fields, a road across, 3 trees (6-10 m)
    and a 6 m building, their heights x ``object_scale``; everything placed relative to ``bounds``."""
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = bounds
    w, h = xmax - xmin, ymax - ymin
    size = max(w, h)
    hills = np.array([[rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-1.5, 3.0),
                       rng.uniform(0.2, 0.35) * size] for _ in range(4)])
    ramp = (float(rng.uniform(-0.01, 0.01)), float(rng.uniform(-0.01, 0.01)))
    n_fields = 5
    seeds = np.column_stack([rng.uniform(xmin, xmax, n_fields), rng.uniform(ymin, ymax, n_fields)])
    kind = np.array([0, 0, 1, 0, 2])[:n_fields]  # mostly ploughed
    angle = np.where(kind == 1, math.radians(CROP_ANGLE_DEG), math.radians(FURROW_ANGLE_DEG))
    angle = angle + np.radians(rng.uniform(-4, 4, n_fields))
    tone = rng.uniform(0.38, 0.58, n_fields)
    road = ((xmin + 0.3 * w, ymin), (xmin + 0.55 * w, ymax), min(2.5, 0.03 * size))
    scene = FarmScene(seed, bounds, 150.0, hills, ramp, ((0.0, 0.0), (1.0, 0.0), 0.0, 0.0), [],
                      texture_res=0.04, height_res=height_res, field_seeds=seeds, field_kind=kind, field_tone=tone,
                      field_angle=angle, road=road, contrast=contrast)
    cx, cy = xmin + 0.7 * w, ymin + 0.6 * h
    g = float(scene.ground_at(cx, cy))
    scene.buildings = [syn.Building(cx, cy, min(5.0, 0.04 * size), min(4.0, 0.03 * size), 0.3, g + 6.0 * object_scale)]
    trees: List[Tree] = []
    while len(trees) < 3:
        tx, ty = rng.uniform(xmin + 0.2 * w, xmax - 0.2 * w), rng.uniform(ymin + 0.2 * h, ymax - 0.2 * h)
        r = float(rng.uniform(2.0, 3.5)) * min(1.0, size / 150.0)
        if scene.road_distance(tx, ty) < road[2] + r + 1 or scene.buildings[0].contains(tx, ty, r + 3):
            continue
        if any(math.hypot(tx - t.cx, ty - t.cy) < r + t.radius + 2 for t in trees):
            continue
        trees.append(Tree(tx, ty, r, float(rng.uniform(6.0, 10.0)) * object_scale))
    scene.trees = trees
    return scene


def farm_block(camera: syn.CameraModel, gsd: float, n_strips: int = 2, per_strip: int = 5, seed: int = 33,
               forward_overlap: float = 0.8, side_overlap: float = 0.6, contrast: float = 1.0,
               height_res: Optional[float] = None) -> FarmBlock:
    """Vertical strips along local x (serpentine) at the altitude giving ``gsd`` m per pixel over the fields."""
    rng = np.random.default_rng(seed + 1)
    altitude = gsd * camera.fx
    along = camera.width * gsd
    across = camera.height * gsd
    base = (1.0 - forward_overlap) * along
    spacing = (1.0 - side_overlap) * across
    length = (per_strip - 1) * base
    widthy = (n_strips - 1) * spacing
    margin = 0.6 * max(along, across) + 5.0
    bounds = (-length / 2 - margin, -widthy / 2 - margin, length / 2 + margin, widthy / 2 + margin)
    # trees and the building as tall for the flying height as on a 150 m flight (a 10 m tree under a 17 m flight
    # hides a quarter of the ground around it)
    scene = farm_scene(seed, bounds, contrast, height_res or max(0.03, min(0.1, 1.5 * gsd)),
                       object_scale=min(1.0, 2.5 * altitude / 150.0))
    z_fly = scene.base_z + altitude
    shots = []
    for si in range(n_strips):
        y = -widthy / 2 + si * spacing
        heading = 1.0 if si % 2 == 0 else -1.0
        for k in range(per_strip):
            x = heading * (-length / 2 + k * base)
            c = np.array([x, y, z_fly]) + rng.normal(0.0, 0.3, 3)
            r = syn.small_rotation(rng, 0.8) @ syn.look_at(c, c - np.array([0.0, 0.0, 1.0]),
                                                           np.array([0.0, heading, 0.0]))
            shots.append(syn.Shot(f"F{si + 1}_{k + 1:02d}.jpg", r, c, "vertical", si + 1))
    return FarmBlock(scene, camera, shots, altitude, seed=seed)


def small_block(contrast: float = 1.0) -> FarmBlock:
    """The fast test's block: 640 x 480 px, 2 strips of 5, 3 cm GSD."""
    cam = syn.CameraModel(640, 480, 560.0, 560.0, 321.7, 238.4, k1=-0.06, k2=0.01, p1=0.0004, p2=-0.0003)
    return farm_block(cam, 0.03, n_strips=2, per_strip=5, contrast=contrast)


def full_block(n_strips: int = 4, per_strip: int = 10, contrast: float = 1.0) -> FarmBlock:
    """The benchmark's block: 3600 x 2700 px (9.7 MP) at 4.9 cm GSD, ``n_strips`` x ``per_strip`` photos."""
    cam = syn.CameraModel(3600, 2700, 3060.0, 3060.0, 1803.2, 1348.9, k1=-0.05, k2=0.01, p1=0.0003, p2=-0.0002)
    return farm_block(cam, 0.049, n_strips=n_strips, per_strip=per_strip, contrast=contrast)


def fixed_wing_block(contrast: float = 1.0, seed: int = 46, forward_overlap: float = 0.58, tilt_deg: float = 6.0,
                     jpeg_quality: int = 85) -> FarmBlock:
    """Issue 46: the farmland as a fixed-wing drone without a gimbal photographs it (seneca_south): the strip flown
    along the frames' short side at ``forward_overlap`` (58 %: the ground between two photos' common part and the
    next one's is seen by those two photos alone), frames tilted by N(0, ``tilt_deg``) about each axis, and after
    the strip a turn: two photos with the heading turned by about 100 and 160 degrees beside its end (pairs of
    wide baselines, B/Z 0.8-1.2, and small overlaps); saved as JPEG ``jpeg_quality``.  640 x 480 px at 3 cm GSD
    (a test block), 4 photos in the strip."""
    cam = syn.CameraModel(640, 480, 560.0, 560.0, 321.7, 238.4, k1=-0.06, k2=0.01, p1=0.0004, p2=-0.0003)
    gsd = 0.03
    rng = np.random.default_rng(seed + 1)
    altitude = gsd * cam.fx
    along = cam.height * gsd  # the strip runs along the frames' short side
    base = (1.0 - forward_overlap) * along
    n = 4
    length = (n - 1) * base
    margin = 0.6 * cam.width * gsd + 5.0
    bounds = (-margin, -length / 2 - margin, margin + 0.8 * cam.width * gsd, length / 2 + margin)
    scene = farm_scene(seed, bounds, contrast, max(0.03, min(0.1, 1.5 * gsd)),
                       object_scale=min(1.0, 2.5 * altitude / 150.0))
    z_fly = scene.base_z + altitude
    shots = []
    centres = [np.array([0.0, -length / 2 + k * base, z_fly]) for k in range(n)]
    ups = [np.array([0.0, 1.0, 0.0])] * n  # the flight direction up in the frame: the strip along its short side
    # after the turn: beside the strip's end, the heading turned (seneca_south's IMG_0455 and IMG_0456)
    end = centres[-1]
    for dx, dy, turn in ((0.55 * cam.width * gsd, -0.45 * base, 100.0), (0.7 * cam.width * gsd, 0.9 * base, 160.0)):
        centres.append(end + np.array([dx, dy, 0.0]))
        a = math.radians(turn)
        ups.append(np.array([-math.sin(a), math.cos(a), 0.0]))
    for k, (c, up) in enumerate(zip(centres, ups)):
        c = c + rng.normal(0.0, 0.3, 3)
        r = syn.small_rotation(rng, tilt_deg) @ syn.look_at(c, c - np.array([0.0, 0.0, 1.0]), up)
        shots.append(syn.Shot(f"W1_{k + 1:02d}.jpg", r, c, "vertical", 1))
    block = FarmBlock(scene, cam, shots, altitude, seed=seed)
    block.jpeg_quality = jpeg_quality
    return block
