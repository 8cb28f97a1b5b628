"""Heights for GCPs from a DSM / DTM raster layer (e.g. an ALS DSM): bilinear interpolation between
the four nearest cell centres, in the raster's own CRS."""
import math

from qgis.core import QgsCoordinateTransform, QgsPointXY, QgsProject, QgsRectangle


def bilinear(values, fx, fy):
    """Bilinear interpolation in a 2x2 cell block ``values[row][col]`` (row 0 = upper) at the fractions
    ``fx`` (to the right) and ``fy`` (down) from the upper-left centre.  Cells that are None (nodata)
    are left out and the weights of the others renormalised; None when all four are nodata or the
    point lies on a missing cell's side of the block with weight < 0.25 left (a hole edge)."""
    w = [[(1 - fx) * (1 - fy), fx * (1 - fy)], [(1 - fx) * fy, fx * fy]]
    total = acc = 0.0
    for r in range(2):
        for c in range(2):
            v = values[r][c]
            if v is None or not math.isfinite(v):
                continue
            total += w[r][c]
            acc += w[r][c] * v
    if total < 0.25:
        return None
    return acc / total


def sample_height(layer, point, point_crs, band=1, project=None):
    """Height of ``layer`` at ``point`` (QgsPointXY in ``point_crs``), bilinear; None outside / nodata."""
    if layer is None or not layer.isValid():
        return None
    project = project or QgsProject.instance()
    p = QgsPointXY(point)
    if point_crs is not None and point_crs.isValid() and layer.crs().isValid() and point_crs != layer.crs():
        try:
            p = QgsCoordinateTransform(point_crs, layer.crs(), project).transform(p)
        except Exception:  # noqa: BLE001 - QgsCsException: the point has no place in the raster CRS
            return None
    ext = layer.extent()
    nx, ny = layer.width(), layer.height()
    if nx <= 0 or ny <= 0 or not ext.contains(p):
        return None
    rx, ry = ext.width() / nx, ext.height() / ny
    # position in cell-centre units, 0 at the centre of the upper-left cell
    cx = (p.x() - ext.xMinimum()) / rx - 0.5
    cy = (ext.yMaximum() - p.y()) / ry - 0.5
    c0 = min(max(int(math.floor(cx)), 0), max(nx - 2, 0))
    r0 = min(max(int(math.floor(cy)), 0), max(ny - 2, 0))
    fx = min(max(cx - c0, 0.0), 1.0) if nx > 1 else 0.0
    fy = min(max(cy - r0, 0.0), 1.0) if ny > 1 else 0.0
    cols, rows = min(2, nx), min(2, ny)
    block_ext = QgsRectangle(ext.xMinimum() + c0 * rx, ext.yMaximum() - (r0 + rows) * ry,
                             ext.xMinimum() + (c0 + cols) * rx, ext.yMaximum() - r0 * ry)
    block = layer.dataProvider().block(band, block_ext, cols, rows)
    if block is None or not block.isValid():
        return None
    vals = [[None, None], [None, None]]
    for r in range(2):
        for c in range(2):
            rr, cc = min(r, rows - 1), min(c, cols - 1)
            if block.isNoData(rr, cc):
                continue
            vals[r][c] = float(block.value(rr, cc))
    return bilinear(vals, fx, fy)
