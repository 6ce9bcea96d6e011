"""The ``nonlinear_hunting`` check of campaigns and the ``nonlinear_hunting`` study kind (issue 26 items 6–7).

The end-to-end case: the single wheelset on S1002/60E1 1:40 (tests/models/vehicle/data/wheelset-s1002.toml)
required to run at 50 m/s.  Its existing suspension is linearly stable up to 74.3 m/s, yet keeps a stable hunting
cycle down to about 44.5 m/s: the linear check passes it and the nonlinear check must not.  The independent
evidence is a direct simulation of the nonlinear vehicle (solve_ivp, not the ramp or the check): at the required
speed, from the ramp's 2 mm disturbance, the existing design settles on a cycle and the recommended design decays.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.nonlinear import nonlinear_vehicle
from railopt.models.vehicle.wheelset_forces import SaturatedCreepLaw, profile_forces
from railopt.studies.cli import main
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.nonlinear_hunting import NonlinearHuntingStudyConfig

WHEELSET = str(Path(__file__).parents[1] / "models" / "vehicle" / "data" / "wheelset-s1002.toml")
REQUIRED = 50.0
RAW = {
    "study": {"name": "nonlinear_check", "kind": "campaign"},
    "models": [{"label": "wheelset", "model": "vehicle_forced",
                "options": {"vehicle": WHEELSET, "view": "lateral", "track": "rigid", "speed_m_s": 30.0,
                            "input": {"kind": "alignment", "amplitude_m": 0.001}, "outputs": ["wheelset.v"],
                            "max_operating_speed_m_s": REQUIRED}}],
    "objective": {"output": "wheelset.v", "band_hz": [0.5, 15.0]},
    "design": {"n_starts": 2, "seed": 4, "checks": ["hunting", "nonlinear_hunting"],
               "variables": [{"name": "lateral_stiffness", "lower": 5.0e5, "upper": 4.0e6, "scale": "log"},
                             {"name": "yaw_stiffness", "lower": 1.0e6, "upper": 8.0e6, "scale": "log"}]},
    "nonlinear_hunting": {"top_speed_m_s": 60.0, "step_m_s": 5.0, "fine_step_m_s": 1.0, "lowest_speed_m_s": 30.0,
                          "dwell_wavelengths": 15.0, "initial_amplitude_mm": 2.0, "continuation": False},
}


TOML = f"""
[study]
name = "nonlinear_check"
kind = "campaign"

[[models]]
label = "wheelset"
model = "vehicle_forced"

[models.options]
vehicle = "{WHEELSET}"
view = "lateral"
track = "rigid"
speed_m_s = 30.0
input = {{ kind = "alignment", amplitude_m = 0.001 }}
outputs = ["wheelset.v"]
max_operating_speed_m_s = {REQUIRED}

[objective]
output = "wheelset.v"
band_hz = [0.5, 15.0]

[design]
n_starts = 2
seed = 4
checks = ["hunting", "nonlinear_hunting"]

[[design.variables]]
name = "lateral_stiffness"
lower = 5.0e5
upper = 4.0e6
scale = "log"

[[design.variables]]
name = "yaw_stiffness"
lower = 1.0e6
upper = 8.0e6
scale = "log"

[nonlinear_hunting]
top_speed_m_s = 60.0
step_m_s = 5.0
fine_step_m_s = 1.0
lowest_speed_m_s = 30.0
dwell_wavelengths = 15.0
initial_amplitude_mm = 2.0
continuation = false
"""  # the same study as RAW, as a file for the CLI


def _raw(**changes) -> dict:
    raw = copy.deepcopy(RAW)
    for key, value in changes.items():
        raw[key] = value
    return raw


def test_the_check_needs_profiles_and_its_settings_need_the_check():
    sd40 = _raw(models=[{"label": "sd40-2", "model": "vehicle_forced",
                         "options": {"vehicle": "sd40-2", "view": "lateral", "track": "rigid",
                                     "input": {"kind": "alignment"}, "outputs": ["body.v"]}}])
    sd40["objective"] = {"output": "body.v", "band_hz": [0.5, 15.0]}
    sd40["design"] = {**sd40["design"], "variables": [
        {"name": "secondary_lateral_stiffness", "lower": 1e5, "upper": 5e6}]}
    with pytest.raises(ValueError, match=r"design\.checks.*\[wheel_rail\]"):
        CampaignStudyConfig.model_validate(sd40)
    unused = _raw(design={**RAW["design"], "checks": ["hunting"]})
    with pytest.raises(ValueError, match="nonlinear_hunting: settings given but design.checks"):
        CampaignStudyConfig.model_validate(unused)
    with pytest.raises(ValueError, match="top_speed_m_s"):
        CampaignStudyConfig.model_validate(_raw(nonlinear_hunting={**RAW["nonlinear_hunting"],
                                                                   "top_speed_m_s": 20.0}))


def test_the_check_takes_the_study_settings_and_required_speed():
    cfg = CampaignStudyConfig.model_validate(RAW)
    check = cfg.setups()["wheelset"].checks["nonlinear_hunting"]
    assert check.max_speed == REQUIRED
    a = check.analysis
    assert (a.top_speed, a.step, a.fine_step, a.lowest_speed) == (60.0, 5.0, 1.0, 30.0)
    assert a.initial_amplitude == pytest.approx(2e-3) and a.continuation is False
    assert check.flag_names == ("nonlinear_stable",)


@pytest.mark.parametrize("options, field", [
    ({"vehicle": "manchester-coach", "track": "flexible"}, "track"),
    ({"vehicle": "sd40-2"}, "wheel_rail"),
])
def test_the_study_kind_refuses_what_it_cannot_run(options, field):
    raw = {"study": {"name": "nh", "kind": "nonlinear_hunting"},
           "models": [{"label": "m", "model": "vehicle_lateral", "options": options}]}
    with pytest.raises(ValueError, match=field):
        NonlinearHuntingStudyConfig.model_validate(raw)
    raw["models"][0]["model"] = "cab_lateral"
    with pytest.raises(ValueError, match="vehicle_lateral"):
        NonlinearHuntingStudyConfig.model_validate(raw)


def _settles_on_a_cycle(values: dict[str, float]) -> bool:
    """A direct simulation of the nonlinear wheelset with ``values`` at the required speed from 2 mm: True when
    the motion over the last second is still at least a tenth of a millimetre (a hunting cycle), False when it
    has decayed below a micrometre."""
    vehicle = load_vehicle(WHEELSET).with_parameters(values)
    forces = profile_forces(vehicle.wheel_rail(), vehicle.contact_table(), SaturatedCreepLaw(0.3))
    nv = nonlinear_vehicle(vehicle, forces)
    x0 = np.zeros(2 * nv.n_dof)
    x0[nv.index("wheelset.v")] = 2e-3
    t = np.linspace(0.0, 6.0, 3001)
    y = solve_ivp(nv.rhs, (0.0, 6.0), x0, args=(REQUIRED,), t_eval=t, method="RK45", rtol=1e-7,
                  atol=1e-10).y[nv.index("wheelset.v")]
    late = np.max(np.abs(y[t > 5.0]))
    assert late > 1e-4 or late < 1e-6, f"neither a cycle nor rest after 6 s: {late:.3g} m"
    return bool(late > 1e-4)


@pytest.mark.slow
def test_a_campaign_recommends_only_a_design_without_a_hunting_cycle(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(TOML)
    assert main(["run", str(path), "--workers", "0", "--results", str(tmp_path / "out"), "--no-progress"]) == 0
    out = tmp_path / "out" / "nonlinear_check"
    optima = pd.read_csv(out / "optima.csv")
    assert {"nonlinear_hunting", "nonlinear_stable", "lowest_hunting_speed_m_s", "fold_confirmed"} <= set(optima)
    recommended = pd.read_csv(out / "recommended.csv")
    values = {n: float(recommended[n].iloc[0]) for n in ("lateral_stiffness", "yaw_stiffness")}
    row = optima.loc[np.isclose(optima["lateral_stiffness"], values["lateral_stiffness"])
                     & np.isclose(optima["yaw_stiffness"], values["yaw_stiffness"])].iloc[0]
    assert bool(row["nonlinear_stable"]) and bool(row["stable"])
    assert not _settles_on_a_cycle(values)  # the direct simulation agrees: no hunting at the required speed
    existing = {"lateral_stiffness": 1.0e6, "yaw_stiffness": 2.0e6}
    assert _settles_on_a_cycle(existing)  # while the existing design hunts there, linear stable to 74 m/s
    summary = (out / "summary.md").read_text()
    assert "nonlinear_stable yes" in summary
    # the summary shows both speeds for the existing design and the recommended one
    assert "| linear_critical_speed_m_s | 74.322 |" in summary
    assert "| lowest_hunting_speed_m_s | 45 | no hunting cycle at any ramp speed |" in summary
    assert "| nonlinear_hunting check passed (nonlinear_stable) | NO | yes |" in summary
    assert "| hunting check passed (stable, certified) | yes | yes |" in summary


@pytest.mark.slow
def test_the_study_kind_writes_the_ramp_indicators_and_verdict(tmp_path):
    """The wheelset through ``railopt run`` (ramp only): the verdict at the required speed follows the ramp's
    bracket, the indicators are those of the steady speeds, and the flange use is peak |y| over the table's flange
    onset (6.3 mm on S1002/60E1 1:40, the benchmark's 6.0–6.5 mm)."""
    study = tmp_path / "nh.toml"
    study.write_text(f"""
[study]
name = "nh"
kind = "nonlinear_hunting"

[[models]]
label = "wheelset"
model = "vehicle_lateral"

[models.options]
vehicle = "{WHEELSET}"
max_operating_speed_m_s = 40.0

[nonlinear_hunting]
top_speed_m_s = 46.0
step_m_s = 1.0
fine_step_m_s = 0.5
lowest_speed_m_s = 43.0
initial_amplitude_mm = 0.6
continuation = false
""")
    assert main(["run", str(study), "--results", str(tmp_path / "out"), "--no-progress"]) == 0
    out = tmp_path / "out" / "nh"
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    ramp = pd.read_csv(out / "ramp.csv")
    steady = ramp[ramp["classification"] == "steady"]
    assert summary["ramp_last_cycle_m_s"] == steady["speed_m_s"].min()
    assert summary["lowest_hunting_speed_m_s"] == summary["ramp_last_cycle_m_s"] > 40.0
    assert bool(summary["passes_required"]) and not bool(summary["fold_confirmed"])
    assert summary["nonlinear_over_linear"] == pytest.approx(summary["lowest_hunting_speed_m_s"]
                                                             / summary["linear_critical_speed_m_s"], rel=1e-12)
    indicators = pd.read_csv(out / "indicators.csv")
    assert list(indicators["speed_m_s"]) == list(steady["speed_m_s"])
    assert np.allclose(indicators["flange_clearance_mm"], 6.3)
    assert np.allclose(indicators["flange_use"], indicators["peak_y_mm"] / 6.3, rtol=1e-12)
    assert np.allclose(indicators["peak_y_mm"], steady["amplitude_mm"], rtol=3e-3)  # a symmetric cycle
    assert (out / "bifurcation_wheelset.png").is_file()
    assert "Verdict: no stable hunting cycle up to 40 m/s." in (out / "summary.md").read_text()


@pytest.mark.parametrize("workers, warmed", [(2, True), (None, True), (0, False)])
def test_a_campaign_with_the_check_warms_the_wheel_rail_kernels_before_its_cluster(monkeypatch, tmp_path, workers,
                                                                                   warmed):
    """The check runs on the workers: the driver compiles (or loads) the wheel/rail kernels before the cluster
    starts, so that cold workers do not each compile them; a serial run does not need it.  Without the check no
    warm-up of these kernels."""
    from railopt.studies.kind import StudyContext
    from railopt.studies.kinds.campaign import run

    events = []

    class Started(Exception):
        pass

    def cluster(context):
        events.append("cluster")
        raise Started

    monkeypatch.setattr("railopt.studies.kernel_warmup.warm_nonlinear_kernels", lambda show: events.append("warm"))
    monkeypatch.setattr(run, "dask_context", cluster)
    context = StudyContext(store_dir=tmp_path, workers=workers)
    with pytest.raises(Started):
        run.compute(CampaignStudyConfig.model_validate(_raw()), context)
    assert events == (["warm", "cluster"] if warmed else ["cluster"])
    events.clear()
    without = _raw(design={**RAW["design"], "checks": ["hunting"]})
    without.pop("nonlinear_hunting")
    with pytest.raises(Started):
        run.compute(CampaignStudyConfig.model_validate(without), context)
    assert events == ["cluster"]
