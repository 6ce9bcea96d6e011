"""The config of the ``campaign`` kind: models, design variables, objective, constraints, methods × objectives,
starts, checks, report, trade-offs and surfaces.  Everything a run would reject is rejected on validation
(``railopt validate`` = ``run``); method names are those of the design registry.  The specs shared with other
kinds (variables, objective, constraints, stability, ...) live in :mod:`railopt.studies.specs`; data only, the
adapter's targets are made from them by :mod:`railopt.studies.adapter`."""

from __future__ import annotations

from dataclasses import replace
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from railopt.studies.catalog import ModelSetup, ModelsStudy, PositiveInterval, require_unique
from railopt.studies.config import FiniteModel, MethodName, StrictModel
from railopt.studies.specs import (
    CampaignSettings,
    ConstraintSpec,
    ObjectiveSpec,
    OutputSpec,
    SolverOptions,
    SpectrumSpec,
    StabilitySpec,
    VariableSpec,
)

__all__ = [
    "CampaignDesign",
    "CampaignSettings",
    "CampaignStudyConfig",
    "ConstraintSpec",
    "ObjectiveSpec",
    "OutputSpec",
    "ReportSpec",
    "SolverOptions",
    "SpectrumSpec",
    "StabilitySpec",
    "SurfaceSpec",
    "TradeoffSpec",
    "VariableSpec",
]


class CampaignDesign(CampaignSettings):
    """``[design]``: variables, the methods × objectives matrix, starts, solver options."""

    variables: list[VariableSpec] = Field(min_length=1)
    methods: list[MethodName] = Field(default=["slsqp"], min_length=1)
    objectives: list[Literal["thesis", "exact", "rms"]] = Field(
        default=["exact"], min_length=1,
        description="thesis: maxima (4.71)-(4.73); exact: certified band maximum; rms: RMS per metre under "
                    "[objective.spectrum] at the model's speed")
    problems: list[Literal["constrained", "unconstrained"]] = Field(
        default=["constrained"], min_length=1,
        description="constrained: subject to [[constraints]] and [stability]; unconstrained: the objective alone")
    constrained_methods: list[MethodName] | None = Field(
        None, description="methods of the constrained problem when both problems run (default: methods)")
    constrained_objectives: list[Literal["thesis", "exact", "rms"]] | None = Field(
        None, description="objectives of the constrained problem when both problems run (default: objectives)")

    def plan(self, problem: str) -> list[tuple[str, str]]:
        """(objective, method) pairs of one problem."""
        constrained = problem == "constrained" and len(self.problems) > 1
        objectives = (self.constrained_objectives if constrained else None) or self.objectives
        methods = (self.constrained_methods if constrained else None) or self.methods
        return [(o, m) for o in objectives for m in methods]
    start_from: list[str] = Field(default_factory=list, description="named designs of each model used as starts")
    points: list[dict[str, float]] = Field(default_factory=list, description="explicit starts {variable: value}")
    checks: list[str] = Field(default_factory=lambda: ["spectral_abscissa"], description="checks of each optimum")
    method: MethodName = "slsqp"  # set per campaign from `methods`, never by the config

    @field_validator("method")  # runs only for a value written in the config (defaults are not validated)
    @classmethod
    def _no_single_method(cls, v: str) -> str:
        raise ValueError(f"this kind runs every entry of `methods`; write methods = [{v!r}] instead")

    @field_validator("methods", "objectives", "problems")
    @classmethod
    def _unique(cls, v: list[str]) -> list[str]:
        if len(set(v)) != len(v):
            raise ValueError(f"entries must be unique, got {v}")
        return v


class ReportSpec(StrictModel):
    """``[report]``: the designs compared in the tables and figures, FRF points, figure resolution."""
    compare: list[str] = Field(default_factory=list, description="named designs reported beside the optima")
    before: str | None = Field(None, description="a named design reported before/after against the best optimum")
    outputs: list[str] = Field(default_factory=list, description="outputs shown before/after (default: objective)")
    inch_outputs: list[str] = Field(default_factory=list, description="outputs also reported in inches (m → in)")
    locus_speeds_m_s: PositiveInterval | None = Field(None, description="root locus before/after over speed, m/s")
    published: dict[str, tuple[float, float]] = Field(
        default_factory=dict, description="output -> published (before, after) peaks, in inches for inch_outputs")
    frf_points: int = Field(800, ge=50, le=20000)
    dpi: int = Field(110, ge=50, le=300)


class TradeoffSpec(FiniteModel):
    """One constraint sweep: a constraint output (g = its f_k ≤ ε), the ``hunting`` check (the constrained
    problem with its stability rows up to each required speed ε, m/s, and the critical speed confirmed),
    ``damping`` (the constrained problem with every vehicle mode at least ε damped, ζ_min = ε, up to the required
    speed: what each per cent of damping costs in U), or another check (value ≥ ε, derivative-free)."""

    name: str = Field(pattern=r"^[A-Za-z0-9_\-]+$")
    output: str | None = None
    check: str | None = None
    epsilons: list[float] = Field(min_length=2)
    method: MethodName = "slsqp"
    n_starts: int = Field(4, ge=1, le=1000, strict=True)
    exact: bool = True

    @field_validator("epsilons")
    @classmethod
    def _positive(cls, v: list[float]) -> list[float]:
        bad = [e for e in v if not e > 0]
        if bad:
            raise ValueError(f"every target must be > 0 (an output limit, or a speed in m/s), got {bad}")
        return v

    @model_validator(mode="after")
    def _one(self) -> TradeoffSpec:
        if (self.output is None) == (self.check is None):
            raise ValueError(f"tradeoffs.{self.name}: give exactly one of output or check")
        if self.check not in (None, "hunting", "damping") and self.method != "cobyla":
            raise ValueError(f"tradeoffs.{self.name}.method: a check is not differentiable; use method = 'cobyla'")
        return self


class SurfaceSpec(FiniteModel):
    """U over two design variables (the others at the optimum); ``relax`` scales the lower bounds of the
    unconstrained grid toward zero."""

    variables: tuple[str, str]
    points: int = Field(21, ge=3, le=201, strict=True)
    relax: float = Field(0.01, gt=0, lt=1)


class CampaignStudyConfig(ModelsStudy):
    """A ``campaign`` study file: models, objective, design variables and problems, methods, stability
    and output constraints, trade-offs, surfaces and the report (every key in docs/config-reference.md)."""
    KIND: ClassVar[str] = "campaign"
    objective: ObjectiveSpec
    constraints: list[ConstraintSpec] = Field(default_factory=list)
    stability: StabilitySpec | None = None
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
            _check_setup(self, ref.setup(where), where)
        return self

    def setups(self) -> dict[str, ModelSetup]:
        """The built model of each ``[[models]]`` entry by label: those built (and checked) on validation
        (each entry keeps its model, :meth:`ModelRef.setup`), the ``hunting`` check stating the ``[stability]``
        criterion of the study (σ_min, ζ_min, the lowest and the required speed), as the constraint rows do."""
        key = "criterion " + ("none" if self.stability is None else self.stability.model_dump_json())
        return {m.label: m.built(key, lambda m=m, i=i: self._with_criterion(m.setup(f"models[{i}]")))
                for i, m in enumerate(self.models)}

    def _with_criterion(self, setup: ModelSetup) -> ModelSetup:
        check = setup.checks.get("hunting")
        if self.stability is None or check is None or not hasattr(check, "with_criterion"):
            return setup
        spec = self.stability
        lowest = spec.lowest_speed_m_s or spec.required(setup) / spec.speeds
        stated = check.with_criterion(sigma_min=spec.sigma_min, zeta_min=spec.zeta_min, lowest_speed=lowest,
                                      max_speed=spec.required(setup))
        return replace(setup, checks={**setup.checks, "hunting": stated})


def _check_setup(cfg: CampaignStudyConfig, setup: ModelSetup, where: str) -> None:
    names = [v.name for v in cfg.design.variables]
    bad = [n for n in names if n not in setup.designable]
    if bad:
        raise ValueError(f"design.variables: {bad} are not parameters of {where}; choose from {list(setup.designable)}")
    setup.parameter_map.check_variables(cfg.design.variables)  # stiffness, damping, mass, inertia ≥ 0
    outputs = setup.family.output_names
    specs = [("objective", cfg.objective)] + [(f"constraints[{i}]", c) for i, c in enumerate(cfg.constraints)]
    for field, spec in specs:
        if spec.output is not None and spec.output not in outputs:
            raise ValueError(f"{field}.output: unknown output {spec.output!r} of {where}; outputs are {list(outputs)}")
    _check_rms(cfg, setup, where)
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
        needed = "hunting" if t.check == "damping" else t.check
        if needed is not None and needed not in setup.checks:
            raise ValueError(f"tradeoffs.{t.name}.check: {where} has no check {needed!r}")
        if t.check in ("hunting", "damping") and not setup.stability:
            raise ValueError(f"tradeoffs.{t.name}.check: {where} has no stability family to sweep against")
    for i, c in enumerate(cfg.constraints):
        if c.clearance is not None and c.clearance not in setup.limits:
            raise ValueError(f"constraints[{i}].clearance: {where} has no clearance {c.clearance!r}; it has "
                             f"{sorted(setup.limits)} (the vehicle file's [clearances])")
    if cfg.stability is not None:
        if not setup.stability:
            raise ValueError(f"stability: {where} has no forward speed (no stability family to constrain)")
        bad = [t for t in cfg.stability.tracks if t not in setup.stability]
        if bad:
            raise ValueError(f"stability.tracks: {bad} are not tracks of {where}; it has {sorted(setup.stability)}")
        if cfg.stability.required(setup) is None:
            raise ValueError(f"stability.required_speed_m_s: {where} has no maximum operating speed; give one")
    for sp in cfg.surfaces:
        bad = [v for v in sp.variables if v not in names]
        if bad or sp.variables[0] == sp.variables[1]:
            raise ValueError(f"surfaces.variables: need two different design variables of {names}, got {sp.variables}")
    if cfg.report.locus_speeds_m_s is not None and not setup.stability:
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
    # the objective must have a response over its band at the model's own design (e.g. not unbounded at 0 Hz)
    if "rms" not in cfg.design.objectives or len(cfg.design.objectives) > 1:
        output = cfg.objective.output or setup.family.output_names[0]
        try:
            setup.family.at().response_maxima(band_hz=cfg.objective.band_hz, exact=False, output=output)
        except ValueError as exc:
            raise ValueError(f"objective.band_hz: {where}: {exc}") from None


def _check_rms(cfg: CampaignStudyConfig, setup: ModelSetup, where: str) -> None:
    """The ``rms`` objective needs a spectrum, a model with a forward speed forced per rail irregularity
    (vehicle_forced: ``options.speed_m_s``, ``options.input.amplitude_m``), and a band inside the spectrum's
    validity at that speed."""
    wanted = set(cfg.design.objectives) | set(cfg.design.constrained_objectives or [])
    if "rms" not in wanted:
        return
    if cfg.objective.spectrum is None:
        raise ValueError("objective.spectrum: the rms objective needs a track spectrum ([objective.spectrum] with "
                         "standard = 'fra' | 'erri_b176' | 'table')")
    if setup.family.speed is None or setup.input_amplitude_m is None:
        raise ValueError(f"design.objectives: 'rms' needs a model running at a forward speed over a rail "
                         f"irregularity (vehicle_forced: options.speed_m_s); {where} has no speed "
                         f"({setup.description})")
    if not cfg.objective.band_hz[0] > 0:
        raise ValueError(f"objective.band_hz: the rms objective needs a band above 0 Hz, got {cfg.objective.band_hz}")
    from railopt.models.random_response import _check_spectrum_band

    try:
        _check_spectrum_band(cfg.objective.spectrum.spectrum(), setup.family.speed, tuple(cfg.objective.band_hz))
    except ValueError as exc:
        raise ValueError(f"objective.{exc} ({where})") from None
