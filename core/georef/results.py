"""What a georeferencing returns: the residual rows, the outliers, and ``GeorefResult`` with its files.

``GeorefResult.save`` writes ``transform.json`` and ``residuals.json`` (the workspace format: the keys are
read back by the report, the dock and older workspaces); ``core.project.frame.GeorefFrame`` (through
``Layout.load_transform``) reads a transform back, typed.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ..common.files import atomic_write_text
from ..geometry.similarity import Similarity
from ..io.gcp import CHECK, CONTROL

TRANSFORM_FILE = "transform.json"
RESIDUALS_FILE = "residuals.json"
FORMAT_VERSION = 1

# point status values in residual rows
USED = "used"  # control point that took part in the adjustment
REJECTED = "rejected"  # control point removed as an outlier (evaluated like a check point)
CHECKED = "check"  # check point
NOT_TRIANGULATED = "not triangulated"


@dataclass
class PointResidual:
    """One ground point: estimated (from the images, world) minus given coordinates."""

    name: str
    role: str  # CONTROL / CHECK
    status: str  # USED / REJECTED / CHECKED / NOT_TRIANGULATED
    x: float
    y: float
    z: float
    dx: Optional[float] = None
    dy: Optional[float] = None
    dz: Optional[float] = None
    n_obs: int = 0  # observations used in the triangulation
    observations: List[Dict[str, Any]] = field(default_factory=list)  # {"image", "px"} (px None: not used)
    notes: List[str] = field(default_factory=list)
    # control points: the sigmas the adjustment weighted the coordinates with (given, or estimated from the data)
    sigma_xy: Optional[float] = None
    sigma_z: Optional[float] = None

    @property
    def error_3d(self) -> Optional[float]:
        if self.dx is None:
            return None
        return math.sqrt(self.dx ** 2 + self.dy ** 2 + self.dz ** 2)

    def to_dict(self) -> Dict[str, Any]:
        return {"name": self.name, "role": self.role, "status": self.status, "x": self.x, "y": self.y,
                "z": self.z, "dx": self.dx, "dy": self.dy, "dz": self.dz, "n_obs": self.n_obs,
                "observations": self.observations, "notes": self.notes, "sigma_xy": self.sigma_xy,
                "sigma_z": self.sigma_z}


@dataclass
class CameraResidual:
    image: str
    x: float
    y: float
    z: float
    dx: float
    dy: float
    dz: float
    used: bool = True
    sigma_xy: Optional[float] = None  # the sigmas the adjustment weighted the position with (given or estimated)
    sigma_z: Optional[float] = None

    def to_dict(self) -> Dict[str, Any]:
        return dict(self.__dict__)


@dataclass
class Outlier:
    kind: str  # "control point", "observation", "camera position"
    name: str  # point name or image name (camera position)
    residual: float
    unit: str  # "m", "px", "sigma"
    stage: str  # "triangulation", "helmert", "adjustment"
    image: Optional[str] = None  # for observations
    message: str = ""

    def to_dict(self) -> Dict[str, Any]:
        return dict(self.__dict__)


def _rmse(rows: Sequence[PointResidual]) -> Dict[str, Optional[float]]:
    d = np.array([[r.dx, r.dy, r.dz] for r in rows if r.dx is not None], dtype=float).reshape(-1, 3)
    if len(d) == 0:
        return {"n": 0, "x": None, "y": None, "z": None, "xy": None, "xyz": None}
    m = np.sqrt(np.mean(d ** 2, axis=0))
    return {"n": int(len(d)), "x": float(m[0]), "y": float(m[1]), "z": float(m[2]),
            "xy": float(math.sqrt(m[0] ** 2 + m[1] ** 2)), "xyz": float(np.sqrt(np.sum(m ** 2)))}


@dataclass
class GeorefResult:
    reconstruction: Any  # adjusted pycolmap.Reconstruction in the local frame (world - offset)
    model_to_local: Similarity  # initial Helmert: sparse model frame -> local frame
    offset: np.ndarray  # (3,) world = local + offset
    crs: str
    source: str  # "control points" or "camera positions"
    points: List[PointResidual] = field(default_factory=list)  # after the adjustment
    helmert_points: List[PointResidual] = field(default_factory=list)  # after the Helmert step only
    cameras: List[CameraResidual] = field(default_factory=list)
    mean_reprojection_error: float = float("nan")  # tie points, px, after the adjustment
    gcp_reprojection_error: float = float("nan")  # GCP observations used, px (mean)
    warnings: List[str] = field(default_factory=list)
    outliers: List[Outlier] = field(default_factory=list)
    adjusted: bool = True
    refined_intrinsics: Dict[int, List[float]] = field(default_factory=dict)
    statistics: Dict[str, Any] = field(default_factory=dict)  # iterations, sizes, timings
    # control points / camera positions given without sigmas: their estimated sigmas, one dict per group
    # (core.georef.control_sigma.SigmaEstimate.to_dict)
    sigma_estimates: List[Dict[str, Any]] = field(default_factory=list)

    @property
    def similarity(self) -> Similarity:
        return self.model_to_local

    @property
    def local_to_world(self) -> Similarity:
        return Similarity.translation_only(self.offset)

    def to_world(self, xyz_local) -> np.ndarray:
        return np.asarray(xyz_local, dtype=float) + self.offset

    def to_local(self, xyz_world) -> np.ndarray:
        return np.asarray(xyz_world, dtype=float) - self.offset

    def rmse(self, role: str = CHECK, helmert: bool = False) -> Dict[str, Optional[float]]:
        rows = self.helmert_points if helmert else self.points
        if role == CHECK:
            rows = [r for r in rows if r.status == CHECKED]
        else:
            rows = [r for r in rows if r.role == role and r.status == USED]
        return _rmse(rows)

    def transform_dict(self) -> Dict[str, Any]:
        return {
            "format": "archaeoortho-georef-transform",
            "version": FORMAT_VERSION,
            "crs": self.crs,
            "offset": [float(v) for v in self.offset],
            "note": "the adjusted model is in the local frame: world = local + offset; "
                    "model_to_local maps the unadjusted alignment model into the local frame",
            "local_to_world": self.local_to_world.to_dict(),
            "model_to_local": self.model_to_local.to_dict(),
            "model_to_world": Similarity.translation_only(self.offset).compose(self.model_to_local).to_dict(),
            "source": self.source,
            "adjusted": self.adjusted,
        }

    def residuals_dict(self) -> Dict[str, Any]:
        return {
            "format": "archaeoortho-georef-residuals",
            "version": FORMAT_VERSION,
            "crs": self.crs,
            "points": [p.to_dict() for p in self.points],
            "helmert_points": [p.to_dict() for p in self.helmert_points],
            "cameras": [c.to_dict() for c in self.cameras],
            "rmse": {"control": self.rmse(CONTROL), "check": self.rmse(CHECK),
                     "check_helmert_only": self.rmse(CHECK, helmert=True)},
            "mean_reprojection_error_px": _finite_or_none(self.mean_reprojection_error),
            "gcp_reprojection_error_px": _finite_or_none(self.gcp_reprojection_error),
            "refined_intrinsics": {str(k): v for k, v in self.refined_intrinsics.items()},
            "sigma_estimates": list(self.sigma_estimates),
            "warnings": list(self.warnings),
            "outliers": [o.to_dict() for o in self.outliers],
            "statistics": self.statistics,
        }

    def to_dict(self) -> Dict[str, Any]:
        return {"transform": self.transform_dict(), "residuals": self.residuals_dict()}

    def save(self, folder: str) -> Dict[str, str]:
        """Write transform.json and residuals.json into ``folder`` (atomically); returns the paths."""
        os.makedirs(folder, exist_ok=True)
        paths = {}
        for name, data in ((TRANSFORM_FILE, self.transform_dict()), (RESIDUALS_FILE, self.residuals_dict())):
            path = os.path.join(folder, name)
            _atomic_write(path, json.dumps(_jsonable(data), indent=1, allow_nan=False))
            paths[name] = path
        return paths


def _finite_or_none(v) -> Optional[float]:
    return float(v) if v is not None and np.isfinite(v) else None


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def _atomic_write(path: str, text: str) -> None:
    atomic_write_text(path, text)


__all__ = ["CHECKED", "CameraResidual", "FORMAT_VERSION", "GeorefResult", "NOT_TRIANGULATED", "Outlier",
           "PointResidual", "REJECTED", "RESIDUALS_FILE", "TRANSFORM_FILE", "USED"]
