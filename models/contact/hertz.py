"""Hertz contact ellipse (thesis (4.19)–(4.20)) with the coefficients m, n from elliptic integrals.

Convention: the gap between the undeformed surfaces is h = A x² + B y², x along the rolling
direction, y lateral; A, B are the *relative* principal curvatures (half the sums of the principal
curvatures of the two bodies, positive when convex).  For a wheel on a straight rail
(:func:`wheel_rail_curvatures`)

    A = 1/(2 r_w),   B = ½ (1/R_rail − 1/R_wheel_transverse)

with R_wheel_transverse > 0 for a concave (hollow/worn) tread and ``inf`` for a coned tread.

Hertz's solution for two bodies of the same material (E, ν): with semi-axes a' ≥ b' of the ellipse,
g = b'/a', k² = 1 − g², K(k), E(k) the complete elliptic integrals, the major axis lies along the
smaller curvature and

    A_small / A_large = (K − E) / (E/g² − K)                                              (Hertz)
    a' = m c₀,  b' = n c₀,  c₀ = (3 N (1 − ν²) / (2 E (A + B)))^{1/3}               (4.19)–(4.20)
    m = (2 E(k) / (π g²))^{1/3},   n = m g.

(From A + B = p0 E(k)/(E* b') with E* = E/(2(1 − ν²)) and N = (2/3) π a' b' p0; A = B gives m = n = 1.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from railopt.models.validation import number as finite
from railopt.models.validation import poisson, positive


def _curvature_ratio(g: float) -> float:
    """A_small/A_large of the ellipse with axis ratio g = b'/a' ≤ 1 (Hertz; parameter m = k² = 1 − g²)."""
    m = 1.0 - g * g
    K, E = ellipk(m), ellipe(m)
    return (K - E) / (E / (g * g) - K)


def hertz_coefficients(curvature_ratio: float) -> tuple[float, float, float]:
    """Hertz's m, n (major, minor) and the axis ratio g = n/m for a curvature ratio.

    Parameters
    ----------
    curvature_ratio : float
        min(A, B) / max(A, B) in (0, 1].  (Hertz tables list cos τ = (B − A)/(A + B); the ratio is
        (1 − cos τ)/(1 + cos τ).)

    Returns
    -------
    (m, n, g) : tuple of float
        Dimensionless coefficients of (4.19)–(4.20), m ≥ n, and g = n/m.
    """
    rho = finite("curvature_ratio", curvature_ratio)
    if not 0.0 < rho <= 1.0:
        raise ValueError(f"curvature_ratio: must lie in (0, 1], got {rho}")
    if rho >= 1.0 - 1e-14:
        return 1.0, 1.0, 1.0
    # _curvature_ratio increases monotonically from 0 (g -> 0) to 1 (g -> 1).
    lo = 1e-6
    if _curvature_ratio(lo) > rho:
        raise ValueError(f"curvature_ratio: {rho} too small (ellipse more slender than b/a = 1e-6)")
    g = brentq(lambda t: _curvature_ratio(t) - rho, lo, 1.0 - 1e-15, xtol=1e-15, rtol=1e-15, maxiter=200)
    m = (2.0 * ellipe(1.0 - g * g) / (math.pi * g * g)) ** (1.0 / 3.0)
    return float(m), float(m * g), float(g)


@dataclass(frozen=True)
class HertzEllipse:
    """Contact ellipse of one wheel on its rail (SI).

    Attributes
    ----------
    a : float
        Semi-axis along the rolling direction x, m.
    b : float
        Semi-axis along the lateral direction y, m.
    m, n : float
        Hertz coefficients of (4.19)–(4.20) (m for the major, n for the minor axis).
    p0 : float
        Maximum contact pressure 3N/(2πab), Pa.
    """

    a: float
    b: float
    m: float
    n: float
    p0: float

    @property
    def c(self) -> float:
        """Equivalent radius √(ab), m (the thesis's c)."""
        return math.sqrt(self.a * self.b)

    @property
    def aspect(self) -> float:
        """a/b (rolling over lateral)."""
        return self.a / self.b


def hertz_ellipse(N: float, E: float, nu: float, A: float, B: float) -> HertzEllipse:
    """Hertz ellipse (4.19)–(4.20) for normal load ``N`` (N) between two bodies of one material.

    Parameters
    ----------
    N, E : float
        Normal load (N) and Young's modulus (Pa).
    nu : float
        Poisson's ratio.
    A, B : float
        Relative principal curvatures along the rolling (x) and lateral (y) directions, 1/m.
    """
    N = positive("N", N)
    E = positive("E", E)
    nu = poisson("nu", nu)
    A = positive("A", A)
    B = positive("B", B)
    m, n, _ = hertz_coefficients(min(A, B) / max(A, B))
    c0 = (3.0 * N * (1.0 - nu * nu) / (2.0 * E * (A + B))) ** (1.0 / 3.0)
    major, minor = m * c0, n * c0
    a, b = (major, minor) if A <= B else (minor, major)  # the major axis lies along the smaller curvature
    return HertzEllipse(a=a, b=b, m=m, n=n, p0=3.0 * N / (2.0 * math.pi * a * b))


def wheel_rail_curvatures(r_wheel: float, R_rail: float, R_wheel_transverse: float = math.inf) -> tuple[float, float]:
    """Relative curvatures (A, B), 1/m, of a wheel (rolling radius ``r_wheel``) on a straight rail.

    A = 1/(2 r_wheel) (rolling direction); B = ½ (1/R_rail − 1/R_wheel_transverse) (lateral), with
    ``R_wheel_transverse`` > 0 for a concave tread and ``inf`` for a coned tread.
    """
    r_wheel = positive("r_wheel", r_wheel)
    R_rail = positive("R_rail", R_rail)
    Rw = float(R_wheel_transverse)
    if math.isnan(Rw) or Rw <= 0.0:
        raise ValueError(f"R_wheel_transverse: must be > 0 (inf for a coned tread), got {Rw}")
    B = 0.5 * (1.0 / R_rail - 1.0 / Rw)
    if B <= 0.0:
        raise ValueError("R_wheel_transverse: must exceed R_rail (otherwise the profiles do not touch at a point)")
    return 0.5 / r_wheel, B


__all__ = ["HertzEllipse", "hertz_coefficients", "hertz_ellipse", "wheel_rail_curvatures"]
