"""A spectral index of a multi-band raster, block by block: ``spectral_index(IndexOptions, progress)``.

Every check comes before any work: the raster exists and GDAL reads it, the output is not the input, the bands the
formula names exist (:mod:`.bands`: their numbers and how each was identified are listed when one is missing),
NDVI and NDRE have two distinct bands.  The raster is then read in blocks of at most ``block_cells`` cells (full
width strips of a multiple of 256 rows where a row fits, else square tiles), each band of a block as float64, so
memory stays bounded whatever the raster's size; a cell is nodata where any band used is nodata (its nodata value,
NaN), masked (an alpha band, a per-dataset mask) or where the formula's denominator is zero.  The index goes,
block by block, into a tiled temporary GeoTIFF and then into a float32 Cloud-Optimized GeoTIFF (DEFLATE, nodata
-9999, the input's CRS and geotransform, the band described by the index's name and formula), written atomically.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Dict, Iterator, Optional, Tuple

import numpy as np

from ..common.files import refuse_overwriting_inputs
from ..common.progress import NullProgress, Progress, SubProgress
from ..io import raster
from .bands import BandTable, read_band_table
from .errors import SpectralError
from .expression import Expression, parse
from .options import FORMULAS, NORMALISED, IndexOptions

NODATA = raster.NODATA
TILE = 256  # the output's (and a strip's) block side


@dataclass
class IndexResult:
    path: str
    index: str  # NDVI, NDRE, Index (an expression)
    formula: str
    bands: Dict[str, int]  # canonical band name used -> band number
    how: Dict[str, str]  # canonical band name -> how it was identified
    width: int
    height: int
    valid: int = 0  # cells with a value
    minimum: float = math.nan
    maximum: float = math.nan
    mean: float = math.nan
    log_lines: list = field(default_factory=list)


def blocks(h: int, w: int, max_cells: int) -> Iterator[Tuple[int, int, int, int]]:
    """(col, row, width, height) windows covering an h x w raster, each of at most ``max_cells`` cells: full-width
    strips (a multiple of 256 rows when 256 rows fit) where a row fits, else square tiles."""
    max_cells = max(1, int(max_cells))
    if w <= max_cells:
        rows = max(1, max_cells // w)
        if rows >= TILE:
            rows -= rows % TILE
        for r0 in range(0, h, rows):
            yield 0, r0, w, min(rows, h - r0)
        return
    side = max(1, int(math.isqrt(max_cells)))
    for r0 in range(0, h, side):
        for c0 in range(0, w, side):
            yield c0, r0, min(side, w - c0), min(side, h - r0)


def _open(path: str) -> raster.RasterFile:
    try:
        return raster.RasterFile(path, "input raster")
    except raster.RasterError as e:
        raise SpectralError(f"the spectral index cannot be made: {e}") from e


def resolve(expr: Expression, table: BandTable, options: IndexOptions) -> Dict[str, int]:
    """Canonical band name -> band number for every name of the formula; SpectralError (naming the raster, its
    bands and how each was identified) for a missing or ambiguous band, a raster with one band for NDVI / NDRE, or
    NDVI's two bands being one."""
    if options.index in FORMULAS and len(table.data_bands) < 2:
        raise SpectralError(f"{options.label} needs two bands ({' and '.join(expr.names)}), the raster {table.path} "
                            f"has {len(table.data_bands)} band(s) with data: {table.describe()}")
    used = {name: table.number(name) for name in expr.names}
    if options.index in FORMULAS and len(set(used.values())) < len(used):
        pairs = ", ".join(f"{k} = band {v}" for k, v in used.items())
        raise SpectralError(f"{options.label} of {table.path} needs distinct bands, but {pairs}: set the band numbers")
    return used


def read_block(r: raster.RasterFile, table: BandTable, used: Dict[str, int], window) -> Tuple[dict, np.ndarray]:
    """({canonical name: float64 values}, valid) of one window: valid where every band used has a finite value
    other than its nodata and no alpha band or per-dataset mask hides the cell."""
    values, valid = {}, None
    for name, n in used.items():
        v = r.read(n, window).astype(np.float64)
        ok = np.isfinite(v)
        nd = r.nodata(n)
        if nd is not None and math.isfinite(nd):
            ok &= v != nd
        mask = r.read_mask(n, window)
        if mask is not None:
            ok &= mask
        valid = ok if valid is None else valid & ok
        values[name] = v
    for n in table.alpha_bands:
        valid &= r.read(n, window) > 0
    return values, valid


class _Stats:
    def __init__(self):
        self.n, self.lo, self.hi, self.total = 0, math.inf, -math.inf, 0.0

    def add(self, v: np.ndarray) -> None:
        ok = v[np.isfinite(v)]
        if ok.size:
            self.n += int(ok.size)
            self.lo, self.hi = min(self.lo, float(ok.min())), max(self.hi, float(ok.max()))
            self.total += float(ok.sum(dtype=np.float64))


def _block_values(r: raster.RasterFile, job: Tuple[Expression, BandTable, Dict[str, int]], stats: _Stats,
                  options: IndexOptions, progress: Progress, n_blocks: int):
    """``block_values`` for core.io.raster.write_float_blocks: the index of each window of ``r`` (NaN where a band
    is nodata or masked), its statistics gathered in ``stats``."""
    expr, table, used = job
    done = [0]

    def values(r0, r1, c0, c1):
        vals, valid = read_block(r, table, used, (c0, r0, c1 - c0, r1 - r0))
        out = expr.evaluate(vals)
        out[~valid] = np.nan
        stats.add(out)
        done[0] += 1
        progress.report(done[0] / n_blocks, f"{options.label}: block {done[0]} of {n_blocks}")
        return out

    return values


def spectral_index(options: IndexOptions, progress: Optional[Progress] = None) -> IndexResult:
    """Write the index of ``options`` (NDVI, NDRE or an expression) of ``options.input`` to ``options.output``."""
    progress = progress or NullProgress()
    expr = parse(options.formula)
    with _open(options.input) as r:
        refuse_overwriting_inputs({"index raster": options.output}, {"input raster": options.input}, SpectralError)
        table = read_band_table(r, options.bands)
        used = resolve(expr, table, options)
        how = {name: table.bands[n - 1].how or "its number" for name, n in used.items()}
        result = IndexResult(os.path.abspath(options.output), options.label, options.formula, used, how, r.width,
                             r.height)
        description = f"{options.label} = {options.formula}"
        bands_text = ", ".join(f"{k} = band {v} ({how[k]})" for k, v in used.items())
        progress.info(f"{description} of {options.input} ({r.width} x {r.height} cells): {bands_text}")
        meta = {"ARCHAEOORTHO_PRODUCT": "spectral-index", "INDEX": options.label, "FORMULA": options.formula,
                "BANDS": bands_text, "SOURCE": os.path.abspath(options.input)}
        windows = [(r0, r0 + h, c0, c0 + w) for c0, r0, w, h in blocks(r.height, r.width, options.block_cells)]
        stats = _Stats()
        values = _block_values(r, (expr, table, used), stats, options, SubProgress(progress, 0.0, 0.7), len(windows))

        def display_range():
            lo, hi = (-1.0, 1.0) if options.index in NORMALISED else (stats.lo, stats.hi)
            return {"DISPLAY_MIN": f"{lo:.6g}", "DISPLAY_MAX": f"{hi:.6g}"}

        raster.write_float_blocks(options.output, raster.RasterFrame((r.height, r.width), r.geotransform, r.crs_wkt),
                                  raster.BandLabel(description, "", NODATA, meta), windows, values,
                                  SubProgress(progress, 0.7, 1.0), SpectralError, display_range)
    if stats.n:
        result.valid, result.minimum, result.maximum, result.mean = stats.n, stats.lo, stats.hi, stats.total / stats.n
    result.log_lines.append(f"{options.label}: {result.valid} of {r.width * r.height} cells with a value, "
                            f"{result.minimum:.4g} .. {result.maximum:.4g}, mean {result.mean:.4g} -> {options.output}")
    for line in result.log_lines:
        progress.info(line)
    return result


__all__ = ["IndexResult", "blocks", "read_block", "resolve", "spectral_index"]
