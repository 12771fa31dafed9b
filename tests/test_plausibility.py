"""Plausibility gates on tidy data (gaitlib.plausibility): bad inputs stop with a one-line
message naming file, quantity, row and expected range, before any problem is built."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitlib.problems import gait as gait_ocp
from gaitlib import data as data_mod
from gaitlib import plausibility as P
from gaitlib.gap import io as gio

COLS = list(data_mod.TIDY_COLUMNS)


@pytest.fixture(scope="module")
def good() -> pd.DataFrame:
    """The Free class of the committed Schwartz 2008 file (all its quantities), row order kept."""
    df = pd.read_csv(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    return df[df.speed_class == "Free"].reset_index(drop=True)


def write(df: pd.DataFrame, path) -> str:
    df[COLS].to_csv(path, index=False, float_format="%.10g")
    return str(path)


def line_of(df: pd.DataFrame, mask) -> int:
    """CSV line number (header = 1) of the first row where ``mask`` holds."""
    return int(np.flatnonzero(np.asarray(mask))[0]) + 2


def scaled(df, quantity, factor, col="mean"):
    df = df.copy()
    sel = df.quantity == quantity
    df.loc[sel, col] = df.loc[sel, col] * factor
    return df


def test_committed_data_pass_every_class():
    """Every committed curve file, every class; gaitutils only with its EMG (no SD in the
    source) accepted as tracked without SD."""
    files = sorted(data_mod.DATA_DIR.glob("*_curves.csv"))
    assert {f.name for f in files} == {"schwartz2008_curves.csv", "gaitutils_curves.csv"}
    df = data_mod.load_tidy(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    assert set(df.speed_class) == {"VerySlow", "Slow", "Free", "Fast", "VeryFast"}
    assert P.check_tidy(df, "schwartz2008_curves.csv") == ()
    with pytest.raises(data_mod.DataError, match=r"gaitutils_curves.csv: quantity 'emg_\w+'.*sd is 0 at every"):
        P.check_file(data_mod.DATA_DIR / "gaitutils_curves.csv")
    no_sd = P.check_file(data_mod.DATA_DIR / "gaitutils_curves.csv", allow_no_sd=True)
    assert len(no_sd) == 16 and all(c.startswith("emg_") for c in no_sd)  # 8 muscles x R, L


def test_every_quantity_has_a_range():
    assert set(P.RANGES) == set(data_mod.QUANTITY_UNITS)


def test_good_file_reads(tmp_path, good):
    ds = gio.read_data(write(good, tmp_path / "good.csv"))
    assert ds.gait.speed_class == "Free" and not ds.notes


# ------------------------------------------------------------------ the suite of bad inputs
# (name, corruption of the good Free frame, substrings the one-line message must hold)

def _deg_x57(df):  # degrees labelled, radians-to-degrees applied once more
    return scaled(df, "knee_flexion", 180 / np.pi)


def _rad(df):  # radians labelled deg
    return scaled(df, "knee_flexion", np.pi / 180)


def _knee_included(df):  # knee as the included angle (180° = straight)
    df = df.copy()
    sel = df.quantity == "knee_flexion"
    df.loc[sel, "mean"] = 180.0 - df.loc[sel, "mean"]
    return df


def _knee_sign(df):  # knee extension positive
    return scaled(df, "knee_flexion", -1.0)


def _pelvis_rad(df):
    return scaled(df, "pelvis_anterior_tilt", np.pi / 180)


def _grf_pct(df):  # % body weight labelled BW
    return scaled(df, "grf_vertical", 100.0)


def _grf_newton(df):  # newtons labelled BW (41.4 kg child: peak ~ 450 N)
    return scaled(df, "grf_vertical", 41.4 * 9.81)


def _moment_nm(df):  # N*m labelled N*m/kg
    return scaled(df, "ankle_plantarflexor_moment", 41.4)


def _moment_tiny(df):  # N*m/kg divided by 100
    return scaled(df, "hip_extensor_moment", 0.01)


def _fraction(df):  # percent_cycle as 0-1
    df = df.copy()
    df["percent_cycle"] = df["percent_cycle"] / 100.0
    return df


def _set(quantity, pct, col, value):
    def f(df):
        df = df.copy()
        df[col] = df[col].astype(object)
        df.loc[(df.quantity == quantity) & (df.percent_cycle == pct), col] = value
        return df
    return f


def _sd_zero(df):
    df = df.copy()
    df.loc[df.quantity == "knee_flexion", "sd"] = 0.0
    return df


def _sd_pct(df):  # the SD in % BW while the mean is in BW
    return scaled(df, "grf_vertical", 100.0, col="sd")


def _second_half_missing(df):
    return df[~((df.quantity == "hip_flexion") & (df.percent_cycle > 50))]


def _random_half_missing(df):
    drop = df[df.quantity == "ankle_dorsiflexion"].sample(frac=0.5, random_state=1).index
    return df.drop(drop)


def _every_20pct(df):
    return df[df.percent_cycle % 20 == 0]


def _no_100(df):
    return df[df.percent_cycle < 100]


def _off_grid(df):
    df = df.copy()
    df.loc[(df.quantity == "knee_flexion") & (df.percent_cycle == 30), "percent_cycle"] = 31.0
    return df


def _side(value):
    def f(df):
        df = df.copy()
        df.loc[df.quantity == "knee_flexion", "side"] = value
        return df
    return f


def _side_r_only(df):
    df = df.copy()
    df.loc[df.quantity == "knee_flexion", "side"] = "R"
    return df


BAD = [
    ("degrees x57", _deg_x57, ["quantity 'knee_flexion'", "outside [-30, 120] deg", "converted"]),
    ("radians as deg", _rad, ["quantity 'knee_flexion'", "range of motion", "[5, 120] deg", "radians"]),
    ("knee included angle", _knee_included, ["quantity 'knee_flexion'", "outside [-30, 120] deg",
                                             "another angle convention"]),
    ("knee sign flipped", _knee_sign, ["quantity 'knee_flexion'", "outside [-30, 120] deg"]),
    ("pelvis radians", _pelvis_rad, ["quantity 'pelvis_anterior_tilt'", "[0.3, 30] deg", "radians"]),
    ("GRF % BW", _grf_pct, ["quantity 'grf_vertical'", "outside [-0.05, 2] BW", "% body weight"]),
    ("GRF newtons", _grf_newton, ["quantity 'grf_vertical'", "outside [-0.05, 2] BW", "newtons"]),
    ("moment N*m", _moment_nm, ["quantity 'ankle_plantarflexor_moment'", "outside [-4, 4] N*m/kg", "not per kg"]),
    ("moment /100", _moment_tiny, ["quantity 'hip_extensor_moment'", "peak", "[0.05, 4] N*m/kg"]),
    ("percent as fraction", _fraction, ["percent_cycle ends at 1", "0–100", "fraction"]),
    ("inf mean", _set("knee_flexion", 40.0, "mean", "inf"), ["quantity 'knee_flexion'", "'mean'", "finite"]),
    ("inf sd", _set("grf_anterior", 10.0, "sd", "inf"), ["quantity 'grf_anterior'", "'sd'", "finite"]),
    ("1e308 mean", _set("hip_flexion", 60.0, "mean", "1e308"), ["quantity 'hip_flexion'", "1e+308",
                                                                 "[-60, 100] deg"]),
    ("SD = 0", _sd_zero, ["quantity 'knee_flexion'", "sd is 0 at every point", "sd > 0", "--allow-no-sd"]),
    ("SD in % BW", _sd_pct, ["quantity 'grf_vertical'", "sd ", "[0, 1] BW"]),
    ("second half missing", _second_half_missing, ["quantity 'hip_flexion'", "25 of 51 cycle points missing",
                                                   "52, 54, 56, …, 100", "after row", "every 2 % from 0 to 100"]),
    ("random half missing", _random_half_missing, ["quantity 'ankle_dorsiflexion'", "cycle points missing",
                                                   "every 2 % from 0 to 100"]),
    ("20 % grid", _every_20pct, ["grid step 20 %", "at most 10 %", "rows"]),
    ("no 100 %", _no_100, ["1 of 51 cycle points missing", "percent_cycle 100"]),
    ("off-grid point", _off_grid, ["quantity 'knee_flexion'", "percent_cycle 31", "off the class's grid"]),
    ("side 'right'", _side("right"), ["quantity 'knee_flexion'", "side 'right' is not accepted", "'ipsilateral'",
                                      "'R' and 'L'"]),
    ("side R alone", _side_r_only, ["quantity 'knee_flexion'", "['R']", "'ipsilateral' alone"]),
]


@pytest.mark.parametrize("name,corrupt,expect", BAD, ids=[b[0] for b in BAD])
def test_bad_input_fails_with_one_line(tmp_path, good, name, corrupt, expect):
    path = write(corrupt(good), tmp_path / "bad.csv")
    with pytest.raises(data_mod.DataError) as e:
        gio.read_data(path)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: ")
    assert "row" in msg
    for s in expect:
        assert s in msg, (s, msg)


def test_message_names_the_row_of_the_bad_value(tmp_path, good):
    df = _set("knee_flexion", 40.0, "mean", "inf")(good)
    path = write(df, tmp_path / "bad.csv")
    line = line_of(df, (df.quantity == "knee_flexion") & (df.percent_cycle == 40.0))
    with pytest.raises(data_mod.DataError, match=rf"row {line}: column 'mean' is inf; expected a finite number"):
        gio.read_data(path)
    # ×57: the row of the largest knee angle (Free: 59.13° at 72 % of the cycle in Schwartz
    # 2008), 59.1317 × 57.2958 = 3388.0°
    df = _deg_x57(good)
    k = df[df.quantity == "knee_flexion"]
    peak = k["mean"].idxmax()
    assert good.loc[peak, "percent_cycle"] == 72.0 and good.loc[peak, "mean"] == pytest.approx(59.13, abs=0.01)
    with pytest.raises(data_mod.DataError, match=rf"row {peak + 2}: mean 3388(\.\d+)? deg outside \[-30, 120\]"):
        gio.read_data(write(df, tmp_path / "bad.csv"))


def test_range_of_motion_in_the_message(tmp_path, good):
    """Radians labelled deg: the message's range of motion is the knee's (max − min) in
    degrees × π/180 (Free: 59.13° − 4.03° = 55.11° → 0.9618)."""
    k = good[good.quantity == "knee_flexion"]["mean"]
    rom = (k.max() - k.min()) * np.pi / 180
    assert rom == pytest.approx(0.9618, abs=1e-4)
    with pytest.raises(data_mod.DataError, match=rf"rows? \d+ \(max\) and rows? \d+ \(min\): range of motion "
                                                 rf"{rom:g} deg outside \[5, 120\] deg"):
        gio.read_data(write(_rad(good), tmp_path / "bad.csv"))


def test_without_sd_is_explicit_and_leaves_the_gap(tmp_path, good):
    """SD = 0 everywhere: refused; with allow_no_sd the curve is read (tracked) and the
    located gap lists both knee channels as excluded, the others standardised."""
    from gaitlib.gap import locate as L

    path = write(_sd_zero(good), tmp_path / "nosd.csv")
    ds = gio.read_data(path, allow_no_sd=True)
    assert ds.notes == ("tracked without SD (left out of the located gap): knee_flexion",)
    view = gait_ocp.tracking_data(ds.gait)
    sim = view.mean.copy()
    sim.index = pd.Index(view.time / view.cycle_time, name="tau")
    loc = L.locate(sim[sim.index < 1.0], ds)
    excluded = {d["id"]: d["reason"] for d in loc.excluded}
    assert excluded == {"angle:knee_r": "no SD in the data", "angle:knee_l": "no SD in the data"}
    assert loc.rss == pytest.approx(0.0, abs=1e-12)


def test_sd_zero_at_some_points_is_accepted(tmp_path, good):
    """Zero SD at a few points (GRF in swing) is covered by the gap's SD* floor."""
    df = good.copy()
    df.loc[(df.quantity == "grf_vertical") & (df.percent_cycle > 62), "sd"] = 0.0
    gio.read_data(write(df, tmp_path / "swing.csv"))


def test_both_legs_and_coarse_uniform_grid_are_accepted(tmp_path, good):
    """Sides R and L for a quantity, and a uniform 10 % grid, are valid tidy data."""
    df = good[good.percent_cycle % 10 == 0]
    k = df[df.quantity == "knee_flexion"]
    both = pd.concat([df[df.quantity != "knee_flexion"], k.assign(side="R"), k.assign(side="L")])
    gio.read_data(write(both, tmp_path / "legs.csv"))


# ------------------------------------------------------------------ speed classes and the CLI

@pytest.fixture
def no_solve(monkeypatch):
    """Any attempt to build a problem or start the diagnosis fails the test."""
    from gaitlib.gap import diagnose as D

    def boom(*a, **k):
        raise AssertionError("a problem was built")

    monkeypatch.setattr(D, "diagnose", boom)
    monkeypatch.setattr(gait_ocp, "build", boom)


def test_multi_class_file_needs_a_speed_class(tmp_path):
    path = data_mod.DATA_DIR / "schwartz2008_curves.csv"
    with pytest.raises(data_mod.DataError, match=r"several classes \['VerySlow', 'Slow', 'Free', 'Fast', "
                                                 r"'VeryFast'\]; choose one .*--speed-class"):
        gio.read_data(path)
    with pytest.raises(data_mod.DataError, match=r"no rows for speed class 'fast'; the file has \['VerySlow'"):
        gio.read_data(path, speed_class="fast")
    assert gio.read_data(path, speed_class="Fast").gait.speed_class == "Fast"


def test_cli_speed_class_option(tmp_path, monkeypatch, capsys):
    """``gaitlib gap --speed-class Fast`` on the committed multi-class CSV reads the Fast
    class and goes on to the diagnosis; without it: exit 2, one line listing the classes."""
    from gaitlib.cli import main
    from gaitlib.gap import diagnose as D

    seen = {}

    class Reached(BaseException):  # not caught by the CLI's one-line error handler
        pass

    def stop(ds, **kw):
        seen["class"] = ds.gait.speed_class
        raise Reached

    monkeypatch.setattr(D, "diagnose", stop)
    csv = str(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    with pytest.raises(Reached):
        main(["gap", "--data", csv, "--out", str(tmp_path / "o"), "--speed-class", "Fast"])
    assert seen["class"] == "Fast"
    for extra in ([], ["--speed-class", "Medium"]):
        rc = main(["gap", "--data", csv, "--out", str(tmp_path / "o"), *extra])
        err = capsys.readouterr().err
        assert rc == 2 and err.count("\n") == 1 and err.startswith("gaitlib gap: ")
        assert "['VerySlow', 'Slow', 'Free', 'Fast', 'VeryFast']" in err


@pytest.mark.parametrize("name,corrupt,expect", BAD, ids=[b[0] for b in BAD])
def test_cli_bad_input_exits_2_before_any_problem(tmp_path, good, no_solve, capsys, name, corrupt, expect):
    from gaitlib.cli import main

    path = write(corrupt(good), tmp_path / "bad.csv")
    rc = main(["gap", "--data", path, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith(f"gaitlib gap: {path}: ")
    assert all(s in err for s in expect)
    assert not (tmp_path / "out").exists()


def test_cli_bad_input_in_a_fresh_process(tmp_path, good):
    """``python -m gaitlib gap`` on %BW labelled BW: exit 2, one line, no traceback."""
    import os
    import subprocess
    import sys

    path = write(_grf_pct(good), tmp_path / "bad.csv")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    p = subprocess.run([sys.executable, "-m", "gaitlib", "gap", "--data", path, "--out", str(tmp_path / "out")],
                       env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and "Traceback" not in p.stderr
    assert "quantity 'grf_vertical'" in p.stderr and "outside [-0.05, 2] BW" in p.stderr
    assert p.stdout == ""
