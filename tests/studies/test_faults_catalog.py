"""Fault tests of the model catalog (issue 16 item 13 and F02–F04, issue 15 finding 7).

Physical parameters (stiffness, damping, mass, inertia) cannot be designed below zero; the critical-speed search
ranges of the vehicle models are ordered, finite, positive intervals; a vehicle's readable aliases are design
variables wherever an element id is.  Refusals are checked through a real ``railopt validate`` process: exit 2,
one line naming the field, nothing written.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from railopt.models.vehicle import load_vehicle
from railopt.studies.catalog import ModelRef, ParameterMap
from railopt.studies.catalog.vehicle import physical_limits
from railopt.studies.cli import STUDIES_DIR

CLI = [sys.executable, "-m", "railopt.studies.cli"]


def validate(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, "validate", str(path)], capture_output=True, text=True, timeout=120,
                          cwd=path.parent)


def refused(path: Path, message: str) -> None:
    """``railopt validate`` exits 2 with one line on stderr containing ``message``, nothing on stdout, no files."""
    before = sorted(path.parent.iterdir())
    done = validate(path)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert message in lines[0], lines[0]
    assert done.stdout == ""
    assert sorted(path.parent.iterdir()) == before


def flagship(tmp_path: Path, replacements: dict[str, str]) -> Path:
    """The bundled flagship study with text replaced (each old text must occur)."""
    text = (STUDIES_DIR / "cab_lateral_minimax.toml").read_text()
    for old, new in replacements.items():
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / "study.toml"
    path.write_text(text)
    return path


def setup(model: str, **options):
    vehicle = {} if model == "tmd" else {"vehicle": "sd40-2"}  # vehicle models need one named
    return ModelRef(label="m", model=model, options={**vehicle, **options}).setup("models[0]")


# ---------------------------------------------------------------------------------------------- physical bounds
@pytest.mark.parametrize("model", ["cab_lateral", "vehicle_lateral", "vehicle_forced"])
@pytest.mark.parametrize("name, lower, key, what", [
    ("secondary_lateral_stiffness", -1.0e6, "K2", "stiffness"),
    ("K2", -0.5, "K2", "stiffness"),
    ("C2", -1.0, "C2", "damping coefficient"),
    ("lateral_shock_absorber_damping", -1.0e4, "C13", "damping coefficient"),
])
def test_negative_element_bounds_are_refused_naming_the_lower_bound(model, name, lower, key, what):
    pm = setup(model).parameter_map
    label = name if name == key else f"{name} ({key})"
    with pytest.raises(ValueError) as err:
        pm.check_bounds(name, lower, 5.0e6, "design.variables[2]")
    assert str(err.value) == (f"design.variables[2].lower: {label} is a {what} and cannot be below 0; "
                              f"got {lower:g}")


@pytest.mark.parametrize("model", ["cab_lateral", "vehicle_lateral", "vehicle_forced"])
def test_zero_and_positive_element_bounds_pass(model):
    pm = setup(model).parameter_map
    pm.check_bounds("secondary_lateral_stiffness", 0.0, 5.0e6, "design.variables[0]")
    pm.check_bounds("C2", 1.0e3, 1.0e6, "design.variables[1]")


def test_every_vehicle_parameter_is_physical():
    s = setup("vehicle_forced")
    assert set(s.parameter_map.limits) == set(s.family.parameters)
    assert {v[0] for v in s.parameter_map.limits.values()} == {0.0}


def test_mass_and_inertia_are_physical():
    vehicle = load_vehicle("sd40-2")
    body = vehicle.bodies[0].name
    limits = physical_limits(vehicle, [f"{body}.mass", f"{body}.Izz", "K2", "conicity"])
    assert limits == {f"{body}.mass": (0.0, "mass"), f"{body}.Izz": (0.0, "moment of inertia"),
                      "K2": (0.0, "stiffness")}
    pm = ParameterMap((f"{body}.mass", f"{body}.Izz", "K2", "conicity"), np.array([1.0e5, 1.0e6, 5.0e5, 0.05]),
                      limits=limits)
    with pytest.raises(ValueError, match=rf"^design.variables\[0\].lower: {body}.mass is a mass and cannot be "
                                         r"below 0; got -2000$"):
        pm.check_variables([_Var(f"{body}.mass", -2000.0, 1.0e5)])
    with pytest.raises(ValueError, match=rf"^design.variables\[1\].lower: {body}.Izz is a moment of inertia"):
        pm.check_variables([_Var("K2", 0.0, 1.0), _Var(f"{body}.Izz", -1.0, 1.0)])
    pm.check_variables([_Var("conicity", -0.1, 0.3)])  # not a physical magnitude: either sign allowed


def test_nan_lower_bound_is_refused():
    pm = setup("cab_lateral").parameter_map
    with pytest.raises(ValueError, match=r"^design.variables\[0\].lower: K2 is a stiffness .* got nan$"):
        pm.check_bounds("K2", float("nan"), 1.0, "design.variables[0]")


@pytest.mark.parametrize("name, what", [("k2", "stiffness"), ("c2", "damping coefficient"),
                                        ("tuning", "frequency ratio"), ("damping_ratio", "damping ratio")])
def test_tmd_parameters_are_physical(name, what):
    pm = setup("tmd", mass_ratio=0.05).parameter_map
    with pytest.raises(ValueError, match=rf"^design.variables\[0\].lower: {name} is a {what} and cannot be below 0"):
        pm.check_bounds(name, -0.01, 1.0, "design.variables[0]")


class _Var:
    def __init__(self, name, lower, upper):
        self.name, self.lower, self.upper = name, lower, upper


def test_frf_design_with_a_negative_damping_ratio_is_refused(tmp_path):
    text = (STUDIES_DIR / "tmd_frf.toml").read_text()
    old = "values = { tuning = 0.952, damping_ratio = 0.02 }"
    assert old in text
    path = tmp_path / "study.toml"
    path.write_text(text.replace(old, "values = { tuning = 0.952, damping_ratio = -0.02 }"))
    refused(path, "designs[2].values.damping_ratio: a damping ratio cannot be below 0, got -0.02")


def test_campaign_with_negative_stiffness_bound_is_refused(tmp_path):  # F02
    path = flagship(tmp_path, {"lower = 1.0e5\nupper = 5.0e6\nscale = \"log\"":
                               "lower = -1.0e6\nupper = 5.0e6\nscale = \"linear\""})
    refused(path, "design.variables[0].lower: secondary_lateral_stiffness (K2) is a stiffness and cannot be below 0; "
                  "got -1e+06")


# ---------------------------------------------------------------------------------------------- search ranges
@pytest.mark.parametrize("interval, message", [
    ("[300.0, 2.0]", ": inverted or empty: lower 300.0 ≥ upper 2.0"),
    ("[2.0, 2.0]", ": inverted or empty: lower 2.0 ≥ upper 2.0"),
    ("[0.0, 300.0]", ": lower end must be > 0, got 0.0"),
    ("[-5.0, 300.0]", ": lower end must be > 0, got -5.0"),
    ("[nan, 300.0]", ".0: Input should be a finite number (got nan)"),  # every number of a config is finite
    ("[2.0, inf]", ".1: Input should be a finite number (got inf)"),
])
def test_cab_critical_search_must_be_an_ordered_positive_interval(tmp_path, interval, message):  # F03
    path = flagship(tmp_path, {"max_operating_speed_mph = 70.0 }":
                               f"max_operating_speed_mph = 70.0, critical_search_mph = {interval} }}"})
    refused(path, f"models[0].options.critical_search_mph{message}")


@pytest.mark.parametrize("interval, message", [
    ("[150.0, 1.0]", "inverted or empty: lower 150.0 ≥ upper 1.0"),
    ("[0.0, 150.0]", "lower end must be > 0, got 0.0"),
    ("[-1.0, 150.0]", "lower end must be > 0, got -1.0"),
])
@pytest.mark.parametrize("model", ["vehicle_lateral", "vehicle_forced"])
def test_vehicle_critical_search_must_be_an_ordered_positive_interval(interval, message, model):
    with pytest.raises(ValueError) as err:
        ModelRef(label="m", model=model, options={"vehicle": "sd40-2", "critical_search_m_s": eval(interval)}
                 ).setup("models[0]")
    assert str(err.value) == f"models[0].options.critical_search_m_s: {message}"


def test_cab_critical_search_reaches_the_hunting_check_in_m_s():
    s = setup("cab_lateral", critical_search_mph=[10.0, 200.0])
    assert s.checks["hunting"].search == pytest.approx((10.0 * 0.44704, 200.0 * 0.44704), rel=1e-15)


# ---------------------------------------------------------------------------------------------- aliases
@pytest.mark.parametrize("model", ["vehicle_forced", "vehicle_lateral", "cab_lateral"])
def test_aliases_are_design_variables_and_named_design_entries(model):
    s = setup(model)
    assert s.parameter_map.aliases["secondary_lateral_stiffness"] == "K2"
    assert {"secondary_lateral_stiffness", "lateral_shock_absorber_damping", "K2"} <= set(s.designable)
    existing = s.named_designs["existing"]
    assert existing["secondary_lateral_stiffness"] == existing["K2"] == 5.0e5
    p_alias, J_alias = s.parameters(["secondary_lateral_stiffness", "C13"], np.array([1.23e6, 2.0e5]))
    p_id, J_id = s.parameters(["K2", "lateral_shock_absorber_damping"], np.array([1.23e6, 2.0e5]))
    names = list(s.family.parameters)
    assert p_alias[names.index("K2")] == 1.23e6 and p_alias[names.index("C13")] == 2.0e5
    np.testing.assert_array_equal(p_alias, p_id)
    np.testing.assert_array_equal(J_alias, J_id)


def test_vehicle_forced_campaign_with_aliases_validates(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text("""
[study]
name = "forced_aliases"
kind = "campaign"

[[models]]
label = "sd40-2"
model = "vehicle_forced"
options = { vehicle = "sd40-2", view = "lateral", input = { kind = "alignment" }, outputs = ["body.v"] }

[objective]
band_hz = [0.5, 3.0]

[design]
n_starts = 1
start_from = ["existing"]

[[design.variables]]
name = "secondary_lateral_stiffness"
lower = 1.0e5
upper = 5.0e6
scale = "log"

[[design.variables]]
name = "lateral_shock_absorber_damping"
lower = 1.0e4
upper = 1.0e6
scale = "log"

[report]
compare = ["existing"]
""")
    done = validate(path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"{path}: valid campaign study 'forced_aliases'"
