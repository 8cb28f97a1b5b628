"""The terrain products in the products section: the DTM (ground share, interpolated share, preview), the
classified point cloud, the contours and the relief visualisations (greyscale previews in RVT's display
ranges).  Empty when the workspace has no DTM and no relief visualisation."""
from __future__ import annotations

import math
import os
from typing import List, Tuple

import numpy as np

from ...io.raster import RasterError, RasterFile
from ...project.stages import RELIEF, TERRAIN
from ...terrain.options import VISUALISATIONS
from ..context import ReportContext
from ..figures import draw_dem, embed, equal_xy, new_figure
from ..html import esc, kv, num
from ..labels import t

_LABELS = dict(VISUALISATIONS)


def _read(path: str, max_side: int = 700):
    """(array at most ``max_side`` cells a side with NaN for nodata, extent, cell size, metadata) or None."""
    try:
        with RasterFile(path, "terrain product") as r:
            w, h = r.width, r.height
            step = max(1, int(math.ceil(max(w, h) / max_side)))
            z = r.read(1, out_shape=(max(1, h // step), max(1, w // step))).astype(float)
            nd, gt, metadata = r.nodata(1), r.geotransform or (0.0, 1.0, 0.0, 0.0, 0.0, 1.0), r.metadata()
    except RasterError:
        return None
    if nd is not None:
        z[z == nd] = np.nan
    extent = (gt[0], gt[0] + gt[1] * w, gt[3] + gt[5] * h, gt[3])
    return z, extent, abs(gt[1]) * w / z.shape[1], metadata


def subsection(ctx: ReportContext) -> str:
    """The terrain products' HTML ('' when there are none)."""
    lay = ctx.d.layout
    dtm = lay.dtm()
    terrain = ctx.d.stage_record(TERRAIN)
    relief = [(k, lay.resolve(p)) for k, p in sorted((ctx.d.stage_record(RELIEF).get("outputs") or {}).items())
              if os.path.isfile(lay.resolve(p))]
    if not dtm and not relief:
        return ""
    parts = ["<h3>" + esc(t("Terrain (DTM)")) + "</h3>"]
    if dtm:
        parts.append(_dtm(ctx, dtm, terrain))
    if relief:
        parts.append(_relief(relief))
    return "".join(parts)


def _dtm(ctx: ReportContext, path: str, rec: dict) -> str:
    res = rec.get("results") or {}
    out = rec.get("outputs") or {}
    info: List[Tuple[str, str]] = [("File", esc(ctx.d.layout.rel(path)))]
    gf, interp = num(res.get("ground_fraction")), num(res.get("interpolated_fraction"))
    if gf is not None:
        info.append(("DSM cells on the ground (SMRF ground filter)", f'<span data-key="dtm.ground">{gf:.3f}</span>'))
        ctx.figures["DTM_GROUND_FRACTION"] = gf
    if interp is not None:
        info.append(("DTM cells interpolated (under objects, in holes)", f"{interp:.3f}"))
        ctx.figures["DTM_INTERPOLATED_FRACTION"] = interp
    if out.get("dtm_source"):
        info.append(("Measured / interpolated cells", esc(out["dtm_source"]) + " (1 = measured ground, "
                                                                              "2 = interpolated)"))
    if out.get("point_cloud"):
        info.append(("Classified point cloud", f"{esc(out['point_cloud'])}: {res.get('ground_points', 0)} of "
                                               f"{res.get('points', 0)} points ground (ASPRS class 2)"))
    if out.get("contours"):
        info.append(("Contours", f"{esc(out['contours'])}: {res.get('contour_lines', 0)} lines every "
                                 f"{num(res.get('contour_interval')) or 0:g} m"))
    got = _read(path)
    if got is None:
        return kv(info) + f'<p class="warn">{esc(path)} cannot be read</p>'
    z, extent, cell, _ = got
    fig = new_figure(7.5, 6.0)
    ax = fig.add_subplot(111)
    valid = np.isfinite(z)
    shown = draw_dem(fig, ax, z, valid, cell, cell, extent)
    if shown is not None:
        info.append(("Height range (1st–99th percentile)", f"{shown[0]:.2f} – {shown[1]:.2f} m"))
    equal_xy(ax)
    ax.grid(False)
    return kv(info) + embed(fig, "DTM preview", "DTM (bare earth) preview with hillshade.")


def _relief(items: List[Tuple[str, str]]) -> str:
    n = len(items)
    cols = min(3, n)
    rows = int(math.ceil(n / cols))
    fig = new_figure(3.4 * cols, 3.2 * rows)
    names = []
    for i, (key, path) in enumerate(items):
        ax = fig.add_subplot(rows, cols, i + 1)
        got = _read(path, 500)
        vis = key.split("-", 1)[1] if "-" in key else key
        surface = key.split("-", 1)[0].upper() if "-" in key else "DTM"
        title = f"{_LABELS.get(vis, vis)} ({surface})"
        names.append(f"{esc(title)}: {esc(os.path.basename(path))}")
        if got is None:
            ax.set_title(title + ": unreadable", fontsize=8)
            continue
        z, extent, _, meta = got
        lo, hi = num(meta.get("DISPLAY_MIN")), num(meta.get("DISPLAY_MAX"))
        if lo is None or hi is None or hi <= lo:
            lo, hi = np.nanpercentile(z, [2, 98]) if np.isfinite(z).any() else (0.0, 1.0)
        ax.imshow(z, extent=extent, cmap="gray", vmin=lo, vmax=hi, interpolation="nearest")
        ax.set_title(title, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    return ("<h3>" + esc(t("Relief visualisations")) + "</h3><p>" + "<br>".join(names) + "</p>"
            + embed(fig, "Relief visualisations", "Relief visualisations (rvt-py, RVT's default parameters scaled to "
                                                  "the cell size), in RVT's display ranges."))
