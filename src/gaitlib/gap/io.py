"""Reading any tidy-format CSV as a data set the gait problem can track, and writing one.

The tidy format is :mod:`gaitlib.data`'s (``source, speed_class, quantity, side,
percent_cycle, mean, sd, unit``; quantities and units of
:data:`gaitlib.data.QUANTITY_UNITS`). A CSV is read by writing its rows, as the named base
source, into a temporary data folder together with that source's speed/cycle-time and
event files, and calling :func:`gaitlib.data.load_gait_data` — the very reader of the real
data (validation, unit conversion, sign conventions, the left leg generated from the right
by the Fourier phase shift).

Both legs: a model quantity given with sides ``R`` and ``L`` (instead of ``ipsilateral``)
is read with its measured left leg; otherwise the left leg is generated from the right one.

The base source (speed, cycle time, events) is: ``like`` if given; else the CSV's
``source`` if it is ``schwartz2008`` or ``gaitutils``; else the name inside
``twin(<source>)`` (synthetic data sets written by :mod:`gaitlib.gap.twin`).

Accepted values (checked by :func:`read_data` before anything is built; a failure is a
one-line :class:`gaitlib.data.DataError` naming file, quantity, row and expected range)
-----------------------------------------------------------------------------------------
``source``         one value per file (see above).
``speed_class``    one of ``VerySlow, Slow, Free, Fast, VeryFast``; a file with several
                   classes needs ``speed_class=`` (CLI ``--speed-class``).
``quantity/unit``  the pairs of :data:`gaitlib.data.QUANTITY_UNITS` (angles ``deg``, GRFs
                   ``BW`` = fractions of body weight, moments ``N*m/kg``, powers ``W/kg``,
                   EMG ``1``); the quantities of :data:`REQUIRED_QUANTITIES` must be present
                   (or ``fill_from``).
``side``           per quantity ``ipsilateral`` alone or both ``R`` and ``L``.
``percent_cycle``  percent of the cycle, 0 and 100 both present, one uniform grid per class
                   (joint/GRF quantities; EMG may have its own) with a step ≤ 10 %; no
                   missing points (a curve is never interpolated across a gap).
``mean, sd``       finite; within the plausible ranges of :data:`gaitlib.plausibility.RANGES`
                   (e.g. angles in per-joint windows inside ±180°, knee −30–120°, with a
                   sagittal joint range of motion of 5–120°; vertical GRF peak 0.5–2 BW;
                   moments within ±4 N·m/kg); SD > 0 at some point of every curve, unless
                   ``allow_no_sd=True`` (CLI ``--allow-no-sd``): such a curve is tracked
                   but left out of the located gap.
See :mod:`gaitlib.plausibility` for every threshold and its source.

Number of subjects. n (the mean's standard error is SD/√n: the band test of
:mod:`gaitlib.gap.locate` and the % closed intervals scale with √n) is a property of the
data, never of the base source: in order, the ``n_subjects`` argument (CLI:
``--n-subjects``); an optional ``n_subjects`` column of the CSV (a positive integer, one
value per speed class; e.g. ``source,speed_class,quantity,side,percent_cycle,mean,sd,unit,
n_subjects``); the known source the CSV names itself (:func:`n_subjects`: Schwartz 2008 the
speed table's n of the class, 82 at Free; gaitutils: not published with its normal data,
1 — the conservative value; ``twin(<source>)``: the source's, as the twin's noise was
drawn with it). A CSV of another source without either is an error: ``like`` borrows
speed, cycle time and events only. :attr:`DataSet.n_source` says which it was.
"""

from __future__ import annotations

import hashlib
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .. import conventions as cv
from .. import data as data_mod
from .. import plausibility

__all__ = ["KNOWN_SOURCES", "REQUIRED_QUANTITIES", "DataSet", "read_data", "load_real", "base_source_of",
           "n_subjects", "subject_count", "known_source", "signature", "MODEL_QUANTITIES"]

KNOWN_SOURCES = ("schwartz2008", "gaitutils")
#: Quantities the gait problem needs (tracked channels, the hip's pelvis correction, the
#: HAT height from the vertical GRF).
REQUIRED_QUANTITIES = ("pelvis_anterior_tilt", "hip_flexion", "knee_flexion", "ankle_dorsiflexion",
                       "hip_extensor_moment", "knee_extensor_moment", "ankle_plantarflexor_moment",
                       "grf_anterior", "grf_vertical")
#: model channel stem → tidy quantity (the inverse of :data:`gaitlib.data.MODEL_CHANNELS`).
MODEL_QUANTITIES = {v[0]: k for k, v in data_mod.MODEL_CHANNELS.items()}
_BASE_FILES = {"schwartz2008": ("schwartz2008_speed.csv", "schwartz2008_events.csv"),
               "gaitutils": ("gaitutils_timedist.csv",)}


@dataclass(frozen=True)
class DataSet:
    """A data set as the gap diagnosis sees it.

    Attributes
    ----------
    gait : :class:`gaitlib.data.GaitData` (SI, model signs, both legs).
    label : a name for tables (file name or ``"<source> <class>"``).
    base : the base source (speed, cycle time, events, subjects).
    n : number of subjects behind the mean (SD/√n is the mean's uncertainty); Schwartz
        2008: the speed table's n of the class; gaitutils: unknown → 1 (conservative).
    filled : quantities taken from another data set (``fill_from``); their channels are
        tracked but excluded from the located gap.
    path : the CSV, if read from one.
    n_source : where ``n`` came from: ``"option"``, ``"column"`` or ``"known source <name>"``
        (module docstring).
    background : None, or (a change relative to a reference, :mod:`gaitlib.gap.reference`)
        the reference fit's residual S_R − R per channel on the data's time grid (model units,
        tracked representation), which :func:`gaitlib.gap.locate.locate` adds to these data
        (after any data-model effect) before standardising; the fits never see it.
    reference_sd : None, or (relative, :data:`gaitlib.gap.method.RELATIVE` ``quiet_points``)
        the reference's SD per channel on the data's time grid: :func:`gaitlib.gap.locate.locate`
        leaves out the points where neither these data nor the reference have variance (both
        SDs below the locate floor: the GRFs in swing), where nothing in the data can change.
    """

    gait: object
    label: str
    base: str
    n: int
    filled: tuple = ()
    path: str | None = None
    notes: tuple = field(default_factory=tuple)
    n_source: str = ""
    background: object | None = None  # DataFrame: a reference fit's residual (gaitlib.gap.reference)
    reference_sd: object | None = None  # DataFrame: the reference's SD (relative; gaitlib.gap.reference)

    @property
    def signature(self) -> str:
        return signature(self.gait)


def base_source_of(source: str, like: str | None = None) -> str:
    if like:
        if like not in KNOWN_SOURCES:
            raise data_mod.DataError(f"like={like!r}: expected one of {KNOWN_SOURCES}")
        return like
    if known_source(source) is not None:
        return known_source(source)
    raise data_mod.DataError(f"source {source!r} is not a known data set {KNOWN_SOURCES}: pass like=<source> "
                             "(CLI: --like) to take speed, cycle time and events from it")


def known_source(source: str) -> str | None:
    """The known data set a CSV's ``source`` names (itself, or ``x`` of ``twin(x)``), else None."""
    if source in KNOWN_SOURCES:
        return source
    if source.startswith("twin(") and source.endswith(")") and source[5:-1] in KNOWN_SOURCES:
        return source[5:-1]
    return None


def subject_count(df: pd.DataFrame, speed_class: str, n_option=None, path=None) -> tuple[int, str]:
    """(n, where it came from) of a tidy frame of one speed class (module docstring):
    ``n_option``, else the ``n_subjects`` column, else the known source; a one-line
    :class:`gaitlib.data.DataError` when none gives it or they disagree."""
    col = None
    if "n_subjects" in df.columns:
        v = pd.to_numeric(df["n_subjects"].replace("", np.nan), errors="coerce")
        bad = v.isna() | (v < 1) | (v != np.round(v))
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise data_mod.DataError(f"{path}: column 'n_subjects' row {df.index[i] + 2}: {df['n_subjects'].iloc[i]!r} "
                                     "is not a positive integer (subjects behind the means)")
        vals = sorted(set(int(x) for x in v))
        if len(vals) != 1:
            raise data_mod.DataError(f"{path}: column 'n_subjects' has several values {vals} for speed class "
                                     f"{speed_class!r}; expected one")
        col = vals[0]
    if n_option is not None:
        n = int(n_option)
        if n != n_option or n < 1:
            raise data_mod.DataError(f"n_subjects={n_option!r}: expected a positive integer (subjects behind the means)")
        if col is not None and col != n:
            raise data_mod.DataError(f"{path}: column 'n_subjects' says {col}, the option (--n-subjects) {n}: "
                                     "they disagree")
        return n, "option"
    if col is not None:
        return col, "column"
    src = str(df["source"].iloc[0])
    known = known_source(src)
    if known is None:
        raise data_mod.DataError(
            f"{path}: the number of subjects behind the means of source {src!r} is unknown: pass n_subjects "
            "(CLI: --n-subjects N) or add a column 'n_subjects'; --like borrows speed, cycle time and events only")
    return n_subjects(known, speed_class), f"known source {known}"


def n_subjects(base: str, speed_class: str, data_dir=None) -> int:
    """Subjects behind the group mean of a known source: Schwartz 2008 the speed table's n
    of the class (``schwartz2008_speed.csv``, column ``n``); gaitutils 1 (its normal data
    do not state n; 1 is the conservative value)."""
    if base != "schwartz2008":
        return 1
    d = Path(data_dir) if data_dir is not None else data_mod.DATA_DIR
    sp = pd.read_csv(d / "schwartz2008_speed.csv")
    sel = sp[(sp["speed_class"] == speed_class) & (sp["parameter"] == "dimensionless_speed")]
    return int(sel["n"].iloc[0]) if len(sel) else 1


#: Significant digits of a data set's numbers that its signature keeps (relative to each
#: column's largest magnitude): the last bits of derived curves (the Fourier left leg) differ
#: between CPUs and BLAS kernels, and a cache key must not.
SIGNATURE_DIGITS = 9


def _quantised(a) -> bytes:
    """Columns of ``a`` on a power-of-ten grid :data:`SIGNATURE_DIGITS` digits below the
    column's largest magnitude (int64 bytes; machine-independent)."""
    a = np.atleast_2d(np.asarray(a, float).T).T
    peak = np.nanmax(np.abs(np.where(np.isfinite(a), a, np.nan)), axis=0, initial=0.0)
    exponent = np.floor(np.log10(np.where(peak > 0, peak, 1.0))) - SIGNATURE_DIGITS
    q = np.where(np.isfinite(a), np.round(np.nan_to_num(a) / 10.0 ** exponent), -2**62)
    # the grid's exponents too: a column scaled by a power of ten keeps its integers
    return np.ascontiguousarray(exponent.astype(np.int64)).tobytes() + np.ascontiguousarray(q.astype(np.int64)).tobytes()


def signature(gait) -> str:
    """Hash of a GaitData's numbers (means, SDs, time, speed, events, left shift), each
    column to :data:`SIGNATURE_DIGITS` significant digits of its largest value."""
    h = hashlib.sha256(b"signature/2")
    for frame in (gait.mean, gait.sd):
        h.update(_quantised(frame.to_numpy(float)))
        h.update(",".join(map(str, frame.columns)).encode())
    h.update(_quantised(np.asarray(gait.time, float)))
    h.update(repr((round(float(gait.speed), 9), round(float(gait.cycle_time), 9), round(float(gait.left_shift), 9),
                   sorted((k, round(float(v), 9)) for k, v in gait.events.items()))).encode())
    return h.hexdigest()[:16]


def load_real(speed_class: str = "Free", source: str = "schwartz2008", fill_from: str | None = None) -> DataSet:
    """A committed data set (``data/``) as a :class:`DataSet`; ``fill_from`` completes
    quantities the problem needs from another source's same class (gaitutils has no GRFs)."""
    path = data_mod.DATA_DIR / f"{source}_curves.csv"
    df = data_mod.load_tidy(path)
    df = df[df["speed_class"] == speed_class]
    return _from_frame(df, label=f"{source} {speed_class}", like=source, fill_from=fill_from, path=str(path))


def read_data(path, like: str | None = None, speed_class: str | None = None,
              fill_from: str | None = None, allow_no_sd: bool = False, n_subjects: int | None = None) -> DataSet:
    """Read a tidy CSV (:data:`gaitlib.data.TIDY_COLUMNS`) into a :class:`DataSet`.

    Parameters
    ----------
    path : the CSV; validated by :func:`gaitlib.data.load_tidy` (form: columns, numbers,
        units) and, for the chosen class, by :func:`gaitlib.plausibility.check_tidy`
        (values: module docstring); errors name the file, quantity, row and expected range.
    like : base source for speed, cycle time and events (module docstring).
    speed_class : the class to use if the CSV has several (required then).
    fill_from : ``"schwartz2008"`` — quantities of :data:`REQUIRED_QUANTITIES` missing in
        the CSV are taken from that data set (same class) and excluded from the gap;
        without it a missing quantity is an error naming it.
    allow_no_sd : accept curves whose SD is 0 everywhere: tracked, but left out of the
        located gap (listed in the DataSet's notes).
    n_subjects : subjects behind the means (module docstring); needed unless the CSV has an
        ``n_subjects`` column or names a known source.
    """
    path = Path(path)
    df = data_mod.load_tidy(path)
    classes = sorted(set(df["speed_class"]), key=list(cv.SPEED_CLASSES).index)
    if speed_class is None:
        if len(classes) != 1:
            raise data_mod.DataError(f"{path}: column 'speed_class' has several classes {classes}; choose one with "
                                     "speed_class=... (CLI: --speed-class)")
        speed_class = classes[0]
    df = df[df["speed_class"] == speed_class]
    if df.empty:
        raise data_mod.DataError(f"{path}: no rows for speed class {speed_class!r}; the file has {classes}")
    no_sd = plausibility.check_tidy(df, path, allow_no_sd=allow_no_sd)
    notes = ()
    if no_sd:
        qs = sorted({c.split(" ")[0] for c in no_sd})
        notes = (f"tracked without SD (left out of the located gap): {', '.join(qs)}",)
    return _from_frame(df, label=path.name, like=like, fill_from=fill_from, path=str(path), notes=notes,
                       n_option=n_subjects)


def _from_frame(df: pd.DataFrame, label: str, like=None, fill_from=None, path=None, notes=(),
                n_option=None) -> DataSet:
    sources = sorted(set(df["source"]))
    if len(sources) != 1:
        raise data_mod.DataError(f"{path}: column 'source' has several values {sources}; one data set per file")
    speed_class = str(df["speed_class"].iloc[0])
    base = base_source_of(sources[0], like)
    n, n_source = subject_count(df, speed_class, n_option, path)
    df = df[list(data_mod.TIDY_COLUMNS)]
    have = set(df["quantity"])
    missing = [q for q in REQUIRED_QUANTITIES if q not in have]
    filled = ()
    if missing:
        if not fill_from:
            raise data_mod.DataError(
                f"{path}: missing quantity/quantities {missing} (column 'quantity'), needed by the gait problem; "
                "pass fill_from='schwartz2008' (CLI: --fill-from) to take them from another data set")
        other = data_mod.load_tidy(data_mod.DATA_DIR / f"{fill_from}_curves.csv")
        other = other[(other["speed_class"] == speed_class) & other["quantity"].isin(missing)]
        if other.empty:
            other = data_mod.load_tidy(data_mod.DATA_DIR / f"{fill_from}_curves.csv")
            other = other[(other["speed_class"] == "Free") & other["quantity"].isin(missing)]
        df = pd.concat([df, other], ignore_index=True)
        filled = tuple(missing)
    df = df.copy()
    df["source"] = base
    # both legs given (sides R and L) for a model quantity: R is read as the reference leg,
    # L replaces the generated left leg afterwards
    two = {q for q, g in df.groupby("quantity") if q in data_mod.MODEL_CHANNELS and {"R", "L"} <= set(g["side"])}
    left_rows = df[df["quantity"].isin(two) & (df["side"] == "L")]
    df = df[~(df["quantity"].isin(two) & (df["side"] == "L"))]
    df.loc[df["quantity"].isin(two) & (df["side"] == "R"), "side"] = "ipsilateral"
    tmp = Path(tempfile.mkdtemp(prefix="gaitlib-gap-"))
    try:
        df.to_csv(tmp / f"{base}_curves.csv", index=False)
        for f in _BASE_FILES[base]:
            shutil.copy(data_mod.DATA_DIR / f, tmp / f)
        # the file's own checks ran above, with the caller's allow_no_sd
        gait = data_mod.load_gait_data(speed_class, base, data_dir=tmp, allow_no_sd=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if two:
        gait = _with_left(gait, left_rows)
    notes = list(notes)
    if filled:
        notes.append(f"{', '.join(filled)} taken from {fill_from} ({speed_class}) and excluded from the gap")
    return DataSet(gait=gait, label=label, base=base, n=n, filled=filled, path=path, notes=tuple(notes),
                   n_source=n_source)


def _with_left(gait, rows: pd.DataFrame):
    """``gait`` with left-leg channels from tidy rows of side ``L`` (converted like the
    reference leg: :func:`gaitlib.data._convert`, model signs)."""
    import dataclasses

    mean, sd = gait.mean.copy(), gait.sd.copy()
    frac = np.asarray(gait.time, float) / float(gait.cycle_time)
    for q, g in rows.groupby("quantity"):
        stem, kind, sign_key = data_mod.MODEL_CHANNELS[q]
        col = f"{stem}_l"
        if col not in mean.columns:
            continue
        g = g.sort_values("percent_cycle")
        fr = g["percent_cycle"].to_numpy() / 100.0
        m = data_mod._convert(kind, g["mean"].to_numpy(), cv.DATA_SIGN[sign_key], gait.body_mass)
        s_ = np.abs(data_mod._convert(kind, g["sd"].to_numpy(), 1.0, gait.body_mass))
        mean[col] = np.interp(frac, fr, m)
        sd[col] = np.interp(frac, fr, s_)
    return dataclasses.replace(gait, mean=mean, sd=sd,
                               notes=tuple(gait.notes) + ("left leg measured (side L), not generated",))


def filled_channels(ds: DataSet) -> set:
    """Model channels (``tau_hip_r`` …) whose data were filled from another data set."""
    out = set()
    for q in ds.filled:
        if q in data_mod.MODEL_CHANNELS:
            stem = data_mod.MODEL_CHANNELS[q][0]
            out |= {f"{stem}_r", f"{stem}_l", stem}
    return out


def to_tidy(values: dict, sd: dict, source: str, speed_class: str, pct=None) -> pd.DataFrame:
    """Tidy rows from ``(quantity, side) → (51,) values`` and SDs on 0..100 % (step 2);
    side ``ipsilateral``, ``R`` or ``L``."""
    pct = np.linspace(0.0, 100.0, 51) if pct is None else np.asarray(pct, float)
    rows = []
    for (q, side), v in values.items():
        unit = data_mod.QUANTITY_UNITS[q]
        for p_, m_, s_ in zip(pct, np.asarray(v, float), np.asarray(sd[(q, side)], float)):
            rows.append((source, speed_class, q, side, float(p_), float(m_), float(abs(s_)), unit))
    return pd.DataFrame(rows, columns=list(data_mod.TIDY_COLUMNS))


def model_to_data_units(stem: str, values: np.ndarray, body_mass: float) -> np.ndarray:
    """Inverse of :func:`gaitlib.data._convert` for a model channel stem (``hip``,
    ``tau_knee``, ``grf_y`` …): model units and signs → the tidy quantity's units/signs."""
    q = MODEL_QUANTITIES[stem]
    _, kind, sign_key = data_mod.MODEL_CHANNELS[q]
    sign = cv.DATA_SIGN[sign_key]
    v = np.asarray(values, float)
    if kind == "deg":
        return np.rad2deg(v) / sign
    if kind in ("moment", "power"):
        return v / (sign * body_mass)
    if kind == "force":
        return v / (sign * body_mass * cv.G)
    raise ValueError(kind)
