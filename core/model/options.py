"""The options of the model stage (Build 3-D model): defaults in this one place, and its error."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

from ..common.errors import ArchaeoOrthoError

GEOMETRIES = ("auto", "dsm", "points")
FORMATS = ("obj", "glb", "ply", "tiles")  # tiles: OGC 3D Tiles 1.1 (core.model.tiles), georeferenced blocks only
# a block whose photos look down steeper than this (median angle of the optical axes from the nadir, degrees) is
# vertical: its surface is a height field and the DSM describes it; more oblique blocks see walls and overhangs
VERTICAL_TILT_DEG = 20.0
MIN_ATLAS = 256


class ModelError(ArchaeoOrthoError, RuntimeError):
    """The 3-D model cannot be built from this workspace or with these options; the message says why and the fix."""


@dataclass
class ModelOptions:
    """Build 3-D model: the geometry (``auto``: the DSM's 2.5-D surface for a vertical block, the fused dense points'
    3-D surface for an oblique one, decided from the cameras' tilt), the face budget, the texture atlases and the
    files written (in ``<workspace>/model/``, or ``output_dir``)."""

    geometry: str = "auto"  # auto / dsm / points
    face_budget: int = 200_000  # faces at most (a laptop's viewer keeps a few hundred thousand fluid)
    atlas_size: int = 4096  # px, the side of each texture atlas (a power of two: every viewer and GPU takes it)
    max_atlases: int = 4  # atlases at most: the photos' detail is reduced to fit (memory: 48 MiB per 4096 atlas)
    formats: Sequence[str] = FORMATS
    texture: bool = True  # False: geometry only (a grey model)
    jpeg_quality: int = 90
    output_dir: Optional[str] = None  # the files there instead of <workspace>/model/

    def __post_init__(self):
        self.formats = tuple(str(f).lower() for f in self.formats)
        if self.geometry not in GEOMETRIES:
            raise ModelError(f"geometry must be one of {', '.join(GEOMETRIES)}, got {self.geometry!r}")
        bad = [f for f in self.formats if f not in FORMATS]
        if bad or not self.formats:
            raise ModelError(f"the model's formats must be some of {', '.join(FORMATS)}, got "
                             f"{', '.join(self.formats) or 'none'}")
        if not (isinstance(self.face_budget, int) and self.face_budget >= 2):
            raise ModelError(f"the face budget must be a whole number of faces, 2 or more, got {self.face_budget!r}: "
                             "give the most triangles the model may have (e.g. 200000)")
        size = self.atlas_size
        if not (isinstance(size, int) and MIN_ATLAS <= size <= 16384 and size & (size - 1) == 0):
            raise ModelError(f"the atlas size must be a power of two from {MIN_ATLAS} to 16384 pixels, got {size!r}")
        if not (isinstance(self.max_atlases, int) and self.max_atlases >= 1):
            raise ModelError(f"the number of atlases must be 1 or more, got {self.max_atlases!r}")
        if not 1 <= int(self.jpeg_quality) <= 100:
            raise ModelError(f"the JPEG quality must be 1 to 100, got {self.jpeg_quality}")

    def atlas_bytes(self) -> int:
        """The memory the atlases take at most (RGB, 8 bits)."""
        return 3 * self.atlas_size * self.atlas_size * self.max_atlases

