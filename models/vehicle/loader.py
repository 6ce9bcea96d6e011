"""Read and validate vehicle files (TOML); schema in ``docs/vehicle.md``.

Numbers in ``cg_m``, ``point_m``, ``point_a_m``, ``point_b_m`` and ``direction`` may be strings
with arithmetic over the file's ``[lengths]`` and ``[angles_deg]`` names (``"l3 + l16"``,
``"cos(alpha1)"``), so the file reads like the thesis's geometry.  Every error is a
:class:`VehicleFileError` naming the item and the file; nothing is written anywhere.
"""

from __future__ import annotations

import ast
import math
import operator
import tomllib
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

from railopt.models.vehicle.bodies import KINDS, Body
from railopt.models.vehicle.elements import ELEMENT_TYPES, GROUND, VALUE_KEYS, Element
from railopt.models.vehicle.spec import ConstraintSpec, ContactSpec, Lengths, TrackSpec
from railopt.models.vehicle.vehicle import Vehicle
from railopt.models.vehicle.wheelrail import Creep

BUNDLED = ("sd40-2", "single-wheelset", "manchester-coach")


class VehicleFileError(ValueError):
    """A vehicle file is invalid; the message names the item and the file."""


_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_FUNCS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "radians": math.radians}


def evaluate(value: Any, names: Mapping[str, float], what: str) -> float:
    """A number, or an arithmetic string over ``names`` (+ − × ÷ **, sin, cos, tan, sqrt, radians)."""
    if isinstance(value, bool):
        raise ValueError(f"{what}: expected a number, got {value!r}")
    if isinstance(value, int | float):
        x = float(value)
    elif isinstance(value, str):
        try:
            x = float(_eval(ast.parse(value, mode="eval").body, names))
        except (SyntaxError, KeyError, TypeError, ZeroDivisionError) as exc:
            raise ValueError(f"{what}: cannot evaluate {value!r} ({exc})") from None
    else:
        raise ValueError(f"{what}: expected a number or an expression, got {value!r}")
    if not math.isfinite(x):
        raise ValueError(f"{what}: must be finite, got {value!r}")
    return x


def _eval(node: ast.AST, names: Mapping[str, float]) -> float:
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float) and not isinstance(node.value, bool):
        return node.value
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise KeyError(f"unknown length or angle {node.id!r}")
        return names[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return _BINOPS[type(node.op)](_eval(node.left, names), _eval(node.right, names))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        x = _eval(node.operand, names)
        return -x if isinstance(node.op, ast.USub) else x
    call = isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and len(node.args) == 1
    if call and node.func.id in _FUNCS:
        return _FUNCS[node.func.id](_eval(node.args[0], names))
    raise TypeError(f"unsupported expression element {ast.dump(node)[:40]}")


def bundled_path(name: str) -> Path:
    """Path of a bundled vehicle file (``"sd40-2"``, ``"single-wheelset"``, ``"manchester-coach"``)."""
    return Path(str(resources.files("railopt.models.vehicle") / "data" / f"{name}.toml"))


def load_vehicle(name_or_path: str | Path, lengths: Mapping[str, float] | None = None) -> Vehicle:
    """Load a bundled vehicle by name or a vehicle file by path.

    Parameters
    ----------
    name_or_path : str or Path
        One of :data:`BUNDLED` or a path to a ``.toml`` file.
    lengths : mapping, optional
        Overrides of ``[lengths]`` entries (m) before the geometry is evaluated.

    Raises
    ------
    VehicleFileError
        Unknown name, unreadable file or invalid content (the message names the item and file).
    """
    if isinstance(name_or_path, str) and name_or_path in BUNDLED:
        path = bundled_path(name_or_path)
    else:
        path = Path(name_or_path)
        if not path.is_file():
            raise VehicleFileError(f"{name_or_path}: no such vehicle file; bundled vehicles: {', '.join(BUNDLED)}")
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise VehicleFileError(f"{path}: cannot read vehicle file ({exc})") from None
    try:
        return parse_vehicle(data, str(path), lengths)
    except VehicleFileError:
        raise
    except ValueError as exc:
        raise VehicleFileError(f"{path}: {exc}") from None


def _table(data: Mapping[str, Any], key: str, required: bool = True) -> dict[str, Any]:
    t = data.get(key)
    if t is None:
        if required:
            raise ValueError(f"missing [{key}] table")
        return {}
    if not isinstance(t, dict):
        raise ValueError(f"[{key}] must be a table")
    return t


def _named_values(table: Mapping[str, Any], what: str) -> tuple[dict[str, float], dict[str, str]]:
    values, sources = {}, {}
    for k, v in table.items():
        if isinstance(v, dict):
            sources[k] = str(v.get("source", "estimate"))
            v = v.get("value")
        values[k] = evaluate(v, {}, f"{what}.{k}")
    return values, sources


def parse_vehicle(data: Mapping[str, Any], path: str = "<memory>",
                  length_overrides: Mapping[str, float] | None = None) -> Vehicle:
    """Build a :class:`Vehicle` from parsed TOML ``data`` (errors raise ValueError naming the item)."""
    head = _table(data, "vehicle")
    name = str(head.get("name", Path(path).stem))
    lengths, lsources = _named_values(_table(data, "lengths", required=False), "lengths")
    for k, v in (length_overrides or {}).items():
        if k not in lengths:
            raise ValueError(f"lengths: unknown override {k!r}; defined: {sorted(lengths)}")
        lengths[k] = evaluate(v, {}, f"lengths.{k}")
    angles, _ = _named_values(_table(data, "angles_deg", required=False), "angles_deg")
    names = dict(lengths)
    names.update({k: math.radians(v) for k, v in angles.items()})

    bodies = [_body(i, b, names) for i, b in enumerate(_list(data, "bodies"))]
    if not bodies:
        raise ValueError("no [[bodies]]: a vehicle needs at least one body")
    body_names = [b.name for b in bodies]
    dup = {n for n in body_names if body_names.count(n) > 1}
    if dup:
        raise ValueError(f"bodies: duplicate names {sorted(dup)}")
    known = set(body_names)

    elements: list[Element] = []
    for i, e in enumerate(_list(data, "elements", required=False)):
        el, mirror = _element(i, e, names, known)
        elements.append(el)
        if mirror:
            elements.append(el.mirrored_y())
    values: dict[str, float] = {}
    for e in elements:
        if values.setdefault(e.id, e.value) != e.value:
            raise ValueError(f"elements: id {e.id!r} given two values ({values[e.id]} and {e.value})")

    constraints = [_constraint(i, c, names, known) for i, c in enumerate(_list(data, "constraints", required=False))]
    contact = _contact(_table(data, "contact", required=False), names)
    if contact is None and any(b.kind == "wheelset" for b in bodies):
        raise ValueError("missing [contact] table: the vehicle has wheelsets")
    track = _track(_table(data, "track", required=False))
    cab = _table(data, "cab", required=False)
    cab_point = _vector(cab["point_m"], names, "cab.point_m") if "point_m" in cab else None

    vehicle = Vehicle(name=name, description=str(head.get("description", "")), bodies=tuple(bodies),
                      elements=tuple(elements), constraints=tuple(constraints), contact=contact, track=track,
                      cab_point=cab_point, lengths=Lengths(lengths, lsources), aliases={}, path=path)
    aliases = {str(k): str(v) for k, v in _table(data, "aliases", required=False).items()}
    valid = set(vehicle.parameter_names())
    for k, v in aliases.items():
        if v not in valid:
            raise ValueError(f"aliases.{k}: unknown parameter {v!r}; valid: {', '.join(sorted(valid))}")
    return Vehicle(**{**vehicle.__dict__, "aliases": aliases, "_cache": {}})


def _list(data: Mapping[str, Any], key: str, required: bool = True) -> list[dict[str, Any]]:
    v = data.get(key, [])
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise ValueError(f"[[{key}]] must be an array of tables")
    if required and not v:
        raise ValueError(f"missing [[{key}]]")
    return v


def _vector(v: Any, names: Mapping[str, float], what: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise ValueError(f"{what}: expected 3 values [x, y, z], got {v!r}")
    return tuple(evaluate(x, names, f"{what}[{i}]") for i, x in enumerate(v))


def _number(t: Mapping[str, Any], key: str, what: str, default: float | None = None, positive: bool = False,
            names: Mapping[str, float] | None = None) -> float:
    if key not in t:
        if default is None:
            raise ValueError(f"{what}: missing {key}")
        return default
    x = evaluate(t[key], names or {}, f"{what}.{key}")
    if positive and x <= 0.0:
        raise ValueError(f"{what}.{key}: must be positive, got {x!r}")
    return x


def _body(i: int, b: Mapping[str, Any], names: Mapping[str, float]) -> Body:
    label = f"bodies[{i}] ({b.get('name', '?')})"
    if "name" not in b:
        raise ValueError(f"{label}: missing name")
    mass = _number(b, "mass_kg", label)
    if mass <= 0.0:
        raise ValueError(f"{label}: mass_kg must be positive, got {mass!r}")
    inertia = b.get("inertia_kg_m2")
    if isinstance(inertia, list) and len(inertia) == 3 and all(isinstance(r, list) for r in inertia):
        inertia = [[evaluate(x, names, f"{label}.inertia_kg_m2") for x in row] for row in inertia]  # 3x3 tensor
        diagonal = [inertia[i][i] for i in range(3)]
    elif isinstance(inertia, list) and len(inertia) == 3:
        inertia = diagonal = [evaluate(x, names, f"{label}.inertia_kg_m2") for x in inertia]
    else:
        raise ValueError(f"{label}: inertia_kg_m2 must be [Ixx, Iyy, Izz] or a 3x3 tensor")
    if any(x < 0.0 for x in diagonal):
        raise ValueError(f"{label}: inertia_kg_m2 must be >= 0")
    kind = str(b.get("kind", "body"))
    if kind not in KINDS[:2]:
        raise ValueError(f"{label}: kind must be 'body' or 'wheelset', got {kind!r}")
    return Body(str(b["name"]), mass, tuple(inertia), _vector(b.get("cg_m"), names, f"{label}.cg_m"), kind,
                str(b.get("source", "estimate")))


def _element(i: int, e: Mapping[str, Any], names: Mapping[str, float], known: set[str]) -> tuple[Element, bool]:
    label = f"elements[{i}] ({e.get('id', '?')})"
    for key in ("id", "type", "body_a", "body_b"):
        if key not in e:
            raise ValueError(f"{label}: missing {key}")
    etype = str(e["type"])
    if etype not in ELEMENT_TYPES:
        raise ValueError(f"{label}: type must be one of {sorted(ELEMENT_TYPES)}, got {etype!r}")
    for key in ("body_a", "body_b"):
        if e[key] != GROUND and e[key] not in known:
            raise ValueError(f"{label}: {key} {e[key]!r} is not a body (bodies: {sorted(known)}, or 'ground')")
    if e["body_a"] == GROUND:
        raise ValueError(f"{label}: body_a must be a body ('ground' only as body_b)")
    vkey = VALUE_KEYS[etype]
    if vkey not in e:
        raise ValueError(f"{label}: missing {vkey} (value of a {etype})")
    value = _number(e, vkey, label)
    if value < 0.0:
        raise ValueError(f"{label}: {vkey} must be >= 0, got {value!r}")
    zero = [0.0, 0.0, 0.0]
    el = Element(id=str(e["id"]), alias=str(e.get("alias", "")), type=etype, body_a=str(e["body_a"]),
                 point_a=_vector(e.get("point_a_m", zero), names, f"{label}.point_a_m"), body_b=str(e["body_b"]),
                 point_b=_vector(e.get("point_b_m", zero), names, f"{label}.point_b_m"),
                 direction=_vector(e.get("direction"), names, f"{label}.direction"), value=value,
                 source=str(e.get("source", "estimate")))
    return el, bool(e.get("mirror_y", False))


def _constraint(i: int, c: Mapping[str, Any], names: Mapping[str, float], known: set[str]) -> ConstraintSpec:
    label = f"constraints[{i}]"
    for key in ("type", "body"):
        if key not in c:
            raise ValueError(f"{label}: missing {key}")
    for key in ("body", "to"):
        if key in c and c[key] not in known:
            raise ValueError(f"{label}: {key} {c[key]!r} is not a body (bodies: {sorted(known)})")
    if c["type"] in ("rigid", "hinge") and "to" not in c:
        raise ValueError(f"{label}: missing to")
    if c["type"] == "rigid" and not c.get("dofs"):
        raise ValueError(f"{label}: rigid constraint needs dofs")
    return ConstraintSpec(type=str(c["type"]), body=str(c["body"]), to=str(c.get("to", "")),
                          dofs=tuple(c.get("dofs", ())), axis=str(c.get("axis", "y")),
                          point=_vector(c.get("point_m", [0, 0, 0]), names, f"{label}.point_m"))


def _contact(t: Mapping[str, Any], names: Mapping[str, float]) -> ContactSpec | None:
    if not t:
        return None
    what = "contact"
    r0 = _number(t, "wheel_radius_m", what, positive=True, names=names)
    e0 = _number(t, "semi_gauge_m", what, positive=True, names=names)
    if "conicity" in t:
        lam = _number(t, "conicity", what)
    elif "delta_r_m" in t:
        from railopt.models.contact import equivalent_conicity

        if "delta_r_y_m" not in t:
            raise ValueError("contact: a Δr table needs delta_r_y_m (lateral positions) with delta_r_m")
        lam = equivalent_conicity(t["delta_r_y_m"], t["delta_r_m"], _number(t, "amplitude_m", what, positive=True),
                                  r0=r0, e0=e0)
    else:
        raise ValueError("contact: give conicity or a Δr table (delta_r_y_m, delta_r_m, amplitude_m)")
    if lam < 0.0:
        raise ValueError(f"contact.conicity must be >= 0, got {lam!r}")
    mode = str(t.get("creep", "given"))
    coeffs = None
    if mode == "given":
        coeffs = Creep(_number(t, "f11_N", what, positive=True), _number(t, "f22_N", what, positive=True),
                       _number(t, "f23_N_m", what, 0.0), _number(t, "f33_N_m2", what, 0.0))
    load = _number(t, "axle_load_N", what, positive=True) if "axle_load_N" in t else None
    return ContactSpec(
        r0=r0, e0=e0, conicity=lam, theta0=_number(t, "theta0", what, 0.0), epsilon=_number(t, "epsilon", what, 0.0),
        eta=_number(t, "eta", what, 0.0), creep=mode, coefficients=coeffs,
        creep_factor=_number(t, "creep_factor", what, 1.0, positive=True), spin=bool(t.get("spin", True)),
        gravity_stiffness=bool(t.get("gravity_stiffness", True)), axle_load=load,
        youngs_modulus=_number(t, "youngs_modulus_Pa", what, 2.07e11, positive=True),
        poisson_ratio=_number(t, "poisson_ratio", what, 0.28),
        shear_modulus=_number(t, "shear_modulus_Pa", what, positive=True) if "shear_modulus_Pa" in t else None,
        theory=str(t.get("theory", "kalker")),
        rail_head_radius=_number(t, "rail_head_radius_m", what, 0.254, positive=True),
        wheel_transverse_radius=_number(t, "wheel_transverse_radius_m", what, math.inf, positive=True),
        source=str(t.get("source", "estimate")),
    )


def _track(t: Mapping[str, Any]) -> TrackSpec | None:
    if not t:
        return None
    what = "track"
    return TrackSpec(track_modulus=_number(t, "track_modulus_N_m2", what, positive=True),
                     rail_EI=_number(t, "rail_EI_N_m2", what, positive=True),
                     mass_per_length=_number(t, "mass_per_length_kg_m", what, positive=True),
                     damping_ratio=_number(t, "damping_ratio", what, 0.1), source=str(t.get("source", "estimate")))
