"""The replication report card: the verdict rule on hand-made cases, the card's shape from the
stored solutions, and that ``ours`` is read from the solutions (never typed)."""

import math
import shutil

import numpy as np
import pandas as pd
import pytest

from gaitlib.problems import gait as gait_ocp
from gaitlib import cache
from gaitlib.cli import main
from gaitlib.studies import card
from gaitlib.studies import msk
from gaitlib import mtg
from gaitlib.studies import mtg_id


# --------------------------------------------------------------------------------------
# The verdict rule
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("thesis, ours, unit, sd, expected", [
    (10.0, 10.9, "1", None, "reproduced"),          # 9 % off
    (100.0, 111.0, "1", None, "not reproduced"),    # 11 % off, no absolute tolerance for "1"
    (0.6, 1.5, "deg", None, "reproduced"),          # 0.9° ≤ 1° resolution although 150 % off
    (0.6, 3.0, "deg", 4.0, "within data SD"),       # 2.4° > 1°, ≤ SD 4°
    (0.6, 3.0, "deg", 2.0, "not reproduced"),       # 2.4° > SD 2°
    (26.49, 65.3, "N", 40.0, "within data SD"),
    (1.53, 5.12, "J/kg/m", None, "not reproduced"),
    (-150.0, -149.99, "deg", None, "reproduced"),   # sign kept: |d| = 0.01
    (0.0, 0.9, "N", None, "reproduced"),            # a zero thesis value: the unit's resolution
    (0.0, 2.1, "N", None, "not reproduced"),
])
def test_verdict_numbers(thesis, ours, unit, sd, expected):
    assert card.verdict(thesis, ours, unit=unit, sd=sd) == expected


def test_verdict_missing_and_claims():
    assert card.verdict(1.53, float("nan")) == "not comparable"
    assert card.verdict(1.53, None) == "not comparable"
    assert card.verdict(None, 1.0) == "not comparable"
    assert card.verdict("a < b", "b < a") == "not comparable"  # text without an evaluated claim
    assert card.verdict("a < b", "a 1 < b 2", holds=True) == "qualitatively reproduced"
    assert card.verdict("a < b", "b 1 < a 2", holds=False) == "not reproduced"


def test_invalid_never_reproduced():
    """A solution that failed a gate or did not converge gives "invalid", even for an exact number
    or a claim that holds; the number-alone verdict stays in the cause."""
    for valid in ("invalid: swing load 55 N > 8.12 N (2 % BW)", "not converged (Maximum_Iterations_Exceeded)",
                  "not converged (Maximum_Iterations_Exceeded); invalid: double support 90% > 40%"):
        assert card.verdict(1.53, 1.53, unit="J/kg/m", valid=valid) == "invalid"
        assert card.verdict("U", "U", holds=True, valid=valid) == "invalid"
    rec = card.Row(5, "x", 1.53, 1.53, "J/kg/m", valid="invalid: swing load 55 N > 8.12 N").record()
    assert rec["verdict"] == "invalid" and "the number alone: reproduced" in rec["cause"]
    assert card.verdict(1.53, 1.53, valid="valid") == "reproduced"
    assert card.verdict(1.53, 1.53, valid="not gated (converged)") == "reproduced"


def test_joint_validity():
    assert card._joint({"a": "valid", "b": "valid"}) == "valid"
    j = card._joint({"a": "valid", "b": "not converged (Maximum_Iterations_Exceeded); invalid: swing load 9 N > 8 N"})
    assert j.startswith("invalid") and "b (not converged, swing load)" in j
    assert card._joint({"a": "not converged (X)"}).startswith("not converged")
    assert card._joint({"a": ""}).startswith("not converged")  # a missing solution blocks too


# --------------------------------------------------------------------------------------
# The card from the stored solutions (one CLI run)
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cli_card(tmp_path_factory):
    out = tmp_path_factory.mktemp("card")
    assert main(["card", "--out", str(out)]) == 0
    return pd.read_csv(out / "card.csv")


def test_cli_writes_card(cli_card):
    c = cli_card
    assert tuple(c.columns) == card.COLUMNS
    assert len(c) >= 40
    assert set(c["verdict"]) <= set(card.VERDICTS)
    assert set(c["chapter"]) == {3, 4, 5, 6, 7}
    assert c["thesis"].notna().all() and c["item"].is_unique
    # a blocked solution never yields "reproduced"
    blocked = c["valid"].fillna("").str.contains("invalid|not converged")
    assert not (blocked & c["verdict"].isin(["reproduced", "within data SD", "qualitatively reproduced"])).any()
    # the thesis-bounds jumps say why they are not a human jump
    jumps = c[(c["chapter"] == 3) & c["item"].str.contains("jump height \\(")]
    thesis_bounds = jumps[~jumps["item"].str.contains("strength")]
    assert len(thesis_bounds) == 3 and thesis_bounds["cause"].str.contains("human standing jumps").all()
    # the strength-limited jumps (where stored) are rows of their own, against the same human range
    strong = jumps[jumps["item"].str.contains("strength")]
    assert strong["cause"].str.contains("MTG strength envelope").all()
    assert strong["cause"].str.contains("human standing jumps").all()
    assert (card.counts(c).sum() == len(c))
    # a reproduced row (of any kind) needs no cause, so none says "unknown"
    ok = c["verdict"].isin(["reproduced", "within data SD", "qualitatively reproduced"])
    assert not c.loc[ok, "cause"].fillna("").str.startswith("unknown").any()
    # every Ch 5 tracking row carries its channel's located gap (Ch 8's first step); other rows none
    track = c["item"].str.contains(r"^N?MSK RMSE ")
    assert c.loc[track, "gap"].str.match(r"RMS z \d+\.\d\d").all()
    assert c.loc[~track, "gap"].isna().all()


def test_ch6_excitation_claims_checked_from_the_thesis_guess(cli_card):
    """A not-reproduced excitation claim of Ch 6 says what the runs from the thesis's partial
    guess (a second start) decide, with their ranking, rather than "unknown"."""
    c = cli_card
    exc = c[(c["chapter"] == 6) & c["item"].str.contains("predicts the (?:most|least) accurate excitations")
            & (c["verdict"] == "not reproduced")]
    if exc.empty:
        pytest.skip("no such row is decided on the stored runs")
    assert exc["cause"].str.match(r"(not the start|the start decides it): from the thesis's partial guess "
                                  r"\(Sec 6\.1; \d valid NMSK runs\)").all()
    assert exc["cause"].str.contains(r"rank \d of \d").all()


def test_card_reads_the_stored_numbers(tmp_path, monkeypatch):
    """Change a stored number in a copy of the Ch 5 MSK entry (the book's reading, which the
    card's Ch 5 rows report): the card's row follows it."""
    where = gait_ocp.cache_dir(msk.ch5_spec("MSK", reading="book"))
    found = cache.find(where, "spec.json")
    if found is None:
        pytest.skip("the Ch 5 MSK solution is not stored")
    store = tmp_path / "store"
    entry = store / found.parent.name / found.name
    shutil.copytree(found, entry)
    rm = pd.read_csv(entry / "rmse.csv")
    i = rm.index[(rm["kind"] == "angle") & (rm["channel"] == "hip_r")][0]
    rm.loc[i, "rmse"] = 0.65  # thesis Table 5.4: 0.6°
    rm.to_csv(entry / "rmse.csv", index=False)
    if hasattr(cache, "write_manifest"):  # stores that verify their entries
        cache.write_manifest(entry)
    monkeypatch.setenv("GAITLIB_STORE", str(store))
    monkeypatch.setenv("GAITLIB_SOLUTIONS", str(tmp_path / "empty"))
    c = card.build(chapters=(5,))
    row = c[c["item"] == "MSK RMSE angle hip R (Table 5.4)"].iloc[0]
    assert math.isclose(row["ours"], 0.65)
    assert row["solution"].startswith(f"{found.parent.name}/{found.name}")
    # the NMSK solution is not in this store: its rows are not comparable, never typed in
    nm = c[c["item"].str.startswith("NMSK RMSE")]
    assert len(nm) == 16 and nm["ours"].isna().all() and (nm["verdict"] == "not comparable").all()
    assert np.isfinite(row["thesis"])


def test_card_never_solves(tmp_path, monkeypatch):
    """Without stored solutions the rows are "not comparable" and nothing is solved or written."""
    monkeypatch.setenv("GAITLIB_STORE", "")
    monkeypatch.setenv("GAITLIB_SOLUTIONS", str(tmp_path / "cache"))
    c = card.build(chapters=(3, 4))
    assert len(c) >= 30 and (c["verdict"] == "not comparable").all()
    assert (c["cause"] == "no stored solution").all()
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").rglob("*.json"))


def test_mtg_causes_say_where_eq_5_15_binds_on_our_data():
    causes = card._mtg_causes({g: mtg.MTGParams() for g in mtg.GENERATORS})
    margins = mtg_id.margins_table({"x": None}, mtg_id.demanded_torques(mtg_id.chapter_spec())).xs(
        "Eq 5.15", axis=1, level=1)["x"]
    for g, m in margins.items():
        assert causes[g].startswith("Eq 5.15 inactive" if m > 0 else "Eq 5.15 binds"), g
        assert f"{abs(m):.1f} N·m" in causes[g] and "#which-constraints-bind" in causes[g]
    assert any(m < 0 for m in margins) and any(m > 0 for m in margins)  # both kinds occur on our data


def test_time_split_is_iterations_times_time_per_iteration():
    """150 s in 50 iterations against 100 s in 100: ×0.5 the iterations at ×3 the time each
    (0.5 × 3 = 1.5, the time ratio)."""
    from gaitlib.studies import card as card_mod

    a = {"iterations": 100, "solve_time_s": 90.0, "build_time_s": 10.0}
    b = {"iterations": 50, "solve_time_s": 140.0, "build_time_s": 10.0}
    assert card_mod._time_split(a, b, "NMSK FP", "MSK FP") == (
        "NMSK FP 150 s in 50 iterations, MSK FP 100 s in 100: iterations ×0.50, time per iteration ×3.00")


def test_time_ratio_row_sums_the_runs_and_splits_the_ratio():
    """Two MSK runs (100 s / 100 it, 200 s / 100 it) against two NMSK runs (150 s / 50 it each):
    ratio 300 / 300 = 1, split ×2 the iterations (200 / 100) at ×0.5 the time each (1.5 / 3)."""
    from types import SimpleNamespace

    def run(t, it):
        return SimpleNamespace(stats={"iterations": it, "solve_time_s": t - 1.0, "build_time_s": 1.0})

    runs = {"MSK a": run(100, 100), "MSK b": run(200, 100), "NMSK a": run(150, 50), "NMSK b": run(150, 50)}
    th = {"MSK": {"a": 2.0, "b": 4.0}, "NMSK": {"a": 1.0, "b": 1.0}}
    row = card._time_ratio_row(6, "x", th, runs, ("a", "b"), "s", {k: "valid" for k in runs})
    assert row.thesis == 3.0 and row.ours == pytest.approx(1.0)
    assert row.cause == ("MSK 300 s in 200 iterations, NMSK 300 s in 100: iterations ×2.00, time per iteration "
                         "×0.50 (sums over the runs)")


def test_slip_lines_by_hand():
    t = pd.DataFrame({"slip (m/s)": [0.05, 0.2, 0.9], "rows": [2, 3, 4], "rows counted as reproduced": [1, 2, 1],
                      "reference's slip (m/s)": [0.23, 0.23, 0.47]})
    (line,) = card.slip_lines(t)
    # two solutions above v_tr = 0.1 m/s, backing 3 + 4 rows, 2 + 1 of them counted as agreeing
    assert "Of the 3 stored gait solutions behind the card's rows, 2 carry their load" in line
    assert "slip 0.05–0.90 m/s" in line and "They back 7 rows, 3 of them" in line
    # references 0.23–0.47; faster than their reference: 0.9 > 0.47 only
    assert "already slide 0.23–0.47 m/s; 1 of the 3 solutions slide faster than their reference." in line
    assert card.slip_lines(t.iloc[:0]) == []
