"""The TMD campaign (a generic `campaign` config) against the exact H∞ optimum of Nishihara & Asami (2002)."""

from __future__ import annotations

import pytest

from railopt.design import METHODS, solve
from railopt.models.tmd import den_hartog, nishihara_asami
from railopt.studies.cli import STUDIES_DIR
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign import campaign_problem, design_peak

_, CONFIG, _ = load_study(STUDIES_DIR / "tmd_hinf.toml")
SETUPS = CONFIG.setups()
LABEL = {0.05: "mu0.05", 0.1: "mu0.1"}


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("mu", [0.05, 0.1])
def test_exact_option_reproduces_nishihara_asami(mu, method):
    na, dh = nishihara_asami(mu), den_hartog(mu)
    problem = campaign_problem(CONFIG, SETUPS[LABEL[mu]], "exact")
    r = solve(problem, [0.9, 0.3], method=method)
    assert r.value == pytest.approx(na.peak, rel=1e-4)
    assert r.x[0] == pytest.approx(na.tuning, abs=1e-3)
    assert r.x[1] == pytest.approx(na.damping_ratio, abs=1e-3)
    assert r.value <= dh.peak  # at least as good as Den Hartog's design


@pytest.mark.parametrize("mu", [0.05, 0.1])
def test_thesis_approximation_error_is_positive_and_bounded(mu):
    """The thesis objective (peaks at ω_d) underestimates the true peak, so its optimum is worse."""
    na = nishihara_asami(mu)
    setup = SETUPS[LABEL[mu]]
    problem = campaign_problem(CONFIG, setup, "thesis")
    r = solve(problem, [den_hartog(mu).tuning, den_hartog(mu).damping_ratio], method="slsqp")
    peak = design_peak(CONFIG, setup, {"tuning": r.x[0], "damping_ratio": r.x[1]})
    assert r.value < peak  # the approximation reads low
    assert 0 < (peak - na.peak) / na.peak < 0.02  # its optimum is a worse design than the exact one


def test_named_designs_are_the_closed_forms():
    for mu, label in LABEL.items():
        named = SETUPS[label].named_designs
        assert named["nishihara_asami"] == {"tuning": nishihara_asami(mu).tuning,
                                            "damping_ratio": nishihara_asami(mu).damping_ratio}
        assert design_peak(CONFIG, SETUPS[label], named["nishihara_asami"]) == pytest.approx(
            nishihara_asami(mu).peak, rel=1e-10)
