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

import signal
import threading
from typing import Any

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # the preload runs in a dask worker, where distributed is there; serial use never ships
    WorkerPlugin = object  # type: ignore[assignment,misc]


def dask_setup(worker: object = None) -> None:
    """Ignore SIGINT in this worker process (only possible from its main thread, where dask runs it)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


class ShippedObject(WorkerPlugin):  # type: ignore[misc,valid-type]
    """A worker plugin holding ``value`` (unpickled once per worker, when the plugin is added to it).

    Registered under ``name`` by :func:`railopt.design.parallel.shipping`, removed when the campaign ends.
    """

    def __init__(self, name: str, value: Any) -> None:
        self.name = name
        self.value = value

    def setup(self, worker: Any) -> None:  # noqa: D102  (nothing to do: the value came with the plugin)
        return None

    def teardown(self, worker: Any) -> None:
        """Let go of the value on the worker when the campaign's plugin is removed."""
        self.value = None


__all__ = ["ShippedObject", "dask_setup"]
