"""Cache keys: what changes them and what does not (gaitlib.cache)."""

from __future__ import annotations

import shutil

import pytest

from gaitlib import cache
from gaitlib import data as data_mod
from gaitlib import transcription as tr


@pytest.fixture
def data_copy(tmp_path, monkeypatch):
    """A private copy of data/ (so the test may write identified sets into it)."""
    d = tmp_path / "data"
    shutil.copytree(data_mod.DATA_DIR, d)
    monkeypatch.setattr(data_mod, "DATA_DIR", d)
    return d


def test_identified_sets_of_a_spec():
    assert tr.GaitSpec(model="SK", cost="Eq4.11").identified_sets() == ()
    assert tr.GaitSpec(model="SK", cost="Eq4.11", body_params="ch4").identified_sets() == ("ch4_child",)
    s = tr.GaitSpec(model="MSK", cost="Eq5.33", contact_params="ch4", body_params="ch4", mtg_params="ch5")
    assert s.identified_sets() == ("ch4_child", "ch5_mtg")


def test_keys_hash_exactly_the_identified_sets_a_solution_reads(data_copy):
    spec = {"kind": "test", "x": 1}
    k_none, k_ch4, k_all = (cache.key(spec, identified=()), cache.key(spec, identified=("ch4_child",)),
                            cache.key(spec))
    ident = data_copy / "identified"
    ident.mkdir(exist_ok=True)
    # a set nobody named: changes only the conservative (all-sets) key
    (ident / "other.json").write_text('{"a": 1}')
    assert cache.key(spec, identified=()) == k_none
    assert cache.key(spec, identified=("ch4_child",)) == k_ch4
    assert cache.key(spec) != k_all
    # rewriting a named set changes the keys that read it, at once (no stale memo)
    f = ident / "ch4_child.json"
    old = f.read_bytes() if f.exists() else None
    f.write_text('{"changed": true}')
    assert cache.key(spec, identified=("ch4_child",)) != k_ch4
    assert cache.key(spec, identified=()) == k_none
    if old is not None:
        f.write_bytes(old)
        assert cache.key(spec, identified=("ch4_child",)) == k_ch4
    # a raw data file changes every key
    csv = sorted(data_copy.glob("*.csv"))[0]
    csv.write_bytes(csv.read_bytes() + b"\n")
    assert cache.key(spec, identified=()) != k_none


def test_a_missing_named_set_is_part_of_the_key(data_copy):
    spec = {"kind": "test"}
    k = cache.key(spec, identified=("nothere",))
    assert k != cache.key(spec, identified=())
    (data_copy / "identified" / "nothere.json").write_text("{}")
    assert cache.key(spec, identified=("nothere",)) != k
