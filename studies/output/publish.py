"""Publishing a study's results all-or-nothing, one run per study at a time.

Layout under the results root (``--results``, default ``results/``)::

    <study>/                      the published folder: tables, figures, summary.md, study.toml,
      campaigns/<label>.sqlite    and the campaign stores (the resumable state)
    .<study>.lock                 held while a run of <study> is under way (PID, host, start time)
    .staging-<study>-<pid>/       a run's new files, built up beside the published folder
    .old-<study>-<pid>/           the previous published folder, for the moment of the swap

A run takes the study lock (:func:`study_lock`), clears what dead runs left (:func:`clear_leftovers`),
writes everything it publishes into its staging folder, and then swaps the whole folder in with
two renames (:func:`publish`); on any failure the previous folder is put back, so a reader always
sees one complete run.  Campaign stores are written as starts finish — in the published folder, so
that a killed run can be resumed, or (``--fresh``) in the staging folder, so that the old stores are
discarded only when the new run has succeeded.  Before the swap the stores are copied into staging.
"""

from __future__ import annotations

import datetime as _dt
import errno
import fcntl
import os
import re
import shutil
import socket
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

__all__ = [
    "CAMPAIGNS",
    "ResultsError",
    "StudyLocked",
    "carry_stores",
    "check_writable",
    "clear_leftovers",
    "ensure_folder",
    "lock_path",
    "publish",
    "write_error",
    "writing",
    "staging_path",
    "study_lock",
]

CAMPAIGNS = "campaigns"


class ResultsError(RuntimeError):
    """A results folder that cannot be used (a file in the way, not writable, busy); names the path."""


class StudyLocked(ResultsError):
    """Another run of the same study holds its lock."""


def _os_error(exc: OSError, path: Path, doing: str) -> ResultsError:
    where = exc.filename if exc.filename is not None else path
    if exc.errno in (errno.ENOTDIR, errno.EEXIST):
        why = "a file is in the way where a folder must be"
    else:
        why = exc.strerror or str(exc)
    return ResultsError(f"results: cannot {doing} {where}: {why}; --results must name a writable folder")


def write_error(exc: OSError, path: Path | str) -> ResultsError:
    """A failed write of ``path`` as one line naming it (a failed ``write()`` has no filename of its own):
    ``results: cannot write <path>: No space left on device; free space or choose another --results``."""
    where = exc.filename if exc.filename is not None else path
    why = exc.strerror or str(exc) or type(exc).__name__
    hint = "free space or choose another --results" if exc.errno in (errno.ENOSPC, errno.EDQUOT) else \
        "--results must name a writable folder"
    return ResultsError(f"results: cannot write {where}: {why}; {hint} (the published results are unchanged)")


@contextmanager
def writing(path: Path | str) -> Iterator[None]:
    """Turn an ``OSError`` raised while writing ``path`` into a :class:`ResultsError` naming it (see
    :func:`write_error`); the caller's staging folder is removed by the CLI, so nothing half-written remains."""
    try:
        yield
    except ResultsError:
        raise
    except OSError as exc:
        raise write_error(exc, path) from None


def ensure_folder(path: Path) -> Path:
    """Create ``path`` (and parents) as a folder, or raise :class:`ResultsError` naming it."""
    if path.exists() and not path.is_dir():
        raise ResultsError(f"results: {path} is a file, not a folder; --results must name a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _os_error(exc, path, "create the folder") from None
    return path


def check_writable(*folders: Path) -> None:
    """Refuse early, naming it, a folder among ``folders`` that exists but cannot be written."""
    for folder in folders:
        if folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
            raise ResultsError(f"results: {folder} is not writable; make it writable or choose another --results")


def lock_path(results: Path, study: str) -> Path:
    """The lock file of ``study`` under ``results``: ``results/.<study>.lock`` (see :func:`study_lock`)."""
    return results / f".{study}.lock"


def _holder(fd: int) -> str:
    os.lseek(fd, 0, os.SEEK_SET)
    return os.read(fd, 512).decode(errors="replace").strip()


def _describe(holder: str) -> str:
    """``"PID 123 on host h since t"`` from a lock file's ``pid host time`` line."""
    parts = holder.split()
    if len(parts) >= 2 and parts[0].isdigit():
        return f"PID {parts[0]} on host {parts[1]}" + (f" since {parts[2]}" if len(parts) > 2 else "")
    return "a process that is just starting"


@contextmanager
def study_lock(results: Path, study: str) -> Iterator[Path]:
    """Hold the lock of ``study`` under ``results`` for the duration of the block.

    The lock is an ``flock`` on ``results/.<study>.lock``, which holds the holder's PID, host and
    start time.  The kernel drops the lock when its holder dies, so the file a killed run leaves
    behind is a stale lock and is taken over (with a note naming the dead holder); a live holder
    makes this raise :class:`StudyLocked` naming it and the lock file.
    """
    path = lock_path(results, study)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise _os_error(exc, path, "create the lock file") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            # the holder writes its line right after taking the lock: a blank line is a holder a moment old
            for _ in range(50):
                if holder:
                    break
                time.sleep(0.02)
                holder = _holder(fd)
            os.close(fd)
            raise StudyLocked(
                f"results: study {study!r} is being run by {_describe(holder)} (lock {path}); "
                "wait for that run to finish"
            ) from None
        except OSError as exc:
            os.close(fd)
            raise _os_error(exc, path, "lock") from None
        # the holder we waited for may have removed the file between our open and our lock
        try:
            current = os.stat(path)
        except FileNotFoundError:
            current = None
        if current is not None and os.path.samestat(os.fstat(fd), current):
            break
        os.close(fd)
    try:
        stale = _holder(fd)
        if stale:
            print(f"railopt: note: took over the stale lock {path} of {_describe(stale)} (no longer running)",
                  file=sys.stderr)
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        os.write(fd, f"{os.getpid()} {socket.gethostname()} {now}\n".encode())
        yield path
    finally:
        with suppress(OSError):  # a folder made read-only meanwhile must not hide the run's own error
            path.unlink(missing_ok=True)  # while still holding it: see the samestat check above
        os.close(fd)


def staging_path(results: Path, study: str) -> Path:
    """This run's staging folder for ``study``."""
    return results / f".staging-{study}-{os.getpid()}"


def _leftovers(results: Path, study: str, kind: str) -> list[Path]:
    pattern = re.compile(rf"^\.{kind}-{re.escape(study)}-(\d+)$")
    return sorted((p for p in results.iterdir() if pattern.match(p.name)), key=lambda p: p.stat().st_mtime)


def clear_leftovers(results: Path, study: str) -> None:
    """Remove what dead runs of ``study`` left behind (with a note on stderr); call it holding the study lock.

    Holding the lock means no other run of the study is alive, so every staging folder of the
    study is stale.  A run killed between the two renames of :func:`publish` leaves no published
    folder but an ``.old-`` one: that one is put back.
    """
    final = results / study
    olds = _leftovers(results, study, "old")
    if olds and not final.exists():
        os.rename(olds.pop(), final)  # the newest: the folder that was published last
        print(f"railopt: note: put back {final}, moved aside by a run killed while publishing", file=sys.stderr)
    for path in _leftovers(results, study, "staging") + olds:  # ours too: a dead run may have had our PID
        shutil.rmtree(path, ignore_errors=True)
        print(f"railopt: note: removed {path}, left by a run that did not finish", file=sys.stderr)


def carry_stores(final: Path, staging: Path) -> None:
    """Copy the campaign stores of the published folder into the staging folder (taken as they are now)."""
    source = final / CAMPAIGNS
    if not source.is_dir():
        return
    target = staging / CAMPAIGNS
    with writing(target):
        target.mkdir(exist_ok=True)
    for item in sorted(source.iterdir()):
        if item.is_file() and not item.name.startswith(".") and not (target / item.name).exists():
            with writing(target / item.name):
                shutil.copy2(item, target / item.name)


def publish(staging: Path, final: Path) -> None:
    """Make ``staging`` the published ``final`` folder with renames; the old one survives any failure."""
    old = final.parent / f".old-{final.name}-{os.getpid()}"
    had_final = final.exists()
    if had_final:
        os.rename(final, old)
    try:
        os.rename(staging, final)
    except BaseException:
        if had_final:
            os.rename(old, final)
        raise
    if had_final:
        shutil.rmtree(old, ignore_errors=True)
