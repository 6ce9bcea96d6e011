"""Where tasks run: in-process, or on dask.distributed (an embedded LocalCluster or a scheduler).

The design layer takes an optional ``client``; with none, the same code runs serially.
Results stream back in completion order (``as_completed``); a lost worker's tasks are retried.
Every task runs with single-threaded BLAS: parallelism is across tasks, small matrices gain
nothing from threads, and a threaded BLAS rounds differently — with it, a serial run and a
dask run of the same campaign would not give the same table.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from threadpoolctl import threadpool_limits

SCHEDULER_ENV = "RAILOPT_SCHEDULER"
SCHEDULER_TIMEOUT_ENV = "RAILOPT_SCHEDULER_TIMEOUT"
DEFAULT_SCHEDULER_TIMEOUT = 5.0


@dataclass(frozen=True)
class _SingleThreaded:
    fn: Callable[[Any], Any]

    def __call__(self, item: Any) -> Any:
        with threadpool_limits(limits=1, user_api="blas"):
            return self.fn(item)


def call(task: Callable[[], Any]) -> Any:
    """Run a self-contained task object: ``map_unordered(call, tasks, client)``."""
    return task()


def map_unordered(
    fn: Callable[[Any], Any], items: Iterable[Any], client: Any = None, retries: int = 3
) -> Iterator[Any]:
    """Yield ``fn(item)`` for each item, in completion order; serial when ``client`` is None."""
    items = list(items)
    task = _SingleThreaded(fn)
    if client is None:
        for item in items:
            yield task(item)
        return
    from dask.distributed import as_completed

    futures = client.map(task, items, pure=False, retries=retries)
    try:
        for future in as_completed(futures):
            yield future.result()
    finally:
        for future in futures:  # interrupted: do not leave work queued on a shared cluster
            if not future.done():
                future.cancel()


class SchedulerError(ConnectionError):
    """The dask scheduler cannot be reached (or its address is not valid); the message names it."""


def scheduler_timeout(timeout: float | None = None, field: str = "timeout") -> float:
    """Seconds to wait for a scheduler: ``timeout``, else ``$RAILOPT_SCHEDULER_TIMEOUT``, else 5.

    A value that is not a positive finite number raises ``ValueError`` naming ``field`` (or the variable).
    """
    if timeout is None:
        text = os.environ.get(SCHEDULER_TIMEOUT_ENV, "").strip()
        try:
            timeout, field = (float(text), SCHEDULER_TIMEOUT_ENV) if text else (DEFAULT_SCHEDULER_TIMEOUT, field)
        except ValueError:
            raise ValueError(f"{SCHEDULER_TIMEOUT_ENV}: must be a number of seconds, got {text!r}") from None
    if not (isinstance(timeout, numbers.Real) and not isinstance(timeout, bool) and 0 < timeout < math.inf):
        raise ValueError(f"{field}: must be a positive number of seconds, got {timeout!r}")
    return float(timeout)


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None,
                timeout: float | None = None) -> Iterator[Any]:
    """A dask client: the ``scheduler`` address if given, else a LocalCluster (or serial).

    ``workers`` = number of worker processes of the embedded cluster (one thread each); ``0``
    yields ``None`` (serial, in-process).  ``$RAILOPT_SCHEDULER`` is used only when neither
    ``scheduler`` nor ``workers`` is given: an explicit request wins over the environment.
    ``timeout`` (s; default :func:`scheduler_timeout`) bounds the wait for a scheduler: an
    unreachable one raises :class:`SchedulerError` naming the address.
    """
    if scheduler is None and workers is None:
        scheduler = os.environ.get(SCHEDULER_ENV) or None
    if scheduler is None and workers == 0:
        yield None
        return
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        wait = scheduler_timeout(timeout)
        hint = f"check the address (--scheduler or ${SCHEDULER_ENV}), or run on a local cluster with --workers N"
        try:
            client = Client(scheduler, timeout=wait)
        except (ValueError, TypeError) as exc:
            raise SchedulerError(f"scheduler: {scheduler!r} is not a valid address ({exc}); {hint}") from None
        except OSError as exc:
            raise SchedulerError(f"scheduler: cannot connect to {scheduler!r} within {wait:g} s ({exc}); {hint}"
                                 ) from None
        with client:
            yield client
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 0:
        raise ValueError(f"workers: must be ≥ 0, got {n}")
    with (
        LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        Client(cluster) as client,
    ):
        yield client
