"""Faults of the dask paths: a start that kills its worker, unpicklable problems, wrong or lost schedulers.

Real processes only (an embedded LocalCluster, ``dask scheduler``/``dask worker`` subprocesses, TCP servers on
127.0.0.1), each bounded in time.  Values are checked against the closed form of the test problem:
f = ((a − 0.6)² + b, (b − 0.2)² + 0.1) on [0, 1]², U* = 0.7 − √0.35 = 0.108392 at a = 0.6 where f1 = f2.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import dask
import distributed  # noqa: F401  (its config holds the connect timeout)
import numpy as np
import pytest
from dask.utils import parse_timedelta

from railopt.design import (
    CampaignStore,
    DesignVariable,
    MinimaxProblem,
    check_designs,
    epsilon_sweep,
    multistart,
    objective_surface,
)
from railopt.design.parallel import SCHEDULER_MARGIN, SchedulerError, dask_client, map_unordered

U_STAR = 0.7 - np.sqrt(0.35)
# A hang guard, not a timing of railopt (timings are `railopt bench` rows): what a client without our timeouts waits
# for a silent or lost scheduler, dask's own connect timeout (30 s).  Our failures come after the test's timeout
# (2-3 s) plus SCHEDULER_MARGIN; the guard only tells "gave up on our timeout" from "waited for dask's".
HANG_S = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"))
assert HANG_S > 3 + SCHEDULER_MARGIN  # the guard separates the two
VARIABLES = [DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)]


def _f(x: np.ndarray) -> np.ndarray:
    return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])


@dataclass(frozen=True)
class Poisoned:
    """The model crashes its process (as a segfault in native code would) for a < 0.12, after noting it in ``log``."""

    log: str
    crash: bool = True

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if self.crash and x[0] < 0.12:
            with open(self.log, "a") as fh:
                fh.write(f"{os.getpid()}\n")
            os._exit(1)
        return _f(x)


def _crashes(log: Path) -> int:
    return len(log.read_text().splitlines()) if log.exists() else 0


@pytest.mark.timeout(240)
def test_a_start_that_kills_its_worker_is_stored_as_lost_and_not_retried_unless_asked(tmp_path: Path) -> None:
    log = tmp_path / "crashes.txt"
    path = tmp_path / "poison.sqlite"
    poisoned = MinimaxProblem(VARIABLES, Poisoned(str(log)))
    args = {"n_starts": 7, "method": "slsqp", "seed": 3, "points": [[0.05, 0.5]]}
    with dask_client(workers=2) as client, CampaignStore.create(path, "p", {}, ["a", "b"]) as store:
        table = multistart(poisoned, client=client, store=store, **args)
        assert list(table["start_id"]) == list(range(8))
        lost = table[table["status"] == "worker_lost"]
        assert 0 in set(lost["start_id"])  # the user point a = 0.05 < 0.12
        assert lost["message"].str.contains("worker lost").all() and lost["message"].str.contains("tcp://").all()
        assert np.all(np.isinf(lost["value"])) and not lost["success"].any()
        solved = table[table["status"] == "converged"]
        assert len(solved) + len(lost) == 8 and len(solved) >= 4
        np.testing.assert_allclose(solved["value"], U_STAR, atol=1e-7)  # closed form
        # exactly the starts that crash are lost (a < 0.12, from their x0): dask also blames a death on a task
        # queued on the dying worker, so a lost task's starts run again alone before one is stored as lost
        assert set(lost["start_id"]) == set(table.loc[table["x0_a"] < 0.12, "start_id"])
        crashes = _crashes(log)
        # each lost start killed two workers by itself in the run alone, and at most two before it; no other crashed
        assert 2 * len(lost) <= crashes <= 4 * len(lost)

        # a resume does not try the lost starts again: no new crash, the table unchanged
        again = multistart(poisoned, client=client, store=store, **args)
        assert _crashes(log) == crashes
        assert list(again["status"]) == list(table["status"])

        # asked to, it retries them (the model fixed): each replaced once, every start stored exactly once
        fixed = MinimaxProblem(VARIABLES, Poisoned(str(log), crash=False))
        retried = multistart(fixed, client=client, store=store, retry_failed=True, **args)
        assert _crashes(log) == crashes
        assert list(retried["start_id"]) == list(range(8)) and set(retried["status"]) == {"converged"}
        np.testing.assert_allclose(retried["value"], U_STAR, atol=1e-7)
        assert store.lost_ids() == set()
    # the finished rows were never rewritten by the resumes
    with CampaignStore.open(path, read_only=True) as s:
        rows = s.starts().set_index("start_id")
    kept = table.set_index("start_id")
    ok = kept["status"] == "converged"
    np.testing.assert_array_equal(rows.loc[ok[ok].index, "value"], kept.loc[ok, "value"])


@pytest.mark.timeout(240)
def test_a_batch_with_a_crashing_start_loses_only_that_start(tmp_path: Path) -> None:
    """Starts batched several per task: a batch lost to a crash is run again one start per task, so exactly the
    starts that crash (a < 0.12, known from x0) are stored as lost, and every other row is the serial one."""
    log = tmp_path / "crashes.txt"
    args = {"n_starts": 23, "method": "slsqp", "seed": 11, "points": [[0.05, 0.5]]}
    serial = multistart(MinimaxProblem(VARIABLES, Poisoned(str(log), crash=False)), **args)
    poisoned = MinimaxProblem(VARIABLES, Poisoned(str(log)))
    with dask_client(workers=2) as client:
        table = multistart(poisoned, client=client, batch=4, **args)
    crashing = set(serial.loc[serial["x0_a"] < 0.12, "start_id"])
    assert 2 <= len(crashing) < 8  # the case has something to isolate, and more than one batch survives
    assert set(table.loc[table["status"] == "worker_lost", "start_id"]) == crashing
    kept = table[~table["start_id"].isin(crashing)].reset_index(drop=True)
    ref = serial[~serial["start_id"].isin(crashing)].reset_index(drop=True)
    for col in ("start_id", "a", "b", "value", "evaluations", "status"):
        np.testing.assert_array_equal(kept[col], ref[col])
    np.testing.assert_allclose(kept["value"], U_STAR, atol=1e-7)  # closed form


@dataclass(frozen=True)
class Storm:
    """Crashes its process for a < 0.4 and b > 0.5 (about one start in five)."""

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if x[0] < 0.4 and x[1] > 0.5:
            os._exit(1)
        return _f(x)


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_many_crashing_starts_do_not_exhaust_the_cluster() -> None:
    """A dozen crashing starts (each kills up to four workers): dask would close a nanny whose worker is still
    restarting 15 s after a crash and leave the cluster without workers; the embedded cluster never gives one up,
    so the campaign ends with exactly the crashing starts lost and every other row the serial one."""
    args = {"n_starts": 59, "method": "slsqp", "seed": 5, "points": [[0.1, 0.9]]}
    serial = multistart(MinimaxProblem(VARIABLES, _f), **args)
    crashing = set(serial.loc[(serial["x0_a"] < 0.4) & (serial["x0_b"] > 0.5), "start_id"])
    assert len(crashing) >= 9
    with dask_client(workers=2) as client:
        table = multistart(MinimaxProblem(VARIABLES, Storm()), client=client, **args)
    assert set(table.loc[table["status"] == "worker_lost", "start_id"]) == crashing
    kept = table[~table["start_id"].isin(crashing)].reset_index(drop=True)
    ref = serial[~serial["start_id"].isin(crashing)].reset_index(drop=True)
    for col in ("start_id", "a", "b", "value", "evaluations", "status"):
        np.testing.assert_array_equal(kept[col], ref[col])


def test_batch_must_be_a_positive_whole_number() -> None:
    problem = MinimaxProblem(VARIABLES, _f)
    for bad in (0, -2, 1.5, True, "4"):
        with pytest.raises(ValueError, match="batch"):
            multistart(problem, 4, batch=bad)
    assert len(multistart(problem, 4, batch=np.int64(2))) == 4  # numpy integers are whole numbers


# ---------------------------------------------------------------------- unpicklable problems


def _locked_problem() -> tuple[MinimaxProblem, threading.Lock]:
    lock = threading.Lock()

    def functions(x: np.ndarray) -> np.ndarray:
        with lock:
            return _f(x)

    def g(x: np.ndarray) -> np.ndarray:
        with lock:
            return np.array([x[1]])

    return MinimaxProblem(VARIABLES, functions, constraints=g, epsilon=0.5), lock


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=1) as c:
        yield c


@pytest.mark.timeout(120)
def test_an_unpicklable_problem_is_named_before_anything_is_submitted(client, tmp_path: Path) -> None:
    problem, _ = _locked_problem()
    # serially it runs, and gives the closed-form optimum
    serial = multistart(problem, 4, seed=0)
    assert serial["value"].min() == pytest.approx(U_STAR, abs=1e-7)
    with CampaignStore.create(tmp_path / "c.sqlite", "c", {}, ["a", "b"]) as store:
        with pytest.raises(ValueError, match=r"^problem\.functions\.lock: cannot be sent to dask workers "
                                             r"\(TypeError: cannot pickle '_thread\.lock' object\).*workers=0"):
            multistart(problem, 4, seed=0, client=client, store=store)
        assert store.finished_ids() == set()  # refused before any start was solved
    assert client.who_has() == {} or not any(client.who_has().values())  # nothing was submitted
    with pytest.raises(ValueError, match=r"^problem\.functions\.lock: cannot be sent"):
        objective_surface(problem, ("a", "b"), [0.1, 0.2], [0.3], [0.5, 0.5], client=client)
    with pytest.raises(ValueError, match=r"^problem\.functions\.lock: cannot be sent"):
        epsilon_sweep(problem, [0.3], n_starts=2, client=client)
    lock = threading.Lock()

    def check(x: np.ndarray) -> tuple[float, dict]:
        with lock:
            return float(x[0]), {}

    designs = serial[["start_id", "a", "b"]]
    with pytest.raises(ValueError, match=r"^check\.lock: cannot be sent to dask workers"):
        check_designs(check, designs, ["a", "b"], "c", client=client)
    with pytest.raises(ValueError, match=r"^\[0\]: cannot be sent|^lock: cannot be sent|cannot be sent"):
        list(map_unordered(len, [[threading.Lock()]], client=client))
    # the same checks on a picklable problem pass and agree with the serial run (second method)
    plain = MinimaxProblem(VARIABLES, _f)
    on_dask = multistart(plain, 4, seed=0, client=client)
    np.testing.assert_allclose(on_dask["value"], multistart(plain, 4, seed=0)["value"], rtol=0, atol=0)


# ---------------------------------------------------------------------- schedulers


def _serve(reply: bytes | None) -> tuple[socket.socket, list[socket.socket]]:
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    held: list[socket.socket] = []

    def loop() -> None:
        while True:
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            if reply:
                try:
                    conn.sendall(reply)
                except OSError:
                    pass
            held.append(conn)

    threading.Thread(target=loop, daemon=True).start()
    return srv, held


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("reply", "said"), [
    (b"HTTP/1.0 400 Bad Request\r\n\r\nnot dask\r\n" * 50, "did not answer as a dask scheduler"),
    (None, "did not answer as a dask scheduler within"),
], ids=["http-server", "silent-server"])
def test_a_server_that_is_not_a_scheduler_fails_within_the_timeout(reply: bytes | None, said: str) -> None:
    srv, held = _serve(reply)
    address = f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    began = time.monotonic()
    with pytest.raises(SchedulerError, match=said) as err, dask_client(scheduler=address, timeout=2):
        pass
    elapsed = time.monotonic() - began
    assert address in str(err.value) and "--workers N" in str(err.value)
    assert elapsed >= 2 or reply is not None, elapsed  # a silent server is given the whole timeout
    assert elapsed < HANG_S, elapsed
    srv.close()
    for c in held:
        c.close()


def _start(*args: str) -> subprocess.Popen:
    """A dask process in its own session; it can import this module (the tasks' classes live here)."""
    path = os.pathsep.join([str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")])
    return subprocess.Popen([sys.executable, "-m", *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True, env={**os.environ, "PYTHONPATH": path})


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)  # started by this test in its own session
    proc.wait()


@pytest.fixture
def scheduler(tmp_path: Path):
    from dask_scheduler import scheduler_address  # here: a dask worker that imports this module has no tests/

    file = tmp_path / "scheduler.json"
    proc = _start("distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                  "--scheduler-file", str(file))
    try:
        address = scheduler_address(file, proc)
    except AssertionError:
        _stop(proc)
        raise
    yield address, proc
    _stop(proc)


@pytest.mark.timeout(60)
def test_a_scheduler_without_workers_is_named_within_the_timeout(scheduler) -> None:
    address, _ = scheduler
    began = time.monotonic()
    with pytest.raises(SchedulerError, match="has no workers") as err, dask_client(scheduler=address, timeout=2):
        pass
    elapsed = time.monotonic() - began
    assert address in str(err.value) and "waited 2 s" in str(err.value)
    assert 2 <= elapsed < HANG_S, elapsed  # it waited the timeout for a worker to join, then gave up


@dataclass(frozen=True)
class Slow:
    """f of the closed-form problem, 20 ms per evaluation (a start takes about a second)."""

    def __call__(self, x: np.ndarray) -> np.ndarray:
        time.sleep(0.02)
        return _f(x)


@pytest.mark.timeout(180)
def test_a_lost_scheduler_is_one_error_and_the_finished_starts_are_kept(scheduler, tmp_path: Path) -> None:
    address, proc = scheduler
    worker = _start("distributed.cli.dask_worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard")
    path = tmp_path / "c.sqlite"
    problem = MinimaxProblem(VARIABLES, Slow())
    killed_at: list[float] = []

    def kill_after_two(done: int, total: int) -> None:
        if done >= 2 and not killed_at:
            os.killpg(proc.pid, signal.SIGKILL)
            killed_at.append(time.monotonic())

    try:
        with CampaignStore.create(path, "c", {}, ["a", "b"]) as store:
            with pytest.raises(SchedulerError) as err, dask_client(scheduler=address, timeout=3) as client:
                multistart(problem, 12, seed=2, client=client, store=store, progress=kill_after_two)
            waited = time.monotonic() - killed_at[0]
            kept = store.starts()
    finally:
        _stop(worker)
    assert str(err.value) == (f"scheduler: lost the connection to {address!r}; finished starts are kept, "
                              "rerun with --resume")
    assert waited < HANG_S, waited
    assert 2 <= len(kept) < 12
    # the resume (serial) completes every start exactly once and keeps the finished ones as they were
    with CampaignStore.open(path) as store:
        table = multistart(problem, 12, seed=2, store=store)
    assert list(table["start_id"]) == list(range(12))
    np.testing.assert_allclose(table["value"].min(), U_STAR, atol=1e-7)
    again = table.set_index("start_id").loc[kept["start_id"]]
    np.testing.assert_array_equal(again["value"], kept["value"].to_numpy())


CTRL_C = """
import sys, time
from railopt.design.parallel import dask_client, map_unordered


def slow(i):
    time.sleep(0.2)
    return i


if __name__ == "__main__":
    try:
        with dask_client(workers=2) as client:
            print("pids", *client.run(lambda: __import__("os").getpid()).values(), flush=True)
            for i in map_unordered(slow, range(10_000), client=client):
                if i == 3:
                    print("running", flush=True)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
"""


@pytest.mark.timeout(120)
def test_ctrl_c_to_the_process_group_prints_no_worker_traceback(tmp_path: Path) -> None:
    """SIGINT to the whole group (what Ctrl-C in a terminal does): the workers ignore it, dask says nothing."""
    from terminal import as_a_foreground_job  # here: a dask worker that imports this module has no tests/
    script = tmp_path / "ctrl_c.py"
    script.write_text(CTRL_C)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=as_a_foreground_job)
    pids = [int(p) for p in proc.stdout.readline().split()[1:]]
    assert len(pids) == 2
    assert proc.stdout.readline().strip() == "running"
    os.killpg(proc.pid, signal.SIGINT)  # the group this test started
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip() == "interrupted", err  # no "Traceback", no "KeyboardInterrupt", no dask WARNING lines
    for pid in pids:  # the workers were shut down by the main process, not killed by the signal
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
