"""The records the figures take: frequency-response curves and panels, and the constraint boundaries of an
objective surface.  Small frozen dataclasses in place of nested tuples; the figures only draw them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Boundary", "FrfCurve", "FrfPanel"]


@dataclass(frozen=True)
class FrfCurve:
    """One curve of a frequency-response panel: its legend label, frequencies (Hz), values (``|H|`` or a PSD)
    and a style key of :data:`~railopt.studies.output.figures.FRF_STYLES` (any other key: cycled colours)."""

    label: str
    f_hz: np.ndarray
    values: np.ndarray
    style: str = ""

    @classmethod
    def of(cls, curve: FrfCurve | Sequence[Any]) -> FrfCurve:
        """A curve as it is, or from a ``(label, f_hz, values, style)`` tuple."""
        return curve if isinstance(curve, FrfCurve) else cls(*curve)


@dataclass(frozen=True)
class FrfPanel:
    """One panel of frequency-response curves: its title, y-axis label (quantity, unit, input) and curves."""

    title: str
    ylabel: str
    curves: tuple[FrfCurve, ...]

    @classmethod
    def of(cls, panel: FrfPanel | Sequence[Any]) -> FrfPanel:
        """A panel as it is, or from a ``(title, ylabel, curves)`` tuple (curves as :meth:`FrfCurve.of` takes)."""
        if isinstance(panel, FrfPanel):
            return panel
        title, ylabel, curves = panel
        return cls.build(title, ylabel, curves)

    @classmethod
    def build(cls, title: str, ylabel: str, curves: Sequence[FrfCurve | Sequence[Any]]) -> FrfPanel:
        """A panel of ``curves``, each a :class:`FrfCurve` or a ``(label, f_hz, values, style)`` tuple."""
        return cls(title, ylabel, tuple(FrfCurve.of(c) for c in curves))


@dataclass(frozen=True)
class Boundary:
    """A constraint's value on the constrained surface grid (``values[j, i]``) and its limit: the boundary is the
    contour ``values = limit``; feasible is ``values ≥ limit`` when ``at_least`` else ``values ≤ limit``."""

    label: str
    values: np.ndarray
    limit: float
    at_least: bool
