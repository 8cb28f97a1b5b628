"""Radiometry benchmark (issue 14 item 3): the mosaic without and with the radiometric correction (vignetting and
hot spot fitted from the overlaps and removed, seams levelled by a gain field per image).

1. synthetic: a 3 x 5 block rendered with a known model (tests.synthetic.Radiometry: fall-off 1 - 0.25 r^2 +
   0.05 r^4, a 12 % hot spot with the sun at 65 deg, exposures varying 8 %, a 3 % ramp per photo): the fitted
   fall-off against the truth, the hot spot, the median brightness step across the seamlines, the unevenness of
   the mosaic against the true albedo, seconds;
2. --workspace WS (real, repeatable): a copy of a georeferenced workspace with a DSM (e.g. the demo's,
   build/demo-workspace) mosaicked both ways: the seam step before / after and the figures the fit gives.

Quicklooks of both mosaics go to docs/screenshots/radiometry-<name>-before.png / -after.png (--no-png: none).

usage: python benchmarks/radiometry.py [--workspace WS] [--out DIR] [--no-png] [--skip-synthetic]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

import numpy as np  # noqa: E402

SHOTS = os.path.join(ROOT, "docs", "screenshots")


def _quicklook(src: str, dst: str, width: int = 640) -> None:
    from osgeo import gdal

    gdal.UseExceptions()
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    ds = gdal.Open(src)
    w = min(width, ds.RasterXSize)
    gdal.Translate(dst, ds, format="PNG", width=w, height=0, resampleAlg="average")
    for extra in (dst + ".aux.xml",):
        if os.path.exists(extra):
            os.remove(extra)


def _mosaics(ws: str, out: str, dsm=None):
    from core.ortho.options import OrthoOptions
    from core.ortho.stage import build_orthophoto_workspace

    res = {}
    for on in (False, True):
        t0 = time.time()
        r = build_orthophoto_workspace(ws, OrthoOptions(dsm_path=dsm, radiometry=on,
                                                        output=os.path.join(out, f"mosaic-{'on' if on else 'off'}.tif")))
        res[on] = (r, time.time() - t0)
    return res


def _print_run(name: str, res) -> dict:
    off, t_off = res[False]
    on, t_on = res[True]
    s = on.radiometry
    print(f"\n## {name}")
    print(f"mosaic without / with the correction: {t_off:.1f} s / {t_on:.1f} s "
          f"(radiometry fit {on.timings.get('radiometry', float('nan')):.1f} s)")
    for line in on.log_lines:
        if "radiometry" in line:
            print("  " + line)
    if s:
        print(f"seam brightness step (median): {100 * s['seam_step_before']:.2f} % -> {100 * s['seam_step_after']:.2f} %")
        print(f"  on level ground ({100 * s['seam_level_fraction']:.0f} % of the seam points): "
              f"{100 * s['seam_step_level_before']:.2f} % -> {100 * s['seam_step_level_after']:.2f} %")
        print(f"overlapping images disagree (median of chunks): {100 * s['overlap_step_before']:.2f} % -> "
              f"{100 * s['overlap_step_after']:.2f} %")
    return {"seconds_off": round(t_off, 2), "seconds_on": round(t_on, 2),
            "radiometry": {k: v for k, v in s.items() if k != "camera_ids"}}


def synthetic(out: str, png: bool) -> dict:
    from tests.test_ortho import make_workspace, truth_dsm
    from tests.test_radiometry import RADII, TRUTH, _albedo_ratio, _block, _unevenness

    block = _block()
    images = os.path.join(out, "images")
    if not os.path.exists(os.path.join(out, "rendered")):
        block.render(images, radiometry=TRUTH)
        open(os.path.join(out, "rendered"), "w").close()
    shutil.rmtree(os.path.join(out, "ws"), ignore_errors=True)
    dsm = truth_dsm(block, os.path.join(out, "dsm.tif"))
    ws = make_workspace(os.path.join(out, "ws"), block, images)
    res = _mosaics(ws, out, dsm)
    fig = _print_run("synthetic 3 x 5 block, known model", res)
    s = res[True][0].radiometry
    truth = TRUTH.falloff(np.array(RADII))
    fitted = np.array(s["falloff"]["1"])
    print("| r (of the half diagonal) | " + " | ".join(f"{r:g}" for r in RADII) + " |")
    print("|---|" + "---|" * len(RADII))
    print("| truth | " + " | ".join(f"{v:.4f}" for v in truth) + " |")
    print("| fitted | " + " | ".join(f"{v:.4f}" for v in fitted) + " |")
    print(f"worst fall-off error {100 * np.max(np.abs(fitted / truth - 1)):.2f} %")
    hot = math.exp(s["hot_spot"][0]) - 1.0
    angle = math.degrees(math.acos(np.clip(np.dot(s["antisolar"], TRUTH.antisolar()), -1, 1)))
    print(f"hot spot +{100 * hot:.1f} % (truth +{100 * TRUTH.hot:.0f} %), {s['hot_width_deg']:.1f} deg wide (truth "
          f"{TRUTH.hot_width_deg:g}), sun direction {angle:.1f} deg off")
    before, after = (_albedo_ratio(block, res[k][0].orthomosaic) for k in (False, True))
    ub, ua = _unevenness(before), _unevenness(after)
    print(f"unevenness against the true albedo (robust std of 8 x 8-cell medians about a smooth surface): "
          f"{100 * ub:.2f} % -> {100 * ua:.2f} %")
    fig.update({"falloff_truth": [round(float(v), 4) for v in truth], "falloff_fitted": fitted.tolist(),
                "hot_spot": round(hot, 4), "sun_direction_error_deg": round(angle, 2),
                "unevenness_before": round(ub, 4), "unevenness_after": round(ua, 4)})
    if png:
        _quicklook(res[False][0].orthomosaic, os.path.join(SHOTS, "radiometry-synthetic-before.png"))
        _quicklook(res[True][0].orthomosaic, os.path.join(SHOTS, "radiometry-synthetic-after.png"))
        _ratio_png(before, after, os.path.join(SHOTS, "radiometry-synthetic-albedo-ratio.png"))
    return fig


def _ratio_png(before, after, path, span=0.15):
    """Mosaic / true albedo (log, 8 x 8-cell medians), before above after, mid grey = the median, +-span."""
    import cv2

    tiles = []
    for o in (before, after):
        v = np.clip(128 + (o - np.nanmedian(o)) / span * 127, 0, 255)
        v[~np.isfinite(o)] = 0
        tiles.append(cv2.resize(v.astype(np.uint8), None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST))
    gap = np.zeros((12, tiles[0].shape[1]), np.uint8)
    cv2.imwrite(path, np.vstack([tiles[0], gap, tiles[1]]))


def _crop_pair(before: str, after: str, dst: str, box=(0.05, 0.75, 0.0, 0.45), width: int = 450) -> None:
    """Before | after of one part of two mosaics (fractions of rows and columns) at about full resolution."""
    import cv2
    from osgeo import gdal

    tiles = []
    for path in (before, after):
        a = gdal.Open(path).ReadAsArray()
        h, w = a.shape[1:]
        c = np.moveaxis(a[:3, int(box[0] * h):int(box[1] * h), int(box[2] * w):int(box[3] * w)], 0, -1)[:, :, ::-1]
        s = width / c.shape[1]
        tiles.append(cv2.resize(np.ascontiguousarray(c), None, fx=s, fy=s, interpolation=cv2.INTER_AREA))
    cv2.imwrite(dst, np.hstack([tiles[0], np.full((tiles[0].shape[0], 8, 3), 255, np.uint8), tiles[1]]))


def real(ws_src: str, out: str, png: bool) -> dict:
    name = os.path.basename(os.path.normpath(ws_src))
    ws = os.path.join(out, name)
    shutil.rmtree(ws, ignore_errors=True)
    shutil.copytree(ws_src, ws, ignore=shutil.ignore_patterns("orthomosaic*.tif", "report*", "terrain", "dense"))
    res = _mosaics(ws, out)
    fig = _print_run(f"real: {ws_src}", res)
    if png:
        tag = "demo" if "demo" in name else name
        _quicklook(res[False][0].orthomosaic, os.path.join(SHOTS, f"radiometry-{tag}-before.png"))
        _quicklook(res[True][0].orthomosaic, os.path.join(SHOTS, f"radiometry-{tag}-after.png"))
        _crop_pair(res[False][0].orthomosaic, res[True][0].orthomosaic,
                   os.path.join(SHOTS, f"radiometry-{tag}-crop.png"))
    return fig


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workspace", action="append", default=[], help="a georeferenced workspace with a DSM (copied)")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench-radiometry"))
    ap.add_argument("--no-png", action="store_true")
    ap.add_argument("--skip-synthetic", action="store_true")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    figures = {}
    if not a.skip_synthetic:
        syn_out = os.path.join(a.out, "synthetic")
        os.makedirs(syn_out, exist_ok=True)
        figures["synthetic"] = synthetic(syn_out, not a.no_png)
    for ws in a.workspace:
        figures[os.path.basename(os.path.normpath(ws))] = real(os.path.abspath(ws), a.out, not a.no_png)
    with open(os.path.join(a.out, "figures.json"), "w") as f:
        json.dump(figures, f, indent=1, default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
