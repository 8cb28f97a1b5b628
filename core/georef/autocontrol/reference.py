"""The reference: an orthophoto raster (any CRS, any resolution, grey or colour) and a DSM/DTM raster.

The orthophoto is read through a GDAL warp onto the grid the match needs (its own CRS, any box and resolution:
averaged when coarser); the DSM is sampled bilinearly in the orthophoto's CRS (warped on the fly when it has
another one, ``core.io.raster.DsmReader``).
"""
from __future__ import annotations

import os
from typing import Tuple

import numpy as np

from ...common.errors import require
from ...geometry.crs import crs_identifier
from ...io.raster import DsmError, DsmReader
from .errors import AutoControlError


class Reference:
    """``ortho_path``, ``dsm_path``: rasters GDAL reads, north-up; the DSM's heights are in the unit of the
    orthophoto's CRS (metres)."""

    def __init__(self, ortho_path: str, dsm_path: str):
        gdal = require("osgeo.gdal", "reading the reference orthophoto")
        for what, p in (("reference orthophoto", ortho_path), ("reference DSM", dsm_path)):
            if not p or not os.path.isfile(p):
                raise AutoControlError(f"{what} {p!r} does not exist")
        try:
            ds = gdal.Open(ortho_path)
        except RuntimeError as e:
            raise AutoControlError(f"reference orthophoto {ortho_path} is not a raster GDAL can read: {e}") from e
        if ds is None or ds.RasterCount < 1:
            raise AutoControlError(f"reference orthophoto {ortho_path} is not a raster GDAL can read")
        gt = ds.GetGeoTransform(can_return_null=True)
        if gt is None:
            raise AutoControlError(f"reference orthophoto {ortho_path} has no georeferencing (geotransform)")
        if gt[2] != 0 or gt[4] != 0:
            raise AutoControlError(f"reference orthophoto {ortho_path} is rotated (geotransform {gt}): warp it "
                                   "north-up first")
        self.crs_wkt = ds.GetProjection() or ""
        if not self.crs_wkt:
            raise AutoControlError(f"reference orthophoto {ortho_path} has no CRS")
        self.ortho_path, self.dsm_path = ortho_path, dsm_path
        self.geotransform = tuple(gt)
        self.gsd = float(abs(gt[1]))
        w, h = ds.RasterXSize, ds.RasterYSize
        xs, ys = (gt[0], gt[0] + w * gt[1]), (gt[3], gt[3] + h * gt[5])
        self.bounds = (min(xs), min(ys), max(xs), max(ys))
        self.n_bands = ds.RasterCount
        self._gdal = gdal
        self._ds = ds
        try:
            self.dsm = DsmReader(dsm_path, self.crs_wkt)
        except DsmError as e:
            raise AutoControlError(f"reference DSM {dsm_path}: {e}") from e
        self.dsm_gsd = float(abs(self.dsm.geotransform[1]))

    @property
    def crs(self) -> str:
        """'EPSG:n' when the CRS has an EPSG code, else its WKT (a national CRS without one is as good)."""
        return crs_identifier(self.crs_wkt)

    def grey(self, box: Tuple[float, float, float, float], res: float
             ) -> Tuple[np.ndarray, np.ndarray, Tuple[float, ...]]:
        """(grey uint8 image, valid mask, geotransform) of the orthophoto over ``box`` (xmin, ymin, xmax, ymax)
        at ``res`` per pixel (a box beyond the raster gives invalid pixels there)."""
        xmin, ymin, xmax, ymax = box
        w = max(1, int(round((xmax - xmin) / res)))
        h = max(1, int(round((ymax - ymin) / res)))
        alg = "average" if res > 1.2 * self.gsd else "bilinear"
        out = self._gdal.Warp("", self._ds, format="MEM", outputBounds=(xmin, ymax - h * res, xmin + w * res, ymax),
                              width=w, height=h, resampleAlg=alg, dstAlpha=True)
        if out is None:
            raise AutoControlError(f"reference orthophoto {self.ortho_path}: cannot resample it to {res:g} per pixel")
        bands = [out.GetRasterBand(k + 1).ReadAsArray().astype(np.float32) for k in range(out.RasterCount)]
        valid = bands[-1] > 0
        colour = bands[:-1]
        if len(colour) >= 3:
            grey = 0.299 * colour[0] + 0.587 * colour[1] + 0.114 * colour[2]
        else:
            grey = colour[0]
        if grey.dtype != np.uint8 and float(np.nanmax(grey[valid], initial=0.0)) > 255.0:
            lo, hi = np.percentile(grey[valid], [0.5, 99.5]) if valid.any() else (0.0, 1.0)
            grey = (grey - lo) * (255.0 / max(hi - lo, 1e-6))
        grey = np.clip(np.where(valid, grey, 0.0), 0, 255).astype(np.uint8)
        return grey, valid, (xmin, res, 0.0, ymax, 0.0, -res)

    def heights(self, x, y) -> np.ndarray:
        """DSM heights (NaN outside / nodata) at points of the orthophoto's CRS."""
        return self.dsm.sample(x, y)

    def relief(self, x, y, radius: float) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(height, slope, misfit) around each point: a plane through the 3 x 3 DSM samples ``radius`` apart
        gives the height at the centre and the slope; misfit is the samples' largest distance from the plane."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        d = np.array([-1.0, 0.0, 1.0]) * radius
        du, dv = np.meshgrid(d, d)
        du, dv = du.ravel(), dv.ravel()
        z = self.heights(x[:, None] + du[None], y[:, None] + dv[None])  # (N, 9)
        a = np.column_stack([np.ones(9), du, dv])
        coef, *_ = np.linalg.lstsq(a, np.nan_to_num(z).T, rcond=None)  # (3, N)
        fit = (a @ coef).T
        misfit = np.max(np.abs(z - fit), axis=1)
        misfit[~np.all(np.isfinite(z), axis=1)] = np.inf
        slope = np.hypot(coef[1], coef[2])
        return coef[0], slope, misfit

    def close(self) -> None:
        self.dsm.close()
        self._ds = None


__all__ = ["Reference"]
