"""Selection of the recommended design of the ``campaign`` kind: the best distinct optimum that passes every check
and meets every constraint (certified), the best unconstrained optimum beside it, and the active bounds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from railopt.studies.catalog import ModelSetup
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import _constraint_peaks, _p, design_peak

__all__ = ["Recommended"]


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


def _active_bounds(cfg: CampaignStudyConfig, after: dict[str, float]) -> list[str]:
    out = []
    for v in cfg.design.variables:
        width = v.upper - v.lower
        if min(abs(after[v.name] - v.lower), abs(after[v.name] - v.upper)) <= 1e-6 * width:
            side = "lower" if abs(after[v.name] - v.lower) <= 1e-6 * width else "upper"
            out.append(f"{v.name} at its {side} bound")
    return out
