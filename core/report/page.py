"""The page around the sections: the head, the "at a glance" cards and lines, the footer and the
machine-readable copy of the key figures (``<script id="report-data">``, read back by
:func:`read_report_data`)."""
from __future__ import annotations

import datetime as _dt
import json
import os
from typing import Any, Dict, List, Optional, Sequence

from .context import ReportContext
from .html import badge, duration, esc, esc_json, fmt, num
from .labels import current_language, t

# the plugin folder (metadata.txt holds the version)
_PLUGIN_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CSS = """
body{font-family:-apple-system,"Segoe UI",Roboto,"DejaVu Sans",Arial,sans-serif;color:#222;margin:0;background:#f4f5f7}
main{max-width:1180px;margin:0 auto;padding:16px 28px 40px;background:#fff}
h1{font-size:24px;margin:8px 0 2px}h2{font-size:19px;border-bottom:2px solid #4477aa;padding-bottom:3px;margin-top:34px}
h3{font-size:15px;margin:22px 0 6px;color:#234}
.sub{color:#666;font-size:12px;margin:0 0 12px}
nav{font-size:13px;margin:8px 0 14px}nav a{margin-right:14px;color:#2a5d9f;text-decoration:none}
.cards{display:grid;grid-template-columns:repeat(auto-fill,minmax(165px,1fr));gap:10px;margin:12px 0}
.card{border:1px solid #d6dde6;border-radius:6px;padding:8px 10px;background:#f8fafc}
.card .v{font-size:20px;font-weight:600;color:#1d3b5e}.card .l{font-size:12px;color:#555}
ul.glance{list-style:none;padding:0;margin:8px 0}ul.glance li{margin:3px 0;font-size:14px}
.dot{display:inline-block;width:10px;height:10px;border-radius:50%;margin-right:8px;background:#999}
li.ok .dot{background:#2e9e44}li.warn .dot{background:#e69f00}li.bad .dot{background:#c0392b}
table{border-collapse:collapse;font-size:12px;margin:6px 0;width:auto}
th,td{border:1px solid #dde2e8;padding:3px 6px;text-align:left;vertical-align:top}
thead th{background:#eef2f7}tbody tr:nth-child(even){background:#fafbfc}
td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
table.kv th{background:#f3f5f8;font-weight:600;width:300px}
td.small,.small{font-size:11px}td.ok,p.ok{color:#1e7b34}td.warn,p.warn,li.warn{color:#8a5a00}
td.bad,li.bad{color:#a3271b;font-weight:600}td.chk{color:#1d3b5e;font-weight:600}
p.skip{color:#666;font-style:italic}p.note,.note{color:#555;font-size:12px}
.param{display:inline-block;margin:0 10px 2px 0;white-space:nowrap}
ul.statements li{font-size:15px;font-weight:600;color:#1d3b5e;margin:4px 0}
figure{margin:10px 0}figure img{max-width:100%;border:1px solid #e3e6ea}
figcaption{font-size:12px;color:#555;margin-top:3px}
details{margin:6px 0}summary{cursor:pointer;color:#2a5d9f;font-size:13px}
section.skipped h2{color:#777;border-color:#bbb}
footer{margin-top:30px;font-size:11px;color:#777;border-top:1px solid #ddd;padding-top:6px}
"""

# the titles marked for the catalogue (t() at import is English), translated where shown
SECTIONS = (("summary", t("Summary")), ("orientation", t("Orientation quality")),
            ("georeferencing", t("Georeferencing")), ("uncertainty", t("Uncertainty")), ("products", t("Products")))


def version() -> str:
    path = os.path.join(_PLUGIN_DIR, "metadata.txt")
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("version="):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return "?"


def cards(fig: Dict[str, Any], georef: bool) -> str:
    cards = []

    def add(label, value, key=None):
        k = f' data-key="card.{key}"' if key else ""
        cards.append(f'<div class="card"><div class="v"{k}>{value}</div><div class="l">{esc(label)}</div></div>')

    if fig.get("REGISTERED_IMAGES") is not None:
        add(t("images aligned"), f"{fig['REGISTERED_IMAGES']} / {fig.get('IMAGES')}")
    if fig.get("MEAN_REPROJECTION_ERROR") is not None:
        add(t("mean reprojection error"), fmt(fig["MEAN_REPROJECTION_ERROR"], 2, "px"))
    if fig.get("GSD") is not None:
        add(t("ground sample distance"), fmt(fig["GSD"] * 100, 1, "cm"))
    if fig.get("AREA_M2") is not None:
        add(t("area"), f"{fig['AREA_M2'] / 1e4:.2f} ha")
    if fig.get("CHECK_RMSE_XY") is not None:
        add(t("check RMSE XY"), fmt(fig["CHECK_RMSE_XY"], 3, "m"), "check_xy")
    if fig.get("CHECK_RMSE_Z") is not None and fig.get("NSSDA_V") is not None:
        add(t("check RMSE Z"), fmt(fig["CHECK_RMSE_Z"], 3, "m"), "check_z")
    if fig.get("NSSDA_H") is not None:
        add(t("NSSDA horizontal 95 %"), fmt(fig["NSSDA_H"], 3, "m"))
    if fig.get("NSSDA_V") is not None:
        add(t("NSSDA vertical 95 %"), fmt(fig["NSSDA_V"], 3, "m"))
    if fig.get("ASPRS_2014_H_CLASS_CM") is not None:
        add(t("ASPRS 2014 horizontal class"), fmt(fig["ASPRS_2014_H_CLASS_CM"], 1, "cm"))
    if fig.get("CAMERA_RMSE_XY") is not None:
        add(t("camera position RMSE XY (the block's fit to the positions)"), fmt(fig["CAMERA_RMSE_XY"], 2, "m"))
    if fig.get("POINT_STD_XY_MEDIAN") is not None and georef:
        add(t("tie point σXY / σZ (median; predicted ground uncertainty, datum included)"),
            f"{fmt(fig['POINT_STD_XY_MEDIAN'], 3)} / {fmt(fig.get('POINT_STD_Z_MEDIAN'), 3)} m")
    if fig.get("DSM_VALID_FRACTION") is not None:
        add(t("DSM valid fraction"), fmt(fig["DSM_VALID_FRACTION"], 3))
    return '<div class="cards">' + "".join(cards) + "</div>"


def precision_badge(unc, gsd: Optional[float], camera_rmse: Optional[float] = None) -> str:
    """Green when the tie points' median sigma XY is within 3 GSD, amber (with the likely reason) beyond; with
    camera positions, what each figure measures (issue 36 item 21: a σ of 10.8 m beside a camera RMSE of 0.54 m
    read as a contradiction)."""
    s = unc.summary()
    sxy, sz = s["point_std_xy_median"], s["point_std_z_median"]
    txt = f"precision from the adjustment: tie points σXY {fmt(sxy, 3)} m, σZ {fmt(sz, 3)} m (median)"
    if camera_rmse is not None and sxy is not None:
        txt += (f". σ is how uncertain the ground points' position is, the datum included: the whole block may "
                "shift and tilt within the camera positions' stated accuracy; the camera position RMSE "
                f"({camera_rmse:.2f} m) is how closely the block fits those positions, which says nothing of "
                "their own error")
    if sxy is None or gsd is None or sxy <= 3 * gsd:
        return badge("ok", esc(txt))
    why = (" — the datum is weak: positions of limited accuracy (e.g. EXIF GPS) leave the block free to shift and "
           "tilt; add ground control points" if not unc.n_control else
           " — the control does not hold the block well (too few or badly spread control points)")
    return badge("warn", esc(txt + f"; more than 3 × the GSD ({gsd:.3f} m)" + why))


def glance_lines(ctx: ReportContext, figures: Dict[str, Any], status: Dict[str, str]) -> List[str]:
    """The "at a glance" list: the alignment first, the sections' own lines, then precision and products."""
    lines = list(ctx.glance)
    if ctx.d.rec is not None:
        n_img, n_reg = figures.get("IMAGES"), figures.get("REGISTERED_IMAGES")
        kind = "ok" if n_img and n_reg == n_img else "warn"
        lines.insert(0, badge(kind, t("{} of {} images aligned, mean reprojection error {} px").format(
            n_reg, n_img, fmt(figures.get('MEAN_REPROJECTION_ERROR'), 2))))
    else:
        lines.insert(0, badge("bad", t("no aligned model: run 'Align images'")))
    if ctx.unc is not None and ctx.d.georeferenced:
        lines.append(precision_badge(ctx.unc, ctx.gsd, num(figures.get("CAMERA_RMSE_XY"))))
    if status.get("products") != "ok":
        lines.append(badge("note", t("no DSM / orthomosaic yet")))
    return lines


def page(root: str, figures: Dict[str, Any], status: Dict[str, str], georef: bool, glance: Sequence[str],
         body: Sequence[str], seconds: float) -> str:
    """The whole HTML page (``body``: the sections' HTML; ``seconds``: the time the report took)."""
    now = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    title = t("ArchaeoOrtho report — {}").format(os.path.basename(root.rstrip(os.sep)))
    nav = "".join(f'<a href="#{sid}">{esc(t(name))}</a>' for sid, name in SECTIONS)
    machine = json.dumps({"figures": figures, "sections": status}, default=str, allow_nan=False)
    return (
        f"<!DOCTYPE html>\n<html lang=\"{esc(current_language())}\"><head><meta charset=\"utf-8\">"
        f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{esc(title)}</title>"
        f"<style>{CSS}</style></head><body><main>"
        f"<h1>{esc(title)}</h1><p class=\"sub\">{esc(root)} · {esc(t('generated'))} {esc(now)} · ArchaeoOrtho "
        f"{esc(version())}</p><nav>{nav}</nav>"
        f"<section id=\"glance\"><h2>{esc(t('At a glance'))}</h2>{cards(figures, georef)}<ul class=\"glance\">"
        + "".join(glance) + "</ul></section>" + "".join(body)
        + f"<footer>Accuracy figures: core.accuracy (FGDC-STD-007.3-1998 NSSDA; ASPRS Positional Accuracy "
          f"Standards 2014 and 2023). Report written in {duration(seconds)}.</footer>"
        + f"<script type=\"application/json\" id=\"report-data\">{esc_json(machine)}</script>"
        + "</main></body></html>\n")


def read_report_data(path: str) -> Dict[str, Any]:
    """The machine-readable figures embedded in a report (``<script id="report-data">``)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    start = text.index('id="report-data">') + len('id="report-data">')
    end = text.index("</script>", start)
    return json.loads(text[start:end].replace("<\\/", "</"))
