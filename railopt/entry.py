"""The ``railopt`` command's entry point.

The command-line interface (:mod:`railopt.studies.cli`) is imported inside a guard: Ctrl-C while its heavy imports
(numpy, pandas, dask, matplotlib) load ends quietly with ``railopt: interrupted`` and exit status 130, as Ctrl-C does
at any later moment, instead of a traceback of the import machinery.
"""

from __future__ import annotations

import sys

__all__ = ["EXIT_INTERRUPTED", "main"]

EXIT_INTERRUPTED = 130  # 128 + SIGINT, the shell's convention (the CLI's own EXIT_INTERRUPTED)


def main() -> int:
    """Run ``railopt`` with ``sys.argv``; returns the exit status (130 when interrupted while starting)."""
    try:
        from railopt.studies.cli import main as cli_main
    except KeyboardInterrupt:
        print("railopt: interrupted (while starting; nothing was run)", file=sys.stderr)
        return EXIT_INTERRUPTED
    return cli_main()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
