"""Every figure of the studies.  These functions only draw data they are given; models never draw.

Track figures (Figs 3.3–3.9 style): deflection is plotted positive downward (the rail sinks under
the wheel), distance along the track with the load at 0, ahead to the right.
``units="inch-pound"`` shows inches (the thesis's units), ``"SI"`` metres and millimetres.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from railopt.models.units import INCH
from railopt.studies.output.records import Boundary, FrfCurve, FrfPanel

if TYPE_CHECKING:
    from railopt.design import Surface

__all__ = [
    "Boundary", "Curve", "FrfCurve", "FrfPanel", "StylePicker", "plot_amplification", "plot_before_after",
    "plot_forced_response", "plot_frf_panels", "plot_profiles", "plot_root_loci_before_after", "plot_root_locus",
    "plot_surfaces", "plot_time_histories", "plot_tradeoff", "title_once", "vehicle_label", "wrap_title",
]

_UNITS = ("inch-pound", "SI")


@dataclass(frozen=True)
class Curve:
    """One curve: label, abscissa (m or s), deflection (m), and a matplotlib style."""

    label: str
    x: np.ndarray
    y: np.ndarray
    style: str = "-"


def _scales(units: str) -> tuple[float, str, float, str]:
    if units not in _UNITS:
        raise ValueError(f"units: must be one of {_UNITS}, got {units!r}")
    if units == "inch-pound":
        return 1.0 / INCH, "in", 1.0 / INCH, "in"
    return 1.0, "m", 1000.0, "mm"


def _caption(fig: Figure, note: str) -> None:
    """Parameters as a caption under the axes, wrapped to the figure's width, the axes raised above it."""
    if note:
        width, height = fig.get_size_inches()
        text = wrap_title(note, width - 0.4, 7)
        fig.text(0.5, 0.01, text, ha="center", va="bottom", fontsize=7, color="0.3")
        room = 0.02 + (text.count("\n") + 1) * 7 * 1.3 / 72 / height
        fig.tight_layout(rect=(0.0, max(0.07, room), 1.0, 1.0))
    else:
        fig.tight_layout()


def wrap_title(text: str, width_in: float, fontsize: float) -> str:
    """``text`` wrapped to lines that fit ``width_in`` inches at ``fontsize`` points (about 0.55 em a character)."""
    width = max(16, int(width_in * 72.0 / (0.55 * fontsize)))
    return "\n".join(textwrap.fill(part, width, break_on_hyphens=False) for part in text.split("\n"))


def title_once(title: str) -> str:
    """A ``"<label>: <text>"`` title whose text starts with the label again (a model labelled by its vehicle's name,
    described by the vehicle: ``"sd40-2: sd40-2 cab model, ..."``) without the repeated label: ``"sd40-2 cab model,
    ..."``; any other title unchanged."""
    head, sep, rest = title.partition(": ")
    return rest if sep and head and (rest == head or rest.startswith((f"{head} ", f"{head},", f"{head} ("))) else title


def vehicle_label(name: str, path: str | Path = "") -> str:
    """A vehicle as figure titles name it: its name and its file, ``"sd40-2 (sd40-2.toml)"`` (the name alone when
    it has no file)."""
    return f"{name} ({Path(path).name})" if str(path) else name


LINE_STYLES = ("-", "--", "-.", ":")


class StylePicker:
    """Distinct (colour, line style) pairs within one panel: a preferred pair when it is free, else the same colour
    with the next line style, else the next free pair of matplotlib's cycle."""

    def __init__(self) -> None:
        self.used: set[tuple[str, str]] = set()

    def take(self, color: str, ls: str = "-") -> tuple[str, str]:
        """The next unused line style of the given kind (colour and dash), so no two curves look alike."""
        candidates = [(color, ls)] + [(color, x) for x in LINE_STYLES] + \
                     [(f"C{i}", x) for x in LINE_STYLES for i in range(10)]
        for pair in candidates:
            if pair not in self.used:
                self.used.add(pair)
                return pair
        return color, ls


def _band_edge(values: np.ndarray) -> str:
    """", band edge" when the largest value lies at the first or last frequency (the curve still rising)."""
    k = int(np.argmax(values))
    return ", band edge" if k in (0, len(values) - 1) else ""


def plot_profiles(curves: Sequence[Curve], title: str, units: str = "inch-pound", note: str = "") -> Figure:
    """Deflection profiles y(ξ) against ξ = x − vt (figs 3.5–3.9 and the accelerating load).

    Parameters
    ----------
    curves : sequence of Curve
        ``x`` is ξ in m, ``y`` the deflection in m.
    title : str
        Figure title.
    units : {"inch-pound", "SI"}
        Display units.
    note : str
        Text placed in the lower right corner (parameters).
    """
    sx, ux, sy, uy = _scales(units)
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    for c in curves:
        ax.plot(np.asarray(c.x) * sx, np.asarray(c.y) * sy, c.style, label=c.label, lw=1.4)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.axvline(0.0, color="0.4", lw=0.8, ls=":")
    ax.invert_yaxis()
    ax.annotate(
        "P",
        xy=(0.0, 0.86),
        xycoords=("data", "axes fraction"),
        xytext=(0.0, 0.985),
        textcoords=("data", "axes fraction"),
        ha="center",
        va="top",
        arrowprops={"arrowstyle": "->"},
    )
    ax.set_xlabel(f"distance from the load ξ = x − vt ({ux})   ← behind | ahead →")
    ax.set_ylabel(f"deflection ({uy}, downward)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8, loc="best")
    _caption(fig, note)
    return fig


def plot_time_histories(
    curves: Sequence[Curve],
    title: str,
    units: str = "inch-pound",
    reference: float | None = None,
    reference_label: str = "",
    note: str = "",
    time_unit: str = "ms",
) -> Figure:
    """Deflection at a point against time (figs 3.3 and 3.4); ``x`` of each curve is t in s."""
    _, _, sy, uy = _scales(units)
    st = 1000.0 if time_unit == "ms" else 1.0
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    for c in curves:
        ax.plot(np.asarray(c.x) * st, np.asarray(c.y) * sy, c.style, label=c.label, lw=1.2, ms=4)
    if reference is not None:
        ax.axhline(reference * sy, color="k", ls="--", lw=0.9, label=reference_label)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel(f"time after loading ({time_unit})")
    ax.set_ylabel(f"deflection under the load ({uy}, downward)")
    ax.invert_yaxis()
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8)
    _caption(fig, note)
    return fig


def plot_amplification(
    speed_ratio: np.ndarray, curves: Sequence[tuple[str, np.ndarray]], title: str
) -> Figure:
    """Dynamic amplification y_max / y_static against v/v_cr for several damping ratios."""
    fig = Figure(figsize=(7.0, 4.2))
    ax = fig.subplots()
    for label, amp in curves:
        ax.plot(speed_ratio, np.minimum(amp, 1e3), label=label, lw=1.3)
    ax.set_xlabel("speed ratio v / v_cr")
    ax.set_ylabel("y_max / y_static")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


FRF_STYLES = {"ref": ("k", "-", 2.5, 0.35), "exact": ("C0", "-", 1.3, 1.0), "thesis": ("C3", "--", 1.2, 1.0)}


def plot_frf_panels(panels: Sequence[FrfPanel | Sequence[Any]]) -> Figure:
    """One panel per :class:`FrfPanel` (title, y label, curves); a curve is a :class:`FrfCurve` (label,
    frequency in Hz, |H|, style key).  Plain ``(title, ylabel, curves)`` tuples are taken as :meth:`FrfPanel.of`.

    Style keys: ``"ref"`` (named designs: wide grey), ``"exact"``, ``"thesis"`` (optima of the two
    objectives); any other key cycles through matplotlib's colours.  No two curves of a panel share colour and
    line style (a repeated key takes its colour's next line style).  Titles name the vehicle once
    (:func:`title_once`) and are wrapped to the panel's width;
    the y label should name the quantity, its unit and the input amplitude (``ModelSetup.axis_label``).
    """
    width = 6.2
    fig = Figure(figsize=(width * len(panels), 4.6))
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, panel in zip(axes, map(FrfPanel.of, panels), strict=True):
        title, ylabel = panel.title, panel.ylabel
        styles = StylePicker()
        for i, (label, f_hz, mag, key) in enumerate((c.label, c.f_hz, c.values, c.style) for c in panel.curves):
            color, ls, lw, alpha = FRF_STYLES.get(key, (f"C{i % 10}", LINE_STYLES[i % len(LINE_STYLES)], 1.4, 1.0))
            color, ls = styles.take(color, ls)
            ax.plot(f_hz, mag, color=color, ls=ls, lw=lw, alpha=alpha, label=label)
        ax.set_title(wrap_title(title_once(title), width - 1.2, 9), fontsize=9)
        ax.set_xlabel("forcing frequency (Hz)")
        ax.set_ylabel(wrap_title(ylabel, 3.8, 9), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def _upper_roots(d: pd.DataFrame) -> pd.DataFrame:
    """One root of each complex pair (Im s ≥ 0) and the real roots."""
    return d[d["imag"] >= 0] if "imag" in d else d


def _off_chart(d: pd.DataFrame, max_hz: float) -> int:
    """The most roots above ``max_hz`` at any one speed (one per complex pair)."""
    above = _upper_roots(d)
    above = above[above["frequency_hz"] > max_hz]
    return int(above.groupby("speed").size().max()) if len(above) else 0


def _below(d: pd.DataFrame, max_hz: float) -> pd.DataFrame:
    up = _upper_roots(d)
    return up[up["frequency_hz"] <= max_hz]


def _locus_panels(ax_z, ax_f, d: pd.DataFrame, max_hz: float, color: str, marker: str, label: str,
                  filled: bool = True) -> None:
    """Damping ratio (top) and frequency (bottom) of the roots below ``max_hz`` against speed."""
    shown = _below(d, max_hz)
    kw = {"ls": "none", "marker": marker, "ms": 2.2 if filled else 3.0, "color": color, "label": label,
          "markerfacecolor": color if filled else "none", "markeredgewidth": 0.6}
    ax_z.plot(shown["speed"], shown["damping_ratio"], **kw)
    ax_f.plot(shown["speed"], shown["frequency_hz"], **kw)


ZETA_LINEAR = 1e-3
"""The damping-ratio axes of root loci are symmetric-logarithmic, linear within ±ZETA_LINEAR (0.1 %): a root
0.1 % damped stands apart from the stability boundary ζ = 0 and from one 1 % damped."""
ZETA_TICKS = (-1.0, -0.1, -0.01, -0.001, 0.0, 0.001, 0.01, 0.1, 1.0)


def _locus_axes(ax_z, ax_f, max_hz: float, shown: pd.DataFrame) -> None:
    ax_z.axhline(0.0, color="k", lw=0.8)
    ax_z.set_ylabel("damping ratio ζ = −Re s / |s|\n(symlog, linear within ±0.1 %)")
    ax_f.set_ylabel("frequency |Im s| / 2π (Hz)")
    ax_f.set_xlabel("forward speed (m/s)")
    top = float(shown["frequency_hz"].max()) if len(shown) else max_hz
    ax_f.set_ylim(0.0, min(max_hz, 1.08 * top) if top > 0 else max_hz)
    low = float(shown["damping_ratio"].min()) if len(shown) else 0.0
    ax_z.set_yscale("symlog", linthresh=ZETA_LINEAR, linscale=0.6)
    bottom = min(-0.01, 1.5 * low)
    ax_z.set_ylim(bottom, 1.05)
    ax_z.set_yticks([t for t in ZETA_TICKS if bottom <= t <= 1.05])
    ax_z.set_yticklabels([f"{100 * t:g} %" for t in ZETA_TICKS if bottom <= t <= 1.05])
    for ax in (ax_z, ax_f):
        ax.grid(alpha=0.3)


def _required_speed(ax_z, ax_f, speed: float | None) -> None:
    """The required (maximum operating) speed: a dotted vertical line on both panels, a marker on the ζ = 0 line."""
    if speed is None:
        return
    for ax in (ax_z, ax_f):
        ax.axvline(speed, color="C2", ls=":", lw=1.2, zorder=5,
                   label=f"required speed {speed:.4g} m/s" if ax is ax_z else None)
    ax_z.plot([speed], [0.0], marker="v", color="C2", ms=7, ls="none", zorder=6, clip_on=False)


def plot_root_locus(locus: pd.DataFrame, critical: pd.DataFrame, max_hz: float = 25.0) -> Figure:
    """Velocity root loci in the rail convention: per model, the damping ratio (top, symmetric-log axis linear
    within ±0.1 %) and the frequency (bottom, Hz) of each root against forward speed, sharing the speed axis;
    roots with ζ < 0 (hunting) in red, named in the legend when the locus has mode names, the critical speed
    dashed.  Each panel's title names the model, its vehicle (``critical``'s ``vehicle`` column, when it has one)
    and its critical speed.  Roots above ``max_hz`` (track modes) are not drawn; each model's panel and the
    caption say how many.
    """
    models = list(dict.fromkeys(locus["model"]))
    ncols = min(2, len(models))
    mrows = -(-len(models) // ncols)
    width = 6.0
    fig = Figure(figsize=(width * ncols, 6.0 * mrows), layout="constrained")
    axes = fig.subplots(2 * mrows, ncols, squeeze=False, sharex="col")
    notes = []
    for k, m in enumerate(models):
        ax_z, ax_f = axes[2 * (k // ncols), k % ncols], axes[2 * (k // ncols) + 1, k % ncols]
        d = locus[locus["model"] == m]
        _locus_panels(ax_z, ax_f, d[d["damping_ratio"] >= 0], max_hz, "C0", "o", "roots, ζ ≥ 0")
        if (d["damping_ratio"] < 0).any():
            unstable = d[d["damping_ratio"] < 0]
            named = ", ".join(dict.fromkeys(unstable["name"])) if "name" in unstable else ""
            label = wrap_title(f"roots, ζ < 0{': ' + named if named else ''}", width - 2.5, 7)  # within the panel
            _locus_panels(ax_z, ax_f, unstable, max_hz, "C3", "o", label)
        cs = critical[critical["model"] == m].iloc[0]
        vehicle = cs.get("vehicle", "")
        title = (f"{m}{f' — {vehicle}' if isinstance(vehicle, str) and vehicle else ''}: critical speed "
                 f"{cs['critical_speed_m_s']:.2f} m/s ({cs['critical_speed_mph']:.1f} mph)")
        if isinstance(cs.get("mode"), str):
            title += f", {cs['mode']}"
        if np.isfinite(cs["critical_speed_m_s"]):
            for ax in (ax_z, ax_f):
                ax.axvline(cs["critical_speed_m_s"], color="k", ls="--", lw=0.9,
                           label="critical speed" if ax is ax_z else None)
        _locus_axes(ax_z, ax_f, max_hz, _below(d, max_hz))
        ax_z.set_title(wrap_title(title, width - 2.0, 9), fontsize=9)  # the axes, not the figure column, is the width
        ax_z.legend(fontsize=7, markerscale=3, loc="lower left")
        hidden = _off_chart(d, max_hz)
        if hidden:
            text = f"{hidden} roots above {max_hz:g} Hz not shown"
            ax_f.text(0.01, 0.98, text, transform=ax_f.transAxes, va="top", ha="left", fontsize=7, color="0.3")
            notes.append(f"{m}: {text}")
    for k in range(len(models), mrows * ncols):
        axes[2 * (k // ncols), k % ncols].set_visible(False)
        axes[2 * (k // ncols) + 1, k % ncols].set_visible(False)
    if notes:  # a caption the constrained layout makes room for
        fig.supxlabel(wrap_title("; ".join(notes), width * ncols - 0.5, 7), fontsize=7, color="0.3")
    return fig


# ---------------------------------------------------------------------------------------------- forced response
TRACK_STYLES = {"rigid": ("C0", "-", 1.4), "flexible": ("C3", "--", 1.4)}


def plot_forced_response(series: dict[str, pd.DataFrame], title: str,
                         peaks: dict[str, tuple[float, float]] | None = None, note: str = "",
                         log_frequency: bool = False, input_label: str = "") -> Figure:
    """Figs 4.5–4.12 style: amplitude of one output against the forcing frequency, rigid and flexible
    track on the same axes (the thesis plots amplitudes only).

    Parameters
    ----------
    series : mapping track -> DataFrame
        Columns ``frequency_hz``, ``amplitude``, ``unit``, ``output`` (one output).
    title : str
        Figure title (thesis figure label and name).
    peaks : mapping track -> (value, frequency in Hz), optional
        Certified band maxima, marked and quoted in the legend.
    note : str
        Caption (model, speed, irregularity).
    log_frequency : bool
        Logarithmic frequency axis.
    input_label : str
        The input the amplitudes are per (``"6.35 mm vertical irregularity"``), named on the y axis.
    """
    width = 7.0
    fig = Figure(figsize=(width, 4.6))
    ax = fig.subplots()
    unit = output = ""
    styles = StylePicker()
    for track, d in series.items():
        color, ls, lw = TRACK_STYLES.get(track, ("k", "-", 1.2))
        color, ls = styles.take(color, ls)
        label = f"{track} track"
        if peaks and track in peaks:
            value, f_peak = peaks[track]
            label += f" (peak {value:.4g} at {f_peak:.3g} Hz)"
            ax.plot([f_peak], [value], marker="v", color=color, ms=5, ls="none")
        ax.plot(d["frequency_hz"], d["amplitude"], color=color, ls=ls, lw=lw, label=label)
        unit, output = d["unit"].iloc[0], d["output"].iloc[0]
    per = f" per {input_label}" if input_label else ""
    ax.set_ylabel(wrap_title(f"|{output}| ({unit}{per})", 3.6, 9), fontsize=9)
    ax.set_xlabel("forcing frequency f = S/L (Hz)")
    if log_frequency:
        ax.set_xscale("log")
    ax.set_title(wrap_title(title, width - 1.0, 10), fontsize=10)
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _caption(fig, wrap_title(note, width - 0.4, 7))
    return fig


def plot_before_after(f_hz: np.ndarray, before: np.ndarray, after: np.ndarray, title: str, ylabel: str) -> Figure:
    """An output's |H| before and after optimisation against frequency (Figs 4.13–4.16).  The legend gives each
    peak and where it lies ("band edge" when the largest value is at an end of the band: the curve still rising);
    ``ylabel`` should name the quantity, its unit and the input amplitude (``ModelSetup.axis_label``)."""
    width = 7.0
    fig = Figure(figsize=(width, 4.4))
    ax = fig.subplots()
    for label, values, color, lw in (("before", before, "C3", 1.3), ("after", after, "C0", 1.6)):
        k = int(np.argmax(values))
        ax.plot(f_hz, values, color=color, ls="-", lw=lw,
                label=f"{label} (peak {values[k]:.4g} at {f_hz[k]:.3g} Hz{_band_edge(values)})")
        ax.plot([f_hz[k]], [values[k]], color=color, marker="v", ls="none", ms=5)
    ax.set_xlabel("forcing frequency (Hz)")
    ax.set_ylabel(wrap_title(ylabel, 3.6, 9), fontsize=9)
    ax.set_title(wrap_title(title, width - 1.0, 10), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


DESIGN_STYLES = (("C3", "o"), ("C0", "^"), ("C2", "s"), ("C4", "D"), ("C1", "v"), ("C5", "P"))


def plot_root_loci_before_after(loci: Mapping[str, pd.DataFrame], title: str, max_hz: float = 25.0,
                                required_speed: float | None = None) -> Figure:
    """Velocity root loci of two or more designs (Fig 4.17) in the rail convention: damping ratio (top, symmetric-log
    axis linear within ±0.1 %, so a 0.1 %-damped root reads) and frequency (Hz, bottom) against forward speed.

    ``loci``: design label → locus (:meth:`RootLocus.to_pandas` columns); a locus with a ``track`` column is drawn
    per track — the rows of every stability track (rigid and flexible when the stability rows use both) — filled
    markers for the first track, open ones for the others; one colour and marker per design.  ``required_speed``
    (m/s): the speed the stability rows require, a dotted line with a marker on ζ = 0.  Roots above ``max_hz``
    are counted in the caption, not drawn."""
    width = 7.0
    fig = Figure(figsize=(width, 6.8))
    ax_z, ax_f = fig.subplots(2, 1, sharex=True)
    notes = []
    for k, (label, d) in enumerate(loci.items()):
        color, marker = DESIGN_STYLES[k % len(DESIGN_STYLES)]
        tracks = list(dict.fromkeys(d["track"])) if "track" in d.columns else [None]
        for j, track in enumerate(tracks):
            part = d if track is None else d[d["track"] == track]
            name = label if track is None else f"{label}, {track} track"
            _locus_panels(ax_z, ax_f, part, max_hz, color, marker, name, filled=j == 0)
            hidden = _off_chart(part, max_hz)
            if hidden:
                notes.append(f"{name}: {hidden} roots above {max_hz:g} Hz not shown")
    _locus_axes(ax_z, ax_f, max_hz, pd.concat([_below(d, max_hz) for d in loci.values()]))
    _required_speed(ax_z, ax_f, required_speed)
    ax_z.set_title(wrap_title(title, width - 1.0, 10), fontsize=10)
    ax_z.legend(fontsize=7, markerscale=2.5, loc="lower left")
    _caption(fig, "; ".join(notes))
    return fig


def _front_line(front: pd.DataFrame, quantity: str, targets: Sequence[float] | None) -> tuple[np.ndarray, np.ndarray]:
    """The front's (quantity, U) points sorted by quantity, with a NaN between two consecutive points that are not
    neighbours: a sweep target lies strictly between them (more than 1e-3 of its size from both), so the sweep
    found no design there (infeasible, or every design for it lies beyond) — no segment may claim one."""
    d = front.sort_values([quantity, "U"])
    q, u = d[quantity].to_numpy(float), d["U"].to_numpy(float)
    xs, ys = [], []
    for k in range(len(q)):
        if k and targets is not None:
            lo, hi = q[k - 1], q[k]
            if any(lo + 1e-3 * max(abs(t), 1e-12) < t < hi - 1e-3 * max(abs(t), 1e-12) for t in targets):
                xs.append(np.nan)
                ys.append(np.nan)
        xs.append(q[k])
        ys.append(u[k])
    return np.array(xs), np.array(ys)


def _quantity_label(quantity: str) -> str:
    unit = " (m/s)" if quantity.endswith("_m_s") else " (m)" if "stroke" in quantity else \
        " (−Re s/|s|, dimensionless)" if "damping_ratio" in quantity else ""
    return f"{quantity}{unit}"


def _recommended_point(table: pd.DataFrame, quantity: str,
                       recommended: Mapping[str, float]) -> tuple[float, float] | None:
    """(quantity, U) of the recommended design: its row of ``table`` (every design variable it names equal to
    1e-6), else its own ``quantity`` and ``U`` when it carries them; None when neither."""
    names = [n for n in recommended if n in table.columns and n not in (quantity, "U")]
    if names:
        same = np.ones(len(table), dtype=bool)
        for n in names:
            same &= np.isclose(table[n].to_numpy(float), float(recommended[n]), rtol=1e-6, atol=0.0)
        if same.any():
            row = table[same].iloc[0]
            return float(row[quantity]), float(row["U"])
    if quantity in recommended and "U" in recommended:
        return float(recommended[quantity]), float(recommended["U"])
    return None


def plot_tradeoff(table: pd.DataFrame, quantity: str, title: str, required: float | None = None, *,
                  u_label: str | None = None, quantity_label: str | None = None,
                  recommended: Mapping[str, float] | None = None, targets: Sequence[float] | None = None) -> Figure:
    """U against a traded quantity: every design (campaign starts, sweep optima), the non-dominated front of the
    feasible ones and, with ``required``, the requirement as a vertical line; designs that miss another constraint
    (``feasible`` False: unconstrained starts, designs that hunt) are drawn apart, never on the front.

    ``u_label`` names U's axis: the objective output, what U is of it (certified peak, RMS) and its unit (the
    campaign's ``ModelSetup.axis_label``); ``quantity_label`` the traded quantity's axis (default: its name and the
    unit its name implies).  ``recommended`` (design variable → value, or ``quantity`` and ``U``) is marked with a
    star above everything else; when it is not among the designs the axes say so.  ``targets`` (the sweep's ε): the
    front's line is broken (a NaN) between consecutive front points with a target strictly between them — no design
    lies there.  The legend sits beside the axes, never over a point."""
    fig = Figure(figsize=(9.4, 4.6), layout="constrained")
    ax = fig.subplots()
    ok = table["feasible"] if "feasible" in table.columns else pd.Series(True, index=table.index)
    starts = table[table["source"].str.startswith("start") & ok]
    sweep = table[(table["source"] == "sweep") & ok]
    missed = table[~ok]
    front = table[table["nondominated"]]
    ax.scatter(starts[quantity], starts["U"], s=10, color="0.6", marker="o", label="campaign starts", zorder=2)
    ax.scatter(sweep[quantity], sweep["U"], s=22, color="C0", marker="s", label="constrained optima per target",
               zorder=3)
    if len(missed):
        ax.scatter(missed[quantity], missed["U"], s=16, color="C1", marker="x",
                   label="missing another constraint (not on the front)", zorder=3)
    xs, ys = _front_line(front, quantity, targets)
    broken = "; broken where no design lies" if np.isnan(xs).any() else ""
    ax.plot(xs, ys, color="C3", ls="-", marker=".", lw=1.2, label=f"non-dominated{broken}", zorder=4)
    if required is not None:
        ax.axvline(required, color="k", ls="--", lw=0.9, label=f"requirement {required:.4g}", zorder=1)
    if recommended is not None:
        point = _recommended_point(table, quantity, recommended)
        if point is not None:
            ax.plot([point[0]], [point[1]], marker="*", ms=15, color="gold", markeredgecolor="k", ls="none",
                    zorder=10, clip_on=False, label=f"recommended design (U = {point[1]:.4g})")
        else:
            ax.text(0.99, 0.01, "the recommended design is not among these designs", transform=ax.transAxes,
                    ha="right", va="bottom", fontsize=7, color="0.3")
    ax.set_xlabel(quantity_label or _quantity_label(quantity))
    ax.set_ylabel(wrap_title(u_label or "U: certified peak of the objective output", 3.8, 9), fontsize=9)
    ax.set_title(wrap_title(title, 6.0, 9), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


BOUNDARY_STYLES = (("k", "--"), ("C1", ":"), ("C2", "-."), ("C4", "--"))
# later marks larger: visible behind a star on the same point
MARK_STYLES = (("r", "*", 13), ("w", "X", 19), ("C1", "P", 19))


def plot_surfaces(constrained: Surface, unconstrained: Surface, title: str, boundaries: Sequence[Boundary] = (),
                  marks: Mapping[str, Mapping[str, float]] | None = None,
                  units: tuple[str, str, str] = ("", "", "")) -> Figure:
    """Fig 4.18: U over two variables as 3-D surfaces and contours, constrained and unconstrained.

    ``boundaries`` (:class:`Boundary`: label, values on the constrained grid, limit, at_least) are drawn as contours
    ``values = limit`` on the constrained contour panel, the infeasible side hatched; ``marks`` (label -> design
    values) are marked on both contour panels (e.g. the recommended design and the unconstrained optimum), above
    the contours and never clipped; the contour panels' legends sit below them, off the data.
    ``units`` of the two variables and of U: the axes read ``log10 <name> (<unit>)``, the value in that unit."""
    if units is None or isinstance(units, str) or len(units) != 3:
        raise ValueError(f"units: (unit of {constrained.names[0]}, of {constrained.names[1]}, of U), got {units!r}")

    def log_label(name: str, unit: str) -> str:
        return f"log10 {name} ({unit})" if unit and unit != "–" else f"log10 {name}"

    fig = Figure(figsize=(12.0, 10.0), layout="constrained")
    for row, (surf, label) in enumerate(((unconstrained, "unconstrained (bounds relaxed toward zero)"),
                                         (constrained, "constrained (inside the bounds)"))):
        XI, XJ = np.meshgrid(np.log10(surf.xi), np.log10(surf.xj))
        Z = np.log10(np.where(np.isfinite(surf.values), surf.values, np.nan))
        ax = fig.add_subplot(2, 2, 2 * row + 1, projection="3d")
        ax.plot_surface(XI, XJ, Z, cmap="viridis", linewidth=0, antialiased=True)
        ax.set_xlabel(log_label(surf.names[0], units[0]), fontsize=7)
        ax.set_ylabel(log_label(surf.names[1], units[1]), fontsize=7)
        ax.set_zlabel(log_label("U", units[2]), fontsize=7)
        ax.set_title(label, fontsize=9)
        ax2 = fig.add_subplot(2, 2, 2 * row + 2)
        cs = ax2.contourf(XI, XJ, Z, levels=20, cmap="viridis")
        fig.colorbar(cs, ax=ax2, label=log_label("U", units[2]))
        m = surf.minimum(inside_only=row == 1)
        ax2.plot(np.log10(m[surf.names[0]]), np.log10(m[surf.names[1]]), "c^", ms=8, label="grid minimum of U")
        if row == 1:
            for k, b in enumerate(boundaries):
                color, ls = BOUNDARY_STYLES[k % len(BOUNDARY_STYLES)]
                values = np.where(np.isfinite(b.values), b.values, np.nanmax(b.values[np.isfinite(b.values)])
                                  if np.any(np.isfinite(b.values)) else 0.0)
                if np.nanmin(values) < b.limit < np.nanmax(values):
                    ax2.contour(XI, XJ, values, levels=[b.limit], colors=color, linestyles=ls, linewidths=1.8)
                    bad = values < b.limit if b.at_least else values > b.limit
                    ax2.contourf(XI, XJ, bad.astype(float), levels=[0.5, 1.5], colors="none", hatches=["//"])
                ax2.plot([], [], color=color, ls=ls, label=f"{b.label} ({b.limit:.4g}); hatched: violated")
        for k, (name, values) in enumerate((marks or {}).items()):  # the first mark (the recommended design) on top
            color, marker, ms = MARK_STYLES[k % len(MARK_STYLES)]
            ax2.plot(np.log10(values[surf.names[0]]), np.log10(values[surf.names[1]]), marker=marker, color=color,
                     ms=ms, ls="none", markeredgecolor="k", label=name, zorder=20 - k, clip_on=False)
        ax2.set_xlabel(log_label(surf.names[0], units[0]))
        ax2.set_ylabel(log_label(surf.names[1], units[1]))
        ax2.set_title(label, fontsize=9)
        ax2.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, framealpha=0.85)
    fig.suptitle(title, fontsize=11)
    return fig
