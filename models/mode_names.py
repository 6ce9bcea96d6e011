"""The mode-naming vocabulary: a mode's name from its coordinates' shares of the modal kinetic energy.

:func:`mode_name` names one mode ("body lateral", "body hunting", "front truck hunting", "wheelset 3 lateral",
"track") from the share of each coordinate in vᴴMv, gathering bodies into groups; :func:`readable` spells a
body or group name as words.  The thresholds (:data:`HUNTING_DAMPING`, :data:`HUNTING_COUPLING`,
:data:`HUNTING_LATERAL`) and the words (:data:`MOTIONS`, :data:`SIDES`, :data:`WORDS`) are shared by the
stability analyses (:mod:`railopt.models.stability`) and the stability constraint rows
(:mod:`railopt.models.stability_rows`).  Coordinates are named ``"<body>.<dof>"``; lumped track bodies end in
``_track``.  This module never imports the vehicle package.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np

from railopt.models.modal import NEUTRAL_ROOT
from railopt.models.system import LinearSystem
from railopt.models.units import rad_s_to_hz

__all__ = ["HUNTING_COUPLING", "HUNTING_DAMPING", "HUNTING_LATERAL", "MOTIONS", "SIDES", "WORDS", "mode_name",
           "readable"]

MOTIONS = {"u": "longitudinal", "v": "lateral", "w": "bounce", "alpha": "roll", "beta": "pitch", "gamma": "yaw"}
HUNTING_DAMPING = 0.3  # a hunting mode is oscillatory and lightly damped (heavily creep-damped sway is not hunting)
HUNTING_COUPLING = 0.05  # share of the energy a body mode must give to its trucks (running gear) to be body hunting
HUNTING_LATERAL = 0.3  # share of a truck group's energy in lateral motion for truck hunting


def _body_dof(name: str) -> tuple[str, str]:
    body, _, dof = name.rpartition(".")
    return (body, dof) if body else (name, "")


def _track_body(body: str) -> bool:
    return body.endswith("_track") or body == "track"


SIDES = ("front", "rear", "leading", "trailing", "middle", "centre", "center")
WORDS = {"frame": "truck"}  # a locomotive's truck frame is "the truck"


def readable(group: str) -> str:
    """A body or group name as words: ``"frame_front"`` → "front truck", ``"bogie_rear"`` → "rear bogie",
    ``"wheelset3"`` → "wheelset 3"; other names unchanged."""
    parts = group.split("_")
    if len(parts) == 2 and parts[1].lower() in SIDES:
        return f"{parts[1]} {WORDS.get(parts[0], parts[0])}"
    return re.sub(r"(\D)(\d+)$", r"\1 \2", group)


def _shares(system: LinearSystem, vectors: np.ndarray) -> np.ndarray:
    """Each coordinate's share of the modal kinetic energy Re(v̄_i (M v)_i) / vᴴMv (sums to 1), for one mode
    vector (n,) or for the columns of (n, k) at once."""
    e = np.real(np.conj(vectors) * (system.M @ vectors))
    total = np.sum(e, axis=0)
    uniform = np.full(e.shape, 1.0 / e.shape[0])
    return np.where(total > 0, e / np.where(total > 0, total, 1.0), uniform)


def mode_name(names: Sequence[str], shares: np.ndarray, damping_ratio: float,
              groups: Mapping[str, str] | None = None, main: str | None = None) -> tuple[str, str, float]:
    """Name of a mode from the coordinates' shares of its kinetic energy: ``(name, group, its share)``.

    Bodies are gathered into groups (``groups``: body → group, e.g. a truck frame with its wheelsets and
    motors; a vehicle view provides them; default: each body its own group).  The group with the largest
    share dominates; a mode dominated by lumped track bodies is "track".  Its motion is the kind of
    coordinate with the largest share within the group ("lateral", "yaw", "roll", "bounce", "pitch").
    A lightly damped (ζ < 0.3) mode is *hunting* when the main body (``main``, the car body) dominates in a
    lateral, yaw or roll motion and gives at least 5 % of the energy to the running gear ("body hunting": the
    kinematic motion of the trucks coupled to the body's lower sway), or when a truck group (or the only body
    of a one-body vehicle) dominates with at least 30 % of its energy in lateral motion ("<truck> hunting").
    """
    groups = dict(groups or {})
    per_group: dict[str, float] = {}
    per_kind: dict[tuple[str, str], float] = {}
    for name, share in zip(names, shares, strict=True):
        body, dof = _body_dof(name)
        group = "track" if _track_body(body) else groups.get(body, body)
        per_group[group] = per_group.get(group, 0.0) + share
        kind = MOTIONS.get(dof, dof or body)
        per_kind[(group, kind)] = per_kind.get((group, kind), 0.0) + share
    if per_group.get("track", 0.0) > 0.5:
        return "track", "track", per_group["track"]
    group = max((g for g in per_group if g != "track"), key=per_group.get)
    own = {k: v for (g, k), v in per_kind.items() if g == group}
    total = max(sum(own.values()), 1e-300)
    motion = max(own, key=own.get)
    if damping_ratio < HUNTING_DAMPING and main is not None:
        running_gear = sum(v for g, v in per_group.items() if g not in (main, "track"))
        if group == main and running_gear >= HUNTING_COUPLING and motion in ("lateral", "yaw", "roll"):
            motion = "hunting"
        elif (group != main or len(per_group) == 1) and own.get("lateral", 0.0) >= HUNTING_LATERAL * total:
            motion = "hunting"  # a truck group; or a vehicle of one body (a single wheelset)
    if not motion or motion == group:
        return readable(group), group, per_group[group]
    return f"{readable(group)} {motion}", group, per_group[group]

def _named_roots(system: LinearSystem, indices: np.ndarray, groups: Mapping[str, str] | None,
                 main: str | None) -> list[dict]:
    """One row per root ``system.modal().s[k]`` (k in ``indices``) with its :func:`mode_name`."""
    m = system.modal()
    n = system.n
    scale = float(np.max(np.abs(m.s)))
    rows = []
    for k in indices:
        s = m.s[k]
        shares = _shares(system, m.V[:n, k])
        mag = abs(s)
        zeta = -s.real / mag if mag else 1.0
        if mag <= NEUTRAL_ROOT * scale:
            name, group, share = "rigid body", _body_dof(system.names[int(np.argmax(shares))])[0], float(np.max(shares))
        else:
            name, group, share = mode_name(system.names, shares, zeta, groups, main)
        track_share = float(sum(v for c, v in zip(system.names, shares, strict=True) if _track_body(_body_dof(c)[0])))
        rows.append({"frequency_hz": rad_s_to_hz(abs(s.imag)), "damping_ratio": zeta, "real": s.real,
                     "imag": abs(s.imag), "name": name, "group": group, "share": share, "track_share": track_share})
    return rows
