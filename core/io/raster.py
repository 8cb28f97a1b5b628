"""Rasters and point clouds on disk: the one raster reader (:class:`RasterFile`), the DSM's Cloud-Optimized
GeoTIFF, the DSM reader, LAS point clouds.

This is the one module that writes and reads DSMs, so the orthophoto stage reads
ours and an external one (an ALS DSM the user has) through the same helpers:
:func:`open_dsm`, :class:`DsmReader` (window reads, bilinear sampling, optional
reprojection into the workspace CRS).  :class:`Grid` is the north-up raster grid
both stages write on; turning points into heights on it is
:mod:`core.dense.grid`.

Outputs are written to a temporary name and renamed when complete
(:func:`core.project.workspace.atomic_output`).
"""
from __future__ import annotations

import datetime
import math
import os
import struct
from dataclasses import dataclass, field
from typing import Iterable, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output
from ..common.progress import NullProgress, Progress, check_cancel
from ..geometry.crs import epsg_code, linear_unit

NODATA = -9999.0


class RasterError(ArchaeoOrthoError, RuntimeError):
    """A raster cannot be opened or read; the message names the file and says why."""


class DsmError(RasterError):
    """A DSM cannot be written or read; the message says why."""


def _gdal():
    from osgeo import gdal, osr

    gdal.UseExceptions()
    osr.UseExceptions()
    return gdal, osr


class RasterFile:
    """A raster file opened with GDAL: the one place in core/ that opens rasters (DSMs, orthophotos, references,
    photos, masks, products); errors are :class:`RasterError` naming the file and what it was meant to be.

    with RasterFile(path, "reference orthophoto") as r:
        r.width, r.height, r.count, r.geotransform, r.crs_wkt, r.nodata(1)
        a = r.read(1, window=(x0, y0, w, h), out_shape=(h2, w2), resampling="average")
        rgb = r.read_bands([1, 2, 3])

    ``update=True`` opens it for writing (a product being finished).  ``dataset`` is the GDAL dataset, for the
    GDAL operations that take one (warp, translate, polygonize); nothing else should need it.
    """

    def __init__(self, path: str, what: str = "raster", update: bool = False):
        gdal, _ = _gdal()
        self.path = path
        self.what = what
        if not (os.path.isfile(path) or path.startswith("/vsi")):
            raise RasterError(f"{what} {path} does not exist")
        try:
            ds = gdal.Open(path, gdal.GA_Update if update else gdal.GA_ReadOnly)
        except RuntimeError as e:
            raise RasterError(f"{what} {path} is not a raster GDAL can read: {e}") from e
        if ds is None or ds.RasterCount < 1:
            raise RasterError(f"{what} {path} has no raster band")
        self._ds = ds
        self.width, self.height, self.count = ds.RasterXSize, ds.RasterYSize, ds.RasterCount
        self.geotransform: Optional[Tuple[float, ...]] = ds.GetGeoTransform(can_return_null=True)
        if self.geotransform is not None:
            self.geotransform = tuple(self.geotransform)
        self._crs_wkt: Optional[str] = None

    @property
    def crs_wkt(self) -> str:
        """The CRS as WKT ('' when none), read on first use: exporting it costs about a millisecond, which a
        reader of many small windows that opens the file for each would pay every time."""
        if self._crs_wkt is None:
            if self._ds is None:  # asked after close (the file as it was opened: read again)
                gdal, _ = _gdal()
                ds = gdal.Open(self.path)
                self._crs_wkt = (ds.GetProjection() if ds is not None else "") or ""
            else:
                self._crs_wkt = self._ds.GetProjection() or ""
        return self._crs_wkt

    @property
    def dataset(self):
        if self._ds is None:
            raise RasterError(f"{self.what} {self.path} is closed")
        return self._ds

    def __enter__(self) -> "RasterFile":
        return self

    def __exit__(self, *exc) -> bool:
        self.close()
        return False

    def close(self) -> None:
        if self._ds is not None:
            self._ds.FlushCache()
        self._ds = None

    def band(self, index: int = 1):
        if not 1 <= index <= self.count:
            raise RasterError(f"{self.what} {self.path} has {self.count} band(s), not band {index}")
        return self.dataset.GetRasterBand(index)

    def nodata(self, index: int = 1) -> Optional[float]:
        return self.band(index).GetNoDataValue()

    def metadata(self, index: Optional[int] = None, domain: str = "") -> dict:
        src = self.dataset if index is None else self.band(index)
        return src.GetMetadata(domain) or {}

    def require_georeferenced(self, north_up: bool = True) -> Tuple[float, ...]:
        """The geotransform; RasterError when the file has none (or is rotated, with ``north_up``)."""
        gt = self.geotransform
        if gt is None:
            raise RasterError(f"{self.what} {self.path} has no georeferencing (geotransform)")
        if north_up and (gt[2] != 0 or gt[4] != 0):
            raise RasterError(f"{self.what} {self.path} is rotated (geotransform {gt}); warp it north-up first")
        return gt

    def read(self, index: int = 1, window: Optional[Tuple[int, int, int, int]] = None,
             out_shape: Optional[Tuple[int, int]] = None, resampling: str = "nearest") -> np.ndarray:
        """Band ``index`` (or the ``window`` (col, row, width, height) of it) as an array, resampled to
        ``out_shape`` (rows, cols) when given (GDAL's overview-aware resampling: "nearest", "average", ...)."""
        gdal, _ = _gdal()
        x0, y0, w, h = window if window is not None else (0, 0, self.width, self.height)
        kw = {}
        if out_shape is not None:
            kw = {"buf_xsize": int(out_shape[1]), "buf_ysize": int(out_shape[0]),
                  "resample_alg": getattr(gdal, f"GRIORA_{resampling.capitalize()}", gdal.GRIORA_NearestNeighbour)}
        try:
            arr = self.band(index).ReadAsArray(int(x0), int(y0), int(w), int(h), **kw)
        except RuntimeError as e:
            raise RasterError(f"{self.what} {self.path}: band {index} cannot be read ({e})") from e
        if arr is None:
            raise RasterError(f"{self.what} {self.path}: band {index} cannot be read (window {window})")
        return arr

    def read_mask(self, index: int = 1, window: Optional[Tuple[int, int, int, int]] = None) -> Optional[np.ndarray]:
        """Where band ``index`` is valid by the file's own mask (a per-dataset mask: the alpha band, an internal or
        .msk mask), as a bool array of the ``window``; None when the file has no such mask (every cell valid, or
        only a nodata value, which the caller compares with the values)."""
        gdal, _ = _gdal()
        flags = self.band(index).GetMaskFlags()
        if flags & gdal.GMF_ALL_VALID or not flags & gdal.GMF_PER_DATASET:
            return None
        x0, y0, w, h = window if window is not None else (0, 0, self.width, self.height)
        try:
            arr = self.band(index).GetMaskBand().ReadAsArray(int(x0), int(y0), int(w), int(h))
        except RuntimeError as e:
            raise RasterError(f"{self.what} {self.path}: the mask of band {index} cannot be read ({e})") from e
        return np.asarray(arr) > 0

    def read_bands(self, indices: Optional[Sequence[int]] = None, window: Optional[Tuple[int, int, int, int]] = None,
                   out_shape: Optional[Tuple[int, int]] = None, resampling: str = "nearest") -> np.ndarray:
        """Several bands stacked (bands, rows, cols); every band when ``indices`` is None."""
        indices = list(indices) if indices is not None else list(range(1, self.count + 1))
        return np.stack([self.read(i, window, out_shape, resampling) for i in indices])


# ---------------------------------------------------------------------------
# does a raster hold heights
# ---------------------------------------------------------------------------

ELEVATION_PRODUCTS = ("dtm", "dsm", None)  # ARCHAEOORTHO_PRODUCT values that are heights (None: not ours)


def not_heights(ds, products: bool = True) -> str:
    """Why the GDAL dataset ``ds`` cannot hold heights ('' when it can): the one check every reader of heights
    makes (a DSM, a DTM, a reference DEM for the terrain tools, the co-registration, DEM control, the automatic
    control, the orthophoto): an image (red / green / blue / palette bands, three or more bands of bytes, a byte
    band with an alpha band: an orthophoto or a rendered map given as heights) or one of the plugin's own products
    that are not heights (the DSM's source raster, a relief visualisation, a spectral index).  A band of heights
    with an alpha (mask) band is heights.  ``products`` False: the plugin's own products are not judged (the DSM
    reader, :func:`read_dsm`, also reads the DTM's source band and the relief rasters as arrays)."""
    gdal, _ = _gdal()
    product = (ds.GetMetadata() or {}).get("ARCHAEOORTHO_PRODUCT")
    if products and product not in ELEVATION_PRODUCTS:
        return f"an ArchaeoOrtho {product} raster, not heights: give a DSM or DTM"
    names = {gdal.GCI_RedBand: "red", gdal.GCI_GreenBand: "green", gdal.GCI_BlueBand: "blue",
             gdal.GCI_AlphaBand: "alpha", gdal.GCI_PaletteIndex: "palette"}
    bands = [ds.GetRasterBand(i + 1) for i in range(ds.RasterCount)]
    interp = [names.get(b.GetColorInterpretation()) for b in bands]
    byte = bands[0].DataType == gdal.GDT_Byte
    colour = any(c in ("red", "green", "blue", "palette") for c in interp)
    if colour or (len(bands) >= 3 and byte) or (byte and "alpha" in interp):
        kinds = "/".join(c or "grey" for c in interp)
        return (f"an image, not heights: {len(bands)} band(s) of {gdal.GetDataTypeName(bands[0].DataType)} "
                f"({kinds}); an orthophoto or a rendered picture cannot be a terrain model: give a DSM or DTM (one "
                "band of heights)")
    return ""


def check_heights(ds, name: str, error=None, products: bool = True) -> None:
    """``error`` (RasterError by default) '``name`` is an image, not heights: ...' when the GDAL dataset ``ds``
    cannot hold heights (:func:`not_heights`); ``name`` names the input and its file ('the DSM /path/x.tif')."""
    why = not_heights(ds, products)
    if why:
        raise (error or RasterError)(f"{name} is {why}")


def check_heights_file(path: str, what: str, error=None) -> None:
    """:func:`check_heights` on the file ``path`` (``what`` it was given as: 'reference DEM'), before any work;
    a file that cannot be opened is left to the reader that follows (it names what is wrong with it)."""
    try:
        r = RasterFile(path, what)
    except RasterError:
        return
    with r:
        check_heights(r.dataset, f"{what} {path}", error)


def crs_to_wkt(crs: Optional[str]) -> str:
    """WKT of a CRS given as 'EPSG:xxxx', WKT or PROJ string; '' for None (local frame)."""
    if not crs:
        return ""
    _, osr = _gdal()
    srs = osr.SpatialReference()
    try:
        srs.SetFromUserInput(crs)
    except RuntimeError as e:
        raise DsmError(f"unknown CRS {crs!r}: {e}") from e
    return srs.ExportToWkt()


def crs_epsg(crs: Optional[str]) -> Tuple[Optional[int], bool]:
    """(EPSG code or None, is_geographic) of a CRS string; a CRS with no EPSG code (a national transverse
    Mercator given by its parameters) gives None, not GDAL's "Unsupported SRS"."""
    if not crs:
        return None, False
    _, osr = _gdal()
    srs = osr.SpatialReference()
    try:
        srs.SetFromUserInput(crs)
    except RuntimeError as e:
        raise DsmError(f"unknown CRS {crs!r}: {e}") from e
    return epsg_code(crs), bool(srs.IsGeographic())


_FEET = {"ft": 0.3048, "foot": 0.3048, "feet": 0.3048, "international foot": 0.3048, "ft-us": 1200.0 / 3937.0,
         "us-ft": 1200.0 / 3937.0, "ftus": 1200.0 / 3937.0, "us survey foot": 1200.0 / 3937.0,
         "foot_us": 1200.0 / 3937.0}
_METRES = {"m", "metre", "meter", "metres", "meters"}


def height_unit(path: str) -> Tuple[str, float, str]:
    """(unit name, metres per unit, where it was read) of a DSM's heights: the band's unit type when it declares
    one ('ft', 'US survey foot', 'm'), else a compound CRS's vertical unit, else the unit of a projected CRS
    whose axes are not in metres (a state plane DEM in feet), else metres ('' where nothing says: a DEM in a
    geographic or metric CRS)."""
    _, osr = _gdal()
    with RasterFile(path, "DSM") as r:
        unit = (r.band(1).GetUnitType() or "").strip()
        wkt = r.crs_wkt
    if unit:
        low = unit.lower()
        if low in _FEET:
            return unit, _FEET[low], "the band's unit"
        if low in _METRES:
            return unit, 1.0, "the band's unit"
    if wkt:
        srs = osr.SpatialReference(wkt=wkt)
        if srs.IsCompound() or srs.IsVertical():
            try:
                return "vertical CRS unit", float(srs.GetTargetLinearUnits("VERT_CS") or 1.0), "its vertical CRS"
            except RuntimeError:
                pass
        if srs.IsProjected() and abs(srs.GetLinearUnits() - 1.0) > 1e-9:
            return srs.GetLinearUnitsName() or "unit", float(srs.GetLinearUnits()), "its CRS's axes"
    return "metre", 1.0, ""


def axis_metres(crs_wkt: str) -> float:
    """Metres per unit of a CRS's horizontal axes: 1 for a metric, geographic or missing CRS (heights are
    then in metres), 0.3048... for one in feet."""
    metres = linear_unit(crs_wkt)[1] if crs_wkt else math.nan
    return metres if metres == metres and metres > 0 else 1.0


# ---------------------------------------------------------------------------
# grid
# ---------------------------------------------------------------------------

@dataclass
class Grid:
    """A north-up raster grid in world coordinates: x0, y0 = upper-left corner."""

    x0: float
    y0: float
    resolution: float
    width: int
    height: int

    @property
    def geotransform(self) -> Tuple[float, float, float, float, float, float]:
        return (self.x0, self.resolution, 0.0, self.y0, 0.0, -self.resolution)

    @classmethod
    def covering(cls, xmin: float, ymin: float, xmax: float, ymax: float, resolution: float,
                 what: str = "DSM") -> Grid:
        """The grid with cell edges on multiples of ``resolution`` that covers the box; ``what`` it is for (the
        messages name it: "DSM", "orthophoto")."""
        if not (resolution > 0 and math.isfinite(resolution)):
            raise DsmError(f"resolution must be positive, got {resolution}")
        x0 = math.floor(xmin / resolution) * resolution
        y0 = math.ceil(ymax / resolution) * resolution
        w = max(1, int(math.ceil((xmax - x0) / resolution)))
        h = max(1, int(math.ceil((y0 - ymin) / resolution)))
        if w * h > 2_000_000_000:
            raise DsmError(f"a {w} x {h} {what} at {resolution:g} per cell ({w * h / 1e9:.3g} billion cells) is too "
                           f"large: choose a coarser RESOLUTION for the {what}")
        return cls(x0, y0, resolution, w, h)

    def cell_centres(self) -> Tuple[np.ndarray, np.ndarray]:
        xs = self.x0 + (np.arange(self.width) + 0.5) * self.resolution
        ys = self.y0 - (np.arange(self.height) + 0.5) * self.resolution
        return xs, ys


# ---------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------

@dataclass
class BandLabel:
    """How a written single-band raster labels its values: the band's description, its unit type where the
    values' unit is not the CRS's (a difference in metres on a grid in feet: "m"), the nodata value NaN cells
    become, and the file's metadata items."""

    description: str = "DSM"
    unit: str = ""
    nodata: float = NODATA
    metadata: Optional[dict] = None


def write_cog(path: str, array: np.ndarray, geotransform: Sequence[float], crs: Optional[str],
              label: Optional[BandLabel] = None, progress: Optional[Progress] = None) -> str:
    """Write a single-band float32 Cloud-Optimized GeoTIFF (DEFLATE, overviews) atomically, labelled by ``label``
    (:class:`BandLabel`: a "DSM" band with nodata :data:`NODATA` by default).

    NaN cells become the label's nodata.  ``crs`` None writes no CRS (local frame).  A cancel or crash
    leaves no file at ``path`` (a previous complete file stays until the new one is complete)."""
    label = label or BandLabel()
    nodata, description, unit, metadata = label.nodata, label.description, label.unit, label.metadata
    gdal, _ = _gdal()
    progress = progress or NullProgress()
    data = np.where(np.isfinite(array), array, nodata).astype(np.float32)
    wkt = crs_to_wkt(crs)
    with atomic_output(path) as tmp:
        mem = gdal.GetDriverByName("MEM").Create("", data.shape[1], data.shape[0], 1, gdal.GDT_Float32)
        mem.SetGeoTransform(tuple(float(v) for v in geotransform))
        if wkt:
            mem.SetProjection(wkt)
        band = mem.GetRasterBand(1)
        band.SetNoDataValue(float(nodata))
        band.SetDescription(description)
        if unit:
            band.SetUnitType(unit)
        band.WriteArray(data)
        if metadata:
            mem.SetMetadata({str(k): str(v) for k, v in metadata.items()})
        check_cancel(progress)
        translate_to_cog(mem, tmp, path, progress)
        mem = None
        check_cancel(progress)
    return path


class RasterFrame(NamedTuple):
    """Where a written raster lies: (rows, cols), its geotransform (None: none) and its CRS as WKT ('' : none)."""
    shape: Tuple[int, int]
    geotransform: Optional[Sequence[float]]
    crs_wkt: str


def write_float_blocks(path: str, frame: RasterFrame, label: "BandLabel", windows: Iterable[Tuple[int, int, int, int]],
                       block_values, progress: Optional[Progress] = None, error=None, late_metadata=None) -> str:
    """A float32 COG on ``frame`` written block by block, so the raster is never whole in memory:
    ``block_values(r0, r1, c0, c1)`` gives each window's values (NaN = nodata, written as ``label.nodata``); they
    go into a temporary tiled GeoTIFF beside ``path``, then into the COG (atomically).  ``label``: the band's
    description, unit and the file's metadata; ``late_metadata()``, when given, adds items known only once every
    block is written (a display range).  A cancel is honoured between blocks; ``error`` (DsmError by default)
    names ``path`` when GDAL cannot write it."""
    gdal, _ = _gdal()
    error = error or DsmError
    progress = progress or NullProgress()
    (h, w), geotransform, crs_wkt = frame
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with atomic_output(path) as tmp:
        work = tmp + ".blocks.tif"
        ds = band = None
        try:
            try:
                ds = gdal.GetDriverByName("GTiff").Create(work, w, h, 1, gdal.GDT_Float32, [
                    "TILED=YES", "BLOCKXSIZE=256", "BLOCKYSIZE=256", "COMPRESS=DEFLATE", "ZLEVEL=1",
                    "BIGTIFF=IF_SAFER"])
            except RuntimeError as e:
                raise error(f"cannot write {path}: {e}") from e
            if geotransform is not None:
                ds.SetGeoTransform(tuple(float(v) for v in geotransform))
            if crs_wkt:
                ds.SetProjection(crs_wkt)
            band = ds.GetRasterBand(1)
            band.SetNoDataValue(float(label.nodata))
            band.SetDescription(label.description)
            if label.unit:
                band.SetUnitType(label.unit)
            metadata = {str(k): str(v) for k, v in (label.metadata or {}).items()}
            ds.SetMetadata(metadata)
            for r0, r1, c0, c1 in windows:
                values = np.asarray(block_values(r0, r1, c0, c1), dtype=np.float32)
                band.WriteArray(np.where(np.isfinite(values), values, np.float32(label.nodata)), c0, r0)
                check_cancel(progress)
            if late_metadata is not None:
                ds.SetMetadata({**metadata, **{str(k): str(v) for k, v in late_metadata().items()}})
            ds.FlushCache()
            ds = band = None
            translate_to_cog(work, tmp, path, progress, error)
        finally:
            ds = band = None
            if os.path.exists(work):
                os.remove(work)
    return path


def translate_to_cog(source, tmp: str, path: str, progress: Progress, error=None) -> None:
    """``source`` (a GDAL dataset or file) into the Cloud-Optimized GeoTIFF ``tmp`` (DEFLATE, overviews), the
    progress reported and a cancel honoured; ``error`` (DsmError by default) names ``path`` when GDAL fails."""
    gdal, _ = _gdal()
    error = error or DsmError

    def cb(fraction, _msg, _data):
        progress.report(fraction, "writing Cloud-Optimized GeoTIFF")
        return 0 if progress.is_cancelled() else 1

    opts = gdal.TranslateOptions(format="COG", creationOptions=[
        "COMPRESS=DEFLATE", "PREDICTOR=YES", "BLOCKSIZE=256", "OVERVIEWS=IGNORE_EXISTING",
        "OVERVIEW_RESAMPLING=AVERAGE", "BIGTIFF=IF_SAFER"], callback=cb)
    try:
        out = gdal.Translate(tmp, source, options=opts)
    except RuntimeError as e:
        check_cancel(progress)  # GDAL reports a user interrupt as an error
        raise error(f"cannot write {path}: {e}") from e
    if out is None:
        check_cancel(progress)
        raise error(f"cannot write {path}")
    out.FlushCache()
    out = None


# measured / interpolated: the values of the source rasters beside a DSM (dense/dsm-source.tif) or a DTM
# (terrain/dtm-source.tif); 0 = nodata
SOURCE_MEASURED = 1
SOURCE_INTERPOLATED = 2


def write_classes(path: str, array: np.ndarray, geotransform: Sequence[float], crs: Optional[str],
                  description: str, metadata: Optional[dict] = None) -> str:
    """A class raster (small integers, 0 = nodata, e.g. SOURCE_MEASURED / SOURCE_INTERPOLATED) as a COG on the
    grid ``geotransform``, written atomically like :func:`write_cog`."""
    data = np.where(array > 0, array.astype(np.float32), np.nan)
    return write_cog(path, data, geotransform, crs, BandLabel(description, nodata=0.0, metadata=metadata))


def push_pull(z: np.ndarray, known: np.ndarray) -> np.ndarray:
    """``z`` with the unknown cells filled from the known ones: a pyramid of means (push) and back (pull, bilinear),
    relaxed a few times at each level (a smooth membrane).  Unknown everywhere: NaN."""
    z = np.where(known, z, 0.0).astype(np.float64)
    if not known.any():
        return np.full(z.shape, np.nan)
    if known.all():
        return z
    h, w = z.shape
    if h <= 2 and w <= 2:
        return np.where(known, z, z[known].mean())
    # push: 2 x 2 block means of the known cells
    hp, wp = h + h % 2, w + w % 2
    zs = np.zeros((hp, wp))
    ws = np.zeros((hp, wp))
    zs[:h, :w] = z * known
    ws[:h, :w] = known
    zsum = zs.reshape(hp // 2, 2, wp // 2, 2).sum(axis=(1, 3))
    wsum = ws.reshape(hp // 2, 2, wp // 2, 2).sum(axis=(1, 3))
    coarse_known = wsum > 0
    coarse = push_pull(np.where(coarse_known, zsum / np.maximum(wsum, 1e-12), 0.0), coarse_known)
    # pull: bilinear back onto this level's cell centres
    up = _upsample(coarse, h, w)
    out = np.where(known, z, up)
    unknown = ~known
    for _ in range(4):  # Jacobi relaxation of the unknown cells (edges replicated)
        p = np.pad(out, 1, mode="edge")
        avg = 0.25 * (p[:-2, 1:-1] + p[2:, 1:-1] + p[1:-1, :-2] + p[1:-1, 2:])
        out[unknown] = avg[unknown]
    return out


def _upsample(coarse: np.ndarray, h: int, w: int) -> np.ndarray:
    """Bilinear values of a 2x coarser grid at the centres of an h x w grid (edges replicated)."""
    ch, cw = coarse.shape
    fr = np.clip((np.arange(h) + 0.5) / 2.0 - 0.5, 0, ch - 1)
    fc = np.clip((np.arange(w) + 0.5) / 2.0 - 0.5, 0, cw - 1)
    r0 = np.minimum(np.floor(fr).astype(int), max(ch - 2, 0))
    c0 = np.minimum(np.floor(fc).astype(int), max(cw - 2, 0))
    r1 = np.minimum(r0 + 1, ch - 1)
    c1 = np.minimum(c0 + 1, cw - 1)
    ty = (fr - r0)[:, None]
    tx = (fc - c0)[None, :]
    a = coarse[np.ix_(r0, c0)]
    b = coarse[np.ix_(r0, c1)]
    c = coarse[np.ix_(r1, c0)]
    d = coarse[np.ix_(r1, c1)]
    return (1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * c + tx * d)


# ---------------------------------------------------------------------------
# reading (our DSM or an external one, e.g. ALS)
# ---------------------------------------------------------------------------

@dataclass
class DsmInfo:
    path: str
    width: int
    height: int
    geotransform: Tuple[float, ...]
    crs_wkt: str
    nodata: Optional[float]
    bounds: Tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
    resolution: Tuple[float, float]
    metadata: dict = field(default_factory=dict)


def open_dsm(path: str) -> DsmInfo:
    """Check and describe a DSM raster (ours or external).  Raises DsmError with a clear message."""
    try:
        with RasterFile(path, "DSM") as r:
            check_heights(r.dataset, f"DSM {path}", DsmError, products=False)
            gt = r.require_georeferenced()
            w, h = r.width, r.height
            xs = (gt[0], gt[0] + w * gt[1])
            ys = (gt[3], gt[3] + h * gt[5])
            return DsmInfo(path=path, width=w, height=h, geotransform=tuple(gt), crs_wkt=r.crs_wkt,
                           nodata=r.nodata(1), bounds=(min(xs), min(ys), max(xs), max(ys)),
                           resolution=(abs(gt[1]), abs(gt[5])), metadata=r.metadata())
    except DsmError:
        raise
    except RasterError as e:
        raise DsmError(str(e)) from e


class DsmReader:
    """Reads heights from a DSM, optionally reprojected into ``target_crs`` on the fly (a GDAL warped
    VRT, so an ALS DSM in another CRS works without a copy).  Heights are float64 with NaN for nodata, in the
    unit of the CRS they are read in (``target_crs``, else the DSM's own; metres for a geographic or metric
    one): converted from the unit the DSM declares (:func:`height_unit`: a band in feet, a vertical CRS in feet,
    a state plane DEM in feet read into UTM), the one conversion every reader of heights goes through
    (``z_scale``: the factor applied, ``z_unit``: (unit, metres per unit, where it was read)).

    with DsmReader(path, target_crs="EPSG:32617") as dsm:
        z = dsm.sample(x, y)                 # bilinear, world coordinates of target_crs
        arr, gt = dsm.read_window(xmin, ymin, xmax, ymax)
    """

    def __init__(self, path: str, target_crs: Optional[str] = None, resampling: str = "bilinear"):
        gdal, osr = _gdal()
        self.info = open_dsm(path)
        self._file = RasterFile(path, "DSM")
        self._ds = self._file.dataset
        if target_crs and self.info.crs_wkt:
            src = osr.SpatialReference(wkt=self.info.crs_wkt)
            dst = osr.SpatialReference()
            dst.SetFromUserInput(target_crs)
            if not src.IsSame(dst):
                self._ds = gdal.AutoCreateWarpedVRT(self._ds, self.info.crs_wkt, dst.ExportToWkt(),
                                                    getattr(gdal, f"GRA_{resampling.capitalize()}", gdal.GRA_Bilinear))
        gt = self._ds.GetGeoTransform()
        self.geotransform = gt
        self.width, self.height = self._ds.RasterXSize, self._ds.RasterYSize
        self.nodata = self._ds.GetRasterBand(1).GetNoDataValue()
        self.crs_wkt = self._ds.GetProjection()
        self.z_unit = height_unit(path)
        self.z_scale = self.z_unit[1] / axis_metres(self.crs_wkt)
        if abs(self.z_scale - 1.0) < 1e-12:
            self.z_scale = 1.0
        self._cache: Optional[np.ndarray] = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        self._ds = None
        self._file.close()
        self._cache = None

    def _clean(self, arr: np.ndarray) -> np.ndarray:
        arr = arr.astype(np.float64)
        if self.nodata is not None:
            arr[arr == self.nodata] = np.nan
        arr[~np.isfinite(arr)] = np.nan
        if self.z_scale != 1.0:
            arr *= self.z_scale
        return arr

    def read_window(self, xmin: float, ymin: float, xmax: float, ymax: float) -> Tuple[np.ndarray, Tuple[float, ...]]:
        """Heights of the cells covering a box (clipped to the raster) and the window's geotransform."""
        gt = self.geotransform
        c0 = max(0, int(math.floor((xmin - gt[0]) / gt[1])))
        c1 = min(self.width, int(math.ceil((xmax - gt[0]) / gt[1])))
        r0 = max(0, int(math.floor((ymax - gt[3]) / gt[5])))
        r1 = min(self.height, int(math.ceil((ymin - gt[3]) / gt[5])))
        if c1 <= c0 or r1 <= r0:
            return np.full((0, 0), np.nan), gt
        arr = self._ds.GetRasterBand(1).ReadAsArray(c0, r0, c1 - c0, r1 - r0)
        wgt = (gt[0] + c0 * gt[1], gt[1], 0.0, gt[3] + r0 * gt[5], 0.0, gt[5])
        return self._clean(arr), wgt

    def read_all(self) -> np.ndarray:
        if self._cache is None:
            self._cache = self._clean(self._ds.GetRasterBand(1).ReadAsArray())
        return self._cache

    def sample(self, x, y) -> np.ndarray:
        """Bilinear heights at world points (NaN outside or where a neighbour cell is nodata)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        if x.size == 0:
            return np.zeros(x.shape)
        gt = self.geotransform
        fc = (x - gt[0]) / gt[1] - 0.5
        fr = (y - gt[3]) / gt[5] - 0.5
        finite = np.isfinite(fc) & np.isfinite(fr)
        if not finite.any():
            return np.full(x.shape, np.nan)
        c0 = int(max(0, math.floor(np.nanmin(fc[finite])) - 1))
        c1 = int(min(self.width, math.ceil(np.nanmax(fc[finite])) + 2))
        r0 = int(max(0, math.floor(np.nanmin(fr[finite])) - 1))
        r1 = int(min(self.height, math.ceil(np.nanmax(fr[finite])) + 2))
        out = np.full(x.shape, np.nan)
        if c1 <= c0 or r1 <= r0:
            return out
        if self._cache is not None:
            arr = self._cache[r0:r1, c0:c1]
        else:
            arr = self._clean(self._ds.GetRasterBand(1).ReadAsArray(c0, r0, c1 - c0, r1 - r0))
        return bilinear(arr, fc - c0, fr - r0)


def bilinear(arr: np.ndarray, fc: np.ndarray, fr: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of ``arr`` at fractional (column, row) positions of cell centres;
    NaN outside or where any of the four cells is NaN."""
    h, w = arr.shape
    out = np.full(np.shape(fc), np.nan)
    c = np.floor(fc)
    r = np.floor(fr)
    # points on the outer half cell clamp to the edge cell
    c = np.where((fc >= -0.5) & (fc < 0), 0, np.where((fc >= w - 1) & (fc <= w - 0.5), w - 2, c))
    r = np.where((fr >= -0.5) & (fr < 0), 0, np.where((fr >= h - 1) & (fr <= h - 0.5), h - 2, r))
    ok = np.isfinite(c) & np.isfinite(r) & (c >= 0) & (r >= 0) & (c <= w - 2) & (r <= h - 2)
    if w == 1 or h == 1:
        ci = np.clip(np.round(fc), 0, w - 1)
        ri = np.clip(np.round(fr), 0, h - 1)
        ok1 = np.isfinite(ci) & np.isfinite(ri) & (fc > -0.5) & (fc < w - 0.5) & (fr > -0.5) & (fr < h - 0.5)
        out[ok1] = arr[ri[ok1].astype(int), ci[ok1].astype(int)]
        return out
    ci = c[ok].astype(np.int64)
    ri = r[ok].astype(np.int64)
    tx = np.clip(fc[ok] - ci, 0.0, 1.0)
    ty = np.clip(fr[ok] - ri, 0.0, 1.0)
    v = ((1 - tx) * (1 - ty) * arr[ri, ci] + tx * (1 - ty) * arr[ri, ci + 1]
         + (1 - tx) * ty * arr[ri + 1, ci] + tx * ty * arr[ri + 1, ci + 1])
    out[ok] = v
    return out


def read_dsm(path: str, target_crs: Optional[str] = None) -> Tuple[np.ndarray, Tuple[float, ...], str]:
    """The whole DSM as (heights float64 with NaN, geotransform, CRS WKT); for small rasters and tests."""
    with DsmReader(path, target_crs) as r:
        return r.read_all().copy(), r.geotransform, r.crs_wkt


# ---------------------------------------------------------------------------
# LAS point clouds (own writer: LAS 1.2, point format 2 = XYZ + RGB)
# ---------------------------------------------------------------------------

LAS_SCALE = 0.001


def _geokey_vlr(epsg: int, geographic: bool) -> bytes:
    # GeoKeyDirectoryTag: header (1, 1, 0, n) then keys (id, location 0, count 1, value)
    keys = [(1024, 0, 1, 2 if geographic else 1)]  # GTModelTypeGeoKey
    keys.append((2048 if geographic else 3072, 0, 1, epsg))  # Geographic/ProjectedCSTypeGeoKey
    if not geographic:
        keys.append((3076, 0, 1, 9001))  # ProjLinearUnitsGeoKey: metre
    data = struct.pack("<4H", 1, 1, 0, len(keys)) + b"".join(struct.pack("<4H", *k) for k in keys)
    return _vlr(b"LASF_Projection", 34735, data, b"GeoKeyDirectoryTag")


def _wkt_vlr(wkt: str) -> bytes:
    return _vlr(b"LASF_Projection", 2112, wkt.encode("utf-8") + b"\0", b"OGC WKT")


def _vlr(user_id: bytes, record_id: int, data: bytes, description: bytes) -> bytes:
    return (struct.pack("<H", 0) + user_id.ljust(16, b"\0")[:16] + struct.pack("<HH", record_id, len(data))
            + description.ljust(32, b"\0")[:32] + data)


def write_las(path: str, chunks: Iterable[Tuple[np.ndarray, np.ndarray]], offset: Sequence[float],
              crs: Optional[str], progress: Optional[Progress] = None, total: int = 0,
              system_id: str = "ArchaeoOrtho dense") -> int:
    """Write a LAS 1.2 file (point data format 2: XYZ + RGB) from (xyz local float, rgb uint8) chunks.

    World = local + ``offset``; coordinates are stored as int32 at 1 mm with the LAS offset at the
    rounded workspace offset.  The CRS goes in a GeoKeyDirectory VLR (EPSG) and/or an OGC WKT VLR.
    Written atomically; returns the number of points."""
    progress = progress or NullProgress()
    off = np.round(np.asarray(offset, dtype=np.float64), 0)
    local_shift = np.asarray(offset, dtype=np.float64) - off
    vlrs = b""
    n_vlr = 0
    if crs:
        epsg, geographic = crs_epsg(crs)
        if epsg:
            vlrs += _geokey_vlr(epsg, geographic)
            n_vlr += 1
        vlrs += _wkt_vlr(crs_to_wkt(crs))
        n_vlr += 1
    header_size = 227
    offset_to_points = header_size + len(vlrs)
    n = 0
    mins = np.full(3, np.inf)
    maxs = np.full(3, -np.inf)
    returns = 0
    dt = np.dtype([("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("intensity", "<u2"), ("flags", "u1"),
                   ("cls", "u1"), ("angle", "i1"), ("user", "u1"), ("src", "<u2"),
                   ("r", "<u2"), ("g", "<u2"), ("b", "<u2")])
    assert dt.itemsize == 26
    with atomic_output(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(b"\0" * header_size)
            f.write(vlrs)
            for xyz, rgb in chunks:
                check_cancel(progress)
                if len(xyz) == 0:
                    continue
                w = xyz.astype(np.float64) + local_shift
                rec = np.zeros(len(w), dtype=dt)
                q = np.round(w / LAS_SCALE)
                rec["x"], rec["y"], rec["z"] = q[:, 0], q[:, 1], q[:, 2]
                rec["flags"] = 0b00001001  # return 1 of 1
                rec["cls"] = 1  # unclassified
                rgb16 = rgb.astype(np.uint16) * 257
                rec["r"], rec["g"], rec["b"] = rgb16[:, 0], rgb16[:, 1], rgb16[:, 2]
                rec["intensity"] = (rgb.astype(np.uint32).sum(axis=1) * 257 // 3).astype(np.uint16)
                f.write(rec.tobytes())
                mins = np.minimum(mins, q.min(axis=0) * LAS_SCALE + off)
                maxs = np.maximum(maxs, q.max(axis=0) * LAS_SCALE + off)
                n += len(w)
                returns += len(w)
                if total:
                    progress.report(min(1.0, n / total), f"point cloud: {n} points")
            if n == 0:
                mins = maxs = off.copy()
            today = datetime.date.today()
            hdr = bytearray(header_size)
            struct.pack_into("<4sHH", hdr, 0, b"LASF", 0, 0)  # file source id, global encoding
            # GUID (16 bytes) zero, version 1.2
            struct.pack_into("<BB", hdr, 24, 1, 2)
            struct.pack_into("<32s32s", hdr, 26, system_id.encode()[:32], b"ArchaeoOrtho QGIS plugin")
            struct.pack_into("<HHHIIBHI", hdr, 90, today.timetuple().tm_yday, today.year, header_size,
                             offset_to_points, n_vlr, 2, dt.itemsize, min(n, 2 ** 32 - 1))
            struct.pack_into("<5I", hdr, 111, min(returns, 2 ** 32 - 1), 0, 0, 0, 0)
            struct.pack_into("<3d3d", hdr, 131, LAS_SCALE, LAS_SCALE, LAS_SCALE, *off)
            struct.pack_into("<6d", hdr, 179, maxs[0], mins[0], maxs[1], mins[1], maxs[2], mins[2])
            f.seek(0)
            f.write(bytes(hdr))
            f.flush()
            os.fsync(f.fileno())
    return n


def read_las(path: str) -> Tuple[np.ndarray, np.ndarray, dict]:
    """Read a LAS 1.2 format-2 file written by :func:`write_las`: (xyz world float64, rgb uint16, header)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"LASF":
        raise DsmError(f"{path} is not a LAS file")
    major, minor = struct.unpack_from("<BB", data, 24)
    header_size, offset_to_points, n_vlr, fmt, rec_len, n = struct.unpack_from("<HIIBHI", data, 94)
    scale = struct.unpack_from("<3d", data, 131)
    off = struct.unpack_from("<3d", data, 155)
    bounds = struct.unpack_from("<6d", data, 179)
    vlrs = []
    pos = header_size
    for _ in range(n_vlr):
        user = data[pos + 2:pos + 18].rstrip(b"\0").decode()
        rid, length = struct.unpack_from("<HH", data, pos + 18)
        vlrs.append((user, rid, data[pos + 54:pos + 54 + length]))
        pos += 54 + length
    raw = np.frombuffer(data, dtype=np.uint8, count=n * rec_len, offset=offset_to_points).reshape(n, rec_len)
    ints = raw[:, :12].copy().view("<i4").reshape(n, 3)
    xyz = ints * np.asarray(scale) + np.asarray(off)
    rgb = raw[:, 20:26].copy().view("<u2").reshape(n, 3) if fmt in (2, 3) else np.zeros((n, 3), np.uint16)
    header = {"version": f"{major}.{minor}", "point_format": fmt, "record_length": rec_len, "count": n,
              "scale": scale, "offset": off, "max_min": bounds, "vlrs": vlrs}
    return xyz, rgb, header


__all__ = ["Grid", "BandLabel", "write_cog", "translate_to_cog", "open_dsm", "DsmReader", "DsmInfo", "read_dsm", "write_las",
           "read_las", "DsmError", "RasterError", "RasterFile", "axis_metres",
           "NODATA", "bilinear", "crs_to_wkt", "crs_epsg", "height_unit", "ELEVATION_PRODUCTS", "not_heights",
           "check_heights", "check_heights_file"]
