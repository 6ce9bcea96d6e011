"""Preloaded into every worker process of the embedded LocalCluster (see :mod:`railopt.design.parallel`).

Ctrl-C in a terminal sends SIGINT to the whole foreground process group, the workers included; the main
process handles it (and shuts the cluster down), so the workers ignore it instead of printing a
``KeyboardInterrupt`` traceback each.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker: object = None) -> None:
    """Ignore SIGINT in this worker process (only possible from its main thread, where dask runs it)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


__all__ = ["dask_setup"]
