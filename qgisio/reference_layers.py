"""Reference layers of any provider for the automatic control: a WMS / XYZ / WCS layer, a virtual raster or a
remote raster is saved to a GeoTIFF in the workspace for the extent the block needs (core reads files only).

qgis.core only (no qgis.gui, no processing): used by the Georeference / Automatic control algorithms and by the
dock's automatic control (ui/gcp_autocontrol.py), in a worker thread there: the dock passes LayerSnapshots
taken on the GUI thread (the provider cloned there), never the project's layers.

- the extent: given (a map extent, the algorithm's REFERENCE_EXTENT), else the block's rough extent from the
  photos' EXIF GPS plus a margin, else the other reference's extent when that one is a file, else the layer's own
  extent when it is small enough;
- the CRS: the layer's, unless it is geographic or Web Mercator (heights in metres need a conformal, true-scale
  grid): then the DSM layer's when that is projected, else the UTM zone of the extent's centre;
- the resolution: ``gsd`` (default 0.25 m for the orthophoto, twice that, at least 0.5 m, for the DSM), made
  coarser beyond ``MAX_PIXELS`` (said in the log);
- a fetch that fails or returns nothing over the extent is a ReferenceLayerError naming the layer and the extent.
"""
import math
import os

from qgis.core import (
    Qgis,
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransform,
    QgsPointXY,
    QgsProject,
    QgsRasterBlockFeedback,
    QgsRasterFileWriter,
    QgsRasterPipe,
    QgsRasterProjector,
    QgsRectangle,
)

from ..core.common.errors import ArchaeoOrthoError
from ..core.common.progress import Cancelled

DEFAULT_GSD = 0.25  # metres per pixel of a saved reference orthophoto when none is given
MIN_DSM_GSD = 0.5
MAX_PIXELS = 64_000_000  # cells of one saved reference (8000 x 8000): coarser beyond
MIN_MARGIN = 100.0  # metres around the photos' GPS positions (the footprints reach beyond the camera centres)
WEB_MERCATOR = ("EPSG:3857", "EPSG:900913", "EPSG:3785")
IMAGE_TYPES = (Qgis.DataType.ARGB32, Qgis.DataType.ARGB32_Premultiplied)


class ReferenceLayerError(ArchaeoOrthoError, RuntimeError):
    """A reference layer cannot be saved for the automatic control: the message names the layer and why."""


class LayerSnapshot:
    """What the saving needs of a map layer, taken on the thread that owns the layer (the GUI thread in the
    dock): its name, source, CRS and extent, and a clone of its provider.  A worker thread then reads the
    snapshot, never the project's layer, which the map canvas renders and the user may remove meanwhile (a
    layer and its provider are not thread-safe).  It answers the few QgsMapLayer calls this module makes."""

    def __init__(self, layer):
        self._name, self._provider_type, self._source = layer.name(), layer.providerType(), layer.source()
        self._valid = layer.isValid()
        self._crs = QgsCoordinateReferenceSystem(layer.crs())
        self._extent = QgsRectangle(layer.extent())
        provider = layer.dataProvider() if self._valid else None
        self._provider = provider.clone() if provider is not None and local_file(layer) is None else None

    def name(self):
        return self._name

    def providerType(self):  # noqa: N802 (the QgsMapLayer names)
        return self._provider_type

    def source(self):
        return self._source

    def isValid(self):  # noqa: N802
        return self._valid

    def crs(self):
        return self._crs

    def extent(self):
        return self._extent

    def dataProvider(self):  # noqa: N802
        return self._provider


def snapshot(layer):
    """A LayerSnapshot of ``layer`` (None stays None): call it on the layer's own thread."""
    return None if layer is None else LayerSnapshot(layer)


def local_file(layer):
    """The file of a layer GDAL reads from the local disk, else None (a web layer, a virtual or remote raster)."""
    if layer is None or layer.providerType() != "gdal":
        return None
    path = layer.source().split("|")[0]
    return path if os.path.isfile(path) else None


_NOT_HEIGHTS_CACHE = {}  # (file, size, mtime) -> why not heights ('' when heights): each file read once


def layer_not_heights(layer, workspace_dir=None):
    """Why the raster ``layer`` cannot be a reference DSM / a source of heights ('' when it can): a hillshade
    (a picture of its DSM, listed beside it), a web map (rendered colours), a file that core/io/raster.py's
    not_heights refuses (an orthophoto, a relief visualisation, an index), or one of the open workspace's own
    products (``workspace_dir``: the block cannot be its own reference).  Reads a file's header only."""
    from .layers import DTM_HILLSHADE, HILLSHADE, KIND_PROPERTY

    if layer is None or not layer.isValid():
        return ""
    kind = layer.customProperty(KIND_PROPERTY, "")
    if kind in (HILLSHADE, DTM_HILLSHADE):
        return "a hillshade (a picture of its elevation model): choose the DSM or DTM layer itself"
    path = local_file(layer)
    if path is None:
        provider = layer.dataProvider()
        if provider is not None and provider.bandCount() >= 1 and provider.dataType(1) in IMAGE_TYPES:
            return "a rendered map (colours), not heights"
        return ""  # a WCS layer or a remote raster: judged when it is saved
    if workspace_dir:
        root = os.path.normcase(os.path.realpath(workspace_dir))
        if os.path.normcase(os.path.realpath(path)).startswith(root + os.sep):
            return "a product of this workspace: the block cannot be its own reference"
    try:
        st = os.stat(path)
    except OSError:
        return ""
    key = (path, st.st_size, st.st_mtime_ns)
    if key not in _NOT_HEIGHTS_CACHE:
        from osgeo import gdal

        from ..core.io.raster import not_heights

        try:
            ds = gdal.OpenEx(path, gdal.OF_RASTER | gdal.OF_READONLY)
        except RuntimeError:  # QGIS reads it, GDAL not as a file: judged by the reader when it is used
            ds = None
        _NOT_HEIGHTS_CACHE[key] = not_heights(ds) if ds is not None and ds.RasterCount else ""
        ds = None
    return _NOT_HEIGHTS_CACHE[key]


def describe(layer):
    return f"'{layer.name()}' ({layer.providerType()}: {layer.source()[:200]})"


def _projected(crs):
    return crs.isValid() and not crs.isGeographic() and crs.authid() not in WEB_MERCATOR


def target_crs(layer, other=None, centre_lonlat=None):
    """The CRS a layer is saved in: its own when projected (not Web Mercator), else ``other``'s, else UTM."""
    if _projected(layer.crs()):
        return layer.crs()
    if other is not None and _projected(other.crs()):
        return other.crs()
    if centre_lonlat is None:
        raise ReferenceLayerError(f"reference layer {describe(layer)} is in {layer.crs().authid()}, which is no "
                                  "true-scale grid: give the other reference in a projected CRS, or photos with EXIF "
                                  "GPS (the UTM zone is taken from them)")
    from ..core.geometry.crs import utm_epsg_for_lonlat

    return QgsCoordinateReferenceSystem(f"EPSG:{utm_epsg_for_lonlat(*centre_lonlat)}")


def _transform(rect, src, dst, context=None):
    if src == dst:
        return QgsRectangle(rect)
    ct = QgsCoordinateTransform(src, dst, context or QgsProject.instance().transformContext())
    return ct.transformBoundingBox(rect)


def gps_lonlat(workspace_dir):
    """[(lon, lat)] of the workspace's photos that carry EXIF GPS."""
    from ..core.project.workspace import Workspace

    out = []
    for im in Workspace.open(workspace_dir).data.get("images", []):
        g = im.get("gps")
        if g and g[0] is not None and g[1] is not None:
            out.append((float(g[0]), float(g[1])))
    return out


def gps_extent(lonlat, crs, margin=MIN_MARGIN, context=None):
    """The photos' GPS positions' box in ``crs``, plus ``margin`` metres or half the box's size (the larger)."""
    wgs = QgsCoordinateReferenceSystem("EPSG:4326")
    ct = QgsCoordinateTransform(wgs, crs, context or QgsProject.instance().transformContext())
    pts = [ct.transform(QgsPointXY(lon, lat)) for lon, lat in lonlat]
    xs, ys = [p.x() for p in pts], [p.y() for p in pts]
    m = max(margin, 0.5 * max(max(xs) - min(xs), max(ys) - min(ys)))
    return QgsRectangle(min(xs) - m, min(ys) - m, max(xs) + m, max(ys) + m)


def _grid(extent, res, what, layer, progress):
    """(extent snapped to ``res``, columns, rows, resolution): coarser when it exceeds MAX_PIXELS."""
    area = extent.width() * extent.height()
    if area <= 0:
        raise ReferenceLayerError(f"reference {what} {describe(layer)}: the extent to save is empty "
                                  f"({extent.toString(2)})")
    if area / (res * res) > MAX_PIXELS:
        coarser = math.sqrt(area / MAX_PIXELS)
        if progress is not None:
            progress.warning(f"reference {what} {layer.name()}: {extent.width():.0f} x {extent.height():.0f} m at "
                             f"{res:g} m would exceed {MAX_PIXELS} pixels: saved at {coarser:.3g} m")
        res = coarser
    x0 = math.floor(extent.xMinimum() / res) * res
    y1 = math.ceil(extent.yMaximum() / res) * res
    cols = max(1, int(math.ceil((extent.xMaximum() - x0) / res - 1e-9)))
    rows = max(1, int(math.ceil((y1 - extent.yMinimum()) / res - 1e-9)))
    return QgsRectangle(x0, y1 - rows * res, x0 + cols * res, y1), cols, rows, res


def save_layer(layer, path, extent, crs, res, what="orthophoto", progress=None, context=None):
    """Save ``layer`` over ``extent`` (in ``crs``) at ``res`` to the GeoTIFF ``path`` (through a QgsRasterPipe
    with a projector when the CRSs differ).  Returns (path, extent written, resolution)."""
    from osgeo import gdal

    provider = layer.dataProvider() if layer is not None and layer.isValid() else None
    if provider is None:
        raise ReferenceLayerError(f"reference {what} layer {describe(layer) if layer else '(none)'} is not valid")
    image = provider.dataType(1) in IMAGE_TYPES
    if what == "DSM" and image:
        raise ReferenceLayerError(f"reference DSM {describe(layer)} is a rendered image (a WMS/XYZ map), not heights: "
                                  "give a DSM file or a WCS layer")
    grid, cols, rows, res = _grid(extent, res, what, layer, progress)
    context = context or QgsProject.instance().transformContext()
    pipe = QgsRasterPipe()
    if not pipe.set(provider.clone()):
        raise ReferenceLayerError(f"reference {what} {describe(layer)}: cannot read its provider")
    if layer.crs() != crs:
        projector = QgsRasterProjector()
        projector.setCrs(layer.crs(), crs, context)
        if not pipe.insert(2, projector):
            raise ReferenceLayerError(f"reference {what} {describe(layer)}: cannot reproject it to {crs.authid()}")
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    tmp = path + ".part.tif"
    writer = QgsRasterFileWriter(tmp)
    writer.setCreateOptions(["COMPRESS=DEFLATE", "TILED=YES"])
    feedback = QgsRasterBlockFeedback()

    def progressed(value):
        if progress is not None:
            progress.report(value / 100.0, f"saving the reference {what} {layer.name()}")
            if progress.is_cancelled():
                feedback.cancel()

    feedback.progressChanged.connect(progressed)
    where = f"{grid.toString(2)} in {crs.authid()} at {res:g} per pixel ({cols} x {rows})"
    if progress is not None:
        progress.info(f"saving the reference {what} {describe(layer)}: {where}")
    try:
        err = writer.writeRaster(pipe, cols, rows, grid, crs, context, feedback)
    finally:
        # the pipe (with its provider clone) and the feedback die here, in the thread that made them: the
        # feedback and its slot refer to each other, and Python's cycle collector would delete that QObject
        # later in whatever thread runs Python then
        feedback.progressChanged.disconnect(progressed)
        del pipe, writer
    if feedback.isCanceled() or (progress is not None and progress.is_cancelled()):
        _remove(tmp)
        raise Cancelled(f"saving the reference {what} {layer.name()}")
    if int(getattr(err, "value", err)) != 0:  # NoError (3.22), Qgis.RasterFileWriterResult.Success (3.40)
        _remove(tmp)
        raise ReferenceLayerError(f"reference {what} {describe(layer)}: fetching {where} failed (writer error "
                                  f"{getattr(err, 'value', err)})")
    valid = _valid_fraction(gdal, tmp)
    if valid <= 0.0:
        _remove(tmp)
        raise ReferenceLayerError(f"reference {what} {describe(layer)} returned no data over {where}: the server did "
                                  f"not answer, or the layer does not cover the block")
    os.replace(tmp, path)
    if progress is not None:
        progress.info(f"reference {what} saved to {path} ({100.0 * valid:.0f} % of it has data)")
    return path, grid, res


def _valid_fraction(gdal, path):
    ds = gdal.Open(path)
    if ds is None:
        return 0.0
    alpha = [k for k in range(1, ds.RasterCount + 1)
             if ds.GetRasterBand(k).GetColorInterpretation() == gdal.GCI_AlphaBand]
    band = ds.GetRasterBand(alpha[0] if alpha else 1)
    a = band.ReadAsArray()
    if alpha:
        ok = a > 0
    else:
        nodata = band.GetNoDataValue()
        ok = a == a  # not NaN
        if nodata is not None:
            ok &= a != nodata
    return float(ok.mean()) if a.size else 0.0


def _remove(path):
    try:
        os.remove(path)  # noqa: QGS201 (os.remove, not QgsRasterPipe.remove)
    except OSError:
        pass


def _extent_for(layer, crs, other, extent, extent_crs, lonlat, res, context):
    """The extent (in ``crs``) to save ``layer`` over, or a ReferenceLayerError saying what to give."""
    if extent is not None and not extent.isEmpty():
        return _transform(extent, extent_crs if extent_crs is not None and extent_crs.isValid() else crs, crs,
                          context)
    if lonlat:
        return gps_extent(lonlat, crs, context=context)
    if other is not None and local_file(other) is not None:
        return _transform(other.extent(), other.crs(), crs, context)
    own = _transform(layer.extent(), layer.crs(), crs, context)
    if own.width() * own.height() / (res * res) <= MAX_PIXELS:
        return own
    raise ReferenceLayerError(f"reference layer {describe(layer)} covers {own.width() / 1000:.0f} x "
                              f"{own.height() / 1000:.0f} km and the photos carry no GPS: give the area to fetch "
                              "(REFERENCE_EXTENT, or the map extent in the dock)")


def resolve_references(ortho_layer, dsm_layer, workspace_dir, gsd=None, extent=None, extent_crs=None,
                       progress=None, context=None):
    """(orthophoto file, DSM file) for core.georef.autocontrol: a layer's own file when GDAL reads it from disk,
    else the layer saved to georef/reference-ortho.tif / georef/reference-dsm.tif of the workspace."""
    from ..core.project.layout import Layout
    from ..core.project.workspace import Workspace

    if ortho_layer is None or dsm_layer is None:
        missing = "orthophoto" if ortho_layer is None else "DSM"
        raise ReferenceLayerError(f"automatic control needs a reference {missing} layer as well")
    paths = [local_file(ortho_layer), local_file(dsm_layer)]
    if all(paths):
        return paths[0], paths[1]
    lay = Layout(Workspace.open(workspace_dir))
    lonlat = gps_lonlat(workspace_dir)
    centre = (sum(p[0] for p in lonlat) / len(lonlat), sum(p[1] for p in lonlat) / len(lonlat)) if lonlat else None
    res = float(gsd) if gsd else DEFAULT_GSD
    for k, (layer, other, what, out, r) in enumerate((
            (ortho_layer, dsm_layer, "orthophoto", lay.reference_ortho_tif, res),
            (dsm_layer, ortho_layer, "DSM", lay.reference_dsm_tif, max(2.0 * res, MIN_DSM_GSD)))):
        if paths[k]:
            continue
        crs = target_crs(layer, other, centre)
        box = _extent_for(layer, crs, other, extent, extent_crs, lonlat, r, context)
        paths[k] = save_layer(layer, out, box, crs, r, what, progress, context)[0]
    return paths[0], paths[1]


__all__ = ["DEFAULT_GSD", "MAX_PIXELS", "LayerSnapshot", "ReferenceLayerError", "gps_extent", "layer_not_heights", "local_file",
           "resolve_references", "save_layer", "snapshot", "target_crs"]


def reference_crs(ortho_path):
    """'EPSG:n' (or the WKT) of a reference orthophoto file: the CRS the automatic control's result is in (its
    own; the UTM zone's for a geographic or Web Mercator file)."""
    from ..core.georef.autocontrol.errors import AutoControlError
    from ..core.georef.autocontrol.reference import result_crs

    try:
        return result_crs(ortho_path)
    except AutoControlError as e:
        raise ReferenceLayerError(str(e)) from e
