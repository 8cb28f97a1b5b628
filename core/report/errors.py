"""The report's error."""
from __future__ import annotations

from ..common.errors import ArchaeoOrthoError


class ReportError(ArchaeoOrthoError, RuntimeError):
    """The report cannot be written; the message says why."""
