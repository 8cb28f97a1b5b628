"""The summary section: images given / aligned / not aligned (and why), GSD, area, CRS, image screening,
cameras with their calibrated parameters, processing stages and their parameters."""
from __future__ import annotations

import json

from ...project.stages import REPORT
from ..context import ReportContext
from ..figures import embed, new_figure, poly_area
from ..html import area_text, cell, duration, esc, fmt, kv, table, td
from ..labels import t


def section(ctx: ReportContext) -> str:
    d = ctx.d
    m = d.manifest
    images = m.get("images", [])
    al = d.alignment or {}
    n_given = al.get("images_given", len(images))
    parts = []
    rows = [("Workspace", esc(d.ws.root)), ("Images folder", esc(m.get("images_dir") or "–"))]
    if d.rec is not None:
        n_reg = len(d.obs.image_ids)
        ctx.figures.update(IMAGES=n_given, REGISTERED_IMAGES=n_reg, POINTS3D=int(len(d.obs.point_ids)))
        rows.append(("Images given / aligned / not aligned",
                     f'<span data-key="images.given">{n_given}</span> / '
                     f'<span data-key="images.aligned">{n_reg}</span> / '
                     f'<span data-key="images.not_aligned">{max(0, n_given - n_reg)}</span>'))
        rows.append(("Tie points / image observations", f"{len(d.obs.point_ids):,} / {len(d.obs.img):,}"))
        ctx.gsd = d.gsd()
        fp = d.footprint()
        area = poly_area(fp) if d.georeferenced else None
        ctx.figures.update(GSD=ctx.gsd if d.georeferenced else None, AREA_M2=area)
        if d.georeferenced:
            rows.append(("Ground sample distance (median)",
                         f'<span data-key="gsd">{fmt(ctx.gsd, 4)}</span> m ({fmt(ctx.gsd and ctx.gsd * 100, 2)} cm)'))
            rows.append(("Area covered by tie points", area_text(area)))
        else:
            rows.append(("Ground sample distance", f"{fmt(ctx.gsd, 5)} model units per pixel (not georeferenced)"))
    else:
        ctx.figures.update(IMAGES=len(images) or None, REGISTERED_IMAGES=None)
        rows.append(("Images given", str(len(images))))
    crs_txt = ("none (local model frame)" if not d.crs else d.crs_label
               if str(d.crs) in d.crs_label or "no EPSG code" in d.crs_label else f"{d.crs_label}: {d.crs}")
    rows.append(("Coordinate reference system", esc(crs_txt)))
    parts.append(kv(rows))

    # not aligned, with why
    unreg = al.get("unregistered") or {}
    skipped = al.get("skipped_files") or []
    if unreg or skipped:
        r = [[td(n), td(w)] for n, w in sorted(unreg.items())] + [[td(s), td("not read")] for s in skipped]
        parts.append("<h3>" + esc(t("Images not aligned")) + "</h3>" + table(["image", "why"], r))
    elif d.rec is not None:
        parts.append('<p class="ok">Every image given was aligned.</p>')
    if al.get("other_components"):
        parts.append('<p class="warn">Separate components left out: ' + "; ".join(
            esc(", ".join(c)) for c in al["other_components"]) + "</p>")

    parts.append(_screening(ctx))
    parts.append(_cameras(ctx))
    parts.append(_stages(ctx))
    return "".join(parts)


def _screening(ctx: ReportContext) -> str:
    s = ctx.d.screening
    if not s:
        return ('<h3>' + esc(t("Image screening")) + '</h3><p class="skip">Not run: the images were not screened '
                "(run 'Prepare images' for blur and exposure scores).</p>")
    imgs = s.get("images", [])
    rows = []
    for q in sorted(imgs, key=lambda q: q.get("blur_rank", 0)):
        cls = "bad" if q.get("decision") == "exclude" else ("warn" if q.get("flags") else "")
        rows.append([td(q.get("name")), cell(q.get("blur_score"), 1), cell(q.get("blur_relative"), 2),
                     cell(q.get("exposure_score"), 2), cell(q.get("dynamic_range"), 2),
                     td(", ".join(q.get("flags") or []) or "–"), td(q.get("decision", "keep"), cls)])
    head = ("<h3>" + esc(t("Image screening")) + "</h3><p>" + esc(t(
        "{} images screened: {} flagged, {} excluded, {} kept (blurriest first).").format(
        len(imgs), s.get('flagged', 0), s.get('excluded', 0), s.get('kept', len(imgs)))) + "</p>")
    plot = ""
    if imgs:
        fig = new_figure(7.5, 2.6)
        ax = fig.add_subplot(111)
        srt = sorted(imgs, key=lambda q: q.get("blur_score", 0.0))
        colours = ["#c0392b" if q.get("decision") == "exclude" else "#e69f00" if q.get("flags") else "#4477aa"
                   for q in srt]
        ax.bar(range(len(srt)), [q.get("blur_score", 0.0) for q in srt], color=colours)
        med = (s.get("median") or {}).get("blur_score")
        if med:
            ax.axhline(med, color="k", lw=0.8, ls="--", label=t("median"))
            ax.legend(fontsize=7)
        ax.set_ylabel(t("blur score (higher = sharper)"), fontsize=8)
        ax.set_xlabel(t("images, blurriest first"), fontsize=8)
        ax.tick_params(labelsize=7)
        plot = embed(fig, "blur scores", "Blur score per image (orange: flagged, red: excluded).")
    return head + plot + "<details><summary>" + esc(t("Screening table")) + "</summary>" + table(
        ["image", "blur score", "blur / median", "exposure", "dynamic range", "flags", "decision"], rows
    ) + "</details>"


def _cameras(ctx: ReportContext) -> str:
    d = ctx.d
    if d.rec is None:
        return ""
    unc = ctx.unc
    rows = []
    for cid, cam in sorted(d.rec.cameras.items()):
        names = [n.strip() for n in str(cam.params_info).split(",")]
        info = unc.intrinsics.get(int(cid)) if unc is not None else None
        n_img = sum(1 for i in d.obs.image_ids if int(d.rec.image(int(i)).camera_id) == int(cid))
        params = []
        for k, (n, v) in enumerate(zip(names, cam.params)):
            if n in ("k4", "k5", "k6") and float(v) == 0.0:  # FULL_OPENCV of a calibration: zero by construction
                continue
            sd = info["std"][k] if info else None
            dec = 2 if abs(v) >= 10 else 6
            txt = f"{v:.{dec}f}" + (f" ± {sd:.{dec}f}" if sd is not None else (" (fixed)" if info else ""))
            params.append(f"<span class=\"param\"><b>{esc(n)}</b> {esc(txt)}</span>")
        rows.append([td(cid), td(cam.model.name), td(f"{cam.width} × {cam.height}"), td(n_img),
                     "<td>" + " ".join(params) + "</td>"])
    note = ("Standard deviations from the bundle adjustment covariance (see Uncertainty), scaled by "
            "sigma0; “fixed”: held constant in the adjustment." if unc is not None else
            f"No standard deviations: {ctx.unc_error or 'uncertainty not computed'}.")
    return ("<h3>" + esc(t("Cameras and calibrated parameters")) + "</h3>"
            + table(["camera", "model", "size (px)", "images", "parameters (pixels; distortion unitless)"],
                     rows, cls="cams") + f'<p class="note">{esc(note)}</p>')


def _stages(ctx: ReportContext) -> str:
    stages = ctx.d.manifest.get("stages", {})
    if not stages:
        return ""
    rows, prow = [], []
    for name, rec in stages.items():
        if name == REPORT:
            continue
        timings = rec.get("timings") or {}
        steps = ", ".join(f"{k.replace('_', ' ')} {duration(v)}" for k, v in timings.items() if k != "total")
        rows.append([td(name), td(rec.get("status", "–"), "ok" if rec.get("status") == "done" else "warn"),
                     td(duration(timings.get("total"))), td(steps or "–"), td(rec.get("finished") or "–")])
        params = rec.get("parameters") or {}
        prow.append([td(name), "<td>" + ", ".join(
            f"<b>{esc(k)}</b>={esc(json.dumps(v, default=str))}" for k, v in params.items()) + "</td>"])
    return ("<h3>" + esc(t("Processing stages")) + "</h3>" + table(["stage", "status", "time", "steps", "finished"], rows)
            + "<details><summary>" + esc(t("Parameters used")) + "</summary>" + table(["stage", "parameters"], prow)
            + "</details>")
