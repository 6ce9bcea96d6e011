"""Study kind ``forced_response``: vehicle responses to a sinusoidal rail irregularity, rigid vs flexible track.

Thesis §4.3.2, Figs 4.5–4.12.  A config lists ``vehicle_forced`` models (``[[models]]``: vehicle,
view, track, speed, irregularity) and comparison groups (``[[groups]]``: a rigid-track and a
flexible-track model, the figure panels — one output each — and the bands).  For each group it
writes the FRF of every panel output on both tracks (``frf.csv``: amplitude per the given
irregularity amplitude, phase relative to the profile at the leading axle), the certified exact
band maxima and the flexible/rigid ratio (``peaks.csv``), the damped natural frequencies of the
flexible model above a threshold (``modes.csv``, named by kinetic-energy shares: "track" for the track carrying
the wheelsets, "front truck pitch", ...), one
figure per panel (rigid vs flexible on one axes, thesis figure label) and ``summary.md``.

A group with ``wavelength_m`` runs the thesis's own sweep instead: a fixed wavelength L, each frequency
reached by the speed S = f L (the models' speeds unused); its peaks are grid maxima refined by Brent
(a family of systems, one per speed, so no certificate).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import ClassVar, Literal

import numpy as np
import pandas as pd
from pydantic import Field, model_validator

from railopt.models import all_response_maxima
from railopt.models.peak_search import grid_maximum
from railopt.models.stability import modes, spectral_abscissa
from railopt.models.units import FOOT, INCH, MPH
from railopt.models.units import RAD_PER_HZ as HZ
from railopt.studies.catalog import ModelsStudy, require_unique
from railopt.studies.catalog.vehicle import VehicleForcedOptions, model_vehicles, vehicle_forced_model, vehicle_title
from railopt.studies.config import BandHz, FileName, FiniteModel
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.figures import plot_forced_response
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.writer import Writer

__all__ = [
    "BandSpec", "FigureSpec", "ForcedResponseConfig", "ForcedResult", "GroupSpec", "PanelSpec", "compute", "report",
]

TRACKS = ("rigid", "flexible")


class PanelSpec(FiniteModel):
    """One figure: an output of both models of a group."""

    output: str
    title: str
    figure: str = Field("", description="thesis figure label, e.g. 'Fig 4.6'")
    quantity: Literal["displacement", "velocity", "acceleration"] = "displacement"


class BandSpec(FiniteModel):
    """A frequency band of a group: ``points`` frequencies (Hz, linear or log spacing) over ``band_hz``.

    The lower edge must be > 0 Hz: the vertical block has a free fore-aft translation, so Z(0) is singular.
    ``plot`` = false computes the band's responses and peaks without a figure.
    """

    label: FileName
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
    """A rigid/flexible comparison: the labels of the two models, the panels (one output each) and the bands.

    With ``wavelength_m`` the group runs the thesis's sweep at a fixed wavelength (S = f L) instead of at the
    models' speeds.
    """

    label: FileName
    rigid: str = Field(description="label of the rigid-track model")
    flexible: str = Field(description="label of the flexible-track model")
    panels: list[PanelSpec] = Field(min_length=1)
    bands: list[BandSpec] = Field(min_length=1)
    wavelength_m: float | None = Field(None, gt=0, description=(
        "the thesis's sweep: a fixed wavelength L, each frequency f run at S = f L (the models' speeds are "
        "then unused); peaks are grid maxima refined by Brent, not certified (one system per speed)"))


class ForcedResponseConfig(ModelsStudy):
    """The config model of the ``forced_response`` kind (thesis §4.3.2, Figs 4.5–4.12).

    ``[[models]]`` must be ``vehicle_forced`` models; every group names a rigid-track and a flexible-track model among
    them (each on that track), and every panel's output must be an output of both.  ``track_mode_min_hz`` sets the
    modes listed in ``modes.csv``.
    """

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
                ref = self.models[labels.index(label)]
                _, model, irregularity = ref.built("forced", lambda o=opts, w=f"groups[{gi}].{key}": _model(o, w))
                for pi, p in enumerate(g.panels):
                    try:
                        model.forced_system(irregularity, [p.output], p.quantity)
                    except ValueError as exc:
                        raise ValueError(f"groups[{gi}].panels[{pi}].output: {exc}") from None
        figures: dict[str, str] = {}  # one file per figure: a second with the same name would overwrite the first
        for gi, g in enumerate(self.groups):
            for pi, p in enumerate(g.panels):
                for b in g.bands:
                    name, field = f"{g.label}_{_slug(p.output)}_{b.label}", f"groups[{gi}].panels[{pi}].output"
                    if name in figures:
                        raise ValueError(f"{field}: its figure {name}.png is also the figure of {figures[name]}; one "
                                         "would overwrite the other (one panel per output and group)")
                    figures[name] = field
        return self


def _model(options: VehicleForcedOptions, where: str):
    try:
        return vehicle_forced_model(options)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _grid(band: BandSpec) -> np.ndarray:
    lo, hi = band.band_hz
    return np.geomspace(lo, hi, band.points) if band.spacing == "log" else np.linspace(lo, hi, band.points)


@dataclass
class _Group:
    """What one group computes: responses per (track, band, output), peaks, modes, checks, figures."""

    responses: dict = field(default_factory=dict)
    peak_at: dict = field(default_factory=dict)
    peaks: list[dict] = field(default_factory=list)
    modes: list[dict] = field(default_factory=list)
    checks: list[str] = field(default_factory=list)
    tracks: list = field(default_factory=list)


@dataclass(frozen=True)
class FigureSpec:
    """One panel figure: rigid and flexible series of one output over one band."""

    name: str
    group: str
    panel: PanelSpec
    band: str
    series: dict
    title: str
    peaks: dict
    note: str
    log_frequency: bool
    input_label: str = ""


@dataclass(frozen=True)
class ForcedResult:
    """FRFs (``frf``), the peaks with the flexible/rigid ratio (``table``), modes, checks and figure specs."""

    config: ForcedResponseConfig
    frf: pd.DataFrame
    table: pd.DataFrame
    modes: pd.DataFrame
    figures: list[FigureSpec]
    checks: list[str]
    tracks: list


def _group_models(cfg: ForcedResponseConfig, gi: int, g: GroupSpec) -> dict:
    """track -> (label, options, vehicle, view, irregularity) of one group."""
    refs = {m.label: m for m in cfg.models}
    models = {}
    for track in TRACKS:
        label = getattr(g, track)
        where = f"groups[{gi}].{track}"
        opts = refs[label].validated_options(where)
        models[track] = (label, opts, *refs[label].built("forced", lambda o=opts, w=where: _model(o, w)))
    return models


def _band_peaks(model, sys, irregularity, b: BandSpec, outputs: list[str], quantity: str, out: _Group,
                track: str) -> dict:
    """output -> (peak, frequency in Hz, certified): certified band maxima of ``sys``, or (fixed wavelength,
    no one system) grid maxima refined by the shared peak search."""
    if sys is not None:
        maxima = all_response_maxima(sys, band_hz=b.band_hz, exact=True, outputs=outputs)
        return {o: (rm.value, rm.argmax_frequency / HZ, rm.certified) for o, rm in maxima.items()}
    return {o: (*_grid_peak(model, irregularity, o, quantity, out.responses[(track, b.label, o)]), False)
            for o in outputs}


def _track_responses(cfg: ForcedResponseConfig, g: GroupSpec, track: str, entry: tuple, out: _Group) -> None:
    """Responses and peaks of every panel output of one track's model, one system per quantity."""
    label, opts, vehicle, model, irregularity = entry
    if g.wavelength_m is not None:
        irregularity = replace(irregularity, wavelength_m=g.wavelength_m)
        out.checks += _stability_over_speeds(label, model, g)
    by_quantity: dict[str, list[PanelSpec]] = {}
    for p in g.panels:
        by_quantity.setdefault(p.quantity, []).append(p)
    sys = None
    for quantity, panels in by_quantity.items():
        outputs = [p.output for p in panels]
        sys = None
        if g.wavelength_m is None:  # one LinearSystem per (track, quantity): its outputs share one eigen-decomposition
            sys = model.forced_system(irregularity, outputs, quantity)
            if not sys.is_stable(tol=1e-8 * float(np.max(np.abs(sys.eigenvalues())))):
                out.checks.append(f"{label}: a root has Re s > 0 at {opts.speed_m_s:g} m/s — no steady state")
        for b in g.bands:
            df = model.frequency_response(_grid(b), irregularity, outputs, quantity)
            worst = float(df["residual"].max())
            if worst > 1e-10:
                out.checks.append(f"{label} {b.label}: residual of Z X = F up to {worst:.2e}")
            for o, d in df.groupby("output", sort=False):
                out.responses[(track, b.label, o)] = d
            found = _band_peaks(model, sys, irregularity, b, outputs, quantity, out, track)
            for p in panels:
                value, f_peak, certified = found[p.output]
                out.peak_at[(track, b.label, p.output)] = (value, f_peak)
                unit = out.responses[(track, b.label, p.output)]["unit"].iloc[0]
                out.peaks.append({"group": g.label, "band": b.label, "figure": p.figure, "output": p.output,
                                  "quantity": quantity, "unit": unit, "track": track, "peak": value,
                                  "frequency_hz": f_peak, "certified": certified})
    if track == "flexible" and sys is not None:
        out.modes += _modes(g.label, label, model, cfg.track_mode_min_hz)
        out.tracks.append((g.label, vehicle.lumped_track()))


def _curves_and_figures(g: GroupSpec, models: dict, out: _Group) -> tuple[list[pd.DataFrame], list[FigureSpec]]:
    """Rigid and flexible columns side by side per (panel, band), and the figure of each plotted band."""
    curves, figures = [], []
    for p in g.panels:
        for b in g.bands:
            rows = {t: out.responses[(t, b.label, p.output)] for t in TRACKS}
            curves.append(pd.DataFrame({
                "group": g.label, "band": b.label, "output": p.output, "unit": rows["rigid"]["unit"].to_numpy(),
                "frequency_hz": rows["rigid"]["frequency_hz"].to_numpy(),
                "wavelength_m": rows["rigid"]["wavelength_m"].to_numpy(),
                **{f"{t}_{c}": rows[t][c].to_numpy() for t in TRACKS for c in ("amplitude", "phase_deg")},
            }))
            if b.plot:
                figures.append(FigureSpec(f"{g.label}_{_slug(p.output)}_{b.label}", g.label, p, b.label, rows,
                                          f"{p.figure} {p.title}".strip(),
                                          {t: out.peak_at[(t, b.label, p.output)] for t in TRACKS},
                                          _note(models, b, g), b.spacing == "log", _input_label(models)))
    return curves, figures


def compute(config: ForcedResponseConfig, context: StudyContext) -> ForcedResult:
    """The FRFs, peaks, modes and checks of every group (data only; writes nothing).

    For each group and track: one system per output quantity, its responses on every band grid (amplitude per the
    irregularity amplitude, phase to the leading axle's profile) and the certified band maxima, or (fixed wavelength)
    grid maxima refined by Brent; the flexible/rigid ratio of each peak; the flexible model's modes above
    ``track_mode_min_hz``.  A root with Re s > 0 or a residual of Z X = F above 1e-10 becomes a check line.
    """
    cfg = config
    curves, figures, groups = [], [], []
    for gi, g in enumerate(cfg.groups):
        models = _group_models(cfg, gi, g)
        out = _Group()
        for track, entry in models.items():
            _track_responses(cfg, g, track, entry, out)
        c, f = _curves_and_figures(g, models, out)
        curves += c
        figures += [replace(x, title=vehicle_title(cfg.models, g.rigid, x.title).removeprefix(f"{g.rigid}: "))
                    for x in f]  # the vehicle and its file named, not the model label
        groups.append(out)
    return ForcedResult(cfg, pd.concat(curves, ignore_index=True),
                        _ratios(pd.DataFrame([r for o in groups for r in o.peaks])),
                        pd.DataFrame([r for o in groups for r in o.modes]), figures,
                        [c for o in groups for c in o.checks], [t for o in groups for t in o.tracks])


def report(result: ForcedResult, writer: Writer) -> str:
    """Write the panel figures and ``frf``, ``peaks`` (and ``modes``) tables; return the summary markdown."""
    cfg = result.config
    for f in result.figures:
        fig = plot_forced_response(f.series, title=f.title, peaks=f.peaks, note=f.note, log_frequency=f.log_frequency,
                                   input_label=f.input_label)
        writer.figure(fig, f.name, dpi=cfg.dpi)
    writer.table(result.frf, "frf")
    writer.table(result.table, "peaks")
    if not result.modes.empty:
        writer.table(result.modes, "modes")
    return "\n".join(line for section in SECTIONS for line in section(result)) + "\n"


def _modes(group: str, label: str, model, min_hz: float) -> list[dict]:
    """Modes of the model at its speed above ``min_hz``, named by their kinetic-energy shares
    (:func:`railopt.models.stability.modes`: "track", "front truck pitch", ...)."""
    table = modes(model, speed=model.speed)
    table = table[table["frequency_hz"] >= min_hz]
    return [{"group": group, "model": label, "frequency_hz": r["frequency_hz"], "damping_ratio": r["damping_ratio"],
             "name": r["name"], "share": r["share"], "track_share": r["track_share"]} for _, r in table.iterrows()]


def _input_label(models: dict) -> str:
    """The irregularity the amplitudes are per: ``"6.35 mm vertical irregularity"``."""
    irr = models["rigid"][4]
    return f"{irr.amplitude_m * 1000:.4g} mm {irr.kind} irregularity"


def _slug(output: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in output).strip("_")


def _note(models: dict, band: BandSpec, group: GroupSpec) -> str:
    _, opts, _, _, irr = models["rigid"]
    lo, hi = band.band_hz
    if group.wavelength_m is not None:
        L = group.wavelength_m
        return (f"{opts.vehicle}, {opts.view} model; {irr.kind} a = {irr.amplitude_m:g} m per rail, {irr.rails}; "
                f"fixed L = {L:.4g} m, S = f L = {lo * L:.3g}–{hi * L:.3g} m/s ({hi * L / MPH:.0f} mph)")
    return (f"{opts.vehicle}, {opts.view} model, S = {opts.speed_m_s:g} m/s; {irr.label} per rail; "
            f"f = S/L (L = {opts.speed_m_s / hi:.3g}–{opts.speed_m_s / lo:.3g} m)")


def _grid_peak(model, irregularity, output: str, quantity: str, df: pd.DataFrame) -> tuple[float, float]:
    """Largest sample of a fixed-wavelength sweep refined between its neighbours (the shared peak search)."""
    f = df["frequency_hz"].to_numpy()

    def amplitude(x: np.ndarray) -> np.ndarray:
        return model.frequency_response(np.atleast_1d(x), irregularity, [output], quantity)["amplitude"].to_numpy()

    f_peak, value = grid_maximum(amplitude, f, df["amplitude"].to_numpy())
    return value, f_peak


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


def _models_section(r: ForcedResult) -> list[str]:
    cfg = r.config
    lines = [f"# {cfg.study.name}", "", cfg.study.description, "", "## Models", ""]
    vehicles = model_vehicles(cfg.models)
    for label, o in ((m.label, m.validated_options("models")) for m in cfg.models):
        v = vehicles.get(label, {"vehicle": o.vehicle, "vehicle_file": ""})
        lines.append(f"* `{label}`: **{v['vehicle']}** (file `{v['vehicle_file']}`), {o.view} block, {o.track} track, "
                     f"S = {o.speed_m_s:g} m/s "
                     f"({o.speed_m_s / MPH:.1f} mph), {o.input.kind} irregularity, amplitude "
                     f"{o.input.amplitude_m:g} m per rail ({o.input.amplitude_m / INCH:.3g} in)")
    for g in cfg.groups:
        if g.wavelength_m is not None:
            lines.append(f"* group `{g.label}`: the thesis's sweep — fixed wavelength L = {g.wavelength_m:g} m "
                         f"({g.wavelength_m / FOOT:.3g} ft), each frequency f run at S = f L (the models' speeds "
                         "unused)")
    return lines + ["", "A frequency f at speed S is the wavelength L = S/f; each axle sees the profile delayed by "
                    "its distance behind the leading axle over S.  Amplitudes are the responses to the irregularity "
                    "amplitude above (m, rad, m/s²); our signs (the thesis's pitch is −β: phases differ by 180°, "
                    "amplitudes do not).", ""]


def _findings_section(r: ForcedResult) -> list[str]:
    lines = ["## Rigid vs flexible track", ""] + _findings(r.table) + [""]
    return lines + ([r.config.notes.strip(), ""] if r.config.notes else [])


def _lumped_track_line(group: str, lt, table: pd.DataFrame) -> str:
    f0 = np.sqrt(lt.K_e_pair / lt.m_e_pair) / HZ
    line = (f"Lumped track ({group} models): K_e = {lt.K_e_pair:.4g} N/m, m_e = {lt.m_e_pair:.4g} kg, "
            f"C_e = {lt.C_e_pair:.4g} N·s/m per rail pair; its own frequency f0 = √(K_e/m_e)/2π = {f0:.2f} Hz "
            "(4.35).")
    if not table.empty:
        own = table[(table["group"] == group) & (table["name"] == "track")]
        if not own.empty:
            f_lo, f_hi = own["frequency_hz"].min(), own["frequency_hz"].max()
            z_lo, z_hi = own["damping_ratio"].min(), own["damping_ratio"].max()
            line += ("  Coupled to the vehicle the wheelset rides on m_e (4.66), so the track's own modes are "
                     f"those of the track carrying the wheelset, at {f_lo:.2f}–{f_hi:.2f} Hz (ζ {z_lo:.3f}–"
                     f"{z_hi:.3f}); nothing resonates at f0.")
    return line


def _peaks_section(r: ForcedResult) -> list[str]:
    lines = ["## Peaks (band maxima) and the flexible/rigid ratio", "", markdown_table(r.table, digits=4), ""]
    for group, lt in r.tracks:
        lines += [_lumped_track_line(group, lt, r.modes), ""]
    return lines


def _modes_section(r: ForcedResult) -> list[str]:
    if r.modes.empty:
        return []
    return [f"## Modes of the flexible-track models above {r.config.track_mode_min_hz:g} Hz", "",
            markdown_table(r.modes, digits=5), ""]


def _low_frequency_section(r: ForcedResult) -> list[str]:
    frf = r.frf
    low = frf[frf["frequency_hz"] == frf.groupby(["group", "band"])["frequency_hz"].transform("min")]
    low = low.drop_duplicates(["group", "output"])
    return ["## Low-frequency limit (lowest grid frequency)", "",
            markdown_table(low[["group", "output", "frequency_hz", "wavelength_m", "rigid_amplitude",
                                "flexible_amplitude"]], digits=6), ""]


def _checks_section(r: ForcedResult) -> list[str]:
    lines = ["## Checks", ""]
    if r.checks:
        lines += [f"* {c}" for c in r.checks]
    else:
        lines.append("* every model stable at its speed; residual of Z X = F ≤ 1e-10 relative at every frequency "
                     "computed")
    for group, t in r.table.groupby("group", sort=False):
        how = ("certified exact band maxima" if bool(t["certified"].all())
               else "grid maxima refined by Brent (fixed wavelength: one system per speed, not certified)")
        lines.append(f"* {group}: peaks are {how}")
    return lines


def _figures_section(r: ForcedResult) -> list[str]:
    return ["", "## Figures", ""] + [f"* {f.panel.figure} {f.panel.title} ({f.band}): ![{f.name}.png]({f.name}.png)"
                                     for f in r.figures]


SECTIONS = [_models_section, _findings_section, _peaks_section, _modes_section, _low_frequency_section,
            _checks_section, _figures_section]
"""The summary, section by section."""


SUMMARY = "vehicle responses to sinusoidal rail irregularities, rigid vs flexible track (Figs 4.5–4.12)"
KIND = register_kind(StudyKind("forced_response", ForcedResponseConfig, compute, report, summary=SUMMARY))
