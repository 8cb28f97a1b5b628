"""The error of the spectral indices."""
from __future__ import annotations

from ..common.errors import ArchaeoOrthoError

MAX_EXPRESSION_CHARS = 2000


class SpectralError(ArchaeoOrthoError, ValueError):
    """A spectral index cannot be made from this raster or expression; the message names the file (or the
    expression) and the problem."""
