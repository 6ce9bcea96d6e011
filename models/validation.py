"""Input checks of the model layer: one helper per kind of input, one message style.

Every error is a ``ValueError`` whose message starts with the field name: ``"band: inverted …"``.
Numpy scalars are accepted wherever Python numbers are; complex values where real ones belong,
booleans where numbers belong, NaN and infinities are refused.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from numbers import Real
from pathlib import Path

import numpy as np

from railopt.models.units import RAD_PER_HZ


def number(name: str, value: object, *, positive: bool = False, non_negative: bool = False) -> float:
    """A finite real number (Python or numpy scalar, not bool), optionally > 0 or ≥ 0."""
    if isinstance(value, float):  # the common case (numpy's float64 too), without the abstract-class checks (µs)
        v = float(value)
    elif isinstance(value, bool | np.bool_) or not isinstance(value, Real | np.floating | np.integer):
        raise ValueError(f"{name}: must be a real number, got {value!r}")
    else:
        v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name}: must be finite, got {v}")
    if positive and not v > 0:
        raise ValueError(f"{name}: must be positive, got {v}")
    if non_negative and not v >= 0:
        raise ValueError(f"{name}: must be ≥ 0, got {v}")
    return v


def real_array(name: str, value: object, shape: tuple[int, ...] | None = None, ndim: int | None = None) -> np.ndarray:
    """A finite real float array; complex input is an error (never a silently dropped imaginary part)."""
    arr = np.asarray(value)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise ValueError(f"{name}: must be a numeric array, got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name}: must be real, got a complex array (dtype {arr.dtype})")
    arr = arr.astype(float)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: must be a {ndim}-D array, got shape {arr.shape}")
    if shape is not None and arr.shape != shape:
        raise ValueError(f"{name}: must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or infinite entries")
    return arr


def square_matrix(name: str, value: object, n: int | None = None) -> np.ndarray:
    """A finite real square matrix, at least 1×1, of size n when given."""
    a = real_array(name, value, ndim=2)
    if a.shape[0] != a.shape[1] or a.shape[0] == 0:
        raise ValueError(f"{name}: must be a non-empty square matrix, got shape {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name}: shape {a.shape} does not match M's ({n}, {n})")
    return a


def band(value: object, name: str = "band", unit: str = "rad/s") -> tuple[float, float]:
    """A frequency band in ``unit``: exactly two finite edges, 0 ≤ lower < upper."""
    try:
        edges = list(value)  # type: ignore[call-overload]
    except TypeError as exc:
        raise ValueError(f"{name}: must be a pair (lower, upper) in {unit}, got {value!r}") from exc
    if len(edges) != 2:
        raise ValueError(f"{name}: must be a pair (lower, upper) in {unit}, got {len(edges)} values")
    try:
        lo, hi = number(name, edges[0]), number(name, edges[1])
    except ValueError as exc:
        raise ValueError(f"{exc} (band edges must be finite numbers in {unit})") from None
    if lo < 0:
        raise ValueError(f"{name}: lower edge must be ≥ 0, got {lo}")
    if not hi > lo:
        raise ValueError(f"{name}: is empty or inverted, lower {lo} ≥ upper {hi}")
    return lo, hi


def frequencies_rad_s(value: object, name: str = "omega") -> np.ndarray:
    """Forcing frequencies in rad/s as a 1-D float array: numbers (not strings or booleans), finite, ≥ 0."""
    arr = np.atleast_1d(np.asarray(value, dtype=object) if not isinstance(value, np.ndarray) else value)
    if arr.dtype == object or arr.dtype.kind in "USb":
        bad = [v for v in arr.ravel() if isinstance(v, bool | np.bool_ | str | bytes)
               or not isinstance(v, Real | np.floating | np.integer)]
        if bad or arr.dtype.kind in "USb":
            shown = bad[0] if bad else arr.ravel()[0]
            raise ValueError(f"{name}: frequencies must be real numbers, got {shown!r}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name}: frequencies must be real, got a complex array")
    w = arr.astype(float).ravel()
    if not np.all(np.isfinite(w)):
        raise ValueError(f"{name}: must be finite and ≥ 0 (frequencies), got {w[~np.isfinite(w)][:3].tolist()}")
    if np.any(w < 0):
        raise ValueError(f"{name}: frequencies must be ≥ 0, got {w[w < 0][:3].tolist()}")
    return w


def forward_speeds(speeds: object, name: str = "speeds") -> np.ndarray:
    """Forward speeds (m/s) as a float array (K,): one number or a sequence of positive finite numbers.

    Raises
    ------
    ValueError
        An empty list, or an item that is not a positive finite number (naming ``speeds[i]``; "(forward
        speeds in m/s)" appended).
    """
    try:
        items = list(speeds) if isinstance(speeds, Sequence | np.ndarray) and not isinstance(speeds, str) else [speeds]
        values = [number(f"{name}[{i}]", s, positive=True) for i, s in enumerate(items)]
    except ValueError as exc:
        raise ValueError(f"{exc} (forward speeds in m/s)") from None
    if not values:
        raise ValueError(f"{name}: give at least one forward speed (m/s)")
    return np.array(values)


def positive(name: str, value: object) -> float:
    """A finite real number > 0."""
    return number(name, value, positive=True)


def poisson(name: str, value: object) -> float:
    """Poisson's ratio in [0, 0.5]."""
    x = number(name, value)
    if not 0.0 <= x <= 0.5:
        raise ValueError(f"{name}: Poisson's ratio must lie in [0, 0.5], got {x}")
    return x


def _in_rad_s(positional: object, in_hz: object, in_rad_s: object, names: tuple[str, str, str],
              check: object) -> object:
    """The one value of ``in_hz`` (converted ×2π) or ``in_rad_s``, checked by ``check(value, name, unit)``; a
    positional value is ambiguous and refused naming ``names[0]``."""
    positional_name, hz_name, rad_name = names
    if positional is not None:
        what = "band" if positional_name == "band" else "frequency"
        raise ValueError(f"{positional_name}: a positional {what} is ambiguous (Hz or rad/s?); give "
                         f"{hz_name}= in Hz or {rad_name}= in rad/s")
    if (in_hz is None) == (in_rad_s is None):
        raise ValueError(f"{hz_name}: give exactly one of {hz_name}= in Hz or {rad_name}= in rad/s")
    if in_hz is not None:
        return RAD_PER_HZ * np.asarray(check(in_hz, hz_name, "Hz"))
    return check(in_rad_s, rad_name, "rad/s")


def band_arg(positional: object = None, band_hz: object = None, band_rad_s: object = None) -> tuple[float, float]:
    """The one frequency convention of railopt's public API: a band is given as ``band_hz=(lo, hi)`` in Hz or
    ``band_rad_s=(lo, hi)`` in rad/s (exactly one); a positional ``band`` is refused, because (0.2, 5.0) in Hz
    read as rad/s gives a 13× different answer without any sign of it.  Returns (lo, hi) in rad/s."""
    lo, hi = _in_rad_s(positional, band_hz, band_rad_s, ("band", "band_hz", "band_rad_s"), band)
    return float(lo), float(hi)


def frequencies_arg(omega: object = None, frequencies_hz: object = None, omega_rad_s: object = None) -> np.ndarray:
    """Forcing frequencies as ``frequencies_hz=`` (Hz) or ``omega_rad_s=`` (rad/s), exactly one; a positional
    value is refused (see :func:`band_arg`).  Returns rad/s, 1-D."""
    return np.asarray(_in_rad_s(omega, frequencies_hz, omega_rad_s, ("omega", "frequencies_hz", "omega_rad_s"),
                                lambda value, name, unit: frequencies_rad_s(value, name)), dtype=float)


_COUNT_WORDS = {2: "two", 3: "three", 4: "four"}


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_number_table(path: str | Path, columns: tuple[str, ...]) -> tuple[np.ndarray, list[int]]:
    """The rows of a CSV file of numbers, ``(values (rows, len(columns)), 1-based file row of each)``.

    The file is UTF-8 text (a leading byte-order mark, as spreadsheets write, is not part of the first cell).  A
    first row none of whose cells parses as a number is a header; blank rows and empty cells are skipped.

    Raises
    ------
    ValueError
        ``path: cannot read ...``; ``<file>: not UTF-8 text ...``; or naming the file and the row: a cell that is
        not a number (a first row with some numbers is data, not a header), a wrong number of columns
        (``columns`` names them, with units), a non-finite value; fewer than two data rows.
    """
    p = Path(path)
    try:
        text = p.read_bytes().decode("utf-8-sig")
    except OSError as exc:
        raise ValueError(f"path: cannot read {str(p)!r}: {exc.strerror}") from exc
    except UnicodeDecodeError as exc:
        raise ValueError(f"{p}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset {exc.start}); save it as "
                         f"UTF-8 (or plain ASCII) comma-separated values: {', '.join(columns)}") from None
    n = len(columns)
    data: list[list[float]] = []
    rows: list[int] = []
    for i, row in enumerate(csv.reader(text.splitlines()), start=1):
        cells = [c.strip() for c in row if c.strip() != ""]
        if not cells:
            continue
        try:
            vals = [float(c) for c in cells]
        except ValueError:
            if i == 1 and not any(_is_number(c) for c in cells):
                continue  # header
            raise ValueError(f"{p}: row {i}: not {_COUNT_WORDS.get(n, n)} numbers: {row!r}") from None
        if len(vals) != n:
            raise ValueError(f"{p}: row {i}: expected {n} columns ({', '.join(columns)}), got {len(vals)}")
        if not all(math.isfinite(v) for v in vals):
            raise ValueError(f"{p}: row {i}: non-finite value")
        data.append(vals)
        rows.append(i)
    if len(data) < 2:
        raise ValueError(f"{p}: at least two data rows are needed, got {len(data)}")
    return np.array(data), rows


__all__ = [
    "band", "band_arg", "forward_speeds", "frequencies_arg", "frequencies_rad_s", "number", "poisson", "positive",
    "read_number_table", "real_array", "square_matrix",
]
