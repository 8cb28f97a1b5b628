"""Output rasters: a tiled GeoTIFF that tiles stream into, translated to a Cloud-Optimized GeoTIFF (atomically);
the GDAL block cache bound while writing."""
from __future__ import annotations

import contextlib
import os
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.files import atomic_output
from ..common.progress import NullProgress, Progress, check_cancel
from ..io import raster as dsmmod
from ..io.raster import RasterFile
from .options import OrthoError
from .pixels import load_gdal


def _alpha_value(dtype: str) -> Optional[float]:
    dt = np.dtype(dtype)
    if dt.kind in "ui":
        return float(np.iinfo(dt).max)
    return None  # float images: nodata NaN instead of an alpha band


def photo_band_names(paths: Sequence[str]) -> Tuple[List[str], List[Dict[str, str]]]:
    """The band descriptions the photos ``paths`` share (a multispectral capture's band names, core.prepare.captures)
    and, per band, the metadata items every photo gives alike (wavelength, unit, radiometry; an item of one capture,
    such as how its bands were registered, is left out); ([], []) when they have no names or do not agree on them."""
    names = None
    shared: List[Dict[str, str]] = []
    for path in paths:
        with RasterFile(path, "photo") as r:
            these = tuple(r.band(i + 1).GetDescription() for i in range(r.count))
            mds = [dict(r.metadata(i + 1)) for i in range(r.count)]
        if names is None:
            names, shared = these, mds
        elif these != names:
            return [], []
        else:
            shared = [{k: v for k, v in s.items() if m.get(k) == v} for s, m in zip(shared, mds)]
    if not names or not any(names):
        return [], []
    return list(names), shared


REFLECTANCE_UNIT = "reflectance"  # a photo band's RADIOMETRIC_UNIT item (core.prepare.band_radiometry.REFLECTANCE)


def calibrated_reflectance(paths: Sequence[str]) -> bool:
    """Do the photos hold calibrated reflectance: every band of every photo says RADIOMETRIC_UNIT reflectance (a
    multispectral capture calibrated by its panel, core.prepare.captures)?  Their values are then mosaicked as
    they are (core.ortho.mosaic)."""
    _names, mds = photo_band_names(paths)
    return bool(mds) and all(m.get("RADIOMETRIC_UNIT") == REFLECTANCE_UNIT for m in mds)


class RasterWriter:
    """A tiled GeoTIFF that tiles are written into, then translated to a COG (atomically)."""

    def __init__(self, path: str, width: int, height: int, bands: int, dtype: str, geotransform, crs: Optional[str]):
        gdal = load_gdal()
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
                                                      else []) + (["ALPHA=YES"] if self.alpha is not None and
                                                                  bands in (1, 3) else []))
        # ALPHA=YES marks the first extra sample: the alpha after a grey band or RGB, but band 2 of a multispectral
        # mosaic (NIR, Red, ...: Red was read as a mask); there the alpha is marked by its colour interpretation
        self.ds.SetGeoTransform(tuple(float(v) for v in geotransform))
        wkt = dsmmod.crs_to_wkt(crs) if crs else ""
        if wkt:
            self.ds.SetProjection(wkt)
        if self.alpha is not None:
            self.ds.GetRasterBand(n).SetColorInterpretation(gdal.GCI_AlphaBand)
        else:
            for b in range(1, bands + 1):
                self.ds.GetRasterBand(b).SetNoDataValue(float("nan"))

    def describe(self, descriptions: Sequence[str], metadata: Sequence[Dict[str, str]]) -> None:
        """Name the image bands (the photos' own band descriptions and band metadata: a multispectral capture's
        band names and wavelengths); nothing when ``descriptions`` is empty."""
        for b, (text, md) in enumerate(zip(descriptions[:self.bands], metadata[:self.bands])):
            band = self.ds.GetRasterBand(b + 1)
            if text:
                band.SetDescription(str(text))
            if md:
                band.SetMetadata({str(k): str(v) for k, v in md.items()})

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
        gdal = load_gdal()
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
        md = load_gdal().GetDriverByName("GTiff").GetMetadataItem("DMD_CREATIONOPTIONLIST") or ""
        _ZSTD = "ZSTD" in md
    return _ZSTD


@contextlib.contextmanager
def gdal_cache(mb: int):
    gdal = load_gdal()
    old = gdal.GetCacheMax()
    gdal.SetCacheMax(int(mb) << 20)
    try:
        yield
    finally:
        gdal.SetCacheMax(old)


def interior_nodata(path: str) -> int:
    """The nodata cells of a mosaic (alpha 0, or NaN in a float mosaic) that data encloses: not connected (4-way)
    to the raster's border through nodata; the holes and cracks inside the mosaic, for benchmarks and checks.  It
    also counts ground that no image sees but data encloses (behind a roof at the block's border, beyond the images'
    edge), so it need not be 0 where every photographed cell has data."""
    from scipy import ndimage

    gdal = load_gdal()
    with RasterFile(path, "mosaic") as r:
        if r.band(r.count).GetColorInterpretation() == gdal.GCI_AlphaBand:
            nodata = r.read(r.count) == 0
        else:
            nodata = ~np.isfinite(r.read(1).astype(np.float32))
    lab, n = ndimage.label(nodata)
    if not n:
        return 0
    edge = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    return int((nodata & ~np.isin(lab, edge[edge > 0])).sum())
