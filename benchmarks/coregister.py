"""DEM co-registration benchmark (core/georef/coregister.py, issue 32 item 4): size, and xdem side by side.

1. ``--size N`` (default 4000): a synthetic N x N DSM at 5 m (tests/test_coregister.py's rugged terrain, shifted,
   tilted, with a forest, buildings and noise) against a 25 m reference DEM, both written as GeoTIFFs; then
   ``coregister_rasters`` (warps the DSM from the file; also from a copy in EPSG:25833, reprojected) and
   ``coregister_dems`` (the DSM read whole as float32 first, as a caller holding it would, then 25 pseudo control
   points from it), each in a child process: seconds, peak resident memory (the child's ru_maxrss above its RSS
   after the imports; NumPy's part by tracemalloc) and the errors against the truth.
2. ``--xdem``: the same synthetic pairs as the tests (6 km at 5 m against 25 m), ours against xdem's NuthKaab
   (and Deramp(poly_order=1) after or before it where the pair is tilted) on the DSM averaged onto the reference
   grid (xdem compares on one grid).  xdem is not in requirements-dev.txt: xdem 0.2.3 brings geoutils, rasterio,
   pyproj, geopandas, pandas and xarray (rasterio and pyproj as wheels with their own GDAL and PROJ beside the
   system's), and rasterio 1.4.4 fails with the affine 3.0.1 that pip picks ("TransformError: Invalid inputs";
   affine<3 works); QGIS's Python on Windows and macOS has none of them.  Run this part from a throw-away venv:

       /usr/bin/python3 -m venv --system-site-packages /tmp/xdemvenv
       /tmp/xdemvenv/bin/pip install -c build/constraints.txt xdem "affine<3" pytest
       /tmp/xdemvenv/bin/python benchmarks/coregister.py --xdem

usage: python benchmarks/coregister.py [--size N] [--xdem]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tests.test_coregister import (  # noqa: E402
    BLOCK,
    FINE,
    REF_CELL,
    X0,
    Y0,
    Terrain,
    block_dsm,
    correction,
    reference,
    write,
)

TRUTH = {"shift": (37.0, -21.0), "dz": 3.2, "tilt": (8e-4, -5e-4)}


def _rss_mib() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return math.nan


def _errors(res, shift, dz, tilt, xs, ys):
    err = res.correction(xs, ys) - correction(xs, ys, dz, tilt)
    return {"shift_error_m": round(math.hypot(res.shift[0] - shift[0], res.shift[1] - shift[1]), 3),
            "height_error_max_m": round(float(np.max(np.abs(err))), 3),
            "nmad_before": round(res.nmad_before, 3), "nmad_after": round(res.nmad_after, 3),
            "iterations": res.iterations, "converged": res.converged}


def child(mode: str, dsm_path: str, ref_path: str, size: int) -> None:
    import tracemalloc

    from core.georef.coregister import (
        HeightGrid,
        control_points_from_coregistration,
        coregister_dems,
        coregister_rasters,
    )

    base = _rss_mib()
    extra = {}
    tracemalloc.start()
    t = time.perf_counter()
    if mode == "rasters":
        res = coregister_rasters(dsm_path, ref_path)
    elif mode == "reprojected":  # the DSM in EPSG:25833, the reference in EPSG:32633: warped across CRSs
        from osgeo import gdal

        gdal.UseExceptions()
        other = dsm_path.replace("dsm.tif", "dsm-25833.tif")
        gdal.Translate(other, dsm_path, outputSRS="EPSG:25833")
        t = time.perf_counter()
        res = coregister_rasters(other, ref_path)
    else:
        from osgeo import gdal

        gdal.UseExceptions()
        ds, rds = gdal.Open(dsm_path), gdal.Open(ref_path)
        dsm = ds.GetRasterBand(1).ReadAsArray()
        ref = rds.GetRasterBand(1).ReadAsArray()
        res = coregister_dems(HeightGrid(dsm, ds.GetGeoTransform(), -9999.0), HeightGrid(ref, rds.GetGeoTransform()))
        t_pc = time.perf_counter()
        pc = control_points_from_coregistration(res, HeightGrid(ref, rds.GetGeoTransform()),
                                                dem=HeightGrid(dsm, ds.GetGeoTransform()), n=25)
        extra = {"control_points": len(pc), "control_points_seconds": round(time.perf_counter() - t_pc, 2)}
    seconds = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    numpy_peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    bx, by = X0 + 1000.0, Y0 + 1000.0
    side = size * FINE
    xs = np.array([bx, bx + side, bx, bx + side, bx + side / 2])
    ys = np.array([by, by, by + side, by + side, by + side / 2])
    out = {"mode": mode, "seconds": round(seconds, 2), "peak_mib_above_imports": round(peak - base, 1),
           "python_numpy_peak_mib": round(numpy_peak, 1),
           "compared_cells": res.n_compared, **_errors(res, TRUTH["shift"], TRUTH["dz"], TRUTH["tilt"], xs, ys),
           **extra}
    print(json.dumps(out))


def size_run(size: int) -> None:
    terrain = Terrain(1, 40, 400.0, 150.0, 1500.0)
    side = size * FINE
    extent = side + 2000.0
    n_ref = int(math.ceil(extent / REF_CELL))
    k = int(REF_CELL / FINE)
    # the reference: the terrain at 5 m averaged over 25 m, row blocks (bounded memory)
    ref = np.empty((n_ref, n_ref))
    xs = X0 + (np.arange(n_ref * k) + 0.5) * FINE
    for r in range(n_ref):
        ys = Y0 + extent - (r * k + np.arange(k) + 0.5) * FINE
        ref[r] = terrain.grid(xs, ys).reshape(k, n_ref, k).mean(axis=(0, 2))
    ref_gt = (X0, REF_CELL, 0.0, Y0 + extent, 0.0, -REF_CELL)
    bx, by = X0 + 1000.0, Y0 + 1000.0
    dxs = bx + (np.arange(size) + 0.5) * FINE + TRUTH["shift"][0]
    dsm = np.empty((size, size), np.float32)
    rng = np.random.default_rng(5)
    for r0 in range(0, size, 500):
        dys = by + side - (np.arange(r0, min(size, r0 + 500)) + 0.5) * FINE + TRUTH["shift"][1]
        z = terrain.grid(dxs, dys) - correction(dxs[None, :], dys[:, None], TRUTH["dz"], TRUTH["tilt"])
        dsm[r0:r0 + len(dys)] = z + rng.normal(0, 0.5, z.shape)
    dsm[size // 6: size // 3, size // 4: size // 2] += 18.0  # a forest
    for _ in range(size // 10):
        r, c = rng.integers(0, size - 20, 2)
        dsm[r:r + 6, c:c + 8] += rng.uniform(6, 15)
    gt = (bx, FINE, 0.0, by + side, 0.0, -FINE)
    with tempfile.TemporaryDirectory() as tmp:
        ref_path = write(os.path.join(tmp, "ref.tif"), ref, ref_gt, "EPSG:32633")
        dsm_path = write(os.path.join(tmp, "dsm.tif"), dsm, gt, "EPSG:32633")
        del dsm, ref
        print(f"{size} x {size} DSM at {FINE:g} m ({side / 1000:g} km) against a {n_ref} x {n_ref} reference at "
              f"{REF_CELL:g} m")
        for mode in ("rasters", "reprojected", "arrays"):
            out = subprocess.run([sys.executable, __file__, "--child", mode, dsm_path, ref_path, str(size)],
                                 capture_output=True, text=True, check=True)
            print(out.stdout.strip())


def xdem_run() -> None:
    import rasterio
    import xdem
    from affine import Affine
    from osgeo import gdal

    from core.georef.coregister import CoregOptions, HeightGrid, coregister_dems, nmad
    from core.io.raster import bilinear

    gdal.UseExceptions()
    terrain = Terrain(1, 40, 400.0, 150.0, 1500.0)
    ref, ref_gt = reference(terrain, noise=0.2)
    bx, by, size = BLOCK
    xs = np.array([bx, bx + size, bx, bx + size, bx + size / 2])
    ys = np.array([by, by, by + size, by + size, by + size / 2])
    print(f"xdem {xdem.__version__}; 6 km DSM at 5 m against the 25 m reference; errors against the truth")
    for name, (shift, dz, tilt) in {"shift only": ((37.0, -21.0), 3.2, (0.0, 0.0)),
                                    "shift + tilt": ((37.0, -21.0), 3.2, (8e-4, -5e-4))}.items():
        dsm, gt = block_dsm(terrain, shift, dz, tilt)
        # the DSM averaged onto the reference grid (what both compare)
        mem = gdal.GetDriverByName("MEM").Create("", dsm.shape[1], dsm.shape[0], 1, gdal.GDT_Float32)
        mem.SetGeoTransform(gt)
        mem.GetRasterBand(1).SetNoDataValue(float("nan"))
        mem.GetRasterBand(1).WriteArray(dsm)
        on_ref = gdal.Warp("", mem, format="MEM", outputBounds=(X0, Y0, X0 + ref.shape[1] * REF_CELL,
                           Y0 + ref.shape[0] * REF_CELL), width=ref.shape[1], height=ref.shape[0],
                           resampleAlg="average", dstNodata=float("nan")).ReadAsArray()
        t = time.perf_counter()
        ours = coregister_dems(HeightGrid(dsm, gt), HeightGrid(ref, ref_gt), options=CoregOptions(tilt=any(tilt)))
        t_ours = time.perf_counter() - t
        e = _errors(ours, shift, dz, tilt, xs, ys)
        print(f"  {name}: ours      shift ({ours.shift[0]:.2f}, {ours.shift[1]:.2f}) error {e['shift_error_m']} m, "
              f"height error max {e['height_error_max_m']} m, NMAD after {e['nmad_after']} m, {t_ours:.2f} s")
        pipelines = {"NuthKaab": xdem.coreg.NuthKaab()}
        if any(tilt):
            pipelines["NuthKaab + Deramp(1)"] = xdem.coreg.NuthKaab() + xdem.coreg.Deramp(poly_order=1)
            pipelines["Deramp(1) + NuthKaab"] = xdem.coreg.Deramp(poly_order=1) + xdem.coreg.NuthKaab()
        for label, coreg in pipelines.items():
            t = time.perf_counter()
            coreg.fit(ref.astype(np.float32), on_ref, transform=Affine.from_gdal(*ref_gt),
                      crs=rasterio.crs.CRS.from_epsg(32633), random_state=42)
            t_x = time.perf_counter() - t
            steps = coreg.pipeline if hasattr(coreg, "pipeline") else [coreg]
            nk = next(c for c in steps if isinstance(c, xdem.coreg.NuthKaab))
            aff = nk.meta["outputs"]["affine"]
            sx, sy, sz = aff["shift_x"], aff["shift_y"], aff["shift_z"]
            # after xdem's shift (the DSM resampled at the shifted cells, bilinear, plus its dz): what is left
            gy, gx = np.mgrid[0:ref.shape[0], 0:ref.shape[1]]
            moved = bilinear(on_ref.astype(float), gx - sx / REF_CELL, gy + sy / REF_CELL)
            resid = ref - (moved + sz)
            print(f"  {name}: xdem {label:<20} shift ({sx:.2f}, {sy:.2f}, dz {sz:.2f}) error "
                  f"{math.hypot(sx - shift[0], sy - shift[1]):.3f} m (sign as ours: {sx * shift[0] > 0}), "
                  f"NMAD after its shift {nmad(resid):.3f} m, {t_x:.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=int, default=4000)
    ap.add_argument("--xdem", action="store_true")
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args.child[0], args.child[1], args.child[2], int(args.child[3]))
    elif args.xdem:
        xdem_run()
    else:
        size_run(args.size)


if __name__ == "__main__":
    main()
