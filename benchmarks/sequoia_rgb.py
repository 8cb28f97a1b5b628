"""The Sequoia sample's RGB frame undistorted (issue 37 Must show), with two models: the one its XMP carries (Pix4D
perspective: PrincipalPoint, PerspectiveFocalLength, PerspectiveDistortion; core.geometry.lens) and one fitted by
the alignment on another flight of the same camera (``../shared/data/garfield_rgb_small``, 28 photos at a third of
the size: Align images' self-calibrated OPENCV camera, its focal length held at the photos' own after it drifted;
scaled by 3).  Prints how far the two models' undistortions lie apart over the frame and writes a quicklook:
the frame as recorded, undistorted by its XMP model, undistorted by the fitted one (``build/sequoia_rgb/``).

    python benchmarks/sequoia_rgb.py [--workspace WS]   # WS: an aligned garfield_rgb_small workspace (else aligned)
"""
import argparse
import os
import sys
import time

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
FRAME = os.path.join(DATA, "sequoia_sample", "IMG_161122_163234_0000_RGB.JPG")


def fitted_camera(workspace):
    """(fx, fy, cx, cy, k1, k2, p1, p2) of the aligned garfield block, and its frame size."""
    import pycolmap

    rec = pycolmap.Reconstruction(os.path.join(workspace, "sfm", "model"))
    cam = next(iter(rec.cameras.values()))
    return [float(v) for v in cam.params], (cam.width, cam.height), rec.num_reg_images()


def opencv_project(params, rays):
    fx, fy, cx, cy, k1, k2, p1, p2 = params
    x, y = rays[..., 0] / rays[..., 2], rays[..., 1] / rays[..., 2]
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 * r2
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return np.stack([fx * xd + cx, fy * yd + cy], axis=-1)


def main():
    from core.geometry.lens import perspective_from_pix4d
    from core.io.multispectral import read_band_info

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workspace", default="")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "sequoia_rgb"))
    a = ap.parse_args()
    ws = a.workspace
    if not ws:
        from core.align.options import AlignOptions
        from core.align.stage import align

        ws = os.path.join(a.out, "garfield-ws")
        t0 = time.time()
        r = align(os.path.join(DATA, "garfield_rgb_small", "images"), ws, AlignOptions())
        print(f"garfield_rgb_small aligned: {r.registered}/{r.images_given} at {r.mean_reprojection_error:.3f} px, "
              f"{time.time() - t0:.0f} s")
    params, (w0, h0), registered = fitted_camera(ws)
    info = read_band_info(FRAME)
    lens = perspective_from_pix4d(info.lens.principal_point_mm, info.lens.focal_length, info.focal_plane_px_per_mm,
                                  info.lens.distortion)
    w, h = info.width, info.height
    s = w / w0
    scaled = [params[0] * s, params[1] * s, (params[2] + 0.5) * s - 0.5, (params[3] + 0.5) * s - 0.5] + params[4:]
    print(f"XMP model: f {lens.f:.1f} px, principal point {lens.cx:.1f}, {lens.cy:.1f}, radial {lens.radial}, "
          f"tangential {lens.tangential}")
    print(f"fitted on garfield_rgb_small ({registered} photos, {w0} x {h0}), scaled x{s:g}: f {scaled[0]:.1f} px, "
          f"principal point {scaled[2]:.1f}, {scaled[3]:.1f}, k1 {params[4]:.4f}, k2 {params[5]:.4f}, "
          f"p1 {params[6]:.5f}, p2 {params[7]:.5f}")
    # the undistorted frame: a pinhole of the XMP focal at the centre; each model maps it into the recorded frame
    f = lens.f
    jj, ii = np.meshgrid(np.arange(w, dtype=np.float64) + 0.5, np.arange(h, dtype=np.float64) + 0.5)
    rays = np.stack([(jj - w / 2) / f, (ii - h / 2) / f, np.ones_like(jj)], axis=-1)
    xmp = lens.project(rays) - 0.5
    fit = opencv_project(scaled, rays) - 0.5
    d = np.hypot(*(xmp - fit).transpose(2, 0, 1))
    corr_xmp = np.hypot(xmp[..., 0] - (jj - 0.5), xmp[..., 1] - (ii - 0.5))
    corr_fit = np.hypot(fit[..., 0] - (jj - 0.5), fit[..., 1] - (ii - 0.5))
    print(f"correction (undistorted -> recorded) at the corners: XMP {corr_xmp[[0, 0, -1, -1], [0, -1, 0, -1]].round(1)} px,"
          f" fitted {corr_fit[[0, 0, -1, -1], [0, -1, 0, -1]].round(1)} px")
    print(f"the two models apart: median {np.median(d):.1f} px, 95th percentile {np.percentile(d, 95):.1f} px, "
          f"max {d.max():.1f} px (inner half of the frame: median "
          f"{np.median(d[h // 4:3 * h // 4, w // 4:3 * w // 4]):.1f} px)")
    # the distortion's shape apart from focal length and principal point: the residual of the best affine map
    # between the two models' recorded positions (a sample of the frame)
    pick = (slice(None, None, 16), slice(None, None, 16))
    a_xy, b_xy = xmp[pick].reshape(-1, 2), fit[pick].reshape(-1, 2)
    design = np.hstack([a_xy, np.ones((len(a_xy), 1))])
    coef, *_ = np.linalg.lstsq(design, b_xy, rcond=None)
    shape = np.hypot(*(design @ coef - b_xy).T)
    print(f"their distortions' shape apart (after the best affine map: focal length and principal point aside): "
          f"median {np.median(shape):.1f} px, 95th percentile {np.percentile(shape, 95):.1f} px, max {shape.max():.1f} px")
    img = cv2.imread(FRAME)
    out_xmp = cv2.remap(img, xmp[..., 0].astype(np.float32), xmp[..., 1].astype(np.float32), cv2.INTER_LINEAR)
    out_fit = cv2.remap(img, fit[..., 0].astype(np.float32), fit[..., 1].astype(np.float32), cv2.INTER_LINEAR)
    os.makedirs(a.out, exist_ok=True)
    small = [cv2.resize(x, (w // 4, h // 4), interpolation=cv2.INTER_AREA) for x in (img, out_xmp, out_fit)]
    for x, label in zip(small, ("recorded", "undistorted: XMP model", "undistorted: fitted (garfield)")):
        cv2.putText(x, label, (20, 50), cv2.FONT_HERSHEY_SIMPLEX, 1.4, (0, 255, 255), 3)
    path = os.path.join(a.out, "quicklook.jpg")
    cv2.imwrite(path, np.hstack(small), [cv2.IMWRITE_JPEG_QUALITY, 85])
    cv2.imwrite(os.path.join(a.out, "undistorted_fitted.jpg"), out_fit, [cv2.IMWRITE_JPEG_QUALITY, 90])
    print(f"quicklook: {path}")


if __name__ == "__main__":
    main()
