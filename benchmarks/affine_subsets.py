"""Could a cheaper affine round register the synthetic orbit's steep views?  (issue 13 item 1's time criterion)

The escalation's affine round re-extracts every image of a small block with upsampled affine-shape SIFT and
matches every pair again (core/align/escalation.py); on the orbit it brings the steep views in but costs more
than pycolmap's whole default pipeline.  This script runs our fast path once (escalation off), then on copies of
its database re-extracts only a subset of the images with the affine round's SIFT settings, matches every pair
that touches a re-extracted image, maps anew with the stage's mapping (its relaxed second pass included) and
prints per subset: images re-extracted, pairs matched,
seconds (features, matching, mapping), images registered and the tie points of the steep views.  The subsets:
the escalated images only, the escalated images and their steep (65 deg) neighbours, every steep view, and every
image (today's round).  pycolmap's default pipeline on the same photos is the reference line.

    python benchmarks/affine_subsets.py [--workdir DIR]
"""
import argparse
import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)


def fast_path(images, ws):
    from core.align.options import AlignOptions
    from core.align.stage import align

    shutil.rmtree(ws, ignore_errors=True)
    t0 = time.time()
    r = align(images, ws, AlignOptions(escalate=False))
    return r, time.time() - t0


def fast_ties(ws):
    """Image -> tie points in the fast path's model."""
    from core.align.stage import load_model

    rec = load_model(ws)
    return {rec.images[i].name: int(rec.images[i].num_points3D) for i in rec.reg_image_ids()}


def affine_round(pycolmap, images, source_db, work, redo, sift):
    """Re-extract ``redo`` with ``sift`` in a copy of ``source_db``, match every pair touching them, map."""
    from core.align.escalation import forget_features
    from core.align.features import match_pairs
    from core.align.mapping import MappingJob, run_mapping
    from core.align.options import AlignOptions
    from core.common.progress import NullProgress

    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "sparse"))
    db_path = os.path.join(work, "database.db")
    shutil.copyfile(source_db, db_path)
    db = pycolmap.Database.open(db_path)
    try:
        cams = {im.name: im.camera_id for im in db.read_all_images()}
    finally:
        db.close()
    names = sorted(cams)
    t0 = time.time()
    forget_features(db_path, redo)
    eo = pycolmap.FeatureExtractionOptions()
    for k, v in sift.items():
        setattr(eo.sift, k, v)
    for cam in sorted({cams[n] for n in redo}):
        ro = pycolmap.ImageReaderOptions()
        ro.existing_camera_id = cam
        pycolmap.extract_features(db_path, images, image_names=[n for n in redo if cams[n] == cam],
                                  camera_mode=pycolmap.CameraMode.SINGLE, reader_options=ro, extraction_options=eo,
                                  device=pycolmap.Device.cpu)
    t1 = time.time()
    pairs = sorted({tuple(sorted((a, b))) for a in redo for b in names if a != b})
    options = AlignOptions()
    match_pairs(pycolmap, db_path, pairs, work, options, NullProgress())
    t2 = time.time()
    # the stage's own mapping (its relaxed second pass included), as an escalation round maps
    recs = run_mapping(pycolmap, MappingJob(db_path, images, os.path.join(work, "sparse"), len(names)), options,
                       NullProgress())
    t3 = time.time()
    rec = max(recs.values(), key=lambda r: r.num_reg_images()) if recs else None
    ties = {rec.images[i].name: int(rec.images[i].num_points3D) for i in rec.reg_image_ids()} if rec else {}
    return {"pairs": len(pairs), "features": t1 - t0, "matching": t2 - t1, "mapping": t3 - t2, "ties": ties}


def main():
    import pycolmap
    from align import pycolmap_defaults, table_set

    from core.align.escalation import WEAK_MIN_TIES, escalated_sift
    from core.align.options import AlignOptions

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "build", "bench-affine-subsets"))
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    images, _extra, note = table_set("orbit", a.workdir)
    names = sorted(n for n in os.listdir(images) if n.lower().endswith(".jpg"))
    ref, ref_wall, _ = pycolmap_defaults(images, a.workdir)
    print(f"orbit: {note}, {len(names)} images")
    print(f"pycolmap's default pipeline: {ref['registered']}/{len(names)} registered in {ref_wall:.1f} s")
    r, wall = fast_path(images, os.path.join(a.workdir, "ws"))
    left = sorted(r.unregistered)
    print(f"our fast path (escalation off): {r.registered}/{len(names)} in {wall:.1f} s; left out: {', '.join(left)}")
    steep = [n for n in names if n.startswith("T65")]
    weak = sorted(n for n, t in fast_ties(os.path.join(a.workdir, "ws")).items() if t < WEAK_MIN_TIES)
    escalated = sorted(set(left) | set(weak))  # as the escalation takes them: left out or weakly tied
    print(f"escalated: {', '.join(escalated)}")
    idx = {n: k for k, n in enumerate(steep)}
    near = sorted({steep[(idx[n] + d) % len(steep)] for n in escalated if n in idx for d in (-1, 0, 1)})
    sift = escalated_sift(AlignOptions(), 480, 360, "affine")
    print(f"affine round settings: {sift}")
    print("| re-extracted | images | pairs | features s | matching s | mapping s | round s | registered | "
          "tie points of the steep views (min) |")
    print("|---|---|---|---|---|---|---|---|---|")
    db = os.path.join(a.workdir, "ws", "sfm", "database.db")
    for label, redo in (("escalated only", escalated), ("escalated + steep neighbours", near),
                        ("every steep view", steep), ("every image (today's round)", names)):
        o = affine_round(pycolmap, images, db, os.path.join(a.workdir, "round"), redo, sift)
        tie = {n: o["ties"].get(n, 0) for n in steep}
        total = o["features"] + o["matching"] + o["mapping"]
        print(f"| {label} | {len(redo)} | {o['pairs']} | {o['features']:.2f} | {o['matching']:.2f} | "
              f"{o['mapping']:.2f} | {total:.2f} | {len(o['ties'])}/{len(names)} | {min(tie.values())} "
              f"({', '.join(f'{n[:-4]} {t}' for n, t in tie.items() if t < WEAK_MIN_TIES) or f'all >= {WEAK_MIN_TIES}'}) |", flush=True)


if __name__ == "__main__":
    main()
