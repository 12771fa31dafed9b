"""Validation of the gap diagnosis that is not circular: effects injected into *real* data by
manipulating the data file only (no gaitlib model or effect code), diagnosed as a user
would (:func:`gaitlib.gap.diagnose` on the manipulated CSV).

Two sets, each manipulation with its right answer stated here, in advance:

``independent``     manipulations that a library effect represents (a load scale like a body
                    mass error, a marker offset of one joint angle, a force-plate gain or
                    anterior–posterior bias); the right answer is that effect's name.
``out-of-library``  manipulations that no library effect represents (a changed knee range of
                    motion, a swing-phase hip bump, an ankle-moment gain alone, a larger
                    impact peak); the right answer is "unexplained".

Every manipulation acts on the tidy CSV in its own units (degrees, N·m/kg, W/kg, body
weights) and on the ipsilateral rows; the real data already carry a gap of their own (the
unedited data's diagnosis is run beside), so an injection is found on top of it, as in a
laboratory.

Draws. Each manipulation has three magnitude bands (small, middle, large; the
out-of-library set uses middle and large). The magnitudes (uniform within a band) and the
sign (for offsets and biases) are drawn from a generator seeded by the method's hash
(:meth:`gaitlib.gap.method.Method.hash`) and the manipulation's name: a change of method
redraws the validation. Scores: top-1 (named = expected) and the "unexplained" rate per set
and band, and the confusion matrix.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .. import data as data_mod
from . import diagnose
from . import io as gio
from . import locate
from .method import METHOD, Method

__all__ = ["Injection", "INJECTIONS", "SETS", "BANDS", "PLATE_THRESHOLD_BW", "draws", "inject", "run", "Validation"]

#: Vertical force (body weights) above which a foot counts as on the plate in the AP-bias
#: manipulation: 10 N for the Schwartz 2008 mean child (41.4 kg), a typical plate threshold.
PLATE_THRESHOLD_BW = 0.025
#: Band names, in order.
BANDS = ("small", "middle", "large")


def _rows(df, quantities):
    return df["quantity"].isin(quantities) & (df["side"] == "ipsilateral")


def _scale(quantities):
    def f(df, m):
        df = df.copy()
        r = _rows(df, quantities)
        df.loc[r, "mean"] = df.loc[r, "mean"] * (1.0 + m)
        return df

    return f


def _add(quantity):
    def f(df, c):
        df = df.copy()
        r = _rows(df, [quantity])
        df.loc[r, "mean"] = df.loc[r, "mean"] + c
        return df

    return f


def _ap_bias(df, b):
    """+b body weights on the anterior force where the vertical force is above
    :data:`PLATE_THRESHOLD_BW` (same speed class and percent of the cycle)."""
    df = df.copy()
    key = ["speed_class", "percent_cycle"]
    fy = df[_rows(df, ["grf_vertical"])].set_index(key)["mean"]
    r = _rows(df, ["grf_anterior"])
    on = df.loc[r, key].apply(tuple, axis=1).map(lambda k: float(fy.get(k, 0.0)) > PLATE_THRESHOLD_BW)
    df.loc[r, "mean"] = df.loc[r, "mean"] + b * on.astype(float)
    return df


def _rom(df, a):
    """Knee flexion's excursion about its cycle mean scaled by (1 + a) (a knee axis
    misaligned with the flexion axis: cross-talk that scales the range of motion)."""
    df = df.copy()
    for _, g in df[_rows(df, ["knee_flexion"])].groupby("speed_class"):
        y = g["mean"].to_numpy(float)
        df.loc[g.index, "mean"] = y.mean() + (1.0 + a) * (y - y.mean())
    return df


def _bump(quantity, centre, width, relative):
    """+ c · exp(−½((p − centre)/width)²) (``relative``: c times the mean curve)."""
    def f(df, c):
        df = df.copy()
        r = _rows(df, [quantity])
        p = df.loc[r, "percent_cycle"].to_numpy(float)
        w = np.exp(-0.5 * ((p - centre) / width) ** 2)
        y = df.loc[r, "mean"].to_numpy(float)
        df.loc[r, "mean"] = y + (c * y * w if relative else c * w)
        return df

    return f


@dataclass(frozen=True)
class Injection:
    """One manipulation of the tidy data: ``apply(frame, magnitude) → frame``; ``bands``:
    (low, high) of |magnitude| per band (None: not drawn); ``signed``: the sign is drawn
    too; ``expected``: the right answer (an effect name or "unexplained")."""

    name: str
    title: str
    unit: str
    apply: Callable
    bands: tuple
    expected: str
    set: str
    signed: bool = False


_LOADS = ("hip_extensor_moment", "knee_extensor_moment", "ankle_plantarflexor_moment", "hip_power", "knee_power",
          "ankle_power", "grf_anterior", "grf_vertical")

#: The manipulations by name.
INJECTIONS: dict[str, Injection] = {i.name: i for i in (
    Injection("load_scale", "loads × (1 + m): moments, powers and GRFs (a body mass error)", "1", _scale(_LOADS),
              ((0.04, 0.08), (0.08, 0.14), (0.14, 0.25)), "body_mass", "independent"),
    Injection("hip_offset", "hip flexion + c (marker placement)", "deg", _add("hip_flexion"),
              ((1.0, 2.0), (2.0, 4.0), (4.0, 8.0)), "hip_offset", "independent", signed=True),
    Injection("knee_offset", "knee flexion + c (marker placement)", "deg", _add("knee_flexion"),
              ((1.0, 2.0), (2.0, 4.0), (4.0, 8.0)), "knee_offset", "independent", signed=True),
    Injection("ankle_offset", "ankle dorsiflexion + c (marker placement)", "deg", _add("ankle_dorsiflexion"),
              ((1.0, 2.0), (2.0, 4.0), (4.0, 8.0)), "ankle_offset", "independent", signed=True),
    Injection("plate_gain", "GRFs × (1 + s) (force-plate calibration)", "1", _scale(("grf_anterior", "grf_vertical")),
              ((0.02, 0.04), (0.04, 0.08), (0.08, 0.15)), "grf_scale", "independent", signed=True),
    Injection("plate_ap_bias", f"anterior GRF + b where vertical > {PLATE_THRESHOLD_BW:g} BW (plate offset)", "BW",
              _ap_bias, ((0.005, 0.01), (0.01, 0.02), (0.02, 0.04)), "grf_ap_bias", "independent", signed=True),
    Injection("knee_rom", "knee flexion's excursion about its mean × (1 + a) (knee-axis cross-talk)", "1", _rom,
              (None, (0.08, 0.15), (0.15, 0.3)), "unexplained", "out-of-library"),
    Injection("hip_swing_bump", "hip flexion + c·exp(−½((p − 85)/6)²) (a swing-phase bump)", "deg",
              _bump("hip_flexion", 85.0, 6.0, False), (None, (3.0, 5.0), (5.0, 10.0)), "unexplained", "out-of-library"),
    Injection("ankle_moment_gain", "ankle moment and power × (1 + a) alone (an inverse-dynamics error)", "1",
              _scale(("ankle_plantarflexor_moment", "ankle_power")), (None, (0.08, 0.15), (0.15, 0.3)), "unexplained",
              "out-of-library"),
    Injection("impact_peak", "vertical GRF × (1 + a·exp(−½((p − 12)/4)²)) (a larger loading peak)", "1",
              _bump("grf_vertical", 12.0, 4.0, True), (None, (0.08, 0.15), (0.15, 0.3)), "unexplained",
              "out-of-library"),
)}
#: Sets of manipulations.
SETS = {s: tuple(n for n, i in INJECTIONS.items() if i.set == s) for s in ("independent", "out-of-library")}


def _seed(method_hash: str, name: str, draw: int) -> int:
    return int(hashlib.sha256(f"{method_hash}|{name}|{draw}".encode()).hexdigest()[:12], 16)


def draws(sets=("independent", "out-of-library"), per_band: int = 1, method: Method = METHOD) -> pd.DataFrame:
    """The validation's draws: one row per (manipulation, band, draw) with its magnitude and
    expected answer; magnitudes from generators seeded by ``method.hash()``."""
    h = method.hash()
    rows = []
    for s in sets:
        for n in SETS[s]:
            inj = INJECTIONS[n]
            for b, band in enumerate(inj.bands):
                if band is None:
                    continue
                for k in range(per_band):
                    rng = np.random.default_rng(_seed(h, n, b * 1000 + k))
                    m = float(rng.uniform(*band))
                    if inj.signed and rng.random() < 0.5:
                        m = -m
                    rows.append({"set": s, "injection": n, "band": BANDS[b], "draw": k, "magnitude": round(m, 6),
                                 "unit": inj.unit, "expected": inj.expected,
                                 "case": f"{n}_{BANDS[b]}_{k}"})
    return pd.DataFrame(rows)


def real_frame(speed_class: str = "Free", source: str = "schwartz2008") -> pd.DataFrame:
    """The committed tidy curves of one speed class (the data the manipulations act on)."""
    df = data_mod.load_tidy(data_mod.DATA_DIR / f"{source}_curves.csv")
    return df[df["speed_class"] == speed_class].reset_index(drop=True)


def inject(frame: pd.DataFrame, name: str, magnitude: float) -> pd.DataFrame:
    """``frame`` with manipulation ``name`` at ``magnitude`` (its unit: :attr:`Injection.unit`)."""
    if name not in INJECTIONS:
        raise ValueError(f"unknown injection {name!r}; known: {', '.join(INJECTIONS)}")
    return INJECTIONS[name].apply(frame, float(magnitude))


class Validation:
    """Results of :func:`run`: ``rows`` (one per case: expected, named, verdict, the top two
    ranked effects with their ΔBIC and % closed, correct; ``rss_added`` / ``added_pct``: how
    much worse the baseline fits after the manipulation — the RSS of its fit of the
    manipulated data minus that of its fit of the unedited data, absolute and as % of the
    latter: at most what the right effect can close, so how visible the injection is
    against the real data's own gap; ``rss_added_unrefit``: the same at the unedited data's
    fit, not re-fitted — what the manipulation adds before the baseline adapts to it),
    ``unedited`` (the diagnosis of the unedited data), ``settings`` (method, its hash,
    mesh)."""

    def __init__(self, rows: pd.DataFrame, unedited: dict, settings: dict):
        self.rows, self.unedited, self.settings = rows, unedited, settings

    def scores(self) -> pd.DataFrame:
        """Per set and band: cases, top-1 % (named = expected), "unexplained" %."""
        r = self.rows
        out = (r.groupby(["set", "band"], sort=False)
               .agg(cases=("correct", "size"), top1_pct=("correct", "mean"),
                    unexplained_pct=("named", lambda s: (s == "unexplained").mean()))
               .reset_index())
        out[["top1_pct", "unexplained_pct"]] *= 100.0
        return out

    def confusion(self) -> pd.DataFrame:
        """Expected answer × named effect counts."""
        return pd.crosstab(self.rows["expected"], self.rows["named"])

    def to_dict(self) -> dict:
        return {"settings": self.settings, "unedited": self.unedited,
                "rows": json.loads(self.rows.to_json(orient="records")),
                "scores": json.loads(self.scores().to_json(orient="records"))}

    def save(self, out) -> Path:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "validation.json").write_text(json.dumps(self.to_dict(), indent=1))
        self.rows.to_csv(out / "cases.csv", index=False, float_format="%.6g")
        self.scores().to_csv(out / "scores.csv", index=False, float_format="%.4g")
        self.confusion().to_csv(out / "confusion.csv")
        return out


def _top2(d: diagnose.Diagnosis) -> dict:
    r = d.ranking
    r = r[r["rank"].notna()] if not r.empty else r
    out = {}
    for i in range(2):
        if len(r) > i:
            out[f"rank{i + 1}"] = str(r.iloc[i]["effect"])
            out[f"rank{i + 1}_dBIC"] = float(r.iloc[i]["dBIC"])
            out[f"rank{i + 1}_pct"] = float(r.iloc[i]["pct_closed"])
        else:
            out[f"rank{i + 1}"], out[f"rank{i + 1}_dBIC"], out[f"rank{i + 1}_pct"] = None, np.nan, np.nan
    return out


def _summary(d: diagnose.Diagnosis, expected: str | None = None) -> dict:
    out = {"named": d.top_effect, "verdict": d.verdict, "rss_baseline": float(d.located.rss),
           "n_eff": float(d.located.n_eff), "contenders": list(d.settings.get("contenders", [])), **_top2(d)}
    if expected is not None and expected in set(d.ranking["effect"]):
        e = d.ranking.set_index("effect").loc[expected]
        out.update(expected_rank=(None if pd.isna(e["rank"]) else int(e["rank"])), expected_dBIC=float(e["dBIC"]),
                   expected_pct=float(e["pct_closed"]), expected_parameters=dict(e["parameters"] or {}))
    return out


def run(sets=("independent", "out-of-library"), *, per_band: int = 1, speed_class: str = "Free",
        base: dict | None = None, work_dir=None, resamples: int = 0, progress: bool = False,
        method: Method = METHOD, **diag_kw) -> Validation:
    """Diagnose every draw of :func:`draws` (and the unedited data) with
    :func:`gaitlib.gap.diagnose` — baseline ``base`` (default: the method's), all
    applicable library effects as candidates. The manipulated CSVs are written to
    ``work_dir`` (a temporary folder if None) and read back through
    :func:`gaitlib.gap.io.read_data`, as ``gaitlib gap --data`` reads a user's file."""
    import tempfile

    if method is not METHOD:
        raise ValueError("the diagnosis runs with gaitlib.gap.method.METHOD; validate that method")
    base = dict(method.base if base is None else base, speed_class=speed_class)
    table = draws(sets, per_band, method)
    frame = real_frame(speed_class)
    rows = []
    with tempfile.TemporaryDirectory() as td:
        wd = Path(work_dir) if work_dir is not None else Path(td)
        wd.mkdir(parents=True, exist_ok=True)
        p0 = wd / "unedited.csv"
        frame.to_csv(p0, index=False)
        d0 = diagnose.diagnose(gio.read_data(p0), base=base, resamples=resamples, **diag_kw)
        unedited = _summary(d0)
        for _, c in table.iterrows():
            p = wd / f"{c['case']}.csv"
            inject(frame, c["injection"], c["magnitude"]).to_csv(p, index=False)
            ds = gio.read_data(p)
            # the gap the manipulation adds at the unedited data's baseline fit (no re-fit)
            unrefit = locate.locate(d0.baseline, ds).rss - d0.located.rss
            try:
                d = diagnose.diagnose(ds, base=base, resamples=resamples, **diag_kw)
                s = _summary(d, c["expected"])
                added = s["rss_baseline"] - d0.located.rss
            except diagnose.BaselineFailed as exc:
                s = {"named": "baseline failed", "verdict": "baseline failed", "error": str(exc)}
                added = np.nan
            row = {**c.to_dict(), "rss_added": added, "added_pct": 100.0 * added / d0.located.rss,
                   "rss_added_unrefit": unrefit, **s}
            row["correct"] = row["named"] == c["expected"]
            rows.append(row)
            if progress:
                print(f"{c['case']}: {c['magnitude']:+g} {c['unit']} -> {row['named']} ({row['verdict']}), "
                      f"expected {c['expected']}", flush=True)
    settings = {"method": method.to_dict(), "method_hash": method.hash(), "base": base, "per_band": per_band,
                "sets": list(sets), "speed_class": speed_class}
    return Validation(pd.DataFrame(rows), unedited, settings)
