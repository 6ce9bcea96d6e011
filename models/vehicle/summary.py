"""A one-page summary of a vehicle: masses, axle loads, CG, lateral modes, critical speeds, plausibility.

:func:`vehicle_summary` returns a :class:`VehicleSummary` record; ``.to_text()`` / ``.to_markdown()``
render it for the command line (the ``railopt vehicle NAME_OR_FILE`` command and its argument parsing live in
:mod:`railopt.studies.cli`, :func:`~railopt.studies.cli.main_vehicle`); :func:`main_validate_vehicle` is the
vehicle part of ``railopt validate car.toml``.

Modes are the roots of the lateral view at the given speed (one eigen-solve), one row per mode, named by
:func:`railopt.models.stability.modes` from the shares of the modal kinetic energy by body group
(``"body lateral"``, ``"body hunting"``, ``"front truck hunting"``, ``"wheelset 3 lateral"``, ``"track"``);
the critical speeds name their critical mode the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from railopt.models.stability import modes
from railopt.models.units import GRAVITY
from railopt.models.vehicle.plausibility import NOMINAL_SPEED, PlausibilityWarning, plausibility
from railopt.models.vehicle.vehicle import Vehicle

SPEED_RANGE = (1.0, 150.0)  # m/s, searched for the critical speeds
TOL = 0.01  # m/s


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
    contact: list[tuple[str, str]] = field(default_factory=list)

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
        if self.contact:
            out += [f"{h}Wheel/rail contact", ""] + _table(["quantity", "value"], self.contact, markdown) + [""]
        out += [f"{h}Critical speeds (lateral, {SPEED_RANGE[0]:g}-{SPEED_RANGE[1]:g} m/s, tol {TOL} m/s)", ""]
        crit = []
        for track, c in self.critical.items():
            if c.stable_over_range:
                crit.append((track, "stable over the range", "", ""))
            else:
                note = " (unstable at the lower end)" if c.unstable_at_lower_end else ""
                crit.append((track, f"{c.speed:.2f} m/s ({c.speed * 3.6:.1f} km/h){note}",
                             f"{c.frequency:.3f} Hz", c.mode))
        out += _table(["track", "critical speed", "frequency", "critical mode"], crit, markdown) + [""]
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


def mode_table(vehicle: Vehicle, speed: float, track: str = "rigid") -> pd.DataFrame:
    """Lateral modes at ``speed`` (m/s) on ``track``: ``frequency_hz``, ``damping_ratio``, ``real``, ``name``,
    ``share``, one row per mode in ascending frequency, named by :func:`railopt.models.stability.modes`
    (kinetic-energy shares by body group: "body lateral", "body hunting", "front truck hunting", "track")."""
    table = modes(vehicle.lateral(track, speed=speed))
    return table[["frequency_hz", "damping_ratio", "real", "name", "share"]]


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
                          modes=modes, critical=critical, warnings=plausibility(vehicle),
                          contact=contact_rows(vehicle))


AMPLITUDES_MM = (1.0, 2.0, 3.0, 4.0, 5.0)
"""Wheelset amplitudes ŷ (mm) at which the summary lists the profiles' equivalent conicity (EN 15302)."""


def contact_rows(vehicle: Vehicle) -> list[tuple[str, str]]:
    """The summary's wheel/rail rows: the conicity the linear model uses and where it comes from; with
    ``[wheel_rail]`` profiles, the pair, and their EN 15302 equivalent conicity at :data:`AMPLITUDES_MM` with the
    lateral shift where flange contact begins (the left contact angle passing 45° as the wheelset moves left)."""
    c = vehicle.contact
    if c is None:
        return []
    w = vehicle.profiles
    stated = {"stated": "[contact] conicity", "delta_r table": "[contact] Δr table, EN 15302",
              "parameter override": "a parameter override"}.get(c.conicity_source, "")
    if c.conicity_source == "profiles":
        stated = f"[wheel_rail] profiles, EN 15302 at {w.conicity_amplitude * 1e3:g} mm"
    rows = [("conicity of the linear model", f"{c.conicity:.4g} ({stated})")]
    if w is None:
        return rows
    from railopt.models.contact import equivalent_conicity

    table = vehicle.contact_table()
    rows.append(("profiles", f"{w.wheel_profile} on {w.rail_profile} inclined {w.inclination:.4g}, gauge "
                             f"{w.gauge * 1e3:g} mm, back-to-back {w.flange_back * 1e3:g} mm"))
    values = []
    for a in AMPLITUDES_MM:
        try:
            values.append(f"{a:g} mm: {equivalent_conicity(table.y, table.delta_r, a * 1e-3):.3f}")
        except ValueError:
            values.append(f"{a:g} mm: –")
    rows.append(("tan γe of the profiles", ", ".join(values)))
    onset = table.flange_onset()
    rows.append(("flange contact from", f"y = {onset * 1e3:.2f} mm" if np.isfinite(onset) else "beyond the table"))
    return rows


def main_validate_vehicle(path: str) -> tuple[str, int]:
    """``railopt validate car.toml`` for a vehicle file: ``(text, 0)`` when it loads, its plausibility warnings listed
    one a line as ``warning: <file>: <key>: <what is unusual>: <likely slip>``; ``(error, 2)`` otherwise (a file that
    does not load: ``railopt: error: <file>: <key>: <what>``)."""
    from railopt.models.vehicle.loader import load_vehicle

    try:
        vehicle = load_vehicle(path)
    except ValueError as exc:
        return f"railopt: error: {exc}", 2
    warnings = plausibility(vehicle)
    head = f"{path}: valid vehicle file ({vehicle!r})"
    return "\n".join([head] + [f"warning: {w.line()}" for w in warnings]) + "\n", 0


__all__ = ["AMPLITUDES_MM", "SPEED_RANGE", "TOL", "VehicleSummary", "contact_rows", "main_validate_vehicle",
           "mode_table", "vehicle_summary"]
