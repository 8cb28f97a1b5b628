"""The DSM stage's journal: its timings, warnings and log lines (the log lines also go to the progress)."""
from __future__ import annotations

import time
from typing import Dict, List

from ..common.progress import Progress
from ..project.workspace import Workspace


class Journal:
    """What the DSM stage tells: ``warn`` and ``info`` go to the progress at once and are kept for the result;
    ``note`` only keeps a line (told later with ``tell_last``)."""

    def __init__(self, progress: Progress):
        self.progress = progress
        self.t_start = time.time()
        self.timings: Dict[str, float] = {}
        self.warnings: List[str] = []
        self.log: List[str] = []

    def warn(self, msg: str) -> None:
        self.warnings.append(msg)
        self.progress.warning(msg)

    def info(self, line: str) -> None:
        self.log.append(line)
        self.progress.info(line)

    def note(self, line: str) -> None:
        self.log.append(line)

    def record_timings(self, ws: Workspace, stage: str) -> None:
        """Each step's seconds (not the total) into the workspace's record of ``stage``."""
        for k, v in self.timings.items():
            if k != "total":
                ws.record_timing(stage, k, v)

    def close(self) -> None:
        """The total time, and a log line with every step's seconds."""
        self.timings["total"] = time.time() - self.t_start
        self.log.append("seconds: " + ", ".join(f"{k.replace('_', ' ')} {v:.1f}" for k, v in self.timings.items()))
