"""A failed result never looks like a result: the figures and tables that show a solve
carry a visible mark when it did not converge (or is declared invalid)."""

from __future__ import annotations

import json
from dataclasses import replace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

from gaitlib import data, marks, plots  # noqa: E402
from gaitlib.studies import gait  # noqa: E402
from gaitlib.studies import predictive as pr  # noqa: E402
from gaitlib.sweep import RunRecord  # noqa: E402

FAILED = "Maximum_Iterations_Exceeded"


def _texts(fig):
    return [t.get_text() for t in fig.findobj(matplotlib.text.Text)]


def _watermarks(fig):
    return [a for a in marks.marks_in(fig) if isinstance(a, matplotlib.text.Text) and a.axes is not None
            and a.get_rotation() not in (0.0,)]


def _failed(sol):
    """The same solution under a non-converged IPOPT status."""
    return replace(sol, stats={**sol.stats, "status": FAILED, "success": False})


# ------------------------------------------------------------------ labels
class _Rec:
    def __init__(self, ok, status):
        self.ok, self.status = ok, status


def test_failure_label_reads_every_kind_of_outcome():
    assert marks.failure_label("Solve_Succeeded") is None
    assert marks.failure_label("Solved_To_Acceptable_Level") is None
    assert marks.failure_label(FAILED) == f"NOT CONVERGED: {FAILED}"
    assert marks.failure_label({"status": "Solve_Succeeded", "success": True}) is None
    assert marks.failure_label({"status": "Invalid_Number_Detected", "success": False}) == \
        "NOT CONVERGED: Invalid_Number_Detected"
    rec = RunRecord("x", False, "error", None, "Traceback", 0.0, "serial")
    assert marks.failure_label(rec) == "NOT CONVERGED: error"
    assert marks.failure_label(_Rec(True, "Solve_Succeeded")) is None
    assert marks.failure_label(None) is None  # nothing known against it


def test_invalid_is_a_second_reason():
    assert marks.failure_label("Solve_Succeeded", valid=True) is None
    assert marks.failure_label("Solve_Succeeded", valid=False) == "INVALID"
    assert marks.failure_label("Solve_Succeeded", valid="foot loaded in swing") == "INVALID: foot loaded in swing"
    both = marks.failure_label(FAILED, valid="foot loaded in swing")
    assert both == f"NOT CONVERGED: {FAILED}; INVALID: foot loaded in swing"

    class Gate:
        ok, reason = False, "knee torque above strength"

    assert marks.failure_label("Solve_Succeeded", valid=Gate()) == "INVALID: knee torque above strength"


@pytest.fixture(scope="module")
def no_gates():
    """The marks of convergence alone: the validity gates off for the tests that ask (and the
    study built for them, whose tables carry their marks), the process's check restored after
    the module (the stored SK solution these tests reuse fails the gates — the
    Ch 2 thesis-reading solve loads a swinging foot — and they test the convergence marks)."""
    before = marks._validity_check
    marks.use_validity_check(None)
    yield
    marks.use_validity_check(before)


def test_mark_kinds_drop_the_reasons_of_an_invalid_run_with_several():
    """An invalid run's reasons are joined by "; " like the kinds: only the kinds come back."""
    label = ("NOT CONVERGED: Maximum_Iterations_Exceeded; INVALID: torque 87.1 N·m > 82.9 N·m (ankle_r peak); "
             "angle 40.9 deg > 40 deg (ankle_r, thesis Table 3.5); GRF 42 N > 20 N (swing)")
    assert marks.mark_kinds(label) == ["NOT CONVERGED", "INVALID"]
    assert marks.mark_kinds("INVALID") == ["INVALID"] and marks.mark_kinds(None) == [] and marks.mark_kinds("") == []
    # the validity gates' own label (the card's valid column) reads the same
    assert marks.mark_kinds("not converged (Maximum_Iterations_Exceeded); invalid: double support 90% > 40%; "
                            "swing load 55 N > 8 N") == ["NOT CONVERGED", "INVALID"]
    assert marks.mark_kinds("invalid: double support 96% > 40% (of the cycle)") == ["INVALID"]
    assert marks.mark_kinds("valid") == []


def test_a_validity_check_reaches_every_label():
    before = marks._validity_check
    try:
        marks.use_validity_check(lambda obj: "foot loaded in swing" if obj == "Solve_Succeeded" else None)
        assert marks.failure_label("Solve_Succeeded") == "INVALID: foot loaded in swing"
        assert marks.failure_label("Solve_Succeeded", valid=True) is None  # an explicit verdict wins
        assert marks.failure_label(FAILED) == f"NOT CONVERGED: {FAILED}"
        marks.use_validity_check(None)
        assert marks.failure_label("Solve_Succeeded") is None
    finally:
        marks.use_validity_check(before)  # no hidden state: later tests see the process's check
    assert marks._validity_check is before


def test_mark_table_flags_rows_and_unmarked_drops_them():
    df = pd.DataFrame({"nrmse": [0.1, 0.2]}, index=pd.MultiIndex.from_tuples([("NMSK", "DT"), ("NMSK", "SDT3")]))
    out = marks.mark_table(df, {("NMSK", "SDT3"): f"NOT CONVERGED: {FAILED}"})
    assert list(out.columns) == ["mark", "nrmse"]
    assert out.index[1] == ("NMSK", "SDT3 †") and out.index[0] == ("NMSK", "DT")
    assert out["mark"].iloc[1] == f"NOT CONVERGED: {FAILED}" and out["mark"].iloc[0] == ""
    assert list(marks.unmarked(out)["nrmse"]) == [0.1]


# ------------------------------------------------------------------ figures
@pytest.fixture(scope="module")
def tracked():
    return gait.tracking_data(data.load_gait_data("Free"))


def _sim_from_data(g, shift=0.0):
    """A 'simulation' frame: the data mean (plus ``shift``), indexed by time in s."""
    cols = [c for c in plots.GAIT_CHANNELS if c in g.mean]
    return pd.DataFrame({c: g.mean[c].to_numpy() + shift for c in cols}, index=np.asarray(g.time, float))


def test_tracking_figure_of_a_failed_solve_carries_the_watermark(tracked):
    label = marks.failure_label(FAILED)
    sim = _sim_from_data(tracked)
    fig = plots.tracking_figure(tracked, {"SK Eq4.11": sim}, marks={"SK Eq4.11": label}, title="tracking")
    wm = _watermarks(fig)
    # every panel that draws the run (all but the metatarsal torques, which the data lack)
    assert len(wm) == len(sim.columns) == len(plots.GAIT_CHANNELS) - 2
    for t in wm:
        assert t.get_text() == f"NOT CONVERGED: {FAILED}"
        assert to_rgba(t.get_color())[:3] == pytest.approx(to_rgba(marks.MARK_COLOR)[:3])
        assert t.get_zorder() > max(line.get_zorder() for line in t.axes.lines)
    assert fig._suptitle.get_text().startswith(f"NOT CONVERGED: {FAILED}")
    assert any(f"† NOT CONVERGED: {FAILED}" in s for s in _texts(fig))  # the legend says it too
    plt.close(fig)


def test_tracking_figure_marks_only_the_failed_run(tracked):
    fig = plots.tracking_figure(tracked, {"A": _sim_from_data(tracked), "B": _sim_from_data(tracked, 0.1)},
                                marks={"A": None, "B": f"NOT CONVERGED: {FAILED}"})
    wm = _watermarks(fig)
    assert wm and all(t.get_text() == f"B: NOT CONVERGED: {FAILED}" for t in wm)
    ax = wm[0].axes
    styles = {ln.get_label(): ln.get_linestyle() for ln in ax.lines if not ln.get_label().startswith("_")}
    assert styles["A"] == "-" and styles[f"B † NOT CONVERGED: {FAILED}"] == "--"
    plt.close(fig)


def test_converged_tracking_figure_has_no_mark(tracked):
    fig = plots.tracking_figure(tracked, {"A": _sim_from_data(tracked)}, marks={"A": None})
    assert marks.marks_in(fig) == []
    plt.close(fig)


def _scores(failed_case="SDT3"):
    rows = []
    for model in ("MSK", "NMSK"):
        for case in ("DT", "SDT3"):
            bad = model == "NMSK" and case == failed_case
            for ch, v in (("hip", 0.1), ("knee", 0.2)):
                rows.append({"run": f"{model} {case}", "model": model, "case": case,
                             "mark": f"NOT CONVERGED: {FAILED}" if bad else None, "kind": "angle",
                             "channel": ch, "side": "r", "unit": "deg", "rmse": v, "nrmse": v})
    return pd.DataFrame(rows)


def test_score_bars_hatch_the_failed_run():
    fig = plots.score_bars(_scores(), "angle", value="nrmse", cases=["DT", "SDT3"], title="bars")
    for ax in fig.axes[:2]:
        patches = [p for p in ax.patches if p.get_height() > 0]
        assert len(patches) == 4
        hatched = [p for p in patches if p.get_hatch()]
        assert len(hatched) == 1
        p = hatched[0]
        assert p.get_gid() == marks.MARK_GID
        assert to_rgba(p.get_edgecolor())[:3] == pytest.approx(to_rgba(marks.MARK_COLOR)[:3])
        # the hatched bar is NMSK's (right of the pair) at SDT3 (x = 1)
        assert p.get_x() + p.get_width() / 2 == pytest.approx(1.2)
    assert "NMSK SDT3" in fig._suptitle.get_text() and FAILED in fig._suptitle.get_text()
    assert any("hatched: NOT CONVERGED" in s for s in _texts(fig))
    plt.close(fig)


# ------------------------------------------------------------------ the CLI's figure
@pytest.fixture(scope="module")
def stored_sk():
    """The book's SK natural-gait solution, from the solution store (no solve)."""
    sol = gait.natural_gait("SK", progress=False)
    if not sol.stats.get("from_cache"):
        pytest.skip("stored SK solution not hit")
    return sol


def test_cli_tracking_png_of_a_failed_solve_is_marked(stored_sk, tmp_path, monkeypatch):
    seen = {}
    orig = plots.tracking_figure

    def spy(*a, **kw):
        fig = orig(*a, **kw)
        seen["fig"] = fig
        return fig

    monkeypatch.setattr(plots, "tracking_figure", spy)
    out = gait.write_outputs(_failed(stored_sk), tmp_path / "run")
    assert (out / "tracking.png").stat().st_size > 0
    wm = _watermarks(seen["fig"])
    assert len(wm) == len(plots.GAIT_CHANNELS) and all(FAILED in t.get_text() for t in wm)
    assert json.loads((out / "summary.json").read_text())["stats"]["status"] == FAILED


# ------------------------------------------------------------------ the Ch 6/7 study tables and figures
@pytest.fixture(scope="module")
def study(stored_sk, no_gates):
    """A Ch 6-like study of two runs, one of which stopped at the iteration limit."""
    ok, bad = stored_sk, _failed(stored_sk)
    sols = {"MSK DT": ok, "MSK SDT3": bad}
    recs = {k: RunRecord(k, s.stats["success"], s.stats["status"], s, None, 1.0, "serial") for k, s in sols.items()}
    specs = {k: s.spec for k, s in sols.items()}
    free = data.load_gait_data("Free")
    return pr.StudyResult(specs, recs, sols, {}, pr._scores(sols, {"Free": free}, lambda s: "Free"))


def test_study_tables_carry_the_failure(study, no_gates):
    st = study.stats()
    assert st.loc["MSK SDT3", "mark"] == f"NOT CONVERGED: {FAILED}" and st.loc["MSK DT", "mark"] == ""
    sc = study.scores
    assert set(sc.loc[sc["run"] == "MSK SDT3", "mark"]) == {f"NOT CONVERGED: {FAILED}"}
    assert sc.loc[sc["run"] == "MSK DT", "mark"].isna().all()
    assert set(study.converged_scores()["run"]) == {"MSK DT"}  # headlines never see the failed run
    times = pr.times_table(study, pr.THESIS_HOURS_TABLE_6_3)
    assert times["mark"].tolist() == ["", f"NOT CONVERGED: {FAILED}"]
    assert study.marks() == {"MSK DT": None, "MSK SDT3": f"NOT CONVERGED: {FAILED}"}


def test_study_bar_figures_hatch_the_failed_run(study, no_gates):
    for kind in ("angle", "torque", "grf"):
        fig = plots.score_bars(study.scores, kind, cases=["DT", "SDT3"])
        hatched = [p for ax in fig.axes for p in ax.patches if p.get_hatch()]
        panels = [ax for ax in fig.axes if ax.patches]
        assert len(hatched) == len(panels) > 0  # one hatched bar (SDT3) per panel
        assert all(p.get_x() + p.get_width() / 2 == pytest.approx(1.0) for p in hatched)
        plt.close(fig)


# ------------------------------------------------------------------ the gap figures
class _Loc:
    """The part of a :class:`gaitlib.gap.locate.Located` the heat maps read."""

    channels = pd.DataFrame({"channel": ["angle:knee_r", "grf:grf_y_r"]})

    def heat(self, value="rms_z"):
        from gaitlib.gap.locate import PHASES

        v = False if value == "significant" else 1.5
        return pd.DataFrame(v, index=["angle:knee_r", "grf:grf_y_r"], columns=list(PHASES))


def test_gap_heatmap_of_a_failed_baseline_is_marked():
    from gaitlib.gap import figures as F

    label = marks.failure_label(FAILED)
    fig = F.gap_heatmap(_Loc(), title="gap", mark=label)
    assert [t.get_text() for t in _watermarks(fig)] == [label]
    assert fig.axes[0].get_title().startswith(label)
    plt.close(fig)
    fig = F.gap_heatmap(_Loc(), title="gap")
    assert marks.marks_in(fig) == []
    plt.close(fig)


def test_ranking_bars_hatch_a_failed_candidate():
    from gaitlib.gap import figures as F

    r = pd.DataFrame({"effect": ["a", "b"], "n_params": [1, 2], "pct_closed": [30.0, 10.0], "dBIC": [-20.0, -5.0],
                      "ok": [True, False], "status": ["Solve_Succeeded", FAILED]})
    fig = F.ranking_bars(r, top="a")
    for ax in fig.axes[:2]:
        hatched = [p for p in ax.patches if p.get_hatch()]
        assert len(hatched) == 1 and hatched[0].get_width() in (10.0, -5.0)
    assert any(f"b (k=2) † {FAILED}" == t.get_text() for t in fig.axes[0].get_yticklabels())
    plt.close(fig)


def test_cot_table_and_stats_table_mark_the_failed_solve(stored_sk, no_gates):
    bad = _failed(stored_sk)
    ch7 = pr.StudyResult({"NMSK Free": bad.spec}, {}, {"NMSK Free": bad}, {})
    cot = pr.cot_table(ch7, {"Free (reference)": stored_sk})
    assert cot.loc["Free", "mark"] == f"NOT CONVERGED: {FAILED}" and not cot.loc["Free", "converged"]
    assert cot.loc["Free (reference)", "mark"] == ""
    st = gait.stats_table({"ok": stored_sk, "bad": bad})
    assert st.loc["bad", "mark"] == f"NOT CONVERGED: {FAILED}" and st.loc["ok", "mark"] == ""


def test_mark_all_watermarks_every_drawn_axes():
    fig, axes = plt.subplots(1, 3)
    axes[0].plot([0, 1], [0, 1])
    axes[1].bar([0], [1])
    axes[2].axis("off")
    marks.mark_all(fig, "NOT CONVERGED: x")
    assert [t.axes for t in _watermarks(fig)] == [axes[0], axes[1]]
    assert fig._suptitle.get_text() == "NOT CONVERGED: x"
    plt.close(fig)


# ------------------------------------------------------------------ the book's sources pass the marks on
def test_every_book_figure_of_a_solve_passes_its_mark():
    """Every call in book/src that draws simulated curves or animates a solve hands over the
    failure labels (``marks=``/``mark=``); bar charts get them through the scores' ``mark``
    column (checked above). Data-only drawings are listed by file and line of the call."""
    import ast
    from pathlib import Path

    data_only = {("appendix_physics.py", "animate_gait")}  # the data's kinematics, no solve
    src = Path(__file__).resolve().parents[1] / "book" / "src"
    missing = []
    for f in sorted(src.glob("ch0[2-8]*.py")) + [src / "appendix_physics.py"]:
        cells = [c for c in f.read_text().split("# %%") if not c.startswith(" [markdown]")]
        code = "\n".join("# %%" + c for c in cells)
        for node in ast.walk(ast.parse(code)):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
                continue
            name = node.func.attr
            if name not in ("tracking_figure", "animate_gait", "animate_jump", "animate"):
                continue
            if (f.name, name) in data_only:
                continue
            if not {kw.arg for kw in node.keywords} & {"marks", "mark"}:
                missing.append(f"{f.name} (code line {node.lineno}) {name}")
    assert not missing, "figures of a solve without its failure label: " + ", ".join(missing)


def test_a_long_mark_never_widens_a_saved_figure(tmp_path):
    """Many marked runs give a label of hundreds of characters: the saved figure (tight
    bounding box, as the book's notebooks save them) stays within its own width."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    label = "; ".join(f"NMSK run {i} (INVALID: swing load {100 + i} N > 8.12 N (2 % BW); double support 52.9% > 40%)"
                      for i in range(8))
    fig, axes = plt.subplots(1, 4, figsize=(10, 3), dpi=50)
    for ax in axes:
        ax.plot([0, 1], [0, 1])
        marks.mark_axes(ax, label)
    marks.mark_figure(fig, label)
    fig.savefig(tmp_path / "f.png", bbox_inches="tight")
    plt.close(fig)
    width_px = Image.open(tmp_path / "f.png").size[0]
    assert width_px <= 1.1 * 10 * 50


def test_a_legend_of_long_marked_run_labels_never_widens_a_tracking_figure(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    from gaitlib import plots

    fig, axes = plt.subplots(1, 2, figsize=(8, 3), dpi=50, squeeze=False)
    for i in range(3):
        axes[0, 0].plot([0, 1], [0, i], label=f"run {i} † INVALID: swing load {100 + i} N > 8.12 N (2 % BW); "
                                              "double support 96.1% > 40% (of the cycle); residual force 331 N")
    plots._finish_panels(fig, axes, 1, title="t")
    fig.savefig(tmp_path / "f.png", bbox_inches="tight")
    plt.close(fig)
    assert Image.open(tmp_path / "f.png").size[0] <= 1.1 * 8 * 50


def test_a_marked_one_row_tracking_figure_keeps_its_axes_and_its_width(tracked, tmp_path):
    """Ch 4's GRF figure: one row of four panels, a run marked with three failed gates (a
    title of three lines and a legend label of two) — at its nominal 2.1 in the decorations
    left the axes no height and constrained layout gave up ("axes sizes collapsed to zero").
    The figure grows to fit them: saving raises no layout warning, every panel keeps at least
    1.4 in of the figure, and the width is not exceeded."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    from gaitlib import plots

    label = ("INVALID: swing load 47.4 N > 8.12 N (2 % BW); residual force 331 N > 24.5 N (5 % of peak external "
             "force); residual moment 29.3 N·m > 4.11 N·m (1 % of COM height × peak external force)")
    sims = {"(a) trajectory optimisation": tracked.mean, "(b) optimal control": tracked.mean,
            "(c) optimal control + body parameters": tracked.mean}
    fig = plots.tracking_figure(tracked, sims, channels=("grf_x_r", "grf_y_r", "grf_x_l", "grf_y_l"), ncols=4,
                                title="Figs 4.9 / 4.15", marks={"(a) trajectory optimisation": label})
    assert fig.get_size_inches()[1] >= 1.4 + 0.35
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig.savefig(tmp_path / "f.png", bbox_inches="tight", dpi=50)
    h_ax = min(ax.get_position().height for ax in fig.axes if ax.get_visible()) * fig.get_size_inches()[1]
    plt.close(fig)
    assert h_ax > 0.5
    assert Image.open(tmp_path / "f.png").size[0] <= 1.1 * 12 * 50
