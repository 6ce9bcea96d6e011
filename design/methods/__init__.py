"""Registered local minimax methods.  Every module of this package registers its methods with
:func:`~railopt.design.methods.base.register` when imported; the package imports them all (``pkgutil``),
so a new method is one new module here (bundled: ``slsqp``, ``cobyla`` (NLopt), ``slp`` (cvxpy LP))."""

import importlib
import pkgutil

from railopt.design.methods.base import METHODS, register

for _info in pkgutil.iter_modules(__path__):
    if _info.name != "base":
        importlib.import_module(f"{__name__}.{_info.name}")

__all__ = ["METHODS", "register"]
