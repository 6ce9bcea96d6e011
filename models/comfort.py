"""Ride comfort: EN 12299 frequency weightings and comfort indices, and Sperling's ride index Wz.

Everything in SI: accelerations in m/s², frequencies in Hz, PSDs in (m/s²)²/Hz (one-sided).

Frequency weightings (EN 12299:2009 Annex A, after ISO 2631-1:1997 Annex A / ISO 2631-4:2001 and the
parameter table of ISO 8041) — a product of four transfer functions, s = 2πif:

* band-limiting high pass   ``H_h = s² / (s² + ω₁s/Q₁ + ω₁²)``,
* band-limiting low pass    ``H_l = ω₂² / (s² + ω₂s/Q₂ + ω₂²)``,
* acceleration–velocity transition ``H_t = (1 + s/ω₃) / (1 + s/(Q₄ω₄) + s²/ω₄²)``,
* upward step               ``H_s = (s² + ω₅s/Q₅ + ω₅²) / (s² + ω₆s/Q₆ + ω₆²)`` (1 when f₅ = f₆ = ∞),

``W(f) = K·H_h·H_l·H_t·H_s`` with ω_i = 2πf_i.  Parameters (:data:`WEIGHTINGS`):

========  ====  ===  =====  ====  ====  ====  ===  ===  ===  ===  =====
name      f₁    f₂   Q₁,Q₂  f₃    f₄    Q₄    f₅   Q₅   f₆   Q₆   K
========  ====  ===  =====  ====  ====  ====  ===  ===  ===  ===  =====
Wb        0.4   100  1/√2   16    16    0.63  2.5  0.8  4    0.8  1.024
Wb_iso    0.4   100  1/√2   16    16    0.55  2.5  0.9  4    0.95 1.024
Wc        0.4   100  1/√2   8     8     0.63  ∞    –    ∞    –    1
Wd        0.4   100  1/√2   2     2     0.63  ∞    –    ∞    –    1
Wk        0.4   100  1/√2   12.5  12.5  0.63  2.37 0.91 3.35 0.91 1
========  ====  ===  =====  ====  ====  ====  ===  ===  ===  ===  =====

``Wb`` is EN 12299's vertical weighting (written there with K = 0.4 on a step normalised to 1 at low
frequency: 0.4·(4/2.5)² = 1.024 in the form above; parameters as implemented in the public ``comfpy``
package, ``comfpy/filters.py``); ``Wb_iso`` is ISO 2631-4:2001 / ISO 8041 Table (Larson Davis HVM200
manual, Table 3.1); ``Wc``, ``Wd`` EN 12299 = ISO 2631-1; ``Wk`` ISO 2631-1 (for checks).

EN 12299 comfort (floor accelerations, x longitudinal, y lateral, z vertical; d = Wd, b = Wb):

* continuous comfort ``C_Cx(t), C_Cy(t), C_Cz(t)``: the RMS over the preceding 5 s of the Wd-, Wd- and
  Wb-weighted accelerations (:func:`continuous_comfort`);
* mean comfort (standard method) ``N_MV = 6·sqrt(a_XP,d,95² + a_YP,d,95² + a_ZP,b,95²)``: the 95th
  percentiles of the RMS values over consecutive 5-s blocks (the standard takes 60 blocks, 5 min)
  (:func:`mean_comfort`);
* mean comfort, complete method, standing ``N_VD = 3·sqrt(16 a_XP,d,50² + 4 a_YP,d,50² + a_ZP,b,50²)
  + 5 a_YP,d,95`` (50th and 95th percentiles) (:func:`standing_comfort`; the formula as reproduced in
  the secondary literature — not checked against the text of the standard);
* classes (:func:`comfort_class`): N < 1 very comfortable, 1 ≤ N < 2 comfortable, 2 ≤ N < 4 medium,
  4 ≤ N < 5 uncomfortable, N ≥ 5 very uncomfortable.

Sperling's ride index (Sperling 1941; Garg & Dukkipati, *Dynamics of Railway Vehicle Systems*, 1984,
§12): the weighting ``B_z(f) = 0.588·sqrt((1.911f² + (0.25f²)²) / ((1 − 0.277f²)² + (1.563f −
0.0368f³)²))`` (vertical), ``B_y = 1.25·B_z`` (lateral), f in Hz; a harmonic of peak acceleration a
(cm/s²) gives ``Wz = (a·B(f))^0.3``; a random signal ``Wz = (2·∫ B² S_a df)^0.15`` with S_a in
(cm/s²)²/Hz (the energy form used by ``comfpy``'s ``calculate_Wz``: the peak of the weighted
acceleration taken as √2 × its RMS).

Time histories: synthesised from PSDs with random phases and a recorded seed
(:func:`synthesise_accelerations`) or read from CSV (``time_s, ax, ay, az``; :func:`read_accelerations`).
Weighting is applied by FFT (exact linear filtering of the periodic extension; on measured records
the ends are wrapped — discard the first and last 1/f₁ = 2.5 s if that matters).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from railopt.models.units import RAD_PER_HZ as TWO_PI
from railopt.models.validation import number, read_number_table

BLOCK_S = 5.0  # EN 12299 RMS block length (s)
PsdLike = Callable[[np.ndarray], np.ndarray] | None


@dataclass(frozen=True)
class Weighting:
    """A frequency weighting ``K·H_h·H_l·H_t·H_s`` (see module docstring); frequencies in Hz.

    ``f5 = f6 = inf`` means no upward step.
    """

    name: str
    f1: float
    f2: float
    f3: float
    f4: float
    q4: float
    f5: float = math.inf
    q5: float = 1.0
    f6: float = math.inf
    q6: float = 1.0
    k: float = 1.0
    q1: float = 1.0 / math.sqrt(2.0)
    q2: float = 1.0 / math.sqrt(2.0)
    source: str = ""

    def response(self, frequency_hz: object) -> np.ndarray:
        """Complex W(f), dimensionless, at f (Hz), vectorised; f = 0 gives 0 (the high pass)."""
        f = np.asarray(frequency_hz, dtype=float)
        if not np.all(np.isfinite(f)) or np.any(f < 0):
            raise ValueError("frequency_hz: must be finite and ≥ 0 Hz")
        s = 1j * TWO_PI * f
        w1, w2, w3, w4 = (TWO_PI * x for x in (self.f1, self.f2, self.f3, self.f4))
        h = s * s / (s * s + w1 * s / self.q1 + w1 * w1)
        h = h * w2 * w2 / (s * s + w2 * s / self.q2 + w2 * w2)
        h = h * (1 + s / w3) / (1 + s / (self.q4 * w4) + s * s / w4**2)
        if math.isfinite(self.f5):
            w5, w6 = TWO_PI * self.f5, TWO_PI * self.f6
            h = h * (s * s + w5 * s / self.q5 + w5 * w5) / (s * s + w6 * s / self.q6 + w6 * w6)
        return self.k * h

    def magnitude(self, frequency_hz: object) -> np.ndarray:
        """|W(f)| at f (Hz)."""
        return np.abs(self.response(frequency_hz))


WEIGHTINGS: dict[str, Weighting] = {
    "Wb": Weighting("Wb", 0.4, 100.0, 16.0, 16.0, 0.63, 2.5, 0.8, 4.0, 0.8, 1.024,
                    source="EN 12299:2009 (K = 0.4 on the low-frequency-normalised step)"),
    "Wb_iso": Weighting("Wb_iso", 0.4, 100.0, 16.0, 16.0, 0.55, 2.5, 0.9, 4.0, 0.95, 1.024,
                        source="ISO 2631-4:2001 / ISO 8041"),
    "Wc": Weighting("Wc", 0.4, 100.0, 8.0, 8.0, 0.63, source="EN 12299 / ISO 2631-1"),
    "Wd": Weighting("Wd", 0.4, 100.0, 2.0, 2.0, 0.63, source="EN 12299 / ISO 2631-1"),
    "Wk": Weighting("Wk", 0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91, 1.0, source="ISO 2631-1"),
}


def weighting(name: str) -> Weighting:
    """The weighting ``name`` (Wb, Wb_iso, Wc, Wd, Wk); an unknown name is a ValueError naming it."""
    try:
        return WEIGHTINGS[name]
    except KeyError:
        raise ValueError(f"name: unknown weighting {name!r}; known: {sorted(WEIGHTINGS)}") from None


# ------------------------------------------------------------------------------------- time histories
@dataclass(frozen=True)
class AccelerationRecord:
    """Uniformly sampled floor accelerations (m/s²).

    Attributes
    ----------
    sample_rate_hz : float
    ax, ay, az : (N,) ndarray
        Longitudinal, lateral, vertical accelerations, m/s².
    seed : int or None
        The seed of a synthesised record (None for a measured one).
    source : str
    """

    sample_rate_hz: float
    ax: np.ndarray
    ay: np.ndarray
    az: np.ndarray
    seed: int | None = None
    source: str = ""

    @property
    def duration_s(self) -> float:
        """Length of the record in seconds: samples / ``sample_rate_hz``."""
        return len(self.az) / self.sample_rate_hz

    @property
    def time_s(self) -> np.ndarray:
        """Sample times in seconds, shape (n,), starting at 0."""
        return np.arange(len(self.az)) / self.sample_rate_hz


def _line_amplitudes(psd: PsdLike, f: np.ndarray, df: float, name: str) -> np.ndarray:
    if psd is None:
        return np.zeros_like(f)
    s = np.asarray(psd(f), dtype=float)
    if s.shape != f.shape or not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ValueError(f"{name}: must return finite PSD values ≥ 0 ((m/s²)²/Hz), one per frequency")
    return np.sqrt(2.0 * s * df)


def synthesise_accelerations(psd_x: PsdLike, psd_y: PsdLike, psd_z: PsdLike, duration_s: float,
                             sample_rate_hz: float, seed: int, frequency_step_hz: float | None = None,
                             band_hz: tuple[float, float] | None = None) -> AccelerationRecord:
    """Accelerations with the given one-sided PSDs ((m/s²)²/Hz, callables of f in Hz; None = zero axis).

    Random-phase harmonic sum ``a(t) = Σ_k sqrt(2 S(f_k) Δf) cos(2π f_k t + φ_k)``, f_k = kΔf inside
    ``band_hz`` (default: Δf … just below the Nyquist frequency), φ_k uniform on [0, 2π) from
    ``numpy.random.default_rng(seed)`` (x, then y, then z).  The variance is ``Σ S(f_k) Δf`` exactly.
    ``frequency_step_hz`` Δf defaults to 1/duration; it must be a multiple of 1/duration.  With
    Δf = 0.2 Hz every 5-s block holds whole periods of every line, so every block RMS equals the overall
    RMS (a closed form for N_MV).

    Raises
    ------
    ValueError
        Non-positive duration or rate, a non-integer ``seed``, a step that is not a multiple of 1/duration,
        a PSD callable returning bad values.
    """
    T = number("duration_s", duration_s, positive=True)
    fs = number("sample_rate_hz", sample_rate_hz, positive=True)
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise ValueError(f"seed: must be an integer (recorded with the record), got {seed!r}")
    n = int(round(T * fs))
    if abs(n - T * fs) > 1e-9 * T * fs or n < 4:
        raise ValueError(f"duration_s: duration × sample_rate_hz must be a whole number of samples ≥ 4, got {T * fs}")
    df = 1.0 / T if frequency_step_hz is None else number("frequency_step_hz", frequency_step_hz, positive=True)
    m = df * T
    if abs(m - round(m)) > 1e-9 * m or round(m) < 1:
        raise ValueError(f"frequency_step_hz: must be a multiple of 1/duration_s = {1 / T:g} Hz, got {df}")
    m = int(round(m))
    lo, hi = (df, 0.5 * fs) if band_hz is None else (float(band_hz[0]), float(band_hz[1]))
    bins = np.arange(m, n // 2, m)  # FFT bins k·m, strictly below Nyquist
    f = bins / T
    sel = (f >= lo - 1e-12) & (f <= hi + 1e-12)
    bins, f = bins[sel], f[sel]
    rng = np.random.default_rng(int(seed))
    axes = []
    for name, psd in (("psd_x", psd_x), ("psd_y", psd_y), ("psd_z", psd_z)):
        amp = _line_amplitudes(psd, f, df, name)
        phase = rng.uniform(0.0, TWO_PI, len(f))
        spec = np.zeros(n // 2 + 1, dtype=complex)
        spec[bins] = 0.5 * n * amp * np.exp(1j * phase)
        axes.append(np.fft.irfft(spec, n=n))
    return AccelerationRecord(fs, *axes, seed=int(seed), source=f"synthesised, seed {int(seed)}")


def read_accelerations(path: str | Path) -> AccelerationRecord:
    """Measured accelerations from CSV: columns ``time_s, ax, ay, az`` (s, m/s²); a header row is allowed.

    Raises
    ------
    ValueError
        Naming the file and the row: wrong column count, non-numeric or non-finite values, time not
        strictly increasing or not uniformly sampled (deviation > 1e-6 of the step), fewer than 2 rows.
    """
    arr, rows = read_number_table(path, ("time_s", "ax", "ay", "az"))
    p = Path(path)
    dt = np.diff(arr[:, 0])
    back = np.flatnonzero(dt <= 0)
    if back.size:
        k = int(back[0])
        raise ValueError(f"{p}: row {rows[k + 1]}: time must increase strictly ({arr[k + 1, 0]} after {arr[k, 0]})")
    step = float(np.median(dt))
    bad = np.flatnonzero(np.abs(dt - step) > 1e-6 * step)
    if bad.size:
        raise ValueError(f"{p}: row {rows[int(bad[0]) + 1]}: non-uniform "
                         f"sampling (step {dt[bad[0]]:g} s, expected {step:g} s)")
    return AccelerationRecord(1.0 / step, arr[:, 1].copy(), arr[:, 2].copy(), arr[:, 3].copy(), None, str(p))


def weighted(signal: np.ndarray, sample_rate_hz: float, w: Weighting | str) -> np.ndarray:
    """The signal filtered by the weighting (FFT, circular: exact for periodic signals), same units."""
    wt = weighting(w) if isinstance(w, str) else w
    x = np.asarray(signal, dtype=float)
    f = np.fft.rfftfreq(len(x), 1.0 / sample_rate_hz)
    return np.fft.irfft(np.fft.rfft(x) * wt.response(f), n=len(x))


def _block_rms(x: np.ndarray, fs: float) -> np.ndarray:
    nb = int(round(BLOCK_S * fs))
    blocks = len(x) // nb
    if blocks < 1:
        raise ValueError(f"record: shorter than one {BLOCK_S:g}-s block ({len(x) / fs:g} s)")
    return np.sqrt(np.mean(x[: blocks * nb].reshape(blocks, nb) ** 2, axis=1))


@dataclass(frozen=True)
class ComfortResult:
    """``value`` (N_MV or N_VD, dimensionless), its class, and the per-axis block RMS values (m/s²)."""

    value: float
    comfort_class: str
    block_rms_x: np.ndarray
    block_rms_y: np.ndarray
    block_rms_z: np.ndarray
    seed: int | None


def _weighted_blocks(record: AccelerationRecord) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    fs = record.sample_rate_hz
    return (_block_rms(weighted(record.ax, fs, "Wd"), fs), _block_rms(weighted(record.ay, fs, "Wd"), fs),
            _block_rms(weighted(record.az, fs, "Wb"), fs))


def mean_comfort(record: AccelerationRecord) -> ComfortResult:
    """EN 12299 mean comfort, standard method: ``N_MV = 6·sqrt(a_XP,d,95² + a_YP,d,95² + a_ZP,b,95²)``.

    a_·,95: 95th percentile (numpy linear interpolation) of the RMS over consecutive 5-s blocks of the
    Wd (x, y) and Wb (z) weighted floor accelerations (m/s²).  The standard uses 60 blocks (5 min); any
    whole number ≥ 1 is accepted here.
    """
    bx, by, bz = _weighted_blocks(record)
    a = [float(np.percentile(b, 95)) for b in (bx, by, bz)]
    n = 6.0 * math.sqrt(sum(v * v for v in a))
    return ComfortResult(n, comfort_class(n), bx, by, bz, record.seed)


def standing_comfort(record: AccelerationRecord) -> ComfortResult:
    """EN 12299 mean comfort, complete method, standing:
    ``N_VD = 3·sqrt(16 a_XP,d,50² + 4 a_YP,d,50² + a_ZP,b,50²) + 5 a_YP,d,95`` (5-s block RMS percentiles)."""
    bx, by, bz = _weighted_blocks(record)
    x50, y50, z50 = (float(np.percentile(b, 50)) for b in (bx, by, bz))
    n = 3.0 * math.sqrt(16 * x50**2 + 4 * y50**2 + z50**2) + 5.0 * float(np.percentile(by, 95))
    return ComfortResult(n, comfort_class(n), bx, by, bz, record.seed)


def continuous_comfort(record: AccelerationRecord) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """EN 12299 continuous comfort: ``(t, C_Cx, C_Cy, C_Cz)``, the RMS (m/s²) of the weighted accelerations
    over the 5 s preceding each sample time t ≥ 5 s (Wd for x and y, Wb for z)."""
    fs = record.sample_rate_hz
    nb = int(round(BLOCK_S * fs))
    if len(record.az) < nb:
        raise ValueError(f"record: shorter than {BLOCK_S:g} s")
    out = []
    for x, w in ((record.ax, "Wd"), (record.ay, "Wd"), (record.az, "Wb")):
        c = np.concatenate([[0.0], np.cumsum(weighted(x, fs, w) ** 2)])
        out.append(np.sqrt(np.maximum(c[nb:] - c[:-nb], 0.0) / nb))
    t = np.arange(nb, len(record.az) + 1) / fs
    return t, out[0], out[1], out[2]


def comfort_class(n: float) -> str:
    """EN 12299 comfort scale for N_MV (or N_VD, N_VA): <1, 1–2, 2–4, 4–5, ≥5."""
    n = number("n", n, non_negative=True)
    if n < 1:
        return "very comfortable"
    if n < 2:
        return "comfortable"
    if n < 4:
        return "medium"
    if n < 5:
        return "uncomfortable"
    return "very uncomfortable"


# ------------------------------------------------------------------------------- frequency domain
def _trapezoid(y: np.ndarray, x: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def _psd_grid(frequencies_hz: object, psd: object) -> tuple[np.ndarray, np.ndarray]:
    f = np.asarray(frequencies_hz, dtype=float)
    s = np.asarray(psd, dtype=float)
    if f.ndim != 1 or f.size < 2 or not np.all(np.isfinite(f)) or np.any(np.diff(f) <= 0) or f[0] < 0:
        raise ValueError("frequencies_hz: must be ≥ 2 increasing finite frequencies ≥ 0 Hz")
    if s.shape != f.shape or not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ValueError("psd: must be finite values ≥ 0 ((m/s²)²/Hz), one per frequency")
    return f, s


def weighted_rms_from_psd(frequencies_hz: object, psd: object, w: Weighting | str) -> float:
    """``sqrt(∫ |W(f)|² S_a(f) df)`` (m/s²) by the trapezoidal rule on the given grid (Hz, (m/s²)²/Hz)."""
    f, s = _psd_grid(frequencies_hz, psd)
    wt = weighting(w) if isinstance(w, str) else w
    return math.sqrt(float(_trapezoid(wt.magnitude(f) ** 2 * s, f)))


def mean_comfort_from_psd(frequencies_hz: object, psd_x: object, psd_y: object, psd_z: object) -> float:
    """Frequency-domain estimate ``6·sqrt(a_x,d² + a_y,d² + a_z,b²)`` from the weighted RMS values.

    For a stationary signal the 5-s block RMS values scatter around the overall RMS, so their 95th
    percentile exceeds it: this estimate is the N_MV of a record with no block-to-block scatter (a lower
    estimate; the scatter shrinks as the bandwidth × 5 s grows).
    """
    ax = weighted_rms_from_psd(frequencies_hz, psd_x, "Wd")
    ay = weighted_rms_from_psd(frequencies_hz, psd_y, "Wd")
    az = weighted_rms_from_psd(frequencies_hz, psd_z, "Wb")
    return 6.0 * math.sqrt(ax * ax + ay * ay + az * az)


# --------------------------------------------------------------------------------------- Sperling
SPERLING_DIRECTIONS = ("vertical", "lateral")


def sperling_weighting(frequency_hz: object, direction: str = "vertical") -> np.ndarray:
    """Sperling's B(f): vertical ``0.588·sqrt((1.911f² + (0.25f²)²)/((1 − 0.277f²)² + (1.563f − 0.0368f³)²))``,
    lateral 1.25 × vertical (f in Hz)."""
    if direction not in SPERLING_DIRECTIONS:
        raise ValueError(f"direction: must be one of {SPERLING_DIRECTIONS}, got {direction!r}")
    f = np.asarray(frequency_hz, dtype=float)
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("frequency_hz: must be finite and ≥ 0 Hz")
    num = 1.911 * f**2 + (0.25 * f**2) ** 2
    b = 0.588 * np.sqrt(num / ((1 - 0.277 * f**2) ** 2 + (1.563 * f - 0.0368 * f**3) ** 2))
    return b * (1.25 if direction == "lateral" else 1.0)


def sperling_index_harmonic(peak_acceleration_m_s2: float, frequency_hz: float, direction: str = "vertical") -> float:
    """Wz of one harmonic: ``(a·B(f))^0.3`` with a the peak acceleration in cm/s² (given in m/s²)."""
    a = number("peak_acceleration_m_s2", peak_acceleration_m_s2, non_negative=True)
    b = float(sperling_weighting(number("frequency_hz", frequency_hz, positive=True), direction))
    return (100.0 * a * b) ** 0.3


def sperling_index_from_psd(frequencies_hz: object, psd: object, direction: str = "vertical") -> float:
    """Wz of a random acceleration: ``(2·∫ B² S_a df)^0.15`` with S_a converted to (cm/s²)²/Hz (trapezoid)."""
    f, s = _psd_grid(frequencies_hz, psd)
    return (2.0 * float(_trapezoid(sperling_weighting(f, direction) ** 2 * s * 1e4, f))) ** 0.15


def sperling_index(signal: np.ndarray, sample_rate_hz: float, direction: str = "vertical") -> float:
    """Wz of a time history (m/s²): ``(√2 · 100 · RMS of the B-weighted signal)^0.3`` (FFT weighting)."""
    fs = number("sample_rate_hz", sample_rate_hz, positive=True)
    x = np.asarray(signal, dtype=float)
    f = np.fft.rfftfreq(len(x), 1.0 / fs)
    xb = np.fft.irfft(np.fft.rfft(x) * sperling_weighting(f, direction), n=len(x))
    return (math.sqrt(2.0) * 100.0 * math.sqrt(float(np.mean(xb**2)))) ** 0.3


__all__ = [
    "WEIGHTINGS",
    "AccelerationRecord",
    "ComfortResult",
    "Weighting",
    "comfort_class",
    "continuous_comfort",
    "mean_comfort",
    "mean_comfort_from_psd",
    "read_accelerations",
    "sperling_index",
    "sperling_index_from_psd",
    "sperling_index_harmonic",
    "sperling_weighting",
    "standing_comfort",
    "synthesise_accelerations",
    "weighted",
    "weighted_rms_from_psd",
    "weighting",
]
