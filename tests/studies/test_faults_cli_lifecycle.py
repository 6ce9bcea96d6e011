"""Issue 27 R6 (the command line), R7 and item 12: what the ``railopt`` command does with absurd numbers, a reader that
goes away, files that are not what they seem, a reader holding a finished store, a study folder that is a symbolic
link, long silent work, Ctrl-C while the local cluster starts, an output folder that cannot be used, and where a
run's outputs go.

Real ``railopt`` processes (``python -m railopt.studies.cli``) unless a test needs to change a constant of the
running code (then ``main`` in-process); every assertion against an independent source: the numbers written, the
file's own bytes, a fresh run against the committed reference.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest
from faults_cli import (
    CLI,
    STUDY,
    assert_refused,
    baseline_fixtures,
    cli,
    dead_pid,
    env,
    inputs_study,
    run_args,
    start_rows,
    store_path,
    study_file,
)
from reference_rule import assert_matches_reference

from railopt.design import store as store_module
from railopt.design.parallel import reporting_progress
from railopt.design.surface import grid_map
from railopt.models.track.spectra import read_spectrum_table
from railopt.studies.cli import EXIT_PIPE, RESULTS_DEFAULT, STUDIES_DIR, build_parser, main
from railopt.studies.output.progress import Progress

ROOT = Path(__file__).resolve().parents[2]
N_STARTS = 6
published, results = baseline_fixtures(N_STARTS)


def _in(folder: Path, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """The command run from ``folder`` (its default results root is ``folder/runs``)."""
    return subprocess.run([*CLI, *args], env=env(), capture_output=True, text=True, timeout=timeout, cwd=folder)


# ---------------------------------------------------------------------------------------------- numbers (R6)
@pytest.mark.parametrize("args, flag", [
    (["vehicle", "sd40-2", "--speed", "1e308"], "--speed"),  # the issue's: an OverflowError traceback
    (["vehicle", "sd40-2", "--speed", "inf"], "--speed"),
    (["vehicle", "sd40-2", "--speed", "nan"], "--speed"),
    (["vehicle", "sd40-2", "--speed", "5e3"], "--speed"),  # 18,000 km/h: a slip, not a speed
    (["run", "tmd_hinf", "--workers", "1000000", "--no-progress"], "--workers"),
    (["bench", "--workers", "0"], "--workers"),
    (["bench", "--workers", "99999999"], "--workers"),
    (["run", "tmd_hinf", "--scheduler-timeout", "inf"], "--scheduler-timeout"),
], ids=["speed 1e308", "speed inf", "speed nan", "speed 5e3", "workers 1e6", "bench workers 0", "bench workers 1e8",
        "scheduler-timeout inf"])
def test_absurd_numbers_on_the_command_line_are_refused_naming_the_flag(args, flag, tmp_path):
    done = _in(tmp_path, *args)
    assert_refused(done, flag)
    assert list(tmp_path.iterdir()) == []  # refused before anything was written


def test_the_largest_accepted_speed_still_gives_a_modes_table(tmp_path):
    done = _in(tmp_path, "vehicle", "single-wheelset", "--speed", "1000")
    assert done.returncode == 0, done.stderr
    assert "Lateral modes at 1000 m/s, rigid track" in done.stdout


# ---------------------------------------------------------------------------------------------- a closed pipe (R6)
def _into_a_closed_pipe(*args: str) -> subprocess.CompletedProcess:
    """Run with stdout a pipe whose reader has already gone (what ``| head -1`` becomes once head has its line)."""
    read, write = os.pipe()
    os.close(read)
    try:
        return subprocess.run([*CLI, *args], env=env(), stdout=write, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write)


@pytest.mark.parametrize("args", [["vehicle", "sd40-2"], ["list"], ["reference"], ["validate", "tmd_hinf"]],
                         ids=lambda a: a[0])
def test_a_reader_that_went_away_is_not_an_error(args):
    done = _into_a_closed_pipe(*args)
    assert done.stderr == ""  # no "railopt: error: [Errno 32] Broken pipe", no "Exception ignored"
    assert done.returncode == EXIT_PIPE


def test_the_issue_pipeline_prints_its_first_line_and_nothing_on_stderr():
    command = f"{sys.executable} -m railopt.studies.cli vehicle sd40-2 | head -1"
    done = subprocess.run(["bash", "-c", command], env=env(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stderr == ""
    assert done.stdout.startswith("Vehicle sd40-2  (") and done.stdout.count("\n") == 1


def test_a_broken_pipe_of_something_else_is_still_an_error(monkeypatch, capsys):
    """Only our own output's reader going away is quiet: a broken connection inside the work is reported."""
    import railopt.studies.cli as cli_module

    def broken(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(cli_module, "cmd_vehicle", broken)
    assert main(["vehicle", "sd40-2"]) == 2
    assert capsys.readouterr().err == "railopt: error: [Errno 32] Broken pipe\n"


# ---------------------------------------------------------------------------------------------- spectrum CSVs (R6)
def _rows(n: int = 6) -> np.ndarray:
    w = np.geomspace(0.05, 5.0, n)
    return np.column_stack([w, 1e-6 / (1 + (w / 0.5) ** 2)])


@pytest.mark.parametrize("header", [False, True], ids=["no header", "header"])
def test_a_spectrum_csv_with_a_byte_order_mark_loads_every_row(header, tmp_path):
    """The issue's file: a spreadsheet's "CSV UTF-8" (a byte-order mark) without a header; its first row was
    taken for a header and dropped.  With a header the header goes, the rows stay."""
    rows = _rows()
    head = "wavenumber (rad/m),PSD (m²/(rad/m))\n" if header else ""
    text = head + "\n".join(f"{w!r},{s!r}" for w, s in rows.tolist())
    path = tmp_path / "psd.csv"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    spectrum = read_spectrum_table(path)
    np.testing.assert_array_equal(spectrum.wavenumbers, rows[:, 0])  # every row, bit for bit
    np.testing.assert_array_equal(spectrum.values, rows[:, 1])


@pytest.mark.parametrize("encoding", ["latin-1", "utf-16"])
def test_a_spectrum_csv_not_in_utf8_is_refused_naming_the_file(encoding, tmp_path):
    """A Latin-1 header (``m²``, the issue's "not in UTF-8"), and a UTF-16 file (a spreadsheet's "Unicode text")."""
    rows = _rows()
    text = "Wellenzahl (rad/m),PSD (m²/(rad/m))\n" + "\n".join(f"{w!r},{s!r}" for w, s in rows.tolist())
    path = tmp_path / "psd.csv"
    path.write_bytes(text.encode(encoding))
    with pytest.raises(ValueError, match=rf"{re.escape(str(path))}: not UTF-8 text"):
        read_spectrum_table(path)
    study = inputs_study(tmp_path / "study")
    (tmp_path / "study" / "psd.csv").write_bytes(path.read_bytes())
    done = cli("validate", str(study))
    assert_refused(done, tmp_path / "study" / "psd.csv", "objective.spectrum", "not UTF-8 text")


def test_an_invisible_character_in_the_first_row_is_named_not_dropped(tmp_path):
    """The same kind: a zero-width space before the first number made the row a "header" and lost it."""
    rows = _rows()
    path = tmp_path / "psd.csv"
    path.write_text("\u200b" + "\n".join(f"{w!r},{s!r}" for w, s in rows.tolist()), encoding="utf-8")
    with pytest.raises(ValueError, match=rf"{re.escape(str(path))}: row 1: not two numbers"):
        read_spectrum_table(path)


# ------------------------------------------------------------------------------------------- a reader holding a store
def _reader(path: Path, how: str, seconds: float) -> subprocess.Popen:
    """Another process reading the finished store as a notebook does: an unconsumed cursor, or a read transaction
    left open; it lets go after ``seconds``."""
    hold = {"cursor": "cur = db.execute('SELECT * FROM starts'); cur.fetchone()",
            "transaction": "db.execute('BEGIN'); db.execute('SELECT count(*) FROM checks').fetchall()"}[how]
    code = (f"import sqlite3, time\ndb = sqlite3.connect({str(path)!r}, isolation_level=None)\n{hold}\n"
            f"print('reading', flush=True)\ntime.sleep({seconds})\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "reading"
    return proc


@pytest.mark.parametrize("how", ["cursor", "transaction"])
def test_a_reader_holding_a_finished_store_is_named(how, published, results, monkeypatch, capsys):
    study, _ = published
    store = store_path(results)
    rows = start_rows(store)
    more = study_file(results.parent / "more", N_STARTS + 2)
    reader = _reader(store, how, 120)
    try:
        monkeypatch.setattr(store_module, "BUSY_TIMEOUT", 1.0)  # the wait, shortened
        code = main(run_args(more, results, "--resume"))
    finally:
        reader.kill()
        reader.wait()
    err = capsys.readouterr().err
    assert code == 2, err
    line = next(line for line in err.splitlines() if line.startswith("railopt: error:"))
    assert str(store) in line and f"PID {reader.pid}" in line and "waited 1 s" in line, line
    assert start_rows(store) == rows  # nothing written


def test_a_reader_that_lets_go_is_waited_for(published, results, capsys):
    study, _ = published
    store = store_path(results)
    more = study_file(results.parent / "more", N_STARTS + 2)
    reader = _reader(store, "transaction", 2.0)
    try:
        code = main(run_args(more, results, "--resume"))
    finally:
        reader.wait(30)
    assert code == 0, capsys.readouterr().err
    assert [r[0] for r in start_rows(store)] == list(range(N_STARTS + 3))


# ----------------------------------------------------------------------------------------- symlinked study folder (R7)
def _leftovers(*folders: Path) -> list[str]:
    return sorted(p.name for f in folders for p in f.iterdir() if p.name.startswith((".old-", ".staging-")))


def _other_seed(folder: Path, seed: int) -> Path:
    study = study_file(folder, N_STARTS)
    study.write_text(study.read_text().replace("seed = 2002", f"seed = {seed}"))
    return study


def test_a_symlinked_study_folder_keeps_its_link_and_a_deleted_target_is_not_resurrected(published, results, tmp_path):
    """The issue: the swap renamed the link itself, left an ``.old-`` link no run could remove, and after the user
    deleted the folder the next run put the first run's results back as current."""
    study, _ = published
    elsewhere = tmp_path / "disk2"
    elsewhere.mkdir()
    target = elsewhere / STUDY
    (results / STUDY).rename(target)
    (results / STUDY).symlink_to(target, target_is_directory=True)
    for _ in range(2):
        done = cli(*run_args(study, results, "--resume"))
        assert done.returncode == 0, done.stderr
        assert (results / STUDY).is_symlink() and (results / STUDY).resolve() == target.resolve()
        assert _leftovers(results, elsewhere) == []
    assert [r[0] for r in start_rows(store_path(results))] == list(range(N_STARTS + 1))
    shutil.rmtree(target)  # the user deletes the results (the link now dangles)
    seven = _other_seed(tmp_path / "seven", 7)
    done = cli(*run_args(seven, results))
    assert done.returncode == 0, done.stderr
    assert (results / STUDY).is_symlink() and "seed = 7" in (target / "study.toml").read_text()
    assert "seed 7" in (target / "summary.md").read_text()
    assert _leftovers(results, elsewhere) == []


@pytest.mark.parametrize("leftover", ["link", "folder"])
def test_a_finished_runs_old_folder_is_removed_never_put_back(leftover, published, results, tmp_path):
    """What the old swap left (an ``.old-`` link), or an ``.old-`` folder a finished swap could not remove: once the
    user deleted the published folder, the next run published the stale one as current."""
    old = results / f".old-{STUDY}-{dead_pid()}"
    if leftover == "link":
        stale = tmp_path / "stale"
        shutil.copytree(results / STUDY, stale)
        old.symlink_to(stale, target_is_directory=True)
    else:
        shutil.copytree(results / STUDY, old)
    shutil.rmtree(results / STUDY)
    seven = _other_seed(tmp_path / "seven", 7)
    done = cli(*run_args(seven, results))
    assert done.returncode == 0, done.stderr
    assert f"removed {old}" in done.stderr and "put back" not in done.stderr
    assert "seed = 7" in (results / STUDY / "study.toml").read_text()
    assert _leftovers(results) == []
    if leftover == "link":
        assert (tmp_path / "stale" / "summary.md").exists()  # a link is unlinked, never what it points to


# ---------------------------------------------------------------------------------------------- progress (R7)
def test_every_map_reports_progress_and_the_maps_add_up():
    """A 201-point surface is one map of 201 row tasks: progress(done, total) after each row; several maps (a
    trade-off's sweeps) add up in one line."""
    calls = []
    grid_map(lambda x: float(x.sum()), ["a", "b"], ("a", "b"), np.linspace(0, 1, 5), np.linspace(0, 1, 201),
             [0.0, 0.0], progress=lambda done, total: calls.append((done, total)))
    assert calls == [(i, 201) for i in range(202)]
    import io

    stream = io.StringIO()
    bar = Progress("sweep", unit="task", stream=stream, terminal=False, interval_s=0.0)
    with reporting_progress(bar.over_maps()):
        for rows in (3, 4):
            grid_map(lambda x: 0.0, ["a", "b"], ("a", "b"), [0.0], np.arange(rows, dtype=float), [0.0, 0.0])
    bar.close()
    assert stream.getvalue().splitlines()[-1] == "sweep: 7 tasks (map 2: 4/4)"


def _ride_study(folder: Path) -> Path:
    text = (STUDIES_DIR / "ride_comfort.toml").read_text()
    first = text.index("[[cases]]")
    second = text.index("[[cases]]", first + 1)
    text = text[:second] + text[text.index("[design]"):]  # the first case only
    text = re.sub(r"n_starts = \d+", "n_starts = 1", text)
    assert "n_starts = 1" in text
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "ride.toml"
    path.write_text(text)
    return path


@pytest.mark.slow
def test_the_ride_kind_prints_progress_lines_in_a_log(tmp_path):
    study = _ride_study(tmp_path / "study")
    done = cli("run", str(study), "--results", str(tmp_path / "r"))
    assert done.returncode == 0, done.stderr
    assert "\r" not in done.stderr
    case = re.search(r'label = "([^"]+)"', study.read_text()[study.read_text().index("[[cases]]"):]).group(1)
    for criterion in ("minimax_sinusoid", "rms_random"):  # n_starts 1 + the existing design: 2 starts each
        assert f"{case} {criterion}: 2/2 starts (100 %)" in done.stderr.splitlines(), done.stderr


# ---------------------------------------------------------------------------------------------- Ctrl-C (R7)
def _spawned_workers(pid: int) -> list[psutil.Process]:
    try:
        children = psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []
    out = []
    for child in children:
        try:
            if "spawn_main" in " ".join(child.cmdline()):
                out.append(child)
        except psutil.Error:
            continue
    return out


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_while_the_local_cluster_starts_is_one_line(workers, tmp_path):
    """SIGINT to the process group (Ctrl-C) while the worker processes are still importing: 30–124 traceback lines
    before (each worker's KeyboardInterrupt, then dask's atexit); one line and exit 130 now."""
    from terminal import as_a_foreground_job  # here: a dask worker that imports this module has no tests/
    study = study_file(tmp_path / "study", 3)
    proc = subprocess.Popen([*CLI, *run_args(study, tmp_path / "results", workers=workers)], env=env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=as_a_foreground_job)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None and not _spawned_workers(proc.pid):
        time.sleep(0.02)
    assert proc.poll() is None, proc.communicate()
    os.killpg(proc.pid, signal.SIGINT)  # the group this test started
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.splitlines() == ["railopt: interrupted; finished starts are kept in the campaign store; rerun with "
                                "--resume"], err


# ---------------------------------------------------------------------------------------------- output folders (R7)
def test_bench_out_that_cannot_be_used_is_refused_before_the_bench(tmp_path):
    blocker = tmp_path / "a file"
    blocker.write_text("not a folder")
    began = time.monotonic()
    done = _in(tmp_path, "bench", "--out", str(blocker))
    assert_refused(done, blocker, "--out")
    assert time.monotonic() - began < 60 and done.stdout == ""  # refused before any benchmark ran (they take minutes)
    assert blocker.read_text() == "not a folder"
    (tmp_path / "out" / "bench.csv").mkdir(parents=True)  # the same kind: a folder where a result file goes
    assert_refused(_in(tmp_path, "bench", "--out", str(tmp_path / "out")), tmp_path / "out" / "bench.csv", "--out")


@pytest.mark.parametrize("value", ["", "  "], ids=["empty", "blank"])
@pytest.mark.parametrize("command", ["run", "bench", "reference"])
def test_an_empty_output_folder_is_refused_not_taken_for_the_working_folder(command, value, tmp_path):
    args = {"run": ["run", str(study_file(tmp_path / "study", 2)), "--workers", "0", "--results", value],
            "bench": ["bench", "--out", value], "reference": ["reference", "--out", value]}[command]
    before = sorted(tmp_path.rglob("*"))
    done = _in(tmp_path, *args)
    assert_refused(done, "--results" if command == "run" else "--out", "empty")
    assert sorted(tmp_path.rglob("*")) == before


# ---------------------------------------------------------------------------------------------- where runs go (item 12)
def test_the_default_results_root_is_git_ignored_and_not_the_committed_references():
    assert build_parser().parse_args(["run", "x"]).results == RESULTS_DEFAULT == "runs"
    assert build_parser().parse_args(["bench"]).out == "runs/benchmarks"
    ignored = [line.strip() for line in (ROOT / ".gitignore").read_text().splitlines()]
    assert "runs/" in ignored
    assert not {"results", "results/", "/results", "/results/"} & set(ignored)  # the references stay tracked


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tmd_frf", "tmd_hinf"])
def test_a_fresh_run_of_a_bundled_study_writes_to_runs_and_matches_its_committed_reference(name, tmp_path):
    """README command 1's kind, from a clean folder: the run goes to ``runs/<study>/`` (never over ``results/``) and
    its tables match the committed reference's under the reference rule (tests/reference_rule.py: U to 1e-9, other
    reals to 1e-6, counts, statuses and labels exactly)."""
    done = _in(tmp_path, "run", str(STUDIES_DIR / f"{name}.toml"), "--fresh", "--workers", "0", "--no-progress",
               timeout=300)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["runs"]
    assert_matches_reference(tmp_path / "runs" / name, ROOT / "results" / name)


SLP_SCRIPT = """
import sys
import numpy as np
from railopt.design import DesignVariable, MinimaxProblem, dask_client, multistart

def f(x):
    return np.array([(x[0] - 0.6) ** 2 + x[1], (x[1] - 0.2) ** 2 + 0.1])

if __name__ == "__main__":
    problem = MinimaxProblem([DesignVariable("a", 0.0, 1.0), DesignVariable("b", 0.0, 1.0)], f)
    with dask_client(workers=int(sys.argv[1])) as client:
        table = multistart(problem, 4, method="slp", seed=1, client=client)
    print(f"{table['value'].min():.6f}")
"""


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["0", "2"])
def test_the_lp_solver_prints_no_banner(workers, tmp_path):
    """HiGHS printed its copyright banner once per process that solved an LP: twice in the flagship run."""
    script = tmp_path / "slp.py"
    script.write_text(SLP_SCRIPT)
    done = subprocess.run([sys.executable, str(script), workers], env=env(), capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"{0.7 - np.sqrt(0.35):.6f}"  # the closed-form minimax value
    assert "HiGHS" not in done.stdout + done.stderr
