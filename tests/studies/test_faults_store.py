"""Fault tests of the campaign store: damaged files are refused by name, creation is exclusive.

From a real CLI process, a published study's store is damaged in each way a disk, a crash or a
careless user can damage it; ``--resume`` must refuse it with one line naming the file and the
way out (``--fresh``), change nothing, and ``--fresh`` must then replace it.
"""

from __future__ import annotations

import multiprocessing
import os
import random
import re
import sqlite3
from pathlib import Path

import pytest
from faults_cli import (
    STUDY,
    assert_refused,
    baseline_fixtures,
    cli,
    read_only,
    run_args,
    snapshot,
    start_rows,
    store_path,
)

from railopt.design.store import CampaignStore, StoreDamaged, StoreError

N_STARTS = 3  # + the Den Hartog start: ids 0..3


published, results = baseline_fixtures(N_STARTS)


def _layout(store: Path) -> tuple[dict[str, int], int]:
    with sqlite3.connect(store) as db:
        roots = dict(db.execute("SELECT name, rootpage FROM sqlite_master"))
        return roots, db.execute("PRAGMA page_size").fetchone()[0]


def _patch_page(store: Path, page: int, change) -> None:
    _, size = _layout(store)
    data = bytearray(store.read_bytes())
    start = (page - 1) * size
    data[start:start + size] = change(bytearray(data[start:start + size]))
    store.write_bytes(bytes(data))


def _garble(page: bytearray, skip: int = 8) -> bytearray:
    """Random bytes over a page, after its first ``skip`` bytes (the b-tree page header by default)."""
    rng = random.Random(3)
    for i in range(skip, len(page)):
        page[i] = rng.randrange(256)
    return page


def _rename_index_keys(page: bytearray) -> bytearray:
    """Change the keys in an index page without breaking its structure: only a full check can see it."""
    assert b"spectral_abscissa" in page
    return bytearray(bytes(page).replace(b"spectral_abscissa", b"Xpectral_abscissa"))


def _empty_sqlite(store: Path) -> None:
    store.unlink()
    db = sqlite3.connect(store)
    db.execute("PRAGMA user_version = 7")  # a valid SQLite file with no tables
    db.close()


DAMAGE = {
    "zero-length": (lambda p: p.write_bytes(b""), "empty file"),
    "truncated": (lambda p: p.write_bytes(p.read_bytes()[: p.stat().st_size // 2]), "malformed"),
    "random bytes": (lambda p: p.write_bytes(random.Random(7).randbytes(p.stat().st_size)), "bad header"),
    "bad header": (lambda p: p.write_bytes(b"NotSQLite format" + p.read_bytes()[16:]), "bad header"),
    "empty SQLite file": (_empty_sqlite, "no campaign tables"),
    "garbled table page": (lambda p: _patch_page(p, _layout(p)[0]["starts"], _garble), "integrity check"),
    "garbled index page": (lambda p: _patch_page(p, _layout(p)[0]["sqlite_autoindex_checks_1"], _rename_index_keys),
                           "missing from index"),
    "garbled schema page": (lambda p: _patch_page(p, 1, lambda page: _garble(page, 200)), "malformed"),
}


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_resume_refuses_a_damaged_store_naming_it_and_changes_nothing(damage, published, results):
    study, _ = published
    store = store_path(results)
    harm, reason = DAMAGE[damage]
    harm(store)
    before = snapshot(results)
    done = cli(*run_args(study, results, "--resume"))
    line = assert_refused(done, store, "is damaged", reason, "--fresh")
    assert line.endswith("run again with --fresh to discard it")
    assert snapshot(results) == before  # the previous results and the damaged store as they were
    assert sorted(p.name for p in results.iterdir()) == [STUDY]  # no staging folder, no lock left


def test_a_garbled_index_page_passes_quick_check_but_not_the_store(published, results):
    """The damage the issue found passing ``--resume``: ``quick_check`` misses it, so open runs ``integrity_check``."""
    store = store_path(results)
    DAMAGE["garbled index page"][0](store)
    with sqlite3.connect(store) as db:
        assert db.execute("PRAGMA quick_check").fetchall() == [("ok",)]
    with pytest.raises(StoreDamaged, match="missing from index"):
        CampaignStore.open(store)


@pytest.mark.parametrize("damage", ["garbled index page", "zero-length"])
def test_fresh_replaces_a_damaged_store(damage, published, results):
    study, _ = published
    reference = start_rows(store_path(published[1]))
    DAMAGE[damage][0](store_path(results))
    done = cli(*run_args(study, results, "--fresh"))
    assert done.returncode == 0, done.stderr
    with CampaignStore.open(store_path(results)) as store:  # intact again, every start once
        assert sorted(store.finished_ids()) == list(range(N_STARTS + 1))
    assert [r[0] for r in start_rows(store_path(results))] == [r[0] for r in reference]


def test_a_read_only_store_is_named_and_kept(published, results):
    study, _ = published
    store = store_path(results)
    before = snapshot(results)
    with read_only(store):
        done = cli(*run_args(study, results, "--resume"))
    error = assert_refused(done, "cannot write check 'spectral_abscissa' of start", f"to {store}", "readonly database")
    assert re.search(r"of start \d+ to ", error)  # names the start whose check could not be stored
    assert snapshot(results) == before
    assert sorted(p.name for p in results.iterdir()) == [STUDY]


def test_a_file_where_the_campaigns_folder_must_be_is_named(published, tmp_path):
    study, _ = published
    results = tmp_path / "results"
    (results / STUDY).mkdir(parents=True)
    (results / STUDY / "campaigns").write_text("not a folder")
    done = cli(*run_args(study, results))
    assert_refused(done, results / STUDY, "a file is in the way")
    assert (results / STUDY / "campaigns").read_text() == "not a folder"
    assert sorted(p.name for p in (results / STUDY).iterdir()) == ["campaigns"]  # nothing published


def _create(path: str, barrier, outcomes) -> None:
    barrier.wait()
    try:
        CampaignStore.create(path, "c", {"creator": os.getpid()}, ["x"]).close()
        outcomes.put(("created", os.getpid()))
    except FileExistsError as exc:
        outcomes.put(("refused", str(exc)))


def test_two_processes_creating_one_store_one_wins_and_its_file_survives(tmp_path):
    """The issue's 12-of-20 failure: the loser's clean-up unlinked the winner's file."""
    ctx = multiprocessing.get_context("fork")
    for trial in range(20):
        path = tmp_path / f"c{trial}.sqlite"
        barrier, outcomes = ctx.Barrier(2), ctx.Queue()
        procs = [ctx.Process(target=_create, args=(str(path), barrier, outcomes)) for _ in range(2)]
        for p in procs:
            p.start()
        for p in procs:
            p.join(30)
            assert p.exitcode == 0
        results = sorted(outcomes.get(timeout=5) for _ in procs)
        assert [r[0] for r in results] == ["created", "refused"], results
        assert str(path) in results[1][1]
        with CampaignStore.open(path) as store:  # the winner's store, intact
            assert store.config() == {"creator": results[0][1]}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"c{t}.sqlite" for t in range(20))  # no temp files


def test_store_open_refusals_name_the_file(tmp_path):
    path = tmp_path / "c.sqlite"
    CampaignStore.create(path, "c", {}, ["x"]).close()
    with pytest.raises(StoreError, match=f"^store: {path}.*different config.*--fresh"):
        CampaignStore.open(path, expect_config={"other": 1})
    (tmp_path / "d.sqlite").mkdir()
    with pytest.raises(StoreDamaged, match="not a file"):
        CampaignStore.open(tmp_path / "d.sqlite")
