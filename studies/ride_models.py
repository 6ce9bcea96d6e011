"""The cab ride model of the flagship study (thesis §4.3.3), registered in the model catalog.

``cab_lateral``: the body's lateral/roll/yaw motion on the secondary suspension with the trucks
following a lateral irregularity (:mod:`railopt.models.vehicle.cab`); every suspension element acting
on the body is designable by id or alias.  Its ``hunting`` check puts a design into the full lateral
model with creep (rigid and flexible track) and reports the critical speeds and the least damping
ratio up to the maximum operating speed — the stability check of every distinct optimum.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from railopt.models.stability import critical_speed, least_damping
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.cab import INCH, MPH, CabInput, cab_lateral_model
from railopt.studies.base import StrictModel
from railopt.studies.catalog import ModelSetup, register_model


class CabOptions(StrictModel):
    vehicle: str = Field("sd40-2", description="a bundled vehicle name or a vehicle file path")
    amplitude_in: float = Field(0.25, gt=0, lt=100, allow_inf_nan=False, description="lateral irregularity, in")
    max_frequency_hz: float = Field(3.0, gt=0, lt=1000, allow_inf_nan=False)
    max_speed_mph: float = Field(150.0, gt=0, lt=1000, allow_inf_nan=False, description="speed at max_frequency_hz")
    mode: Literal["fixed_wavelength", "fixed_speed"] = "fixed_wavelength"
    max_operating_speed_mph: float = Field(70.0, gt=0, lt=1000, allow_inf_nan=False,
                                           description="the hunting check requires stability up to this speed")
    critical_search_mph: tuple[float, float] = Field((2.0, 300.0), description="critical-speed search range")
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


@register_model("cab_lateral", CabOptions,
                "thesis §4.3.3 cab model: body lateral/roll/yaw on the secondary suspension, trucks following a "
                "lateral irregularity; outputs cab_acceleration (m/s²), cab_displacement, strokes")
def cab_lateral_setup(options: CabOptions) -> ModelSetup:
    vehicle = load_vehicle(options.vehicle)
    if options.parameters:
        vehicle = vehicle.with_parameters(options.parameters)
    cab = cab_lateral_model(vehicle, CabInput(options.amplitude_in * INCH, options.max_frequency_hz,
                                              options.max_speed_mph * MPH, options.mode))
    names = list(cab.system.parameters)
    defaults = cab.parameters()
    aliases = {a: k for a, k in vehicle.element_aliases().items() if k in names}
    lateral = {track: vehicle.lateral(track=track).family(names) for track in ("rigid", "flexible")}
    v_max = options.max_operating_speed_mph * MPH
    search = (options.critical_search_mph[0] * MPH, options.critical_search_mph[1] * MPH)

    def speed_model(p: np.ndarray, track: str = "rigid"):
        return lateral[track].with_values(p)

    def hunting(p: np.ndarray) -> tuple[float, dict]:
        """min critical speed (m/s) over rigid and flexible track; flags and numbers per track."""
        payload: dict = {}
        for track in ("rigid", "flexible"):
            model = speed_model(p, track)
            cs = critical_speed(model, speed_range=search, tol=0.01, grid=16)
            payload[f"critical_speed_{track}_m_s"] = cs.speed
            payload[f"least_damping_{track}"] = least_damping(model, np.linspace(search[0], v_max, 24))
        speed = min(payload["critical_speed_rigid_m_s"], payload["critical_speed_flexible_m_s"])
        payload["required_speed_m_s"] = v_max
        payload["stable"] = bool(speed > v_max and min(payload["least_damping_rigid"],
                                                       payload["least_damping_flexible"]) > 0)
        return speed, payload

    setup = ModelSetup(system=cab.system, defaults=defaults,
                       named_designs={"existing": {**dict(zip(names, defaults, strict=True)),
                                                   **{a: float(defaults[names.index(k)]) for a, k in aliases.items()}}},
                       description=f"{vehicle.name} cab model, ±{options.amplitude_in:g} in lateral irregularity, "
                                   f"λ = {cab.cab_input.wavelength_m:.2f} m" if options.mode == "fixed_wavelength"
                       else f"{vehicle.name} cab model, S = {options.max_speed_mph:g} mph",
                       speed_model=speed_model, aliases=aliases)
    setup.checks["hunting"] = hunting
    return setup
