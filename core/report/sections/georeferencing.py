"""The georeferencing section: control and check points, RMSE per set, the accuracy estimated for control given
without sigmas, residual vectors, camera-position residuals, outliers and the "at a glance" accuracy lines."""
from __future__ import annotations

import math
from typing import Any, Dict, Sequence

import numpy as np

from ..context import ReportContext, Skip
from ..figures import embed, equal_xy, new_figure, nice
from ..html import badge, cell, crs_label, esc, fmt, kv, num, table, td
from ..labels import t
from ..residuals import accuracy_figures, camera_position_figures, residual_rows
from . import autocontrol
from .standards import accuracy_statements


def section(ctx: ReportContext) -> str:
    d = ctx.d
    if not d.georeferenced or d.residuals is None:
        st = d.manifest.get("stages", {}).get("georeference", {}).get("status")
        why = "the workspace is not georeferenced" + (f" (georeference stage: {st})" if st else "")
        ctx.glance.append(badge("warn", esc(why) + ": no accuracy figures"))
        raise Skip(why + ": run 'Georeference' with ground control points (and check points) or camera "
                          "positions.")
    res = d.residuals
    ortho_res = ctx.d.ortho_resolution()
    acc = accuracy_figures(res, ortho_res or ctx.gsd)
    ctx.acc = acc
    stats = acc["stats"]
    parts = [kv([
        ("CRS", esc(crs_label(res.get("crs") or d.crs))),
        ("Source of the datum", esc((d.frame.source if d.frame is not None else "") or "–")),
        ("Local frame offset (world = local + offset)", esc(", ".join(f"{v:.1f}" for v in d.offset))),
        ("Tie-point reprojection error after the adjustment",
         f"{fmt(res.get('mean_reprojection_error_px'), 3)} px"),
        ("GCP observation reprojection error in the adjustment (mean; control held at its coordinates "
         "within its sigmas)", f"{fmt(res.get('gcp_reprojection_error_px'), 3)} px"),
    ])]
    parts.append(_sigma_estimates(ctx, res))
    if acc["placeholder_z"]:
        parts.append('<p class="warn">Every control point has the same height (a placeholder, not a surveyed '
                     "Z): the Z residuals measure departure from one level surface, not height accuracy; no "
                     "vertical accuracy is stated.</p>")
    points = residual_rows(res)
    if points:
        parts.append("<h3>" + esc(t("Control and check points")) + "</h3>" + _points_table(ctx, points))
        parts.append(_stats_table(ctx, stats))
        parts.append(accuracy_statements(ctx, acc))
        parts.append(_residual_plot(ctx, points))
    else:
        parts.append('<p class="skip">No ground control points: the block was georeferenced from camera '
                     "positions only, so there are no ground residuals and no NSSDA / ASPRS accuracy.</p>")
        ctx.glance.append(badge("warn", "no ground control or check points: accuracy not tested"))
    cams = camera_position_figures(res)
    if cams:
        parts.append(_camera_residuals(ctx, cams))
    parts.append(_outliers(ctx, res, acc))
    parts.append(autocontrol.subsection(ctx))  # '' unless automatic control georeferenced the block
    _glance_accuracy(ctx, acc)
    return "".join(parts)


def _sigma_estimates(ctx: ReportContext, res: Dict[str, Any]) -> str:
    """The sigmas estimated for control points / camera positions given without them (core.georef.control_sigma),
    '' when every sigma was given."""
    ests = res.get("sigma_estimates") or []
    if not ests:
        return ""
    rows = []
    for e in ests:
        grp = str(e.get("group", ""))
        key = "control" if grp.startswith("control") else "camera"
        how = {"helmert": "rigid fit", "helmert + variance components":
               f"rigid fit + variance components ({e.get('iterations', 0)} it.)",
               "residuals": "residuals (no redundancy)", "none": "placeholders kept"}.get(e.get("method"),
                                                                                         e.get("method"))
        rows.append([td(grp), td(e.get("n")), cell(e.get("sigma_xy_m"), 3, f"sigma.{key}.xy"),
                     cell(e.get("sigma_z_m"), 3, f"sigma.{key}.z"), cell(e.get("helmert_xy_m"), 3),
                     cell(e.get("helmert_z_m"), 3), cell(e.get("floor_xy_m"), 3), cell(e.get("floor_z_m"), 3),
                     td(f"{e.get('prior_xy_m', float('nan')):g} / {e.get('prior_z_m', float('nan')):g}"), td(how),
                     cell(e.get("pixel_sigma"), 2),
                     td(", ".join(e.get("excluded") or []) or "–")])
        pre = "CONTROL" if key == "control" else "CAMERA_POSITION"
        ctx.figures.update({f"{pre}_SIGMA_XY": num(e.get("sigma_xy_m")), f"{pre}_SIGMA_Z": num(e.get("sigma_z_m"))})
        ctx.glance.append(badge("ok", esc(f"{grp} without sigma: accuracy estimated from the data, sigma XY "
                                          f"{fmt(e.get('sigma_xy_m'), 3)} m, Z {fmt(e.get('sigma_z_m'), 3)} m")))
    return ("<h3>" + esc(t("Accuracy of the control given without sigmas, estimated from the data")) + "</h3>" + table(
        ["group", "n", "σ XY", "σ Z", "rigid fit σ XY", "rigid fit σ Z", "floor XY", "floor Z", "placeholders",
         "estimated from", "image σ (px)", "left out as suspect"], rows)
        + '<p class="note">Metres. The files gave no sigmas for these points (or positions), so their accuracy was '
          "estimated: first from the residuals of the rigid (7-parameter) fit of the block onto them, divided by "
          "their redundancy, with the suspect ones left out; then refined by variance components in the "
          "adjustment (their share of the weighted residuals over their share of the redundancy), the image "
          "observations' own sigma estimated alongside (image σ). The adjustment weighted them with the estimate: metre-level control leaves the block "
          "as rigid as the rigid fit, precise control lets it bend where the tie points allow. The floor is the "
          "block's own precision at the points (their forward intersection at the adjustment's pixel sigma): "
          "nothing finer can be told from the data.</p>")


def _points_table(ctx: ReportContext, points: Sequence[Dict[str, Any]]) -> str:
    rows = []
    for p in sorted(points, key=lambda p: ({"used": 0, "rejected": 1, "check": 2}.get(p.get("status"), 3),
                                           p.get("name", ""))):
        px = [o.get("px") for o in p.get("observations", []) if o.get("px") is not None]
        dxy = math.hypot(p["dx"], p["dy"]) if p.get("dx") is not None else None
        d3 = math.sqrt(p["dx"] ** 2 + p["dy"] ** 2 + p["dz"] ** 2) if p.get("dx") is not None else None
        key = f"pt.{p.get('name')}"
        status = p.get("status", "")
        cls = {"used": "", "check": "chk", "rejected": "bad"}.get(status, "warn")
        obs_txt = ", ".join(f"{o['image']}: {o['px']:.2f}" if o.get("px") is not None else f"{o['image']}: –"
                            for o in p.get("observations", []))
        rows.append([td(p.get("name")), td(p.get("role")), td(status, cls), cell(p.get("x"), 3),
                     cell(p.get("y"), 3), cell(p.get("z"), 3), cell(p.get("dx"), 3, key + ".dx"),
                     cell(p.get("dy"), 3, key + ".dy"), cell(p.get("dz"), 3, key + ".dz"), cell(dxy, 3),
                     cell(d3, 3), td(p.get("n_obs", 0)), cell(np.mean(px) if px else None, 2),
                     cell(max(px) if px else None, 2),
                     f'<td class="small">{esc(obs_txt)}'
                     + (f"<br><i>{esc('; '.join(p.get('notes') or []))}</i>" if p.get("notes") else "") + "</td>"])
    return table(["name", "role", "status", "X", "Y", "Z", "dX", "dY", "dZ", "dXY", "d3D", "obs", "mean px",
                   "max px", "image residuals (px)"], rows, cls="pts") + (
        '<p class="note">Residuals are adjusted (triangulated in the adjusted block) minus given, in metres. '
        "Check points took no part in the adjustment; rejected control points were left out as outliers and are "
        "evaluated like check points.</p>")


def _stats_table(ctx: ReportContext, stats: Dict[str, Dict[str, Any]]) -> str:
    labels = {"control": "control (used)", "check": "check points", "rejected": "rejected control",
              "check_helmert_only": "check points, Helmert (7-parameter) only"}
    rows = []
    for k, lab in labels.items():
        s = stats[k]
        if not s["n"]:
            continue
        rows.append([td(lab), td(s["n"]), cell(s["rmse_x"], 3, f"{k}.rmse_x"),
                     cell(s["rmse_y"], 3, f"{k}.rmse_y"), cell(s["rmse_z"], 3, f"{k}.rmse_z"),
                     cell(s["rmse_r"], 3, f"{k}.rmse_r"), cell(s["rmse_xyz"], 3, f"{k}.rmse_xyz"),
                     cell(s["mean_x"], 3), cell(s["mean_y"], 3), cell(s["mean_z"], 3),
                     cell(s["max"]["r"], 3), cell(s["max_z"], 3)])
    if not rows:
        return '<p class="skip">No control or check point could be evaluated.</p>'
    for k in ("control", "check"):
        s = stats[k]
        if s["n"]:
            pre = "CHECK" if k == "check" else "CONTROL"
            ctx.figures.update({f"{pre}_N": s["n"], f"{pre}_RMSE_X": num(s["rmse_x"]),
                                 f"{pre}_RMSE_Y": num(s["rmse_y"]), f"{pre}_RMSE_Z": num(s["rmse_z"]),
                                 f"{pre}_RMSE_XY": num(s["rmse_r"])})
    return ("<h3>" + esc(t("RMSE per set")) + "</h3>" + table(
        ["set", "n", "RMSE X", "RMSE Y", "RMSE Z", "RMSE XY (radial)", "RMSE 3D", "mean dX", "mean dY", "mean dZ",
         "max dXY", "max |dZ|"], rows) + '<p class="note">Metres. The mean is the bias of each axis.</p>')


def _residual_plot(ctx: ReportContext, points: Sequence[Dict[str, Any]]) -> str:
    d = ctx.d
    pts = [p for p in points if p.get("dx") is not None]
    if not pts:
        return ""
    fig = new_figure(7.5, 6.2)
    ax = fig.add_subplot(111)
    fp = d.footprint()
    if fp is not None:
        ax.fill(fp[:, 0], fp[:, 1], color="#eef3f8", ec="#9fb3c8", lw=0.8, label=t("tie-point footprint"))
    centres = d.centres()
    ax.scatter(centres[:, 0], centres[:, 1], s=6, c="#888888", marker="s", lw=0, label=t("camera centres"))
    xy = np.array([[p["x"], p["y"]] for p in pts], dtype=float)
    dxy = np.array([[p["dx"], p["dy"]] for p in pts], dtype=float)
    dz = np.array([p["dz"] for p in pts], dtype=float)
    allxy = np.vstack([xy] + ([fp] if fp is not None else []))
    ext = float(np.ptp(allxy, axis=0).max()) if len(allxy) > 1 else 1.0
    lmax = float(np.hypot(dxy[:, 0], dxy[:, 1]).max())
    k = 0.12 * ext / lmax if lmax > 0 else 1.0
    lim = float(np.max(np.abs(dz))) if len(dz) else 1.0
    markers = {"used": ("^", "control"), "check": ("o", "check"), "rejected": ("X", "rejected control")}
    sc = None
    for st, (mk, lab) in markers.items():
        m = np.array([p.get("status") == st for p in pts])
        if m.any():
            sc = ax.scatter(xy[m, 0], xy[m, 1], c=dz[m], cmap="RdBu_r", vmin=-lim, vmax=lim, marker=mk, s=70,
                            edgecolors="k", linewidths=0.6, zorder=4, label=lab)
    q = ax.quiver(xy[:, 0], xy[:, 1], dxy[:, 0] * k, dxy[:, 1] * k, angles="xy", scale_units="xy", scale=1,
                  color="#222222", width=0.004, zorder=5)
    ref = nice(lmax)
    ax.quiverkey(q, 0.82, 0.96, ref * k, f"{ref:g} m", labelpos="E", coordinates="axes",
                 fontproperties={"size": 7})
    for p in pts:
        ax.annotate(p["name"], (p["x"], p["y"]), xytext=(4, 4), textcoords="offset points", fontsize=7)
    if sc is not None:
        fig.colorbar(sc, ax=ax, shrink=0.7, label=t("dZ (m)"))
    ax.legend(fontsize=7, loc="lower left")
    equal_xy(ax)
    ax.set_title(t("ground point residuals ({})").format(d.crs_label), fontsize=9)
    return "<h3>" + esc(t("Residual vectors over the footprint")) + "</h3>" + embed(
        fig, "residual vectors", f"Horizontal residual of each control (triangle) and check point (circle), "
        f"exaggerated ×{k:.3g} (key: {ref:g} m); colour: vertical residual. Systematic patterns (all arrows one "
        "way, growing towards an edge) point at a block deformation or a datum problem; a lone long arrow at a "
        "wrong coordinate or marking.")


def _camera_residuals(ctx: ReportContext, cams: Dict[str, Any]) -> str:
    s = cams["stats"]
    ctx.figures.update(CAMERA_RMSE_XY=num(s["rmse_r"]), CAMERA_RMSE_Z=num(s["rmse_z"]))
    rows = [[td(c["image"]), td("yes" if c.get("used", True) else "excluded"), cell(c.get("dx"), 3),
             cell(c.get("dy"), 3), cell(c.get("dz"), 3),
             cell(math.hypot(c["dx"], c["dy"]) if c.get("dx") is not None else None, 3)] for c in cams["rows"]]
    summary = table(["set", "n", "RMSE X", "RMSE Y", "RMSE Z", "RMSE XY", "mean dX", "mean dY", "mean dZ"], [[
        td("camera positions used"), td(s["n"]), cell(s["rmse_x"], 3, "cam.rmse_x"),
        cell(s["rmse_y"], 3, "cam.rmse_y"), cell(s["rmse_z"], 3, "cam.rmse_z"),
        cell(s["rmse_r"], 3, "cam.rmse_r"), cell(s["mean_x"], 3), cell(s["mean_y"], 3),
        cell(s["mean_z"], 3)]])
    return ("<h3>" + esc(t("Camera-position residuals")) + "</h3>" + summary
            + '<p class="note">Adjusted projection centre minus given position, metres (see the camera '
              "positions plot under Orientation quality). They show how well the block fits the positions, "
              "not the accuracy of the ground.</p><details><summary>" + esc(t("Per camera")) + "</summary>"
            + table(["image", "used", "dX", "dY", "dZ", "dXY"], rows) + "</details>")


def _outliers(ctx: ReportContext, res: Dict[str, Any], acc: Dict[str, Any]) -> str:
    items = []
    for o in res.get("outliers") or []:
        items.append(f"<li class=\"bad\">{esc(o.get('message') or (str(o.get('kind')) + ' ' + str(o.get('name'))))}"
                     "</li>")
    cc = (res.get("statistics") or {}).get("control_consistency")
    if cc and cc.get("suspects"):
        items.append("<li class=\"warn\">Control points that disagree with the others through the block "
                     f"(more than {cc.get('tolerance_m', 0):.3f} m from the best-agreeing subset's fit"
                     f"{', XY only' if cc.get('xy_only') else ''}): "
                     + esc(", ".join(f"{n} ({cc['residuals_m'].get(n, float('nan')):.2f} m)"
                                      for n in cc["suspects"])) + "</li>")
    for k in ("control", "check"):
        s = acc["stats"][k]
        if s["n"] < 3:
            continue
        rr = num(s["rmse_r"]) or 0.0
        for p in acc["sets"][k]:
            dxy = math.hypot(p["dx"], p["dy"])
            if rr > 0 and dxy > 2.5 * rr:
                items.append(f"<li class=\"warn\">Suspect {k} point {esc(p['name'])}: horizontal residual "
                             f"{dxy:.3f} m, {dxy / rr:.1f} × the set's RMSE XY.</li>")
    for p in residual_rows(res):
        px = [o.get("px") for o in p.get("observations", []) if o.get("px") is not None]
        if px and max(px) > 3.0:
            items.append(f"<li class=\"warn\">{esc(p['name'])}: an image residual of {max(px):.1f} px "
                         "(check the marking).</li>")
        if p.get("status") == "not triangulated":
            items.append(f"<li class=\"warn\">{esc(p['name'])}: not triangulated "
                         f"({esc('; '.join(p.get('notes') or []))}).</li>")
    for w in res.get("warnings") or []:
        items.append(f"<li class=\"note\">{esc(w)}</li>")
    if not items:
        return '<h3>' + esc(t("Outliers and suspect points")) + '</h3><p class="ok">None found.</p>'
    return "<h3>" + esc(t("Outliers, suspect points and warnings")) + "</h3><ul class=\"issues\">" + "".join(items) + "</ul>"


def _glance_accuracy(ctx: ReportContext, acc: Dict[str, Any]) -> None:
    st = acc["stats"]
    if acc["tested"]:
        s = st["check"]
        txt = (f"check points: RMSE XY {s['rmse_r']:.3f} m"
               + (f", Z {s['rmse_z']:.3f} m" if not acc["placeholder_z"] and num(s["rmse_z"]) is not None else "")
               + f" ({s['n']} points)")
        kind = "ok" if ctx.gsd is None or s["rmse_r"] <= 3 * ctx.gsd else "warn"
        ctx.glance.append(badge(kind, esc(txt)))
    elif acc["basis"] == "control":
        ctx.glance.append(badge("warn", "no check points: accuracy not tested (control residuals only)"))
    if acc["placeholder_z"]:
        ctx.glance.append(badge("warn", "control heights are placeholders: no vertical accuracy"))
    if acc["tested"] and ctx.unc is not None:
        sxy = ctx.unc.summary()["point_std_xy_median"]
        rr = num(st["check"]["rmse_r"])
        if sxy and rr and rr > 5 * max(sxy, ctx.gsd or 0.0):
            ctx.glance.append(badge("bad", esc(
                f"check-point RMSE XY is {rr / sxy:.0f} × the precision the adjustment predicts for tie points "
                f"({sxy:.3f} m): the errors are systematic (control coordinates, their marking, or a deformed "
                "block), not noise")))
    if acc["sets"]["rejected"]:
        ctx.glance.append(badge("bad", "rejected control points: " + esc(
            ", ".join(p["name"] for p in acc["sets"]["rejected"]))))
