"""Why does no threshold name the load injections right? An experiment on Chapter 8's
relative validations of relative method revision 4 (issue 25), outside the frozen method.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_load_confusion.py   # reloads the validations' solves

Decided again at every threshold, the independent middle+large injections of revision 4's
two replicates reach at best 42 of 48 (``gaitlib.studies.gap.threshold_sweep``): the six
cases no threshold names right are all ``load_scale`` (loads × (1 + m): a normalising-mass
error, expected ``body_mass``) or ``plate_gain`` (GRFs × (1 + s), expected ``grf_scale``),
named the other one (``ranking_misses``). For every middle and large ``load_scale`` and
``plate_gain`` case of both replicates (regenerated as ``gaitlib gap-validate --relative``
made them, :func:`gaitlib.gap.validate.relative_case_sets`) the relative diagnosis is run
again without the null calibration (the ranking only; fits from the cache), and for the
baseline, ``body_mass`` and ``grf_scale`` the located relative RSS is split by channel kind
(angles, net joint torques, GRFs) — the torques being the only channels in which the two
manipulations differ — with each effect's identified change beside the injected one and
the GRF channel × phase cell each effect leaves largest.

Writes ``results/gap_validation/load_confusion.json`` and ``.md``.
"""

from __future__ import annotations

import dataclasses
import json
import sys

import numpy as np
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "load_confusion.json"

#: The stored validations re-diagnosed: relative method revision 4, replicates 0 and 1.
VALIDATIONS = ("relative_rev4", "relative_rev4_r1")
#: The manipulations of the load family and the bands looked at.
INJECTIONS = ("load_scale", "plate_gain")
BANDS = ("middle", "large")
#: The models compared.
MODELS = ("baseline", "body_mass", "grf_scale")
#: The swing phases of gaitlib.gap.locate.
SWING = ("ISw", "MSw", "TSw")


def by_kind(loc) -> dict:
    """A located gap's RSS split by channel kind, and its largest GRF channel × phase cell."""
    t = loc.table.assign(ss=loc.table["n"] * loc.table["rms_z"] ** 2)
    out = {k: float(v) for k, v in t.groupby("kind")["ss"].sum().items()}
    g = t[t["kind"] == "grf"].sort_values("ss", ascending=False)
    out["worst_grf_cell"] = f"{g.iloc[0]['channel']} {g.iloc[0]['phase']}" if len(g) else None
    out["worst_grf_cell_ss"] = float(g.iloc[0]["ss"]) if len(g) else None
    return out


def swing_load(sol, gait) -> dict:
    """Peak vertical GRF (N) each foot of a fit carries in its own swing (ISw–TSw of
    :mod:`gaitlib.gap.locate`; the data carry none there)."""
    from gaitlib.gap import locate

    sim = locate.sim_channels(sol, gait.source)
    tau = sim.index.to_numpy(float)
    out = {}
    for side in ("r", "l"):
        ph = locate.phase_of(tau, gait.events, float(gait.left_shift) if side == "l" else 0.0)
        sw = np.isin(ph, locate.PHASES[3:])
        out[side] = float(np.max(sim[f"grf_y_{side}"].to_numpy()[sw])) if sw.any() else float("nan")
    return out


def case_summary(d, c) -> dict:
    r = d.ranking.set_index("effect")
    row = {"case": str(c["case"]), "injection": str(c["injection"]), "band": str(c["band"]),
           "magnitude": float(c["magnitude"]), "expected": str(c["expected"]), "named_stored": str(c["named"]),
           "rank1_stored": str(c["rank1"]), "rank1": str(d.ranking.iloc[0]["effect"])}
    for m in MODELS:
        loc = d.located if m == "baseline" else d.fits[m].located
        x = by_kind(loc)
        sol = d.baseline if m == "baseline" else d.fits[m].solution
        x["swing_load_N"] = swing_load(sol, d.data.gait)
        t = loc.table.assign(ss=loc.table["n"] * loc.table["rms_z"] ** 2)
        g = t[t["kind"] == "grf"]
        x["grf_swing"] = float(g.loc[g["phase"].isin(SWING), "ss"].sum())
        if m != "baseline":
            x.update(dBIC=float(r.loc[m, "dBIC"]), rank=int(r.loc[m, "rank"]),
                     change=float(next(iter(r.loc[m, "parameter_change"].values()))))
        row[m] = x
    return row


def table(res: dict) -> str:
    lines = ["| case | injected | rank 1 | baseline RSS: angle / torque / GRF, peak swing load | body_mass: change, "
             "ΔBIC, angle / torque / GRF (in swing), worst GRF cell, peak swing load | grf_scale: the same |",
             "|---|---|---|---|---|---|"]
    for c in res["cases"]:
        b = c["baseline"]
        cells = [f"{b['angle']:.1f} / {b['torque']:.1f} / {b['grf']:.1f}, swing load R/L "
                 f"{b['swing_load_N']['r']:.0f}/{b['swing_load_N']['l']:.0f} N"]
        for m in ("body_mass", "grf_scale"):
            x = c[m]
            cells.append(f"{x['change']:+.3f}, {x['dBIC']:.0f}, {x['angle']:.1f} / {x['torque']:.1f} / {x['grf']:.1f} "
                         f"({x['grf_swing']:.1f} in swing), {x['worst_grf_cell']} {x['worst_grf_cell_ss']:.1f}, swing "
                         f"load R/L {x['swing_load_N']['r']:.0f}/{x['swing_load_N']['l']:.0f} N")
        lines.append(f"| {c['case']} ({c['validation']}) | {c['magnitude']:+.3f} | {c['rank1']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> int:
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import validate as V
    from gaitlib.studies import gap as gap_study

    rel0 = D.RELATIVE
    res = {"method_hash": V.METHOD.hash(), "validations": {}, "cases": []}
    try:
        # revision 4's relative method, the ranking only (no null calibration)
        D.RELATIVE = dataclasses.replace(rel0, null_draws=0, revision=4)
        for name in VALIDATIONS:
            val = gap_study.superseded_validation(name)
            res["validations"][name] = val.settings["relative_method_hash"]
            r = val.rows
            cases = list(r.loc[r["injection"].isin(INJECTIONS) & r["band"].isin(BANDS), "case"])
            with tempfile.TemporaryDirectory() as td:
                ref, sets = V.relative_case_sets(val, td, cases)
                for c, ds in sets:
                    d = D.diagnose(ds, base=val.settings["base"], resamples=0, reference=ref, serial=True)
                    row = {"validation": name, **case_summary(d, c)}
                    res["cases"].append(row)
                    print(json.dumps(row), flush=True)
    finally:
        D.RELATIVE = rel0
    OUT.write_text(json.dumps(res, indent=1))
    OUT.with_suffix(".md").write_text(
        "# The load family's rankings (relative method revision 4, both replicates)\n\n"
        "Each middle/large `load_scale` and `plate_gain` case diagnosed again (ranking only, no null calibration); "
        "located relative RSS by channel kind for the baseline and the two load effects, each effect's identified "
        "change (R → N) and ΔBIC, the GRF channel × phase cell it leaves largest, the GRF RSS in swing phases, and the "
        "peak vertical GRF each foot of the data fit carries in its own swing (N; the data carry none).\n\n" + table(res) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
