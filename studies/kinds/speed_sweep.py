"""Study kind ``speed_sweep``: roots against forward speed, critical speeds, damping, sensitivities.

For each model with forward speed (``[[models]]`` naming e.g. ``vehicle_lateral``): the velocity
root locus over ``[speeds]`` (Fig 4.4), the least damping ratio and the spectral abscissa at each
speed, and the critical speed (lowest S with a root in Re s > 0, bracketed and refined by Brent's
method to a tolerance, §4.3.1, (4.51)–(4.59)).  Optional ``[[sensitivity]]`` tables repeat the
critical-speed search with one vehicle parameter scaled by each factor, in the order given.  Each model's modes
are drawn on the vehicle's plan view (``modes_<label>.png``) at its critical speed, or at ``modes_speed_m_s``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pandas as pd
from pydantic import Field, field_validator, model_validator

from railopt.models.stability import critical_speed, root_locus
from railopt.models.units import MPH
from railopt.studies.catalog import ModelRef, ModelSetup, ModelsStudy
from railopt.studies.catalog.vehicle import load
from railopt.studies.catalog.views import stability_view, vehicle_view
from railopt.studies.config import FiniteModel, Interval, not_one_of
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.figures import plot_root_locus, vehicle_label
from railopt.studies.output.map_figure import plot_stability_map
from railopt.studies.output.markdown import markdown_table, stable_over
from railopt.studies.output.mode_figure import plot_mode_shapes
from railopt.studies.output.writer import Writer

__all__ = ["CriticalSpec", "ModeShapes", "SensitivitySpec", "SpeedGrid", "SpeedSweepConfig", "SpeedSweepResult",
           "compute", "report", "sensitivity_pivot"]


class SpeedGrid(FiniteModel):
    """``points`` speeds evenly spaced over ``range_m_s`` (m/s, lower edge > 0)."""

    range_m_s: Interval
    points: int = Field(100, ge=2, le=20_000, strict=True)

    @field_validator("range_m_s")
    @classmethod
    def _positive(cls, v: tuple[float, float]) -> tuple[float, float]:
        if v[0] <= 0:
            raise ValueError(f"speeds must be positive, got lower {v[0]} m/s")
        return v

    def speeds(self) -> np.ndarray:
        """The speeds in m/s, shape (points,), both edges included."""
        return np.linspace(*self.range_m_s, self.points)


class CriticalSpec(SpeedGrid):
    """Critical-speed search: bracketing grid of ``points`` speeds, then Brent to ``tol_m_s``."""

    points: int = Field(8, ge=2, le=10_000, strict=True)
    tol_m_s: float = Field(0.01, gt=0)


class SensitivitySpec(FiniteModel):
    """One sensitivity table: the critical speed with ``parameter`` scaled by each of ``factors`` (≥ 0, in the order
    given; 0 switches an element off, where the vehicle can run without it)."""

    parameter: str
    factors: list[float] = Field(min_length=1)

    @field_validator("factors")
    @classmethod
    def _non_negative(cls, v: list[float]) -> list[float]:
        if any(f < 0 for f in v):
            raise ValueError(f"factors must be ≥ 0 (a scaled stiffness, damping, mass or length keeps its sign), "
                             f"got {v}")
        return v


class SpeedSweepConfig(ModelsStudy):
    """The config model of the ``speed_sweep`` kind: models with a forward speed, the locus grid, the critical search.

    Validation rejects a model without stability families and a sensitivity parameter the model does not have.
    """

    KIND: ClassVar[str] = "speed_sweep"
    speeds: SpeedGrid
    critical: CriticalSpec
    sensitivity: list[SensitivitySpec] = Field(default_factory=list)
    dpi: int = Field(110, ge=50, le=300, strict=True)
    modes_speed_m_s: float | None = Field(None, gt=0, lt=1000, allow_inf_nan=False,
                                          description="speed of the mode-shape figures, m/s (default: each model's "
                                                      "critical speed; the search's upper end when it is stable)")

    @model_validator(mode="after")
    def _resolve(self) -> SpeedSweepConfig:
        slugs = [_slug(ref.label) for ref in self.models]  # each model's mode figure, modes_<label>.png
        for i, slug in enumerate(slugs):
            if slug in slugs[:i]:
                raise ValueError(f"models[{i}].label: its figure modes_{slug}.png is also that of "
                                 f"models[{slugs.index(slug)}]; give the models labels that differ in more than "
                                 "'.' and '_'")
        for i, ref in enumerate(self.models):
            setup = ref.setup(f"models[{i}]")
            if not setup.stability:
                raise ValueError(f"models[{i}].model: {ref.model!r} has no forward speed; use a vehicle model")
            for j, sens in enumerate(self.sensitivity):  # every variant is built (and kept for the run)
                for k, factor in enumerate(sens.factors):
                    _variant(ref, sens.parameter, factor, f"sensitivity[{j}]", f"sensitivity[{j}].factors[{k}]")
        return self


def _variant(ref: ModelRef, parameter: str, factor: float, where: str, at: str | None = None) -> ModelSetup:
    """The model with one vehicle parameter scaled by ``factor`` (through the ``parameters`` option); a variant the
    vehicle cannot be built with (a zero mass) is refused naming ``at`` (default ``where``)."""
    options = ref.validated_options(where)
    if "parameters" not in type(options).model_fields:
        raise ValueError(f"{where}.parameter: model {ref.model!r} takes no parameter overrides")
    vehicle = load(options)
    try:
        base = vehicle.parameter(parameter)
    except ValueError:
        unknown = not_one_of(parameter, vehicle.parameter_names(), "parameter")
        raise ValueError(f"{where}.parameter: {unknown} (vehicle {vehicle.name!r})") from None
    changed = {**options.parameters, parameter: factor * base}
    variant = ref.model_copy(update={"options": {**ref.options, "parameters": changed}})

    def build() -> ModelSetup:
        try:
            return variant.setup(where)
        except ValueError as exc:
            reason = str(exc).removeprefix(f"{where}.options: ")
            raise ValueError(f"{at or where}: {parameter} × {factor:g} = {factor * base:g} gives no model: "
                             f"{reason}") from None

    return ref.built(f"variant {parameter} x{factor!r}", build)  # validation's, in compute


def _critical(label: str, setup: ModelSetup, spec: CriticalSpec) -> tuple[dict, pd.DataFrame]:
    """The critical-speed row of a model and its stability map (every stable and unstable interval)."""
    cs = critical_speed(setup.stability_model(setup.defaults), speed_range=spec.range_m_s, tol=spec.tol_m_s,
                        grid=spec.points)
    row = {"model": label, "critical_speed_m_s": cs.speed, "critical_speed_mph": cs.speed / MPH,
           "hunting_frequency_hz": cs.frequency, "mode": cs.mode, "eigen_solves": cs.eigen_solves,
           "unstable_at_lower_end": cs.unstable_at_lower_end, "stable_over_range": math.isinf(cs.speed),
           "tol_m_s": cs.tol, "method": cs.method, "certified": cs.certified}
    return row, cs.intervals.assign(model=label)


def _critical_row(label: str, setup: ModelSetup, spec: CriticalSpec) -> dict:
    return _critical(label, setup, spec)[0]


@dataclass(frozen=True, eq=False)
class ModeShapes:
    """What the mode-shape figure of one model draws: its label, the vehicle view (plan view), the model's system at
    ``speed`` (m/s; its coordinates the view's) and the figure title (vehicle name and file, speed, track)."""

    label: str
    view: object
    system: object
    speed: float
    title: str


@dataclass(frozen=True)
class SpeedSweepResult:
    """Root loci, least damping per speed, critical speeds (``table``), sensitivities, the track effect and the mode
    shapes of each model."""

    config: SpeedSweepConfig
    locus: pd.DataFrame
    damping: pd.DataFrame
    table: pd.DataFrame
    sensitivity: pd.DataFrame
    track_effect: pd.DataFrame
    maps: pd.DataFrame
    shapes: list[ModeShapes] = field(default_factory=list)


def _vehicle(ref: ModelRef, where: str):
    """The model's vehicle (its ``parameters`` applied) and the view of its stability families, or None for a model
    without a vehicle file."""
    options = ref.validated_options(where)
    if not hasattr(options, "vehicle"):
        return None, None
    return load(options), stability_view(getattr(options, "view", "lateral"))


def _mode_shapes(ref: ModelRef, setup: ModelSetup, row: dict, cfg: SpeedSweepConfig, where: str) -> ModeShapes | None:
    """The mode shapes of a vehicle model on its first stability track at ``modes_speed_m_s``, else at its critical
    speed (the critical search's upper end when stable over it); None for a model without a vehicle file."""
    vehicle, view_name = _vehicle(ref, where)
    if vehicle is None:
        return None
    track = next(iter(setup.stability))
    view = vehicle_view(vehicle, view_name, track)
    if cfg.modes_speed_m_s is not None:
        speed, at = cfg.modes_speed_m_s, "the asked speed"
    elif math.isfinite(row["critical_speed_m_s"]):
        speed, at = row["critical_speed_m_s"], "its critical speed"
    else:
        speed, at = cfg.critical.range_m_s[1], "the search's upper end (stable over the range)"
    system = setup.stability_model(setup.defaults).at(speed=speed)
    title = (f"{ref.label} — {vehicle_label(vehicle.name, vehicle.path)}: modes at {speed:.4g} m/s ({at}), "
             f"{track} track")
    return ModeShapes(ref.label, view, system, float(speed), title)


def _locus_and_damping(label: str, setup: ModelSetup, speeds: np.ndarray) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The root locus at the defaults and, per speed, its largest real part and least damping ratio."""
    locus = root_locus(setup.stability_model(setup.defaults), speeds).to_pandas().assign(model=label)
    g = locus.groupby("speed")
    damping = pd.DataFrame({"model": label, "speed_m_s": g["real"].max().index,
                            "spectral_abscissa": g["real"].max().to_numpy(),
                            "least_damping_ratio": g["damping_ratio"].min().to_numpy()})
    return locus, damping


def _sensitivity_rows(cfg: SpeedSweepConfig, ref: ModelRef) -> list[dict]:
    rows = []
    for j, sens in enumerate(cfg.sensitivity):
        for factor in sens.factors:
            row = _critical_row(ref.label, _variant(ref, sens.parameter, factor, f"sensitivity[{j}]"), cfg.critical)
            rows.append({"parameter": sens.parameter, "factor": factor, **row})
    return rows


def compute(config: SpeedSweepConfig, context: StudyContext) -> SpeedSweepResult:
    """Root locus, least damping and spectral abscissa per speed, critical speeds and sensitivities of every model.

    Critical speeds (m/s and mph) are the lowest speeds with a root in Re s > 0, bracketed on the critical grid and
    refined by Brent to ``tol_m_s`` (§4.3.1, (4.51)–(4.59)); rigid and flexible entries of the same vehicle are
    compared in ``track_effect``; each vehicle model's modes at its critical speed (or ``modes_speed_m_s``) are kept
    for the mode-shape figure.
    """
    cfg = config
    loci, critical, damping, sens_rows, maps, shapes = [], [], [], [], [], []
    for i, ref in enumerate(cfg.models):
        where = f"models[{i}]"
        setup = ref.setup(where)
        locus, damp = _locus_and_damping(ref.label, setup, cfg.speeds.speeds())
        loci.append(locus)
        damping.append(damp)
        row, intervals = _critical(ref.label, setup, cfg.critical)
        vehicle, _ = _vehicle(ref, where)
        critical.append({"model": ref.label, "vehicle": "" if vehicle is None else
                         vehicle_label(vehicle.name, vehicle.path), **row})
        maps.append(intervals)
        sens_rows += _sensitivity_rows(cfg, ref)
        shape = _mode_shapes(ref, setup, row, cfg, where)
        if shape is not None:
            shapes.append(shape)
    critical_table = pd.DataFrame(critical)
    return SpeedSweepResult(cfg, pd.concat(loci, ignore_index=True), pd.concat(damping, ignore_index=True),
                            critical_table, pd.DataFrame(sens_rows), _track_effect(cfg, critical_table),
                            pd.concat(maps, ignore_index=True), shapes)


def report(result: SpeedSweepResult, writer: Writer) -> str:
    """Write the locus, critical-speed, damping (and sensitivity) tables, the root-locus, stability-map and
    mode-shape figures; return markdown."""
    cfg, critical_table, sens_table, track_effect = result.config, result.table, result.sensitivity, result.track_effect
    writer.table(result.locus, "root_locus")
    writer.table(critical_table, "critical_speeds")
    writer.table(result.damping, "damping")
    if len(sens_table):
        writer.table(sens_table, "sensitivity")
    writer.figure(plot_root_locus(result.locus, critical_table), "root_locus", dpi=cfg.dpi)
    if len(result.maps):
        writer.table(result.maps[["model", *[c for c in result.maps.columns if c != "model"]]], "stability_map")
        vehicles = dict(zip(critical_table["model"], critical_table["vehicle"], strict=True))
        writer.figure(plot_stability_map(result.damping, result.maps, f"{cfg.study.name}: stability map over "
                                         f"{cfg.critical.range_m_s[0]:g}–{cfg.critical.range_m_s[1]:g} m/s",
                                         vehicles=vehicles),
                      "stability_map", dpi=cfg.dpi)
    shapes = []
    for shape in result.shapes:
        name = writer.figure(plot_mode_shapes(shape.view, shape.system, shape.title), f"modes_{_slug(shape.label)}",
                             dpi=cfg.dpi)
        shapes.append(f"![modes of {shape.label} at {shape.speed:.4g} m/s]({name})")
    stable = dict.fromkeys(("critical_speed_m_s", "critical_speed_mph"), stable_over(cfg.critical.range_m_s))
    lines = [f"# {cfg.study.name}", "", cfg.study.description, "",
             f"Root locus over {cfg.speeds.range_m_s[0]:g}–{cfg.speeds.range_m_s[1]:g} m/s; critical speed searched "
             f"in {cfg.critical.range_m_s[0]:g}–{cfg.critical.range_m_s[1]:g} m/s to ±{cfg.critical.tol_m_s:g} m/s.",
             "", markdown_table(critical_table, infinite=stable), ""]
    if len(track_effect):
        lines += ["Flexible against rigid track (same vehicle and parameters):", "",
                  markdown_table(track_effect, infinite=dict.fromkeys(("rigid_m_s", "flexible_m_s"), stable[
                      "critical_speed_m_s"])), ""]
        lines += _track_effect_sentences(track_effect, sens_table, stable["critical_speed_m_s"])
        writer.table(track_effect, "track_effect")
    if len(sens_table):
        pivot = sensitivity_pivot(sens_table)
        lines += ["Critical speed (m/s) with one parameter scaled by `factor` (all columns in `sensitivity.csv`):",
                  "", markdown_table(pivot, digits=5, infinite=dict.fromkeys(
                      map(str, pivot.columns), stable_over(cfg.critical.range_m_s))), ""]
    if len(result.maps):
        verdict = ("certified for every model" if bool(critical_table["certified"].all())
                   else "NOT certified for every model (see the method column)")
        lines += [f"Stability map (`stability_map.csv`): every stable and unstable interval of "
                  f"{cfg.critical.range_m_s[0]:g}–{cfg.critical.range_m_s[1]:g} m/s, each crossing found by the "
                  "bialternate pencil (no speed grid) and confirmed by eigen-solves within "
                  f"{cfg.critical.tol_m_s:g} m/s — {verdict}:", "",
                  markdown_table(result.maps[["model", "start_m_s", "end_m_s", "state", "mode_at_start",
                                              "mode_at_end"]], digits=5), "", "![stability map](stability_map.png)", ""]
    lines += ["![root locus](root_locus.png)", ""]
    if shapes:
        lines += ["Mode shapes on the plan view (each body displaced by the mode's lateral motion and turned by its "
                  "yaw, names from the shapes: `railopt.models.mode_names`):", "", *shapes, ""]
    return "\n".join(lines)


def sensitivity_pivot(sens: pd.DataFrame) -> pd.DataFrame:
    """Critical speed (m/s) per parameter and factor (rows, in the order the study lists them) and model (columns,
    in the study's order); a factor listed twice for one parameter is one row."""
    keys = sens[["parameter", "factor"]].drop_duplicates().reset_index(drop=True)
    for model in dict.fromkeys(sens["model"]):
        rows = sens[sens["model"] == model].drop_duplicates(["parameter", "factor"])
        keys = keys.merge(rows[["parameter", "factor", "critical_speed_m_s"]].rename(
            columns={"critical_speed_m_s": model}), on=["parameter", "factor"], how="left")
    return keys


def _slug(label: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in label)


def _track_effect_sentences(effect: pd.DataFrame, sens: pd.DataFrame,
                            stable: str = "stable over the range") -> list[str]:
    """The rigid/flexible finding in words, with the track-modulus limit when it was swept; a track on which the
    search found no crossing is named ``stable`` (:func:`stable_over`), never a change of ``nan`` %."""
    lines = []
    for _, r in effect.iterrows():
        if not (np.isfinite(r["rigid_m_s"]) and np.isfinite(r["flexible_m_s"])):
            def shown(v: float) -> str:
                return stable if np.isinf(v) else f"{v:.4g} m/s"

            lines.append(f"- `{r['flexible']}`: critical speed on flexible track {shown(r['flexible_m_s'])}, on "
                         f"rigid track (`{r['rigid']}`) {shown(r['rigid_m_s'])}: no change can be given.")
            continue
        verb = "raises" if r["change_m_s"] > 0 else "lowers"
        text = (f"- `{r['flexible']}`: the flexible track {verb} the critical speed by "
                f"{abs(r['change_percent']):.2f} % ({abs(r['change_m_s']):.3f} m/s) against `{r['rigid']}`.")
        if len(sens) and "track_modulus" in set(sens["parameter"]):
            rows = sens[(sens["parameter"] == "track_modulus") & (sens["model"] == r["flexible"])]
            steps = ", ".join(f"×{f:g}: {stable}" if np.isinf(v) else f"×{f:g}: {100 * (v / r['rigid_m_s'] - 1):+.2f} %"
                              for f, v in zip(rows["factor"], rows["critical_speed_m_s"], strict=True))
            text += f" Against the rigid value with the track modulus scaled: {steps} (→ rigid as the modulus grows)."
        lines.append(text)
    return lines + [""]


def _track_effect(cfg: SpeedSweepConfig, critical: pd.DataFrame) -> pd.DataFrame:
    """Pairs of models that differ only in ``track``: the change of critical speed, flexible − rigid."""
    by_key: dict[str, dict[str, str]] = {}
    for ref in cfg.models:
        opts = dict(ref.options)
        track = opts.pop("track", "rigid")
        key = f"{ref.model}:{sorted(opts.items())}"
        by_key.setdefault(key, {})[track] = ref.label
    crit = critical.set_index("model")
    rows = []
    for pair in by_key.values():
        if {"rigid", "flexible"} <= set(pair):
            r, f = crit.loc[pair["rigid"]], crit.loc[pair["flexible"]]
            both = np.isfinite(r["critical_speed_m_s"]) and np.isfinite(f["critical_speed_m_s"])
            change = f["critical_speed_m_s"] - r["critical_speed_m_s"] if both else np.nan  # no change to a range
            rows.append({"rigid": pair["rigid"], "flexible": pair["flexible"],
                         "rigid_m_s": r["critical_speed_m_s"], "flexible_m_s": f["critical_speed_m_s"],
                         "change_m_s": change, "change_percent": 100 * change / r["critical_speed_m_s"],
                         "rigid_hz": r["hunting_frequency_hz"], "flexible_hz": f["hunting_frequency_hz"]})
    return pd.DataFrame(rows)


SUMMARY = "root locus, critical speed and sensitivities over forward speed"
KIND = register_kind(StudyKind("speed_sweep", SpeedSweepConfig, compute, report, summary=SUMMARY))
