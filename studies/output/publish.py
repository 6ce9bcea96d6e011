"""Publishing a study's results all-or-nothing, one run per study at a time.

Layout under the results root (``--results``, default ``runs/``)::

    <study>/                      the published folder: tables, figures, summary.md, study.toml,
      campaigns/<label>.sqlite    and the campaign stores (the resumable state)
    .<study>.lock                 held while a run of <study> is under way (PID, host, start time)
    .staging-<study>-<pid>/       a run's new files, built up beside the published folder
    .old-<study>-<pid>/           the previous published folder, for the moment of the swap

A run takes the study lock (:func:`study_lock`), clears what dead runs left (:func:`clear_leftovers`),
writes everything it publishes into its staging folder, and then swaps the whole folder in with
two renames (:func:`publish`); on any failure the previous folder is put back, so a reader always
sees one complete run.  A study folder that is a symbolic link (results kept on another disk) keeps its
link: the swap is done where the link points (:func:`study_home`), with the staging and ``.old-`` folders
beside the link's target, so a run never moves the link itself.  :func:`publication` does all of this for one
run.  Campaign stores are written as starts finish — in the published folder, so that a killed run can be
resumed, or (``--fresh``) in the staging folder, so that the old stores are discarded only when the new run
has succeeded.  Before the swap the stores are copied into staging.
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
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "CAMPAIGNS",
    "Publication",
    "ResultsError",
    "StudyLocked",
    "carry_stores",
    "check_writable",
    "clear_leftovers",
    "ensure_folder",
    "lock_path",
    "publication",
    "publish",
    "remove_if_empty",
    "results_root",
    "study_home",
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


def _os_error(exc: OSError, path: Path, doing: str, flag: str = "--results") -> ResultsError:
    where = exc.filename if exc.filename is not None else path
    if exc.errno in (errno.ENOTDIR, errno.EEXIST):
        why = "a file is in the way where a folder must be"
    else:
        why = exc.strerror or str(exc)
    return ResultsError(f"results: cannot {doing} {where}: {why}; {flag} must name a writable folder")


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


def results_root(text: str, flag: str = "--results") -> Path:
    """The results root a user named (``--results``): refused when empty or blank, which would otherwise mean the
    working folder (``Path("")`` is ``.``); ``.`` written out is taken as asked.  Raises :class:`ResultsError`
    naming ``flag``."""
    if not str(text).strip():
        raise ResultsError(f"{flag}: empty; name the folder to write into (e.g. {flag} runs), or . for this folder")
    return Path(text)


def study_home(final: Path) -> Path:
    """Where the study folder ``final`` really is: ``final`` itself, or where it points when it is a symbolic link
    (followed to the end; a dangling link's target is where the next run publishes).

    Raises :class:`ResultsError` naming ``final`` for a link that loops.
    """
    if not final.is_symlink():
        return final
    try:
        return final.resolve(strict=False)
    except (OSError, RuntimeError) as exc:  # a loop: RuntimeError before Python 3.13, OSError (ELOOP) after
        raise ResultsError(f"results: {final} is a symbolic link that cannot be followed ({exc}); remove it or "
                           "point it at a folder") from None


def remove_if_empty(folder: Path) -> None:
    """Remove ``folder/campaigns`` and ``folder`` if they are empty folders (a failed first run made them for its
    stores and stored nothing); anything with content is kept."""
    for path in (folder / CAMPAIGNS, folder):
        with suppress(OSError):
            if path.is_dir() and not path.is_symlink():
                path.rmdir()


def ensure_folder(path: Path, flag: str = "--results") -> Path:
    """Create ``path`` (and parents) as a folder, or raise :class:`ResultsError` naming it (and ``flag``, the
    option that named it)."""
    if path.exists() and not path.is_dir():
        raise ResultsError(f"results: {path} is a file, not a folder; {flag} must name a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _os_error(exc, path, "create the folder", flag) from None
    return path


def check_writable(*folders: Path, flag: str = "--results") -> None:
    """Refuse early, naming it, a folder among ``folders`` that exists but cannot be written."""
    for folder in folders:
        if folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
            raise ResultsError(f"results: {folder} is not writable; make it writable or choose another {flag}")


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
    return sorted((p for p in results.iterdir() if pattern.match(p.name)), key=lambda p: p.lstat().st_mtime)


def _remove(path: Path) -> bool:
    """Remove a leftover: a link or file by unlinking it (never what a link points to), a folder with its contents;
    True when it is gone."""
    with suppress(OSError):
        if path.is_symlink() or not path.is_dir():
            path.unlink()
        else:
            shutil.rmtree(path)
    return not os.path.lexists(path)


def clear_leftovers(results: Path, study: str) -> None:
    """Remove what dead runs of ``study`` left behind (with a note on stderr); call it holding the study lock.

    Holding the lock means no other run of the study is alive, so every staging folder of the
    study is stale.  A run killed between the two renames of :func:`publish` leaves no published
    folder but an ``.old-`` one and its own staging folder: that ``.old-`` folder is put back.  Any other ``.old-``
    entry (one a finished swap could not remove, a link left by an older railopt) is removed, never put back: once
    its run finished it is not the current result, even after the published folder is deleted.  A leftover that
    cannot be removed is named, with what to do.
    """
    final = results / study
    staging = {p.name.rsplit("-", 1)[1] for p in _leftovers(results, study, "staging")}
    olds = _leftovers(results, study, "old")
    interrupted = [p for p in olds if p.name.rsplit("-", 1)[1] in staging and p.is_dir() and not p.is_symlink()]
    if interrupted and not os.path.lexists(final):
        back = interrupted[-1]  # the newest: the folder that was published last
        os.rename(back, final)
        olds.remove(back)
        print(f"railopt: note: put back {final}, moved aside by a run killed while publishing", file=sys.stderr)
    for path in _leftovers(results, study, "staging") + olds:  # ours too: a dead run may have had our PID
        if _remove(path):
            print(f"railopt: note: removed {path}, left by a run that did not finish", file=sys.stderr)
        else:
            print(f"railopt: warning: cannot remove {path}, left by a run that did not finish; remove it by hand "
                  "(it is never taken for the current results)", file=sys.stderr)


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
    """Make ``staging`` the published ``final`` folder with renames; the old one survives any failure.

    A ``final`` that is a symbolic link is kept: the folder it points to is swapped (``staging`` must then be on
    that folder's file system, e.g. beside it: :func:`staging_path` of ``study_home(final).parent``)."""
    final = study_home(final)
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
        _remove(old)  # one it cannot remove is removed (or named) by the next run; it is never put back


@dataclass(frozen=True)
class Publication:
    """One run's folders (see :func:`publication`): ``final`` the study folder as the user names it
    (``<results>/<study>``), ``home`` where it really is (its target when ``final`` is a symbolic link),
    ``staging`` this run's staging folder (beside ``home``)."""

    results: Path
    study: str
    final: Path
    home: Path
    staging: Path

    def publish(self, carry: bool = True) -> None:
        """Copy the published folder's campaign stores into staging (``carry``; not under ``--fresh``, whose new
        stores are in staging already), then swap staging in as the study folder (:func:`publish`)."""
        if carry:
            carry_stores(self.final, self.staging)
        with writing(self.final):
            publish(self.staging, self.final)


@contextmanager
def publication(results: Path | str, study: str, flag: str = "--results") -> Iterator[Publication]:
    """The folders of one run of ``study`` under ``results``, checked before any work, the study lock held
    throughout.

    Before yielding: ``results`` is refused when empty (:func:`results_root`) or a file, created if missing; the
    study folder (or what its link points to) is refused when it is a file; every folder the run will write is
    checked writable; the lock is taken (:class:`StudyLocked` naming its holder) and what dead runs left is cleared
    (:func:`clear_leftovers`, beside the link and beside its target).  On leaving, the staging folder is removed;
    after a failure, a study folder this run created is removed again if nothing was stored in it (a first run
    that failed before finishing a start leaves nothing that blocks the next run).
    """
    root = ensure_folder(results_root(str(results), flag) if isinstance(results, str) else Path(results))
    final = root / study
    home = study_home(final)
    if home.exists() and not home.is_dir():
        raise ResultsError(f"results: {home} is a file, not a folder; move it away to publish study {study!r}")
    beside = ensure_folder(home.parent)
    check_writable(root, beside, home, home / CAMPAIGNS)  # before hours of work, not when publishing
    existed = home.exists()
    if final.is_symlink() and not existed:  # a dangling link (its folder deleted): the stores go where it points
        ensure_folder(home)
    with study_lock(root, study):
        clear_leftovers(root, study)
        if (beside, home.name) != (root, study):
            clear_leftovers(beside, home.name)
        staging = ensure_folder(staging_path(beside, home.name))
        try:
            yield Publication(root, study, final, home, staging)
        except BaseException:
            if not existed:
                remove_if_empty(home)
            raise
        finally:
            shutil.rmtree(staging, ignore_errors=True)
