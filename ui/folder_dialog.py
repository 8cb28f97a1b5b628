"""A folder dialog that takes a new folder's name as well as an existing folder (a workspace folder to make).

Qt's folder dialog (QFileDialog.getExistingDirectory) answers a typed name that does not exist yet with
'Directory not found'; this one makes the folder (its parent must exist) and takes it."""
import os

from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import QDialog, QDialogButtonBox, QFileDialog, QLineEdit, QMessageBox


class FolderDialog(QFileDialog):
    """Qt's own (non-native) folder dialog whose Choose button also takes a new folder name typed in it."""

    def __init__(self, parent=None, caption="", directory=""):
        super().__init__(parent, caption, directory)
        self.setFileMode(QFileDialog.FileMode.Directory)
        self.setOption(QFileDialog.Option.ShowDirsOnly, True)
        self.setOption(QFileDialog.Option.DontUseNativeDialog, True)  # accept() below is Qt's dialog's
        # Qt disables Choose while the typed name is no existing folder: enabled again (after Qt's own slot)
        edit = self.findChild(QLineEdit, "fileNameEdit")
        if edit is not None:
            edit.textChanged.connect(self._enable_new_name)

    def _new_folder(self):
        """The typed folder that does not exist yet and can be made (its parent exists), else ''."""
        files = self.selectedFiles()
        path = files[0] if files else ""
        if path and not os.path.exists(path) and os.path.isdir(os.path.dirname(os.path.normpath(path))):
            return path
        return ""

    def choose_button(self):
        box = self.findChild(QDialogButtonBox, "buttonBox")
        return box.button(QDialogButtonBox.StandardButton.Open) if box is not None else None

    def _enable_new_name(self, _text=""):
        button = self.choose_button()
        if button is not None and self._new_folder():
            button.setEnabled(True)

    def accept(self):
        path = self._new_folder()
        if path:
            try:
                os.mkdir(path)
            except OSError as e:
                QMessageBox.warning(self, self.windowTitle(), QCoreApplication.translate(
                    "FolderDialog", "The folder {} cannot be made: {}").format(path, e.strerror or e))
                return
        super().accept()


def choose_folder(parent, caption, directory=""):
    """The folder chosen or typed (made when new), or '' when the dialog was cancelled."""
    dialog = FolderDialog(parent, caption, directory)
    if dialog.exec() != QDialog.DialogCode.Accepted or not dialog.selectedFiles():
        return ""
    return dialog.selectedFiles()[0]
