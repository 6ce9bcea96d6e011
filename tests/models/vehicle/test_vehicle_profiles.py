"""A vehicle file's ``[wheel_rail]`` table (issue 26 item 1): profiles named in the file, the linear model's
conicity from them by EN 15302, the contact table for the nonlinear model, and errors that name the key.

Independent reference: EN 15302 Annex E case E1 (R-UIC 519-A wheels, 920 mm, on S-UIC 519-A rails, gauge
1435.16 mm), reference tan γe at ŷ = 3 mm = 0.188 (criogenox/B_ECC ben_E1.dat, tests/models/contact/
en15302_annex_e.py), Annex F tolerance ±min(0.05, 0.5 tan γe).  The rails' data are already inclined (1:20, found
in issue 26's profile work), so the file says ``inclination = 0``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from railopt.models.contact import PROFILE_NAMES
from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.loader import VehicleFileError
from tests.models.contact import en15302_annex_e as annex_e

COACH = Path(__file__).parents[3] / "models" / "vehicle" / "data" / "manchester-coach.toml"
CONICITY = "conicity = 0.15            # stated equivalent conicity for S1002 / UIC60 1:40 (linear model)\n"


def _without_wheel_rail(text: str) -> str:
    return re.sub(r"^\[wheel_rail\].*?(?=^\[)", "", text, flags=re.M | re.S)


def _coach(tmp_path: Path, wheel_rail: str, keep_conicity: bool = False, radius: str | None = None) -> Path:
    text = COACH.read_text()
    assert CONICITY in text
    text = _without_wheel_rail(text)  # the bundled coach's own table, replaced below
    if not keep_conicity:
        text = text.replace(CONICITY, "")
    if radius is not None:
        text = re.sub(r'^wheel_radius_m = "r0"', f"wheel_radius_m = {radius}", text, flags=re.M)
    path = tmp_path / "coach.toml"
    path.write_text(text + "\n[wheel_rail]\n" + wheel_rail)
    return path


E1 = 'wheel_profile = "R-UIC 519-A"\nrail_profile = "S-UIC 519-A"\ninclination = 0.0\ngauge_m = 1.43516\n'


def test_conicity_from_profiles_meets_en15302_case_e1(tmp_path):
    v = load_vehicle(_coach(tmp_path, E1, radius="0.46"))
    amplitude, ref = annex_e.BENCH["E1"][:, 0], annex_e.BENCH["E1"][:, 1]
    expected = float(ref[np.isclose(amplitude, 3.0)][0])
    assert expected == 0.188
    assert abs(v.contact.conicity - expected) <= float(annex_e.annex_f_tolerance(expected))
    assert v.profiles.conicity_amplitude == 0.003 and v.profiles.inclination == 0.0


def test_profiles_give_the_linear_model_its_conicity_and_the_contact_table(tmp_path):
    path = _coach(tmp_path, 'wheel_profile = "s1002"\nrail_profile = "uic60"\ninclination = "1/40"\n')
    v = load_vehicle(path)
    table = v.contact_table()
    # the table's own small-amplitude slope: a restoring pair (Δr > 0 for y > 0), odd in y for a symmetric pair
    assert np.all(table.delta_r[table.y > 0] > 0)
    np.testing.assert_allclose(table.delta_r, -table.delta_r[::-1], atol=1e-12)
    # S1002 on UIC60 1:40 at 1360 mm back-to-back: tan γe(3 mm) lies in the band the literature quotes for a new
    # pair, 0.1-0.3 (EN 15302 Annex E cases run 0.13-0.40 at 1-7 mm); and it is what the linear model uses
    assert 0.1 < v.contact.conicity < 0.3
    assert v.wheel_rail().conicity == v.contact.conicity
    base = load_vehicle("manchester-coach")
    speeds = [critical_speed(x.lateral("rigid"), speed_range=(1.0, 150.0)).speed for x in (v, base)]
    assert speeds[0] < speeds[1]  # a higher conicity than the file's 0.15 lowers the coach's critical speed


def test_explicit_conicity_wins_for_the_linear_model(tmp_path):
    v = load_vehicle(_coach(tmp_path, 'wheel_profile = "s1002"\nrail_profile = "60e1"\ninclination = "1/40"\n',
                            keep_conicity=True))
    assert v.contact.conicity == 0.15 and v.profiles.rail_profile == "60e1"


@pytest.mark.parametrize(("table", "key", "words"), [
    ('wheel_profile = "s1003"\nrail_profile = "60e1"\ninclination = "1/40"\n', "wheel_rail.wheel_profile",
     "neither a profile name"),
    ('wheel_profile = "60e1"\nrail_profile = "60e1"\ninclination = "1/40"\n', "wheel_rail.wheel_profile",
     "is a rail profile, not a wheel profile"),
    ('wheel_profile = "s1002"\nrail_profile = "60e1"\ninclination = 40\n', "wheel_rail.inclination", "<= 0.1"),
    ('wheel_profile = "s1002"\nrail_profile = "60e1"\n', "wheel_rail: missing inclination", '"1/40"'),
    ('wheel_profile = "s1002"\nrail_profile = "60e1"\ninclination = "1/40"\ngauge_m = 1435\n', "wheel_rail.gauge_m",
     "<= 2"),
])
def test_bad_wheel_rail_tables_name_the_key(tmp_path, table, key, words):
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(_coach(tmp_path, table))
    assert key in str(err.value) and words in str(err.value) and "coach.toml" in str(err.value)


def test_no_conicity_and_no_profiles_is_refused_naming_the_field(tmp_path):
    path = tmp_path / "coach.toml"
    path.write_text(_without_wheel_rail(COACH.read_text()).replace(CONICITY, ""))
    with pytest.raises(VehicleFileError, match=r"contact\.conicity: missing; give conicity, a Δr table"):
        load_vehicle(path)


def test_a_profile_file_next_to_the_vehicle_file(tmp_path):
    rows = [(y, 0.0 if y > -30 else (y + 30) ** 2 / 40.0) for y in np.arange(-70.0, 60.01, 0.5)]
    (tmp_path / "worn.csv").write_text("# a test wheel\n" + "\n".join(f"{y:.2f},{-z:.5f}" for y, z in rows))
    with pytest.raises(VehicleFileError, match=r"wheel_rail\.wheel_profile: .*"):
        load_vehicle(_coach(tmp_path, 'wheel_profile = "worn_typo.csv"\nrail_profile = "60e1"\ninclination = 0.025\n'))
    # found next to the vehicle file; a CSV wheel has no flange-back position, so it cannot be placed: said so
    with pytest.raises(VehicleFileError, match=r"wheel_rail: the profiles cannot be placed .*flange_back"):
        load_vehicle(_coach(tmp_path, 'wheel_profile = "worn.csv"\nrail_profile = "60e1"\ninclination = 0.025\n'))
    assert all(name.lower() == name for name in PROFILE_NAMES)


def test_summary_lists_the_profiles_conicity_and_flange_onset():
    """The bundled coach names S1002 on 60E1 1:40: the summary gives the linear model's stated 0.15, the profiles'
    tan γe and the flange onset.  Reference for the onset: CONTACT's solution of the Manchester Contact Benchmark
    (S1002 on UIC60 1:40, 1360 mm back-to-back), flange contact beginning between y = 6.0 and 6.5 mm
    (eve70a/CONTACT examples/mbench_a22_*.ref_out, used in tests/models/contact/test_rigid_contact.py)."""
    from railopt.models.vehicle.summary import vehicle_summary

    rows = dict(vehicle_summary(load_vehicle("manchester-coach")).contact)
    assert rows["conicity of the linear model"] == "0.15 ([contact] conicity)"
    assert rows["profiles"].startswith("s1002 on 60e1 inclined 0.025")
    onset_mm = float(rows["flange contact from"].split("=")[1].split("mm")[0])
    assert 6.0 <= onset_mm <= 6.5
    assert "3 mm: 0.177" in rows["tan γe of the profiles"]  # the value docs/vehicle.md quotes


def test_summary_says_when_the_conicity_comes_from_the_profiles(tmp_path):
    from railopt.models.vehicle.summary import vehicle_summary

    v = load_vehicle(_coach(tmp_path, 'wheel_profile = "s1002"\nrail_profile = "60e1"\ninclination = "1/40"\n'))
    rows = dict(vehicle_summary(v).contact)
    assert rows["conicity of the linear model"] == f"{v.contact.conicity:.4g} ([wheel_rail] profiles, EN 15302 at 3 mm)"


def test_a_conicity_override_is_named_as_such(tmp_path):
    from railopt.models.vehicle.summary import contact_rows

    v = load_vehicle(_coach(tmp_path, 'wheel_profile = "s1002"\nrail_profile = "60e1"\ninclination = "1/40"\n'))
    assert v.contact.conicity_source == "profiles"
    override = v.with_parameters({"conicity": 0.2})
    assert override.contact.conicity == 0.2 and override.contact.conicity_source == "parameter override"
    assert dict(contact_rows(override))["conicity of the linear model"] == "0.2 (a parameter override)"
