"""make demo: run the pipeline, as far as it exists, on the bundled sample through qgis_process.

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
    res, secs = run_alg(a.qgis_process, env, "archaeoortho:alignimages", IMAGES=images, WORKSPACE=ws)
    n = len([f for f in os.listdir(images) if f.lower().endswith(".jpg")])
    print("\n=== ArchaeoOrtho demo: Toledo sample ===")
    print(f"images aligned:             {res['REGISTERED_IMAGES']} of {n}")
    print(f"mean reprojection error:    {res['MEAN_REPROJECTION_ERROR']:.3f} px")
    print(f"alignment time:             {secs:.1f} s")
    print(f"workspace:                  {res['WORKSPACE']}")
    print(f"sparse model (COLMAP):      {os.path.join(res['WORKSPACE'], 'sfm', 'model')}")
    print(f"camera centres (GeoPackage): {res['CAMERAS']}")
    print(f"total time:                 {time.time() - t_all:.1f} s")


if __name__ == "__main__":
    main()
