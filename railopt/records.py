"""A base for frozen result records that hold numpy arrays (shared by every layer).

Frozen dataclasses with array fields have three traps: their arrays stay writable, ``==`` raises
("truth value of an array is ambiguous") and the generated repr prints every element.
:class:`ArrayRecord` fixes all three: array fields are stored as read-only copies, equality
compares arrays element-wise (same shape, same values; NaN equal to NaN), and the repr shows
scalars and the shapes of arrays only.  Records are unhashable (``__hash__ = None``).
"""

from __future__ import annotations

import dataclasses

import numpy as np


def _frozen(value: object) -> object:
    if isinstance(value, np.ndarray):
        arr = np.array(value, copy=True)
        arr.setflags(write=False)
        return arr
    return value


def _same(a: object, b: object) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc" and b.dtype.kind in "fc"))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return bool(a == b)


def _short(value: object) -> str:
    if isinstance(value, np.ndarray):
        return f"<{value.dtype.name} array {value.shape}>"
    if isinstance(value, float):
        return f"{value:.6g}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class ArrayRecord:
    """Mixin for ``@dataclass(frozen=True, eq=False)`` records with numpy fields."""

    __hash__ = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            object.__setattr__(self, f.name, _frozen(getattr(self, f.name)))

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(_same(getattr(self, f.name), getattr(other, f.name))
                   for f in dataclasses.fields(self))  # type: ignore[arg-type]

    def __repr__(self) -> str:
        fields = [f for f in dataclasses.fields(self) if f.repr]  # type: ignore[arg-type]
        inner = ", ".join(f"{f.name}={_short(getattr(self, f.name))}" for f in fields)
        return f"{type(self).__name__}({inner})"


__all__ = ["ArrayRecord"]
