"""Forced response of a vehicle model to rail irregularities (thesis §4.3.2, (4.60)–(4.70)).

The reduced equations with prescribed rail inputs u (``z = T x + T_in u``, (B.1.48), (B.2.42)) are

    M ẍ + C ẋ + K x = −(M_in ü + C_in u̇ + K_in u)                       (4.62), (4.63)

and an irregularity gives ``u(t) = Σ_i u_i e^{iΩ(t − τ_i)}`` (one term per axle, τ_i = its distance
behind the leading axle / S, :mod:`railopt.models.vehicle.irregularity`), so

    Z(Ω) X = F(Ω) = −Σ_i (K_in + iΩ C_in + (iΩ)² M_in) u_i e^{−iΩτ_i}        (4.69), (4.70)

with ``Z = K − Ω²M + iΩC``.  :func:`forced_system` returns this as a
:class:`~railopt.models.LinearSystem` whose forcing declares its delays (``Forcing.delayed``), so
``peak(band, exact=True)`` is certified; :func:`forced_parametric` gives the
:class:`~railopt.models.ParametricSystem` in named suspension parameters (their share of the input
matrices enters as parametric forcing) for the design layer; :func:`frequency_response` a table.

Outputs, by name:

* an independent coordinate of the block (``"body.w"``, ``"body.beta"``, ``"motor3.beta"``,
  ``"wheelset3_track.w"``), m or rad;
* any other coordinate of the block's bodies (``"wheelset3.w"``, ``"frame_rear.gamma"``) through
  the constraint rows ``z = T x + T_in u`` — some depend on the input directly (``wheelset3.w`` =
  track + rail profile): that part becomes the LinearSystem output's delayed feedthrough d(Ω);
* ``"<wheelset>_track.<dof>"`` on rigid track: identically zero (the rigid track does not move;
  the thesis's Fig 4.12 rigid curve);
* the model's named rows (``"cab.vertical"``, ``"cab.lateral"``, ``"cab.longitudinal"``);
* a body point ``"<body>[x, y, z].<x|y|z>"`` (offset from the body's CG in m, direction of the
  displacement), or a :class:`PointOutput` with any direction;
* a difference ``"<output> - <output>"`` (e.g. the primary stroke
  ``"frame_rear[-2.07,1,-0.25].z - wheelset1.w"``).

Signs are ours (x forward, y left, z up, right-handed rotations; the thesis's pitch is −β, its
lateral −v: ``THESIS_SIGNS``), which changes phases by 180° but never amplitudes.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from railopt.models.forcing import Forcing
from railopt.models.linear_system import RESPONSE_ORDER, LinearSystem
from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.vehicle.geometry import LATERAL_DOFS, VERTICAL_DOFS, point_jacobian, split, unit
from railopt.models.vehicle.irregularity import Irregularity, RailInput, wavelength_m

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.vehicle.model import VehicleModel

POINT = re.compile(r"^\s*(?P<body>[^\[\]\s]+)\s*\[(?P<offset>[^\]]*)\]\s*\.\s*(?P<dir>[xyz])\s*$")
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
ROTATIONS = ("alpha", "beta", "gamma")
UNIT_SUFFIX = {"displacement": "", "velocity": "/s", "acceleration": "/s²"}


@dataclass(frozen=True)
class PointOutput:
    """Displacement of a body point along a direction.

    Attributes
    ----------
    body : str
        Body name.
    offset_m : (3,) float
        Point relative to the body's CG (m), our axes.
    direction : str or (3,) float
        ``"x" | "y" | "z"`` or a vector (normalised).
    name : str or None
        Name in tables (default ``"<body>[x,y,z].<dir>"``).
    """

    body: str
    offset_m: tuple[float, float, float]
    direction: str | tuple[float, float, float] = "z"
    name: str | None = None

    @property
    def label(self) -> str:
        if self.name:
            return self.name
        off = ",".join(f"{c:g}" for c in self.offset_m)
        d = self.direction if isinstance(self.direction, str) else ",".join(f"{c:g}" for c in self.direction)
        return f"{self.body}[{off}].{d}"


@dataclass(frozen=True, eq=False)
class OutputRow:
    """One resolved output: ``y = row·x + feed·u`` (units ``unit`` per the input's units)."""

    name: str
    row: np.ndarray
    feed: np.ndarray
    unit: str

    @property
    def has_feedthrough(self) -> bool:
        return bool(np.any(self.feed != 0.0))


# ---------------------------------------------------------------------------------------------- geometry
def _source(model: VehicleModel):
    vehicle = getattr(model, "vehicle", None)
    track = getattr(model, "track", None)
    if vehicle is None or track is None:
        raise ValueError("model: carries no vehicle geometry (axle positions, constraint rows); build it with "
                         "Vehicle.vertical(...) or Vehicle.lateral(...)")
    return vehicle, track


def _block_transformation(model: VehicleModel):
    """``(assembly, T, T_in)`` with the columns of this block's x and u."""
    vehicle, track = _source(model)
    a = vehicle.assembly(track)
    cols = [a.independent.index(c) for c in model.coordinates]
    icols = [a.inputs.index(c) for c in model.inputs]
    return a, a.T[:, cols], a.T_in[:, icols]


def _block_dofs(model: VehicleModel) -> tuple[str, ...]:
    present = {split(c)[1] for c in model.coordinates}
    dofs: tuple[str, ...] = ()
    if present & set(LATERAL_DOFS):
        dofs += LATERAL_DOFS
    if present & set(VERTICAL_DOFS):
        dofs += VERTICAL_DOFS
    return dofs


def wheelset_positions(model: VehicleModel) -> list[tuple[str, float]]:
    """``[(wheelset name, x of its axle in m), ...]`` of the model's vehicle."""
    vehicle, _ = _source(model)
    return [(b.name, float(b.cg[0])) for b in vehicle.wheelsets()]


def _valid_names(model: VehicleModel) -> str:
    return (f"coordinates {list(model.coordinates)}, other '<body>.<dof>' of the block, rows "
            f"{sorted(model.output_rows)}, or body points '<body>[x,y,z].<x|y|z>'")


def output_row(model: VehicleModel, output: str | PointOutput) -> OutputRow:
    """Resolve one output name (or :class:`PointOutput`) into ``y = row·x + feed·u``."""
    n, m = model.n_dof, len(model.inputs)
    zero_feed = np.zeros(m)
    if isinstance(output, PointOutput):
        return _point_row(model, output)
    if not isinstance(output, str) or not output.strip():
        raise ValueError(f"outputs: an output must be a non-empty name or a PointOutput, got {output!r}")
    if " - " in output:  # a relative output, e.g. a suspension stroke "<frame point> - <wheelset>.w"
        first, _, second = output.partition(" - ")
        a, b = output_row(model, first.strip()), output_row(model, second.strip())
        if a.unit != b.unit:
            raise ValueError(f"outputs: {output!r} subtracts {b.unit} from {a.unit}")
        return OutputRow(output, a.row - b.row, a.feed - b.feed, a.unit)
    if output in model.coordinates:
        row = np.zeros(n)
        row[model.coordinates.index(output)] = 1.0
        return OutputRow(output, row, zero_feed, "rad" if split(output)[1] in ROTATIONS else "m")
    if output in model.output_rows:
        return OutputRow(output, np.asarray(model.output_rows[output], dtype=float), zero_feed, "m")
    match = POINT.match(output)
    if match:
        try:
            offset = tuple(float(c) for c in match["offset"].split(","))
        except ValueError:
            offset = ()
        if len(offset) != 3 or not all(np.isfinite(offset)):
            raise ValueError(f"outputs: {output!r}: the point offset must be three numbers in m, '<body>[x,y,z].<dir>'")
        return _point_row(model, PointOutput(match["body"], offset, match["dir"], name=output))
    body, dof = split(output)
    vehicle, track = _source(model)
    a, T, T_in = _block_transformation(model)
    if output in a.coordinates:
        if dof not in _block_dofs(model):
            raise ValueError(f"outputs: {output!r} is not a coordinate of this block (its coordinates are "
                             f"{_block_dofs(model)}); use the other model view")
        i = a.coordinates.index(output)
        return OutputRow(output, T[i].copy(), T_in[i].copy(), "rad" if dof in ROTATIONS else "m")
    wheelsets = {b.name for b in vehicle.wheelsets()}
    if track == "rigid" and body.endswith("_track") and body.removesuffix("_track") in wheelsets and dof in (
            _block_dofs(model)):
        return OutputRow(output, np.zeros(n), zero_feed, "rad" if dof in ROTATIONS else "m")
    raise ValueError(f"outputs: unknown output {output!r}; valid: {_valid_names(model)}")


def _point_row(model: VehicleModel, p: PointOutput) -> OutputRow:
    a, T, T_in = _block_transformation(model)
    names = [b.name for b in a.bodies]
    if p.body not in names:
        raise ValueError(f"outputs: {p.label!r}: unknown body {p.body!r}; bodies: {names}")
    if isinstance(p.direction, str):
        if p.direction not in AXES:
            raise ValueError(f"outputs: {p.label!r}: direction must be x, y, z or a vector, got {p.direction!r}")
        direction = np.array(AXES[p.direction])
    else:
        direction = unit(np.asarray(p.direction, dtype=float), f"outputs: {p.label!r} direction")
    jac = point_jacobian(np.asarray(p.offset_m, dtype=float))
    i = a.coordinates.index(f"{p.body}.u")
    rz = np.zeros(len(a.coordinates))
    rz[i:i + 6] = direction @ jac
    return OutputRow(p.label, rz @ T, rz @ T_in, "m")


# ---------------------------------------------------------------------------------------------- inputs
def rail_input(model: VehicleModel, input: Irregularity | RailInput) -> RailInput:
    """The delayed axle inputs of ``input`` for this model (an :class:`Irregularity` is placed on the
    vehicle's axles at the model's speed)."""
    if isinstance(input, RailInput):
        if tuple(input.inputs) != tuple(model.inputs):
            raise ValueError(f"input: RailInput over {list(input.inputs)} does not match the model's inputs "
                             f"{list(model.inputs)}")
        return input
    if not isinstance(input, Irregularity):
        raise ValueError(f"input: must be an Irregularity or a RailInput, got {type(input).__name__}")
    vehicle, _ = _source(model)
    speed = model._speed()
    return input.rail_input(model.inputs, wheelset_positions(model), speed, vehicle.wheel_rail().e0)


def _delayed(rail: RailInput, K: np.ndarray | None, C: np.ndarray | None, M: np.ndarray | None) -> Forcing:
    """``−Σ_i (K + iΩ C + (iΩ)² M) u_i e^{−iΩτ_i}`` as declared delayed terms."""
    terms = []
    for u, tau in rail.terms:
        coeffs = np.zeros((3, (K if K is not None else C if C is not None else M).shape[0]))
        for j, mat in enumerate((K, C, M)):
            if mat is not None:
                coeffs[j] = -(mat @ u)
        terms.append((coeffs, tau))
    return Forcing.delayed(terms)


def _fixed_speed(input: Irregularity | RailInput) -> None:
    if isinstance(input, Irregularity) and input.wavelength_m is not None:
        raise ValueError("input.wavelength_m: a fixed wavelength makes the speed vary with the frequency (S = f L), "
                         "but a LinearSystem has one speed; use frequency_response, or omit wavelength_m (then "
                         "f = S/L at the model's speed)")


def input_forcing(model: VehicleModel, input: Irregularity | RailInput) -> Forcing:
    """F(Ω) of (4.63) at the model's values and speed, with its delays declared."""
    _fixed_speed(input)
    rail = rail_input(model, input)
    M_in, C_in, K_in = model.input_matrices()
    return _delayed(rail, K_in, C_in, M_in)


# ---------------------------------------------------------------------------------------------- systems
def _check_quantity(quantity: str) -> str:
    if quantity not in RESPONSE_ORDER:
        raise ValueError(f"quantity: must be one of {sorted(RESPONSE_ORDER)}, got {quantity!r}")
    return quantity


def _rows(model: VehicleModel, outputs: Sequence[str | PointOutput] | str | PointOutput) -> list[OutputRow]:
    if isinstance(outputs, str | PointOutput):
        outputs = [outputs]
    outputs = list(outputs)
    if not outputs:
        raise ValueError("outputs: at least one output is needed")
    rows = [output_row(model, o) for o in outputs]
    names = [r.name for r in rows]
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise ValueError(f"outputs: repeated {dup}")
    return rows


def _output_specs(rows: list[OutputRow], rail: RailInput, quantity: str) -> dict[str, tuple]:
    """LinearSystem outputs: ``(row, quantity)``, plus the delayed feedthrough ``Σ (d·u_i) e^{−iΩτ_i}``
    when the output contains the input itself (e.g. a wheelset that follows the profile)."""
    specs: dict[str, tuple] = {}
    for r in rows:
        if r.has_feedthrough:
            feed = Forcing.delayed([(np.array([r.feed @ u]), tau) for u, tau in rail.terms])
            specs[r.name] = (r.row, quantity, feed)
        else:
            specs[r.name] = (r.row, quantity)
    return specs


def forced_system(model: VehicleModel, input: Irregularity | RailInput,
                  outputs: Sequence[str | PointOutput] | str | PointOutput,
                  quantity: str = "displacement") -> LinearSystem:
    """The :class:`LinearSystem` ``Z(Ω) X = F(Ω)`` of (4.69) for one irregularity, with named outputs.

    Its forcing is ``Forcing.delayed`` (one term per axle), so band maxima are certified.
    """
    quantity = _check_quantity(quantity)
    rows = _rows(model, outputs)
    forcing = input_forcing(model, input)
    return LinearSystem(model.M, model.C, model.K, forcing, names=model.coordinates,
                        outputs=_output_specs(rows, rail_input(model, input), quantity))


def forced_parametric(model: VehicleModel, input: Irregularity | RailInput, names: Sequence[str],
                      outputs: Sequence[str | PointOutput] | str | PointOutput,
                      quantity: str = "displacement") -> ParametricSystem:
    """The forced model as a :class:`ParametricSystem` in suspension parameters ``names`` (ids or aliases).

    Each named parameter contributes its stiffness or damping weight matrix and its share of the
    input matrices as a delayed parametric forcing; everything else is held at the model's values.
    """
    quantity = _check_quantity(quantity)
    names = list(names)
    model._check_names(names)
    ids = [model._id(n) for n in names]
    if len(set(ids)) != len(ids):
        raise ValueError(f"parameters {names} name one element id twice")
    rows = _rows(model, outputs)
    _fixed_speed(input)
    rail = rail_input(model, input)
    base = model.with_values({k: 0.0 for k in ids})
    M_in, C_in, K_in = base.input_matrices()
    parts = {}
    for name, k in zip(names, ids, strict=True):
        kind, mat = model.parts[k]
        in_mat = model.in_parts[k]
        if kind == "K":
            parts[name] = ParameterPart(K=mat, F=_delayed(rail, in_mat, None, None))
        else:
            parts[name] = ParameterPart(C=mat, F=_delayed(rail, None, in_mat, None))
    return ParametricSystem(base.M, base.C, base.K, _delayed(rail, K_in, C_in, M_in), parts=parts,
                            names=model.coordinates, outputs=_output_specs(rows, rail, quantity))


# ---------------------------------------------------------------------------------------------- table
def _frequencies(frequencies_hz: Sequence[float] | np.ndarray) -> np.ndarray:
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float)).ravel()
    if f.size == 0:
        raise ValueError("frequencies_hz: empty; give at least one frequency in Hz")
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        bad = f[~(np.isfinite(f) & (f > 0))]
        raise ValueError(f"frequencies_hz: must be finite and > 0 Hz (f = S/L; f = 0 is an infinitely long "
                         f"wave), got {bad[:5].tolist()}")
    return f


def solve(model: VehicleModel, frequencies_hz: Sequence[float] | np.ndarray,
          input: Irregularity | RailInput) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``X(Ω)`` (N, n), the input amplitudes ``u(Ω)`` (N, m), the relative residuals
    ``‖Z X − F‖∞ / ‖F‖∞`` (N,) and the speeds (N,) by direct solves at ``frequencies_hz``.

    A fixed-wavelength irregularity runs each frequency at its own speed S = f L.
    """
    f = _frequencies(frequencies_hz)
    if isinstance(input, Irregularity) and input.wavelength_m is not None:
        parts = [_solve(model.at_speed(fi * input.wavelength_m), np.array([fi]), input) for fi in f]
        X, U, R = (np.concatenate([p[i] for p in parts]) for i in range(3))
        return X, U, R, f * input.wavelength_m
    X, U, R = _solve(model, f, input)
    return X, U, R, np.full(len(f), model._speed())


def _solve(model: VehicleModel, f: np.ndarray, input: Irregularity | RailInput):
    rail = rail_input(model, input)
    M_in, C_in, K_in = model.input_matrices()
    w = 2 * np.pi * f
    M, C, K = model.M, model.C, model.K
    Z = K[None] - w[:, None, None] ** 2 * M[None] + 1j * w[:, None, None] * C[None]
    U = rail.value(w).reshape(len(w), -1)
    s = 1j * w[:, None, None]
    Zin = K_in[None] + s * C_in[None] + s**2 * M_in[None]
    F = -np.einsum("kij,kj->ki", Zin, U)
    X = np.linalg.solve(Z, F[..., None])[..., 0]
    R = np.einsum("kij,kj->ki", Z, X) - F
    scale = np.maximum(np.max(np.abs(F), axis=1), np.finfo(float).tiny)
    return X, U, np.max(np.abs(R), axis=1) / scale


def frequency_response(model: VehicleModel, frequencies_hz: Sequence[float] | np.ndarray,
                       input: Irregularity | RailInput,
                       outputs: Sequence[str | PointOutput] | str | PointOutput,
                       quantity: str = "displacement") -> pd.DataFrame:
    """Steady-state response to an irregularity at each frequency (4.67)–(4.70).

    Returns a DataFrame with one row per (output, frequency): ``frequency_hz``, ``wavelength_m``
    (= S/f), ``output``, ``quantity``, ``unit``, ``amplitude`` (≥ 0, per the irregularity's
    amplitude as given), ``phase_deg`` (relative to the profile at the leading axle), ``real``,
    ``imag``, ``residual`` (‖Z X − F‖∞/‖F‖∞ of the solve), ``track``, ``speed_m_s``, ``input``.
    The model's speed is used unless the irregularity fixes its wavelength (then S = f L per row).
    """
    quantity = _check_quantity(quantity)
    rows = _rows(model, outputs)
    f = _frequencies(frequencies_hz)
    X, U, residual, speed = solve(model, f, input)
    w = 2 * np.pi * f
    gain = (1j * w) ** RESPONSE_ORDER[quantity]
    _, track = _source(model)
    label = input.label if isinstance(input, Irregularity | RailInput) else str(input)
    frames = []
    for r in rows:
        y = (X @ r.row + U @ r.feed) * gain
        frames.append(pd.DataFrame({
            "frequency_hz": f, "wavelength_m": wavelength_m(f, speed), "output": r.name,
            "quantity": quantity, "unit": r.unit + UNIT_SUFFIX[quantity], "amplitude": np.abs(y),
            "phase_deg": np.degrees(np.angle(y)), "real": y.real, "imag": y.imag, "residual": residual,
            "track": track, "speed_m_s": speed, "input": label,
        }))
    return pd.concat(frames, ignore_index=True)


__all__ = [
    "OutputRow",
    "PointOutput",
    "forced_parametric",
    "forced_system",
    "frequency_response",
    "input_forcing",
    "output_row",
    "rail_input",
    "solve",
    "wheelset_positions",
]
