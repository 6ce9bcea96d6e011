"""Vehicle files: each bad input is a VehicleFileError naming the item and the file; nothing is written."""

from __future__ import annotations

from pathlib import Path

import pytest

from railopt.models.vehicle import VehicleFileError, load_vehicle

GOOD = """
[vehicle]
name = "test"

[lengths]
r0 = 0.45

[aliases]
mass = "wheelset.mass"

[[bodies]]
name = "wheelset"
kind = "wheelset"
mass_kg = 1500.0
inertia_kg_m2 = [700.0, 100.0, 700.0]
cg_m = [0.0, 0.0, "r0"]

[[elements]]
id = "ky"
alias = "lateral_stiffness"
type = "spring"
body_a = "wheelset"
body_b = "ground"
direction = [0.0, 1.0, 0.0]
stiffness_N_per_m = 1.0e6

[[elements]]
id = "kpsi"
type = "rotational_spring"
body_a = "wheelset"
body_b = "ground"
direction = [0.0, 0.0, 1.0]
stiffness_N_m_per_rad = 2.0e6

[contact]
conicity = 0.1
wheel_radius_m = "r0"
semi_gauge_m = 0.75
f11_N = 1.0e7
f22_N = 9.0e6
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "vehicle.toml"
    path.write_text(text)
    return path


def test_good_file_loads(tmp_path: Path) -> None:
    v = load_vehicle(write(tmp_path, GOOD))
    assert v.lateral(speed=10.0).n_dof == 2
    assert v.with_parameters({"mass": 1000.0}).body("wheelset").mass == 1000.0


@pytest.mark.parametrize(
    ("old", "new", "item"),
    [
        ("mass_kg = 1500.0", "mass_kg = -1500.0", "bodies\\[0\\] \\(wheelset\\): mass_kg"),
        ("mass_kg = 1500.0", "mass_kg = nan", "bodies\\[0\\] \\(wheelset\\).mass_kg"),
        ("stiffness_N_per_m = 1.0e6", "stiffness_N_per_m = nan", "elements\\[0\\] \\(ky\\).stiffness_N_per_m"),
        ('body_a = "wheelset"\nbody_b = "ground"\ndirection = [0.0, 1.0',
         'body_a = "wheelset"\nbody_b = "frame"\ndirection = [0.0, 1.0', "elements\\[0\\] \\(ky\\): body_b 'frame'"),
        ('mass = "wheelset.mass"', 'mass = "wheelset.weight"', "aliases.mass: unknown parameter 'wheelset.weight'"),
        ('cg_m = [0.0, 0.0, "r0"]', 'cg_m = [0.0, 0.0, "r1"]', "bodies\\[0\\] \\(wheelset\\).cg_m\\[2\\].*'r1'"),
        ('type = "spring"', 'type = "bushing"', "elements\\[0\\] \\(ky\\): type"),
        ("stiffness_N_per_m = 1.0e6", "damping_N_s_per_m = 1.0e6",
         "elements\\[0\\] \\(ky\\): missing stiffness_N_per_m"),
        ("f22_N = 9.0e6", "", "contact: missing f22_N"),
        ("semi_gauge_m = 0.75", "semi_gauge_m = 0.0", "contact.semi_gauge_m: must be positive"),
        ('[[bodies]]\nname = "wheelset"', '[[bodies]]\nnom = "wheelset"', "bodies\\[0\\] \\(\\?\\): missing name"),
        ("direction = [0.0, 1.0, 0.0]", "direction = [0.0, 0.0, 0.0]", "element 'ky': direction"),
    ],
)
def test_bad_file_names_item_and_file(tmp_path: Path, old: str, new: str, item: str) -> None:
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    before = sorted(tmp_path.iterdir())
    with pytest.raises(VehicleFileError, match=item) as err:
        load_vehicle(path)
    assert str(path) in str(err.value)
    assert isinstance(err.value, ValueError)
    assert sorted(tmp_path.iterdir()) == before  # nothing written


def test_missing_body_table_and_constraint_body(tmp_path: Path) -> None:
    no_bodies = GOOD.split("[[bodies]]")[0] + "[contact]" + GOOD.split("[contact]")[1]
    with pytest.raises(VehicleFileError, match="bodies") as err:
        load_vehicle(write(tmp_path, no_bodies))
    assert "vehicle.toml" in str(err.value)
    bad = GOOD + '\n[[constraints]]\ntype = "rigid"\nbody = "wheelset"\nto = "frame"\ndofs = ["u"]\n'
    with pytest.raises(VehicleFileError, match="constraints\\[0\\]: to 'frame' is not a body"):
        load_vehicle(write(tmp_path, bad))


def test_unknown_name_and_bad_toml(tmp_path: Path) -> None:
    with pytest.raises(VehicleFileError, match="no-such-loco.*bundled vehicles: sd40-2"):
        load_vehicle("no-such-loco")
    with pytest.raises(VehicleFileError, match="vehicle.toml: not valid TOML"):
        load_vehicle(write(tmp_path, "[vehicle\nname="))


def test_unknown_parameter_names_file(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD)
    with pytest.raises(ValueError, match=f"unknown parameter 'k2'.*{path.name}.*valid names: ky, kpsi"):
        load_vehicle(path).with_parameters({"k2": 1.0})


def test_inconsistent_repeated_id(tmp_path: Path) -> None:
    text = GOOD + '\n[[elements]]\nid = "ky"\ntype = "spring"\nbody_a = "wheelset"\nbody_b = "ground"\n' \
        'direction = [0.0, 1.0, 0.0]\nstiffness_N_per_m = 2.0e6\n'
    with pytest.raises(VehicleFileError, match="id 'ky' given two values"):
        load_vehicle(write(tmp_path, text))


def test_delta_r_table_gives_equivalent_conicity(tmp_path: Path) -> None:
    """Δr = 2λy (a coned pair) read as a table: EN 15302 equivalent conicity = λ."""
    y = [i * 0.0005 for i in range(-20, 21)]
    table = f"delta_r_y_m = {y}\ndelta_r_m = {[2 * 0.12 * v for v in y]}\namplitude_m = 0.003"
    v = load_vehicle(write(tmp_path, GOOD.replace("conicity = 0.1", table)))
    assert v.parameter("conicity") == pytest.approx(0.12, rel=1e-3)


def test_full_inertia_tensor(tmp_path: Path) -> None:
    text = GOOD.replace("inertia_kg_m2 = [700.0, 100.0, 700.0]",
                        "inertia_kg_m2 = [[700.0, 0.0, 0.0], [0.0, 100.0, 0.0], [0.0, 0.0, 650.0]]")
    v = load_vehicle(write(tmp_path, text))
    assert v.lateral(speed=10.0).M[1, 1] == 650.0
