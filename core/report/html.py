"""HTML pieces of the report: escaping, number formats, tables, key-value lists, badges and CRS names.

Text only: no matplotlib here (plots are embedded by :mod:`core.report.figures`).
"""
from __future__ import annotations

import html
import math
from typing import Any, Optional, Sequence, Tuple

from .labels import t

MAX_TABLE_ROWS = 400  # longer tables are cut (the GeoPackage layers hold everything)


def esc(v: Any) -> str:
    return html.escape(str(v), quote=True)


def esc_json(text: str) -> str:
    """JSON inside <script>: only '</' needs escaping."""
    return text.replace("</", "<\\/")


def num(v: Any) -> Optional[float]:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def fmt(v: Any, decimals: int = 3, unit: str = "") -> str:
    f = num(v)
    if f is None:
        return "–"
    return f"{f:.{decimals}f}{(' ' + unit) if unit else ''}"


def cell(v: Any, decimals: int = 3, key: Optional[str] = None) -> str:
    """A numeric table cell; ``key`` names it for machines (``data-key``) with the full value."""
    f = num(v)
    attrs = ' class="n"'
    if key:
        attrs += f' data-key="{esc(key)}"'
        if f is not None:
            attrs += f' data-value="{f!r}"'
    return f"<td{attrs}>{fmt(v, decimals)}</td>"


def table(header: Sequence[str], rows: Sequence[Sequence[str]], cls: str = "", raw: bool = True,
          limit: int = MAX_TABLE_ROWS) -> str:
    """Rows are lists of ready HTML cells (``<td>...``) when ``raw``, else of texts to escape; the column headings
    in the report's language (i18n/make_catalog.py collects table()'s literal headings)."""
    out = [f'<table class="{cls}"><thead><tr>' + "".join(f"<th>{esc(t(h))}</th>" for h in header)
           + "</tr></thead><tbody>"]
    for r in rows[:limit]:
        cells = r if raw else [f"<td>{esc(c)}</td>" for c in r]
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table>")
    if len(rows) > limit:
        out.append(f'<p class="note">{len(rows) - limit} more rows not shown.</p>')
    return "".join(out)


def td(text: Any, cls: str = "") -> str:
    return f'<td class="{cls}">{esc(text)}</td>' if cls else f"<td>{esc(text)}</td>"


def kv(rows: Sequence[Tuple[str, str]]) -> str:
    """(label, HTML) rows; the labels in the report's language (i18n/make_catalog.py collects the sections'
    ("Label", value) pairs)."""
    return ('<table class="kv"><tbody>' + "".join(f"<tr><th>{esc(t(k))}</th><td>{v}</td></tr>" for k, v in rows)
            + "</tbody></table>")


def duration(sec: Any) -> str:
    s = num(sec)
    if s is None:
        return "–"
    if s < 60:
        return f"{s:.1f} s"
    if s < 3600:
        return f"{int(s // 60)} min {s % 60:02.0f} s"
    return f"{int(s // 3600)} h {int(s % 3600 // 60):02d} min"


def area_text(m2: Optional[float]) -> str:
    if m2 is None:
        return "–"
    if m2 >= 1e6:
        return f"{m2 / 1e6:.3f} km² ({m2 / 1e4:.1f} ha)"
    return f"{m2 / 1e4:.3f} ha ({m2:.0f} m²)"


def badge(kind: str, text: str) -> str:
    return f'<li class="{kind}"><span class="dot"></span>{text}</li>'


def crs_label(crs: Optional[str]) -> str:
    """A short name for a CRS given as EPSG code, WKT or proj string, e.g. "EPSG:32611 (WGS 84 / UTM zone 11N)";
    a proj string that matches an EPSG definition is named by it ("~" marks the match)."""
    if not crs:
        return "local model frame"
    try:
        from osgeo import osr

        srs = osr.SpatialReference()
        if srs.SetFromUserInput(str(crs)) != 0:
            return str(crs)
        code = srs.GetAuthorityCode(None)
        if code:
            return f"{srs.GetAuthorityName(None)}:{code} ({srs.GetName()})"
        for m, conf in srs.FindMatches() or []:
            if conf >= 70 and m.GetAuthorityCode(None):
                return f"~{m.GetAuthorityName(None)}:{m.GetAuthorityCode(None)} ({m.GetName()})"
        proj = srs.ExportToProj4() if srs.IsProjected() or srs.IsGeographic() else ""
        name = srs.GetName() or "unnamed CRS"
        return f"{name} (no EPSG code: {proj.strip()})" if proj else (srs.GetName() or str(crs))
    except Exception:  # noqa: BLE001 - GDAL raises or returns codes depending on UseExceptions
        return str(crs)


def raster_crs_name(wkt: str) -> str:
    """The name of a raster's CRS (its WKT), e.g. "EPSG:32633 (WGS 84 / UTM zone 33N)"; "none" without one."""
    from osgeo import osr

    if not wkt:
        return "none"
    srs = osr.SpatialReference(wkt=wkt)
    code = srs.GetAuthorityCode(None)
    name = srs.GetName() or "unnamed"
    return f"{srs.GetAuthorityName(None)}:{code} ({name})" if code else name
