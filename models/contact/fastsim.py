"""Kalker's FASTSIM: the simplified theory of rolling contact on an elliptic contact area.

Source: J.J. Kalker, "A fast algorithm for the simplified theory of rolling contact", Vehicle System Dynamics
11 (1982) 1–13; the three-flexibility variant as in CONTACT (E.A.H. Vollebregt & J.J. Kalker, Apache-2.0,
``src/m_hertz.f90`` ``simpflex`` and ``src/m_sdis.f90``, option M = 3, without its creepage "blending").

Simplified theory (Kalker): the surface displacement is u = L p (a Winkler bed of flexibility L, m³/N).  Here
each creepage has its own flexibility, chosen so that the small-creepage forces equal Kalker's linear theory:

    L1 = 8a / (3 G C11),   L2 = 8a / (3 G C22),   L3 = π a √(a/b) / (4 G C23)          (Kalker 1982)

C_ij from Kalker's Table E.3 (:func:`railopt.models.contact.creep.kalker_coefficients`), a the semi-axis along
the rolling direction x, b lateral.  Steady rolling, the material enters the contact at the leading edge
x = +a(y) = a √(1 − y²/b²) with zero traction and leaves at x = −a(y).  In adhesion the traction grows as

    dp_x/d(−x) = −(ξ_x / L1 − ξ_sp y / L3),   dp_y/d(−x) = −(ξ_y / L2 + ξ_sp x / L3)

(rigid slip w = (ξ_x − ξ_sp y, ξ_y + ξ_sp x), Kalker's sign, so that T = −f ξ as in creep.py); where |p|
would exceed the traction bound g = μ p_n(x, y) it is scaled back onto the bound in its own direction (slip).

Discretisation (after Kalker 1982): n_y strips of equal width 2b/n_y centred at y_j; each strip divided into
n_x elements of equal length 2a(y_j)/n_x; the traction is computed at the element centres, marching from the
leading edge, with the rigid slip of each step taken at the step's midpoint (so the adhesion solution is exact
at the centres); forces and moment by the midpoint rule along x and across strips.  The pressure p_n is scaled
so that its discrete sum is exactly N, which makes |F| ≤ μN hold exactly.  Traction bound: ``"parabolic"``
(Kalker's, p_n = 2N/(πab)(1 − x²/a² − y²/b²), the default and the consistent choice for the simplified theory)
or ``"elliptic"`` (Hertz, 3N/(2πab)√(…)).

Accuracy of the defaults n_x = n_y = 64 (``tests/models/contact/test_fastsim.py``): small-creepage slopes are
Kalker's C11, C22 times (1 + 1/(2n_y²)) exactly (1.2e-4) and C23 within 1.4e-4; without spin the force is
within 1e-4 μN of the closed form of the simplified theory, the error falling ~4× per doubling of
n_x = n_y.  With spin the slip direction changes along a strip and FASTSIM is first-order accurate (the
motivation of Vollebregt & Wilders' second-order FASTSIM2, Comput. Mech. 2011): about 0.4 % in F_y and
0.6 % in M_z at the defaults in CONTACT's example (a = 8, b = 4 mm), halving per doubling.  FASTSIM's spin
moment is not Kalker's C33 (the simplified theory does not reproduce the moment coefficients); against exact
theory (CONTACT) its lateral force with spin was 6.6 % high and its spin moment 22 % low in that example.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from railopt.models.contact.creep import kalker_coefficients
from railopt.models.validation import number as finite
from railopt.models.validation import poisson, real_array

Bound = Literal["parabolic", "elliptic"]
BOUNDS: tuple[str, ...] = ("parabolic", "elliptic")
DEFAULT_N_X = 64
DEFAULT_N_Y = 64


@dataclass(frozen=True)
class FastsimResult:
    """FASTSIM's total forces, and optionally its traction distribution (shapes for inputs broadcast to ``S``).

    Attributes
    ----------
    Fx, Fy : numpy.ndarray
        Longitudinal and lateral force on the wheel, N, shape ``S`` (sign of creep.py: T = −f ξ).
    Mz : numpy.ndarray
        Spin moment about the contact centre, N·m, shape ``S``.
    x, y : numpy.ndarray or None
        Element centres, m, shape ``S + (n_y, n_x)`` (element 0 at the leading edge); ``None`` unless
        ``tractions=True``.
    px, py : numpy.ndarray or None
        Tangential tractions at the element centres, Pa, same shape.
    slip : numpy.ndarray or None
        ``True`` where the element is in slip (traction on the bound), same shape.
    """

    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    px: np.ndarray | None = None
    py: np.ndarray | None = None
    slip: np.ndarray | None = None

    @property
    def slip_fraction(self) -> np.ndarray:
        """Area fraction of the contact in slip, shape ``S`` (needs ``tractions=True``)."""
        if self.slip is None or self.x is None:
            raise ValueError("slip: run fastsim(..., tractions=True) to get the slip area")
        dx = self.x[..., :1] - self.x[..., 1:2]  # element length per strip, S + (n_y, 1)
        return np.sum(self.slip * dx, axis=(-2, -1)) / np.sum(np.broadcast_to(dx, self.slip.shape), axis=(-2, -1))


def fastsim_flexibilities(a: float, b: float, G: float, nu: float) -> tuple[float, float, float]:
    """Kalker's flexibilities L1, L2, L3 (m³/N) of the simplified theory for semi-axes a (rolling), b (m).

    L1 = 8a/(3 G C11), L2 = 8a/(3 G C22), L3 = π a √(a/b)/(4 G C23) (Kalker 1982; CONTACT ``simpflex``).

    Raises
    ------
    ValueError
        a, b, G not positive; ν outside [0, ½]; a/b outside Kalker's table (0.1–10).
    """
    a, b, G = (finite(n, v, positive=True) for n, v in (("a", a), ("b", b), ("G", G)))
    c11, c22, c23, _ = kalker_coefficients(a / b, poisson("nu", nu))
    return 8.0 * a / (3.0 * G * c11), 8.0 * a / (3.0 * G * c22), math.pi * a * math.sqrt(a / b) / (4.0 * G * c23)


def fastsim(
    xi_x: np.ndarray | float,
    xi_y: np.ndarray | float,
    xi_sp: np.ndarray | float,
    a: np.ndarray | float,
    b: np.ndarray | float,
    N: np.ndarray | float,
    mu: np.ndarray | float,
    G: float | None = None,
    nu: float | None = None,
    *,
    flexibilities: tuple[np.ndarray | float, np.ndarray | float, np.ndarray | float] | None = None,
    n_x: int = DEFAULT_N_X,
    n_y: int = DEFAULT_N_Y,
    bound: Bound = "parabolic",
    tractions: bool = False,
) -> FastsimResult:
    """Tangential forces of steady rolling by FASTSIM (module docstring).

    Parameters
    ----------
    xi_x, xi_y : array_like
        Longitudinal and lateral creepage (dimensionless).
    xi_sp : array_like
        Spin creepage, 1/m.
    a, b : array_like
        Semi-axes of the contact ellipse along the rolling (x) and lateral (y) directions, m.
    N : array_like
        Normal load, N (> 0).
    mu : array_like
        Coefficient of friction (> 0).
    G, nu : float
        Shear modulus (Pa) and Poisson's ratio; they give the flexibilities through Kalker's C11, C22, C23.
        Not needed when ``flexibilities`` is given.
    flexibilities : (L1, L2, L3), optional
        Flexibilities in m³/N (array_like, broadcast with the rest), instead of Kalker's.
    n_x, n_y : int
        Steps per strip and number of strips (≥ 2 each).
    bound : {"parabolic", "elliptic"}
        Traction bound μ p_n with Kalker's parabolic or Hertz's elliptic pressure.
    tractions : bool
        Also return node coordinates, tractions and the slip flags.

    All array inputs broadcast to one shape ``S``; forces have shape ``S``, distributions ``S + (n_y, n_x)``.

    Raises
    ------
    ValueError
        Non-finite inputs, non-positive a, b, N, μ, G or flexibilities, ν outside [0, ½], a/b outside Kalker's
        table, an unknown ``bound``, grids smaller than 2, neither or both of (G, ν) and ``flexibilities``.
    """
    if bound not in BOUNDS:
        raise ValueError(f"bound: unknown {bound!r}; choose one of {', '.join(BOUNDS)}")
    for name, n in (("n_x", n_x), ("n_y", n_y)):
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 2:
            raise ValueError(f"{name}: must be an integer >= 2, got {n!r}")
    xx, xy, xs = (real_array(n, v) for n, v in (("xi_x", xi_x), ("xi_y", xi_y), ("xi_sp", xi_sp)))
    aa, bb, NN, mm = (real_array(n, v) for n, v in (("a", a), ("b", b), ("N", N), ("mu", mu)))
    for name, arr in (("a", aa), ("b", bb), ("N", NN), ("mu", mm)):
        if np.any(arr <= 0.0):
            raise ValueError(f"{name}: must be > 0")
    if flexibilities is None:
        if G is None or nu is None:
            raise ValueError("G, nu: give the shear modulus and Poisson's ratio, or flexibilities=(L1, L2, L3)")
        Gv, nuv = finite("G", G, positive=True), poisson("nu", nu)
        ab, bb_ = np.broadcast_arrays(aa, bb)
        flex = np.vectorize(lambda p, q: fastsim_flexibilities(p, q, Gv, nuv), otypes=[float] * 3)(ab, bb_)
        L1, L2, L3 = (np.asarray(f, dtype=float) for f in flex)
    else:
        if G is not None or nu is not None:
            raise ValueError("flexibilities: give either (G, nu) or flexibilities=(L1, L2, L3), not both")
        if len(flexibilities) != 3:
            raise ValueError("flexibilities: give three values (L1, L2, L3) in m^3/N")
        L1, L2, L3 = (real_array(f"flexibilities[{i}]", v) for i, v in enumerate(flexibilities))
        if any(np.any(L <= 0.0) for L in (L1, L2, L3)):
            raise ValueError("flexibilities: must be > 0 (m^3/N)")
    try:
        xx, xy, xs, aa, bb, NN, mm, L1, L2, L3 = np.broadcast_arrays(xx, xy, xs, aa, bb, NN, mm, L1, L2, L3)
    except ValueError as exc:
        raise ValueError(f"xi_x, xi_y, xi_sp, a, b, N, mu, flexibilities: shapes do not broadcast ({exc})") from None

    e = (...,) + (None,)  # append the strip axis
    t = -1.0 + (2.0 * np.arange(n_y) + 1.0) / n_y  # strip centres y/b (midpoint rule)
    y = bb[e] * t  # S + (n_y,)
    half = aa[e] * np.sqrt(1.0 - t * t)  # a(y), half-length of each strip
    dx = 2.0 * half / n_x
    dy = 2.0 * bb / n_y  # S

    # element centres x_k = a(y) − (k − ½) dx, k = 1 … n_x: the midpoint rule along x and across strips
    xc = half[..., None] - dx[..., None] * (np.arange(n_x) + 0.5)  # S + (n_y, n_x)
    rho2 = np.clip(1.0 - (xc / aa[..., None, None]) ** 2 - t[:, None] ** 2, 0.0, None)
    shape = rho2 if bound == "parabolic" else np.sqrt(rho2)
    scale = NN / (np.sum(np.sum(shape, axis=-1) * dx, axis=-1) * dy)  # discrete normal load = N exactly
    g = (mm * scale)[..., None, None] * shape  # traction bound at the element centres, Pa

    rate_x = -(xx[e] / L1[e] - xs[e] * y / L3[e])  # dp_x per unit travel towards −x, S + (n_y,)
    px = np.zeros(y.shape)
    py = np.zeros(y.shape)
    fx = np.zeros(y.shape)
    fy = np.zeros(y.shape)
    mz = np.zeros(y.shape)
    if tractions:
        PX = np.zeros(xc.shape)
        PY = np.zeros(xc.shape)
        SL = np.zeros(xc.shape, dtype=bool)
    for k in range(n_x):
        step = 0.5 * dx if k == 0 else dx  # leading edge -> first centre, then centre -> centre
        x_mid = half - (k + 0.5) * dx + 0.5 * step  # midpoint of the step: exact for the linear rigid slip
        px = px + step * rate_x
        py = py - step * (xy[e] / L2[e] + xs[e] * x_mid / L3[e])
        bound_k = g[..., k]
        mag = np.hypot(px, py)
        over = mag > bound_k
        if np.any(over):
            f = np.where(over, bound_k / np.where(over, mag, 1.0), 1.0)
            px, py = px * f, py * f
        fx += px
        fy += py
        mz += xc[..., k] * py - y * px
        if tractions:
            PX[..., k], PY[..., k], SL[..., k] = px, py, over
    Fx = np.sum(fx * dx, axis=-1) * dy
    Fy = np.sum(fy * dx, axis=-1) * dy
    Mz = np.sum(mz * dx, axis=-1) * dy
    if not tractions:
        return FastsimResult(Fx, Fy, Mz)
    yy = np.broadcast_to(y[..., None], xc.shape).copy()
    return FastsimResult(Fx, Fy, Mz, xc, yy, PX, PY, SL)


__all__ = ["BOUNDS", "DEFAULT_N_X", "DEFAULT_N_Y", "FastsimResult", "fastsim", "fastsim_flexibilities"]
