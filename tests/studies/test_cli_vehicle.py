"""`railopt vehicle NAME_OR_FILE` and `railopt validate car.toml`: a real CLI process, numbers asserted."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.summary import SPEED_RANGE, TOL

CLI = [sys.executable, "-m", "railopt.studies.cli"]
WHEELSET = Path(__file__).resolve().parents[2] / "models" / "vehicle" / "data" / "single-wheelset.toml"


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """The real command in a new process (its run time is `railopt bench`'s row, never a test's)."""
    return subprocess.run([*CLI, *args], capture_output=True, text=True, cwd=cwd, timeout=120)


def printed_critical(text: str, track: str) -> float:
    match = re.search(rf"^{track}\s+(\d+\.\d\d) m/s \(", text, re.MULTILINE)
    assert match, text
    return float(match.group(1))


@pytest.mark.parametrize("name, rigid", [("sd40-2", 33.88), ("manchester-coach", 79.89)])
def test_vehicle_summary_prints_critical_speeds(name, rigid):
    done = run_cli("vehicle", name)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.startswith(f"Vehicle {name}  (")
    model_layer = critical_speed(load_vehicle(name), track="rigid", speed_range=SPEED_RANGE, tol=TOL).speed
    shown = printed_critical(done.stdout, "rigid")
    assert shown == pytest.approx(model_layer, abs=0.005 + TOL)
    assert shown == pytest.approx(rigid, abs=0.015)  # tol 0.01 m/s of the search
    assert printed_critical(done.stdout, "flexible") > 0


def test_sd40_2_summary_masses_and_axle_load():
    done = run_cli("vehicle", "sd40-2", "--speed", "20")
    assert done.returncode == 0, done.stderr
    assert re.search(r"^total\s+166,922 kg", done.stdout, re.MULTILINE)
    assert "axle load (6 wheelsets)  272.8 kN (27.82 t)" in done.stdout
    assert "Lateral modes at 20 m/s, rigid track" in done.stdout


def test_vehicle_markdown():
    done = run_cli("vehicle", "sd40-2", "--markdown")
    assert done.returncode == 0, done.stderr
    assert re.search(r"^\| rigid \| 33\.88 m/s", done.stdout, re.MULTILINE), done.stdout


def test_validate_vehicle_file_prints_its_unit_slip_warning(tmp_path):
    car = tmp_path / "car.toml"
    car.write_text(WHEELSET.read_text().replace("conicity = 0.1", "conicity = 2.5"))
    done = run_cli("validate", "car.toml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("car.toml: valid vehicle file (")
    assert "warning: car.toml: contact.conicity: conicity 2.5 is above 0.5: looks like per cent (2.5 → 0.025) or " \
        "10× too large (→ 0.25)?" in lines


def test_validate_good_vehicle_file_has_no_conicity_warning(tmp_path):
    car = tmp_path / "car.toml"
    car.write_text(WHEELSET.read_text())
    done = run_cli("validate", str(car))
    assert done.returncode == 0, done.stderr
    assert "conicity" not in done.stdout.split("\n", 1)[1]


def test_validate_a_bundled_vehicle_by_name():
    done = run_cli("validate", "sd40-2")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("sd40-2: valid vehicle file (")


@pytest.mark.parametrize("command", ["validate", "vehicle"])
def test_bad_vehicle_file_exits_2_with_one_line_naming_file_and_key(command, tmp_path):
    car = tmp_path / "car.toml"
    car.write_text(WHEELSET.read_text() + "\n[trak]\n")
    done = run_cli(command, str(car))
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr == (f"railopt: error: {car}: trak: unknown table or key at the top level; did you mean "
                           "'track'?\n")


def test_unknown_vehicle_name_exits_2_with_one_line():
    done = run_cli("vehicle", "sd40-3")
    assert done.returncode == 2
    assert done.stderr == ("railopt: error: sd40-3: no such vehicle file; bundled vehicles: sd40-2, single-wheelset, "
                           "manchester-coach\n")


def test_vehicle_options_before_the_name_and_help():
    done = run_cli("vehicle", "--speed", "30", "--track", "rigid", "single-wheelset")
    assert done.returncode == 0, done.stderr
    assert "Lateral modes at 30 m/s, rigid track" in done.stdout
    helped = run_cli("vehicle", "--help")
    assert helped.returncode == 0 and helped.stdout.startswith("usage: railopt vehicle [-h] [--speed SPEED]")
    usage = run_cli("vehicle")
    assert usage.returncode == 2
    assert usage.stderr.splitlines()[-1] == "railopt vehicle: error: the following arguments are required: vehicle"
