"""Study kind ``campaign``: a multi-start minimax campaign of any catalogued model, from config alone.

A config lists the models (``[[models]]``: a label, a registered model and its options), the
design variables (``[[design.variables]]``: name, bounds, scale), the objective (an output over a
band), optional constraints (other outputs' maxima below a limit), the matrix of methods ×
objectives (thesis approximation (4.71)–(4.73) and/or the certified band maximum), the starts
(Sobol/LHS plus named designs or explicit points) and the checks of every distinct optimum
(stability).  One campaign runs per model × objective × method, each into its own resumable
SQLite store.  Tables: ``comparison.csv`` (one row per campaign: success rate, distinct optima,
evaluations, wall time, best U, true band peak at the best design, comparison with named designs),
``starts.csv/.parquet``, ``optima.csv`` (distinct optima with their checks); figure ``frf.png``.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
import pandas as pd
from pydantic import Field, field_validator, model_validator

from railopt.design import DesignVariable, MinimaxProblem, distinct_optima
from railopt.studies.base import (
    BandHz,
    FiniteModel,
    StrictModel,
    StudyContext,
    StudyKind,
    StudyOutcome,
    dask_context,
    register_kind,
)
from railopt.studies.campaign import CampaignSettings, check_optima, check_stores, run_campaign
from railopt.studies.catalog import ModelSetup, ModelsStudy, require_unique
from railopt.studies.figures import plot_frf_panels
from railopt.studies.problem import ResponseTarget, minimax_problem
from railopt.studies.report import markdown_table, write_table
from railopt.studies.ride_report import ride_report
from railopt.studies.tradeoffs import SurfaceSpec, TradeoffSpec

HZ = 2 * np.pi


class VariableSpec(FiniteModel):
    name: str
    lower: float
    upper: float
    scale: Literal["linear", "log"] = "linear"

    @model_validator(mode="after")
    def _bounds(self) -> VariableSpec:
        DesignVariable(self.name, self.lower, self.upper, self.scale)  # same rules as the design layer
        return self

    def variable(self) -> DesignVariable:
        return DesignVariable(self.name, self.lower, self.upper, self.scale)


class OutputSpec(FiniteModel):
    """An output of the model over a band (Hz)."""

    output: str | None = None
    band_hz: BandHz

    def target(self, setup: ModelSetup, exact: bool) -> ResponseTarget:
        output = self.output or setup.system.output_names[0]
        return ResponseTarget(output, (self.band_hz[0] * HZ, self.band_hz[1] * HZ), exact)


class ConstraintSpec(OutputSpec):
    """f_k of ``output`` ≤ ``limit`` (units of the output) — the ε of ε-constraint sweeps."""

    limit: float = Field(gt=0)
    exact: bool = True


class CampaignDesign(CampaignSettings):
    """``[design]``: variables, the methods × objectives matrix, starts, solver options."""

    variables: list[VariableSpec] = Field(min_length=1)
    methods: list[Literal["slsqp", "cobyla", "slp"]] = Field(default=["slsqp"], min_length=1)
    objectives: list[Literal["thesis", "exact"]] = Field(default=["exact"], min_length=1)
    start_from: list[str] = Field(default_factory=list, description="named designs of each model used as starts")
    points: list[dict[str, float]] = Field(default_factory=list, description="explicit starts {variable: value}")
    checks: list[str] = Field(default_factory=lambda: ["spectral_abscissa"], description="checks of each optimum")
    method: Literal["slsqp", "cobyla", "slp"] = "slsqp"  # set per campaign from `methods`, never by the config

    @field_validator("method")  # runs only for a value written in the config (defaults are not validated)
    @classmethod
    def _no_single_method(cls, v: str) -> str:
        raise ValueError(f"this kind runs every entry of `methods`; write methods = [{v!r}] instead")

    @field_validator("methods", "objectives")
    @classmethod
    def _unique(cls, v: list[str]) -> list[str]:
        if len(set(v)) != len(v):
            raise ValueError(f"entries must be unique, got {v}")
        return v


class ReportSpec(StrictModel):
    compare: list[str] = Field(default_factory=list, description="named designs reported beside the optima")
    before: str | None = Field(None, description="a named design reported before/after against the best optimum")
    outputs: list[str] = Field(default_factory=list, description="outputs shown before/after (default: objective)")
    inch_outputs: list[str] = Field(default_factory=list, description="outputs also reported in inches (m → in)")
    locus_speeds_m_s: tuple[float, float] | None = Field(None, description="root locus before/after over speed")
    published: dict[str, tuple[float, float]] = Field(
        default_factory=dict, description="output -> published (before, after) peaks, in inches for inch_outputs")
    frf_points: int = Field(800, ge=50, le=20000)
    dpi: int = Field(110, ge=50, le=300)


class CampaignStudyConfig(ModelsStudy):
    KIND: ClassVar[str] = "campaign"
    objective: OutputSpec
    constraints: list[ConstraintSpec] = Field(default_factory=list)
    design: CampaignDesign
    report: ReportSpec = ReportSpec()
    tradeoffs: list[TradeoffSpec] = Field(default_factory=list)
    surfaces: list[SurfaceSpec] = Field(default_factory=list)

    @model_validator(mode="after")
    def _resolve(self) -> CampaignStudyConfig:
        """Everything a run would reject is rejected here (``railopt validate`` = ``run``)."""
        require_unique("design.variables", [v.name for v in self.design.variables])
        for i, ref in enumerate(self.models):
            where = f"models[{i}]"
            setup = ref.setup(where)
            _check_setup(self, setup, where)
        return self

    def setups(self) -> dict[str, ModelSetup]:
        return {m.label: m.setup(f"models[{i}]") for i, m in enumerate(self.models)}


def _check_setup(cfg: CampaignStudyConfig, setup: ModelSetup, where: str) -> None:
    names = [v.name for v in cfg.design.variables]
    bad = [n for n in names if n not in setup.designable]
    if bad:
        raise ValueError(f"design.variables: {bad} are not parameters of {where}; choose from {list(setup.designable)}")
    outputs = setup.system.output_names
    specs = [("objective", cfg.objective)] + [(f"constraints[{i}]", c) for i, c in enumerate(cfg.constraints)]
    for field, spec in specs:
        if spec.output is not None and spec.output not in outputs:
            raise ValueError(f"{field}.output: unknown output {spec.output!r} of {where}; outputs are {list(outputs)}")
    before = [cfg.report.before] if cfg.report.before else []
    for field, named in (("design.start_from", cfg.design.start_from), ("report.compare", cfg.report.compare),
                         ("report.before", before)):
        for name in named:
            if name not in setup.named_designs:
                raise ValueError(f"{field}: {where} has no named design {name!r}; it has {sorted(setup.named_designs)}")
            missing = [n for n in names if n not in setup.named_designs[name]]
            if missing:
                raise ValueError(f"{field}: named design {name!r} of {where} does not set {missing}")
    for i, point in enumerate(cfg.design.points):
        if sorted(point) != sorted(names):
            raise ValueError(f"design.points[{i}]: must give exactly the variables {names}, got {sorted(point)}")
        for v in cfg.design.variables:
            if not (v.lower <= point[v.name] <= v.upper) or not np.isfinite(point[v.name]):
                raise ValueError(f"design.points[{i}].{v.name}: {point[v.name]} outside [{v.lower}, {v.upper}]")
    for field, wanted in (("report.outputs", cfg.report.outputs), ("report.inch_outputs", cfg.report.inch_outputs),
                          ("report.published", list(cfg.report.published)),
                          ("tradeoffs.output", [t.output for t in cfg.tradeoffs if t.output])):
        bad = [o for o in wanted if o not in outputs]
        if bad:
            raise ValueError(f"{field}: {bad} are not outputs of {where}; outputs are {list(outputs)}")
    for t in cfg.tradeoffs:
        if t.check is not None and t.check not in setup.checks:
            raise ValueError(f"tradeoffs.{t.name}.check: {where} has no check {t.check!r}")
    for sp in cfg.surfaces:
        bad = [v for v in sp.variables if v not in names]
        if bad or sp.variables[0] == sp.variables[1]:
            raise ValueError(f"surfaces.variables: need two different design variables of {names}, got {sp.variables}")
    if cfg.report.locus_speeds_m_s is not None and setup.speed_model is None:
        raise ValueError(f"report.locus_speeds_m_s: {where} has no forward speed")
    for name in cfg.design.checks:
        if name not in setup.checks:
            raise ValueError(f"design.checks: {where} has no check {name!r}; it has {sorted(setup.checks)}")
    # the model must evaluate at every start before anything is written
    for name in cfg.design.start_from:
        point = [setup.named_designs[name][n] for n in names]
        for v, x in zip(cfg.design.variables, point, strict=True):
            if not (v.lower <= x <= v.upper):
                raise ValueError(f"design.start_from: named design {name!r}: {v.name} = {x:g} is outside its bounds")
        setup.parameters(names, np.array(point))


def campaign_label(model: str, objective: str, method: str) -> str:
    return f"{model}-{objective}-{method}"


def campaign_problem(cfg: CampaignStudyConfig, setup: ModelSetup, objective: str) -> MinimaxProblem:
    """The minimax problem of one model and objective kind ("thesis" or "exact")."""
    exact = objective == "exact"
    constraints = [c.target(setup, c.exact) for c in cfg.constraints]
    return minimax_problem(setup, [v.variable() for v in cfg.design.variables], cfg.objective.target(setup, exact),
                           constraints, [c.limit for c in cfg.constraints])


def design_peak(cfg: CampaignStudyConfig, setup: ModelSetup, values: dict[str, float]) -> float:
    """Certified band maximum of the objective output at a design {variable: value}."""
    names = [v.name for v in cfg.design.variables]
    p, _ = setup.parameters(names, np.array([values[n] for n in names]))
    target = cfg.objective.target(setup, exact=True)
    return setup.system.at(p).peak(target.band, exact=True, output=target.output)


def _starts(cfg: CampaignStudyConfig, setup: ModelSetup) -> list[list[float]] | None:
    names = [v.name for v in cfg.design.variables]
    points = [[setup.named_designs[nm][n] for n in names] for nm in cfg.design.start_from]
    points += [[p[n] for n in names] for p in cfg.design.points]
    return points or None


def run(config: CampaignStudyConfig, context: StudyContext) -> StudyOutcome:
    cfg = config
    setups = cfg.setups()
    names = [v.name for v in cfg.design.variables]
    campaigns = [(m, o, meth) for m in setups for o in cfg.design.objectives for meth in cfg.design.methods]
    check_stores(context, [campaign_label(*c) for c in campaigns])
    base_config = cfg.model_dump(mode="json")
    tables: dict[tuple[str, str, str], pd.DataFrame] = {}
    optima: dict[tuple[str, str, str], pd.DataFrame] = {}
    with dask_context(context) as client:
        for model, objective, method in campaigns:
            setup = setups[model]
            problem = campaign_problem(cfg, setup, objective)
            label = campaign_label(model, objective, method)
            settings = cfg.design.model_copy(update={"method": method})
            campaign_cfg = {**base_config, "campaign": {"model": model, "objective": objective, "method": method}}
            table = run_campaign(problem, label, settings, context, campaign_cfg, client, _starts(cfg, setup))
            tables[(model, objective, method)] = table
            found = distinct_optima(table, problem).rename(columns={"best_start": "start_id"})
            for check in cfg.design.checks:
                found = check_optima(found, names, label, context, check,
                                     _parameter_check(setup, names, setup.checks[check]), client)
            optima[(model, objective, method)] = found
        rows = [_comparison_row(cfg, setups[m], m, o, meth, tables[(m, o, meth)], optima[(m, o, meth)])
                for m, o, meth in campaigns]
        comparison = pd.DataFrame(rows)
        extra_files, extra_md = ride_report(cfg, setups, comparison, tables, context, client)
    starts = pd.concat([t.drop(columns=["functions"], errors="ignore").assign(model=m, objective=o, method=meth)
                        for (m, o, meth), t in tables.items()], ignore_index=True)
    optima_table = pd.concat([t.assign(model=m, objective=o, method=meth) for (m, o, meth), t in optima.items()],
                             ignore_index=True)
    files = write_table(comparison, context.outdir, "comparison")
    files += write_table(starts, context.outdir, "starts", parquet=True)
    files += write_table(optima_table, context.outdir, "optima")
    files += _frf_figure(cfg, setups, comparison, context) + extra_files
    markdown = _markdown(cfg, comparison, names) + "\n".join(extra_md)
    return StudyOutcome(table=_short(comparison, names), markdown=markdown, files=files)


def _parameter_check(setup: ModelSetup, names: list[str], check):
    """A check of the design x, through the setup's parameter map (runs as a dask task)."""

    def on_design(x: np.ndarray):
        p, _ = setup.parameters(names, x)
        return check(p)

    return on_design


def _comparison_row(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, objective: str, method: str,
                    table: pd.DataFrame, optima: pd.DataFrame) -> dict:
    names = [v.name for v in cfg.design.variables]
    ok = table[table["success"]]
    row: dict = {"model": model, "objective": objective, "method": method, "starts": len(table),
                 "converged": int(table["success"].sum()), "success_rate": float(table["success"].mean()),
                 "distinct_optima": len(optima), "evaluations": int(table["evaluations"].sum()),
                 "wall_time_s": float(table["wall_time"].sum())}
    flags = [c for c in optima.columns if optima[c].dtype == bool]
    row["all_optima_pass_checks"] = bool(optima[flags].all().all()) if flags else None
    if len(ok):
        best = ok.sort_values(["value", "start_id"]).iloc[0]
        values = {n: float(best[n]) for n in names}
        peak = design_peak(cfg, setup, values)
        row |= {**values, "U_objective": float(best["value"]), "true_peak": peak,
                "objective_underestimate": (peak - float(best["value"])) / peak,
                "best_start": int(best["start_id"])}
        for ref in cfg.report.compare:
            ref_values = setup.named_designs[ref]
            ref_peak = design_peak(cfg, setup, ref_values)
            row[f"{ref}_peak"] = ref_peak
            row[f"rel_err_vs_{ref}"] = (peak - ref_peak) / ref_peak
            for n in names:
                row[f"{n}_err_vs_{ref}"] = values[n] - ref_values[n]
    return row


def _main_columns(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "objective", "method", *names, "U_objective", "true_peak", "objective_underestimate",
            "converged", "starts", "distinct_optima", "evaluations", "wall_time_s", "all_optima_pass_checks"]
    return comparison[[c for c in cols if c in comparison.columns]]


def _short(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "objective", "method", *names, "U_objective", "true_peak", "converged", "starts",
            "distinct_optima"]
    cols += [c for c in comparison.columns if c.startswith("rel_err_vs_")]
    return comparison[[c for c in cols if c in comparison.columns]]


def _frf_figure(cfg: CampaignStudyConfig, setups: dict[str, ModelSetup], comparison: pd.DataFrame,
                context: StudyContext) -> list[str]:
    """|H| of the objective output over its band at each campaign's best design and the named designs."""
    names = [v.name for v in cfg.design.variables]
    panels = []
    for model, setup in setups.items():
        target = cfg.objective.target(setup, exact=True)
        f_hz = np.linspace(cfg.objective.band_hz[0], cfg.objective.band_hz[1], cfg.report.frf_points)
        curves = []
        for ref in cfg.report.compare:
            p, _ = setup.parameters(names, np.array([setup.named_designs[ref][n] for n in names]))
            curves.append((f"{ref} (peak {design_peak(cfg, setup, setup.named_designs[ref]):.6g})", f_hz,
                           np.abs(setup.system.at(p).frf(f_hz * HZ, target.output)), "ref"))
        for _, r in comparison[comparison["model"] == model].iterrows():
            if not np.isfinite(r.get("true_peak", np.nan)):
                continue
            p, _ = setup.parameters(names, np.array([r[n] for n in names]))
            curves.append((f"railopt {r['objective']}/{r['method']} (peak {r['true_peak']:.6g})", f_hz,
                           np.abs(setup.system.at(p).frf(f_hz * HZ, target.output)), r["objective"]))
        panels.append((f"{model}: {setup.description}", f"|H| of {target.output}", curves))
    fig = plot_frf_panels(panels)
    fig.savefig(context.outdir / "frf.png", dpi=cfg.report.dpi)
    return ["frf.png"]


def _markdown(cfg: CampaignStudyConfig, comparison: pd.DataFrame, names: list[str]) -> str:
    d = cfg.design
    starts = f"{d.n_starts} {d.sampler} starts (seed {d.seed})"
    if d.start_from:
        starts += " plus the named designs " + ", ".join(f"`{s}`" for s in d.start_from)
    if d.points:
        starts += f" plus {len(d.points)} explicit point(s)"
    lines = [
        f"# {cfg.study.name}",
        "",
        cfg.study.description,
        "",
        f"Variables: {', '.join(f'{v.name} ∈ [{v.lower:g}, {v.upper:g}]' for v in d.variables)}; "
        f"objective: {cfg.objective.output or 'first output'} over {cfg.objective.band_hz[0]:g}–"
        f"{cfg.objective.band_hz[1]:g} Hz; methods {', '.join(d.methods)}; {starts}.",
        "",
        "`thesis` minimises the response maxima (4.71)–(4.73) (|H| at the damped natural frequencies and the",
        "band edges); `exact` minimises the certified band maximum. `true_peak` is the certified band maximum",
        "at the best design found; `objective_underestimate` is how far the minimised value lies below it.",
        "",
        markdown_table(_main_columns(comparison, names)),
        "",
    ]
    for ref in cfg.report.compare:
        cols = ["model", "objective", "method", f"{ref}_peak", f"rel_err_vs_{ref}"]
        cols += [f"{n}_err_vs_{ref}" for n in names]
        lines += [f"Against `{ref}` (its certified peak, and the best design's differences):", "",
                  markdown_table(comparison[[c for c in cols if c in comparison.columns]]), ""]
    lines += [
        "Per campaign: evaluations and wall time are sums over its starts; `comparison.csv` has every column.",
        "",
        "![FRF at the optima](frf.png)",
        "",
    ]
    return "\n".join(lines)


KIND = register_kind(StudyKind(
    name="campaign",
    config_model=CampaignStudyConfig,
    run=run,
    summary="multi-start minimax campaign (methods × objectives) of a catalogued model",
))
