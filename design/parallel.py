"""Where tasks run: in-process, or on dask.distributed (an embedded LocalCluster or a scheduler).

The design layer takes an optional ``client``; with none, the same code runs serially.
Results stream back in completion order (``as_completed``); a lost worker's tasks are retried.
Every task runs with single-threaded BLAS: parallelism is across tasks, small matrices gain
nothing from threads, and a threaded BLAS rounds differently — with it, a serial run and a
dask run of the same campaign would not give the same table.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from threadpoolctl import threadpool_limits

SCHEDULER_ENV = "RAILOPT_SCHEDULER"


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


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None) -> Iterator[Any]:
    """A dask client: ``scheduler`` address (or $RAILOPT_SCHEDULER) if given, else a LocalCluster.

    ``workers`` = number of worker processes of the embedded cluster (one thread each); ``0``
    yields ``None`` (serial, in-process).
    """
    scheduler = scheduler or os.environ.get(SCHEDULER_ENV) or None
    if scheduler is None and workers == 0:
        yield None
        return
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        with Client(scheduler) as client:
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
