"""The difference of two DSMs (issue 16 item 2): what changed between two epochs of one site.

``dsm_difference(a, b, output)`` writes ``b - a`` on the grid of ``a`` (its CRS, extent and cells, or its extent
at another ``resolution``): ``b`` is warped there with GDAL (bilinear, any CRS), a cell is nodata where either
has none.  The figures (cells compared, median, mean, standard deviation, 5th / 95th percentiles, cells that
changed by more than 1 m) say whether the two surfaces agree where nothing changed (the median near 0: the
epochs registered on each other) and how much changed.
"""
from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass
from typing import Any, Dict, Optional, Tuple

import numpy as np

from ..common.files import refuse_overwriting_inputs
from ..common.progress import NullProgress, Progress, check_cancel
from ..io import raster
from .options import TerrainError
from .rasters import check_elevation_kind, check_memory, check_north_up, open_raster

CHANGE_THRESHOLD = 1.0  # metres: a cell whose height changed by more than this counts as changed


@dataclass
class DsmDifference:
    path: str
    cells: int  # cells where both DSMs have a height
    median: float  # of b - a over those cells (metres; NaN when none)
    mean: float
    std: float
    p5: float
    p95: float
    changed: int  # cells with |b - a| > threshold
    threshold: float
    resolution: float  # of the difference raster, in the CRS units of a
    width: int
    height: int

    def figures(self) -> Dict[str, Any]:
        return {k: v for k, v in asdict(self).items() if k != "path"}


@dataclass
class _Raster:
    path: str
    wkt: str
    gt: Tuple[float, ...]
    width: int
    height: int
    nodata: Optional[float]

    @property
    def bounds(self) -> Tuple[float, float, float, float]:
        xs = (self.gt[0], self.gt[0] + self.width * self.gt[1])
        ys = (self.gt[3], self.gt[3] + self.height * self.gt[5])
        return min(xs), min(ys), max(xs), max(ys)


def _open(path: str, what: str) -> _Raster:
    """A DSM's grid and CRS; TerrainError naming the file when it is missing, not a raster, has no CRS or no
    north-up georeferencing."""
    with open_raster(path, what) as r:
        check_elevation_kind(r, path, what)
        gt, wkt = r.geotransform, r.crs_wkt
        if gt is None:
            raise TerrainError(f"the {what} {path} has no georeferencing (no geotransform): it cannot be compared")
        if not wkt:
            raise TerrainError(f"the {what} {path} has no CRS: assign its CRS first (Raster > Projections > "
                               "Assign Projection) so that it can be compared with the other DSM")
        check_north_up(path, what, gt)
        return _Raster(path, wkt, tuple(gt), r.width, r.height, r.nodata(1))


def _grid(a: _Raster, resolution: Optional[float]) -> Tuple[Tuple[float, ...], int, int]:
    """(geotransform, width, height) of the difference: a's grid, or a's extent at ``resolution``."""
    if not resolution:
        return a.gt, a.width, a.height
    if not (resolution > 0 and math.isfinite(resolution)):
        raise TerrainError(f"the resolution of the DSM difference must be positive, got {resolution}")
    xmin, ymin, xmax, ymax = a.bounds
    w = max(1, int(math.ceil((xmax - xmin) / resolution - 1e-9)))
    h = max(1, int(math.ceil((ymax - ymin) / resolution - 1e-9)))
    return (xmin, float(resolution), 0.0, ymax, 0.0, -float(resolution)), w, h


def _warp(r: _Raster, wkt: str, gt: Tuple[float, ...], w: int, h: int) -> np.ndarray:
    """``r`` on the grid (gt, w, h) of CRS ``wkt``, bilinear; float64 with NaN for nodata and outside."""
    from osgeo import gdal

    gdal.UseExceptions()
    with raster.RasterFile(r.path, "DSM") as src:
        if wkt == r.wkt and tuple(gt) == r.gt and (w, h) == (r.width, r.height):
            z = src.read(1).astype(np.float64)
        else:
            bounds = (gt[0], gt[3] + h * gt[5], gt[0] + w * gt[1], gt[3])
            opts = gdal.WarpOptions(format="MEM", dstSRS=wkt, outputBounds=bounds, width=w, height=h,
                                    resampleAlg="bilinear", outputType=gdal.GDT_Float32, dstNodata=float("nan"),
                                    srcNodata=r.nodata, multithread=False)
            try:
                out = gdal.Warp("", src.dataset, options=opts)
            except RuntimeError as e:
                raise TerrainError(f"cannot warp {r.path} onto the grid of the other DSM: {e}") from e
            z = out.GetRasterBand(1).ReadAsArray().astype(np.float64)
            out = None
    if r.nodata is not None:
        z[z == r.nodata] = np.nan
    z[~np.isfinite(z)] = np.nan
    return z


DIFFERENCE_BYTES_PER_CELL = 48  # two float64 grids, the difference, the mask and the float32 copy written


def dsm_difference(dsm_a: str, dsm_b: str, output: str, resolution: Optional[float] = None,
                   threshold: float = CHANGE_THRESHOLD, progress: Optional[Progress] = None) -> DsmDifference:
    """Write ``b - a`` in metres (float32 Cloud-Optimized GeoTIFF, nodata where either DSM has none; each DSM's
    heights read in their own unit, io.raster.height_unit) on the grid of
    ``dsm_a`` to ``output`` and return its figures.  ``resolution``: cells of that size over a's extent instead
    of a's own cells (both warped, bilinear).  Raises TerrainError naming the file: missing, not a raster, no
    CRS, rotated, the two not overlapping or sharing no cell with data."""
    progress = progress or NullProgress()
    a, b = _open(dsm_a, "DSM A"), _open(dsm_b, "DSM B")
    refuse_overwriting_inputs({"DSM difference": output}, {"DSM A": a.path, "DSM B": b.path}, TerrainError)
    gt, w, h = _grid(a, resolution)
    check_memory(a.path, "DSM A", w, h, bytes_per_cell=DIFFERENCE_BYTES_PER_CELL)
    # heights in metres, each from its own unit (a DSM in feet against one in metres was 22 m of "change")
    za = _warp(a, a.wkt, gt, w, h) * raster.height_unit(a.path)[1]
    progress.report(0.3, "DSM A read")
    check_cancel(progress)
    zb = _warp(b, a.wkt, gt, w, h) * raster.height_unit(b.path)[1]
    progress.report(0.6, "DSM B warped onto the grid of DSM A")
    check_cancel(progress)
    if not np.isfinite(zb).any():
        raise TerrainError(f"the DSMs do not overlap: {b.path} has no height inside the extent of {a.path} "
                           f"({', '.join(f'{v:.3f}' for v in a.bounds)} in the CRS of DSM A); are they of the same "
                           "place, and is the CRS of each right?")
    both = np.isfinite(za) & np.isfinite(zb)
    if not both.any():
        raise TerrainError(f"the DSMs {a.path} and {b.path} overlap but share no cell where both have a height")
    d = np.where(both, zb - za, np.nan)
    v = d[both]
    res = abs(gt[1])
    out = DsmDifference(os.path.abspath(output), int(v.size), float(np.median(v)), float(v.mean()), float(v.std()),
                        float(np.percentile(v, 5)), float(np.percentile(v, 95)),
                        int(np.count_nonzero(np.abs(v) > threshold)), float(threshold), res, w, h)
    meta = {"dsm_a": os.path.abspath(dsm_a), "dsm_b": os.path.abspath(dsm_b),
            **{k: f"{val:.6g}" if isinstance(val, float) else val for k, val in out.figures().items()}}
    raster.write_cog(output, d, gt, a.wkt, raster.BandLabel("DSM difference (B - A), metres", "m", metadata=meta),
                     progress)
    progress.report(1.0, "DSM difference written")
    return out


__all__ = ["CHANGE_THRESHOLD", "DsmDifference", "dsm_difference"]
