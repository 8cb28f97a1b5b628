"""A synthetic multispectral rig block through the whole chain (issue 37): band files -> Stack multispectral
captures (irradiance radiometry) -> Run pipeline on the stacked photos -> NDVI, checked against the scene's truth
(tests/rig_scene.py), and timed against the same block's primary band alone.

    python benchmarks/rig_block.py [--strips 4 --per-strip 10] [--supersample 1] [--workdir DIR] [--no-primary]

Prints: the stacking's CPU-s and its worst band residual; for the chain on the stacked photos and on the Green band
files alone: wall, CPU-s per stage and peak RSS of the process tree (benchmarks/chain.py's child); the 4-band /
primary ratio of the whole (stacking included); and the orthomosaic against the truth (rig_scene.evaluate):
reflectance per band over one constant, band-to-band registration in the mosaic, the crop mark's NDVI contrast.
"""
import argparse
import json
import os
import resource
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)


def _cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def _orthomosaic(ws):
    for root, _dirs, files in os.walk(ws):
        for f in files:
            if f == "orthomosaic.tif":
                return os.path.join(root, f)
    raise SystemExit(f"no orthomosaic.tif under {ws}")


def main():
    from chain import one_run

    from core.prepare.captures import CaptureStackOptions, stack_capture_folder
    from tests import rig_scene as rs

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--strips", type=int, default=4)
    ap.add_argument("--per-strip", type=int, default=10)
    ap.add_argument("--supersample", type=int, default=1)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-rig"))
    ap.add_argument("--no-primary", action="store_true", help="skip the primary band's chain")
    a = ap.parse_args()
    n = a.strips * a.per_strip
    work = os.path.join(a.workdir, f"rig{n}")
    bands = os.path.join(work, "bands")
    rig = rs.rig_block(n_strips=a.strips, per_strip=a.per_strip)
    t0 = time.time()
    if not os.path.isdir(bands) or len(os.listdir(bands)) != 4 * n:
        shutil.rmtree(work, ignore_errors=True)
        rs.render(rig, bands, supersample=a.supersample)
    print(f"{n} captures of 4 bands ({rig.width} x {rig.height} px), ring at {rig.ring}; rendered in "
          f"{time.time() - t0:.0f} s", flush=True)
    photos = os.path.join(work, "stacked", "images")
    shutil.rmtree(os.path.dirname(photos), ignore_errors=True)
    c0, w0 = _cpu(), time.time()
    st = stack_capture_folder(bands, CaptureStackOptions(photos, radiometry="irradiance"))
    stack_cpu, stack_wall = _cpu() - c0, time.time() - w0
    shutil.copyfile(os.path.join(work, "camera_positions.csv"), os.path.join(work, "stacked", "camera_positions.csv"))
    print(f"stacking: {len(st.photos)} photos, bands {', '.join(st.bands)}, {stack_wall:.0f} s wall, "
          f"{stack_cpu:.0f} CPU-s; worst band residual after registration (px): "
          f"{json.dumps({k: round(v, 3) for k, v in st.worst_residual_px.items()})}", flush=True)
    runs = {}
    r = one_run(photos, sorted(os.listdir(photos)), os.path.join(a.workdir, f"rig{n}-chain"), False)
    runs["4-band"] = r
    if not a.no_primary:
        prim = os.path.join(work, "primary", "images")
        shutil.rmtree(os.path.dirname(prim), ignore_errors=True)
        os.makedirs(prim)
        for f in sorted(os.listdir(bands)):
            if f.endswith("_GRE.TIF"):
                os.symlink(os.path.join(bands, f), os.path.join(prim, f))
        with open(os.path.join(work, "camera_positions.csv")) as f:
            lines = f.read().splitlines()
        with open(os.path.join(work, "primary", "camera_positions.csv"), "w") as f:
            f.write("\n".join(lines[:2] + [ln.replace(".tif,", "_GRE.TIF,", 1) for ln in lines[2:]]) + "\n")
        runs["primary (Green)"] = one_run(prim, sorted(os.listdir(prim)), os.path.join(a.workdir, f"rig{n}-primary"),
                                          False)
    for name, r in runs.items():
        cpu = sum((r.get("cpu_seconds") or {}).values())
        stages = ", ".join(f"{k} {v:.0f}" for k, v in (r.get("cpu_seconds") or {}).items())
        print(f"\nchain on {name}: {r['registered']}/{r['images']} registered at {r['mre']:.3f} px; wall "
              f"{r['wall']:.0f} s; CPU-s {cpu:.0f} ({stages}); peak RSS {r['peak_rss_mib']:.0f} MiB; DSM measured "
              f"{r.get('dsm_measured')}; mosaic valid {r['ortho_valid']:.3f}", flush=True)
    if "primary (Green)" in runs:
        four = sum(runs["4-band"]["cpu_seconds"].values()) + stack_cpu
        one = sum(runs["primary (Green)"]["cpu_seconds"].values())
        print(f"\n4-band block (stacking + chain) / primary band alone: {four:.0f} / {one:.0f} CPU-s = "
              f"{four / one:.2f} x (wall {runs['4-band']['wall'] + stack_wall:.0f} / "
              f"{runs['primary (Green)']['wall']:.0f} s)")
    ortho = _orthomosaic(os.path.join(a.workdir, f"rig{n}-chain"))
    ev = rs.evaluate(rig, ortho)
    print("\northomosaic against the truth (open ground):")
    print(json.dumps(ev, indent=1))


if __name__ == "__main__":
    main()
