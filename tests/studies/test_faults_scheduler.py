"""Fault tests of the dask scheduler choice: a dead scheduler fails fast by name; flags beat the environment; a
worker lost on an external cluster is said, and ``timing.csv`` records the workers at the start and the end."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import dask
import distributed  # noqa: F401  (its config holds the connect timeout)
import pandas as pd
import pytest
from dask.distributed import Client
from dask.utils import parse_timedelta
from dask_scheduler import scheduler_address
from faults_cli import (
    STUDY,
    assert_refused,
    cli,
    count_starts,
    env,
    run_args,
    start,
    start_rows,
    store_path,
    study_file,
    wait_until,
)

from railopt.studies.cli import main

DEAD = "tcp://127.0.0.1:1"  # nothing listens on port 1
# A hang guard, not a timing (timings are `railopt bench` rows): what a run without our timeout waited, dask's own
# connect timeout; a refusal on our timeout (1-5 s) plus a CLI start is told from it however loaded the machine.
HANG_S = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"))


@pytest.fixture
def study(tmp_path):
    return study_file(tmp_path / "study", 3)


@pytest.mark.parametrize("how", ["flag", "environment"])
def test_an_unreachable_scheduler_fails_fast_naming_the_address(how, study, tmp_path):
    results = tmp_path / "results"
    if how == "flag":
        args, environ = run_args(study, results, "--scheduler", DEAD, "--scheduler-timeout", "1", workers=None), env()
    else:
        args = run_args(study, results, workers=None)
        environ = env(RAILOPT_SCHEDULER=DEAD, RAILOPT_SCHEDULER_TIMEOUT="1")
    began = time.monotonic()
    done = cli(*args, environ=environ)
    elapsed = time.monotonic() - began
    assert_refused(done, f"cannot connect to '{DEAD}' within 1 s", "--workers N")  # our timeout was the one used
    assert elapsed < HANG_S, elapsed  # a hang guard: the run waited dask's own 30 s, then printed a traceback
    assert list(results.iterdir()) == []  # nothing published, no staging, lock released


@pytest.mark.slow
def test_the_default_scheduler_timeout_is_a_few_seconds(study, tmp_path):
    began = time.monotonic()
    done = cli(*run_args(study, tmp_path / "results", "--scheduler", DEAD, workers=None))
    elapsed = time.monotonic() - began
    assert_refused(done, DEAD, "within 5 s")
    assert 5 <= elapsed < HANG_S, elapsed  # it waited the default 5 s (well-determined), not dask's 30 s


def test_explicit_workers_0_beats_RAILOPT_SCHEDULER(study, tmp_path):
    """The environment names a dead scheduler; ``--workers 0`` asks for serial and gets it."""
    results = tmp_path / "results"
    done = cli(*run_args(study, results, workers="0"), environ=env(RAILOPT_SCHEDULER=DEAD))
    assert done.returncode == 0, done.stderr
    assert [r[0] for r in start_rows(store_path(results))] == [0, 1, 2, 3]
    assert (results / STUDY / "summary.md").is_file()


@pytest.mark.parametrize(
    ("extra", "environ", "named"),
    [
        (["--workers", "1", "--scheduler", DEAD], {}, "--workers and --scheduler"),
        (["--scheduler", DEAD, "--scheduler-timeout", "0"], {}, "--scheduler-timeout"),
        (["--scheduler", DEAD], {"RAILOPT_SCHEDULER_TIMEOUT": "soon"}, "RAILOPT_SCHEDULER_TIMEOUT"),
        (["--scheduler", "nonsense"], {}, "'nonsense' is not a valid address"),
    ],
)
def test_bad_scheduler_flags_are_named(extra, environ, named, study, tmp_path, monkeypatch, capsys):
    """In-process (quicker): an exception escaping ``main`` would fail the test as a traceback would."""
    for key, value in environ.items():
        monkeypatch.setenv(key, value)
    results = tmp_path / "results"
    assert main(run_args(study, results, *extra, workers=None)) == 2
    err = capsys.readouterr().err
    assert err.startswith("railopt: error:") and err.count("\n") == 1 and named in err, err
    assert not results.exists() or list(results.iterdir()) == []  # nothing written, lock released


# ---------------------------------------------------------------------------------------------- a lost worker (item 14)
def _own_session(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True, env=env())


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_a_worker_lost_on_an_external_cluster_is_said_and_timing_records_the_workers(tmp_path):
    """An external cluster of two workers (no nanny: a killed worker stays dead) loses one while the campaign runs:
    the run finishes with every start once, says that the worker left and its tasks were re-run, and ``timing.csv``
    records 2 workers at the start, 1 at the end, 2 at most, 1 lost."""
    file = tmp_path / "scheduler.json"
    procs = [_own_session("distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                          "--no-dashboard", "--scheduler-file", str(file))]
    try:
        address = scheduler_address(file, procs[0])
        procs += [_own_session("distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
                               "--no-dashboard", "--host", "127.0.0.1") for _ in range(2)]
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
        study = study_file(tmp_path / "study", 200)
        results = tmp_path / "results"
        run = start(*run_args(study, results, "--scheduler", address, "--scheduler-timeout", "30", workers=None))
        assert wait_until(run, lambda: count_starts(store_path(results)) >= 5), run.communicate()
        os.killpg(procs[1].pid, signal.SIGKILL)  # one worker, started by this test in its own session
        out, err = run.communicate(timeout=240)
    finally:
        for proc in procs:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert run.returncode == 0, err
    assert [r[0] for r in start_rows(store_path(results))] == list(range(201))  # every start once
    timing = pd.read_csv(results / STUDY / "timing.csv").iloc[0]
    assert (timing["workers_at_start"], timing["workers_at_end"], timing["workers_max"]) == (2, 1, 2)
    assert timing["workers_lost"] == 1 and timing["tasks_rerun"] >= 1
    notes = [line for line in err.splitlines() if line.startswith("railopt: note: ")]
    assert notes == [f"railopt: note: {timing['cluster_events']}"], err
    assert f"1 dask worker left the cluster {address} during the run" in notes[0]
    rerun = int(timing["tasks_rerun"])
    assert f"{rerun} task{' was' if rerun == 1 else 's were'} re-run on other workers" in notes[0]
