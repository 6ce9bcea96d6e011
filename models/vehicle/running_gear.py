"""The running gear of a vehicle read from its links: which body each wheelset rides in, the bogies, element roles.

A vehicle file names bodies and elements, not bogies; the plausibility checks need the layout.  It is read from
the links (elements and constraints) alone, never from names:

* a wheelset's **frame** is the body (of kind ``"body"``, or ground) it shares most links with (ties: the heavier),
  so a traction motor hung on the axle (one hinge) does not take it from the bogie frame (springs and a rigid
  constraint);
* a frame is a **bogie** when it is linked to a heavier body of kind ``"body"`` that is no wheelset's frame (its
  car body); otherwise its wheelsets are carried directly (a two-axle wagon, a test rig on ground);
* an element is **primary** between a wheelset and a body or ground, **secondary** between a bogie and its car
  body, **other** otherwise (motor noses, inter-body links);
* the **axis** an element acts along (or about) is the largest component of its direction; the axis its id or
  alias *names* is read from words (``longitudinal``/``lateral``/``vertical``; for rotational elements
  ``roll``/``pitch``/``yaw``; a translational ``yaw`` damper acts longitudinally) or from short ids such as
  ``kpx``, ``csy``, ``kz1``.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

import numpy as np

from railopt.models.vehicle.elements import GROUND, Element
from railopt.models.vehicle.vehicle import Vehicle

AXES = ("x", "y", "z")
# The envelope any rail vehicle fits in (vehicle axes, m): the longest bodies are ~27.5 m with bogie centres 19-20 m
# apart; the widest loading gauges (EN 15273, GOST 9238) are 3.4-3.75 m wide and reach ~5.3 m above rail.
MAX_HALF_LENGTH_M = 20.0  # |x| of any CG or point
HALF_WIDTH_M = 2.0  # |y| of any CG or point
POINT_HEIGHT_M = (-0.5, 5.5)  # z of any point: from below the axle to above the highest loading gauge
AXIS_WORDS = {"longitudinal": 0, "lateral": 1, "vertical": 2, "bounce": 2}
ROTATION_WORDS = {"roll": 0, "pitch": 1, "yaw": 2}
SHORT_ID = re.compile(r"^[kc][a-z]{0,2}([xyz])$")  # kx, ky1, kpx, csy, cpz (digits and separators dropped)


@dataclass(frozen=True)
class RunningGear:
    """The layout of a vehicle's running gear.

    Attributes
    ----------
    frames : dict
        Wheelset name -> the body it rides in (a bogie frame or the car body), ``"ground"``, or ``""`` (unlinked).
    bogies : dict
        Bogie name -> its wheelsets in ascending x.
    car_bodies : dict
        Bogie name -> the heavier body it carries (the car body).
    """

    frames: dict[str, str]
    bogies: dict[str, tuple[str, ...]]
    car_bodies: dict[str, str]

    def role(self, e: Element, wheelsets: set[str]) -> str:
        """``"primary"`` (wheelset to body or ground), ``"secondary"`` (bogie to its car body) or ``"other"``."""
        a, b = e.body_a in wheelsets, e.body_b in wheelsets
        if a != b:
            return "primary"
        for bogie, car in self.car_bodies.items():
            if {e.body_a, e.body_b} == {bogie, car}:
                return "secondary"
        return "other"


def link_counts(v: Vehicle) -> dict[str, Counter]:
    """Body -> ``Counter`` of the bodies (or ground) it is linked to, one count per element and constraint."""
    links: dict[str, Counter] = {b.name: Counter() for b in v.bodies}
    for e in v.elements:
        links[e.body_a][e.body_b] += 1
        if e.body_b != GROUND:
            links[e.body_b][e.body_a] += 1
    for c in v.constraints:
        other = c.to or GROUND
        links[c.body][other] += 1
        if c.to:
            links[c.to][c.body] += 1
    return links


def running_gear(v: Vehicle) -> RunningGear:
    """The frames of the wheelsets, the bogies and their car bodies of ``v`` (see the module docstring)."""
    links = link_counts(v)
    mass = {b.name: b.mass for b in v.bodies}
    mass[GROUND] = np.inf
    wheelsets = {b.name for b in v.wheelsets}
    frames: dict[str, str] = {}
    for w in wheelsets:
        linked = [(n, c) for n, c in links[w].items() if n not in wheelsets]
        frames[w] = max(linked, key=lambda nc: (nc[1], mass[nc[0]]))[0] if linked else ""
    framing = set(frames.values()) - {GROUND, ""}
    x = {b.name: b.cg[0] for b in v.bodies}
    bogies: dict[str, tuple[str, ...]] = {}
    cars: dict[str, str] = {}
    for f in sorted(framing, key=lambda n: x[n]):
        heavier = [n for n in links[f] if n != GROUND and n not in wheelsets and n not in framing
                   and mass[n] > mass[f]]
        if heavier:
            cars[f] = max(heavier, key=lambda n: mass[n])
            bogies[f] = tuple(sorted((w for w, g in frames.items() if g == f), key=lambda w: x[w]))
    return RunningGear(frames=frames, bogies=bogies, car_bodies=cars)


def inside_envelope(p) -> bool:
    """Whether the absolute point ``p`` (m) lies inside the envelope any rail vehicle fits in."""
    return (abs(p[0]) <= MAX_HALF_LENGTH_M and abs(p[1]) <= HALF_WIDTH_M
            and POINT_HEIGHT_M[0] <= p[2] <= POINT_HEIGHT_M[1])


def acting_axis(e: Element) -> int:
    """The axis (0 x, 1 y, 2 z) of the largest component of the element's direction."""
    return int(np.argmax(np.abs(e.direction)))


def named_axis(e: Element) -> int | None:
    """The axis (0 x, 1 y, 2 z) the element's id or alias names, or ``None`` (no axis word, or two different)."""
    found = set()
    for name in (e.id, e.alias):
        words = [w for w in re.split(r"[^a-z]+", name.lower()) if w]
        for w in words:
            if w in AXIS_WORDS:
                found.add(AXIS_WORDS[w])
            elif w in ROTATION_WORDS:
                found.add(ROTATION_WORDS[w] if e.rotational else (0 if w == "yaw" else None))
        short = SHORT_ID.match("".join(words))
        if short and len(words) == 1:
            found.add(AXES.index(short.group(1)))
    found.discard(None)
    return found.pop() if len(found) == 1 else None


__all__ = ["AXES", "AXIS_WORDS", "HALF_WIDTH_M", "MAX_HALF_LENGTH_M", "POINT_HEIGHT_M", "ROTATION_WORDS", "RunningGear",
           "SHORT_ID", "acting_axis", "inside_envelope", "link_counts", "named_axis", "running_gear"]
