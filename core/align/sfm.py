"""Alignment with pycolmap: features, pair selection, matching, incremental mapping, BA.

The stage reads images from a folder and writes, in the workspace:

- ``sfm/database.db``: COLMAP database (features, matches); kept between runs so
  a re-run after a cancel reuses the features and matches already computed;
- ``sfm/model/``: the largest reconstruction in COLMAP binary format, in the
  local model frame;
- ``sfm/alignment.json``: figures and the list of images not registered, with why.

Masks: feature extraction ignores the black pixels of ``<workspace>/masks/<image
name>.png`` (core.masks: COLMAP's own convention, as core.scans writes them
for scanned film and Prepare images for user polygons); an image without a
mask uses every pixel (it is extracted without ``mask_path``: COLMAP would
skip it).  Masks found only as ``masks/<stem>.png`` (also
accepted by the orthophoto stage) are linked under COLMAP's names into
``sfm/masks/``.  The masks are part of the database key: a change of masks
extracts the features afresh.

Pair selection (``pairing``):

- ``exhaustive``: every pair (n(n-1)/2);
- ``sequential``: each image with the next ``SEQUENTIAL_OVERLAP`` images in file
  order (flight order), plus vocabulary-free loop pairs: every image with
  every ``LOOP_STRIDE``-th image, which closes loops between strips (at most
  ``MAX_LOOP_ANCHORS`` such anchor images: the stride grows with the set, so the
  pair count grows linearly, not quadratically, with the number of images);
- ``spatial``: each image with its ``SPATIAL_NEIGHBOURS`` nearest neighbours by
  EXIF GPS (horizontal distance), plus a sequential overlap of 3 as a safety
  net; falls back to exhaustive with a warning when images lack GPS;
- ``auto``: spatial when at least 80 % of the images carry GPS; otherwise
  exhaustive up to ``AUTO_EXHAUSTIVE_MAX`` images and sequential+loop beyond.
"""
from __future__ import annotations

import hashlib
import math
import os
import shutil
import threading
import time
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Cancelled, NullProgress, Progress, SubProgress, check_cancel
from ..io.images import GROUP_AUTO, CameraGroup, ImageError, ImageInfo, group_cameras, scan_images
from ..io.vector import write_cameras_gpkg
from ..project.workspace import (
    CANCELLED,
    DONE,
    FAILED,
    Workspace,
    atomic_output,
    atomic_write_text,
    fingerprint,
)

PAIRINGS = ("auto", "exhaustive", "sequential", "spatial")
CAMERA_MODELS = ("AUTO", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV")

SPATIAL_NEIGHBOURS = 12
SEQUENTIAL_OVERLAP = 12
LOOP_STRIDE = 10
MAX_LOOP_ANCHORS = 30
AUTO_EXHAUSTIVE_MAX = 100
UPSAMPLE_BELOW = 1000  # long side (px, at the matching scale) below which SIFT starts on a 2x upsampled image
MATCH_BLOCK = 24  # pairs per matching call: the unit of progress and cancel
EXTRACT_BLOCK = 2  # images per extraction call: the unit of progress and cancel
STAGE = "align"


class AlignError(RuntimeError):
    """Alignment cannot start or produced nothing usable; the message says why."""


@dataclass
class AlignOptions:
    pairing: str = "auto"
    camera_model: str = "AUTO"
    max_image_size: int = 0  # 0 = full size; downscale for feature extraction only
    max_features: int = 0  # 0 = auto: about 4000 per megapixel, between 2048 and 8192
    affine_features: bool = False  # affine-shape SIFT + domain-size pooling (oblique sets)
    grouping: str = GROUP_AUTO  # auto / single / per_image
    focal_mm: Optional[float] = None
    sensor_width_mm: Optional[float] = None
    focal_px: Optional[float] = None
    spatial_neighbours: int = SPATIAL_NEIGHBOURS
    num_threads: int = -1
    refine_principal_point: bool = True  # in the final global BA, when the camera has enough images
    min_images_opencv: int = 10  # AUTO picks OPENCV from this many images per camera, RADIAL below
    mapper: str = "incremental"  # incremental (COLMAP) or global (GLOMAP: rotation averaging + global positioning)
    first_octave: Optional[int] = None  # SIFT's first octave; None = auto (-1, upsampled, below UPSAMPLE_BELOW px)
    seed: int = 1


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


# ---------------------------------------------------------------------------
# pycolmap helpers
# ---------------------------------------------------------------------------

def _pycolmap():
    try:
        import pycolmap
    except ImportError as e:  # pragma: no cover - depends on the install
        raise AlignError(
            "pycolmap is not installed in the Python that runs ArchaeoOrtho: "
            "run 'make setup' or 'pip install -r requirements.txt'"
        ) from e
    if not os.environ.get("ARCHAEOORTHO_VERBOSE"):
        pycolmap.logging.minloglevel = 2  # errors only; the Progress protocol reports the rest
    return pycolmap


class _CancelWatcher:
    """Polls ``progress.is_cancelled()`` and cancels a pycolmap CancellationToken."""

    def __init__(self, progress: Progress):
        self.progress = progress
        pycolmap = _pycolmap()
        self.token = pycolmap.CancellationToken()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self._stop.wait(0.2):
            if self.progress.is_cancelled():
                self.token.cancel()
                return

    def __enter__(self):
        self._thread.start()
        return self.token

    def __exit__(self, exc_type, exc, tb):
        self._stop.set()
        self._thread.join(timeout=1)
        if exc_type is not None and issubclass(exc_type, InterruptedError) and self.token.is_cancelled:
            raise Cancelled("cancelled by the user") from exc
        return False


def choose_camera_model(requested: str, n_images: int, min_images_opencv: int = 10) -> str:
    requested = (requested or "AUTO").upper()
    if requested not in CAMERA_MODELS:
        raise AlignError(f"unknown camera model {requested!r}; choose one of {', '.join(CAMERA_MODELS)}")
    if requested != "AUTO":
        return requested
    if n_images >= min_images_opencv:
        return "OPENCV"
    if n_images >= 3:
        return "RADIAL"
    return "SIMPLE_RADIAL"


# ---------------------------------------------------------------------------
# pair selection
# ---------------------------------------------------------------------------

def gps_to_local_xy(gps: Sequence[Tuple[float, float, float]]) -> np.ndarray:
    """EXIF lon/lat to a local metric plane around their mean (enough for neighbour search)."""
    a = np.asarray(gps, dtype=float)
    lon0, lat0 = a[:, 0].mean(), a[:, 1].mean()
    x = (a[:, 0] - lon0) * 111320.0 * math.cos(math.radians(lat0))
    y = (a[:, 1] - lat0) * 110540.0
    return np.column_stack([x, y])


def select_pairs(images: Sequence[ImageInfo], pairing: str,
                 spatial_neighbours: int = SPATIAL_NEIGHBOURS) -> Tuple[List[Tuple[str, str]], str, List[str]]:
    """Returns (pairs of image names, the pairing actually used, warnings)."""
    pairing = (pairing or "auto").lower()
    if pairing not in PAIRINGS:
        raise AlignError(f"unknown pairing {pairing!r}; choose one of {', '.join(PAIRINGS)}")
    warnings: List[str] = []
    n = len(images)
    names = [im.name for im in images]
    with_gps = sum(1 for im in images if im.gps)
    if pairing == "auto":
        if with_gps >= 0.8 * n and n > spatial_neighbours + 1:
            pairing = "spatial"
        elif with_gps >= 0.8 * n or n <= AUTO_EXHAUSTIVE_MAX:
            pairing = "exhaustive"
        else:
            pairing = "sequential"
    if pairing == "spatial" and with_gps < n:
        missing = [im.name for im in images if not im.gps]
        warnings.append(
            f"spatial pairing needs EXIF GPS on every image; {len(missing)} lack it "
            f"({', '.join(missing[:5])}{'…' if len(missing) > 5 else ''}): falling back to exhaustive"
        )
        pairing = "exhaustive"
    pairs = set()

    def add(i, j):
        if i != j:
            pairs.add((min(i, j), max(i, j)))

    if pairing == "exhaustive":
        for i in range(n):
            for j in range(i + 1, n):
                add(i, j)
    elif pairing == "sequential":
        stride = max(LOOP_STRIDE, -(-n // MAX_LOOP_ANCHORS))
        for i in range(n):
            for k in range(1, SEQUENTIAL_OVERLAP + 1):
                if i + k < n:
                    add(i, i + k)
            for j in range(0, n, stride):
                add(i, j)
    else:  # spatial
        xy = gps_to_local_xy([im.gps for im in images])
        d = np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=2)
        k = min(spatial_neighbours, n - 1)
        for i in range(n):
            for j in np.argsort(d[i])[1:k + 1]:
                add(i, int(j))
            for s in range(1, 4):
                if i + s < n:
                    add(i, i + s)
    return [(names[i], names[j]) for i, j in sorted(pairs)], pairing, warnings


# ---------------------------------------------------------------------------
# the stage
# ---------------------------------------------------------------------------

def _setup_database(pycolmap, db_path: str, groups: List[CameraGroup], options: AlignOptions,
                    images_dir: str, state: dict, masks_key: Optional[str] = None) -> Dict[str, int]:
    """Create (or check) the database's cameras; returns camera_id per group key."""
    what = {
        "groups": [(g.key, g.width, g.height, round(g.focal_px, 3), sorted(g.images)) for g in groups],
        "model": options.camera_model, "max_image_size": options.max_image_size,
        "max_features": options.max_features, "affine": options.affine_features,
        "images_dir": os.path.abspath(images_dir),
    }
    if masks_key:  # only with masks: the key of a workspace without masks stays as it was
        what["masks"] = masks_key
    g0 = max(groups, key=lambda g: g.width * g.height)
    octave = sift_first_octave(options, g0.width, g0.height)
    if octave != -1:  # COLMAP's default (-1) keeps the key of earlier workspaces
        what["first_octave"] = octave
    key = fingerprint(what)
    if os.path.exists(db_path) and state.get("database_key") != key:
        os.unlink(db_path)  # different images or extraction settings: start afresh
    state["database_key"] = key
    db = pycolmap.Database.open(db_path)
    try:
        ids = {}
        existing = {c.camera_id: c for c in db.read_all_cameras()}
        for g in groups:
            model = choose_camera_model(options.camera_model, len(g.images), options.min_images_opencv)
            if g.camera_id in existing:
                ids[g.key] = g.camera_id
                continue
            cam = pycolmap.Camera.create_from_model_name(g.camera_id, model, g.focal_px, g.width, g.height)
            cam.has_prior_focal_length = g.focal_source != "default"
            ids[g.key] = db.write_camera(cam, use_camera_id=True)
        return ids
    finally:
        db.close()


def auto_max_features(width: int, height: int, max_image_size: int = 0) -> int:
    """Features per image when the user leaves it at 0: ~4000 per megapixel matched, 2048..8192."""
    scale = min(1.0, max_image_size / max(width, height)) if max_image_size else 1.0
    mp = width * height * scale * scale / 1e6
    return int(min(8192, max(2048, round(4000 * mp, -2))))


def _file_hash(path: str) -> str:
    h = hashlib.sha1()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()[:16]


def _masks_for_colmap(masks_dir: str, infos: Sequence[ImageInfo], sfm_dir: str) -> Tuple[Optional[str], Dict[str, str]]:
    """The folder to give COLMAP as ``mask_path`` (None without masks) and image -> mask file.

    Every mask must have its image's size (COLMAP drops every feature outside
    a smaller mask).  When all masks carry COLMAP's names the workspace's
    masks folder is used as it is; otherwise ``sfm/masks`` gets links (or
    copies) under COLMAP's names.
    """
    from ..prepare.masks import MaskError, find_mask, mask_file_name, png_size

    found: Dict[str, str] = {}
    for im in infos:
        p = find_mask(masks_dir, im.name)
        if not p:
            continue
        try:
            w, h = png_size(p)
        except MaskError as e:
            raise AlignError(str(e)) from e
        if (w, h) != (im.width, im.height):
            raise AlignError(f"mask {p} is {w} x {h} px but image {im.name} is {im.width} x {im.height} px: "
                             "a mask must have its image's size (run 'Prepare images' again or remove the mask)")
        found[im.name] = p
    linked = os.path.join(sfm_dir, "masks")
    if all(os.path.basename(p) == mask_file_name(n) for n, p in found.items()):
        shutil.rmtree(linked, ignore_errors=True)
        return (masks_dir if found else None), found
    with atomic_output(linked) as tmp:
        os.makedirs(tmp)
        for n, p in found.items():
            dst = os.path.join(tmp, mask_file_name(n))
            try:
                os.link(p, dst)
            except OSError:
                shutil.copyfile(p, dst)
    return linked, found


def sift_first_octave(options: AlignOptions, width: int, height: int) -> int:
    """SIFT's first octave: -1 (the image upsampled 2x: more small-scale features, 4x the work) for small
    images, 0 from ``UPSAMPLE_BELOW`` px on the long side at the matching scale, where the image itself has
    features enough; ``options.first_octave`` overrides."""
    if options.first_octave is not None:
        return int(options.first_octave)
    side = max(width, height)
    if options.max_image_size and options.max_image_size > 0:
        side = min(side, options.max_image_size)
    return -1 if side < UPSAMPLE_BELOW else 0


def _extract(pycolmap, db_path, images_dir, groups, camera_ids, options, progress: Progress,
             mask_path: Optional[str] = None, masked: Optional[Sequence[str]] = None):
    eo = pycolmap.FeatureExtractionOptions()
    g0 = max(groups, key=lambda g: g.width * g.height)
    eo.sift.max_num_features = int(options.max_features or auto_max_features(g0.width, g0.height,
                                                                              options.max_image_size))
    if options.max_image_size and options.max_image_size > 0:
        eo.max_image_size = int(options.max_image_size)
    eo.sift.first_octave = sift_first_octave(options, g0.width, g0.height)
    eo.num_threads = options.num_threads
    if options.affine_features:
        eo.sift.estimate_affine_shape = True
        eo.sift.domain_size_pooling = True
    db = pycolmap.Database.open(db_path)
    try:
        done = {im.name for im in db.read_all_images() if db.exists_keypoints(im.image_id)}
    finally:
        db.close()
    masked = set(masked or ())
    todo: List[Tuple[CameraGroup, List[str]]] = []
    for g in groups:
        rest = [n for n in g.images if n not in done]
        # COLMAP skips an image whose mask is missing when mask_path is set: masked and unmasked images go
        # in separate blocks (in file order), only the masked ones with mask_path
        block: List[str] = []
        for n in rest:
            if block and (len(block) >= EXTRACT_BLOCK or (n in masked) != (block[0] in masked)):
                todo.append((g, block))
                block = []
            block.append(n)
        if block:
            todo.append((g, block))
    total = sum(len(b) for _, b in todo)
    if done:
        progress.info(f"features: {len(done)} images already extracted, reused")
    count = 0
    for g, block in todo:
        check_cancel(progress)
        ro = pycolmap.ImageReaderOptions()
        ro.existing_camera_id = camera_ids[g.key]
        if mask_path and block[0] in masked:
            ro.mask_path = mask_path  # <mask_path>/<image name>.png, black = no features
        with _CancelWatcher(progress) as token:
            pycolmap.extract_features(db_path, images_dir, image_names=block,
                                      camera_mode=pycolmap.CameraMode.SINGLE, reader_options=ro,
                                      extraction_options=eo, device=pycolmap.Device.cpu,
                                      cancellation_token=token)
        check_cancel(progress)
        count += len(block)
        progress.report(count / max(1, total), f"features: {count}/{total} images ({block[-1]})")


def _match(pycolmap, db_path, pairs, work_dir, options, progress: Progress):
    db = pycolmap.Database.open(db_path)
    try:
        id_by_name = {im.name: im.image_id for im in db.read_all_images()}
        todo = []
        for a, b in pairs:
            if a not in id_by_name or b not in id_by_name:
                continue
            if not db.exists_two_view_geometry(id_by_name[a], id_by_name[b]):
                todo.append((a, b))
    finally:
        db.close()
    if len(todo) < len(pairs):
        progress.info(f"matching: {len(pairs) - len(todo)} of {len(pairs)} pairs already matched, reused")
    mo = pycolmap.FeatureMatchingOptions()
    mo.num_threads = options.num_threads
    vo = pycolmap.TwoViewGeometryOptions()
    list_path = os.path.join(work_dir, "pairs-block.txt")
    for start in range(0, len(todo), MATCH_BLOCK):
        check_cancel(progress)
        block = todo[start:start + MATCH_BLOCK]
        atomic_write_text(list_path, "".join(f"{a} {b}\n" for a, b in block))
        po = pycolmap.ImportedPairingOptions()
        po.match_list_path = list_path
        with _CancelWatcher(progress) as token:
            pycolmap.match_image_pairs(db_path, matching_options=mo, pairing_options=po,
                                       verification_options=vo, device=pycolmap.Device.cpu,
                                       cancellation_token=token)
        check_cancel(progress)
        done = min(len(todo), start + MATCH_BLOCK)
        progress.report(done / max(1, len(todo)), f"matching: {done}/{len(todo)} pairs")


def _verified_partners(pycolmap, db_path, min_inliers: int) -> Dict[str, int]:
    db = pycolmap.Database.open(db_path)
    try:
        names = {im.image_id: im.name for im in db.read_all_images()}
        pair_ids, counts = db.read_two_view_geometry_num_inliers()
        partners = {n: 0 for n in names.values()}
        for pid, c in zip(pair_ids, counts):
            if c >= min_inliers:
                i, j = pycolmap.pair_id_to_image_pair(pid)
                partners[names[i]] += 1
                partners[names[j]] += 1
        return partners
    finally:
        db.close()


MAPPERS = ("incremental", "global")


def _map(pycolmap, db_path, images_dir, out_dir, n_images, options, progress: Progress):
    if options.mapper == "global":
        return _map_global(pycolmap, db_path, images_dir, out_dir, options, progress)
    opts = pycolmap.IncrementalPipelineOptions()
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.mapper.random_seed = options.seed
    opts.triangulation.random_seed = options.seed
    opts.ba_refine_principal_point = False
    opts.min_model_size = 3  # keep small separate components so they can be reported by name
    state = {"n": 0}

    def on_next():
        state["n"] += 1
        progress.report(min(1.0, state["n"] / max(1, n_images)), f"mapping: registered image {state['n']}")

    with _CancelWatcher(progress) as token:
        recs = pycolmap.incremental_mapping(db_path, images_dir, out_dir, options=opts,
                                            next_image_callback=on_next, cancellation_token=token)
    check_cancel(progress)
    return recs


def _map_global(pycolmap, db_path, images_dir, out_dir, options, progress: Progress):
    """GLOMAP's global pipeline (rotation averaging, global positioning, bundle adjustment).  pycolmap 4.2
    gives it no cancellation token and no progress callback: a cancel takes effect when it returns."""
    opts = pycolmap.GlobalPipelineOptions()
    opts.num_threads = options.num_threads
    opts.random_seed = options.seed
    opts.min_model_size = 3
    progress.report(0.0, "mapping: global SfM (rotation averaging, global positioning, bundle adjustment)")
    check_cancel(progress)
    recs = pycolmap.global_mapping(db_path, images_dir, out_dir, options=opts)
    check_cancel(progress)
    progress.report(1.0, "mapping: global SfM done")
    return recs


def _final_ba(pycolmap, rec, options: AlignOptions, progress: Progress):
    ba = pycolmap.BundleAdjustmentOptions()
    ba.print_summary = False
    counts: Dict[int, int] = {}
    for im in rec.images.values():
        if im.has_pose:
            counts[im.camera_id] = counts.get(im.camera_id, 0) + 1
    ba.refine_principal_point = bool(options.refine_principal_point and counts
                                     and min(counts.values()) >= options.min_images_opencv)
    ba.ceres.loss_function_type = pycolmap.LossFunctionType.CAUCHY
    ba.ceres.solver_options.max_num_iterations = 30  # the mapper's last global BA has already converged
    with _CancelWatcher(progress) as token:
        pycolmap.bundle_adjustment(rec, ba, cancellation_token=token)
    check_cancel(progress)
    return ba.refine_principal_point


def camera_rows(rec) -> List[dict]:
    """Per registered image: name, camera id, projection centre (model frame), viewing direction."""
    rows = []
    for im in sorted(rec.images.values(), key=lambda i: i.name):
        if not im.has_pose:
            continue
        c = np.asarray(im.projection_center(), dtype=float)
        d = np.asarray(im.viewing_direction(), dtype=float)
        rows.append({"image": im.name, "camera_id": int(im.camera_id), "x": float(c[0]), "y": float(c[1]),
                     "z": float(c[2]), "dx": float(d[0]), "dy": float(d[1]), "dz": float(d[2]),
                     "points": int(im.num_points3D)})
    return rows


def camera_summary(rec) -> List[dict]:
    out = []
    for cam in rec.cameras.values():
        out.append({"camera_id": int(cam.camera_id), "model": cam.model.name, "width": int(cam.width),
                    "height": int(cam.height), "params": [float(v) for v in cam.params],
                    "params_info": cam.params_info})
    return out


def align(images_dir: str, workspace_dir: str, options: Optional[AlignOptions] = None,
          progress: Optional[Progress] = None) -> AlignResult:
    """Run the alignment stage.  Raises AlignError / ImageError / WorkspaceError / Cancelled."""
    options = options or AlignOptions()
    progress = progress or NullProgress()
    if options.mapper not in MAPPERS:
        raise AlignError(f"unknown mapper {options.mapper!r}; choose one of {', '.join(MAPPERS)}")
    pycolmap = _pycolmap()
    t_start = time.time()
    images_dir = os.path.abspath(images_dir)
    if not os.path.isdir(images_dir):
        raise AlignError(f"image folder {images_dir} does not exist")
    ws = Workspace.create_or_open(workspace_dir)  # checks writability before any work
    timings: Dict[str, float] = {}

    # 1. images
    t0 = time.time()
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
    timings["images"] = time.time() - t0
    params = asdict(options)
    ws.data["images_dir"] = images_dir
    ws.data["images"] = [im.to_dict() for im in infos]
    ws.data["camera_groups"] = [asdict(g) for g in groups]
    state = ws.data["stages"].get(STAGE, {})
    database_key = state.get("database_key")
    ws.begin_stage(STAGE, params, {"images": fingerprint([(im.name, im.width, im.height) for im in infos])})
    rec_state = ws.data["stages"][STAGE]
    if database_key:
        rec_state["database_key"] = database_key
    for g in groups:
        progress.info(f"camera {g.camera_id}: {g.make} {g.model} {g.width}x{g.height}, focal prior "
                      f"{g.focal_px:.1f} px ({g.focal_source}), {len(g.images)} images")
    sfm_dir = ws.subdir("sfm")
    db_path = os.path.join(sfm_dir, "database.db")
    try:
        mask_path, masks = _masks_for_colmap(ws.path("masks"), infos, sfm_dir)
        masks_key = fingerprint(sorted((n, _file_hash(p)) for n, p in masks.items())) if masks else None
        if masks:
            rec_state["inputs"]["masks"] = masks_key
            progress.info(f"masks: {len(masks)} of {len(infos)} images have a mask ({ws.path('masks')}): "
                          "no features where they are black")
        camera_ids = _setup_database(pycolmap, db_path, groups, options, images_dir, rec_state, masks_key)
        ws.save()

        # 2. features
        t0 = time.time()
        _extract(pycolmap, db_path, images_dir, groups, camera_ids, options, SubProgress(progress, 0.02, 0.35),
                 mask_path, list(masks))
        timings["features"] = time.time() - t0
        ws.record_timing(STAGE, "features", timings["features"])

        # 3. pairs + matching
        t0 = time.time()
        pairs, pairing_used, pw = select_pairs(infos, options.pairing, options.spatial_neighbours)
        for w in pw:
            progress.warning(w)
        progress.info(f"pair selection: {pairing_used}, {len(pairs)} pairs for {len(infos)} images")
        _match(pycolmap, db_path, pairs, sfm_dir, options, SubProgress(progress, 0.35, 0.65))
        timings["matching"] = time.time() - t0
        ws.record_timing(STAGE, "matching", timings["matching"])

        # 4. mapping
        t0 = time.time()
        map_tmp = os.path.join(sfm_dir, ".mapping")
        shutil.rmtree(map_tmp, ignore_errors=True)
        os.makedirs(map_tmp)
        recs = _map(pycolmap, db_path, images_dir, map_tmp, len(infos), options, SubProgress(progress, 0.65, 0.93))
        shutil.rmtree(map_tmp, ignore_errors=True)
        timings["mapping"] = time.time() - t0
        partners = _verified_partners(pycolmap, db_path, 15)
        if not recs:
            isolated = [n for n, c in partners.items() if c == 0]
            raise AlignError(
                "no reconstruction could be built: the images do not overlap enough. "
                f"{len(isolated)} of {len(infos)} images share no verified matches with any other image"
                + (f" ({', '.join(isolated[:10])})" if isolated else "")
            )
        ordered = sorted(recs.values(), key=lambda r: r.num_reg_images(), reverse=True)
        rec = ordered[0]
        others = [sorted(rec2.images[i].name for i in rec2.reg_image_ids()) for rec2 in ordered[1:]]

        # 5. final global bundle adjustment
        t0 = time.time()
        progress.report(0.94, "final bundle adjustment")
        pp = _final_ba(pycolmap, rec, options, progress)
        timings["bundle_adjustment"] = time.time() - t0
        ws.record_timing(STAGE, "mapping", timings["mapping"])
        ws.record_timing(STAGE, "bundle_adjustment", timings["bundle_adjustment"])

        registered = {rec.images[i].name for i in rec.reg_image_ids()}
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
        for n, why in unregistered.items():
            progress.warning(f"not registered: {n}: {why}")
        if others:
            progress.warning(
                f"the images form {len(others) + 1} separate components; kept the largest ({len(registered)} "
                "images); others: " + "; ".join(f"#{k}: {', '.join(c)}" for k, c in enumerate(others, start=2))
            )
        check_cancel(progress)

        # 6. write the model atomically
        model_dir = os.path.join(sfm_dir, "model")
        with atomic_output(model_dir) as tmp:
            os.makedirs(tmp)
            rec.write_binary(tmp)
        cameras_path = write_cameras_gpkg(ws.root, camera_rows(rec), crs=None)
        mre = float(rec.compute_mean_reprojection_error())
        result = AlignResult(
            workspace=ws.root, model_dir=model_dir, cameras_path=cameras_path, images_given=len(infos), registered=len(registered),
            mean_reprojection_error=mre, num_points3d=int(rec.num_points3D()), unregistered=unregistered,
            other_components=others, skipped_files=skipped, pairing_used=pairing_used, num_pairs=len(pairs),
            timings={k: round(v, 3) for k, v in timings.items()}, cameras=camera_summary(rec),
            masked_images=len(masks),
        )
        figures = {k: v for k, v in asdict(result).items() if k not in ("workspace", "model_dir", "cameras_path")}
        figures["principal_point_refined"] = pp
        atomic_write_text(os.path.join(sfm_dir, "alignment.json"), _json(figures))
        ws.end_stage(STAGE, DONE, outputs={"model": os.path.relpath(model_dir, ws.root),
                                            "cameras": os.path.relpath(cameras_path, ws.root)},
                     results={"registered": result.registered, "images": len(infos),
                              "mean_reprojection_error": mre, "points3d": result.num_points3d,
                              "pairing": pairing_used, "pairs": len(pairs), "masked_images": len(masks),
                              "total_seconds": round(time.time() - t_start, 2)})
        # later stages were built on the previous model
        ws.invalidate_after(STAGE, ["align", "georeference", "dsm", "orthophoto", "report"])
        progress.report(1.0, f"aligned {result.registered}/{len(infos)} images, {mre:.3f} px")
        return result
    except Cancelled:
        ws.end_stage(STAGE, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        ws.end_stage(STAGE, FAILED, error=str(e))
        raise


def load_model(workspace_dir: str):
    """The aligned (or georeferenced) model of a workspace as a pycolmap.Reconstruction."""
    pycolmap = _pycolmap()
    ws = Workspace.open(workspace_dir)
    model_dir = ws.path("sfm", "model")
    if not ws.stage_done(STAGE) or not os.path.isdir(model_dir):
        raise AlignError(f"workspace {ws.root} has no aligned model: run 'Align images' first")
    rec = pycolmap.Reconstruction()
    rec.read_binary(model_dir)
    return rec


def _json(obj) -> str:
    import json

    return json.dumps(obj, indent=2, default=str)
