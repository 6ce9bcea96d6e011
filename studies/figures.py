"""Every figure of the studies.  These functions only draw data they are given; models never draw.

Track figures (Figs 3.3–3.9 style): deflection is plotted positive downward (the rail sinks under
the wheel), distance along the track with the load at 0, ahead to the right.
``units="inch-pound"`` shows inches (the thesis's units), ``"SI"`` metres and millimetres.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from railopt.models.track.units import INCH

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
    """Parameters as a caption under the axes."""
    if note:
        fig.text(0.5, 0.01, note, ha="center", va="bottom", fontsize=7, color="0.3")
        fig.tight_layout(rect=(0.0, 0.07, 1.0, 1.0))
    else:
        fig.tight_layout()


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


def plot_frf_panels(panels: Sequence[tuple[str, str, Sequence[tuple[str, np.ndarray, np.ndarray, str]]]]) -> Figure:
    """One panel per (title, y label, curves); a curve is (label, frequency in Hz, |H|, style key).

    Style keys: ``"ref"`` (named designs: wide grey), ``"exact"``, ``"thesis"`` (optima of the two
    objectives); any other key cycles through matplotlib's colours.
    """
    fig = Figure(figsize=(6.2 * len(panels), 4.3))
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, (title, ylabel, curves) in zip(axes, panels, strict=True):
        for i, (label, f_hz, mag, key) in enumerate(curves):
            color, ls, lw, alpha = FRF_STYLES.get(key, (f"C{i % 10}", "-", 1.2, 1.0))
            ax.plot(f_hz, mag, color=color, ls=ls, lw=lw, alpha=alpha, label=label)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("forcing frequency (Hz)")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def plot_root_locus(locus: pd.DataFrame, critical: pd.DataFrame) -> Figure:
    """Fig 4.4 style: roots in the complex plane coloured by speed, one panel per model; and the
    least damping ratio against speed."""
    models = list(dict.fromkeys(locus["model"]))
    ncols = min(3, len(models) + 1)
    nrows = -(-(len(models) + 1) // ncols)
    fig = Figure(figsize=(5.4 * ncols, 4.2 * nrows))
    axes = list(fig.subplots(nrows, ncols, squeeze=False).ravel())
    for extra in axes[len(models) + 1:]:
        extra.set_visible(False)
    axes = axes[: len(models) + 1]
    for ax, m in zip(axes, models, strict=False):
        d = locus[(locus["model"] == m) & (locus["frequency_hz"] < 25)]
        sc = ax.scatter(d["real"], d["frequency_hz"], c=d["speed"], s=3, cmap="viridis")
        ax.axvline(0.0, color="k", lw=0.8)
        cs = critical[critical["model"] == m].iloc[0]
        ax.set_title(f"{m}: critical {cs['critical_speed_m_s']:.2f} m/s ({cs['critical_speed_mph']:.1f} mph)",
                     fontsize=9)
        ax.set_xlabel("Re s (1/s)")
        ax.set_ylabel("Im s / 2π (Hz)")
        ax.set_xlim(max(d["real"].min(), -15.0), max(d["real"].max() * 1.2, 1.0))
        ax.grid(alpha=0.3)
        fig.colorbar(sc, ax=ax, label="speed (m/s)")
    ax = axes[-1]
    for m in models:
        g = locus[locus["model"] == m].groupby("speed")["damping_ratio"].min()
        ax.plot(g.index, g.to_numpy(), label=m)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("speed (m/s)")
    ax.set_ylabel("least damping ratio")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


# ---------------------------------------------------------------------------------------------- forced response
TRACK_STYLES = {"rigid": ("C0", "-", 1.4), "flexible": ("C3", "--", 1.4)}


def plot_forced_response(series: dict[str, pd.DataFrame], title: str, note: str = "") -> Figure:
    """Figs 4.5–4.12 style: amplitude (top) and phase (bottom) of one output against the forcing frequency,
    rigid and flexible track on the same axes.

    Parameters
    ----------
    series : mapping track -> DataFrame
        Columns ``frequency_hz``, ``amplitude``, ``phase_deg``, ``unit``, ``output`` (one output).
    title : str
        Figure title (thesis figure label and name).
    note : str
        Caption (model, speed, irregularity).
    """
    fig = Figure(figsize=(7.0, 5.2))
    ax, axp = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    unit = output = ""
    for track, d in series.items():
        color, ls, lw = TRACK_STYLES.get(track, ("k", "-", 1.2))
        f = d["frequency_hz"].to_numpy()
        i = int(np.argmax(d["amplitude"].to_numpy()))
        ax.plot(f, d["amplitude"], color=color, ls=ls, lw=lw,
                label=f"{track} track (max {d['amplitude'].iloc[i]:.4g} at {f[i]:.3g} Hz)")
        axp.plot(f, d["phase_deg"], color=color, ls="none", marker=".", ms=1.5)
        unit, output = d["unit"].iloc[0], d["output"].iloc[0]
    ax.set_ylabel(f"|{output}| ({unit})")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    axp.set_ylabel("phase (deg)")
    axp.set_yticks([-180, -90, 0, 90, 180])
    axp.set_xlabel("forcing frequency f = S/L (Hz)")
    axp.grid(alpha=0.3)
    _caption(fig, note)
    return fig
