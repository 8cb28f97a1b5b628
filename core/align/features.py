"""Features and matches in the COLMAP database: cameras, masks for COLMAP, SIFT extraction, pair matching.

Masks: feature extraction ignores the black pixels of ``<workspace>/masks/<image
name>.png`` (core.prepare.masks: COLMAP's own convention, as core.prepare.scans writes
them for scanned film and Prepare images for user polygons); an image without a
mask uses every pixel (it is extracted without ``mask_path``: COLMAP would
skip it).  Masks found only as ``masks/<stem>.png`` (also accepted by the
orthophoto stage) are linked under COLMAP's names into ``sfm/masks/``.  The
masks are part of the database key: a change of masks extracts the features
afresh.
"""
from __future__ import annotations

import hashlib
import math
import os
import shutil
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from ..common.cancel import CancelWatcher
from ..common.files import atomic_output, atomic_write_text, fingerprint
from ..common.parallel import auto_workers
from ..common.progress import Progress, check_cancel
from ..io.images import CameraGroup, ImageError, ImageInfo, open_image, photo_fingerprint, read_matching_grey8
from ..prepare.masks import MaskError, find_mask, mask_file_name, png_size
from .calibrated import GivenCamera, colmap_camera
from .options import (
    AUTO_FEATURE_MEGAPIXELS,
    AUTO_FEATURES_PER_MP,
    AUTO_FEATURES_RANGE,
    CAMERA_MODELS,
    EXTRACT_BLOCK,
    EXTRACT_BLOCK_MEGAPIXELS,
    MATCH_BLOCK,
    MATCH_BLOCK_KEYPOINTS,
    MAX_EXTRACT_BLOCK,
    MAX_MATCH_BLOCK,
    UPSAMPLE_BELOW,
    AlignError,
    AlignOptions,
)


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


def database_key(groups: List[CameraGroup], options: AlignOptions, images_dir: str, masks_key: Optional[str] = None,
                 photos_key: Optional[str] = None, first_pass: Optional[Dict[str, object]] = None) -> str:
    """The key of what a database's features were extracted from: images (names, sizes, content), folder,
    camera settings, masks and the first pass's settings where the texture probe (core.align.firstpass) chose
    other than the default (``first_pass``); a database of another key is not reused."""
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
    size = feature_image_size(g0.width, g0.height, options.max_image_size)
    if size < max(g0.width, g0.height) and not options.max_image_size:  # the auto size: only where it scales
        what["feature_image_size"] = size
    n_auto = auto_max_features(g0.width, g0.height, options.max_image_size)
    if not options.max_features and n_auto == AUTO_FEATURES_RANGE[1]:  # the cap (8192 before it was 4096)
        what["auto_features"] = n_auto
    if first_pass:  # richer settings chosen from the photos' texture: another choice extracts afresh
        what["first_pass"] = first_pass
    if photos_key:  # the photos' content: another photo under the same name is extracted afresh
        what["photos"] = photos_key
    return fingerprint(what)


def setup_database(pycolmap, db_path: str, groups: List[CameraGroup], options: AlignOptions, key: str,
                   known_key: Optional[str], given: Optional[Dict[str, GivenCamera]] = None) -> Dict[str, int]:
    """Create (or update) the database's cameras; returns camera_id per group key.  A database at ``db_path``
    made for ``known_key`` is removed first when the ``key`` of this run differs.  ``given``: group key -> its
    given interior orientation (core.align.calibrated): that camera gets the calibration's model and parameters
    (the features do not depend on them, so a database kept from an earlier run takes this run's cameras)."""
    if os.path.exists(db_path) and known_key != key:
        os.unlink(db_path)  # different images or extraction settings: start afresh
    db = pycolmap.Database.open(db_path)
    try:
        ids = {}
        existing = {c.camera_id: c for c in db.read_all_cameras()}
        for g in groups:
            model = choose_camera_model(options.camera_model, len(g.images), options.min_images_opencv)
            cam = colmap_camera(pycolmap, g, (given or {}).get(g.key), model)
            if g.camera_id in existing:
                db.update_camera(cam)
                ids[g.key] = g.camera_id
                continue
            ids[g.key] = db.write_camera(cam, use_camera_id=True)
        return ids
    finally:
        db.close()


def feature_image_size(width: int, height: int, max_image_size: int = 0) -> int:
    """The long side (px) of the image SIFT runs on: ``max_image_size`` when given (> 0), else the photo's own up to
    AUTO_FEATURE_MEGAPIXELS, scaled down to that beyond."""
    side = max(width, height)
    if max_image_size and max_image_size > 0:
        return min(side, int(max_image_size))
    mp = width * height / 1e6
    if mp <= AUTO_FEATURE_MEGAPIXELS:
        return side
    return int(side * math.sqrt(AUTO_FEATURE_MEGAPIXELS / mp))


def auto_max_features(width: int, height: int, max_image_size: int = 0) -> int:
    """Features per image when the user leaves it at 0: AUTO_FEATURES_PER_MP per megapixel of the image the
    features come from (``feature_image_size``), within AUTO_FEATURES_RANGE."""
    scale = feature_image_size(width, height, max_image_size) / max(width, height)
    mp = width * height * scale * scale / 1e6
    lo, hi = AUTO_FEATURES_RANGE
    return int(min(hi, max(lo, round(AUTO_FEATURES_PER_MP * mp, -2))))


def file_hash(path: str) -> str:
    h = hashlib.sha1()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()[:16]


FEATURE_IMAGES = "feature_images"  # sfm/<this>: the 8-bit primary-band images COLMAP extracts features from
FEATURE_IMAGES_VERSION = 1  # how they are made (core.io.images.matching_grey8); part of the database's key
FEATURE_SOURCE = "ARCHAEOORTHO_SOURCE"  # an image's item: version, its photo's fingerprint, the band it took


def _feature_image_source(path: str) -> Optional[str]:
    """What the feature image ``path`` was made from (None: not known, an unreadable image: made again)."""
    try:
        with open_image(path) as r:
            return r.metadata().get(FEATURE_SOURCE)
    except ImageError:
        return None


def feature_image_needed(im: ImageInfo) -> bool:
    """Is a photo's features' image an 8-bit one made for COLMAP (:func:`feature_images`): a photo other than
    8-bit, or one that names its primary band?"""
    return bool(im.primary_band) or im.dtype != "Byte"


def feature_images(infos: Sequence[ImageInfo], sfm_dir: str) -> Tuple[Optional[str], List[str]]:
    """The folder COLMAP reads the photos that are not plain 8-bit from, or that name a primary band (None when
    there are none), and those photos.

    A multispectral capture's stacked photo (core.prepare.captures) names the band it is matched on; COLMAP would
    read its first three bands as a colour photo.  A 16-bit photo (a band file, a 12-bit sensor's TIFF, a scan)
    COLMAP scales to 8 bits by its full 16-bit range: a band whose values fill a few thousand DN becomes a few
    grey levels, and SIFT finds few features; a float photo it cannot read.  Each such photo gets an 8-bit image
    (core.io.images.matching_grey8: its primary band, else its grey, stretched from the 0.5 to the 99.5
    percentile to 0..255) under its own name in ``sfm/feature_images``, the pixel grid unchanged, so keypoints
    are the photo's pixels; an image is made again when its photo's content fingerprint, band or the way images
    are made (FEATURE_IMAGES_VERSION) is not the one it records."""
    from osgeo import gdal

    chosen = [im for im in infos if feature_image_needed(im)]
    folder = os.path.join(sfm_dir, FEATURE_IMAGES)
    if not chosen:
        shutil.rmtree(folder, ignore_errors=True)
        return None, []
    os.makedirs(folder, exist_ok=True)
    for im in chosen:
        dst = os.path.join(folder, im.name)
        source = f"{FEATURE_IMAGES_VERSION}:{photo_fingerprint(im.path)}:{im.primary_band}"
        if os.path.isfile(dst) and _feature_image_source(dst) == source:
            continue
        try:
            grey = read_matching_grey8(im.path, im.primary_band)
        except ImageError as e:
            raise AlignError(str(e)) from e
        with atomic_output(dst) as tmp:
            ds = gdal.GetDriverByName("GTiff").Create(tmp, grey.shape[1], grey.shape[0], 1, gdal.GDT_Byte)
            ds.GetRasterBand(1).WriteArray(grey)
            ds.SetMetadataItem(FEATURE_SOURCE, source)
            ds = None
    return folder, sorted(im.name for im in chosen)


def masks_for_colmap(masks_dir: str, infos: Sequence[ImageInfo], sfm_dir: str) -> Tuple[Optional[str], Dict[str, str]]:
    """The folder to give COLMAP as ``mask_path`` (None without masks) and image -> mask file.

    Every mask must have its image's size (COLMAP drops every feature outside
    a smaller mask).  When all masks carry COLMAP's names the workspace's
    masks folder is used as it is; otherwise ``sfm/masks`` gets links (or
    copies) under COLMAP's names.
    """
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
    side = feature_image_size(width, height, options.max_image_size)
    return -1 if side < UPSAMPLE_BELOW else 0


def extract_block(width: int, height: int, max_image_size: int = 0, first_octave: int = 0) -> int:
    """Images per extraction call: about EXTRACT_BLOCK_MEGAPIXELS of SIFT's work (at the features' scale, an
    upsampled image four times its pixels), within EXTRACT_BLOCK..MAX_EXTRACT_BLOCK."""
    scale = feature_image_size(width, height, max_image_size) / max(width, height)
    mp = width * height * scale * scale / 1e6 * (4.0 if first_octave < 0 else 1.0)
    return int(min(MAX_EXTRACT_BLOCK, max(EXTRACT_BLOCK, EXTRACT_BLOCK_MEGAPIXELS // max(mp, 1e-6))))


def match_block(mean_keypoints: float) -> int:
    """Pairs per matching call: MATCH_BLOCK at MATCH_BLOCK_KEYPOINTS keypoints per image, more for fewer (the
    cost of a pair grows with the product of the counts), within MATCH_BLOCK..MAX_MATCH_BLOCK."""
    ratio = MATCH_BLOCK_KEYPOINTS / max(1.0, float(mean_keypoints))
    return int(min(MAX_MATCH_BLOCK, max(MATCH_BLOCK, round(MATCH_BLOCK * ratio * ratio))))


@dataclass
class FeatureSettings:
    """The SIFT settings of one extraction: the long side (px) of the image SIFT runs on, the features kept per
    image, SIFT's first octave and peak threshold (None: SIFT's default); ``extra``: other SIFT options (the
    escalation's affine shape)."""

    image_size: int
    max_features: int
    first_octave: int
    peak_threshold: Optional[float] = None
    extra: Dict[str, object] = field(default_factory=dict)

    def with_sift(self, sift: Dict[str, object]) -> FeatureSettings:
        """These settings with SIFT options overridden (``max_num_features``, ``first_octave``,
        ``peak_threshold`` and any other SIFT option)."""
        sift = dict(sift)
        return FeatureSettings(self.image_size, int(sift.pop("max_num_features", self.max_features)),
                               int(sift.pop("first_octave", self.first_octave)),
                               sift.pop("peak_threshold", self.peak_threshold), {**self.extra, **sift})

    def to_dict(self) -> Dict[str, object]:
        out: Dict[str, object] = {"image_size": self.image_size, "max_features": self.max_features,
                                  "first_octave": self.first_octave}
        if self.peak_threshold is not None:
            out["peak_threshold"] = round(float(self.peak_threshold), 6)
        out.update(self.extra)
        return out


def default_settings(options: AlignOptions, width: int, height: int) -> FeatureSettings:
    """The fast path's settings for photos of ``width`` x ``height`` (the options' values where the user set
    them, else the automatic scale, budget and first octave)."""
    return FeatureSettings(feature_image_size(width, height, options.max_image_size),
                           int(options.max_features or auto_max_features(width, height, options.max_image_size)),
                           sift_first_octave(options, width, height))


@dataclass
class Extraction:
    """What an extraction works on: the database, the photos' folder, the camera groups with their database
    ids, and COLMAP's mask folder with the images that have a mask."""

    db_path: str
    images_dir: str
    groups: List[CameraGroup]
    camera_ids: Dict[str, int]
    mask_path: Optional[str] = None
    masked: Sequence[str] = ()
    # the folder of 8-bit primary-band images (feature_images) and the photos read from it instead
    proxy_path: Optional[str] = None
    proxied: Sequence[str] = ()


# COLMAP's CPU SIFT holds about this many bytes per pixel of the image it runs on (its scale space, after the
# first octave's upsampling) in each extraction thread: measured 0.55 GiB a thread on 3600 x 2700 photos at 2 MP
# and first octave -1 (an escalation round), 0.15 GiB at first octave 0
SIFT_BYTES_PER_PX = 60


def extraction_threads(num_threads: int, settings: FeatureSettings) -> int:
    """COLMAP's extraction threads: ``num_threads`` when given (> 0), else one per core, as many as keep the
    stage within core.common.parallel.STAGE_MEMORY beside this process (issue 46: an escalation round's upsampled
    SIFT on every core of a 4-core machine held 2.4 GiB)."""
    if num_threads and num_threads > 0:
        return num_threads
    thread_memory = SIFT_BYTES_PER_PX * settings.image_size ** 2 * 4.0 ** max(0, -settings.first_octave)
    return auto_workers(int(thread_memory))


def _extraction_options(pycolmap, settings: FeatureSettings, options: AlignOptions):
    eo = pycolmap.FeatureExtractionOptions()
    eo.sift.max_num_features = int(settings.max_features)
    eo.max_image_size = int(settings.image_size)
    eo.sift.first_octave = int(settings.first_octave)
    if settings.peak_threshold is not None:
        eo.sift.peak_threshold = float(settings.peak_threshold)
    eo.num_threads = extraction_threads(options.num_threads, settings)
    if options.affine_features:
        eo.sift.estimate_affine_shape = True
        eo.sift.domain_size_pooling = True
    for k, v in settings.extra.items():
        setattr(eo.sift, k, v)
    return eo


def _extraction_blocks(job: Extraction, done, settings: FeatureSettings) -> List[Tuple[CameraGroup, List[str]]]:
    masked = set(job.masked or ())
    proxied = set(job.proxied or ())
    todo: List[Tuple[CameraGroup, List[str]]] = []
    for g in job.groups:
        rest = [n for n in g.images if n not in done]
        scale = min(1.0, settings.image_size / max(g.width, g.height))
        size = extract_block(g.width, g.height, int(round(max(g.width, g.height) * scale)), settings.first_octave)
        # COLMAP skips an image whose mask is missing when mask_path is set: masked and unmasked images go
        # in separate blocks (in file order), only the masked ones with mask_path; so do the images read from
        # the primary-band folder
        block: List[str] = []
        for n in rest:
            if block and (len(block) >= size or (n in masked) != (block[0] in masked)
                          or (n in proxied) != (block[0] in proxied)):
                todo.append((g, block))
                block = []
            block.append(n)
        if block:
            todo.append((g, block))
    return todo


def extract_features(pycolmap, job: Extraction, settings: FeatureSettings, options: AlignOptions,
                     progress: Progress) -> None:
    """SIFT features with ``settings`` of every image of ``job.groups`` the database has none for."""
    eo = _extraction_options(pycolmap, settings, options)
    db = pycolmap.Database.open(job.db_path)
    try:
        done = {im.name for im in db.read_all_images() if db.exists_keypoints(im.image_id)}
    finally:
        db.close()
    masked = set(job.masked or ())
    todo = _extraction_blocks(job, done, settings)
    total = sum(len(b) for _, b in todo)
    if done:
        progress.info(f"features: {len(done)} images already extracted, reused")
    count = 0
    for g, block in todo:
        check_cancel(progress)
        ro = pycolmap.ImageReaderOptions()
        ro.existing_camera_id = job.camera_ids[g.key]
        if job.mask_path and block[0] in masked:
            ro.mask_path = job.mask_path  # <mask_path>/<image name>.png, black = no features
        with CancelWatcher(progress) as token:
            folder = job.proxy_path if block[0] in set(job.proxied or ()) else job.images_dir
            pycolmap.extract_features(job.db_path, folder, image_names=block,
                                      camera_mode=pycolmap.CameraMode.SINGLE, reader_options=ro,
                                      extraction_options=eo, device=pycolmap.Device.cpu,
                                      cancellation_token=token)
        check_cancel(progress)
        count += len(block)
        progress.report(count / max(1, total), f"features: {count}/{total} images ({block[-1]})")


def match_pairs(pycolmap, db_path, pairs, work_dir, options, progress: Progress):
    db = pycolmap.Database.open(db_path)
    try:
        id_by_name = {im.name: im.image_id for im in db.read_all_images()}
        size = match_block(db.num_keypoints() / max(1, len(id_by_name)))
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
    for start in range(0, len(todo), size):
        check_cancel(progress)
        block = todo[start:start + size]
        atomic_write_text(list_path, "".join(f"{a} {b}\n" for a, b in block))
        po = pycolmap.ImportedPairingOptions()
        po.match_list_path = list_path
        with CancelWatcher(progress) as token:
            pycolmap.match_image_pairs(db_path, matching_options=mo, pairing_options=po,
                                       verification_options=vo, device=pycolmap.Device.cpu,
                                       cancellation_token=token)
        check_cancel(progress)
        done = min(len(todo), start + size)
        progress.report(done / max(1, len(todo)), f"matching: {done}/{len(todo)} pairs")
