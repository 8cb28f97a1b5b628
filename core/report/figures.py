"""Plot helpers of the report: matplotlib figures (Agg canvas, no pyplot, so no GUI backend is touched)
embedded as PNG ``data:`` URIs, and the geometry and shading behind the plots."""
from __future__ import annotations

import base64
import io
import math
from typing import Optional

import numpy as np

from .html import esc
from .labels import t

DPI = 96


def new_figure(w: float = 7.0, h: float = 4.0):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=DPI)
    return fig


def embed(fig, alt: str, caption: str = "", cls: str = "") -> str:
    """The figure as an ``<figure>`` with the PNG inline (``caption`` is HTML); ``alt`` and ``caption`` in the
    report's language where they are catalogued (i18n/make_catalog.py collects embed()'s literal texts)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight", facecolor="white")
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    cap = f"<figcaption>{t(caption)}</figcaption>" if caption else ""
    return (f'<figure class="{cls}"><img alt="{esc(t(alt))}" src="data:image/png;base64,{data}">{cap}</figure>')


def equal_xy(ax) -> None:
    ax.set_aspect("equal", adjustable="datalim")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.tick_params(labelsize=7)
    ax.grid(True, color="#ddd", lw=0.5)


def hull(xy: np.ndarray) -> Optional[np.ndarray]:
    """Convex hull (closed ring) of the robust bulk of 2-D points (1st-99th percentile box)."""
    if len(xy) < 3:
        return None
    lo, hi = np.percentile(xy, 1, axis=0), np.percentile(xy, 99, axis=0)
    m = np.all((xy >= lo) & (xy <= hi), axis=1)
    pts = xy[m] if m.sum() >= 3 else xy
    try:
        from scipy.spatial import ConvexHull

        h = ConvexHull(pts)
    except Exception:  # noqa: BLE001 - degenerate (collinear) points
        return None
    ring = pts[h.vertices]
    return np.vstack([ring, ring[:1]])


def poly_area(ring: Optional[np.ndarray]) -> Optional[float]:
    if ring is None:
        return None
    x, y = ring[:, 0], ring[:, 1]
    return float(0.5 * abs(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1])))


def nice(v: float) -> float:
    """A round number near v (1, 2, 5 × 10^k) for plot keys."""
    if not v or not math.isfinite(v) or v <= 0:
        return 1.0
    e = math.floor(math.log10(v))
    for m in (5, 2, 1):
        if m * 10 ** e <= v:
            return float(m * 10 ** e)
    return float(10 ** e)


def hillshade(z: np.ndarray, dx: float, dy: float, azimuth: float = 315.0, altitude: float = 45.0) -> np.ndarray:
    """Hillshade in [0, 1] of a height grid (NaN = no data, shaded as flat); cell sizes dx, dy in metres."""
    zf = np.where(np.isfinite(z), z, np.nanmedian(z) if np.isfinite(z).any() else 0.0)
    gy, gx = np.gradient(zf, dy, dx)
    slope = np.pi / 2 - np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az = math.radians(360.0 - azimuth + 90.0)
    alt = math.radians(altitude)
    hs = np.sin(alt) * np.sin(slope) + np.cos(alt) * np.cos(slope) * np.cos(az - aspect)
    return np.clip(hs, 0.0, 1.0)


def draw_dem(fig, ax, zz: np.ndarray, valid: np.ndarray, cell_x: float, cell_y: float, extent) -> Optional[tuple]:
    """A DSM preview: terrain colours shaded by the hillshade, no-data transparent, with a colour bar;
    returns the (1st, 99th) height percentiles shown, or None when no cell has data."""
    if not valid.any():
        return None
    lo, hi = np.nanpercentile(zz, [1, 99])
    hs = hillshade(zz, cell_x, cell_y)
    from matplotlib import cm, colormaps
    from matplotlib.colors import Normalize

    rgb = colormaps["terrain"](Normalize(lo, hi)(np.nan_to_num(zz, nan=lo)))[..., :3]
    shaded = np.clip(rgb * (0.35 + 0.65 * hs[..., None]), 0, 1)
    rgba = np.dstack([shaded, valid.astype(float)])
    ax.imshow(rgba, extent=extent, interpolation="nearest")
    sm = cm.ScalarMappable(norm=Normalize(lo, hi), cmap="terrain")
    fig.colorbar(sm, ax=ax, shrink=0.7, label=t("height (m)"))
    return lo, hi


def draw_image(ax, arr: np.ndarray, alpha: np.ndarray, extent) -> None:
    """An orthomosaic preview: bands stretched between the 0.5th and 99.5th percentile of the valid cells."""
    if arr.shape[2] == 1:
        arr = np.repeat(arr, 3, axis=2)
    lo, hi = np.percentile(arr[alpha], [0.5, 99.5]) if alpha.any() else (0.0, 255.0)
    rgb = np.clip((arr - lo) / max(hi - lo, 1e-9), 0, 1)
    ax.imshow(np.dstack([rgb, alpha.astype(float)]), extent=extent, interpolation="nearest")
