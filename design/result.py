"""One result type every method fills, and one table of status codes."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from railopt.records import ArrayRecord

STATUSES: dict[str, str] = {
    "converged": "a stopping tolerance (xtol/ftol) was reached",
    "maxeval": "the evaluation limit was reached; best point kept",
    "maxtime": "the time limit was reached; best point kept",
    "roundoff_limited": "NLopt: roundoff errors limited progress; best point kept",
    "forced_stop": "the run was stopped by a callback; best point kept",
    "failure": "the solver failed (e.g. SLSQP's iteration limit or a singular QP); best point kept",
    "error": "the problem functions raised an exception; best point kept",
    "uncertified": "a semi-infinite constraint stayed violated after the exchange limit (MAX_EXCHANGES rounds of "
                   "rows added where the certificate found it violated); best point kept",
    "worker_lost": "the start killed every dask worker that ran it (a crash in native code, out of memory); "
                   "x = x0, U = inf; a resume skips it unless retry_failed",
}
SUCCESS_STATUSES = frozenset({"converged"})
FEASIBILITY_TOL = 1e-6


def succeeded(status: Any, constraint_violation: Any, bound_violation: Any, value: Any) -> Any:
    """The one success rule: a status in :data:`SUCCESS_STATUSES`, both violations within
    :data:`FEASIBILITY_TOL` and a finite value.  Scalars (one solve: a bool) or equal-length arrays/columns
    (a table of starts: a boolean array)."""
    if isinstance(status, str):
        return (status in SUCCESS_STATUSES and constraint_violation <= FEASIBILITY_TOL
                and bound_violation <= FEASIBILITY_TOL and np.isfinite(value))
    return (np.isin(np.asarray(status, dtype=object), sorted(SUCCESS_STATUSES))
            & (np.asarray(constraint_violation, dtype=float) <= FEASIBILITY_TOL)
            & (np.asarray(bound_violation, dtype=float) <= FEASIBILITY_TOL)
            & np.isfinite(np.asarray(value, dtype=float)))


@dataclass(frozen=True, eq=False, repr=False)
class SolveResult(ArrayRecord):
    """Outcome of one local solve, re-evaluated by railopt (not trusted from the solver).

    Attributes
    ----------
    x : (d,) ndarray
        Final design (the better of the solver's answer and the best point it evaluated).
    value : float
        U(x) = max_k f_k(x) re-evaluated at ``x``; +inf for an unbounded response.
    t : float
        Epigraph variable at the end of the solve (units of f); ``value − t`` is the slack the
        solver left.
    status : str
        A key of :data:`STATUSES`.
    message : str
        Solver detail (exception text, NLopt result code).
    evaluations : int
        Number of f evaluations (with or without gradient).
    wall_time : float
        Seconds of the whole solve, its certification (:attr:`MinimaxProblem.refine`) and exchange rounds included.
    method : str
        Registered method name.
    x0 : (d,) ndarray
        Start point.
    constraint_violation : float
        max(0, g(x) − ε) at ``x``.
    bound_violation : float
        Largest bound excess relative to the variable's range.
    functions : (m,) ndarray
        f_k(x) at ``x``.
    """

    x: np.ndarray
    value: float
    t: float
    status: str
    message: str
    evaluations: int
    wall_time: float
    method: str
    x0: np.ndarray
    constraint_violation: float = 0.0
    bound_violation: float = 0.0
    functions: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status: unknown status {self.status!r}")
        super().__post_init__()

    def __repr__(self) -> str:
        """Every field in full, one per line (like scipy's ``OptimizeResult``): ``x``, ``value`` (U), ``status``,
        ``success`` and the whole ``message`` first (strings unquoted); arrays with the shortest digits that
        round-trip."""
        def text(value: Any) -> str:
            if isinstance(value, np.ndarray):
                return np.array2string(value, separator=", ", floatmode="unique", max_line_width=100,
                                       threshold=10_000).replace("\n", "\n" + " " * 23)
            return value if isinstance(value, str) else repr(value)

        rows = [("x", self.x), ("value", self.value), ("status", self.status), ("success", self.success),
                ("message", self.message), ("method", self.method), ("evaluations", self.evaluations),
                ("wall_time", self.wall_time), ("t", self.t), ("constraint_violation", self.constraint_violation),
                ("bound_violation", self.bound_violation), ("x0", self.x0), ("functions", self.functions)]
        return "SolveResult(\n" + "".join(f"{name:>20s}: {text(value)}\n" for name, value in rows) + ")"

    def to_dict(self) -> dict[str, Any]:
        """Every field, arrays as lists of floats (JSON-ready)."""
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in asdict(self).items()}

    @property
    def feasible(self) -> bool:
        """True when the constraint and bound violations are both within ``FEASIBILITY_TOL``."""
        return self.constraint_violation <= FEASIBILITY_TOL and self.bound_violation <= FEASIBILITY_TOL

    @property
    def success(self) -> bool:
        """:func:`succeeded` of this result."""
        return bool(succeeded(self.status, self.constraint_violation, self.bound_violation, self.value))


__all__ = ["FEASIBILITY_TOL", "STATUSES", "SUCCESS_STATUSES", "SolveResult", "succeeded"]
