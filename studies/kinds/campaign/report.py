"""Report of the ``campaign`` kind: tables, figures and the summary, as a list of section builders.

Each builder takes the :class:`~railopt.studies.kinds.campaign.run.CampaignResult` (or one model's sections)
and the writer, writes its tables and figures, and returns its markdown lines: the comparison (every
campaign), then per model the before/after (Figs 4.13–4.17), the trade-offs and the surfaces (Fig 4.18).
"""

from __future__ import annotations

import pandas as pd

from railopt.studies.kinds.campaign.run import BeforeAfter, CampaignResult, ModelSections
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

__all__ = ["report"]


def _main_columns(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "objective", "method", *names, "U_objective", "true_peak", "objective_underestimate",
            "converged", "starts", "distinct_optima", "evaluations", "wall_time_s", "all_optima_pass_checks"]
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
        fig = plot_before_after(f_hz, before, after, f"{model}: {o} before and after optimisation", f"|{o}| ({unit})")
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
    writer.figure(plot_tradeoff(t.table, q, f"{s.model}: U against {q} ({spec.name})"), f"pareto_{stem}",
                  dpi=result.config.report.dpi)
    md = [f"Trade-off `{spec.name}`: {len(t.front)} non-dominated designs among {len(t.table)} distinct designs "
          f"(ε-sweep optima and every start); `pareto_{stem}.csv`:", "",
          markdown_table(t.front[["source", "U", q, *names]].head(12), digits=5), ""]
    if t.flagged:
        need = t.after_check.get("required_speed_m_s", float("nan"))
        md += [f"**The best optimum is flagged**: its `{spec.check}` value is {t.after_check['value']:.4g} "
               f"against the required {need:.4g}, so it is not a recommendable design."]
        if t.pick is not None:
            pick = t.pick
            md += [f"The best design of this trade-off that meets it: U = {pick['U']:.5g} "
                   f"({100 * (pick['U'] / s.best['true_peak'] - 1):+.1f} % against the unconstrained optimum), "
                   f"{spec.check} = {pick[q]:.4g}; " + ", ".join(f"{n} = {pick[n]:.4g}" for n in names) + ".", ""]
    return md


def tradeoffs_section(result: CampaignResult, s: ModelSections, writer: Writer) -> list[str]:
    """tradeoff_*.csv, pareto_*.csv/.png of one model."""
    return [line for t in s.tradeoffs for line in _tradeoff(result, s, t, writer)]


def _surface(result: CampaignResult, s: ModelSections, g: TradeoffSurfaces, writer: Writer) -> list[str]:
    a, b = g.spec.variables
    stem = f"surface_{a}_{b}{s.tag}"
    writer.table(g.constrained.to_pandas(), f"{stem}_constrained")
    writer.table(g.unconstrained.to_pandas(), f"{stem}_unconstrained")
    writer.figure(plot_surfaces(g.constrained, g.unconstrained, f"{s.model}: U over {a} × {b}"), stem,
                  dpi=result.config.report.dpi)
    cmin, umin = g.constrained.minimum(), g.unconstrained.minimum(inside_only=False)
    return [f"Objective surface over {g.spec.variables} (others at the optimum): least U on the constrained "
            f"grid {cmin['U']:.4g} at {cmin[a]:.4g}, {cmin[b]:.4g}; on the grid relaxed toward zero "
            f"{umin['U']:.4g} at {umin[a]:.4g}, {umin[b]:.4g}.", "", f"![surfaces]({stem}.png)", ""]


def surfaces_section(result: CampaignResult, s: ModelSections, writer: Writer) -> list[str]:
    """surface_*_constrained/unconstrained.csv and the surface figure of one model."""
    return [line for g in s.surfaces for line in _surface(result, s, g, writer)]


MODEL_SECTIONS = [before_after_section, tradeoffs_section, surfaces_section]
"""The sections of each model, in order (after the comparison)."""


def report(result: CampaignResult, writer: Writer) -> str:
    """Write every table and figure; the summary markdown."""
    head = comparison_section(result, writer)
    extra: list[str] = []
    for s in result.sections:
        if s.best is None:
            extra += [f"No successful {s.objective} optimum for `{s.model}`: no before/after report.", ""]
            continue
        for section in MODEL_SECTIONS:
            extra += section(result, s, writer)
    return "\n".join(head) + "\n".join(extra)
