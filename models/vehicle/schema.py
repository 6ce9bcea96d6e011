"""The vehicle file's schema (pydantic v2): which tables and keys exist and of which type.

The schema checks the *shape* of a file: unknown tables and keys are refused with a did-you-mean,
numbers are numbers (or arithmetic strings over ``[lengths]`` and ``[angles_deg]``, evaluated later
by :mod:`railopt.models.vehicle.loader`), booleans are ``true``/``false`` (never ``"no"``), choices
(``kind``, ``type``, ``creep``, ``theory``, ``axis``, ``dofs``) are one of their values.  Values that
need the file's names (positivity, ranges, inertia tensors) are checked by the loader after evaluation.
Every error is one line ``<key path>: <what is wrong>`` (:func:`validate_file`); the loader prefixes
the file.  Units are in the key names (SI): ``_m``, ``_kg``, ``_kg_m2``, ``_N_per_m``, ``_Pa`` ...
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, ValidationError, model_validator

from railopt.models.contact.creep import THEORIES
from railopt.models.vehicle.geometry import DOFS

MAX_EXPRESSION = 200  # characters of an arithmetic string
BODY_KINDS = ("body", "wheelset")
ELEMENT_KINDS = ("spring", "damper", "rotational_spring", "rotational_damper")
VALUE_KEYS = {
    "spring": "stiffness_N_per_m",
    "damper": "damping_N_s_per_m",
    "rotational_spring": "stiffness_N_m_per_rad",
    "rotational_damper": "damping_N_m_s_per_rad",
}
CONSTRAINT_KINDS = ("rigid", "hinge", "fixed")
CREEP_MODES = ("given", "hertz")
AXES = ("x", "y", "z")


def did_you_mean(word: str, options: Sequence[str]) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``options`` (``difflib``), else ``""``."""
    close = difflib.get_close_matches(str(word), [str(o) for o in options], n=1, cutoff=0.6)
    if not close:
        lowered = {str(o).lower(): str(o) for o in options}
        if str(word).lower() in lowered:
            close = [lowered[str(word).lower()]]
    return f"; did you mean {close[0]!r}?" if close else ""


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


# ---------------------------------------------------------------------------------------------- value types
def _num(value: Any) -> float | str:
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError(f"expected a number or an arithmetic expression, got {_short(value)}")
    if isinstance(value, str):
        return value  # evaluated (and bounded to MAX_EXPRESSION characters) by the loader, which names the item
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"number out of range: {_short(value)}") from None


def _bool(value: Any) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"expected true or false, got {_short(value)}")
    return value


def _str(value: Any) -> str:
    if not isinstance(value, str):
        raise ValueError(f"expected a string, got {_short(value)}")
    return value


def _vec(value: Any) -> tuple:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ValueError(f"expected 3 values [x, y, z], got {_short(value)}")
    return tuple(_num(x) for x in value)


def _numbers(value: Any) -> tuple:
    if not isinstance(value, list | tuple):
        raise ValueError(f"expected a list of numbers, got {_short(value)}")
    return tuple(_num(x) for x in value)


def _inertia(value: Any) -> tuple:
    if isinstance(value, list | tuple) and len(value) == 3:
        if all(isinstance(r, list | tuple) for r in value):
            return tuple(_vec(r) for r in value)
        return tuple(_num(x) for x in value)
    raise ValueError(f"must be [Ixx, Iyy, Izz] or a 3x3 tensor (kg m^2), got {_short(value)}")


def _choice(options: Sequence[str]):
    def check(value: Any) -> str:
        if not isinstance(value, str) or value not in options:
            listed = ", ".join(repr(o) for o in options)
            raise ValueError(f"must be one of {listed}, got {_short(value)}{did_you_mean(str(value), options)}")
        return value

    return BeforeValidator(check)


def _dofs(value: Any) -> tuple[str, ...]:
    if not isinstance(value, list | tuple):
        raise ValueError(f"expected a list of coordinates {list(DOFS)}, got {_short(value)}")
    for d in value:
        if d not in DOFS:
            raise ValueError(f"unknown coordinate {_short(d)}; valid: {list(DOFS)}{did_you_mean(str(d), DOFS)}")
    return tuple(value)


Num = Annotated[float | str, BeforeValidator(_num)]
Bool = Annotated[bool, BeforeValidator(_bool)]
Str = Annotated[str, BeforeValidator(_str)]
Vec3 = Annotated[tuple, BeforeValidator(_vec)]
Numbers = Annotated[tuple, BeforeValidator(_numbers)]
Inertia = Annotated[tuple, BeforeValidator(_inertia)]
Dofs = Annotated[tuple, BeforeValidator(_dofs)]
ZERO = (0.0, 0.0, 0.0)


class Strict(BaseModel):
    """Base of every table: unknown keys are errors (with a did-you-mean), values are frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True, arbitrary_types_allowed=True)


# ---------------------------------------------------------------------------------------------- tables
class HeadSchema(Strict):
    """``[vehicle]``."""

    name: Str | None = None
    description: Str = ""


class LengthSchema(Strict):
    """``name = { value = …, source = "…" }`` in ``[lengths]``."""

    value: Num
    source: Str = "estimate"


def _length(value: Any) -> Any:
    if not isinstance(value, dict):
        return _num(value)
    for key in value:
        if key not in LengthSchema.model_fields:
            raise ValueError(f"{key}: unknown key{did_you_mean(key, list(LengthSchema.model_fields))}")
    if "value" not in value:
        raise ValueError("missing value")
    return LengthSchema(value=_num(value["value"]), source=_str(value.get("source", "estimate")))


Length = Annotated[Any, BeforeValidator(_length)]


class CabSchema(Strict):
    """``[cab]``: the cab point (absolute, m), carried by the first body."""

    point_m: Vec3


class BodySchema(Strict):
    """``[[bodies]]``: a rigid body; ``kind`` is required (``"wheelset"`` gets wheel/rail contact)."""

    name: Str
    kind: Annotated[str, _choice(BODY_KINDS)]
    mass_kg: Num
    inertia_kg_m2: Inertia
    cg_m: Vec3
    source: Str = "estimate"


class ElementSchema(Strict):
    """``[[elements]]``: a spring or damper; exactly the value key of its ``type``."""

    id: Str
    alias: Str = ""
    type: Annotated[str, _choice(ELEMENT_KINDS)]
    body_a: Str
    point_a_m: Vec3 = ZERO
    body_b: Str
    point_b_m: Vec3 = ZERO
    direction: Vec3
    stiffness_N_per_m: Num | None = None
    damping_N_s_per_m: Num | None = None
    stiffness_N_m_per_rad: Num | None = None
    damping_N_m_s_per_rad: Num | None = None
    mirror_y: Bool = False
    source: Str = "estimate"

    @model_validator(mode="after")
    def _one_value(self) -> ElementSchema:
        key = VALUE_KEYS[self.type]
        if getattr(self, key) is None:
            raise ValueError(f"missing {key} (value of a {self.type})")
        other = [k for k in VALUE_KEYS.values() if k != key and getattr(self, k) is not None]
        if other:
            raise ValueError(f"{other[0]}: not a key of a {self.type} (its value is {key})")
        return self

    @property
    def value(self) -> float | str:
        """The element's value, read from the key of its type (``stiffness_N_per_m``, ``damping_N_s_per_m``, …)."""
        return getattr(self, VALUE_KEYS[self.type])


class ConstraintSchema(Strict):
    """``[[constraints]]``: ``rigid`` (body, to, dofs), ``hinge`` (body, to, axis, point_m), ``fixed`` (body, dofs)."""

    type: Annotated[str, _choice(CONSTRAINT_KINDS)]
    body: Str
    to: Str = ""
    dofs: Dofs = ()
    axis: Annotated[str, _choice(AXES)] = "y"
    point_m: Vec3 = ZERO

    @model_validator(mode="after")
    def _complete(self) -> ConstraintSchema:
        if self.type in ("rigid", "hinge") and not self.to:
            raise ValueError("missing to")
        if self.type in ("rigid", "fixed") and not self.dofs:
            raise ValueError(f"{self.type} constraint needs dofs")
        return self


class ContactSchema(Strict):
    """``[contact]``: wheel/rail data shared by every wheelset (SI)."""

    conicity: Num | None = None
    delta_r_y_m: Numbers | None = None
    delta_r_m: Numbers | None = None
    amplitude_m: Num | None = None
    wheel_radius_m: Num
    semi_gauge_m: Num
    theta0: Num = 0.0
    epsilon: Num = 0.0
    eta: Num = 0.0
    creep: Annotated[str, _choice(CREEP_MODES)] = "given"
    f11_N: Num | None = None
    f22_N: Num | None = None
    f23_N_m: Num = 0.0
    f33_N_m2: Num = 0.0
    creep_factor: Num = 1.0
    spin: Bool = True
    gravity_stiffness: Bool = True
    axle_load_N: Num | None = None
    youngs_modulus_Pa: Num = 2.07e11
    poisson_ratio: Num = 0.28
    shear_modulus_Pa: Num | None = None
    theory: Annotated[str, _choice(THEORIES)] = "kalker"
    rail_head_radius_m: Num = 0.254
    wheel_transverse_radius_m: Num = math.inf
    source: Str = "estimate"

    @model_validator(mode="after")
    def _complete(self) -> ContactSchema:
        if self.conicity is None and (self.delta_r_m is not None or self.delta_r_y_m is not None):
            # neither conicity nor a table: the conicity comes from [wheel_rail]'s profiles (checked by the loader)
            for key in ("delta_r_y_m", "delta_r_m", "amplitude_m"):
                if getattr(self, key) is None:
                    raise ValueError(f"missing {key} (a Δr table needs delta_r_y_m, delta_r_m and amplitude_m)")
        elif self.delta_r_m is not None or self.delta_r_y_m is not None:
            raise ValueError("give conicity or a Δr table, not both")
        if self.creep == "given":
            for key in ("f11_N", "f22_N"):
                if getattr(self, key) is None:
                    raise ValueError(f"missing {key} (creep = 'given' needs f11_N and f22_N)")
        return self


class WheelRailSchema(Strict):
    """``[wheel_rail]``: the wheel and rail profiles of every wheelset (contact geometry, EN 15302 conicity)."""

    wheel_profile: Str
    rail_profile: Str
    inclination: Num
    gauge_m: Num = 1.435
    flange_back_m: Num = 1.360
    conicity_amplitude_m: Num = 0.003
    friction_coefficient: Num = 0.4
    source: Str = "estimate"


class TrackSchema(Strict):
    """``[track]``: per-rail data of the lumped flexible track."""

    track_modulus_N_m2: Num
    rail_EI_N_m2: Num
    mass_per_length_kg_m: Num
    damping_ratio: Num = 0.1
    source: Str = "estimate"


class VehicleFileSchema(Strict):
    """A whole vehicle file."""

    vehicle: HeadSchema
    lengths: dict[str, Length] = {}
    angles_deg: dict[str, Length] = {}
    clearances: dict[str, Length] = {}
    aliases: dict[str, Str] = {}
    cab: CabSchema | None = None
    bodies: list[BodySchema]
    elements: list[ElementSchema] = []
    constraints: list[ConstraintSchema] = []
    contact: ContactSchema | None = None
    wheel_rail: WheelRailSchema | None = None
    track: TrackSchema | None = None


TABLES: dict[str, type[Strict]] = {
    "vehicle": HeadSchema, "cab": CabSchema, "bodies": BodySchema, "elements": ElementSchema,
    "constraints": ConstraintSchema, "contact": ContactSchema, "wheel_rail": WheelRailSchema, "track": TrackSchema,
    "lengths": LengthSchema,
    "angles_deg": LengthSchema, "clearances": LengthSchema,
}
ARRAYS = ("bodies", "elements", "constraints")
MISSING_HINTS = {"kind": ' (kind = "body" or "wheelset": a wheelset gets wheel/rail contact)',
                 "inclination": ' (the rail inclination as a slope: "1/40", "1/20"; 0 when the rail profile\'s data '
                                'are already inclined)'}


# ---------------------------------------------------------------------------------------------- errors
def item_label(data: Mapping[str, Any], table: str, index: int) -> str:
    """``bodies[0] (wheelset)``, ``elements[3] (K2)``, ``constraints[1]``."""
    key = {"bodies": "name", "elements": "id"}.get(table)
    label = f"{table}[{index}]"
    if key is None:
        return label
    items = data.get(table)
    item = items[index] if isinstance(items, list) and index < len(items) else None
    name = item.get(key, "?") if isinstance(item, dict) else "?"
    return f"{label} ({name})"


def key_path(data: Mapping[str, Any], loc: Sequence[Any]) -> str:
    """The readable path of a pydantic error location: ``bodies[0] (wheelset).cg_m[2]``."""
    loc = [p for p in loc if not (isinstance(p, str) and ("[" in p or p in ("float", "str", "function-before")))]
    out = ""
    i = 0
    while i < len(loc):
        part = loc[i]
        if i == 0 and part in ARRAYS and i + 1 < len(loc) and isinstance(loc[i + 1], int):
            out = item_label(data, part, loc[i + 1])
            i += 2
            continue
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
        i += 1
    return out or "(top level)"


def _allowed(table: Sequence[Any]) -> list[str]:
    """Keys allowed in ``table`` (a location without the unknown key; ``[]`` for the top level)."""
    if not table:
        return list(VehicleFileSchema.model_fields)
    model = TABLES.get(table[0])
    return list(model.model_fields) if model is not None else []


def _message(err: Mapping[str, Any]) -> str:
    msg = str(err["msg"])
    if err["type"] == "value_error":
        msg = msg.removeprefix("Value error, ")
    return msg


def format_errors(data: Mapping[str, Any], exc: ValidationError) -> str:
    """One line per error, ``<key path>: <message>``, unknown keys with a did-you-mean."""
    lines = []
    for err in exc.errors(include_url=False):
        loc = list(err["loc"])
        if err["type"] == "extra_forbidden":
            key = loc[-1]
            where = key_path(data, loc[:-1])
            table = loc[:-1]
            if not table:
                lines.append(f"{key}: unknown table or key at the top level{did_you_mean(key, _allowed([]))}")
                continue
            lines.append(f"{where}.{key}: unknown key{did_you_mean(key, _allowed(table))}")
        elif err["type"] == "missing":
            where = key_path(data, loc[:-1])
            if len(loc) == 1:
                lines.append(f"missing [{loc[0]}] table" if loc[0] != "bodies" else
                             "missing [[bodies]]: a vehicle needs at least one body")
            else:
                lines.append(f"{where}: missing {loc[-1]}{MISSING_HINTS.get(loc[-1], '')}")
        elif err["type"] in ("list_type", "model_type", "dict_type") and len(loc) == 1:
            kind = "an array of tables [[...]]" if loc[0] in ARRAYS else "a table"
            lines.append(f"[{loc[0]}] must be {kind}, got {_short(err.get('input'))}")
        elif _message(err).startswith("must be one of") and loc and isinstance(loc[-1], str):
            lines.append(f"{key_path(data, loc[:-1])}: {loc[-1]} {_message(err)}")
        else:
            lines.append(f"{key_path(data, loc)}: {_message(err)}")
    return "; ".join(dict.fromkeys(lines))


def validate_file(data: Mapping[str, Any]) -> VehicleFileSchema:
    """The file's tables as schema objects; ``ValueError`` (one line per fault, key paths named) otherwise."""
    if not isinstance(data, Mapping):
        raise ValueError(f"a vehicle file is a TOML table, got {type(data).__name__}")
    try:
        return VehicleFileSchema.model_validate(dict(data))
    except ValidationError as exc:
        raise ValueError(format_errors(data, exc)) from None


__all__ = [
    "ARRAYS", "AXES", "BODY_KINDS", "BodySchema", "Bool", "CONSTRAINT_KINDS", "CREEP_MODES", "CabSchema",
    "ConstraintSchema", "ContactSchema", "Dofs", "ELEMENT_KINDS", "ElementSchema", "HeadSchema", "Inertia",
    "Length", "LengthSchema", "MAX_EXPRESSION", "MISSING_HINTS", "Num", "Numbers", "Str", "Strict", "TABLES",
    "TrackSchema", "VALUE_KEYS", "Vec3", "VehicleFileSchema", "WheelRailSchema", "ZERO", "did_you_mean",
    "format_errors", "item_label", "key_path", "validate_file",
]
