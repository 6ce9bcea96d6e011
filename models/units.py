"""The only home of unit constants: inch-pound units of the thesis (for the edges: configs, tables,
figures), the Hz ↔ rad/s factor and standard gravity.  SI and radians everywhere inside."""

from __future__ import annotations

import math

INCH = 0.0254  # m
FOOT = 0.3048  # m
POUND_FORCE = 4.4482216152605  # N
POUND_MASS = 0.45359237  # kg
PSI = POUND_FORCE / INCH**2  # Pa = N/m²; also the unit of the track modulus u (lb/in per in)
MPH = 0.44704  # m/s
KIP = 1000.0 * POUND_FORCE  # N
LB_PER_YARD = POUND_MASS / 0.9144  # kg/m
RAD_PER_HZ = 2.0 * math.pi  # ω (rad/s) = RAD_PER_HZ · f (Hz)
GRAVITY = 9.80665  # m/s², standard gravity


def m_to_in(value: float) -> float:
    """Metres to inches."""
    return value / INCH


def n_to_lb(value: float) -> float:
    """Newtons to pounds-force."""
    return value / POUND_FORCE


def m_s_to_mph(value: float) -> float:
    """m/s to mph."""
    return value / MPH


def hz_to_rad_s(value):
    """Hz to rad/s (scalars or arrays)."""
    return value * RAD_PER_HZ


def rad_s_to_hz(value):
    """rad/s to Hz (scalars or arrays)."""
    return value / RAD_PER_HZ


__all__ = [
    "FOOT", "GRAVITY", "INCH", "KIP", "LB_PER_YARD", "MPH", "POUND_FORCE", "POUND_MASS", "PSI", "RAD_PER_HZ",
    "hz_to_rad_s", "m_s_to_mph", "m_to_in", "n_to_lb", "rad_s_to_hz",
]
