"""Every code block of README.md and docs/*.md runs, and the numbers the docs quote are the code's.

* ```python blocks: each page's blocks are written, in order, into one script that runs as ``__main__`` in a new
  process (a temporary folder as working folder, so outputs go there; later blocks use earlier names).  The
  blocks preceded by ``<!-- file: NAME -->`` (TOML files of a tutorial) are written there first.
* ```bash blocks: every command of every line (``&&`` chains split).  ``railopt validate | list | vehicle`` run
  for real; ``railopt run | bench | reference`` are parsed by the CLI's own parser, and a study they name must
  exist and validate; set-up commands (venv, pip with extras that exist, ruff, pytest) are accepted; ``cat
  PATH`` needs PATH to exist or to be written by a ``railopt run`` before it.  Anything else fails.
* A block that must not run carries ``<!-- norun: reason -->`` on the line before its fence: the reason is
  required, and a python block so marked must still compile.
* No command hides in an indented (unfenced) code block.

Blocks of other languages (TOML snippets, output listings, folder trees) are not code to run.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest

from railopt.studies.cli import build_parser, main
from railopt.studies.config import load_study
from railopt.studies.run_study import resolve_study

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^(```+|~~~+)\s*([\w+-]*)\s*$")
MARKER = re.compile(r"^<!--\s*(norun|file)\s*:(.*?)-->\s*$")
SCRIPT_TIMEOUT_S = 240


def _rel(page: Path) -> str:
    return str(page.relative_to(ROOT)) if page.is_relative_to(ROOT) else page.name


@dataclass(frozen=True)
class Block:
    """One fenced block: its page, the line of its first content line (1-based), language, text and marker."""

    page: Path
    line: int
    lang: str
    body: str
    marker: str | None = None  # "norun" or "file"
    note: str = ""  # the norun reason or the file name

    @property
    def where(self) -> str:
        return f"{_rel(self.page)}:{self.line}"


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page``, in order, with the ``<!-- norun: … -->`` / ``<!-- file: … -->`` marker on the
    line before each fence."""
    lines = page.read_text().splitlines()
    found, i = [], 0
    while i < len(lines):
        opened = FENCE.match(lines[i])
        if not opened:
            i += 1
            continue
        fence, lang = opened.groups()
        end = next((j for j in range(i + 1, len(lines)) if lines[j].startswith(fence[:3])
                    and not lines[j][len(fence):].strip()), None)
        assert end is not None, f"{page.name}:{i + 1}: unclosed fence"
        before = lines[i - 1].strip() if i > 0 else ""
        marked = MARKER.match(before)
        found.append(Block(page, i + 2, lang.lower(), "\n".join(lines[i + 1:end]),
                           marked.group(1) if marked else None, marked.group(2).strip() if marked else ""))
        i = end + 1
    return found


ALL = [b for page in PAGES for b in blocks(page)]
PYTHON_PAGES = sorted({b.page for b in ALL if b.lang == "python" and b.marker != "norun"})
BASH_PAGES = sorted({b.page for b in ALL if b.lang in ("bash", "sh", "shell", "console") and b.marker != "norun"})


def test_blocks_are_found():
    assert len(PAGES) >= 10 and ROOT / "README.md" in PAGES
    langs = {b.lang for b in ALL}
    assert {"python", "bash", "toml"} <= langs
    assert len(PYTHON_PAGES) >= 5 and len(BASH_PAGES) >= 2


def test_every_marker_has_a_reason_and_every_norun_block_compiles():
    for page in PAGES:
        lines = page.read_text().splitlines()
        for n, line in enumerate(lines):
            if "<!--" in line and re.search(r"\b(norun|file)\b", line):
                marked = MARKER.match(line.strip())
                assert marked and marked.group(2).strip(), f"{_rel(page)}:{n + 1}: `<!-- norun: reason -->` or " \
                                                          f"`<!-- file: NAME -->` with a reason / name: {line!r}"
                assert n + 1 < len(lines) and FENCE.match(lines[n + 1]), \
                    f"{_rel(page)}:{n + 1}: a marker must be the line right before a fence"
    for block in ALL:
        if block.marker == "norun" and block.lang == "python":
            compile(block.body, block.where, "exec")


def test_no_command_hides_in_an_indented_block():
    for page in PAGES:
        inside = False
        for n, line in enumerate(page.read_text().splitlines()):
            if FENCE.match(line):
                inside = not inside
            elif not inside and re.match(r"^( {4}|\t)\s*(railopt |python|\.venv/|from railopt|import railopt)", line):
                pytest.fail(f"{_rel(page)}:{n + 1}: an indented code line escapes this test; fence it: {line!r}")


def script(page: Path) -> tuple[str, dict[int, str]]:
    """The page's runnable python blocks as one script, and script line → doc location."""
    parts, where, line = [], {}, 1
    for block in blocks(page):
        if block.lang != "python" or block.marker == "norun":
            continue
        parts.append(f"# --- {block.where}")
        line += 1
        for k, text in enumerate(block.body.splitlines()):
            parts.append(text)
            where[line] = f"{_rel(page)}:{block.line + k}"
            line += 1
    return "\n".join(parts) + "\n", where


def files(page: Path, folder: Path) -> None:
    """Write the page's ``<!-- file: NAME -->`` blocks into ``folder``."""
    for block in blocks(page):
        if block.marker == "file":
            (folder / block.note).write_text(block.body + "\n")


def _doc_lines(stderr: str, where: dict[int, str]) -> str:
    """The traceback's script lines as doc locations."""
    return re.sub(r'File "[^"]*doc_script\.py", line (\d+)',
                  lambda m: f"File {where.get(int(m.group(1)), 'script:' + m.group(1))}", stderr)


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=_rel)
def test_python_blocks_run(page, tmp_path):
    text, where = script(page)
    files(page, tmp_path)
    (tmp_path / "doc_script.py").write_text(text)
    (tmp_path / "tmp").mkdir()  # temporary folders the blocks make (run_study's default results root) land here
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONWARNINGS": "ignore::DeprecationWarning",
           "TMPDIR": str(tmp_path / "tmp")}
    done = subprocess.run([sys.executable, "doc_script.py"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=SCRIPT_TIMEOUT_S, env=env)
    assert done.returncode == 0, f"{_rel(page)}: a python block fails\n{_doc_lines(done.stderr, where)[-4000:]}"


# ---------------------------------------------------------------------------------------------------- bash blocks

def commands(page: Path) -> list[tuple[str, list[str]]]:
    """``(doc location, argv)`` of every command of the page's bash blocks (``&&`` chains split, comments off)."""
    found = []
    for block in blocks(page):
        if block.lang not in ("bash", "sh", "shell", "console") or block.marker == "norun":
            continue
        for k, line in enumerate(block.body.replace("\\\n", " ").splitlines()):
            tokens = shlex.split(line, comments=True)
            command: list[str] = []
            for token in [*tokens, "&&"]:
                if token in ("&&", ";", "||"):
                    if command:
                        found.append((f"{_rel(page)}:{block.line + k}", command))
                    command = []
                else:
                    command.append(token)
    return found


def _program(argv0: str) -> str:
    return Path(argv0).name


def _railopt(where: str, args: list[str], cwd: Path, produced: set[Path]) -> None:
    command = args[0] if args else ""
    if command in ("validate", "list", "vehicle"):  # cheap: run them
        out, err = io.StringIO(), io.StringIO()
        with contextlib.chdir(cwd), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
        assert code == 0, f"{where}: `railopt {' '.join(args)}` exits {code}: {err.getvalue()[-2000:]}"
        assert out.getvalue().strip(), f"{where}: `railopt {' '.join(args)}` printed nothing"
        if command == "list":  # a bundled study that does not load is listed as kind "?"
            assert "| ? |" not in out.getvalue(), f"{where}: `railopt list` lists an invalid study:\n{out.getvalue()}"
        return
    assert command in ("run", "bench", "reference"), f"{where}: unknown railopt command {args}"
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            parsed = build_parser().parse_args(list(args))
    except SystemExit:
        pytest.fail(f"{where}: `railopt {' '.join(args)}` is refused by the CLI parser: {err.getvalue()}")
    if command == "run":
        with contextlib.chdir(cwd):
            kind, config, _ = load_study(resolve_study(parsed.study))  # exists and validates
        produced.add((cwd / parsed.results / config.study.name).resolve())
    elif command == "reference" and parsed.out is not None:
        assert (cwd / parsed.out).parent.is_dir(), f"{where}: --out {parsed.out}: no such folder"
    elif command == "bench":
        assert parsed.workers >= 0, where


PYTEST_VALUE_OPTIONS = {"-n", "--numprocesses", "--dist", "--durations", "-k", "-m", "-p", "--timeout"}  # take a value


def _setup_command(where: str, argv: list[str], cwd: Path, produced: set[Path]) -> None:
    program = _program(argv[0])
    if program in ("python", "python3") and argv[1:3] in (["-m", "venv"], ["-m", "pytest"]):
        args = argv[3 if argv[2] == "pytest" else 4:]
        for before, path in zip([None, *args], args, strict=False):
            if not path.startswith("-") and before not in PYTEST_VALUE_OPTIONS:
                assert (cwd / path.split("::")[0]).exists(), f"{where}: {path}: no such test path"
        return
    if program == "pip" and argv[1:2] == ["install"]:
        extras = {e for spec in argv[2:] for e in re.findall(r"\[([^\]]+)\]", spec) for e in e.split(",")}
        declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
        assert extras <= set(declared), f"{where}: pip extras {sorted(extras - set(declared))} are not declared"
        return
    if program == "ruff" and argv[1:2] == ["check"]:
        return
    if program == "cat":
        for name in argv[1:]:
            path = (cwd / name).resolve()
            made = any(path == p or p in path.parents for p in produced)
            if produced:  # after a `railopt run` on the line: what that run wrote, not a committed reference file
                assert made, f"{where}: cat {name}: not in what the `railopt run` before it writes ({sorted(produced)})"
            assert made or path.exists(), f"{where}: cat {name}: no such file, and no `railopt run` before writes it"
        return
    pytest.fail(f"{where}: `{' '.join(argv)}`: a command this test does not know; make it a railopt command or "
                f"mark the block `<!-- norun: reason -->`")


@pytest.mark.parametrize("page", BASH_PAGES, ids=_rel)
def test_bash_commands(page, tmp_path):
    cwd = ROOT
    if any(b.marker == "file" for b in blocks(page)):  # a tutorial: its files in a folder of their own
        files(page, tmp_path)
        cwd = tmp_path
    produced: set[Path] = set()  # what the `railopt run` commands of the current line write
    found = commands(page)
    assert found, f"{_rel(page)}: bash blocks without a command"
    line = None
    for where, argv in found:
        if where != line:
            line, produced = where, set()
        if _program(argv[0]) == "railopt":
            _railopt(where, argv[1:], cwd, produced)
        else:
            _setup_command(where, argv, cwd, produced)


def test_the_block_parser_sees_markers_and_chains(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("text\n<!-- norun: starts a 2 h campaign -->\n```python\nx = 1\n```\n\n"
                    "<!-- file: a.toml -->\n```toml\n[a]\n```\n```bash\nrailopt list && cat a.toml  # c\n```\n")
    found = blocks(page)
    assert [(b.lang, b.line, b.marker, b.note) for b in found] == [
        ("python", 4, "norun", "starts a 2 h campaign"), ("toml", 9, "file", "a.toml"), ("bash", 12, None, "")]
    assert [argv for _, argv in commands(page)] == [["railopt", "list"], ["cat", "a.toml"]]


# ------------------------------------------------------------------------------- numbers the docs quote


def _table(page: Path, heading: str) -> pd.DataFrame:
    """The first Markdown table after ``heading`` on ``page``."""
    text = page.read_text()
    start = text.index(heading)
    rows = []
    for line in text[start:].splitlines()[1:]:
        if line.startswith("|"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif rows:
            break
    return pd.DataFrame(rows[2:], columns=rows[0])


def test_vehicle_md_critical_speeds_are_the_models_and_the_studys():
    """docs/vehicle.md's results table: speed, frequency, critical mode name and eigen-solves as computed, and as
    the bundled stability study publishes them (results/locomotive_stability/critical_speeds.csv)."""
    from railopt.models.stability import critical_speed
    from railopt.models.vehicle import load_vehicle

    table = _table(ROOT / "docs" / "vehicle.md", "## Results")
    study = pd.read_csv(ROOT / "results" / "locomotive_stability" / "critical_speeds.csv").set_index("model")
    labels = {"sd40-2": "sd40-2", "manchester-coach": "coach"}
    assert len(table) >= 5
    for row in table.itertuples(index=False):
        vehicle, track = row.vehicle, row.track
        cs = critical_speed(load_vehicle(vehicle), track, (1.0, 150.0), tol=0.01)
        speed = float(re.match(r"([\d.]+) m/s", row._2).group(1))
        assert speed == round(cs.speed, 2), (vehicle, track)
        assert float(row._3.split()[0]) == pytest.approx(cs.frequency, abs=0.006), (vehicle, track)
        assert row.mode == cs.mode, (vehicle, track, row.mode, cs.mode)
        assert int(row._5.split()[0]) == cs.eigen_solves, (vehicle, track)
        if vehicle in labels:
            published = study.loc[f"{labels[vehicle]}_{track}"]
            assert row.mode == published["mode"], (vehicle, track, "results/locomotive_stability")
            assert speed == round(published["critical_speed_m_s"], 2)


# ------------------------------------------------------------------ positions said in words (x forward, y left, z up)

POINT = re.compile(r"\w+\[\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*\]")
WORDS = {  # a word about a point's position → (axis, sign) in railopt's axes (docs/vehicle.md: x forward, y left, z up)
    r"\bahead\b|\bin front\b|\bforward of\b": (0, +1), r"\bbehind\b|\brear of\b": (0, -1),
    r"\bleft\b": (1, +1), r"\bright\b": (1, -1),
    r"\babove\b|\bup\b": (2, +1), r"\bbelow\b|\bdown\b": (2, -1),
}


def direction_slips(text: str) -> list[str]:
    """Lines where a point ``body[x,y,z]`` is described in words that contradict the signs of its coordinates."""
    slips = []
    for line in text.splitlines():
        points = POINT.findall(line)
        if len(points) != 1:
            continue  # no point, or several: the words cannot be attributed
        xyz = [float(v) for v in points[0]]
        words = line[line.index("#"):] if "#" in line else line
        for pattern, (axis, sign) in WORDS.items():
            if re.search(pattern, words, re.IGNORECASE) and xyz[axis] * sign < 0:
                slips.append(f"{line.strip()!r}: {pattern.split('|')[0].strip(chr(92) + 'b')} but "
                             f"{'xyz'[axis]} = {xyz[axis]:g}")
    return slips


def test_the_direction_check_catches_the_slip_kind():
    assert direction_slips('output = "body[6,0.8,1.0].z"  # a seat 6 m behind the body centre, 1 m up')  # the issue's
    assert direction_slips('seat = "body[-4,0.8,1.0].z"  # 4 m ahead of the CG, 0.8 m to the left')  # the same kind
    assert direction_slips('"frame_front[2,-0.6,0].z"  # a point 0.6 m to the left of the frame CG')
    assert not direction_slips('"body[6,0.8,1.0].z"  # 6 m ahead of the body CG, 0.8 m to its left, 1 m above it')


def test_positions_said_in_words_agree_with_the_axes():
    files = [*PAGES, *sorted((ROOT / "studies").glob("*.toml")), *sorted((ROOT / "studies").rglob("*.py")),
             *sorted((ROOT / "models").rglob("*.py"))]
    slips = [f"{_rel(f)}: {slip}" for f in files for slip in direction_slips(f.read_text())]
    assert not slips, "\n".join(slips)


def _first_column(page: Path, header: str) -> set[str]:
    """The first-column names (between backticks) of the Markdown table whose header row starts with ``header``."""
    lines = page.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append(re.match(r"\|\s*`([^`]+)`", line).group(1))
    return set(rows)


def test_studies_md_lists_every_registered_kind_and_catalog_model():
    """A kind (`ride` was missing) or a catalog model that docs/studies.md does not list is a doc out of date."""
    from railopt.studies.catalog import discover_models
    from railopt.studies.kind import discover_kinds

    page = ROOT / "docs" / "studies.md"
    assert _first_column(page, "| kind | module |") == set(discover_kinds())
    assert _first_column(page, "| model | options |") == set(discover_models())
