"""The synthetic wide-angle rolling-shutter block over tall, sparse trees (issue 37 Must show, tests/woodland_scene.py)
aligned by Align images (default options) and by pycolmap's default pipeline (``extract_features`` +
``match_exhaustive`` + ``incremental_mapping``), for several rolling-shutter settings, against the truth.

    python benchmarks/woodland_block.py [--readout-ms 0,40,80] [--strips 3 --per-strip 8] [--workdir DIR]
                                        [--jobs 2] [--threads 2] [--no-pycolmap]

``--readout-ms``: the frame's readout time (0: a global shutter; 40: the default, 44 us a line at 900 rows) at the
drone's 8 m/s.  Each setting's photos are rendered once under ``<workdir>/<setting>/images`` and reused.  Prints per
setting and pipeline: photos registered, mean reprojection error, the camera centres against the truth after the
best similarity (RMSE and worst, m and % of the flying height), the focal length found (truth 900 px), the CPU-s
(user + system of the child process) and wall seconds, and a table to paste.
"""
import argparse
import json
import os
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from _util import LAST_RUN, run_measured  # noqa: E402

OURS = r"""
import json, sys
sys.path.insert(0, sys.argv[1])
from core.align.options import AlignOptions
from core.align.stage import align
r = align(sys.argv[2], sys.argv[3], AlignOptions(num_threads=int(sys.argv[4])))
print("RESULT", json.dumps({"registered": r.registered, "mre": r.mean_reprojection_error, "model": r.model_dir,
                            "escalation": bool(r.escalation), "first_pass": (r.first_pass or {}).get("level"),
                            "focal_held": bool(r.focal_held)}))
"""

PYCOLMAP = r"""
import json, os, sys
import pycolmap
images, d, threads = sys.argv[1], sys.argv[2], int(sys.argv[3])
db = os.path.join(d, "database.db")
extraction = pycolmap.FeatureExtractionOptions()
extraction.num_threads = threads
pycolmap.extract_features(db, images, extraction_options=extraction, device=pycolmap.Device.cpu)
matching = pycolmap.FeatureMatchingOptions()
matching.num_threads = threads
pycolmap.match_exhaustive(db, matching_options=matching, device=pycolmap.Device.cpu)
mapping = pycolmap.IncrementalPipelineOptions()
mapping.num_threads = threads
recs = pycolmap.incremental_mapping(db, images, os.path.join(d, "sparse"), options=mapping)
best = max(recs, key=lambda k: recs[k].num_reg_images()) if recs else None
print("RESULT", json.dumps({"registered": recs[best].num_reg_images() if recs else 0,
                            "mre": recs[best].compute_mean_reprojection_error() if recs else None,
                            "model": os.path.join(d, "sparse", str(best)) if recs else None}))
"""


def _child(code, args, log):
    rc, wall, _rss = run_measured([sys.executable, "-c", code] + [str(a) for a in args], log_path=log)
    if rc != 0:
        raise SystemExit(f"failed, see {log}")
    out = [json.loads(line[7:]) for line in open(log) if line.startswith("RESULT ")][0]
    out["wall"], out["cpu"] = wall, LAST_RUN["cpu"]
    return out


def run_ours(images, work, threads):
    ws = os.path.join(work, "ws")
    shutil.rmtree(ws, ignore_errors=True)  # nothing reused: the CPU-s are the whole alignment's
    return _child(OURS, [ROOT, images, ws, threads], os.path.join(work, "ours.log"))


def run_pycolmap(images, work, threads):
    d = os.path.join(work, "pycolmap")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "sparse"))
    return _child(PYCOLMAP, [images, d, threads], os.path.join(d, "run.log"))


def _judge(block, out):
    import pycolmap

    from tests import woodland_scene as wl

    if not out.get("model"):
        return dict(out, rmse=float("nan"), max=float("nan"), focal=float("nan"))
    rec = pycolmap.Reconstruction(out["model"])
    err = wl.centre_errors(block, rec)
    cam = next(iter(rec.cameras.values()))
    return dict(out, rmse=err["rmse"], max=err["max"], focal=float(cam.params[0]), model_name=cam.model.name)


def main():
    from tests import woodland_scene as wl

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--readout-ms", default="0,40,80")
    ap.add_argument("--strips", type=int, default=3)
    ap.add_argument("--per-strip", type=int, default=8)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-woodland"))
    ap.add_argument("--jobs", type=int, default=2, help="processes rendering the photos")
    ap.add_argument("--threads", type=int, default=2, help="threads of either alignment")
    ap.add_argument("--no-pycolmap", action="store_true")
    a = ap.parse_args()
    rows = []
    for ms in (float(v) for v in a.readout_ms.split(",")):
        flight = wl.Flight(n_strips=a.strips, per_strip=a.per_strip, line_time=ms / 1000.0 / wl.CAMERA.height)
        block = wl.woodland_block(flight=flight)
        work = os.path.join(a.workdir, f"{a.strips}x{a.per_strip}-readout{ms:g}ms")
        images = os.path.join(work, "images")
        if not os.path.isdir(images) or len(os.listdir(images)) != len(block.shots):
            shutil.rmtree(work, ignore_errors=True)
            block.render(images, jobs=a.jobs)
        shift = flight.speed * ms / 1000.0
        print(f"\n== readout {ms:g} ms ({flight.line_time * 1e6:.1f} us a line; {shift:.2f} m of flight, "
              f"{shift / block.gsd:.1f} px on the ground, between first and last row): {len(block.shots)} photos "
              f"{block.camera.width} x {block.camera.height}, {flight.altitude:g} m up, GSD {block.gsd * 100:.1f} cm, "
              f"{len(block.scene.trees)} trees {min(t[2] for t in block.scene.trees):.0f}-"
              f"{max(t[2] for t in block.scene.trees):.0f} m, span {block.span():.0f} m")
        for name, run in (("ours", run_ours), ("pycolmap defaults", run_pycolmap))[:1 if a.no_pycolmap else 2]:
            r = _judge(block, run(images, work, a.threads))
            h = flight.altitude
            print(f"{name}: {r['registered']}/{len(block.shots)} registered, {r['mre'] or float('nan'):.3f} px, "
                  f"centres {r['rmse']:.3f} m RMSE ({100 * r['rmse'] / h:.2f} % of {h:g} m), worst {r['max']:.3f} m; "
                  f"focal {r['focal']:.1f} px (truth {block.camera.fx:g}); {r['cpu']:.1f} CPU-s, {r['wall']:.1f} s wall"
                  + (f"; first pass {r['first_pass']}, escalation {r['escalation']}, focal held {r['focal_held']}"
                     if name == "ours" else ""))
            rows.append((ms, name, len(block.shots), h, r))
    print("\n| readout | pipeline | registered | reprojection | camera centres RMSE / worst (% of flying height) "
          "| focal (truth 900 px) | CPU-s |\n|---|---|---|---|---|---|---|")
    for ms, name, n, h, r in rows:
        print(f"| {ms:g} ms | {name} | {r['registered']}/{n} | {r['mre'] or float('nan'):.3f} px | {r['rmse']:.3f} / "
              f"{r['max']:.3f} m ({100 * r['rmse'] / h:.2f} / {100 * r['max'] / h:.2f} %) | {r['focal']:.0f} px | "
              f"{r['cpu']:.1f} |")


if __name__ == "__main__":
    main()
