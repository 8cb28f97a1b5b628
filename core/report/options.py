"""The options of the report stage (defaults in one place)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class ReportOptions:
    uncertainty: bool = True  # compute the bundle-adjustment covariance (the uncertainty section)
    write_layers: bool = True  # and write <workspace>/uncertainty/cameras.gpkg and points.gpkg
