"""The options of a spectral index: defaults in this one place, checked when made (a bad expression fails here)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from .errors import SpectralError
from .expression import parse

# the indices (Processing enum order) and their formulas over the band names of :mod:`.bands`
INDEX_CHOICES = ("ndvi", "ndre", "expression")
FORMULAS = {"ndvi": "(NIR - RED) / (NIR + RED)", "ndre": "(NIR - REDEDGE) / (NIR + REDEDGE)"}
# indices bounded to -1 .. 1 (normalised differences): their display range, whatever the data
NORMALISED = ("ndvi", "ndre")
# cells of one block the index is computed on (its bands read as float64): memory, not result
BLOCK_CELLS = 4_000_000


@dataclass
class BandOverrides:
    """Band numbers (1 = the first) that replace what the raster's band names say; 0 = from the names."""

    nir: int = 0
    red: int = 0
    red_edge: int = 0

    def items(self):
        """(band name, number) of the bands set."""
        return [(name, n) for name, n in (("NIR", self.nir), ("RED", self.red), ("REDEDGE", self.red_edge)) if n]


@dataclass
class IndexOptions:
    """One index of the raster ``input`` written to ``output``: ``index`` one of :data:`INDEX_CHOICES`; for
    "expression", ``expression`` over b1..bN and the band names (NIR, RED, REDEDGE / REG / RE, GREEN / GRE, BLUE)."""

    input: str
    output: str
    index: str = "ndvi"
    expression: str = ""
    bands: Optional[BandOverrides] = None
    block_cells: int = BLOCK_CELLS

    def __post_init__(self):
        self.index = str(self.index).strip().lower()
        if self.index not in INDEX_CHOICES:
            raise SpectralError(f"unknown spectral index {self.index!r}: choose one of {', '.join(INDEX_CHOICES)}")
        if self.bands is None:
            self.bands = BandOverrides()
        for name, n in (("NIR", self.bands.nir), ("red", self.bands.red), ("red-edge", self.bands.red_edge)):
            if not isinstance(n, int) or n < 0:
                raise SpectralError(f"the {name} band must be a band number (1 = the first) or 0 (from the raster's "
                                    f"band names), got {n!r}")
        if not self.input:
            raise SpectralError("no input raster given for the spectral index")
        if not self.output:
            raise SpectralError(f"no output file given for the spectral index of {self.input}")
        if self.block_cells < 1:
            raise SpectralError(f"block_cells must be at least 1, got {self.block_cells}")
        if self.index == "expression" and not self.expression.strip():
            raise SpectralError("the index 'expression' needs an expression, e.g. (NIR - RED) / (NIR + RED) or "
                                "(b4 - b3) / (b4 + b3)")
        parse(self.formula)  # a bad expression fails here, before any file is read

    @property
    def formula(self) -> str:
        return self.expression.strip() if self.index == "expression" else FORMULAS[self.index]

    @property
    def label(self) -> str:
        """The index's name in the band description and the log: NDVI, NDRE, Index (an expression)."""
        return self.index.upper() if self.index in FORMULAS else "Index"
