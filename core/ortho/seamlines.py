"""The seamlines GeoPackage: written by the mosaic (one polygon per image, its name in the field ``image``) and
read back, edited, to say which image the mosaic takes where (Build orthophoto's SEAMLINES_IN).

A user moves a seam off a crop mark or a moving car by editing the polygons (reshaping one, drawing a new one,
changing its ``image``) and gives the file back.  Where a polygon names an image that differs from the automatic
choice, that image is used where it sees the ground (elsewhere the automatic seams stay, and the log says so);
where polygons overlap, the one that differs from the automatic choice wins (the edit), and of several edits the
later feature.  A polygon whose ``image`` is empty leaves its area to the automatic seams."""
from __future__ import annotations

import difflib
import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output
from ..io import raster as dsmmod
from ..io.vector import VectorError, open_vector
from .options import OrthoError
from .pixels import load_gdal

LAYER = "mosaic_sources"
IMAGE_FIELD = "image"


class SeamlineError(OrthoError):
    """The edited seamlines cannot be used (the file, a field, an image name or the CRS); the message says which."""


@dataclass
class SeamlineEdits:
    """Polygons of an edited seamlines layer: (image name as in the mosaic, geometry as WKB) in feature order."""

    source: str
    polygons: List[Tuple[str, bytes]] = field(default_factory=list)
    skipped: int = 0  # features without geometry or without an image (automatic seams there)
    notes: List[str] = field(default_factory=list)  # for the log (a layer without a CRS taken as the mosaic's)


def _split_source(source: str) -> Tuple[str, Optional[str]]:
    """'path' or 'path|layername=name' (a QGIS layer source) -> (path, layer name or None)."""
    path, _, rest = source.partition("|")
    layer = None
    for part in rest.split("|"):
        key, _, value = part.partition("=")
        if key.strip().lower() == "layername" and value:
            layer = value.strip()
    return path, layer


def edits_fingerprint(source: str) -> str:
    """The stage's input fingerprint of an edited seamlines layer ('' while the file is missing)."""
    from ..common.files import file_fingerprint

    path, layer = _split_source(source)
    return (file_fingerprint(path) + (f"|{layer}" if layer else "")) if os.path.isfile(path) else ""


def _find(value: str, names: Sequence[str]) -> Optional[str]:
    """``value`` among ``names``: as it is, in another case, or by its stem when only one has it."""
    if value in names:
        return value
    low = {n.lower(): n for n in names}
    if value.lower() in low:
        return low[value.lower()]
    stems: Dict[str, List[str]] = {}
    for n in names:
        stems.setdefault(os.path.splitext(n)[0].lower(), []).append(n)
    hit = stems.get(os.path.splitext(value)[0].lower(), [])
    return hit[0] if len(hit) == 1 else None


def _match_name(value: str, names: Sequence[str], where: str, left_out: Sequence[str] = (),
                images_filter: Optional[str] = None) -> str:
    hit = _find(value, names)
    if hit is not None:
        return hit
    out = _find(value, left_out)
    if out is not None:
        raise SeamlineError(f"{where} names the image {out!r}, which IMAGES_FILTER {images_filter or ''!r} leaves "
                            "out of this mosaic: add it to the filter, or give the polygon one of the images the "
                            "mosaic is made of")
    close = difflib.get_close_matches(value, list(names), n=3, cutoff=0.5)
    hint = (f"did you mean {', '.join(repr(c) for c in close)}?" if close else
            f"the mosaic's images are {', '.join(list(names)[:8])}{' ...' if len(names) > 8 else ''}")
    raise SeamlineError(f"{where} names the image {value!r}, which is not one of the {len(names)} images of this "
                        f"mosaic: {hint}")


def _check_crs(path: str, lyr, crs: Optional[str]) -> None:
    from osgeo import osr

    srs = lyr.GetSpatialRef()
    if srs is None or not crs:
        return
    want = osr.SpatialReference()
    want.SetFromUserInput(crs)
    if not srs.IsSame(want):
        name = srs.GetName() or "?"
        code = srs.GetAuthorityCode(None)
        have = f"{srs.GetAuthorityName(None)}:{code} ({name})" if code else name
        raise SeamlineError(f"seamlines {path}: the layer is in {have}, the mosaic in {crs}: the polygons must be in "
                            f"the mosaic's CRS (save the layer in {crs}, or edit the seamlines the mosaic wrote)")


def _unknown_crs(out: SeamlineEdits, path: str, crs: Optional[str], extent) -> None:
    """A layer without a CRS (a shapefile without its .prj): taken as the mosaic's when its polygons lie on the
    mosaic's ``extent`` (xmin, ymin, xmax, ymax; said in the log); SeamlineError when none does (issue 36 item
    13: they were ignored, 'polygon(s) outside the mosaic', without a word on the CRS)."""
    from osgeo import ogr

    if not crs:
        return
    if extent is not None and out.polygons:
        xmin, ymin, xmax, ymax = extent
        on = 0
        for _, wkb in out.polygons:
            gx0, gx1, gy0, gy1 = ogr.CreateGeometryFromWkb(wkb).GetEnvelope()
            on += int(gx0 <= xmax and gx1 >= xmin and gy0 <= ymax and gy1 >= ymin)
        if not on:
            raise SeamlineError(f"seamlines {path}: the layer's CRS is unknown (a shapefile without its .prj file?) "
                                f"and none of its {len(out.polygons)} polygon(s) lies on the mosaic ({xmin:.0f}..{xmax:.0f}, "
                                f"{ymin:.0f}..{ymax:.0f} in {crs}): save the layer in the mosaic's CRS ({crs}) with its CRS")
    out.notes.append(f"seamlines {path}: the layer's CRS is unknown (no .prj?): its coordinates are taken as the "
                     f"mosaic's CRS ({crs})")


def dsm_extent(dsm_path: str, crs: Optional[str]) -> Optional[Tuple[float, float, float, float]]:
    """The DSM's bounds in the mosaic's CRS (the mosaic lies within them: the ``extent`` of
    :func:`read_seamline_edits`), None when they cannot be told."""
    from ..geometry.crs import transform_points

    try:
        info = dsmmod.open_dsm(dsm_path)
        b = np.array([[info.bounds[0], info.bounds[1]], [info.bounds[2], info.bounds[3]],
                      [info.bounds[0], info.bounds[3]], [info.bounds[2], info.bounds[1]]])
        if crs and info.crs_wkt:
            b = transform_points(b, info.crs_wkt, crs)
    except (dsmmod.DsmError, ArchaeoOrthoError):
        return None
    return float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 0].max()), float(b[:, 1].max())


def read_seamline_edits(source: str, names: Sequence[str], crs: Optional[str], left_out: Sequence[str] = (),
                        images_filter: Optional[str] = None, extent=None) -> SeamlineEdits:
    """The polygons of an edited seamlines layer (``source``: a file path, or 'path|layername=...'), checked
    against the mosaic's image ``names`` and ``crs``.  SeamlineError naming the file and the problem (an image
    of ``left_out``: left out by ``images_filter``; a layer without a CRS none of whose polygons lies on the
    mosaic's ``extent``)."""
    from osgeo import ogr

    ogr.UseExceptions()
    path, layer_name = _split_source(source)
    try:
        ds = open_vector(path, "seamlines")
    except VectorError as e:
        raise SeamlineError(str(e)) from e
    if layer_name:
        lyr = ds.GetLayerByName(layer_name)
        if lyr is None:
            raise SeamlineError(f"seamlines {path} has no layer {layer_name!r}")
    else:
        lyr = ds.GetLayerByName(LAYER) or ds.GetLayer(0)
    where = f"seamlines {path} (layer {lyr.GetName()})"
    defn = lyr.GetLayerDefn()
    fields = [defn.GetFieldDefn(i).GetName() for i in range(defn.GetFieldCount())]
    field_name = next((f for f in fields if f.lower() == IMAGE_FIELD), None)
    if field_name is None:
        raise SeamlineError(f"{where} has no field '{IMAGE_FIELD}' naming the image each polygon takes (its fields: "
                            f"{', '.join(fields) or 'none'})")
    _check_crs(path, lyr, crs)
    out = SeamlineEdits(path)
    for feat in lyr:
        geom = feat.GetGeometryRef()
        value = feat.GetField(field_name)
        value = str(value).strip() if value is not None else ""
        if geom is None or geom.IsEmpty() or not value:
            out.skipped += 1
            continue
        flat = ogr.GT_Flatten(geom.GetGeometryType())
        if flat in (ogr.wkbCurvePolygon, ogr.wkbMultiSurface):
            geom = geom.GetLinearGeometry()
            flat = ogr.GT_Flatten(geom.GetGeometryType())
        if flat not in (ogr.wkbPolygon, ogr.wkbMultiPolygon):
            raise SeamlineError(f"{where}: feature {feat.GetFID()} is a {geom.GetGeometryName()}, not a polygon")
        name = _match_name(value, names, f"{where}, feature {feat.GetFID()},", left_out, images_filter)
        out.polygons.append((name, bytes(geom.ExportToWkb())))
    if lyr.GetSpatialRef() is None:
        _unknown_crs(out, path, crs, extent)
    return out


def _rasterise(wkb: bytes, grid: dsmmod.Grid) -> Optional[Tuple[int, int, np.ndarray]]:
    """(row0, col0, mask) of the cells of ``grid`` whose centre lies in the polygon; None when none does."""
    from osgeo import ogr

    from .grid import subgrid

    gdal = load_gdal()
    geom = ogr.CreateGeometryFromWkb(wkb)
    xmin, xmax, ymin, ymax = geom.GetEnvelope()
    sub = subgrid(grid, (xmin, ymin, xmax, ymax))
    if sub is None:
        return None
    r0, c0, h, w = sub
    p = grid.resolution
    mem = gdal.GetDriverByName("MEM").Create("", w, h, 1, gdal.GDT_Byte)
    mem.SetGeoTransform((grid.x0 + c0 * p, p, 0.0, grid.y0 - r0 * p, 0.0, -p))
    vds = ogr.GetDriverByName("Memory").CreateDataSource("")
    lyr = vds.CreateLayer("p", None, ogr.wkbUnknown)
    f = ogr.Feature(lyr.GetLayerDefn())
    f.SetGeometry(geom)
    lyr.CreateFeature(f)
    gdal.PushErrorHandler("CPLQuietErrorHandler")  # neither has a CRS: both are the mosaic's
    try:
        gdal.RasterizeLayer(mem, [1], lyr, burn_values=[1])
    finally:
        gdal.PopErrorHandler()
    mask = mem.GetRasterBand(1).ReadAsArray() > 0
    return (r0, c0, mask) if mask.any() else None


def force_edits(labels: np.ndarray, grid: dsmmod.Grid, edits: SeamlineEdits, names: Sequence[str], costs,
                windows) -> Tuple[int, List[str]]:
    """Give the planning cells of ``labels`` (on ``grid``) that the edited polygons claim for an image to that
    image where it sees the ground (a finite view cost), in place.  Returns (cells changed, log lines)."""
    index = {n: i for i, n in enumerate(names)}
    auto = labels.copy()
    claim = np.full(labels.shape, -1, dtype=np.int32)
    missing: Dict[str, int] = {}
    outside = 0
    for name, wkb in edits.polygons:
        ras = _rasterise(wkb, grid)
        if ras is None:
            outside += 1
            continue
        r0, c0, mask = ras
        h, w = mask.shape
        i = index.get(name, -1)
        if i < 0:  # an image of the block that sees none of the DSM (left out of the mosaic)
            missing[name] = missing.get(name, 0) + int(mask.sum())
            continue
        cur = claim[r0:r0 + h, c0:c0 + w]
        au = auto[r0:r0 + h, c0:c0 + w]
        take = mask & ((cur < 0) | (au != i) | (cur == au))  # an edit is kept against a later unedited claim
        cur[take] = i
    changed = 0
    lines: List[str] = []
    for i in np.unique(claim[(claim >= 0) & (claim != auto)]):
        rr, cc = np.nonzero((claim == i) & (auto != i))
        sees = np.zeros(len(rr), dtype=bool)
        if windows[i] is not None and costs[i] is not None:
            wr0, wc0, wh, ww = windows[i]
            r, c = rr - wr0, cc - wc0
            ok = (r >= 0) & (r < wh) & (c >= 0) & (c < ww)
            sees[ok] = np.isfinite(costs[i][r[ok], c[ok]])
        labels[rr[sees], cc[sees]] = i
        changed += int(sees.sum())
        if (~sees).any():
            missing[names[i]] = missing.get(names[i], 0) + int((~sees).sum())
    p = grid.resolution
    lines.append(f"seamlines {edits.source}: {len(edits.polygons)} polygon(s) name an image, {changed} planning cells "
                 f"({changed * p * p:.0f} m2) given to the image they name instead of the automatic choice"
                 + (f"; {edits.skipped} feature(s) without an image or a geometry left to the automatic seams"
                    if edits.skipped else "") + (f"; {outside} polygon(s) outside the mosaic" if outside else ""))
    for name, n in sorted(missing.items(), key=lambda t: -t[1]):
        lines.append(f"seamlines {edits.source}: {n} planning cells ({n * p * p:.0f} m2) of polygons naming {name} "
                     "keep the automatic seams: that image does not see the ground there")
    return changed, lines


def write_seamlines(path: str, labels: np.ndarray, grid: dsmmod.Grid, names: Sequence[str],
                    camera_ids: Sequence[int], gains: Sequence[float], crs: Optional[str]) -> str:
    """The which-image layer: one (multi)polygon per image of the planning ``labels`` (on ``grid``) with the
    fields image, camera_id, gain and label, editable and taken back by read_seamline_edits."""
    from osgeo import ogr, osr

    gdal = load_gdal()
    ogr.UseExceptions()
    mem = gdal.GetDriverByName("MEM").Create("", labels.shape[1], labels.shape[0], 1, gdal.GDT_Int32)
    mem.SetGeoTransform((grid.x0, grid.resolution, 0.0, grid.y0, 0.0, -grid.resolution))
    band = mem.GetRasterBand(1)
    band.WriteArray(labels.astype(np.int32))
    band.SetNoDataValue(-1)
    vds = ogr.GetDriverByName("Memory").CreateDataSource("")
    tmp_lyr = vds.CreateLayer("p", None, ogr.wkbPolygon)
    tmp_lyr.CreateField(ogr.FieldDefn("label", ogr.OFTInteger))
    gdal.Polygonize(band, band.GetMaskBand(), tmp_lyr, 0, [], callback=None)
    parts: Dict[int, ogr.Geometry] = {}
    for f in tmp_lyr:
        i = f.GetField("label")
        if i is None or not 0 <= i < len(names):
            continue
        parts.setdefault(i, ogr.Geometry(ogr.wkbMultiPolygon)).AddGeometry(f.GetGeometryRef())
    srs = None
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    with atomic_output(path) as tmp:
        ds = ogr.GetDriverByName("GPKG").CreateDataSource(tmp)
        lyr = ds.CreateLayer(LAYER, srs, ogr.wkbMultiPolygon)
        for name, kind in ((IMAGE_FIELD, ogr.OFTString), ("camera_id", ogr.OFTInteger), ("gain", ogr.OFTReal),
                           ("label", ogr.OFTInteger)):
            lyr.CreateField(ogr.FieldDefn(name, kind))
        lyr.StartTransaction()
        for i in sorted(parts):
            geom = parts[i].UnionCascaded()
            if geom is None or geom.IsEmpty():
                continue
            if ogr.GT_Flatten(geom.GetGeometryType()) == ogr.wkbPolygon:
                geom = ogr.ForceToMultiPolygon(geom)
            f = ogr.Feature(lyr.GetLayerDefn())
            f.SetField(IMAGE_FIELD, names[i])
            f.SetField("camera_id", int(camera_ids[i]))
            f.SetField("gain", float(gains[i]))
            f.SetField("label", int(i))
            f.SetGeometry(geom)
            lyr.CreateFeature(f)
        lyr.CommitTransaction()
        ds = None
    return path
