"""The DSM over real low-texture farmland, pair by pair (issue 46 item 1): ``seneca_south`` (12 NIR photos of bare
fields, 1800 x 1350, EXIF GPS) or any folder of photos with EXIF GPS.

1. ``align``: Align images and Georeference (EXIF GPS) into --workspace, unless it is georeferenced already;
2. ``dsm``: the DSM stage at --quality (default full, the photos' own size), the pair cache cleared first
   (``--resume`` keeps it);
3. ``report``: per stereo pair the valid depth fraction (of the left image's rectified frame), the share of the
   pair's overlap matched at the coarsest pyramid level and in the end, its baseline / depth and heading; then, of
   the cells inside the camera centres' hull, measured / interpolated / removed, and the same split by what could
   measure a cell (its ground, at the DSM's height, seen by how many registered photos, by how many chosen pairs,
   and by a photo that holds two chosen pairs there: what fusion needs with ``min_consistent`` 2).

    nice -n 19 python benchmarks/seneca.py --workspace /tmp/seneca-ws [--images DIR] [--steps align,dsm,report]
        [--quality full] [--json out.json]

The figures of issue 46 are in docs/notes_issue46_dsm.md.
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")


def dsm_step(ws: str, quality: str, resume: bool, block: int = 0) -> None:
    import shutil

    from core.common.progress import NullProgress
    from core.dense import stage as dense
    from core.dense.options import DenseOptions

    if not resume:
        for d in glob.glob(os.path.join(ws, "dense", "pairs-*")):
            shutil.rmtree(d, ignore_errors=True)
    t0 = time.time()
    r = dense.build_dsm_workspace(ws, DenseOptions(quality=quality, block_size=block), progress=NullProgress())
    print(f"DSM stage {time.time() - t0:.0f} s: {r.pairs} pairs, {r.points} points")
    for line in r.log_lines:
        print("  " + line)


def _pair_summaries(ws: str) -> list:
    from core.dense.stereo import read_pair_summary

    out = []
    for p in sorted(glob.glob(os.path.join(ws, "dense", "pairs-*", "*.npz"))):
        out.append(read_pair_summary(p))
    return out


def coverage(ws: str, dsm: np.ndarray, gt, src: np.ndarray) -> dict:
    """Per hull cell: photos that see it, chosen pairs that see it (both photos), and whether a photo holds two
    chosen pairs there; the source split by those classes."""
    from core.dense import grid as gridding
    from core.dense.block import load_block
    from core.dense.options import DenseOptions
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    lay = Layout(Workspace.open(ws))
    block = load_block(lay, DenseOptions(), lambda s: None)
    off = block.offset
    h, w = dsm.shape
    xs = gt[0] + (np.arange(w) + 0.5) * gt[1]
    ys = gt[3] + (np.arange(h) + 0.5) * gt[5]
    gx, gy = np.meshgrid(xs, ys)
    grid_ = type("G", (), {})()
    centres = np.array([v.centre[:2] + off[:2] for v in block.views.values()])
    hull_poly = gridding.convex_hull_xy(centres)
    from matplotlib.path import Path

    hull = Path(hull_poly).contains_points(np.column_stack([gx.ravel(), gy.ravel()])).reshape(h, w)
    del grid_
    zfill = np.where(np.isfinite(dsm), dsm, np.nanmedian(dsm))
    pts = np.column_stack([gx[hull] - off[0], gy[hull] - off[1], zfill[hull] - off[2]])
    sees = {}
    for iid, v in block.views.items():
        pc = pts @ v.R.T + v.t
        k, dist = v.camera_matrix()
        import cv2

        ok = pc[:, 2] > 0
        uv = np.full((len(pts), 2), -1.0)
        if ok.any():
            proj, _ = cv2.projectPoints(pc[ok].reshape(-1, 1, 3), np.zeros(3), np.zeros(3), k, dist)
            uv[ok] = proj.reshape(-1, 2)
        sees[iid] = ok & (uv[:, 0] >= 0) & (uv[:, 0] < v.width) & (uv[:, 1] >= 0) & (uv[:, 1] < v.height)
    n_photos = np.sum(list(sees.values()), axis=0)
    n_pairs = np.zeros(len(pts), int)
    per_image = {iid: np.zeros(len(pts), int) for iid in block.views}
    for p in block.pairs:
        both = sees[p.i] & sees[p.j]
        n_pairs += both
        per_image[p.i] += both
        per_image[p.j] += both
    fusable = np.zeros(len(pts), bool)
    for iid in block.views:
        fusable |= per_image[iid] >= 2
    s = src[hull]
    classes = {"seen by <2 photos": n_photos < 2,
               ">=2 photos, no chosen pair": (n_photos >= 2) & (n_pairs == 0),
               "one chosen pair, no photo with 2": (n_pairs >= 1) & ~fusable,
               "a photo with 2 chosen pairs": fusable}
    out = {"hull_cells": int(hull.sum()), "classes": {}}
    for name, m in classes.items():
        n = int(m.sum())
        out["classes"][name] = {"share": n / max(1, len(s)),
                                "measured": float((s[m] == 1).mean()) if n else 0.0,
                                "interpolated": float((s[m] == 2).mean()) if n else 0.0,
                                "removed": float((s[m] == 3).mean()) if n else 0.0}
    # what any two photos seeing a cell could give: the chosen pairs against all the candidate pairs
    out["photos_hist"] = {int(k): int((n_photos == k).sum()) for k in range(0, int(n_photos.max()) + 1)}
    return out


def report_step(ws: str, as_json: str) -> dict:
    from core.io import raster
    from core.project.workspace import Workspace

    st = Workspace.open(ws).stage("dsm")
    res = st.get("results") or {}
    pairs = _pair_summaries(ws)
    print(f"{'pair':24s} {'valid':>6s} {'ovl':>6s} {'coarse':>6s} {'relerr':>7s} {'az':>6s} {'disp':>10s} note")
    vals = []
    for s in pairs:
        if s.get("skipped"):
            print(f"{s['i'][:10] + '+' + s['j'][:10]:24s} skipped: {s['skipped']}")
            continue
        pyr = s.get("pyramid") or {}
        vals.append(s.get("valid_fraction", 0.0))
        print(f"{s['i'][4:8] + '+' + s['j'][4:8]:24s} {s.get('valid_fraction', 0):6.3f} "
              f"{pyr.get('overlap_matched', 0):6.3f} {pyr.get('coarsest_matched', 0):6.3f} "
              f"{s.get('rel_err', 0):7.5f} {s.get('baseline_azimuth', 0):6.1f} {str(s.get('disparities')):>10s}")
    if vals:
        print(f"pairs {len(vals)}: valid median {np.median(vals):.3f}, min {min(vals):.3f}, "
              f"under 0.12: {sum(v < 0.12 for v in vals)}")
    print(f"DSM record: measured {res.get('MEASURED_FRACTION')}, interpolated {res.get('INTERPOLATED_FRACTION')}, "
          f"removed {res.get('REMOVED_FRACTION')} (inside the camera hull)")
    outs = st.get("outputs") or {}
    dsm, gt, _ = raster.read_dsm(os.path.join(ws, outs["dsm"]))
    src, _, _ = raster.read_dsm(os.path.join(ws, outs["dsm_source"]))
    src = np.nan_to_num(src).astype(np.uint8)
    cov = coverage(ws, dsm, gt, src)
    print(f"hull cells {cov['hull_cells']}; photos seeing a hull cell: {cov['photos_hist']}")
    for name, c in cov["classes"].items():
        print(f"  {name:34s} {100 * c['share']:5.1f} % of the hull: measured {100 * c['measured']:5.1f} %, "
              f"interpolated {100 * c['interpolated']:5.1f} %, removed {100 * c['removed']:4.1f} %")
    out = {"pairs": pairs, "results": res, "coverage": cov}
    if as_json:
        with open(as_json, "w") as f:
            json.dump(out, f, indent=1, default=str)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--images", default=os.path.join(DATA, "seneca_south", "images"))
    ap.add_argument("--workspace", default="/tmp/seneca-ws")
    ap.add_argument("--steps", default="align,dsm,report")
    ap.add_argument("--quality", default="full")
    ap.add_argument("--resume", action="store_true", help="keep the pair cache of an earlier run")
    ap.add_argument("--json", default="")
    ap.add_argument("--block", type=int, default=0, help="the SGBM block (0: the stage's automatic one)")
    args = ap.parse_args()
    steps = args.steps.split(",")
    if "align" in steps:
        from dense import ensure_georeferenced  # benchmarks/dense.py: Align images + Georeference (EXIF GPS)

        ensure_georeferenced(args.images, args.workspace, None)
    if "dsm" in steps:
        dsm_step(args.workspace, args.quality, args.resume, args.block)
    if "report" in steps:
        report_step(args.workspace, args.json)


if __name__ == "__main__":
    main()
