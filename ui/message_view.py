"""Bounded message areas for the GCP dock (issue 36 items 19, 20).

``MessageView``: a read-only text area for the dock's status line.  A message of any length is wrapped at word
boundaries, a path with no space anywhere, so it never widens the dock; it takes the height of its text up to
``max_lines`` lines and scrolls beyond them, so a long error (a failed automatic control names files, reasons
and counts) neither runs off the dock nor squeezes the GCP table.  ``text()`` / ``setText()`` as a QLabel's;
``rich``: the text is HTML (the adjustment's diagnosis).

``FitScrollArea``: the dock's body in a scroll area that is as wide as the body needs (its toolbars never go
into an overflow) but can be made shorter than the body: on a small screen, or with the Processing Toolbox and
Results Viewer docked beside it, the dock scrolls instead of making the main window taller than the screen.
"""
from qgis.gui import QgsScrollArea
from qgis.PyQt.QtCore import QSize, Qt
from qgis.PyQt.QtGui import QTextCursor, QTextOption
from qgis.PyQt.QtWidgets import QFrame, QSizePolicy, QTextBrowser


class MessageView(QTextBrowser):
    """A message in a few wrapped lines: as tall as its text, at most ``max_lines``, then a scroll bar."""

    def __init__(self, parent=None, max_lines=5, min_lines=2, rich=False):
        super().__init__(parent)
        self.max_lines, self.min_lines, self.rich = max_lines, min_lines, rich
        self.setReadOnly(True)
        self.setOpenLinks(False)
        self.setFrameShape(QFrame.Shape.NoFrame)
        self.setWordWrapMode(QTextOption.WrapMode.WrapAtWordBoundaryOrAnywhere)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAsNeeded)
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Maximum)
        self.viewport().setAutoFillBackground(False)
        self.setStyleSheet("QTextBrowser { background: transparent; }")
        self.document().setDocumentMargin(1)
        self._text = ""
        self._width = -1

    def setText(self, text):  # noqa: N802 (QLabel's name)
        self._text = str(text or "")
        if self.rich:
            self.setHtml(self._text)
        else:
            self.setPlainText(self._text)
        self.moveCursor(QTextCursor.MoveOperation.Start)  # its first line in view, whatever the height
        self.verticalScrollBar().setValue(0)
        self.setVisible(bool(self._text))
        self.updateGeometry()

    def text(self):
        """What was set (plain text, or the rich text as given)."""
        return self._text

    def _line(self):
        return self.fontMetrics().lineSpacing()

    def _frame(self):
        return 2 * self.frameWidth() + 2 * int(self.document().documentMargin()) + 2

    def _content_height(self):
        doc = self.document()
        width = self.viewport().width()
        if width > 0:
            doc.setTextWidth(width)
        return int(doc.size().height() + 0.5)

    def sizeHint(self):  # noqa: N802 (Qt API name)
        height = min(self._content_height(), self.max_lines * self._line()) if self._text else 0
        return QSize(super().sizeHint().width(), height + self._frame())

    def minimumSizeHint(self):  # noqa: N802 (Qt API name)
        height = min(self._content_height(), self.min_lines * self._line()) if self._text else 0
        return QSize(0, height + self._frame())

    def resizeEvent(self, event):  # noqa: N802 (Qt API name)
        super().resizeEvent(event)
        if event.size().width() != self._width:  # another width: another number of lines
            self._width = event.size().width()
            self.updateGeometry()


class FitScrollArea(QgsScrollArea):
    """A vertical scroll area as wide as its widget needs and at least ``min_height`` tall."""

    def __init__(self, parent=None, min_height=150):
        super().__init__(parent)
        self.min_height = min_height
        self.setWidgetResizable(True)
        self.setFrameShape(QFrame.Shape.NoFrame)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)

    def _extra_width(self):
        return self.verticalScrollBar().sizeHint().width() + 2 * self.frameWidth()

    def minimumSizeHint(self):  # noqa: N802 (Qt API name)
        w = self.widget()
        width = w.minimumSizeHint().width() if w is not None else 0
        return QSize(width + self._extra_width(), self.min_height)

    def sizeHint(self):  # noqa: N802 (Qt API name)
        w = self.widget()
        hint = w.sizeHint() if w is not None else QSize(0, self.min_height)
        return QSize(hint.width() + self._extra_width(), max(hint.height(), self.min_height))
