"""The Poincaré section: a hyperplane x[index] = value crossed in one direction.

For a hunting vehicle the natural section is a wheelset's lateral velocity (or displacement) through zero,
crossed upwards: each period of the cycle crosses it once in that direction.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PoincareSection:
    """The hyperplane ``x[index] = value`` of the state space, counted when crossed in ``direction``.

    Attributes
    ----------
    index : int
        The state coordinate fixed on the section (0 ≤ index < n).
    value : float
        Its value on the section (the state's units).
    direction : int
        +1: crossings with x[index] increasing; −1: decreasing.
    """

    index: int
    value: float = 0.0
    direction: int = 1

    def __post_init__(self) -> None:
        if not isinstance(self.index, int | np.integer) or self.index < 0:
            raise ValueError(f"index: must be a non-negative int, got {self.index!r}")
        if self.direction not in (1, -1):
            raise ValueError(f"direction: must be +1 or -1, got {self.direction!r}")
        if not np.isfinite(self.value):
            raise ValueError(f"value: must be finite, got {self.value!r}")

    def check(self, n: int) -> None:
        """ValueError unless the section's index fits a state of size ``n``."""
        if self.index >= n:
            raise ValueError(f"index: {self.index} is outside a state of size {n}")

    def free(self, n: int) -> np.ndarray:
        """The indices (n − 1,) of the coordinates that are free on the section."""
        return np.array([i for i in range(n) if i != self.index])

    def place(self, free_values: np.ndarray, n: int) -> np.ndarray:
        """The state (n,) on the section with the free coordinates ``free_values`` (n − 1,)."""
        x = np.empty(n)
        x[self.free(n)] = free_values
        x[self.index] = self.value
        return x

    def event(self) -> Callable[[float, np.ndarray], float]:
        """A terminal :func:`scipy.integrate.solve_ivp` event for this crossing (reads only y[index])."""

        def crossing(t: float, y: np.ndarray) -> float:
            return float(y[self.index] - self.value)

        crossing.terminal = True  # type: ignore[attr-defined]
        crossing.direction = float(self.direction)  # type: ignore[attr-defined]
        return crossing


__all__ = [
    "PoincareSection",
]
