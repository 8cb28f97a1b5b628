"""Georeferencing on real data: COPR (surveyed targets, check points) and Toledo (EXIF GPS).

COPR: align (or reuse --copr-workspace), then georeference with every target except the check
points gcp03, gcp06, gcp09 as control; print per-point residuals after the Helmert step and after
the GCP-constrained adjustment, the outliers found, and the figures.
Toledo: georeference with EXIF GPS only and compare the camera centres with cameras_32617.txt.

    python benchmarks/georef.py [--copr-workspace DIR] [--toledo-workspace DIR] [--only copr|toledo]
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")

from core.align.options import AlignOptions  # noqa: E402
from core.align.stage import align  # noqa: E402
from core.common.progress import PrintProgress  # noqa: E402
from core.georef import stage as georef_stage  # noqa: E402
from core.georef.options import GeorefOptions  # noqa: E402
from core.project.workspace import Workspace  # noqa: E402


def ensure_aligned(images, ws):
    try:
        if Workspace.open(ws).stage_done("align"):
            return
    except Exception:
        pass
    t0 = time.time()
    r = align(images, ws, AlignOptions(), PrintProgress("  align "))
    print(f"aligned {r.registered}/{r.images_given} in {time.time() - t0:.0f} s, {r.mean_reprojection_error:.3f} px")


def table(rows, title):
    print(f"\n{title}")
    print(f"  {'point':>8} {'role':<8} {'status':<16} {'dX':>8} {'dY':>8} {'dZ':>8} {'dXY':>8}  obs")
    for p in rows:
        if p["dx"] is None:
            print(f"  {p['name']:>8} {p['role']:<8} {p['status']:<16} not triangulated")
            continue
        print(f"  {p['name']:>8} {p['role']:<8} {p['status']:<16} {p['dx']:8.3f} {p['dy']:8.3f} {p['dz']:8.3f} "
              f"{np.hypot(p['dx'], p['dy']):8.3f}  {p['n_obs']}")


def copr_second_alignment(ws):
    """An independent alignment (SIMPLE_RADIAL camera, 2048 features, principal point fixed): if the
    block were bent by metres, the two blocks would disagree; the targets' misfits would change."""
    done = os.path.exists(os.path.join(ws, "workspace.json")) and Workspace.open(ws).stage_done("align")
    if not done:
        align(os.path.join(DATA, "copr", "images"), ws,
              AlignOptions(camera_model="SIMPLE_RADIAL", max_features=2048, refine_principal_point=False))
    print("\nsecond, independent alignment (SIMPLE_RADIAL, 2048 features):")
    consistency(ws)


def consistency(ws):
    """Every target (control and check) against the block: which agree with each other?"""
    import pycolmap

    from core.georef.outliers import control_consistency
    from core.georef.triangulate import triangulate_observations
    from core.io import gcp as gcpmod

    rec = pycolmap.Reconstruction()
    rec.read_binary(os.path.join(ws, "sfm", "model"))
    g = gcpmod.read_gcps(os.path.join(DATA, "copr", "gcp_list.txt"))
    m, w, n = [], [], []
    print("\ntargets triangulated in the unadjusted block (px: residual per observation):")
    for p in g.points:
        t = triangulate_observations(rec, p.observations)
        px = " ".join(f"{ob.image}:{v:.2f}" for ob, v in zip(p.observations, t.residuals_px))
        print(f"  {p.name}: {'not triangulated' if t.xyz is None else f'angle {t.angle_deg:4.1f} deg'}  {px}")
        if t.xyz is not None:
            m.append(t.xyz)
            w.append([p.x, p.y, p.z])
            n.append(p.name)
    c = control_consistency(np.array(m), np.array(w), n, 0.06, xy_only=True)
    print(f"largest set of targets that one similarity fits within 0.06 m (XY; Z is a placeholder): "
          f"{', '.join(c.consistent)} at {c.rms:.3f} m RMS")
    for name in n:
        print(f"  {name}: {c.residuals[name]:.3f} m from that fit" + ("" if name in c.consistent else "  <- suspect"))


def _tarp_side_px(img, x, y, r=50):
    """Side (px) of the black square of the cross target at (x, y): the convex hull of its four dark quadrants."""
    import cv2

    xi, yi = int(round(x)), int(round(y))
    x0, y0 = max(0, xi - r), max(0, yi - r)
    win = cv2.cvtColor(img[y0:yi + r, x0:xi + r], cv2.COLOR_BGR2GRAY)
    _, m = cv2.threshold(win, 0, 255, cv2.THRESH_BINARY_INV + cv2.THRESH_OTSU)
    m = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    n, lab, st, cen = cv2.connectedComponentsWithStats(m)
    c = np.array([x - x0, y - y0])
    quads = [i for i in range(1, n) if np.linalg.norm(cen[i] - c) < 30 and st[i, cv2.CC_STAT_AREA] > 20]
    quads = sorted(quads, key=lambda i: -st[i, cv2.CC_STAT_AREA])[:4]
    if len(quads) < 4:
        return None
    pts = np.vstack([np.argwhere(lab == i)[:, ::-1] for i in quads]).astype(np.float32)
    return float(np.sqrt(cv2.contourArea(cv2.convexHull(pts))))


def tarp_ruler(ws):
    """An independent test of the block, needing no coordinates: the COPR targets are identical tarps, so at each
    observation (depth in the model x tarp side in px / focal length) is the model's length of one tarp side
    there.  If the block were deformed by the metres the coordinates ask for, that length would vary by tens of
    per cent across the block; its spread is the block's local scale error."""
    import cv2
    import pycolmap

    from core.georef.triangulate import triangulate_observations
    from core.io import gcp as gcpmod

    rec = pycolmap.Reconstruction()
    rec.read_binary(os.path.join(ws, "sfm", "model"))
    images = {im.name: im for im in rec.images.values() if im.has_pose}
    g = gcpmod.read_gcps(os.path.join(DATA, "copr", "gcp_list.txt"))
    scales, xyz = [], {}
    for p in g.points:
        t = triangulate_observations(rec, p.observations)
        if t.xyz is None:
            continue
        xyz[p.name] = np.asarray(t.xyz)
        for ob, res in zip(p.observations, t.residuals_px):
            im = images.get(ob.image)
            if im is None or not np.isfinite(res):
                continue
            side = _tarp_side_px(cv2.imread(os.path.join(DATA, "copr", "images", ob.image)), ob.x, ob.y)
            if side:
                depth = (im.cam_from_world() * t.xyz)[2]
                scales.append((p.name, ob.image, depth * side / rec.cameras[im.camera_id].params[0]))
    k = np.array([s[2] for s in scales])
    med = float(np.median(k))
    print("\nthe tarps as a ruler (no coordinates used): model length of one tarp side at each observation, "
          "relative to the median")
    print("  " + ", ".join(f"{n}/{i[4:8]} {v / med:.3f}" for n, i, v in scales))
    print(f"  spread {100 * k.std() / med:.1f} % (std) over {len(k)} observations, largest "
          f"{100 * np.abs(k / med - 1).max():.1f} %: the block's local scale is uniform to a few per cent")
    # what the coordinates say for two targets in the same photos, against what the photos say
    w = {p.name: np.array([p.x, p.y]) for p in g.points}
    for a, b, img in (("gcp03", "gcp04", "46, 52"), ("gcp07", "gcp08", "82")):
        if a in xyz and b in xyz:
            tarps = np.linalg.norm(xyz[a] - xyz[b]) / med
            print(f"  {a}-{b} (both in IMG_{img}): {tarps:.2f} tarp sides apart in the photos; the coordinates "
                  f"say {np.linalg.norm(w[a] - w[b]):.2f} m, i.e. a tarp of "
                  f"{100 * np.linalg.norm(w[a] - w[b]) / tarps:.1f} cm")
    print("  one tarp cannot have two sizes: coordinates that imply different sizes for the same tarps disagree "
          "with the photos, not with a deformed block")


def copr(ws, variants=True):
    ensure_aligned(os.path.join(DATA, "copr", "images"), ws)
    consistency(ws)
    tarp_ruler(ws)
    if variants:
        for refine in ("all", True):
            r = georef_stage.georeference_workspace(ws, GeorefOptions(
                gcp_path=os.path.join(DATA, "copr", "gcp_list.txt"), check_points=["gcp03", "gcp06", "gcp09"],
                refine_intrinsics=refine))
            f = r.figures
            print(f"variant REFINE_INTRINSICS={refine}: control RMSE XY {f['GCP_RMSE_XY']:.3f} m, check RMSE XY "
                  f"{f['CHECK_RMSE_XY']:.3f} m, tie points {f['MEAN_REPROJECTION_ERROR']:.3f} px")
    t0 = time.time()
    r = georef_stage.georeference_workspace(ws, GeorefOptions(gcp_path=os.path.join(DATA, "copr", "gcp_list.txt"),
                                                          check_points=["gcp03", "gcp06", "gcp09"]),
                                        progress=PrintProgress("  "))
    secs = time.time() - t0
    res = json.load(open(os.path.join(ws, "georef", "residuals.json")))
    table(res["helmert_points"], "after the Helmert (7-parameter) step only:")
    table(res["points"], "after the GCP-constrained bundle adjustment:")
    print("\noutliers:", *(f"\n  {o}" for o in r.outliers) or [" none"])
    print("warnings:", *(f"\n  {w}" for w in r.warnings) or [" none"])
    f = r.figures
    print(f"\nCOPR  control RMSE XY {f['GCP_RMSE_XY']:.3f} m | check RMSE XY {f['CHECK_RMSE_XY']:.3f} m "
          f"(Helmert only: {f['HELMERT_CHECK_RMSE_XY']:.3f} m) | check RMSE Z {f['CHECK_RMSE_Z']:.3f} m "
          f"| NSSDA H {f['NSSDA_H']:.3f} m | tie points {f['MEAN_REPROJECTION_ERROR']:.3f} px | {secs:.1f} s")
    print("      (Z of every COPR target is a placeholder 0: Z residuals measure the block's height"
          " datum and tilt against a flat 0, not accuracy)")


def toledo(ws):
    ensure_aligned(os.path.join(DATA, "toledo", "images"), ws)
    t0 = time.time()
    r = georef_stage.georeference_workspace(ws, GeorefOptions(use_exif_gps=True, crs="EPSG:32617"),
                                        progress=PrintProgress("  "))
    secs = time.time() - t0
    ref = {}
    for line in open(os.path.join(DATA, "toledo", "cameras_32617.txt")):
        parts = line.split()
        if len(parts) == 3 and not line.startswith("EPSG"):
            ref[parts[2]] = (float(parts[0]), float(parts[1]))
    from osgeo import ogr

    ds = ogr.Open(r.cameras_path)
    lyr = ds.GetLayer(0)
    d = []
    for feat in lyr:
        g = feat.GetGeometryRef()
        name = feat.GetField("image")
        if name in ref:
            d.append((g.GetX() - ref[name][0], g.GetY() - ref[name][1]))
    d = np.array(d)
    dist = np.hypot(d[:, 0], d[:, 1])
    print(f"\nToledo  CAMERA_RMSE_XYZ {r.figures['CAMERA_RMSE_XYZ']:.3f} m (against EXIF GPS) | "
          f"cameras vs cameras_32617.txt: n={len(d)}, mean {dist.mean():.2f} m, max {dist.max():.2f} m, "
          f"RMSE {np.sqrt((dist ** 2).mean()):.2f} m | {secs:.1f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--copr-workspace", default=os.path.join(ROOT, "build", "bench-georef", "copr"))
    ap.add_argument("--toledo-workspace", default=os.path.join(ROOT, "build", "bench-georef", "toledo"))
    ap.add_argument("--only", choices=["copr", "toledo"])
    ap.add_argument("--second-alignment", action="store_true",
                    help="also align COPR a second way and compare the targets' misfits")
    a = ap.parse_args()
    if a.only != "toledo":
        copr(a.copr_workspace)
        if a.second_alignment:
            copr_second_alignment(a.copr_workspace + "-simple-radial")
    if a.only != "copr":
        toledo(a.toledo_workspace)


if __name__ == "__main__":
    main()
