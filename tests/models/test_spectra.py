"""Track irregularity spectra against published numbers and independent quadrature."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from railopt.models.track.spectra import irregularity_spectrum

# Published band RMS (mm) over 0.024–0.333 cycles/m (wavelengths 3–41.7 m): the public ORVD code's test
# ``CheckSpectrumParametersAndBandVariance`` (AAR/FRA single-cutoff spectra, k = 0.25, Ω_c = 0.8245 rad/m,
# A in cm²·rad/m × 1e-4), which asserts these to 1e-7 mm.
PUBLISHED_RMS_MM = {
    (5, "alignment"): 3.0624168,
    (5, "profile"): 5.0778379,
    (6, "alignment"): 2.0426157,
    (6, "profile"): 2.0426157,
}


@pytest.mark.parametrize(("track_class", "component"), sorted(PUBLISHED_RMS_MM))
def test_fra_band_rms_matches_published(track_class, component):
    spec = irregularity_spectrum("fra", track_class=track_class, component=component)
    assert 1000 * spec.rms((0.024, 0.333)) == pytest.approx(PUBLISHED_RMS_MM[(track_class, component)], abs=2e-7)


@pytest.mark.parametrize("track_class", range(1, 7))
@pytest.mark.parametrize("component", ["profile", "alignment", "cross_level"])
def test_fra_rms_closed_form_equals_quadrature_of_psd(track_class, component):
    """The closed-form band RMS against scipy quad of .psd() (m²/(rad/m) over rad/m)."""
    spec = irregularity_spectrum("fra", track_class=track_class, component=component)
    lo, hi = 2 * math.pi * 0.024, 2 * math.pi * 0.333
    var, _ = quad(spec.psd, lo, hi, epsabs=0, epsrel=1e-12, limit=200)
    assert spec.rms((0.024, 0.333)) == pytest.approx(math.sqrt(var), rel=1e-10)


def test_fra_formula_and_units():
    """S_v = k A_v Ω_c²/(Ω²(Ω²+Ω_c²)) with A_v cm²·rad/m → m²: class 5 profile at Ω = 1 rad/m, and the
    cross-level 4 k A_v Ω_c²/((Ω²+Ω_c²)(Ω²+Ω_s²)) with Ω_s = 0.8209 (Hamid et al. 1983; Zhai 2020)."""
    k, av, oc, os_ = 0.25, 0.2095e-4, 0.8245, 0.8209
    prof = irregularity_spectrum("fra", track_class=5, component="profile")
    cl = irregularity_spectrum("fra", track_class=5, component="cross_level")
    assert prof.psd(1.0) == pytest.approx(k * av * oc**2 / (1.0 * (1.0 + oc**2)), rel=1e-14)
    assert cl.psd(0.5) == pytest.approx(4 * k * av * oc**2 / ((0.25 + oc**2) * (0.25 + os_**2)), rel=1e-14)
    w = np.array([0.1, 0.5, 2.0])
    assert np.allclose(prof.psd(w), [prof.psd(x) for x in w], rtol=0, atol=0)  # vectorised


@pytest.mark.parametrize(("level", "component", "a"), [
    ("low", "profile", 4.032e-7), ("high", "profile", 1.080e-6),
    ("low", "alignment", 2.119e-7), ("high", "alignment", 6.125e-7)])
def test_erri_b176_formula_and_published_coefficients(level, component, a):
    """ERRI B176: S = A Ω_c²/((Ω²+Ω_r²)(Ω²+Ω_c²)), Ω_c = 0.8246, Ω_r = 0.0206 rad/m (ORE B176); the
    expanded numerators A Ω_c² published in the ORVD implementation (SIMPACK QCH coefficients)."""
    numerators = {("low", "profile"): 2.741619e-7, ("high", "profile"): 7.343623e-7,
                  ("low", "alignment"): 1.440846e-7, ("high", "alignment"): 4.164787e-7}
    spec = irregularity_spectrum("erri_b176", level=level, component=component)
    for om in (0.05, 0.3, 1.0, 3.0):
        expected = numerators[(level, component)] / (0.00028855 + 0.6803895 * om**2 + om**4)
        assert spec.psd(om) == pytest.approx(expected, rel=2e-6)
        assert spec.psd(om) == pytest.approx(a * 0.8246**2 / ((om**2 + 0.0206**2) * (om**2 + 0.8246**2)), rel=1e-14)
    var, _ = quad(spec.psd, 2 * math.pi * 0.01, 2 * math.pi * 0.5, epsabs=0, epsrel=1e-12)
    assert spec.rms((0.01, 0.5)) == pytest.approx(math.sqrt(var), rel=1e-10)


def test_cycles_per_metre_conversion():
    """S_f(f_s) = 2π S(2π f_s): the variance is the same in either variable."""
    spec = irregularity_spectrum("erri_b176", level="high", component="profile")
    var_f, _ = quad(lambda f: 2 * math.pi * spec.psd(2 * math.pi * f), 0.02, 0.4, epsabs=0, epsrel=1e-12)
    assert spec.rms((0.02, 0.4)) ** 2 == pytest.approx(var_f, rel=1e-10)


def test_table_spectrum(tmp_path):
    """A tabulated power law S = c Ω⁻³ is reproduced exactly (log–log interpolation) with its closed-form RMS."""
    w = np.geomspace(0.05, 5.0, 9)
    path = tmp_path / "measured.csv"
    rows = "".join(f"{float(x)!r},{float(2e-8 * x**-3)!r}\n" for x in w)
    path.write_text("wavenumber_rad_per_m,psd_m2_per_rad_per_m\n" + rows)
    spec = irregularity_spectrum.from_table(path)
    assert spec.psd(0.7) == pytest.approx(2e-8 * 0.7**-3, rel=1e-12)
    lo, hi = 0.03, 0.6  # cycles/m → Ω = 0.188 … 3.77 rad/m
    a, b = 2 * math.pi * lo, 2 * math.pi * hi
    exact = 2e-8 * (a**-2 - b**-2) / 2
    assert spec.rms((lo, hi)) == pytest.approx(math.sqrt(exact), rel=1e-12)


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(("kwargs", "name"), [
    (dict(standard="fra", track_class=-1, component="profile"), "track_class"),
    (dict(standard="fra", track_class=2.5, component="profile"), "track_class"),
    (dict(standard="fra", track_class=7, component="profile"), "track_class"),
    (dict(standard="fra", track_class=True, component="profile"), "track_class"),
    (dict(standard="fra", track_class=5, component="gauge"), "component"),
    (dict(standard="erri_b176", level="medium", component="profile"), "level"),
    (dict(standard="erri_b176", level="low", component="cross_level"), "component"),
    (dict(standard="iso8608", level="low"), "standard"),
    (dict(standard="fra", track_class=5, level="low"), "level"),
])
def test_bad_spectrum_arguments_name_the_argument(kwargs, name):
    standard = kwargs.pop("standard")
    with pytest.raises(ValueError, match=f"^{name}:"):
        irregularity_spectrum(standard, **kwargs)


def test_outside_validity_names_the_argument():
    spec = irregularity_spectrum("fra", track_class=5, component="alignment")  # 1.524–304.8 m
    with pytest.raises(ValueError, match="^band_cycles_per_m:"):
        spec.rms((0.001, 0.333))  # 1000 m wavelength
    with pytest.raises(ValueError, match="^band_cycles_per_m:"):
        spec.rms((0.024, 1.0))  # 1 m wavelength
    with pytest.raises(ValueError, match="^band_cycles_per_m:"):
        spec.rms((0.3, 0.1))
    with pytest.raises(ValueError, match="^wavenumber_rad_per_m:"):
        spec.psd(np.array([0.1, 10.0]))


@pytest.mark.parametrize(("body", "fragment"), [
    ("1.0,1e-6\n2.0,0.0\n", "row 2: PSD must be positive"),
    ("1.0,1e-6\n2.0,-1e-7\n", "row 2: PSD must be positive"),
    ("k,S\n1.0,1e-6\n1.0,1e-7\n", "row 3: wavenumbers must increase"),
    ("1.0,1e-6\n0.5,1e-7\n", "row 2: wavenumbers must increase"),
    ("0.0,1e-6\n0.5,1e-7\n", "row 1: wavenumber must be positive"),
    ("1.0,1e-6\n2.0,abc\n", "row 2: not two numbers"),
    ("1.0,1e-6\n", "at least two data rows"),
])
def test_bad_table_names_file_and_row(tmp_path, body, fragment):
    path = tmp_path / "bad.csv"
    path.write_text(body)
    with pytest.raises(ValueError, match="bad.csv") as err:
        irregularity_spectrum.from_table(path)
    assert fragment in str(err.value)
