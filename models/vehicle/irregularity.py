"""Sinusoidal rail irregularities as delayed axle inputs (thesis (4.63)–(4.66)).

A vehicle running forward (+x) at speed S over a stationary sinusoidal rail profile of wavelength
L sees it at the leading axle as ``ε(t) = a e^{iΩt}`` with Ω = 2πS/L, and at an axle a distance
d_i behind the leading one as the same profile delayed by ``τ_i = d_i / S``::

    u_i(t) = a e^{iΩ(t − τ_i)}.

At a fixed speed a forcing frequency f (Hz) therefore *is* a wavelength ``L = S / f`` (the thesis's
"input frequency, which is a function of the wave length of the irregularities and the vehicle
forward speed"); the delays turn into the phases ``e^{−iΩτ_i} = e^{−2πi d_i / L}`` (wheelbase
filtering).

Kinds (our axes: x forward, y left, z up; rails' contact points at y = ±e0):

* ``"vertical"``, ``rails="in_phase"``: both rails' vertical profile ``a`` (input ``<ws>_rail.w``);
  rigid-track wheels follow it (4.65), flexible-track wheels follow it plus the track deflection
  (4.66) — the assembly's constraint ``w_wheelset = w_track + w_rail``.
* ``"vertical"``, ``rails="out_of_phase"`` ≡ ``"cross_level"``: left rail ``+a``, right rail ``−a``:
  a cross level (height difference) of 2a, rail roll ``a / e0`` (input ``<ws>_rail.alpha``, rigid
  track only: the lumped flexible track has no rail-roll input).
* ``"alignment"`` (≡ ``"lateral"`` in phase): both rails shifted by ``a`` to the left (input
  ``<ws>_rail.v``).  Out-of-phase lateral rail motion (gauge variation) does not enter this linear
  model and is refused.

The amplitude is per rail, in metres; every response is the response to that amplitude (the
convention of the thesis's figures: displacement per given irregularity amplitude).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.validation import number

KINDS = ("vertical", "alignment", "cross_level", "lateral")
RAILS = ("in_phase", "out_of_phase")


@dataclass(frozen=True)
class RailInput:
    """Prescribed rail inputs as delayed terms: ``u(t) = Σ_i u_i e^{iΩ(t − τ_i)}``.

    Attributes
    ----------
    inputs : tuple of str
        Names of the model's input coordinates (``VehicleModel.inputs``).
    terms : tuple of (ndarray (m,), float)
        Per axle: the real input vector u_i over ``inputs`` (m, rad) and its delay τ_i (s).
    label : str
        Description for tables.
    """

    inputs: tuple[str, ...]
    terms: tuple[tuple[np.ndarray, float], ...]
    label: str = "rail input"

    def __post_init__(self) -> None:
        m = len(self.inputs)
        if not self.terms:
            raise ValueError("input: at least one (u, delay) term is needed")
        checked = []
        for i, (u, tau) in enumerate(self.terms):
            arr = np.asarray(u, dtype=float)
            if arr.shape != (m,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"input.terms[{i}]: u must be {m} finite numbers over {self.inputs}, got {u!r}")
            tau = number(f"input.terms[{i}].delay", tau, non_negative=True)
            checked.append((arr, tau))
        object.__setattr__(self, "terms", tuple(checked))

    @property
    def max_delay(self) -> float:
        """Largest delay τ_i (s)."""
        return max(t for _, t in self.terms)

    def value(self, omega: float | np.ndarray) -> np.ndarray:
        """Complex input amplitudes ``Σ u_i e^{−iΩτ_i}``, shape (m,) or (N, m) for Ω in rad/s."""
        w = np.asarray(omega, dtype=float)
        out = sum(np.multiply.outer(np.exp(-1j * w * tau), u) for u, tau in self.terms)
        return np.asarray(out, dtype=complex)


@dataclass(frozen=True)
class Irregularity:
    """A sinusoidal rail irregularity (thesis §4.3.2).

    Parameters
    ----------
    kind : {"vertical", "alignment", "cross_level", "lateral"}
        Direction of the rail displacement; ``"cross_level"`` is ``"vertical"`` out of phase,
        ``"alignment"`` is ``"lateral"`` in phase.
    amplitude_m : float
        Amplitude a of each rail's displacement, m (> 0).
    rails : {"in_phase", "out_of_phase"}
        Both rails alike, or left ``+a`` and right ``−a``.  ``"cross_level"`` is out of phase by
        definition (its ``rails`` must be left at ``"out_of_phase"`` or given so).
    wavelength_m : float or None
        None (default): the model's speed S is fixed and a frequency f means the wavelength S/f.
        A wavelength L (m): the thesis's sweep ("increased from zero to 8 hertz corresponding to a
        forward speed of approximately 200 mph") — f is reached by running at S = f L, so the
        creep damping and the delays change with f while the axle phases 2π d_i/L stay fixed
        (:func:`railopt.models.vehicle.forced.frequency_response` only; a LinearSystem has one speed).
    """

    kind: str = "vertical"
    amplitude_m: float = 1.0
    rails: str | None = None
    wavelength_m: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"input.kind: must be one of {KINDS}, got {self.kind!r}")
        number("input.amplitude_m", self.amplitude_m, positive=True)
        default = "out_of_phase" if self.kind == "cross_level" else "in_phase"
        rails = default if self.rails is None else self.rails
        if rails not in RAILS:
            raise ValueError(f"input.rails: must be one of {RAILS}, got {rails!r}")
        if self.kind == "cross_level" and rails != "out_of_phase":
            raise ValueError("input.rails: a cross_level irregularity is out of phase by definition")
        if self.kind in ("alignment", "lateral") and rails != "in_phase":
            raise ValueError("input.rails: lateral rail motion is modelled in phase (alignment); out-of-phase lateral "
                             "rails (gauge variation) do not enter the linear model")
        object.__setattr__(self, "rails", rails)
        if self.wavelength_m is not None:
            number("input.wavelength_m", self.wavelength_m, positive=True)

    @property
    def direction(self) -> str:
        """``"w"`` (vertical rail motion) or ``"v"`` (lateral)."""
        return "w" if self.kind in ("vertical", "cross_level") else "v"

    @property
    def label(self) -> str:
        """A short label for legends: kind, rails, amplitude (m) and, for a fixed wavelength, L (m)."""
        fixed = "" if self.wavelength_m is None else f", L = {self.wavelength_m:g} m"
        return f"{self.kind} {self.rails} a = {self.amplitude_m:g} m{fixed}"

    def axle_vector(self, inputs: Sequence[str], wheelset: str, semi_gauge: float) -> np.ndarray:
        """The input vector u over ``inputs`` for one wheelset (m or rad).

        Raises a ValueError naming ``input`` when the model has no such input (e.g. a lateral
        irregularity on the vertical block, cross level on flexible track).
        """
        a = float(self.amplitude_m)
        if self.direction == "w" and self.rails == "in_phase":
            name, value = f"{wheelset}_rail.w", a
        elif self.direction == "w":
            name, value = f"{wheelset}_rail.alpha", a / semi_gauge  # left +a, right −a: roll a/e0
        else:  # lateral, in phase (out of phase is refused at construction)
            name, value = f"{wheelset}_rail.v", a
        if name not in inputs:
            raise ValueError(f"input: a {self.kind} {self.rails} irregularity needs the input {name!r}, which this "
                             f"model does not have (its inputs: {list(inputs)}); vertical profiles excite the "
                             "vertical block, alignment and cross level (rigid track) the lateral block")
        u = np.zeros(len(inputs))
        u[list(inputs).index(name)] = value
        return u

    def axle_inputs(self, inputs: Sequence[str], wheelsets: Sequence[tuple[str, float]],
                    semi_gauge: float) -> list[tuple[np.ndarray, float]]:
        """Per axle: the input vector u_i over ``inputs`` and its distance (m) behind the foremost axle
        (the vehicle runs towards +x); wheelsets ``[(name, x_m), ...]``."""
        if not wheelsets:
            raise ValueError("input: the vehicle has no wheelsets to excite")
        lead = max(x for _, x in wheelsets)
        return [(self.axle_vector(inputs, name, semi_gauge), lead - x) for name, x in wheelsets]

    def rail_input(self, inputs: Sequence[str], wheelsets: Sequence[tuple[str, float]], speed: float,
                   semi_gauge: float) -> RailInput:
        """Delayed axle inputs for wheelsets ``[(name, x_m), ...]`` at forward speed ``speed`` (m/s).

        ``τ_i = (x_lead − x_i) / S`` with x_lead the foremost axle (the vehicle runs towards +x).
        """
        speed = number("speed", speed, positive=True)
        terms = tuple((u, d / speed) for u, d in self.axle_inputs(inputs, wheelsets, semi_gauge))
        return RailInput(tuple(inputs), terms, self.label)


def wavelength_m(frequency_hz: float | np.ndarray, speed: float) -> float | np.ndarray:
    """Wavelength L = S / f (m) of the irregularity that a vehicle at ``speed`` (m/s) meets at f (Hz)."""
    f = np.asarray(frequency_hz, dtype=float)
    with np.errstate(divide="ignore"):
        out = speed / f
    return float(out) if out.ndim == 0 else out


def frequency_hz(wavelength: float, speed: float) -> float:
    """Forcing frequency f = S / L (Hz) of an irregularity of wavelength L (m) at speed S (m/s)."""
    wavelength = number("wavelength_m", wavelength, positive=True)
    return number("speed", speed, positive=True) / wavelength


__all__ = ["Irregularity", "RailInput", "frequency_hz", "wavelength_m"]
