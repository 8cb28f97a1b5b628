"""Options of Find targets (core.georef.targets.stage.find_targets)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Tuple

from ..errors import GeorefError

AUTO = "auto"
CROSS = "cross"
CHECKERBOARD = "checkerboard"
CIRCLE = "circle"
ARUCO = "aruco"  # a coded target: the kind is ARUCO, the dictionary names it (OpenCV's DICT_... names)
PLAIN_KINDS: Tuple[str, ...] = (CROSS, CHECKERBOARD, CIRCLE)
DEFAULT_DICTIONARY = "DICT_4X4_50"
DICTIONARIES: Tuple[str, ...] = ("DICT_4X4_50", "DICT_4X4_100", "DICT_4X4_250", "DICT_5X5_50", "DICT_5X5_100",
                                 "DICT_6X6_50", "DICT_6X6_250", "DICT_7X7_50", "DICT_ARUCO_ORIGINAL",
                                 "DICT_APRILTAG_16h5", "DICT_APRILTAG_25h9", "DICT_APRILTAG_36h10",
                                 "DICT_APRILTAG_36h11")
KINDS: Tuple[str, ...] = (AUTO,) + PLAIN_KINDS + DICTIONARIES


@dataclass
class FindTargetsOptions:
    """``kind``: AUTO (crosses, checkerboards, circles and ``DEFAULT_DICTIONARY`` markers), one of PLAIN_KINDS or
    an OpenCV ArUco/AprilTag dictionary name.  ``target_size``: the target's side or diameter (m), when known:
    marks whose size on the ground (pixels x depth / focal length x the constellation's scale) disagrees with it
    by more than a factor 2 are left out.  ``crs``: the
    coordinates' CRS where the targets file names none.  ``output``: the gcp_list.txt to write (default: the
    workspace's georef/targets/gcp_list.txt); ``layer``: the GeoPackage of the found marks (default beside it).
    ``min_size_px``: the smallest target (side or diameter, pixels) looked for; ``max_size_fraction``: the
    largest, as a fraction of the photo's shorter side.  ``targets``: the surveyed targets, a CSV or gcp_list.txt of
    coordinates (pixel columns ignored): what Find targets looks for."""

    kind: str = AUTO
    target_size: Optional[float] = None
    crs: Optional[str] = None
    output: Optional[str] = None
    layer: Optional[str] = None
    min_size_px: float = 8.0
    max_size_fraction: float = 0.2
    num_threads: int = 0  # 0: as many as the machine has
    targets: Optional[str] = None

    def __post_init__(self) -> None:
        """GeorefError naming the option for a kind that is not one, or a size out of range (before any work)."""
        kind = str(self.kind or AUTO)
        low = kind.lower()
        self.kind = low if low in (AUTO,) + PLAIN_KINDS else next((d for d in DICTIONARIES if d.lower() == low), kind)
        if self.kind not in KINDS:
            raise GeorefError(f"Find targets: unknown target kind {kind!r}; choose one of {', '.join(KINDS)}")
        if self.target_size is not None and not (math.isfinite(self.target_size) and self.target_size > 0):
            raise GeorefError(f"Find targets: the target size must be a positive length (m) or none, not "
                              f"{self.target_size!r}")
        if not (math.isfinite(self.min_size_px) and self.min_size_px > 0):
            raise GeorefError(f"FindTargetsOptions.min_size_px must be a positive number, not {self.min_size_px!r}")
        if not (0 < self.max_size_fraction <= 1):
            raise GeorefError(f"FindTargetsOptions.max_size_fraction must be in (0, 1], not {self.max_size_fraction!r}")

    def kinds(self) -> Tuple[Tuple[str, ...], Tuple[str, ...]]:
        """(plain kinds, dictionaries) to look for."""
        if self.kind == AUTO:
            return PLAIN_KINDS, (DEFAULT_DICTIONARY,)
        if self.kind in PLAIN_KINDS:
            return (self.kind,), ()
        return (), (self.kind,)
