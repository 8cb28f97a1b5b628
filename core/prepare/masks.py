"""Per-image masks: where they live, and user polygons rasterised into them.

A mask is ``<workspace>/masks/<image name>.png`` (the image's full file name,
extension included, plus ``.png``: ``IMG_0012.JPG`` -> ``IMG_0012.JPG.png``),
8-bit grey at the image's size, white (255) = use, black (0) = ignore.  That
is COLMAP's convention (``ImageReaderOptions.mask_path``: pixels of value 0
are ignored by feature extraction) and the one :mod:`core.prepare.scans` writes for
scanned film; :func:`find_mask` also accepts ``masks/<stem>.png`` and is the
lookup the alignment, the screening and the orthophoto stage share.

User masks are polygons meaning "ignore this area" (a boom, the drone's
shadow, a data strip, a date stamp), each in the pixel coordinates of an image:
origin at the upper-left corner of the upper-left pixel, x right, y down.  The
QGIS georeferencer shows a non-georeferenced image with y = -row (y up from the
top edge); that form is detected when every y is <= 0 (or chosen with
``y_axis``).  A polygon names its image, or applies to every image when the
name is empty.  A pixel is ignored when its centre lies inside a polygon
(even-odd rule across the polygon's rings: holes stay usable).  The polygons
are merged with any mask the image already has (logical AND of the areas to
use), and each mask is written atomically.

Plain Python + numpy + OpenCV: no qgis, no Qt.
"""
from __future__ import annotations

import math
import os
import struct
from dataclasses import dataclass, field
from typing import Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ..common.errors import ArchaeoOrthoError, require
from ..common.files import atomic_output
from ..io.images import image_size, list_images
from .options import Y_AXES

MASKS_DIR = "masks"

Ring = Sequence[Tuple[float, float]]


class MaskError(ArchaeoOrthoError, ValueError):
    """Masks cannot be made; the message names the polygon (or file) and the problem."""


# ---------------------------------------------------------------------------
# the naming convention
# ---------------------------------------------------------------------------

def mask_file_name(image_name: str) -> str:
    """``IMG_0012.JPG`` -> ``IMG_0012.JPG.png`` (COLMAP's ``<mask_path>/<image name>.png``)."""
    return image_name + ".png"


def find_mask(masks_dir: Optional[str], name: str) -> Optional[str]:
    """``masks/<image>.png`` (COLMAP's name, as core.prepare.scans writes them) or ``masks/<stem>.png``; None if there is
    none.  The one lookup the alignment, the screening and the orthophotos share."""
    if not masks_dir or not os.path.isdir(masks_dir):
        return None
    for cand in (mask_file_name(name), os.path.splitext(name)[0] + ".png"):
        p = os.path.join(masks_dir, cand)
        if os.path.isfile(p):
            return p
    return None


def png_size(path: str) -> Tuple[int, int]:
    """(width, height) from a PNG header, without decoding it; raises MaskError when it is not a PNG."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
    except OSError as e:
        raise MaskError(f"mask {path} cannot be read ({e.strerror or e})") from e
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise MaskError(f"mask {path} is not a PNG file")
    w, h = struct.unpack(">II", head[16:24])
    return int(w), int(h)


def read_keep(path: str, width: int, height: int) -> np.ndarray:
    """A mask file as a boolean array, True = use (grey >= 128); its size must be the image's."""
    cv2 = require("cv2", "image masks")

    m = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if m is None:
        raise MaskError(f"mask {path} cannot be read")
    if m.shape != (height, width):
        raise MaskError(f"mask {path} is {m.shape[1]} x {m.shape[0]} px but its image is {width} x {height} px")
    return m >= 128


def write_keep(path: str, keep: np.ndarray) -> None:
    """Write a keep-area (True = use) as a 0/255 PNG, atomically (temporary name, then rename)."""
    cv2 = require("cv2", "image masks")

    with atomic_output(path) as tmp:
        if not cv2.imwrite(tmp, np.where(keep, 255, 0).astype(np.uint8)):
            raise MaskError(f"mask {path} cannot be written")


def image_sizes(images_dir: str, names: Optional[Iterable[str]] = None) -> Dict[str, Tuple[int, int]]:
    """(width, height) of the images of a folder (headers only)."""
    return {n: image_size(os.path.join(images_dir, n))
            for n in (list(names) if names is not None else list_images(images_dir))}


# ---------------------------------------------------------------------------
# polygons
# ---------------------------------------------------------------------------

@dataclass
class MaskPolygon:
    """One polygon: exterior ring first, then holes, in pixel coordinates (y down once normalised)."""

    rings: List[np.ndarray]  # each (N, 2) float, not closed
    image: Optional[str] = None  # None = every image
    label: str = ""

    def bounds(self) -> Tuple[float, float, float, float]:
        a = self.rings[0]
        return float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 0].max()), float(a[:, 1].max())


@dataclass
class MaskResult:
    masks: Dict[str, str] = field(default_factory=dict)  # image -> mask file written
    ignored_fraction: Dict[str, float] = field(default_factory=dict)  # image -> share of pixels ignored
    polygons: Dict[str, int] = field(default_factory=dict)  # image -> user polygons applied
    warnings: List[str] = field(default_factory=list)
    y_axis: str = "down"


PolygonItem = Union[MaskPolygon, Tuple[Optional[str], Sequence[Ring]], Tuple[Optional[str], Sequence[Ring], str]]


def _ring(ring, where: str) -> np.ndarray:
    try:
        a = np.asarray(ring, dtype=float)
    except (TypeError, ValueError) as e:
        raise MaskError(f"{where}: not a polygon: a ring must be a list of (x, y) points") from e
    if a.ndim != 2 or a.shape[1] < 2:
        raise MaskError(f"{where}: not a polygon: a ring must be a list of (x, y) points")
    a = a[:, :2]
    if not np.all(np.isfinite(a)):
        raise MaskError(f"{where}: a coordinate is not a finite number")
    if len(a) >= 2 and np.array_equal(a[0], a[-1]):
        a = a[:-1]  # closed ring: drop the repeated first point
    if len(np.unique(a, axis=0)) < 3:
        raise MaskError(f"{where}: not a polygon: a ring has fewer than 3 distinct points (a point or a line)")
    return a


def _area(a: np.ndarray) -> float:
    x, y = a[:, 0], a[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def to_polygons(items: Iterable[PolygonItem], source: str = "mask polygons") -> List[MaskPolygon]:
    """Validate ``(image, rings[, label])`` items (or MaskPolygon) into MaskPolygons; raises MaskError."""
    out = []
    for i, item in enumerate(items):
        if isinstance(item, MaskPolygon):
            image, rings, label = item.image, item.rings, item.label
        else:
            if not isinstance(item, (tuple, list)) or len(item) not in (2, 3):
                raise MaskError(f"{source}: polygon {i + 1}: expected (image name, list of rings[, label])")
            image, rings = item[0], item[1]
            label = item[2] if len(item) == 3 else ""
        label = str(label or f"polygon {i + 1}")
        where = f"{source}: {label}"
        if image is not None and not isinstance(image, str):
            raise MaskError(f"{where}: the image name must be text, not {image!r}")
        image = (image or "").strip() or None
        if rings is None or isinstance(rings, (str, bytes)) or len(rings) == 0:
            raise MaskError(f"{where}: not a polygon: no rings (an empty geometry)")
        first = rings[0]
        if len(first) and np.isscalar(first[0]):
            raise MaskError(f"{where}: not a polygon: expected a list of rings, each a list of (x, y) points "
                            "(a point or a line was given)")
        arrs = [_ring(r, where) for r in rings]
        if abs(_area(arrs[0])) <= 0.0:
            raise MaskError(f"{where}: not a polygon: its outer ring has no area")
        out.append(MaskPolygon(arrs, image, label))
    return out


def detect_y_axis(polygons: Sequence[MaskPolygon]) -> str:
    """'up' (QGIS georeferencer: y = -row) when every y is <= 0 and some is < 0, else 'down'."""
    ys = [r[:, 1] for p in polygons for r in p.rings]
    if not ys:
        return "down"
    y = np.concatenate(ys)
    return "up" if (y.max() <= 0.0 and y.min() < 0.0) else "down"


def polygons_by_image(items: Iterable[PolygonItem], names: Sequence[str], aliases: Optional[Mapping[str, str]] = None,
                      source: str = "mask polygons", y_axis: str = "auto") -> Tuple[Dict[str, List[MaskPolygon]], str]:
    """The polygons each image gets, in y-down pixel coordinates, and the y axis used.

    ``names``: the images that masks are made for; ``aliases``: other names
    that mean one of them (the original name of a prepared scan).  An unknown
    image name raises MaskError naming the polygon and the name.
    """
    if y_axis not in Y_AXES:
        raise MaskError(f"unknown y axis {y_axis!r}; choose one of {', '.join(Y_AXES)}")
    polys = to_polygons(items, source)
    axis = detect_y_axis(polys) if y_axis == "auto" else y_axis
    if axis == "up":
        for p in polys:
            p.rings = [np.column_stack([r[:, 0], -r[:, 1]]) for r in p.rings]
    names = list(names)
    known = set(names)
    aliases = dict(aliases or {})
    by_lower = {}
    for n in list(names) + list(aliases):
        by_lower.setdefault(n.lower(), n)
    out: Dict[str, List[MaskPolygon]] = {}
    for p in polys:
        if p.image is None:
            for n in names:
                out.setdefault(n, []).append(p)
            continue
        n = p.image if (p.image in known or p.image in aliases) else by_lower.get(p.image.lower())
        if n is None:
            sample = ", ".join(names[:5]) + ("…" if len(names) > 5 else "")
            raise MaskError(f"{source}: {p.label}: unknown image {p.image!r} (the images are: {sample}); "
                            "leave the image name empty for a polygon that applies to every image")
        out.setdefault(aliases.get(n, n), []).append(p)
    return out, axis


def rasterise(polygons: Sequence[MaskPolygon], width: int, height: int) -> np.ndarray:
    """Boolean (height, width): True where a pixel's centre lies inside one of the polygons.

    Scanline fill with the even-odd rule inside each polygon (holes) and the
    union across polygons; coordinates are y-down pixel coordinates.
    """
    inside = np.zeros((height, width), bool)
    for p in polygons:
        x0 = np.concatenate([r[:, 0] for r in p.rings])
        y0 = np.concatenate([r[:, 1] for r in p.rings])
        x1 = np.concatenate([np.roll(r[:, 0], -1) for r in p.rings])
        y1 = np.concatenate([np.roll(r[:, 1], -1) for r in p.rings])
        flat = y0 == y1
        x0, y0, x1, y1 = x0[~flat], y0[~flat], x1[~flat], y1[~flat]
        if not len(x0):
            continue
        slope = (x1 - x0) / (y1 - y0)
        r_first = max(0, int(math.ceil(min(y0.min(), y1.min()) - 0.5)))
        r_last = min(height - 1, int(math.floor(max(y0.max(), y1.max()) - 0.5)))
        for r in range(r_first, r_last + 1):
            yc = r + 0.5
            cross = (y0 <= yc) != (y1 <= yc)  # half-open: a vertex on the scanline counts once
            if not cross.any():
                continue
            xs = np.sort(x0[cross] + (yc - y0[cross]) * slope[cross])
            # pixel c is inside when a <= c + 0.5 < b
            starts = np.clip(np.ceil(xs[0::2] - 0.5), 0, width).astype(np.int64)
            ends = np.clip(np.ceil(xs[1::2] - 0.5), 0, width).astype(np.int64)
            row = inside[r]
            for a, b in zip(starts, ends):
                if b > a:
                    row[a:b] = True
    return inside


def build_masks(by_image: Mapping[str, Sequence[MaskPolygon]], sizes: Mapping[str, Tuple[int, int]], out_dir: str,
                base_masks: Optional[Mapping[str, Union[str, Sequence[str]]]] = None,
                source: str = "mask polygons") -> MaskResult:
    """Write ``<out_dir>/<image>.png`` for every image with polygons or base masks.

    Each mask = (AND of the base masks' areas to use) minus the polygons.
    ``sizes``: (width, height) per image.  A polygon for one image that lies
    entirely outside it raises MaskError; one for every image is an error only
    when it lies outside all of them (a warning names the others).
    """
    base_masks = dict(base_masks or {})
    res = MaskResult()
    targets = sorted(set(by_image) | set(base_masks))
    missing = [n for n in targets if n not in sizes]
    if missing:
        raise MaskError(f"{source}: no image size for {', '.join(missing[:5])}")
    # outside checks first: nothing is written when a polygon is wrong
    outside: Dict[int, List[str]] = {}
    applied: Dict[int, List[str]] = {}
    poly_of: Dict[int, MaskPolygon] = {}
    for n in targets:
        w, h = sizes[n]
        for p in by_image.get(n, ()):
            poly_of[id(p)] = p
            applied.setdefault(id(p), []).append(n)
            xmin, ymin, xmax, ymax = p.bounds()
            if xmax <= 0 or ymax <= 0 or xmin >= w or ymin >= h:
                outside.setdefault(id(p), []).append(n)
    for pid, out_names in outside.items():
        p = poly_of[pid]
        xmin, ymin, xmax, ymax = p.bounds()
        n0 = out_names[0]
        w, h = sizes[n0]
        if p.image is not None or len(out_names) == len(applied[pid]):
            which = f"image {n0} ({w} x {h} px)" if p.image is not None else f"every image (e.g. {n0}, {w} x {h} px)"
            raise MaskError(
                f"{source}: {p.label}: the polygon lies entirely outside {which}: "
                f"x {xmin:g} to {xmax:g}, y {ymin:g} to {ymax:g} (pixel coordinates: origin at the upper-left "
                "corner, x right, y down; or y = -row as the QGIS georeferencer shows an image)")
        res.warnings.append(f"{source}: {p.label}: the polygon lies outside {len(out_names)} of "
                            f"{len(applied[pid])} images ({', '.join(out_names[:5])})")
    os.makedirs(out_dir, exist_ok=True)
    for n in targets:
        w, h = sizes[n]
        keep = np.ones((h, w), bool)
        bases = base_masks.get(n) or ()
        for b in ([bases] if isinstance(bases, str) else list(bases)):
            if b:
                keep &= read_keep(b, w, h)
        polys = list(by_image.get(n, ()))
        if polys:
            keep &= ~rasterise(polys, w, h)
        path = os.path.join(out_dir, mask_file_name(n))
        write_keep(path, keep)
        res.masks[n] = path
        res.polygons[n] = len(polys)
        res.ignored_fraction[n] = 1.0 - float(keep.mean()) if keep.size else 1.0
        if not keep.any():
            res.warnings.append(f"the mask of {n} hides the whole image: no feature can be found in it")
    return res


def write_user_masks(items: Iterable[PolygonItem], sizes: Mapping[str, Tuple[int, int]], masks_dir: str,
                     aliases: Optional[Mapping[str, str]] = None, source: str = "mask polygons",
                     y_axis: str = "auto", merge_existing: bool = True) -> MaskResult:
    """Rasterise "ignore" polygons into ``<masks_dir>/<image>.png``, merged with the masks already there.

    ``items``: ``(image name or None/"" for every image, [exterior ring, hole, ...][, label])``
    with rings as lists of (x, y) pixel coordinates.  ``sizes``: (width, height)
    per image (:func:`image_sizes` reads them from a folder).  Raises MaskError.
    """
    by_image, axis = polygons_by_image(items, list(sizes), aliases, source, y_axis)
    bases = {}
    if merge_existing:
        for n in by_image:
            p = find_mask(masks_dir, n)
            if p:
                bases[n] = p
    res = build_masks(by_image, sizes, masks_dir, bases, source)
    res.y_axis = axis
    return res
