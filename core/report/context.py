"""What the sections of one report share: the data read, the key figures and "at a glance" lines they add,
the warnings, and the bundle-adjustment uncertainty computed before them."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

from ..common.progress import Progress
from .data import ReportData


class Skip(Exception):
    """A section without its inputs: the message is shown instead of the section."""


@dataclass
class ReportContext:
    d: ReportData
    progress: Progress
    figures: Dict[str, Any] = field(default_factory=dict)  # the key figures (Processing outputs, report-data)
    glance: List[str] = field(default_factory=list)  # "at a glance" badges (HTML <li>)
    warnings: List[str] = field(default_factory=list)
    layers: Dict[str, str] = field(default_factory=dict)  # uncertainty GeoPackages
    unc: Any = None  # core.georef.uncertainty.UncertaintyResult, when computed
    unc_error: Optional[str] = None  # why it was not
    acc: Optional[Dict[str, Any]] = None  # residuals.accuracy_figures()
    gsd: Optional[float] = None  # set by the summary section
