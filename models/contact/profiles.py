"""Wheel and rail profiles: loading (SIMPACK ``.prw``/``.prr``, two-column CSV), analytic S1002 and 60E1, inclination.

Convention (one for every profile, converted at load)
-----------------------------------------------------
A :class:`Profile` is the cross-section of ONE wheel or rail, seen as the left-hand one of the track:

* ``y`` — lateral coordinate, m, positive towards the **field side** (away from the track centre): a wheel's
  flange lies at negative ``y``, a rail's gauge face at negative ``y``;
* ``z`` — height, m, positive **UP**.  A wheel's ``z`` is the height of its running surface in the wheelset
  frame, so its rolling radius at ``y`` is ``r0 − (z(y) − z(taping_line))``: the flange tip (a larger radius)
  has ``z`` ≈ −28 mm on S1002.  A rail's ``z`` is the height of its head; its crown is near ``z = 0``.

The right-hand wheel and rail are the mirror images (:mod:`.rigid_contact` places them).  Files use other
conventions — SIMPACK and the S1002 definition have z positive *down*, files are in mm — and the loaders
convert.  A profile is a single-valued function z(y) on strictly increasing ``y``; its height, slope and
curvature are those of the not-a-knot cubic spline through the points (``scipy.interpolate.CubicSpline``), so
the curvature of a measured, noisy profile is noisy too (smooth it before, if it matters).

Sources
-------
* S1002: EN 13715 / UIC 510-2 wheel profile, piecewise definition (sections A–H: a line, two polynomials, a
  line and four arcs) as circulated with the note "courtesy Dr. H. Netter, DLR"; checked against the
  Manchester Contact Benchmark's ``MBench_S1002_v3.prw`` (CONTACT, Apache-2.0) to 2e-6 mm.
* 60E1 (UIC60) head: EN 13674-1 arcs R300 (|y| ≤ 10.228 mm), R80 (to 26.0265 mm), R13 until its tangent is the
  1:20 flank (|y| = 35.9998 mm at 14.300 mm depth: head width 72 mm), then the flank.
* EN 15302 Annex D reference profiles (R-UIC 519-A/B/H/I wheels, S-UIC 519-A rail) as tabulated by
  criogenox/A_WRCC (MIT); the S-UIC 519-A data are **already inclined 1:20** (see ``docs/contact_geometry.md``).

Files shipped under ``data/profiles/`` (see its ``NOTICE``) are reached by name through :func:`load_profile`.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from railopt.models.validation import number as finite

DATA_DIR = Path(__file__).resolve().parent / "data" / "profiles"
KINDS = ("wheel", "rail")

# ---------------------------------------------------------------------------------------------------------------
# the profile


@dataclass(frozen=True, eq=False)
class Profile:
    """One wheel or rail cross-section (see the module doc for the convention).

    Attributes
    ----------
    y, z : numpy.ndarray
        Shape (n,), m; ``y`` strictly increasing (towards the field side), ``z`` up.  Read-only copies.
    kind : str
        ``"wheel"`` or ``"rail"``.
    name : str
        Free text (catalogue name or file).
    flange_back : float or None
        Wheels: ``y`` of the flange back (inner face), m (S1002 and the EN 15302 wheels: −0.070).  Needed to
        place the wheel on its axle from the flange-back (back-to-back) distance.
    taping_line : float
        Wheels: ``y`` of the nominal rolling circle (taping line), m, where the nominal radius r0 is taken
        (S1002: 0, i.e. 70 mm from the flange back).
    source : str
        Where the points come from (file, standard), for reports.

    Profiles compare by identity (``is``); the arrays are read-only.

    Raises
    ------
    ValueError
        Naming the field: arrays not 1-D of equal length ≥ 4, not finite, ``y`` not strictly increasing,
        unknown ``kind``, or a rail with a ``flange_back``.
    """

    y: np.ndarray
    z: np.ndarray
    kind: str
    name: str = ""
    flange_back: float | None = None
    taping_line: float = 0.0
    source: str = ""
    _spline: CubicSpline = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        y = np.array(self.y, dtype=float)
        z = np.array(self.z, dtype=float)
        where = f"profile {self.name!r}" if self.name else "profile"
        if y.ndim != 1 or z.shape != y.shape or y.size < 4:
            raise ValueError(f"{where}: y and z must be 1-D arrays of one length >= 4, got {y.shape} and {z.shape}")
        if not (np.all(np.isfinite(y)) and np.all(np.isfinite(z))):
            raise ValueError(f"{where}: y, z contain NaN or inf")
        if not np.all(np.diff(y) > 0.0):
            i = int(np.argmin(np.diff(y)))
            raise ValueError(f"{where}: y must be strictly increasing (y[{i}] = {y[i]:.9g} m, "
                             f"y[{i + 1}] = {y[i + 1]:.9g} m); a profile is a function z(y)")
        if self.kind not in KINDS:
            raise ValueError(f"{where}: kind must be one of {KINDS}, got {self.kind!r}")
        if self.kind == "rail" and self.flange_back is not None:
            raise ValueError(f"{where}: flange_back is a wheel's attribute (rail given one)")
        if self.flange_back is not None:
            object.__setattr__(self, "flange_back", finite("flange_back", self.flange_back))
        object.__setattr__(self, "taping_line", finite("taping_line", self.taping_line))
        y.setflags(write=False)
        z.setflags(write=False)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "_spline", CubicSpline(y, z))

    # --- evaluation (NaN outside [y[0], y[-1]]: no surface there) ---
    def _eval(self, y: np.ndarray | float, nu: int) -> np.ndarray:
        y = np.asarray(y, dtype=float)
        out = self._spline(y, nu)
        return np.where((y >= self.y[0]) & (y <= self.y[-1]), out, np.nan)

    def height(self, y: np.ndarray | float) -> np.ndarray:
        """z(y), m (NaN outside the profile's range)."""
        return self._eval(y, 0)

    def slope(self, y: np.ndarray | float) -> np.ndarray:
        """dz/dy (NaN outside the range)."""
        return self._eval(y, 1)

    def second_derivative(self, y: np.ndarray | float) -> np.ndarray:
        """d²z/dy², 1/m (NaN outside the range)."""
        return self._eval(y, 2)

    def curvature(self, y: np.ndarray | float) -> np.ndarray:
        """Signed curvature κ = z''/(1 + z'²)^{3/2}, 1/m, of the profile curve (κ < 0: bulging upwards)."""
        return self._eval(y, 2) / (1.0 + self._eval(y, 1) ** 2) ** 1.5

    @property
    def top(self) -> tuple[float, float]:
        """(y, z) of the highest point, m (from the points)."""
        i = int(np.argmax(self.z))
        return float(self.y[i]), float(self.z[i])

    def rolling_radius(self, y: np.ndarray | float, r0: float) -> np.ndarray:
        """Wheels: rolling radius r0 − (z(y) − z(taping_line)), m, of the circle through the point at ``y``."""
        if self.kind != "wheel":
            raise ValueError(f"profile {self.name!r}: rolling_radius needs a wheel profile")
        return r0 - (self.height(y) - float(self.height(self.taping_line)))

    def inclined(self, inclination: float, about: tuple[float, float] = (0.0, 0.0)) -> Profile:
        """This rail inclined towards the track centre by ``inclination`` (tan of the angle); see :func:`incline`."""
        return incline(self, inclination, about)


# ---------------------------------------------------------------------------------------------------------------
# inclination


def incline(profile: Profile, inclination: float, about: tuple[float, float] = (0.0, 0.0)) -> Profile:
    """Rail ``profile`` inclined towards the track centre by the angle atan(``inclination``) (1/40, 1/20, …).

    The profile is rotated counter-clockwise in its (y towards the field, z up) plane about the point
    ``about`` = (y, z), m (default the profile origin: the crown of the analytic 60E1): the running surface then
    rises towards the field side, its normal leans towards the track centre, and the highest point of an R300
    crown moves 300 mm × sin(atan 1/40) = 7.5 mm to the field side.  A negative ``inclination`` de-inclines.
    Points whose rotated ``y`` would fold back (a near-vertical flank turned past vertical) cannot be a function
    z(y); they are dropped from that end and the number dropped is written into ``source``.

    Raises
    ------
    ValueError
        ``inclination`` not finite or |inclination| ≥ 1; ``profile`` not a rail; fewer than 4 points left.
    """
    t = finite("inclination", inclination)
    if abs(t) >= 1.0:
        raise ValueError(f"inclination: give the tangent of the angle (1/40 = 0.025), got {t}")
    if profile.kind != "rail":
        raise ValueError(f"profile: incline() rotates a rail, got a {profile.kind} ({profile.name!r})")
    y0, z0 = (finite("about", about[0]), finite("about", about[1]))
    a = math.atan(t)
    c, s = math.cos(a), math.sin(a)
    dy, dz = profile.y - y0, profile.z - z0
    y = y0 + c * dy - s * dz
    z = z0 + s * dy + c * dz
    keep = _longest_increasing_run(y)
    dropped = y.size - int(keep.sum())
    note = f"{profile.source}; inclined by atan({t:.6g}) about ({y0:.6g}, {z0:.6g}) m"
    if dropped:
        note += f" ({dropped} folded flank points dropped)"
    return replace(profile, y=y[keep], z=z[keep], source=note)


def _longest_increasing_run(y: np.ndarray) -> np.ndarray:
    """Boolean mask of the longest run of consecutive points with strictly increasing ``y``."""
    up = np.diff(y) > 0.0
    best, best_start, start = 0, 0, 0
    for i, ok in enumerate(np.append(up, False)):
        if not ok:
            if i + 1 - start > best:
                best, best_start = i + 1 - start, start
            start = i + 1
    mask = np.zeros(y.size, dtype=bool)
    mask[best_start:best_start + best] = True
    return mask


# ---------------------------------------------------------------------------------------------------------------
# analytic S1002


# Sections of S1002 (F positive down, S and F in mm; S from the taping line, flange side negative), from
# ``../shared/profiles/s1002_sections.csv``, re-derived and checked in tests/models/contact/test_profiles.py.
S1002_BREAKPOINTS_MM = (60.0, 32.15796, -26.0, -35.0, -38.426669071, -39.764473993, -49.662510381, -62.764705882,
                        -70.0)
_B = (0.0, -3.358537058e-02, 1.565681624e-03, -2.810427944e-05, 5.844240864e-08, -1.562379023e-08, 5.309217349e-15,
      -5.957839843e-12, 2.646656573e-13)
_C = (-4.320221063e03, -1.038384026e03, -1.065501873e02, -6.051367875, -2.054332446e-01, -4.169739389e-03,
      -4.687195829e-05, -2.252755540e-07)


def s1002_depth_mm(s_mm: np.ndarray | float) -> np.ndarray:
    """S1002 profile depth F(S), mm, positive DOWN, at the lateral coordinate S (mm, flange side negative).

    Piecewise (EN 13715 / UIC 510-2 as circulated by H. Netter, DLR):
    A line F = 1.364323640 − 0.066666667 S on [32.15796, 60]; B 8th-degree polynomial on [−26, 32.15796];
    C 7th-degree polynomial on [−35, −26]; D arc R13 F = 16.446 − √(13² − (S + 26.210665)²) on
    [−38.426669071, −35]; E line F = −93.576667419 − 2.747477419 S on [−39.764473993, −38.426669071];
    F arc R20 F = 8.834924130 + √(20² − (S + 58.558326413)²) on [−49.662510381, −39.764473993];
    G arc R12 F = 16 + √(12² − (S + 55)²) on [−62.764705882, −49.662510381];
    H arc R20.5 F = 9.519259302 + √(20.5² − (S + 49.5)²) on [−70, −62.764705882].
    NaN outside [−70, 60].
    """
    s = np.asarray(s_mm, dtype=float)
    bp = S1002_BREAKPOINTS_MM
    with np.errstate(invalid="ignore"):
        pieces = [
            (s >= bp[1]) & (s <= bp[0]),
            (s >= bp[2]) & (s < bp[1]),
            (s >= bp[3]) & (s < bp[2]),
            (s >= bp[4]) & (s < bp[3]),
            (s >= bp[5]) & (s < bp[4]),
            (s >= bp[6]) & (s < bp[5]),
            (s >= bp[7]) & (s < bp[6]),
            (s >= bp[8]) & (s < bp[7]),
        ]
        values = [
            1.364323640 - 0.066666667 * s,
            np.polynomial.polynomial.polyval(s, _B),
            np.polynomial.polynomial.polyval(s, _C),
            16.446 - np.sqrt(np.maximum(13.0**2 - (s + 26.210665) ** 2, 0.0)),
            -93.576667419 - 2.747477419 * s,
            8.834924130 + np.sqrt(np.maximum(20.0**2 - (s + 58.558326413) ** 2, 0.0)),
            16.0 + np.sqrt(np.maximum(12.0**2 - (s + 55.0) ** 2, 0.0)),
            9.519259302 + np.sqrt(np.maximum(20.5**2 - (s + 49.5) ** 2, 0.0)),
        ]
    return np.select(pieces, values, default=np.nan)


def s1002(step: float = 1e-4) -> Profile:
    """S1002 wheel (analytic sections sampled every ``step`` m, plus the breakpoints), flange back −0.070 m.

    The taping line (nominal rolling circle, 70 mm from the flange back) is y = 0.  The flange back face itself
    (y = −70 mm, vertical) is the profile's first point.
    """
    step = finite("step", step)
    if not 1e-6 <= step <= 1e-3:
        raise ValueError(f"step: must lie in [1e-6, 1e-3] m, got {step}")
    s = np.union1d(np.arange(-70.0, 60.0, step * 1e3), np.array(S1002_BREAKPOINTS_MM))
    s = s[(s >= -70.0) & (s <= 60.0)]
    s = np.unique(np.round(s, 9))
    return Profile(y=s * 1e-3, z=-s1002_depth_mm(s) * 1e-3, kind="wheel", name="s1002", flange_back=-0.070,
                   taping_line=0.0, source="S1002 analytic sections (EN 13715 / UIC 510-2; H. Netter, DLR)")


# ---------------------------------------------------------------------------------------------------------------
# analytic 60E1 head


@dataclass(frozen=True)
class RailHeadArcs:
    """A rail head of three tangent arcs and a flank line, symmetric about y = 0, crown at (0, 0) (SI, m).

    ``radii`` (crown, middle, corner) and the lateral tangent points ``y12`` (crown/middle) and ``y23``
    (middle/corner); the corner arc runs until its slope reaches the flank inclination ``flank`` (dz/dy of
    the flank is 1/flank: 1:20 → flank = 1/20, nearly vertical); the flank then runs down to ``depth_max``.
    Each arc's centre lies on the normal of the previous arc at the tangent point (tangent continuity).
    """

    radii: tuple[float, float, float] = (0.300, 0.080, 0.013)
    y12: float = 0.010228
    y23: float = 0.0260265
    flank: float = 1.0 / 20.0
    depth_max: float = 0.020

    def geometry(self) -> dict[str, np.ndarray | float]:
        """Centres (y, z) of the three arcs (right half, z up) and the corner/flank tangent point, m."""
        R1, R2, R3 = self.radii
        c1 = np.array([0.0, -R1])
        t1 = math.asin(self.y12 / R1)
        c2 = c1 + (R1 - R2) * np.array([math.sin(t1), math.cos(t1)])
        t2 = math.asin((self.y23 - c2[0]) / R2)
        c3 = c2 + (R2 - R3) * np.array([math.sin(t2), math.cos(t2)])
        # corner/flank tangent point: outward normal (1, flank)/√(1 + flank²), slope of the flank −1/flank
        n = np.array([1.0, self.flank]) / math.hypot(1.0, self.flank)
        p3 = c3 + R3 * n
        return {"c1": c1, "c2": c2, "c3": c3, "t1": t1, "t2": t2, "p3": p3}

    def depth(self, y: np.ndarray | float) -> np.ndarray:
        """Height z(y) ≤ 0, m, of the head (z up, crown 0), symmetric; NaN beyond the flank's ``depth_max``."""
        g = self.geometry()
        R1, R2, R3 = self.radii
        a = np.abs(np.asarray(y, dtype=float))
        c1, c2, c3, p3 = g["c1"], g["c2"], g["c3"], g["p3"]
        with np.errstate(invalid="ignore"):
            z1 = c1[1] + np.sqrt(R1**2 - a**2)
            z2 = c2[1] + np.sqrt(R2**2 - (a - c2[0]) ** 2)
            z3 = c3[1] + np.sqrt(R3**2 - (a - c3[0]) ** 2)
            zf = p3[1] - (a - p3[0]) / self.flank
        z = np.select([a <= self.y12, a <= self.y23, a <= p3[0]], [z1, z2, z3], zf)
        return np.where(z >= -self.depth_max - 1e-12, z, np.nan)

    def profile(self, step: float = 1e-4, name: str = "60e1", source: str = "") -> Profile:
        """Sampled head as a rail :class:`Profile` (points every ``step`` m plus the tangent points)."""
        g = self.geometry()
        p3y = float(g["p3"][0])
        y_end = p3y + (self.depth_max + float(g["p3"][1])) * self.flank
        ys = np.arange(0.0, y_end, step)
        ys = np.union1d(ys, [self.y12, self.y23, p3y, y_end])
        ys = np.unique(np.concatenate([-ys[::-1], ys]))
        return Profile(y=ys, z=self.depth(ys), kind="rail", name=name, source=source)


RAIL_60E1 = RailHeadArcs()


def rail_60e1(step: float = 1e-4) -> Profile:
    """60E1 (UIC60) head from its arcs (EN 13674-1), uninclined, crown at (0, 0), flank down to 20 mm depth."""
    return RAIL_60E1.profile(step, name="60e1", source="60E1 head arcs R300/R80/R13 + 1:20 flank (EN 13674-1)")


# ---------------------------------------------------------------------------------------------------------------
# loaders

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"


def _simpack_number(text: str, path: Path, key: str) -> float:
    try:
        return float(text.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise ValueError(f"{path}: {key} = {text!r} is not a number") from None


def read_simpack_profile(path: str | Path, kind: str | None = None, flange_back: float | None = None,
                         taping_line: float = 0.0, name: str | None = None) -> Profile:
    """Load a SIMPACK rail-wheel profile (``.prw`` wheel, ``.prr`` rail).

    Reads the ``point.begin … point.end`` list (y, z[, weight]; ``!`` starts a comment) and the header flags
    ``type`` (0 rail, 1 wheel), ``mirror.y``, ``mirror.z``, ``inversion`` (reverses the point order: no effect on
    the geometry, profiles are stored with increasing y), ``units.len.f`` (file length units per metre:
    1000 for mm).  SIMPACK's z points down; it is negated here (z up, see the module doc).  After
    ``mirror.y`` the wheel's flange lies at negative y.  ``shift.y``, ``shift.z``, ``rotate`` must be 0 and the
    ``bound`` clipping off (min > max): profiles that need them are refused rather than half-read.

    Parameters
    ----------
    kind : {"wheel", "rail"}, optional
        Overrides the header ``type`` (default: from the header, else from the extension).
    flange_back, taping_line : float
        Wheels: see :class:`Profile` (m, in the loaded coordinates).

    Raises
    ------
    ValueError
        Naming the file and the line or key: unreadable numbers, missing point list, unsupported settings,
        non-monotone y.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        text = path.read_text(encoding="latin-1")
    except OSError as exc:
        raise ValueError(f"{path}: cannot read profile file ({exc.strerror})") from None
    keys: dict[str, str] = {}
    points: list[tuple[float, float]] = []
    in_points = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("!", 1)[0].strip()
        if not line:
            continue
        low = line.lower()
        if low == "point.begin":
            in_points = True
            continue
        if low == "point.end":
            in_points = False
            continue
        if in_points:
            parts = line.replace(",", " ").split()
            if len(parts) < 2:
                raise ValueError(f"{path}, line {lineno}: expected 'y z [weight]', got {raw.strip()!r}")
            try:
                points.append((float(parts[0].replace("D", "E")), float(parts[1].replace("D", "E"))))
            except ValueError:
                raise ValueError(f"{path}, line {lineno}: not a number in {raw.strip()!r}") from None
            continue
        m = re.match(r"^([A-Za-z0-9_.]+)\s*=\s*(.+)$", line)
        if m:
            keys.setdefault(m.group(1).lower(), m.group(2).strip().strip("'\""))  # header type before spline type
    if len(points) < 4:
        raise ValueError(f"{path}: no point list (point.begin … point.end with at least 4 points)")
    pts = np.array(points, dtype=float)

    def flag(key: str, default: float) -> float:
        return _simpack_number(keys[key], path, key) if key in keys else default

    for key in ("shift.y", "shift.z", "rotate"):
        if flag(key, 0.0) != 0.0:
            raise ValueError(f"{path}: {key} = {keys[key]} is not supported (only 0)")
    for axis in ("y", "z"):
        if flag(f"bound.{axis}.min", 1.0) <= flag(f"bound.{axis}.max", 0.0):
            raise ValueError(f"{path}: bound.{axis}.min/max clipping is not supported (set min > max)")
    factor = flag("units.len.f", 1000.0)
    if not factor > 0.0:
        raise ValueError(f"{path}: units.len.f must be > 0, got {factor}")
    y, z_down = pts[:, 0] / factor, pts[:, 1] / factor
    if flag("mirror.y", 0.0):
        y = -y
    if flag("mirror.z", 0.0):
        z_down = -z_down
    if flag("inversion", 0.0):
        y, z_down = y[::-1], z_down[::-1]
    if kind is None:
        if "type" in keys:
            kind = "wheel" if int(flag("type", 0.0)) == 1 else "rail"
        else:
            kind = "wheel" if path.suffix.lower() == ".prw" else "rail"
    order = np.argsort(y, kind="stable")
    try:
        return Profile(y=y[order], z=-z_down[order], kind=kind, name=name or path.stem, flange_back=flange_back,
                       taping_line=taping_line, source=str(path))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def read_profile_csv(path: str | Path, kind: str, *, z_down: bool = False, mirror_y: bool = False,
                     flange_back: float | None = None, taping_line: float = 0.0, name: str | None = None) -> Profile:
    """Load a two-column profile file: y, z in **mm** (comma, semicolon, tab or space separated).

    Lines starting with ``#`` are comments; one header line of non-numbers (e.g. ``y_mm,z_mm``) before the
    first data line is allowed; a UTF-8 byte-order mark is tolerated.  ``z_down=True`` for files whose z points
    down (SIMPACK-style), ``mirror_y=True`` to negate y.  Points are sorted by y.

    Raises
    ------
    ValueError
        Naming the file and line: a line without exactly two numbers (after the header), fewer than 4 points,
        repeated or non-monotone y, unreadable file.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not UTF-8 text") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read profile file ({exc.strerror})") from None
    rows: list[tuple[float, float]] = []
    header_seen = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        parts = [p for p in re.split(r"[,;\s]+", line) if p]
        try:
            values = [float(p) for p in parts]
        except ValueError:
            if not rows and not header_seen:
                header_seen = True
                continue
            raise ValueError(f"{path}, line {lineno}: expected two numbers (y, z in mm), got {line!r}") from None
        if len(values) != 2:
            raise ValueError(f"{path}, line {lineno}: expected two columns (y, z in mm), got {len(values)}")
        rows.append((values[0], values[1]))
    if len(rows) < 4:
        raise ValueError(f"{path}: needs at least 4 points (y, z in mm), found {len(rows)}")
    a = np.array(rows) * 1e-3
    y, z = a[:, 0], a[:, 1]
    if mirror_y:
        y = -y
    if z_down:
        z = -z
    order = np.argsort(y, kind="stable")
    try:
        return Profile(y=y[order], z=z[order], kind=kind, name=name or path.stem, flange_back=flange_back,
                       taping_line=taping_line, source=str(path))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


# ---------------------------------------------------------------------------------------------------------------
# catalogue


def _shipped_csv(file: str, kind: str, **kw: float) -> Callable[[], Profile]:
    return lambda: read_profile_csv(DATA_DIR / file, kind, **kw)


def _shipped_simpack(file: str, **kw: float) -> Callable[[], Profile]:
    return lambda: read_simpack_profile(DATA_DIR / file, **kw)


CATALOGUE: dict[str, tuple[Callable[[], Profile], str]] = {
    "s1002": (s1002, "S1002 wheel, analytic (EN 13715)"),
    "60e1": (rail_60e1, "60E1 rail head, analytic arcs, uninclined (EN 13674-1)"),
    "mbench_s1002": (_shipped_simpack("MBench_S1002_v3.prw", flange_back=-0.070),
                     "S1002 of the Manchester Contact Benchmark v3 (SIMPACK .prw)"),
    "mbench_uic60": (_shipped_simpack("MBench_UIC60_v3.prr"),
                     "UIC60 of the Manchester Contact Benchmark v3, already inclined 1:40, origin at the top"),
    "r_uic519_a": (_shipped_csv("en15302_r_uic519_a.csv", "wheel", flange_back=-0.070),
                   "EN 15302 Annex D wheel R-UIC 519-A"),
    "r_uic519_b": (_shipped_csv("en15302_r_uic519_b.csv", "wheel", flange_back=-0.070),
                   "EN 15302 Annex D wheel R-UIC 519-B"),
    "r_uic519_h": (_shipped_csv("en15302_r_uic519_h.csv", "wheel", flange_back=-0.070),
                   "EN 15302 Annex D wheel R-UIC 519-H"),
    "r_uic519_i": (_shipped_csv("en15302_r_uic519_i.csv", "wheel", flange_back=-0.070),
                   "EN 15302 Annex D wheel R-UIC 519-I"),
    "s_uic519_a": (_shipped_csv("en15302_s_uic519_a.csv", "rail"),
                   "EN 15302 Annex D rail S-UIC 519-A (data already inclined 1:20)"),
}
ALIASES = {"uic60": "60e1"}
PROFILE_NAMES = tuple(CATALOGUE) + tuple(ALIASES)


def _key(name: str) -> str:
    k = re.sub(r"[\s\-]+", "_", name.strip().lower())
    k = re.sub(r"^([rs])_?uic_?519_?([abhi])$", r"\1_uic519_\2", k)
    return ALIASES.get(k, k)


def is_profile_name(name: str) -> bool:
    """Whether ``name`` is a catalogue name or alias (:data:`PROFILE_NAMES`), spelled as :func:`load_profile`
    accepts it (case and ``-``/``_``/space insensitive)."""
    return _key(name) in CATALOGUE


@functools.lru_cache(maxsize=32)
def _cached(key: str) -> Profile:
    return CATALOGUE[key][0]()


def load_profile(name_or_path: str | Path, kind: str | None = None, **kw: object) -> Profile:
    """A profile by catalogue name (:data:`PROFILE_NAMES`, case and ``-``/``_``/space insensitive:
    ``"S1002"``, ``"60E1"``, ``"UIC60"``, ``"R-UIC 519-A"``) or by path (``.prw``/``.prr`` → SIMPACK,
    anything else → two-column CSV in mm, which then needs ``kind``).  Extra keywords go to the loader.  With a
    catalogue name, ``kind`` (when given) must be the profile's own: a wheel where a rail is wanted is an error.

    Raises
    ------
    ValueError
        Unknown name (listing the catalogue), missing file, or the loader's errors.
    """
    if isinstance(name_or_path, str) and _key(name_or_path) in CATALOGUE and not kw:
        profile = _cached(_key(name_or_path))
        if kind is not None and profile.kind != kind:
            raise ValueError(f"profile: {name_or_path!r} is a {profile.kind} profile, not a {kind} profile")
        return profile
    path = Path(name_or_path)
    if not path.is_file():
        raise ValueError(f"profile: {str(name_or_path)!r} is neither a catalogue name ({', '.join(PROFILE_NAMES)}) "
                         "nor an existing file")
    if path.suffix.lower() in (".prw", ".prr"):
        return read_simpack_profile(path, kind=kind, **kw)  # type: ignore[arg-type]
    if kind is None:
        raise ValueError(f"{path}: kind ('wheel' or 'rail') is required for a CSV profile")
    return read_profile_csv(path, kind, **kw)  # type: ignore[arg-type]


__all__ = [
    "ALIASES", "CATALOGUE", "DATA_DIR", "PROFILE_NAMES", "RAIL_60E1", "S1002_BREAKPOINTS_MM", "Profile", "RailHeadArcs",
    "incline", "is_profile_name", "load_profile", "rail_60e1", "read_profile_csv", "read_simpack_profile", "s1002",
    "s1002_depth_mm",
]
