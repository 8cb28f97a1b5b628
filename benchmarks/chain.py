"""The whole chain to orthomosaic (core.pipeline.run_pipeline: align, EXIF-GPS georeference, DSM, orthomosaic,
report), timed per stage, with the peak memory of the whole process tree (pool workers included).

With --counts the chain runs on the first N images of the set for each N, and prints how time and memory grow
with the number of images (a power-law exponent fitted over the runs: 1 = linear).  --synthetic N renders the
synthetic vertical block of tests/synthetic.py with about N images (800 x 600, strips of 20) and runs the chain
on it, georeferenced by its camera positions (sigma 0.5 m) instead of EXIF GPS.

    python benchmarks/chain.py [--images DIR] [--counts 25,50,75] [--synthetic N] [--workdir DIR] [--no-report]

Defaults: Toledo (../shared/data/toledo/images, all 57 images).  Growth, as the issue asks:
    python benchmarks/chain.py --images ../shared/data/caliterra/images --counts 25,50,75
"""
import argparse
import json
import math
import os
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from _util import run_tree_measured  # noqa: E402

DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
EXT = (".jpg", ".jpeg", ".tif", ".tiff")


def child(images, ws, result, report, mapper="incremental", escalate=True):
    from core import pipeline
    from core.align.options import AlignOptions
    from core.common.progress import PrintProgress

    positions = os.path.join(os.path.dirname(images), "camera_positions.csv")
    control = (pipeline.Control(camera_positions_path=positions) if os.path.isfile(positions)
               else pipeline.Control(use_exif_gps=True))
    r = pipeline.run_pipeline(images, ws, pipeline.PipelineOptions(
        align=AlignOptions(mapper=mapper, escalate=escalate), make_report=report), control,
                              progress=PrintProgress("  "))
    with open(result, "w") as f:
        json.dump({"registered": r.align.registered, "images": r.align.images_given,
                   "mre": r.align.mean_reprojection_error, "align_timings": r.align.timings,
                   "seconds": r.seconds, "cpu_seconds": getattr(r, "cpu_seconds", None), "camera_rmse": r.georef.figures.get("CAMERA_RMSE_XYZ"),
                   "dsm_valid": r.dsm.valid_fraction, "pairs": r.dsm.pairs, "points": r.dsm.points,
                   "ortho_valid": r.ortho.valid_fraction, "ortho_resolution": r.ortho.resolution,
                   "dsm_resolution": r.dsm.resolution,
                   # issue 14's figures (absent before it: None): the DSM's measured / interpolated share of the
                   # cameras' hull, the radiometric correction's seam step, the nodata cells data encloses
                   "dsm_measured": getattr(r.dsm, "measured_fraction", None),
                   "dsm_interpolated": getattr(r.dsm, "interpolated_fraction", None),
                   "radiometry": getattr(r.ortho, "radiometry", None),
                   "interior_nodata": _interior_nodata(r.ortho.orthomosaic)}, f)


def _interior_nodata(path):
    """core.ortho.writer.interior_nodata where this checkout has it (None before issue 14)."""
    try:
        from core.ortho.writer import interior_nodata
    except ImportError:
        return None
    return interior_nodata(path)


def one_run(images, names, workdir, report, mapper="incremental", escalate=True):
    n = len(names)
    d = os.path.join(workdir, f"n{n}" + ("" if mapper == "incremental" else f"-{mapper}"))
    shutil.rmtree(d, ignore_errors=True)
    sub = os.path.join(d, "images")
    os.makedirs(sub)
    for name in names:
        os.symlink(os.path.join(images, name), os.path.join(sub, name))
    positions = os.path.join(os.path.dirname(images), "camera_positions.csv")
    if os.path.isfile(positions):
        shutil.copyfile(positions, os.path.join(d, "camera_positions.csv"))
    result = os.path.join(d, "result.json")
    cmd = [sys.executable, os.path.abspath(__file__), "--child", sub, os.path.join(d, "ws"), result]
    if not report:
        cmd.append("--no-report")
    cmd += ["--mapper", mapper] + ([] if escalate else ["--no-escalate"])
    log = os.path.join(d, "chain.log")
    when = []
    rc, wall, rss = run_tree_measured(cmd, log_path=log, peak_at=when)
    if rc != 0:
        raise SystemExit(f"the chain failed on {n} images (exit {rc}), see {log}")
    with open(result) as f:
        r = json.load(f)
    r.update(wall=wall, peak_rss_mib=rss, n=n, peak_stage=_stage_at(r["seconds"], when[0] if when else 0.0))
    return r


def _stage_at(seconds, t):
    """The stage running ``t`` seconds after the start (stages run in order; start-up counts to the first)."""
    elapsed = 0.0
    for stage, secs in seconds.items():
        elapsed += secs
        if t <= elapsed:
            return stage
    return "after the last stage"


def synthetic_set(n, workdir, supersample=2):
    """Render the synthetic vertical block with ~n images (``supersample`` x the pixel density ray-cast, in
    forked processes, one per core); write its camera positions beside the images."""
    from tests import synthetic as syn

    per_strip = 20
    strips = max(1, round(n / per_strip))
    d = os.path.join(workdir, f"synthetic{strips * per_strip}" + ("" if supersample == 2 else f"-ss{supersample}"))
    images = os.path.join(d, "images")
    if not os.path.isdir(images) or len(os.listdir(images)) != strips * per_strip:
        shutil.rmtree(d, ignore_errors=True)
        block = syn.vertical_block(seed=3, n_strips=strips, per_strip=per_strip, forward_overlap=0.75,
                                   side_overlap=0.35, n_buildings=max(5, strips * 3))
        block.render(images, supersample=supersample, jobs=os.cpu_count() or 1)
        positions, _ = block.camera_positions(sigma=0.5)
        with open(os.path.join(d, "camera_positions.csv"), "w") as f:
            f.write(f"{syn.CRS}\nimage,x,y,z,sigma\n")
            for p in positions:
                f.write(f"{p.image},{p.x:.3f},{p.y:.3f},{p.z:.3f},0.5\n")
    return images


def fit_exponent(xs, ys):
    """Least-squares slope of log(y) over log(x)."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(max(y, 1e-9)) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    den = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / den if den else float("nan")


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        mapper = sys.argv[sys.argv.index("--mapper") + 1] if "--mapper" in sys.argv else "incremental"
        child(sys.argv[2], sys.argv[3], sys.argv[4], "--no-report" not in sys.argv, mapper,
              "--no-escalate" not in sys.argv)
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--images", default=os.path.join(DATA, "toledo", "images"))
    ap.add_argument("--counts", default="", help="comma-separated image counts (first N images); empty = all")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-chain"))
    ap.add_argument("--no-report", action="store_true")
    ap.add_argument("--synthetic", type=int, default=0, help="render a synthetic block of about N images")
    ap.add_argument("--supersample", type=int, default=2, help="the synthetic block's ray-casting density (1: "
                    "four times faster to render, for the 1,000-photo block)")
    ap.add_argument("--no-escalate", action="store_true", help="the alignment's fast path only (Align images' "
                    "ESCALATE off): at 1,000 photos one escalation round of 49 photos took 25 minutes")
    ap.add_argument("--mapper", default="incremental", help="incremental, global, or both (each count runs twice)")
    a = ap.parse_args()
    images = os.path.abspath(synthetic_set(a.synthetic, a.workdir, a.supersample) if a.synthetic else a.images)
    names = sorted(n for n in os.listdir(images) if n.lower().endswith(EXT))
    counts = [int(c) for c in a.counts.split(",") if c.strip()] or [len(names)]
    workdir = os.path.join(a.workdir, os.path.basename(os.path.dirname(images)) or "set")
    print(f"images: {images} ({len(names)}); cores: {os.cpu_count()}; runs: {counts}", flush=True)
    mappers = ["incremental", "global"] if a.mapper == "both" else [a.mapper]
    runs = []
    for n, mapper in [(n, m) for n in counts for m in mappers]:
        r = one_run(images, names[:n], workdir, not a.no_report, mapper, not a.no_escalate)
        r["mapper"] = mapper
        runs.append(r)
        stages = ", ".join(f"{k} {v:.0f}" for k, v in r["seconds"].items())
        print(f"\n{n} images, {mapper} mapping: wall {r['wall']:.0f} s ({stages}); peak RSS (process tree) {r['peak_rss_mib']:.0f} MiB "
              f"(during {r['peak_stage']})",
              flush=True)
        if r.get("cpu_seconds"):
            cpu = ", ".join(f"{k} {v:.0f}" for k, v in r["cpu_seconds"].items())
            print(f"  CPU seconds: {sum(r['cpu_seconds'].values()):.0f} ({cpu})")
        al = ", ".join(f"{k} {v:.0f}" for k, v in r["align_timings"].items())
        print(f"  align: {r['registered']}/{r['images']} registered, {r['mre']:.3f} px ({al} s)")
        cam = "n/a" if r["camera_rmse"] is None else f"{r['camera_rmse']:.2f} m"
        print(f"  georeference ({'camera positions' if a.synthetic else 'EXIF GPS'}): camera RMSE XYZ {cam}")
        print(f"  DSM: {r['pairs']} pairs, {r['points']} points, {r['dsm_resolution']:.3f} m cells, valid "
              f"{r['dsm_valid']:.3f}; orthomosaic {r['ortho_resolution']:.3f} m cells, valid {r['ortho_valid']:.3f}")
        rad = r.get("radiometry") or {}
        print(f"  DSM measured / interpolated (of the cameras' hull): {r.get('dsm_measured')} / "
              f"{r.get('dsm_interpolated')}; mosaic nodata cells enclosed by data: {r.get('interior_nodata')}; "
              f"radiometry: {json.dumps(rad) if rad else 'n/a'}")
        print(f"  per image: {r['wall'] / n:.1f} s", flush=True)
    for mapper in mappers:
        grown = [r for r in runs if r["mapper"] == mapper]
        if len(grown) > 1:
            _print_growth(mapper, grown)


def _print_growth(mapper, runs):
    if len(runs) > 1:
        xs = [r["n"] for r in runs]
        print(f"\ngrowth with the number of images, {mapper} mapping (exponent of a power law fitted over the runs; 1 = linear):")
        print(f"  whole chain time   {fit_exponent(xs, [r['wall'] for r in runs]):.2f}")
        for stage in runs[0]["seconds"]:
            print(f"  {stage:<18} {fit_exponent(xs, [r['seconds'].get(stage, 0.0) for r in runs]):.2f}")
        print(f"  peak RSS           {fit_exponent(xs, [r['peak_rss_mib'] for r in runs]):.2f}")


if __name__ == "__main__":
    main()
