"""The uncertainty section: standard deviations of cameras and tie points from the bundle adjustment
covariance (:mod:`core.georef.uncertainty`), also written as GeoPackage layers."""
from __future__ import annotations

import os
from typing import Optional

import numpy as np

from ...common.progress import Progress, SubProgress
from ...georef import uncertainty as unc
from ..context import ReportContext, Skip
from ..figures import embed, equal_xy, new_figure
from ..html import cell, duration, esc, fmt, kv, num, table, td
from ..labels import t
from ..residuals import residual_rows


def compute(ctx: ReportContext, requested: bool, layers_dir: Optional[str], progress: Progress) -> None:
    """The covariance into ``ctx.unc`` (or why not into ``ctx.unc_error``); with ``layers_dir`` its
    GeoPackage layers into ``ctx.layers``."""
    d = ctx.d
    if not requested:
        ctx.unc_error = "not requested"
        return
    if d.rec is None:
        ctx.unc_error = "the workspace is not aligned"
        return
    try:
        control, priors, free, offset = unc.workspace_inputs(d.ws, d.rec)
        ctx.unc = unc.estimate(d.rec, control, priors, free, offset=offset, observations=d.obs,
                                progress=SubProgress(progress, 0.0, 1.0))
    except (unc.UncertaintyError, ValueError, np.linalg.LinAlgError, MemoryError) as e:
        ctx.unc_error = str(e)
        ctx.warnings.append(f"uncertainty not computed: {e}")
        return
    if layers_dir:
        try:
            ctx.layers = unc.write_layers(ctx.unc, layers_dir, d.crs)
        except (OSError, RuntimeError) as e:
            ctx.warnings.append(f"uncertainty layers not written: {e}")


def section(ctx: ReportContext) -> str:
    d = ctx.d
    u = ctx.unc
    if u is None:
        raise Skip(f"not computed: {ctx.unc_error or 'unknown reason'}.")
    s = u.summary()
    unit = "m" if u.datum != "free network" else d.unit
    ctx.figures.update(SIGMA0=num(u.sigma0), POINT_STD_XY_MEDIAN=s["point_std_xy_median"],
                        POINT_STD_Z_MEDIAN=s["point_std_z_median"])
    parts = [kv([
        ("Datum", esc(u.datum_text())),
        ("Sigma0 (a posteriori, unit weight = 1 px)", f'<span data-key="sigma0">{fmt(u.sigma0, 3)}</span>'),
        ("Redundancy", f"{u.redundancy:,}"),
        ("Observations / points", f"{u.n_observations:,} / {u.n_points:,}"),
        ("Camera position σXY / σZ (median)", f"{fmt(s['camera_std_xy_median'], 3)} / "
                                               f"{fmt(s['camera_std_z_median'], 3)} {unit}"),
        ("Tie point σXY / σZ (median)", f"{fmt(s['point_std_xy_median'], 3)} / {fmt(s['point_std_z_median'], 3)} "
                                        f"{unit}"),
        ("Tie point σXY / σZ (95th percentile)", f"{fmt(s['point_std_xy_p95'], 3)} / "
                                                  f"{fmt(s['point_std_z_p95'], 3)} {unit}"),
        ("GeoPackage layers", esc(", ".join(os.path.relpath(p, d.ws.root) for p in ctx.layers.values()))
         or "not written"),
        ("Computed in", duration(u.seconds)),
    ])]
    if u.notes:
        parts.append('<ul class="notes">' + "".join(f"<li>{esc(n)}</li>" for n in u.notes) + "</ul>")
    ps = u.point_std
    ok = np.all(np.isfinite(ps), axis=1)
    if ok.any():
        h = np.hypot(ps[ok, 0], ps[ok, 1])
        z = ps[ok, 2]
        fig = new_figure(11.0, 4.2)
        gs = fig.add_gridspec(1, 3, wspace=0.45)
        ax = fig.add_subplot(gs[0, 0])
        hi = float(np.percentile(np.concatenate([h, z]), 99))
        ax.hist(np.clip(h, 0, hi), bins=40, alpha=0.7, label=t("σXY"), color="#4477aa")
        ax.hist(np.clip(z, 0, hi), bins=40, alpha=0.6, label=t("σZ"), color="#e69f00")
        ax.set_xlabel(t("standard deviation ({})").format(unit), fontsize=8)
        ax.set_ylabel(t("tie points"), fontsize=8)
        ax.legend(fontsize=7)
        ax.tick_params(labelsize=7)
        ax2 = fig.add_subplot(gs[0, 1:])
        xyz = u.point_xyz[ok] + u.offset
        order = np.argsort(z)
        vmax = float(np.percentile(z, 95))
        sc = ax2.scatter(xyz[order, 0], xyz[order, 1], c=z[order], s=1.5, cmap="magma_r", vmin=0, vmax=vmax,
                         lw=0)
        fig.colorbar(sc, ax=ax2, shrink=0.8, label=f"σZ ({unit})")
        cxy = np.array([[c["x"], c["y"]] for c in u.cameras]) + u.offset[:2]
        ax2.scatter(cxy[:, 0], cxy[:, 1], s=12, marker="s", c="#4477aa", label=t("cameras"))
        if u.control:
            res_pts = {p["name"]: p for p in residual_rows(d.residuals or {})}
            cp = [res_pts[c["name"]] for c in u.control if c["name"] in res_pts]
            if cp:
                ax2.scatter([p["x"] for p in cp], [p["y"] for p in cp], marker="^", s=50, c="none",
                            edgecolors="#228833", linewidths=1.2, label=t("control"))
        ax2.legend(fontsize=7, loc="lower left")
        equal_xy(ax2)
        parts.append(embed(fig, "point standard deviations",
                          "Left: distribution of the tie points' standard deviations. Right: σZ over the block, "
                          "colours clipped at the 95th percentile (precision degrades where few images overlap "
                          "and away from control)."))
    rows = [[td(c["image"]), td(c["camera_id"]), cell(c["sx"], 3), cell(c["sy"], 3), cell(c["sz"], 3),
             cell(c["s_rx"], 4), cell(c["s_ry"], 4), cell(c["s_rz"], 4)] for c in u.cameras]
    parts.append("<details><summary>" + esc(t("Per camera: standard deviations")) + "</summary>" + table(
        ["image", "camera", f"σX ({unit})", f"σY ({unit})", f"σZ ({unit})", "σ rot x (°)", "σ rot y (°)",
         "σ rot z (°)"], rows) + "<p class=\"note\">Rotations about the camera axes (x right, y down, z along "
                                 "the view).</p></details>")
    if u.control:
        rows = [[td(c["name"]), cell(c["sx"], 4), cell(c["sy"], 4), cell(c["sz"], 4)] for c in u.control]
        parts.append("<details><summary>" + esc(t("Control points: adjusted standard deviations")) + "</summary>"
                     + table(["name", "σX (m)", "σY (m)", "σZ (m)"], rows) + "</details>")
    return "".join(parts)
