"""Forced response of a vehicle view to rail irregularities (thesis §4.3.2, (4.60)–(4.70)).

The reduced equations with prescribed rail inputs u (``z = T x + T_in u``, (B.1.48), (B.2.42)) are

    M ẍ + C ẋ + K x = −(M_in ü + C_in u̇ + K_in u)                       (4.62), (4.63)

and an irregularity gives ``u(t) = Σ_i u_i e^{iΩ(t − d_i/S)}`` (one term per axle, d_i its distance
behind the leading axle, :mod:`railopt.models.vehicle.irregularity`), so

    Z(Ω) X = F(Ω) = −Σ_i (K_in + iΩ C_in + (iΩ)² M_in) u_i e^{−iΩ d_i/S}        (4.69), (4.70)

with ``Z = K − Ω²M + iΩC``.  :func:`family_forcing` writes F as
:class:`~railopt.models.forcing.DistanceForcing` parts of the view's family (the delays follow the
speed, the creep input ``C_in_creep/S`` is the family's forcing speed term), so
``view.family(names, input, outputs).at(p, speed=S)`` is a :class:`~railopt.models.system.LinearSystem`
whose band maxima are certified; :func:`forced_system` is that at the view's values and speed;
:func:`frequency_response` a table.  Outputs: :mod:`railopt.models.vehicle.outputs`.

Signs are ours (x forward, y left, z up, right-handed rotations; the thesis's pitch is −β, its
lateral −v: ``THESIS_SIGNS``), which changes phases by 180° but never amplitudes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from railopt.models.forcing import DistanceForcing, Forcing
from railopt.models.modal import growing_roots
from railopt.models.system import RESPONSE_ORDER, LinearSystem
from railopt.models.units import hz_to_rad_s
from railopt.models.validation import frequencies_rad_s
from railopt.models.vehicle.irregularity import Irregularity, RailInput, wavelength_m
from railopt.models.vehicle.outputs import UNIT_SUFFIX, PointOutput, output_rows

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.vehicle.views import VehicleView

Outputs = Sequence[str | PointOutput] | str | PointOutput


def check_quantity(quantity: str) -> str:
    """``quantity`` unchanged when it is ``displacement``, ``velocity`` or ``acceleration``.

    Raises ValueError naming the valid quantities otherwise.
    """
    if quantity not in RESPONSE_ORDER:
        raise ValueError(f"quantity: must be one of {sorted(RESPONSE_ORDER)}, got {quantity!r}")
    return quantity


def _axle_terms(view: VehicleView, input: Irregularity | RailInput) -> tuple[list[tuple[np.ndarray, float]], bool]:
    """Per axle (u_i, distance_m) for an Irregularity, or (u_i, delay_s) of a RailInput; True for distances."""
    if isinstance(input, RailInput):
        if tuple(input.inputs) != tuple(view.inputs):
            raise ValueError(f"input: RailInput over {list(input.inputs)} does not match the model's inputs "
                             f"{list(view.inputs)}")
        return list(input.terms), False
    if not isinstance(input, Irregularity):
        raise ValueError(f"input: must be an Irregularity or a RailInput, got {type(input).__name__}")
    if input.wavelength_m is not None:
        raise ValueError("input.wavelength_m: a fixed wavelength makes the speed vary with the frequency (S = f L), "
                         "but a LinearSystem has one speed; use frequency_response, or omit wavelength_m (then "
                         "f = S/L at the model's speed)")
    return input.axle_inputs(view.inputs, view.wheelsets, view.semi_gauge or 1.0), True


def _input_forcing(terms: list[tuple[np.ndarray, float]], distances: bool,
                   K: np.ndarray | None = None, C: np.ndarray | None = None, M: np.ndarray | None = None):
    """``−Σ_i (K + iΩ C + (iΩ)² M) u_i e^{−iΩ d_i/S}``: a DistanceForcing (distances) or a delayed Forcing."""
    n = next(m for m in (K, C, M) if m is not None).shape[0]
    built = []
    for u, where in terms:
        coeffs = np.zeros((3, n))
        for j, mat in enumerate((K, C, M)):
            if mat is not None:
                coeffs[j] = -(mat @ u)
        built.append((coeffs, where))
    return DistanceForcing(built) if distances else Forcing.delayed(built)


def family_forcing(view: VehicleView, input: Irregularity | RailInput, base: dict[str, np.ndarray],
                   ids: Sequence[str]) -> tuple:
    """(F0, F_speed, [F_i]) of the family of ``view``: the constant input matrices ``base`` (every parameter not
    in ``ids`` folded in at its value), the creep input C_in_creep (divided by S in the family) and one part per id."""
    terms, distances = _axle_terms(view, input)
    F0 = _input_forcing(terms, distances, K=base["K_in"], C=base["C_in"], M=view.M_in)
    F_speed = _input_forcing(terms, distances, C=view.C_in_creep) if np.any(view.C_in_creep) else None
    parts = []
    for k in ids:
        kind, _ = view.parts[k]
        mat = view.in_parts[k]
        weights = {"K": mat} if kind == "K" else {"C": mat}
        parts.append(_input_forcing(terms, distances, **weights))
    return F0, F_speed, parts


def output_specs(view: VehicleView, outputs: Outputs, quantity: str,
                 input: Irregularity | RailInput | None) -> dict[str, tuple]:
    """Family outputs ``(row, quantity)``, plus the feedthrough ``Σ (d·u_i) e^{−iΩ d_i/S}`` when an output contains
    the input itself (e.g. a wheelset that follows the profile)."""
    quantity = check_quantity(quantity)
    specs: dict[str, tuple] = {}
    for r in output_rows(view, outputs):
        if r.has_feedthrough:
            if input is None:
                raise ValueError(f"outputs: {r.name!r} contains the rail input itself; give the input")
            terms, distances = _axle_terms(view, input)
            feed = [(np.array([r.feed @ u]), where) for u, where in terms]
            specs[r.name] = (r.row, quantity, DistanceForcing(feed) if distances else Forcing.delayed(feed))
        else:
            specs[r.name] = (r.row, quantity)
    return specs


def forced_system(view: VehicleView, input: Irregularity | RailInput, outputs: Outputs,
                  quantity: str = "displacement") -> LinearSystem:
    """The :class:`LinearSystem` ``Z(Ω) X = F(Ω)`` of (4.69) at the view's values and speed, with named outputs.

    Its forcing declares one delay per axle, so band maxima are certified.
    """
    return view.family([], input=input, outputs=outputs, quantity=quantity).at()


def _frequencies(frequencies_hz) -> np.ndarray:
    f = frequencies_rad_s(frequencies_hz, "frequencies_hz")
    if f.size == 0:
        raise ValueError("frequencies_hz: empty; give at least one frequency in Hz")
    if np.any(f <= 0):
        raise ValueError(f"frequencies_hz: must be finite and > 0 Hz (f = S/L; f = 0 is an infinitely long wave), "
                         f"got {f[f <= 0][:5].tolist()}")
    return f


def _solve(system: LinearSystem, f: np.ndarray, names: list[str]) -> tuple[np.ndarray, np.ndarray, bool]:
    """Output values (N, outputs), the relative residuals ‖Z X − F‖∞ / ‖F‖∞ (N,) by direct solves, and whether a
    steady state exists (no root with Re s > 0)."""
    w = hz_to_rad_s(f)
    with np.errstate(over="ignore", invalid="ignore"):
        Z = system.impedance(w)
    if not np.all(np.isfinite(Z)):
        raise ValueError(f"frequencies_hz: Z(Ω) overflows at {f[~np.all(np.isfinite(Z), axis=(1, 2))][:3].tolist()} "
                         "Hz; no response can be computed there")
    F = system.forcing.values(w).reshape(len(w), -1)
    X = np.linalg.solve(Z, F[..., None])[..., 0]
    R = np.einsum("kij,kj->ki", Z, X) - F
    scale = np.maximum(np.max(np.abs(F), axis=1), np.finfo(float).tiny)
    Y = np.empty((len(w), len(names)), dtype=complex)
    for j, name in enumerate(names):
        o = system.outputs[name]
        feed = o.feedthrough_values(w) if o.feedthrough is not None else 0.0
        Y[:, j] = (X @ o.row + feed) * (1j * w) ** o.order
    return Y, np.max(np.abs(R), axis=1) / scale, growing_roots(system.eigenvalues()).size == 0


def frequency_response(view: VehicleView, frequencies_hz: Sequence[float] | np.ndarray,
                       input: Irregularity | RailInput, outputs: Outputs,
                       quantity: str = "displacement") -> pd.DataFrame:
    """Steady-state response to an irregularity at each frequency (4.67)–(4.70).

    Returns a DataFrame with one row per (output, frequency): ``frequency_hz``, ``wavelength_m``
    (= S/f), ``output``, ``quantity``, ``unit``, ``amplitude`` (≥ 0, per the irregularity's
    amplitude as given), ``phase_deg`` (relative to the profile at the leading axle), ``real``,
    ``imag``, ``residual`` (‖Z X − F‖∞/‖F‖∞ of the solve), ``track``, ``speed_m_s``, ``input``,
    ``steady_state`` (False where a root has Re s > 0 at that speed: the amplitude is then the formal
    Z⁻¹F, not a response the vehicle reaches — it hunts).
    The view's speed is used unless the irregularity fixes its wavelength (then S = f L per row).

    Raises
    ------
    ValueError
        Frequencies not positive finite numbers (naming ``frequencies_hz``), an unknown output or quantity.
    """
    quantity = check_quantity(quantity)
    rows = output_rows(view, outputs)
    f = _frequencies(frequencies_hz)
    names = [r.name for r in rows]
    fixed = isinstance(input, Irregularity) and input.wavelength_m is not None
    family = view.family([], input=replace(input, wavelength_m=None) if fixed else input, outputs=outputs,
                         quantity=quantity)
    if fixed:
        speed = f * input.wavelength_m
        parts = [_solve(family.at(speed=float(s)), f[i:i + 1], names) for i, s in enumerate(speed)]
        Y, residual = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
        steady = np.array([p[2] for p in parts])
    else:
        if view.speed is None:
            raise ValueError("speed: this view has no forward speed; use .at_speed(S) with S in m/s")
        speed = np.full(len(f), view.speed)
        Y, residual, stable = _solve(family.at(), f, names)
        steady = np.full(len(f), stable)
    label = input.label if isinstance(input, Irregularity | RailInput) else str(input)
    frames = []
    for j, r in enumerate(rows):
        y = Y[:, j]
        frames.append(pd.DataFrame({
            "frequency_hz": f, "wavelength_m": wavelength_m(f, speed), "output": r.name,
            "quantity": quantity, "unit": r.unit + UNIT_SUFFIX[quantity], "amplitude": np.abs(y),
            "phase_deg": np.degrees(np.angle(y)), "real": y.real, "imag": y.imag, "residual": residual,
            "track": view.track, "speed_m_s": speed, "input": label, "steady_state": steady,
        }))
    return pd.concat(frames, ignore_index=True)


def forced_parametric(view: VehicleView, input: Irregularity | RailInput, names: Sequence[str], outputs: Outputs,
                      quantity: str = "displacement"):
    """The forced family in suspension parameters ``names`` (ids or aliases); see ``VehicleView.family``."""
    return view.family(names, input=input, outputs=outputs, quantity=quantity)


__all__ = ["check_quantity", "family_forcing", "forced_parametric", "forced_system", "frequency_response",
           "output_specs"]
