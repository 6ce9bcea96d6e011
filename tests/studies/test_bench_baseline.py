"""The bench's baseline row builds an earlier commit's code from the checkout's history
(studies/bench_baseline.py): it must import that code, not the installed one, and say so when it cannot."""

from __future__ import annotations

import os
import subprocess
import sys

from railopt.studies import bench_baseline


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
    done = subprocess.run([sys.executable, "-c", probe], env={**os.environ, "PYTHONPATH": str(path)}, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
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
    assert row["note"].startswith(f"skipped: commit {'0' * 40} is not in this checkout's history")
    assert "ratio" not in row
