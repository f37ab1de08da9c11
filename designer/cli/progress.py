"""The commands' progress bar: one rule for where it is drawn and when."""

from __future__ import annotations

import sys


class progress_display:
    """A transient progress bar on standard error, fed as ``progress(stage, done, total)``; drawn
    only when standard error is a terminal and the command was not given ``--quiet`` (``quiet``).
    Entering gives that callable, or None when nothing is drawn."""

    def __init__(self, quiet: bool, first: str):
        self.enabled, self.first = not quiet and sys.stderr.isatty(), first
        self._progress = self._task = None

    def __enter__(self):
        if not self.enabled:
            return None
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                  TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn(), transient=True,
                                  console=Console(stderr=True))
        self._task = self._progress.add_task(self.first, total=None)
        self._progress.start()
        return self.update

    def update(self, stage: str, done: int, total: int) -> None:
        self._progress.update(self._task, description=stage, completed=done, total=total)

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.stop()
        return False
