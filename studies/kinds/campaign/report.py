"""Report of the ``campaign`` kind: tables, figures and the summary, as a list of section builders.

Each builder takes the :class:`~railopt.studies.kinds.campaign.run.CampaignResult` (or one model's sections)
and the writer, writes its tables and figures, and returns its markdown lines: the recommended design, the
comparison (every campaign) and every start's outcome, then per model the before/after (Figs 4.13–4.17), the
trade-offs and the surfaces (Fig 4.18).  Headlines, before/after and U columns are in the measure the objective
minimised (the certified peak, or the RMS under the spectrum; the other measure is a named side column); every
table where a vehicle is involved names it (``vehicle``, ``vehicle_file``); an infinite critical speed prints as
"stable over the range (… m/s)" (the range searched; CSVs keep ``inf`` with ``critical_speed_search_m_s``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from railopt.studies.kinds.campaign.config import surface_stem, tradeoff_stem
from railopt.studies.kinds.campaign.problems import MEASURES, measure_label
from railopt.studies.kinds.campaign.run import CampaignResult
from railopt.studies.kinds.campaign.sections import (
    OUTCOMES,
    BeforeAfter,
    ModelSections,
    figure_title,
    model_vehicles,
    outcome_counts,
    start_outcomes,
)
from railopt.studies.kinds.campaign.selection import Recommended, change
from railopt.studies.kinds.campaign.tradeoffs import Tradeoff, TradeoffSurfaces
from railopt.studies.output.figures import (
    plot_before_after,
    plot_frf_panels,
    plot_root_loci_before_after,
    plot_surfaces,
    plot_tradeoff,
)
from railopt.studies.output.markdown import markdown_table, stable_over
from railopt.studies.output.writer import Writer

__all__ = [
    "before_after_section", "comparison_section", "recommended_section", "report", "surfaces_section",
    "tradeoffs_section",
]


# ---------------------------------------------------------------------------------------------- shared pieces
def _search(result: CampaignResult, model: str) -> tuple[float, float] | None:
    """The speed range (m/s) the model's hunting check searches for a critical speed (None without the check)."""
    check = result.config.setups()[model].checks.get("hunting")
    return None if check is None else tuple(check.search)


def _speeds(result: CampaignResult, model: str, columns) -> dict[str, str]:
    """Columns holding critical speeds -> the words their +inf prints as (:func:`stable_over` the range searched)."""
    search = _search(result, model)
    words = {} if search is None else {str(c): stable_over(search) for c in columns
                                       if str(c).startswith(("critical", "linear_critical"))}
    # the nonlinear check's value: inf when no speed of its ramp, from the top down, held a hunting cycle
    words.update({str(c): "no hunting cycle at any ramp speed" for c in columns
                  if str(c) == "lowest_hunting_speed_m_s"})
    return words


def _csv(result: CampaignResult, df: pd.DataFrame, model: str | None = None) -> pd.DataFrame:
    """``df`` as a CSV of the report: the vehicle of each row's model (or of ``model``) as ``vehicle`` and
    ``vehicle_file`` after ``model``, and with critical speeds the range searched (``critical_speed_search_m_s``: an
    ``inf`` there means stable over that range)."""
    vehicles = model_vehicles(result.config)
    models = [model] * len(df) if model is not None else (list(df["model"]) if "model" in df.columns else [])
    out = df.copy()
    if vehicles and models and any(m in vehicles for m in models):
        at = list(out.columns).index("model") + 1 if "model" in out.columns else 0
        for k, key in enumerate(("vehicle", "vehicle_file")):
            out.insert(at + k, key, [vehicles.get(m, {}).get(key, "") for m in models])
    if models and any(str(c).startswith("critical") for c in out.columns):
        ranges = [_search(result, m) for m in models]
        out["critical_speed_search_m_s"] = [f"{r[0]:g}-{r[1]:g}" if r else "" for r in ranges]
    return out


def _vehicle_line(result: CampaignResult, model: str) -> str:
    """"Vehicle: **SD40-2**, file `sd40-2.toml (bundled)`." ("" for a model without a vehicle)."""
    v = model_vehicles(result.config).get(model)
    return f"Vehicle: **{v['vehicle']}**, file `{v['vehicle_file']}`." if v else ""


def _signed(relative: float | None, worse: bool | None) -> str:
    """A signed relative change in words: ``"-55.1 % (better)"``, ``"+67 % (WORSE)"``."""
    if relative is None:
        return "" if worse is None else "better (the existing value does not exist)"
    return f"{100 * relative:+.3g} % ({'WORSE' if worse else 'better' if relative < 0 else 'unchanged'})"


def _main_columns(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "vehicle", "problem", "objective", "method", *names, "U_objective", "true_peak", "true_rms",
            "objective_underestimate", "active_bounds", "converged", "starts", "distinct_optima", "failing_optima",
            "best_failing_U", "evaluations", "wall_time_s"]
    return comparison[[c for c in cols if c in comparison.columns]]


def comparison_section(result: CampaignResult, writer: Writer) -> list[str]:
    """comparison.csv, starts.csv/.parquet (with every start's ``outcome`` and ``reason``), outcomes.csv,
    optima.csv, frf.png and the summary's head."""
    cfg = result.config
    comparison = _csv(result, result.comparison)
    names = [v.name for v in cfg.design.variables]
    starts = start_outcomes(cfg, cfg.setups(), result.starts)
    counts = _csv(result, outcome_counts(starts))
    writer.table(comparison, "comparison")
    writer.table(_csv(result, starts), "starts", parquet=True)
    writer.table(counts, "outcomes")
    writer.table(_csv(result, result.optima), "optima")
    writer.figure(plot_frf_panels(result.frf_panels), "frf", dpi=cfg.report.dpi)
    d = cfg.design
    n_starts = f"{d.n_starts} {d.sampler} starts (seed {d.seed})"
    if d.start_from:
        n_starts += " plus the named designs " + ", ".join(f"`{s}`" for s in d.start_from)
    if d.points:
        n_starts += f" plus {len(d.points)} explicit point(s)"
    vehicles = model_vehicles(cfg)
    lines = [
        f"# {cfg.study.name}",
        "",
        cfg.study.description,
        "",
        f"Variables: {', '.join(f'{v.name} ∈ [{v.lower:g}, {v.upper:g}]' for v in d.variables)}; "
        f"objective: {cfg.objective.output or 'first output'} over {cfg.objective.band_hz[0]:g}–"
        f"{cfg.objective.band_hz[1]:g} Hz; methods {', '.join(d.methods)}; {n_starts}."
        + ("" if not vehicles else " Vehicles: " + "; ".join(
            f"`{m}` is **{v['vehicle']}** (file `{v['vehicle_file']}`)" for m, v in vehicles.items()) + "."),
        "",
        "`thesis` minimises the response maxima (4.71)–(4.73) (|H| at the damped natural frequencies and the",
        "band edges); `exact` minimises the certified band maximum; `rms` minimises the RMS per metre of",
        "irregularity under the track spectrum. `U_objective` is the campaign's own value at its best design (for",
        "`rms` the RMS); `true_peak` is the certified band maximum there (for `rms` a side measure, not minimised)",
        "and `true_rms` its RMS; `objective_underestimate` is how far the thesis or exact value lies below the",
        "certified maximum (not applicable to `rms`).",
        "A campaign's best design is its best distinct optimum that passes every check (`design.checks`); the",
        "optima that fail them are counted in `failing_optima` and the best of them is `best_failing_U`",
        "(never reported as an optimum: `optima.csv` has each with its checks).",
        "",
        markdown_table(_main_columns(comparison, names)),
        "",
    ]
    for ref in cfg.report.compare:
        cols = ["model", "vehicle", "problem", "objective", "method", f"{ref}_peak", f"{ref}_rms", f"change_vs_{ref}"]
        cols += [f"{n}_change_vs_{ref}" for n in names]
        lines += [f"Against `{ref}` (its certified peak and RMS, and the best design's signed change in the "
                  f"campaign's own measure, negative: better; then the differences of the variables):", "",
                  markdown_table(comparison[[c for c in cols if c in comparison.columns]]), ""]
    lost = counts[counts["outcome"] != "optimum"]
    lines += [
        f"Every start by outcome (`outcomes.csv`; each start's `outcome` and `reason` are in `starts.csv`): "
        f"{int(counts.loc[counts['outcome'] == 'optimum', 'starts'].sum())} of {len(starts)} converged to a "
        f"feasible design; {int(lost['starts'].sum())} did not. "
        + " ".join(f"`{k}`: {v}." for k, v in OUTCOMES.items() if k in set(counts["outcome"]) and k != "optimum"),
        "",
        markdown_table(counts),
        "",
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
    setup = cfg.setups()[model]
    dpi = cfg.report.dpi
    writer.table(_csv(result, ba.table, model), f"before_after{tag}")
    worse = ba.table[ba.table["worse"].eq(True)]
    side_worse = ba.table[ba.table["peak_worse"].eq(True)] if "peak_worse" in ba.table.columns else ba.table.iloc[0:0]
    measure = ("the RMS per metre under the spectrum at the model's speed (the certified band maxima are the "
               "`peak_…` side columns)" if s.measure == "rms" else "the certified band maximum")
    md = [f"## {model}: before (`{cfg.report.before}`) and after (best {best['objective']} optimum, "
          f"{best['method']})", "", *([_vehicle_line(result, model), ""] if _vehicle_line(result, model) else []),
          f"`before` and `after` are {measure} of each output; the minimised one is "
          f"{measure_label(cfg, setup, s.measure)}. `change` is signed (negative: better) and `worse` is true "
          "where the optimum is worse than before.", "",
          markdown_table(ba.table, digits=5), ""]
    if len(worse):
        md += ["**Worse after optimisation:** " + ", ".join(
            f"{r['output']}: {_signed(r['change'], True)}" for _, r in worse.iterrows())
               + "; only the objective output was minimised, the others are shown, not optimised.", ""]
    if len(side_worse):
        md += ["**Side measure worse after optimisation:** certified peak of " + ", ".join(
            f"{r['output']}: {_signed(r['peak_change'], True)}" for _, r in side_worse.iterrows())
               + "; the RMS was minimised, not the sinusoid peak.", ""]
    md += [f"Active bounds at the optimum: {', '.join(ba.active) if ba.active else 'none'}. The thesis approximation "
           f"(4.71)–(4.73) reads {ba.thesis:.5g} at this optimum against the certified maximum {ba.exact:.5g} "
           f"({100 * (ba.thesis - ba.exact) / ba.exact:+.2f} %).", ""]
    for o, f_hz, before, after, unit in ba.frfs:
        fig = plot_before_after(f_hz, before, after, figure_title(cfg, model, f"{o} before and after optimisation"),
                                unit)
        name = writer.figure(fig, f"{o}_before_after{tag}", dpi=dpi)
        md += [f"![{o}]({name})", ""]
    if ba.stability is not None:
        writer.table(_csv(result, ba.stability, model), f"stability{tag}")
        texts = _speeds(result, model, ba.stability.columns)
        shown = ba.stability.copy()
        if texts and "check" in shown.columns:  # the hunting check's value is the lowest critical speed
            hunting = (shown["check"] == "hunting") & np.isposinf(shown["value"].astype(float))
            shown["value"] = shown["value"].astype(object).where(~hunting, next(iter(texts.values())))
        md += ["Stability before and after (every distinct optimum's checks are in `optima.csv`):", "",
               markdown_table(shown, digits=5, infinite=texts), ""]
    if ba.loci is not None:
        tracks = " and ".join(dict.fromkeys(t for d in ba.loci.values() for t in d["track"]))
        required = cfg.stability.required(setup) if cfg.stability is not None else setup.required_speed
        fig = plot_root_loci_before_after(
            ba.loci, figure_title(cfg, model, f"velocity root loci before and after ({tracks} track)"),
            required_speed=required)
        name = writer.figure(fig, f"root_locus_before_after{tag}", dpi=dpi)
        writer.table(_csv(result, pd.concat([d.assign(design=k) for k, d in ba.loci.items()]), model),
                     f"root_locus_before_after{tag}")
        md += [f"![root loci]({name})", ""]
    return md


def _tradeoff(result: CampaignResult, s: ModelSections, t: Tradeoff, writer: Writer) -> list[str]:
    names = [v.name for v in result.config.design.variables]
    stem, q, spec = tradeoff_stem(t.spec.name, s.tag), t.quantity, t.spec
    writer.table(_csv(result, t.table, s.model), f"tradeoff_{stem}")
    writer.table(_csv(result, t.front, s.model), f"pareto_{stem}")
    setup = result.config.setups()[s.model]
    u_label = f"U: {measure_label(result.config, setup, s.measure)}"
    writer.figure(plot_tradeoff(t.table, q, figure_title(result.config, s.model, f"U against {q} ({spec.name})"),
                                required=t.required, u_label=u_label,
                                recommended=s.recommended.values if s.recommended is not None else None,
                                targets=spec.epsilons),
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
          f"not are listed in `tradeoff_{stem}.csv` (`feasible` False) and drawn apart; U is the "
          f"{measure_label(result.config, result.config.setups()[s.model], s.measure)}; `pareto_{stem}.csv`:", "",
          markdown_table(t.front[["source", "count", "U", q, *names]].head(12), digits=5,
                         infinite=_speeds(result, s.model, [q])), ""]
    if t.required is not None:
        sense = "≥" if spec.check is not None else "≤"
        if t.pick is not None:
            shown = _speeds(result, s.model, [q]).get(q) if np.isposinf(t.pick[q]) else f"{t.pick[q]:.4g}"
            md += [f"Best design with {q} {sense} {t.required:.4g} that meets every constraint and the whole "
                   f"stability criterion: U = {t.pick['U']:.5g}, {q} = {shown}.", ""]
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
    stem = surface_stem((a, b), s.tag)
    writer.table(_csv(result, g.constrained.to_pandas(), s.model), f"{stem}_constrained")
    writer.table(_csv(result, g.unconstrained.to_pandas(), s.model), f"{stem}_unconstrained")
    for bd in g.boundaries:
        writer.table(_csv(result, g.constrained.to_pandas().assign(**{bd.label.split(" ")[0]: bd.values.ravel()}),
                          s.model), f"{stem}_{bd.label.split(' ')[0].replace(' ', '_')}")
    title = figure_title(result.config, s.model, f"U over {a} × {b}")
    writer.figure(plot_surfaces(g.constrained, g.unconstrained, title,
                                boundaries=g.boundaries, marks=g.marks, units=g.units), stem,
                  dpi=result.config.report.dpi)
    cmin, umin = g.constrained.minimum(), g.unconstrained.minimum(inside_only=False)
    md = [f"Objective surface over {g.spec.variables} (others at the {next(iter(g.marks), 'optimum')} design; U is the "
          f"{measure_label(result.config, result.config.setups()[s.model], s.measure)}): "
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
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return ""
    if isinstance(x, float) and np.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.{digits}g}"


def _design_table(result: CampaignResult, s: ModelSections, rec: Recommended, ref: dict | None) -> pd.DataFrame:
    """The quantity rows of one recommended design beside the existing design and the unconstrained optimum: the
    variables, U in its measure, the signed change against the existing design, the reduction factor, the other
    measures (side rows, not minimised), every check's numbers (an infinite critical speed in words) and every
    constraint's peak."""
    cfg = result.config
    setup = cfg.setups()[s.model]
    names = [v.name for v in cfg.design.variables]
    speeds = _speeds(result, s.model, [k for payload in rec.checks.values() for k in payload])
    table: list[tuple[str, str, str, str]] = []

    def add(label, ex, r, u, key=None):
        def cell(v):
            if isinstance(v, str):
                return v
            if key in speeds and isinstance(v, float) and np.isposinf(v):
                return speeds[key]
            return _value(v)

        table.append((label, cell(ex), cell(r), cell(u)))

    ex_values = result.named.get(s.model, {})
    for n in names:
        add(n, ex_values.get(n), rec.values[n], None if ref is None else ref["values"][n])
    missing = f"does not exist ({rec.existing_reason})" if rec.existing_reason else rec.existing_U
    add(f"U: {measure_label(cfg, setup, rec.measure)}", missing, rec.U, None if ref is None else ref["U"])
    if rec.existing_U is not None:
        add("change against existing (negative: better)", None, _signed(*change(rec.existing_U, rec.U)),
            None if ref is None else _signed(*change(rec.existing_U, ref["U"])))
        add("reduction factor against existing (existing / U)", 1.0, rec.existing_U / rec.U,
            None if ref is None else rec.existing_U / ref["U"])
    for measure, (existing, value) in (rec.side or {}).items():
        unc = None if ref is None else ref["side"].get(measure)
        add(f"side measure, not minimised: {measure_label(cfg, setup, measure)}", existing, value, unc)
        if existing is not None:
            add("… its change against existing", None, _signed(*change(existing, value)),
                None if unc is None else _signed(*change(existing, unc)))
    for name, payload in rec.checks.items():
        for key, value in payload.items():
            if isinstance(value, bool):
                continue
            ex_check = result.existing_checks.get(s.model, {}).get(name, {})
            ref_value = None if ref is None else ref["checks"][name].payload().get(key)
            add(key, ex_check.get(key), value, ref_value, key)
        flags = [k for k, v in payload.items() if isinstance(v, bool)]
        if flags:  # the check's verdict on each design: every flag true

            def passed(p: dict | None, flags: list[str] = flags) -> str | None:
                return None if not p else ("yes" if all(bool(p.get(f)) for f in flags) else "NO")

            ex_check = result.existing_checks.get(s.model, {}).get(name)
            ref_payload = None if ref is None else ref["checks"][name].payload()
            add(f"{name} check passed ({', '.join(flags)})", passed(ex_check), passed(payload), passed(ref_payload))
    for c in rec.constraints:
        ref_peak = None if ref is None else next(
            r["peak"] for r in ref["constraints"] if r["output"] == c["output"])
        add(f"{c['output']} peak (limit {c['limit']:.4g})", None, c["peak"], ref_peak)
    return pd.DataFrame(table, columns=["quantity", "existing", "recommended", "unconstrained optimum"])


def recommended_section(result: CampaignResult, writer: Writer) -> list[str]:
    """recommended.csv (one row per model and measure: the measure, variables, element values, U and the existing
    design's U in it, the signed change, the other measures, critical speeds, constraint peaks) and the summary's
    first section: per model the recommended design in the headline measure (the one its objective minimised)
    beside the existing one and the unconstrained optimum, then in the study's other measure, if any."""
    rows = [r.row() for s in result.sections if s.recommended is not None for r in s.recommended.all()]
    if rows:
        writer.table(_csv(result, pd.DataFrame(rows)), "recommended")
    cfg = result.config
    md: list[str] = []
    for s in result.sections:
        rec = s.recommended
        vehicle = _vehicle_line(result, s.model)
        md += [f"## Recommended design: {s.model}", "", *([vehicle, ""] if vehicle else [])]
        if rec is None:
            md += ["**No recommended design**: no optimum of the constrained problem passes every check and "
                   "constraint (see `optima.csv` and the outcome of every start below).", ""]
            continue
        setup = cfg.setups()[s.model]
        for k, r in enumerate(rec.all()):
            ref = s.unconstrained if k == 0 else None  # the unconstrained optimum is judged in the headline measure
            relative, worse = change(r.existing_U, r.U)
            existing = (f" against the existing design, where it does not exist ({r.existing_reason})"
                        if r.existing_reason else f" against {_value(r.existing_U)} for the existing design"
                        if r.existing_U is not None else " (the model has no existing design to compare)")
            verdict = ", ".join(f"{key} {'yes' if v else 'NO'}" for payload in r.checks.values()
                                for key, v in payload.items() if isinstance(v, bool))
            heading = ("" if k == 0 else f"### In the study's other measure ({r.measure}: the "
                       f"`{'`, `'.join(o for o in dict.fromkeys(cfg.design.objectives) if MEASURES[o] == r.measure)}`"
                       " campaigns)")
            md += ([heading, ""] if heading else []) + [
                f"Minimised: {measure_label(cfg, setup, r.measure)}. **U = {_value(r.U)}{existing}"
                + (f": {_signed(relative, worse)}" if relative is not None else "") + ".**", "",
                f"The best distinct optimum of the {r.source['problem']} problem ({r.source['objective']} "
                f"objective, {r.source['method']}, start {r.source['start_id']}) that passes every check "
                f"({verdict}) and meets every constraint; written to `recommended.csv` (`measure` {r.measure}; "
                "element values in SI):", "",
                markdown_table(_design_table(result, s, r, ref)), ""]
            if ref is not None:
                failing = [f"{n}: {key}" for n, res in ref["checks"].items() for key, v in res.flags.items() if not v]
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
