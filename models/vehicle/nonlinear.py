"""The nonlinear vehicle: the assembled linear suspension plus nonlinear wheel/rail forces.

Equations (independent coordinates q of the chosen block, z = T q the assembly's coordinates, rail inputs 0)::

    M q̈ + C q̇ + K q = Tᵀ Q(z, ż, S)            x = (q, q̇),   ẋ = (q̇, M⁻¹(Tᵀ Q − C q̇ − K q))

M, K, C are the assembly's without the linear contact terms (``assemble(vehicle, track, contact=False)``:
suspension, inertia and the contact constraints w = w_rail, α = ψ v of (4.7)), reduced by T exactly as the
linear views reduce them; Q are the wheelsets' nonlinear forces (:mod:`.wheelset_forces`) on their u, v, α, β,
γ rows, vectorised over the wheelsets.  With the linear model's conical forces
(:func:`~railopt.models.vehicle.wheelset_forces.linear_model_forces`) the linearisation at x = 0 is the
linear view's state matrix (4.53) to round-off: ``tests/models/vehicle/test_nonlinear_vehicle.py`` and
``docs/nonlinear_vehicle.md``.

``rhs(t, x, speed)`` is the right-hand side for :func:`scipy.integrate.solve_ivp` and for
:mod:`railopt.models.bifurcation`; ``jacobian(x, speed)`` is its Jacobian by central differences (the step
stated there; the contact forces have no closed-form derivative through a tabulated geometry).

Limits: rigid track (straight, no irregularity inputs); the wheelset roll follows the assembly's linear
constraint α = ψ v (ψ from the vehicle file), a tabulated geometry enters through the contact points only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from railopt.models.kernels import c_array
from railopt.models.vehicle.assembly import assemble
from railopt.models.vehicle.geometry import LATERAL_DOFS, VERTICAL_DOFS, coordinate, split
from railopt.models.vehicle.wheelset_forces import (
    FORCE_ROWS,
    WheelsetContactState,
    WheelsetForces,
    forward_speed,
    linear_model_forces,
)
from railopt.models.vehicle.wheelset_kernel import vehicle_jacobian, vehicle_rhs

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.vehicle.vehicle import Vehicle

BLOCKS = {"lateral": LATERAL_DOFS, "full": LATERAL_DOFS + VERTICAL_DOFS}

#: Relative step of :meth:`NonlinearVehicle.jacobian`: h_j = JACOBIAN_STEP · max(1, |x_j|) (SI units).
JACOBIAN_STEP = 1e-6


@dataclass(frozen=True, eq=False)
class NonlinearVehicle:
    """A vehicle with linear suspension and nonlinear wheel/rail forces, first-order form x = (q, q̇).

    Attributes
    ----------
    name : str
        Vehicle name.
    coordinates : tuple of str
        Independent coordinates q (``"<body>.<dof>"``), the same as the linear view of the block.
    M, K, C : (n, n) ndarray
        Reduced mass, suspension stiffness and suspension damping (SI).
    wheelsets : tuple of str
        Wheelset names, in the order of the force arrays.
    rows : (5, K) int ndarray
        Rows of the wheelsets' u, v, α, β, γ in the assembly's coordinates z.
    T_rows : (5K, n) ndarray
        Those rows of T (z = T q), flattened row by row of ``rows``.
    forces : WheelsetForces
        The nonlinear wheel/rail forces (the same for every wheelset).
    """

    name: str
    coordinates: tuple[str, ...]
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    wheelsets: tuple[str, ...]
    rows: np.ndarray
    T_rows: np.ndarray
    forces: WheelsetForces

    def __post_init__(self) -> None:
        Minv = np.linalg.inv(self.M)
        object.__setattr__(self, "_MK", c_array(Minv @ self.K))
        object.__setattr__(self, "_MC", c_array(Minv @ self.C))
        object.__setattr__(self, "_MB", c_array(Minv @ self.T_rows.T))
        object.__setattr__(self, "_T", c_array(self.T_rows))

    @property
    def n_dof(self) -> int:
        """Number of coordinates q (the state has twice as many)."""
        return len(self.coordinates)

    @property
    def state_names(self) -> tuple[str, ...]:
        """Names of x: the coordinates, then their rates (``"<coordinate>.rate"``)."""
        return self.coordinates + tuple(f"{c}.rate" for c in self.coordinates)

    def index(self, name: str) -> int:
        """Position of a coordinate (or ``"<coordinate>.rate"``) in x; ValueError naming the valid ones."""
        names = self.state_names
        if name not in names:
            raise ValueError(f"unknown state {name!r}; valid: {', '.join(names)}")
        return names.index(name)

    def _kernel_state(self, x: np.ndarray) -> np.ndarray:
        """x as the kernels' writeable C array of shape (2n,); the shape error of :meth:`_split` otherwise."""
        x = np.asarray(x, dtype=float)
        if x.shape != (2 * self.n_dof,):
            self._split(x)  # raises the shape error
        return c_array(x)

    def _split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = np.asarray(x, dtype=float)
        n = self.n_dof
        if x.shape != (2 * n,):
            raise ValueError(f"x: state of shape ({2 * n},) expected, got {x.shape}")
        return x[:n], x[n:]

    def wheelset_states(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and rates (5, K) of the wheelsets' u, v, α, β, γ at state x."""
        q, qd = self._split(x)
        k = len(self.wheelsets)
        return (self.T_rows @ q).reshape(len(FORCE_ROWS), k), (self.T_rows @ qd).reshape(len(FORCE_ROWS), k)

    def contact_forces(self, x: np.ndarray, speed: float) -> np.ndarray:
        """Generalised contact forces (5, K) on the wheelsets' u, v, α, β, γ rows at state x, speed (m/s)."""
        z, zd = self.wheelset_states(x)
        return self.forces.generalized_forces(z[1], z[4], zd[1], zd[2], zd[4], zd[0], zd[3], speed)

    def contact_state(self, x: np.ndarray, speed: float) -> WheelsetContactState:
        """Everything the wheel/rail forces compute at state x and speed (m/s): creepages, creep and normal forces,
        the wheels' vertical Q and lateral Y (N, arrays (2, K): left, right wheel of each of ``wheelsets``)."""
        z, zd = self.wheelset_states(x)
        return self.forces.evaluate(z[1], z[4], zd[1], zd[2], zd[4], zd[0], zd[3], speed)

    def rhs(self, t: float, x: np.ndarray, speed: float) -> np.ndarray:
        """ẋ at time t (unused: autonomous) and forward speed ``speed`` (m/s), shape (2n,): one compiled call
        (:func:`~railopt.models.vehicle.wheelset_kernel.vehicle_rhs`).

        Raises
        ------
        ValueError
            x of the wrong shape, and the errors of :meth:`WheelsetForces.evaluate` (a wheel that lifts is a
            :class:`~railopt.models.vehicle.wheelset_forces.WheelLift`)."""
        x = self._kernel_state(x)
        out = np.empty(x.size)
        info = np.zeros(2)
        status = vehicle_rhs(x, forward_speed(speed), self._MK, self._MC, self._MB, self._T,
                             *self.forces.kernel_arguments, out, info)
        self.forces.raise_status(status, info)
        return out

    def jacobian(self, x: np.ndarray, speed: float, step: float = JACOBIAN_STEP) -> np.ndarray:
        """∂ẋ/∂x (2n, 2n) by central differences, h_j = step · max(1, |x_j|) (error O(h²) plus round-off
        ≈ 1e-16 |f|/h: about 1e-11 relative at the default step at x = 0 for the bundled vehicles).

        The 4n perturbed states go through the wheel/rail forces in one compiled call (as 4n·K wheelsets,
        :func:`~railopt.models.vehicle.wheelset_kernel.vehicle_jacobian`), so a Jacobian costs about one
        right-hand side of 4n·K wheelsets plus small matrix products.

        Raises
        ------
        ValueError
            As :meth:`rhs`, for any of the perturbed states."""
        x = self._kernel_state(x)
        out = np.empty((x.size, x.size))
        info = np.zeros(2)
        status = vehicle_jacobian(x, forward_speed(speed), float(step), self._MK, self._MC, self._MB, self._T,
                                  *self.forces.kernel_arguments, out, info)
        self.forces.raise_status(status, info)
        return out


def nonlinear_vehicle(vehicle: Vehicle, forces: WheelsetForces | None = None, block: str = "lateral",
                      track: str = "rigid") -> NonlinearVehicle:
    """Build the :class:`NonlinearVehicle` of ``vehicle``.

    Parameters
    ----------
    vehicle : Vehicle
        A vehicle definition with wheelsets and a ``[contact]`` table.
    forces : WheelsetForces, optional
        The wheel/rail forces; default :func:`~railopt.models.vehicle.wheelset_forces.linear_model_forces` of
        the vehicle's contact (the conical geometry and linear creep law that reproduce the linear model).
    block : {"lateral", "full"}
        Coordinates: the lateral block (v, α, γ; the wheelsets' u and β held at zero, as in the linear lateral
        view) or all independent coordinates.
    track : {"rigid"}
        Only rigid track is built.

    Raises
    ------
    ValueError
        Flexible (or unknown) track, an unknown block, a vehicle without wheelsets.
    """
    if track != "rigid":
        raise ValueError(f"track: the nonlinear vehicle is built on rigid track only, got {track!r} (the lumped "
                         "track's roll and lateral motion are not in the nonlinear contact)")
    if block not in BLOCKS:
        raise ValueError(f"block: one of {tuple(BLOCKS)}, got {block!r}")
    wheelsets = tuple(b.name for b in vehicle.bodies if b.kind == "wheelset")
    if not wheelsets:
        raise ValueError(f"vehicle {vehicle.name!r}: no wheelsets, no wheel/rail forces")
    if forces is None:
        forces = linear_model_forces(vehicle.wheel_rail())
    a = assemble(vehicle, track, contact=False)
    dofs = BLOCKS[block]
    cols = [j for j, c in enumerate(a.independent) if split(c)[1] in dofs]
    T = a.T[:, cols]

    def red(m: np.ndarray) -> np.ndarray:
        return T.T @ m @ T

    index = {c: i for i, c in enumerate(a.coordinates)}
    rows = np.array([[index[coordinate(ws, d)] for ws in wheelsets] for d in FORCE_ROWS], dtype=int)
    return NonlinearVehicle(name=vehicle.name, coordinates=tuple(a.independent[j] for j in cols), M=red(a.M),
                            K=red(a.K()), C=red(a.C_const()), wheelsets=wheelsets, rows=rows,
                            T_rows=T[rows.reshape(-1)], forces=forces)


__all__ = ["BLOCKS", "JACOBIAN_STEP", "NonlinearVehicle", "nonlinear_vehicle"]
