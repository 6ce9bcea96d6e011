"""Shared by the printed-equation tests: our assembled matrices on a randomised sd40-2 layout, read in
the thesis's signs (``THESIS_SIGNS``), entry by entry or as sums over merged coordinates."""

from __future__ import annotations

import tomllib

import numpy as np

from railopt.models.vehicle import THESIS_SIGNS, parse_vehicle
from railopt.models.vehicle.geometry import split
from railopt.models.vehicle.loader import bundled_path


class PrintedMatrices:
    """The bundled sd40-2 file with random lengths (and whatever :meth:`customise` randomises) and random
    suspension values, assembled on flexible track at ``speed`` (m/s)."""

    speed = 30.0

    def __init__(self, seed: int) -> None:
        rng = np.random.default_rng(seed)
        data = tomllib.loads(bundled_path("sd40-2").read_text())
        lengths = {k: float(rng.uniform(0.1, 2.0)) for k in data["lengths"]}
        lengths["l3"] = float(rng.uniform(5.0, 8.0))
        data["lengths"] = lengths
        self.l = lengths
        self.customise(rng, data)
        vehicle = parse_vehicle(data)
        self.p = {k: float(rng.uniform(1e4, 5e6)) for k in vehicle.element_ids()}
        self.vehicle = vehicle.with_parameters(self.p)
        a = self.vehicle.assembly("flexible")
        self.index = {c: i for i, c in enumerate(a.coordinates)}
        d = np.array([THESIS_SIGNS[split(c)[1]] for c in a.coordinates])
        self.mats = {"M": a.M * np.outer(d, d), "K": a.K() * np.outer(d, d),
                     "C": a.C(self.speed) * np.outer(d, d)}
        self.lt = self.vehicle.lumped_track()
        self.body = {b.name: b for b in self.vehicle.bodies}

    def customise(self, rng: np.random.Generator, data: dict) -> None:
        """Randomise more of the file (angles, contact) before it is parsed."""
        raise NotImplementedError

    def vec(self, coords: str) -> np.ndarray:
        v = np.zeros(len(self.index))
        for c in coords.split("+"):
            v[self.index[c.strip()]] = 1.0
        return v

    def __call__(self, mat: str, row: str, col: str) -> float:
        return float(self.vec(row) @ self.mats[mat] @ self.vec(col))
