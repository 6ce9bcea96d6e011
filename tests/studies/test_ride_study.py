"""Issue 17, integration: the campaign's ride objective ("rms") and the ride study (studies/ride_comfort.toml).

* The study's RMS values, recomputed from its committed design rows by a fresh vehicle (file → with_parameters →
  view → family forced per metre, amplitude 1), agree to 1e-9.
* The ride objective of the campaign equals ``random_response.rms`` of the same system (per metre), and its
  analytic gradient equals central differences.
* Bad input (an unknown standard, a negative track class, a speed of 0, a model without speed) is refused by
  validation, naming the field.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from railopt.models.random_response import rms
from railopt.models.track.spectra import irregularity_spectrum
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.irregularity import Irregularity
from railopt.studies.config import ConfigError, load_study
from railopt.studies.kinds.campaign import campaign_problem
from railopt.studies.kinds.campaign.config import CampaignStudyConfig

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "studies" / "ride_comfort.toml"
RESULTS = ROOT / "results" / "ride_comfort"
SEAT = "body[6,0.8,1.0].z"
NAMES = ["secondary_vertical_stiffness", "secondary_vertical_damping"]


def _coach_campaign(amplitude: float = 0.01, **spectrum) -> dict:
    return {
        "study": {"name": "ride_objective", "kind": "campaign"},
        "models": [{"label": "coach", "model": "vehicle_forced",
                    "options": {"vehicle": "manchester-coach", "view": "vertical", "speed_m_s": 40.0,
                                "input": {"kind": "vertical", "amplitude_m": amplitude}, "outputs": [SEAT],
                                "quantity": "acceleration"}}],
        "objective": {"output": SEAT, "band_hz": [0.5, 20.0],
                      "spectrum": spectrum or {"standard": "erri_b176", "level": "low", "component": "profile"}},
        "design": {"objectives": ["rms", "exact"], "n_starts": 2, "variables": [
            {"name": NAMES[0], "lower": 1e5, "upper": 2e6, "scale": "log"},
            {"name": NAMES[1], "lower": 1e3, "upper": 1e5, "scale": "log"}]},
    }


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(text)
    return path


# ---------------------------------------------------------------------------------------------- the study's numbers
def test_study_rms_recomputed_from_its_design_rows_by_a_fresh_vehicle():
    study = tomllib.loads(STUDY.read_text())
    models = {m["label"]: m["options"] for m in study["models"]}
    cases = {c["label"]: c for c in study["cases"]}
    designs = pd.read_csv(RESULTS / "designs.csv")
    assert set(designs["design"]) == {"existing", "minimax_sinusoid", "rms_random"}
    assert len(designs) == 3 * len(cases)
    checked = 0
    for _, row in designs.iterrows():
        case = cases[row["case"]]
        opts = models[case["model"]]
        vehicle = load_vehicle(opts["vehicle"])
        values = {v["name"]: float(row[v["name"]]) for v in case["variables"]}
        fresh = vehicle.with_parameters(values)
        view = (fresh.vertical if opts["view"] == "vertical" else fresh.lateral)(track=opts["track"],
                                                                                speed=opts["speed_m_s"])
        system = view.family(input=Irregularity(opts["input"]["kind"], 1.0), outputs=[case["output"]],
                             quantity="acceleration").at()  # per metre of irregularity
        spec = case["spectrum"]
        spectrum = irregularity_spectrum(spec["standard"], level=spec["level"], component=spec["component"])
        value = rms(system, spectrum, opts["speed_m_s"], tuple(case["band_hz"]), case["output"])
        assert value == pytest.approx(row["rms"], rel=1e-9, abs=0), (row["case"], row["design"])
        checked += 1
    assert checked == 6


def test_study_summary_states_comfort_before_and_after_for_both_vehicles():
    text = (RESULTS / "summary.md").read_text()
    assert text.count("**Comfort before → after") == 2
    for label in ("coach_seat_vertical", "locomotive_cab_lateral"):
        assert f"## {label}" in text
    designs = pd.read_csv(RESULTS / "designs.csv")
    for case, rows in designs.groupby("case"):
        rows = rows.set_index("design")
        # each optimum is best under its own criterion (the cross comparison is meaningful)
        assert rows.loc["rms_random", "rms"] <= rows["rms"].min() * (1 + 1e-9), case
        assert rows.loc["minimax_sinusoid", "peak_sinusoid"] <= rows["peak_sinusoid"].min() * (1 + 1e-9), case
        assert rows.loc["rms_random", "rms"] < rows.loc["existing", "rms"], case
        assert rows["stable"].all(), case


# ---------------------------------------------------------------------------------------------- the ride objective
def test_ride_objective_equals_random_response_rms_per_metre_and_its_gradient_central_differences():
    cfg = CampaignStudyConfig.model_validate(_coach_campaign(amplitude=0.01))
    setup = cfg.setups()["coach"]
    problem = campaign_problem(cfg, setup, "rms", "unconstrained")
    assert problem.has_analytic_gradient
    x = np.array([6.0e5, 3.0e4])
    ev = problem.evaluate(x, gradient=True)
    assert ev.f.shape == (1,)
    p, _ = setup.parameters(NAMES, x)
    spectrum = irregularity_spectrum("erri_b176", level="low", component="profile")
    direct = rms(setup.family.at(p), spectrum, 40.0, (0.5, 20.0), SEAT)
    assert ev.f[0] == pytest.approx(direct / 0.01, rel=1e-12)  # responses per 10 mm, objective per metre
    # the same design on a model forced by another amplitude: the objective is per metre, so the same
    other = CampaignStudyConfig.model_validate(_coach_campaign(amplitude=0.5))
    other_setup = other.setups()["coach"]
    assert campaign_problem(other, other_setup, "rms", "unconstrained").value(x) == pytest.approx(ev.f[0], rel=1e-9)
    for j in range(2):
        h = 1e-5 * x[j]
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        central = (problem.value(xp) - problem.value(xm)) / (2 * h)
        assert ev.df[0, j] == pytest.approx(central, rel=1e-6), j


def test_ride_objective_runs_with_the_stability_rows_of_the_constrained_problem():
    raw = _coach_campaign()
    raw["stability"] = {"speeds": 2}
    raw["design"]["variables"].append({"name": "secondary_lateral_damping", "lower": 1e3, "upper": 1e5,
                                       "scale": "log"})
    cfg = CampaignStudyConfig.model_validate(raw)
    setup = cfg.setups()["coach"]
    x = np.array([4.3e5, 2.0e4, 2.0e4])
    constrained = campaign_problem(cfg, setup, "rms", "constrained")
    ev = constrained.evaluate(x, gradient=True)
    assert ev.f == pytest.approx(campaign_problem(cfg, setup, "rms", "unconstrained").evaluate(x).f, rel=1e-12)
    assert ev.g.size > 0 and np.all(ev.g <= 0)  # the existing coach is stable up to 40 m/s
    assert ev.df.shape == (1, 3) and math.isfinite(constrained.value(x))


# ---------------------------------------------------------------------------------------------- bad input
def _campaign_toml(spectrum: str = 'standard = "erri_b176"\nlevel = "low"', speed: str = "40.0",
                   model: str = "vehicle_forced", objectives: str = '["rms"]') -> str:
    options = (f'{{ vehicle = "manchester-coach", view = "vertical", speed_m_s = {speed}, input = {{ kind = '
               f'"vertical", amplitude_m = 0.01 }}, outputs = ["{SEAT}"], quantity = "acceleration" }}'
               if model == "vehicle_forced" else "{ vehicle = \"sd40-2\" }")
    output = SEAT if model == "vehicle_forced" else "cab_acceleration"
    return f"""
[study]
name = "bad"
kind = "campaign"

[[models]]
label = "m"
model = "{model}"
options = {options}

[objective]
output = "{output}"
band_hz = [0.5, 3.0]

[objective.spectrum]
{spectrum}

[design]
objectives = {objectives}
n_starts = 1

[[design.variables]]
name = "secondary_lateral_stiffness"
lower = 1.0e5
upper = 2.0e6
"""


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"spectrum": 'standard = "aar"'}, "objective.spectrum.standard"),
    ({"spectrum": 'standard = "fra"\ntrack_class = -1\ncomponent = "profile"'}, "track_class"),
    ({"spectrum": 'standard = "fra"\ntrack_class = 4\ncomponent = "gauge"'}, "component"),
    ({"spectrum": 'standard = "table"\npath = "no_such_spectrum.csv"'}, "path"),
    ({"speed": "0.0"}, "models[0].options.speed_m_s"),
    ({"model": "cab_lateral"}, "design.objectives"),
])
def test_bad_ride_objective_input_is_refused_naming_the_field(tmp_path, kwargs, field):
    with pytest.raises(ConfigError) as err:
        load_study(_write(tmp_path, _campaign_toml(**kwargs)))
    assert field in str(err.value)
    if kwargs.get("model") == "cab_lateral":
        assert "speed_m_s" in str(err.value)


def test_a_band_outside_the_spectrum_is_refused_naming_the_band(tmp_path):
    text = _campaign_toml().replace("band_hz = [0.5, 3.0]", "band_hz = [0.5, 300.0]")
    with pytest.raises(ConfigError, match=r"objective\.band_hz"):
        load_study(_write(tmp_path, text))


def test_the_ride_study_validates_and_refuses_a_negative_class(tmp_path):
    load_study(STUDY)
    text = STUDY.read_text().replace('spectrum = { standard = "erri_b176", level = "low", component = "profile" }',
                                     'spectrum = { standard = "fra", track_class = -2, component = "profile" }')
    with pytest.raises(ConfigError, match=r"cases\.0\.spectrum.*track_class"):
        load_study(_write(tmp_path, text))


# ---------------------------------------------------------------------------------------------- end to end
@pytest.mark.slow
def test_ride_study_runs_end_to_end_and_reproduces_the_committed_rms(tmp_path):
    from railopt.studies.cli import main

    assert main(["run", str(STUDY), "--workers", "0", "--results", str(tmp_path), "--no-progress"]) == 0
    fresh = pd.read_csv(tmp_path / "ride_comfort" / "designs.csv")
    committed = pd.read_csv(RESULTS / "designs.csv")
    assert list(fresh["design"]) == list(committed["design"])
    np.testing.assert_allclose(fresh["rms"], committed["rms"], rtol=1e-6)
    assert (tmp_path / "ride_comfort" / "psd.png").is_file()


@pytest.mark.slow
def test_a_campaign_with_the_rms_objective_finds_the_ride_studys_rms_optimum(tmp_path):
    """The campaign kind's "rms" objective and the ride kind's RMS-random criterion are the same function: the
    campaign's best RMS equals the ride study's rms_random row of the coach (same model, band, spectrum)."""
    from railopt.studies.cli import main

    study = tomllib.loads(STUDY.read_text())
    coach = next(c for c in study["cases"] if c["model"] == "coach")
    options = next(m for m in study["models"] if m["label"] == "coach")["options"]
    variables = "\n".join(f'[[design.variables]]\nname = "{v["name"]}"\nlower = {v["lower"]}\nupper = {v["upper"]}\n'
                          f'scale = "{v["scale"]}"\n' for v in coach["variables"])
    spec = coach["spectrum"]
    text = f"""
[study]
name = "rms_campaign"
kind = "campaign"

[[models]]
label = "coach"
model = "vehicle_forced"
options = {{ vehicle = "{options['vehicle']}", view = "vertical", speed_m_s = {options['speed_m_s']}, input = {{ kind = "vertical", amplitude_m = 0.02 }}, outputs = ["{SEAT}"], quantity = "acceleration" }}

[objective]
output = "{SEAT}"
band_hz = {coach['band_hz']}
[objective.spectrum]
standard = "{spec['standard']}"
level = "{spec['level']}"
component = "{spec['component']}"

[design]
objectives = ["rms"]
n_starts = 2
start_from = ["existing"]

{variables}
"""  # noqa: E501
    path = _write(tmp_path, text)
    assert main(["run", str(path), "--workers", "0", "--results", str(tmp_path / "out"), "--no-progress"]) == 0
    comparison = pd.read_csv(tmp_path / "out" / "rms_campaign" / "comparison.csv")
    designs = pd.read_csv(RESULTS / "designs.csv")
    ride = designs[(designs["case"] == coach["label"]) & (designs["design"] == "rms_random")]["rms"].iloc[0]
    assert comparison["U_objective"].iloc[0] == pytest.approx(ride, rel=1e-6)
