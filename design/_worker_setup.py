"""What a dask worker is set up with: SIGINT ignored (the preload), and the objects a campaign ships once.

The preload.  Ctrl-C in a terminal sends SIGINT to the whole foreground process group, the workers included; the
main process handles it (and shuts the cluster down), so the workers of the embedded LocalCluster ignore it
instead of printing a ``KeyboardInterrupt`` traceback each (:func:`dask_setup`; see
:mod:`railopt.design.parallel`, which passes this file's text as the preload).

Shipping.  :class:`ShippedObject` is a dask worker plugin that carries one object (a campaign's problem) to every
worker once: the scheduler keeps it and hands it to every worker that joins later (a restarted one included),
so the tasks of a campaign carry only the plugin's name (:class:`railopt.design.parallel.Shipped`).
"""

from __future__ import annotations

import logging
import signal
import threading
from typing import Any

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # the preload runs in a dask worker, where distributed is there; serial use never ships
    WorkerPlugin = object  # type: ignore[assignment,misc]


SCHEDULER_GONE = "Failed to communicate with scheduler during heartbeat"
"""The worker log record dropped in the embedded cluster: its scheduler lives in the main process, so when it is
gone the main process is shutting the cluster down (Ctrl-C, the end of a run) or has failed and says so itself;
the worker's ERROR with a traceback would only add noise to what the user reads."""


class SchedulerGone(logging.Filter):
    """Drops the :data:`SCHEDULER_GONE` records of the ``distributed.worker`` logger."""

    def filter(self, record: logging.LogRecord) -> bool:
        """False for a heartbeat failure (dropped), True for everything else."""
        return SCHEDULER_GONE not in record.getMessage()


def dask_setup(worker: object = None) -> None:
    """Ignore SIGINT in this worker process (only possible from its main thread, where dask runs it), and drop the
    heartbeat failures a worker logs when the main process closes the scheduler first (:class:`SchedulerGone`)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    log = logging.getLogger("distributed.worker")
    if not any(isinstance(f, SchedulerGone) for f in log.filters):
        log.addFilter(SchedulerGone())


class ShippedObject(WorkerPlugin):  # type: ignore[misc,valid-type]
    """A worker plugin holding ``value`` (unpickled once per worker, when the plugin is added to it).

    Registered under ``name`` by :func:`railopt.design.parallel.shipping`, removed when the campaign ends.
    """

    def __init__(self, name: str, value: Any) -> None:
        self.name = name
        self.value = value

    def setup(self, worker: Any) -> None:
        """Nothing to do: the value came with the plugin."""
        return None

    def teardown(self, worker: Any) -> None:
        """Let go of the value on the worker when the campaign's plugin is removed."""
        self.value = None


__all__ = ["SCHEDULER_GONE", "SchedulerGone", "ShippedObject", "dask_setup"]
