"""Automatic control against a reference orthophoto + DSM on Toledo (issue 16 item 1 step 4).

Toledo's photos come from two cameras (DJI FC350: 47 photos, FC300X: 10).  The reference is made from the FC350
photos: aligned, georeferenced by their EXIF GPS, DSM and orthomosaic (``core.pipeline.run_pipeline``, no report;
cached in the work folder: ``--fresh`` remakes it).  The FC300X photos are copied with their GPS removed from the
files, aligned on their own, and georeferenced by ``autocontrol_workspace`` with no prior at all (rotation and
scale searched); their recovered camera centres are compared with ``toledo/cameras_32617.txt`` (X, Y).  Prints
the figures (matches, automatic GCPs, camera errors, the autocontrol step's time).

    python benchmarks/autocontrol.py [--workdir DIR] [--prior none|gps] [--fresh]

Measured (2 cores shared, nice 19; reference 276 s once, cached): the FC300X block with no prior, 618 matches,
306 fit one similarity, 218 their tiles, 43 automatic GCPs kept; camera centres vs cameras_32617.txt: median
0.89 m, largest 1.95 m (the FC350 reference's own cameras, georeferenced by EXIF GPS: median 0.69 m against the
same file); autocontrol 53-81 s (rotation search 24 s, adjustment with focal + distortion refined 33 s).  Without
refining the FC300X's calibration (10 photos self-calibrated alone) the median was 1.75 m.
"""
import argparse
import json
import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

DATA = os.path.join(os.path.dirname(ROOT), "shared", "data", "toledo")
REFERENCE_CAMERA, NEW_CAMERA = "FC350", "FC300X"


def split_by_camera(images, workdir):
    """{camera model: folder}: the reference camera's photos linked, the other camera's copied without GPS."""
    from PIL import Image

    out = {}
    for name in sorted(os.listdir(images)):
        path = os.path.join(images, name)
        with Image.open(path) as im:
            exif = im.getexif()
            model = str(exif.get(272, "")).strip("\x00").strip()
            folder = os.path.join(workdir, model, "images")
            os.makedirs(folder, exist_ok=True)
            out[model] = folder
            target = os.path.join(folder, name)
            if os.path.exists(target):
                continue
            if model == REFERENCE_CAMERA:
                os.symlink(path, target)
            else:  # no GPS in the file: the block has no prior at all
                exif.pop(0x8825, None)
                im.save(target, quality="keep", exif=exif.tobytes())
    return out


def reference(images, workdir, fresh):
    from core import pipeline
    from core.common.progress import PrintProgress
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    ws = os.path.join(workdir, "reference-ws")
    done = os.path.join(workdir, "reference.json")
    if fresh or not os.path.isfile(done):
        if fresh:
            shutil.rmtree(ws, ignore_errors=True)
        t = time.time()  # a workspace left by an interrupted run resumes (features and matches kept)
        options = pipeline.PipelineOptions(make_report=False, make_dtm=False, dsm_quality="quarter")
        r = pipeline.run_pipeline(images, ws, options,
                                  pipeline.Control(use_exif_gps=True), progress=PrintProgress("  ref "))
        with open(done, "w") as f:
            json.dump({"seconds": time.time() - t, "registered": r.align.registered, "dsm": r.dsm.dsm_path,
                       "ortho": r.ortho.orthomosaic, "stages": r.seconds}, f)
    with open(done) as f:
        info = json.load(f)
    lay = Layout(Workspace.open(ws))
    return info, info["dsm"] or lay.dsm(), info["ortho"]


def true_centres():
    out = {}
    with open(os.path.join(DATA, "cameras_32617.txt")) as f:
        for line in f:
            p = line.split()
            if len(p) >= 3 and not line.startswith("EPSG"):
                out[p[2]] = (float(p[0]), float(p[1]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-autocontrol"))
    ap.add_argument("--prior", default="none", choices=("none", "gps"))
    ap.add_argument("--fresh", action="store_true")
    a = ap.parse_args()
    import numpy as np

    from core.align.stage import align
    from core.common.progress import PrintProgress
    from core.georef.autocontrol.stage import autocontrol_workspace
    from core.project.layout import Layout
    from core.project.workspace import Workspace

    os.makedirs(a.workdir, exist_ok=True)
    folders = split_by_camera(os.path.join(DATA, "images"), a.workdir)
    info, dsm, ortho = reference(folders[REFERENCE_CAMERA], a.workdir, a.fresh)
    print(f"reference ({REFERENCE_CAMERA}): {info['registered']} photos registered, {info['seconds']:.0f} s; "
          f"orthomosaic {ortho}, DSM {dsm}")
    ws = os.path.join(a.workdir, "new-ws")
    shutil.rmtree(ws, ignore_errors=True)
    t = time.time()
    al = align(folders[NEW_CAMERA], ws, progress=PrintProgress("  new "))
    print(f"{NEW_CAMERA}: {al.registered} of {al.images_given} photos aligned in {time.time() - t:.0f} s "
          "(no GPS in the files)")
    t = time.time()
    r = autocontrol_workspace(ws, ortho, dsm, prior=a.prior, progress=PrintProgress("  auto "))
    seconds = time.time() - t
    rec, tr = Layout(Workspace.open(ws)).load_georef_model()
    truth = true_centres()
    errs = []
    for im in rec.images.values():
        m = np.asarray(im.cam_from_world().matrix())
        c = -m[:, :3].T @ m[:, 3] + np.asarray(tr["offset"], dtype=float)
        if im.name in truth:
            errs.append(float(np.hypot(c[0] - truth[im.name][0], c[1] - truth[im.name][1])))
    f = r.georef.figures
    print(json.dumps({"prior": a.prior, "autocontrol_seconds": round(seconds, 1), "timings": r.timings,
                      "figures": r.figures, "gcp_rmse_xy": f["GCP_RMSE_XY"], "gcp_rmse_z": f["GCP_RMSE_Z"],
                      "camera_xy_error_median_m": float(np.median(errs)) if errs else None,
                      "camera_xy_error_max_m": float(np.max(errs)) if errs else None, "cameras": len(errs)},
                     indent=1))
    for m in r.messages:
        print("  ", m)


if __name__ == "__main__":
    main()
