"""Plausibility warnings: the bundled vehicles are clean; each unit slip of the issue (on the Manchester coach)
and each other check produces its warning with the key path and the value."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.loader import VehicleFileError, bundled_path
from railopt.models.vehicle.plausibility import PlausibilityWarning, body_frequencies, plausibility, sprung_bodies
from railopt.models.vehicle.slips import LENGTH_UNITS, RATIO_UNITS, likely_slip, rescalings
from railopt.models.vehicle.summary import main_validate_vehicle

COACH = bundled_path("manchester-coach").read_text()
WS = bundled_path("single-wheelset").read_text()
LOCO = bundled_path("sd40-2").read_text()
TUTORIAL = Path(__file__).parents[3] / "docs" / "tutorial.md"


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


def test_the_tutorial_car_is_plausible(tmp_path: Path) -> None:
    """The two-axle car of docs/tutorial.md (wheelsets carried by the body, no bogies) gives no warning either."""
    car = re.search(r"<!-- file: car.toml -->\n```toml\n(.*?)```", TUTORIAL.read_text(), re.S).group(1)
    path = tmp_path / "car.toml"
    path.write_text(car)
    assert plausibility(load_vehicle(path)) == []


def loco_with(tmp_path: Path, old: str, new: str, count: int = 1):
    assert old in LOCO, old
    path = tmp_path / "loco.toml"
    path.write_text(LOCO.replace(old, new, count))
    return load_vehicle(path)


def only(warnings: list[PlausibilityWarning], check: str, path: str, exact: bool = False) -> PlausibilityWarning:
    """The one warning of ``check`` whose key contains ``path`` (is ``path``, when ``exact``)."""
    found = [w for w in warnings if w.check == check and (w.path == path if exact else path in w.path)]
    assert len(found) == 1, "\n".join(w.line() for w in warnings)
    return found[0]


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


@pytest.mark.parametrize(
    ("conicity", "said", "never"),
    [
        (1.5, "looks 10× too large: 1.5 → 0.15?", "0.015"),  # issue 27 item 8: 1.5 is 10× of 0.15, not per cent
        (15.0, "looks like per cent: 15 → 0.15?", "1.5"),  # per cent, and only per cent, lands in 0.02-0.5
        (2.5, "looks like per cent (2.5 → 0.025) or 10× too large (→ 0.25)?", "write"),  # both land: both said
        (7.0e4, "out of the range of tread conicities (0.02-0.5)", "→"),  # no power of ten to 1000 lands: none said
    ],
)
def test_conicity_suggests_only_rescalings_that_land_in_range(tmp_path: Path, conicity: float, said: str,
                                                               never: str) -> None:
    (w,) = plausibility(coach_with(tmp_path, "conicity = 0.15", f"conicity = {conicity!r}"))
    assert (w.path, w.value, w.check) == ("contact.conicity", conicity, "conicity")
    assert w.message == f"conicity {conicity:g} is above 0.5: {said}"
    assert never not in w.message.split(": ", 1)[1]


def test_rescalings_land_in_the_band_named_units_first() -> None:
    """Every suggested value lies in the band and is the value times a named factor or a power of ten."""
    found = rescalings(2.5, (0.02, 0.5), RATIO_UNITS)
    assert found == [("per cent", pytest.approx(0.025)), ("10× too large", pytest.approx(0.25))]
    assert rescalings(1280.0, (0.7, 1.8), LENGTH_UNITS) == [("mm", pytest.approx(1.28))]
    assert rescalings(0.0, (0.1, 1.0)) == [] and rescalings(7e4, (0.02, 0.5), RATIO_UNITS) == []
    assert likely_slip(8.4, (1.8, 3.0), LENGTH_UNITS, "m") == "looks like feet: 8.4 → 2.56 m?"


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


# ---------------------------------------------------------------------------------------------- issue 27 item 3
# Each slip the issue names, then a second of the same kind it does not name (often on the locomotive).
def test_semi_wheelbase_in_mm(tmp_path: Path) -> None:
    w = plausibility(coach_with(tmp_path, "value = 1.28,", "value = 1280.0,"))
    length = only(w, "length", "lengths.semi_wheelbase")
    assert length.value == 1280.0 and "looks like mm (1280 → 1.28 m)" in length.message
    assert length.file.endswith("coach.toml") and length.line().startswith(f"{length.file}: lengths.semi_wheelbase")
    spacing = only(w, "wheelbase", "bodies[3] (wheelset2).cg_m[0]")
    assert spacing.value == pytest.approx(2560.0) and "looks like mm: 2560 → 2.56 m?" in spacing.message
    loco = plausibility(loco_with(tmp_path, 'l23 = { value = 2.07,', 'l23 = { value = 2070.0,'))
    assert "looks like mm" in only(loco, "length", "lengths.l23").message
    assert only(loco, "wheelbase", "(wheelset3).cg_m[0]").value == pytest.approx(2070.0)


def test_bogie_semi_spacing_in_mm(tmp_path: Path) -> None:
    w = plausibility(coach_with(tmp_path, "value = 9.5,", "value = 9500.0,"))
    assert "looks like mm: 9500 → 9.5 m?" in only(w, "length", "lengths.bogie_semi_spacing").message
    assert only(w, "extent", "bodies[4] (bogie_front).cg_m[0]").value == 9500.0  # |x| beyond any vehicle (20 m)
    loco = plausibility(loco_with(tmp_path, 'l3 = { value = 6.629,', 'l3 = { value = 662.9,'))  # cm
    assert "like cm (→ 6.629 m)" in only(loco, "length", "lengths.l3").message


def test_primary_lateral_semi_spacing_and_damper_lever_in_mm(tmp_path: Path) -> None:
    """Through ``[lengths]``: the length's own warning (the positions it feeds are not repeated); written inline in
    a point: the point's warning, one per pair of bodies (both ends and the mirror image together)."""
    w = plausibility(coach_with(tmp_path, "primary_semi_spacing = { value = 1.0,",
                                "primary_semi_spacing = { value = 1000.0,"))
    assert "looks like mm (1000 → 1 m)" in only(w, "length", "lengths.primary_semi_spacing").message
    assert [x for x in w if x.check == "lateral_offset"] == []
    inline = COACH.replace('point_a_m = [0.0, "primary_semi_spacing", 0.0]', "point_a_m = [0.0, 1000.0, 0.0]")
    path = tmp_path / "inline.toml"
    path.write_text(inline)
    wide = [x for x in plausibility(load_vehicle(path)) if x.check == "lateral_offset"]
    assert [x.path for x in wide] == [f"elements (kpx, kpy, kpz, cpx, cpy, cpz: wheelset{i}-bogie_{s}).point_a_m[1]"
                                      for i, s in ((1, "rear"), (2, "rear"), (3, "front"), (4, "front"))]
    assert all("looks like mm: 1000 → 1 m?" in x.message for x in wide)
    loco = plausibility(loco_with(tmp_path, 'l11 = { value = 1.35,', 'l11 = { value = 1350.0,'))  # yaw damper lever
    assert "looks like mm" in only(loco, "length", "lengths.l11").message
    loco = plausibility(loco_with(tmp_path, 'point_a_m = ["-l6", "-l11", "-l15"]',
                                  'point_a_m = ["-l6", -1350.0, "-l15"]'))
    (lever,) = [x for x in loco if x.check == "lateral_offset"]
    assert lever.path == "elements (C15: body-frame_rear).point_a_m[1]"
    assert "looks like mm: -1350 → -1.35 m?" in lever.message


def test_primary_longitudinal_stiffness_in_kN_per_m(tmp_path: Path) -> None:
    """60,000 N/m meant as kN/m: above the 20 kN/m of any spring, but 0.12 MN/m per wheelset is below any primary."""
    path = tmp_path / "coach.toml"
    path.write_text(COACH.replace("stiffness_N_per_m = 31391000.0", "stiffness_N_per_m = 60000.0"))
    w = plausibility(load_vehicle(path))
    assert by_check(w, "stiffness") == []
    low = [x for x in w if x.check == "primary_stiffness"]
    assert [x.value for x in low] == [pytest.approx(1.2e5)] * 4  # per wheelset, both sides
    assert all(x.path == "elements (kpx).stiffness_N_per_m" and "kpx = 60000 N/m → ×1000?" in x.message for x in low)
    loco = plausibility(loco_with(tmp_path, "stiffness_N_per_m = 2700000.0", "stiffness_N_per_m = 27000.0", 6))
    assert [x.path for x in loco if x.check == "primary_stiffness"] == ["elements (K9).stiffness_N_per_m"] * 6


def test_track_modulus_in_MN_per_m2(tmp_path: Path) -> None:
    (w,) = plausibility(coach_with(tmp_path, "track_modulus_N_m2 = 40.0e6", "track_modulus_N_m2 = 40.0"))
    assert (w.path, w.check) == ("track.track_modulus_N_m2", "track")
    assert "looks like MN/m² (MPa): 40 → 4e+07 N/m²?" in w.message
    (loco,) = plausibility(loco_with(tmp_path, "rail_EI_N_m2 = 7.5935e6", "rail_EI_N_m2 = 7.5935e12"))  # N mm²
    assert loco.path == "track.rail_EI_N_m2" and "N·mm²" in loco.message


def test_body_Ixx_and_Izz_swapped(tmp_path: Path) -> None:
    w = plausibility(coach_with(tmp_path, "inertia_kg_m2 = [56800.0, 1970000.0, 1970000.0]",
                                "inertia_kg_m2 = [1970000.0, 1970000.0, 56800.0]"))
    roll = only(w, "gyration_size", "bodies[0] (body).inertia_kg_m2[0]")
    assert roll.value == pytest.approx((1970000.0 / 32000.0) ** 0.5) and "Ixx and Izz swapped?" in roll.message
    order = [x for x in w if x.check == "inertia_order"]
    assert len(order) == 2 and all("Ixx and Izz swapped?" in x.message for x in order)  # flat in z, long in x
    loco = plausibility(loco_with(tmp_path, "inertia_kg_m2 = [2.0e5, 3.0e6, 3.0e6]",
                                  "inertia_kg_m2 = [3.0e6, 3.0e6, 2.0e5]"))
    roll = only(loco, "gyration_size", "bodies[0] (body).inertia_kg_m2[0]")
    assert roll.value == pytest.approx((3e6 / 122522) ** 0.5)


def _without(text: str, wheelset: str) -> str:
    """The file without the body ``wheelset`` and every element on it (a wheelset deleted with its elements)."""
    parts = re.split(r"(?m)^(?=\[)", text)
    return "".join(p for p in parts if f'name = "{wheelset}"' not in p and f'body_a = "{wheelset}"' not in p
                   and f'body = "{wheelset}"' not in p and f'to = "{wheelset}"' not in p)


def test_a_wheelset_deleted_with_its_elements(tmp_path: Path) -> None:
    path = tmp_path / "coach.toml"
    path.write_text(_without(COACH, "wheelset4"))
    w = plausibility(load_vehicle(path))
    assert "wheelset deleted" in only(w, "bogie_wheelsets", "bodies[4] (bogie_front)", exact=True).message  # 1 vs 2
    off = only(w, "bogie_wheelsets", "bodies[4] (bogie_front).cg_m[0]")
    assert off.value == pytest.approx(1.28)  # the bogie's CG from its one wheelset: the semi-wheelbase
    cg = only(w, "vehicle_cg", "bodies (vehicle CG)")
    masses = np.array([32000.0] + [2615.0] * 2 + [1813.0] * 3)
    xs = np.array([0.0, -9.5, 9.5, -10.78, -8.22, 8.22])
    assert cg.value == pytest.approx(masses @ xs / masses.sum() - np.mean([-10.78, -8.22, 8.22]))
    path.write_text(_without(LOCO, "wheelset5"))  # a C-C locomotive with a 2-axle front truck
    loco = plausibility(load_vehicle(path))
    assert only(loco, "bogie_wheelsets", "bodies[2] (frame_front)", exact=True).value == 2
    assert only(loco, "wheelbase", "(wheelset6).cg_m[0]").value == pytest.approx(4.14)


def test_longitudinal_spring_with_a_lateral_direction(tmp_path: Path) -> None:
    v = coach_with(tmp_path, r'(id = "kpx"\n(?:.*\n)*?direction = )\[1.0, 0.0, 0.0\]', r"\g<1>[0.0, 1.0, 0.0]",
                   regex=True)
    w = by_check(plausibility(v), "direction")  # every kpx (one per wheelset) edited
    assert [x.path for x in w] == [f"elements (kpx: wheelset{i}-bogie_{s}).direction"
                                   for i, s in ((1, "rear"), (2, "rear"), (3, "front"), (4, "front"))]
    assert all("named for x (kpx / primary_longitudinal_stiffness) but acts along y" in x.message for x in w)
    loco = plausibility(loco_with(tmp_path, 'alias = "secondary_pivot_longitudinal_stiffness"\ntype = "spring"\n'
                                  'body_a = "body"\npoint_a_m = ["-(l3 + l16)", 0.0, "-l1"]\nbody_b = "frame_rear"\n'
                                  'point_b_m = ["-l16", 0.0, "l2"]\ndirection = [1.0, 0.0, 0.0]',
                                  'alias = "secondary_pivot_longitudinal_stiffness"\ntype = "spring"\n'
                                  'body_a = "body"\npoint_a_m = ["-(l3 + l16)", 0.0, "-l1"]\nbody_b = "frame_rear"\n'
                                  'point_b_m = ["-l16", 0.0, "l2"]\ndirection = [0.0, 0.0, 1.0]'))
    assert "named for x" in only(loco, "direction", "(K1: body-frame_rear).direction").message


def test_element_point_pairs_far_apart(tmp_path: Path) -> None:
    """A secondary spring's body end written at the other bogie (x sign): its ends are 19 m apart."""
    v = coach_with(tmp_path, r'(id = "ksz"\n(?:.*\n)*?point_a_m = \[)"-bogie_semi_spacing"',
                   r'\g<1>"bogie_semi_spacing"', regex=True)
    w = only(plausibility(v), "point_pair", "(ksz: body-bogie_rear)")
    assert w.value == pytest.approx(19.0) and "sign slip in point_a_m[0]?" in w.message


# ---------------------------------------------------------------------------------------------- issue 27 R6
@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ("mass_kg = 1813.0", "mass_kg = 1e-30", r"bodies\[2\] \(wheelset1\)\.mass_kg: 1e-30 kg is"),
        ("inertia_kg_m2 = [1722.0, 1476.0, 3067.0]", "inertia_kg_m2 = [1e-30, 1e-30, 1e-30]",
         r"bodies\[1\] \(bogie_rear\)\.inertia_kg_m2: principal moments"),
        ("mass_kg = 32000.0", "mass_kg = 1e30", r"bodies\[1\] \(bogie_rear\)\.mass_kg: 2615 kg is .* heaviest body "
                                                r"\(body, 1e\+30 kg\)"),
    ],
)
def test_a_body_without_mass_or_inertia_is_refused_naming_file_and_body(tmp_path: Path, old: str, new: str,
                                                                         key: str) -> None:
    path = tmp_path / "coach.toml"
    path.write_text(COACH.replace(old, new, 1))
    with pytest.raises(VehicleFileError, match=key) as err:
        load_vehicle(path)
    assert str(err.value).startswith(f"{path}: ")
    text, code = main_validate_vehicle(str(path))
    assert code == 2 and text.startswith(f"railopt: error: {path}: ") and re.search(key, text)


@pytest.mark.parametrize("value", ["0.0", "-0.0254", '"0.0254 - 1 / 25"'])
def test_a_clearance_that_admits_no_design_is_refused(tmp_path: Path, value: str) -> None:
    path = tmp_path / "loco.toml"
    path.write_text(LOCO.replace("secondary_lateral_m = { value = 0.0254,",
                                 f"secondary_lateral_m = {{ value = {value},"))
    with pytest.raises(VehicleFileError, match=r"clearances\.secondary_lateral_m: must be positive") as err:
        load_vehicle(path)
    assert str(err.value).startswith(f"{path}: ")


def test_plausibility_never_raises_on_a_vehicle_it_cannot_solve() -> None:
    """A view that cannot be solved is reported as a warning, not raised (validate must list, not crash)."""
    v = load_vehicle("manchester-coach")
    body = v.bodies[0]
    light = type(body)(body.name, 1e-20, body.inertia, body.cg, body.kind, body.source)
    broken = type(v)(**{**v.__dict__, "bodies": (light,) + v.bodies[1:], "_cache": {}})
    w = [x for x in plausibility(broken) if x.check == "body_frequency"]
    assert len(w) == 1 and "could not be computed" in w[0].message
