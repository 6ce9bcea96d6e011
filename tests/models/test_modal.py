"""The eigen-decomposition record (thesis eqs. 4.53–4.58): left eigenvectors worked out when first read, the
same afterwards and across pickling; a singular eigenvector matrix is named by W = NaN and cond = inf."""

from __future__ import annotations

import pickle

import cloudpickle
import numpy as np
import pytest

from railopt.models.modal import CONDITION_LIMIT, Modal, modal
from railopt.models.system import LinearSystem


def test_left_eigenvectors_when_first_read_and_then_the_same() -> None:
    rng = np.random.default_rng(3)
    G = rng.normal(size=(6, 6))
    m = modal(G)
    assert "_left" not in m.__dict__  # roots and right vectors only until W is asked for
    np.testing.assert_allclose(G @ m.V, m.V * m.s, atol=1e-12)
    W = m.W
    np.testing.assert_allclose(W @ m.V, np.eye(6), atol=1e-12)  # W = V⁻¹
    np.testing.assert_allclose(W @ G, m.s[:, None] * W, atol=1e-11)  # rows are left eigenvectors
    assert m.W is W and not W.flags.writeable
    # the kernel's sums of |v_ij| against numpy's norm: the same definition, rounded in another order (numpy's
    # complex abs and pairwise sums depend on the CPU's vector instructions), so equal to a few ulps, not bits
    assert m.condition == pytest.approx(np.linalg.norm(m.V, 1) * np.linalg.norm(W, 1), rel=1e-14, abs=0.0)
    for dumps, loads in ((pickle.dumps, pickle.loads), (cloudpickle.dumps, cloudpickle.loads)):
        before = loads(dumps(modal(G)))  # pickled before W was read
        after = loads(dumps(m))
        np.testing.assert_array_equal(before.W, W)
        np.testing.assert_array_equal(after.W, W)
        assert before == m == after


def test_a_singular_eigenvector_matrix_gives_nan_w_and_infinite_condition() -> None:
    m = Modal(np.array([1.0 + 0j, 1.0 + 0j]), np.ones((2, 2), dtype=complex))
    assert np.all(np.isnan(m.W)) and m.condition == float("inf")
    # a defective G (a Jordan block): V is singular to rounding, so the condition is far past the limit and the
    # pole–residue form is not used
    jordan = LinearSystem(np.eye(1), np.array([[2.0]]), np.array([[1.0]]), F=np.ones(1))  # s = −1 twice
    assert jordan.modal().condition > CONDITION_LIMIT
    assert jordan.pole_residue() is None


def test_neutral_roots_take_a_split_jordan_block_at_zero_and_not_a_slow_mode() -> None:
    """A free undamped drift x = a + bt is a Jordan block at s = 0; rounding splits it into ±δ or ±iδ with
    δ ≈ √ε·max|s| (1.1e-8 to 1.3e-8 measured on one CPU: above NEUTRAL_ROOT = 1e-8, so |s| alone misjudged it
    there).  Its two roots are each other's negative; a slow mode, a slow divergence, a flutter pair or anything
    beyond 1e-7·max|s| is not neutral (cases from a review that broke a looser rule)."""
    from railopt.models.modal import DEFECTIVE_ZERO, NEUTRAL_ROOT, growing_roots, neutral_roots

    fast = np.array([-3.0 - 40.0j, -3.0 + 40.0j, -10.0 - 5.0j, -10.0 + 5.0j])
    scale = np.max(np.abs(fast))

    def judged(*slow: complex) -> tuple[list[bool], np.ndarray]:
        s = np.concatenate([fast, np.asarray(slow, dtype=complex) * scale])
        mask = neutral_roots(s)
        assert not mask[:4].any()
        return list(mask[4:]), growing_roots(s) / scale

    for d in (1j * 1.3e-8 + 3e-15, 1.3e-8, 5e-8, 1e-7 * (1 - 1e-9)):  # ±iδ, ±δ: split blocks up to the cap
        assert abs(d) > NEUTRAL_ROOT and abs(d) <= DEFECTIVE_ZERO
        mask, growing = judged(d, -d)
        assert mask == [True, True] and growing.size == 0  # +δ of a split block is not an instability
    assert judged(5e-7j, -5e-7j)[0] == [False, False]  # an undamped slow mode beyond the cap
    mask, growing = judged(1e-7 + 1e-7j, 1e-7 - 1e-7j, -1e-7 + 1e-7j, -1e-7 - 1e-7j)  # a slow flutter quadruple
    assert mask == [False] * 4 and growing.size == 2
    mask, growing = judged(4e-7, -2e-7 + 3e-7j, -2e-7 - 3e-7j)  # a slow divergence beside a stable pair
    assert mask == [False] * 3 and np.allclose(growing, [4e-7])
    mask, growing = judged(3e-8, -3e-8, -5e-7)  # a split block beside a slow damped root
    assert mask == [True, True, False] and growing.size == 0
    mask, growing = judged(3e-8j, -3e-8j, -1e-8 + 5e-7j, -1e-8 - 5e-7j)
    assert mask == [True, True, False, False] and growing.size == 0
    slow = 1.3e-8 * np.array([-np.sin(0.6) + 1j * np.cos(0.6), -np.sin(0.6) - 1j * np.cos(0.6)])  # ζ = sin 0.6
    assert judged(*slow)[0] == [False, False]
    mask, growing = judged(2e-8)  # a lone slow divergence within the cap
    assert mask == [False] and np.allclose(growing, [2e-8])
    assert judged(1e-9)[0] == [True]  # a simple zero
    assert judged(2e-8j, -2e-8j, 4e-8, -4e-8)[0] == [True] * 4  # two free drifts: two split blocks
    stack = np.stack([np.concatenate([fast, [1.3e-8 * scale, -1.3e-8 * scale]]),
                      np.concatenate([fast, slow * scale])])
    np.testing.assert_array_equal(neutral_roots(stack), [[False] * 4 + [True] * 2, [False] * 6])  # rows alone


def test_a_free_undamped_body_is_neutral_whatever_the_rounding() -> None:
    """Two bodies joined by a spring and a damper, free to drift together: roots 0 (double, defective: the drift
    x = a + bt) and the relative mode.  Whatever the computed split of the double zero, exactly those two roots
    are neutral, at every scaling of the stiffness (the split is ~√ε·max|s|)."""
    from railopt.models.modal import neutral_roots

    for k in (1e2, 1e4, 1e6, 1e8):
        K = k * np.array([[1.0, -1.0], [-1.0, 1.0]])
        C = 0.02 * np.sqrt(k) * np.array([[1.0, -1.0], [-1.0, 1.0]])
        system = LinearSystem(np.diag([2.0, 3.0]), C, K, F=np.ones(2))
        s = system.eigenvalues()
        mask = neutral_roots(s)
        assert mask.sum() == 2, (k, s)
        # the relative mode's roots, closed form: m_r s² + c s + k = 0 with m_r = 2·3/5
        m_r, c = 6.0 / 5.0, 0.02 * np.sqrt(k)
        expected = np.roots([m_r, c, k])
        np.testing.assert_allclose(np.sort_complex(s[~mask]), np.sort_complex(expected), rtol=1e-9)
