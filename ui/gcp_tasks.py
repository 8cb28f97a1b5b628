"""The GCP dock's background work (ui.tasks.CoreTask): aligning a folder of photos, the adjustment with the
dock's points, and the result layers it loads afterwards.  A mixin of ui.gcp_dock.GcpDock; its strings are
translated in the dock's context."""
import os

from qgis.core import Qgis, QgsProject
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import QFileDialog

from ..core.georef.options import GeorefOptions
from ..core.io import gcp as gcpmod
from ..core.project.stages import ALIGN, GEOREFERENCE
from ..qgisio import layers
from .gcp_table import fmt, short_crs
from .tasks import CoreTask, start

translate = QCoreApplication.translate


def georeference_then_prepare(root, options, progress=None):
    """The adjustment, then (still in the worker thread) the image footprints the result layers show: the dock's
    done() only adds layers (issue 18.5).  Returns (GeorefResult, footprints path or None)."""
    from ..core.georef import stage as georef_stage

    result = georef_stage.georeference_workspace(root, options, progress=progress)
    try:
        model = read_block_model(root)
    except Exception:  # noqa: BLE001 - the dock's load_predictor reads it again and reports the problem
        model = None
    return result, prepare_results(root, progress=progress), model


def read_block_model(root, progress=None):
    """(model, transform or None, ground sample distance) of a workspace, read in a worker thread for
    GcpPlacement.load_predictor: the georeferenced model when there is one, else the aligned one."""
    from ..core.align import stage as align_stage
    from ..core.georef import guided
    from ..core.georef.stage import load_georef_model
    from ..core.project.layout import Layout
    from ..core.project.workspace import Workspace

    ws = Workspace.open(root)
    if ws.stage_done(GEOREFERENCE) and os.path.isdir(Layout(ws).georef_model_dir):
        rec, transform = load_georef_model(root)
    else:
        rec, transform = align_stage.load_model(root), None
    return rec, transform, guided.ground_sample_distance(rec)


def prepare_results(root, progress=None):
    """What takes time before the result layers can be added (worker thread): the footprints GeoPackage."""
    return layers.footprints_path(root)


def match_in_background(rec, refs, image, image_path, pred_xy, xyz, radius, progress=None):
    """Refine a prediction in ``image`` by matching the point's look in the photos ``refs`` ([(name, (x, y),
    path)], best first): core.georef.guided.refine_by_matching, the photos read here (a worker thread)."""
    from ..core.common.progress import check_cancel
    from ..core.georef import guided

    target = guided.read_gray(image_path)
    for k, (ref_image, ref_xy, ref_path) in enumerate(refs):
        check_cancel(progress)
        progress.report(k / max(1, len(refs)), ref_image)
        match = guided.refine_by_matching(rec, guided.PhotoPoint(ref_image, ref_xy, guided.read_gray(ref_path)),
                                          guided.PhotoPoint(image, pred_xy, target), xyz,
                                          guided.MatchSearch(radius=radius))
        if match is not None:
            return match
    return None


class GcpTasks:
    """Alignment and adjustment in the background, one task at a time; the summary of the adjustment; the
    refinement of predictions by matching in tasks of their own."""

    refine_in_background = False  # the plugin's dock: True (the photo shows the geometric prediction meanwhile)

    # ------------------------------------------------------------------ the block model, read in a task
    def _take_prebuilt_model(self, root, georeferenced):
        """(model, transform, gsd) a task read for ``root`` (once; the georeferenced model when
        ``georeferenced``), else None: GcpPlacement.load_predictor reads it itself then."""
        prebuilt = self.__dict__.pop("_prebuilt_model", None)
        if prebuilt is None or os.path.normpath(prebuilt[0]) != os.path.normpath(root):
            return None
        model = prebuilt[1]
        return model if (model[1] is not None) == bool(georeferenced) else None

    def open_workspace_in_background(self, folder):
        """The Open button: the block model is read in a task, then the workspace opens (fast)."""
        from ..core.project.workspace import Workspace, WorkspaceError

        try:
            Workspace.open(folder)  # a folder that is no workspace is told at once
        except WorkspaceError as e:
            self.message(str(e), Qgis.MessageLevel.Critical)
            return None
        if self.__dict__.get("_open_task") is not None:
            return None

        def done(model):
            self._open_task = None
            self._prebuilt_model = (folder, model)
            self.open_workspace(folder)

        def failed(message, cancelled):
            self._open_task = None
            self._prebuilt_model = None
            self.open_workspace(folder)  # without a model: the dock says why there are no predictions

        self._open_task = CoreTask(translate("GcpDock", "ArchaeoOrtho: open workspace"), read_block_model,
                                   (folder,), on_done=done, on_error=failed)
        self.message(translate("GcpDock", "Opening {}\u2026").format(os.path.basename(os.path.normpath(folder))))
        return start(self._open_task)

    def follow_workspace(self, folder):
        """The workspace a Processing run (Run pipeline from the Toolbox) loaded results of: the dock shows it
        (issue 48 item 4), read in a task as Open does; not while a task of this dock runs (its result would
        land in another workspace), which is said."""
        if self.task is not None:
            self.message(translate("GcpDock", "{} has new results: open it once this dock's task has ended").format(
                os.path.basename(os.path.normpath(folder))), Qgis.MessageLevel.Info)
            return None
        return self.open_workspace_in_background(folder)

    # ------------------------------------------------------------------ refinement by matching
    def _refine_later(self, key, point, image, pred):
        """Start (or find running) the matching that refines ``pred``; False to match now, in the caller.
        Matching takes 0.2 to 5 s a photo: on the GUI thread it froze the dock (issue 18.5)."""
        if not self.refine_in_background:
            return False
        jobs = self.__dict__.setdefault("_refine_jobs", {})
        if key in jobs:
            return True
        try:
            xyz, _ = self.predictor.model_point(self._predictable(point))
            size = max(max(c.width, c.height) for c in self.predictor.rec.cameras.values())
        except Exception:  # noqa: BLE001 - the caller's own attempt records the failure
            return False
        paths = {im["name"]: im["path"] for im in self.store.images()}
        refs = sorted(point.observations, key=lambda o: self._baseline(o.image, image))[:2]
        ref_args = [(o.image, (o.x, o.y), paths.get(o.image)) for o in refs]
        if paths.get(image) is None or any(p is None for _n, _xy, p in ref_args):
            return False

        def done(match):
            jobs.pop(key, None)
            self.matches[key] = match
            self._refined(key)

        def failed(message, cancelled):
            jobs.pop(key, None)
            if not cancelled:
                self.matches[key] = None  # matching is a help: the geometric prediction stays
                self._refined(key)

        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: refine {} in {}").format(point.name, image),
                        match_in_background, (self.predictor.rec, ref_args, image, paths[image], pred.xy, xyz,
                                              min(600.0, 0.3 * size)), on_done=done, on_error=failed)
        jobs[key] = task
        start(task)
        return True

    def _refined(self, key):
        """A refinement ended: redraw the photo when it is still the one shown for that point."""
        point = self.current_point()
        if point is not None and point.name == key[0] and self.photo_panel.image == key[1]:
            self._update_photo()

    def refinement_pending(self, image=None):
        jobs = self.__dict__.get("_refine_jobs", {})
        return any(k[1] == image for k in jobs) if image else bool(jobs)

    def wait_for_refinement(self, image=None, timeout=15.0):
        """Let the refinement of ``image`` finish (events keep flowing: the dock stays responsive)."""
        import time

        t0 = time.time()
        while self.refinement_pending(image) and time.time() - t0 < timeout:
            QCoreApplication.processEvents()
            time.sleep(0.01)

    # ------------------------------------------------------------------ alignment
    def choose_photos(self):
        images = QFileDialog.getExistingDirectory(self, translate("GcpDock", "Folder of photos"))
        if not images:
            return
        from .folder_dialog import choose_folder

        # a new folder's name typed in the dialog is taken (Qt's folder dialog said 'Directory not found')
        ws = choose_folder(self, translate("GcpDock", "Workspace folder (new or existing)"),
                           os.path.dirname(os.path.normpath(images)))
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
        # the dock shows the workspace being made, nothing of the one open before (issue 48 item 4)
        self.store.close()
        self.ws_label.setText(os.path.basename(os.path.normpath(workspace_dir)))  # the status line says that it is being aligned
        self.ws_label.setToolTip(workspace_dir)
        self.message(translate("GcpDock", "Aligning the photos of {} into {}\u2026").format(images_dir, workspace_dir))
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
            # said first: a task still queued ends within cancel() ('Cancelled'), which this must not overwrite
            self.message(translate("GcpDock", "Cancelling\u2026"))
            self.task.cancel()

    def run_georeference(self):
        """Adjust the block with the current points in a background task; residuals update when it ends."""
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

        def done(outcome):
            result, footprints, model = outcome
            self._task_ended()
            self.progress.setValue(100)
            self.store.reload_workspace()
            self._prebuilt_model = (root, model) if model is not None else None
            self.store.save()  # the stage wrote the points it used to control.json: keep all of the dock's
            self.store.load_residuals()
            self.load_predictor()
            self._selection_changed()
            self.load_results(kinds=("cameras", "residuals"), footprints=footprints)
            extra = ""
            if result.outliers:
                extra = " " + translate("GcpDock", "Outliers left out: {}").format("; ".join(result.outliers))
            self.message(translate("GcpDock", "Georeferenced in {}.").format(short_crs(result.crs)) + extra,
                         Qgis.MessageLevel.Warning if result.outliers else Qgis.MessageLevel.Success)

        options = GeorefOptions(gcps=gs, refine_intrinsics=self.refine_box.isChecked())
        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: georeference"), georeference_then_prepare, (root, options),
                        {},
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
    def load_results_in_background(self):
        """The Load results button: the footprints are written in a task, then the layers are added (fast)."""
        if self.store.root is None or self.__dict__.get("_results_task") is not None:
            return None
        root = self.store.root

        def done(footprints):
            self._results_task = None
            if self.store.root == root:
                self.load_results(footprints=footprints or "")
                self.message(translate("GcpDock", "Results loaded"))

        def failed(message, cancelled):
            self._results_task = None
            if not cancelled:
                self.message(message, Qgis.MessageLevel.Warning)

        self._results_task = CoreTask(translate("GcpDock", "ArchaeoOrtho: load results"), prepare_results, (root,),
                                      on_done=done, on_error=failed)
        self.message(translate("GcpDock", "Loading the results\u2026"))
        return start(self._results_task)

    def load_results(self, kinds=None, footprints=None):
        """Add the workspace's products as styled layers (DSM + hillshade, orthomosaic, cameras +
        footprints, residuals).  ``footprints``: written already (a task's), "" for none, None: write now."""
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
            out += layers.load_cameras(lay.cameras_gpkg, project, group, workspace=root if footprints is None else None,
                                       footprints=footprints or None)
        res = lay.residuals_gpkg
        if "residuals" in kinds and os.path.exists(res) and self.store.stage_done(GEOREFERENCE):
            out += layers.load_residuals(res, project, group)
        return out
