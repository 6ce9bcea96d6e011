"""Compute of the ``campaign`` kind: the campaigns (models × objectives × methods) into their resumable stores,
the checks of every distinct optimum, the comparison with named designs, and the data of the report's
sections (FRFs at the optima, before/after, stability, root loci, trade-offs, surfaces).  Writes no file
but the campaign stores."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from railopt.design import CampaignStore, MinimaxProblem, check_designs, distinct_optima, multistart
from railopt.models.stability import root_locus
from railopt.models.units import RAD_PER_HZ as HZ
from railopt.models.units import m_to_in
from railopt.studies.adapter import minimax_problem
from railopt.studies.catalog import Check, ModelSetup
from railopt.studies.kind import StudyContext, dask_context
from railopt.studies.kinds.campaign.config import (
    CampaignSettings,
    CampaignStudyConfig,
    ConstraintSpec,
    StabilitySpec,
    TradeoffSpec,
)
from railopt.studies.kinds.campaign.tradeoffs import Tradeoff, TradeoffSurfaces, surfaces, tradeoff_table
from railopt.studies.output.records import FrfPanel

__all__ = [
    "BeforeAfter",
    "CampaignResult",
    "ModelSections",
    "campaign_label",
    "Recommended",
    "campaign_problem",
    "check_optima",
    "check_stores",
    "compute",
    "design_peak",
    "run_campaign",
    "store_path",
    "warnings",
]


# ---------------------------------------------------------------------------------------------- stores and runs
def store_path(context: StudyContext, label: str) -> Path:
    return context.store_dir / "campaigns" / f"{label}.sqlite"


def check_stores(context: StudyContext, labels: list[str]) -> None:
    """Before any work: an existing store without --resume is an error naming the file."""
    if context.resume:
        return
    existing = [str(store_path(context, lb)) for lb in labels if store_path(context, lb).exists()]
    if existing:
        raise FileExistsError(
            f"store: {', '.join(existing)} already exist(s); pass --resume to finish or reuse them, "
            "or --fresh to discard them"
        )


def run_campaign(
    problem: MinimaxProblem,
    label: str,
    settings: CampaignSettings,
    context: StudyContext,
    config: dict[str, Any],
    client: Any = None,
    points: list[list[float]] | None = None,
) -> pd.DataFrame:
    """Run (or resume) one campaign into ``<store_dir>/campaigns/<label>.sqlite``; returns its table."""
    path = store_path(context, label)
    if path.exists():
        store = CampaignStore.open(path, expect_config=config)
    else:
        store = CampaignStore.create(path, label, config, list(problem.space.names))
    from railopt.studies.output.progress import Progress  # a bar on a terminal, plain periodic lines in a log

    bar = Progress(label, unit="start", enabled=context.show_progress)
    try:
        return multistart(problem, settings.n_starts, method=settings.method, seed=settings.seed,
                          sampler=settings.sampler, points=points, client=client, store=store,
                          options=settings.solver_options(), progress=bar.update,
                          retry_failed=context.retry_failed)
    finally:
        bar.close()
        store.close()


def _design_check(setup: ModelSetup, names: list[str], check: Check):
    """A check of the design x through the setup's parameter map, as the design layer runs it (a task):
    ``x -> (value, payload)``."""

    def on_design(x: np.ndarray) -> tuple[float, dict]:
        p, _ = setup.parameters(names, x)
        result = check(p)
        return result.value, result.payload()

    return on_design


def check_optima(optima: pd.DataFrame, setup: ModelSetup, names: list[str], label: str, context: StudyContext,
                 name: str, client: Any = None) -> tuple[pd.DataFrame, list[str]]:
    """Run check ``name`` of ``setup`` on each distinct optimum as tasks (results go to the campaign's store).

    Returns ``optima`` with a column ``name`` (the check's value) and the check's payload (a column already in
    ``optima`` is prefixed ``name.``), and the columns of the check's flags."""
    check = setup.checks[name]
    with CampaignStore.open(store_path(context, label)) as store:
        checks = check_designs(_design_check(setup, names, check), optima, names, name, client=client, store=store)
    checks = checks.drop(columns="name").rename(columns={"value": name})
    renamed = {c: f"{name}.{c}" for c in checks.columns if c not in ("start_id", name) and c in optima.columns}
    checks = checks.rename(columns=renamed)
    return optima.merge(checks, on="start_id", how="left"), [renamed.get(f, f) for f in check.flag_names]


# ---------------------------------------------------------------------------------------------- problems
def campaign_label(model: str, objective: str, method: str, problem: str = "constrained") -> str:
    """The store name of a campaign: ``<model>-<objective>-<method>``, with ``-unconstrained`` after the model for
    the unconstrained problem of a study that has constraints."""
    return f"{model}-{objective}-{method}" if problem == "constrained" else f"{model}-{problem}-{objective}-{method}"


def campaign_problem(cfg: CampaignStudyConfig, setup: ModelSetup, objective: str, problem: str = "constrained",
                     required_speed: float | None = None, limits: dict[int, float] | None = None) -> MinimaxProblem:
    """The minimax problem of one model, objective kind ("thesis", "exact" or "rms": the RMS per metre under
    ``[objective.spectrum]``) and problem: "constrained" (the config's ``[[constraints]]`` and ``[stability]``) or
    "unconstrained" (the objective alone).  A sweep changes the required speed of the stability rows
    (``required_speed``, m/s) or a constraint's limit (``limits``)."""
    exact = objective == "exact"
    variables = [v.variable() for v in cfg.design.variables]
    target = cfg.objective.rms_target(setup) if objective == "rms" else cfg.objective.target(setup, exact)
    if problem == "unconstrained":
        return minimax_problem(setup, variables, target)
    constraints = [c.target(setup, c.exact) for c in cfg.constraints]
    values = [c.limit_value(setup) for c in cfg.constraints]
    for i, value in (limits or {}).items():
        values[i] = value
    stability = None if cfg.stability is None else cfg.stability.target(setup, required_speed)
    return minimax_problem(setup, variables, target, constraints, values, stability)


def _p(cfg: CampaignStudyConfig, setup: ModelSetup, values: dict[str, float]) -> np.ndarray:
    names = [v.name for v in cfg.design.variables]
    return setup.parameters(names, np.array([values[n] for n in names]))[0]


def design_peak(cfg: CampaignStudyConfig, setup: ModelSetup, values: dict[str, float]) -> float:
    """Certified band maximum of the objective output at a design {variable: value}."""
    target = cfg.objective.target(setup, exact=True)
    return setup.family.at(_p(cfg, setup, values)).peak(band_rad_s=target.band, exact=True, output=target.output)


def _starts(cfg: CampaignStudyConfig, setup: ModelSetup) -> list[list[float]] | None:
    names = [v.name for v in cfg.design.variables]
    points = [[setup.named_designs[nm][n] for n in names] for nm in cfg.design.start_from]
    points += [[p[n] for n in names] for p in cfg.design.points]
    return points or None


# ---------------------------------------------------------------------------------------------- comparison
def _comparison_row(cfg: CampaignStudyConfig, setup: ModelSetup, key: tuple[str, str, str, str],
                    table: pd.DataFrame, optima: pd.DataFrame, flags: list[str]) -> dict:
    names = [v.name for v in cfg.design.variables]
    model, problem, objective, method = key
    ok = table[table["success"]]
    row: dict = {"model": model, "problem": problem, "objective": objective, "method": method, "starts": len(table),
                 "converged": int(table["success"].sum()), "success_rate": float(table["success"].mean()),
                 "distinct_optima": len(optima), "evaluations": int(table["evaluations"].sum()),
                 "wall_time_s": float(table["wall_time"].sum())}
    flags = [f for f in flags if f in optima.columns]  # no optima: no check columns
    row["all_optima_pass_checks"] = bool(optima[flags].all().all()) if flags and len(optima) else None
    # never an unstable design as the best: the best optimum is the best that passes every check
    passing = optima[optima[flags].all(axis=1)] if flags and len(optima) else optima
    row["failing_optima"] = len(optima) - len(passing)
    if flags and len(optima) and len(passing) < len(optima):
        failing = optima.drop(passing.index).sort_values("value").iloc[0]
        row["best_failing_U"] = float(failing["value"])
    ok = ok[ok["start_id"].isin(passing["start_id"])] if flags and len(optima) else ok
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
            row[f"change_vs_{ref}"] = (peak - ref_peak) / ref_peak
            for n in names:
                row[f"{n}_change_vs_{ref}"] = values[n] - ref_values[n]
        row["active_bounds"] = "; ".join(_active_bounds(cfg, values)) or "none"
    return row


def _short(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "problem", "objective", "method", *names, "U_objective", "true_peak", "converged", "starts",
            "distinct_optima"]
    cols += [c for c in comparison.columns if c.startswith("change_vs_")]
    return comparison[[c for c in cols if c in comparison.columns]]


def _frf_panels(cfg: CampaignStudyConfig, setups: dict[str, ModelSetup], comparison: pd.DataFrame) -> list:
    """|H| of the objective output over its band at each campaign's best design and the named designs."""
    panels = []
    f_hz = np.linspace(cfg.objective.band_hz[0], cfg.objective.band_hz[1], cfg.report.frf_points)
    names = [v.name for v in cfg.design.variables]
    for model, setup in setups.items():
        target = cfg.objective.target(setup, exact=True)
        curves = []
        for ref in cfg.report.compare:
            curves.append((f"{ref} (peak {design_peak(cfg, setup, setup.named_designs[ref]):.6g})", f_hz,
                           np.abs(setup.family.at(_p(cfg, setup, setup.named_designs[ref])).frf(
                               omega_rad_s=f_hz * HZ, output=target.output)), "ref"))
        for _, r in comparison[comparison["model"] == model].iterrows():
            if not np.isfinite(r.get("true_peak", np.nan)):
                continue
            p = _p(cfg, setup, {n: r[n] for n in names})
            label = f"{r['problem']} {r['objective']}/{r['method']}" if len(cfg.design.problems) > 1 else \
                f"railopt {r['objective']}/{r['method']}"
            curves.append((f"{label} (peak {r['true_peak']:.6g})", f_hz,
                           np.abs(setup.family.at(p).frf(frequencies_hz=f_hz, output=target.output)),
                           r["objective"]))
        panels.append(FrfPanel.build(f"{model}: {setup.description}", setup.axis_label(target.output), curves))
    return panels


# ---------------------------------------------------------------------------------------------- recommended design
@dataclass(frozen=True)
class Recommended:
    """The recommended design of one model: the best (certified U) distinct optimum of the constrained problem
    that passes every check (stable to the required speed) and meets every constraint.

    ``values`` are the design variables; ``parameters`` the family's parameters they set (element ids, SI);
    ``checks`` the payload of each check (critical speeds on each track, least damping, ...);
    ``constraints`` per constraint: output, certified peak, limit."""

    model: str
    source: dict[str, object]
    values: dict[str, float]
    parameters: dict[str, float]
    U: float
    existing_U: float | None
    checks: dict[str, dict]
    constraints: list[dict]

    def row(self) -> dict:
        """One row of ``recommended.csv``: the source, the variables, the element values (SI), U, the reduction
        against the existing design, every check's numbers and every constraint's peak and limit."""
        out: dict = {"model": self.model, **self.source, **self.values}
        out |= {k: v for k, v in self.parameters.items() if k not in self.values}
        out |= {"U": self.U, "existing_U": self.existing_U,
                "reduction_factor": self.existing_U / self.U if self.existing_U else None}
        for payload in self.checks.values():
            out |= payload
        for c in self.constraints:
            out |= {f"{c['output']}_peak": c["peak"], f"{c['output']}_limit": c["limit"]}
        return out


def _constraint_peaks(cfg: CampaignStudyConfig, setup: ModelSetup, p: np.ndarray) -> list[dict]:
    system = setup.family.at(p)
    return [{"output": c.output, "limit": c.limit_value(setup),
             "peak": system.peak(band_hz=c.band_hz, exact=True, output=c.output)} for c in cfg.constraints]


def _recommend(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, optima: dict, flags: dict,
               problem: str = "constrained") -> Recommended | None:
    """The best distinct optimum of ``problem`` over every objective and method that passes all its checks and
    meets every constraint (certified), or None."""
    names = [v.name for v in cfg.design.variables]
    best: tuple[float, dict, tuple] | None = None
    for key, found in optima.items():
        if key[0] != model or key[1] != problem or found.empty:
            continue
        keep = [f for f in flags[key] if f in found.columns]
        passing = found[found[keep].all(axis=1)] if keep else found
        for _, r in passing.iterrows():
            values = {n: float(r[n]) for n in names}
            U = design_peak(cfg, setup, values)
            if best is None or U < best[0]:
                best = (U, values, (key, int(r["start_id"])))
    if best is None:
        return None
    U, values, ((_, prob, objective, method), start) = best
    p = _p(cfg, setup, values)
    peaks = _constraint_peaks(cfg, setup, p) if problem == "constrained" else []
    if any(c["peak"] > c["limit"] * (1 + 1e-6) for c in peaks):
        return None
    existing = setup.named_designs.get("existing")
    existing_U = design_peak(cfg, setup, existing) if existing is not None else None
    designed = {n: setup.parameter_map.aliases.get(n, n) for n in names}
    parameters = {pid: float(p[list(setup.family.parameters).index(pid)]) for pid in designed.values()
                  if pid in setup.family.parameters}
    checks = {name: setup.checks[name](p).payload() for name in cfg.design.checks}
    return Recommended(model, {"problem": prob, "objective": objective, "method": method, "start_id": start},
                       values, parameters, U, existing_U, checks, peaks)


def warnings(cfg: CampaignStudyConfig) -> list[str]:
    """An existing design that fails a check (e.g. hunts below the required speed): the study still runs."""
    out = []
    for i, ref in enumerate(cfg.models):
        setup = ref.setup(f"models[{i}]")
        existing = setup.named_designs.get("existing")
        if existing is None:
            continue
        names = [n for n in existing if n in setup.family.parameters]
        p, _ = setup.parameters(names, np.array([existing[n] for n in names]))
        for name in cfg.design.checks:
            result = setup.checks[name](p)
            failed = [f for f, ok in result.flags.items() if not ok]
            if failed:
                numbers = ", ".join(f"{k} = {v:.4g}" for k, v in result.data.items())
                out.append(f"models[{i}] ({ref.label}): the existing design fails the {name!r} check "
                           f"({', '.join(failed)} is false: value {result.value:.4g}; {numbers})")
    return out


# ---------------------------------------------------------------------------------------------- report sections
@dataclass(frozen=True)
class BeforeAfter:
    """A named design against the best optimum: maxima per output, FRFs, checks and root loci."""

    table: pd.DataFrame
    thesis: float  # thesis approximation at the optimum
    exact: float  # certified maximum at the optimum
    active: list[str]  # active bounds at the optimum
    frfs: list[tuple[str, np.ndarray, np.ndarray, np.ndarray, str]]  # output, f (Hz), |before|, |after|, unit
    stability: pd.DataFrame | None
    loci: dict[str, pd.DataFrame] | None


@dataclass(frozen=True)
class ModelSections:
    """The report sections of one model: its best optimum, before/after, trade-offs and surfaces."""

    model: str
    tag: str
    best: pd.Series | None
    objective: str
    before_after: BeforeAfter | None = None
    tradeoffs: list[Tradeoff] = field(default_factory=list)
    surfaces: list[TradeoffSurfaces] = field(default_factory=list)
    recommended: Recommended | None = None
    unconstrained: dict | None = None


def _check_rows(cfg: CampaignStudyConfig, setup: ModelSetup, designs: dict[str, np.ndarray]) -> pd.DataFrame | None:
    rows = [{"design": label, "check": name, "value": (r := setup.checks[name](p)).value, **r.payload()}
            for label, p in designs.items() for name in cfg.design.checks]
    return pd.DataFrame(rows) if rows else None


def _where(rm) -> str:
    """Where a band maximum lies: "band edge" (the response still rising there) or "resonance"."""
    k = int(np.argmax(rm.values))
    return "band edge" if k >= len(rm.values) - 2 or rm.frequencies[k] in rm.band else "resonance"


def _active_bounds(cfg: CampaignStudyConfig, after: dict[str, float]) -> list[str]:
    out = []
    for v in cfg.design.variables:
        width = v.upper - v.lower
        if min(abs(after[v.name] - v.lower), abs(after[v.name] - v.upper)) <= 1e-6 * width:
            side = "lower" if abs(after[v.name] - v.lower) <= 1e-6 * width else "upper"
            out.append(f"{v.name} at its {side} bound")
    return out


def _before_after(cfg: CampaignStudyConfig, setup: ModelSetup, after: dict[str, float],
                  band: tuple[float, float]) -> BeforeAfter:
    """Maxima, FRFs, checks and (with forward speed) root loci of the named design ``report.before`` and the
    optimum ``after`` (Figs 4.13–4.17)."""
    p_before = _p(cfg, setup, setup.named_designs[cfg.report.before])
    p_after = _p(cfg, setup, after)
    sys_b, sys_a = setup.family.at(p_before), setup.family.at(p_after)
    outputs = cfg.report.outputs or [cfg.objective.target(setup, True).output]
    rows = []
    for o in outputs:
        rb = sys_b.response_maxima(band_rad_s=band, exact=True, output=o)
        ra = sys_a.response_maxima(band_rad_s=band, exact=True, output=o)
        row = {"output": o, "before": rb.value, "after": ra.value, "reduction_factor": rb.value / ra.value,
               "before_at_hz": rb.argmax_frequency / HZ, "before_peak_is": _where(rb),
               "after_at_hz": ra.argmax_frequency / HZ, "after_peak_is": _where(ra),
               "certified": rb.certified and ra.certified}
        if o in cfg.report.inch_outputs:
            row |= {"before_in": m_to_in(rb.value), "after_in": m_to_in(ra.value)}  # in, in/s or in/s² by quantity
        if o in cfg.report.published:
            pb, pa = cfg.report.published[o]
            row |= {"published_before": pb, "published_after": pa, "published_factor": pb / pa}
        rows.append(row)
    objective_output = cfg.objective.target(setup, True).output
    f_hz = np.linspace(band[0] / HZ, band[1] / HZ, cfg.report.frf_points)
    frfs = []
    for o in outputs:
        inch = o in cfg.report.inch_outputs
        before = np.abs(sys_b.frf(frequencies_hz=f_hz, output=o))
        after_h = np.abs(sys_a.frf(frequencies_hz=f_hz, output=o))
        if inch:
            before, after_h = m_to_in(before), m_to_in(after_h)
        frfs.append((o, f_hz, before, after_h, setup.axis_label(o, inch=inch)))
    loci = None
    if cfg.report.locus_speeds_m_s is not None:
        speeds = np.linspace(*cfg.report.locus_speeds_m_s, 80)
        loci = {label: root_locus(setup.stability_model(p), speeds).to_pandas()
                for label, p in (("before", p_before), ("after", p_after))}
    thesis = sys_a.response_maxima(band_rad_s=band, exact=False, output=objective_output).value
    return BeforeAfter(pd.DataFrame(rows), thesis,
                       sys_a.response_maxima(band_rad_s=band, exact=True, output=objective_output).value,
                       _active_bounds(cfg, after), frfs,
                       _check_rows(cfg, setup, {"before": p_before, "after": p_after}), loci)


def _sweep_problems(cfg: CampaignStudyConfig, setup: ModelSetup, objective: str, spec: TradeoffSpec
                    ) -> list[tuple[float, MinimaxProblem]]:
    """The constrained problem at each target of ``spec``: the output held below ε (replacing its constraint's
    limit, or added), the stability rows required up to the speed ε (``hunting``), or another check ≥ ε."""
    out = []
    for e in spec.epsilons:
        if spec.output is not None:
            index = next((i for i, c in enumerate(cfg.constraints) if c.output == spec.output), None)
            if index is not None:
                problem = campaign_problem(cfg, setup, objective, "constrained", limits={index: e})
            else:
                extra = ConstraintSpec(output=spec.output, band_hz=cfg.objective.band_hz, limit=e, exact=spec.exact)
                problem = campaign_problem(cfg.model_copy(update={"constraints": [*cfg.constraints, extra]}),
                                           setup, objective, "constrained")
        elif spec.check == "hunting":
            stable = cfg if cfg.stability is not None else cfg.model_copy(update={"stability": StabilitySpec()})
            problem = campaign_problem(stable, setup, objective, "constrained", required_speed=e)
        else:
            check, names = setup.checks[spec.check], [v.name for v in cfg.design.variables]
            problem = campaign_problem(cfg, setup, objective, "unconstrained").with_constraints(
                _CheckConstraint(setup, names, check), epsilon=-e)
        out.append((e, problem))
    return out


@dataclass(frozen=True)
class _CheckConstraint:
    """g(x) = −check value (≥ ε as −value ≤ −ε); a check stable over its whole range puts no constraint."""

    setup: ModelSetup
    names: list[str]
    check: Check

    def __call__(self, x: np.ndarray) -> np.ndarray:
        value = self.check(self.setup.parameters(self.names, x)[0]).value
        return np.array([-value if np.isfinite(value) else -1e12])


@dataclass(frozen=True)
class _DesignValues:
    """Values at a design x (a task on dask): the hunting check's critical speed and the constraints' peaks."""

    cfg: CampaignStudyConfig
    setup: ModelSetup
    hunting: bool

    def __call__(self, x: np.ndarray) -> np.ndarray:
        names = [v.name for v in self.cfg.design.variables]
        p, _ = self.setup.parameters(names, np.asarray(x, dtype=float))
        out = [self.setup.checks["hunting"](p).value] if self.hunting else []
        return np.array(out + [c["peak"] for c in _constraint_peaks(self.cfg, self.setup, p)])


def _quantity(cfg: CampaignStudyConfig, setup: ModelSetup, spec: TradeoffSpec):
    names = [v.name for v in cfg.design.variables]

    def value(x: np.ndarray) -> float:
        p, _ = setup.parameters(names, x)
        if spec.output is not None:
            return setup.family.at(p).peak(band_hz=cfg.objective.band_hz, exact=spec.exact, output=spec.output)
        return setup.checks[spec.check](p).value

    return value


def _unconstrained_best(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, tables: dict) -> dict | None:
    """The best unconstrained optimum whatever its checks say (for comparison beside the recommended design):
    the lowest certified peak among each objective's and method's best (the thesis objective's own value
    underestimates the peak, so values of different objectives are not compared)."""
    names = [v.name for v in cfg.design.variables]
    rows = [t[t["success"]] for (m, prob, _, _), t in tables.items() if m == model and prob == "unconstrained"]
    candidates = [{n: float(r.sort_values(["value", "start_id"]).iloc[0][n]) for n in names} for r in rows if len(r)]
    if not candidates:
        return None
    peaks = [design_peak(cfg, setup, values) for values in candidates]
    values = candidates[int(np.argmin(peaks))]
    p = _p(cfg, setup, values)
    return {"values": values, "U": min(peaks),
            "checks": {name: setup.checks[name](p) for name in cfg.design.checks},
            "constraints": _constraint_peaks(cfg, setup, p)}


def _model_sections(cfg: CampaignStudyConfig, model: str, setup: ModelSetup, comparison: pd.DataFrame,
                    tables: dict, tag: str, client, recommended: Recommended | None) -> ModelSections:
    """The before/after, trade-off and surface sections of one model, at its recommended design (or, without
    one, its best optimum passing the checks of the exact objective, or of the first objective)."""
    names = [v.name for v in cfg.design.variables]
    objective = "exact" if "exact" in cfg.design.objectives else cfg.design.objectives[0]
    rows = comparison[(comparison["model"] == model) & (comparison["objective"] == objective)
                      & (comparison["problem"] == cfg.design.problems[0])]
    rows = rows[np.isfinite(rows["true_peak"])] if "true_peak" in rows.columns else rows.iloc[0:0]
    if rows.empty and recommended is None:
        return ModelSections(model, tag, None, objective)
    best = rows.sort_values("true_peak").iloc[0] if len(rows) else None
    after = dict(recommended.values) if recommended is not None else {n: float(best[n]) for n in names}
    if best is None or recommended is not None:
        best = pd.Series({**after, "true_peak": recommended.U, **recommended.source})
    band = cfg.objective.target(setup, exact=True).band
    before_after = _before_after(cfg, setup, after, band) if cfg.report.before else None
    starts = pd.concat([t for (m, _, o, _), t in tables.items() if m == model])
    x_after = np.array([after[n] for n in names])
    tradeoffs = []
    for spec in cfg.tradeoffs:
        required = None
        if spec.check == "hunting":
            required = (cfg.stability.required(setup) if cfg.stability is not None else setup.required_speed)
        elif spec.output is not None:
            limits = [c.limit_value(setup) for c in cfg.constraints if c.output == spec.output]
            required = limits[0] if limits else None
        tradeoffs.append(tradeoff_table(
            spec, _sweep_problems(cfg, setup, objective, spec), starts, _quantity(cfg, setup, spec),
            lambda x: design_peak(cfg, setup, dict(zip(names, x, strict=True))), cfg.design.seed,
            points=[list(x_after)], client=client, required=required))
    reference = _unconstrained_best(cfg, setup, model, tables)
    marks = {"recommended" if recommended is not None else "optimum": after}
    if reference is not None:
        marks["unconstrained optimum"] = reference["values"]
    hunting = "hunting" in setup.checks and bool(setup.stability)
    limits = ([("critical speed (m/s) = required", (cfg.stability.required(setup) if cfg.stability is not None
                                                    else setup.required_speed), True)] if hunting else [])
    limits += [(f"{c.output} ({setup.units[c.output]}) = limit" if setup.units.get(c.output) else f"{c.output} = limit",
                c.limit_value(setup), False) for c in cfg.constraints]
    problem = campaign_problem(cfg, setup, objective, "unconstrained")
    u_unit = setup.units.get(cfg.objective.output or setup.family.output_names[0], "")
    grids = [surfaces(problem, spec, x_after, client, _DesignValues(cfg, setup, hunting), limits, marks,
                      units=(*(setup.parameter_map.unit(v) for v in spec.variables), u_unit))
             for spec in cfg.surfaces]
    return ModelSections(model, tag, best, objective, before_after, tradeoffs, grids, recommended, reference)


# ---------------------------------------------------------------------------------------------- compute
@dataclass(frozen=True)
class CampaignResult:
    """Every campaign's starts and checked optima, the comparison, FRF panels and the report sections."""

    config: CampaignStudyConfig
    comparison: pd.DataFrame
    starts: pd.DataFrame
    optima: pd.DataFrame
    table: pd.DataFrame  # the CLI's short comparison
    frf_panels: list
    sections: list[ModelSections]
    named: dict[str, dict[str, float]] = field(default_factory=dict)  # model -> its existing design
    existing_checks: dict[str, dict[str, dict]] = field(default_factory=dict)  # model -> check -> payload


def _store_config(cfg: CampaignStudyConfig, key: tuple[str, str, str, str]) -> dict:
    """What a campaign's store is made from: the whole config but the number of starts (a resume may extend a
    campaign: the same seed and sampler give the same first starts, so only the new ones run)."""
    model, kind, objective, method = key
    dumped = cfg.model_dump(mode="json")
    dumped["design"] = {k: v for k, v in dumped["design"].items() if k != "n_starts"}
    return {**dumped, "campaign": {"model": model, "objective": objective, "method": method, "problem": kind}}


def _flat(value: object, prefix: str = "") -> dict[str, object]:
    if isinstance(value, dict):
        out: dict[str, object] = {}
        for k, v in value.items():
            out |= _flat(v, f"{prefix}.{k}" if prefix else str(k))
        return out
    return {prefix: value}


def _check_resumable(path: Path, config: dict) -> None:
    """A store made from another config is refused naming the fields that differ (``n_starts`` may grow)."""
    if not path.exists():
        return
    with CampaignStore.open(path) as store:
        stored = store.config()
    old, new = _flat(stored), _flat(json.loads(json.dumps(config, sort_keys=True, default=str)))
    changed = sorted(k for k in old.keys() | new.keys() if old.get(k, "<absent>") != new.get(k, "<absent>"))
    if changed:
        shown = ", ".join(f"{k} ({old.get(k, '<absent>')!r} → {new.get(k, '<absent>')!r})" for k in changed[:6])
        more = f" and {len(changed) - 6} more" if len(changed) > 6 else ""
        raise ValueError(f"store: {path} was made from a different config: {shown}{more}; only design.n_starts may "
                         "change on --resume (run with --fresh to discard the store)")


def _campaign(cfg: CampaignStudyConfig, setup: ModelSetup, key: tuple[str, str, str, str], context: StudyContext,
              client) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """One campaign (model, problem, objective, method): its starts, its checked distinct optima and their flags."""
    model, kind, objective, method = key
    names = [v.name for v in cfg.design.variables]
    problem = campaign_problem(cfg, setup, objective, kind)
    label = campaign_label(model, objective, method, kind)
    settings = cfg.design.model_copy(update={"method": method})
    store_config = _store_config(cfg, key)
    _check_resumable(store_path(context, label), store_config)
    table = run_campaign(problem, label, settings, context, store_config, client, _starts(cfg, setup))
    found = distinct_optima(table, problem).rename(columns={"best_start": "start_id"})
    flags: list[str] = []
    for check in cfg.design.checks:
        found, check_flags = check_optima(found, setup, names, label, context, check, client)
        flags += check_flags
    return table, found, flags


def compute(config: CampaignStudyConfig, context: StudyContext) -> CampaignResult:
    cfg = config
    setups = cfg.setups()
    names = [v.name for v in cfg.design.variables]
    keys = [(m, prob, o, meth) for m in setups for prob in cfg.design.problems for o, meth in cfg.design.plan(prob)]
    check_stores(context, [campaign_label(m, o, meth, prob) for m, prob, o, meth in keys])
    tables: dict[tuple[str, str, str, str], pd.DataFrame] = {}
    optima: dict[tuple[str, str, str, str], pd.DataFrame] = {}
    rows = []
    flags: dict[tuple[str, str, str, str], list[str]] = {}
    with dask_context(context) as client:
        for key in keys:
            tables[key], optima[key], flags[key] = _campaign(cfg, setups[key[0]], key, context, client)
            rows.append(_comparison_row(cfg, setups[key[0]], key, tables[key], optima[key], flags[key]))
        comparison = pd.DataFrame(rows)
        recommended = {m: _recommend(cfg, s, m, optima, flags, cfg.design.problems[0]) for m, s in setups.items()}
        sections = []
        if cfg.report.before or cfg.tradeoffs or cfg.surfaces or any(recommended.values()):
            sections = [_model_sections(cfg, m, s, comparison, tables, "" if len(setups) == 1 else f"_{m}", client,
                                        recommended[m])
                        for m, s in setups.items()]
    starts = pd.concat([t.drop(columns=["functions"], errors="ignore").assign(model=m, problem=prob, objective=o,
                                                                             method=meth)
                        for (m, prob, o, meth), t in tables.items()], ignore_index=True)
    optima_table = pd.concat([t.assign(model=m, problem=prob, objective=o, method=meth)
                              for (m, prob, o, meth), t in optima.items()], ignore_index=True)
    named = {m: {n: float(s.named_designs["existing"][n]) for n in names} for m, s in setups.items()
             if "existing" in s.named_designs}
    existing_checks = {m: {c: s.checks[c](_p(cfg, s, named[m])).payload() for c in cfg.design.checks}
                       for m, s in setups.items() if m in named}
    return CampaignResult(cfg, comparison, starts, optima_table, _short(comparison, names),
                          _frf_panels(cfg, setups, comparison), sections, named, existing_checks)
