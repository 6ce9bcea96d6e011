"""Ride comfort: weightings against published values, N_MV / N_VD closed forms, Sperling, seeds, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from railopt.models.comfort import (
    comfort_class,
    continuous_comfort,
    mean_comfort,
    mean_comfort_from_psd,
    read_accelerations,
    sperling_index,
    sperling_index_from_psd,
    sperling_index_harmonic,
    sperling_weighting,
    standing_comfort,
    synthesise_accelerations,
    weighted_rms_from_psd,
    weighting,
)

# ISO 2631-1:1997 Table 3 (weighting factors at the nominal one-third-octave centre frequencies, × 1000);
# Wd is EN 12299's horizontal weighting, Wk is the ISO 2631-1 seat vertical weighting.
ISO2631_TABLE3 = {
    "Wd": {0.5: 0.853, 1.0: 1.011, 2.0: 0.890, 4.0: 0.512, 8.0: 0.253, 16.0: 0.125},
    "Wk": {0.5: 0.418, 1.0: 0.482, 2.0: 0.531, 4.0: 0.967, 8.0: 1.036},
}
# Value of each weighting at the reference frequency 100 rad/s (15.915 Hz), as listed by ZETLAB's
# "frequency weighting functions" page (Wb after ISO 2631-4, Wc and Wd after ISO 2631-1).
AT_100_RAD_S = {"Wb_iso": 0.8126, "Wc": 0.5145, "Wd": 0.1261}


@pytest.mark.parametrize("name", sorted(ISO2631_TABLE3))
def test_weighting_matches_iso2631_table(name):
    f = np.array(sorted(ISO2631_TABLE3[name]))
    table = np.array([ISO2631_TABLE3[name][x] for x in f])
    assert np.allclose(weighting(name).magnitude(f), table, rtol=0, atol=6e-4)  # the table rounds to 3 digits


@pytest.mark.parametrize("name", sorted(AT_100_RAD_S))
def test_weighting_at_reference_frequency(name):
    assert float(weighting(name).magnitude(100 / (2 * math.pi))) == pytest.approx(AT_100_RAD_S[name], abs=6e-5)


def test_en12299_wb_in_the_standards_own_form():
    """EN 12299 writes the Wb step with K = 0.4 on (1 + s/(Q5ω5) + s²/ω5²)/(1 + s/(Q6ω6) + s²/ω6²), Q4 = 0.63,
    Q5 = Q6 = 0.8 (as in comfpy/filters.py); our product form uses K = 1.024 = 0.4·(4/2.5)²."""
    f = np.array([0.3, 1.0, 2.5, 4.0, 6.3, 16.0, 40.0])
    s = 2j * math.pi * f
    w1, w2, w3, w4, w5, w6 = (2 * math.pi * x for x in (0.4, 100, 16, 16, 2.5, 4))
    q = 1 / math.sqrt(2)
    hp = s**2 / (s**2 + w1 * s / q + w1**2)
    lp = w2**2 / (s**2 + w2 * s / q + w2**2)
    av = (w4**2 / w3 * s + w4**2) / (s**2 + w4 / 0.63 * s + w4**2)
    step = 0.4 * (s**2 / w5**2 + s / (0.8 * w5) + 1) / (s**2 / w6**2 + s / (0.8 * w6) + 1)
    assert np.allclose(weighting("Wb").response(f), hp * lp * av * step, rtol=1e-12, atol=0)


def test_sperling_weighting_formula_and_table():
    """B_z from its formula; B_y = 1.25 B_z; and consistent with Sperling's frequency correction F(f)
    (vertical: 0.325 f² below 5.9 Hz, 400/f² to 20 Hz) through Wz = 0.896 (a³F/f)^0.1 = (a·B)^0.3, i.e.
    B = 0.896^(10/3) (F/f)^(1/3), within 4 % at 1–8 Hz (the two are fits of the same curve)."""
    for f in (0.5, 1.0, 3.0, 10.0):
        expected = 0.588 * math.sqrt((1.911 * f * f + (0.25 * f * f) ** 2)
                                     / ((1 - 0.277 * f * f) ** 2 + (1.563 * f - 0.0368 * f**3) ** 2))
        assert float(sperling_weighting(f)) == pytest.approx(expected, rel=1e-14)
        assert float(sperling_weighting(f, "lateral")) == pytest.approx(1.25 * expected, rel=1e-14)
    for f in (1.0, 2.0, 4.0, 8.0):
        F = 0.325 * f * f if f < 5.9 else 400 / f**2
        assert float(sperling_weighting(f)) == pytest.approx(0.896 ** (10 / 3) * (F / f) ** (1 / 3), rel=0.04)


def test_sperling_index_harmonic_time_and_psd_agree():
    a, f, fs, T = 0.3, 2.0, 200.0, 20.0  # 0.3 m/s² peak at 2 Hz
    t = np.arange(int(fs * T)) / fs
    expected = (100 * a * float(sperling_weighting(f))) ** 0.3
    assert sperling_index_harmonic(a, f) == pytest.approx(expected, rel=1e-14)
    assert sperling_index(a * np.sin(2 * math.pi * f * t), fs) == pytest.approx(expected, rel=1e-10)
    # a narrow flat PSD of the same variance a²/2 around f gives nearly the same Wz
    grid = np.linspace(f - 0.005, f + 0.005, 201)
    assert sperling_index_from_psd(grid, np.full(grid.size, a * a / 2 / 0.01)) == pytest.approx(expected, rel=1e-4)


def test_n_mv_of_sinusoids_closed_form():
    """ax, ay, az sinusoids with whole periods in every 5-s block: each block RMS is |W(f)|·A/√2."""
    fs, T = 100.0, 60.0
    t = np.arange(int(fs * T)) / fs
    amps = {"x": (0.2, 1.4), "y": (0.3, 0.8), "z": (0.5, 4.0)}
    ax, ay, az = (amps[k][0] * np.sin(2 * math.pi * amps[k][1] * t) for k in "xyz")
    from railopt.models.comfort import AccelerationRecord

    rec = AccelerationRecord(fs, ax, ay, az)
    wx = float(weighting("Wd").magnitude(1.4)) * 0.2 / math.sqrt(2)
    wy = float(weighting("Wd").magnitude(0.8)) * 0.3 / math.sqrt(2)
    wz = float(weighting("Wb").magnitude(4.0)) * 0.5 / math.sqrt(2)
    result = mean_comfort(rec)
    assert result.value == pytest.approx(6 * math.sqrt(wx**2 + wy**2 + wz**2), rel=1e-10)
    assert len(result.block_rms_z) == 12


def flat(level):
    return lambda f: np.full(np.shape(f), level)


def test_n_mv_and_n_vd_of_synthesised_line_spectrum_closed_form():
    """Lines every 0.2 Hz: each 5-s block holds whole periods of every line, so every block RMS equals
    sqrt(Σ_k |W(f_k)|² S(f_k) Δf) and N_MV, N_VD follow in closed form (independent of the phases)."""
    fs, T, df, band = 200.0, 300.0, 0.2, (0.2, 40.0)
    sx, sy, sz = 0.002, 0.004, 0.01  # (m/s²)²/Hz
    rec = synthesise_accelerations(flat(sx), flat(sy), flat(sz), T, fs, seed=7, frequency_step_hz=df, band_hz=band)
    f = np.arange(1, 201) * df  # 0.2 … 40 Hz
    ax = math.sqrt(np.sum(weighting("Wd").magnitude(f) ** 2 * sx * df))
    ay = math.sqrt(np.sum(weighting("Wd").magnitude(f) ** 2 * sy * df))
    az = math.sqrt(np.sum(weighting("Wb").magnitude(f) ** 2 * sz * df))
    n_mv = mean_comfort(rec)
    assert n_mv.value == pytest.approx(6 * math.sqrt(ax**2 + ay**2 + az**2), rel=1e-9)
    assert np.allclose(n_mv.block_rms_z, az, rtol=1e-9)
    n_vd = standing_comfort(rec)
    assert n_vd.value == pytest.approx(3 * math.sqrt(16 * ax**2 + 4 * ay**2 + az**2) + 5 * ay, rel=1e-9)
    t, cx, cy, cz = continuous_comfort(rec)
    assert t[0] == pytest.approx(5.0) and np.allclose(cz, az, rtol=1e-9) and np.allclose(cx, ax, rtol=1e-9)
    # the unweighted variance is Σ S Δf exactly
    assert np.var(rec.az) == pytest.approx(sz * df * 200, rel=1e-9)
    # the frequency-domain estimate of the same spectra (trapezoid on a fine grid) is within 1 %
    grid = np.linspace(0.2, 40.0, 4001)
    est = mean_comfort_from_psd(grid, np.full(grid.size, sx), np.full(grid.size, sy), np.full(grid.size, sz))
    assert est == pytest.approx(n_mv.value, rel=0.01)


def test_seed_reproducibility():
    psd = flat(0.01)
    a = synthesise_accelerations(psd, psd, psd, 60.0, 100.0, seed=42)
    b = synthesise_accelerations(psd, psd, psd, 60.0, 100.0, seed=42)
    c = synthesise_accelerations(psd, psd, psd, 60.0, 100.0, seed=43)
    assert a.seed == 42 and np.array_equal(a.az, b.az) and np.array_equal(a.ax, b.ax)
    assert mean_comfort(a).value == mean_comfort(b).value
    assert not np.allclose(a.az, c.az)
    assert mean_comfort(a).value != mean_comfort(c).value
    assert mean_comfort(a).seed == 42


def test_weighted_rms_from_psd_against_quad():
    s = lambda f: 0.01 / (1 + (f / 3.0) ** 4)  # noqa: E731
    grid = np.linspace(0.1, 50.0, 200_001)
    expected = math.sqrt(quad(lambda f: float(weighting("Wb").magnitude(f)) ** 2 * s(f), 0.1, 50.0,
                              epsabs=0, epsrel=1e-12, limit=200)[0])
    assert weighted_rms_from_psd(grid, s(grid), "Wb") == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize(("n", "label"), [(0.5, "very comfortable"), (1.0, "comfortable"), (1.99, "comfortable"),
                                          (2.0, "medium"), (3.9, "medium"), (4.0, "uncomfortable"),
                                          (5.0, "very uncomfortable"), (7.0, "very uncomfortable")])
def test_comfort_classes(n, label):
    assert comfort_class(n) == label


def test_csv_round_trip(tmp_path):
    fs, T = 50.0, 10.0
    t = np.arange(int(fs * T)) / fs
    az = 0.4 * np.sin(2 * math.pi * 2.0 * t)
    path = tmp_path / "acc.csv"
    rows = "".join(f"{x!r},0.0,0.0,{float(z)!r}\n" for x, z in zip(t.tolist(), az, strict=True))
    path.write_text("time_s,ax,ay,az\n" + rows)
    rec = read_accelerations(path)
    assert rec.sample_rate_hz == pytest.approx(fs) and rec.seed is None
    assert mean_comfort(rec).value == pytest.approx(6 * float(weighting("Wb").magnitude(2.0)) * 0.4 / math.sqrt(2),
                                                    rel=1e-9)


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(("body", "fragment"), [
    ("time_s,ax,ay,az\n0,0,0,0\n0.01,0,0,0\n0.01,0,0,0\n", "row 4: time must increase"),
    ("0,0,0,0\n0.01,0,0,0\n0.03,0,0,0\n0.04,0,0,0\n", "row 3: non-uniform sampling"),
    ("0,0,0,0\n0.01,0,0\n", "row 2: expected 4 columns"),
    ("0,0,0,0\n0.01,0,x,0\n", "row 2: not four numbers"),
    ("0,0,0,0\n", "at least two data rows"),
])
def test_bad_acceleration_csv_names_file_and_row(tmp_path, body, fragment):
    path = tmp_path / "bad_acc.csv"
    path.write_text(body)
    with pytest.raises(ValueError, match="bad_acc.csv") as err:
        read_accelerations(path)
    assert fragment in str(err.value)


def test_bad_arguments_name_the_argument():
    with pytest.raises(ValueError, match="^name:"):
        weighting("Wz")
    with pytest.raises(ValueError, match="^direction:"):
        sperling_weighting(1.0, "vertically")
    with pytest.raises(ValueError, match="^seed:"):
        synthesise_accelerations(flat(1.0), None, None, 10.0, 100.0, seed=1.5)
    with pytest.raises(ValueError, match="^frequency_step_hz:"):
        synthesise_accelerations(flat(1.0), None, None, 10.0, 100.0, seed=1, frequency_step_hz=0.15)
    with pytest.raises(ValueError, match="^psd_x:"):
        synthesise_accelerations(lambda f: -np.ones_like(f), None, None, 10.0, 100.0, seed=1)
    with pytest.raises(ValueError, match="^n:"):
        comfort_class(-1.0)
    with pytest.raises(ValueError, match="^record:"):
        mean_comfort(synthesise_accelerations(flat(1.0), None, None, 4.0, 100.0, seed=1))
    with pytest.raises(ValueError, match="^frequencies_hz:"):
        weighted_rms_from_psd([1.0, 0.5], [1.0, 1.0], "Wd")
