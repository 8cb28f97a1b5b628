"""The products section: DSM and orthomosaic previews (hillshade), resolution, valid fraction; then the terrain
products (:mod:`.terrain`)."""
from __future__ import annotations

import math
import os

import numpy as np

from ...io.raster import RasterError, RasterFile
from ..context import ReportContext, Skip
from ..errors import ReportError
from ..figures import draw_dem, draw_image, embed, equal_xy, new_figure
from ..html import esc, kv, num, raster_crs_name
from ..labels import t
from . import terrain


def section(ctx: ReportContext) -> str:
    dsm = ctx.d.dsm_path()
    ortho = ctx.d.orthomosaic_path()
    if not dsm and not ortho:
        raise Skip("no DSM or orthomosaic yet: run 'Build DSM' and 'Build orthophoto'.")
    parts = []
    if dsm:
        parts.append(_raster(ctx, dsm, "DSM", dem=True))
    else:
        parts.append('<p class="skip">No DSM yet.</p>')
    if ortho:
        parts.append(_raster(ctx, ortho, "Orthomosaic", dem=False))
    else:
        parts.append('<p class="skip">No orthomosaic yet.</p>')
    parts.append(terrain.subsection(ctx))  # DTM, contours, relief visualisations ('' without them)
    return "".join(parts)


def _raster(ctx: ReportContext, path: str, title: str, dem: bool) -> str:
    try:
        ds = RasterFile(path, title.lower())
    except RasterError as e:
        return f'<h3>{esc(_shown(title))}</h3><p class="warn">{esc(path)} cannot be read: {esc(e.__cause__ or e)}</p>'
    w, h = ds.width, ds.height
    gt = ds.geotransform or (0.0, 1.0, 0.0, 0.0, 0.0, 1.0)  # GDAL's default for a raster with none
    step = max(1, int(math.ceil(max(w, h) / 900)))
    bw, bh = max(1, w // step), max(1, h // step)
    nodata = ds.nodata(1)
    info = [("File", esc(os.path.relpath(path, ctx.d.ws.root))), ("Size", f"{w} × {h} cells, {ds.count} "
                                                                          "band(s)"),
            ("Resolution", f"{abs(gt[1]):.4g} × {abs(gt[5]):.4g} m"),
            ("CRS", esc(raster_crs_name(ds.crs_wkt)))]
    fig = new_figure(7.5, 6.0)
    ax = fig.add_subplot(111)
    extent = (gt[0], gt[0] + gt[1] * w, gt[3] + gt[5] * h, gt[3])
    try:
        if dem:
            z = ds.read(1, out_shape=(bh, bw)).astype(float)
        else:
            arr, alpha = _read_image(ds, bw, bh)
    except RasterError as e:  # a damaged tile: GDAL's "IReadBlock failed ... TIFFReadEncodedTile() failed"
        raise ReportError(f"the {title.lower()} {path} is damaged: GDAL cannot read its cells ({e.__cause__ or e}). "
                          f"Run the stage that writes it again ('{'Build DSM' if dem else 'Build orthophoto'}')") from e
    finally:
        ds.close()
    if dem:
        valid = np.isfinite(z) & ((z != nodata) if nodata is not None else True)
        frac = float(valid.mean())
        zz = np.where(valid, z, np.nan)
        shown = draw_dem(fig, ax, zz, valid, abs(gt[1]) * w / bw, abs(gt[5]) * h / bh, extent)
        if shown is not None:
            info.append(("Height range (1st–99th percentile)", f"{shown[0]:.2f} – {shown[1]:.2f} m"))
    else:
        frac = float(alpha.mean())
        draw_image(ax, arr, alpha, extent)
    info.append(("Valid fraction (cells with data)", f'<span data-key="{title.lower()}.valid">{frac:.3f}</span>'
                                                      + (f" (estimated on a 1:{step} overview)" if step > 1 else "")))
    stage_vf = num(((ctx.d.manifest.get("stages", {}).get("dsm" if dem else "orthophoto") or {}).get("results")
                     or {}).get("VALID_FRACTION"))
    if stage_vf is not None:
        info.append(("Valid fraction inside the camera centres' convex hull (as the stage reports it)",
                     f"{stage_vf:.3f}"))
    results = (ctx.d.manifest.get("stages", {}).get("dsm") or {}).get("results") or {}
    if dem and num(results.get("MEASURED_FRACTION")) is not None:
        info.append(("Inside that hull: measured / interpolated (filled holes) / removed as blunders "
                     "(dense/dsm-source.tif)",
                     f"{num(results['MEASURED_FRACTION']):.3f} / {num(results.get('INTERPOLATED_FRACTION')) or 0:.3f}"
                     f" / {num(results.get('REMOVED_FRACTION')) or 0:.3f}"))
    if not dem:
        info += _seam_rows((ctx.d.manifest.get("stages", {}).get("orthophoto") or {}).get("results") or {})
    # the key figure is the stage's own (the Processing output VALID_FRACTION): inside the camera centres'
    # convex hull; the whole raster's share is shown beside it above
    ctx.figures[f"{'DSM' if dem else 'ORTHO'}_VALID_FRACTION"] = stage_vf if stage_vf is not None else frac
    ctx.figures[f"{'DSM' if dem else 'ORTHO'}_RESOLUTION"] = abs(gt[1])
    equal_xy(ax)
    ax.grid(False)
    preview = (t("DSM preview with hillshade (sun from the north-west, 45°).") if dem
               else t("{} preview.").format(_shown(title)))
    return f"<h3>{esc(_shown(title))}</h3>" + kv(info) + embed(fig, f"{title} preview", preview)


def _shown(title: str) -> str:
    """A product's title in the report's language (its data keys stay English)."""
    return {"DSM": t("DSM"), "Orthomosaic": t("Orthomosaic")}.get(title, title)


def _seam_rows(results) -> list:
    """The orthophoto stage's seam figures (core.ortho.radiometry.seam_figures), where it recorded them."""
    after, before = num(results.get("seam_step_after")), num(results.get("seam_step_before"))
    if after is None:
        return []
    rows = [("Brightness step across the seamlines (median; before → after the radiometric correction)",
             (f"{100 * before:.1f} % → " if before is not None else "")
             + f'<span data-key="ortho.seam_step">{100 * after:.1f}</span> %')]
    level, share = num(results.get("seam_step_level_after")), num(results.get("seam_level_fraction"))
    if level is not None and share is not None:
        lb = num(results.get("seam_step_level_before"))
        rows.append((f"The same over level ground ({100 * share:.0f} % of the seams; at crowns, walls and roof "
                     "edges two photos see different sides, which no brightness model levels)",
                     (f"{100 * lb:.1f} % → " if lb is not None else "")
                     + f'<span data-key="ortho.seam_step_level">{100 * level:.1f}</span> %'))
    return rows


def _read_image(ds: RasterFile, bw: int, bh: int):
    """The first three bands at (bw, bh) cells, and where they hold data (the alpha band, else the mask)."""
    from osgeo import gdal

    arr = np.dstack([ds.read(i + 1, out_shape=(bh, bw)).astype(float) for i in range(min(3, ds.count))])
    alpha = None
    for i in range(ds.count):
        if ds.band(i + 1).GetColorInterpretation() == gdal.GCI_AlphaBand:
            alpha = ds.read(i + 1, out_shape=(bh, bw)) > 0
    if alpha is None:
        try:
            mb = ds.band(1).GetMaskBand().ReadAsArray(buf_xsize=bw, buf_ysize=bh)
        except RuntimeError as e:
            raise RasterError(f"{ds.what} {ds.path}: its mask cannot be read ({e})") from e
        alpha = mb > 0
    return arr, alpha
