"""Study kind ``ride``: ride comfort under random track geometry, and the minimax-sinusoid optimum against the
RMS-random optimum.

Each ``[[cases]]`` entry names a ``vehicle_forced`` model of ``[[models]]`` (a forward speed, a rail irregularity),
an acceleration output at a body point (a seat, the cab), the comfort direction (vertical: EN 12299 Wb and Sperling
vertical; lateral: Wd and Sperling lateral), a band, a track spectrum (``[cases.spectrum]``, as the campaign's
``[objective.spectrum]``) and the design variables.  For each case two minimax problems are solved from a few
starts (the existing design among them): the certified band maximum of |H| (the thesis's sinusoid criterion,
"minimax_sinusoid") and the RMS under the spectrum (:class:`railopt.studies.adapter.RMSTarget`, "rms_random").
The existing design and both optima are then evaluated under both criteria and for comfort:

* ``peak_sinusoid``: certified band maximum under the model's sinusoid (its amplitude a, output units);
  ``peak_per_m`` = ``peak_sinusoid / a``;
* ``rms``: RMS of the output under the spectrum at the model's speed over the band (output units; the model's
  responses divided by a, i.e. per metre of irregularity, times the spectrum) — :func:`random_response.rms`;
* ``n_mv``: the frequency-domain EN 12299 N_MV estimate ``6·a_w`` of this one direction (the other directions
  taken as zero: a lower estimate of the full index), from the output PSD on a log grid of ``psd_points``
  over the band; ``comfort_class`` its class; ``wz``: Sperling's Wz of the random acceleration.

Tables ``designs.csv`` (one row per case × design, with the variables, the element ids' values, the speed, the
amplitude and the spectrum, enough to recompute every number), ``starts.csv``; figures ``frf.png`` (|H| per
metre, the three designs overlaid) and ``psd.png`` (output PSDs).  Runs in well under a minute per case.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
import pandas as pd
from pydantic import Field, model_validator

from railopt.design import multistart
from railopt.models.comfort import comfort_class, mean_comfort_from_psd, sperling_index_from_psd
from railopt.models.random_response import _check_spectrum_band, output_psd, random_response
from railopt.models.units import RAD_PER_HZ as HZ
from railopt.studies.adapter import ResponseTarget, RMSTarget, minimax_problem
from railopt.studies.catalog import ModelSetup, ModelsStudy, require_unique
from railopt.studies.catalog.vehicle import model_vehicles, vehicle_title
from railopt.studies.config import BandHz, FileName, FiniteModel
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.figures import plot_frf_panels
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.progress import Progress
from railopt.studies.output.records import FrfPanel
from railopt.studies.output.writer import Writer
from railopt.studies.specs import CampaignSettings, SpectrumSpec, VariableSpec

__all__ = ["DESIGNS", "RideCase", "RideResult", "RideStudyConfig", "compute", "evaluate_design", "report"]

DESIGNS = ("existing", "minimax_sinusoid", "rms_random")


class RideCase(FiniteModel):
    """One output of one model: its band, spectrum, comfort direction and design variables."""

    label: FileName
    model: str = Field(description="label of a [[models]] entry (a vehicle_forced model)")
    output: str = Field(description="an acceleration output, e.g. body[6,0.8,1.0].z or cab.lateral")
    direction: Literal["vertical", "lateral"] = Field(
        description="comfort direction: vertical (EN 12299 Wb, Sperling vertical) or lateral (Wd, Sperling lateral)")
    band_hz: BandHz
    spectrum: SpectrumSpec
    variables: list[VariableSpec] = Field(min_length=1)


class RideStudyConfig(ModelsStudy):
    """The config model of the ``ride`` kind: ``[[models]]``, ``[[cases]]``, the multistart settings and the PSD grid.

    Validation checks every case against its model (the label, a forward speed over a rail irregularity, an
    acceleration output, the design variables, a band above 0 Hz within the spectrum's validity), naming
    ``cases[i]``.
    """

    KIND: ClassVar[str] = "ride"
    cases: list[RideCase] = Field(min_length=1)
    design: CampaignSettings = CampaignSettings(n_starts=2)
    psd_points: int = Field(2000, ge=50, le=100_000, strict=True, description="log grid of the PSDs and comfort")
    dpi: int = Field(110, ge=50, le=300, strict=True)

    @model_validator(mode="after")
    def _resolve(self) -> RideStudyConfig:
        require_unique("cases", [c.label for c in self.cases])
        labels = [m.label for m in self.models]
        for i, case in enumerate(self.cases):
            where = f"cases[{i}]"
            if case.model not in labels:
                raise ValueError(f"{where}.model: no [[models]] entry labelled {case.model!r}; labels are {labels}")
            j = labels.index(case.model)
            setup = self.models[j].setup(f"models[{j}]")
            _check_case(case, setup, where, f"models[{j}]")
        return self

    def setup(self, case: RideCase) -> ModelSetup:
        """The :class:`ModelSetup` of the ``[[models]]`` entry ``case`` names."""
        j = [m.label for m in self.models].index(case.model)
        return self.models[j].setup(f"models[{j}]")


def _check_case(case: RideCase, setup: ModelSetup, where: str, model: str) -> None:
    if setup.family.speed is None or setup.input_amplitude_m is None:
        raise ValueError(f"{where}.model: {model} has no forward speed over a rail irregularity; use vehicle_forced "
                         "(options.speed_m_s, options.input)")
    outputs = setup.family.output_names
    if case.output not in outputs:
        raise ValueError(f"{where}.output: unknown output {case.output!r} of {model}; outputs are {list(outputs)}")
    quantity = setup.family.at().outputs[case.output].quantity
    if quantity != "acceleration":
        raise ValueError(f"{where}.output: comfort needs an acceleration; {model} gives {quantity} "
                         "(set options.quantity = 'acceleration')")
    names = [v.name for v in case.variables]
    require_unique(f"{where}.variables", names)
    setup.parameter_map.check_variables(case.variables, f"{where}.variables", model)  # names (did-you-mean), bounds
    try:
        _check_spectrum_band(case.spectrum.spectrum(), setup.family.speed, tuple(case.band_hz))
    except ValueError as exc:
        raise ValueError(f"{where}.{exc}") from None
    if not case.band_hz[0] > 0:
        raise ValueError(f"{where}.band_hz: must start above 0 Hz, got {case.band_hz}")


# ---------------------------------------------------------------------------------------------- compute
@dataclass(frozen=True)
class RideResult:
    """What the ``ride`` kind computes: ``designs`` (one row per case × design, see the module docstring),
    ``starts`` (every multistart row of both criteria) and the FRF and PSD figure panels.
    """

    config: RideStudyConfig
    designs: pd.DataFrame
    starts: pd.DataFrame
    frf_panels: list
    psd_panels: list

    @property
    def table(self) -> pd.DataFrame:
        """The CLI's short table: each design under both criteria and its comfort."""
        cols = ["case", "design", "peak_sinusoid", "rms", "n_mv", "comfort_class", "wz", "stable"]
        return self.designs[cols]


def _targets(case: RideCase, setup: ModelSetup) -> tuple[ResponseTarget, RMSTarget]:
    band = (case.band_hz[0] * HZ, case.band_hz[1] * HZ)
    return (ResponseTarget(case.output, band, exact=True),
            RMSTarget(case.output, tuple(case.band_hz), case.spectrum.spectrum(), float(setup.family.speed),
                      1.0 / setup.input_amplitude_m, case.spectrum.rtol))


def evaluate_design(case: RideCase, setup: ModelSetup, values: dict[str, float], psd_points: int) -> dict:
    """Both criteria and the comfort of one design {variable: value} (see the module docstring)."""
    names = [v.name for v in case.variables]
    p, _ = setup.parameters(names, np.array([values[n] for n in names]))
    system = setup.family.at(p)
    a, V = setup.input_amplitude_m, float(setup.family.speed)
    spectrum = case.spectrum.spectrum()
    peak = system.peak(band_hz=tuple(case.band_hz), exact=True, output=case.output)
    rr = random_response(system, spectrum, V, tuple(case.band_hz), case.output, case.spectrum.rtol)
    f = np.geomspace(case.band_hz[0], case.band_hz[1], psd_points)
    psd = output_psd(system, spectrum, V, f, case.output) / a**2
    zero = np.zeros_like(f)
    n_mv = (mean_comfort_from_psd(f, zero, zero, psd) if case.direction == "vertical"
            else mean_comfort_from_psd(f, zero, psd, zero))
    abscissa = setup.checks["spectral_abscissa"](p)
    ids = {setup.parameter_map.aliases.get(n, n): float(p[list(setup.family.parameters).index(
        setup.parameter_map.aliases.get(n, n))]) for n in names}
    return {"peak_sinusoid": peak, "peak_per_m": peak / a, "rms": rr.rms / a, "n_mv": n_mv,
            "comfort_class": comfort_class(n_mv), "wz": sperling_index_from_psd(f, psd, case.direction),
            "spectral_abscissa": abscissa.value, "stable": abscissa.flags["stable"],
            "ids": ids, "frequencies_hz": f, "psd": psd}


def _active_bounds(case: RideCase, values: dict[str, float]) -> str:
    out = []
    for v in case.variables:
        tol = 1e-6 * (v.upper - v.lower)
        if abs(values[v.name] - v.lower) <= tol or abs(values[v.name] - v.upper) <= tol:
            out.append(f"{v.name} at its {'lower' if abs(values[v.name] - v.lower) <= tol else 'upper'} bound")
    return "; ".join(out) or "none"


def _optimum(table: pd.DataFrame, names: list[str]) -> tuple[dict[str, float], bool]:
    ok = table[table["success"]]
    best = (ok if len(ok) else table).sort_values(["value", "start_id"]).iloc[0]
    return {n: float(best[n]) for n in names}, bool(len(ok))


def compute(config: RideStudyConfig, context: StudyContext) -> RideResult:
    """Both optima of every case and the three designs evaluated under both criteria and for comfort.

    For each case: the minimax-sinusoid and RMS-random problems solved by multistart (the existing design, clipped
    to the bounds, among the starts); the best successful start of each (or the best start when none succeeded);
    then :func:`evaluate_design` for ``existing``, ``minimax_sinusoid`` and ``rms_random``.
    """
    cfg = config
    rows, starts, frf_panels, psd_panels = [], [], [], []
    settings = cfg.design
    for case in cfg.cases:
        setup = cfg.setup(case)
        names = [v.name for v in case.variables]
        variables = [v.variable() for v in case.variables]
        existing = {n: float(setup.named_designs["existing"][n]) for n in names}
        start = [[min(max(existing[v.name], v.lower), v.upper) for v in case.variables]]
        sin_target, rms_target = _targets(case, setup)
        designs = {"existing": (existing, True)}
        for label, target in (("minimax_sinusoid", sin_target), ("rms_random", rms_target)):
            problem = minimax_problem(setup, variables, target)
            bar = Progress(f"{case.label} {label}", unit="start", enabled=context.show_progress)
            try:
                table = multistart(problem, settings.n_starts, method=settings.method, seed=settings.seed,
                                   sampler=settings.sampler, points=start, options=settings.solver_options(),
                                   progress=bar.update)
            finally:
                bar.close()
            starts.append(table.drop(columns=["functions"], errors="ignore").assign(case=case.label,
                                                                                    criterion=label))
            designs[label] = _optimum(table, names)
        a = setup.input_amplitude_m
        vehicles = model_vehicles(cfg.models)
        frf_curves, psd_curves = [], []
        f_frf = np.geomspace(case.band_hz[0], case.band_hz[1], cfg.psd_points)
        for label, (values, converged) in designs.items():
            ev = evaluate_design(case, setup, values, cfg.psd_points)
            p, _ = setup.parameters(names, np.array([values[n] for n in names]))
            rows.append({"case": case.label, "model": case.model, **vehicles.get(case.model, {}),
                         "output": case.output, "direction": case.direction,
                         "design": label, **values, **{k: v for k, v in ev["ids"].items() if k not in values},
                         "converged": converged, "active_bounds": _active_bounds(case, values),
                         **{k: ev[k] for k in ("peak_sinusoid", "peak_per_m", "rms", "n_mv", "comfort_class", "wz",
                                               "spectral_abscissa", "stable")},
                         "speed_m_s": float(setup.family.speed), "amplitude_m": a,
                         "band_lo_hz": case.band_hz[0], "band_hi_hz": case.band_hz[1],
                         "spectrum": case.spectrum.spectrum().label, "rtol": case.spectrum.rtol})
            h = np.abs(setup.family.at(p).frf(frequencies_hz=f_frf, output=case.output)) / a
            key = "ref" if label == "existing" else f"C{DESIGNS.index(label)}"
            frf_curves.append((f"{label} (peak {ev['peak_per_m']:.4g}, RMS {ev['rms']:.4g})", f_frf, h, key))
            psd_curves.append((f"{label} (RMS {ev['rms']:.4g} m/s², N_MV {ev['n_mv']:.3g})", ev["frequencies_hz"],
                               ev["psd"], key))
        unit = setup.units.get(case.output, "m/s²")
        title = vehicle_title(cfg.models, case.model, f"{case.label}, {setup.description.rsplit(',', 1)[0]}")
        frf_panels.append(FrfPanel.build(title, f"|{case.output}| ({unit} per m of irregularity)", frf_curves))
        psd_panels.append(FrfPanel.build(f"{title}; {case.spectrum.spectrum().label}",
                                         f"PSD of {case.output} ((m/s²)²/Hz)", psd_curves))
    designs = pd.DataFrame(rows)
    for case in cfg.cases:  # each design under the other's criterion, relative to that criterion's optimum
        sel = designs["case"] == case.label
        best_peak = designs.loc[sel & (designs["design"] == "minimax_sinusoid"), "peak_sinusoid"].iloc[0]
        best_rms = designs.loc[sel & (designs["design"] == "rms_random"), "rms"].iloc[0]
        designs.loc[sel, "peak_vs_sinusoid_optimum"] = designs.loc[sel, "peak_sinusoid"] / best_peak
        designs.loc[sel, "rms_vs_rms_optimum"] = designs.loc[sel, "rms"] / best_rms
    return RideResult(cfg, designs, pd.concat(starts, ignore_index=True), frf_panels, psd_panels)


# ---------------------------------------------------------------------------------------------- report
def _log_figure(panels: list):
    fig = plot_frf_panels(panels)
    for ax in fig.axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
    return fig


def report(result: RideResult, writer: Writer) -> str:
    """Write ``designs``, ``starts`` and the ``frf`` and ``psd`` figures; return the summary markdown."""
    cfg = result.config
    d = result.designs
    writer.table(d, "designs")
    writer.table(result.starts, "starts")
    writer.figure(_log_figure(result.frf_panels), "frf", dpi=cfg.dpi)
    psd = _log_figure(result.psd_panels)
    for ax in psd.axes:
        ax.set_xlabel("frequency (Hz)")
    writer.figure(psd, "psd", dpi=cfg.dpi)
    lines = [f"# {cfg.study.name}", "", cfg.study.description, ""]
    for case in cfg.cases:
        rows = d[d["case"] == case.label].set_index("design")
        before, after = rows.loc["existing"], rows.loc["rms_random"]
        lines += [f"## {case.label}", "",
                  f"{case.output} ({case.direction}) of {case.model} at {before['speed_m_s']:g} m/s, "
                  f"{before['band_lo_hz']:g}–{before['band_hi_hz']:g} Hz, {before['spectrum']}."
                  + (f" Vehicle: **{before['vehicle']}**, file `{before['vehicle_file']}`."
                     if "vehicle" in rows else ""),
                  "",
                  f"**Comfort before → after (the RMS-random optimum):** RMS {before['rms']:.4g} → {after['rms']:.4g} "
                  f"m/s²; N_MV ({case.direction} only) {before['n_mv']:.3g} ({before['comfort_class']}) → "
                  f"{after['n_mv']:.3g} ({after['comfort_class']}); Sperling Wz {before['wz']:.3g} → "
                  f"{after['wz']:.3g}.", ""]
        cols = ["design", *[c for c in ("vehicle",) if c in rows], *[v.name for v in case.variables],
                "peak_sinusoid", "peak_vs_sinusoid_optimum", "rms",
                "rms_vs_rms_optimum", "n_mv", "comfort_class", "wz", "stable", "active_bounds"]
        lines += [markdown_table(rows.reset_index()[cols]), ""]
    lines += ["`peak_sinusoid`: certified band maximum under the model's sinusoid (amplitude `amplitude_m`); `rms`: "
              "RMS under the spectrum (per-metre response × spectrum, adaptive quadrature); `*_vs_*_optimum`: each "
              "design under the other's criterion relative to that criterion's optimum.  N_MV is the "
              "frequency-domain EN 12299 estimate of one direction (a lower estimate of the full index).", "",
              "![FRF per metre](frf.png)", "", "![Output PSD](psd.png)", ""]
    return "\n".join(lines)


SUMMARY = "ride comfort under a track spectrum: minimax-sinusoid against RMS-random optima, N_MV, Wz, PSDs"
KIND = register_kind(StudyKind("ride", RideStudyConfig, compute, report, summary=SUMMARY))
