"""Spectral index benchmark (issue 37 item 3): wall time, CPU time and peak memory of one index (NDVI by default) of a
10,000 x 10,000 4-band raster (Green, Red, Red edge, NIR; uint16 reflectance x 10000, tiled DEFLATE GeoTIFF, nodata
0, a strip of nodata), measured in a child process (core.spectral.index.spectral_index, the raster read in blocks).

usage: python benchmarks/spectral_index.py [--size 10000] [--index ndvi|ndre|expression] [--expression TEXT]
                                           [--work DIR] [--keep]

The input is made once in --work (default build/bench-spectral) by blocks of 256 rows, and kept with --keep.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from benchmarks._util import LAST_RUN, run_measured  # noqa: E402


def make_input(path: str, size: int) -> None:
    """A size x size 4-band uint16 raster written by strips: fields with a crop mark (a ditch: NIR higher) and
    a little noise; the first 100 rows nodata."""
    from osgeo import gdal, osr

    gdal.UseExceptions()
    tmp = path + ".part"
    ds = gdal.GetDriverByName("GTiff").Create(tmp, size, size, 4, gdal.GDT_UInt16, [
        "TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=2", "BIGTIFF=YES", "INTERLEAVE=BAND"])
    ds.SetGeoTransform((500000.0, 0.05, 0.0, 4600000.0 + size * 0.05, 0.0, -0.05))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    base = (800, 500, 2500, 4500)  # green, red, red edge, NIR reflectance x 10000
    for b, name in enumerate(("Green", "Red", "Red edge", "NIR")):
        ds.GetRasterBand(b + 1).SetDescription(name)
        ds.GetRasterBand(b + 1).SetNoDataValue(0)
    rng = np.random.default_rng(0)
    cols = np.arange(size)
    ditch = (cols % 2000 > 900) & (cols % 2000 < 960)
    for r0 in range(0, size, 256):
        h = min(256, size - r0)
        for b in range(4):
            v = base[b] + rng.integers(-40, 40, (h, size))
            if b == 3:
                v[:, ditch] += 1000
            if r0 < 100:
                v[:100 - r0] = 0
            ds.GetRasterBand(b + 1).WriteArray(v.astype(np.uint16), 0, r0)
    ds = None
    os.replace(tmp, path)


def run_child(args) -> None:
    from core.common.progress import NullProgress
    from core.spectral.index import spectral_index
    from core.spectral.options import IndexOptions

    t0 = time.time()
    r = spectral_index(IndexOptions(args.input, args.output, args.index, args.expression), NullProgress())
    print(f"{r.index} {r.formula}: {r.valid} cells, {r.minimum:.4f} .. {r.maximum:.4f}, mean {r.mean:.4f}, "
          f"{time.time() - t0:.1f} s in the child", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=int, default=10_000)
    ap.add_argument("--index", default="ndvi")
    ap.add_argument("--expression", default="")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "bench-spectral"))
    ap.add_argument("--keep", action="store_true", help="keep the input raster for a re-run")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--input", help=argparse.SUPPRESS)
    ap.add_argument("--output", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        run_child(args)
        return
    os.makedirs(args.work, exist_ok=True)
    src = os.path.join(args.work, f"rgn-{args.size}.tif")
    if not os.path.exists(src):
        t0 = time.time()
        make_input(src, args.size)
        print(f"input {src}: {args.size} x {args.size} x 4 uint16, {os.path.getsize(src) / 2 ** 20:.0f} MiB, "
              f"made in {time.time() - t0:.1f} s", flush=True)
    out = os.path.join(args.work, f"{args.index}.tif")
    log = os.path.join(args.work, "child.log")
    cmd = [sys.executable, os.path.abspath(__file__), "--child", "--input", src, "--output", out, "--index",
           args.index, "--expression", args.expression]
    code, wall, rss = run_measured(cmd, log_path=log)
    cpu = LAST_RUN["cpu"]
    with open(log) as f:
        print(f.read().strip())
    if code:
        sys.exit(f"the index failed ({code}), see {log}")
    base, _, base_rss = run_measured([sys.executable, "-c", "import numpy; from osgeo import gdal"])
    print(f"{args.index} of {args.size} x {args.size} x 4: wall {wall:.1f} s, CPU {cpu:.1f} s, "
          f"peak RSS {rss:.0f} MiB (python + numpy + GDAL alone: {base_rss:.0f} MiB); output "
          f"{os.path.getsize(out) / 2 ** 20:.0f} MiB", flush=True)
    os.remove(out)
    if not args.keep:
        os.remove(src)


if __name__ == "__main__":
    main()
