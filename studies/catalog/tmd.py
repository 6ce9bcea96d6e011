"""Catalog model ``tmd``: a tuned mass damper on an undamped primary (thesis §4.2)."""

from __future__ import annotations

from pydantic import Field

from railopt.models.tmd import den_hartog, nishihara_asami, tmd_parameters, tmd_system
from railopt.models.units import RAD_PER_HZ
from railopt.studies.catalog import AbscissaCheck, ModelSetup, ParameterMap, register_model
from railopt.studies.config import StrictModel

__all__ = ["TMDOptions", "tmd_setup"]


class TMDOptions(StrictModel):
    """Options of the ``tmd`` model: mass ratio μ = m2/m1, primary mass m1 (kg) and primary natural frequency (Hz)."""

    mass_ratio: float = Field(gt=0, le=10, allow_inf_nan=False, description="absorber / primary mass")
    primary_mass_kg: float = Field(1000.0, gt=0, lt=1e12, allow_inf_nan=False)
    primary_frequency_hz: float = Field(2.0, gt=0, lt=1e6, allow_inf_nan=False)


@register_model("tmd", TMDOptions, "tuned mass damper (k2, c2) on an undamped primary; output k1·x1 per unit force")
def tmd_setup(options: TMDOptions) -> ModelSetup:
    """TMD on an undamped primary: parameters (k2, c2), designable also as (tuning, damping_ratio)."""
    mu, m1 = options.mass_ratio, options.primary_mass_kg
    k1 = m1 * (RAD_PER_HZ * options.primary_frequency_hz) ** 2

    def transform(values: dict[str, float]) -> tuple[dict[str, float], dict[str, dict[str, float]]]:
        if set(values) != {"tuning", "damping_ratio"}:
            raise ValueError("variables: design tuning and damping_ratio together (they map to k2 and c2)")
        p, jac = tmd_parameters(values["tuning"], values["damping_ratio"], mu, m1, k1)
        return ({"k2": p[0], "c2": p[1]},
                {"k2": {"tuning": jac[0, 0], "damping_ratio": jac[0, 1]},
                 "c2": {"tuning": jac[1, 0], "damping_ratio": jac[1, 1]}})

    dh, na = den_hartog(mu), nishihara_asami(mu)
    defaults, _ = tmd_parameters(dh.tuning, dh.damping_ratio, mu, m1, k1)
    family = tmd_system(mu, m1, k1, output_name="amplification").with_values(defaults)
    return ModelSetup(
        family=family,
        parameter_map=ParameterMap(tuple(family.parameters), family.values, transform=transform,
                                   derived=("tuning", "damping_ratio"),
                                   limits={"k2": (0.0, "stiffness"), "c2": (0.0, "damping coefficient"),
                                           "tuning": (0.0, "frequency ratio"),
                                           "damping_ratio": (0.0, "damping ratio")}),
        named_designs={
            "den_hartog": {"tuning": dh.tuning, "damping_ratio": dh.damping_ratio},
            "nishihara_asami": {"tuning": na.tuning, "damping_ratio": na.damping_ratio},
        },
        checks={"spectral_abscissa": AbscissaCheck(family)},
        description=f"TMD, μ = {mu:g}, m1 = {m1:g} kg, f1 = {options.primary_frequency_hz:g} Hz",
        units={"amplification": "k1·x1 / F, dimensionless"},
    )
