"""Frozen data of a vehicle definition other than bodies and elements: constraints, contact, track."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from railopt.models.vehicle.geometry import DOFS
from railopt.models.vehicle.wheelrail import Creep

CONSTRAINT_TYPES = ("rigid", "hinge", "fixed")
CREEP_MODES = ("given", "hertz")


@dataclass(frozen=True)
class ConstraintSpec:
    """A constraint as written in a vehicle file.

    ``rigid``: ``body`` follows ``to`` in ``dofs``; ``hinge``: ``body`` tied to ``to`` except a
    rotation about ``axis`` through ``point`` (relative to ``to``'s CG); ``fixed``: ``dofs`` of
    ``body`` held at zero.
    """

    type: str
    body: str
    to: str = ""
    dofs: tuple[str, ...] = ()
    axis: str = "y"
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.type not in CONSTRAINT_TYPES:
            raise ValueError(f"constraint on {self.body!r}: type must be one of {CONSTRAINT_TYPES}, got {self.type!r}")
        bad = [d for d in self.dofs if d not in DOFS]
        if bad:
            raise ValueError(f"constraint on {self.body!r}: unknown dofs {bad}; valid: {list(DOFS)}")


@dataclass(frozen=True)
class ContactSpec:
    """Wheel/rail data of the file's ``[contact]`` table (SI).

    ``creep = "given"`` uses ``coefficients``; ``"hertz"`` computes them per wheel from the Hertz
    ellipse under half the axle load (``railopt.models.contact``).  ``conicity`` may come from a
    Δr table (``delta_r_y``, ``delta_r``, ``amplitude``) by the EN 15302 method.  Every field is given: the
    defaults are the file schema's (:class:`~railopt.models.vehicle.schema.ContactSchema`), in one place.
    """

    r0: float
    e0: float
    conicity: float
    theta0: float
    epsilon: float
    eta: float
    creep: str
    coefficients: Creep | None
    creep_factor: float
    spin: bool
    gravity_stiffness: bool
    axle_load: float | None
    youngs_modulus: float
    poisson_ratio: float
    shear_modulus: float | None
    theory: str
    rail_head_radius: float
    wheel_transverse_radius: float
    source: str
    conicity_source: str = "stated"  # "stated", "delta_r table", "profiles" ([wheel_rail]) or "parameter override"

    def __post_init__(self) -> None:
        if self.creep not in CREEP_MODES:
            raise ValueError(f"contact.creep must be one of {CREEP_MODES}, got {self.creep!r}")
        if self.creep == "given" and self.coefficients is None:
            raise ValueError("contact: creep = 'given' needs f11_N and f22_N")
        if not math.isfinite(self.creep_factor) or self.creep_factor <= 0.0:
            raise ValueError(f"contact.creep_factor must be positive, got {self.creep_factor!r}")


@dataclass(frozen=True)
class WheelRailSpec:
    """The file's ``[wheel_rail]`` table (SI): the profiles every wheelset runs on, placed on the track.

    ``wheel_profile``/``rail_profile`` are catalogue names (:data:`railopt.models.contact.PROFILE_NAMES`) or
    absolute paths (the loader resolves a path relative to the vehicle file); ``inclination`` the rail inclination
    applied to the rail profile (tan of the angle: 1/40; 0 for a profile already inclined); ``gauge`` and
    ``flange_back`` (back-to-back distance) in m; ``conicity_amplitude`` the wheelset amplitude ŷ (m) at which the
    linear model's equivalent conicity is taken from the profiles (EN 15302; 3 mm by default);
    ``friction_coefficient`` μ of the saturated creep forces of the nonlinear model."""

    wheel_profile: str
    rail_profile: str
    inclination: float
    gauge: float = 1.435
    flange_back: float = 1.360
    conicity_amplitude: float = 0.003
    friction_coefficient: float = 0.4
    source: str = "estimate"

    def track(self, r0: float):
        """The wheelset on its track: a :class:`~railopt.models.contact.WheelsetTrack` with both wheels the wheel
        profile at rolling radius ``r0`` (m), both rails the rail profile inclined by ``inclination``.

        Raises
        ------
        ValueError
            The profiles cannot be placed (naming the field of :class:`~railopt.models.contact.WheelsetTrack`)."""
        from railopt.models.contact import WheelsetTrack, load_profile

        return WheelsetTrack.symmetric(load_profile(self.wheel_profile, "wheel"),
                                       load_profile(self.rail_profile, "rail"), gauge=self.gauge,
                                       flange_back_distance=self.flange_back, r0=r0, inclination=self.inclination)

    def table(self, r0: float, y_max: float = 0.012, step: float = 1e-4):
        """Rigid contact geometry of :meth:`track` over −y_max … y_max (m) in steps of ``step``: a
        :class:`~railopt.models.contact.ContactTable`, computed once per pair, radius, range and step (about 1 s
        for the default 241 shifts; a profile file is named by its path: edit it and load it in a new process)."""
        return _contact_table(self, float(r0), float(y_max), float(step))


@functools.lru_cache(maxsize=32)
def _contact_table(profiles: WheelRailSpec, r0: float, y_max: float, step: float):
    from railopt.models.contact import rigid_contact_table

    n = int(round(2.0 * y_max / step)) + 1
    return rigid_contact_table(profiles.track(r0), np.linspace(-y_max, y_max, n))


@dataclass(frozen=True)
class TrackSpec:
    """Per-rail track data for the lumped model (4.33)–(4.39), (4.49)."""

    track_modulus: float  # N/m² per rail
    rail_EI: float  # N·m²
    mass_per_length: float  # kg/m per rail
    damping_ratio: float = 0.1
    source: str = "estimate"

    def __post_init__(self) -> None:
        for name in ("track_modulus", "rail_EI", "mass_per_length"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0.0:
                raise ValueError(f"track.{name} must be positive and finite, got {v!r}")
        if not math.isfinite(self.damping_ratio) or self.damping_ratio < 0.0:
            raise ValueError(f"track.damping_ratio must be >= 0, got {self.damping_ratio!r}")


@dataclass(frozen=True)
class Lengths:
    """Named lengths (thesis l1…l35 and others), m, with their sources."""

    values: dict[str, float] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)


__all__ = ["CONSTRAINT_TYPES", "CREEP_MODES", "ConstraintSpec", "ContactSpec", "Lengths", "TrackSpec", "WheelRailSpec"]
