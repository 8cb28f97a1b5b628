"""Multispectral and NIR rigs (issue 37): a band file's metadata, the captures of a block, the primary band.

A multispectral rig (Parrot Sequoia, MicaSense RedEdge / Altum, DJI P4 Multispectral / Mavic 3M) writes one file
per band per capture; each file says in its XMP packet which band it is, which camera of the rig took it, which
capture it belongs to, its lens model and its radiometric calibration.  :func:`read_band_info` reads that into a
typed :class:`BandInfo` (a field a file does not carry is None: nothing is guessed); :func:`read_block` groups
band files into :class:`Capture` objects and checks the block (:class:`MultispectralError` for what cannot be
built, warning lines for what is built with less); :func:`primary_band` picks the band the geometry is built on.

Tag names, checked against (public material, read for this module; no code copied):
- Pix4D "Specifications of XMP Camera tags" (namespace ``Camera``, http://pix4d.com/camera/1.0/): ModelType,
  PrincipalPoint (mm), PerspectiveFocalLength (mm), PerspectiveDistortion (R1, R2, R3, T1, T2),
  FisheyeAffineMatrix (C, D, E, F), FisheyePolynomial, RigName, RigCameraIndex, RigRelatives (rotation from the
  rig's reference camera, degrees), CaptureUUID, BandName / CentralWavelength / WavelengthFWHM / BlackCurrent
  (rdf:Seq, one item per band);
- OpenDroneMap ``opendm/photo.py`` (reads all three vendors): capture id from ``drone-dji:CaptureUUID``,
  ``MicaSense:CaptureId``, ``Camera:CaptureUUID``; ``Camera:VignettingCenter`` / ``VignettingPolynomial``;
  ``Camera:Irradiance`` / ``SpectralIrradiance`` / ``HorizontalIrradiance`` / ``IrradianceScaleToSIUnits``;
  (``Camera:BlackLevel`` for MicaSense and DJI is read as the issue names it; the sources above give their black
  level in EXIF ``BlackLevel``, which is read too when GDAL shows it as ``EXIF_BlackLevel``);
  ``drone-dji:SensorGain`` / ``SensorGainAdjustment``; and ``opendm/multispectral.py`` (its primary band rule);
- MicaSense ``imageprocessing/micasense/metadata.py``: ``XMP:CaptureId``, ``PrincipalPoint`` (mm),
  ``PerspectiveFocalLength`` with ``PerspectiveFocalLengthUnits``, ``PerspectiveDistortion``, EXIF
  ``BlackLevel`` (mean of its values), gain = ISO / 100 (not applied here: ``iso`` is kept as read);
- DJI "P4 Multispectral Image Processing Guide" (v1.0 2020.07): ``drone-dji:CalibratedOpticalCenterX/Y``
  (vignetting centre, px), ``VignettingData`` (k0..k5 of a polynomial in the radius in px), ``DewarpData``
  ("date;fx,fy,cx,cy,k1,k2,p1,p2,k3", cx / cy relative to the optical centre), ``Irradiance``,
  ``SensorGain``, ``SensorGainAdjustment``, ``ExposureTime`` (microseconds), black level 4096 (EXIF);
- Sequoia ``IrradianceList``: base64 of little-endian records ``uint64 timestamp (us), uint16 CH0, uint16 CH1,
  uint16 gain index, uint16 integration time (ms), float yaw, pitch, roll`` (28 bytes), the layout given on
  Parrot's developer forum ("details of irradiance list tag for sunshine sensor", quoted in public scripts that
  decode it with ``struct.iter_unpack("qHHHHfff", ...)``).

``LineReadoutTime`` is kept as the number written: the material above gives no unit (the Sequoia writes 23076 on
its 1280 x 960 band cameras and 47500 on its 4608 x 3456 RGB camera).

Pure: the standard library, NumPy and GDAL (through :class:`core.io.raster.RasterFile`); no qgis, no Qt.
"""
from __future__ import annotations

import base64
import binascii
import os
import re
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.files import atomic_output
from .images import IMAGE_EXTENSIONS, XMP_SCAN_BYTES, photo_metadata
from .raster import RasterError, RasterFile


class MultispectralError(ArchaeoOrthoError, ValueError):
    """A set of band files that cannot be used as it is; the message names the files and the problem."""


# XMP namespaces by a piece of their URI -> the prefix the vendors write (the prefix in a file may differ)
NAMESPACES = (("pix4d.com/camera", "Camera"), ("dji.com/drone-dji", "drone-dji"),
              ("micasense.com/MicaSense", "MicaSense"), ("micasense.com/DLS", "DLS"),
              ("ns.sensefly.com", "sensefly"), ("www.w3.org/1999/02/22-rdf-syntax-ns", "rdf"))
RDF = "{http://www.w3.org/1999/02/22-rdf-syntax-ns#}"

# a file stamped within this many seconds of a capture of its rig belongs to it when it carries no capture id.
# The Sequoia sample's RGB frame (no CaptureUUID) is stamped 68 ms after its four band frames, which spread over
# 10 ms; a rig triggered at most a few times a second keeps its captures well over 0.1 s apart (not checked
# here: a file without id between two captures closer than the tolerance joins the nearer one)
DEFAULT_TIME_TOLERANCE_S = 0.1

SEQUOIA_RECORD = struct.Struct("<QHHHHfff")  # one IrradianceList record, 28 bytes

RGB_NAMES = ("rgb", "redgreenblue")
# the bands each index needs: named in the warning for a capture that lacks one
INDEX_BANDS = (("NDVI", ("nir", "red")), ("NDRE", ("nir", "rededge")), ("GNDVI", ("nir", "green")))


@dataclass(frozen=True)
class LensModel:
    """The band camera's interior orientation as the file gives it (nothing converted).

    ``kind``: "fisheye" / "perspective" (Pix4D ``Camera:ModelType``), "opencv" (DJI ``DewarpData``: OpenCV's
    Brown model in pixels), None when the file names none.  ``principal_point_mm``: Pix4D / MicaSense
    ``PrincipalPoint`` (millimetres).  ``focal_length`` in ``focal_length_unit`` ("mm" unless MicaSense's
    ``PerspectiveFocalLengthUnits`` says otherwise).  ``distortion``: Pix4D R1, R2, R3, T1, T2, or DJI k1, k2,
    p1, p2, k3.  ``fisheye_affine``: C, D, E, F; ``fisheye_polynomial``: p0..p3.  ``dewarp``: DJI fx, fy, cx,
    cy (px) and ``dewarp_date``; ``optical_center_px``: DJI ``CalibratedOpticalCenterX/Y``."""
    kind: Optional[str] = None
    principal_point_mm: Optional[Tuple[float, ...]] = None
    focal_length: Optional[float] = None
    focal_length_unit: Optional[str] = None
    distortion: Optional[Tuple[float, ...]] = None
    fisheye_affine: Optional[Tuple[float, ...]] = None
    fisheye_polynomial: Optional[Tuple[float, ...]] = None
    dewarp: Optional[Tuple[float, ...]] = None
    dewarp_date: Optional[str] = None
    optical_center_px: Optional[Tuple[float, ...]] = None


@dataclass(frozen=True)
class Vignetting:
    """A vignetting model as given.  ``model``: "poly2d" (Sequoia ``VignettingPolynomial2D``: coefficient i
    multiplies x^a y^b with (a, b) the i-th pair of ``VignettingPolynomial2DName``, x, y the pixel position
    divided by the width / height) or "radial" (MicaSense ``VignettingPolynomial`` / DJI ``VignettingData``:
    coefficients of r, r^2, ... with r the distance in px from ``center_px``).  ``source``: the tag read."""
    model: str
    coefficients: Tuple[float, ...]
    exponents: Optional[Tuple[Tuple[int, int], ...]] = None
    center_px: Optional[Tuple[float, ...]] = None
    source: str = ""


@dataclass(frozen=True)
class SunshineRecord:
    """One record of the Sequoia sunshine sensor's ``IrradianceList``: raw counts of its two channels, the gain
    index and integration time they were taken with, and the sensor's attitude (degrees)."""
    timestamp_us: int
    ch0: int
    ch1: int
    gain_index: int
    integration_ms: int
    yaw: float
    pitch: float
    roll: float


@dataclass(frozen=True)
class Irradiance:
    """The sun sensor's reading for this band.  ``value``: MicaSense ``Camera:Irradiance`` /
    ``SpectralIrradiance`` or DJI ``Irradiance`` as written (MicaSense DLS2 values in the unit that
    ``scale_to_si`` converts to W/m^2/nm); ``horizontal``: MicaSense ``HorizontalIrradiance``; ``records``: the
    Sequoia's decoded ``IrradianceList`` (raw counts, not W/m^2); ``source``: the tag read."""
    value: Optional[float] = None
    horizontal: Optional[float] = None
    scale_to_si: Optional[float] = None
    records: Tuple[SunshineRecord, ...] = ()
    source: str = ""


@dataclass(frozen=True)
class BandInfo:
    """What one band file says about itself; None where it says nothing."""
    path: str
    band_name: Optional[str]
    band_names: Tuple[str, ...]
    width: int
    height: int
    central_wavelength_nm: Optional[float] = None
    fwhm_nm: Optional[float] = None
    rig_name: Optional[str] = None
    rig_camera_index: Optional[int] = None
    rig_relatives: Optional[Tuple[float, ...]] = None
    capture_id: Optional[str] = None
    timestamp: Optional[datetime] = None
    make: Optional[str] = None
    model: Optional[str] = None
    lens: LensModel = field(default_factory=LensModel)
    black_level: Optional[float] = None
    vignetting: Optional[Vignetting] = None
    band_gain: Optional[float] = None
    gain_adjustment: Optional[float] = None
    exposure_s: Optional[float] = None
    iso: Optional[float] = None
    irradiance: Optional[Irradiance] = None
    line_readout_time: Optional[float] = None
    sensor_temperature_c: Optional[float] = None
    focal_plane_px_per_mm: Optional[Tuple[float, float]] = None
    # the sensor's radiometric model as written: MicaSense ``RadiometricCalibration`` (a1, a2, a3), Sequoia
    # ``SensorModel`` (A, B, C of Parrot's SEQ-AN-01); the EXIF f-number; the Sequoia sun sensor's
    # ``IrradianceCalibrationMeasurement`` as (gain index, integration ms, ch0, ch1) rows
    radiometric_calibration: Optional[Tuple[float, ...]] = None
    sensor_model: Optional[Tuple[float, ...]] = None
    f_number: Optional[float] = None
    irradiance_calibration: Tuple[Tuple[int, int, int, int], ...] = ()

    @property
    def name(self) -> str:
        return os.path.basename(self.path)

    @property
    def is_rgb(self) -> bool:
        return (self.band_name or "").lower() in RGB_NAMES

    @property
    def has_calibration(self) -> bool:
        """True when the file carries any radiometric calibration (black level, vignetting, sun sensor)."""
        return self.black_level is not None or self.vignetting is not None or self.irradiance is not None


# ---------------------------------------------------------------- XMP
def _prefix(uri: str) -> str:
    for piece, prefix in NAMESPACES:
        if piece in uri:
            return prefix
    return uri


def _qname(tag: str) -> str:
    """'{uri}Local' -> 'Prefix:Local' with the vendor's usual prefix."""
    if tag.startswith("{"):
        uri, local = tag[1:].split("}", 1)
        return f"{_prefix(uri)}:{local}"
    return tag


def _element_value(el) -> str:
    """An XMP property written as an element: its rdf:Seq / rdf:Bag / rdf:Alt items joined by commas, else its
    text (items such as Sequoia's VignettingPolynomial2DName are themselves comma lists)."""
    items = [(li.text or "").strip() for li in el.iter(RDF + "li")]
    if items:
        return ",".join(items)
    return (el.text or "").strip()


def parse_xmp(xmp: str) -> Dict[str, str]:
    """The properties of an XMP packet as {"Prefix:Name": text}, attribute form (``Camera:BandName="NIR"``) and
    element form (``<Camera:BandName><rdf:Seq><rdf:li>NIR</rdf:li>...``) alike; sequences joined by commas.
    Prefixes are the vendors' usual ones whatever the file declares (by namespace URI).  A packet that is not
    well-formed XML (undeclared prefixes happen) is read for its attributes only; {} when there is none."""
    start, end = xmp.find("<x:xmpmeta"), xmp.rfind("</x:xmpmeta>")
    if start < 0 or end < start:
        return {}
    text = xmp[start:end + len("</x:xmpmeta>")]
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return {m.group(1): m.group(2) for m in re.finditer(r'([A-Za-z][\w-]*:\w+)\s*=\s*"([^"]*)"', text)
                if not m.group(1).startswith("xmlns:")}
    out: Dict[str, str] = {}
    for desc in root.iter(RDF + "Description"):
        for key, value in desc.attrib.items():
            out.setdefault(_qname(key), value.strip())
        for child in desc:
            out.setdefault(_qname(child.tag), _element_value(child))
    return out


def read_xmp(r: RasterFile) -> str:
    """The XMP packet of an opened file: GDAL's ``xml:XMP`` domain (TIFF tag 700, JPEG APP1), else the first
    ``XMP_SCAN_BYTES`` of the file scanned for it; "" when it has none."""
    md = r.metadata(domain="xml:XMP")
    packets = list(md.values()) if isinstance(md, dict) else list(md or [])
    if packets:
        return "\n".join(packets)
    try:
        with open(r.path, "rb") as f:
            head = f.read(XMP_SCAN_BYTES)
    except OSError:
        return ""
    start, end = head.find(b"<x:xmpmeta"), head.find(b"</x:xmpmeta>")
    return head[start:end + 12].decode("utf-8", "replace") if 0 <= start < end else ""


# ---------------------------------------------------------------- values
def numbers(text: Optional[str]) -> Optional[Tuple[float, ...]]:
    """The numbers in a comma / space / semicolon separated list ("(0.0018)", "1/800" and "+1.5" included);
    None when the text is absent or holds something else."""
    if text is None:
        return None
    out = []
    for part in re.split(r"[,\s;]+", text.strip().strip("()")):
        part = part.strip("()")
        if not part:
            continue
        try:
            if "/" in part:
                num, den = part.split("/", 1)
                out.append(float(num) / float(den))
            else:
                out.append(float(part))
        except (ValueError, ZeroDivisionError):
            return None
    return tuple(out) if out else None


def _first(tags: Dict[str, str], *names: str) -> Optional[str]:
    for n in names:
        v = (tags.get(n) or "").strip("\x00 ")
        if v:
            return v
    return None


def _number(tags: Dict[str, str], *names: str) -> Optional[float]:
    """The first of ``names`` present as a number (a one-item sequence's item; several: their mean, as
    MicaSense's black level of a 2 x 2 pattern)."""
    for n in names:
        vals = numbers(tags.get(n))
        if vals:
            return float(np.mean(vals))
    return None


def _vector(tags: Dict[str, str], *names: str) -> Optional[Tuple[float, ...]]:
    for n in names:
        vals = numbers(tags.get(n))
        if vals:
            return vals
    return None


def _timestamp(md: Dict[str, str]) -> Optional[datetime]:
    """EXIF DateTimeOriginal plus its SubSecTimeOriginal (else SubSecTime) as the digits after the decimal point
    (the camera's clock; no time zone)."""
    text = (md.get("EXIF_DateTimeOriginal") or "").strip().strip("\x00")
    try:
        t = datetime.strptime(text, "%Y:%m:%d %H:%M:%S")
    except ValueError:
        return None
    sub = (md.get("EXIF_SubSecTime_Original") or md.get("EXIF_SubSecTime") or "").strip().strip("\x00")
    if sub.isdigit():
        t += timedelta(seconds=float("0." + sub))
    return t


def decode_irradiance_list(text: str) -> Tuple[SunshineRecord, ...]:
    """The Sequoia sunshine sensor records of an ``IrradianceList`` (base64, whitespace allowed); () when it is
    not base64 of whole 28-byte records."""
    try:
        raw = base64.b64decode("".join(text.split()), validate=True)
    except (binascii.Error, ValueError):
        return ()
    if not raw or len(raw) % SEQUOIA_RECORD.size:
        return ()
    return tuple(SunshineRecord(*rec) for rec in SEQUOIA_RECORD.iter_unpack(raw))


# ---------------------------------------------------------------- the parts of a BandInfo
def lens_model(tags: Dict[str, str]) -> LensModel:
    """Pix4D / MicaSense ``Camera:`` lens tags, or DJI ``drone-dji:DewarpData`` (see :class:`LensModel`)."""
    kind = _first(tags, "Camera:ModelType")
    dewarp, dewarp_date, dewarp_k = None, None, None
    text = _first(tags, "drone-dji:DewarpData")
    if text:
        date, _, values = text.rpartition(";")
        vals = numbers(values)
        if vals and len(vals) == 9:
            dewarp, dewarp_k, dewarp_date = vals[:4], vals[4:], (date.strip() or None)
    distortion = _vector(tags, "Camera:PerspectiveDistortion") or dewarp_k
    center = None
    cx, cy = _number(tags, "drone-dji:CalibratedOpticalCenterX"), _number(tags, "drone-dji:CalibratedOpticalCenterY")
    if cx is not None and cy is not None:
        center = (cx, cy)
    focal = _number(tags, "Camera:PerspectiveFocalLength")
    unit = _first(tags, "Camera:PerspectiveFocalLengthUnits") or ("mm" if focal is not None else None)
    if focal is None and _number(tags, "drone-dji:CalibratedFocalLength") is not None:
        focal, unit = _number(tags, "drone-dji:CalibratedFocalLength"), "px"
    return LensModel(kind=kind.lower() if kind else ("opencv" if dewarp is not None else None),
                     principal_point_mm=_vector(tags, "Camera:PrincipalPoint"), focal_length=focal,
                     focal_length_unit=unit, distortion=distortion,
                     fisheye_affine=_vector(tags, "Camera:FisheyeAffineMatrix"),
                     fisheye_polynomial=_vector(tags, "Camera:FisheyePolynomial"),
                     dewarp=dewarp, dewarp_date=dewarp_date, optical_center_px=center)


def vignetting(tags: Dict[str, str], lens: LensModel) -> Optional[Vignetting]:
    """Sequoia ``VignettingPolynomial2D`` (+ ``...2DName``), MicaSense ``VignettingCenter`` +
    ``VignettingPolynomial``, DJI ``VignettingData`` (centre: ``CalibratedOpticalCenterX/Y``); None when none."""
    coeffs = _vector(tags, "Camera:VignettingPolynomial2D")
    if coeffs:
        names = _vector(tags, "Camera:VignettingPolynomial2DName")
        pairs = None
        if names and len(names) == 2 * len(coeffs):
            pairs = tuple((int(names[2 * i]), int(names[2 * i + 1])) for i in range(len(coeffs)))
        return Vignetting("poly2d", coeffs, exponents=pairs, source="Camera:VignettingPolynomial2D")
    for tag, center_tag in (("Camera:VignettingPolynomial", "Camera:VignettingCenter"),
                            ("drone-dji:VignettingData", None)):
        coeffs = _vector(tags, tag)
        if coeffs:
            center = _vector(tags, center_tag) if center_tag else lens.optical_center_px
            return Vignetting("radial", coeffs, center_px=center, source=tag)
    return None


def irradiance(tags: Dict[str, str]) -> Optional[Irradiance]:
    """The sun sensor's reading: Sequoia ``IrradianceList`` decoded, MicaSense ``Camera:Irradiance`` /
    ``SpectralIrradiance`` / ``HorizontalIrradiance`` (+ ``IrradianceScaleToSIUnits``), DJI
    ``drone-dji:Irradiance`` or ``Camera:Irradiance``; None when none."""
    records = decode_irradiance_list(tags.get("Camera:IrradianceList", ""))
    value_tags = ("Camera:Irradiance", "Camera:SpectralIrradiance", "drone-dji:Irradiance")
    source = next((t for t in value_tags if numbers(tags.get(t))), None)
    horizontal = _number(tags, "Camera:HorizontalIrradiance")
    if not records and source is None and horizontal is None:
        return None
    if records:
        source = "Camera:IrradianceList"
    return Irradiance(value=_number(tags, *value_tags), horizontal=horizontal,
                      scale_to_si=_number(tags, "Camera:IrradianceScaleToSIUnits"), records=records,
                      source=source or "Camera:HorizontalIrradiance")


def _band_names(tags: Dict[str, str], bands: int) -> Tuple[Optional[str], Tuple[str, ...]]:
    """(the band's name, the names as listed): one name for a band file; "RGB" for a colour frame (a
    three-item Red, Green, Blue sequence such as the Sequoia's RGB JPG, or a three-band file naming none)."""
    text = _first(tags, "Camera:BandName", "drone-dji:BandName")
    names = tuple(n.strip() for n in text.split(",") if n.strip()) if text else ()
    if len(names) == 1:
        return names[0], names
    if (names and sorted(n.lower() for n in names) == ["blue", "green", "red"]) or (not names and bands == 3):
        return "RGB", names
    return (",".join(names) or None), names


# EXIF FocalPlaneResolutionUnit -> millimetres per unit (EXIF 2.3: 2 inch (the default), 3 cm; 4 mm and 5 um as
# written by cameras that extend it, the Sequoia's 4 with 266.667: a 3.75 um pitch on its 4.8 x 3.6 mm sensor)
FOCAL_PLANE_UNIT_MM = {1: None, 2: 25.4, 3: 10.0, 4: 1.0, 5: 0.001}


def focal_plane_resolution(md: Dict[str, str]) -> Optional[Tuple[float, float]]:
    """EXIF FocalPlaneX/YResolution in pixels per millimetre (the unit of FocalPlaneResolutionUnit converted);
    None when absent, zero or in no unit.  Pix4D / MicaSense give the principal point and focal length in mm: this
    turns them into pixels."""
    x, y = _number(md, "EXIF_FocalPlaneXResolution"), _number(md, "EXIF_FocalPlaneYResolution")
    unit = _number(md, "EXIF_FocalPlaneResolutionUnit")
    per_unit = FOCAL_PLANE_UNIT_MM.get(int(unit) if unit is not None else 2)
    if x is None or not per_unit or x <= 0:
        return None
    y = y if y is not None and y > 0 else x
    return x / per_unit, y / per_unit


def read_band_info(path: str) -> BandInfo:
    """The multispectral metadata of one band file (TIFF or JPEG): XMP through GDAL's ``xml:XMP`` domain, EXIF
    through :func:`core.io.images.photo_metadata`.  MultispectralError naming the file when GDAL cannot open it."""
    try:
        r = RasterFile(path, "band file")
    except RasterError as e:
        raise MultispectralError(f"{path}: not a readable image ({e})") from e
    with r:
        tags = parse_xmp(read_xmp(r))
        md = photo_metadata(r)
        width, height, count = r.width, r.height, r.count
    name, names = _band_names(tags, count)
    lens = lens_model(tags)
    index = _number(tags, "Camera:RigCameraIndex", "DLS:SensorId", "drone-dji:SensorIndex")
    exposure = _number(md, "EXIF_ExposureTime")
    if exposure is None and _number(tags, "drone-dji:ExposureTime") is not None:
        exposure = _number(tags, "drone-dji:ExposureTime") * 1e-6
    return BandInfo(
        path=path, band_name=name, band_names=names, width=width, height=height,
        central_wavelength_nm=_number(tags, "Camera:CentralWavelength", "drone-dji:CentralWavelength"),
        fwhm_nm=_number(tags, "Camera:WavelengthFWHM", "drone-dji:WavelengthFWHM"),
        rig_name=_first(tags, "Camera:RigName"), rig_camera_index=None if index is None else int(index),
        rig_relatives=_vector(tags, "Camera:RigRelatives"),
        capture_id=_first(tags, "Camera:CaptureUUID", "drone-dji:CaptureUUID", "MicaSense:CaptureId"),
        timestamp=_timestamp(md), make=_first(md, "EXIF_Make", "TIFFTAG_MAKE"),
        model=_first(md, "EXIF_Model", "TIFFTAG_MODEL"), lens=lens,
        black_level=_number({**md, **tags}, "Camera:BlackCurrent", "Camera:BlackLevel", "drone-dji:BlackLevel",
                            "drone-dji:BlackCurrent", "EXIF_BlackLevel"),
        vignetting=vignetting(tags, lens),
        band_gain=_number(tags, "Camera:BandGain", "drone-dji:SensorGain"),
        gain_adjustment=_number(tags, "drone-dji:SensorGainAdjustment"), exposure_s=exposure,
        iso=_number(md, "EXIF_ISOSpeedRatings", "EXIF_ISOSpeed", "EXIF_PhotographicSensitivity"),
        irradiance=irradiance(tags), line_readout_time=_number(tags, "Camera:LineReadoutTime"),
        sensor_temperature_c=_number(tags, "Camera:SensorTemperature"),
        focal_plane_px_per_mm=focal_plane_resolution(md),
        radiometric_calibration=_vector(tags, "Camera:RadiometricCalibration"),
        sensor_model=_vector(tags, "Camera:SensorModel"), f_number=_number(md, "EXIF_FNumber"),
        irradiance_calibration=_calibration_rows(_vector(tags, "Camera:IrradianceCalibrationMeasurement")))


def _calibration_rows(values: Optional[Tuple[float, ...]]) -> Tuple[Tuple[int, int, int, int], ...]:
    """The Sequoia's ``IrradianceCalibrationMeasurement`` (gain index, integration ms, ch0, ch1, ...) as rows."""
    if not values or len(values) % 4:
        return ()
    return tuple(tuple(int(v) for v in values[i:i + 4]) for i in range(0, len(values), 4))


# ---------------------------------------------------------------- band names
@dataclass(frozen=True)
class NamedBand:
    """A band with a name of its own (:data:`NAMED_BANDS`).  ``name``: its canonical name (as index expressions
    write it; its :func:`band_key`, :attr:`key`, is how band files' names are compared); ``words``: the words
    (lower case, a trailing number dropped: "NIR1") that name it in a band name or description; ``phrases``: what
    names it wherever it stands in the text's letters run together ("Red edge", "Near-infrared"); ``nm``: its
    centre wavelength range in nm (lo <= nm < hi)."""
    name: str
    words: Tuple[str, ...]
    phrases: Tuple[str, ...]
    nm: Tuple[float, float]

    @property
    def key(self) -> str:
        return band_key(self.name)


# The named bands, stated once for core.io and core.spectral (core.spectral.bands reads band descriptions, names
# and wavelengths with it), in the order a text is matched: red edge before red (its name holds "red"), NIR
# before the visible bands.  Centre wavelengths: Sequoia green 550, red 660, red edge 735, NIR 790; MicaSense
# 475 / 560 / 668 / 717 / 842; Sentinel-2 B5 705, B6 740 red edge, B7 783, B8 842 NIR
NAMED_BANDS: Tuple[NamedBand, ...] = (
    NamedBand("REDEDGE", ("rededge", "reg", "re"), ("rededge",), (690.0, 760.0)),
    NamedBand("NIR", ("nir",), ("nearinfrared", "nearir"), (760.0, 1000.0)),
    NamedBand("RED", ("red",), (), (600.0, 690.0)),
    NamedBand("GREEN", ("green", "gre"), (), (500.0, 600.0)),
    NamedBand("BLUE", ("blue",), (), (400.0, 500.0)))


def band_key(name: Optional[str]) -> str:
    """A band name compared across vendors: lower case, letters and digits only ("Red edge" -> "rededge"; the
    :attr:`NamedBand.key` of the bands of :data:`NAMED_BANDS`: "nir", "red", "rededge", "green", "blue")."""
    return re.sub(r"[^a-z0-9]", "", (name or "").lower())


# ---------------------------------------------------------------- captures
@dataclass(frozen=True)
class Capture:
    """The band files of one trigger of the rig.  ``capture_id``: the files' capture id, else
    "<rig> <time>" for files matched by time; ``timestamp``: the earliest of its files'."""
    capture_id: str
    rig_name: Optional[str]
    timestamp: Optional[datetime]
    bands: Tuple[BandInfo, ...]

    @property
    def band_names(self) -> Tuple[str, ...]:
        return tuple(b.band_name or "?" for b in self.bands)

    def band(self, name: str) -> Optional[BandInfo]:
        key = band_key(name)
        return next((b for b in self.bands if band_key(b.band_name) == key), None)


@dataclass(frozen=True)
class Block:
    """The captures of a set of band files, every band name seen (rig camera order, RGB last) and the warnings
    of :func:`check_captures` (what is built with less)."""
    captures: Tuple[Capture, ...]
    band_names: Tuple[str, ...]
    warnings: Tuple[str, ...]


def band_order(b: BandInfo) -> Tuple[bool, int, float]:
    """Sort key of bands: rig camera index, else central wavelength, RGB frames last (a stable sort keeps the
    files' order among bands that give neither)."""
    index = b.rig_camera_index if b.rig_camera_index is not None else 1 << 16
    return b.is_rgb, index, b.central_wavelength_nm if b.central_wavelength_nm is not None else float("inf")


def _names(infos: Sequence[BandInfo], most: int = 6) -> str:
    names = [b.name for b in infos]
    more = f" and {len(names) - most} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def _time(t: Optional[datetime]) -> str:
    return t.isoformat(sep=" ", timespec="milliseconds") if t else "no time"


def _seconds(a: datetime, b: datetime) -> float:
    return abs((a - b).total_seconds())


def _nearest(groups: Dict[str, List[BandInfo]], info: BandInfo, tolerance_s: float) -> Optional[str]:
    """The key of the group of ``info``'s rig whose earliest file lies nearest in time, within the tolerance."""
    best, best_dt = None, tolerance_s
    for key, members in groups.items():
        times = [m.timestamp for m in members if m.timestamp is not None]
        if not times or members[0].rig_name != info.rig_name:
            continue
        dt = _seconds(min(times), info.timestamp)
        if dt <= best_dt:
            best, best_dt = key, dt
    return best


def group_captures(infos: Sequence[BandInfo], tolerance_s: float = DEFAULT_TIME_TOLERANCE_S) -> List[Capture]:
    """Band files grouped into captures: by capture id (Sequoia / DJI CaptureUUID, MicaSense CaptureId); a file
    without one joins the capture of its rig stamped nearest to it within ``tolerance_s`` (the Sequoia's RGB
    frame), else starts one with the files of its rig stamped within the tolerance.  A file with neither id nor
    time is left out here (:func:`check_captures` names it).  Captures in time order."""
    groups: Dict[str, List[BandInfo]] = {}
    for info in infos:
        if info.capture_id:
            groups.setdefault(info.capture_id, []).append(info)
    loose = sorted((i for i in infos if not i.capture_id and i.timestamp is not None), key=lambda i: i.timestamp)
    for info in loose:
        key = _nearest(groups, info, tolerance_s)
        if key is None:
            key = f"{info.rig_name or 'camera'} {_time(info.timestamp)}"
            groups.setdefault(key, [])
        groups[key].append(info)
    captures = []
    for key, members in groups.items():
        times = [m.timestamp for m in members if m.timestamp is not None]
        order = sorted(members, key=band_order)
        captures.append(Capture(key, members[0].rig_name, min(times) if times else None, tuple(order)))
    return sorted(captures, key=lambda c: (c.timestamp or datetime.min, c.capture_id))


def _id_errors(captures: Sequence[Capture], tolerance_s: float) -> List[str]:
    """Files of two captures under one capture id (copied or renamed files): their times differ more than the
    tolerance; and duplicate bands in one capture."""
    errors = []
    for cap in captures:
        tagged = [b for b in cap.bands if b.capture_id == cap.capture_id and b.timestamp is not None]
        if tagged and _seconds(max(b.timestamp for b in tagged), min(b.timestamp for b in tagged)) > tolerance_s:
            listed = ", ".join(f"{b.name} ({_time(b.timestamp)})" for b in sorted(tagged, key=lambda b: b.timestamp))
            errors.append(f"capture id {cap.capture_id} is carried by files taken at different times: {listed}; "
                          f"files of two captures share one id (copied or renamed files?): keep one capture's "
                          f"files under each id")
        seen: Dict[str, List[BandInfo]] = {}
        for b in cap.bands:
            seen.setdefault(band_key(b.band_name), []).append(b)
        for dup in (v for v in seen.values() if len(v) > 1):
            errors.append(f"capture {cap.capture_id} has band {dup[0].band_name} twice ({_names(dup)}): "
                          f"remove the copies so that one file is left per band")
    return errors


def _missing_band_warnings(captures: Sequence[Capture], names: Sequence[str]) -> List[str]:
    warnings = []
    for cap in captures:
        have = {band_key(n) for n in cap.band_names}
        lacks = [n for n in names if band_key(n) not in have]
        if not lacks:
            continue
        lost = [idx for idx, needs in INDEX_BANDS if any(band_key(n) in needs for n in lacks)]
        also = f"; {', '.join(lost)} not available for that capture" if lost else ""
        warnings.append(f"capture {cap.capture_id} ({_time(cap.timestamp)}) lacks {', '.join(lacks)} "
                        f"(files: {_names(cap.bands)}): its other bands are used{also}")
    return warnings


def _calibration_warnings(infos: Sequence[BandInfo]) -> List[str]:
    """Band files (not RGB frames, which carry no radiometric model) with no black level, vignetting or sun
    sensor reading, by band."""
    bare: Dict[str, List[BandInfo]] = {}
    for b in infos:
        if not b.is_rgb and not b.has_calibration:
            bare.setdefault(b.band_name or "?", []).append(b)
    return [f"band {name}: {len(files)} file(s) carry no radiometric calibration (no black level, vignetting "
            f"or sun-sensor reading: {_names(files)}): they are used for the geometry and their raw values are "
            f"mosaicked, but no reflectance is computed for that band" for name, files in bare.items()]


def block_band_names(captures: Sequence[Capture]) -> Tuple[str, ...]:
    """Every band name of the captures once, in :func:`band_order`."""
    seen: Dict[str, BandInfo] = {}
    for cap in captures:
        for b in cap.bands:
            seen.setdefault(band_key(b.band_name), b)
    order = sorted(seen.values(), key=band_order)
    return tuple(b.band_name for b in order)


def check_captures(infos: Sequence[BandInfo], captures: Sequence[Capture],
                   tolerance_s: float = DEFAULT_TIME_TOLERANCE_S) -> List[str]:
    """Check a block before any work.  MultispectralError (every problem, each naming its files) for what
    cannot be built right: a file that names no band (not a band file of a rig), a file with neither capture id
    nor time (no capture can be found for it), files of two captures under one capture id, a band twice in one
    capture (which file is meant cannot be told).  The warnings returned are for what is built with less: a
    capture that lacks a band the others have (its other bands are used; the indices that need the missing band
    are not available there), band files without radiometric calibration (geometry only, no reflectance)."""
    errors = [f"{b.name}: its XMP names no band (Camera:BandName): not a band file of a multispectral rig"
              for b in infos if not b.band_name]
    placed = {id(b) for cap in captures for b in cap.bands}
    lost = [b for b in infos if b.band_name and id(b) not in placed]
    if lost:
        errors.append(f"{_names(lost)}: no capture id in the XMP and no EXIF DateTimeOriginal: the capture "
                      f"these files belong to cannot be found")
    errors += _id_errors(captures, tolerance_s)
    if errors:
        raise MultispectralError("the band files cannot be used as they are:\n- " + "\n- ".join(errors))
    return (_missing_band_warnings(captures, block_band_names(captures))
            + _calibration_warnings([b for cap in captures for b in cap.bands]))


def band_files(folder: str) -> List[str]:
    """The image files of a folder (sorted); MultispectralError naming the folder when it has none."""
    if not os.path.isdir(folder):
        raise MultispectralError(f"{folder}: not a folder")
    files = sorted(os.path.join(folder, n) for n in os.listdir(folder) if n.lower().endswith(IMAGE_EXTENSIONS))
    if not files:
        raise MultispectralError(f"{folder}: no image files ({', '.join(IMAGE_EXTENSIONS)})")
    return files


def _camera(b: BandInfo) -> str:
    return " ".join(v for v in (b.make, b.model) if v) or "unknown camera"


def not_of_the_rig(captures: Sequence[Capture]) -> Tuple[List[Capture], List[str]]:
    """(the captures of the rig, warnings): a capture made only of colour frames that name no rig of the block's
    band files (a drone's or a phone's photos left among a rig's bands: no rig name, no capture id, taken at none
    of the rig's captures' times) is not the rig's; its files are named, with how many and which camera, and left
    out, rather than taken for the rig's RGB frames (and every rig capture said to lack that "band")."""
    rigs = {c.rig_name for c in captures if any(not b.is_rgb for b in c.bands)}
    if not rigs:
        return list(captures), []
    kept, other = [], []
    for c in captures:
        foreign = all(b.is_rgb and b.rig_name not in rigs for b in c.bands)
        (other if foreign else kept).append(c)
    if not other:
        return kept, []
    files = [b for c in other for b in c.bands]
    cameras = ", ".join(sorted({_camera(b) for b in files}))
    rig = ", ".join(sorted(r or "without a rig name" for r in rigs))
    bands = ", ".join(block_band_names(kept))
    return kept, [f"{len(files)} file(s) are not band files of the rig {rig} (its bands: {bands}): {_names(files, 12)} "
                  f"({cameras}: colour photos that belong to none of the rig's captures): left out"]


def read_block(paths: Sequence[str], tolerance_s: float = DEFAULT_TIME_TOLERANCE_S) -> Block:
    """The band files read (:func:`read_band_info`), grouped into captures and checked (:func:`check_captures`:
    MultispectralError before any work, else the block with its warnings); colour photos of another camera among
    the files are named and left out (:func:`not_of_the_rig`)."""
    infos = [read_band_info(p) for p in paths]
    grouped = group_captures(infos, tolerance_s)
    captures, foreign = not_of_the_rig(grouped)
    gone = {id(b) for c in grouped for b in c.bands} - {id(b) for c in captures for b in c.bands}
    warnings = foreign + check_captures([b for b in infos if id(b) not in gone], captures, tolerance_s)
    return Block(tuple(captures), block_band_names(captures), tuple(warnings))


# ---------------------------------------------------------------- primary band
TEXTURE_SIZE = 320  # long side (px) of the decimated read the texture is measured on


@dataclass(frozen=True)
class PrimaryBand:
    """The band the geometry (matching, alignment) is built on, why, and the texture scores measured (empty
    when an RGB camera decided it)."""
    name: str
    reason: str
    scores: Dict[str, float] = field(default_factory=dict)


def texture(path: str, size: int = TEXTURE_SIZE) -> float:
    """Gradient energy of the photo's first band read decimated (GDAL average) to ``size`` px on its long side,
    its values scaled to their 1-99 percentile range: contrast and gain do not count, edges do; averaging the
    pixels down also averages the sensor noise out.  MultispectralError naming the file when it cannot be read."""
    try:
        with RasterFile(path, "band file") as r:
            scale = min(1.0, size / max(r.width, r.height))
            shape = (max(2, round(r.height * scale)), max(2, round(r.width * scale)))
            a = r.read(1, out_shape=shape, resampling="average").astype(np.float64)
    except RasterError as e:
        raise MultispectralError(f"{path}: cannot be read for its texture ({e})") from e
    lo, hi = np.percentile(a, [1.0, 99.0])
    if hi <= lo:
        return 0.0
    a = (a - lo) / (hi - lo)
    gy, gx = np.gradient(a)
    return float(np.mean(gx * gx + gy * gy))


def primary_band(block: Block, sample: int = 3) -> PrimaryBand:
    """The primary band: the RGB camera when a capture has one (most texture and detail, and the frame a user
    recognises); else the band with the most texture (:func:`texture`, median over up to ``sample`` captures
    holding the most bands, spread over the block).  Measured rather than taken from a vendor default (ODM's is
    RGB, then Green, then Blue): which band is sharpest depends on the scene (NIR over vegetation, green over bare
    soil and stone), and reading ``sample`` decimated frames per band costs a fraction of a second."""
    if any(b.is_rgb for cap in block.captures for b in cap.bands):
        rgb = next(b for cap in block.captures for b in cap.bands if b.is_rgb)
        return PrimaryBand(rgb.band_name, "the RGB camera of the rig")
    if not block.captures:
        raise MultispectralError("no capture to choose a primary band from")
    most = max(len(c.bands) for c in block.captures)
    full = [c for c in block.captures if len(c.bands) == most]
    picks = [full[i] for i in sorted({round(k * (len(full) - 1) / max(1, sample - 1)) for k in range(sample)})]
    values: Dict[str, List[float]] = {}
    for cap in picks:
        for b in cap.bands:
            values.setdefault(b.band_name, []).append(texture(b.path))
    scores = {name: float(np.median(v)) for name, v in values.items()}
    name = max(scores, key=lambda n: scores[n])
    return PrimaryBand(name, f"the most texture (gradient energy) over {len(picks)} capture(s)", scores)


# ---------------------------------------------------------------- registered bands
PHOTO_DTYPES = ("uint16", "reflectance")  # the multi-band photos the chain reads (write_band_stack)


REFLECTANCE_FLOOR = np.float32(1e-6)  # the least reflectance a photo's pixel holds: 0 is its nodata


def write_band_stack(path: str, bands: np.ndarray, names: Sequence[str], metadata: Optional[Dict[str, str]] = None,
                     wavelengths: Optional[Sequence[Optional[float]]] = None, exif: Optional[Dict[str, str]] = None,
                     dtype: str = "float32", band_metadata: Optional[Sequence[Dict[str, str]]] = None) -> str:
    """Write registered bands (bands, rows, cols) as one plain TIFF (no georeferencing; DEFLATE), atomically: each
    band described by its name, with its central wavelength (``wavelength``, nm) and its ``band_metadata`` items in
    its metadata where given; the ``exif`` tags in GDAL's EXIF domain.  ``dtype``: ``float32``, NaN nodata;
    ``uint16`` (a capture's photo for the chain, core.prepare.captures): the values rounded and clipped to 0..65535,
    NaN (where a band does not reach) 0; ``reflectance`` (a capture's photo in reflectance): float32, NaN 0 and 0
    declared the bands' nodata, every value at least REFLECTANCE_FLOOR (a dark pixel -- water, shadow, noise
    below the dark level -- is dark, not nodata).  MultispectralError naming
    the file when it cannot be written."""
    from osgeo import gdal

    gdal.UseExceptions()
    data = np.asarray(bands)
    wavelengths = list(wavelengths) if wavelengths is not None else [None] * len(names)
    extra = list(band_metadata) if band_metadata is not None else [{}] * len(names)
    if data.ndim != 3 or data.shape[0] != len(names) or len(wavelengths) != len(names) or len(extra) != len(names):
        raise MultispectralError(f"{path}: {len(names)} band names for an array of shape {data.shape}")
    photo = dtype in PHOTO_DTYPES
    if dtype == "uint16":
        data = np.clip(np.nan_to_num(data.astype(np.float64), nan=0.0), 0, 65535).round().astype(np.uint16)
    elif dtype == "reflectance":
        data = data.astype(np.float32)
        there = np.isfinite(data)  # a value, however dark, stays a value: at least REFLECTANCE_FLOOR, not nodata
        data = np.where(there, np.maximum(data, REFLECTANCE_FLOOR), np.float32(0.0)).astype(np.float32)
    else:
        data = data.astype(np.float32)
    integer = data.dtype == np.uint16
    try:
        with atomic_output(path) as tmp:
            ds = gdal.GetDriverByName("GTiff").Create(
                tmp, data.shape[2], data.shape[1], data.shape[0], gdal.GDT_UInt16 if integer else gdal.GDT_Float32,
                ["COMPRESS=DEFLATE", f"PREDICTOR={2 if integer else 3}", "TILED=YES", "INTERLEAVE=BAND"])
            for i, (name, nm, md) in enumerate(zip(names, wavelengths, extra)):
                band = ds.GetRasterBand(i + 1)
                band.SetDescription(str(name))
                if not integer:
                    band.SetNoDataValue(0.0 if photo else float("nan"))
                items = {"wavelength": f"{nm:g}", "wavelength_units": "nm"} if nm is not None else {}
                items.update({str(k): str(v) for k, v in (md or {}).items()})
                if items:
                    band.SetMetadata(items)
                band.WriteArray(data[i])
            if exif:
                ds.SetMetadata({str(k): str(v) for k, v in exif.items()}, "EXIF")
            if metadata:
                ds.SetMetadata({str(k): str(v) for k, v in metadata.items()})
            ds.FlushCache()
            ds = None
    except (RuntimeError, OSError) as e:
        raise MultispectralError(f"{path}: the bands cannot be written ({e})") from e
    return path


# EXIF tags a capture's multi-band photo takes from its reference band file (where it is, when, by what)
CARRIED_EXIF = ("EXIF_GPSLatitude", "EXIF_GPSLatitudeRef", "EXIF_GPSLongitude", "EXIF_GPSLongitudeRef",
                "EXIF_GPSAltitude", "EXIF_GPSAltitudeRef", "EXIF_GPSMapDatum", "EXIF_DateTimeOriginal",
                "EXIF_SubSecTime_Original", "EXIF_Make", "EXIF_Model")


def capture_exif(reference_path: str, focal_px: float, width: int, height: int) -> Dict[str, str]:
    """The EXIF of a capture's registered multi-band photo: the reference band file's position, time and camera
    (CARRIED_EXIF), and the pinhole frame's focal length written as core.io.images reads it back (a focal length
    in mm over a focal plane resolution in px/mm of a ``width`` x ``height`` frame), so the alignment starts from
    the registered frame's own focal length.  MultispectralError naming the file when it cannot be read."""
    try:
        with RasterFile(reference_path, "band file") as r:
            md = photo_metadata(r)
    except RasterError as e:
        raise MultispectralError(f"{reference_path}: its EXIF cannot be read ({e})") from e
    out = {k: v for k, v in md.items() if k in CARRIED_EXIF and str(v).strip()}
    px_per_mm = 100.0  # any pitch will do: only the product f_mm * px_per_mm is read back
    out.update({"EXIF_FocalLength": f"({focal_px / px_per_mm:.6f})", "EXIF_FocalPlaneXResolution": f"({px_per_mm:g})",
                "EXIF_FocalPlaneYResolution": f"({px_per_mm:g})", "EXIF_FocalPlaneResolutionUnit": "4",
                "EXIF_PixelXDimension": str(int(width)), "EXIF_PixelYDimension": str(int(height))})
    return out
