"""Map tool of the GCP dock: a click on the canvas (over any backdrop: orthophoto, WMS/XYZ, hillshade)
gives a GCP's X, Y; markers show the GCPs on the canvas."""
from qgis.core import QgsPointXY
from qgis.gui import QgsMapToolEmitPoint, QgsVertexMarker
from qgis.PyQt.QtCore import Qt, pyqtSignal
from qgis.PyQt.QtGui import QColor


class GcpMapTool(QgsMapToolEmitPoint):
    """Emits ``picked(QgsPointXY)`` in the canvas CRS on a left click; Escape gives the tool up."""

    picked = pyqtSignal(QgsPointXY)
    escaped = pyqtSignal()

    def __init__(self, canvas):
        super().__init__(canvas)
        self.setCursor(Qt.CursorShape.CrossCursor)

    def canvasReleaseEvent(self, event):  # noqa: N802 (Qt API name)
        if event.button() != Qt.MouseButton.LeftButton:
            return
        point = event.snapPoint() if hasattr(event, "snapPoint") else event.mapPoint()
        self.picked.emit(QgsPointXY(point))

    def keyPressEvent(self, event):  # noqa: N802 (Qt API name)
        if event.key() == Qt.Key.Key_Escape:
            self.escaped.emit()
            event.accept()
            return
        super().keyPressEvent(event)


class GcpMarkers:
    """Vertex markers for the GCPs on a canvas; the selected one is larger and red."""

    def __init__(self, canvas):
        self.canvas = canvas
        self.markers = {}

    def clear(self):
        for m in self.markers.values():
            self.canvas.scene().removeItem(m)
        self.markers = {}

    def update(self, points, selected=None):
        """``points``: {name: QgsPointXY in the canvas CRS}."""
        self.clear()
        for name, p in points.items():
            m = QgsVertexMarker(self.canvas)
            m.setCenter(p)
            icons = QgsVertexMarker.IconType
            m.setIconType(icons.ICON_CROSS if name != selected else icons.ICON_CIRCLE)
            m.setColor(QColor("#d7191c") if name == selected else QColor("#2b83ba"))
            m.setIconSize(16 if name == selected else 10)
            m.setPenWidth(3 if name == selected else 2)
            m.setToolTip(name)
            self.markers[name] = m
