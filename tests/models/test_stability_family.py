"""Stability analyses on models that are not vehicle files: a hand-built class with ``at(speed=S)`` and a
:class:`ParametricSystem` with a speed term, against the Routh–Hurwitz closed form (conftest)."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import LinearSystem, ParameterPart, ParametricSystem
from railopt.models.stability import critical_speed, root_locus, spectral_abscissa

from conftest import routh_hurwitz

CASES = [
    dict(m=1500.0, iz=700.0, ky=1e6, kpsi=2e6, f11=10e6, f22=9e6, lam=0.1, e0=0.75, r0=0.45),
    dict(m=1200.0, iz=500.0, ky=2e6, kpsi=5e6, f11=10e6, f22=9e6, lam=0.2, e0=0.75, r0=0.45),
    dict(m=2000.0, iz=1100.0, ky=0.4e6, kpsi=1e6, f11=6e6, f22=7e6, lam=0.1, e0=0.7465, r0=0.5),
    dict(m=1500.0, iz=700.0, ky=1e6, kpsi=8e6, f11=10e6, f22=12e6, lam=0.05, e0=0.75, r0=0.45),
]


class RestrainedWheelset:
    """A user's own model: lateral v and yaw ψ of a wheelset on springs, creep damping 1/S (no vehicle file)."""

    def __init__(self, m, iz, ky, kpsi, f11, f22, lam, e0, r0) -> None:
        self.M = np.diag([m, iz])
        self.C_speed = np.diag([2 * f22, 2 * f11 * e0**2])
        self.K = np.array([[ky, -2 * f22], [2 * f11 * e0 * lam / r0, kpsi]])

    def at(self, speed: float) -> LinearSystem:
        return LinearSystem(self.M, self.C_speed / speed, self.K)


def family(m, iz, ky, kpsi, f11, f22, lam, e0, r0) -> ParametricSystem:
    """The same wheelset as a family in (k_y, k_ψ) with the creep damping as its speed term."""
    return ParametricSystem(
        np.diag([m, iz]), np.zeros((2, 2)), np.array([[0.0, -2 * f22], [2 * f11 * e0 * lam / r0, 0.0]]),
        parts={"ky": ParameterPart(K=np.diag([1.0, 0.0])), "kpsi": ParameterPart(K=np.diag([0.0, 1.0]))},
        C_speed=np.diag([2 * f22, 2 * f11 * e0**2]), values=[ky, kpsi], names=("v", "psi"))


@pytest.mark.parametrize("case", CASES)
def test_critical_speed_of_a_hand_built_model_equals_routh_hurwitz(case: dict) -> None:
    exact_speed, exact_freq = routh_hurwitz(**case)
    for model in (RestrainedWheelset(**case), family(**case)):
        cs = critical_speed(model, speed_range=(1.0, 3.0 * exact_speed), tol=1e-7)
        assert abs(cs.speed - exact_speed) / exact_speed < 1e-6
        assert abs(cs.frequency - exact_freq) / exact_freq < 1e-6
        assert not cs.unstable_at_lower_end
    assert cs.coordinate in ("v", "psi")
    table = cs.to_pandas()
    assert table["speed"].iloc[0] == cs.speed and bool(table["stable_over_range"].iloc[0]) is False


def test_family_members_and_the_abscissa_sign_around_the_critical_speed() -> None:
    case = CASES[0]
    exact, _ = routh_hurwitz(**case)
    fam = family(**case)
    assert spectral_abscissa(fam, speed=0.99 * exact) < 0.0 < spectral_abscissa(fam, speed=1.01 * exact)
    locus = root_locus(fam, [0.5 * exact, exact, 2 * exact])
    assert locus.roots.shape == (3, 4)
    df = locus.to_pandas()
    assert list(df.columns) == ["speed", "mode", "real", "imag", "damping_ratio", "frequency_hz", "name"]
    # at the critical speed one root pair sits on the imaginary axis
    at_crit = locus.roots[1]
    assert np.min(np.abs(at_crit.real)) < 1e-6 * np.max(np.abs(at_crit))


def test_models_without_a_speed_are_refused_naming_the_argument() -> None:
    with pytest.raises(ValueError, match="^model: a LinearSystem has one speed"):
        critical_speed(RestrainedWheelset(**CASES[0]).at(10.0))
    with pytest.raises(ValueError, match="^model: needs a method at"):
        critical_speed(object())
    with pytest.raises(ValueError, match=r"^speed_range: must be a pair"):
        critical_speed(RestrainedWheelset(**CASES[0]), speed_range=(1, 2, 3))
    with pytest.raises(ValueError, match=r"^grid: must be an integer"):
        critical_speed(RestrainedWheelset(**CASES[0]), grid=2.5)
