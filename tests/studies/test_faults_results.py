"""Fault tests of results folders, publishing and the study lock, from a real CLI process.

Runs are killed during the campaign and during publishing, folders are made unusable (a file
where a folder must be, so that the tests bite when run as root too), two runs of one study are
started at once.  Each test asserts: no traceback, a non-zero exit where the run cannot go on,
the previous results byte-identical, every finished start kept exactly once.
"""

from __future__ import annotations

import os
import signal
import socket
import sqlite3
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from faults_cli import (
    STUDY,
    assert_refused,
    baseline_fixtures,
    cli,
    count_starts,
    dead_pid,
    env,
    read_only,
    run_args,
    snapshot,
    start,
    start_rows,
    store_path,
    study_file,
    wait_until,
)

from railopt.studies.output import publish as publish_module
from railopt.studies.output.publish import lock_path, publish

N_STARTS = 96  # + the Den Hartog start: ids 0..96; ~1.5 s of starts, so that a signal sent once 6 or 8 are stored
# still finds the run going on a loaded machine (with 24, a run under load had finished before its SIGTERM went)
IDS = list(range(N_STARTS + 1))


published, results = baseline_fixtures(N_STARTS)


def _published_files(results: Path) -> dict[str, bytes]:
    """The published folder without its campaign stores (which a resumed run adds starts to)."""
    return {k: v for k, v in snapshot(results / STUDY).items() if not k.startswith("campaigns/")}


def _leftovers(results: Path) -> list[str]:
    return sorted(p.name for p in results.iterdir() if p.name != STUDY)


def _forget_starts_from(store: Path, first: int) -> None:
    """Make the store look like a campaign killed after ``first`` starts."""
    with sqlite3.connect(store) as db:
        db.execute("DELETE FROM starts WHERE start_id >= ?", (first,))
        db.execute("DELETE FROM checks")
    db.close()


# ---------------------------------------------------------------------------------------------- folders
def test_results_root_that_is_a_file_is_named(published, tmp_path):
    study, _ = published
    root = tmp_path / "results"
    root.write_text("a file")
    done = cli(*run_args(study, root))
    assert_refused(done, root, "is a file, not a folder")
    assert root.read_text() == "a file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]


def test_study_folder_that_is_a_file_is_named(published, tmp_path):
    study, _ = published
    root = tmp_path / "results"
    root.mkdir()
    (root / STUDY).write_text("a file")
    done = cli(*run_args(study, root))
    assert_refused(done, root / STUDY, "is a file, not a folder")
    assert (root / STUDY).read_text() == "a file"
    assert sorted(p.name for p in root.iterdir()) == [STUDY]  # no staging, no lock left


@pytest.mark.parametrize("where", ["", STUDY, f"{STUDY}/campaigns"])
def test_read_only_folders_are_named_and_the_previous_results_kept(where, published, results):
    study, _ = published
    folder = results / where
    before, rows = _published_files(results), start_rows(store_path(results))
    with read_only(folder):
        done = cli(*run_args(study, results, "--resume"))
    assert_refused(done, folder)
    assert _published_files(results) == before
    assert start_rows(store_path(results)) == rows
    assert _leftovers(results) == []


# ---------------------------------------------------------------------------------------------- publishing
def test_a_published_file_that_cannot_be_replaced_no_longer_mixes_runs(published, results, tmp_path):
    """The issue's mixed folder: the whole folder is swapped, so every file comes from the new run."""
    study, _ = published
    blocker = results / STUDY / "comparison.csv"
    blocker.unlink()
    blocker.mkdir()
    (blocker / "keep").write_text("a folder where a published file was")
    other_seed = study_file(tmp_path / "seed", N_STARTS)
    other_seed.write_text(other_seed.read_text().replace("seed = 2002", "seed = 7"))
    old_starts = pd.read_csv(results / STUDY / "starts.csv")
    done = cli(*run_args(other_seed, results, "--fresh"))
    assert done.returncode == 0, done.stderr
    new = results / STUDY
    assert blocker.is_file()
    assert (new / "study.toml").read_text() == other_seed.read_text()
    new_starts = pd.read_csv(new / "starts.csv")
    assert not new_starts["x0_tuning"].iloc[1:].equals(old_starts["x0_tuning"].iloc[1:])  # starts of seed 7
    assert "seed 7" in (new / "summary.md").read_text()
    assert [r[0] for r in start_rows(store_path(results))] == IDS
    assert _leftovers(results) == []


def test_a_failed_swap_puts_the_previous_folder_back(tmp_path, monkeypatch):
    final, staging = tmp_path / "study", tmp_path / ".staging-study-1"
    for folder, text in ((final, "old"), (staging, "new")):
        (folder / "campaigns").mkdir(parents=True)
        (folder / "summary.md").write_text(text)
        (folder / "campaigns" / "c.sqlite").write_text(text)
    before = snapshot(final)
    real_rename = os.rename

    def rename(src, dst):
        if Path(src) == staging:
            raise OSError(28, "No space left on device", str(dst))
        real_rename(src, dst)

    monkeypatch.setattr(publish_module.os, "rename", rename)
    with pytest.raises(OSError, match="No space left"):
        publish(staging, final)
    assert snapshot(final) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [".staging-study-1", "study"]  # no .old- left


# ---------------------------------------------------------------------------------------------- kills
def _kill_when(proc: subprocess.Popen, condition, sig: int = signal.SIGKILL) -> None:
    landed = wait_until(proc, condition)
    out, err = (None, None) if landed else proc.communicate()
    assert landed, f"the run ended (rc {proc.returncode}) before it could be killed: {err}"
    assert proc.poll() is None, f"the run ended (rc {proc.returncode}) before the signal went: too few starts left"
    proc.send_signal(sig)
    proc.wait(30)


def _interrupt_a_resumed_campaign(study: Path, results: Path, sig: int, at: int):
    """Resume a campaign that stopped after 4 starts; send ``sig`` once ``at`` starts are stored.

    Returns the process and the published files (stores aside) as they were before.
    """
    store = store_path(results)
    _forget_starts_from(store, 4)
    published_before = _published_files(results)
    proc = start(*run_args(study, results, "--resume"))
    _kill_when(proc, lambda: count_starts(store) >= at, sig=sig)
    return proc, published_before


@pytest.mark.slow
def test_kill_during_a_fresh_campaign_keeps_the_previous_results_and_stores(published, results):
    study, _ = published
    before = snapshot(results)
    proc = start(*run_args(study, results, "--fresh"))
    new_store = results / f".staging-{STUDY}-{proc.pid}" / "campaigns" / store_path(results).name
    _kill_when(proc, lambda: count_starts(new_store) >= 1)
    assert proc.returncode == -signal.SIGKILL
    assert snapshot(results / STUDY) == {k[len(STUDY) + 1:]: v for k, v in before.items()}  # old stores too
    assert f".staging-{STUDY}-{proc.pid}" in _leftovers(results)  # what kill -9 leaves ...
    done = cli(*run_args(study, results, "--resume"))
    assert done.returncode == 0, done.stderr
    assert _leftovers(results) == []  # ... is gone after the next run
    assert f"removed {results / f'.staging-{STUDY}-{proc.pid}'}, left by a run that did not finish" in done.stderr
    assert f"PID {proc.pid}" in done.stderr and "stale lock" in done.stderr
    assert start_rows(store_path(results)) == start_rows(store_path(published[1]))  # old starts, not rerun


@pytest.mark.slow
def test_kill_during_a_resumed_campaign_keeps_every_finished_start_once(published, results):
    study, _ = published
    store = store_path(results)
    proc, published_before = _interrupt_a_resumed_campaign(study, results, signal.SIGKILL, at=8)
    kept = start_rows(store)
    assert 8 <= len(kept) < len(IDS)
    assert _published_files(results) == published_before  # nothing published by the killed run
    done = cli(*run_args(study, results, "--resume"))
    assert done.returncode == 0, done.stderr
    rows = start_rows(store)
    assert [r[0] for r in rows] == IDS
    assert set(kept) <= set(rows)  # the starts finished before the kill were kept, not redone
    assert _leftovers(results) == []


@pytest.mark.slow
def test_kill_during_publishing_keeps_the_previous_results(published, results):
    study, _ = published
    before, rows = _published_files(results), start_rows(store_path(results))
    for _attempt in range(3):  # the window (tables written, figure being drawn) is short; retry if missed
        proc = start(*run_args(study, results, "--resume"))
        staging = results / f".staging-{STUDY}-{proc.pid}"
        if wait_until(proc, lambda s=staging: (s / "comparison.csv").exists(), poll=0.002):
            proc.send_signal(signal.SIGKILL)
            proc.wait(30)
            break
        proc.communicate()
        assert proc.returncode == 0
        before = _published_files(results)
    else:
        pytest.fail("never caught a run while it was publishing")
    assert _published_files(results) == before  # the previous tables, figure and summary, byte for byte
    assert start_rows(store_path(results)) == rows  # (the resumed run re-records its checks in the store)
    assert _leftovers(results) == sorted([f".{STUDY}.lock", staging.name])  # what kill -9 leaves
    done = cli(*run_args(study, results, "--resume"))
    assert done.returncode == 0, done.stderr
    assert _leftovers(results) == []
    assert [r[0] for r in start_rows(store_path(results))] == IDS


def test_a_run_killed_between_the_swap_renames_is_rolled_back(published, results):
    """Killed after the old folder was moved aside and before the new one was moved in."""
    study, _ = published
    pid = dead_pid()
    aside = results / f".old-{STUDY}-{pid}"
    (results / STUDY).rename(aside)
    (results / f".staging-{STUDY}-{pid}").mkdir()
    (results / f".staging-{STUDY}-{pid}" / "summary.md").write_text("half a run")
    done = cli(*run_args(study, results, "--resume"))
    assert done.returncode == 0, done.stderr
    assert start_rows(store_path(results)) == start_rows(store_path(published[1]))  # the old stores came back
    assert f"put back {results / STUDY}" in done.stderr
    assert _leftovers(results) == []


@pytest.mark.slow
def test_sigterm_during_a_campaign_cleans_up_and_keeps_finished_starts(published, results):
    study, _ = published
    store = store_path(results)
    proc, published_before = _interrupt_a_resumed_campaign(study, results, signal.SIGTERM, at=6)
    err = proc.stderr.read()
    assert proc.returncode == 143, err
    assert "Traceback" not in err and "rerun with --resume" in err
    assert _leftovers(results) == []  # staging removed, lock released
    assert _published_files(results) == published_before
    assert len(start_rows(store)) >= 6


# ---------------------------------------------------------------------------------------------- the lock
HOLD = """
import sys, time
from pathlib import Path
from railopt.studies.output.publish import study_lock
with study_lock(Path(sys.argv[1]), sys.argv[2]):
    print("held", flush=True)
    time.sleep(120)
"""


def test_a_live_holder_of_the_study_lock_is_named(published, results):
    study, _ = published
    before = snapshot(results)
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(results), STUDY], stdout=subprocess.PIPE, text=True,
                              env=env())
    try:
        assert holder.stdout.readline().strip() == "held"
        done = cli(*run_args(study, results, "--resume"))
    finally:
        holder.kill()
        holder.wait()
    assert_refused(done, f"PID {holder.pid} on host {socket.gethostname()}", lock_path(results, STUDY))
    lock_file = lock_path(results, STUDY)
    assert {k: v for k, v in snapshot(results).items() if k != lock_file.name} == before


def test_a_holder_that_has_locked_but_not_yet_written_its_line_is_still_named(tmp_path):
    """The window between the holder's ``flock`` and its line (the race two runs started at once hit): the
    refused run waits for the line instead of reporting an anonymous holder."""
    import fcntl
    import threading

    from railopt.studies.output.publish import StudyLocked, study_lock

    path = lock_path(tmp_path, STUDY)
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # locked, line not yet written
    writer = threading.Timer(0.2, lambda: os.write(fd, b"4242 somehost 2026-12-02T00:00:00+00:00\n"))
    writer.start()
    try:
        with pytest.raises(StudyLocked, match="PID 4242 on host somehost"), study_lock(tmp_path, STUDY):
            pass
    finally:
        writer.join()
        os.close(fd)


def test_a_stale_lock_of_a_dead_process_is_taken_over(published, results):
    study, _ = published
    pid = dead_pid()
    lock_path(results, STUDY).write_text(f"{pid} {socket.gethostname()} 2026-01-01T00:00:00+00:00\n")
    done = cli(*run_args(study, results, "--resume"))
    assert done.returncode == 0, done.stderr
    assert f"stale lock {lock_path(results, STUDY)} of PID {pid}" in done.stderr
    assert _leftovers(results) == []


@pytest.mark.slow
def test_two_runs_of_one_study_at_once_on_dask(published, tmp_path):
    """Exactly one runs; the other is refused naming the holder; every start is stored once."""
    study = study_file(tmp_path / "study", 8)
    results = tmp_path / "results"
    procs = [start(*run_args(study, results, workers="1")) for _ in range(2)]
    outcomes = [(p, *p.communicate(timeout=180)) for p in procs]
    winners = [(p, out, err) for p, out, err in outcomes if p.returncode == 0]
    losers = [(p, out, err) for p, out, err in outcomes if p.returncode != 0]
    assert len(winners) == 1 and len(losers) == 1, [(p.returncode, err) for p, _, err in outcomes]
    (winner, _, _), (loser, _, err) = winners[0], losers[0]
    assert_refused(subprocess.CompletedProcess(loser.args, loser.returncode, "", err),
                   f"PID {winner.pid}", lock_path(results, STUDY))
    assert [r[0] for r in start_rows(store_path(results))] == list(range(9))
    assert sorted(p.name for p in results.iterdir()) == [STUDY]
