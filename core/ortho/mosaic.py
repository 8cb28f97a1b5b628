"""True orthophotos per image, the orthomosaic, and single-image orthorectification on an existing DSM.

Pure Python + numpy + OpenCV + GDAL: no qgis, no Qt (DESIGN.md §1).

How a cell of an orthophoto gets its value
------------------------------------------
Every output cell (a north-up grid in the working CRS) takes its height from the DSM (bilinear), goes
through the full camera model (pose, intrinsics, lens distortion: :class:`core.resection.Intrinsics`) into
the image, and is sampled there (bilinear by default, cubic or nearest on request; 8/16-bit, float, any
number of bands, kept as they are).  A cell is *nodata* (alpha 0) when it falls outside the image, in a
masked area (``<workspace>/masks/<image>.png``, white = use), where the DSM has no height, or when it is
hidden from that camera by higher surface.

Occlusion: radial sweep from the nadir point
--------------------------------------------
Seen from a camera at height H over the nadir point N, a surface point at horizontal distance r and height z
has the "tangent" t = r / (H - z).  Along every radial line from N, a point is visible exactly when its t is
not below the largest t of the surface closer to N (Habib et al. 2007, angle-based true orthophotos).  Per
image the DSM is resampled on a polar grid around N (bins of half a DSM cell), the running maximum of t is
taken along each ray (``np.maximum.accumulate``), and a cell is hidden when its height lies more than a small
tolerance below the sight line over that maximum.  The polar table is built once per image from the DSM of
its footprint and cached on disk, so a tile needs only table look-ups: no z-buffer splatting artefacts, no
per-cell ray marching, and memory per image independent of the output area.

Orthomosaic
-----------
1. A *planning grid* (a few GSD per cell, its size fixed in ground units, independent of the output
   resolution) holds for every image its validity and a cost (squared distance from the principal point +
   squared tangent of the viewing angle: "closest to nadir"); each planning cell takes the cheapest valid
   image.
2. Seamlines avoid relief: objects standing above their surroundings (buildings, trees: a morphological
   top-hat of the DSM) are given whole to one image that sees all of them, so no seam cuts a roof or a crown
   (where a seam would show any DSM error as a step).
3. Exposure: one gain per image from the mean brightness of the overlaps (least squares, as OpenCV's gain
   compensator).
4. Tiles (512 cells, memory bounded by one tile and the caches): each image's label region is feathered
   (a linear ramp across the seam), or blended with a Laplacian pyramid (multi-band), or cut hard; cells whose
   image is occluded there at full resolution are filled from the best image that sees them.
5. Tiles stream into a tiled GeoTIFF that becomes a Cloud-Optimized GeoTIFF with overviews; optional per-image
   true orthophotos (COG) and a GeoPackage layer of which image each part of the mosaic comes from.

Outputs are written to a temporary name and renamed when complete (``core.workspace.atomic_output``).
"""
from __future__ import annotations

import contextlib
import fnmatch
import json
import math
import os
import shutil
import tempfile
import time
from collections import OrderedDict
from dataclasses import asdict, dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Cancelled, NullProgress, Progress, SubProgress, check_cancel
from ..geometry.camera import Intrinsics, Pose, opk_from_rotation, rotation_from_opk
from ..io import raster as dsmmod
from ..prepare.masks import find_mask
from ..project.workspace import (
    CANCELLED,
    DONE,
    FAILED,
    Workspace,
    atomic_output,
    file_fingerprint,
    fingerprint,
)

STAGE = "orthophoto"
BLENDINGS = ("feather", "multiband", "none")
INTERPOLATIONS = ("bilinear", "cubic", "nearest")
PLANNING_GSD = 4.0  # planning cell = 4 x GSD
MAX_PLANNING_CELLS = 4096 * 4096
MAX_POLAR_CELLS = 12_000_000


class OrthoError(RuntimeError):
    """Orthophoto production cannot run with this input; the message says why."""


@dataclass
class OrthoOptions:
    """Options of the orthophoto stage (one dataclass, as OpenSfM's config)."""

    resolution: float = 0.0  # output cell size in CRS units; 0 = the images' median ground sample distance
    blending: str = "feather"  # feather / multiband / none
    interpolation: str = "bilinear"  # bilinear / cubic / nearest
    tile: int = 512  # output cells per tile side
    feather_gsd: float = 16.0  # width of the feathering ramp across a seam, in GSD
    occlusion: bool = True  # leave cells hidden from a camera nodata (true orthophoto)
    height_tolerance: float = 0.0  # m below the sight line still counted visible; 0 = max(0.1, DSM cell)
    fill_dsm_gaps_m: float = 25.0  # DSM gaps inside the data's hull, up to this far from a height, interpolated
    exposure: bool = True  # per-image gain compensation in the mosaic
    avoid_relief: bool = True  # keep seamlines off buildings and trees
    seam_iterations: int = 2  # passes moving the seamlines towards where the images agree (0 = off)
    seam_alpha: float = 5.0  # weight of the view cost against the seam cost in those moves
    relief_height: float = 1.5  # m above the surroundings that makes an object seams go around
    compress: str = "DEFLATE"
    cache_mb: int = 256  # decoded images + visibility tables kept in memory
    workers: int = 1  # tile workers (core.parallel); 0 = one per core
    scheduler: Optional[str] = None  # Dask scheduler address

    def check(self) -> None:
        if self.blending not in BLENDINGS:
            raise OrthoError(f"unknown BLENDING {self.blending!r}; choose one of {', '.join(BLENDINGS)}")
        if self.interpolation not in INTERPOLATIONS:
            raise OrthoError(f"unknown interpolation {self.interpolation!r}; choose one of {', '.join(INTERPOLATIONS)}")
        if self.resolution is None or not math.isfinite(self.resolution) or self.resolution < 0:
            raise OrthoError(f"RESOLUTION must be 0 (the ground sample distance) or a positive number of metres, "
                             f"got {self.resolution}")
        if self.tile < 64:
            raise OrthoError(f"tile size must be at least 64 cells, got {self.tile}")


# ---------------------------------------------------------------------------
# cameras
# ---------------------------------------------------------------------------

@dataclass
class OrthoCamera:
    """One image with its orientation in the local frame (world = local + offset)."""

    name: str
    path: str
    camera: Intrinsics
    pose: Pose
    camera_id: int = 0
    mask_path: Optional[str] = None

    @property
    def centre(self) -> np.ndarray:
        return self.pose.centre

    def project(self, xyz_local: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pixels (N, 2), depth (N,), ok (N,): in front, trusted by the lens model and inside the image)."""
        xc = self.pose.to_camera(xyz_local)
        px, ok = self.camera.project(xc)
        ok &= self.camera.inside(px) & np.all(np.isfinite(px), axis=-1)
        return px, xc[..., 2], ok


def cameras_from_reconstruction(rec, images_dir: str, masks_dir: Optional[str] = None) -> List[OrthoCamera]:
    """OrthoCameras of the registered images of a pycolmap.Reconstruction (its frame = the local frame)."""
    out = []
    for im in sorted(rec.images.values(), key=lambda i: i.name):
        if not im.has_pose:
            continue
        cam = rec.cameras[im.camera_id]
        p = im.cam_from_world()
        pose = Pose(np.asarray(p.rotation.matrix(), dtype=float), np.asarray(p.translation, dtype=float))
        out.append(OrthoCamera(im.name, os.path.join(images_dir or "", im.name), Intrinsics.from_pycolmap(cam), pose,
                               int(im.camera_id), find_mask(masks_dir, im.name)))
    return out


def select_cameras(cameras: Sequence[OrthoCamera], images_filter: Optional[str],
                   camera_groups: Sequence[dict] = ()) -> List[OrthoCamera]:
    """The cameras an IMAGES_FILTER names.

    The filter is a list separated by commas, semicolons or new lines; each item is an image name, a wildcard
    (``DJI_00*.JPG``, case-insensitive), or ``group:<n>`` / ``group:<text>`` for a camera group by id or by a
    part of its make, model or key (``group:2``, ``group:FC300X``, ``group:NIR``).  An item starting with ``!``
    removes what it matches.  Empty: all."""
    if not images_filter or not images_filter.strip():
        return list(cameras)
    items = [s.strip() for s in images_filter.replace(";", ",").replace("\n", ",").split(",") if s.strip()]
    chosen: "OrderedDict[str, OrthoCamera]" = OrderedDict()
    positive = [i for i in items if not i.startswith("!")]
    negative = [i[1:].strip() for i in items if i.startswith("!")]
    unmatched = []

    def matches(item: str) -> List[OrthoCamera]:
        if item.lower().startswith("group:"):
            key = item.split(":", 1)[1].strip().lower()
            ids = set()
            for g in camera_groups:
                gid = str(g.get("camera_id", ""))
                text = " ".join(str(g.get(k, "")) for k in ("key", "make", "model")).lower()
                if key == gid or (key and key in text):
                    ids.add(int(g.get("camera_id")))
            names = {n for g in camera_groups if int(g.get("camera_id", -1)) in ids for n in g.get("images", [])}
            return [c for c in cameras if c.camera_id in ids or c.name in names]
        pat = item.lower()
        return [c for c in cameras if fnmatch.fnmatchcase(c.name.lower(), pat)
                or fnmatch.fnmatchcase(os.path.basename(c.name).lower(), pat)]

    for item in positive or ["*"]:
        found = matches(item)
        if not found:
            unmatched.append(item)
        for c in found:
            chosen[c.name] = c
    for item in negative:
        for c in matches(item):
            chosen.pop(c.name, None)
    if not chosen:
        examples = ", ".join(c.name for c in list(cameras)[:5])
        groups = ", ".join(f"{g.get('camera_id')}: {g.get('model') or g.get('key')}" for g in camera_groups)
        raise OrthoError(f"IMAGES_FILTER {images_filter!r} matches none of the {len(cameras)} oriented images "
                         f"(for example {examples}{'; camera groups ' + groups if groups else ''})")
    return list(chosen.values())


# ---------------------------------------------------------------------------
# DSM access (through core.dsm.DsmReader, reprojected into the working CRS on the fly)
# ---------------------------------------------------------------------------

class _Dsm:
    """Heights from a DSM in the working CRS, in world coordinates (NaN = no height)."""

    def __init__(self, path: str, crs: Optional[str]):
        try:
            self.info = dsmmod.open_dsm(path)
        except dsmmod.DsmError as e:
            raise OrthoError(str(e)) from e
        if crs and not self.info.crs_wkt:
            raise OrthoError(f"DSM {path} has no CRS: it cannot be placed in {crs}; assign its CRS first")
        self.path = path
        self.crs = crs
        self.reader = dsmmod.DsmReader(path, target_crs=crs)
        gt = self.reader.geotransform
        self.geotransform = gt
        self.res = float(min(abs(gt[1]), abs(gt[5])))
        xs = (gt[0], gt[0] + self.reader.width * gt[1])
        ys = (gt[3], gt[3] + self.reader.height * gt[5])
        self.bounds = (min(xs), min(ys), max(xs), max(ys))
        self.reprojected = bool(crs and self.info.crs_wkt and not _same_crs(self.info.crs_wkt, crs))

    def close(self):
        self.reader.close()

    def sample(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return self.reader.sample(x, y)

    def window(self, box: Tuple[float, float, float, float]) -> Tuple[np.ndarray, Tuple[float, ...]]:
        """Heights of the cells covering ``box`` (full resolution), with their geotransform; (0, 0) if outside."""
        return self.reader.read_window(*box)

    def window_sampler(self, box: Tuple[float, float, float, float], margin_cells: int = 2):
        """A bilinear sampler over one window read once: f(x, y) -> z (NaN outside)."""
        g = self.geotransform
        m = margin_cells * self.res
        arr, wgt = self.window((box[0] - m, box[1] - m, box[2] + m, box[3] + m))

        arr32 = arr.astype(np.float32) if arr.size else arr

        def f(x, y):
            x = np.asarray(x, dtype=np.float64)
            if arr.size == 0:
                return np.full(x.shape, np.nan)
            fc = (x - wgt[0]) / g[1] - 0.5
            fr = (np.asarray(y, dtype=np.float64) - wgt[3]) / g[5] - 0.5
            if arr.shape[0] < 2 or arr.shape[1] < 2 or max(arr.shape) >= 32767:
                return dsmmod.bilinear(arr, fc, fr)
            # cv2.remap: bilinear, NaN where a neighbour is NaN (like dsm.bilinear), far faster
            out = _remap(arr32[:, :, None], fc.ravel(), fr.ravel(), "bilinear", border_nan=True)[:, 0]
            return out.reshape(x.shape).astype(np.float64)
        return f

    def coarse(self, box: Tuple[float, float, float, float], max_cells: int = 1_000_000
               ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Heights on a coarse grid over ``box`` (at most ``max_cells`` samples): (z, x, y) 2-D arrays."""
        x0, y0, x1, y1 = box
        x0, y0 = max(x0, self.bounds[0]), max(y0, self.bounds[1])
        x1, y1 = min(x1, self.bounds[2]), min(y1, self.bounds[3])
        if x1 <= x0 or y1 <= y0:
            return np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0))
        step = max(self.res, math.sqrt((x1 - x0) * (y1 - y0) / max_cells))
        xs = np.arange(x0 + step / 2, x1, step)
        ys = np.arange(y1 - step / 2, y0, -step)
        out = np.full((len(ys), len(xs)), np.nan)
        rows = max(1, int(4_000_000 * self.res * self.res / max(1e-12, (x1 - x0) * step)))  # bound window reads
        for r0 in range(0, len(ys), rows):
            yy = ys[r0:r0 + rows]
            gx, gy = np.meshgrid(xs, yy)
            out[r0:r0 + len(yy)] = self.sample(gx, gy)
        gx, gy = np.meshgrid(xs, ys)
        return out, gx, gy


def _same_crs(wkt: str, crs: str) -> bool:
    from osgeo import osr

    a = osr.SpatialReference(wkt=wkt)
    b = osr.SpatialReference()
    try:
        b.SetFromUserInput(crs)
    except RuntimeError:
        return False
    return bool(a.IsSame(b))


# ---------------------------------------------------------------------------
# footprints and visibility
# ---------------------------------------------------------------------------

@dataclass
class Footprint:
    polygon: np.ndarray  # (K, 2) world XY, convex, counter-clockwise
    bbox: Tuple[float, float, float, float]
    gsd: float  # ground sample distance at the nadir-most view, metres per pixel
    z_ref: float


def camera_footprint(cam: OrthoCamera, offset: np.ndarray, z_lo: float, z_hi: float,
                     max_range_factor: float = 15.0) -> Optional[Footprint]:
    """Ground area the image can see between heights z_lo and z_hi (world): the image border's rays
    intersected with both planes (rays near the horizon clipped at ``max_range_factor`` x the height)."""
    w, h = cam.camera.width, cam.camera.height
    t = np.linspace(0.0, 1.0, 17)
    border = np.concatenate([np.column_stack([t * w, np.zeros_like(t)]), np.column_stack([np.full_like(t, w), t * h]),
                             np.column_stack([(1 - t) * w, np.full_like(t, h)]), np.column_stack([np.zeros_like(t), (1 - t) * h])])
    xn = cam.camera.unproject(border)
    d = np.column_stack([xn, np.ones(len(xn))]) @ cam.pose.rotation  # world directions (R^T d)
    c = cam.centre + offset
    pts = []
    for z in (z_lo, z_hi):
        height = c[2] - z
        if height <= 0:
            continue
        max_h = max_range_factor * height
        for di in d:
            horiz = math.hypot(di[0], di[1])
            if di[2] < -1e-9:
                s = (z - c[2]) / di[2]
                if s * horiz > max_h:
                    s = max_h / max(horiz, 1e-12)
            elif horiz > 1e-12:
                s = max_h / horiz
            else:
                continue
            pts.append((c[0] + s * di[0], c[1] + s * di[1]))
    if len(pts) < 3:
        return None
    poly = dsmmod.convex_hull_xy(np.array(pts))
    if len(poly) < 3:
        return None
    xmin, ymin = poly.min(axis=0)
    xmax, ymax = poly.max(axis=0)
    z_ref = 0.5 * (z_lo + z_hi)
    gsd = max(c[2] - z_ref, 1e-6) / cam.camera.focal
    return Footprint(poly, (float(xmin), float(ymin), float(xmax), float(ymax)), float(gsd), float(z_ref))


def _point_in_polygon(poly: np.ndarray, x: float, y: float) -> bool:
    from matplotlib.path import Path

    return bool(Path(poly).contains_point((x, y)))


@dataclass
class Visibility:
    """Polar occlusion table of one camera (see the module docstring).  ``table`` holds, per angle row and
    radius bin k, the largest t = r / (H - z) of the surface in bins < k."""

    nadir: Tuple[float, float]
    height: float  # camera Z (world)
    dr: float
    phi0: float
    dphi: float
    n_phi: int
    n_r: int
    full_circle: bool
    tolerance: float
    path: str = ""
    table: Optional[np.ndarray] = field(default=None, repr=False)

    def nbytes(self) -> int:
        return self.n_phi * self.n_r * 4

    def load(self) -> np.ndarray:
        if self.table is None:
            self.table = np.load(self.path)
        return self.table

    def visible(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, table: Optional[np.ndarray] = None) -> np.ndarray:
        tab = self.load() if table is None else table
        dx = x - self.nadir[0]
        dy = y - self.nadir[1]
        r = np.hypot(dx, dy)
        a = np.arctan2(dy, dx) - self.phi0
        a = np.mod(a, 2 * np.pi)
        j = np.rint(a / self.dphi).astype(np.int64)
        if self.full_circle:
            j %= self.n_phi
            inside = np.ones(j.shape, dtype=bool)
        else:
            inside = (j >= 0) & (j < self.n_phi)
            j = np.clip(j, 0, self.n_phi - 1)
        k = np.clip(np.floor(r / self.dr).astype(np.int64) - 1, 0, self.n_r - 1)
        m = tab[j, k]
        vis = (self.height - z - self.tolerance) * m <= r
        return vis | ~inside


def build_visibility(cam: OrthoCamera, offset: np.ndarray, fp: Footprint, dsm: _Dsm, tolerance: float,
                     path: str = "") -> Visibility:
    """The polar occlusion table of ``cam`` over its footprint (saved to ``path`` when given)."""
    c = cam.centre + offset
    nx, ny, hz = float(c[0]), float(c[1]), float(c[2])
    poly = fp.polygon
    rel = poly - [nx, ny]
    r_max = float(np.max(np.hypot(rel[:, 0], rel[:, 1])))
    dr = max(0.5 * dsm.res, 0.5 * fp.gsd, 1e-3)  # finer than the DSM or the image resolves is wasted
    full = _point_in_polygon(poly, nx, ny) or r_max < 4 * dr
    if full:
        phi0, span = -math.pi, 2 * math.pi
    else:
        ang = np.arctan2(rel[:, 1], rel[:, 0])
        centre_dir = math.atan2(float(np.mean(rel[:, 1])), float(np.mean(rel[:, 0])))
        da = np.mod(ang - centre_dir + np.pi, 2 * np.pi) - np.pi
        lo, hi = float(da.min()), float(da.max())
        pad = 0.02
        phi0, span = centre_dir + lo - pad, (hi - lo) + 2 * pad
        if span >= 2 * math.pi - 1e-6:
            full, phi0, span = True, -math.pi, 2 * math.pi
    r_max += 2 * dr
    n_r = int(math.ceil(r_max / dr)) + 1
    n_phi = max(8, int(math.ceil(span * r_max / dr)))
    while n_r * n_phi > MAX_POLAR_CELLS:
        dr *= 1.25
        n_r = int(math.ceil(r_max / dr)) + 1
        n_phi = max(8, int(math.ceil(span * r_max / dr)))
    dphi = span / n_phi
    sampler = dsm.window_sampler((nx - r_max, ny - r_max, nx + r_max, ny + r_max) if full else
                                 (min(nx, poly[:, 0].min()), min(ny, poly[:, 1].min()),
                                  max(nx, poly[:, 0].max()), max(ny, poly[:, 1].max())))
    table = np.empty((n_phi, n_r), dtype=np.float32)
    radii = (np.arange(n_r) + 0.5) * dr
    rows = max(1, 2_000_000 // n_r)
    for j0 in range(0, n_phi, rows):
        phis = phi0 + np.arange(j0, min(n_phi, j0 + rows)) * dphi
        xx = nx + np.cos(phis)[:, None] * radii[None, :]
        yy = ny + np.sin(phis)[:, None] * radii[None, :]
        z = sampler(xx, yy)
        depth = hz - z
        t = np.where(np.isfinite(z), np.where(depth > 1e-6, radii[None, :] / np.maximum(depth, 1e-6), np.inf), 0.0)
        cm = np.maximum.accumulate(t, axis=1)
        table[j0:j0 + len(phis), 0] = 0.0
        table[j0:j0 + len(phis), 1:] = cm[:, :-1]
    vis = Visibility((nx, ny), hz, dr, phi0, dphi, n_phi, n_r, full, tolerance, path)
    if path:
        np.save(path, table)
    else:
        vis.table = table
    return vis


# ---------------------------------------------------------------------------
# image access and sampling
# ---------------------------------------------------------------------------

class _LRU:
    """A byte-bounded least-recently-used cache."""

    def __init__(self, max_bytes: int):
        self.max_bytes = max_bytes
        self.items: "OrderedDict[Any, Tuple[Any, int]]" = OrderedDict()
        self.size = 0

    def get(self, key, make):
        if key in self.items:
            self.items.move_to_end(key)
            return self.items[key][0]
        value, nbytes = make()
        self.items[key] = (value, nbytes)
        self.size += nbytes
        while self.size > self.max_bytes and len(self.items) > 1:
            _, (_, nb) = self.items.popitem(last=False)
            self.size -= nb
        return value

    def clear(self):
        self.items.clear()
        self.size = 0


_CACHE = _LRU(256 << 20)
_WHOLE_IMAGE_MAX = 96 << 20  # images up to this size are decoded whole and cached; larger ones read by window


def _gdal():
    from osgeo import gdal

    gdal.UseExceptions()
    return gdal


@dataclass
class ImageMeta:
    width: int
    height: int
    bands: int
    dtype: str  # numpy dtype name


def image_meta(path: str) -> ImageMeta:
    gdal = _gdal()
    from osgeo import gdal_array

    try:
        ds = gdal.Open(path)
    except RuntimeError as e:
        raise OrthoError(f"image {path} cannot be read: {e}") from e
    if ds is None or ds.RasterCount == 0:
        raise OrthoError(f"image {path} cannot be read")
    dt = np.dtype(gdal_array.GDALTypeCodeToNumericTypeCode(ds.GetRasterBand(1).DataType)).name
    return ImageMeta(ds.RasterXSize, ds.RasterYSize, ds.RasterCount, dt)


def _read_window(path: str, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    gdal = _gdal()
    ds = gdal.Open(path)
    arr = ds.ReadAsArray(x0, y0, x1 - x0, y1 - y0)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    else:
        arr = np.moveaxis(arr, 0, -1)
    return np.ascontiguousarray(arr)


def _image_window(path: str, meta: ImageMeta, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    nbytes = meta.width * meta.height * meta.bands * np.dtype(meta.dtype).itemsize
    if nbytes <= _WHOLE_IMAGE_MAX:
        whole = _CACHE.get(("img", path), lambda: (_read_window(path, 0, 0, meta.width, meta.height), nbytes))
        return whole[y0:y1, x0:x1]
    return _read_window(path, x0, y0, x1, y1)


def _mask(path: Optional[str]) -> Optional[np.ndarray]:
    if not path:
        return None

    def make():
        import cv2

        m = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        if m is None:
            raise OrthoError(f"mask {path} cannot be read")
        return m, m.nbytes
    return _CACHE.get(("mask", path), make)


def _table(vis: Visibility) -> np.ndarray:
    if vis.table is not None:
        return vis.table
    return _CACHE.get(("vis", vis.path), lambda: (np.load(vis.path), vis.nbytes()))


_CV_TYPES = ("uint8", "uint16", "int16", "float32")


def _remap(src: np.ndarray, mx: np.ndarray, my: np.ndarray, interpolation: str, border_nan: bool = False
           ) -> np.ndarray:
    """cv2.remap of 1-D coordinate arrays (rows of 1024, as remap wants short sides) -> (N, bands) float32."""
    import cv2

    flag = {"bilinear": cv2.INTER_LINEAR, "cubic": cv2.INTER_CUBIC, "nearest": cv2.INTER_NEAREST}[interpolation]
    n = mx.size
    cols = 1024
    rows = max(1, -(-n // cols))
    pad = rows * cols - n
    fx = np.pad(mx.astype(np.float32), (0, pad), constant_values=-10).reshape(rows, cols)
    fy = np.pad(my.astype(np.float32), (0, pad), constant_values=-10).reshape(rows, cols)
    if src.dtype.name not in _CV_TYPES:
        src = src.astype(np.float32)
    bands = src.shape[2]
    out = np.empty((n, bands), dtype=np.float32)
    border = cv2.BORDER_REPLICATE
    kw = {}
    if border_nan:
        border, kw = cv2.BORDER_CONSTANT, {"borderValue": float("nan")}
    for b0 in range(0, bands, 4):
        part = np.ascontiguousarray(src[:, :, b0:b0 + 4])
        if part.shape[2] == 1:
            part = part[:, :, 0]
        elif part.shape[2] == 2:  # remap takes 1, 3 or 4 channels
            for k in range(2):
                r = cv2.remap(np.ascontiguousarray(part[:, :, k]), fx, fy, flag, borderMode=border, **kw)
                out[:, b0 + k] = r.reshape(-1)[:n]
            continue
        r = cv2.remap(part, fx, fy, flag, borderMode=border, **kw)
        r = r.reshape(rows * cols, -1)[:n]
        out[:, b0:b0 + r.shape[1]] = r
    return out


@dataclass
class Sampled:
    values: np.ndarray  # (N, bands) float32 (only rows where valid are meaningful)
    valid: np.ndarray  # (N,) bool
    cost: np.ndarray  # (N,) float32, inf where not valid


def sample_camera(cam: OrthoCamera, meta: ImageMeta, offset: np.ndarray, x: np.ndarray, y: np.ndarray,
                  z: np.ndarray, vis: Optional[Visibility], interpolation: str = "bilinear",
                  want_values: bool = True) -> Sampled:
    """Values of ground points (world, 1-D arrays) in one image, with validity and the view cost."""
    n = x.size
    finite = np.isfinite(z)
    xyz = np.column_stack([x - offset[0], y - offset[1], np.where(finite, z, 0.0) - offset[2]])
    px, _depth, ok = cam.project(xyz)
    ok &= finite
    if vis is not None and ok.any():
        idx = np.flatnonzero(ok)
        ok[idx] = vis.visible(x[idx], y[idx], z[idx], _table(vis))
    mask = _mask(cam.mask_path)
    if mask is not None and ok.any():
        idx = np.flatnonzero(ok)
        mc = np.clip(px[idx, 0].astype(np.int64), 0, mask.shape[1] - 1)
        mr = np.clip(px[idx, 1].astype(np.int64), 0, mask.shape[0] - 1)
        ok[idx] = mask[mr, mc] >= 128
    cost = np.full(n, np.inf, dtype=np.float32)
    values = np.zeros((n, meta.bands), dtype=np.float32)
    if not ok.any():
        return Sampled(values, ok, cost)
    idx = np.flatnonzero(ok)
    c = cam.centre
    dxy = np.hypot(xyz[idx, 0] - c[0], xyz[idx, 1] - c[1])
    dz = np.maximum(c[2] - xyz[idx, 2], 1e-6)
    half_diag = 0.5 * math.hypot(cam.camera.width, cam.camera.height)
    rho = np.hypot(px[idx, 0] - cam.camera.cx, px[idx, 1] - cam.camera.cy) / half_diag
    cost[idx] = (rho * rho + (dxy / dz) ** 2).astype(np.float32)
    if want_values:
        u = px[idx, 0] - 0.5
        v = px[idx, 1] - 0.5
        pad = 3
        x0 = max(0, int(math.floor(u.min())) - pad)
        y0 = max(0, int(math.floor(v.min())) - pad)
        x1 = min(meta.width, int(math.ceil(u.max())) + pad + 1)
        y1 = min(meta.height, int(math.ceil(v.max())) + pad + 1)
        win = _image_window(cam.path, meta, x0, y0, x1, y1)
        values[idx] = _remap(win, u - x0, v - y0, interpolation)
    return Sampled(values, ok, cost)


# ---------------------------------------------------------------------------
# output rasters
# ---------------------------------------------------------------------------

def _alpha_value(dtype: str) -> Optional[float]:
    dt = np.dtype(dtype)
    if dt.kind in "ui":
        return float(np.iinfo(dt).max)
    return None  # float images: nodata NaN instead of an alpha band


class _RasterWriter:
    """A tiled GeoTIFF that tiles are written into, then translated to a COG (atomically)."""

    def __init__(self, path: str, width: int, height: int, bands: int, dtype: str, geotransform, crs: Optional[str]):
        gdal = _gdal()
        from osgeo import gdal_array

        self.path = path
        self.dtype = np.dtype(dtype)
        self.bands = bands
        self.alpha = _alpha_value(dtype)
        n = bands + (1 if self.alpha is not None else 0)
        gtype = gdal_array.NumericTypeCodeToGDALTypeCode(self.dtype)
        drv = gdal.GetDriverByName("GTiff")
        self.ds = drv.Create(path, width, height, n, gtype, options=[
            "TILED=YES", "BLOCKXSIZE=256", "BLOCKYSIZE=256", "COMPRESS=ZSTD" if _has_zstd() else "COMPRESS=LZW",
            "BIGTIFF=IF_SAFER", "SPARSE_OK=TRUE"] + (["PHOTOMETRIC=RGB"] if bands == 3 and self.dtype == np.uint8
                                                      else []) + (["ALPHA=YES"] if self.alpha is not None else []))
        self.ds.SetGeoTransform(tuple(float(v) for v in geotransform))
        wkt = dsmmod.crs_to_wkt(crs) if crs else ""
        if wkt:
            self.ds.SetProjection(wkt)
        if self.alpha is not None:
            self.ds.GetRasterBand(n).SetColorInterpretation(gdal.GCI_AlphaBand)
        else:
            for b in range(1, bands + 1):
                self.ds.GetRasterBand(b).SetNoDataValue(float("nan"))

    def write(self, r0: int, c0: int, values: np.ndarray, valid: np.ndarray) -> None:
        """values (h, w, bands) float32, valid (h, w) bool."""
        dt = self.dtype
        if dt.kind in "ui":
            info = np.iinfo(dt)
            v = np.clip(np.rint(values), info.min, info.max).astype(dt)
        else:
            v = values.astype(dt)
            v[~valid] = np.nan
        if dt.kind in "ui":
            v[~valid] = 0
        for b in range(self.bands):
            self.ds.GetRasterBand(b + 1).WriteArray(v[:, :, b], int(c0), int(r0))
        if self.alpha is not None:
            a = np.where(valid, self.alpha, 0).astype(dt)
            self.ds.GetRasterBand(self.bands + 1).WriteArray(a, int(c0), int(r0))

    def finish(self, out_path: str, compress: str, progress: Optional[Progress], metadata: Optional[dict] = None
               ) -> None:
        """Translate to a Cloud-Optimized GeoTIFF at ``out_path`` (atomic) and delete the work file."""
        gdal = _gdal()
        progress = progress or NullProgress()
        if metadata:
            self.ds.SetMetadata({str(k): str(v) for k, v in metadata.items()})
        self.ds.FlushCache()
        self.ds = None

        def cb(fraction, _msg, _data):
            progress.report(fraction, "writing Cloud-Optimized GeoTIFF")
            return 0 if progress.is_cancelled() else 1

        opts = ["COMPRESS=" + compress, "BLOCKSIZE=256", "OVERVIEWS=IGNORE_EXISTING", "OVERVIEW_RESAMPLING=AVERAGE",
                "BIGTIFF=IF_SAFER", "NUM_THREADS=1"]
        if compress.upper() in ("DEFLATE", "LZW", "ZSTD"):
            opts.append("PREDICTOR=YES")
        try:
            with atomic_output(out_path) as tmp:
                try:
                    out = gdal.Translate(tmp, self.path, options=gdal.TranslateOptions(
                        format="COG", creationOptions=opts, callback=cb))
                except RuntimeError as e:
                    check_cancel(progress)
                    raise OrthoError(f"cannot write {out_path}: {e}") from e
                if out is None:
                    check_cancel(progress)
                    raise OrthoError(f"cannot write {out_path}")
                out.FlushCache()
                out = None
                check_cancel(progress)
        finally:
            with contextlib.suppress(OSError):
                os.unlink(self.path)

    def abort(self):
        self.ds = None
        with contextlib.suppress(OSError):
            os.unlink(self.path)


_ZSTD: Optional[bool] = None


def _has_zstd() -> bool:
    global _ZSTD
    if _ZSTD is None:
        md = _gdal().GetDriverByName("GTiff").GetMetadataItem("DMD_CREATIONOPTIONLIST") or ""
        _ZSTD = "ZSTD" in md
    return _ZSTD


@contextlib.contextmanager
def _gdal_cache(mb: int):
    gdal = _gdal()
    old = gdal.GetCacheMax()
    gdal.SetCacheMax(int(mb) << 20)
    try:
        yield
    finally:
        gdal.SetCacheMax(old)


# ---------------------------------------------------------------------------
# grids and tiles
# ---------------------------------------------------------------------------

def _tiles(width: int, height: int, tile: int) -> List[Tuple[int, int, int, int]]:
    return [(r, c, min(tile, height - r), min(tile, width - c)) for r in range(0, height, tile)
            for c in range(0, width, tile)]


def _cell_centres(grid: dsmmod.Grid, r0: int, c0: int, h: int, w: int) -> Tuple[np.ndarray, np.ndarray]:
    xs = grid.x0 + (c0 + np.arange(w) + 0.5) * grid.resolution
    ys = grid.y0 - (r0 + np.arange(h) + 0.5) * grid.resolution
    gx, gy = np.meshgrid(xs, ys)
    return gx.ravel(), gy.ravel()


def _subgrid(grid: dsmmod.Grid, bbox: Tuple[float, float, float, float]) -> Optional[Tuple[int, int, int, int]]:
    """(row0, col0, height, width) of the cells of ``grid`` covering ``bbox``, clipped; None if disjoint."""
    res = grid.resolution
    c0 = max(0, int(math.floor((bbox[0] - grid.x0) / res)))
    c1 = min(grid.width, int(math.ceil((bbox[2] - grid.x0) / res)))
    r0 = max(0, int(math.floor((grid.y0 - bbox[3]) / res)))
    r1 = min(grid.height, int(math.ceil((grid.y0 - bbox[1]) / res)))
    if c1 <= c0 or r1 <= r0:
        return None
    return r0, c0, r1 - r0, c1 - c0


def _box_intersects(a, b) -> bool:
    return not (a[2] <= b[0] or a[0] >= b[2] or a[3] <= b[1] or a[1] >= b[3])


# ---------------------------------------------------------------------------
# the block set-up shared by the mosaic and per-image orthophotos
# ---------------------------------------------------------------------------

@dataclass
class _Prepared:
    cameras: List[OrthoCamera]
    metas: List[ImageMeta]
    footprints: List[Footprint]
    visibility: List[Optional[Visibility]]
    grid: dsmmod.Grid
    gsd: float
    z_range: Tuple[float, float]
    warnings: List[str]


def prepare_block(cameras: Sequence[OrthoCamera], dsm: _Dsm, offset: np.ndarray, resolution: float,
                  workdir: str, occlusion: bool = True, height_tolerance: float = 0.0,
                  progress: Optional[Progress] = None) -> _Prepared:
    """Footprints, the output grid and per-image visibility tables; checks the DSM against the images."""
    progress = progress or NullProgress()
    warnings: List[str] = []
    offset = np.asarray(offset, dtype=float)
    if not cameras:
        raise OrthoError("no image to orthorectify")
    centres = np.array([c.centre + offset for c in cameras])
    # a first look at the DSM around the cameras (coarse): the ground under them, then its height range
    z_nadir = dsm.sample(centres[:, 0], centres[:, 1])
    if np.isfinite(z_nadir).any():
        above = centres[:, 2] - float(np.nanmedian(z_nadir))
        span = float(np.clip(1.5 * np.max(above), 20.0, 5000.0))
    else:
        span = 1000.0
    box0 = (float(centres[:, 0].min() - span), float(centres[:, 1].min() - span),
            float(centres[:, 0].max() + span), float(centres[:, 1].max() + span))
    z0, _, _ = dsm.coarse(box0, 400_000)
    if z0.size == 0:
        raise OrthoError(
            f"the DSM {dsm.path} does not cover the images: its extent {_fmt_box(dsm.bounds)} and the cameras' area "
            f"{_fmt_box(box0)} (in {dsm.crs or 'the DSM CRS'}) do not overlap. Use a DSM of this area"
            + (" (or check the CRS: the DSM was reprojected)" if dsm.reprojected else ""))
    zf = z0[np.isfinite(z0)]
    if zf.size == 0:
        raise OrthoError(f"the DSM {dsm.path} has no valid height (all nodata) where the images are "
                         f"({_fmt_box(box0)}): it cannot orthorectify them")
    z_lo, z_hi = float(np.percentile(zf, 0.5)), float(np.percentile(zf, 99.9))
    below = [c.name for c, p in zip(cameras, centres) if p[2] <= z_hi]
    if below and len(below) == len(cameras):
        raise OrthoError(f"every camera is below the DSM's surface (highest {z_hi:.1f}, cameras at "
                         f"{centres[:, 2].min():.1f}..{centres[:, 2].max():.1f}): heights of the DSM and the block "
                         "disagree (vertical datum, units or CRS?)")
    footprints: List[Optional[Footprint]] = []
    for c in cameras:
        footprints.append(camera_footprint(c, offset, z_lo, z_hi))
    keep = [i for i, f in enumerate(footprints) if f is not None]
    dropped = [cameras[i].name for i, f in enumerate(footprints) if f is None]
    if dropped:
        warnings.append(f"{len(dropped)} image(s) see no ground below the DSM's heights and are left out: "
                        f"{', '.join(dropped[:8])}")
    cams = [cameras[i] for i in keep]
    fps = [footprints[i] for i in keep]
    if not cams:
        raise OrthoError("no image sees the ground of the DSM (cameras below the surface or looking up)")
    # DSM coverage per image
    covered = []
    for f in fps:
        zc, _, _ = dsm.coarse(f.bbox, 4000)
        frac = float(np.isfinite(zc).mean()) if zc.size else 0.0
        covered.append(frac)
    if max(covered) == 0.0:
        raise OrthoError(
            f"the DSM {dsm.path} does not cover the images: no valid height under any of the {len(cams)} images' "
            f"footprints (DSM extent {_fmt_box(dsm.bounds)}, images {_fmt_box(_union(f.bbox for f in fps))})")
    poor = [c.name for c, f in zip(cams, covered) if f < 0.5]
    if poor:
        warnings.append(f"the DSM covers less than half of the footprint of {len(poor)} image(s) "
                        f"({', '.join(poor[:6])}{' ...' if len(poor) > 6 else ''}): their uncovered parts stay nodata")
    # metadata of the images
    metas = []
    for c in cams:
        if not os.path.isfile(c.path):
            raise OrthoError(f"image {c.name} is missing: {c.path}")
        m = image_meta(c.path)
        if (m.width, m.height) != (c.camera.width, c.camera.height):
            raise OrthoError(f"image {c.path} is {m.width} x {m.height} pixels but its camera model is "
                             f"{c.camera.width} x {c.camera.height}: the file is not the one that was oriented")
        metas.append(m)
    # grid
    gsd = float(np.median([f.gsd for f in fps]))
    res = float(resolution) if resolution and resolution > 0 else _nice(gsd)
    box = _union(f.bbox for f in fps)
    zc, gx, gy = dsm.coarse(box, 1_000_000)
    ok = np.isfinite(zc)
    if not ok.any():
        raise OrthoError(f"the DSM {dsm.path} has no valid height under the images (all nodata there)")
    step = abs(gx[0, 1] - gx[0, 0]) if gx.shape[1] > 1 else dsm.res
    vbox = (float(gx[ok].min() - step), float(gy[ok].min() - step), float(gx[ok].max() + step),
            float(gy[ok].max() + step))
    box = (max(box[0], vbox[0]), max(box[1], vbox[1]), min(box[2], vbox[2]), min(box[3], vbox[3]))
    if box[2] <= box[0] or box[3] <= box[1]:
        raise OrthoError("the DSM's valid heights and the images' footprints do not overlap")
    grid = dsmmod.Grid.covering(*box, res)
    if grid.width * grid.height > 400_000_000:
        raise OrthoError(f"a {grid.width} x {grid.height} orthophoto at {res:g} is too large: choose a coarser "
                         "RESOLUTION or fewer images")
    # visibility tables
    tol = height_tolerance if height_tolerance and height_tolerance > 0 else max(0.1, dsm.res)
    vis: List[Optional[Visibility]] = []
    for i, (c, f) in enumerate(zip(cams, fps)):
        check_cancel(progress)
        if occlusion:
            vis.append(build_visibility(c, offset, f, dsm, tol, os.path.join(workdir, f"vis_{i:05d}.npy")))
        else:
            vis.append(None)
        progress.report((i + 1) / len(cams), f"visibility {i + 1}/{len(cams)}: {c.name}")
    return _Prepared(cams, metas, fps, vis, grid, gsd, (z_lo, z_hi), warnings)


def _nice(gsd: float) -> float:
    """GSD rounded to 2 significant digits."""
    if gsd <= 0 or not math.isfinite(gsd):
        raise OrthoError(f"cannot derive a resolution from a ground sample distance of {gsd}")
    e = math.floor(math.log10(gsd)) - 1
    return round(gsd / 10 ** e) * 10 ** e


def _union(boxes: Iterable[Tuple[float, float, float, float]]) -> Tuple[float, float, float, float]:
    b = np.array(list(boxes), dtype=float)
    return float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()), float(b[:, 3].max())


def _fmt_box(b) -> str:
    return f"[{b[0]:.1f}, {b[1]:.1f}] - [{b[2]:.1f}, {b[3]:.1f}]"


def _check_kind(metas: Sequence[ImageMeta], cams: Sequence[OrthoCamera]) -> Tuple[int, str]:
    kinds = {}
    for m, c in zip(metas, cams):
        kinds.setdefault((m.bands, m.dtype), []).append(c.name)
    if len(kinds) > 1:
        desc = "; ".join(f"{b} band(s) {d}: {', '.join(n[:3])}{' ...' if len(n) > 3 else ''}"
                         for (b, d), n in kinds.items())
        raise OrthoError(f"the images differ in bands or data type ({desc}): one mosaic needs one kind; choose a "
                         "subset with IMAGES_FILTER (e.g. group:<camera> for the NIR camera only)")
    (bands, dtype), = kinds.keys()
    return bands, dtype


# ---------------------------------------------------------------------------
# per-image true orthophoto
# ---------------------------------------------------------------------------

def write_camera_ortho(cam: OrthoCamera, meta: ImageMeta, vis: Optional[Visibility], fp: Footprint, dsm: _Dsm,
                       offset: np.ndarray, grid: dsmmod.Grid, crs: Optional[str], out_path: str,
                       options: OrthoOptions, progress: Optional[Progress] = None) -> Optional[Dict[str, Any]]:
    """One image's true orthophoto on the cells of ``grid`` under its footprint, as a COG.  Returns the
    sub-grid and valid fraction, or None when the image covers no cell."""
    progress = progress or NullProgress()
    sub = _subgrid(grid, fp.bbox)
    if sub is None:
        return None
    r0, c0, h, w = sub
    g = dsmmod.Grid(grid.x0 + c0 * grid.resolution, grid.y0 - r0 * grid.resolution, grid.resolution, w, h)
    work = os.path.join(os.path.dirname(os.path.abspath(out_path)), ".work-" + os.path.basename(out_path))
    writer = _RasterWriter(work, w, h, meta.bands, meta.dtype, g.geotransform, crs)
    n_valid = 0
    try:
        tiles = _tiles(w, h, options.tile)
        for k, (tr, tc, th, tw) in enumerate(tiles):
            check_cancel(progress)
            x, y = _cell_centres(g, tr, tc, th, tw)
            z = dsm.sample(x, y)
            s = sample_camera(cam, meta, offset, x, y, z, vis, options.interpolation)
            writer.write(tr, tc, s.values.reshape(th, tw, -1), s.valid.reshape(th, tw))
            n_valid += int(s.valid.sum())
            progress.report(0.9 * (k + 1) / len(tiles), f"{cam.name}: tile {k + 1}/{len(tiles)}")
        writer.finish(out_path, options.compress, SubProgress(progress, 0.9, 1.0),
                      metadata={"ARCHAEOORTHO_STAGE": "orthophoto", "IMAGE": cam.name})
    except BaseException:
        writer.abort()
        raise
    return {"path": out_path, "grid": asdict(g), "valid_fraction": n_valid / float(w * h)}


# ---------------------------------------------------------------------------
# mosaic planning: labels, relief-aware seams, exposure
# ---------------------------------------------------------------------------

@dataclass
class _Plan:
    k: int  # planning cell = k output cells
    width: int
    height: int
    labels_path: str  # int32 (height, width), -1 = no image
    gains: List[float]
    windows: List[Optional[Tuple[int, int, int, int]]]  # per camera: (r0, c0, h, w) in planning cells
    feather_cells: int
    relief_blobs: int
    relief_reassigned: int
    seam_before: float = float("nan")  # mean brightness disagreement of the two images along the seams
    seam_after: float = float("nan")


def _plan_mosaic(prep: _Prepared, dsm: _Dsm, offset: np.ndarray, options: OrthoOptions, workdir: str,
                 progress: Progress) -> _Plan:
    import cv2

    grid = prep.grid
    k = max(1, int(round(PLANNING_GSD * prep.gsd / grid.resolution)))
    while math.ceil(grid.width / k) * math.ceil(grid.height / k) > MAX_PLANNING_CELLS:
        k += 1
    pw, ph = int(math.ceil(grid.width / k)), int(math.ceil(grid.height / k))
    p = k * grid.resolution
    pgrid = dsmmod.Grid(grid.x0, grid.y0, p, pw, ph)
    # DSM at planning cells
    zp = np.full((ph, pw), np.nan, dtype=np.float32)
    rows = max(1, 1_000_000 // pw)
    for r0 in range(0, ph, rows):
        h = min(rows, ph - r0)
        x, y = _cell_centres(pgrid, r0, 0, h, pw)
        zp[r0:r0 + h] = dsm.sample(x, y).reshape(h, pw)
    best = np.full((ph, pw), np.inf, dtype=np.float32)
    labels = np.full((ph, pw), -1, dtype=np.int32)
    windows: List[Optional[Tuple[int, int, int, int]]] = []
    costs: List[Optional[np.ndarray]] = []
    greys: List[Optional[np.ndarray]] = []
    n = len(prep.cameras)
    for i, (cam, meta, fp, vis) in enumerate(zip(prep.cameras, prep.metas, prep.footprints, prep.visibility)):
        check_cancel(progress)
        sub = _subgrid(pgrid, fp.bbox)
        windows.append(sub)
        if sub is None:
            costs.append(None)
            greys.append(None)
            continue
        r0, c0, h, w = sub
        x, y = _cell_centres(pgrid, r0, c0, h, w)
        z = zp[r0:r0 + h, c0:c0 + w].ravel().astype(np.float64)
        s = sample_camera(cam, meta, offset, x, y, z, vis, "bilinear")
        cost = s.cost.reshape(h, w)
        costs.append(cost)
        greys.append(s.values.mean(axis=1).reshape(h, w).astype(np.float32))
        win_best = best[r0:r0 + h, c0:c0 + w]
        better = cost < win_best
        win_best[better] = cost[better]
        labels[r0:r0 + h, c0:c0 + w][better] = i
        progress.report(0.7 * (i + 1) / n, f"planning the mosaic: {i + 1}/{n}")

    # exposure gains (OpenCV's gain compensator: overlaps' mean intensities)
    gains = [1.0] * n
    if options.exposure:
        gains = _exposure_gains(windows, costs, greys, prep.metas[0].dtype)
    greys = [None if g is None else g * np.float32(gi) for g, gi in zip(greys, gains)]

    # seamlines where the overlapping images agree and the scene is smooth (not across edges or moving things)
    scale = float(np.iinfo(np.dtype(prep.metas[0].dtype)).max) if np.dtype(prep.metas[0].dtype).kind in "ui" else 1.0
    seam_before = _seam_disagreement(labels, windows, greys, scale)
    if options.seam_iterations > 0:
        labels = _refine_seams(labels, windows, costs, greys, scale, options.seam_iterations, options.seam_alpha)
    seam_after = _seam_disagreement(labels, windows, greys, scale)

    # relief: objects above their surroundings go whole to one image
    blobs = reassigned = 0
    if options.avoid_relief and np.isfinite(zp).any():
        zf = np.where(np.isfinite(zp), zp, np.nanmin(zp)).astype(np.float32)
        radius = max(1, int(math.ceil(12.0 / p)))  # objects up to ~24 m across
        ker = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * radius + 1, 2 * radius + 1))
        opened = cv2.dilate(cv2.erode(zf, ker), ker)
        core = (zf - opened) > options.relief_height
        margin = max(1, int(math.ceil(1.0 / p)))
        tall = cv2.dilate(core.astype(np.uint8), cv2.getStructuringElement(
            cv2.MORPH_ELLIPSE, (2 * margin + 1, 2 * margin + 1))) > 0
        from scipy import ndimage

        lab, nb = ndimage.label(tall)
        blobs = int(nb)
        if nb:
            slices = ndimage.find_objects(lab)
            for b, sl in enumerate(slices, start=1):
                if sl is None:
                    continue
                region = lab[sl] == b
                region_core = core[sl][region]
                current = labels[sl][region]
                present = np.unique(current[current >= 0])
                if len(present) <= 1:
                    continue
                br0, bc0 = sl[0].start, sl[1].start
                choice, choice_key = None, None
                for cid in present:
                    win = windows[cid]
                    if win is None:
                        continue
                    wr0, wc0, wh, ww = win
                    rr, cc = np.nonzero(region)
                    rr = rr + br0 - wr0
                    cc = cc + bc0 - wc0
                    inwin = (rr >= 0) & (rr < wh) & (cc >= 0) & (cc < ww)
                    vals = np.full(len(rr), np.inf, dtype=np.float32)
                    vals[inwin] = costs[cid][rr[inwin], cc[inwin]]
                    frac = float(np.isfinite(vals[region_core]).mean()) if region_core.any() else 0.0
                    key = (frac >= 0.97, -float(np.mean(vals[np.isfinite(vals)])) if np.isfinite(vals).any() else -1e9)
                    if choice_key is None or key > choice_key:
                        choice, choice_key, choice_vals = cid, key, vals
                if choice is None or not choice_key[0]:
                    continue
                sub_labels = labels[sl]
                put = region.copy()
                put[region] = np.isfinite(choice_vals)
                sub_labels[put] = choice
                reassigned += 1
    np.save(os.path.join(workdir, "labels.npy"), labels)
    progress.report(1.0, "mosaic planned")
    feather = max(1, int(round(options.feather_gsd * prep.gsd / (2 * p)))) if options.blending == "feather" else 0
    return _Plan(k, pw, ph, os.path.join(workdir, "labels.npy"), gains, windows, feather, blobs, reassigned,
                 seam_before, seam_after)


def _gather(arrays: Sequence[Optional[np.ndarray]], windows, lab: np.ndarray, rr: np.ndarray, cc: np.ndarray,
            fill: float = np.inf) -> np.ndarray:
    """arrays[lab[k]][rr[k], cc[k]] in planning coordinates (each array covers its image's window)."""
    out = np.full(len(rr), fill, dtype=np.float32)
    for i in np.unique(lab):
        if i < 0 or windows[i] is None or arrays[i] is None:
            continue
        sel = np.flatnonzero(lab == i)
        r0, c0, h, w = windows[i]
        r, c = rr[sel] - r0, cc[sel] - c0
        ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        out[sel[ok]] = arrays[i][r[ok], c[ok]]
    return out


_NEIGHBOURS = ((-1, 0), (1, 0), (0, -1), (0, 1))


def _seam_cells(labels: np.ndarray, parity: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
    h, w = labels.shape
    b = np.zeros_like(labels, dtype=bool)
    b[1:] |= labels[1:] != labels[:-1]
    b[:-1] |= labels[:-1] != labels[1:]
    b[:, 1:] |= labels[:, 1:] != labels[:, :-1]
    b[:, :-1] |= labels[:, :-1] != labels[:, 1:]
    b &= labels >= 0
    if parity is not None:
        rr, cc = np.indices((h, w))
        b &= (rr + cc) % 2 == parity
    return np.nonzero(b)


def _seam_disagreement(labels: np.ndarray, windows, greys, scale: float) -> float:
    """Mean |difference| (fraction of full scale) of the two images on either side of the seams."""
    rr, cc = _seam_cells(labels)
    if not len(rr):
        return 0.0
    h, w = labels.shape
    own = labels[rr, cc]
    tot, n = 0.0, 0
    ga = _gather(greys, windows, own, rr, cc, np.nan)
    for dr, dc in _NEIGHBOURS:
        qr, qc = np.clip(rr + dr, 0, h - 1), np.clip(cc + dc, 0, w - 1)
        other = labels[qr, qc]
        m = (other != own) & (other >= 0)
        if m.any():
            gb = _gather(greys, windows, other[m], rr[m], cc[m], np.nan)
            d = np.abs(ga[m] - gb)
            d = d[np.isfinite(d)]
            tot += float(d.sum())
            n += len(d)
    return tot / n / scale if n else 0.0


def _refine_seams(labels: np.ndarray, windows, costs, greys, scale: float, iterations: int = 1,
                  alpha: float = 5.0, tol: float = 0.05, band: int = 8) -> np.ndarray:
    """Move the seamline between every two adjacent images within a band of ``band`` planning cells to where the
    two images agree and the scene has no edges: a minimum cut (scipy max-flow) of the band with the cost
    alpha * view cost per cell and, per seam edge, 1 + |grey_a - grey_b| / tol + mean gradient / tol
    (brightness as a fraction of full scale).  Cells outside the band, or seen by only one of the two, stay."""
    import cv2
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, maximum_flow

    grads = []
    for g in greys:
        if g is None:
            grads.append(None)
            continue
        gf = np.where(np.isfinite(g), g, 0.0).astype(np.float32) / scale
        gx = cv2.Sobel(gf, cv2.CV_32F, 1, 0, ksize=3) / 8.0
        gy = cv2.Sobel(gf, cv2.CV_32F, 0, 1, ksize=3) / 8.0
        grads.append(np.hypot(gx, gy))
    norm = [None if g is None else g / scale for g in greys]
    labels = labels.copy()
    h, w = labels.shape
    kernel = np.ones((2 * band + 1, 2 * band + 1), np.uint8)
    for _ in range(max(1, iterations)):
        pairs = set()
        for a_, b_ in ((labels[:, 1:], labels[:, :-1]), (labels[1:], labels[:-1])):
            m = (a_ != b_) & (a_ >= 0) & (b_ >= 0)
            for u, v in zip(a_[m].tolist(), b_[m].tolist()):
                pairs.add((min(u, v), max(u, v)))
        changed = 0
        for la, lb in sorted(pairs):
            in_a, in_b = labels == la, labels == lb
            seam = np.zeros_like(in_a)
            seam[:, 1:] |= (in_a[:, 1:] & in_b[:, :-1]) | (in_b[:, 1:] & in_a[:, :-1])
            seam[:, :-1] |= (in_a[:, :-1] & in_b[:, 1:]) | (in_b[:, :-1] & in_a[:, 1:])
            seam[1:] |= (in_a[1:] & in_b[:-1]) | (in_b[1:] & in_a[:-1])
            seam[:-1] |= (in_a[:-1] & in_b[1:]) | (in_b[:-1] & in_a[1:])
            if not seam.any():
                continue
            rows, cols = np.nonzero(seam)
            r0, r1 = max(0, rows.min() - band - 1), min(h, rows.max() + band + 2)
            c0, c1 = max(0, cols.min() - band - 1), min(w, cols.max() + band + 2)
            sub = labels[r0:r1, c0:c1]
            near = cv2.dilate(seam[r0:r1, c0:c1].astype(np.uint8), kernel) > 0
            cand = near & ((sub == la) | (sub == lb))
            rr, cc = np.nonzero(cand)
            gr, gc = rr + r0, cc + c0
            ca = _gather(costs, windows, np.full(len(rr), la), gr, gc)
            cb = _gather(costs, windows, np.full(len(rr), lb), gr, gc)
            ok = np.isfinite(ca) & np.isfinite(cb)
            if ok.sum() < 4:
                continue
            rr, cc, gr, gc, ca, cb = rr[ok], cc[ok], gr[ok], gc[ok], ca[ok], cb[ok]
            n = len(rr)
            index = np.full(sub.shape, -1, dtype=np.int64)
            index[rr, cc] = np.arange(n)
            ga = _gather(norm, windows, np.full(n, la), gr, gc, np.nan)
            gb = _gather(norm, windows, np.full(n, lb), gr, gc, np.nan)
            diff = np.nan_to_num(np.abs(ga - gb), nan=0.2)
            edge = (_gather(grads, windows, np.full(n, la), gr, gc, 0.0)
                    + _gather(grads, windows, np.full(n, lb), gr, gc, 0.0)) / 2.0
            unit = diff / tol + edge / tol  # per cell; an edge costs 1 + the mean of its two cells
            d_a = alpha * ca.astype(np.float64)  # cost of giving the cell to la
            d_b = alpha * cb.astype(np.float64)
            src, dst, cap = [], [], []
            for dr, dc in ((0, 1), (1, 0), (0, -1), (-1, 0)):
                qr, qc = rr + dr, cc + dc
                inside = (qr >= 0) & (qr < sub.shape[0]) & (qc >= 0) & (qc < sub.shape[1])
                q = np.full(n, -1, dtype=np.int64)
                q[inside] = index[qr[inside], qc[inside]]
                lq = np.full(n, -1, dtype=labels.dtype)
                lq[inside] = sub[qr[inside], qc[inside]]
                fixed = inside & (q < 0) & (lq >= 0)  # a neighbour that keeps its label
                wgt = 1.0 + unit
                d_a += np.where(fixed & (lq != la), wgt, 0.0)
                d_b += np.where(fixed & (lq != lb), wgt, 0.0)
                if dr >= 0 and dc >= 0:  # each free-free edge once, both directions
                    both = q >= 0
                    if both.any():
                        wq = 1.0 + 0.5 * (unit[both] + unit[q[both]])
                        src += [np.arange(n)[both], q[both]]
                        dst += [q[both], np.arange(n)[both]]
                        cap += [wq, wq]
            s_node, t_node = n, n + 1
            lo = np.minimum(d_a, d_b)
            src += [np.full(n, s_node), np.arange(n)]
            dst += [np.arange(n), np.full(n, t_node)]
            cap += [d_b - lo, d_a - lo]  # cutting s->p puts p on lb's side (pays d_b), p->t on la's side
            cap_i = np.maximum(0, np.rint(np.concatenate(cap) * 100.0)).astype(np.int32)
            si, di = np.concatenate(src), np.concatenate(dst)
            keep = cap_i > 0
            graph = coo_matrix((cap_i[keep], (si[keep], di[keep])), shape=(n + 2, n + 2)).tocsr()
            flow = maximum_flow(graph, s_node, t_node).flow
            residual = (graph - flow).tocsr()
            residual.data = (residual.data > 0).astype(np.int8)
            residual.eliminate_zeros()
            reach = breadth_first_order(residual, s_node, directed=True, return_predecessors=False)
            side_a = np.zeros(n + 2, dtype=bool)
            side_a[reach] = True
            new = np.where(side_a[:n], la, lb)
            moved = new != sub[rr, cc]
            sub[rr[moved], cc[moved]] = new[moved]
            changed += int(moved.sum())
        if changed == 0:
            break
    return labels


def _exposure_gains(windows, costs, greys, dtype: str) -> List[float]:
    n = len(windows)
    scale = float(np.iinfo(np.dtype(dtype)).max) if np.dtype(dtype).kind in "ui" else 1.0
    sigma_n, sigma_g = 10.0 / 255.0, 0.1
    a = np.zeros((n, n))
    b = np.zeros(n)
    for i in range(n):
        wi = windows[i]
        if wi is None or greys[i] is None:
            continue
        for j in range(i + 1, n):
            wj = windows[j]
            if wj is None or greys[j] is None:
                continue
            r0, c0 = max(wi[0], wj[0]), max(wi[1], wj[1])
            r1, c1 = min(wi[0] + wi[2], wj[0] + wj[2]), min(wi[1] + wi[3], wj[1] + wj[3])
            if r1 <= r0 or c1 <= c0:
                continue
            si = (slice(r0 - wi[0], r1 - wi[0]), slice(c0 - wi[1], c1 - wi[1]))
            sj = (slice(r0 - wj[0], r1 - wj[0]), slice(c0 - wj[1], c1 - wj[1]))
            both = np.isfinite(costs[i][si]) & np.isfinite(costs[j][sj])
            nij = int(both.sum())
            if nij < 16:
                continue
            iij = float(greys[i][si][both].mean()) / scale
            iji = float(greys[j][sj][both].mean()) / scale
            for p, q, ip, iq in ((i, j, iij, iji), (j, i, iji, iij)):
                a[p, p] += nij * (ip * ip / sigma_n ** 2 + 1.0 / sigma_g ** 2)
                a[p, q] -= nij * ip * iq / sigma_n ** 2
                b[p] += nij / sigma_g ** 2
    gains = np.ones(n)
    used = np.flatnonzero(np.diag(a) > 0)
    if len(used):
        try:
            g = np.linalg.solve(a[np.ix_(used, used)], b[used])
            gains[used] = np.clip(g, 0.5, 2.0)
        except np.linalg.LinAlgError:
            pass
    return [float(v) for v in gains]


# ---------------------------------------------------------------------------
# mosaic tiles
# ---------------------------------------------------------------------------

@dataclass
class _TileUnit:
    """Everything one mosaic tile needs (picklable: runs in a pool worker or on a Dask cluster)."""

    index: int
    r0: int  # tile rows/cols in output cells (without halo)
    c0: int
    h: int
    w: int
    halo: int
    grid: Dict[str, Any]
    dsm_path: str
    crs: Optional[str]
    offset: List[float]
    cameras: List[OrthoCamera]
    metas: List[ImageMeta]
    visibility: List[Optional[Visibility]]
    primary: List[int]  # indices into cameras (labels present near the tile)
    secondary: List[int]  # other images over the tile, best first (fill occlusions)
    gains: List[float]
    labels_path: str
    k: int
    plan_shape: Tuple[int, int]
    feather_cells: int
    blending: str
    interpolation: str
    cache_mb: int


_DSM_CACHE: Dict[Tuple[str, Optional[str]], _Dsm] = {}


def _dsm_for(path: str, crs: Optional[str]) -> _Dsm:
    key = (path, crs)
    if key not in _DSM_CACHE:
        _DSM_CACHE.clear()
        _DSM_CACHE[key] = _Dsm(path, crs)
    return _DSM_CACHE[key]


def _render_tile(unit: _TileUnit, cancel_path: Optional[str] = None) -> Dict[str, Any]:
    """Blend one mosaic tile: returns values (h, w, bands) float32, valid (h, w) and which-image counts."""
    import cv2

    _CACHE.max_bytes = unit.cache_mb << 20
    grid = dsmmod.Grid(**unit.grid)
    dsm = _dsm_for(unit.dsm_path, unit.crs)
    off = np.asarray(unit.offset, dtype=float)
    halo = unit.halo
    # rows/cols with halo, clipped to the grid
    ar0, ac0 = max(0, unit.r0 - halo), max(0, unit.c0 - halo)
    ar1, ac1 = min(grid.height, unit.r0 + unit.h + halo), min(grid.width, unit.c0 + unit.w + halo)
    hh, ww = ar1 - ar0, ac1 - ac0
    x, y = _cell_centres(grid, ar0, ac0, hh, ww)
    z = dsm.sample(x, y)
    bands = unit.metas[0].bands
    labels_all = np.load(unit.labels_path, mmap_mode="r")
    k = unit.k
    ph, pw = unit.plan_shape
    # planning window around the tile (margin for the feathering blur)
    m = unit.feather_cells + 1
    pr0, pc0 = max(0, ar0 // k - m), max(0, ac0 // k - m)
    pr1, pc1 = min(ph, (ar1 - 1) // k + 1 + m), min(pw, (ac1 - 1) // k + 1 + m)
    lab = np.asarray(labels_all[pr0:pr1, pc0:pc1])
    rows = np.arange(ar0, ar1)
    cols = np.arange(ac0, ac1)
    # planning coordinates of the output cells (for soft weights), nearest planning cell (for hard labels)
    fr = ((rows + 0.5) / k - 0.5 - pr0).astype(np.float32)
    fc = ((cols + 0.5) / k - 0.5 - pc0).astype(np.float32)
    map_x, map_y = np.meshgrid(fc, fr)
    hard = lab[(rows // k - pr0)[:, None], (cols // k - pc0)[None, :]]

    acc = np.zeros((hh * ww, bands), dtype=np.float64) if unit.blending != "multiband" else None
    wsum = np.zeros(hh * ww, dtype=np.float64)
    any_valid = np.zeros(hh * ww, dtype=bool)
    best_cost = np.full(hh * ww, np.inf, dtype=np.float32)
    layers = []  # multiband: (values, weight)
    counts: Dict[int, int] = {}
    for ci in unit.primary:
        if cancel_path and os.path.exists(cancel_path):
            raise Cancelled("cancelled by the user")
        cam = unit.cameras[ci]
        s = sample_camera(cam, unit.metas[ci], off, x, y, z, unit.visibility[ci], unit.interpolation)
        if not s.valid.any():
            continue
        vals = s.values * np.float32(unit.gains[ci])
        if unit.blending == "feather" and unit.feather_cells > 0:
            onehot = (lab == ci).astype(np.float32)
            ksz = 2 * unit.feather_cells + 1
            soft = cv2.blur(onehot, (ksz, ksz), borderType=cv2.BORDER_REPLICATE)
            wgt = cv2.remap(soft, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).ravel()
        else:
            wgt = (hard == ci).astype(np.float32).ravel()
        wgt = np.where(s.valid, wgt, 0.0)
        any_valid |= s.valid
        better = s.cost < best_cost
        best_cost[better] = s.cost[better]
        if unit.blending == "multiband":
            layers.append((vals, s.valid, wgt))
        else:
            acc += vals * wgt[:, None]
        wsum += wgt
    # cells whose planned image cannot see them: the best image that does (primary first, then the others)
    need = wsum <= 1e-6
    fill_vals = np.zeros((hh * ww, bands), dtype=np.float32)
    fill_cost = np.full(hh * ww, np.inf, dtype=np.float32)
    if need.any():
        order = list(unit.primary) + list(unit.secondary)
        idx = np.flatnonzero(need)
        for ci in order:
            if not len(idx):
                break
            s = sample_camera(unit.cameras[ci], unit.metas[ci], off, x[idx], y[idx], z[idx], unit.visibility[ci],
                              unit.interpolation)
            better = s.valid & (s.cost < fill_cost[idx])
            if better.any():
                sel = idx[better]
                fill_vals[sel] = s.values[better] * np.float32(unit.gains[ci])
                fill_cost[sel] = s.cost[better]
                counts[ci] = counts.get(ci, 0) + int(better.sum())
        filled = need & np.isfinite(fill_cost)
    else:
        filled = need
    valid = (wsum > 1e-6) | filled
    if unit.blending == "multiband":
        out = _multiband(layers, fill_vals, filled, hh, ww, bands)
    else:
        out = np.zeros((hh * ww, bands), dtype=np.float32)
        ok = wsum > 1e-6
        out[ok] = (acc[ok] / wsum[ok, None]).astype(np.float32)
        out[filled] = fill_vals[filled]
    # crop the halo
    rr0, cc0 = unit.r0 - ar0, unit.c0 - ac0
    out = out.reshape(hh, ww, bands)[rr0:rr0 + unit.h, cc0:cc0 + unit.w]
    valid = valid.reshape(hh, ww)[rr0:rr0 + unit.h, cc0:cc0 + unit.w]
    return {"index": unit.index, "r0": unit.r0, "c0": unit.c0, "values": out, "valid": valid,
            "fill_cells": int(filled.reshape(hh, ww)[rr0:rr0 + unit.h, cc0:cc0 + unit.w].sum())}


def _multiband(layers, fill_vals: np.ndarray, filled: np.ndarray, h: int, w: int, bands: int) -> np.ndarray:
    """Laplacian-pyramid blending of the layers (values, valid, weight) plus the hard fill."""
    import cv2

    levels = max(1, min(5, int(math.log2(max(2, min(h, w)))) - 3))
    items = list(layers)
    if filled.any():
        items.append((fill_vals, filled, filled.astype(np.float32)))
    if not items:
        return np.zeros((h * w, bands), dtype=np.float32)
    num = None
    den = None
    for vals, valid, wgt in items:
        img = _push_pull(vals.reshape(h, w, bands), valid.reshape(h, w), levels + 1)
        lap = _laplacian(img, levels)
        gw = [wgt.reshape(h, w).astype(np.float32)]
        for _ in range(levels):
            gw.append(cv2.pyrDown(gw[-1]))
        if num is None:
            num = [np.zeros_like(li) for li in lap]
            den = [np.zeros(g.shape, dtype=np.float32) for g in gw]
        for lv in range(levels + 1):
            num[lv] += lap[lv] * gw[lv][:, :, None]
            den[lv] += gw[lv]
    blended = [n_ / np.maximum(d_, 1e-6)[:, :, None] for n_, d_ in zip(num, den)]
    out = blended[-1]
    for lv in range(levels - 1, -1, -1):
        sz = (blended[lv].shape[1], blended[lv].shape[0])
        out = _pyr_up(out, sz) + blended[lv]
    return out.reshape(h * w, bands)


def _pyr_up(a: np.ndarray, size) -> np.ndarray:
    import cv2

    up = cv2.pyrUp(a, dstsize=size)
    return up if up.ndim == 3 else up[:, :, None]


def _pyr_down(a: np.ndarray) -> np.ndarray:
    import cv2

    d = cv2.pyrDown(a)
    return d if d.ndim == 3 else d[:, :, None]


def _laplacian(img: np.ndarray, levels: int) -> List[np.ndarray]:
    gp = [img]
    for _ in range(levels):
        gp.append(_pyr_down(gp[-1]))
    lp = []
    for lv in range(levels):
        size = (gp[lv].shape[1], gp[lv].shape[0])
        lp.append(gp[lv] - _pyr_up(gp[lv + 1], size))
    lp.append(gp[-1])
    return lp


def _push_pull(img: np.ndarray, valid: np.ndarray, levels: int) -> np.ndarray:
    """Fill invalid cells from valid neighbours at coarser scales (so pyramids see no dark holes)."""
    if valid.all():
        return img.astype(np.float32)
    wv = valid.astype(np.float32)
    pyr_v = [img.astype(np.float32) * wv[:, :, None]]
    pyr_w = [wv]
    for _ in range(levels + 4):
        if min(pyr_w[-1].shape) <= 2:
            break
        pyr_v.append(_pyr_down(pyr_v[-1]))
        pyr_w.append(_pyr_down(pyr_w[-1][:, :, None])[:, :, 0])
    est = pyr_v[-1] / np.maximum(pyr_w[-1], 1e-6)[:, :, None]
    for lv in range(len(pyr_v) - 2, -1, -1):
        size = (pyr_v[lv].shape[1], pyr_v[lv].shape[0])
        up = _pyr_up(est, size)
        wl = pyr_w[lv]
        here = pyr_v[lv] / np.maximum(wl, 1e-6)[:, :, None]
        a = np.clip(wl, 0.0, 1.0)[:, :, None]
        est = a * here + (1 - a) * up
    out = img.astype(np.float32).copy()
    out[~valid] = est[~valid]
    return out


# ---------------------------------------------------------------------------
# the mosaic
# ---------------------------------------------------------------------------

@dataclass
class MosaicResult:
    path: str
    crs: Optional[str]
    resolution: float
    gsd: float
    width: int
    height: int
    images: List[str]
    valid_fraction: float
    per_image: Dict[str, str] = field(default_factory=dict)
    seamlines_path: Optional[str] = None
    gains: Dict[str, float] = field(default_factory=dict)
    timings: Dict[str, float] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)


def build_orthomosaic(cameras: Sequence[OrthoCamera], dsm_path: str, crs: Optional[str], offset: Sequence[float],
                      output: str, options: Optional[OrthoOptions] = None, per_image_folder: Optional[str] = None,
                      seamlines_path: Optional[str] = None, progress: Optional[Progress] = None) -> MosaicResult:
    """The orthomosaic of ``cameras`` (poses in the local frame, world = local + ``offset``) on a DSM.

    Writes a COG at ``output`` (atomically), optionally one true orthophoto per image into
    ``per_image_folder`` and the which-image polygons into the GeoPackage ``seamlines_path``."""
    options = options or OrthoOptions()
    options.check()
    progress = progress or NullProgress()
    offset = np.asarray(offset, dtype=float)
    t_start = time.time()
    timings: Dict[str, float] = {}
    log: List[str] = []
    out_dir = os.path.dirname(os.path.abspath(output))
    os.makedirs(out_dir, exist_ok=True)
    workdir = tempfile.mkdtemp(prefix=".ortho-work-", dir=out_dir)
    _CACHE.max_bytes = options.cache_mb << 20
    source_dsm = dsm_path
    try:
        dsm_path, filled = fill_dsm_gaps(dsm_path, os.path.join(workdir, "dsm-gaps-filled.tif"),
                                         options.fill_dsm_gaps_m)
        dsm = _Dsm(dsm_path, crs)
    except BaseException:
        shutil.rmtree(workdir, ignore_errors=True)
        raise
    if filled:
        log.append(f"DSM gaps: {filled} cells without a height, inside the hull of the measured ones and at most "
                   f"{options.fill_dsm_gaps_m:g} m from one, took interpolated heights for the orthophoto (the DSM "
                   "file is unchanged)")
        progress.info(log[-1])
    try:
        with _gdal_cache(64):
            t0 = time.time()
            prep = prepare_block(cameras, dsm, offset, options.resolution, workdir, options.occlusion,
                                 options.height_tolerance, SubProgress(progress, 0.0, 0.12))
            for w_ in prep.warnings:
                progress.warning(w_)
            if dsm.reprojected:
                log.append(f"DSM {source_dsm} reprojected on the fly into {crs}")
            bands, dtype = _check_kind(prep.metas, prep.cameras)
            grid = prep.grid
            timings["visibility"] = time.time() - t0
            log.append(f"{len(prep.cameras)} images, GSD {prep.gsd:.3f}, mosaic {grid.width} x {grid.height} cells "
                       f"at {grid.resolution:g} ({bands} band(s) {dtype}), blending {options.blending}")
            progress.info(log[-1])
            t0 = time.time()
            plan = _plan_mosaic(prep, dsm, offset, options, workdir, SubProgress(progress, 0.12, 0.2))
            timings["planning"] = time.time() - t0
            log.append(f"seamlines: {plan.relief_blobs} raised objects, {plan.relief_reassigned} given whole to one "
                       f"image; mean brightness difference across the seams {100 * plan.seam_before:.1f} % before and "
                       f"{100 * plan.seam_after:.1f} % after moving them to where the images agree; exposure gains "
                       f"{min(plan.gains):.3f}..{max(plan.gains):.3f}")
            progress.info(log[-1])
            t0 = time.time()
            n_valid, fill_cells = _run_tiles(prep, plan, dsm_path, crs, offset, output, options, bands, dtype,
                                             SubProgress(progress, 0.2, 0.85 if per_image_folder else 0.97))
            timings["mosaic"] = time.time() - t0
            valid_fraction = n_valid / float(grid.width * grid.height)
            labels = np.load(plan.labels_path)
            if seamlines_path:
                _write_sources_gpkg(seamlines_path, labels, prep, plan, crs)
            del labels
            per_image: Dict[str, str] = {}
            if per_image_folder:
                t0 = time.time()
                os.makedirs(per_image_folder, exist_ok=True)
                sp = SubProgress(progress, 0.85, 1.0)
                for i, (cam, meta, fp, vis) in enumerate(zip(prep.cameras, prep.metas, prep.footprints,
                                                             prep.visibility)):
                    path = os.path.join(per_image_folder, os.path.splitext(os.path.basename(cam.name))[0] + ".tif")
                    info = write_camera_ortho(cam, meta, vis, fp, dsm, offset, grid, crs, path, options,
                                              SubProgress(sp, i / len(prep.cameras), (i + 1) / len(prep.cameras)))
                    if info:
                        per_image[cam.name] = path
                timings["per_image"] = time.time() - t0
            timings["total"] = time.time() - t_start
            log.append(f"mosaic {output}: {100 * valid_fraction:.1f} % of the cells have data, {fill_cells} cells "
                       "filled from another image where the planned one is occluded")
            progress.report(1.0, "orthomosaic done")
            return MosaicResult(path=output, crs=crs, resolution=grid.resolution, gsd=prep.gsd, width=grid.width,
                                height=grid.height, images=[c.name for c in prep.cameras],
                                valid_fraction=valid_fraction, per_image=per_image, seamlines_path=seamlines_path,
                                gains={c.name: g for c, g in zip(prep.cameras, plan.gains)},
                                timings={k: round(v, 3) for k, v in timings.items()}, warnings=prep.warnings,
                                log_lines=log)
    finally:
        dsm.close()
        _DSM_CACHE.clear()
        _CACHE.clear()
        shutil.rmtree(workdir, ignore_errors=True)


FILL_MAX_CELLS = 120_000_000  # larger DSMs are used as they are (the fill works on the whole raster in memory)


def fill_dsm_gaps(dsm_path: str, out_path: str, max_distance: float) -> Tuple[str, int]:
    """Fill the gaps of a DSM for orthorectification: cells without a height that lie inside the convex hull of
    the measured cells and within ``max_distance`` (CRS units) of one get a height interpolated (inverse distance,
    GDAL FillNodata) from their surroundings, so that a tree crown the dense matching missed does not leave a hole
    in the orthophoto.  Beyond the measured area (a DSM that covers part of the block) nothing is invented.

    Returns (path of the DSM to use, cells filled): ``out_path`` when something was filled, else ``dsm_path``."""
    import cv2
    from osgeo import gdal

    if not max_distance or max_distance <= 0:
        return dsm_path, 0
    ds = gdal.Open(dsm_path)
    if ds is None or ds.RasterXSize * ds.RasterYSize > FILL_MAX_CELLS:
        return dsm_path, 0
    band = ds.GetRasterBand(1)
    z = band.ReadAsArray().astype(np.float32)
    nodata = band.GetNoDataValue()
    valid = np.isfinite(z)
    if nodata is not None and np.isfinite(nodata):
        valid &= z != nodata
    if valid.all() or not valid.any():
        return dsm_path, 0
    rows, cols = np.nonzero(valid)
    hull = cv2.convexHull(np.column_stack([cols, rows]).astype(np.int32))
    inside = np.zeros(z.shape, np.uint8)
    cv2.fillConvexPoly(inside, hull, 1)
    gaps = (~valid) & inside.astype(bool)
    if not gaps.any():
        return dsm_path, 0
    gt = ds.GetGeoTransform()
    max_cells = max(1.0, max_distance / max(abs(gt[1]), abs(gt[5])))
    fill_value = -9999.0
    mem = gdal.GetDriverByName("MEM").Create("", ds.RasterXSize, ds.RasterYSize, 1, gdal.GDT_Float32)
    mem.SetGeoTransform(gt)
    mem.SetProjection(ds.GetProjection())
    mb = mem.GetRasterBand(1)
    mb.SetNoDataValue(fill_value)
    mb.WriteArray(np.where(valid, z, fill_value).astype(np.float32))
    gdal.FillNodata(mb, None, maxSearchDist=float(max_cells), smoothingIterations=0)
    out = mb.ReadAsArray()
    take = gaps & (out != fill_value)
    result = np.where(valid, z, np.nan).astype(np.float32)
    result[take] = out[take]
    n = int(take.sum())
    if n == 0:
        return dsm_path, 0
    srs = ds.GetSpatialRef()
    dsmmod.write_cog(out_path, result, gt, srs.ExportToWkt() if srs is not None else None)
    return out_path, n


def _run_tiles(prep: _Prepared, plan: _Plan, dsm_path: str, crs, offset, output: str, options: OrthoOptions,
               bands: int, dtype: str, progress: Progress) -> Tuple[int, int]:
    from ..common import parallel

    grid = prep.grid
    work = os.path.join(os.path.dirname(os.path.abspath(output)), ".work-" + os.path.basename(output))
    writer = _RasterWriter(work, grid.width, grid.height, bands, dtype, grid.geotransform, crs)
    halo = 0
    if options.blending == "multiband":
        halo = 64
    labels = np.load(plan.labels_path, mmap_mode="r")
    units = []
    k = plan.k
    for i, (r0, c0, h, w) in enumerate(_tiles(grid.width, grid.height, options.tile)):
        m = plan.feather_cells + 1 + (halo // k + 1)
        pr0, pc0 = max(0, r0 // k - m), max(0, c0 // k - m)
        pr1, pc1 = min(plan.height, (r0 + h - 1) // k + 1 + m), min(plan.width, (c0 + w - 1) // k + 1 + m)
        present = [int(v) for v in np.unique(labels[pr0:pr1, pc0:pc1]) if v >= 0]
        tb = (grid.x0 + c0 * grid.resolution, grid.y0 - (r0 + h) * grid.resolution,
              grid.x0 + (c0 + w) * grid.resolution, grid.y0 - r0 * grid.resolution)
        cx, cy = 0.5 * (tb[0] + tb[2]), 0.5 * (tb[1] + tb[3])
        others = [j for j, fp in enumerate(prep.footprints) if j not in present and _box_intersects(fp.bbox, tb)]
        others.sort(key=lambda j: math.hypot(prep.cameras[j].centre[0] + offset[0] - cx,
                                             prep.cameras[j].centre[1] + offset[1] - cy))
        if not present and not others:
            continue
        units.append(_TileUnit(i, r0, c0, h, w, halo, asdict(grid), dsm_path, crs, [float(v) for v in offset],
                               prep.cameras, prep.metas, prep.visibility, present, others, plan.gains,
                               plan.labels_path, k, (plan.height, plan.width), plan.feather_cells, options.blending,
                               options.interpolation, options.cache_mb))
    del labels
    n_valid = 0
    fill = 0
    try:
        workers = options.workers if options.workers and options.workers > 0 else 0
        with parallel.make_executor(workers, "auto", options.scheduler) as ex:
            for _i, res in parallel.run_units(ex, _render_tile, units, progress, label="tile"):
                writer.write(res["r0"], res["c0"], res["values"], res["valid"])
                n_valid += int(res["valid"].sum())
                fill += res["fill_cells"]
                del res
                _trim_heap()
        writer.finish(output, options.compress, None,
                      metadata={"ARCHAEOORTHO_STAGE": "orthophoto", "BLENDING": options.blending,
                                "IMAGES": len(prep.cameras), "RESOLUTION": grid.resolution})
    except BaseException:
        writer.abort()
        raise
    return n_valid, fill


_LIBC: Any = None


def _trim_heap() -> None:
    """Give freed heap memory back to the system between tiles (glibc keeps it otherwise, and the peak memory
    would creep up with the number of tiles instead of staying at one tile's worth)."""
    global _LIBC
    if _LIBC is None:
        try:
            import ctypes

            _LIBC = ctypes.CDLL("libc.so.6")
            _LIBC.malloc_trim.argtypes = [ctypes.c_size_t]
        except (OSError, AttributeError):
            _LIBC = False
    if _LIBC:
        _LIBC.malloc_trim(0)


def _write_sources_gpkg(path: str, labels: np.ndarray, prep: _Prepared, plan: _Plan, crs: Optional[str]) -> str:
    """Polygons of the image each part of the mosaic comes from (the seamlines are their borders)."""
    gdal = _gdal()
    from osgeo import ogr, osr

    ogr.UseExceptions()
    grid = prep.grid
    p = plan.k * grid.resolution
    mem = gdal.GetDriverByName("MEM").Create("", plan.width, plan.height, 1, gdal.GDT_Int32)
    mem.SetGeoTransform((grid.x0, p, 0.0, grid.y0, 0.0, -p))
    band = mem.GetRasterBand(1)
    band.WriteArray(labels.astype(np.int32))
    band.SetNoDataValue(-1)
    srs = None
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    with atomic_output(path) as tmp:
        ds = ogr.GetDriverByName("GPKG").CreateDataSource(tmp)
        lyr = ds.CreateLayer("mosaic_sources", srs, ogr.wkbPolygon)
        lyr.CreateField(ogr.FieldDefn("label", ogr.OFTInteger))
        gdal.Polygonize(band, band.GetMaskBand(), lyr, 0, [], callback=None)
        lyr.CreateField(ogr.FieldDefn("image", ogr.OFTString))
        lyr.CreateField(ogr.FieldDefn("camera_id", ogr.OFTInteger))
        lyr.CreateField(ogr.FieldDefn("gain", ogr.OFTReal))
        lyr.StartTransaction()
        for f in lyr:
            i = f.GetField("label")
            if i is not None and 0 <= i < len(prep.cameras):
                f.SetField("image", prep.cameras[i].name)
                f.SetField("camera_id", prep.cameras[i].camera_id)
                f.SetField("gain", plan.gains[i])
                lyr.SetFeature(f)
        lyr.CommitTransaction()
        ds = None
    return path


# ---------------------------------------------------------------------------
# the workspace stage
# ---------------------------------------------------------------------------

@dataclass
class OrthoStageResult:
    workspace: str
    orthomosaic: str
    crs: Optional[str]
    resolution: float
    images: List[str]
    valid_fraction: float
    per_image_folder: Optional[str]
    seamlines: Optional[str]
    timings: Dict[str, float]
    warnings: List[str]
    log_lines: List[str]


def workspace_dsm(ws: Workspace) -> Optional[str]:
    """The workspace's DSM: the DSM stage's output if recorded, else <workspace>/dsm.tif; None if absent."""
    rec = ws.stage("dsm")
    out = (rec.get("outputs") or {}).get("dsm")
    if out:
        p = out if os.path.isabs(out) else ws.path(out)
        if os.path.isfile(p):
            return p
    p = ws.path("dsm.tif")
    return p if os.path.isfile(p) else None


def build_orthophoto_workspace(workspace_dir: str, dsm_path: Optional[str] = None, images_filter: Optional[str] = None,
                               resolution: float = 0.0, blending: str = "feather", output: Optional[str] = None,
                               per_image_folder: Optional[str] = None, seamlines: Optional[str] = None,
                               options: Optional[OrthoOptions] = None,
                               progress: Optional[Progress] = None) -> OrthoStageResult:
    """The orthophoto stage of a georeferenced workspace: orthomosaic (default <workspace>/orthomosaic.tif),
    optional per-image true orthophotos and the which-image layer.  Records the stage in workspace.json.

    Raises OrthoError (bad input), WorkspaceError, Cancelled."""
    import pycolmap

    progress = progress or NullProgress()
    options = options or OrthoOptions()
    options.resolution = float(resolution or 0.0)
    options.blending = (blending or options.blending).lower()
    options.check()
    ws = Workspace.open(workspace_dir)
    if not ws.stage_done("georeference") or not os.path.isdir(ws.path("georef", "model")):
        state = ws.stage("georeference").get("status", "pending")
        raise OrthoError(f"workspace {ws.root} is not georeferenced (georeference stage: {state}): run "
                         "'Georeference' first; an orthophoto needs the images in a map CRS")
    dsm_path = os.path.abspath(dsm_path) if dsm_path else workspace_dsm(ws)
    if not dsm_path:
        raise OrthoError(f"workspace {ws.root} has no DSM: run 'Build DSM' first or give a DSM raster")
    if not os.path.isfile(dsm_path):
        raise OrthoError(f"DSM {dsm_path} does not exist")
    rec = pycolmap.Reconstruction()
    rec.read_binary(ws.path("georef", "model"))
    with open(ws.path("georef", "transform.json"), encoding="utf-8") as f:
        transform = json.load(f)
    offset = np.asarray(transform.get("offset", [0.0, 0.0, 0.0]), dtype=float)
    crs = transform.get("crs") or ws.crs
    images_dir = ws.data.get("images_dir") or ""
    cams = cameras_from_reconstruction(rec, images_dir, ws.path("masks"))
    if not cams:
        raise OrthoError(f"the model of {ws.root} has no oriented image")
    cams = select_cameras(cams, images_filter, ws.data.get("camera_groups", []))
    output = os.path.abspath(output) if output else ws.path("orthomosaic.tif")
    per_image_folder = os.path.abspath(per_image_folder) if per_image_folder else None
    seamlines = os.path.abspath(seamlines) if seamlines else None
    params = {"dsm": dsm_path, "images_filter": images_filter or "", "resolution": options.resolution,
              "blending": options.blending, "output": output, "per_image_folder": per_image_folder,
              "seamlines": seamlines, "options": {k: v for k, v in asdict(options).items()
                                                  if k not in ("workers", "scheduler", "cache_mb")}}
    inputs = {"dsm": file_fingerprint(dsm_path), "images": fingerprint(sorted(c.name for c in cams))}
    model_dir = ws.path("georef", "model")
    for n in sorted(os.listdir(model_dir)):
        if n.endswith(".bin"):
            inputs["model/" + n] = file_fingerprint(os.path.join(model_dir, n))
    ws.begin_stage(STAGE, params, inputs)
    try:
        result = build_orthomosaic(cams, dsm_path, crs, offset, output, options, per_image_folder, seamlines, progress)
        for k_, v in result.timings.items():
            if k_ != "total":
                ws.record_timing(STAGE, k_, v)
        outputs = {"orthomosaic": _rel(ws, output)}
        if per_image_folder:
            outputs["per_image_folder"] = _rel(ws, per_image_folder)
        if seamlines:
            outputs["seamlines"] = _rel(ws, seamlines)
        ws.end_stage(STAGE, DONE, outputs=outputs, results={
            "resolution": result.resolution, "gsd": result.gsd, "width": result.width, "height": result.height,
            "images": len(result.images), "valid_fraction": result.valid_fraction, "warnings": result.warnings})
        ws.invalidate_after(STAGE)
        return OrthoStageResult(ws.root, output, crs, result.resolution, result.images, result.valid_fraction,
                                per_image_folder, seamlines, result.timings, result.warnings, result.log_lines)
    except Cancelled:
        ws.end_stage(STAGE, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        ws.end_stage(STAGE, FAILED, error=str(e))
        raise


def _rel(ws: Workspace, path: str) -> str:
    rel = os.path.relpath(path, ws.root)
    return path if rel.startswith("..") else rel


# ---------------------------------------------------------------------------
# one image on an existing DSM: space resection or known orientation; true ortho or planar rectification
# ---------------------------------------------------------------------------

MODES = ("ortho", "planar")
_ORIENTATION_KEYS = {
    "x": ("x", "easting", "e", "lon", "x_m"), "y": ("y", "northing", "n", "lat", "y_m"),
    "z": ("z", "height", "h", "alt", "altitude", "elevation", "z_m"),
    "omega": ("omega", "o", "omega_deg"), "phi": ("phi", "p", "phi_deg"), "kappa": ("kappa", "k", "kappa_deg"),
    "image": ("image", "imagename", "name", "image_name", "file", "filename", "photo"),
    "focal_mm": ("focal_mm", "focal", "f_mm", "focallength"), "sensor_width_mm": ("sensor_width_mm", "sensor_mm",
                                                                                 "sensorwidth"),
    "focal_px": ("focal_px", "f_px"), "cx": ("cx", "ppx", "cx_px"), "cy": ("cy", "ppy", "cy_px"),
    "k1": ("k1",), "k2": ("k2",), "p1": ("p1",), "p2": ("p2",), "crs": ("crs", "epsg", "srs"),
}


def _orientation_key(name: str) -> Optional[str]:
    n = name.strip().lower().replace(" ", "").replace("-", "_")
    for key, aliases in _ORIENTATION_KEYS.items():
        if n in aliases:
            return key
    return None


def _normalise_orientation(d: Dict[str, Any], source: str, exterior: bool = True) -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for k, v in d.items():
        key = _orientation_key(str(k))
        if key is None or v is None or v == "":
            continue
        if key in ("image", "crs"):
            out[key] = str(v).strip()
        else:
            try:
                out[key] = float(v)
            except (TypeError, ValueError) as e:
                raise OrthoError(f"{source}: {k} = {v!r} is not a number") from e
    missing = [k for k in ("x", "y", "z", "omega", "phi", "kappa") if k not in out]
    if missing and not exterior and len(missing) == 6 and ("focal_px" in out or "focal_mm" in out):
        return out  # interior orientation only (with GCPs: space resection with a calibrated camera)
    if missing:
        raise OrthoError(f"{source}: the orientation lacks {', '.join(missing)} (needs x, y, z, omega, phi, kappa "
                         "in degrees; optional focal_mm, sensor_width_mm, focal_px, cx, cy, k1, k2, p1, p2, crs)")
    return out


def read_orientation(path: str, image_name: Optional[str] = None, exterior: bool = True) -> Dict[str, Any]:
    """Exterior (and optionally interior) orientation of one image from a file.

    JSON: ``{"x": .., "y": .., "z": .., "omega": .., "phi": .., "kappa": .., "crs": "EPSG:..", "focal_mm": ..}``
    (or ``{"images": {name: {...}}}``).  Text: an optional CRS line (``EPSG:xxxx`` or ``# crs: ...``), a header
    row naming the columns (``imageName X Y Z Omega Phi Kappa`` as Pix4D writes it, comma or white space
    separated, more columns allowed), then one row per image; the row of ``image_name`` (case-insensitive, with
    or without extension) is taken, or the only row.  A file without header holds ``x y z omega phi kappa``
    or ``image x y z omega phi kappa``.  Angles in degrees, photogrammetric convention (see core.resection)."""
    if not os.path.isfile(path):
        raise OrthoError(f"orientation file {path} does not exist")
    with open(path, encoding="utf-8-sig") as f:
        text = f.read()
    want = (image_name or "").lower()

    def name_ok(n: str) -> bool:
        n = os.path.basename(n.replace("\\", "/")).lower()
        return bool(want) and (n == want or os.path.splitext(n)[0] == os.path.splitext(want)[0])

    if text.lstrip().startswith("{"):
        try:
            d = json.loads(text)
        except json.JSONDecodeError as e:
            raise OrthoError(f"{path}: not valid JSON ({e})") from e
        if isinstance(d.get("images"), dict):
            rows = d["images"]
            hit = [v for k, v in rows.items() if name_ok(k)]
            if not hit and len(rows) == 1:
                hit = list(rows.values())
            if not hit:
                raise OrthoError(f"{path} holds no orientation for {image_name} (images: {', '.join(list(rows)[:6])})")
            merged = {k: v for k, v in d.items() if k != "images"}
            merged.update(hit[0])
            return _normalise_orientation(merged, path, exterior)
        return _normalise_orientation(d, path, exterior)
    crs = None
    header: Optional[List[str]] = None
    rows: List[List[str]] = []
    for raw in text.splitlines():
        line = raw.strip()
        if not line:
            continue
        low = line.lower()
        if line.startswith("#"):
            body = line.lstrip("#").strip()
            if body.lower().startswith("crs:") or body.lower().startswith("crs="):
                crs = body[4:].strip()
            continue
        if low.startswith("epsg:") or low.startswith("+proj") or low.startswith("wgs84 utm"):
            crs = line
            continue
        cells = [c.strip() for c in (line.split(",") if "," in line else line.split("\t") if "\t" in line
                                     else line.split())]
        if header is None and not rows and any(_orientation_key(c) in ("x", "omega") for c in cells):
            header = cells
            continue
        rows.append(cells)
    if not rows:
        raise OrthoError(f"{path} holds no orientation row")
    parsed = []
    for cells in rows:
        if header:
            d = dict(zip(header, cells))
        elif len(cells) == 6:
            d = dict(zip(("x", "y", "z", "omega", "phi", "kappa"), cells))
        elif len(cells) >= 7:
            d = dict(zip(("image", "x", "y", "z", "omega", "phi", "kappa"), cells))
        else:
            raise OrthoError(f"{path}: a row needs x y z omega phi kappa (optionally the image name first); got "
                             f"{' '.join(cells)!r}")
        parsed.append(d)
    hit = [d for d in parsed if name_ok(str(next((v for k, v in d.items() if _orientation_key(k) == "image"), "")))]
    if not hit and len(parsed) == 1:
        hit = parsed
    if not hit:
        raise OrthoError(f"{path} holds {len(parsed)} orientations but none for {image_name}")
    d = dict(hit[0])
    if crs and "crs" not in {_orientation_key(k) for k in d}:
        d["crs"] = crs
    return _normalise_orientation(d, path, exterior)


@dataclass
class SingleImageResult:
    output: str
    mode: str
    crs: Optional[str]
    resolution: float
    valid_fraction: float
    orientation: Dict[str, float]  # x, y, z (world), omega, phi, kappa (degrees), focal_px, k1
    source: str  # "resection" or "orientation"
    rmse_px: Optional[float] = None
    residuals: List[Dict[str, Any]] = field(default_factory=list)
    outliers: List[str] = field(default_factory=list)
    estimated_intrinsics: bool = False
    planar_rmse_m: Optional[float] = None
    planar_error: Optional[Dict[str, float]] = None  # how far planar rectification is off given the DSM
    residuals_path: Optional[str] = None
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)


def _image_observations(gcps, name: str) -> List[Tuple[Any, Any]]:
    """(point, observation) pairs of the GCP set observed in image ``name`` (by name, base name, stem)."""
    base = os.path.basename(name).lower()
    stem = os.path.splitext(base)[0]
    out = []
    for p in gcps.points:
        for o in p.observations:
            ob = os.path.basename(o.image.replace("\\", "/")).lower()
            if ob == base or os.path.splitext(ob)[0] == stem:
                out.append((p, o))
                break
    return out


def _focal(meta: ImageMeta, image_path: str, focal_px, focal_mm, sensor_width_mm, orient: Optional[dict]
           ) -> Tuple[Optional[float], str]:
    long_side = max(meta.width, meta.height)
    if focal_px:
        return float(focal_px), "FOCAL_PX"
    if focal_mm and sensor_width_mm:
        return float(focal_mm) / float(sensor_width_mm) * long_side, "FOCAL_MM / SENSOR_WIDTH_MM"
    if focal_mm or sensor_width_mm:
        raise OrthoError("give both FOCAL_MM and SENSOR_WIDTH_MM (the sensor's long side in mm), or neither")
    if orient:
        if orient.get("focal_px"):
            return float(orient["focal_px"]), "orientation file"
        if orient.get("focal_mm") and orient.get("sensor_width_mm"):
            return float(orient["focal_mm"]) / float(orient["sensor_width_mm"]) * long_side, "orientation file"
    from ..io.images import ImageError, read_image_info

    try:
        info = read_image_info(image_path)
    except ImageError:
        return None, "none"
    if info.focal_source != "default" and info.focal_px:
        return float(info.focal_px), f"EXIF ({info.focal_source})"
    return None, "none"


def orthorectify_image(image_path: str, output: str, dsm_path: Optional[str] = None, gcps=None,
                       orientation=None, focal_mm: Optional[float] = None, sensor_width_mm: Optional[float] = None,
                       focal_px: Optional[float] = None, mode: str = "ortho", crs: Optional[str] = None,
                       resolution: float = 0.0, residuals_path: Optional[str] = None,
                       estimate_intrinsics="auto", mask_path: Optional[str] = None,
                       camera: Optional[Intrinsics] = None,
                       options: Optional[OrthoOptions] = None, progress: Optional[Progress] = None
                       ) -> SingleImageResult:
    """Orthorectify one image (even one outside any block) on an existing DSM.

    Orientation from ``gcps`` (a GCP file path or a core.gcp.GCPSet with observations in this image: space
    resection, >= 4 control points, >= 6 to also estimate focal length and k1) or from ``orientation`` (a file
    for :func:`read_orientation` or a dict with x, y, z, omega, phi, kappa).  ``mode`` "ortho": true orthophoto
    on the DSM (required; reprojected on the fly when in another CRS); "planar": projective rectification
    through the control points onto a plane, and, when a DSM is given, how far that is off.  ``camera``: a
    calibrated interior orientation (e.g. the block's camera), kept as it is unless ``estimate_intrinsics`` is
    True; an orientation file without x..kappa is taken as interior orientation too.  Writes a COG at
    ``output`` and optionally the GCP residuals to the GeoPackage ``residuals_path``."""
    from ..geometry import resection as rs
    from ..io import gcp as gcpmod

    progress = progress or NullProgress()
    options = options or OrthoOptions()
    options.resolution = float(resolution or 0.0)
    options.check()
    mode = (mode or "ortho").lower()
    if mode not in MODES:
        raise OrthoError(f"unknown MODE {mode!r}; choose one of {', '.join(MODES)}")
    if not image_path or not os.path.isfile(image_path):
        raise OrthoError(f"image {image_path} does not exist")
    if gcps is None and orientation is None:
        raise OrthoError("give ground control points observed in the image (GCPS) or its orientation (ORIENTATION)")
    if mode == "ortho" and not dsm_path:
        raise OrthoError("a true orthophoto needs a DSM; give DSM, or choose MODE planar for flat ground")
    if mode == "planar" and gcps is None:
        raise OrthoError("planar rectification needs at least 4 ground control points observed in the image (GCPS)")
    name = os.path.basename(image_path)
    meta = image_meta(image_path)
    warnings: List[str] = []
    log: List[str] = []

    def warn(msg: str) -> None:
        warnings.append(msg)
        progress.warning(msg)

    orient = None
    if orientation is not None:
        orient = (read_orientation(orientation, name, exterior=gcps is None) if isinstance(orientation, str)
                  else _normalise_orientation(dict(orientation), "ORIENTATION", exterior=gcps is None))
        if "omega" not in orient:  # interior orientation only
            interior = orient
            orient = None
            if camera is None:
                f_i, _src = _focal(meta, image_path, None, None, None, interior)
                camera = Intrinsics.simple(meta.width, meta.height, f_i, interior.get("cx"), interior.get("cy"),
                                           interior.get("k1", 0.0), interior.get("k2", 0.0), interior.get("p1", 0.0),
                                           interior.get("p2", 0.0))
    if isinstance(gcps, str):
        try:
            gcps = gcpmod.read_gcps(gcps)
        except gcpmod.GCPError as e:
            raise OrthoError(str(e)) from e
    # working CRS
    dsm_info = dsmmod.open_dsm(dsm_path) if dsm_path else None
    work_crs = crs or (gcps.crs if gcps is not None and gcps.crs else None) or (orient or {}).get("crs")
    if not work_crs and dsm_info is not None and dsm_info.crs_wkt:
        work_crs = dsm_info.crs_wkt
    if not work_crs:
        warn("no CRS given: coordinates are taken as they are (no CRS written)")
    # ground control observed in this image
    pairs = []
    if gcps is not None:
        for w_ in getattr(gcps, "warnings", []):
            warn(w_)
        pairs = _image_observations(gcps, name)
        if gcps.crs and work_crs and not _crs_equal(gcps.crs, work_crs):
            xyz = gcpmod.transform_points(np.array([[p.x, p.y, p.z] for p, _ in pairs], dtype=float).reshape(-1, 3),
                                          gcps.crs, work_crs)
        else:
            xyz = np.array([[p.x, p.y, p.z] for p, _ in pairs], dtype=float).reshape(-1, 3)
        control = [i for i, (p, _) in enumerate(pairs) if p.role == gcpmod.CONTROL]
        checks = [i for i, (p, _) in enumerate(pairs) if p.role != gcpmod.CONTROL]
        need = rs.MIN_RESECTION_POINTS if orient is None else 0
        if len(control) < need:
            images = ", ".join(gcps.image_names()[:6]) if hasattr(gcps, "image_names") else ""
            raise OrthoError(
                f"space resection needs at least {rs.MIN_RESECTION_POINTS} ground control points observed in {name} "
                f"({rs.MIN_INTRINSICS_POINTS} to also estimate the focal length and k1); found {len(control)}"
                + (f" (and {len(checks)} check points, which are not used)" if checks else "")
                + (f". The control file names the images {images}" if not pairs and images else ""))
        px_all = np.array([[o.x, o.y] for _, o in pairs], dtype=float).reshape(-1, 2)
        outside = [pairs[i][0].name for i in range(len(pairs))
                   if not (0 <= px_all[i, 0] <= meta.width and 0 <= px_all[i, 1] <= meta.height)]
        if outside:
            warn(f"GCP observation(s) outside the {meta.width} x {meta.height} image {name}: {', '.join(outside)}")
    # local frame
    if orient is not None:
        c_world = np.array([orient["x"], orient["y"], orient["z"]], dtype=float)
        ocrs = orient.get("crs")
        if ocrs and work_crs and not _crs_equal(ocrs, work_crs):
            c_world = gcpmod.transform_points(c_world[None], ocrs, work_crs)[0]
        offset = np.array([round(c_world[0]), round(c_world[1]), 0.0])
    else:
        offset = np.array([round(float(np.mean(xyz[control, 0]))), round(float(np.mean(xyz[control, 1]))), 0.0])
    # interior orientation
    if camera is not None:
        if (camera.width, camera.height) != (meta.width, meta.height):
            raise OrthoError(f"the camera model is {camera.width} x {camera.height} pixels but {name} is "
                             f"{meta.width} x {meta.height}")
        f_px, f_source = camera.focal, "calibrated camera"
        if estimate_intrinsics == "auto":
            estimate_intrinsics = False
    else:
        f_px, f_source = _focal(meta, image_path, focal_px, focal_mm, sensor_width_mm, orient)
    n_control = len(control) if gcps is not None else 0
    if f_px is None:
        if orient is None and n_control >= rs.MIN_INTRINSICS_POINTS:
            f_px = 1.2 * max(meta.width, meta.height)
            estimate_intrinsics = True
            warn(f"the focal length of {name} is unknown (no EXIF, none given): it is estimated from the "
                 f"{n_control} control points")
        else:
            raise OrthoError(
                f"the focal length of {name} is unknown (no EXIF focal length): give FOCAL_MM and SENSOR_WIDTH_MM "
                f"(or a focal length in the orientation file), or at least {rs.MIN_INTRINSICS_POINTS} GCPs to "
                "estimate it")
    o = orient or {}
    cam0 = camera.as_opencv() if camera is not None else rs.Intrinsics.simple(
        meta.width, meta.height, f_px, o.get("cx"), o.get("cy"), o.get("k1", 0.0), o.get("k2", 0.0),
        o.get("p1", 0.0), o.get("p2", 0.0))
    log.append(f"{name}: {meta.width} x {meta.height} px, {meta.bands} band(s) {meta.dtype}, focal {f_px:.1f} px "
               f"({f_source})")
    # exterior orientation
    residuals: List[Dict[str, Any]] = []
    rmse = None
    outliers: List[str] = []
    estimated = False
    if orient is not None:
        rot = rotation_from_opk(orient["omega"], orient["phi"], orient["kappa"])
        pose = rs.Pose.from_centre(rot, c_world - offset)
        cam = cam0
        source = "orientation"
        if pairs:
            proj, ok = rs.project_points(pose, cam, xyz - offset)
            for i, (p, ob) in enumerate(pairs):
                residuals.append(_residual_row(p, ob, name, xyz[i], proj[i], True, "check (orientation given)"))
            r = np.array([row["res_px"] for row in residuals])
            rmse = float(np.sqrt(np.mean(r ** 2)))
    else:
        try:
            res = rs.space_resection(xyz[control] - offset, px_all[control], cam0,
                                     names=[pairs[i][0].name for i in control],
                                     estimate_intrinsics=estimate_intrinsics, image=name)
        except rs.ResectionError as e:
            raise OrthoError(str(e)) from e
        pose, cam, estimated, rmse = res.pose, res.camera, res.estimated_intrinsics, res.rmse_px
        outliers = res.outliers
        for w_ in res.warnings:
            warn(w_)
        source = "resection"
        proj, ok = rs.project_points(pose, cam, xyz - offset)
        used = {r.name: r.used for r in res.residuals}
        for i, (p, ob) in enumerate(pairs):
            role = "control" if i in control else "check"
            residuals.append(_residual_row(p, ob, name, xyz[i], proj[i], used.get(p.name, False) if i in control
                                           else False, role if used.get(p.name, True) else "outlier"))
        chk = [row["res_px"] for row in residuals if row["role"] == "check"]
        log.append(f"space resection from {res.n_used} of {len(control)} control points: RMSE {rmse:.2f} px"
                   + (f", check points RMSE {float(np.sqrt(np.mean(np.square(chk)))):.2f} px ({len(chk)})" if chk else "")
                   + (f"; estimated {' and '.join(res.estimated_params)}: focal length {cam.focal:.1f} px, k1 "
                      f"{cam.dist[0]:+.4f}" if estimated else "")
                   + (f"; left out: {', '.join(outliers)}" if outliers else ""))
        progress.info(log[-1])
    centre_w = pose.centre + offset
    om, ph, ka = opk_from_rotation(pose.rotation)
    orientation_out = {"x": float(centre_w[0]), "y": float(centre_w[1]), "z": float(centre_w[2]), "omega": om,
                       "phi": ph, "kappa": ka, "focal_px": float(cam.focal), "k1": float(cam.dist[0])}
    log.append(f"camera at X {centre_w[0]:.2f} Y {centre_w[1]:.2f} Z {centre_w[2]:.2f}, omega {om:.3f} phi {ph:.3f} "
               f"kappa {ka:.3f} deg")
    progress.info(log[-1])
    progress.report(0.1, "oriented")
    ocam = OrthoCamera(name, os.path.abspath(image_path), cam, pose, 0, mask_path)
    out_dir = os.path.dirname(os.path.abspath(output))
    os.makedirs(out_dir, exist_ok=True)
    workdir = tempfile.mkdtemp(prefix=".ortho-work-", dir=out_dir)
    _CACHE.max_bytes = options.cache_mb << 20
    dsm = _Dsm(dsm_path, work_crs) if dsm_path else None
    result = SingleImageResult(output, mode, work_crs, 0.0, 0.0, orientation_out, source, rmse, residuals, outliers,
                               estimated, warnings=warnings, log_lines=log)
    try:
        with _gdal_cache(64):
            if dsm is not None and dsm.reprojected:
                log.append(f"DSM {dsm_path} reprojected on the fly into the working CRS")
                progress.info(log[-1])
            if mode == "ortho":
                prep = prepare_block([ocam], dsm, offset, options.resolution, workdir, options.occlusion,
                                     options.height_tolerance, SubProgress(progress, 0.1, 0.3))
                for w_ in prep.warnings:
                    warn(w_)
                info = write_camera_ortho(ocam, prep.metas[0], prep.visibility[0], prep.footprints[0], dsm, offset,
                                          prep.grid, work_crs, output, options, SubProgress(progress, 0.3, 1.0))
                if info is None:
                    raise OrthoError(f"the DSM does not cover the ground seen by {name}")
                result.resolution = prep.grid.resolution
                result.valid_fraction = info["valid_fraction"]
                if info["valid_fraction"] == 0.0:
                    raise OrthoError(f"no cell of the orthophoto of {name} has data: the DSM has no valid height "
                                     "where the image looks")
            else:
                _planar(result, ocam, meta, pairs, control, xyz, px_all, offset, dsm, options, output, warn,
                        SubProgress(progress, 0.1, 1.0))
        log.append(f"{mode} orthophoto {output}: {result.resolution:g} per cell, "
                   f"{100 * result.valid_fraction:.1f} % of its cells with data")
        progress.info(log[-1])
        if residuals_path and residuals:
            from ..io.vector import write_points_gpkg

            fields = [("name", "str"), ("role", "str"), ("image", "str"), ("px", "float"), ("py", "float"),
                      ("dx_px", "float"), ("dy_px", "float"), ("res_px", "float"), ("used", "int"),
                      ("dx_m", "float"), ("dy_m", "float"), ("res_m", "float")]
            write_points_gpkg(residuals_path, "gcp_residuals", residuals, fields, work_crs)
            result.residuals_path = residuals_path
        progress.report(1.0, "done")
        return result
    finally:
        if dsm is not None:
            dsm.close()
        _CACHE.clear()
        shutil.rmtree(workdir, ignore_errors=True)


def _crs_equal(a: str, b: str) -> bool:
    from osgeo import osr

    sa, sb = osr.SpatialReference(), osr.SpatialReference()
    try:
        sa.SetFromUserInput(a)
        sb.SetFromUserInput(b)
    except RuntimeError:
        return a == b
    return bool(sa.IsSame(sb))


def _residual_row(p, ob, image: str, xyz_w, proj, used: bool, role: str) -> Dict[str, Any]:
    dx, dy = float(proj[0] - ob.x), float(proj[1] - ob.y)
    return {"name": p.name, "role": role, "image": image, "px": float(ob.x), "py": float(ob.y), "dx_px": dx,
            "dy_px": dy, "res_px": math.hypot(dx, dy), "used": int(bool(used)), "x": float(xyz_w[0]),
            "y": float(xyz_w[1]), "z": float(xyz_w[2])}


def _planar(result: SingleImageResult, ocam: OrthoCamera, meta: ImageMeta, pairs, control, xyz, px_all,
            offset: np.ndarray, dsm: Optional[_Dsm], options: OrthoOptions, output: str, warn, progress: Progress
            ) -> None:
    """Projective rectification through the control points; with a DSM, how far it is off from the truth."""
    from ..geometry import resection as rs

    cam = ocam.camera
    name = ocam.name

    def undist_px(px):
        xn = cam.unproject(px)
        return np.stack([cam.fx * xn[..., 0] + cam.cx, cam.fy * xn[..., 1] + cam.cy], axis=-1)

    try:
        hom = rs.fit_homography(undist_px(px_all[control]), (xyz[control, :2] - offset[:2]),
                                [pairs[i][0].name for i in control], image=name)
    except rs.ResectionError as e:
        raise OrthoError(str(e)) from e
    for w_ in hom.warnings:
        warn(w_)
    result.planar_rmse_m = hom.rmse_m
    by_name = {r.name: r for r in hom.residuals}
    for row in result.residuals:
        r = by_name.get(row["name"])
        if r is not None:
            row["dx_m"], row["dy_m"], row["res_m"] = r.dx, r.dy, r.residual
    # which side of the horizon the image is on: the sign of w at the image centre
    hmat = hom.matrix
    w_c = (hmat @ np.array([cam.cx, cam.cy, 1.0]))[2]
    t = np.linspace(0.0, 1.0, 33)
    border = np.concatenate([np.column_stack([t * cam.width, np.zeros_like(t)]),
                             np.column_stack([np.full_like(t, cam.width), t * cam.height]),
                             np.column_stack([(1 - t) * cam.width, np.full_like(t, cam.height)]),
                             np.column_stack([np.zeros_like(t), (1 - t) * cam.height])])
    ub = undist_px(border)
    wb = np.column_stack([ub, np.ones(len(ub))]) @ hmat.T
    if np.any(wb[:, 2] * w_c <= 0):
        raise OrthoError(f"the plane through the control points reaches the horizon in {name}: planar "
                         "rectification of an oblique view this steep has no bounded result; use MODE ortho")
    corners = wb[:, :2] / wb[:, 2:3] + offset[:2]
    jac_d = 1.0
    c0 = hom.world_from_pixel(np.array([[cam.cx, cam.cy], [cam.cx + jac_d, cam.cy], [cam.cx, cam.cy + jac_d]]))
    gsd = math.sqrt(abs(np.cross(c0[1] - c0[0], c0[2] - c0[0])))
    res = options.resolution if options.resolution > 0 else _nice(gsd)
    grid = dsmmod.Grid.covering(float(corners[:, 0].min()), float(corners[:, 1].min()), float(corners[:, 0].max()),
                                float(corners[:, 1].max()), res)
    if grid.width * grid.height > 400_000_000:
        raise OrthoError(f"a {grid.width} x {grid.height} planar rectification at {res:g} is too large")
    work = os.path.join(os.path.dirname(os.path.abspath(output)), ".work-" + os.path.basename(output))
    writer = _RasterWriter(work, grid.width, grid.height, meta.bands, meta.dtype, grid.geotransform, result.crs)
    n_valid = 0
    try:
        tiles = _tiles(grid.width, grid.height, options.tile)
        for k, (r0, c0_, h, w) in enumerate(tiles):
            check_cancel(progress)
            x, y = _cell_centres(grid, r0, c0_, h, w)
            pu = hom.pixel_from_world(np.column_stack([x - offset[0], y - offset[1]]))
            xn = np.column_stack([(pu[:, 0] - cam.cx) / cam.fx, (pu[:, 1] - cam.cy) / cam.fy])
            ok = cam.valid_normalized(xn)
            xd = cam.distort(xn)
            px = np.column_stack([cam.fx * xd[:, 0] + cam.cx, cam.fy * xd[:, 1] + cam.cy])
            ok &= cam.inside(px) & np.all(np.isfinite(px), axis=1)
            vals = np.zeros((len(x), meta.bands), dtype=np.float32)
            if ok.any():
                idx = np.flatnonzero(ok)
                u, v = px[idx, 0] - 0.5, px[idx, 1] - 0.5
                xa, ya = max(0, int(u.min()) - 3), max(0, int(v.min()) - 3)
                xb, yb = min(meta.width, int(u.max()) + 4), min(meta.height, int(v.max()) + 4)
                win = _image_window(ocam.path, meta, xa, ya, xb, yb)
                vals[idx] = _remap(win, u - xa, v - ya, options.interpolation)
                mask = _mask(ocam.mask_path)
                if mask is not None:
                    ok[idx] &= mask[np.clip(px[idx, 1].astype(int), 0, mask.shape[0] - 1),
                                    np.clip(px[idx, 0].astype(int), 0, mask.shape[1] - 1)] >= 128
            writer.write(r0, c0_, vals.reshape(h, w, -1), ok.reshape(h, w))
            n_valid += int(ok.sum())
            progress.report(0.8 * (k + 1) / len(tiles), f"planar rectification: tile {k + 1}/{len(tiles)}")
        writer.finish(output, options.compress, SubProgress(progress, 0.8, 0.95),
                      metadata={"ARCHAEOORTHO_STAGE": "planar rectification", "IMAGE": name})
    except BaseException:
        writer.abort()
        raise
    result.resolution = res
    result.valid_fraction = n_valid / float(grid.width * grid.height)
    log = result.log_lines
    log.append(f"planar rectification through {sum(r.used for r in hom.residuals)} control points: RMSE "
               f"{hom.rmse_m:.3f} m on the plane")
    if dsm is None:
        warn("no DSM given: how far planar rectification is off because of relief cannot be measured")
        return
    # displacement of planar rectification against the true geometry: ground (X, Y, DSM) -> image (pose) ->
    # plane (homography); the difference is where the plane puts what truly lies at (X, Y)
    n = 200
    xs = np.linspace(grid.x0, grid.x0 + grid.width * res, n)
    ys = np.linspace(grid.y0, grid.y0 - grid.height * res, n)
    gx, gy = np.meshgrid(xs, ys)
    gx, gy = gx.ravel(), gy.ravel()
    gz = dsm.sample(gx, gy)
    fin = np.isfinite(gz)
    xyz_l = np.column_stack([gx - offset[0], gy - offset[1], np.where(fin, gz, 0.0) - offset[2]])
    px, _d, ok = ocam.project(xyz_l)
    ok &= fin
    if not ok.any():
        warn("the DSM does not cover the image's ground: planar displacement not measured")
        return
    planar = hom.world_from_pixel(undist_px(px[ok]))
    d = np.hypot(planar[:, 0] - xyz_l[ok, 0], planar[:, 1] - xyz_l[ok, 1])
    relief = float(np.nanpercentile(gz[ok], 99) - np.nanpercentile(gz[ok], 1))
    result.planar_error = {"mean_m": float(d.mean()), "p95_m": float(np.percentile(d, 95)), "max_m": float(d.max()),
                           "mean_px": float(d.mean() / res), "p95_px": float(np.percentile(d, 95) / res),
                           "max_px": float(d.max() / res), "relief_m": relief, "samples": int(ok.sum())}
    pe = result.planar_error
    log.append(f"planar rectification is off by {pe['mean_m']:.2f} m on average, {pe['p95_m']:.2f} m at the 95th "
               f"percentile and {pe['max_m']:.2f} m at most ({pe['p95_px']:.1f} cells at 95 %) over "
               f"{pe['relief_m']:.1f} m of relief in the DSM")
