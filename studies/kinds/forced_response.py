"""Study kind ``forced_response``: vehicle responses to a sinusoidal rail irregularity, rigid vs flexible track.

Thesis §4.3.2, Figs 4.5–4.12.  A config lists ``vehicle_forced`` models (``[[models]]``: vehicle,
view, track, speed, irregularity) and comparison groups (``[[groups]]``: a rigid-track and a
flexible-track model, the figure panels — one output each — and the bands).  For each group it
writes the FRF of every panel output on both tracks (``frf.csv``: amplitude per the given
irregularity amplitude, phase relative to the profile at the leading axle), the certified exact
band maxima and the flexible/rigid ratio (``peaks.csv``), the damped natural frequencies of the
flexible model above a threshold (``modes.csv``: the modes of the track carrying the wheelsets), one
figure per panel (rigid vs flexible on one axes, thesis figure label) and ``summary.md``.

A group with ``wavelength_m`` runs the thesis's own sweep instead: a fixed wavelength L, each frequency
reached by the speed S = f L (the models' speeds unused); its peaks are grid maxima refined by Brent
(a family of systems, one per speed, so no certificate).
"""

from __future__ import annotations

from dataclasses import replace
from typing import ClassVar, Literal

import numpy as np
import pandas as pd
from pydantic import Field, model_validator
from scipy.optimize import minimize_scalar

from railopt.models import all_response_maxima
from railopt.models.stability import spectral_abscissa
from railopt.studies.base import BandHz, FiniteModel, StudyContext, StudyKind, StudyOutcome, register_kind
from railopt.studies.catalog import ModelsStudy, require_unique
from railopt.studies.figures import plot_forced_response
from railopt.studies.models import VehicleForcedOptions, vehicle_forced_model
from railopt.studies.report import markdown_table, write_table

HZ = 2 * np.pi
TRACKS = ("rigid", "flexible")


class PanelSpec(FiniteModel):
    """One figure: an output of both models of a group."""

    output: str
    title: str
    figure: str = Field("", description="thesis figure label, e.g. 'Fig 4.6'")
    quantity: Literal["displacement", "velocity", "acceleration"] = "displacement"


class BandSpec(FiniteModel):
    label: str = Field(pattern=r"^[A-Za-z0-9_.\-]+$")
    band_hz: BandHz
    points: int = Field(300, ge=2, le=20_000, strict=True)
    spacing: Literal["linear", "log"] = "linear"
    plot: bool = True

    @model_validator(mode="after")
    def _positive(self) -> BandSpec:
        if self.band_hz[0] <= 0:
            raise ValueError("band_hz: the lower edge must be > 0 Hz (f = S/L; the vertical block has a free "
                             "fore-aft translation, so Z(0) is singular)")
        return self


class GroupSpec(FiniteModel):
    label: str = Field(pattern=r"^[A-Za-z0-9_.\-]+$")
    rigid: str = Field(description="label of the rigid-track model")
    flexible: str = Field(description="label of the flexible-track model")
    panels: list[PanelSpec] = Field(min_length=1)
    bands: list[BandSpec] = Field(min_length=1)
    wavelength_m: float | None = Field(None, gt=0, description=(
        "the thesis's sweep: a fixed wavelength L, each frequency f run at S = f L (the models' speeds are "
        "then unused); peaks are grid maxima refined by Brent, not certified (one system per speed)"))


class ForcedResponseConfig(ModelsStudy):
    KIND: ClassVar[str] = "forced_response"
    groups: list[GroupSpec] = Field(min_length=1)
    track_mode_min_hz: float = Field(15.0, gt=0, allow_inf_nan=False,
                                     description="list the flexible models' modes above this frequency")
    dpi: int = Field(100, ge=50, le=110, strict=True)
    notes: str = Field("", description="commentary placed in the summary under the rigid/flexible findings")

    @model_validator(mode="after")
    def _resolve(self) -> ForcedResponseConfig:
        require_unique("groups", [g.label for g in self.groups])
        labels = [m.label for m in self.models]
        for i, ref in enumerate(self.models):
            if ref.model != "vehicle_forced":
                raise ValueError(f"models[{i}].model: the forced_response kind takes 'vehicle_forced' models, "
                                 f"got {ref.model!r}")
        for gi, g in enumerate(self.groups):
            require_unique(f"groups[{gi}].bands", [b.label for b in g.bands])
            for key, track in (("rigid", "rigid"), ("flexible", "flexible")):
                label = getattr(g, key)
                if label not in labels:
                    raise ValueError(f"groups[{gi}].{key}: unknown model {label!r}; models: {labels}")
                opts = self.models[labels.index(label)].validated_options(f"models[{labels.index(label)}]")
                if opts.track != track:
                    raise ValueError(f"groups[{gi}].{key}: model {label!r} is on {opts.track} track")
                model, irregularity = _model(opts, f"groups[{gi}].{key}")
                for pi, p in enumerate(g.panels):
                    try:
                        model.forced_system(irregularity, [p.output], p.quantity)
                    except ValueError as exc:
                        raise ValueError(f"groups[{gi}].panels[{pi}].output: {exc}") from None
        return self


def _vehicle(options: VehicleForcedOptions):
    from railopt.models.vehicle import load_vehicle

    vehicle = load_vehicle(options.vehicle)
    return vehicle.with_parameters(options.parameters) if options.parameters else vehicle


def _model(options: VehicleForcedOptions, where: str):
    try:
        return vehicle_forced_model(options)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _grid(band: BandSpec) -> np.ndarray:
    lo, hi = band.band_hz
    return np.geomspace(lo, hi, band.points) if band.spacing == "log" else np.linspace(lo, hi, band.points)


def run(config: ForcedResponseConfig, context: StudyContext) -> StudyOutcome:
    cfg = config
    refs = {m.label: m for m in cfg.models}
    curves, peaks, modes, files, figures, tracks = [], [], [], [], [], []
    checks: list[str] = []
    for gi, g in enumerate(cfg.groups):
        models = {}
        for track in TRACKS:
            label = getattr(g, track)
            opts = refs[label].validated_options(f"groups[{gi}].{track}")
            models[track] = (label, opts, *_model(opts, f"groups[{gi}].{track}"))
        # one LinearSystem per (track, quantity): all panel outputs share its eigen-decomposition
        by_quantity: dict[str, list[PanelSpec]] = {}
        for p in g.panels:
            by_quantity.setdefault(p.quantity, []).append(p)
        responses: dict[tuple[str, str, str], pd.DataFrame] = {}
        peak_at: dict[tuple[str, str, str], tuple[float, float]] = {}
        for track, (label, opts, model, irregularity) in models.items():
            if g.wavelength_m is not None:
                irregularity = replace(irregularity, wavelength_m=g.wavelength_m)
                checks += _stability_over_speeds(label, model, g)
            for quantity, panels in by_quantity.items():
                outputs = [p.output for p in panels]
                sys = None
                if g.wavelength_m is None:
                    sys = model.forced_system(irregularity, outputs, quantity)
                    if not sys.is_stable(tol=1e-8 * float(np.max(np.abs(sys.eigenvalues())))):
                        checks.append(f"{label}: a root has Re s > 0 at {opts.speed_m_s:g} m/s — no steady state")
                for b in g.bands:
                    df = model.frequency_response(_grid(b), irregularity, outputs, quantity)
                    worst = float(df["residual"].max())
                    if worst > 1e-10:
                        checks.append(f"{label} {b.label}: residual of Z X = F up to {worst:.2e}")
                    for o, d in df.groupby("output", sort=False):
                        responses[(track, b.label, o)] = d
                    if sys is not None:
                        maxima = all_response_maxima(sys, (b.band_hz[0] * HZ, b.band_hz[1] * HZ), exact=True,
                                                     outputs=outputs)
                        found = {o: (rm.value, rm.argmax_frequency / HZ, rm.certified) for o, rm in maxima.items()}
                    else:
                        found = {o: (*_grid_peak(model, irregularity, o, quantity, responses[(track, b.label, o)]),
                                     False) for o in outputs}
                    for p in panels:
                        value, f_peak, certified = found[p.output]
                        peak_at[(track, b.label, p.output)] = (value, f_peak)
                        unit = responses[(track, b.label, p.output)]["unit"].iloc[0]
                        peaks.append({"group": g.label, "band": b.label, "figure": p.figure, "output": p.output,
                                      "quantity": quantity, "unit": unit, "track": track, "peak": value,
                                      "frequency_hz": f_peak, "certified": certified})
            if track == "flexible" and sys is not None:
                modes += _modes(g.label, label, model, sys, cfg.track_mode_min_hz)
                tracks.append((g.label, _vehicle(opts).lumped_track()))
        for p in g.panels:
            for b in g.bands:
                rows = {t: responses[(t, b.label, p.output)] for t in TRACKS}
                curves.append(pd.DataFrame({
                    "group": g.label, "band": b.label, "output": p.output, "unit": rows["rigid"]["unit"].to_numpy(),
                    "frequency_hz": rows["rigid"]["frequency_hz"].to_numpy(),
                    "wavelength_m": rows["rigid"]["wavelength_m"].to_numpy(),
                    **{f"{t}_{c}": rows[t][c].to_numpy() for t in TRACKS for c in ("amplitude", "phase_deg")},
                }))
                if not b.plot:
                    continue
                fig = plot_forced_response(rows, title=f"{p.figure} {p.title}".strip(),
                                           peaks={t: peak_at[(t, b.label, p.output)] for t in TRACKS},
                                           note=_note(models, b, g), log_frequency=b.spacing == "log")
                name = f"{g.label}_{_slug(p.output)}_{b.label}.png"
                fig.savefig(context.outdir / name, dpi=cfg.dpi)
                files.append(name)
                figures.append((g.label, p, b.label, name))
    frf = pd.concat(curves, ignore_index=True)
    table = _ratios(pd.DataFrame(peaks))
    mode_table = pd.DataFrame(modes)
    files += _write(frf, context, "frf") + write_table(table, context.outdir, "peaks")
    if not mode_table.empty:
        files += write_table(mode_table, context.outdir, "modes")
    md = _summary(cfg, table, mode_table, frf, figures, checks, tracks)
    return StudyOutcome(table=table, markdown=md, files=files)


def _modes(group: str, label: str, model, sys, min_hz: float) -> list[dict]:
    """Damped modes above ``min_hz`` with their three largest coordinates (displacement part of V)."""
    m = sys.modal()
    n = sys.n
    out = []
    for k in np.flatnonzero((m.s.imag > 0) & (m.s.imag >= min_hz * HZ)):
        top = np.argsort(-np.abs(m.V[:n, k]))[:3]
        out.append({"group": group, "model": label, "frequency_hz": m.s[k].imag / HZ,
                    "damping_ratio": -m.s[k].real / abs(m.s[k]),
                    "dominant": ", ".join(model.coordinates[i] for i in top)})
    return sorted(out, key=lambda r: r["frequency_hz"])


def _write(df: pd.DataFrame, context: StudyContext, stem: str) -> list[str]:
    context.outdir.mkdir(parents=True, exist_ok=True)
    df.to_csv(context.outdir / f"{stem}.csv", index=False, float_format="%.5g")
    return [f"{stem}.csv"]


def _slug(output: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in output).strip("_")


def _note(models: dict, band: BandSpec, group: GroupSpec) -> str:
    _, opts, _, irr = models["rigid"]
    lo, hi = band.band_hz
    if group.wavelength_m is not None:
        L = group.wavelength_m
        return (f"{opts.vehicle}, {opts.view} model; {irr.kind} a = {irr.amplitude_m:g} m per rail, {irr.rails}; "
                f"fixed L = {L:.4g} m, S = f L = {lo * L:.3g}–{hi * L:.3g} m/s ({hi * L / 0.44704:.0f} mph)")
    return (f"{opts.vehicle}, {opts.view} model, S = {opts.speed_m_s:g} m/s; {irr.label} per rail; "
            f"f = S/L (L = {opts.speed_m_s / hi:.3g}–{opts.speed_m_s / lo:.3g} m)")


def _grid_peak(model, irregularity, output: str, quantity: str, df: pd.DataFrame) -> tuple[float, float]:
    """Largest sample of a fixed-wavelength sweep refined by bounded Brent between its neighbours."""
    f = df["frequency_hz"].to_numpy()
    a = df["amplitude"].to_numpy()
    k = int(np.argmax(a))
    lo, hi = f[max(k - 1, 0)], f[min(k + 1, len(f) - 1)]
    if hi <= lo:
        return float(a[k]), float(f[k])

    def amplitude(x: float) -> float:
        return float(model.frequency_response([x], irregularity, [output], quantity)["amplitude"].iloc[0])

    r = minimize_scalar(lambda x: -amplitude(x), bounds=(lo, hi), method="bounded", options={"xatol": 1e-9 * hi})
    return (float(-r.fun), float(r.x)) if -r.fun > a[k] else (float(a[k]), float(f[k]))


def _stability_over_speeds(label: str, model, group: GroupSpec) -> list[str]:
    """A fixed-wavelength sweep runs at S = f L: check the spectral abscissa at the band edges' speeds."""
    out = []
    for b in group.bands:
        for f in b.band_hz:
            speed = f * group.wavelength_m
            if spectral_abscissa(model.at_speed(speed)) >= 0:
                out.append(f"{label}: a root has Re s ≥ 0 at {speed:.3g} m/s — no steady state there")
    return out


def _ratios(peaks: pd.DataFrame) -> pd.DataFrame:
    """Rows per (group, band, output): rigid and flexible peaks and their ratio flexible / rigid."""
    keys = ["group", "band", "figure", "output", "quantity", "unit"]
    wide = peaks.pivot_table(index=keys, columns="track", values=["peak", "frequency_hz", "certified"],
                             aggfunc="first", sort=False)
    out = pd.DataFrame({
        **{k: wide.index.get_level_values(k) for k in keys},
        "rigid_peak": wide[("peak", "rigid")].to_numpy(float),
        "rigid_hz": wide[("frequency_hz", "rigid")].to_numpy(float),
        "flexible_peak": wide[("peak", "flexible")].to_numpy(float),
        "flexible_hz": wide[("frequency_hz", "flexible")].to_numpy(float),
    })
    with np.errstate(divide="ignore", invalid="ignore"):
        out["flexible_over_rigid"] = np.where(out["rigid_peak"] > 0, out["flexible_peak"] / out["rigid_peak"], np.inf)
    out["certified"] = (wide[("certified", "rigid")].to_numpy(bool) & wide[("certified", "flexible")].to_numpy(bool))
    return out.reset_index(drop=True)


def _findings(table: pd.DataFrame) -> list[str]:
    """The thesis's finding in numbers: flexible/rigid peak ratios by kind of body and band."""
    lines = []
    kinds = {"body": "body", "frame": "frames", "motor": "motors", "wheelset": "wheelsets", "cab": "cab"}
    for (group, band), t in table.groupby(["group", "band"], sort=False):
        parts = []
        for prefix, name in kinds.items():
            r = t[t["output"].str.startswith(prefix) & ~t["output"].str.contains("_track")
                  & np.isfinite(t["flexible_over_rigid"])]
            if not r.empty:
                lo, hi = r["flexible_over_rigid"].min(), r["flexible_over_rigid"].max()
                parts.append(f"{name} {lo:.3g}" + (f"–{hi:.3g}" if hi > lo * 1.0005 else ""))
        if parts:
            lines.append(f"* {group}, {band}: flexible/rigid peak ratio " + "; ".join(parts))
    return lines


def _summary(cfg: ForcedResponseConfig, table: pd.DataFrame, modes: pd.DataFrame, frf: pd.DataFrame,
             figures: list, checks: list[str], tracks: list) -> str:
    lines = [f"# {cfg.study.name}", "", cfg.study.description, ""]
    refs = {m.label: m.validated_options("models") for m in cfg.models}
    lines += ["## Models", ""]
    for label, o in refs.items():
        lines.append(f"* `{label}`: {o.vehicle}, {o.view} block, {o.track} track, S = {o.speed_m_s:g} m/s "
                     f"({o.speed_m_s / 0.44704:.1f} mph), {o.input.kind} irregularity, amplitude "
                     f"{o.input.amplitude_m:g} m per rail ({o.input.amplitude_m / 0.0254:.3g} in)")
    for g in cfg.groups:
        if g.wavelength_m is not None:
            lines.append(f"* group `{g.label}`: the thesis's sweep — fixed wavelength L = {g.wavelength_m:g} m "
                         f"({g.wavelength_m / 0.3048:.3g} ft), each frequency f run at S = f L (the models' speeds "
                         "unused)")
    lines += ["", "A frequency f at speed S is the wavelength L = S/f; each axle sees the profile delayed by its "
              "distance behind the leading axle over S.  Amplitudes are the responses to the irregularity "
              "amplitude above (m, rad, m/s²); our signs (the thesis's pitch is −β: phases differ by 180°, "
              "amplitudes do not).", ""]
    lines += ["## Rigid vs flexible track", ""] + _findings(table) + [""]
    if cfg.notes:
        lines += [cfg.notes.strip(), ""]
    lines += ["## Peaks (band maxima) and the flexible/rigid ratio", "",
              markdown_table(table, digits=4), ""]
    for group, lt in tracks:
        f0 = np.sqrt(lt.K_e_pair / lt.m_e_pair) / HZ
        line = (f"Lumped track ({group} models): K_e = {lt.K_e_pair:.4g} N/m, m_e = {lt.m_e_pair:.4g} kg, "
                f"C_e = {lt.C_e_pair:.4g} N·s/m per rail pair; its own frequency f0 = √(K_e/m_e)/2π = {f0:.2f} Hz "
                "(4.35).")
        if not modes.empty:
            own = modes[(modes["group"] == group) & modes["dominant"].str.split(",").str[0].str.contains("_track")]
            if not own.empty:
                f_lo, f_hi = own["frequency_hz"].min(), own["frequency_hz"].max()
                z_lo, z_hi = own["damping_ratio"].min(), own["damping_ratio"].max()
                line += ("  Coupled to the vehicle the wheelset rides on m_e (4.66), so the track's own modes are "
                         f"those of the track carrying the wheelset, at {f_lo:.2f}–{f_hi:.2f} Hz (ζ {z_lo:.3f}–"
                         f"{z_hi:.3f}); nothing resonates at f0.")
        lines += [line, ""]
    if not modes.empty:
        lines += [f"## Modes of the flexible-track models above {cfg.track_mode_min_hz:g} Hz", "",
                  markdown_table(modes, digits=5), ""]
    low = frf[frf["frequency_hz"] == frf.groupby(["group", "band"])["frequency_hz"].transform("min")]
    low = low.drop_duplicates(["group", "output"])
    lines += ["## Low-frequency limit (lowest grid frequency)", "",
              markdown_table(low[["group", "output", "frequency_hz", "wavelength_m", "rigid_amplitude",
                                  "flexible_amplitude"]], digits=6), ""]
    lines += ["## Checks", ""]
    if checks:
        lines += [f"* {c}" for c in checks]
    else:
        lines.append("* every model stable at its speed; residual of Z X = F ≤ 1e-10 relative at every frequency "
                     "computed")
    for group, t in table.groupby("group", sort=False):
        how = ("certified exact band maxima" if bool(t["certified"].all())
               else "grid maxima refined by Brent (fixed wavelength: one system per speed, not certified)")
        lines.append(f"* {group}: peaks are {how}")
    lines += ["", "## Figures", ""]
    lines += [f"* {p.figure} {p.title} ({b}): ![{name}]({name})" for _, p, b, name in figures]
    return "\n".join(lines) + "\n"


KIND = register_kind(StudyKind(
    name="forced_response",
    config_model=ForcedResponseConfig,
    run=run,
    summary="vehicle responses to sinusoidal rail irregularities, rigid vs flexible track (Figs 4.5–4.12)",
))
