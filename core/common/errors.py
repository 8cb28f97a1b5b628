"""The errors a user may see, and the missing-dependency message.

Every error that core/ raises on purpose (bad input, a workspace that cannot be used, a stage that cannot
run) derives from :class:`ArchaeoOrthoError`.  The faces (processing_provider/, ui/) catch that base and
show its message; anything else is a bug and keeps its traceback in the log.

The stage errors keep their historical second base (ValueError or RuntimeError) so existing callers that
catch those still work.
"""
from __future__ import annotations

import importlib
from typing import Any, Optional

from .dependencies import REQUIREMENTS, install_command


class ArchaeoOrthoError(Exception):
    """Base of every error whose message is meant for the user (names the file and the problem)."""


class MissingDependencyError(ArchaeoOrthoError, ImportError):
    """A Python package the plugin needs is not installed (or is the wrong version)."""

    def __init__(self, package: str, purpose: str = "", detail: str = ""):
        self.package = package
        self.purpose = purpose
        self.detail = detail
        super().__init__(self._message())

    def _message(self) -> str:
        what = f" (needed for {self.purpose})" if self.purpose else ""
        command = install_command([self.package])
        msg = f"the Python package '{self.package}' is missing{what}. "
        if self.package in PINNED:
            msg += ("Install it with the 'Install' button that ArchaeoOrtho shows in the QGIS message bar, or "
                    f"run (in the OSGeo4W Shell on Windows): {command}")
        else:
            msg += f"Install it into the Python that QGIS uses: {command}"
        if self.detail:
            msg += f". Import error: {self.detail}"
        return msg


# the versions requirements.txt pins (the messages name them so a user installs the tested build)
PINNED = {r.dist: r.pin for r in REQUIREMENTS}

# import name -> PyPI name
_PYPI = {"cv2": "opencv-python-headless", "pycolmap": "pycolmap", "rvt": "rvt-py", "rvt.vis": "rvt-py"}


def require(module: str, purpose: str = "") -> Any:
    """Import ``module`` or raise :class:`MissingDependencyError` naming the package to install."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise MissingDependencyError(_PYPI.get(module, module), purpose, str(e)) from e


def user_message(error: BaseException) -> Optional[str]:
    """The message to show for ``error`` if it is meant for the user, else None (a bug: show the traceback)."""
    if isinstance(error, ArchaeoOrthoError):
        return str(error)
    if isinstance(error, ModuleNotFoundError) and error.name:
        root = error.name.split(".")[0]
        return str(MissingDependencyError(_PYPI.get(root, root), detail=str(error)))
    return None
