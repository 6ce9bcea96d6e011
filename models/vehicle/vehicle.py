"""The vehicle definition: bodies, elements, constraints, contact, track — and its model views."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from railopt.models.track.beam import Beam
from railopt.models.track.lumped import LumpedTrack, lumped
from railopt.models.units import GRAVITY
from railopt.models.validation import number
from railopt.models.vehicle.assembly import TRACKS, Assembly, assemble
from railopt.models.vehicle.bodies import Body
from railopt.models.vehicle.constraints import check_reduced_mass
from railopt.models.vehicle.elements import Element
from railopt.models.vehicle.geometry import LATERAL_DOFS, VERTICAL_DOFS, point_jacobian, split
from railopt.models.vehicle.spec import ConstraintSpec, ContactSpec, Lengths, TrackSpec, WheelRailSpec
from railopt.models.vehicle.views import BodyPlace, VehicleView, check_speed
from railopt.models.vehicle.wheelrail import Creep, WheelRail

INERTIA_NAMES = {"Ixx": 0, "Iyy": 1, "Izz": 2}
CONTACT_NAMES = {
    "conicity": "conicity",
    "wheel_radius": "r0",
    "semi_gauge": "e0",
    "theta0": "theta0",
    "epsilon": "epsilon",
    "eta": "eta",
    "creep_factor": "creep_factor",
    "axle_load": "axle_load",
}
CREEP_NAMES = ("f11", "f22", "f23", "f33")
TRACK_NAMES = {"track_modulus": "track_modulus", "track_damping_ratio": "damping_ratio"}


@dataclass(frozen=True, repr=False)
class Vehicle:
    """A vehicle definition (SI units); load one with :func:`railopt.models.vehicle.load_vehicle`.

    Model views: :meth:`lateral`, :meth:`vertical` (the thesis's lateral (v, α, γ) and
    longitudinal–vertical (u, w, β) blocks) on ``"rigid"`` or ``"flexible"`` track.
    """

    name: str
    description: str
    bodies: tuple[Body, ...]
    elements: tuple[Element, ...]
    constraints: tuple[ConstraintSpec, ...] = ()
    contact: ContactSpec | None = None
    track: TrackSpec | None = None
    profiles: WheelRailSpec | None = None
    cab_point: tuple[float, float, float] | None = None
    lengths: Lengths = field(default_factory=Lengths)
    clearances: Lengths = field(default_factory=Lengths)
    aliases: dict[str, str] = field(default_factory=dict)
    path: str = ""
    _cache: dict = field(default_factory=dict, compare=False, repr=False, hash=False)

    def __repr__(self) -> str:
        contact = "no contact" if self.contact is None else (
            f"contact λ={self.contact.conicity:g} r0={self.contact.r0:g} m e0={self.contact.e0:g} m "
            f"creep={self.contact.creep}")
        track = "no track data" if self.track is None else "track data"
        where = f", {self.path!r}" if self.path else ""
        return (f"Vehicle({self.name!r}, {len(self.bodies)} bodies ({len(self.wheelsets)} wheelsets), "
                f"{len(self.elements)} elements ({len(self.element_ids())} parameters), "
                f"{self.total_mass:,.0f} kg, {contact}, {track}{where})")

    # ------------------------------------------------------------------ parameters
    def body(self, name: str) -> Body:
        """The body called ``name``.

        Raises ValueError listing the bodies when there is none by that name.
        """
        for b in self.bodies:
            if b.name == name:
                return b
        raise ValueError(f"unknown body {name!r}; bodies: {[b.name for b in self.bodies]}")

    def element_ids(self) -> tuple[str, ...]:
        """The element ids (the designable parameters), each once, in file order; symmetric pairs share one id."""
        return tuple(dict.fromkeys(e.id for e in self.elements))

    def element_aliases(self) -> dict[str, str]:
        """alias -> element id."""
        return {e.alias: e.id for e in self.elements if e.alias}

    def parameter_names(self) -> tuple[str, ...]:
        """Every name :meth:`with_parameters` accepts."""
        names = list(self.element_ids()) + list(self.element_aliases())
        for b in self.bodies:
            names += [f"{b.name}.mass"] + [f"{b.name}.{k}" for k in INERTIA_NAMES]
        if self.contact is not None:
            names += list(CONTACT_NAMES) + list(CREEP_NAMES)
        if self.track is not None:
            names += list(TRACK_NAMES)
        names += list(self.aliases)
        return tuple(dict.fromkeys(names))

    def _canonical(self, name: str) -> str:
        name = self.aliases.get(name, name)
        return self.element_aliases().get(name, name)

    def parameter(self, name: str) -> float:
        """Current value of a named parameter (SI)."""
        key = self._canonical(name)
        if key in self.element_ids():
            return next(e.value for e in self.elements if e.id == key)
        body, _, attr = key.rpartition(".")
        if attr == "mass":
            return self.body(body).mass
        if attr in INERTIA_NAMES:
            i = INERTIA_NAMES[attr]
            return self.body(body).inertia[i][i]
        if key in CONTACT_NAMES and self.contact is not None:
            wr = self.wheel_rail()
            return {"creep_factor": self.contact.creep_factor}.get(key, getattr(wr, CONTACT_NAMES[key], math.nan))
        if key in CREEP_NAMES and self.contact is not None:
            return getattr(self.wheel_rail().creep, key)
        if key in TRACK_NAMES and self.track is not None:
            return getattr(self.track, TRACK_NAMES[key])
        raise ValueError(self._unknown(name))

    def _unknown(self, name: str) -> str:
        where = f" in {self.path}" if self.path else ""
        valid = ", ".join(self.parameter_names())
        return f"unknown parameter {name!r} of vehicle {self.name!r}{where}; valid names: {valid}"

    def with_parameters(self, values: Mapping[str, float]) -> Vehicle:
        """A changed copy.  Names: element ids and aliases, ``<body>.mass``, ``<body>.Ixx|Iyy|Izz``,
        contact (conicity, wheel_radius, semi_gauge, theta0, epsilon, eta, creep_factor, axle_load,
        f11, f22, f23, f33), track (track_modulus, track_damping_ratio) and the file's aliases."""
        if not isinstance(values, Mapping):
            raise ValueError(f"values: must be a mapping of parameter names to numbers, got {type(values).__name__}")
        v = self
        for name, value in values.items():
            v = v._with_one(name, number(str(name), value))
        return v

    def _with_one(self, name: str, value: float) -> Vehicle:
        key = self._canonical(name)
        if key in self.element_ids():
            if value < 0.0:
                raise ValueError(f"{name}: suspension value must be >= 0, got {value!r}")
            els = tuple(replace(e, value=value) if e.id == key else e for e in self.elements)
            # suspension values enter linearly: keep the assembled weight matrices, change the values only
            cache = {t: replace(a, values={**a.values, key: value}) for t, a in self._cache.items()}
            return replace(self, elements=els, _cache=cache)
        body, _, attr = key.rpartition(".")
        if body in {b.name for b in self.bodies} and (attr == "mass" or attr in INERTIA_NAMES):
            def change(b: Body) -> Body:
                if b.name != body:
                    return b
                if attr == "mass":
                    return replace(b, mass=value)
                inertia = np.array(b.inertia)
                i = INERTIA_NAMES[attr]
                inertia[i, i] = value
                return replace(b, inertia=inertia)
            return replace(self, bodies=tuple(change(b) for b in self.bodies), _cache={})
        if self.contact is not None and (key in CONTACT_NAMES or key in CREEP_NAMES):
            c = self.contact
            if key in CREEP_NAMES:
                if c.creep != "given":
                    raise ValueError(f"{name}: creep coefficients are computed (creep = 'hertz'); set creep_factor")
                coefficients = replace(c.coefficients, **{key: value})
                return replace(self, contact=replace(c, coefficients=coefficients), _cache={})
            source = {"conicity_source": "parameter override"} if CONTACT_NAMES[key] == "conicity" else {}
            return replace(self, contact=replace(c, **{CONTACT_NAMES[key]: value}, **source), _cache={})
        if self.track is not None and key in TRACK_NAMES:
            return replace(self, track=replace(self.track, **{TRACK_NAMES[key]: value}), _cache={})
        raise ValueError(self._unknown(name))

    # ------------------------------------------------------------------ derived data
    @property
    def total_mass(self) -> float:
        """Mass of all bodies, kg."""
        return float(sum(b.mass for b in self.bodies))

    @property
    def wheelsets(self) -> tuple[Body, ...]:
        """The bodies of kind ``"wheelset"``, in file order."""
        return tuple(b for b in self.bodies if b.kind == "wheelset")

    def axle_load(self) -> float:
        """W, N: the file's value or the vehicle weight shared equally by the wheelsets."""
        if self.contact is not None and self.contact.axle_load is not None:
            return self.contact.axle_load
        n = len(self.wheelsets)
        return GRAVITY * self.total_mass / n if n else 0.0

    def wheel_rail(self) -> WheelRail:
        """Resolved contact parameters (creep coefficients computed when ``creep = "hertz"``)."""
        c = self.contact
        if c is None:
            raise ValueError(f"vehicle {self.name!r} has no [contact] table")
        W = self.axle_load()
        if c.creep == "given":
            creep = c.coefficients.scaled(c.creep_factor)
        else:
            creep = hertz_creep(c, W / 2.0)
        return WheelRail(conicity=c.conicity, r0=c.r0, e0=c.e0, creep=creep, axle_load=W, theta0=c.theta0,
                         epsilon=c.epsilon, eta=c.eta, spin=c.spin, gravity_stiffness=c.gravity_stiffness)

    def contact_track(self):
        """The wheelset on its track from the file's ``[wheel_rail]`` profiles: a
        :class:`~railopt.models.contact.WheelsetTrack` (both wheels the wheel profile at the ``[contact]`` rolling
        radius, both rails the rail profile inclined by ``inclination``, the gauge and back-to-back distance).

        Raises
        ------
        ValueError
            The vehicle has no ``[wheel_rail]`` table, or the profiles cannot be placed (naming the field)."""
        if self.profiles is None:
            raise ValueError(f"vehicle {self.name!r} has no [wheel_rail] table (wheel and rail profiles)")
        if self.contact is None:
            raise ValueError(f"vehicle {self.name!r}: [wheel_rail] needs the [contact] table's wheel_radius_m")
        return self.profiles.track(self.contact.r0)

    def contact_table(self, y_max: float = 0.012, step: float = 1e-4):
        """Rigid contact geometry of the ``[wheel_rail]`` profiles over −y_max … y_max (m) in steps of ``step``:
        a :class:`~railopt.models.contact.ContactTable` (:meth:`WheelRailSpec.table`, computed once per profile pair,
        radius, range and step: the table the loader took the conicity from when the file states none)."""
        self.contact_track()  # the errors naming what is missing
        return self.profiles.table(self.contact.r0, y_max, step)

    def lumped_track(self) -> LumpedTrack:
        """Per-rail lumped track (4.33)–(4.39), roll terms (4.49) with ℓ18 = 2 e0."""
        t = self.track
        if t is None:
            raise ValueError(f"vehicle {self.name!r} has no [track] table")
        beam = Beam(EI=t.rail_EI, m=t.mass_per_length, k=t.track_modulus)
        return lumped(beam, t.damping_ratio, contact_spacing=2.0 * self.contact.e0)

    # ------------------------------------------------------------------ models
    def assembly(self, track: str = "rigid") -> Assembly:
        """All-coordinate matrices (cached per track variant)."""
        if track not in TRACKS:
            raise ValueError(f"track: must be one of {TRACKS}, got {track!r}")
        if track not in self._cache:
            self._cache[track] = assemble(self, track)
        return self._cache[track]

    def lateral(self, track: str = "rigid", speed: float | None = None) -> VehicleView:
        """Lateral (v, α, γ) model: 9 DOF on rigid and 15 on flexible track for the locomotive."""
        return self._block(track, LATERAL_DOFS, speed)

    def cab_lateral(self, cab_input=None):
        """The thesis's simplified cab model (§4.3.3) at this vehicle's values, a
        :class:`~railopt.models.LinearSystem` whose first output ``cab_acceleration`` is the cab point's
        lateral acceleration (m/s²) for the irregularity of ``cab_input`` (default 0.25 in, 0–3 Hz,
        3 Hz at 150 mph); see :mod:`railopt.models.vehicle.cab`."""
        from railopt.models.vehicle.cab import CabInput, cab_lateral_model

        return cab_lateral_model(self, cab_input or CabInput()).at()

    def vertical(self, track: str = "rigid", speed: float | None = None) -> VehicleView:
        """Longitudinal–vertical (u, w, β) model: 21 / 27 DOF for the locomotive."""
        return self._block(track, VERTICAL_DOFS, speed)

    def full(self, track: str = "rigid", speed: float | None = None) -> VehicleView:
        """All independent coordinates together (both blocks)."""
        return self._block(track, LATERAL_DOFS + VERTICAL_DOFS, speed)

    def _block(self, track: str, dofs: tuple[str, ...], speed: float | None) -> VehicleView:
        if speed is not None:
            speed = check_speed(speed)
        a = self.assembly(track)
        cols = [j for j, c in enumerate(a.independent) if split(c)[1] in dofs]
        icols = [j for j, c in enumerate(a.inputs) if split(c)[1] in dofs]
        T = a.T[:, cols]
        T_in = a.T_in[:, icols]
        others = [j for j in range(len(a.independent)) if j not in cols]
        if others:
            To = a.T[:, others]
            # at the current values: a pair of parameters may each break symmetry while their sum keeps it
            # (the thesis's C17 and C18 of the outer axles, equal "because of symmetry")
            # (a cross term at rounding level, 1e-12 of the matrix's largest entry, is not a coupling)
            mats = [a.M, a.K(), a.C_const(), a.C_creep]
            worst = max(float(np.max(np.abs(T.T @ m @ To))) / max(float(np.max(np.abs(m))), 1e-300) for m in mats)
            if worst > 1e-12:
                raise ValueError(f"vehicle {self.name!r}: the {'/'.join(dofs)} block couples to the other "
                                 f"coordinates (|cross term| up to {worst:.3g} of the largest entry); the vehicle is "
                                 "not symmetric, use .full()")

        def red(m: np.ndarray) -> np.ndarray:
            return T.T @ m @ T

        E = T_in  # input coordinates map to themselves (identity rows) plus any constraint terms
        parts = {k: (kind, red(m)) for k, (kind, m) in a.parts.items()}
        in_parts = {k: T.T @ m @ E for k, (_, m) in a.parts.items()}
        check_reduced_mass(red(a.M), [a.independent[j] for j in cols])
        rows = {}
        if self.cab_point is not None:
            rows.update(self._cab_rows(a, T))
        wr = self.contact
        return VehicleView(
            name=self.name, track=track,
            coordinates=tuple(a.independent[j] for j in cols),
            inputs=tuple(a.inputs[j] for j in icols),
            M=red(a.M), K0=red(a.K0), C0=red(a.C0), C_creep=red(a.C_creep),
            parts=parts, values=dict(a.values),
            M_in=T.T @ a.M @ E, K_in0=T.T @ a.K0 @ E, C_in0=T.T @ a.C0 @ E, C_in_creep=T.T @ a.C_creep @ E,
            in_parts=in_parts, speed=speed, output_rows=rows, aliases=self.element_aliases(),
            all_coordinates=a.coordinates, T=T, T_in=T_in,
            bodies=tuple(BodyPlace(b.name, b.kind, b.cg) for b in a.bodies),
            wheelsets=tuple((b.name, float(b.cg[0])) for b in self.wheelsets),
            semi_gauge=None if wr is None else wr.e0, block_dofs=dofs,
            groups=self.mode_groups(), main_body=self.bodies[0].name,
        )

    def mode_groups(self) -> dict[str, str]:
        """Body -> group for mode names: the car body (first body) alone; each body suspended from it (a truck
        frame) with every body reached from that frame without passing the car body (its wheelsets, motors)."""
        main = self.bodies[0].name
        links: dict[str, set[str]] = {b.name: set() for b in self.bodies}
        pairs = [(e.body_a, e.body_b) for e in self.elements] + [(c.body, c.to) for c in self.constraints if c.to]
        for a, b in pairs:
            if a in links and b in links:
                links[a].add(b)
                links[b].add(a)
        groups = {main: main}
        frontier = sorted(links[main] - {main})
        groups.update({f: f for f in frontier})
        while frontier:
            reached = []
            for f in frontier:
                for b in sorted(links[f]):
                    if b not in groups:
                        groups[b] = groups[f]
                        reached.append(b)
            frontier = reached
        return groups

    def _cab_rows(self, a: Assembly, T: np.ndarray) -> dict[str, np.ndarray]:
        """Displacement rows of the cab point (carried by the first body) in x, y, z."""
        host = self.bodies[0]
        jac = point_jacobian(np.subtract(self.cab_point, host.cg))
        i = a.coordinates.index(f"{host.name}.u")
        out = {}
        for k, axis in enumerate(("longitudinal", "lateral", "vertical")):
            row = np.zeros(len(a.coordinates))
            row[i:i + 6] = jac[k]
            out[f"cab.{axis}"] = row @ T
        return out


def hertz_creep(c: ContactSpec, normal_load: float) -> Creep:
    """Per-wheel creep coefficients from the Hertz ellipse (uses :mod:`railopt.models.contact`)."""
    try:
        from railopt.models.contact import creep_coefficients, hertz_ellipse, wheel_rail_curvatures
    except ImportError as exc:  # pragma: no cover - depends on the contact package being installed
        raise ValueError("contact.creep = 'hertz' needs railopt.models.contact; give f11_N, f22_N instead") from exc
    A, B = wheel_rail_curvatures(c.r0, c.rail_head_radius, c.wheel_transverse_radius)
    ell = hertz_ellipse(normal_load, c.youngs_modulus, c.poisson_ratio, A, B)
    G = c.shear_modulus if c.shear_modulus is not None else c.youngs_modulus / (2.0 * (1.0 + c.poisson_ratio))
    cc = creep_coefficients(ell.a, ell.b, G, c.poisson_ratio, theory=c.theory, factor=c.creep_factor,
                            r0=c.r0, N=normal_load)
    return Creep(cc.f11, cc.f22, cc.f23, cc.f33)


__all__ = ["CONTACT_NAMES", "CREEP_NAMES", "INERTIA_NAMES", "TRACK_NAMES", "Vehicle", "hertz_creep"]
