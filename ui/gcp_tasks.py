"""The GCP dock's background work (ui.tasks.CoreTask): aligning a folder of photos, the adjustment with the
dock's points, and the result layers it loads afterwards.  A mixin of ui.gcp_dock.GcpDock; its strings are
translated in the dock's context."""
import os

from qgis.core import Qgis, QgsProject
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import QFileDialog

from ..core.io import gcp as gcpmod
from ..core.project.stages import ALIGN, GEOREFERENCE
from . import layers
from .gcp_table import fmt, short_crs
from .tasks import CoreTask, start

translate = QCoreApplication.translate


class GcpTasks:
    """Alignment and adjustment in the background, one task at a time; the summary of the adjustment."""

    # ------------------------------------------------------------------ alignment
    def choose_photos(self):
        images = QFileDialog.getExistingDirectory(self, translate("GcpDock", "Folder of photos"))
        if not images:
            return
        ws = QFileDialog.getExistingDirectory(self, translate("GcpDock", "Workspace folder (new or existing)"))
        if ws:
            self.start_alignment(images, ws)

    def start_alignment(self, images_dir, workspace_dir, options=None):
        from ..core.align import stage as align_stage

        if self._busy():
            return None

        def done(result):
            self._task_ended()
            self.open_workspace(workspace_dir)  # first: its own message must not replace the result
            text = translate("GcpDock", "Aligned {} of {} photos, mean reprojection error {:.2f} px").format(
                result.registered, result.images_given, result.mean_reprojection_error)
            if result.unregistered:
                text += ". " + translate("GcpDock", "Not aligned: {}").format(
                    "; ".join(f"{n} ({why})" for n, why in sorted(result.unregistered.items())))
            self.message(text, Qgis.MessageLevel.Warning if result.unregistered else Qgis.MessageLevel.Success)

        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: align photos"), align_stage.align, (images_dir, workspace_dir),
                        {"options": options}, on_done=done, on_error=self._task_failed)
        return self._start_task(task)

    # ------------------------------------------------------------------ adjustment
    def _busy(self):
        if self.task is not None:
            self.message(translate("GcpDock", "A task of this dock is still running"), Qgis.MessageLevel.Warning)
            return True
        return False

    def _start_task(self, task):
        self.task = task
        self.last_task_error = None
        self.progress.setValue(0)
        task.progressChanged.connect(lambda v: self.progress.setValue(int(round(v))))
        task.message.connect(self.status.setText)
        start(task)
        self._update_enabled()
        return task

    def _task_ended(self):
        self.task = None
        self._update_enabled()

    def _task_failed(self, message, cancelled):
        self._task_ended()
        self.last_task_error = message
        self.progress.setValue(0)
        if cancelled:
            self.message(translate("GcpDock", "Cancelled"), Qgis.MessageLevel.Info)
        else:
            self.message(message, Qgis.MessageLevel.Critical)
        self.store.reload_workspace()

    def cancel_task(self):
        if self.task is not None:
            self.task.cancel()
            self.message(translate("GcpDock", "Cancelling\u2026"))

    def run_georeference(self):
        """Adjust the block with the current points in a background task; residuals update when it ends."""
        from ..core.georef import stage as georef_stage

        if self.store.workspace is None or self._busy():
            return None
        if not self.store.stage_done(ALIGN):
            self.message(translate("GcpDock", "The block is not aligned yet: run Align images first"),
                         Qgis.MessageLevel.Warning)
            return None
        gs = self.store.usable_gcps()
        n_control = sum(1 for p in gs.points if p.role == gcpmod.CONTROL and len(p.observations) >= 1)
        if n_control < 3:
            self.message(translate("GcpDock", "The adjustment needs at least 3 control points with coordinates and "
                                 "observations; there are {}").format(n_control), Qgis.MessageLevel.Warning)
            return None
        root = self.store.root

        def done(result):
            self._task_ended()
            self.progress.setValue(100)
            self.store.reload_workspace()
            self.store.save()  # the stage wrote the points it used to control.json: keep all of the dock's
            self.store.load_residuals()
            self.load_predictor()
            self._selection_changed()
            self.load_results(kinds=("cameras", "residuals"))
            extra = ""
            if result.outliers:
                extra = " " + translate("GcpDock", "Outliers left out: {}").format("; ".join(result.outliers))
            self.message(translate("GcpDock", "Georeferenced in {}.").format(short_crs(result.crs)) + extra,
                         Qgis.MessageLevel.Warning if result.outliers else Qgis.MessageLevel.Success)

        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: georeference"), georef_stage.georeference_workspace, (root,),
                        {"gcps": gs, "refine_intrinsics": self.refine_box.isChecked()},
                        on_done=done, on_error=self._task_failed)
        self.message(translate("GcpDock", "Georeferencing with {} control points\u2026").format(n_control))
        return self._start_task(task)

    def _update_summary(self):
        f = self.store.figures
        if not f:
            self.summary.setText(translate("GcpDock", "Not georeferenced yet.") if self.store.workspace is not None else "")
            return
        parts = [translate("GcpDock", "Control: RMSE XY {} m, Z {} m (n = {})").format(
            fmt(f.get("GCP_RMSE_XY")), fmt(f.get("GCP_RMSE_Z")), f.get("GCP_N", 0))]
        if f.get("CHECK_N"):
            parts.append(translate("GcpDock", "Check: RMSE XY {} m, Z {} m (n = {})").format(
                fmt(f.get("CHECK_RMSE_XY")), fmt(f.get("CHECK_RMSE_Z")), f.get("CHECK_N")))
        if f.get("PLACEHOLDER_Z"):
            parts.append(translate("GcpDock", "heights are placeholders: no vertical accuracy"))
        if f.get("MEAN_REPROJECTION_ERROR") is not None:
            parts.append(translate("GcpDock", "tie points {} px").format(fmt(f.get("MEAN_REPROJECTION_ERROR"), 2)))
        if self.store.stale:
            parts.append("<i>" + translate("GcpDock", "edited since: re-run to update") + "</i>")
        self.summary.setText("<br>".join(parts))

    # ------------------------------------------------------------------ result layers
    def load_results(self, kinds=None):
        """Add the workspace's products as styled layers (DSM + hillshade, orthomosaic, cameras +
        footprints, residuals)."""
        if self.store.root is None:
            return []
        root = self.store.root
        lay = self.store.layout
        group = layers.workspace_group_name(root)
        project = QgsProject.instance()
        out = []
        kinds = kinds or ("dsm", "ortho", "cameras", "residuals")
        if "dsm" in kinds and os.path.exists(lay.default_dsm):
            out += layers.load_dsm(lay.default_dsm, project, group)
        if "ortho" in kinds and os.path.exists(lay.default_orthomosaic):
            out += layers.load_orthomosaic(lay.default_orthomosaic, project, group)
        if "cameras" in kinds and os.path.exists(lay.cameras_gpkg):
            out += layers.load_cameras(lay.cameras_gpkg, project, group, workspace=root)
        res = lay.residuals_gpkg
        if "residuals" in kinds and os.path.exists(res) and self.store.stage_done(GEOREFERENCE):
            out += layers.load_residuals(res, project, group)
        return out
