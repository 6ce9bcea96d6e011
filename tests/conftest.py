"""Shared fixtures: standard systems named after what they check."""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models import LinearSystem, ParameterPart, ParametricSystem
from railopt.models.vehicle import load_vehicle


def random_system(n: int, seed: int, damping: float = 0.05) -> LinearSystem:
    """A lightly damped, non-symmetric n-DOF chain (creep-like skew terms in C and K)."""
    rng = np.random.default_rng(seed)
    M = np.diag(rng.uniform(0.5, 2.0, n))
    k = rng.uniform(0.5, 3.0, n)
    K = np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    K += 0.05 * (rng.standard_normal((n, n)) - rng.standard_normal((n, n)).T)  # non-symmetric part
    C = damping * K.copy() + 0.01 * np.eye(n)
    F = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    return LinearSystem(M, C, K, F, rng.standard_normal(n))


@pytest.fixture
def chain3() -> LinearSystem:
    return random_system(3, seed=1)


def base_excited_parametric(seed: int = 3) -> ParametricSystem:
    """3-DOF chain on a moving base through parameterised spring/damper; acceleration output.

    The base moves as y e^{iΩt} with two contact points delayed by τ, so F(Ω) depends on Ω and
    on the parameters (k_b, c_b) — the structure of the vehicle's forcing (4.63).
    """
    rng = np.random.default_rng(seed)
    n = 3
    M = np.diag(rng.uniform(0.5, 2.0, n))
    K0 = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) + 0.1 * rng.standard_normal((n, n))
    C0 = 0.02 * np.eye(n)
    tau = 0.7
    e0 = np.array([1.0, 0.0, 0.0])

    def base(omega: float) -> np.ndarray:
        return e0 * (1 + np.exp(-1j * omega * tau)) / 2

    parts = {
        "k_b": ParameterPart(K=np.outer(e0, e0), F=lambda w: base(w)),
        "c_b": ParameterPart(C=np.outer(e0, e0), F=lambda w: 1j * w * base(w)),
        "k_12": ParameterPart(K=np.array([[1.0, -1.0, 0], [-1.0, 1.0, 0], [0, 0, 0]])),
    }
    return ParametricSystem(M, C0, K0, np.zeros(n), np.array([0.0, 0.0, 1.0]), parts, response="acceleration")


@pytest.fixture(scope="session")
def sd40():
    """The bundled locomotive (its assembly cache is shared by the tests that use it)."""
    return load_vehicle("sd40-2")


@pytest.fixture(scope="session")
def coach():
    """The bundled Manchester benchmark coach."""
    return load_vehicle("manchester-coach")


def routh_hurwitz(m: float, iz: float, ky: float, kpsi: float, f11: float, f22: float, lam: float, e0: float,
                  r0: float) -> tuple[float, float]:
    """Critical speed (m/s) and hunting frequency (Hz) of an elastically restrained wheelset on rigid track,
    no spin creep and no gravity stiffness, derived by Routh–Hurwitz:

        m v'' + 2 f22 (v'/S − ψ) + k_y v = 0,   I ψ'' + 2 f11 e0 (e0 ψ'/S + λ v/r0) + k_ψ ψ = 0.

    With x = 1/S the characteristic polynomial is a4 s⁴ + p x s³ + (q0 + q2 x²) s² + r x s + a0; the Hurwitz
    determinant a3 a2 a1 − a1² a4 − a3² a0 vanishes at x² = (a4 r² + p² a0 − p r q0)/(p r q2), where the root
    on the imaginary axis is s = ±i sqrt(r/p).
    """
    A, Cc, b = 2 * f22, 2 * e0**2 * f11, 2 * e0 * lam * f11 / r0
    p = m * Cc + A * iz
    q0, q2 = m * kpsi + ky * iz, A * Cc
    r = A * kpsi + Cc * ky
    a4, a0 = m * iz, ky * kpsi + 2 * f22 * b
    x2 = (a4 * r**2 + p**2 * a0 - p * r * q0) / (p * r * q2)
    return 1.0 / math.sqrt(x2), math.sqrt(r / p) / (2 * math.pi)
