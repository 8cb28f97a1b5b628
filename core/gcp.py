"""Ground control: GCPs, check points, camera positions; readers and writers.

Pixel coordinates: origin at the upper-left corner of the upper-left pixel,
x to the right, y down (the same convention as COLMAP, whose pixel centres
sit at +0.5).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional

CONTROL = "control"
CHECK = "check"


class GCPError(ValueError):
    """A problem with a ground-control file; the message names file, line and reason."""


@dataclass
class Observation:
    image: str
    x: float
    y: float


@dataclass
class GroundPoint:
    name: str
    x: float
    y: float
    z: float
    sigma_xy: float = 0.02
    sigma_z: float = 0.05
    role: str = CONTROL  # CONTROL or CHECK
    observations: List[Observation] = field(default_factory=list)


@dataclass
class GCPSet:
    crs: str  # as given: "EPSG:xxxx", WKT or a proj string
    points: List[GroundPoint] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)

    def by_name(self, name: str) -> Optional[GroundPoint]:
        for p in self.points:
            if p.name == name:
                return p
        return None


@dataclass
class CameraPosition:
    image: str
    x: float
    y: float
    z: float
    sigma_xy: float = 5.0
    sigma_z: float = 10.0
