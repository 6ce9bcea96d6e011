"""The mode-shape figure: each mode of a vehicle's lateral view drawn on its plan view.

Every body of the view — car body, bogie or truck frames, wheelsets, motors — is a rectangle at its centre of mass,
displaced sideways by the mode's lateral motion and turned by its yaw: the real part of the mode shape at the phase
where its leading coordinate (the largest kinetic-energy share) peaks, all bodies scaled by one factor so that the
largest excursion of a body's corner or side (roll counted) reads ``displacement_m`` on the drawing.  The
undisplaced vehicle is drawn dashed beneath.  Roll does not show in a plan view: each panel says which share of
the mode's kinetic energy is roll; a lumped track body's roll is a dot under its wheelset.  The names are
:func:`railopt.models.mode_names.named_modes`'s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from railopt.models.mode_names import NamedMode, named_modes
from railopt.models.system import LinearSystem
from railopt.studies.output.figures import vehicle_label, wrap_title

__all__ = ["PlanView", "body_outlines", "plot_mode_shapes", "vehicle_mode_figure", "write_mode_figure"]

COLOURS = {"main": "C0", "frame": "C1", "wheelset": "C3", "other": "C2"}


class PlanView(Protocol):
    """What the figure reads of a vehicle view (:class:`~railopt.models.vehicle.views.VehicleView` has it):
    ``bodies`` (name, kind, cg in m), ``all_coordinates`` and ``T`` (every body coordinate z = T x of the view's
    coordinates x), ``coordinates``, ``groups`` (body → group), ``main_body`` and ``semi_gauge`` (m)."""

    bodies: Sequence
    all_coordinates: Sequence[str]
    T: np.ndarray
    coordinates: Sequence[str]
    groups: dict
    main_body: str | None
    semi_gauge: float | None


def body_outlines(view: PlanView) -> dict[str, tuple[float, float, float, float, str]]:
    """body → (x, y, half-length, half-width, role) in m of its plan-view rectangle, for every body of the view but
    lumped track bodies.  The car body spans every other body plus 1 m at each end; a frame (a body that names its
    group) spans its group's members plus 0.6 m, as wide as the gauge; a wheelset is ±0.15 m long and spans the
    gauge (``semi_gauge``, default 0.75 m); any other body is 0.6 m × 0.8 m."""
    gauge = float(view.semi_gauge or 0.75)
    places = {b.name: (float(b.cg[0]), float(b.cg[1]), b.kind) for b in view.bodies if b.kind != "track"}
    main = view.main_body
    groups = dict(view.groups)
    out = {}
    others = [x for name, (x, _, _) in places.items() if name != main]
    for name, (x, y, kind) in places.items():
        if name == main:
            half = max((abs(p - x) for p in others), default=1.0) + 1.0
            out[name] = (x, y, half, gauge + 0.7, "main")
        elif kind == "wheelset":
            out[name] = (x, y, 0.15, gauge, "wheelset")
        elif groups.get(name) == name:
            members = [places[m][0] for m, g in groups.items() if g == name and m != name and m in places]
            half = max((abs(p - x) for p in members), default=0.5) + 0.6
            out[name] = (x, y, half, gauge + 0.15, "frame")
        else:
            out[name] = (x, y, 0.3, 0.4, "other")
    return out


def _motion(view: PlanView, vector: np.ndarray) -> dict[str, tuple[float, float, float]]:
    """body → (lateral displacement v in m, yaw γ, roll α in rad): the real part of every body coordinate z = T x
    (0 for a coordinate the body does not have)."""
    z = np.real(np.asarray(view.T) @ vector)
    index = {c: i for i, c in enumerate(view.all_coordinates)}
    out = {}
    for b in view.bodies:
        out[b.name] = tuple(float(z[index[f"{b.name}.{d}"]]) if f"{b.name}.{d}" in index else 0.0
                            for d in ("v", "gamma", "alpha"))
    return out


def _corners(x: float, y: float, half_l: float, half_w: float, v: float = 0.0, angle: float = 0.0) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    local = np.array([[-half_l, -half_w], [half_l, -half_w], [half_l, half_w], [-half_l, half_w]])
    return np.column_stack([x + c * local[:, 0] - s * local[:, 1], y + v + s * local[:, 0] + c * local[:, 1]])


def _roll_share(system: LinearSystem, mode: NamedMode) -> float:
    e = np.real(np.conj(mode.vector) * (system.M @ mode.vector))
    roll = [i for i, c in enumerate(system.names) if c.endswith(".alpha")]
    return float(np.sum(e[roll]) / np.sum(e)) if np.sum(e) > 0 else 0.0


def plot_mode_shapes(view: PlanView, system: LinearSystem, title: str, columns: int = 3,
                     displacement_m: float = 0.8) -> Figure:
    """One plan-view panel per mode of ``system`` (the view at a speed), in mode order, titled with the mode's name,
    frequency (Hz) and damping ratio.

    ``view`` gives the bodies' places and the map from the view's coordinates to every body's (:class:`PlanView`);
    ``system.names`` must be ``view.coordinates``.  Each body's rectangle (:func:`body_outlines`) is moved by the
    mode's lateral displacement and turned by its yaw, scaled so that the largest corner excursion of any rectangle is
    ``displacement_m`` (m on the drawing; the panel says the scale); x forward to the right, y to the left up.
    ``title`` (the figure's) should name the vehicle, its file, the speed and the track.

    Raises
    ------
    ValueError
        ``system`` whose coordinates are not the view's, ``columns`` < 1, ``displacement_m`` ≤ 0.
    """
    if tuple(system.names) != tuple(view.coordinates):
        raise ValueError(f"system: coordinates {list(system.names)[:4]}... are not the view's "
                         f"{list(view.coordinates)[:4]}...")
    if columns < 1:
        raise ValueError(f"columns: must be ≥ 1, got {columns}")
    if not displacement_m > 0:
        raise ValueError(f"displacement_m: must be > 0, got {displacement_m}")
    modes = named_modes(system, view.groups, view.main_body)
    outlines = body_outlines(view)
    ncols = min(columns, len(modes))
    nrows = -(-len(modes) // ncols)
    length = 2 * max(abs(x) + h for x, _, h, _, _ in outlines.values())
    width_in = 4.6
    fig = Figure(figsize=(width_in * ncols, 1.8 * nrows + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    order = sorted(outlines, key=lambda b: ("main", "frame", "other", "wheelset").index(outlines[b][4]))
    for ax, mode in zip(axes, modes, strict=False):
        motion = _motion(view, mode.vector)
        reach = 0.0  # the largest excursion of a corner; roll (a side's sway; a track body's) counted, not drawn
        for body, (v, gamma, alpha) in motion.items():
            half_l, half_w = outlines[body][2:4] if body in outlines else (0.0, float(view.semi_gauge or 0.75))
            reach = max(reach, abs(v) + abs(gamma) * math.hypot(half_l, half_w) + abs(alpha) * half_w)
        scale = displacement_m / reach if reach > 0 else 0.0
        for z, body in enumerate(order):
            x, y, half_l, half_w, role = outlines[body]
            v, gamma, _ = motion[body]
            colour = COLOURS[role]
            ax.add_patch(Polygon(_corners(x, y, half_l, half_w), closed=True, fill=False, ls="--", lw=0.6,
                                 ec="0.65", zorder=1 + z))
            ax.add_patch(Polygon(_corners(x, y, half_l, half_w, scale * v, scale * gamma), closed=True,
                                 fc=colour, alpha=0.35 if role == "main" else 0.6, ec=colour, lw=1.0,
                                 zorder=20 + z, label=body))
        track = [(float(b.cg[0]), abs(motion[b.name][2]) * scale) for b in view.bodies if b.kind == "track"]
        if track:  # a lumped track body rolls: a dot under its wheelset, its size the rail's sway
            gauge = float(view.semi_gauge or 0.75)
            ax.scatter([x for x, _ in track], [-(gauge + 1.0)] * len(track), s=[60.0 * a * gauge / displacement_m
                                                                               for _, a in track],
                       color="0.3", zorder=40, label="track roll")
        ax.set_xlim(-0.55 * length, 0.55 * length)
        ax.set_ylim(-(outlines[view.main_body][3] if view.main_body in outlines else 2.0) - 1.2,
                    (outlines[view.main_body][3] if view.main_body in outlines else 2.0) + 1.2)
        ax.set_aspect("equal")
        ax.set_title(wrap_title(f"{mode.name}\n{mode.frequency_hz:.3f} Hz, ζ = {mode.damping_ratio:.3f}",
                                width_in - 0.4, 8), fontsize=8)
        roll = _roll_share(system, mode)
        note = f"×{scale:.3g} (largest excursion {displacement_m:g} m)"
        if roll >= 0.2:
            note += f"; roll {100 * roll:.0f} % of the energy (not seen in plan)"
        ax.text(0.01, 0.02, note, transform=ax.transAxes, fontsize=6, color="0.3", va="bottom")
        ax.tick_params(labelsize=6)
        ax.set_xlabel("x (m, forward →)", fontsize=7)
        ax.set_ylabel("y (m, left)", fontsize=7)
    for ax in axes[len(modes):]:
        ax.set_visible(False)
    fig.suptitle(wrap_title(title, width_in * ncols - 0.5, 10), fontsize=10)
    return fig


def vehicle_mode_figure(vehicle, speed: float, track: str = "rigid", title: str | None = None) -> Figure:
    """:func:`plot_mode_shapes` of a vehicle's lateral view on ``track`` at ``speed`` (m/s), titled with the vehicle's
    name and file, the speed and the track (``title`` replaces the words after the vehicle).  ``vehicle`` is a
    :class:`~railopt.models.vehicle.vehicle.Vehicle`; errors are its view's (a flexible track without ``[track]``)."""
    view = vehicle.lateral(track)
    what = title or f"lateral mode shapes at {speed:g} m/s, {track} track"
    return plot_mode_shapes(view, view.at(speed=speed), f"{vehicle_label(vehicle.name, vehicle.path)}: {what}")


def write_mode_figure(vehicle, speed: float, track: str, path: str | Path, dpi: int = 110) -> Path:
    """Write :func:`vehicle_mode_figure` to ``path`` (PNG; ``""``: ``<vehicle name>_modes.png`` in the working
    folder) and return the path.  Raises ``ValueError`` naming the file when it cannot be written."""
    out = Path(path) if str(path) else Path(f"{vehicle.name}_modes.png")
    fig = vehicle_mode_figure(vehicle, speed, track)
    try:
        fig.savefig(out, dpi=dpi)
    except OSError as exc:
        raise ValueError(f"{out}: cannot write the mode-shape figure ({exc.strerror or exc})") from None
    return out
