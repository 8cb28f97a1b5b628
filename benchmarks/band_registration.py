"""Band registration of one multispectral capture (issue 37): each band's lens model, the rotation applied, the
registration residual against the reference band (model only, and after the refinement), a false-colour NIR-R-G
quicklook and before / after crops.

usage: python benchmarks/band_registration.py [CAPTURE_FOLDER] [--out DIR] [--capture N] [--crop X,Y,W,H]
                                            [--conventions]
       (CAPTURE_FOLDER: ../shared/data/sequoia_sample by default: one Parrot Sequoia capture, GRE / RED / REG / NIR
       16-bit TIFFs 1280 x 960 with Pix4D fisheye models and rig relatives)
       --crop: a region shown 4x before / after (default: the Sequoia sample's parking lot, whose white lines show
       the bands' colour fringes)
       --conventions: also the model-only residual under the conventions not taken (rotation transposed, no
       rotation, principal point measured from the bottom edge), the evidence for the one used.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from core.geometry.lens import FisheyeLens, PerspectiveLens  # noqa: E402
from core.io.multispectral import band_files, read_block  # noqa: E402
from core.prepare.bands import (  # noqa: E402
    RegistrationOptions,
    band_cameras,
    band_map,
    gradient_image,
    read_band,
    reference_frame,
    register_capture,
    residual_of,
    warp,
    window_shifts,
    write_registered,
)

DEFAULT_FOLDER = os.path.join(ROOT, "..", "shared", "data", "sequoia_sample")


def describe_lens(lens) -> str:
    if isinstance(lens, FisheyeLens):
        return (f"Pix4D fisheye: c = ({lens.cx:.2f}, {lens.cy:.2f}) px, affine C D E F = "
                f"{', '.join(f'{v:.3f}' for v in lens.affine)} px, polynomial {', '.join(f'{v:.6g}' for v in lens.polynomial)}"
                f" (focal at the centre {lens.focal_px:.2f} px)")
    if isinstance(lens, PerspectiveLens):
        return (f"Pix4D perspective: f = {lens.f:.2f} px, c = ({lens.cx:.2f}, {lens.cy:.2f}) px, R1 R2 R3 = "
                f"{lens.radial}, T1 T2 = {lens.tangential}")
    return repr(lens)


def stretch(a: np.ndarray) -> np.ndarray:
    """A band to 0..255 by its 2-98 percentiles (NaN black)."""
    lo, hi = np.nanpercentile(a, [2, 98])
    out = np.clip((a - lo) / max(hi - lo, 1e-6), 0, 1) * 255
    return np.where(np.isfinite(out), out, 0).astype(np.uint8)


def false_colour(bands: np.ndarray, names) -> np.ndarray:
    """NIR-R-G as R-G-B (BGR array for cv2.imwrite)."""
    keys = [n.lower().replace(" ", "") for n in names]
    pick = [next(i for i, k in enumerate(keys) if k.startswith(w)) for w in ("nir", "red", "green")]
    r, g, b = (stretch(bands[i]) for i in pick)
    return np.dstack([b, g, r])


def convention_check(capture, options) -> None:
    """The model-only residual under the conventions not taken (module docstring)."""
    cams, ref = band_cameras(capture, options.reference)
    images = {c.path: read_band(c.path) for c in cams}
    shape = images[ref.path].shape
    flip = lambda c: dataclasses.replace(c, lens=dataclasses.replace(c.lens, cy=shape[0] - 1 - c.lens.cy))  # noqa: E731
    variants = (("as used: R_ref^T R, R = Rx Ry Rz, principal point from the top-left", lambda c: c),
                ("rotation transposed", lambda c: dataclasses.replace(c, rotation=c.rotation.T)),
                ("no rotation", lambda c: dataclasses.replace(c, rotation=np.eye(3))),
                ("principal point y from the bottom edge", flip))
    print("\nconventions (model only, median / worst px):")
    for label, change in variants:
        vc = [change(c) for c in cams]
        vref = vc[cams.index(ref)]
        frame = reference_frame(vref)
        rg = gradient_image(warp(images[vref.path], band_map(vref, frame, shape)))
        parts = []
        for c in vc:
            if c is vref:
                continue
            r = residual_of(window_shifts(rg, gradient_image(warp(images[c.path], band_map(c, frame, shape))), options))
            parts.append(f"{c.name} {r.median:.2f} / {r.worst:.2f}")
        print(f"  {label:70s} {'; '.join(parts)}")


def crops(reg, out: str, size: int = 240) -> str:
    """Before (model only) / after (refined) false-colour crops of the frame's corners and centre, 2x enlarged."""
    import cv2

    h, w = reg.bands.shape[1:]
    spots = [(60, 60), (w - size - 60, 60), ((w - size) // 2, (h - size) // 2), (60, h - size - 60),
             (w - size - 60, h - size - 60)]
    rows = []
    for model, label in ((reg.model_bands, "model only"), (reg.bands, "refined")):
        fc = false_colour(model, reg.names)
        tiles = [cv2.resize(fc[y:y + size, x:x + size], None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
                 for x, y in spots]
        row = np.hstack([np.pad(t, ((4, 4), (4, 4), (0, 0)), constant_values=255) for t in tiles])
        cv2.putText(row, label, (12, 30), cv2.FONT_HERSHEY_SIMPLEX, 0.9, (255, 255, 255), 2)
        rows.append(row)
    path = os.path.join(out, "before_after_crops.png")
    cv2.imwrite(path, np.vstack(rows))
    return path


def zoom(reg, out: str, box, factor: int = 4) -> str:
    """One region, model only above refined below, enlarged ``factor`` times (nearest: pixels stay visible)."""
    import cv2

    x, y, w, h = box
    rows = [cv2.resize(false_colour(b, reg.names)[y:y + h, x:x + w], None, fx=factor, fy=factor,
                       interpolation=cv2.INTER_NEAREST) for b in (reg.model_bands, reg.bands)]
    path = os.path.join(out, "before_after_zoom.png")
    cv2.imwrite(path, np.vstack([rows[0], np.full((8, rows[0].shape[1], 3), 255, np.uint8), rows[1]]))
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", nargs="?", default=DEFAULT_FOLDER)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "band_registration"))
    ap.add_argument("--capture", type=int, default=0, help="which capture of the folder (0: the first)")
    ap.add_argument("--crop", default="700,120,200,150", help="X,Y,W,H of the 4x before / after region")
    ap.add_argument("--conventions", action="store_true")
    args = ap.parse_args(argv)
    import cv2

    block = read_block(band_files(args.folder))
    capture = block.captures[args.capture]
    options = RegistrationOptions()
    t0 = time.perf_counter()
    reg = register_capture(capture, options, keep_model=True)
    seconds = time.perf_counter() - t0
    print(f"capture {capture.capture_id}: bands {', '.join(reg.names)}; reference {reg.reference}; pinhole frame "
          f"f = {reg.frame.f:.2f} px, c = ({reg.frame.cx:.2f}, {reg.frame.cy:.2f}) px, "
          f"{reg.bands.shape[2]} x {reg.bands.shape[1]}; {seconds:.1f} s")
    for r in reg.results:
        cam = r.camera
        print(f"\n{cam.name} ({os.path.basename(cam.path)})\n  lens: {describe_lens(cam.lens)}")
        rot = ", ".join(f"{v:+.4f}" for v in cam.rotation_deg)
        print(f"  rig relatives {cam.relatives} deg -> rotation into the reference about x, y, z: {rot} deg")
        if r is reg.results[0]:
            print("  the reference band")
            continue
        print(f"  residual, model only: {r.model_residual}\n  residual, refined:    {r.refined_residual}")
        print(f"  refinement homography: {np.array2string(r.correction, precision=6, suppress_small=True)}")
    os.makedirs(args.out, exist_ok=True)
    quick = os.path.join(args.out, "quicklook_nir_r_g.png")
    cv2.imwrite(quick, false_colour(reg.bands, reg.names))
    raw = np.stack([read_band(c.camera.path) for c in reg.results])
    cv2.imwrite(os.path.join(args.out, "quicklook_unregistered_nir_r_g.png"), false_colour(raw, reg.names))
    crop = crops(reg, args.out)
    zoomed = zoom(reg, args.out, [int(v) for v in args.crop.split(",")])
    tif = write_registered(os.path.join(args.out, "registered_bands.tif"), reg)
    print(f"\nwritten to {args.out}: {os.path.basename(quick)}, quicklook_unregistered_nir_r_g.png, "
          f"{os.path.basename(crop)}, {os.path.basename(zoomed)}, {os.path.basename(tif)}")
    if args.conventions:
        convention_check(capture, options)
    return 0


if __name__ == "__main__":
    sys.exit(main())
