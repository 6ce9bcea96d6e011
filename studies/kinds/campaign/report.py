"""Report of the ``campaign`` kind: tables, figures and the summary, as a list of section builders.

Each builder takes the :class:`~railopt.studies.kinds.campaign.run.CampaignResult` (or one model's sections)
and the writer, writes its tables and figures, and returns its markdown lines: the comparison (every
campaign), then per model the before/after (Figs 4.13–4.17), the trade-offs and the surfaces (Fig 4.18).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from railopt.studies.kinds.campaign.run import CampaignResult
from railopt.studies.kinds.campaign.sections import BeforeAfter, ModelSections
from railopt.studies.kinds.campaign.tradeoffs import Tradeoff, TradeoffSurfaces
from railopt.studies.output.figures import (
    plot_before_after,
    plot_frf_panels,
    plot_root_loci_before_after,
    plot_surfaces,
    plot_tradeoff,
)
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.writer import Writer

__all__ = [
    "before_after_section", "comparison_section", "recommended_section", "report", "surfaces_section",
    "tradeoffs_section",
]


def _main_columns(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "problem", "objective", "method", *names, "U_objective", "true_peak", "objective_underestimate",
            "active_bounds", "converged", "starts", "distinct_optima", "failing_optima", "best_failing_U",
            "evaluations", "wall_time_s"]
    return comparison[[c for c in cols if c in comparison.columns]]


def comparison_section(result: CampaignResult, writer: Writer) -> list[str]:
    """comparison.csv, starts.csv/.parquet, optima.csv, frf.png and the summary's head."""
    cfg, comparison = result.config, result.comparison
    names = [v.name for v in cfg.design.variables]
    writer.table(comparison, "comparison")
    writer.table(result.starts, "starts", parquet=True)
    writer.table(result.optima, "optima")
    writer.figure(plot_frf_panels(result.frf_panels), "frf", dpi=cfg.report.dpi)
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
        "A campaign's best design is its best distinct optimum that passes every check (`design.checks`); the",
        "optima that fail them are counted in `failing_optima` and the best of them is `best_failing_U`",
        "(never reported as an optimum: `optima.csv` has each with its checks).",
        "",
        markdown_table(_main_columns(comparison, names)),
        "",
    ]
    for ref in cfg.report.compare:
        cols = ["model", "problem", "objective", "method", f"{ref}_peak", f"change_vs_{ref}"]
        cols += [f"{n}_change_vs_{ref}" for n in names]
        lines += [f"Against `{ref}` (its certified peak, and the best design's differences):", "",
                  markdown_table(comparison[[c for c in cols if c in comparison.columns]]), ""]
    lines += [
        "Per campaign: evaluations and wall time are sums over its starts; `comparison.csv` has every column.",
        "",
        "![FRF at the optima](frf.png)",
        "",
    ]
    return lines


def before_after_section(result: CampaignResult, s: ModelSections, writer: Writer) -> list[str]:
    """before_after.csv, the FRFs before and after, stability.csv and the root loci of one model."""
    ba: BeforeAfter | None = s.before_after
    if ba is None:
        return []
    cfg, tag, model, best = result.config, s.tag, s.model, s.best
    dpi = cfg.report.dpi
    writer.table(ba.table, f"before_after{tag}")
    md = [f"## {model}: before (`{cfg.report.before}`) and after (best {best['objective']} optimum, "
          f"{best['method']})", "", markdown_table(ba.table, digits=5), "",
          f"Active bounds at the optimum: {', '.join(ba.active) if ba.active else 'none'}. The thesis approximation "
          f"(4.71)–(4.73) reads {ba.thesis:.5g} at this optimum against the certified maximum {ba.exact:.5g} "
          f"({100 * (ba.thesis - ba.exact) / ba.exact:+.2f} %).", ""]
    for o, f_hz, before, after, unit in ba.frfs:
        fig = plot_before_after(f_hz, before, after, f"{model}: {o} before and after optimisation", unit)
        name = writer.figure(fig, f"{o}_before_after{tag}", dpi=dpi)
        md += [f"![{o}]({name})", ""]
    if ba.stability is not None:
        writer.table(ba.stability, f"stability{tag}")
        md += ["Stability before and after (every distinct optimum's checks are in `optima.csv`):", "",
               markdown_table(ba.stability, digits=5), ""]
    if ba.loci is not None:
        fig = plot_root_loci_before_after(ba.loci, f"{model}: velocity root loci before and after (rigid track)")
        name = writer.figure(fig, f"root_locus_before_after{tag}", dpi=dpi)
        writer.table(pd.concat([d.assign(design=k) for k, d in ba.loci.items()]), f"root_locus_before_after{tag}")
        md += [f"![root loci]({name})", ""]
    return md


def _tradeoff(result: CampaignResult, s: ModelSections, t: Tradeoff, writer: Writer) -> list[str]:
    names = [v.name for v in result.config.design.variables]
    stem, q, spec = f"{t.spec.name}{s.tag}", t.quantity, t.spec
    writer.table(t.table, f"tradeoff_{stem}")
    writer.table(t.front, f"pareto_{stem}")
    writer.figure(plot_tradeoff(t.table, q, f"{s.model}: U against {q} ({spec.name})", required=t.required),
                  f"pareto_{stem}", dpi=result.config.report.dpi)
    how = ("the constrained problem solved with the stability rows required up to each speed"
           if spec.check == "hunting" else "the constrained problem solved with every vehicle mode at least ζ_min "
           "damped up to the required speed, at each ζ_min" if spec.check == "damping"
           else f"the constrained problem solved at each limit of {spec.output}"
           if spec.output else f"the {spec.check} check held above each value")
    missed = int((~t.table["feasible"]).sum()) if "feasible" in t.table.columns else 0
    md = [f"Trade-off `{spec.name}` ({how}; targets {', '.join(f'{e:g}' for e in spec.epsilons)}): "
          f"{len(t.front)} non-dominated designs among the {len(t.table) - missed} of {len(t.table)} distinct "
          f"designs (sweep optima and every start; `count` = how many identical designs each row stands for) that "
          f"meet every other constraint of the constrained problem ({_others(result, spec)}); the {missed} that do "
          f"not are listed in `tradeoff_{stem}.csv` (`feasible` False) and drawn apart; `pareto_{stem}.csv`:", "",
          markdown_table(t.front[["source", "count", "U", q, *names]].head(12), digits=5), ""]
    if t.required is not None:
        sense = "≥" if spec.check is not None else "≤"
        if t.pick is not None:
            md += [f"Best design with {q} {sense} {t.required:.4g} that meets every constraint and the whole "
                   f"stability criterion: U = {t.pick['U']:.5g}, {q} = {t.pick[q]:.4g}.", ""]
            rec = s.recommended
            if rec is not None and t.pick["U"] < rec.U * (1 - 1e-6):
                md += [f"**It beats the recommended design (U = {rec.U:.5g})**, which is the best certified optimum "
                       "of the constrained campaigns: the sweep found a better certified design than the campaign's "
                       "starts; raise `design.n_starts` (the recommendation is kept from the campaigns).", ""]
            elif rec is not None:
                md += [f"The recommended design (U = {rec.U:.5g}) is at least as good: no certified design of the "
                       "sweep or the starts beats it.", ""]
        else:
            md += [f"No design with {q} {sense} {t.required:.4g} meets every constraint and the whole stability "
                   "criterion.", ""]
    return md


def _others(result: CampaignResult, spec) -> str:
    """The constraints a front design must meet besides the traded one, in words."""
    cfg = result.config
    parts = [f"{c.output} within its limit" for c in cfg.constraints if c.output != spec.output]
    if cfg.stability is not None and spec.check != "hunting":
        parts.append("the stability criterion, certified")
    return ", ".join(parts) or "none"


def tradeoffs_section(result: CampaignResult, s: ModelSections, writer: Writer) -> list[str]:
    """tradeoff_*.csv, pareto_*.csv/.png of one model."""
    return [line for t in s.tradeoffs for line in _tradeoff(result, s, t, writer)]


def _surface(result: CampaignResult, s: ModelSections, g: TradeoffSurfaces, writer: Writer) -> list[str]:
    a, b = g.spec.variables
    stem = f"surface_{a}_{b}{s.tag}"
    writer.table(g.constrained.to_pandas(), f"{stem}_constrained")
    writer.table(g.unconstrained.to_pandas(), f"{stem}_unconstrained")
    for bd in g.boundaries:
        writer.table(g.constrained.to_pandas().assign(**{bd.label.split(" ")[0]: bd.values.ravel()}),
                     f"{stem}_{bd.label.split(' ')[0].replace(' ', '_')}")
    writer.figure(plot_surfaces(g.constrained, g.unconstrained, f"{s.model}: U over {a} × {b}",
                                boundaries=g.boundaries, marks=g.marks, units=g.units), stem,
                  dpi=result.config.report.dpi)
    cmin, umin = g.constrained.minimum(), g.unconstrained.minimum(inside_only=False)
    md = [f"Objective surface over {g.spec.variables} (others at the {next(iter(g.marks), 'optimum')} design): "
          f"least U on the constrained grid {cmin['U']:.4g} at {cmin[a]:.4g}, {cmin[b]:.4g}; on the grid relaxed "
          f"toward zero {umin['U']:.4g} at {umin[a]:.4g}, {umin[b]:.4g}."]
    for bd in g.boundaries:
        feasible = bd.values >= bd.limit if bd.at_least else bd.values <= bd.limit
        inside = np.where(feasible & g.constrained.inside, g.constrained.values, np.inf)
        best = float(np.min(inside)) if np.isfinite(np.min(inside)) else float("nan")
        md[-1] += (f" {bd.label} ({bd.limit:.4g}) is drawn on the constrained panel; {int(feasible.sum())} of "
                   f"{feasible.size} grid points meet it (least U among them {best:.4g}).")
    if s.recommended is not None:
        rec = s.recommended.U
        if g.below_certified:
            d = g.below_certified[0]
            md[-1] += (f" **A grid point beats the recommended design (U = {rec:.5g}) and meets every constraint and "
                       f"the whole stability criterion: U = {d['U']:.5g} at {a} = {d[a]:.4g}, {b} = {d[b]:.4g}** — "
                       "the campaign's starts missed it; raise `design.n_starts` (the recommendation is kept from "
                       "the campaigns).")
        elif g.below:
            md[-1] += (f" {len(g.below)} grid point(s) with U below the recommended design's {rec:.5g} meet the drawn "
                       "boundaries, but none of them meets the whole stability criterion (certified decay rate and "
                       "damping ratio at every speed): the recommendation stands.")
        else:
            md[-1] += f" No grid point meeting the drawn boundaries has U below the recommended design's {rec:.5g}."
    return md + ["", f"![surfaces]({stem}.png)", ""]


def surfaces_section(result: CampaignResult, s: ModelSections, writer: Writer) -> list[str]:
    """surface_*_constrained/unconstrained.csv and the surface figure of one model."""
    return [line for g in s.surfaces for line in _surface(result, s, g, writer)]


def _value(x: object, digits: int = 5) -> str:
    return "" if x is None or (isinstance(x, float) and not np.isfinite(x)) else f"{x:.{digits}g}"


def recommended_section(result: CampaignResult, writer: Writer) -> list[str]:
    """recommended.csv (one row per model: variables, element values, U, critical speeds, constraint peaks) and
    the summary's first section: the recommended design beside the existing one and the unconstrained optimum."""
    rows = [s.recommended.row() for s in result.sections if s.recommended is not None]
    if rows:
        writer.table(pd.DataFrame(rows), "recommended")
    cfg = result.config
    names = [v.name for v in cfg.design.variables]
    md: list[str] = []
    for s in result.sections:
        rec, ref = s.recommended, s.unconstrained
        md += [f"## Recommended design: {s.model}", ""]
        if rec is None:
            md += ["**No recommended design**: no optimum of the constrained problem passes every check and "
                   "constraint (see `optima.csv`).", ""]
            continue
        table: list[tuple[str, str, str, str]] = []

        def add(label, ex, r, u, table=table):
            table.append((label, *(v if isinstance(v, str) else _value(v) for v in (ex, r, u))))

        ex_values = result.named.get(s.model, {})
        for n in names:
            add(n, ex_values.get(n), rec.values[n], None if ref is None else ref["values"][n])
        add(f"U: peak {cfg.objective.output} (certified)", rec.existing_U, rec.U, None if ref is None else ref["U"])
        add("reduction factor against existing", 1.0 if rec.existing_U else None,
            rec.existing_U / rec.U if rec.existing_U else None,
            rec.existing_U / ref["U"] if rec.existing_U and ref is not None else None)
        for name, payload in rec.checks.items():
            for key, value in payload.items():
                if isinstance(value, bool):
                    continue
                ex_check = result.existing_checks.get(s.model, {}).get(name, {})
                ref_value = None if ref is None else ref["checks"][name].payload().get(key)
                add(key, ex_check.get(key), value, ref_value)
        for c in rec.constraints:
            ref_peak = None if ref is None else next(
                r["peak"] for r in ref["constraints"] if r["output"] == c["output"])
            add(f"{c['output']} peak (limit {c['limit']:.4g})", None, c["peak"], ref_peak)
        columns = pd.DataFrame(table, columns=["quantity", "existing", "recommended", "unconstrained optimum"])
        verdict = ", ".join(f"{k} {'yes' if v else 'NO'}" for n, p in rec.checks.items()
                            for k, v in p.items() if isinstance(v, bool))
        md += [f"The best distinct optimum of the {rec.source['problem']} problem ({rec.source['objective']} "
               f"objective, {rec.source['method']}, start {rec.source['start_id']}) that passes every check "
               f"({verdict}) and meets every constraint; written to `recommended.csv` (element values in SI):", "",
               markdown_table(columns), ""]
        if ref is not None:
            failing = [f"{n}: {k}" for n, r in ref["checks"].items() for k, v in r.flags.items() if not v]
            note = ("it fails the check(s) " + ", ".join(f"{f} (is false)" for f in failing)
                    + " — shown for comparison only, not recommendable"
                    if failing else "it passes every check")
            md += [f"The unconstrained optimum (the objective alone): U = {_value(ref['U'])}; {note}.", ""]
    return md


MODEL_SECTIONS = [before_after_section, tradeoffs_section, surfaces_section]
"""The sections of each model, in order (after the comparison)."""


def report(result: CampaignResult, writer: Writer) -> str:
    """Write every table and figure; the summary markdown (the recommended design first)."""
    head = comparison_section(result, writer)
    recommended = recommended_section(result, writer)
    extra: list[str] = []
    for s in result.sections:
        if s.best is None:
            extra += [f"No successful {s.objective} optimum for `{s.model}`: no before/after report.", ""]
            continue
        for section in MODEL_SECTIONS:
            extra += section(result, s, writer)
    return "\n".join(head[:4] + recommended + head[4:]) + "\n".join(extra)
