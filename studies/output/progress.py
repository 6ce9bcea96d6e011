"""Progress of a long run on stderr: a redrawn bar on a terminal, plain periodic lines in a log.

On a terminal :class:`Progress` draws a ``tqdm`` bar (carriage-return redraws, at most one per
``mininterval`` seconds).  When the stream is not a terminal (a log file, a pipe, a batch system) it never
writes a carriage return: one line ``<label>: <done>/<total> starts (<pct> %)`` each time another tenth of the
starts has finished or ``interval_s`` seconds have passed since the last line, and one at the end.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress"]


def _is_terminal(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # closed or not a file
        return False


class Progress:
    """``update(done, total)`` as work finishes, ``close()`` at the end (also a context manager).

    Parameters
    ----------
    label : str
        Names the work in every line (e.g. the campaign's store label).
    unit : str
        What is counted (``"start"``).
    enabled : bool
        ``False``: nothing is written.
    stream : text stream, optional
        Default ``sys.stderr`` (looked up when the object is made).
    interval_s : float
        In a log: the longest time between two lines while work goes on.
    steps : int
        In a log: a line each time another ``1/steps`` of the total has finished.
    terminal : bool, optional
        Force the terminal (bar) or log (lines) behaviour; default: ``stream.isatty()``.
    """

    def __init__(self, label: str, unit: str = "start", enabled: bool = True, stream: TextIO | None = None,
                 interval_s: float = 30.0, steps: int = 10, mininterval: float = 0.5,
                 terminal: bool | None = None) -> None:
        self.label, self.unit, self.enabled = label, unit, enabled
        self.stream = stream if stream is not None else sys.stderr
        self.interval_s, self.steps = float(interval_s), max(1, int(steps))
        self.terminal = _is_terminal(self.stream) if terminal is None else terminal
        self.done, self.total = 0, None
        self._bar = None
        self._last_step = 0
        self._last_time = time.monotonic()
        self._last_line: tuple[int, int | None] | None = None
        if enabled and self.terminal:
            from tqdm import tqdm

            self._bar = tqdm(desc=label, unit=unit, file=self.stream, mininterval=mininterval)

    def update(self, done: int, total: int | None = None) -> None:
        """``done`` of ``total`` finished (absolute counts, not increments)."""
        self.done, self.total = int(done), (None if total is None else int(total))
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.total = self.total
            self._bar.n = self.done
            self._bar.refresh() if self.done == self.total else self._bar.update(0)
            return
        now = time.monotonic()
        step = self.done * self.steps // self.total if self.total else 0
        if step > self._last_step or now - self._last_time >= self.interval_s or (
                self.total is not None and self.done >= self.total):
            self._last_step = max(self._last_step, step)
            self._line(now)

    def _line(self, now: float) -> None:
        if self._last_line == (self.done, self.total):
            return
        if self.total:
            text = f"{self.label}: {self.done}/{self.total} {self.unit}s ({100 * self.done / self.total:.0f} %)"
        else:
            text = f"{self.label}: {self.done} {self.unit}s"
        print(text, file=self.stream, flush=True)
        self._last_line, self._last_time = (self.done, self.total), now

    def close(self) -> None:
        """End the bar (terminal) or write the final count if it was not the last line (log)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and self.total is not None and self.done > 0:
            self._line(time.monotonic())
        self.enabled = False

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
