"""Image reading, grey conversion, EXIF camera priors and GPS, camera groups.

Images are read through GDAL (JPEG, TIFF 8/16-bit, RGB, single-band NIR or
grey).  Everything here is plain Python + GDAL + numpy: no qgis, no Qt.
"""
from __future__ import annotations

import hashlib
import math
import os
import re
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from .raster import RasterError, RasterFile

IMAGE_EXTENSIONS = (".jpg", ".jpeg", ".tif", ".tiff", ".png")

# one camera per distinct (make, model, focal, size) / one for all / one per image
GROUP_AUTO = "auto"
GROUP_SINGLE = "single"
GROUP_PER_IMAGE = "per_image"

# m: the horizontal error of consumer GNSS in EXIF GPS: the a priori sigma of EXIF GPS camera positions
# (core.georef.options.EXIF_SIGMA_XY) and the GPS error allowed when control is compared with it (core.io.control_place)
EXIF_GPS_SIGMA_XY = 3.0

FULL_FRAME_DIAGONAL_MM = math.hypot(36.0, 24.0)
DEFAULT_FOCAL_FACTOR = 1.2  # focal = 1.2 x long side when nothing is known (COLMAP's guess)


class ImageError(ArchaeoOrthoError, ValueError):
    """An image that cannot be used; the message names the file and the problem."""


@dataclass
class ImageInfo:
    name: str  # file name relative to the images folder
    path: str
    width: int
    height: int
    bands: int
    dtype: str
    make: str = ""
    model: str = ""
    focal_mm: Optional[float] = None
    focal_35mm: Optional[float] = None
    focal_px: Optional[float] = None  # best prior for the focal length in pixels
    focal_source: str = "default"  # exif35 / exif_plane / manual / default
    gps: Optional[Tuple[float, float, float]] = None  # lon, lat, ellipsoidal(ish) alt (WGS84)
    orientation: int = 1  # EXIF orientation (1-8): how a photo viewer turns the stored grid; see ORIENTATION_STEPS
    # the band (1-based) features and dense matching are taken from, where the photo names one (a multispectral
    # capture's stacked photo: PRIMARY_BAND, core.prepare.captures); 0 = the photo's grey (see to_grey)
    primary_band: int = 0

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gps"] = list(self.gps) if self.gps else None
        return d

    @classmethod
    def from_dict(cls, d: dict) -> ImageInfo:
        d = dict(d)
        if d.get("gps"):
            d["gps"] = tuple(d["gps"])
        return cls(**d)


@dataclass
class CameraGroup:
    camera_id: int
    key: str
    make: str
    model: str
    width: int
    height: int
    focal_px: float
    focal_source: str
    images: List[str] = field(default_factory=list)


def _gdal():
    from osgeo import gdal

    gdal.UseExceptions()
    return gdal


def _rational(value: str) -> List[float]:
    """Parse GDAL's EXIF rationals: '(3.61)' or '(41) (32) (57.8681)'."""
    nums = re.findall(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?", value or "")
    return [float(n) for n in nums]


def _dms(value: str, ref: str) -> Optional[float]:
    parts = _rational(value)
    if not parts:
        return None
    deg = parts[0] + (parts[1] / 60.0 if len(parts) > 1 else 0.0) + (parts[2] / 3600.0 if len(parts) > 2 else 0.0)
    if ref.strip().upper() in ("S", "W"):
        deg = -deg
    return deg


def check_image_folder(folder: str, what: str = "image folder") -> None:
    """ImageError unless ``folder`` is a readable folder; the message says which of the three it is not."""
    if not folder or not os.path.exists(folder):
        raise ImageError(f"{what} {folder} does not exist")
    if not os.path.isdir(folder):
        raise ImageError(f"{what} {folder} is a file, not a folder: give the folder that holds the photos")
    if not os.access(folder, os.R_OK | os.X_OK):
        raise ImageError(f"{what} {folder} cannot be read (permission denied)")


def require_images(folder: str, what: str = "image folder") -> List[str]:
    """:func:`list_images`, ImageError when the folder holds none (before a workspace is created for it)."""
    names = list_images(folder)
    if not names:
        others = [n for n in os.listdir(folder) if not n.startswith(".")]
        raise ImageError(f"{what} {folder} holds no readable images ({', '.join(IMAGE_EXTENSIONS)})"
                         + (f": its {len(others)} entries are other files or folders (e.g. {others[0]})" if others
                            else ": it is empty") + "; give the folder that holds the photos")
    return names


def list_images(folder: str) -> List[str]:
    """Names (relative to ``folder``) of files with an image extension, sorted; no recursion."""
    check_image_folder(folder)
    return sorted(
        n for n in os.listdir(folder)
        if n.lower().endswith(IMAGE_EXTENSIONS) and os.path.isfile(os.path.join(folder, n))
    )


def read_image_info(path: str, name: Optional[str] = None, manual_focal_mm: Optional[float] = None,
                    manual_sensor_width_mm: Optional[float] = None,
                    manual_focal_px: Optional[float] = None) -> ImageInfo:
    """Open the image header, check that its pixels decode (:func:`check_image`), read EXIF.  Raises ImageError."""
    gdal = _gdal()
    name = name or os.path.basename(path)
    with _checked_file(path) as r:
        w, h, nb = r.width, r.height, r.count
        dtype = gdal.GetDataTypeName(r.band(1).DataType)
        md = photo_metadata(r)
        primary = _primary_band(r, md)
    info = ImageInfo(name=name, path=os.path.abspath(path), width=w, height=h, bands=nb, dtype=dtype,
                     primary_band=primary)
    info.make = md.get("EXIF_Make", "").strip().strip("\x00")
    info.model = md.get("EXIF_Model", "").strip().strip("\x00")
    fmm = _rational(md.get("EXIF_FocalLength", ""))
    info.focal_mm = fmm[0] if fmm and fmm[0] > 0 else None
    f35 = _rational(md.get("EXIF_FocalLengthIn35mmFilm", ""))
    info.focal_35mm = f35[0] if f35 and f35[0] > 0 else None
    info.orientation = _orientation_value(md.get("EXIF_Orientation"))
    info.focal_px, info.focal_source = _focal_prior(info, md, manual_focal_mm, manual_sensor_width_mm, manual_focal_px)
    info.gps = _exif_gps(md)
    return info


def _exif_gps(md: Dict[str, str]) -> Optional[Tuple[float, float, float]]:
    """(lon, lat, alt) of a photo's EXIF GPS tags (its metadata, :func:`photo_metadata`); None without (0, 0: none)."""
    lat = _dms(md.get("EXIF_GPSLatitude", ""), md.get("EXIF_GPSLatitudeRef", "N"))
    lon = _dms(md.get("EXIF_GPSLongitude", ""), md.get("EXIF_GPSLongitudeRef", "E"))
    if lat is None or lon is None or (abs(lat) <= 1e-9 and abs(lon) <= 1e-9):
        return None
    alt_v = _rational(md.get("EXIF_GPSAltitude", ""))
    alt = alt_v[0] if alt_v else 0.0
    if md.get("EXIF_GPSAltitudeRef", "0x00").strip() in ("0x01", "1"):
        alt = -alt
    return lon, lat, alt


def folder_gps(folder: str) -> Dict[str, Tuple[float, float, float]]:
    """{name: (lon, lat, alt)} of the photos of ``folder`` (:func:`list_images`) that carry EXIF GPS, read from
    their headers only (no pixel decoded: a second for hundreds of photos), for the checks made before the
    alignment reads them; a photo GDAL cannot open is left out here (the alignment names it)."""
    out: Dict[str, Tuple[float, float, float]] = {}
    for name in list_images(folder):
        try:
            gps = photo_gps(os.path.join(folder, name))
        except ImageError:
            continue  # named by the alignment, which skips it
        if gps is not None:
            out[name] = gps
    return out


def photo_gps(path: str) -> Optional[Tuple[float, float, float]]:
    """(lon, lat, alt) of a photo's EXIF GPS read from its header (no pixel decoded); None without.  ImageError
    naming the file when GDAL cannot open it."""
    with open_image(path) as r:
        return _exif_gps(photo_metadata(r))


# --------------------------------------------------------------------------------------------------
# EXIF orientation
#
# The one convention: every pixel coordinate the plugin stores (GCP observations, COLMAP's keypoints,
# georef/control.json) is in the STORED pixel grid, the raster as written in the file (COLMAP's grid, EXIF
# orientation not applied).  A photo viewer (a browser, the GCP dock) shows the photo UPRIGHT: the stored grid
# turned by the EXIF orientation tag.  The functions below convert between the two; both use the pixel
# convention of core.io.gcp (origin at the upper-left corner of the upper-left pixel, x right, y down), and
# ``width``, ``height`` are always the STORED size.
# --------------------------------------------------------------------------------------------------

# EXIF orientation -> (degrees clockwise, then mirror left-right, then mirror top-bottom) that turn the stored
# grid upright (the EXIF 2.3 definitions: 6 = "the 0th row is the visual right-hand side", shown by a 90 degree
# clockwise turn, as cameras held in portrait write it; 8 = 270 degrees clockwise)
ORIENTATION_STEPS: Dict[int, Tuple[int, bool, bool]] = {
    1: (0, False, False), 2: (0, True, False), 3: (180, False, False), 4: (0, False, True),
    5: (90, True, False), 6: (90, False, False), 7: (90, False, True), 8: (270, False, False)}


def _orientation_value(text: Optional[str]) -> int:
    try:
        value = int(str(text).strip().strip("\x00")) if text is not None else 1
    except ValueError:
        return 1
    return value if value in ORIENTATION_STEPS else 1


def photo_metadata(r: RasterFile) -> Dict[str, str]:
    """A photo's metadata with its EXIF tags: GDAL shows a JPEG's EXIF in the default domain and a TIFF's (the
    band files of multispectral cameras: Parrot Sequoia, MicaSense, DJI P4M) only in the ``EXIF`` domain; the
    default domain's value wins where both have a key."""
    md = dict(r.metadata(domain="EXIF"))
    md.update(r.metadata())
    return md


PRIMARY_BAND = "PRIMARY_BAND"  # a photo's metadata item naming (by its description) the band to match on


def _primary_band(r: RasterFile, md: Dict[str, str]) -> int:
    """The 1-based band the photo's PRIMARY_BAND item names, 0 when it names none (or no band of the photo)."""
    name = md.get(PRIMARY_BAND, "").strip()
    if not name or r.count < 2:
        return 0
    for i in range(1, r.count + 1):
        if r.band(i).GetDescription().strip() == name:
            return i
    return 0


def primary_band(path: str) -> int:
    """The 1-based band of ``path`` its PRIMARY_BAND item names (0: none); reads the header only."""
    with open_image(path) as r:
        return _primary_band(r, photo_metadata(r))


def matching_grey8(arr: np.ndarray, band: int = 0) -> np.ndarray:
    """(rows, cols[, bands]) pixels -> the 8-bit grey that features and dense matching see: the photo's primary
    ``band`` (1-based) where it names one, else its grey (three bands or more: Rec. 601 luminance, else the first
    band); values other than 8-bit stretched from their 0.5 to 99.5 percentile to 0..255 (a 16-bit band
    photo's values fill a few hundredths of the 16-bit range)."""
    a = np.asarray(arr)
    if a.ndim == 3 and band and band <= a.shape[2]:
        a = a[:, :, band - 1]
    if a.ndim == 3:
        if a.shape[2] >= 3:  # float32 throughout (a 20 MP 16-bit photo: no float64 copies)
            g = a[:, :, 0].astype(np.float32) * np.float32(0.299)
            g += a[:, :, 1].astype(np.float32) * np.float32(0.587)
            g += a[:, :, 2].astype(np.float32) * np.float32(0.114)
            if a.dtype == np.uint8:
                return np.clip(np.rint(g), 0, 255).astype(np.uint8)
        else:
            g = a[:, :, 0]
    else:
        g = a
    if g.dtype == np.uint8:
        return np.ascontiguousarray(g)
    return stretch8(g)


def stretch8(values: np.ndarray) -> np.ndarray:
    """(rows, cols[, bands]) values other than 8-bit -> uint8, stretched from their 0.5 to their 99.5 percentile
    (taken over about 4 million values at most, NaN left out) to 0..255; NaN (a float photo's no data) 0."""
    g = np.asarray(values).astype(np.float32, copy=False)
    step = max(1, int(np.sqrt(g.shape[0] * g.shape[1] / 4e6)))
    sample = g[::step, ::step]
    sample = sample[np.isfinite(sample)]
    lo, hi = (float(v) for v in np.percentile(sample, [0.5, 99.5])) if sample.size else (0.0, 1.0)
    out = (np.nan_to_num(g, nan=lo) - np.float32(lo)) * np.float32(255.0 / max(hi - lo, 1e-6))
    return np.ascontiguousarray(np.clip(out, 0, 255).astype(np.uint8))


def read_matching_grey8(path: str, band: int = 0, max_size: Optional[int] = None) -> np.ndarray:
    """:func:`matching_grey8` of the photo ``path``: its ``band`` (1-based) alone where given, else every band;
    read downscaled (GDAL average) to ``max_size`` px on its long side when larger.  ImageError naming the file
    when it cannot be read."""
    with open_image(path) as r:
        shape = None
        if max_size and max(r.width, r.height) > max_size:
            s = max_size / max(r.width, r.height)
            shape = (max(1, round(r.height * s)), max(1, round(r.width * s)))
        if band:
            return matching_grey8(r.read(band, out_shape=shape, resampling="average"))
        return matching_grey8(np.moveaxis(r.read_bands(out_shape=shape, resampling="average"), 0, -1))


def exif_orientation(path: str) -> int:
    """The EXIF orientation (1-8) of a photo, 1 when it has none or an invalid one; reads the header only.
    ImageError naming the file when it cannot be opened."""
    with open_image(path) as r:
        return _orientation_value(photo_metadata(r).get("EXIF_Orientation"))


XMP_SCAN_BYTES = 262144  # the XMP packet of a drone photo sits in its first APP1 segments (DJI: within 64 KiB)
_PITCH_RE = re.compile(rb"(?:Gimbal|Camera)PitchDegree(?:\s*=\s*[\"']|>)\s*([-+]?\d+(?:\.\d+)?)")


def xmp_camera_pitch(path: str) -> Optional[float]:
    """The camera's pitch in degrees above the horizontal (-90: straight down) as a drone writes it in the XMP
    packet (DJI ``drone-dji:GimbalPitchDegree``, Parrot ``CameraPitchDegree``); None when the photo has none.
    Reads the first ``XMP_SCAN_BYTES`` of the file; OSError when it cannot be read."""
    with open(path, "rb") as f:
        head = f.read(XMP_SCAN_BYTES)
    m = _PITCH_RE.search(head)
    if not m:
        return None
    value = float(m.group(1))
    return value if -180.0 <= value <= 180.0 else None


def _check_orientation(orientation: int) -> int:
    o = int(orientation)
    if o not in ORIENTATION_STEPS:
        raise ValueError(f"EXIF orientation must be 1-8, got {orientation!r}")
    return o


def upright_size(orientation: int, width: int, height: int) -> Tuple[int, int]:
    """(width, height) of the upright photo whose stored grid is ``width`` x ``height``."""
    turn = ORIENTATION_STEPS[_check_orientation(orientation)][0]
    return (height, width) if turn in (90, 270) else (width, height)


def orientation_matrix(orientation: int, width: int, height: int) -> np.ndarray:
    """3 x 3 matrix taking stored pixel coordinates (x, y, 1) to upright ones (exact: a signed permutation plus
    a shift)."""
    turn, mirror_lr, mirror_tb = ORIENTATION_STEPS[_check_orientation(orientation)]
    w, h = float(width), float(height)
    m = np.eye(3)
    if turn == 90:  # (x, y) -> (h - y, x)
        m = np.array([[0.0, -1.0, h], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    elif turn == 180:
        m = np.array([[-1.0, 0.0, w], [0.0, -1.0, h], [0.0, 0.0, 1.0]])
    elif turn == 270:  # (x, y) -> (y, w - x)
        m = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, w], [0.0, 0.0, 1.0]])
    uw, uh = upright_size(orientation, width, height)
    if mirror_lr:
        m = np.array([[-1.0, 0.0, float(uw)], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) @ m
    if mirror_tb:
        m = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, float(uh)], [0.0, 0.0, 1.0]]) @ m
    return m


def _apply(m: np.ndarray, x, y):
    xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    u = m[0, 0] * xa + m[0, 1] * ya + m[0, 2]
    v = m[1, 0] * xa + m[1, 1] * ya + m[1, 2]
    if u.ndim == 0:
        return float(u), float(v)
    return u, v


def stored_to_upright(x, y, orientation: int, width: int, height: int):
    """Upright pixel coordinates of stored ones (floats or arrays) in a photo stored ``width`` x ``height``."""
    return _apply(orientation_matrix(orientation, width, height), x, y)


def upright_to_stored(x, y, orientation: int, width: int, height: int):
    """Stored pixel coordinates of upright ones (as measured on the photo a viewer shows); ``width``, ``height``:
    the STORED size."""
    return _apply(np.linalg.inv(orientation_matrix(orientation, width, height)), x, y)


def to_upright(arr: np.ndarray, orientation: int) -> np.ndarray:
    """The stored raster ``arr`` (rows, cols[, bands]) turned upright, as a photo viewer shows it."""
    turn, mirror_lr, mirror_tb = ORIENTATION_STEPS[_check_orientation(orientation)]
    out = np.rot90(arr, k=-(turn // 90), axes=(0, 1)) if turn else arr
    if mirror_lr:
        out = out[:, ::-1]
    if mirror_tb:
        out = out[::-1]
    return np.ascontiguousarray(out)


def _checked_file(path: str) -> RasterFile:
    """The opened photo (:class:`core.io.raster.RasterFile`) whose pixels decode to the last row; ImageError naming
    the file and the problem otherwise (see :func:`check_image`)."""
    gdal = _gdal()
    if not os.path.exists(path):
        raise ImageError(f"{path}: the photo does not exist")
    if os.path.isdir(path):
        raise ImageError(f"{path}: a folder, not an image file")
    if os.path.getsize(path) == 0:
        raise ImageError(f"{path}: empty file (0 bytes)")
    r = open_image(path)
    w, h = r.width, r.height
    # decode a strip at the bottom: a JPEG decodes sequentially, so this decodes the whole scan and a truncated
    # JPEG fails there (libjpeg only warns unless told); a truncated TIFF fails on its last strip or tile
    old = gdal.GetConfigOption("GDAL_ERROR_ON_LIBJPEG_WARNING")
    gdal.SetConfigOption("GDAL_ERROR_ON_LIBJPEG_WARNING", "TRUE")
    try:
        for b in range(1, r.count + 1):
            r.read(b, (0, max(0, h - 8), w, min(8, h)))
    except RasterError as e:
        r.close()
        raise ImageError(f"{path}: image data is corrupt or truncated ({_gdal_reason(e)})") from e
    finally:
        gdal.SetConfigOption("GDAL_ERROR_ON_LIBJPEG_WARNING", old)
    return r


def _gdal_reason(e: RasterError) -> str:
    """GDAL's own words in a RasterError (its cause), else the error's message."""
    return str(e.__cause__ or e).strip()


def open_image(path: str) -> RasterFile:
    """The image file opened (:class:`core.io.raster.RasterFile`, a context manager); ImageError naming the file
    when GDAL cannot read it."""
    try:
        return RasterFile(path, "image")
    except RasterError as e:
        reason = _gdal_reason(e) if e.__cause__ is not None else ""
        raise ImageError(f"{path}: not a readable image" + (f" ({reason})" if reason else "")) from e


def image_size(path: str) -> Tuple[int, int]:
    """(width, height) of an image file from its header; ImageError naming the file when GDAL cannot read it."""
    with open_image(path) as r:
        return r.width, r.height


def check_image(path: str) -> None:
    """The one check of a photo before its pixels are used (alignment, DSM, orthophoto, Orthorectify image):
    the file exists, is not empty, GDAL opens it and its pixels decode to the last row (a truncated or corrupt
    JPEG or TIFF fails).  Raises ImageError naming the file and the problem."""
    _checked_file(path).close()


PHOTO_BLOCK = 65536  # bytes hashed at the start, the middle and the end of a photo


def photo_fingerprint(path: str) -> str:
    """The content fingerprint of a photo: its size and a hash of three 64 KiB blocks (start, middle, end).

    Another photo under the same name differs in its EXIF block (time, exposure) and in its compressed
    pixels; the modification time is left out, so a copy of the folder (``cp -p`` or not, another disk)
    keeps the fingerprints.  OSError when the file cannot be read."""
    size = os.path.getsize(path)
    h = hashlib.sha1()
    with open(path, "rb") as f:
        for start in sorted({0, max(0, size // 2 - PHOTO_BLOCK // 2), max(0, size - PHOTO_BLOCK)}):
            f.seek(start)
            h.update(f.read(PHOTO_BLOCK))
    return f"{size}:{h.hexdigest()[:20]}"


def _focal_prior(info: ImageInfo, md: dict, manual_focal_mm, manual_sensor_width_mm, manual_focal_px):
    w, h = info.width, info.height
    long_side = max(w, h)
    if manual_focal_px:
        return float(manual_focal_px), "manual"
    if manual_focal_mm and manual_sensor_width_mm:
        # sensor width is the long side of the frame as scanned/recorded
        return float(manual_focal_mm) / float(manual_sensor_width_mm) * long_side, "manual"
    if info.focal_35mm:
        diag = math.hypot(w, h)
        return info.focal_35mm / FULL_FRAME_DIAGONAL_MM * diag, "exif35"
    if info.focal_mm:
        res = _rational(md.get("EXIF_FocalPlaneXResolution", ""))
        unit = md.get("EXIF_FocalPlaneResolutionUnit", "2").strip()
        orig_w = _rational(md.get("EXIF_PixelXDimension", ""))
        if res and res[0] > 0 and orig_w and orig_w[0] > 0:
            mm_per_unit = {"2": 25.4, "3": 10.0, "4": 1.0}.get(unit, 25.4)
            px_per_mm = res[0] / mm_per_unit
            f_orig = info.focal_mm * px_per_mm
            ow = orig_w[0]
            oh = (_rational(md.get("EXIF_PixelYDimension", "")) or [0])[0]
            # the stored image may have been resized: scale by the long side if the aspect matches
            if oh and abs(ow / oh - w / h) < 0.02:
                return f_orig * w / ow, "exif_plane"
    return DEFAULT_FOCAL_FACTOR * long_side, "default"


def scan_images(folder: str, manual_focal_mm: Optional[float] = None,
                manual_sensor_width_mm: Optional[float] = None,
                manual_focal_px: Optional[float] = None,
                progress=None) -> Tuple[List[ImageInfo], List[str]]:
    """Read every image in ``folder``.  Returns (usable images, warnings naming skipped files)."""
    check_image_folder(folder)
    names = sorted(n for n in os.listdir(folder) if os.path.isfile(os.path.join(folder, n)))
    good: List[ImageInfo] = []
    warnings: List[str] = []
    for i, n in enumerate(names):
        path = os.path.join(folder, n)
        if n.startswith("."):
            continue
        if not n.lower().endswith(IMAGE_EXTENSIONS):
            warnings.append(f"{path}: skipped, not an image file (extension)")
            continue
        try:
            good.append(read_image_info(path, n, manual_focal_mm, manual_sensor_width_mm, manual_focal_px))
        except ImageError as e:
            warnings.append(f"skipped {e}")
        if progress is not None:
            progress.report((i + 1) / max(1, len(names)), "reading images")
    return good, warnings


def group_cameras(images: Sequence[ImageInfo], mode: str = GROUP_AUTO) -> List[CameraGroup]:
    """One camera per distinct (make, model, focal, image size), or one for all, or one per image."""
    groups: Dict[str, CameraGroup] = {}
    for im in images:
        if mode == GROUP_SINGLE:
            key = "all"
        elif mode == GROUP_PER_IMAGE:
            key = im.name
        else:
            key = f"{im.make}|{im.model}|{round(im.focal_px or 0, 1)}|{im.width}x{im.height}"
        g = groups.get(key)
        if g is None:
            g = CameraGroup(camera_id=len(groups) + 1, key=key, make=im.make, model=im.model,
                            width=im.width, height=im.height, focal_px=float(im.focal_px or 0),
                            focal_source=im.focal_source)
            groups[key] = g
        elif mode == GROUP_SINGLE and (im.width, im.height) != (g.width, g.height):
            raise ImageError(
                f"{im.path}: size {im.width}x{im.height} differs from {g.width}x{g.height}; "
                "one camera for all images needs images of one size"
            )
        g.images.append(im.name)
    return list(groups.values())


def read_image(path: str, max_size: Optional[int] = None) -> np.ndarray:
    """Pixels as (rows, cols, bands) array in the file's data type, optionally downscaled."""
    with open_image(path) as r:
        w, h = r.width, r.height
        if max_size and max(w, h) > max_size:
            s = max_size / max(w, h)
            arr = r.read_bands(out_shape=(max(1, round(h * s)), max(1, round(w * s))), resampling="average")
        else:
            arr = r.read_bands()
    return np.moveaxis(arr, 0, -1)


def full_scale(arr: np.ndarray) -> float:
    """The value that means "white" for this array: 255 for 8-bit, 2^k - 1 for 16-bit, 1 for floats <= 1."""
    if arr.dtype == np.uint8:
        return 255.0
    mx = float(np.nanmax(arr)) if arr.size else 1.0
    if np.issubdtype(arr.dtype, np.integer):
        bits = max(8, int(np.ceil(np.log2(mx + 1.0)))) if mx > 0 else 8
        for b in (8, 10, 12, 14, 16):  # camera and scanner bit depths
            if bits <= b:
                return float(2 ** b - 1)
        return float(2 ** bits - 1)
    return 1.0 if mx <= 1.0 else mx


def to_grey(arr: np.ndarray, scale: Optional[float] = None) -> np.ndarray:
    """(rows, cols[, bands]) pixels -> float32 grey in [0, 1].

    Three or more bands are read as R, G, B (GDAL band order) with Rec. 601
    weights; one or two bands use the first band (grey, NIR).
    """
    a = np.asarray(arr)
    scale = float(scale or full_scale(a))
    if a.ndim == 3 and a.shape[2] >= 3:
        g = (0.299 * a[:, :, 0].astype(np.float32) + 0.587 * a[:, :, 1].astype(np.float32)
             + 0.114 * a[:, :, 2].astype(np.float32))
    elif a.ndim == 3:
        g = a[:, :, 0].astype(np.float32)
    else:
        g = a.astype(np.float32)
    return g / np.float32(scale)
