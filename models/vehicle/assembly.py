"""Assemble M, K, C of all body coordinates and the constraint transformation (App. B method).

The assembly runs once per vehicle and track variant: suspension elements are stored as the
matrix multiplying their parameter (``K = K0 + Σ p_i K_i``), creep damping as ``C_creep`` (the
damping is ``C_creep / S``), so new parameter values or a new speed never re-run it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from railopt.models.parametric import affine
from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.constraints import Relation, fixed, hinge, rigid_tie, transformation
from railopt.models.vehicle.elements import GROUND, Element
from railopt.models.vehicle.geometry import DOFS, coordinate
from railopt.models.vehicle.wheelrail import contact_matrices

if TYPE_CHECKING:
    from railopt.models.vehicle.vehicle import Vehicle

TRACKS = ("rigid", "flexible")


@dataclass(frozen=True, eq=False)
class SuspensionMatrices:
    """Second-order matrices with one weight matrix per suspension parameter: what an assembly and a view share.

    ``K = K0 + Σ p_i K_i``, ``C = C0 + Σ p_i C_i + C_creep / S`` over the parameters in ``parts``
    ((4.50), the one summation being :func:`~railopt.models.parametric.affine`).

    Attributes
    ----------
    coordinates : tuple of str
        The coordinates the matrices span (``"<body>.<dof>"``).
    inputs : tuple of str
        Rail irregularity coordinates ``"<wheelset>_rail.v"`` (alignment), ``".w"`` (vertical
        profile) and on rigid track ``".alpha"`` (cross level).
    M, K0, C0, C_creep : (n, n) ndarray
        Mass, constant stiffness, constant damping, creep damping times speed (N·s).
    parts : dict
        Parameter id -> (``"K"`` or ``"C"``, weight matrix (n, n)).
    values : dict
        Parameter id -> value (SI).
    """

    coordinates: tuple[str, ...]
    inputs: tuple[str, ...]
    M: np.ndarray
    K0: np.ndarray
    C0: np.ndarray
    C_creep: np.ndarray
    parts: dict[str, tuple[str, np.ndarray]]
    values: dict[str, float]

    def weighted(self, kind: str, base: np.ndarray, stacks: dict[str, np.ndarray] | None = None,
                 skip: tuple[str, ...] = ()) -> np.ndarray:
        """``base + Σ p_i W_i`` over the parameters of ``kind`` (``"K"`` or ``"C"``) not in ``skip``, with
        ``W_i`` from ``stacks`` (parameter id -> matrix) or else the parameter's own weight matrix."""
        ids = [k for k, (kd, _) in self.parts.items() if kd == kind and k not in skip]
        mats = [self.parts[k][1] if stacks is None else stacks[k] for k in ids]
        stack = np.array(mats).reshape(len(ids), *base.shape)
        return affine(base, stack, np.array([self.values[k] for k in ids]))


@dataclass(frozen=True, eq=False)
class Assembly(SuspensionMatrices):
    """Matrices over all coordinates z (6 per body, then the prescribed inputs).

    Attributes
    ----------
    coordinates : tuple of str
        All coordinates z; the last ``len(inputs)`` are the prescribed inputs.
    bodies : tuple of Body
        Every body, the lumped track bodies included on flexible track.
    T, T_in : ndarray
        ``z = T x + T_in u`` (B.1.48).
    independent : tuple of str
        Names of x.

    The other attributes are those of :class:`SuspensionMatrices`.
    """

    bodies: tuple[Body, ...]
    T: np.ndarray
    T_in: np.ndarray
    independent: tuple[str, ...]

    def K(self) -> np.ndarray:
        """Full stiffness at the stored parameter values, N/m and N·m/rad."""
        return self.weighted("K", self.K0)

    def C_const(self) -> np.ndarray:
        """Speed-independent damping at the stored parameter values, N·s/m."""
        return self.weighted("C", self.C0)

    def C(self, speed: float) -> np.ndarray:
        """Full damping at forward speed ``speed`` (m/s): ``C_const + C_creep / S``."""
        return self.C_const() + self.C_creep / speed


def track_body_name(wheelset: str) -> str:
    """Name of the lumped-track body under ``wheelset`` on flexible track (``<wheelset>_track``)."""
    return f"{wheelset}_track"


def rail_name(wheelset: str) -> str:
    """Name of the rail under ``wheelset`` (``<wheelset>_rail``); its ``v``, ``w`` coordinates are inputs."""
    return f"{wheelset}_rail"


def assemble(vehicle: Vehicle, track: str = "rigid", contact: bool = True) -> Assembly:
    """Assemble the vehicle on ``"rigid"`` or ``"flexible"`` (lumped, (4.33)–(4.49)) track.

    ``contact=False`` leaves out the linear wheel/rail terms (creep, gravity stiffness, track-roll coupling
    of :func:`~railopt.models.vehicle.wheelrail.contact_matrices`) and keeps everything else, the contact
    constraints included: the suspension a nonlinear contact model adds its forces to
    (:mod:`railopt.models.vehicle.nonlinear`)."""
    if track not in TRACKS:
        raise ValueError(f"track: must be one of {TRACKS}, got {track!r}")
    wheelsets = [b for b in vehicle.bodies if b.kind == "wheelset"]
    bodies = list(vehicle.bodies)
    elements: list[Element] = []
    relations: list[Relation] = []
    wr = vehicle.wheel_rail() if wheelsets else None
    if track == "flexible":
        if vehicle.track is None:
            raise ValueError(f"vehicle {vehicle.name!r}: flexible track needs a [track] table")
        lt = vehicle.lumped_track()
        for ws in wheelsets:
            name = track_body_name(ws.name)
            inertia = (lt.roll_inertia, 0.0, 0.0)
            bodies.append(Body(name, lt.m_e_pair, inertia, (ws.cg[0], 0.0, 0.0), kind="track", source="lumped track"))
            for side in (1.0, -1.0):
                p = (0.0, side * wr.e0, 0.0)
                elements.append(Element("track_K_e", "track_stiffness", "spring", name, p, GROUND, p, (0, 0, 1),
                                        lt.K_e_prime))
                elements.append(Element("track_C_e", "track_damping", "damper", name, p, GROUND, p, (0, 0, 1),
                                        lt.C_e_prime))
            relations += fixed(name, ("u", "v", "beta", "gamma"), origin=f"lumped track {name}")
    inputs: list[str] = []
    for ws in wheelsets:
        rail = rail_name(ws.name)
        inputs += [coordinate(rail, "v"), coordinate(rail, "w")]
        if track == "rigid":
            inputs.append(coordinate(rail, "alpha"))
    coordinates = tuple(coordinate(b.name, d) for b in bodies for d in DOFS) + tuple(inputs)
    index = {c: i for i, c in enumerate(coordinates)}
    n = len(coordinates)
    byname = {b.name: b for b in bodies}

    M = np.zeros((n, n))
    for b in bodies:
        i = index[coordinate(b.name, "u")]
        M[i:i + 6, i:i + 6] = b.mass_matrix

    K0 = np.zeros((n, n))
    C0 = np.zeros((n, n))
    for e in elements:  # constant (track) elements
        (K0 if e.matrix == "K" else C0)[...] += e.value * e.unit_matrix(index, n)
    parts: dict[str, tuple[str, np.ndarray]] = {}
    values: dict[str, float] = {}
    for e in vehicle.elements:
        kind, mat = parts.setdefault(e.id, (e.matrix, np.zeros((n, n))))
        mat += e.unit_matrix(index, n)
        values[e.id] = e.value

    C_creep = np.zeros((n, n))
    for ws in wheelsets:
        rail = rail_name(ws.name)
        if track == "flexible":
            tb = track_body_name(ws.name)
            roll = coordinate(tb, "alpha")
            terms = ((coordinate(tb, "w"), 1.0), (coordinate(rail, "w"), 1.0))
            relations.append(Relation(coordinate(ws.name, "w"), terms, f"contact {ws.name}"))
        else:
            tb = None
            roll = coordinate(rail, "alpha")
            relations.append(Relation(coordinate(ws.name, "w"), ((coordinate(rail, "w"), 1.0),), f"contact {ws.name}"))
        relations.append(Relation(coordinate(ws.name, "alpha"),
                                  ((roll, 1.0), (coordinate(ws.name, "v"), wr.psi), (coordinate(rail, "v"), -wr.psi)),
                                  f"roll constraint (4.7) {ws.name}"))
        if contact:
            Kc, Cc = contact_matrices(wr, index, ws.name, roll, coordinate(rail, "v"), tb, n)
            K0 += Kc
            C_creep += Cc

    for c in vehicle.constraints:
        body = byname[c.body]
        if c.type == "fixed":
            relations += fixed(c.body, c.dofs, origin=f"fixed {c.body}")
        elif c.type == "rigid":
            relations += rigid_tie(body, byname[c.to], c.dofs, origin=f"rigid {c.body}->{c.to}")
        else:
            relations += hinge(body, byname[c.to], c.axis, c.point, origin=f"hinge {c.body}->{c.to}")
    T, T_in, independent = transformation(coordinates, relations, inputs)
    return Assembly(coordinates=coordinates, inputs=tuple(inputs), M=M, K0=K0, C0=C0, C_creep=C_creep, parts=parts,
                    values=values, bodies=tuple(bodies), T=T, T_in=T_in, independent=independent)


__all__ = ["Assembly", "SuspensionMatrices", "TRACKS", "assemble", "rail_name", "track_body_name"]
