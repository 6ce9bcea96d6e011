"""Read and validate vehicle files (TOML); schema in ``docs/vehicle.md`` and :mod:`.schema`.

Numbers in ``cg_m``, ``point_m``, ``point_a_m``, ``point_b_m``, ``direction``, masses, inertias and
contact values may be strings with arithmetic over the file's ``[lengths]`` and ``[angles_deg]`` names
(``"l3 + l16"``, ``"cos(alpha1)"``), so the file reads like the thesis's geometry.  The shape of the
file (tables, keys, types) is checked by :func:`railopt.models.vehicle.schema.validate_file`; values
after evaluation here.  Every error is one :class:`VehicleFileError` ``<file>: <key path>: <what>``;
nothing is written anywhere.  Warnings about values that load but look wrong (units, magnitudes):
:func:`railopt.models.vehicle.plausibility.plausibility`.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.elements import GROUND, Element
from railopt.models.vehicle.schema import (
    MAX_EXPRESSION,
    VALUE_KEYS,
    BodySchema,
    ContactSchema,
    ElementSchema,
    LengthSchema,
    TrackSchema,
    VehicleFileSchema,
    WheelRailSchema,
    did_you_mean,
    validate_file,
)
from railopt.models.vehicle.spec import ConstraintSpec, ContactSpec, Lengths, TrackSpec, WheelRailSpec
from railopt.models.vehicle.vehicle import Vehicle
from railopt.models.vehicle.wheelrail import Creep
from railopt.tomlfile import read_toml

_LISTED_FIRST = ("sd40-2", "single-wheelset", "manchester-coach")
"""Listing order of the first bundled vehicles in messages (the flagship first); not a registry: a file in
``data/`` is bundled whether or not it is named here, and a name here without its file is not."""


def bundled_vehicles() -> tuple[str, ...]:
    """Names of the bundled vehicles: the stems of the ``data/*.toml`` files shipped with this package (a new
    bundled vehicle is one file there), listed in :data:`_LISTED_FIRST` order, then by name."""
    data = resources.files("railopt.models.vehicle") / "data"
    names = {f.name.removesuffix(".toml") for f in data.iterdir() if f.is_file() and f.name.endswith(".toml")}
    first = {n: i for i, n in enumerate(_LISTED_FIRST)}
    return tuple(sorted(names, key=lambda n: (first.get(n, len(first)), n)))


BUNDLED = bundled_vehicles()
"""The bundled vehicle names (:func:`bundled_vehicles`), read once at import."""
MAX_DEPTH = 32  # nesting of an arithmetic expression
INERTIA_RTOL = 1e-9  # eigenvalues of an inertia tensor below this fraction of the largest count as zero
MASS_RTOL = 1e-9  # a body's mass (its smallest moment) below this fraction of the vehicle's largest: refused
# (the state matrix refuses a mass matrix whose LU pivots fall below 1e-14 of the largest: models/system.py)


class VehicleFileError(ValueError):
    """A vehicle file is invalid; the message names the item and the file."""


def _pow(a: float, b: float) -> float:
    return math.pow(a, b)  # float power: OverflowError or a domain ValueError, never a complex or a huge int


_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: _pow}
_FUNCS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "radians": math.radians}
_FAULTS = (SyntaxError, KeyError, TypeError, ZeroDivisionError, OverflowError, RecursionError, MemoryError, ValueError)


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def evaluate(value: Any, names: Mapping[str, float], what: str) -> float:
    """A number, or an arithmetic string over ``names`` (+ − × ÷ **, sin, cos, tan, sqrt, radians).

    Raises a ``ValueError`` naming ``what`` for anything else: an unknown name, a result that is not finite,
    an overflow (``"10.0 ** 400"``), a math domain error (``"sqrt(-1)"``), an expression longer than 200
    characters or nested deeper than 32 levels.
    """
    if isinstance(value, bool):
        raise ValueError(f"{what}: expected a number, got {value!r}")
    if isinstance(value, int | float):
        try:
            x = float(value)
        except OverflowError:
            raise ValueError(f"{what}: number out of range {_short(value)}") from None
    elif isinstance(value, str):
        try:
            if len(value) > MAX_EXPRESSION:
                raise ValueError(f"expression longer than {MAX_EXPRESSION} characters")
            x = float(_eval(ast.parse(value.strip(), mode="eval").body, names, 0))
        except _FAULTS as exc:
            reason = {OverflowError: "result out of range", RecursionError: "nested too deeply",
                      MemoryError: "too large"}.get(type(exc)) or str(exc.args[0] if exc.args else exc)
            raise ValueError(f"{what}: cannot evaluate {_short(value)} ({reason})") from None
    else:
        raise ValueError(f"{what}: expected a number or an expression, got {_short(value)}")
    if not math.isfinite(x):
        raise ValueError(f"{what}: must be finite, got {_short(value)}")
    return x


def _eval(node: ast.AST, names: Mapping[str, float], depth: int) -> float:
    if depth > MAX_DEPTH:
        raise ValueError(f"nested deeper than {MAX_DEPTH} levels")
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float) and not isinstance(node.value, bool):
        return float(node.value)
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise KeyError(f"unknown length or angle {node.id!r}{did_you_mean(node.id, list(names))}")
        return names[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return _BINOPS[type(node.op)](_eval(node.left, names, depth + 1), _eval(node.right, names, depth + 1))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        x = _eval(node.operand, names, depth + 1)
        return -x if isinstance(node.op, ast.USub) else x
    call = (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and len(node.args) == 1
            and not node.keywords)
    if call and node.func.id in _FUNCS:
        return _FUNCS[node.func.id](_eval(node.args[0], names, depth + 1))
    raise TypeError(f"unsupported expression element {ast.dump(node)[:40]}")


def bundled_path(name: str) -> Path:
    """Path of a bundled vehicle file (``"sd40-2"``, ``"single-wheelset"``, ``"manchester-coach"``)."""
    return Path(str(resources.files("railopt.models.vehicle") / "data" / f"{name}.toml"))


def read_vehicle_file(name_or_path: str | Path) -> tuple[dict[str, Any], str]:
    """The parsed TOML of a bundled name or a path, and the path as text (errors name the file)."""
    if isinstance(name_or_path, str) and name_or_path in BUNDLED:
        path = bundled_path(name_or_path)
    else:
        path = Path(name_or_path)
        if not path.is_file():
            raise VehicleFileError(f"{name_or_path}: no such vehicle file; bundled vehicles: {', '.join(BUNDLED)}")
    try:
        return read_toml(path, "vehicle file"), str(path)
    except ValueError as exc:
        raise VehicleFileError(str(exc)) from None


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
        Unknown name, unreadable or non-UTF-8 file, or invalid content: ``<file>: <key path>: <what>``.
    """
    data, path = read_vehicle_file(name_or_path)
    return parse_vehicle(data, path, lengths)


def parse_vehicle(data: Mapping[str, Any], path: str = "<memory>",
                  length_overrides: Mapping[str, float] | None = None) -> Vehicle:
    """Build a :class:`Vehicle` from parsed TOML ``data``.

    Raises
    ------
    VehicleFileError
        ``<path>: <key path>: <what>`` (a ``ValueError``).
    """
    try:
        return _parse(data, path, length_overrides)
    except VehicleFileError:
        raise
    except ValueError as exc:
        raise VehicleFileError(f"{path}: {exc}") from None


def _parse(data: Mapping[str, Any], path: str, length_overrides: Mapping[str, float] | None) -> Vehicle:
    f = validate_file(data)
    name = f.vehicle.name or Path(path).stem
    lengths, lsources = _named_values(f.lengths, "lengths")
    for k, v in (length_overrides or {}).items():
        if k not in lengths:
            raise ValueError(f"lengths: unknown override {k!r}{did_you_mean(k, list(lengths))}; "
                             f"defined: {sorted(lengths)}")
        lengths[k] = evaluate(v, {}, f"lengths.{k}")
    angles, _ = _named_values(f.angles_deg, "angles_deg")
    clash = sorted(set(lengths) & set(angles))
    if clash:
        raise ValueError(f"angles_deg.{clash[0]}: also defined in [lengths]")
    names = dict(lengths)
    names.update({k: math.radians(v) for k, v in angles.items()})

    if not f.bodies:
        raise ValueError("no [[bodies]]: a vehicle needs at least one body")
    bodies = [_body(i, b, names) for i, b in enumerate(f.bodies)]
    _check_inertia_scale(bodies)
    body_names = [b.name for b in bodies]
    dup = {n for n in body_names if body_names.count(n) > 1}
    if dup:
        raise ValueError(f"bodies: duplicate names {sorted(dup)}")
    known = set(body_names)

    elements: list[Element] = []
    for i, e in enumerate(f.elements):
        elements += _element(i, e, names, known)
    _check_ids(f, elements)

    constraints = [_constraint(i, c, names, known) for i, c in enumerate(f.constraints)]
    profiles = _wheel_rail(f.wheel_rail, names, path)
    contact = _contact(f.contact, names, profiles)
    if contact is None and any(b.kind == "wheelset" for b in bodies):
        raise ValueError("missing [contact] table: the vehicle has wheelsets")
    track = _track(f.track, names)
    cab_point = _vector(f.cab.point_m, names, "cab.point_m") if f.cab is not None else None

    vehicle = Vehicle(name=name, description=f.vehicle.description, bodies=tuple(bodies),
                      elements=tuple(elements), constraints=tuple(constraints), contact=contact, track=track,
                      profiles=profiles,
                      cab_point=cab_point, lengths=Lengths(lengths, lsources),
                      clearances=_clearances(f.clearances), aliases={}, path=path)
    _check_aliases(vehicle, f.aliases)
    vehicle = Vehicle(**{**vehicle.__dict__, "aliases": dict(f.aliases), "_cache": {}})
    _check_contact(vehicle)
    return vehicle


def _named_values(table: Mapping[str, Any], what: str) -> tuple[dict[str, float], dict[str, str]]:
    values, sources = {}, {}
    for k, v in table.items():
        if not k.isidentifier() or k in _FUNCS:
            raise ValueError(f"{what}.{k}: a name must be an identifier other than {sorted(_FUNCS)}")
        if isinstance(v, LengthSchema):
            sources[k] = v.source
            v = v.value
        values[k] = evaluate(v, {}, f"{what}.{k}")
    return values, sources


def _vector(v: Any, names: Mapping[str, float], what: str) -> tuple[float, float, float]:
    return tuple(evaluate(x, names, f"{what}[{i}]") for i, x in enumerate(v))


def _body(i: int, b: BodySchema, names: Mapping[str, float]) -> Body:
    label = f"bodies[{i}] ({b.name})"
    mass = evaluate(b.mass_kg, names, f"{label}.mass_kg")
    if mass <= 0.0:
        raise ValueError(f"{label}: mass_kg must be positive, got {mass!r}")
    what = f"{label}.inertia_kg_m2"
    if isinstance(b.inertia_kg_m2[0], tuple):
        tensor = np.array([[evaluate(x, names, f"{what}[{r}][{c}]") for c, x in enumerate(row)]
                           for r, row in enumerate(b.inertia_kg_m2)])
        if not np.allclose(tensor, tensor.T, rtol=1e-12, atol=0.0):
            raise ValueError(f"{what}: not symmetric (Ixy, Ixz, Iyz must equal Iyx, Izx, Izy)")
    else:
        tensor = np.diag([evaluate(x, names, f"{what}[{k}]") for k, x in enumerate(b.inertia_kg_m2)])
    if np.any(np.diag(tensor) < 0.0):
        raise ValueError(f"{what}: must be >= 0 on the diagonal, got {np.diag(tensor).tolist()}")
    eig = np.linalg.eigvalsh(tensor)
    scale = float(np.max(np.abs(eig)))
    if eig[0] < -INERTIA_RTOL * scale:
        raise ValueError(f"{what}: not positive semi-definite (principal moments {_moments(eig)} kg m^2; "
                         "a product of inertia exceeds what the moments allow, e.g. Ixz^2 > Ixx Izz)")
    if eig[0] <= INERTIA_RTOL * scale:
        raise ValueError(f"{what}: singular inertia tensor (principal moments {_moments(eig)} kg m^2): every "
                         "rotation of a body needs inertia")
    inertia = tuple(map(tuple, tensor)) if isinstance(b.inertia_kg_m2[0], tuple) else tuple(np.diag(tensor))
    return Body(b.name, mass, inertia, _vector(b.cg_m, names, f"{label}.cg_m"), b.kind, b.source)


def _check_inertia_scale(bodies: list[Body]) -> None:
    """Every body's mass and principal moments at least :data:`MASS_RTOL` of the vehicle's largest: a body (nearly)
    without mass or inertia leaves the mass matrix singular and every analysis refuses it later, naming no body."""
    heaviest = max(bodies, key=lambda b: b.mass)
    moments = {b.name: np.linalg.eigvalsh(np.asarray(b.inertia)) for b in bodies}
    largest = max(bodies, key=lambda b: moments[b.name][-1])
    for i, b in enumerate(bodies):
        label = f"bodies[{i}] ({b.name})"
        if b.mass < MASS_RTOL * heaviest.mass:
            raise ValueError(f"{label}.mass_kg: {b.mass:g} kg is {b.mass / heaviest.mass:.3g} of the heaviest body "
                             f"({heaviest.name}, {heaviest.mass:g} kg): a body without mass makes the mass matrix "
                             "singular; the unit is kg")
        if moments[b.name][0] < MASS_RTOL * moments[largest.name][-1]:
            raise ValueError(f"{label}.inertia_kg_m2: principal moments {_moments(moments[b.name])} kg m^2, the "
                             f"smallest {moments[b.name][0] / moments[largest.name][-1]:.3g} of the largest moment of "
                             f"the vehicle ({largest.name}, {moments[largest.name][-1]:.4g} kg m^2): a rotation "
                             "without inertia makes the mass matrix singular; the unit is kg m^2")


def _clearances(table: Mapping[str, Any]) -> Lengths:
    """The ``[clearances]``: each a free travel before a stop, positive (a stroke limit ≤ 0 admits no design)."""
    values, sources = _named_values(table, "clearances")
    for k, x in values.items():
        if not x > 0.0:
            raise ValueError(f"clearances.{k}: must be positive (a free travel before a stop, m), got {x!r}: a limit "
                             "≤ 0 on a stroke makes every design infeasible")
    return Lengths(values, sources)


def _moments(eig: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.4g}" for x in eig) + "]"


def _element(i: int, e: ElementSchema, names: Mapping[str, float], known: set[str]) -> list[Element]:
    label = f"elements[{i}] ({e.id})"
    for key in ("body_a", "body_b"):
        b = getattr(e, key)
        if b != GROUND and b not in known:
            raise ValueError(f"{label}: {key} {b!r} is not a body{did_you_mean(b, sorted(known) + [GROUND])} "
                             f"(bodies: {sorted(known)}, or 'ground')")
    if e.body_a == GROUND:
        raise ValueError(f"{label}: body_a must be a body ('ground' only as body_b)")
    if e.body_a == e.body_b:
        raise ValueError(f"{label}: body_a and body_b are both {e.body_a!r}")
    key = f"{label}.{VALUE_KEYS[e.type]}"
    value = evaluate(e.value, names, key)
    if value < 0.0:
        raise ValueError(f"{key}: must be >= 0, got {value!r}")
    pa = _vector(e.point_a_m, names, f"{label}.point_a_m")
    pb = _vector(e.point_b_m, names, f"{label}.point_b_m")
    try:
        el = Element(id=e.id, alias=e.alias, type=e.type, body_a=e.body_a, point_a=pa, body_b=e.body_b, point_b=pb,
                     direction=_vector(e.direction, names, f"{label}.direction"), value=value, source=e.source)
    except ValueError as exc:
        raise ValueError(f"{label}: {exc}") from None
    if not e.mirror_y:
        return [el]
    if pa[1] == 0.0 and pb[1] == 0.0:
        raise ValueError(f"{label}.mirror_y: the element lies at y = 0 (point_a_m[1] = point_b_m[1] = 0), so its "
                         "mirror image is itself and mirror_y would double it under one id; give the whole value "
                         "without mirror_y")
    return [el, el.mirrored_y()]


def _check_ids(f: VehicleFileSchema, elements: list[Element]) -> None:
    """One value and one alias per id; an element alias is not another element's id."""
    values: dict[str, float] = {}
    alias_of: dict[str, str] = {}
    for e in elements:
        if values.setdefault(e.id, e.value) != e.value:
            raise ValueError(f"elements: id {e.id!r} given two values ({values[e.id]} and {e.value})")
    ids = set(values)
    for i, e in enumerate(f.elements):
        if not e.alias:
            continue
        if e.alias in ids and e.alias != e.id:
            raise ValueError(f"elements[{i}] ({e.id}).alias: {e.alias!r} is the id of another element")
        if alias_of.setdefault(e.alias, e.id) != e.id:
            raise ValueError(f"elements[{i}] ({e.id}).alias: {e.alias!r} already names element "
                             f"{alias_of[e.alias]!r}")


def _check_aliases(vehicle: Vehicle, aliases: Mapping[str, str]) -> None:
    """An ``[aliases]`` name is new (not a parameter name) and points at a parameter."""
    valid = vehicle.parameter_names()
    ids = set(vehicle.element_ids())
    for k, v in aliases.items():
        if k in valid:
            what = "the element id" if k in ids else "the parameter"
            raise ValueError(f"aliases.{k}: shadows {what} {k!r} (an alias must not be a parameter name); "
                             f"pick another name")
        if v not in valid:
            raise ValueError(f"aliases.{k}: unknown parameter {v!r}{did_you_mean(v, valid)}; "
                             f"valid: {', '.join(sorted(valid))}")


def _constraint(i: int, c: Any, names: Mapping[str, float], known: set[str]) -> ConstraintSpec:
    label = f"constraints[{i}]"
    for key in ("body", "to"):
        b = getattr(c, key)
        if (key == "body" or b) and b not in known:
            raise ValueError(f"{label}: {key} {b!r} is not a body{did_you_mean(b, sorted(known))} "
                             f"(bodies: {sorted(known)})")
    return ConstraintSpec(type=c.type, body=c.body, to=c.to, dofs=tuple(c.dofs), axis=c.axis,
                          point=_vector(c.point_m, names, f"{label}.point_m"))


def _num(t: Any, key: str, names: Mapping[str, float], table: str, positive: bool = False,
         lower: float | None = None, upper: float | None = None) -> float:
    what = f"{table}.{key}"
    raw = getattr(t, key)
    x = math.inf if key == "wheel_transverse_radius_m" and raw == math.inf else evaluate(raw, names, what)
    if positive and not x > 0.0:
        raise ValueError(f"{what}: must be positive, got {x!r}")
    if lower is not None and x < lower:
        raise ValueError(f"{what}: must be >= {lower}, got {x!r}")
    if upper is not None and x > upper:
        raise ValueError(f"{what}: must be <= {upper}, got {x!r}")
    return x


def _wheel_rail(t: WheelRailSchema | None, names: Mapping[str, float], path: str) -> WheelRailSpec | None:
    """``[wheel_rail]``: numbers evaluated, each profile a catalogue name or a file (relative to the vehicle file),
    loaded once here so that a wrong name or a bad file is an error naming its key."""
    if t is None:
        return None
    from railopt.models.contact import PROFILE_NAMES, load_profile
    from railopt.models.contact.profiles import is_profile_name

    sources = {}
    for key, kind in (("wheel_profile", "wheel"), ("rail_profile", "rail")):
        raw = getattr(t, key)
        if is_profile_name(raw):
            source = raw
        else:
            where = Path(raw) if Path(raw).is_absolute() else Path(path).resolve().parent / raw
            if not where.is_file():
                raise ValueError(f"wheel_rail.{key}: {raw!r} is neither a profile name ({', '.join(PROFILE_NAMES)}) "
                                 f"nor a file (looked for {where})")
            source = str(where)
        try:
            load_profile(source, kind)
        except ValueError as exc:
            raise ValueError(f"wheel_rail.{key}: {exc}") from None
        sources[key] = source
    inclination = _num(t, "inclination", names, "wheel_rail", lower=0.0, upper=0.1)
    return WheelRailSpec(
        wheel_profile=sources["wheel_profile"], rail_profile=sources["rail_profile"], inclination=inclination,
        gauge=_num(t, "gauge_m", names, "wheel_rail", lower=1.0, upper=2.0),
        flange_back=_num(t, "flange_back_m", names, "wheel_rail", lower=0.9, upper=2.0),
        conicity_amplitude=_num(t, "conicity_amplitude_m", names, "wheel_rail", positive=True, upper=0.012),
        friction_coefficient=_num(t, "friction_coefficient", names, "wheel_rail", positive=True, upper=1.0),
        source=t.source)


def _profile_conicity(profiles: WheelRailSpec, r0: float, e0: float) -> float:
    """The EN 15302 equivalent conicity of the ``[wheel_rail]`` profile pair at its ``conicity_amplitude``, from
    the pair's 0.1 mm rigid-contact table (:meth:`WheelRailSpec.table`, the one ``Vehicle.contact_table`` gives)."""
    from railopt.models.contact import equivalent_conicity

    try:
        table = profiles.table(r0, max(0.012, 2.0 * profiles.conicity_amplitude))
    except ValueError as exc:
        raise ValueError(f"wheel_rail: the profiles cannot be placed on the track ({exc})") from None
    try:
        return equivalent_conicity(table.y, table.delta_r, profiles.conicity_amplitude, r0=r0, e0=e0)
    except ValueError as exc:
        raise ValueError(f"wheel_rail.conicity_amplitude_m: {exc}") from None


def _contact(t: ContactSchema | None, names: Mapping[str, float],
             profiles: WheelRailSpec | None = None) -> ContactSpec | None:
    if t is None:
        if profiles is not None:
            raise ValueError("wheel_rail: needs a [contact] table (wheel_radius_m, semi_gauge_m, creep data)")
        return None
    r0 = _num(t, "wheel_radius_m", names, "contact", positive=True)
    e0 = _num(t, "semi_gauge_m", names, "contact", positive=True)
    source = "stated" if t.conicity is not None else "delta_r table" if t.delta_r_m is not None else "profiles"
    if t.conicity is not None:
        lam = _num(t, "conicity", names, "contact", lower=0.0)
    elif t.delta_r_m is None:
        if profiles is None:
            raise ValueError("contact.conicity: missing; give conicity, a Δr table (delta_r_y_m, delta_r_m, "
                             "amplitude_m) or a [wheel_rail] table of profiles")
        lam = _profile_conicity(profiles, r0, e0)
    else:
        from railopt.models.contact import equivalent_conicity

        y = [evaluate(x, names, f"contact.delta_r_y_m[{i}]") for i, x in enumerate(t.delta_r_y_m)]
        dr = [evaluate(x, names, f"contact.delta_r_m[{i}]") for i, x in enumerate(t.delta_r_m)]
        amplitude = _num(t, "amplitude_m", names, "contact", positive=True)
        try:
            lam = equivalent_conicity(y, dr, amplitude, r0=r0, e0=e0)
        except ValueError as exc:
            field = {"y": "delta_r_y_m", "delta_r": "delta_r_m", "amplitude": "amplitude_m"}.get(
                str(exc).split(":")[0], "delta_r_m")
            raise ValueError(f"contact.{field}: {exc}") from None
    coeffs = None
    if t.creep == "given":
        coeffs = Creep(_num(t, "f11_N", names, "contact", positive=True),
                       _num(t, "f22_N", names, "contact", positive=True),
                       _num(t, "f23_N_m", names, "contact"), _num(t, "f33_N_m2", names, "contact", lower=0.0))
    load = _num(t, "axle_load_N", names, "contact", positive=True) if t.axle_load_N is not None else None
    shear = _num(t, "shear_modulus_Pa", names, "contact", positive=True) if t.shear_modulus_Pa is not None else None
    return ContactSpec(
        r0=r0, e0=e0, conicity=lam, theta0=_num(t, "theta0", names, "contact"),
        epsilon=_num(t, "epsilon", names, "contact"), eta=_num(t, "eta", names, "contact"), creep=t.creep,
        coefficients=coeffs, creep_factor=_num(t, "creep_factor", names, "contact", positive=True), spin=t.spin,
        gravity_stiffness=t.gravity_stiffness, axle_load=load,
        youngs_modulus=_num(t, "youngs_modulus_Pa", names, "contact", positive=True),
        poisson_ratio=_num(t, "poisson_ratio", names, "contact", lower=0.0, upper=0.5),
        shear_modulus=shear, theory=t.theory,
        rail_head_radius=_num(t, "rail_head_radius_m", names, "contact", positive=True),
        wheel_transverse_radius=_num(t, "wheel_transverse_radius_m", names, "contact", positive=True),
        source=t.source, conicity_source=source,
    )


# what a contact error's leading name means in the file (railopt.models.contact names its arguments)
_CONTACT_FIELDS = {
    "a_over_b": "wheel_radius_m", "curvature_ratio": "wheel_radius_m", "R_rail": "rail_head_radius_m",
    "R_wheel_transverse": "wheel_transverse_radius_m", "R_wheel": "wheel_transverse_radius_m",
    "theta0": "theta0", "nu": "poisson_ratio", "E": "youngs_modulus_Pa", "G": "shear_modulus_Pa",
}


def _check_contact(vehicle: Vehicle) -> None:
    """Resolve the contact (Hertz creep) and the lumped track now, so a bad value names its key at load."""
    c = vehicle.contact
    if c is not None:
        try:
            vehicle.wheel_rail()
        except ValueError as exc:
            lead = str(exc).split(":")[0].strip()
            key = _CONTACT_FIELDS.get(lead)
            if key == "wheel_radius_m":
                raise ValueError(
                    f"contact.wheel_radius_m: the Hertz contact of a {c.r0:g} m wheel on a {c.rail_head_radius:g} m "
                    f"rail crown (wheel_transverse_radius_m = {c.wheel_transverse_radius:g}) is outside the creep "
                    f"theory ({exc}); is the radius in mm? the file's unit is m") from None
            raise ValueError(f"contact.{key}: {exc}" if key else f"contact: {exc}") from None
    if vehicle.track is not None and c is not None:
        try:
            vehicle.lumped_track()
        except ValueError as exc:
            raise ValueError(f"track: {exc}") from None


def _track(t: TrackSchema | None, names: Mapping[str, float]) -> TrackSpec | None:
    if t is None:
        return None
    return TrackSpec(track_modulus=_num(t, "track_modulus_N_m2", names, "track", positive=True),
                     rail_EI=_num(t, "rail_EI_N_m2", names, "track", positive=True),
                     mass_per_length=_num(t, "mass_per_length_kg_m", names, "track", positive=True),
                     damping_ratio=_num(t, "damping_ratio", names, "track", lower=0.0), source=t.source)


__all__ = [
    "BUNDLED", "INERTIA_RTOL", "MASS_RTOL", "MAX_DEPTH", "VehicleFileError", "bundled_path", "bundled_vehicles",
    "evaluate", "load_vehicle", "parse_vehicle", "read_vehicle_file",
]
