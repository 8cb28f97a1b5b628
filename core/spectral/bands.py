"""Which band of a multi-band raster is NIR, red, red edge, green or blue, and how that was read.

Evidence, strongest first: a band number the user set (:class:`~.options.BandOverrides`); the band's description
("NIR", "Red edge", "Band 4 (790 nm)"); a naming metadata item of the band (BAND_NAME, NAME ...); a wavelength
metadata item (wavelength, CENTRAL_WAVELENGTH_UM, with wavelength_units; nm or µm), placed in
:data:`WAVELENGTH_RANGES_NM`; the band's colour interpretation (red / green / blue; NIR and red edge in GDAL >=
3.10).  A name is the band with the strongest evidence for it; two bands with equally strong evidence for one
name are refused when that name is used, naming both.  Alpha bands (colour interpretation alpha) have no name:
they mask the others.  The names, the words that say them and the wavelength ranges are
:data:`core.io.multispectral.NAMED_BANDS`, shared with the band files of multispectral rigs.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

from ..io import raster
from ..io.multispectral import NAMED_BANDS
from .errors import SpectralError
from .options import BandOverrides

_BY_WAVELENGTH = sorted(NAMED_BANDS, key=lambda b: b.nm)
BAND_NAMES: Tuple[str, ...] = tuple(b.name for b in _BY_WAVELENGTH)  # BLUE, GREEN, RED, REDEDGE, NIR
# the centre wavelength (nm) ranges of the named bands (NAMED_BANDS), shortest first
WAVELENGTH_RANGES_NM: Tuple[Tuple[str, float, float], ...] = tuple((b.name, b.nm[0], b.nm[1]) for b in _BY_WAVELENGTH)
# the kinds of evidence, strongest first
SET, DESCRIPTION, METADATA, WAVELENGTH, COLOUR, NONE = range(6)
EVIDENCE = {SET: "set", DESCRIPTION: "description", METADATA: "metadata", WAVELENGTH: "wavelength",
            COLOUR: "colour interpretation"}
NAME_KEYS = ("band_name", "bandname", "name", "band", "spectral_band", "channel", "color", "colour")
# GDAL colour interpretation names (lower case, no spaces: GDAL >= 3.10's "RedEdge") -> canonical name
COLOURS = {b.key: b.name for b in NAMED_BANDS}
# words beside "infrared" that make it another infrared than the near one
OTHER_INFRARED = {"shortwave", "swir", "thermal", "mid", "tir"}


@dataclass
class BandInfo:
    number: int
    description: str = ""
    name: str = ""  # the canonical name (BAND_NAMES) its evidence gives; '' for none
    how: str = ""  # the evidence, as the messages say it: "its description 'NIR'"
    level: int = NONE
    alpha: bool = False

    def describe(self) -> str:
        label = f" '{self.description}'" if self.description else ""
        if self.alpha:
            return f"band {self.number}{label}: alpha (masks the others)"
        return f"band {self.number}{label}: " + (f"{self.name} from {self.how}" if self.name else "no name found")


@dataclass
class BandTable:
    """The bands of the raster ``path`` and what each is."""

    path: str
    bands: List[BandInfo] = field(default_factory=list)

    @property
    def count(self) -> int:
        return len(self.bands)

    @property
    def alpha_bands(self) -> List[int]:
        return [b.number for b in self.bands if b.alpha]

    @property
    def data_bands(self) -> List[int]:
        return [b.number for b in self.bands if not b.alpha]

    def describe(self) -> str:
        return "; ".join(b.describe() for b in self.bands)

    def number(self, name: str) -> int:
        """The band number of a canonical name (B4, NIR ...); SpectralError naming the raster, the name and the
        bands it has (and how each was identified) when there is none or more than one."""
        m = re.fullmatch(r"B(\d+)", name)
        if m:
            n = int(m.group(1))
            if not 1 <= n <= self.count:
                raise SpectralError(f"the raster {self.path} has {self.count} band(s), no b{n}: its bands are "
                                    f"{self.describe()}")
            return n
        found = [b for b in self.bands if b.name == name and not b.alpha]
        best = [b for b in found if b.level == min((f.level for f in found), default=NONE)]
        if len(best) == 1:
            return best[0].number
        if not best:
            raise SpectralError(f"the raster {self.path} has no band named {name}: its bands are {self.describe()}. "
                                f"Set the {name} band's number, or write the expression with b1 .. b{self.count}")
        raise SpectralError(f"the raster {self.path} has {len(best)} bands that are {name} (bands "
                            f"{', '.join(str(b.number) for b in best)}, each by its {EVIDENCE[best[0].level]}): set "
                            f"the {name} band's number; its bands are {self.describe()}")


def name_from_text(text: str) -> str:
    """The canonical band name a description or name item says ('Red edge', 'NIR1', 'Band 3 - Red'); ''."""
    tokens = {re.sub(r"\d+$", "", t) for t in re.split(r"[^a-z0-9]+", text.lower()) if t}
    joined = "".join(re.split(r"[^a-z]+", text.lower()))
    infrared = "infrared" in tokens and not OTHER_INFRARED & tokens
    for band in NAMED_BANDS:  # in their matching order: red edge before red, NIR before the visible bands
        if tokens & set(band.words) or any(p in joined for p in band.phrases) or (infrared and band.name == "NIR"):
            return band.name
    return ""


def wavelength_name(nm: float) -> str:
    for name, lo, hi in WAVELENGTH_RANGES_NM:
        if lo <= nm < hi:
            return name
    return ""


def _number(text: str) -> Optional[float]:
    m = re.search(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", text)
    return float(m.group(0)) if m else None


def wavelength_nm(key: str, value: str, units: str = "") -> Optional[float]:
    """The wavelength in nm of a metadata item (key, value), its unit from the key (_UM, _NM), the value ('790 nm',
    '0.79 um') or the raster's wavelength_units, else from its size (under 30: µm)."""
    v = _number(value)
    if v is None or v <= 0:
        return None
    hint = f"{key} {value} {units}".lower()
    if key.lower().endswith(("_um", "_micrometers")) or re.search(r"(\bum\b|µm|micro)", hint):
        return v * 1000.0
    if re.search(r"(nm\b|nano)", hint):
        return v
    return v * 1000.0 if v < 30 else v


def _from_metadata(meta: Dict[str, str], units: str) -> Tuple[str, str, int]:
    for key, value in meta.items():
        if key.lower() in NAME_KEYS and name_from_text(str(value)):
            return name_from_text(str(value)), f"its metadata item {key}={value}", METADATA
    for key, value in meta.items():
        low = key.lower()
        if "wavelength" in low and not any(w in low for w in ("unit", "fwhm", "width", "min", "max")):
            nm = wavelength_nm(key, str(value), units)
            if nm is not None and wavelength_name(nm):
                return wavelength_name(nm), f"its wavelength {nm:g} nm (metadata item {key})", WAVELENGTH
    return "", "", NONE


def identify(description: str, meta: Dict[str, str], colour: str = "", units: str = "") -> Tuple[str, str, int]:
    """(canonical name, how it was read, evidence level) of one band; ('', '', NONE) when nothing names it."""
    if name_from_text(description):
        return name_from_text(description), f"its description '{description}'", DESCRIPTION
    found = _from_metadata(meta, units)
    nm = wavelength_nm("description", description) if re.search(r"\d\s*nm\b", description.lower()) else None
    if found[2] > WAVELENGTH and nm is not None and wavelength_name(nm):
        return wavelength_name(nm), f"the wavelength {nm:g} nm in its description", WAVELENGTH
    if found[0]:
        return found
    if colour.lower().replace(" ", "") in COLOURS:
        return COLOURS[colour.lower().replace(" ", "")], f"its colour interpretation {colour}", COLOUR
    return "", "", NONE


def read_band_table(r: raster.RasterFile, overrides: Optional[BandOverrides] = None) -> BandTable:
    """What each band of the open raster ``r`` is; the ``overrides`` (band numbers the user set) first:
    SpectralError when one is not a band of the raster or two name one band."""
    from osgeo import gdal

    table = BandTable(r.path)
    units = next((v for k, v in r.metadata().items() if k.lower() == "wavelength_units"), "")
    for i in range(1, r.count + 1):
        band = r.band(i)
        colour = gdal.GetColorInterpretationName(band.GetColorInterpretation()) or ""
        meta = {**r.metadata(i, "IMAGERY"), **r.metadata(i)}
        band_units = next((v for k, v in meta.items() if k.lower() == "wavelength_units"), units)
        description = (band.GetDescription() or "").strip()
        if colour.lower() == "alpha":
            table.bands.append(BandInfo(i, description, alpha=True))
            continue
        name, how, level = identify(description, meta, colour, band_units)
        table.bands.append(BandInfo(i, description, name, how, level))
    taken: Dict[int, str] = {}
    for name, n in (overrides or BandOverrides()).items():
        if not 1 <= n <= r.count:
            raise SpectralError(f"the {name} band is set to band {n}, but the raster {r.path} has {r.count} band(s): "
                                f"{table.describe()}")
        if n in taken:
            raise SpectralError(f"band {n} of {r.path} is set as both the {taken[n]} and the {name} band")
        taken[n] = name
        info = table.bands[n - 1]
        info.name, info.how, info.level, info.alpha = name, f"the {name} band set to {n}", SET, False
    return table


__all__ = ["BAND_NAMES", "WAVELENGTH_RANGES_NM", "BandInfo", "BandTable", "identify", "name_from_text",
           "read_band_table", "wavelength_name", "wavelength_nm"]
