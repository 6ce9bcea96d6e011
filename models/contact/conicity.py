"""Equivalent conicity tan γe from a rolling-radius-difference table (EN 15302 integral method).

Beyond the thesis, which takes λ as given (4.5)–(4.6).  Conventions:

* ``y`` — wheelset lateral displacement, m, positive towards the **left** rail (EN 15302's usual sign);
* ``delta_r`` — Δr(y) = r_l − r_r, m (left minus right rolling radius), so a restoring pair has
  Δr > 0 for y > 0.  A linear pair of conicity λ has Δr = 2λy.  (In the thesis's coordinate v,
  positive to the right, Δr = r_l − r_r = −2λv by (4.5)–(4.6): the same law with y = −v.)

Method.  The kinematic (Klingel) wheelset rolling without slip along the track coordinate x obeys

    y'' = −Δr(y) / (2 e0 r0)

(yaw ψ = y', ψ' = −Δr/(2 e0 r0)).  Δr is interpolated linearly between the table points.  The
oscillation of amplitude ŷ is the periodic orbit whose turning points y_min < y* < y_max (y* the zero
of Δr) satisfy y_max − y_min = 2ŷ and lie on one energy level, F(y_min) = F(y_max) with F' = Δr; for
an odd Δr they are ±ŷ.  Its wavelength L = 2 ∫ dy / √((F(y_max) − F(y)) / (e0 r0)) is evaluated
segment by segment (Gauss–Legendre in the angle y = y_c + h sin φ, which removes the turning-point
singularities), and Klingel's formula L = 2π √(r0 e0 / tan γe) gives

    tan γe = e0 r0 (2π / L)².

The result does not depend on r0 and e0 (L scales with √(e0 r0)); they are accepted for clarity.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from railopt.models.validation import number as finite
from railopt.models.validation import positive

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)


def _table(y: np.ndarray, delta_r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError("y: must be a 1-D array of numbers") from exc
    try:
        d = np.asarray(delta_r, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError("delta_r: must be a 1-D array of numbers") from exc
    if y.ndim != 1 or y.size < 2:
        raise ValueError("y: must be a 1-D array with at least two points")
    if d.shape != y.shape:
        raise ValueError(f"delta_r: shape {d.shape} does not match y {y.shape}")
    if not np.all(np.isfinite(y)):
        raise ValueError("y: contains NaN or inf")
    if not np.all(np.isfinite(d)):
        raise ValueError("delta_r: contains NaN or inf")
    if not np.all(np.diff(y) > 0.0):
        raise ValueError("y: must be strictly increasing")
    return y, d


class _Potential:
    """F(y) = ∫ Δr dy for piecewise-linear Δr, exact (piecewise quadratic)."""

    def __init__(self, y: np.ndarray, d: np.ndarray) -> None:
        self.y, self.d = y, d
        self.s = np.diff(d) / np.diff(y)
        self.c = np.concatenate([[0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(y))])

    def seg(self, x: np.ndarray | float) -> np.ndarray:
        return np.clip(np.searchsorted(self.y, x, side="right") - 1, 0, self.y.size - 2)

    def dr(self, x: np.ndarray | float) -> np.ndarray:
        i = self.seg(x)
        return self.d[i] + self.s[i] * (np.asarray(x) - self.y[i])

    def F(self, x: np.ndarray | float) -> np.ndarray:
        i = self.seg(x)
        t = np.asarray(x) - self.y[i]
        return self.c[i] + self.d[i] * t + 0.5 * self.s[i] * t * t


def _equilibrium(p: _Potential) -> float:
    """The single zero y* of Δr with Δr < 0 left of it and > 0 right of it."""
    d, y = p.d, p.y
    pos, neg = d > 0.0, d < 0.0
    if not pos.any() or not neg.any():
        raise ValueError("delta_r: must change sign (negative for small y, positive for large y)")
    last_neg = int(np.nonzero(neg)[0][-1])
    first_pos = int(np.nonzero(pos)[0][0])
    if first_pos < last_neg or np.any(neg[first_pos:]) or np.any(pos[:last_neg]):
        raise ValueError("delta_r: must change sign exactly once, from negative to positive")
    if first_pos - last_neg == 1:
        i = last_neg
        return float(y[i] - d[i] * (y[i + 1] - y[i]) / (d[i + 1] - d[i]))
    return float(0.5 * (y[last_neg + 1] + y[first_pos - 1]))  # Δr = 0 on a plateau: its mid-point


def turning_points(y: np.ndarray, delta_r: np.ndarray, amplitude: float) -> tuple[float, float]:
    """(y_min, y_max), m, of the kinematic oscillation of amplitude ``amplitude`` (see module doc)."""
    y, d = _table(y, delta_r)
    a = positive("amplitude", amplitude)
    p = _Potential(y, d)
    ys = _equilibrium(p)
    f_left, f_right = float(p.F(y[0])), float(p.F(y[-1]))
    f_star = float(p.F(ys))

    def ymin_of(level: float) -> float:
        if level <= f_star:
            return ys
        if level >= f_left:  # the left end of the table (round-off for symmetric tables)
            return float(y[0])
        return brentq(lambda t: float(p.F(t)) - level, y[0], ys, xtol=1e-16, rtol=4 * np.finfo(float).eps)

    level_cap = min(f_left, f_right)
    if level_cap <= f_star:
        raise ValueError("amplitude: the table has no room for an oscillation about Δr = 0")
    if f_right <= f_left:
        ymax_cap = float(y[-1])
    else:
        ymax_cap = brentq(lambda t: float(p.F(t)) - level_cap, ys, y[-1], xtol=1e-16, rtol=4 * np.finfo(float).eps)

    def excess(ymax: float) -> float:
        return ymax - ymin_of(float(p.F(ymax))) - 2.0 * a

    if excess(ymax_cap) < 0.0:
        raise ValueError(
            f"amplitude: {a} m needs a wider table (largest amplitude the table supports: "
            f"{0.5 * (ymax_cap - ymin_of(float(p.F(ymax_cap)))):.6g} m)"
        )
    ymax = brentq(excess, ys, ymax_cap, xtol=1e-16, rtol=4 * np.finfo(float).eps)
    return ymin_of(float(p.F(ymax))), ymax


def kinematic_wavelength(
    y: np.ndarray, delta_r: np.ndarray, amplitude: float, r0: float = 0.46, e0: float = 0.75
) -> float:
    """Wavelength L (m) of the kinematic oscillation y'' = −Δr(y)/(2 e0 r0) with amplitude ŷ."""
    r0 = positive("r0", r0)
    e0 = positive("e0", e0)
    y, d = _table(y, delta_r)
    ymin, ymax = turning_points(y, d, amplitude)
    p = _Potential(y, d)
    yc, h = 0.5 * (ymin + ymax), 0.5 * (ymax - ymin)
    # table nodes strictly inside the orbit; nodes within 1e-9 h of a turning point are dropped (the turning
    # point is then treated as lying on the node, an error of that relative size in a tiny end piece)
    tol = 1e-9 * h
    inner = y[(y > ymin + tol) & (y < ymax - tol)]
    phis = np.concatenate([[-0.5 * math.pi], np.arcsin(np.clip((inner - yc) / h, -1.0, 1.0)), [0.5 * math.pi]])
    phis = np.unique(phis)
    lo, hi = phis[:-1], phis[1:]
    phi = 0.5 * (hi - lo)[:, None] * _GL_X[None, :] + 0.5 * (hi + lo)[:, None]
    w = 0.5 * (hi - lo)[:, None] * _GL_W[None, :]
    s, c = np.sin(phi), np.cos(phi)
    yy = yc + h * s
    f_max = float(p.F(ymax))
    gap = f_max - p.F(yy)  # F(y_max) − F(y) ≥ 0
    # Near the turning points use the exact local trapezoid (Δr linear within one segment), written so that
    # the factor cos²φ cancels analytically: no loss of precision where the gap vanishes.
    dr_y = p.dr(yy)
    # the first and the last φ-interval end on a turning point and lie within one table segment
    # (a single interval holds both turning points: split it at φ = 0)
    row = np.arange(phi.shape[0])[:, None] * np.ones_like(phi, dtype=int)
    n_int = phi.shape[0]
    top = row == n_int - 1
    bottom = row == 0
    if n_int == 1:
        top, bottom = s > 0.0, s <= 0.0
    integrand = np.empty_like(phi)
    core = ~(top | bottom)
    integrand[core] = h * c[core] / np.sqrt(gap[core] / (e0 * r0))
    # top: gap = (y_max − y)(Δr(y) + Δr(y_max))/2, y_max − y = h c²/(1 + s)
    d_top = dr_y[top] + float(p.dr(ymax))
    integrand[top] = np.sqrt(2.0 * h * (1.0 + s[top]) * e0 * r0 / d_top)
    # bottom: gap = −(y − y_min)(Δr(y) + Δr(y_min))/2, y − y_min = h c²/(1 − s)
    d_bot = -(dr_y[bottom] + float(p.dr(ymin)))
    integrand[bottom] = np.sqrt(2.0 * h * (1.0 - s[bottom]) * e0 * r0 / d_bot)
    if not np.all(np.isfinite(integrand)):
        raise ValueError("delta_r: the oscillation reaches a region where Δr has the wrong sign")
    return 2.0 * float(np.sum(w * integrand))


def equivalent_conicity(
    y: np.ndarray, delta_r: np.ndarray, amplitude: float, r0: float = 0.46, e0: float = 0.75
) -> float:
    """Equivalent conicity tan γe (dimensionless), EN 15302 integral method.

    Parameters
    ----------
    y : array_like
        Lateral displacements of the table, m, strictly increasing, positive to the left.
    delta_r : array_like
        Rolling-radius difference Δr(y) = r_l − r_r at ``y``, m.
    amplitude : float
        Peak lateral wheelset amplitude ŷ, m (half the peak-to-peak excursion).
    r0, e0 : float
        Nominal rolling radius and half contact-point spacing, m (the result is independent of them).

    Returns
    -------
    float
        tan γe = e0 r0 (2π/L)², L the kinematic wavelength of amplitude ŷ.

    Raises
    ------
    ValueError
        Naming ``y``, ``delta_r`` or ``amplitude``: non-monotone or non-finite tables, Δr without a
        single sign change, or an amplitude the table does not cover.
    """
    r0 = positive("r0", r0)
    e0 = positive("e0", e0)
    L = kinematic_wavelength(y, delta_r, amplitude, r0=r0, e0=e0)
    return e0 * r0 * (2.0 * math.pi / L) ** 2


def linear_delta_r_table(conicity: float, y_max: float = 0.012, n: int = 241) -> tuple[np.ndarray, np.ndarray]:
    """Table (y, Δr = 2λy) of a linear pair of conicity λ on [−y_max, y_max] (read-only arrays, m)."""
    lam = finite("conicity", conicity)
    if lam <= 0.0:
        raise ValueError(f"conicity: must be > 0, got {lam}")
    y_max = positive("y_max", y_max)
    if int(n) < 2:
        raise ValueError(f"n: need at least 2 points, got {n}")
    y = np.linspace(-y_max, y_max, int(n))
    d = 2.0 * lam * y
    y.setflags(write=False)
    d.setflags(write=False)
    return y, d
