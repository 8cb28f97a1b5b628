"""Placing the GCP dock's points: on the map canvas (X, Y and the height from a DSM layer) and in the photos,
with guided placement (core.georef.guided predicts where a point is in each photo and refines that by
matching its look in a photo where it is placed).  A mixin of ui.gcp_dock.GcpDock: it works on the dock's
store, table and photo panel; its strings are translated in the dock's context."""
import dataclasses
import html
import math
import os

import numpy as np
from qgis.core import Qgis, QgsCoordinateTransform, QgsPointXY, QgsProject
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import QMessageBox

from ..core.project.stages import ALIGN, GEOREFERENCE
from ..qgisio import layers
from ..qgisio.messages import translate_message
from .raster import sample_height

translate = QCoreApplication.translate


class GcpPlacement:
    """Guided placement of the selected point (the predictor, the predictions, the photo strip) and the
    map tool."""

    # ------------------------------------------------------------------ the block model
    def load_predictor(self):
        """Load the block model for guided placement: the georeferenced model when its CRS is the GCPs',
        else the aligned one (positions then come from rays and a Helmert fit of the placed points)."""
        self.predictor = None
        self.predictor_note = ""
        if self.store.workspace is None or not self.store.stage_done(ALIGN):
            return
        try:
            from ..core.align import stage as align_stage
            from ..core.georef import guided
            from ..core.georef.stage import load_georef_model
        except ImportError as e:
            self.predictor_note = translate("GcpDock", "no predicted positions: {}").format(e)
            return
        ws = self.store.root
        try:
            if self.store.stage_done(GEOREFERENCE) and os.path.isdir(self.store.layout.georef_model_dir):
                prebuilt = self._take_prebuilt_model(ws, True)  # read and measured in a task (GcpTasks), or None
                rec, transform = prebuilt[:2] if prebuilt else load_georef_model(ws)
                same = layers.qgs_crs(transform.crs) == layers.qgs_crs(self.store.crs)
                self.predictor = guided.Predictor(rec, transform.offset if same else None)
            else:
                prebuilt = self._take_prebuilt_model(ws, False)
                self.predictor = guided.Predictor(prebuilt[0] if prebuilt else align_stage.load_model(ws))
            gsd = prebuilt[2] if prebuilt else guided.ground_sample_distance(self.predictor.rec)
            self._gsd_tolerance = None
            if gsd and self.predictor.georeferenced and not self.store.settings.get("tolerance"):
                self._gsd_tolerance = (max(0.001, round(3.0 * gsd, 3)), gsd)
                self.tol_spin.blockSignals(True)  # a default, not the user's choice: not saved (but shown)
                self.tol_spin.setValue(self._gsd_tolerance[0])
                self.tol_spin.blockSignals(False)
                self.model.repaint_all()
        except Exception as e:  # noqa: BLE001 - a broken model must not break the dock
            self.predictor = None
            self.predictor_note = translate("GcpDock", "no predicted positions: {}").format(e)
            self.show_tolerance_source()
            return
        self.show_tolerance_source()
        self.predictor_note = (translate("GcpDock", "Predicted positions from the georeferenced block.")
                               if self.predictor.georeferenced else
                               translate("GcpDock", "Predicted positions once a point is placed in 2 photos, and for every "
                                       "point once 3 points are placed."))

    # ------------------------------------------------------------------ tolerance and diagnosis
    def tolerance_source(self):
        """Where the residual tolerance comes from, as the dock shows it next to the value."""
        if self.store.settings.get("tolerance"):
            return translate("GcpDock", "your setting")
        gsd = getattr(self, "_gsd_tolerance", None)
        if gsd is not None and abs(self.tol_spin.value() - gsd[0]) < 5e-4:
            return translate("GcpDock", "default: 3 × GSD of the georeferenced block (GSD {:.3f} m)").format(gsd[1])
        return translate("GcpDock", "default")

    def show_tolerance_source(self):
        text = self.tolerance_source()
        label = getattr(self, "tol_source", None)
        if label is not None:
            label.setText(text if "(" in text else "(" + text + ")")
        self.tol_spin.setToolTip(translate("GcpDock", "Residuals up to this are green, up to 3 times yellow, beyond "
                                           "red. Now: {}").format(text))

    def diagnosis_text(self, shown=None):
        """The last adjustment's diagnosis (its warnings and outliers, georef/residuals.json) as rich text, one
        bullet per message: the first ``shown`` messages and how many more; None (the dock): all of them, whole
        (the finding, e.g. four automatic GCPs suspect and the worst, was cut at 100 characters: issue 36 item 18)."""
        lines = self.store.diagnosis
        if not lines:
            return ""
        title = "<b>" + translate("GcpDock", "Diagnosis of the adjustment:") + "</b>"
        listed = lines if shown is None else lines[:shown]
        more = len(lines) - len(listed)
        # the core's English in the user's language (qgisio/messages.py: issue 48 item 6)
        return title + "<br>" + "<br>".join("\u2022 " + html.escape(translate_message(t)) for t in listed) + (
            f" <i>(+{more})</i>" if more else "")

    def show_diagnosis(self):
        """The diagnosis under the summary, every message whole (the dock's body scrolls)."""
        label = getattr(self, "diagnosis", None)
        if label is not None:
            text = self.diagnosis_text()
            label.setText(text)
            label.setVisible(bool(text))

    # ------------------------------------------------------------------ map tool
    def set_picking(self, on):
        if self.map_tool is None or self.canvas is None:
            return
        if on:
            if self.canvas.mapTool() is not self.map_tool:
                self.prev_tool = self.canvas.mapTool()
            self.canvas.setMapTool(self.map_tool)
            self.message(translate("GcpDock", "Click on the map at the selected point's position (Esc to stop)"))
        elif self.canvas.mapTool() is self.map_tool:
            self.canvas.unsetMapTool(self.map_tool)
            if self.prev_tool is not None:
                self.canvas.setMapTool(self.prev_tool)
            self.prev_tool = None
        if self.act_pick.isChecked() != on:
            self.act_pick.setChecked(on)

    def _project_crs(self):
        if self.canvas is not None:
            return self.canvas.mapSettings().destinationCrs()
        return QgsProject.instance().crs()

    def map_picked(self, point):
        """A canvas click at ``point`` (canvas CRS): X, Y of the selected point (a new one when none is
        selected) in the GCP CRS, Z from the heights layer."""
        if self.store.workspace is None:
            return
        if self.store.crs:
            return self._map_picked(point)
        stack = self.store.undo_stack
        stack.beginMacro(translate("GcpDock", "pick on map"))  # the CRS it sets and the point: one undo step
        try:
            return self._map_picked(point)
        finally:
            stack.endMacro()

    def _map_picked(self, point):
        canvas_crs = self._project_crs()
        if not self.store.crs:
            self.store.set_crs(layers.crs_text(canvas_crs))
        gcp_crs = layers.qgs_crs(self.store.crs)
        p = QgsPointXY(point)
        if gcp_crs.isValid() and canvas_crs.isValid() and gcp_crs != canvas_crs:
            p = QgsCoordinateTransform(canvas_crs, gcp_crs, QgsProject.instance()).transform(p)
        z = None
        dsm = self.dsm_combo.currentLayer()
        if dsm is not None:
            z = sample_height(dsm, QgsPointXY(point), canvas_crs)
        name = self.current_name()
        moved = ""
        old = self.store.gcps.by_name(name) if name is not None else None
        if old is not None and old.observations and math.isfinite(old.x) and math.isfinite(old.y):
            choice = self._ask_move(old, math.hypot(p.x() - old.x, p.y() - old.y))
            if choice is None:
                self.set_picking(False)
                self.message(translate("GcpDock", "{} not moved").format(name))
                return None
            if choice == "new":
                name = old = None
        if name is None:
            name = self.add_point(x=p.x(), y=p.y(), z=z if z is not None else math.nan)
        else:
            if math.isfinite(old.x) and math.isfinite(old.y):
                moved = " " + translate("GcpDock", "Moved {:.2f} m (Undo: Ctrl+Z).").format(
                    math.hypot(p.x() - old.x, p.y() - old.y))
            fields = {"x": p.x(), "y": p.y()}
            if z is not None:
                fields["z"] = z
            self.store.set_point(name, **fields)
        # one pick per 'Pick on map': a later click on the map must not move the point
        self.set_picking(False)
        if z is not None:
            self.message(translate("GcpDock", "{}: X {:.3f}, Y {:.3f}, Z {:.3f} (from {})").format(
                name, p.x(), p.y(), z, dsm.name()) + moved)
        elif dsm is not None:
            self.message(translate("GcpDock", "{}: X {:.3f}, Y {:.3f}. No height at this place in {}: Z left as it was").format(
                name, p.x(), p.y(), dsm.name()) + moved, Qgis.MessageLevel.Warning)
        else:
            self.message(translate("GcpDock", "{}: X {:.3f}, Y {:.3f}").format(name, p.x(), p.y()) + moved)
        self.show_best_photo()
        return name

    def _ask_move(self, point, distance):
        """A map pick for a point already placed in photos: "move", "new" (a new point there) or None (cancel)."""
        box = QMessageBox(QMessageBox.Icon.Question, translate("GcpDock", "Pick on map"),
                          translate("GcpDock", "{} is placed in {} photos. Move it {:.2f} m to the picked position, or "
                                    "add a new point there?").format(point.name, len(point.observations), distance),
                          parent=self)
        move = box.addButton(translate("GcpDock", "Move {}").format(point.name), QMessageBox.ButtonRole.AcceptRole)
        new = box.addButton(translate("GcpDock", "New point"), QMessageBox.ButtonRole.AcceptRole)
        box.addButton(QMessageBox.StandardButton.Cancel)
        box.setDefaultButton(new)
        box.exec()
        clicked = box.clickedButton()
        return "move" if clicked is move else "new" if clicked is new else None

    def best_photo(self):
        """The photo where the selected point is predicted most centrally and not yet placed (None if none)."""
        point = self.current_point()
        if point is None:
            return None
        observed = set(point.images())
        shown = set(self.photo_panel.paths)
        cands = [n for n in self.predictions if n not in observed and n in shown and self._may_offer(n)]
        return min(cands, key=lambda n: self.predictions[n].centrality) if cands else None

    def show_best_photo(self):
        """Show the best predicted photo of the selected point, zoomed to the prediction."""
        best = self.best_photo()
        if best is None:
            return False
        if best == self.photo_panel.image:
            self._update_photo(zoom=True)
        else:
            self.show_photo(best)
        return True

    def _update_markers(self):
        if self.markers is None:
            return
        gcp_crs = layers.qgs_crs(self.store.crs)
        canvas_crs = self._project_crs()
        tr = None
        if gcp_crs.isValid() and canvas_crs.isValid() and gcp_crs != canvas_crs:
            tr = QgsCoordinateTransform(gcp_crs, canvas_crs, QgsProject.instance())
        pts = {}
        for p in self.store.gcps.points:
            if not (math.isfinite(p.x) and math.isfinite(p.y)):
                continue
            q = QgsPointXY(p.x, p.y)
            if tr is not None:
                try:
                    q = tr.transform(q)
                except Exception:  # noqa: BLE001 - QgsCsException: not drawable in this CRS
                    continue
            pts[p.name] = q
        self.markers.update(pts, self.current_name())

    # ------------------------------------------------------------------ photos and predictions
    def _predictable(self, point):
        """The point as the predictor is to see it: a point with X and Y but no Z (no heights layer, none typed)
        on a georeferenced block stands at the height of the block's tie points around it."""
        self._z_from_block = False
        if point is None or self.predictor is None or not self.predictor.georeferenced \
                or not (math.isfinite(point.x) and math.isfinite(point.y)) or math.isfinite(point.z):
            return point
        off = self.predictor.offset
        try:
            z = self.predictor.surface_height(point.x - off[0], point.y - off[1])
        except Exception:  # noqa: BLE001 - no surface: no prediction from the world coordinates
            z = None
        if z is None or not math.isfinite(z):
            return point
        self._z_from_block = True
        return dataclasses.replace(point, z=float(z + off[2]))

    def _update_predictions(self):
        self.predictions = {}
        point = self.current_point()
        if point is None or self.predictor is None:
            return
        try:
            self.predictor.fit(self.store.gcps)
            point = self._predictable(point)
            preds = self.predictor.predict_point(point)
            if any(p.source != "rays" for p in preds.values()):
                # positions from world coordinates can be off by the block's misfit to the control: offer
                # the photos where the point lands near the frame too (matching may find it inside)
                slack = -0.15 * max(self.predictor.rec.cameras[c].width for c in self.predictor.rec.cameras)
                preds = self.predictor.predict_point(point, margin=slack)
            self.predictions = preds
        except Exception as e:  # noqa: BLE001 - degenerate geometry: no predictions, say why
            self.message(translate("GcpDock", "no predicted positions: {}").format(e), Qgis.MessageLevel.Warning)
            self.predictions = {}

    def _gray_image(self, name):
        from ..core.georef.guided import read_gray

        if name not in self._gray:
            path = next((im["path"] for im in self.store.images() if im["name"] == name), None)
            if path is None:
                return None
            self._gray[name] = read_gray(path)
            while len(self._gray) > 6:
                self._gray.pop(next(iter(self._gray)))
        return self._gray[name]

    def refined_prediction(self, image):
        """The prediction offered in ``image``: the refined one (``_refined_prediction``) when its position is in
        the photo and outside its mask, else (None, None) and ``refused[image]`` says why."""
        refused = self.__dict__.setdefault("refused", {})
        refused.pop(image, None)
        pred, match = self._refined_prediction(image)
        if pred is None:
            return None, None
        problem = self.store.position_problem(image, pred.x, pred.y)
        if problem is not None:
            refused[image] = problem
            return None, None
        return pred, match

    @staticmethod
    def _match_key(point, image, pred):
        return (point.name, image, tuple((o.image, round(o.x, 3), round(o.y, 3)) for o in point.observations),
                round(pred.x, 2), round(pred.y, 2))

    def _may_offer(self, image, masks=True):
        """Whether the prediction in ``image`` can be offered: its geometric position (or its refinement, when
        already matched) lies in the photo (and, with ``masks``, outside its mask)."""
        pred = self.predictions.get(image)
        point = self.current_point()
        if pred is None or point is None:
            return False
        if self.store.position_problem(image, pred.x, pred.y, masks=masks) is None:
            return True
        match = self.matches.get(self._match_key(point, image, pred))
        return match is not None and self.store.position_problem(image, match.x, match.y, masks=masks) is None

    def _refined_prediction(self, image):
        """The prediction in ``image``, refined by matching the point's look in a photo where it is placed
        (core.guided.refine_by_matching); the geometric prediction when matching finds nothing sure."""
        from ..core.georef import guided

        pred = self.predictions.get(image)
        point = self.current_point()
        if pred is None or point is None or pred.source == guided.RAYS or not point.observations \
                or self.predictor is None:
            return pred, None
        key = self._match_key(point, image, pred)
        if key not in self.matches and self._refine_later(key, point, image, pred):
            return pred, None  # matching in a background task (GcpTasks._refine_later); the photo updates after
        if key not in self.matches:
            match = None
            try:
                xyz, _ = self.predictor.model_point(self._predictable(point))
                cam = self.predictor.rec.cameras
                size = max(max(c.width, c.height) for c in cam.values())
                tgt = self._gray_image(image)
                refs = sorted(point.observations, key=lambda o: self._baseline(o.image, image))
                for ref in refs[:2]:
                    match = guided.refine_by_matching(
                        self.predictor.rec, guided.PhotoPoint(ref.image, (ref.x, ref.y), self._gray_image(ref.image)),
                        guided.PhotoPoint(image, pred.xy, tgt), xyz, guided.MatchSearch(radius=min(600.0, 0.3 * size)))
                    if match is not None:
                        break
            except Exception:  # noqa: BLE001 - matching is a help, never an obstacle
                match = None
            self.matches[key] = match
        match = self.matches[key]
        if match is None:
            return pred, None
        return guided.Prediction(pred.name, image, match.x, match.y, "matched", pred.centrality), match

    def _baseline(self, a, b):
        """Distance between two photos' projection centres (nearer photos look more alike)."""
        try:
            lookup = self.predictor._lookup
            ca = np.asarray(lookup[a].projection_center())
            cb = np.asarray(lookup[b].projection_center())
            return float(np.linalg.norm(ca - cb))
        except (KeyError, AttributeError):
            return float("inf")

    def visible_photos(self):
        """Photos for the strip: all, or (filter on) the observed ones and those predicted to see the point."""
        from ..core.georef.guided import images_seeing

        names = [im["name"] for im in self.store.images()]
        point = self.current_point()
        if point is None or not self.photo_panel.filter_box.isChecked():
            return names
        observed = point.images()
        if not self.predictions:
            return observed + [n for n in names if n not in observed]
        return [n for n in images_seeing(self.predictions, observed) if n in set(names)]

    def _update_thumbnails(self):
        point = self.current_point()
        marks = {}
        if point is not None:
            # placed photos: how far the click is from where the point's other photos put it
            loo = self.predictor.leave_one_out(point) if self.predictor is not None else {}
            for o in point.observations:
                d = loo.get(o.image)
                marks[o.image] = "\u2713" + (" " + translate("GcpDock", "{:.1f} px").format(d) if d is not None else "")
            for n in self.predictions:
                marks.setdefault(n, translate("GcpDock", "predicted") if self._may_offer(n, masks=False)
                                 else translate("GcpDock", "near the edge"))
        self.photo_panel.set_thumbnails(self.visible_photos(), marks)

    def show_photo(self, name):
        if self.photo_panel.show_photo(name):
            self._update_photo(zoom=True)

    def _update_photo(self, zoom=False):
        panel = self.photo_panel
        point = self.current_point()
        image = panel.image
        if point is not None and image is None:  # a point and no photo yet: show the first one of the strip
            strip = panel.thumbnail_names()
            if strip and panel.show_photo(strip[0]):
                image, zoom = panel.image, True
        if point is None or image is None:
            panel.set_markers(None)
            panel.set_next_available(False)
            panel.title.setText(f"<b>{point.name if point is not None else image or ''}</b>")
            if self.store.workspace is None:
                panel.hint.setText("")
            elif point is None:
                panel.hint.setText(translate("GcpDock", "Select or add a ground point in the table, then click on it "
                                             "in the photo."))
            else:
                panel.hint.setText(self._no_photo_hint(point))
            return
        obs = next((o for o in point.observations if o.image == image), None)
        pred, match = self.refined_prediction(image) if obs is None else (self.predictions.get(image), None)
        source = {"rays": translate("GcpDock", "from the point's other observations"),
                  "georef": translate("GcpDock", "from the georeferenced block"),
                  "helmert": translate("GcpDock", "from the points already placed (similarity fit)"),
                  "matched": translate("GcpDock", "by matching its look in another photo")}.get(pred.source if pred else "", "")
        if pred is not None and pred.source != "rays" and getattr(self, "_z_from_block", False):
            source += " " + translate("GcpDock", "(no Z yet: at the height of the block's tie points)")
        if match is not None:
            source += " " + translate("GcpDock", "(correlation {:.2f}, {:.0f} px from the geometric prediction)").format(
                match.score, match.shift)
        panel.set_markers(point.name, (obs.x, obs.y) if obs else None, (pred.x, pred.y) if pred else None, source)
        panel.set_next_available(self.next_photo() is not None)
        panel.title.setText(f"<b>{point.name}</b> \u2014 {image}")
        if obs is not None:
            panel.hint.setText(translate("GcpDock", "Placed at x {:.2f}, y {:.2f}. Click to move it, drag it, or press Delete "
                                       "to remove it.").format(obs.x, obs.y))
        elif pred is not None:
            panel.hint.setText(translate("GcpDock", "Predicted {}. Press Enter to accept it and go on (Space: accept), drag "
                                       "it, or click where the point really is.").format(source))
        elif image in getattr(self, "refused", {}):
            panel.hint.setText(translate("GcpDock", "{} is predicted where it cannot be placed: {}. Click where the "
                                         "point is if you see it, or press Enter for the next photo.").format(
                point.name, self.refused[image]))
        elif not point.observations and not self.predictions and not (
                math.isfinite(point.x) and math.isfinite(point.y)) and self.predictor is not None \
                and self.predictor.georeferenced:
            panel.hint.setText(translate("GcpDock", "Click where {} is in this photo, or use Pick on map (or type X, "
                                         "Y, Z in the table) to have it predicted in the photos.").format(point.name))
        else:
            panel.hint.setText(translate("GcpDock", "Click where {} is in this photo.").format(point.name))
        if zoom:
            if obs is not None or pred is not None:
                panel.zoom_to_point(max(2.0, panel.view.zoom()))
            else:
                panel.view.fit()

    def _no_photo_hint(self, point):
        """The viewer's hint for a selected point when no photo is shown: what to do next."""
        if not self.photo_panel.paths:
            return translate("GcpDock", "{}: the workspace has no photos to place it in.").format(point.name)
        if not (math.isfinite(point.x) and math.isfinite(point.y)):
            return translate("GcpDock", "{} is selected: use Pick on map or type X, Y, Z in the table, or choose a "
                             "photo in the strip below and click on the point.").format(point.name)
        return translate("GcpDock", "{} is selected: choose a photo in the strip below and click on the point.").format(
            point.name)

    def place_observation(self, image, x, y):
        name = self.current_name()
        if name is None:
            self.message(translate("GcpDock", "Select or add a ground point first"), Qgis.MessageLevel.Warning)
            return
        try:
            self.store.set_observation(name, image, x, y)
        except ValueError as e:  # outside the photo or in its mask: not stored, the marker goes back
            self.message(str(e), Qgis.MessageLevel.Warning)
            self._update_photo()

    def remove_observation(self, image):
        name = self.current_name()
        if name is not None:
            self.store.remove_observation(name, image)

    def confirm_prediction(self, image=None):
        image = image or self.photo_panel.image
        pred, _ = self.refined_prediction(image)
        name = self.current_name()
        if pred is None or name is None:
            return False
        try:
            self.store.set_observation(name, image, pred.x, pred.y)
        except ValueError as e:
            self.message(str(e), Qgis.MessageLevel.Warning)
            return False
        return True

    def next_photo(self):
        """The next photo in the strip where the selected point is predicted but not yet placed."""
        point = self.current_point()
        if point is None:
            return None
        observed = set(point.images())
        names = self.photo_panel.thumbnail_names()
        cur = self.photo_panel.image
        start = names.index(cur) + 1 if cur in names else 0
        for n in names[start:] + names[:start]:
            if n not in observed and n in self.predictions and self._may_offer(n):
                return n
        return None

    def confirm_and_next(self):
        """Accept the prediction in the photo shown (if any) and show the next photo still to place."""
        self.confirm_prediction()
        nxt = self.next_photo()
        if nxt is not None:
            self.show_photo(nxt)
        else:
            self.message(translate("GcpDock", "{}: every photo predicted to see it has an observation").format(
                self.current_name() or ""))
