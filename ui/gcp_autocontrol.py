"""The GCP dock's automatic control (issue 16 item 1): a mode of the georeference panel.

Ticked, the panel's Georeference button georeferences the block with no hand-picked GCP, from a reference
orthophoto and a reference DSM picked among the project's raster layers (files, or WMS / XYZ / WCS layers, saved
for the block's extent in the worker thread by qgisio/reference_layers.py: qgis.core only).  It runs
core.georef.autocontrol.stage.autocontrol_workspace in a ui.tasks.CoreTask, as the dock's adjustment does; the
dock's points, if any, become check points (as in Processing's Georeference).  When it ends, the table shows
what the stage wrote to georef/control.json (the automatic GCPs auto_NNN and the check points) and the map the
cameras and the automatic GCPs' residuals.  A mixin of ui.gcp_dock.GcpDock; its strings are in the dock's
translation context.
"""
from qgis.core import Qgis, QgsCoordinateTransformContext, QgsMapLayerProxyModel, QgsProject, QgsRasterLayer
from qgis.gui import QgsMapLayerComboBox
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import QFormLayout, QGroupBox

from ..core.project.stages import ALIGN
from ..qgisio import layers
from .tasks import CoreTask

translate = QCoreApplication.translate

AUTOMATIC_COLOUR = "#0b8a5f"  # an automatic GCP's measured position in the photo (found, not placed by hand)


def autocontrol_then_prepare(root, ortho_layer, dsm_layer, check_points=None, extent=None, extent_crs=None,
                             context=None, progress=None):
    """In the worker thread: the reference layers as files (saved when they are web layers), the automatic
    control, then the image footprints the result layers show.  Returns (AutoControlResult, footprints)."""
    from ..core.common.progress import SubProgress
    from ..core.georef.autocontrol.options import AutoControlOptions
    from ..core.georef.autocontrol.stage import autocontrol_workspace
    from ..core.georef.options import GeorefOptions
    from ..qgisio import reference_layers as refs

    ortho, dsm = refs.resolve_references(ortho_layer, dsm_layer, root, extent=extent, extent_crs=extent_crs,
                                         progress=SubProgress(progress, 0.0, 0.1), context=context)
    # the dock's points: read and checked by core as the dock's georeference reads them, then check points
    control = GeorefOptions(gcps=check_points) if check_points is not None else None
    result = autocontrol_workspace(root, AutoControlOptions(reference_ortho=ortho, reference_dsm=dsm, control=control),
                                   SubProgress(progress, 0.1, 0.97))
    return result, layers.footprints_path(root)


class GcpAutoControl:
    """The 'Automatic control' box of the georeference panel and its task."""

    def _build_autocontrol_box(self):
        self.auto_box = QGroupBox(translate("GcpDock", "Automatic control from a reference orthophoto"))
        self.auto_box.setCheckable(True)
        self.auto_box.setChecked(False)
        self.auto_box.setToolTip(translate(
            "GcpDock", "Georeference with no hand-picked GCP: the block is matched to a reference orthophoto and "
                       "takes its heights from a reference DSM. The points of the table become check points."))
        form = QFormLayout(self.auto_box)
        form.setContentsMargins(4, 2, 4, 2)
        self.auto_ortho_combo, self.auto_dsm_combo = QgsMapLayerComboBox(), QgsMapLayerComboBox()
        for combo, tip in ((self.auto_ortho_combo, translate(
                "GcpDock", "A reference orthophoto: a raster file, or a WMS / XYZ layer (saved for the block's "
                           "extent, from the photos' GPS or the map extent)")),
                           (self.auto_dsm_combo, translate(
                               "GcpDock", "A reference DSM or DTM (heights in metres): a raster file or a WCS layer. "
                                          "Only height rasters are listed: not orthophotos, hillshades, web maps "
                                          "or this workspace's own products"))):
            combo.setFilters(QgsMapLayerProxyModel.Filter.RasterLayer)
            combo.setAllowEmptyLayer(True)
            combo.setLayer(None)
            combo.setToolTip(tip)
        form.addRow(translate("GcpDock", "Reference orthophoto:"), self.auto_ortho_combo)
        form.addRow(translate("GcpDock", "Reference DSM:"), self.auto_dsm_combo)
        self.auto_box.toggled.connect(self._autocontrol_toggled)
        self._autocontrol_toggled(False)
        return self.auto_box

    def _watch_height_layers(self):
        """The boxes of heights (the reference DSM here, the dock's 'Heights (Z) from') list height rasters only,
        judged by qgisio.reference_layers.layer_not_heights (core/io/raster.py's check): kept up to date as layers
        are added and as the workspace changes (its own products are no reference)."""
        QgsProject.instance().layersAdded.connect(self._filter_height_layers)
        self.store.workspaceChanged.connect(self._filter_height_layers)
        self._filter_height_layers()

    def _unwatch_height_layers(self):
        try:
            QgsProject.instance().layersAdded.disconnect(self._filter_height_layers)
        except (TypeError, RuntimeError):  # not connected
            pass

    def _filter_height_layers(self, *_args):
        from ..qgisio.reference_layers import layer_not_heights

        rasters = [lyr for lyr in QgsProject.instance().mapLayers().values() if isinstance(lyr, QgsRasterLayer)]
        root = self.store.root if self.store.workspace is not None else None
        for combo, workspace in ((self.auto_dsm_combo, root), (getattr(self, "dsm_combo", None), None)):
            if combo is None:
                continue
            current = combo.currentLayer()
            excepted = [lyr for lyr in rasters if layer_not_heights(lyr, workspace)]
            combo.setExceptedLayerList(excepted)
            if current is not None and current in excepted:
                combo.setLayer(None)

    def _autocontrol_toggled(self, on):
        """Unticked, the box folds to its title: the combos and their labels take no room (issue 36 item 20)."""
        form = self.auto_box.layout()
        # folded: the title's line alone (the style draws the box's empty frame under it otherwise)
        self.auto_box.setMaximumHeight(16777215 if on else self.auto_box.fontMetrics().height() + 6)
        for w in (self.auto_ortho_combo, self.auto_dsm_combo):
            w.setVisible(bool(on))
            label = form.labelForField(w)
            if label is not None:
                label.setVisible(bool(on))
        if hasattr(self, "refine_box"):  # the automatic control refines focal length and distortion in any case
            self.refine_box.setEnabled(not on)
        if hasattr(self, "btn_georef"):
            self.btn_georef.setToolTip(
                translate("GcpDock", "Georeference from the reference orthophoto and DSM (in the background)") if on
                else translate("GcpDock", "Run the adjustment with these points (in the background)"))

    def autocontrol_mode(self):
        return self.auto_box.isChecked()

    def georeference_clicked(self):
        """The Georeference button: the automatic control when its box is ticked, else the adjustment."""
        return self.run_autocontrol() if self.autocontrol_mode() else self.run_georeference()

    def run_autocontrol(self):
        """Georeference with automatic control in a background task; never raises (messages in the dock)."""
        if self.store.workspace is None or self._busy():
            return None
        if not self.store.stage_done(ALIGN):
            self.message(translate("GcpDock", "The block is not aligned yet: run Align images first"),
                         Qgis.MessageLevel.Warning)
            return None
        ortho, dsm = self.auto_ortho_combo.currentLayer(), self.auto_dsm_combo.currentLayer()
        if ortho is None or dsm is None:
            self.message(translate("GcpDock", "Automatic control: choose a reference orthophoto and a reference DSM "
                                              "layer"), Qgis.MessageLevel.Warning)
            return None
        root = self.store.root
        gs = self.store.usable_gcps()
        extent = crs = None
        if self.canvas is not None:  # used for web layers when the photos carry no GPS
            extent, crs = self.canvas.extent(), self.canvas.mapSettings().destinationCrs()
            from ..qgisio.reference_layers import gps_lonlat

            if gps_lonlat(root):
                extent = crs = None

        def done(outcome):
            result, footprints = outcome
            self._task_ended()
            self.progress.setValue(100)
            self.open_workspace(root)  # the table: the automatic GCPs and the check points the stage used
            self.load_results(kinds=("cameras",), footprints=footprints)
            self._load_automatic_gcps()
            f = result.georef.figures
            text = translate("GcpDock", "Automatic control: {} automatic GCPs kept of {} matches; georeferenced in "
                                        "{}.").format(result.n_kept, result.figures.get("matches"), result.crs)
            if f.get("CHECK_N"):
                text += " " + translate("GcpDock", "Check points: RMSE XY {:.3f} m, Z {:.3f} m (n = {}).").format(
                    f.get("CHECK_RMSE_XY") or 0.0, f.get("CHECK_RMSE_Z") or 0.0, f.get("CHECK_N"))
            self.message(text, Qgis.MessageLevel.Success)
            self.auto_result = result

        self.auto_result = None
        from ..qgisio.reference_layers import snapshot

        # the worker reads snapshots taken here, on the GUI thread, not the project's layers the canvas renders
        # and the project's transform context, copied here: QgsProject is not read from the worker either
        context = QgsCoordinateTransformContext(QgsProject.instance().transformContext())
        task = CoreTask(translate("GcpDock", "ArchaeoOrtho: automatic control"), autocontrol_then_prepare,
                        (root, snapshot(ortho), snapshot(dsm)), {"check_points": gs if gs.points else None, "extent": extent,
                                             "extent_crs": crs, "context": context},
                        on_done=done, on_error=self._task_failed)
        self.message(translate("GcpDock", "Automatic control against {} and {}\u2026").format(ortho.name(), dsm.name()))
        return self._start_task(task)

    def _load_automatic_gcps(self):
        """The automatic GCPs (and the check points) with their residual vectors, as a styled layer."""
        lay = self.store.layout
        if lay is None:
            return []
        import os

        if not os.path.exists(lay.residuals_gpkg):
            return []
        return layers.load_residuals(lay.residuals_gpkg, QgsProject.instance(), layers.workspace_group_name(
            self.store.root), name=translate("GcpDock", "Automatic GCPs (residuals)"))

    # ------------------------------------------------------------------ the automatic GCPs in the photos
    def automatic_photo(self, name):
        """The photo to show for the automatic GCP ``name``: the one shown when it was measured there, else the
        first photo of the strip where it was measured (issue 48 item 11: never one to place it in by hand)."""
        point = self.store.gcps.by_name(name)
        measured = point.images() if point is not None else []
        if self.photo_panel.image in measured:
            return self.photo_panel.image
        strip = self.photo_panel.thumbnail_names()
        return next((n for n in strip if n in measured), measured[0] if measured else None)

    def show_automatic_marker(self):
        """An automatic GCP's observation in the photo view: labelled and coloured as found by the automatic
        control, with the hint saying where it comes from (it was shown as a prediction to place by hand)."""
        from qgis.PyQt.QtGui import QColor

        panel = self.photo_panel
        name = self.current_name()
        marker = panel.observation
        if marker is None or not self.store.is_automatic(name):
            return False
        point = self.store.gcps.by_name(name)
        obs = next((o for o in point.observations if o.image == panel.image), None)
        if obs is None:
            return False
        marker.label = translate("GcpDock", "{} (automatic)").format(name)
        marker.colour = QColor(AUTOMATIC_COLOUR)
        marker.setToolTip(translate("GcpDock", "Automatic GCP: measured by the automatic control (matched against "
                                               "the reference orthophoto)"))
        marker.update()
        panel.title.setText(translate("GcpDock", "<b>{}</b> (automatic GCP) \u2014 {}").format(name, panel.image))
        panel.hint.setText(translate("GcpDock", "{} is an automatic GCP: found by the automatic control at x {:.2f}, "
                                                "y {:.2f} in this photo (measured in {} photos), not a prediction to "
                                                "place. Drag it to correct it, or press Delete to remove it from "
                                                "this photo.").format(name, obs.x, obs.y, len(point.observations)))
        return True
