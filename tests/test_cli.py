"""The command line's contract: exit status, one-line errors, options checked before any
solve, outputs staged and moved into place (gaitlib.cli, gaitlib.cli.gap)."""

from __future__ import annotations

import json
from types import SimpleNamespace

import pandas as pd
import pytest

from gaitlib.problems import gait as gait_ocp
from gaitlib import __version__, cli
from gaitlib import data as data_mod
from gaitlib import sweep as sw
from gaitlib.gap import diagnose as D
from gaitlib import effects as effects_mod
from gaitlib.gap import io as gio

FAILED = "Maximum_Iterations_Exceeded"


class Fake:
    """A solution as the code under test reads it: only ``stats``."""

    def __init__(self, status: str, objective: float = 1.0):
        self.stats = {"status": status, "objective": objective, "iterations": 3}


def _no_solve(*a, **k):
    raise AssertionError("a solve was started")


@pytest.fixture
def no_solve(monkeypatch):
    """Any solve (gait study, sweep, diagnosis, twin) fails the test."""
    from gaitlib.gap import twin

    for mod, name in ((gait_ocp, "solve_cached"), (gait_ocp, "solve_specs"), (D, "diagnose"), (twin, "make_twin")):
        monkeypatch.setattr(mod, name, _no_solve)


def _run(argv, capsys):
    """``gaitlib argv`` in this process: (exit status, stdout, stderr)."""
    try:
        rc = cli.main(argv)
    except SystemExit as e:  # argparse
        rc = e.code
    out, err = capsys.readouterr()
    return rc, out, err


def _free_csv(path):
    """The committed Schwartz 2008 Free data as a tidy CSV of their own."""
    df = pd.read_csv(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    df[df.speed_class == "Free"].to_csv(path, index=False)


def _one_line(err: str, cmd: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"gaitlib {cmd}: "), err
    return lines[0]


# -------------------------------------------------------------------------- parse time

@pytest.mark.parametrize("argv", [
    ["gap", "--data", "x.csv", "--out", "o", "--resamples", "-5"],
    ["gap", "--data", "x.csv", "--out", "o", "--workers", "0"],
    ["gap", "--data", "x.csv", "--out", "o", "--seed", "-1"],
    ["gap", "--data", "x.csv", "--out", "o", "--intervals", "0"],
    ["gap-twin", "--effect", "friction", "--magnitude", "nan", "--out", "t.csv"],
    ["run", "gait", "--out", "o", "--degree", "0"],
    ["run", "gait", "--out", "o", "--max-iter", "-1"],
    ["run", "gait", "--out", "o", "--intervals", "2.5"],
    ["run", "jump", "--out", "o"],
    ["sweep", "--costs", "DT", "--out", "o", "--workers", "-2"],
])
def test_bad_options_are_rejected_at_parse_time(argv, capsys, no_solve, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, _, err = _run(argv, capsys)
    assert rc == 2
    _one_line(err, argv[0])
    assert not any(tmp_path.iterdir())  # nothing written, not even a temporary folder


@pytest.mark.parametrize("argv, words", [
    (["run", "gait", "--out", "o", "--speed", "Medium"], ["unknown speed class 'Medium'", "VeryFast"]),
    (["sweep", "--costs", "DT,XX", "--out", "o"], ["unknown cost 'XX'"]),
    (["sweep", "--costs", ",", "--out", "o"], ["--costs and --speeds"]),
    (["gap", "--data", "missing.csv", "--out", "o", "--effects", "friction,nope"],
     ["unknown effect(s) nope", "known: " + ", ".join(effects_mod.EFFECTS)]),
    (["gap-twin", "--effect", "body_mass", "--out", "t.csv"], ["needs --magnitude", "[-0.3, 0.3]"]),
    (["gap-twin", "--effect", "body_mass", "--magnitude", "5", "--out", "t.csv"], ["outside [-0.3, 0.3]"]),
    (["gap-twin", "--effect", "nope", "--magnitude", "0.1", "--out", "t.csv"], ["unknown effect 'nope'"]),
    (["gap-twin", "--effect", "none", "--magnitude", "0.1", "--out", "t.csv"], ["--magnitude given without"]),
    (["gap-twin", "--effect", "friction", "--magnitude", "-0.1", "--effect2", "hat_com", "--out", "t.csv"],
     ["--effect2 hat_com needs --magnitude2"]),
    (["gap-twin", "--effect", "co_contraction", "--magnitude", "0.1", "--out", "t.csv"],
     ["applies to models", "'SK'"]),
])
def test_bad_input_is_one_line_before_any_solve(argv, words, capsys, no_solve, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, _, err = _run(argv, capsys)
    line = _one_line(err, argv[0])
    assert rc == 2 and "Traceback" not in err and "--debug" not in line
    for w in words:
        assert w in line
    assert not any(tmp_path.iterdir())


def test_debug_shows_the_traceback(capsys, no_solve):
    with pytest.raises(ValueError, match="unknown speed class"):
        cli.main(["--debug", "run", "gait", "--out", "o", "--speed", "Medium"])
    with pytest.raises(ValueError, match="unknown speed class"):
        cli.main(["run", "gait", "--out", "o", "--speed", "Medium", "--debug"])


def test_unexpected_errors_are_one_line_too(capsys, monkeypatch, tmp_path):

    def boom(*a, **k):
        raise ZeroDivisionError("deep inside")

    monkeypatch.setattr(gait_ocp, "solve_cached", boom)
    rc, _, err = _run(["run", "gait", "--out", str(tmp_path / "o"), "--cache", str(tmp_path / "c")], capsys)
    line = _one_line(err, "run")
    assert rc == 2 and "ZeroDivisionError: deep inside" in line and "--debug" in line
    assert not (tmp_path / "o").exists() and [p.name for p in tmp_path.iterdir()] == ["c"]


def test_version(capsys):
    rc, out, _ = _run(["--version"], capsys)
    assert rc == 0 and out.strip() == f"gaitlib {__version__}"


# -------------------------------------------------------------------------- statuses

def test_pick_best_never_keeps_a_failed_solve():
    a, b, c = Fake("Solve_Succeeded", 2.0), Fake(FAILED, 0.5), Fake("Solved_To_Acceptable_Level", 1.5)
    assert D.pick_best([a, b, None, c]) is c  # the converged one with the lowest objective
    assert D.pick_best([b, Fake("Invalid_Number_Detected", 0.1), None]) is None
    assert D.pick_best([]) is None
    # candidates: a fit none of whose starts converged is still reported (ok=False)
    assert D.lowest_objective([b, a, None]) is b and D.lowest_objective([None]) is None


def test_diagnose_refuses_a_baseline_none_of_whose_starts_converged(monkeypatch):
    """Every start returns a solution that did not converge: diagnose raises BaselineFailed
    naming each start's status, before any candidate is solved."""
    calls = []

    def fake_solve_many(groups, **kw):
        calls.append(sorted(groups))
        status = {"cold": "Invalid_Number_Detected", "dt1": "Solve_Succeeded", "grf1": FAILED}
        return {key: Fake(status.get(key.split("|")[1], FAILED)) for _, (_, jobs) in groups.items()
                for key, _, _ in jobs}

    monkeypatch.setattr(D, "solve_many", fake_solve_many)
    with pytest.raises(D.BaselineFailed) as e:
        D.diagnose(gio.load_real(), base=dict(model="SK", cost="DT", n_intervals=4, degree=3), serial=True)
    assert e.value.statuses == {"cold": "Invalid_Number_Detected", "dt": FAILED, "grf": FAILED}
    assert str(e.value) == f"baseline failed: cold Invalid_Number_Detected, dt {FAILED}, grf {FAILED}"
    assert all(g.startswith("baseline-") for c in calls for g in c)  # no candidate was solved


def test_gap_cli_says_baseline_failed_and_writes_nothing(capsys, monkeypatch, tmp_path):
    def failed(*a, **k):
        raise D.BaselineFailed({"cold": "Invalid_Number_Detected", "dt": FAILED})

    monkeypatch.setattr(D, "diagnose", failed)
    csv = tmp_path / "d.csv"
    _free_csv(csv)
    out = tmp_path / "out"
    rc, _, err = _run(["gap", "--data", str(csv), "--out", str(out), "--cache", str(tmp_path / "c")], capsys)
    assert rc == 2
    assert _one_line(err, "gap") == f"gaitlib gap: baseline failed: cold Invalid_Number_Detected, dt {FAILED}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c", "d.csv"]  # no out, no temporary folder


def _fake_diagnosis(statuses: dict):
    """A Diagnosis-like object with candidates of the given statuses."""
    fits = {n: SimpleNamespace(effect=n, status=s, ok=s != FAILED) for n, s in statuses.items()}
    ranking = pd.DataFrame({"rank": range(1, len(fits) + 1), "effect": list(fits), "n_params": 1,
                            "start": "baseline", "nests_baseline": True, "status": list(statuses.values()), "pct_closed": 10.0, "dAIC": -1.0, "dBIC": -1.0,
                            "residual_ratio": 0.04})

    def save(out, figures=True):
        (out / "diagnosis.json").write_text(json.dumps({"verdict": "unexplained"}))
        (out / "ranking.csv").write_text("effect\n")

    return SimpleNamespace(fits=fits, ranking=ranking, top_effect="unexplained", verdict="unexplained",
                           located=SimpleNamespace(rss=100.0, n_eff=20.0), baseline=Fake("Solve_Succeeded"),
                           save=save)


@pytest.mark.parametrize("statuses, rc_expected", [
    ({"friction": "Solve_Succeeded", "hat_com": "Solve_Succeeded (comparison only)"}, 0),
    ({"friction": "Solve_Succeeded", "hat_com": FAILED}, 2),
])
def test_gap_exit_status_follows_the_candidates(statuses, rc_expected, capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(D, "diagnose", lambda *a, **k: _fake_diagnosis(statuses))
    monkeypatch.setattr(gio, "read_data", lambda *a, **k: gio.load_real())
    out = tmp_path / "out"
    rc, stdout, err = _run(["gap", "--data", "x.csv", "--out", str(out), "--cache", str(tmp_path / "c")], capsys)
    assert rc == rc_expected and (out / "diagnosis.json").is_file()
    assert '"baseline_status": "Solve_Succeeded"' in stdout
    if rc_expected:
        assert f"hat_com {FAILED}" in _one_line(err, "gap")


def test_gap_twin_refuses_a_failed_generating_solve(capsys, monkeypatch, tmp_path):
    from gaitlib.gap import twin

    frame = pd.DataFrame({"x": [1.0]})
    status = {"s": FAILED}
    monkeypatch.setattr(twin, "make_twin", lambda effects, seed, **kw: (frame, {
        "status": status["s"], "iterations": 1000, "effects": [list(e) for e in effects]}))
    out = tmp_path / "tw" / "twin.csv"
    argv = ["gap-twin", "--effect", "friction", "--magnitude", "-0.2", "--out", str(out),
            "--cache", str(tmp_path / "c")]
    rc, _, err = _run(argv, capsys)
    assert rc == 2 and "did not converge (Maximum_Iterations_Exceeded, 1000 iterations)" in _one_line(err, "gap-twin")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c"]  # no twin, no temporary folder
    status["s"] = "Solve_Succeeded"
    rc, _, _ = _run(argv, capsys)
    truth = json.loads(out.with_suffix(".truth.json").read_text())
    assert rc == 0 and out.is_file() and truth["effects"] == [["friction", -0.2]]
    # an existing twin is kept unless --overwrite; other files beside it are never touched
    (out.parent / "mine.txt").write_text("keep")
    rc, _, err = _run(argv, capsys)
    assert rc == 2 and "twin.csv exists" in _one_line(err, "gap-twin") and "--overwrite" in err
    rc, _, _ = _run(argv + ["--overwrite"], capsys)
    assert rc == 0 and sorted(p.name for p in out.parent.iterdir()) == ["mine.txt", "twin.csv", "twin.truth.json"]


def test_write_twin_raises_on_a_failed_solve(monkeypatch, tmp_path):
    from gaitlib.gap import twin
    from gaitlib.ocp import SolveFailedError

    monkeypatch.setattr(twin, "make_twin", lambda *a, **k: (pd.DataFrame(), {"status": FAILED, "iterations": 9}))
    with pytest.raises(SolveFailedError, match="did not converge"):
        twin.write_twin(tmp_path / "t.csv", (("friction", -0.1),))
    assert not any(tmp_path.iterdir())


def test_a_twin_without_a_converged_baseline_counts_as_a_miss():
    from gaitlib.gap.twin import TwinValidation

    truth = {"friction@1#1": {"effects": (("friction", -0.3),), "seed": 1, "level": 1}}
    tv = TwinValidation.build({}, truth, {"friction": (-0.15, -0.3, -0.45)}, {}, settings={
        "effects": ["friction"], "baseline_failed": {"friction@1#1": {"cold": FAILED}}})
    assert tv.rows[["twin", "top", "correct"]].values.tolist() == [["friction@1#1", "baseline failed", False]]
    acc = tv.accuracy()
    assert acc.loc["middle", "twins"] == 1 and acc.loc["middle", "top-1 accuracy (%)"] == 0.0
    assert tv.confusion.loc["friction", "baseline failed"] == 1


def group(arg):
    """A sweep item returning a group of solutions (as gaitlib.gap.solve.solve_many's)."""
    return {f"k{i}": Fake(s) for i, s in enumerate(arg)}


def test_progress_shows_ipopt_statuses_of_a_group(capsys):
    recs = sw.sweep(group, {"mixed": ["Solve_Succeeded", FAILED, "Solve_Succeeded"],
                            "same": ["Solve_Succeeded", "Solved_To_Acceptable_Level"],
                            "fine": ["Solve_Succeeded"] * 2}, serial=True)
    by = {r.name: r for r in recs}
    assert (by["mixed"].ok, by["mixed"].status) == (False, f"2 Solve_Succeeded, 1 {FAILED}")
    assert (by["same"].ok, by["same"].status) == (True, "1 Solve_Succeeded, 1 Solved_To_Acceptable_Level")
    assert (by["fine"].ok, by["fine"].status) == (True, "Solve_Succeeded")
    err = capsys.readouterr().err
    line = next(ln for ln in err.splitlines() if " mixed " in ln)
    assert f"2 Solve_Succeeded, 1 {FAILED}" in line and line.endswith("FAILED")
    assert "sweep: 2/3 ok, 1 failed" in err
    # values that are not solutions stay "done"
    assert sw._status_of({"a": 1}) == (True, "done") and sw._status_of({}) == (True, "done")


# -------------------------------------------------------------------------- outputs

def test_output_checks_come_before_the_solve(capsys, no_solve, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("x")
    rc, _, err = _run(["run", "gait", "--out", "afile/o", "--cache", "c"], capsys)
    assert rc == 2 and "--out afile/o: cannot write in" in _one_line(err, "run")
    rc, _, err = _run(["run", "gait", "--out", "o", "--cache", "afile/c"], capsys)
    assert rc == 2 and "the solutions cache afile/c is not writable" in _one_line(err, "run")
    rc, _, err = _run(["sweep", "--costs", "DT", "--out", "afile", "--cache", "c"], capsys)
    assert rc == 2 and "exists and is not a folder" in _one_line(err, "sweep")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x.txt").write_text("x")
    rc, _, err = _run(["gap", "--data", "d.csv", "--out", "full", "--cache", "c"], capsys)
    # (the data are read first: a missing CSV is reported before the folder)
    assert rc == 2 and "d.csv" in _one_line(err, "gap")
    _free_csv(tmp_path / "d.csv")
    rc, _, err = _run(["gap", "--data", "d.csv", "--out", "full", "--cache", "c"], capsys)
    assert rc == 2 and "--out full exists and is not empty: pass --overwrite" in _one_line(err, "gap")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "c", "d.csv", "full"]


def test_a_crash_while_writing_leaves_the_old_output(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"files": ["a.csv", "summary.json"]}')
    (out / "a.csv").write_text("old")
    with pytest.raises(RuntimeError, match="disk full"):
        with cli.Output(out, overwrite=True, owned={"a.csv", "summary.json"}, last=("summary.json",)) as o:
            (o.tmp / "summary.json").write_text('{"files": ["b.csv"]}')
            raise RuntimeError("disk full")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # the temporary folder is gone
    assert (out / "a.csv").read_text() == "old" and "a.csv" in (out / "summary.json").read_text()
    # a fresh folder: one rename, nothing half-written on the way
    new = tmp_path / "new"
    with cli.Output(new) as o:
        (o.tmp / "summary.json").write_text("{}")
        assert not new.exists()
    assert [p.name for p in new.iterdir()] == ["summary.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new", "out"]


def test_run_exits_2_on_a_failed_solve_and_overwrites_only_its_files(capsys, tmp_path, monkeypatch):
    """A real 4 × 3 solve stopped at 3 iterations: outputs written with the status, exit 2;
    the same --out again is refused; --overwrite replaces the run's files (those the old
    summary.json listed too), keeps foreign ones, and the new summary lists only the new."""
    monkeypatch.chdir(tmp_path)
    argv = ["run", "gait", "--model", "SK", "--cost", "DT", "--intervals", "4", "--degree", "3", "--max-iter", "3",
            "--no-figures", "--quiet", "--cache", "c", "--out", "o"]
    rc, out, err = _run(argv, capsys)
    assert rc == 2 and f"did not converge ({FAILED}, 3 iterations)" in _one_line(err, "run")
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["stats"]["status"] == FAILED and f'"status": "{FAILED}"' in out
    assert set(summary["files"]) == {p.name for p in (tmp_path / "o").iterdir()}
    rc, _, err = _run(argv, capsys)
    assert rc == 2 and "exists and is not empty: pass --overwrite" in _one_line(err, "run")
    (tmp_path / "o" / "notes.txt").write_text("mine")
    (tmp_path / "o" / "stale.csv").write_text("old")
    summary["files"].append("stale.csv")
    (tmp_path / "o" / "summary.json").write_text(json.dumps(summary))
    rc, _, _ = _run(argv + ["--overwrite"], capsys)  # from the cache this time
    files = {p.name for p in (tmp_path / "o").iterdir()}
    new = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert rc == 2 and new["stats"]["from_cache"] and "notes.txt" in files and "stale.csv" not in files
    assert set(new["files"]) == files - {"notes.txt"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c", "o"]


def test_sweep_exit_status_and_owned_run_folders(capsys, tmp_path, monkeypatch):
    """sweep: exit 2 with a failed run; --overwrite replaces sweep.csv and the run folders
    the old and new sweep.csv list, keeps the rest."""
    monkeypatch.chdir(tmp_path)
    solved = {}

    def fake_solve_specs(specs, **kw):
        solved.update(specs)
        return {n: sw.RunRecord(n, False, "error", None, "Traceback\nValueError: boom", 0.1, "serial")
                if n.endswith("Slow") else sw.RunRecord(n, True, "done", None, None, 0.1, "serial") for n in specs}

    monkeypatch.setattr(gait_ocp, "solve_specs", fake_solve_specs)
    base = ["sweep", "--model", "SK", "--costs", "DT", "--intervals", "4", "--degree", "3", "--cache", "c",
            "--out", "o"]
    rc, _, err = _run(base + ["--speeds", "Slow,Free"], capsys)
    assert rc == 2 and "1 of 2 runs did not converge: SK_DT_Slow error" in _one_line(err, "sweep")
    assert pd.read_csv(tmp_path / "o" / "sweep.csv")["name"].tolist() == ["SK_DT_Slow", "SK_DT_Free"]
    assert (tmp_path / "o" / "SK_DT_Slow" / "error.txt").is_file()
    (tmp_path / "o" / "mine").mkdir()
    rc, _, err = _run(base + ["--speeds", "Free"], capsys)
    assert rc == 2 and "--overwrite" in err
    rc, _, _ = _run(base + ["--speeds", "Free", "--overwrite"], capsys)
    assert rc == 0 and sorted(p.name for p in (tmp_path / "o").iterdir()) == ["mine", "sweep.csv"]
    assert solved["SK_DT_Free"].n_intervals == 4


def test_gap_validate_checks_its_sets_before_any_solve(capsys, monkeypatch, tmp_path):
    from gaitlib.gap import validate as V

    monkeypatch.setattr(V, "run", lambda *a, **k: pytest.fail("solved despite a bad option"))
    rc, _, err = _run(["gap-validate", "--set", "independent,nope", "--out", str(tmp_path / "v"),
                       "--cache", str(tmp_path / "c")], capsys)
    assert rc == 2 and "unknown set(s) nope" in _one_line(err, "gap-validate")
    assert not (tmp_path / "v").exists()


@pytest.mark.parametrize("flag,want", [([], None), (["--defects", "differential"], None),
                                       (["--defects", "integral"], "integral")])
def test_run_gait_defects_reach_the_spec_and_keep_the_default_key(flag, want, capsys, monkeypatch, tmp_path):
    seen = []

    def spy(spec, *a, **k):
        seen.append(spec)
        raise ZeroDivisionError("stop here")

    monkeypatch.setattr(gait_ocp, "solve_cached", spy)
    _run(["run", "gait", "--out", str(tmp_path / "o"), "--cache", str(tmp_path / "c"), *flag], capsys)
    (spec,) = seen
    assert spec.defects == want
    if want is None:  # the default form is the unset option: the stored solutions' keys
        assert "defects" not in spec.to_dict()


def test_gap_reference_of_another_speed_class_is_refused_before_any_solve(capsys, monkeypatch, tmp_path):
    """``gaitlib gap --reference``: a reference without the data's speed class is one line
    naming the reference and the class, exit 2, nothing solved or written (another time grid:
    :func:`gaitlib.gap.reference.check_same_grid`, tests/test_gap_reference.py); a matching
    one reaches the diagnosis."""
    from gaitlib.gap import validate as V

    frame = V.real_frame("Free")
    free, slow = tmp_path / "free.csv", tmp_path / "slow.csv"
    frame.to_csv(free, index=False)
    V.real_frame("Slow").to_csv(slow, index=False)
    seen = []
    monkeypatch.setattr(D, "diagnose", lambda ds, **k: seen.append(k["reference"]) or _fake_diagnosis({}))
    out = tmp_path / "out"
    rc, _, err = _run(["gap", "--data", str(free), "--reference", str(slow), "--out", str(out),
                       "--cache", str(tmp_path / "c")], capsys)
    line = _one_line(err, "gap")
    assert rc == 2 and "slow.csv" in line and "'Free'" in line
    assert not seen and not out.exists()
    rc, _, _ = _run(["gap", "--data", str(free), "--reference", str(free), "--out", str(out),
                     "--cache", str(tmp_path / "c")], capsys)
    assert rc == 0 and len(seen) == 1 and seen[0].label == "free.csv"


def test_gap_validate_relative_has_no_model_variant_set(capsys, monkeypatch, tmp_path):
    from gaitlib.gap import validate as V

    monkeypatch.setattr(V, "run", lambda *a, **k: pytest.fail("solved despite a bad option"))
    rc, _, err = _run(["gap-validate", "--relative", "--set", "model-variant", "--out", str(tmp_path / "v"),
                       "--cache", str(tmp_path / "c")], capsys)
    assert rc == 2 and "unknown set(s) model-variant" in _one_line(err, "gap-validate") and "--relative" in err

