"""Study kind ``track``: the track-dynamics figures of thesis Ch. 3 (Figs 3.3–3.9) and tables.

A config names the track (SI keys with units in the name), the figures to draw and the grids of
the amplification table.  ``compute`` collects the tables and the figure specs (a plot function and its
data) in order; ``report`` writes them and returns the summary markdown.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Literal

import numpy as np
import pandas as pd
from pydantic import Field, model_validator

from railopt.models.track import (
    Beam,
    ImpulseLoad,
    MovingLoad,
    SuddenLoad,
    dynamic_amplification,
    f0_table,
    hetenyi_deflection,
    impulse_constant,
    impulse_response_at_load,
    lumped,
    moving_load,
    printed_impulse_constant,
    transient,
)
from railopt.models.track.parameters import RAILS
from railopt.models.units import INCH, MPH, POUND_FORCE, PSI, RAD_PER_HZ
from railopt.studies.config import StrictModel, StudyHeader
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.figures import Curve, plot_amplification, plot_profiles, plot_time_histories
from railopt.studies.output.writer import Writer

__all__ = [
    "AmplificationTable", "FiguresTable", "MovingLoadTable", "TrackResult", "TrackStudyConfig", "TrackTable",
    "TransientTable", "compute", "report",
]

FigureName = Literal[
    "fig3_3_impulse",
    "fig3_4_step",
    "fig3_5_damping",
    "fig3_6_damping_axial",
    "fig3_7_axial",
    "fig3_8_velocity_damped",
    "fig3_9_velocity_undamped",
    "accelerating",
    "oscillating",
    "amplification",
]


class TrackTable(StrictModel):
    """One rail on its foundation (SI).  ``rail`` is a label for the record; EI is given explicitly."""

    rail: str = "132 RE"
    EI_N_m2: float = Field(gt=0, default_factory=lambda: RAILS["132 RE"].EI)
    k_N_m2: float = Field(gt=0, default=3000.0 * PSI)
    m_kg_m: float = Field(gt=0, default=3000.0 * PSI / (RAD_PER_HZ * 62.0) ** 2)
    P_N: float = Field(gt=0, default=30_000.0 * POUND_FORCE)
    contact_spacing_m: float = Field(gt=0, default=1.5)
    lumped_damping_ratio: float = Field(ge=0, default=0.1)


class FiguresTable(StrictModel):
    """``[figures]``: which thesis figures to draw, their units (inch-pound or SI), dpi, half length (m) and points."""

    make: list[FigureName] = Field(default_factory=list)
    units: Literal["inch-pound", "SI"] = "inch-pound"
    dpi: int = Field(gt=20, le=300, default=100)
    half_length_m: float = Field(gt=0, default=5.0)
    points: int = Field(gt=10, le=5000, default=601)


class MovingLoadTable(StrictModel):
    """Parameters of Figs 3.5–3.9 (ratios to the critical values)."""

    speed_ratio: float = Field(ge=0, default=0.5)
    damping_ratios: list[float] = Field(default_factory=lambda: [0.0, 0.1, 0.2])
    axial_ratio_fig3_6: float = Field(lt=1, default=0.5)
    axial_ratios: list[float] = Field(default_factory=lambda: [-0.5, 0.0, 0.5])
    damping_ratio_fig3_7: float = Field(ge=0, default=0.1)
    speed_ratios: list[float] = Field(default_factory=lambda: [0.0, 0.1, 0.2, 0.3])
    damping_ratio_fig3_8: float = Field(ge=0, default=0.1)


class TransientTable(StrictModel):
    """Parameters of Figs 3.3, 3.4 and the accelerating and oscillating loads."""

    impulse_N_s: float = Field(gt=0, default=100.0)
    impulse_end_omega0_t: float = Field(gt=0, default=30.0)
    step_damping_ratio: float = Field(ge=0, default=0.05)
    step_end_s: float = Field(gt=0, default=0.25)
    accel_speed_mph: float = Field(ge=0, default=100.0)
    accel_m_s2: float = Field(default=1.0)
    accel_time_s: float = Field(gt=0, default=1.0)
    accel_damping_ratio: float = Field(ge=0, default=0.1)
    oscillating_frequency_Hz: float = Field(ge=0, default=20.0)
    oscillating_speed_mph: float = Field(ge=0, default=100.0)
    oscillating_damping_ratio: float = Field(ge=0, default=0.1)
    oscillating_time_s: float = Field(gt=0, default=0.5)


class AmplificationTable(StrictModel):
    """``[amplification]``: the grids of the dynamic-amplification table: v/v_cr, c/c_cr and N/N_cr ratios."""

    speed_ratios: list[float] = Field(
        default_factory=lambda: [0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.2, 1.5]
    )
    damping_ratios: list[float] = Field(default_factory=lambda: [0.0, 0.05, 0.1, 0.2, 0.5])
    axial_ratios: list[float] = Field(default_factory=lambda: [-0.5, 0.0, 0.5])


class TrackStudyConfig(StrictModel):
    """The config model of the ``track`` kind (thesis Ch. 3): the track, the figures and their parameter tables.

    Validation requires ``study.kind = "track"``, an ``[amplification]`` table when that figure is asked for, and a
    valid beam (EI, m, k > 0).
    """

    study: StudyHeader
    track: TrackTable = Field(default_factory=TrackTable)
    figures: FiguresTable = Field(default_factory=FiguresTable)
    moving_load: MovingLoadTable = Field(default_factory=MovingLoadTable)
    transient: TransientTable = Field(default_factory=TransientTable)
    amplification: AmplificationTable | None = None

    @model_validator(mode="after")
    def _check(self) -> TrackStudyConfig:
        if self.study.kind != "track":
            raise ValueError(f"study.kind: must be 'track' for this config model, got {self.study.kind!r}")
        if "amplification" in self.figures.make and self.amplification is None:
            raise ValueError("figures.make: lists 'amplification' but the [amplification] table is missing")
        Beam(EI=self.track.EI_N_m2, m=self.track.m_kg_m, k=self.track.k_N_m2)
        return self


# --- figure builders ---------------------------------------------------------------------------------
def _note(beam: Beam, P: float, extra: str = "") -> str:
    text = (
        f"EI = {beam.EI / 1e6:.2f} MN·m², k = {beam.k / PSI:.0f} lb/in², m = {beam.m:.0f} kg/m, "
        f"P = {P / POUND_FORCE / 1000:.0f} kip; v_cr = {beam.critical_velocity() / MPH:.0f} mph"
    )
    return text + (f"\n{extra}" if extra else "")


def _profile_table(sols: list, labels: list[str]) -> pd.DataFrame:
    df = pd.DataFrame({"xi_m": sols[0].xi, "xi_in": sols[0].xi / INCH})
    for s, lab in zip(sols, labels, strict=True):
        df[f"y_m [{lab}]"] = s.y
    return df


def _maxima_rows(sols: list, labels: list[str], figure: str) -> list[dict]:
    return [
        {
            "figure": figure,
            "case": lab,
            "speed_ratio": s.speed_ratio,
            "damping_ratio": s.beam.damping_ratio,
            "axial_ratio": s.beam.axial_ratio,
            "y_max_in": s.y_max / INCH,
            "x_max_in": s.x_max / INCH,
            "y_max_m": s.y_max,
            "x_max_m": s.x_max,
        }
        for s, lab in zip(sols, labels, strict=True)
    ]


@dataclass
class _Sections:
    """Tables and figure specs (a plot function with its data, drawn by the report) in the order made."""

    items: list[tuple[str, str, object]] = field(default_factory=list)

    def figure(self, spec: Callable[[], object], name: str) -> None:
        self.items.append(("figure", name, spec))

    def table(self, df: pd.DataFrame, name: str) -> None:
        self.items.append(("table", name, df))

    @property
    def files(self) -> list[str]:
        return [f"{name}.png" if kind == "figure" else f"{name}.csv" for kind, name, _ in self.items]


def _profiles_figure(cfg: TrackStudyConfig, out: _Sections, name: str, title: str, beams, labels, speeds):
    xi = np.linspace(-cfg.figures.half_length_m, cfg.figures.half_length_m, cfg.figures.points)
    P = cfg.track.P_N
    sols = [moving_load(b, xi, P, v) for b, v in zip(beams, speeds, strict=True)]
    styles = ["-", "--", "-.", ":", (0, (5, 1))]
    curves = [
        Curve(lab, s.xi, s.y, styles[i % 4]) for i, (s, lab) in enumerate(zip(sols, labels, strict=True))
    ]
    out.figure(partial(plot_profiles, curves, title, cfg.figures.units, _note(beams[0].with_(c=0.0, N=0.0), P)), name)
    out.table(_profile_table(sols, labels), name)
    return _maxima_rows(sols, labels, name)


def _fig_impulse(cfg: TrackStudyConfig, beam: Beam, out: _Sections) -> dict:
    t = np.linspace(0.0, cfg.transient.impulse_end_omega0_t / beam.omega0, 301)
    I = cfg.transient.impulse_N_s  # noqa: E741
    exact = impulse_response_at_load(beam, t, I, method="closed")
    num = impulse_response_at_load(beam, t, I, method="numerical")
    t_pts = t[::10]
    trans = transient(beam, [0.0], t_pts, ImpulseLoad(I)).y[:, 0]
    curves = [
        Curve("exact (3.24), derived constant", t, exact, "-"),
        Curve("numerical Fourier inversion", t[::5], num[::5], "o"),
        Curve("transient solver, case (ii)", t_pts, trans, "x"),
    ]
    note = _note(beam, cfg.track.P_N, f"impulse I = {I:g} N·s, no damping, no axial force")
    out.figure(
        partial(plot_time_histories, curves, "Fig 3.3 — response under q = I δ(x) δ(t)", cfg.figures.units, note=note),
        "fig3_3_impulse",
    )
    out.table(pd.DataFrame({"t_s": t, "y_exact_m": exact, "y_numerical_m": num}), "fig3_3_impulse")
    scale = np.max(np.abs(exact))
    return {
        "impulse_closed_vs_numerical_rel": float(np.max(np.abs(exact - num)) / scale),
        "impulse_closed_vs_transient_rel": float(np.max(np.abs(exact[::10] - trans)) / scale),
    }


def _fig_step(cfg: TrackStudyConfig, beam: Beam, out: _Sections) -> dict:
    b = beam.with_(c=cfg.transient.step_damping_ratio * beam.critical_damping)
    t = np.linspace(0.0, cfg.transient.step_end_s, 501)
    P = cfg.track.P_N
    y = transient(b, [0.0], t, SuddenLoad(P)).y[:, 0]
    y_st = float(hetenyi_deflection(0.0, P, b.k, b.EI))
    note = _note(beam, P, f"damping ratio {b.damping_ratio:g}, no axial force")
    fig = partial(plot_time_histories,
        [Curve("transient, case (i)", t, y, "-")],
        "Fig 3.4 — response to q = P δ(x) from rest",
        cfg.figures.units,
        reference=y_st,
        reference_label="steady state (3.19)",
        note=note,
    )
    out.figure(fig, "fig3_4_step")
    out.table(pd.DataFrame({"t_s": t, "y_m": y, "y_static_3_19_m": y_st}), "fig3_4_step")
    return {"step_final_rel_error": abs(y[-1] - y_st) / y_st}


def _fig_accelerating(cfg: TrackStudyConfig, beam: Beam, out: _Sections) -> dict:
    tr = cfg.transient
    b = beam.with_(c=tr.accel_damping_ratio * beam.critical_damping)
    v0 = tr.accel_speed_mph * MPH
    load = MovingLoad(cfg.track.P_N, v0, acceleration=tr.accel_m_s2)
    T = tr.accel_time_s
    xi = np.linspace(-cfg.figures.half_length_m, cfg.figures.half_length_m, 241)
    y_acc = transient(b, xi + float(load.position(T)), [T], load).y[0]
    v_now = v0 + tr.accel_m_s2 * T
    steady = moving_load(b, xi, cfg.track.P_N, v_now)
    curves = [
        Curve(f"accelerating {tr.accel_m_s2:g} m/s², case (vi), at t = {T:g} s", xi, y_acc, "-"),
        Curve(f"constant speed {v_now / MPH:.0f} mph, steady state (3.29)", xi, steady.y, "--"),
    ]
    note = _note(beam, cfg.track.P_N, f"damping ratio {b.damping_ratio:g}")
    out.figure(
        partial(plot_profiles, curves, "Accelerating load vs constant-speed load", cfg.figures.units, note),
        "accelerating",
    )
    out.table(pd.DataFrame({"xi_m": xi, "y_accelerating_m": y_acc, "y_steady_m": steady.y}), "accelerating")
    return {"accelerating_vs_steady_rel": float(np.max(np.abs(y_acc - steady.y)) / steady.y_max)}


def _fig_oscillating(cfg: TrackStudyConfig, beam: Beam, out: _Sections) -> dict:
    tr = cfg.transient
    b = beam.with_(c=tr.oscillating_damping_ratio * beam.critical_damping)
    v = tr.oscillating_speed_mph * MPH
    Omega = RAD_PER_HZ * tr.oscillating_frequency_Hz
    load = MovingLoad(cfg.track.P_N, v, Omega=Omega)
    times = np.linspace(0.0, tr.oscillating_time_s, 401)
    sol = transient(b, [v * tr.oscillating_time_s], times, load)
    const = transient(b, [v * tr.oscillating_time_s], times, MovingLoad(cfg.track.P_N, v)).y[:, 0]
    curves = [
        Curve(f"P cos(Ωt), f = {tr.oscillating_frequency_Hz:g} Hz, case (v)", times, sol.y[:, 0], "-"),
        Curve("constant P, case (iv)", times, const, "--"),
    ]
    x_obs = v * tr.oscillating_time_s
    title = (
        f"Moving loads passing the point x = {x_obs:.1f} m at t = {tr.oscillating_time_s:g} s "
        f"({v / MPH:.0f} mph)"
    )
    note = _note(beam, cfg.track.P_N, f"damping ratio {b.damping_ratio:g}")
    out.figure(partial(plot_time_histories, curves, title, cfg.figures.units, note=note), "oscillating")
    out.table(
        pd.DataFrame({"t_s": times, "y_oscillating_m": sol.y[:, 0], "y_constant_m": const}), "oscillating"
    )
    return {}


@dataclass(frozen=True)
class TrackResult:
    """The summary quantities (``table``), the profile maxima and the figure and table sections."""

    config: TrackStudyConfig
    table: pd.DataFrame
    summary: dict
    maxima: list[dict]
    sections: _Sections


def compute(config: TrackStudyConfig, context: StudyContext) -> TrackResult:
    """Compute the requested figures' data and the tables."""
    cfg = config
    out = _Sections()
    tk = cfg.track
    beam = Beam(EI=tk.EI_N_m2, m=tk.m_kg_m, k=tk.k_N_m2)
    lt = lumped(beam, tk.lumped_damping_ratio, contact_spacing=tk.contact_spacing_m)
    summary = {
        "rail": tk.rail,
        "EI_N_m2": beam.EI,
        "k_N_m2": beam.k,
        "k_lb_in2": beam.k / PSI,
        "m_kg_m": beam.m,
        "P_N": tk.P_N,
        "beta_1_m": beam.beta,
        "f0_Hz": beam.f0,
        "v_cr_m_s": beam.critical_velocity(),
        "v_cr_mph": beam.critical_velocity() / MPH,
        "N_cr_N": beam.buckling_load(),
        "c_cr_N_s_m2": beam.critical_damping,
        "y_static_m": float(hetenyi_deflection(0.0, tk.P_N, beam.k, beam.EI)),
        "K_e_N_m": lt.K_e,
        "m_e_kg": lt.m_e,
        "C_e_N_s_m": lt.C_e,
        "l_e_m": lt.l_e,
        "roll_stiffness_N_m_rad": lt.roll_stiffness,
        "impulse_constant_derived": impulse_constant(beam),
        "impulse_constant_printed_3_24": printed_impulse_constant(beam),
    }
    out.table(lt.to_pandas(), "lumped")
    out.table(f0_table(), "f0_choices")
    maxima: list[dict] = []
    for name in cfg.figures.make:
        if name in PROFILE_FIGURES:
            maxima += _profiles_figure(cfg, out, name, *PROFILE_FIGURES[name](cfg, beam))
        else:
            summary.update(OTHER_FIGURES[name](cfg, beam, out))
    if cfg.amplification is not None and "amplification" not in cfg.figures.make:
        _amplification(cfg, beam, out)  # the table alone
    if maxima:
        out.table(pd.DataFrame(maxima), "maxima")
    summary_df = pd.DataFrame([{"quantity": k, "value": v} for k, v in summary.items()])
    out.table(summary_df, "summary")
    return TrackResult(cfg, summary_df, summary, maxima, out)


def report(result: TrackResult, writer: Writer) -> str:
    """Draw the figures, write the tables (in the order computed) and return the summary markdown."""
    for kind, name, item in result.sections.items:
        if kind == "figure":
            writer.figure(item(), name, dpi=result.config.figures.dpi)
        else:
            writer.table(item, name)
    return _markdown(result.config, result.summary, result.maxima, result.sections.files)


def _amplification(cfg: TrackStudyConfig, beam: Beam, out: _Sections) -> dict:
    """Dynamic-amplification table over v/v_cr, c/c_cr, N/N_cr and, when asked, its figure."""
    am, P = cfg.amplification, cfg.track.P_N
    table = dynamic_amplification(beam.EI, beam.m, beam.k, P, am.speed_ratios, am.damping_ratios, am.axial_ratios)
    table["y_max_in"] = table["y_max_m"] / INCH
    table["x_max_in"] = table["x_max_m"] / INCH
    out.table(table, "amplification")
    if "amplification" in cfg.figures.make:
        theta = np.linspace(0.0, 1.6, 161)
        fine = dynamic_amplification(beam.EI, beam.m, beam.k, P, theta, [z for z in am.damping_ratios if z > 0], [0.0])
        curves = [(f"c/c_cr = {z:g}", g["speed_amplification"].to_numpy()) for z, g in fine.groupby("damping_ratio")]
        out.figure(partial(plot_amplification, theta, curves, "Dynamic amplification of the maximum deflection, N = 0"),
                   "amplification")
    return {}


def _ratios(beam: Beam, zeta: float, nu: float) -> Beam:
    return Beam.from_ratios(beam.EI, beam.m, beam.k, damping_ratio=zeta, axial_ratio=nu)


def _fig3_5(cfg: TrackStudyConfig, beam: Beam):
    ml = cfg.moving_load
    beams = [_ratios(beam, z, 0.0) for z in ml.damping_ratios]
    return (f"Fig 3.5 — effect of damping, N = 0, v/v_cr = {ml.speed_ratio:g}", beams,
            [f"c/c_cr = {z:g}" for z in ml.damping_ratios], [ml.speed_ratio * b.critical_velocity() for b in beams])


def _fig3_6(cfg: TrackStudyConfig, beam: Beam):
    ml = cfg.moving_load
    beams = [_ratios(beam, z, ml.axial_ratio_fig3_6) for z in ml.damping_ratios]
    return (f"Fig 3.6 — effect of damping, N/N_cr = {ml.axial_ratio_fig3_6:g}, v/v_cr(N=0) = {ml.speed_ratio:g}",
            beams, [f"c/c_cr = {z:g}" for z in ml.damping_ratios],
            [ml.speed_ratio * beam.critical_velocity()] * len(beams))


def _fig3_7(cfg: TrackStudyConfig, beam: Beam):
    ml = cfg.moving_load
    beams = [_ratios(beam, ml.damping_ratio_fig3_7, nu) for nu in ml.axial_ratios]
    return (f"Fig 3.7 — effect of axial force (+ compression), c/c_cr = {ml.damping_ratio_fig3_7:g}, "
            f"v/v_cr(N=0) = {ml.speed_ratio:g}", beams, [f"N/N_cr = {nu:+g}" for nu in ml.axial_ratios],
            [ml.speed_ratio * beam.critical_velocity()] * len(beams))


def _velocity(zeta_of: Callable[[MovingLoadTable], float], label: str):
    def spec(cfg: TrackStudyConfig, beam: Beam):
        ml, vcr = cfg.moving_load, beam.critical_velocity()
        zeta = zeta_of(ml)
        beams = [_ratios(beam, zeta, 0.0)] * len(ml.speed_ratios)
        return (f"{label} — effect of velocity, c/c_cr = {zeta:g}, N = 0", beams,
                [f"v/v_cr = {th:g} ({th * vcr / MPH:.0f} mph)" for th in ml.speed_ratios],
                [th * vcr for th in ml.speed_ratios])

    return spec


# the figures a config can ask for: moving-load profile figures (title, beams, labels, speeds) …
PROFILE_FIGURES: dict[str, Callable] = {
    "fig3_5_damping": _fig3_5,
    "fig3_6_damping_axial": _fig3_6,
    "fig3_7_axial": _fig3_7,
    "fig3_8_velocity_damped": _velocity(lambda ml: ml.damping_ratio_fig3_8, "Fig 3.8"),
    "fig3_9_velocity_undamped": _velocity(lambda ml: 0.0, "Fig 3.9"),
}
# … and figures drawn by their own builder (cfg, beam, writer) -> summary entries
OTHER_FIGURES: dict[str, Callable] = {
    "fig3_3_impulse": _fig_impulse,
    "fig3_4_step": _fig_step,
    "accelerating": _fig_accelerating,
    "oscillating": _fig_oscillating,
    "amplification": _amplification,
}


def _markdown(cfg: TrackStudyConfig, s: dict, maxima: list[dict], files: list[str]) -> str:
    lines = [
        f"# {cfg.study.name}",
        "",
        cfg.study.description,
        "",
        f"Track: {s['rail']} rail, EI = {s['EI_N_m2']:.4g} N·m², k = {s['k_lb_in2']:.0f} lb/in² per rail "
        f"({s['k_N_m2']:.4g} N/m²), m = {s['m_kg_m']:.1f} kg/m → f0 = {s['f0_Hz']:.1f} Hz, "
        f"β = {s['beta_1_m']:.4f} 1/m, v_cr = {s['v_cr_m_s']:.1f} m/s ({s['v_cr_mph']:.0f} mph), "
        f"N_cr = {s['N_cr_N'] / 1e6:.2f} MN, static deflection {s['y_static_m'] * 1000:.3f} mm "
        f"({s['y_static_m'] / INCH:.4f} in) under P = {s['P_N'] / 1000:.1f} kN.",
        "",
        f"Lumped track per rail: K_e = {s['K_e_N_m']:.4g} N/m, m_e = {s['m_e_kg']:.1f} kg, "
        f"l_e = {s['l_e_m']:.3f} m, C_e = {s['C_e_N_s_m']:.4g} N·s/m.",
        "",
    ]
    for key in (
        "impulse_closed_vs_numerical_rel",
        "impulse_closed_vs_transient_rel",
        "step_final_rel_error",
        "accelerating_vs_steady_rel",
    ):
        if key in s:
            lines.append(f"- {key}: {s[key]:.3g}")
    if maxima:
        lines += ["", "| figure | case | y_max (in) | x_max (in, − = behind) |", "|---|---|---|---|"]
        lines += [
            f"| {r['figure']} | {r['case']} | {r['y_max_in']:.5f} | {round(r['x_max_in'], 3) + 0.0:+.3f} |"  # no −0
            for r in maxima
        ]
    lines += ["", "Files: " + ", ".join(files)]
    return "\n".join(lines) + "\n"


SUMMARY = "Track beam on a Kelvin foundation: Figs 3.3–3.9, amplification, lumped track (thesis Ch. 3)"
KIND = register_kind(StudyKind("track", TrackStudyConfig, compute, report, summary=SUMMARY))
