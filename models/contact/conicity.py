"""Equivalent conicity tan γe from a rolling-radius-difference table (EN 15302 integral method).

Beyond the thesis, which takes λ as given (4.5)–(4.6).  Conventions:

* ``y`` — wheelset lateral displacement, m, positive towards the **left** rail (EN 15302's usual sign);
* ``delta_r`` — Δr(y) = r_l − r_r, m (left minus right rolling radius), so a restoring pair has
  Δr > 0 for y > 0.  A linear pair of conicity λ has Δr = 2λy.  (In the thesis's coordinate v,
  positive to the right, Δr = r_l − r_r = −2λv by (4.5)–(4.6): the same law with y = −v.)

Method.  The kinematic (Klingel) wheelset rolling without slip along the track coordinate x obeys

    y'' = −Δr(y) / (2 e0 r0)

(yaw ψ = y', ψ' = −Δr/(2 e0 r0)).  Δr is interpolated linearly between the table points.  The
oscillation of amplitude ŷ is the periodic orbit whose turning points y_min < y_max (about the bottom
of the potential well) satisfy y_max − y_min = 2ŷ and lie on one energy level, F(y_min) = F(y_max) with F' = Δr; for
an odd Δr they are ±ŷ.  Its wavelength L = 2 ∫ dy / √((F(y_max) − F(y)) / (e0 r0)) is evaluated
segment by segment (Gauss–Legendre in the angle y = y_c + h sin φ, which removes the turning-point
singularities), and Klingel's formula L = 2π √(r0 e0 / tan γe) gives

    tan γe = e0 r0 (2π / L)².

The result does not depend on r0 and e0 (L scales with √(e0 r0)); they are accepted for clarity.

Which orbit.  The orbit of amplitude ŷ is the connected piece {F ≤ E} around the bottom of the well of
F (the least F over the centre region where Δr changes sign) whose width is 2ŷ; E is found by root
finding on that width, which grows with E.  This needs no single zero of Δr: it holds for a flat centre
(Δr = 0 on an interval) and for measured tables whose Δr crosses zero several times in the noise.

Flat centre (Δr = 0 for |y| ≤ d, Δr = 2λ(y ∓ d) beyond; EN 15302 case E4 has d = 1.7 mm).  Let
ω² = λ/(e0 r0).  For ŷ > d the periodic solution is: outside the plateau, y − d obeys y'' = −ω²(y − d),
a harmonic arc y = d + (ŷ − d) cos ω(x − x0) from the turning point ŷ back to the edge d, which takes
a quarter period π/(2ω) and reaches the edge with slope y' = −ω(ŷ − d); on the plateau Δr = 0, so the
yaw ψ = y' stays constant and the wheelset crosses the width 2d in 2d/(ω(ŷ − d)); the other side is the
mirror image.  One wavelength has two arcs (2 × π/ω) and two crossings:

    L = 2π/ω + 4d/(ω(ŷ − d)),   tan γe = e0 r0 (2π/L)² = λ π² / (π + 2d/(ŷ − d))².

For ŷ ≤ d there is no restoring within the orbit (no periodic solution with finite wavelength: the
wavelength tends to infinity as ŷ → d⁺), and tan γe = 0, continuously.  The quadrature above
reproduces this closed form (the plateau is a "core" piece where F(y_max) − F(y) is constant).

Measured tables.  Measured Δr carries noise, so near a flat centre it crosses zero several times
(CEN/TR 17792 discusses noise, smoothing and plausibility of measured Δr).  The integral method is
robust to it because F = ∫Δr averages the noise; what it cannot resolve is an orbit held in place by
the noise itself.  So (i) the sign check ignores values within a noise band about zero (given as
``noise``, or estimated from the table: :func:`noise_level`), (ii) an amplitude whose orbit would be
held, at either turning point, by a restoring Δr within that band gives tan γe = 0 (its noise-free
value for a flat centre), and (iii) an amplitude whose orbit would have to end on a local maximum of F
(a noise hump) has an infinite wavelength, tan γe = 0.  Genuinely ambiguous tables — Δr changing sign
beyond the noise band more than once (two stable equilibria) — are refused naming ``delta_r``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from railopt.models.validation import number as finite
from railopt.models.validation import positive

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
NOISE_FRACTION = 1e-3  # the default noise band about Δr = 0 is at least this fraction of max|Δr| in the table
NOISE_SIGMAS = 4.0  # ... and at least this many times the table's own noise level (:func:`noise_level`)


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
    """F(y) = ∫ Δr dy for piecewise-linear Δr, exact (piecewise quadratic), with F(y[origin]) = 0.

    The cumulative integral runs outwards from the node ``origin`` (the bottom of the well): values
    near the bottom are then small and exact to their own precision, not differences of large sums.
    """

    def __init__(self, y: np.ndarray, d: np.ndarray, origin: int = 0) -> None:
        self.y, self.d = y, d
        self.s = np.diff(d) / np.diff(y)
        trap = 0.5 * (d[1:] + d[:-1]) * np.diff(y)
        self.c = np.zeros(y.size)
        self.c[origin + 1:] = np.cumsum(trap[origin:])
        self.c[:origin] = -np.cumsum(trap[:origin][::-1])[::-1]

    def seg(self, x: np.ndarray | float) -> np.ndarray:
        return np.clip(np.searchsorted(self.y, x, side="right") - 1, 0, self.y.size - 2)

    def dr(self, x: np.ndarray | float) -> np.ndarray:
        i = self.seg(x)
        return self.d[i] + self.s[i] * (np.asarray(x) - self.y[i])

    def F(self, x: np.ndarray | float) -> np.ndarray:
        i = self.seg(x)
        t = np.asarray(x) - self.y[i]
        return self.c[i] + self.d[i] * t + 0.5 * self.s[i] * t * t

    def seg_max(self, i: int, lo: float, hi: float) -> float:
        """Largest F on [lo, hi] ⊂ segment i (ends, or the inside point where Δr = 0)."""
        best = max(float(self.F_in(i, lo)), float(self.F_in(i, hi)))
        if self.s[i] < 0.0:  # Δr falls through zero: F has its maximum there
            t = -self.d[i] / self.s[i]
            if lo < self.y[i] + t < hi:
                best = max(best, float(self.F_in(i, self.y[i] + t)))
        return best

    def F_in(self, i: int, x: float) -> float:
        t = x - self.y[i]
        return self.c[i] + self.d[i] * t + 0.5 * self.s[i] * t * t

    def crossing(self, i: int, level: float, lo: float, hi: float, first: bool) -> float:
        """The first (or last) y in [lo, hi] ⊂ segment i where F reaches ``level`` (F(y) = level)."""
        a, b, c = 0.5 * self.s[i], self.d[i], self.c[i] - level  # F − level = a t² + b t + c, t = y − y_i
        if a == 0.0:
            roots = [-c / b] if b != 0.0 else []
        else:
            disc = max(b * b - 4.0 * a * c, 0.0)
            q = -0.5 * (b + math.copysign(math.sqrt(disc), b if b != 0.0 else 1.0))
            roots = [q / a, c / q] if q != 0.0 else [0.0]
        t_lo, t_hi = lo - self.y[i], hi - self.y[i]
        slack = 1e-12 * max(t_hi - t_lo, abs(t_lo), abs(t_hi))
        inside = [min(max(r, t_lo), t_hi) for r in roots if t_lo - slack <= r <= t_hi + slack]
        if not inside:  # round-off: the level is reached at the end nearest to it
            inside = [t_hi if abs(self.F_in(i, hi) - level) < abs(self.F_in(i, lo) - level) else t_lo]
        return float(self.y[i] + (min(inside) if first else max(inside)))


def _signs(y: np.ndarray, d: np.ndarray, noise: float) -> tuple[int, int]:
    """Check the sign pattern of Δr; return (last node clearly < 0, first node clearly > 0).

    Values within ±``noise`` of zero count as zero: a measured table may cross zero several times in
    its flat centre.  Outside that band Δr must be negative on the left, positive on the right.
    """
    neg, pos = d < -noise, d > noise
    if not pos.any() or not neg.any():
        raise ValueError("delta_r: must change sign (negative for small y, positive for large y)")
    last_neg = int(np.nonzero(neg)[0][-1])
    first_pos = int(np.nonzero(pos)[0][0])
    if first_pos < last_neg:
        raise ValueError(
            f"delta_r: must change sign exactly once, from negative to positive (beyond the noise band ±{noise:.3g} m:"
            f" Δr > 0 at y = {y[first_pos]:.6g} m but < 0 at y = {y[last_neg]:.6g} m); two equilibria are ambiguous"
        )
    return last_neg, first_pos


def noise_level(y: np.ndarray, delta_r: np.ndarray) -> float:
    """Robust estimate σ̂ (m) of white measurement noise in a Δr table.

    Each inner value is compared with the straight line through its two neighbours; for independent
    noise of standard deviation σ the residual has standard deviation σ √(1 + (h₋² + h₊²)/(h₋ + h₊)²)
    (√1.5 σ on a uniform grid), and the median absolute residual / 0.6745 estimates that without being
    moved by the few kinks of a clean piecewise-linear or smooth table (whose residuals are zero or tiny).
    """
    y, d = _table(y, delta_r)
    if y.size < 3:
        return 0.0
    hm, hp = np.diff(y)[:-1], np.diff(y)[1:]
    resid = d[1:-1] - (d[:-2] * hp + d[2:] * hm) / (hm + hp)
    gain = np.sqrt(1.0 + (hm**2 + hp**2) / (hm + hp) ** 2)
    return float(np.median(np.abs(resid) / gain) / 0.6745)


def _noise(y: np.ndarray, d: np.ndarray, noise: float | None) -> tuple[float, float]:
    """(band for the sign check, band within which a restoring Δr is indistinguishable from noise), m."""
    if noise is None:
        band = NOISE_SIGMAS * noise_level(y, d)
        return max(band, NOISE_FRACTION * float(np.max(np.abs(d)))), band
    value = finite("noise", noise)
    if value < 0.0:
        raise ValueError(f"noise: must be ≥ 0, got {value}")
    return value, value


class _Orbit:
    """The periodic kinematic orbit of amplitude ŷ on one energy level (see the module doc)."""

    def __init__(self, y: np.ndarray, d: np.ndarray, noise: float | None) -> None:
        tol, self.flat = _noise(y, d, noise)
        lo, hi = _signs(y, d, tol)
        # the bottom of the well: the least F over the centre band (nodes and inside points where Δr = 0)
        p0 = _Potential(y, d, lo)
        cands = [float(v) for v in y[lo:hi + 1]]
        for i in range(lo, hi):
            if p0.s[i] > 0.0 and y[i] < y[i] - d[i] / p0.s[i] < y[i + 1]:
                cands.append(float(y[i] - d[i] / p0.s[i]))
        values = [float(p0.F(c)) for c in cands]
        m = cands[int(np.argmin(values))]
        origin = int(np.clip(np.searchsorted(y, m), 0, y.size - 1))
        self.p = _Potential(y, d, origin)
        self.m = m
        self.f_min = float(self.p.F(m))
        self.y = y
        self.i_m = int(self.p.seg(m))

    def right(self, level: float) -> float | None:
        """inf{y ≥ m : F(y) > level}; None beyond the table."""
        p, y = self.p, self.y
        for i in range(self.i_m, y.size - 1):
            lo = max(float(y[i]), self.m)
            if p.seg_max(i, lo, float(y[i + 1])) > level:
                return p.crossing(i, level, lo, float(y[i + 1]), first=True)
        return None

    def left(self, level: float) -> float | None:
        """sup{y ≤ m : F(y) > level}; None beyond the table."""
        p, y = self.p, self.y
        for i in range(self.i_m, -1, -1):
            hi = min(float(y[i + 1]), self.m)
            if hi <= y[i]:
                continue
            if p.seg_max(i, float(y[i]), hi) > level:
                return p.crossing(i, level, float(y[i]), hi, first=False)
        return None

    def width(self, level: float) -> float:
        lo, hi = self.left(level), self.right(level)
        return math.inf if lo is None or hi is None else hi - lo

    def turning_points(self, amplitude: float) -> tuple[float, float] | None:
        """(y_min, y_max) with F(y_min) = F(y_max), y_max − y_min = 2ŷ; None: no oscillation (tan γe = 0)."""
        p, y = self.p, self.y
        left = max(p.seg_max(i, float(y[i]), min(float(y[i + 1]), self.m)) for i in range(self.i_m + 1)
                   if y[i] < self.m or i == self.i_m)
        right = max(p.seg_max(i, max(float(y[i]), self.m), float(y[i + 1])) for i in range(self.i_m, y.size - 1))
        cap = min(left, right)  # above it the well spills over an end of the table
        target = 2.0 * amplitude
        if self.width(self.f_min) >= target:  # inside the flat centre: no restoring, no oscillation
            return None
        top = np.nextafter(cap, -math.inf)
        if not self.width(top) >= target or not math.isfinite(self.width(top)):
            largest = 0.5 * self.width(top) if math.isfinite(self.width(top)) else 0.0
            raise ValueError(f"amplitude: {amplitude} m needs a wider table (largest amplitude the table supports: "
                             f"{largest:.6g} m)")
        level = brentq(lambda e: self.width(e) - target, self.f_min, top, xtol=1e-300, rtol=4 * np.finfo(float).eps,
                       maxiter=500)
        lo, hi = self.left(level), self.right(level)
        if abs((hi - lo) - target) > 1e-9 * target:
            # the amplitude falls where the orbit just reaches a local maximum of F (a noise hump in the flat
            # centre): the wheelset creeps over it in infinite time, the wavelength is infinite
            return None
        if min(float(self.p.dr(hi)), -float(self.p.dr(lo))) <= self.flat:
            # the restoring Δr at a turning point is within the noise band: an orbit (partly) held by the noise
            # of a flat centre, not by the profiles (its noise-free value is 0)
            return None
        return lo, hi


def turning_points(y: np.ndarray, delta_r: np.ndarray, amplitude: float,
                   noise: float | None = None) -> tuple[float, float]:
    """(y_min, y_max), m, of the kinematic oscillation of amplitude ``amplitude`` (see the module doc).

    Raises
    ------
    ValueError
        Naming ``y``, ``delta_r``, ``noise`` or ``amplitude`` (as :func:`equivalent_conicity`), and naming
        ``amplitude`` when it lies within the flat centre of Δr, where there is no oscillation.
    """
    y, d = _table(y, delta_r)
    a = positive("amplitude", amplitude)
    ends = _Orbit(y, d, noise).turning_points(a)
    if ends is None:
        raise ValueError(f"amplitude: {a} m lies within the flat centre of Δr (no restoring): no kinematic "
                         "oscillation of that amplitude (tan γe = 0, wavelength infinite)")
    return ends


def kinematic_wavelength(
    y: np.ndarray, delta_r: np.ndarray, amplitude: float, r0: float = 0.46, e0: float = 0.75,
    noise: float | None = None,
) -> float:
    """Wavelength L (m) of the kinematic oscillation y'' = −Δr(y)/(2 e0 r0) with amplitude ŷ; inf in a flat centre."""
    r0 = positive("r0", r0)
    e0 = positive("e0", e0)
    y, d = _table(y, delta_r)
    orbit = _Orbit(y, d, noise)
    ends = orbit.turning_points(positive("amplitude", amplitude))
    if ends is None:
        return math.inf
    ymin, ymax = ends
    p = orbit.p
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
    gap = f_max - p.F(yy)  # F(y_max) − F(y) > 0 inside the orbit
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
    with np.errstate(divide="ignore", invalid="ignore"):
        integrand[core] = h * c[core] / np.sqrt(gap[core] / (e0 * r0))
        # top: gap = (y_max − y)(Δr(y) + Δr(y_max))/2, y_max − y = h c²/(1 + s)
        d_top = dr_y[top] + float(p.dr(ymax))
        integrand[top] = np.sqrt(2.0 * h * (1.0 + s[top]) * e0 * r0 / d_top)
        # bottom: gap = −(y − y_min)(Δr(y) + Δr(y_min))/2, y − y_min = h c²/(1 − s)
        d_bot = -(dr_y[bottom] + float(p.dr(ymin)))
        integrand[bottom] = np.sqrt(2.0 * h * (1.0 - s[bottom]) * e0 * r0 / d_bot)
    if not np.all(np.isfinite(integrand)):  # not expected: inside the orbit F < F(y_max) by construction
        raise ValueError("delta_r: the oscillation reaches a region where Δr has the wrong sign")
    return 2.0 * float(np.sum(w * integrand))


def equivalent_conicity(
    y: np.ndarray, delta_r: np.ndarray, amplitude: float, r0: float = 0.46, e0: float = 0.75,
    noise: float | None = None,
) -> float:
    """Equivalent conicity tan γe (dimensionless), EN 15302 integral method.

    Parameters
    ----------
    y : array_like
        Lateral displacements of the table, m, strictly increasing, positive to the left.
    delta_r : array_like
        Rolling-radius difference Δr(y) = r_l − r_r at ``y``, m (analytic or measured).
    amplitude : float
        Peak lateral wheelset amplitude ŷ, m (half the peak-to-peak excursion).
    r0, e0 : float
        Nominal rolling radius and half contact-point spacing, m (the result is independent of them).
    noise : float, optional
        Half-width, m, of the band about Δr = 0 within which sign changes are taken as measurement noise
        (default: the larger of :data:`NOISE_SIGMAS` × :func:`noise_level` of the table and
        :data:`NOISE_FRACTION` × max|Δr|).  It only decides whether the table has one equilibrium region
        and where its bottom is sought; the wavelength is always integrated from the table as given.

    Returns
    -------
    float
        tan γe = e0 r0 (2π/L)², L the kinematic wavelength of amplitude ŷ; 0 when the orbit of that
        amplitude would lie within the flat centre of Δr (Δr = 0 for |y| ≤ d: ŷ ≤ d) or would have to
        stop on a local maximum of F (infinite wavelength).

    Raises
    ------
    ValueError
        Naming ``y``, ``delta_r``, ``amplitude``, ``noise``, ``r0`` or ``e0``: non-monotone or non-finite
        tables, Δr that is not negative on the left and positive on the right (beyond the noise band) with
        one sign change, or an amplitude the table does not cover.
    """
    r0 = positive("r0", r0)
    e0 = positive("e0", e0)
    L = kinematic_wavelength(y, delta_r, amplitude, r0=r0, e0=e0, noise=noise)
    return 0.0 if math.isinf(L) else e0 * r0 * (2.0 * math.pi / L) ** 2


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


__all__ = [
    "NOISE_FRACTION", "NOISE_SIGMAS", "equivalent_conicity", "kinematic_wavelength", "linear_delta_r_table",
    "noise_level", "turning_points",
]
