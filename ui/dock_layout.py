"""Where the GCP dock and its photo dock go when first shown, and their sizes (issue 48 item 7).

On a 1366 x 768 screen the photo dock at the bottom left the map 145 px tall, and the GCP dock stacked under the
Processing Toolbox left the Toolbox's list a few rows.  Now each dock has a side column's full height, and the map
the window's full height between the toolbars and the status bar:

* the GCP dock goes to the right, a tab beside the docks already shown there (the Toolbox, the Results Viewer),
  raised: each of them has the column's height when its tab is up;
* the photo dock goes to the left, a tab beside the Layers and Browser panels, raised, ``PHOTO_SHARE`` of the
  window wide (at least its own minimum); its width is dragged at the separator, and it is closed (collapsed)
  with its title bar's button and brought back from View > Panels or the plugin's button, giving the map the room;
* the GCP dock is as wide as its key columns need (its size hint).
"""
from qgis.PyQt.QtCore import Qt, QTimer
from qgis.PyQt.QtWidgets import QDockWidget

RIGHT = Qt.DockWidgetArea.RightDockWidgetArea
LEFT = Qt.DockWidgetArea.LeftDockWidgetArea
PHOTO_SHARE = 0.3  # the photo column's width: this share of the window's (a 1366 px window: 410 px)


def _shown_in(main, area, skip):
    return [w for w in main.findChildren(QDockWidget)
            if w not in skip and w.isVisible() and not w.isFloating() and main.dockWidgetArea(w) == area]


def _add_tabbed(main, area, dock, add, skip):
    """``dock`` in ``area``, in one tab group with the docks shown there (so each has the column's height),
    raised."""
    others = _shown_in(main, area, skip)
    add(area, dock)
    for w in (others[1:] + [dock]) if others else []:
        main.tabifyDockWidget(others[0], w)
    dock.show()
    dock.raise_()


def place_docks(main, dock, photo_dock, add=None):
    """Add ``dock`` to the right and ``photo_dock`` to the left area of the main window ``main``, each a raised
    tab beside the docks there; ``add(area, widget)``: how to add a dock (QGIS's iface.addDockWidget; default
    the main window's)."""
    add = add or main.addDockWidget
    _add_tabbed(main, RIGHT, dock, add, (dock, photo_dock))
    _add_tabbed(main, LEFT, photo_dock, add, (dock, photo_dock))
    default_sizes(main, dock, photo_dock)
    QTimer.singleShot(0, lambda: default_sizes(main, dock, photo_dock))  # again once the window has laid them out


def default_sizes(main, dock, photo_dock):
    """The GCP dock at its size hint's width, the photo column PHOTO_SHARE of the window."""
    if not hasattr(main, "resizeDocks"):
        return
    photo = max(int(main.width() * PHOTO_SHARE), photo_dock.minimumSizeHint().width())
    main.resizeDocks([dock, photo_dock], [dock.sizeHint().width(), photo], Qt.Orientation.Horizontal)
