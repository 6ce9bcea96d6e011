"""The mode-naming vocabulary: a mode's name from its shape — the coordinates' shares of the modal kinetic energy,
the phase between like running gear, the work of the creep forces.

:func:`named_modes` names every mode of a system at once (one per mode, railopt's mode order), so that no two
distinct modes share a name; :func:`mode_name` names one mode from its eigenvector; :func:`readable` spells a
body or group name as words.  The vocabulary:

* **subject** — the group (``groups``: body → group, e.g. a bogie frame with its wheelsets; a vehicle view
  provides them) holding most of the kinetic energy vᴴMv: the car body (``main``) — "body ..."; a running-gear
  group — "front bogie ..."; two like groups (same stem, "bogie_front"/"bogie_rear", "bogie1"/"bogie2") whose
  weaker holds at least :data:`TWIN_RATIO` of the stronger's energy — "bogie ..." with their phase; the
  group's wheelsets (members other than its frame) when they hold more than the frame — "wheelset 3 ...",
  "front bogie wheelsets ...", "wheelsets ... (bogies in phase)"; lumped track bodies (names ending ``_track``)
  holding more than half — "track";
* **motion** — the kind of coordinate with the largest share within the subject ("lateral", "yaw", "roll",
  "bounce", "pitch"); or **hunting**, reserved for the kinematic modes: oscillatory and either not damped
  (ζ ≤ 0: only the creep forces' circulatory stiffness can feed a passive vehicle's motion) or lightly damped
  (ζ < :data:`HUNTING_DAMPING`) and creep-driven — the circulatory (skew-symmetric) stiffness of the creep forces,
  which couples each wheelset's lateral and yaw motion, does per radian of the motion at least
  :data:`HUNTING_CIRCULATION` times the mode's energy scale (:func:`circulation`);
* **qualifier** — two like groups: "(in phase)", "(anti-phase)" or "(in quadrature)" from the phase of their
  momenta in the motion (lateral for hunting; within :data:`PHASE_DEGREES` of 0° or 180°); a car-body lateral or
  roll mode with both motions: "(lower sway)" (roll centre below the centre of mass) or "(upper sway)" (above);
  a car-body mode whose running gear holds at least :data:`GEAR_SHARE` of the energy (always for body hunting):
  which gear and how ("bogies in phase", "front truck"), e.g. "body yaw (bogies anti-phase)",
  "body roll (upper sway; bogies in phase)", "body hunting (trucks in phase)".

Names left equal by shape get " #2", " #3", ... in ascending frequency (:func:`named_modes`).  Coordinates are
named ``"<body>.<dof>"``.  This module never imports the vehicle package.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.modal import mode_order, neutral_roots
from railopt.models.system import LinearSystem
from railopt.models.units import rad_s_to_hz

__all__ = ["GEAR_SHARE", "HUNTING_CIRCULATION", "HUNTING_DAMPING", "MOTIONS", "NamedMode", "PHASE_DEGREES", "SIDES",
           "SWAY_SHARE", "TWIN_RATIO", "WORDS", "circulation", "mode_name", "named_modes", "readable"]

MOTIONS = {"u": "longitudinal", "v": "lateral", "w": "bounce", "alpha": "roll", "beta": "pitch", "gamma": "yaw"}
HUNTING_DAMPING = 0.3  # a hunting mode is oscillatory and lightly damped (heavily creep-damped sway is not hunting)
HUNTING_CIRCULATION = 1.0  # |vᴴ K_skew v| / (|s|² vᴴMv + |vᴴ K_sym v|) of a kinematic (creep-driven) mode
TWIN_RATIO = 0.25  # two like groups are named together when the weaker holds this share of the stronger's energy
SWAY_SHARE = 0.02  # a body mode is a sway when lateral and roll each hold this share of the body's energy
GEAR_SHARE = 0.05  # a body mode names its running gear when the gear holds this share of the kinetic energy
PHASE_DEGREES = 45.0  # in phase / anti-phase within this many degrees of 0° / 180°; else in quadrature

SIDES = ("front", "rear", "leading", "trailing", "middle", "centre", "center")
WORDS = {"frame": "truck"}  # a locomotive's truck frame is "the truck"


def _body_dof(name: str) -> tuple[str, str]:
    body, _, dof = name.rpartition(".")
    return (body, dof) if body else (name, "")


def _track_body(body: str) -> bool:
    return body.endswith("_track") or body == "track"


def readable(group: str) -> str:
    """A body or group name as words: ``"frame_front"`` → "front truck", ``"bogie_rear"`` → "rear bogie",
    ``"wheelset3"`` → "wheelset 3"; other names unchanged."""
    parts = group.split("_")
    if len(parts) == 2 and parts[1].lower() in SIDES:
        return f"{parts[1]} {WORDS.get(parts[0], parts[0])}"
    return re.sub(r"(\D)(\d+)$", r"\1 \2", group)


def _stem(name: str) -> str | None:
    """The kind of a numbered or sided name as a word: ``"bogie_front"`` → "bogie", ``"frame_rear"`` → "truck",
    ``"wheelset3"`` → "wheelset"; None for a name without side or number."""
    parts = name.split("_")
    if len(parts) == 2 and parts[1].lower() in SIDES:
        return WORDS.get(parts[0], parts[0])
    match = re.fullmatch(r"(.*\D)_?\d+", name)
    return WORDS.get(match.group(1), match.group(1)) if match else None


def _plural(words: set[str | None]) -> str:
    """"wheelsets" for members all of one stem, else "running gear"."""
    return f"{next(iter(words))}s" if len(words) == 1 and None not in words else "running gear"


def _shares(system: LinearSystem, vectors: np.ndarray) -> np.ndarray:
    """Each coordinate's share of the modal kinetic energy Re(v̄_i (M v)_i) / vᴴMv (sums to 1), for one mode
    vector (n,) or for the columns of (n, k) at once."""
    e = np.real(np.conj(vectors) * (system.M @ vectors))
    total = np.sum(e, axis=0)
    uniform = np.full(e.shape, 1.0 / e.shape[0])
    return np.where(total > 0, e / np.where(total > 0, total, 1.0), uniform)


def circulation(system: LinearSystem, vector: np.ndarray, root: complex) -> float:
    """How creep-driven a mode is: ``|vᴴ K_c v| / (|s|² Re vᴴMv + |Re vᴴ K_s v|)`` (dimensionless, ≥ 0).

    ``K_c = (K − Kᵀ)/2`` is the circulatory stiffness (the creep forces' lateral–yaw coupling of each wheelset),
    ``K_s`` the symmetric part; ``vector`` (n,) the mode's displacement part, ``root`` its s (1/s).  The
    numerator is, per radian of the motion, the work the circulatory forces do on the mode (it needs coordinates
    moving out of phase, as a wheelset's lateral and yaw motion do in its kinematic oscillation); the
    denominator twice the mode's kinetic plus potential energy scale.  The bundled vehicles' critical modes read
    1.1–7.7 at their critical speeds (conicity 0.025–0.4), their suspension modes mostly below 0.2 (3–150 m/s);
    0 for a system with a symmetric K.
    """
    v = np.asarray(vector, dtype=complex)
    K = system.K
    work = abs(np.conj(v) @ (0.5 * (K - K.T)) @ v)
    if work == 0.0:
        return 0.0
    scale = abs(root) ** 2 * float(np.real(np.conj(v) @ system.M @ v)) + abs(float(np.real(np.conj(v) @
                                                                                         (0.5 * (K + K.T)) @ v)))
    return float(work / scale) if scale > 0 else math.inf


class _Layout:
    """The coordinates of a system sorted by body, group and kind of motion (computed once per naming)."""

    def __init__(self, names: Sequence[str], groups: Mapping[str, str] | None, main: str | None) -> None:
        groups = dict(groups or {})
        self.names = list(names)
        self.main = main
        self.body = [_body_dof(c)[0] for c in self.names]
        self.dof = [_body_dof(c)[1] for c in self.names]
        self.group = ["track" if _track_body(b) else groups.get(b, b) for b in self.body]
        self.kind = [MOTIONS.get(d, d or b) for b, d in zip(self.body, self.dof, strict=True)]
        self.track = np.array([g == "track" for g in self.group], dtype=bool)

    def sums(self, shares: np.ndarray, key: list[str], where: np.ndarray | None = None) -> dict[str, float]:
        """Shares summed by ``key`` (one label per coordinate), over the coordinates ``where`` (default all)."""
        out: dict[str, float] = {}
        for i, label in enumerate(key):
            if where is None or where[i]:
                out[label] = out.get(label, 0.0) + float(shares[i])
        return out

    def member(self, i: int) -> bool:
        """Coordinate ``i`` belongs to a group's member (a wheelset or motor), not to the group's own body."""
        return self.body[i] != self.group[i]


def _phase(layout: _Layout, momenta: np.ndarray, a: str, b: str, kind: str) -> str:
    """"in phase", "anti-phase" or "in quadrature": the phase between the momenta of groups ``a`` and ``b`` in
    motion ``kind`` (Σ (Mv)_i over each group's coordinates of that kind)."""
    p = [sum(momenta[i] for i in range(len(layout.names)) if layout.group[i] == g and layout.kind[i] == kind)
         for g in (a, b)]
    if abs(p[0]) == 0.0 or abs(p[1]) == 0.0:
        return "in quadrature"
    cosine = float(np.real(p[0] * np.conj(p[1])) / (abs(p[0]) * abs(p[1])))
    limit = math.cos(math.radians(PHASE_DEGREES))
    return "in phase" if cosine >= limit else "anti-phase" if cosine <= -limit else "in quadrature"


def _twin(per_group: Mapping[str, float], top: str, others: Sequence[str]) -> str | None:
    """The group named together with ``top``: the strongest of ``others`` when it has ``top``'s stem and at least
    :data:`TWIN_RATIO` of its energy."""
    if not others or _stem(top) is None:
        return None
    second = others[0]
    return second if _stem(second) == _stem(top) and per_group[second] >= TWIN_RATIO * per_group[top] else None


def _name(layout: _Layout, system: LinearSystem, vector: np.ndarray, shares: np.ndarray, root: complex,
          kappa: float) -> tuple[str, str, float]:
    """(name, group, the group's share) of one mode, by the rules of the module docstring (``kappa``: its
    :func:`circulation`)."""
    per_group = layout.sums(shares, layout.group)
    if per_group.get("track", 0.0) > 0.5:
        return "track", "track", per_group["track"]
    ranked = sorted((g for g in per_group if g != "track"), key=lambda g: -per_group[g])
    top = ranked[0]
    mag = abs(root)
    zeta = -root.real / mag if mag else 1.0
    hunting = root.imag != 0 and (zeta <= 0.0 or (zeta < HUNTING_DAMPING and kappa >= HUNTING_CIRCULATION))
    momenta = system.M @ vector
    main = layout.main
    running = [g for g in ranked if g != main and g != top]
    in_top = np.array([g == top for g in layout.group])
    if top == main:  # the car body (or the only body)
        word = readable(top)
        gear = [g for g in ranked if g != main]
        if hunting:
            twin = _twin(per_group, gear[0], gear[1:]) if gear else None
            if twin is not None:
                return (f"{word} hunting ({_stem(gear[0])}s {_phase(layout, momenta, gear[0], twin, 'lateral')})",
                        top, per_group[top])
            return (f"{word} hunting ({readable(gear[0])})" if gear else f"{word} hunting"), top, per_group[top]
        kinds = layout.sums(shares, layout.kind, in_top)
        motion = max(kinds, key=kinds.get)
        if not motion or motion == top:
            return word, top, per_group[top]
        qualifiers = []
        lateral, roll = kinds.get("lateral", 0.0), kinds.get("roll", 0.0)
        if motion in ("lateral", "roll") and min(lateral, roll) >= SWAY_SHARE * per_group[top]:
            iv, ia = layout.names.index(f"{top}.v"), layout.names.index(f"{top}.alpha")
            # a point z above the centre of mass moves v − α z sideways: the roll centre is at z = v/α
            below = float(np.real(vector[iv] * np.conj(vector[ia]))) < 0.0
            qualifiers.append(f"{'lower' if below else 'upper'} sway")
        if gear and sum(per_group[g] for g in gear) >= GEAR_SHARE:  # the running gear takes part
            twin = _twin(per_group, gear[0], gear[1:])
            in_gear = np.array([g == gear[0] for g in layout.group])
            gear_kinds = layout.sums(shares, layout.kind, in_gear)
            gear_motion = max(gear_kinds, key=gear_kinds.get)
            qualifiers.append(readable(gear[0]) if twin is None else
                              f"{_stem(gear[0])}s {_phase(layout, momenta, gear[0], twin, gear_motion)}")
        return f"{word} {motion}" + (f" ({'; '.join(qualifiers)})" if qualifiers else ""), top, per_group[top]
    twin = _twin(per_group, top, running)
    subject = [top] if twin is None else [top, twin]
    in_subject = np.array([g in subject for g in layout.group])
    word = readable(top) if twin is None else str(_stem(top))
    if hunting:
        qualifier = "" if twin is None else f" ({_phase(layout, momenta, top, twin, 'lateral')})"
        return f"{word} hunting{qualifier}", top, per_group[top]
    members = np.array([in_subject[i] and layout.member(i) for i in range(len(layout.names))])
    held = float(np.sum(shares[members]))
    if held > float(np.sum(shares[in_subject])) - held:  # the wheelsets (members) hold more than the frames
        per_member = layout.sums(shares, layout.body, members)
        plural = _plural({_stem(b) for b in per_member})
        kinds = layout.sums(shares, layout.kind, members)
        motion = max(kinds, key=kinds.get)
        if twin is not None:
            phase = _phase(layout, momenta, top, twin, motion)
            return f"{plural} {motion} ({word}s {phase})", top, per_group[top]
        strongest = max(per_member, key=per_member.get)
        who = readable(strongest) if per_member[strongest] >= 0.5 * held else f"{word} {plural}"
        return f"{who} {motion}", top, per_group[top]
    kinds = layout.sums(shares, layout.kind, in_subject)
    motion = max(kinds, key=kinds.get)
    if not motion or motion == top:
        return word, top, per_group[top]
    qualifier = "" if twin is None else f" ({_phase(layout, momenta, top, twin, motion)})"
    return f"{word} {motion}{qualifier}", top, per_group[top]


def mode_name(system: LinearSystem, vector: np.ndarray, root: complex, groups: Mapping[str, str] | None = None,
              main: str | None = None) -> tuple[str, str, float]:
    """The name of one mode from its shape: ``(name, group, the group's share of the kinetic energy)``.

    ``vector`` (n,) is the mode's displacement part (the first n entries of the state eigenvector), ``root`` its
    s (1/s); ``groups`` body → group (default: each body its own group), ``main`` the car body.  The rules are
    the module's (:mod:`railopt.models.mode_names`): e.g. "body lateral (lower sway)", "body hunting (trucks in
    phase)", "bogie hunting (anti-phase)", "wheelset 3 lateral", "track".  A neutral root (s ≈ 0) is not
    recognised here (:func:`named_modes` calls it "rigid body"), nor are equal names told apart.
    """
    layout = _Layout(system.names, groups, main)
    v = np.asarray(vector, dtype=complex)
    return _name(layout, system, v, _shares(system, v), complex(root), circulation(system, v, complex(root)))


@dataclass(frozen=True, eq=False)
class NamedMode:
    """One mode of a system, named by its shape (:func:`named_modes`).

    Attributes
    ----------
    root : complex
        Its root s (Im s ≥ 0 of a complex pair; the second of a real pair in mode order), 1/s.
    vector : (n,) complex ndarray
        Its displacement shape, scaled so that the coordinate with the largest kinetic-energy share is 1 (real
        and positive): the real part is the displacement when that coordinate is at its maximum (m, rad).
    name : str
        Its name; distinct modes have distinct names.
    group : str
        The group holding most of its kinetic energy ("track" for a track mode).
    share : float
        That group's share of the kinetic energy vᴴMv.
    track_share : float
        The share of lumped track bodies.
    circulation : float
        :func:`circulation` (how creep-driven it is).
    """

    root: complex
    vector: np.ndarray
    name: str
    group: str
    share: float
    track_share: float
    circulation: float

    @property
    def frequency_hz(self) -> float:
        """|Im s| / 2π, Hz."""
        return rad_s_to_hz(abs(self.root.imag))

    @property
    def damping_ratio(self) -> float:
        """−Re s / |s| (1 for s = 0)."""
        mag = abs(self.root)
        return -self.root.real / mag if mag else 1.0


def named_modes(system: LinearSystem, groups: Mapping[str, str] | None = None,
                main: str | None = None) -> list[NamedMode]:
    """Every mode of ``system`` named by its shape, one per mode in railopt's mode order (ascending |Im s|, then
    Re s: the roots ``mode_order(s)[1::2]``, a real pair counting as one mode).

    Names by :func:`mode_name`; a neutral root (:func:`~railopt.models.modal.neutral_roots`) is "rigid body";
    distinct modes that the shape names alike get " #2", " #3", ... after the first (in this order, so by
    ascending frequency).  ``groups`` body → group, ``main`` the car body (a vehicle view has both).  Returns a
    list of :class:`NamedMode` (length n).
    """
    m = system.modal()
    n = system.n
    layout = _Layout(system.names, groups, main)
    neutral = neutral_roots(m.s)
    out, seen = [], {}
    for k in mode_order(m.s)[1::2]:
        s = complex(m.s[k])
        v = np.asarray(m.V[:n, k], dtype=complex)
        if s.imag < 0:  # the pair's root with Im s > 0 (its conjugate vector: the same motion)
            s, v = s.conjugate(), np.conj(v)
        shares = _shares(system, v)
        lead = int(np.argmax(shares))
        v = v / v[lead] if v[lead] != 0 else v
        kappa = circulation(system, v, s)
        if neutral[k]:
            name, group, share = "rigid body", layout.body[lead], float(shares[lead])
        else:
            name, group, share = _name(layout, system, v, shares, s, kappa)
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            name = f"{name} #{seen[name]}"
        out.append(NamedMode(s, v, name, group, share, float(np.sum(shares[layout.track])), kappa))
    return out


def _named_roots(system: LinearSystem, indices: Sequence[int], groups: Mapping[str, str] | None,
                 main: str | None) -> list[dict]:
    """One row per root ``system.modal().s[k]`` (k in ``indices``): its own frequency, damping ratio, real and
    |imag| parts with the name, group and shares of its mode in :func:`named_modes` (both roots of a pair share
    their mode's name)."""
    m = system.modal()
    modes = named_modes(system, groups, main)
    position = np.empty(len(m.s), dtype=int)
    position[mode_order(m.s)] = np.arange(len(m.s))
    rows = []
    for k in indices:
        s = m.s[k]
        mode = modes[position[k] // 2]
        mag = abs(s)
        rows.append({"frequency_hz": rad_s_to_hz(abs(s.imag)), "damping_ratio": -s.real / mag if mag else 1.0,
                     "real": s.real, "imag": abs(s.imag), "name": mode.name, "group": mode.group,
                     "share": mode.share, "track_share": mode.track_share})
    return rows
