"""Cache keys: what changes them and what does not (gaitlib.cache)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from gaitlib import cache
from gaitlib import data as data_mod
from gaitlib.problems import gait as gait_ocp

F = gait_ocp.FORMULATION


@pytest.fixture
def data_copy(tmp_path, monkeypatch):
    """A private copy of data/ (so the test may write identified sets into it)."""
    d = tmp_path / "data"
    shutil.copytree(data_mod.DATA_DIR, d)
    monkeypatch.setattr(data_mod, "DATA_DIR", d)
    return d


def test_identified_sets_of_a_spec():
    assert gait_ocp.GaitSpec(model="SK", cost="Eq4.11").identified_sets() == ()
    assert gait_ocp.GaitSpec(model="SK", cost="Eq4.11", body_params="ch4").identified_sets() == ("ch4_child",)
    s = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", contact_params="ch4", body_params="ch4", mtg_params="ch5")
    assert s.identified_sets() == ("ch4_child", "ch5_mtg")


def test_keys_hash_exactly_the_identified_sets_a_solution_reads(data_copy):
    spec = {"kind": "test", "x": 1}
    k_none, k_ch4, k_all = (cache.key(spec, F, identified=()), cache.key(spec, F, identified=("ch4_child",)),
                            cache.key(spec, F))
    ident = data_copy / "identified"
    ident.mkdir(exist_ok=True)
    # a set nobody named: changes only the conservative (all-sets) key
    (ident / "other.json").write_text('{"a": 1}')
    assert cache.key(spec, F, identified=()) == k_none
    assert cache.key(spec, F, identified=("ch4_child",)) == k_ch4
    assert cache.key(spec, F) != k_all
    # rewriting a named set changes the keys that read it, at once (no stale memo)
    f = ident / "ch4_child.json"
    old = f.read_bytes() if f.exists() else None
    f.write_text('{"changed": true}')
    assert cache.key(spec, F, identified=("ch4_child",)) != k_ch4
    assert cache.key(spec, F, identified=()) == k_none
    if old is not None:
        f.write_bytes(old)
        assert cache.key(spec, F, identified=("ch4_child",)) == k_ch4
    # a raw data file changes every key
    csv = sorted(data_copy.glob("*.csv"))[0]
    csv.write_bytes(csv.read_bytes() + b"\n")
    assert cache.key(spec, F, identified=()) != k_none


def test_a_missing_named_set_is_part_of_the_key(data_copy):
    spec = {"kind": "test"}
    k = cache.key(spec, F, identified=("nothere",))
    assert k != cache.key(spec, F, identified=())
    (data_copy / "identified" / "nothere.json").write_text("{}")
    assert cache.key(spec, F, identified=("nothere",)) != k


# -- entries: atomic, checksummed, never served corrupt ------------------------------------


def _write(files):
    def write(d):
        for name, text in files.items():
            (d / name).parent.mkdir(parents=True, exist_ok=True)
            (d / name).write_text(text)
    return write


def test_an_entry_is_written_with_a_manifest_and_served(tmp_path, monkeypatch):
    monkeypatch.setenv("GAITLIB_STORE", "")
    where = tmp_path / "gait" / "abc"
    cache.save(where, _write({"spec.json": "{}", "ocp/cycle_states.csv": "t,x\n0,1\n1,2\n"}))
    assert (where / cache.MANIFEST).is_file()
    assert cache.find(where, "spec.json") == where
    assert not [p for p in where.parent.iterdir() if p.name.startswith(".")]  # no temporary left


@pytest.mark.parametrize("damage", ["truncate", "empty", "delete", "add", "no-manifest"])
def test_a_corrupt_entry_is_reported_with_its_path_and_never_served(tmp_path, monkeypatch, damage):
    monkeypatch.setenv("GAITLIB_STORE", "")
    where = tmp_path / "gait" / "abc"
    rows = "".join(f"{i},{i * 0.5}\n" for i in range(25))
    cache.save(where, _write({"spec.json": '{"model": "SK"}', "ocp/cycle_states.csv": "t,x\n" + rows}))
    f = where / "ocp" / "cycle_states.csv"
    if damage == "truncate":  # 19 of 25 rows, as a killed writer leaves it
        f.write_text("t,x\n" + "".join(rows.splitlines(True)[:19]))
    elif damage == "empty":
        (where / "spec.json").write_text("")
    elif damage == "delete":
        f.unlink()
    elif damage == "add":
        (where / "stale.csv").write_text("x\n")
    else:
        (where / cache.MANIFEST).unlink()
    with pytest.warns(cache.CacheWarning, match=str(where)):
        assert cache.find(where, "spec.json") is None
    bad = [p for p, fault in cache.scan(tmp_path) if fault]
    assert bad == [where]
    # re-solving replaces it: the repaired entry verifies again
    cache.save(where, _write({"spec.json": '{"model": "SK"}'}))
    assert cache.find(where, "spec.json") == where and cache.scan(tmp_path) == [(where, None)]


def test_a_corrupt_store_entry_is_not_served_either(tmp_path, monkeypatch):
    store = tmp_path / "store"
    cache.save(store / "gait" / "k1", _write({"spec.json": "{}"}))
    (store / "gait" / "k1" / "spec.json").write_text("[]")  # same size, other bytes
    monkeypatch.setenv("GAITLIB_STORE", str(store))
    with pytest.warns(cache.CacheWarning, match="checksum"):
        assert cache.find(tmp_path / "cache" / "gait" / "k1", "spec.json") is None


def _writer(args):
    root, tag = args
    from gaitlib import cache as c

    big = "".join(f"{tag},{i}\n" for i in range(20000))

    def write(d):
        for k in range(5):
            (d / f"part{k}.csv").write_text(big)
    c.save(root / "gait" / "same", write)
    return tag


def test_two_writers_of_one_key_never_mix(tmp_path, monkeypatch):
    """Two processes write one key at once: the entry that stays is one writer's, complete."""
    import multiprocessing as mp

    monkeypatch.setenv("GAITLIB_STORE", "")
    with mp.get_context("spawn").Pool(2) as pool:
        for _ in range(3):
            pool.map(_writer, [(tmp_path, "A"), (tmp_path, "B")])
            where = tmp_path / "gait" / "same"
            cache.verify(where)
            tags = {line.split(",")[0] for p in where.glob("part*.csv") for line in p.read_text().splitlines()}
            assert len(tags) == 1
    assert [p.name for p in (tmp_path / "gait").iterdir()] == ["same"]


def test_a_writer_that_loses_the_race_keeps_the_other_writers_entry(tmp_path, monkeypatch):
    """The interleaving CI once hit: our first rename fails (an entry is there), the other
    writer moves that entry aside, then puts its own in place just before our second rename.
    The save must neither fail nor mix: the other writer's complete entry stays."""
    import os

    monkeypatch.setenv("GAITLIB_STORE", "")
    where = tmp_path / "gait" / "same"
    cache.save(where, _write({"a.csv": "first"}))
    theirs = cache.save(tmp_path / "other" / "same", _write({"a.csv": "theirs"}))
    real = os.rename
    seen = []

    def racing(src, dst):
        src, dst = Path(src), Path(dst)
        if src.name.startswith(".tmp-") and dst == where:
            seen.append(src)
            if len(seen) == 2:  # the other writer's entry lands just before our retry
                real(theirs, where)
        try:
            return real(src, dst)
        finally:
            if len(seen) == 1 and src.name.startswith(".tmp-") and where.exists():
                real(where, tmp_path / "aside")  # the other writer moves the old entry aside

    monkeypatch.setattr(cache.os, "rename", racing)
    cache.save(where, _write({"a.csv": "ours"}))
    monkeypatch.setattr(cache.os, "rename", real)
    assert len(seen) == 2
    cache.verify(where)
    assert (where / "a.csv").read_text() == "theirs"
    assert [p.name for p in (tmp_path / "gait").iterdir()] == ["same"]


def test_cache_verify_command_lists_and_removes_bad_entries(tmp_path, capsys):
    from gaitlib import cli

    cache.save(tmp_path / "gait" / "good", _write({"spec.json": "{}"}))
    cache.save(tmp_path / "gait" / "bad", _write({"spec.json": "{}"}))
    (tmp_path / "gait" / "bad" / "spec.json").write_text("")
    assert cli.main(["cache", "verify", "--root", str(tmp_path)]) == 1
    assert "corrupt: " + str(tmp_path / "gait" / "bad") in capsys.readouterr().out
    assert cli.main(["cache", "verify", "--root", str(tmp_path), "--remove"]) == 0
    assert sorted(p.name for p in (tmp_path / "gait").iterdir()) == ["good"]


def test_context_curves_are_not_part_of_any_key(data_copy):
    """data/context/ holds curves no solve reads (data.CONTEXT_FILES): adding or editing one
    leaves every key as it was; the same file at the top of data/ changes them."""
    spec = {"kind": "test", "x": 2}
    keys = (cache.key(spec, F, identified=()), cache.key(spec, F))
    ctx = data_copy / data_mod.CONTEXT
    ctx.mkdir(exist_ok=True)
    (ctx / "new_context.csv").write_text("source,speed_class\n")
    for name in data_mod.CONTEXT_FILES:
        f = data_copy / name
        f.write_bytes(f.read_bytes() + b"\n")
    assert (cache.key(spec, F, identified=()), cache.key(spec, F)) == keys
    (data_copy / "new_context.csv").write_text("source,speed_class\n")
    assert cache.key(spec, F, identified=()) != keys[0]
