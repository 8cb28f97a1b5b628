"""The accuracy standards: NSSDA statements at 95 % confidence (FGDC-STD-007.3-1998) and the ASPRS 2014 and
2023 positional accuracy classes, as figured by :func:`core.report.residuals.accuracy_figures`."""
from __future__ import annotations

from typing import Any, Dict

from ..context import ReportContext
from ..html import esc, fmt, num
from ..labels import t

ASPRS_MIN_CHECKS = {2014: 20, 2023: 30}
NSSDA_MIN_CHECKS = 20


def accuracy_statements(ctx: ReportContext, acc: Dict[str, Any]) -> str:
    nssda = acc["nssda"]
    if nssda is None:
        return ""
    parts = ["<h3>" + esc(t("NSSDA accuracy at 95 % confidence (FGDC-STD-007.3-1998)")) + "</h3>"]
    if not acc["tested"]:
        parts.append('<p class="warn">No check points: the accuracy was <b>not tested</b>. The figures below '
                     "come from the control points' own residuals, which took part in the adjustment (not "
                     "independent, optimistic); the standard's “Compiled to meet” wording is used.</p>")
    elif nssda["n"] < NSSDA_MIN_CHECKS:
        parts.append(f'<p class="warn">The NSSDA asks for at least {NSSDA_MIN_CHECKS} check points; this test '
                     f"used {nssda['n']}: treat the figures as indicative.</p>")
    items = []
    h = nssda["horizontal"]
    if h is not None:
        ctx.figures["NSSDA_H"] = num(h["accuracy"])
        items.append(f'<li class="statement" data-key="nssda.horizontal" data-value="{h["accuracy"]!r}">'
                     f"{esc(h['statement'])}</li>")
        note = h.get("note", "")
        parts_note = f'<p class="note">Horizontal: {esc(note)}; RMSE_x / RMSE_y ratio {h["ratio"]:.2f}.</p>'
    else:
        parts_note = ""
    v = nssda["vertical"]
    if v is not None:
        ctx.figures["NSSDA_V"] = num(v["accuracy"])
        items.append(f'<li class="statement" data-key="nssda.vertical" data-value="{v["accuracy"]!r}">'
                     f"{esc(v['statement'])}</li>")
    elif acc["placeholder_z"]:
        items.append("<li>No vertical accuracy: the control heights are placeholders.</li>")
    parts.append("<ul class=\"statements\">" + "".join(items) + "</ul>" + parts_note)
    if acc["asprs"]:
        parts.append("<h3>" + esc(t("ASPRS positional accuracy class")) + "</h3>")
        rows = []
        for ed, a in acc["asprs"].items():
            hh, vv = a["horizontal"], a["vertical"]
            n_need = ASPRS_MIN_CHECKS[ed]
            if hh:
                ctx.figures[f"ASPRS_{ed}_H_CLASS_CM"] = hh["class_cm"]
            if vv:
                ctx.figures[f"ASPRS_{ed}_V_CLASS_CM"] = vv["class_cm"]
            rows.append(
                f"<tr><th>{'Edition 1 (2014)' if ed == 2014 else 'Edition 2 (2023)'}</th>"
                f'<td class="n" data-key="asprs.{ed}.h" data-value="{hh["class_cm"] if hh else ""}">'
                f"{fmt(hh and hh['class_cm'], 1)} cm</td>"
                f'<td class="n" data-key="asprs.{ed}.v" data-value="{vv["class_cm"] if vv else ""}">'
                f"{fmt(vv and vv['class_cm'], 1)} cm</td>"
                f'<td class="small">{esc(hh["statement"]) if hh else ""}'
                f"{'<br>' + esc(vv['statement']) if vv else ''}"
                + (f"<br><i>The standard asks for at least {n_need} check points; {acc['nssda']['n']} were "
                   "used.</i>" if acc["nssda"]["n"] < n_need else "")
                + ("<br><i>Edition 2 adds the check points' own survey error in quadrature: taken as 0 here "
                   "(not recorded in the workspace).</i>" if ed == 2023 else "")
                + (f"<br><i>Relative to {hh['gsd_cm']:.1f} cm pixels: {esc(hh['recommended_use'])} "
                   f"({hh['class_pixels']:.1f} pixels).</i>" if hh and hh.get("recommended_use") else "")
                + "</td></tr>")
        parts.append('<table class="asprs"><thead><tr><th>standard</th><th>horizontal class (RMSE)</th>'
                     "<th>vertical class (RMSE)</th><th>statement</th></tr></thead><tbody>" + "".join(rows)
                     + "</tbody></table>")
    return "".join(parts)
