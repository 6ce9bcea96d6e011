"""Root locus and critical speed: the bracketing + Brent search against a dense root-locus scan."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from railopt.models.stability import CriticalSpeed, critical_speed, root_locus, spectral_abscissa
from railopt.models.vehicle import load_vehicle


def first_unstable_speed(vehicle, track: str, lo: float, hi: float, step: float) -> float:
    """Lowest speed of a dense grid with a root in Re s > 0 (the independent reference)."""
    speeds = np.arange(lo, hi + step / 2, step)
    rl = root_locus(vehicle, speeds, track=track).to_pandas()
    abscissa = rl.groupby("speed")["real"].max()
    unstable = abscissa[abscissa > 0.0]
    return float(unstable.index[0]) if len(unstable) else math.inf


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_critical_speed_matches_dense_scan(sd40, track: str) -> None:
    tol = 0.01
    cs = critical_speed(sd40, track, (1.0, 60.0), tol=tol)
    assert isinstance(cs, CriticalSpeed) and not cs.unstable_at_lower_end
    # coarse scan below, fine scan (step 0.002 m/s) around the result
    assert first_unstable_speed(sd40, track, 1.0, cs.speed - 0.5, 0.05) == math.inf
    scan = first_unstable_speed(sd40, track, cs.speed - 0.5, cs.speed + 0.5, 0.002)
    assert abs(scan - cs.speed) <= tol + 0.002
    assert cs.bracket[0] <= scan <= cs.bracket[1] + 0.002
    assert cs.eigen_solves <= 25  # goal: 0.01 m/s in at most 25 eigen-solves
    assert 0.1 < cs.frequency < 5.0


def test_flexible_and_rigid_critical_speeds_differ_little(sd40) -> None:
    rigid = critical_speed(sd40, "rigid", (1.0, 60.0))
    flexible = critical_speed(sd40, "flexible", (1.0, 60.0))
    assert abs(flexible.speed - rigid.speed) / rigid.speed < 0.05


def test_stable_over_range_and_unstable_at_lower_end() -> None:
    v = load_vehicle("single-wheelset")  # critical speed about 74.3 m/s
    stable = critical_speed(v, "rigid", (5.0, 50.0))
    assert stable.speed == math.inf and stable.stable_over_range and math.isnan(stable.frequency)
    unstable = critical_speed(v, "rigid", (80.0, 120.0))
    assert unstable.unstable_at_lower_end and unstable.speed == 80.0
    assert spectral_abscissa(v.lateral(speed=80.0)) > 0.0


def test_root_locus_table(sd40) -> None:
    rl = root_locus(sd40, [10.0, 20.0], track="rigid").to_pandas()
    assert list(rl.columns) == ["speed", "mode", "real", "imag", "damping_ratio", "frequency_hz", "name"]
    assert isinstance(rl, pd.DataFrame)
    one = rl[rl.speed == 10.0]
    s = sd40.lateral("rigid", speed=10.0).eigenvalues()
    assert len(one) == np.sum(s.imag >= 0)
    assert np.allclose(np.sort(one.real), np.sort(s[s.imag >= 0].real))
    assert np.allclose(one.frequency_hz, one.imag / (2 * np.pi))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"speed_range": (0.0, 10.0)}, "speed"),
        ({"speed_range": (-5.0, 10.0)}, "speed"),
        ({"speed_range": (20.0, 10.0)}, "speed_range"),
        ({"speed_range": (1.0, 10.0), "tol": 0.0}, "tol"),
        ({"speed_range": (1.0, float("nan"))}, "speed"),
    ],
)
def test_bad_search_inputs(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        critical_speed(load_vehicle("single-wheelset"), "rigid", **kwargs)


def test_non_positive_speed_in_models() -> None:
    v = load_vehicle("single-wheelset")
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="speed"):
            v.lateral(speed=bad)
        with pytest.raises(ValueError, match="speed"):
            root_locus(v, [bad], track="rigid")
    with pytest.raises(ValueError, match="speed"):
        v.lateral().C  # noqa: B018 - no speed set


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_neutral_rigid_body_roots_are_not_instability(sd40, track: str) -> None:
    """The longitudinal–vertical block has s = 0 roots (free fore-aft motion, wheelset spin perturbations);
    the abscissa ignores them instead of reading rounding noise as instability."""
    for speed in (5.0, 20.0, 60.0):
        m = sd40.vertical(track, speed=speed)
        s = m.eigenvalues()
        assert np.sum(np.abs(s) < 1e-6) >= 6
        assert spectral_abscissa(m) < 0.0


def test_hidden_unstable_window_between_samples_is_found():
    """a(S) = −0.1 + 0.3 exp(−((S − 50)/4)²): every sample of an 8-point grid on [1, 100] is negative, but
    the window raises a sampled local maximum; its first crossing is S = 50 − 4 √ln 3 exactly."""
    from railopt.models.stability import first_crossing

    def a(S):
        return -0.1 + 0.3 * np.exp(-(((S - 50.0) / 4.0) ** 2))

    grid = np.linspace(1.0, 100.0, 8)
    assert np.all(a(grid) < 0)
    speed, bracket = first_crossing(a, 1.0, 100.0, 1e-6, 8)
    assert speed == pytest.approx(50.0 - 4.0 * np.sqrt(np.log(3.0)), abs=1e-6)
    assert bracket[0] <= speed <= bracket[1]


def test_monotone_stable_abscissa_reports_no_crossing():
    from railopt.models.stability import first_crossing

    speed, bracket = first_crossing(lambda S: -1.0 / S, 1.0, 100.0, 0.01, 8)
    assert speed == float("inf") and bracket == (100.0, float("inf"))
