"""make demo: run the whole pipeline on the bundled sample through qgis_process (archaeoortho:runpipeline).

Prints where the products are and the key figures.  Usage:
    python sample/demo.py [--qgis-process PATH] [--build DIR] [--workspace DIR]
"""
import argparse
import json
import os
import subprocess
import sys
import sysconfig
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def qgis_env(build):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([sysconfig.get_paths()["purelib"], env.get("PYTHONPATH", "")])
    env["QGIS_PLUGINPATH"] = os.path.join(build, "qgis-plugins")
    env["QGIS_CUSTOM_CONFIG_PATH"] = os.path.join(build, "qgis-profile")
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    return env


def run_alg(exe, env, alg, **params):
    cmd = [exe, "--json", "run", alg, "--"] + [f"{k}={v}" for k, v in params.items()]
    print(f"\n$ qgis_process run {alg} " + " ".join(f"{k}={v}" for k, v in params.items()), flush=True)
    t0 = time.time()
    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.stderr.write(out.stdout[-4000:] + out.stderr[-4000:])
        raise SystemExit(f"{alg} failed (exit {out.returncode})")
    doc = json.loads(out.stdout)
    for line in doc.get("log", {}).get("info", []):
        print("   " + line)
    return doc["results"], time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--qgis-process", default="/usr/bin/qgis_process.bin")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--workspace", default=None)
    a = ap.parse_args()
    ws = a.workspace or os.path.join(a.build, "demo-workspace")
    env = qgis_env(a.build)
    subprocess.run([a.qgis_process, "plugins", "enable", "archaeoortho"], env=env, capture_output=True)
    images = os.path.join(HERE, "toledo", "images")
    t_all = time.time()
    # the whole chain in one call (the same functions as the single stages): align, georeference with the
    # photos' EXIF GPS, DSM, orthomosaic, accuracy report
    res, secs = run_alg(a.qgis_process, env, "archaeoortho:runpipeline", IMAGES=images, WORKSPACE=ws,
                        USE_EXIF_GPS="true")
    n = len([f for f in os.listdir(images) if f.lower().endswith(".jpg")])

    def fmt(v, unit=""):
        return "n/a" if v is None else f"{v:.3f}{unit}"

    print("\n=== ArchaeoOrtho demo: Toledo sample (18 photos, georeferenced by their EXIF GPS) ===")
    print(f"images aligned:              {res['REGISTERED_IMAGES']} of {n}")
    print(f"mean reprojection error:     {fmt(res['MEAN_REPROJECTION_ERROR'], ' px')}")
    print(f"camera position RMSE XYZ:    {fmt(res['CAMERA_RMSE_XYZ'], ' m')} (against the EXIF GPS)")
    print(f"DSM valid fraction:          {fmt(res['DSM_VALID_FRACTION'])}")
    print(f"orthomosaic valid fraction:  {fmt(res['ORTHO_VALID_FRACTION'])}")
    print(f"workspace:                   {res['WORKSPACE']}")
    print(f"sparse model (COLMAP):       {os.path.join(res['WORKSPACE'], 'georef', 'model')}")
    print(f"DSM (COG):                   {res['DSM']}")
    print(f"orthomosaic (COG):           {res['ORTHOMOSAIC']}")
    print(f"accuracy report (HTML):      {res['REPORT']}")
    print(f"total time:                  {time.time() - t_all:.1f} s (pipeline {secs:.1f} s)")


if __name__ == "__main__":
    main()
