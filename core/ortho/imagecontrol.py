"""One image orthorectified on its own (:mod:`core.ortho.single`): the record of its run (messages, progress)
and the ground control observed in it, shared by the space resection and the planar rectification."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, List, Tuple

import numpy as np

from ..common.progress import Progress
from .pixels import ImageMeta


@dataclass
class ImageRun:
    """One call of orthorectify_image: the image, its messages and progress."""

    name: str
    meta: ImageMeta
    progress: Progress
    warnings: List[str] = field(default_factory=list)
    log: List[str] = field(default_factory=list)

    def warn(self, msg: str) -> None:
        self.warnings.append(msg)
        self.progress.warning(msg)

    def info(self, msg: str) -> None:
        self.log.append(msg)
        self.progress.info(msg)


@dataclass
class ImageControl:
    """Ground control observed in the image: (point, observation) pairs, their world XYZ (working CRS) and
    pixels, and the indices of the control (not check) points."""

    pairs: List[Tuple[Any, Any]] = field(default_factory=list)
    xyz: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    px: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    control: List[int] = field(default_factory=list)
