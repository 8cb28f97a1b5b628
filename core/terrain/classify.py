"""ASPRS classes of the dense point cloud from the DTM: 2 (ground) within the ground tolerance of the DTM where
the DTM is measured ground, 1 (unclassified: buildings, vegetation, ...) elsewhere."""
from __future__ import annotations

import shutil
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


def classify_las(las_in: str, las_out: str, dtm: Elevation, source: np.ndarray, tolerance: float,
                 chunk: int = 2_000_000) -> Tuple[int, int]:
    """Copy ``las_in`` to ``las_out`` with each point's class set; returns (points, ground points).  The copy is
    patched in place, ``chunk`` points at a time (a cloud of any size in bounded memory)."""
    with open(las_in, "rb") as f:
        head = f.read(227)
    if head[:4] != b"LASF" or len(head) < 227:
        raise TerrainError(f"{las_in} is not a LAS file")
    _header_size, offset_to_points, _n_vlr, fmt, rec_len, n = struct.unpack_from("<HIIBHI", head, 94)
    if fmt > 3:
        raise TerrainError(f"{las_in}: LAS point format {fmt} is not supported (0 to 3 are)")
    scale = np.asarray(struct.unpack_from("<3d", head, 131))
    off = np.asarray(struct.unpack_from("<3d", head, 155))
    gt = dtm.geotransform
    heights = dtm.z if dtm.unit == 1.0 else dtm.z / dtm.unit
    n_ground = 0
    with atomic_output(las_out) as tmp:
        shutil.copyfile(las_in, tmp)
        if n:
            records = np.memmap(tmp, dtype=np.uint8, mode="r+", offset=offset_to_points, shape=(n, rec_len))
            for i in range(0, n, chunk):
                raw = records[i:i + chunk]
                xyz = np.ascontiguousarray(raw[:, :12]).view("<i4").reshape(-1, 3) * scale + off
                fc = (xyz[:, 0] - gt[0]) / gt[1] - 0.5
                fr = (xyz[:, 1] - gt[3]) / gt[5] - 0.5
                height = raster.bilinear(heights, fc, fr)
                ci = np.clip(np.round(fc).astype(np.int64), 0, source.shape[1] - 1)
                ri = np.clip(np.round(fr).astype(np.int64), 0, source.shape[0] - 1)
                with np.errstate(invalid="ignore"):
                    ground = (np.abs(xyz[:, 2] - height) <= tolerance / dtm.unit) & (source[ri, ci] == SOURCE_MEASURED)
                raw[:, _CLASS_BYTE] = np.where(ground, ASPRS_GROUND, ASPRS_UNCLASSIFIED).astype(np.uint8)
                n_ground += int(ground.sum())
            records.flush()
            del records
    return int(n), n_ground
