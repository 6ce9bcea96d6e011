"""Outputs of a vehicle view by name: ``y = row·x + feed·u`` (thesis §4.3.2).

Names a view resolves (:func:`output_row`):

* an independent coordinate of the block (``"body.w"``, ``"body.beta"``, ``"motor3.beta"``,
  ``"wheelset3_track.w"``), m or rad;
* any other coordinate of the block's bodies (``"wheelset3.w"``, ``"frame_rear.gamma"``) through
  the constraint rows ``z = T x + T_in u`` — some depend on the input directly (``wheelset3.w`` =
  track + rail profile): that part is the output's feedthrough of the input;
* ``"<wheelset>_track.<dof>"`` on rigid track: identically zero (the rigid track does not move;
  the thesis's Fig 4.12 rigid curve);
* the view's named rows (``"cab.vertical"``, ``"cab.lateral"``, ``"cab.longitudinal"``);
* a body point ``"<body>[x, y, z].<x|y|z>"`` (offset from the body's CG in m, direction of the
  displacement), or a :class:`PointOutput` with any direction;
* a difference ``"<output> - <output>"`` (e.g. the primary stroke
  ``"frame_rear[-2.07,1,-0.25].z - wheelset1.w"``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from railopt.models.vehicle.geometry import point_jacobian, split, unit

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.vehicle.views import VehicleView

POINT = re.compile(r"^\s*(?P<body>[^\[\]\s]+)\s*\[(?P<offset>[^\]]*)\]\s*\.\s*(?P<dir>[xyz])\s*$")
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
ROTATIONS = ("alpha", "beta", "gamma")
UNIT_SUFFIX = {"displacement": "", "velocity": "/s", "acceleration": "/s²"}


@dataclass(frozen=True)
class PointOutput:
    """Displacement of a body point along a direction.

    Attributes
    ----------
    body : str
        Body name.
    offset_m : (3,) float
        Point relative to the body's CG (m), our axes.
    direction : str or (3,) float
        ``"x" | "y" | "z"`` or a vector (normalised).
    name : str or None
        Name in tables (default ``"<body>[x,y,z].<dir>"``).
    """

    body: str
    offset_m: tuple[float, float, float]
    direction: str | tuple[float, float, float] = "z"
    name: str | None = None

    @property
    def label(self) -> str:
        """The output's name, or ``<body>[x,y,z].<direction>`` built from the point offset (m) and direction."""
        if self.name:
            return self.name
        off = ",".join(f"{c:g}" for c in self.offset_m)
        d = self.direction if isinstance(self.direction, str) else ",".join(f"{c:g}" for c in self.direction)
        return f"{self.body}[{off}].{d}"


@dataclass(frozen=True, eq=False)
class OutputRow:
    """One resolved output: ``y = row·x + feed·u`` (units ``unit`` per the input's units)."""

    name: str
    row: np.ndarray
    feed: np.ndarray
    unit: str

    @property
    def has_feedthrough(self) -> bool:
        """True when the input enters the output directly (some ``feed`` entry is non-zero)."""
        return bool(np.any(self.feed != 0.0))


def _valid_names(view: VehicleView) -> str:
    return (f"coordinates {list(view.coordinates)}, other '<body>.<dof>' of the block, rows "
            f"{sorted(view.output_rows)}, or body points '<body>[x,y,z].<x|y|z>'")


def _unit(dof: str) -> str:
    return "rad" if dof in ROTATIONS else "m"


def output_row(view: VehicleView, output: str | PointOutput) -> OutputRow:
    """Resolve one output name (or :class:`PointOutput`) of ``view`` into ``y = row·x + feed·u``."""
    n, m = view.n_dof, len(view.inputs)
    zero_feed = np.zeros(m)
    if isinstance(output, PointOutput):
        return _point_row(view, output)
    if not isinstance(output, str) or not output.strip():
        raise ValueError(f"outputs: an output must be a non-empty name or a PointOutput, got {output!r}")
    if " - " in output:  # a relative output, e.g. a suspension stroke "<frame point> - <wheelset>.w"
        first, _, second = output.partition(" - ")
        a, b = output_row(view, first.strip()), output_row(view, second.strip())
        if a.unit != b.unit:
            raise ValueError(f"outputs: {output!r} subtracts {b.unit} from {a.unit}")
        return OutputRow(output, a.row - b.row, a.feed - b.feed, a.unit)
    if output in view.coordinates:
        row = np.zeros(n)
        row[view.coordinates.index(output)] = 1.0
        return OutputRow(output, row, zero_feed, _unit(split(output)[1]))
    if output in view.output_rows:
        return OutputRow(output, np.asarray(view.output_rows[output], dtype=float), zero_feed, "m")
    match = POINT.match(output)
    if match:
        try:
            offset = tuple(float(c) for c in match["offset"].split(","))
        except ValueError:
            offset = ()
        if len(offset) != 3 or not all(np.isfinite(offset)):
            raise ValueError(f"outputs: {output!r}: the point offset must be three numbers in m, '<body>[x,y,z].<dir>'")
        return _point_row(view, PointOutput(match["body"], offset, match["dir"], name=output))
    body, dof = split(output)
    if output in view.all_coordinates:
        if dof not in view.block_dofs:
            raise ValueError(f"outputs: {output!r} is not a coordinate of this block (its coordinates are "
                             f"{view.block_dofs}); use the other model view")
        i = view.all_coordinates.index(output)
        return OutputRow(output, view.T[i].copy(), view.T_in[i].copy(), _unit(dof))
    wheelsets = {name for name, _ in view.wheelsets}
    if (view.track == "rigid" and body.endswith("_track") and body.removesuffix("_track") in wheelsets
            and dof in view.block_dofs):
        return OutputRow(output, np.zeros(n), zero_feed, _unit(dof))
    raise ValueError(f"outputs: unknown output {output!r}; valid: {_valid_names(view)}")


def _point_row(view: VehicleView, p: PointOutput) -> OutputRow:
    names = [b.name for b in view.bodies]
    if p.body not in names:
        raise ValueError(f"outputs: {p.label!r}: unknown body {p.body!r}; bodies: {names}")
    if isinstance(p.direction, str):
        if p.direction not in AXES:
            raise ValueError(f"outputs: {p.label!r}: direction must be x, y, z or a vector, got {p.direction!r}")
        direction = np.array(AXES[p.direction])
    else:
        direction = unit(np.asarray(p.direction, dtype=float), f"outputs: {p.label!r} direction")
    jac = point_jacobian(np.asarray(p.offset_m, dtype=float))
    i = view.all_coordinates.index(f"{p.body}.u")
    rz = np.zeros(len(view.all_coordinates))
    rz[i:i + 6] = direction @ jac
    return OutputRow(p.label, rz @ view.T, rz @ view.T_in, "m")


def output_rows(view: VehicleView, outputs) -> list[OutputRow]:
    """Resolve several outputs (a name, a PointOutput or a sequence of them); repeated names are an error."""
    if isinstance(outputs, str | PointOutput):
        outputs = [outputs]
    outputs = list(outputs)
    if not outputs:
        raise ValueError("outputs: at least one output is needed")
    rows = [output_row(view, o) for o in outputs]
    names = [r.name for r in rows]
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise ValueError(f"outputs: repeated {dup}")
    return rows


__all__ = ["AXES", "OutputRow", "POINT", "PointOutput", "ROTATIONS", "UNIT_SUFFIX", "output_row", "output_rows"]
