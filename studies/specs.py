"""The config specs shared by study kinds (pydantic models only, data without runtime objects): the
``[design]`` settings and solver options, design variables, outputs over a band, the objective and its track
spectrum, constraints and the stability constraints.  Kinds build their configs from these; the targets the design
layer runs are made from them by :mod:`railopt.studies.adapter` (``response_target``, ``rms_target``,
``stability_target``), which configs never import."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from railopt.design import DesignVariable
from railopt.studies.config import BandHz, FiniteModel, MethodName, StrictModel

if TYPE_CHECKING:
    from railopt.studies.catalog import ModelSetup

__all__ = [
    "CampaignSettings",
    "ConstraintSpec",
    "NonlinearHuntingSpec",
    "ObjectiveSpec",
    "OutputSpec",
    "SolverOptions",
    "SpectrumSpec",
    "StabilitySpec",
    "VariableSpec",
]


class SolverOptions(StrictModel):
    """``[design.options]``: the solver's tolerances, evaluation and time limits."""

    xtol: float = Field(1e-10, gt=0, strict=True)  # strict: `true` is not a number
    ftol: float = Field(1e-12, gt=0, strict=True)
    maxeval: int = Field(3000, gt=0, strict=True)
    maxtime: float = Field(120.0, gt=0, strict=True)


class CampaignSettings(StrictModel):
    """The ``[design]`` table shared by campaign studies."""

    method: MethodName = "slsqp"
    n_starts: int = Field(16, gt=0, strict=True)  # strict: `true` or 16.0 is not a count
    sampler: Literal["sobol", "lhs"] = "sobol"
    seed: int = Field(0, ge=0, strict=True)
    options: SolverOptions = SolverOptions()

    def solver_options(self) -> dict[str, Any]:
        """The solver options as keyword arguments of the design layer."""
        return self.options.model_dump()

    def solver_methods(self) -> list[str]:
        """The methods a run solves with: ``method``."""
        return [self.method]

    @model_validator(mode="after")
    def _options_of_each_method(self) -> CampaignSettings:
        """The design layer's own check of the options (:func:`railopt.design.solve.method_options`) for every
        method a run solves with: what a run would refuse, refused here naming ``options.<key>``."""
        from railopt.design.solve import method_options

        for method in self.solver_methods():
            method_options(method, self.solver_options())
        return self


class VariableSpec(FiniteModel):
    """A design variable: a designable parameter of the model, its bounds and its scale."""

    name: str
    lower: float
    upper: float
    scale: Literal["linear", "log"] = "linear"

    @model_validator(mode="after")
    def _bounds(self) -> VariableSpec:
        DesignVariable(self.name, self.lower, self.upper, self.scale)  # same rules as the design layer
        return self

    def variable(self) -> DesignVariable:
        """The design layer's variable."""
        return DesignVariable(self.name, self.lower, self.upper, self.scale)


class OutputSpec(FiniteModel):
    """An output of the model over a band (Hz)."""

    output: str | None = None
    band_hz: BandHz


class SpectrumSpec(StrictModel):
    """``[objective.spectrum]``: the track spectrum of the ``rms`` objective
    (:func:`railopt.models.track.spectra.irregularity_spectrum`): ``standard = "fra"`` with ``track_class`` 1–6,
    ``"erri_b176"`` with ``level`` low/high, or ``"table"`` with ``path`` (CSV: wavenumber rad/m, PSD m²/(rad/m);
    relative to the working directory); ``component`` profile/alignment (FRA also cross_level)."""

    standard: Literal["fra", "erri_b176", "table"]
    track_class: int | None = Field(None, strict=True)
    level: Literal["low", "high"] | None = None
    component: str = "profile"
    path: str | None = None
    rtol: float = Field(1e-8, gt=0, lt=0.1, description="relative tolerance of the RMS quadrature (variance)")

    @model_validator(mode="after")
    def _build(self) -> SpectrumSpec:
        self.spectrum()  # its errors name the argument: track_class, level, component, path
        return self

    def spectrum(self):
        """The track spectrum the spec names."""
        from railopt.models.track.spectra import irregularity_spectrum

        if self.standard == "table":
            if self.path is None:
                raise ValueError("path: a table spectrum needs the path of its CSV (wavenumber rad/m, PSD m²/(rad/m))")
            bad = [n for n in ("track_class", "level") if getattr(self, n) is not None]
            if bad:
                raise ValueError(f"{bad[0]}: does not apply to a table spectrum")
            try:
                return irregularity_spectrum.from_table(self.path)
            except OSError as exc:
                raise ValueError(f"path: {exc}") from None
        if self.path is not None:
            raise ValueError(f"path: applies to standard = 'table' only, not {self.standard!r}")
        return irregularity_spectrum(self.standard, track_class=self.track_class, level=self.level,
                                     component=self.component)


class ObjectiveSpec(OutputSpec):
    """``[objective]``: an output over a band (Hz); with the ``rms`` objective also ``[objective.spectrum]``."""

    spectrum: SpectrumSpec | None = None


class ConstraintSpec(OutputSpec):
    """f_k of ``output`` ≤ ``limit`` (units of the output), or ≤ the model's named ``clearance`` (the vehicle
    file's ``[clearances]``, m) — the ε of ε-constraint sweeps."""

    limit: float | None = Field(None, gt=0)
    clearance: str | None = Field(None, description="a named limit of the model, e.g. secondary_lateral_m")
    exact: bool = True

    @model_validator(mode="after")
    def _one_limit(self) -> ConstraintSpec:
        if (self.limit is None) == (self.clearance is None):
            raise ValueError("give exactly one of limit (a number in the output's units) or clearance (a name)")
        return self

    def limit_value(self, setup: ModelSetup) -> float:
        """The limit in the output's units: ``limit``, or the model's named clearance."""
        return self.limit if self.limit is not None else setup.limits[self.clearance]


class StabilitySpec(FiniteModel):
    """``[stability]``: the stability constraints of the constrained problem (SPEC §2.5).

    Every vehicle mode's root must satisfy Re s + σ_min ≤ 0 at ``speeds`` speeds evenly spaced from
    ``lowest_speed_m_s`` up to the required speed (``required_speed_m_s``, default the model's maximum operating
    speed), on each of ``tracks`` (default: every track of the model's stability families); track modes and the
    modes named in ``exclude`` are left out; with ``zeta_min`` every kept mode is also at least that damped.
    Each optimum's critical speeds are then confirmed by the hunting check.
    """

    speeds: int = Field(4, ge=1, le=50, strict=True)
    lowest_speed_m_s: float | None = Field(None, gt=0, lt=1000, description="first speed of the grid (default: "
                                           "the required speed / speeds)")
    sigma_min: float = Field(0.0, ge=0, description="1/s")
    zeta_min: float | None = Field(None, ge=0, lt=1)
    required_speed_m_s: float | None = Field(None, gt=0, lt=1000)
    tracks: list[Literal["rigid", "flexible"]] = Field(default_factory=list)
    exclude: list[str] = Field(default_factory=list, description="mode names (or name prefixes) left out; each "
                               "must name a mode of the model")

    @field_validator("tracks", "exclude")
    @classmethod
    def _unique(cls, v: list[str]) -> list[str]:
        repeated = sorted({x for x in v if v.count(x) > 1})
        if repeated:
            raise ValueError(f"entries must be unique, repeated {repeated}")
        return v

    @field_validator("exclude")
    @classmethod
    def _named(cls, v: list[str]) -> list[str]:
        for i, name in enumerate(v):
            if not name:
                raise ValueError(f"entry {i} is empty: an empty name is a prefix of every mode name and would leave "
                                 "every root out of the constraint; name a mode, e.g. 'body hunting'")
            if not name.strip():
                raise ValueError(f"entry {i} is blank: it names no mode; name one, e.g. 'body hunting'")
        return v

    @model_validator(mode="after")
    def _rows(self) -> StabilitySpec:
        if self.lowest_speed_m_s is not None and self.speeds == 1:
            raise ValueError("lowest_speed_m_s: with speeds = 1 the one row is at the lowest speed and the required "
                             "speed is never checked; give speeds ≥ 2 or leave lowest_speed_m_s out")
        if self.lowest_speed_m_s is not None and self.required_speed_m_s is not None:
            self.check_lowest(self.required_speed_m_s, "required_speed_m_s")
        return self

    def check_lowest(self, required: float, what: str, prefix: str = "") -> None:
        """Refuse a ``lowest_speed_m_s`` at or above the ``required`` speed (m/s): the rows would collapse onto one
        speed.  ValueError naming ``<prefix>lowest_speed_m_s`` and ``what`` the required speed is."""
        if self.lowest_speed_m_s is not None and not self.lowest_speed_m_s < required:
            raise ValueError(f"{prefix}lowest_speed_m_s: {self.lowest_speed_m_s:g} m/s is not below the required speed "
                             f"{required:g} m/s ({what}): the {self.speeds} rows would collapse onto one speed")

    def required(self, setup: ModelSetup) -> float:
        """The required speed (m/s): ``required_speed_m_s``, or the model's maximum operating speed."""
        return self.required_speed_m_s or setup.required_speed

    def grid(self, required: float) -> tuple[float, ...]:
        """The rows' speeds (m/s), ``speeds`` of them evenly spaced from ``lowest_speed_m_s`` (default ``required /
        speeds``) to ``required``."""
        low = min(self.lowest_speed_m_s or required / self.speeds, required)
        return tuple(float(v) for v in np.linspace(low, required, self.speeds))


class NonlinearHuntingSpec(FiniteModel):
    """``[nonlinear_hunting]``: the nonlinear critical-speed analysis on the vehicle's wheel and rail profiles.

    The settings of :class:`railopt.models.vehicle.hunting.HuntingAnalysis` in file units (m/s, mm): a coarse
    descending ramp from ``top_speed_m_s`` (default 1.2 × the linear critical speed) in ``step_m_s`` steps (default
    5 % of the top), a fine ramp in ``fine_step_m_s`` steps (default 1 %) through the speed where the coarse ramp
    lost its cycle, each speed held for ``dwell_wavelengths`` kinematic wavelengths, started with the leading
    wheelset ``initial_amplitude_mm`` off centre; with ``continuation`` the cycle is then followed by shooting and
    pseudo-arclength continuation through its fold (minutes per vehicle; without it the answer is the ramp's
    bracket).  ``window_m`` is the EN 14363 sliding-RMS window of the ΣY indicator.
    """

    top_speed_m_s: float | None = Field(None, gt=0, lt=1000)
    lowest_speed_m_s: float = Field(5.0, gt=0, lt=1000)
    step_m_s: float | None = Field(None, gt=0, lt=100)
    fine_step_m_s: float | None = Field(None, gt=0, lt=100)
    dwell_wavelengths: float = Field(20.0, gt=0, le=1000)
    initial_amplitude_mm: float = Field(3.0, gt=0, le=20, description="leading wheelset's lateral offset at the "
                                        "start, mm")
    friction_coefficient: float | None = Field(None, gt=0, le=1, description="default: the vehicle file's "
                                               "[wheel_rail] friction_coefficient")
    rtol: float = Field(1e-6, gt=0, le=1e-3)
    continuation: bool = True
    max_points: int = Field(150, ge=2, le=10_000, strict=True)
    points_after_fold: int | None = Field(None, ge=1, le=10_000, strict=True, description=(
        "stop the continuation this many points past the fold (default: follow the unstable branch)"))
    window_m: float = Field(100.0, gt=0, le=10_000, description="sliding-RMS window of ΣY (EN 14363), m")

    @model_validator(mode="after")
    def _speeds(self) -> NonlinearHuntingSpec:
        if self.top_speed_m_s is not None and not self.top_speed_m_s > self.lowest_speed_m_s:
            raise ValueError(f"top_speed_m_s: {self.top_speed_m_s:g} m/s is not above lowest_speed_m_s "
                             f"{self.lowest_speed_m_s:g} m/s (a descending ramp)")
        return self

    def analysis(self, search: tuple[float, float] = (1.0, 150.0)) -> Any:
        """The :class:`~railopt.models.vehicle.hunting.HuntingAnalysis` of these settings (SI units)."""
        from railopt.models.vehicle.hunting import HuntingAnalysis

        return HuntingAnalysis(top_speed=self.top_speed_m_s, lowest_speed=self.lowest_speed_m_s, step=self.step_m_s,
                               fine_step=self.fine_step_m_s, dwell_wavelengths=self.dwell_wavelengths,
                               initial_amplitude=self.initial_amplitude_mm * 1e-3,
                               friction_coefficient=self.friction_coefficient, search=tuple(search),
                               rtol=self.rtol, atol=self.rtol * 1e-3, continuation=self.continuation,
                               max_points=self.max_points, points_after_fold=self.points_after_fold)
