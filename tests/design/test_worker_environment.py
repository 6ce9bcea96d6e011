"""The embedded LocalCluster's workers start without dask's ``MALLOC_TRIM_THRESHOLD_=65536``.

Dask's nanny sets that variable in every worker it spawns (``distributed.nanny.pre-spawn-environ``), to hand freed
memory back to the OS early.  Setting it also switches off glibc's adaptive mmap threshold (mallopt(3):
M_MMAP_THRESHOLD is fixed once M_TRIM_THRESHOLD is set), so every array over 128 kB is a fresh mmap whose pages
fault in on first touch — the flagship's starts ran 5–8 % slower in a worker than in a plain process.  Checked here
by what the variable does, not by the variable alone: a worker that allocates, fills and frees a 1 MB array 50 times
takes ~256 page faults per round with it (4 kB pages), and next to none without it (glibc raises the threshold after
the first free and reuses the heap).  A ``MALLOC_TRIM_THRESHOLD_`` of the user's own environment still wins.
"""

from __future__ import annotations

import os
import resource
import sys

import numpy as np
import pytest

from railopt.design import dask_client

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc (Linux)")

ROUNDS = 50


def _faults_per_round(_=None) -> float:
    np.ones(131_072).sum()  # one round first: the threshold adapts on the first free
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _round in range(ROUNDS):
        a = np.empty(131_072)  # 1 MB, over glibc's initial 128 kB mmap threshold
        a.fill(1.0)
        del a
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / ROUNDS


def _trim_threshold(_=None) -> str | None:
    return os.environ.get("MALLOC_TRIM_THRESHOLD_")


@pytest.mark.timeout(120)
def test_workers_keep_glibcs_adaptive_mmap_threshold(monkeypatch) -> None:
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    with dask_client(workers=1) as client:
        assert set(client.run(_trim_threshold).values()) == {None}
        assert max(client.run(_faults_per_round).values()) < 20  # the heap is reused: no page faults a round


@pytest.mark.timeout(120)
def test_the_users_own_trim_threshold_still_wins_and_costs_the_page_faults(monkeypatch) -> None:
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")
    with dask_client(workers=1) as client:
        assert set(client.run(_trim_threshold).values()) == {"65536"}
        assert min(client.run(_faults_per_round).values()) > 200  # 1 MB = 256 pages of 4 kB, mapped afresh
