"""The Progress protocol: how long work reports progress and hears a cancel.

core/ never sees QgsFeedback; the faces (processing_provider/, ui/) wrap it in
an object with the two methods below.  ``NullProgress`` is the default.
"""
from __future__ import annotations

import logging
from typing import Optional, Protocol

log = logging.getLogger("archaeoortho")


class Cancelled(Exception):
    """Raised by core functions when the user asked to stop."""


class Progress(Protocol):
    def report(self, fraction: float, message: str = "") -> None:
        """fraction in [0, 1] of the current task; message may be empty."""

    def is_cancelled(self) -> bool:
        ...

    def info(self, message: str) -> None:
        ...

    def warning(self, message: str) -> None:
        ...


class NullProgress:
    """Reports to the ``archaeoortho`` logger and is never cancelled."""

    def report(self, fraction: float, message: str = "") -> None:
        if message:
            log.debug("%3.0f%% %s", 100.0 * fraction, message)

    def is_cancelled(self) -> bool:
        return False

    def info(self, message: str) -> None:
        log.info(message)

    def warning(self, message: str) -> None:
        log.warning(message)


class PrintProgress(NullProgress):
    """Prints to stdout; used by the demo and benchmarks."""

    def __init__(self, prefix: str = ""):
        self.prefix = prefix
        self._last = -1.0

    def report(self, fraction: float, message: str = "") -> None:
        if fraction - self._last >= 0.05 or fraction >= 1.0:
            self._last = fraction
            print(f"{self.prefix}{100 * fraction:5.1f}% {message}", flush=True)

    def info(self, message: str) -> None:
        print(f"{self.prefix}{message}", flush=True)

    def warning(self, message: str) -> None:
        print(f"{self.prefix}WARNING: {message}", flush=True)


class SubProgress:
    """Maps [0, 1] of a sub-task onto [start, end] of a parent Progress."""

    def __init__(self, parent: Optional[Progress], start: float, end: float):
        self.parent = parent or NullProgress()
        self.start = start
        self.end = end

    def report(self, fraction: float, message: str = "") -> None:
        f = min(max(fraction, 0.0), 1.0)
        self.parent.report(self.start + (self.end - self.start) * f, message)

    def is_cancelled(self) -> bool:
        return self.parent.is_cancelled()

    def info(self, message: str) -> None:
        self.parent.info(message)

    def warning(self, message: str) -> None:
        self.parent.warning(message)


def check_cancel(progress: Optional[Progress]) -> None:
    if progress is not None and progress.is_cancelled():
        raise Cancelled("cancelled by the user")
