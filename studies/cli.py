"""The ``railopt`` command: run studies, list them, benchmark the hot paths.

``railopt run studies/<name>.toml [--workers N] [--scheduler ADDR] [--resume]`` validates the
config (errors name the field, exit code 2, nothing written), runs the study into a staging
folder, and publishes the files into ``results/<name>/`` only when the run succeeds.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

from railopt import __version__
from railopt.studies.base import StudyContext
from railopt.studies.config import ConfigError, load_study
from railopt.studies.report import markdown_table

STUDIES_DIR = Path(__file__).resolve().parent
EXIT_USAGE = 2
EXIT_FAILED = 1
EXIT_INTERRUPTED = 130


def resolve_study(arg: str) -> Path:
    """A path as given, else ``<name>.toml`` among the bundled studies."""
    path = Path(arg)
    if path.is_file():
        return path
    for candidate in (STUDIES_DIR / arg, STUDIES_DIR / f"{arg}.toml"):
        if candidate.is_file():
            return candidate
    raise ConfigError(f"study: no such file {arg!r} (and no bundled study of that name; see `railopt list`)")


def _publish(staging: Path, final: Path) -> None:
    final.mkdir(parents=True, exist_ok=True)
    for item in sorted(staging.iterdir()):
        os.replace(item, final / item.name)
    staging.rmdir()


def cmd_run(args: argparse.Namespace) -> int:
    kind, config, _ = load_study(resolve_study(args.study))
    if args.workers is not None and args.workers < 0:
        raise ConfigError(f"--workers: must be ≥ 0, got {args.workers}")
    name = config.study.name
    results = Path(args.results)
    final = results / name
    if args.fresh and (final / "campaigns").exists():
        shutil.rmtree(final / "campaigns")
    staging = results / f".staging-{name}-{os.getpid()}"
    staging.mkdir(parents=True, exist_ok=False)
    context = StudyContext(
        outdir=staging,
        store_dir=final,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        show_progress=not args.no_progress,
    )
    try:
        outcome = kind.run(config, context)
        (staging / "summary.md").write_text(outcome.markdown)
        shutil.copyfile(resolve_study(args.study), staging / "study.toml")
        _publish(staging, final)
    finally:
        if staging.exists():
            shutil.rmtree(staging)
    with_pd_options = outcome.table.to_string(index=False, float_format=lambda v: f"{v:.7g}")
    print(f"\n{name}: {kind.summary}\n")
    print(with_pd_options)
    print(f"\nwritten to {final}/ ({', '.join(['summary.md', *outcome.files])})")
    return 0


def cmd_list(args: argparse.Namespace) -> int:
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


def cmd_validate(args: argparse.Namespace) -> int:
    kind, config, _ = load_study(resolve_study(args.study))
    print(f"{args.study}: valid {kind.name} study '{config.study.name}'")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    from railopt.studies.bench import run_bench

    run_bench(Path(args.out), workers=args.workers, quick=args.quick)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="railopt", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"railopt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a study: railopt run studies/<name>.toml")
    run.add_argument("study", help="path to a study TOML, or the name of a bundled study")
    run.add_argument("--workers", type=int, default=None,
                     help="dask worker processes of the embedded LocalCluster (default: CPU count; 0 = serial)")
    run.add_argument("--scheduler", default=None,
                     help="address of an existing dask scheduler (also $RAILOPT_SCHEDULER)")
    stores = run.add_mutually_exclusive_group()
    stores.add_argument("--resume", action="store_true", help="finish an interrupted campaign from its store")
    stores.add_argument("--fresh", action="store_true", help="discard existing campaign stores of this study first")
    run.add_argument("--results", default="results", help="results root folder (default: ./results)")
    run.add_argument("--no-progress", action="store_true", help="no progress bars")
    run.set_defaults(func=cmd_run)

    lst = sub.add_parser("list", help="list the bundled studies")
    lst.set_defaults(func=cmd_list)

    val = sub.add_parser("validate", help="validate a study config without running it")
    val.add_argument("study")
    val.set_defaults(func=cmd_validate)

    bench = sub.add_parser("bench", help="benchmarks, printed as ratios; written to results/benchmarks/")
    bench.add_argument("--out", default="results/benchmarks")
    bench.add_argument("--workers", type=int, default=2)
    bench.add_argument("--quick", action="store_true", help="fewer repetitions")
    bench.set_defaults(func=cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ConfigError, ValueError, FileExistsError, FileNotFoundError) as exc:
        print(f"railopt: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("railopt: interrupted; finished starts are kept in the campaign store; rerun with --resume",
              file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
