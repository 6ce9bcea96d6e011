"""The strict vehicle schema and the loader's faults (V01–V07 and their kinds): each bad file is one
VehicleFileError naming the file and the key path, never a traceback; the bundled files load unchanged."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import VehicleFileError, load_vehicle, parse_vehicle
from railopt.models.vehicle.loader import bundled_path, evaluate

COACH = bundled_path("manchester-coach").read_text()
WS = bundled_path("single-wheelset").read_text()
LOCO = bundled_path("sd40-2").read_text()
TENSOR = "inertia_kg_m2 = [2.0e5, 3.0e6, 3.0e6]"


def refused(tmp_path: Path, base: str, old: str, new: str, pattern: str, count: int = 1) -> str:
    """Write ``base`` with ``old`` → ``new``; the load must raise naming the file and matching ``pattern``."""
    assert old in base, old
    path = tmp_path / "car.toml"
    path.write_text(base.replace(old, new, count))
    with pytest.raises(VehicleFileError, match=pattern) as err:
        load_vehicle(path)
    message = str(err.value)
    assert message.startswith(f"{path}: "), message
    assert "Traceback" not in message and "\n" not in message
    return message


# ---------------------------------------------------------------------------------------------- unknown keys
@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ("[cab]", "[cabin]", r": cabin: unknown table or key at the top level; did you mean 'cab'\?"),
        ("[track]", "[trak]", r": trak: unknown table or key at the top level; did you mean 'track'\?"),
        ('name = "body"\nkind = "body"\n', 'name = "body"\nkind = "body"\ncolour = "red"\n',
         r": bodies\[0\] \(body\)\.colour: unknown key"),
        ("stiffness_N_per_m = 160000.0\n", "stiffness_N_per_m = 160000.0\nstiffness_kN_per_m = 182.3\n",
         r": elements\[0\] \(ksx\)\.stiffness_kN_per_m: unknown key; did you mean 'stiffness_N_per_m'\?"),
        ("[vehicle]\n", 'units = "mm"\n[vehicle]\n', r": units: unknown table or key at the top level"),
        ("mirror_y = true", "mirror_Y = true",
         r": elements\[0\] \(ksx\)\.mirror_Y: unknown key; did you mean 'mirror_y'\?"),
        ("creep_factor = 1.0", "creep_facter = 1.0",
         r": contact\.creep_facter: unknown key; did you mean 'creep_factor'\?"),
        ("damping_ratio = 0.1", "damping_ration = 0.1",
         r": track\.damping_ration: unknown key; did you mean 'damping_ratio'\?"),
        ('r0 = { value = 0.46, source = "Iwnicki 1998" }', 'r0 = { value = 0.46, sauce = "Iwnicki 1998" }',
         r": lengths\.r0: sauce: unknown key; did you mean 'source'\?"),
    ],
)
def test_unknown_keys_and_tables_refused_with_did_you_mean(tmp_path: Path, old: str, new: str, pattern: str) -> None:
    refused(tmp_path, COACH, old, new, pattern)


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ("spin = true", 'spin = "no"', r": contact\.spin: expected true or false, got 'no'"),
        ("gravity_stiffness = true", "gravity_stiffness = 1",
         r": contact\.gravity_stiffness: expected true or false, got 1"),
        ("mirror_y = true", 'mirror_y = "true"',
         r": elements\[0\] \(ksx\)\.mirror_y: expected true or false, got 'true'"),
        ("mass_kg = 32000.0", "mass_kg = true", r": bodies\[0\] \(body\)\.mass_kg: expected a number or an arithmetic "
                                                r"expression, got True"),
        ('theory = "kalker"', 'theory = "kalkr"',
         r": contact: theory must be one of .*got 'kalkr'; did you mean 'kalker'\?"),
        ('creep = "hertz"', 'creep = "herz"',
         r": contact: creep must be one of 'given', 'hertz', got 'herz'; did you mean"),
        ('name = "wheelset1"\nkind = "wheelset"', 'name = "wheelset1"\nkind = "wheelst"',
         r": bodies\[2\] \(wheelset1\): kind must be one of 'body', 'wheelset', got 'wheelst'; "
         r"did you mean 'wheelset'"),
    ],
)
def test_types_and_choices_are_strict(tmp_path: Path, old: str, new: str, pattern: str) -> None:
    refused(tmp_path, COACH, old, new, pattern)


def test_body_kind_is_required(tmp_path: Path) -> None:
    """A body without kind is an error (a wheelset named wheelset1 without kind would silently get no contact)."""
    refused(tmp_path, COACH, 'name = "wheelset1"\nkind = "wheelset"\n', 'name = "wheelset1"\n',
            r": bodies\[2\] \(wheelset1\): missing kind \(kind = \"body\" or \"wheelset\"")
    refused(tmp_path, COACH, 'name = "body"\nkind = "body"\n', 'name = "body"\n',
     r": bodies\[0\] \(body\): missing kind")


def test_mirror_at_y_zero_refused(tmp_path: Path) -> None:
    refused(tmp_path, COACH, "stiffness_N_m_per_rad = 940000.0\n",
     "stiffness_N_m_per_rad = 940000.0\nmirror_y = true\n",
            r": elements\[7\] \(karb\)\.mirror_y: the element lies at y = 0")
    # a ground spring of the single wheelset: both points at y = 0
    refused(tmp_path, WS, "stiffness_N_per_m = 1.0e6\n", "stiffness_N_per_m = 1.0e6\nmirror_y = true\n",
            r": elements\[0\] \(ky\)\.mirror_y: the element lies at y = 0")


def test_mirror_off_centre_doubles_the_weight(tmp_path: Path) -> None:
    """mirror_y on an element at y = 0.8 adds its image at y = −0.8: two elements with one id."""
    text = WS.replace("point_b_m = [0.0, 0.0, \"r0\"]", "point_b_m = [0.0, 0.8, \"r0\"]").replace(
        "point_a_m = [0.0, 0.0, 0.0]", "point_a_m = [0.0, 0.8, 0.0]").replace(
        "stiffness_N_per_m = 1.0e6\n", "stiffness_N_per_m = 1.0e6\nmirror_y = true\n")
    path = tmp_path / "m.toml"
    path.write_text(text)
    v = load_vehicle(path)
    ky = [e for e in v.elements if e.id == "ky"]
    assert [e.point_a[1] for e in ky] == [0.8, -0.8]
    assert v.lateral(speed=10.0).K[0, 0] == pytest.approx(2.0e6)


# ---------------------------------------------------------------------------------------------- contact and track
@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ('wheel_radius_m = "r0"', "wheel_radius_m = 460.0",
         r": contact\.wheel_radius_m: the Hertz contact of a 460 m wheel.*is the radius in mm\?"),
        ("poisson_ratio = 0.28", "poisson_ratio = 3.0", r": contact\.poisson_ratio: must be <= 0\.5, got 3\.0"),
        ("poisson_ratio = 0.28", "poisson_ratio = -0.1", r": contact\.poisson_ratio: must be >= 0\.0, got -0\.1"),
        ("youngs_modulus_Pa = 2.1e11", "youngs_modulus_Pa = 0.0", r": contact\.youngs_modulus_Pa: must be positive"),
        ("rail_head_radius_m = 0.3", "rail_head_radius_m = -0.3", r": contact\.rail_head_radius_m: must be positive"),
        ("conicity = 0.15", "conicity = -0.15", r": contact\.conicity: must be >= 0\.0, got -0\.15"),
        ("track_modulus_N_m2 = 40.0e6", "track_modulus_N_m2 = 0.0", r": track\.track_modulus_N_m2: must be positive"),
        ("damping_ratio = 0.1", "damping_ratio = -0.1", r": track\.damping_ratio: must be >= 0\.0"),
        ("semi_gauge_m = 0.75", "semi_gauge_m = \"sqrt(-1)\"",
         r": contact\.semi_gauge_m: cannot evaluate 'sqrt\(-1\)' \(math domain error\)"),
    ],
)
def test_contact_and_track_errors_name_file_and_field(tmp_path: Path, old: str, new: str, pattern: str) -> None:
    message = refused(tmp_path, COACH, old, new, pattern)
    assert "a_over_b" not in message.split("(")[0]


def test_wheel_radius_in_mm_with_given_creep_is_named_when_it_cannot_be_computed(tmp_path: Path) -> None:
    """θ0 > 0 with r0 in mm makes e0 − r0 θ0 negative: the roll constraint fails, named at load."""
    text = WS.replace('wheel_radius_m = "0.45"', "wheel_radius_m = 450.0").replace("theta0 = 0.0", "theta0 = 0.05")
    path = tmp_path / "ws.toml"
    path.write_text(text)
    with pytest.raises(VehicleFileError, match=re.escape(f"{path}: contact") + r".*e0 - r0\*theta0") as err:
        load_vehicle(path)
    assert "\n" not in str(err.value)


# ---------------------------------------------------------------------------------------------- expressions (V01–V03)
@pytest.mark.parametrize(
    ("expr", "reason"),
    [
        ("10.0 ** 400", "result out of range"),  # V01
        ("2 ** 2000", "result out of range"),  # integer power: float arithmetic, no huge integer
        ("(-8) ** 0.5", "math domain error"),  # no complex result
        ("-" * 5000 + "r0", "expression longer than 200 characters"),  # V02
        ("sin(" * 33 + "r0" + ")" * 33, "nested deeper than 32 levels"),
        ("-" * 60 + "r0", "nested deeper than 32 levels"),
        ("sqrt(-1)", "math domain error"),  # V03
        ("r0 / 0", "float division by zero"),
        ("r00 + 1", "unknown length or angle 'r00'; did you mean 'r0'\\?"),
        ("__import__('os')", "unsupported expression element"),
        ("1e308 * 10", "must be finite"),
    ],
)
def test_expression_faults_name_the_item(tmp_path: Path, expr: str, reason: str) -> None:
    text = WS.replace('cg_m = [0.0, 0.0, "r0"]', f'cg_m = [0.0, 0.0, "{expr}"]')
    path = tmp_path / "ws.toml"
    path.write_text(text)
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(path)
    message = str(err.value)
    assert message.startswith(f"{path}: bodies[0] (wheelset).cg_m[2]: "), message
    assert re.search(reason, message), message
    assert len(message) < 400


def test_expression_in_an_element_point_names_element_and_index() -> None:
    with pytest.raises(ValueError, match=r"elements\[0\] \(ky\)\.point_b_m\[2\]: cannot evaluate '10 \*\* 10 \*\* 10'"):
        evaluate("10 ** 10 ** 10", {"r0": 0.45}, "elements[0] (ky).point_b_m[2]")
    assert evaluate("2 ** 10 + sqrt(16) - -1", {}, "x") == 1029.0


def test_non_utf8_file_named(tmp_path: Path) -> None:
    """V04: bytes FF FE at the start, and a bad byte in the middle."""
    path = tmp_path / "v04.toml"
    path.write_bytes(b"\xff\xfe" + WS.encode())
    with pytest.raises(VehicleFileError, match=re.escape(f"{path}: not a text file (byte 0 is not UTF-8)")):
        load_vehicle(path)
    middle = WS.encode().replace(b"Routh", b"R\xe9uth")
    path.write_bytes(middle)
    bad = middle.index(bytes([0xE9]))
    with pytest.raises(VehicleFileError, match=rf"not a text file \(byte {bad} is not UTF-8\)"):
        load_vehicle(path)


# ---------------------------------------------------------------------------------------------- aliases (V05)
@pytest.mark.parametrize(
    ("new", "pattern"),
    [
        ('ky = "kpsi"', r"aliases\.ky: shadows the element id 'ky'"),  # V05
        ('lateral_stiffness = "kpsi"', r"aliases\.lateral_stiffness: shadows the parameter 'lateral_stiffness'"),
        ('conicity = "wheelset.mass"', r"aliases\.conicity: shadows the parameter 'conicity'"),
        ('"wheelset.Izz" = "wheelset.mass"', r"aliases\.wheelset\.Izz: shadows the parameter 'wheelset\.Izz'"),
        ('weight = "wheelset.masss"', r"aliases\.weight: unknown parameter 'wheelset\.masss'; did you mean "
                                      r"'wheelset\.mass'\?"),
    ],
)
def test_alias_may_not_shadow_a_parameter(tmp_path: Path, new: str, pattern: str) -> None:
    refused(tmp_path, WS, 'mass = "wheelset.mass"', new, pattern)


def test_element_alias_may_not_be_another_id(tmp_path: Path) -> None:
    refused(tmp_path, WS, 'alias = "yaw_stiffness"', 'alias = "ky"',
            r"elements\[1\] \(kpsi\)\.alias: 'ky' is the id of another element")


# ---------------------------------------------------------------------------------------------- inertia (V06, V07)
@pytest.mark.parametrize(
    ("tensor", "pattern"),
    [
        ("[[2.0e5, 0.0, 1.0e6], [0.0, 3.0e6, 0.0], [1.0e6, 0.0, 3.0e6]]",
         r"bodies\[0\] \(body\)\.inertia_kg_m2: not positive semi-definite \(principal moments \[-1\.205e\+05,"),  # V06
        ("[[2.0e5, 3.0e5, 0.0], [3.0e5, 3.0e5, 0.0], [0.0, 0.0, 3.0e6]]",
         r"bodies\[0\] \(body\)\.inertia_kg_m2: not positive semi-definite"),  # Ixy^2 = 9e10 > Ixx Iyy = 6e10
        ("[[2.0e5, 0.0, 2.0e5], [0.0, 3.0e6, 0.0], [2.0e5, 0.0, 2.0e5]]",
         r"bodies\[0\] \(body\)\.inertia_kg_m2: singular inertia tensor \(principal moments \[0, 4e\+05, 3e\+06\]"),
        ("[2.0e5, 0.0, 3.0e6]", r"bodies\[0\] \(body\)\.inertia_kg_m2: singular inertia tensor"),
        ("[[2.0e5, 1.0, 0.0], [0.0, 3.0e6, 0.0], [0.0, 0.0, 3.0e6]]",
         r"bodies\[0\] \(body\)\.inertia_kg_m2: not symmetric"),
        ("[2.0e5, -3.0e6, 3.0e6]", r"bodies\[0\] \(body\)\.inertia_kg_m2: must be >= 0 on the diagonal"),
    ],
)
def test_inertia_tensor_checked(tmp_path: Path, tensor: str, pattern: str) -> None:
    refused(tmp_path, LOCO, TENSOR, f"inertia_kg_m2 = {tensor}", pattern)


def test_parse_vehicle_names_memory_source() -> None:
    with pytest.raises(VehicleFileError, match=r"^<memory>: missing \[vehicle\] table"):
        parse_vehicle({"bodies": []})
    with pytest.raises(VehicleFileError, match=r"^<memory>: \[bodies\] must be an array of tables"):
        parse_vehicle({"vehicle": {}, "bodies": {"name": "x"}})


# ---------------------------------------------------------------------------------------------- bundled files
@pytest.mark.parametrize(
    ("name", "track", "speed", "mass"),
    [("sd40-2", "rigid", 33.876, 166_922.0), ("sd40-2", "flexible", 33.169, 166_922.0),
     ("manchester-coach", "rigid", 79.885, 44_482.0), ("single-wheelset", "rigid", 74.320, 1_500.0)],
)
def test_bundled_files_load_unchanged_in_meaning(name: str, track: str, speed: float, mass: float) -> None:
    v = load_vehicle(name)
    assert v.total_mass == pytest.approx(mass, abs=1.0)
    cs = critical_speed(v, track=track, speed_range=(1.0, 100.0), tol=0.01)
    assert cs.speed == pytest.approx(speed, abs=0.01)


def test_vehicle_repr_is_short() -> None:
    r = repr(load_vehicle("sd40-2"))
    assert len(r) < 500
    assert r.startswith("Vehicle('sd40-2', 15 bodies (6 wheelsets), 116 elements (27 parameters), 166,922 kg, contact")


def test_infinite_values_refused_except_a_coned_tread(tmp_path: Path) -> None:
    refused(tmp_path, COACH, "youngs_modulus_Pa = 2.1e11", "youngs_modulus_Pa = inf",
            r": contact\.youngs_modulus_Pa: must be finite, got inf")
    path = tmp_path / "coned.toml"
    path.write_text(COACH.replace("rail_head_radius_m = 0.3",
                                  "rail_head_radius_m = 0.3\nwheel_transverse_radius_m = inf"))
    assert load_vehicle(path).contact.wheel_transverse_radius == float("inf")
