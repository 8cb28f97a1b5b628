"""Per-band radiometry of a multispectral rig's band files (issue 37 item 2), applied to each band file before its
capture is registered and stacked (:mod:`core.prepare.captures`).

Each band file's pixel values ``p`` are turned into values proportional to the scene's radiance, from what the file
says about itself (:class:`core.io.multispectral.BandInfo`), in the band's own pixel frame (before undistortion,
where the vignetting model lives):

1. the dark level (Sequoia ``BlackCurrent``, MicaSense / DJI ``BlackLevel``) subtracted, negatives set to 0;
2. the vignetting divided out: Sequoia ``VignettingPolynomial2D`` (V = sum c_i (x/w)^a_i (y/h)^b_i, the pixel
   column and row over the width and height; corrected = p / V, Parrot's sample code), MicaSense
   ``VignettingPolynomial`` about ``VignettingCenter`` (V = 1 + k_1 r + k_2 r^2 + ..., r in pixels; corrected =
   p / V, MicaSense's image processing library), DJI ``VignettingData`` about the calibrated optical centre
   (corrected = p x (1 + k_1 r + ...), DJI's P4 Multispectral image processing guide);
3. exposure and gain normalised: divided by exposure time x gain, the gain ISO / 100 where the file gives an ISO,
   else its ``BandGain`` / ``SensorGain``; a Sequoia with ``SensorModel`` (A, B, C) uses Parrot's SEQ-AN-01
   instead: f^2 (p - B) / (A t ISO + C) (its B is the dark level);
4. in ``irradiance`` mode, divided by the sun sensor's irradiance for that band: the Sequoia's ``IrradianceList``
   records, each ch0 / (the calibration's ch0 per millisecond at the record's gain index x its integration time),
   their median (relative to the sensor's calibration light); MicaSense ``HorizontalIrradiance`` (else
   ``Irradiance``); DJI ``Irradiance`` over ``SensorGainAdjustment``.  The values are then proportional to
   reflectance, band by band, over a flight whose light changes (a calibration panel, not read here, would fix
   each band's constant).

The values of a band are finally multiplied by one factor for the whole block (the block's median of what was
divided out for that band), so that they stay in the band's DN range and fit the 16-bit photo the chain reads;
what was done is stated in the photo's metadata (``RADIOMETRY`` and each band's ``RADIOMETRY_*`` items).

Pure: NumPy; no qgis, no Qt.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..io.multispectral import BandInfo, band_key

MODES = ("raw", "normalised", "irradiance")
MODE_TEXT = {"raw": "raw DN (no radiometric correction)",
             "normalised": "DN normalised: dark level removed, vignetting corrected, exposure x gain normalised",
             "irradiance": "DN normalised and divided by the sun sensor's irradiance (proportional to reflectance)"}


class BandRadiometryError(ArchaeoOrthoError, ValueError):
    """A band file whose metadata does not allow the radiometry asked for; the message names the file."""


@dataclass(frozen=True)
class BandFactors:
    """What one band file's correction uses: the dark level, the vignetting tag ("" none), exposure x gain (s), the
    sun sensor's irradiance (None unless in irradiance mode), and whether Parrot's sensor model was applied."""
    dark_level: float
    vignetting: str
    exposure_gain: float
    irradiance: Optional[float] = None
    sensor_model: bool = False

    @property
    def divisor(self) -> float:
        """What the band's values are divided by (after the dark level and vignetting)."""
        return self.exposure_gain * (self.irradiance if self.irradiance is not None else 1.0)


def vignetting_falloff(info: BandInfo, shape: Tuple[int, int]) -> Optional[np.ndarray]:
    """The band's vignetting as a falloff V (rows, cols), float32: corrected = p / V; None without a model."""
    v = info.vignetting
    if v is None or not v.coefficients:
        return None
    rows, cols = shape
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float64)
    if v.model == "poly2d":
        if not v.exponents:
            return None
        xn, yn = x / cols, y / rows
        out = np.zeros(shape, np.float64)
        for c, (a, b) in zip(v.coefficients, v.exponents):
            out += c * xn ** a * yn ** b
        return out.astype(np.float32)
    if not v.center_px or len(v.center_px) < 2:
        return None
    r = np.hypot(x - v.center_px[0], y - v.center_px[1])
    poly = np.ones(shape, np.float64)
    for i, k in enumerate(v.coefficients):
        poly += k * r ** (i + 1)
    if v.source.startswith("drone-dji"):  # DJI multiplies by the polynomial: the falloff is its inverse
        return (1.0 / poly).astype(np.float32)
    return poly.astype(np.float32)


def gain(info: BandInfo) -> float:
    """The band's gain: ISO / 100 where the file gives an ISO, else its band / sensor gain, else 1."""
    if info.iso and info.iso > 0:
        return info.iso / 100.0
    if info.band_gain and info.band_gain > 0:
        return float(info.band_gain)
    return 1.0


def sun_irradiance(info: BandInfo) -> Optional[float]:
    """The sun sensor's irradiance for the band (module docstring, step 4); None when the file gives none usable."""
    irr = info.irradiance
    if irr is None:
        return None
    if irr.records:
        per_ms = {g: ch0 / t for g, t, ch0, _ch1 in info.irradiance_calibration if 0 < ch0 < 65535 and t > 0}
        values = [r.ch0 / (per_ms[r.gain_index] * r.integration_ms) for r in irr.records
                  if r.gain_index in per_ms and r.integration_ms > 0 and 0 < r.ch0 < 65535]
        return float(np.median(values)) if values else None
    value = irr.horizontal if irr.horizontal else irr.value
    if not value or value <= 0:
        return None
    if irr.source.startswith("drone-dji") and info.gain_adjustment:
        return float(value) / float(info.gain_adjustment)
    return float(value) * (irr.scale_to_si or 1.0)


def band_factors(info: BandInfo, mode: str) -> BandFactors:
    """The factors of ``mode`` for one band file; BandRadiometryError naming the file where its metadata lacks
    what the mode needs."""
    if mode not in MODES or mode == "raw":
        raise BandRadiometryError(f"radiometry {mode!r}: one of {', '.join(MODES[1:])} (raw needs no factors)")
    if not info.exposure_s or info.exposure_s <= 0:
        raise BandRadiometryError(f"{info.path}: no exposure time in its EXIF or XMP: the {mode} radiometry needs "
                                  "it (choose raw DN for this block)")
    model = info.sensor_model if info.sensor_model and len(info.sensor_model) == 3 and info.f_number else None
    dark = float(model[1]) if model else float(info.black_level or 0.0)
    if model:  # SEQ-AN-01: L = f^2 (p - B) / (A t ISO + C)
        a, _b, c = model
        exposure_gain = (a * info.exposure_s * (info.iso or 100.0) + c) / info.f_number ** 2
    else:
        exposure_gain = info.exposure_s * gain(info)
    irradiance = None
    if mode == "irradiance":
        irradiance = sun_irradiance(info)
        if irradiance is None:
            raise BandRadiometryError(f"{info.path}: no usable sun-sensor irradiance for band {info.band_name} "
                                      "(Sequoia IrradianceList with its calibration, MicaSense Irradiance, DJI "
                                      "Irradiance): the normalised radiometry can still be built")
    return BandFactors(dark, info.vignetting.source if info.vignetting else "", float(exposure_gain), irradiance,
                       model is not None)


def check_bands(bands: Sequence[BandInfo], mode: str) -> Dict[str, BandFactors]:
    """Every band file's factors (path -> factors) before any work; one BandRadiometryError naming every file
    that lacks what the mode needs."""
    if mode == "raw":
        return {}
    out, bad = {}, []
    for b in bands:
        try:
            out[b.path] = band_factors(b, mode)
        except BandRadiometryError as e:
            bad.append(str(e))
    if bad:
        more = f" (and {len(bad) - 5} more)" if len(bad) > 5 else ""
        raise BandRadiometryError(f"{len(bad)} band file(s) cannot take the {mode} radiometry: "
                                  + "; ".join(bad[:5]) + more)
    return out


def block_scales(bands: Sequence[BandInfo], factors: Dict[str, BandFactors]) -> Dict[str, float]:
    """band name -> the block's median divisor of that band: the corrected values are multiplied by it, so that
    they stay in the band's DN range."""
    per: Dict[str, List[float]] = {}
    for b in bands:
        if b.path in factors:
            per.setdefault(b.band_name or "?", []).append(factors[b.path].divisor)
    return {n: float(np.median(v)) for n, v in per.items()}


def correct(pixels: np.ndarray, info: BandInfo, factors: BandFactors, scale: float = 1.0) -> np.ndarray:
    """One band file's values corrected (module docstring) and multiplied by ``scale``: float32."""
    out = np.asarray(pixels, dtype=np.float32) - np.float32(factors.dark_level)
    np.maximum(out, 0.0, out=out)
    falloff = vignetting_falloff(info, out.shape)
    if falloff is not None:
        out /= np.maximum(falloff, 1e-3)
    out *= np.float32(scale / factors.divisor)
    return out


def describe(mode: str, bands: Sequence[BandInfo], factors: Dict[str, BandFactors],
             scales: Dict[str, float]) -> Dict[str, str]:
    """The photo's metadata items stating its radiometry: ``RADIOMETRY`` and, per band (its name's key in upper
    case), the vignetting model used, the dark level and the block's scale."""
    md = {"RADIOMETRY": MODE_TEXT[mode]}
    for b in bands:
        f = factors.get(b.path)
        if mode == "raw" or f is None:
            continue
        key = band_key(b.band_name).upper()
        md[f"{key}_VIGNETTING"] = f.vignetting or "none given"
        md[f"{key}_DARK_LEVEL"] = f"{f.dark_level:g}"
        md[f"{key}_BLOCK_SCALE"] = f"{scales.get(b.band_name or '?', 1.0):.6g}"
        if f.sensor_model:
            md[f"{key}_SENSOR_MODEL"] = "Parrot SEQ-AN-01 (SensorModel)"
        if f.irradiance is not None:
            md[f"{key}_IRRADIANCE"] = f"{f.irradiance:.6g}"
    return md
