"""Reading an elevation raster for the terrain products (checked: projected CRS, data, size) and writing them."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ..common.parallel import available_memory
from ..io import raster
from .options import TILE_CELLS, TerrainError

MIN_CELLS = 16  # the smallest raster side the filters work on
# bytes of memory per cell the terrain products need at their peak: Build DTM holds its masks, labels and the
# DTM whole (about 12 bytes a cell; the heights are read and processed by tiles), plus tiles and GDAL's cache
# (issue 33: 6.0 GiB before for a 7,220 x 6,052 DSM, 160 bytes a cell); a raster that needs more than is
# available is refused
PEAK_BYTES_PER_CELL = 24


@dataclass
class Elevation:
    path: str
    z: Optional[np.ndarray]  # float64, NaN = nodata, in metres; None: read by windows (:meth:`read`)
    geotransform: Tuple[float, ...]
    crs_wkt: str
    cell: float  # metres
    unit: float  # metres per height unit (io.raster.height_unit: the heights are scaled by it, and back on writing)
    size: Tuple[int, int] = (0, 0)  # rows, columns

    @property
    def shape(self) -> Tuple[int, int]:
        return self.z.shape if self.z is not None else self.size

    def read(self, r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        """Rows r0:r1, columns c0:c1 as float64 metres (NaN = nodata), from memory or from the file."""
        if self.z is not None:
            return np.array(self.z[r0:r1, c0:c1], dtype=np.float64)
        with raster.RasterFile(self.path, "elevation raster") as r:
            z = r.read(1, (c0, r0, c1 - c0, r1 - r0)).astype(np.float64)
            nd = r.nodata(1)
        if nd is not None:
            z[z == nd] = np.nan
        z[~np.isfinite(z)] = np.nan
        return z * self.unit if self.unit != 1.0 else z


def open_raster(path: str, what: str) -> raster.RasterFile:
    """``path`` opened (:class:`core.io.raster.RasterFile`); TerrainError naming the file (as the ``what`` it was
    given as) when it is missing, not a raster GDAL can read, or has no band."""
    try:
        return raster.RasterFile(path, f"the {what}")
    except raster.RasterError as e:
        raise TerrainError(str(e)) from e


def check_north_up(path: str, what: str, gt) -> None:
    """TerrainError naming the file when its geotransform ``gt`` is rotated."""
    if gt[2] or gt[4]:
        raise TerrainError(f"the {what} {path} is rotated (geotransform {gt}): warp it to a north-up grid first")


def check_elevation_kind(r: raster.RasterFile, path: str, what: str) -> None:
    """TerrainError naming the file and what it holds when the raster is of a kind that cannot be heights
    (core.io.raster.not_heights, the one check every reader of heights makes): an image (the orthomosaic given as
    a DSM) or one of the plugin's own non-elevation products (a DSM/DTM source raster, a relief visualisation)."""
    raster.check_heights(r.dataset, f"the {what} {path}", TerrainError)


def check_memory(path: str, what: str, w: int, h: int, bytes_per_cell: int = PEAK_BYTES_PER_CELL) -> None:
    """TerrainError before any reading when a raster of w x h cells needs more memory than is available (issue 36
    item 11: a 60,000 x 60,000 sparse DSM ended in a MemoryError after allocating gigabytes)."""
    need = float(w) * float(h) * bytes_per_cell
    avail = available_memory()
    if avail is not None and need > avail:
        raise TerrainError(f"the {what} {path} is {w} x {h} cells: its terrain products need about "
                           f"{need / 2 ** 30:.1f} GiB of memory, {avail / 2 ** 30:.1f} GiB is available; resample "
                           "it to a coarser cell (Raster > Projections > Warp) or clip it to the area of interest "
                           "first")


def read_elevation(path: str, what: str = "DSM", whole: bool = True,
                   bytes_per_cell: int = PEAK_BYTES_PER_CELL) -> Elevation:
    """The whole raster ``path`` (band 1) as metres; TerrainError naming the file for a raster that cannot be a
    terrain model: unreadable, geographic CRS (degrees), rotated or non-square cells, too small, no data.
    ``whole`` False: the checks on the file only, the heights read by windows later (:meth:`Elevation.read`;
    the caller checks the data with :func:`check_data`)."""
    from osgeo import osr

    with open_raster(path, what) as r:
        check_elevation_kind(r, path, what)
        gt = r.geotransform or (0.0, 1.0, 0.0, 0.0, 0.0, 1.0)  # GDAL's default for a raster with none
        wkt = r.crs_wkt
        xy_unit = 1.0
        if wkt:
            srs = osr.SpatialReference(wkt=wkt)
            if srs.IsGeographic():
                raise TerrainError(f"the {what} {path} is in a geographic CRS ({srs.GetName()}, cells in degrees): "
                                   "a terrain model needs metres; reproject it to a projected CRS (e.g. its UTM "
                                   "zone) with Raster > Projections > Warp first")
            xy_unit = float(srs.GetLinearUnits() or 1.0)
        unit = raster.height_unit(path)[1]  # the heights' own unit: the band's, a vertical CRS's, else the axes'

        check_north_up(path, what, gt)
        if abs(abs(gt[1]) - abs(gt[5])) > 1e-6 * abs(gt[1]):
            raise TerrainError(f"the {what} {path} has non-square cells ({gt[1]:g} x {abs(gt[5]):g}): resample it "
                               "to square cells first")
        w, h = r.width, r.height
        if w < MIN_CELLS or h < MIN_CELLS:
            raise TerrainError(f"the {what} {path} is {w} x {h} cells: too small for a terrain model (at least "
                               f"{MIN_CELLS} x {MIN_CELLS} cells)")
        check_memory(path, what, w, h, bytes_per_cell)
        if not whole:
            return Elevation(path, None, tuple(gt), wkt, abs(gt[1]) * xy_unit, unit, (h, w))
        z = r.read(1).astype(np.float64)
        nd = r.nodata(1)
    if nd is not None:
        z[z == nd] = np.nan
    z[~np.isfinite(z)] = np.nan
    check_data(path, what, int(np.isfinite(z).sum()), w, h)
    return Elevation(path, z * unit, tuple(gt), wkt, abs(gt[1]) * xy_unit, unit, (h, w))


def check_data(path: str, what: str, n_valid: int, w: int, h: int) -> None:
    """TerrainError naming the file when it has no data or too few cells with data for a terrain model."""
    if n_valid == 0:
        raise TerrainError(f"the {what} {path} has no data: every one of its {w} x {h} cells is nodata")
    if n_valid < MIN_CELLS * MIN_CELLS:
        raise TerrainError(f"the {what} {path} has only {n_valid} cells with data: too few for a terrain model "
                           f"(at least {MIN_CELLS * MIN_CELLS})")


def scan(elev: Elevation, what: str, tile: int = TILE_CELLS) -> Tuple[int, float, float]:
    """(cells with data, lowest, highest height in metres) of ``elev`` read tile by tile; TerrainError naming the
    file (:func:`check_data`) when it has no data or too little."""
    h, w = elev.shape
    n, lo, hi = 0, np.inf, -np.inf
    for r0, r1, c0, c1 in tiles(h, w, tile):
        z = elev.read(r0, r1, c0, c1)
        ok = np.isfinite(z)
        k = int(np.count_nonzero(ok))
        if k:
            n += k
            lo, hi = min(lo, float(z[ok].min())), max(hi, float(z[ok].max()))
    check_data(elev.path, what, n, w, h)
    return n, lo, hi


def tiles(h: int, w: int, size: int):
    """(r0, r1, c0, c1) of the tiles of ``size`` x ``size`` cells covering an h x w raster, row by row."""
    size = max(1, int(size))
    for r0 in range(0, h, size):
        for c0 in range(0, w, size):
            yield r0, min(h, r0 + size), c0, min(w, c0 + size)


def write_float_tiles(path: str, tile_values, elev: Elevation, label: raster.BandLabel, heights: bool = True,
                      tile: int = TILE_CELLS, progress=None) -> str:
    """A float32 COG on the grid of ``elev`` written tile by tile (core.io.raster.write_float_blocks):
    ``tile_values(r0, r1, c0, c1)`` gives the values (metres when ``heights``, NaN = nodata) of each tile, written
    in the grid's own unit; ``label`` (:class:`core.io.raster.BandLabel`): the band's description, nodata and the
    metadata."""
    def values(r0, r1, c0, c1):
        v = np.asarray(tile_values(r0, r1, c0, c1), dtype=np.float32)
        return v / np.float32(elev.unit) if heights and elev.unit != 1.0 else v

    frame = raster.RasterFrame(elev.shape, elev.geotransform, elev.crs_wkt)
    return raster.write_float_blocks(path, frame, label, tiles(*elev.shape, tile), values, progress, TerrainError)


def write_classes(path: str, array: np.ndarray, elev: Elevation, description: str, metadata: dict,
                  tile: int = TILE_CELLS) -> str:
    """A class raster (small integers, 0 = nodata) as a COG on the grid of ``elev`` (as core.io.raster.write_classes
    writes it: float32, nodata 0), written tile by tile."""
    def values(r0, r1, c0, c1):
        part = array[r0:r1, c0:c1]
        return np.where(part > 0, part.astype(np.float32), np.float32(np.nan))

    return write_float_tiles(path, values, elev, raster.BandLabel(description, nodata=0.0, metadata=metadata),
                             heights=False, tile=tile)


def same_grid(a: str, b: str) -> Optional[str]:
    """None when rasters ``a`` and ``b`` share size and geotransform, else what differs."""
    with raster.RasterFile(a, "raster") as da, raster.RasterFile(b, "raster") as db:
        if (da.width, da.height) != (db.width, db.height):
            return f"size {da.width} x {da.height} vs {db.width} x {db.height}"
        if not np.allclose(da.geotransform, db.geotransform):
            return f"geotransform {da.geotransform} vs {db.geotransform}"
    return None
