"""GeoPackage vector output through OGR (cameras, residuals, footprints)."""
from __future__ import annotations

import os
from typing import Dict, List, Optional, Sequence

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output


class VectorError(ArchaeoOrthoError, RuntimeError):
    """A vector file cannot be read; the message names the file and the problem."""


def open_vector(path: str, what: str):
    """The OGR dataset of the vector file ``path`` (``what`` it is meant to be, e.g. "seamlines", begins the
    messages); VectorError when the file is missing, not a vector file GDAL can read, or holds no layer."""
    from osgeo import gdal

    gdal.UseExceptions()
    if not os.path.isfile(path):
        raise VectorError(f"{what} {path} does not exist")
    try:
        ds = gdal.OpenEx(path, gdal.OF_VECTOR)
    except RuntimeError as e:
        raise VectorError(f"{what} {path} is not a vector file GDAL can read: {e}") from e
    if ds is None or ds.GetLayerCount() == 0:
        raise VectorError(f"{what} {path} holds no vector layer")
    return ds


def write_points_gpkg(path: str, layer: str, rows: Sequence[Dict], fields: Sequence[tuple],
                      crs: Optional[str] = None, xyz=("x", "y", "z")) -> str:
    """Write point rows (dicts) to a GeoPackage, atomically.

    ``fields``: (name, type) with type in {"str", "int", "float"}; ``crs``: anything
    osr understands, or None for a local engineering frame (no CRS).
    """
    from osgeo import ogr, osr

    ogr.UseExceptions()
    srs = None
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    types = {"str": ogr.OFTString, "int": ogr.OFTInteger64, "float": ogr.OFTReal}
    with atomic_output(path) as tmp:
        drv = ogr.GetDriverByName("GPKG")
        ds = drv.CreateDataSource(tmp)
        lyr = ds.CreateLayer(layer, srs, ogr.wkbPoint25D)
        for name, t in fields:
            lyr.CreateField(ogr.FieldDefn(name, types[t]))
        defn = lyr.GetLayerDefn()
        for r in rows:
            f = ogr.Feature(defn)
            for name, _t in fields:
                v = r.get(name)
                if v is not None:
                    f.SetField(name, v)
            g = ogr.Geometry(ogr.wkbPoint25D)
            g.AddPoint(float(r[xyz[0]]), float(r[xyz[1]]), float(r[xyz[2]]))
            f.SetGeometry(g)
            lyr.CreateFeature(f)
        ds = None
    return path


CAMERA_FIELDS: List[tuple] = [("image", "str"), ("camera_id", "int"), ("x", "float"), ("y", "float"),
                              ("z", "float"), ("points", "int")]


def write_cameras_gpkg(workspace_root: str, rows: Sequence[Dict], crs: Optional[str] = None) -> str:
    path = os.path.join(workspace_root, "cameras.gpkg")
    return write_points_gpkg(path, "cameras", rows, CAMERA_FIELDS, crs)
