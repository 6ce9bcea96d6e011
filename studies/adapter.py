"""The one adapter from a model to the design layer: ModelSetup + config → MinimaxProblem.

The objective is the vector f_k (4.71)–(4.73) of one output over a band; optional constraints are
the f_k of other outputs held below a limit (ε-constraint trade-offs, g(x) ≤ ε) and the stability rows
of SPEC §2.5 (:class:`StabilityTarget`: Re s_j + σ_min ≤ 0 for every vehicle mode at a grid of speeds up to
the required speed, on each track's stability family; optionally ζ_j ≥ ζ_min).  Gradients are analytic:
``df/dx = df/dp · dp/dx`` (model Jacobian, then the parameter map of the setup); the stability rows from
the eigenvalue sensitivities (:func:`railopt.models.stability.root_constraints`).  The objective and the
response constraints at one x share one system and one eigen-decomposition.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from railopt.design import DesignVariable, MinimaxProblem
from railopt.models import LinearSystem
from railopt.models.sensitivity import maxima_jacobians
from railopt.models.stability import damping_constraints, root_constraints
from railopt.studies.catalog import ModelSetup

__all__ = ["ResponseTarget", "StabilityTarget", "minimax_problem"]


@dataclass(frozen=True)
class ResponseTarget:
    """The f_k of one output over a band (rad/s); ``exact`` picks the certified cell maxima."""

    output: str
    band: tuple[float, float]
    exact: bool = True


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
    """f or g at x with its Jacobian, the system of the last x kept (f and g share it)."""

    def __init__(self, setup: ModelSetup, names: Sequence[str]) -> None:
        self.setup, self.names = setup, list(names)
        self._key: bytes | None = None
        self._sys: LinearSystem | None = None
        self._dp: np.ndarray | None = None

    def system(self, x: np.ndarray) -> tuple[LinearSystem, np.ndarray]:
        key = np.asarray(x, dtype=float).tobytes()
        if key != self._key:
            p, dp = self.setup.parameters(self.names, np.asarray(x, dtype=float))
            self._sys, self._dp, self._key = self.setup.family.at(p), dp, key
        return self._sys, self._dp

    def maxima(self, x: np.ndarray, targets: Sequence[ResponseTarget]) -> tuple[np.ndarray, np.ndarray]:
        sys, dp = self.system(x)
        values, jacs = [], []
        for t in targets:
            rm, J = maxima_jacobians(sys, band_rad_s=t.band, exact=t.exact, outputs=[t.output])[t.output]
            values.append(rm.values)
            jacs.append(J @ dp)
        return np.concatenate(values), np.vstack(jacs)

    def stability(self, x: np.ndarray, target: StabilityTarget) -> tuple[np.ndarray, np.ndarray]:
        """The rows of ``target`` at x and their Jacobian in x."""
        _, dp = self.system(x)
        p, _ = self.setup.parameters(self.names, np.asarray(x, dtype=float))
        params = list(self.setup.family.parameters)
        values, jacs = [], []
        for track in target.tracks:
            family = self.setup.stability[track]
            rows = [params.index(n) for n in family.parameters]
            moving = [i for i, r in enumerate(rows) if np.any(dp[r] != 0.0)]  # only designed parameters
            p_fam = p[rows]
            g, J = root_constraints(family, p_fam, target.speeds, target.sigma_min, target.exclude, wrt=moving)
            values.append(g)
            jacs.append(J @ dp[[rows[i] for i in moving]])
            if target.zeta_min is not None:
                g, J = damping_constraints(family, p_fam, target.speeds, target.zeta_min, target.exclude, wrt=moving)
                values.append(g)
                jacs.append(J @ dp[[rows[i] for i in moving]])
        return np.concatenate(values), np.vstack(jacs)

    def constraints(self, x: np.ndarray, targets: Sequence[ResponseTarget],
                    stability: StabilityTarget | None) -> tuple[np.ndarray, np.ndarray]:
        parts = [self.maxima(x, targets)] if targets else []
        if stability is not None:
            parts.append(self.stability(x, stability))
        return np.concatenate([v for v, _ in parts]), np.vstack([j for _, j in parts])

    def __getstate__(self) -> dict:  # ship to dask workers without the cached system
        return {"setup": self.setup, "names": self.names, "_key": None, "_sys": None, "_dp": None}


def minimax_problem(
    setup: ModelSetup,
    variables: Sequence[DesignVariable],
    objective: ResponseTarget,
    constraints: Sequence[ResponseTarget] = (),
    limits: Sequence[float] = (),
    stability: StabilityTarget | None = None,
) -> MinimaxProblem:
    """min_x max_k f_k(x) of ``objective`` subject to the f_k of each constraint ≤ its limit and, with
    ``stability``, the stability rows ≤ 0."""
    names = [v.name for v in variables]
    unknown = [n for n in names if n not in setup.designable]
    if unknown:
        raise ValueError(f"variables: {unknown} are not parameters of the model; choose from {list(setup.designable)}")
    evaluator = _Evaluator(setup, names)
    if not constraints and stability is None:
        return MinimaxProblem(list(variables), lambda x: evaluator.maxima(x, [objective]), jacobian=True)
    if stability is not None:
        missing = [t for t in stability.tracks if t not in setup.stability]
        if missing:
            raise ValueError(f"stability.tracks: {missing} have no stability family in this model; it has "
                             f"{sorted(setup.stability)}")
    epsilon = np.repeat(np.asarray(limits, dtype=float), setup.family.n + 2)  # n + 2 maxima per constraint
    if stability is not None:
        epsilon = np.concatenate([epsilon, np.zeros(stability.rows(setup))])
    targets = list(constraints)
    return MinimaxProblem(
        list(variables),
        lambda x: evaluator.maxima(x, [objective]),
        jacobian=True,
        constraints=lambda x: evaluator.constraints(x, targets, stability),
        constraint_jacobian=True,
        epsilon=epsilon,
    )
