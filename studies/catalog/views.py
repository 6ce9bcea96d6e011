"""The views of a vehicle a catalog model studies (``lateral``, ``vertical``, ``full``), and why a symmetric view
refuses an asymmetric vehicle, in the study's terms.

A vehicle symmetric about its centre line (y = 0) splits into a lateral (v, α, γ) and a vertical (u, w, β) block;
one that is not (a one-sided damper, a forgotten ``mirror_y``, worn wheels) couples them, and only the ``full``
view (both blocks together) holds it.  :func:`vehicle_view` builds the view a model's ``view`` option names and,
when a symmetric view is refused, names the elements that couple the blocks and the option that studies the
vehicle whole (``view = "full"``).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from railopt.models.vehicle.geometry import LATERAL_DOFS, VERTICAL_DOFS, split

__all__ = ["BLOCKS", "SHARE", "View", "coupling", "stability_view", "vehicle_view"]

View = Literal["lateral", "vertical", "full"]
"""A vehicle view: the lateral block, the vertical block, or every coordinate together (any vehicle)."""

BLOCKS: dict[str, tuple[str, ...]] = {"lateral": LATERAL_DOFS, "vertical": VERTICAL_DOFS}
"""The coordinates of each symmetric view."""

SHARE = 0.01
"""An element is named as coupling the blocks when it carries at least this share of the cross terms (projection
of its own cross terms on the total; two elements that cancel each other, as the thesis's C17 and C18, carry none)."""


def coupling(vehicle, track: str, view: str) -> tuple[list[str], bool]:
    """What couples ``view``'s block to the other coordinates of ``vehicle`` on ``track``.

    Returns ``(element ids, masses)``: the ids of the elements carrying at least :data:`SHARE` of the stiffness or
    damping cross terms, and whether the mass matrix couples the blocks too (a body off the centre line, a product
    of inertia).  Both empty/false for a symmetric vehicle.
    """
    a = vehicle.assembly(track)
    block = [j for j, c in enumerate(a.independent) if split(c)[1] in BLOCKS[view]]
    others = [j for j in range(len(a.independent)) if j not in block]
    if not others:
        return [], False
    T, To = a.T[:, block], a.T[:, others]

    def cross(m: np.ndarray) -> np.ndarray:
        return T.T @ m @ To

    def relative(m: np.ndarray) -> float:
        return float(np.max(np.abs(cross(m)))) / max(float(np.max(np.abs(m))), 1e-300)

    totals = {"K": cross(a.K()), "C": cross(a.C_const())}
    named = []
    for key, (kind, weights) in a.parts.items():
        total = totals[kind]
        size = float(np.sum(total * total))
        if size > 0 and float(np.sum(a.values[key] * cross(weights) * total)) >= SHARE * size:
            named.append(key)
    return named, relative(a.M) > 1e-12


def _one_sided(vehicle, ids: list[str]) -> list[str]:
    """Those of ``ids`` with an element off the centre line whose mirror image (y → −y, same bodies) is not an
    element of the same id: one side only."""
    def mirror(e) -> tuple:
        return (e.body_a, e.body_b, (e.point_a[0], -e.point_a[1], e.point_a[2]),
                (e.point_b[0], -e.point_b[1], e.point_b[2]))

    out = []
    for key in ids:
        members = [e for e in vehicle.elements if e.id == key]
        placed = {(e.body_a, e.body_b, tuple(e.point_a), tuple(e.point_b)) for e in members}
        if any((e.point_a[1] != 0.0 or e.point_b[1] != 0.0) and mirror(e) not in placed for e in members):
            out.append(key)
    return out


def vehicle_view(vehicle, view: str, track: str, speed: float | None = None):
    """``vehicle.lateral|vertical|full(track, speed)``: the :class:`~railopt.models.vehicle.views.VehicleView` the
    model's ``view`` option names.

    Raises
    ------
    ValueError
        ``"view: ..."`` when a symmetric view (lateral, vertical) is asked of a vehicle that is not symmetric about
        its centre line: the message names the elements that couple the blocks (the one-sided ones: a forgotten
        ``mirror_y``?) and the option that studies the vehicle whole, ``view = "full"``.  Other errors of the view
        as the vehicle raises them.
    """
    try:
        return getattr(vehicle, view)(track=track, speed=speed)
    except ValueError:
        if view == "full":
            raise
        ids, masses = coupling(vehicle, track, view)
        if not ids and not masses:
            raise
        what = []
        if ids:
            one_sided = _one_sided(vehicle, ids)
            hint = (f"; {', '.join(repr(i) for i in one_sided)} lie(s) on one side only — a forgotten "
                    "mirror_y = true?" if one_sided else "")
            what.append(f"the element(s) {', '.join(repr(i) for i in ids)} couple the lateral and vertical "
                        f"coordinates{hint}")
        if masses:
            what.append("the masses couple them (a body off the centre line, or a product of inertia)")
        raise ValueError(f"view: vehicle {vehicle.name!r} ({vehicle.path or 'bundled'}) is not symmetric about its "
                         f"centre line, so its {view} block cannot be studied alone: {'; '.join(what)}; set "
                         "view = \"full\" in the model's options to study it whole (both blocks together), or make "
                         "the vehicle symmetric") from None


def stability_view(view: str) -> str:
    """The view of a model's stability families (root loci, hunting, stability rows): ``full`` for a full-view
    model, else ``lateral`` (hunting is a lateral instability of a symmetric vehicle)."""
    return "full" if view == "full" else "lateral"
