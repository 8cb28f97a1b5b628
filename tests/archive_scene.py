"""An archive test scene (issue 32, item 5): scanned film and a digital metric frame over a hilly landscape.

No scanned archive sortie is at hand, so this makes one whose truth is known (pure numpy + OpenCV + GDAL):

- **terrain** (:class:`ArchiveTerrain`): a valley with a river between hills, ``relief`` (default 450 m) from the
  lowest to the highest ground; fields in zones of their own orientation and parcel size, hedges and tracks,
  forests, main roads, villages (box buildings with shadows), and at every *site* a crossing of two tracks (the
  well-textured ground features the control and check points sit on).  Everything is a function of the local
  coordinates (``texture(xs, ys, epoch)``), so any grid of any resolution samples one and the same landscape;
- **epoch 1** ("decades later"): in a third of the zones the fields were merged and re-oriented, a few new
  buildings and halls, another season (the sun from another side, a tone curve) and colour;
- **cameras** (:class:`FrameCamera`): a film metric camera (152.82 mm lens, a 230 x 230 mm picture area with cut
  corners, 4 or 8 fiducial marks, cross in a ring, bright on the dark film border), each frame *scanned*: 0.2 mm
  pixels (1300 x 1300: 260 mm), a small scan rotation, a film affinity (x and y scales differing by 0.2 %), an offset,
  film grain; and a digital metric frame (120 mm lens, 92.16 x 165.888 mm sensor, 640 x 1152 px of 0.144 mm);
- **flight**: strips along local x at about 5000 m (about 4600 m above the mean ground), 60 % forward overlap,
  30 % side overlap; 4 frames = one strip, 12 frames = two strips of 6 flown in opposite directions;
- **reference** (:func:`write_reference`): the epoch-1 orthophoto (2 m, RGB, JPEG-compressed GeoTIFF) and a 25 m
  DEM of the bare ground, in a transverse Mercator CRS that has no EPSG code (:data:`ARCHIVE_PROJ`).

Pixel convention: COLMAP's (the centre of the first pixel at (0.5, 0.5)).  Film / sensor coordinates: mm, x right,
y up, origin at the fiducial centre (film) or the sensor centre (digital); the principal point at ``ppa_mm``.
World coordinates: local + :data:`ORIGIN` in :data:`ARCHIVE_PROJ` (local x east, y north, z up; metres).

Entry point: :func:`archive_block` (renders into ``out_dir`` once; a ``done`` file marks a complete rendering).
"""
from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import cv2
import numpy as np

from tests.synthetic import Shot, _ray_cast, look_at, small_rotation

ARCHIVE_PROJ = ("+proj=tmerc +lat_0=0 +lon_0=13.6666666667 +k=0.99985 +x_0=415000 +y_0=-4850000 +ellps=bessel "
                "+towgs84=577.326,90.129,463.919,5.137,1.474,5.297,2.4232 +units=m +no_defs")
ORIGIN = np.array([406000.0, 406000.0, 0.0])  # world = local + ORIGIN (about 13.55 E, 47.45 N)
VERSION = "archive-v4"  # part of the cache marker: bump when the rendering changes


def archive_wkt() -> str:
    """The CRS as one-line WKT 1 (what the GeoTIFFs and the GCP files carry)."""
    from osgeo import osr

    s = osr.SpatialReference()
    s.ImportFromProj4(ARCHIVE_PROJ)
    return s.ExportToWkt()


# --------------------------------------------------------------------------------------------------
# hashing and noise: functions of the coordinates, the same on any grid
# --------------------------------------------------------------------------------------------------

def _hash01(*keys) -> np.ndarray:
    """Uniform [0, 1) per tuple of integer arrays (broadcast), deterministic (one multiply-xorshift round)."""
    h = np.int64(0x2545F491)
    with np.errstate(over="ignore"):
        for k, mult in zip(keys, (0x85EBCA6B, 0xC2B2AE35, 0x27D4EB2F, 0x165667B1, 0x9E3779B1)):
            h = h + np.asarray(k).astype(np.int64) * np.int64(mult)
        h = h & np.int64(0xFFFFFFFF)
        h = ((h ^ (h >> 15)) * np.int64(0x2C1B3C6D)) & np.int64(0xFFFFFFFF)
        h = ((h ^ (h >> 12)) * np.int64(0x297A2D39)) & np.int64(0xFFFFFFFF)
        h = h ^ (h >> 15)
    return (h & np.int64(0xFFFFFF)).astype(np.float32) * np.float32(1.0 / (1 << 24))


class _Lattice:
    """Band-limited noise of one wavelength: N(0, 1) values on a lattice at half the wavelength over the bounds
    (plus a margin), interpolated bicubically at any point."""

    def __init__(self, seed: int, bounds, wavelength: float):
        xmin, ymin, xmax, ymax = bounds
        self.step = wavelength / 2.0
        self.x0, self.y1 = xmin - 4 * self.step, ymax + 4 * self.step
        nx = int(math.ceil((xmax - xmin) / self.step)) + 9
        ny = int(math.ceil((ymax - ymin) / self.step)) + 9
        self.values = np.random.default_rng(seed).normal(0.0, 1.0, (ny, nx)).astype(np.float32)

    def __call__(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        mx = ((x - self.x0) / self.step).astype(np.float32)
        my = ((self.y1 - y) / self.step).astype(np.float32)
        return cv2.remap(self.values, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)


def _smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


# --------------------------------------------------------------------------------------------------
# the terrain
# --------------------------------------------------------------------------------------------------


@dataclass
class House:
    cx: float
    cy: float
    half_w: float
    half_l: float
    angle: float
    height: float
    roof: float  # grey level offset of the roof (texture units)
    epoch: int = 0  # built in this epoch (0: there in both)

    def corners(self, grow: float = 0.0) -> np.ndarray:
        c, s = math.cos(self.angle), math.sin(self.angle)
        u = np.array([-1, 1, 1, -1]) * (self.half_w + grow)
        v = np.array([-1, -1, 1, 1]) * (self.half_l + grow)
        return np.column_stack([self.cx + c * u - s * v, self.cy + s * u + c * v])


@dataclass
class Site:
    """A crossing of two tracks: where a control or check point sits."""

    name: str
    x: float
    y: float
    angles: Tuple[float, float]  # radians, the two tracks' directions
    arms: Tuple[float, float]  # m, half lengths
    width: float
    value: float  # texture value of the tracks (bright gravel or dark tarmac)


class ArchiveTerrain:
    """The landscape in the local frame over ``bounds``; ground heights from ``base_z`` to ``base_z + relief``."""

    def __init__(self, seed: int, bounds: Tuple[float, float, float, float], relief: float = 450.0,
                 base_z: float = 200.0, height_res: float = 5.0, texture_res: float = 3.0,
                 site_grid: Tuple[int, int] = (6, 3), site_area: Optional[Tuple[float, float, float, float]] = None):
        self.seed = int(seed)
        self.bounds = tuple(float(v) for v in bounds)
        self.relief, self.base_z = float(relief), float(base_z)
        self.height_res, self.texture_res = float(height_res), float(texture_res)
        rng = np.random.default_rng(seed)
        xmin, ymin, xmax, ymax = self.bounds
        w, h = xmax - xmin, ymax - ymin
        size = max(w, h)
        # hills: broad ones and smaller knolls
        big = [[rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(0.6, 1.0), rng.uniform(0.12, 0.22) * size]
               for _ in range(6)]
        small = [[rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(0.08, 0.2), rng.uniform(300, 900)]
                 for _ in range(18)]
        self.hills = np.array(big + small)
        # the valley: a meandering line along x at about a third of the height
        self.valley = (ymin + rng.uniform(0.3, 0.45) * h, rng.uniform(0.04, 0.08) * h, rng.uniform(0.25, 0.4) * w,
                       rng.uniform(0, 2 * math.pi), 0.9, rng.uniform(900.0, 1400.0))  # y0, amp, period, phase, depth, width
        self.tilt = (rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3))
        # normalise the raw field to [0, 1] over the bounds
        gx, gy = np.meshgrid(np.linspace(xmin, xmax, 240), np.linspace(ymin, ymax, 240))
        raw = self._raw(gx, gy)
        self._lo, self._hi = float(raw.min()), float(raw.max())
        # zones of fields
        nz = max(4, int(round(w * h / 12e6)))
        self.zones = np.column_stack([rng.uniform(xmin, xmax, nz), rng.uniform(ymin, ymax, nz)])
        self.zone_params = {e: self._zone_params(np.random.default_rng(seed + 17 + 1000 * e), nz) for e in (0, 1)}
        self.changed_zones = np.zeros(nz, bool)
        self.changed_zones[rng.permutation(nz)[:max(1, nz // 3)]] = True
        self._noise = {wl: _Lattice(seed + 31 + k, self.bounds, wl)
                       for k, wl in enumerate((10.0, 20.0, 45.0, 110.0, 300.0, 2000.0))}
        self.roads = self._roads(rng)
        self.sites = self._sites(rng, site_area or self.bounds, site_grid)
        self.houses = self._villages(rng)
        self._rasters: Dict[str, np.ndarray] = {}

    # ---- heights
    def _raw(self, x, y):
        x = np.asarray(x, float)
        y = np.asarray(y, float)
        z = np.zeros(np.broadcast(x, y).shape)
        for hx, hy, amp, sig in self.hills:
            z = z + amp * np.exp(-((x - hx) ** 2 + (y - hy) ** 2) / (2.0 * sig * sig))
        xmin, ymin, xmax, ymax = self.bounds
        z = z + self.tilt[0] * (x - xmin) / (xmax - xmin) + self.tilt[1] * (y - ymin) / (ymax - ymin)
        d = y - self._valley_line(x)
        return z - self.valley[4] * np.exp(-(d / self.valley[5]) ** 2)

    def _valley_line(self, x):
        y0, amp, period, phase = self.valley[:4]
        return y0 + amp * np.sin(2 * np.pi * np.asarray(x) / period + phase)

    def ground_at(self, x, y) -> np.ndarray:
        """Ground height (no buildings) at local x, y: the truth of every control and check point."""
        return self.base_z + self.relief * (self._raw(x, y) - self._lo) / (self._hi - self._lo)

    def height_raster(self) -> np.ndarray:
        """Surface heights (ground + buildings) at ``height_res``, row 0 at the north edge."""
        if "height" not in self._rasters:
            xs, ys = self.grid(self.height_res)
            out = np.empty((len(ys), len(xs)), np.float32)
            for r0 in range(0, len(ys), 256):
                yy, xx = np.meshgrid(ys[r0:r0 + 256], xs, indexing="ij")
                out[r0:r0 + 256] = self.ground_at(xx, yy)
            for hs in self.houses:
                if hs.epoch == 0:
                    z = float(self.ground_at(hs.cx, hs.cy)) + hs.height
                    cv2.fillConvexPoly(out, self._poly(hs.corners(), self.height_res, 0, xs[0]), z, cv2.LINE_8, 4)
            self._rasters["height"] = out
        return self._rasters["height"]

    def max_height(self) -> float:
        return float(self.height_raster().max())

    # ---- grids
    def grid(self, res: float, bounds=None) -> Tuple[np.ndarray, np.ndarray]:
        xmin, ymin, xmax, ymax = bounds or self.bounds
        nx, ny = int(math.ceil((xmax - xmin) / res)), int(math.ceil((ymax - ymin) / res))
        return xmin + (np.arange(nx) + 0.5) * res, ymax - (np.arange(ny) + 0.5) * res

    def _poly(self, xy: np.ndarray, res: float, row0: int, x_first: float, y_first: Optional[float] = None):
        """cv2 polygon (shift 4) of local points on a grid of ``res`` whose first cell centre is x_first, y_first
        (default: the grid of the bounds), rows counted from ``row0``."""
        y_first = self.bounds[3] - 0.5 * res if y_first is None else y_first
        col = (xy[:, 0] - x_first) / res
        row = (y_first - xy[:, 1]) / res - row0
        return np.round(np.column_stack([col, row]) * 16).astype(np.int32)

    # ---- layout: zones, roads, sites, villages
    @staticmethod
    def _zone_params(rng, n):
        out = {"angle": rng.uniform(0, np.pi, n), "width": rng.uniform(45.0, 160.0, n),
               "length": rng.uniform(160.0, 520.0, n), "hedge": rng.uniform(0.1, 0.6, n)}
        return {k: v.astype(np.float32) for k, v in out.items()}

    def _roads(self, rng) -> List[np.ndarray]:
        xmin, ymin, xmax, ymax = self.bounds
        w, h = xmax - xmin, ymax - ymin
        roads = []
        # the valley road, beside the river
        xs = np.linspace(xmin - 100, xmax + 100, 60)
        roads.append(np.column_stack([xs, self._valley_line(xs) + 0.6 * self.valley[5]]))
        for _ in range(max(3, int(round(w * h / 40e6)))):  # roads crossing the area, with a few bends
            if rng.uniform() < 0.5:
                a = np.array([xmin - 100, rng.uniform(ymin, ymax)])
                b = np.array([xmax + 100, rng.uniform(ymin, ymax)])
            else:
                a = np.array([rng.uniform(xmin, xmax), ymin - 100])
                b = np.array([rng.uniform(xmin, xmax), ymax + 100])
            t = np.linspace(0, 1, 8)[:, None]
            pts = a + t * (b - a)
            n = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
            pts[1:-1] += n * rng.normal(0, 250.0, (6, 1))
            roads.append(pts)
        return roads

    def _sites(self, rng, area, grid) -> List[Site]:
        x0, y0, x1, y1 = area
        nx, ny = grid
        out = []
        for j in range(ny):
            for i in range(nx):
                x = x0 + (i + 0.5) / nx * (x1 - x0) + rng.uniform(-0.2, 0.2) * (x1 - x0) / nx
                y = y0 + (j + 0.5) / ny * (y1 - y0) + rng.uniform(-0.2, 0.2) * (y1 - y0) / ny
                a = rng.uniform(0, np.pi)
                out.append(Site(f"S{len(out) + 1:02d}", float(x), float(y), (a, a + rng.uniform(1.0, 2.1)),
                                (float(rng.uniform(250, 600)), float(rng.uniform(250, 600))),
                                float(rng.uniform(5.0, 8.0)), float(rng.choice([1.3, -1.1]))))
        return out

    def _villages(self, rng) -> List[House]:
        xmin, ymin, xmax, ymax = self.bounds
        w, h = xmax - xmin, ymax - ymin
        houses: List[House] = []
        n_villages = max(3, int(round(w * h / 25e6)))
        for v in range(n_villages):
            cx, cy = rng.uniform(xmin + 0.05 * w, xmax - 0.05 * w), rng.uniform(ymin + 0.05 * h, ymax - 0.05 * h)
            if any(math.hypot(cx - s.x, cy - s.y) < 500 for s in self.sites):
                cx += 700.0
            ang = rng.uniform(0, np.pi)
            for k in range(int(rng.integers(15, 40))):
                r, t = rng.uniform(0, 350.0), rng.uniform(0, 2 * np.pi)
                hx, hy = cx + r * math.cos(t), cy + r * math.sin(t)
                if any(math.hypot(hx - s.x, hy - s.y) < 120 for s in self.sites):
                    continue
                houses.append(House(hx, hy, rng.uniform(5, 11), rng.uniform(6, 16), ang + rng.normal(0, 0.15),
                                    rng.uniform(6, 14), float(rng.choice([1.2, -1.0, 0.6])), 0))
            # decades later: new houses at the village's edge and an industrial hall
            for k in range(int(rng.integers(4, 9))):
                r, t = rng.uniform(380, 600.0), rng.uniform(0, 2 * np.pi)
                houses.append(House(cx + r * math.cos(t), cy + r * math.sin(t), rng.uniform(6, 10),
                                    rng.uniform(8, 14), ang, rng.uniform(6, 10), 1.4, 1))
            houses.append(House(cx + 700 * math.cos(ang), cy + 700 * math.sin(ang), 25, 45, ang, 12, 1.6, 1))
        return houses

    # ---- classes
    def zone_of(self, x, y) -> np.ndarray:
        """The zone (Voronoi cell of the zone seeds) at x, y, from a 5 m raster (nearest)."""
        if "zones" not in self._rasters:
            xs, ys = self.grid(5.0)
            out = np.empty((len(ys), len(xs)), np.int16)
            for r0 in range(0, len(ys), 512):
                yy, xx = np.meshgrid(ys[r0:r0 + 512], xs, indexing="ij")
                out[r0:r0 + 512] = self._zone_exact(xx, yy)
            self._rasters["zones"] = out
        z = self._rasters["zones"]
        mx, my = self.raster_coords(x, y, 5.0)
        col = np.clip(np.round(mx).astype(np.int64), 0, z.shape[1] - 1)
        row = np.clip(np.round(my).astype(np.int64), 0, z.shape[0] - 1)
        return z[row, col].astype(np.int64)

    def _zone_exact(self, x, y) -> np.ndarray:
        x = np.asarray(x, float)
        y = np.asarray(y, float)
        best = np.zeros(np.broadcast(x, y).shape, np.int64)
        bd = np.full(best.shape, np.inf)
        for k, (zx, zy) in enumerate(self.zones):
            d = (x - zx) ** 2 + (y - zy) ** 2
            closer = d < bd
            best[closer], bd[closer] = k, d[closer]
        return best

    def forest_at(self, x, y) -> np.ndarray:
        """Forest cover 0..1 (the same in both epochs): on the higher ground, in patches."""
        x = np.asarray(x, np.float32)
        y = np.asarray(y, np.float32)
        mx, my = self.raster_coords(x, y, self.height_res)
        z = cv2.remap(self.height_raster(), mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        return _smoothstep((self._noise[2000.0](x, y) + 1.2 * (z - self.base_z) / self.relief - 1.9) / 0.15)

    def changed_at(self, x, y) -> np.ndarray:
        """True where the fields changed between epoch 0 and epoch 1 (their zone was re-parcelled; not forest)."""
        return self.changed_zones[self.zone_of(x, y)] & (self.forest_at(x, y) < 0.05)

    # ---- texture
    def texture(self, xs: np.ndarray, ys: np.ndarray, epoch: int = 0, colour: bool = False) -> np.ndarray:
        """Grey (ny, nx) float32 in about 0..1 (or RGB (ny, nx, 3) with ``colour``) of the cell centres xs (west to
        east) x ys (north to south) in ``epoch`` (0: the archive's, 1: decades later)."""
        out = np.empty((len(ys), len(xs), 3) if colour else (len(ys), len(xs)), np.float32)
        for r0 in range(0, len(ys), 256):
            out[r0:r0 + 256] = self._texture_rows(xs, ys[r0:r0 + 256], epoch, colour)
        return out

    def _fields(self, x, y, epoch):
        """(value, tint 0..1, hedge strength) of the fields at x, y."""
        zone = self.zone_of(x, y)
        use_new = (epoch == 1) & self.changed_zones[zone]
        p0, p1 = self.zone_params[0], self.zone_params[1]
        pick = {k: np.where(use_new, p1[k][zone], p0[k][zone]) for k in p0}
        if epoch == 1:  # merged fields: wider and longer
            pick["width"] = np.where(use_new, pick["width"] * 2.2, pick["width"])
            pick["length"] = np.where(use_new, pick["length"] * 1.8, pick["length"])
        c, s = np.cos(pick["angle"]), np.sin(pick["angle"])
        u, v = c * x + s * y, -s * x + c * y
        i = np.floor(v / pick["width"])
        off = _hash01(zone, i, 7 + use_new) * pick["length"]
        j = np.floor((u + off) / pick["length"])
        key = zone * 2 + use_new
        val = (_hash01(key, i, j, self.seed) - 0.5) * 2.6
        tint = _hash01(key, i, j, self.seed + 1)
        fv = v / pick["width"] - i
        fu = (u + off) / pick["length"] - j
        edge = np.minimum(np.minimum(fv, 1 - fv) * pick["width"], np.minimum(fu, 1 - fu) * pick["length"])
        hedge = np.exp(-(edge / 3.0) ** 2) * (_hash01(key, i, 3) < pick["hedge"] + 0.3)
        rough = 0.25 + 0.9 * _hash01(key, i, j, 5)  # how much texture the field has
        return val, tint, hedge, rough

    def _texture_rows(self, xs, ys, epoch, colour):
        x, y = np.meshgrid(xs.astype(np.float32), ys.astype(np.float32))
        n = self._noise
        fx, fy = x, y
        if epoch == 1:  # where the fields changed, so did the soil and crop patterns within them
            moved = self.changed_zones[self.zone_of(x, y)].astype(np.float32)
            fx, fy = x + moved * 7777.0, y - moved * 3333.0
        fine = n[10.0](fx, fy) * 0.6 + n[20.0](fx, fy) * 0.7 + n[45.0](fx, fy) * 0.6
        val, tint, hedge, rough = self._fields(x, y, epoch)
        tex = val + rough * fine + 0.45 * n[110.0](fx, fy) + 0.35 * n[300.0](fx, fy)
        tex = tex * (1 - hedge) + (-1.4 + 0.5 * fine) * hedge
        forest = self.forest_at(x, y)
        crowns = 0.6 * n[10.0](x, y) + 0.5 * n[20.0](x, y) + 0.4 * n[45.0](x, y)
        tex = tex * (1 - forest) + (-1.1 + crowns) * forest
        river = np.exp(-((y - self._valley_line(x)) / 14.0) ** 4)
        tex = tex * (1 - river) - 2.0 * river
        tex = tex.astype(np.float32)
        tint = tint * (1 - forest) + 0.9 * forest
        # roads, tracks at the sites, houses: drawn on this block of rows
        res = xs[1] - xs[0]
        row0 = (ys[0] - ys[0]) / res
        paint = np.zeros(x.shape, np.float32)
        cover = np.zeros(x.shape, np.float32)

        def draw(poly_pts, value, width=None):
            pts = self._poly(poly_pts, res, row0, xs[0], ys[0])
            if width is None:
                cv2.fillConvexPoly(paint, pts, value, cv2.LINE_8, 4)
                cv2.fillConvexPoly(cover, pts, 1.0, cv2.LINE_8, 4)
            else:
                th = max(1, int(round(width / res)))
                cv2.polylines(paint, [pts], False, value, th, cv2.LINE_8, 4)
                cv2.polylines(cover, [pts], False, 1.0, th, cv2.LINE_8, 4)

        y_lo, y_hi = ys[-1] - 1000, ys[0] + 1000
        for road in self.roads:
            if road[:, 1].max() > y_lo and road[:, 1].min() < y_hi:
                draw(road, 1.5, 9.0)
        for st in self.sites:
            if y_lo < st.y < y_hi:
                for a, arm in zip(st.angles, st.arms):
                    d = np.array([math.cos(a), math.sin(a)]) * arm
                    draw(np.array([[st.x, st.y] - d, [st.x, st.y] + d]), st.value, st.width)
        sun = (0.6, 0.35) if epoch == 0 else (-0.45, 0.5)
        for hs in self.houses:
            if hs.epoch > epoch or not (y_lo < hs.cy < y_hi):
                continue
            shadow = hs.corners() - np.array(sun) * hs.height * 1.2
            draw(shadow, -1.8)
            draw(hs.corners(), hs.roof)
        cover = cv2.GaussianBlur(cover, (0, 0), 0.5)
        tex = tex * (1 - cover) + paint * cover
        # shading of the ground
        gx, gy = self._gradient(x, y)
        shade = (1.0 + sun[0] * gx + sun[1] * gy) / np.sqrt(1.0 + gx * gx + gy * gy)
        if epoch == 0:
            grey = (0.47 + 0.13 * tex) * shade
        else:  # another season: brighter, flatter fields, a tone curve
            grey = np.clip(0.52 + 0.11 * tex, 0.0, 1.0) ** 0.85 * shade
        grey = np.clip(grey, 0.02, 0.98).astype(np.float32)
        if not colour:
            return grey
        green = np.array([0.78, 1.05, 0.70], np.float32)
        brown = np.array([1.12, 0.98, 0.78], np.float32)
        t = tint[..., None].astype(np.float32)
        rgb = grey[..., None] * (green * t + brown * (1 - t))
        grey_cover = cover[..., None]
        rgb = rgb * (1 - grey_cover) + grey[..., None] * grey_cover * np.array([1.02, 1.0, 0.98], np.float32)
        return np.clip(rgb, 0.0, 1.0)

    def _gradient(self, x, y):
        """dz/dx, dz/dy of the ground (from the height raster, bilinear)."""
        if "grad" not in self._rasters:
            hr = self.height_raster().astype(np.float64)
            gy_, gx_ = np.gradient(hr, self.height_res)
            self._rasters["grad"] = (gx_.astype(np.float32), (-gy_).astype(np.float32))
        gx_, gy_ = self._rasters["grad"]
        mx, my = self.raster_coords(x, y, self.height_res)
        return (cv2.remap(gx_, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE),
                cv2.remap(gy_, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE))

    def raster_coords(self, x, y, res):
        xmin, _, _, ymax = self.bounds
        return ((np.asarray(x) - xmin) / res - 0.5).astype(np.float32), ((ymax - np.asarray(y)) / res - 0.5).astype(
            np.float32)

    def texture_raster(self, blur_m: float = 0.0) -> np.ndarray:
        """Epoch 0 grey texture over the bounds at ``texture_res``, low-pass filtered with a Gaussian of ``blur_m``
        metres (the renderer's anti-aliasing: one ray per pixel samples a texture filtered to the pixel's size);
        the last one is kept."""
        key = ("texture", round(float(blur_m), 2))
        if key not in self._rasters:
            for k in [k for k in self._rasters if isinstance(k, tuple)]:
                del self._rasters[k]
            tex = self.texture(*self.grid(self.texture_res), epoch=0)
            if blur_m > 0:
                tex = cv2.GaussianBlur(tex, (0, 0), blur_m / self.texture_res)
            self._rasters[key] = tex
        return self._rasters[key]

    def surface_value(self, xyz: np.ndarray, blur_m: float = 0.0) -> np.ndarray:
        tex = self.texture_raster(blur_m)
        mx, my = self.raster_coords(xyz[..., 0], xyz[..., 1], self.texture_res)
        return cv2.remap(tex, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)

    def occluded(self, centre: np.ndarray, xyz: np.ndarray, step: float = 10.0) -> np.ndarray:
        """True where the line of sight from surface points (N,3) to ``centre`` passes below the surface."""
        hr = self.height_raster()
        zmax = float(hr.max())
        seg = centre[None, :] - xyz
        frac = np.clip((zmax - xyz[:, 2]) / np.maximum(seg[:, 2], 1e-9), 0, 1)
        n = int(np.ceil((frac * np.linalg.norm(seg, axis=1)).max() / step)) + 1
        blocked = np.zeros(len(xyz), bool)
        for s in np.linspace(0, 1, n + 1)[1:]:
            p = xyz + (s * frac)[:, None] * seg
            mx, my = self.raster_coords(p[:, 0], p[:, 1], self.height_res)
            h = cv2.remap(hr, mx[None], my[None], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)[0]
            blocked |= (s * frac * np.linalg.norm(seg, axis=1) > 15.0) & (p[:, 2] < h - 0.5)
        return blocked


# --------------------------------------------------------------------------------------------------
# cameras: film (scanned) and digital
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FrameCamera:
    """A metric frame camera: focal length, principal point (mm in the film / sensor frame, x right, y up), the
    picture area (half sizes, mm; cut corners for film) and, for film, the fiducial marks (id -> mm)."""

    kind: str  # film / digital
    focal_mm: float
    ppa_mm: Tuple[float, float]
    half_mm: Tuple[float, float]  # half the picture area, x and y
    corner_cut_mm: float = 0.0  # |x| + |y| beyond half_x + half_y - this is masked (film corners)
    fiducials_mm: Tuple[Tuple[str, float, float], ...] = ()
    mark_mm: float = 4.0  # outer diameter of a fiducial mark
    pixel_mm: float = 0.2  # scan pixel (film) or sensor pixel (digital)
    size_px: Tuple[int, int] = (1300, 1300)  # width, height of the scan / the image

    def calibration(self) -> dict:
        """The camera's calibration as a plain dict (a calibration file writer's input)."""
        return {"kind": self.kind, "focal_mm": self.focal_mm, "pixel_size_mm": self.pixel_mm,
                "principal_point_mm": list(self.ppa_mm), "sensor_mm": [2 * self.half_mm[0], 2 * self.half_mm[1]],
                "image_size_px": list(self.size_px),
                "fiducials_mm": {k: [x, y] for k, x, y in self.fiducials_mm}}

    def inside(self, xy_mm: np.ndarray, margin_mm: float = 0.0) -> np.ndarray:
        x, y = np.abs(xy_mm[..., 0]), np.abs(xy_mm[..., 1])
        hx, hy = self.half_mm[0] - margin_mm, self.half_mm[1] - margin_mm
        ok = (x <= hx) & (y <= hy)
        if self.corner_cut_mm:
            ok &= x + y <= hx + hy - self.corner_cut_mm
        return ok

    def film_from_camera(self, xc: np.ndarray) -> np.ndarray:
        """Camera frame points (N,3; x right, y down, z forward) -> film mm (x right, y up)."""
        xn = xc[..., :2] / xc[..., 2:3]
        return np.stack([self.ppa_mm[0] + self.focal_mm * xn[..., 0], self.ppa_mm[1] - self.focal_mm * xn[..., 1]],
                        axis=-1)

    def rays_from_film(self, xy_mm: np.ndarray) -> np.ndarray:
        """Film mm -> camera frame directions (..., 3)."""
        xn = (xy_mm[..., 0] - self.ppa_mm[0]) / self.focal_mm
        yn = -(xy_mm[..., 1] - self.ppa_mm[1]) / self.focal_mm
        return np.stack([xn, yn, np.ones_like(xn)], axis=-1)


def film_camera(fiducials: int = 8, seed: int = 0, side_mm: float = 119.5) -> FrameCamera:
    """A 152.82 mm / 23 cm film metric camera with 4 (side) or 8 (side + corner) fiducials, calibrated coordinates
    a few hundredths of a mm off their nominal places.  ``side_mm``: the side marks' distance from the centre
    (119.5: their 4 mm rings 2.5 mm clear of the 115 mm picture edge; 117: the rings touch it)."""
    rng = np.random.default_rng(900 + seed)
    s = float(side_mm)
    nominal = [("1", -s, 0.0), ("2", s, 0.0), ("3", 0.0, s), ("4", 0.0, -s)]
    if fiducials == 8:
        nominal += [("5", -110.0, 110.0), ("6", 110.0, 110.0), ("7", 110.0, -110.0), ("8", -110.0, -110.0)]
    elif fiducials != 4:
        raise ValueError("fiducials: 4 or 8")
    fids = tuple((k, round(x + rng.normal(0, 0.01), 3), round(y + rng.normal(0, 0.01), 3)) for k, x, y in nominal)
    return FrameCamera("film", 152.82, (0.012, -0.008), (115.0, 115.0), 25.0, fids, 4.0, 0.2, (1300, 1300))


def digital_camera() -> FrameCamera:
    """A 120 mm digital metric frame, 92.16 x 165.888 mm sensor, 640 x 1152 px of 0.144 mm."""
    return FrameCamera("digital", 120.0, (0.05, -0.03), (46.08, 82.944), 0.0, (), 0.0, 0.144, (640, 1152))


@dataclass
class ScanGeometry:
    """Film mm -> scan pixel (corner convention): rotation (deg, clockwise on screen), the film's affinity
    (x, y scales), the offset of the fiducial centre from the scan centre (px).  Identity-like for digital."""

    pixel_mm: float
    size_px: Tuple[int, int]
    rotation_deg: float = 0.0
    scale: Tuple[float, float] = (1.0, 1.0)
    offset_px: Tuple[float, float] = (0.0, 0.0)

    @property
    def matrix(self) -> np.ndarray:
        """2 x 3: scan px = M @ (x_mm, y_mm, 1)."""
        t = math.radians(self.rotation_deg)
        r = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        a = r @ np.diag([self.scale[0], -self.scale[1]]) / self.pixel_mm
        c = np.array([self.size_px[0] / 2 + self.offset_px[0], self.size_px[1] / 2 + self.offset_px[1]])
        return np.column_stack([a, c])

    def to_scan(self, xy_mm: np.ndarray) -> np.ndarray:
        m = self.matrix
        return xy_mm @ m[:, :2].T + m[:, 2]

    def to_film(self, px: np.ndarray) -> np.ndarray:
        m = self.matrix
        return (np.asarray(px, float) - m[:, 2]) @ np.linalg.inv(m[:, :2]).T


# --------------------------------------------------------------------------------------------------
# rendering
# --------------------------------------------------------------------------------------------------

BORDER = 0.07  # grey of the unexposed film border (a positive)
MARK = 0.86  # grey of the fiducial marks


def mark_coverage(dx: np.ndarray, dy: np.ndarray, size: float) -> np.ndarray:
    """A cross in a ring (outer diameter ``size``), 1 on the mark."""
    r = np.hypot(dx, dy)
    t, arm = 0.05 * size, 0.33 * size
    cross = ((np.abs(dx) <= arm) & (np.abs(dy) <= t)) | ((np.abs(dy) <= arm) & (np.abs(dx) <= t))
    return (cross | (np.abs(r - 0.45 * size) <= 0.05 * size)).astype(np.float32)


def render_frame(terrain: ArchiveTerrain, cam: FrameCamera, shot: Shot, scan: ScanGeometry, seed: int = 0,
                 supersample: int = 1, grain: float = 0.014) -> np.ndarray:
    """The frame as scanned (film: grey with border, marks and grain) or as recorded (digital): uint8 (h, w).

    ``supersample`` rays per pixel and axis, cast into the height raster (first surface along the ray); each ray
    samples the texture low-pass filtered to about half the ground sample distance (so one ray per pixel does
    not alias)."""
    w, h = scan.size_px
    gsd = (shot.centre[2] - terrain.base_z - 0.45 * terrain.relief) / cam.focal_mm * scan.pixel_mm
    s = int(supersample)
    uu, vv = np.meshgrid((np.arange(w * s) + 0.5) / s, (np.arange(h * s) + 0.5) / s)
    film = scan.to_film(np.stack([uu, vv], axis=-1))
    del uu, vv
    rays = cam.rays_from_film(film) @ shot.rotation  # world directions (R^T d)
    xyz = _ray_cast(terrain, shot.centre, rays.astype(np.float64), step=terrain.height_res)
    del rays
    canvas = terrain.surface_value(xyz, round(0.45 * gsd / s * 2) / 2).astype(np.float32)  # one filter per block
    dist = np.linalg.norm(xyz - shot.centre, axis=-1).astype(np.float32)
    del xyz
    canvas = 0.82 * canvas + 0.18 * 0.62 * (dist / 5000.0)  # haze: more with distance
    r2 = ((film[..., 0] ** 2 + film[..., 1] ** 2) / (cam.half_mm[0] ** 2 + cam.half_mm[1] ** 2)).astype(np.float32)
    canvas *= 1.0 - 0.12 * r2  # light fall-off
    inside = cam.inside(film)
    canvas[~inside] = BORDER
    canvas = cv2.GaussianBlur(canvas, (0, 0), 0.4 * s)
    img = cv2.resize(canvas, (w, h), interpolation=cv2.INTER_AREA)
    rng = np.random.default_rng(seed)
    img *= np.float32(math.exp(rng.normal(0, 0.05)))  # exposure / development
    if cam.kind == "film":
        _draw_marks(img, cam, scan)
        g = rng.normal(0.0, grain, img.shape).astype(np.float32)
        img += cv2.GaussianBlur(g, (0, 0), 0.7) * 2.2
        cv2.putText(img, f"7-{seed % 10000:04d}", (int(0.02 * w), int(0.6 * h)), cv2.FONT_HERSHEY_SIMPLEX,
                    0.3, MARK * 0.8, 1, cv2.LINE_AA)  # a frame number in the border
    else:
        img += rng.normal(0.0, 0.004, img.shape).astype(np.float32)
    return np.clip(np.round(img * 255.0), 0, 255).astype(np.uint8)


def _draw_marks(img: np.ndarray, cam: FrameCamera, scan: ScanGeometry, supersample: int = 4) -> None:
    size_px = cam.mark_mm / scan.pixel_mm
    r = int(math.ceil(0.7 * size_px)) + 2
    off = (np.arange(supersample) + 0.5) / supersample
    for _, fx, fy in cam.fiducials_mm:
        u, v = scan.to_scan(np.array([fx, fy]))
        c0, r0 = int(u) - r, int(v) - r
        cov = np.zeros((2 * r + 1, 2 * r + 1), np.float32)
        for oy in off:
            for ox in off:
                jj, ii = np.meshgrid(c0 + np.arange(2 * r + 1) + ox, r0 + np.arange(2 * r + 1) + oy)
                f = scan.to_film(np.stack([jj, ii], axis=-1))
                cov += mark_coverage(f[..., 0] - fx, f[..., 1] - fy, cam.mark_mm)
        cov /= supersample * supersample
        sub = img[r0:r0 + 2 * r + 1, c0:c0 + 2 * r + 1]
        sub[:] = sub * (1 - cov) + MARK * cov


# --------------------------------------------------------------------------------------------------
# the block
# --------------------------------------------------------------------------------------------------


@dataclass
class Frame:
    name: str
    shot: Shot  # local frame
    scan: ScanGeometry
    strip: int

    @property
    def centre_world(self) -> np.ndarray:
        return self.shot.centre + ORIGIN


@dataclass
class GroundPointTruth:
    name: str
    xyz: np.ndarray  # world (ARCHIVE_PROJ), true
    role: str  # control / check
    observations: Dict[str, np.ndarray] = field(default_factory=dict)  # frame -> exact pixel
    noisy_observations: Dict[str, np.ndarray] = field(default_factory=dict)  # + N(0, obs_noise_px)
    xyz_3m: Optional[np.ndarray] = None  # control: the "3 m accuracy" coordinates


@dataclass
class ArchiveBlock:
    """A rendered (or only planned) archive block and its truth.

    ``frames``: name, true pose (``shot``: camera-from-world rotation and centre, local), the scan geometry (film mm
    -> scan px); ``points``: control (``role`` "control", with ``xyz_3m``) and check points, world coordinates in
    ARCHIVE_PROJ, exact and noisy pixel observations; ``camera.calibration()``: the calibration dict;
    ``interior(name)``: a frame's interior orientation as scanned; ``project(name, xyz)``: world -> (px, film mm);
    ``paths``: images, control_csv (3 m, no sigma), control_true_csv, check_csv, calibration, truth (json), ortho,
    dem; ``gsd``: m at the mean ground height."""

    kind: str
    terrain: ArchiveTerrain
    camera: FrameCamera
    frames: List[Frame]
    points: List[GroundPointTruth]
    out_dir: str
    seed: int
    paths: Dict[str, str] = field(default_factory=dict)  # images, control_csv, check_csv, truth, ortho, dem
    render_seconds: float = 0.0
    gsd: float = 0.0  # m, at the mean ground height, nadir

    @property
    def names(self) -> List[str]:
        return [f.name for f in self.frames]

    def frame(self, name: str) -> Frame:
        return next(f for f in self.frames if f.name == name)

    @property
    def control(self) -> List[GroundPointTruth]:
        return [p for p in self.points if p.role == "control"]

    @property
    def check(self) -> List[GroundPointTruth]:
        return [p for p in self.points if p.role == "check"]

    def project(self, name: str, xyz_world: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """(pixels (N,2) in the scan / image, film mm (N,2)) of world points."""
        f = self.frame(name)
        xc = f.shot.to_camera(np.atleast_2d(xyz_world) - ORIGIN)
        mm = self.camera.film_from_camera(xc)
        return f.scan.to_scan(mm), mm

    def fiducials_scan(self, name: str) -> Dict[str, np.ndarray]:
        sc = self.frame(name).scan
        return {k: sc.to_scan(np.array([x, y])) for k, x, y in self.camera.fiducials_mm}

    def interior(self, name: str) -> dict:
        """The interior orientation of one frame as scanned: focal in px (x, y), principal point (px), pixel size,
        the film -> scan affine, fiducials (mm and scan px)."""
        sc = self.frame(name).scan
        m = sc.matrix
        return {"focal_mm": self.camera.focal_mm, "pixel_size_mm": sc.pixel_mm,
                "focal_px": self.camera.focal_mm / sc.pixel_mm,
                "focal_px_xy": [float(self.camera.focal_mm * np.linalg.norm(m[:, 0])),
                                float(self.camera.focal_mm * np.linalg.norm(m[:, 1]))],
                "principal_point_px": [float(v) for v in sc.to_scan(np.array(self.camera.ppa_mm))],
                "film_to_scan": m.tolist(), "scan_rotation_deg": sc.rotation_deg, "film_scale": list(sc.scale),
                "scan_offset_px": list(sc.offset_px),
                "fiducials_mm": {k: [x, y] for k, x, y in self.camera.fiducials_mm},
                "fiducials_scan_px": {k: [float(v[0]), float(v[1])] for k, v in self.fiducials_scan(name).items()}}

    def truth_dict(self) -> dict:
        return {
            "version": VERSION, "kind": self.kind, "seed": self.seed, "crs_proj": ARCHIVE_PROJ,
            "origin": ORIGIN.tolist(), "gsd_m": self.gsd, "calibration": self.camera.calibration(),
            "relief_m": [float(self.terrain.height_raster().min()), float(self.terrain.height_raster().max())],
            "frames": [{"name": f.name, "strip": f.strip, "centre": f.centre_world.tolist(),
                        "cam_from_world": f.shot.rotation.tolist(), "interior": self.interior(f.name)}
                       for f in self.frames],
            "points": [{"name": p.name, "role": p.role, "xyz": p.xyz.tolist(),
                        "xyz_3m": None if p.xyz_3m is None else p.xyz_3m.tolist(),
                        "observations": {k: v.tolist() for k, v in p.observations.items()},
                        "noisy_observations": {k: v.tolist() for k, v in p.noisy_observations.items()}}
                       for p in self.points],
            "paths": self.paths, "render_seconds": self.render_seconds,
        }


def _flight(kind: str, n_frames: int, cam: FrameCamera, z_fly: float, mean_ground: float, forward: float,
            side: float, rng) -> Tuple[List[Tuple[np.ndarray, int, float]], Tuple[float, float]]:
    """Nominal exposure stations (local xy, strip, heading) and the footprint size (along, across) in m."""
    hgt = z_fly - mean_ground
    along = 2 * cam.half_mm[0] / cam.focal_mm * hgt
    across = 2 * cam.half_mm[1] / cam.focal_mm * hgt
    if n_frames == 4:
        strips, per = 1, 4
    elif n_frames == 12:
        strips, per = 2, 6
    else:
        raise ValueError("n_frames: 4 or 12")
    base, spacing = (1 - forward) * along, (1 - side) * across
    out = []
    for si in range(strips):
        y = (si - (strips - 1) / 2) * spacing
        heading = 1.0 if si % 2 == 0 else -1.0
        for k in range(per):
            x = heading * (k - (per - 1) / 2) * base
            out.append((np.array([x, y]) + rng.normal(0, 40.0, 2), si + 1, heading))
    return out, (along, across)


def build_block(kind: str = "film", n_frames: int = 4, seed: int = 1, out_dir: str = "", fiducials: int = 8,
                z_fly: float = 5000.0, relief: float = 450.0, obs_noise_px: float = 0.3,
                control_sigma: float = 3.0, side_mm: float = 119.5) -> ArchiveBlock:
    """The block and its truth, not rendered (fast: the terrain's height raster only)."""
    rng = np.random.default_rng(seed)
    cam = film_camera(fiducials, seed, side_mm) if kind == "film" else digital_camera()
    base_z = 200.0
    mean_ground = base_z + 0.45 * relief
    stations, (along, across) = _flight(kind, n_frames, cam, z_fly, mean_ground, 0.6, 0.3, rng)
    xy = np.array([s[0] for s in stations])
    reach = 0.5 * max(along, across) * (z_fly - base_z) / (z_fly - mean_ground) * 1.12 + 300.0
    # footprints are rectangles; the scene covers them all (plus attitude and relief displacement)
    half_x = 0.5 * along * (z_fly - base_z) / (z_fly - mean_ground) * 1.1 + 400.0
    half_y = 0.5 * across * (z_fly - base_z) / (z_fly - mean_ground) * 1.1 + 400.0
    del reach
    bounds = (float(xy[:, 0].min() - half_x), float(xy[:, 1].min() - half_y), float(xy[:, 0].max() + half_x),
              float(xy[:, 1].max() + half_y))
    # sites (control / check candidates) over the area every frame's footprint spans, a little inside
    area = (float(xy[:, 0].min() - 0.42 * along), float(xy[:, 1].min() - 0.42 * across),
            float(xy[:, 0].max() + 0.42 * along), float(xy[:, 1].max() + 0.42 * across))
    grid = (6, 3) if n_frames == 4 else (8, 4)
    terrain = ArchiveTerrain(seed, bounds, relief=relief, base_z=base_z, site_grid=grid, site_area=area)
    frames = []
    for k, (st, strip, heading) in enumerate(stations):
        c = np.array([st[0], st[1], z_fly + rng.normal(0, 15.0)])
        r = look_at(c, c - np.array([0.0, 0.0, 1.0]), np.array([0.0, heading, 0.0]))  # image x along track
        crab = cv2.Rodrigues(np.array([0.0, 0.0, math.radians(rng.normal(0, 2.0))]))[0]
        r = small_rotation(rng, 0.8) @ crab @ r
        if kind == "film":
            scan = ScanGeometry(cam.pixel_mm, cam.size_px, float(rng.normal(0.0, 0.35)),
                                (1.0 - 0.0012 + rng.normal(0, 0.0001), 1.0 + 0.0009 + rng.normal(0, 0.0001)),
                                (float(rng.uniform(-12, 12)), float(rng.uniform(-12, 12))))
        else:
            scan = ScanGeometry(cam.pixel_mm, cam.size_px)
        frames.append(Frame(f"{'F' if kind == 'film' else 'D'}{strip}_{k + 1:02d}.tif", Shot(
            f"f{k}", r, c, "vertical", strip), scan, strip))
    block = ArchiveBlock(kind, terrain, cam, frames, [], out_dir, seed,
                         gsd=(z_fly - mean_ground) / cam.focal_mm * cam.pixel_mm)
    block.points = _points(block, rng, obs_noise_px, control_sigma, 6 if n_frames == 4 else 10)
    return block


def _points(block: ArchiveBlock, rng, obs_noise_px: float, sigma: float, n_control: int) -> List[GroundPointTruth]:
    """Control and check points at the sites seen in >= 2 frames (inside the picture area, 3 mm from its edge,
    not hidden by the terrain): ``n_control`` well spread (farthest-point order from the area's corners), the
    others check points."""
    t = block.terrain
    seen = []
    for st in t.sites:
        xyz = np.array([st.x, st.y, float(t.ground_at(st.x, st.y))])
        obs = {}
        for f in block.frames:
            xc = f.shot.to_camera(xyz[None])
            if xc[0, 2] <= 0:
                continue
            mm = block.camera.film_from_camera(xc)
            if not block.camera.inside(mm, 3.0)[0] or t.occluded(f.shot.centre, xyz[None])[0]:
                continue
            obs[f.name] = f.scan.to_scan(mm)[0]
        if len(obs) >= 2:
            seen.append((st, xyz, obs))
    if len(seen) < n_control + 3:
        raise RuntimeError(f"only {len(seen)} sites are seen in two frames")
    pts = np.array([s[1][:2] for s in seen])
    lo, hi = pts.min(0), pts.max(0)
    chosen: List[int] = []
    for target in (lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]):
        k = int(np.argmin(np.linalg.norm(pts - np.asarray(target), axis=1)))
        if k not in chosen:
            chosen.append(k)
    while len(chosen) < n_control:
        d = np.min(np.linalg.norm(pts[:, None, :] - pts[chosen][None], axis=2), axis=1)
        d[chosen] = -1
        chosen.append(int(np.argmax(d)))
    out = []
    n_g = n_c = 0
    for k, (st, xyz, obs) in enumerate(seen):
        control = k in chosen
        if control:
            n_g += 1
            name = f"G{n_g:02d}"
        else:
            n_c += 1
            name = f"C{n_c:02d}"
        w = xyz + ORIGIN
        p = GroundPointTruth(name, w, "control" if control else "check", obs)
        p.noisy_observations = {k2: v + rng.normal(0, obs_noise_px, 2) for k2, v in obs.items()}
        out.append(p)
    noise = np.random.default_rng(block.seed + 3333)  # the 3 m coordinates: their own fixed seed
    for p in out:
        if p.role == "control":
            p.xyz_3m = p.xyz + noise.normal(0.0, sigma, 3)
    return out


# --------------------------------------------------------------------------------------------------
# writing: images, control, truth, reference
# --------------------------------------------------------------------------------------------------


def _write_points(path: str, points: Sequence[GroundPointTruth], which: str, crs_wkt: str) -> Tuple[str, str]:
    """CSV pair: ``# crs: <WKT>``, name,x,y,z (no sigma columns); observations name,image,px,py (noisy)."""
    obs_path = os.path.splitext(path)[0] + "_observations.csv"
    lines = [f"# crs: {crs_wkt}", "name,x,y,z"]
    olines = ["name,image,px,py"]
    for p in points:
        xyz = p.xyz_3m if which == "3m" else p.xyz
        lines.append(f"{p.name},{xyz[0]:.3f},{xyz[1]:.3f},{xyz[2]:.3f}")
        for img, px in sorted(p.noisy_observations.items()):
            olines.append(f"{p.name},{img},{px[0]:.3f},{px[1]:.3f}")
    for pth, ls in ((path, lines), (obs_path, olines)):
        with open(pth, "w", encoding="utf-8") as fh:
            fh.write("\n".join(ls) + "\n")
    return path, obs_path


def write_reference(terrain: ArchiveTerrain, out_dir: str, ortho_res: float = 2.0, dem_res: float = 25.0,
                    bounds=None, detail_res: float = 3.0, ortho: bool = True) -> Tuple[Optional[str], str]:
    """The epoch-1 orthophoto (RGB, JPEG in a tiled GeoTIFF) and the 25 m DEM of the ground, both in
    ARCHIVE_PROJ (no EPSG code) over ``bounds`` (default the terrain's).  The ortho's texture is computed at
    ``detail_res`` and resampled (bicubic) to ``ortho_res`` (time: the texture costs per cell)."""
    from osgeo import gdal

    gdal.UseExceptions()
    wkt = archive_wkt()
    b = bounds or terrain.bounds
    xmin, ymin, xmax, ymax = b
    drv = gdal.GetDriverByName("GTiff")
    ortho_path = os.path.join(out_dir, "modern_ortho_2m.tif") if ortho else None
    if ortho_path:
        _write_ortho(terrain, ortho_path, b, ortho_res, detail_res, wkt)
    dem = os.path.join(out_dir, "modern_dem_25m.tif")
    xs, ys = terrain.grid(dem_res, b)
    xx, yy = np.meshgrid(xs, ys)
    z = terrain.ground_at(xx, yy).astype(np.float32)
    ds = drv.Create(dem + ".tmp.tif", len(xs), len(ys), 1, gdal.GDT_Float32, ["COMPRESS=DEFLATE", "PREDICTOR=3"])
    ds.SetGeoTransform((xmin + ORIGIN[0], dem_res, 0.0, ymax + ORIGIN[1], 0.0, -dem_res))
    ds.SetProjection(wkt)
    ds.GetRasterBand(1).WriteArray(z)
    ds.GetRasterBand(1).SetNoDataValue(-9999.0)
    ds = None
    os.replace(dem + ".tmp.tif", dem)
    return ortho_path, dem


def _write_ortho(terrain: ArchiveTerrain, ortho: str, b, ortho_res: float, detail_res: float, wkt: str) -> None:
    from osgeo import gdal

    xmin, _, xmax, ymax = b
    xs, ys = terrain.grid(ortho_res, b)
    ds = gdal.GetDriverByName("GTiff").Create(ortho + ".tmp.tif", len(xs), len(ys), 3, gdal.GDT_Byte,
                                              ["TILED=YES", "COMPRESS=JPEG", "JPEG_QUALITY=90", "PHOTOMETRIC=YCBCR"])
    ds.SetGeoTransform((xmin + ORIGIN[0], ortho_res, 0.0, ymax + ORIGIN[1], 0.0, -ortho_res))
    ds.SetProjection(wkt)
    xd = np.arange(xmin - 2 * detail_res, xmax + 3 * detail_res, detail_res)
    for r0 in range(0, len(ys), 512):
        yc = ys[r0:r0 + 512]
        yd = np.arange(yc[0] + 3 * detail_res, yc[-1] - 3 * detail_res, -detail_res)
        fine = terrain.texture(xd, yd, epoch=1, colour=True)
        mx, my = np.meshgrid(((xs - xd[0]) / detail_res).astype(np.float32), ((yd[0] - yc) / detail_res).astype(
            np.float32))
        rgb = cv2.remap(fine, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
        rgb = np.clip(np.round(rgb * 255), 0, 255).astype(np.uint8)
        for bnd in range(3):
            ds.GetRasterBand(bnd + 1).WriteArray(rgb[..., bnd], 0, r0)
    ds = None
    os.replace(ortho + ".tmp.tif", ortho)


def archive_block(kind: str = "film", n_frames: int = 4, seed: int = 1, out_dir: Optional[str] = None,
                  fiducials: int = 8, reference=True, supersample: int = 1, side_mm: float = 119.5,
                  progress=None) -> ArchiveBlock:
    """An archive block with its truth; the frames (and the modern reference) rendered into ``out_dir`` once.

    ``out_dir``/images/*.tif: the scans (film: 1300 x 1300 grey) or the digital frames (640 x 1152 grey);
    control_3m.csv (+ _observations.csv): the control points with N(0, 3 m) noise on X, Y and Z (seeded), no
    sigma columns, a ``# crs:`` WKT line, noisy pixel observations (N(0, 0.3 px)); control_true.csv: the same
    points' true coordinates; check.csv (+ observations): the check points, true; truth.json: everything;
    modern_ortho_2m.tif, modern_dem_25m.tif: the reference of epoch 1 (``reference``: True both, "dem" the DEM only,
    False none)."""
    block = build_block(kind, n_frames, seed, out_dir or "", fiducials, side_mm=side_mm)
    if out_dir is None:
        return block
    os.makedirs(os.path.join(out_dir, "images"), exist_ok=True)
    wkt = archive_wkt()
    images = os.path.join(out_dir, "images")
    block.paths = {"images": images, "truth": os.path.join(out_dir, "truth.json")}
    done = os.path.join(out_dir, "done")
    ref = int(reference) if isinstance(reference, bool) else reference
    marker = f"{VERSION} {kind} {n_frames} {seed} {fiducials} {ref} {supersample}" + (
        f" side {side_mm:g}" if side_mm != 119.5 else "")
    if os.path.exists(done) and open(done).read().strip() == marker:
        with open(block.paths["truth"]) as fh:
            old = json.load(fh)
        block.paths, block.render_seconds = old["paths"], old["render_seconds"]
        return block
    t0 = time.time()
    for k, f in enumerate(block.frames):
        img = render_frame(block.terrain, block.camera, f.shot, f.scan, seed=seed * 100 + k, supersample=supersample)
        if not cv2.imwrite(os.path.join(images, f.name), img):
            raise OSError(f"cannot write {f.name}")
        if progress:
            progress(f"{f.name} rendered ({time.time() - t0:.1f} s)")
    block.render_seconds = round(time.time() - t0, 2)
    block.paths["control_csv"], block.paths["control_observations"] = _write_points(
        os.path.join(out_dir, "control_3m.csv"), block.control, "3m", wkt)
    block.paths["control_true_csv"], _ = _write_points(os.path.join(out_dir, "control_true.csv"), block.control,
                                                       "true", wkt)
    block.paths["check_csv"], block.paths["check_observations"] = _write_points(
        os.path.join(out_dir, "check.csv"), block.check, "true", wkt)
    calib = os.path.join(out_dir, "calibration.json")
    with open(calib, "w") as fh:
        json.dump(block.camera.calibration(), fh, indent=1)
    block.paths["calibration"] = calib
    if reference:
        block.terrain._rasters.pop("texture", None)  # the old epoch's texture is not needed any more
        t1 = time.time()
        ortho, block.paths["dem"] = write_reference(block.terrain, out_dir, ortho=reference != "dem")
        if ortho:
            block.paths["ortho"] = ortho
        if progress:
            progress(f"reference written ({time.time() - t1:.1f} s)")
    with open(block.paths["truth"], "w") as fh:
        json.dump(block.truth_dict(), fh, indent=1)
    with open(done, "w") as fh:
        fh.write(marker + "\n")
    return block
