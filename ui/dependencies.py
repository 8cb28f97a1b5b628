"""Install pycolmap / OpenCV from inside QGIS: the message bar item at load and the installer dialog.

What is needed, where it goes and the pip command come from core.common.dependencies; this module only
runs pip with QProcess (QGIS never freezes), streams its output into a log, lets the user cancel (pip is
killed) and retry, and checks the result by importing the packages in a fresh Python.
"""
import os

from qgis.core import Qgis
from qgis.PyQt.QtCore import QCoreApplication, QProcess, QProcessEnvironment, pyqtSignal
from qgis.PyQt.QtGui import QFont, QTextCursor
from qgis.PyQt.QtWidgets import (
    QDialog,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPlainTextEdit,
    QProgressBar,
    QPushButton,
    QVBoxLayout,
)

from ..core.common import dependencies

_STATE_TEXT = {"missing": "missing", "unsupported": "wrong version", "untested": "untested version", "ok": "ok"}


def _tr(text):
    return QCoreApplication.translate("DependenciesDialog", text)


def summary(bad):
    """One short sentence for the message bar: what is missing or of a version that does not work."""
    def name(f):
        return f.requirement.label.split(" (")[0]

    missing = [name(f) for f in bad if f.state == "missing"]
    wrong = [f"{name(f)} {f.version}" for f in bad if f.state != "missing"]
    parts = []
    if missing:
        parts.append(_tr("{} (not installed)").format(_tr(" and ").join(missing)))
    if wrong:
        parts.append(_tr("{} (wrong version)").format(_tr(" and ").join(wrong)))
    return _tr("needs {}").format("; ".join(parts))


def push_missing_message(iface, bad, profile_dir):
    """ONE message bar item, with an Install button that opens the dialog.  Returns the item."""
    bar = iface.messageBar()
    item = bar.createMessage("ArchaeoOrtho", summary(bad))
    button = QPushButton(_tr("Install…"), item)
    button.setObjectName("ArchaeoOrthoInstallDependencies")
    button.setToolTip(_tr("Install {} into the plugin's own folder").format(
        ", ".join(f.requirement.pin for f in bad)))
    item.layout().addWidget(button)

    def open_dialog():
        dialog = DependenciesDialog(profile_dir, parent=iface.mainWindow())
        dialog.installed.connect(lambda: bar.popWidget(item))
        item._archaeoortho_dialog = dialog  # keep it alive while the item lives
        dialog.show()

    button.clicked.connect(open_dialog)
    bar.pushWidget(item, Qgis.MessageLevel.Warning)
    return item


def optional_packages_html():
    """The optional packages (core.common.dependencies.OPTIONAL): what this Python has of each, and the command
    that installs a missing one; the features that need them say so when used, the plugin loads without them."""
    rows = []
    for f in dependencies.check(dependencies.OPTIONAL):
        colour = "green" if f.usable else "#777"
        how = "" if f.usable else " " + _tr("install with: {}").format(
            f"<code>{dependencies.install_command([f.requirement.dist])}</code>")
        rows.append(f"<li><span style='color:{colour}'>[{_tr(_STATE_TEXT[f.state])}]</span> {f.describe()}{how}</li>")
    if not rows:
        return ""
    return _tr("Optional (only the feature named needs it):") + f"<ul>{''.join(rows)}</ul>"


class DependenciesDialog(QDialog):
    """Lists what is missing, installs it with pip (QProcess, log, busy bar, Cancel, Retry), verifies it.

    ``state`` is idle / running / verifying / done / failed / cancelled.  ``command`` (program, arguments)
    is the pip run and ``verify_command`` the import check; tests may replace either."""

    installed = pyqtSignal()

    def __init__(self, profile_dir, requirements=dependencies.REQUIREMENTS, find_links=None, no_index=False,
                 python=None, parent=None):
        super().__init__(parent)
        self.setObjectName("ArchaeoOrthoDependenciesDialog")
        self.setWindowTitle(_tr("ArchaeoOrtho: install Python packages"))
        self.profile_dir = profile_dir
        self.requirements = tuple(requirements)
        self.target = dependencies.target_dir(profile_dir)
        self.python = python or dependencies.find_python()
        self.command = (self.python, dependencies.pip_arguments(self.target, self.requirements, find_links,
                                                                no_index))
        self.verify_command = (self.python, dependencies.verify_arguments(self.target, self.requirements))
        self.state = "idle"
        self.process = None
        self._build()
        self.refresh()

    # ------------------------------------------------------------------ widgets
    def _build(self):
        layout = QVBoxLayout(self)
        self.packages_label = QLabel(self)
        self.packages_label.setObjectName("packages")
        self.packages_label.setWordWrap(True)
        layout.addWidget(self.packages_label)
        where = QLabel(_tr("pip installs the tested versions with QGIS's own Python, {python}, into the plugin's "
                           "folder in your QGIS profile:<br><code>{target}</code><br>QGIS's own packages "
                           "(NumPy, GDAL) are left as they are; removing that folder undoes the install.").format(
            python=self.python, target=self.target), self)
        where.setWordWrap(True)
        layout.addWidget(where)
        platform_text = dependencies.SUPPORTED
        reason = dependencies.unsupported_platform()
        if reason:
            platform_text = "<b>" + _tr("This computer: {}.").format(reason) + "</b> " + platform_text
        self.platform_label = QLabel(platform_text, self)
        self.platform_label.setWordWrap(True)
        layout.addWidget(self.platform_label)
        layout.addWidget(QLabel(_tr("The same from a terminal (the OSGeo4W Shell on Windows):"), self))
        self.command_edit = QLineEdit(dependencies.command_line(*self.command), self)
        self.command_edit.setReadOnly(True)
        self.command_edit.setCursorPosition(0)
        layout.addWidget(self.command_edit)
        self.progress = QProgressBar(self)
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.progress.setTextVisible(False)
        layout.addWidget(self.progress)
        self.status_label = QLabel(self)
        self.status_label.setObjectName("status")
        self.status_label.setWordWrap(True)
        layout.addWidget(self.status_label)
        self.log = QPlainTextEdit(self)
        self.log.setObjectName("log")
        self.log.setReadOnly(True)
        self.log.setFont(QFont("monospace"))
        self.log.setMinimumHeight(160)
        self.log.setVisible(False)
        layout.addWidget(self.log, 1)
        buttons = QHBoxLayout()
        buttons.addStretch(1)
        self.install_button = QPushButton(_tr("Install"), self)
        self.install_button.setObjectName("install")
        self.install_button.clicked.connect(self.start)
        self.cancel_button = QPushButton(_tr("Cancel"), self)
        self.cancel_button.setObjectName("cancel")
        self.cancel_button.clicked.connect(self.cancel)
        self.close_button = QPushButton(_tr("Close"), self)
        self.close_button.clicked.connect(self.reject)
        for b in (self.install_button, self.cancel_button, self.close_button):
            buttons.addWidget(b)
        layout.addLayout(buttons)
        self.resize(860, 640)

    def refresh(self):
        """Show what this Python has of each package and which buttons apply."""
        found = dependencies.check(self.requirements)
        rows = []
        for f in found:
            colour = "green" if f.usable else "#b00"
            rows.append(f"<li><span style='color:{colour}'>[{_tr(_STATE_TEXT[f.state])}]</span> "
                        f"{f.describe()}</li>")
        heading = _tr("ArchaeoOrtho needs these Python packages:")
        self.packages_label.setText(f"{heading}<ul>{''.join(rows)}</ul>{optional_packages_html()}")
        running = self.state in ("running", "verifying")
        self.install_button.setEnabled(not running)
        self.install_button.setText({"failed": _tr("Retry"), "cancelled": _tr("Retry"),
                                     "done": _tr("Reinstall")}.get(self.state, _tr("Install")))
        self.cancel_button.setEnabled(running)
        return found

    # ------------------------------------------------------------------ the pip run
    def start(self):
        """Run pip (again: Retry) in a QProcess; output streams into the log."""
        if self.state in ("running", "verifying"):
            return
        self.log.clear()
        self.log.setVisible(True)
        os.makedirs(os.path.dirname(self.target), exist_ok=True)
        self._run("running", self.command, _tr("Installing with pip… (this downloads about 80 MB)"))

    def _run(self, state, command, message):
        self.state = state
        program, args = command
        shown = list(args)
        if len(shown) > 1 and shown[0] == "-c" and "\n" in shown[1]:
            shown[1] = "<import check>"
        self._append(f"$ {dependencies.command_line(program, shown)}\n")
        self.process = QProcess(self)
        env = QProcessEnvironment()
        for key, value in dependencies.pip_environment().items():
            env.insert(key, value)
        self.process.setProcessEnvironment(env)
        self.process.setProcessChannelMode(QProcess.ProcessChannelMode.MergedChannels)
        self.process.readyReadStandardOutput.connect(self._read)
        self.process.finished.connect(self._finished)
        self.process.errorOccurred.connect(self._error)
        self.progress.setRange(0, 0)  # busy
        self.status_label.setText(message)
        self.refresh()
        self.process.start(program, list(args))

    def _read(self):
        if self.process is not None:
            self._append(bytes(self.process.readAllStandardOutput()).decode("utf-8", "replace"))

    def _append(self, text):
        self.log.moveCursor(QTextCursor.MoveOperation.End)
        self.log.insertPlainText(text)
        self.log.ensureCursorVisible()

    def _error(self, error):
        if error == QProcess.ProcessError.FailedToStart and self.state in ("running", "verifying"):
            self._fail(_tr("Could not start {}: {}").format(self.command[0], self.process.errorString()))

    def _finished(self, code, status):
        self._read()
        if self.state == "cancelled":
            return
        if status != QProcess.ExitStatus.NormalExit or code != 0:
            what = _tr("pip") if self.state == "running" else _tr("The import check")
            self._fail(_tr("{} failed (exit code {}). The log below says why; fix it and press Retry.").format(
                what, code))
        elif self.state == "running" and self.verify_command is not None:
            self._run("verifying", self.verify_command, _tr("Checking that the packages load…"))
        else:
            self._done()

    def _fail(self, message):
        self.state = "failed"
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.status_label.setText(f"<b style='color:#b00'>{message}</b>")
        self.log.setVisible(True)
        self.refresh()

    def _done(self):
        unmet = dependencies.unmet_requirements(self.target, self.requirements)
        if unmet:
            self._fail(_tr("Installed, but QGIS's Python lacks what the packages need: {}").format("; ".join(unmet)))
            return
        dependencies.activate(self.profile_dir, requirements=self.requirements)
        self.state = "done"
        self.progress.setRange(0, 1)
        self.progress.setValue(1)
        self.status_label.setText(_tr("Installed. ArchaeoOrtho can use them now (restart QGIS if it had already "
                                      "loaded an older version)."))
        self.refresh()
        self.installed.emit()

    def cancel(self):
        """Kill pip (or the import check)."""
        if self.process is None or self.state not in ("running", "verifying"):
            return
        self.state = "cancelled"
        self.process.kill()
        self.process.waitForFinished(5000)
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self._append("\n" + _tr("Cancelled.") + "\n")
        self.status_label.setText(_tr("Cancelled: pip was stopped. Press Retry to start again."))
        self.refresh()

    def reject(self):
        self.cancel()
        super().reject()
