"""Georeferencing against synthetic ground truth: render -> align (pycolmap) -> georeference.

For each seed, renders the synthetic vertical block of tests/synthetic.py (optionally with an oblique
orbit), aligns it with core.align.stage.align and georeferences it with core.georef: 5 well-spread control
points (the rest check points), Helmert only, camera positions only (sigma 0.5 m), and the truth-built
model for comparison.  Prints the GSD, check-point RMSE in metres and in GSD, per-stage seconds.

    python benchmarks/synthetic_georef.py [--seeds 1 2 3] [--orbit 0] [--noise 0.4] [--workdir DIR]
                                          [--features 2000] [--keep]
"""
import argparse
import math
import os
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

from core.align.options import AlignOptions  # noqa: E402
from core.align.stage import align, load_model  # noqa: E402
from core.georef.adjust import georeference  # noqa: E402
from core.georef.results import CHECKED  # noqa: E402
from core.io.gcp import CHECK, CONTROL  # noqa: E402
from tests import synthetic as syn  # noqa: E402


def _line(label, r, gsd):
    if not r or not r.get("n"):
        return f"  {label:<34} n=0"
    return (f"  {label:<34} n={r['n']:<2} XY {r['xy']:.4f} m ({r['xy'] / gsd:.2f} GSD)  "
            f"Z {r['z']:.4f} m ({r['z'] / gsd:.2f} GSD)")


def run(seed, args, work):
    t0 = time.time()
    block = syn.vertical_block(seed=seed, orbit=args.orbit)
    t_scene = time.time() - t0
    images = os.path.join(work, f"seed{seed}", "images")
    ws = os.path.join(work, f"seed{seed}", "ws")
    shutil.rmtree(os.path.dirname(images), ignore_errors=True)
    t0 = time.time()
    block.render(images)
    t_render = time.time() - t0
    t0 = time.time()
    res = align(images, ws, AlignOptions(pairing="exhaustive", num_threads=args.threads,
                                                 max_features=args.features))
    t_align = time.time() - t0
    gsd = block.gsd
    print(f"seed {seed}: {len(block.shots)} images {block.camera.width}x{block.camera.height}, GSD {gsd:.4f} m, "
          f"{len(block.gcps)} GCPs; scene {t_scene:.1f} s, render {t_render:.1f} s, align {t_align:.1f} s "
          f"({res.timings}), registered {res.registered}, reprojection {res.mean_reprojection_error:.3f} px")
    rec = load_model(ws)
    control = block.spread_control(5)
    gcps = block.gcp_set(control, noise_px=args.noise)
    t0 = time.time()
    result = georeference(rec, gcps)
    t_geo = time.time() - t0
    print(f"  control: {', '.join(control)}; georeference {t_geo:.1f} s; outliers: "
          f"{[o.name for o in result.outliers] or 'none'}")
    print(_line("control (adjusted)", result.rmse(CONTROL), gsd))
    print(_line("check, constrained adjustment", result.rmse(CHECK), gsd))
    print(_line("check, Helmert only", result.rmse(CHECK, helmert=True), gsd))
    for r in result.points:
        if r.status == CHECKED:
            print(f"    {r.name}: dx {r.dx:+.3f} dy {r.dy:+.3f} dz {r.dz:+.3f} m, {r.n_obs} obs")
    truth = georeference(block.truth_reconstruction(), gcps)
    print(_line("check, truth-built model", truth.rmse(CHECK), gsd))
    positions, _ = block.camera_positions(sigma=0.5, seed=13)
    pos = georeference(rec, block.gcp_set([], noise_px=args.noise), positions)
    print(_line("check, positions only (0.5 m)", pos.rmse(CHECK), gsd)
          + f"   (sigma/sqrt(n) = {0.5 / math.sqrt(len(positions)):.3f} m)")
    return result.rmse(CHECK), gsd


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--orbit", type=int, default=0, help="oblique images on an orbit, in addition")
    ap.add_argument("--noise", type=float, default=0.4, help="GCP observation noise, px")
    ap.add_argument("--features", type=int, default=2000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--keep", action="store_true", help="keep the rendered images and workspaces")
    args = ap.parse_args()
    work = args.workdir or tempfile.mkdtemp(prefix="archaeoortho-synthetic-")
    rows = []
    try:
        for seed in args.seeds:
            rows.append(run(seed, args, work))
    finally:
        if not args.keep and not args.workdir:
            shutil.rmtree(work, ignore_errors=True)
    if len(rows) > 1:
        print("summary (check RMSE in GSD, goal XY <= 1, Z <= 1.5):")
        for seed, (r, gsd) in zip(args.seeds, rows):
            print(f"  seed {seed}: XY {r['xy'] / gsd:.2f}  Z {r['z'] / gsd:.2f}")


if __name__ == "__main__":
    main()
