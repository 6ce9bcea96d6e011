"""Issue 27, study-config validation: everything a run would refuse or silently get wrong, ``railopt validate``
refuses first, exit 2, with one line naming the file and the dotted field — each kind of fault by the input the
issue names and a second input of the same kind.

Kinds: a vehicle model without ``vehicle`` (item 2); vacuous stability rows (R3: an exclude entry that matches
nothing or everything, rows collapsed onto one speed); outputs that land on one file (R4); names that cannot be
file names and non-finite numbers (R5); asymmetric vehicles (item 6: ``view = "full"``, the coupling element
named); ``[stability] tracks`` of a ride model (item 7); misspelt tables, keys and parameters (item 8, with a
did-you-mean, never the whole list) and speed-sweep factors of 0 (item 8).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle
from railopt.studies.cli import STUDIES_DIR, main
from railopt.studies.config import load_study

VEHICLES = Path(__file__).resolve().parents[2] / "models" / "vehicle" / "data"
FLAGSHIP = (STUDIES_DIR / "cab_lateral_minimax.toml").read_text()
TMD = (STUDIES_DIR / "tmd_hinf.toml").read_text()
SWEEP = (STUDIES_DIR / "locomotive_stability.toml").read_text()


def write(tmp_path: Path, text: str, replacements: dict[str, str], name: str = "study.toml") -> Path:
    """``text`` with each old string (which must occur) replaced once, written to ``tmp_path / name``."""
    for old, new in replacements.items():
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / name
    path.write_text(text)
    return path


def refused(capsys, path: Path, field: str, *words: str) -> str:
    """``railopt validate`` exits 2 with one ``railopt: error: <file>: <field>: ...`` line holding every word."""
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    errors = [line for line in err if line.startswith("railopt: error:")]
    assert len(errors) == 1, err
    line = errors[0]
    assert line.startswith(f"railopt: error: {path}: {field}"), line
    for word in words:
        assert word in line, (word, line)
    return line


def valid(capsys, path: Path) -> None:
    assert main(["validate", str(path)]) == 0, capsys.readouterr().err
    capsys.readouterr()


# ---------------------------------------------------------------------------------------------- item 2: vehicle
@pytest.mark.parametrize("text, old, new", [
    (FLAGSHIP, 'vehicle = "sd40-2", ', ""),  # cab_lateral (the issue's)
    (SWEEP, 'options = { vehicle = "sd40-2", track = "rigid" }', 'options = { track = "rigid" }'),  # vehicle_lateral
])
def test_a_vehicle_model_without_vehicle_is_refused(tmp_path, capsys, text, old, new):
    path = write(tmp_path, text, {old: new})
    refused(capsys, path, "models[0].options.vehicle", "Field required")


def test_a_forced_model_without_vehicle_is_refused(tmp_path, capsys):
    ride = (STUDIES_DIR / "ride_comfort.toml").read_text()
    path = write(tmp_path, ride, {'options = { vehicle = "manchester-coach", ': "options = { "})
    refused(capsys, path, "models[0].options.vehicle", "Field required")


# ---------------------------------------------------------------------------------------------- R3: vacuous rows
@pytest.mark.parametrize("exclude, field, words", [
    ('[""]', "stability.exclude", ["entry 0 is empty", "every root"]),  # the issue's
    ('["body hunting", "   "]', "stability.exclude", ["entry 1 is blank"]),
    ('["bdoy hunting"]', "stability.exclude[0]", ["unknown mode name 'bdoy hunting'", "did you mean 'body hunting'"]),
    ('["body hunting", "rear truk"]', "stability.exclude[1]", ["unknown mode name 'rear truk'", "did you mean"]),
    ('["body", "frame_front", "frame_rear"]', "stability.exclude", ["leaves out every mode", "constrain nothing"]),
])
def test_an_exclude_that_makes_the_stability_rows_vacuous_is_refused(tmp_path, capsys, exclude, field, words):
    path = write(tmp_path, FLAGSHIP, {"zeta_min = 0.02 ": f"zeta_min = 0.02\nexclude = {exclude} "})
    refused(capsys, path, field, *words)


def test_an_exclude_naming_a_mode_or_a_group_is_accepted(tmp_path, capsys):
    for exclude in ('["body hunting"]', '["frame_front"]', '["body h"]'):  # a name, a group, a prefix
        valid(capsys, write(tmp_path, FLAGSHIP, {"zeta_min = 0.02 ": f"zeta_min = 0.02\nexclude = {exclude} "}))


@pytest.mark.parametrize("old, new, field, words", [
    # the issue's: a required speed below the lowest collapses the 12 rows onto one speed
    ("lowest_speed_m_s = 15.0", "lowest_speed_m_s = 15.0\nrequired_speed_m_s = 10.0",
     "stability.lowest_speed_m_s", ["15 m/s is not below the required speed 10 m/s", "collapse"]),
    ("lowest_speed_m_s = 15.0", "lowest_speed_m_s = 20.0\nrequired_speed_m_s = 20.0",  # equal: collapsed too
     "stability.lowest_speed_m_s", ["20 m/s is not below the required speed 20 m/s"]),
    ("lowest_speed_m_s = 15.0", "lowest_speed_m_s = 40.0",  # above the model's maximum operating speed (31.3 m/s)
     "stability.lowest_speed_m_s", ["40 m/s is not below the required speed 31.2928 m/s",
                                    "maximum operating speed of models[0]"]),
    ("speeds = 12 ", "speeds = 1 ", "stability.lowest_speed_m_s", ["required speed is never checked"]),
    ("epsilons = [26.0,", "epsilons = [15.0,", "tradeoffs[1].epsilons", ["15 m/s is not above", "lowest_speed_m_s"]),
])
def test_rows_collapsed_onto_one_speed_are_refused(tmp_path, capsys, old, new, field, words):
    refused(capsys, write(tmp_path, FLAGSHIP, {old: new}), field, *words)


# -------------------------------------------------------------------------------------------- R4: one file, two writers
def test_two_tradeoffs_of_one_name_are_refused(tmp_path, capsys):  # the issue's
    path = write(tmp_path, FLAGSHIP, {'name = "damping"': 'name = "stroke"'})
    refused(capsys, path, "tradeoffs[2].name", "'stroke' is the name of tradeoffs[0] too")


@pytest.mark.parametrize("pair", [
    '["sidebearer1_vertical_stiffness", "secondary_lateral_stiffness"]',  # the issue's: either order
    '["secondary_lateral_stiffness", "sidebearer1_vertical_stiffness"]',
])
def test_two_surfaces_over_one_pair_are_refused(tmp_path, capsys, pair):
    path = write(tmp_path, FLAGSHIP, {"relax = 0.001": f"relax = 0.001\n\n[[surfaces]]\nvariables = {pair}"})
    refused(capsys, path, "surfaces[1].variables", "is the pair of surfaces[0]")


def test_tradeoffs_of_two_models_that_land_on_one_file_are_refused(tmp_path, capsys):
    """Trade-off ``s_x`` of model ``y`` and trade-off ``s`` of model ``x_y`` both write tradeoff_s_x_y.csv."""
    path = write(tmp_path, TMD, {'label = "mu0.05"': 'label = "y"', 'label = "mu0.1"': 'label = "x_y"',
                                 '[report]': '[[tradeoffs]]\nname = "s_x"\noutput = "amplification"\n'
                                             'epsilons = [1.0, 2.0]\n\n[[tradeoffs]]\nname = "s"\n'
                                             'output = "amplification"\nepsilons = [1.0, 2.0]\n\n[report]'})
    refused(capsys, path, "tradeoffs[1].name", "tradeoff_s_x_y.csv is also a file of tradeoffs[0].name")


def test_two_models_whose_campaign_stores_are_one_file_are_refused(tmp_path, capsys):
    """The unconstrained campaign of ``m`` and the constrained one of ``m-unconstrained`` are one store."""
    path = write(tmp_path, TMD, {'label = "mu0.05"': 'label = "m"', 'label = "mu0.1"': 'label = "m-unconstrained"',
                                 'methods = ["slsqp"]': 'methods = ["slsqp"]\nproblems = ["constrained", '
                                                        '"unconstrained"]'})
    refused(capsys, path, "models[1].label", "campaigns/m-unconstrained-thesis-slsqp.sqlite is also a file of "
                                             "models[0].label")


def test_forced_response_panels_drawing_one_figure_are_refused(tmp_path, capsys):
    """A second panel of one output (its velocity) in one group: both figures would be <group>_body_u_<band>.png."""
    text = (STUDIES_DIR / "locomotive_vertical_response.toml").read_text()
    first = '  { figure = "Fig 4.5", title = "Body longitudinal displacement", output = "body.u" },\n'
    path = write(tmp_path, text, {first: first + '  { title = "Body longitudinal velocity", output = "body.u", '
                                                 'quantity = "velocity" },\n'})
    refused(capsys, path, "groups[0].panels[1].output", "is also the figure of groups[0].panels[0].output")


def test_speed_sweep_labels_drawing_one_mode_figure_are_refused(tmp_path, capsys):
    path = write(tmp_path, SWEEP, {'label = "sd40-2_rigid"': 'label = "sd40-2.flexible"'})
    refused(capsys, path, "models[1].label", "modes_sd40-2_flexible.png is also that of models[0]")


# ---------------------------------------------------------------------------------------------- R5: run-time refusals
@pytest.mark.parametrize("name, words", [
    ("t" * 300, ["too long for a file name: 300 characters, at most 100"]),  # the issue's
    ("a/b", ["'/' cannot be part of a file name"]),
    ("", ["must not be empty"]),
])
def test_a_tradeoff_name_that_cannot_be_a_file_name_is_refused(tmp_path, capsys, name, words):
    line = refused(capsys, write(tmp_path, FLAGSHIP, {'name = "damping"': f'name = "{name}"'}), "tradeoffs.2.name",
                   *words)
    assert "t" * 100 not in line  # a long name is counted, not repeated


@pytest.mark.parametrize("old, new, field", [
    ('name = "cab_lateral_minimax"', f'name = "{"s" * 101}"', "study.name"),
    ('label = "sd40-2"', f'label = "{"m" * 150}"', "models.0.label"),
    ('label = "sd40-2"', 'label = "a\\\\b"', "models.0.label"),
])
def test_other_names_that_become_file_names_are_refused(tmp_path, capsys, old, new, field):
    refused(capsys, write(tmp_path, FLAGSHIP, {old: new}), field)


@pytest.mark.parametrize("old, new, field", [
    ("xtol = 1e-8", "xtol = inf", "design.options.xtol"),  # the three
    ("ftol = 1e-10", "ftol = inf", "design.options.ftol"),
    ("maxtime = 120.0", "maxtime = inf", "design.options.maxtime"),
    ("xtol = 1e-8", "xtol = nan", "design.options.xtol"),
    ("sigma_min = 0.005", "sigma_min = inf", "stability.sigma_min"),
    ("band_hz = [0.0, 3.0]", "band_hz = [0.0, inf]", "objective.band_hz.1"),
    ("epsilons = [0.005, 0.01,", "epsilons = [0.005, nan,", "tradeoffs.2.epsilons.1"),
    ("max_operating_speed_mph = 70.0 }", "max_operating_speed_mph = 70.0, parameters = { K2 = inf } }",
     "models[0].options.parameters.K2"),  # a float in a model's options
])
def test_a_non_finite_number_is_refused_naming_the_field(tmp_path, capsys, old, new, field):
    refused(capsys, write(tmp_path, FLAGSHIP, {old: new}), field, "finite")


@pytest.mark.parametrize("study, old, new, field", [
    ("ride_comfort", "n_starts = 2", "n_starts = 2\noptions = { xtol = inf }", "design.options.xtol"),
    ("wheelset_stability", "tol_m_s = 0.01", "tol_m_s = inf", "critical.tol_m_s"),
    ("track_moving_load", "EI_N_m2 = 7.5935296e6", "EI_N_m2 = inf", "track.EI_N_m2"),  # a StrictModel table
    ("tmd_frf", "mass_ratio = 0.05", "mass_ratio = nan", "models[0].options.mass_ratio"),
])
def test_every_kind_refuses_a_non_finite_number(tmp_path, capsys, study, old, new, field):
    text = (STUDIES_DIR / f"{study}.toml").read_text()
    refused(capsys, write(tmp_path, text, {old: new}), field, "finite")


def test_a_damping_tradeoff_target_of_1_or_more_is_refused(tmp_path, capsys):
    path = write(tmp_path, FLAGSHIP, {"epsilons = [0.005, 0.01,": "epsilons = [0.005, 1.5,"})
    refused(capsys, path, "tradeoffs.2.epsilons", "damping ratios below 1, got 1.5")


def test_the_command_line_exits_2_naming_file_and_field(tmp_path):
    path = write(tmp_path, FLAGSHIP, {"xtol = 1e-8": "xtol = inf"})
    done = subprocess.run([sys.executable, "-m", "railopt.studies.cli", "validate", str(path)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 2
    assert done.stderr.strip() == (f"railopt: error: {path}: design.options.xtol: Input should be a finite number "
                                   "(got inf)")


# ---------------------------------------------------------------------------------------------- item 6: asymmetric
def one_sided(tmp_path: Path, element: str) -> Path:
    """The Manchester coach with ``mirror_y`` dropped from ``element``: one side only."""
    text = (VEHICLES / "manchester-coach.toml").read_text()
    start = text.index(f'id = "{element}"')
    cut = text.index("mirror_y = true\n", start)
    path = tmp_path / f"coach_{element}.toml"
    path.write_text(text[:cut] + text[cut + len("mirror_y = true\n"):])
    return path


def coach_sweep(tmp_path: Path, vehicle: Path | str, view: str = "") -> Path:
    extra = f', view = "{view}"' if view else ""
    text = (f'[study]\nname = "coach"\nkind = "speed_sweep"\n\n[[models]]\nlabel = "coach"\nmodel = "vehicle_lateral"\n'
            f'options = {{ vehicle = "{vehicle}", track = "rigid"{extra} }}\n\n[speeds]\nrange_m_s = [5.0, 100.0]\n'
            "points = 4\n\n[critical]\nrange_m_s = [5.0, 150.0]\npoints = 16\n")
    path = tmp_path / f"sweep{view}.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("element", ["csz", "csx"])  # a one-sided vertical damper; a one-sided longitudinal one
def test_an_asymmetric_vehicle_in_a_symmetric_view_names_the_element_and_the_full_view(tmp_path, capsys, element):
    car = one_sided(tmp_path, element)
    refused(capsys, coach_sweep(tmp_path, car), "models[0].options.view", f"'{element}'",
            "forgotten mirror_y = true", 'view = "full"')
    valid(capsys, coach_sweep(tmp_path, car, "full"))


def test_the_full_view_of_a_symmetric_vehicle_gives_the_lateral_views_critical_speed(tmp_path):
    """For a symmetric vehicle the blocks decouple: the full view's critical speed is the lateral block's (the
    single wheelset: 4 coordinates in full, 2 in the lateral view)."""
    found, sizes = {}, {}
    for view in ("lateral", "full"):
        _, cfg, _ = load_study(coach_sweep(tmp_path, "single-wheelset", view))
        setup = cfg.models[0].setup("models[0]")
        family = setup.stability_model(setup.defaults)
        found[view], sizes[view] = critical_speed(family, speed_range=(5.0, 300.0), tol=1e-3), family.n
        assert found[view].certified
    assert sizes == {"lateral": 2, "full": 4}
    assert found["full"].speed == pytest.approx(found["lateral"].speed, abs=2e-3)


# ---------------------------------------------------------------------------------------------- item 7: ride + tracks
COACH = '''[study]
name = "coach_ride"
kind = "campaign"

[[models]]
label = "coach"
model = "{model}"
options = {{ vehicle = "{vehicle}", {options}track = "{track}", speed_m_s = 40.0, max_operating_speed_m_s = 40.0 }}

[objective]
output = "{output}"
band_hz = [0.5, 8.0]

[stability]
tracks = {tracks}
speeds = 3

[design]
objectives = ["exact"]
n_starts = 2
checks = ["hunting"]

[[design.variables]]
name = "kpx"
lower = 1.0e6
upper = 3.0e8
scale = "log"
'''
FORCED = 'view = "lateral", input = { kind = "alignment", amplitude_m = 0.001 }, outputs = ["cab.lateral"], '


@pytest.mark.parametrize("model, options, output, track, tracks", [
    ("vehicle_forced", FORCED, "cab.lateral", "rigid", '["rigid", "flexible"]'),  # the issue's
    ("vehicle_lateral", "", "body.v", "flexible", '["rigid", "flexible"]'),
    ("vehicle_forced", FORCED, "cab.lateral", "rigid", '["flexible"]'),
])
def test_stability_tracks_beyond_the_models_own_are_constrained_and_checked(tmp_path, model, options, output,
                                                                            track, tracks):
    path = tmp_path / "ride.toml"
    path.write_text(COACH.format(model=model, vehicle="manchester-coach", options=options, output=output,
                                 track=track, tracks=tracks))
    _, cfg, _ = load_study(path)
    setup = cfg.setups()["coach"]
    wanted = sorted({track, *eval(tracks)})
    assert sorted(setup.stability) == wanted and sorted(setup.checks["hunting"].stability) == wanted
    coach = load_vehicle("manchester-coach")
    for t in wanted:  # each family the vehicle's own lateral view on that track (the rows' size)
        assert setup.stability[t].n == coach.lateral(track=t).n_dof
    from railopt.studies.adapter import stability_target

    target = stability_target(cfg.stability, setup)
    assert target.tracks == tuple(eval(tracks))
    assert target.rows(setup) == 3 * sum(coach.lateral(track=t).n_dof for t in eval(tracks))


def test_a_track_the_vehicle_has_no_data_for_is_refused(tmp_path, capsys):
    path = tmp_path / "ride.toml"
    path.write_text(COACH.format(model="vehicle_lateral", vehicle="single-wheelset", options="", output="wheelset.v",
                                 track="rigid", tracks='["rigid", "flexible"]').replace('"kpx"', '"ky"')
                    .replace("lower = 1.0e6", "lower = 1.0e5"))
    refused(capsys, path, "stability.tracks", "no 'flexible' track", "[track]")


# ---------------------------------------------------------------------------------------------- item 8: did you mean
@pytest.mark.parametrize("old, new, field, words", [
    ("[report]", "[reprot]", "reprot", ["unknown table or key at the top level", "did you mean 'report'"]),
    ("[design.options]", "[design.optoins]", "design.optoins", ["unknown key", "did you mean 'options'"]),
    ("maxtime = 120.0", "maxtiem = 120.0", "design.options.maxtiem", ["did you mean 'maxtime'"]),
    ("sigma_min = 0.005", "sigma_mn = 0.005", "stability.sigma_mn", ["did you mean 'sigma_min'"]),
    ("amplitude_in = 0.25", "amplitud_in = 0.25", "models[0].options.amplitud_in", ["did you mean 'amplitude_in'"]),
])
def test_a_misspelt_table_or_key_gets_a_did_you_mean(tmp_path, capsys, old, new, field, words):
    refused(capsys, write(tmp_path, FLAGSHIP, {old: new}), field, *words)


@pytest.mark.parametrize("old, new, field, words", [
    ('name = "secondary_lateral_stiffness"   #', 'name = "secondary_lateral_stifness"   #', "design.variables[0].name",
     ["unknown parameter 'secondary_lateral_stifness'", "did you mean 'secondary_lateral_stiffness'"]),
    ('name = "secondary_lateral_stiffness"   #', 'name = "K22"   #', "design.variables[0].name",
     ["unknown parameter 'K22'", "did you mean 'K2'"]),
    ("max_operating_speed_mph = 70.0 }", "max_operating_speed_mph = 70.0, parameters = { conicty = 0.1 } }",
     "models[0].options.parameters.conicty", ["did you mean 'conicity'"]),
    ('output = "cab_acceleration" ', 'output = "cab_acceleraton" ', "objective.output",
     ["unknown output 'cab_acceleraton'", "did you mean 'cab_acceleration'"]),
])
def test_a_misspelt_parameter_gets_a_did_you_mean_not_the_whole_list(tmp_path, capsys, old, new, field, words):
    line = refused(capsys, write(tmp_path, FLAGSHIP, {old: new}), field, *words)
    assert "K1" not in line.replace("K2", "") and len(line) < 400  # no 70-name dump


def test_a_misspelt_sensitivity_parameter_gets_a_did_you_mean(tmp_path, capsys):
    path = write(tmp_path, SWEEP, {'parameter = "conicity"': 'parameter = "conicty"'})
    line = refused(capsys, path, "sensitivity[0].parameter", "did you mean 'conicity'")
    assert "K1" not in line


def zero_damper_sweep(tmp_path: Path, factors: str, parameter: str = "C13") -> Path:
    path = tmp_path / "zero.toml"
    path.write_text('[study]\nname = "zero_damper"\nkind = "speed_sweep"\n\n[[models]]\nlabel = "loco"\n'
                    'model = "vehicle_lateral"\noptions = { vehicle = "sd40-2", track = "rigid" }\n\n[speeds]\n'
                    "range_m_s = [5.0, 60.0]\npoints = 4\n\n[critical]\nrange_m_s = [5.0, 150.0]\npoints = 16\n\n"
                    f'[[sensitivity]]\nparameter = "{parameter}"\nfactors = {factors}\n')
    return path


def test_a_damper_switched_off_is_swept_in_the_users_order(tmp_path, capsys):
    """factors = [2, 0, 1, 0.5] of the lateral shock absorber C13: rows in that order, the 0 row the critical speed
    of the vehicle with C13 = 0 (computed here from the vehicle, not the study), the 1 row the model's own."""
    path = zero_damper_sweep(tmp_path, "[2.0, 0.0, 1.0, 0.5]")
    assert main(["run", str(path), "--results", str(tmp_path / "r"), "--workers", "0", "--no-progress"]) == 0
    capsys.readouterr()
    out = tmp_path / "r" / "zero_damper"
    sens = pd.read_csv(out / "sensitivity.csv")
    assert list(sens["factor"]) == [2.0, 0.0, 1.0, 0.5]
    loco = load_vehicle("sd40-2")
    for factor in (0.0, 1.0):
        vehicle = loco.with_parameters({"C13": factor * loco.parameter("C13")})
        view = vehicle.lateral(track="rigid")
        expected = critical_speed(view.family(list(view.parts)), speed_range=(5.0, 150.0), tol=0.01, grid=16).speed
        got = float(sens.loc[sens["factor"] == factor, "critical_speed_m_s"].iloc[0])
        assert got == pytest.approx(expected, abs=0.02)
    own = float(pd.read_csv(out / "critical_speeds.csv")["critical_speed_m_s"].iloc[0])
    assert float(sens.loc[sens["factor"] == 1.0, "critical_speed_m_s"].iloc[0]) == pytest.approx(own, abs=1e-9)
    summary = (out / "summary.md").read_text()
    rows = [line for line in summary.splitlines() if line.startswith("| C13 ")]
    assert [float(r.split("|")[2]) for r in rows] == [2.0, 0.0, 1.0, 0.5]


@pytest.mark.parametrize("parameter, factors, field, words", [
    ("track_modulus", "[1.0, 0.0]", "sensitivity[0].factors[1]", ["track_modulus × 0 = 0 gives no model"]),
    ("body.mass", "[0.0]", "sensitivity[0].factors[0]", ["body.mass × 0 = 0 gives no model", "massless"]),
    ("C13", "[1.0, -0.5]", "sensitivity.0.factors", ["must be ≥ 0"]),
])
def test_a_factor_the_physics_refuses_is_refused_on_validation(tmp_path, capsys, parameter, factors, field, words):
    refused(capsys, zero_damper_sweep(tmp_path, factors, parameter), field, *words)


def test_every_bundled_study_still_validates(capsys):
    for path in sorted(STUDIES_DIR.glob("*.toml")):
        assert main(["validate", str(path)]) == 0, (path, capsys.readouterr().err)
    capsys.readouterr()
