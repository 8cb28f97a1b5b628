"""Orthophoto benchmark on real data (Toledo, 57 DJI images): prints comparable figures.

1. per-image true orthophotos of every image, and how well overlapping ones agree: phase correlation of
   128 x 128-cell windows over their common area, the median shift per pair, the distribution over pairs
   (the issue asks for <= 1.5 px for >= 90 % of the overlapping pairs);
2. peak RSS of the orthomosaic (a child process per run) at the default resolution and at half of it
   (4 x the output area): tiles, not one array, so the second must stay within 1.3 x the first;
3. one image taken out of the block and orthorectified alone on the block's DSM, from GCPs transferred from
   the block (sparse points seen in it) by space resection, and from its known orientation: its shift
   against the mosaic of the other images.

usage: python benchmarks/ortho.py --workspace WS [--out DIR] [--skip-rss] [--skip-single] [--pairs N]

WS is a georeferenced workspace of the Toledo images with a DSM (core.dense.build_dsm_workspace).  Without a
DSM the script makes one by interpolating the sparse points (and says so).  --build makes the workspace from
../shared/data/toledo (align all 57 images, EXIF GPS georeference, CPU DSM: 10-30 min on 2 cores).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import resource
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402

TOLEDO = os.path.join(os.path.dirname(ROOT), "shared", "data", "toledo")


def _read(path):
    from osgeo import gdal

    ds = gdal.Open(path)
    a = ds.ReadAsArray()
    if a.ndim == 2:
        a = a[None]
    return a, ds.GetGeoTransform()


def _grey(a):
    bands = a[:-1] if a.shape[0] in (2, 4) else a
    return bands.astype(np.float32).mean(axis=0)


def _phase(a, b):
    import cv2

    win = cv2.createHanningWindow((a.shape[1], a.shape[0]), cv2.CV_64F)
    (dx, dy), resp = cv2.phaseCorrelate(a.astype(np.float64), b.astype(np.float64), win)
    return dx, dy, resp


def _common_windows(a, ga, b, gb, size=128, max_windows=6, rng=None):
    """(window of a, window of b) pairs over cells valid in both (same grid, integer offsets)."""
    res = ga[1]
    dc = int(round((gb[0] - ga[0]) / res))  # column of b's origin in a
    dr = int(round((gb[3] - ga[3]) / -res))
    r0, c0 = max(0, dr), max(0, dc)
    r1, c1 = min(a.shape[1], dr + b.shape[1]), min(a.shape[2], dc + b.shape[2])
    if r1 - r0 < size or c1 - c0 < size:
        return []
    va = a[-1, r0:r1, c0:c1] > 0
    vb = b[-1, r0 - dr:r1 - dr, c0 - dc:c1 - dc] > 0
    both = (va & vb).astype(np.uint8)
    # windows fully valid in both: integral image
    ii = np.pad(both.astype(np.int64).cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    full = ii[size:, size:] - ii[:-size, size:] - ii[size:, :-size] + ii[:-size, :-size] == size * size
    rr, cc = np.nonzero(full[::16, ::16])
    if not len(rr):
        return []
    rng = rng or np.random.default_rng(0)
    pick = rng.permutation(len(rr))[:max_windows * 3]
    out = []
    taken = []
    ga_, gb_ = _grey(a), _grey(b)
    for k in pick:
        r, c = rr[k] * 16, cc[k] * 16
        if any(abs(r - t[0]) < size and abs(c - t[1]) < size for t in taken):
            continue
        taken.append((r, c))
        wa = ga_[r0 + r:r0 + r + size, c0 + c:c0 + c + size]
        wb = gb_[r0 - dr + r:r0 - dr + r + size, c0 - dc + c:c0 - dc + c + size]
        out.append((wa, wb))
        if len(out) >= max_windows:
            break
    return out


def pair_agreement(folder, names, max_pairs=0):
    """Median phase-correlation shift (px) per overlapping pair of per-image orthophotos."""
    rasters = {}
    for n in names:
        p = os.path.join(folder, os.path.splitext(n)[0] + ".tif")
        if os.path.isfile(p):
            from osgeo import gdal

            ds = gdal.Open(p)
            gt = ds.GetGeoTransform()
            rasters[n] = (p, (gt[0], gt[3], gt[0] + ds.RasterXSize * gt[1], gt[3] + ds.RasterYSize * gt[5]))
    keys = sorted(rasters)
    pairs = []
    for i, a in enumerate(keys):
        ba = rasters[a][1]
        for b in keys[i + 1:]:
            bb = rasters[b][1]
            ox = min(ba[2], bb[2]) - max(ba[0], bb[0])
            oy = min(ba[1], bb[1]) - max(ba[3], bb[3])
            if ox > 0 and oy > 0:
                pairs.append((a, b, ox * oy))
    pairs.sort(key=lambda t: -t[2])
    if max_pairs:
        pairs = pairs[:max_pairs]
    cache = {}

    def load(n):
        if n not in cache:
            if len(cache) > 12:
                cache.pop(next(iter(cache)))
            cache[n] = _read(rasters[n][0])
        return cache[n]

    results = []
    all_windows = []
    rng = np.random.default_rng(0)
    for a, b, _area in pairs:
        (ra, ga), (rb, gb) = load(a), load(b)
        wins = _common_windows(ra, ga, rb, gb, rng=rng)
        shifts = []
        for wa, wb in wins:
            dx, dy, resp = _phase(wa, wb)
            if resp > 0.05:
                shifts.append(math.hypot(dx, dy))
        if shifts:
            all_windows.extend(shifts)
            results.append((a, b, float(np.median(shifts)), len(shifts)))
    return results, all_windows


def _dist(values, label, unit="px"):
    v = np.asarray(values, dtype=float)
    if not len(v):
        print(f"{label}: none")
        return
    q = np.percentile(v, [10, 50, 75, 90, 95, 100])
    print(f"{label}: n={len(v)}  p10 {q[0]:.2f}  median {q[1]:.2f}  p75 {q[2]:.2f}  p90 {q[3]:.2f}  p95 {q[4]:.2f}  "
          f"max {q[5]:.2f} {unit}")


def sparse_dsm(ws_dir, path, res=0.5):
    """A DSM from the sparse points (linear interpolation), for a workspace without a dense DSM."""
    from scipy.interpolate import griddata

    from core.georef.stage import load_georef_model
    from core.io import raster as dsmmod

    rec, transform = load_georef_model(ws_dir)
    off = np.asarray(transform.offset, dtype=float)
    xyz = np.array([p.xyz for p in rec.points3D.values() if p.track.length() >= 3 and p.error < 2.0]) + off
    lo, hi = np.percentile(xyz[:, 2], [1, 99.5])
    xyz = xyz[(xyz[:, 2] >= lo - 5) & (xyz[:, 2] <= hi + 5)]
    grid = dsmmod.Grid.covering(xyz[:, 0].min(), xyz[:, 1].min(), xyz[:, 0].max(), xyz[:, 1].max(), res)
    xs, ys = grid.cell_centres()
    gx, gy = np.meshgrid(xs, ys)
    z = griddata(xyz[:, :2], xyz[:, 2], (gx, gy), method="linear")
    dsmmod.write_cog(path, z.astype(np.float32), grid.geotransform, transform.crs)
    return path


def build_workspace(ws_dir):
    from core.align.stage import align
    from core.common.progress import PrintProgress
    from core.dense import stage as dense
    from core.georef.options import GeorefOptions
    from core.georef.stage import georeference_workspace

    align(os.path.join(TOLEDO, "images"), ws_dir, progress=PrintProgress("align "))
    georeference_workspace(ws_dir, GeorefOptions(use_exif_gps=True, crs="EPSG:32617"), progress=PrintProgress("georef "))
    dense.build_dsm_workspace(ws_dir, progress=PrintProgress("dsm "))


def mosaic_only(args):
    """Child process of the RSS measurement: one orthomosaic, prints JSON."""
    from core.ortho.options import OrthoOptions
    from core.ortho.stage import build_orthophoto_workspace

    t0 = time.time()
    res = build_orthophoto_workspace(args.workspace, OrthoOptions(dsm_path=args.dsm, resolution=args.resolution,
                                                                  images_filter=args.filter, output=args.output))
    print(json.dumps({"seconds": time.time() - t0, "width": res.resolution and None, "resolution": res.resolution,
                      "timings": res.timings, "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))


def _run_child(args, resolution, output, extra=()):
    from _util import run_measured

    cmd = [sys.executable, os.path.abspath(__file__), "--mosaic-only", "--workspace", args.workspace,
           "--resolution", str(resolution), "--output", output] + list(extra)
    if args.dsm:
        cmd += ["--dsm", args.dsm]
    log = output + ".log"
    rc, wall, rss = run_measured(cmd, log_path=log)
    if rc != 0:
        print(open(log).read()[-3000:])
        raise SystemExit(f"mosaic run failed (exit {rc})")
    return wall, rss


def transferred_gcps(ws_dir, name, n=10):
    """GCPs for one image from the block: well-spread sparse points (track >= 4) seen in it (world coords)."""
    from core.georef.stage import load_georef_model
    from core.io import gcp as gcpmod

    rec, transform = load_georef_model(ws_dir)
    off = np.asarray(transform.offset, dtype=float)
    im = next(i for i in rec.images.values() if i.name == name)
    cands = []
    for p2 in im.points2D:
        if not p2.has_point3D():
            continue
        p3 = rec.points3D[p2.point3D_id]
        if p3.track.length() >= 4 and p3.error < 1.0:
            cands.append((np.asarray(p2.xy, dtype=float), np.asarray(p3.xyz, dtype=float) + off))
    px = np.array([c[0] for c in cands])
    cam = rec.cameras[im.camera_id]
    order = [int(np.argmin(np.hypot(px[:, 0] - cam.width / 2, px[:, 1] - cam.height / 2)))]
    while len(order) < min(n, len(cands)):
        d = np.min(np.hypot(px[:, None, 0] - px[order][None, :, 0], px[:, None, 1] - px[order][None, :, 1]), axis=1)
        order.append(int(np.argmax(d)))
    pts = [gcpmod.GroundPoint(f"B{k + 1}", *map(float, cands[i][1]),
                              observations=[gcpmod.Observation(name, float(cands[i][0][0]), float(cands[i][0][1]))])
           for k, i in enumerate(order)]
    return gcpmod.GCPSet(transform.crs, pts), rec, im, off


def shifts_against(path, mosaic_path, size=128, count=40):
    a, ga = _read(path)
    m, gm = _read(mosaic_path)
    if abs(ga[1] - gm[1]) > 1e-9:
        raise SystemExit("different resolutions")
    wins = _common_windows(a, ga, m, gm, size=size, max_windows=count)
    out = []
    for wa, wm in wins:
        dx, dy, resp = _phase(wm, wa)
        if resp > 0.05:
            out.append((dx, dy))
    return np.array(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workspace", default="")
    ap.add_argument("--dsm", default="")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench-ortho"))
    ap.add_argument("--build", action="store_true")
    ap.add_argument("--skip-rss", action="store_true")
    ap.add_argument("--skip-single", action="store_true")
    ap.add_argument("--skip-pairs", action="store_true")
    ap.add_argument("--pairs", type=int, default=0, help="largest overlaps only (0 = all pairs)")
    ap.add_argument("--single", default="DJI_0085.JPG")
    ap.add_argument("--mosaic-only", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--resolution", type=float, default=0.0, help=argparse.SUPPRESS)
    ap.add_argument("--output", default="", help=argparse.SUPPRESS)
    ap.add_argument("--filter", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    args.dsm = args.dsm or None
    if args.mosaic_only:
        return mosaic_only(args)

    from core.ortho.options import OrthoOptions, SingleImageOptions
    from core.ortho.single import orthorectify_image
    from core.ortho.stage import build_orthophoto_workspace, workspace_dsm
    from core.project.workspace import Workspace

    os.makedirs(args.out, exist_ok=True)
    if not args.workspace:
        args.workspace = os.path.join(args.out, "toledo-ws")
        if not os.path.isfile(os.path.join(args.workspace, "workspace.json")):
            if not args.build:
                raise SystemExit("give --workspace (georeferenced Toledo workspace, with a DSM) or --build")
            build_workspace(args.workspace)
    ws = Workspace.open(args.workspace)
    if not args.dsm and not workspace_dsm(ws):
        args.dsm = sparse_dsm(args.workspace, os.path.join(args.out, "sparse_dsm.tif"))
        print(f"NOTE: the workspace has no DSM; using one interpolated from the sparse points: {args.dsm}")
    dsm_used = args.dsm or workspace_dsm(ws)
    print(f"workspace {args.workspace}, DSM {dsm_used}, {len(ws.data.get('images', []))} images")

    # 1. per-image orthophotos and their agreement
    if not args.skip_pairs:
        folder = os.path.join(args.out, "per_image")
        t0 = time.time()
        res = build_orthophoto_workspace(args.workspace, OrthoOptions(
            dsm_path=args.dsm, output=os.path.join(args.out, "mosaic_all.tif"), per_image_folder=folder,
            seamlines=os.path.join(args.out, "seamlines.gpkg")))
        print(f"mosaic + {len(res.images)} per-image orthophotos at {res.resolution:g} m: {time.time() - t0:.1f} s "
              f"({', '.join(f'{k} {v:.1f}' for k, v in res.timings.items())})")
        for line in res.log_lines:
            print("  " + line)
        t0 = time.time()
        pairs, windows = pair_agreement(folder, res.images, args.pairs)
        med = [p[2] for p in pairs]
        print(f"pairwise agreement ({time.time() - t0:.1f} s): {len(pairs)} overlapping pairs with common 128 x 128 "
              "windows")
        _dist(med, "  per-pair median shift")
        _dist(windows, "  all windows")
        ok = float(np.mean(np.array(med) <= 1.5)) if med else float("nan")
        print(f"  pairs with median shift <= 1.5 px: {100 * ok:.1f} % (goal >= 90 %)")
        worst = sorted(pairs, key=lambda p: -p[2])[:5]
        print("  worst pairs: " + "; ".join(f"{a}/{b} {s:.2f} px ({n} win)" for a, b, s, n in worst))

    # 2. peak RSS at 1x and 4x the output area
    if not args.skip_rss:
        from osgeo import gdal

        p1, p2 = os.path.join(args.out, "mosaic_r1.tif"), os.path.join(args.out, "mosaic_r2.tif")
        w1, rss1 = _run_child(args, 0.0, p1)  # the default resolution (the GSD)
        d1 = gdal.Open(p1)
        r1 = d1.GetGeoTransform()[1]
        w2, rss2 = _run_child(args, r1 / 2, p2)
        d2 = gdal.Open(p2)
        print(f"orthomosaic at {r1:g} m (RESOLUTION 0 = GSD): {d1.RasterXSize} x {d1.RasterYSize} cells, {w1:.1f} s, "
              f"peak RSS {rss1:.0f} MiB")
        print(f"orthomosaic at {r1 / 2:g} m (4x the area): {d2.RasterXSize} x {d2.RasterYSize} cells, {w2:.1f} s, "
              f"peak RSS {rss2:.0f} MiB; ratio {rss2 / rss1:.2f} (goal <= 1.3), cells ratio "
              f"{d2.RasterXSize * d2.RasterYSize / (d1.RasterXSize * d1.RasterYSize):.2f}")

    # 3. one image alone on the block's DSM
    if not args.skip_single:
        from core.geometry import camera as gcam

        name = args.single
        mos = os.path.join(args.out, "mosaic_without_single.tif")
        res = build_orthophoto_workspace(args.workspace, OrthoOptions(dsm_path=args.dsm, images_filter=f"!{name}",
                                                                      output=mos))
        img = os.path.join(ws.data["images_dir"], name)
        print(f"single image {name}, against the mosaic of the other {len(res.images)} images (128 x 128 windows):")
        _gcps, rec, im, off = transferred_gcps(args.workspace, name, 4)
        block_cam = gcam.Intrinsics.from_pycolmap(rec.cameras[im.camera_id]).as_opencv()
        cases = [("resection, 6 GCPs, the block's calibrated camera", 6, {"camera": block_cam}),
                 ("resection, 20 GCPs, EXIF focal length only (a lone photo)", 20, {}),
                 ("resection, 8 GCPs, EXIF focal length only (a lone photo)", 8, {})]
        for label, n, kw in cases:
            gcps, *_ = transferred_gcps(args.workspace, name, n)
            out = os.path.join(args.out, f"single_{n}.tif")
            t0 = time.time()
            r = orthorectify_image(SingleImageOptions(img, out, dsm_used, gcps=gcps,
                                                      ortho=OrthoOptions(resolution=res.resolution), **kw))
            s = shifts_against(out, mos)
            d = np.hypot(s[:, 0], s[:, 1]) if len(s) else np.zeros(0)
            print(f"  {label} ({time.time() - t0:.1f} s): GCP RMSE {r.rmse_px:.2f} px, left out "
                  f"{r.outliers or 'none'}, focal {r.orientation['focal_px']:.1f} px, k1 {r.orientation['k1']:+.3f}; "
                  f"mean shift ({s[:, 0].mean():+.2f}, {s[:, 1].mean():+.2f}) px")
            _dist(d, "    shift")
        # known orientation from the block
        p = im.cam_from_world()
        pose = gcam.Pose(np.asarray(p.rotation.matrix()), np.asarray(p.translation))
        c = pose.centre + off
        om, ph, ka = gcam.opk_from_rotation(pose.rotation)
        k = dict(zip(("k1", "k2", "p1", "p2"), block_cam.dist[:4]))
        orientation = {"x": c[0], "y": c[1], "z": c[2], "omega": om, "phi": ph, "kappa": ka,
                       "focal_px": block_cam.focal, "cx": block_cam.cx, "cy": block_cam.cy, "crs": "EPSG:32617", **k}
        out2 = os.path.join(args.out, "single_orientation.tif")
        orthorectify_image(SingleImageOptions(img, out2, dsm_used, orientation=orientation,
                                              ortho=OrthoOptions(resolution=res.resolution)))
        s = shifts_against(out2, mos)
        d = np.hypot(s[:, 0], s[:, 1])
        print(f"  known orientation (x y z omega phi kappa + interior from the block): mean shift "
              f"({s[:, 0].mean():+.2f}, {s[:, 1].mean():+.2f}) px")
        _dist(d, "    shift")

if __name__ == "__main__":
    main()
