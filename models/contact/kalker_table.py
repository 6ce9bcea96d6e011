"""Kalker's creepage coefficients C_ij of the linear theory of rolling contact (his Table E.3).

Source of C11, C22, C23: the public repository eve70a/CONTACT (E.A.H. Vollebregt & J.J. Kalker,
Apache-2.0), file ``src/m_hertz.f90``, subroutine ``linrol`` ("Table E.3 of Kalker coefficients Cij of
the linear theory of rolling contact for elliptical contact areas"), commit 0ecc556a.  Transcribed
row by row; the layout there is, per row, C11(ν = 0, ¼, ½), C22(ν = 0, ¼, ½), C23(ν = 0, ¼, ½).

One entry differs between that file and ``src/usetab_table.f90`` of the same repository:
C23(a/b = 0.8, ν = 0.25) is 1.25 in ``m_hertz.f90`` and 1.15 in ``usetab_table.f90``.  We use 1.25:
it continues the monotone column 1.14 (a/b = 0.7), 1.25, 1.36 (a/b = 0.9) with the same step as its
ν = 0 and ν = 0.5 neighbours (0.10–0.11), whereas 1.15 would break monotone spacing.

C33 is **not** in ``linrol``.  The C33 column below is Kalker's Table E.3 spin coefficient as
reproduced in the railway-dynamics literature (Kalker 1967/1990; e.g. Garg & Dukkipati, *Dynamics
of Railway Vehicle Systems*, 1984).  It could not be cross-checked against a digital copy
here; ``tests/test_contact_creep.py`` checks it against the strip-theory limit C33 → π²/(16(1 − ν) g)
for a/b = g → 0 (derived in ``docs/contact.md``), its smooth monotone trend, and that spin stiffness
falls as the ellipse turns from narrow to long.  Treat C33 with the caution that note implies.

The values are data: ``data/kalker_table_e3.csv`` (one row per branch and g; columns C11, C22, C23, C33
at ν = 0, ¼, ½).  Rows: g = 0.1, 0.2, …, 1.0; ``A_OVER_B_LE_1`` is indexed by g = a/b, ``B_OVER_A_LE_1`` by g = b/a
(the second branch, a > b).  a is the semi-axis along the rolling direction.
"""

from __future__ import annotations

import csv
from importlib import resources

import numpy as np

NU_NODES = np.array([0.0, 0.25, 0.5])
G_NODES = np.round(np.arange(1, 11) / 10.0, 10)
COEFFICIENTS = ("C11", "C22", "C23", "C33")


def _read_table() -> dict[str, np.ndarray]:
    """Branch -> (10 g-rows, 4 coefficients C11 C22 C23 C33, 3 ν) from the bundled CSV, rows checked against
    ``G_NODES``."""
    text = resources.files("railopt.models.contact").joinpath("data/kalker_table_e3.csv").read_text()
    rows = list(csv.reader(line for line in text.splitlines() if line and not line.startswith("#")))
    header, rows = rows[0], rows[1:]
    expected = ["branch", "g"] + [f"{c}_nu{n:g}" for c in COEFFICIENTS for n in NU_NODES]
    if header != expected:  # pragma: no cover - guards the bundled file
        raise ValueError(f"kalker_table_e3.csv: header {header} is not {expected}")
    tables = {}
    for branch in ("a_le_b", "b_le_a"):
        mine = [r for r in rows if r[0] == branch]
        g = np.array([float(r[1]) for r in mine])
        if g.shape != G_NODES.shape or not np.array_equal(g, G_NODES):  # pragma: no cover
            raise ValueError(f"kalker_table_e3.csv: branch {branch} rows are g = {g}, not {G_NODES}")
        table = np.array([[float(x) for x in r[2:]] for r in mine]).reshape(len(G_NODES), len(COEFFICIENTS), 3)
        table.setflags(write=False)
        tables[branch] = table
    return tables


_TABLES = _read_table()
#: (10 g-rows, 4 coefficients C11 C22 C23 C33, 3 ν) for g = a/b ≤ 1
A_OVER_B_LE_1 = _TABLES["a_le_b"]
#: same for g = b/a ≤ 1 (a > b)
B_OVER_A_LE_1 = _TABLES["b_le_a"]
NU_NODES.setflags(write=False)
G_NODES.setflags(write=False)


__all__ = ["A_OVER_B_LE_1", "B_OVER_A_LE_1", "COEFFICIENTS", "G_NODES", "NU_NODES"]
