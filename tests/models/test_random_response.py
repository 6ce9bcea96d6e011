"""Random response to track irregularity: quadrature against independent integrals and against the
state-space (modal covariance, exact delays) method on the vehicle models."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from railopt.models import Forcing, LinearSystem
from railopt.models.random_response import output_psd, random_response, rms, rms_combined, rms_state_space
from railopt.models.track.spectra import irregularity_spectrum
from railopt.models.vehicle import Irregularity, load_vehicle

TWO_PI = 2 * math.pi


def sdof(m: float, k: float, zeta: float, quantity: str = "displacement") -> LinearSystem:
    """Mass on a spring and damper whose base follows the rail: m ẍ + c ẋ + k x = k u + c u̇."""
    c = 2 * zeta * math.sqrt(k * m)
    return LinearSystem([[m]], [[c]], [[k]], Forcing.polynomial(np.array([[k], [c]])), [1.0], response=quantity)


# Independent spectrum formulas (not through the module): (gain b₀, p₁, p₂) of b₀/((Ω²+p₁²)(Ω²+p₂²)).
INDEPENDENT = {
    ("fra", 5, "profile"): (0.25 * 0.2095e-4 * 0.8245**2, 0.0, 0.8245),
    ("fra", 5, "alignment"): (0.25 * 0.0762e-4 * 0.8245**2, 0.0, 0.8245),
    ("fra", 6, "profile"): (0.25 * 0.0339e-4 * 0.8245**2, 0.0, 0.8245),
    ("fra", 4, "cross_level"): (4 * 0.25 * 0.5376e-4 * 0.8245**2, 0.8245, 1.1312),
    ("erri_b176", "low", "profile"): (4.032e-7 * 0.8246**2, 0.0206, 0.8246),
    ("erri_b176", "high", "profile"): (1.080e-6 * 0.8246**2, 0.0206, 0.8246),
    ("erri_b176", "low", "alignment"): (2.119e-7 * 0.8246**2, 0.0206, 0.8246),
    ("erri_b176", "high", "alignment"): (6.125e-7 * 0.8246**2, 0.0206, 0.8246),
}


def make_spectrum(key):
    standard, which, component = key
    if standard == "fra":
        return irregularity_spectrum("fra", track_class=which, component=component)
    return irregularity_spectrum("erri_b176", level=which, component=component)


@pytest.mark.parametrize("key", sorted(INDEPENDENT, key=str))
@pytest.mark.parametrize(("zeta", "quantity"), [(0.05, "displacement"), (0.2, "acceleration"), (0.002, "displacement")])
def test_sdof_rms_equals_independent_quadrature(key, zeta, quantity):
    """RMS² = ∫|(k+iωc)/(k−mω²+iωc)|² ω^{2q} S(ω/V)/V dω by scipy quad, to 1e-6 relative."""
    m, k, V, band = 1000.0, 4.0e5, 30.0, (0.5, 15.0)  # f_n = 3.18 Hz; Ω = 0.105–3.14 rad/m (inside validity)
    system = sdof(m, k, zeta, quantity)
    c = 2 * zeta * math.sqrt(k * m)
    b0, p1, p2 = INDEPENDENT[key]
    q = 2 if quantity == "acceleration" else 0

    def integrand(w):
        t2 = abs((k + 1j * w * c) / (k - m * w * w + 1j * w * c)) ** 2 * w ** (2 * q)
        om = w / V
        return t2 * b0 / ((om * om + p1 * p1) * (om * om + p2 * p2)) / V

    wn = math.sqrt(k / m)
    expected, _ = quad(integrand, TWO_PI * band[0], TWO_PI * band[1], points=[wn], epsabs=0, epsrel=1e-13,
                       limit=2000)
    got = rms(system, make_spectrum(key), V, band)
    assert got == pytest.approx(math.sqrt(expected), rel=1e-6)


def test_sdof_rms_under_measured_table_equals_independent_quadrature(tmp_path):
    """A measured (CSV) spectrum: a tabulated power law S = c Ω⁻³ (log–log interpolation is exact for it)."""
    w = np.geomspace(0.05, 5.0, 7)
    path = tmp_path / "measured.csv"
    path.write_text("".join(f"{float(x)!r},{float(3e-8 * x**-3)!r}\n" for x in w))
    spec = irregularity_spectrum.from_table(path)
    m, k, zeta, V, band = 1000.0, 4.0e5, 0.05, 30.0, (0.5, 15.0)
    c = 2 * zeta * math.sqrt(k * m)

    def integrand(x):
        return abs((k + 1j * x * c) / (k - m * x * x + 1j * x * c)) ** 2 * 3e-8 * (x / V) ** -3 / V

    expected, _ = quad(integrand, TWO_PI * band[0], TWO_PI * band[1], points=[math.sqrt(k / m)], epsabs=0,
                       epsrel=1e-13, limit=500)
    assert rms(sdof(m, k, zeta), spec, V, band) == pytest.approx(math.sqrt(expected), rel=1e-6)


def test_quadrature_rule_is_reusable_and_error_controlled():
    system = sdof(1000.0, 4.0e5, 0.001)  # a very lightly damped peak
    spec = irregularity_spectrum("erri_b176", level="low", component="profile")
    r = random_response(system, spec, 30.0, (0.5, 15.0), rtol=1e-10)
    assert r.rule.integrate(r.gain_squared * r.input_psd) == pytest.approx(r.variance, rel=1e-14)
    assert r.error_estimate <= 1e-10 * r.variance
    # |H|² at the nodes is |frf|², the input PSD is S(ω/V)/V
    assert np.allclose(r.gain_squared, np.abs(system.frf(omega_rad_s=r.rule.omega)) ** 2, rtol=1e-12)
    assert np.allclose(r.input_psd, spec.psd(r.rule.omega / 30.0) / 30.0, rtol=1e-14)
    coarse = random_response(system, spec, 30.0, (0.5, 15.0), rtol=1e-4)
    assert coarse.rms == pytest.approx(r.rms, rel=1e-4)


def test_output_psd_units_integrate_to_the_variance():
    """output_psd is in output²/Hz: ∫ PSD df over the band (Hz) equals RMS²."""
    system = sdof(1000.0, 4.0e5, 0.1, "acceleration")
    spec = irregularity_spectrum("fra", track_class=5, component="profile")
    V, band = 30.0, (0.5, 15.0)
    var_hz, _ = quad(lambda f: float(output_psd(system, spec, V, f)), *band, points=[3.18], epsabs=0, epsrel=1e-12,
                     limit=500)
    assert rms(system, spec, V, band) ** 2 == pytest.approx(var_hz, rel=1e-8)
    f = np.array([1.0, 3.0, 10.0])
    expected = np.abs(system.frf(omega_rad_s=TWO_PI * f)) ** 2 * TWO_PI * spec.psd(TWO_PI * f / V) / V
    assert np.allclose(output_psd(system, spec, V, f), expected, rtol=1e-14)


def test_independent_inputs_add_in_power():
    a, b = sdof(1000.0, 4.0e5, 0.1, "acceleration"), sdof(800.0, 2.0e5, 0.2, "acceleration")
    pa = irregularity_spectrum("fra", track_class=5, component="profile")
    pb = irregularity_spectrum("fra", track_class=5, component="alignment")
    total = rms_combined([(a, pa), (b, pb, "output")], 30.0, (0.5, 15.0))
    assert total == pytest.approx(math.hypot(rms(a, pa, 30.0, (0.5, 15.0)), rms(b, pb, 30.0, (0.5, 15.0))), rel=1e-12)


def test_state_space_sdof_matches_closed_form_quadrature():
    """Method (b) on the SDOF against scipy quad of the closed form over (0, ∞)."""
    m, k, zeta, V = 1000.0, 4.0e5, 0.05, 30.0
    c = 2 * zeta * math.sqrt(k * m)
    b0, p1, p2 = INDEPENDENT[("erri_b176", "high", "profile")]

    def integrand(w):
        om = w / V
        return abs((k + 1j * w * c) / (k - m * w * w + 1j * w * c)) ** 2 * b0 / ((om**2 + p1**2) * (om**2 + p2**2)) / V

    expected = quad(integrand, 0, 1.0, epsabs=0, epsrel=1e-13, limit=500)[0] + \
        quad(integrand, 1.0, np.inf, epsabs=0, epsrel=1e-13, limit=500)[0]
    spec = irregularity_spectrum("erri_b176", level="high", component="profile")
    assert rms_state_space(sdof(m, k, zeta), spec, V) == pytest.approx(math.sqrt(expected), rel=1e-9)


# ---------------------------------------------------------------- the two methods on the vehicle models
VEHICLE_CASES = [
    # vehicle, block, irregularity, output, quantity, speed (m/s), ERRI level, component, axle terms
    ("manchester-coach", "vertical", "vertical", "body.w", "acceleration", 40.0, "low", "profile", 4),
    ("manchester-coach", "vertical", "vertical", "body.w", "displacement", 40.0, "high", "profile", 4),
    ("manchester-coach", "lateral", "alignment", "body.v", "acceleration", 40.0, "high", "alignment", 4),
    ("sd40-2", "vertical", "vertical", "body.w", "acceleration", 40.0, "low", "profile", 6),
    ("sd40-2", "vertical", "vertical", "body.w", "displacement", 40.0, "low", "profile", 6),
    ("sd40-2", "lateral", "alignment", "body.v", "acceleration", 25.0, "low", "alignment", 6),  # stable < ~33 m/s
]


@pytest.mark.parametrize("case", VEHICLE_CASES, ids=lambda c: "-".join(map(str, c[:5])))
def test_quadrature_and_state_space_agree_on_vehicles(case):
    """(a) adaptive quadrature of the extrapolated rational spectrum over 1e-9–1e5 Hz against (b) the modal
    covariance with exact axle delays over 0 < ω < ∞: agreement to 1e-4 relative (measured ~1e-9 or better;
    the band tails are below 1e-9 of the variance: |H|²S ~ ω⁴ (acceleration) or ~const (displacement) as ω→0,
    ~ω⁻² or faster as ω→∞)."""
    vehicle, block, kind, out, quantity, speed, level, component, axles = case
    view = getattr(load_vehicle(vehicle), block)("rigid", speed=speed)
    system = view.forced_system(Irregularity(kind, amplitude_m=1.0), [out], quantity=quantity)
    delays = sorted(t.delay for t in system.forcing.terms)
    assert len(delays) == axles and delays[-1] > 0.3  # one delayed term per axle: wheelbase filtering is in |H|
    spec = irregularity_spectrum("erri_b176", level=level, component=component)
    a = random_response(system, spec.unbounded(), speed, (1e-9, 1e5), rtol=1e-10)
    b = rms_state_space(system, spec, speed)
    assert a.rms == pytest.approx(b, rel=1e-4)
    assert abs(a.rms / b - 1) < 1e-7  # what is actually measured (documented in docs/ride.md)


def test_vertical_model_free_mode_is_handled():
    """The vertical coach has a free fore-aft rigid-body mode (roots at s = 0): the quadrature never evaluates
    ω = 0 and |H| stays finite as ω → 0; a zero lower band edge is refused."""
    system = load_vehicle("manchester-coach").vertical("rigid", speed=40.0).forced_system(
        Irregularity("vertical", amplitude_m=1.0), ["body.w"], quantity="acceleration")
    assert np.min(np.abs(system.eigenvalues())) < 1e-6
    spec = irregularity_spectrum("fra", track_class=5, component="profile")
    value = rms(system, spec, 40.0, (0.2, 20.0))
    assert math.isfinite(value) and value > 0
    with pytest.raises(ValueError, match="^band_hz:"):
        rms(system, spec, 40.0, (0.0, 20.0))


# ---------------------------------------------------------------- bad input
def test_bad_inputs_name_the_argument():
    system = sdof(1000.0, 4.0e5, 0.1)
    fra = irregularity_spectrum("fra", track_class=5, component="profile")
    with pytest.raises(ValueError, match="^band_hz:"):
        rms(system, fra, 30.0, (0.01, 15.0))  # Ω = 0.002 rad/m: below FRA validity
    with pytest.raises(ValueError, match="^band_hz:"):
        rms(system, fra, 30.0, (0.5, 50.0))  # Ω = 10.5 rad/m: above
    with pytest.raises(ValueError, match="^band_hz:"):
        rms(system, fra, 30.0, (5.0, 1.0))
    with pytest.raises(ValueError, match="^speed_m_s:"):
        rms(system, fra, -1.0, (0.5, 15.0))
    with pytest.raises(ValueError, match="^output:"):
        rms(system, fra, 30.0, (0.5, 15.0), output="nope")
    with pytest.raises(ValueError, match="^spectrum:"):
        rms_state_space(system, fra, 30.0)  # p₁ = 0: no stable shaping filter
    with pytest.raises(ValueError, match="^frequencies_hz:"):
        output_psd(system, fra, 30.0, [0.0, 1.0])
    with pytest.raises(ValueError, match="^inputs:"):
        rms_combined([], 30.0, (0.5, 15.0))


def test_unstable_system_is_refused():
    system = load_vehicle("sd40-2").lateral("rigid", speed=40.0).forced_system(
        Irregularity("alignment", amplitude_m=1.0), ["body.v"], quantity="acceleration")  # hunting at 40 m/s
    spec = irregularity_spectrum("erri_b176", level="low", component="alignment")
    with pytest.raises(ValueError, match="^system: unstable"):
        rms(system, spec, 40.0, (0.5, 20.0))
    with pytest.raises(ValueError, match="^system: not asymptotically stable"):
        rms_state_space(system, spec, 40.0)
