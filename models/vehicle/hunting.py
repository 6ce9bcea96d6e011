"""The nonlinear critical speed of a vehicle on its wheel and rail profiles (issue 26 item 5).

The vehicle file's ``[wheel_rail]`` profiles give the rigid contact table (:meth:`Vehicle.contact_table`); the
wheelsets' forces are :func:`~railopt.models.vehicle.wheelset_forces.profile_forces` on that table with
Shen–Hedrick–Elkins saturation (μ from ``[wheel_rail] friction_coefficient``); the suspension is the assembled
linear one (:func:`~railopt.models.vehicle.nonlinear.nonlinear_vehicle`).  :func:`nonlinear_hunting` runs the
generic machinery of :mod:`railopt.models.bifurcation` on it:

1. the linear critical speed V_L of the vehicle's linear model (certified,
   :func:`~railopt.models.stability.critical_speed`) sets the scales;
2. a coarse descending ramp from ``top_speed`` (default 1.2 V_L) in steps of ``step`` (default 5 % of the top),
   the state carried over, each speed held for ``dwell_wavelengths`` kinematic wavelengths L = 2π √(r0 e0/λ)
   (Klingel; λ the linear model's conicity), started from the leading wheelset displaced by
   ``initial_amplitude``.  A speed where a wheel lifts (flange contact steeper than the rigid quasi-static model
   holds, :class:`~railopt.models.vehicle.wheelset_forces.WheelLift`) is recorded as ``"model_limit"`` and the
   next speed starts afresh;
3. a fine ramp (``fine_step``, default 1 % of the top) from the last steady state of the coarse ramp down through
   its bracket: the fold bracket (V_low, V_high] is then as fine as ``fine_step``;
4. shooting on the Poincaré section "leading wheelset's lateral displacement = 0, increasing" at V_high, and
   pseudo-arclength continuation of that cycle through the fold (``continuation=True``);
5. the fold confirmed when it lies in the ramp's bracket:
   :meth:`~railopt.models.bifurcation.BifurcationDiagram.nonlinear_critical_speed`.

Amplitudes are the leading wheelset's lateral displacement relative to the track (m, half peak-to-peak).
The right-hand side is one compiled call (:mod:`railopt.models.vehicle.wheelset_kernel`, 6–10 µs on a profile
table, once compiled: 10–15 s the first time, cached on disk): what remains is the integrator's own Python
(``docs/nonlinear_vehicle.md``, ``railopt bench``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from railopt.models.bifurcation import (
    BifurcationDiagram,
    ContinuationOptions,
    Dwell,
    IntegrationSettings,
    NonlinearCriticalSpeed,
    PoincareSection,
    RampResult,
    ShootingOptions,
    continue_periodic_orbit,
    find_periodic_orbit,
    speed_ramp,
)
from railopt.models.stability import critical_speed
from railopt.models.vehicle.nonlinear import NonlinearVehicle, nonlinear_vehicle
from railopt.models.vehicle.running_stability import (
    flange_clearance_use,
    max_derailment_quotient,
    record_duration_s,
    running_stability,
)
from railopt.models.vehicle.vehicle import Vehicle
from railopt.models.vehicle.wheelset_forces import FlangeSpring, SaturatedCreepLaw, profile_forces

__all__ = ["CycleIndicators", "HuntingAnalysis", "HuntingResult", "cycle_indicators", "leading_wheelset",
           "nonlinear_hunting", "profile_vehicle"]


@dataclass(frozen=True)
class HuntingAnalysis:
    """Settings of :func:`nonlinear_hunting` (speeds in m/s, lengths in m).

    Attributes
    ----------
    top_speed : float or None
        First ramp speed; default 1.2 × the linear critical speed (``search[1]`` when the linear model is
        stable over the search).
    lowest_speed : float
        The ramp stops here at the latest.
    step : float or None
        Coarse ramp step; default 5 % of the top speed.
    fine_step : float or None
        Fine ramp step through the coarse bracket; default 1 % of the top speed.
    dwell_wavelengths : float
        Kinematic wavelengths travelled at each ramp speed.
    initial_amplitude : float
        Leading wheelset's lateral displacement at the start (m).
    friction_coefficient : float or None
        μ of the saturation; default the file's ``[wheel_rail] friction_coefficient``.
    flange : FlangeSpring or None
        An optional dead-band flange spring (only for benchmark models that specify one; real profiles carry the
        flange in their table).
    search : (float, float)
        Range of the linear critical-speed search (m/s).
    method : str
        solve_ivp method of every trajectory (default ``"RK45"``: on the profile tables of the coach and the single
        wheelset it took 0.6–0.75 of LSODA's time at rtol 1e-6 — the cost is the table's kinks and contact jumps,
        not stiffness; docs/nonlinear_vehicle.md).
    rtol, atol : float
        Integration tolerances (atol in m and m/s).
    continuation : bool
        Follow the cycle through the fold by shooting and pseudo-arclength continuation (False: the ramp's
        bracket only).
    max_points : int
        Points of the continuation.
    points_after_fold : int or None
        Stop the continuation this many points past the fold (None: follow the unstable branch, the edge of the
        hunting cycle's basin, until another rule fires).
    """

    top_speed: float | None = None
    lowest_speed: float = 5.0
    step: float | None = None
    fine_step: float | None = None
    dwell_wavelengths: float = 20.0
    initial_amplitude: float = 0.003
    friction_coefficient: float | None = None
    flange: FlangeSpring | None = None
    search: tuple[float, float] = (1.0, 150.0)
    method: str = "RK45"
    rtol: float = 1e-6
    atol: float = 1e-9
    continuation: bool = True
    max_points: int = 150
    points_after_fold: int | None = None

    def __post_init__(self) -> None:
        for name in ("lowest_speed", "dwell_wavelengths", "initial_amplitude", "rtol", "atol"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: must be positive and finite, got {value!r}")
        for name in ("top_speed", "step", "fine_step", "friction_coefficient"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: must be positive and finite (or None), got {value!r}")
        if self.initial_amplitude > 0.02:
            raise ValueError(f"initial_amplitude: {self.initial_amplitude} m is beyond the flange (the unit is m)")
        low, high = self.search
        if not (0 < low < high and math.isfinite(high)):
            raise ValueError(f"search: need 0 < low < high, got {self.search!r}")
        IntegrationSettings(method=self.method, rtol=self.rtol, atol=self.atol)  # refuses an unknown method
        if not (isinstance(self.max_points, int) and self.max_points >= 1):
            raise ValueError(f"max_points: must be a positive integer, got {self.max_points!r}")


@dataclass(frozen=True, eq=False)
class HuntingResult:
    """The nonlinear hunting analysis of one vehicle.

    Attributes
    ----------
    vehicle : str
        The vehicle's name.
    linear_critical_speed : float
        The linear model's certified critical speed (m/s; inf when stable over ``search``).
    ramp : RampResult
        The coarse ramp down to its bracket followed by the fine ramp (speeds decreasing).
    diagram : BifurcationDiagram or None
        The continued branch (None when ``continuation`` was off or no orbit converged; ``reason`` says which).
    critical : NonlinearCriticalSpeed
        The fold speed and whether the ramp confirms it.
    wavelength_m : float
        The kinematic wavelength used for the dwell (m).
    watched : str
        The watched coordinate (the leading wheelset's lateral displacement).
    reason : str
        What happened, in words.
    """

    vehicle: str
    linear_critical_speed: float
    ramp: RampResult
    diagram: BifurcationDiagram | None
    critical: NonlinearCriticalSpeed
    wavelength_m: float
    watched: str
    reason: str

    @property
    def bracket(self) -> tuple[float, float] | None:
        """(V_low, V_high] of the ramp (m/s): a steady cycle at V_high, none at V_low; None without a loss."""
        return self.ramp.fold_bracket

    @property
    def steady(self) -> list[int]:
        """Indices of the ramp speeds where the detector saw a steady cycle."""
        return [i for i, v in enumerate(self.ramp.verdicts) if v.classification == "steady"]

    def lowest_hunting_speed(self) -> float:
        """The lowest speed with a stable hunting cycle found (m/s): the confirmed fold, else the ramp's V_high;
        inf when no steady cycle was seen at any ramp speed."""
        if self.critical.confirmed:
            return self.critical.speed
        return float(min(self.ramp.speeds[self.steady])) if self.steady else math.inf

    def gap(self) -> float:
        """Linear critical speed − :meth:`lowest_hunting_speed` (m/s); NaN without a hunting cycle."""
        lowest = self.lowest_hunting_speed()
        return self.linear_critical_speed - lowest if math.isfinite(lowest) else math.nan

    def passes(self, required_speed: float) -> bool | None:
        """True when no stable hunting cycle exists at or below ``required_speed`` (m/s), False when one does,
        None when the ramp's bracket straddles it without a confirmed fold (undecided)."""
        if self.critical.confirmed:
            return bool(self.critical.speed > required_speed)
        steady = self.ramp.speeds[self.steady]
        if any(s <= required_speed for s in steady):
            return False
        bracket = self.bracket
        if bracket is not None and bracket[0] >= required_speed:
            return True
        if not len(steady) and all(v.classification in ("decaying", "rest") for v in self.ramp.verdicts):
            return True  # no cycle at any ramp speed, all started from the initial disturbance
        return None

    def ramp_table(self) -> pd.DataFrame:
        """The ramp: one row per speed (speed_m_s, classification, amplitude in m, frequency_hz, growth…)."""
        return self.ramp.to_pandas()


def profile_vehicle(vehicle: Vehicle, friction_coefficient: float | None = None,
                    flange: FlangeSpring | None = None) -> NonlinearVehicle:
    """The nonlinear vehicle on its ``[wheel_rail]`` profiles with Shen–Hedrick–Elkins creep saturation.

    Raises
    ------
    ValueError
        The vehicle has no ``[wheel_rail]`` table (naming it)."""
    if vehicle.profiles is None:
        raise ValueError(f"vehicle {vehicle.name!r}: no [wheel_rail] table; the nonlinear model needs wheel and rail "
                         "profiles (wheel_profile, rail_profile, inclination)")
    mu = friction_coefficient if friction_coefficient is not None else vehicle.profiles.friction_coefficient
    forces = profile_forces(vehicle.wheel_rail(), vehicle.contact_table(), SaturatedCreepLaw(mu), flange=flange)
    return nonlinear_vehicle(vehicle, forces)


def leading_wheelset(vehicle: Vehicle) -> str:
    """The wheelset furthest forward (largest x of its centre of mass): the one the analysis watches.

    Raises
    ------
    ValueError
        The vehicle has no wheelsets."""
    wheelsets = [b for b in vehicle.bodies if b.kind == "wheelset"]
    if not wheelsets:
        raise ValueError(f"vehicle {vehicle.name!r}: no wheelsets")
    return max(wheelsets, key=lambda b: b.cg[0]).name


def _joined(coarse: RampResult, fine: RampResult, upto: int) -> RampResult:
    """The coarse ramp's first ``upto`` + 1 speeds followed by the fine ramp (all decreasing)."""
    speeds = np.concatenate([coarse.speeds[: upto + 1], fine.speeds])
    return RampResult(speeds, (*coarse.verdicts[: upto + 1], *fine.verdicts),
                      np.vstack([coarse.states[: upto + 1], fine.states]), float(np.max(-np.diff(speeds))))


def nonlinear_hunting(vehicle: Vehicle, analysis: HuntingAnalysis | None = None,
                      progress: object | None = None) -> HuntingResult:
    """Ramp, shoot and continue the vehicle's hunting cycle on its profiles: the nonlinear critical speed.

    Parameters
    ----------
    vehicle : Vehicle
        With a ``[wheel_rail]`` table (profiles).
    analysis : HuntingAnalysis, optional
    progress : callable, optional
        ``progress(message: str)`` called at each stage (plain lines for the CLI).

    Returns
    -------
    HuntingResult
        The ramp (coarse and fine), the continued diagram and the nonlinear critical speed, confirmed when the
        continuation's fold lies in the fine ramp's bracket.

    Raises
    ------
    ValueError
        No ``[wheel_rail]`` table; bad settings (naming the field); an integration failure.
    """
    a = analysis or HuntingAnalysis()
    say = progress if callable(progress) else (lambda message: None)
    nv = profile_vehicle(vehicle, a.friction_coefficient, a.flange)
    linear = critical_speed(vehicle.lateral("rigid"), speed_range=a.search).speed
    top = a.top_speed if a.top_speed is not None else (1.2 * linear if math.isfinite(linear) else a.search[1])
    if top <= a.lowest_speed:
        raise ValueError(f"top_speed: {top:.4g} m/s is not above lowest_speed {a.lowest_speed:.4g} m/s")
    step = a.step if a.step is not None else 0.05 * top
    fine = a.fine_step if a.fine_step is not None else 0.01 * top
    c = vehicle.contact
    wavelength = 2.0 * math.pi * math.sqrt(c.r0 * c.e0 / max(c.conicity, 1e-6))
    name = f"{leading_wheelset(vehicle)}.v"
    watched = nv.index(name)
    x0 = np.zeros(2 * nv.n_dof)
    x0[watched] = a.initial_amplitude
    settings = IntegrationSettings(method=a.method, rtol=a.rtol, atol=a.atol)
    dwell = Dwell(wavelengths=a.dwell_wavelengths, wavelength_m=wavelength)
    rate = 40.0 * top / wavelength  # 40 samples per kinematic period at the top speed
    speeds = np.round(np.arange(top, a.lowest_speed - 1e-9, -step), 9)  # 81.6, not 81.60000000000001
    say(f"{vehicle.name}: coarse ramp {top:.1f} → {speeds[-1]:.1f} m/s in {step:.2f} m/s steps "
        f"(linear critical speed {linear:.2f} m/s)")
    coarse = speed_ramp(nv.rhs, x0, speeds, dwell, watched, sample_rate_hz=rate, settings=settings)
    k = coarse.last_steady
    if k is None:
        reason = "the coarse ramp never lost a steady cycle"
        return HuntingResult(vehicle.name, linear, coarse, None,
                             NonlinearCriticalSpeed(math.nan, math.nan, None, False, reason), wavelength, name, reason)
    high = float(coarse.speeds[k])
    low = float(coarse.speeds[k + 1])
    fine_speeds = np.round(np.arange(high - fine, low - 1e-9, -fine), 9)
    if fine_speeds.size >= 2:
        say(f"{vehicle.name}: fine ramp {fine_speeds[0]:.2f} → {fine_speeds[-1]:.2f} m/s in {fine:.2f} m/s steps")
        refined = speed_ramp(nv.rhs, coarse.states[k], fine_speeds, dwell, watched, sample_rate_hz=rate,
                             settings=settings)
        ramp = _joined(coarse, refined, k)
    else:
        ramp = coarse
    bracket = ramp.fold_bracket
    reason = f"ramp bracket ({bracket[0]:.2f}, {bracket[1]:.2f}] m/s" if bracket else "the ramp lost no cycle"

    def unconfirmed(why: str) -> HuntingResult:
        critical = NonlinearCriticalSpeed(math.nan, math.nan, bracket, False, why)
        return HuntingResult(vehicle.name, linear, ramp, None, critical, wavelength, name, why)

    if not a.continuation or bracket is None:
        return unconfirmed(f"{reason}; continuation not run" if bracket else reason)
    j = ramp.last_steady
    speed = float(ramp.speeds[j])
    period = 1.0 / ramp.verdicts[j].frequency_hz
    section = PoincareSection(index=watched, value=0.0, direction=1)
    arrived = solve_ivp(lambda t, x: nv.rhs(t, x, speed), (0.0, 3 * period), ramp.states[j],
                        events=section.event(), **settings.options())
    shooting = ShootingOptions(tol=1e-8, min_amplitude=1e-5)
    jac = (lambda t, x, v: nv.jacobian(x, v))  # noqa: E731
    say(f"{vehicle.name}: shooting the cycle at {speed:.2f} m/s")
    if not arrived.t_events[0].size:
        return unconfirmed(f"{reason}; the state at {speed:.2f} m/s did not reach the section")
    orbit = find_periodic_orbit(nv.rhs, arrived.y_events[0][0], speed, section, period, watched,
                                options=shooting, settings=settings, jacobian=jac)
    if not orbit.converged:
        return unconfirmed(f"{reason}; no periodic orbit at {speed:.2f} m/s: {orbit.reason}")
    say(f"{vehicle.name}: continuing the cycle from {speed:.2f} m/s (amplitude {orbit.amplitude * 1e3:.3f} mm)")
    # scaled so that the cycle's velocities (≈ 2πf × amplitude, the largest free coordinates on the section) are
    # O(1) and a step of 0.05 moves the speed by about a fifth of the fine ramp step
    options = ContinuationOptions(step=0.05, max_step=0.3,
                                  state_scale=max(2 * math.pi * orbit.amplitude / orbit.period, 1e-4),
                                  speed_scale=max(bracket[1] - bracket[0], fine) * 4, max_points=a.max_points,
                                  points_after_fold=a.points_after_fold)
    down = continue_periodic_orbit(nv.rhs, orbit, section, watched, speed_range=(a.lowest_speed, top),
                                   direction=-1, options=options, shooting=shooting, settings=settings,
                                   jacobian=jac, linear_critical_speed=linear,
                                   progress=lambda line: say(f"{vehicle.name}: continuation {line}"))
    diagram = dataclasses.replace(down, ramp=ramp)
    critical = diagram.nonlinear_critical_speed()
    say(f"{vehicle.name}: {critical.reason}")
    return HuntingResult(vehicle.name, linear, ramp, diagram, critical, wavelength, name, critical.reason)


@dataclass(frozen=True)
class CycleIndicators:
    """EN 14363-style indicators of a steady hunting cycle of the watched (leading) wheelset.

    Attributes
    ----------
    speed : float
        m/s.
    period : float
        The cycle's period (s).
    peak_displacement : float
        max |y| of the wheelset relative to the track over the cycle (m).
    flange_clearance : float
        The shift where the contact reaches the flange (m, :meth:`ContactTable.flange_onset`).
    flange_use : float
        peak_displacement / flange_clearance (≥ 1: flange contact).
    sum_y_rms : float
        The largest sliding r.m.s. of the band-passed ΣY = Y_left + Y_right (N) over ``window_m``.
    sum_y_limit : float
        (ΣY)_rms,lim = (ΣY)_lim / 2 with Prud'homme's (ΣY)_lim = α (10 kN + P/3), P the axle load (N).
    sum_y_ratio : float
        sum_y_rms / sum_y_limit (≤ 1: the criterion is met).
    derailment_quotient : float
        max |Y/Q| over both wheels and the cycle.
    """

    speed: float
    period: float
    peak_displacement: float
    flange_clearance: float
    flange_use: float
    sum_y_rms: float
    sum_y_limit: float
    sum_y_ratio: float
    derailment_quotient: float

    def to_dict(self) -> dict[str, float]:
        """The fields in table units (m/s, s, mm, kN)."""
        return {"speed_m_s": self.speed, "period_s": self.period, "peak_y_mm": self.peak_displacement * 1e3,
                "flange_clearance_mm": self.flange_clearance * 1e3, "flange_use": self.flange_use,
                "sum_y_rms_kN": self.sum_y_rms / 1e3, "sum_y_rms_limit_kN": self.sum_y_limit / 1e3,
                "sum_y_ratio": self.sum_y_ratio, "max_Y_over_Q": self.derailment_quotient}


def cycle_indicators(nv: NonlinearVehicle, vehicle: Vehicle, speed: float, state: np.ndarray, watched: str,
                     settings: IntegrationSettings, *, window_m: float = 100.0,
                     samples_per_period: int = 128) -> CycleIndicators:
    """ΣY (EN 14363 sliding r.m.s.), flange-clearance use and Y/Q of the steady cycle through ``state``.

    The cycle is integrated over one period, from its crossing of the section "watched displacement = 0,
    increasing" to the next, at ``samples_per_period`` uniform samples; the steady cycle is periodic, so the record
    the standard's filter and window need (settling time + ``window_m``) is that period repeated — exact for a
    periodic signal, and one period's cost instead of seconds of simulation.  ΣY and Y/Q are those of the watched
    wheelset (:meth:`NonlinearVehicle.contact_state`); the axle load is the wheel/rail model's static load.

    Parameters
    ----------
    nv : NonlinearVehicle
    vehicle : Vehicle
        For the contact table's flange onset.
    speed : float
        m/s.
    state : (2n,) ndarray
        A state on (or settled onto) the steady cycle, e.g. the ramp's state at the end of a steady dwell.
    watched : str
        The wheelset's lateral coordinate (``"<wheelset>.v"``).
    settings : IntegrationSettings
    window_m : float
        Sliding r.m.s. window (m).
    samples_per_period : int

    Raises
    ------
    ValueError
        The state does not return to the section within three kinematic periods (not on a cycle).
    """
    index = nv.index(watched)
    section = PoincareSection(index=index, value=0.0, direction=1)
    options = settings.options()

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        return nv.rhs(t, x, speed)

    first = solve_ivp(rhs, (0.0, 2.0), state, events=section.event(), **options)
    if not first.t_events[0].size:
        raise ValueError(f"state: no crossing of {watched} = 0 within 2 s at {speed:g} m/s (not on a cycle)")
    start = first.y_events[0][0]
    arm = 1e-3  # s: the start lies on the section; the crossing one period later ends the second leg
    leaving = solve_ivp(rhs, (0.0, arm), start, dense_output=True, **options)
    ride = solve_ivp(rhs, (arm, 2.0), leaving.y[:, -1], events=section.event(), dense_output=True, **options)
    if not ride.t_events[0].size:
        raise ValueError(f"state: the cycle at {speed:g} m/s did not return to {watched} = 0 within 2 s")
    period = float(ride.t_events[0][0])
    t = np.arange(samples_per_period) * (period / samples_per_period)
    x = np.where(t < arm, leaving.sol(np.minimum(t, arm)), ride.sol(np.maximum(t, arm)))
    k = nv.wheelsets.index(watched.rsplit(".", 1)[0])
    contact = [nv.contact_state(x[:, j], speed) for j in range(t.size)]
    sum_y = np.array([c.Y[0, k] + c.Y[1, k] for c in contact])
    axle_load = nv.forces.axle_load
    frequency = 1.0 / period
    dt = period / samples_per_period
    # the record the criterion needs (the filter's settling time and one window) in whole periods: the window and
    # 5 s, doubled while shorter than that
    needed = record_duration_s(frequency, dt, speed, window_m=window_m)
    repeats = int(math.ceil((window_m / speed + 5.0) / period))
    while (repeats * samples_per_period - 1) * dt < needed:
        repeats *= 2
    record = running_stability(np.arange(repeats * samples_per_period) * dt, np.tile(sum_y, repeats), speed,
                               axle_load, frequency_hz=frequency, window_m=window_m)
    clearance = vehicle.contact_table().flange_onset()
    use = flange_clearance_use(x[index], clearance)
    quotient = max(max_derailment_quotient(np.array([c.Y[s, k] for c in contact]),
                                           np.array([c.Q[s, k] for c in contact])) for s in (0, 1))
    return CycleIndicators(float(speed), period, use.peak_m, clearance, use.fraction, record.max_rms_n,
                           record.limit_n, record.ratio, quotient)
