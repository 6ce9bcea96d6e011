"""Progress of a long run on stderr: a redrawn bar on a terminal, plain periodic lines in a log.

On a terminal :class:`Progress` draws a ``tqdm`` bar (carriage-return redraws, at most one per
``mininterval`` seconds).  When the stream is not a terminal (a log file, a pipe, a batch system) it never
writes a carriage return: one line ``<label>: <done>/<total> starts (<pct> %)`` each time another tenth of the
starts has finished or ``interval_s`` seconds have passed since the last line, and one at the end.

Every long loop of a run reports through it: a campaign's starts, the checks of its optima, its trade-offs and
surfaces (many maps, added up by :meth:`Progress.over_maps`), the ride kind's starts.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
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
        self.done, self.total, self.detail = 0, None, ""
        self._bar = None
        self._last_step = 0
        self._last_time = time.monotonic()
        self._last_line: tuple[int, int | None] | None = None
        if enabled and self.terminal:
            from tqdm import tqdm

            self._bar = tqdm(desc=label, unit=unit, file=self.stream, mininterval=mininterval)

    def update(self, done: int, total: int | None = None, detail: str = "") -> None:
        """``done`` of ``total`` finished (absolute counts, not increments); ``detail`` is added to the line in
        brackets.  Without a total, a log gets a line per ``interval_s`` only (and the final count)."""
        self.done, self.total, self.detail = int(done), (None if total is None else int(total)), detail
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.total = self.total
            self._bar.n = self.done
            if detail:
                self._bar.set_postfix_str(detail, refresh=False)
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
            text = f"{self.label}: {self.done} {self.unit}s" + (f" ({self.detail})" if self.detail else "")
        print(text, file=self.stream, flush=True)
        self._last_line, self._last_time = (self.done, self.total), now

    def over_maps(self) -> Callable[[int, int], None]:
        """A ``progress(done, total)`` for :func:`railopt.design.parallel.reporting_progress`: the maps of long work
        (each begins with ``done = 0``: a trade-off's sweeps, a surface's grids) add up.  The line counts every task
        finished so far, with the current map's ``done/total`` as its detail; as the number of maps to come is not
        known, a log gets a line every ``interval_s`` and the final count (``label: 39 tasks (map 13: 3/3)``)."""
        begun = [0, 0]  # tasks finished in the maps before the current one; maps begun
        current = [0, 0]

        def report(done: int, total: int) -> None:
            if done == 0:  # a new map
                begun[0] += current[0]
                begun[1] += 1
            current[:] = [int(done), int(total)]
            self.update(begun[0] + current[0], None, detail=f"map {begun[1]}: {current[0]}/{current[1]}")

        return report

    def close(self) -> None:
        """End the bar (terminal) or write the final count if it was not the last line (log)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and self.done > 0:
            self._line(time.monotonic())
        self.enabled = False

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
