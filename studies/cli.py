"""The ``railopt`` command: run and validate studies, summarise vehicles, list studies, benchmark the hot paths.

``railopt validate FILE`` checks a study file or a vehicle file (decided by content: a ``[study]`` table or a
``[vehicle]`` table); ``railopt vehicle NAME_OR_FILE`` prints a vehicle's summary; ``railopt reference`` writes the
config reference (``docs/config-reference.md``).  Errors are one line ``railopt: error: FILE: field.path: message``;
warnings (things a study does not refuse but a user must hear of) ``railopt: warning: FILE: message``.

``railopt run studies/<name>.toml [--workers N] [--scheduler ADDR] [--resume]`` validates the
config (errors name the field, exit code 2, nothing written), takes the study's lock, runs the
study into a staging folder, and swaps it in as ``results/<name>/`` only when the run succeeds
(see :mod:`railopt.studies.output.publish`; the run itself is
:func:`railopt.studies.run_study.execute_study`, shared with the Python API ``run_study``).  Every failure a user
can cause — a bad config, a damaged store, a results folder that cannot be written, a busy study, an unreachable
scheduler — ends as one line on stderr naming the file, field or address, and exit code 2.
"""

from __future__ import annotations

import argparse
import math
import os
import select
import signal
import sqlite3
import sys
import threading
from collections.abc import Sequence
from pathlib import Path

from railopt import __version__
from railopt.design.parallel import SCHEDULER_TIMEOUT_ENV, scheduler_timeout
from railopt.studies.config import ConfigError, load_study, read_toml
from railopt.studies.kind import StudyKind
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.publish import ResultsError, check_writable, ensure_folder, results_root
from railopt.studies.run_study import STUDIES_DIR, execute_study, resolve_study, run_timing, study_warnings

__all__ = [
    "STUDIES_DIR", "build_parser", "check_number", "cmd_bench", "cmd_list", "cmd_reference", "cmd_run", "cmd_validate",
    "cmd_vehicle", "main", "main_vehicle", "print_warnings", "resolve_study", "run_timing", "study_warnings",
]

EXIT_USAGE = 2
EXIT_FAILED = 1
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143
EXIT_PIPE = 141  # 128 + SIGPIPE: what a shell reports for a tool whose reader went away (`seq 1 1e6 | head -1`)
RESULTS_DEFAULT = "runs"  # a user's runs: git-ignored; the committed reference outputs are under results/
MAX_SPEED_M_S = 1000.0  # above any rail vehicle's speed: a larger --speed is a slip (or 1e308), refused by name
WORKERS_PER_CPU = 16  # --workers above this many per CPU is a slip: each worker is a process


def print_warnings(kind: StudyKind, config: object, study_file: Path | str) -> list[str]:
    """Print the kind's warnings on ``config`` as ``railopt: warning: FILE: message`` (stderr); returns them."""
    messages = study_warnings(kind, config)
    for message in messages:
        print(f"railopt: warning: {study_file}: {' '.join(str(message).split())}", file=sys.stderr)
    return messages


def check_number(value: float | None, flag: str, lowest: float, highest: float, *, above: bool = False,
                 unit: str = "") -> float | None:
    """A command-line number (``None`` passes): finite and within [``lowest``, ``highest``] (``above``: strictly
    above ``lowest``), else a :class:`ConfigError` naming ``flag``, the range and the value.  argparse reads
    ``1e308``, ``inf`` and ``nan`` as floats: they are refused here, before any work."""
    if value is None:
        return None
    low_ok = value > lowest if above else value >= lowest
    if not (math.isfinite(value) and low_ok and value <= highest):
        bound = f"{'>' if above else '≥'} {lowest:g}"
        raise ConfigError(f"{flag}: must be a finite number {bound} and ≤ {highest:g}{unit}, got {value!r}")
    return value


def _max_workers() -> int:
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


def _check_workers(workers: int | None, flag: str = "--workers", lowest: int = 0) -> None:
    if workers is not None and not lowest <= workers <= _max_workers():
        raise ConfigError(f"{flag}: must be {lowest} to {_max_workers()} ({WORKERS_PER_CPU} per CPU of this machine: "
                          f"each worker is a process), got {workers}")


def _check_flags(args: argparse.Namespace) -> None:
    _check_workers(args.workers)
    if args.workers is not None and args.scheduler:
        raise ConfigError("--workers and --scheduler: give one of them (a local cluster or an existing scheduler)")
    if args.scheduler_timeout is not None:
        scheduler_timeout(args.scheduler_timeout, "--scheduler-timeout")


class _Terminated(KeyboardInterrupt):
    """SIGTERM, unwound like Ctrl-C: the staging folder is removed and the study lock released."""


def _terminate(signum: int, frame: object) -> None:
    raise _Terminated


def cmd_run(args: argparse.Namespace) -> int:
    """``railopt run``: validate, compute and publish one study; exit code 2 on a user error."""
    study_file = resolve_study(args.study)
    kind, config, _ = load_study(study_file)
    _check_flags(args)
    print_warnings(kind, config, study_file)
    done = execute_study(study_file, kind, config, args.results, fresh=args.fresh, resume=args.resume,
                         workers=args.workers, scheduler=args.scheduler, scheduler_timeout=args.scheduler_timeout,
                         retry_failed=args.retry_failed, show_progress=not args.no_progress)
    events = done.tables["timing"]["cluster_events"] if "cluster_events" in done.tables["timing"] else []
    for text in (t for t in events if isinstance(t, str) and t):
        print(f"railopt: note: {text}", file=sys.stderr)  # a lost worker, and the tasks re-run elsewhere
    name, final = done.name, done.folder
    with_pd_options = done.table.to_string(index=False, float_format=lambda v: f"{v:.7g}")
    print(f"\n{name}: {kind.summary}\n")
    print(with_pd_options)
    print(f"\ncompute {done.compute_s:.1f} s, report {done.report_s:.1f} s")
    print(f"\nwritten to {final}/ ({', '.join(['summary.md', *done.files])})")
    return 0


def cmd_list(args: argparse.Namespace) -> int:
    """``railopt list``: the bundled studies with their kinds and descriptions."""
    import pandas as pd

    rows = []
    for path in sorted(STUDIES_DIR.glob("*.toml")):
        try:
            kind, config, _ = load_study(path)
            rows.append({"study": path.stem, "kind": kind.name, "description": config.study.description})
        except ConfigError as exc:
            rows.append({"study": path.stem, "kind": "?", "description": f"invalid: {exc}"})
    print(markdown_table(pd.DataFrame(rows, columns=["study", "kind", "description"])))
    return 0


def _vehicle_names() -> tuple[str, ...]:
    from railopt.models.vehicle.loader import bundled_vehicles

    return bundled_vehicles()


def _hook_output(text: str, code: int) -> int:
    """Print a hook's text: stdout when it succeeded, stderr (one line for an error) otherwise."""
    stream = sys.stdout if code == 0 else sys.stderr
    print(text.rstrip("\n"), file=stream)
    return code


def cmd_validate(args: argparse.Namespace) -> int:
    """``railopt validate``: check a study or vehicle file without running it."""
    path = Path(args.study)
    if not path.is_file() and args.study in _vehicle_names():
        return _validate_vehicle(args.study)
    study_file = resolve_study(args.study)
    raw = read_toml(study_file, "study or vehicle")
    if "study" not in raw and "vehicle" in raw:
        return _validate_vehicle(str(study_file))
    if "study" not in raw:
        raise ConfigError(f"{study_file}: neither a study file (no [study] table with name and kind) nor a vehicle "
                          "file (no [vehicle] table)")
    kind, config, _ = load_study(study_file)
    print_warnings(kind, config, study_file)
    print(f"{args.study}: valid {kind.name} study '{config.study.name}'")
    return 0


def _validate_vehicle(path: str) -> int:
    from railopt.models.vehicle.summary import main_validate_vehicle

    return _hook_output(*main_validate_vehicle(path))


class _UsageError(Exception):
    pass


class _VehicleParser(argparse.ArgumentParser):
    """Argument errors come back as text (the CLI prints them), not on stderr."""

    def error(self, message: str):  # noqa: D102
        raise _UsageError(f"{self.format_usage().rstrip()}\n{self.prog}: error: {message}")


def main_vehicle(argv: Sequence[str]) -> tuple[str, int]:
    """``railopt vehicle NAME_OR_FILE [--speed S] [--track rigid|flexible] [--markdown] [--modes [PNG]]``: the report
    and the exit code (0; 2 for a file error, with the message ``<file>: <key path>: <what>``); ``--modes`` also
    writes the mode-shape figure (:func:`railopt.studies.output.mode_figure.write_mode_figure`) and names it last.

    ``argv`` are the arguments after ``vehicle``; ``--speed`` is the speed of the modes table in m/s (default
    20 m/s).  Returns ``(text, code)``: the plain-text or Markdown report of
    :func:`railopt.models.vehicle.summary.vehicle_summary` and 0; the usage and the argument error and 2; the
    help and 0 for ``--help``; ``"railopt: error: ..."`` and 2 when the vehicle does not load.  Nothing is printed.
    """
    from railopt.models.vehicle.loader import load_vehicle
    from railopt.models.vehicle.summary import vehicle_summary
    from railopt.studies.output.mode_figure import write_mode_figure

    parser = _VehicleParser(prog="railopt vehicle", description="Summary of a vehicle file.")
    parser.add_argument("vehicle", help="bundled name (sd40-2, manchester-coach, single-wheelset) or a .toml file")
    parser.add_argument("--speed", type=float, default=None, help="speed of the modes table, m/s (default 20)")
    parser.add_argument("--track", choices=("rigid", "flexible"), default="rigid")
    parser.add_argument("--markdown", action="store_true", help="Markdown instead of plain text")
    parser.add_argument("--modes", nargs="?", const="", default=None, metavar="PNG",
                        help="also draw every mode on the plan view at the table's speed (default <name>_modes.png)")
    try:
        args = parser.parse_args(list(argv))
    except _UsageError as exc:
        return str(exc), 2
    except SystemExit:  # --help
        return parser.format_help(), 0
    try:
        check_number(args.speed, "--speed", 0.0, MAX_SPEED_M_S, above=True, unit=" m/s")
        vehicle = load_vehicle(args.vehicle)
        summary = vehicle_summary(vehicle, speed=args.speed, track=args.track)
        drawn = None if args.modes is None else write_mode_figure(vehicle, summary.speed, args.track, args.modes)
    except ValueError as exc:
        return f"railopt: error: {exc}", 2
    text = summary.to_markdown() if args.markdown else summary.to_text()
    return (text if drawn is None else f"{text.rstrip()}\n\nMode shapes: {drawn}\n"), 0


def cmd_vehicle(args: argparse.Namespace) -> int:
    """``railopt vehicle``: a vehicle's summary (masses, modes, critical speeds)."""
    return _hook_output(*main_vehicle(args.argv))


def cmd_reference(args: argparse.Namespace) -> int:
    """``railopt reference``: the config reference (Markdown) to stdout or ``--out``."""
    from railopt.studies.reference import reference_markdown

    text = reference_markdown()
    if args.out is None:
        sys.stdout.write(text)
        return 0
    out = results_root(args.out, "--out")
    try:
        out.write_text(text)
    except OSError as exc:
        raise ResultsError(f"{out}: cannot write the reference ({exc.strerror or exc})") from None
    print(f"written {out}")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """``railopt bench``: the benchmark rows as ratios, written to ``--out`` (default ``runs/benchmarks/``; the
    committed rows are ``results/benchmarks/``, written with ``--out results/benchmarks``).  The folder is checked
    before the benchmarks run (minutes), not when they are written."""
    _check_workers(args.workers, lowest=1)
    out = ensure_folder(results_root(args.out, "--out"), "--out")
    for name in ("bench.csv", "bench.md"):
        if (out / name).exists() and not (out / name).is_file():
            raise ResultsError(f"--out: {out / name} is in the way (not a file); move it away or choose another --out")
    check_writable(out, flag="--out")
    from railopt.studies.bench import run_bench

    run_bench(out, workers=args.workers, quick=args.quick)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The ``railopt`` argument parser: run, list, validate, vehicle, reference, bench."""
    parser = argparse.ArgumentParser(prog="railopt", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"railopt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a study: railopt run studies/<name>.toml")
    run.add_argument("study", help="path to a study TOML, or the name of a bundled study")
    run.add_argument("--workers", type=int, default=None,
                     help="dask worker processes of the embedded LocalCluster (default: CPU count; 0 = serial)")
    run.add_argument("--scheduler", default=None,
                     help="address of an existing dask scheduler (also $RAILOPT_SCHEDULER, used when neither "
                          "--scheduler nor --workers is given)")
    run.add_argument("--scheduler-timeout", type=float, default=None, metavar="SECONDS",
                     help=f"how long to wait for the scheduler (also ${SCHEDULER_TIMEOUT_ENV}; default 5)")
    stores = run.add_mutually_exclusive_group()
    stores.add_argument("--resume", action="store_true", help="finish an interrupted campaign from its store")
    run.add_argument("--retry-failed", action="store_true",
                     help="with --resume: run again the starts stored as worker_lost (a start that killed its worker)")
    stores.add_argument("--fresh", action="store_true",
                        help="start new campaign stores; the old ones are discarded when this run is published")
    run.add_argument("--results", default=RESULTS_DEFAULT,
                     help=f"results root folder (default: ./{RESULTS_DEFAULT}, git-ignored; the committed reference "
                          "outputs are regenerated with --results results)")
    run.add_argument("--no-progress", action="store_true", help="no progress bars")
    run.set_defaults(func=cmd_run)

    lst = sub.add_parser("list", help="list the bundled studies")
    lst.set_defaults(func=cmd_list)

    val = sub.add_parser("validate", help="validate a study file or a vehicle file without running it")
    val.add_argument("study", help="a study TOML ([study] table), a vehicle TOML ([vehicle] table), or a bundled name")
    val.set_defaults(func=cmd_validate)

    veh = sub.add_parser("vehicle", add_help=False,
                         help="summary of a vehicle: railopt vehicle NAME_OR_FILE [--speed S] "
                              "[--track rigid|flexible] [--markdown]")
    veh.add_argument("argv", nargs=argparse.REMAINDER)
    veh.set_defaults(func=cmd_vehicle)

    ref = sub.add_parser("reference", help="the config reference (Markdown) of every kind and catalog model")
    ref.add_argument("--out", default=None, help="write it to this file (default: stdout)")
    ref.set_defaults(func=cmd_reference)

    bench = sub.add_parser("bench", help=f"benchmarks, printed as ratios; written to {RESULTS_DEFAULT}/benchmarks/")
    bench.add_argument("--out", default=f"{RESULTS_DEFAULT}/benchmarks",
                       help=f"folder of bench.csv and bench.md (default: ./{RESULTS_DEFAULT}/benchmarks; the committed "
                            "rows: --out results/benchmarks)")
    bench.add_argument("--workers", type=int, default=2, help="dask workers of the cluster benchmarks (default 2)")
    bench.add_argument("--quick", action="store_true", help="fewer repetitions")
    bench.set_defaults(func=cmd_bench)
    return parser


def _one_line(exc: BaseException) -> str:
    """The message of a user-caused failure, on one line, naming the file where the error has one."""
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}"
    elif isinstance(exc, sqlite3.Error):
        text = f"store: {exc}"
    else:
        text = str(exc) or type(exc).__name__
    return " ".join(text.split())


def _pipe_closed(stream: object) -> bool:
    """Whether ``stream`` is a pipe (or socket) whose reader has gone away (``railopt vehicle sd40-2 | head -1``)."""
    try:
        fd = stream.fileno()  # type: ignore[attr-defined]
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        return any(events & (select.POLLERR | select.POLLHUP) for _, events in poller.poll(0))
    except (AttributeError, ValueError, OSError):  # no file behind it (a test's capture), or closed
        return False


def _quiet_exit() -> int:
    """The reader of stdout went away: no message (it is not an error), and no second failure when Python flushes
    stdout at exit; :data:`EXIT_PIPE`, as a tool ended by SIGPIPE."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (AttributeError, ValueError, OSError):
        pass
    return EXIT_PIPE


def main(argv: list[str] | None = None) -> int:
    """The ``railopt`` entry point: returns the exit code (0, or 2 with one ``railopt: error:`` line; 130 after
    Ctrl-C, 143 after SIGTERM; 141, silently, when the reader of the output went away, e.g. ``| head -1``)."""
    try:
        code = _main(argv)
        sys.stdout.flush()  # a closed pipe shows here, not as "Exception ignored" at exit
        return code
    except BrokenPipeError:
        if _pipe_closed(sys.stdout) or _pipe_closed(sys.stderr):
            return _quiet_exit()
        raise


def _main(argv: list[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["vehicle"]:  # its own options (--speed, --help) go to the vehicle hook, in any order
        args = argparse.Namespace(command="vehicle", func=cmd_vehicle, argv=argv[1:])
    else:
        args = build_parser().parse_args(argv)
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if in_main_thread else None
    try:
        return args.func(args)
    except BrokenPipeError as exc:  # the reader of our output went away: quiet; any other broken pipe is an error
        if _pipe_closed(sys.stdout) or _pipe_closed(sys.stderr):
            return _quiet_exit()
        print(f"railopt: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_USAGE
    except (ValueError, OSError, ResultsError, sqlite3.Error) as exc:  # config, store, results folder, scheduler
        print(f"railopt: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt as exc:
        if args.command != "run":
            kept = ""
        elif getattr(args, "fresh", False):
            kept = "; the previous results and campaign stores are unchanged (this --fresh run's starts are discarded)"
        else:
            kept = "; finished starts are kept in the campaign store; rerun with --resume"
        print(f"railopt: interrupted{kept}", file=sys.stderr)
        return EXIT_TERMINATED if isinstance(exc, _Terminated) else EXIT_INTERRUPTED
    finally:
        if in_main_thread:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
