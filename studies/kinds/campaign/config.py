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
from railopt.studies.config import FileName, FiniteModel, MethodName, StrictModel, not_one_of
from railopt.studies.specs import (
    CampaignSettings,
    ConstraintSpec,
    NonlinearHuntingSpec,
    ObjectiveSpec,
    OutputSpec,
    SolverOptions,
    SpectrumSpec,
    StabilitySpec,
    VariableSpec,
)

__all__ = [
    "FILE_NAME_BYTES",
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
    "campaign_label",
    "model_tag",
    "output_files",
    "surface_stem",
    "tradeoff_stem",
]

FILE_NAME_BYTES = 255
"""The longest file name (bytes, UTF-8) the file systems a study publishes to accept."""


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

    def solver_methods(self) -> list[str]:
        """Every method a campaign of this design runs: ``methods`` and ``constrained_methods``."""
        return list(dict.fromkeys([*self.methods, *(self.constrained_methods or [])]))


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

    name: FileName = Field(pattern=r"^[A-Za-z0-9_\-]+$", description="names its files (tradeoff_<name>.csv, "
                           "pareto_<name>.csv/.png): unique among the trade-offs")
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
        if self.check == "damping" and max(self.epsilons) >= 1:
            raise ValueError(f"epsilons: a 'damping' trade-off's targets are damping ratios below 1, got "
                             f"{max(self.epsilons)}")
        if self.check == "hunting" and max(self.epsilons) >= 1000:
            raise ValueError(f"epsilons: a 'hunting' trade-off's targets are required speeds below 1000 m/s, got "
                             f"{max(self.epsilons)}")
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
    nonlinear_hunting: NonlinearHuntingSpec | None = None

    @model_validator(mode="after")
    def _resolve(self) -> CampaignStudyConfig:
        """Everything a run would reject is rejected here (``railopt validate`` = ``run``)."""
        require_unique("design.variables", [v.name for v in self.design.variables])
        _check_solver_options(self)
        _check_unique_outputs(self)
        for i, ref in enumerate(self.models):
            where = f"models[{i}]"
            _check_setup(self, ref.setup(where), where)
        return self

    def setups(self) -> dict[str, ModelSetup]:
        """The built model of each ``[[models]]`` entry by label: those built (and checked) on validation
        (each entry keeps its model, :meth:`ModelRef.setup`), the ``hunting`` check stating the ``[stability]``
        criterion of the study (σ_min, ζ_min, the lowest and the required speed, every track constrained), as the
        constraint rows do."""
        key = "criterion " + ("none" if self.stability is None else self.stability.model_dump_json()) + (
            "" if self.nonlinear_hunting is None else self.nonlinear_hunting.model_dump_json())
        return {m.label: m.built(key, lambda m=m, i=i: self._with_criterion(m.setup(f"models[{i}]")))
                for i, m in enumerate(self.models)}

    def _with_criterion(self, setup: ModelSetup) -> ModelSetup:
        nonlinear = setup.checks.get("nonlinear_hunting")
        if nonlinear is not None:  # the study's [nonlinear_hunting] settings and required speed
            hunting = setup.checks["hunting"]
            spec = self.nonlinear_hunting or NonlinearHuntingSpec()
            required = self.stability.required(setup) if self.stability is not None else setup.required_speed
            setup = replace(setup, checks={**setup.checks, "nonlinear_hunting": nonlinear.with_analysis(
                spec.analysis(hunting.search), required)})
        if self.stability is None:
            return setup
        spec = self.stability
        added = {t: setup.other_tracks[t] for t in spec.tracks if t not in setup.stability}
        if added:  # a track the model does not check by default: its family joins the rows and the check
            stability = {**setup.stability, **added}
            setup = replace(setup, stability=stability,
                            other_tracks={t: f for t, f in setup.other_tracks.items() if t not in added})
        check = setup.checks.get("hunting")
        if check is None or not hasattr(check, "with_criterion"):
            return setup
        lowest = spec.lowest_speed_m_s or spec.required(setup) / spec.speeds
        stated = check.with_criterion(sigma_min=spec.sigma_min, zeta_min=spec.zeta_min, lowest_speed=lowest,
                                      max_speed=spec.required(setup))
        if added:
            stated = replace(stated, stability={**stated.stability, **added})
        return replace(setup, checks={**setup.checks, "hunting": stated})


# ---------------------------------------------------------------------------------------------- output files
def campaign_label(model: str, objective: str, method: str, problem: str = "constrained") -> str:
    """The store name of a campaign: ``<model>-<objective>-<method>``, with ``-unconstrained`` after the model for
    the unconstrained problem of a study that has constraints."""
    return f"{model}-{objective}-{method}" if problem == "constrained" else f"{model}-{problem}-{objective}-{method}"


def model_tag(label: str, n_models: int) -> str:
    """The suffix of a model's files: ``""`` for a study of one model, else ``"_<label>"``."""
    return "" if n_models == 1 else f"_{label}"


def tradeoff_stem(name: str, tag: str) -> str:
    """The stem of a trade-off's files: ``tradeoff_<stem>.csv``, ``pareto_<stem>.csv`` and ``.png``."""
    return f"{name}{tag}"


def surface_stem(variables: tuple[str, str], tag: str) -> str:
    """The stem of a surface's files: ``<stem>.png``, ``<stem>_constrained.csv``, ``<stem>_unconstrained.csv`` and a
    table per boundary drawn."""
    return f"surface_{variables[0]}_{variables[1]}{tag}"


def output_files(cfg: CampaignStudyConfig) -> list[tuple[str, str]]:
    """``(file name, field that names it)`` of every file a run of ``cfg`` may write: the campaign stores
    (``campaigns/<label>.sqlite``), the per-model before/after, trade-off and surface files.  Two entries with the
    same file name would overwrite each other."""
    own = "the report's own files"
    files: list[tuple[str, str]] = [(f"{stem}.{ext}", own) for stem, ext in (
        ("comparison", "csv"), ("starts", "csv"), ("starts", "parquet"), ("outcomes", "csv"), ("optima", "csv"),
        ("frf", "png"), ("recommended", "csv"), ("timing", "csv"))]
    d = cfg.design
    for ref in cfg.models:
        tag = model_tag(ref.label, len(cfg.models))
        files += [(f"{stem}{tag}.{ext}", own) for stem, ext in (
            ("before_after", "csv"), ("stability", "csv"), ("root_locus_before_after", "csv"),
            ("root_locus_before_after", "png"))]
    for i, ref in enumerate(cfg.models):
        for prob in d.problems:
            for objective, method in d.plan(prob):
                files.append((f"campaigns/{campaign_label(ref.label, objective, method, prob)}.sqlite",
                              f"models[{i}].label"))
        tag = model_tag(ref.label, len(cfg.models))
        shown = cfg.report.outputs or [cfg.objective.output or "objective"]
        files += [(f"{o}_before_after{tag}.png", "report.outputs") for o in dict.fromkeys(shown)]
        for j, t in enumerate(cfg.tradeoffs):
            stem = tradeoff_stem(t.name, tag)
            files += [(f"{prefix}_{stem}.{ext}", f"tradeoffs[{j}].name")
                      for prefix, ext in (("tradeoff", "csv"), ("pareto", "csv"), ("pareto", "png"))]
        boundaries = ["critical"] + [c.output for c in cfg.constraints if c.output]
        for j, sp in enumerate(cfg.surfaces):
            stem = surface_stem(sp.variables, tag)
            suffixes = ["constrained", "unconstrained", *(b.split(" ")[0] for b in boundaries)]
            files += [(f"{stem}.png", f"surfaces[{j}].variables")]
            files += [(f"{stem}_{x}.csv", f"surfaces[{j}].variables") for x in suffixes]
    return files


def _check_unique_outputs(cfg: CampaignStudyConfig) -> None:
    """Refuse two trade-offs of one name, two surfaces over one pair (either order), and any two sections whose
    files would land on one name (one would overwrite the other); and a file name too long to write."""
    names = [t.name for t in cfg.tradeoffs]
    for j, name in enumerate(names):
        if name in names[:j]:
            raise ValueError(f"tradeoffs[{j}].name: {name!r} is the name of tradeoffs[{names.index(name)}] too; "
                             "each trade-off names its files (tradeoff_<name>.csv, pareto_<name>.*): give it another")
    pairs = [frozenset(sp.variables) for sp in cfg.surfaces]
    for j, pair in enumerate(pairs):
        if pair in pairs[:j]:
            raise ValueError(f"surfaces[{j}].variables: {list(cfg.surfaces[j].variables)} is the pair of "
                             f"surfaces[{pairs.index(pair)}] (in either order it is one surface, one set of files)")
    seen: dict[str, str] = {}
    for name, field in output_files(cfg):
        if len(name.rpartition("/")[2].encode()) > FILE_NAME_BYTES:
            raise ValueError(f"{field}: makes the file name {name[:40]}… of {len(name.encode())} bytes, more than "
                             f"the file system's {FILE_NAME_BYTES}; shorten it")
        if name in seen and seen[name] != field:
            raise ValueError(f"{field}: its file {name} is also a file of {seen[name]}; one would overwrite the other "
                             "— rename one of them")
        seen.setdefault(name, field)


def _check_solver_options(cfg: CampaignStudyConfig) -> None:
    """The design layer's own check of the solver options (:func:`railopt.design.solve.method_options`) for the
    trade-offs' methods (the design's own are checked by :class:`CampaignSettings`), naming
    ``design.options.<key>``."""
    from railopt.design.solve import method_options

    options = cfg.design.solver_options()
    for method in dict.fromkeys(t.method for t in cfg.tradeoffs):
        try:
            method_options(method, options)
        except ValueError as exc:
            raise ValueError(f"design.{exc}") from None


# ---------------------------------------------------------------------------------------------- per model
def _check_setup(cfg: CampaignStudyConfig, setup: ModelSetup, where: str) -> None:
    names = [v.name for v in cfg.design.variables]
    setup.parameter_map.check_variables(cfg.design.variables, "design.variables", where)  # names, then ≥ 0 bounds
    outputs = setup.family.output_names
    specs = [("objective", cfg.objective)] + [(f"constraints[{i}]", c) for i, c in enumerate(cfg.constraints)]
    for field, spec in specs:
        if spec.output is not None and spec.output not in outputs:
            raise ValueError(f"{field}.output: {where}: {not_one_of(spec.output, outputs, 'output')}")
    _check_rms(cfg, setup, where)
    before = [cfg.report.before] if cfg.report.before else []
    for field, named in (("design.start_from", cfg.design.start_from), ("report.compare", cfg.report.compare),
                         ("report.before", before)):
        for name in named:
            if name not in setup.named_designs:
                raise ValueError(f"{field}: {where}: {not_one_of(name, sorted(setup.named_designs), 'named design')}")
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
        for o in wanted:
            if o not in outputs:
                raise ValueError(f"{field}: {where}: {not_one_of(o, outputs, 'output')}")
    for t in cfg.tradeoffs:
        needed = "hunting" if t.check == "damping" else t.check
        if needed is not None and needed not in setup.checks:
            raise ValueError(f"tradeoffs.{t.name}.check: {where}: {not_one_of(needed, sorted(setup.checks), 'check')}")
        if t.check in ("hunting", "damping") and not setup.stability:
            raise ValueError(f"tradeoffs.{t.name}.check: {where} has no stability family to sweep against")
    for i, c in enumerate(cfg.constraints):
        if c.clearance is not None and c.clearance not in setup.limits:
            raise ValueError(f"constraints[{i}].clearance: {where}: "
                             f"{not_one_of(c.clearance, sorted(setup.limits), 'clearance')} (the vehicle file's "
                             "[clearances])")
    if cfg.stability is not None:
        _check_stability(cfg, setup, where)
    for j, t in enumerate(cfg.tradeoffs):
        lowest = (cfg.stability.lowest_speed_m_s if cfg.stability is not None else None)
        if t.check == "hunting" and lowest is not None and min(t.epsilons) <= lowest:
            raise ValueError(f"tradeoffs[{j}].epsilons: a required speed of {min(t.epsilons):g} m/s is not above "
                             f"stability.lowest_speed_m_s = {lowest:g} m/s: its stability rows would collapse onto one "
                             "speed")
    for sp in cfg.surfaces:
        bad = [v for v in sp.variables if v not in names]
        if bad or sp.variables[0] == sp.variables[1]:
            raise ValueError(f"surfaces.variables: need two different design variables of {names}, got {sp.variables}")
    if cfg.report.locus_speeds_m_s is not None and not setup.stability:
        raise ValueError(f"report.locus_speeds_m_s: {where} has no forward speed")
    for name in cfg.design.checks:
        if name == "nonlinear_hunting" and name not in setup.checks:
            raise ValueError(f"design.checks: {where}: 'nonlinear_hunting' needs a vehicle with wheel and rail "
                             "profiles (a [wheel_rail] table in its vehicle file: wheel_profile, rail_profile, "
                             "inclination)")
        if name not in setup.checks:
            raise ValueError(f"design.checks: {where}: {not_one_of(name, sorted(setup.checks), 'check')}")
    if cfg.nonlinear_hunting is not None and "nonlinear_hunting" not in cfg.design.checks:
        raise ValueError("nonlinear_hunting: settings given but design.checks does not list 'nonlinear_hunting'")
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


def _check_stability(cfg: CampaignStudyConfig, setup: ModelSetup, where: str) -> None:
    """``[stability]`` against the model: a forward speed, known tracks, a required speed above the lowest, and
    rows that constrain something: every ``exclude`` entry names a mode of the model, and not every mode is left
    out (a vacuous constraint is refused, naming the field)."""
    spec = cfg.stability
    if not setup.stability:
        raise ValueError(f"stability: {where} has no forward speed (no stability family to constrain)")
    families = {**setup.stability, **setup.other_tracks}
    for t in spec.tracks:
        if t not in families:
            raise ValueError(f"stability.tracks: {where} has no {t!r} track (its vehicle file has no [track] table); "
                             f"it has {sorted(families)}")
    required = spec.required(setup)
    if required is None:
        raise ValueError(f"stability.required_speed_m_s: {where} has no maximum operating speed; give one")
    spec.check_lowest(required, "required_speed_m_s" if spec.required_speed_m_s else
                      f"the maximum operating speed of {where}", "stability.")
    _check_exclude(spec, {t: families[t] for t in (spec.tracks or setup.stability)}, required, where)


def _check_exclude(spec, families: dict, required: float, where: str) -> None:
    """Each ``exclude`` entry must leave out some mode of the existing design at a row speed on some track, and the
    entries together must keep at least one mode at every row speed on every track (by the rows' own rule,
    :attr:`railopt.models.stability_rows.StabilityRows.kept`); an unknown name gets a did-you-mean among the modes'
    names and groups."""
    if not spec.exclude:
        return
    from railopt.models.stability import modes
    from railopt.models.stability_rows import StabilityRows

    speeds = spec.grid(required)
    matched = [False] * len(spec.exclude)
    names: set[str] = set()
    for track, family in families.items():
        kept = StabilityRows(family, None, speeds, ()).kept  # (speeds, modes)
        for i, entry in enumerate(spec.exclude):
            matched[i] |= bool((StabilityRows(family, None, speeds, [entry]).kept != kept).any())
        left = StabilityRows(family, None, speeds, spec.exclude).kept
        for speed, keep in zip(speeds, left, strict=True):
            if not keep.any():
                raise ValueError(f"stability.exclude: {spec.exclude} leaves out every mode of {where} on {track} track "
                                 f"at {speed:g} m/s: the stability constraint would constrain nothing")
        for speed in (speeds[0], speeds[-1]):
            table = modes(family, speed=speed)
            names |= set(table["group"])
            for name in table["name"]:  # each name and its leading words ("body hunting" of "body hunting (...)")
                words = name.split()
                names |= {" ".join(words[:k]) for k in range(1, len(words) + 1)}
    for i, entry in enumerate(spec.exclude):
        if not matched[i]:
            unknown = not_one_of(entry, sorted(names), "mode name")
            raise ValueError(f"stability.exclude[{i}]: {where}: {unknown} (no mode of the existing design on "
                             f"{'/'.join(families)} track between {speeds[0]:g} and {speeds[-1]:g} m/s is named so, "
                             "nor starts so: the entry leaves nothing out)")


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
