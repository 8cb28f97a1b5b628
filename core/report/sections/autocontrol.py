"""The automatic control in the georeferencing section (issue 16): the reference, how many matches survived each
step, why candidates were dropped, and a map of the automatic GCPs with their residuals.  Empty when the current
georeferencing did not use automatic control (``georef/autocontrol.json`` absent, or none of its points among
the adjustment's)."""
from __future__ import annotations

from collections import Counter
from typing import Any, Dict, List

import numpy as np

from ...geometry.crs import linear_unit
from ...georef.autocontrol.candidates import KEPT, reason
from ...project.layout import read_json
from ..context import ReportContext
from ..figures import embed, equal_xy, new_figure
from ..html import crs_label, esc, fmt, kv, table
from ..labels import t

_STEPS = (("matches", "matches found (ratio test)"), ("similarity_inliers", "fit one similarity (RANSAC)"),
          ("tile_inliers", "fit the affine of their tile"), ("candidates", "tied back to the photos"),
          ("observed", "seen in at least 2 photos, DSM height trusted"),
          ("consistent", "agree with one similarity model -> world"), ("kept", "kept by the adjustment"))


def subsection(ctx: ReportContext) -> str:
    """The automatic control's HTML ('' when the georeferencing did not use it)."""
    doc = read_json(ctx.d.layout.autocontrol_json)  # None when absent or unreadable
    rows = {r.get("name"): r for r in ((ctx.d.residuals or {}).get("points") or [])}
    cands: List[Dict[str, Any]] = (doc or {}).get("candidates") or []
    if not cands or not any(c.get("name") in rows for c in cands):
        return ""
    f = doc.get("figures") or {}
    parts = ["<h3>" + esc(t("Automatic control")) + "</h3>", kv([
        ("Reference orthophoto", esc(doc.get("reference_ortho", "–"))),
        ("Reference DSM", esc(doc.get("reference_dsm", "–"))),
        ("Rough position (prior)", esc(doc.get("prior", "–"))),
        ("Reference CRS", esc(crs_label(doc.get("crs")))),
        ("Common resolution of the match", f"{fmt(doc.get('gsd'), 3)} {_unit(doc.get('crs'))} per pixel"),
    ])]
    parts.append(table(["step", "matches / points"], [[label, str(f[k])] for k, label in _STEPS if k in f],
                       raw=False))
    dropped = doc.get("dropped") or dict(Counter(reason(c["status"]) for c in cands
                                                 if c.get("status") != KEPT).most_common())
    if dropped:
        parts.append(table(["dropped because", "candidates"], [[k, str(v)] for k, v in dropped.items()],
                           raw=False))
    parts.append(_map(cands, rows))
    return "".join(parts)


def _unit(crs) -> str:
    """'m' for a CRS in metres, else its unit's name (US survey foot, ...) as the CRS declares it."""
    name, metres = linear_unit(str(crs or ""))
    return "m" if metres == 1.0 else (name or "units")


def _map(cands: List[Dict[str, Any]], rows: Dict[str, Dict[str, Any]]) -> str:
    fig = new_figure(7.0, 5.8)
    ax = fig.add_subplot(111)
    off = np.array([[c["x"], c["y"]] for c in cands if c.get("status") != "kept"], dtype=float).reshape(-1, 2)
    if len(off):
        ax.scatter(off[:, 0], off[:, 1], s=14, c="#999999", marker="x", lw=0.8, label=t("dropped candidates"))
    used = [(c, rows[c["name"]]) for c in cands if c.get("name") in rows and rows[c["name"]].get("dx") is not None]
    if used:
        xy = np.array([[c["x"], c["y"]] for c, _ in used], dtype=float)
        dxy = np.array([float(np.hypot(r["dx"], r["dy"])) for _, r in used])
        ok = np.array([r.get("status") == "used" for _, r in used])
        sc = ax.scatter(xy[ok, 0], xy[ok, 1], c=dxy[ok], cmap="viridis", s=30, marker="^", edgecolors="k",
                        linewidths=0.4, label=t("automatic GCPs (colour: XY residual)"))
        if (~ok).any():
            ax.scatter(xy[~ok, 0], xy[~ok, 1], s=40, c="#d62728", marker="X", label=t("rejected by the adjustment"))
        fig.colorbar(sc, ax=ax, shrink=0.7, label=t("XY residual (m)"))
    ax.legend(fontsize=7, loc="lower left")
    equal_xy(ax)
    ax.set_title(t("automatic control points"), fontsize=9)
    return embed(fig, "automatic control points", "Where the automatic GCPs lie (triangles, coloured by their "
                 "horizontal residual after the adjustment), the ones the adjustment rejected (red) and the "
                 "candidates dropped before it (grey): a change between the epochs, a height the DSM does not "
                 "give, a point found in one photo only.")


__all__ = ["subsection"]
