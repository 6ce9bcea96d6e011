"""Reduced equations of motion of one block (lateral or longitudinal–vertical), plain numpy.

``M ẍ + (C0 + Σ p_i C_i + C_creep/S) ẋ + (K0 + Σ p_i K_i) x = F`` (4.50) in the independent
coordinates x; ``F(Ω) = −(K_in + iΩ C_in − Ω² M_in) u`` for prescribed rail inputs u (4.60)–(4.63)
(forced response: :mod:`railopt.models.vehicle.response`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.linalg as sla

from railopt.models.parametric import ParameterPart, ParametricSystem


def check_speed(speed: float) -> float:
    """Forward speed S in m/s, finite and positive (else a ValueError naming ``speed``)."""
    s = float(speed)
    if not math.isfinite(s) or s <= 0.0:
        raise ValueError(f"speed: forward speed must be a positive finite number of m/s, got {speed!r}")
    return s


@dataclass(frozen=True)
class VehicleModel:
    """Linear model of one block of coordinates.

    Attributes
    ----------
    coordinates : tuple of str
        Independent coordinates x (``"<body>.<dof>"``), m and rad.
    inputs : tuple of str
        Prescribed input coordinates u of this block.
    M, K0, C0, C_creep : (n, n) ndarray
        Mass, constant stiffness, constant damping, creep damping times speed (N·s).
    parts : dict
        Parameter id -> (``"K"`` or ``"C"``, weight matrix).
    values : dict
        Parameter id -> value (SI).
    M_in, K_in0, C_in0, C_in_creep : (n, m) ndarray
        Input matrices (constant parts); ``K_in_parts`` / ``C_in_parts`` per parameter.
    speed : float or None
        Forward speed S, m/s.
    output_rows : dict
        Named output rows (e.g. ``"cab.lateral"``): displacement of a point = row · x.
    track : str or None
        ``"rigid"`` or ``"flexible"`` (set by :class:`~railopt.models.vehicle.Vehicle`).
    vehicle : Vehicle or None
        The vehicle the model was built from (geometry for forced-response inputs and outputs).
    """

    coordinates: tuple[str, ...]
    inputs: tuple[str, ...]
    M: np.ndarray
    K0: np.ndarray
    C0: np.ndarray
    C_creep: np.ndarray
    parts: dict[str, tuple[str, np.ndarray]]
    values: dict[str, float]
    M_in: np.ndarray
    K_in0: np.ndarray
    C_in0: np.ndarray
    C_in_creep: np.ndarray
    in_parts: dict[str, np.ndarray] = field(default_factory=dict)
    speed: float | None = None
    output_rows: dict[str, np.ndarray] = field(default_factory=dict)
    aliases: dict[str, str] = field(default_factory=dict)
    track: str | None = None
    vehicle: Any = field(default=None, compare=False, repr=False)

    def _id(self, name: str) -> str:
        return self.aliases.get(name, name)

    def _check_names(self, names: Sequence[str]) -> None:
        bad = sorted(n for n in names if self._id(n) not in self.parts)
        if bad:
            valid = sorted(set(self.parts) | set(self.aliases))
            raise ValueError(f"unknown parameters {bad}; valid: {valid}")

    @property
    def n_dof(self) -> int:
        return len(self.coordinates)

    def _weighted(self, kind: str) -> np.ndarray:
        out = np.zeros_like(self.K0)
        for name, (k, mat) in self.parts.items():
            if k == kind:
                out += self.values[name] * mat
        return out

    @property
    def K(self) -> np.ndarray:
        """Stiffness (n, n), N/m, N/rad, N·m/rad."""
        return self.K0 + self._weighted("K")

    def _speed(self) -> float:
        if self.speed is None:
            raise ValueError("speed: this model has no forward speed; use .at_speed(S) with S in m/s")
        return self.speed

    @property
    def C_const(self) -> np.ndarray:
        """Speed-independent damping (suspension), N·s/m."""
        return self.C0 + self._weighted("C")

    @property
    def C(self) -> np.ndarray:
        """Damping at the model's speed: ``C_const + C_creep / S``."""
        return self.C_const + self.C_creep / self._speed()

    def at_speed(self, speed: float) -> VehicleModel:
        """The same model at forward speed ``speed`` (m/s)."""
        return replace(self, speed=check_speed(speed))

    def with_values(self, values: Mapping[str, float]) -> VehicleModel:
        """New suspension parameter values by id or alias (no re-assembly); unknown names raise."""
        self._check_names(list(values))
        new = dict(self.values)
        for k, v in values.items():
            v = float(v)
            if not math.isfinite(v):
                raise ValueError(f"{k}: value must be finite, got {v!r}")
            new[self._id(k)] = v
        return replace(self, values=new)

    def state_matrix(self) -> np.ndarray:
        """G of (4.53), (2n, 2n)."""
        n = self.n_dof
        mk = np.linalg.solve(self.M, np.hstack([self.K, self.C]))
        top = np.hstack([np.zeros((n, n)), np.eye(n)])
        return np.vstack([top, -mk])

    def eigenvalues(self) -> np.ndarray:
        """Roots s_j of (4.56), 1/s, sorted by decreasing real part."""
        s = sla.eigvals(self.state_matrix())
        return s[np.argsort(-s.real, kind="stable")]

    def eigen(self) -> tuple[np.ndarray, np.ndarray]:
        """Roots and the displacement part of the right eigenvectors (n, 2n)."""
        s, vec = sla.eig(self.state_matrix())
        order = np.argsort(-s.real, kind="stable")
        return s[order], vec[: self.n_dof, order]

    def input_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M_in, C_in, K_in)`` at the current values and speed: ``F(Ω) = −(K_in + iΩ C_in − Ω² M_in) u``."""
        K_in = self.K_in0.copy()
        C_in = self.C_in0 + self.C_in_creep / self._speed()
        for name, mat in self.in_parts.items():
            kind = self.parts[name][0]
            (K_in if kind == "K" else C_in)[...] += self.values[name] * mat
        return self.M_in, C_in, K_in

    def parametric(self, names: Sequence[str], output: str | None = None,
                   response: str = "displacement") -> ParametricSystem:
        """A :class:`~railopt.models.ParametricSystem` in the named suspension parameters (ids or aliases).

        The constant part holds every other term at the current values and speed; each named
        parameter contributes its assembled weight matrix.  Forcing is zero (the forced-response
        model adds its own); the output row is ``output`` of :attr:`output_rows` or the first
        coordinate.
        """
        names = list(names)
        self._check_names(names)
        ids = [self._id(n) for n in names]
        if len(set(ids)) != len(ids):
            raise ValueError(f"parameters {names} name one element id twice")
        base = replace(self, values={**self.values, **{k: 0.0 for k in ids}})
        parts = {}
        for name, k in zip(names, ids, strict=True):
            kind, mat = self.parts[k]
            parts[name] = ParameterPart(K=mat) if kind == "K" else ParameterPart(C=mat)
        if output is None:
            row = np.eye(self.n_dof)[0]
        else:
            if output not in self.output_rows:
                raise ValueError(f"output: unknown {output!r}; valid: {sorted(self.output_rows)}")
            row = self.output_rows[output]
        return ParametricSystem(base.M, base.C, base.K, np.zeros(self.n_dof), row, parts, response=response,
                                names=list(self.coordinates))

    # ------------------------------------------------------------------ forced response (delegates)
    def frequency_response(self, frequencies_hz, input, outputs, quantity: str = "displacement"):
        """Response table to a rail irregularity; see :func:`railopt.models.vehicle.response.frequency_response`."""
        from railopt.models.vehicle.response import frequency_response

        return frequency_response(self, frequencies_hz, input, outputs, quantity)

    def forced_system(self, input, outputs, quantity: str = "displacement"):
        """:class:`~railopt.models.LinearSystem` of the forced response; see
        :func:`railopt.models.vehicle.response.forced_system`."""
        from railopt.models.vehicle.response import forced_system

        return forced_system(self, input, outputs, quantity)

    def forced_parametric(self, input, names: Sequence[str], outputs, quantity: str = "displacement"):
        """:class:`~railopt.models.ParametricSystem` of the forced response in suspension parameters ``names``;
        see :func:`railopt.models.vehicle.response.forced_parametric`."""
        from railopt.models.vehicle.response import forced_parametric

        return forced_parametric(self, input, names, outputs, quantity)
