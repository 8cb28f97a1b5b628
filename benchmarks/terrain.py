"""Terrain benchmark on real data (Toledo): DTM under the two houses, timings, relief screenshots.

1. the DTM of the workspace's DSM (core.terrain.stage.build_dtm, into --out, the workspace is not changed):
   seconds, ground share, interpolated share;
2. under each of the two houses of the Toledo block (footprints: the DSM cells more than 1 m above the DTM in a
   box around each house): the DTM minus a plane fitted to the measured ground 2-10 m around the house (median,
   95th percentile and largest absolute difference; the issue asks for <= 0.5 m), and the roof height above the
   DTM;
3. the relief visualisations of the DTM (seconds each, the radii in cells) and PNG screenshots of the sky-view
   factor and the simple local relief model (greyscale in RVT's display ranges) into --screenshots.

usage: python benchmarks/terrain.py [--workspace WS] [--out DIR] [--screenshots DIR]

WS: a georeferenced Toledo workspace with a DSM, e.g. the one `make demo` writes (build/demo-workspace: the 18
sample images of sample/toledo at half quality).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

# boxes (UTM 17N: xmin, ymin, xmax, ymax) around the two houses of the Toledo block
HOUSES = {"north house": (274917.8, 4603365.1, 274939.0, 4603377.7),
          "middle house": (274902.0, 4603317.7, 274931.4, 4603343.0)}


def house_figures(dsm, dtm, source, gt):
    from scipy import ndimage

    cell = gt[1]
    h, w = dsm.shape
    rr, cc = np.mgrid[0:h, 0:w]
    xs, ys = gt[0] + (cc + 0.5) * cell, gt[3] - (rr + 0.5) * cell
    out = {}
    for name, (x0, y0, x1, y1) in HOUSES.items():
        box = (xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1)
        roof = box & (np.nan_to_num(dsm - dtm) > 1.0)
        lab, n = ndimage.label(roof)
        if n == 0:
            out[name] = {"error": "no roof found (DSM not above the DTM)"}
            continue
        sizes = ndimage.sum(roof, lab, range(1, n + 1))
        roof = ndimage.binary_fill_holes(lab == 1 + int(np.argmax(sizes)))
        dist = ndimage.distance_transform_edt(~roof) * cell
        ring = (dist > 2) & (dist < 10) & (source == 1) & np.isfinite(dtm)
        a = np.column_stack([xs[ring], ys[ring], np.ones(ring.sum())])
        coef, *_ = np.linalg.lstsq(a, dtm[ring], rcond=None)
        plane = coef[0] * xs + coef[1] * ys + coef[2]
        dev = (dtm - plane)[roof]
        out[name] = {"roof_m2": round(float(roof.sum() * cell * cell), 1),
                     "roof_above_dtm_m": round(float(np.nanmedian((dsm - dtm)[roof])), 2),
                     "dtm_minus_ground_median_m": round(float(np.median(dev)), 3),
                     "dtm_minus_ground_p95_abs_m": round(float(np.percentile(np.abs(dev), 95)), 3),
                     "dtm_minus_ground_max_abs_m": round(float(np.abs(dev).max()), 3),
                     "ground_ring_residual_sd_m": round(float(np.std((dtm - plane)[ring])), 3),
                     "interpolated_share": round(float(np.mean(source[roof] == 2)), 3)}
    return out


def screenshot(path_tif, png, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from osgeo import gdal

    ds = gdal.Open(path_tif)
    z = ds.GetRasterBand(1).ReadAsArray().astype(float)
    nd = ds.GetRasterBand(1).GetNoDataValue()
    if nd is not None:
        z[z == nd] = np.nan
    meta = ds.GetMetadata()
    lo, hi = float(meta["DISPLAY_MIN"]), float(meta["DISPLAY_MAX"])
    gt = ds.GetGeoTransform()
    extent = (gt[0], gt[0] + gt[1] * ds.RasterXSize, gt[3] + gt[5] * ds.RasterYSize, gt[3])
    fig, ax = plt.subplots(figsize=(8, 8))
    ax.imshow(z, cmap="gray", vmin=lo, vmax=hi, extent=extent, interpolation="nearest")
    ax.set_title(title, fontsize=10)
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.tick_params(labelsize=7)
    fig.savefig(png, dpi=90, bbox_inches="tight")
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workspace", default=os.path.join(ROOT, "build", "demo-workspace"))
    ap.add_argument("--out", default="/tmp/archaeoortho-terrain-bench")
    ap.add_argument("--screenshots", default=os.path.join(ROOT, "docs", "screenshots"))
    args = ap.parse_args(argv)

    from core.io import raster
    from core.project.layout import Layout
    from core.project.workspace import Workspace
    from core.terrain.stage import build_dtm, relief

    lay = Layout(Workspace.open(args.workspace))
    dsm_path = lay.dsm()
    if not dsm_path:
        sys.exit(f"{args.workspace} has no DSM: run the pipeline first (make demo)")
    os.makedirs(args.out, exist_ok=True)
    t0 = time.time()
    r = build_dtm(dsm_path, os.path.join(args.out, "dtm.tif"), contour_interval=0.5)
    t_dtm = time.time() - t0
    dsm, gt, _ = raster.read_dsm(dsm_path)
    dtm, _, _ = raster.read_dsm(r.dtm_path)
    source, _, _ = raster.read_dsm(r.source_path)
    figures = {"dsm": dsm_path, "dsm_cells": list(dsm.shape), "cell_m": gt[1], "dtm_seconds": round(t_dtm, 2),
               "ground_fraction": round(r.ground_fraction, 4), "interpolated_fraction": round(r.interpolated_fraction, 4),
               "contour_lines_0.5m": r.contour_lines, "houses": house_figures(dsm, dtm, source, gt)}
    rel = relief(r.dtm_path, ["svf", "slrm", "openness_pos", "vat"], os.path.join(args.out, "relief"))
    figures["relief_seconds"] = rel.timings
    figures["relief_radii_cells"] = rel.radii
    os.makedirs(args.screenshots, exist_ok=True)
    for key, title in (("svf", "Sky-view factor of the DTM (RVT defaults: 16 directions, 10 m)"),
                       ("slrm", "Simple local relief model of the DTM (RVT default: 20 m), -2 .. 2 m")):
        png = os.path.join(args.screenshots, f"terrain-toledo-{key}.png")
        screenshot(rel.paths[key], png, title)
        figures.setdefault("screenshots", []).append(png)
    print(json.dumps(figures, indent=2))
    worst = max((v.get("dtm_minus_ground_max_abs_m", 99) for v in figures["houses"].values()), default=99)
    print(f"DTM under the houses: largest |DTM - ground around| {worst:.3f} m (goal <= 0.5 m)")


if __name__ == "__main__":
    main()
