"""Nonlinear critical speed: limit cycles of an autonomous system continued in speed (generic machinery).

Any right-hand side ``rhs(t, x, speed) -> dx/dt`` plugs in: x of shape (n,), speed a scalar in m/s, t in s
(unused by the periodic-orbit parts, which assume an autonomous system).  Amplitudes are in the state's units,
frequencies in Hz, periods in s.  Method, tolerances and limits: ``docs/nonlinear_hunting.md``.

Public API
----------
* :class:`IntegrationSettings` (:mod:`.integration`) — solve_ivp method and tolerances (LSODA, rtol 1e-10,
  atol 1e-12 by default); :class:`ModelLimit`, raised by a right-hand side whose model stops applying.
* :class:`PoincareSection` (:mod:`.section`) — hyperplane x[index] = value crossed in ``direction``.
* :func:`detect_limit_cycle`, :class:`CycleTolerances`, :class:`CycleVerdict` (:mod:`.limit_cycle`) —
  amplitude, frequency and growth per cycle of a sampled coordinate; steady / decaying / growing / rest.
* :func:`speed_ramp`, :class:`Dwell`, :class:`RampResult` (:mod:`.ramp`) — descending ramp, state carried
  over, fold bracket.
* :func:`find_periodic_orbit`, :class:`PeriodicOrbit`, :class:`ShootingOptions` (:mod:`.periodic_orbit`) —
  Newton shooting on the section; Floquet multipliers from the variational equations.
* :func:`continue_periodic_orbit`, :class:`ContinuationOptions` (:mod:`.continuation`) — pseudo-arclength
  continuation in speed through folds.
* :class:`BifurcationDiagram`, :class:`Fold`, :class:`NonlinearCriticalSpeed` (:mod:`.diagram`).
* :func:`bifurcation_diagram` (:mod:`.critical_speed`) — ramp → shooting → continuation in one call.
"""

from railopt.models.bifurcation.continuation import ContinuationOptions, continue_periodic_orbit
from railopt.models.bifurcation.critical_speed import bifurcation_diagram
from railopt.models.bifurcation.diagram import BifurcationDiagram, Fold, NonlinearCriticalSpeed
from railopt.models.bifurcation.integration import IntegrationSettings, ModelLimit
from railopt.models.bifurcation.limit_cycle import CycleTolerances, CycleVerdict, detect_limit_cycle
from railopt.models.bifurcation.periodic_orbit import PeriodicOrbit, ShootingOptions, find_periodic_orbit
from railopt.models.bifurcation.ramp import Dwell, RampResult, speed_ramp
from railopt.models.bifurcation.section import PoincareSection

__all__ = [
    "BifurcationDiagram",
    "ContinuationOptions",
    "CycleTolerances",
    "CycleVerdict",
    "Dwell",
    "Fold",
    "IntegrationSettings",
    "ModelLimit",
    "NonlinearCriticalSpeed",
    "PeriodicOrbit",
    "PoincareSection",
    "RampResult",
    "ShootingOptions",
    "bifurcation_diagram",
    "continue_periodic_orbit",
    "detect_limit_cycle",
    "find_periodic_orbit",
    "speed_ramp",
]
