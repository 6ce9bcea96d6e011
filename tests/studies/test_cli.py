"""The railopt command: bad input names the field, exits non-zero and writes nothing; resume works."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from railopt.studies.cli import STUDIES_DIR, main

TMD = (STUDIES_DIR / "tmd_hinf.toml").read_text()


def write_study(tmp_path: Path, replace: dict[str, str] | None = None, append: str = "") -> Path:
    text = TMD
    for old, new in (replace or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "study.toml"
    path.write_text(text + append)
    return path


BAD = {
    "inverted bounds": ({"lower = 0.5\nupper = 1.5": "lower = 1.5\nupper = 0.5"}, "", "design.variables.0"),
    "unknown method": ({'methods = ["slsqp"]': 'methods = ["newton"]'}, "", "design.methods"),
    "n_starts zero": ({"n_starts = 16": "n_starts = 0"}, "", "design.n_starts"),
    "wrong type": ({"n_starts = 16": 'n_starts = "sixteen"'}, "", "design.n_starts"),
    "inverted band": ({"band_hz = [1.0, 3.0]": "band_hz = [3.0, 1.0]"}, "", "objective.band_hz"),
    "nan mass ratio": ({"mass_ratio = 0.05,": "mass_ratio = nan,"}, "", "models[0].options.mass_ratio"),
    "huge mass ratio": ({"mass_ratio = 0.05,": "mass_ratio = 1e308,"}, "", "models[0].options.mass_ratio"),
    "unknown field": ({}, "\n[extra]\nfoo = 1\n", "extra"),
    "unknown option": ({"maxtime = 120.0": "maxtime = 120.0\nmax_time = 5"}, "", "design.options.max_time"),
    "unknown kind": ({'kind = "campaign"': 'kind = "tmd"'}, "", "study.kind"),
    "negative time": ({"maxtime = 120.0": "maxtime = -1.0"}, "", "design.options.maxtime"),
    "unknown variable": ({'name = "tuning"': 'name = "stiffness"'}, "", "design.variables"),
    "unknown output": ({'output = "amplification"': 'output = "stroke"'}, "", "objective.output"),
    "repeated label": ({'label = "mu0.1"': 'label = "mu0.05"'}, "", "models: labels must be unique"),
    "unknown model": ({'model = "tmd"': 'model = "tdm"'}, "", "models[0].model"),
    "unknown named start": ({'start_from = ["den_hartog"]': 'start_from = ["existing"]'}, "", "design.start_from"),
    "unknown check": ({'checks = ["spectral_abscissa"]': 'checks = ["hunting"]'}, "", "design.checks"),
    "bool for an int": ({"n_starts = 16": "n_starts = true"}, "", "design.n_starts"),
    "single method": ({'methods = ["slsqp"]': 'method = "cobyla"'}, "", "design.method"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_config_names_the_field_exits_2_and_writes_nothing(case, tmp_path, capsys):
    replace, append, field = BAD[case]
    study = write_study(tmp_path, replace, append)
    results = tmp_path / "results"
    code = main(["run", str(study), "--results", str(results), "--workers", "0", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert field in err, err
    assert not results.exists()


def test_missing_study_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.toml"), "--results", str(tmp_path / "r")]) == 2
    assert "study: no such file" in capsys.readouterr().err


def small_study(tmp_path: Path, n_starts: int = 6, objectives: str = '["exact"]') -> Path:
    study = write_study(tmp_path, {"n_starts = 16": f"n_starts = {n_starts}",
                                   'objectives = ["thesis", "exact"]': f"objectives = {objectives}"})
    text = study.read_text()
    second = text.index("[[models]]", text.index("[[models]]") + 1)
    study.write_text(text[:second] + text[text.index("[objective]"):])  # one model: mu0.05
    return study


def test_run_publishes_results_and_refuses_to_overwrite_a_store(tmp_path, capsys):
    study = small_study(tmp_path)
    results = tmp_path / "results"
    assert main(["run", str(study), "--results", str(results), "--workers", "0", "--no-progress"]) == 0
    out = results / "tmd_hinf"
    for name in ("summary.md", "comparison.csv", "starts.csv", "starts.parquet", "frf.png", "study.toml"):
        assert (out / name).is_file(), name
    assert not list(results.glob(".staging-*"))
    comparison = pd.read_csv(out / "comparison.csv")
    assert abs(comparison["change_vs_nishihara_asami"].iloc[0]) < 1e-4
    before = (out / "campaigns" / "mu0.05-exact-slsqp.sqlite").read_bytes()
    assert main(["run", str(study), "--results", str(results), "--workers", "0", "--no-progress"]) == 2
    assert "--resume" in capsys.readouterr().err
    assert (out / "campaigns" / "mu0.05-exact-slsqp.sqlite").read_bytes() == before  # nothing lost


@pytest.mark.slow
def test_killed_campaign_resumes_with_every_start_exactly_once(tmp_path):
    study = small_study(tmp_path, n_starts=48, objectives='["exact"]')
    results = tmp_path / "results"
    store = results / "tmd_hinf" / "campaigns" / "mu0.05-exact-slsqp.sqlite"
    cmd = [sys.executable, "-m", "railopt.studies.cli", "run", str(study), "--results", str(results),
           "--workers", "0", "--no-progress"]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    finished = 0
    while time.time() < deadline and proc.poll() is None:
        if store.exists():
            try:
                with sqlite3.connect(store) as db:
                    finished = db.execute("SELECT COUNT(*) FROM starts").fetchone()[0]
            except sqlite3.OperationalError:
                finished = 0
            if finished >= 5:
                break
        time.sleep(0.05)
    assert proc.poll() is None, "campaign finished before it could be killed"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    with sqlite3.connect(store) as db:
        killed_at = db.execute("SELECT COUNT(*) FROM starts").fetchone()[0]
    assert 5 <= killed_at < 49
    assert not (results / "tmd_hinf" / "summary.md").exists()  # nothing published by the killed run
    done = subprocess.run([*cmd, "--resume"], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    with sqlite3.connect(store) as db:
        ids = [r[0] for r in db.execute("SELECT start_id FROM starts ORDER BY start_id")]
    assert ids == list(range(49))
    # the resumed table equals an uninterrupted run of the same config and seed
    fresh = tmp_path / "fresh"
    assert main(["run", str(study), "--results", str(fresh), "--workers", "0", "--no-progress"]) == 0
    a = pd.read_csv(results / "tmd_hinf" / "starts.csv")
    b = pd.read_csv(fresh / "tmd_hinf" / "starts.csv")
    cols = ["start_id", "x0_tuning", "x0_damping_ratio", "tuning", "damping_ratio", "value", "status", "evaluations"]
    pd.testing.assert_frame_equal(a[cols], b[cols])


def test_scheduler_address_runs_the_campaign_on_an_existing_cluster(tmp_path, monkeypatch):
    from dask.distributed import LocalCluster

    study = small_study(tmp_path, n_starts=4)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_cluster = tmp_path / "cluster"
        assert main(["run", str(study), "--results", str(on_cluster), "--scheduler", cluster.scheduler_address,
                     "--no-progress"]) == 0
        monkeypatch.setenv("RAILOPT_SCHEDULER", cluster.scheduler_address)
        via_env = tmp_path / "env"
        assert main(["run", str(study), "--results", str(via_env), "--no-progress"]) == 0
    serial = tmp_path / "serial"
    monkeypatch.delenv("RAILOPT_SCHEDULER")
    assert main(["run", str(study), "--results", str(serial), "--workers", "0", "--no-progress"]) == 0
    cols = ["start_id", "tuning", "damping_ratio", "value", "status", "evaluations"]
    ref = pd.read_csv(serial / "tmd_hinf" / "starts.csv")[cols]
    for root in (on_cluster, via_env):
        pd.testing.assert_frame_equal(pd.read_csv(root / "tmd_hinf" / "starts.csv")[cols], ref)


def test_timing_says_where_the_run_ran(tmp_path: Path) -> None:
    """``timing.csv``: a kind that opens no dask client ran serially, whatever --workers says; ``--workers 0``
    is serial too; a fresh run is not a resumed one."""
    assert main(["run", str(STUDIES_DIR / "tmd_frf.toml"), "--results", str(tmp_path), "--fresh", "--no-progress"]) == 0
    frf = pd.read_csv(tmp_path / "tmd_frf" / "timing.csv").iloc[0]
    assert frf["workers"] == "serial" and not frf["resumed"] and frf["total_s"] >= frf["compute_s"] > 0
    assert main(["run", str(STUDIES_DIR / "tmd_hinf.toml"), "--results", str(tmp_path), "--fresh", "--workers", "0",
                 "--no-progress"]) == 0
    assert pd.read_csv(tmp_path / "tmd_hinf" / "timing.csv").iloc[0]["workers"] == "serial"
    assert main(["run", str(STUDIES_DIR / "tmd_hinf.toml"), "--results", str(tmp_path), "--resume", "--workers", "0",
                 "--no-progress"]) == 0
    assert bool(pd.read_csv(tmp_path / "tmd_hinf" / "timing.csv").iloc[0]["resumed"])
