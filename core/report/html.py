"""The accuracy and quality report: one self-contained HTML file a person reads at a glance.

``build_report(workspace)`` reads what the stages left in a workspace and writes ``<workspace>/report.html``
(or ``output_html``): no network, no scripts, every plot a PNG embedded as a ``data:`` URI (matplotlib,
Agg canvas, no pyplot so it never touches a GUI backend).  Sections:

- *at a glance*: key figures and a short list of what is good and what needs attention;
- *summary*: images given / aligned / not aligned (and why), image screening when "Prepare images" ran,
  cameras with their calibrated parameters and standard deviations, GSD, area, CRS, stage times,
  parameters;
- *orientation quality*: reprojection errors (histogram, per image), tie-point track lengths, image
  connectivity (shared tie points, as a matrix and a map), camera positions with their residuals;
- *georeferencing*: control and check points with dX dY dZ and image residuals, a residual vector plot
  over the footprint, RMSE per set, NSSDA (FGDC-STD-007.3-1998) statements, ASPRS 2014 and 2023 classes,
  camera-position residuals, outliers and suspect points;
- *uncertainty*: standard deviations of cameras and points from the bundle adjustment covariance
  (``core.uncertainty``), also written as GeoPackage layers;
- *products*: DSM and orthomosaic previews (hillshade), resolution, valid fraction.

A section whose stage has not run says so in one line and the rest of the report is still written.  Every
accuracy number is computed by ``core.accuracy`` (``residual_stats``, ``nssda_horizontal_report``,
``nssda_vertical``, ``nssda_statement``, ``asprs_horizontal_class``, ``asprs_vertical_class``): the same
functions behind the Processing outputs.  The file is written through a temporary name and renamed when
complete, so a cancelled run never leaves a report that looks finished.
"""
from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import json
import math
import os
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Cancelled, NullProgress, Progress, SubProgress, check_cancel
from ..georef import accuracy
from ..project.workspace import CANCELLED, DONE, FAILED, Workspace, WorkspaceError, atomic_output

STAGE = "report"
REPORT_FILE = "report.html"
UNCERTAINTY_DIR = "uncertainty"
DPI = 96
MAX_TABLE_ROWS = 400  # longer tables are cut (the GeoPackage layers hold everything)
ASPRS_MIN_CHECKS = {2014: 20, 2023: 30}
NSSDA_MIN_CHECKS = 20


class ReportError(RuntimeError):
    """The report cannot be written; the message says why."""


class _Skip(Exception):
    """A section without its inputs: the message is shown instead of the section."""


@dataclass
class ReportResult:
    path: str
    workspace: str
    figures: Dict[str, Any]
    sections: Dict[str, str]  # section id -> "ok" or the reason it was skipped
    layers: Dict[str, str] = field(default_factory=dict)  # uncertainty GeoPackages
    warnings: List[str] = field(default_factory=list)
    seconds: float = 0.0


# --------------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------------

def _esc(v: Any) -> str:
    return html.escape(str(v), quote=True)


def _num(v: Any) -> Optional[float]:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def _f(v: Any, decimals: int = 3, unit: str = "") -> str:
    f = _num(v)
    if f is None:
        return "–"
    return f"{f:.{decimals}f}{(' ' + unit) if unit else ''}"


def _cell(v: Any, decimals: int = 3, key: Optional[str] = None) -> str:
    """A numeric table cell; ``key`` names it for machines (``data-key``) with the full value."""
    f = _num(v)
    attrs = ' class="n"'
    if key:
        attrs += f' data-key="{_esc(key)}"'
        if f is not None:
            attrs += f' data-value="{f!r}"'
    return f"<td{attrs}>{_f(v, decimals)}</td>"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]], cls: str = "", raw: bool = True,
           limit: int = MAX_TABLE_ROWS) -> str:
    """Rows are lists of ready HTML cells (``<td>...``) when ``raw``, else of texts to escape."""
    out = [f'<table class="{cls}"><thead><tr>' + "".join(f"<th>{_esc(h)}</th>" for h in header)
           + "</tr></thead><tbody>"]
    for r in rows[:limit]:
        cells = r if raw else [f"<td>{_esc(c)}</td>" for c in r]
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table>")
    if len(rows) > limit:
        out.append(f'<p class="note">{len(rows) - limit} more rows not shown.</p>')
    return "".join(out)


def _td(text: Any, cls: str = "") -> str:
    return f'<td class="{cls}">{_esc(text)}</td>' if cls else f"<td>{_esc(text)}</td>"


def _kv(rows: Sequence[Tuple[str, str]]) -> str:
    return ('<table class="kv"><tbody>' + "".join(f"<tr><th>{_esc(k)}</th><td>{v}</td></tr>" for k, v in rows)
            + "</tbody></table>")


def _read_json(path: str) -> Optional[Dict[str, Any]]:
    if not os.path.isfile(path):
        return None
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        raise ReportError(f"{path} cannot be read: {e}") from e


def _duration(sec: Any) -> str:
    s = _num(sec)
    if s is None:
        return "–"
    if s < 60:
        return f"{s:.1f} s"
    if s < 3600:
        return f"{int(s // 60)} min {s % 60:02.0f} s"
    return f"{int(s // 3600)} h {int(s % 3600 // 60):02d} min"


def _area(m2: Optional[float]) -> str:
    if m2 is None:
        return "–"
    if m2 >= 1e6:
        return f"{m2 / 1e6:.3f} km² ({m2 / 1e4:.1f} ha)"
    return f"{m2 / 1e4:.3f} ha ({m2:.0f} m²)"


def _badge(kind: str, text: str) -> str:
    return f'<li class="{kind}"><span class="dot"></span>{text}</li>'


# --------------------------------------------------------------------------------------------------
# plots
# --------------------------------------------------------------------------------------------------

def _figure(w: float = 7.0, h: float = 4.0):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=DPI)
    return fig


def _img(fig, alt: str, caption: str = "", cls: str = "") -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight", facecolor="white")
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    cap = f"<figcaption>{caption}</figcaption>" if caption else ""
    return (f'<figure class="{cls}"><img alt="{_esc(alt)}" src="data:image/png;base64,{data}">{cap}</figure>')


def _equal_xy(ax) -> None:
    ax.set_aspect("equal", adjustable="datalim")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.tick_params(labelsize=7)
    ax.grid(True, color="#ddd", lw=0.5)


def _hull(xy: np.ndarray) -> Optional[np.ndarray]:
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


def _poly_area(ring: Optional[np.ndarray]) -> Optional[float]:
    if ring is None:
        return None
    x, y = ring[:, 0], ring[:, 1]
    return float(0.5 * abs(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1])))


# --------------------------------------------------------------------------------------------------
# what the workspace holds
# --------------------------------------------------------------------------------------------------

class _Data:
    """Everything the sections read, loaded once."""

    def __init__(self, ws: Workspace, progress: Progress):
        from ..georef.uncertainty import collect_observations

        self.ws = ws
        self.manifest = json.loads(json.dumps(ws.data, default=str))  # as it was before the report stage
        self.alignment = _read_json(ws.path("sfm", "alignment.json"))
        self.georeferenced = ws.stage_done("georeference") and os.path.isdir(ws.path("georef", "model"))
        self.residuals = _read_json(ws.path("georef", "residuals.json")) if self.georeferenced else None
        self.transform = _read_json(ws.path("georef", "transform.json")) if self.georeferenced else None
        self.offset = np.asarray((self.transform or {}).get("offset", [0.0, 0.0, 0.0]), dtype=float)
        self.crs = ws.crs if self.georeferenced else None
        self.crs_label = crs_label(self.crs) if self.crs else None
        self.screening = _read_json(ws.path("screening.json"))
        self.rec = None
        self.obs = None
        model = ws.path("georef", "model") if self.georeferenced else ws.path("sfm", "model")
        if ws.stage_done("align") and os.path.isdir(model):
            import pycolmap

            progress.report(0.0, "reading the sparse model")
            self.rec = pycolmap.Reconstruction()
            self.rec.read_binary(model)
            self.obs = collect_observations(self.rec)
        self.model_dir = model
        self.unit = "m" if self.georeferenced else "model units"

    # --- derived ---------------------------------------------------------------------------------
    def centres(self) -> np.ndarray:
        rec, obs = self.rec, self.obs
        return np.array([np.asarray(rec.image(int(i)).projection_center(), dtype=float) for i in obs.image_ids]
                        ).reshape(-1, 3) + self.offset

    def tie_xyz(self) -> np.ndarray:
        return self.obs.xyz + self.offset

    def gsd(self) -> Optional[float]:
        """Median over images of (median depth of the image's tie points / focal length in pixels)."""
        if self.rec is None or not len(self.obs.img):
            return None
        vals = []
        o = self.obs
        order = np.argsort(o.img, kind="stable")
        bounds = np.searchsorted(o.img[order], np.arange(len(o.image_ids) + 1))
        for k, iid in enumerate(o.image_ids):
            rows = order[bounds[k]:bounds[k + 1]]
            if not len(rows):
                continue
            im = self.rec.image(int(iid))
            mat = np.asarray(im.cam_from_world().matrix())
            depth = o.xyz[o.pt[rows]] @ mat[2, :3] + mat[2, 3]
            depth = depth[depth > 0]
            cam = self.rec.cameras[im.camera_id]
            f = float(np.mean([cam.params[i] for i in cam.focal_length_idxs()]))
            if len(depth) and f > 0:
                vals.append(float(np.median(depth)) / f)
        return float(np.median(vals)) if vals else None

    def footprint(self) -> Optional[np.ndarray]:
        if self.rec is None or not len(self.obs.xyz):
            return None
        return _hull(self.tie_xyz()[:, :2])

    def shared_points(self) -> np.ndarray:
        import scipy.sparse as sp

        o = self.obs
        n_i, n_p = len(o.image_ids), len(o.point_ids)
        a = sp.csr_matrix((np.ones(len(o.img)), (o.pt, o.img)), shape=(n_p, n_i))
        a.data[:] = 1.0
        c = (a.T @ a).toarray()
        np.fill_diagonal(c, 0)
        return c

    def per_image_error(self) -> Tuple[np.ndarray, np.ndarray]:
        o = self.obs
        err = o.error
        ok = np.isfinite(err)
        n = np.bincount(o.img[ok], minlength=len(o.image_ids))
        s = np.bincount(o.img[ok], weights=err[ok], minlength=len(o.image_ids))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, s / np.maximum(n, 1), np.nan), n


# --------------------------------------------------------------------------------------------------
# accuracy figures (core.accuracy)
# --------------------------------------------------------------------------------------------------

def _residual_rows(residuals: Dict[str, Any], key: str = "points") -> List[Dict[str, Any]]:
    return [p for p in (residuals or {}).get(key, []) if isinstance(p, dict)]


def _sets(points: Sequence[Dict[str, Any]]) -> Dict[str, List[Dict[str, Any]]]:
    return {
        "control": [p for p in points if p.get("status") == "used" and p.get("dx") is not None],
        "check": [p for p in points if p.get("status") == "check" and p.get("dx") is not None],
        "rejected": [p for p in points if p.get("status") == "rejected" and p.get("dx") is not None],
    }


def _stats(rows: Sequence[Dict[str, Any]]) -> Dict[str, Any]:
    def col(k):
        return [np.nan if r.get(k) is None else float(r[k]) for r in rows]

    return accuracy.residual_stats(col("dx"), col("dy"), col("dz"))


def accuracy_figures(residuals: Dict[str, Any], gsd: Optional[float] = None) -> Dict[str, Any]:
    """Statistics, NSSDA and ASPRS figures from georef/residuals.json, all through core.accuracy.

    ``tested`` is True when check points exist (NSSDA "Tested ..."); otherwise the control points' residuals
    give a "Compiled to meet ..." figure (not independent: optimistic) and ``tested`` is False."""
    points = _residual_rows(residuals)
    sets = _sets(points)
    stats = {k: _stats(v) for k, v in sets.items()}
    helmert = _sets(_residual_rows(residuals, "helmert_points"))["check"]
    stats["check_helmert_only"] = _stats(helmert)
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
    cams = [c for c in _residual_rows(residuals, "cameras") if c.get("dx") is not None]
    if not cams:
        return None
    used = [c for c in cams if c.get("used", True)]
    return {"rows": cams, "stats": _stats(used), "excluded": [c for c in cams if not c.get("used", True)]}


# --------------------------------------------------------------------------------------------------
# sections
# --------------------------------------------------------------------------------------------------

class _Report:
    def __init__(self, data: _Data, progress: Progress, uncertainty: bool, layers_dir: Optional[str]):
        self.d = data
        self.progress = progress
        self.do_uncertainty = uncertainty
        self.layers_dir = layers_dir
        self.figures: Dict[str, Any] = {}
        self.glance: List[str] = []
        self.warnings: List[str] = []
        self.layers: Dict[str, str] = {}
        self.unc = None
        self.unc_error: Optional[str] = None
        self.acc: Optional[Dict[str, Any]] = None
        self.gsd: Optional[float] = None

    # ---- summary ---------------------------------------------------------------------------------
    def summary(self) -> str:
        d = self.d
        m = d.manifest
        images = m.get("images", [])
        al = d.alignment or {}
        n_given = al.get("images_given", len(images))
        parts = []
        rows = [("Workspace", _esc(d.ws.root)), ("Images folder", _esc(m.get("images_dir") or "–"))]
        if d.rec is not None:
            n_reg = len(d.obs.image_ids)
            self.figures.update(IMAGES=n_given, REGISTERED_IMAGES=n_reg, POINTS3D=int(len(d.obs.point_ids)))
            rows.append(("Images given / aligned / not aligned",
                         f'<span data-key="images.given">{n_given}</span> / '
                         f'<span data-key="images.aligned">{n_reg}</span> / '
                         f'<span data-key="images.not_aligned">{max(0, n_given - n_reg)}</span>'))
            rows.append(("Tie points / image observations", f"{len(d.obs.point_ids):,} / {len(d.obs.img):,}"))
            self.gsd = d.gsd()
            fp = d.footprint()
            area = _poly_area(fp) if d.georeferenced else None
            self.figures.update(GSD=self.gsd if d.georeferenced else None, AREA_M2=area)
            if d.georeferenced:
                rows.append(("Ground sample distance (median)",
                             f'<span data-key="gsd">{_f(self.gsd, 4)}</span> m ({_f(self.gsd and self.gsd * 100, 2)} cm)'))
                rows.append(("Area covered by tie points", _area(area)))
            else:
                rows.append(("Ground sample distance", f"{_f(self.gsd, 5)} model units per pixel (not georeferenced)"))
        else:
            self.figures.update(IMAGES=len(images) or None, REGISTERED_IMAGES=None)
            rows.append(("Images given", str(len(images))))
        crs_txt = ("none (local model frame)" if not d.crs else d.crs_label if str(d.crs) in d.crs_label
                   else f"{d.crs_label}: {d.crs}")
        rows.append(("Coordinate reference system", _esc(crs_txt)))
        parts.append(_kv(rows))

        # not aligned, with why
        unreg = al.get("unregistered") or {}
        skipped = al.get("skipped_files") or []
        if unreg or skipped:
            r = [[_td(n), _td(w)] for n, w in sorted(unreg.items())] + [[_td(s), _td("not read")] for s in skipped]
            parts.append("<h3>Images not aligned</h3>" + _table(["image", "why"], r))
        elif d.rec is not None:
            parts.append('<p class="ok">Every image given was aligned.</p>')
        if al.get("other_components"):
            parts.append('<p class="warn">Separate components left out: ' + "; ".join(
                _esc(", ".join(c)) for c in al["other_components"]) + "</p>")

        parts.append(self._screening())
        parts.append(self._cameras())
        parts.append(self._stages())
        return "".join(parts)

    def _screening(self) -> str:
        s = self.d.screening
        if not s:
            return ('<h3>Image screening</h3><p class="skip">Not run: the images were not screened '
                    "(run 'Prepare images' for blur and exposure scores).</p>")
        imgs = s.get("images", [])
        rows = []
        for q in sorted(imgs, key=lambda q: q.get("blur_rank", 0)):
            cls = "bad" if q.get("decision") == "exclude" else ("warn" if q.get("flags") else "")
            rows.append([_td(q.get("name")), _cell(q.get("blur_score"), 1), _cell(q.get("blur_relative"), 2),
                         _cell(q.get("exposure_score"), 2), _cell(q.get("dynamic_range"), 2),
                         _td(", ".join(q.get("flags") or []) or "–"), _td(q.get("decision", "keep"), cls)])
        head = (f"<h3>Image screening</h3><p>{len(imgs)} images screened: {s.get('flagged', 0)} flagged, "
                f"{s.get('excluded', 0)} excluded, {s.get('kept', len(imgs))} kept (blurriest first).</p>")
        plot = ""
        if imgs:
            fig = _figure(7.5, 2.6)
            ax = fig.add_subplot(111)
            srt = sorted(imgs, key=lambda q: q.get("blur_score", 0.0))
            colours = ["#c0392b" if q.get("decision") == "exclude" else "#e69f00" if q.get("flags") else "#4477aa"
                       for q in srt]
            ax.bar(range(len(srt)), [q.get("blur_score", 0.0) for q in srt], color=colours)
            med = (s.get("median") or {}).get("blur_score")
            if med:
                ax.axhline(med, color="k", lw=0.8, ls="--", label="median")
                ax.legend(fontsize=7)
            ax.set_ylabel("blur score (higher = sharper)", fontsize=8)
            ax.set_xlabel("images, blurriest first", fontsize=8)
            ax.tick_params(labelsize=7)
            plot = _img(fig, "blur scores", "Blur score per image (orange: flagged, red: excluded).")
        return head + plot + "<details><summary>Screening table</summary>" + _table(
            ["image", "blur score", "blur / median", "exposure", "dynamic range", "flags", "decision"], rows
        ) + "</details>"

    def _cameras(self) -> str:
        d = self.d
        if d.rec is None:
            return ""
        unc = self.unc
        rows = []
        for cid, cam in sorted(d.rec.cameras.items()):
            names = [n.strip() for n in str(cam.params_info).split(",")]
            info = unc.intrinsics.get(int(cid)) if unc is not None else None
            n_img = sum(1 for i in d.obs.image_ids if int(d.rec.image(int(i)).camera_id) == int(cid))
            params = []
            for k, (n, v) in enumerate(zip(names, cam.params)):
                sd = info["std"][k] if info else None
                dec = 2 if abs(v) >= 10 else 6
                txt = f"{v:.{dec}f}" + (f" ± {sd:.{dec}f}" if sd is not None else (" (fixed)" if info else ""))
                params.append(f"<span class=\"param\"><b>{_esc(n)}</b> {_esc(txt)}</span>")
            rows.append([_td(cid), _td(cam.model.name), _td(f"{cam.width} × {cam.height}"), _td(n_img),
                         "<td>" + " ".join(params) + "</td>"])
        note = ("Standard deviations from the bundle adjustment covariance (see Uncertainty), scaled by "
                "sigma0; “fixed”: held constant in the adjustment." if unc is not None else
                f"No standard deviations: {self.unc_error or 'uncertainty not computed'}.")
        return ("<h3>Cameras and calibrated parameters</h3>"
                + _table(["camera", "model", "size (px)", "images", "parameters (pixels; distortion unitless)"],
                         rows, cls="cams") + f'<p class="note">{_esc(note)}</p>')

    def _stages(self) -> str:
        stages = self.d.manifest.get("stages", {})
        if not stages:
            return ""
        rows, prow = [], []
        for name, rec in stages.items():
            if name == STAGE:
                continue
            t = rec.get("timings") or {}
            steps = ", ".join(f"{k.replace('_', ' ')} {_duration(v)}" for k, v in t.items() if k != "total")
            rows.append([_td(name), _td(rec.get("status", "–"), "ok" if rec.get("status") == "done" else "warn"),
                         _td(_duration(t.get("total"))), _td(steps or "–"), _td(rec.get("finished") or "–")])
            params = rec.get("parameters") or {}
            prow.append([_td(name), "<td>" + ", ".join(
                f"<b>{_esc(k)}</b>={_esc(json.dumps(v, default=str))}" for k, v in params.items()) + "</td>"])
        return ("<h3>Processing stages</h3>" + _table(["stage", "status", "time", "steps", "finished"], rows)
                + "<details><summary>Parameters used</summary>" + _table(["stage", "parameters"], prow)
                + "</details>")

    # ---- orientation quality ---------------------------------------------------------------------
    def orientation(self) -> str:
        d = self.d
        if d.rec is None:
            raise _Skip("the workspace is not aligned: run 'Align images'.")
        o = d.obs
        err = o.error
        fin = err[np.isfinite(err)]
        mean_img, n_img = d.per_image_error()
        d.rec.update_point_3d_errors()
        mre = _num(d.rec.compute_mean_reprojection_error()) if len(fin) else None
        self.figures["MEAN_REPROJECTION_ERROR"] = mre
        parts = [_kv([
            ("Mean reprojection error (mean over tie points of their mean error, as COLMAP reports it)",
             f'<span data-key="reproj.mean">{_f(mre, 3)}</span> px'),
            ("Reprojection error of the observations: mean / median / RMS",
             f'<span data-key="reproj.obs_mean">{_f(np.mean(fin) if len(fin) else None, 3)}</span> / '
             f'{_f(np.median(fin) if len(fin) else None, 3)} / {_f(accuracy.rmse(fin), 3)} px'),
            ("Largest reprojection error", f"{_f(fin.max() if len(fin) else None, 2)} px"),
            ("Track length: mean / median / max",
             f"{_f(np.mean(o.track_length), 2)} / {_f(np.median(o.track_length), 0)} / {int(o.track_length.max())}"
             if len(o.track_length) else "–"),
            ("Model", _esc(os.path.relpath(d.model_dir, d.ws.root))),
        ])]
        # histogram + track lengths
        fig = _figure(9.0, 3.0)
        ax = fig.add_subplot(121)
        if len(fin):
            hi = max(float(np.percentile(fin, 99.5)), 1e-3)
            ax.hist(np.clip(fin, 0, hi), bins=50, color="#4477aa")
            ax.axvline(np.mean(fin), color="#c0392b", lw=1, label=f"mean {np.mean(fin):.2f} px")
            ax.axvline(np.median(fin), color="k", lw=1, ls="--", label=f"median {np.median(fin):.2f} px")
            ax.legend(fontsize=7)
        ax.set_xlabel("reprojection error (px)", fontsize=8)
        ax.set_ylabel("observations", fontsize=8)
        ax.tick_params(labelsize=7)
        ax2 = fig.add_subplot(122)
        if len(o.track_length):
            tl = o.track_length
            top = int(min(tl.max(), np.percentile(tl, 99.5) + 1))
            ax2.hist(np.clip(tl, 2, top), bins=np.arange(1.5, top + 1.5), color="#228833")
        ax2.set_xlabel("track length (images per tie point)", fontsize=8)
        ax2.set_ylabel("tie points", fontsize=8)
        ax2.tick_params(labelsize=7)
        parts.append(_img(fig, "reprojection error and track length histograms",
                          "Left: reprojection error of every tie-point observation (clipped at the 99.5th "
                          "percentile). Right: number of images per tie point."))
        # per image
        names = d.obs.image_names
        n = len(names)
        fig = _figure(max(7.0, min(16.0, 0.18 * n + 2)), 3.6)
        ax = fig.add_subplot(211)
        med = np.nanmedian(mean_img) if n else 0.0
        colours = ["#c0392b" if v > 2 * med else "#4477aa" for v in np.nan_to_num(mean_img)]
        ax.bar(range(n), np.nan_to_num(mean_img), color=colours)
        ax.set_ylabel("mean error (px)", fontsize=8)
        ax.set_xticks([])
        ax.tick_params(labelsize=7)
        ax2 = fig.add_subplot(212)
        ax2.bar(range(n), n_img, color="#228833")
        ax2.set_ylabel("observations", fontsize=8)
        ax2.set_xticks(range(n))
        ax2.set_xticklabels(names if n <= 80 else [""] * n, rotation=90, fontsize=6)
        ax2.tick_params(axis="y", labelsize=7)
        parts.append(_img(fig, "reprojection error per image",
                          "Mean reprojection error (red: more than twice the median) and tie-point observations "
                          "per image."))
        rows = [[_td(nm), _cell(mean_img[k], 3), _td(int(n_img[k]))] for k, nm in enumerate(names)]
        parts.append("<details><summary>Per-image table</summary>"
                     + _table(["image", "mean reprojection error (px)", "observations"], rows) + "</details>")
        bad = [names[k] for k in range(n) if np.isfinite(mean_img[k]) and mean_img[k] > 2 * med]
        if bad:
            self.glance.append(_badge("warn", f"{len(bad)} image(s) with more than twice the median reprojection "
                                              f"error: {_esc(', '.join(bad[:6]))}{' …' if len(bad) > 6 else ''}"))
        check_cancel(self.progress)
        parts.append(self._connectivity())
        parts.append(self._camera_plot())
        return "".join(parts)

    def _connectivity(self) -> str:
        d = self.d
        c = d.shared_points()
        n = len(c)
        centres = d.centres()
        fig = _figure(10.5, 4.6)
        gs = fig.add_gridspec(1, 2, wspace=0.35)
        ax = fig.add_subplot(gs[0, 0])
        from matplotlib.colors import LogNorm

        im = ax.imshow(np.where(c > 0, c, np.nan), cmap="viridis", norm=LogNorm(vmin=1, vmax=max(2, c.max())),
                       interpolation="nearest")
        fig.colorbar(im, ax=ax, shrink=0.8, label="shared tie points")
        if n <= 40:
            ax.set_xticks(range(n))
            ax.set_yticks(range(n))
            ax.set_xticklabels(d.obs.image_names, rotation=90, fontsize=5)
            ax.set_yticklabels(d.obs.image_names, fontsize=5)
        else:
            ax.tick_params(labelsize=6)
        ax.set_title("image × image", fontsize=9)
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
        _equal_xy(ax2)
        ax2.autoscale()
        ax2.set_title(f"camera centres ({d.unit}); line width ∝ shared points", fontsize=9)
        n_pairs = int((np.triu(c) > 0).sum())
        return ("<h3>Image connectivity</h3>" + _img(
            fig, "image connectivity", f"Which photos share tie points and how many: {n_pairs} connected image pairs. "
            "Images linked to at most one other image are named on the map.")
            + (f'<p class="warn">Weakly connected images: {_esc(", ".join(d.obs.image_names[k] for k in weak))}</p>'
               if weak else ""))

    def _camera_plot(self) -> str:
        d = self.d
        centres = d.centres()
        tie = d.tie_xyz()
        mean_img, _ = d.per_image_error()
        cams = camera_position_figures(d.residuals) if d.residuals else None
        fig = _figure(7.5, 6.0)
        ax = fig.add_subplot(111)
        if len(tie):
            sub = tie[:: max(1, len(tie) // 20000)]
            ax.scatter(sub[:, 0], sub[:, 1], s=0.3, c="#bbbbbb", lw=0, label="tie points")
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
            fig.colorbar(sc, ax=ax, shrink=0.7, label="dZ (m): adjusted − given")
            q = ax.quiver(xy[:, 0], xy[:, 1], dxy[:, 0] * k, dxy[:, 1] * k, angles="xy", scale_units="xy", scale=1,
                          color="#c0392b", width=0.004, zorder=4)
            ref = _nice(lmax)
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
            fig.colorbar(sc, ax=ax, shrink=0.7, label="mean reprojection error (px)")
            caption += "; colour: mean reprojection error per image (no camera positions were given)."
        _equal_xy(ax)
        ax.set_title(f"camera positions ({d.crs_label or d.unit})", fontsize=9)
        return "<h3>Camera positions</h3>" + _img(fig, "camera positions", caption)

    # ---- georeferencing --------------------------------------------------------------------------
    def georeferencing(self) -> str:
        d = self.d
        if not d.georeferenced or d.residuals is None:
            st = d.manifest.get("stages", {}).get("georeference", {}).get("status")
            why = "the workspace is not georeferenced" + (f" (georeference stage: {st})" if st else "")
            self.glance.append(_badge("warn", _esc(why) + ": no accuracy figures"))
            raise _Skip(why + ": run 'Georeference' with ground control points (and check points) or camera "
                              "positions.")
        res = d.residuals
        ortho_res = self._ortho_resolution()
        acc = accuracy_figures(res, ortho_res or self.gsd)
        self.acc = acc
        stats = acc["stats"]
        tf = d.transform or {}
        parts = [_kv([
            ("CRS", _esc(crs_label(res.get("crs") or d.crs))),
            ("Source of the datum", _esc(tf.get("source", "–"))),
            ("Local frame offset (world = local + offset)", _esc(", ".join(f"{v:.1f}" for v in d.offset))),
            ("Tie-point reprojection error after the adjustment",
             f"{_f(res.get('mean_reprojection_error_px'), 3)} px"),
            ("GCP observation reprojection error in the adjustment (mean; control held at its coordinates "
             "within its sigmas)", f"{_f(res.get('gcp_reprojection_error_px'), 3)} px"),
        ])]
        if acc["placeholder_z"]:
            parts.append('<p class="warn">Every control point has the same height (a placeholder, not a surveyed '
                         "Z): the Z residuals measure departure from one level surface, not height accuracy; no "
                         "vertical accuracy is stated.</p>")
        points = _residual_rows(res)
        if points:
            parts.append("<h3>Control and check points</h3>" + self._points_table(points))
            parts.append(self._stats_table(stats))
            parts.append(self._accuracy_statements(acc))
            parts.append(self._residual_plot(points))
        else:
            parts.append('<p class="skip">No ground control points: the block was georeferenced from camera '
                         "positions only, so there are no ground residuals and no NSSDA / ASPRS accuracy.</p>")
            self.glance.append(_badge("warn", "no ground control or check points: accuracy not tested"))
        cams = camera_position_figures(res)
        if cams:
            parts.append(self._camera_residuals(cams))
        parts.append(self._outliers(res, acc))
        self._glance_accuracy(acc)
        return "".join(parts)

    def _points_table(self, points: Sequence[Dict[str, Any]]) -> str:
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
            rows.append([_td(p.get("name")), _td(p.get("role")), _td(status, cls), _cell(p.get("x"), 3),
                         _cell(p.get("y"), 3), _cell(p.get("z"), 3), _cell(p.get("dx"), 3, key + ".dx"),
                         _cell(p.get("dy"), 3, key + ".dy"), _cell(p.get("dz"), 3, key + ".dz"), _cell(dxy, 3),
                         _cell(d3, 3), _td(p.get("n_obs", 0)), _cell(np.mean(px) if px else None, 2),
                         _cell(max(px) if px else None, 2),
                         f'<td class="small">{_esc(obs_txt)}'
                         + (f"<br><i>{_esc('; '.join(p.get('notes') or []))}</i>" if p.get("notes") else "") + "</td>"])
        return _table(["name", "role", "status", "X", "Y", "Z", "dX", "dY", "dZ", "dXY", "d3D", "obs", "mean px",
                       "max px", "image residuals (px)"], rows, cls="pts") + (
            '<p class="note">Residuals are adjusted (triangulated in the adjusted block) minus given, in metres. '
            "Check points took no part in the adjustment; rejected control points were left out as outliers and are "
            "evaluated like check points.</p>")

    def _stats_table(self, stats: Dict[str, Dict[str, Any]]) -> str:
        labels = {"control": "control (used)", "check": "check points", "rejected": "rejected control",
                  "check_helmert_only": "check points, Helmert (7-parameter) only"}
        rows = []
        for k, lab in labels.items():
            s = stats[k]
            if not s["n"]:
                continue
            rows.append([_td(lab), _td(s["n"]), _cell(s["rmse_x"], 3, f"{k}.rmse_x"),
                         _cell(s["rmse_y"], 3, f"{k}.rmse_y"), _cell(s["rmse_z"], 3, f"{k}.rmse_z"),
                         _cell(s["rmse_r"], 3, f"{k}.rmse_r"), _cell(s["rmse_xyz"], 3, f"{k}.rmse_xyz"),
                         _cell(s["mean_x"], 3), _cell(s["mean_y"], 3), _cell(s["mean_z"], 3),
                         _cell(s["max"]["r"], 3), _cell(s["max_z"], 3)])
        if not rows:
            return '<p class="skip">No control or check point could be evaluated.</p>'
        for k in ("control", "check"):
            s = stats[k]
            if s["n"]:
                pre = "CHECK" if k == "check" else "CONTROL"
                self.figures.update({f"{pre}_N": s["n"], f"{pre}_RMSE_X": _num(s["rmse_x"]),
                                     f"{pre}_RMSE_Y": _num(s["rmse_y"]), f"{pre}_RMSE_Z": _num(s["rmse_z"]),
                                     f"{pre}_RMSE_XY": _num(s["rmse_r"])})
        return ("<h3>RMSE per set</h3>" + _table(
            ["set", "n", "RMSE X", "RMSE Y", "RMSE Z", "RMSE XY (radial)", "RMSE 3D", "mean dX", "mean dY", "mean dZ",
             "max dXY", "max |dZ|"], rows) + '<p class="note">Metres. The mean is the bias of each axis.</p>')

    def _accuracy_statements(self, acc: Dict[str, Any]) -> str:
        nssda = acc["nssda"]
        if nssda is None:
            return ""
        parts = ["<h3>NSSDA accuracy at 95 % confidence (FGDC-STD-007.3-1998)</h3>"]
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
            self.figures["NSSDA_H"] = _num(h["accuracy"])
            items.append(f'<li class="statement" data-key="nssda.horizontal" data-value="{h["accuracy"]!r}">'
                         f"{_esc(h['statement'])}</li>")
            note = h.get("note", "")
            parts_note = f'<p class="note">Horizontal: {_esc(note)}; RMSE_x / RMSE_y ratio {h["ratio"]:.2f}.</p>'
        else:
            parts_note = ""
        v = nssda["vertical"]
        if v is not None:
            self.figures["NSSDA_V"] = _num(v["accuracy"])
            items.append(f'<li class="statement" data-key="nssda.vertical" data-value="{v["accuracy"]!r}">'
                         f"{_esc(v['statement'])}</li>")
        elif acc["placeholder_z"]:
            items.append("<li>No vertical accuracy: the control heights are placeholders.</li>")
        parts.append("<ul class=\"statements\">" + "".join(items) + "</ul>" + parts_note)
        if acc["asprs"]:
            parts.append("<h3>ASPRS positional accuracy class</h3>")
            rows = []
            for ed, a in acc["asprs"].items():
                hh, vv = a["horizontal"], a["vertical"]
                n_need = ASPRS_MIN_CHECKS[ed]
                if hh:
                    self.figures[f"ASPRS_{ed}_H_CLASS_CM"] = hh["class_cm"]
                if vv:
                    self.figures[f"ASPRS_{ed}_V_CLASS_CM"] = vv["class_cm"]
                rows.append(
                    f"<tr><th>{'Edition 1 (2014)' if ed == 2014 else 'Edition 2 (2023)'}</th>"
                    f'<td class="n" data-key="asprs.{ed}.h" data-value="{hh["class_cm"] if hh else ""}">'
                    f"{_f(hh and hh['class_cm'], 1)} cm</td>"
                    f'<td class="n" data-key="asprs.{ed}.v" data-value="{vv["class_cm"] if vv else ""}">'
                    f"{_f(vv and vv['class_cm'], 1)} cm</td>"
                    f'<td class="small">{_esc(hh["statement"]) if hh else ""}'
                    f"{'<br>' + _esc(vv['statement']) if vv else ''}"
                    + (f"<br><i>The standard asks for at least {n_need} check points; {acc['nssda']['n']} were "
                       "used.</i>" if acc["nssda"]["n"] < n_need else "")
                    + ("<br><i>Edition 2 adds the check points' own survey error in quadrature: taken as 0 here "
                       "(not recorded in the workspace).</i>" if ed == 2023 else "")
                    + (f"<br><i>Relative to {hh['gsd_cm']:.1f} cm pixels: {_esc(hh['recommended_use'])} "
                       f"({hh['class_pixels']:.1f} pixels).</i>" if hh and hh.get("recommended_use") else "")
                    + "</td></tr>")
            parts.append('<table class="asprs"><thead><tr><th>standard</th><th>horizontal class (RMSE)</th>'
                         "<th>vertical class (RMSE)</th><th>statement</th></tr></thead><tbody>" + "".join(rows)
                         + "</tbody></table>")
        return "".join(parts)

    def _residual_plot(self, points: Sequence[Dict[str, Any]]) -> str:
        d = self.d
        pts = [p for p in points if p.get("dx") is not None]
        if not pts:
            return ""
        fig = _figure(7.5, 6.2)
        ax = fig.add_subplot(111)
        fp = d.footprint()
        if fp is not None:
            ax.fill(fp[:, 0], fp[:, 1], color="#eef3f8", ec="#9fb3c8", lw=0.8, label="tie-point footprint")
        centres = d.centres()
        ax.scatter(centres[:, 0], centres[:, 1], s=6, c="#888888", marker="s", lw=0, label="camera centres")
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
        ref = _nice(lmax)
        ax.quiverkey(q, 0.82, 0.96, ref * k, f"{ref:g} m", labelpos="E", coordinates="axes",
                     fontproperties={"size": 7})
        for p in pts:
            ax.annotate(p["name"], (p["x"], p["y"]), xytext=(4, 4), textcoords="offset points", fontsize=7)
        if sc is not None:
            fig.colorbar(sc, ax=ax, shrink=0.7, label="dZ (m)")
        ax.legend(fontsize=7, loc="lower left")
        _equal_xy(ax)
        ax.set_title(f"ground point residuals ({d.crs_label})", fontsize=9)
        return "<h3>Residual vectors over the footprint</h3>" + _img(
            fig, "residual vectors", f"Horizontal residual of each control (triangle) and check point (circle), "
            f"exaggerated ×{k:.3g} (key: {ref:g} m); colour: vertical residual. Systematic patterns (all arrows one "
            "way, growing towards an edge) point at a block deformation or a datum problem; a lone long arrow at a "
            "wrong coordinate or marking.")

    def _camera_residuals(self, cams: Dict[str, Any]) -> str:
        s = cams["stats"]
        self.figures.update(CAMERA_RMSE_XY=_num(s["rmse_r"]), CAMERA_RMSE_Z=_num(s["rmse_z"]))
        rows = [[_td(c["image"]), _td("yes" if c.get("used", True) else "excluded"), _cell(c.get("dx"), 3),
                 _cell(c.get("dy"), 3), _cell(c.get("dz"), 3),
                 _cell(math.hypot(c["dx"], c["dy"]) if c.get("dx") is not None else None, 3)] for c in cams["rows"]]
        summary = _table(["set", "n", "RMSE X", "RMSE Y", "RMSE Z", "RMSE XY", "mean dX", "mean dY", "mean dZ"], [[
            _td("camera positions used"), _td(s["n"]), _cell(s["rmse_x"], 3, "cam.rmse_x"),
            _cell(s["rmse_y"], 3, "cam.rmse_y"), _cell(s["rmse_z"], 3, "cam.rmse_z"),
            _cell(s["rmse_r"], 3, "cam.rmse_r"), _cell(s["mean_x"], 3), _cell(s["mean_y"], 3),
            _cell(s["mean_z"], 3)]])
        return ("<h3>Camera-position residuals</h3>" + summary
                + '<p class="note">Adjusted projection centre minus given position, metres (see the camera '
                  "positions plot under Orientation quality). They show how well the block fits the positions, "
                  "not the accuracy of the ground.</p><details><summary>Per camera</summary>"
                + _table(["image", "used", "dX", "dY", "dZ", "dXY"], rows) + "</details>")

    def _outliers(self, res: Dict[str, Any], acc: Dict[str, Any]) -> str:
        items = []
        for o in res.get("outliers") or []:
            items.append(f"<li class=\"bad\">{_esc(o.get('message') or (str(o.get('kind')) + ' ' + str(o.get('name'))))}"
                         "</li>")
        cc = (res.get("statistics") or {}).get("control_consistency")
        if cc and cc.get("suspects"):
            items.append("<li class=\"warn\">Control points that disagree with the others through the block "
                         f"(more than {cc.get('tolerance_m', 0):.3f} m from the best-agreeing subset's fit"
                         f"{', XY only' if cc.get('xy_only') else ''}): "
                         + _esc(", ".join(f"{n} ({cc['residuals_m'].get(n, float('nan')):.2f} m)"
                                          for n in cc["suspects"])) + "</li>")
        for k in ("control", "check"):
            s = acc["stats"][k]
            if s["n"] < 3:
                continue
            rr = _num(s["rmse_r"]) or 0.0
            for p in acc["sets"][k]:
                dxy = math.hypot(p["dx"], p["dy"])
                if rr > 0 and dxy > 2.5 * rr:
                    items.append(f"<li class=\"warn\">Suspect {k} point {_esc(p['name'])}: horizontal residual "
                                 f"{dxy:.3f} m, {dxy / rr:.1f} × the set's RMSE XY.</li>")
        for p in _residual_rows(res):
            px = [o.get("px") for o in p.get("observations", []) if o.get("px") is not None]
            if px and max(px) > 3.0:
                items.append(f"<li class=\"warn\">{_esc(p['name'])}: an image residual of {max(px):.1f} px "
                             "(check the marking).</li>")
            if p.get("status") == "not triangulated":
                items.append(f"<li class=\"warn\">{_esc(p['name'])}: not triangulated "
                             f"({_esc('; '.join(p.get('notes') or []))}).</li>")
        for w in res.get("warnings") or []:
            items.append(f"<li class=\"note\">{_esc(w)}</li>")
        if not items:
            return '<h3>Outliers and suspect points</h3><p class="ok">None found.</p>'
        return "<h3>Outliers, suspect points and warnings</h3><ul class=\"issues\">" + "".join(items) + "</ul>"

    def _glance_accuracy(self, acc: Dict[str, Any]) -> None:
        st = acc["stats"]
        if acc["tested"]:
            s = st["check"]
            txt = (f"check points: RMSE XY {s['rmse_r']:.3f} m"
                   + (f", Z {s['rmse_z']:.3f} m" if not acc["placeholder_z"] and _num(s["rmse_z"]) is not None else "")
                   + f" ({s['n']} points)")
            kind = "ok" if self.gsd is None or s["rmse_r"] <= 3 * self.gsd else "warn"
            self.glance.append(_badge(kind, _esc(txt)))
        elif acc["basis"] == "control":
            self.glance.append(_badge("warn", "no check points: accuracy not tested (control residuals only)"))
        if acc["placeholder_z"]:
            self.glance.append(_badge("warn", "control heights are placeholders: no vertical accuracy"))
        if acc["tested"] and self.unc is not None:
            sxy = self.unc.summary()["point_std_xy_median"]
            rr = _num(st["check"]["rmse_r"])
            if sxy and rr and rr > 5 * max(sxy, self.gsd or 0.0):
                self.glance.append(_badge("bad", _esc(
                    f"check-point RMSE XY is {rr / sxy:.0f} × the precision the adjustment predicts for tie points "
                    f"({sxy:.3f} m): the errors are systematic (control coordinates, their marking, or a deformed "
                    "block), not noise")))
        if acc["sets"]["rejected"]:
            self.glance.append(_badge("bad", "rejected control points: " + _esc(
                ", ".join(p["name"] for p in acc["sets"]["rejected"]))))

    def _ortho_resolution(self) -> Optional[float]:
        path = self._product_path("orthophoto", "orthomosaic", "orthomosaic.tif")
        if not path:
            return None
        try:
            from osgeo import gdal

            ds = gdal.Open(path)
            return abs(ds.GetGeoTransform()[1]) if ds is not None else None
        except Exception:  # noqa: BLE001
            return None

    # ---- uncertainty -----------------------------------------------------------------------------
    def compute_uncertainty(self) -> None:
        from ..georef import uncertainty as unc

        d = self.d
        if not self.do_uncertainty:
            self.unc_error = "not requested"
            return
        if d.rec is None:
            self.unc_error = "the workspace is not aligned"
            return
        try:
            control, priors, free, offset = unc.workspace_inputs(d.ws, d.rec)
            self.unc = unc.estimate(d.rec, control, priors, free, offset=offset, observations=d.obs,
                                    progress=SubProgress(self.progress, 0.0, 1.0))
        except (unc.UncertaintyError, ValueError, np.linalg.LinAlgError, MemoryError) as e:
            self.unc_error = str(e)
            self.warnings.append(f"uncertainty not computed: {e}")
            return
        if self.layers_dir:
            try:
                self.layers = unc.write_layers(self.unc, self.layers_dir, d.crs)
            except (OSError, RuntimeError) as e:
                self.warnings.append(f"uncertainty layers not written: {e}")

    def uncertainty(self) -> str:
        d = self.d
        u = self.unc
        if u is None:
            raise _Skip(f"not computed: {self.unc_error or 'unknown reason'}.")
        s = u.summary()
        unit = "m" if u.datum != "free network" else d.unit
        self.figures.update(SIGMA0=_num(u.sigma0), POINT_STD_XY_MEDIAN=s["point_std_xy_median"],
                            POINT_STD_Z_MEDIAN=s["point_std_z_median"])
        parts = [_kv([
            ("Datum", _esc(u.datum_text())),
            ("Sigma0 (a posteriori, unit weight = 1 px)", f'<span data-key="sigma0">{_f(u.sigma0, 3)}</span>'),
            ("Redundancy", f"{u.redundancy:,}"),
            ("Observations / points", f"{u.n_observations:,} / {u.n_points:,}"),
            ("Camera position σXY / σZ (median)", f"{_f(s['camera_std_xy_median'], 3)} / "
                                                   f"{_f(s['camera_std_z_median'], 3)} {unit}"),
            ("Tie point σXY / σZ (median)", f"{_f(s['point_std_xy_median'], 3)} / {_f(s['point_std_z_median'], 3)} "
                                            f"{unit}"),
            ("Tie point σXY / σZ (95th percentile)", f"{_f(s['point_std_xy_p95'], 3)} / "
                                                      f"{_f(s['point_std_z_p95'], 3)} {unit}"),
            ("GeoPackage layers", _esc(", ".join(os.path.relpath(p, d.ws.root) for p in self.layers.values()))
             or "not written"),
            ("Computed in", _duration(u.seconds)),
        ])]
        if u.notes:
            parts.append('<ul class="notes">' + "".join(f"<li>{_esc(n)}</li>" for n in u.notes) + "</ul>")
        ps = u.point_std
        ok = np.all(np.isfinite(ps), axis=1)
        if ok.any():
            h = np.hypot(ps[ok, 0], ps[ok, 1])
            z = ps[ok, 2]
            fig = _figure(11.0, 4.2)
            gs = fig.add_gridspec(1, 3, wspace=0.45)
            ax = fig.add_subplot(gs[0, 0])
            hi = float(np.percentile(np.concatenate([h, z]), 99))
            ax.hist(np.clip(h, 0, hi), bins=40, alpha=0.7, label="σXY", color="#4477aa")
            ax.hist(np.clip(z, 0, hi), bins=40, alpha=0.6, label="σZ", color="#e69f00")
            ax.set_xlabel(f"standard deviation ({unit})", fontsize=8)
            ax.set_ylabel("tie points", fontsize=8)
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
            ax2.scatter(cxy[:, 0], cxy[:, 1], s=12, marker="s", c="#4477aa", label="cameras")
            if u.control:
                res_pts = {p["name"]: p for p in _residual_rows(d.residuals or {})}
                cp = [res_pts[c["name"]] for c in u.control if c["name"] in res_pts]
                if cp:
                    ax2.scatter([p["x"] for p in cp], [p["y"] for p in cp], marker="^", s=50, c="none",
                                edgecolors="#228833", linewidths=1.2, label="control")
            ax2.legend(fontsize=7, loc="lower left")
            _equal_xy(ax2)
            parts.append(_img(fig, "point standard deviations",
                              "Left: distribution of the tie points' standard deviations. Right: σZ over the block, "
                              "colours clipped at the 95th percentile (precision degrades where few images overlap "
                              "and away from control)."))
        rows = [[_td(c["image"]), _td(c["camera_id"]), _cell(c["sx"], 3), _cell(c["sy"], 3), _cell(c["sz"], 3),
                 _cell(c["s_rx"], 4), _cell(c["s_ry"], 4), _cell(c["s_rz"], 4)] for c in u.cameras]
        parts.append("<details><summary>Per camera: standard deviations</summary>" + _table(
            ["image", "camera", f"σX ({unit})", f"σY ({unit})", f"σZ ({unit})", "σ rot x (°)", "σ rot y (°)",
             "σ rot z (°)"], rows) + "<p class=\"note\">Rotations about the camera axes (x right, y down, z along "
                                     "the view).</p></details>")
        if u.control:
            rows = [[_td(c["name"]), _cell(c["sx"], 4), _cell(c["sy"], 4), _cell(c["sz"], 4)] for c in u.control]
            parts.append("<details><summary>Control points: adjusted standard deviations</summary>"
                         + _table(["name", "σX (m)", "σY (m)", "σZ (m)"], rows) + "</details>")
        return "".join(parts)

    # ---- products --------------------------------------------------------------------------------
    def _product_path(self, stage: str, key: str, default: str) -> Optional[str]:
        rec = self.d.manifest.get("stages", {}).get(stage, {})
        rel = (rec.get("outputs") or {}).get(key)
        for p in ([rel] if rel else []) + [default]:
            path = p if os.path.isabs(p) else self.d.ws.path(p)
            if os.path.isfile(path):
                return path
        return None

    def products(self) -> str:
        dsm = self._product_path("dsm", "dsm", "dsm.tif")
        ortho = self._product_path("orthophoto", "orthomosaic", "orthomosaic.tif")
        if not dsm and not ortho:
            raise _Skip("no DSM or orthomosaic yet: run 'Build DSM' and 'Build orthophoto'.")
        parts = []
        if dsm:
            parts.append(self._raster(dsm, "DSM", dem=True))
        else:
            parts.append('<p class="skip">No DSM yet.</p>')
        if ortho:
            parts.append(self._raster(ortho, "Orthomosaic", dem=False))
        else:
            parts.append('<p class="skip">No orthomosaic yet.</p>')
        return "".join(parts)

    def _raster(self, path: str, title: str, dem: bool) -> str:
        from osgeo import gdal

        gdal.UseExceptions()
        try:
            ds = gdal.Open(path)
        except RuntimeError as e:
            return f'<h3>{title}</h3><p class="warn">{_esc(path)} cannot be read: {_esc(e)}</p>'
        w, h = ds.RasterXSize, ds.RasterYSize
        gt = ds.GetGeoTransform()
        step = max(1, int(math.ceil(max(w, h) / 900)))
        bw, bh = max(1, w // step), max(1, h // step)
        b1 = ds.GetRasterBand(1)
        nodata = b1.GetNoDataValue()
        info = [("File", _esc(os.path.relpath(path, self.d.ws.root))), ("Size", f"{w} × {h} cells, {ds.RasterCount} "
                                                                              "band(s)"),
                ("Resolution", f"{abs(gt[1]):.4g} × {abs(gt[5]):.4g} m"),
                ("CRS", _esc(_crs_name(ds)))]
        fig = _figure(7.5, 6.0)
        ax = fig.add_subplot(111)
        extent = (gt[0], gt[0] + gt[1] * w, gt[3] + gt[5] * h, gt[3])
        if dem:
            z = b1.ReadAsArray(buf_xsize=bw, buf_ysize=bh).astype(float)
            valid = np.isfinite(z) & ((z != nodata) if nodata is not None else True)
            frac = float(valid.mean())
            zz = np.where(valid, z, np.nan)
            if valid.any():
                lo, hi = np.nanpercentile(zz, [1, 99])
                hs = hillshade(zz, abs(gt[1]) * w / bw, abs(gt[5]) * h / bh)
                from matplotlib import cm, colormaps
                from matplotlib.colors import Normalize

                rgb = colormaps["terrain"](Normalize(lo, hi)(np.nan_to_num(zz, nan=lo)))[..., :3]
                shaded = np.clip(rgb * (0.35 + 0.65 * hs[..., None]), 0, 1)
                rgba = np.dstack([shaded, valid.astype(float)])
                ax.imshow(rgba, extent=extent, interpolation="nearest")
                sm = cm.ScalarMappable(norm=Normalize(lo, hi), cmap="terrain")
                fig.colorbar(sm, ax=ax, shrink=0.7, label="height (m)")
                info.append(("Height range (1st–99th percentile)", f"{lo:.2f} – {hi:.2f} m"))
        else:
            bands = [ds.GetRasterBand(i + 1) for i in range(min(3, ds.RasterCount))]
            arr = np.dstack([b.ReadAsArray(buf_xsize=bw, buf_ysize=bh).astype(float) for b in bands])
            alpha = None
            for i in range(ds.RasterCount):
                b = ds.GetRasterBand(i + 1)
                if b.GetColorInterpretation() == gdal.GCI_AlphaBand:
                    alpha = b.ReadAsArray(buf_xsize=bw, buf_ysize=bh) > 0
            if alpha is None:
                mb = b1.GetMaskBand().ReadAsArray(buf_xsize=bw, buf_ysize=bh)
                alpha = mb > 0
            frac = float(alpha.mean())
            if arr.shape[2] == 1:
                arr = np.repeat(arr, 3, axis=2)
            lo, hi = np.percentile(arr[alpha], [0.5, 99.5]) if alpha.any() else (0.0, 255.0)
            rgb = np.clip((arr - lo) / max(hi - lo, 1e-9), 0, 1)
            ax.imshow(np.dstack([rgb, alpha.astype(float)]), extent=extent, interpolation="nearest")
        info.append(("Valid fraction (cells with data)", f'<span data-key="{title.lower()}.valid">{frac:.3f}</span>'
                                                          + (f" (estimated on a 1:{step} overview)" if step > 1 else "")))
        stage_vf = _num(((self.d.manifest.get("stages", {}).get("dsm" if dem else "orthophoto") or {}).get("results")
                         or {}).get("VALID_FRACTION"))
        if stage_vf is not None:
            info.append(("Valid fraction inside the camera centres' convex hull (as the stage reports it)",
                         f"{stage_vf:.3f}"))
        # the key figure is the stage's own (the Processing output VALID_FRACTION): inside the camera centres'
        # convex hull; the whole raster's share is shown beside it above
        self.figures[f"{'DSM' if dem else 'ORTHO'}_VALID_FRACTION"] = stage_vf if stage_vf is not None else frac
        self.figures[f"{'DSM' if dem else 'ORTHO'}_RESOLUTION"] = abs(gt[1])
        _equal_xy(ax)
        ax.grid(False)
        return f"<h3>{title}</h3>" + _kv(info) + _img(fig, f"{title} preview", f"{title} preview" + (
            " with hillshade (sun from the north-west, 45°)." if dem else "."))


def _precision_badge(unc, gsd: Optional[float]) -> str:
    """Green when the tie points' median sigma XY is within 3 GSD, amber (with the likely reason) beyond."""
    s = unc.summary()
    sxy, sz = s["point_std_xy_median"], s["point_std_z_median"]
    txt = f"precision from the adjustment: tie points σXY {_f(sxy, 3)} m, σZ {_f(sz, 3)} m (median)"
    if sxy is None or gsd is None or sxy <= 3 * gsd:
        return _badge("ok", _esc(txt))
    why = (" — the datum is weak: positions of limited accuracy (e.g. EXIF GPS) leave the block free to shift and "
           "tilt; add ground control points" if not unc.n_control else
           " — the control does not hold the block well (too few or badly spread control points)")
    return _badge("warn", _esc(txt + f", more than 3 × the GSD ({gsd:.3f} m)" + why))


def _nice(v: float) -> float:
    """A round number near v (1, 2, 5 × 10^k) for plot keys."""
    if not v or not math.isfinite(v) or v <= 0:
        return 1.0
    e = math.floor(math.log10(v))
    for m in (5, 2, 1):
        if m * 10 ** e <= v:
            return float(m * 10 ** e)
    return float(10 ** e)


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
        return srs.GetName() or str(crs)
    except Exception:  # noqa: BLE001 - GDAL raises or returns codes depending on UseExceptions
        return str(crs)


def _crs_name(ds) -> str:
    from osgeo import osr

    wkt = ds.GetProjection()
    if not wkt:
        return "none"
    srs = osr.SpatialReference(wkt=wkt)
    code = srs.GetAuthorityCode(None)
    name = srs.GetName() or "unnamed"
    return f"{srs.GetAuthorityName(None)}:{code} ({name})" if code else name


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


# --------------------------------------------------------------------------------------------------
# the page
# --------------------------------------------------------------------------------------------------

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

SECTIONS = (("summary", "Summary"), ("orientation", "Orientation quality"), ("georeferencing", "Georeferencing"),
            ("uncertainty", "Uncertainty"), ("products", "Products"))


def _version() -> str:
    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "metadata.txt")
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("version="):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return "?"


def _cards(fig: Dict[str, Any], georef: bool) -> str:
    cards = []

    def add(label, value, key=None):
        k = f' data-key="card.{key}"' if key else ""
        cards.append(f'<div class="card"><div class="v"{k}>{value}</div><div class="l">{_esc(label)}</div></div>')

    if fig.get("REGISTERED_IMAGES") is not None:
        add("images aligned", f"{fig['REGISTERED_IMAGES']} / {fig.get('IMAGES')}")
    if fig.get("MEAN_REPROJECTION_ERROR") is not None:
        add("mean reprojection error", _f(fig["MEAN_REPROJECTION_ERROR"], 2, "px"))
    if fig.get("GSD") is not None:
        add("ground sample distance", _f(fig["GSD"] * 100, 1, "cm"))
    if fig.get("AREA_M2") is not None:
        add("area", f"{fig['AREA_M2'] / 1e4:.2f} ha")
    if fig.get("CHECK_RMSE_XY") is not None:
        add("check RMSE XY", _f(fig["CHECK_RMSE_XY"], 3, "m"), "check_xy")
    if fig.get("CHECK_RMSE_Z") is not None and fig.get("NSSDA_V") is not None:
        add("check RMSE Z", _f(fig["CHECK_RMSE_Z"], 3, "m"), "check_z")
    if fig.get("NSSDA_H") is not None:
        add("NSSDA horizontal 95 %", _f(fig["NSSDA_H"], 3, "m"))
    if fig.get("NSSDA_V") is not None:
        add("NSSDA vertical 95 %", _f(fig["NSSDA_V"], 3, "m"))
    if fig.get("ASPRS_2014_H_CLASS_CM") is not None:
        add("ASPRS 2014 horizontal class", _f(fig["ASPRS_2014_H_CLASS_CM"], 1, "cm"))
    if fig.get("CAMERA_RMSE_XY") is not None:
        add("camera position RMSE XY", _f(fig["CAMERA_RMSE_XY"], 2, "m"))
    if fig.get("POINT_STD_XY_MEDIAN") is not None and georef:
        add("tie point σXY / σZ (median)", f"{_f(fig['POINT_STD_XY_MEDIAN'], 3)} / "
                                            f"{_f(fig.get('POINT_STD_Z_MEDIAN'), 3)} m")
    if fig.get("DSM_VALID_FRACTION") is not None:
        add("DSM valid fraction", _f(fig["DSM_VALID_FRACTION"], 3))
    return '<div class="cards">' + "".join(cards) + "</div>"


def build_report(workspace_dir: str, output_html: Optional[str] = None, *, uncertainty: bool = True,
                 write_layers: bool = True, progress: Optional[Progress] = None) -> ReportResult:
    """Write the HTML report of a workspace (see the module docstring); returns where and the key figures.

    ``output_html``: default ``<workspace>/report.html``.  ``uncertainty``: compute the bundle-adjustment
    covariance (``write_layers``: and write ``<workspace>/uncertainty/cameras.gpkg`` and ``points.gpkg``).
    Raises WorkspaceError (not a workspace), ReportError, Cancelled."""
    progress = progress or NullProgress()
    t0 = time.time()
    ws = Workspace.open(workspace_dir)
    out = os.path.abspath(output_html) if output_html else ws.path(REPORT_FILE)
    if os.path.isdir(out):
        raise ReportError(f"{out} is a folder: give the path of an .html file")
    folder = os.path.dirname(out)
    if not os.path.isdir(folder):
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as e:
            raise ReportError(f"cannot create the folder {folder}: {e.strerror or e}") from e
    data = _Data(ws, SubProgress(progress, 0.0, 0.1))
    ws.begin_stage(STAGE, {"output_html": out, "uncertainty": uncertainty, "write_layers": write_layers})
    try:
        rep = _Report(data, progress, uncertainty, ws.path(UNCERTAINTY_DIR) if write_layers else None)
        check_cancel(progress)
        progress.report(0.1, "uncertainty: bundle adjustment covariance")
        if data.rec is not None and uncertainty:
            rep.progress = SubProgress(progress, 0.1, 0.5)
            rep.compute_uncertainty()
            rep.progress = progress
        else:
            rep.compute_uncertainty()
        body: List[str] = []
        status: Dict[str, str] = {}
        steps = {"summary": rep.summary, "orientation": rep.orientation, "georeferencing": rep.georeferencing,
                 "uncertainty": rep.uncertainty, "products": rep.products}
        for k, (sid, title) in enumerate(SECTIONS):
            check_cancel(progress)
            progress.report(0.5 + 0.45 * k / len(SECTIONS), f"report: {title.lower()}")
            try:
                content = steps[sid]()
                body.append(f'<section id="{sid}"><h2>{_esc(title)}</h2>{content}</section>')
                status[sid] = "ok"
            except _Skip as e:
                body.append(f'<section id="{sid}" class="skipped"><h2>{_esc(title)}</h2>'
                            f'<p class="skip">Skipped: {_esc(e)}</p></section>')
                status[sid] = str(e)
        check_cancel(progress)
        figures = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in rep.figures.items()}
        georef = data.georeferenced
        if data.rec is not None:
            n_img, n_reg = figures.get("IMAGES"), figures.get("REGISTERED_IMAGES")
            kind = "ok" if n_img and n_reg == n_img else "warn"
            rep.glance.insert(0, _badge(kind, f"{n_reg} of {n_img} images aligned, mean reprojection error "
                                              f"{_f(figures.get('MEAN_REPROJECTION_ERROR'), 2)} px"))
        else:
            rep.glance.insert(0, _badge("bad", "no aligned model: run 'Align images'"))
        if rep.unc is not None and georef:
            rep.glance.append(_precision_badge(rep.unc, rep.gsd))
        if status.get("products") != "ok":
            rep.glance.append(_badge("note", "no DSM / orthomosaic yet"))
        now = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
        title = f"ArchaeoOrtho report — {os.path.basename(ws.root.rstrip(os.sep))}"
        nav = "".join(f'<a href="#{sid}">{_esc(t)}</a>' for sid, t in SECTIONS)
        machine = json.dumps({"figures": figures, "sections": status}, default=str, allow_nan=False)
        page = (
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{_esc(title)}</title>"
            f"<style>{CSS}</style></head><body><main>"
            f"<h1>{_esc(title)}</h1><p class=\"sub\">{_esc(ws.root)} · generated {_esc(now)} · ArchaeoOrtho "
            f"{_esc(_version())}</p><nav>{nav}</nav>"
            f"<section id=\"glance\"><h2>At a glance</h2>{_cards(figures, georef)}<ul class=\"glance\">"
            + "".join(rep.glance) + "</ul></section>" + "".join(body)
            + f"<footer>Accuracy figures: core.accuracy (FGDC-STD-007.3-1998 NSSDA; ASPRS Positional Accuracy "
              f"Standards 2014 and 2023). Report written in {_duration(time.time() - t0)}.</footer>"
            + f"<script type=\"application/json\" id=\"report-data\">{_esc_json(machine)}</script>"
            + "</main></body></html>\n")
        check_cancel(progress)
        with atomic_output(out) as tmp:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(page)
        seconds = round(time.time() - t0, 2)
        ws.end_stage(STAGE, DONE, outputs={"report": os.path.relpath(out, ws.root) if out.startswith(ws.root) else out,
                                            **{k: os.path.relpath(v, ws.root) for k, v in rep.layers.items()}},
                     results={"figures": figures, "sections": status, "seconds": seconds})
        progress.report(1.0, f"report written: {out}")
        for w in rep.warnings:
            progress.warning(w)
        return ReportResult(out, ws.root, figures, status, rep.layers, rep.warnings, seconds)
    except Cancelled:
        ws.end_stage(STAGE, CANCELLED, error="cancelled by the user")
        raise
    except Exception as e:
        ws.end_stage(STAGE, FAILED, error=str(e))
        raise


def _esc_json(text: str) -> str:
    """JSON inside <script>: only '</' needs escaping."""
    return text.replace("</", "<\\/")


def read_report_data(path: str) -> Dict[str, Any]:
    """The machine-readable figures embedded in a report (``<script id="report-data">``)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    start = text.index('id="report-data">') + len('id="report-data">')
    end = text.index("</script>", start)
    return json.loads(text[start:end].replace("<\\/", "</"))


__all__ = ["REPORT_FILE", "ReportError", "ReportResult", "WorkspaceError", "accuracy_figures", "build_report",
           "camera_position_figures", "hillshade", "read_report_data"]
