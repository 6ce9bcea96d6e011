"""The vehicle summary: masses, axle loads, CG, named lateral modes, critical speeds, warnings, the CLI hooks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from railopt.models.units import GRAVITY
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.loader import bundled_path
from railopt.models.vehicle.summary import (
    main_validate_vehicle,
    mode_table,
    vehicle_summary,
)
from railopt.studies.cli import main_vehicle

from conftest import routh_hurwitz


@pytest.fixture(scope="module")
def loco_summary():
    return vehicle_summary(load_vehicle("sd40-2"))


def row(modes, name: str):
    rows = modes[modes["name"] == name]
    assert len(rows) >= 1, list(modes["name"])
    return rows.iloc[0]


def test_masses_axle_loads_cg(loco_summary) -> None:
    s = loco_summary
    assert s.total_mass == pytest.approx(166_922.0, abs=1.0)
    assert s.mass_by_kind == pytest.approx({"body": 151_922.0, "wheelset": 15_000.0}, abs=1.0)
    assert len(s.axle_loads) == 6
    assert set(np.round(list(s.axle_loads.values()), 6)) == {round(GRAVITY * 166_922.0 / 6, 6)}  # 272.8 kN
    v = load_vehicle("sd40-2")
    z = sum(b.mass * b.cg[2] for b in v.bodies) / v.total_mass
    assert s.cg[2] == pytest.approx(z, rel=1e-12) and s.cg[2] == pytest.approx(1.4743, abs=1e-4)
    assert s.cg[0] == pytest.approx(0.0, abs=1e-9)


def test_critical_speeds_on_both_tracks(loco_summary) -> None:
    assert loco_summary.critical["rigid"].speed == pytest.approx(33.876, abs=0.01)
    assert loco_summary.critical["flexible"].speed == pytest.approx(33.169, abs=0.01)
    coach = vehicle_summary(load_vehicle("manchester-coach"))
    assert coach.critical["rigid"].speed == pytest.approx(79.885, abs=0.01)
    assert coach.critical["flexible"].speed == pytest.approx(79.912, abs=0.01)
    assert coach.warnings == [] and loco_summary.warnings == []


def test_mode_names_of_the_locomotive(loco_summary) -> None:
    m = loco_summary.modes
    assert list(m.columns) == ["frequency_hz", "damping_ratio", "real", "name", "share"]
    assert len(m) == 9  # 9 lateral DOF: one row per mode (two of them overdamped: real root pairs)
    hunting = row(m, "body hunting (trucks in phase)")  # the trucks' kinematic motion carrying the body at 20 m/s
    assert hunting.frequency_hz == pytest.approx(0.437, abs=1e-3)
    assert hunting.damping_ratio == pytest.approx(0.041, abs=1e-3)
    assert row(m, "body yaw").frequency_hz == pytest.approx(0.380, abs=1e-3)
    assert row(m, "body roll (upper sway)").frequency_hz == pytest.approx(1.850, abs=1e-3)
    assert m["name"].is_unique  # distinct modes, distinct names
    assert np.all(np.diff(m["frequency_hz"].to_numpy()) >= 0.0)


def test_hunting_mode_near_critical_speed_is_the_critical_root() -> None:
    """At 0.99 × the critical speed the mode named hunting is the least damped one, at the critical frequency."""
    coach = load_vehicle("manchester-coach")
    m = mode_table(coach, 79.0)
    hunting = row(m, "bogie hunting (in phase)")
    assert hunting.frequency_hz == pytest.approx(4.502, abs=1e-3)
    assert hunting.damping_ratio == pytest.approx(m["damping_ratio"].min())
    assert row(m, "body lateral (lower sway)").frequency_hz == pytest.approx(0.647, abs=1e-3)
    ws = mode_table(load_vehicle("single-wheelset"), 74.0)
    assert list(ws["name"]) == ["wheelset lateral", "wheelset hunting"]
    assert ws["frequency_hz"].iloc[1] == pytest.approx(6.349, abs=1e-3)
    # at the Routh–Hurwitz critical speed the mode named hunting is the root on the imaginary axis
    speed, frequency = routh_hurwitz(1500.0, 700.0, 1e6, 2e6, 10e6, 9e6, 0.1, 0.75, 0.45)
    at_critical = mode_table(load_vehicle("single-wheelset"), speed)
    hunting = row(at_critical, "wheelset hunting")
    assert hunting.frequency_hz == pytest.approx(frequency, rel=1e-9)
    assert abs(hunting.damping_ratio) < 1e-9


def test_flexible_track_modes_named_track() -> None:
    m = mode_table(load_vehicle("sd40-2"), 30.0, "flexible")
    track = m[m["name"].str.startswith("track")]  # "track", "track #2", ...
    assert len(track) == 6
    assert track["frequency_hz"].to_numpy() == pytest.approx(25.28, abs=0.05)


@pytest.mark.parametrize("name", ["sd40-2", "manchester-coach"])
def test_summary_at_the_asked_speed_and_track(name: str) -> None:  # its time: `railopt bench`, not a test
    v = load_vehicle(name)
    s = vehicle_summary(v, speed=25.0, track="flexible")
    assert s.speed == 25.0 and s.track == "flexible"


def test_reports(loco_summary) -> None:
    text = loco_summary.to_text()
    assert "rigid     33.88 m/s (122.0 km/h)  0.670 Hz" in text  # the frequency at the certified crossing
    assert "0.437         0.041          -0.114    body hunting (trucks in phase)" in text
    assert "- no warnings" in text
    md = loco_summary.to_markdown()
    assert "| flexible | 33.17 m/s (119.4 km/h) | 0.659 Hz | body hunting (front truck) |" in md
    assert "| axle load (6 wheelsets) | 272.8 kN (27.82 t) |" in md
    assert len(repr(loco_summary)) < 300


def test_main_vehicle_hook(tmp_path: Path) -> None:
    text, code = main_vehicle(["manchester-coach", "--speed", "79", "--markdown"])
    assert code == 0 and "| 4.502 | 0.005 | -0.139 | bogie hunting (in phase) | 0.58 |" in text
    bad = tmp_path / "car.toml"
    bad.write_text(bundled_path("manchester-coach").read_text().replace("[track]", "[trak]"))
    text, code = main_vehicle([str(bad)])
    assert code == 2 and text == f"railopt: error: {bad}: trak: unknown table or key at the top level; did you mean " \
                                  "'track'?"
    text, code = main_vehicle(["sd40-2", "--track", "soft"])
    assert code == 2 and "usage: railopt vehicle" in text
    assert text.splitlines()[-1].startswith("railopt vehicle: error: argument --track: invalid choice: 'soft'")


def test_main_validate_vehicle_lists_warnings(tmp_path: Path) -> None:
    path = tmp_path / "car.toml"
    path.write_text(bundled_path("manchester-coach").read_text().replace("conicity = 0.15", "conicity = 2.5"))
    text, code = main_validate_vehicle(str(path))
    assert code == 0
    assert f"warning: {path}: contact.conicity: conicity 2.5 is above 0.5" in text
    path.write_bytes(b"\xff")
    text, code = main_validate_vehicle(str(path))
    expected = f"railopt: error: {path}: not a text file (byte 0 is not UTF-8); a vehicle file is a TOML file"
    assert (text, code) == (expected, 2)
