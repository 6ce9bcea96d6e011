"""A study prints the plausibility warnings of the vehicles it names (issue 27 item 3: each warning names the file,
the key and the likely slip), in ``railopt validate``, ``railopt run`` and ``run_study``; bundled vehicles give none.

Independent reference: the slip is made by hand (the coach's semi-wheelbase 1.28 m written as 1280, i.e. in mm);
the warning must name that file, the key ``lengths.semi_wheelbase`` and the mm reading 1.28 m.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.loader import bundled_vehicles
from railopt.models.vehicle.plausibility import plausibility
from railopt.studies.cli import main
from railopt.studies.run_study import run_study

COACH = Path(__file__).parents[2] / "models" / "vehicle" / "data" / "manchester-coach.toml"

STUDY = """
[study]
name = "slip"
kind = "speed_sweep"

[[models]]
label = "coach"
model = "vehicle_lateral"
options = {{ vehicle = "{vehicle}", track = "rigid" }}

[speeds]
range_m_s = [5.0, 80.0]
points = 4

[critical]
range_m_s = [1.0, 150.0]
points = 4
"""


def _study(tmp_path: Path, vehicle: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(STUDY.format(vehicle=vehicle))
    return path


def _slipped(tmp_path: Path) -> Path:
    text = COACH.read_text()
    slipped = re.sub(r"^semi_wheelbase = \{ value = 1\.28,", "semi_wheelbase = { value = 1280.0,", text, flags=re.M)
    assert slipped != text
    path = tmp_path / "coach_mm.toml"
    path.write_text(slipped)
    return path


def test_validate_prints_the_vehicle_slip_naming_file_and_key(tmp_path, capsys):
    vehicle = _slipped(tmp_path)
    study = _study(tmp_path, vehicle.name)
    assert main(["validate", str(study)]) == 0  # a warning, not a refusal
    err = capsys.readouterr().err
    lines = [x for x in err.splitlines() if "lengths.semi_wheelbase" in x and x.startswith("railopt: warning:")]
    assert lines, err
    assert str(study) in lines[0] and "coach_mm.toml" in lines[0] and "models[0] (coach)" in lines[0]
    assert "1.28 m" in lines[0]


def test_run_study_issues_and_keeps_the_vehicle_warnings(tmp_path):
    vehicle = _slipped(tmp_path)
    study = _study(tmp_path, vehicle.name)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = run_study(study, results=tmp_path / "out", show_progress=False)
    kept = [w for w in run.warnings if "lengths.semi_wheelbase" in w]
    assert kept and "coach_mm.toml" in kept[0]
    assert any("lengths.semi_wheelbase" in str(w.message) for w in caught if w.category is UserWarning)


@pytest.mark.parametrize("vehicle", sorted(bundled_vehicles()))
def test_study_prints_exactly_the_vehicle_plausibility_lines(tmp_path, capsys, vehicle):
    """The bundled locomotive and coach are plausible (no line); the lone thesis wheelset keeps its one axle-load
    line (1.5 t on one axle, no carried body) — the study prints what ``plausibility`` says, nothing more or less."""
    study = _study(tmp_path, vehicle).read_text().replace('"coach"', f'"{vehicle}"')
    (tmp_path / "study.toml").write_text(study)
    assert main(["validate", str(tmp_path / "study.toml")]) == 0
    printed = [x for x in capsys.readouterr().err.splitlines() if x.startswith("railopt: warning:")]
    expected = [w.line() for w in plausibility(load_vehicle(vehicle))]
    assert len(printed) == len(expected) and all(e in p for e, p in zip(expected, printed, strict=True))
    assert (vehicle == "single-wheelset") == bool(expected)
