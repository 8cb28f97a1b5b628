"""Import and export of the GCP dock's ground control: files (OpenDroneMap gcp_list.txt, CSV points and
observations) and point layers (one feature per observation, as the Georeference algorithm's GCP_LAYER).
A mixin of ui.gcp_dock.GcpDock; its strings are translated in the dock's context."""
import os

from qgis.core import (
    Qgis,
    QgsFeature,
    QgsGeometry,
    QgsPoint,
    QgsProject,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QCoreApplication, QVariant
from qgis.PyQt.QtWidgets import QCheckBox, QFileDialog, QInputDialog, QMessageBox

from ..core.geometry.crs import transform_points
from ..core.io import gcp as gcpmod
from ..core.io.images import ImageError, exif_orientation
from ..qgisio import layers

translate = QCoreApplication.translate


class GcpImportExport:
    """Import / export actions of the dock."""

    # ------------------------------------------------------------------ import / export
    def choose_import_file(self):
        path, _ = QFileDialog.getOpenFileName(self, translate("GcpDock", "Import ground control"), self.store.root or "",
                                              translate("GcpDock", "Ground control (*.txt *.csv);;All files (*)"))
        if path:
            merge, upright = self._ask_import_options()
            if merge is not None:
                self.import_file(path, merge=merge, upright=upright)

    def photo_orientations(self):
        """{image: EXIF orientation} of the workspace's photos that a photo viewer shows turned (not 1): as the
        alignment recorded it, read from the photo only in a workspace that predates the record."""
        out = {}
        for im in self.store.images():
            o = im.get("orientation")
            if o is None:
                try:
                    o = exif_orientation(im["path"]) if im.get("path") and os.path.exists(im["path"]) else 1
                except ImageError:
                    o = 1
            if o != 1:
                out[im["name"]] = o
        return out

    def _ask_import_options(self):
        """(merge, upright) for an import; merge None when the user cancelled.  The merge question only when
        points exist, the upright option only when some photo has an EXIF orientation that turns it."""
        turned = self.photo_orientations()
        if not self.store.gcps.points and not turned:
            return False, False
        box = QMessageBox(QMessageBox.Icon.Question, translate("GcpDock", "Import ground control"),
                          translate("GcpDock", "Replace the current points, or add the imported ones to them (same names are "
                                  "updated)?") if self.store.gcps.points else
                          translate("GcpDock", "How were the pixel coordinates measured?"), parent=self)
        replace = box.addButton(translate("GcpDock", "Replace") if self.store.gcps.points else translate("GcpDock", "Import"),
                                QMessageBox.ButtonRole.AcceptRole)
        if self.store.gcps.points:
            box.addButton(translate("GcpDock", "Add"), QMessageBox.ButtonRole.AcceptRole)
        cancel = box.addButton(QMessageBox.StandardButton.Cancel)
        upright = None
        if turned:
            upright = QCheckBox(translate("GcpDock", "Coordinates measured on upright photos ({} photos are stored turned: "
                                          "EXIF orientation); leave unticked for the stored pixel grid (COLMAP's, "
                                          "OpenDroneMap's)").format(len(turned)))
            box.setCheckBox(upright)
        box.exec()
        if box.clickedButton() is cancel:
            return None, False
        return box.clickedButton() is not replace, bool(upright is not None and upright.isChecked())

    def import_file(self, path, merge=False, upright=False):
        """Read an ODM gcp_list.txt or a CSV points file (+ observations) into the workspace's control.
        Observations in photos that are not in the workspace are left out with a warning; an error only when
        none is in one of its photos.  ``upright``: the pixel coordinates were measured on the photos shown
        upright (EXIF orientation applied, as browsers show them): converted to the stored grid."""
        try:
            gs = gcpmod.read_gcps(path, image_names=[im["name"] for im in self.store.images()] or None,
                                  image_sizes=self.store.image_sizes() or None, unknown_images="warn",
                                  upright_orientations=self.photo_orientations() if upright else None)
        except (gcpmod.GCPError, OSError, ValueError) as e:
            self.message(str(e), Qgis.MessageLevel.Critical)
            return None
        return self._import(gs, os.path.basename(path), merge)

    def _import(self, gs, source, merge):
        if self.store.crs and gs.crs and layers.qgs_crs(gs.crs) != layers.qgs_crs(self.store.crs) \
                and self.store.gcps.points:
            xyz = [(p.x, p.y, p.z) for p in gs.points]
            out = transform_points(xyz, gs.crs, self.store.crs) if xyz else []
            for p, q in zip(gs.points, out):
                p.x, p.y = float(q[0]), float(q[1])
            gs.crs = self.store.crs
        n_obs = gs.n_observations()
        if n_obs == 0:  # coordinates only (a surveyor's list): that the points have no observations is the point
            gs.warnings = [w for w in gs.warnings
                           if "no usable observation" not in w and "no observations file" not in w]
        changed = self.store.replace_all(gs, translate("GcpDock", "import {}").format(source), merge=merge)
        warn = f" ({len(gs.warnings)} " + translate("GcpDock", "warnings") + ")" if gs.warnings else ""
        if merge and changed:  # what the merge changed (roles and sigmas the user set are kept)
            warn += ". " + "; ".join(changed)
        # observations left out because their photos are not in the workspace: say which, not just how many
        left_out = next((w for w in gs.warnings if "that are not in the block" in w), None)
        if left_out:
            warn += ": " + left_out.split(": ", 1)[-1]
        self.message(translate("GcpDock", "Imported {} points and {} observations from {}").format(
            len(gs.points), n_obs, source) + warn, Qgis.MessageLevel.Warning if gs.warnings else Qgis.MessageLevel.Info)
        if gs.warnings:
            self.status.setToolTip("\n".join(gs.warnings))
        self.load_predictor()
        self._selection_changed()
        return gs

    def choose_import_layer(self):
        candidates = [lyr for lyr in QgsProject.instance().mapLayers().values()
                      if isinstance(lyr, QgsVectorLayer)
                      and lyr.geometryType() == QgsWkbTypes.GeometryType.PointGeometry]
        if not candidates:
            self.message(translate("GcpDock", "No point layer in the project"), Qgis.MessageLevel.Warning)
            return
        names = [lyr.name() for lyr in candidates]
        name, ok = QInputDialog.getItem(self, translate("GcpDock", "Import ground control"),
                                        translate("GcpDock", "Point layer (one feature per observation: name, image, px, py)"),
                                        names, 0, False)
        if ok:
            merge, upright = self._ask_import_options()
            if merge is not None:
                self.import_layer(candidates[names.index(name)], merge=merge, upright=upright)

    def import_layer(self, layer, merge=False, upright=False):
        """A point layer with one feature per observation (fields name, image, px, py; z, sx, sy, sz, role
        optional), as the Georeference algorithm's GCP_LAYER; ``upright`` as for import_file."""
        fields = [f.name() for f in layer.fields()]
        lower = [f.lower() for f in fields]
        for need in ("name", "image", "px", "py"):
            if need not in lower:
                self.message(translate("GcpDock", "Layer {} lacks the field '{}' (needs name, image, px, py)").format(
                    layer.name(), need), Qgis.MessageLevel.Critical)
                return None
        rows = []
        for feat in layer.getFeatures():
            attrs = {k.lower(): feat[k] for k in fields}
            attrs = {k: (None if isinstance(v, QVariant) and v.isNull() else v) for k, v in attrs.items()}
            geom = feat.geometry()
            if geom.isNull():
                continue
            pt = geom.constGet()
            z = attrs.get("z")
            if z in (None, "") and pt.is3D():
                z = pt.z()
            rows.append(dict(attrs, x=pt.x(), y=pt.y(), z=z if z not in (None, "") else 0.0))
        crs = layers.crs_text(layer.crs())
        try:
            gs = gcpmod.gcps_from_rows(rows, crs, source_name=layer.name(),
                                       image_names=[im["name"] for im in self.store.images()] or None,
                                       image_sizes=self.store.image_sizes() or None, unknown_images="warn",
                                       upright_orientations=self.photo_orientations() if upright else None)
        except (gcpmod.GCPError, ValueError) as e:
            self.message(str(e), Qgis.MessageLevel.Critical)
            return None
        return self._import(gs, layer.name(), merge)

    def choose_export_file(self):
        odm, csv_ = translate("GcpDock", "OpenDroneMap gcp_list (*.txt)"), translate("GcpDock", "CSV points + observations (*.csv)")
        path, chosen = QFileDialog.getSaveFileName(self, translate("GcpDock", "Export ground control"),
                                                   os.path.join(self.store.root or "", "gcp_list.txt"),
                                                   f"{odm};;{csv_}")
        if path:
            if chosen == csv_ and not path.lower().endswith(".csv"):
                path += ".csv"
            self.export_file(path)

    def export_file(self, path):
        gs = self.store.usable_gcps()
        if not gs.crs:
            self.message(translate("GcpDock", "The points have no CRS yet: pick one on the map or import a file first"),
                         Qgis.MessageLevel.Warning)
            return None
        try:
            gcpmod.write_gcps(gs, path)
        except (gcpmod.GCPError, OSError) as e:
            self.message(str(e), Qgis.MessageLevel.Critical)
            return None
        left = len(self.store.gcps.points) - len(gs.points)
        self.message(translate("GcpDock", "Exported {} points to {}").format(len(gs.points), path)
                     + (translate("GcpDock", " ({} without coordinates left out)").format(left) if left else ""))
        return path

    def choose_export_layer(self):
        path, _ = QFileDialog.getSaveFileName(self, translate("GcpDock", "Export ground control as a layer"),
                                              os.path.join(self.store.root or "", "gcp_observations.gpkg"),
                                              translate("GcpDock", "GeoPackage (*.gpkg)"))
        if path:
            self.export_layer(path if path.lower().endswith(".gpkg") else path + ".gpkg", add_to_project=True)

    def export_layer(self, path, add_to_project=False):
        """One PointZ feature per observation (name, image, px, py, z, sx, sy, sz, role): readable by
        'Import from a point layer' and by the Georeference algorithm's GCP_LAYER."""
        gs = self.store.usable_gcps()
        crs = layers.qgs_crs(gs.crs)
        fields = "&".join(f"field={n}:{t}" for n, t in (
            ("name", "string"), ("image", "string"), ("px", "double(0,0)"), ("py", "double(0,0)"), ("z", "double(0,0)"),
            ("sx", "double(0,0)"), ("sy", "double(0,0)"), ("sz", "double(0,0)"), ("role", "string")))
        mem = QgsVectorLayer(f"PointZ?{fields}", "gcp_observations", "memory")
        if crs.isValid():
            mem.setCrs(crs)
        pr = mem.dataProvider()
        feats = []
        for p in gs.points:
            for o in p.observations:
                f = QgsFeature(mem.fields())
                f.setGeometry(QgsGeometry(QgsPoint(p.x, p.y, p.z)))
                # sigmas the source did not give stay empty (NULL): read back, they are estimated again
                sig = [p.sigma_xy, p.sigma_xy, p.sigma_z] if p.sigma_given else [None, None, None]
                f.setAttributes([p.name, o.image, o.x, o.y, p.z, *sig, p.role])
                feats.append(f)
        pr.addFeatures(feats)
        opts = QgsVectorFileWriter.SaveVectorOptions()
        opts.driverName = "GPKG"
        opts.layerName = "gcp_observations"
        res = QgsVectorFileWriter.writeAsVectorFormatV2(mem, path, QgsProject.instance().transformContext(), opts)
        if res[0] != QgsVectorFileWriter.WriterError.NoError:
            self.message(translate("GcpDock", "Cannot write {}: {}").format(path, res[1]), Qgis.MessageLevel.Critical)
            return None
        skipped = [p.name for p in gs.points if not p.observations]
        self.message(translate("GcpDock", "Exported {} observations to {}").format(len(feats), path)
                     + (translate("GcpDock", " (points without observations left out: {})").format(", ".join(skipped))
                        if skipped else ""))
        if add_to_project:
            added = QgsProject.instance().addMapLayer(QgsVectorLayer(path, translate("GcpDock", "GCP observations"), "ogr"))
            if added is None:
                self.message(translate("GcpDock", "Cannot add {} to the project").format(path),
                             Qgis.MessageLevel.Warning)
        return path
