"""Alignment on real faint farmland (issue 46 item 2): ours vs pycolmap's default pipeline on ``seneca_south``.

Prints, for our Align images (default options: texture probe, escalation) and for pycolmap's own default pipeline
(``extract_features`` + ``match_exhaustive`` + ``incremental_mapping``, benchmarks/align.py) in the same run: the
photos registered in the largest block, the components (every model of three or more photos), the CPU seconds of
the child process (user + system, all threads: load-independent, unlike the wall) and the wall seconds; then the
ratio of the CPU seconds and, for our block, the RMS of the camera centres against EXIF GPS after a similarity fit
(metres: a block that registers every photo but drifts along the strip shows here).

    python benchmarks/seneca_align.py [--images DIR] [--workdir DIR] [--threads N] [--skip-pycolmap]

The figures and the per-pair diagnosis are in docs/notes_issue46_align.md.
"""
import argparse
import glob
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
import align as bench_align  # noqa: E402
from _util import LAST_RUN  # noqa: E402

DEFAULT_IMAGES = os.path.join(os.path.dirname(ROOT), "shared", "data", "seneca_south", "images")

PYCOLMAP_COMPONENTS = r"""
import json, sys, pycolmap
recs = pycolmap.Reconstruction
import os
d = sys.argv[1]
comps = []
for sub in sorted(os.listdir(d)):
    p = os.path.join(d, sub)
    if os.path.isdir(p):
        r = pycolmap.Reconstruction(p)
        comps.append(sorted(r.images[i].name for i in r.reg_image_ids()))
print("COMPONENTS", json.dumps(comps))
"""


def gps_rms(model_dir, images):
    """RMS (m) of the model's camera centres against EXIF GPS (local metres, altitude) after a 3D similarity fit."""
    import numpy as np
    import pycolmap

    from core.align.pairs import gps_to_local_xy
    from core.io.images import read_image_info

    rec = pycolmap.Reconstruction(model_dir)
    infos = {os.path.basename(p): read_image_info(p) for p in sorted(glob.glob(os.path.join(images, "*")))}
    located = sorted(n for n, im in infos.items() if im.gps)
    xy = dict(zip(located, gps_to_local_xy([infos[n].gps for n in located])))
    names = [rec.images[i].name for i in rec.reg_image_ids() if rec.images[i].name in xy]
    if len(names) < 3:
        return None
    a = np.array([rec.find_image_with_name(n).projection_center() for n in names], dtype=float)
    b = np.array([[*xy[n], infos[n].gps[2]] for n in names], dtype=float)
    a0, b0 = a - a.mean(0), b - b.mean(0)
    u, s, vt = np.linalg.svd(b0.T @ a0 / len(a))
    d = np.eye(3)
    d[2, 2] = np.sign(np.linalg.det(u @ vt))
    r = u @ d @ vt
    scale = np.trace(np.diag(s) @ d) / ((a0 ** 2).sum() / len(a))
    res = b0 - scale * (r @ a0.T).T
    return float(math.sqrt((res[:, :2] ** 2).sum(1).mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--images", default=DEFAULT_IMAGES)
    ap.add_argument("--workdir", default="/tmp/archaeoortho-seneca-align")
    ap.add_argument("--threads", type=int, default=-1)
    ap.add_argument("--skip-pycolmap", action="store_true")
    a = ap.parse_args()
    if not os.path.isdir(a.images):
        raise SystemExit(f"{a.images} not found (../shared/data/seneca_south/images)")
    os.makedirs(a.workdir, exist_ok=True)
    rows = []
    result, wall, _rss = bench_align.ours(a.images, a.workdir, a.threads)
    cpu = LAST_RUN["cpu"]
    model = os.path.join(a.workdir, "archaeoortho-ws", "sfm", "model")
    comps = 1 + len(result.get("others") or [])
    esc = result.get("escalation") or {}
    rows.append(("ours", result["registered"], result["images"], comps, cpu, wall, gps_rms(model, a.images),
                 f"first pass {result.get('first_pass')}, {len(esc.get('rounds', []))} escalation round(s)"))
    if not a.skip_pycolmap:
        presult, pwall, _prss = bench_align.pycolmap_defaults(a.images, a.workdir)
        pcpu = LAST_RUN["cpu"]
        sparse = os.path.join(a.workdir, "pycolmap-defaults", "sparse")
        import subprocess
        out = subprocess.run([sys.executable, "-c", PYCOLMAP_COMPONENTS, sparse], capture_output=True, text=True)
        pcomps = [json.loads(line[11:]) for line in out.stdout.splitlines() if line.startswith("COMPONENTS ")]
        pcomps = pcomps[0] if pcomps else []
        best = max(pcomps, key=len) if pcomps else []
        subs = sorted(os.listdir(sparse)) if os.path.isdir(sparse) else []
        bdir = next((os.path.join(sparse, s) for s, c in zip(subs, pcomps) if c == best), None)
        rows.append(("pycolmap defaults", presult["registered"], result["images"], len(pcomps), pcpu, pwall,
                     gps_rms(bdir, a.images) if bdir else None, "extract_features + match_exhaustive + "
                     "incremental_mapping, default options"))
    print(f"{'run':<18} {'registered':>10} {'components':>10} {'CPU s':>8} {'wall s':>8} {'GPS RMS m':>9}  notes")
    for name, reg, n, comps, cpu, wall, rms, notes in rows:
        rms_s = f"{rms:.1f}" if rms is not None else "-"
        print(f"{name:<18} {reg:>5}/{n:<4} {comps:>10} {cpu:>8.1f} {wall:>8.1f} {rms_s:>9}  {notes}")
    if len(rows) == 2:
        print(f"CPU ratio ours / pycolmap defaults: {rows[0][4] / max(rows[1][4], 1e-9):.2f} (goal <= 0.5)")


if __name__ == "__main__":
    main()
