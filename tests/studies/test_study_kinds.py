"""Study kinds driven by config alone: a new campaign, an FRF study and a speed sweep need only TOML."""

from __future__ import annotations

import ast
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from railopt.models.tmd import den_hartog, nishihara_asami
from railopt.studies.cli import STUDIES_DIR, main
from railopt.studies.config import ConfigError, load_study

ROOT = Path(__file__).resolve().parents[2]

NEW_CAMPAIGN = """
[study]
name = "tmd_direct"
kind = "campaign"
description = "the TMD designed directly in k2 and c2 (log scale), two methods"

[[models]]
label = "mu0.1"
model = "tmd"
options = {{ mass_ratio = 0.1, primary_mass_kg = 1.0, primary_frequency_hz = {f1} }}

[objective]
band_hz = [{lo}, {hi}]

[design]
methods = ["slsqp", "cobyla"]
objectives = ["exact"]
n_starts = 4
seed = 7
checks = ["spectral_abscissa"]

[[design.variables]]
name = "k2"
lower = 0.02
upper = 0.2
scale = "log"

[[design.variables]]
name = "c2"
lower = 0.001
upper = 0.2
scale = "log"

[design.options]
maxeval = 4000
"""


def test_a_new_minimax_study_is_a_toml_file(tmp_path):
    """Designing (k2, c2) directly instead of (γ, ζ) reaches the same H∞ optimum (Nishihara–Asami)."""
    f1 = 1 / (2 * math.pi)  # ω1 = 1 rad/s, m1 = 1 kg: k1 = 1 N/m
    study = tmp_path / "tmd_direct.toml"
    study.write_text(NEW_CAMPAIGN.format(f1=f1, lo=0.5 * f1, hi=1.5 * f1))
    assert main(["validate", str(study)]) == 0
    assert main(["run", str(study), "--results", str(tmp_path / "r"), "--workers", "0", "--no-progress"]) == 0
    table = pd.read_csv(tmp_path / "r" / "tmd_direct" / "comparison.csv")
    na = nishihara_asami(0.1)
    k2, c2 = 0.1 * na.tuning**2, 2 * na.damping_ratio * 0.1 * na.tuning  # m2 (γ ω1)², 2 ζ m2 γ ω1
    for _, row in table.iterrows():
        assert row["true_peak"] == pytest.approx(na.peak, rel=1e-6), row["method"]
        assert row["k2"] == pytest.approx(k2, rel=1e-3) and row["c2"] == pytest.approx(c2, rel=1e-2)
        assert row["all_optima_pass_checks"]


def test_every_bundled_config_validates_and_lists():
    for path in sorted(STUDIES_DIR.glob("*.toml")):
        kind, config, _ = load_study(path)
        assert config.study.name == path.stem, path
    assert main(["list"]) == 0


def test_validate_rejects_what_run_would_reject(tmp_path):
    """A track config listing the amplification figure without its table: run used to fail, now validate."""
    text = (STUDIES_DIR / "track_moving_load.toml").read_text()
    start = text.index("[amplification]")
    end = text.find("\n[", start + 1)
    study = tmp_path / "t.toml"
    study.write_text(text[:start] + (text[end:] if end > 0 else ""))
    with pytest.raises(ConfigError, match="figures.make"):
        load_study(study)


def test_frf_kind_reports_the_published_peaks(tmp_path):
    assert main(["run", str(STUDIES_DIR / "tmd_frf.toml"), "--results", str(tmp_path), "--no-progress"]) == 0
    peaks = pd.read_csv(tmp_path / "tmd_frf" / "peaks.csv").set_index("design")
    assert peaks.loc["nishihara_asami", "peak"] == pytest.approx(nishihara_asami(0.05).peak, rel=1e-10)
    assert peaks.loc["den_hartog", "peak"] == pytest.approx(den_hartog(0.05).peak, rel=1e-10)
    assert peaks["certified"].all()
    frf = pd.read_csv(tmp_path / "tmd_frf" / "frf.csv")
    assert frf.groupby("design")["amplitude"].max().loc["den_hartog"] <= den_hartog(0.05).peak * (1 + 1e-12)


def routh_hurwitz_critical_speed(m, inertia, k_y, k_psi, f11, f22, lam, e0, r0):
    """Closed form of the single restrained wheelset (no spin, no gravity stiffness), derived independently:
    m v'' + 2 f22 (v'/S − ψ) + k_y v = 0,  I ψ'' + 2 f11 e0 (e0 ψ'/S + λ v/r0) + k_psi ψ = 0.
    Characteristic polynomial a4 s⁴ + a3 s³ + a2 s² + a1 s + a0; the critical speed is where the Hurwitz
    determinant Δ3 = a3 a2 a1 − a1² a4 − a3² a0 vanishes (solved for S by bisection)."""

    def delta3(S):
        cy, cp = 2 * f22 / S, 2 * f11 * e0**2 / S
        a4, a3 = m * inertia, m * cp + inertia * cy
        a2 = m * k_psi + inertia * k_y + cy * cp
        a1 = cy * k_psi + cp * k_y
        a0 = k_y * k_psi + 2 * f22 * 2 * f11 * e0 * lam / r0
        return a3 * a2 * a1 - a1**2 * a4 - a3**2 * a0

    lo, hi = 1.0, 1000.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if delta3(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_speed_sweep_kind_finds_the_routh_hurwitz_critical_speed(tmp_path):
    assert main(["run", str(STUDIES_DIR / "wheelset_stability.toml"), "--results", str(tmp_path),
                 "--no-progress"]) == 0
    out = tmp_path / "wheelset_stability"
    crit = pd.read_csv(out / "critical_speeds.csv").set_index("model")
    sens = pd.read_csv(out / "sensitivity.csv")
    # bundled single-wheelset data (models/vehicle/data/single-wheelset.toml)
    base = dict(m=1500.0, inertia=700.0, k_y=1.0e6, k_psi=2.0e6, f11=10.0e6, f22=9.0e6, lam=0.1, e0=0.75, r0=0.45)
    for label, changes in (("wheelset", {}), ("soft_yaw", {"k_psi": 5.0e5})):
        expected = routh_hurwitz_critical_speed(**(base | changes))
        assert crit.loc[label, "critical_speed_m_s"] == pytest.approx(expected, abs=0.01 + 1e-9)
        assert crit.loc[label, "eigen_solves"] <= 25
    for factor in (0.5, 2.0):
        row = sens[(sens.parameter == "conicity") & (sens.factor == factor) & (sens.model == "wheelset")].iloc[0]
        expected = routh_hurwitz_critical_speed(**(base | {"lam": 0.1 * factor}))
        assert row["critical_speed_m_s"] == pytest.approx(expected, abs=0.01 + 1e-9)
    locus = pd.read_csv(out / "root_locus.csv")
    damping = pd.read_csv(out / "damping.csv")
    # the least damping ratio changes sign where the critical speed lies
    d = damping[damping.model == "wheelset"]
    below, above = d[d.speed_m_s < crit.loc["wheelset", "critical_speed_m_s"]], d[
        d.speed_m_s > crit.loc["wheelset", "critical_speed_m_s"]]
    assert (below["spectral_abscissa"] < 0).all() and (above["spectral_abscissa"] > 0).all()
    assert np.isfinite(locus["real"]).all()


def test_speed_sweep_needs_a_model_with_speed(tmp_path):
    text = (STUDIES_DIR / "wheelset_stability.toml").read_text().replace(
        'model = "vehicle_lateral"\noptions = { vehicle = "single-wheelset", track = "rigid" }',
        'model = "tmd"\noptions = { mass_ratio = 0.1 }', 1)
    study = tmp_path / "s.toml"
    study.write_text(text)
    with pytest.raises(ConfigError, match=r"models\[0\].model: 'tmd' has no forward speed"):
        load_study(study)


def test_no_model_module_imports_matplotlib_or_design():
    for path in (ROOT / "models").rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for name in names:
                assert not name.startswith("matplotlib"), path
                assert not name.startswith("railopt.design"), path


@pytest.mark.slow
def test_locomotive_stability_study_matches_the_model_layer(tmp_path):
    """The bundled stability study: its critical speeds equal direct calls, sensitivities move the way the
    physics says, and flexible track tends to rigid track as the track modulus grows."""
    from railopt.models.stability import critical_speed
    from railopt.models.vehicle import load_vehicle

    assert main(["run", str(STUDIES_DIR / "locomotive_stability.toml"), "--results", str(tmp_path),
                 "--no-progress"]) == 0
    out = tmp_path / "locomotive_stability"
    crit = pd.read_csv(out / "critical_speeds.csv").set_index("model")
    for label, vehicle, track in (("sd40-2_rigid", "sd40-2", "rigid"), ("coach_flexible", "manchester-coach",
                                                                          "flexible")):
        direct = critical_speed(load_vehicle(vehicle), track, (1.0, 150.0), tol=1e-6, grid=16)
        assert crit.loc[label, "critical_speed_m_s"] == pytest.approx(direct.speed, abs=0.01)
    sens = pd.read_csv(out / "sensitivity.csv")
    loco = sens[(sens.model == "sd40-2_flexible") & (sens.parameter == "track_modulus")].sort_values("factor")
    gaps = np.abs(loco["critical_speed_m_s"].to_numpy() - crit.loc["sd40-2_rigid", "critical_speed_m_s"])
    assert np.all(np.diff(gaps) < 0) and gaps[-1] < 0.1  # → rigid as the modulus grows
    rigid = sens[(sens.model == "sd40-2_rigid") & (sens.parameter == "conicity")].sort_values("factor")
    assert np.all(np.diff(rigid["critical_speed_m_s"]) < 0)  # more conicity, lower critical speed
    effect = pd.read_csv(out / "track_effect.csv").set_index("flexible")
    assert effect.loc["sd40-2_flexible", "change_m_s"] == pytest.approx(
        crit.loc["sd40-2_flexible", "critical_speed_m_s"] - crit.loc["sd40-2_rigid", "critical_speed_m_s"], abs=1e-12)


@pytest.mark.parametrize("study", ["tmd_frf", "wheelset_stability", "locomotive_vertical_response", "tmd_hinf"])
def test_each_model_is_built_once_per_run(study, tmp_path, monkeypatch):
    """Validation builds each ``[[models]]`` entry and ``compute`` reuses it: in a whole run (frf, speed sweep,
    forced response and campaign kinds) no entry builds a model twice with the same options, and every entry
    builds (a speed sweep's parameter variants are models of their own)."""
    import json

    import railopt.studies.catalog.vehicle as catalog_vehicle
    import railopt.studies.kinds.forced_response as forced_kind
    from railopt.studies.catalog import MODELS, ModelRef, discover_models

    builds: list[tuple[str, str]] = []
    building: list[str] = []  # the entry whose model is being built
    real_built = ModelRef.built

    def built(self, what, make):
        building.append(self.label)
        try:
            return real_built(self, what, make)
        finally:
            building.pop()

    def note(name, options):
        builds.append((building[0], json.dumps([name, options.model_dump(mode="json")], sort_keys=True)))

    monkeypatch.setattr(ModelRef, "built", built)
    for name, entry in list(discover_models().items()):
        def counted(options, _build=entry.build, _name=name):
            note(_name, options)
            return _build(options)
        monkeypatch.setitem(MODELS, name, replace(entry, build=counted))
    real_forced = catalog_vehicle.vehicle_forced_model
    monkeypatch.setattr(forced_kind, "vehicle_forced_model", lambda o: note("vehicle_forced", o) or real_forced(o))
    path = STUDIES_DIR / f"{study}.toml"
    assert main(["run", str(path), "--results", str(tmp_path), "--workers", "0"]) == 0
    assert len(builds) == len(set(builds))
    assert {label for label, _ in builds} == {m.label for m in load_study(path)[1].models}
    assert (tmp_path / study / "summary.md").is_file()
