"""One block of an assembled vehicle (lateral, longitudinal–vertical or both): a view.

A view holds everything later stages need and nothing they must fetch again: the block's
independent coordinates x and rail inputs u, its reduced matrices (constant parts, one weight
matrix per suspension parameter, the creep damping times speed C_creep, the input matrices), the
rows of ``z = T x + T_in u`` (B.1.48) of every coordinate of the assembly, the bodies' CGs, the axle
positions and the semi-gauge.  The equations of the block are

    M ẍ + (C0 + Σ p_i C_i + C_creep/S) ẋ + (K0 + Σ p_i K_i) x = −(K_in + iΩ C_in − Ω² M_in) u      (4.50), (4.63)

and :meth:`VehicleView.family` turns them into the one
:class:`~railopt.models.parametric.ParametricSystem` with its speed term; stability, forced
response and design all start from it.  The pipeline is one-way: file → definition
(:class:`~railopt.models.vehicle.vehicle.Vehicle`) → assembly → view → outputs / irregularity inputs
→ forced systems (:mod:`railopt.models.vehicle.forced`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.system import LinearSystem
from railopt.models.validation import number
from railopt.models.vehicle.assembly import SuspensionMatrices

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from railopt.models.vehicle.irregularity import Irregularity, RailInput
    from railopt.models.vehicle.outputs import PointOutput


def check_speed(speed: float) -> float:
    """Forward speed S in m/s, finite and positive (else a ValueError naming ``speed``)."""
    try:
        return number("speed", speed, positive=True)
    except ValueError:
        raise ValueError(f"speed: forward speed must be a positive finite number of m/s, got {speed!r}") from None


@dataclass(frozen=True)
class BodyPlace:
    """A body of the assembly as a view sees it: name, kind and CG (m)."""

    name: str
    kind: str
    cg: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class VehicleView(SuspensionMatrices):
    """Linear model of one block of coordinates of an assembled vehicle.

    Attributes
    ----------
    name : str
        Vehicle name.
    track : str
        ``"rigid"`` or ``"flexible"``.
    coordinates : tuple of str
        Independent coordinates x (``"<body>.<dof>"``), m and rad.
    inputs : tuple of str
        Prescribed rail input coordinates u of this block.
    M, K0, C0, C_creep, parts, values
        The block's reduced matrices, as in :class:`~railopt.models.vehicle.assembly.SuspensionMatrices`.
    M_in, K_in0, C_in0, C_in_creep : (n, m) ndarray
        Input matrices (constant parts); ``in_parts`` per parameter id.
    speed : float or None
        Forward speed S, m/s.
    output_rows : dict
        Named displacement rows of x (e.g. ``"cab.lateral"``).
    aliases : dict
        Readable parameter name -> element id.
    all_coordinates : tuple of str
        Every coordinate z of the assembly.
    T, T_in : ndarray (n_z, n), (n_z, m)
        Rows of ``z = T x + T_in u`` for this block's x and u.
    bodies : tuple of BodyPlace
        The assembly's bodies (lumped track bodies included on flexible track).
    wheelsets : tuple of (str, float)
        Wheelset names and axle positions x (m).
    semi_gauge : float or None
        e0 (m) of the contact, for cross-level inputs.
    block_dofs : tuple of str
        The body coordinates this block spans (e.g. ``("v", "alpha", "gamma")``).
    groups : dict
        Body -> group for mode names: each truck frame (a body suspended from the car body) with the wheelsets
        and motors reached from it; lumped track bodies -> "track".
    main_body : str
        The car body (the file's first body).
    """

    name: str
    track: str
    M_in: np.ndarray
    K_in0: np.ndarray
    C_in0: np.ndarray
    C_in_creep: np.ndarray
    in_parts: dict[str, np.ndarray] = field(default_factory=dict)
    speed: float | None = None
    output_rows: dict[str, np.ndarray] = field(default_factory=dict)
    aliases: dict[str, str] = field(default_factory=dict)
    all_coordinates: tuple[str, ...] = ()
    T: np.ndarray | None = None
    T_in: np.ndarray | None = None
    bodies: tuple[BodyPlace, ...] = ()
    wheelsets: tuple[tuple[str, float], ...] = ()
    semi_gauge: float | None = None
    block_dofs: tuple[str, ...] = ()
    groups: dict[str, str] = field(default_factory=dict)
    main_body: str | None = None

    def __repr__(self) -> str:
        speed = "no speed" if self.speed is None else f"S={self.speed:g} m/s"
        return (f"VehicleView({self.name!r}, {self.track} track, {'/'.join(self.block_dofs)}, n={self.n_dof}, "
                f"{len(self.parts)} parameters, {speed})")

    # ------------------------------------------------------------------ parameters
    def _id(self, name: str) -> str:
        return self.aliases.get(name, name)

    def _check_names(self, names: Sequence[str]) -> None:
        bad = sorted(n for n in names if self._id(n) not in self.parts)
        if bad:
            valid = sorted(set(self.parts) | set(self.aliases))
            raise ValueError(f"unknown parameters {bad}; valid: {valid}")

    def _ids(self, names: Sequence[str] | None) -> tuple[list[str], list[str]]:
        names = list(self.parts) if names is None else list(names)
        self._check_names(names)
        ids = [self._id(n) for n in names]
        if len(set(ids)) != len(ids):
            raise ValueError(f"parameters {names} name one element id twice")
        return names, ids

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom of the view (its independent coordinates)."""
        return len(self.coordinates)

    def at_speed(self, speed: float) -> VehicleView:
        """The same view at forward speed ``speed`` (m/s)."""
        return replace(self, speed=check_speed(speed))

    def with_values(self, values: Mapping[str, float]) -> VehicleView:
        """New suspension parameter values by id or alias (no re-assembly); unknown names raise."""
        if not isinstance(values, Mapping):
            raise ValueError(f"values: must be a mapping of parameter names to numbers, got {type(values).__name__}")
        self._check_names(list(values))
        new = dict(self.values)
        for k, v in values.items():
            new[self._id(k)] = number(k, v)
        return replace(self, values=new)

    # ------------------------------------------------------------------ the family
    def _folded(self, ids: Sequence[str]) -> dict[str, np.ndarray]:
        """Constant matrices with every parameter not in ``ids`` at its value."""
        skip = tuple(ids)
        return {"K": self.weighted("K", self.K0, skip=skip), "C": self.weighted("C", self.C0, skip=skip),
                "K_in": self.weighted("K", self.K_in0, self.in_parts, skip),
                "C_in": self.weighted("C", self.C_in0, self.in_parts, skip)}

    def family(self, names: Sequence[str] | None = None, input: Irregularity | RailInput | None = None,
               outputs: Sequence[str | PointOutput] | str | PointOutput | None = None,
               quantity: str = "displacement") -> ParametricSystem:
        """The :class:`~railopt.models.parametric.ParametricSystem` of this view with its speed term.

        Parameters
        ----------
        names : sequence of str, optional
            Suspension parameters (element ids or aliases) of the family, in order; every other one is
            held at the view's value.  Default: every parameter of the view (element ids).
        input : Irregularity or RailInput, optional
            A rail irregularity forcing the view (4.63): each axle's input at its distance behind the
            leading axle, so the delays d/S follow the speed.  None: unforced (eigen-analysis).
        outputs : output names or PointOutput, optional
            Coordinates, named rows, body points, differences (:func:`~railopt.models.vehicle.outputs.output_row`).
        quantity : {"displacement", "velocity", "acceleration"}
            Quantity of every output.

        The family's values are the view's, its speed the view's speed (``family.at(speed=S)`` for another).
        """
        from railopt.models.vehicle.forced import family_forcing, output_specs

        names, ids = self._ids(names)
        base = self._folded(ids)
        parts = {}
        for name, k in zip(names, ids, strict=True):
            kind, mat = self.parts[k]
            parts[name] = ParameterPart(K=mat) if kind == "K" else ParameterPart(C=mat)
        F0 = F_speed = None
        specs = None
        if input is not None:
            F0, F_speed, part_forcing = family_forcing(self, input, base, ids)
            for name, F in zip(names, part_forcing, strict=True):
                parts[name] = replace(parts[name], F=F)
        if outputs is not None:
            specs = output_specs(self, outputs, quantity, input)
        return ParametricSystem(self.M, base["C"], base["K"], F0, parts=parts, names=self.coordinates, outputs=specs,
                                C_speed=self.C_creep, F_speed=F_speed,
                                values=[self.values[k] for k in ids], speed=self.speed,
                                groups=self.groups, main_body=self.main_body)

    @cached_property
    def _free(self) -> ParametricSystem:
        return self.family([])

    def at(self, speed: float | None = None) -> LinearSystem:
        """The unforced :class:`~railopt.models.system.LinearSystem` at the view's values, at ``speed`` (m/s;
        default the view's speed): what :mod:`railopt.models.stability` evaluates."""
        return self._free.at(speed=speed)

    # ------------------------------------------------------------------ matrices at the view's values and speed
    @property
    def K(self) -> np.ndarray:
        """Stiffness (n, n), N/m, N/rad, N·m/rad."""
        return self._folded([])["K"]

    @property
    def C_const(self) -> np.ndarray:
        """Speed-independent damping (suspension), N·s/m."""
        return self._folded([])["C"]

    @property
    def C(self) -> np.ndarray:
        """Damping at the view's speed: ``C_const + C_creep / S``."""
        return self.at().C

    def state_matrix(self) -> np.ndarray:
        """G of (4.53), (2n, 2n), at the view's speed."""
        return self.at().state_matrix()

    def eigenvalues(self) -> np.ndarray:
        """Roots s_j of (4.56), 1/s, at the view's speed, in railopt's one order
        (:func:`~railopt.models.modal.mode_order`)."""
        return self.at().eigenvalues()

    def input_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M_in, C_in, K_in)`` at the view's values and speed: ``F(Ω) = −(K_in + iΩ C_in − Ω² M_in) u``."""
        if self.speed is None:
            raise ValueError("speed: this view has no forward speed; use .at_speed(S) with S in m/s")
        folded = self._folded([])
        return self.M_in, folded["C_in"] + self.C_in_creep / self.speed, folded["K_in"]

    # ------------------------------------------------------------------ forced response (thin delegates)
    def forced_system(self, input: Irregularity | RailInput, outputs, quantity: str = "displacement") -> LinearSystem:
        """:class:`~railopt.models.system.LinearSystem` ``Z(Ω) X = F(Ω)`` of (4.69) at the view's values and speed,
        one declared delay per axle; see :func:`railopt.models.vehicle.forced.forced_system`."""
        from railopt.models.vehicle.forced import forced_system

        return forced_system(self, input, outputs, quantity)

    def forced_parametric(self, input: Irregularity | RailInput, names: Sequence[str], outputs,
                          quantity: str = "displacement") -> ParametricSystem:
        """The forced family in suspension parameters ``names``; see :meth:`family`."""
        return self.family(names, input=input, outputs=outputs, quantity=quantity)

    def frequency_response(self, frequencies_hz, input: Irregularity | RailInput, outputs,
                           quantity: str = "displacement") -> pd.DataFrame:
        """Response table; see :func:`railopt.models.vehicle.forced.frequency_response`."""
        from railopt.models.vehicle.forced import frequency_response

        return frequency_response(self, frequencies_hz, input, outputs, quantity)


VehicleModel = VehicleView  # the name of earlier releases


__all__ = ["BodyPlace", "VehicleModel", "VehicleView", "check_speed"]
