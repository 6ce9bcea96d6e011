"""A one-page summary of a vehicle: masses, axle loads, CG, lateral modes, critical speeds, plausibility.

:func:`vehicle_summary` returns a :class:`VehicleSummary` record; ``.to_text()`` / ``.to_markdown()``
render it for the command line.  :func:`main_vehicle` is the whole ``railopt vehicle NAME_OR_FILE``
command (argument list in, ``(text, exit code)`` out) and :func:`main_validate_vehicle` the vehicle
part of ``railopt validate car.toml``, so the CLI wires each in a few lines.

Modes are the roots of the lateral view at the given speed (one eigen-solve), one row per conjugate
pair (and per real root), named by the body and coordinate holding the largest share of the mode's
kinetic energy ``Re(x̄_j (M x)_j)``: ``"body lateral"``, ``"body yaw"``, ``"front truck yaw"``,
``"wheelset 3 lateral"``, ``"track"``; among the oscillatory modes held mostly by trucks and
wheelsets (> 50 % of the energy) the least damped one is the kinematic mode, ``"front truck hunting"``.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from railopt.models.units import GRAVITY
from railopt.models.vehicle.elements import GROUND
from railopt.models.vehicle.plausibility import NOMINAL_SPEED, PlausibilityWarning, plausibility, sprung_bodies
from railopt.models.vehicle.vehicle import Vehicle

SPEED_RANGE = (1.0, 150.0)  # m/s, searched for the critical speeds
TOL = 0.01  # m/s
DOF_NAMES = {"u": "longitudinal", "v": "lateral", "w": "bounce", "alpha": "roll", "beta": "pitch", "gamma": "yaw"}


@dataclass(frozen=True, eq=False)
class VehicleSummary:
    """What :func:`vehicle_summary` found.

    Attributes
    ----------
    name, path : str
        Vehicle name and file.
    speed : float
        Forward speed of the modes table, m/s.
    track : str
        Track of the modes table (``"rigid"`` or ``"flexible"``).
    total_mass : float
        kg.
    mass_by_kind : dict
        ``{"body": kg, "wheelset": kg}``.
    axle_loads : dict
        Wheelset name -> static load W, N (the file's ``axle_load_N``, else the weight shared equally).
    cg : tuple of float
        Mass centre of the vehicle (x, y, z), m.
    modes : pandas.DataFrame
        Columns ``frequency_hz`` (|Im s|/2π), ``damping_ratio`` (−Re s/|s|), ``real`` (Re s, 1/s), ``name``,
        ``share`` (energy share of the named body and coordinate); ascending frequency.
    critical : dict
        Track -> :class:`~railopt.models.stability.CriticalSpeed` on ``"rigid"`` and (with ``[track]`` data)
        ``"flexible"`` track, over 1–150 m/s to 0.01 m/s.
    warnings : list of PlausibilityWarning
        :func:`~railopt.models.vehicle.plausibility.plausibility`.
    """

    name: str
    path: str
    speed: float
    track: str
    total_mass: float
    mass_by_kind: dict[str, float]
    axle_loads: dict[str, float]
    cg: tuple[float, float, float]
    modes: pd.DataFrame = field(repr=False)
    critical: dict = field(default_factory=dict)
    warnings: list[PlausibilityWarning] = field(default_factory=list)

    def __repr__(self) -> str:
        crit = ", ".join(f"{k} {c.speed:.2f} m/s" for k, c in self.critical.items())
        return (f"VehicleSummary({self.name!r}, {self.total_mass:,.0f} kg, {len(self.modes)} lateral modes at "
                f"{self.speed:g} m/s on {self.track} track, critical: {crit}, {len(self.warnings)} warnings)")

    def _lines(self, markdown: bool) -> list[str]:
        h = "## " if markdown else ""
        out = [f"# {self.name}" if markdown else f"Vehicle {self.name}  ({self.path})", ""]
        if markdown:
            out += [f"File: `{self.path}`", ""]
        out += [f"{h}Mass", ""]
        rows = [("total", f"{self.total_mass:,.0f} kg")]
        rows += [(f"kind {k}", f"{m:,.0f} kg") for k, m in self.mass_by_kind.items()]
        rows += [("CG (x, y, z)", "({:.3f}, {:.3f}, {:.3f}) m".format(*self.cg))]
        loads = sorted(set(round(w, 1) for w in self.axle_loads.values()))
        if loads:
            txt = ", ".join(f"{w / 1000:.1f} kN ({w / GRAVITY / 1000:.2f} t)" for w in loads)
            rows += [(f"axle load ({len(self.axle_loads)} wheelsets)", txt)]
        out += _table(["quantity", "value"], rows, markdown) + [""]
        out += [f"{h}Critical speeds (lateral, {SPEED_RANGE[0]:g}-{SPEED_RANGE[1]:g} m/s, tol {TOL} m/s)", ""]
        crit = []
        for track, c in self.critical.items():
            if c.stable_over_range:
                crit.append((track, "stable over the range", "", ""))
            else:
                note = " (unstable at the lower end)" if c.unstable_at_lower_end else ""
                crit.append((track, f"{c.speed:.2f} m/s ({c.speed * 3.6:.1f} km/h){note}",
                             f"{c.frequency:.3f} Hz", c.mode))
        out += _table(["track", "critical speed", "frequency", "largest coordinate"], crit, markdown) + [""]
        out += [f"{h}Lateral modes at {self.speed:g} m/s, {self.track} track", ""]
        rows = [(f"{r.frequency_hz:.3f}", f"{r.damping_ratio:.3f}", f"{r.real:.3f}", r.name, f"{r.share:.2f}")
                for r in self.modes.itertuples()]
        out += _table(["frequency_hz", "damping_ratio", "real", "name", "share"], rows, markdown) + [""]
        out += [f"{h}Plausibility", ""]
        out += [f"- {w}" for w in self.warnings] or ["- no warnings"]
        return out

    def to_text(self) -> str:
        """Plain-text report (tables aligned in columns)."""
        return "\n".join(self._lines(False)).rstrip() + "\n"

    def to_markdown(self) -> str:
        """Markdown report (pipe tables)."""
        return "\n".join(self._lines(True)).rstrip() + "\n"


def _table(head: Sequence[str], rows: Sequence[Sequence[str]], markdown: bool) -> list[str]:
    rows = [[str(c) for c in r] for r in rows]
    if markdown:
        return ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"] + [
            "| " + " | ".join(r) + " |" for r in rows]
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=False)]
    fmt = "  ".join(f"{{:<{w}}}" for w in widths)
    return [fmt.format(*head), fmt.format(*("-" * w for w in widths))] + [fmt.format(*r) for r in rows]


def _readable(name: str) -> str:
    return re.sub(r"(\D)(\d+)$", r"\1 \2", name)


def _truck(v: Vehicle, name: str) -> str:
    """``"front truck"`` / ``"rear bogie"`` for a body carrying wheelsets."""
    word = "bogie" if "bogie" in name.lower() else "truck"
    low = name.lower()
    side = "front" if "front" in low else "rear" if "rear" in low else ("front" if v.body(name).cg[0] > 0 else "rear")
    return f"{side} {word}"


def kinematic_band(vehicle: Vehicle, speed: float) -> tuple[float, float]:
    """Frequencies (Hz) where a hunting mode lies at ``speed``: half the truck's and twice the wheelset's kinematic
    frequency ``S/2π · sqrt(λ/(e0 r0))`` (the truck's divided by ``sqrt(1 + b²/e0²)``, b its largest half
    wheelbase); ``(0, 0)`` without contact."""
    c = vehicle.contact
    if c is None or c.conicity <= 0.0 or not vehicle.wheelsets:
        return 0.0, 0.0
    f_ws = speed / (2.0 * math.pi) * math.sqrt(c.conicity / (c.e0 * c.r0))
    b = 0.0
    for carrier in _carriers(vehicle):
        x0 = vehicle.body(carrier).cg[0]
        mine = [w.cg[0] - x0 for w in vehicle.wheelsets if carrier in _links_of(vehicle, w.name)]
        b = max([b] + [abs(x) for x in mine])
    return 0.5 * f_ws / math.sqrt(1.0 + (b / c.e0) ** 2), 2.0 * f_ws


def _links_of(v: Vehicle, name: str) -> set[str]:
    out = {e.body_b for e in v.elements if e.body_a == name} | {e.body_a for e in v.elements if e.body_b == name}
    out |= {c.to for c in v.constraints if c.body == name and c.to} | {c.body for c in v.constraints if c.to == name}
    return out - {GROUND}


def _carriers(v: Vehicle) -> set[str]:
    """Bodies of kind "body" linked to a wheelset (truck frames, bogies, motors)."""
    wheelsets = {b.name for b in v.wheelsets}
    return {b for w in wheelsets for b in _links_of(v, w)} - wheelsets


HUNTING_YAW_SHARE = 0.01  # share of the kinetic energy in truck / wheelset yaw of a hunting mode


def mode_table(vehicle: Vehicle, speed: float, track: str = "rigid") -> pd.DataFrame:
    """Lateral modes at ``speed`` (m/s) on ``track``: ``frequency_hz``, ``damping_ratio``, ``real``, ``name``,
    ``share``, one row per conjugate pair or real root, ascending frequency.

    A mode is named by the body and coordinate holding the largest share of its kinetic energy
    ``Re(x̄_j (M x)_j)`` (``"body lateral"``, ``"front truck yaw"``, ``"wheelset 3 lateral"``, ``"track"``;
    ``"wheelsets yaw"`` when the wheelsets hold most of it but none alone half).  The hunting mode is the least
    damped oscillatory mode inside :func:`kinematic_band` with at least 1 % of its energy in truck and wheelset yaw,
    named after the truck (or wheelset) holding most energy: ``"front truck hunting"``.
    """
    view = vehicle.lateral(track, speed=speed)
    m = view.at().modal()
    n = view.n_dof
    X = m.V[:n, :]
    energy = np.real(X.conj() * (view.M @ X))  # (n, 2n): per-coordinate parts of x̄ᵀ M x
    total = energy.sum(axis=0)
    bodies = [c.rsplit(".", 1)[0] for c in view.coordinates]
    dofs = [c.rsplit(".", 1)[1] for c in view.coordinates]
    sprung = set(sprung_bodies(vehicle))
    wheelsets = {b.name for b in vehicle.wheelsets}
    carriers = _carriers(vehicle) - sprung
    running = carriers | wheelsets
    yaw = np.array([b in running and d == "gamma" for b, d in zip(bodies, dofs, strict=True)])
    band = kinematic_band(vehicle, speed)
    rows = []
    for k, s in enumerate(m.s):
        if s.imag < 0.0:
            continue
        share = energy[:, k] / total[k] if total[k] > 0 else np.zeros(n)
        by_body: dict[str, float] = {}
        for b, e in zip(bodies, share, strict=True):
            by_body[b] = by_body.get(b, 0.0) + e
        body = max(by_body, key=by_body.get)
        idx = [i for i in range(n) if bodies[i] == body]
        dof = DOF_NAMES[dofs[max(idx, key=lambda i: share[i])]]
        ws_share = sum(e for b, e in by_body.items() if b in wheelsets)
        if body.endswith("_track") and body not in {b.name for b in vehicle.bodies}:
            name = "track"
        elif ws_share > 0.5 and by_body[body] < 0.5:
            name = f"wheelsets {dof}"
        elif body in wheelsets or body in sprung or body not in carriers:
            name = f"{_readable(body)} {dof}"
        else:
            name = f"{_truck(vehicle, body)} {dof}"
        mag = abs(s)
        f = abs(s.imag) / (2.0 * math.pi)
        gear = [b for b in by_body if b in running]
        lead = max(gear, key=by_body.get) if gear else ""
        hunting = f > 0.0 and band[0] <= f <= band[1] and float(share[yaw].sum()) >= HUNTING_YAW_SHARE and lead
        rows.append({"frequency_hz": f, "damping_ratio": -s.real / mag if mag else 1.0, "real": float(s.real),
                     "name": name, "share": float(by_body[body]), "_hunting": bool(hunting), "_lead": lead})
    df = pd.DataFrame(rows).sort_values(["frequency_hz", "real"], kind="stable").reset_index(drop=True)
    candidates = df[df["_hunting"]]
    if len(candidates):
        j = candidates["damping_ratio"].idxmin()
        lead = df.at[j, "_lead"]
        df.at[j, "name"] = f"{_truck(vehicle, lead) if lead in carriers else _readable(lead)} hunting"
    return df.drop(columns=["_hunting", "_lead"])


def vehicle_summary(vehicle: Vehicle, speed: float | None = None, track: str = "rigid") -> VehicleSummary:
    """Masses, axle loads, CG, lateral modes at ``speed`` on ``track``, critical speeds, plausibility warnings.

    Parameters
    ----------
    vehicle : Vehicle
    speed : float, optional
        Forward speed of the modes table, m/s (default 20 m/s).
    track : {"rigid", "flexible"}
        Track of the modes table; the critical speeds are given on both (flexible with ``[track]`` data).

    Returns
    -------
    VehicleSummary
    """
    speed = NOMINAL_SPEED if speed is None else speed
    if track not in ("rigid", "flexible"):
        raise ValueError(f"track: must be 'rigid' or 'flexible', got {track!r}")
    from railopt.models.stability import critical_speed

    masses = np.array([b.mass for b in vehicle.bodies])
    cgs = np.array([b.cg for b in vehicle.bodies])
    cg = tuple(float(x) for x in masses @ cgs / masses.sum())
    by_kind: dict[str, float] = {}
    for b in vehicle.bodies:
        by_kind[b.kind] = by_kind.get(b.kind, 0.0) + b.mass
    loads = {b.name: vehicle.axle_load() for b in vehicle.wheelsets}
    has_contact = vehicle.contact is not None and bool(vehicle.wheelsets)
    modes = mode_table(vehicle, speed, track) if has_contact or track == "rigid" else None
    critical = {}
    if has_contact:
        for t in ("rigid", "flexible") if vehicle.track is not None else ("rigid",):
            critical[t] = critical_speed(vehicle, track=t, speed_range=SPEED_RANGE, tol=TOL)
    return VehicleSummary(name=vehicle.name, path=vehicle.path, speed=float(speed), track=track,
                          total_mass=vehicle.total_mass, mass_by_kind=by_kind, axle_loads=loads, cg=cg,
                          modes=modes, critical=critical, warnings=plausibility(vehicle))


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    """Argument errors come back as text (the CLI prints them), not on stderr."""

    def error(self, message: str):  # noqa: D102
        raise _UsageError(f"{self.format_usage().rstrip()}\n{self.prog}: error: {message}")


def main_vehicle(argv: Sequence[str]) -> tuple[str, int]:
    """``railopt vehicle NAME_OR_FILE [--speed S] [--track rigid|flexible] [--markdown]``: the report and the exit
    code (0; 2 for a file error, with the message ``<file>: <key path>: <what>``)."""
    from railopt.models.vehicle.loader import load_vehicle

    parser = _Parser(prog="railopt vehicle", description="Summary of a vehicle file.")
    parser.add_argument("vehicle", help="bundled name (sd40-2, manchester-coach, single-wheelset) or a .toml file")
    parser.add_argument("--speed", type=float, default=None, help="speed of the modes table, m/s (default 20)")
    parser.add_argument("--track", choices=("rigid", "flexible"), default="rigid")
    parser.add_argument("--markdown", action="store_true", help="Markdown instead of plain text")
    try:
        args = parser.parse_args(list(argv))
    except _UsageError as exc:
        return str(exc), 2
    except SystemExit:  # --help
        return parser.format_help(), 0
    try:
        summary = vehicle_summary(load_vehicle(args.vehicle), speed=args.speed, track=args.track)
    except ValueError as exc:
        return f"railopt: error: {exc}", 2
    return (summary.to_markdown() if args.markdown else summary.to_text()), 0


def main_validate_vehicle(path: str) -> tuple[str, int]:
    """``railopt validate car.toml`` for a vehicle file: ``(text, 0)`` when it loads (plausibility warnings listed),
    ``(error, 2)`` otherwise."""
    from railopt.models.vehicle.loader import load_vehicle

    try:
        vehicle = load_vehicle(path)
    except ValueError as exc:
        return f"railopt: error: {exc}", 2
    warnings = plausibility(vehicle)
    head = f"{path}: valid vehicle file ({vehicle!r})"
    return "\n".join([head] + [f"warning: {vehicle.path}: {w}" for w in warnings]) + "\n", 0
