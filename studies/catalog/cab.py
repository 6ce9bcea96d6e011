"""The cab ride model of the flagship study (thesis §4.3.3), registered in the model catalog.

``cab_lateral``: the body's lateral/roll/yaw motion on the secondary suspension with the trucks
following a lateral irregularity (:mod:`railopt.models.vehicle.cab`); every suspension element acting
on the body is designable by id or alias.  Its ``hunting`` check puts a design into the full lateral
model with creep (rigid and flexible track) and reports the critical speeds and the least damping
ratio up to the maximum operating speed — the stability check of every distinct optimum.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from railopt.models.units import INCH, MPH
from railopt.models.vehicle.cab import CabInput, cab_lateral_model
from railopt.studies.catalog import ModelSetup, PositiveInterval, register_model
from railopt.studies.catalog.vehicle import VEHICLE, load, vehicle_setup
from railopt.studies.config import StrictModel

__all__ = ["CabOptions", "cab_lateral_setup"]


class CabOptions(StrictModel):
    """Options of the ``cab_lateral`` model (thesis §4.3.3), in the thesis's inch-pound units where named so.

    ``amplitude_in`` is the lateral irregularity (in); the band runs to ``max_frequency_hz``, reached at
    ``max_speed_mph`` (``fixed_wavelength``: λ = S_max / f_max, every frequency at its own speed) or with the speed
    fixed at ``max_speed_mph`` (``fixed_speed``).  ``max_operating_speed_mph`` and ``critical_search_mph`` set the
    hunting check; ``view = "full"`` builds its stability families of every coordinate (an asymmetric vehicle);
    ``parameters`` override values of the vehicle file.
    """

    vehicle: str = Field(description=VEHICLE)
    view: Literal["lateral", "full"] = Field(
        "lateral", description="view of the stability families (hunting check, root loci, stability rows): full for "
                               "a vehicle not symmetric about its centre line")
    amplitude_in: float = Field(0.25, gt=0, lt=100, allow_inf_nan=False, description="lateral irregularity, in")
    max_frequency_hz: float = Field(3.0, gt=0, lt=1000, allow_inf_nan=False)
    max_speed_mph: float = Field(150.0, gt=0, lt=1000, allow_inf_nan=False, description="speed at max_frequency_hz")
    mode: Literal["fixed_wavelength", "fixed_speed"] = "fixed_wavelength"
    max_operating_speed_mph: float = Field(70.0, gt=0, lt=1000, allow_inf_nan=False,
                                           description="the hunting check requires stability up to this speed")
    critical_search_mph: PositiveInterval = Field((2.0, 300.0), description="critical-speed search range, mph")
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


@register_model("cab_lateral", CabOptions,
                "thesis §4.3.3 cab model: body lateral/roll/yaw on the secondary suspension, trucks following a "
                "lateral irregularity; outputs cab_acceleration (m/s²), cab_displacement, strokes")
def cab_lateral_setup(options: CabOptions) -> ModelSetup:
    """The thesis §4.3.3 cab model of the options' vehicle as a catalog :class:`ModelSetup`.

    Body lateral/roll/yaw on the secondary suspension with the trucks following the lateral irregularity; the
    outputs (``cab_acceleration``, ``cab_displacement``, the strokes) are labelled in m, m/s or m/s² (``body_roll``
    in rad); stability families on rigid and flexible track.  Errors of the vehicle file or the options raise
    ValueError naming the field.
    """
    vehicle = load(options)
    cab = cab_lateral_model(vehicle, CabInput(options.amplitude_in * INCH, options.max_frequency_hz,
                                              options.max_speed_mph * MPH, options.mode))
    family = cab.system.with_values(cab.parameters())
    if options.mode == "fixed_wavelength":
        description = (f"{vehicle.name} cab model, ±{options.amplitude_in:g} in lateral irregularity, "
                       f"λ = {cab.cab_input.wavelength_m:.2f} m")
    else:
        description = f"{vehicle.name} cab model, S = {options.max_speed_mph:g} mph"
    search = (options.critical_search_mph[0] * MPH, options.critical_search_mph[1] * MPH)
    setup = vehicle_setup(vehicle, family, description, ("rigid", "flexible"), search,
                          options.max_operating_speed_mph * MPH, abscissa=family, view=options.view)
    suffix = {"displacement": "", "velocity": "/s", "acceleration": "/s²"}
    system = family.at()
    setup.units = {o: ("rad" if o == "body_roll" else "m") + suffix[system.outputs[o].quantity]
                   for o in family.output_names}
    amplitude_mm = options.amplitude_in * INCH * 1000
    setup.input_label = f"{amplitude_mm:.3g} mm ({options.amplitude_in:g} in) lateral irregularity"
    return setup
