"""Running-stability indicators (models/vehicle/running_stability.py) against closed forms and hand arithmetic.

Independent references used here:

* the mean square of A sin(k s + φ) over [a, b]: A²/2 − A² (sin 2(kb + φ) − sin 2(ka + φ)) / (4 k (b − a));
* the exact magnitude of a digital Butterworth band-pass designed by the bilinear transform with pre-warped
  edges (what ``scipy.signal.butter(..., fs=)`` builds): with Ω(f) = 2 fs tan(π f / fs), Ω0² = Ω1 Ω2,
  B = Ω2 − Ω1 and x = (Ω² − Ω0²)/(Ω B), |H(f)| = 1/√(1 + x^(2N)) — a sinusoid through a causal linear filter
  leaves, after the transient, a sinusoid of amplitude |H(f)| A;
* Prud'homme's limit α (10 + 2Q0/3) kN evaluated by hand;
* max |y| / clearance and max |Y/Q| by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models.vehicle.running_stability import (
    ALPHA_FREIGHT,
    ALPHA_PASSENGER,
    estimate_frequency,
    flange_clearance_use,
    max_derailment_quotient,
    running_stability,
    sliding_rms,
    sum_y_limit,
)

G = 9.80665  # standard gravity (m/s²), to turn tonnes of axle load into N
FS = 200.0  # sampling frequency of the synthetic records (Hz)


def butterworth_band_pass_gain(f: float, lo: float, hi: float, order: int, fs: float) -> float:
    """|H(f)| of the bilinear-transform Butterworth band-pass with pre-warped edges (closed form)."""
    w = 2.0 * fs * math.tan(math.pi * f / fs)
    w1 = 2.0 * fs * math.tan(math.pi * lo / fs)
    w2 = 2.0 * fs * math.tan(math.pi * hi / fs)
    x = (w * w - w1 * w2) / (w * (w2 - w1))
    return 1.0 / math.sqrt(1.0 + x ** (2 * order))


def sine_mean_square(amplitude: float, k: float, phase: float, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mean of (A sin(k s + φ))² over [a, b] (closed form)."""
    swing = np.sin(2 * (k * b + phase)) - np.sin(2 * (k * a + phase))
    return amplitude**2 / 2 - amplitude**2 * swing / (4 * k * (b - a))


# --- Prud'homme's limit -------------------------------------------------------------------------------------------

def test_prudhomme_limit_by_hand_in_the_standards_kn_form() -> None:
    # 2Q0 = 160 kN: 10 + 160/3 = 63.3333 kN; 2Q0 = 225 kN: 10 + 75 = 85 kN, freight 0.85 × 85 = 72.25 kN
    assert sum_y_limit(160e3) == pytest.approx(63333.3333, rel=1e-9)
    assert sum_y_limit(225e3, ALPHA_PASSENGER) == pytest.approx(85000.0, rel=1e-12)
    assert sum_y_limit(225e3, ALPHA_FREIGHT) == pytest.approx(72250.0, rel=1e-12)


def test_prudhomme_limit_for_16_t_and_22_5_t_axles() -> None:
    # 16 t: P = 16000 × 9.80665 = 156906.4 N, P/3 = 52302.1333 N, + 10000 N = 62302.1333 N
    assert sum_y_limit(16000 * G) == pytest.approx(62302.1333, rel=1e-9)
    # 22.5 t: P = 220649.625 N, P/3 = 73549.875 N, + 10000 N = 83549.875 N; freight: 0.85 × = 71017.39375 N
    assert sum_y_limit(22500 * G) == pytest.approx(83549.875, rel=1e-12)
    assert sum_y_limit(22500 * G, alpha=0.85) == pytest.approx(71017.39375, rel=1e-12)


@pytest.mark.parametrize(("kwargs", "name"), [({"axle_load_n": -1.0}, "axle_load_n"), ({"axle_load_n": np.nan},
                         "axle_load_n"), ({"axle_load_n": 1e5, "alpha": 0.0}, "alpha"),
                         ({"axle_load_n": "1e5"}, "axle_load_n")])
def test_prudhomme_limit_refuses_bad_input_by_name(kwargs, name) -> None:
    with pytest.raises(ValueError, match=f"^{name}: "):
        sum_y_limit(**kwargs)


# --- sliding r.m.s. ------------------------------------------------------------------------------------------------

def test_sliding_rms_of_a_constant_is_the_constant() -> None:
    s = np.linspace(0.0, 300.0, 3001)
    out = sliding_rms(s, np.full(s.size, -7.5e3), 100.0)
    assert out.rms == pytest.approx(np.full(out.rms.size, 7.5e3), rel=1e-12)  # round-off of the running sums
    # windows start every 10 m while they end within the 300 m record: 0, 10, …, 200
    assert out.start_m == pytest.approx(np.arange(0.0, 201.0, 10.0), abs=1e-9)


def test_sliding_rms_of_a_sinusoid_matches_the_closed_form_window_by_window() -> None:
    amplitude, wavelength, phase = 3.0, 13.7, 0.4  # windows of 100 m are not whole wavelengths
    k = 2 * math.pi / wavelength
    s = np.arange(0.0, 400.0 + 1e-9, 0.02)
    out = sliding_rms(s, amplitude * np.sin(k * s + phase), 100.0, step_m=10.0)
    exact = np.sqrt(sine_mean_square(amplitude, k, phase, out.start_m, out.start_m + 100.0))
    assert out.rms == pytest.approx(exact, rel=1e-6)
    # over whole wavelengths the mean square is A²/2: window = 8 wavelengths of 12.5 m
    out8 = sliding_rms(s, amplitude * np.sin(2 * math.pi / 12.5 * s), 100.0)
    assert out8.rms == pytest.approx(np.full(out8.rms.size, amplitude / math.sqrt(2)), rel=1e-5)


def test_sliding_rms_handles_non_uniform_sampling() -> None:
    rng = np.random.default_rng(7)
    amplitude, wavelength, phase = 2.0, 11.3, 1.1
    k = 2 * math.pi / wavelength
    s = np.sort(np.concatenate(([0.0, 300.0], rng.uniform(0.0, 300.0, 20000))))  # mean spacing 0.015 m, random
    out = sliding_rms(s, amplitude * np.sin(k * s + phase), 100.0, step_m=7.0)
    exact = np.sqrt(sine_mean_square(amplitude, k, phase, out.start_m, out.start_m + 100.0))
    assert out.rms == pytest.approx(exact, rel=5e-5)
    assert out.start_m[-1] == pytest.approx(196.0)  # 0, 7, …, 196 (203 + 100 > 300)


@pytest.mark.parametrize(("distance", "signal", "window", "name"), [
    ([0.0, 50.0, 40.0, 150.0], [1.0, 2.0, 3.0, 4.0], 100.0, "distance_m"),  # not monotone
    ([0.0, 50.0, 50.0, 150.0], [1.0, 2.0, 3.0, 4.0], 100.0, "distance_m"),  # repeated sample
    ([0.0, 50.0, 90.0], [1.0, 2.0, 3.0], 100.0, "distance_m"),  # shorter than one window
    ([0.0, 50.0, 150.0], [1.0, 2.0], 100.0, "signal"),  # shape
    ([0.0, 50.0, 150.0], [1.0, np.nan, 2.0], 100.0, "signal"),
    ([0.0, 50.0, 150.0], [1.0, 2.0, 3.0], 0.0, "window_m"),
])
def test_sliding_rms_refuses_bad_input_by_name(distance, signal, window, name) -> None:
    with pytest.raises(ValueError, match=f"^{name}: "):
        sliding_rms(distance, signal, window)


# --- the filtered criterion ----------------------------------------------------------------------------------------

def _record(duration_s: float, *parts: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, duration_s, 1.0 / FS)
    return t, sum(a * np.sin(2 * math.pi * f * t) for a, f in parts)


def test_a_sinusoid_in_the_passband_gives_its_rms_times_the_filter_gain() -> None:
    amplitude, f0, speed = 30e3, 4.0, 50.0  # 100 m = 2 s = 8 periods: every window holds whole periods
    t, sum_y = _record(8.0, (amplitude, f0))
    result = running_stability(t, sum_y, speed, 160e3, frequency_hz=f0)
    gain = butterworth_band_pass_gain(f0, 2.0, 6.0, 4, FS)
    assert gain == pytest.approx(1.0, abs=1e-5)  # the band's centre: flat to 7.6e-6
    expected = gain * amplitude / math.sqrt(2)
    assert result.sliding.rms == pytest.approx(np.full(result.sliding.rms.size, expected), rel=1e-5)
    assert result.max_rms_n == pytest.approx(amplitude / math.sqrt(2), rel=1e-4)
    assert result.limit_n == pytest.approx(63333.3333 / 2, rel=1e-9)
    assert result.ratio == pytest.approx(result.max_rms_n / result.limit_n, rel=1e-14)
    assert result.stable and result.frequency_source == "given" and result.window_m == 100.0


@pytest.mark.parametrize("f", [1.0, 12.0, 20.0])
def test_a_sinusoid_outside_the_band_is_attenuated_by_the_butterworth_gain(f: float) -> None:
    amplitude, f0, speed = 10e3, 4.0, 50.0  # windows of 2 s hold whole periods of 1, 12 and 20 Hz
    t, sum_y = _record(8.0, (amplitude, f))
    result = running_stability(t, sum_y, speed, 160e3, frequency_hz=f0)
    gain = butterworth_band_pass_gain(f, 2.0, 6.0, 4, FS)
    assert gain < 0.05
    assert result.max_rms_n == pytest.approx(gain * amplitude / math.sqrt(2), rel=1e-4)


def test_the_stable_flag_switches_at_half_the_prudhomme_limit() -> None:
    f0, speed, axle = 5.0, 62.5, 22500 * G  # 100 m = 1.6 s = 8 periods
    limit = sum_y_limit(axle) / 2  # 41774.94 N
    gain = butterworth_band_pass_gain(f0, 3.0, 7.0, 4, FS)
    for factor, stable in ((0.99, True), (1.01, False)):
        t, sum_y = _record(8.0, (math.sqrt(2) * factor * limit / gain, f0))
        result = running_stability(t, sum_y, speed, axle, frequency_hz=f0)
        assert result.ratio == pytest.approx(factor, rel=1e-5)
        assert result.stable is stable


def test_the_instability_frequency_is_estimated_from_the_spectrum() -> None:
    # a hunting-like ΣY: a mean (a curve), a fundamental and a weaker third harmonic
    t, sum_y = _record(10.0, (20e3, 3.7), (6e3, 3 * 3.7))
    assert estimate_frequency(t, 4e3 + sum_y) == pytest.approx(3.7, rel=1e-5)
    result = running_stability(t, 4e3 + sum_y, 37.0, 160e3)  # 100 m = 100/37 s = 10 periods of 3.7 Hz
    assert result.frequency_source == "estimated (spectrum peak)"
    assert result.frequency_hz == pytest.approx(3.7, rel=1e-5)
    # the filter keeps the fundamental with its gain and the harmonic (11.1 Hz) with its own; the mean is gone
    lo, hi = result.frequency_hz - 2.0, result.frequency_hz + 2.0
    g1 = butterworth_band_pass_gain(3.7, lo, hi, 4, FS)
    g3 = butterworth_band_pass_gain(11.1, lo, hi, 4, FS)
    assert result.max_rms_n == pytest.approx(math.hypot(g1 * 20e3, g3 * 6e3) / math.sqrt(2), rel=1e-5)


def test_unfiltered_rms_of_a_constant_is_the_constant_also_on_non_uniform_times() -> None:
    rng = np.random.default_rng(3)
    t = np.sort(np.concatenate(([0.0, 3.0], rng.uniform(0.0, 3.0, 500))))
    result = running_stability(t, np.full(t.size, 25e3), 50.0, 160e3, filtered=False)
    assert result.max_rms_n == pytest.approx(25e3, rel=1e-12)
    assert result.filter == "none" and result.frequency_hz is None and result.settle_s == 0.0


def test_filtering_refuses_non_uniform_sampling() -> None:
    t = np.arange(0.0, 8.0, 1 / FS)
    t[100] += 0.3 / FS
    with pytest.raises(ValueError, match="^t_s: .*uniform"):
        running_stability(t, np.sin(2 * math.pi * 4.0 * t), 50.0, 160e3, frequency_hz=4.0)


def test_a_record_shorter_than_one_window_is_refused_with_the_length_needed() -> None:
    t = np.arange(0.0, 1.9, 1 / FS)  # 95 m at 50 m/s
    with pytest.raises(ValueError, match=r"^t_s: .* one 100 m window needs 2 s"):
        running_stability(t, np.ones(t.size), 50.0, 160e3, filtered=False)
    t = np.arange(0.0, 4.0, 1 / FS)  # 200 m, but the filter's settling (3.7 s at 2-6 Hz) comes first
    with pytest.raises(ValueError, match=r"^t_s: .*settling .* need [0-9.]+ s \([0-9.]+ m\)"):
        running_stability(t, np.sin(2 * math.pi * 4.0 * t), 50.0, 160e3, frequency_hz=4.0)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"speed_m_s": 0.0}, "speed_m_s"),
    ({"axle_load_n": -5.0}, "axle_load_n"),
    ({"alpha": -0.85}, "alpha"),
    ({"frequency_hz": 1.5}, "frequency_hz"),  # f0 − 2 Hz ≤ 0
    ({"frequency_hz": 99.0}, "t_s"),  # f0 + 2 Hz above Nyquist (100 Hz)
    ({"frequency_hz": -4.0}, "frequency_hz"),
    ({"filter_order": 0}, "filter_order"),
    ({"filter_order": 2.5}, "filter_order"),
    ({"window_m": -100.0}, "window_m"),
    ({"sum_y_n": np.ones(10)}, "sum_y_n"),
])
def test_running_stability_refuses_bad_input_by_name(kwargs, name) -> None:
    t = np.arange(0.0, 8.0, 1 / FS)
    args = {"t_s": t, "sum_y_n": np.sin(2 * math.pi * 4.0 * t), "speed_m_s": 50.0, "axle_load_n": 160e3,
            "frequency_hz": 4.0} | kwargs
    with pytest.raises(ValueError, match=f"^{name}: "):
        running_stability(**args)


# --- flange clearance and Y/Q --------------------------------------------------------------------------------------

def test_flange_clearance_use_of_a_sinusoid_is_amplitude_over_clearance() -> None:
    t = np.arange(0.0, 2.0 + 1e-12, 1 / 400)  # 2 Hz: the grid holds the crests at t = 0.125 + 0.5 j
    use = flange_clearance_use(4e-3 * np.sin(2 * math.pi * 2.0 * t), 8e-3)
    assert use.fraction == pytest.approx(0.5, rel=1e-12) and use.peak_m == pytest.approx(4e-3, rel=1e-12)
    assert not use.flange_contact
    assert flange_clearance_use(-9e-3 * np.sin(2 * math.pi * 2.0 * t), 8e-3).fraction == pytest.approx(1.125)
    assert flange_clearance_use([0.0, -8e-3], 8e-3).flange_contact


@pytest.mark.parametrize(("y", "c", "name"), [([], 8e-3, "y_m"), ([0.0, np.inf], 8e-3, "y_m"),
                                              ([0.0, 1e-3], 0.0, "flange_clearance_m")])
def test_flange_clearance_use_refuses_bad_input_by_name(y, c, name) -> None:
    with pytest.raises(ValueError, match=f"^{name}: "):
        flange_clearance_use(y, c)


def test_max_derailment_quotient_by_hand() -> None:
    # |Y/Q| = 0.2, 0.8, 0.25
    assert max_derailment_quotient([10e3, -40e3, 20e3], [50e3, 50e3, 80e3]) == pytest.approx(0.8, rel=1e-15)
    with pytest.raises(ValueError, match="^Q: .*sample 1"):
        max_derailment_quotient([1.0, 2.0], [5.0, 0.0])
    with pytest.raises(ValueError, match="^Q: shape"):
        max_derailment_quotient([1.0, 2.0], [5.0])


def test_record_duration_is_the_length_running_stability_demands():
    """The shortest record it accepts: one sample short of record_duration_s is refused naming t_s, the record
    that reaches it is accepted."""
    from railopt.models.vehicle.running_stability import record_duration_s

    f0, dt, speed = 7.0, 1.0 / 400.0, 60.0
    needed = record_duration_s(f0, dt, speed)
    n = int(np.ceil(needed / dt)) + 1
    t = np.arange(n) * dt
    y = np.sin(2 * np.pi * f0 * t)
    running_stability(t, y, speed, 160e3, frequency_hz=f0)
    with pytest.raises(ValueError, match="t_s"):
        running_stability(t[:-2], y[:-2], speed, 160e3, frequency_hz=f0)
