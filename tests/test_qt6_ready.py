"""QGIS 4 / Qt6 readiness of the plugin's Qt faces (ui/, processing_provider/, plugin.py), by the rules of QGIS's
migration script scripts/pyqt5_to_pyqt6/pyqt5_to_pyqt6.py:

- an unscoped enum access: an attribute ``Name.member`` (not itself the head of a longer attribute chain) where
  ``Name`` is a Qt/QGIS class and ``member`` is a value of one of its enums.  PyQt6 only knows
  ``Name.Enum.member``.  The script derives the pairs from PyQt6's enums; here PyQt5 5.15 / QGIS 3.22 answer the
  same question: ``getattr(Name, member)`` is an enum value whose type's name is not ``Name``.  (Checked against
  the pairs derived from PyQt6 6.11: the same 58 references in ui/ and plugin.py before they were scoped.)
  The scoped form must also resolve on this machine, so the fix works on QGIS 3.22 too;
- a PyQt5-only import: ``from PyQt5.X import`` / ``import PyQt5`` (use qgis.PyQt), a class imported from the
  module it left in Qt6 (QtWidgets -> QtGui) other than as the fallback of a ``try`` that imports it from QtGui,
  or a class Qt6's QtCore/QtGui/QtWidgets no longer have;
- ``exec_()`` (the script renames it to ``exec()``, which PyQt5 5.15 has too).
"""
import ast
import enum
import glob
import importlib
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Derived once from PyQt6 6.11.0 against PyQt5 5.15.9 (names of PyQt5.QtWidgets found in PyQt6.QtGui only; names
# of PyQt5.QtCore/QtGui/QtWidgets found in none of PyQt6.QtCore/QtGui/QtWidgets).
MOVED_TO_QTGUI = {"QAction", "QActionGroup", "QShortcut", "QUndoCommand", "QUndoGroup", "QUndoStack",
                  "QFileSystemModel"}
GONE_IN_QT6 = {"QRegExp", "QRegExpValidator", "QTextCodec", "QTextDecoder", "QTextEncoder", "QDesktopWidget",
               "QDirModel", "QStateMachine", "QState", "QFinalState", "QHistoryState", "QSignalTransition",
               "QEventTransition", "QAbstractState", "QAbstractTransition", "QKeyEventTransition",
               "QMouseEventTransition", "QOpenGLWidget", "QTouchDevice", "QPictureIO", "QStyleOptionTabV4"}


def plugin_sources():
    files = [f for d in ("ui", "processing_provider", "qgisio") for f in glob.glob(os.path.join(ROOT, d, "*.py"))]
    return sorted(files) + [os.path.join(ROOT, "plugin.py")]


def _read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def _qt_module(module):
    return module is not None and (module == "qgis" or module.startswith(("qgis.", "PyQt5")))


def _imported_names(tree):
    """local name -> (module, name) for every ``from qgis... / PyQt5... import`` anywhere in the file."""
    names = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and _qt_module(node.module):
            for alias in node.names:
                names[alias.asname or alias.name] = (node.module, alias.name)
    return names


def _resolve(module, name):
    try:
        return getattr(importlib.import_module(module), name, None)
    except ImportError:
        return None


def _enum_value(value):
    """True for a sip enum value (PyQt5, QGIS) or a Python enum member (QGIS' monkey-patched scoped enums)."""
    if isinstance(value, type):
        return False
    return isinstance(value, enum.Enum) or type(type(value)).__name__ == "enumtype"


def unscoped_enums(source, filename="<source>"):
    """[(line, 'Name.member', 'Name.Enum.member')] for every unscoped enum access in ``source``."""
    tree = ast.parse(source, filename)
    names = _imported_names(tree)
    classes = {}
    found = []
    for parent in ast.walk(tree):
        for node in ast.iter_child_nodes(parent):
            if not (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and not isinstance(parent, ast.Attribute) and node.value.id in names):
                continue
            qual = node.value.id
            if qual not in classes:
                classes[qual] = _resolve(*names[qual])
            cls = classes[qual]
            if not isinstance(cls, type):
                continue
            value = getattr(cls, node.attr, None)
            if value is None or not _enum_value(value) or type(value).__name__ == qual:
                continue
            # the name ``qual`` gives the enum (QGIS >= 3.36: QgsProcessing.SourceType is Qgis.ProcessingSourceType)
            scope = [n for n in dir(cls) if getattr(cls, n, None) is type(value)]
            scope = type(value).__name__ if not scope or type(value).__name__ in scope else scope[0]
            found.append((node.lineno, f"{qual}.{node.attr}", f"{qual}.{scope}.{node.attr}"))
    return sorted(found)


def _fallback_of_qtgui_import(node, parents):
    """A QtWidgets import of moved names inside ``except ImportError`` of a try that imports them from QtGui."""
    handler = parents.get(node)
    tried = parents.get(handler)
    if not (isinstance(handler, ast.ExceptHandler) and isinstance(tried, ast.Try)):
        return False
    wanted = {a.name for a in node.names} & MOVED_TO_QTGUI
    have = set()
    for stmt in tried.body:
        if isinstance(stmt, ast.ImportFrom) and (stmt.module or "").endswith("QtGui"):
            have |= {a.name for a in stmt.names}
    return wanted <= have


def qt5_only(source, filename="<source>"):
    """[(line, what)] for every PyQt5-only import and exec_ call in ``source``."""
    tree = ast.parse(source, filename)
    parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, f"import {a.name}") for a in node.names if a.name.split(".")[0] == "PyQt5"]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names = {a.name for a in node.names}
            if node.module.split(".")[0] == "PyQt5":
                found.append((node.lineno, f"from {node.module} import (use qgis.PyQt)"))
            if node.module.endswith("QtWidgets") and names & MOVED_TO_QTGUI \
                    and not _fallback_of_qtgui_import(node, parents):
                found.append((node.lineno, f"{sorted(names & MOVED_TO_QTGUI)} from QtWidgets (QtGui in Qt6)"))
            if _qt_module(node.module) and names & GONE_IN_QT6:
                found.append((node.lineno, f"{sorted(names & GONE_IN_QT6)} (not in Qt6)"))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "exec_":
            found.append((node.lineno, "exec_() (exec() in Qt6)"))
    return sorted(found)


def _report(per_file):
    return "\n".join(f"{os.path.relpath(f, ROOT)}:{line}: {a}" + (f" -> {b}" if b else "")
                     for f, items in per_file for line, a, b in items)


def test_the_check_finds_what_the_migration_script_rewrites():
    src = (
        "from qgis.core import Qgis, QgsTask, QgsWkbTypes, QgsProcessing\n"
        "from qgis.PyQt.QtCore import Qt\n"
        "from qgis.PyQt.QtWidgets import QSizePolicy, QMessageBox, QAbstractItemView, QUndoStack\n"
        "from PyQt5.QtGui import QColor\n"
        "a = Qt.AlignLeft | Qt.AlignmentFlag.AlignTop\n"
        "b = QSizePolicy.Expanding, QMessageBox.Yes, QAbstractItemView.SelectRows\n"
        "c = Qgis.Info, QgsTask.CanCancel, QgsWkbTypes.PolygonGeometry, QgsProcessing.TypeVectorPoint\n"
        "d = Qgis.MessageLevel.Warning, QgsTask.Flag.CanCancel, Qt.UserRole + 1\n"
        "QMessageBox().exec_()\n"
    )
    got = {a: b for _line, a, b in unscoped_enums(src)}
    assert got == {
        "Qt.AlignLeft": "Qt.AlignmentFlag.AlignLeft",
        "QSizePolicy.Expanding": "QSizePolicy.Policy.Expanding",
        "QMessageBox.Yes": "QMessageBox.StandardButton.Yes",
        "QAbstractItemView.SelectRows": "QAbstractItemView.SelectionBehavior.SelectRows",
        "Qgis.Info": "Qgis.MessageLevel.Info",
        "QgsTask.CanCancel": "QgsTask.Flag.CanCancel",
        "QgsWkbTypes.PolygonGeometry": "QgsWkbTypes.GeometryType.PolygonGeometry",
        "QgsProcessing.TypeVectorPoint": "QgsProcessing.SourceType.TypeVectorPoint",
        "Qt.UserRole": "Qt.ItemDataRole.UserRole",
    }
    old = [what for _line, what in qt5_only(src)]
    assert len(old) == 3 and "QUndoStack" in old[0] and "PyQt5.QtGui" in old[1] and "exec_" in old[2], old
    fallback = ("try:\n    from qgis.PyQt.QtGui import QUndoStack\n"
                "except ImportError:\n    from qgis.PyQt.QtWidgets import QUndoStack\n")
    assert qt5_only(fallback) == []
    assert len(qt5_only(fallback.replace("QtGui", "QtCore"))) == 1


@pytest.mark.parametrize("path", plugin_sources(), ids=lambda p: os.path.relpath(p, ROOT))
def test_no_unscoped_enum(path):
    src = _read(path)
    found = unscoped_enums(src, path)
    assert not found, "unscoped enums (PyQt6 needs the scoped form):\n" + _report([(path, found)])


def _guarded(attr, parents):
    """``Name.Enum`` under an ``if hasattr(Name, "Enum")`` (a form only newer QGIS versions have)."""
    node = attr
    while node in parents:
        node = parents[node]
        if isinstance(node, (ast.If, ast.IfExp)):
            for call in ast.walk(node.test):
                if (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "hasattr"
                        and len(call.args) == 2 and isinstance(call.args[0], ast.Name)
                        and call.args[0].id == attr.value.id and isinstance(call.args[1], ast.Constant)
                        and call.args[1].value == attr.attr):
                    return True
    return False


def missing_scoped(source, filename="<source>"):
    """[(line, 'Name.Enum.member')] for scoped enum accesses that do not resolve on this QGIS / PyQt5 (a form only
    newer versions have), unless guarded by ``if hasattr(Name, "Enum")``."""
    tree = ast.parse(source, filename)
    names = _imported_names(tree)
    parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    found = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute)
                and isinstance(node.value.value, ast.Name) and node.value.value.id in names
                and node.value.attr[:1].isupper() and not _guarded(node.value, parents)):
            continue
        cls = _resolve(*names[node.value.value.id])
        if not isinstance(cls, type):
            continue
        scope = getattr(cls, node.value.attr, None)
        is_enum = isinstance(scope, enum.EnumMeta) or type(scope).__name__ == "enumtype"
        if scope is None or (is_enum and getattr(scope, node.attr, None) is None):
            found.append((node.lineno, f"{node.value.value.id}.{node.value.attr}.{node.attr}"))
    return sorted(found)


def test_scoped_enums_resolve_on_this_qgis():
    """Every scoped ``Name.Enum.member`` the sources use exists here (QGIS 3.22 / PyQt5 5.15): no fix that only
    works on Qt6."""
    src = ("from qgis.core import Qgis, QgsTask\n"
           "a = Qgis.MessageLevel.Info, QgsTask.Flag.CanCancel, QgsTask.Flag.NoSuchFlag, Qgis.NoSuchEnum.X\n"
           "b = Qgis.LabelPlacement.OverPoint if hasattr(Qgis, 'LabelPlacement') else None\n")
    assert [what for _line, what in missing_scoped(src)] == ["Qgis.NoSuchEnum.X", "QgsTask.Flag.NoSuchFlag"]
    bad = [(path, [(line, what, "") for line, what in missing_scoped(_read(path), path)])
           for path in plugin_sources()]
    bad = [item for item in bad if item[1]]
    assert not bad, "scoped enums missing on this QGIS:\n" + _report(bad)


@pytest.mark.parametrize("path", plugin_sources(), ids=lambda p: os.path.relpath(p, ROOT))
def test_no_pyqt5_only_import(path):
    found = qt5_only(_read(path), path)
    assert not found, "PyQt5-only:\n" + "\n".join(f"{os.path.relpath(path, ROOT)}:{ln}: {w}" for ln, w in found)


def test_metadata_claims_qt6_only_when_ready():
    """supportsQt6=True and qgisMaximumVersion=4.99 go together (the checks above pass, so the claim is true)."""
    import configparser

    meta = configparser.ConfigParser(interpolation=None)
    meta.read(os.path.join(ROOT, "metadata.txt"), encoding="utf-8")
    general = meta["general"]
    qt6 = general.get("supportsQt6", "False").strip().lower() in ("true", "yes", "1")
    maximum = general.get("qgisMaximumVersion", "3.99").strip()
    assert qt6 == maximum.startswith("4"), (general.get("supportsQt6"), maximum)
