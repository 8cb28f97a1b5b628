"""Find targets (issue 34): COPR's targets found with no clicks, against the hand file; the synthetic block.

COPR: the hand gcp_list.txt (27 observations of 10 targets) reduced to coordinates alone; the block aligned (or
--copr-workspace reused); Find targets timed (2 threads by default: the issue's 2 cores); each hand observation
looked up among the found ones (within 1.5 px, named otherwise, missing); the observations the hand file does not
have; then the block georeferenced twice, from the hand file and from the found file, with the same check points
(gcp03, gcp06, gcp09, as benchmarks/georef.py), the residuals side by side.
Synthetic: tests/targets_scene.py's block (checkerboard, circle, ArUco, cross; obliques, an occluded target, targets cut
by the border): recall, wrong names, error against the rendered truth per kind.

    python benchmarks/find_targets.py [--copr-workspace DIR] [--only copr|synthetic] [--threads N]
"""
import argparse
import json
import math
import os
import shutil
import sys
import time
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
OUT = os.path.join(ROOT, "build", "bench-find-targets")

from core.align.options import AlignOptions  # noqa: E402
from core.align.stage import align  # noqa: E402
from core.common.progress import PrintProgress  # noqa: E402
from core.georef import stage as georef_stage  # noqa: E402
from core.georef.options import GeorefOptions  # noqa: E402
from core.georef.targets.options import FindTargetsOptions  # noqa: E402
from core.georef.targets.stage import find_targets  # noqa: E402
from core.io import gcp as gcpmod  # noqa: E402
from core.project.workspace import Workspace  # noqa: E402

CHECK = ["gcp03", "gcp06", "gcp09"]


def ensure_aligned(images, ws):
    if os.path.exists(os.path.join(ws, "workspace.json")) and Workspace.open(ws).stage_done("align"):
        return
    t0 = time.time()
    r = align(images, ws, AlignOptions(), PrintProgress("  align "))
    print(f"aligned {r.registered}/{r.images_given} in {time.time() - t0:.0f} s, {r.mean_reprojection_error:.3f} px")


def coordinates_only(hand_path, out_path):
    """The hand file reduced to its coordinates: the CRS line, then 'x y z name' once per target."""
    with open(hand_path, encoding="utf-8") as fh:
        lines = [ln.rstrip("\n") for ln in fh if ln.strip()]
    seen = {}
    for ln in lines[1:]:
        t = ln.split()
        seen.setdefault(t[6], f"{t[0]} {t[1]} {t[2]} {t[6]}")
    with open(out_path, "w", encoding="utf-8") as out:
        out.write(lines[0].strip() + "\n" + "\n".join(seen.values()) + "\n")
    return out_path


def compare(hand, result):
    """Each hand observation: found within 1.5 px, named otherwise, or missing; returns the counts."""
    found = {(o.image, o.name): o for o in result.observations}
    rows, within, wrong = [], 0, []
    for p in hand.points:
        for ob in p.observations:
            o = found.get((ob.image, p.name))
            e = math.hypot(o.x - ob.x, o.y - ob.y) if o else None
            other = [f.name for f in result.observations if f.image == ob.image and f.name != p.name
                     and math.hypot(f.x - ob.x, f.y - ob.y) < 5.0]
            twin = [q.name for q in hand.points if q is not p
                    and any(o2.image == ob.image and math.hypot(o2.x - ob.x, o2.y - ob.y) < 1.0
                            for o2 in q.observations)]
            within += e is not None and e <= 1.5
            if other:
                wrong.append((ob.image, p.name, other, twin))
            rows.append(f"  {p.name} {ob.image}: " + (f"{e:.2f} px ({o.source}, residual {o.residual_px:.2f} px)"
                                                       if o else "not found")
                        + (f"; found there as {', '.join(other)}" if other else "")
                        + (f"; the hand file clicks the same pixel as {', '.join(twin)}" if twin else ""))
    print("\n".join(rows))
    n = hand.n_observations()
    print(f"COPR: {within} of {n} hand observations found within 1.5 px ({100.0 * within / n:.0f} %); "
          f"{len(wrong)} found under another name: {wrong or 'none'}")
    hand_keys = {(ob.image, p.name) for p in hand.points for ob in p.observations}
    extra = [o for o in result.observations if (o.image, o.name) not in hand_keys]
    res = [o.residual_px for o in extra if np.isfinite(o.residual_px)]
    print(f"      {len(extra)} observations the hand file does not have (residual of their target's triangulation: "
          f"median {np.median(res) if res else float('nan'):.2f} px, largest {max(res) if res else float('nan'):.2f}"
          " px)")
    return within, n, wrong


def georeference_both(ws, hand_path, found_path):
    rows = {}
    for label, path in (("hand", hand_path), ("found", found_path)):
        copy = os.path.join(OUT, f"copr-georef-{label}")
        shutil.rmtree(copy, ignore_errors=True)
        os.makedirs(copy)
        shutil.copytree(os.path.join(ws, "sfm"), os.path.join(copy, "sfm"))
        shutil.copy(os.path.join(ws, "workspace.json"), copy)
        r = georef_stage.georeference_workspace(copy, GeorefOptions(gcp_path=path, check_points=CHECK))
        with open(os.path.join(copy, "georef", "residuals.json"), encoding="utf-8") as fh:
            pts = {p["name"]: p for p in json.load(fh)["points"]}
        rows[label] = (r.figures, pts, r.outliers)
    print("\ngeoreference from the hand file | from the found file (check points " + ", ".join(CHECK) + "):")
    print(f"  {'point':>6} {'role':<8} {'hand dXY':>9} {'obs':>4} | {'found dXY':>9} {'obs':>4}")
    names = sorted(set(rows["hand"][1]) | set(rows["found"][1]))
    for n in names:
        cells = []
        for label in ("hand", "found"):
            p = rows[label][1].get(n)
            dxy = math.hypot(p["dx"], p["dy"]) if p and p.get("dx") is not None else None
            cells.append(f"{dxy:9.3f} {p['n_obs']:4d}" if dxy is not None else f"{'-':>9} {'-':>4}")
        role = (rows["hand"][1].get(n) or rows["found"][1].get(n))["role"]
        print(f"  {n:>6} {role:<8} {cells[0]} | {cells[1]}")
    for label in ("hand", "found"):
        f, _, outliers = rows[label]
        print(f"  {label:>5}: control RMSE XY {f['GCP_RMSE_XY']:.3f} m, check RMSE XY {f['CHECK_RMSE_XY']:.3f} m, "
              f"check RMSE Z {f['CHECK_RMSE_Z']:.3f} m; outliers: {'; '.join(outliers) or 'none'}")


def copr(ws, threads):
    images = os.path.join(DATA, "copr", "images")
    hand_path = os.path.join(DATA, "copr", "gcp_list.txt")
    os.makedirs(OUT, exist_ok=True)
    ensure_aligned(images, ws)
    coords = coordinates_only(hand_path, os.path.join(OUT, "copr_targets.txt"))
    found_path = os.path.join(OUT, "copr_found_gcp_list.txt")
    t0 = time.time()
    r = find_targets(ws, FindTargetsOptions(targets=coords, num_threads=threads, output=found_path))
    secs = time.time() - t0
    print(f"\nFind targets on COPR (auto: crosses, checkers, circles, ArUco 4x4): {secs:.1f} s on {threads} "
          f"thread(s); {r.candidates} candidate marks, {r.marks} tied across photos, {r.n_targets} of "
          f"{len(r.targets)} targets and {r.n_observations} observations found; tie tolerance "
          f"{r.tie_tolerance_px:.2f} px; constellation fit RMS {r.fit_rms:.2f} m (tolerance {r.fit_tolerance:.2f} m)")
    for line in r.reports:
        print("  report:", line)
    compare(gcpmod.read_gcps(hand_path), r)
    georeference_both(ws, hand_path, found_path)


def synthetic(threads):
    sys.path.insert(0, ROOT)
    from tests import targets_scene
    from tests.workspaces import synthetic_workspace

    root = os.path.join(OUT, "synthetic")
    shutil.rmtree(root, ignore_errors=True)
    scene = targets_scene.render(os.path.join(root, "photos"), crosses=True)
    rec = targets_scene.reconstruction(scene)
    fake = types.SimpleNamespace(camera=types.SimpleNamespace(width=targets_scene.W, height=targets_scene.H),
                                 names=[s[0] for s in scene.shots])
    ws = synthetic_workspace(os.path.join(root, "ws"), fake, rec, photos=scene.photos)
    csv = targets_scene.write_targets_csv(scene, os.path.join(root, "targets.csv"))
    t0 = time.time()
    r = find_targets(ws, FindTargetsOptions(targets=csv, num_threads=threads))
    secs = time.time() - t0
    visible = {(i, n) for i, v in scene.visible.items() for n in v}
    found = {(o.image, o.name): o for o in r.observations}
    err = {k: math.hypot(o.x - scene.truth[o.image][o.name][0], o.y - scene.truth[o.image][o.name][1])
           for k, o in found.items()}
    wrong = [k for k, e in err.items() if e > 1.5]
    edge = [k for k in scene.cut if -10 < scene.truth[k[0]][k[1]][0] < targets_scene.W + 10
            and -10 < scene.truth[k[0]][k[1]][1] < targets_scene.H + 10]
    print(f"\nsynthetic block ({len(scene.photos)} photos of {targets_scene.W} x {targets_scene.H}, "
          f"{len(scene.targets)} targets): {secs:.1f} s; recall {len(visible & set(found))} of {len(visible)} "
          f"whole targets; {len(wrong)} wrong; found of the {len(scene.occluded)} occluded and the {len(edge)} cut by "
          f"the border: {len(set(scene.occluded + scene.cut) & set(found))}; whole but under "
          f"{targets_scene.MIN_SIDE_PX:g} px (not asked for) found {len(set(scene.small) & set(found))}"
          f" of {len(scene.small)}")
    for kind in ("checkerboard", "circle", "aruco", "cross"):
        e = [err[k] for k in visible & set(found) if found[k].kind == kind]
        print(f"  {kind:>12}: {len(e)} observations, error RMS {math.sqrt(np.mean(np.square(e))):.3f} px, "
              f"largest {max(e):.3f} px")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--copr-workspace", default=os.path.join(OUT, "copr"))
    ap.add_argument("--only", choices=("copr", "synthetic"))
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    if a.only in (None, "synthetic"):
        synthetic(a.threads)
    if a.only in (None, "copr"):
        copr(a.copr_workspace, a.threads)


if __name__ == "__main__":
    main()
