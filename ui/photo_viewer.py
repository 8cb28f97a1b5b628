"""Photo viewer of the GCP dock: a zoomable, pannable photo on an image pyramid cut into tiles.

Scene coordinates are pixel coordinates of the photo shown UPRIGHT, as photo viewers and browsers show it
(turned by its EXIF orientation; core.io.images), in the convention of core.gcp (origin at the upper-left corner
of the upper-left pixel, x right, y down).  Observations are stored in the stored pixel grid (COLMAP's): the
panel draws them at their upright positions and maps a click back to the stored grid (exact: a quarter turn
or a mirror), with the precision of one screen pixel at the current zoom (sub-pixel when zoomed in).

The photo is decoded once per visit; its pyramid levels (1, 1/2, 1/4, ...) are built from that decode
and cut into tiles on first use, and a repaint draws only the tiles of the level that matches the zoom
inside the exposed area: smooth on 20-megapixel photos.

Mouse and keys: wheel zooms about the cursor; a left click places the observation of the selected GCP
(a second click moves it); dragging a marker moves it; dragging the background, or the middle / right
button, pans; Delete / Backspace removes the observation; Space confirms the prediction, Enter confirms it and
shows the next photo to place; F fits the photo, Z zooms to the GCP.
"""
import math
from collections import OrderedDict

from qgis.PyQt.QtCore import QPointF, QRectF, QSize, Qt, QTimer, pyqtSignal
from qgis.PyQt.QtGui import QBrush, QColor, QFont, QIcon, QImage, QImageReader, QPainter, QPen, QPixmap, QTransform
from qgis.PyQt.QtWidgets import (
    QCheckBox,
    QGraphicsItem,
    QGraphicsObject,
    QGraphicsScene,
    QGraphicsView,
    QHBoxLayout,
    QLabel,
    QListView,
    QListWidget,
    QListWidgetItem,
    QSizePolicy,
    QSplitter,
    QStyleOptionGraphicsItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.io.images import ORIENTATION_STEPS, ImageError, exif_orientation, stored_to_upright, upright_to_stored

TILE = 512
THUMB = QSize(120, 80)


def photo_orientation(path):
    """The EXIF orientation of a photo (1 when it has none or cannot be read)."""
    try:
        return exif_orientation(path)
    except ImageError:
        return 1


def upright_qimage(image, orientation):
    """The stored QImage turned upright, as a photo viewer shows it: the steps of
    core.io.images.ORIENTATION_STEPS (a clockwise turn, then mirrors), so that display and coordinates agree."""
    turn, mirror_lr, mirror_tb = ORIENTATION_STEPS.get(orientation, (0, False, False))
    if turn:
        image = image.transformed(QTransform().rotate(turn))
    if mirror_lr or mirror_tb:
        image = image.mirrored(mirror_lr, mirror_tb)
    return image


class ImagePyramid:
    """Levels 0 (full size), 1 (half), ... of one photo, cut into TILE x TILE pixmaps on demand."""

    def __init__(self, path, max_cached_tiles=256, orientation=None):
        reader = QImageReader(path)
        reader.setAutoTransform(False)  # the stored raster (COLMAP's grid), turned upright below by our own rule
        image = reader.read()
        if image.isNull():
            raise OSError(f"cannot read {path}: {reader.errorString()}")
        if image.format() not in (QImage.Format.Format_RGB32, QImage.Format.Format_ARGB32,
                                  QImage.Format.Format_ARGB32_Premultiplied):
            image = image.convertToFormat(QImage.Format.Format_RGB32)
        self.path = path
        self.stored_width, self.stored_height = image.width(), image.height()
        self.orientation = photo_orientation(path) if orientation is None else int(orientation)
        image = upright_qimage(image, self.orientation)
        self.width, self.height = image.width(), image.height()  # upright: the scene's size
        self.levels = [image]
        while max(self.levels[-1].width(), self.levels[-1].height()) > TILE:
            prev = self.levels[-1]
            self.levels.append(prev.scaled(max(1, prev.width() // 2), max(1, prev.height() // 2),
                                           Qt.AspectRatioMode.IgnoreAspectRatio,
                                           Qt.TransformationMode.SmoothTransformation))
        self._tiles = OrderedDict()
        self._max = max_cached_tiles
        self.tiles_made = 0

    def to_scene(self, x, y):
        """Scene (upright) coordinates of stored pixel coordinates."""
        return stored_to_upright(x, y, self.orientation, self.stored_width, self.stored_height)

    def to_stored(self, x, y):
        """Stored pixel coordinates of scene (upright) ones."""
        return upright_to_stored(x, y, self.orientation, self.stored_width, self.stored_height)

    def level_for(self, lod):
        """The coarsest level that still has at least one image pixel per screen pixel at ``lod``."""
        if lod <= 0:
            return len(self.levels) - 1
        k = int(math.floor(math.log2(1.0 / lod))) if lod < 1.0 else 0
        return min(max(k, 0), len(self.levels) - 1)

    def scale(self, level):
        """Full-resolution pixels per pixel of ``level`` (x, y)."""
        im = self.levels[level]
        return self.width / im.width(), self.height / im.height()

    def tile(self, level, tx, ty):
        key = (level, tx, ty)
        pm = self._tiles.get(key)
        if pm is not None:
            self._tiles.move_to_end(key)
            return pm
        im = self.levels[level]
        pm = QPixmap.fromImage(im.copy(tx * TILE, ty * TILE, min(TILE, im.width() - tx * TILE),
                                       min(TILE, im.height() - ty * TILE)))
        self._tiles[key] = pm
        self.tiles_made += 1
        while len(self._tiles) > self._max:
            self._tiles.popitem(last=False)
        return pm

    def thumbnail(self, size=THUMB):
        return QPixmap.fromImage(self.levels[-1].scaled(size, Qt.AspectRatioMode.KeepAspectRatio,
                                                        Qt.TransformationMode.SmoothTransformation))


def read_thumbnail(path, size=THUMB):
    """A small pixmap of a photo, upright, decoded at reduced size where the format allows (JPEG)."""
    reader = QImageReader(path)
    reader.setAutoTransform(False)
    orientation = photo_orientation(path)
    turned = ORIENTATION_STEPS.get(orientation, (0,))[0] in (90, 270)
    full = reader.size()
    if full.isValid():
        upright = full.transposed() if turned else full
        small = upright.scaled(size, Qt.AspectRatioMode.KeepAspectRatio)
        reader.setScaledSize(small.transposed() if turned else small)
    image = reader.read()
    if image.isNull():
        pm = QPixmap(size)
        pm.fill(QColor("#606060"))
        return pm
    return QPixmap.fromImage(upright_qimage(image, orientation))


class ThumbStrip(QListWidget):
    """A one-row strip of thumbnails that only ever scrolls sideways."""

    def scrollTo(self, index, hint=QListWidget.ScrollHint.EnsureVisible):  # noqa: N802 (Qt API name)
        super().scrollTo(index, hint)
        self.verticalScrollBar().setValue(0)

    def resizeEvent(self, event):  # noqa: N802 (Qt API name)
        super().resizeEvent(event)
        self.verticalScrollBar().setValue(0)


class PyramidItem(QGraphicsItem):
    """Draws the tiles of the pyramid level that fits the view's zoom, only inside the exposed area."""

    def __init__(self, pyramid):
        super().__init__()
        self.pyramid = pyramid
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemUsesExtendedStyleOption, True)
        self.setZValue(-1)
        self.last_level = None

    def boundingRect(self):  # noqa: N802 (Qt API name)
        return QRectF(0, 0, self.pyramid.width, self.pyramid.height)

    def paint(self, painter, option, widget=None):
        lod = QStyleOptionGraphicsItem.levelOfDetailFromTransform(painter.worldTransform())
        level = self.pyramid.level_for(lod)
        self.last_level = level
        sx, sy = self.pyramid.scale(level)
        im = self.pyramid.levels[level]
        exposed = option.exposedRect.intersected(self.boundingRect())
        if exposed.isEmpty():
            return
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, lod < 1.0)
        x0 = max(int(exposed.left() / sx) // TILE, 0)
        y0 = max(int(exposed.top() / sy) // TILE, 0)
        x1 = min(int(math.ceil(exposed.right() / sx)) // TILE, (im.width() - 1) // TILE)
        y1 = min(int(math.ceil(exposed.bottom() / sy)) // TILE, (im.height() - 1) // TILE)
        for ty in range(y0, y1 + 1):
            for tx in range(x0, x1 + 1):
                pm = self.pyramid.tile(level, tx, ty)
                target = QRectF(tx * TILE * sx, ty * TILE * sy, pm.width() * sx, pm.height() * sy)
                painter.drawPixmap(target, pm, QRectF(pm.rect()))


class MarkerItem(QGraphicsObject):
    """A GCP observation (solid cross) or prediction (dashed circle); constant size on screen, draggable."""

    moved = pyqtSignal(QPointF)
    activated = pyqtSignal()

    def __init__(self, label, predicted=False, colour="#ff2a2a"):
        super().__init__()
        self.label = label
        self.predicted = predicted
        self.colour = QColor(colour)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsMovable, True)
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemSendsGeometryChanges, True)
        self.setCursor(Qt.CursorShape.SizeAllCursor)
        self.setZValue(10)
        self._press = None

    def boundingRect(self):  # noqa: N802 (Qt API name)
        return QRectF(-16, -16, 120, 32)

    def shape(self):
        from qgis.PyQt.QtGui import QPainterPath

        path = QPainterPath()
        path.addEllipse(QRectF(-12, -12, 24, 24))
        return path

    def paint(self, painter, option, widget=None):
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        halo = QPen(QColor(255, 255, 255, 200), 4)
        pen = QPen(self.colour, 2, Qt.PenStyle.DashLine if self.predicted else Qt.PenStyle.SolidLine)
        for p in (halo, pen):
            painter.setPen(p)
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawEllipse(QRectF(-10, -10, 20, 20))
            if not self.predicted:
                painter.drawLine(QPointF(-14, 0), QPointF(-3, 0))
                painter.drawLine(QPointF(3, 0), QPointF(14, 0))
                painter.drawLine(QPointF(0, -14), QPointF(0, -3))
                painter.drawLine(QPointF(0, 3), QPointF(0, 14))
        painter.setPen(QPen(self.colour, 1))
        painter.setBrush(QBrush(self.colour))
        painter.drawEllipse(QRectF(-1.2, -1.2, 2.4, 2.4))
        font = QFont()
        font.setPointSizeF(9)
        font.setBold(True)
        painter.setFont(font)
        painter.setPen(QPen(QColor("white"), 3))
        painter.drawText(QPointF(14, -6), self.label)
        painter.setPen(QPen(self.colour, 1))
        painter.drawText(QPointF(14, -6), self.label)

    def mousePressEvent(self, event):  # noqa: N802 (Qt API name)
        self._press = QPointF(self.pos())
        super().mousePressEvent(event)

    def mouseReleaseEvent(self, event):  # noqa: N802 (Qt API name)
        super().mouseReleaseEvent(event)
        if self._press is not None and (self.pos() - self._press).manhattanLength() > 1e-9:
            pos = QPointF(self.pos())
            # later: the receiver may replace this very item, which must not die inside its own handler
            QTimer.singleShot(0, lambda: self.moved.emit(pos))
        self._press = None

    def mouseDoubleClickEvent(self, event):  # noqa: N802 (Qt API name)
        QTimer.singleShot(0, self.activated.emit)
        event.accept()


class PhotoView(QGraphicsView):
    """The zoomable, pannable view.  Signals carry scene (= pixel) coordinates."""

    clicked = pyqtSignal(QPointF)
    deleteRequested = pyqtSignal()  # noqa: N815 (Qt signal naming)
    confirmRequested = pyqtSignal()  # noqa: N815
    nextRequested = pyqtSignal()  # noqa: N815
    zoomToPointRequested = pyqtSignal()  # noqa: N815

    MIN_SCALE = 1.0 / 64
    MAX_SCALE = 64.0

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.AnchorUnderMouse)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.SmartViewportUpdate)
        self.setBackgroundBrush(QBrush(QColor("#2b2b2b")))
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(True)
        self.pyramid_item = None
        self._press_pos = None
        self._pan_from = None
        self._panning = False
        self._fit_mode = True  # refit when the view is resized, until the user zooms or pans

    # --- content
    def set_pyramid(self, pyramid):
        if self.pyramid_item is not None:
            self.scene().removeItem(self.pyramid_item)
            self.pyramid_item = None
        if pyramid is None:
            return
        self.pyramid_item = PyramidItem(pyramid)
        self.scene().addItem(self.pyramid_item)
        w, h = pyramid.width, pyramid.height
        self.scene().setSceneRect(QRectF(-0.25 * w, -0.25 * h, 1.5 * w, 1.5 * h))

    def zoom(self):
        return self.transform().m11()

    def fit(self):
        self._fit_mode = True
        if self.pyramid_item is not None:
            self.fitInView(self.pyramid_item.boundingRect(), Qt.AspectRatioMode.KeepAspectRatio)

    def resizeEvent(self, event):  # noqa: N802 (Qt API name)
        super().resizeEvent(event)
        if self._fit_mode:
            self.fit()

    def set_zoom(self, scale, centre=None):
        self._fit_mode = False
        scale = min(max(scale, self.MIN_SCALE), self.MAX_SCALE)
        self.resetTransform()
        self.scale(scale, scale)
        if centre is not None:
            self.centerOn(centre)

    def scene_pos(self, widget_pos):
        """Scene (= pixel) coordinates of a viewport position: the centre of the screen pixel clicked."""
        inv, _ = self.viewportTransform().inverted()
        return inv.map(QPointF(widget_pos) + QPointF(0.5, 0.5))

    # --- mouse
    def wheelEvent(self, event):  # noqa: N802 (Qt API name)
        steps = event.angleDelta().y() / 120.0
        if steps == 0:
            return
        factor = 1.25 ** steps
        new = self.zoom() * factor
        if not (self.MIN_SCALE <= new <= self.MAX_SCALE):
            return
        self._fit_mode = False
        self.scale(factor, factor)
        event.accept()

    def _marker_at(self, pos):
        for item in self.items(pos):
            if isinstance(item, MarkerItem):
                return item
        return None

    def mousePressEvent(self, event):  # noqa: N802 (Qt API name)
        self.setFocus()
        if event.button() in (Qt.MouseButton.MiddleButton, Qt.MouseButton.RightButton):
            self._pan_from = event.pos()
            self._panning = True
            event.accept()
            return
        if event.button() == Qt.MouseButton.LeftButton and self._marker_at(event.pos()) is None:
            self._press_pos = event.pos()
            self._pan_from = event.pos()
            self._panning = False
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event):  # noqa: N802 (Qt API name)
        if self._pan_from is not None:
            if self._press_pos is not None and (event.pos() - self._press_pos).manhattanLength() > 4:
                self._panning = True
            if self._panning:
                self._fit_mode = False
                delta = event.pos() - self._pan_from
                self._pan_from = event.pos()
                self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() - delta.x())
                self.verticalScrollBar().setValue(self.verticalScrollBar().value() - delta.y())
                event.accept()
                return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event):  # noqa: N802 (Qt API name)
        if self._pan_from is not None:
            click = self._press_pos is not None and not self._panning and event.button() == Qt.MouseButton.LeftButton
            self._pan_from = None
            self._press_pos = None
            self._panning = False
            if click and self.pyramid_item is not None:
                p = self.scene_pos(event.localPos() if hasattr(event, "localPos") else event.pos())
                if self.pyramid_item.boundingRect().contains(p):
                    self.clicked.emit(p)
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def keyPressEvent(self, event):  # noqa: N802 (Qt API name)
        key = event.key()
        if key in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
            self.deleteRequested.emit()
        elif key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.nextRequested.emit()
        elif key == Qt.Key.Key_Space:
            self.confirmRequested.emit()
        elif key in (Qt.Key.Key_Plus, Qt.Key.Key_Equal):
            self._fit_mode = False
            self.scale(1.25, 1.25)
        elif key == Qt.Key.Key_Minus:
            self._fit_mode = False
            self.scale(0.8, 0.8)
        elif key == Qt.Key.Key_F:
            self.fit()
        elif key == Qt.Key.Key_Z:
            self.zoomToPointRequested.emit()
        else:
            super().keyPressEvent(event)
            return
        event.accept()


class PhotoPanel(QWidget):
    """Photo view + thumbnails strip + a small toolbar.  Knows nothing about GCP storage: the dock
    feeds it (``show_photo``, ``set_markers``, ``set_thumbnails``) and listens to its signals."""

    photoSelected = pyqtSignal(str)  # noqa: N815 - image name
    placed = pyqtSignal(str, float, float)  # image, x, y: a click or a drag placed the observation
    removeRequested = pyqtSignal(str)  # noqa: N815 - image
    confirmRequested = pyqtSignal(str)  # noqa: N815 - image: accept the prediction
    nextRequested = pyqtSignal()  # noqa: N815 - confirm and go on to the next photo
    filterChanged = pyqtSignal(bool)  # noqa: N815

    def __init__(self, parent=None):
        super().__init__(parent)
        self.image = None  # name of the photo shown
        self.paths = {}  # image name -> path
        self._pyramids = OrderedDict()
        self._thumbs = {}
        self._thumb_queue = []
        self._thumb_timer = QTimer(self)
        self._thumb_timer.setInterval(0)
        self._thumb_timer.timeout.connect(self._load_some_thumbs)
        self.observation = None
        self.prediction = None
        self.point_name = ""

        self.title = QLabel()
        self.title.setTextFormat(Qt.TextFormat.RichText)
        self.hint = QLabel()
        self.orientation_note = QLabel()  # says when the photo is shown turned from its stored grid
        self.orientation_note.setWordWrap(True)
        self.orientation_note.setVisible(False)
        self.found_info = None  # (point, image) -> (tooltip, note) of an observation found by Find targets, or None
        self.found_note = QLabel()  # says that the observation shown was found by Find targets, and the keys
        self.found_note.setWordWrap(True)
        self.found_note.setStyleSheet("color: #1f6fd1")
        self.found_note.setVisible(False)
        self.hint.setWordWrap(True)
        self.view = PhotoView(self)
        self.thumbs = ThumbStrip(self)
        self.thumbs.setViewMode(QListView.ViewMode.IconMode)
        self.thumbs.setFlow(QListView.Flow.LeftToRight)
        self.thumbs.setWrapping(False)
        self.thumbs.setMovement(QListView.Movement.Static)
        self.thumbs.setIconSize(THUMB)
        self.thumbs.setGridSize(QSize(THUMB.width() + 20, THUMB.height() + 42))
        self.thumbs.setUniformItemSizes(True)
        self.thumbs.setWordWrap(True)
        self.thumbs.setTextElideMode(Qt.TextElideMode.ElideMiddle)
        self.thumbs.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.thumbs.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOn)
        self.thumbs.currentItemChanged.connect(self._thumb_changed)

        self.filter_box = QCheckBox(self.tr("Only photos that probably see the point"))
        self.filter_box.setChecked(True)
        self.filter_box.toggled.connect(self.filterChanged)
        self.btn_fit = self._button(self.tr("Fit"), self.tr("Show the whole photo (F)"), self.view.fit)
        self.btn_zoom = self._button(self.tr("Zoom to point"), self.tr("Zoom to the observation or prediction (Z)"),
                                     self.zoom_to_point)
        self.btn_confirm = self._button(self.tr("Confirm"), self.tr("Accept the predicted position (Space)"),
                                        self._confirm)
        self.btn_next = self._button(self.tr("Confirm && next"),
                                     self.tr("Accept the prediction and show the next photo to place (Enter)"),
                                     self.nextRequested)
        self.btn_remove = self._button(self.tr("Remove"), self.tr("Remove the observation in this photo (Delete)"),
                                       self._remove)

        # two rows of buttons: the panel fits the right dock column under the GCP dock (issue 48 item 7; German
        # labels in one row made it 743 px wide)
        bar, bar2 = QHBoxLayout(), QHBoxLayout()
        for w in (self.btn_fit, self.btn_zoom, self.btn_remove):
            bar.addWidget(w)
        for w in (self.btn_confirm, self.btn_next):
            bar2.addWidget(w)
        bar.addStretch(1)
        bar2.addStretch(1)
        heading = QHBoxLayout()  # the filter beside the title, not after the buttons: the dock fits a 1366 px screen
        self.title.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        heading.addWidget(self.title, 1)
        heading.addWidget(self.filter_box)
        top = QWidget()
        tl = QVBoxLayout(top)
        tl.setContentsMargins(0, 0, 0, 0)
        tl.addLayout(heading)
        tl.addLayout(bar)
        tl.addLayout(bar2)
        tl.addWidget(self.view, 1)
        tl.addWidget(self.orientation_note)
        tl.addWidget(self.found_note)
        tl.addWidget(self.hint)
        # the photo over the thumbnails, the line between them dragged: the strip folds away to give the photo room
        self.thumbs.setMinimumHeight(1)  # (0 would mean its minimum size hint: the strip could not fold)
        self.thumbs.setMaximumHeight(THUMB.height() + 66)
        self.splitter = QSplitter(Qt.Orientation.Vertical, self)
        self.splitter.addWidget(top)
        self.splitter.addWidget(self.thumbs)
        self.splitter.setStretchFactor(0, 1)
        self.splitter.setStretchFactor(1, 0)
        self.splitter.setCollapsible(0, False)
        self.splitter.setCollapsible(1, True)
        self.splitter.setSizes([10 ** 6, THUMB.height() + 66])
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.splitter, 1)

        self.view.clicked.connect(self._clicked)
        self.view.deleteRequested.connect(self._remove)
        self.view.confirmRequested.connect(self._confirm)
        self.view.nextRequested.connect(self._next)
        self.view.zoomToPointRequested.connect(self.zoom_to_point)
        self._update_buttons()

    def tr(self, text):
        from qgis.PyQt.QtCore import QCoreApplication

        return QCoreApplication.translate("PhotoPanel", text)

    def _button(self, text, tip, slot):
        b = QToolButton(self)
        b.setText(text)
        b.setToolTip(tip)
        b.setAutoRaise(False)
        b.clicked.connect(slot)
        return b

    # --- photos
    def set_photos(self, paths):
        """{image name: path} of the block, in display order."""
        self.paths = dict(paths)
        self._pyramids.clear()
        self._thumbs = {}
        self.thumbs.clear()
        if self.image not in self.paths:
            self.image = None
            self.view.set_pyramid(None)

    def pyramid(self, name):
        pyr = self._pyramids.get(name)
        if pyr is None:
            pyr = ImagePyramid(self.paths[name])
            self._pyramids[name] = pyr
            while len(self._pyramids) > 3:
                self._pyramids.popitem(last=False)
        else:
            self._pyramids.move_to_end(name)
        return pyr

    def show_photo(self, name, keep_view=False):
        """Show a photo (decoded once, kept in a small cache).  Returns False when it cannot be read."""
        if name not in self.paths:
            return False
        if name == self.image and self.view.pyramid_item is not None:
            return True
        try:
            pyr = self.pyramid(name)
        except OSError as e:
            self.hint.setText(str(e))
            return False
        old = self.view.zoom() if keep_view and self.view.pyramid_item is not None else None
        self.image = name
        self.view.set_pyramid(pyr)
        if old is None:
            self.view.fit()
        self._show_orientation(pyr)
        self._select_thumb(name)
        return True

    def _show_orientation(self, pyr):
        turned = pyr.orientation != 1
        if turned:
            self.orientation_note.setText(self.tr(
                "Shown upright (EXIF orientation {}: stored {} x {} px); pixel coordinates are those of the stored "
                "grid, as COLMAP and gcp_list.txt use them").format(pyr.orientation, pyr.stored_width,
                                                                     pyr.stored_height))
        self.orientation_note.setVisible(turned)

    def set_thumbnails(self, names, marks=None):
        """Show ``names`` in the strip; ``marks``: {name: text} shown under the picture (e.g. a tick)."""
        marks = marks or {}
        self.thumbs.blockSignals(True)
        self.thumbs.clear()
        self._thumb_queue = []
        for n in names:
            item = QListWidgetItem(n + (f"\n{marks[n]}" if marks.get(n) else ""))
            item.setData(Qt.ItemDataRole.UserRole, n)
            item.setToolTip(n)
            item.setTextAlignment(Qt.AlignmentFlag.AlignHCenter)
            if n in self._thumbs:
                item.setIcon(self._thumbs[n])
            else:
                item.setIcon(self._placeholder())  # full-size item from the start (uniform item sizes)
                self._thumb_queue.append(n)
            self.thumbs.addItem(item)
        self.thumbs.blockSignals(False)
        self._select_thumb(self.image)
        if self._thumb_queue:
            self._thumb_timer.start()

    def _placeholder(self):
        if getattr(self, "_blank", None) is None:
            pm = QPixmap(THUMB)
            pm.fill(QColor("#505050"))
            self._blank = QIcon(pm)
        return self._blank

    def thumbnail_names(self):
        return [self.thumbs.item(i).data(Qt.ItemDataRole.UserRole) for i in range(self.thumbs.count())]

    def _load_some_thumbs(self, count=4):
        for _ in range(count):
            if not self._thumb_queue:
                self._thumb_timer.stop()
                return
            n = self._thumb_queue.pop(0)
            if n not in self.paths:
                continue
            icon = QIcon(read_thumbnail(self.paths[n]))
            self._thumbs[n] = icon
            for i in range(self.thumbs.count()):
                it = self.thumbs.item(i)
                if it.data(Qt.ItemDataRole.UserRole) == n:
                    it.setIcon(icon)

    def load_all_thumbnails(self):
        while self._thumb_queue:
            self._load_some_thumbs(len(self._thumb_queue))

    def _select_thumb(self, name):
        self.thumbs.blockSignals(True)
        for i in range(self.thumbs.count()):
            if self.thumbs.item(i).data(Qt.ItemDataRole.UserRole) == name:
                self.thumbs.setCurrentRow(i)
                self.thumbs.scrollToItem(self.thumbs.item(i))
                break
        else:
            self.thumbs.setCurrentRow(-1)
        self.thumbs.blockSignals(False)

    def _thumb_changed(self, current, previous):
        del previous
        if current is not None:
            self.photoSelected.emit(current.data(Qt.ItemDataRole.UserRole))

    # --- markers
    def set_markers(self, point_name, observation=None, prediction=None, prediction_source=""):
        """Show the selected point's observation (x, y) and/or prediction (x, y) in the current photo."""
        scene = self.view.scene()
        for item in (self.observation, self.prediction):
            if item is not None:
                scene.removeItem(item)
        self.observation = self.prediction = None
        self.point_name = point_name or ""
        found = self.found_info(point_name, self.image) if point_name and observation is not None \
            and self.found_info is not None else None
        self.found_note.setText(found[1] if found else "")
        self.found_note.setVisible(bool(found))
        if point_name and observation is not None:
            self.observation = MarkerItem(point_name, predicted=False, colour="#1f6fd1" if found else "#ff2a2a")
            if found:
                self.observation.setToolTip(found[0])
            self.observation.setPos(self._scene_point(observation))
            self.observation.moved.connect(self._marker_moved)
            scene.addItem(self.observation)
        if point_name and prediction is not None and observation is None:
            label = self.tr("{} (predicted)").format(point_name)
            self.prediction = MarkerItem(label, predicted=True, colour="#ffb000")
            self.prediction.setPos(self._scene_point(prediction))
            self.prediction.moved.connect(self._marker_moved)
            self.prediction.activated.connect(self._confirm)
            if prediction_source:
                self.prediction.setToolTip(prediction_source)
            scene.addItem(self.prediction)
        self._update_buttons()

    def _update_buttons(self):
        self.btn_confirm.setEnabled(self.prediction is not None or self.found_note.isVisibleTo(self))
        self.btn_next.setEnabled(self.prediction is not None or getattr(self, "_has_next", False))
        self.btn_remove.setEnabled(self.observation is not None)
        self.btn_zoom.setEnabled(self.observation is not None or self.prediction is not None)

    def zoom_to_point(self, scale=None):
        item = self.observation or self.prediction
        if item is None or self.view.pyramid_item is None:
            return
        if scale is None:
            scale = max(self.view.zoom(), 2.0)
        self.view.set_zoom(scale, item.pos())

    def _scene_point(self, xy):
        """The scene (upright) position of stored pixel coordinates in the photo shown."""
        item = self.view.pyramid_item
        return QPointF(*(item.pyramid.to_scene(*xy) if item is not None else xy))

    def _stored(self, pos):
        """Stored pixel coordinates (x, y) of a scene position in the photo shown."""
        item = self.view.pyramid_item
        return item.pyramid.to_stored(pos.x(), pos.y()) if item is not None else (pos.x(), pos.y())

    # --- user actions -> signals (in stored pixel coordinates)
    def _clicked(self, pos):
        if self.image and self.point_name:
            self.placed.emit(self.image, *self._stored(pos))

    def _marker_moved(self, pos):
        if self.image and self.point_name:
            self.placed.emit(self.image, *self._stored(pos))

    def _remove(self):
        if self.image and self.observation is not None:
            self.removeRequested.emit(self.image)

    def _confirm(self):
        if self.image and (self.prediction is not None or self.found_note.isVisibleTo(self)):  # a found observation
            self.confirmRequested.emit(self.image)

    def _next(self):
        if self.btn_next.isEnabled():
            self.nextRequested.emit()

    def set_next_available(self, available):
        """Whether 'Confirm & next' has somewhere to go (the dock knows the photos still to place)."""
        self._has_next = bool(available)
        self._update_buttons()
