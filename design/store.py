"""The campaign store: one SQLite file per campaign, a versioned schema, a reader returning DataFrames.

Finished starts are committed as they stream back: the starts of the tasks that finished together in one
transaction (:meth:`CampaignStore.add_starts`, a group commit of at most 32 tasks, never waiting to fill it), and a
start is reported as done only once committed.  A killed campaign keeps every start it reported; it loses the
starts of the tasks that were running (a task holds one start, or a batch of up to 8 short ones) and at most
the one group received but not yet committed; ``--resume`` skips the finished ones.

Local disk only.  A store is written in SQLite's WAL mode, whose index lives in shared memory that processes on
other hosts do not see ("WAL does not work over a network filesystem", sqlite.org/wal.html), and SQLite's locks
rely on POSIX locks that many network file systems break (sqlite.org/howtocorrupt.html §2.1).  Creating a store,
or opening one for writing, on a network or cluster file system (:data:`NETWORK_FILESYSTEMS`, the type of the
mount holding the path: :func:`network_filesystem`) is refused with a :class:`StoreError` naming the file, the
file system and its mount point; ``$RAILOPT_STORE_ON_NETWORK_FS=allow`` turns that into a warning and keeps the
store in the rollback journal.  Read-only opens are allowed anywhere.
``start_id`` is the primary key: a start can never be stored twice.  No pickles: vectors are
JSON, and the campaign config is stored with its SHA-256 so that a resume with a different
config is refused.

Concurrency.  While a writer has a store open it runs in SQLite's WAL journal mode, with a busy
timeout of :data:`BUSY_TIMEOUT` s: readers never block the writer and the writer never blocks
readers, so a progress monitor or a notebook may read a live store while a campaign writes it.
Closing the writer checkpoints the log into the file and returns it to the rollback journal (one
self-contained file), unless a reader is still attached (it then stays in WAL mode, as safely).  To read a live
store use ``CampaignStore.open(path, read_only=True)``, or plain SQLite::

    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    rows = db.execute("SELECT start_id, status, value FROM starts").fetchall()  # fetch all, then
    db.close()                                                                   # let go of it

A reader that keeps a read transaction open (an unconsumed cursor) does not block the campaign,
but the write-ahead log cannot be folded back into the file while it lasts, so finish reads
promptly.  A *closed* store is back in the rollback journal, where such a reader does block a writer: opening
it for writing (a ``--resume``) waits up to :data:`BUSY_TIMEOUT` s for the reader to finish, then refuses with a
:class:`StoreError` naming the processes that hold the file open.  The ``<store>-wal`` and ``<store>-shm``
files next to a store are part of it while it is open (and after a writer was killed: the next open recovers the
committed starts from them): copy or move a store only when no process has it open, with those files if they exist.

Starts that killed every worker they ran on are stored with status ``worker_lost`` (x = x0, value
+inf); a resume skips them unless asked to retry them (``finished_ids(retry_failed=True)``), and a
retried start replaces its ``worker_lost`` row.  Schema version 1 holds all of this.

A store is created whole or not at all: it is initialised under a temporary name and linked
into place, which fails if the name is taken — two processes creating one store cannot both
succeed, and neither deletes a file it did not make.  Opening checks the file (SQLite header,
``PRAGMA integrity_check``, tables, schema version) and refuses a damaged one with
:class:`StoreDamaged`, naming the file.
"""

from __future__ import annotations

import datetime as _dt
import errno
import hashlib
import json
import math
import os
import sqlite3
import uuid
import warnings
from collections.abc import Iterable, Iterator, Mapping, Sequence
from contextlib import closing, contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

SCHEMA_VERSION = 1
BUSY_TIMEOUT = 30.0  # s a write waits for another writer's lock (readers never lock the writer out in WAL mode)
RETRYABLE_STATUSES = ("worker_lost",)  # rows a resume re-runs when asked to (retry_failed)
TABLES = ("meta", "campaign", "starts", "checks")
_HEADER = b"SQLite format 3\x00"


class StoreError(ValueError):
    """A campaign store that cannot be used; the message names the file."""


class StoreDamaged(StoreError):
    """A store file that is not an intact campaign store (truncated, overwritten, garbled)."""

    def __init__(self, path: Path, reason: str) -> None:
        self.path, self.reason = Path(path), reason
        super().__init__(f"store: {path} is damaged ({reason}); run again with --fresh to discard it")


class DuplicateStart(StoreError, sqlite3.IntegrityError):
    """A start (or row) that is already in the store; still an ``sqlite3.IntegrityError``."""


# SQLite result codes that say nothing about the file's contents: busy, read-only, disk full, ...
_NOT_DAMAGE = ("SQLITE_BUSY", "SQLITE_LOCKED", "SQLITE_CANTOPEN", "SQLITE_READONLY", "SQLITE_IOERR", "SQLITE_FULL",
               "SQLITE_PERM", "SQLITE_NOMEM", "SQLITE_INTERRUPT")


def _sqlite_error(path: Path, exc: sqlite3.Error, doing: str) -> StoreError:
    """A store error naming the file: :class:`StoreDamaged`, unless the failure is not the file's contents."""
    if getattr(exc, "sqlite_errorname", "").startswith(_NOT_DAMAGE):
        return StoreError(f"store: cannot {doing} {path} ({exc})")
    return StoreDamaged(path, str(exc))

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS campaign (
    id INTEGER PRIMARY KEY CHECK (id = 1),
    name TEXT NOT NULL,
    config_json TEXT NOT NULL,
    config_hash TEXT NOT NULL,
    variables_json TEXT NOT NULL,
    created_utc TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS starts (
    start_id INTEGER PRIMARY KEY,
    origin TEXT NOT NULL,
    x0_json TEXT NOT NULL,
    x_json TEXT NOT NULL,
    value REAL,
    t REAL,
    status TEXT NOT NULL,
    message TEXT NOT NULL,
    evaluations INTEGER NOT NULL,
    wall_time REAL NOT NULL,
    solver TEXT NOT NULL,
    seed INTEGER NOT NULL,
    constraint_violation REAL NOT NULL,
    bound_violation REAL NOT NULL,
    functions_json TEXT NOT NULL,
    finished_utc TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS checks (
    start_id INTEGER NOT NULL,
    name TEXT NOT NULL,
    value REAL,
    payload_json TEXT NOT NULL,
    PRIMARY KEY (start_id, name)
);
"""


def _marks(values: Sequence[object]) -> str:
    return ",".join("?" * len(values))


def _holders(path: Path) -> list[str]:
    """The other processes that have ``path`` (or its ``-wal``/``-shm``/``-journal`` file) open, as
    ``"PID 123 (python3 notebook.py)"``, from ``/proc`` (Linux; elsewhere, or without permission, none are found)."""
    targets = {os.path.realpath(f"{path}{extra}") for extra in ("", "-wal", "-shm", "-journal")}
    found = []
    for entry in Path("/proc").glob("[0-9]*") if Path("/proc/self/fd").is_dir() else ():
        if int(entry.name) == os.getpid():
            continue
        try:
            if not any(os.path.realpath(fd) in targets for fd in (entry / "fd").iterdir()):
                continue
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
        except OSError:  # gone meanwhile, or another user's
            continue
        found.append(f"PID {entry.name} ({command[:80] or '?'})")
    return found


def _held(path: Path, waited: float) -> StoreError:
    """A store another connection keeps locked (a reader's unfinished read transaction in rollback mode: a
    notebook's unconsumed cursor), naming who holds it when that can be found."""
    holders = _holders(path)
    who = (f"held open by {', '.join(holders[:3])}" if holders else "held by another connection (of this process, "
           "or of a process this user cannot inspect)")
    return StoreError(f"store: {path} is locked by a reader that has not finished reading ({who}); waited {waited:g} s "
                      "— finish that read (fetch all rows, close the cursor or the connection), or close that "
                      "process, then run again (a live campaign's store may be read at any time: it is in WAL mode)")


# ---------------------------------------------------------------------- the disk a store is on
MOUNTS = Path("/proc/mounts")  # Linux: the mount table (device, mount point, type, options, ...)
NETWORK_STORE_ENV = "RAILOPT_STORE_ON_NETWORK_FS"  # "allow": a store on a network file system, in rollback mode
# File systems on which SQLite's WAL mode (a shared-memory index, mmap of <store>-shm, coherent only between
# processes of one host) or its POSIX locks cannot be trusted: network and cluster file systems, and the shared
# folders of virtual machines.  Linux names (/proc/mounts) and macOS names (psutil); FUSE ones are "fuse.<name>".
NETWORK_FILESYSTEMS = frozenset({
    "nfs", "nfs4", "cifs", "smb", "smb2", "smb3", "smbfs", "ncpfs", "afs", "coda", "9p", "v9fs", "vboxsf", "vmhgfs",
    "prl_fs", "davfs", "webdav", "afpfs", "lustre", "gpfs", "beegfs", "ceph", "glusterfs", "ocfs2", "gfs2",
    "orangefs", "pvfs2", "fuse.sshfs", "sshfs", "fuse.s3fs", "fuse.rclone", "fuse.gcsfuse", "fuse.glusterfs",
    "fuse.ceph", "fuse.cephfs", "fuse.juicefs", "fuse.davfs", "fuse.goofys", "fuse.blobfuse", "fuse.blobfuse2",
    "fuse.vmhgfs-fuse", "fuse.lizardfs", "fuse.moosefs", "fuse.mfs", "fuse.seaweedfs", "fuse.sshfs-fuse",
    "macfuse", "osxfuse",
})


def _unescape_mount(field: str) -> str:
    r"""A /proc/mounts field with its octal escapes decoded (``\040`` is a space, ``\011`` a tab, ...)."""
    out, i = [], 0
    while i < len(field):
        if field[i] == "\\" and i + 3 < len(field) and field[i + 1:i + 4].isdigit():
            out.append(chr(int(field[i + 1:i + 4], 8)))
            i += 4
        else:
            out.append(field[i])
            i += 1
    return "".join(out)


def parse_mounts(text: str) -> list[tuple[str, str, str]]:
    """``(mount point, file system type, options)`` of each line of a /proc/mounts table, in order (a later
    mount on the same point hides an earlier one).  Lines with fewer than four fields are skipped."""
    rows = []
    for line in text.splitlines():
        fields = line.split()
        if len(fields) >= 4:
            rows.append((_unescape_mount(fields[1]), fields[2], fields[3]))
    return rows


def _partitions() -> list[tuple[str, str, str]] | None:
    """The mount table where /proc/mounts is absent (macOS, BSD, Windows): psutil's, or None."""
    try:
        import psutil

        return [(d.mountpoint, d.fstype, d.opts) for d in psutil.disk_partitions(all=True)]
    except Exception:  # noqa: BLE001  (no table: the file system is not known)
        return None


def store_filesystem(path: str | Path, mounts: Sequence[tuple[str, str, str]] | None = None
                     ) -> tuple[str, str, str] | None:
    """``(mount point, file system type, options)`` of the mount holding ``path`` (a file or folder that need not
    exist yet: its nearest existing folder is looked up, links resolved); ``None`` when it cannot be told.

    ``mounts``: a mount table as :func:`parse_mounts` gives it; default the one of :data:`MOUNTS` (Linux), else
    psutil's (``disk_partitions(all=True)``: macOS, BSD, Windows).  The mount is the one whose mount point is the
    longest leading part of the path; of two on one point, the later.
    """
    here = Path(os.path.abspath(path))
    while not here.exists() and here != here.parent:
        here = here.parent
    real = os.path.realpath(here)
    if mounts is None:
        try:
            mounts = parse_mounts(MOUNTS.read_text())
        except OSError:
            mounts = _partitions()
        if mounts is None:
            return None
    best: tuple[str, str, str] | None = None
    for point, fstype, opts in mounts:
        norm = os.path.normcase(os.path.normpath(point))
        target = os.path.normcase(real)
        inside = target == norm or target.startswith(norm.rstrip(os.sep) + os.sep)
        if inside and (best is None or len(norm) >= len(os.path.normcase(os.path.normpath(best[0])))):
            best = (point, fstype, opts)
    return best


def network_filesystem(path: str | Path, mounts: Sequence[tuple[str, str, str]] | None = None) -> str | None:
    """A description (``"nfs4 at /mnt/data"``) when ``path`` is on a network or cluster file system
    (:data:`NETWORK_FILESYSTEMS`, a Windows network drive, a UNC path), else ``None`` (a local disk, or not
    known)."""
    text = str(path)
    if text.startswith(("\\\\", "//")) and os.name == "nt":
        return "a network share (UNC path)"
    found = store_filesystem(path, mounts)
    if found is None:
        return None
    point, fstype, opts = found
    remote = "remote" in opts.split(",") and os.name == "nt"  # psutil marks network drives on Windows so
    if fstype.lower() in NETWORK_FILESYSTEMS or remote:
        return f"{fstype} at {point}"
    return None


def _local_disk(path: Path, doing: str) -> bool:
    """Refuse a store to be written on a network file system (:class:`StoreError`); with
    ``$RAILOPT_STORE_ON_NETWORK_FS=allow`` warn instead and return False (the store then stays in SQLite's rollback
    journal, not WAL).  True: a local disk (or one not known to be remote): WAL mode.

    Why refused: SQLite's WAL keeps an index in shared memory (``<store>-shm``, mapped by every process), coherent
    only between processes of one host — "WAL does not work over a network filesystem" (sqlite.org/wal.html,
    §"Disadvantages") — and its locks rely on the file system's POSIX locks, broken on many network file systems
    (sqlite.org/howtocorrupt.html §2.1): a store written there can be damaged, and a campaign lost with it."""
    where = network_filesystem(path)
    if where is None:
        return True
    allowed = os.environ.get(NETWORK_STORE_ENV, "").strip().lower() == "allow"
    what = (f"store: {path} is on a network file system ({where}); SQLite's write-ahead log needs a local disk "
            "(its shared-memory index is not shared between hosts) and its locks are unreliable on network file "
            "systems")
    if not allowed:
        raise StoreError(f"{what}: refusing to {doing} it — put the results on a local disk (--results), or set "
                         f"{NETWORK_STORE_ENV}=allow to use it in SQLite's rollback journal at your own risk")
    warnings.warn(f"{what}; {NETWORK_STORE_ENV}=allow: using it in the rollback journal, not WAL (no other host "
                  "may write it; a reader blocks the writer)", RuntimeWarning, stacklevel=3)
    return False


def _configure(path: Path, db: sqlite3.Connection, read_only: bool, wal: bool = True) -> None:
    """The busy timeout and, for a writer, WAL journal mode (until :meth:`CampaignStore.close`; not with
    ``wal=False``: a store on a network file system allowed by :data:`NETWORK_STORE_ENV`).

    Switching a closed store (rollback journal) to WAL needs every reader gone: a reader holding a read
    transaction is waited for up to :data:`BUSY_TIMEOUT` s, then the open fails with a :class:`StoreError` naming
    the processes that have the file open — not a failure at the first write of a resumed campaign."""
    # every statement is read to its end (a pragma returns a row): one left pending holds the connection's read
    # lock, and close() could not fold the log back (the store stayed in WAL mode with -wal/-shm files beside it)
    db.execute(f"PRAGMA busy_timeout = {int(BUSY_TIMEOUT * 1000)}").fetchall()
    if read_only or not wal:
        return
    try:
        db.execute("PRAGMA journal_mode = WAL").fetchall()
    except sqlite3.OperationalError as exc:
        if getattr(exc, "sqlite_errorname", "").startswith(("SQLITE_BUSY", "SQLITE_LOCKED")):
            raise _held(path, BUSY_TIMEOUT) from None
        # not writable: the store keeps its journal mode (a write then fails naming the file and what was written)


def config_hash(config: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON of a config mapping."""
    return hashlib.sha256(json.dumps(config, sort_keys=True, default=str).encode()).hexdigest()


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _num(v: float) -> float | None:
    """SQLite stores ±inf as REAL but NaN as NULL; keep inf, map NaN to NULL explicitly."""
    v = float(v)
    return None if math.isnan(v) else v


def _vec(a: Iterable[float]) -> str:
    return json.dumps([None if math.isnan(float(v)) else (str(float(v)) if math.isinf(float(v)) else float(v))
                       for v in np.asarray(a, dtype=float).ravel()])


def _unvec(s: str) -> np.ndarray:
    return np.array([float("nan") if v is None else float(v) for v in json.loads(s)], dtype=float)


def _initialise(db: sqlite3.Connection, name: str, config: Mapping[str, Any], variables: list[str]) -> None:
    from railopt import __version__

    with db:
        db.executescript(_SCHEMA)
        db.executemany(
            "INSERT INTO meta VALUES (?, ?)",
            [("schema_version", str(SCHEMA_VERSION)), ("railopt_version", __version__)],
        )
        db.execute(
            "INSERT INTO campaign VALUES (1, ?, ?, ?, ?, ?)",
            (name, json.dumps(config, sort_keys=True, default=str), config_hash(config),
             json.dumps(list(variables)), _now()),
        )


def _link_exclusive(src: Path, dst: Path) -> None:
    """Give ``src`` the name ``dst`` unless ``dst`` exists (``FileExistsError``); never replaces."""
    taken = f"store: {dst} already exists (another process created it first)"
    try:
        os.link(src, dst)
        return
    except FileExistsError:
        raise FileExistsError(taken) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
    # a file system without hard links: claim the name exclusively, then fill it
    try:
        fd = os.open(dst, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        raise FileExistsError(taken) from None
    with os.fdopen(fd, "wb") as out, open(src, "rb") as inp:
        out.write(inp.read())


def _check_store(path: Path, db: sqlite3.Connection, expect_config: Mapping[str, Any] | None) -> None:
    """Refuse a store that is damaged, of another schema version or (``expect_config``) of another config."""
    problems = [r[0] for r in db.execute("PRAGMA integrity_check").fetchall()]  # quick_check misses index damage
    if problems != ["ok"]:
        raise StoreDamaged(path, f"integrity check: {problems[0].splitlines()[-1]}")
    tables = {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    missing = [t for t in TABLES if t not in tables]
    if missing:
        raise StoreDamaged(path, f"no campaign tables {missing}")
    version = dict(db.execute("SELECT key, value FROM meta").fetchall()).get("schema_version")
    campaigns = db.execute("SELECT config_hash FROM campaign").fetchall()
    if version is None or len(campaigns) != 1:
        raise StoreDamaged(path, "no schema version or campaign record")
    if version != str(SCHEMA_VERSION):
        raise StoreError(f"store: schema version {version} in {path}, this railopt reads {SCHEMA_VERSION}")
    if expect_config is not None and campaigns[0][0] != config_hash(expect_config):
        raise StoreError(f"store: {path} was made from a different config; refusing to resume it "
                         "(run again with --fresh to discard it)")


class CampaignStore:
    """One campaign's SQLite file.  Use :meth:`create` for a new campaign, :meth:`open` to read/resume."""

    def __init__(self, path: Path, connection: sqlite3.Connection, read_only: bool = False, wal: bool = True
                 ) -> None:
        self.path = Path(path)
        self._db = connection
        self.read_only = read_only
        if str(path) != ":memory:":
            _configure(self.path, connection, read_only, wal)

    # ------------------------------------------------------------------ opening
    @classmethod
    def create(cls, path: str | Path, name: str, config: Mapping[str, Any], variables: list[str]) -> CampaignStore:
        """Create a new store; refuses to touch an existing file (``FileExistsError``), and a path on a network
        file system (:class:`StoreError`, before anything is made; see :func:`network_filesystem`)."""
        path = Path(path)
        if path.exists():
            raise FileExistsError(f"store: {path} already exists (resume it, or remove it to start afresh)")
        wal = _local_disk(path, "create")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except (FileExistsError, NotADirectoryError):
            raise StoreError(f"store: cannot create the folder {path.parent}: a file is in the way") from None
        # initialise under a name only this call uses, then link it into place: the link fails if
        # another process got there first, and only our own temporary file is ever removed
        tmp = path.with_name(f".{path.name}.creating-{os.getpid()}-{uuid.uuid4().hex[:8]}")
        try:
            db = sqlite3.connect(tmp)
            try:
                _initialise(db, name, config, variables)
            finally:
                db.close()
            _link_exclusive(tmp, path)
        except sqlite3.Error as exc:
            raise _sqlite_error(path, exc, "create") from None
        except FileExistsError:
            raise
        except OSError as exc:  # a full disk, a read-only folder: the error of write() names no file
            raise StoreError(f"store: cannot create {path}: {exc.strerror or exc}; free space or choose another "
                             "--results") from None
        finally:
            tmp.unlink(missing_ok=True)
        try:
            return cls(path, sqlite3.connect(path, timeout=BUSY_TIMEOUT), wal=wal)
        except sqlite3.Error as exc:
            raise _sqlite_error(path, exc, "open") from None

    @classmethod
    def in_memory(cls, variables: Sequence[str], name: str = "in-memory") -> CampaignStore:
        """A throw-away store in memory (multistart without a file uses the same code path)."""
        db = sqlite3.connect(":memory:")
        _initialise(db, name, {}, list(variables))
        return cls(Path(":memory:"), db)

    @classmethod
    def open(cls, path: str | Path, expect_config: Mapping[str, Any] | None = None,
             read_only: bool = False) -> CampaignStore:
        """Open an existing store; with ``expect_config`` refuse one made from another config.

        ``read_only=True`` opens it for reading only (safe on a store a campaign is writing; allowed on a network
        file system).  Raises :class:`StoreDamaged` (naming the file) if it is not an intact campaign store, and
        :class:`StoreError` (naming it) if it cannot be opened, is of another schema version, or is opened for
        writing on a network file system (:func:`network_filesystem`).
        """
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(f"store: {path} does not exist")
        if not path.is_file():
            raise StoreDamaged(path, "not a file")
        with open(path, "rb") as fh:
            header = fh.read(len(_HEADER))
        if not header:
            raise StoreDamaged(path, "empty file")
        if header != _HEADER:
            raise StoreDamaged(path, "not an SQLite database: bad header")
        wal = True if read_only else _local_disk(path, "write")
        try:
            db = sqlite3.connect(f"{path.resolve().as_uri()}?mode={'ro' if read_only else 'rw'}", uri=True,
                                 timeout=BUSY_TIMEOUT)
        except sqlite3.Error as exc:
            raise _sqlite_error(path, exc, "open") from None
        try:
            _check_store(path, db, expect_config)
            return cls(path, db, read_only, wal)
        except BaseException as exc:
            db.close()
            if isinstance(exc, sqlite3.Error):
                raise _sqlite_error(path, exc, "read") from None
            raise

    def close(self) -> None:
        """Close, then fold the write-ahead log back into the store file (without waiting for readers).

        The switch back to the rollback journal (one self-contained file: no ``-wal``/``-shm`` left for later
        readers) is made on a connection of its own once this one is closed: on this one it can fail with "database
        table is locked" after the integrity check of :meth:`open`.  A reader still attached keeps the store in WAL
        mode, which is as safe (the next open folds the log in)."""
        self._db.close()
        if str(self.path) == ":memory:" or self.read_only:
            return
        try:
            with closing(sqlite3.connect(f"{self.path.resolve().as_uri()}?mode=rw", uri=True, timeout=0)) as db:
                db.execute("PRAGMA journal_mode = DELETE").fetchall()
        except sqlite3.Error:  # a reader attached, or the folder is gone: the log stays next to the file
            pass

    def __enter__(self) -> CampaignStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ writing
    @contextmanager
    def _reading(self) -> Iterator[None]:
        """SQLite failures while reading become a :class:`StoreError` naming the file."""
        try:
            yield
        except sqlite3.Error as exc:
            raise _sqlite_error(self.path, exc, "read") from None

    @contextmanager
    def _writing(self, what: str) -> Iterator[None]:
        """One transaction; SQLite failures become a :class:`StoreError` naming the file."""
        try:
            with self._db:
                yield
        except sqlite3.IntegrityError as exc:
            raise DuplicateStart(f"store: {self.path}: {what} is already stored ({exc}); is another run writing "
                                 "to this campaign?") from None
        except sqlite3.Error as exc:
            raise _sqlite_error(self.path, exc, f"write {what} to") from None

    def add_start(self, start_id: int, origin: str, seed: int, result: Any) -> None:
        """Record one finished start (a :class:`~railopt.design.result.SolveResult`) atomically.

        A start already stored raises :class:`DuplicateStart`, unless its stored status is one of
        :data:`RETRYABLE_STATUSES` (a retried start): then the new result replaces it.
        """
        self.add_starts([(start_id, origin, seed, result)])

    def add_starts(self, rows: Iterable[tuple[int, str, int, Any]]) -> None:
        """Record finished starts ``(start_id, origin, seed, result)`` in one transaction: all of them or none.

        A group commit: one commit (the costly part of a write: its fsync, 0.5–4 ms on a local disk) for many
        starts, so that a campaign of short starts on many workers is not bound by the store.  Rules per start as
        :meth:`add_start`; a start already stored raises :class:`DuplicateStart` naming it, and nothing of the
        group is written.
        """
        rows = list(rows)
        if not rows:
            return
        ids = [int(r[0]) for r in rows]
        what = f"start {ids[0]}" if len(ids) == 1 else f"starts {ids[0]}, …, {ids[-1]} ({len(ids)} starts)"
        current = ids[0]
        try:
            with self._db:
                for start_id, origin, seed, result in rows:
                    current = int(start_id)
                    self._db.execute(
                        f"DELETE FROM starts WHERE start_id = ? AND status IN ({_marks(RETRYABLE_STATUSES)})",
                        (current, *RETRYABLE_STATUSES))
                    self._db.execute(
                        "INSERT INTO starts VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                        (current, origin, _vec(result.x0), _vec(result.x), _num(result.value), _num(result.t),
                         result.status, result.message, int(result.evaluations), float(result.wall_time),
                         result.method, int(seed), float(result.constraint_violation),
                         float(result.bound_violation), _vec(result.functions), _now()),
                    )
        except sqlite3.IntegrityError as exc:
            raise DuplicateStart(f"store: {self.path}: start {current} is already stored ({exc}); is another run "
                                 "writing to this campaign?") from None
        except sqlite3.Error as exc:
            raise _sqlite_error(self.path, exc, f"write {what} to") from None

    def add_check(self, start_id: int, name: str, value: float, payload: Mapping[str, Any] | None = None) -> None:
        """Record a check of an optimum (e.g. a critical speed); replaces an earlier one of that name."""
        with self._writing(f"check {name!r} of start {start_id}"):
            self._db.execute(
                "INSERT OR REPLACE INTO checks VALUES (?,?,?,?)",
                (int(start_id), name, _num(value), json.dumps(payload or {}, sort_keys=True, default=str)),
            )

    # ------------------------------------------------------------------ reading
    def meta(self) -> dict[str, str]:
        """The store's ``meta`` table as a dict (string keys and values: format version, package versions, …)."""
        return dict(self._db.execute("SELECT key, value FROM meta").fetchall())

    @property
    def config_hash(self) -> str:
        """Hash of the campaign's configuration, which a resumed run must match."""
        return self._db.execute("SELECT config_hash FROM campaign").fetchone()[0]

    def config(self) -> dict[str, Any]:
        """The campaign's configuration as stored (parsed JSON)."""
        return json.loads(self._db.execute("SELECT config_json FROM campaign").fetchone()[0])

    def variables(self) -> list[str]:
        """Names of the design variables, in the order of x."""
        return json.loads(self._db.execute("SELECT variables_json FROM campaign").fetchone()[0])

    def finished_ids(self, retry_failed: bool = False) -> set[int]:
        """Ids a resume skips: every stored start, or with ``retry_failed`` all but the ``worker_lost`` ones."""
        with self._reading():
            if retry_failed:
                rows = self._db.execute(
                    f"SELECT start_id FROM starts WHERE status NOT IN ({_marks(RETRYABLE_STATUSES)})",
                    RETRYABLE_STATUSES)
            else:
                rows = self._db.execute("SELECT start_id FROM starts")
            return {r[0] for r in rows}

    def lost_ids(self) -> set[int]:
        """Ids of the stored starts that killed every worker they ran on (status ``worker_lost``)."""
        with self._reading():
            return {r[0] for r in self._db.execute("SELECT start_id FROM starts WHERE status = 'worker_lost'")}

    def starts(self) -> pd.DataFrame:
        """One row per finished start, sorted by start_id; x0 and x expanded to named columns."""
        with self._reading():
            df = pd.read_sql_query("SELECT * FROM starts ORDER BY start_id", self._db)
        names = self.variables()
        x0 = np.array([_unvec(s) for s in df["x0_json"]]).reshape(len(df), len(names))
        x = np.array([_unvec(s) for s in df["x_json"]]).reshape(len(df), len(names))
        for i, n in enumerate(names):
            df[f"x0_{n}"] = x0[:, i]
        for i, n in enumerate(names):
            df[n] = x[:, i]
        df["value"] = df["value"].astype(float)
        df["functions"] = [_unvec(s) for s in df["functions_json"]]
        return df.drop(columns=["x0_json", "x_json", "functions_json"])

    def checks(self) -> pd.DataFrame:
        """The ``checks`` table, one row per (start, check) ordered so, with ``payload`` parsed from its JSON column."""
        with self._reading():
            df = pd.read_sql_query("SELECT * FROM checks ORDER BY start_id, name", self._db)
        df["payload"] = [json.loads(s) for s in df.pop("payload_json")]
        return df


__all__ = [
    "BUSY_TIMEOUT", "MOUNTS", "NETWORK_FILESYSTEMS", "NETWORK_STORE_ENV", "RETRYABLE_STATUSES", "SCHEMA_VERSION",
    "TABLES", "CampaignStore", "DuplicateStart", "StoreDamaged", "StoreError", "config_hash", "network_filesystem",
    "parse_mounts", "store_filesystem",
]
