"""Helpers of the fault tests (``test_faults_*.py``): the real ``railopt`` CLI in a subprocess.

Every fault test runs the CLI as a user would — ``python -m railopt.studies.cli`` in its own
process — on the bundled ``tmd_hinf`` study cut down to one campaign of a few starts.
"""

from __future__ import annotations

import os
import shutil
import sqlite3
import stat
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from railopt.models.track.spectra import irregularity_spectrum
from railopt.models.vehicle.loader import bundled_path
from railopt.studies.cli import STUDIES_DIR

STUDY = "tmd_hinf"
LABEL = "mu0.05-exact-slsqp"
CLI = [sys.executable, "-m", "railopt.studies.cli"]


def study_file(folder: Path, n_starts: int) -> Path:
    """``tmd_hinf.toml`` with one mass ratio, the exact objective and ``n_starts`` Sobol starts (+1 user start)."""
    text = (STUDIES_DIR / "tmd_hinf.toml").read_text()
    for old, new in {"n_starts = 16": f"n_starts = {n_starts}",
                     'objectives = ["thesis", "exact"]': 'objectives = ["exact"]'}.items():
        assert old in text, old
        text = text.replace(old, new)
    second = text.index("[[models]]", text.index("[[models]]") + 1)
    text = text[:second] + text[text.index("[objective]"):]  # one model: mu0.05
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "study.toml"
    path.write_text(text)
    return path


def publish_baseline(folder: Path, n_starts: int) -> tuple[Path, Path]:
    """(study file, results root) of one successful run into ``folder``: the previous results of a test."""
    study = study_file(folder, n_starts)
    done = cli(*run_args(study, folder / "results"))
    assert done.returncode == 0, done.stderr
    return study, folder / "results"


def env(**extra: str) -> dict[str, str]:
    base = {k: v for k, v in os.environ.items() if not k.startswith("RAILOPT_")}
    return {**base, "PYTHONUNBUFFERED": "1", **extra}


def run_args(study: Path, results: Path, *extra: str, workers: str | None = "0") -> list[str]:
    args = ["run", str(study), "--results", str(results), "--no-progress", *extra]
    return args + (["--workers", workers] if workers is not None else [])


def cli(*args: str, environ: dict[str, str] | None = None, timeout: float = 180) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], env=environ or env(), capture_output=True, text=True, timeout=timeout)


def start(*args: str, environ: dict[str, str] | None = None) -> subprocess.Popen:
    return subprocess.Popen([*CLI, *args], env=environ or env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def assert_refused(proc: subprocess.CompletedProcess, *names: object) -> str:
    """Exit code 2, no traceback, exactly one ``railopt: error:`` line, naming each of ``names``."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("railopt: error:")]
    assert len(errors) == 1, proc.stderr
    for name in names:
        assert str(name) in errors[0], (name, errors[0])
    return errors[0]


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative path → bytes): compare before/after to prove nothing changed."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def store_path(results: Path, folder: str = STUDY) -> Path:
    return results / folder / "campaigns" / f"{LABEL}.sqlite"


def start_rows(store: Path) -> list[tuple]:
    """(start_id, finished_utc, value) of every stored start, by start_id; read-only, no locking of the writer."""
    with sqlite3.connect(f"{store.resolve().as_uri()}?mode=ro", uri=True, timeout=5) as db:
        return db.execute("SELECT start_id, finished_utc, value FROM starts ORDER BY start_id").fetchall()


def count_starts(store: Path) -> int:
    try:
        return len(start_rows(store))
    except sqlite3.Error:
        return 0


def wait_until(proc: subprocess.Popen, condition: Callable[[], bool], timeout: float = 60, poll: float = 0.01) -> bool:
    """Poll ``condition`` while ``proc`` runs; True as soon as it holds, False if the process ended first."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if condition():
            return True
        time.sleep(poll)
    return False


def dead_pid() -> int:
    """The PID of a process that has exited."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


@contextmanager
def read_only(path: Path) -> Iterator[None]:
    """``path`` unwritable: by its mode for a user, by the immutable attribute for root (whom modes do not stop)."""
    mode = stat.S_IMODE(path.stat().st_mode)
    if os.geteuid() != 0:
        path.chmod(0o555 if path.is_dir() else 0o444)
        try:
            yield
        finally:
            path.chmod(mode)
        return
    if subprocess.run(["chattr", "+i", str(path)], capture_output=True).returncode != 0:
        pytest.skip("root, and no immutable attribute on this file system (the file-in-the-way tests cover root)")
    try:
        yield
    finally:
        subprocess.run(["chattr", "-i", str(path)], check=True)


def baseline_fixtures(n_starts: int):
    """Module fixtures ``published`` (one successful run with ``n_starts``) and ``results`` (a private copy)."""
    import shutil

    @pytest.fixture(scope="module")
    def published(tmp_path_factory) -> tuple[Path, Path]:
        """(study file, results root) of one successful run: the previous results every test starts from."""
        return publish_baseline(tmp_path_factory.mktemp("published"), n_starts)

    @pytest.fixture
    def results(published, tmp_path) -> Path:
        """A private copy of the published results root."""
        return Path(shutil.copytree(published[1], tmp_path / "results"))

    return published, results


INPUTS = "ride_inputs"
INPUTS_LABEL = "coach-rms-slsqp"
SEAT = "body[6,0.8,1.0].z"


def inputs_study(folder: Path, n_starts: int = 1) -> Path:
    """A campaign on a vehicle file of its own (``coach.toml``, a copy of the bundled coach) under a measured
    spectrum of its own (``psd.csv``: the ERRI B176 low profile tabulated at 60 wavenumbers)."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(bundled_path("manchester-coach"), folder / "coach.toml")
    erri = irregularity_spectrum("erri_b176", level="low", component="profile")
    w = np.geomspace(0.021, 6.28, 60)
    np.savetxt(folder / "psd.csv", np.column_stack([w, erri.psd(w)]), delimiter=",",
               header="wavenumber_rad_per_m,psd_m2_per_rad_per_m", comments="")
    study = folder / "study.toml"
    study.write_text(f"""
[study]
name = "{INPUTS}"
kind = "campaign"

[[models]]
label = "coach"
model = "vehicle_forced"

[models.options]
vehicle = "coach.toml"
view = "vertical"
speed_m_s = 40.0
input = {{ kind = "vertical", amplitude_m = 0.01 }}
outputs = ["{SEAT}"]
quantity = "acceleration"

[objective]
output = "{SEAT}"
band_hz = [0.5, 20.0]
spectrum = {{ standard = "table", path = "{folder / 'psd.csv'}" }}

[design]
objectives = ["rms"]
methods = ["slsqp"]
n_starts = {n_starts}

[design.options]
maxeval = 4

[[design.variables]]
name = "secondary_vertical_stiffness"
lower = 1e5
upper = 2e6
scale = "log"

[[design.variables]]
name = "secondary_vertical_damping"
lower = 1e3
upper = 1e5
scale = "log"
""")
    return study
