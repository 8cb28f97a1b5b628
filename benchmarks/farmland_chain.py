"""The whole chain on issue 33's synthetic low-texture block (tests/lowtexture_scene.py's ``full_block``: 4 strips
x 10 photos of 3600 x 2700 px, 9.7 MP, 4.9 cm GSD, ploughed fields at ``--contrast`` of the scene's texture),
measured per stage and judged against the block's truth.

Three steps (each skips what an earlier run left):

1. ``render``: the photos, once, into <workdir>/farm-<contrast>-<n>/images (the same pixels as
   ``FarmBlock.render``: the same seed per photo, JPEG quality 92; ``--jobs`` processes render alternate photos,
   resumable), and camera_positions.csv beside them: the known projection centres in the block's CRS
   (tests/synthetic.py's EPSG:32633) with N(0, ``--gnss-sigma``) noise from a fixed seed, as a GNSS would give;
2. ``chain``: ``benchmarks/memory.py chain`` on those photos (align, georeference from the positions file, DSM,
   orthophoto, DTM, relief, report; one process per stage: CPU-s and peak RSS of each process tree), the focal
   length given as EXIF would (the photos carry none);
3. ``judge``: from the workspace: registered photos and the first pass / escalation (sfm/alignment.json), the DSM
   stage's measured / interpolated / removed fractions, blunders (cells more than 3 m and 5 m from their 15 x 15
   median, benchmarks/dense.py's count), RMSE over the fields against ``scene.height_at`` in GSD (as georeferenced,
   and after removing the best plane through the error: the GNSS-only georeference's shift and tilt), the seam
   step of the mosaic (the orthophoto stage's radiometry record), and the issue's goals.

    nice -n 19 python benchmarks/farmland_chain.py --contrast 0.3 --workdir /work/bench33 [--jobs 2]
        [--steps render,chain,pycolmap,judge] [--small]

The DSM stage again at quality full on a copy of the workspace, judged:

    nice -n 19 python benchmarks/memory.py chain --images <folder>/images --workdir <folder>/chain --reuse \
        --stages dsm --dsm-quality full
    nice -n 19 python benchmarks/farmland_chain.py --contrast 0.3 --workdir /work/bench33 --steps judge \
        --judge-run chain-0-reuse

(``pycolmap``, not run by default: pycolmap's default pipeline on the same photos, benchmarks/align.py's, the
reference of the alignment's CPU-s and registered photos.)

CPU-s and peak RSS do not depend on the machine's load; wall times do (the run prints them, do not compare them).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
GIB = 2 ** 30
GOALS = {"stage_gib": 3.0, "chain_cpu": 800.0, "measured": 0.85, "rmse_gsd": 1.5, "seam": 0.02}
ISSUE = "issue 33's real block: 1,331 CPU-s, peak 6.7 GiB, DSM 60 % measured, first pass 30/40, escalation 318 s"


def block_of(args):
    from tests import lowtexture_scene as lt

    if args.small:
        return lt.small_block(args.contrast)
    return lt.full_block(args.strips, args.per_strip, args.contrast)


def folder_of(args):
    n = 10 if args.small else args.strips * args.per_strip
    return os.path.join(args.workdir, f"farm{'-small' if args.small else ''}-{args.contrast:g}-{n}")


# ---------------------------------------------------------------- 1. render

def render_part(args):
    """Child: render the photos k with k % jobs == part (FarmBlock.render's pixels), each written atomically."""
    import cv2

    from tests import lowtexture_scene as lt

    block = block_of(args)
    images = os.path.join(folder_of(args), "images")
    for k, s in enumerate(block.shots):
        path = os.path.join(images, s.name)
        if k % args.jobs != args.part or os.path.isfile(path):
            continue
        t0 = time.time()
        img = lt.render_farm_image(block.scene, block.camera, s, 1, seed=block.seed * 1000 + k)
        tmp = os.path.join(os.path.dirname(images), "." + s.name)
        if not cv2.imwrite(tmp, cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), [cv2.IMWRITE_JPEG_QUALITY, 92]):
            raise OSError(f"cannot write {tmp}")
        os.replace(tmp, path)
        print(f"  {s.name} {time.time() - t0:.0f} s", flush=True)


def render(args):
    from tests import synthetic as syn

    block = block_of(args)
    d = folder_of(args)
    images = os.path.join(d, "images")
    os.makedirs(images, exist_ok=True)
    t0 = time.time()
    kids = [subprocess.Popen([sys.executable, os.path.abspath(__file__), "--render-part", str(p)] + sys.argv[1:])
            for p in range(args.jobs)]
    if any(k.wait() for k in kids):
        raise SystemExit("rendering failed")
    n = len([x for x in os.listdir(images) if x.endswith(".jpg")])
    print(f"render: {n} photos of {block.camera.width} x {block.camera.height} px in {images} "
          f"({time.time() - t0:.0f} s wall this run)", flush=True)
    positions = os.path.join(d, "camera_positions.csv")
    if not os.path.isfile(positions):
        pos, _ = block.camera_positions(sigma=args.gnss_sigma, seed=args.gnss_seed)
        with open(positions + ".part", "w") as out:
            out.write(f"{syn.CRS}\nimage,x,y,z,sigma\n")
            for p in pos:
                out.write(f"{p.image},{p.x:.3f},{p.y:.3f},{p.z:.3f},{args.gnss_sigma:g}\n")
        os.replace(positions + ".part", positions)
        print(f"  camera positions (N(0, {args.gnss_sigma:g} m) noise, seed {args.gnss_seed}): {positions}")
    return images


# ---------------------------------------------------------------- 2. chain

def chain(args, images):
    cmd = [sys.executable, os.path.join(HERE, "memory.py"), "chain", "--images", images, "--workdir",
           os.path.join(folder_of(args), "chain"), "--focal-px", f"{block_of(args).camera.fx:g}"]
    if args.stages:
        cmd += ["--stages", args.stages]
    print(" ".join(cmd), flush=True)
    out = subprocess.run(cmd, stdout=subprocess.PIPE, text=True, check=False).stdout
    print(out, flush=True)
    last = [line for line in out.splitlines() if line.startswith("{")]
    rows = list(json.loads(last[-1]).values())[0] if last else []
    with open(os.path.join(folder_of(args), "chain", "stages.json"), "w") as fh:
        json.dump(rows, fh)
    return rows


def pycolmap_reference(args, images):
    """pycolmap's default pipeline on the same photos (benchmarks/align.py's), for the alignment's ratio."""
    sys.path.insert(0, HERE)
    import align as bench_align
    from _util import LAST_RUN

    result, wall, rss = bench_align.pycolmap_defaults(images, os.path.join(folder_of(args), "chain"))
    result.update(cpu=LAST_RUN.get("cpu"), wall=wall, rss_mib=rss)
    with open(os.path.join(folder_of(args), "chain", "pycolmap.json"), "w") as fh:
        json.dump(result, fh)
    print(f"pycolmap defaults: {json.dumps(result)}", flush=True)


# ---------------------------------------------------------------- 3. judge

def local_deviation(z, size=15):
    """|z - its size x size median| (nodata taking the nearest cell's height), NaN on nodata: benchmarks/dense.py's
    blunder count (tests/test_dense_lowtexture.py's blunder_count) is the cells of this above a limit."""
    from scipy import ndimage

    have = np.isfinite(z)
    idx = ndimage.distance_transform_edt(~have, return_distances=False, return_indices=True)
    zf = z[tuple(idx)]
    del idx
    dev = np.abs(zf - ndimage.median_filter(zf, size=size))
    dev[~have] = np.nan
    return dev


def judge(args):
    from core.io import raster
    from tests import synthetic as syn

    block = block_of(args)
    chain_dir = os.path.join(folder_of(args), "chain")
    ws = os.path.join(chain_dir, args.judge_run, "ws")
    stages_path = os.path.join(chain_dir, "stages.json")
    rows = json.load(open(stages_path)) if os.path.isfile(stages_path) else []
    gsd = block.gsd
    print(f"\n== {len(block.shots)} photos of {block.camera.width} x {block.camera.height} px, GSD {gsd:.3f} m, "
          f"fields at contrast {args.contrast:g}; GNSS sigma {args.gnss_sigma:g} m ==")
    total_cpu = sum(r["cpu"] for r in rows if not r["rc"])
    peak = max((r["rss"] for r in rows), default=0)
    print("stage           CPU-s   peak GiB   wall s (shared machine)")
    for r in rows:
        state = "" if not r["rc"] else f"  FAILED (exit {r['rc']})"
        print(f"  {r['stage']:13s} {r['cpu']:7.1f} {r['rss'] / GIB:9.2f} {r['wall']:9.0f}{state}")
    print(f"  {'chain':13s} {total_cpu:7.1f} {peak / GIB:9.2f}   (goals: <= {GOALS['chain_cpu']:.0f} CPU-s, "
          f"<= {GOALS['stage_gib']:g} GiB a stage)")
    al = _read_json(os.path.join(ws, "sfm", "alignment.json"))
    if al:
        fp, esc = al.get("first_pass") or {}, al.get("escalation")
        print(f"alignment: {al.get('registered')}/{al.get('images_given')} registered, "
              f"{al.get('mean_reprojection_error', float('nan')):.3f} px, {al.get('num_pairs')} pairs "
              f"({al.get('pairing_used')}); first pass {fp.get('level')} ({fp.get('reason')}); escalation "
              f"{json.dumps(esc)[:400] if esc else 'did not run'}; timings {al.get('timings')}")
    wsj = _read_json(os.path.join(ws, "workspace.json")) or {}
    res = ((wsj.get("stages") or {}).get("dsm") or {}).get("results") or {}
    if res:
        print(f"DSM stage record: measured {res.get('MEASURED_FRACTION'):.3f}, interpolated "
              f"{res.get('INTERPOLATED_FRACTION'):.3f}, removed {res.get('REMOVED_FRACTION'):.2g} "
              f"({res.get('removed_cells')} cells) of the cameras' hull; {res.get('width')} x {res.get('height')} "
              f"cells at {res.get('resolution')} m; {res.get('pairs')} pairs")
        outs = wsj["stages"]["dsm"].get("outputs") or {}
        dsm_path = os.path.join(ws, outs.get("dsm", ""))
        if os.path.isfile(dsm_path):
            _dsm_truth(block, dsm_path, os.path.join(ws, outs.get("dsm_source", "")), gsd, syn, raster)
    ortho = os.path.join(chain_dir, args.judge_run, "orthophoto.log")
    if os.path.isfile(ortho):
        for line in open(ortho):
            if line.startswith("RADIOMETRY"):
                rad = json.loads(line[len("RADIOMETRY"):])
                print(f"mosaic seam brightness step: {rad.get('seam_step_before')} before, "
                      f"{rad.get('seam_step_after')} after the radiometric correction (goal <= {GOALS['seam']:g})")
                print(f"  on level ground ({rad.get('seam_level_fraction')} of the seam points): "
                      f"{rad.get('seam_step_level_before')} before, {rad.get('seam_step_level_after')} after")
    pyc = _read_json(os.path.join(chain_dir, "pycolmap.json"))
    if pyc:
        align_cpu = next((r["cpu"] for r in rows if r["stage"] == "align" and not r["rc"]), None)
        ratio = f", ours {align_cpu / pyc['cpu']:.2f} x its CPU-s (goal <= 0.35)" if align_cpu and pyc.get("cpu") else ""
        print(f"pycolmap defaults on the same photos: {pyc['registered']}/{len(block.shots)} registered, "
              f"{pyc['mre']:.3f} px, {pyc.get('cpu', 0):.0f} CPU-s, peak {pyc['rss_mib'] / 1024:.2f} GiB{ratio}")
    print(f"issue's starting figures: {ISSUE}")


def _dsm_truth(block, dsm_path, src_path, gsd, syn, raster):
    z, gt, _ = raster.read_dsm(dsm_path)
    h, w = z.shape
    x, y = np.meshgrid(gt[0] + (np.arange(w) + 0.5) * gt[1] - syn.ORIGIN[0],
                       gt[3] + (np.arange(h) + 0.5) * gt[5] - syn.ORIGIN[1])
    src = np.nan_to_num(raster.read_dsm(src_path)[0]) if os.path.isfile(src_path) else None
    # the truth in rows, so that the scene's Voronoi / tree loops do not hold float64 copies of the whole grid
    err = np.full(z.shape, np.nan, np.float32)
    fields = np.zeros(z.shape, bool)
    for r0 in range(0, h, 512):
        sl = slice(r0, r0 + 512)
        err[sl] = z[sl] - (block.scene.height_at(x[sl], y[sl]) - syn.ORIGIN[2])
        fields[sl] = block.scene.field_mask(x[sl], y[sl])
    have = fields & np.isfinite(err)
    xs, ys, es = x[have], y[have], err[have].astype(float)
    step = max(1, xs.size // 2_000_000)  # the plane from a thinned sample
    coef = np.linalg.lstsq(np.column_stack([np.ones_like(xs[::step]), xs[::step], ys[::step]]), es[::step],
                           rcond=None)[0]
    flat = np.full(z.shape, np.nan, np.float32)
    flat[have] = es - (coef[0] + coef[1] * xs + coef[2] * ys)
    del xs, ys, es
    print(f"DSM against the truth (fields: {have.sum()} cells; georeference error as a plane: offset "
          f"{coef[0]:.3f} m, tilt {coef[1] * 1000:.2f} / {coef[2] * 1000:.2f} mm/m)")
    masks = [("fields, every cell with a height", have)]
    if src is not None:
        masks.insert(0, ("fields, measured cells", have & (src == raster.SOURCE_MEASURED)))
        print(f"  measured cells on the fields: {masks[0][1].sum() / max(have.sum(), 1):.3f}")
    for name, m in masks:
        for label, e in (("as georeferenced", err[m]), ("plane removed", flat[m])):
            rmse = float(np.sqrt(np.mean(e.astype(float) ** 2)))
            print(f"  {name}, {label}: RMSE {rmse:.3f} m = {rmse / gsd:.2f} GSD (goal <= {GOALS['rmse_gsd']:g}), "
                  f"median |dz| {np.median(np.abs(e)) / gsd:.2f} GSD, 95 % {np.percentile(np.abs(e), 95) / gsd:.2f}"
                  " GSD")
    far = np.zeros(z.shape, bool)  # the fields 3 m away from the road, trees and building: a step there is a blunder
    for r0 in range(0, h, 512):
        far[r0:r0 + 512] = block.scene.field_mask(x[r0:r0 + 512], y[r0:r0 + 512], margin=3.0)
    dev = local_deviation(z)
    print(f"  blunders: {int((dev > 3.0).sum())} cells > 3 m and {int((dev > 5.0).sum())} > 5 m from their 15 x 15 "
          f"median (the trees and the building included); on the fields 3 m from them: "
          f"{int(((dev > 3.0) & far).sum())} and {int(((dev > 5.0) & far).sum())}; field cells > 1 m off the truth "
          f"(plane removed): {int((np.abs(np.nan_to_num(flat)) > 1.0).sum())}")


def _read_json(path):
    try:
        with open(path) as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--contrast", type=float, default=0.3)
    ap.add_argument("--strips", type=int, default=4)
    ap.add_argument("--per-strip", type=int, default=10)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-farmland"))
    ap.add_argument("--jobs", type=int, default=1, help="rendering processes")
    ap.add_argument("--gnss-sigma", type=float, default=2.0, help="m, the camera positions' noise and sigma")
    ap.add_argument("--gnss-seed", type=int, default=33)
    ap.add_argument("--small", action="store_true", help="the fast test's block (10 photos of 640 x 480): a trial")
    ap.add_argument("--steps", default="render,chain,judge")
    ap.add_argument("--stages", default="", help="memory.py's --stages (default: all)")
    ap.add_argument("--judge-run", default="chain-0",
                    help="judge: the run under <folder>/chain (chain-0-reuse: memory.py chain --reuse's, e.g. the "
                         "DSM at another --dsm-quality)")
    ap.add_argument("--render-part", type=int, default=-1, help=argparse.SUPPRESS)
    args = ap.parse_args()
    args.workdir = os.path.abspath(args.workdir)
    if args.render_part >= 0:
        args.part = args.render_part
        return render_part(args)
    steps = args.steps.split(",")
    images = os.path.join(folder_of(args), "images")
    if "render" in steps:
        images = render(args)
    if "chain" in steps:
        chain(args, images)
    if "pycolmap" in steps:
        pycolmap_reference(args, images)
    if "judge" in steps:
        judge(args)


if __name__ == "__main__":
    main()
