"""The minimax problem: design variables → a fixed-length vector f_k(x), U(x) = max_k f_k(x).

Thesis eqs. (4.74)-(4.75): ``U(x_opt) = min_x max_k f_k(x)`` subject to bounds on x and,
optionally, extra constraints ``g(x) ≤ ε`` (ε-constraint trade-offs).  The design layer never
imports the model layer: ``functions`` is any callable.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from railopt.design.variables import DesignVariable, Space

VectorFunction = Callable[[np.ndarray], np.ndarray]


class ProblemDefinitionError(ValueError):
    """The problem's definition is inconsistent (e.g. ``epsilon`` of a length other than the number of constraints
    found at the first evaluation): not a failure of the model at one x, so :func:`~railopt.design.solve.solve`
    raises it instead of reporting a status."""


@dataclass(frozen=True)
class Evaluation:
    """f (m,), g (p,) and, when asked for, their Jacobians (m, d), (p, d), all in x units."""

    f: np.ndarray
    g: np.ndarray
    df: np.ndarray | None = None
    dg: np.ndarray | None = None
    replaced: tuple[str, ...] = ()  # supplied Jacobian entries that were not finite, replaced by differences

    @property
    def value(self) -> float:
        """U(x) = max_k f_k (4.74); +inf when any f_k is not finite."""
        return float(np.max(self.f)) if np.all(np.isfinite(self.f)) else float("inf")


class MinimaxProblem:
    """min_x max_k f_k(x) over box bounds, optionally subject to g(x) ≤ epsilon.

    Parameters
    ----------
    variables : sequence of DesignVariable
        Names, bounds, scaling.
    functions : callable
        ``functions(x) -> (m,)`` array; with ``jacobian=True`` it returns ``(f, df)``.
    jacobian : callable, True or None
        ``jacobian(x) -> (m, d)``; ``True`` when ``functions`` returns both; ``None`` for
        central finite differences.  Infinite or NaN entries of a supplied Jacobian where f is
        finite (e.g. d√c/dc at c = 0) are replaced by finite differences (one-sided at a bound).
    constraints, constraint_jacobian : callable, optional
        ``g(x) -> (p,)`` and its Jacobian (same conventions as above).
    epsilon : float or (p,) array
        Right-hand side of g(x) ≤ ε: a scalar applies to every constraint (whatever their number); an array
        needs one value per constraint.  A wrong length is a ``ValueError`` naming ``epsilon``: here when the count
        is known (``n_constraints``), otherwise at the first evaluation (when ``constraints`` first returns).
    fd_step : float
        Relative finite-difference step (of each variable's range).
    refine : callable, optional
        Semi-infinite constraints by exchange (constraint generation): ``refine(x) -> MinimaxProblem | None``
        certifies a solved design against the continuum the rows sample (e.g. every speed of a range) and returns
        the problem with rows added where it is violated, or None when ``x`` is certified.  :func:`solve` then
        resumes from ``x`` on the refined problem, up to ``MAX_EXCHANGES`` rounds.
    n_constraints : int, optional
        The number p of values ``constraints`` returns, when known in advance: ``epsilon`` is checked against it
        here, and every evaluation must return p values (a ``ValueError`` naming ``constraints`` otherwise).
        Without it p is learnt from the first evaluation.
    batch_functions : callable, optional
        ``batch_functions(X) -> (B, m)``: f at B designs at once (X of shape (B, d)), the same function as
        ``functions`` row by row, with a row of +inf where the model refuses a design.  :meth:`values` (objective
        surfaces, grid scans) uses it; the solvers keep ``functions``.

    Raises
    ------
    ValueError
        Naming the field: a non-callable ``functions``, ``jacobian``, ``constraints`` or ``refine``; ``epsilon`` not
        finite, not a scalar or 1-D, of a length other than ``n_constraints``, or an array without constraints;
        ``n_constraints`` not a positive integer, or given without constraints.
    """

    def __init__(
        self,
        variables: Sequence[DesignVariable],
        functions: VectorFunction,
        jacobian: VectorFunction | bool | None = None,
        constraints: VectorFunction | None = None,
        constraint_jacobian: VectorFunction | bool | None = None,
        epsilon: float | Sequence[float] = 0.0,
        fd_step: float = 1e-6,
        refine: Callable[[np.ndarray], MinimaxProblem | None] | None = None,
        n_constraints: int | None = None,
        batch_functions: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.space = Space(variables)
        if batch_functions is not None and not callable(batch_functions):
            raise ValueError("batch_functions: must be callable, X (B, d) -> (B, m) array")
        self._batch_functions = batch_functions
        if refine is not None and not callable(refine):
            raise ValueError("refine: must be callable, x -> MinimaxProblem or None")
        self.refine = refine
        if not callable(functions):
            raise ValueError("functions: must be callable, x -> (m,) array")
        if jacobian is not None and jacobian is not True and not callable(jacobian):
            raise ValueError("jacobian: must be a callable, True or None")
        if constraints is not None and not callable(constraints):
            raise ValueError("constraints: must be callable, x -> (p,) array")
        self._functions = functions
        self._jacobian = jacobian
        self._constraints = constraints
        self._constraint_jacobian = constraint_jacobian
        try:
            eps = np.asarray(epsilon, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"epsilon: must be a number or a 1-D array of numbers, got {epsilon!r}") from exc
        if eps.ndim > 1 or eps.size == 0:
            raise ValueError(f"epsilon: must be a number or a non-empty 1-D array (one value per constraint), got "
                             f"shape {eps.shape}")
        if not np.all(np.isfinite(eps)):
            raise ValueError("epsilon: must be finite")
        if n_constraints is not None:
            if constraints is None:
                raise ValueError("n_constraints: given, but the problem has no constraints")
            if isinstance(n_constraints, bool) or not isinstance(n_constraints, numbers.Integral) or n_constraints < 1:
                raise ValueError(f"n_constraints: must be a positive integer, got {n_constraints!r}")
            n_constraints = int(n_constraints)
        if constraints is None and eps.size > 1:
            raise ValueError(f"epsilon: {eps.size} values, but the problem has no constraints")
        self._epsilon = np.atleast_1d(eps)
        self.n_constraints: int | None = None
        if n_constraints is not None:
            self._learn_constraint_count(n_constraints, "n_constraints")
        self.fd_step = float(fd_step)
        self.n_functions: int | None = None

    @property
    def epsilon(self) -> np.ndarray:
        """ε of g(x) ≤ ε, one value per constraint (shape (p,)) once p is known (``n_constraints`` or the first
        evaluation); before that, the values as given (a scalar as shape (1,))."""
        if self.n_constraints is not None and self._epsilon.size == 1:
            return np.full(self.n_constraints, self._epsilon[0])
        return self._epsilon.copy()

    def _learn_constraint_count(self, p: int, source: str) -> None:
        """Fix the number of constraints p (from ``n_constraints`` or the first evaluation) and check ε against it."""
        if self._epsilon.size not in (1, p):
            where = "n_constraints" if source == "n_constraints" else "values the constraints returned"
            raise ProblemDefinitionError(
                f"epsilon: has {self._epsilon.size} values, but there are {p} constraints ({where}: {p}); give one "
                "value per constraint, or a scalar for all")
        self.n_constraints = p

    def with_epsilon(self, epsilon: float | Sequence[float]) -> MinimaxProblem:
        """The same problem with another right-hand side ε of g(x) ≤ ε (ε-constraint sweeps)."""
        return self.with_constraints(self._constraints, self._constraint_jacobian, epsilon, self.n_constraints)

    def with_constraints(self, constraints: VectorFunction | None,
                         constraint_jacobian: VectorFunction | bool | None = None,
                         epsilon: float | Sequence[float] = 0.0, n_constraints: int | None = None) -> MinimaxProblem:
        """The same objective subject to other constraints g(x) ≤ ε (conventions as in the constructor); the
        exchange (``refine``) belongs to the constraints it refined and is not carried over."""
        return MinimaxProblem(self.variables, self._functions, self._jacobian, constraints, constraint_jacobian,
                              epsilon, self.fd_step, n_constraints=n_constraints,
                              batch_functions=self._batch_functions)

    @property
    def variables(self) -> tuple[DesignVariable, ...]:
        """The design variables, in the order of x."""
        return self.space.variables

    @property
    def has_constraints(self) -> bool:
        """True when the problem has constraint functions g_i(x) ≤ 0."""
        return self._constraints is not None

    @property
    def has_analytic_gradient(self) -> bool:
        """True when a Jacobian function was given (otherwise gradients are finite differences)."""
        return self._jacobian is not None

    # ------------------------------------------------------------------ evaluation
    def _vector(self, fun: VectorFunction, jac: VectorFunction | bool | None, x: np.ndarray, want_grad: bool,
                field: str, jac_field: str) -> tuple[np.ndarray, np.ndarray | None, tuple[str, ...]]:
        """Value of ``fun`` at x and, when asked, its Jacobian (supplied, returned with it, or FD).

        The third item names the entries of a supplied Jacobian that were not finite (where the value
        is) and were replaced by finite differences.
        """
        if jac is True:
            v, dv = fun(x)
        else:
            v = fun(x)
            dv = jac(x) if want_grad and callable(jac) else None
        v = self._as_vector(v, field)

        def values(y: np.ndarray) -> np.ndarray:
            return self._as_vector(fun(y)[0] if jac is True else fun(y), field)

        replaced: tuple[str, ...] = ()
        if want_grad and dv is None:  # finite differences: a wrong shape is the function's, not a Jacobian's
            dv = self._fd(values, x, field, len(v))
        elif dv is not None:
            dv = self._as_jacobian(dv, len(v), jac_field)
            # an infinite or NaN derivative of a finite value (√c at c = 0, a bound): finite differences
            # for those entries, one-sided into the box at a bound (the only side a solver can move to)
            bad = ~np.isfinite(dv) & np.isfinite(v)[:, None]
            if bad.any():
                replaced = tuple(f"d{field}[{k}]/d{self.space.names[i]} = {dv[k, i]}" for k, i in np.argwhere(bad))
                fd = self._fd(values, x, field, len(v), columns=np.flatnonzero(bad.any(axis=0)))
                dv = dv.copy()
                dv[bad] = fd[bad]
        return v, dv, replaced

    def _f(self, x: np.ndarray, want_grad: bool) -> tuple[np.ndarray, np.ndarray | None, tuple[str, ...]]:
        return self._vector(self._functions, self._jacobian, x, want_grad, "functions", "jacobian")

    def _g(self, x: np.ndarray, want_grad: bool) -> tuple[np.ndarray, np.ndarray | None, tuple[str, ...]]:
        if self._constraints is None:
            return np.zeros(0), (np.zeros((0, self.space.dim)) if want_grad else None), ()
        return self._vector(self._constraints, self._constraint_jacobian, x, want_grad, "constraints",
                            "constraint_jacobian")

    def evaluate(self, x: Sequence[float], gradient: bool = False) -> Evaluation:
        """Evaluate f (and g) at x; Jacobians when ``gradient`` (analytic or finite differences)."""
        x = np.asarray(x, dtype=float)
        f, df, f_replaced = self._f(x, gradient)
        g, dg, g_replaced = self._g(x, gradient)
        if self.n_functions is None:
            self.n_functions = len(f)
        elif len(f) != self.n_functions:
            raise ValueError(
                f"functions: returned {len(f)} values, earlier {self.n_functions}; the count must be fixed"
            )
        if self.has_constraints:
            if self.n_constraints is None:
                self._learn_constraint_count(len(g), "evaluation")
            elif len(g) != self.n_constraints:
                raise ValueError(f"constraints: returned {len(g)} values, expected {self.n_constraints}; the count "
                                 "must be fixed")
        return Evaluation(f, g, df, dg, f_replaced + g_replaced)

    def value(self, x: Sequence[float]) -> float:
        """U(x) = max_k f_k(x) (4.74)."""
        return self.evaluate(x).value

    def values(self, X: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        """U = max_k f_k at each row of X (B, d): shape (B,); +inf where the model refuses a design (a
        ``ValueError`` raised by ``functions``, or a row of +inf from ``batch_functions``) or any f_k is not finite.
        One call of ``batch_functions`` when given, else ``functions`` row by row; the constraints are not
        evaluated (a surface of U).

        Raises
        ------
        ValueError
            If X is not (B, d); if f returns NaN, or a count m other than at other designs (either path); if
            ``batch_functions`` returns another shape than (B, m).
        """
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.space.dim:
            raise ValueError(f"X: must have shape (B, {self.space.dim}), got {X.shape}")
        if self._batch_functions is None:
            rows = []
            for x in X:
                try:  # the model's own refusal of a design (a ValueError of ``functions``) is +inf ...
                    v = self._functions(x)
                except ValueError:
                    rows.append(None)
                    continue
                rows.append(self._as_vector(v[0] if self._jacobian is True else v, "functions"))  # ... NaN is not
            m = self._learn_function_count({len(r) for r in rows if r is not None}, "functions")
            if m == 0:  # every design refused before any evaluation told the count: U = +inf at each
                return np.full(len(X), np.inf)
            F = np.array([np.full(m, np.inf) if r is None else r for r in rows]).reshape(len(X), m)
        else:
            F = np.asarray(self._batch_functions(X), dtype=float)
            if F.ndim != 2 or F.shape[0] != len(X):
                raise ValueError(f"batch_functions: must return shape ({len(X)}, m), got {F.shape}")
            if np.any(np.isnan(F)):
                raise ValueError("batch_functions: returned NaN (use +inf for a refused design)")
            self._learn_function_count({F.shape[1]}, "batch_functions")
        return np.where(np.all(np.isfinite(F), axis=1), np.max(F, axis=1), np.inf)

    def _learn_function_count(self, counts: set[int], field: str) -> int:
        """The one number m of values f has (learnt here when no evaluation fixed it yet); 0 when unknown."""
        known = counts | ({self.n_functions} if self.n_functions is not None else set())
        if len(known) > 1:
            raise ValueError(f"{field}: returned {sorted(known)} values at different designs; the count must be fixed")
        if known and self.n_functions is None:
            self.n_functions = next(iter(known))
        return self.n_functions or 0

    @property
    def has_batch(self) -> bool:
        """True when ``batch_functions`` evaluates many designs in one call."""
        return self._batch_functions is not None

    def constraint_violation(self, x: Sequence[float], evaluation: Evaluation | None = None) -> float:
        """max(0, max_i g_i(x) − ε_i); 0 without constraints."""
        ev = evaluation if evaluation is not None else self.evaluate(x)
        if ev.g.size == 0:
            return 0.0
        excess = ev.g - self._rhs(ev.g)
        return float(max(0.0, np.max(np.where(np.isfinite(excess), excess, np.inf))))

    def _rhs(self, g: np.ndarray) -> np.ndarray:
        """ε broadcast to the shape of ``g`` (the count was checked when it was learnt)."""
        return np.broadcast_to(self._epsilon, g.shape)

    # ------------------------------------------------------------------ derivatives
    def _fd(self, fun: VectorFunction, x: np.ndarray, field: str = "functions", m: int | None = None,
            columns: Sequence[int] | np.ndarray | None = None) -> np.ndarray:
        """Central differences, steps of fd_step × range, one-sided at the bounds.

        Every step lies inside [lower, upper] (x itself is assumed inside).  ``m`` is the number of
        values ``fun`` returned at x; every step must return as many (a ``ValueError`` naming
        ``field`` otherwise).  ``columns``: only these variables (the other columns are 0).
        """
        sp = self.space
        m = len(fun(x)) if m is None else m

        def at(y: np.ndarray) -> np.ndarray:
            v = fun(y)
            if len(v) != m:
                raise ValueError(f"{field}: returned {len(v)} values at a finite-difference step, {m} at x; "
                                 "the count must be fixed")
            return v

        J = np.zeros((m, sp.dim))
        for i in range(sp.dim) if columns is None else (int(c) for c in columns):
            h = self.fd_step * (sp.upper[i] - sp.lower[i])
            xp, xm = x.copy(), x.copy()
            xp[i] = min(x[i] + h, sp.upper[i])
            xm[i] = max(x[i] - h, sp.lower[i])
            with np.errstate(invalid="ignore"):
                J[:, i] = (at(xp) - at(xm)) / (xp[i] - xm[i])
        J[~np.isfinite(J)] = 0.0  # a difference across an unbounded (inf) response carries no slope
        return J

    def gradient_check(self, x: Sequence[float]) -> float:
        """Largest |analytic − finite-difference| / (|FD| + 1e-8·max|f|) over the Jacobian of f."""
        if not self.has_analytic_gradient:
            raise ValueError("jacobian: the problem has no analytic gradient to check")
        x = np.asarray(x, dtype=float)
        f, df, _ = self._f(x, True)

        def fun(y: np.ndarray) -> np.ndarray:
            return self._f(y, False)[0]

        fd = self._fd(fun, x)
        scale = np.abs(fd) + 1e-8 * max(np.max(np.abs(f)), 1.0)
        return float(np.max(np.abs(df - fd) / scale))

    # ------------------------------------------------------------------ shape checks
    @staticmethod
    def _as_vector(a: object, field: str) -> np.ndarray:
        v = np.asarray(a, dtype=float)
        if v.ndim != 1 or v.size == 0:
            raise ValueError(f"{field}: must return a non-empty 1-D array, got shape {v.shape}")
        if np.any(np.isnan(v)):
            raise ValueError(f"{field}: returned NaN (use +inf for an unbounded response)")
        return v

    def _as_jacobian(self, a: object, m: int, field: str) -> np.ndarray:
        J = np.asarray(a, dtype=float)
        if J.shape != (m, self.space.dim):
            raise ValueError(f"{field}: must return shape ({m}, {self.space.dim}), got {J.shape}")
        return J


__all__ = ["Evaluation", "MinimaxProblem", "ProblemDefinitionError", "VectorFunction"]
