"""The surface: heights from a DSM in the working CRS (reprojected on the fly), and its gaps filled for
orthorectification."""
from __future__ import annotations

import math
import threading
from typing import Optional, Tuple

import numpy as np

from ..common.errors import require
from ..io import raster as dsmmod
from .options import OrthoError
from .pixels import remap_photo


class Dsm:
    """Heights from a DSM in the working CRS, in world coordinates (NaN = no height)."""

    def __init__(self, path: str, crs: Optional[str], name: Optional[str] = None):
        """``name``: the DSM the messages name (the user's, where ``path`` is a work copy, its gaps filled)."""
        name = name or path
        try:
            self.info = dsmmod.open_dsm(path)
        except dsmmod.DsmError as e:
            raise OrthoError(str(e).replace(path, name)) from e
        if crs and not self.info.crs_wkt:
            raise OrthoError(f"DSM {name} has no CRS: it cannot be placed in {crs}; assign its CRS first")
        self.path = name  # for messages
        self.file = path  # the raster read
        self.crs = crs
        self.reader = dsmmod.DsmReader(path, target_crs=crs)
        gt = self.reader.geotransform
        self.geotransform = gt
        self.res = float(min(abs(gt[1]), abs(gt[5])))
        xs = (gt[0], gt[0] + self.reader.width * gt[1])
        ys = (gt[3], gt[3] + self.reader.height * gt[5])
        self.bounds = (min(xs), min(ys), max(xs), max(ys))
        self.reprojected = bool(crs and self.info.crs_wkt and not _same_crs(self.info.crs_wkt, crs))
        self._lock = threading.Lock()  # one GDAL dataset: window reads from threads take turns

    def close(self):
        self.reader.close()

    def sample(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return self.reader.sample(x, y)

    def window(self, box: Tuple[float, float, float, float]) -> Tuple[np.ndarray, Tuple[float, ...]]:
        """Heights of the cells covering ``box`` (full resolution), with their geotransform; (0, 0) if outside."""
        with self._lock:
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
            out = remap_photo(arr32[:, :, None], fc.ravel(), fr.ravel(), "bilinear", border_nan=True)[:, 0]
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


FILL_MAX_CELLS = 120_000_000  # larger DSMs are used as they are (the fill works on the whole raster in memory)


def _cell_size_m(gt: Tuple[float, ...], srs, rows: np.ndarray, cols: np.ndarray) -> float:
    """The larger side of a DSM cell (geotransform ``gt``, CRS ``srs`` or None) in metres: the CRS's linear unit,
    or degrees at the latitude of the measured cells (the middle of ``rows``); CRS units taken as metres without a
    CRS."""
    dx, dy = abs(gt[1]), abs(gt[5])
    if srs is None:
        return max(dx, dy)
    if srs.IsGeographic():
        lat = gt[3] + (float(np.median(rows)) + 0.5) * gt[5] + (float(np.median(cols)) + 0.5) * gt[4]
        axis_m = math.radians(1.0) * srs.GetSemiMajor()  # metres per degree along a meridian (sphere)
        return max(dx * axis_m * max(math.cos(math.radians(min(89.9, abs(lat)))), 1e-6), dy * axis_m)
    return max(dx, dy) * (srs.GetLinearUnits() or 1.0)


def fill_dsm_gaps(dsm_path: str, out_path: str, max_distance: float) -> Tuple[str, int]:
    """Fill the gaps of a DSM for orthorectification: cells without a height that lie inside the convex hull of
    the measured cells and within ``max_distance`` metres of one (converted with the DSM CRS's units: degrees at the
    DSM's latitude for a geographic CRS, feet for a CRS in feet) get a height interpolated (inverse distance,
    GDAL FillNodata) from their surroundings, so that a tree crown the dense matching missed does not leave a hole
    in the orthophoto.  Beyond the measured area (a DSM that covers part of the block) nothing is invented.

    Returns (path of the DSM to use, cells filled): ``out_path`` when something was filled, else ``dsm_path``."""
    cv2 = require("cv2", "orthophotos")
    from osgeo import gdal, osr

    if not max_distance or max_distance <= 0:
        return dsm_path, 0
    with dsmmod.RasterFile(dsm_path, "DSM") as r:
        if r.width * r.height > FILL_MAX_CELLS:
            return dsm_path, 0
        z = r.read(1).astype(np.float32)
        nodata, unit = r.nodata(1), (r.band(1).GetUnitType() or "").strip()
        gt, wkt, width, height = r.geotransform or (0.0, 1.0, 0.0, 0.0, 0.0, 1.0), r.crs_wkt, r.width, r.height
    srs = osr.SpatialReference(wkt=wkt) if wkt else None
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
    max_cells = max(1.0, max_distance / _cell_size_m(gt, srs, rows, cols))
    fill_value = -9999.0
    mem = gdal.GetDriverByName("MEM").Create("", width, height, 1, gdal.GDT_Float32)
    mem.SetGeoTransform(gt)
    mem.SetProjection(wkt)
    mb = mem.GetRasterBand(1)
    mb.SetNoDataValue(fill_value)
    mb.WriteArray(np.where(valid, z, fill_value).astype(np.float32))
    # the work rasters (distance, value, mask) in memory too: with the default GTiff driver GDAL writes
    # _<pid>_1fill_*_work.tif files into the current directory while it runs
    gdal.FillNodata(mb, None, maxSearchDist=float(max_cells), smoothingIterations=0,
                    options=["TEMP_FILE_DRIVER=MEM"])
    out = mb.ReadAsArray()
    take = gaps & (out != fill_value)
    result = np.where(valid, z, np.nan).astype(np.float32)
    result[take] = out[take]
    n = int(take.sum())
    if n == 0:
        return dsm_path, 0
    # the band's unit kept: a DSM in feet on a metric grid is read in feet from the copy too (io.raster.height_unit)
    dsmmod.write_cog(out_path, result, gt, wkt or None, dsmmod.BandLabel(unit=unit))
    return out_path, n
