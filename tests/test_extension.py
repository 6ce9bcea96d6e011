"""The "where to add" rows of docs/architecture.md, each tried for real.

Every trial copies the package (models/, design/, studies/, railopt/ and docs/) into a temporary folder laid out
as the installed package, adds one piece there by writing files — the files it writes are the count the
architecture page states — and then uses the piece from a fresh interpreter that imports the copy
(``PYTHONPATH`` ahead of the editable install), checking its numbers against an independent computation.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
ARCHITECTURE = (ROOT / "docs" / "architecture.md").read_text()


def _numba_cache_only(folder: str, names: list[str]) -> list[str]:
    """Leave out byte code, but keep numba's cached kernels (``*.nbi``/``*.nbc``; copied with their sources'
    times, numba loads them in the copy instead of compiling every kernel again, ~35 s)."""
    if Path(folder).name != "__pycache__":
        return []
    return [name for name in names if not name.endswith((".nbi", ".nbc"))]


class Copy:
    """A temporary copy of the package; ``write``/``append`` record the files touched."""

    def __init__(self, base: Path) -> None:
        self.base = base
        self.package = base / "railopt"
        shutil.copytree(ROOT / "railopt", self.package, ignore=_numba_cache_only)
        for layer in ("models", "design", "studies"):
            shutil.copytree(ROOT / layer, self.package / layer, ignore=_numba_cache_only)
        shutil.copytree(ROOT / "docs", base / "docs")
        self.touched: set[str] = set()

    def path(self, rel: str) -> Path:
        return self.base / rel if rel.startswith("docs/") else self.package / rel

    def write(self, rel: str, text: str) -> None:
        self.path(rel).write_text(textwrap.dedent(text))
        self.touched.add(rel)

    def append(self, rel: str, text: str) -> None:
        with self.path(rel).open("a") as fh:
            fh.write(textwrap.dedent(text))
        self.touched.add(rel)

    def replace(self, rel: str, old: str, new: str) -> None:
        text = self.path(rel).read_text()
        assert text.count(old) == 1, (rel, old)
        self.path(rel).write_text(text.replace(old, new))
        self.touched.add(rel)

    def python(self, code: str, *args: str) -> str:
        env = {**os.environ, "PYTHONPATH": str(self.base), "MPLBACKEND": "Agg"}
        out = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], capture_output=True, text=True,
                             env=env, cwd=self.base, timeout=300)
        assert out.returncode == 0, out.stderr[-3000:]
        return out.stdout


@pytest.fixture
def copy(tmp_path: Path) -> Copy:
    return Copy(tmp_path)


def _stated(row: str) -> int:
    """The number of files the architecture page states for a row of its "Where to add" table."""
    match = re.search(rf"^\| {re.escape(row)} \| (\d+) files? \|", ARCHITECTURE, flags=re.M)
    assert match, f"docs/architecture.md has no 'Where to add' row {row!r} with a file count"
    return int(match.group(1))


def test_the_copy_is_what_runs(copy: Copy) -> None:
    out = copy.python("import railopt.models, railopt.design, railopt.studies as s; print(s.__file__)")
    assert out.strip().startswith(str(copy.package))


def test_a_vehicle_is_one_file(copy: Copy) -> None:
    text = (ROOT / "models" / "vehicle" / "data" / "manchester-coach.toml").read_text()
    heavier = re.sub(r'(?m)^name = "[^"]*"', 'name = "demo-coach"', text, count=1)
    copy.write("models/vehicle/data/demo-coach.toml", heavier)
    out = copy.python("""
        import json
        from railopt.models.vehicle import BUNDLED, load_vehicle
        a, b = load_vehicle("demo-coach"), load_vehicle("manchester-coach")
        print(json.dumps({"bundled": "demo-coach" in BUNDLED, "mass": a.total_mass, "ref": b.total_mass}))
    """)
    got = json.loads(out)
    assert got["bundled"] and got["mass"] == got["ref"] > 0
    assert len(copy.touched) == _stated("a vehicle")


def test_an_output_is_no_file(copy: Copy) -> None:
    """A body point is an output name, written in the study: row(body[L,0,0].y) − row(body[0,0,0].y) = L·γ-row."""
    out = copy.python("""
        import json
        import numpy as np
        from railopt.models.vehicle import load_vehicle
        from railopt.models.vehicle.outputs import output_row
        view = load_vehicle("sd40-2").lateral("rigid", speed=20.0)
        names = ("body[0,0,0].y", "body[2.5,0,0].y", "body.v", "body.gamma")
        rows = {k: output_row(view, k).row.tolist() for k in names}
        print(json.dumps(rows))
    """)
    rows = {k: np.array(v) for k, v in json.loads(out).items()}
    np.testing.assert_array_equal(rows["body[0,0,0].y"], rows["body.v"])
    np.testing.assert_allclose(np.abs(rows["body[2.5,0,0].y"] - rows["body.v"]), 2.5 * np.abs(rows["body.gamma"]),
                               rtol=0, atol=1e-15)
    assert len(copy.touched) == _stated("an output")


METHOD = """
    \"\"\"Method ``demo_compass``: a compass search on U(x) = max_k f_k(x) in the unit cube (no constraints).\"\"\"

    from dataclasses import dataclass, field

    import numpy as np

    from railopt.design.methods.base import Outcome, register


    @dataclass(frozen=True)
    class CompassSearch:
        \"\"\"Halve the step along ±e_i until it is below xtol; U = max of the scaled functions.\"\"\"

        name: str = "demo_compass"
        uses_gradient: bool = False
        defaults: dict = field(default_factory=dict)

        def run(self, view, u0, options):
            \"\"\"Search from u0; converged when the step falls below options['xtol'].\"\"\"
            def merit(u):
                return float(np.max(view.evaluate_u(u, gradient=False)[0]))

            u, best, step = np.array(u0, dtype=float), merit(u0), 0.25
            while step > max(options["xtol"], 1e-9):
                moved = False
                for i in range(u.size):
                    for sign in (1.0, -1.0):
                        trial = u.copy()
                        trial[i] = min(max(trial[i] + sign * step, 0.0), 1.0)
                        value = merit(trial)
                        if value < best:
                            u, best, moved = trial, value, True
                if not moved:
                    step /= 2
            return Outcome(u, best, "converged", "step below xtol")


    register(CompassSearch())
"""


def test_a_design_method_is_one_file(copy: Copy) -> None:
    """Registered by its module alone; solves a minimax problem with a closed-form optimum and is a config name."""
    copy.write("design/methods/demo_compass.py", METHOD)
    out = copy.python("""
        import json
        import numpy as np
        from railopt.design import METHODS, DesignVariable, MinimaxProblem, solve
        from railopt.studies.config import load_study
        problem = MinimaxProblem([DesignVariable("x", -3.0, 3.0)], lambda x: np.array([x[0] ** 2, (x[0] - 2) ** 2]))
        r = solve(problem, [-2.5], method="demo_compass")
        print(json.dumps({"known": "demo_compass" in METHODS, "x": float(r.x[0]), "u": r.value, "status": r.status}))
    """)
    got = json.loads(out)
    assert got["known"] and got["status"] == "converged"
    assert got["x"] == pytest.approx(1.0, abs=1e-6) and got["u"] == pytest.approx(1.0, abs=1e-5)  # U* = 1 at x = 1
    assert len(copy.touched) == _stated("a design method")


SDOF_MODEL = """
    '''Catalog model ``demo_sdof``: a damped single-degree-of-freedom oscillator under a unit force.'''

    import numpy as np
    from pydantic import Field

    from railopt.models.parametric import ParameterPart, ParametricSystem
    from railopt.studies.catalog import ModelSetup, ParameterMap, register_model
    from railopt.studies.config import StrictModel


    class SDOFOptions(StrictModel):
        '''Mass (kg) of the oscillator.'''

        mass_kg: float = Field(2.0, gt=0)


    @register_model("demo_sdof", SDOFOptions, "m x'' + c x' + k x = F; output k·x per unit force")
    def sdof_setup(options: SDOFOptions) -> ModelSetup:
        '''Parameters k (N/m) and c (N·s/m) at 800 N/m and 4 N·s/m.'''
        family = ParametricSystem(
            M0=np.array([[options.mass_kg]]), C0=np.zeros((1, 1)), K0=np.zeros((1, 1)), F0=np.array([1.0]),
            parts={"k": ParameterPart(K=np.eye(1)), "c": ParameterPart(C=np.eye(1))},
            values={"k": 800.0, "c": 4.0}, outputs={"kx": np.array([800.0])}, names=("x",))
        return ModelSetup(family=family, parameter_map=ParameterMap(("k", "c"), family.values),
                          named_designs={"base": {"k": 800.0, "c": 4.0}}, description="SDOF")
"""

SDOF_STUDY = """
    [study]
    name = "demo_sdof_frf"
    kind = "frf"

    [[models]]
    label = "sdof"
    model = "demo_sdof"

    [[designs]]
    label = "base"
    named = "base"

    [grid]
    band_hz = [0.5, 6.0]
    points = 400
"""


def test_a_catalog_model_is_one_file(copy: Copy) -> None:
    """Discovered by its module alone; an frf study of it finds the closed-form SDOF peak."""
    copy.write("studies/catalog/demo_sdof.py", SDOF_MODEL)
    (copy.base / "sdof.toml").write_text(textwrap.dedent(SDOF_STUDY))  # the user's study, not the package
    out = copy.python("""
        import json, sys
        import pandas as pd
        from railopt.studies.cli import main
        code = main(["run", "sdof.toml", "--workers", "0", "--results", "out"])
        peaks = pd.read_csv("out/demo_sdof_frf/peaks.csv")
        print(json.dumps({"code": code, "peak": float(peaks["peak"].iloc[0])}))
    """)
    got = json.loads(out.strip().splitlines()[-1])
    m, k, c = 2.0, 800.0, 4.0
    zeta = c / (2 * np.sqrt(k * m))
    assert got["code"] == 0
    assert got["peak"] == pytest.approx(1 / (2 * zeta * np.sqrt(1 - zeta**2)), rel=1e-9)  # |H| max of x/F, per unit
    assert len(copy.touched) == _stated("a catalog model")


KIND = """
    '''Study kind ``demo_modes``: the undamped natural frequencies of catalogued models at their defaults.'''

    from dataclasses import dataclass
    from typing import ClassVar

    import numpy as np
    import pandas as pd

    from railopt.studies.catalog import ModelsStudy
    from railopt.studies.kind import StudyKind, register_kind


    class ModesStudyConfig(ModelsStudy):
        '''The models whose natural frequencies are listed.'''

        KIND: ClassVar[str] = "demo_modes"


    @dataclass
    class ModesResult:
        '''One row per model and mode: the natural frequency (Hz).'''

        table: pd.DataFrame


    def compute(config, context):
        '''sqrt(eig(M^-1 K)) / 2π of each model at its default parameters.'''
        rows = []
        for ref in config.models:
            system = ref.setup().family.at()
            w2 = np.sort(np.linalg.eigvals(np.linalg.solve(system.M, system.K)).real)
            rows += [{"model": ref.label, "mode": i, "frequency_hz": float(np.sqrt(max(v, 0.0)) / (2 * np.pi))}
                     for i, v in enumerate(w2)]
        return ModesResult(pd.DataFrame(rows))


    def report(result, writer):
        '''The table and a one-line summary.'''
        writer.table(result.table, "modes")
        return "# natural frequencies\\n"


    register_kind(StudyKind("demo_modes", ModesStudyConfig, compute, report, summary="natural frequencies"))
"""

KIND_STUDY = """
    [study]
    name = "demo_modes"
    kind = "demo_modes"

    [[models]]
    label = "tmd"
    model = "tmd"
    options = { mass_ratio = 0.05, primary_mass_kg = 1000.0, primary_frequency_hz = 2.0 }
"""


def test_a_study_kind_is_two_files(copy: Copy) -> None:
    """Discovered by its module; runs from TOML; the config reference is stale until regenerated (2nd file)."""
    copy.write("studies/kinds/demo_modes.py", KIND)
    (copy.base / "modes.toml").write_text(textwrap.dedent(KIND_STUDY))
    check = """
        import sys
        from pathlib import Path
        from railopt.studies.reference import reference_markdown
        print(reference_markdown() == Path("docs/config-reference.md").read_text())
    """
    assert copy.python(check).strip() == "False"  # the new kind is missing from the reference
    copy.python("from railopt.studies.cli import main; main(['reference', '--out', 'docs/config-reference.md'])")
    copy.touched.add("docs/config-reference.md")
    assert copy.python(check).strip() == "True"
    copy.python("from railopt.studies.cli import main; raise SystemExit(main(['run', 'modes.toml', '--workers', '0', "
                "'--results', 'out']))")
    table = pd.read_csv(copy.base / "out" / "demo_modes" / "modes.csv")
    # the two-DOF TMD at Den Hartog's tuning: ω² roots of m1 m2 ω⁴ − (k1 m2 + k2 (m1 + m2)) ω² + k1 k2 = 0
    mu, m1, f1 = 0.05, 1000.0, 2.0
    k1, m2 = m1 * (2 * np.pi * f1) ** 2, mu * m1
    k2 = m2 * (2 * np.pi * f1 / (1 + mu)) ** 2
    w2 = np.roots([m1 * m2, -(k1 * m2 + k2 * (m1 + m2)), k1 * k2])
    np.testing.assert_allclose(np.sort(table["frequency_hz"]), np.sort(np.sqrt(w2)) / (2 * np.pi), rtol=1e-10)
    assert len(copy.touched) == _stated("a study kind")


CHECK = """


    @dataclass(frozen=True)
    class NaturalFrequencyCheck:
        '''The lowest undamped natural frequency (Hz) of the family at p; ``above``: it exceeds ``minimum_hz``.'''

        family: ParametricSystem
        minimum_hz: float
        flag_names: ClassVar[tuple[str, ...]] = ("above",)

        def __call__(self, p: np.ndarray) -> CheckResult:
            '''Check one parameter vector p (P,).'''
            system = self.family.at(np.asarray(p, dtype=float))
            w2 = np.linalg.eigvals(np.linalg.solve(system.M, system.K)).real
            value = float(np.sqrt(max(w2.min(), 0.0)) / (2 * np.pi))
            return CheckResult(value, {"above": value > self.minimum_hz})
"""


def test_a_check_is_two_files(copy: Copy) -> None:
    """A class beside the others and its entry in the catalog model that offers it; used on a design."""
    copy.append("studies/catalog/checks.py", CHECK)
    copy.replace("studies/catalog/tmd.py", 'checks={"spectral_abscissa": AbscissaCheck(family)},',
                 'checks={"spectral_abscissa": AbscissaCheck(family), '
                 '"natural_frequency": NaturalFrequencyCheck(family, 1.0)},')
    copy.append("studies/catalog/tmd.py",
                "\nfrom railopt.studies.catalog.checks import NaturalFrequencyCheck  # noqa: E402\n")
    out = copy.python("""
        import json
        from railopt.studies.catalog import discover_models
        setup = discover_models()["tmd"].build(discover_models()["tmd"].options(mass_ratio=0.05))
        r = setup.checks["natural_frequency"](setup.defaults)
        print(json.dumps({"value": r.value, "above": r.flags["above"]}))
    """)
    got = json.loads(out)
    mu = 0.05
    k1, m1, m2 = (2 * np.pi * 2.0) ** 2 * 1000.0, 1000.0, 50.0
    k2 = m2 * (2 * np.pi * 2.0 / (1 + mu)) ** 2
    w2 = np.roots([m1 * m2, -(k1 * m2 + k2 * (m1 + m2)), k1 * k2]).min()
    assert got["value"] == pytest.approx(np.sqrt(w2) / (2 * np.pi), rel=1e-10) and got["above"]
    assert len(copy.touched) == _stated("a check of finished designs")
