"""Argument checks of the contact modules: thin names over the model layer's :mod:`railopt.models.validation`.

Every error is a ``ValueError`` whose message starts with the argument name.
"""

from __future__ import annotations

from railopt.models.validation import number


def finite(name: str, value: object) -> float:
    """A finite real number."""
    return number(name, value)


def positive(name: str, value: object) -> float:
    """A finite real number > 0."""
    return number(name, value, positive=True)


def poisson(name: str, value: object) -> float:
    """Poisson's ratio in [0, 0.5]."""
    x = number(name, value)
    if not 0.0 <= x <= 0.5:
        raise ValueError(f"{name}: Poisson's ratio must lie in [0, 0.5], got {x}")
    return x
