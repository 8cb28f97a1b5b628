"""Peak memory and CPU time of every stage (issue 33 item 1: peak RSS <= 3 GiB per stage for a 40-photo block of
10 MP photos, <= 4 GiB at 20 MP), each stage in its own process, measured from outside: the peak summed RSS of the
process and its descendants (pool workers; sampled every 0.2 s, and the child's own ru_maxrss) and its CPU seconds
(user + system of the process and its waited-for children, os.wait4).

Two modes:

- ``terrain``: the terrain stages (Build DTM, relief, contours) on a synthetic DSM of the size issue 33 reports
  (7,220 x 6,052 cells at 4.9 cm: hills, ploughed fields, a road, buildings, trees, a ragged nodata edge), written
  once as a GeoTIFF into --workdir; --compare: the products of the first root against the second's (max / RMS
  difference of each raster);
- ``chain``: align, georeference (EXIF GPS, or camera_positions.csv beside the images), DSM, orthophoto, DTM,
  relief, contours and report on a folder of photos (e.g. ../shared/data/ochota_kap/images), one stage per
  process on one workspace.

--root DIR runs the stages of another checkout (e.g. a worktree of the commit before a change: ``git worktree add
/tmp/wt-mem-before HEAD``) so that one invocation prints before / after:

    python benchmarks/memory.py terrain --root /tmp/wt-mem-before --root .
    python benchmarks/memory.py chain --images ../shared/data/toledo_2400/images --count 30 --root /tmp/wt-mem-before
    python benchmarks/memory.py chain --images ../shared/data/toledo_2400/images --reuse --root . \
        --stages orthophoto,terrain,relief,report

(ochota_kap has no GPS: its chain ends after the alignment.)  Each child logs its progress with the time and its
process tree's RSS (``<workdir>/chain-0/<stage>.log``), and each stage's line names the step after which its
peak was sampled.  Issue 46 item 3 (a 40-photo block of 3600 x 2700 photos of low-texture fields,
``benchmarks/upscaled_set.py --turns``):

    python benchmarks/upscaled_set.py ../shared/data/seneca_south/images /tmp/s23/mem40/images --mp 9.72 \
        --turns 0,180,90,270 --count 40
    nice -n 10 python benchmarks/memory.py chain --images /tmp/s23/mem40/images --workdir /tmp/s23/mem40/run  The orthophoto stage's seam brightness step before /
after the radiometric correction is printed under it.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from _util import tree_rss  # noqa: E402

RELIEF_KEYS = ("svf", "slrm", "mhs", "vat")
GIB = 2 ** 30
DSM_QUALITY = [""]  # --dsm-quality, passed to the children ("": the DSM stage's default)
FOCAL_PX = [0.0]  # --focal-px, passed to the children (0: the alignment's default, EXIF or a guess)


# ---------------------------------------------------------------- measuring a child

def measure(cmd, log_path, cwd=None, interval=0.2, peak_at=None):
    """(exit code, wall s, CPU s, peak RSS bytes) of ``cmd`` and its descendants; ``peak_at`` (a list) receives
    the time (epoch s) the sampled peak was seen, to find it among the child's traced lines."""
    with open(log_path, "w") as out:
        t0 = time.time()
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, cwd=cwd)
        peak = [0]
        stop = threading.Event()

        def sample():
            while not stop.wait(interval):
                rss = tree_rss(proc.pid)[0]
                if rss > peak[0]:
                    peak[0] = rss
                    if peak_at is not None:
                        peak_at[:] = [time.time()]

        th = threading.Thread(target=sample, daemon=True)
        th.start()
        _, status, usage = os.wait4(proc.pid, 0)
        stop.set()
        th.join()
    cpu = usage.ru_utime + usage.ru_stime
    return os.waitstatus_to_exitcode(status), time.time() - t0, cpu, max(peak[0], usage.ru_maxrss * 1024)


# ---------------------------------------------------------------- the synthetic DSM

def synthetic_dsm(path, width=7220, height=6052, cell=0.049, seed=33):
    """A farmland DSM (metres, float32, nodata -9999, UTM 33N): gentle hills, ploughed furrows at 30 degrees,
    a road, six buildings (4-8 m), sixty trees (3-12 m), matching noise and a ragged nodata edge; written in
    strips so that the generator itself stays small."""
    import numpy as np
    from osgeo import gdal, osr

    if os.path.isfile(path):
        return path
    rng = np.random.default_rng(seed)
    tmp = path + ".part"
    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(tmp, width, height, 1, gdal.GDT_Float32,
                    ["TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=3", "BIGTIFF=IF_SAFER"])
    x0, y0 = 500000.0, 5800000.0
    ds.SetGeoTransform((x0, cell, 0.0, y0, 0.0, -cell))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(-9999.0)
    wm, hm = width * cell, height * cell
    hills = [(rng.uniform(0, wm), rng.uniform(0, hm), rng.uniform(40, 120), rng.uniform(-3, 4)) for _ in range(8)]
    buildings = [(rng.uniform(40, wm - 40), rng.uniform(40, hm - 40), rng.uniform(4, 9), rng.uniform(3, 7),
                  rng.uniform(4, 8)) for _ in range(6)]
    trees = [(rng.uniform(10, wm - 10), rng.uniform(10, hm - 10), rng.uniform(1.5, 4.0), rng.uniform(3, 12))
             for _ in range(60)]
    edge_l = 3.0 + 2.0 * np.sin(np.arange(height) * cell / 11.0) + rng.uniform(0, 1, height)  # ragged, metres
    edge_r = 3.0 + 2.0 * np.cos(np.arange(height) * cell / 7.0) + rng.uniform(0, 1, height)
    xs = (np.arange(width) + 0.5) * cell
    strip = 512
    for r0 in range(0, height, strip):
        r1 = min(height, r0 + strip)
        ys = ((np.arange(r0, r1) + 0.5) * cell)[:, None]
        x = xs[None, :]
        z = np.full((r1 - r0, width), 100.0, dtype=np.float32)
        z += (0.01 * x + 0.004 * ys).astype(np.float32)
        for hx, hy, s, a in hills:
            z += (a * np.exp(-((x - hx) ** 2 + (ys - hy) ** 2) / (2 * s * s))).astype(np.float32)
        u = x * np.cos(np.radians(30)) + ys * np.sin(np.radians(30))
        z += (0.04 * np.sin(2 * np.pi * u / 0.75)).astype(np.float32)  # furrows every 75 cm
        road = np.abs(ys - 0.4 * hm - 0.1 * x) < 3.0
        z -= (0.15 * road).astype(np.float32)
        for bx, by, hw, hh, bh in buildings:
            z += (bh * ((np.abs(x - bx) < hw) & (np.abs(ys - by) < hh))).astype(np.float32)
        for tx, ty, rad, th in trees:
            d2 = (x - tx) ** 2 + (ys - ty) ** 2
            z += np.where(d2 < rad * rad, th * np.sqrt(np.clip(1 - d2 / (rad * rad), 0, 1)), 0).astype(np.float32)
        z += rng.normal(0, 0.02, z.shape).astype(np.float32)
        out = (x < edge_l[r0:r1, None]) | (x > wm - edge_r[r0:r1, None])
        holes = rng.uniform(0, 1, z.shape) < 2e-4
        z[out | holes] = -9999.0
        band.WriteArray(z, 0, r0)
    ds.FlushCache()
    ds = None
    os.replace(tmp, path)
    return path


# ---------------------------------------------------------------- children: one stage each

def trace_progress():
    """A progress that prints every message (reports at 5 % steps) with the epoch time and the process tree's RSS
    then: the log shows which step of the stage the peak falls in (the parent prints the peak's time)."""
    from core.common.progress import PrintProgress

    class Trace(PrintProgress):
        def info(self, message):
            super().info(f"[{time.time():.1f} {tree_rss(os.getpid())[0] / GIB:5.2f} GiB] {message}")

        def warning(self, message):
            self.info(f"WARNING: {message}")

        def report(self, fraction, message=""):
            if fraction - self._last >= 0.05 or fraction >= 1.0:
                self._last = fraction
                self.info(f"{100 * fraction:5.1f}% {message}")

    return Trace()


def child(args):
    sys.path.insert(0, args.root)
    os.chdir(args.root)
    p = trace_progress()
    if args.stage == "dtm":
        from core.terrain.products import build_dtm
        build_dtm(args.src, os.path.join(args.out, "dtm.tif"), progress=p)
    elif args.stage.startswith("relief-"):
        from core.terrain.products import relief
        relief(args.src, [args.stage[7:]], args.out, prefix="dtm", progress=p)
    elif args.stage == "contours":
        from core.terrain.contours import write_contours
        write_contours(args.src, os.path.join(args.out, "contours.gpkg"), 0.5, p)
    elif args.stage == "align":
        from core.align.options import AlignOptions
        from core.align.stage import align
        positions = os.path.join(os.path.dirname(args.src), "camera_positions.csv")  # as the pipeline passes it
        kw = ({"camera_positions": positions} if os.path.isfile(positions)
              and "camera_positions" in AlignOptions.__dataclass_fields__ else {})  # an older --root: none
        align(args.src, args.out, AlignOptions(focal_px=args.focal_px or None, **kw), progress=p)
    elif args.stage == "georeference":
        from core.georef.options import GeorefOptions
        from core.georef.stage import georeference_workspace
        positions = os.path.join(os.path.dirname(args.src), "camera_positions.csv")
        kw = {"camera_positions_path": positions} if os.path.isfile(positions) else {"use_exif_gps": True}
        georeference_workspace(args.out, GeorefOptions(**kw), progress=p)
    elif args.stage == "dsm":
        from core.dense.options import DenseOptions
        from core.dense.stage import build_dsm_workspace
        build_dsm_workspace(args.out, DenseOptions(quality=args.dsm_quality) if args.dsm_quality else None, progress=p)
    elif args.stage == "orthophoto":
        from core.ortho.stage import build_orthophoto_workspace
        r = build_orthophoto_workspace(args.out, progress=p)
        rad = getattr(r, "radiometry", None) or {}
        print("RADIOMETRY " + json.dumps({k: rad.get(k) for k in (
            "seam_step_before", "seam_step_after", "seam_step_level_before", "seam_step_level_after",
            "seam_level_fraction", "hot_width_deg", "hot_spot", "antisolar")}))
    elif args.stage == "terrain":
        from core.terrain.options import TerrainOptions
        from core.terrain.stage import build_dtm_workspace
        build_dtm_workspace(args.out, TerrainOptions(contour_interval=0.5), p)
    elif args.stage == "relief":
        from core.terrain.options import ReliefStageOptions
        from core.terrain.stage import relief_workspace
        relief_workspace(args.out, ReliefStageOptions(list(RELIEF_KEYS), source="dtm"), p)
    elif args.stage == "report":
        from core.report.stage import build_report
        build_report(args.out, progress=p)
    else:
        raise SystemExit(f"unknown stage {args.stage}")


def run_stage(root, stage, src, out, logdir):
    cmd = [sys.executable, os.path.abspath(__file__), "--child", stage, "--src", src, "--out", out, "--root", root,
           "--focal-px", str(FOCAL_PX[0]), "--dsm-quality", DSM_QUALITY[0]]
    log = os.path.join(logdir, f"{stage}.log")
    peak_at = []
    rc, wall, cpu, rss = measure(cmd, log, peak_at=peak_at)
    if rc != 0:
        with open(log) as fh:
            tail = fh.read()[-2000:]
        print(f"  {stage}: FAILED (exit {rc}), {log}:\n{tail}")
    return {"stage": stage, "rc": rc, "wall": wall, "cpu": cpu, "rss": rss, "step": peak_step(log, peak_at)}


def peak_step(log, peak_at):
    """The last traced line of the child's log before the sampled peak: the step the peak fell in."""
    if not peak_at:
        return ""
    last = ""
    with open(log) as fh:
        for line in fh:
            if line.startswith("[") and " GiB] " in line:
                try:
                    t = float(line[1:].split()[0])
                except ValueError:
                    continue
                if t > peak_at[0]:
                    break
                last = line.split(" GiB] ", 1)[1].strip()
    return last[:90]


# ---------------------------------------------------------------- comparing products

def compare_rasters(a, b):
    """(max |a - b|, RMS of a - b, cells where only one has data) over two rasters on one grid, read by blocks."""
    import numpy as np
    from osgeo import gdal

    da, db = gdal.Open(a), gdal.Open(b)
    ba, bb = da.GetRasterBand(1), db.GetRasterBand(1)
    nda, ndb = ba.GetNoDataValue(), bb.GetNoDataValue()
    mx, ss, n, only = 0.0, 0.0, 0, 0
    for r0 in range(0, da.RasterYSize, 1024):
        rows = min(1024, da.RasterYSize - r0)
        x = ba.ReadAsArray(0, r0, da.RasterXSize, rows).astype(np.float64)
        y = bb.ReadAsArray(0, r0, da.RasterXSize, rows).astype(np.float64)
        va = np.isfinite(x) & (x != nda if nda is not None else True)
        vb = np.isfinite(y) & (y != ndb if ndb is not None else True)
        both = va & vb
        only += int((va ^ vb).sum())
        d = np.abs(x[both] - y[both])
        if d.size:
            mx = max(mx, float(d.max()))
            ss += float((d ** 2).sum())
            n += d.size
    return mx, (ss / max(n, 1)) ** 0.5, only


# ---------------------------------------------------------------- the two modes

def terrain(args):
    os.makedirs(args.workdir, exist_ok=True)
    dsm = synthetic_dsm(os.path.join(args.workdir, "synthetic-dsm-7220x6052.tif"))
    rows = {}
    for i, root in enumerate(args.root):
        out = os.path.join(args.workdir, f"terrain-{i}")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        print(f"{root}:", flush=True)
        rows[root] = []
        for stage in ["dtm", "contours"] + [f"relief-{k}" for k in args.relief]:
            src = dsm if stage == "dtm" else os.path.join(out, "dtm.tif")
            r = run_stage(root, stage, src, out, out)
            rows[root].append(r)
            print(f"  {stage:14s} {r['cpu']:8.1f} CPU-s {r['wall']:8.1f} s  peak {r['rss'] / GIB:6.2f} GiB", flush=True)
    table(rows)
    if args.compare and len(args.root) == 2:
        a, b = (os.path.join(args.workdir, f"terrain-{i}") for i in range(2))
        print("\nproducts, first root against the second: max |difference|, RMS, cells with data in one only")
        for name in sorted(os.listdir(a)):
            if name.endswith(".tif") and os.path.isfile(os.path.join(b, name)):
                mx, rms, only = compare_rasters(os.path.join(a, name), os.path.join(b, name))
                print(f"  {name:24s} max {mx:.4g}  RMS {rms:.4g}  one-sided {only}")


def chain(args):
    images = os.path.abspath(args.images)
    names = sorted(n for n in os.listdir(images) if n.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff")))
    if args.count:
        names = names[:args.count]
    rows = {}
    for i, root in enumerate(args.root):
        d = os.path.join(args.workdir, f"chain-{i}")
        if args.reuse:  # the stages given, on a copy of the workspace an earlier run left (its first root's)
            fresh = os.path.join(args.workdir, f"chain-{i}-reuse")
            shutil.rmtree(fresh, ignore_errors=True)
            shutil.copytree(os.path.join(args.workdir, "chain-0"), fresh, symlinks=True)
            d = fresh
            rows[root] = _stages(root, args, os.path.join(d, "images"), os.path.join(d, "ws"), d)
            continue
        shutil.rmtree(d, ignore_errors=True)
        sub = os.path.join(d, "images")
        os.makedirs(sub)
        for n in names:
            os.symlink(os.path.join(images, n), os.path.join(sub, n))
        positions = os.path.join(os.path.dirname(images), "camera_positions.csv")
        if os.path.isfile(positions):
            shutil.copyfile(positions, os.path.join(d, "camera_positions.csv"))
        print(f"{root}: {len(names)} photos of {images}", flush=True)
        rows[root] = _stages(root, args, sub, os.path.join(d, "ws"), d)
    table(rows)


def _stages(root, args, images, ws, logdir):
    out = []
    for stage in args.stages.split(","):
        r = run_stage(root, stage, images, ws, logdir)
        out.append(r)
        print(f"  {stage:14s} {r['cpu']:8.1f} CPU-s {r['wall']:8.1f} s  peak {r['rss'] / GIB:6.2f} GiB  "
              f"(after: {r['step']})", flush=True)
        if stage == "orthophoto" and not r["rc"]:
            with open(os.path.join(logdir, "orthophoto.log")) as fh:
                print("".join(f"    {line}" for line in fh if line.startswith("RADIOMETRY")), end="")
        if r["rc"]:
            break
    return out


def table(rows):
    roots = list(rows)
    stages = [r["stage"] for r in rows[roots[0]]]
    print("\nstage          " + "".join(f" | {os.path.basename(os.path.normpath(r))[:24]:>24s}" for r in roots))
    print("               " + " | {:>10s} {:>13s}".format("CPU-s", "peak GiB") * len(roots))
    for s in stages:
        cells = []
        for root in roots:
            r = next((x for x in rows[root] if x["stage"] == s), None)
            cells.append(" | {:>10.1f} {:>13.2f}".format(r["cpu"], r["rss"] / GIB) if r and not r["rc"]
                         else " | {:>24s}".format("failed" if r else "-"))
        print(f"{s:14s} " + "".join(cells))
    print(json.dumps(rows))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", nargs="?", choices=("terrain", "chain"), default="terrain")
    ap.add_argument("--root", action="append", help="checkout whose stages run (repeatable; default: this one)")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-memory"))
    ap.add_argument("--images", default=os.path.join(os.path.dirname(ROOT), "shared", "data", "ochota_kap",
                                                     "images"))
    ap.add_argument("--count", type=int, default=0, help="the first N photos only")
    ap.add_argument("--reuse", action="store_true",
                    help="chain mode: run --stages on a copy of the workspace an earlier run left in --workdir")
    ap.add_argument("--stages", default="align,georeference,dsm,orthophoto,terrain,relief,report")
    ap.add_argument("--relief", default=",".join(RELIEF_KEYS), help="terrain mode: the relief visualisations")
    ap.add_argument("--compare", action="store_true", help="terrain mode: products of root 1 against root 2")
    ap.add_argument("--focal-px", type=float, default=0.0,
                    help="chain mode: the focal length in pixels given to the alignment (photos without EXIF)")
    ap.add_argument("--dsm-quality", default="", help="chain mode: the DSM stage's quality (default: its own)")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--src", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        args.stage = args.child
        args.root = os.path.abspath(args.root[0])
        return child(args)
    args.root = [os.path.abspath(r) for r in (args.root or [ROOT])]
    FOCAL_PX[0] = args.focal_px
    DSM_QUALITY[0] = args.dsm_quality
    args.workdir = os.path.abspath(args.workdir)
    args.relief = [k for k in args.relief.split(",") if k]
    return terrain(args) if args.mode == "terrain" else chain(args)


if __name__ == "__main__":
    main()
