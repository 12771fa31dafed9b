"""benchmarks/gap_paired.py: every experiment's method is the stored validation's, with only
its named fields changed, and hashes as the stored one (so its draws are the stored draws)."""

from __future__ import annotations

import pytest

import gap_paired as gp


@pytest.mark.parametrize("name", sorted(gp.EXPERIMENTS))
def test_each_experiment_rebuilds_the_stored_method_with_its_changes(name):
    validation, changes = gp.EXPERIMENTS[name]
    val = gp.stored(validation)
    m = gp.stored_method(val, changes)
    assert m.hash() == val.settings["relative_method_hash"]
    stored = val.settings["relative_method"]
    for field in type(m).__dataclass_fields__:
        want = changes[field] if field in changes else stored[field]
        assert getattr(m, field) == want, field
    assert m.min_share_closed == 0.0 and not m.centred  # added by revisions 9 and 10: off then


def test_a_field_the_stored_method_lacks_must_be_set():
    val = gp.stored("relative_rev7")
    with pytest.raises(ValueError, match="centred"):
        gp.stored_method(val, {"min_share_closed": 0.0})
