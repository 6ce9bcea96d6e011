"""Workers of the embedded LocalCluster stay quiet when their scheduler goes first: Ctrl-C reaches the whole process
group, the main process closes the cluster, and a worker whose heartbeat then fails must not print an ERROR with a
traceback (it did under load in test_faults_parallel.py's Ctrl-C test).  The filter is checked inside a real worker
on real log records: the heartbeat failure is dropped, any other error of the same logger still goes through."""

from __future__ import annotations

import logging

import pytest

from railopt.design._worker_setup import SCHEDULER_GONE
from railopt.design.parallel import dask_client


def _passes(message: str) -> bool:
    log = logging.getLogger("distributed.worker")
    record = log.makeRecord(log.name, logging.ERROR, __file__, 1, message, (), None)
    return bool(log.filter(record))


@pytest.mark.timeout(120)
def test_worker_drops_the_heartbeat_failure_and_nothing_else():
    with dask_client(workers=1) as client:
        dropped = next(iter(client.run(_passes, f"{SCHEDULER_GONE}.").values()))
        kept = next(iter(client.run(_passes, "Compute Failed: a real error").values()))
    assert dropped is False and kept is True
    assert _passes(f"{SCHEDULER_GONE}.")  # the main process's own logger is untouched
