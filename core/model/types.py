"""The textured mesh the model stage builds and every writer (OBJ, PLY, GLB, 3D Tiles) reads."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np


@dataclass
class MeshPart:
    """Faces textured from one atlas image.

    ``vertices`` are float32 in a local frame: the world coordinate (workspace CRS, metres) is
    ``origin + vertices`` (x east, y north, z up), so that UTM coordinates keep their millimetres.
    ``uv`` is per vertex, glTF's convention (u to the right, v down from the atlas' top-left, in [0, 1]);
    the OBJ writer flips v.  A vertex shared by two charts is duplicated, so ``uv`` is one per vertex.
    """

    vertices: np.ndarray  # (N, 3) float32, local
    faces: np.ndarray  # (M, 3) uint32, counter-clockwise seen from outside / from above
    uv: Optional[np.ndarray] = None  # (N, 2) float32, or None for an untextured part
    atlas: Optional[np.ndarray] = None  # (H, W, 3) uint8 RGB
    normals: Optional[np.ndarray] = None  # (N, 3) float32, unit


@dataclass
class TexturedMesh:
    """A georeferenced model: parts sharing one origin and one CRS."""

    origin: np.ndarray  # (3,) float64, world coordinates of the local frame's zero
    parts: List[MeshPart] = field(default_factory=list)
    crs_wkt: Optional[str] = None  # None: a block in a model frame (no control); writers say so
    crs_name: str = ""  # e.g. "EPSG:32617", for messages and the .prj/.crs beside the files

    @property
    def face_count(self) -> int:
        return int(sum(len(p.faces) for p in self.parts))

    def world_vertices(self, part: MeshPart) -> np.ndarray:
        return self.origin[None, :] + part.vertices.astype(np.float64)
