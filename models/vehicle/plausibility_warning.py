"""The record of one plausibility warning and the key labels the checks share.

Every warning names the file (``file``), the key (``path``: a dotted key path of the file such as
``contact.semi_gauge_m``, ``bodies[2] (wheelset1).cg_m[0]``, ``lengths.semi_wheelbase``, or an element by id and
bodies, ``elements (kpx: wheelset1-bogie_rear).direction``) and, where one rescaling explains the value, the likely
slip (``looks like mm: 1280 → 1.28 m?``, :func:`railopt.models.vehicle.slips.likely_slip`).
"""

from __future__ import annotations

from dataclasses import dataclass

from railopt.models.vehicle.elements import VALUE_KEYS, Element
from railopt.models.vehicle.vehicle import Vehicle


@dataclass(frozen=True)
class PlausibilityWarning:
    """One suspicious value.

    Attributes
    ----------
    path : str
        Key path in the file (``contact.semi_gauge_m``, ``bodies[0] (body).mass_kg``,
        ``elements (ksy).stiffness_N_per_m``) or a derived quantity (``bodies[0] (body): lateral frequency``).
    message : str
        What is unusual, what is usual, and the likely slip when one rescaling explains the value.
    value : float
        The value as loaded (SI: kg, m, N/m, Hz for frequencies, t for axle loads).
    check : str
        Short name of the check (``"axle_load"``, ``"wheelbase"``, ``"point_pair"``, ...; docs/vehicle.md).
    file : str
        The vehicle file (``Vehicle.path``; ``""`` for a vehicle built in memory).
    """

    path: str
    message: str
    value: float
    check: str
    file: str = ""

    def __str__(self) -> str:
        return f"{self.path}: {self.message}"

    def line(self) -> str:
        """``"<file>: <key>: <message>"`` (the file left out when there is none)."""
        return f"{self.file}: {self}" if self.file else str(self)


def body_label(v: Vehicle, name: str) -> str:
    """``bodies[i] (name)``: the key of a body in the file."""
    i = next(k for k, b in enumerate(v.bodies) if b.name == name)
    return f"bodies[{i}] ({name})"


def element_label(e: Element, key: str = "", ids: list[str] | None = None) -> str:
    """``elements (id: body_a-body_b).key``: an element by id and the bodies it joins (ids repeat per wheelset);
    ``ids`` names several elements between the same bodies at once (``elements (ksx, ksy: body-bogie_rear)``)."""
    tail = f".{key}" if key else ""
    return f"elements ({', '.join(dict.fromkeys(ids or [e.id]))}: {e.body_a}-{e.body_b}){tail}"


def value_key(e: Element) -> str:
    """The file key of the element's value (``stiffness_N_per_m``, ``damping_N_s_per_m``, …)."""
    return VALUE_KEYS[e.type]


def suffix(slip: str) -> str:
    """``": <slip>"`` or ``""``: the likely slip appended to a message."""
    return f": {slip}" if slip else ""


__all__ = ["PlausibilityWarning", "body_label", "element_label", "suffix", "value_key"]
