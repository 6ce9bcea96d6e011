"""The thesis's simplified cab model for lateral ride (§4.3.3): the body on its secondary suspension.

"A simplified model of the locomotive on rigid track … assuming that the primary suspension and creep
forces have little effect on the lateral vibrations of the body": the truck frames follow the
lateral irregularity (alignment) of the rail, the rear one with the front one's input delayed, and
the body moves laterally, rolls and yaws (v, α, γ) on the secondary suspension between them.  The
output of the study is the cab point's lateral acceleration for an irregularity amplitude of
0.25 in.

Built from the same vehicle file as every other view: the assembled matrices over all coordinates
(:func:`~railopt.models.vehicle.assembly.assemble`) are cut to the body's lateral coordinates; the
frames' lateral coordinates become prescribed inputs ``u_f``, so the forcing is
``F(Ω) = −Σ_f (K_bf + iΩ C_bf) u_f`` (per suspension parameter, so it stays affine in the design).

**The frequency sweep.** The thesis sweeps the input frequency 0–3 Hz "which corresponds to a forward
speed of 150 mph for the known wave length", i.e. a fixed irregularity wavelength
λ = (150 mph) / (3 Hz) = 22.35 m and a speed S = λ f that rises with the frequency.  Then the delay
between the trucks, L/S, is a fixed *phase* 2πL/λ (L = distance between truck centres), not a delay
in Ω: ``mode="fixed_wavelength"`` (default).  ``mode="fixed_speed"`` instead holds S (150 mph) and
lets the wavelength vary: the rear input is then delayed by L/S in time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.forcing import Forcing
from railopt.models.parametric import ParameterPart, ParametricSystem
from railopt.models.units import INCH, MPH, hz_to_rad_s
from railopt.models.validation import number
from railopt.models.vehicle.geometry import point_jacobian

LATERAL = ("v", "alpha", "gamma")


@dataclass(frozen=True)
class CabInput:
    """The lateral irregularity of the cab study: amplitude (m), band top (Hz) and the speed at it (m/s)."""

    amplitude_m: float = 0.25 * INCH
    max_frequency_hz: float = 3.0
    max_speed_m_s: float = 150 * MPH
    mode: str = "fixed_wavelength"

    def __post_init__(self) -> None:
        number("amplitude_m", self.amplitude_m, positive=True)
        number("max_frequency_hz", self.max_frequency_hz, positive=True)
        number("max_speed_m_s", self.max_speed_m_s, positive=True)
        if self.mode not in ("fixed_wavelength", "fixed_speed"):
            raise ValueError(f"mode: must be 'fixed_wavelength' or 'fixed_speed', got {self.mode!r}")

    @property
    def wavelength_m(self) -> float:
        """λ = S_max / f_max (22.35 m for 150 mph at 3 Hz)."""
        return self.max_speed_m_s / self.max_frequency_hz

    @property
    def band_rad_s(self) -> tuple[float, float]:
        """The frequency band of the cab study, rad/s: (0, 2π ``max_frequency_hz``)."""
        return 0.0, hz_to_rad_s(self.max_frequency_hz)


def _index(coordinates: Sequence[str], name: str) -> int:
    try:
        return list(coordinates).index(name)
    except ValueError:
        raise ValueError(f"cab model: the vehicle has no coordinate {name!r}") from None


def cab_lateral_model(vehicle, cab_input: CabInput = CabInput()) -> CabModel:
    """The cab model of ``vehicle``: a :class:`ParametricSystem` in every suspension parameter that acts
    on the body's lateral motion (element ids), with the vehicle file's values.

    Outputs (per the irregularity amplitude of ``cab_input``): ``"cab_acceleration"`` (m/s², the
    study's objective), ``"cab_displacement"`` (m), ``"body_roll"`` (rad) and, for each truck,
    ``"secondary_stroke_<frame>"`` (m): the lateral displacement of the body above the truck centre
    relative to the truck (a feedthrough of the input).
    """
    if vehicle.cab_point is None:
        raise ValueError(f"vehicle {vehicle.name!r}: the file has no [cab] point_m; the cab model needs one")
    a = vehicle.assembly("rigid")
    host = vehicle.bodies[0]
    dofs = [_index(a.coordinates, f"{host.name}.{d}") for d in LATERAL]
    matrices = {k: m for k, (_, m) in a.parts.items()}
    frames = []
    for b in vehicle.bodies[1:]:
        col = _index(a.coordinates, f"{b.name}.v")
        if any(np.any(m[np.ix_(dofs, [col])] != 0.0) for m in matrices.values()):
            frames.append((b, col))
    if not frames:
        raise ValueError(f"vehicle {vehicle.name!r}: no body is coupled laterally to {host.name!r}")
    lead = max(b.cg[0] for b, _ in frames)
    distances = [lead - b.cg[0] for b, _ in frames]  # m behind the leading truck
    amp = cab_input.amplitude_m

    def forcing(K: np.ndarray | None, C: np.ndarray | None) -> Forcing:
        """−Σ_f (K_bf + iΩ C_bf) u_f for the frames, u_f = amp at the phase (or delay) of frame f."""
        terms = []
        for (_, col), dist in zip(frames, distances, strict=True):
            coeffs = np.zeros((2, 3), dtype=complex)
            if K is not None:
                coeffs[0] = -K[dofs, col] * amp
            if C is not None:
                coeffs[1] = -C[dofs, col] * amp
            if cab_input.mode == "fixed_wavelength":
                terms.append((coeffs * np.exp(-2j * math.pi * dist / cab_input.wavelength_m), 0.0))
            else:
                terms.append((coeffs, dist / cab_input.max_speed_m_s))
        return Forcing.delayed(terms)

    block = np.ix_(dofs, dofs)
    acting = [k for k, m in matrices.items() if np.any(m[block] != 0.0) or
              any(np.any(m[np.ix_(dofs, [col])] != 0.0) for _, col in frames)]
    parts = {}
    for k in acting:
        kind, m = a.parts[k]
        parts[k] = (ParameterPart(K=m[block], F=forcing(m, None)) if kind == "K" else
                    ParameterPart(C=m[block], F=forcing(None, m)))
    cab = point_jacobian(np.subtract(vehicle.cab_point, host.cg))[1, [1, 3, 5]]  # lateral row over (v, α, γ)
    outputs: dict[str, tuple] = {"cab_acceleration": (cab, "acceleration"), "cab_displacement": (cab, "displacement"),
                                 "body_roll": (np.array([0.0, 1.0, 0.0]), "displacement")}
    for (b, _), dist in zip(frames, distances, strict=True):
        above = point_jacobian(np.subtract((b.cg[0], 0.0, b.cg[2]), host.cg))[1, [1, 3, 5]]
        if cab_input.mode == "fixed_wavelength":
            u = Forcing.constant([-amp * np.exp(-2j * math.pi * dist / cab_input.wavelength_m)])
        else:
            u = Forcing.delayed([([-amp], dist / cab_input.max_speed_m_s)])
        outputs[f"secondary_stroke_{b.name}"] = (above, "displacement", u)
    system = ParametricSystem(a.M[block], a.C0[block], a.K0[block], forcing(a.K0, a.C0), parts=parts,
                              outputs=outputs, names=[f"{host.name}.{d}" for d in LATERAL])
    return CabModel(system, {k: float(a.values[k]) for k in system.parameters}, cab_input,
                    tuple(b.name for b, _ in frames))


@dataclass(frozen=True, eq=False)
class CabModel:
    """The cab model: the parametric system, the vehicle file's parameter values (SI) and the input."""

    system: ParametricSystem
    values: dict[str, float]
    cab_input: CabInput
    frames: tuple[str, ...]

    def parameters(self, changes: dict[str, float] | None = None) -> np.ndarray:
        """Parameter vector with ``changes`` (element ids) applied to the file's values."""
        values = dict(self.values)
        for k, v in (changes or {}).items():
            if k not in values:
                raise ValueError(f"{k}: not a parameter of the cab model; parameters are {sorted(values)}")
            values[k] = number(k, v, non_negative=True)
        return np.array([values[k] for k in self.system.parameters])

    def at(self, changes: dict[str, float] | None = None):
        """The :class:`~railopt.models.LinearSystem` at the file's values with ``changes`` applied."""
        return self.system.at(self.parameters(changes))


__all__ = ["CabInput", "CabModel", "LATERAL", "cab_lateral_model"]
