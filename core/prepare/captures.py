"""Multispectral captures as multi-band photos (issue 37): every capture of a rig's band files registered
(:mod:`core.prepare.bands`: each band undistorted with its own lens into the reference band's pinhole frame, turned
by its rig rotation, refined by a residual homography) and written as one 16-bit multi-band photo, so that the
block of captures goes through Align images, the DSM and the orthophoto as photos do, and the orthomosaic comes
out with every band.

The photo's bands are ordered NIR, Red, Green first (then the others in the rig's order), so that QGIS's default
rendering of bands 1-2-3 is the false-colour NIR-R-G view in which crop marks show; each band is described by its
name with its central wavelength in its metadata.  The photo carries the reference band file's GPS, time and
camera, and the pinhole frame's focal length, in its EXIF (:func:`core.io.multispectral.capture_exif`).  Values
are, by default, each band's numbers with its dark level removed, its vignetting corrected and its exposure x gain
normalised to the block's (``radiometry``: raw, normalised or irradiance, :mod:`core.prepare.band_radiometry`,
stated in the photo's ``RADIOMETRY`` metadata and in each band's ``RADIOMETRIC_UNIT`` and ``RADIOMETRY``), 0 where a
band does not reach.  With a calibration panel (``panel``: the band files of one or more captures of a panel of
known reflectance, given apart from the flight's) the photos are float32 reflectance (0..1, 0 = no data): each
band's values are scaled by the panel's reflectance over its value (:func:`calibrate_panel`); panel files left
among the flight's (the same files, or captures with a panel capture's id) are not stacked, and the warnings say
so.

The rig is calibrated once for the block from the captures' own refinements (core.prepare.bands.calibrate_rig,
reported); the captures that cannot be refined (too little texture) or disagree with it are registered again
with it and their photos written again; each photo's ``REGISTRATION`` (and each band's) says refined / block /
model only, and the warnings name the captures not refined by their own windows.

A capture that lacks a band the block has is left out with its reason (an orthomosaic needs every band in every
photo); the block's other warnings (:func:`core.io.multispectral.check_captures`) are passed on.  The RGB camera
of a rig (another sensor, another frame) is not stacked.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from ..common.progress import NullProgress, Progress, check_cancel
from ..io.images import PRIMARY_BAND  # the item naming the band the photo's features and dense matching use
from ..io.multispectral import (
    Block,
    Capture,
    band_files,
    band_key,
    capture_exif,
    primary_band,
    read_block,
    write_band_stack,
)
from ..io.raster import RasterFile
from .band_radiometry import (
    MODES,
    PANEL_WINDOW,
    BandRadiometryError,
    PanelBand,
    band_metadata,
    block_scales,
    check_bands,
    correct,
    describe,
    measure_panel,
    panel_for_bands,
    panel_warnings,
    parse_panel_reflectance,
)
from .bands import (
    BLOCK,
    REFINED,
    RegisteredCapture,
    RegistrationOptions,
    RigCalibration,
    calibrate_rig,
    decide,
    register_capture,
)
from .options import PrepareError

# the bands a photo starts with, in this order (band_key names): bands 1-2-3 shown as RGB are NIR-R-G
FALSE_COLOUR_FIRST = ("nir", "red", "green")


@dataclass(frozen=True)
class CaptureStackOptions:
    """``output_dir``: where the multi-band photos go (one per capture, named after its reference band file
    without the band suffix); ``registration``: the band registration's options (its ``reference``: the band the
    others are registered onto, default the rig's reference camera); ``radiometry``: raw, normalised (dark
    level, vignetting, exposure x gain) or irradiance (normalised and divided by the sun sensor's irradiance:
    proportional to reflectance), core.prepare.band_radiometry; ``panel``: the band files (or folders of them) of
    the calibration panel's captures (the photos are then reflectance, with the normalised or irradiance
    correction), ``panel_reflectance`` the panel's reflectance (one number, band=value items or a CSV file:
    core.prepare.band_radiometry.parse_panel_reflectance), ``panel_window`` the side of the central window the
    panel is measured in, a fraction of the frame's short side."""
    output_dir: str
    registration: RegistrationOptions = field(default_factory=RegistrationOptions)
    radiometry: str = "normalised"
    panel: Tuple[str, ...] = ()
    panel_reflectance: str = ""
    panel_window: float = PANEL_WINDOW

    def __post_init__(self):
        if self.radiometry not in MODES:
            raise PrepareError(f"radiometry {self.radiometry!r}: one of {', '.join(MODES)}")
        panel = (self.panel,) if isinstance(self.panel, str) else tuple(self.panel or ())
        object.__setattr__(self, "panel", tuple(p for p in panel if p))
        text = (self.panel_reflectance or "").strip()
        if self.panel and not text:
            raise PrepareError("calibration panel captures given without the panel's reflectance (one number for "
                               "every band, e.g. 0.5, band=value items or a CSV file of band,reflectance)")
        if text and not self.panel:
            raise PrepareError(f"a panel reflectance ({text}) without the panel's captures: give the panel's band "
                               "files or their folder")
        if self.panel and self.radiometry == "raw":
            raise PrepareError("raw DN cannot be calibrated to reflectance by the panel: choose the normalised or "
                               "the irradiance radiometry")
        if not 0.02 <= float(self.panel_window) <= 1.0:
            raise PrepareError(f"panel window {self.panel_window}: a fraction 0.02 .. 1 of the frame's short side")
        if self.panel:
            parse_panel_reflectance(text)  # a value that is not a reflectance: before any work


@dataclass
class CaptureStackResult:
    """The photos written, their bands in order, the captures left out (capture -> why), the worst refined
    residual per band over the captures refined by their own windows (px), the block's warnings, the calibration
    panel per band (empty without one), the photos' unit, how each capture's bands were registered (capture ->
    band -> refined / block / model only) and the block's rig calibration (None when no band could be
    calibrated)."""
    photos: List[str]
    bands: Tuple[str, ...]
    left_out: Dict[str, str]
    worst_residual_px: Dict[str, float]
    warnings: List[str]
    panel: Dict[str, PanelBand] = field(default_factory=dict)
    unit: str = ""
    registration: Dict[str, Dict[str, str]] = field(default_factory=dict)
    rig: Optional[RigCalibration] = None


def stack_order(names: Sequence[str]) -> List[int]:
    """Indices of ``names`` with NIR, Red, Green first (FALSE_COLOUR_FIRST), then the others as they come."""
    keys = [band_key(n) for n in names]
    first = [keys.index(k) for k in FALSE_COLOUR_FIRST if k in keys]
    return first + [i for i in range(len(names)) if i not in first]


def _safe(text: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in text)


def photo_names(captures: Sequence[Capture]) -> Dict[str, str]:
    """capture id -> its photo's file name: the reference band file's name without its last ``_`` part, the band
    (IMG_..._0000_GRE.TIF -> IMG_..._0000.tif), else the capture id; where two captures would get one name (band
    folders that restart their numbering, as MicaSense's SET folders do) each of them takes its capture id too, so no
    capture's photo is written over another's."""
    names = {}
    for cap in captures:
        stem = os.path.splitext(cap.bands[0].name)[0]
        names[cap.capture_id] = (stem.rsplit("_", 1)[0] if "_" in stem else _safe(cap.capture_id)) + ".tif"
    seen: Dict[str, int] = {}
    for name in names.values():
        seen[name.lower()] = seen.get(name.lower(), 0) + 1
    return {cid: (n if seen[n.lower()] == 1 else f"{n[:-4]}_{_safe(cid)}.tif") for cid, n in names.items()}


GREEN_NM = 550.0  # the band an RGB camera's grey (Rec. 601: 0.587 green) is most like


def alignment_band(captures: Sequence[Capture], names: Sequence[str], with_rgb: bool) -> Tuple[str, str]:
    """(the band a stacked photo's features and dense matching are taken from, why): beside a rig's RGB frames
    (aligned in one block with them) the band nearest green (550 nm), whose grey is most like an RGB photo's;
    else the band with the most texture (core.io.multispectral.primary_band)."""
    if with_rgb:
        nm = {b.band_name: b.central_wavelength_nm for cap in captures for b in cap.bands}
        known = [n for n in names if nm.get(n) is not None]
        if known:
            name = min(known, key=lambda n: abs(nm[n] - GREEN_NM))
            return name, f"nearest {GREEN_NM:g} nm ({nm[name]:g} nm): matched with the rig's RGB photos"
        green = [n for n in names if band_key(n) == "green"]
        if green:
            return green[0], "the green band: matched with the rig's RGB photos"
    p = primary_band(Block(tuple(captures), tuple(names), ()))
    return p.name, p.reason


def _band_captures(paths: Sequence[str]):
    """(captures without the RGB camera's frames, their band names in rig order, warnings, the alignment band and
    why)."""
    block = read_block(paths)
    with_rgb = any(b.is_rgb for c in block.captures for b in c.bands)
    captures = [dataclasses.replace(c, bands=tuple(b for b in c.bands if not b.is_rgb)) for c in block.captures]
    captures = [c for c in captures if c.bands]
    names = tuple(n for n in block.band_names if band_key(n) not in ("rgb", "redgreenblue"))
    if not captures or len(names) < 2:
        raise PrepareError(f"{len(paths)} file(s) hold no capture with two or more bands (bands seen: "
                           f"{', '.join(block.band_names) or 'none'}): nothing to stack")
    return captures, names, list(block.warnings), alignment_band(captures, names, with_rgb)


def panel_files(panel: Sequence[str]) -> List[str]:
    """The calibration panel's band files: each item of ``panel`` a band file or a folder of them (its image files);
    PrepareError naming an item that is neither."""
    out: List[str] = []
    for p in panel:
        if os.path.isdir(p):
            out += band_files(p)
        elif os.path.isfile(p):
            out.append(p)
        else:
            raise PrepareError(f"calibration panel {p}: no such file or folder")
    return out


def _apart_from_panel(paths: Sequence[str], panel: Sequence[str]) -> Tuple[List[str], List[str]]:
    """The flight's band files without the panel's own files (a panel capture left in the band folder and given
    as the panel), and the warning saying so."""
    own = {os.path.realpath(p) for p in panel}
    kept = [p for p in paths if os.path.realpath(p) not in own]
    gone = len(paths) - len(kept)
    return kept, ([f"{gone} band file(s) of the calibration panel lie among the band files: used as the panel, not "
                   "stacked"] if gone else [])


def _panel_captures(panel: Sequence[str], names: Sequence[str], flight: Sequence[Capture]) -> List[Capture]:
    """The panel's captures (RGB frames aside), checked against the flight's rig: every band of the flight, no
    other band, the same frame size and rig name.  PrepareError naming the files otherwise."""
    block = read_block(panel)
    caps = [dataclasses.replace(c, bands=tuple(b for b in c.bands if not b.is_rgb)) for c in block.captures]
    caps = [c for c in caps if c.bands]
    if not caps:
        raise PrepareError(f"the calibration panel's {len(panel)} file(s) hold no band file of a rig "
                           f"({', '.join(os.path.basename(p) for p in panel[:6])})")
    own = {band_key(b.band_name): b for c in flight for b in c.bands}
    rigs = {b.rig_name for b in own.values()}
    errors = []
    for cap in caps:
        files = ", ".join(b.name for b in cap.bands)
        other = [b for b in cap.bands if band_key(b.band_name) not in own or b.rig_name not in rigs
                 or (b.width, b.height) != (own[band_key(b.band_name)].width, own[band_key(b.band_name)].height)]
        if other:
            ref = next(iter(own.values()))
            errors.append(f"panel capture {cap.capture_id}: "
                          + ", ".join(f"{b.name} (band {b.band_name}, {b.width} x {b.height} px, rig {b.rig_name})"
                                      for b in other)
                          + f" not of the flight's camera (bands {', '.join(names)}, {ref.width} x {ref.height} px, "
                            f"rig {ref.rig_name})")
        missing = [n for n in names if cap.band(n) is None]
        if missing:
            errors.append(f"panel capture {cap.capture_id} lacks band {', '.join(missing)} (files: {files}): the "
                          "panel is photographed in every band")
    if errors:
        raise PrepareError("the calibration panel cannot be used:\n- " + "\n- ".join(errors))
    return caps


def calibrate_panel(panel: Sequence[str], names: Sequence[str], flight: Sequence[Capture],
                    options: CaptureStackOptions, progress: Progress) -> Tuple[Dict[str, PanelBand], List[str]]:
    """band name -> the calibration panel's measurement (core.prepare.band_radiometry.PanelBand: the panel's
    reflectance over its corrected value, the mean over the panel's captures), and the warnings (captures that
    disagree).  Every panel band file is corrected as the flight's are (``options.radiometry``) and measured in
    the central window; errors (PrepareError, BandRadiometryError) name every file at fault, before any stacking."""
    caps = _panel_captures(panel, names, flight)
    own = {}
    for c in flight:
        for b in c.bands:
            own.setdefault(band_key(b.band_name), b)
    reflectance = panel_for_bands(parse_panel_reflectance(options.panel_reflectance),
                                  [own[band_key(n)] for n in names])
    infos = [c.band(n) for c in caps for n in names]
    factors = check_bands(infos, options.radiometry)
    values: Dict[str, float] = {}
    errors = []
    for b in infos:
        check_cancel(progress)
        with RasterFile(b.path, "panel band file") as r:
            raw = r.read(1)
        try:
            values[b.path] = measure_panel(correct(raw, b, factors[b.path]), raw, b.path, options.panel_window)
        except BandRadiometryError as e:
            errors.append(str(e))
    if errors:
        raise BandRadiometryError(f"the calibration panel cannot be measured in {len(errors)} file(s): "
                                  + "; ".join(errors))
    out = {n: PanelBand(n, reflectance[n], tuple(c.band(n).path for c in caps),
                        tuple(values[c.band(n).path] for c in caps), tuple(c.capture_id for c in caps))
           for n in names}
    return out, panel_warnings(list(out.values()), options.radiometry)


def _check_output(output_dir: str, paths: Sequence[str]) -> None:
    inputs = {os.path.realpath(os.path.dirname(p)) for p in paths}
    if os.path.realpath(output_dir) in inputs:
        raise PrepareError(f"the output folder {output_dir} holds the band files: choose another one, so that no "
                           "input is written over")


def _panel_apart(captures: Sequence[Capture], panel: Dict[str, PanelBand]) -> Tuple[List[Capture], List[str]]:
    """The flight's captures without those that are the panel's (a copy of a panel capture left in the band
    folder: the same capture id), and the warning saying so."""
    ids = {c for p in panel.values() for c in p.captures if c}
    kept = [c for c in captures if c.capture_id not in ids]
    gone = [c.capture_id for c in captures if c.capture_id in ids]
    return kept, ([f"capture(s) {', '.join(gone)} among the band files are the calibration panel's (same capture "
                   "id): not stacked"] if gone else [])


def _describe_panel(panel: Dict[str, PanelBand], mode: str) -> str:
    return (f"calibration panel ({mode} radiometry), reflectance = factor x corrected value: "
            + "; ".join(f"{n}: panel {p.reflectance:g}, value {p.value:.6g}, factor {p.factor:.6g}"
                        + (f", captures differ by {100 * p.disagreement:.1f} %" if len(p.values) > 1 else "")
                        for n, p in panel.items()))


def stack_captures(paths: Sequence[str], options: CaptureStackOptions,
                   progress: Optional[Progress] = None) -> CaptureStackResult:
    """Register every capture of the band files ``paths`` and write it as one multi-band photo (module
    docstring).  Errors (PrepareError, MultispectralError, BandRegistrationError, BandRadiometryError) name the
    files, before any photo is written for what the block's metadata and the calibration panel already show."""
    progress = progress or NullProgress()
    panel_paths = panel_files(options.panel)
    _check_output(options.output_dir, list(paths) + panel_paths)
    paths, notes = _apart_from_panel(paths, panel_paths)
    if panel_paths and not paths:
        raise PrepareError(f"every band file is the calibration panel's ({', '.join(options.panel)}): put the "
                           "panel's captures in a folder of their own, apart from the flight's band files")
    captures, names, warnings, (primary, why) = _band_captures(paths)
    warnings += notes
    panel: Dict[str, PanelBand] = {}
    if panel_paths:
        panel, more = calibrate_panel(panel_paths, names, captures, options, progress)
        captures, notes = _panel_apart(captures, panel)
        warnings += more + notes
        progress.info(_describe_panel(panel, options.radiometry))
    # the captures stacked (a capture lacking a band is left out below): their bands checked before any work
    every_band = [b for cap in captures if all(cap.band(n) is not None for n in names) for b in cap.bands]
    factors = check_bands(every_band, options.radiometry)  # a band lacking what the radiometry needs: before work
    scales = block_scales(every_band, factors)
    scales.update({n: p.factor for n, p in panel.items()})  # with a panel: reflectance
    by_path = {b.path: b for b in every_band}

    def prepare(path, pixels):
        b = by_path[path]
        return correct(pixels, b, factors[path], scales[b.band_name or "?"]) if path in factors else pixels

    os.makedirs(options.output_dir, exist_ok=True)
    photos: List[str] = []
    left_out: Dict[str, str] = {}
    names_of = photo_names(captures)
    kept: Dict[str, Tuple[Capture, str, RegisteredCapture]] = {}
    writer = _PhotoWriter(primary, why, options.radiometry, factors, scales, panel)
    for k, cap in enumerate(captures):
        check_cancel(progress)
        missing = [n for n in names if cap.band(n) is None]
        if missing:
            left_out[cap.capture_id] = (f"lacks {', '.join(missing)} (files: "
                                        f"{', '.join(b.name for b in cap.bands)})")
            progress.warning(f"capture {cap.capture_id} left out: {left_out[cap.capture_id]}")
            continue
        reg = register_capture(cap, options.registration, prepare=prepare)
        path = writer.write(os.path.join(options.output_dir, names_of[cap.capture_id]), cap, reg)
        kept[cap.capture_id] = (cap, path, _light(reg))
        photos.append(path)
        progress.report((k + 1) / len(captures), f"captures: {k + 1}/{len(captures)} stacked")
    rig = _apply_rig(kept, options.registration, prepare, writer, progress)
    warnings += _registration_warnings(kept, rig)
    worst: Dict[str, float] = {}
    for _cap, _path, reg in kept.values():
        for r in reg.results[1:]:
            if r.status == REFINED and r.refined_residual.count:
                worst[r.camera.name] = max(worst.get(r.camera.name, 0.0), float(r.refined_residual.worst))
    unit = band_metadata(options.radiometry, next(iter(panel.values()), None))["RADIOMETRIC_UNIT"]
    return CaptureStackResult(photos, writer.order_names, left_out, worst, warnings, panel, unit,
                              {cid: reg.registration for cid, (_c, _p, reg) in kept.items()}, rig)


def _light(reg: RegisteredCapture) -> RegisteredCapture:
    """The registration without its pixels (kept for the block's rig calibration)."""
    return dataclasses.replace(reg, bands=reg.bands[:0], model_bands=None)


@dataclass
class _PhotoWriter:
    """Writes one capture's registered bands as its multi-band photo (the block's radiometry and panel)."""
    primary: str
    why: str
    radiometry: str
    factors: Dict[str, object]
    scales: Dict[str, float]
    panel: Dict[str, PanelBand]
    order_names: Tuple[str, ...] = ()

    def write(self, path: str, cap: Capture, reg: RegisteredCapture) -> str:
        order = stack_order(reg.names)
        self.order_names = tuple(reg.names[i] for i in order)
        infos = {b.band_name: b for b in cap.bands}
        ref = infos[reg.reference]
        height, width = reg.bands.shape[1:]
        how = reg.registration
        md = {"REFERENCE_BAND": reg.reference, "CAPTURE": cap.capture_id, PRIMARY_BAND: self.primary,
              PRIMARY_BAND + "_REASON": self.why,
              "BAND_FILES": ",".join(infos[n].name for n in self.order_names),
              "REGISTRATION": ", ".join(f"{n}: {how[n]}" for n in self.order_names if n in how),
              **describe(self.radiometry, [infos[n] for n in self.order_names], self.factors, self.scales,
                         self.panel)}
        bmd = [dict(band_metadata(self.radiometry, _panel_of(self.panel, n)),
                    REGISTRATION=how.get(n, "reference")) for n in self.order_names]
        write_band_stack(path, reg.bands[order], self.order_names, md,
                         [infos[n].central_wavelength_nm for n in self.order_names],
                         capture_exif(ref.path, reg.frame.f, width, height),
                         "reflectance" if self.panel else "uint16", bmd)
        return path


def _needs_block(reg: RegisteredCapture, rig: RigCalibration) -> bool:
    """Does a capture registered without the block's calibration take it for a band (too little texture, or its
    own refinement beyond the block's tolerance)?"""
    return any(decide(r.camera.name, r.trusted, r.correction, rig, "")[0] == BLOCK for r in reg.results[1:])


def _apply_rig(kept: Dict[str, Tuple[Capture, str, RegisteredCapture]], options: RegistrationOptions, prepare,
               writer: "_PhotoWriter", progress: Progress) -> Optional[RigCalibration]:
    """The rig calibrated once for the block from the captures' own refinements (core.prepare.bands.calibrate_rig),
    reported; the captures that need it registered again with it and their photos written again (only those: the
    others keep their own refinement, so the block costs one more registration per capture that needs it).
    ``kept`` is updated; None when no band could be calibrated."""
    if not kept or not options.iterations:
        return None
    first = next(iter(kept.values()))[2]
    rig = calibrate_rig({cid: reg.results for cid, (_c, _p, reg) in kept.items()}, first.frame,
                        first.bands.shape[1:], options)
    if not rig.bands:
        return None
    progress.info(rig.describe())
    for cid, (cap, path, reg) in list(kept.items()):
        if _needs_block(reg, rig):
            check_cancel(progress)
            again = register_capture(cap, options, prepare=prepare, calibration=rig)
            writer.write(path, cap, again)
            kept[cid] = (cap, path, _light(again))
    return rig


def _registration_warnings(kept: Dict[str, Tuple[Capture, str, RegisteredCapture]],
                           rig: Optional[RigCalibration]) -> List[str]:
    """A warning per capture whose bands were not refined by their own windows, naming the capture, the bands
    and why."""
    out = []
    for cid, (_cap, _path, reg) in kept.items():
        off = [r for r in reg.results[1:] if r.status != REFINED]
        if off:
            out.append(f"capture {cid}: " + "; ".join(f"{r.camera.name} {r.status} ({r.note})" for r in off))
    return out


def _panel_of(panel: Dict[str, PanelBand], name: str) -> Optional[PanelBand]:
    return next((p for n, p in panel.items() if band_key(n) == band_key(name)), None)


def stack_capture_folder(folder: str, options: CaptureStackOptions,
                         progress: Optional[Progress] = None) -> CaptureStackResult:
    """:func:`stack_captures` of the band files in ``folder`` (the entry of Stack multispectral captures);
    MultispectralError naming the folder when it holds no image file."""
    return stack_captures(band_files(folder), options, progress)


def is_band_folder(folder: str, probe: int = 8) -> bool:
    """Does ``folder`` hold a multispectral rig's band files: the first ``probe`` image files, the rig's RGB frames
    aside, each name one band with a rig name or a capture id, and they name two bands or more (a folder of one
    band's files is a block of photos, aligned as it is)?  Cheap: a few files' metadata, no pixels."""
    from ..io.images import list_images
    from ..io.multispectral import MultispectralError, read_band_info

    if not os.path.isdir(folder):
        return False
    names = list_images(folder)[:probe]
    bands = set()
    for name in names:
        try:
            b = read_band_info(os.path.join(folder, name))
        except MultispectralError:
            return False
        if b.is_rgb:  # a rig's RGB camera beside its bands (or a folder of colour photos: no band then)
            continue
        if not b.band_name or len(b.band_names) > 1 or not (b.rig_name or b.capture_id):
            return False
        bands.add(band_key(b.band_name))
    return len(bands) >= 2
