"""Issue 27 item 5: a start where the objective does not exist is never lost silently as an ``error``.

The RMS of an unstable vehicle (no stationary random response) and the band maximum of an undamped system are
+inf, not exceptions: the solver's line search backs off from them as from a barrier, and a start placed there ends
with U = inf, counted in the summary and in ``outcomes.csv`` as ``objective does not exist`` with its reason (the
growing root, the undamped mode's frequency), each start's outcome in ``starts.csv``.  The unstable region is built
deliberately (the SD40-2's lateral shock absorbers nearly removed at 30 m/s) and confirmed by a fresh vehicle's
eigenvalues; the undamped one is a TMD with zero absorber damping on its undamped primary, whose natural frequencies
are the closed form of the two-mass system.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from railopt.design import solve
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.irregularity import Irregularity
from railopt.studies.adapter import objective_value, rms_target
from railopt.studies.cli import main
from railopt.studies.kinds.campaign import campaign_problem
from railopt.studies.kinds.campaign.config import CampaignStudyConfig

SPEED = 30.0
NAMES = ["rotational_shock_absorber_damping", "lateral_shock_absorber_damping"]  # C15, C13 of the SD40-2
HUNTING = {NAMES[0]: 1.0e5, NAMES[1]: 2.0e3}  # lateral damping nearly removed: the body hunts at 30 m/s
RAW = {
    "study": {"name": "outcomes", "kind": "campaign"},
    "models": [{"label": "sd40-2", "model": "vehicle_forced",
                "options": {"vehicle": "sd40-2", "view": "lateral", "track": "rigid", "speed_m_s": SPEED,
                            "input": {"kind": "alignment", "amplitude_m": 0.00635}, "outputs": ["cab.lateral"],
                            "quantity": "acceleration"}}],
    "objective": {"output": "cab.lateral", "band_hz": [0.5, 15.0],
                  "spectrum": {"standard": "erri_b176", "level": "low", "component": "alignment"}},
    "design": {"objectives": ["rms"], "n_starts": 4, "seed": 3, "start_from": ["existing"], "points": [HUNTING],
               "variables": [{"name": NAMES[0], "lower": 1e4, "upper": 1e7, "scale": "log"},
                             {"name": NAMES[1], "lower": 1e3, "upper": 1e7, "scale": "log"}]},
}
ROOT = re.compile(r"root s = (?P<re>[-0-9.e+]+)(?P<im>[-+][0-9.e+]+)i 1/s")


def _growth(values: dict[str, float]) -> float:
    """The largest Re s (1/s) of a fresh SD40-2's lateral model at 30 m/s with ``values`` (not the study's code)."""
    view = load_vehicle("sd40-2").with_parameters(values).lateral(track="rigid", speed=SPEED)
    system = view.family(input=Irregularity("alignment", 1.0), outputs=["cab.lateral"], quantity="acceleration").at()
    return float(np.max(system.eigenvalues().real))


def _toml(raw: dict) -> str:
    m, o, d = raw["models"][0], raw["objective"], raw["design"]
    opts = m["options"]
    lines = ['[study]', f'name = "{raw["study"]["name"]}"', 'kind = "campaign"', "", "[[models]]",
             f'label = "{m["label"]}"', f'model = "{m["model"]}"']
    if m["model"] == "tmd":
        lines.append("options = { mass_ratio = 0.05, primary_mass_kg = 1000.0, primary_frequency_hz = 2.0 }")
    else:
        lines.append(f'options = {{ vehicle = "sd40-2", view = "lateral", track = "rigid", speed_m_s = {SPEED}, '
                     f'input = {{ kind = "alignment", amplitude_m = {opts["input"]["amplitude_m"]} }}, '
                     'outputs = ["cab.lateral"], quantity = "acceleration" }')
    lines += ["", "[objective]", f'output = "{o["output"]}"', f"band_hz = {o['band_hz']}"]
    if "spectrum" in o:
        lines += ["[objective.spectrum]", 'standard = "erri_b176"', 'level = "low"', 'component = "alignment"']
    lines += ["", "[design]", f"objectives = {d['objectives']}".replace("'", '"'), f"n_starts = {d['n_starts']}",
              f"seed = {d['seed']}"]
    if d.get("start_from"):
        lines.append('start_from = ["existing"]')
    lines.append("points = [" + ", ".join("{ " + ", ".join(f"{k} = {v!r}" for k, v in p.items()) + " }"
                                          for p in d["points"]) + "]")
    for v in d["variables"]:
        lines += ["", "[[design.variables]]", f'name = "{v["name"]}"', f"lower = {v['lower']!r}",
                  f"upper = {v['upper']!r}"] + ([f'scale = "{v["scale"]}"'] if "scale" in v else [])
    return "\n".join(lines) + "\n"


def _run(tmp_path: Path, raw: dict) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(_toml(raw))
    assert main(["run", str(path), "--workers", "0", "--results", str(tmp_path / "out"), "--no-progress"]) == 0
    return tmp_path / "out" / raw["study"]["name"]


def _counted(out: Path, starts: pd.DataFrame) -> pd.DataFrame:
    """outcomes.csv, checked against starts.csv and the summary's sentence: every start counted once."""
    counts = pd.read_csv(out / "outcomes.csv")
    assert counts["starts"].sum() == len(starts)
    for (keys, group) in starts.groupby(["objective", "outcome"]):
        row = counts[(counts["objective"] == keys[0]) & (counts["outcome"] == keys[1])]
        assert int(row["starts"].iloc[0]) == len(group), keys
    optimum = int(counts.loc[counts["outcome"] == "optimum", "starts"].sum())
    summary = (out / "summary.md").read_text()
    assert (f"{optimum} of {len(starts)} converged to a feasible design; {len(starts) - optimum} did not."
            in summary)
    return counts


# ---------------------------------------------------------------------------------------------- the objective itself
def test_the_rms_of_a_hunting_design_is_inf_with_its_growing_root_never_an_exception():
    assert _growth(HUNTING) > 0 and _growth({}) < 0  # built to hunt; the existing design does not
    cfg = CampaignStudyConfig.model_validate(RAW)
    setup = cfg.setups()["sd40-2"]
    problem = campaign_problem(cfg, setup, "rms", "unconstrained")
    x = np.array([HUNTING[n] for n in NAMES])
    ev = problem.evaluate(x, gradient=True)  # raised "a stationary random response does not exist" before
    assert ev.f.tolist() == [math.inf] and np.all(ev.df == 0.0)
    value, reason = objective_value(setup.family.at(setup.parameters(NAMES, x)[0]), rms_target(cfg.objective, setup))
    assert value == math.inf and reason.startswith("unstable") and "stationary random response does not exist" in reason
    assert float(ROOT.search(reason)["re"]) == pytest.approx(_growth(HUNTING), rel=1e-3)  # printed to 4 digits
    result = solve(problem, x, method="slsqp")
    assert result.status != "error" and result.value == math.inf and result.evaluations > 0
    # a stable design keeps its finite RMS (the same function as before)
    stable = np.array([4.0e5, 1.5e5])
    assert math.isfinite(problem.value(stable)) and problem.value(stable) > 0


# ---------------------------------------------------------------------------------------------- campaigns
@pytest.mark.slow
def test_a_start_placed_where_the_vehicle_hunts_is_counted_with_its_reason(tmp_path):
    out = _run(tmp_path, RAW)
    starts = pd.read_csv(out / "starts.csv")
    assert len(starts) == RAW["design"]["n_starts"] + 2  # the Sobol starts, the existing design, the hunting point
    assert not (starts["status"] == "error").any()
    x0 = [{n: float(r[f"x0_{n}"]) for n in NAMES} for _, r in starts.iterrows()]
    hunts = np.array([_growth(v) > 0 for v in x0])
    placed = starts[np.isclose(starts[f"x0_{NAMES[1]}"], HUNTING[NAMES[1]], rtol=1e-12)].iloc[0]
    assert placed["outcome"] == "objective does not exist"
    assert placed["reason"].startswith("unstable: root s = ") and placed["reason"].endswith("(at its start)")
    # every start that begins hunting is counted so, with its reason; every other converges
    np.testing.assert_array_equal(starts["outcome"] == "objective does not exist", hunts)
    assert (starts.loc[~hunts, "outcome"] == "optimum").all()
    counts = _counted(out, starts)
    lost = counts[counts["outcome"] == "objective does not exist"].iloc[0]
    assert lost["starts"] == hunts.sum() and "a stationary random response does not exist" in lost["reasons"]
    assert pd.read_csv(out / "recommended.csv")["measure"].iloc[0] == "rms"


@pytest.mark.slow
def test_a_start_at_an_undamped_design_is_counted_with_its_unbounded_peak(tmp_path):
    """A TMD with zero absorber damping on its undamped primary: the band maximum (thesis and exact) is unbounded
    at its start; the reason names the lower natural frequency of the undamped two-mass system (closed form)."""
    raw = {"study": {"name": "undamped", "kind": "campaign"},
           "models": [{"label": "tmd", "model": "tmd", "options": {}}],
           "objective": {"output": "amplification", "band_hz": [1.0, 3.0]},
           "design": {"objectives": ["thesis", "exact"], "n_starts": 3, "seed": 2,
                      "points": [{"tuning": 1.0, "damping_ratio": 0.0}],
                      "variables": [{"name": "tuning", "lower": 0.5, "upper": 1.5},
                                    {"name": "damping_ratio", "lower": 0.0, "upper": 0.5}]}}
    out = _run(tmp_path, raw)
    starts = pd.read_csv(out / "starts.csv")
    assert not (starts["status"] == "error").any()
    undamped = starts[starts["x0_damping_ratio"] == 0.0]
    assert len(undamped) == 2 and (undamped["outcome"] == "objective does not exist").all()  # both objectives
    mu, w1 = 0.05, 2 * math.pi * 2.0  # ω⁴ − ω²(ω1² + (1+μ)ω2²) + ω1²ω2² = 0 with ω2 = ω1 (tuning 1)
    b = w1**2 * (2 + mu)
    lower_hz = math.sqrt((b - math.sqrt(b**2 - 4 * w1**4)) / 2) / (2 * math.pi)
    for reason in undamped["reason"]:
        hz = float(re.search(r"an undamped mode at ([0-9.]+) Hz inside the band", reason)[1])
        assert hz == pytest.approx(lower_hz, rel=1e-3) and reason.endswith("unbounded (at its start)")
    assert (starts.loc[starts["x0_damping_ratio"] > 0, "outcome"] == "optimum").all()
    _counted(out, starts)
