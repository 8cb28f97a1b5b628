"""The georeferenced workspace's frame, typed: what ``georef/transform.json`` holds, read once by ``Layout``.

The adjusted model of a georeferenced workspace lives in a local frame (small coordinates, for the adjustment's
and the dense matcher's precision): ``world = local + offset`` in ``crs``.  ``model_to_local`` maps the
unadjusted alignment model into that frame (absent in the oldest workspaces).  Every stage that needs the frame
gets a :class:`GeorefFrame` from ``Layout.load_transform`` / ``Layout.load_georef_model``; nobody unpacks the
JSON's keys.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, Optional

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..geometry.similarity import Similarity


class FrameError(ArchaeoOrthoError, ValueError):
    """A transform.json that cannot describe a frame (no offset, wrong shape)."""


@dataclass(frozen=True)
class GeorefFrame:
    """world = local + offset, in ``crs`` (a CRS string as the workspace records it; "" when the file has none)."""

    crs: str
    offset: np.ndarray  # (3,) float64, metres of the CRS's units
    model_to_local: Optional[Similarity] = None
    local_to_world: Optional[Similarity] = None
    source: str = ""
    adjusted: Optional[bool] = None

    def to_world(self, local_xyz) -> np.ndarray:
        """Local-frame points (N, 3) or (3,) to the CRS."""
        return np.asarray(local_xyz, dtype=np.float64) + self.offset

    def to_local(self, world_xyz) -> np.ndarray:
        """Points in the CRS (N, 3) or (3,) to the local frame."""
        return np.asarray(world_xyz, dtype=np.float64) - self.offset

    @classmethod
    def from_dict(cls, d: Dict[str, Any], path: str = "transform.json") -> "GeorefFrame":
        """The frame of a transform.json's content; FrameError naming ``path`` when it has no usable offset."""
        if not isinstance(d, dict):
            raise FrameError(f"{path} does not hold a georeference transform (a JSON object): run 'Georeference' "
                             "again")
        try:
            offset = np.asarray(d.get("offset", [0.0, 0.0, 0.0]), dtype=np.float64).reshape(3)
        except (TypeError, ValueError) as e:
            raise FrameError(f"{path}: 'offset' is not three numbers ({d.get('offset')!r}): run 'Georeference' "
                             "again") from e
        if not np.all(np.isfinite(offset)):
            raise FrameError(f"{path}: 'offset' is not finite ({offset.tolist()}): run 'Georeference' again")

        def sim(key: str) -> Optional[Similarity]:
            return Similarity.from_dict(d[key]) if isinstance(d.get(key), dict) else None

        adjusted = d.get("adjusted")
        return cls(str(d.get("crs") or ""), offset, sim("model_to_local"), sim("local_to_world"),
                   str(d.get("source") or ""), None if adjusted is None else bool(adjusted))


__all__ = ["FrameError", "GeorefFrame"]
