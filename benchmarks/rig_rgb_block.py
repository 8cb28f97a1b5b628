"""A synthetic rig block with its RGB camera (issue 37 item 1): tests/rig_scene.py's captures, each with four
fisheye band files and the rig's RGB frame, through Run pipeline on the band folder (the captures stacked, the RGB
frames beside them, all aligned as one block, one DSM, the RGB and the multi-band orthomosaics), checked against
the scene's truth.

    python benchmarks/rig_rgb_block.py [--strips 4 --per-strip 10] [--workdir DIR]

Prints: photos registered (captures and RGB frames), reprojection error, wall and CPU-s per stage, peak RSS (this
process and its children), and for each mosaic the median shift of its green against the truth
(rig_scene.shift_to_truth) and the bands' registration on Green (rig_scene.evaluate).
"""
import argparse
import json
import os
import resource
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)


def main():
    from core import pipeline
    from core.align.options import AlignOptions
    from tests import rig_scene as rs

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--strips", type=int, default=4)
    ap.add_argument("--per-strip", type=int, default=10)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-rig-rgb"))
    a = ap.parse_args()
    n = a.strips * a.per_strip
    work = os.path.join(a.workdir, f"rig{n}")
    bands = os.path.join(work, "bands")
    rig = rs.rig_block(n_strips=a.strips, per_strip=a.per_strip)
    t0 = time.time()
    if not os.path.isdir(bands) or len(os.listdir(bands)) != 5 * n:
        shutil.rmtree(work, ignore_errors=True)
        rs.render(rig, bands, supersample=1, rgb=True)
    print(f"{n} captures of 4 bands ({rig.width} x {rig.height} px) + RGB frames "
          f"({rs.rgb_camera(rig).width} x {rs.rgb_camera(rig).height} px); rendered in {time.time() - t0:.0f} s",
          flush=True)
    ws = os.path.join(work, "ws")
    shutil.rmtree(ws, ignore_errors=True)
    w0 = time.time()
    res = pipeline.run_pipeline(bands, ws, pipeline.PipelineOptions(
        align=AlignOptions(num_threads=2), make_report=False, make_dtm=False, capture_radiometry="irradiance"),
        pipeline.Control(camera_positions_path=os.path.join(work, "camera_positions.csv")))
    wall = time.time() - w0
    peak = max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
               resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024
    cpu = sum(res.cpu_seconds.values())
    print(f"registered {res.align.registered} of {len(res.captures.photos) + len(res.rgb_frames)} photos "
          f"({len(res.captures.photos)} stacked captures, {len(res.rgb_frames)} RGB frames) at {res.align.mean_reprojection_error:.3f} px; wall {wall:.0f} s, CPU-s {cpu:.0f} "
          f"({', '.join(f'{k} {v:.0f}' for k, v in res.cpu_seconds.items())}); peak RSS {peak:.0f} MiB")
    print("multi-band mosaic (Green) against the truth:", rs.shift_to_truth(rig, res.ortho.orthomosaic, 3))
    print("RGB mosaic (green) against the truth:", rs.shift_to_truth(rig, res.ortho_rgb.orthomosaic, 2))
    ev = rs.evaluate(rig, res.ortho.orthomosaic)
    print("bands on Green in the multi-band mosaic:", json.dumps(ev["registration_px"]))
    print("ring NDVI contrast:", json.dumps(ev["ndvi"]))


if __name__ == "__main__":
    main()
