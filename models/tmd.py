"""A tuned mass damper (Voigt type) on an undamped primary under a harmonic force.

The standard validation case of minimax design (SPEC §5): primary mass m1 on spring k1, absorber
mass m2 = μ·m1 on spring k2 and damper c2.  The output is the amplitude magnification factor
``|X1 k1 / F|`` (dimensionless).  Design is in terms of the tuning ratio ``γ = ω2/ω1`` and the
absorber damping ratio ``ζ = c2 / (2 m2 ω2)``; the model itself is affine in ``(k2, c2)``.

Reference optima:

- Den Hartog's fixed-point tuning (Den Hartog, *Mechanical Vibrations*, 1956):
  γ = 1/(1+μ), ζ = sqrt(3μ / (8(1+μ))), fixed-point height sqrt(1 + 2/μ).
- The exact H∞ optimum of Nishihara & Asami (2002, J. Vib. Acoust. 124:576, eqs. for the undamped
  primary): γ = 2/(1+μ) · sqrt(2(16 + 23μ + 9μ² + 2(2+μ)sqrt(4+3μ)) / (3(64 + 80μ + 27μ²))),
  ζ = ¼ sqrt((8 + 9μ − 4 sqrt(4+3μ)) / (1+μ)).  The minimum peak is the maximum over frequency of
  the closed-form amplitude :func:`amplification` at that tuning (two equal peaks).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.validation import number


@dataclass(frozen=True)
class TMDTuning:
    """A TMD design: tuning ratio γ, damping ratio ζ and the resulting peak of |X1 k1/F|."""

    mass_ratio: float
    tuning: float
    damping_ratio: float
    peak: float


def tmd_system(mass_ratio: float, primary_mass: float = 1.0, primary_stiffness: float = 1.0,
               output_name: str = "output") -> ParametricSystem:
    """Two-DOF TMD model, parameters ``("k2", "c2")`` (N/m, N·s/m); output ``k1·x1`` per unit force."""
    mass_ratio = number("mass_ratio", mass_ratio, positive=True)
    m1 = number("primary_mass", primary_mass, positive=True)
    k1 = number("primary_stiffness", primary_stiffness, positive=True)
    coupling = np.array([[1.0, -1.0], [-1.0, 1.0]])
    return ParametricSystem(
        M0=np.diag([m1, mass_ratio * m1]),
        C0=np.zeros((2, 2)),
        K0=np.diag([k1, 0.0]),
        F0=np.array([1.0, 0.0]),
        outputs={output_name: np.array([k1, 0.0])},
        parts={"k2": ParameterPart(K=coupling), "c2": ParameterPart(C=coupling)},
        names=("x1", "x2"),
    )


def tmd_parameters(
    tuning: float, damping_ratio: float, mass_ratio: float, primary_mass: float = 1.0, primary_stiffness: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Map (γ, ζ) to p = (k2, c2) and the Jacobian dp/d(γ, ζ), shape (2, 2).

    k2 = m2 (γ ω1)², c2 = 2 ζ m2 γ ω1 with m2 = μ m1, ω1 = sqrt(k1/m1).
    """
    m2 = mass_ratio * primary_mass
    w1 = np.sqrt(primary_stiffness / primary_mass)
    p = np.array([m2 * (tuning * w1) ** 2, 2 * damping_ratio * m2 * tuning * w1])
    jac = np.array([[2 * m2 * tuning * w1**2, 0.0], [2 * damping_ratio * m2 * w1, 2 * m2 * tuning * w1]])
    return p, jac


def amplification(g: np.ndarray | float, tuning: float, damping_ratio: float, mass_ratio: float) -> np.ndarray:
    """Closed-form |X1 k1/F| at frequency ratio g = Ω/ω1 (Den Hartog's textbook expression)."""
    g = np.asarray(g, dtype=float)
    gam, z, mu = tuning, damping_ratio, mass_ratio
    num = (gam**2 - g**2) + 2j * z * gam * g
    den = (1 - g**2) * (gam**2 - g**2) - mu * gam**2 * g**2 + 2j * z * gam * g * (1 - g**2 - mu * g**2)
    return np.abs(num / den)


def peak_amplification(tuning: float, damping_ratio: float, mass_ratio: float, points: int = 20001) -> float:
    """Maximum over g ∈ (0, 3] of :func:`amplification`: every local maximum of a dense uniform
    sampling refined by scipy's bounded Brent.  Deliberately independent of the model layer's band
    search (:mod:`railopt.models.peak_search`), which the published optima are used to check."""
    g = np.linspace(1e-6, 3.0, points)
    a = amplification(g, tuning, damping_ratio, mass_ratio)
    best = float(np.max(a))
    for k in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
        res = minimize_scalar(lambda x: -float(amplification(x, tuning, damping_ratio, mass_ratio)),
                              bounds=(g[k - 1], g[k + 1]), method="bounded", options={"xatol": 1e-14})
        best = max(best, -float(res.fun))
    return best


def den_hartog(mass_ratio: float) -> TMDTuning:
    """Den Hartog's fixed-point optimum for an undamped primary; ``peak`` is its true maximum."""
    mu = mass_ratio
    gam = 1.0 / (1.0 + mu)
    z = np.sqrt(3 * mu / (8 * (1 + mu)))
    return TMDTuning(mu, gam, z, peak_amplification(gam, z, mu))


def den_hartog_fixed_point_height(mass_ratio: float) -> float:
    """Height sqrt(1 + 2/μ) of Den Hartog's equal fixed points (his estimate of the peak)."""
    return float(np.sqrt(1 + 2 / mass_ratio))


def nishihara_asami(mass_ratio: float) -> TMDTuning:
    """Exact H∞ optimum (Nishihara & Asami 2002) of a TMD on an undamped primary."""
    mu = mass_ratio
    r = np.sqrt(4 + 3 * mu)
    gam = 2 / (1 + mu) * np.sqrt(2 * (16 + 23 * mu + 9 * mu**2 + 2 * (2 + mu) * r) / (3 * (64 + 80 * mu + 27 * mu**2)))
    z = 0.25 * np.sqrt((8 + 9 * mu - 4 * r) / (1 + mu))
    return TMDTuning(mu, float(gam), float(z), peak_amplification(gam, z, mu))


__all__ = [
    "TMDTuning", "amplification", "den_hartog", "den_hartog_fixed_point_height", "nishihara_asami",
    "peak_amplification", "tmd_parameters", "tmd_system",
]
