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

from railopt.models.units import INCH

__all__ = [
    "Curve",
    "plot_amplification",
    "plot_before_after",
    "plot_forced_response",
    "plot_frf_panels",
    "plot_profiles",
    "plot_root_loci_before_after",
    "plot_root_locus",
    "plot_surfaces",
    "plot_time_histories",
    "plot_tradeoff",
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


def plot_forced_response(series: dict[str, pd.DataFrame], title: str,
                         peaks: dict[str, tuple[float, float]] | None = None, note: str = "",
                         log_frequency: bool = False) -> Figure:
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
    """
    fig = Figure(figsize=(7.0, 4.4))
    ax = fig.subplots()
    unit = output = ""
    for track, d in series.items():
        color, ls, lw = TRACK_STYLES.get(track, ("k", "-", 1.2))
        label = f"{track} track"
        if peaks and track in peaks:
            value, f_peak = peaks[track]
            label += f" (peak {value:.4g} at {f_peak:.3g} Hz)"
            ax.plot([f_peak], [value], marker="v", color=color, ms=5, ls="none")
        ax.plot(d["frequency_hz"], d["amplitude"], color=color, ls=ls, lw=lw, label=label)
        unit, output = d["unit"].iloc[0], d["output"].iloc[0]
    ax.set_ylabel(f"|{output}| ({unit})")
    ax.set_xlabel("forcing frequency f = S/L (Hz)")
    if log_frequency:
        ax.set_xscale("log")
    ax.set_title(title, fontsize=10)
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _caption(fig, note)
    return fig


def plot_before_after(f_hz: np.ndarray, before: np.ndarray, after: np.ndarray, title: str, ylabel: str) -> Figure:
    """An output's |H| before and after optimisation against frequency (Figs 4.13–4.16)."""
    fig = Figure(figsize=(7.0, 4.2))
    ax = fig.subplots()
    ax.plot(f_hz, before, "C3-", lw=1.3, label=f"before (peak {np.max(before):.4g})")
    ax.plot(f_hz, after, "C0-", lw=1.6, label=f"after (peak {np.max(after):.4g})")
    ax.set_xlabel("forcing frequency (Hz)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_root_loci_before_after(loci: dict[str, pd.DataFrame], title: str) -> Figure:
    """Velocity root loci of two designs (Fig 4.17): roots below 25 Hz, coloured by design."""
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    for (label, d), color in zip(loci.items(), ("C3", "C0"), strict=False):
        d = d[d["frequency_hz"] < 25]
        ax.scatter(d["real"], d["frequency_hz"], s=3, color=color, label=label)
    ax.axvline(0.0, color="k", lw=0.8)
    top = max(float(d["real"].max()) for d in loci.values())
    ax.set_xlim(-15.0, max(1.2 * top, 1.0))
    ax.set_xlabel("Re s (1/s)")
    ax.set_ylabel("Im s / 2π (Hz)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, markerscale=4)
    fig.tight_layout()
    return fig


def plot_tradeoff(table: pd.DataFrame, quantity: str, title: str) -> Figure:
    """U against a traded quantity: every design, the ε-sweep optima and the non-dominated front."""
    fig = Figure(figsize=(6.4, 4.4))
    ax = fig.subplots()
    starts = table[table["source"] == "start"]
    sweep = table[table["source"] == "sweep"]
    front = table[table["nondominated"]].sort_values(quantity)
    ax.scatter(starts[quantity], starts["U"], s=10, color="0.6", label="campaign starts")
    ax.scatter(sweep[quantity], sweep["U"], s=18, color="C0", label="ε-constraint optima")
    ax.plot(front[quantity], front["U"], "C3.-", lw=1.2, label="non-dominated")
    ax.set_xlabel(quantity)
    ax.set_ylabel("U (objective)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_surfaces(constrained, unconstrained, title: str) -> Figure:
    """Fig 4.18: U over two variables as 3-D surfaces and contours, constrained and unconstrained."""
    fig = Figure(figsize=(12.0, 9.0))
    for row, (surf, label) in enumerate(((unconstrained, "unconstrained (bounds relaxed toward zero)"),
                                         (constrained, "constrained (inside the bounds)"))):
        XI, XJ = np.meshgrid(np.log10(surf.xi), np.log10(surf.xj))
        Z = np.log10(np.where(np.isfinite(surf.values), surf.values, np.nan))
        ax = fig.add_subplot(2, 2, 2 * row + 1, projection="3d")
        ax.plot_surface(XI, XJ, Z, cmap="viridis", linewidth=0, antialiased=True)
        ax.set_xlabel(f"log10 {surf.names[0]}", fontsize=7)
        ax.set_ylabel(f"log10 {surf.names[1]}", fontsize=7)
        ax.set_zlabel("log10 U", fontsize=7)
        ax.set_title(label, fontsize=9)
        ax2 = fig.add_subplot(2, 2, 2 * row + 2)
        cs = ax2.contourf(XI, XJ, Z, levels=20, cmap="viridis")
        fig.colorbar(cs, ax=ax2, label="log10 U")
        m = surf.minimum(inside_only=row == 1)
        ax2.plot(np.log10(m[surf.names[0]]), np.log10(m[surf.names[1]]), "r*", ms=12, label="grid minimum")
        ax2.set_xlabel(f"log10 {surf.names[0]}")
        ax2.set_ylabel(f"log10 {surf.names[1]}")
        ax2.legend(fontsize=8)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig
