"""Catalog models of a vehicle file: ``vehicle_lateral`` (unforced, with creep) and ``vehicle_forced``.

Both are built by :func:`vehicle_setup`, the one path from a vehicle and a family to a
:class:`~railopt.studies.catalog.ModelSetup`: every suspension element designable by id (or alias), the
file's values as the existing design, the unforced lateral family on each track for stability (the full family
for a ``view = "full"`` model: an asymmetric vehicle), and the checks ``spectral_abscissa`` (at the model's
speed) and ``hunting`` (:class:`HuntingCheck`).  ``vehicle`` is required: no model runs a vehicle nobody named.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import Literal

from pydantic import Field

from railopt.models import ParametricSystem
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.assembly import TRACKS
from railopt.models.vehicle.loader import bundled_vehicles
from railopt.models.vehicle.outputs import UNIT_SUFFIX, output_rows
from railopt.studies.catalog import (
    AbscissaCheck,
    HuntingCheck,
    ModelSetup,
    ParameterMap,
    PositiveInterval,
    register_model,
)
from railopt.studies.catalog.checks import NonlinearHuntingCheck
from railopt.studies.catalog.views import stability_view, vehicle_view
from railopt.studies.config import StrictModel, not_one_of
from railopt.studies.output.figures import vehicle_label
from railopt.studies.specs import NonlinearHuntingSpec

__all__ = [
    "VEHICLE", "HuntingOptions", "IrregularityOptions", "VehicleForcedOptions", "VehicleOptions", "lateral_family",
    "load", "model_vehicle_file", "model_vehicles", "physical_limits", "readable_aliases", "tracks_of",
    "vehicle_forced_model", "vehicle_forced_setup", "vehicle_lateral_setup", "vehicle_setup", "vehicle_title",
    "vehicle_warnings",
]

VEHICLE = ("a bundled vehicle name (sd40-2, manchester-coach, single-wheelset) or a vehicle file path (relative "
           "to the study file)")
"""The description of the ``vehicle`` option of every vehicle model: required (a forgotten key never runs some
default vehicle)."""


def load(options):
    """The vehicle of ``options`` (a bundled name or a file) with its ``parameters`` overrides; an unknown override
    is a ValueError ``"parameters.<name>: unknown parameter ...; did you mean ...?"``."""
    vehicle = load_vehicle(options.vehicle)
    for name in options.parameters:
        try:
            vehicle.parameter(name)
        except ValueError:
            unknown = not_one_of(name, vehicle.parameter_names(), "parameter")
            raise ValueError(f"parameters.{name}: {unknown} (vehicle {vehicle.name!r})") from None
    return vehicle.with_parameters(options.parameters) if options.parameters else vehicle


def model_vehicles(models: Sequence) -> dict[str, dict[str, str]]:
    """The vehicle of each ``[[models]]`` entry built from a vehicle file, by label: ``{"vehicle": its name (the
    file's ``[vehicle] name``), "vehicle_file": the file}`` — a bundled one as ``"<name>.toml (bundled)"``, another
    by its path relative to the working directory when under it.  Models without a vehicle (``tmd``) are absent.
    Each file is read once per (label, source, modification time, working directory), however many tables name it.
    """
    sources = []
    for i, ref in enumerate(models):
        source = getattr(ref.validated_options(f"models[{i}]"), "vehicle", None)
        if isinstance(source, str):  # the file's modification time in the key: an edited file is read again
            stamp = Path(source).stat().st_mtime_ns if Path(source).is_file() else 0
            sources.append((ref.label, source, stamp))
    return {label: dict(v) for label, v in _vehicles(tuple(sources), str(Path.cwd()))}


@lru_cache(maxsize=64)
def _vehicles(sources: tuple[tuple[str, str, int], ...], cwd: str) -> tuple:
    bundled = bundled_vehicles()
    out = []
    for label, source, _ in sources:
        vehicle = load_vehicle(source)
        if source in bundled:
            shown = f"{source}.toml (bundled)"
        else:
            path = Path(vehicle.path).resolve()
            shown = str(path.relative_to(cwd)) if path.is_relative_to(cwd) else str(path)
        out.append((label, (("vehicle", vehicle.name), ("vehicle_file", shown))))
    return tuple(out)


def model_vehicle_file(models: Sequence, model: str) -> str | None:
    """The file name of the model's vehicle, ``"sd40-2.toml"`` (None for a model without a vehicle)."""
    v = model_vehicles(models).get(model)
    return None if v is None else Path(v["vehicle_file"].removesuffix(" (bundled)")).name


def vehicle_title(models: Sequence, model: str, text: str) -> str:
    """A figure title naming the model's vehicle and file (:func:`~railopt.studies.output.figures.vehicle_label`):
    ``"sd40-2 (sd40-2.toml): <text>"``, or for a model labelled other than its vehicle
    ``"coach_a: manchester-coach (coach.toml): <text>"``; ``"<model>: <text>"`` for a model without a vehicle."""
    v = model_vehicles(models).get(model)
    if v is None:
        return f"{model}: {text}"
    label = vehicle_label(v["vehicle"], model_vehicle_file(models, model))
    return f"{label}: {text}" if model == v["vehicle"] else f"{model}: {label}: {text}"


def vehicle_warnings(config: object) -> list[str]:
    """The plausibility warnings (:func:`railopt.models.vehicle.plausibility`) of every vehicle a study's
    ``[[models]]`` name, with its ``parameters`` applied, as ``"models[i] (<label>): <file>: <key>: <message>"``
    lines — each vehicle (source and overrides) once.  A config without ``models``, or models without a vehicle
    (``tmd``), gives none; a model that cannot be built is left to the run's own error."""
    from railopt.models.vehicle.plausibility import plausibility

    out, seen = [], set()
    for i, ref in enumerate(getattr(config, "models", None) or []):
        try:
            options = ref.validated_options(f"models[{i}]")
        except ValueError:
            continue
        source = getattr(options, "vehicle", None)
        key = (source, tuple(sorted((getattr(options, "parameters", None) or {}).items())))
        if not isinstance(source, str) or key in seen:
            continue
        seen.add(key)
        try:
            vehicle = load(options)
        except ValueError:
            continue
        out += [f"models[{i}] ({ref.label}): {w.line()}" for w in plausibility(vehicle)]
    return out


def lateral_family(vehicle, track: str, names: Sequence[str], view: str = "lateral") -> ParametricSystem:
    """The vehicle's unforced lateral family on ``track`` in those of ``names`` that act laterally; with ``view =
    "full"`` the family of every coordinate (an asymmetric vehicle's lateral motion couples to the vertical)."""
    model = vehicle_view(vehicle, view, track)
    return model.family([n for n in names if n in model.parts or n in model.aliases])


def tracks_of(vehicle) -> tuple[str, ...]:
    """The tracks the vehicle can run on: rigid, and flexible when its file has a ``[track]`` table."""
    return tuple(t for t in TRACKS if t == "rigid" or vehicle.track is not None)


PHYSICAL = {"spring": "stiffness", "damper": "damping coefficient", "rotational_spring": "rotational stiffness",
            "rotational_damper": "rotational damping coefficient"}
"""What an element's value is, by element type: each is ≥ 0."""


def physical_limits(vehicle, names: Sequence[str]) -> dict[str, tuple[float, str]]:
    """name -> (0, what it is) for every element id, body mass (``<body>.mass``) and inertia
    (``<body>.Ixx|Iyy|Izz``) among ``names``: physical values that cannot go below zero."""
    kinds = {e.id: PHYSICAL.get(e.type, "suspension value") for e in vehicle.elements}
    bodies = {b.name for b in vehicle.bodies}
    out = {}
    for n in names:
        body, _, attr = n.rpartition(".")
        if n in kinds:
            out[n] = (0.0, kinds[n])
        elif body in bodies and attr == "mass":
            out[n] = (0.0, "mass")
        elif body in bodies and attr in ("Ixx", "Iyy", "Izz"):
            out[n] = (0.0, "moment of inertia")
    return out


def readable_aliases(vehicle, names: Sequence[str]) -> dict[str, str]:
    """alias -> parameter for the element aliases and the file's own aliases that name one of ``names``."""
    elements = vehicle.element_aliases()
    out = {a: k for a, k in elements.items() if k in names}
    for a, target in vehicle.aliases.items():
        key = elements.get(target, target)
        if key in names and a not in names:
            out[a] = key
    return out


def vehicle_setup(vehicle, family: ParametricSystem, description: str, tracks: Sequence[str],
                  search: tuple[float, float], max_speed: float, abscissa: ParametricSystem | None = None,
                  aliases: dict[str, str] | None = None, view: str = "lateral") -> ModelSetup:
    """A vehicle model ready for a study.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (parameters already overridden).
    family : ParametricSystem
        The study's family; its parameters (element ids) and values are the designable parameters and
        the existing design.
    description : str
        One line for reports.
    tracks : sequence of {"rigid", "flexible"}
        Tracks of the stability families (root loci: the first; hunting check: all).
    search : (float, float)
        Critical-speed search range, m/s.
    max_speed : float
        The hunting check requires stability up to this speed, m/s.
    abscissa : ParametricSystem, optional
        The unforced family whose spectral abscissa (at its speed) is the ``spectral_abscissa`` check;
        default: the first stability family at ``family``'s speed.
    aliases : mapping alias -> id, optional
        Readable names, designable and set in the existing design too; default: every alias of the vehicle
        (element aliases and the file's aliases) that names a parameter of ``family``.
    view : {"lateral", "full"}
        The view of the stability families: ``full`` for an asymmetric vehicle.

    The families of the vehicle's other tracks (:func:`tracks_of`) are the setup's ``other_tracks``: a study's
    ``[stability] tracks`` may constrain them too.
    """
    names = tuple(family.parameters)
    aliases = readable_aliases(vehicle, names) if aliases is None else dict(aliases)
    stability = {track: lateral_family(vehicle, track, names, view) for track in tracks}
    other_tracks = {track: lateral_family(vehicle, track, names, view) for track in tracks_of(vehicle)
                    if track not in stability}
    if abscissa is None:
        abscissa = stability[tracks[0]].with_values(stability[tracks[0]].values, speed=family.speed)
    existing = dict(zip(names, family.values, strict=True))
    existing |= {a: float(existing[k]) for a, k in aliases.items()}
    return ModelSetup(
        family=family,
        parameter_map=ParameterMap(names, family.values, aliases, limits=physical_limits(vehicle, names)),
        named_designs={"existing": existing},
        checks={"spectral_abscissa": AbscissaCheck(abscissa),
                "hunting": HuntingCheck(stability, names, search, max_speed),
                **({"nonlinear_hunting": NonlinearHuntingCheck(vehicle, names, max_speed,
                                                               NonlinearHuntingSpec().analysis(search))}
                   if vehicle.profiles is not None else {})},
        stability=stability,
        other_tracks=other_tracks,
        description=description,
        required_speed=max_speed,
        limits=dict(vehicle.clearances.values),
    )


class HuntingOptions(StrictModel):
    """Options of the ``hunting`` check of a vehicle model."""

    max_operating_speed_m_s: float | None = Field(
        None, gt=0, lt=1000, allow_inf_nan=False,
        description="the hunting check requires stability up to this speed (default: speed_m_s)")
    critical_search_m_s: PositiveInterval = Field((1.0, 150.0),
                                                  description="critical-speed search range of the hunting check, m/s")

    def hunting(self, speed: float) -> tuple[tuple[float, float], float]:
        """(search range, maximum operating speed), m/s."""
        return self.critical_search_m_s, self.max_operating_speed_m_s or speed


class VehicleOptions(HuntingOptions):
    """Options of the ``vehicle_lateral`` model: vehicle file, view, track, forward speed (m/s), output row, overrides.

    With the hunting-check options of :class:`HuntingOptions`; ``output`` defaults to the first coordinate.
    """

    vehicle: str = Field(description=VEHICLE)
    view: Literal["lateral", "full"] = Field(
        "lateral", description="lateral: the (v, alpha, gamma) block of a symmetric vehicle; full: every coordinate "
                               "(a vehicle not symmetric about its centre line: one-sided dampers, worn wheels)")
    track: Literal["rigid", "flexible"] = "rigid"
    speed_m_s: float = Field(30.0, gt=0, lt=1000, allow_inf_nan=False, description="forward speed of `system`")
    output: str | None = Field(None, description="output row of the model (e.g. cab.lateral)")
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


@register_model("vehicle_lateral", VehicleOptions,
                "lateral model (v, α, γ) of a vehicle file with creep; speed-dependent (stability)")
def vehicle_lateral_setup(options: VehicleOptions) -> ModelSetup:
    """The lateral model of a vehicle file; every suspension element is designable by id or alias."""
    vehicle = load(options)
    model = vehicle_view(vehicle, options.view, options.track, options.speed_m_s)
    family = model.family(list(model.parts), outputs=[options.output or model.coordinates[0]])
    return vehicle_setup(vehicle, family, f"{vehicle.name}, {options.view}, {options.track} track", [options.track],
                         *options.hunting(options.speed_m_s), view=stability_view(options.view))


# ---------------------------------------------------------------------------------------------- forced response
class IrregularityOptions(StrictModel):
    """A sinusoidal rail irregularity (:class:`railopt.models.vehicle.irregularity.Irregularity`)."""

    kind: Literal["vertical", "alignment", "cross_level", "lateral"] = "vertical"
    amplitude_m: float = Field(0.00635, gt=0, lt=1.0, allow_inf_nan=False, description="per rail, m")
    rails: Literal["in_phase", "out_of_phase"] | None = None


class VehicleForcedOptions(HuntingOptions):
    """Options of the ``vehicle_forced`` model: a vehicle view forced by a sinusoidal rail irregularity.

    ``view`` vertical, lateral or full (every coordinate: a vehicle not symmetric about its centre line), on rigid
    or flexible ``track`` at ``speed_m_s`` (m/s); ``input`` the irregularity
    (kind, amplitude per rail in m, rail phasing); ``outputs`` coordinates, named rows or body points, as
    ``quantity`` (displacement, velocity or acceleration); ``parameters`` override values of the vehicle file.
    """

    vehicle: str = Field(description=VEHICLE)
    track: Literal["rigid", "flexible"] = "rigid"
    speed_m_s: float = Field(30.0, gt=0, lt=1000, allow_inf_nan=False, description="forward speed S, m/s")
    view: Literal["vertical", "lateral", "full"] = Field(
        "vertical", description="full: every coordinate (a vehicle not symmetric about its centre line)")
    input: IrregularityOptions = Field(default_factory=IrregularityOptions)
    outputs: list[str] = Field(default_factory=lambda: ["body.w"], min_length=1,
                               description="coordinates, named rows or body points '<body>[x,y,z].<x|y|z>'")
    quantity: Literal["displacement", "velocity", "acceleration"] = "displacement"
    parameters: dict[str, float] = Field(default_factory=dict, description="values overriding the vehicle file")


def vehicle_forced_model(options: VehicleForcedOptions):
    """``(vehicle, VehicleView, Irregularity)`` of the options (errors name the option)."""
    from railopt.models.vehicle.irregularity import Irregularity

    vehicle = load(options)
    model = vehicle_view(vehicle, options.view, options.track, options.speed_m_s)
    try:
        irregularity = Irregularity(options.input.kind, options.input.amplitude_m, options.input.rails)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    return vehicle, model, irregularity


@register_model("vehicle_forced", VehicleForcedOptions,
                "a vehicle's vertical or lateral model forced by a delayed sinusoidal rail irregularity "
                "(4.60)-(4.70); outputs as listed, every suspension element designable")
def vehicle_forced_setup(options: VehicleForcedOptions) -> ModelSetup:
    """The forced response as a ParametricSystem in every suspension element (ids), delays declared."""
    vehicle, model, irregularity = vehicle_forced_model(options)
    names = list(model.parts)
    family = model.family(names, input=irregularity, outputs=options.outputs, quantity=options.quantity)
    description = (f"{model.name}, {options.view}, {options.track} track, S = {options.speed_m_s:g} m/s, "
                   f"{irregularity.label}")
    setup = vehicle_setup(vehicle, family, description, [options.track], *options.hunting(options.speed_m_s),
                          abscissa=model.family(names), view=stability_view(options.view))
    setup.units = {r.name: r.unit + UNIT_SUFFIX[options.quantity] for r in output_rows(model, options.outputs)}
    setup.input_label = f"{options.input.amplitude_m * 1000:.4g} mm {options.input.kind} irregularity"
    setup.input_amplitude_m = options.input.amplitude_m
    return setup
