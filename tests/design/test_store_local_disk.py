"""The campaign store needs a local disk: a store on a network file system is refused (or, when allowed, kept out
of WAL mode).  The mount tables here are written by the tests (no real NFS needed); what is checked against them:
the mount holding a path is the longest mount point leading it (the later of two on one point), octal escapes of
/proc/mounts (``\\040`` = space, proc(5)) are decoded, and the types of network file systems are told from local
ones.  Values of the one campaign run against the closed form f = (a², (a − 1)² + 0.5) on [−1, 2]: U* = 0.75 at
a = 0.75 (where f1 = f2)."""

from __future__ import annotations

import sqlite3
import warnings
from contextlib import closing
from pathlib import Path

import numpy as np
import pytest

import railopt.design.store as store_module
from railopt.design import CampaignStore, DesignVariable, MinimaxProblem, multistart
from railopt.design.store import (
    NETWORK_STORE_ENV,
    StoreError,
    network_filesystem,
    parse_mounts,
    store_filesystem,
)

PROBLEM = MinimaxProblem([DesignVariable("a", -1.0, 2.0)], lambda x: np.array([x[0] ** 2, (x[0] - 1) ** 2 + 0.5]))
U_STAR = 0.75 ** 2  # a² = (a − 1)² + 0.5  ⇔  a = 0.75


def _table(tmp_path: Path, fstype: str) -> str:
    """A mount table: the root on ext4, ``tmp_path/share`` on ``fstype``, ``tmp_path/share/local`` on ext4."""
    return (f"/dev/vda / ext4 rw,relatime 0 0\n"
            f"server:/export {tmp_path}/share {fstype} rw,vers=4.2 0 0\n"
            f"/dev/vdb {tmp_path}/share/local ext4 rw 0 0\n")


@pytest.fixture
def mounts(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """Point the store at a fake /proc/mounts; returns a function that writes the table for a given type."""
    fake = tmp_path / "mounts"
    monkeypatch.setattr(store_module, "MOUNTS", fake)
    monkeypatch.delenv(NETWORK_STORE_ENV, raising=False)
    (tmp_path / "share" / "local").mkdir(parents=True)

    def write(fstype: str) -> Path:
        fake.write_text(_table(tmp_path, fstype))
        return tmp_path / "share"

    return write


def test_parse_mounts_decodes_escapes_and_keeps_the_order() -> None:
    text = ("sysfs /sys sysfs rw 0 0\n"
            "srv:/a\\040b /mnt/with\\040space nfs4 rw,hard 0 0\n"
            "srv:/c /mnt/tab\\011and\\134back cifs ro 0 0\n"
            "short line\n")
    assert parse_mounts(text) == [("/sys", "sysfs", "rw"), ("/mnt/with space", "nfs4", "rw,hard"),
                                  ("/mnt/tab\tand\\back", "cifs", "ro")]


def test_the_mount_holding_a_path_is_the_longest_leading_mount_point(tmp_path: Path) -> None:
    share, local = tmp_path / "share", tmp_path / "share" / "local"
    local.mkdir(parents=True)
    table = parse_mounts(_table(tmp_path, "nfs4"))
    assert store_filesystem(share / "c.sqlite", table)[:2] == (str(share), "nfs4")
    assert store_filesystem(local / "c.sqlite", table)[:2] == (str(local), "ext4")  # a local disk mounted inside
    assert store_filesystem(tmp_path / "sharex" / "c.sqlite", table)[:2] == ("/", "ext4")  # a name, not a prefix
    # a folder not made yet: its nearest existing folder decides; a link into the share is the share
    assert store_filesystem(share / "new" / "deeper" / "c.sqlite", table)[1] == "nfs4"
    (tmp_path / "link").symlink_to(share)
    assert store_filesystem(tmp_path / "link" / "c.sqlite", table)[1] == "nfs4"
    # of two mounts on one point, the later hides the earlier
    over = [*table, (str(share), "tmpfs", "rw")]
    assert store_filesystem(share / "c.sqlite", over)[1] == "tmpfs"


@pytest.mark.parametrize("fstype", ["nfs", "nfs4", "cifs", "smb3", "fuse.sshfs", "9p", "lustre", "vboxsf"])
def test_network_file_systems_are_told(tmp_path: Path, fstype: str) -> None:
    (tmp_path / "share").mkdir()
    table = parse_mounts(_table(tmp_path, fstype))
    assert network_filesystem(tmp_path / "share" / "c.sqlite", table) == f"{fstype} at {tmp_path / 'share'}"


@pytest.mark.parametrize("fstype", ["ext4", "xfs", "btrfs", "tmpfs", "overlay", "zfs", "fuseblk", "apfs"])
def test_local_file_systems_are_not(tmp_path: Path, fstype: str) -> None:
    (tmp_path / "share").mkdir()
    assert network_filesystem(tmp_path / "share" / "c.sqlite", parse_mounts(_table(tmp_path, fstype))) is None


def test_a_store_on_nfs_is_refused_before_anything_is_made(tmp_path: Path, mounts) -> None:
    share = mounts("nfs4")
    path = share / "campaigns" / "c.sqlite"
    with pytest.raises(StoreError, match=rf"^store: {path} is on a network file system \(nfs4 at {share}\).*"
                                         rf"refusing to create it.*--results.*{NETWORK_STORE_ENV}=allow"):
        CampaignStore.create(path, "c", {}, ["a"])
    assert sorted(p.name for p in share.iterdir()) == ["local"]  # no folder, no temporary file


def test_a_store_moved_onto_nfs_is_refused_for_writing_and_read_as_it_is(tmp_path: Path, mounts) -> None:
    share = mounts("ext4")
    path = share / "c.sqlite"
    with CampaignStore.create(path, "c", {}, ["a"]) as store:
        table = multistart(PROBLEM, 4, seed=1, store=store)
    mounts("nfs")  # the same folder, now a network mount
    with pytest.raises(StoreError, match=rf"^store: {path} is on a network file system \(nfs at {share}\).*"
                                         "refusing to write it"):
        CampaignStore.open(path)
    with CampaignStore.open(path, read_only=True) as store:  # reading a closed store is allowed
        np.testing.assert_array_equal(store.starts()["value"], table["value"])
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-8)
    with CampaignStore.create(share / "local" / "c.sqlite", "c", {}, ["a"]):  # a local disk inside the share
        pass


def test_allowed_on_nfs_the_store_runs_in_the_rollback_journal_and_warns(tmp_path: Path, mounts,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    share = mounts("nfs4")
    monkeypatch.setenv(NETWORK_STORE_ENV, "allow")
    path = share / "c.sqlite"
    with pytest.warns(RuntimeWarning, match=f"{NETWORK_STORE_ENV}=allow: using it in the rollback journal"):
        store = CampaignStore.create(path, "c", {}, ["a"])
    with store:
        assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "delete"  # never WAL there
        multistart(PROBLEM, 3, seed=2, store=store)
        assert not Path(f"{path}-wal").exists() and not Path(f"{path}-shm").exists()
    with pytest.warns(RuntimeWarning), CampaignStore.open(path) as store:  # a resume: still no WAL
        assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "delete"
        table = multistart(PROBLEM, 6, seed=2, store=store)
    assert list(table["start_id"]) == list(range(6))
    assert table["value"].min() == pytest.approx(U_STAR, abs=1e-8)
    with closing(sqlite3.connect(path)) as db:
        assert db.execute("SELECT count(*) FROM starts").fetchone()[0] == 6


def test_without_proc_mounts_the_portable_table_is_used(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """macOS, BSD, Windows: no /proc/mounts; psutil's partition table (``disk_partitions(all=True)``) is read."""
    share = tmp_path / "share"
    share.mkdir()
    monkeypatch.setattr(store_module, "MOUNTS", tmp_path / "no-such-mounts")
    monkeypatch.delenv(NETWORK_STORE_ENV, raising=False)
    monkeypatch.setattr(store_module, "_partitions", lambda: [("/", "apfs", "rw"), (str(share), "smbfs", "rw")])
    with pytest.raises(StoreError, match=rf"\(smbfs at {share}\)"):
        CampaignStore.create(share / "c.sqlite", "c", {}, ["a"])
    monkeypatch.setattr(store_module, "_partitions", lambda: None)  # no table at all: not known, so not refused
    assert store_filesystem(share / "c.sqlite") is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        CampaignStore.create(share / "c.sqlite", "c", {}, ["a"]).close()


def test_this_machines_own_table_finds_the_root() -> None:
    """The real /proc/mounts (Linux): the root's mount is found for a path there."""
    if not Path("/proc/mounts").exists():
        pytest.skip("no /proc/mounts on this system (the portable table is tested above)")
    assert store_filesystem("/")[0] == "/"
