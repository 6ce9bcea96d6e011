"""API arguments of the wrong kind are refused naming the argument; no NaN or inf passes as a response
(issue 16 item 10: the kinds of the fault report, with inputs of our own)."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models.stability import critical_speed, root_locus
from railopt.models.track.beam import Beam
from railopt.models.vehicle import Irregularity, load_vehicle

from conftest import random_system


@pytest.mark.parametrize("omega", [np.nan, [1.0, np.inf], ["a"], "1.0", [True], -1.0, 1j])
def test_frequencies_that_are_not_frequencies_are_named(omega) -> None:
    with pytest.raises(ValueError, match="^omega_rad_s: "):
        random_system(3, seed=2).frf(omega_rad_s=omega)


def test_an_overflowing_frequency_is_an_error_not_a_nan() -> None:
    with pytest.raises(ValueError, match="^omega: Z"):  # the one check where Z(Ω) is formed
        random_system(3, seed=2).frf(omega_rad_s=1e200)


@pytest.mark.parametrize(("field", "value"), [("EI", "6e6"), ("k", True), ("m", None), ("c", [1.0]), ("N", np.nan)])
def test_beam_fields_must_be_numbers(field: str, value) -> None:
    kwargs = {"EI": 6e6, "m": 60.0, "k": 2e7} | {field: value}
    with pytest.raises(ValueError, match=f"^{field}: "):
        Beam(**kwargs)


@pytest.mark.parametrize("values", [{"ky": "abc"}, {"ky": None}, {"ky": True}, {"ky": [1.0]}, {"ky": np.nan}])
def test_with_parameters_names_the_bad_value(values) -> None:
    with pytest.raises(ValueError, match="^ky: "):
        load_vehicle("single-wheelset").with_parameters(values)
    with pytest.raises(ValueError, match="^ky: "):
        load_vehicle("single-wheelset").lateral(speed=10.0).with_values(values)


@pytest.mark.parametrize("values", [[("ky", 1.0)], "ky=1", None])
def test_with_parameters_wants_a_mapping(values) -> None:
    with pytest.raises(ValueError, match="^values: must be a mapping"):
        load_vehicle("single-wheelset").with_parameters(values)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"speed_range": (1, 2, 3)}, "speed_range"), ({"speed_range": (5.0,)}, "speed_range"),
    ({"speed_range": ("a", 2.0)}, r"speed_range\[0\]"), ({"speed_range": 30.0}, "speed_range"),
    ({"grid": 2.5}, "grid"), ({"grid": True}, "grid"), ({"grid": 1}, "grid"),
    ({"tol": -0.1}, "tol"), ({"tol": "0.1"}, "tol"),
])
def test_critical_speed_arguments_are_named(kwargs, field: str) -> None:
    with pytest.raises(ValueError, match=f"^{field}: "):
        critical_speed(load_vehicle("single-wheelset"), "rigid", **kwargs)


def test_root_locus_speeds_are_named() -> None:
    with pytest.raises(ValueError, match=r"^speeds\[1\]: "):
        root_locus(load_vehicle("single-wheelset"), [10.0, "fast"], track="rigid")


@pytest.mark.parametrize("frequencies", [["a"], [1e300], [np.nan], [0.0], [], [-2.0]])
def test_frequency_response_names_frequencies_hz(sd40, frequencies) -> None:
    view = sd40.vertical("rigid", speed=30.0)
    with pytest.raises(ValueError, match="^frequencies_hz: "):
        view.frequency_response(frequencies, Irregularity("vertical"), ["body.w"])
