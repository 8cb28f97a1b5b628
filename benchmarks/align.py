"""Alignment benchmark: ArchaeoOrtho vs the COLMAP command line on the same images.

Prints per-stage seconds and peak memory for our alignment, then the same work done by
the COLMAP CLI (Debian package ``colmap``): feature_extractor + matcher + mapper, and the
ratio.  "Same work" means the same images, the same camera model (OPENCV, one camera per
camera type), the same number of features and the same pairs: with GPS, COLMAP's
spatial_matcher with the same neighbour count; without, its exhaustive_matcher.
``--colmap-defaults`` runs COLMAP with its own defaults instead (exhaustive matching,
8192 features), the reference the issues quote.  ``--pycolmap-defaults`` also runs pycolmap's own
default pipeline (``extract_features`` + ``match_exhaustive`` + ``incremental_mapping``, default
options) on the same images, the second reference; ratios are printed against each reference run.

    python benchmarks/align.py [--images DIR] [--workdir DIR] [--skip-colmap] [--colmap-defaults]
                               [--pycolmap-defaults] [--mapper incremental|global] [--chain]
    python benchmarks/align.py --table [--sets small,toledo,...] [--only ours|pycolmap]

``--sets farmland`` (or ``farmland-0.4``) adds tests/lowtexture_scene.py's synthetic farmland (issue 33: 20
photos of 3600 x 2700, faint furrows at contrast 0.15), rendered once under ``<workdir>/table``.

``--table`` runs ours (default options: the texture probe's first pass, escalation where it fails) and pycolmap's default
pipeline on every shared set and the synthetic small frames, and prints one table: registered images, mean
reprojection error, wall seconds, what was escalated.  Each run's result is kept under
``<workdir>/table/<set>/`` and reused by the next ``--table`` (delete it to measure again); ``--only`` runs one
side.  ``ochota_kap`` is measured on half-size copies (2304 x 1728, EXIF kept) and, as ``ochota_kap_full``, on
its 16 MP frames.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from _util import LAST_RUN, run_measured  # noqa: E402

DEFAULT_IMAGES = os.path.join(os.path.dirname(ROOT), "shared", "data", "toledo", "images")


def ours(images, work, threads, mapper="incremental", extra=None):
    ws = os.path.join(work, "archaeoortho-ws")
    shutil.rmtree(ws, ignore_errors=True)
    code = ("import sys, json; sys.path.insert(0, %r); from core.align.stage import align, AlignOptions;"
            "r = align(%r, %r, AlignOptions(num_threads=%d, mapper=%r, **%r));"
            "print('RESULT', json.dumps({'registered': r.registered, 'images': r.images_given,"
            "'mre': r.mean_reprojection_error, 'timings': r.timings, 'pairs': r.num_pairs,"
            "'pairing': r.pairing_used, 'points': r.num_points3d, 'others': r.other_components,"
            "'escalation': r.escalation, 'first_pass': (r.first_pass or {}).get('level')}))") % (ROOT, images, ws, threads, mapper, dict(extra or {}))
    log = os.path.join(work, "archaeoortho.log")
    rc, wall, rss = run_measured([sys.executable, "-c", code], log_path=log)
    if rc != 0:
        raise SystemExit(f"our alignment failed, see {log}")
    result = [json.loads(line[7:]) for line in open(log) if line.startswith("RESULT ")][0]
    return result, wall, rss


PYCOLMAP_DEFAULTS = r"""
import json, os, sys, time
import pycolmap
images, d = sys.argv[1], sys.argv[2]
db = os.path.join(d, "database.db")
t = {}
t0 = time.time(); pycolmap.extract_features(db, images, device=pycolmap.Device.cpu); t["features"] = time.time() - t0
t0 = time.time(); pycolmap.match_exhaustive(db, device=pycolmap.Device.cpu); t["matching"] = time.time() - t0
t0 = time.time(); recs = pycolmap.incremental_mapping(db, images, os.path.join(d, "sparse")); t["mapping"] = time.time() - t0
best = max(recs.values(), key=lambda r: r.num_reg_images()) if recs else None
print("RESULT", json.dumps({"timings": t, "registered": best.num_reg_images() if best else 0,
                            "mre": best.compute_mean_reprojection_error() if best else None}))
"""


def pycolmap_defaults(images, work):
    """pycolmap's own default pipeline on the same images, in a child process (wall time, peak RSS)."""
    d = os.path.join(work, "pycolmap-defaults")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "sparse"))
    log = os.path.join(d, "run.log")
    rc, wall, rss = run_measured([sys.executable, "-c", PYCOLMAP_DEFAULTS, images, d], log_path=log)
    if rc != 0:
        raise SystemExit(f"pycolmap defaults failed, see {log}")
    result = [json.loads(line[7:]) for line in open(log) if line.startswith("RESULT ")][0]
    return result, wall, rss


def colmap(images, work, threads, defaults, neighbours, max_features):
    exe = shutil.which("colmap")
    if not exe:
        raise SystemExit("colmap is not installed: apt-get install colmap (make bench does it)")
    d = os.path.join(work, "colmap")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "sparse"))
    db = os.path.join(d, "database.db")
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    common = ["--SiftExtraction.num_threads", str(threads), "--SiftExtraction.use_gpu", "0"]
    steps = []
    fe = [exe, "feature_extractor", "--database_path", db, "--image_path", images] + common
    if not defaults:
        fe += ["--ImageReader.camera_model", "OPENCV", "--SiftExtraction.max_num_features", str(max_features)]
    steps.append(("features", fe))
    with_gps = _has_gps(images)
    if defaults or not with_gps:
        steps.append(("matching", [exe, "exhaustive_matcher", "--database_path", db,
                                   "--SiftMatching.num_threads", str(threads), "--SiftMatching.use_gpu", "0"]))
    else:
        steps.append(("matching", [exe, "spatial_matcher", "--database_path", db, "--SpatialMatching.is_gps", "1",
                                   "--SpatialMatching.ignore_z", "1",
                                   "--SpatialMatching.max_num_neighbors", str(neighbours + 3),
                                   "--SpatialMatching.max_distance", "100000",
                                   "--SiftMatching.num_threads", str(threads), "--SiftMatching.use_gpu", "0"]))
    steps.append(("mapping", [exe, "mapper", "--database_path", db, "--image_path", images,
                              "--output_path", os.path.join(d, "sparse"), "--Mapper.num_threads", str(threads)]))
    timings, peak = {}, 0.0
    for name, cmd in steps:
        rc, wall, rss = run_measured(cmd, env=env, log_path=os.path.join(d, f"{name}.log"))
        if rc != 0:
            raise SystemExit(f"colmap {name} failed, see {d}/{name}.log")
        timings[name] = round(wall, 1)
        peak = max(peak, rss)
    models = sorted(os.listdir(os.path.join(d, "sparse")))
    best = None
    for m in models:
        out = subprocess.run([exe, "model_analyzer", "--path", os.path.join(d, "sparse", m)],
                             capture_output=True, text=True, env=env)
        text = out.stdout + out.stderr
        reg = _grab(text, "Registered images:")
        mre = _grab(text, "Mean reprojection error:")
        if best is None or (reg or 0) > best[0]:
            best = (reg, mre)
    return timings, peak, best


def _grab(text, key):
    for line in text.splitlines():
        if key in line:
            v = line.split(key)[1].strip().replace("px", "").strip()
            try:
                return float(v)
            except ValueError:
                return None
    return None


def _has_gps(images):
    from core.io.images import read_image_info

    names = [n for n in os.listdir(images) if n.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff"))]
    return all(read_image_info(os.path.join(images, n)).gps for n in names[:5])


SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")
TABLE_SETS = ("small", "toledo", "copr", "caliterra", "ochota_kap", "ochota_kap_full", "toledo_2400", "synthetic_mixed",
              "orbit")


def _write_jpeg_with_exif(path, pixels, cam, make, model):
    """A JPEG with Make, Model and FocalLengthIn35mmFilm (the focal prior and the camera grouping read them)."""
    import math

    from PIL import Image

    from core.io.images import FULL_FRAME_DIAGONAL_MM

    ex = Image.Exif()
    ex[0x010F], ex[0x0110] = make, model
    ex.get_ifd(0x8769)[0xA405] = int(round(cam.fx / math.hypot(cam.width, cam.height) * FULL_FRAME_DIAGONAL_MM))
    Image.fromarray(pixels).save(path, quality=95, exif=ex)


def synthetic_mixed(dst):
    """Issue 13 item 5's synthetic block: the tests' orbit (tests/synthetic.py orbit_block, 6 views at 45 and 6
    at 65 degrees off nadir, horizon in the 65 degree views, 480 x 360 camera) plus 6 verticals over the site
    from another camera (640 x 480, its own focal length and distortion)."""
    import numpy as np

    import tests.synthetic as syn

    os.makedirs(dst, exist_ok=True)
    orbit = syn.orbit_block(seed=21, per_ring=6)
    for k, s in enumerate(orbit.shots):
        _write_jpeg_with_exif(os.path.join(dst, s.name), syn.render_oblique_image(orbit.scene, orbit.camera, s, seed=k),
                              orbit.camera, "Synth", "Orbit480")
    vcam = syn.CameraModel(640, 480, 560.0, 560.0, 322.1, 238.4, k1=-0.03, k2=0.005)
    z = orbit.scene.base_z + orbit.altitude
    for k, (x, y) in enumerate([(-12, -8), (0, -8), (12, -8), (-12, 8), (0, 8), (12, 8)]):
        c = np.array([x, y, z])
        shot = syn.Shot(f"V_{k + 1:02d}.jpg", syn.look_at(c, c - np.array([0, 0, 1.0]), np.array([0.0, 1.0, 0.0])),
                        c, "vertical", 9)
        _write_jpeg_with_exif(os.path.join(dst, shot.name), syn.render_oblique_image(orbit.scene, vcam, shot, seed=100 + k),
                              vcam, "Synth", "Nadir640")
    return dst


def _half_size_copies(src, dst):
    """Half-size JPEG copies of ``src``'s photos with their EXIF (focal length, orientation) kept."""
    from PIL import Image

    os.makedirs(dst, exist_ok=True)
    for n in sorted(os.listdir(src)):
        if not n.lower().endswith((".jpg", ".jpeg")) or os.path.exists(os.path.join(dst, n)):
            continue
        with Image.open(os.path.join(src, n)) as im:
            exif = im.info.get("exif", b"")
            im.resize((im.width // 2, im.height // 2), Image.LANCZOS).save(os.path.join(dst, n), quality=95,
                                                                          exif=exif)
    return dst


def table_set(name, work):
    """(images folder, our extra options, note) of a table row; the small frames and the ochota copies are
    made under ``work`` once."""
    if name == "small":
        from tests.test_align_escalation import FOCAL_MM, SENSOR_WIDTH_MM, SMALL_FRAMES, small_frames

        d = os.path.join(work, "small-frames")
        if not os.path.isdir(d):
            small_frames(os.path.join(ROOT, "sample", "toledo", "images"), SMALL_FRAMES, d)
        return d, {"focal_mm": FOCAL_MM, "sensor_width_mm": SENSOR_WIDTH_MM}, \
            "5 Toledo frames at 1152 x 640, contrast 12 %, no EXIF (tests/test_align_escalation.py)"
    if name == "synthetic_mixed":
        d = os.path.join(work, "synthetic-mixed")
        if not os.path.isdir(d):
            synthetic_mixed(d)
        return d, {}, "orbit 6 x 45 deg + 6 x 65 deg (480 x 360) + 6 verticals (640 x 480, another camera)"
    if name == "orbit":  # issue 13 item 4's synthetic orbit as tests/test_obliques.py renders it (sky not masked)
        import tests.synthetic as syn
        from tests.test_obliques import ORBIT

        d = os.path.join(work, "orbit-photos")
        if not os.path.isdir(d):
            syn.orbit_block(**ORBIT).render(d)
        return d, {}, "8 x 45 deg + 8 x 65 deg off nadir (480 x 360), horizon and sky in the 65 deg views"
    if name.startswith("farmland"):  # issue 33: tests/lowtexture_scene.py's 3600 x 2700 farmland, "farmland-0.4"
        return _farmland(work, float(name.split("-")[1]) if "-" in name else 0.15)
    if name == "ochota_kap":
        return _half_size_copies(os.path.join(SHARED, name, "images"), os.path.join(work, "ochota-half")), {}, \
            "half size (2304 x 1728), EXIF kept"
    if name == "ochota_kap_full":
        return os.path.join(SHARED, "ochota_kap", "images"), {}, "full size (4608 x 3456, 16 MP)"
    return os.path.join(SHARED, name, "images"), {}, ""


def _farmland(work, contrast, strips=4, per_strip=5):
    """(images, options, note) of the synthetic farmland block (tests/lowtexture_scene.py full_block: 3600 x 2700
    px, faint furrows at ``contrast``), rendered once under ``work`` (no EXIF: the focal length is given)."""
    from tests import lowtexture_scene as lt

    block = lt.full_block(strips, per_strip, contrast)
    d = os.path.join(work, f"farmland-{contrast:g}-{strips * per_strip}")
    if not os.path.exists(os.path.join(d, "done")):
        block.render(os.path.join(d, "images"), keep_existing=True)
        open(os.path.join(d, "done"), "w").close()
    return os.path.join(d, "images"), {"focal_px": block.camera.fx}, \
        f"synthetic farmland, {strips} x {per_strip} photos of 3600 x 2700, furrows at contrast {contrast:g}, no EXIF"


def _cached(path, run, *args, **kw):
    """The run's {result, wall, rss} kept at ``path``; run only when it is not there."""
    if os.path.exists(path):
        return json.load(open(path))
    out = dict(zip(("result", "wall", "rss"), run(*args, **kw)), cpu=LAST_RUN.get("cpu"))
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
    return out


def table(a):
    """One table across every set: ours vs pycolmap's default pipeline."""
    rows = []
    for name in a.sets.split(","):
        d = os.path.join(a.workdir, "table", name)
        os.makedirs(d, exist_ok=True)
        images, extra, note = table_set(name, os.path.join(a.workdir, "table"))
        n = len([f for f in os.listdir(images) if f.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff", ".png"))])
        print(f"{name}: {images} ({n} images)", flush=True)
        mine = theirs = None
        if a.only in (None, "ours"):
            mine = _cached(os.path.join(d, "ours.json"), ours, images, d, a.threads, extra=extra)
        elif os.path.exists(os.path.join(d, "ours.json")):
            mine = json.load(open(os.path.join(d, "ours.json")))
        if a.only in (None, "pycolmap"):
            theirs = _cached(os.path.join(d, "pycolmap.json"), pycolmap_defaults, images, d)
        elif os.path.exists(os.path.join(d, "pycolmap.json")):
            theirs = json.load(open(os.path.join(d, "pycolmap.json")))
        rows.append((name, n, note, mine, theirs))
        print(_table_text(rows[-1:]), flush=True)
    print("\n" + _table_text(rows))


def _secs(run):
    """'wall s (CPU s)': the CPU seconds of the child do not depend on what else the machine runs."""
    cpu = f" ({run['cpu']:.0f} CPU s)" if run.get("cpu") else ""
    return f"{run['wall']:.1f} s{cpu}"


def _table_text(rows):
    out = ["| set | images | ours: registered | ours: reprojection | ours: wall (CPU) | escalated | "
           "pycolmap defaults: registered | reprojection | wall (CPU) | ours / pycolmap, CPU |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for name, n, note, mine, theirs in rows:
        cells = [name + (f" ({note})" if note else ""), str(n)]
        if mine:
            r = mine["result"]
            esc = r.get("escalation")
            what = "no"
            if esc:
                what = "; ".join(f"round {x['round']} ({x.get('kind', '')}): {len(x['left_out'])} left out, {len(x['re_extracted'])} "
                                 f"re-extracted, {x['registered_before']} -> {x['registered_after']}"
                                 for x in esc["rounds"])
            if r.get("first_pass"):  # the texture probe's choice (core.align.firstpass) and its seconds
                what = f"first pass {r['first_pass']} (probe {r['timings'].get('probe', 0):.1f} s); " + what
            split = f" + {len(r['others'])} other component(s)" if r.get("others") else ""
            cells += [f"{r['registered']}/{n}{split}", f"{r['mre']:.3f} px", _secs(mine), what]
        else:
            cells += ["", "", "", ""]
        if theirs:
            p = theirs["result"]
            cells += [f"{p['registered']}/{n}", "n/a" if p["mre"] is None else f"{p['mre']:.3f} px",
                      _secs(theirs)]
        else:
            cells += ["", "", ""]
        both = mine and theirs and mine.get("cpu") and theirs.get("cpu")
        cells.append(f"{mine['cpu'] / theirs['cpu']:.2f}" if both else "")
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--images", default=DEFAULT_IMAGES)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-align"))
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--skip-colmap", action="store_true")
    ap.add_argument("--colmap-defaults", action="store_true")
    ap.add_argument("--pycolmap-defaults", action="store_true", help="also run pycolmap's default pipeline")
    ap.add_argument("--mapper", default="incremental", choices=["incremental", "global"], help="our mapper")
    ap.add_argument("--chain", action="store_true",
                    help="also run our whole chain to orthomosaic on the same images (benchmarks/chain.py)")
    ap.add_argument("--table", action="store_true", help="one table across every shared set, ours vs pycolmap")
    ap.add_argument("--sets", default=",".join(TABLE_SETS), help="the table's sets (comma-separated)")
    ap.add_argument("--only", choices=["ours", "pycolmap"], help="the table: run one side only")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    if a.table:
        return table(a)
    n = len([f for f in os.listdir(a.images) if f.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff"))])
    print(f"images: {a.images} ({n}); cores: {os.cpu_count()}; threads: {a.threads}", flush=True)
    r, wall, rss = ours(a.images, a.workdir, a.threads, a.mapper)
    print(f"\nArchaeoOrtho align (mapper {a.mapper})")
    for k, v in r["timings"].items():
        print(f"  {k:<18} {v:8.1f} s")
    print(f"  {'wall':<18} {wall:8.1f} s   peak RSS {rss:7.0f} MiB")
    print(f"  registered {r['registered']}/{r['images']}, mean reprojection error {r['mre']:.3f} px, "
          f"{r['points']} points, pairing {r['pairing']} ({r['pairs']} pairs)", flush=True)
    if a.pycolmap_defaults:
        p, pwall, prss = pycolmap_defaults(a.images, a.workdir)
        print("\npycolmap default pipeline (extract_features + match_exhaustive + incremental_mapping)")
        for k, v in p["timings"].items():
            print(f"  {k:<18} {v:8.1f} s")
        print(f"  {'wall':<18} {pwall:8.1f} s   peak RSS {prss:7.0f} MiB")
        mre = "n/a" if p["mre"] is None else f"{p['mre']:.3f}"
        print(f"  registered {p['registered']}/{n}, mean reprojection error {mre} px")
        print(f"\nratio ArchaeoOrtho / pycolmap defaults wall time: {wall / pwall:.2f}", flush=True)
    chain_wall = None
    if a.chain:
        import chain

        names = sorted(f for f in os.listdir(a.images) if f.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff")))
        c = chain.one_run(os.path.abspath(a.images), names, os.path.join(a.workdir, "chain"), True)
        stages = ", ".join(f"{k} {v:.1f}" for k, v in c["seconds"].items())
        print("\nArchaeoOrtho whole chain to orthomosaic (align, EXIF-GPS georeference, DSM, orthomosaic, report)")
        print(f"  wall {c['wall']:.1f} s ({stages}); peak RSS (process tree) {c['peak_rss_mib']:.0f} MiB")
        print(f"  {c['registered']}/{c['images']} registered, DSM valid {c['dsm_valid']:.3f}, orthomosaic valid "
              f"{c['ortho_valid']:.3f}", flush=True)
        chain_wall = c["wall"]
        if a.pycolmap_defaults:
            print(f"  whole chain / pycolmap defaults' alignment alone: {c['wall'] / pwall:.2f}")
    if a.skip_colmap:
        return
    from core.align.features import auto_max_features
    from core.io.images import read_image_info

    first = sorted(f for f in os.listdir(a.images) if f.lower().endswith((".jpg", ".jpeg", ".tif", ".tiff")))[0]
    info = read_image_info(os.path.join(a.images, first))
    feats = auto_max_features(info.width, info.height)
    t, peak, (reg, mre) = colmap(a.images, a.workdir, a.threads, a.colmap_defaults, 12, feats)
    total = sum(t.values())
    label = "COLMAP CLI (its defaults)" if a.colmap_defaults else "COLMAP CLI (same settings)"
    print(f"\n{label}")
    for k, v in t.items():
        print(f"  {k:<18} {v:8.1f} s")
    print(f"  {'wall':<18} {total:8.1f} s   peak RSS {peak:7.0f} MiB")
    print(f"  registered {reg}, mean reprojection error {mre} px")
    print(f"\nratio ArchaeoOrtho / COLMAP wall time: {wall / total:.2f}")
    if chain_wall is not None:
        print(f"ratio ArchaeoOrtho whole chain / COLMAP alignment alone: {chain_wall / total:.2f}")


if __name__ == "__main__":
    main()
