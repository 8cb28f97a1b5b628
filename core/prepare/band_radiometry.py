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

With a **calibration panel** (a capture of a panel of known reflectance, before and / or after the flight, as
MicaSense, DJI and Parrot ask for) that factor is instead the panel's reflectance over the panel's corrected value
(the same correction, normalised or irradiance, measured by :func:`measure_panel`: the median of a central
window, refused when it is saturated or not uniform), the mean over the panel captures; the values are then
reflectance (0..1, float32 photos).  The panel's reflectance is one number for every band, per band name
("Green=0.49,Red=0.50"), or a CSV file of band name or wavelength (nm) and reflectance, as the panel's
calibration sheet gives it (:func:`parse_panel_reflectance`; a curve of wavelengths is interpolated at each band's
central wavelength).

Pure: NumPy; no qgis, no Qt.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..io.multispectral import BandInfo, band_key

MODES = ("raw", "normalised", "irradiance")
MODE_TEXT = {"raw": "raw DN (no radiometric correction)",
             "normalised": "DN normalised: dark level removed, vignetting corrected, exposure x gain normalised",
             "irradiance": "DN normalised and divided by the sun sensor's irradiance (proportional to reflectance)"}
# a band's unit (each band's RADIOMETRIC_UNIT item, carried into the orthomosaic's bands; core.ortho leaves the
# values of photos in REFLECTANCE as they are)
UNITS = {"raw": "DN", "normalised": "normalised DN", "irradiance": "DN proportional to reflectance"}
REFLECTANCE = "reflectance"
PANEL_TEXT = {"normalised": "reflectance (0..1) from the calibration panel: dark level removed, vignetting "
                            "corrected, exposure x gain normalised, scaled by the panel (the light at the panel's "
                            "capture)",
              "irradiance": "reflectance (0..1) from the calibration panel and the sun sensor: dark level removed, "
                            "vignetting corrected, exposure x gain normalised, divided by the sun sensor's "
                            "irradiance, scaled by the panel"}
PANEL_WINDOW = 0.25  # the panel window's side, a fraction of the frame's short side (centred)
PANEL_TOLERANCE = 0.10  # a panel pixel lies within this fraction of the window's median (or 4 noise sigmas) ...
PANEL_OUTLIERS = 0.05  # ... but for at most this fraction of the window's pixels
PANEL_SATURATED = 0.001  # more than this fraction of the window's pixels at the file's full scale: saturated
PANEL_AGREEMENT = 0.03  # panel captures whose values differ by more than this: the light changed between them


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
             scales: Dict[str, float], panel: Optional[Dict[str, "PanelBand"]] = None) -> Dict[str, str]:
    """The photo's metadata items stating its radiometry: ``RADIOMETRY`` and, per band (its name's key in upper
    case), the vignetting model used, the dark level and the block's scale, or with a calibration ``panel`` (band
    name -> PanelBand) the panel's reflectance, value, factor and files."""
    panel = {band_key(n): p for n, p in (panel or {}).items()}
    md = {"RADIOMETRY": PANEL_TEXT[mode] if panel else MODE_TEXT[mode]}
    for b in bands:
        f = factors.get(b.path)
        if mode == "raw" or f is None:
            continue
        key = band_key(b.band_name).upper()
        md[f"{key}_VIGNETTING"] = f.vignetting or "none given"
        md[f"{key}_DARK_LEVEL"] = f"{f.dark_level:g}"
        p = panel.get(band_key(b.band_name))
        if p is None:
            md[f"{key}_BLOCK_SCALE"] = f"{scales.get(b.band_name or '?', 1.0):.6g}"
        else:
            md.update({f"{key}_PANEL_REFLECTANCE": f"{p.reflectance:g}", f"{key}_PANEL_VALUE": f"{p.value:.6g}",
                       f"{key}_PANEL_FACTOR": f"{p.factor:.6g}",
                       f"{key}_PANEL_FILES": ",".join(os.path.basename(x) for x in p.files)})
        if f.sensor_model:
            md[f"{key}_SENSOR_MODEL"] = "Parrot SEQ-AN-01 (SensorModel)"
        if f.irradiance is not None:
            md[f"{key}_IRRADIANCE"] = f"{f.irradiance:.6g}"
    return md


def band_metadata(mode: str, panel: Optional["PanelBand"] = None) -> Dict[str, str]:
    """A photo band's own metadata items stating its unit and radiometry (the same in every photo of the block, so
    the orthomosaic's band carries them: core.ortho.writer.photo_band_names): ``RADIOMETRIC_UNIT`` (reflectance,
    normalised DN, ...), ``RADIOMETRY`` and, with a panel, ``PANEL_REFLECTANCE``."""
    if panel is None:
        return {"RADIOMETRIC_UNIT": UNITS[mode], "RADIOMETRY": MODE_TEXT[mode]}
    return {"RADIOMETRIC_UNIT": REFLECTANCE, "RADIOMETRY": PANEL_TEXT[mode],
            "PANEL_REFLECTANCE": f"{panel.reflectance:g}"}


# ---------------------------------------------------------------- calibration panel
@dataclass(frozen=True)
class PanelReflectance:
    """The panel's reflectance as given: ``value`` for every band; else ``by_name`` ((band name as given, value)
    rows, matched by core.io.multispectral.band_key) or ``curve`` ((wavelength nm, value) rows, ascending: each
    band takes the value at its central wavelength, interpolated, up to CURVE_MARGIN_NM beyond the ends);
    ``source``: the text or the file it came from."""
    value: Optional[float] = None
    by_name: Tuple[Tuple[str, float], ...] = ()
    curve: Tuple[Tuple[float, float], ...] = ()
    source: str = ""

    def for_band(self, name: Optional[str], wavelength_nm: Optional[float]) -> Optional[float]:
        """The reflectance of band ``name`` (central wavelength ``wavelength_nm``); None when it gives none."""
        if self.value is not None:
            return self.value
        if self.by_name:
            return next((v for n, v in self.by_name if band_key(n) == band_key(name)), None)
        if self.curve and wavelength_nm is not None:
            nm = [c[0] for c in self.curve]
            if nm[0] - CURVE_MARGIN_NM <= wavelength_nm <= nm[-1] + CURVE_MARGIN_NM:
                return float(np.interp(wavelength_nm, nm, [c[1] for c in self.curve]))
        return None


CURVE_MARGIN_NM = 10.0  # a band's central wavelength at most this far beyond a reflectance curve's ends


def _reflectance_value(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise BandRadiometryError(f"panel reflectance {where}: {text!r} is not a number") from None
    if not 0.0 < value <= 1.0:
        percent = f" (a percentage? {value:g} % is {value / 100:g})" if 1.0 < value <= 100.0 else ""
        raise BandRadiometryError(f"panel reflectance {where}: {value:g} is not a reflectance between 0 and 1"
                                  + percent)
    return value


# a sheet's header row: words such as band, name, wavelength, nm, reflectance, value
_HEADER = re.compile(r"band|name|wave|\bnm\b|reflect|value|albedo|channel|%", re.I)


def _reflectance_rows(text: str) -> Tuple[List[Tuple[str, str]], str]:
    """(key, value) rows of the panel's reflectance: a CSV file's rows (comma, semicolon or tab; a header row
    and # comments skipped) or a text's items "name=value" / "name: value" separated by commas or semicolons."""
    rows = []
    if os.path.isfile(text):
        try:
            with open(text, newline="", encoding="utf-8-sig") as f:
                lines = [(n, ln) for n, ln in enumerate(f.read().splitlines(), start=1)
                         if ln.strip() and not ln.lstrip().startswith("#")]
        except (OSError, UnicodeDecodeError) as e:
            raise BandRadiometryError(f"panel reflectance file {text}: cannot be read ({e})") from e
        for k, (lineno, line) in enumerate(lines):
            cells = [c.strip().strip('"') for c in re.split(r"[,;\t]", line) if c.strip()]
            if len(cells) >= 2 and re.fullmatch(r"[-+0-9.eE]+", cells[1]):
                rows.append((cells[0], cells[1]))
            elif k == 0 and _HEADER.search(line):
                continue  # the sheet's header row
            elif len(cells) >= 2:
                raise BandRadiometryError(f"panel reflectance file {text}:{lineno}: the reflectance of {cells[0]}, "
                                          f"{cells[1]!r}, is not a number (row {line.strip()!r})")
            else:
                raise BandRadiometryError(f"panel reflectance file {text}:{lineno}: {line.strip()!r} gives a band "
                                          "and no reflectance (rows: band name or wavelength in nm, reflectance)")
        if not rows:
            raise BandRadiometryError(f"panel reflectance file {text}: no row of a band (name or wavelength in nm) "
                                      "and its reflectance (e.g. 'NIR,0.49' or '842,0.49')")
        return rows, f"file {os.path.basename(text)}"
    for item in (i.strip() for i in re.split(r"[,;]", text)):
        m = re.fullmatch(r"(.+?)\s*[=:]\s*(.+)", item) if item else None
        if item and m is None:
            raise BandRadiometryError(f"panel reflectance {text!r}: {item!r} is not 'band=value' (give one number "
                                      "for every band, band=value items, or a CSV file)")
        if m is not None:
            rows.append((m.group(1).strip(), m.group(2).strip()))
    return rows, repr(text)


def parse_panel_reflectance(text: str) -> PanelReflectance:
    """The panel's reflectance (:class:`PanelReflectance`) from what the user gives: one number for every band
    ("0.5"); band=value items ("Green=0.49,Red=0.50,Red edge=0.50,NIR=0.49"); or a CSV file of rows band name or
    wavelength in nm, reflectance (a MicaSense / DJI panel's calibration sheet: "Green,0.49" or "560,0.49").
    Reflectances are fractions (0..1].  BandRadiometryError naming what is wrong."""
    text = (text or "").strip()
    if not text:
        raise BandRadiometryError("no panel reflectance given: one number for every band (e.g. 0.5), band=value "
                                  "items or a CSV file of band,reflectance")
    if re.fullmatch(r"[-+0-9.eE]+", text):
        return PanelReflectance(value=_reflectance_value(text, "for every band"), source=text)
    rows, source = _reflectance_rows(text)
    numeric = [re.fullmatch(r"[0-9.]+(\s*nm)?", k, re.I) is not None for k, _ in rows]
    if any(numeric) and not all(numeric):
        raise BandRadiometryError(f"panel reflectance {source}: give bands either all by name or all by "
                                  f"wavelength (nm), not both ({', '.join(k for k, _ in rows)})")
    if all(numeric):
        curve = sorted((float(re.sub(r"[^0-9.]", "", k)), _reflectance_value(v, f"at {k} ({source})"))
                       for k, v in rows)
        return PanelReflectance(curve=tuple(curve), source=source)
    seen = [band_key(k) for k, _ in rows]
    twice = sorted({k for k, _ in rows if seen.count(band_key(k)) > 1})
    if twice:
        raise BandRadiometryError(f"panel reflectance {source}: band {', '.join(twice)} given twice")
    return PanelReflectance(by_name=tuple((k, _reflectance_value(v, f"of {k} ({source})")) for k, v in rows),
                            source=source)


def panel_for_bands(panel: PanelReflectance, bands: Sequence[BandInfo]) -> Dict[str, float]:
    """band name -> the panel's reflectance, for the rig's bands ``bands`` (one file per band); BandRadiometryError
    for a band named that the rig lacks, or a band of the rig the panel gives no reflectance for."""
    names = {band_key(b.band_name): b for b in bands}
    extra = [n for n, _ in panel.by_name if band_key(n) not in names]
    if extra:
        raise BandRadiometryError(f"panel reflectance {panel.source}: the rig has no band {', '.join(extra)} (its "
                                  f"bands: {', '.join(b.band_name or '?' for b in bands)})")
    out, lacking = {}, []
    for b in bands:
        value = panel.for_band(b.band_name, b.central_wavelength_nm)
        if value is None:
            nm = f" ({b.central_wavelength_nm:g} nm)" if b.central_wavelength_nm else " (no central wavelength)"
            lacking.append((b.band_name or "?") + (nm if panel.curve else ""))
        else:
            out[b.band_name or "?"] = value
    if lacking:
        span = f" (its curve: {panel.curve[0][0]:g}..{panel.curve[-1][0]:g} nm)" if panel.curve else ""
        raise BandRadiometryError(f"panel reflectance {panel.source}{span} gives none for band "
                                  f"{', '.join(lacking)}: give every band's")
    return out


def panel_window(shape: Tuple[int, int], window: float) -> Tuple[slice, slice]:
    """The panel window: a square of ``window`` x the frame's short side (at least 8 px) at the frame's centre."""
    rows, cols = shape
    side = max(8, min(rows, cols, int(round(window * min(rows, cols)))))
    r0, c0 = (rows - side) // 2, (cols - side) // 2
    return slice(r0, r0 + side), slice(c0, c0 + side)


def measure_panel(corrected: np.ndarray, raw: np.ndarray, path: str, window: float = PANEL_WINDOW) -> float:
    """The panel's corrected value in one panel band file: the median of the central window (:func:`panel_window`)
    of ``corrected`` (the band's values after the flight's correction, :func:`correct` with scale 1; ``raw``: the
    file's pixels in its own data type).  BandRadiometryError naming the file when the window is saturated (more
    than PANEL_SATURATED of its raw pixels at the file's full scale, core.io.images.full_scale) or not uniform (more than PANEL_OUTLIERS of its
    pixels beyond PANEL_TOLERANCE, or 4 noise sigmas where the noise is larger, of its median: no panel there, or
    one smaller than the window), or dark."""
    from ..io.images import full_scale

    rows, cols = np.asarray(raw).shape[:2]
    sr, sc = panel_window((rows, cols), window)
    where = (f"the panel window (the central {sr.stop - sr.start} x {sc.stop - sc.start} px, {window:g} of the "
             "frame's short side)")
    raw = np.asarray(raw)
    full = full_scale(raw) if np.issubdtype(raw.dtype, np.integer) else float("inf")  # float files: no full scale
    saturated = float(np.mean(raw[sr, sc] >= 0.99 * full))
    if saturated > PANEL_SATURATED:
        raise BandRadiometryError(f"{path}: {where} is saturated ({100 * saturated:.1f} % of its pixels at "
                                  f"{full:g}): photograph the panel with a shorter exposure (not in direct sun "
                                  "glare)")
    win = np.asarray(corrected, dtype=np.float64)[sr, sc]
    median = float(np.median(win))
    if not median > 0:
        raise BandRadiometryError(f"{path}: {where} is dark (median {median:g} after the dark level): no panel "
                                  "there")
    noise = 1.4826 * float(np.median(np.abs(np.diff(win, axis=1)))) / np.sqrt(2.0)
    tolerance = max(PANEL_TOLERANCE, 4.0 * noise / median)
    off = float(np.mean(np.abs(win / median - 1.0) > tolerance))
    if off > PANEL_OUTLIERS:
        raise BandRadiometryError(f"{path}: {where} is not uniform ({100 * off:.0f} % of its pixels differ from its "
                                  f"median by more than {100 * tolerance:.0f} %): no panel fills it. Photograph "
                                  "the panel so that it fills the centre of the frame, or give a smaller panel "
                                  "window")
    return median


@dataclass(frozen=True)
class PanelBand:
    """One band's calibration: the panel's ``reflectance``, its panel band files (one per panel capture) and
    their corrected panel values (:func:`measure_panel`), and the panel captures' ids."""
    name: str
    reflectance: float
    files: Tuple[str, ...]
    values: Tuple[float, ...]
    captures: Tuple[str, ...] = ()

    @property
    def value(self) -> float:
        """The panel's value: the mean over the panel captures (before and after the flight)."""
        return float(np.mean(self.values))

    @property
    def factor(self) -> float:
        """What the band's corrected values are multiplied by to be reflectance."""
        return self.reflectance / self.value

    @property
    def disagreement(self) -> float:
        """How much the panel captures' values differ: max / min - 1 (0 with one capture)."""
        return max(self.values) / min(self.values) - 1.0


def panel_warnings(bands: Sequence[PanelBand], mode: str) -> List[str]:
    """A warning per band whose panel captures differ by more than PANEL_AGREEMENT (the light changed between
    them, or the panel was shaded or tilted in one)."""
    out = []
    for b in bands:
        if b.disagreement > PANEL_AGREEMENT:
            values = ", ".join(f"{os.path.basename(f)} {v:.6g}" for f, v in zip(b.files, b.values))
            hint = ("in normalised radiometry the panel holds the light of its own capture: irradiance radiometry "
                    "(the sun sensor) follows the light's changes" if mode == "normalised" else
                    "was the panel shaded, tilted or dirty in one of them?")
            out.append(f"calibration panel, band {b.name}: its captures differ by {100 * b.disagreement:.1f} % "
                       f"({values}); their mean is used ({hint})")
    return out
