"""Vehicle models: a generic small-motion rigid-body assembler and vehicle data files.

Public API: :func:`load_vehicle` → :class:`Vehicle`; ``vehicle.with_parameters({...})``,
``vehicle.lateral(track="rigid"|"flexible", speed=S)`` / ``.vertical(...)`` → :class:`VehicleModel`
with ``.M .C .K`` (numpy), ``.n_dof``, ``.coordinates``, ``.eigenvalues()``, ``.parametric(names)``;
forced response to rail irregularities: ``model.frequency_response(f_hz, Irregularity(...), outputs)``,
``model.forced_system(...)`` (``docs/forced_response.md``).
Schema, coordinates and conventions: ``docs/vehicle.md``.
"""

from railopt.models.vehicle.assembly import Assembly, assemble
from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.elements import Element
from railopt.models.vehicle.geometry import DOFS, LATERAL_DOFS, THESIS_SIGNS, VERTICAL_DOFS
from railopt.models.vehicle.irregularity import Irregularity, RailInput
from railopt.models.vehicle.loader import BUNDLED, VehicleFileError, load_vehicle, parse_vehicle
from railopt.models.vehicle.model import VehicleModel
from railopt.models.vehicle.response import PointOutput, forced_parametric, forced_system, frequency_response
from railopt.models.vehicle.vehicle import Vehicle
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
    "PointOutput",
    "RailInput",
    "Vehicle",
    "VehicleFileError",
    "VehicleModel",
    "WheelRail",
    "assemble",
    "forced_parametric",
    "forced_system",
    "frequency_response",
    "load_vehicle",
    "parse_vehicle",
]
