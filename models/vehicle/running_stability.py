"""Running-stability indicators of a simulated hunting cycle, after EN 14363 (and UIC 518).

From the time histories a nonlinear hunting simulation gives for one wheelset at a steady speed V — the
track-shifting force ΣY(t) = Y_left + Y_right (N, y positive left) and the lateral displacement y(t) (m) —
this module computes:

* :func:`sum_y_limit` — Prud'homme's track-shifting limit (ΣY)_lim = α (10 kN + P/3), P the static axle load
  (EN 14363 writes it α (10 + 2Q0/3) kN with Q0 the static wheel force, 2Q0 = P); α = 1 for locomotives,
  power cars and passenger vehicles, α = 0.85 for freight wagons.
* :func:`sliding_rms` — the sliding r.m.s. of a signal over windows of fixed length along the track
  (uniform or non-uniform sampling; the mean square is the exact integral of the piecewise-linear
  interpolant of the squared samples, divided by the window length).
* :func:`running_stability` → :class:`RunningStability` — the stability criterion of the normal measuring
  method: ΣY band-pass filtered around the instability frequency f0 (f0 ± 2 Hz, a Butterworth band-pass,
  ``scipy.signal.butter`` in second-order sections applied once, causally, by ``scipy.signal.sosfilt``), its
  sliding r.m.s. over 100 m in steps of 10 m, and the limit (ΣY)_rms,lim = (ΣY)_lim / 2.
* :func:`flange_clearance_use` → :class:`FlangeClearanceUse` — max |y| over the flangeway clearance.
* :func:`max_derailment_quotient` — max |Y/Q| of one wheel.

Units: SI inside (N, m, s, Hz); "kN" appears only where the standard states its formula in kN.

Sources and what was verified in this session (see ``docs/running_stability.md`` for the quotations):
the table "Acceptance test according to UIC 518 and CEN/TC 256 WG 10 publication EN 14363" of the GENSYS
course notes (gensys.se/course/UIC518_tests.html) lists "∑Y Instability criterion — filtering f0 = ±2 Hz —
Sliding r.m.s. value".  The window (100 m), step (10 m), the factor ½ of the rms limit, the form of
Prud'homme's limit and its α values are EN 14363 / UIC 518's as widely quoted in the literature; the
standard's own text (EN 14363:2016 clause 7.5/7.6 and its tables of limit values and signal processing) was
not available to this session, and the filter order is not verified from it (default: scipy's N = 4, an
order-8 band-pass).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import signal as sps

from railopt.models.validation import number, real_array

__all__ = [
    "ALPHA_FREIGHT",
    "ALPHA_PASSENGER",
    "SETTLE_DECAY",
    "FlangeClearanceUse",
    "RunningStability",
    "SlidingRms",
    "estimate_frequency",
    "flange_clearance_use",
    "max_derailment_quotient",
    "record_duration_s",
    "running_stability",
    "sliding_rms",
    "sum_y_limit",
]

ALPHA_PASSENGER = 1.0  # Prud'homme's α for locomotives, power cars, multiple units and passenger coaches
ALPHA_FREIGHT = 0.85  # Prud'homme's α for freight wagons
PRUDHOMME_CONSTANT_N = 10.0e3  # the 10 kN of (ΣY)_lim = α (10 kN + P/3)
SETTLE_DECAY = 1e-4  # the filter's start transient is discarded until its slowest mode has decayed by this factor
_UNIFORM_RTOL = 1e-6  # sampling counts as uniform when every step is within this fraction of the mean step


def sum_y_limit(axle_load_n: float, alpha: float = ALPHA_PASSENGER) -> float:
    """Prud'homme's track-shifting limit (ΣY)_lim = α (10 kN + P/3) in N.

    Parameters
    ----------
    axle_load_n : the static axle load P = 2 Q0 (N), > 0.
    alpha : α, > 0: 1.0 (:data:`ALPHA_PASSENGER`) for locomotives, power cars and passenger vehicles,
        0.85 (:data:`ALPHA_FREIGHT`) for freight wagons.

    Returns
    -------
    float : the limit of the track-shifting force ΣY (N); EN 14363 states it in kN as α (10 + 2Q0/3).

    Raises
    ------
    ValueError : ``axle_load_n``/``alpha`` not a finite positive number (the message starts with the name).

    Source: Prud'homme's criterion for the lateral resistance of ballasted track, as EN 14363 and UIC 518
    state it (see the module docstring on what was verified).
    """
    p = number("axle_load_n", axle_load_n, positive=True)
    a = number("alpha", alpha, positive=True)
    return a * (PRUDHOMME_CONSTANT_N + p / 3.0)


@dataclass(frozen=True)
class SlidingRms:
    """The sliding r.m.s. of a signal along the track: one value per window.

    Attributes
    ----------
    start_m : (K,) start of each window along the track (m).
    rms : (K,) r.m.s. of the signal over [start_m, start_m + window_m] (the signal's unit).
    window_m : window length (m).
    step_m : distance between the starts of consecutive windows (m).
    """

    start_m: np.ndarray = field(compare=False)
    rms: np.ndarray = field(compare=False)
    window_m: float
    step_m: float

    @property
    def maximum(self) -> float:
        """The largest of the windows' r.m.s. values (the signal's unit)."""
        return float(np.max(self.rms))


def _increasing(name: str, value: object) -> np.ndarray:
    s = real_array(name, value, ndim=1)
    if s.size < 2:
        raise ValueError(f"{name}: needs at least 2 samples, got {s.size}")
    bad = np.flatnonzero(np.diff(s) <= 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{name}: must be strictly increasing, but sample {i + 1} ({s[i + 1]!r}) does not "
                         f"exceed sample {i} ({s[i]!r})")
    return s


def _cumulative_square(s: np.ndarray, p: np.ndarray, at: np.ndarray) -> np.ndarray:
    """∫_{s0}^{at} of the piecewise-linear interpolant of the samples p (of x²) over s, at the points ``at``."""
    seg = np.diff(s)
    cum = np.concatenate(([0.0], np.cumsum(0.5 * seg * (p[:-1] + p[1:]))))
    i = np.clip(np.searchsorted(s, at, side="right") - 1, 0, s.size - 2)
    d = at - s[i]
    slope = (p[i + 1] - p[i]) / seg[i]
    return cum[i] + d * p[i] + 0.5 * slope * d * d


def sliding_rms(distance_m: object, signal: object, window_m: float, *, step_m: float = 10.0) -> SlidingRms:
    """Sliding r.m.s. of ``signal`` over windows of ``window_m`` along the track, starting every ``step_m``.

    The windows are [s0 + k·step_m, s0 + k·step_m + window_m] for k = 0, 1, … while the window ends within the
    record (s0 the first sample's distance).  The mean square over a window is the exact integral of the
    piecewise-linear interpolant of the squared samples (the trapezoidal rule, with the values at the window's
    ends interpolated linearly), divided by the window length: this holds for uniform and non-uniform sampling
    alike, and for a constant signal c gives |c| (to round-off).

    Parameters
    ----------
    distance_m : (n,) distance along the track of each sample (m), strictly increasing; uniform or not.
    signal : (n,) the signal at those distances (any unit).
    window_m : window length (m), > 0, at most the record's length.
    step_m : distance between window starts (m), > 0; EN 14363's stability criterion steps 10 m.

    Returns
    -------
    SlidingRms : the window starts and their r.m.s. values (at least one window).

    Raises
    ------
    ValueError : ``distance_m`` not strictly increasing or shorter than one window; ``signal`` of another
        shape; NaN/inf anywhere; ``window_m``/``step_m`` not positive.
    """
    s = _increasing("distance_m", distance_m)
    x = real_array("signal", signal, ndim=1)
    if x.shape != s.shape:
        raise ValueError(f"signal: shape {x.shape} does not match distance_m's {s.shape}")
    window = number("window_m", window_m, positive=True)
    step = number("step_m", step_m, positive=True)
    length = s[-1] - s[0]
    tol = 1e-9 * max(length, window)
    if window > length + tol:
        raise ValueError(f"distance_m: the record covers {length:.6g} m, shorter than one window of {window:.6g} m")
    k = int(math.floor((length - window + tol) / step)) + 1
    start = s[0] + step * np.arange(k)
    end = np.minimum(start + window, s[-1])
    p = x * x
    mean_square = (_cumulative_square(s, p, end) - _cumulative_square(s, p, start)) / (end - start)
    return SlidingRms(start_m=start, rms=np.sqrt(np.maximum(mean_square, 0.0)), window_m=window, step_m=step)


def estimate_frequency(t_s: object, signal: object) -> float:
    """The dominant frequency (Hz) of a uniformly sampled oscillation: the peak of its spectrum.

    The mean is removed, a Hann window applied, the record zero-padded to 8× its length (at least 2¹⁴ points)
    and the peak bin of the real FFT (DC excluded) refined by a parabola through the logarithms of the three
    magnitudes around it.  For a sinusoid this is exact to a small fraction of the bin 1/(8T); harmonics
    weaker than the fundamental do not move it.

    Parameters
    ----------
    t_s : (n,) sample times (s), strictly increasing and uniform (steps equal within 1e-6 of their mean).
    signal : (n,) the oscillating signal (any unit).

    Returns
    -------
    float : the frequency (Hz).

    Raises
    ------
    ValueError : ``t_s`` not strictly increasing, not uniform or shorter than 4 samples; ``signal`` of
        another shape or constant (no oscillation).
    """
    t = _increasing("t_s", t_s)
    x = real_array("signal", signal, ndim=1)
    if x.shape != t.shape:
        raise ValueError(f"signal: shape {x.shape} does not match t_s's {t.shape}")
    dt = _uniform_step(t)
    if t.size < 4:
        raise ValueError(f"t_s: needs at least 4 samples to estimate a frequency, got {t.size}")
    x = x - x.mean()
    if not np.any(np.abs(x) > 0.0):
        raise ValueError("signal: is constant, it has no frequency")
    n_fft = max(8 * t.size, 1 << 14)
    mag = np.abs(np.fft.rfft(x * np.hanning(t.size), n_fft))
    k = int(np.argmax(mag[1:-1])) + 1
    a, b, c = np.log(np.maximum(mag[k - 1:k + 2], np.finfo(float).tiny))
    denom = a - 2.0 * b + c
    shift = 0.5 * (a - c) / denom if denom < 0 else 0.0
    return float((k + shift) / (n_fft * dt))


def _uniform_step(t: np.ndarray) -> float:
    steps = np.diff(t)
    dt = float(steps.mean())
    worst = float(np.max(np.abs(steps - dt)))
    if worst > _UNIFORM_RTOL * dt:
        raise ValueError(f"t_s: the filter and the spectrum need uniform sampling, but the steps differ from their "
                         f"mean {dt:.6g} s by up to {worst:.3g} s; resample the record uniformly first")
    return dt


@dataclass(frozen=True)
class RunningStability:
    """The running-stability assessment of one wheelset's ΣY record (EN 14363's normal-method criterion).

    Attributes
    ----------
    max_rms_n : the largest sliding r.m.s. of the (filtered) ΣY over the windows (N).
    limit_n : the limit (ΣY)_rms,lim = (ΣY)_lim / 2 (N), (ΣY)_lim from :func:`sum_y_limit`.
    ratio : max_rms_n / limit_n.
    stable : ratio ≤ 1 (the criterion is met).
    frequency_hz : the instability frequency f0 the band-pass is centred on (Hz).
    frequency_source : ``"given"`` or ``"estimated (spectrum peak)"``.
    window_m, step_m : the sliding window's length and step (m).
    speed_m_s : the running speed V (m/s), distance s = V t.
    filter : description of the filter applied (``"none"`` when unfiltered).
    settle_s : length of the start of the record discarded as the filter's transient (s); 0 when unfiltered.
    sliding : the :class:`SlidingRms` the maximum was taken from (window starts in m along the track,
        measured from the first sample).
    """

    max_rms_n: float
    limit_n: float
    ratio: float
    stable: bool
    frequency_hz: float | None
    frequency_source: str
    window_m: float
    step_m: float
    speed_m_s: float
    filter: str
    settle_s: float
    sliding: SlidingRms = field(compare=False, repr=False)


def _band_pass(f0: float, half_width: float, dt: float, order: int) -> np.ndarray:
    nyquist = 0.5 / dt
    lo, hi = f0 - half_width, f0 + half_width
    if lo <= 0.0:
        raise ValueError(f"frequency_hz: f0 = {f0:.6g} Hz leaves no lower band edge for f0 ± {half_width:.6g} Hz; "
                         f"give a smaller band_half_width_hz or filtered=False")
    if hi >= nyquist:
        raise ValueError(f"t_s: the sampling frequency {1 / dt:.6g} Hz is too low for the band's upper edge "
                         f"{hi:.6g} Hz (Nyquist {nyquist:.6g} Hz)")
    return sps.butter(order, [lo, hi], btype="bandpass", fs=1.0 / dt, output="sos")


def _settle_samples(sos: np.ndarray) -> int:
    """Samples for the slowest pole z of the filter to decay by SETTLE_DECAY: |z|^n ≤ SETTLE_DECAY."""
    _, poles, _ = sps.sos2zpk(sos)
    radius = float(np.max(np.abs(poles)))
    return int(math.ceil(math.log(SETTLE_DECAY) / math.log(radius)))


def record_duration_s(frequency_hz: float, sample_interval_s: float, speed_m_s: float, *, window_m: float = 100.0,
                      band_half_width_hz: float = 2.0, filter_order: int = 4) -> float:
    """The shortest uniformly sampled record (s) that :func:`running_stability` accepts, filtered: the band-pass
    filter's settling time (its slowest pole decayed by :data:`SETTLE_DECAY`) plus one ``window_m`` at
    ``speed_m_s``.  Raises ValueError (naming the argument) where the band does not fit the sampling."""
    sos = _band_pass(number("frequency_hz", frequency_hz, positive=True),
                     number("band_half_width_hz", band_half_width_hz, positive=True),
                     number("sample_interval_s", sample_interval_s, positive=True), int(filter_order))
    return _settle_samples(sos) * sample_interval_s + window_m / number("speed_m_s", speed_m_s, positive=True)


def running_stability(t_s: object, sum_y_n: object, speed_m_s: float, axle_load_n: float, *,
                      frequency_hz: float | None = None, alpha: float = ALPHA_PASSENGER, window_m: float = 100.0,
                      step_m: float = 10.0, filtered: bool = True, band_half_width_hz: float = 2.0,
                      filter_order: int = 4) -> RunningStability:
    """EN 14363's running-stability criterion on one wheelset's track-shifting force ΣY(t).

    Method: ΣY is band-pass filtered around the instability frequency f0 (band f0 ± ``band_half_width_hz``,
    a Butterworth of prototype order ``filter_order`` — scipy's band-pass of order 2·filter_order — in
    second-order sections, applied once and causally with ``scipy.signal.sosfilt``, so a sinusoid of
    frequency f comes out with the filter's gain |H(f)| and no squaring of it).  The start of the record is
    discarded until the filter's slowest mode has decayed by :data:`SETTLE_DECAY` (``settle_s``).  The
    remainder is mapped to distance s = V t and its sliding r.m.s. taken over ``window_m`` in steps of
    ``step_m`` (:func:`sliding_rms`); the largest is compared with (ΣY)_rms,lim = (ΣY)_lim / 2.
    With ``filtered=False`` the raw ΣY (mean included) is used from the first sample, and the sampling may
    be non-uniform.

    Parameters
    ----------
    t_s : (n,) sample times (s), strictly increasing; uniform (within 1e-6 of the mean step) when filtered.
    sum_y_n : (n,) ΣY = Y_left + Y_right of one wheelset (N).
    speed_m_s : the running speed V (m/s), > 0, constant over the record.
    axle_load_n : the static axle load P (N), > 0.
    frequency_hz : f0 (Hz); None estimates it from the spectrum of ΣY (:func:`estimate_frequency`).
        Only used when filtered.
    alpha : Prud'homme's α (1.0 passenger/locomotive, 0.85 freight).
    window_m, step_m : sliding window length and step (m); EN 14363: 100 m and 10 m.
    filtered : apply the band-pass (the standard's processing) or not.
    band_half_width_hz : half width of the band (Hz); EN 14363: 2 Hz.
    filter_order : Butterworth prototype order N (an integer ≥ 1).

    Returns
    -------
    RunningStability

    Raises
    ------
    ValueError : ``t_s`` not strictly increasing, not uniform (filtered), too coarse for the band, or
        shorter than the filter's settling plus one window (the message gives the length needed);
        ``sum_y_n`` of another shape; ``speed_m_s``/``axle_load_n``/``alpha``/``window_m``/``step_m`` not
        positive; ``frequency_hz`` not positive or ≤ the band's half width; ``filter_order`` not a positive
        integer; NaN/inf anywhere.
    """
    t = _increasing("t_s", t_s)
    y = real_array("sum_y_n", sum_y_n, ndim=1)
    if y.shape != t.shape:
        raise ValueError(f"sum_y_n: shape {y.shape} does not match t_s's {t.shape}")
    speed = number("speed_m_s", speed_m_s, positive=True)
    limit = 0.5 * sum_y_limit(axle_load_n, alpha)
    window = number("window_m", window_m, positive=True)
    step = number("step_m", step_m, positive=True)
    if not isinstance(filtered, bool | np.bool_):
        raise ValueError(f"filtered: must be True or False, got {filtered!r}")

    f0: float | None = None
    source = "not used (unfiltered)"
    description = "none"
    settle = 0
    if filtered:
        if isinstance(filter_order, bool) or not isinstance(filter_order, int | np.integer) or filter_order < 1:
            raise ValueError(f"filter_order: must be a positive integer, got {filter_order!r}")
        half = number("band_half_width_hz", band_half_width_hz, positive=True)
        dt = _uniform_step(t)
        if frequency_hz is None:
            f0 = estimate_frequency(t, y)
            source = "estimated (spectrum peak)"
        else:
            f0 = number("frequency_hz", frequency_hz, positive=True)
            source = "given"
        sos = _band_pass(f0, half, dt, int(filter_order))
        settle = _settle_samples(sos)
        needed_s = settle * dt + window / speed
        if t[-1] - t[0] < needed_s - 1e-9 * needed_s:
            raise ValueError(f"t_s: the record lasts {t[-1] - t[0]:.6g} s ({(t[-1] - t[0]) * speed:.6g} m at "
                             f"{speed:.6g} m/s); the filter's settling ({settle * dt:.6g} s) plus one {window:.6g} m "
                             f"window need {needed_s:.6g} s ({needed_s * speed:.6g} m)")
        y = sps.sosfilt(sos, y)
        description = (f"Butterworth band-pass {f0 - half:.6g}-{f0 + half:.6g} Hz (f0 ± {half:.6g} Hz), prototype "
                       f"order {int(filter_order)} (band-pass order {2 * int(filter_order)}), second-order "
                       f"sections, causal single pass (scipy.signal.sosfilt)")
    else:
        needed_s = window / speed
        if t[-1] - t[0] < needed_s - 1e-9 * needed_s:
            raise ValueError(f"t_s: the record lasts {t[-1] - t[0]:.6g} s ({(t[-1] - t[0]) * speed:.6g} m at "
                             f"{speed:.6g} m/s); one {window:.6g} m window needs {needed_s:.6g} s")
    distance = (t[settle:] - t[0]) * speed
    sliding = sliding_rms(distance, y[settle:], window, step_m=step)
    peak = sliding.maximum
    return RunningStability(max_rms_n=peak, limit_n=limit, ratio=peak / limit, stable=bool(peak <= limit),
                            frequency_hz=f0, frequency_source=source, window_m=window, step_m=step,
                            speed_m_s=speed, filter=description, settle_s=float(t[settle] - t[0]), sliding=sliding)


@dataclass(frozen=True)
class FlangeClearanceUse:
    """How much of the flangeway clearance a lateral motion uses.

    Attributes
    ----------
    peak_m : max |y| over the record (m).
    clearance_m : the flangeway clearance (m): the lateral shift from the centred position at which the
        flange touches the rail.
    fraction : peak_m / clearance_m; ≥ 1 means flange contact.
    """

    peak_m: float
    clearance_m: float
    fraction: float

    @property
    def flange_contact(self) -> bool:
        """True when the motion reaches the flange (fraction ≥ 1)."""
        return self.fraction >= 1.0


def flange_clearance_use(y_m: object, flange_clearance_m: float) -> FlangeClearanceUse:
    """The fraction of the flangeway clearance a wheelset's lateral motion uses: max |y| / clearance.

    Parameters
    ----------
    y_m : (n,) lateral displacement of the wheelset relative to the track centre (m), n ≥ 1.
    flange_clearance_m : the lateral shift at which the flange touches (m), > 0 (one side; a symmetric
        wheelset on symmetric rails).

    Returns
    -------
    FlangeClearanceUse

    Raises
    ------
    ValueError : ``y_m`` empty, not 1-D or not finite; ``flange_clearance_m`` not positive.
    """
    y = real_array("y_m", y_m, ndim=1)
    if y.size == 0:
        raise ValueError("y_m: is empty")
    c = number("flange_clearance_m", flange_clearance_m, positive=True)
    peak = float(np.max(np.abs(y)))
    return FlangeClearanceUse(peak_m=peak, clearance_m=c, fraction=peak / c)


def max_derailment_quotient(Y: object, Q: object) -> float:  # noqa: N803 (the field's symbols Y, Q)
    """The largest derailment quotient |Y/Q| of one wheel over a record (no sliding mean, no filter).

    Parameters
    ----------
    Y : (n,) lateral wheel/rail force of the wheel (N).
    Q : (n,) vertical wheel force of the same wheel (N), > 0 at every sample.

    Returns
    -------
    float : max over the samples of |Y/Q|.

    Raises
    ------
    ValueError : ``Y``/``Q`` of different shapes, empty or not finite; ``Q`` ≤ 0 at some sample (the wheel
        is lifted and Y/Q is undefined; the message gives the first such sample).
    """
    y = real_array("Y", Y, ndim=1)
    q = real_array("Q", Q, ndim=1)
    if y.shape != q.shape:
        raise ValueError(f"Q: shape {q.shape} does not match Y's {y.shape}")
    if y.size == 0:
        raise ValueError("Y: is empty")
    lifted = np.flatnonzero(q <= 0.0)
    if lifted.size:
        i = int(lifted[0])
        raise ValueError(f"Q: must be > 0 at every sample (wheel lift makes Y/Q undefined), got {q[i]!r} at sample {i}")
    return float(np.max(np.abs(y / q)))
