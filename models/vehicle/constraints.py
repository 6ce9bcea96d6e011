"""Linear constraints ``z = T x + T_in u`` (thesis (B.1.48), (B.2.42)).

A constraint is a :class:`Relation` ``dependent = Σ c_j z_j``.  Relations may refer to other
dependent coordinates; :func:`transformation` resolves them by substitution, so ``T`` maps the
independent coordinates ``x`` (and prescribed input coordinates ``u``, e.g. rail irregularities)
to all coordinates ``z``.  The reduced equations are ``Tᵀ M T ẍ + …`` (B.1.49)–(B.1.50); internal
reactions do no work on admissible motions, so ``Tᵀ R = 0`` eliminates them (the thesis's
multiplier ``p = −ψ`` of the wheelset roll equation is exactly this projection).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.geometry import DOFS, coordinate, point_jacobian

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Relation:
    """``dependent = Σ coefficient · coordinate`` (an empty sum fixes the coordinate at 0)."""

    dependent: str
    terms: tuple[tuple[str, float], ...] = ()
    origin: str = ""


def fixed(body: str, dofs: Iterable[str], origin: str = "fixed") -> list[Relation]:
    """The listed coordinates of ``body`` held at zero."""
    return [Relation(coordinate(body, d), (), origin) for d in dofs]


def rigid_tie(body: Body, to: Body, dofs: Iterable[str], origin: str = "rigid") -> list[Relation]:
    """``body`` follows the rigid motion of ``to`` (at ``body``'s CG) in the listed coordinates."""
    jac = point_jacobian(np.subtract(body.cg, to.cg))
    out = []
    for d in dofs:
        i = DOFS.index(d)
        row = jac[i] if i < 3 else np.eye(6)[i]
        out.append(_relation(coordinate(body.name, d), to.name, row, origin))
    return out


def hinge(body: Body, to: Body, axis: str, point: Sequence[float] = (0.0, 0.0, 0.0),
          origin: str = "hinge") -> list[Relation]:
    """``body`` tied to ``to`` except a rotation about a coordinate axis through ``point``.

    ``point`` is relative to ``to``'s CG (m).  E.g. a traction motor on its axle: ``axis="y"``;
    the relative rotation is ``β_body − β_to`` and ``body.beta`` stays independent.
    """
    if axis not in AXES:
        raise ValueError(f"hinge {body.name!r}: axis must be one of {sorted(AXES)}, got {axis!r}")
    k = AXES[axis]
    r = np.subtract(body.cg, to.cg)
    a = np.eye(3)[k]
    lever = np.cross(a, r - np.asarray(point, dtype=float))  # translation per unit relative rotation
    jac = point_jacobian(r)
    out = []
    for i, d in enumerate(DOFS):
        if i == 3 + k:
            continue
        row = jac[i] if i < 3 else np.eye(6)[i]
        rel = _relation(coordinate(body.name, d), to.name, row, origin)
        if i < 3 and lever[i] != 0.0:
            extra = ((coordinate(body.name, DOFS[3 + k]), float(lever[i])),
                     (coordinate(to.name, DOFS[3 + k]), -float(lever[i])))
            rel = Relation(rel.dependent, rel.terms + extra, origin)
        out.append(rel)
    return out


def _relation(dependent: str, to: str, row: np.ndarray, origin: str) -> Relation:
    terms = tuple((coordinate(to, d), float(c)) for d, c in zip(DOFS, row, strict=True) if c != 0.0)
    return Relation(dependent, terms, origin)


def transformation(
    coordinates: Sequence[str], relations: Iterable[Relation], inputs: Sequence[str] = ()
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Resolve relations into ``z = T x + T_in u``.

    Parameters
    ----------
    coordinates : sequence of str
        All coordinates z (body coordinates and the input coordinates).
    relations : iterable of Relation
    inputs : sequence of str
        Prescribed input coordinates u (a subset of ``coordinates``).

    Returns
    -------
    T : (n_z, n_x) ndarray
    T_in : (n_z, n_u) ndarray
    independent : tuple of str
        Names of x, in ``coordinates`` order.
    """
    index = {c: i for i, c in enumerate(coordinates)}
    rel: dict[str, Relation] = {}
    for r in relations:
        if r.dependent not in index:
            raise ValueError(f"constraint {r.origin!r}: unknown coordinate {r.dependent!r}")
        if r.dependent in rel:
            first = rel[r.dependent].origin
            raise ValueError(f"coordinate {r.dependent!r} constrained twice ({first!r}, {r.origin!r})")
        for name, _ in r.terms:
            if name not in index:
                raise ValueError(f"constraint {r.origin!r}: unknown coordinate {name!r}")
        rel[r.dependent] = r
    input_set = set(inputs)
    independent = tuple(c for c in coordinates if c not in rel and c not in input_set)
    basis = {c: j for j, c in enumerate(independent)}
    in_basis = {c: j for j, c in enumerate(inputs)}
    nx, nu = len(independent), len(inputs)
    resolved: dict[str, np.ndarray] = {}

    def resolve(name: str, stack: tuple[str, ...]) -> np.ndarray:
        if name in resolved:
            return resolved[name]
        v = np.zeros(nx + nu)
        if name in basis:
            v[basis[name]] = 1.0
        elif name in in_basis:
            v[nx + in_basis[name]] = 1.0
        else:
            if name in stack:
                raise ValueError(f"circular constraints: {' -> '.join(stack + (name,))}")
            for other, c in rel[name].terms:
                v += c * resolve(other, stack + (name,))
        resolved[name] = v
        return v

    full = np.array([resolve(c, ()) for c in coordinates]).reshape(len(coordinates), nx + nu)
    return full[:, :nx], full[:, nx:], independent


def check_reduced_mass(M: np.ndarray, names: Sequence[str]) -> None:
    """Raise when an independent coordinate carries no mass (a massless coordinate must be constrained)."""
    bad = [n for n, m in zip(names, np.diag(M), strict=True) if not m > 0.0]
    if bad:
        raise ValueError(f"massless independent coordinates {bad}: give them inertia or constrain them")


__all__ = ["AXES", "Relation", "check_reduced_mass", "fixed", "hinge", "rigid_tie", "transformation"]
