"""The accuracy figures of the report, from georef/residuals.json, all through :mod:`core.georef.accuracy`
(the same functions behind the Processing outputs)."""
from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ..georef import accuracy


def residual_rows(residuals: Dict[str, Any], key: str = "points") -> List[Dict[str, Any]]:
    return [p for p in (residuals or {}).get(key, []) if isinstance(p, dict)]


def point_sets(points: Sequence[Dict[str, Any]]) -> Dict[str, List[Dict[str, Any]]]:
    return {
        "control": [p for p in points if p.get("status") == "used" and p.get("dx") is not None],
        "check": [p for p in points if p.get("status") == "check" and p.get("dx") is not None],
        "rejected": [p for p in points if p.get("status") == "rejected" and p.get("dx") is not None],
    }


def set_stats(rows: Sequence[Dict[str, Any]]) -> Dict[str, Any]:
    def col(k):
        return [np.nan if r.get(k) is None else float(r[k]) for r in rows]

    return accuracy.residual_stats(col("dx"), col("dy"), col("dz"))


def accuracy_figures(residuals: Dict[str, Any], gsd: Optional[float] = None) -> Dict[str, Any]:
    """Statistics, NSSDA and ASPRS figures from georef/residuals.json, all through core.accuracy.

    ``tested`` is True when check points exist (NSSDA "Tested ..."); otherwise the control points' residuals
    give a "Compiled to meet ..." figure (not independent: optimistic) and ``tested`` is False."""
    points = residual_rows(residuals)
    sets = point_sets(points)
    stats = {k: set_stats(v) for k, v in sets.items()}
    helmert = point_sets(residual_rows(residuals, "helmert_points"))["check"]
    stats["check_helmert_only"] = set_stats(helmert)
    placeholder = ((residuals or {}).get("statistics") or {}).get("placeholder_z") is not None
    tested = bool(sets["check"])
    basis = "check" if tested else ("control" if sets["control"] else None)
    out: Dict[str, Any] = {"sets": sets, "stats": stats, "placeholder_z": placeholder, "tested": tested,
                           "basis": basis, "nssda": None, "asprs": {}}
    if basis is None:
        return out
    st = stats[basis]
    nssda: Dict[str, Any] = {"n": st["n"], "horizontal": None, "vertical": None}
    if st["n_r"]:
        rep = accuracy.nssda_horizontal_report(st["rmse_x"], st["rmse_y"])
        nssda["horizontal"] = dict(rep, statement=accuracy.nssda_statement(rep["accuracy"], "horizontal",
                                                                           tested=tested))
    if st["n_z"] and not placeholder:
        v = accuracy.nssda_vertical(st["rmse_z"])
        nssda["vertical"] = {"accuracy": v, "statement": accuracy.nssda_statement(v, "vertical", tested=tested)}
    out["nssda"] = nssda
    if tested:
        for ed in (2014, 2023):
            a: Dict[str, Any] = {"horizontal": None, "vertical": None}
            if st["n_r"]:
                a["horizontal"] = accuracy.asprs_horizontal_class(st["rmse_x"], st["rmse_y"], gsd, edition=ed)
            if st["n_z"] and not placeholder:
                a["vertical"] = accuracy.asprs_vertical_class(st["rmse_z"], edition=ed)
            out["asprs"][ed] = a
    return out


def camera_position_figures(residuals: Dict[str, Any]) -> Optional[Dict[str, Any]]:
    cams = [c for c in residual_rows(residuals, "cameras") if c.get("dx") is not None]
    if not cams:
        return None
    used = [c for c in cams if c.get("used", True)]
    return {"rows": cams, "stats": set_stats(used), "excluded": [c for c in cams if not c.get("used", True)]}


# --------------------------------------------------------------------------------------------------
# sections
