"""Before/after report, stability, trade-offs and surfaces of a campaign study (thesis §4.3.3, Figs 4.13–4.18).

Called by the ``campaign`` kind when its config has ``[report] before``, ``[[tradeoffs]]`` or
``[[surfaces]]``.  The "after" design is the best optimum (lowest certified peak) of the exact objective
(or of the first objective when exact is not run).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from railopt.models.stability import root_locus
from railopt.studies.figures import plot_before_after, plot_root_loci_before_after, plot_surfaces, plot_tradeoff
from railopt.studies.report import markdown_table, write_table
from railopt.studies.tradeoffs import surfaces, tradeoff_table

INCH = 0.0254
HZ = 2 * np.pi


def ride_report(cfg, setups, comparison: pd.DataFrame, tables: dict, context, client) -> tuple[list[str], list[str]]:
    """Files written and markdown lines of the before/after, stability, trade-off and surface sections."""
    if not (cfg.report.before or cfg.tradeoffs or cfg.surfaces):
        return [], []
    from railopt.studies.kinds.campaign import campaign_problem

    names = [v.name for v in cfg.design.variables]
    objective = "exact" if "exact" in cfg.design.objectives else cfg.design.objectives[0]
    files: list[str] = []
    md: list[str] = []
    for model, setup in setups.items():
        rows = comparison[(comparison["model"] == model) & (comparison["objective"] == objective)]
        rows = rows[np.isfinite(rows.get("true_peak", pd.Series(dtype=float)))]
        if rows.empty:
            md += [f"No successful {objective} optimum for `{model}`: no before/after report.", ""]
            continue
        best = rows.sort_values("true_peak").iloc[0]
        after = {n: float(best[n]) for n in names}
        problem = campaign_problem(cfg, setup, objective)
        x_after = np.array([after[n] for n in names])
        band = cfg.objective.target(setup, exact=True).band
        tag = "" if len(setups) == 1 else f"_{model}"
        if cfg.report.before:
            f, m = _before_after(cfg, setup, model, names, after, band, best, tag, context)
            files += f
            md += m
        starts = pd.concat([t for (mm, oo, _), t in tables.items() if mm == model and oo == objective])
        hunting_after = _after_check(cfg, setup, names, after)
        for spec in cfg.tradeoffs:
            target = cfg.objective.target(setup, exact=objective == "exact")
            table = tradeoff_table(problem, setup, target, spec, band, starts, cfg.design.seed, client)
            quantity = spec.output or spec.check
            files += write_table(table, context.outdir, f"tradeoff_{spec.name}{tag}")
            front = table[table["nondominated"]].sort_values("U")
            files += write_table(front, context.outdir, f"pareto_{spec.name}{tag}")
            fig = plot_tradeoff(table, quantity, f"{model}: U against {quantity} ({spec.name})")
            fig.savefig(context.outdir / f"pareto_{spec.name}{tag}.png", dpi=cfg.report.dpi)
            files.append(f"pareto_{spec.name}{tag}.png")
            md += [f"Trade-off `{spec.name}`: {len(front)} non-dominated designs among {len(table)} distinct designs "
                   f"(ε-sweep optima and every start); `pareto_{spec.name}{tag}.csv`:", "",
                   markdown_table(front[["source", "U", quantity, *names]].head(12), digits=5), ""]
            if spec.check is not None and hunting_after is not None and not hunting_after.get("stable", True):
                need = hunting_after.get("required_speed_m_s", np.nan)
                ok = front[front[quantity] > need]
                md += [f"**The best optimum is flagged**: its `{spec.check}` value is {hunting_after['value']:.4g} "
                       f"against the required {need:.4g}, so it is not a recommendable design."]
                if len(ok):
                    pick = ok.sort_values("U").iloc[0]
                    md += [f"The best design of this trade-off that meets it: U = {pick['U']:.5g} "
                           f"({100 * (pick['U'] / best['true_peak'] - 1):+.1f} % against the unconstrained optimum), "
                           f"{spec.check} = {pick[quantity]:.4g}; " + ", ".join(f"{n} = {pick[n]:.4g}" for n in names)
                           + ".", ""]
        for spec in cfg.surfaces:
            constrained, unconstrained = surfaces(problem, spec, x_after, client)
            stem = f"surface_{spec.variables[0]}_{spec.variables[1]}{tag}"
            files += write_table(constrained.to_pandas(), context.outdir, f"{stem}_constrained")
            files += write_table(unconstrained.to_pandas(), context.outdir, f"{stem}_unconstrained")
            title = f"{model}: U over {spec.variables[0]} × {spec.variables[1]}"
            fig = plot_surfaces(constrained, unconstrained, title)
            fig.savefig(context.outdir / f"{stem}.png", dpi=cfg.report.dpi)
            files.append(f"{stem}.png")
            cmin, umin = constrained.minimum(), unconstrained.minimum(inside_only=False)
            md += [f"Objective surface over {spec.variables} (others at the optimum): least U on the constrained "
                   f"grid {cmin['U']:.4g} at {cmin[spec.variables[0]]:.4g}, {cmin[spec.variables[1]]:.4g}; on the "
                   f"grid relaxed toward zero {umin['U']:.4g} at {umin[spec.variables[0]]:.4g}, "
                   f"{umin[spec.variables[1]]:.4g}.", "", f"![surfaces]({stem}.png)", ""]
    return files, md


def _after_check(cfg, setup, names, after) -> dict | None:
    """The first design check at the best optimum (value and payload), or None without checks."""
    if not cfg.design.checks:
        return None
    p, _ = setup.parameters(names, np.array([after[n] for n in names]))
    value, payload = setup.checks[cfg.design.checks[0]](p)
    return {"value": value, **payload}


def _before_after(cfg, setup, model, names, after, band, best, tag, context) -> tuple[list[str], list[str]]:
    before = {n: float(setup.named_designs[cfg.report.before][n]) for n in names}
    p_before, _ = setup.parameters(names, np.array([before[n] for n in names]))
    p_after, _ = setup.parameters(names, np.array([after[n] for n in names]))
    sys_b, sys_a = setup.system.at(p_before), setup.system.at(p_after)
    outputs = cfg.report.outputs or [cfg.objective.target(setup, True).output]
    rows = []
    for o in outputs:
        rb = sys_b.response_maxima(band, exact=True, output=o)
        ra = sys_a.response_maxima(band, exact=True, output=o)
        row = {"output": o, "before": rb.value, "after": ra.value, "reduction_factor": rb.value / ra.value,
               "before_at_hz": rb.argmax_frequency / HZ, "after_at_hz": ra.argmax_frequency / HZ,
               "certified": rb.certified and ra.certified}
        if o in cfg.report.inch_outputs:
            row |= {"before_in": rb.value / INCH, "after_in": ra.value / INCH}  # in, in/s or in/s² by quantity
        if o in cfg.report.published:
            pb, pa = cfg.report.published[o]
            row |= {"published_before": pb, "published_after": pa, "published_factor": pb / pa}
        rows.append(row)
    table = pd.DataFrame(rows)
    files = write_table(table, context.outdir, f"before_after{tag}")
    objective_output = cfg.objective.target(setup, True).output
    thesis = sys_a.response_maxima(band, exact=False, output=objective_output).value
    exact = sys_a.response_maxima(band, exact=True, output=objective_output).value
    space_lo = {v.name: v.lower for v in cfg.design.variables}
    space_hi = {v.name: v.upper for v in cfg.design.variables}
    active = [f"{n} at its {'lower' if abs(after[n] - space_lo[n]) <= 1e-6 * (space_hi[n] - space_lo[n]) else 'upper'}"
              f" bound" for n in names if min(abs(after[n] - space_lo[n]), abs(after[n] - space_hi[n]))
              <= 1e-6 * (space_hi[n] - space_lo[n])]
    md = [f"## {model}: before (`{cfg.report.before}`) and after (best {best['objective']} optimum, "
          f"{best['method']})", "", markdown_table(table, digits=5), "",
          f"Active bounds at the optimum: {', '.join(active) if active else 'none'}. The thesis approximation "
          f"(4.71)–(4.73) reads {thesis:.5g} at this optimum against the certified maximum {exact:.5g} "
          f"({100 * (thesis - exact) / exact:+.2f} %).", ""]
    # FRFs before/after (Figs 4.13–4.16)
    f_hz = np.linspace(band[0] / HZ, band[1] / HZ, cfg.report.frf_points)
    for o in outputs:
        quantity = sys_a.outputs[o].quantity
        suffix = {"displacement": "", "velocity": "/s", "acceleration": "/s²"}[quantity]
        scale, unit = (1 / INCH, f"in{suffix}") if o in cfg.report.inch_outputs else (1.0, "SI units")
        fig = plot_before_after(f_hz, np.abs(sys_b.frf(f_hz * HZ, o)) * scale, np.abs(sys_a.frf(f_hz * HZ, o)) * scale,
                                f"{model}: {o} before and after optimisation", f"|{o}| ({unit})")
        fig.savefig(context.outdir / f"{o}_before_after{tag}.png", dpi=cfg.report.dpi)
        files.append(f"{o}_before_after{tag}.png")
        md += [f"![{o}]({o}_before_after{tag}.png)", ""]
    # stability of before and after (every optimum's checks are in optima.csv)
    stab = []
    for label, p in (("before", p_before), ("after", p_after)):
        for name in cfg.design.checks:
            value, payload = setup.checks[name](p)
            stab.append({"design": label, "check": name, "value": value, **payload})
    if stab:
        stab_table = pd.DataFrame(stab)
        files += write_table(stab_table, context.outdir, f"stability{tag}")
        md += ["Stability before and after (every distinct optimum's checks are in `optima.csv`):", "",
               markdown_table(stab_table, digits=5), ""]
    if cfg.report.locus_speeds_m_s is not None:
        speeds = np.linspace(*cfg.report.locus_speeds_m_s, 80)
        loci = {label: root_locus(setup.speed_model(p), speeds).to_pandas() for label, p in
                (("before", p_before), ("after", p_after))}
        fig = plot_root_loci_before_after(loci, f"{model}: velocity root loci before and after (rigid track)")
        fig.savefig(context.outdir / f"root_locus_before_after{tag}.png", dpi=cfg.report.dpi)
        files.append(f"root_locus_before_after{tag}.png")
        files += write_table(pd.concat([d.assign(design=k) for k, d in loci.items()]), context.outdir,
                             f"root_locus_before_after{tag}")
        md += [f"![root loci](root_locus_before_after{tag}.png)", ""]
    return files, md
