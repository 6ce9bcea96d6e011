"""Response maxima f_k(x) of thesis eqs. (4.71)-(4.73) and the certified band maximum.

Thesis method (``exact=False``): f_j = |H(ω_dj)| at each damped natural frequency, with ω_dj
clipped into the band [Ω_l, Ω_u] so that every f_j stays a continuous function of the design with
a fixed count n; an overdamped mode (ω_d = 0) contributes the value at its clipped frequency.
f_l, f_u are the values at the band edges (4.72).

Exact method (``exact=True``, beyond the thesis): the band is split into n cells whose
boundaries are the midpoints between consecutive clipped ω_dj, and f_j is the maximum of |H|
over cell j.  The union of the cells is the band, so ``max_k f_k`` *is* the band maximum, and
each f_j is still continuous in the design (the maximum of a continuous function over an
interval whose ends move continuously).  Each cell maximum is found on a grid whose spacing
never exceeds ``GRID_FACTOR`` times the distance from Ω to the nearest pole s_j of H (and a
quarter period of the largest delay in F), then refined by bounded Brent maximisation between
the neighbours of the best sample.  A rational |H| cannot vary faster than the distance to its
nearest pole allows, so the sampled maximum lies in the basin of the true one; that is what
``certified`` records, together with the worst spacing ratio used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar

from railopt.models.linear_system import UNDAMPED_ROOT, LinearSystem

GRID_FACTOR = 0.25  # max grid step / distance to nearest pole
CERTIFIED_RATIO = GRID_FACTOR / (1 - GRID_FACTOR)
MIN_CELL_SAMPLES = 8
MAX_GRID_POINTS = 200_000
XATOL_REL = 1e-12


def validate_band(band: tuple[float, float]) -> tuple[float, float]:
    """Check a frequency band (rad/s): finite, 0 ≤ Ω_l < Ω_u. Errors name the field ``band``."""
    try:
        lo, hi = (float(band[0]), float(band[1]))
    except (TypeError, ValueError, IndexError) as exc:
        raise ValueError(f"band: must be a pair (lower, upper) in rad/s, got {band!r}") from exc
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise ValueError(f"band: edges must be finite, got ({lo}, {hi})")
    if lo < 0:
        raise ValueError(f"band: lower edge must be ≥ 0, got {lo}")
    if not hi > lo:
        raise ValueError(f"band: is empty or inverted, lower {lo} ≥ upper {hi}")
    return lo, hi


@dataclass(frozen=True)
class ResponseMaxima:
    """The vector f_k (4.73) with where each value was taken.

    Attributes
    ----------
    values : (n+2,) ndarray
        f_1..f_n (modes), then f_l, f_u (band edges); units of the output.
    frequencies : (n+2,) ndarray
        Forcing frequency (rad/s) at which each value was taken.
    damped_frequencies : (n,) ndarray
        Unclipped ω_dj (rad/s).
    band : (float, float)
        (Ω_l, Ω_u) in rad/s.
    exact : bool
        Whether the cell maxima of the exact method were used.
    certified : bool
        Exact method only: the grid met the spacing rule everywhere and no value was singular.
    grid_ratio : float
        Exact method only: the largest grid step / distance to the nearest pole (certified when
        ≤ CERTIFIED_RATIO).
    """

    values: np.ndarray
    frequencies: np.ndarray
    damped_frequencies: np.ndarray
    band: tuple[float, float]
    exact: bool
    certified: bool = False
    grid_ratio: float = float("nan")

    @property
    def value(self) -> float:
        """U = max_k f_k (4.74)."""
        return float(np.max(self.values))

    @property
    def argmax_frequency(self) -> float:
        """Frequency (rad/s) of the largest f_k."""
        return float(self.frequencies[int(np.argmax(self.values))])

    @property
    def labels(self) -> tuple[str, ...]:
        n = len(self.damped_frequencies)
        return tuple(f"mode {j + 1}" for j in range(n)) + ("lower edge", "upper edge")

    def to_pandas(self) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "function": self.labels,
                "value": self.values,
                "frequency_rad_s": self.frequencies,
                "frequency_hz": self.frequencies / (2 * np.pi),
            }
        )


def response_maxima(system: LinearSystem, band: tuple[float, float], exact: bool = False) -> ResponseMaxima:
    """Response maxima f_k (4.71)-(4.73) of ``system`` over ``band`` (rad/s).

    Zero damping or a singular Z(Ω) gives ``inf`` entries (never NaN), so U = +inf and an
    optimiser can carry on.
    """
    lo, hi = validate_band(band)
    wd = system.damped_frequencies()
    clipped = np.clip(wd, lo, hi)
    edges = np.array([lo, hi])
    # an undamped mode inside the band has an unbounded peak, whatever rounding makes of Z(ω_d)
    resonant = system.undamped_modes() & (wd >= lo) & (wd <= hi)
    if not exact:
        freqs = np.concatenate([clipped, edges])
        vals = _finite_or_inf(np.abs(system.frf(freqs)))
        vals[: len(wd)][resonant] = np.inf
        return ResponseMaxima(vals, freqs, wd, (lo, hi), exact=False)

    poles = system.eigenvalues()
    poles = poles[np.abs(poles.real) > UNDAMPED_ROOT * np.abs(poles)]  # their cells are inf anyway
    grid = band_grid(poles, (lo, hi), max_delay=system.forcing.max_delay, extra=clipped)
    mags = _finite_or_inf(np.abs(system.frf(grid)))
    bounds = np.concatenate([[lo], 0.5 * (clipped[1:] + clipped[:-1]), [hi]])
    cell_vals = np.empty(len(wd))
    cell_freqs = np.empty(len(wd))
    for j in range(len(wd)):
        cell_vals[j], cell_freqs[j] = _cell_maximum(system, grid, mags, bounds[j], bounds[j + 1])
    cell_vals[resonant] = np.inf
    cell_freqs[resonant] = clipped[resonant]
    edge_vals = _finite_or_inf(np.abs(system.frf(edges)))
    vals = np.concatenate([cell_vals, edge_vals])
    freqs = np.concatenate([cell_freqs, edges])
    ratio = _grid_ratio(grid, poles, system.forcing.max_delay)
    certified = bool(np.all(np.isfinite(mags)) and ratio <= CERTIFIED_RATIO * (1 + 1e-9))
    return ResponseMaxima(vals, freqs, wd, (lo, hi), exact=True, certified=certified, grid_ratio=ratio)


def _finite_or_inf(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a[~np.isfinite(a)] = np.inf
    return a


def _step_limit(omega: np.ndarray, poles: np.ndarray, max_delay: float) -> np.ndarray:
    """Largest admissible grid step at each Ω: GRID_FACTOR × distance to the nearest pole."""
    if poles.size == 0:
        return np.full(np.atleast_1d(omega).shape, np.inf)
    dist = np.min(np.abs(1j * np.atleast_1d(omega)[:, None] - poles[None, :]), axis=1)
    step = GRID_FACTOR * dist
    if max_delay > 0:
        step = np.minimum(step, GRID_FACTOR * 2 * np.pi / (4 * max_delay))
    return step


def band_grid(
    poles: np.ndarray,
    band: tuple[float, float],
    max_delay: float = 0.0,
    extra: np.ndarray | None = None,
) -> np.ndarray:
    """Adaptive frequency grid (rad/s) over ``band`` with step ≤ GRID_FACTOR · dist(iΩ, poles).

    The number of points grows with the logarithm of (band width / modal damping), so lightly
    damped modes cost little.  ``extra`` points (e.g. the clipped ω_dj) are merged in.
    """
    lo, hi = band
    floor = (hi - lo) / MAX_GRID_POINTS
    cap = (hi - lo) / (4 * MIN_CELL_SAMPLES)
    pts = [lo]
    w = lo
    while w < hi:
        step = float(_step_limit(np.array([w]), poles, max_delay)[0])
        w = w + min(max(step, floor), cap)
        pts.append(min(w, hi))
    grid = np.array(pts)
    if extra is not None:
        grid = np.union1d(grid, np.asarray(extra, dtype=float))
    return grid


def _grid_ratio(grid: np.ndarray, poles: np.ndarray, max_delay: float) -> float:
    """Worst step / (distance to the nearest pole) over the grid, taking the nearer step end.

    The distance is 1-Lipschitz in Ω, so steps of GRID_FACTOR·dist(left end) keep this ratio
    below GRID_FACTOR / (1 − GRID_FACTOR) = CERTIFIED_RATIO.
    """
    steps = np.diff(grid)
    if steps.size == 0:
        return 0.0
    limit = np.minimum(_step_limit(grid[:-1], poles, max_delay), _step_limit(grid[1:], poles, max_delay))
    with np.errstate(divide="ignore"):
        return float(np.max(GRID_FACTOR * steps / limit))


def _cell_maximum(
    system: LinearSystem, grid: np.ndarray, mags: np.ndarray, a: float, b: float
) -> tuple[float, float]:
    """Maximum of |H| over [a, b]: best grid sample, refined between its neighbours."""
    inside = np.flatnonzero((grid >= a) & (grid <= b))
    cand_w = [a, b]
    cand_f = [float(np.abs(system.frf(a))), float(np.abs(system.frf(b)))]
    if inside.size:
        k = inside[int(np.argmax(mags[inside]))]
        cand_w.append(float(grid[k]))
        cand_f.append(float(mags[k]))
        if np.isfinite(mags[k]):
            left = max(a, float(grid[max(k - 1, 0)]))
            right = min(b, float(grid[min(k + 1, len(grid) - 1)]))
            if right > left:
                res = minimize_scalar(
                    lambda w: -float(np.abs(system.frf(w))),
                    bounds=(left, right),
                    method="bounded",
                    options={"xatol": XATOL_REL * max(right, 1.0)},
                )
                cand_w.append(float(res.x))
                cand_f.append(-float(res.fun))
    cand_f = [f if np.isfinite(f) else np.inf for f in cand_f]
    i = int(np.argmax(cand_f))
    return cand_f[i], cand_w[i]
