"""The steps of the "prepare" stage (:mod:`.stage` runs and records them): the usable images, the scanned film
restituted, the user's polygons, the masks put in ``<workspace>/masks`` by hand and the sky merged into each
image's mask, the screening, the folder of prepared images, the masks put in place.

Masks live in ``<workspace>/masks/<prepared image name>.png``.  The stage rewrites the masks it wrote last
time; a mask it did not write (put there by hand) is merged into the new mask of its image and kept aside in
``masks/.originals/`` so that the next run merges it again instead of the previous result.
"""
from __future__ import annotations

import os
import shutil
from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.files import file_fingerprint, fingerprint
from ..common.progress import Progress, SubProgress
from ..io.images import scan_images
from ..project.layout import Layout
from . import masks as masksmod
from . import scans
from . import sky as skymod
from .options import PrepareOptions, ScanOptions, SkyOptions
from .screening import EXCLUDE, KEEP, ImageQuality, ScreeningError, screen_folder

OUTPUT_MARKER = ".archaeoortho-prepared"
ORIGINALS = ".originals"  # masks/<this>/: masks this stage did not write, kept aside while it replaces them
MASKS_STAGING = ".partial-masks-prepare"


@dataclass
class Screened:
    """What the stage screens: the original images, or the prepared scans, with their masks."""

    folder: str
    names: List[str]
    sizes: Dict[str, Tuple[int, int]]
    aliases: Dict[str, str]  # original name -> prepared name (scanned film)
    mask_files: Dict[str, str] = field(default_factory=dict)  # name -> staged mask
    scan_set: Optional[scans.ScanSet] = None


def _link_or_copy(src: str, dst: str) -> None:
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def check_output_dir(output_dir: str, images_dir: str, ws_root: str) -> None:
    out = os.path.realpath(output_dir)
    src = os.path.realpath(images_dir)
    if out == src or src.startswith(out + os.sep):
        raise ScreeningError(f"the output folder {output_dir} must not be the image folder or hold it: "
                             "choose a new folder for the prepared images")
    if out == os.path.realpath(ws_root) or os.path.realpath(ws_root).startswith(out + os.sep):
        raise ScreeningError(f"the output folder {output_dir} must not be the workspace or hold it")
    if os.path.isfile(output_dir):
        raise ScreeningError(f"the output folder {output_dir} exists and is a file")
    if os.path.isdir(output_dir) and os.listdir(output_dir) and \
            not os.path.exists(os.path.join(output_dir, OUTPUT_MARKER)):
        raise ScreeningError(f"the output folder {output_dir} already holds files that 'Prepare images' did not "
                             "write; choose an empty or new folder (it is replaced as a whole)")


def foreign_mask(lay: Layout, name: str, ours: Sequence[str]) -> Optional[str]:
    """A mask of ``name`` that this stage did not write (by hand, another tool), or None."""
    kept = os.path.join(lay.masks_dir, ORIGINALS, masksmod.mask_file_name(name))
    if os.path.isfile(kept):
        return kept
    ours = {os.path.normpath(r) for r in ours}
    for cand in (masksmod.mask_file_name(name), os.path.splitext(name)[0] + ".png"):
        p = os.path.join(lay.masks_dir, cand)
        if os.path.isfile(p) and os.path.normpath(os.path.relpath(p, lay.root)) not in ours:
            return p
    return None


def polygon_record(polygons: Sequence, source: str) -> dict:
    """JSON-able digest of the user polygons for the stage parameters; raises MaskError for a malformed one."""
    polys = masksmod.to_polygons(polygons, source)
    return {"count": len(polys), "images": sorted({p.image or "*" for p in polys}),
            "fingerprint": fingerprint([(p.image, [np.round(r, 3).tolist() for r in p.rings]) for p in polys])}


def fingerprint_files(folder: str, names: Sequence[str]) -> str:
    return fingerprint([(n, file_fingerprint(os.path.join(folder, n))) for n in names])


def screening_summary(quality: Sequence[ImageQuality]) -> dict:
    return {
        "flagged": sum(1 for q in quality if q.flags),
        "excluded": sum(1 for q in quality if q.decision == EXCLUDE),
        "kept": sum(1 for q in quality if q.decision == KEEP),
        "median": {k: round(float(np.median([getattr(q, k) for q in quality])), 5) for k in
                   ("blur_score", "dynamic_range", "brightness", "exposure_score")},
    }


def check_images(images_dir: str, progress: Progress) -> Tuple[List[str], Dict[str, Tuple[int, int]], List[str]]:
    """(usable images, their sizes, warnings naming each skipped file and why) by the rule of 'Align images'
    (:func:`core.io.images.scan_images`: every file is opened and its pixels decoded; an empty file, a file that is
    not an image, a truncated one is skipped with a warning); ScreeningError, before any work, when no usable image
    remains.  One photo is prepared as several are (a single archive frame is the commonest case: one scan ->
    Orthorectify image); the log says that its screening has no set to compare with."""
    infos, skipped = scan_images(images_dir, progress=SubProgress(progress, 0.0, 0.03))
    for w in skipped:
        progress.warning(w)
    if not infos:
        why = ("; ".join(skipped)) if skipped else "no image file"
        raise ScreeningError(f"no usable image in {images_dir}: at least 1 is needed ({why})")
    if len(infos) == 1:
        progress.info(f"one photo ({infos[0].name}): screened on its own, with no set to compare with (only the "
                      "absolute limits: clipped highlights and shadows, dynamic range); prepared as a set's photos "
                      "are")
    return [i.name for i in infos], {i.name: (i.width, i.height) for i in infos}, skipped


def restitute_scans(images_dir: str, names: Sequence[str], tmp: str, staging: str, options: PrepareOptions,
                     progress: Progress, warnings: List[str]) -> Screened:
    """Scanned film: every scan resampled into the fiducial frame (into ``tmp``), its mask into ``staging``."""
    os.makedirs(staging)
    scan_set = scans.prepare_scans([os.path.join(images_dir, n) for n in names], tmp, staging,
                                   options.scan or ScanOptions(), SubProgress(progress, 0.03, 0.75))
    warnings.extend(scan_set.warnings)
    return Screened(folder=tmp, names=[s.prepared_name for s in scan_set.scans],
                     sizes={s.prepared_name: (scan_set.width, scan_set.height) for s in scan_set.scans},
                     aliases={s.name: s.prepared_name for s in scan_set.scans},
                     mask_files={s.prepared_name: os.path.join(staging, s.mask_name) for s in scan_set.scans},
                     scan_set=scan_set)


def merge_user_masks(sc: Screened, polygons: Sequence, foreign: Dict[str, str], staging: str,
                      options: PrepareOptions, progress: Progress, warnings: List[str]) -> Dict[str, int]:
    """The user's polygons and masks put in <workspace>/masks by hand merged into the staged masks; returns
    image -> polygons applied."""
    by_image, axis = masksmod.polygons_by_image(polygons, sc.names, sc.aliases, options.mask_source,
                                                options.mask_y_axis)
    bases = {n: [p for p in (sc.mask_files.get(n), foreign.get(n)) if p]
             for n in sc.names if n in sc.mask_files or n in by_image}
    os.makedirs(staging, exist_ok=True)
    mres = masksmod.build_masks(by_image, sc.sizes, staging, bases, options.mask_source)
    sc.mask_files.update(mres.masks)
    warnings.extend(mres.warnings)
    user_masked = {n: c for n, c in mres.polygons.items() if c}
    if polygons:
        progress.info(f"masks: {len(polygons)} polygons ({options.mask_source}, y "
                      f"{'= -row' if axis == 'up' else 'down'}) hide parts of {len(user_masked)} "
                      f"of {len(sc.names)} images")
    return user_masked


def add_sky_masks(sc: Screened, foreign: Dict[str, str], staging: str, options: PrepareOptions,
                   progress: Progress, warnings: List[str]) -> Dict[str, float]:
    """The sky detector (core.prepare.sky) on every image; its masks merged into the staged ones (or the masks put
    in <workspace>/masks by hand); returns image -> share hidden as sky."""
    bases = {n: sc.mask_files.get(n) or foreign.get(n) for n in sc.names}
    res = skymod.write_sky_masks(sc.folder, sc.names, staging, options.sky or SkyOptions(), bases,
                                 SubProgress(progress, 0.03, 0.2))
    sc.mask_files.update(res.masks)
    warnings.extend(res.warnings)
    progress.info(f"sky: {len(res.masks)} of {len(sc.names)} images show sky, hidden from the alignment")
    return dict(res.sky_fraction)


def fill_prepared(tmp: str, images_dir: str, quality: Sequence[ImageQuality], scanned_film: bool) -> None:
    """The prepared folder: kept images only (links to the originals, or the prepared scans)."""
    if not any(q.decision == KEEP for q in quality):
        raise ScreeningError("every image was flagged and excluded; lower the thresholds or keep "
                             "flagged images")
    for q in quality:
        if scanned_film:
            if q.decision == EXCLUDE:
                os.unlink(os.path.join(tmp, q.prepared_name))
        elif q.decision == KEEP:
            _link_or_copy(os.path.join(images_dir, q.name), os.path.join(tmp, q.name))
    with open(os.path.join(tmp, OUTPUT_MARKER), "w", encoding="utf-8") as fh:
        fh.write(f"prepared by ArchaeoOrtho from {images_dir}\n")


def place_masks(lay: Layout, previous_masks: Sequence[str], quality: Sequence[ImageQuality],
                 mask_files: Dict[str, str]) -> List[str]:
    """Replace the masks this stage wrote last time by the new ones; returns them relative to the workspace."""
    masks_dir = lay.masks_dir
    for rel in previous_masks:  # masks this stage wrote last time
        p = lay.path(rel)
        if os.path.isfile(p) and os.path.dirname(os.path.abspath(p)) == masks_dir:
            os.unlink(p)
    originals = os.path.join(masks_dir, ORIGINALS)
    if os.path.isdir(originals):  # masks set aside last time go back to their place
        for f in os.listdir(originals):
            src, dst = os.path.join(originals, f), os.path.join(masks_dir, f)
            if os.path.exists(dst):
                os.unlink(src)  # replaced by hand since: the newer one stays
            else:
                os.replace(src, dst)
        shutil.rmtree(originals, ignore_errors=True)
    written = []
    for q in quality:
        src = mask_files.get(q.prepared_name)
        if q.decision == KEEP and src and os.path.isfile(src):
            os.makedirs(masks_dir, exist_ok=True)
            dst = os.path.join(masks_dir, os.path.basename(src))
            if os.path.isfile(dst):  # not ours: merged into the new mask, kept aside for the next run
                os.makedirs(originals, exist_ok=True)
                os.replace(dst, os.path.join(originals, os.path.basename(dst)))
            os.replace(src, dst)
            written.append(os.path.relpath(dst, lay.root))
    return written


def screening_doc(images_dir: str, output_dir: str, options: PrepareOptions, quality: Sequence[ImageQuality],
                   summary: dict) -> dict:
    return {
        "images_dir": images_dir, "prepared_dir": output_dir, "options": asdict(options.screening),
        "scanned_film": options.scanned_film, "median": summary["median"],
        "flagged": summary["flagged"], "excluded": summary["excluded"], "kept": summary["kept"],
        "blurriest_first": [q.name for q in sorted(quality, key=lambda q: q.blur_rank)],
        "images": [q.to_dict() for q in quality],
    }


@dataclass
class MaskPlace:
    """Where the masks of a workspace are made: its layout (``masks/``), the masks this stage wrote last time
    (relative to the workspace) and the folder the new ones are staged in."""

    layout: Layout
    previous: List[str]
    staging: str


@dataclass
class Screening:
    """What the stage found: the images screened with their masks, their quality (under the original names, the
    prepared name beside), the user polygons applied and the share hidden as sky, per image."""

    images: Screened
    quality: List[ImageQuality]
    user_masked: Dict[str, int]
    sky_masked: Dict[str, float]


def screen_images(images: Screened, tmp: str, place: MaskPlace, options: PrepareOptions, progress: Progress,
                  step: Callable, warnings: List[str]) -> Screening:
    """The scans restituted into ``tmp`` (scanned film), the masks merged (the scans', the user's polygons, masks
    put in <workspace>/masks by hand, the sky), every image screened; ``step(name, save=False)`` times each
    (the stage's record)."""
    sc, staging = images, place.staging
    if options.scanned_film:
        with step("scans", save=False):
            sc = restitute_scans(images.folder, images.names, tmp, staging, options, progress, warnings)
        sp = SubProgress(progress, 0.75, 0.95)
    else:
        sp = SubProgress(progress, 0.03, 0.90)
    foreign = {n: p for n in sc.names for p in [foreign_mask(place.layout, n, place.previous)] if p}
    polygons = list(options.mask_polygons or [])
    user_masked: Dict[str, int] = {}
    if polygons or (sc.mask_files and foreign):
        with step("masks", save=False):
            user_masked = merge_user_masks(sc, polygons, foreign, staging, options, progress, warnings)
    sky_masked: Dict[str, float] = {}
    if options.sky_masks:
        with step("sky", save=False):
            sky_masked = add_sky_masks(sc, foreign, staging, options, progress, warnings)
    screen_masks = dict(foreign)
    screen_masks.update(sc.mask_files)
    with step("screening", save=False):
        quality = screen_folder(sc.folder, options.screening, sp, sc.names, screen_masks, check=False)
    # screening measured prepared scans: report under the original names (a scan left out by the restitution has
    # none)
    original = {v: k for k, v in sc.aliases.items()}
    for q in quality:
        q.prepared_name = q.name
        q.name = original.get(q.name, q.name)
    return Screening(sc, quality, user_masked, sky_masked)


def parameters(options: PrepareOptions, output_dir: str) -> dict:
    """The stage's recorded parameters: the screening, scan and sky options, the output folder, a digest of the
    user polygons (MaskError naming a malformed one, before the stage starts)."""
    params = {"screening": asdict(options.screening), "scanned_film": options.scanned_film,
              "scan": asdict(options.scan) if options.scanned_film and options.scan is not None else None,
              "output_dir": output_dir}
    if options.sky_masks:
        params["sky"] = asdict(options.sky or SkyOptions())
    if options.mask_polygons:
        params["mask_polygons"] = dict(polygon_record(list(options.mask_polygons), options.mask_source),
                                       source=options.mask_source, y_axis=options.mask_y_axis)
    return params
