"""Model layer: one parametric system family, analyses as free functions, track, contact and vehicle
physics (never imports design).

Core: :class:`LinearSystem` (one member: M, C, K, forcing, named outputs), :class:`ParametricSystem`
(the family, affine in parameters with a speed term; ``family.at(p, speed=S)``), and the analyses
:func:`response_maxima`, :func:`peak` (:mod:`~railopt.models.response_maxima`), the Jacobians
(:mod:`~railopt.models.sensitivity`), and stability (:mod:`~railopt.models.stability`).
"""

from railopt.models.forcing import DelayedTerm, DistanceForcing, Forcing
from railopt.models.modal import CONDITION_LIMIT, Modal, mode_order
from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.pole_residue import PoleResidue
from railopt.models.response_maxima import ResponseMaxima, all_response_maxima, peak, response_maxima
from railopt.models.system import LinearSystem, Output, Tangent

__all__ = [
    "CONDITION_LIMIT",
    "DelayedTerm",
    "DistanceForcing",
    "Forcing",
    "LinearSystem",
    "Modal",
    "Output",
    "ParameterPart",
    "ParametricSystem",
    "PoleResidue",
    "ResponseMaxima",
    "Tangent",
    "all_response_maxima",
    "mode_order",
    "peak",
    "response_maxima",
]
