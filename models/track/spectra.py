"""Track irregularity spectra: one-sided PSDs of random rail geometry in angular wavenumber.

Every spectrum here is one-sided in the angular wavenumber Ω (rad/m) and returns m²/(rad/m), so the
variance of the irregularity over a band is ``σ² = ∫ S(Ω) dΩ``.  Conversions (variance preserved):

* cycles/m: ``S_f(f_s) = 2π S(2π f_s)`` m²/(cycle/m), f_s = Ω/2π;
* time at speed V (m/s): ``ω = V Ω`` (rad/s), ``S_ω(ω) = S(ω/V)/V`` m²/(rad/s), or per Hz
  ``S_Hz(f) = 2π S(2π f/V)/V`` m²/Hz.

Analytic spectra (all the rational form ``S(Ω) = b₀ / ((Ω² + p₁²)(Ω² + p₂²))``):

* FRA / AAR track classes 1–6 (Hamid, Rasmussen, Baluja & Yang, *Analytical descriptions of track
  geometry variations*, DOT/FRA/ORD-83/03.1, 1983; constants as tabulated e.g. in W. Zhai,
  *Vehicle–Track Coupled Dynamics: Theory and Applications*, Springer 2020, Ch. 2, American track
  spectra):

  - vertical profile  ``S_v(Ω) = k A_v Ω_c² / (Ω² (Ω² + Ω_c²))``,
  - alignment         ``S_a(Ω) = k A_a Ω_c² / (Ω² (Ω² + Ω_c²))``,
  - cross-level       ``S_c(Ω) = 4 k A_v Ω_c² / ((Ω² + Ω_c²)(Ω² + Ω_s²))``,

  with k = 0.25, A_v, A_a in cm²·rad/m (× 1e-4 to m²·rad/m), Ω_c, Ω_s in rad/m (table
  :data:`FRA_CLASSES`), valid for wavelengths 1.524–304.8 m (5–1000 ft), i.e.
  Ω ∈ [2π/304.8, 2π/1.524] rad/m.  The cross-level spectrum is a height difference between the rails
  (m²/(rad/m)); divide by the squared rail-contact base for a roll angle.  Classes 5 and 6 are
  cross-checked against the public ORVD implementation (``aar_track_irregularity_generator``: A, k,
  Ω_c and its published band RMS); the constants of classes 1–4 and Ω_s are as tabulated by Zhai and
  were not checked against a retrieved copy of the FRA report.
* ERRI B176 (ORE/ERRI B176 RP1, 1989; the form used by SIMPACK's predefined PSD library):
  ``S(Ω) = A Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²))`` with Ω_c = 0.8246 rad/m, Ω_r = 0.0206 rad/m and A
  (m·rad) = 4.032e-7 (profile, low), 1.080e-6 (profile, high), 2.119e-7 (alignment, low),
  6.125e-7 (alignment, high).  The coefficient products ``A Ω_c²`` equal the numerators tabulated by
  the public ORVD implementation (``erri_b176_track_irregularity_generator.cc``: 2.741619e-7,
  7.343623e-7, 1.440846e-7, 4.164787e-7 with denominator coefficients 2.8855e-4, 0.6803895).  The
  sources found give no validity range; this module adopts wavelengths 1–300 m
  (Ω ∈ [2π/300, 2π]) — a stated convention, not a number from the standard.

A measured spectrum comes from a CSV table (:meth:`irregularity_spectrum.from_table`); it is
interpolated linearly in log–log and valid over the tabulated wavenumbers only.

Asking a spectrum for a wavenumber outside its validity is a ``ValueError`` naming the argument.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from railopt.models.units import RAD_PER_HZ as TWO_PI
from railopt.models.validation import number, read_number_table, real_array

CM2_TO_M2 = 1e-4
FRA_K = 0.25

#: FRA classes: A_v, A_a (cm²·rad/m), Ω_s, Ω_c (rad/m) (Hamid et al. 1983; Zhai 2020 table).
FRA_CLASSES: dict[int, tuple[float, float, float, float]] = {
    1: (1.2107, 3.3634, 0.6046, 0.8245),
    2: (1.0181, 1.2107, 0.9308, 0.8245),
    3: (0.6816, 0.4128, 0.8520, 0.8245),
    4: (0.5376, 0.3027, 1.1312, 0.8245),
    5: (0.2095, 0.0762, 0.8209, 0.8245),
    6: (0.0339, 0.0339, 0.4380, 0.8245),
}
FRA_VALIDITY = (TWO_PI / 304.8, TWO_PI / 1.524)  # rad/m: wavelengths 304.8 m … 1.524 m

#: ERRI B176: A (m·rad) by (component, level); Ω_c, Ω_r (rad/m).
ERRI_A = {("profile", "low"): 4.032e-7, ("profile", "high"): 1.080e-6,
          ("alignment", "low"): 2.119e-7, ("alignment", "high"): 6.125e-7}
ERRI_OMEGA_C = 0.8246
ERRI_OMEGA_R = 0.0206
ERRI_VALIDITY = (TWO_PI / 300.0, TWO_PI / 1.0)  # adopted convention (see module docstring)

FRA_COMPONENTS = ("profile", "alignment", "cross_level")
ERRI_COMPONENTS = ("profile", "alignment")
LEVELS = ("low", "high")
STANDARDS = ("fra", "erri_b176")


def _check_validity(name: str, omega: np.ndarray, validity: tuple[float, float], label: str) -> None:
    lo, hi = validity
    tol = 1e-12 * hi
    if omega.size and (np.min(omega) < lo - tol or np.max(omega) > hi + tol):
        raise ValueError(f"{name}: {label} is valid for Ω in [{lo:.6g}, {hi:.6g}] rad/m "
                         f"(wavelengths {TWO_PI / hi:.4g}–{TWO_PI / lo:.4g} m); asked for "
                         f"[{np.min(omega):.6g}, {np.max(omega):.6g}] rad/m")


def _band_omega(band_cycles_per_m: object, validity: tuple[float, float], label: str) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in band_cycles_per_m)  # type: ignore[union-attr]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"band_cycles_per_m: must be two numbers (lo, hi) in cycles/m, got "
                         f"{band_cycles_per_m!r}") from exc
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"band_cycles_per_m: must satisfy 0 < lo < hi (cycles/m), got ({lo}, {hi})")
    w = np.array([TWO_PI * lo, TWO_PI * hi])
    _check_validity("band_cycles_per_m", w, validity, label)
    return float(w[0]), float(w[1])


@dataclass(frozen=True)
class RationalSpectrum:
    """``S(Ω) = gain / ((Ω² + p₁²)(Ω² + p₂²))`` m²/(rad/m), one-sided, Ω in rad/m.

    Attributes
    ----------
    label : str
        Name for tables and error messages.
    gain : float
        b₀ in m²·(rad/m)³ (so that S is in m²/(rad/m)).
    corners : (float, float)
        p₁ ≤ p₂ (rad/m); p₁ = 0 gives the Ω⁻² growth of the FRA profile and alignment spectra.
    validity : (float, float)
        Wavenumbers (rad/m) where the spectrum is defined; outside is an error.
    """

    label: str
    gain: float
    corners: tuple[float, float]
    validity: tuple[float, float]

    def psd(self, wavenumber_rad_per_m: object) -> np.ndarray | float:
        """S(Ω) in m²/(rad/m) at Ω (rad/m), scalar or array (vectorised)."""
        w = np.asarray(wavenumber_rad_per_m, dtype=float)
        if not np.all(np.isfinite(w)):
            raise ValueError("wavenumber_rad_per_m: contains NaN or infinite entries")
        _check_validity("wavenumber_rad_per_m", w.ravel(), self.validity, self.label)
        p1, p2 = self.corners
        w2 = w * w
        out = self.gain / ((w2 + p1 * p1) * (w2 + p2 * p2))
        return float(out) if out.ndim == 0 else out

    def variance(self, omega_lo: float, omega_hi: float) -> float:
        """∫ S dΩ over [Ω_lo, Ω_hi] (rad/m), closed form (m²); the band must lie inside validity.

        Partial fractions ``1/((Ω²+p₁²)(Ω²+p₂²)) = (1/(Ω²+p₁²) − 1/(Ω²+p₂²))/(p₂² − p₁²)`` with
        ``∫dΩ/(Ω²+p²) = atan(Ω/p)/p`` (``−1/Ω`` for p = 0).  Corners closer than 1e-6 relative are
        integrated by adaptive quadrature instead (the closed form would cancel).
        """
        _check_validity("band", np.array([omega_lo, omega_hi]), self.validity, self.label)
        p1, p2 = self.corners
        if p2 - p1 <= 1e-6 * p2:
            from scipy.integrate import quad

            val, _ = quad(lambda x: self.gain / ((x * x + p1 * p1) * (x * x + p2 * p2)), omega_lo, omega_hi,
                          epsabs=0.0, epsrel=1e-12, limit=200)
            return float(val)

        def prim(p: float, x: float) -> float:
            return -1.0 / x if p == 0.0 else math.atan(x / p) / p

        return self.gain / (p2 * p2 - p1 * p1) * (
            prim(p1, omega_hi) - prim(p1, omega_lo) - prim(p2, omega_hi) + prim(p2, omega_lo))

    def rms(self, band_cycles_per_m: tuple[float, float]) -> float:
        """RMS irregularity (m) over ``band_cycles_per_m = (lo, hi)`` in cycles/m (closed form)."""
        lo, hi = _band_omega(band_cycles_per_m, self.validity, self.label)
        return math.sqrt(self.variance(lo, hi))

    def unbounded(self) -> RationalSpectrum:
        """The same rational model extended to Ω ∈ (0, ∞) — a model extrapolation, used to compare the
        full-band state-space RMS with quadrature; not a statement about real track."""
        return replace(self, label=f"{self.label} (extrapolated)", validity=(0.0, math.inf))

    def time_psd(self, frequency_hz: object, speed_m_s: float) -> np.ndarray:
        """One-sided PSD of the irregularity seen at speed V: ``2π S(2πf/V)/V`` m²/Hz."""
        V = number("speed_m_s", speed_m_s, positive=True)
        f = np.asarray(frequency_hz, dtype=float)
        return TWO_PI * np.asarray(self.psd(TWO_PI * f / V)) / V


@dataclass(frozen=True)
class TabulatedSpectrum:
    """A measured one-sided spectrum: wavenumbers Ω_k (rad/m, increasing) and PSD S_k (m²/(rad/m), > 0).

    Between table rows S is interpolated linearly in (log Ω, log S) (a power law on each interval);
    the RMS integrates that power law exactly on each interval.  Valid over [Ω_0, Ω_last] only.
    """

    label: str
    wavenumbers: np.ndarray
    values: np.ndarray

    @property
    def validity(self) -> tuple[float, float]:
        """The wavenumber range (Ω_0, Ω_last) of the table, rad/m: the spectrum is valid there only."""
        return float(self.wavenumbers[0]), float(self.wavenumbers[-1])

    def psd(self, wavenumber_rad_per_m: object) -> np.ndarray | float:
        """S(Ω) m²/(rad/m), log–log interpolated, vectorised."""
        w = np.asarray(wavenumber_rad_per_m, dtype=float)
        if not np.all(np.isfinite(w)):
            raise ValueError("wavenumber_rad_per_m: contains NaN or infinite entries")
        _check_validity("wavenumber_rad_per_m", w.ravel(), self.validity, self.label)
        wc = np.clip(w, *self.validity)
        out = np.exp(np.interp(np.log(wc), np.log(self.wavenumbers), np.log(self.values)))
        return float(out) if out.ndim == 0 else out

    def variance(self, omega_lo: float, omega_hi: float) -> float:
        """∫ S dΩ (m²) over [Ω_lo, Ω_hi] rad/m, exact for the log–log interpolant."""
        _check_validity("band", np.array([omega_lo, omega_hi]), self.validity, self.label)
        knots = self.wavenumbers
        inner = knots[(knots > omega_lo) & (knots < omega_hi)]
        edges = np.concatenate([[omega_lo], inner, [omega_hi]])
        s = np.asarray(self.psd(edges))
        total = 0.0
        for a, b, sa, sb in zip(edges[:-1], edges[1:], s[:-1], s[1:], strict=True):
            n = math.log(sb / sa) / math.log(b / a)  # S = sa (Ω/a)^n on [a, b]
            total += sa * a * (math.log(b / a) if abs(n + 1) < 1e-12 else ((b / a) ** (n + 1) - 1) / (n + 1))
        return total

    def rms(self, band_cycles_per_m: tuple[float, float]) -> float:
        """RMS (m) over ``band_cycles_per_m = (lo, hi)`` cycles/m."""
        lo, hi = _band_omega(band_cycles_per_m, self.validity, self.label)
        return math.sqrt(self.variance(lo, hi))

    def time_psd(self, frequency_hz: object, speed_m_s: float) -> np.ndarray:
        """One-sided PSD at speed V: ``2π S(2πf/V)/V`` m²/Hz."""
        V = number("speed_m_s", speed_m_s, positive=True)
        f = np.asarray(frequency_hz, dtype=float)
        return TWO_PI * np.asarray(self.psd(TWO_PI * f / V)) / V


Spectrum = RationalSpectrum | TabulatedSpectrum


def fra_spectrum(track_class: int, component: str) -> RationalSpectrum:
    """The FRA class ``track_class`` (1–6) spectrum of ``component`` (profile, alignment, cross_level)."""
    if isinstance(track_class, bool) or not isinstance(track_class, int | np.integer) or track_class not in FRA_CLASSES:
        raise ValueError(f"track_class: must be an integer 1–6 (FRA track classes), got {track_class!r}")
    if component not in FRA_COMPONENTS:
        raise ValueError(f"component: must be one of {FRA_COMPONENTS} for the FRA spectra, got {component!r}")
    a_v, a_a, om_s, om_c = FRA_CLASSES[int(track_class)]
    if component == "cross_level":
        gain = 4 * FRA_K * a_v * CM2_TO_M2 * om_c**2
        corners = tuple(sorted((om_s, om_c)))
    else:
        amp = a_v if component == "profile" else a_a
        gain = FRA_K * amp * CM2_TO_M2 * om_c**2
        corners = (0.0, om_c)
    return RationalSpectrum(f"FRA class {int(track_class)} {component}", gain, corners, FRA_VALIDITY)


def erri_spectrum(level: str, component: str) -> RationalSpectrum:
    """The ERRI B176 ``level`` (low, high) spectrum of ``component`` (profile, alignment)."""
    if level not in LEVELS:
        raise ValueError(f"level: must be one of {LEVELS} for ERRI B176, got {level!r}")
    if component not in ERRI_COMPONENTS:
        raise ValueError(f"component: must be one of {ERRI_COMPONENTS} for ERRI B176, got {component!r}")
    gain = ERRI_A[(component, level)] * ERRI_OMEGA_C**2
    return RationalSpectrum(f"ERRI B176 {level} {component}", gain, (ERRI_OMEGA_R, ERRI_OMEGA_C), ERRI_VALIDITY)


def read_spectrum_table(path: str | Path) -> TabulatedSpectrum:
    """A measured spectrum from a CSV file: two columns, wavenumber (rad/m) and PSD (m²/(rad/m)).

    UTF-8 text (with or without the byte-order mark spreadsheets write); a first row none of whose cells parses
    as a number is taken as a header.  Errors name the file: a file that is not UTF-8 text, and with the
    (1-based) row: fewer than two data rows, a non-numeric or non-finite cell, a non-positive wavenumber
    or PSD, wavenumbers not strictly increasing (:func:`railopt.models.validation.read_number_table`).
    """
    table, rows = read_number_table(path, ("wavenumber rad/m", "PSD m²/(rad/m)"))
    p = Path(path)
    for k, (w, s) in enumerate(table):
        i = rows[k]
        if w <= 0:
            raise ValueError(f"{p}: row {i}: wavenumber must be positive, got {w}")
        if s <= 0:
            raise ValueError(f"{p}: row {i}: PSD must be positive, got {s}")
        if k and w <= table[k - 1, 0]:
            raise ValueError(f"{p}: row {i}: wavenumbers must increase strictly ({w} after {table[k - 1, 0]})")
    wn, ps = table[:, 0], table[:, 1]
    w_arr = real_array("wavenumbers", wn)
    s_arr = real_array("values", ps)
    w_arr.setflags(write=False)
    s_arr.setflags(write=False)
    return TabulatedSpectrum(f"measured {p.name}", w_arr, s_arr)


class _IrregularitySpectrumFactory:
    """``irregularity_spectrum(standard, ...)`` and ``irregularity_spectrum.from_table(path)``."""

    def __call__(self, standard: str, *, track_class: int | None = None, level: str | None = None,
                 component: str = "profile") -> RationalSpectrum:
        """An analytic spectrum.

        Parameters
        ----------
        standard : {"fra", "erri_b176"}
        track_class : int, FRA only
            FRA track class 1–6.
        level : {"low", "high"}, ERRI B176 only
        component : str
            FRA: ``"profile"`` (vertical), ``"alignment"``, ``"cross_level"``; ERRI B176: ``"profile"``,
            ``"alignment"``.

        Returns
        -------
        RationalSpectrum
            ``.psd(Ω)`` m²/(rad/m), ``.rms((lo, hi) cycles/m)`` m.

        Raises
        ------
        ValueError
            Unknown standard, component or level; a track class that is not an integer 1–6; an argument
            that belongs to the other standard.
        """
        if standard == "fra":
            if level is not None:
                raise ValueError("level: applies to ERRI B176 only (FRA spectra take track_class)")
            if track_class is None:
                raise ValueError("track_class: the FRA spectra need a track class 1–6")
            return fra_spectrum(track_class, component)
        if standard == "erri_b176":
            if track_class is not None:
                raise ValueError("track_class: applies to the FRA spectra only (ERRI B176 takes level)")
            if level is None:
                raise ValueError(f"level: ERRI B176 needs a level, one of {LEVELS}")
            return erri_spectrum(level, component)
        raise ValueError(f"standard: must be one of {STANDARDS}, got {standard!r}")

    @staticmethod
    def from_table(path: str | Path) -> TabulatedSpectrum:
        """A measured spectrum from a CSV table (see :func:`read_spectrum_table`)."""
        return read_spectrum_table(path)


irregularity_spectrum = _IrregularitySpectrumFactory()

__all__ = [
    "ERRI_A",
    "FRA_CLASSES",
    "RationalSpectrum",
    "Spectrum",
    "TabulatedSpectrum",
    "erri_spectrum",
    "fra_spectrum",
    "irregularity_spectrum",
    "read_spectrum_table",
]
