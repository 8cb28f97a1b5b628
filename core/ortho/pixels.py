"""Pixels of the source images: metadata, windows, masks, the byte-bounded cache that holds them, and
cv2.remap of scattered coordinates (bilinear / cubic / nearest)."""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from typing import Any, Optional, Tuple

import numpy as np

from ..common.errors import require
from ..io.raster import RasterError, RasterFile
from .options import OrthoError, OrthoOptions


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


PHOTO_CACHE = _LRU(OrthoOptions.cache_mb << 20)  # each stage sets its options.cache_mb
_WHOLE_IMAGE_MAX = 96 << 20  # images up to this size are decoded whole and cached; larger ones read by window


def load_gdal():
    from osgeo import gdal

    gdal.UseExceptions()
    return gdal


@dataclass
class ImageMeta:
    width: int
    height: int
    bands: int
    dtype: str  # numpy dtype name


def _numpy_dtype(gdal_type: int) -> np.dtype:
    from osgeo import gdal_array

    return np.dtype(gdal_array.GDALTypeCodeToNumericTypeCode(gdal_type))


def image_meta(path: str) -> ImageMeta:
    try:
        with RasterFile(path, "image") as r:
            return ImageMeta(r.width, r.height, r.count, _numpy_dtype(r.band(1).DataType).name)
    except RasterError as e:
        raise OrthoError(str(e)) from e


def _read_window(path: str, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    with RasterFile(path, "image") as r:
        w, h, bands = x1 - x0, y1 - y0, r.count
        gdt = r.band(1).DataType
        dtype = _numpy_dtype(gdt)
        # read pixel-interleaved (rows, cols, bands) directly: half the time of a band-sequential read and a copy
        isz = dtype.itemsize
        buf = r.dataset.ReadRaster(x0, y0, w, h, buf_type=gdt, buf_pixel_space=bands * isz,
                                   buf_line_space=bands * isz * w, buf_band_space=isz)
        nodata = r.band(1).GetNoDataValue() if dtype.kind == "f" else None
    out = np.frombuffer(bytearray(buf) if isinstance(buf, bytes) else buf, dtype=dtype).reshape(h, w, bands)
    if nodata is not None and np.isfinite(nodata):
        # a float photo's declared nodata (a multispectral capture in reflectance: 0 where a band does not reach,
        # core.io.multispectral.write_band_stack) read as NaN: its samples, and those interpolated from it, are
        # then no data (core.ortho.sampling.sample_camera)
        out[out == nodata] = np.nan
    return out


def image_window(path: str, meta: ImageMeta, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    nbytes = meta.width * meta.height * meta.bands * np.dtype(meta.dtype).itemsize
    if nbytes <= _WHOLE_IMAGE_MAX:
        whole = PHOTO_CACHE.get(("img", path), lambda: (_read_window(path, 0, 0, meta.width, meta.height), nbytes))
        return whole[y0:y1, x0:x1]
    return _read_window(path, x0, y0, x1, y1)


def photo_mask(path: Optional[str]) -> Optional[np.ndarray]:
    if not path:
        return None

    def make():
        cv2 = require("cv2", "orthophotos")

        m = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        if m is None:
            raise OrthoError(f"mask {path} cannot be read")
        return m, m.nbytes
    return PHOTO_CACHE.get(("mask", path), make)


_CV_TYPES = ("uint8", "uint16", "int16", "float32")


def remap_photo(src: np.ndarray, mx: np.ndarray, my: np.ndarray, interpolation: str, border_nan: bool = False
           ) -> np.ndarray:
    """cv2.remap of 1-D coordinate arrays (rows of 1024, as remap wants short sides) -> (N, bands) float32."""
    cv2 = require("cv2", "orthophotos")

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
        # up to 4 bands: the window itself (cv2 takes its row stride; a copy of it per call cost as much as
        # the remap), more: 4 bands at a time, copied
        part = src if bands <= 4 else np.ascontiguousarray(src[:, :, b0:b0 + 4])
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
