"""Inch-pound units of the thesis, for the edges (configs, tables, figures).  SI everywhere inside."""

from __future__ import annotations

INCH = 0.0254  # m
FOOT = 0.3048  # m
POUND_FORCE = 4.4482216152605  # N
POUND_MASS = 0.45359237  # kg
PSI = POUND_FORCE / INCH**2  # Pa = N/m²; also the unit of the track modulus u (lb/in per in)
MPH = 0.44704  # m/s
KIP = 1000.0 * POUND_FORCE  # N
LB_PER_YARD = POUND_MASS / 0.9144  # kg/m


def m_to_in(value: float) -> float:
    """Metres to inches."""
    return value / INCH


def n_to_lb(value: float) -> float:
    """Newtons to pounds-force."""
    return value / POUND_FORCE


def m_s_to_mph(value: float) -> float:
    """m/s to mph."""
    return value / MPH
