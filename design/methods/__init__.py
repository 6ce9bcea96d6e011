"""Registered local minimax methods: ``slsqp`` and ``cobyla`` (NLopt), ``slp`` (cvxpy LP)."""

from railopt.design.methods import nlopt_methods, slp  # noqa: F401  (registration)
from railopt.design.methods.base import METHODS, register

__all__ = ["METHODS", "register"]
