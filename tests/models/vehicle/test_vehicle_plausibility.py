"""Plausibility warnings: the bundled vehicles are clean; each unit slip of the issue (on the Manchester coach)
and each other check produces its warning with the key path and the value."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.loader import bundled_path
from railopt.models.vehicle.plausibility import PlausibilityWarning, body_frequencies, plausibility, sprung_bodies

COACH = bundled_path("manchester-coach").read_text()
WS = bundled_path("single-wheelset").read_text()


def coach_with(tmp_path: Path, old: str, new: str, regex: bool = False):
    text = re.sub(old, new, COACH) if regex else COACH.replace(old, new, 1)
    assert text != COACH
    path = tmp_path / "coach.toml"
    path.write_text(text)
    return load_vehicle(path)


def by_check(warnings: list[PlausibilityWarning], check: str) -> list[PlausibilityWarning]:
    return [w for w in warnings if w.check == check]


@pytest.mark.parametrize("name", ["sd40-2", "manchester-coach"])
def test_bundled_vehicles_are_plausible(name: str) -> None:
    assert plausibility(load_vehicle(name)) == []


def test_body_frequencies_of_bundled_vehicles() -> None:
    """Lateral and bounce of the sprung body (one eigen-solve per view at 20 m/s, rigid track)."""
    coach = body_frequencies(load_vehicle("manchester-coach"))
    assert coach[("body", "lateral")] == pytest.approx(0.6719, abs=1e-3)
    assert coach[("body", "bounce")] == pytest.approx(1.0802, abs=1e-3)
    loco = body_frequencies(load_vehicle("sd40-2"))
    assert loco[("body", "lateral")] == pytest.approx(0.8557, abs=1e-3)
    assert loco[("body", "bounce")] == pytest.approx(2.3038, abs=1e-3)
    assert sprung_bodies(load_vehicle("sd40-2")) == ("body",)


# ---------------------------------------------------------------------------------------------- the slips
def test_secondary_lateral_stiffness_in_kN_per_m(tmp_path: Path) -> None:
    v = coach_with(tmp_path, r'(id = "ksy"\n(?:.*\n)*?stiffness_N_per_m = )160000.0', r"\g<1>160.0", regex=True)
    w = plausibility(v)
    (spring,) = by_check(w, "stiffness")
    assert spring.path == "elements (ksy).stiffness_N_per_m" and spring.value == 160.0
    assert "kN/m" in spring.message
    (freq,) = by_check(w, "body_frequency")
    assert freq.path == "bodies[0] (body): lateral frequency"
    assert freq.value == pytest.approx(7.97e-4, rel=1e-2)  # ≈ sqrt(4·160 N/m / 32 t)/2π... nearly free


def test_body_mass_in_tonnes(tmp_path: Path) -> None:
    w = plausibility(coach_with(tmp_path, "mass_kg = 32000.0", "mass_kg = 32.0"))
    (mass,) = by_check(w, "mass")
    assert (mass.path, mass.value) == ("bodies[0] (body).mass_kg", 32.0)
    assert "tonnes" in mass.message
    gyration = by_check(w, "gyration")
    assert [round(g.value, 1) for g in gyration] == [42.1, 248.1, 248.1]  # sqrt(56800/32), sqrt(1.97e6/32)
    (bounce,) = by_check(w, "body_frequency")
    assert bounce.path == "bodies[0] (body): bounce frequency" and bounce.value == pytest.approx(3.452, abs=1e-3)


def test_semi_gauge_in_mm(tmp_path: Path) -> None:
    (w,) = plausibility(coach_with(tmp_path, "semi_gauge_m = 0.75", "semi_gauge_m = 750"))
    assert (w.path, w.value, w.check) == ("contact.semi_gauge_m", 750.0, "semi_gauge")


def test_conicity_in_per_cent(tmp_path: Path) -> None:
    (w,) = plausibility(coach_with(tmp_path, "conicity = 0.15", "conicity = 2.5"))
    assert (w.path, w.value) == ("contact.conicity", 2.5)
    assert "per cent (write 0.025)" in w.message


def test_body_cg_height_in_mm(tmp_path: Path) -> None:
    (w,) = plausibility(coach_with(tmp_path, 'cg_m = [0.0, 0.0, "h_body"]', "cg_m = [0.0, 0.0, 1800.0]"))
    assert (w.path, w.value, w.check) == ("bodies[0] (body).cg_m[2]", 1800.0, "cg_height")
    assert "mm" in w.message


# ---------------------------------------------------------------------------------------------- the other checks
def test_wheel_radius_outside_usual_band(tmp_path: Path) -> None:
    v = coach_with(tmp_path, 'r0 = { value = 0.46, source = "Iwnicki 1998" }', "r0 = 0.9")
    (w,) = by_check(plausibility(v), "wheel_radius")
    assert (w.path, w.value) == ("contact.wheel_radius_m", 0.9)
    assert by_check(plausibility(v), "cg_height") == []  # the wheelset CG follows r0 ("r0" expression)


def test_wheelset_cg_away_from_rolling_radius(tmp_path: Path) -> None:
    v = coach_with(tmp_path, 'cg_m = ["-bogie_semi_spacing - semi_wheelbase", 0.0, "r0"]',
                   'cg_m = ["-bogie_semi_spacing - semi_wheelbase", 0.0, 0.2]')
    (w,) = plausibility(v)
    assert (w.path, w.value) == ("bodies[2] (wheelset1).cg_m[2]", 0.2)


def test_axle_load_outside_band(tmp_path: Path) -> None:
    light = plausibility(load_vehicle("single-wheelset"))
    assert [(w.check, w.value) for w in light] == [("axle_load", 1.5)]  # a 1.5 t wheelset alone
    heavy = coach_with(tmp_path, "theta0 = 0.0\n", "theta0 = 0.0\naxle_load_N = 5.0e5\n")
    (w,) = by_check(plausibility(heavy), "axle_load")
    assert w.path == "contact.axle_load_N" and w.value == pytest.approx(5.0e5 / 9.80665 / 1000.0)


def test_damper_in_kN_s_per_m(tmp_path: Path) -> None:
    v = coach_with(tmp_path, r'(id = "csy"\n(?:.*\n)*?damping_N_s_per_m = )32000.0', r"\g<1>32.0", regex=True)
    (w,) = by_check(plausibility(v), "damping")
    assert (w.path, w.value) == ("elements (csy).damping_N_s_per_m", 32.0)


def test_wheelset_without_contact_and_unloaded_body(tmp_path: Path) -> None:
    extra = ('[[bodies]]\nname = "wheelset9"\nkind = "body"\nmass_kg = 1500.0\ninertia_kg_m2 = [700.0, 100.0, 700.0]\n'
             'cg_m = [3.0, 0.0, "r0"]\n\n')
    text = WS.replace("[[elements]]", extra + "[[elements]]", 1)
    path = tmp_path / "ws.toml"
    path.write_text(text)
    w = plausibility(load_vehicle(path))
    named = by_check(w, "wheelsets")
    assert [x.path for x in named] == ["bodies[1] (wheelset9).kind"]
    (alone,) = by_check(w, "unconnected")
    assert (alone.path, alone.value) == ("bodies[1] (wheelset9)", 1500.0)


def test_contact_table_without_wheelsets(tmp_path: Path) -> None:
    path = tmp_path / "ws.toml"
    path.write_text(WS.replace('kind = "wheelset"', 'kind = "body"'))
    w = plausibility(load_vehicle(path))
    assert [x.path for x in by_check(w, "wheelsets")] == ["contact", "bodies[0] (wheelset).kind"]
