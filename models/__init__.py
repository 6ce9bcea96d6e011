"""Model layer: linear systems, response maxima, track and vehicle models (never imports design)."""

from railopt.models.forcing import DelayedTerm, Forcing
from railopt.models.linear_system import LinearSystem, Output
from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.pole_residue import CONDITION_LIMIT, Modal, PoleResidue
from railopt.models.response_maxima import ResponseMaxima, all_response_maxima, response_maxima

__all__ = [
    "CONDITION_LIMIT",
    "DelayedTerm",
    "Forcing",
    "LinearSystem",
    "Modal",
    "Output",
    "ParameterPart",
    "ParametricSystem",
    "PoleResidue",
    "ResponseMaxima",
    "all_response_maxima",
    "response_maxima",
]
