"""The bundled models a study config can name (registered in :mod:`railopt.studies.catalog`)."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from railopt.models.stability import spectral_abscissa
from railopt.models.tmd import den_hartog, nishihara_asami, tmd_parameters, tmd_system
from railopt.models.vehicle import load_vehicle
from railopt.studies.base import StrictModel
from railopt.studies.catalog import ModelSetup, register_model


def abscissa_check(setup: ModelSetup):
    """A check: the largest real part of the roots of G (4.53), 1/s; stable when negative (4.59)."""

    def check(p: np.ndarray) -> tuple[float, dict[str, bool]]:
        value = float(np.max(setup.system.at(p).eigenvalues().real))
        return value, {"stable": value < 0}

    return check


class TMDOptions(StrictModel):
    mass_ratio: float = Field(gt=0, le=10, allow_inf_nan=False, description="absorber / primary mass")
    primary_mass_kg: float = Field(1000.0, gt=0, lt=1e12, allow_inf_nan=False)
    primary_frequency_hz: float = Field(2.0, gt=0, lt=1e6, allow_inf_nan=False)


@register_model("tmd", TMDOptions, "tuned mass damper (k2, c2) on an undamped primary; output k1·x1 per unit force")
def tmd_setup(options: TMDOptions) -> ModelSetup:
    """TMD on an undamped primary: parameters (k2, c2), designable also as (tuning, damping_ratio)."""
    mu, m1 = options.mass_ratio, options.primary_mass_kg
    k1 = m1 * (2 * np.pi * options.primary_frequency_hz) ** 2
    system = tmd_system(mu, m1, k1, output_name="amplification")

    def transform(values: dict[str, float]) -> tuple[dict[str, float], dict[str, dict[str, float]]]:
        if set(values) != {"tuning", "damping_ratio"}:
            raise ValueError("variables: design tuning and damping_ratio together (they map to k2 and c2)")
        p, jac = tmd_parameters(values["tuning"], values["damping_ratio"], mu, m1, k1)
        return ({"k2": p[0], "c2": p[1]},
                {"k2": {"tuning": jac[0, 0], "damping_ratio": jac[0, 1]},
                 "c2": {"tuning": jac[1, 0], "damping_ratio": jac[1, 1]}})

    dh, na = den_hartog(mu), nishihara_asami(mu)
    defaults, _ = tmd_parameters(dh.tuning, dh.damping_ratio, mu, m1, k1)
    setup = ModelSetup(
        system=system,
        defaults=defaults,
        named_designs={
            "den_hartog": {"tuning": dh.tuning, "damping_ratio": dh.damping_ratio},
            "nishihara_asami": {"tuning": na.tuning, "damping_ratio": na.damping_ratio},
        },
        transform=transform,
        transform_variables=("tuning", "damping_ratio"),
        description=f"TMD, μ = {mu:g}, m1 = {m1:g} kg, f1 = {options.primary_frequency_hz:g} Hz",
    )
    setup.checks["spectral_abscissa"] = abscissa_check(setup)
    return setup


class VehicleOptions(StrictModel):
    vehicle: str = Field("sd40-2", description="a bundled vehicle name or a vehicle file path")
    track: Literal["rigid", "flexible"] = "rigid"
    speed_m_s: float = Field(30.0, gt=0, lt=1000, allow_inf_nan=False, description="forward speed of `system`")
    output: str | None = Field(None, description="output row of the model (e.g. cab.lateral)")
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


@register_model("vehicle_lateral", VehicleOptions,
                "lateral model (v, α, γ) of a vehicle file with creep; speed-dependent (stability)")
def vehicle_lateral_setup(options: VehicleOptions) -> ModelSetup:
    """The lateral model of a vehicle file; every suspension element is designable by id or alias."""
    vehicle = load_vehicle(options.vehicle)
    if options.parameters:
        vehicle = vehicle.with_parameters(options.parameters)
    model = vehicle.lateral(track=options.track, speed=options.speed_m_s)
    names = list(model.parts)
    system = model.family(names, outputs=[options.output or model.coordinates[0]])
    defaults = np.array([model.values[n] for n in names])
    free = model.family(names)

    def speed_model(p: np.ndarray):
        return free.with_values(p)

    setup = ModelSetup(system=system, defaults=defaults,
                       named_designs={"existing": dict(zip(names, defaults, strict=True))},
                       description=f"{vehicle.name}, lateral, {options.track} track", speed_model=speed_model)

    def hunting(p: np.ndarray) -> tuple[float, dict[str, bool]]:
        value = spectral_abscissa(speed_model(p), speed=options.speed_m_s)
        return value, {"stable": value < 0}

    setup.checks["spectral_abscissa"] = hunting
    return setup


# ---------------------------------------------------------------------------------------------- forced response
class IrregularityOptions(StrictModel):
    """A sinusoidal rail irregularity (:class:`railopt.models.vehicle.irregularity.Irregularity`)."""

    kind: Literal["vertical", "alignment", "cross_level", "lateral"] = "vertical"
    amplitude_m: float = Field(0.00635, gt=0, lt=1.0, allow_inf_nan=False, description="per rail, m")
    rails: Literal["in_phase", "out_of_phase"] | None = None


class VehicleForcedOptions(StrictModel):
    vehicle: str = Field("sd40-2", description="a bundled vehicle name or a vehicle file path")
    track: Literal["rigid", "flexible"] = "rigid"
    speed_m_s: float = Field(30.0, gt=0, lt=1000, allow_inf_nan=False, description="forward speed S, m/s")
    view: Literal["vertical", "lateral"] = "vertical"
    input: IrregularityOptions = Field(default_factory=IrregularityOptions)
    outputs: list[str] = Field(default_factory=lambda: ["body.w"], min_length=1,
                               description="coordinates, named rows or body points '<body>[x,y,z].<x|y|z>'")
    quantity: Literal["displacement", "velocity", "acceleration"] = "displacement"
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


def vehicle_forced_model(options: VehicleForcedOptions):
    """``(VehicleModel, Irregularity)`` of the options (errors name the option)."""
    from railopt.models.vehicle.irregularity import Irregularity

    vehicle = load_vehicle(options.vehicle)
    if options.parameters:
        vehicle = vehicle.with_parameters(options.parameters)
    view = vehicle.vertical if options.view == "vertical" else vehicle.lateral
    model = view(track=options.track, speed=options.speed_m_s)
    try:
        irregularity = Irregularity(options.input.kind, options.input.amplitude_m, options.input.rails)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    return model, irregularity


@register_model("vehicle_forced", VehicleForcedOptions,
                "a vehicle's vertical or lateral model forced by a delayed sinusoidal rail irregularity "
                "(4.60)-(4.70); outputs as listed, every suspension element designable")
def vehicle_forced_setup(options: VehicleForcedOptions) -> ModelSetup:
    """The forced response as a ParametricSystem in every suspension element (ids), delays declared."""
    model, irregularity = vehicle_forced_model(options)
    names = list(model.parts)
    system = model.forced_parametric(irregularity, names, options.outputs, options.quantity)
    defaults = np.array([model.values[n] for n in names])
    free = model.family(names)

    def speed_model(p: np.ndarray):
        return free.with_values(p)

    setup = ModelSetup(system=system, defaults=defaults,
                       named_designs={"existing": dict(zip(names, defaults, strict=True))},
                       description=f"{model.name}, {options.view}, {options.track} track, "
                                   f"S = {options.speed_m_s:g} m/s, {irregularity.label}",
                       speed_model=speed_model)

    def stability(p: np.ndarray) -> tuple[float, dict[str, bool]]:
        value = spectral_abscissa(speed_model(p))  # neutral roots (free fore-aft translation) ignored
        return value, {"stable": value < 0}

    setup.checks["spectral_abscissa"] = stability
    return setup
