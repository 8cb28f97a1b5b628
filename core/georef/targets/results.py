"""What Find targets returns and writes: each observation found (:class:`FoundObservation`: its pixel, the
detector's quality, its residual, how it was found), each target's status (:class:`TargetStatus`), the result
(:class:`FindTargetsResult`) and its products (:func:`write_products`: the gcp_list.txt Georeference reads, the
review layer, the JSON record)."""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional

import numpy as np

from ...io import gcp as gcpmod
from ...project.layout import write_json

TIED = "tied"  # the observation's mark was tied across photos and matched to the constellation
PROJECTED = "projected"  # found at the target's projection through the block
CLICK = "click"  # the user's click in the targets file, which no mark found answers


@dataclass
class FoundObservation:
    """One observation found: pixel (COLMAP convention), the detector's quality in [0, 1], the residual (px) of the
    target's triangulation (NaN when it is the target's only observation) and how it was found."""

    name: str
    image: str
    x: float
    y: float
    kind: str
    quality: float
    residual_px: float
    size_px: float
    source: str
    found: bool = True  # found by the machine, not placed by hand (the dock's mark)
    size_m: Optional[float] = None  # the mark's size on the ground (m), through the constellation's scale


@dataclass
class TargetStatus:
    name: str
    x: float
    y: float
    z: float
    found: bool
    observations: int
    fit: Optional[float] = None  # distance (world units) of its mark from it after the constellation fit
    note: str = ""


@dataclass
class FindTargetsResult:
    crs: str
    gcps_path: str
    layer_path: str
    json_path: str
    observations: List[FoundObservation] = field(default_factory=list)
    targets: List[TargetStatus] = field(default_factory=list)
    candidates: int = 0
    marks: int = 0  # tracks triangulated in the block
    tie_tolerance_px: float = 0.0
    fit_tolerance: float = 0.0
    fit_rms: float = float("nan")
    mirrored: bool = False
    prior: str = ""  # what narrowed the match ("EXIF GPS of n photos, x RMS"), empty without
    reports: List[str] = field(default_factory=list)  # what did not fit, never assigned
    seconds: float = 0.0

    @property
    def n_targets(self) -> int:
        return sum(1 for t in self.targets if t.found)

    @property
    def n_observations(self) -> int:
        return len(self.observations)

    def gcpset(self) -> gcpmod.GCPSet:
        pts = []
        for t in self.targets:
            obs = [gcpmod.Observation(o.image, o.x, o.y) for o in self.observations if o.name == t.name]
            if obs:
                pts.append(gcpmod.GroundPoint(t.name, t.x, t.y, t.z, observations=obs, sigma_given=False))
        return gcpmod.GCPSet(self.crs, pts)

    def to_dict(self) -> Dict:
        d = asdict(self)
        d["n_targets"], d["n_observations"] = self.n_targets, self.n_observations
        return d


def keep_clicks(result: FindTargetsResult, clicks: Dict[str, List[gcpmod.Observation]]) -> None:
    """The user's clicks no mark answers go to the output as they are (found False: placed by hand)."""
    for n, obs in clicks.items():
        for ob in obs:
            result.observations.append(FoundObservation(n, ob.image, ob.x, ob.y, CLICK, 1.0, float("nan"), 0.0,
                                                        CLICK, found=False))
        t = next(t for t in result.targets if t.name == n)
        t.found, t.observations = True, t.observations + len(obs)


def write_products(gs, result: FindTargetsResult) -> None:
    """The observations found as an OpenDroneMap gcp_list.txt (what Georeference reads), the targets as a
    GeoPackage for review, and the JSON record with every observation's quality."""
    from ...io.vector import write_points_gpkg

    os.makedirs(os.path.dirname(result.gcps_path) or ".", exist_ok=True)
    gcpmod.write_odm_gcp_list(result.gcpset(), result.gcps_path)
    rows = []
    for t in result.targets:
        res = [o.residual_px for o in result.observations if o.name == t.name and np.isfinite(o.residual_px)]
        rows.append({"name": t.name, "x": t.x, "y": t.y, "z": t.z, "found": int(t.found),
                     "observations": t.observations, "fit": t.fit,
                     "residual_px": float(np.sqrt(np.mean(np.square(res)))) if res else None, "note": t.note})
    write_points_gpkg(result.layer_path, "targets", rows,
                      [("name", "str"), ("found", "int"), ("observations", "int"), ("fit", "float"),
                       ("residual_px", "float"), ("note", "str")], crs=gs.crs)
    write_json(result.json_path, result.to_dict())


__all__ = ["CLICK", "PROJECTED", "TIED", "FindTargetsResult", "FoundObservation", "TargetStatus", "keep_clicks",
           "write_products"]
