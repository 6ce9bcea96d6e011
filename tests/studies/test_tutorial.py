"""docs/tutorial.md: its files are extracted, validated and run with the real CLI; the numbers it quotes are checked
against the run and against the model layer."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle

DOC = Path(__file__).resolve().parents[2] / "docs" / "tutorial.md"
CLI = [sys.executable, "-m", "railopt.studies.cli"]


def blocks() -> dict[str, str]:
    """``{file name: content}`` of every fenced block preceded by ``<!-- file: NAME -->``."""
    found = re.findall(r"<!-- file: (\S+) -->\n```toml\n(.*?)\n```", DOC.read_text(), re.DOTALL)
    return {name: body + "\n" for name, body in found}


def commands() -> list[list[str]]:
    """The ``railopt ...`` lines of the bash blocks, in order."""
    bash = re.findall(r"```bash\n(.*?)\n```", DOC.read_text(), re.DOTALL)
    return [line.split()[1:] for block in bash for line in block.splitlines() if line.startswith("railopt ")]


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.fixture(scope="module")
def tutorial(tmp_path_factory) -> tuple[Path, dict[str, subprocess.CompletedProcess]]:
    folder = tmp_path_factory.mktemp("tutorial")
    files = blocks()
    assert sorted(files) == ["car.toml", "study.toml"]
    for name, body in files.items():
        (folder / name).write_text(body)
    done = {}
    for args in commands():
        result = cli(*args, cwd=folder)
        assert result.returncode == 0, (args, result.stderr)
        done[" ".join(args)] = result
    return folder, done


def test_commands_are_the_expected_ones(tutorial):
    _, done = tutorial
    assert list(done) == ["validate car.toml", "vehicle car.toml", "validate study.toml", "run study.toml --workers 0"]


def test_vehicle_summary_numbers_match_the_text_and_the_model_layer(tutorial):
    folder, done = tutorial
    out = done["vehicle car.toml"].stdout
    assert re.search(r"^total\s+20,000 kg", out, re.MULTILINE)
    assert "axle load (2 wheelsets)  98.1 kN (10.00 t)" in out
    match = re.search(r"^rigid\s+(\d+\.\d\d) m/s \((\d+\.\d) km/h\)\s+(\d+\.\d+) Hz", out, re.MULTILINE)
    assert match, out
    assert match.group(1) == "47.33" and match.group(2) == "170.4"
    text = DOC.read_text()
    assert "**47.33 m/s** (170.4 km/h), hunting at 3.23 Hz" in text
    assert round(float(match.group(3)), 2) == 3.23
    assert done["validate car.toml"].stdout.startswith("car.toml: valid vehicle file (")
    assert "warning" not in done["validate car.toml"].stdout


def test_study_critical_speeds_match_the_text_and_the_model_layer(tutorial):
    folder, done = tutorial
    table = pd.read_csv(folder / "runs" / "two_axle_car" / "critical_speeds.csv").set_index("model")
    vehicle = load_vehicle(str(folder / "car.toml"))
    direct = critical_speed(vehicle.lateral(track="rigid"), speed_range=(5.0, 150.0), tol=0.01, grid=16)
    assert table.loc["car", "critical_speed_m_s"] == pytest.approx(direct.speed, abs=1e-9)
    assert table.loc["car", "critical_speed_m_s"] == pytest.approx(47.32, abs=0.01)
    stiffer = vehicle.with_parameters({"primary_longitudinal_stiffness": 1.0e7})
    direct_stiffer = critical_speed(stiffer.lateral(track="rigid"), speed_range=(5.0, 150.0), tol=0.01, grid=16)
    assert table.loc["stiffer_primary", "critical_speed_m_s"] == pytest.approx(direct_stiffer.speed, abs=1e-9)
    text = DOC.read_text()
    for model in ("car", "stiffer_primary"):
        speed = table.loc[model, "critical_speed_m_s"]
        hz = table.loc[model, "hunting_frequency_hz"]
        assert f"| {model} | {speed:.2f} m/s | {hz:.2f} Hz |" in text
    sens = pd.read_csv(folder / "runs" / "two_axle_car" / "sensitivity.csv")
    car = sens[(sens["model"] == "car") & (sens["parameter"] == "conicity")].set_index("factor")
    assert f"at half the conicity the car hunts at {car.loc[0.5, 'critical_speed_m_s']:.2f} m/s" in text
    assert f"at twice\nthe conicity at {car.loc[2.0, 'critical_speed_m_s']:.2f} m/s" in text
    assert car.loc[1.0, "critical_speed_m_s"] == table.loc["car", "critical_speed_m_s"]


def test_the_quoted_conicity_warning_is_what_validate_prints(tutorial, tmp_path):
    folder, _ = tutorial
    slip = tmp_path / "car.toml"
    slip.write_text((folder / "car.toml").read_text().replace("conicity = 0.15", "conicity = 15"))
    done = cli("validate", "car.toml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    quoted = re.search(r"```text\n(warning: car.toml: contact.conicity: .*?)\n```", DOC.read_text()).group(1)
    assert quoted in done.stdout.splitlines()
