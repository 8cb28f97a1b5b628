"""The error the georeferencing raises when it cannot run with the given input."""
from __future__ import annotations

from ..common.errors import ArchaeoOrthoError


class GeorefError(ArchaeoOrthoError, ValueError):
    """Georeferencing cannot run with the given input; the message says what was found."""


__all__ = ["GeorefError"]
