"""Design variables: a name, finite bounds and a scaling to the unit interval the solvers see."""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

SCALES = ("linear", "log")


@dataclass(frozen=True)
class DesignVariable:
    """One design variable ``lower ≤ x ≤ upper`` (units of the model parameter it drives).

    ``scale="log"`` maps log(x) linearly to [0, 1] (stiffnesses spanning decades); it needs
    ``lower > 0``.
    """

    name: str
    lower: float
    upper: float
    scale: str = "linear"

    def __post_init__(self) -> None:
        if not self.name or not isinstance(self.name, str):
            raise ValueError(f"name: a design variable needs a non-empty name, got {self.name!r}")
        for field_name in ("lower", "upper"):
            v = getattr(self, field_name)
            # any real number, numpy scalars included (np.float32, np.int64), but not a bool
            if not isinstance(v, numbers.Real) or isinstance(v, bool | np.bool_) or not math.isfinite(v):
                raise ValueError(f"{self.name}.{field_name}: must be a finite number, got {v!r}")
            object.__setattr__(self, field_name, float(v))
        if not self.upper > self.lower:
            raise ValueError(f"{self.name}: bounds inverted or empty, lower {self.lower} ≥ upper {self.upper}")
        if self.scale not in SCALES:
            raise ValueError(f"{self.name}.scale: must be one of {SCALES}, got {self.scale!r}")
        if self.scale == "log" and self.lower <= 0:
            raise ValueError(f"{self.name}.lower: log scale needs lower > 0, got {self.lower}")


class Space:
    """Vectorised map between design vectors x and unit-cube coordinates u ∈ [0, 1]^d."""

    def __init__(self, variables: Sequence[DesignVariable]) -> None:
        if not variables:
            raise ValueError("variables: at least one design variable is needed")
        names = [v.name for v in variables]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"variables: duplicate names {sorted(dup)}")
        self.variables = tuple(variables)
        self.names = tuple(names)
        self.lower = np.array([v.lower for v in variables], dtype=float)
        self.upper = np.array([v.upper for v in variables], dtype=float)
        self.log = np.array([v.scale == "log" for v in variables])
        self._lo = np.where(self.log, np.log(np.where(self.log, self.lower, 1.0)), self.lower)
        self._hi = np.where(self.log, np.log(np.where(self.log, self.upper, 1.0)), self.upper)

    @property
    def dim(self) -> int:
        """Number of design variables d."""
        return len(self.variables)

    def to_x(self, u: np.ndarray) -> np.ndarray:
        """Design x (units of each variable) at unit-cube coordinates u, shape (..., d).

        The result is always inside [lower, upper], and u = 0, 1 give the bounds exactly: the log map
        may round one or two ULP past a bound (0.3 → 0.30000000000000004), so the result is clipped;
        ``exp`` is evaluated on the log-scaled entries only (no overflow warning for large linear values).
        """
        u = np.asarray(u, dtype=float)
        y = self._lo + u * (self._hi - self._lo)
        with np.errstate(over="ignore"):  # u far outside [0, 1] on a log variable: clipped to the bound below
            x = np.where(self.log, np.exp(np.where(self.log, y, 0.0)), y)
        x = np.where(u <= 0.0, self.lower, np.where(u >= 1.0, self.upper, x))  # the bounds themselves, exactly
        return np.clip(x, self.lower, self.upper)

    def to_u(self, x: np.ndarray) -> np.ndarray:
        """Unit-cube coordinates u of design x, shape (..., d): the inverse of :meth:`to_x`.

        Linear variables map affinely, log variables through ``log x``; points outside the bounds give u outside [0, 1].
        """
        x = np.asarray(x, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(self.log, np.log(np.where(self.log, x, 1.0)), x)
        return (y - self._lo) / (self._hi - self._lo)

    def dx_du(self, u: np.ndarray) -> np.ndarray:
        """Diagonal of dx/du, shape (d,)."""
        span = self._hi - self._lo
        return np.where(self.log, self.to_x(u) * np.where(self.log, span, 1.0), span)

    def bound_violation(self, x: np.ndarray) -> float:
        """Largest bound excess of x, relative to each variable's range (0 when inside)."""
        x = np.asarray(x, dtype=float)
        span = self.upper - self.lower
        return float(np.max(np.maximum(0.0, np.maximum(self.lower - x, x - self.upper)) / span))

    def check_point(self, x: Sequence[float], field: str = "x0") -> np.ndarray:
        """x as a float array of shape (d,), checked and placed onto the bounds.

        Raises ValueError (prefixed by ``field``) for a wrong shape, a NaN or infinite entry, or a point outside
        the bounds by more than 1e-12 of a variable's range; within that tolerance the point is clipped.
        """
        x = np.asarray(x, dtype=float)
        if x.shape != (self.dim,):
            raise ValueError(f"{field}: expected {self.dim} values for {self.names}, got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise ValueError(f"{field}: contains NaN or infinite values")
        if self.bound_violation(x) > 1e-12:
            bad = [n for n, xi, lo, hi in zip(self.names, x, self.lower, self.upper, strict=True) if not lo <= xi <= hi]
            raise ValueError(f"{field}: outside the bounds for {bad}")
        return np.clip(x, self.lower, self.upper)  # within the 1e-12 tolerance: onto the bound, never past it


__all__ = ["SCALES", "DesignVariable", "Space"]
