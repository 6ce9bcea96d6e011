"""The one adapter from a model to the design layer: ModelSetup + config → MinimaxProblem.

The objective is the vector f_k (4.71)–(4.73) of one output over a band; optional constraints are
the f_k of other outputs held below a limit (ε-constraint trade-offs, g(x) ≤ ε).  Gradients are
analytic: ``df/dx = df/dp · dp/dx`` (model Jacobian, then the parameter map of the setup).  The
objective and the constraints at one x share one system and one eigen-decomposition.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from railopt.design import DesignVariable, MinimaxProblem
from railopt.models import LinearSystem
from railopt.models.sensitivity import maxima_jacobians
from railopt.studies.catalog import ModelSetup

__all__ = ["ResponseTarget", "minimax_problem"]


@dataclass(frozen=True)
class ResponseTarget:
    """The f_k of one output over a band (rad/s); ``exact`` picks the certified cell maxima."""

    output: str
    band: tuple[float, float]
    exact: bool = True


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
            rm, J = maxima_jacobians(sys, t.band, exact=t.exact, outputs=[t.output])[t.output]
            values.append(rm.values)
            jacs.append(J @ dp)
        return np.concatenate(values), np.vstack(jacs)

    def __getstate__(self) -> dict:  # ship to dask workers without the cached system
        return {"setup": self.setup, "names": self.names, "_key": None, "_sys": None, "_dp": None}


def minimax_problem(
    setup: ModelSetup,
    variables: Sequence[DesignVariable],
    objective: ResponseTarget,
    constraints: Sequence[ResponseTarget] = (),
    limits: Sequence[float] = (),
) -> MinimaxProblem:
    """min_x max_k f_k(x) of ``objective`` subject to the f_k of each constraint ≤ its limit."""
    names = [v.name for v in variables]
    unknown = [n for n in names if n not in setup.designable]
    if unknown:
        raise ValueError(f"variables: {unknown} are not parameters of the model; choose from {list(setup.designable)}")
    evaluator = _Evaluator(setup, names)
    if not constraints:
        return MinimaxProblem(list(variables), lambda x: evaluator.maxima(x, [objective]), jacobian=True)
    epsilon = np.repeat(np.asarray(limits, dtype=float), setup.family.n + 2)  # n + 2 maxima per constraint
    return MinimaxProblem(
        list(variables),
        lambda x: evaluator.maxima(x, [objective]),
        jacobian=True,
        constraints=lambda x: evaluator.maxima(x, list(constraints)),
        constraint_jacobian=True,
        epsilon=epsilon,
    )
