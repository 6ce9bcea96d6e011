"""The ``railopt`` entry point: Ctrl-C while the CLI's imports load ends with one line and exit 130, no traceback.

The interrupt is made deterministic by an import hook that raises KeyboardInterrupt when ``railopt.studies.cli`` is
imported (what a Ctrl-C during the seconds numpy/pandas/dask take to load does); a real subprocess checks that the
installed script runs the CLI (exit 0 and its usage line for ``--help``).
"""

from __future__ import annotations

import importlib.abc
import subprocess
import sys

from railopt import entry


class _Interrupt(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "railopt.studies.cli":
            raise KeyboardInterrupt
        return None


def test_ctrl_c_during_imports_is_one_line_and_exit_130(monkeypatch, capsys):
    monkeypatch.delitem(sys.modules, "railopt.studies.cli", raising=False)
    monkeypatch.setattr(sys, "meta_path", [_Interrupt(), *sys.meta_path])
    assert entry.main() == 130
    err = capsys.readouterr().err
    assert err.strip().splitlines() == ["railopt: interrupted (while starting; nothing was run)"]


def test_entry_runs_the_cli():
    out = subprocess.run([sys.executable, "-m", "railopt.entry", "--help"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "usage: railopt" in out.stdout
