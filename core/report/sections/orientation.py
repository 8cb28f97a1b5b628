"""The orientation quality section: reprojection errors, track lengths, image connectivity, camera
positions."""
from __future__ import annotations

import os
from typing import Optional

import numpy as np

from ...align.calibrated import source_label
from ...common.progress import check_cancel
from ...georef import accuracy
from ...georef.bundle import CALIBRATION_ZERO_TERMS, given_priors
from ...georef.options import (
    REFINED_FOCAL_SIGMA,
    REFINED_PP_SIGMA,
    REFINED_RADIAL_SIGMA,
    REFINED_TANGENTIAL_SIGMA,
)
from ..context import ReportContext, Skip
from ..figures import embed, equal_xy, new_figure, nice
from ..html import badge, cell, esc, fmt, kv, num, table, td
from ..labels import t
from ..residuals import camera_position_figures


def section(ctx: ReportContext) -> str:
    d = ctx.d
    if d.rec is None:
        raise Skip("the workspace is not aligned: run 'Align images'.")
    o = d.obs
    err = o.error
    fin = err[np.isfinite(err)]
    mean_img, n_img = d.per_image_error()
    d.rec.update_point_3d_errors()
    mre = num(d.rec.compute_mean_reprojection_error()) if len(fin) else None
    ctx.figures["MEAN_REPROJECTION_ERROR"] = mre
    parts = [kv([
        ("Mean reprojection error (mean over tie points of their mean error, as COLMAP reports it)",
         f'<span data-key="reproj.mean">{fmt(mre, 3)}</span> px'),
        ("Reprojection error of the observations: mean / median / RMS",
         f'<span data-key="reproj.obs_mean">{fmt(np.mean(fin) if len(fin) else None, 3)}</span> / '
         f'{fmt(np.median(fin) if len(fin) else None, 3)} / {fmt(accuracy.rmse(fin), 3)} px'),
        ("Largest reprojection error", f"{fmt(fin.max() if len(fin) else None, 2)} px"),
        ("Track length: mean / median / max",
         f"{fmt(np.mean(o.track_length), 2)} / {fmt(np.median(o.track_length), 0)} / {int(o.track_length.max())}"
         if len(o.track_length) else "–"),
        ("Model", esc(os.path.relpath(d.model_dir, d.ws.root))),
    ])]
    # histogram + track lengths
    fig = new_figure(9.0, 3.0)
    ax = fig.add_subplot(121)
    if len(fin):
        hi = max(float(np.percentile(fin, 99.5)), 1e-3)
        ax.hist(np.clip(fin, 0, hi), bins=50, color="#4477aa")
        ax.axvline(np.mean(fin), color="#c0392b", lw=1, label=t("mean {} px").format(f"{np.mean(fin):.2f}"))
        ax.axvline(np.median(fin), color="k", lw=1, ls="--", label=t("median {} px").format(f"{np.median(fin):.2f}"))
        ax.legend(fontsize=7)
    ax.set_xlabel(t("reprojection error (px)"), fontsize=8)
    ax.set_ylabel(t("observations"), fontsize=8)
    ax.tick_params(labelsize=7)
    ax2 = fig.add_subplot(122)
    if len(o.track_length):
        tl = o.track_length
        top = int(min(tl.max(), np.percentile(tl, 99.5) + 1))
        ax2.hist(np.clip(tl, 2, top), bins=np.arange(1.5, top + 1.5), color="#228833")
    ax2.set_xlabel(t("track length (images per tie point)"), fontsize=8)
    ax2.set_ylabel(t("tie points"), fontsize=8)
    ax2.tick_params(labelsize=7)
    parts.append(embed(fig, "reprojection error and track length histograms",
                      "Left: reprojection error of every tie-point observation (clipped at the 99.5th "
                      "percentile). Right: number of images per tie point."))
    # per image
    names = d.obs.image_names
    n = len(names)
    fig = new_figure(max(7.0, min(16.0, 0.18 * n + 2)), 3.6)
    ax = fig.add_subplot(211)
    med = np.nanmedian(mean_img) if n else 0.0
    colours = ["#c0392b" if v > 2 * med else "#4477aa" for v in np.nan_to_num(mean_img)]
    ax.bar(range(n), np.nan_to_num(mean_img), color=colours)
    ax.set_ylabel(t("mean error (px)"), fontsize=8)
    ax.set_xticks([])
    ax.tick_params(labelsize=7)
    ax2 = fig.add_subplot(212)
    ax2.bar(range(n), n_img, color="#228833")
    ax2.set_ylabel(t("observations"), fontsize=8)
    ax2.set_xticks(range(n))
    ax2.set_xticklabels(names if n <= 80 else [""] * n, rotation=90, fontsize=6)
    ax2.tick_params(axis="y", labelsize=7)
    parts.append(embed(fig, "reprojection error per image",
                      "Mean reprojection error (red: more than twice the median) and tie-point observations "
                      "per image."))
    rows = [[td(nm), cell(mean_img[k], 3), td(int(n_img[k]))] for k, nm in enumerate(names)]
    parts.append("<details><summary>" + esc(t("Per-image table")) + "</summary>"
                 + table(["image", "mean reprojection error (px)", "observations"], rows) + "</details>")
    bad = [names[k] for k in range(n) if np.isfinite(mean_img[k]) and mean_img[k] > 2 * med]
    if bad:
        ctx.glance.append(badge("warn", f"{len(bad)} image(s) with more than twice the median reprojection "
                                          f"error: {esc(', '.join(bad[:6]))}{' …' if len(bad) > 6 else ''}"))
    check_cancel(ctx.progress)
    parts.append(interior_orientation(ctx))
    parts.append(_connectivity(ctx))
    parts.append(_camera_plot(ctx))
    return "".join(parts)


# a refined parameter further than this many sigmas from its given value is named in a warning
MOVED_SIGMAS = 3.0


# the parameters in the order a calibration certificate lists them, with their names for a person
_PARAM_ORDER = ("f", "fx", "fy", "cx", "cy", "k", "k1", "k2", "k3", "p1", "p2")
_PARAM_LABEL = {"f": "focal length f (px)", "fx": "focal length fx (px)", "fy": "focal length fy (px)",
                "cx": "principal point cx (px)", "cy": "principal point cy (px)", "k": "radial k1", "k1": "radial k1",
                "k2": "radial k2", "k3": "radial k3", "p1": "tangential p1", "p2": "tangential p2"}


def _corner_distortion_px(params: dict, width: float, height: float) -> Optional[float]:
    """The radial distortion (px, positive outward) at the image corner of a camera's k1..k3 (OpenCV's model,
    normalised coordinates), measured from the principal point; None without a focal length."""
    f = num(params.get("f", params.get("fx")))
    cx, cy = num(params.get("cx")), num(params.get("cy"))
    if not f or cx is None or cy is None:
        return None
    rho = max(float(np.hypot(x - cx, y - cy)) for x in (0.0, width) for y in (0.0, height)) / f
    ks = [num(params.get(k)) or 0.0 for k in ("k1", "k2", "k3")]
    if "k" in params:
        ks[0] = num(params["k"]) or 0.0
    return round(float(f * rho * (ks[0] * rho ** 2 + ks[1] * rho ** 4 + ks[2] * rho ** 6)), 2) + 0.0  # no -0.00


def _camera_in_mm(cid, r: dict, final: dict) -> str:
    """One line per camera in the certificate's units: focal length and principal point in mm (x right, y up
    from the image centre) given and final, where the calibration gave the pixel size; the radial distortion at
    the image corner in px."""
    name = f" '{r['name']}'" if r.get("name") else ""
    src = source_label(str(r.get("source") or ""))
    parts = [f"camera {cid}{name} ({esc(src)}), {r['mode']}"]
    g = r["given"]
    w, h = num(r.get("width")), num(r.get("height"))
    px = num(r.get("pixel_size_mm"))
    if px and w and h:
        def mm(p):
            fx = num(p.get("f", p.get("fx")))
            fy = num(p.get("f", p.get("fy"))) or fx
            py = px * fx / fy
            return fx * px, (num(p["cx"]) - w / 2.0) * px, (h / 2.0 - num(p["cy"])) * py

        gf, gx, gy = (round(v, 3) + 0.0 for v in mm(g))
        ff, fx0, fy0 = (round(v, 3) + 0.0 for v in mm(final))
        parts.append(f"focal length {gf:.3f} mm given, {ff:.3f} mm final; principal point ({gx:+.3f}, {gy:+.3f}) "
                     f"mm given, ({fx0:+.3f}, {fy0:+.3f}) mm final (from the image centre, x right, y up); pixel "
                     f"{px:.4g} mm")
    if w and h:
        dg, df = _corner_distortion_px(g, w, h), _corner_distortion_px(final, w, h)
        if dg is not None and df is not None:
            parts.append(f"radial distortion at the image corner {dg:+.2f} px given, {df:+.2f} px final")
    return "; ".join(parts) + "."


def _flying_height(d, given: dict) -> str:
    """A georeferenced block's flying height above the ground (the camera centres' median height less the tie
    points') and, per camera whose focal length is known in mm, its photo scale: what a person checks against
    the sortie's record, since a wrong focal length held fixed moves the cameras up or down in proportion while
    the reprojection error of a vertical block hardly changes ("" when not georeferenced)."""
    if not getattr(d, "georeferenced", False):
        return ""
    try:
        centres, tie = d.centres(), d.tie_xyz()
    except Exception:  # noqa: BLE001 - a partial model: no line rather than no report
        return ""
    if not len(centres) or not len(tie):
        return ""
    h = float(np.median(centres[:, 2]) - np.median(tie[:, 2]))
    if not h > 0:
        return ""
    scales = []
    for cid, r in sorted(given.items()):
        px = num(r.get("pixel_size_mm"))
        cam = d.rec.cameras[cid] if cid in d.rec.cameras else None
        if px and cam is not None:
            f_mm = float(cam.params[0]) * px
            scales.append(f"camera {cid}: focal length {f_mm:.3f} mm, photo scale 1:{h / (f_mm / 1000.0):,.0f}")
    return (f'<p data-key="intrinsics.flying_height">Flying height above the ground: {h:,.0f} m (the camera centres\' '
            f'median height less the tie points\')' + (f"; {'; '.join(scales)}" if scales else "")
            + ". Compare it with the sortie's record (flying height, the scale on the frames): a focal length held "
            "fixed at a wrong value moves the cameras up or down in proportion (10 % too long: 10 % too high), "
            "which the reprojection error of a vertical block hardly shows.</p>")


def interior_orientation(ctx: ReportContext) -> str:
    """Per camera with a given calibration (sfm/alignment.json ``intrinsics``): what was held; for a refined camera
    how far each parameter moved from its given value, in its sigma (the prior the georeference used), with a
    warning beyond MOVED_SIGMAS; for a fixed one whether it kept its values.  The parameters in a certificate's
    order (focal length, principal point, k1..k3, p1, p2; FULL_OPENCV's k4..k6, zero for a calibration, left
    out), the focal length's move also in percent, and a line per camera in mm where the pixel size is known."""
    d = ctx.d
    records = d.layout.camera_intrinsics()
    given = {cid: r for cid, r in records.items() if r.get("given")}
    if not given:
        return ""
    rows, far, lines = [], [], []
    for cid, r in sorted(given.items()):
        cam = d.rec.cameras[cid] if cid in d.rec.cameras else None
        if cam is None:
            continue
        names = [n.strip() for n in cam.params_info.split(",")]
        sigma = {names[i]: s for i, _, s in given_priors(cam, r)}
        final = {n: float(v) for n, v in zip(names, cam.params)}
        order = sorted(range(len(names)), key=lambda i: (_PARAM_ORDER.index(names[i]) if names[i] in _PARAM_ORDER
                                                         else len(_PARAM_ORDER) + i))
        for i in order:
            name, value = names[i], float(cam.params[i])
            g = num(r["given"].get(name))
            if name in CALIBRATION_ZERO_TERMS and not g and not value:
                continue
            moved = None if g is None else value - g
            in_sigma = None if moved is None or r["mode"] != "refined" else moved / sigma[name]
            if in_sigma is not None and abs(in_sigma) > MOVED_SIGMAS:
                far.append(f"camera {cid} {name} {in_sigma:+.1f} σ")
            if r["mode"] == "fixed" and moved:
                far.append(f"camera {cid} {name} moved {moved:+.3g} although fixed")
            moved_cell = cell(moved, 6)
            if moved and name in ("f", "fx", "fy") and g:
                moved_cell = f'<td class="n">{moved:+.6f} ({100.0 * moved / g:+.2f} %)</td>'
            rows.append([td(cid), td(r["mode"]), td(_PARAM_LABEL.get(name, name)), cell(g, 6),
                         cell(sigma[name] if r["mode"] == "refined" else None, 6), cell(value, 6), moved_cell,
                         cell(in_sigma, 2)])
        lines.append(f"<li>{_camera_in_mm(cid, r, final)}</li>")
    modes = ", ".join(f"camera {cid}: {r['mode']} ({esc(source_label(str(r.get('source') or '')))})"
                      for cid, r in sorted(given.items()))
    height = _flying_height(d, given)
    if far:
        ctx.warnings.append("interior orientation moved beyond its given sigmas: " + "; ".join(far))
        ctx.glance.append(badge("warn", esc("calibration moved beyond " + f"{MOVED_SIGMAS:g} σ: " + "; ".join(far))))
    return ("<h3>" + esc(t("Interior orientation")) + "</h3>"
            + f'<p data-key="intrinsics.modes">Given calibrations: {modes}. Fixed: held at the given values through '
            "the alignment and the georeference; refined: refined in the georeference with priors at the given "
            f"values (σ from the calibration file, else {100 * REFINED_FOCAL_SIGMA:g} % of the focal length, "
            f"{100 * REFINED_PP_SIGMA:g} % of the image's long side for the principal point, "
            f"{REFINED_RADIAL_SIGMA:g} for k1..k3, {REFINED_TANGENTIAL_SIGMA:g} for p1, p2); estimated: "
            "self-calibrated from the given values. Pixels: (0, 0) is the upper-left corner of the image, y down; "
            "k1..k3, p1, p2 are OpenCV's coefficients on normalised image coordinates.</p>"
            + (f'<p class="warn" data-key="intrinsics.warning">Moved beyond {MOVED_SIGMAS:g} σ: '
               f'{esc("; ".join(far))}</p>' if far else "")
            + f'<ul data-key="intrinsics.mm">{"".join(lines)}</ul>' + height
            + table(["camera", "mode", "parameter", "given", "σ", "final", "moved", "moved (σ)"], rows))


def _connectivity(ctx: ReportContext) -> str:
    d = ctx.d
    c = d.shared_points()
    n = len(c)
    centres = d.centres()
    fig = new_figure(10.5, 4.6)
    gs = fig.add_gridspec(1, 2, wspace=0.35)
    ax = fig.add_subplot(gs[0, 0])
    from matplotlib.colors import LogNorm

    im = ax.imshow(np.where(c > 0, c, np.nan), cmap="viridis", norm=LogNorm(vmin=1, vmax=max(2, c.max())),
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, shrink=0.8, label=t("shared tie points"))
    if n <= 40:
        ax.set_xticks(range(n))
        ax.set_yticks(range(n))
        ax.set_xticklabels(d.obs.image_names, rotation=90, fontsize=5)
        ax.set_yticklabels(d.obs.image_names, fontsize=5)
    else:
        ax.tick_params(labelsize=6)
    ax.set_title(t("image × image"), fontsize=9)
    ax2 = fig.add_subplot(gs[0, 1])
    iu = np.argwhere(np.triu(c) > 0)
    if len(iu):
        w = c[iu[:, 0], iu[:, 1]]
        order = np.argsort(w)
        from matplotlib.collections import LineCollection

        segs = np.stack([centres[iu[order, 0], :2], centres[iu[order, 1], :2]], axis=1)
        lc = LineCollection(segs, array=np.log10(w[order]), cmap="viridis",
                            linewidths=0.4 + 2.0 * w[order] / w.max())
        ax2.add_collection(lc)
    ax2.scatter(centres[:, 0], centres[:, 1], s=10, c="#c0392b", zorder=3)
    weak = [k for k in range(n) if (c[k] > 0).sum() <= 1]
    for k in weak:
        ax2.annotate(d.obs.image_names[k], centres[k, :2], fontsize=6, color="#c0392b")
    equal_xy(ax2)
    ax2.autoscale()
    ax2.set_title(t("camera centres ({}); line width ∝ shared points").format(d.unit), fontsize=9)
    n_pairs = int((np.triu(c) > 0).sum())
    return ("<h3>" + esc(t("Image connectivity")) + "</h3>" + embed(
        fig, "image connectivity", f"Which photos share tie points and how many: {n_pairs} connected image pairs. "
        "Images linked to at most one other image are named on the map.")
        + (f'<p class="warn">Weakly connected images: {esc(", ".join(d.obs.image_names[k] for k in weak))}</p>'
           if weak else ""))


def _camera_plot(ctx: ReportContext) -> str:
    d = ctx.d
    centres = d.centres()
    tie = d.tie_xyz()
    mean_img, _ = d.per_image_error()
    cams = camera_position_figures(d.residuals) if d.residuals else None
    fig = new_figure(7.5, 6.0)
    ax = fig.add_subplot(111)
    if len(tie):
        sub = tie[:: max(1, len(tie) // 20000)]
        ax.scatter(sub[:, 0], sub[:, 1], s=0.3, c="#bbbbbb", lw=0, label=t("tie points"))
    caption = "Camera projection centres over the tie points"
    if cams:
        rows = [r for r in cams["rows"] if r.get("dx") is not None]
        xy = np.array([[r["x"], r["y"]] for r in rows], dtype=float)
        dxy = np.array([[r["dx"], r["dy"]] for r in rows], dtype=float)
        dz = np.array([np.nan if r.get("dz") is None else r["dz"] for r in rows], dtype=float)
        ext = float(np.ptp(centres[:, :2], axis=0).max()) if len(centres) > 1 else 1.0
        lmax = float(np.hypot(dxy[:, 0], dxy[:, 1]).max()) if len(dxy) else 0.0
        k = 0.15 * ext / lmax if lmax > 0 else 1.0
        lim = float(np.nanmax(np.abs(dz))) if np.any(np.isfinite(dz)) else 1.0
        sc = ax.scatter(xy[:, 0], xy[:, 1], c=np.nan_to_num(dz), cmap="RdBu_r", vmin=-lim, vmax=lim, s=28,
                        edgecolors="k", linewidths=0.4, zorder=3)
        fig.colorbar(sc, ax=ax, shrink=0.7, label=t("dZ (m): adjusted − given"))
        q = ax.quiver(xy[:, 0], xy[:, 1], dxy[:, 0] * k, dxy[:, 1] * k, angles="xy", scale_units="xy", scale=1,
                      color="#c0392b", width=0.004, zorder=4)
        ref = nice(lmax)
        ax.quiverkey(q, 0.82, 0.96, ref * k, f"{ref:g} m", labelpos="E", coordinates="axes",
                     fontproperties={"size": 7})
        excl = [r for r in cams["rows"] if not r.get("used", True)]
        for r in excl:
            ax.annotate("excluded " + r["image"], (r["x"], r["y"]), fontsize=6, color="#c0392b")
        caption += (f"; arrows: horizontal camera-position residual (adjusted − given), exaggerated ×{k:.3g}; "
                    "colour: vertical residual.")
    else:
        sc = ax.scatter(centres[:, 0], centres[:, 1], c=np.nan_to_num(mean_img), cmap="viridis", s=28,
                        edgecolors="k", linewidths=0.4, zorder=3)
        fig.colorbar(sc, ax=ax, shrink=0.7, label=t("mean reprojection error (px)"))
        caption += "; colour: mean reprojection error per image (no camera positions were given)."
    equal_xy(ax)
    ax.set_title(t("camera positions ({})").format(d.crs_label or d.unit), fontsize=9)
    return "<h3>" + esc(t("Camera positions")) + "</h3>" + embed(fig, "camera positions", caption)
