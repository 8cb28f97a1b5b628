"""ASPRS classes of the dense point cloud from the DTM: 2 (ground) within the ground tolerance of the DTM where
the DTM is measured ground, 1 (unclassified: buildings, vegetation, ...) elsewhere."""
from __future__ import annotations

import struct
from typing import Tuple

import numpy as np

from ..common.files import atomic_output
from ..io import raster
from .options import SOURCE_MEASURED, TerrainError
from .rasters import Elevation

ASPRS_UNCLASSIFIED = 1
ASPRS_GROUND = 2
_CLASS_BYTE = 15  # in a LAS 1.2 point record of format 0-3: x y z (12) intensity (2) flags (1) class (1)


def classify_las(las_in: str, las_out: str, dtm: Elevation, source: np.ndarray, tolerance: float) -> Tuple[int, int]:
    """Copy ``las_in`` to ``las_out`` with each point's class set; returns (points, ground points)."""
    with open(las_in, "rb") as f:
        data = bytearray(f.read())
    if data[:4] != b"LASF":
        raise TerrainError(f"{las_in} is not a LAS file")
    header_size, offset_to_points, _n_vlr, fmt, rec_len, n = struct.unpack_from("<HIIBHI", data, 94)
    if fmt > 3:
        raise TerrainError(f"{las_in}: LAS point format {fmt} is not supported (0 to 3 are)")
    scale = np.asarray(struct.unpack_from("<3d", data, 131))
    off = np.asarray(struct.unpack_from("<3d", data, 155))
    raw = np.frombuffer(data, dtype=np.uint8, count=n * rec_len, offset=offset_to_points).reshape(n, rec_len)
    xyz = raw[:, :12].copy().view("<i4").reshape(n, 3) * scale + off
    gt = dtm.geotransform
    fc = (xyz[:, 0] - gt[0]) / gt[1] - 0.5
    fr = (xyz[:, 1] - gt[3]) / gt[5] - 0.5
    height = raster.bilinear(dtm.z / dtm.unit, fc, fr)
    ci = np.clip(np.round(fc).astype(np.int64), 0, source.shape[1] - 1)
    ri = np.clip(np.round(fr).astype(np.int64), 0, source.shape[0] - 1)
    with np.errstate(invalid="ignore"):
        ground = (np.abs(xyz[:, 2] - height) <= tolerance / dtm.unit) & (source[ri, ci] == SOURCE_MEASURED)
    classes = np.where(ground, ASPRS_GROUND, ASPRS_UNCLASSIFIED).astype(np.uint8)
    view = np.frombuffer(data, dtype=np.uint8, count=n * rec_len, offset=offset_to_points).reshape(n, rec_len)
    view[:, _CLASS_BYTE] = classes
    with atomic_output(las_out) as tmp:
        with open(tmp, "wb") as f:
            f.write(bytes(data))
    return int(n), int(ground.sum())
