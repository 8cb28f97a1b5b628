"""The options of the report stage (defaults in one place)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional


@dataclass
class ReportOptions:
    uncertainty: bool = True  # compute the bundle-adjustment covariance (the uncertainty section)
    write_layers: bool = True  # and write <workspace>/uncertainty/cameras.gpkg and points.gpkg
    output_html: Optional[str] = None  # the report there instead of <workspace>/report.html
