"""The driver writes the kernel cache before a cluster's workers start: a fresh process then loads every kernel
of the certified path from disk (numba's cache hits) instead of compiling it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pytest

from railopt.studies import kind

ROOT = Path(__file__).resolve().parents[2]

PROBE = """
import json, sys
from railopt.models import kernels
from railopt.studies.kernel_warmup import warm_kernels
warm_kernels(show_progress=False)
if sys.argv[1] == "worker":  # what a campaign's dask tasks run: flagship starts with gradients, a surface row
    import numpy as np
    from pathlib import Path
    from railopt.studies.config import load_study
    from railopt.studies.kinds.campaign import campaign_problem
    _, config, _ = load_study(Path("studies/cab_lateral_minimax.toml"))
    setup = config.setups()["sd40-2"]
    names = [v.name for v in config.design.variables]
    x0 = np.array([setup.named_designs["existing"][n] for n in names])
    for objective in ("exact", "thesis"):
        campaign_problem(config, setup, objective).evaluate(x0, gradient=True)
    campaign_problem(config, setup, "exact", "unconstrained").values(np.array([x0, 1.1 * x0]))
used = {name: (d.stats.cache_hits, d.stats.cache_misses) for name, d in vars(kernels).items()
        if hasattr(d, "stats") and (d.stats.cache_hits or d.stats.cache_misses)}
print(json.dumps({name: [sum(h.values()), sum(m.values())] for name, (h, m) in used.items()}))
"""


def _probe(cache, role: str) -> dict[str, list[int]]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", PROBE, role], env=env, capture_output=True, text=True, timeout=300,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_after_the_warm_up_a_fresh_process_loads_every_kernel_from_the_cache(tmp_path):
    cold = _probe(tmp_path, "driver")  # the driver's warm-up compiles and writes the cache (misses)
    assert cold and all(misses >= 1 for _, misses in cold.values())
    worker = _probe(tmp_path, "worker")  # a worker started afterwards runs the campaign's own work
    # every kernel the worker's work calls from Python is loaded, none compiled (callees compiled into a caller
    # show up only in the cold process: they travel inside the caller's cached code)
    assert worker and all(hits >= 1 and misses == 0 for hits, misses in worker.values()), worker


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


NONLINEAR_PROBE = """
import json, sys
from railopt.models.vehicle import wheelset_kernel
if sys.argv[1] == "driver":
    from railopt.studies.kernel_warmup import warm_nonlinear_kernels
    warm_nonlinear_kernels(show_progress=False)
else:  # what a nonlinear_hunting check's task runs: the profile vehicle's rhs, Jacobian and contact state
    import numpy as np
    from railopt.models.vehicle import load_vehicle
    from railopt.models.vehicle.hunting import profile_vehicle
    model = profile_vehicle(load_vehicle("tests/models/vehicle/data/wheelset-s1002.toml"))
    x = np.zeros(2 * model.n_dof)
    x[0] = 1e-3
    model.rhs(0.0, x, 40.0), model.jacobian(x, 40.0), model.contact_state(x, 40.0)
used = {name: (d.stats.cache_hits, d.stats.cache_misses) for name, d in vars(wheelset_kernel).items()
        if hasattr(d, "stats") and (d.stats.cache_hits or d.stats.cache_misses)}
print(json.dumps({name: [sum(h.values()), sum(m.values())] for name, (h, m) in used.items()}))
"""


@pytest.mark.slow
def test_after_the_nonlinear_warm_up_a_check_loads_the_wheel_rail_kernels_from_the_cache(tmp_path):
    """A campaign with a ``nonlinear_hunting`` check warms the wheel/rail kernels in the driver
    (``warm_nonlinear_kernels``): the check's work in a fresh process then compiles none of them."""
    def probe(role: str, cache: Path = tmp_path) -> dict[str, list[int]]:
        env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
        done = subprocess.run([sys.executable, "-c", NONLINEAR_PROBE, role], env=env, capture_output=True,
                              text=True, timeout=300, cwd=ROOT)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout.strip().splitlines()[-1])

    unwarmed = probe("worker", tmp_path / "elsewhere")  # the probe sees a compile where there is one
    assert unwarmed["vehicle_rhs"][1] >= 1 and unwarmed["vehicle_jacobian"][1] >= 1
    cold = probe("driver")
    assert {"vehicle_rhs", "vehicle_jacobian", "wheelset_forces"} <= set(cold)
    assert all(misses >= 1 for _, misses in cold.values())
    worker = probe("worker")
    assert {"vehicle_rhs", "vehicle_jacobian", "wheelset_forces"} <= set(worker)
    assert all(hits >= 1 and misses == 0 for hits, misses in worker.values()), worker
