"""The GCP dock's table: the model over the store's points (coordinates and sigmas editable), the role
editor, and the residuals of the last adjustment coloured against the dock's tolerance."""
import math

from qgis.core import Qgis
from qgis.PyQt.QtCore import QAbstractTableModel, QCoreApplication, QModelIndex, Qt
from qgis.PyQt.QtGui import QColor, QFont
from qgis.PyQt.QtWidgets import QComboBox, QStyledItemDelegate

from ..core.io import gcp as gcpmod
from ..qgisio import layers

NAME, X, Y, Z, SXY, SZ, ROLE, OBS, DXY, DZ, PX = range(11)
EDITABLE = {NAME, X, Y, Z, SXY, SZ, ROLE}
GOOD, FAIR, BAD, NONE = QColor("#b8e6b0"), QColor("#ffe08a"), QColor("#f4a3a3"), QColor("#dddddd")


def fmt(v, digits=3):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "\u2014"
    return f"{v:.{digits}f}"


class GcpTableModel(QAbstractTableModel):
    """The GCP table: coordinates and sigmas editable, residuals of the last adjustment in colour."""

    def __init__(self, dock):
        super().__init__(dock)
        self.dock = dock
        self.store = dock.store
        self.found_info = None  # point name -> tooltip line on its found observations not confirmed, or None

    def tr(self, text):
        return QCoreApplication.translate("GcpTableModel", text)

    def headers(self):
        return [self.tr("Name"), self.tr("X"), self.tr("Y"), self.tr("Z"), self.tr("\u03c3 XY"), self.tr("\u03c3 Z"),
                self.tr("Role"), self.tr("Obs."), self.tr("dXY (m)"), self.tr("dZ (m)"), self.tr("px")]

    def role_text(self, role):
        return self.tr("check") if role == gcpmod.CHECK else self.tr("control")

    def rowCount(self, parent=QModelIndex()):  # noqa: N802, B008 (Qt API)
        return 0 if parent.isValid() else len(self.store.gcps.points)

    def columnCount(self, parent=QModelIndex()):  # noqa: N802, B008 (Qt API)
        return 0 if parent.isValid() else 11

    def headerData(self, section, orientation, role=Qt.ItemDataRole.DisplayRole):  # noqa: N802 (Qt API)
        if orientation == Qt.Orientation.Horizontal and role == Qt.ItemDataRole.DisplayRole:
            return self.headers()[section]
        if orientation == Qt.Orientation.Horizontal and role == Qt.ItemDataRole.ToolTipRole:
            tips = {DXY: self.tr("Horizontal residual after the adjustment (estimated from the photos minus given)"),
                    DZ: self.tr("Vertical residual after the adjustment"),
                    PX: self.tr("Mean reprojection error of the point's observations (pixels)"),
                    OBS: self.tr("Number of photos the point is placed in")}
            return tips.get(section)
        return None

    def residual(self, name):
        return self.store.residuals.get(name)

    def quality(self, name):
        """(colour, text) of a point's residual against the dock's tolerance."""
        r = self.residual(name)
        if r is None:
            return None, ""
        if r.get("status") == "rejected":
            return BAD, self.tr("rejected as an outlier")
        if r.get("dx") is None:
            return NONE, self.tr("not triangulated (fewer than 2 usable observations)")
        tol = max(self.dock.tolerance(), 1e-9)
        ratio = math.hypot(r["dx"], r["dy"]) / tol
        if not self.store.figures.get("PLACEHOLDER_Z") and r.get("dz") is not None:
            ratio = max(ratio, abs(r["dz"]) / (1.5 * tol))
        if ratio <= 1.0:
            return GOOD, self.tr("within the tolerance")
        if ratio <= 3.0:
            return FAIR, self.tr("up to 3 times the tolerance")
        return BAD, self.tr("more than 3 times the tolerance")

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid():
            return None
        p = self.store.gcps.points[index.row()]
        col = index.column()
        r = self.residual(p.name)
        if role in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.EditRole):
            if col == NAME:
                return p.name
            if col in (X, Y, Z):
                v = {X: p.x, Y: p.y, Z: p.z}[col]
                if role == Qt.ItemDataRole.EditRole:
                    return None if not math.isfinite(v) else v
                return fmt(v, 3)
            if col == SXY:
                return p.sigma_xy if role == Qt.ItemDataRole.EditRole else fmt(p.sigma_xy, 3)
            if col == SZ:
                return p.sigma_z if role == Qt.ItemDataRole.EditRole else fmt(p.sigma_z, 3)
            if col == ROLE:
                return p.role if role == Qt.ItemDataRole.EditRole else self.role_text(p.role)
            if col == OBS:
                return len(p.observations)
            if r is None:
                return "" if col in (DXY, DZ, PX) else None
            if col == DXY:
                return fmt(None if r.get("dx") is None else math.hypot(r["dx"], r["dy"]), 3)
            if col == DZ:
                return fmt(r.get("dz"), 3)
            if col == PX:
                px = [o.get("px") for o in r.get("observations", []) if o.get("px") is not None]
                return fmt(sum(px) / len(px), 2) if px else "\u2014"
        if role == Qt.ItemDataRole.BackgroundRole and col in (NAME, DXY, DZ, PX):
            colour, _ = self.quality(p.name)
            return colour
        found = self.found_info(p.name) if self.found_info is not None and col in (NAME, OBS) else None
        if found and role == Qt.ItemDataRole.ForegroundRole:
            return QColor("#1f6fd1")  # observations found by Find targets, not confirmed yet
        if found and role == Qt.ItemDataRole.FontRole:
            f = QFont()
            f.setBold(True)
            return f
        if role == Qt.ItemDataRole.ToolTipRole:
            colour, text = self.quality(p.name)
            lines = [text] if text else []
            if found:
                lines.append(found)
            if r is not None:
                lines += r.get("notes", [])
            if p.name in self.store.stale and r is not None:
                lines.append(self.tr("edited since the last adjustment: run Georeference to update"))
            return "\n".join(lines) or None
        if role == Qt.ItemDataRole.FontRole and p.name in self.store.stale and col in (DXY, DZ, PX):
            f = QFont()
            f.setItalic(True)
            return f
        if role == Qt.ItemDataRole.ForegroundRole and p.name in self.store.stale and col in (DXY, DZ, PX):
            return QColor("#777777")
        if role == Qt.ItemDataRole.TextAlignmentRole and col not in (NAME, ROLE):
            return int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return None

    def flags(self, index):
        f = super().flags(index)
        if index.isValid() and index.column() in EDITABLE:
            f |= Qt.ItemFlag.ItemIsEditable
        return f

    def setData(self, index, value, role=Qt.ItemDataRole.EditRole):  # noqa: N802 (Qt API)
        if role != Qt.ItemDataRole.EditRole or not index.isValid():
            return False
        p = self.store.gcps.points[index.row()]
        col = index.column()
        try:
            if col == NAME:
                name = str(value).strip()
                if not name or name == p.name:
                    return False
                self.store.set_point(p.name, name=name)
            elif col in (X, Y, Z, SXY, SZ):
                v = float(str(value).replace(",", "."))
                if col in (SXY, SZ) and not v > 0:
                    return False
                key = {X: "x", Y: "y", Z: "z", SXY: "sigma_xy", SZ: "sigma_z"}[col]
                self.store.set_point(p.name, **{key: v})
            elif col == ROLE:
                self.store.set_point(p.name, role=gcpmod.CHECK if value == gcpmod.CHECK else gcpmod.CONTROL)
        except ValueError as e:
            self.dock.message(str(e), Qgis.MessageLevel.Warning)
            return False
        return True

    def refresh(self):
        self.beginResetModel()
        self.endResetModel()

    def repaint_all(self):
        """Values changed, rows did not: keeps the selection."""
        if self.rowCount():
            self.dataChanged.emit(self.index(0, 0), self.index(self.rowCount() - 1, self.columnCount() - 1))


class RoleDelegate(QStyledItemDelegate):
    def createEditor(self, parent, option, index):  # noqa: N802 (Qt API)
        combo = QComboBox(parent)
        model = index.model()
        combo.addItem(model.role_text(gcpmod.CONTROL), gcpmod.CONTROL)
        combo.addItem(model.role_text(gcpmod.CHECK), gcpmod.CHECK)
        return combo

    def setEditorData(self, editor, index):  # noqa: N802 (Qt API)
        editor.setCurrentIndex(1 if index.data(Qt.ItemDataRole.EditRole) == gcpmod.CHECK else 0)

    def setModelData(self, editor, model, index):  # noqa: N802 (Qt API)
        model.setData(index, editor.currentData(), Qt.ItemDataRole.EditRole)


def short_crs(text):
    """A CRS as the dock shows it: its authority id, else its description."""
    crs = layers.qgs_crs(text)
    if crs.isValid():
        return crs.authid() or crs.description() or text[:40]
    return text[:40]
