"""A speed sweep whose critical-speed search finds no crossing prints "stable over the range (lo–hi m/s)" in every
table of its summary, never an empty cell or a bare "inf" (issue 27 item 1).

Independent reference: the coach's critical speed is ~79.9 m/s on rigid track (results/locomotive_stability, a
pencil-certified crossing confirmed by eigen-solves); searched over 1–20 m/s no root crosses, so the critical speed
is +inf and the words must name 1–20 m/s.  A dense eigenvalue scan of the same family over 1–20 m/s checks that the
words are true (every root has Re s < 0 there).
"""

from __future__ import annotations

import numpy as np

from railopt.models.vehicle import load_vehicle
from railopt.studies.catalog.vehicle import lateral_family
from railopt.studies.run_study import run_study

STUDY = """
[study]
name = "stable_words"
kind = "speed_sweep"

[[models]]
label = "coach_rigid"
model = "vehicle_lateral"
options = { vehicle = "manchester-coach", track = "rigid" }

[[models]]
label = "coach_flexible"
model = "vehicle_lateral"
options = { vehicle = "manchester-coach", track = "flexible" }

[speeds]
range_m_s = [2.0, 20.0]
points = 4

[critical]
range_m_s = [1.0, 20.0]
points = 4

[[sensitivity]]
parameter = "conicity"
factors = [1.0, 2.0]
"""


def test_infinite_critical_speed_prints_as_stable_over_the_range(tmp_path):
    (tmp_path / "study.toml").write_text(STUDY)
    run = run_study(tmp_path / "study.toml", results=tmp_path / "out", show_progress=False)
    text = (run.folder / "summary.md").read_text()
    words = "stable over the range (1–20 m/s)"
    critical = [line for line in text.splitlines() if line.startswith("| coach_rigid |")]
    assert critical and words in critical[0]
    pivot = [line for line in text.splitlines() if line.startswith("| conicity |")]
    assert len(pivot) == 2 and all(line.count(words) == 2 for line in pivot)
    effect = [line for line in text.splitlines() if line.startswith("| coach_rigid | coach_flexible |")]
    assert effect and effect[0].count(words) == 2
    assert "| inf |" not in text and "nan" not in text

    family = lateral_family(load_vehicle("manchester-coach"), "rigid", [])
    for v in np.linspace(1.0, 20.0, 96):  # the words are true: every root decays on 1-20 m/s
        assert np.max(np.linalg.eigvals(family.at(speed=v).state_matrix()).real) < 0
