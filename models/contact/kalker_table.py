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

Rows: g = 0.1, 0.2, …, 1.0; ``A_OVER_B_LE_1`` is indexed by g = a/b, ``B_OVER_A_LE_1`` by g = b/a
(the second branch, a > b).  a is the semi-axis along the rolling direction.
"""

from __future__ import annotations

import numpy as np

NU_NODES = np.array([0.0, 0.25, 0.5])
G_NODES = np.round(np.arange(1, 11) / 10.0, 10)

# shape (10 rows, 3 coefficients C11 C22 C23, 3 nu)
_A_LE_B = np.array(
    [
        [[2.51, 3.31, 4.85], [2.51, 2.52, 2.53], [0.334, 0.473, 0.731]],
        [[2.59, 3.37, 4.81], [2.59, 2.63, 2.66], [0.483, 0.603, 0.809]],
        [[2.68, 3.44, 4.80], [2.68, 2.75, 2.81], [0.607, 0.715, 0.889]],
        [[2.78, 3.53, 4.82], [2.78, 2.88, 2.98], [0.720, 0.823, 0.977]],
        [[2.88, 3.62, 4.83], [2.88, 3.01, 3.14], [0.827, 0.929, 1.07]],
        [[2.98, 3.72, 4.91], [2.98, 3.14, 3.31], [0.930, 1.03, 1.18]],
        [[3.09, 3.81, 4.97], [3.09, 3.28, 3.48], [1.03, 1.14, 1.29]],
        [[3.19, 3.91, 5.05], [3.19, 3.41, 3.65], [1.13, 1.25, 1.40]],  # C23(0.25) = 1.25, see above
        [[3.29, 4.01, 5.12], [3.29, 3.54, 3.82], [1.23, 1.36, 1.51]],
        [[3.40, 4.12, 5.20], [3.40, 3.67, 3.98], [1.33, 1.47, 1.63]],
    ]
)
# b/a = 0.1 ... 1.0 (m_hertz.f90 lists a/b = 10 first)
_B_LE_A = np.array(
    [
        [[10.7, 11.7, 12.9], [10.7, 12.8, 16.0], [12.2, 14.6, 18.0]],
        [[6.96, 7.78, 8.82], [6.96, 8.14, 9.79], [5.72, 6.63, 7.89]],
        [[5.57, 6.34, 7.34], [5.57, 6.40, 7.51], [3.79, 4.32, 5.01]],
        [[4.84, 5.57, 6.57], [4.84, 5.48, 6.31], [2.88, 3.24, 3.70]],
        [[4.37, 5.10, 6.11], [4.37, 4.90, 5.56], [2.35, 2.62, 2.96]],
        [[4.06, 4.78, 5.80], [4.06, 4.50, 5.04], [2.01, 2.23, 2.50]],
        [[3.82, 4.54, 5.58], [3.82, 4.21, 4.67], [1.76, 1.95, 2.18]],
        [[3.65, 4.36, 5.42], [3.65, 3.99, 4.39], [1.58, 1.75, 1.94]],
        [[3.51, 4.22, 5.30], [3.51, 3.81, 4.16], [1.44, 1.59, 1.77]],
        [[3.40, 4.12, 5.20], [3.40, 3.67, 3.98], [1.33, 1.47, 1.63]],
    ]
)
# C33(nu = 0, 0.25, 0.5): literature reproduction of Table E.3 (not in CONTACT's linrol; see above)
_C33_A_LE_B = np.array(
    [
        [6.42, 8.28, 11.7],
        [3.46, 4.27, 5.66],
        [2.49, 2.96, 3.72],
        [2.02, 2.32, 2.77],
        [1.74, 1.93, 2.22],
        [1.56, 1.68, 1.86],
        [1.43, 1.50, 1.60],
        [1.34, 1.37, 1.42],
        [1.27, 1.27, 1.27],
        [1.21, 1.19, 1.16],
    ]
)
_C33_B_LE_A = np.array(
    [
        [0.795, 0.526, 0.228],
        [0.828, 0.601, 0.341],
        [0.868, 0.674, 0.446],
        [0.912, 0.747, 0.549],
        [0.958, 0.819, 0.650],
        [1.01, 0.892, 0.751],
        [1.05, 0.965, 0.852],
        [1.10, 1.04, 0.954],
        [1.16, 1.11, 1.06],
        [1.21, 1.19, 1.16],
    ]
)


def _assemble(c123: np.ndarray, c33: np.ndarray) -> np.ndarray:
    out = np.concatenate([c123, c33[:, None, :]], axis=1)  # (10, 4 coefficients, 3 nu)
    out.setflags(write=False)
    return out


#: (10 g-rows, 4 coefficients C11 C22 C23 C33, 3 ν) for g = a/b ≤ 1
A_OVER_B_LE_1 = _assemble(_A_LE_B, _C33_A_LE_B)
#: same for g = b/a ≤ 1 (a > b)
B_OVER_A_LE_1 = _assemble(_B_LE_A, _C33_B_LE_A)
NU_NODES.setflags(write=False)
G_NODES.setflags(write=False)
