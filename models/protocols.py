"""What the stability analyses accept: a speed family (:class:`SpeedFamily`) or a vehicle (:class:`LateralModel`).

Structural types only (:class:`typing.Protocol`): nothing here is checked at run time; the analyses in
:mod:`railopt.models.stability` keep recognising a model by its methods (``at`` and ``lateral``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from railopt.models.system import LinearSystem

__all__ = ["LateralModel", "SpeedFamily", "StabilityModel"]


class SpeedFamily(Protocol):
    """A model that gives one linear system per forward speed: what :func:`~railopt.models.stability.critical_speed`,
    :func:`~railopt.models.stability.root_locus`, :func:`~railopt.models.stability.least_damping`,
    :func:`~railopt.models.stability.spectral_abscissa` and :func:`~railopt.models.stability.modes` accept.

    Contract: ``at(speed=S)`` with ``S`` a forward speed in m/s (> 0, finite) returns the
    :class:`~railopt.models.system.LinearSystem` (M, C, K of n coordinates, named ``"<body>.<dof>"``) of the
    model at that speed; ``speed`` is passed by keyword only, so a family whose ``at`` also takes parameters
    first (``ParametricSystem.at(p=None, speed=None)``, p: its P parameter values, None for its own) fits as
    well as a vehicle view (``VehicleView.at(speed=None)``).  Each call may cost one assembly; the analyses
    then solve one eigenproblem of the state matrix per speed (thesis (4.53)).  Optional attributes read
    when present: ``groups`` (body → group, for mode names) and ``main_body`` (the car body).  A
    :class:`~railopt.models.system.LinearSystem` itself (one speed only) is refused with a ``ValueError``.
    """

    def at(self, *, speed: float) -> LinearSystem:
        """The system at forward speed ``speed`` (m/s)."""
        ...


class LateralModel(Protocol):
    """A vehicle definition: ``lateral(track)`` returns its lateral view on ``track`` ("rigid" or "flexible"),
    a :class:`SpeedFamily`.  The analyses take one with ``track=`` (default "rigid"); a model with both ``at``
    and ``lateral`` is used through ``at`` unless ``track`` is given."""

    def lateral(self, track: str = "rigid") -> SpeedFamily:
        """The lateral view of the vehicle on ``track``."""
        ...


StabilityModel = SpeedFamily | LateralModel
"""What the stability analyses take: a :class:`SpeedFamily`, or a :class:`LateralModel` (a vehicle) with ``track``."""
