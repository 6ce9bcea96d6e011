"""Problems of the ``campaign`` kind: the minimax problem of one model × objective × problem (targets made by
:mod:`railopt.studies.adapter` from the config's specs), the design's parameters, the certified peak and the
measure of each objective at a design (:data:`MEASURES`), the starts, and the problems and quantities of the
trade-off sweeps and surfaces."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from railopt.design import MinimaxProblem
from railopt.studies.adapter import (
    ResponseTarget,
    RMSTarget,
    minimax_problem,
    objective_value,
    response_target,
    rms_target,
    stability_target,
)
from railopt.studies.catalog import Check, ModelSetup
from railopt.studies.kinds.campaign.config import (  # campaign_label: the config checks the stores' names too
    CampaignStudyConfig,
    ConstraintSpec,
    StabilitySpec,
    TradeoffSpec,
    campaign_label,
)

__all__ = ["MEASURES", "FeasibleDesign", "campaign_label", "campaign_problem", "design_peak", "design_value",
           "measure_label", "measure_target", "reported_measures", "section_objective", "study_measures"]

MEASURES: dict[str, str] = {"thesis": "peak", "exact": "peak", "rms": "rms"}
"""What each objective kind minimises, as the measure a design is judged by: ``peak``, the certified band maximum
of |H| under the sinusoid (the thesis objective is judged by the maximum it approximates), or ``rms``, the RMS per
metre of irregularity under ``[objective.spectrum]``.  A campaign's headline, before/after and tables are in the
measure of the objective it minimised; the other measure is a side column."""


def campaign_problem(cfg: CampaignStudyConfig, setup: ModelSetup, objective: str, problem: str = "constrained",
                     required_speed: float | None = None, limits: dict[int, float] | None = None) -> MinimaxProblem:
    """The minimax problem of one model, objective kind ("thesis", "exact" or "rms": the RMS per metre under
    ``[objective.spectrum]``) and problem: "constrained" (the config's ``[[constraints]]`` and ``[stability]``) or
    "unconstrained" (the objective alone).  A sweep changes the required speed of the stability rows
    (``required_speed``, m/s) or a constraint's limit (``limits``)."""
    exact = objective == "exact"
    variables = [v.variable() for v in cfg.design.variables]
    target = rms_target(cfg.objective, setup) if objective == "rms" else response_target(cfg.objective, setup, exact)
    if problem == "unconstrained":
        return minimax_problem(setup, variables, target)
    constraints = [response_target(c, setup, c.exact) for c in cfg.constraints]
    values = [c.limit_value(setup) for c in cfg.constraints]
    for i, value in (limits or {}).items():
        values[i] = value
    stability = None if cfg.stability is None else stability_target(cfg.stability, setup, required_speed)
    return minimax_problem(setup, variables, target, constraints, values, stability)


def _p(cfg: CampaignStudyConfig, setup: ModelSetup, values: dict[str, float]) -> np.ndarray:
    names = [v.name for v in cfg.design.variables]
    return setup.parameters(names, np.array([values[n] for n in names]))[0]


def design_peak(cfg: CampaignStudyConfig, setup: ModelSetup, values: dict[str, float]) -> float:
    """Certified band maximum of the objective output at a design {variable: value}."""
    target = response_target(cfg.objective, setup, exact=True)
    return setup.family.at(_p(cfg, setup, values)).peak(band_rad_s=target.band, exact=True, output=target.output)


def measure_target(cfg: CampaignStudyConfig, setup: ModelSetup, measure: str) -> ResponseTarget | RMSTarget:
    """The adapter's target of a measure (a key's value of :data:`MEASURES`): the certified band maximum of the
    objective output, or its RMS per metre under the spectrum."""
    if measure == "rms":
        return rms_target(cfg.objective, setup)
    if measure == "peak":
        return response_target(cfg.objective, setup, exact=True)
    raise ValueError(f"measure: unknown measure {measure!r}; measures are {sorted(set(MEASURES.values()))}")


def design_value(cfg: CampaignStudyConfig, setup: ModelSetup, measure: str, values: dict[str, float]
                 ) -> tuple[float, str]:
    """A design {variable: value} in ``measure`` (output units; an RMS per metre), and ``""`` — or ``inf`` and why
    the measure does not exist there (an unstable design, an undamped mode in the band):
    :func:`railopt.studies.adapter.objective_value`."""
    return objective_value(setup.family.at(_p(cfg, setup, values)), measure_target(cfg, setup, measure))


def measure_label(cfg: CampaignStudyConfig, setup: ModelSetup, measure: str) -> str:
    """The measure in words, with its unit: ``"RMS of cab.lateral under erri_b176 low alignment at 25 m/s,
    0.5–15 Hz (m/s²)"`` or ``"peak |cab_acceleration| over 0–3 Hz, certified (m/s² per 6.35 mm ... irregularity)"``."""
    output = cfg.objective.output or setup.family.output_names[0]
    band = f"{cfg.objective.band_hz[0]:g}–{cfg.objective.band_hz[1]:g} Hz"
    unit = setup.units.get(output, "")
    if measure == "rms":
        sp = cfg.objective.spectrum
        named = sp.path if sp.standard == "table" else " ".join(
            str(v) for v in (sp.standard, f"class {sp.track_class}" if sp.track_class else sp.level, sp.component) if v)
        return f"RMS of {output} under {named} at {setup.family.speed:g} m/s, {band}" + (f" ({unit})" if unit else "")
    per = " ".join(p for p in (unit, f"per {setup.input_label}" if setup.input_label else "") if p)
    return f"peak |{output}| over {band}, certified" + (f" ({per})" if per else "")


def study_measures(cfg: CampaignStudyConfig, problem: str | None = None) -> list[str]:
    """The measures (:data:`MEASURES`) of ``problem``'s objectives (of every problem's when None), in the order the
    objectives are first listed: the first of the recommended problem's is the study's headline measure."""
    problems = cfg.design.problems if problem is None else [problem]
    return list(dict.fromkeys(MEASURES[o] for prob in problems for o, _ in cfg.design.plan(prob)))


def reported_measures(cfg: CampaignStudyConfig) -> list[str]:
    """The measures a design is reported in: the study's (:func:`study_measures`) and always the certified peak (a
    side column of an ``rms`` study; the RMS needs the spectrum and speed only an ``rms`` study has)."""
    return list(dict.fromkeys([*study_measures(cfg), "peak"]))


def section_objective(cfg: CampaignStudyConfig, measure: str | None = None) -> str:
    """The objective kind whose problem the model sections (before/after, trade-offs, surfaces) solve: of
    ``measure``'s objectives (all of them when None) ``exact`` if the study has it, else the first of the study's."""
    planned = [o for o in dict.fromkeys([*cfg.design.objectives, *(cfg.design.constrained_objectives or [])])
               if measure is None or MEASURES[o] == measure]
    return "exact" if "exact" in planned else planned[0]


def _starts(cfg: CampaignStudyConfig, setup: ModelSetup) -> list[list[float]] | None:
    names = [v.name for v in cfg.design.variables]
    points = [[setup.named_designs[nm][n] for n in names] for nm in cfg.design.start_from]
    points += [[p[n] for n in names] for p in cfg.design.points]
    return points or None


def _constraint_peaks(cfg: CampaignStudyConfig, setup: ModelSetup, p: np.ndarray) -> list[dict]:
    system = setup.family.at(p)
    return [{"output": c.output, "limit": c.limit_value(setup),
             "peak": system.peak(band_hz=c.band_hz, exact=True, output=c.output)} for c in cfg.constraints]


# ---------------------------------------------------------------------------------------- trade-off sweeps and surfaces
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
        elif spec.check == "damping":
            base = cfg.stability or StabilitySpec()
            damped = cfg.model_copy(update={"stability": base.model_copy(update={"zeta_min": float(e)})})
            problem = campaign_problem(damped, setup, objective, "constrained")
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
        check = self.setup.checks["hunting"] if self.hunting else None
        out = [] if check is None else [check.critical_speed(p) if hasattr(check, "critical_speed") else check(p).value]
        return np.array(out + [c["peak"] for c in _constraint_peaks(self.cfg, self.setup, p)])


@dataclass(frozen=True)
class FeasibleDesign:
    """Whether a design x meets every constraint of the constrained problem but the one ``spec`` trades: each other
    ``[[constraints]]`` output within its limit (certified peak, to 1e-9 of the limit) and, unless the critical
    speed is the traded quantity, the ``[stability]`` criterion certified by the hunting check (``stable``).  A
    trade-off front holds only such designs.  ``spec`` None: every constraint, the whole criterion (a design the
    study could recommend)."""

    cfg: CampaignStudyConfig
    setup: ModelSetup
    spec: TradeoffSpec | None

    def __call__(self, x: np.ndarray) -> bool:
        names = [v.name for v in self.cfg.design.variables]
        p, _ = self.setup.parameters(names, np.asarray(x, dtype=float))
        traded = None if self.spec is None else self.spec.output
        kind = None if self.spec is None else self.spec.check
        for c in _constraint_peaks(self.cfg, self.setup, p):
            if c["output"] != traded and not c["peak"] <= c["limit"] * (1 + 1e-9):
                return False
        if self.cfg.stability is not None and kind != "hunting" and "hunting" in self.setup.checks:
            check = self.setup.checks["hunting"]
            if kind == "damping":  # the damping ratio is the traded quantity: the rest of the criterion
                check = replace(check, zeta_min=0.0)
            return bool(check(p).flags["stable"])
        return True


def _quantity(cfg: CampaignStudyConfig, setup: ModelSetup, spec: TradeoffSpec):
    names = [v.name for v in cfg.design.variables]

    def value(x: np.ndarray) -> float:
        p, _ = setup.parameters(names, x)
        if spec.output is not None:
            return setup.family.at(p).peak(band_hz=cfg.objective.band_hz, exact=spec.exact, output=spec.output)
        if spec.check == "damping":  # the least damping ratio over the tracks, up to the required speed
            data = setup.checks["hunting"](p).data
            return min(v for k, v in data.items() if k.startswith("least_damping_") and not k.endswith("_m_s"))
        return setup.checks[spec.check](p).value

    return value
