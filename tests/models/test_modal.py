"""The eigen-decomposition record (thesis eqs. 4.53–4.58): left eigenvectors worked out when first read, the
same afterwards and across pickling; a singular eigenvector matrix is named by W = NaN and cond = inf."""

from __future__ import annotations

import pickle

import cloudpickle
import numpy as np

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
    assert m.condition == np.linalg.norm(m.V, 1) * np.linalg.norm(W, 1)
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
