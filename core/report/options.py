"""The options of the report stage (defaults in one place)."""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Optional

from .errors import ReportError


@dataclass
class ReportOptions:
    uncertainty: bool = True  # compute the bundle-adjustment covariance (the uncertainty section)
    write_layers: bool = True  # and write <workspace>/uncertainty/cameras.gpkg and points.gpkg
    output_html: Optional[str] = None  # the report there instead of <workspace>/report.html
    language: str = ""  # its headings and figure labels in this language ("de", "it"; "" English): core/report/labels

    def __post_init__(self):
        if not re.fullmatch(r"([a-z]{2,3}([_-][A-Za-z]{2})?)?", self.language or ""):
            raise ReportError(f"language: {self.language!r} is not a language code such as 'de' or 'it'")
        code = re.split("[_-]", self.language or "")[0]
        self.language = "" if code == "en" else code
