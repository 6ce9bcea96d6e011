"""The address of a ``dask scheduler`` process a test started with ``--port 0 --scheduler-file FILE``.

A port picked beforehand (bind to port 0, close, pass the number on) is free only until someone else binds it: with
the suite in two processes, the other one's clusters can take it in the second the scheduler needs to start, and
the test then talks to that cluster.  The scheduler picks its own port and writes it to the file instead; the file
is written in place, not atomically, so it is read until it parses.
"""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path

__all__ = ["scheduler_address"]


def scheduler_address(scheduler_file: Path, proc: subprocess.Popen, limit: float = 60.0) -> str:
    """The ``tcp://`` address ``proc`` writes to ``scheduler_file``; AssertionError when it ends or ``limit`` s
    pass first."""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if proc.poll() is not None:
            raise AssertionError(f"the dask scheduler ended (rc {proc.returncode}) before writing {scheduler_file}")
        try:
            return json.loads(scheduler_file.read_text())["address"]
        except (OSError, ValueError, KeyError):  # not there yet, or half written
            time.sleep(0.1)
    raise AssertionError(f"no scheduler address in {scheduler_file} within {limit:g} s")
