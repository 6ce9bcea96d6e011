"""Linear creep coefficients of one wheel (thesis §4.2.2, (4.9)–(4.32)).

Constitutive law per wheel (4.9), creepages ξ_x, ξ_y (dimensionless), spin ξ_sp (1/m):

    T_x = −f11 ξ_x
    T_y = −f22 ξ_y − f23 ξ_sp
    M_z = −f32 ξ_y − f33 ξ_sp,      f32 = −f23 by default (Kalker; the thesis's remark under (4.9))

Units: f11, f22 in N; f23, f32 in N·m; f33 in N·m².  Thesis names: f1 = f11, f2 = f22, f3 = f33.

Theories (``creep_coefficients(theory=...)``); a is the semi-axis along the rolling direction, b lateral,
c = √(ab), G the shear modulus:

* ``"kalker"`` — linear theory, f11 = G ab C11, f22 = G ab C22, f23 = G (ab)^{3/2} C23,
  f33 = G (ab)² C33, C_ij from Table E.3 (:mod:`railopt.models.contact.kalker_table`).
* ``"vermeulen-johnson"`` — f11 = Gπab/Φ, f22 = Gπab/Ψ1 (4.25)–(4.26), with Φ, Ψ1 from
  :func:`vermeulen_johnson_phi_psi`; spin by Johnson's sphere theory: f33 (4.29), f23 (4.32).
* ``"carter"`` — f11 = f22 = f of (4.10), f23 = f33 = 0.

``factor`` multiplies every coefficient (the thesis's creep correction factor, §4.2.2 after (4.26)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.special import ellipe, ellipk, gammaln

from railopt.models.contact import kalker_table
from railopt.models.units import INCH as _INCH
from railopt.models.units import POUND_FORCE as _LBF
from railopt.models.validation import number as finite
from railopt.models.validation import poisson, positive

Theory = Literal["vermeulen-johnson", "kalker", "carter"]
THEORIES: tuple[str, ...] = ("vermeulen-johnson", "kalker", "carter")

#: Carter's constant of (4.10) in its own units, lbf^½ / in^½ (f in lbf for r0 in in and N in lbf).
CARTER_CONSTANT_US = 3500.0
#: The same constant in SI, N^½ / m^½ (f in N for r0 in m and N in N): 3500 √(lbf/in) ≈ 4.632e4.
CARTER_CONSTANT_SI = CARTER_CONSTANT_US * math.sqrt(_LBF / _INCH)


@dataclass(frozen=True)
class CreepCoefficients:
    """Creep coefficients of one wheel, law (4.9).

    Attributes
    ----------
    f11 : float
        Longitudinal, N (thesis f1).
    f22 : float
        Lateral, N (thesis f2).
    f23 : float
        Lateral force per unit spin, N·m.
    f33 : float
        Spin moment per unit spin, N·m² (thesis f3).
    f32 : float
        Spin moment per unit lateral creepage, N·m; ``None`` (default) sets ``f32 = −f23`` (4.9), (4.32).
    """

    f11: float
    f22: float
    f23: float = 0.0
    f33: float = 0.0
    f32: float | None = None  # resolved to a float (−f23 when None) by __post_init__

    def __post_init__(self) -> None:
        for name in ("f11", "f22", "f23", "f33"):
            object.__setattr__(self, name, finite(name, getattr(self, name)))
        if self.f11 < 0.0 or self.f22 < 0.0 or self.f33 < 0.0:
            raise ValueError("f11, f22, f33: creep coefficients must be >= 0")
        f32 = 0.0 - self.f23 if self.f32 is None else finite("f32", self.f32)
        object.__setattr__(self, "f32", f32)

    def scaled(self, factor: float) -> CreepCoefficients:
        """All coefficients multiplied by ``factor`` (≥ 0)."""
        k = finite("factor", factor)
        if k < 0.0:
            raise ValueError(f"factor: must be >= 0, got {k}")
        return CreepCoefficients(self.f11 * k, self.f22 * k, self.f23 * k, self.f33 * k, self.f32 * k)

    def forces(self, xi_x: float, xi_y: float, xi_sp: float) -> tuple[float, float, float]:
        """(T_x, T_y, M_z) in N, N, N·m from creepages and spin (1/m), law (4.9)."""
        return (
            -self.f11 * xi_x,
            -self.f22 * xi_y - self.f23 * xi_sp,
            -self.f32 * xi_y - self.f33 * xi_sp,
        )


# --------------------------------------------------------------------------------------------------
# Kalker


def kalker_coefficients(a_over_b: float, nu: float) -> np.ndarray:
    """Kalker's C11, C22, C23, C33 (dimensionless) for ellipse ratio a/b and Poisson's ratio ν.

    Table E.3 nodes: g = min(a/b, b/a) ∈ {0.1, …, 1.0}, ν ∈ {0, ¼, ½}.  Linear interpolation in g on
    the branch (a ≤ b or a > b); in ν a quadratic through the three nodes of 1/C_ij (the scheme of
    CONTACT's ``linrol``), which returns the table values at the nodes.

    Raises
    ------
    ValueError
        ``a_over_b`` outside [0.1, 10] or ``nu`` outside [0, 0.5].
    """
    r = positive("a_over_b", a_over_b)
    nu = poisson("nu", nu)
    g, table = (r, kalker_table.A_OVER_B_LE_1) if r <= 1.0 else (1.0 / r, kalker_table.B_OVER_A_LE_1)
    if g < 0.1 - 1e-12:
        raise ValueError(f"a_over_b: Kalker's table covers 0.1 <= a/b <= 10, got {r}")
    t = min(max((g - 0.1) / 0.1, 0.0), 9.0)
    i = min(int(math.floor(t)), 8)
    w = t - i
    c_nu = (1.0 - w) * table[i] + w * table[i + 1]  # (4 coefficients, 3 nu)
    if nu in (0.0, 0.25, 0.5):
        return np.array(c_nu[:, int(round(nu * 4))], dtype=float)
    inv = 1.0 / c_nu
    l0 = (nu - 0.25) * (nu - 0.5) / ((0.0 - 0.25) * (0.0 - 0.5))
    l1 = (nu - 0.0) * (nu - 0.5) / ((0.25 - 0.0) * (0.25 - 0.5))
    l2 = (nu - 0.0) * (nu - 0.25) / ((0.5 - 0.0) * (0.5 - 0.25))
    return 1.0 / (l0 * inv[:, 0] + l1 * inv[:, 1] + l2 * inv[:, 2])


# --------------------------------------------------------------------------------------------------
# Vermeulen & Johnson


def _a_integrals(k2: float) -> tuple[float, float, float]:
    """A_n = ∫_0^{π/2} sin^{2n}θ (1 − k² sin²θ)^{-3/2} dθ for n = 0, 1, 2 (k² = elliptic parameter)."""
    if k2 < 0.1:  # binomial series; the closed forms below cancel for k² -> 0
        j = np.arange(60)
        log_binom = gammaln(j + 1.5) - gammaln(1.5) - gammaln(j + 1.0)  # (3/2)_j / j!
        powers = np.exp(log_binom + j * math.log(k2)) if k2 > 0.0 else (j == 0).astype(float)

        def w(p: np.ndarray) -> np.ndarray:  # ∫ sin^{2p} = (π/2) (2p−1)!!/(2p)!!
            return 0.5 * math.sqrt(math.pi) * np.exp(gammaln(p + 0.5) - gammaln(p + 1.0))

        return tuple(float(np.sum(powers * w(j + n))) for n in (0, 1, 2))  # type: ignore[return-value]
    K, E = float(ellipk(k2)), float(ellipe(k2))
    a0 = E / (1.0 - k2)
    a1 = (a0 - K) / k2
    a2 = (a1 - (K - E) / k2) / k2
    return a0, a1, a2


def vermeulen_johnson_phi_psi(a_over_b: float, nu: float) -> tuple[float, float]:
    """Vermeulen–Johnson Φ, Ψ1 (dimensionless) of (4.21)–(4.26) for ellipse ratio a/b and ν.

    Derived from their stick-ellipse model (Vermeulen & Johnson 1964, J. Appl. Mech. 31:338): the
    traction is the difference of two ellipsoidal (Hertz-shaped) tractions, so the creepage equals
    2 (1 − k) μ p0 C / G with C the coefficient of x² in the relative tangential displacement under
    the traction √(1 − x²/a² − y²/b²) (Cerruti's half-space kernel).  Closed forms, A_n from
    complete elliptic integrals (see :func:`_a_integrals`; derivation in ``docs/contact.md``):

    a ≤ b, g = a/b, k² = 1 − g²:   Φ = g² (A1 − ν A2),                 Ψ1 = g² ((1 − ν) A1 + ν A2)
    a > b,  g = b/a, k² = 1 − g²:   Φ = g ((1 − ν) A0 − (1 − 2ν) A1 − ν A2),   Ψ1 = g (A0 − (1 + ν) A1 + ν A2)

    A circle gives Φ = π(4 − 3ν)/16, Ψ1 = π(4 − ν)/16 (Johnson's sphere results).
    """
    r = positive("a_over_b", a_over_b)
    nu = poisson("nu", nu)
    if r <= 1.0:
        g = r
        a0, a1, a2 = _a_integrals(1.0 - g * g)
        return g * g * (a1 - nu * a2), g * g * ((1.0 - nu) * a1 + nu * a2)
    g = 1.0 / r
    a0, a1, a2 = _a_integrals(1.0 - g * g)
    return g * ((1.0 - nu) * a0 - (1.0 - 2.0 * nu) * a1 - nu * a2), g * (a0 - (1.0 + nu) * a1 + nu * a2)


def johnson_spin(c: float, G: float, nu: float, f22: float) -> tuple[float, float]:
    """Johnson's spin coefficients (f23 in N·m, f33 in N·m²), (4.27)–(4.32).

    f33 = (32/9) (2 − ν)/(3 − 2ν) G c⁴ (4.29); f23 = 2(2 − ν)/(3(3 − 2ν)) c f22 (4.32)
    (the thesis's 0.469 c f2 is this factor at ν ≈ 0.27).
    """
    k = (2.0 - nu) / (3.0 - 2.0 * nu)
    return 2.0 * k / 3.0 * c * f22, 32.0 / 9.0 * k * G * c**4


# --------------------------------------------------------------------------------------------------
# Carter


def carter_coefficient(r0: float, N: float) -> float:
    """Carter's empirical creep coefficient f = 3500 √(r0 N) (4.10), returned in N.

    In (4.10) the constant 3500 carries units lbf^½/in^½ (r0 in inches, N in lbf, f in lbf).  Here
    ``r0`` is in m and ``N`` (the wheel's normal load) in N, and f = 4.632e4 √(r0 N) N
    (:data:`CARTER_CONSTANT_SI`, N^½/m^½).
    """
    return CARTER_CONSTANT_SI * math.sqrt(positive("r0", r0) * positive("N", N))


# --------------------------------------------------------------------------------------------------


def creep_coefficients(
    a: float,
    b: float,
    G: float,
    nu: float,
    theory: Theory = "vermeulen-johnson",
    factor: float = 1.0,
    *,
    r0: float | None = None,
    N: float | None = None,
) -> CreepCoefficients:
    """Creep coefficients of one wheel from its contact ellipse.

    Parameters
    ----------
    a, b : float
        Semi-axes of the contact ellipse along the rolling and lateral directions, m.
    G : float
        Shear modulus E/(2(1 + ν)), Pa.
    nu : float
        Poisson's ratio.
    theory : {"vermeulen-johnson", "kalker", "carter"}
        See the module docstring.
    factor : float
        Correction factor multiplying every coefficient.
    r0, N : float, optional
        Wheel radius (m) and normal load (N); required by ``"carter"`` only.

    Returns
    -------
    CreepCoefficients
        f11, f22 (N), f23 (N·m), f33 (N·m²), f32 = −f23.
    """
    if theory not in THEORIES:
        raise ValueError(f"theory: unknown {theory!r}; choose one of {', '.join(THEORIES)}")
    if theory == "carter":
        if r0 is None or N is None:
            raise ValueError("r0, N: Carter's coefficient (4.10) needs the wheel radius and the normal load")
        f = carter_coefficient(r0, N)
        return CreepCoefficients(f, f, 0.0, 0.0).scaled(factor)
    a = positive("a", a)
    b = positive("b", b)
    G = positive("G", G)
    nu = poisson("nu", nu)
    ab = a * b
    if theory == "kalker":
        c11, c22, c23, c33 = kalker_coefficients(a / b, nu)
        cc = CreepCoefficients(G * ab * c11, G * ab * c22, G * ab**1.5 * c23, G * ab**2 * c33)
        return cc.scaled(factor)
    phi, psi1 = vermeulen_johnson_phi_psi(a / b, nu)
    f11 = G * math.pi * ab / phi
    f22 = G * math.pi * ab / psi1
    f23, f33 = johnson_spin(math.sqrt(ab), G, nu, f22)
    return CreepCoefficients(f11, f22, f23, f33).scaled(factor)


__all__ = [
    "CARTER_CONSTANT_SI", "CARTER_CONSTANT_US", "CreepCoefficients", "THEORIES", "Theory", "carter_coefficient",
    "creep_coefficients", "johnson_spin", "kalker_coefficients", "vermeulen_johnson_phi_psi",
]
