"""The error the automatic control raises when it cannot run with the given input."""
from __future__ import annotations

from ..errors import GeorefError


class AutoControlError(GeorefError):
    """Automatic control cannot run (a reference that does not cover the block, too few matches); the message
    names the file and what was found."""


__all__ = ["AutoControlError"]
