"""Faults of the campaign store with other processes: a reader never blocks the writer (WAL), a writer killed
with ``kill -9`` loses nothing it committed, a full disk is reported naming the file.

Real processes only.  Values against the closed form f = ((a − 0.6)² + b, (b − 0.2)² + 0.1), U* = 0.7 − √0.35.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
from contextlib import closing
from pathlib import Path

import numpy as np
import pytest

from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart
from railopt.design.store import StoreError

U_STAR = 0.7 - np.sqrt(0.35)
PROBLEM = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)],
                         lambda x: np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1]))


def _reader(path: Path, seconds: float) -> subprocess.Popen:
    """A second process that opens the store as a notebook would and keeps a read transaction open."""
    code = f"""
import sqlite3, time
cur = sqlite3.connect({str(path)!r}).execute('SELECT * FROM starts'); cur.fetchone()
print('reading', flush=True); time.sleep({seconds})
"""
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, start_new_session=True)
    assert proc.stdout.readline().strip() == "reading"
    return proc


def _journal_mode(path: Path) -> str:
    """The journal mode recorded in the file header (bytes 18-19: 1 = rollback, 2 = WAL)."""
    header = path.read_bytes()[:20]
    return {1: "delete", 2: "wal"}[header[18]]


@pytest.mark.timeout(120)
def test_a_reader_holding_a_transaction_does_not_block_the_campaign(tmp_path: Path) -> None:
    path = tmp_path / "monitored.sqlite"
    store = CampaignStore.create(path, "m", {}, ["a", "b"])
    multistart(PROBLEM, 3, seed=1, store=store)
    reader = _reader(path, 60)
    try:
        table = multistart(PROBLEM, 12, seed=1, store=store)
        assert reader.poll() is None  # the reader still holds its transaction: the writer did not wait for it
        # the reader's process sees the committed starts too (its own new transaction)
        with closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as db:
            assert db.execute("SELECT count(*) FROM starts").fetchone()[0] == 12
    finally:
        reader.kill()
        reader.wait()
    store.close()
    assert list(table["start_id"]) == list(range(12))  # the same seed: the 3 stored starts are ids 0-2 of the 12
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-7)
    # (the old store failed after sqlite's 5 s busy timeout, "database is locked": the table above is complete)
    assert _journal_mode(path) == "delete"  # closed: one self-contained file again
    assert sorted(p.name for p in tmp_path.iterdir()) == ["monitored.sqlite"]


def test_journal_modes_and_read_only_open(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite"
    with CampaignStore.create(path, "c", {}, ["a", "b"]) as store:
        assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        multistart(PROBLEM, 2, seed=0, store=store)
        with CampaignStore.open(path, read_only=True) as live:  # a live store, read while it is open for writing
            assert sorted(live.finished_ids()) == [0, 1]
            with pytest.raises(StoreError, match=f"cannot write start 9 to {path}.*readonly"):
                live.add_start(9, "user", 0, multistart(PROBLEM, 1, seed=0).iloc[0])
    assert _journal_mode(path) == "delete"
    with CampaignStore.open(path) as store:  # a closed (rollback-journal) store opens for writing as before
        assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert len(store.starts()) == 2


WRITER = textwrap.dedent("""
    import sys, time
    import numpy as np
    from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart

    def f(x):
        time.sleep(0.01)
        return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])

    problem = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], f)
    store = CampaignStore.open(sys.argv[1])
    multistart(problem, 40, seed=4, store=store, progress=lambda done, total: print(done, flush=True))
    print("finished", flush=True)
""")


@pytest.mark.timeout(180)
def test_kill_9_of_the_writer_with_a_reader_attached_keeps_every_finished_start_once(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite"
    CampaignStore.create(path, "c", {}, ["a", "b"]).close()
    script = tmp_path / "writer.py"
    script.write_text(WRITER)
    reader = _reader(path, 120)
    writer = subprocess.Popen([sys.executable, str(script), str(path)], stdout=subprocess.PIPE, text=True,
                              start_new_session=True)
    try:
        while int(writer.stdout.readline() or -1) < 6:
            assert writer.poll() is None
        os.kill(writer.pid, signal.SIGKILL)
        writer.wait()
        assert (tmp_path / "c.sqlite-wal").exists()  # the commits may still be in the log only
        with closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as db:  # what a fresh reader sees
            before = db.execute("SELECT start_id, finished_utc, value FROM starts ORDER BY start_id").fetchall()
        assert len(before) >= 6
        with CampaignStore.open(path) as store:  # the reader is still attached
            table = multistart(PROBLEM, 40, seed=4, store=store)
            rows = store._db.execute("SELECT start_id, finished_utc, value FROM starts ORDER BY start_id").fetchall()
    finally:
        reader.kill()
        reader.wait()
    assert [r[0] for r in rows] == list(range(40))  # every start exactly once (start_id is the key)
    assert rows[: len(before)] == before  # the starts finished before the kill, unchanged
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-7)
    assert len(table) == 40 and table["start_id"].is_unique


DISK = textwrap.dedent("""
    import resource, signal, sys
    import numpy as np
    from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, solve
    from railopt.design.store import StoreError

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG, as on a full disk
    limit = int(sys.argv[2])
    problem = MinimaxProblem([DesignVariable("a", 0.0, 1.0)], lambda x: np.array([x[0] ** 2]))
    result = solve(problem, [0.5])
    try:
        if limit == 0:
            resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
            CampaignStore.create(sys.argv[1], "c", {}, ["a"])
        else:
            store = CampaignStore.create(sys.argv[1], "c", {}, ["a"])
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
            for i in range(10000):
                store.add_start(i, "user", 0, result)
    except StoreError as exc:
        print("StoreError:", exc)
""")


@pytest.mark.parametrize("limit", [0, 60_000], ids=["creating", "writing"])
def test_a_full_disk_is_reported_naming_the_store(tmp_path: Path, limit: int) -> None:
    script = tmp_path / "disk.py"
    script.write_text(DISK)
    path = tmp_path / "sub" / "c.sqlite"
    done = subprocess.run([sys.executable, str(script), str(path), str(limit)], capture_output=True, text=True,
                          timeout=120)
    line = done.stdout.strip()
    assert line.startswith("StoreError: store: cannot "), (done.stdout, done.stderr)
    assert str(path) in line and ("full" in line or "too large" in line or "I/O" in line), line
    if limit == 0:
        assert not path.exists() and list(path.parent.iterdir()) == []  # no half-made store, no temporary file
    else:
        assert "cannot write start" in line
        with CampaignStore.open(path) as store:  # what was committed before the disk filled is intact
            n = len(store.finished_ids())
        assert n > 10 and f"start {n} " in line
