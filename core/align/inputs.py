"""What the alignment reads from the image folder before any work: the usable photos, their camera groups,
content fingerprints and given interior orientations."""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Dict, List, Sequence, Tuple

from ..common.progress import Progress, SubProgress
from ..io.control_place import positions_off, usable_gps
from ..io.gcp import read_camera_positions
from ..io.images import CameraGroup, ImageError, ImageInfo, group_cameras, scan_images
from ..project.layout import Layout
from .calibrated import GivenCamera, held_cameras, plan_cameras, scan_interior, source_label
from .options import AlignError, AlignOptions
from .pairs import photo_positions
from .photos import check_same_photos, fingerprint_photos


def read_images(images_dir: str, options: AlignOptions,
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


def check_positions_file(infos: Sequence[ImageInfo], path: str, progress: Progress) -> None:
    """A camera positions file given to the alignment (its positions choose the pairs), checked before any work:
    its rows that name a photo twice warned in the log; a file that names its CRS compared with the photos' EXIF
    GPS (``core.io.control_place``, the georeference stage's check: latitude and longitude swapped, another UTM
    zone), AlignError naming the file and the likely cause.  A file without a CRS line is read in the CRS given at
    Georeference: nothing to compare with yet."""
    said: List[str] = []
    crs = read_camera_positions(path, warnings=said)[0]
    for w in said:
        progress.warning(w)
    if crs:
        what = positions_off(usable_gps((im.name, im.gps) for im in infos), path, crs)
        if what:
            raise AlignError(what)


@dataclass
class Photos:
    """What the alignment reads from the image folder before any work."""

    images_dir: str
    infos: List[ImageInfo]
    skipped: List[str]
    groups: List[CameraGroup]
    fingerprints: Dict[str, str]  # image name -> content fingerprint (core.align.photos)
    seconds: float
    given: Dict[str, GivenCamera]  # group key -> its given interior orientation (core.align.calibrated)
    positions: Dict[str, Tuple[float, float]]  # image name -> horizontal position (core.align.pairs.photo_positions)

    def log_cameras(self, progress: Progress) -> None:
        """One line per camera: make, model, size, the focal length given or its prior, how many images."""
        for g in self.groups:
            given = self.given.get(g.key)
            focal = (f"focal {given.params[0]:.1f} px ({given.mode}, {source_label(given.source)})"
                     if given is not None else f"focal prior {g.focal_px:.1f} px ({g.focal_source})")
            progress.info(f"camera {g.camera_id}: {g.make} {g.model} {g.width}x{g.height}, {focal}, "
                          f"{len(g.images)} images")

    def held(self) -> Tuple[Dict[int, GivenCamera], bool]:
        """(camera id -> given, of the cameras the alignment holds; whether every camera is held)."""
        ids = held_cameras(self.groups, self.given)
        return ids, bool(ids) and len(ids) == len(self.groups)


def read_folder(pycolmap, lay: Layout, images_dir: str, options: AlignOptions, calibrations: list,
                 progress: Progress) -> Photos:
    """The usable photos of ``images_dir``, their fingerprints and their cameras' given interior orientations
    (a calibration file's, film scans' restituted by Prepare images); AlignError with fewer than two, or with a
    folder of other photos than those of the workspace's finished alignment (photos.check_same_photos)."""
    t0 = time.time()
    infos, skipped, groups = read_images(images_dir, options, progress)
    groups, given = plan_cameras(pycolmap, groups, infos, calibrations, scan_interior(lay.scans_json, infos),
                                 options, progress)
    positions = photo_positions(infos, options.camera_positions)
    if options.camera_positions:
        check_positions_file(infos, options.camera_positions, progress)
    prints = fingerprint_photos(infos)
    check_same_photos(lay.ws, images_dir, prints)  # another block's photos on a finished workspace: before any change
    return Photos(images_dir, infos, skipped, groups, prints, time.time() - t0, given, positions)
