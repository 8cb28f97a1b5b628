"""The alignment stage: images -> features -> pairs -> matches -> mapping -> final bundle adjustment.

:func:`align` reads images from a folder and writes, in the workspace (paths from
:class:`core.project.layout.Layout`):

- ``sfm/database.db``: COLMAP database (features, matches); kept between runs so
  a re-run after a cancel reuses the features and matches already computed;
- ``sfm/model/``: the largest reconstruction in COLMAP binary format, in the
  local model frame;
- ``sfm/alignment.json``: figures and the list of images not registered, with why;
- ``cameras.gpkg``: the camera positions (model frame).

The algorithm modules: :mod:`.features` (cameras, masks, extraction, matching), :mod:`.pairs` (pair
selection), :mod:`.mapping` (incremental or global mapping, bundle adjustment); the options in :mod:`.options`.
"""
from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional, Sequence, Set, Tuple

from ..common.cancel import load_pycolmap
from ..common.files import atomic_output, atomic_write_text, fingerprint
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io.images import CameraGroup, ImageError, ImageInfo, group_cameras, scan_images
from ..io.vector import write_cameras_gpkg
from ..project.layout import Layout
from ..project.stages import ALIGN, run_stage
from ..project.workspace import Workspace
from .features import extract_features, file_hash, masks_for_colmap, match_pairs, setup_database
from .mapping import camera_rows, camera_summary, final_bundle_adjustment, run_mapping, verified_partners
from .options import MAPPERS, MIN_VERIFIED_INLIERS, AlignError, AlignOptions
from .pairs import select_pairs

STAGE = ALIGN


@dataclass
class AlignResult:
    workspace: str
    model_dir: str
    cameras_path: str
    images_given: int
    registered: int
    mean_reprojection_error: float
    num_points3d: int
    unregistered: Dict[str, str]  # image -> why
    other_components: List[List[str]]
    skipped_files: List[str]
    pairing_used: str
    num_pairs: int
    timings: Dict[str, float]
    cameras: List[dict]
    masked_images: int = 0


def _json(obj) -> str:
    return json.dumps(obj, indent=2, default=str)


def _read_images(images_dir: str, options: AlignOptions,
                 progress: Progress) -> Tuple[List[ImageInfo], List[str], List[CameraGroup]]:
    """(usable images, warnings naming skipped files, camera groups); AlignError with fewer than 2 images."""
    infos, skipped = scan_images(images_dir, options.focal_mm, options.sensor_width_mm, options.focal_px,
                                 SubProgress(progress, 0.0, 0.02))
    for w in skipped:
        progress.warning(w)
    if len(infos) == 0:
        raise AlignError(f"no readable images in {images_dir}")
    if len(infos) < 2:
        raise AlignError(f"only one readable image in {images_dir} ({infos[0].name}): alignment needs at least 2 "
                         "overlapping images (for a single photo use 'Orthorectify image')")
    try:
        groups = group_cameras(infos, options.grouping)
    except ImageError as e:
        raise AlignError(str(e)) from e
    return infos, skipped, groups


def diagnose_unregistered(infos: Sequence[ImageInfo], registered: Set[str], others: Sequence[Sequence[str]],
                          partners: Dict[str, int]) -> Dict[str, str]:
    """Why each image outside the main block is not registered: image -> reason."""
    in_other = {n: k for k, comp in enumerate(others, start=2) for n in comp}
    unregistered: Dict[str, str] = {}
    for im in infos:
        if im.name in registered:
            continue
        if im.name in in_other:
            k = in_other[im.name]
            unregistered[im.name] = (f"in a separate component (#{k}, {len(others[k - 2])} images) that "
                                     "shares too few matches with the main block")
        elif partners.get(im.name, 0) == 0:
            unregistered[im.name] = "no verified matches with any other image (no overlap, blur or too little texture)"
        else:
            unregistered[im.name] = (f"matched {partners[im.name]} image(s) but could not be registered "
                                     "(too few 2D-3D correspondences)")
    return unregistered


def _report_unregistered(progress: Progress, unregistered: Dict[str, str], others: Sequence[Sequence[str]],
                         n_registered: int) -> None:
    for n, why in unregistered.items():
        progress.warning(f"not registered: {n}: {why}")
    if others:
        progress.warning(
            f"the images form {len(others) + 1} separate components; kept the largest ({n_registered} "
            "images); others: " + "; ".join(f"#{k}: {', '.join(c)}" for k, c in enumerate(others, start=2))
        )


def _no_reconstruction(partners: Dict[str, int], n_images: int) -> AlignError:
    isolated = [n for n, c in partners.items() if c == 0]
    return AlignError(
        "no reconstruction could be built: the images do not overlap enough. "
        f"{len(isolated)} of {n_images} images share no verified matches with any other image"
        + (f" ({', '.join(isolated[:10])})" if isolated else "")
    )


def _mapping(pycolmap, lay: Layout, images_dir: str, n_images: int, options: AlignOptions, progress: Progress):
    """The reconstructions, largest first; mapping works in a scratch folder removed afterwards."""
    map_tmp = os.path.join(lay.sfm_dir, ".mapping")
    shutil.rmtree(map_tmp, ignore_errors=True)
    os.makedirs(map_tmp)
    recs = run_mapping(pycolmap, lay.database, images_dir, map_tmp, n_images, options, progress)
    shutil.rmtree(map_tmp, ignore_errors=True)
    return sorted(recs.values(), key=lambda r: r.num_reg_images(), reverse=True) if recs else []


def _setup(pycolmap, lay: Layout, infos, groups, options: AlignOptions, images_dir: str, record: dict,
           progress: Progress):
    """Masks for COLMAP and the database's cameras: (mask_path, image -> mask, camera ids)."""
    mask_path, masks = masks_for_colmap(lay.masks_dir, infos, lay.sfm_dir)
    masks_key = fingerprint(sorted((n, file_hash(p)) for n, p in masks.items())) if masks else None
    if masks:
        record["inputs"]["masks"] = masks_key
        progress.info(f"masks: {len(masks)} of {len(infos)} images have a mask ({lay.masks_dir}): "
                      "no features where they are black")
    camera_ids = setup_database(pycolmap, lay.database, groups, options, images_dir, record, masks_key)
    return mask_path, masks, camera_ids


def align(images_dir: str, workspace_dir: str, options: Optional[AlignOptions] = None,
          progress: Optional[Progress] = None) -> AlignResult:
    """Run the alignment stage.  Raises AlignError / ImageError / WorkspaceError / Cancelled."""
    options = options or AlignOptions()
    progress = progress or NullProgress()
    if options.mapper not in MAPPERS:
        raise AlignError(f"unknown mapper {options.mapper!r}; choose one of {', '.join(MAPPERS)}")
    pycolmap = load_pycolmap("the alignment")
    t_start = time.time()
    images_dir = os.path.abspath(images_dir)
    if not os.path.isdir(images_dir):
        raise AlignError(f"image folder {images_dir} does not exist")
    ws = Workspace.create_or_open(workspace_dir)  # checks writability before any work
    lay = Layout(ws)

    # 1. images
    t0 = time.time()
    infos, skipped, groups = _read_images(images_dir, options, progress)
    images_seconds = time.time() - t0
    ws.data["images_dir"] = images_dir
    ws.data["images"] = [im.to_dict() for im in infos]
    ws.data["camera_groups"] = [asdict(g) for g in groups]
    database_key = ws.data["stages"].get(STAGE, {}).get("database_key")
    inputs = {"images": fingerprint([(im.name, im.width, im.height) for im in infos])}
    with run_stage(ws, STAGE, asdict(options), inputs) as run:
        if database_key:
            run.record["database_key"] = database_key
        for g in groups:
            progress.info(f"camera {g.camera_id}: {g.make} {g.model} {g.width}x{g.height}, focal prior "
                          f"{g.focal_px:.1f} px ({g.focal_source}), {len(g.images)} images")
        os.makedirs(lay.sfm_dir, exist_ok=True)
        mask_path, masks, camera_ids = _setup(pycolmap, lay, infos, groups, options, images_dir, run.record,
                                              progress)
        ws.save()

        # 2. features
        with run.step("features", save=False):
            extract_features(pycolmap, lay.database, images_dir, groups, camera_ids, options,
                             SubProgress(progress, 0.02, 0.35), mask_path, list(masks))
        # 3. pairs + matching
        with run.step("matching", save=False):
            pairs, pairing_used, pw = select_pairs(infos, options.pairing, options.spatial_neighbours)
            for w in pw:
                progress.warning(w)
            progress.info(f"pair selection: {pairing_used}, {len(pairs)} pairs for {len(infos)} images")
            match_pairs(pycolmap, lay.database, pairs, lay.sfm_dir, options, SubProgress(progress, 0.35, 0.65))
        # 4. mapping
        with run.step("mapping", save=False):
            ordered = _mapping(pycolmap, lay, images_dir, len(infos), options, SubProgress(progress, 0.65, 0.93))
        partners = verified_partners(pycolmap, lay.database, MIN_VERIFIED_INLIERS)
        if not ordered:
            raise _no_reconstruction(partners, len(infos))
        rec = ordered[0]
        others = [sorted(rec2.images[i].name for i in rec2.reg_image_ids()) for rec2 in ordered[1:]]
        # 5. final global bundle adjustment
        with run.step("bundle_adjustment", save=False):
            progress.report(0.94, "final bundle adjustment")
            pp = final_bundle_adjustment(pycolmap, rec, options, progress)
        registered = {rec.images[i].name for i in rec.reg_image_ids()}
        unregistered = diagnose_unregistered(infos, registered, others, partners)
        _report_unregistered(progress, unregistered, others, len(registered))
        check_cancel(progress)

        # 6. write the model atomically
        with atomic_output(lay.aligned_model_dir) as tmp:
            os.makedirs(tmp)
            rec.write_binary(tmp)
        cameras_path = write_cameras_gpkg(ws.root, camera_rows(rec), crs=None)
        mre = float(rec.compute_mean_reprojection_error())
        timings = dict(images=images_seconds, **run.timings)
        result = AlignResult(
            workspace=ws.root, model_dir=lay.aligned_model_dir, cameras_path=cameras_path, images_given=len(infos),
            registered=len(registered), mean_reprojection_error=mre, num_points3d=int(rec.num_points3D()),
            unregistered=unregistered, other_components=others, skipped_files=skipped, pairing_used=pairing_used,
            num_pairs=len(pairs), timings={k: round(v, 3) for k, v in timings.items()},
            cameras=camera_summary(rec), masked_images=len(masks),
        )
        figures = {k: v for k, v in asdict(result).items() if k not in ("workspace", "model_dir", "cameras_path")}
        figures["principal_point_refined"] = pp
        atomic_write_text(lay.alignment_json, _json(figures))
        run.finish(outputs={"model": lay.rel(lay.aligned_model_dir), "cameras": lay.rel(cameras_path)},
                   results={"registered": result.registered, "images": len(infos),
                            "mean_reprojection_error": mre, "points3d": result.num_points3d,
                            "pairing": pairing_used, "pairs": len(pairs), "masked_images": len(masks),
                            "total_seconds": round(time.time() - t_start, 2)})
    # later stages were built on the previous model: run_stage marked them stale
    progress.report(1.0, f"aligned {result.registered}/{len(infos)} images, {mre:.3f} px")
    return result


def load_model(workspace_dir: str):
    """The aligned model of a workspace as a pycolmap.Reconstruction (LayoutError, a RuntimeError, if none)."""
    load_pycolmap("reading the aligned model")
    return Layout(Workspace.open(workspace_dir)).load_aligned_model()
