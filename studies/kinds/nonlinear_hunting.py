"""Study kind ``nonlinear_hunting``: the nonlinear critical speed of vehicles on their wheel and rail profiles.

Issue 26 item 5/7.  A config lists ``vehicle_lateral`` models on rigid track (``[[models]]``: a vehicle file with a
``[wheel_rail]`` table, optional ``parameters`` overrides, ``max_operating_speed_m_s`` the required speed) and the
analysis settings (``[nonlinear_hunting]``, :class:`~railopt.studies.specs.NonlinearHuntingSpec`).  For each
model :func:`railopt.models.vehicle.hunting.nonlinear_hunting` runs the descending ramp (coarse, then fine through
the loss of the cycle), shoots the cycle at the last steady speed and continues it through its fold; at each
speed where the ramp held a steady cycle, :func:`~railopt.models.vehicle.hunting.cycle_indicators` gives ΣY
(EN 14363 sliding r.m.s. against Prud'homme/2), the flangeway clearance used and the largest Y/Q.

Writes ``summary.csv`` (per model: linear and nonlinear critical speeds, the ramp's bracket, the fold and whether
the ramp confirms it, the gap, the verdict at the required speed), ``ramp.csv``, ``diagram.csv`` (the continued
branch: amplitude, frequency, largest Floquet multiplier, stable), ``indicators.csv`` and one bifurcation figure
per model.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
from pydantic import Field, model_validator

from railopt.models.bifurcation import IntegrationSettings
from railopt.models.vehicle.hunting import HuntingResult, cycle_indicators, nonlinear_hunting, profile_vehicle
from railopt.studies.catalog import ModelsStudy
from railopt.studies.catalog.vehicle import VehicleOptions, load, model_vehicles, vehicle_title
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.bifurcation_figure import plot_bifurcation_diagram
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.writer import Writer
from railopt.studies.specs import NonlinearHuntingSpec

__all__ = ["HuntingStudyResult", "NonlinearHuntingStudyConfig", "compute", "report"]


class NonlinearHuntingStudyConfig(ModelsStudy):
    """The config model of the ``nonlinear_hunting`` kind.

    ``[[models]]`` must be ``vehicle_lateral`` models on rigid track whose vehicle file has a ``[wheel_rail]``
    table; ``[nonlinear_hunting]`` the analysis settings (one set for every model); ``indicators`` = false skips
    ΣY and the flange use.
    """

    KIND: ClassVar[str] = "nonlinear_hunting"
    nonlinear_hunting: NonlinearHuntingSpec = NonlinearHuntingSpec()
    indicators: bool = True
    dpi: int = Field(100, ge=50, le=110, strict=True)
    notes: str = Field("", description="commentary placed in the summary")

    @model_validator(mode="after")
    def _models(self) -> NonlinearHuntingStudyConfig:
        for i, ref in enumerate(self.models):
            if ref.model != "vehicle_lateral":
                raise ValueError(f"models[{i}].model: the nonlinear_hunting kind takes 'vehicle_lateral' models, "
                                 f"got {ref.model!r}")
            options = ref.validated_options(f"models[{i}]")
            if options.track != "rigid":
                raise ValueError(f"models[{i}].options.track: the nonlinear model runs on rigid track only, got "
                                 f"{options.track!r}")
            try:
                vehicle = load(options)
            except ValueError as exc:
                raise ValueError(f"models[{i}].options: {exc}") from None
            if vehicle.profiles is None:
                raise ValueError(f"models[{i}].options.vehicle: {options.vehicle!r} has no [wheel_rail] table (wheel "
                                 "and rail profiles); the nonlinear analysis needs one")
            spec = self.nonlinear_hunting
            if spec.top_speed_m_s is not None and spec.top_speed_m_s > options.critical_search_m_s[1]:
                raise ValueError(f"nonlinear_hunting.top_speed_m_s: {spec.top_speed_m_s:g} m/s is above models[{i}]'s "
                                 f"critical_search_m_s upper end {options.critical_search_m_s[1]:g} m/s")
        return self


@dataclass(frozen=True)
class HuntingStudyResult:
    """Per model: the analysis, its indicators; the summary (``table``), ramp, diagram and indicator tables."""

    config: NonlinearHuntingStudyConfig
    results: dict[str, HuntingResult]
    table: pd.DataFrame
    ramp: pd.DataFrame
    diagram: pd.DataFrame
    indicators: pd.DataFrame


def _verdict(result: HuntingResult, required: float) -> str:
    passes = result.passes(required)
    if passes is None:
        return f"undecided at {required:g} m/s (the ramp's bracket straddles it, fold not confirmed)"
    return (f"no stable hunting cycle up to {required:g} m/s" if passes
            else f"a stable hunting cycle at or below {required:g} m/s")


def _located(r: HuntingResult) -> str:
    """How the lowest fold was located (``Fold.located``: brent or hermite); empty without a fold."""
    folds = [] if r.diagram is None else sorted(r.diagram.folds, key=lambda f: f.speed)
    return folds[0].located if folds else ""


def _summary_row(label: str, vehicle: dict, r: HuntingResult, required: float, ind: pd.DataFrame) -> dict:
    low, high = r.bracket if r.bracket is not None else (math.nan, math.nan)
    lowest = r.lowest_hunting_speed()
    return {"model": label, **vehicle, "linear_critical_speed_m_s": r.linear_critical_speed,
            "ramp_last_cycle_m_s": high, "ramp_lost_cycle_at_m_s": low, "fold_speed_m_s": r.critical.fold_speed,
            "fold_located": _located(r), "fold_confirmed": r.critical.confirmed,
            "nonlinear_critical_speed_m_s": r.critical.speed,
            "lowest_hunting_speed_m_s": lowest,
            "nonlinear_over_linear": lowest / r.linear_critical_speed if math.isfinite(lowest) else math.nan,
            "gap_m_s": r.gap(), "required_speed_m_s": required,
            "passes_required": r.passes(required), "verdict": _verdict(r, required),
            "max_flange_use": float(ind["flange_use"].max()) if len(ind) else math.nan,
            "max_sum_y_ratio": float(ind["sum_y_ratio"].max()) if len(ind) else math.nan,
            "reason": r.reason,
            "continuation_stop": r.diagram.stop_reason if r.diagram is not None else "not run"}


def compute(config: NonlinearHuntingStudyConfig, context: StudyContext) -> HuntingStudyResult:
    """Run the nonlinear hunting analysis of every model (minutes each; progress lines on stderr)."""
    cfg = config
    spec = cfg.nonlinear_hunting
    vehicles = model_vehicles(cfg.models)
    results, rows, ramps, diagrams, indicators = {}, [], [], [], []
    for i, ref in enumerate(cfg.models):
        options: VehicleOptions = ref.validated_options(f"models[{i}]")
        search, required = options.hunting(options.speed_m_s)
        vehicle = load(options)

        def say(message: str, label: str = "" if ref.label == vehicle.name else f"{ref.label}: ") -> None:
            if context.show_progress:
                print(f"{label}{message}", file=sys.stderr, flush=True)

        analysis = spec.analysis(search)
        result = nonlinear_hunting(vehicle, analysis, progress=say)
        results[ref.label] = result
        ramp = result.ramp_table()
        ramp.insert(0, "model", ref.label)
        ramps.append(ramp.assign(amplitude_mm=ramp["amplitude"] * 1e3).drop(columns="amplitude"))
        if result.diagram is not None:
            d = result.diagram.to_pandas()
            diagrams.append(pd.DataFrame({"model": ref.label, "speed_m_s": d["speed_m_s"],
                                          "amplitude_mm": d["amplitude"] * 1e3, "frequency_hz": d["frequency_hz"],
                                          "max_abs_multiplier": d["max_abs_multiplier"], "stable": d["stable"],
                                          "branch": d["branch"]}))
        ind = pd.DataFrame()
        if cfg.indicators:
            say("ΣY, flange use and Y/Q at each steady ramp speed")
            nv = profile_vehicle(vehicle, analysis.friction_coefficient, analysis.flange)
            settings = IntegrationSettings(method=analysis.method, rtol=analysis.rtol, atol=analysis.atol)
            ramp = result.ramp
            ind = pd.DataFrame([{"model": ref.label, **cycle_indicators(
                nv, vehicle, float(ramp.speeds[i]), ramp.states[i], result.watched, settings,
                window_m=spec.window_m).to_dict()} for i in result.steady])
            indicators.append(ind)
        rows.append(_summary_row(ref.label, vehicles.get(ref.label, {}), result, required, ind))

    def joined(frames: list[pd.DataFrame]) -> pd.DataFrame:
        return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()

    return HuntingStudyResult(cfg, results, pd.DataFrame(rows), joined(ramps), joined(diagrams), joined(indicators))


def _figure_title(cfg: NonlinearHuntingStudyConfig, label: str, r: HuntingResult) -> str:
    return vehicle_title(cfg.models, label, "hunting cycle of the leading wheelset against speed "
                                            "(bifurcation diagram)")


def report(result: HuntingStudyResult, writer: Writer) -> str:
    """Write the tables and one bifurcation figure per model; return the summary markdown."""
    cfg = result.config
    writer.table(result.table, "summary")
    writer.table(result.ramp, "ramp")
    if len(result.diagram):
        writer.table(result.diagram, "diagram")
    if len(result.indicators):
        writer.table(result.indicators, "indicators")
    md = [f"# {cfg.study.name}", "", cfg.study.description, ""]
    for label, r in result.results.items():
        diagram = r.diagram.to_pandas() if r.diagram is not None else pd.DataFrame(
            {"speed_m_s": [], "amplitude": [], "stable": []})
        diagram.attrs.setdefault("fold_speeds_m_s", [] if r.diagram is None else [f.speed for f in r.diagram.folds])
        diagram.attrs["linear_critical_speed_m_s"] = r.linear_critical_speed
        figure = plot_bifurcation_diagram(diagram, _figure_title(cfg, label, r),
                                          f"lateral displacement of {r.watched.rsplit('.', 1)[0]}, half peak-to-peak "
                                          "(mm)", ramp=r.ramp_table(), scale=1e3)
        name = f"bifurcation_{label}"
        writer.figure(figure, name, dpi=cfg.dpi)
        row = result.table[result.table["model"] == label].iloc[0]
        low, high = row["ramp_lost_cycle_at_m_s"], row["ramp_last_cycle_m_s"]
        md += [f"## {label}", "",
               f"* Linear critical speed (certified, the linear model's conicity): "
               f"{r.linear_critical_speed:.2f} m/s.",
               f"* Descending ramp: a steady hunting cycle down to {high:.2f} m/s, lost at {low:.2f} m/s."
               if np.isfinite(high) else f"* Descending ramp: {r.reason}.",
               f"* Path following: {r.critical.reason}"
               + (f" (the continuation stopped: {r.diagram.stop_reason})." if r.diagram is not None else "."),
               f"* Lowest speed with a stable hunting cycle: {row['lowest_hunting_speed_m_s']:.2f} m/s, "
               f"{row['nonlinear_over_linear']:.2f} of the linear critical speed (gap {row['gap_m_s']:.2f} m/s).",
               f"* Verdict: {row['verdict']}.", "", f"![bifurcation diagram]({name}.png)", ""]
    md += ["## Summary", "", markdown_table(result.table.drop(columns=["reason", "continuation_stop"])), ""]
    if len(result.indicators):
        md += ["## Cycle indicators (EN 14363-style, leading wheelset)", "",
               "ΣY: the largest 100 m sliding r.m.s. of the band-passed (f0 ± 2 Hz) track-shifting force against "
               "(ΣY)_lim/2 = (10 kN + P/3)/2 (`docs/running_stability.md`); flange use: the largest |y| over the "
               "flange onset of the profiles.", "", markdown_table(result.indicators), ""]
    md += ["Method and limits: `docs/nonlinear_vehicle.md`, `docs/nonlinear_hunting.md`."]
    if cfg.notes:
        md += ["", cfg.notes]
    return "\n".join(md) + "\n"


SUMMARY = "nonlinear critical speed on wheel/rail profiles: ramp, shooting and continuation, ΣY and flange use"
KIND = register_kind(StudyKind("nonlinear_hunting", NonlinearHuntingStudyConfig, compute, report, summary=SUMMARY))
