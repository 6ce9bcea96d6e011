"""The bench's baseline row builds an earlier commit's code from the checkout's history
(studies/bench_baseline.py): it must import that code, not the installed one, say so when it cannot, and never
take the whole bench down with it."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys

import pytest

from railopt.studies import bench_baseline


def _has_commit() -> bool:
    if shutil.which("git") is None:
        return False
    return subprocess.run(["git", "-C", str(bench_baseline.ROOT), "cat-file", "-e",
                           f"{bench_baseline.BASELINE_COMMIT}^{{commit}}"], capture_output=True).returncode == 0


# a precondition of the environment (a full clone with git), not a failing test: the row itself says "skipped"
needs_history = pytest.mark.skipif(not _has_commit(), reason="needs git and the baseline commit in the history")


@needs_history
def test_the_baseline_package_is_the_commits_code_and_imports_from_its_folder(tmp_path):
    """The laid-out package imports from the temporary folder, its files are the commit's (``git show``, an
    independent read of the history), and a module the commit lacks (the compiled kernels came later) is not
    handed over from the current checkout by the editable install."""
    path = bench_baseline._old_package(tmp_path)
    probe = bench_baseline.HERMETIC + (
        "import railopt.design.multistart\n"
        "print(sys.modules['railopt.design.multistart'].__file__)\n"
        "try:\n    import railopt.models.kernels\n    print(sys.modules['railopt.models.kernels'].__file__)\n"
        "except ModuleNotFoundError:\n    print('no-kernels')\n")
    done = subprocess.run([sys.executable, "-P", "-c", probe], env={**os.environ, "PYTHONPATH": str(path)},
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    first, second = done.stdout.split()
    assert first.startswith(str(path)), first
    assert second == "no-kernels", second
    committed = subprocess.run(["git", "-C", str(bench_baseline.ROOT), "show",
                                f"{bench_baseline.BASELINE_COMMIT}:design/multistart.py"], capture_output=True,
                               text=True, check=True).stdout
    assert (path / "railopt" / "design" / "multistart.py").read_text() == committed


def test_a_commit_missing_from_the_history_is_a_skipped_row_not_an_error(monkeypatch):
    monkeypatch.setattr(bench_baseline, "BASELINE_COMMIT", "0" * 40)
    row = bench_baseline.baseline_row()
    assert row["note"].startswith("skipped: ")
    if shutil.which("git") is not None and shutil.which("tar") is not None:
        assert row["note"].startswith(f"skipped: commit {'0' * 40} is not in this checkout's history")
    assert "ratio" not in row


@needs_history
def test_a_failed_or_different_run_is_not_a_result_and_not_an_error(monkeypatch):
    """A child process that fails, or two codes that do not find the same U, give a row marked 'not a result'
    (ratio NaN) instead of an exception that would lose the bench's other rows."""
    def failing(pythonpath, study, expected):
        raise RuntimeError("exit status 1: ImportError: something the old code needs")

    monkeypatch.setattr(bench_baseline, "_start_times", failing)
    row = bench_baseline.baseline_row()
    assert math.isnan(row["ratio"]) and row["note"].startswith("failed, not a result: the baseline run")

    answers = iter([{"seconds": 6.0, "U": [1.0, 2.0], "evaluations": [5, 6]},
                    {"seconds": 2.0, "U": [1.0, 2.5], "evaluations": [5, 6]}] * bench_baseline.BASELINE_ROUNDS)
    monkeypatch.setattr(bench_baseline, "_start_times", lambda *args: next(answers))
    row = bench_baseline.baseline_row()
    assert math.isnan(row["ratio"]) and row["note"].startswith("not a result: U differs by 2.5e-01")
