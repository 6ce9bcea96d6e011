"""Response maxima f_k(x) of thesis eqs. (4.71)-(4.73) and the certified band maximum.

Thesis method (``exact=False``): f_j = |H(ω_dj)| at each damped natural frequency, with ω_dj
clipped into the band [Ω_l, Ω_u] so that every f_j stays a continuous function of the design with
a fixed count n; an overdamped mode (ω_d = 0) contributes the value at its clipped frequency.
f_l, f_u are the values at the band edges (4.72).

Exact method (``exact=True``, beyond the thesis): the band is split into n cells whose
boundaries are the midpoints between consecutive clipped ω_dj, and f_j is the maximum of |H|
over cell j.  The union of the cells is the band, so ``max_k f_k`` *is* the band maximum, and
each f_j is still continuous in the design.  Each cell is sampled on a grid whose step never
exceeds ``GRID_FACTOR`` times the distance from iΩ to the nearest pole of H, nor GRID_FACTOR times
a quarter period 2π/(4τ_max) of the largest declared delay in F; every sampled local maximum within 10 % of
its cell's best sample is refined between its neighbours (:func:`~railopt.models.peak_search.cell_maxima`), and
the reported value is a direct solve ``Z(Ω)X = F`` at the refined frequency.  H is sampled in pole–residue form
(O(n) per frequency) when the eigenvector matrix is well conditioned
(:data:`~railopt.models.pole_residue.CONDITION_LIMIT`), by direct solves otherwise.  Free rigid-body roots make
Z(Ω) singular to rounding near Ω = 0: below :class:`ZeroZone`'s step H is a limit model.

``certified`` means U is the band maximum to :data:`CERTIFIED_RTOL` (1e-8 relative).  It is a resolution
certificate, not an interval proof: the spacing rule held at every step, every sample was finite, every delay in F
was declared (a plain callable forcing is never certified) and every candidate was refined.  Between two poles a
rational |H| cannot rise and fall within a quarter of the distance to the nearest pole, and a delayed term cannot
within a sixteenth of its period, so each true local maximum has a sample within a few per cent of its top.  Where
that cannot be vouched for — a mode undamped to rounding (ζ ≤ 1e-12, reported as inf), a pole whose damping is
within the rounding of its eigenvalue (defective or nearly repeated pairs), a mode too soft to be told from
rigid-body motion, a delay whose grid would exceed :data:`MAX_GRID_POINTS`, a limit at 0 known less well than
1e-8 where it may be the maximum — ``certified`` is False and ``reason`` says why.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from railopt.models import kernels
from railopt.models.modal import CONDITION_LIMIT, NEUTRAL_ROOT, UNDAMPED_ROOT, growing_roots, neutral_roots
from railopt.models.peak_search import BRACKET_RTOL, cell_maxima
from railopt.models.pole_residue import forcing_arrays
from railopt.models.units import rad_s_to_hz
from railopt.models.validation import band as validate_band
from railopt.models.validation import band_arg
from railopt.records import ArrayRecord

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.parametric import MemberStack
    from railopt.models.system import LinearSystem

GRID_FACTOR = 0.25  # max grid step / distance to nearest pole
CERTIFIED_RATIO = GRID_FACTOR / (1 - GRID_FACTOR)
POLE_STEP = 0.2  # step in u of the per-pole grids Ω = ω_k + σ_k sinh(u); keeps step/dist ≤ 0.222
MIN_CELL_SAMPLES = 8
MAX_GRID_POINTS = 200_000
CONSISTENCY_RTOL = 1e-6  # pole–residue vs direct value at a refined maximum; beyond it, redo by direct solves
POLISH_RTOL = 1e-12  # beyond it (but within CONSISTENCY_RTOL), that maximiser is located again on direct solves

__all__ = ["CERTIFIED_RTOL", "ResponseMaxima", "ZeroZone", "all_response_maxima", "band_grid",
           "batch_response_maxima", "peak",
           "response_maxima", "validate_band", "zero_zone"]


@dataclass(frozen=True, eq=False, repr=False)
class ResponseMaxima(ArrayRecord):
    """The vector f_k (4.73) with where each value was taken; array-like (``np.asarray(rm)``
    gives ``values``).

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
        Exact method only: U is the band maximum to CERTIFIED_RTOL (1e-8 relative) — the grid met the spacing
        rule everywhere, no sample was singular, the forcing declared its delays and every pole was resolved
        (see the module docstring; ``reason`` says why not).
    grid_ratio : float
        Exact method only: the largest grid step / distance to the nearest pole (certified when
        ≤ CERTIFIED_RATIO).
    output : str
        Name of the output.
    evaluation : str
        How H was sampled: ``"thesis"`` (n+2 direct solves), ``"pole-residue"`` or ``"direct"``.
    grid_points : int
        Exact method only: number of frequencies sampled.
    reason : str
        Why the values are not certified ("" when they are, or for the thesis method on a stable system);
        for an unstable system it names the growing root and every value is +inf (no steady state exists).
    """

    values: np.ndarray
    frequencies: np.ndarray
    damped_frequencies: np.ndarray
    band: tuple[float, float]
    exact: bool
    certified: bool = False
    grid_ratio: float = float("nan")
    output: str = "output"
    evaluation: str = "thesis"
    grid_points: int = 0
    reason: str = ""

    @classmethod
    def _owned(cls, values: np.ndarray, frequencies: np.ndarray, damped_frequencies: np.ndarray,
               band: tuple[float, float], **fields: object) -> ResponseMaxima:
        """The record from arrays nobody else holds (fresh from a kernel): made read-only in place, not copied."""
        self = object.__new__(cls)
        values.setflags(write=False)
        frequencies.setflags(write=False)
        damped_frequencies.setflags(write=False)
        state = self.__dict__  # a frozen dataclass's fields live in __dict__ (no slots)
        state["values"], state["frequencies"], state["damped_frequencies"], state["band"] = (
            values, frequencies, damped_frequencies, band)
        for name, default in _TAIL_FIELDS:
            state[name] = fields.get(name, default)
        return self

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
        """Label of each candidate f_k: ``mode 1`` … ``mode n`` for the resonance peaks, then the two band edges."""
        n = len(self.damped_frequencies)
        return tuple(f"mode {j + 1}" for j in range(n)) + ("lower edge", "upper edge")

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return np.array(self.values, dtype=dtype)

    def __len__(self) -> int:
        return len(self.values)

    def __getitem__(self, index):
        return self.values[index]

    def __iter__(self):
        return iter(self.values)

    def __repr__(self) -> str:
        kind = ("exact, certified" if self.certified else "exact, not certified") if self.exact else "thesis"
        if self.reason:
            kind += f": {self.reason}"
        return (f"ResponseMaxima(U={self.value:.6g} at {self.argmax_frequency:.6g} rad/s, n={len(self.values)}, "
                f"output={self.output!r}, {kind}, band=({self.band[0]:g}, {self.band[1]:g}) rad/s)")

    def to_pandas(self) -> pd.DataFrame:
        """One row per f_k: function, value, frequency_rad_s, frequency_hz."""
        return pd.DataFrame(
            {
                "function": self.labels,
                "value": self.values,
                "frequency_rad_s": self.frequencies,
                "frequency_hz": rad_s_to_hz(self.frequencies),
            }
        )


# the fields after the four arrays/band, with their defaults, for ResponseMaxima._owned
_TAIL_FIELDS = tuple((f.name, f.default) for f in dataclasses.fields(ResponseMaxima)[4:])


def response_maxima(system: LinearSystem, band: object = None, *, band_hz: tuple[float, float] | None = None,
                    band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                    output: str | None = None) -> ResponseMaxima:
    """Response maxima f_k (4.71)-(4.73) of one output of ``system`` over ``band`` (rad/s).

    Zero damping or a singular Z(Ω) gives ``inf`` entries (never NaN), so U = +inf and an
    optimiser can carry on.
    """
    col = system.output_index(output)
    name = system.output_names[col]
    lo, hi = band_arg(band, band_hz, band_rad_s)
    return _maxima(system, lo, hi, exact, [name], [col])[name]


def peak(system: LinearSystem, band: object = None, *, band_hz: tuple[float, float] | None = None,
         band_rad_s: tuple[float, float] | None = None, exact: bool = True, output: str | None = None) -> float:
    """``U = max_k f_k`` (4.74) of one output over ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s); ``exact=True``
    gives the certified band maximum."""
    return response_maxima(system, band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact, output=output).value


def all_response_maxima(system: LinearSystem, band: object = None, *, band_hz: tuple[float, float] | None = None,
                        band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                        outputs: list[str] | None = None) -> dict[str, ResponseMaxima]:
    """f_k of several outputs sharing one eigen-decomposition and one frequency grid; the band as
    ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s), see :func:`railopt.models.validation.band_arg`.

    Returns ``{output: ResponseMaxima}`` (n + 2 values each).  An unstable system gives +inf everywhere with the
    reason; an undamped mode in the band (ζ ≤ 1e-12) an inf entry; a lower edge below the rigid-body zone's step
    (:func:`zero_zone`) the limit model's value.  Raises ``ValueError`` naming ``band`` for a band from 0 Hz where
    an output grows without bound (free rigid-body motion), or naming an unknown output.
    """
    lo, hi = band_arg(band, band_hz, band_rad_s)
    names = list(system.output_names if outputs is None else outputs)
    return _maxima(system, lo, hi, exact, names, [system.output_index(nm) for nm in names])


def _maxima(system: LinearSystem, lo: float, hi: float, exact: bool, names: list[str],
            cols: list[int]) -> dict[str, ResponseMaxima]:
    """:func:`all_response_maxima` of a validated band (rad/s) and the outputs ``names`` (columns ``cols``)."""
    if exact:
        compiled = _certified(system, (lo, hi), names, cols)
        if compiled is not None:  # the common case: the whole exact path in one compiled call
            return compiled
        system.modal()  # one eigen-decomposition with vectors serves the roots too
    roots = system.eigenvalues()  # one sort serves ω_d, the undamped modes, the growth check and the zero limit
    modes = roots[1::2]  # = system.mode_roots()
    wd = np.abs(modes.imag)  # = system.damped_frequencies()
    clipped = np.clip(wd, lo, hi)
    edges = np.array([lo, hi])
    growing = growing_roots(roots)
    if growing.size:  # no steady state exists: never a silent number
        worst = growing[np.argmax(growing.real)]
        reason = (f"unstable: root s = {worst.real:.6g}{worst.imag:+.6g}i 1/s has Re s > 0, so no steady-state "
                  "response exists")
        freqs = np.concatenate([clipped, edges])
        return {nm: ResponseMaxima(np.full(len(freqs), np.inf), freqs, wd, (lo, hi), exact=exact, certified=False,
                                   output=nm, evaluation="unstable", reason=reason) for nm in names}
    # free rigid-body roots (s = 0) make Z(Ω) singular to rounding near 0: below the zone's step the response is
    # the limit model (its value at 0, or an error naming the band where an output grows without bound there)
    zone = zero_zone(system, hi, roots)
    if zone is not None and lo >= zone.step:
        zone = None
    near_zero = None
    if zone is not None:
        near_zero = _near_zero(system, zone, cols, lo)
        if lo == 0.0 and near_zero.growing.any():
            bad = [nm for nm, g in zip(names, near_zero.growing, strict=True) if g]
            raise ValueError(f"band: starts at 0 Hz, where the output(s) {bad} are unbounded (free rigid-body "
                             "motion: Z(0) is singular and the response grows as Ω → 0); start the band above 0")
    lo_eval = zone.step if zone is not None else lo
    edges_eval = np.array([lo_eval, hi])
    clipped_eval = np.clip(wd, lo_eval, hi)
    # an undamped mode inside the band has an unbounded peak, whatever rounding makes of Z(ω_d); the neutral roots
    # of free rigid-body motion (s ≈ 0, perhaps ±iδ by rounding) are not modes with a peak
    neutral_modes = neutral_roots(roots)[1::2]
    undamped = (np.abs(modes.real) <= UNDAMPED_ROOT * np.abs(modes)) & (modes.imag != 0) & ~neutral_modes
    resonant = undamped & (wd >= lo) & (wd <= hi)
    if not exact:
        freqs = np.concatenate([clipped, edges])
        H = _finite_or_inf(np.abs(_direct(system, np.concatenate([clipped_eval, edges_eval]), cols)))
        if near_zero is not None:  # the limit model at the lower edge (and at modes clipped to it)
            H[np.concatenate([clipped_eval, edges_eval]) == lo_eval] = near_zero.values
        out = {}
        for i, nm in enumerate(names):
            vals = H[:, i].copy()
            vals[: len(wd)][resonant] = np.inf
            out[nm] = ResponseMaxima(vals, freqs, wd, (lo, hi), exact=False, output=nm)
        return out

    modal = system.modal()
    poles = modal.s
    damped = np.abs(poles.real) > UNDAMPED_ROOT * np.abs(poles)  # the undamped poles' cells are inf anyway
    if zone is not None:  # the outputs have a finite limit at 0: the neutral poles are cancelled there
        damped &= ~neutral_roots(poles)
    poles = poles[damped]
    # cell boundaries from the band's clipping (not the zone's step, which moves with the design): the same cells
    # whatever the limit model, so a maximum on a boundary moves with the damped frequencies only
    bounds = np.concatenate([[lo_eval], np.maximum(0.5 * (clipped[1:] + clipped[:-1]), lo_eval), [hi]]).astype(float)
    max_delay = system.max_delay
    grid, ratio = band_grid(poles, (lo_eval, hi), max_delay=max_delay or 0.0,
                            extra=np.concatenate([clipped_eval, bounds]))
    pr = system.pole_residue()
    result = _exact_cells(system, pr, grid, bounds, cols, edges_eval)
    if result is None:  # pole–residue inconsistent with direct solves at a maximum: sample directly
        pr = None
        result = _exact_cells(system, None, grid, bounds, cols, edges_eval)
    cell_f, cell_x, all_finite, edge_vals = result
    if near_zero is not None:  # the limit model: the lower edge's value, and the first cell's if it is larger
        edge_vals[0] = near_zero.values
        first = near_zero.values
        larger = first > cell_f[:, 0]
        cell_f[larger, 0], cell_x[larger, 0] = first[larger], lo_eval
    reasons = _uncertified(system, modal, roots, resonant, wd, (lo, hi), max_delay, ratio, all_finite)
    out = {}
    for i, nm in enumerate(names):
        f, x = cell_f[i].copy(), cell_x[i].copy()
        f[resonant] = np.inf
        x[resonant] = clipped[resonant]
        x[x == lo_eval] = lo  # the limit model is reported at the lower edge
        why = list(reasons)
        if near_zero is not None and near_zero.growing[i]:
            why.append(f"the output grows without bound as Ω → 0 (free rigid-body motion) and the lower edge "
                       f"{lo:.6g} rad/s lies where Z(Ω) is singular to rounding (below {zone.step:.3g} rad/s)")
        elif near_zero is not None:
            top, edge, err = float(np.max(f)), near_zero.values[i], near_zero.error[i]
            if edge + err >= top * (1 - CERTIFIED_RTOL) and err > CERTIFIED_RTOL * top:
                why.append(f"the maximum may be the limit Ω → {lo:.6g} rad/s, known only to {err / top:.2g} "
                           "relative (free rigid-body roots make Z(Ω) singular there)")
        out[nm] = ResponseMaxima(
            np.concatenate([f, edge_vals[:, i]]), np.concatenate([x, edges]), wd, (lo, hi), exact=True,
            certified=not why, grid_ratio=ratio, output=nm,
            evaluation="direct" if pr is None else "pole-residue", grid_points=len(grid), reason="; ".join(why),
        )
    return out


ZERO_STEP = 1e-3  # ε = ZERO_STEP · (least non-neutral |s|): the nodes ε, 2ε, 4ε of the limit model near Ω = 0
RESOLVED_DAMPING = 100.0  # a pole's |Re s| must exceed this × its rounding ε·κ_k·max|s| to be certified
CERTIFIED_RTOL = 1e-8  # what ``certified`` promises: U is the band maximum to this relative accuracy


@dataclass(frozen=True)
class ZeroZone:
    """Where free rigid-body roots (s ≈ 0) make Z(Ω) singular to rounding: Ω below ``step`` = ε (rad/s).

    There ``H`` is the limit model: the quadratic through the direct solves at ε, 2ε and 4ε (Lagrange
    weights :meth:`weights`), exact to O(ε³) and, at Ω = 0, the limit of outputs whose poles at the origin cancel
    (H(0) ≈ (8H(ε) − 6H(2ε) + H(4ε))/3).
    """

    step: float

    @property
    def nodes(self) -> np.ndarray:
        """The frequencies ε, 2ε, 4ε (rad/s) the model interpolates."""
        return self.step * np.array([1.0, 2.0, 4.0])

    def weights(self, omega: float) -> np.ndarray:
        """Lagrange weights (3,) of H at :attr:`nodes` giving the model at ``omega`` (rad/s, 0 ≤ omega ≤ ε)."""
        a = float(omega) / self.step
        return np.array([(a - 2) * (a - 4) / 3.0, -(a - 1) * (a - 4) / 2.0, (a - 1) * (a - 2) / 6.0])


@dataclass(frozen=True)
class _NearZero:
    values: np.ndarray  # |H| of the limit model at the lower edge, per output
    error: np.ndarray  # its estimated error: the magnitude of the same model through 2ε, 4ε, 8ε differs by this much
    growing: np.ndarray  # outputs that grow without bound as Ω → 0 (no limit)


def zero_zone(system: LinearSystem, hi: float, roots: np.ndarray | None = None) -> ZeroZone | None:
    """The zone near Ω = 0 where free rigid-body roots make ``Z(Ω)`` singular to rounding, or None without them.

    Neutral roots (:func:`~railopt.models.modal.neutral_roots`) are free rigid-body motion (s = 0 perturbed by
    rounding, perhaps to ±iδ).
    The zone's step is ε = ZERO_STEP·(least non-neutral |s|) (ZERO_STEP = 1e-3), at most 1e-3·``hi`` (rad/s);
    below ε the rounding of a direct solve grows as 1/Ω² (the response there is :class:`ZeroZone`'s limit model).
    """
    s = system.eigenvalues() if roots is None else roots
    scale = float(np.max(np.abs(s))) if s.size else 0.0
    neutral = neutral_roots(s)
    if scale == 0.0 or not np.any(neutral) or np.all(neutral):
        return None
    return ZeroZone(min(ZERO_STEP * float(np.min(np.abs(s[~neutral]))), 1e-3 * hi))


def _near_zero(system: LinearSystem, zone: ZeroZone, cols: list[int], lo: float) -> _NearZero:
    """|H| at ``lo`` (< zone.step) by the limit model with its error estimate, and which outputs grow as Ω → 0
    (|H(ε/10)| > 1.5|H(ε)|: the displacement of a free body under a force); for those the value is the direct
    solve at ``lo`` (its rounding then unbounded)."""
    eps = zone.step
    H = _direct(system, np.array([eps, 2 * eps, 4 * eps, 8 * eps, 0.1 * eps]), cols)
    mags = np.abs(H)
    growing = ~np.isfinite(mags[4]) | (mags[4] > 1.5 * mags[0] + 1e-300)
    model = zone.weights(lo) @ H[:3]
    coarse = ZeroZone(2 * eps).weights(lo) @ H[1:4]
    values = np.abs(model)
    error = np.abs(np.abs(model) - np.abs(coarse))  # of the magnitude reported (a change in phase does not count)
    if np.any(growing) and lo > 0.0:
        values = np.where(growing, _finite_or_inf(np.abs(_direct(system, np.array([lo]), cols)[0])), values)
    return _NearZero(values, error, growing)


def batch_response_maxima(stack: MemberStack, band: object = None, *, band_hz: tuple[float, float] | None = None,
                          band_rad_s: tuple[float, float] | None = None, output: str | None = None) -> np.ndarray:
    """The certified f_k (exact method) of one output for every member of ``stack`` at once: (B, n + 2) values,
    row b equal to ``all_response_maxima(stack.member(b), ..., exact=True)[output].values``.

    The M⁻¹[K C] of all members and their state matrices in one compiled call, the eigen-decompositions stacked in
    one ``np.linalg.eig``, then :func:`railopt.models.kernels.certified_maxima_batch` (one call).  A member whose
    kernel status sends it to the general path (growth, the rigid-body zone, cond(V) beyond CONDITION_LIMIT, an
    inconsistent pole–residue sum, a singular V or Z(Ω)), or an output with a feedthrough, is recomputed on
    :func:`all_response_maxima`; a member the model refuses (a singular M, a ``ValueError`` there) is a row of +inf.

    Raises ``ValueError`` naming ``output`` for an unknown output or ``band`` for a bad band.
    """
    lo, hi = band_arg(band, band_hz, band_rad_s)
    names = list(stack.outputs)
    if output is None:
        output = names[0] if names else None
    if output not in stack.outputs:
        raise ValueError(f"output: unknown output {output!r}; outputs are {names}")
    chosen = stack.outputs[output]
    B, n = stack.M.shape[0], stack.M.shape[1]
    out = np.full((B, n + 2), np.inf)
    general = np.ones(B, dtype=bool)
    if chosen.feedthrough is None and B:
        M, C, K = (kernels.c_array(a) for a in (stack.M, stack.C, stack.K))
        G, regular = kernels.state_matrices(M, C, K, 1e-14)
        s, V = kernels.stacked_eigen_pairs(G)
        delays = kernels.c_array(stack.delays)
        max_delay = float(np.max(delays, initial=0.0))
        count = _grid_count((lo, hi), max_delay)
        status, values, *_ = kernels.certified_maxima_batch(
            M, C, K, kernels.c_array(s, complex), kernels.c_array(V, complex),
            kernels.c_array(stack.coefficients, complex), delays, kernels.c_array(np.atleast_2d(chosen.row)),
            np.array([chosen.order], dtype=np.int64), float(lo), float(hi), max_delay, int(count), _SETTINGS, regular)
        ok = status == kernels.CERT_OK
        out[ok] = values[ok, 0]
        general = ~ok & regular  # a singular M is refused (+inf), as LinearSystem refuses it
    for b in np.flatnonzero(general):
        try:
            out[b] = all_response_maxima(stack.member(int(b)), band_rad_s=(lo, hi), exact=True,
                                         outputs=[output])[output].values
        except ValueError:
            out[b] = np.inf
    return out


_SETTINGS = np.array([UNDAMPED_ROOT, NEUTRAL_ROOT, ZERO_STEP, CONDITION_LIMIT, CONSISTENCY_RTOL, POLISH_RTOL,
                      BRACKET_RTOL, GRID_FACTOR, POLE_STEP, MAX_GRID_POINTS, RESOLVED_DAMPING])


def _certified(system: LinearSystem, band: tuple[float, float], names: list[str],
               cols: list[int]) -> dict[str, ResponseMaxima] | None:
    """The exact path by :func:`railopt.models.kernels.certified_maxima` (one compiled call after the
    eigen-decomposition), or None where the general path must run: a callable forcing or undeclared delay, an output
    with a feedthrough, and whatever the kernel's status sends back (growth, the rigid-body zone, cond(V) beyond
    CONDITION_LIMIT, pole–residue inconsistent with direct solves, F or Z not finite, a singular Z)."""
    outs = list(system.outputs.values())
    chosen = [outs[c] for c in cols]
    max_delay = system.max_delay
    if max_delay is None or not system.forcing.is_polynomial:
        return None
    for o in chosen:
        if o.feedthrough is not None:
            return None
    lo, hi = band
    s, V = system.eigen_pairs()
    A, delays = forcing_arrays(system.forcing, system.n)
    rows = np.array([o.row for o in chosen], dtype=float)  # a fresh C-contiguous copy, as the kernel takes it
    orders = np.array([o.order for o in chosen], dtype=np.int64)
    count = _grid_count((lo, hi), max_delay)
    try:
        (status, values, freqs, ratio, points, all_finite, resonant, soft, unresolved, kappa, W, condition,
         wd) = kernels.certified_maxima(
            *system._mck, kernels.c_array(s, complex), kernels.c_array(V, complex), A, delays, rows, orders,
            float(lo), float(hi), float(max_delay), int(count), _SETTINGS)
    except np.linalg.LinAlgError:  # V or a Z(Ω) exactly singular
        return None
    if W.size:
        system.remember_left(W, condition)
    if status != kernels.CERT_OK:
        return None
    why = _reasons(band, max_delay, ratio, all_finite, resonant,
                   system.eigenvalues() if np.count_nonzero(resonant) else s, wd, None if soft < 0 else s[soft],
                   None if unresolved < 0 else s[unresolved], kappa)
    return {nm: ResponseMaxima._owned(values[i], freqs[i], wd, (lo, hi), exact=True, certified=not why,
                                      grid_ratio=float(ratio), output=nm, evaluation="pole-residue",
                                      grid_points=int(points), reason="; ".join(why))
            for i, nm in enumerate(names)}


def _uncertified(system: LinearSystem, modal, roots: np.ndarray, resonant: np.ndarray, wd: np.ndarray,
                 band: tuple[float, float], max_delay: float | None, ratio: float, all_finite: bool) -> list[str]:
    """Why the cell maxima are not certified (empty when they are), common to every output."""
    # neutral roots are taken as free rigid-body motion (s = 0 up to rounding: real pairs ±δ, or ±iδ on the axis); a
    # complex pair among them damped beyond rounding is a genuine mode too soft for the search, whose peak is missed;
    # a pole whose damping is within rounding of the eigenvalue: the grid, built around the computed pole, cannot
    # be trusted to resolve the true peak (near-defective pairs, tiny damping) — the kernel's own check
    s = modal.s
    soft, unresolved, kappa_k = kernels.weak_roots(
        kernels.c_array(s, complex), kernels.c_array(modal.V, complex), kernels.c_array(modal.W, complex),
        float(band[0]), float(band[1]), NEUTRAL_ROOT, UNDAMPED_ROOT, RESOLVED_DAMPING)
    soft_root = s[soft] if soft >= 0 else None
    pole = s[unresolved] if unresolved >= 0 else None
    return _reasons(band, max_delay, ratio, all_finite, resonant, roots, wd, soft_root, pole, kappa_k)


def _reasons(band: tuple[float, float], max_delay: float | None, ratio: float, all_finite: bool,
             resonant: np.ndarray, roots: np.ndarray, wd: np.ndarray, soft_root: complex | None,
             pole: complex | None, kappa: float) -> list[str]:
    """The wording of why the cell maxima are not certified, from the checks' outcomes (empty when certified)."""
    why = []
    if max_delay is None:
        why.append("the forcing does not declare its delays")
    if not ratio <= CERTIFIED_RATIO * (1 + 1e-9):
        needed = _delay_points(band, max_delay or 0.0)
        why.append(f"the grid broke the spacing rule (ratio {ratio:.3g})" + (
            f": the delay {max_delay:.6g} s alone needs {needed} points, more than {MAX_GRID_POINTS}"
            if needed > MAX_GRID_POINTS else ""))
    if not all_finite:
        why.append("a sample was singular (an undamped or rigid-body pole on the band)")
    if np.count_nonzero(resonant):  # (.any() costs µs more on these few entries)
        j = int(np.flatnonzero(resonant)[0])
        mode = roots[1::2][j]
        why.append(f"mode {j + 1} at {wd[j] / (2 * np.pi):.6g} Hz has damping ratio {abs(mode.real) / abs(mode):.3g} "
                   f"≤ {UNDAMPED_ROOT:g} (undamped to rounding): its peak is taken as unbounded, a finite one is "
                   "not resolved in double precision")
    if soft_root is not None:
        root = soft_root
        why.append(f"the root s = {root.real:.3g}{root.imag:+.3g}i 1/s is below {NEUTRAL_ROOT:g}·max|s| (taken as "
                   "free rigid-body motion) yet damped beyond rounding: a mode too soft for the band search")
    if pole is not None:
        why.append(f"the pole s = {pole.real:.6g}{pole.imag:+.6g}i 1/s has its damping within rounding of the "
                   f"eigen-decomposition (eigenvalue condition {kappa:.3g}; a defective or nearly repeated "
                   "pair): the grid around it may not resolve the peak")
    return why


def _grid_count(band: tuple[float, float], max_delay: float) -> int:
    """Points of the uniform part of the band grid: the delay rule's (:func:`_delay_points`), at least
    4·MIN_CELL_SAMPLES + 1, at most MAX_GRID_POINTS (beyond it the grid is not certified)."""
    return max(4 * MIN_CELL_SAMPLES + 1, min(_delay_points(band, max_delay), MAX_GRID_POINTS))


def _delay_points(band: tuple[float, float], max_delay: float) -> int:
    """Points the uniform grid of the delay rule needs over ``band``: step 0.9·GRID_FACTOR·2π/(4τ_max)."""
    if max_delay <= 0:
        return 0
    step = 0.9 * GRID_FACTOR * 2 * np.pi / (4 * max_delay)
    return int(np.ceil((band[1] - band[0]) / step)) + 1


def _exact_cells(system: LinearSystem, pr, grid: np.ndarray, bounds: np.ndarray, cols: list[int],
                 edges: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool, np.ndarray] | None:
    """Cell maxima (values by direct solves at the refined frequencies) for each output column, and |H| at
    the band edges (the same batch of direct solves)."""
    H = _direct(system, grid, cols) if pr is None else pr.evaluate(grid, outputs=cols)
    mags = _finite_or_inf(np.abs(H))
    xs, fs = [], []
    for i, c in enumerate(cols):  # per output (usually one); the cells of each are refined all at once
        data = pr.kernel_data(c) if pr is not None else None
        if data is not None:  # the compiled search with the pole–residue |H| inline
            x, f, _ = kernels.cell_maxima_pole_residue(grid, kernels.c_array(mags[:, i]), bounds,
                                                       BRACKET_RTOL, *data)
        else:
            fun = pr.magnitude_function(c) if pr is not None else (
                lambda w, c=c: _finite_or_inf(np.abs(_direct(system, w, [c])[:, 0])))
            x, f = cell_maxima(fun, grid, mags[:, i], bounds)
        xs.append(x)
        fs.append(f)
    X = np.array(xs)
    direct = _finite_or_inf(np.abs(_direct(system, np.concatenate([X.ravel(), edges]), cols)))
    edge_vals, direct = direct[-len(edges):], direct[: -len(edges)]
    F = np.array([direct[i * X.shape[1]:(i + 1) * X.shape[1], i] for i in range(len(cols))])
    if pr is not None:
        sampled = np.array(fs)
        ok = np.isfinite(sampled) & np.isfinite(F)
        scale = np.max(np.where(ok, F, 0.0), initial=0.0)
        if np.any(np.abs(sampled[ok] - F[ok]) > CONSISTENCY_RTOL * max(scale, 1e-300)):
            return None
        # the pole–residue sum carries rounding noise (up to ~cond(V)·ε) that is random in Ω, so a maximiser found
        # on it is located only to ~√noise of the peak's width; where the noise shows at a refined maximum, the
        # maximiser is located again on direct solves between its grid neighbours
        noisy = ok & (np.abs(sampled - F) > POLISH_RTOL * np.abs(F))
        for i, j in zip(*np.nonzero(noisy), strict=True):
            X[i, j], F[i, j] = _polish(system, cols[i], grid, bounds[j:j + 2], X[i, j], F[i, j])
    return F, X, bool(np.all(np.isfinite(mags))), edge_vals


def _polish(system: LinearSystem, col: int, grid: np.ndarray, cell: np.ndarray, x: float,
            f: float) -> tuple[float, float]:
    """The maximum of |H_col| by direct solves between the grid neighbours of ``x`` (clipped to ``cell``), started
    from (x, f); the better of the two."""
    lo = max(grid[max(np.searchsorted(grid, x, side="left") - 1, 0)], cell[0])
    hi = min(grid[min(np.searchsorted(grid, x, side="right"), len(grid) - 1)], cell[1])
    if not (lo < x < hi):
        return x, f
    pts = np.array([lo, x, hi])

    def fun(w: np.ndarray) -> np.ndarray:
        return _finite_or_inf(np.abs(_direct(system, w, [col])[:, 0]))

    xr, fr = cell_maxima(fun, pts, fun(pts), np.array([lo, hi]))
    return (float(xr[0]), float(fr[0])) if fr[0] > f else (x, f)


def _direct(system: LinearSystem, w: np.ndarray, cols: list[int]) -> np.ndarray:
    """``system.frf_outputs(omega_rad_s=w)[:, cols]`` (the same batched solves ``Z(Ω)X = F``) with the polynomial
    forcing evaluated for all Ω at once and only the outputs ``cols``; anything unusual (a callable term, a
    non-finite F or Z, a singular Z) goes to ``frf_outputs`` itself, which handles or names it."""
    forcing = system.forcing
    outputs = list(system.outputs.values())
    chosen = [outputs[c] for c in cols]
    if not forcing.is_polynomial or any(o.feedthrough is not None for o in chosen):
        return system.frf_outputs(omega_rad_s=w)[:, cols]
    w = kernels.c_array(np.ravel(w))
    A, delays = forcing_arrays(forcing, system.n)
    rows = kernels.c_array(np.array([o.row for o in chosen], dtype=float))
    orders = np.array([o.order for o in chosen], dtype=np.int64)
    try:  # the certified path's own direct-solve formula (the thesis values and the exact edges agree exactly)
        H, status = kernels.direct_outputs(kernels.c_array(system.M), kernels.c_array(system.C),
                                           kernels.c_array(system.K), w, A, delays, rows, orders)
    except np.linalg.LinAlgError:
        return system.frf_outputs(omega_rad_s=w)[:, cols]
    if status:
        return system.frf_outputs(omega_rad_s=w)[:, cols]
    return H


def _finite_or_inf(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a[~np.isfinite(a)] = np.inf
    return a


def band_grid(poles: np.ndarray, band: tuple[float, float], max_delay: float = 0.0,
              extra: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """Frequency grid (rad/s) over ``band`` with step ≤ GRID_FACTOR · dist(iΩ, poles) everywhere.

    Around each pole s_k = −σ_k + iω_k the points Ω = ω_k + σ_k sinh(u), u on a step of :data:`POLE_STEP`, have
    step/dist(iΩ, s_k) ≤ 0.222; the union over poles (and a uniform grid for the delay, step ≤
    0.9·GRID_FACTOR·2π/(4τ_max), and a 33-point floor) meets the rule for the nearest pole at every Ω ≥ 0.  Any
    step that still fails is bisected.  The number of points grows with log(band width / modal damping), so
    lightly damped modes cost little.  Returns the grid and its worst step ratio, step / (distance to the nearest
    pole at the nearer step end) — the distance is 1-Lipschitz in Ω, so steps of GRID_FACTOR·dist(left end) keep
    it below GRID_FACTOR / (1 − GRID_FACTOR) = CERTIFIED_RATIO, and the grid is certified when it is.  The
    compiled kernel is :func:`railopt.models.kernels.band_grid`.
    """
    lo, hi = float(band[0]), float(band[1])
    count = _grid_count((lo, hi), max_delay)
    extra = np.zeros(0) if extra is None else kernels.c_array(np.ravel(extra))
    grid, ratio = kernels.band_grid(kernels.c_array(np.ravel(poles), complex), lo, hi,
                                    float(max_delay), extra, int(count), GRID_FACTOR, POLE_STEP, MAX_GRID_POINTS)
    return grid, float(ratio)
