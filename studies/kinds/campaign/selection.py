"""Selection of the recommended design of the ``campaign`` kind: in each measure the study minimised
(:data:`~railopt.studies.kinds.campaign.problems.MEASURES`), the best distinct optimum that passes every check and
meets every constraint (certified), the best unconstrained optimum beside it, and the active bounds."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from railopt.studies.catalog import ModelSetup
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import (
    MEASURES,
    _constraint_peaks,
    _p,
    design_value,
    reported_measures,
    study_measures,
)

__all__ = ["Recommended", "change"]


def change(before: float | None, after: float) -> tuple[float | None, bool | None]:
    """The signed relative change ``(after − before)/before`` (negative: smaller, better for a minimised measure)
    and whether ``after`` is worse (larger) than ``before``.  ``(None, None)`` when ``before`` is None or 0 or
    ``after`` is not finite; ``(None, False)`` when ``before`` is +inf (the measure does not exist there: any
    finite ``after`` is better, by no finite ratio)."""
    if before is None or before == 0 or not math.isfinite(after):
        return None, None
    if math.isinf(before):
        return None, False
    return (after - before) / before, bool(after > before)


@dataclass(frozen=True)
class Recommended:
    """The recommended design of one model in one measure (``peak`` or ``rms``): the best distinct optimum of the
    constrained problem's campaigns of that measure that passes every check (stable to the required speed) and
    meets every constraint.

    ``values`` are the design variables; ``parameters`` the family's parameters they set (element ids, SI);
    ``U`` and ``existing_U`` are in ``measure`` (``existing_U`` inf where the measure does not exist at the
    existing design, ``existing_reason`` says why); ``side`` the other measures of the study at the recommended
    and the existing design, ``{measure: (existing, recommended)}``; ``checks`` the payload of each check
    (critical speeds on each track, least damping, ...); ``constraints`` per constraint: output, certified peak,
    limit; ``others`` the recommended designs in the study's other measures (the first measure is the headline)."""

    model: str
    source: dict[str, object]
    values: dict[str, float]
    parameters: dict[str, float]
    U: float
    existing_U: float | None
    checks: dict[str, dict]
    constraints: list[dict]
    measure: str = "peak"
    existing_reason: str = ""
    side: dict[str, tuple[float | None, float]] | None = None
    others: tuple[Recommended, ...] = ()

    def row(self) -> dict:
        """One row of ``recommended.csv``: the source, the measure, the variables, the element values (SI), U and
        the existing design's U in that measure, the signed change against it (negative: better) and ``worse``,
        the reduction factor existing_U/U, the other measures (``peak_U``, ``rms_U`` and ``existing_…``), every
        check's numbers and every constraint's peak and limit."""
        out: dict = {"model": self.model, **self.source, "measure": self.measure, **self.values}
        out |= {k: v for k, v in self.parameters.items() if k not in self.values}
        relative, worse = change(self.existing_U, self.U)
        out |= {"U": self.U, "existing_U": self.existing_U, "change_vs_existing": relative, "worse": worse,
                "reduction_factor": self.existing_U / self.U if self.existing_U else None}
        if self.existing_reason:
            out["existing_U_reason"] = self.existing_reason
        for measure, (existing, value) in (self.side or {}).items():
            out |= {f"{measure}_U": value, f"existing_{measure}_U": existing}
        for payload in self.checks.values():
            out |= payload
        for c in self.constraints:
            out |= {f"{c['output']}_peak": c["peak"], f"{c['output']}_limit": c["limit"]}
        return out

    def all(self) -> list[Recommended]:
        """This design and those of the other measures, the headline first."""
        return [self, *self.others]


def _recommend(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, optima: dict, flags: dict,
               problem: str = "constrained") -> Recommended | None:
    """The recommended design of ``problem`` in each of its measures (:func:`study_measures`): the headline
    measure's design with the others in ``others``; the first measure that has one heads (None: no measure has)."""
    found = [r for m in study_measures(cfg, problem)
             if (r := _recommend_in(cfg, setup, model, optima, flags, problem, m)) is not None]
    if not found:
        return None
    head, *others = found
    return replace(head, others=tuple(others))


def _recommend_in(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, optima: dict, flags: dict,
                  problem: str, measure: str) -> Recommended | None:
    """The best distinct optimum of ``problem`` over the objectives of ``measure`` and every method that passes
    all its checks and meets every constraint (certified), judged in ``measure``, or None."""
    names = [v.name for v in cfg.design.variables]
    best: tuple[float, dict, tuple] | None = None
    for key, found in optima.items():
        if key[0] != model or key[1] != problem or MEASURES[key[2]] != measure or found.empty:
            continue
        keep = [f for f in flags[key] if f in found.columns]
        passing = found[found[keep].all(axis=1)] if keep else found
        for _, r in passing.iterrows():
            values = {n: float(r[n]) for n in names}
            U, _ = design_value(cfg, setup, measure, values)
            if np.isfinite(U) and (best is None or U < best[0]):
                best = (U, values, (key, int(r["start_id"])))
    if best is None:
        return None
    U, values, ((_, prob, objective, method), start) = best
    p = _p(cfg, setup, values)
    peaks = _constraint_peaks(cfg, setup, p) if problem == "constrained" else []
    if any(c["peak"] > c["limit"] * (1 + 1e-6) for c in peaks):
        return None
    existing = setup.named_designs.get("existing")
    existing_U, reason = design_value(cfg, setup, measure, existing) if existing is not None else (None, "")
    side = {m: (design_value(cfg, setup, m, existing)[0] if existing is not None else None,
                design_value(cfg, setup, m, values)[0])
            for m in reported_measures(cfg) if m != measure}
    designed = {n: setup.parameter_map.aliases.get(n, n) for n in names}
    parameters = {pid: float(p[list(setup.family.parameters).index(pid)]) for pid in designed.values()
                  if pid in setup.family.parameters}
    checks = {name: setup.checks[name](p).payload() for name in cfg.design.checks}
    return Recommended(model, {"problem": prob, "objective": objective, "method": method, "start_id": start},
                       values, parameters, U, existing_U, checks, peaks, measure, reason, side)


def _unconstrained_best(cfg: CampaignStudyConfig, setup: ModelSetup, model: str, tables: dict,
                        measure: str = "peak") -> dict | None:
    """The best unconstrained optimum in ``measure`` whatever its checks say (for comparison beside the
    recommended design): the lowest value in ``measure`` among the best of each unconstrained campaign of an
    objective of that measure (the thesis objective's own value underestimates the peak, so each best is judged
    in the measure, not by its campaign's value); None without such a campaign."""
    names = [v.name for v in cfg.design.variables]
    rows = [t[t["success"]] for (m, prob, objective, _), t in tables.items()
            if m == model and prob == "unconstrained" and MEASURES[objective] == measure]
    candidates = [{n: float(r.sort_values(["value", "start_id"]).iloc[0][n]) for n in names} for r in rows if len(r)]
    if not candidates:
        return None
    judged = [design_value(cfg, setup, measure, values)[0] for values in candidates]
    values = candidates[int(np.argmin(judged))]
    p = _p(cfg, setup, values)
    return {"values": values, "U": min(judged),
            "side": {m: design_value(cfg, setup, m, values)[0] for m in reported_measures(cfg) if m != measure},
            "checks": {name: setup.checks[name](p) for name in cfg.design.checks},
            "constraints": _constraint_peaks(cfg, setup, p)}


def _active_bounds(cfg: CampaignStudyConfig, after: dict[str, float]) -> list[str]:
    out = []
    for v in cfg.design.variables:
        width = v.upper - v.lower
        if min(abs(after[v.name] - v.lower), abs(after[v.name] - v.upper)) <= 1e-6 * width:
            side = "lower" if abs(after[v.name] - v.lower) <= 1e-6 * width else "upper"
            out.append(f"{v.name} at its {side} bound")
    return out
