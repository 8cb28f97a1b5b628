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
stated in the photo's ``RADIOMETRY`` metadata), 0 where a band does not reach.

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
from .band_radiometry import MODES, block_scales, check_bands, correct, describe
from .bands import RegistrationOptions, register_capture
from .options import PrepareError

# the bands a photo starts with, in this order (band_key names): bands 1-2-3 shown as RGB are NIR-R-G
FALSE_COLOUR_FIRST = ("nir", "red", "green")


@dataclass(frozen=True)
class CaptureStackOptions:
    """``output_dir``: where the multi-band photos go (one per capture, named after its reference band file
    without the band suffix); ``registration``: the band registration's options (its ``reference``: the band the
    others are registered onto, default the rig's reference camera); ``radiometry``: raw, normalised (dark
    level, vignetting, exposure x gain) or irradiance (normalised and divided by the sun sensor's irradiance:
    proportional to reflectance), core.prepare.band_radiometry."""
    output_dir: str
    registration: RegistrationOptions = field(default_factory=RegistrationOptions)
    radiometry: str = "normalised"

    def __post_init__(self):
        if self.radiometry not in MODES:
            raise PrepareError(f"radiometry {self.radiometry!r}: one of {', '.join(MODES)}")


@dataclass
class CaptureStackResult:
    """The photos written, their bands in order, the captures left out (capture -> why), the worst refined
    residual per band over the captures (px), and the block's warnings."""
    photos: List[str]
    bands: Tuple[str, ...]
    left_out: Dict[str, str]
    worst_residual_px: Dict[str, float]
    warnings: List[str]


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


def _check_output(output_dir: str, paths: Sequence[str]) -> None:
    inputs = {os.path.realpath(os.path.dirname(p)) for p in paths}
    if os.path.realpath(output_dir) in inputs:
        raise PrepareError(f"the output folder {output_dir} holds the band files: choose another one, so that no "
                           "input is written over")


def stack_captures(paths: Sequence[str], options: CaptureStackOptions,
                   progress: Optional[Progress] = None) -> CaptureStackResult:
    """Register every capture of the band files ``paths`` and write it as one multi-band photo (module
    docstring).  Errors (PrepareError, MultispectralError, BandRegistrationError) name the files, before any photo
    is written for what the block's metadata already shows."""
    progress = progress or NullProgress()
    _check_output(options.output_dir, paths)
    captures, names, warnings, (primary, why) = _band_captures(paths)
    # the captures stacked (a capture lacking a band is left out below): their bands checked before any work
    every_band = [b for cap in captures if all(cap.band(n) is not None for n in names) for b in cap.bands]
    factors = check_bands(every_band, options.radiometry)  # a band lacking what the radiometry needs: before work
    scales = block_scales(every_band, factors)
    by_path = {b.path: b for b in every_band}

    def prepare(path, pixels):
        b = by_path[path]
        return correct(pixels, b, factors[path], scales[b.band_name or "?"]) if path in factors else pixels

    os.makedirs(options.output_dir, exist_ok=True)
    photos: List[str] = []
    left_out: Dict[str, str] = {}
    worst: Dict[str, float] = {}
    order_names: Tuple[str, ...] = ()
    names_of = photo_names(captures)
    for k, cap in enumerate(captures):
        check_cancel(progress)
        missing = [n for n in names if cap.band(n) is None]
        if missing:
            left_out[cap.capture_id] = (f"lacks {', '.join(missing)} (files: "
                                        f"{', '.join(b.name for b in cap.bands)})")
            progress.warning(f"capture {cap.capture_id} left out: {left_out[cap.capture_id]}")
            continue
        reg = register_capture(cap, options.registration, prepare=prepare)
        order = stack_order(reg.names)
        order_names = tuple(reg.names[i] for i in order)
        infos = {b.band_name: b for b in cap.bands}
        ref = infos[reg.reference]
        height, width = reg.bands.shape[1:]
        path = os.path.join(options.output_dir, names_of[cap.capture_id])
        md = {"REFERENCE_BAND": reg.reference, "CAPTURE": cap.capture_id, PRIMARY_BAND: primary,
              PRIMARY_BAND + "_REASON": why,
              "BAND_FILES": ",".join(infos[n].name for n in order_names),
              **describe(options.radiometry, [infos[n] for n in order_names], factors, scales)}
        write_band_stack(path, reg.bands[order], order_names, md,
                         [infos[n].central_wavelength_nm for n in order_names],
                         capture_exif(ref.path, reg.frame.f, width, height), dtype="uint16")
        photos.append(path)
        for r in reg.results[1:]:
            worst[r.camera.name] = max(worst.get(r.camera.name, 0.0), float(r.refined_residual.worst))
        progress.report((k + 1) / len(captures), f"captures: {k + 1}/{len(captures)} stacked")
    return CaptureStackResult(photos, order_names, left_out, worst, warnings)


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
