"""Vehicle models: a generic small-motion rigid-body assembler and vehicle data files.

A one-way pipeline: file (:func:`load_vehicle`) → definition (:class:`Vehicle`) → assembly
(:func:`assemble`) → views (``vehicle.lateral(track, speed)`` / ``.vertical(...)`` / ``.full(...)`` →
:class:`VehicleView`: one block's matrices, coordinates, inputs and constraint rows) → outputs
(:mod:`~railopt.models.vehicle.outputs`), irregularity inputs and forced systems
(:mod:`~railopt.models.vehicle.forced`).  ``view.family(names, input, outputs)`` is the
:class:`~railopt.models.parametric.ParametricSystem` with its speed term that stability, forced
response and design use (``docs/forced_response.md``).
Schema, coordinates and conventions: ``docs/vehicle.md``.  The nonlinear vehicle (the same suspension, wheel/rail
forces from profiles with creep saturation): :func:`nonlinear_vehicle` → :class:`NonlinearVehicle`
(``docs/nonlinear_vehicle.md``).
"""

from railopt.models.vehicle.assembly import Assembly, assemble
from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.elements import Element
from railopt.models.vehicle.forced import forced_parametric, forced_system, frequency_response
from railopt.models.vehicle.geometry import DOFS, LATERAL_DOFS, THESIS_SIGNS, VERTICAL_DOFS
from railopt.models.vehicle.irregularity import Irregularity, RailInput
from railopt.models.vehicle.loader import BUNDLED, VehicleFileError, load_vehicle, parse_vehicle
from railopt.models.vehicle.nonlinear import NonlinearVehicle, nonlinear_vehicle
from railopt.models.vehicle.outputs import PointOutput
from railopt.models.vehicle.vehicle import Vehicle
from railopt.models.vehicle.views import VehicleModel, VehicleView
from railopt.models.vehicle.wheelrail import Creep, WheelRail

__all__ = [
    "BUNDLED",
    "DOFS",
    "LATERAL_DOFS",
    "THESIS_SIGNS",
    "VERTICAL_DOFS",
    "Assembly",
    "Body",
    "Creep",
    "Element",
    "Irregularity",
    "NonlinearVehicle",
    "PointOutput",
    "RailInput",
    "Vehicle",
    "VehicleFileError",
    "VehicleModel",
    "VehicleView",
    "WheelRail",
    "assemble",
    "forced_parametric",
    "forced_system",
    "frequency_response",
    "load_vehicle",
    "nonlinear_vehicle",
    "parse_vehicle",
]
