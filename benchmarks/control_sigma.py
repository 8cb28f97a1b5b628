"""Control of unknown accuracy (issue 32, item 2) on real data: Helmert-only against the adjusted solution on the
same check points, with the control's sigma estimated from the data (the files carry none) and, for comparison,
with the placeholder sigma stated as if it were the control's accuracy (the behaviour before the estimate).

Synthetic (tests/synthetic.py, models built from the truth): the vertical block (18 photos, 8 control points, 6
check points) and a single strip that sags by 1.5 m (12 photos, 5 control, 9 check), control of 3 m and of
0.02 m accuracy without sigmas, ``--seeds`` noise realisations each.
COPR (cross targets, handheld-GPS metre-level coordinates, Z a placeholder 0, no sigma columns): every set of 3
targets held out as check points in turn (a rotating selection, ``--copr-sets``), the others control.
Toledo: the EXIF GPS camera positions (no sigma) as the datum, the 4 surveyed targets of gcp_list.txt (Z a
placeholder) as check points in XY, and the camera centres against cameras_32617.txt.

Archive (``--only archive``): the synthetic archive blocks that benchmarks/archive.py aligned (build/bench-archive/
*/ws, copied, not touched), georeferenced through the stage with its "3 m" control CSV (no sigma columns) and the
same with sigmas of 3 m given: Helmert-only vs adjusted check points.

Prints the figures, asserts nothing.  Aligns the sets once into build/bench-control-sigma/ (reused).

    python benchmarks/control_sigma.py [--only synthetic|copr|toledo|archive] [--copr-sets N] [--seeds N]
"""
import argparse
import dataclasses
import itertools
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
WORK = os.path.join(ROOT, "build", "bench-control-sigma")

from core.align.options import AlignOptions  # noqa: E402
from core.align.stage import align, load_model  # noqa: E402
from core.georef.adjust import georeference  # noqa: E402
from core.georef.options import GeorefOptions  # noqa: E402
from core.io import gcp as gcpmod  # noqa: E402
from core.project.workspace import Workspace  # noqa: E402


def ensure_aligned(name):
    ws = os.path.join(WORK, name)
    try:
        if Workspace.open(ws).stage_done("align"):
            return ws
    except Exception:  # noqa: BLE001 - not there yet
        pass
    t0 = time.time()
    r = align(os.path.join(DATA, name, "images"), ws, AlignOptions(num_threads=2))
    print(f"{name}: aligned {r.registered}/{r.images_given} in {time.time() - t0:.0f} s")
    return ws


def stated(gcps):
    """The same points with their placeholder sigmas stated as given (a file with 0.02 / 0.05 m columns)."""
    return dataclasses.replace(gcps, points=[dataclasses.replace(p, sigma_given=True) for p in gcps.points])


def _xy(r):
    return f"{r['xy']:.3f}" if r and r.get("n") else "  –  "


def _est(result):
    return "; ".join(f"{e['group']}: sigma XY {e['sigma_xy_m']:.3f} Z {e['sigma_z_m']:.3f} m (rigid fit "
                     f"{e['helmert_xy_m']:.3f} / {e['helmert_z_m']:.3f}, {e['iterations']} it., excluded "
                     f"{','.join(e['excluded']) or '-'})" for e in result.sigma_estimates) or "sigmas given"


def synthetic(n_seeds):
    from tests import synthetic as syn

    block = syn.vertical_block(seed=1)
    strip = syn.single_strip(seed=3, n=12)
    xs = np.array([s.centre[0] for s in strip.shots])
    bend = syn.dome(1.5, (float(xs.mean()), 0.0), 0.5 * (xs.max() - xs.min()) + 10.0)
    ground = sorted((p for p in strip.gcps if p.kind == "ground"), key=lambda p: p.xyz[0])
    sets = (("vertical block", block, block.truth_reconstruction(), block.spread_control(8)),
            ("sagging strip", strip, strip.truth_reconstruction(deform=bend),
             [ground[0].name, ground[1].name, ground[-1].name, ground[-2].name, ground[len(ground) // 2].name]))
    print(f"\nSynthetic: check RMSE 3-D (XY / Z), metres, mean over {n_seeds} noise realisations; GSD "
          f"{block.gsd:.3f} m")
    print(f"  {'set':<16} {'control':>8} {'Helmert':>20} {'adjusted, estimated':>22} {'worst ratio':>11} "
          f"{'adjusted, stated 0.02':>22} {'worst':>6}  estimated sigma XY / Z (range)")
    for label, blk, rec, control in sets:
        for noise in (3.0, 0.02):
            h, a, o, sig = [], [], [], []
            for seed in range(n_seeds):
                g = blk.gcp_set(control, noise_px=0.4)
                rng = np.random.default_rng(100 + seed)
                pts = []
                for p in g.points:
                    if p.role == gcpmod.CONTROL:
                        e = rng.normal(0.0, noise, 3)
                        p = dataclasses.replace(p, x=p.x + e[0], y=p.y + e[1], z=p.z + e[2], sigma_given=False)
                    pts.append(p)
                g = dataclasses.replace(g, points=pts)
                est = georeference(rec, g)
                old = georeference(rec, stated(g))
                h.append(est.rmse(gcpmod.CHECK, helmert=True))
                a.append(est.rmse(gcpmod.CHECK))
                o.append(old.rmse(gcpmod.CHECK))
                e = est.sigma_estimates[0]
                sig.append((e["sigma_xy_m"], e["sigma_z_m"]))

            def m(rows, k):
                return float(np.mean([r[k] for r in rows]))

            def txt(rows):
                return f"{m(rows, 'xyz'):.3f} ({m(rows, 'xy'):.3f}/{m(rows, 'z'):.3f})"

            worst = max(x["xyz"] / y["xyz"] for x, y in zip(a, h))
            worst_o = max(x["xyz"] / y["xyz"] for x, y in zip(o, h))
            sg = np.array(sig)
            print(f"  {label:<16} {noise:>6g} m {txt(h):>20} {txt(a):>22} {worst:>11.3f} {txt(o):>22} {worst_o:>6.2f}  "
                  f"{sg[:, 0].mean():.3f} / {sg[:, 1].mean():.3f} ({sg.min():.3f}-{sg.max():.3f})")


def copr(n_sets):
    ws = ensure_aligned("copr")
    rec = load_model(ws)
    names = sorted({im.name for im in rec.images.values()})
    base = gcpmod.read_gcps(os.path.join(DATA, "copr", "gcp_list.txt"), image_names=names)
    targets = [p.name for p in base.points if len(p.images()) >= 2]  # gcp00 has one observation
    sets = [("gcp03", "gcp06", "gcp09")]  # benchmarks/georef.py's check points first
    rng = np.random.default_rng(0)
    combos = list(itertools.combinations(targets, 3))
    for k in rng.permutation(len(combos)):
        if len(sets) >= n_sets:
            break
        if combos[k] not in sets:
            sets.append(combos[k])
    print(f"\nCOPR: {len(targets)} targets ({', '.join(targets)}), Z a placeholder (0): check RMSE in XY, metres")
    print(f"  {'check points':<24} {'Helmert':>8} {'adj. est.':>9} {'ratio':>6} {'adj. 0.02':>9} {'ratio':>6}  "
          "estimated sigma")
    rows = []
    for chk in sets:
        g = gcpmod.apply_check_points(dataclasses.replace(base, points=[dataclasses.replace(p) for p in base.points]),
                                      list(chk))
        t0 = time.time()
        est = georeference(rec, g)
        secs = time.time() - t0
        old = georeference(rec, stated(g))
        h, a, o = est.rmse(gcpmod.CHECK, helmert=True), est.rmse(gcpmod.CHECK), old.rmse(gcpmod.CHECK)
        rows.append((h["xy"], a["xy"], o["xy"]))
        print(f"  {','.join(chk):<24} {_xy(h):>8} {_xy(a):>9} {a['xy'] / h['xy']:6.3f} {_xy(o):>9} "
              f"{o['xy'] / h['xy']:6.3f}  {_est(est)} [{secs:.1f} s]")
        outl = [o_.name for o_ in est.outliers if o_.kind == "control point"]
        if outl:
            print(f"      outliers (estimated sigma): {', '.join(outl)}")
    r = np.array(rows)
    print(f"  mean over {len(r)} sets: Helmert {r[:, 0].mean():.3f}, adjusted with the estimate {r[:, 1].mean():.3f} "
          f"(ratio of means {r[:, 1].mean() / r[:, 0].mean():.3f}, worst set {np.max(r[:, 1] / r[:, 0]):.3f}), "
          f"adjusted at the stated 0.02 m {r[:, 2].mean():.3f} (worst {np.max(r[:, 2] / r[:, 0]):.3f})")


def _exif_positions(ws, crs):
    from core.georef.control_input import exif_positions

    return exif_positions(Workspace.open(ws), crs)


def toledo():
    ws = ensure_aligned("toledo")
    rec = load_model(ws)
    names = sorted({im.name for im in rec.images.values()})
    g = gcpmod.read_gcps(os.path.join(DATA, "toledo", "gcp_list.txt"), image_names=names)
    # the named targets (an unnamed group of lines in the file, gcp_2, is an example of bad lines: 1.3 km off)
    g.points = [p for p in g.points if p.name.startswith("HV")]
    for p in g.points:
        p.role = gcpmod.CHECK
    crs = "EPSG:32617"
    cams = _exif_positions(ws, crs)
    ref = {}
    for line in open(os.path.join(DATA, "toledo", "cameras_32617.txt")):
        parts = line.split()
        if len(parts) == 3 and not line.startswith("EPSG"):
            ref[parts[2]] = np.array([float(parts[0]), float(parts[1])])
    print(f"\nToledo: {len(cams)} EXIF GPS positions (no sigma) as the datum, {len(g.points)} targets "
          f"({', '.join(p.name for p in g.points)}; Z a placeholder) as check points in XY, or with the positions as "
          "control; camera centres against cameras_32617.txt (XY)")
    ctl = dataclasses.replace(g, points=[dataclasses.replace(p, role=gcpmod.CONTROL) for p in g.points])
    for label, gcps, positions in (
            ("EXIF, sigma estimated", g, cams),
            ("EXIF, stated 3 / 5 m", g, [dataclasses.replace(c, sigma_given=True) for c in cams]),
            ("targets + EXIF, both estimated", ctl, cams),
            ("targets 0.02 + EXIF 3 / 5 m stated", stated(ctl), [dataclasses.replace(c, sigma_given=True)
                                                                for c in cams])):
        t0 = time.time()
        res = georeference(rec, gcps, positions, options=GeorefOptions(crs=crs))
        secs = time.time() - t0
        h, a = res.rmse(gcpmod.CHECK, helmert=True), res.rmse(gcpmod.CHECK)
        # camera centres: adjusted, and the Helmert step's (model_to_local applied to the aligned model)
        ims = {im.name: im for im in res.reconstruction.images.values()}
        ims0 = {im.name: im for im in rec.images.values()}
        d_adj, d_hel = [], []
        for n, xy in ref.items():
            if n in ims:
                d_adj.append(np.linalg.norm(res.to_world(ims[n].projection_center())[:2] - xy))
                d_hel.append(np.linalg.norm(res.to_world(res.model_to_local.apply(
                    np.asarray(ims0[n].projection_center())))[:2] - xy))
        print(f"  {label:<34} check XY: Helmert {_xy(h)} adjusted {_xy(a)} m (n={a['n']}) | camera centres vs "
              f"reference: Helmert median {np.median(d_hel):.2f} adjusted {np.median(d_adj):.2f} m (n={len(d_adj)}) "
              f"| {_est(res)} [{secs:.1f} s]")


def archive():
    import json
    import shutil

    from core.georef.options import GeorefOptions
    from core.georef.stage import georeference_workspace

    base = os.path.join(ROOT, "build", "bench-archive")
    found = sorted(d for d in os.listdir(base) if os.path.isdir(os.path.join(base, d, "ws", "sfm"))) \
        if os.path.isdir(base) else []
    if not found:
        print("\nArchive: no aligned block in build/bench-archive (run benchmarks/archive.py first)")
        return
    print("\nArchive (benchmarks/archive.py's aligned blocks): check RMSE XY / Z, metres")
    for d in found:
        src = os.path.join(base, d)
        for label, csv in (("3 m, no sigma", "control_for_georef.csv"), ("3 m, sigma 3 m", "control_sigma3.csv")):
            if not os.path.exists(os.path.join(src, csv)):
                continue
            ws = os.path.join(WORK, "archive", d)
            shutil.rmtree(ws, ignore_errors=True)
            shutil.copytree(os.path.join(src, "ws"), ws, ignore=shutil.ignore_patterns("georef", "*.lock"))
            try:
                t0 = time.time()
                georeference_workspace(ws, GeorefOptions(gcp_path=os.path.join(src, csv)))
                secs = time.time() - t0
            except Exception as e:  # noqa: BLE001 - a benchmark reports and goes on
                print(f"  {d:<16} {label:<15} failed: {e}")
                continue
            with open(os.path.join(ws, "georef", "residuals.json"), encoding="utf-8") as f:
                res = json.load(f)
            h, a = res["rmse"]["check_helmert_only"], res["rmse"]["check"]

            class _R:
                sigma_estimates = res.get("sigma_estimates") or []
            print(f"  {d:<16} {label:<15} Helmert {h['xy']:.2f} / {h['z']:.2f}  adjusted {a['xy']:.2f} / "
                  f"{a['z']:.2f} (3-D ratio {a['xyz'] / h['xyz']:.3f}, n={a['n']})  {_est(_R)} [{secs:.1f} s]")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", choices=["synthetic", "copr", "toledo", "archive"])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--copr-sets", type=int, default=6)
    a = ap.parse_args()
    if a.only in (None, "synthetic"):
        synthetic(a.seeds)
    if a.only in (None, "copr"):
        copr(a.copr_sets)
    if a.only in (None, "toledo"):
        toledo()
    if a.only in (None, "archive"):
        archive()


if __name__ == "__main__":
    main()
