"""The tidy CSV format every data set is converted to, and its reader.

One row per (source, speed class, quantity, side, % gait cycle) with the across-subject mean
and SD in the unit :data:`QUANTITY_UNITS` prescribes. :func:`load_tidy` checks the format
(columns, numbers, units, classes, duplicates) and raises :class:`DataError` naming the
file, column and row; the physiological ranges are :mod:`gaitlib.plausibility`'s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from . import conventions as cv

__all__ = ["TIDY_COLUMNS", "QUANTITY_UNITS", "DataError", "load_tidy"]

#: The columns of a tidy CSV, in order.
TIDY_COLUMNS = ("source", "speed_class", "quantity", "side", "percent_cycle", "mean", "sd", "unit")

#: Units each tidy quantity must carry (an unexpected unit is an error, never coerced).
QUANTITY_UNITS = {
    "trunk_anterior_tilt": "deg",
    "pelvis_anterior_tilt": "deg",
    "pelvis_rotation": "deg",
    "hip_flexion": "deg",
    "knee_flexion": "deg",
    "ankle_dorsiflexion": "deg",
    "grf_anterior": "BW",
    "grf_vertical": "BW",
    "hip_extensor_moment": "N*m/kg",
    "knee_extensor_moment": "N*m/kg",
    "ankle_plantarflexor_moment": "N*m/kg",
    "hip_power": "W/kg",
    "knee_power": "W/kg",
    "ankle_power": "W/kg",
}
for _m in ("RF", "MH", "LH", "TA", "MG", "GM", "VM", "BF", "SOL", "PL", "GAM"):
    QUANTITY_UNITS[f"emg_{_m}"] = "1"


class DataError(ValueError):
    """Malformed or unexpected input data; the message names the file and the field."""


def load_tidy(path: str | Path) -> pd.DataFrame:
    """Read a tidy curve CSV and validate it.

    Raises :class:`DataError` naming the file and the column/quantity when: a column of
    :data:`TIDY_COLUMNS` is missing; a mean or sd is NaN or not a number; an sd is negative;
    a percent_cycle is outside [0, 100]; a quantity is unknown or carries a unit other than
    the one in :data:`QUANTITY_UNITS`; a speed class is unknown; a row is duplicated.
    """
    path = Path(path)
    if not path.exists():
        raise DataError(f"{path}: file not found")
    try:
        df = pd.read_csv(path, dtype={"source": str, "speed_class": str, "quantity": str,
                                      "side": str, "unit": str}, keep_default_na=False)
    except Exception as exc:  # pragma: no cover - pandas error text varies
        raise DataError(f"{path}: not a readable CSV ({exc})") from exc
    missing = [c for c in TIDY_COLUMNS if c not in df.columns]
    if missing:
        raise DataError(f"{path}: missing column(s) {missing}; expected columns {list(TIDY_COLUMNS)}")
    for col in ("percent_cycle", "mean", "sd"):
        num = pd.to_numeric(df[col].replace("", np.nan), errors="coerce")
        bad = num.isna()
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise DataError(f"{path}: column {col!r} row {i + 2} (quantity {df['quantity'].iloc[i]!r}): "
                            f"value {df[col].iloc[i]!r} is missing or not a number")
        df[col] = num.astype(float)
    if (df["sd"] < 0).any():
        i = int(np.flatnonzero((df["sd"] < 0).to_numpy())[0])
        raise DataError(f"{path}: column 'sd' row {i + 2} (quantity {df['quantity'].iloc[i]!r}): "
                        f"negative SD {df['sd'].iloc[i]} (expected ≥ 0)")
    out_of_range = (df["percent_cycle"] < 0) | (df["percent_cycle"] > 100)
    if out_of_range.any():
        i = int(np.flatnonzero(out_of_range.to_numpy())[0])
        raise DataError(f"{path}: column 'percent_cycle' row {i + 2}: {df['percent_cycle'].iloc[i]} "
                        "outside [0, 100] (expected unit: percent of the gait cycle)")
    for q, unit in df[["quantity", "unit"]].drop_duplicates().itertuples(index=False):
        if q not in QUANTITY_UNITS:
            raise DataError(f"{path}: column 'quantity': unknown quantity {q!r}; known: {sorted(QUANTITY_UNITS)}")
        if unit != QUANTITY_UNITS[q]:
            raise DataError(f"{path}: column 'unit' for quantity {q!r}: got {unit!r}, "
                            f"expected {QUANTITY_UNITS[q]!r}")
    bad_cls = set(df["speed_class"]) - set(cv.SPEED_CLASSES)
    if bad_cls:
        raise DataError(f"{path}: column 'speed_class': unknown {sorted(bad_cls)}; known {list(cv.SPEED_CLASSES)}")
    dup = df.duplicated(["source", "speed_class", "quantity", "side", "percent_cycle"])
    if dup.any():
        i = int(np.flatnonzero(dup.to_numpy())[0])
        raise DataError(f"{path}: row {i + 2} duplicates an earlier row "
                        f"({df['quantity'].iloc[i]!r}, {df['percent_cycle'].iloc[i]} %)")
    return df
