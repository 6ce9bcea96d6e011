"""Compiled kernels (numba) of the nonlinear wheel/rail forces: the one implementation of their formulas.

:class:`~railopt.models.vehicle.wheelset_forces.WheelsetForces` (the model, its conventions and its sources are in
that module's docstring) and :meth:`~railopt.models.vehicle.nonlinear.NonlinearVehicle.rhs` call these kernels;
nothing else computes the forces.  What lives here, each written once:

- the contact geometry at lateral shifts y: :func:`conical_points` (the linear model's cone, thesis (4.1)–(4.8))
  and :func:`table_points` (a rigid contact table as a piecewise cubic in y: scipy's PCHIP coefficients, or the
  piecewise-linear interpolant written as a cubic with zero higher terms);
- :func:`creep_law` — Kalker's linear law (4.9) or the Shen–Hedrick–Elkins saturation of its resultant with
  Hertz load scaling of the coefficients;
- :func:`wheelset_forces` — creepages (4.11)–(4.18) with the exact-in-y geometry, the normal loads from the
  quasi-static vertical and roll balance (iterated with a load-dependent law), the creep and normal forces in
  track axes and the generalised forces on the wheelsets' u, v, α, β, γ rows, for K wheelsets at once;
- :func:`vehicle_rhs` — ẋ = (q̇, M⁻¹(Tᵀ Q − C q̇ − K q)) of the nonlinear vehicle, the integrators' right-hand
  side, and :func:`vehicle_jacobian`, its Jacobian by central differences.

Why compiled: the forces act on two wheels of one or two wheelsets, arrays of 2–4 numbers, so numpy spent its
time in per-call overhead (260–650 µs a right-hand side with the saturated law's load iteration, against a few
µs here); a hunting ramp or a continuation evaluates it millions of times.

Parameters travel as one float vector (indices ``P_*`` below) and a table (breakpoints, cubic coefficients) so
that each kernel has one compiled signature; errors come back as a status code (``OK``, ``BAD_SPEED``,
``OUTSIDE_TABLE``, ``WHEEL_LIFT``, ``NO_CONVERGENCE``, ``NOT_FINITE``) with the numbers the message needs in
``info``, and the Python callers raise them
(:meth:`~railopt.models.vehicle.wheelset_forces.WheelsetForces.raise_status`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from railopt.models.contact.saturation import she_ratio
from railopt.models.kernels import JIT

# ---- the parameter vector: contact, creep law, plane, flange, geometry
P_R0, P_W, P_F11, P_F22, P_F23, P_F33 = range(6)
P_LAW, P_MU, P_SPIN_SCALED, P_LOAD_SCALING = range(6, 10)  # law: 0 linear, 1 Shen-Hedrick-Elkins
P_PLANE = 10  # 0 contact plane, 1 track plane
P_FLANGE_K, P_FLANGE_D = 11, 12  # a dead-band flange spring (stiffness 0: none)
P_GEOMETRY = 13  # 0 cone (the P_CONE_* below), 1 table (breakpoints and coefficients)
P_CONICITY, P_CONE_R0, P_E0, P_THETA0, P_EPSILON, P_ETA = range(14, 20)
N_PARAMS = 20

# ---- rows of the state array (13, 2, K) that wheelset_forces fills (row 0 of the middle axis: left wheel)
S_RADIUS, S_ANGLE, S_LATERAL_ARM, S_VERTICAL_ARM = range(4)
S_XI_X, S_XI_Y, S_XI_SP, S_FX, S_FY, S_MZ, S_N, S_Q, S_Y = range(4, 13)
N_STATE = 13

# ---- status codes
OK, BAD_SPEED, OUTSIDE_TABLE, WHEEL_LIFT, NO_CONVERGENCE, NOT_FINITE = range(6)

MAX_PASSES = 50  # normal-load passes with a load-dependent law
LOAD_TOLERANCE = 1e-10  # |ΔN| ≤ LOAD_TOLERANCE · W ends them


@njit(**JIT)
def conical_points(y: np.ndarray, params: np.ndarray, out: np.ndarray) -> None:
    """Cone geometry at shifts y (K,) into ``out`` (4, 2, K): r = r0 ± λy, tan δ = θ0 ± εy/e0, arms e0 ∓ ηy, r0."""
    lam, r0, e0 = params[P_CONICITY], params[P_CONE_R0], params[P_E0]
    theta0, eps, eta = params[P_THETA0], params[P_EPSILON], params[P_ETA]
    for k in range(y.size):
        for side in range(2):
            sigma = 1.0 - 2.0 * side
            out[S_RADIUS, side, k] = r0 + sigma * lam * y[k]
            out[S_ANGLE, side, k] = math.atan(theta0 + sigma * eps * y[k] / e0)
            out[S_LATERAL_ARM, side, k] = e0 - sigma * eta * y[k]
            out[S_VERTICAL_ARM, side, k] = r0


@njit(**JIT)
def table_points(y: np.ndarray, breaks: np.ndarray, coef: np.ndarray, out: np.ndarray) -> None:
    """A contact table's geometry at shifts y (K,) inside ``[breaks[0], breaks[-1]]`` into ``out`` (4, 2, K).

    ``coef`` (4, n − 1, 8): the cubic of interval i, field f is Σ_m coef[m, i, f] (y − breaks[i])^(3 − m) (scipy's
    PPoly layout); fields in the order r_l, r_r, δ_l, δ_r, a_l, a_r, h_l, h_r.  Interval i holds
    breaks[i] ≤ y < breaks[i+1], the last one also its right end."""
    last = breaks.size - 2
    for k in range(y.size):
        i = np.searchsorted(breaks, y[k], side="right") - 1
        i = min(max(i, 0), last)
        d = y[k] - breaks[i]
        for f in range(8):
            v = ((coef[0, i, f] * d + coef[1, i, f]) * d + coef[2, i, f]) * d + coef[3, i, f]
            out[f // 2, f % 2, k] = v


@njit(**JIT)
def creep_law(params: np.ndarray, xi_x: float, xi_y: float, xi_sp: float, N: float,
              N0: float) -> tuple[float, float, float]:
    """Creep forces (Fx, Fy, Mz) of one contact (N, N·m) in the sign convention of :mod:`.wheelrail`.

    Linear law (4.9): ``Fx = −f11 ξx``, ``Fy = −f22 ξy + f23 ξsp``, ``Mz = −f23 ξy − f33 ξsp``.  Saturated: the
    same with f11, f22 ∝ (N/N0)^(2/3), f23 ∝ N/N0, f33 ∝ (N/N0)^(4/3) (with load scaling), then the forces
    times ε = she_ratio(r)/r, r = |(Fx, Fy)|/(μN) (the spin moment too when it is scaled; ``she_ratio`` of
    :mod:`railopt.models.contact.saturation`)."""
    f11, f22, f23, f33 = params[P_F11], params[P_F22], params[P_F23], params[P_F33]
    if params[P_LAW] == 0.0:
        return -f11 * xi_x, -f22 * xi_y + f23 * xi_sp, -f23 * xi_y - f33 * xi_sp
    k = N / N0 if params[P_LOAD_SCALING] != 0.0 else 1.0
    c = np.cbrt(k)
    s2, s3, s4 = c * c, k, k * c
    tx = -f11 * s2 * xi_x
    ty = -f22 * s2 * xi_y + f23 * s3 * xi_sp
    mz = -f23 * s3 * xi_y - f33 * s4 * xi_sp
    r = math.hypot(tx, ty) / (params[P_MU] * N)
    eps = she_ratio(r) / r if r > 0.0 else 1.0
    if params[P_SPIN_SCALED] != 0.0:
        mz = eps * mz
    return eps * tx, eps * ty, mz


@njit(**JIT)
def creep_forces(params: np.ndarray, xi_x: np.ndarray, xi_y: np.ndarray, xi_sp: np.ndarray, N: np.ndarray,
                 N0: float, out: np.ndarray) -> None:
    """:func:`creep_law` over flat arrays (m,) into ``out`` (3, m): Fx, Fy, Mz."""
    for j in range(xi_x.size):
        out[0, j], out[1, j], out[2, j] = creep_law(params, xi_x[j], xi_y[j], xi_sp[j], N[j], N0)


@njit(**JIT)
def wheelset_forces(y: np.ndarray, yaw: np.ndarray, dy: np.ndarray, droll: np.ndarray, dyaw: np.ndarray,
                    du: np.ndarray, dpitch: np.ndarray, speed: float, params: np.ndarray, breaks: np.ndarray,
                    coef: np.ndarray, state: np.ndarray, gen: np.ndarray, info: np.ndarray) -> int:
    """Contact state ``state`` (13, 2, K) and generalised forces ``gen`` (5, K: u, v, α, β, γ) of K wheelsets.

    Inputs (K,): lateral shift y relative to the rail (m), yaw (rad), and the rates of v, α, γ, u, β; ``speed``
    S (m/s).  The normal loads of all K wheelsets are iterated together until the largest change is at most
    ``LOAD_TOLERANCE · W`` (one pass with the linear law); the forces are those of the last pass's creep forces
    and the loads that balance them.  Returns a status; ``info`` gets the offending numbers: the speed, the
    largest |y| outside the table, the lowest load and its wheelset's y, or (``NOT_FINITE``) k ≥ 0 for wheelset
    k's state, −1 − k for its normal loads."""
    K = y.size
    if not (speed > 0.0 and math.isfinite(speed)):
        info[0] = speed
        return BAD_SPEED
    for k in range(K):  # a NaN would pass every comparison below unnoticed (max(0, nan) is 0 in numba)
        if not (math.isfinite(y[k]) and math.isfinite(yaw[k]) and math.isfinite(dy[k]) and math.isfinite(droll[k])
                and math.isfinite(dyaw[k]) and math.isfinite(du[k]) and math.isfinite(dpitch[k])):
            info[0] = k
            return NOT_FINITE
    r0, W = params[P_R0], params[P_W]
    if params[P_GEOMETRY] == 0.0:
        conical_points(y, params, state)
    else:
        for k in range(K):
            if not (breaks[0] <= y[k] <= breaks[-1]):
                info[0] = np.max(np.abs(y))
                return OUTSIDE_TABLE
        table_points(y, breaks, coef, state)
    contact = params[P_PLANE] == 0.0
    N0 = 0.5 * W
    # per wheel: the lateral tangent (ty, tz), the normal (ny, nz), the spin axis (my, mz), the arms (px, py, h)
    ty = np.empty((2, K))
    tz = np.empty((2, K))
    ny = np.empty((2, K))
    nz = np.empty((2, K))
    my = np.empty((2, K))
    mzz = np.empty((2, K))
    px = np.empty((2, K))
    py = np.empty((2, K))
    arm_n = np.empty((2, K))
    for k in range(K):
        sg, cg = math.sin(yaw[k]), math.cos(yaw[k])
        for side in range(2):
            sigma = 1.0 - 2.0 * side
            r = state[S_RADIUS, side, k]
            a = state[S_LATERAL_ARM, side, k]
            h = state[S_VERTICAL_ARM, side, k]
            s, c = math.sin(state[S_ANGLE, side, k]), math.cos(state[S_ANGLE, side, k])
            px[side, k] = -sigma * a * sg
            py[side, k] = sigma * a * cg
            state[S_XI_X, side, k] = (du[k] - sigma * a * dyaw[k] - r * dpitch[k]) / speed + (r0 - r) / r0
            nu = (dy[k] + h * droll[k]) / speed - yaw[k]
            if contact:
                state[S_XI_Y, side, k] = nu / c
                state[S_XI_SP, side, k] = dyaw[k] * c / speed - sigma * s / r0
                ty[side, k], tz[side, k] = c, sigma * s
                my[side, k], mzz[side, k] = -sigma * s, c
            else:
                state[S_XI_Y, side, k] = nu
                state[S_XI_SP, side, k] = dyaw[k] / speed
                ty[side, k], tz[side, k] = 1.0, 0.0
                my[side, k], mzz[side, k] = 0.0, 1.0
            ny[side, k], nz[side, k] = -sigma * s, c
            arm_n[side, k] = py[side, k] * c + h * (-sigma * s)  # roll moment of a unit normal load
            state[S_N, side, k] = N0 / c
    load_dependent = params[P_LAW] != 0.0
    converged = False
    for _ in range(MAX_PASSES):
        change = 0.0
        for k in range(K):
            rhs_v = W
            rhs_r = 0.0
            for side in range(2):
                fx, fy, mz = creep_law(params, state[S_XI_X, side, k], state[S_XI_Y, side, k],
                                       state[S_XI_SP, side, k], state[S_N, side, k], N0)
                state[S_FX, side, k], state[S_FY, side, k], state[S_MZ, side, k] = fx, fy, mz
                rhs_v -= fy * tz[side, k]
                rhs_r -= py[side, k] * (fy * tz[side, k]) + state[S_VERTICAL_ARM, side, k] * (fy * ty[side, k])
            det = nz[0, k] * arm_n[1, k] - nz[1, k] * arm_n[0, k]
            n_left = (rhs_v * arm_n[1, k] - nz[1, k] * rhs_r) / det
            n_right = (nz[0, k] * rhs_r - arm_n[0, k] * rhs_v) / det
            change = max(change, abs(n_left - state[S_N, 0, k]), abs(n_right - state[S_N, 1, k]))
            state[S_N, 0, k], state[S_N, 1, k] = n_left, n_right
        lowest = np.inf
        at = 0
        for k in range(K):
            for side in range(2):
                if not math.isfinite(state[S_N, side, k]):  # e.g. a singular balance: not a converged load
                    info[0] = -1.0 - k
                    return NOT_FINITE
                if state[S_N, side, k] < lowest:
                    lowest, at = state[S_N, side, k], k
        if lowest <= 0.0:
            info[0], info[1] = lowest, y[at]
            return WHEEL_LIFT
        if not load_dependent or change <= LOAD_TOLERANCE * W:
            converged = True
            break
    if not converged:
        return NO_CONVERGENCE
    for k in range(K):
        g0 = g1 = g2 = g3 = g4 = 0.0
        for side in range(2):
            fy, n, h = state[S_FY, side, k], state[S_N, side, k], state[S_VERTICAL_ARM, side, k]
            fx, mz = state[S_FX, side, k], state[S_MZ, side, k]
            f_y = fy * ty[side, k] + n * ny[side, k]
            f_z = fy * tz[side, k] + n * nz[side, k]
            state[S_Q, side, k], state[S_Y, side, k] = f_z, f_y
            g0 += fx
            g1 += f_y
            g2 += py[side, k] * f_z + h * f_y
            g3 += -h * fx - px[side, k] * f_z + mz * my[side, k]
            g4 += px[side, k] * f_y - py[side, k] * fx + mz * mzz[side, k]
        d = params[P_FLANGE_D]
        g1 += -params[P_FLANGE_K] * (y[k] - min(max(y[k], -d), d))
        gen[0, k], gen[1, k], gen[2, k], gen[3, k], gen[4, k] = g0, g1, g2, g3, g4
    return OK


@njit(**JIT)
def vehicle_rhs(x: np.ndarray, speed: float, MK: np.ndarray, MC: np.ndarray, MB: np.ndarray,
                T_rows: np.ndarray, params: np.ndarray, breaks: np.ndarray, coef: np.ndarray, out: np.ndarray,
                info: np.ndarray) -> int:
    """ẋ (2n,) into ``out`` of the nonlinear vehicle at x (2n,) and speed (m/s); returns :func:`wheelset_forces`'
    status.  ``MK``, ``MC`` (n, n): M⁻¹K, M⁻¹C; ``MB`` (n, 5K): M⁻¹ Tᵀ of the wheelsets' force rows; ``T_rows``
    (5K, n): those rows of T, in the order u, v, α, β, γ, each over the K wheelsets."""
    n = MK.shape[0]
    K = T_rows.shape[0] // 5
    q = x[:n]
    qd = x[n:]
    z = T_rows @ q
    zd = T_rows @ qd
    state = np.empty((N_STATE, 2, K))
    gen = np.empty((5, K))
    status = wheelset_forces(z[K:2 * K], z[4 * K:], zd[K:2 * K], zd[2 * K:3 * K], zd[4 * K:], zd[:K],
                             zd[3 * K:4 * K], speed, params, breaks, coef, state, gen, info)
    if status != OK:
        return status
    acc = MB @ gen.reshape(5 * K) - MK @ q - MC @ qd
    out[:n] = qd
    out[n:] = acc
    return OK


@njit(**JIT)
def vehicle_jacobian(x: np.ndarray, speed: float, step: float, MK: np.ndarray, MC: np.ndarray, MB: np.ndarray,
                     T_rows: np.ndarray, params: np.ndarray, breaks: np.ndarray, coef: np.ndarray, out: np.ndarray,
                     info: np.ndarray) -> int:
    """∂ẋ/∂x (2n, 2n) into ``out`` by central differences, h_j = step · max(1, |x_j|); arguments as
    :func:`vehicle_rhs`.  The 4n perturbed states go through :func:`wheelset_forces` in one call (4n·K
    wheelsets, their normal loads iterated together); returns its status."""
    n = MK.shape[0]
    n2 = 2 * n
    m = 2 * n2
    K = T_rows.shape[0] // 5
    h = np.empty(n2)
    X = np.empty((m, n2))
    for j in range(n2):
        h[j] = step * max(1.0, abs(x[j]))
    for i in range(m):
        X[i] = x
    for j in range(n2):
        X[j, j] += h[j]
        X[n2 + j, j] -= h[j]
    Z = np.ascontiguousarray(X[:, :n]) @ np.ascontiguousarray(T_rows.T)  # (m, 5K)
    Zd = np.ascontiguousarray(X[:, n:]) @ np.ascontiguousarray(T_rows.T)
    z = np.empty((5, m * K))  # row f, column i·K + k: coordinate f of wheelset k in perturbed state i
    zd = np.empty((5, m * K))
    for i in range(m):
        for f in range(5):
            for k in range(K):
                z[f, i * K + k] = Z[i, f * K + k]
                zd[f, i * K + k] = Zd[i, f * K + k]
    state = np.empty((N_STATE, 2, m * K))
    gen = np.empty((5, m * K))
    status = wheelset_forces(z[1], z[4], zd[1], zd[2], zd[4], zd[0], zd[3], speed, params, breaks, coef, state,
                             gen, info)
    if status != OK:
        return status
    Q = np.empty((m, 5 * K))
    for i in range(m):
        for f in range(5):
            for k in range(K):
                Q[i, f * K + k] = gen[f, i * K + k]
    acc = Q @ np.ascontiguousarray(MB.T) - np.ascontiguousarray(X[:, :n]) @ np.ascontiguousarray(MK.T) \
        - np.ascontiguousarray(X[:, n:]) @ np.ascontiguousarray(MC.T)
    for j in range(n2):
        inv = 1.0 / (2.0 * h[j])
        for r in range(n):
            out[r, j] = (X[j, n + r] - X[n2 + j, n + r]) * inv
            out[n + r, j] = (acc[j, r] - acc[n2 + j, r]) * inv
    return OK


__all__ = [
    "BAD_SPEED",
    "NOT_FINITE",
    "NO_CONVERGENCE",
    "OK",
    "OUTSIDE_TABLE",
    "WHEEL_LIFT",
    "conical_points",
    "creep_forces",
    "creep_law",
    "table_points",
    "vehicle_jacobian",
    "vehicle_rhs",
    "wheelset_forces",
]
