"""The report stage: ``build_report(workspace)`` reads what the stages left in a workspace and writes one
self-contained HTML file, ``<workspace>/report.html`` (or ``output_html``), that a person reads at a glance.

No network, no scripts, every plot a PNG embedded as a ``data:`` URI.  Sections:

- *at a glance*: key figures and a short list of what is good and what needs attention;
- *summary* (:mod:`.sections.summary`): images given / aligned / not aligned (and why), image screening when
  "Prepare images" ran, cameras with their calibrated parameters and standard deviations, GSD, area, CRS,
  stage times, parameters;
- *orientation quality* (:mod:`.sections.orientation`): reprojection errors (histogram, per image), tie-point
  track lengths, image connectivity (shared tie points, as a matrix and a map), camera positions with their
  residuals;
- *georeferencing* (:mod:`.sections.georeferencing`, :mod:`.sections.standards`): control and check points
  with dX dY dZ and image residuals, a residual vector plot over the footprint, RMSE per set, NSSDA
  (FGDC-STD-007.3-1998) statements, ASPRS 2014 and 2023 classes, camera-position residuals, outliers and
  suspect points;
- *uncertainty* (:mod:`.sections.uncertainty`): standard deviations of cameras and points from the bundle
  adjustment covariance (``core.georef.uncertainty``), also written as GeoPackage layers;
- *products* (:mod:`.sections.products`): DSM and orthomosaic previews (hillshade), resolution, valid fraction.

A section whose stage has not run says so in one line and the rest of the report is still written.  Every
accuracy number is computed by ``core.georef.accuracy`` (through :mod:`.residuals`): the same functions behind
the Processing outputs.  The file is written through a temporary name and renamed when complete, so a
cancelled run never leaves a report that looks finished.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from ..common.files import atomic_output
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..project.layout import REPORT_HTML, Layout
from ..project.stages import REPORT, run_stage
from ..project.workspace import Workspace
from .context import ReportContext, Skip
from .data import ReportData
from .errors import ReportError
from .html import esc
from .labels import language, t
from .options import ReportOptions
from .page import SECTIONS, glance_lines, page
from .sections import georeferencing, orientation, products, summary
from .sections import uncertainty as uncertainty_section

STAGE = REPORT
REPORT_FILE = REPORT_HTML
_SECTION_BUILDERS = {"summary": summary.section, "orientation": orientation.section,
                     "georeferencing": georeferencing.section, "uncertainty": uncertainty_section.section,
                     "products": products.section}


@dataclass
class ReportResult:
    path: str
    workspace: str
    figures: Dict[str, Any]
    sections: Dict[str, str]  # section id -> "ok" or the reason it was skipped
    layers: Dict[str, str] = field(default_factory=dict)  # uncertainty GeoPackages
    warnings: List[str] = field(default_factory=list)
    seconds: float = 0.0


def _output_path(lay: Layout, output_html: Optional[str]) -> str:
    out = os.path.abspath(output_html) if output_html else lay.default_report
    if os.path.isdir(out):
        raise ReportError(f"{out} is a folder: give the path of an .html file")
    folder = os.path.dirname(out)
    if not os.path.isdir(folder):
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as e:
            raise ReportError(f"cannot create the folder {folder}: {e.strerror or e}") from e
    return out


def _sections(ctx: ReportContext, progress: Progress) -> Tuple[List[str], Dict[str, str]]:
    """The sections' HTML, and for each "ok" or the reason it was skipped."""
    body: List[str] = []
    status: Dict[str, str] = {}
    for k, (sid, title) in enumerate(SECTIONS):
        check_cancel(progress)
        progress.report(0.5 + 0.45 * k / len(SECTIONS), f"report: {title.lower()}")
        try:
            content = _SECTION_BUILDERS[sid](ctx)
            body.append(f'<section id="{sid}"><h2>{esc(t(title))}</h2>{content}</section>')
            status[sid] = "ok"
        except Skip as e:
            body.append(f'<section id="{sid}" class="skipped"><h2>{esc(t(title))}</h2>'
                        f'<p class="skip">{esc(t("Skipped:"))} {esc(e)}</p></section>')
            status[sid] = str(e)
    return body, status


def build_report(workspace_dir: str, options: Optional[ReportOptions] = None,
                 progress: Optional[Progress] = None) -> ReportResult:
    """Write the HTML report of a workspace (see the module docstring); returns where and the key figures.

    :class:`ReportOptions`: ``output_html`` (default ``<workspace>/report.html``), ``uncertainty`` (compute the
    bundle-adjustment covariance) and ``write_layers`` (and write ``<workspace>/uncertainty/cameras.gpkg`` and
    ``points.gpkg``).  Raises WorkspaceError (not a workspace), ReportError, Cancelled."""
    opts = options or ReportOptions()
    output_html = opts.output_html
    progress = progress or NullProgress()
    t0 = time.time()
    ws = Workspace.open(workspace_dir)
    lay = Layout(ws)
    out = _output_path(lay, output_html)
    ctx = ReportContext(ReportData(ws, SubProgress(progress, 0.0, 0.1)), progress)
    params = {"output_html": out, "uncertainty": opts.uncertainty, "write_layers": opts.write_layers,
              "language": opts.language}
    # the last stage: nothing after it to mark stale; headings and figure labels in the options' language
    with run_stage(ws, STAGE, params, invalidate=False) as run, language(opts.language):
        check_cancel(progress)
        progress.report(0.1, "uncertainty: bundle adjustment covariance")
        computing = ctx.d.rec is not None and opts.uncertainty
        uncertainty_section.compute(ctx, opts.uncertainty, lay.uncertainty_dir if opts.write_layers else None,
                                    SubProgress(progress, 0.1, 0.5) if computing else progress)
        body, status = _sections(ctx, progress)
        check_cancel(progress)
        figures = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in ctx.figures.items()}
        text = page(ws.root, figures, status, ctx.d.georeferenced, glance_lines(ctx, figures, status), body,
                    time.time() - t0)
        check_cancel(progress)
        with atomic_output(out) as tmp:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(text)
        seconds = round(time.time() - t0, 2)
        run.finish(outputs={"report": os.path.relpath(out, ws.root) if out.startswith(ws.root) else out,
                            **{k: os.path.relpath(v, ws.root) for k, v in ctx.layers.items()}},
                   results={"figures": figures, "sections": status, "seconds": seconds})
    progress.report(1.0, f"report written: {out}")
    for w in ctx.warnings:
        progress.warning(w)
    return ReportResult(out, ws.root, figures, status, ctx.layers, ctx.warnings, seconds)


def report_of(ws) -> Optional[str]:
    """The accuracy report of the Workspace ``ws`` that is on disk: the file its report stage recorded (an
    OUTPUT_HTML given), else ``<workspace>/report.html``; None when there is none (the dock's 'Open report')."""
    recorded = (ws.stage(STAGE).get("outputs") or {}).get("report")
    candidates = [recorded if os.path.isabs(recorded) else os.path.join(ws.root, recorded)] if recorded else []
    candidates.append(Layout(ws).default_report)
    return next((os.path.abspath(p) for p in candidates if os.path.isfile(p)), None)


__all__ = ["REPORT_FILE", "ReportResult", "build_report", "report_of"]
