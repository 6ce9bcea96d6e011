"""The one adapter from a model to the design layer: ModelSetup + config → MinimaxProblem.

The objective is the vector f_k (4.71)–(4.73) of one output over a band; optional constraints are
the f_k of other outputs held below a limit (ε-constraint trade-offs, g(x) ≤ ε) and the stability rows
of SPEC §2.5 (:class:`StabilityTarget`: Re s_j + σ_min ≤ 0 for every vehicle mode at a grid of speeds up to
the required speed, on each track's stability family; optionally ζ_j ≥ ζ_min).  Gradients are analytic:
``df/dx = df/dp · dp/dx`` (model Jacobian, then the parameter map of the setup); the stability rows from
the eigenvalue sensitivities (:class:`railopt.models.stability.StabilityRows`: the members solved once, the
derivatives only when the method asks).  The objective and the response constraints at one x share one
system and one eigen-decomposition.

A ride objective (:class:`RMSTarget`) is the RMS of one output per metre of rail irregularity under a track
spectrum at the family's speed over a band (:func:`railopt.models.random_response.random_response`, adaptive
quadrature), a single function; its gradient is analytic on the final quadrature rule
(:func:`railopt.models.random_response.rms_gradient` with dp/dx folded in:
``dRMS/dx = Σ_k w_k S_k Re(conj(H_k) dH_k/dx) / RMS`` with ``dH/dx = (iω)^q c·Z⁻¹(dF/dx − dZ/dx Z⁻¹F)`` from the
member's tangent; the rule's nodes held fixed: the derivative of the discrete sum, equal to the derivative of
the RMS to the quadrature tolerance).

Where an objective does not exist at a design — an unstable member has no steady-state response and no stationary
random response; an undamped mode inside the band makes the band maximum (and the RMS) unbounded — its value is
+inf, never an exception: a solver's line search backs off from it as from a barrier, and a start placed there ends
with U = inf, which the campaign report counts with the reason :func:`objective_value` gives.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from railopt.design import DesignVariable, MinimaxProblem
from railopt.models import LinearSystem
from railopt.models.modal import growing_roots
from railopt.models.random_response import RandomResponse, random_response, rms_gradient
from railopt.models.response_maxima import all_response_maxima, batch_response_maxima
from railopt.models.sensitivity import maxima_jacobians
from railopt.models.stability_map import least_damping_ratio, stability_map, worst_speed
from railopt.models.stability_rows import StabilityRows
from railopt.models.units import RAD_PER_HZ
from railopt.studies.catalog import ModelSetup
from railopt.studies.catalog.checks import CRITERION_TOL

if TYPE_CHECKING:
    from railopt.studies.specs import ObjectiveSpec, OutputSpec, StabilitySpec

__all__ = [
    "RMSTarget",
    "ResponseTarget",
    "StabilityExchange",
    "StabilityTarget",
    "minimax_problem",
    "objective_value",
    "response_target",
    "rms_target",
    "stability_target",
]


@dataclass(frozen=True)
class ResponseTarget:
    """The f_k of one output over a band (rad/s); ``exact`` picks the certified cell maxima."""

    output: str
    band: tuple[float, float]
    exact: bool = True


@dataclass(frozen=True)
class RMSTarget:
    """RMS of ``output`` per metre of irregularity under ``spectrum`` (``.psd(Ω)`` m²/(rad/m)) at ``speed`` (m/s,
    the family's own speed) over ``band_hz`` (Hz): ``scale × rms(family.at(p), spectrum, speed, band_hz)``.

    ``scale`` makes it per metre: ``1/a`` for a model forced by an irregularity of amplitude a (m), whose
    responses are per a (the response is linear in a).  ``rtol``: the quadrature's relative tolerance on the
    variance."""

    output: str
    band_hz: tuple[float, float]
    spectrum: object
    speed: float
    scale: float = 1.0
    rtol: float = 1e-8

    def response(self, system: LinearSystem) -> RandomResponse | str:
        """The random response of ``system`` (a member of the family, forced per the model's amplitude) or, where
        none exists, why (a non-empty reason): a growing root (no stationary response), an undamped mode in the
        band (|H| unbounded there).  Other failures of the quadrature raise as
        :func:`~railopt.models.random_response.random_response` does."""
        reason = _no_steady_state(system)
        if reason:
            return reason + "; a stationary random response does not exist"
        try:
            return random_response(system, self.spectrum, self.speed, self.band_hz, self.output, self.rtol)
        except ValueError:
            undamped = _undamped_in_band(system, (self.band_hz[0] * RAD_PER_HZ, self.band_hz[1] * RAD_PER_HZ))
            if undamped:
                return undamped + "; the RMS is unbounded"
            raise


def _no_steady_state(system: LinearSystem) -> str:
    """Why ``system`` has no steady-state response ("" when it has one): its fastest-growing root."""
    growing = growing_roots(system.eigenvalues())
    if not growing.size:
        return ""
    worst = growing[np.argmax(growing.real)]
    return (f"unstable: root s = {worst.real:.4g}{worst.imag:+.4g}i 1/s ({abs(worst.imag) / RAD_PER_HZ:.4g} Hz) "
            "has Re s > 0")


def _undamped_in_band(system: LinearSystem, band_rad_s: tuple[float, float]) -> str:
    """An undamped mode inside the band (rad/s), in words ("" when there is none)."""
    freqs = system.damped_frequencies()[system.undamped_modes()]
    inside = freqs[(freqs >= band_rad_s[0]) & (freqs <= band_rad_s[1])]
    return f"an undamped mode at {inside[0] / RAD_PER_HZ:.4g} Hz inside the band" if inside.size else ""


def objective_value(system: LinearSystem, target: ResponseTarget | RMSTarget) -> tuple[float, str]:
    """The objective at one member of the family and, where it does not exist, why.

    Parameters
    ----------
    system : LinearSystem
        The family at the design's parameters (``ParametricSystem.at(p)``).
    target : ResponseTarget or RMSTarget
        The band maximum (certified with ``exact``) of an output, or its RMS per metre under a spectrum.

    Returns
    -------
    (float, str)
        The value (output units; per metre for an RMS) and ``""``; or ``inf`` and the reason: an unstable member
        (its growing root: no steady state, no stationary random response) or an undamped mode inside the band
        (an unbounded band maximum or RMS).  The value is the one the minimax problem's objective takes.
    """
    if isinstance(target, RMSTarget):
        response = target.response(system)
        return (float("inf"), response) if isinstance(response, str) else (target.scale * response.rms, "")
    maxima = all_response_maxima(system, band_rad_s=target.band, exact=target.exact, outputs=[target.output])
    value = maxima[target.output].value
    if np.isfinite(value):
        return float(value), ""
    unstable = _no_steady_state(system)
    reason = unstable + "; no steady-state response exists" if unstable else _undamped_in_band(system, target.band)
    return float("inf"), f"{reason}; the band maximum is unbounded" if reason else "the band maximum is unbounded"


@dataclass(frozen=True)
class StabilityTarget:
    """Stability rows of the NLP: ``Re s_j(p, S_k) + σ_min ≤ 0`` for every vehicle mode j at each speed S_k (m/s)
    on each track's family of the setup (track modes and ``exclude`` left out), and with ``zeta_min`` also
    ``ζ_min − ζ_j ≤ 0``.  A design meeting them at speeds up to the required one is confirmed by its critical
    speed afterwards (the rows are checked on a grid; the crossing is found by the hunting check)."""

    tracks: tuple[str, ...]
    speeds: tuple[float, ...]
    sigma_min: float = 0.0
    zeta_min: float | None = None
    exclude: tuple[str, ...] = ()

    def rows(self, setup: ModelSetup) -> int:
        """Number of constraint rows (fixed: one per mode, speed and track)."""
        per = 2 if self.zeta_min is not None else 1
        return per * len(self.speeds) * sum(setup.stability[t].n for t in self.tracks)


class _Evaluator:
    """f or g at x, and their Jacobians when the solver asks, the system and the pieces of the last x kept:
    values first (a derivative-free method stops there), the Jacobian from the same maxima afterwards."""

    def __init__(self, setup: ModelSetup, names: Sequence[str]) -> None:
        self.setup, self.names = setup, list(names)
        self._key: bytes | None = None
        self._sys: LinearSystem | None = None
        self._p: np.ndarray | None = None
        self._dp: np.ndarray | None = None
        self._pieces: dict = {}

    def system(self, x: np.ndarray) -> tuple[LinearSystem, np.ndarray]:
        key = np.asarray(x, dtype=float).tobytes()
        if key != self._key:
            p, dp = self.setup.parameters(self.names, np.asarray(x, dtype=float))
            self._sys, self._p, self._dp, self._key, self._pieces = self.setup.family.at(p), p, dp, key, {}
        return self._sys, self._dp

    def _piece(self, x: np.ndarray, kind: str, target: object, compute):
        """The ``kind`` of result for ``target`` at x, computed once.  Keyed by the target object itself (held with
        the result): a different target that happens to reuse a freed one's id is computed afresh."""
        self.system(x)  # a new x clears the pieces
        held = self._pieces.get((kind, id(target)))
        if held is None or held[0] is not target:
            held = (target, compute())
            self._pieces[(kind, id(target))] = held
        return held[1]

    def _maxima(self, x: np.ndarray, t: ResponseTarget):
        sys, _ = self.system(x)
        return self._piece(x, "maxima", t, lambda: all_response_maxima(
            sys, band_rad_s=t.band, exact=t.exact, outputs=[t.output])[t.output])

    def maxima(self, x: np.ndarray, targets: Sequence[ResponseTarget]) -> np.ndarray:
        return np.concatenate([self._maxima(x, t).values for t in targets])

    def maxima_jacobian(self, x: np.ndarray, targets: Sequence[ResponseTarget]) -> np.ndarray:
        sys, dp = self.system(x)
        return np.vstack([maxima_jacobians(sys, band_rad_s=t.band, exact=t.exact, outputs=[t.output],
                                           maxima={t.output: self._maxima(x, t)})[t.output][1] @ dp for t in targets])

    def _rms(self, x: np.ndarray, target: RMSTarget) -> RandomResponse | str:
        sys, _ = self.system(x)
        return self._piece(x, "rms", target, lambda: target.response(sys))

    def objective(self, x: np.ndarray, target: ResponseTarget | RMSTarget) -> np.ndarray:
        if isinstance(target, RMSTarget):
            response = self._rms(x, target)  # a reason where none exists: +inf, a barrier to line searches
            return np.array([np.inf if isinstance(response, str) else target.scale * response.rms])
        return self.maxima(x, [target])

    def objective_jacobian(self, x: np.ndarray, target: ResponseTarget | RMSTarget) -> np.ndarray:
        if isinstance(target, RMSTarget):
            sys, dp = self.system(x)
            response = self._rms(x, target)
            if isinstance(response, str):  # f = inf carries no slope (the design layer zeroes it too)
                return np.zeros((1, dp.shape[1]))
            return target.scale * rms_gradient(sys, response, dp)[None, :]
        return self.maxima_jacobian(x, [target])

    def _stability_rows(self, x: np.ndarray,
                        target: StabilityTarget) -> list[tuple[StabilityRows, list[int], list[int]]]:
        """Per track: the solved members (:class:`StabilityRows`), the designed parameters' indices in the track
        family and in the design family."""
        def compute():
            _, dp = self.system(x)
            p = self._p  # the parameters of the system just built for x
            params = list(self.setup.family.parameters)
            out = []
            for track in target.tracks:
                family = self.setup.stability[track]
                rows = [params.index(n) for n in family.parameters]
                moving = [i for i, r in enumerate(rows) if np.any(dp[r] != 0.0)]  # only designed parameters
                out.append((StabilityRows(family, p[rows], target.speeds, target.exclude), moving,
                            [rows[i] for i in moving]))
            return out

        return self._piece(x, "stability rows", target, compute)

    def stability(self, x: np.ndarray, target: StabilityTarget) -> np.ndarray:
        """The rows of ``target`` at x: for each track, Re s + σ_min, then ζ_min − ζ when ζ_min is set."""
        def compute():
            values = []
            for rows, _, _ in self._stability_rows(x, target):
                values.append(rows.roots(target.sigma_min))
                if target.zeta_min is not None:
                    values.append(rows.damping(target.zeta_min))
            return np.concatenate(values)

        return self._piece(x, "stability", target, compute)

    def stability_jacobian(self, x: np.ndarray, target: StabilityTarget) -> np.ndarray:
        """d(rows)/dx (rows, d), from the members solved for :meth:`stability` (a derivative-free method never pays
        it)."""
        _, dp = self.system(x)
        jacs = []
        for rows, moving, design_rows in self._stability_rows(x, target):
            jacs.append(rows.roots_jacobian(moving) @ dp[design_rows])
            if target.zeta_min is not None:
                jacs.append(rows.damping_jacobian(moving) @ dp[design_rows])
        return np.vstack(jacs)

    def _constraint_parts(self, x: np.ndarray, targets: Sequence[ResponseTarget], stability: StabilityTarget | None,
                          jacobian: bool) -> list[np.ndarray]:
        parts = [(self.maxima_jacobian if jacobian else self.maxima)(x, targets)] if targets else []
        if stability is not None:
            parts.append((self.stability_jacobian if jacobian else self.stability)(x, stability))
        return parts

    def constraints(self, x: np.ndarray, targets: Sequence[ResponseTarget],
                    stability: StabilityTarget | None) -> np.ndarray:
        return np.concatenate(self._constraint_parts(x, targets, stability, jacobian=False))

    def constraints_jacobian(self, x: np.ndarray, targets: Sequence[ResponseTarget],
                             stability: StabilityTarget | None) -> np.ndarray:
        return np.vstack(self._constraint_parts(x, targets, stability, jacobian=True))

    def batch_objective(self, X: np.ndarray, target: ResponseTarget) -> np.ndarray:
        """The f_k of ``target`` at every row of X (B, d): (B, n + 2), the members stacked and their certified
        maxima in one compiled call (:func:`~railopt.models.response_maxima.batch_response_maxima`); a row whose
        parameters the model refuses (a ``ValueError``) is +inf, as :meth:`MinimaxProblem.values` takes a refused
        point.  A family that cannot be stacked (a callable forcing term) is evaluated row by row (the same values)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = np.full((len(X), self.setup.family.n + 2), np.inf)
        try:
            P, kept = self.setup.parameter_map.rows(self.names, X), list(range(len(X)))
        except ValueError:  # a derived variable's transform refuses some row: find which, row by row
            kept, P = [], []
            for b, x in enumerate(X):
                try:
                    P.append(self.setup.parameters(self.names, x)[0])
                except ValueError:
                    continue
                kept.append(b)
        if not kept:
            return out
        try:
            stack = self.setup.family.stack(np.array(P))
        except ValueError:  # callable forcing terms: no stacked form
            for b in kept:
                try:
                    out[b] = self.maxima(X[b], [target])
                except ValueError:
                    pass
            return out
        out[kept] = batch_response_maxima(stack, band_rad_s=target.band, output=target.output)
        return out

    def __getstate__(self) -> dict:  # ship to dask workers without the cached system
        return {"setup": self.setup, "names": self.names, "_key": None, "_sys": None, "_p": None, "_dp": None,
                "_pieces": {}}



# ---------------------------------------------------------------------------------------------- targets from specs
def response_target(spec: OutputSpec, setup: ModelSetup, exact: bool) -> ResponseTarget:
    """The f_k of ``spec.output`` (default: the family's first output) over ``spec.band_hz`` (Hz, as rad/s)."""
    output = spec.output or setup.family.output_names[0]
    return ResponseTarget(output, (spec.band_hz[0] * RAD_PER_HZ, spec.band_hz[1] * RAD_PER_HZ), exact)


def rms_target(spec: ObjectiveSpec, setup: ModelSetup) -> RMSTarget:
    """The ride objective: RMS of the output per metre of irregularity (responses divided by the model's
    irregularity amplitude) under ``spec.spectrum`` at the model's speed over ``spec.band_hz``."""
    output = spec.output or setup.family.output_names[0]
    return RMSTarget(output, tuple(spec.band_hz), spec.spectrum.spectrum(), float(setup.family.speed),
                     1.0 / setup.input_amplitude_m, spec.spectrum.rtol)


def stability_target(spec: StabilitySpec, setup: ModelSetup, required: float | None = None) -> StabilityTarget:
    """The stability rows of ``spec`` at ``spec.speeds`` speeds up to ``required`` (m/s; default
    ``spec.required(setup)``)."""
    top = required or spec.required(setup)
    low = min(spec.lowest_speed_m_s or top / spec.speeds, top)
    speeds = tuple(float(v) for v in np.linspace(low, top, spec.speeds))
    return StabilityTarget(tuple(spec.tracks or setup.stability), speeds, spec.sigma_min, spec.zeta_min,
                           tuple(spec.exclude))


def minimax_problem(
    setup: ModelSetup,
    variables: Sequence[DesignVariable],
    objective: ResponseTarget | RMSTarget,
    constraints: Sequence[ResponseTarget] = (),
    limits: Sequence[float] = (),
    stability: StabilityTarget | None = None,
) -> MinimaxProblem:
    """min_x max_k f_k(x) of ``objective`` subject to the f_k of each constraint ≤ its limit and, with
    ``stability``, the stability rows ≤ 0.  A :class:`RMSTarget` objective is one function (the RMS per metre)."""
    names = [v.name for v in variables]
    unknown = [n for n in names if n not in setup.designable]
    if unknown:
        raise ValueError(f"variables: {unknown} are not parameters of the model; choose from {list(setup.designable)}")
    evaluator = _Evaluator(setup, names)
    if isinstance(objective, RMSTarget):
        if setup.family.speed is None or abs(objective.speed - setup.family.speed) > 1e-12 * setup.family.speed:
            raise ValueError(f"objective.speed: {objective.speed} m/s is not the model's speed {setup.family.speed}")
        if objective.output not in setup.family.output_names:
            raise ValueError(f"objective.output: unknown output {objective.output!r}; outputs are "
                             f"{list(setup.family.output_names)}")
    # the certified maxima of many designs at once (objective surfaces, grid scans): one compiled call per batch
    batch = (None if not isinstance(objective, ResponseTarget) or not objective.exact
             else lambda X: evaluator.batch_objective(X, objective))
    if not constraints and stability is None:
        return MinimaxProblem(list(variables), lambda x: evaluator.objective(x, objective),
                              jacobian=lambda x: evaluator.objective_jacobian(x, objective), batch_functions=batch)
    if stability is not None:
        missing = [t for t in stability.tracks if t not in setup.stability]
        if missing:
            raise ValueError(f"stability.tracks: {missing} have no stability family in this model; it has "
                             f"{sorted(setup.stability)}")
    epsilon = np.repeat(np.asarray(limits, dtype=float), setup.family.n + 2)  # n + 2 maxima per constraint
    if stability is not None:
        epsilon = np.concatenate([epsilon, np.zeros(stability.rows(setup))])
    targets = list(constraints)
    refine = None if stability is None else StabilityExchange(setup, tuple(variables), objective, tuple(constraints),
                                                               tuple(limits), stability)
    return MinimaxProblem(
        list(variables),
        lambda x: evaluator.objective(x, objective),
        jacobian=lambda x: evaluator.objective_jacobian(x, objective),
        constraints=lambda x: evaluator.constraints(x, targets, stability),
        constraint_jacobian=lambda x: evaluator.constraints_jacobian(x, targets, stability),
        epsilon=epsilon,
        refine=refine,
        batch_functions=batch,
    )


@dataclass(frozen=True)
class StabilityExchange:
    """The certificate of the stability rows as a semi-infinite constraint (``MinimaxProblem.refine``).

    The rows hold Re s_j + σ_min ≤ 0 (and ζ_j ≥ ζ_min) at grid speeds; the criterion is every speed from the first
    to the last row.  For a solved design x, on each track: the certified stability map for the line Re s = −σ_min
    (:func:`~railopt.models.stability_map.stability_map`) gives every violating interval; the speed where the
    spectral abscissa peaks in it (:func:`~railopt.models.stability_map.worst_speed`) becomes a new row when a kept
    mode (the rows' modes: track modes and ``exclude`` left out) violates there by more than
    :data:`~railopt.studies.catalog.checks.CRITERION_TOL` (the rows' feasibility tolerance, as the check allows).
    With ζ_min the least damping ratio (sampled and refined) adds its speed likewise.  Returns the problem with
    those speeds added, or None when x meets the criterion at every speed (:func:`railopt.design.solve` resumes from
    x until then).
    """

    setup: ModelSetup
    variables: tuple[DesignVariable, ...]
    objective: ResponseTarget | RMSTarget
    constraints: tuple[ResponseTarget, ...]
    limits: tuple[float, ...]
    stability: StabilityTarget
    tol: float = 0.01

    def new_speeds(self, x: np.ndarray) -> list[float]:
        """The speeds (m/s) where the design ``x`` violates the criterion between the rows, ascending."""
        names = [v.name for v in self.variables]
        p, _ = self.setup.parameters(names, np.asarray(x, dtype=float))
        lo, hi = min(self.stability.speeds), max(self.stability.speeds)
        found: list[float] = []
        for track in self.stability.tracks:
            model = self.setup.stability_model(p, track)
            smap = (stability_map(model, (lo, hi), sigma=self.stability.sigma_min - CRITERION_TOL, tol=self.tol)
                    if hi > lo else None)
            candidates = [] if smap is None else [worst_speed(model, (iv.start, iv.end), tol=self.tol)[0]
                                                   for iv in smap.intervals if not iv.stable]
            if self.stability.zeta_min is not None and hi > lo:
                zeta, at = least_damping_ratio(model, (lo, hi), tol=self.tol)
                if zeta < self.stability.zeta_min - CRITERION_TOL:
                    candidates.append(at)
            for S in candidates:
                rows = StabilityRows(model, None, [S], self.stability.exclude)
                worst = float(np.max(rows.roots(self.stability.sigma_min)))
                if self.stability.zeta_min is not None:
                    worst = max(worst, float(np.max(rows.damping(self.stability.zeta_min))))
                if worst > CRITERION_TOL and all(abs(S - q) > 0.5 * self.tol for q in (*self.stability.speeds, *found)):
                    found.append(float(S))
        return sorted(found)

    def __call__(self, x: np.ndarray) -> MinimaxProblem | None:
        new = self.new_speeds(x)
        if not new:
            return None
        stability = replace(self.stability, speeds=tuple(sorted((*self.stability.speeds, *new))))
        return minimax_problem(self.setup, self.variables, self.objective, self.constraints, self.limits, stability)
