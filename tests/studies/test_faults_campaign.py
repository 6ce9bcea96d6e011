"""Campaign configs that validated and then failed late (issue 16, F01 and F06 and their kinds)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from railopt.studies.cli import STUDIES_DIR, main

FLAGSHIP = (STUDIES_DIR / "cab_lateral_minimax.toml").read_text()


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "railopt.studies.cli", *args], capture_output=True, text=True,
                          timeout=300)


@pytest.mark.parametrize("targets", ["[-0.004, 0.006]", "[0.0, 0.006]"])
def test_a_trade_off_target_must_be_positive(tmp_path, targets: str) -> None:
    path = tmp_path / "f06.toml"
    path.write_text(FLAGSHIP.replace("epsilons = [0.004, 0.005, 0.006, 0.008, 0.010, 0.013]", f"epsilons = {targets}"))
    proc = cli("validate", str(path))
    assert proc.returncode == 2 and "epsilons: every target must be > 0" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_study_where_no_start_converges_reports_it(tmp_path) -> None:
    """maxeval = 1: every start stops at its first evaluation; the run still publishes and says so."""
    text = FLAGSHIP.replace("maxeval = 2000", "maxeval = 1").replace("n_starts = 8", "n_starts = 1")
    text = text.replace('methods = ["slsqp", "cobyla", "slp"]', 'methods = ["slsqp"]')
    text = text.replace('objectives = ["thesis", "exact"]', 'objectives = ["exact"]')
    text = text[: text.index("[[tradeoffs]]")]
    path = tmp_path / "f01.toml"
    path.write_text(text)
    assert main(["run", str(path), "--results", str(tmp_path / "r"), "--workers", "0", "--no-progress"]) == 0
    summary = (tmp_path / "r" / "cab_lateral_minimax" / "summary.md").read_text()
    assert "**No recommended design**" in summary
    assert "No successful exact optimum for `sd40-2`: no before/after report." in summary
