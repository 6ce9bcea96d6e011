"""The driver writes the kernel cache before a cluster's workers start: a fresh process then loads every kernel
of the certified path from disk (numba's cache hits) instead of compiling it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from contextlib import contextmanager

import pytest

from railopt.studies import kind

PROBE = """
import json
from railopt.models import kernels
from railopt.studies.kernel_warmup import warm_kernels
warm_kernels(show_progress=False)
used = {name: (d.stats.cache_hits, d.stats.cache_misses) for name, d in vars(kernels).items()
        if hasattr(d, "stats") and (d.stats.cache_hits or d.stats.cache_misses)}
print(json.dumps({name: [sum(h.values()), sum(m.values())] for name, (h, m) in used.items()}))
"""


def _probe(cache) -> dict[str, list[int]]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_after_the_warm_up_a_fresh_process_loads_every_kernel_from_the_cache(tmp_path):
    cold = _probe(tmp_path)  # compiles everything and writes it (cache misses)
    assert cold and all(misses >= 1 for _, misses in cold.values())
    warm = _probe(tmp_path)  # a worker started afterwards
    # every kernel the worker calls from Python is loaded, none compiled (callees compiled into a caller show up
    # only in the cold process: they travel inside the caller's cached code)
    assert warm and set(warm) <= set(cold)
    assert all(hits >= 1 and misses == 0 for hits, misses in warm.values()), warm


@pytest.mark.parametrize("workers, warmed", [(2, True), (None, True), (0, False)])
def test_the_study_context_warms_the_kernels_before_any_cluster_starts(monkeypatch, tmp_path, workers, warmed):
    events = []
    monkeypatch.setattr("railopt.studies.kernel_warmup.warm_kernels", lambda show: events.append("warm"))

    @contextmanager
    def fake_client(workers, scheduler, timeout=None):
        events.append("cluster")
        yield None

    monkeypatch.setattr("railopt.design.parallel.dask_client", fake_client)
    context = kind.StudyContext(store_dir=tmp_path, workers=workers)
    with kind.dask_context(context):
        pass
    assert events == (["warm", "cluster"] if warmed else ["cluster"])
