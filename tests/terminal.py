"""Starting a process that a test interrupts as Ctrl-C in a terminal does.

A shell without job control (a script, or a CI runner, that starts ``pytest … &``) starts its background commands
with SIGINT ignored, and ``exec`` keeps it ignored: Python then installs no ``KeyboardInterrupt`` handler, and a
child that a test sends SIGINT never sees it.  The test would then check the shell's setting, not railopt (the
three Ctrl-C tests failed in exactly this way whenever the suite ran in the background).  A terminal's
foreground job has SIGINT at its default disposition and unblocked; :func:`as_a_foreground_job` gives the child
that.
"""

from __future__ import annotations

import signal

__all__ = ["as_a_foreground_job"]


def as_a_foreground_job() -> None:
    """``preexec_fn`` for :class:`subprocess.Popen`: SIGINT at its default disposition and unblocked in the
    child, whatever the test process inherited."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
