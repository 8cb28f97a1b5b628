"""pycolmap, imported quietly, and the watcher that turns a user's cancel into a pycolmap cancellation.

pycolmap's long calls (feature extraction, matching, mapping, bundle adjustment, patch-match stereo) take a
``CancellationToken``; :class:`CancelWatcher` polls ``progress.is_cancelled()`` on a thread and cancels the
token, and turns the ``InterruptedError`` pycolmap raises into :class:`~.progress.Cancelled`::

    with CancelWatcher(progress) as token:
        pycolmap.extract_features(..., cancellation_token=token)
"""
from __future__ import annotations

import os
import threading

from .errors import require
from .progress import Cancelled, Progress


def load_pycolmap(purpose: str = "photogrammetry"):
    """pycolmap (MissingDependencyError naming it when absent), its log cut to errors unless
    ARCHAEOORTHO_VERBOSE is set (the Progress protocol reports the rest)."""
    pycolmap = require("pycolmap", purpose)
    if not os.environ.get("ARCHAEOORTHO_VERBOSE"):
        pycolmap.logging.minloglevel = 2
    return pycolmap


class CancelWatcher:
    """Polls ``progress.is_cancelled()`` and cancels a pycolmap CancellationToken."""

    def __init__(self, progress: Progress):
        self.progress = progress
        pycolmap = load_pycolmap()
        self.token = pycolmap.CancellationToken()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self._stop.wait(0.2):
            if self.progress.is_cancelled():
                self.token.cancel()
                return

    def __enter__(self):
        self._thread.start()
        return self.token

    def __exit__(self, exc_type, exc, tb):
        self._stop.set()
        self._thread.join(timeout=1)
        if exc_type is not None and issubclass(exc_type, InterruptedError) and self.token.is_cancelled:
            raise Cancelled("cancelled by the user") from exc
        return False
