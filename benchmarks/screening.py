"""Prepare-images benchmark: screening figures on the real sets, scan restitution on synthetic scans.

1. Screening: every image of a set (default: the 57 Toledo photos of ../shared/data) plus
   three copies of one photo blurred with a known Gaussian sigma and one over-exposed copy;
   prints seconds per image, the blurriest-first ranking, the blur scores of the copies
   against the originals, and what the default thresholds flag in each real set.
2. Scanned film: synthetic scans (tests/test_scans.py) at a realistic resolution
   (``--scan-res`` px/mm, default 20: about 3,000 x 2,500 px); prints detection and
   resampling seconds per scan and the fiducial errors against the exact truth.

    python benchmarks/screening.py [--images DIR] [--scans N] [--scan-res PX_PER_MM] [--workdir DIR]
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

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from core.prepare.screening import screen_folder  # noqa: E402

DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")


def screening(images, work):
    d = os.path.join(work, "screening")
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(images, d)
    names = sorted(n for n in os.listdir(d) if n.lower().endswith((".jpg", ".jpeg", ".tif", ".png")))
    src = names[len(names) // 2]
    img = cv2.imread(os.path.join(d, src))
    blurs = {f"zz_blur_sigma{s}.jpg": s for s in (0.8, 1.5, 3.0)}
    for n, s in blurs.items():
        cv2.imwrite(os.path.join(d, n), cv2.GaussianBlur(img, (0, 0), s), [cv2.IMWRITE_JPEG_QUALITY, 95])
    cv2.imwrite(os.path.join(d, "zz_overexposed.jpg"), cv2.convertScaleAbs(img, alpha=1.8, beta=60))
    t0 = time.time()
    q = screen_folder(d)
    dt = time.time() - t0
    print(f"screening: {len(q)} images in {dt:.2f} s ({1000 * dt / len(q):.0f} ms per image, "
          f"{img.shape[1]}x{img.shape[0]} px)")
    ranked = sorted(q, key=lambda x: x.blur_rank)
    for x in ranked[:6]:
        print(f"  {x.blur_rank:3d} {x.name:28s} blur {x.blur_score:8.1f} ({100 * x.blur_relative:5.1f} % of median) "
              f"exposure {x.exposure_score:.2f} {','.join(x.flags) or 'ok'}")
    orig = np.array([x.blur_score for x in q if x.name in names])
    print(f"  originals ({len(orig)}): min {orig.min():.1f}, median {np.median(orig):.1f}, max {orig.max():.1f}; "
          f"source of the copies {src}: {next(x.blur_score for x in q if x.name == src):.1f}")
    ok = [x.name for x in ranked[:3]] == sorted(blurs, key=lambda n: -blurs[n])
    print(f"  blurred copies rank lowest, strongest first: {'yes' if ok else 'NO'}; "
          f"originals flagged: {sum(1 for x in q if x.name in names and x.flags)}")


def real_sets():
    for name in ("toledo", "copr", "caliterra"):
        d = os.path.join(DATA, name, "images")
        if not os.path.isdir(d):
            continue
        q = screen_folder(d)
        b = np.array([x.blur_score for x in q])
        flagged = [(x.name, x.flags) for x in q if x.flags]
        print(f"{name}: {len(q)} images, blur median {np.median(b):.1f} (min {b.min():.1f}, max {b.max():.1f}); "
              f"flagged {len(flagged)}: {flagged[:6]}")


def scans(n, res, work):
    from core.prepare.options import ScanOptions
    from core.prepare.scans import prepare_scans
    from tests.conftest import SAMPLE, TOLEDO_STRIP
    from tests.test_scans import SCAN_SETUP, calibration_text, make_scan

    d = os.path.join(work, "scans")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "in"))
    truth, paths = {}, []
    for i in range(n):
        photo, r0, ang, off = SCAN_SETUP[i % len(SCAN_SETUP)]
        p = os.path.join(d, "in", f"frame_{i + 1:03d}.tif")
        truth[os.path.basename(p)], _ = make_scan(os.path.join(SAMPLE, "images", TOLEDO_STRIP[i % 5]), p, i + 1,
                                                  res * r0 / 7.5, ang, (off[0] * res / 7.5, off[1] * res / 7.5))
        paths.append(p)
    shape = cv2.imread(paths[0], cv2.IMREAD_UNCHANGED).shape
    for x in ("out", "masks"):
        os.makedirs(os.path.join(d, x))
    t0 = time.time()
    r = prepare_scans(paths, os.path.join(d, "out"), os.path.join(d, "masks"),
                      ScanOptions(fiducial_coordinates=calibration_text()))
    dt = time.time() - t0
    errs = [math.hypot(f.x - truth[s.name][f.slot][0], f.y - truth[s.name][f.slot][1]) for s in r.scans
            for f in s.fiducials]
    print(f"scans: {n} synthetic scans of about {shape[1]}x{shape[0]} px -> {r.width}x{r.height} px prepared, "
          f"{dt:.1f} s ({dt / n:.1f} s per scan: detection, resampling, masks)")
    print(f"  fiducial error against truth over {len(errs)} marks: mean {np.mean(errs):.3f} px, "
          f"max {np.max(errs):.3f} px; affine RMS per scan: "
          + ", ".join(f"{s.rms_px:.3f}" for s in r.scans))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--images", default=os.path.join(DATA, "toledo", "images"))
    ap.add_argument("--scans", type=int, default=3)
    ap.add_argument("--scan-res", type=float, default=20.0)
    ap.add_argument("--workdir")
    a = ap.parse_args()
    work = a.workdir or tempfile.mkdtemp(prefix="archaeoortho-bench-screening-")
    os.makedirs(work, exist_ok=True)
    if os.path.isdir(a.images):
        screening(a.images, work)
        real_sets()
    else:
        print(f"no images at {a.images}: screening skipped")
    if a.scans:
        scans(a.scans, a.scan_res, work)
    if not a.workdir:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
