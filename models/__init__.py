"""Model layer: linear systems, response maxima, track and vehicle models (never imports design)."""

from railopt.models.linear_system import Forcing, LinearSystem
from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.response_maxima import ResponseMaxima, response_maxima

__all__ = [
    "Forcing",
    "LinearSystem",
    "ParameterPart",
    "ParametricSystem",
    "ResponseMaxima",
    "response_maxima",
]
