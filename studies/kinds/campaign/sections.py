"""Report sections of the ``campaign`` kind: the comparison rows, the outcome of every start, the FRF panels at the
optima, the before/after of a named design against the optimum, each model's sections (before/after, trade-offs,
surfaces) in the measure its objective minimised, and the vehicle each model is built from."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from railopt.design.result import FEASIBILITY_TOL
from railopt.models.stability import root_locus
from railopt.models.units import RAD_PER_HZ as HZ
from railopt.models.units import m_to_in
from railopt.studies.adapter import objective_value, response_target, rms_target
from railopt.studies.catalog import ModelSetup
from railopt.studies.catalog.vehicle import model_vehicle_file, vehicle_title
from railopt.studies.catalog.vehicle import model_vehicles as catalog_model_vehicles
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import (
    MEASURES,
    FeasibleDesign,
    _DesignValues,
    _p,
    _quantity,
    _sweep_problems,
    campaign_problem,
    design_peak,
    design_value,
    section_objective,
    study_measures,
)
from railopt.studies.kinds.campaign.selection import Recommended, _active_bounds, _unconstrained_best, change
from railopt.studies.kinds.campaign.tradeoffs import (
    Tradeoff,
    TradeoffSurfaces,
    grid_points_below,
    surfaces,
    tradeoff_table,
)
from railopt.studies.output.records import FrfPanel

__all__ = ["BeforeAfter", "ModelSections", "figure_title", "model_vehicles", "outcome_counts", "start_outcomes"]


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
    measure: str = "peak"  # what U is in these sections: the measure the objective minimised (MEASURES)


# ---------------------------------------------------------------------------------------------- vehicles
def model_vehicles(cfg: CampaignStudyConfig) -> dict[str, dict[str, str]]:
    """The vehicle of each ``[[models]]`` entry by label (:func:`railopt.studies.catalog.vehicle.model_vehicles`)."""
    return catalog_model_vehicles(cfg.models)


def figure_title(cfg: CampaignStudyConfig, model: str, text: str) -> str:
    """A figure title naming the model's vehicle and file (:func:`railopt.studies.catalog.vehicle.vehicle_title`)."""
    return vehicle_title(cfg.models, model, text)


# ---------------------------------------------------------------------------------------------- start outcomes
OUTCOMES: dict[str, str] = {
    "optimum": "converged to a feasible design (success)",
    "objective does not exist": "U = inf where the solve ended: the objective does not exist there (an unstable "
                                "design: no steady-state or stationary random response; an undamped mode in the "
                                "band: an unbounded maximum); a start placed there cannot move",
    "infeasible": "the solve ended outside the constraints (violation above the feasibility tolerance)",
}
"""The outcomes of a start beside the design layer's statuses (a start that ends otherwise is counted under its
status, ``maxeval``, ``failure``, ``error``, ..., with its message as the reason)."""


def start_outcomes(cfg: CampaignStudyConfig, setups: dict[str, ModelSetup], starts: pd.DataFrame) -> pd.DataFrame:
    """``starts`` (the campaigns' starts: ``model``, ``objective``, the variables, ``value``, ``status``,
    ``message``, ``success``, ``constraint_violation``) with ``outcome`` (a key of :data:`OUTCOMES`, or the
    status) and ``reason``: for U = inf, why the objective does not exist at the start's final design (recomputed
    there by :func:`railopt.studies.adapter.objective_value`, "at its start" when it never moved); for an
    infeasible end, the violation; otherwise the solver's message.  Nothing is dropped: every start has a row."""
    names = [v.name for v in cfg.design.variables]
    outcomes, reasons = [], []
    for _, r in starts.iterrows():
        if bool(r["success"]):
            outcome, reason = "optimum", ""
        elif not np.isfinite(float(r["value"])):
            setup = setups[r["model"]]
            values = {n: float(r[n]) for n in names}
            target = (rms_target(cfg.objective, setup) if MEASURES[r["objective"]] == "rms"
                      else response_target(cfg.objective, setup, exact=r["objective"] == "exact"))
            try:
                value, why = objective_value(setup.family.at(_p(cfg, setup, values)), target)
            except Exception:  # noqa: BLE001  (the model fails there: the solver's status and message say how)
                value, why = 0.0, ""
            if np.isfinite(value):  # the design layer's U is inf for another reason (a lost worker, an error)
                outcome, reason = str(r["status"]), str(r["message"])
            else:
                moved = not np.allclose([float(r[n]) for n in names], [float(r[f"x0_{n}"]) for n in names],
                                        rtol=1e-9, atol=0.0)
                outcome, reason = "objective does not exist", why + ("" if moved else " (at its start)")
        elif float(r["constraint_violation"]) > FEASIBILITY_TOL:
            outcome, reason = "infeasible", f"constraint violation {float(r['constraint_violation']):.3g}"
        else:
            outcome, reason = str(r["status"]), str(r["message"])
        outcomes.append(outcome)
        reasons.append(reason)
    return starts.assign(outcome=outcomes, reason=reasons)


def outcome_counts(starts: pd.DataFrame) -> pd.DataFrame:
    """Per campaign (model, problem, objective, method) and outcome: the number of starts and the distinct
    reasons (the first three, with how many more), from :func:`start_outcomes`' table."""
    keys = [k for k in ("model", "problem", "objective", "method") if k in starts.columns]
    rows = []
    for key, group in starts.groupby([*keys, "outcome"], sort=False):
        reasons = list(dict.fromkeys(x for x in group["reason"] if x))
        shown = "; ".join(reasons[:3]) + (f"; and {len(reasons) - 3} more" if len(reasons) > 3 else "")
        rows.append({**dict(zip([*keys, "outcome"], key, strict=True)), "starts": len(group), "reasons": shown})
    return pd.DataFrame(rows, columns=[*keys, "outcome", "starts", "reasons"])


# ---------------------------------------------------------------------------------------------- comparison
def _comparison_row(cfg: CampaignStudyConfig, setup: ModelSetup, key: tuple[str, str, str, str],
                    table: pd.DataFrame, optima: pd.DataFrame, flags: list[str]) -> dict:
    """One row of ``comparison.csv``: the campaign's counts, its best design passing the checks, that design's
    ``U_objective`` (the campaign's own value: the thesis approximation, the certified peak or the RMS), its
    ``true_peak`` (certified) and, in a study with an ``rms`` objective, its ``true_rms``; against each
    ``report.compare`` design: its peak (``<ref>_peak``), its RMS (``<ref>_rms``) and ``change_vs_<ref>``, signed,
    in the campaign's own measure (negative: the best design is better)."""
    names = [v.name for v in cfg.design.variables]
    model, problem, objective, method = key
    measure = MEASURES[objective]
    with_rms = "rms" in study_measures(cfg)
    ok = table[table["success"]]
    row: dict = {"model": model, "problem": problem, "objective": objective, "method": method, "measure": measure,
                 "starts": len(table), "converged": int(table["success"].sum()),
                 "success_rate": float(table["success"].mean()),
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
                "objective_underestimate": (peak - float(best["value"])) / peak if measure == "peak" else np.nan,
                "best_start": int(best["start_id"])}
        if with_rms:
            row["true_rms"] = design_value(cfg, setup, "rms", values)[0]
        own = row["true_rms"] if measure == "rms" else peak
        for ref in cfg.report.compare:
            ref_values = setup.named_designs[ref]
            row[f"{ref}_peak"] = design_peak(cfg, setup, ref_values)
            if with_rms:
                row[f"{ref}_rms"] = design_value(cfg, setup, "rms", ref_values)[0]
            relative = change(row[f"{ref}_{measure}"], own)[0]
            row[f"change_vs_{ref}"] = np.nan if relative is None else relative
            for n in names:
                row[f"{n}_change_vs_{ref}"] = values[n] - ref_values[n]
        row["active_bounds"] = "; ".join(_active_bounds(cfg, values)) or "none"
    return row


def _short(comparison: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    cols = ["model", "problem", "objective", "method", *names, "U_objective", "true_peak", "true_rms", "converged",
            "starts", "distinct_optima"]
    cols += [c for c in comparison.columns if c.startswith("change_vs_")]
    return comparison[[c for c in cols if c in comparison.columns]]


def _frf_panels(cfg: CampaignStudyConfig, setups: dict[str, ModelSetup], comparison: pd.DataFrame) -> list:
    """|H| of the objective output over its band at each campaign's best design and the named designs."""
    panels = []
    f_hz = np.linspace(cfg.objective.band_hz[0], cfg.objective.band_hz[1], cfg.report.frf_points)
    names = [v.name for v in cfg.design.variables]
    for model, setup in setups.items():
        target = response_target(cfg.objective, setup, exact=True)
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
            rms = f"RMS {r['true_rms']:.4g}, " if MEASURES[r["objective"]] == "rms" else ""
            curves.append((f"{label} ({rms}peak {r['true_peak']:.6g})", f_hz,
                           np.abs(setup.family.at(p).frf(frequencies_hz=f_hz, output=target.output)),
                           r["objective"]))
        file = model_vehicle_file(cfg.models, model)  # the description names the vehicle, the file goes beside it
        title = f"{setup.description} ({file})" if file else f"{model}: {setup.description}"
        panels.append(FrfPanel.build(title, setup.axis_label(target.output), curves))
    return panels


# -------------------------------------------------------------------------------------- before/after and model sections
def _check_rows(cfg: CampaignStudyConfig, setup: ModelSetup, designs: dict[str, np.ndarray]) -> pd.DataFrame | None:
    rows = [{"design": label, "check": name, "value": (r := setup.checks[name](p)).value, **r.payload()}
            for label, p in designs.items() for name in cfg.design.checks]
    return pd.DataFrame(rows) if rows else None


def _where(rm) -> str:
    """Where a band maximum lies: "band edge" (the response still rising there) or "resonance"."""
    k = int(np.argmax(rm.values))
    return "band edge" if k >= len(rm.values) - 2 or rm.frequencies[k] in rm.band else "resonance"


def _before_after(cfg: CampaignStudyConfig, setup: ModelSetup, after: dict[str, float],
                  band: tuple[float, float], measure: str = "peak") -> BeforeAfter:
    """Maxima (or RMS), FRFs, checks and (with forward speed) root loci of the named design ``report.before`` and
    the optimum ``after`` (Figs 4.13–4.17).  ``before``/``after`` are in ``measure`` (the certified band maximum,
    or the RMS per metre under the spectrum with the certified maxima as ``peak_…`` side columns, their own
    ``peak_change`` and ``peak_worse`` too), with the signed relative ``change`` (negative: better) and ``worse``
    (after > before) beside the reduction factor."""
    p_before = _p(cfg, setup, setup.named_designs[cfg.report.before])
    p_after = _p(cfg, setup, after)
    sys_b, sys_a = setup.family.at(p_before), setup.family.at(p_after)
    outputs = cfg.report.outputs or [response_target(cfg.objective, setup, True).output]
    rows = []
    for o in outputs:
        rb = sys_b.response_maxima(band_rad_s=band, exact=True, output=o)
        ra = sys_a.response_maxima(band_rad_s=band, exact=True, output=o)
        peaks = {"before": rb.value, "after": ra.value, "before_at_hz": rb.argmax_frequency / HZ,
                 "before_peak_is": _where(rb), "after_at_hz": ra.argmax_frequency / HZ, "after_peak_is": _where(ra),
                 "certified": rb.certified and ra.certified}
        if measure == "rms":
            target = rms_target(cfg.objective.model_copy(update={"output": o}), setup)
            (vb, why_b), (va, why_a) = objective_value(sys_b, target), objective_value(sys_a, target)
            peak_change, peak_worse = change(rb.value, ra.value)
            main, side = {"before": vb, "after": va}, {f"peak_{k}": v for k, v in peaks.items()}
            side |= {"peak_change": peak_change, "peak_worse": peak_worse}
            side |= {k: why for k, why in (("before_reason", why_b), ("after_reason", why_a)) if why}
        else:
            main, side = {"before": rb.value, "after": ra.value}, {k: v for k, v in peaks.items()
                                                                   if k not in ("before", "after")}
        relative, worse = change(main["before"], main["after"])
        row = {"output": o, "measure": measure, **main, "change": relative, "worse": worse,
               "reduction_factor": main["before"] / main["after"], **side}
        if o in cfg.report.inch_outputs:  # in, in/s or in/s² by quantity
            row |= {"before_in": m_to_in(main["before"]), "after_in": m_to_in(main["after"])}
        if o in cfg.report.published:
            pb, pa = cfg.report.published[o]
            row |= {"published_before": pb, "published_after": pa, "published_factor": pb / pa}
        rows.append(row)
    objective_output = response_target(cfg.objective, setup, True).output
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
        loci = {label: pd.concat([root_locus(setup.stability_model(p, track), speeds).to_pandas().assign(track=track)
                                  for track in setup.stability], ignore_index=True)
                for label, p in (("before", p_before), ("after", p_after))}
    thesis = sys_a.response_maxima(band_rad_s=band, exact=False, output=objective_output).value
    return BeforeAfter(pd.DataFrame(rows), thesis,
                       sys_a.response_maxima(band_rad_s=band, exact=True, output=objective_output).value,
                       _active_bounds(cfg, after), frfs,
                       _check_rows(cfg, setup, {"before": p_before, "after": p_after}), loci)


def _model_sections(cfg: CampaignStudyConfig, model: str, setup: ModelSetup, comparison: pd.DataFrame,
                    tables: dict, tag: str, client, recommended: Recommended | None) -> ModelSections:
    """The before/after, trade-off and surface sections of one model, at its recommended design (or, without
    one, its best optimum passing the checks of the exact objective, or of the first objective), in the measure
    of the recommended design (:data:`MEASURES`): the sweeps solve that measure's objective and U is in it."""
    names = [v.name for v in cfg.design.variables]
    objective = section_objective(cfg, recommended.measure if recommended is not None else None)
    measure = MEASURES[objective]
    rows = comparison[(comparison["model"] == model) & (comparison["objective"] == objective)
                      & (comparison["problem"] == cfg.design.problems[0])]
    judged = f"true_{measure}"
    rows = rows[np.isfinite(rows[judged])] if judged in rows.columns else rows.iloc[0:0]
    if rows.empty and recommended is None:
        return ModelSections(model, tag, None, objective, measure=measure)
    best = rows.sort_values(judged).iloc[0] if len(rows) else None
    after = dict(recommended.values) if recommended is not None else {n: float(best[n]) for n in names}
    if best is None or recommended is not None:
        best = pd.Series({**after, judged: recommended.U, **recommended.source})
    band = response_target(cfg.objective, setup, exact=True).band
    before_after = _before_after(cfg, setup, after, band, measure) if cfg.report.before else None
    starts = pd.concat([t.assign(problem=prob) for (m, prob, o, _), t in tables.items() if m == model])
    x_after = np.array([after[n] for n in names])
    tradeoffs = []
    for spec in cfg.tradeoffs:
        required = None
        if spec.check == "hunting":
            required = (cfg.stability.required(setup) if cfg.stability is not None else setup.required_speed)
        elif spec.check == "damping":
            required = cfg.stability.zeta_min if cfg.stability is not None else None
        elif spec.output is not None:
            limits = [c.limit_value(setup) for c in cfg.constraints if c.output == spec.output]
            required = limits[0] if limits else None
        tradeoffs.append(tradeoff_table(
            spec, _sweep_problems(cfg, setup, objective, spec), starts, _quantity(cfg, setup, spec),
            lambda x: design_value(cfg, setup, measure, dict(zip(names, x, strict=True)))[0], cfg.design.seed,
            points=[list(x_after)], client=client, required=required, feasible=FeasibleDesign(cfg, setup, spec),
            criterion=(FeasibleDesign(cfg, setup, None) if spec.check in ("hunting", "damping") else None)))
    reference = _unconstrained_best(cfg, setup, model, tables, measure)
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
    if recommended is not None:  # grid points that beat the recommendation: do they meet everything?
        grids = [grid_points_below(g, after, recommended.U, FeasibleDesign(cfg, setup, None), names) for g in grids]
    return ModelSections(model, tag, best, objective, before_after, tradeoffs, grids, recommended, reference,
                         measure)
