"""Study kind ``frf``: frequency responses of catalogued models at named or explicit designs.

A config lists models (``[[models]]``), the designs to evaluate (named designs of each model or
explicit ``{variable: value}`` tables), the outputs and a frequency band.  For every model ×
design × output it writes |H| and its phase on a grid (``frf.csv``), the certified band maximum
and where it lies (``peaks.csv``, the exact option of (4.71)–(4.73)), and one figure per model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
import pandas as pd
from pydantic import Field, model_validator

from railopt.models import all_response_maxima
from railopt.models.units import RAD_PER_HZ as HZ
from railopt.studies.catalog import ModelSetup, ModelsStudy, require_unique
from railopt.studies.catalog.vehicle import model_vehicles, vehicle_title
from railopt.studies.config import BandHz, FileName, FiniteModel, not_one_of
from railopt.studies.kind import StudyContext, StudyKind, register_kind
from railopt.studies.output.figures import plot_frf_panels
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.records import FrfPanel
from railopt.studies.output.writer import Writer

__all__ = ["DesignSpec", "FRFResult", "FRFStudyConfig", "GridSpec", "compute", "report"]


class DesignSpec(FiniteModel):
    """A design to evaluate: a named design of the model, or explicit values."""

    label: FileName
    named: str | None = None
    values: dict[str, float] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _one(self) -> DesignSpec:
        if (self.named is None) == (not self.values):
            raise ValueError(f"designs.{self.label}: give either named or values")
        return self

    def resolve(self, setup: ModelSetup, where: str) -> dict[str, float]:
        """{variable: value} of this design on ``setup``: the named design's values or the explicit ones.

        Raises ValueError, prefixed by ``where``, for an unknown named design, names that are not parameters of the
        model, or values outside the parameters' physical limits.
        """
        if self.named is not None:
            if self.named not in setup.named_designs:
                raise ValueError(f"{where}.named: no named design {self.named!r}; known: {sorted(setup.named_designs)}")
            return dict(setup.named_designs[self.named])
        for k in self.values:
            if k not in setup.designable:
                raise ValueError(f"{where}.values.{k}: {not_one_of(k, setup.designable, 'parameter')}")
        setup.parameter_map.check_values(self.values, f"{where}.values")
        return dict(self.values)


class GridSpec(FiniteModel):
    """The frequency grid: ``points`` frequencies over ``band_hz`` (Hz), linear or log (log: lower edge > 0)."""

    band_hz: BandHz
    points: int = Field(1000, ge=2, le=200_000, strict=True)
    spacing: Literal["linear", "log"] = "linear"

    @model_validator(mode="after")
    def _log(self) -> GridSpec:
        if self.spacing == "log" and self.band_hz[0] <= 0:
            raise ValueError("spacing: log spacing needs band_hz[0] > 0")
        return self

    def frequencies_hz(self) -> np.ndarray:
        """The grid's frequencies in Hz, shape (points,), increasing, both edges included."""
        lo, hi = self.band_hz
        return np.geomspace(lo, hi, self.points) if self.spacing == "log" else np.linspace(lo, hi, self.points)


class FRFStudyConfig(ModelsStudy):
    """The config model of the ``frf`` kind: models, designs, outputs (empty = all), the grid and figure dpi.

    Validation resolves every design on every model, so unknown named designs or parameters fail before a run.
    """

    KIND: ClassVar[str] = "frf"
    designs: list[DesignSpec] = Field(min_length=1)
    outputs: list[str] = Field(default_factory=list, description="outputs to compute; empty = all")
    grid: GridSpec
    dpi: int = Field(110, ge=50, le=300, strict=True)

    @model_validator(mode="after")
    def _resolve(self) -> FRFStudyConfig:
        require_unique("designs", [d.label for d in self.designs])
        for i, ref in enumerate(self.models):
            setup = ref.setup(f"models[{i}]")
            for j, d in enumerate(self.designs):
                values = d.resolve(setup, f"designs[{j}]")
                setup.parameters(list(values), np.array(list(values.values())))
            bad = [o for o in self.outputs if o not in setup.family.output_names]
            if bad:
                known = list(setup.family.output_names)
                raise ValueError(f"outputs: {bad} are not outputs of models[{i}]; it has {known}")
        return self


@dataclass(frozen=True)
class FRFResult:
    """|H| and phase on the grid (``frf``), the certified peaks (``table``) and the figure panels."""

    config: FRFStudyConfig
    frf: pd.DataFrame
    table: pd.DataFrame
    panels: list


def _model_curves(cfg: FRFStudyConfig, i: int, ref, f_hz: np.ndarray, band: tuple[float, float]):
    """Curves, peak rows and figure panels of one model at every design."""
    setup = ref.setup(f"models[{i}]")
    outputs = cfg.outputs or list(setup.family.output_names)
    curves, peaks = [], []
    vehicle = model_vehicles(cfg.models).get(ref.label, {})  # vehicle and vehicle_file (none for a tmd model)
    panel_curves: dict[str, list] = {o: [] for o in outputs}
    for j, d in enumerate(cfg.designs):
        values = d.resolve(setup, f"designs[{j}]")
        p, _ = setup.parameters(list(values), np.array(list(values.values())))
        sys = setup.family.at(p)
        H = sys.frf_outputs(omega_rad_s=f_hz * HZ)
        maxima = all_response_maxima(sys, band_rad_s=band, exact=True, outputs=outputs)
        for o in outputs:
            h = H[:, sys.output_index(o)]
            curves.append(pd.DataFrame({"model": ref.label, "design": d.label, "output": o, "frequency_hz": f_hz,
                                        "amplitude": np.abs(h), "phase_deg": np.degrees(np.angle(h))}))
            rm = maxima[o]
            peaks.append({"model": ref.label, **vehicle, "design": d.label, "output": o, "peak": rm.value,
                          "frequency_hz": rm.argmax_frequency / HZ, "certified": rm.certified,
                          "grid_points": rm.grid_points, "evaluation": rm.evaluation})
            panel_curves[o].append((f"{d.label} (peak {rm.value:.6g} at {rm.argmax_frequency / HZ:.4g} Hz)",
                                    f_hz, np.abs(h), f"C{j}"))
    panels = [FrfPanel.build(vehicle_title(cfg.models, ref.label, setup.description), setup.axis_label(o), c)
              for o, c in panel_curves.items()]
    return curves, peaks, panels


def compute(config: FRFStudyConfig, context: StudyContext) -> FRFResult:
    """|H| and phase on the grid and the certified band maximum of every model × design × output.

    Frequencies in Hz in the tables; the maxima are the exact option of (4.71)–(4.73) over ``grid.band_hz``.
    """
    cfg = config
    f_hz = cfg.grid.frequencies_hz()
    band = (cfg.grid.band_hz[0] * HZ, cfg.grid.band_hz[1] * HZ)
    curves, peaks, panels = [], [], []
    for i, ref in enumerate(cfg.models):
        c, p, pn = _model_curves(cfg, i, ref, f_hz, band)
        curves += c
        peaks += p
        panels += pn
    return FRFResult(cfg, pd.concat(curves, ignore_index=True), pd.DataFrame(peaks), panels)


def report(result: FRFResult, writer: Writer) -> str:
    """Write ``frf`` and ``peaks`` tables and the ``frf`` figure; return the summary markdown."""
    cfg = result.config
    writer.table(result.frf, "frf")
    writer.table(result.table, "peaks")
    writer.figure(plot_frf_panels(result.panels), "frf", dpi=cfg.dpi)
    return "\n".join([f"# {cfg.study.name}", "", cfg.study.description, "",
                      f"Band {cfg.grid.band_hz[0]:g}–{cfg.grid.band_hz[1]:g} Hz; `peak` is the certified band "
                      "maximum (exact option of (4.71)–(4.73)).", "", markdown_table(result.table), "",
                      "![FRF](frf.png)", ""])


SUMMARY = "frequency responses and certified band maxima of catalogued models at given designs"
KIND = register_kind(StudyKind("frf", FRFStudyConfig, compute, report, summary=SUMMARY))
