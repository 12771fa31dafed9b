"""The replication report card: one row per headline number of the thesis, ours beside it.

:func:`build` reads the stored solutions the book uses (never solves: a solution that is not
stored gives a "not comparable" row) and returns a DataFrame with the columns :data:`COLUMNS`:

``chapter``   thesis chapter (3–7)
``item``      what is compared, with the thesis's table / figure / section
``thesis``    the thesis's value (its labelled constant in the study modules) or claim
``ours``      computed here from the stored solution (a number, or a text for a claim)
``unit``      SI-ish display unit of both (deg, N*m, N, cm, J/kg/m, %, 1 …)
``verdict``   :func:`verdict` (the rule below, stated once)
``cause``     a one-line measured reason with the book page/section that measures it,
              ``"unknown"``, or empty for a reproduced row, qualitatively reproduced
              included (it needs none)
``solution``  the stored solution (cache kind/key and what it is)
``valid``     its physical validity gates (:func:`gaitlib.validity.check`): ``"valid"``,
              ``"not converged (…)"`` and/or ``"invalid: …"``
``gap``       tracking rows (Ch 5): the located gap of that channel (:func:`gaitlib.gap.locate`,
              Ch 8's first step) — its RMS z against the data's SD, whether it is significant,
              and its largest gait phase — and the diagnosis's verdict on that solution where
              one was run (NMSK: Ch 8's muscle-level attribution); empty elsewhere

Verdict rule (:func:`verdict`)
------------------------------
1. ``not comparable`` — ours is missing (no stored solution, NaN) or the thesis gives no value.
2. ``invalid`` — the solution failed a validity gate or did not converge: such a row never
   counts as reproduced, whatever its number.
3. A claim (ordering, sign, "converges"): ``qualitatively reproduced`` if it holds on ours,
   else ``not reproduced``.
4. A number: ``reproduced`` if |ours − thesis| ≤ max(:data:`REL_TOL` × |thesis|,
   :data:`ABS_TOL` [unit]); else ``within data SD`` if the data give a standard deviation
   for that quantity (tracking RMSEs: the RMS over the cycle of the data's between-subject
   SD of the channel) and |ours − thesis| ≤ SD; else ``not reproduced``.

Thesis values are on other data (Bovi 2011; ours Schwartz et al. 2008), so even a perfect
replication need not reproduce a tracking error; the card says how far each number is, not
why — the ``cause`` column does that where a page of the book has measured it.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from .. import cache
from .. import conventions as cv
from .. import data as data_mod
from .. import ocp
from ..problems import gait as gait_ocp
from .. import validity
from . import jump
from ..model import ELLIPSOID_LABELS, ChildModel
from . import contact_id as ci
from .. import mtg
from . import gait as sg
from . import msk
from . import mtg_id
from .. import activation
from . import predictive as pr
from . import fidelity
from . import ch6_claims
from .. import marks as marks_mod
from ..gap import io as gap_io
from ..gap import locate as gap_locate
from . import gap as gap_study

__all__ = ["COLUMNS", "VERDICTS", "REL_TOL", "ABS_TOL", "RULE", "verdict", "Row", "StoredGait", "stored_gait",
           "gate", "build", "counts", "write", "PHYSIOLOGICAL_JUMP_RISE_M"]

COLUMNS = ("chapter", "item", "thesis", "ours", "unit", "verdict", "cause", "solution", "valid", "gap")
VERDICTS = ("reproduced", "within data SD", "qualitatively reproduced", "not reproduced", "not comparable",
            "invalid")
#: Relative tolerance of "reproduced": 10 % of the thesis's value.
REL_TOL = 0.10
#: Absolute tolerance of "reproduced" per unit (the resolution below which a difference is
#: not meaningful for the quantity): joint angles 1° (marker-based sagittal kinematics),
#: torques 1 N·m, forces 2 N, heights 2 cm, COT 0.1 J kg⁻¹ m⁻¹, percentages 5 points,
#: masses 0.5 kg; dimensionless parameters, time ratios and hours: relative only.
ABS_TOL = {"deg": 1.0, "N*m": 1.0, "N": 2.0, "cm": 2.0, "J/kg/m": 0.1, "%": 5.0, "kg": 0.5, "s": 0.001}
#: The rule in one sentence (for the book page).
RULE = ("reproduced: |ours − thesis| ≤ max(10 % of the thesis's value, the unit's resolution: "
        + ", ".join(f"{v:g} {u}" for u, v in ABS_TOL.items())
        + "); within data SD: |ours − thesis| ≤ the data's SD of the quantity (tracking RMSEs: RMS of the "
          "channel's between-subject SD over the cycle); qualitatively reproduced: the thesis's claim "
          "(ordering, sign, convergence) holds on ours; not reproduced: otherwise; not comparable: ours "
          "missing or another quantity; invalid: the solution failed a validity gate or did not converge "
          "(never counted as reproduced)")

#: Flight COM rise of human standing vertical jumps, m (:data:`gaitlib.studies.jump.HUMAN_JUMP_RISE_M`):
#: the thesis-bounds jumps of Ch 3 are compared with it in the ``cause`` column.
PHYSIOLOGICAL_JUMP_RISE_M = jump.HUMAN_JUMP_RISE_M

_BOOK = "book/"
#: A foot's load in the data's swing is given as the cause of a vertical-GRF miss when it
#: makes at least this share (%) of the foot's squared error.
SWING_SHARE = 20.0  # causes point at the book's pages: <page>#<section anchor>


def verdict(thesis, ours, *, unit: str = "", sd: float | None = None, holds: bool | None = None,
            valid: str = "valid") -> str:
    """The card's verdict for one row (module docstring, "Verdict rule").

    ``thesis``/``ours``: numbers (same ``unit``), or anything for a claim row, whose outcome
    is ``holds`` (True/False; None: not evaluated). ``sd``: the data's SD of the quantity
    (same unit) or None. ``valid``: the solution's gate text; ``"invalid…"`` or
    ``"not converged…"`` make the row ``invalid``."""
    if _missing(ours) or _missing(thesis) or (holds is None and not _numeric(thesis, ours)):
        return "not comparable"
    if _blocked(valid):
        return "invalid"
    if holds is not None:
        return "qualitatively reproduced" if holds else "not reproduced"
    d = abs(float(ours) - float(thesis))
    if d <= max(REL_TOL * abs(float(thesis)), ABS_TOL.get(unit, 0.0)):
        return "reproduced"
    if sd is not None and np.isfinite(sd) and d <= float(sd):
        return "within data SD"
    return "not reproduced"


def _missing(v) -> bool:
    return v is None or (isinstance(v, (float, np.floating)) and not np.isfinite(v)) or (isinstance(v, str) and not v)


def _numeric(*vs) -> bool:
    return all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) for v in vs)


def _blocked(valid: str) -> bool:
    v = str(valid)
    return v.startswith("invalid") or v.startswith("not converged") or "; invalid" in v


@dataclass
class Row:
    """One card row before its verdict (:func:`verdict` is applied by :meth:`record`)."""

    chapter: int
    item: str
    thesis: object
    ours: object
    unit: str = ""
    cause: str = "unknown"
    solution: str = ""
    valid: str = ""
    sd: float | None = None
    holds: bool | None = None
    gap: str = ""

    def record(self) -> dict:
        v = verdict(self.thesis, self.ours, unit=self.unit, sd=self.sd, holds=self.holds, valid=self.valid)
        cause = self.cause
        if v == "invalid":
            alone = verdict(self.thesis, self.ours, unit=self.unit, sd=self.sd, holds=self.holds)
            cause = f"{'gates fail (valid column)' if cause in ('unknown', '') else cause}; the number alone: {alone}"
        if _missing(self.ours) and cause == "unknown":
            cause = "no stored solution"
        if v in ("reproduced", "within data SD", "qualitatively reproduced") and cause == "unknown":
            cause = ""  # a reproduced row needs no cause
        def g6(x):  # 6 significant digits for numbers (text kept)
            return float(f"{float(x):.6g}") if _numeric(x) else x

        return {"chapter": self.chapter, "item": self.item, "thesis": g6(self.thesis), "ours": g6(self.ours),
                "unit": self.unit,
                "verdict": v, "cause": cause, "solution": self.solution, "valid": self.valid, "gap": self.gap}


def _anchor(page: str, heading: str) -> str:
    """``book/<page>#<section id>`` of a heading (the ids the book's HTML gives its sections)."""
    slug = re.sub(r"[^a-z0-9]+", "-", heading.lower().encode("ascii", "ignore").decode()).strip("-")
    return f"{_BOOK}{page}#{slug}"


# ======================================================================================
# Stored solutions, read without rebuilding their NLP
# ======================================================================================
_FRAMES = ("q", "qd", "torques", "torques_active", "residuals", "grf", "ellipsoids", "activations", "excitations",
           "muscle_activations", "metabolic")


class StoredGait:
    """A stored gait solution read from its entry (``spec.json``, ``summary.json``, the frames
    and the raw ``ocp/`` solution) without rebuilding the NLP: the attributes of
    :class:`gaitlib.problems.gait.GaitSolution` the card and the gates read (``spec``,
    ``stats``, ``solution``, ``q``, ``torques``, ``grf``, ``rmse`` …; frames absent from the
    entry are None). ``path``: the entry."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.spec = gait_ocp.GaitSpec.from_dict(json.loads((self.path / "spec.json").read_text()))
        summary = json.loads((self.path / "summary.json").read_text())
        self.stats = summary["stats"]
        self.solution = ocp.Solution.load(self.path / "ocp")
        for name in _FRAMES:
            f = self.path / f"{name}.csv"
            setattr(self, name, pd.read_csv(f, index_col=0) if f.is_file() else None)
        self.rmse = pd.read_csv(self.path / "rmse.csv")
        self._add_slip()

    def _add_slip(self) -> None:
        """Entries stored before the foot-slip gate have no ``vs_`` (slip velocity) columns:
        computed from the stored q and q̇ with the spec's contact parameters (the identified
        ones when the contact was free). Left out for specs with effects (they may change
        the contact parameters)."""
        e, q, qd = self.ellipsoids, self.q, self.qd
        if e is None or q is None or qd is None or any(c.startswith("vs_") for c in e.columns) or self.spec.effects:
            return
        pc = gait_ocp.solved_contact_params(self)
        vs = gait_ocp.slip_velocities(gait_ocp.spec_model(self.spec), q[list(cv.COORDS)].to_numpy(), qd[list(cv.COORDS)].to_numpy(), pc)
        self.ellipsoids = e.assign(**{f"vs_{lab}": vs[i] for i, lab in enumerate(ELLIPSOID_LABELS)})

    @property
    def success(self) -> bool:
        return bool(self.stats["success"])

    @property
    def name(self) -> str:
        s = self.spec
        return f"{self.path.parent.name}/{self.path.name} ({s.model} {s.cost} {s.speed_class})"


def stored_gait(where) -> StoredGait | None:
    """The gait solution stored at a :func:`gaitlib.cache.lookup` directory (or the same entry
    in the repository's store) as a :class:`StoredGait`; None if absent."""
    found = cache.find(where, "spec.json", to_solve=False)
    return StoredGait(found) if found is not None else None


def gate(sol, name: str = "") -> str:
    """The validity text of a solution: ``"valid"``, or :meth:`gaitlib.validity.Gates.label`
    (``"not converged (…)"``, ``"invalid: …"``)."""
    return validity.label(sol, name=name)


def _rms_sd(gait, col: str, scale: float = 1.0) -> float:
    """RMS over the cycle of the data's SD of a channel (× ``scale``)."""
    return float(np.sqrt(np.mean(gait.sd[col].to_numpy(float) ** 2))) * scale


def _hours(st: dict) -> float:
    return (float(st.get("solve_time_s", np.nan)) + float(st.get("build_time_s", np.nan))) / 3600


# ======================================================================================
# Chapter 3: jumps
# ======================================================================================
def _ch3() -> list[Row]:
    rows, sols, valid = [], {}, {}
    for n in jump.THESIS:
        sp = jump.SPECS[n]
        if cache.find(jump.cache_location(sp), "solution.json", to_solve=False) is not None:
            sols[n] = jump.solve(sp, use_cache=True)
            valid[n] = gate(sols[n], n)
    lo, hi = PHYSIOLOGICAL_JUMP_RISE_M
    why = _anchor("ch03_jump", "What we found")
    strong, strong_valid = {}, {}
    for n, sp in jump.strength_specs().items():
        if cache.find(jump.cache_location(sp), "solution.json", to_solve=False) is not None:
            strong[n] = jump.solve(sp, use_cache=True)
            strong_valid[n] = gate(strong[n], f"{n}, strength-limited")
    where_strong = _anchor("ch03_jump", "The physiological jump: joint torques limited by strength")
    retries = {}  # the other procedures of a strength-limited jump that did not converge (stored ones)
    for n, s in strong.items():
        if not s.success:
            specs = {r: sp for r in jump.STRENGTH_RETRIES if (sp := jump.retry_spec(s.spec, r)) is not None}
            got = {c: jump.solve(sp, use_cache=True) for c, sp in specs.items()
                   if cache.find(jump.cache_location(sp), "solution.json", to_solve=False) is not None}
            if len(got) == len(specs):
                retries[n] = got
    stand_ins = jump.strength_stand_ins(strong, retries, lambda x: not _blocked(gate(x, x.spec.name)))
    own = dict(strong)  # each jump's own procedure; ``strong`` from here on: its stand-in where it has one
    strong = {**strong, **stand_ins}
    strong_valid.update({n: gate(x, f"{n}, strength-limited") for n, x in stand_ins.items()})
    for n, th in jump.THESIS.items():
        s = sols.get(n)
        sol_name = f"jump/{cache.find(jump.cache_location(jump.SPECS[n]), 'solution.json', to_solve=False).name} ({n})" if s else ""
        lab = jump.LABELS[n]
        if s is not None:
            rise = s.jump_height["com_rise_flight"]
            peak = max(s.trajectory[f"tau_{j}"].abs().max() for j in s.model.joints)
            state = ("NOT converged" if n in strong and not strong[n].success else "converged" if n not in stand_ins
                     else f"its own procedure did not converge; {jump.retry_label(strong[n])} did")
            phys = (f"the strength-limited version: COM rise {100 * strong[n].jump_height['com_rise_flight']:.0f} cm "
                    f"({state}) [{where_strong}]" if n in strong
                    else "the strength-limited version is not stored")
            cause = (f"thesis-bounds formulation (Table 3.5 torques to 4000 N·m): COM rise in flight {100 * rise:.0f} cm, "
                     f"{'outside' if not lo <= rise <= hi else 'inside'} the {100 * lo:.0f}–{100 * hi:.0f} cm of human "
                     f"standing jumps, peak torque {peak:.0f} N·m — not a human jump; {phys} [{why}]")
            knee = float(s.trajectory["knee"].min() / cv.DEG)
            mu = float(s.required_friction)
        else:
            rise = knee = mu = np.nan
            cause = "unknown"
        v = valid.get(n, "")
        rows += [Row(3, f"{lab}: jump height (Sec 3.4.4; ours: COM rise in flight)", th["jump_height_cm"],
                     100 * rise, "cm", cause, sol_name, v),
                 Row(3, f"{lab}: required static friction μ_s (Sec 3.4.3, Fig 3.7)", th["mu_s"], mu, "1", cause,
                     sol_name, v),
                 Row(3, f"{lab}: most flexed knee (Sec 3.4.1, Fig 3.3)", th["knee_min_deg"], knee, "deg", cause,
                     sol_name, v)]
    if len(sols) == len(jump.THESIS):
        rise = {n: s.jump_height["com_rise_flight"] for n, s in sols.items()}
        order = sorted(rise, key=rise.get)
        v = _joint(valid)
        rows.append(Row(3, "jump height order toeless < toe < ellipsoid (Sec 3.4.4)", "toeless < toe < ellipsoid",
                        " < ".join(order), "", f"COM rises {', '.join(f'{n} {100 * r:.0f} cm' for n, r in rise.items())} "
                        f"[{why}]", "jump (3 solutions)", v, holds=order == ["toeless", "toe", "ellipsoid"]))
        mu = {n: s.required_friction for n, s in sols.items()}
        rows.append(Row(3, "ellipsoid contact needs less friction than either welded foot (Sec 3.4.3)",
                        "μ_s ellipsoid < toeless, toe", ", ".join(f"{n} {m:.2f}" for n, m in mu.items()), "",
                        "thesis-bounds formulation (Table 3.5 torques to 4000 N·m): peak joint torques beyond the "
                        f"body's strength (valid column), COM rises {', '.join(f'{n} {100 * r:.0f} cm' for n, r in rise.items())}"
                        f" — not human jumps [{why}]", "jump (3 solutions)", v,
                        holds=mu["ellipsoid"] < min(mu["toeless"], mu["toe"])))
    retry_text = {n: re.sub(r"\*\*[^*]*\*\* — ", "", t) for n, t in
                  zip(retries, jump.strength_retry_findings(own, retries))}
    apex = {}  # each jump read with Table 3.9's take-off term scaled down (stored ones)
    for n, s in strong.items():
        sp = jump.apex_cost_spec(s.spec)
        if cache.find(jump.cache_location(sp), "solution.json", to_solve=False) is not None:
            apex[n] = jump.solve(sp, use_cache=True)
    where_cost = _anchor("ch03_jump", "Why the strength-limited jumps leave the ground crouched: the cost")
    apex_ok = {n: a for n, a in apex.items() if not _blocked(gate(a, n))}
    apex_order = ("; the apex above the standing COM with Table 3.9's take-off velocity term × "
                  f"{jump.TAKEOFF_FACTOR:g}: " + ", ".join(f"{n} {100 * jump.takeoff_state(a)['apex']:.0f} cm"
                                                           for n, a in apex_ok.items()) + f" [{where_cost}]"
                  if len(apex_ok) == len(jump.THESIS) else "")
    takeoff = {n: f"; {jump.takeoff_clause(s, apex.get(n), n in apex_ok)} [{where_cost}]"
               for n, s in strong.items()}
    for n, s in strong.items():
        rise = s.jump_height["com_rise_flight"]
        name = f"jump/{cache.find(jump.cache_location(s.spec), 'solution.json', to_solve=False).name} ({n}, strength-limited)"
        stand = (f"its own procedure: {own[n].status} after {own[n].stats['iterations']} iterations; read through "
                 f"its stand-in, {jump.retry_label(s)}; " if n in stand_ins else "")
        rows.append(Row(3, f"{jump.LABELS[n]}, torques within the body's strength (ours): jump height (Sec 3.4.4; "
                           "ours: COM rise in flight)", jump.THESIS[n]["jump_height_cm"], 100 * rise, "cm",
                        stand + f"the MTG strength envelope (Eq 5.8, Eq 5.21): COM rise {100 * rise:.0f} cm, "
                        f"{'inside' if lo <= rise <= hi else 'outside'} the {100 * lo:.0f}–{100 * hi:.0f} cm of human "
                        f"standing jumps" + (f"; {retry_text[n]}" if n in retry_text else "") + f" [{where_strong}]"
                        + takeoff[n],
                        name, strong_valid[n]))
    if len(strong) == len(jump.THESIS):
        rise = {n: s.jump_height["com_rise_flight"] for n, s in strong.items()}
        order = sorted(rise, key=rise.get)
        rows.append(Row(3, "jump height order toeless < toe < ellipsoid, torques within the body's strength (Sec 3.4.4)",
                        "toeless < toe < ellipsoid", " < ".join(order), "",
                        f"COM rises {', '.join(f'{n} {100 * r:.0f} cm' for n, r in rise.items())}"
                        + "".join(f"; {n}: its stand-in, {jump.retry_label(x)}" for n, x in stand_ins.items())
                        + f" [{where_strong}]" + apex_order, "jump (3 strength-limited solutions)", _joint(strong_valid),
                        holds=order == ["toeless", "toe", "ellipsoid"]))
    return rows


# ======================================================================================
# Chapter 4: contact identification
# ======================================================================================
def _ch4() -> list[Row]:
    res = {}
    try:
        with cache.only("the card reads stored solutions only"):
            res["a"] = ci.trajectory_optimization()
            res["b"] = ci.optimal_control_multistart()
            res["c"] = ci.optimal_control_body(warm=res["b"])
    except cache.NotCached:
        pass
    names, valid = {}, {}
    for k, r in res.items():
        if r.solution is not None:
            names[k] = f"{r.solution.spec.model} {r.solution.spec.cost} ({ci.APPROACHES[k]})"
        else:
            names[k] = f"contact_id {ci.APPROACHES[k]}, {r.stats['n_local']} local solves"
        valid[k] = gate(r, k)
    table = ci.rmse_table(res) if res else pd.DataFrame(columns=["approach", "quantity", "side", "unit", "ours"])
    gait = data_mod.load_gait_data("Free")
    ph = ci.grf_error_by_phase(res) if res else None
    where = _anchor("ch04_contact", "Why the GRF fits differ from the thesis's: where the error is")
    jerk = _jerk_causes("SK")
    a_cause = _ch4_a_cause(table) if "a" in res else ""
    cabl = _ch4c_ablation_causes(res.get("b"))
    fric = _ch4_friction_causes() if {"b", "c"} <= set(res) else {}
    rows = []
    for k, th in ci.THESIS_RMSE.items():
        if k == "c_wide":
            continue
        for (qty, side), tv in th.items():
            m = table[(table["approach"] == k) & (table["quantity"] == qty) & (table["side"] == side)]
            ours = float(m["ours"].iloc[0]) if len(m) else np.nan
            unit = "N*m" if qty.startswith("tau") or qty == "R_z" else "N"
            col = qty if qty.startswith("R_") else f"{qty}_{side}"
            sd = _rms_sd(gait, col) if col in gait.sd.columns else None
            cause = "unknown"
            foot = {"r": "right", "l": "left"}.get(side)
            p = ph.loc[(ci.APPROACHES[k], foot)] if ph is not None and k in res and foot else None
            if qty == "grf_y" and p is not None and p["share of squared error in swing (%)"] >= SWING_SHARE:
                cause = (f"the {foot} foot carries {p['mean simulated force in swing (N)']:.0f} N in the data's swing: "
                         f"{p['share of squared error in swing (%)']:.0f} % of its squared error [{where}]")
            jk = ("torque", qty[4:], side) if qty.startswith("tau_") else ("grf", qty[4:], side)
            if cause == "unknown" and k == "c" and (qty, side) in cabl:
                cause = cabl[(qty, side)]
            if cause == "unknown" and k != "a" and jk in jerk:  # (a) has no Jrk term (trajectory optimisation)
                cause = jerk[jk]
            if cause == "unknown" and k == "a" and a_cause:
                cause = a_cause
            if k in fric and qty.startswith("grf"):
                cause = fric[k] if cause == "unknown" else f"{cause}; {fric[k]}"
            item = f"({k}) RMSE {qty}{' ' + side.upper() if side else ''} ({ci.THESIS_RMSE_SOURCE[k]})"
            rows.append(Row(4, item, tv, ours, unit, cause, names.get(k, ""), valid.get(k, ""), sd=sd))
    if {"a", "b", "c"} <= set(res):
        fit = ci.grf_fit(res)["mean GRF RMSE (N)"]
        m = {k: float(fit[ci.APPROACHES[k]]) for k in res}
        v = _joint({f"({k})": valid[k] for k in res})
        sw = ph.loc[ci.APPROACHES["c"]]["mean simulated force in swing (N)"]
        rows.append(Row(4, "GRF fit ranking (c) < (b) < (a) (Sec 4.4.2, Sec 4.5)", "(c) < (b) < (a)",
                        ", ".join(f"({k}) {v_:.1f} N" for k, v_ in m.items()) + " mean GRF RMSE", "",
                        f"(c)'s feet carry {sw['right']:.0f} N (right) and {sw['left']:.0f} N (left) in the data's "
                        f"swing [{where}]", "contact_id (a), (b), (c)", v,
                        holds=m["c"] < m["b"] < m["a"]))
        masses = [i for i, n in enumerate(ci.P_BODY_NAMES) if n.startswith("mass_")]
        th_mass = _total_mass(ChildModel().p_body_identified(), masses, ci.P_BODY_NAMES)
        rows.append(Row(4, "(c) total identified mass (Sec 4.4.2; Table 4.15 tuned, both legs)", round(th_mass, 2),
                        _total_mass(res["c"].p_body, masses, ci.P_BODY_NAMES), "kg", "unknown", names["c"],
                        valid["c"]))
    return rows


#: The Ch 4 page's section of the friction lower bound (the card links to it).
CH4_FRICTION_HEADING = "Do the identified feet stand still? (b) and (c) with a friction lower bound"


def _stored(study):
    """``study()`` from stored solutions only (:func:`gaitlib.cache.only`), or None when one
    it needs is not stored."""
    try:
        with cache.only("the card reads stored solutions only"):
            return study()
    except cache.NotCached:
        return None


def _ch4_friction_causes() -> dict:
    """"b"/"c" → what identifying with every μ ≥ the friction floor measured
    (:func:`gaitlib.studies.contact_id.friction_identification`, the floor alone): the book's
    foot slip and mean GRF RMSE beside the bounded run's, and how deep each sinks; with how
    fast the tracking reference's own feet slide (:func:`gaitlib.studies.gait.reference_slip`).
    Empty when not stored; "not compared" when either run is not converged or not valid."""
    runs = _stored(ci.friction_identification)
    if runs is None:
        return {}
    t = ci.friction_table(runs)
    where = _anchor("ch04_contact", CH4_FRICTION_HEADING)
    f = fidelity.FRICTION_FLOOR
    ref = sg.reference_slip(replace(ci.spec_c(), contact_params="ch4"))
    local = bool(ci.friction_starts_findings(runs))
    legs = _ch4_leg_clauses()
    out = {}
    for k in ("b", "c"):
        r0, r1 = t.loc[ci.APPROACHES[k]], t.loc[ci.friction_label(k, f)]
        usable = all(r["status"] in validity.CONVERGED_STATUSES and r["gates"] == "valid" for r in (r0, r1))
        if not usable:
            out[k] = f"({k}) with every μ ≥ {f:g}: not compared ({r1['status']}, {r1['gates']}) [{where}]"
            continue
        out[k] = (f"its feet slide {r0[sg.SLIP_COLUMN]:.2f} m/s under load (ball μ_d {r0['ball mu_d']:.3f}; the "
                  f"tracking reference's own feet slide {ref['slip']:.2f} m/s); identified with every μ ≥ {f:g} they "
                  f"{'stand' if r1[sg.SLIP_COLUMN] <= fidelity.SLIP_V else 'still slide'} "
                  f"({r1[sg.SLIP_COLUMN]:.2f} m/s) but sink {r1['deepest sink (mm)']:.0f} mm (vs "
                  f"{r0['deepest sink (mm)']:.0f}) and the mean GRF RMSE goes {r0['mean GRF RMSE (N)']:.1f} → "
                  f"{r1['mean GRF RMSE (N)']:.1f} N")
        sk = ci.friction_label(k, f, ci.SINK_LIMIT)
        if sk in t.index and t.loc[sk, "status"] in validity.CONVERGED_STATUSES and t.loc[sk, "gates"] == "valid":
            out[k] += (f"; sinking ≤ {1e3 * ci.SINK_LIMIT:g} mm as well, {t.loc[sk, 'mean GRF RMSE (N)']:.1f} N"
                       + (" (from a (b) multistart that stops in a local optimum: an upper bound)" if local else ""))
        out[k] += legs.get(k, "") + f" [{where}]"
    return out


def _ch4_leg_clauses() -> dict:
    """"b"/"c" → "; identified on thigh and shank × s …": the approach identified on longer
    legs (:func:`gaitlib.studies.contact_id.leg_identification`) — the reference's slip there,
    the identified feet's slip and sink, the ball's μ_d and the mean GRF RMSE; empty when not
    stored."""
    runs = _stored(ci.leg_identification)
    if runs is None:
        return {}
    t = ci.friction_table(runs)
    s = sg.LEG_SCALE
    ref = sg.reference_slip(replace(ci.spec_c(), contact_params="ch4", leg_scale=s))
    out = {}
    for k in ("b", "c"):
        r1 = t.loc[ci.leg_label(k, s)]
        if r1["status"] not in validity.CONVERGED_STATUSES or r1["gates"] != "valid":
            out[k] = f"; identified on thigh and shank ×{s:g}: not compared ({r1['status']}, {r1['gates']})"
            continue
        out[k] = (f"; identified on thigh and shank ×{s:g} (where the reference slides {ref['slip']:.2f} m/s) the "
                  f"feet slide {r1[sg.SLIP_COLUMN]:.2f} m/s and sink {r1['deepest sink (mm)']:.0f} mm, ball μ_d "
                  f"{r1['ball mu_d']:.3f}, mean GRF RMSE {r1['mean GRF RMSE (N)']:.1f} N")
    return out


#: The Ch 4 page's section of the (c) ablation (the card links to it).
CH4C_ABLATION_HEADING = "What (c)'s GRF error depends on: one change at a time"


def _ch4c_ablation_causes(b) -> dict:
    """(quantity, side) → the (c) ablation's answer for that GRF channel (:func:`gaitlib.
    studies.contact_id.c_ablation`: one change at a time on (c), warm-started from (b)): the
    lowest RMSE a converged, valid run reaches, which runs meet the target, and the floor the
    book's (c) kinematics put under the vertical error; empty when (b) or the ablation is not
    stored or the book's (c) is not usable."""
    if b is None:
        return {}
    try:
        with cache.only("the card reads stored solutions only"):
            table, _ = ci.c_ablation(b)
    except cache.NotCached:
        return {}
    ok = table[table["status"].isin(validity.CONVERGED_STATUSES) & (table["gates"] == "valid")]
    if ci.C_BASE_ROW not in ok.index or len(ok) < 2:
        return {}
    where = _anchor("ch04_contact", CH4C_ABLATION_HEADING)
    every = list(ok.index[ok["GRF targets met"]])
    every = f"; every GRF target at once: met by {', '.join(every) if every else 'no run'}"
    floor = float(ok.loc[ci.C_BASE_ROW, "vertical floor per foot (N)"])
    out = {}
    for q in ("grf_x", "grf_y"):
        for s in cv.SIDES:
            col = f"{q} {s.upper()} (N)"
            tgt = ci.C_TARGET_FACTOR * ci.THESIS_RMSE["c"][(q, s)]
            best = ok[col].idxmin()
            met = [k for k in ok.index if ok.loc[k, col] <= tgt]
            text = (f"(c) ablation ({len(ok) - 1} usable changes): lowest {ok.loc[best, col]:.2f} N ({best}), "
                    f"target {tgt:.2f} N met by: {', '.join(met) if met else 'none'}{every}")
            if q == "grf_y":
                text += f"; the book's (c) kinematics force at least {floor:.1f} N per foot (total-force mismatch)"
            out[(q, s)] = f"{text} [{where}]"
    return out


def _ch4_a_cause(table: pd.DataFrame) -> str:
    """Why approach (a) fails the residual gate by construction: its kinematics are the data's,
    so the pelvis residual loads carry all of the motion's dynamic inconsistency (nothing in
    Eq 4.5 bounds or weights them) — ours beside the thesis's own (a) (Table 4.9, a labelled
    reference) against the gate's residual-force threshold (:mod:`gaitlib.validity`)."""
    m = table[(table["approach"] == "a") & (table["quantity"] == "R_y")]
    if not len(m):
        return ""
    th = ci.THESIS_RMSE["a"].get(("R_y", ""))
    ours = float(m["ours"].iloc[0])
    return (f"(a) fixes the kinematics to the data, and Eq 4.5 neither bounds nor weights the pelvis residuals: "
            f"they carry all of the motion's dynamic inconsistency (R_y RMSE ours {ours:.0f} N"
            + (f", the thesis's (a) {th:.0f} N (Table 4.9)" if th is not None else "")
            + f") [{_anchor('ch04_contact', 'Residual loads on the pelvis (Fig 4.13)')}]")


def _total_mass(p, idx, names) -> float:
    """Whole-body mass (kg) from the body parameters: HAT once, leg segments twice."""
    return float(sum(p[i] * (1 if "hat" in names[i].lower() else 2) for i in idx))


# ======================================================================================
# Chapter 5: MTG identification, MSK and NMSK tracking, COT
# ======================================================================================
def _ch5(bases: dict) -> list[Row]:
    rows = []
    # Table 5.2 / Sec 5.1.2: the stored identified MTG set and its provenance
    f = mtg_id.PARAMS_FILE
    if f.is_file():
        doc = json.loads(f.read_text())
        prov, params = doc["provenance"], doc["params"]
        v = "not gated (converged)" if prov["success"] else f"not converged ({prov['status']})"
        name = f"data/identified/{f.name} (MTG identification)"
        for j, tv in mtg_id.THESIS_RMSE_DEG.items():
            rows.append(Row(5, f"MTG identification: {j} angle RMSE (Sec 5.1.2)", tv, prov["rmse_deg"].get(j, np.nan),
                            "deg", "unknown", name, v))
        causes = _mtg_causes(gait_ocp.load_mtg_params(f))
        for g in mtg.GENERATORS:
            for k in ("s_tau", "s_V"):
                rows.append(Row(5, f"MTG {g}: {k} (Table 5.2)", float(getattr(mtg.THESIS_PARAMS[g], k)),
                                float(params[g][k]), "1", causes[g], name, v))
    gait = sg.tracking_data(data_mod.load_gait_data("Free"))
    # Tables 5.4 and 5.11: tracking RMSEs
    ablation = {"MSK": _ablation_causes("MSK")}
    jerk = _jerk_causes("MSK")
    floor = _floor_causes()
    ch5abl = {m: _ch5_ablation_causes(m) for m in ("MSK", "NMSK")}
    gaps = {m: _located_gaps(s) for m, s in bases.items() if s is not None}
    verdicts = {"NMSK": _nmsk_diagnosis_text(), "MSK": _msk_diagnosis_text()}
    for model, table in (("MSK", "Table 5.4"), ("NMSK", "Table 5.11")):
        s = bases.get(model)
        valid = gate(s, model) if s is not None else ""
        r = s.rmse.set_index(["kind", "channel"])["rmse"] if s is not None else None
        for (kind, part, side), tv in sg.THESIS_RMSE[model].items():
            ch = f"grf_{part}_{side}" if kind == "grf" else f"{part}_{side}"
            col = {"angle": ch, "torque": f"tau_{ch}", "grf": ch}[kind]
            unit = {"angle": "deg", "torque": "N*m", "grf": "N"}[kind]
            sd = _rms_sd(gait, col, 1 / cv.DEG if kind == "angle" else 1.0)
            ours = float(r.get((kind, ch), np.nan)) if r is not None else np.nan
            # the Ch 5 ablation on the book's reading itself; angles: the geometric floor
            # (no dynamics); otherwise the Ch 2 measurements, made from the thesis's reading
            # and labelled so
            parts = [ch5abl.get(model, {}).get((kind, part, side)), floor.get((part, side)) if kind == "angle" else None]
            cause = "; ".join(p for p in parts if p) or None
            if cause is None:
                cause = ablation.get(model, {}).get((kind, part, side)) or jerk.get((kind, part, side))
                cause = f"measured from the thesis's reading: {cause}" if cause else None
            rows.append(Row(5, f"{model} RMSE {kind} {part} {side.upper()} ({table})", tv, ours, unit,
                            cause or "unknown",
                            s.name if s is not None else "", valid, sd=sd,
                            gap=_gap_text(gaps.get(model, {}).get(f"{kind}:{'grf_' if kind == 'grf' else ''}{part}_{side}", ""),
                                          verdicts.get(model, ""))))
    # Table 5.10 and COT: the NMSK solution
    s = bases.get("NMSK")
    valid = gate(s, "NMSK") if s is not None else ""
    ap = s.stats.get("activation_parameters", {}) if s is not None else {}

    syn = msk.synergy_cost_table(s) if ap else None
    for k, tv in msk.THESIS_TABLE_5_10["identified"].items():
        ours = ap.get(k, np.nan)
        cause = "unknown"
        lo, hi = activation.ACTIVATION_BOUNDS[k]
        if np.isfinite(ours) and min(abs(ours - lo), abs(ours - hi)) <= 1e-3 * (hi - lo):
            why = "Eq 5.55 has no term comparing excitations with EMG, so only the effort terms move γ"
            if k in ("s1", "s2") and syn is not None:
                c = syn["Act cost / A²"]
                # at (0.5, 0.5) both partial derivatives of |w|² are +1 with s1, s2 at their upper
                # bounds: a local minimum of 1/|w|² on the box (a KKT point); (0, 0) is the global one
                why += (f"; the least Act cost per squared ankle-extensor activation (1/|w|², Eq 5.54) is "
                        f"{c['ours']:.2f} at ours, {c['initial (Table 5.10)']:.2f} at Table 5.10's initial guess (a "
                        f"stationary point, the largest), {c['thesis, Table 5.10']:.2f} at the thesis's values and "
                        f"{c['corner (0, 0): GAM only']:.2f} with GAM only"
                        + ("; ours, GAM weight 0, is a local minimum on the bounds"
                           if all(abs(ap[x] - 0.5) <= 1e-3 for x in ("s1", "s2")) else ""))
            cause = (f"at its bound {lo if abs(ours - lo) < abs(ours - hi) else hi:g} (bounds {lo:g}–{hi:g}): {why} "
                     f"[{_anchor('ch05_msk', 'Table 5.10: activation parameters')}]")
        rows.append(Row(5, f"NMSK identified {k} (Table 5.10)", tv, ours, "s" if k == "tau_act" else "1", cause,
                        s.name if s is not None else "", valid))
    cot = s.stats.get("COT", np.nan) if s is not None else np.nan
    cause = "unknown"
    if s is not None and s.muscle_activations is not None:
        br = msk.cot_breakdown(s).iloc[:, 0]
        cause = (f"shortening heat {br['shortening']:.2f} of {br['total']:.2f} J/kg/m (Eq 5.47 as printed) "
                 f"[{_anchor('ch05_msk', 'Cost of transport (Eq 5.57)')}]")
    rows.append(Row(5, "NMSK cost of transport, natural speed (Sec 5.3.5, Eq 5.57)", msk.THESIS_COT, cot, "J/kg/m",
                    cause, s.name if s is not None else "", valid))
    rows += _ch5_unloaded()
    return rows


def _ch5_unloaded() -> list[Row]:
    """The Ch 5 NMSK solve with the swing foot unloaded (Ch 5, "the same on valid gaits"), and the
    same re-optimised with Bhargava's reading of Eq 5.47's F0: their COT beside the thesis's, with
    children's measured costs (:func:`gaitlib.studies.msk.cot_ranges`) as the cause."""
    b = fidelity.swing_bound()
    m = stored_gait(gait_ocp.cache_dir(msk.ch5_spec("MSK", swing_load_max=b)))
    where = _anchor("ch05_msk", "Against children's measured cost: which reading of Eq 5.47 lands in range")
    rows = []
    for item, kw in (("NMSK cost of transport, natural speed, swing foot unloaded (Sec 5.3.5, Eq 5.57)", {}),
                     ("NMSK cost of transport, natural speed, swing foot unloaded, Bhargava's F0 in Eq 5.47 (ours) "
                      "(Sec 5.3.5, Eq 5.57)", {"isometric_torque": "bhargava"})):
        n = stored_gait(gait_ocp.cache_dir(msk.ch5_spec("NMSK", swing_load_max=b, **kw), guess=m.solution)) if m else None
        if n is None:
            rows.append(Row(5, item, msk.THESIS_COT, np.nan, "J/kg/m", "unknown", "", ""))
            continue
        r = msk.cot_ranges({"run": n}).iloc[0]
        mean, sd = msk.STRIDE_COST
        inside = abs(r["z (net)"]) <= fidelity.RANGE_Z
        cause = (f"{'inside' if inside else 'outside'} children's measured range: {r['per stride']:.2f} J/kg per stride "
                 f"against {mean:g} ± {sd:g} (Weyand et al. 2010, read as net), z = {r['z (net)']:+.1f} SD; gross "
                 f"{r['COT gross']:.2f} J/kg/m = {r['gross ÷ Waters']:.2f}× the 6–12-year-olds' {msk.CHILD_COT_GROSS:.1f} "
                 f"(Waters et al. 1983); the thesis's {msk.THESIS_COT:g} is "
                 f"{(msk.THESIS_COT * r['D (m)'] - mean) / sd:+.1f} SD [{where}]")
        rows.append(Row(5, item, msk.THESIS_COT, float(r["COT"]), "J/kg/m", cause, n.name, gate(n, "NMSK")))
    return rows


def _mtg_causes(ours: dict) -> dict[str, str]:
    """generator → why its identified Γ is where it is: the smallest margin of Eq 5.15 (the
    generator strong enough for the demanded torque, N·m) on our data for Eq 5.22's initial
    set, the thesis's Table 5.2 and ``ours`` (:func:`gaitlib.studies.mtg_id.margins_table`).
    Eq 5.23 penalises any departure from the initial values, so a generator whose initial
    set already meets the demand (margin > 0) keeps it; one short of it moves."""
    sets = {"initial": None, "thesis": mtg.THESIS_PARAMS, "ours": ours}
    m = mtg_id.margins_table(sets, mtg_id.demanded_torques(mtg_id.chapter_spec())).xs("Eq 5.15", axis=1, level=1)
    where = _anchor("ch05_msk", "Which constraints bind")
    out = {}
    for g, r in m.iterrows():
        if r["initial"] > 0:
            out[g] = (f"Eq 5.15 inactive on our data: Eq 5.22's initial set is {r['initial']:.1f} N·m stronger than "
                      f"the demand, so Eq 5.23's regulariser keeps Γ at it (Table 5.2's set: margin "
                      f"{r['thesis']:.1f} N·m) [{where}]")
        else:
            out[g] = (f"Eq 5.15 binds on our data: Eq 5.22's initial set is {-r['initial']:.1f} N·m short of the "
                      f"demand, Table 5.2's {-r['thesis']:.1f} N·m short; ours {r['ours']:+.2f} N·m [{where}]")
    return out


def _ablation_causes(model: str = "MSK") -> dict:
    """(kind, part, side) → the tracking ablation's measured answer for that channel (Ch 2:
    the lowest RMSE any single change reaches, and whether any meets the Fidelity II target);
    empty when the ablation is not stored."""
    try:
        swing = fidelity.swing_ablation(model)
        _, picked = fidelity.tracking_ablation(model, swing=swing)
    except cache.NotCached:
        return {}
    where = _anchor("ch02_gait", "The tracking ablation: one change at a time")
    out = {}
    for (kind, part, side, unit), r in fidelity.channel_table(picked, model).iterrows():
        out[(kind, part, side)] = (f"tracking ablation: lowest {r[r['best change']]:.1f} {unit} "
                                   f"({r['best change']}), target {r['target']:.1f} {unit} met by: {r['met by']} [{where}]")
    return out


def _gap_text(located: str, verdict: str) -> str:
    return f"{located}; {verdict}" if located and verdict else located


def _nmsk_diagnosis_text() -> str:
    """The diagnosis of the book's Ch 5 NMSK solution (Ch 8 section 5: muscle-level
    candidates, :func:`gaitlib.studies.gap.nmsk_attribution`): its verdict and top effect;
    says so when it is not stored."""
    try:
        with cache.only("the card reads stored solutions only"):
            d = gap_study.nmsk_attribution(reading="book", resamples=0)
    except cache.NotCached:
        return "diagnosis not stored"
    where = _anchor("ch08_gap", "5. Does co-contraction close the TA/GAM gap? (thesis Sec 5.3.5)")
    return (f"diagnosis (co-contraction, joint stiffness, activation timing on this solution): {d.verdict}"
            + (f", top {d.top_effect}" if d.top_effect != "unexplained" else "") + f" [{where}]")


#: Ch 8's section holding the library diagnosis of the book's Ch 5 MSK solution.
MSK_DIAGNOSIS_HEADING = "6b. The library's candidates on the Ch 5 MSK solution"


def _msk_diagnosis_text() -> str:
    """The diagnosis of the book's Ch 5 MSK solution with every applicable library effect
    (:func:`gaitlib.studies.gap.ch5_attribution`): its verdict and top effect; "no diagnosis
    run on this solution" when it is not stored."""
    try:
        with cache.only("the card reads stored solutions only"):
            d = gap_study.ch5_attribution("MSK", reading="book", resamples=0)
    except cache.NotCached:
        return "no diagnosis run on this solution"
    where = _anchor("ch08_gap", MSK_DIAGNOSIS_HEADING)
    return (f"diagnosis (the library's {len(d.settings.get('candidates', []))} candidates on this solution): "
            f"{d.verdict}" + (f", top {d.top_effect}" if d.top_effect != "unexplained" else "") + f" [{where}]")


def _located_gaps(sol) -> dict:
    """Channel (``"angle:knee_r"`` …) → the located gap of ``sol`` against the Free data
    (:func:`gaitlib.gap.locate.locate`): RMS z, significance, and the phase with the largest
    RMS z."""
    loc = gap_locate.locate(sol, gap_io.load_real("Free", "schwartz2008"))
    where = _anchor("ch08_gap", "1. Locate: SD-standardised residuals by channel and phase")
    out = {}
    for _, c in loc.channels.iterrows():
        ph = loc.table[loc.table["channel"] == c["channel"]].sort_values("rms_z").iloc[-1]
        out[c["channel"]] = (f"RMS z {c['rms_z']:.2f}{' (significant)' if c['significant'] else ''}; largest in "
                             f"{ph['phase']} (z {ph['rms_z']:.2f}{', significant' if ph['significant'] else ''}) [{where}]")
    return out


#: The Ch 5 page's section of each model's ablation (the card links to it).
CH5_ABLATION_HEADINGS = {"MSK": "Where the misfit comes from: one change at a time",
                         "NMSK": "Where the NMSK misfit comes from: one change at a time"}


def _ch5_ablation_causes(model: str = "MSK") -> dict:
    """(kind, part, side) → the Ch 5 ablation's answer for that channel (:func:`gaitlib.
    studies.fidelity.ch5_ablation`: one change at a time on the book's reading; the lowest
    RMSE a converged, valid run reaches and which changes meet the target); empty when it is
    not stored or the book's own Ch 5 solution is not usable."""
    try:
        with cache.only("the card reads stored solutions only"):
            _, sols = fidelity.ch5_ablation(model)
    except cache.NotCached:
        return {}
    ok = fidelity.usable_solutions(sols)
    if fidelity.CH5_BASE_ROW not in ok or len(ok) < 2:
        return {}
    where = _anchor("ch05_msk", CH5_ABLATION_HEADINGS[model])
    out = {}
    table = fidelity.channel_table(ok, model)
    every = fidelity.all_targets(table)
    every = (f"; every angle, torque and GRF target at once: met by {', '.join(every)}" if every else
             "; every angle, torque and GRF target at once: met by no run")
    legs = fidelity.LEG_SET_ROW if fidelity.LEG_SET_ROW in table.columns else None
    for (kind, part, side, unit), r in table.iterrows():
        leg = (f"; at the book's weights on legs ×{fidelity.LEG_SCALE:g} with Ch 4 (c) identified on them "
               f"{r[legs]:.1f} {unit} (book's run {r[fidelity.CH5_BASE_ROW]:.1f})" if legs else "")
        out[(kind, part, side)] = (f"Ch 5 ablation (book's reading, {len(ok) - 1} usable changes): lowest "
                                   f"{r[r['best change']]:.1f} {unit} ({r['best change']}), target {r['target']:.1f} "
                                   f"{unit} met by: {r['met by']}{every}{leg} [{where}]")
    return out


def _floor_causes(clearance_mm: float = 1e3 * fidelity.TOUCH) -> dict:
    """(joint, side) → the geometric angle floor of that joint (Ch 2,
    :func:`gaitlib.studies.fidelity.kinematic_floor_table`: the poses closest to the data whose
    feet agree with its phases, no dynamics), with the planned metatarsal angles tracked and
    free, at ``clearance_mm`` of swing clearance."""
    t = fidelity.kinematic_floor_table((clearance_mm / 1e3,))
    where = _anchor("ch02_gait", "The jerk term's denominators: a HAT pinned to a constant speed")
    at = t.set_index("metatarsal")
    out = {}
    for col in t.columns:
        if col.endswith(" (deg)") and col != "worst (deg)":
            j, side = col[:-len(" (deg)")].rsplit("_", 1)
            out[(j, side)] = (f"geometric floor (no dynamics, {clearance_mm:g} mm swing clearance): "
                              f"{at[col].iloc[0]:.1f}° with the planned metatarsal angles tracked, "
                              f"{at[col].iloc[1]:.1f}° with them free [{where}]")
    return out


def _jerk_causes(model: str) -> dict:
    """(kind, part, side) → what the Ch 2 problem of ``model`` gives at that channel with the
    Jrk term's denominators from the data (:func:`gaitlib.studies.fidelity.jerk_study`,
    swing foot unloaded) beside the reference's (the thesis's reading); empty when the study is not stored."""
    try:
        with cache.only("the card reads stored solutions only"):
            table, sols = fidelity.jerk_study(model)
    except cache.NotCached:
        return {}
    runs = list(table.index)
    book, data = sols[runs[2]], sols[runs[3]]
    if data.stats["status"] not in validity.CONVERGED_STATUSES:
        return {}
    where = _anchor("ch02_gait", "The jerk term's denominators: a HAT pinned to a constant speed")
    a = book.rmse.set_index(["kind", "channel"])["rmse"]
    b = data.rmse.set_index(["kind", "channel"])["rmse"]
    units = {"angle": "°", "torque": " N·m", "grf": " N"}
    out = {}
    for (kind, ch), v in b.items():
        part, side = (ch[4:-2], ch[-1]) if kind == "grf" else (ch[:-2], ch[-1])
        out[(kind, part, side)] = (f"Ch 2 {model}, swing unloaded ({table.loc[runs[3], 'gates']}): Jrk denominators of "
                                   f"the HAT from the data {v:.1f}{units[kind]} vs the fallback 1 "
                                   f"{a[(kind, ch)]:.1f}{units[kind]} [{where}]")
    return out


def _ch5_bases(reading: str = "thesis") -> dict:
    """The Ch 5 MSK and NMSK solutions (Eq 5.33, Eq 5.55) in ``reading``
    (:data:`gaitlib.studies.gait.READINGS`) as :class:`StoredGait`: the book's reading gives
    Ch 5's rows; Chs 6–7 start from the thesis's until they are solved again."""
    out = {}
    b = stored_gait(gait_ocp.cache_dir(msk.ch5_spec("MSK", reading=reading)))
    if b is not None:
        out["MSK"] = b
        nb = stored_gait(gait_ocp.cache_dir(msk.ch5_spec("NMSK", reading=reading), guess=b.solution))
        if nb is not None:
            out["NMSK"] = nb
    return out


# ======================================================================================
# Chapters 6 and 7: cost functions and speeds
# ======================================================================================
def _runs(bases: dict, which: str, reading: str = "thesis", policy: str | None = None, **changes) -> dict:
    """name → StoredGait (or None) of the Ch 6 (``which="ch6"``) or Ch 7 runs in ``reading``
    (``bases``: the Ch 5 solutions of that reading), found as
    :func:`gaitlib.studies.predictive.cost_function_study` / ``speed_study`` store them;
    ``changes``: GaitSpec fields of a variant of those runs (e.g. ``max_iter=3000``: the
    reruns of :meth:`gaitlib.studies.predictive.StudyResult.rerun_failed`; ``weights=``: the
    Ch 7 pin experiment); ``policy``: the runs' start (:data:`gaitlib.studies.predictive.
    GUESS_POLICY` for Ch 6, ``GUESS_POLICY_CH7`` for Ch 7, by default; ``"thesis"``: the
    thesis's partial guess, Ch 6 only)."""
    out = {}
    for m, base in bases.items():
        if which == "ch6":
            specs = pr.ch6_specs(m, base, pr.CH6_COSTS, reading=reading, **pr.default_params())
            guesses = {k: pr.run_guess(base, policy or pr.GUESS_POLICY[m]) for k in specs}
        else:
            specs = pr.ch7_specs(m, base, pr.CH7_CLASSES, reading=reading, **pr.default_params())
            guesses = {}
            for k, s in specs.items():
                g = data_mod.load_gait_data(s.speed_class, s.source)
                guesses[k] = pr.run_guess(base, pr.GUESS_POLICY_CH7[m], cycle_time=g.cycle_time,
                                          stride=g.speed * g.cycle_time)
        for k, s in specs.items():
            s = replace(s, **changes) if changes else s
            out[k] = stored_gait(gait_ocp.cache_dir(s, guess=guesses[k]))
    return out


def _with_reruns(runs: dict, reruns: dict) -> tuple[dict, dict]:
    """(``runs`` with each blocked run — not converged or invalid — replaced by its rerun
    where that rerun is stored, converged and valid; name → note on the rerun used). The
    rule of :meth:`gaitlib.studies.predictive.StudyResult.with_reruns`, on stored runs."""
    out, notes = dict(runs), {}
    for k, s in runs.items():
        r = reruns.get(k)
        if s is not None and _blocked(gate(s, k)) and r is not None and r.success and not _blocked(gate(r, k)):
            out[k] = r
            notes[k] = (f"{k}: its {r.spec.max_iter}-iteration rerun ({r.stats['iterations']} iterations; the "
                        f"{s.spec.max_iter}-iteration run: {s.stats['status']})")
    return out, notes


def _converges_row(chapter: int, item: str, thesis: str, s, r, valid: str, anchor: str) -> Row:
    """Did a run converge (Tables 6.3, 7.2)? ``s`` the study's run, ``r`` its rerun with
    more iterations (or None): when ``s`` stopped at its limit and ``r`` converged and is
    valid, the claim holds with the larger limit, and the row says so and takes ``r``'s gate."""
    if s is None:
        return Row(chapter, item, thesis, np.nan, "", "unknown", "", valid, holds=False)
    ours = f"{s.stats['status']}, {s.stats['iterations']} it, {_hours(s.stats):.2f} h"
    if s.success:
        return Row(chapter, item, thesis, ours, "", "", s.name, valid, holds=True)
    cause = f"{s.stats['status']} after {s.stats['iterations']} iterations [{anchor}]"
    rv = gate(r, "") if r is not None else ""
    if r is not None and r.success and not _blocked(rv):
        ours += (f"; its {r.spec.max_iter}-iteration rerun: {r.stats['status']}, {r.stats['iterations']} it, "
                 f"{_hours(r.stats):.2f} h")
        return Row(chapter, item, thesis, ours, "", cause + f"; converged with the {r.spec.max_iter}-iteration limit "
                   f"(the thesis's GPOPS-II ran to convergence)", r.name, rv, holds=True)
    return Row(chapter, item, thesis, ours, "", cause, s.name, valid, holds=False)


def _mean(df: pd.DataFrame, kind: str | None = None, col: str = "nrmse") -> float:
    d = df if kind is None else df[df["kind"] == kind]
    return float(d[col].mean()) if len(d) else np.nan


def _joint(valids: dict) -> str:
    """The validity text of a row computed from several solutions (name → gate text):
    ``"valid"`` when none is blocked, else ``"invalid: …"`` / ``"not converged: …"`` naming
    the blocked ones."""
    bad = {k: v or "missing" for k, v in valids.items() if _blocked(v) or not v}
    if not bad:
        return "valid"
    head = "invalid" if any("invalid" in v for v in bad.values()) else "not converged"
    return f"{head}: " + "; ".join(f"{k} ({_short(v)})" for k, v in bad.items())


def _short(label: str) -> str:
    """The failed checks' names of a gate label (``"swing load, double support"``)."""
    parts = re.split(r"; |: ", label.replace("invalid: ", ""))
    names = [re.sub(r"\s*[-\d(].*$", "", p).strip() for p in parts]
    return ", ".join(dict.fromkeys(n for n in names if n))


def _ch6(bases: dict, runs: dict, valid: dict, reruns: dict | None = None) -> list[Row]:
    reruns = reruns or {}
    rows = []
    status = _anchor("ch06_costfun", "Did every run converge? Solver statistics and Table 6.3")
    where = _anchor("ch06_costfun", "FP with the gait's phase timing")
    timed = _fp_timed(bases)
    for model, hours in pr.THESIS_HOURS_TABLE_6_3.items():
        for c, h in hours.items():
            k = f"{model} {c}"
            row = _converges_row(6, f"{k} converges (Table 6.3: {h} h)", f"converged, {h} h", runs.get(k),
                                 reruns.get(k), valid.get(k, ""), status)
            if k in timed and _blocked(row.valid):
                row.cause = _fp_as_printed(row.valid, where, timed[k])
            rows.append(row)
    free = data_mod.load_gait_data("Free")
    rows += _ch6_claims(bases, runs, valid, free, reruns)
    first = len(rows)
    rows += _ch6_fp(runs, valid, bases.get("NMSK"), free)
    if timed:  # the same rows on the FP runs with the gait's phase timing (our reading), beside them
        for r in rows[first:]:
            if _blocked(r.valid):
                r.cause = "; ".join(x for x in (r.cause if r.cause != "unknown" else "", _fp_as_printed(
                    r.valid, where, None)) if x)
        rows += _ch6_fp({**runs, **timed}, {**valid, **{k: gate(v, k) for k, v in timed.items()}}, bases.get("NMSK"),
                        free, _FP_TIMED_LABEL, f"[{where}]", _ch6_activation_cause(bases, runs))
    item = "all 8 MSK runs' compute time ÷ all 8 NMSK runs' (Sec 6.3, Table 6.3)"
    rows.append(_time_ratio_row(6, item, pr.THESIS_HOURS_TABLE_6_3, runs, pr.CH6_COSTS, "Ch 6, 16 runs", valid))
    used, notes = _with_reruns(runs, reruns)
    used.update(timed)
    notes.update({k: f"{k}: with the gait's phase timing (ours)" for k in timed})
    if notes:  # the same ratio with the blocked runs' stand-ins (each named), beside it
        v = {k: gate(s, k) for k, s in used.items() if s is not None}
        alt = _time_ratio_row(6, f"{item} — the blocked runs' converged, valid stand-ins (ours)",
                              pr.THESIS_HOURS_TABLE_6_3, used, pr.CH6_COSTS, "Ch 6, 16 runs", v)
        alt.cause += "; uses " + "; ".join(notes[k] for k in sorted(notes)) + f" [{status}]"
        if _blocked(rows[-1].valid) and not _blocked(alt.valid):
            rows[-1].cause += f"; with the blocked runs' converged, valid stand-ins: {alt.ours:.2f} (the row below)"
        rows.append(alt)
    return rows


#: Appended to the items of the Ch 6 FP rows computed on the phase-timed FP runs.
_FP_TIMED_LABEL = " — FP with the gait's phase timing (ours: as printed, FP is not a gait)"


def _fp_as_printed(valid: str, where: str, timed=None) -> str:
    """The cause of an as-printed FP row that fails the gates: FP has no data term and the
    book's swing bound is timed by the data, so nothing makes a foot swing — the measured
    experiment is the same problem with the gait's phase timing (``timed``: that run, when the
    row is its convergence row)."""
    out = ("as printed nothing in FP makes a foot swing (no data term; the swing bound is timed by the data): "
           f"{valid.split(': ', 1)[-1]}")
    if timed is not None:
        out += (f"; with the gait's phase timing (ours): {timed.stats['status']}, {timed.stats['iterations']} it, "
                f"{gate(timed, timed.name) or 'valid'}")
    else:
        out += f"; the same claim with the gait's phase timing (ours) is the row \"…{_FP_TIMED_LABEL}\""
    return f"{out} [{where}]"


def _fp_timed(bases: dict) -> dict:
    """The Ch 6 FP runs with the gait's phase timing (our reading, :func:`gaitlib.studies.
    predictive.fp_timed_study`; the book's reading otherwise) that are stored, converged and
    valid: name → StoredGait."""
    return {k: v for k, v in _runs(bases, "ch6", "book", swing_load_max=validity.swing_bound()).items()
            if k.endswith(" FP") and v is not None and not _blocked(gate(v, k))}


def _time_split(sa: dict, sb: dict, b: str, a: str) -> str:
    """Run ``b``'s compute time (build + solve) against ``a``'s (solver stats ``sb``, ``sa``),
    split into the ratio of iterations and the ratio of time per iteration (their product)."""
    ia, ib = int(sa["iterations"]), int(sb["iterations"])
    ta, tb = 3600 * _hours(sa), 3600 * _hours(sb)
    return (f"{b} {tb:.0f} s in {ib} iterations, {a} {ta:.0f} s in {ia}: iterations ×{ib / ia:.2f}, "
            f"time per iteration ×{(tb / ib) / (ta / ia):.2f}")


def _ch6_fp(runs: dict, valid: dict, n5, free, label: str = "", where: str = "", model_cause: str = "") -> list[Row]:
    """The thesis's numeric FP claims (Secs 6.2.4, 6.3): NMSK FP's RMSE and compute time
    against MSK FP's, and NMSK FP's excitations against Ch 5's data tracking (``n5``), on
    ``runs``; ``label`` is appended to each item and ``where`` (the section the runs are
    shown in) to each cause (both empty for the runs as printed); ``model_cause``: the
    measured cause of an NMSK-vs-MSK accuracy difference, the RMSE rows' cause."""
    def cause(c: str = "") -> str:
        return "; ".join(x for x in (c, where) if x) or "unknown"

    rows = []
    a, b = "MSK FP", "NMSK FP"
    sc = {k: pr.score(runs[k], free) for k in (a, b) if runs.get(k) is not None}
    for kind, tv in pr.THESIS_FP_GAIN_PCT.items():
        ours = (100 * (1 - _mean(sc[b], kind, "rmse") / _mean(sc[a], kind, "rmse"))) if a in sc and b in sc else np.nan
        rows.append(Row(6, f"FP: NMSK {kind} RMSE lower than MSK's by (Sec 6.3){label}", tv, ours, "%", cause(model_cause),
                        f"Ch 6 {a}, {b}", _joint({a: valid.get(a, ""), b: valid.get(b, "")})))
    th = pr.THESIS_HOURS_TABLE_6_3
    sa, sb = runs.get(a), runs.get(b)
    rows.append(Row(6, f"FP: NMSK compute time lower than MSK's by (Sec 6.2.4, Table 6.3){label}",
                    100 * (1 - th["NMSK"]["FP"] / th["MSK"]["FP"]),
                    100 * (1 - _hours(sb.stats) / _hours(sa.stats)) if sa and sb else np.nan, "%",
                    cause(_time_split(sa.stats, sb.stats, b, a) if sa and sb else ""),
                    f"Ch 6 {a}, {b}", _joint({k: valid.get(k, "") for k in (a, b)})))
    ours = np.nan
    if n5 is not None and runs.get(b) is not None:
        ours = 100 * (1 - float(pr.excitation_score(runs[b], free)["rmse"].mean())
                      / float(pr.excitation_score(n5, free)["rmse"].mean()))
    rows.append(Row(6, f"NMSK FP excitation RMSE lower than the Ch 5 data tracking's by (Sec 6.2.4){label}",
                    pr.THESIS_FP_EXCITATION_GAIN_PCT, ours, "%", cause(), f"Ch 6 {b}, Ch 5 NMSK",
                    _joint({b: valid.get(b, ""), "Ch 5 NMSK": gate(n5, "NMSK") if n5 is not None else ""})))
    return rows


def _ch6_claims(bases: dict, runs: dict, valid: dict, free, reruns: dict) -> list[Row]:
    """The Ch 6 conclusions (:func:`gaitlib.studies.ch6_claims.conclusions`) that the thesis
    states without a number, one row each, on the runs that converged and pass the gates;
    the verdict is the NRMSE one, and a claim whose verdict changes with the metric says so in
    its cause."""
    where = _anchor("ch06_costfun", "The thesis's conclusions, re-derived from valid runs (Secs 6.2–6.3)")
    usable, notes = {}, {}
    for k, s in runs.items():
        if s is not None and not _blocked(valid.get(k, "")):
            usable[k] = s
        elif reruns.get(k) is not None and not _blocked(gate(reruns[k], k)):  # the page's rule
            usable[k] = reruns[k]
            notes[k] = f"its {reruns[k].spec.max_iter}-iteration rerun ({reruns[k].stats['iterations']} iterations)"
    n5 = bases.get("NMSK")
    table = ch6_claims.conclusions(usable, free, excluded={k: valid.get(k, "") for k in runs if k not in usable},
                                   ch5_nmsk=n5, notes=notes)
    valid = {**valid, **{k: gate(s, k) for k, s in usable.items()},
             ch6_claims.CH5_NMSK: gate(n5, "NMSK") if n5 is not None else ""}
    # the FP claims again on the FP runs with the gait's phase timing (Ch 6, our reading)
    timed = _fp_timed(bases)
    table_t = (ch6_claims.conclusions({**usable, **timed}, free, ch5_nmsk=n5, notes=notes).set_index("claim")
               if timed else None)
    fp_where = _anchor("ch06_costfun", "FP with the gait's phase timing")
    act_cause = _ch6_activation_cause(bases, runs)
    # the same claims with our Ch 5 activation parameters in every NMSK run (the thesis's procedure, our data)
    c5, c5_notes = {}, {}
    if n5 is not None:  # a run blocked at the iteration limit counts through its converged, valid rerun (the page's rule)
        c5, c5_notes = _with_reruns(_runs({"NMSK": n5}, "ch6", "book", activation_params="ch5"),
                             _runs({"NMSK": n5}, "ch6", "book", activation_params="ch5", max_iter=3000))
        c5 = {k: v for k, v in c5.items() if v is not None and not _blocked(gate(v, k))}
    table_c5 = (ch6_claims.conclusions({**{k: v for k, v in usable.items() if not k.startswith("NMSK")}, **c5}, free,
                                       ch5_nmsk=n5).set_index("claim") if c5 else None)
    c5_where = _anchor("ch06_costfun", "The thesis's procedure on our data: Ch 5's activation parameters in every "
                                       "NMSK run")
    start_check = _ch6_start_check(n5, free, usable, c5)
    rows = []
    for _, r in table[~table["numeric"].astype(bool)].iterrows():
        # a decided claim is computed from the usable runs alone; an untested one names all
        names = (r["used"] if r["verdict"] != "not tested" else r["runs"]).split(", ")
        exc = isinstance(r["RMSE: verdict"], str)  # an excitation claim: RMSE (the thesis's), else NRMSE
        metric, other = ("RMSE", "NRMSE") if exc else ("NRMSE", "SD units")
        ours = r[metric] if r["verdict"] != "not tested" else np.nan
        cause = "unknown"
        if r["verdict"] == "not tested":
            cause = f"not tested: {r['ours']} [{where}]"
            if table_t is not None and r["claim"] in table_t.index and table_t.loc[r["claim"], "verdict"] != "not tested":
                t = table_t.loc[r["claim"]]
                cause += (f"; with the gait's phase timing (FP, our reading): {t['verdict']} "
                          f"({t['RMSE' if exc else 'NRMSE']}) [{fp_where}]")
        model_pair = r["claim"].split(":")[0] in pr.CH6_COSTS and ("MSK" in r["claim"] and "NMSK" in r["claim"])
        if cause == "unknown" and model_pair and act_cause:
            cause = act_cause
            if table_c5 is not None and r["claim"] in table_c5.index:
                t = table_c5.loc[r["claim"]]
                cause += (f"; with our Ch 5 activation parameters in every NMSK run (the thesis's procedure on our "
                          f"data{''.join(_rerun_note(c5_notes, n) for n in r['runs'].split(', '))}): "
                          f"{t['verdict']} ({t['NRMSE']}) [{c5_where}]")
        if cause == "unknown" and exc and r["claim"] in start_check:
            cause = start_check[r["claim"]]
        if r["depends on metric"]:
            cause = f"depends on the metric: {other} says {r[f'{other}: verdict']} ({r[other]}) [{where}]"
        rows.append(Row(6, f"{r['claim']} (Sec {r['thesis']})", "holds", ours, "", cause,
                        f"Ch 6 {', '.join(names)}", _joint({n: valid.get(n, "") for n in names}),
                        holds=None if r["verdict"] == "not tested" else r[f"{metric}: verdict"] == "holds"))
    return rows


def _ch6_start_check(n5, free, book_runs: dict | None = None, c5: dict | None = None) -> dict:
    """claim → what the Ch 6 conclusions say on the NMSK runs started from the thesis's
    partial guess (Sec 6.1; the book's reading, converged and valid runs only) for the
    excitation claims that are decided there: a second start, which tells whether a claim's
    fate comes from the book's start (the Ch 5 solution). Where that start does not decide a
    claim, the cause adds how finely the runs rank (:func:`gaitlib.studies.ch6_claims.
    excitation_resolution` over ``book_runs``, the second start and ``c5``, the runs with our
    Ch 5 activation parameters). Empty when not stored."""
    if n5 is None:
        return {}
    tg = {k: v for k, v in _runs({"NMSK": n5}, "ch6", "book", policy="thesis").items()
          if v is not None and not _blocked(gate(v, k))}
    if not tg:
        return {}
    where = _anchor("ch06_costfun", "A second start: the excitation claims on the runs from the thesis's partial guess")
    t = ch6_claims.conclusions(tg, free, ch5_nmsk=n5)
    variants = {"book's runs": book_runs or {}, "the thesis's partial guess as start": tg,
                **({"our Ch 5 activation parameters": c5} if c5 else {})}
    resolution = ch6_claims.excitation_resolution(ch6_claims.excitation_scores(variants, free)) if book_runs else ""
    res_where = _anchor("ch06_costfun", "How finely the runs rank by excitation accuracy")
    out = {}
    for _, r in t.iterrows():
        if isinstance(r["RMSE: verdict"], str) and r["verdict"] != "not tested":
            guess = f"from the thesis's partial guess (Sec 6.1; {len(tg)} valid NMSK runs)"
            out[r["claim"]] = (f"the start decides it: {guess} it holds: {r['RMSE']} [{where}]"
                               if r["RMSE: verdict"] == "holds" else
                               f"not the start: {guess} it does not hold either: {r['RMSE']} [{where}]"
                               + (f"; how finely the runs rank: {resolution[0].lower()}{resolution[1:]} [{res_where}]"
                                  if resolution else ""))
    return out


def _ch6_activation_cause(bases: dict, runs: dict) -> str:
    """The activation experiment of Ch 6 (:func:`gaitlib.studies.predictive.activation_study`:
    NMSK DT with its activation parameters identified instead of Table 5.10's), as a cause of
    the NMSK-vs-MSK accuracy rows; empty when it is not stored or a run is not usable."""
    m, n = runs.get("MSK DT"), runs.get("NMSK DT")
    if m is None or n is None or bases.get("NMSK") is None:
        return ""
    a = _runs({"NMSK": bases["NMSK"]}, "ch6", "book", free_activation=True).get("NMSK DT")
    if a is None or _blocked(gate(a, "NMSK DT")):
        return ""
    free = data_mod.load_gait_data("Free")
    nr = {k: float(pr.mean_nrmse(pr.score(v, free).assign(model="x", case="y")).iloc[0]) for k, v in
          (("MSK", m), ("NMSK", n), ("identified", a))}
    where = _anchor("ch06_costfun", "A measured cause: the NMSK runs' activation parameters")
    return (f"the NMSK runs use Table 5.10's activation parameters: NMSK DT mean NRMSE {nr['NMSK']:.3f} with them, "
            f"{nr['identified']:.3f} with them identified on our data (MSK DT {nr['MSK']:.3f}) — measured on DT [{where}]")


def _time_ratio_row(chapter: int, item: str, th: dict, runs: dict, names, solution: str, valid: dict) -> Row:
    """The MSK ÷ NMSK ratio of summed compute times: the thesis's table ``th`` vs our runs."""
    ms = [runs.get(f"MSK {c}") for c in names]
    ns = [runs.get(f"NMSK {c}") for c in names]
    ours, cause = np.nan, "unknown"
    if all(ms) and all(ns):
        ours = sum(_hours(s.stats) for s in ms) / sum(_hours(s.stats) for s in ns)

        def total(sols):
            return {k: sum(float(s.stats[k]) for s in sols) for k in ("iterations", "solve_time_s", "build_time_s")}
        cause = _time_split(total(ns), total(ms), "MSK", "NMSK") + " (sums over the runs)"
    return Row(chapter, item, sum(th["MSK"].values()) / sum(th["NMSK"].values()), ours, "1", cause, solution,
               _joint({k: valid.get(k, "") for k in runs}))


def _ch7(bases: dict, runs: dict, valid: dict, ch6: dict, valid6: dict, act_cause: str = "",
         reruns: dict | None = None) -> list[Row]:
    """Ch 7's rows. The convergence rows are the study's own runs (with their reruns beside);
    every other row uses a blocked run's converged, valid rerun in its place
    (:func:`_with_reruns`, the page's rule) and names it in its cause."""
    rows = []
    inv = {v: k for k, v in pr.THESIS_CLASS.items()}
    status = _anchor("ch07_speed", "Compute times (thesis Table 7.2)")
    reruns = reruns or {}
    for model, hours in pr.THESIS_HOURS_TABLE_7_2.items():
        for tc, h in hours.items():
            k = f"{model} {inv[tc]}"
            rows.append(_converges_row(7, f"{k} ({tc}) converges (Table 7.2: {h} h)", f"converged, {h} h",
                                       runs.get(k), reruns.get(k), valid.get(k, ""), status))
    runs, notes = _with_reruns(runs, reruns)
    valid = {k: gate(s, k) for k, s in runs.items() if s is not None}
    n0 = len(rows)
    th = pr.THESIS_HOURS_TABLE_7_2
    rows.append(_time_ratio_row(7, "all 4 MSK runs' compute time ÷ all 4 NMSK runs' (Sec 7.3, Table 7.2)", th, runs,
                                pr.CH7_CLASSES, "Ch 7, 8 runs", valid))
    c5, c5_free, c5_notes = _ch7_c5(bases)  # the NMSK runs with our Ch 5 activation parameters (our reading)
    c5_where = _anchor("ch07_speed", "With our Ch 5 activation parameters")
    # NMSK torques more accurate than MSK's per class (Sec 7.2)
    for tc, tv in pr.THESIS_TORQUE_GAIN_PCT_CH7.items():
        c = inv[tc]
        a, b = runs.get(f"MSK {c}"), runs.get(f"NMSK {c}")
        ours = np.nan
        if a is not None and b is not None:
            ours = pr.torque_gain(b, a, c)
        cause = act_cause or "unknown"
        o = c5.get(f"NMSK {c}")
        if a is not None and o is not None and not _blocked(gate(a, f"MSK {c}")):
            cause = "; ".join(x for x in (act_cause, f"with our Ch 5 activation parameters in the NMSK run"
                                                     f"{_rerun_note(c5_notes, f'NMSK {c}')}: "
                                                     f"{pr.torque_gain(o, a, c):.1f} % [{c5_where}]") if x)
        rows.append(Row(7, f"{c} ({tc}): NMSK torque NRMSE lower than MSK's by (Sec 7.2)", tv, ours, "%",
                        cause, f"Ch 7 MSK {c}, NMSK {c}",
                        _joint({f"MSK {c}": valid.get(f"MSK {c}", ""), f"NMSK {c}": valid.get(f"NMSK {c}", "")})))
    # Fig 7.5: COT against speed; the natural-speed point is the like-for-like Ch 6 NMSK DT
    cot_page = _anchor("ch07_speed", "Cost of transport against speed (thesis Fig 7.5)")
    pts, vals = {}, {}
    n5 = bases.get("NMSK")
    for tc, speed, tv in pr.THESIS_COT_FIG_7_5:
        c = inv[tc]
        s = ch6.get("NMSK DT") if c == "Free" else runs.get(f"NMSK {c}")
        v = valid6.get("NMSK DT", "") if c == "Free" else valid.get(f"NMSK {c}", "")
        cot = float(s.stats.get("COT", np.nan)) if s is not None else np.nan
        cause = "unknown"
        if s is not None and getattr(s, "muscle_activations", None) is not None:
            br = msk.cot_breakdown(s).iloc[:, 0]
            cause = (f"shortening heat {br['shortening']:.2f} of {br['total']:.2f} J/kg/m (Eq 5.47 as printed); the "
                     f"thesis's value is {tv / msk.CHILD_COT_GROSS:.2f}× the gross COT children aged 6–12 were measured "
                     f"at free speed ({msk.CHILD_COT_GROSS:.1f} J/kg/m, Waters et al. 1983) [{cot_page}]")
        if c == "Free" and n5 is not None:
            cause = (f"ours: Ch 6 NMSK DT (the cost of the other points); the Ch 5 NMSK (Eq 5.55, its own "
                     f"activation parameters) gives {n5.stats.get('COT', np.nan):.2f}; "
                     + (cause if cause != "unknown" else f"[{cot_page}]"))
        g = data_mod.load_gait_data(c)
        pts[c] = (g.speed, cot)
        vals[f"NMSK {c}"] = v
        rows.append(Row(7, f"COT at {c} ({tc}, thesis {speed} m/s; ours {g.speed:.2f} m/s) (Fig 7.5)", tv, cot,
                        "J/kg/m", cause, s.name if s is not None else "", v))
    u_cause = "unknown"
    if all(np.isfinite(v[1]) for v in pts.values()) and len(pts) == 5:
        order = sorted(pts, key=lambda k: pts[k][0])
        cots = [pts[k][1] for k in order]
        i = int(np.argmin(cots))
        bumps = pr.u_breaks(pts)  # U-shaped: falling to the minimum, rising after it
        holds = order[i] == "Free" and 0 < i < len(cots) - 1 and not bumps
        ours = ", ".join(f"{k} {pts[k][1]:.2f}" for k in order) + f" (minimum at {order[i]})"
        if bumps:
            u_cause = "not U-shaped: the COT moves the wrong way between " + "; ".join(bumps)
        pts5 = {k: (data_mod.load_gait_data(k).speed, float(v.stats.get("COT", np.nan)))
                for k, v in {**{n.split(" ", 1)[1]: x for n, x in c5.items()}, "Free": c5_free}.items() if v is not None}
        if len(pts5) == 5 and all(np.isfinite(v[1]) for v in pts5.values()):
            o5 = sorted(pts5, key=lambda k: pts5[k][0])
            b5 = pr.u_breaks(pts5)
            u_cause = "" if u_cause == "unknown" else u_cause + "; "
            u_cause += (f"with our Ch 5 activation parameters (every NMSK run, Free = Ch 6 DT"
                        + "".join(_rerun_note(c5_notes, k) for k in sorted(c5_notes)) + "): "
                        + ", ".join(f"{k} {pts5[k][1]:.2f}" for k in o5)
                        + f", minimum at {min(pts5, key=lambda k: pts5[k][1])}"
                        + (f", not U-shaped ({'; '.join(b5)})" if b5 else ", U-shaped") + f" [{c5_where}]")
    else:
        holds, ours = None, np.nan
    rows.append(Row(7, "COT against speed is U-shaped with its minimum at the natural speed (Sec 7.2, Fig 7.5)",
                    "U, minimum at natural speed", ours, "", u_cause,
                    "Ch 6 NMSK DT, Ch 7 NMSK", _joint(vals), holds=holds))
    rows.append(_ch7_pin(bases, runs, c5, c5_notes))
    for i in range(n0, len(rows)):  # name the reruns a row uses
        used = [n for k, n in notes.items() if _ch7_uses(rows[i].item, k)]
        if used:
            c = rows[i].cause if rows[i].cause != "unknown" else ""
            rows[i].cause = "; ".join(x for x in (c, "uses " + "; ".join(used)) if x)
    rows += _ch7_consistent()
    return rows


def _rerun_note(notes: dict, name: str) -> str:
    """``"; <name>: its 3000-iteration rerun (…)"`` when ``name`` is represented by its rerun
    (``notes`` of :func:`_with_reruns`), else ``""`` — every use of a rerun is named."""
    return f"; {notes[name]}" if name in notes else ""


def _ch7_c5(bases: dict) -> tuple[dict, object, dict]:
    """The Ch 7 NMSK runs with our Ch 5 activation parameters (:func:`gaitlib.studies.predictive.
    ch5_activation_speed_study`; a run blocked at the iteration limit through its converged,
    valid rerun) that are stored, converged and valid, the Ch 6 NMSK DT run with them (the
    natural-speed point; None if not usable), and the notes naming the reruns used."""
    n5 = bases.get("NMSK")
    if n5 is None:
        return {}, None, {}
    runs, notes = _with_reruns(_runs({"NMSK": n5}, "ch7", "book", activation_params="ch5"),
                           _runs({"NMSK": n5}, "ch7", "book", activation_params="ch5", max_iter=3000))
    dt = _runs({"NMSK": n5}, "ch6", "book", activation_params="ch5").get("NMSK DT")
    ok = {k: v for k, v in runs.items() if v is not None and not _blocked(gate(v, k))}
    return ok, (dt if dt is not None and not _blocked(gate(dt, "NMSK DT")) else None), notes


def _ch7_uses(item: str, run: str) -> bool:
    """Whether the Ch 7 card row ``item`` is computed from run ``run`` (``"MSK VeryFast"``)."""
    model, c = run.split(" ", 1)
    if "compute time" in item:
        return True
    if "NMSK torque NRMSE" in item:
        return item.startswith(f"{c} (")
    if item.startswith("COT at "):
        return model == "NMSK" and item.startswith(f"COT at {c} (")
    return model == "NMSK" and ("U-shaped" in item or "predictions closer" in item)


def _starts_clause(bases: dict, nm: dict, gaits: dict) -> str:
    """The card's clause on the Ch 7 start experiment (:func:`gaitlib.studies.predictive.
    data_start_study`: the NMSK runs from data-based starts, the class's own data among them),
    read from the store; empty when a run is not stored. ``nm``: the chapter's NMSK runs
    (reruns standing in), ``gaits``: class → GaitData."""
    base = bases.get("NMSK")
    if base is None:
        return ""
    specs = pr.ch7_specs("NMSK", base, pr.CH7_CLASSES, reading="book", **pr.default_params())
    studies = {pr.CH7_OWN_START: pr.Runs(nm)}
    for st in pr.DATA_STARTS:
        sp, guesses = pr.data_start_runs(specs, st)
        sols = {k: stored_gait(gait_ocp.cache_dir(s, guess=guesses.get(k))) for k, s in sp.items()}
        if any(v is None for v in sols.values()):
            return ""
        studies[st] = pr.Runs(sols)
    text = pr.start_findings(pr.start_table(studies, gaits), pr.CH7_OWN_START)
    where = _anchor("ch07_speed", "Accuracy against each class's own (untracked) data — thesis Figs 7.1–7.4")
    return text[-1].replace("**", "") + f" [{where}]"


def _ch7_pin(bases: dict, runs: dict, c5: dict | None = None, c5_notes: dict | None = None) -> Row:
    """Thesis Secs 7.2–7.3: the predictions approach the speed classes' own (untracked) data.
    Ours: the NMSK cells (class × kind) closer to the class data than the time-scaled Free
    data they tracked; the cause: the pin experiment (:func:`gaitlib.studies.predictive.
    pin_findings`, Table 7.1's data weights ÷ 10) and, when all four are usable, the same count
    on the NMSK runs with our Ch 5 activation parameters (``c5``, :func:`_ch7_c5`)."""
    item = "NMSK predictions closer to each class's own data than the scaled Free data they tracked (Secs 7.2–7.3)"
    gaits = {c: data_mod.load_gait_data(c) for c in cv.SPEED_CLASSES}
    nm = {k: s for k, s in runs.items() if k.startswith("NMSK ")}
    if not all(s is not None for s in nm.values()):
        return Row(7, item, "closer", np.nan, "", "unknown", "", "")
    pull = pr.input_pull(pr.Runs(nm), gaits)
    closer, n = pr.closer_cells(pull)
    loose = _runs({m: b for m, b in bases.items() if m == "NMSK"}, "ch7", "book", weights=pr.LOOSE_TRACKING)
    cause = "unknown"
    if all(s is not None for s in loose.values()):
        lines = pr.pin_findings(pull, pr.input_pull(pr.Runs(loose), gaits))
        where = _anchor("ch07_speed", "Accuracy against each class's own (untracked) data — thesis Figs 7.1–7.4")
        if lines:
            cause = lines[-1].lstrip("- ") + f" [{where}]"
    if c5 and len(c5) == len(nm):
        k5, n5 = pr.closer_cells(pr.input_pull(pr.Runs(c5), gaits))
        cause = "; ".join(x for x in (cause if cause != "unknown" else "",
                                      f"with our Ch 5 activation parameters in the NMSK runs"
                                      + "".join(_rerun_note(c5_notes or {}, k) for k in sorted(c5_notes or {}))
                                      + f": closer in {k5} of {n5} "
                                      f"cells [{_anchor('ch07_speed', 'With our Ch 5 activation parameters')}]") if x)
    starts = _starts_clause(bases, nm, gaits)
    legs = _legs_clause("cells")
    for x in (starts, legs):
        if x:
            cause = "; ".join(y for y in (cause if cause != "unknown" else "", x) if y)
    valid = _joint({k: gate(s, k) for k, s in nm.items() if s is not None and not marks_mod.failure_label(s)})
    return Row(7, item, "closer", f"{closer} of {n} unmarked cells", "", cause, "Ch 7 NMSK, 4 runs",
               valid or "valid", holds=closer > n / 2)


def _ch7_consistent() -> list[Row]:
    """Fig 7.5's claim on the consistent curve of valid gaits (Ch 7, "one consistent
    problem on valid gaits"): the minimum's class and, if not Free, the by-term difference."""
    item = ("COT against speed is U-shaped with its minimum at the natural speed — one consistent problem, "
            "swing foot unloaded (Sec 7.2, Fig 7.5)")
    try:
        res = fidelity.consistent_speed_study(progress=False)
    except cache.NotCached:
        return [Row(7, item, "U, minimum at natural speed", np.nan, "", "unknown", "", "")]
    cot = pr.cot_table(res)
    terms = fidelity.cot_terms(cot, res.solutions)
    valid = {k: gate(s, k) for k, s in res.solutions.items()}
    if len(terms) < len(cot):
        return [Row(7, item, "U, minimum at natural speed", np.nan, "", "not every speed valid", "",
                    _joint(valid), holds=None)]
    at = terms["total"].astype(float).idxmin()
    ours = ", ".join(f"{c} {v:.2f}" for c, v in terms["total"].items()) + f" (minimum at {at})"
    cause = fidelity.cot_curve_findings(cot, terms)[-1] if at != "Free" else ""
    where = _anchor("ch07_speed", "One consistent problem on valid gaits")
    cause = f"{cause} [{where}]" if cause else ""
    skate = _skating_cause(cot, res)
    cause = "; ".join(x for x in (cause, skate, _restart_clause(res, terms), _legs_clause("cot"), _f0_clause(),
                                  _own_data_clause()) if x) or "unknown"
    return [Row(7, item, "U, minimum at natural speed", ours, "", cause,
                "Ch 7 NMSK DT, swing unloaded", _joint(valid), holds=at == "Free")]


def _restart_clause(res, terms: pd.DataFrame) -> str:
    """The card's clause on the consistent curve's multistart (Ch 7, "Is each point a local
    optimum?", :func:`gaitlib.studies.fidelity.multistart`); empty when not stored."""
    try:
        with cache.only("the restarts"):
            restarts = fidelity.multistart(res, rounds=fidelity.CH7_ROUNDS, progress=False)
    except cache.NotCached:
        return ""
    rt, best, cot_b, terms_b = fidelity.restart_curve(restarts)
    where = _anchor("ch07_speed", "Is each point a local optimum? Every run from every other run's solution")
    text = fidelity.restart_findings(best, terms, cot_b, terms_b, n_runs=len(rt) - len(best), table=rt)
    return " ".join(x.replace("**", "") for x in text) + f" [{where}]"


def _f0_clause() -> str:
    """The card's clause on the consistent curve re-optimised with Bhargava's reading of Eq 5.47's
    F0 (Ch 7, "With Bhargava's reading of Eq 5.47's F0"): its valid points and minimum; empty
    when not stored."""
    try:
        _, _, res = fidelity.stored_consistent_study("the runs with Bhargava's F0", isometric_torque="bhargava")
    except cache.NotCached:
        return ""
    try:
        _, used = fidelity.stored_restarts(res, "the restarts of the marked points with Bhargava's F0")
    except cache.NotCached:
        used = res
    cot, terms, _ = fidelity.curve_tables(used)
    where = _anchor("ch07_speed", "With Bhargava's reading of Eq 5.47's F0")
    if len(terms) < 3:
        return f"with Bhargava's F0 re-optimised only {len(terms)} of {len(cot)} speeds are valid [{where}]"
    at = terms["total"].astype(float).idxmin()
    pts = ", ".join(f"{c} {v:.2f}" for c, v in terms["total"].items())
    return (f"with Bhargava's F0 in Eq 5.47 re-optimised at every speed ({len(terms)} of {len(cot)} valid"
            + "".join(f"; {x}" for x in fidelity.stand_in_labels(used))
            + f"): {pts}, {fidelity.minimum_phrase(cot, at)} [{where}]")


#: The Ch 7 page's section of the consistent problem tracking each class's own data.
CH7_OWN_DATA_HEADING = "Each class's own data tracked (a probe of the input)"


def _own_data_clause() -> str:
    """The card's clause on the consistent problem with each class tracking its own data
    (Ch 7, :data:`CH7_OWN_DATA_HEADING`): :func:`gaitlib.studies.fidelity.own_data_findings`
    of every stored probe of :data:`gaitlib.studies.fidelity.OWN_DATA_VARIANTS`; empty when
    none is stored."""
    text, tables = [], {}
    for variant in fidelity.OWN_DATA_VARIANTS:
        try:
            base, own = fidelity.stored_own_data(variant)
        except cache.NotCached:
            continue
        tables[variant] = fidelity.own_data_table(base, own)
        text += fidelity.own_data_findings(tables[variant], variant=variant)
    if "" in tables:
        text += fidelity.tracking_weight_findings(tables)
    if not text:
        return ""
    return " ".join(x.replace("**", "") for x in text) + f" [{_anchor('ch07_speed', CH7_OWN_DATA_HEADING)}]"


#: The Ch 7 page's section of the consistent curve on longer legs (the card links to it).
CH7_LEGS_HEADING = "On longer legs with the contact identified on them (a probe)"


def _legs_curve() -> dict | None:
    """The consistent curve on legs × :data:`gaitlib.studies.fidelity.LEG_SCALE` with the
    contact identified on them (Ch 7, :data:`CH7_LEGS_HEADING`), from the store: ``ok`` (the
    classes of converged, valid runs), ``cot``, ``terms``, ``slip``, ``at`` (the class of the
    lowest COT among ``ok``, or None), ``closer``/``n`` (:func:`gaitlib.studies.predictive.
    closer_cells` of its non-Free runs), ``used`` (the 3000-iteration reruns standing in) and
    ``restarted`` (the marked points' restarts standing in, :func:`gaitlib.studies.fidelity.
    stored_restarts`, where stored); None when not stored."""
    try:
        _, _, res = fidelity.stored_consistent_study("the runs on longer legs", **fidelity.LEGS_PROBES["legs"])
    except cache.NotCached:
        return None
    try:
        _, res = fidelity.stored_restarts(res, "the restarts of the marked points on longer legs",
                                          also=fidelity.legs_partner("legs"))
    except cache.NotCached:
        pass  # the study as solved: its marked points stay out
    cot, terms, slip = fidelity.curve_tables(res)
    ok = [c for c in cot.index if not cot.loc[c, "mark"]]
    gaits = {c: data_mod.load_gait_data(c) for c in cv.SPEED_CLASSES}
    pull = pr.input_pull(res, gaits).drop(index="NMSK Free", level="run", errors="ignore")
    closer, n = pr.closer_cells(pull)
    at = cot.loc[ok, "COT (J/kg/m)"].astype(float).idxmin() if ok else None
    return {"ok": ok, "cot": cot, "terms": terms, "slip": slip, "at": at, "closer": closer, "n": n,
            "used": tuple(res.rerun_used), "restarted": fidelity.stand_in_labels(res),
            "drift": fidelity.hat_reference_drift(res)}


def _legs_clause(what: str) -> str:
    """The card's clause on the consistent curve on longer legs (:func:`_legs_curve`):
    ``what="cot"`` its COT points and minimum, ``"cells"`` its cells closer to the class data;
    empty when not stored."""
    g = _legs_curve()
    if g is None:
        return ""
    where = _anchor("ch07_speed", CH7_LEGS_HEADING)
    head = f"on legs ×{fidelity.LEG_SCALE:g} with the contact identified on them (a probe"
    if not g["ok"]:
        return f"{head}) no run is a converged, valid gait [{where}]"
    used = (f", {', '.join(g['used'])} through {'its 3000-iteration rerun' if len(g['used']) == 1 else 'their 3000-iteration reruns'}"
            if g["used"] else "")
    used += "".join(f", {x}" for x in g["restarted"])
    if abs(g["drift"]) > fidelity.HAT_DRIFT_TOL:
        used += (f"; caveat: their HAT reference is not periodic (it drifts {g['drift']:.3f} m over the cycle, "
                 "a sawtooth no periodic gait can follow)")
    col = "slip, force-weighted (m/s)"
    if what == "cells":
        return f"{head}; {len(g['ok'])} of {len(g['cot'])} runs converged and valid{used}): closer in {g['closer']} of {g['n']} cells [{where}]"
    cot = g["cot"]
    low = fidelity.minimum_table({"legs": cot}).iloc[0]
    shape = (f" (not a U: {low['steps the wrong way (not a U)']})" if low["steps the wrong way (not a U)"] else " (a U)"
             ) if low["minimum at Free"] else ""
    return (f"{head}; {len(g['ok'])} of {len(cot)} runs converged and valid{used}, feet sliding "
            f"{g['slip'].loc[g['ok'], col].min():.2f}–{g['slip'].loc[g['ok'], col].max():.2f} m/s): "
            + ", ".join(f"{c} {cot.loc[c, 'COT (J/kg/m)']:.2f}" for c in g["ok"])
            + f", {fidelity.minimum_phrase(cot, g['at'])}{shape} [{where}]")


def _skating_cause(cot: pd.DataFrame, res) -> str:
    """The consistent runs' foot slip and the same problem with the friction floor (Ch 7,
    "The feet skate"): where its curve has its minimum, from the converged, valid runs."""
    slip = fidelity.slip_table({s.spec.speed_class: s for s in res.solutions.values()})
    col = "slip, force-weighted (m/s)"
    text = (f"the loaded feet slide at {slip[col].min():.2f}–{slip[col].max():.2f} m/s (force-weighted; the friction "
            f"law sticks below {fidelity.SLIP_V:g} m/s)")
    try:
        _, _, res_f = fidelity.stored_consistent_study("the runs with the friction floor",
                                                       friction_floor=fidelity.FRICTION_FLOOR)
    except cache.NotCached:
        return text + " — the same problem with friction not stored"
    try:
        _, res_f = fidelity.stored_restarts(res_f, "the restarts of the marked points with the friction floor")
    except cache.NotCached:
        pass  # the study as solved: its marked points stay out
    cot_f = pr.cot_table(res_f)
    ok = [c for c in cot_f.index if not cot_f.loc[c, "mark"]]
    where = _anchor("ch07_speed", "The feet skate: the same problem with friction")
    if not ok:
        return text + f"; with every ellipsoid's friction ≥ {fidelity.FRICTION_FLOOR:g} no run is a converged, valid gait [{where}]"
    slip_f = fidelity.slip_table({s.spec.speed_class: s for s in res_f.solutions.values()})
    at = cot_f.loc[ok, "COT (J/kg/m)"].astype(float).idxmin()
    used = (f"; {', '.join(res_f.rerun_used)} through "
            f"{'its 3000-iteration rerun' if len(res_f.rerun_used) == 1 else 'their 3000-iteration reruns'}"
            if res_f.rerun_used else "")
    used += "".join(f"; {x}" for x in fidelity.stand_in_labels(res_f))
    return (text + f"; with every ellipsoid's friction ≥ {fidelity.FRICTION_FLOOR:g} ({len(ok)} of {len(cot_f)} runs "
            f"converged and valid{used}, slip {slip_f.loc[ok, col].min():.2f}–{slip_f.loc[ok, col].max():.2f} m/s): "
            + ", ".join(f"{c} {cot_f.loc[c, 'COT (J/kg/m)']:.2f}" for c in ok) + f", {fidelity.minimum_phrase(cot_f, at)} [{where}]")


# ======================================================================================
# The card
# ======================================================================================
#: The verdicts that count a row as (at least qualitatively) reproduced.
_AGREE = ("reproduced", "within data SD", "qualitatively reproduced")


def slip_table(card: pd.DataFrame) -> pd.DataFrame:
    """Foot slip (:func:`gaitlib.studies.fidelity.foot_slip`, a measurement, not a validity
    gate) of every stored gait solution a card row names (``gait/<key>`` in its ``solution``
    column): chapter, the solution, its rows, the force-weighted slip speed of the loaded
    feet (m/s), the share of the load carried while sliding faster than the friction law's
    v_tr (%), how fast the feet of its tracking reference alone slide (m/s, no solve:
    :func:`gaitlib.studies.gait.reference_slip` of its spec), the walking speed (m/s) and the
    row verdicts it carries."""
    out = []
    refs: dict = {}
    ids = card["solution"].str.extract(r"^(gait/[0-9a-f]{16})", expand=False)
    for sid, part in card.groupby(ids, sort=False):
        sol = stored_gait(cache.default_dir() / sid)
        if sol is None:
            continue
        f = fidelity.foot_slip(sol)
        sp = sol.spec
        rk = (sp.speed_class, sp.track_class, sp.source, sp.fourier_order, sp.contact_params, sp.friction_floor)
        if rk not in refs:  # the reference depends on the data and the contact set only
            refs[rk] = sg.reference_slip(sp)["slip"]
        out.append({"chapter": int(part["chapter"].iloc[0]), "solution": part["solution"].iloc[0], "rows": len(part),
                    "slip (m/s)": f["slip"], f"load sliding > {fidelity.SLIP_V:g} m/s (%)": 100 * f["sliding"],
                    "reference's slip (m/s)": refs[rk], "walking speed (m/s)": f["speed"],
                    "verdicts": ", ".join(f"{k} {v}" for k, v in part["verdict"].value_counts().items()),
                    "rows counted as reproduced": int(part["verdict"].isin(_AGREE).sum())})
    return pd.DataFrame(out)


def legs_slip_lines() -> list[str]:
    """One sentence: the Ch 5 ablation's run on longer legs with the contact and body
    identified on them (:data:`gaitlib.studies.fidelity.LEG_SET_ROW`) beside the book's
    Ch 5 run, per model — the force-weighted foot slip and the worst angle RMSE; empty when
    not stored, a run not usable is said so."""
    parts, both = [], []
    for model in ("MSK", "NMSK"):
        got = _stored(lambda m=model: fidelity.ch5_ablation(m))
        if got is None:
            continue
        t = got[0]
        if fidelity.LEG_SET_ROW not in t.index or fidelity.CH5_BASE_ROW not in t.index:
            continue
        a, b = t.loc[fidelity.CH5_BASE_ROW], t.loc[fidelity.LEG_SET_ROW]
        if b["status"] not in validity.CONVERGED_STATUSES or b["gates"] != "valid":
            parts.append(f"{model} not compared ({b['status']}, {b['gates']})")
            continue
        parts.append(f"{model} {a[fidelity.SLIP_COLUMN]:.3f} → {b[fidelity.SLIP_COLUMN]:.3f} m/s (worst angle "
                     f"{a['worst angle RMSE (deg)']:.2f} → {b['worst angle RMSE (deg)']:.2f}°)")
        both.append(b[fidelity.SLIP_COLUMN] <= fidelity.SLIP_V < a[fidelity.SLIP_COLUMN]
                    and b["worst angle RMSE (deg)"] < a["worst angle RMSE (deg)"])
    if not parts:
        return []
    return [f"On thigh and shank ×{fidelity.LEG_SCALE:g} with Ch 4's (c) identified on them (a probe, Ch 4 and the "
            f"Ch 5 ablation) the book-weights Ch 5 solutions' feet slide: {'; '.join(parts)}"
            + (f" — in every run the feet stop sliding (below v_tr = {fidelity.SLIP_V:g} m/s) and the worst angle falls "
               "together, once the model's legs fit the data's stride and its contact is identified on them."
               if both and all(both) else ".")]


def stride_lines() -> list[str]:
    """One sentence, no solve (Ch 4): how much of the data's stride the data's angles carry
    the model's loaded feet with our Ch 4 contact set (:func:`gaitlib.studies.gait.stride_sweep`),
    and the two 3-D/normalisation readings measured against it — the pelvic rotation the 2-D
    model lacks (the hip width it would need, :func:`gaitlib.studies.gait.pelvic_rotation_slip`)
    and the leg length the data would have to be converted with."""
    spec = replace(ci.spec_c(), contact_params="ch4")
    d = sg.stride_sweep(spec)
    _, w0 = sg.pelvic_rotation_slip(spec, widths=(0.0,))
    hip_ankle = d["hip_to_ankle"]
    return [f"Why the data's stride is too long for the model's legs (Ch 4, no solve): the data's angles carry its loaded "
            f"feet {100 * d['ratio']:.0f} % of the stride; the pelvis's rotation, which the 2-D model lacks, would close "
            f"the rest only with the hip centres {w0:.2f} m apart, and the dimensionless data only if converted with a "
            f"leg length of {d['conversion_length']:.3f} m (the model's hip to ankle: {hip_ankle:.3f} m)"
            + (" — neither explains it." if w0 > sg.HIP_WIDTH_OUT_OF_REACH_BH * cv.BODY_HEIGHT and d["conversion_length"] < hip_ankle else ".")]


def slip_lines(table: pd.DataFrame) -> list[str]:
    """Sentences on :func:`slip_table`: how many of the card's gait solutions (and rows) slide
    faster than v_tr on average, the range, and how many rows would change verdict if foot
    slip were a gate (the rows not already invalid or not comparable)."""
    if table.empty:
        return []
    v = fidelity.SLIP_V
    ref = "reference's slip (m/s)"
    over = table[table["slip (m/s)"] > v]
    carried = int(over["rows counted as reproduced"].sum())
    return [f"Of the {len(table)} stored gait solutions behind the card's rows, {len(over)} carry their load on feet "
            f"that slide faster than the friction law's sticking limit v_tr = {v:g} m/s on average (force-weighted "
            f"slip {table['slip (m/s)'].min():.2f}–{table['slip (m/s)'].max():.2f} m/s; a standing foot does not "
            f"slide). They back {int(over['rows'].sum())} rows, {carried} of them now reproduced, within data SD or "
            "qualitatively reproduced. Foot slip is measured here, not yet a validity gate."
            + (f" Their tracking references alone — the data on the model, no solve — already slide "
               f"{table[ref].min():.2f}–{table[ref].max():.2f} m/s; {int((table['slip (m/s)'] > table[ref]).sum())} of "
               f"the {len(table)} solutions slide faster than their reference." if ref in table.columns else "")]


def build(chapters=(3, 4, 5, 6, 7)) -> pd.DataFrame:
    """The report card (module docstring) from the stored solutions; never solves
    (:func:`gaitlib.cache.only`: a missing solution is a "not comparable" row)."""
    with cache.only("the card reads stored solutions only"):
        return _build(tuple(chapters))


def _build(chapters) -> pd.DataFrame:
    rows: list[Row] = []
    if 3 in chapters:
        rows += _ch3()
    if 4 in chapters:
        rows += _ch4()
    # Chs 5–7 report the book's reading (the Ch 5 solutions, the Ch 6 runs and the Ch 7 runs)
    bases = _ch5_bases("book") if {5, 6, 7} & set(chapters) else {}
    if 5 in chapters:
        rows += _ch5(bases)
    ch6 = _runs(bases, "ch6", "book") if {6, 7} & set(chapters) else {}
    valid6 = {k: gate(s, k) for k, s in ch6.items() if s is not None}
    if 6 in chapters:
        rows += _ch6(bases, ch6, valid6, _runs(bases, "ch6", "book", max_iter=3000))
    if 7 in chapters:  # the Free point is the Ch 6 NMSK DT run
        ch7 = _runs(bases, "ch7", "book")
        valid7 = {k: gate(s, k) for k, s in ch7.items() if s is not None}
        dt7 = {k: v for k, v in ch6.items() if k == "NMSK DT"}
        rows += _ch7(bases, ch7, valid7, dt7, {k: v for k, v in valid6.items() if k == "NMSK DT"},
                     _ch6_activation_cause(bases, ch6),  # Ch 7's NMSK runs use Table 5.10's too
                     _runs(bases, "ch7", "book", max_iter=3000))
    return pd.DataFrame([r.record() for r in rows], columns=list(COLUMNS))


def counts(card: pd.DataFrame) -> pd.Series:
    """Number of rows per verdict (every verdict listed, zeros included)."""
    return card["verdict"].value_counts().reindex(list(VERDICTS), fill_value=0)


def write(out) -> Path:
    """Write ``card.csv`` into the directory ``out`` (created)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    f = out / "card.csv"
    build().to_csv(f, index=False, float_format="%.6g")
    return f
