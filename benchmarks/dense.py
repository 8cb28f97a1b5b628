"""Dense matching + DSM on real data: Toledo (57 images, georeferenced with EXIF GPS).

Aligns and georeferences the block first when the workspace is not ready (or reuses
--workspace), clears the pair cache (unless --resume), then runs the DSM stage in a
child process while sampling the memory of the whole process tree (the child and its
pool workers).  Prints seconds per stereo pair and per megapixel, total seconds, peak
RSS, VALID_FRACTION inside the convex hull of the image centres, the heights of raised
objects above a local ground estimate, and writes a hillshade PNG of the DSM.

    python benchmarks/dense.py [--workspace DIR] [--quality half] [--workers 0] [--resume]
                               [--png PATH] [--point-cloud]
    python benchmarks/dense.py --synthetic 600,1200 [--contrast 0.03]   (seconds per megapixel at two sizes of
                               one synthetic block, quality full; fill and accuracy against the truth)
    python benchmarks/dense.py --farmland full|small [--contrast 0.15] [--strips 4 --per-strip 10]
                               [--quality half]   (issue 33: tests/lowtexture_scene.py's farmland, 3600 x 2700
                               px or the test's 640 x 480: measured / interpolated / removed fractions, blunder
                               count, RMSE over the fields against the truth; run under /usr/bin/time -v for
                               the peak RSS)
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import threading
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
sys.path.insert(0, HERE)
from _util import tree_rss  # noqa: E402

DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")


def ensure_georeferenced(images, ws, crs):
    from core.align.options import AlignOptions
    from core.align.stage import align
    from core.common.progress import PrintProgress
    from core.georef.options import GeorefOptions
    from core.georef.stage import georeference_workspace
    from core.project.workspace import Workspace

    try:
        w = Workspace.open(ws)
        if w.stage_done("georeference"):
            return
        aligned = w.stage_done("align")
    except Exception:  # noqa: BLE001 - no workspace yet
        aligned = False
    if not aligned:
        t0 = time.time()
        r = align(images, ws, AlignOptions(), PrintProgress("  align "))
        print(f"aligned {r.registered}/{r.images_given} in {time.time() - t0:.0f} s")
    r = georeference_workspace(ws, GeorefOptions(use_exif_gps=True, crs=crs), progress=PrintProgress("  georef "))
    print(f"georeferenced with EXIF GPS: camera RMSE {r.figures['CAMERA_RMSE_XYZ']:.2f} m")


def run_child(args):
    """Run the DSM stage in a child process; sample the tree's memory every 0.2 s."""
    out_json = os.path.join(os.path.dirname(os.path.abspath(args.workspace)), "bench-dense-result.json")
    cmd = [sys.executable, os.path.abspath(__file__), "--child", "--workspace", args.workspace,
           "--quality", args.quality, "--workers", str(args.workers), "--result", out_json]
    if args.point_cloud:
        cmd.append("--point-cloud")
    peak = {"sum": 0, "procs": 0}
    proc = subprocess.Popen(cmd)
    stop = threading.Event()

    def sample():
        while not stop.wait(0.2):
            s, n = tree_rss(proc.pid)
            if s > peak["sum"]:
                peak["sum"], peak["procs"] = s, n

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    _, status, usage = os.wait4(proc.pid, 0)
    stop.set()
    th.join()
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise SystemExit(f"DSM stage failed (exit {code})")
    with open(out_json) as f:
        result = json.load(f)
    result["peak_rss_tree_mib"] = peak["sum"] / 2 ** 20
    result["peak_rss_single_mib"] = usage.ru_maxrss / 1024.0
    result["processes_at_peak"] = peak["procs"]
    result["cpu_tree"] = usage.ru_utime + usage.ru_stime
    return result


def child(args):
    from core.common.progress import PrintProgress
    from core.dense import stage as dense
    from core.dense.options import DenseOptions
    from core.dense.stereo import read_pair_summary

    pc = os.path.join(args.workspace, "dense", "points.las") if args.point_cloud else None
    t0 = time.time()
    r = dense.build_dsm_workspace(args.workspace, DenseOptions(quality=args.quality, output_point_cloud=pc,
                                                               workers=args.workers), progress=PrintProgress("  "))
    wall = time.time() - t0
    # per-pair figures from the cache summaries
    from glob import glob

    pairs = []
    for p in glob(os.path.join(args.workspace, "dense", "pairs-*", "*.npz")):
        s = read_pair_summary(p)
        if not s.get("skipped"):
            pairs.append(s)
    import resource

    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(args.result, "w") as f:
        json.dump({"wall": wall, "cpu_self": own.ru_utime + own.ru_stime, "cpu_workers": kids.ru_utime + kids.ru_stime,
                   "dsm": r.dsm_path, "point_cloud": r.point_cloud_path, "pairs": r.pairs,
                   "pairs_reused": r.pairs_reused, "points": r.points, "valid_fraction": r.valid_fraction,
                   "measured_fraction": r.measured_fraction, "interpolated_fraction": r.interpolated_fraction,
                   "resolution": r.resolution, "timings": r.timings, "log": r.log_lines,
                   "pair_seconds": [s["seconds"] for s in pairs], "pair_cpu": [s.get("cpu_seconds", 0.0) for s in pairs], "pair_megapixels": [s["megapixels"] for s in pairs],
                   "pair_valid_fraction": [s.get("valid_fraction", 0.0) for s in pairs]}, f)


def hillshade(z, res, azimuth=315.0, altitude=45.0):
    zf = np.where(np.isfinite(z), z, np.nanmedian(z))
    gy, gx = np.gradient(zf, res)
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = np.radians(360.0 - azimuth + 90.0), np.radians(altitude)
    hs = np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(az - aspect)
    return np.clip(hs, 0, 1)


def figures_png(dsm_path, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy import ndimage

    from core.io import raster as dsm

    z, gt, _ = dsm.read_dsm(dsm_path)
    res = gt[1]
    hs = hillshade(z, res)
    hs[~np.isfinite(z)] = np.nan
    # normalised DSM: height above a local ground estimate (grey opening, 31 m window)
    zf = np.where(np.isfinite(z), z, np.nanmax(z))
    size = max(3, int(round(31.0 / res)) | 1)
    ground = ndimage.grey_opening(zf, size=(size, size))
    ground = ndimage.uniform_filter(ground, size=max(3, size // 3))
    ndsm = np.where(np.isfinite(z), z - ground, np.nan)
    fig, ax = plt.subplots(1, 2, figsize=(16, 7))
    ax[0].imshow(hs, cmap="gray", interpolation="nearest")
    ax[0].set_title(f"hillshade, {res:g} m cells")
    im = ax[1].imshow(ndsm, cmap="viridis", vmin=-1, vmax=12, interpolation="nearest")
    ax[1].set_title("height above local ground (m)")
    fig.colorbar(im, ax=ax[1], shrink=0.8)
    for a in ax:
        a.set_xticks([])
        a.set_yticks([])
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)
    raised = ndsm[np.isfinite(ndsm) & (ndsm > 2.5)]
    return raised


def synthetic(widths, contrast, quality, strips=2, per_strip=6, workers=1):
    """The same synthetic block (tests/test_dense_fill.py's: 2 strips of 6, a low-texture patch in the west) with
    its camera at each of ``widths`` pixels across: seconds and CPU seconds per megapixel matched, peak RSS, the
    DSM's measured / interpolated share of the cameras' hull and its accuracy (measured cells) against the truth."""
    import resource

    from core.common.progress import NullProgress
    from core.dense import stage as dense
    from core.dense.options import DenseOptions
    from core.dense.stereo import read_pair_summary
    from core.io import raster
    from tests import synthetic as syn
    from tests.workspaces import synthetic_workspace

    base = syn.CameraModel(400, 300, 325.0, 325.0, 201.9, 148.1, k1=-0.08, k2=0.02, p1=0.0006, p2=-0.0004)
    print(f"\n== dense matching, synthetic block (low-texture patch at {contrast:g} of the contrast), "
          f"quality {quality} ==")
    print("  width  MP/pair  pairs  s/pair  s/MP  cpu-s/MP  measured %  interpolated %  median |dz| m  "
          "peak RSS MiB")
    for width in widths:
        f = width / 400.0
        cam = syn.CameraModel(width, int(round(300 * f)), 325.0 * f, 325.0 * f, 201.9 * f, 148.1 * f, k1=-0.08,
                              k2=0.02, p1=0.0006, p2=-0.0004) if width != 400 else base
        block = syn.vertical_block(seed=8, camera=cam, altitude=40.0, n_strips=strips, per_strip=per_strip, forward_overlap=0.8,
                                   side_overlap=0.5, gcp_grid=(2, 2), roofs=0, low_texture=(0.0, 0.0, 0.41, 1.0),
                                   low_texture_contrast=contrast)
        size = "" if (strips, per_strip) == (2, 6) else f"-{strips}x{per_strip}"
        root = os.path.join(ROOT, "build", "bench-dense", f"synthetic-{width}-{contrast:g}{size}")
        images = os.path.join(root, "images")
        if not os.path.exists(os.path.join(root, "rendered")):
            t0 = time.time()
            block.render(images, supersample=1 if cam.width > 3000 else 2)  # 16 MP x 4 rays: > 10 GiB to cast
            open(os.path.join(root, "rendered"), "w").close()
            print(f"  (rendered {len(block.shots)} images of {cam.width} x {cam.height} px in {time.time() - t0:.0f} s)")
        ws = os.path.join(root, "ws")
        shutil.rmtree(ws, ignore_errors=True)
        rec = block.truth_reconstruction(model_from_local=None, noise_px=0.2, n_points=1500)
        synthetic_workspace(ws, block, rec, images_dir=images, georeferenced=True, crs=syn.CRS, offset=syn.ORIGIN)
        r = dense.build_dsm_workspace(ws, DenseOptions(quality=quality, workers=workers), progress=NullProgress())
        from glob import glob

        pairs = [read_pair_summary(p) for p in glob(os.path.join(ws, "dense", "pairs-*", "*.npz"))]
        pairs = [p for p in pairs if not p.get("skipped")]
        secs = sum(p["seconds"] for p in pairs)
        cpu = sum(p.get("cpu_seconds", 0.0) for p in pairs)
        mp = sum(p["megapixels"] for p in pairs)
        z, gt, _ = raster.read_dsm(r.dsm_path)
        src, _, _ = raster.read_dsm(r.source_path)
        h, w = z.shape
        xs = gt[0] + (np.arange(w) + 0.5) * gt[1] - syn.ORIGIN[0]
        ys = gt[3] + (np.arange(h) + 0.5) * gt[5] - syn.ORIGIN[1]
        x, y = np.meshgrid(xs, ys)
        err = z - block.scene.height_at(x, y)
        med = float(np.median(np.abs(err[np.nan_to_num(src) == raster.SOURCE_MEASURED])))
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
        print(f"  {width:5d}  {mp / max(len(pairs), 1):7.2f}  {len(pairs):5d}  {secs / max(len(pairs), 1):6.2f}  "
              f"{secs / mp:4.2f}  {cpu / mp:8.2f}  {100 * r.measured_fraction:10.1f}  "
              f"{100 * r.interpolated_fraction:14.1f}  {med:13.3f}  {rss:12.0f}")


def farmland(size, contrast, quality, strips, per_strip, workers, out_dir=None):
    """The DSM stage on tests/lowtexture_scene.py's farmland block against its truth (photos rendered once under
    ``out_dir``, default build/bench-dense)."""
    from core.common.progress import NullProgress
    from core.dense import stage as dense
    from core.dense.options import DenseOptions
    from core.io import raster
    from tests import lowtexture_scene as lt
    from tests import synthetic as syn
    from tests.test_dense_lowtexture import blunder_count
    from tests.workspaces import synthetic_workspace

    block = lt.full_block(strips, per_strip, contrast) if size == "full" else lt.small_block(contrast)
    root = os.path.join(out_dir or os.path.join(ROOT, "build", "bench-dense"),
                        f"farmland-{size}-{contrast:g}-{len(block.shots)}")
    images = os.path.join(root, "images")
    if not os.path.exists(os.path.join(root, "rendered")):
        t0 = time.time()
        block.render(images, keep_existing=True)
        open(os.path.join(root, "rendered"), "w").close()
        print(f"  (rendered {len(block.shots)} images of {block.camera.width} x {block.camera.height} px in "
              f"{time.time() - t0:.0f} s)")
    ws = os.path.join(root, "ws-" + os.path.basename(ROOT))  # one per source tree (a comparison with another)
    shutil.rmtree(ws, ignore_errors=True)
    rec = block.truth_reconstruction(model_from_local=None, noise_px=0.3, n_points=1500 if size != "full" else 6000)
    synthetic_workspace(ws, block, rec, images_dir=images, georeferenced=True, crs=syn.CRS, offset=syn.ORIGIN)
    t0, c0 = time.time(), time.process_time()
    r = dense.build_dsm_workspace(ws, DenseOptions(quality=quality, workers=workers), progress=NullProgress())
    wall = time.time() - t0
    import resource

    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = time.process_time() - c0 + kids.ru_utime + kids.ru_stime
    z, gt, _ = raster.read_dsm(r.dsm_path)
    src, _, _ = raster.read_dsm(r.source_path)
    src = np.nan_to_num(src)
    h, w = z.shape
    x, y = np.meshgrid(gt[0] + (np.arange(w) + 0.5) * gt[1] - syn.ORIGIN[0],
                       gt[3] + (np.arange(h) + 0.5) * gt[5] - syn.ORIGIN[1])
    err = z - block.scene.height_at(x, y)
    fields = block.scene.field_mask(x, y)
    gsd = block.gsd
    print(f"\n== DSM of the farmland block ({size}: {len(block.shots)} photos of {block.camera.width} x "
          f"{block.camera.height} px, GSD {gsd:.3f} m, fields at {contrast:g} of their contrast), quality {quality} ==")
    for line in r.log_lines:
        print("  " + line)
    print(f"  measured {r.measured_fraction:.3f}, interpolated {r.interpolated_fraction:.3f}, removed "
          f"{getattr(r, 'removed_fraction', 0.0):.4f} of the cameras' hull ({getattr(r, 'removed_cells', 0)} cells "
          "removed in all)")
    for name, m in (("fields, measured cells", fields & (src == raster.SOURCE_MEASURED)),
                    ("fields, every cell with a height", fields & np.isfinite(z))):
        e = err[m]
        print(f"  {name}: RMSE {np.sqrt(np.mean(e ** 2)):.3f} m = {np.sqrt(np.mean(e ** 2)) / gsd:.2f} GSD, median "
              f"|dz| {np.median(np.abs(e)) / gsd:.2f} GSD, 95 % {np.percentile(np.abs(e), 95) / gsd:.2f} GSD")
    print(f"  blunders (cells more than 100 GSD = 5 m at 4.9 cm from their 15 x 15 median): "
          f"{blunder_count(z, 100 * gsd)}")
    print(f"  DSM stage: {wall:.0f} s wall, {cpu:.0f} CPU-s (this process and its workers)")


def diagnose(contrast, workers, out_dir=None):
    """Per pair of the small farmland block, why the matching gives up on the fields: the share of the overlap
    matched at the coarsest pyramid level (the whole disparity range: a periodic texture's repeats compete there)
    and in the end, with the baseline's direction, under the settings before issue 33 and each change alone."""
    from glob import glob

    from core.common.progress import NullProgress
    from core.dense import stage as dense
    from core.dense.options import DenseOptions
    from core.dense.stereo import read_pair_summary
    from tests import lowtexture_scene as lt
    from tests import synthetic as syn
    from tests.workspaces import synthetic_workspace

    block = lt.small_block(contrast)
    root = os.path.join(out_dir or os.path.join(ROOT, "build", "bench-dense"), f"farmland-small-{contrast:g}-10")
    images = os.path.join(root, "images")
    if not os.path.exists(os.path.join(root, "rendered")):
        block.render(images)
        open(os.path.join(root, "rendered"), "w").close()
    settings = {"neither (as before)": dict(equalize=False, fine_uniqueness=10),
                "equalised only": dict(equalize=True, fine_uniqueness=10),
                "fine uniqueness 3 only": dict(equalize=False, fine_uniqueness=3),
                "both (default)": dict(equalize=True, fine_uniqueness=3)}
    table, fractions = {}, {}
    for name, opts in settings.items():
        ws = os.path.join(root, "ws-diagnose")
        shutil.rmtree(ws, ignore_errors=True)
        rec = block.truth_reconstruction(model_from_local=None, noise_px=0.3, n_points=1500)
        synthetic_workspace(ws, block, rec, images_dir=images, georeferenced=True, crs=syn.CRS, offset=syn.ORIGIN)
        r = dense.build_dsm_workspace(ws, DenseOptions(quality="full", workers=workers, **opts),
                                      progress=NullProgress())
        fractions[name] = (r.measured_fraction, r.removed_fraction)
        for p in glob(os.path.join(ws, "dense", "pairs-*", "*.npz")):
            sm = read_pair_summary(p)
            key = (sm["i"], sm["j"])
            table.setdefault(key, {"azimuth": sm.get("baseline_azimuth"), "rel_err": sm.get("rel_err")})[name] = (
                sm.get("pyramid", {}).get("coarsest_matched", float("nan")),
                sm.get("pyramid", {}).get("overlap_matched", float("nan")))
    print(f"\n== per pair: share of the overlap matched, coarsest level / in the end (farmland small, contrast "
          f"{contrast:g}; furrows at {lt.FURROW_ANGLE_DEG:g} deg to the strips, rows at {lt.CROP_ANGLE_DEG:g}) ==")
    names = list(settings)
    print("  pair                    baseline az  depth err/px  " + "  ".join(f"{n[:22]:>22s}" for n in names))
    for (i, j), row in sorted(table.items()):
        cells = "  ".join(f"{row[n][0]:10.2f} / {row[n][1]:4.2f}    " if n in row else " " * 22 for n in names)
        print(f"  {i:>10s} + {j:<10s}  {row['azimuth']:8.1f}  {row['rel_err'] or 0:12.4f}  {cells}")
    for n in names:
        print(f"  {n}: DSM measured {fractions[n][0]:.3f}, removed {fractions[n][1]:.4f} of the cameras' hull "
              "(the blunder filter on in all four)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--synthetic", default=None, metavar="W1,W2",
                    help="instead of Toledo: the synthetic block with its camera W1, W2 ... px wide (e.g. 600,1200)")
    ap.add_argument("--contrast", type=float, default=None,
                    help="the synthetic low-texture patch's contrast (0.03), or the farmland's (0.15)")
    ap.add_argument("--farmland", choices=("full", "small"), default=None,
                    help="instead of Toledo: tests/lowtexture_scene.py's farmland block (issue 33)")
    ap.add_argument("--workspace", default=os.path.join(ROOT, "build", "bench-dense", "toledo-ws"))
    ap.add_argument("--images", default=os.path.join(DATA, "toledo", "images"))
    ap.add_argument("--crs", default="EPSG:32617")
    ap.add_argument("--quality", default=None, help="matching quality (default: half for Toledo, full synthetic)")
    ap.add_argument("--strips", type=int, default=None, help="synthetic: strips of the block (2; farmland 4)")
    ap.add_argument("--per-strip", type=int, default=None,
                    help="synthetic: images per strip (6; farmland full 10)")
    ap.add_argument("--workers", type=int, default=0)
    ap.add_argument("--diagnose", action="store_true",
                    help="per pair of the small farmland block: the share matched at the coarsest level and in the end "
                         "under the settings before issue 33 and each change alone")
    ap.add_argument("--out", default=None, help="--farmland: where its photos and workspaces go (build/bench-dense)")
    ap.add_argument("--resume", action="store_true", help="keep the pair cache (measures a resumed run)")
    ap.add_argument("--point-cloud", action="store_true", help="also write dense/points.las")
    ap.add_argument("--png", default=None, help="hillshade PNG (default beside the workspace)")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--result", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args)
        return
    if args.diagnose:
        diagnose(0.15 if args.contrast is None else args.contrast, args.workers or 1, args.out)
        return
    if args.farmland:
        full = args.farmland == "full"
        farmland(args.farmland, 0.15 if args.contrast is None else args.contrast,
                 args.quality or ("half" if full else "full"), args.strips or (4 if full else 2),
                 args.per_strip or (10 if full else 5), args.workers or 1, args.out)
        return
    if args.synthetic:
        synthetic([int(v) for v in args.synthetic.split(",")], 0.03 if args.contrast is None else args.contrast,
                  args.quality or "full", args.strips or 2,
                  args.per_strip or 6, args.workers or 1)
        return
    args.quality = args.quality or "half"
    if not os.path.isdir(args.images):
        raise SystemExit(f"no images at {args.images}")
    ensure_georeferenced(args.images, args.workspace, args.crs)
    if not args.resume:
        for name in os.listdir(os.path.join(args.workspace, "dense")) if os.path.isdir(
                os.path.join(args.workspace, "dense")) else []:
            shutil.rmtree(os.path.join(args.workspace, "dense", name), ignore_errors=True)
    r = run_child(args)
    secs = np.array(r["pair_seconds"])
    mp = np.array(r["pair_megapixels"])
    png = args.png or os.path.join(os.path.dirname(os.path.abspath(args.workspace)), "toledo_dsm_hillshade.png")
    raised = figures_png(r["dsm"], png)
    print("\n== dense matching + DSM, Toledo ==")
    for line in r["log"]:
        print("  " + line)
    print(f"  quality {args.quality}: {r['pairs']} pairs ({r['pairs_reused']} reused), {r['points']} points, "
          f"DSM {r['resolution']:g} m")
    if len(secs):
        print(f"  seconds per pair: mean {secs.mean():.2f}, median {np.median(secs):.2f}, max {secs.max():.2f} "
              "(one worker's time for one pair)")
        print(f"  seconds per megapixel (both images of a pair at the matching scale): {secs.sum() / mp.sum():.2f}")
        cpu = np.array(r["pair_cpu"])
        print(f"  CPU seconds per pair (all threads of the worker; unaffected by other load): mean {cpu.mean():.2f}, "
              f"per megapixel {cpu.sum() / mp.sum():.2f}")
        print(f"  matched share of the rectified left image per pair: median {np.median(r['pair_valid_fraction']):.2f}")
    print("  stage seconds: " + ", ".join(f"{k} {v:.1f}" for k, v in r["timings"].items()))
    print(f"  CPU seconds: {r['cpu_tree']:.1f} for the whole stage (process tree), {r['cpu_workers']:.1f} of them in pool "
          f"workers (matching, fusion), {r['cpu_self']:.1f} in the stage's own process (pair selection, DSM)")
    print(f"  total seconds (wall, child process): {r['wall']:.1f}; machine load average now "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"  peak RSS: {r['peak_rss_tree_mib']:.0f} MiB for the whole process tree ({r['processes_at_peak']} processes), "
          f"{r['peak_rss_single_mib']:.0f} MiB for the largest single process (limit 4096 MiB)")
    print(f"  inside the convex hull of the image centres: VALID_FRACTION {r['valid_fraction']:.3f}, measured "
          f"{r.get('measured_fraction') or 0:.3f}, interpolated {r.get('interpolated_fraction') or 0:.3f}")
    if len(raised):
        print(f"  raised objects (> 2.5 m above local ground): {len(raised)} cells, "
              f"height percentiles 50/90/99: {np.percentile(raised, 50):.1f} / {np.percentile(raised, 90):.1f} / "
              f"{np.percentile(raised, 99):.1f} m")
    print(f"  hillshade: {png}")


if __name__ == "__main__":
    main()
