"""Chapter 3, predictive vertical jumps: the three jumps of the thesis solved
(:mod:`gaitlib.problems.jump`, whose names this module re-exports for the book), their
results beside the thesis's (labelled references), the channel figures and the animation.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from .. import conventions as cv
from ..problems.jump import (FORMULATION, LABELS, SPECS, TABLE_3_5, THESIS, JumpProblem, JumpSolution,  # noqa: F401
                             JumpSpec, build, cache_location, initial_guess, joint_bounds, meshes, solve, spec,
                             strength_envelope)
from .. import plots

__all__ = ["solve_all", "results_table", "stats_table", "plot_channels", "animate", "THESIS", "SPECS",
           "JumpSpec", "JumpSolution", "joint_bounds", "spec", "solve", "build", "cache_location",
           "THESIS_HEIGHT_ORDER", "AT_BOUND", "torques_at_bound", "findings", "HUMAN_JUMP_RISE_M", "strength_specs",
           "solve_strength", "strength_use", "strength_table", "strength_findings", "HEIGHT_CLAIMS", "height_claims",
           "STRENGTH_RETRIES", "PIVTOL", "retry_spec", "retry_label", "strength_stand_ins", "strength_retries",
           "strength_retry_table", "strength_retry_findings", "TAKEOFF_GOAL", "TAKEOFF_FACTOR", "TAKEOFF_COSTS",
           "apex_cost_spec", "solve_apex_cost", "takeoff_state", "takeoff_table", "takeoff_change", "takeoff_clause",
           "takeoff_findings"]


def solve_all(names=("toeless", "toe", "ellipsoid"), use_cache: bool = False,
              **overrides) -> dict[str, JumpSolution]:
    """Solve several of the thesis's jumps (``overrides`` applied to every spec)."""
    return {n: solve(spec(n, **overrides), use_cache=use_cache) for n in names}


# ======================================================================================
# Tables and figures
# ======================================================================================
def results_table(sols: dict[str, JumpSolution]) -> pd.DataFrame:
    """Our jump heights, required friction and deepest knee beside the thesis's values
    (columns labelled "thesis, Sec 3.4.x"); failed solves keep their status."""
    rows = {}
    for name, s in sols.items():
        h, th = s.jump_height, THESIS[name]
        rows[s.spec.label] = {
            "IPOPT status": s.status,
            "COM rise in flight (cm)": 100 * h["com_rise_flight"],
            "v_TO²/2g (cm)": 100 * h["ballistic"],
            "COM rise from standing (cm)": 100 * h["com_rise_standing"],
            "foot (MTP) lift at apex (cm)": 100 * h["foot_lift"],
            "jump height (cm), thesis, Sec 3.4.4": th["jump_height_cm"],
            "required μ_s = max|Fx/Fy|": s.required_friction,
            "μ_s, thesis, Sec 3.4.3": th["mu_s"],
            "deepest knee (deg)": float(s.trajectory["knee"].min() / cv.DEG),
            "deepest knee (deg), thesis, Sec 3.4.1": th["knee_min_deg"],
            "take-off v_y,COM (m/s)": h["takeoff_vy"],
            "take-off time (s)": h["takeoff_time"],
        }
    return pd.DataFrame(rows).T


def stats_table(sols: dict[str, JumpSolution]) -> pd.DataFrame:
    """IPOPT status, iterations, times and problem size per solve."""
    return pd.DataFrame({s.spec.label: s.stats for s in sols.values()}).T


#: Rows of the Ch 3 figures: kind → (channels, title). Units at the edge: :data:`DISPLAY`.
FIGURES = {
    "angles": (("mtp", "ankle", "knee", "hip"), "joint angles (thesis Fig 3.3)"),
    "torques": (("tau_mtp", "tau_ankle", "tau_knee", "tau_hip"), "joint torques (thesis Fig 3.4)"),
    "grf": (("grf_x", "grf_y"), "ground reaction force, both feet (thesis Figs 3.5, 3.6)"),
    "friction": (("friction_ratio",), "|F_x / F_y| (thesis Eq 3.6, Fig 3.7)"),
    "foot": (("x", "y", "theta_z", "foot_angle"), "foot position and orientation (thesis Fig 3.8)"),
}
#: channel → (label, scale from SI, unit)
DISPLAY = {
    "mtp": ("metatarsal (+ toe extension)", 1 / cv.DEG, "deg"),
    "ankle": ("ankle (+ dorsiflexion)", 1 / cv.DEG, "deg"),
    "knee": ("knee (− flexion)", 1 / cv.DEG, "deg"),
    "hip": ("hip (+ flexion)", 1 / cv.DEG, "deg"),
    "tau_mtp": ("τ metatarsal", 1.0, "N·m"), "tau_ankle": ("τ ankle (+ dorsiflexor)", 1.0, "N·m"),
    "tau_knee": ("τ knee (+ extensor)", 1.0, "N·m"), "tau_hip": ("τ hip (+ flexor)", 1.0, "N·m"),
    "grf_x": ("F_x (tangential)", 1.0, "N"), "grf_y": ("F_y (normal)", 1.0, "N"),
    "friction_ratio": ("|F_x / F_y|", 1.0, "–"),
    "x": ("MTP point x", 100.0, "cm"), "y": ("MTP point y", 100.0, "cm"),
    "theta_z": ("toe (root) angle", 1 / cv.DEG, "deg"),
    "foot_angle": ("foot angle (− heel up)", 1 / cv.DEG, "deg"),
}
PHASE_COLORS = {"crouch": "tab:blue", "thrust": "tab:orange", "flight": "tab:green"}


def plot_channels(sols: dict[str, JumpSolution], kind: str, figsize_per=(3.4, 2.0), titles: dict | None = None):
    """One figure in the layout of thesis Figs 3.3–3.8: one column per jump, one row per
    channel of ``kind`` (a key of :data:`FIGURES`), each phase in its colour
    (:data:`PHASE_COLORS`; the kinematic models' crouch + thrust are the thesis's
    preflight phase), the body weight as a dashed line on F_y. A failed solve's column is
    titled "FAILED: <IPOPT status>" in red. ``titles``: name → column title in place of the
    jump's label (e.g. a stand-in named as such). Degrees and cm appear only here."""
    import matplotlib.pyplot as plt

    channels, title = FIGURES[kind]
    names = list(sols)
    fig, axes = plt.subplots(len(channels), len(names),
                             figsize=(figsize_per[0] * len(names), figsize_per[1] * len(channels) + 0.6),
                             squeeze=False, constrained_layout=True, sharex="col")
    for jcol, name in enumerate(names):
        s = sols[name]
        tr = s.trajectory
        for i, c in enumerate(channels):
            ax = axes[i, jcol]
            lab, sc, unit = DISPLAY[c]
            if c not in tr.columns:
                ax.text(0.5, 0.5, "(no toe)", ha="center", va="center", transform=ax.transAxes,
                        color="0.5", fontsize=8)
                ax.set_yticks([])
            else:
                for ph, seg in tr.groupby("phase", sort=False):
                    ax.plot(seg.index, sc * seg[c], lw=1.4, color=PHASE_COLORS[ph], label=ph)
                if c == "grf_y":
                    W = s.model.total_mass * s.model.g
                    ax.axhline(W, color="k", ls="--", lw=0.8, label="body weight")
            ax.set_ylabel(f"{lab} ({unit})", fontsize=7)
            ax.tick_params(labelsize=7)
            if i == 0:
                ok = s.success
                ax.set_title((titles or {}).get(name, s.spec.label) + ("" if ok else f"\nFAILED: {s.status}"),
                             fontsize=8.5,
                             color="k" if ok else "tab:red")
        axes[-1, jcol].set_xlabel("time (s)", fontsize=8)
    handles, labels = [], []
    for ax in axes.flat:
        for h, lb in zip(*ax.get_legend_handles_labels()):
            if lb not in labels:
                handles.append(h)
                labels.append(lb)
    fig.legend(handles, labels, loc="outside lower center", ncols=len(labels), fontsize=8)
    fig.suptitle(title, fontsize=10)
    return fig


def animate(s: JumpSolution, **kw):
    """Stick-figure animation of a solved jump (:func:`gaitlib.plots.animate_jump`), with
    the ground reaction force drawn from ``cop_x``."""
    t, Q = s.poses()
    tr = s.trajectory[~pd.Index(s.trajectory.index).duplicated(keep="last")]
    grf = tr[["grf_x", "grf_y"]].to_numpy(float)
    title = s.spec.label + ("" if s.success else f" — FAILED: {s.status}")
    return plots.animate_jump(s.model, t, Q, p_contact=s.p_contact, grf=grf,
                              cop=tr["cop_x"].to_numpy(float), title=title, **kw)


# --------------------------------------------------------------------------------------
# What the chapter found
# --------------------------------------------------------------------------------------

#: The thesis's order of the jump heights, lowest first (Sec 3.4.4).
THESIS_HEIGHT_ORDER = ("toeless", "toe", "ellipsoid")
#: A joint torque counts as at its Table 3.5 bound from this fraction of the bound on.
AT_BOUND = 0.99


def torques_at_bound(sol, fraction: float = AT_BOUND) -> list[str]:
    """Joints of a jump solution whose torque reaches ``fraction`` of its Table 3.5 bound
    (:func:`joint_bounds`, either sign) somewhere in the motion."""
    out = []
    for j in sol.model.joints:
        lo, hi = joint_bounds(j)["tau"]
        tau = sol.trajectory[f"tau_{j}"]
        if max(tau.max() / hi, tau.min() / lo) > fraction:
            out.append(j)
    return out


def findings(sols: dict, contact_params) -> list[str]:
    """The chapter's findings, one sentence group per item, every number from the solutions
    (``sols``: name → :class:`JumpSolution` for "toeless", "toe", "ellipsoid"): per solve the
    convergence, COM rise, MTP lift, required friction and deepest knee beside :data:`THESIS`;
    the order of the heights against :data:`THESIS_HEIGHT_ORDER`; the friction each contact
    needs; the largest torques and peak vertical GRF (body weights); the torques at their
    bound (:func:`torques_at_bound`); and the heights of the coarse continuation optima.
    ``contact_params``: the ellipsoid contact's parameter vector (13 per ellipsoid, μ_s third)."""
    def cm(v):
        return f"{100 * v:.0f} cm"

    out = []
    for n, s in sols.items():
        h, th, st = s.jump_height, THESIS[n], s.stats
        verdict = "converged" if st["success"] else f"did NOT converge ({st['status']})"
        out.append(f"{s.spec.label}: {verdict} in {st['iterations']} iterations, {st['solve_time_s']:.0f} s. "
                   f"COM rise in flight {cm(h['com_rise_flight'])} (take-off v_y {h['takeoff_vy']:.2f} m/s), "
                   f"MTP lift {cm(h['foot_lift'])} — thesis {th['jump_height_cm']:.0f} cm; "
                   f"required μ_s {s.required_friction:.2f} — thesis {th['mu_s']:g}; deepest knee "
                   f"{np.degrees(s.trajectory['knee'].min()):.0f}° — thesis {th['knee_min_deg']:.0f}°.")
    if not all(s.success for s in sols.values()):
        out.append("NOT every solve converged: the figures and numbers of a failed solve are the last "
                   "iterate of IPOPT, shown for diagnosis only.")
    rise = {n: s.jump_height["com_rise_flight"] for n, s in sols.items()}
    order = sorted(rise, key=rise.get)
    out.append(f"Order of jump heights (COM rise): {' < '.join(order)}; thesis: {' < '.join(THESIS_HEIGHT_ORDER)}"
               f" — {'the same order' if order == list(THESIS_HEIGHT_ORDER) else 'a DIFFERENT order'}.")
    out.append("Our COM rise ÷ the thesis's jump height: "
               + ", ".join(f"{n} {rise[n] / (THESIS[n]['jump_height_cm'] / 100):.1f}×" for n in sols))
    mu = {n: s.required_friction for n, s in sols.items()}
    lower = mu["ellipsoid"] < min(mu["toeless"], mu["toe"])
    out.append(f"Required static friction: ellipsoid contact {mu['ellipsoid']:.2f}, welded toeless "
               f"{mu['toeless']:.2f}, welded toe-included {mu['toe']:.2f} — the ellipsoid contact needs "
               f"{'LESS than either welded contact, as in the thesis' if lower else 'NOT less than both welded contacts, unlike the thesis'}."
               f" Largest μ_s of its ellipsoids: {max(contact_params[13 * i + 2] for i in range(3)):.2f}.")
    peak = {n: max(s.trajectory[f'tau_{j}'].abs().max() for j in s.model.joints) for n, s in sols.items()}
    out.append("Largest joint torque: " + ", ".join(f"{n} {v:.0f} N·m" for n, v in peak.items())
               + " (Table 3.5 allows 1500–4000 N·m); peak F_y "
               + ", ".join(f"{n} {s.trajectory['grf_y'].max() / (s.model.total_mass * cv.G):.1f}×"
                           for n, s in sols.items()) + " the body weight.")
    out.append("Joint torques at (≥ 99 % of) their Table 3.5 bound: "
               + "; ".join(f"{n}: {', '.join(torques_at_bound(s)) or 'none'}" for n, s in sols.items()) + ".")
    coarse = {n: s.solution.info["continuation"][0]["com_rise_flight"] for n, s in sols.items()
              if s.solution.info.get("continuation")}
    out.append("The 5-interval optima the final solves started from: "
               + ", ".join(f"{n} {cm(v)}" for n, v in coarse.items())
               + " — local optima of the same problem, far from the 10-interval ones.")
    return out


# --------------------------------------------------------------------------------------
# The physiological jump: joint torques limited by the body's strength
# --------------------------------------------------------------------------------------

#: Flight COM rise of human standing vertical jumps, m: ≈ 0.2 m (untrained) to ≈ 0.7 m
#: (trained adults) — e.g. Linthorne NP (2001) "Analysis of standing vertical jumps using a
#: force platform", Am J Phys 69:1198–1204. A labelled reference range, not a result.
HUMAN_JUMP_RISE_M = (0.2, 0.7)


def strength_specs(names=tuple(THESIS)) -> dict[str, JumpSpec]:
    """The thesis's jumps with the joint torques limited by the body's strength
    (:class:`JumpSpec` ``torque_limits="strength"``), everything else as :data:`SPECS`."""
    return {n: spec(n, torque_limits="strength") for n in names}


def solve_strength(names=tuple(THESIS), use_cache: bool = True) -> dict[str, JumpSolution]:
    """Solve (or reload) :func:`strength_specs`."""
    return {n: solve(sp, use_cache=use_cache) for n, sp in strength_specs(names).items()}


def strength_use(sol) -> dict[str, float]:
    """Per joint, the largest |τ| over the jump as a fraction of the strength bound at the same
    instant (:func:`gaitlib.problems.jump.strength_envelope`: the MTG envelope at that joint
    angle and velocity for hip, knee and ankle; the box for the metatarsal joint); > 1 means
    the bound is exceeded."""
    env = strength_envelope(sol.model)
    tr = sol.trajectory
    out = {}
    for j in sol.model.joints:
        tau = tr[f"tau_{j}"].to_numpy(float)
        if j in env["envelope"]:
            lo, hi = env["envelope"][j](tr[j].to_numpy(float), tr[f"qd_{j}"].to_numpy(float))
        else:
            lo, hi = env["peak"][j]
        out[j] = float(np.max(np.where(tau >= 0, tau / hi, tau / lo)))
    return out


def strength_table(sols: dict[str, JumpSolution], gates: dict[str, str] | None = None) -> pd.DataFrame:
    """One row per strength-limited jump: IPOPT status and iterations, COM rise in flight
    (cm) beside the human range (:data:`HUMAN_JUMP_RISE_M`) and the thesis's height (a
    labelled reference), take-off v_y, required μ_s, the largest joint torque and its use
    of the strength bound (:func:`strength_use`), and the validity gates (``gates``: name →
    label, e.g. from :func:`gaitlib.validity.label`)."""
    lo, hi = HUMAN_JUMP_RISE_M
    rows = {}
    for n, s in sols.items():
        h = s.jump_height
        use = strength_use(s)
        rows[s.spec.label] = {
            "IPOPT status": s.status, "iterations": s.stats["iterations"],
            "COM rise in flight (cm)": 100 * h["com_rise_flight"],
            "human range (cm), Linthorne 2001": f"{100 * lo:.0f}–{100 * hi:.0f}",
            "jump height (cm), thesis, Sec 3.4.4": THESIS[n]["jump_height_cm"],
            "take-off v_y,COM (m/s)": h["takeoff_vy"],
            "required μ_s = max|Fx/Fy|": s.required_friction,
            "largest |τ| (N·m)": max(s.trajectory[f"tau_{j}"].abs().max() for j in s.model.joints),
            "largest τ / strength": max(use.values()),
            "gates": (gates or {}).get(n, ""),
        }
    return pd.DataFrame(rows).T


#: The thesis's claims on the jump heights (Sec 3.4.4): (lower jump, higher jump, claim).
HEIGHT_CLAIMS = (("toeless", "toe", "the toes raise the jump"), ("toe", "ellipsoid", "the compliant contact raises it further"),
                 ("toeless", "ellipsoid", "toes and compliant contact together raise it"))


def height_claims(heights: dict[str, float], where: str) -> list[str]:
    """One sentence per claim of :data:`HEIGHT_CLAIMS`, read on ``heights`` (name → m, only
    the jumps that converged and pass the gates); a claim with a jump missing is not read.
    ``where``: the words naming the jumps (e.g. "with strength limits")."""
    out = []
    for a, b, claim in HEIGHT_CLAIMS:
        if a in heights and b in heights:
            ra, rb = heights[a], heights[b]
            out.append(f"Thesis: {claim} — {where} {LABELS[a]} {100 * ra:.0f} cm, {LABELS[b]} "
                       f"{100 * rb:.0f} cm: {'holds' if rb > ra else 'does NOT hold'}.")
        else:
            out.append(f"Thesis: {claim} — not read: " + ", ".join(
                LABELS[n] for n in (a, b) if n not in heights) + " not converged or not valid.")
    return out


def strength_findings(sols: dict[str, JumpSolution], valid: dict[str, bool],
                      stand_ins: dict[str, JumpSolution] | None = None) -> list[str]:
    """The strength-limited jumps' sentences, computed: per jump convergence, validity and COM
    rise against :data:`HUMAN_JUMP_RISE_M`; the thesis's claims (toes raise the jump; the
    compliant contact raises it further and needs less friction) read on converged, valid
    jumps only. ``valid``: name → whether the jump passes the validity gates. ``stand_ins``
    (:func:`strength_stand_ins`): a jump whose own procedure did not converge is read through
    its stand-in, and its sentence names the procedure."""
    lo, hi = HUMAN_JUMP_RISE_M
    stand_ins = stand_ins or {}
    ok = {n: s for n, s in sols.items() if s.success and valid.get(n, False)}
    ok.update(stand_ins)
    out = []
    for n, s in sols.items():
        state = ("converged, valid" if s.success and valid.get(n, False) else
                 ("did NOT converge (" + s.status + ")") if not s.success else "converged, fails a validity gate")
        if n in stand_ins:
            s = stand_ins[n]
            state += f" with its own procedure; with {retry_label(s)}: converged, valid"
        r = s.jump_height["com_rise_flight"]
        out.append(f"**{s.spec.label}** ({state}): COM rise in flight {100 * r:.0f} cm — "
                   + ("inside" if lo <= r <= hi else "outside")
                   + f" the {100 * lo:.0f}–{100 * hi:.0f} cm of human standing jumps; take-off v_y "
                   f"{s.jump_height['takeoff_vy']:.2f} m/s; required μ_s {s.required_friction:.2f}.")
    out += height_claims({n: s.jump_height["com_rise_flight"] for n, s in ok.items()}, "with strength limits")
    if "ellipsoid" in ok and ({"toeless", "toe"} & set(ok)):
        mu_e = ok["ellipsoid"].required_friction
        welded = {n: ok[n].required_friction for n in ("toeless", "toe") if n in ok}
        out.append(f"Required friction: ellipsoid contact {mu_e:.2f} vs welded "
                   + ", ".join(f"{LABELS[n]} {v:.2f}" for n, v in welded.items())
                   + (" — less, as in the thesis." if mu_e < min(welded.values()) else " — NOT less, unlike the thesis."))
    return out


#: Other procedures tried for a strength-limited jump that did not converge with its own,
#: as (mesh continuation :attr:`JumpSpec.continuation`, IPOPT iteration limit or None for the
#: spec's, the welded foot's friction capped, the jump whose strength-limited solution starts
#: the full mesh (:attr:`JumpSpec.start_from`) or None, further IPOPT options): no
#: continuation (the full mesh from the box-limited start's guess); a 7-interval stage
#: instead of the 5-interval one; the same with three times the iterations; the spec's own
#: continuation with |F_x| ≤ μ F_y (:attr:`JumpSpec.friction_max`, μ the static friction
#: Sec 3.4.3 calls satisfactory for that welded model, :data:`THESIS`) — whether the
#: unbounded friction of a welded foot is what keeps IPOPT from converging; and that with
#: three times the iterations. Then the linear algebra and the start, one change at a time:
#: the spec's own procedure with MUMPS's pivot tolerance raised from IPOPT's 1e-6 to
#: :data:`PIVTOL` (more stable pivoting, so a more reliable inertia of the KKT matrix); the
#: full mesh started from the toeless jump's strength-limited solution (metatarsal joint at
#: 0: the foot flat on its toe); that start with the raised pivot tolerance; and that with
#: the friction cap.
PIVTOL = (("mumps_pivtol", 1e-2),)
STRENGTH_RETRIES = (((), None, False, None, ()), ((7,), None, False, None, ()), ((7,), 15000, False, None, ()),
                    ((5,), None, True, None, ()), ((5,), 15000, True, None, ()),
                    ((5,), None, False, None, PIVTOL), ((), None, False, "toeless", ()),
                    ((), None, False, "toeless", PIVTOL), ((), None, True, "toeless", PIVTOL))


def retry_spec(sp: JumpSpec, retry: tuple) -> JumpSpec | None:
    """``sp`` with one procedure of :data:`STRENGTH_RETRIES`; None when the procedure would
    start ``sp`` from its own model's solution."""
    c, it, cap, start, ipopt = retry
    if start == sp.name:
        return None
    return replace(sp, continuation=c, **({} if it is None else {"max_iter": it}),
                   **({"friction_max": THESIS[sp.name]["mu_s"]} if cap and sp.contact == "kinematic" else {}),
                   **({"start_from": start} if start else {}), **({"ipopt": sp.ipopt + ipopt} if ipopt else {}))


def strength_retries(sols: dict[str, JumpSolution], use_cache: bool = True) -> dict[str, dict[tuple, JumpSolution]]:
    """For every strength-limited jump in ``sols`` that did not converge: name → {procedure of
    :data:`STRENGTH_RETRIES`: the same spec solved with it} — whether the failure is the
    procedure's or the problem's. Cached like every jump."""
    return {n: {r: solve(retry_spec(s.spec, r), use_cache=use_cache) for r in STRENGTH_RETRIES
                if retry_spec(s.spec, r) is not None}
            for n, s in sols.items() if not s.success}


def strength_stand_ins(sols: dict[str, JumpSolution], retries: dict, valid: dict[str, bool]) -> dict[str, JumpSolution]:
    """Name → the stand-in of each strength-limited jump of ``sols`` that did not converge:
    of its :func:`strength_retries` that solve the same problem (a different procedure, not
    the friction cap) and converged and pass the validity gates (``valid``: solution → bool),
    the one with the lowest objective — the result its claims are read on, named wherever it
    is used (:func:`retry_label`)."""
    out = {}
    for n, per in retries.items():
        ok = [s for s in per.values() if s.success and s.spec.friction_max == sols[n].spec.friction_max and valid(s)]
        if ok:
            out[n] = min(ok, key=lambda x: x.solution.objective)
    return out


def retry_label(s: JumpSolution, own: bool = False) -> str:
    """The procedure of a strength-limited jump in words (continuation or start, friction cap,
    iteration limit, IPOPT options)."""
    sp = s.spec
    c = sp.continuation
    if sp.start_from is not None:
        t = f"the full mesh started from the {LABELS[sp.start_from]} jump's solution (same torque limits)"
    else:
        t = f"a {', '.join(map(str, c))}-interval continuation stage" if c else "no continuation"
    t += f", |F_x| ≤ {sp.friction_max:g} F_y" if sp.friction_max is not None else ""
    t += "".join(f", {k} {v:g}" for k, v in sp.ipopt)
    return t + (" (the spec's own)" if own else f", limit {sp.max_iter} iterations")


def strength_retry_table(sols: dict[str, JumpSolution], retries: dict) -> pd.DataFrame:
    """The spec's own continuation beside each retry of :func:`strength_retries`: status,
    iterations, largest constraint violation, COM rise in flight (cm), required μ_s."""
    rows = []
    for n, per in retries.items():
        for _, s in {"own": sols[n], **per}.items():
            c = s.spec.continuation
            rows.append({"jump": s.spec.label,
                         "start": (f"{s.spec.start_from} solution" if s.spec.start_from else
                                   ", ".join(map(str, c)) + "-interval stage" if c else "full mesh"),
                         "iteration limit": s.spec.max_iter, "friction cap μ": s.spec.friction_max,
                         "IPOPT options": ", ".join(f"{k} {v:g}" for k, v in s.spec.ipopt),
                         "IPOPT status": s.status, "iterations": s.stats["iterations"], "objective": s.solution.objective,
                         "max violation": s.solution.max_violation, "worst constraint": s.solution.worst_constraint,
                         "COM rise in flight (cm)": 100 * s.jump_height["com_rise_flight"],
                         "required μ_s": s.required_friction})
    return pd.DataFrame(rows)


def strength_retry_findings(sols: dict[str, JumpSolution], retries: dict) -> list[str]:
    """One sentence per jump of :func:`strength_retries`: the status of each procedure and,
    where one ended at a feasible point (largest violation ≤ 1e-6) without converging, its
    COM rise and required friction."""
    lab = retry_label
    out = []
    for n, per in retries.items():
        runs = {"own": sols[n], **per}
        parts = [f"{lab(s, k == 'own')}: {s.status} after {s.stats['iterations']} iterations" for k, s in runs.items()]
        feas = [s for s in runs.values() if not s.success and s.solution.max_violation <= 1e-6]
        line = f"**{sols[n].spec.label}** — " + "; ".join(parts) + "."
        conv = [s for s in per.values() if s.success]
        if conv:
            line += " Converged: " + "; ".join(
                f"with {lab(s)}, COM rise {100 * s.jump_height['com_rise_flight']:.0f} cm, take-off v_y "
                f"{s.jump_height['takeoff_vy']:.2f} m/s, required μ_s {s.required_friction:.1f} (objective "
                f"{s.solution.objective:.2f})" for s in sorted(conv, key=lambda x: x.solution.objective)) + "."
        elif feas:
            s = min(feas, key=lambda x: x.solution.objective)
            line += (f" With {lab(s)} it stopped at a feasible point (largest "
                     f"violation {s.solution.max_violation:.1e}; COM rise {100 * s.jump_height['com_rise_flight']:.0f} cm, "
                     f"required μ_s {s.required_friction:.1f}): the strength-limited problem has jumps, IPOPT did not "
                     "converge to one.")
        elif not any(s.success for s in runs.values()):
            line += " No procedure found a feasible point."
        out.append(line)
    return out


# --------------------------------------------------------------------------------------
# The take-off posture and the cost: what Table 3.9's take-off velocity term does
# --------------------------------------------------------------------------------------

#: The goal of Table 3.9's take-off velocity term, (v_des / v_y,COM(t_TO))² (the w1 term of
#: the welded jumps, the w3 term of the ellipsoid jump).
TAKEOFF_GOAL = "v_takeoff"
#: Where that term's weight is in :attr:`JumpSpec.weights`, by contact.
_TAKEOFF_WEIGHT = {"kinematic": 0, "ellipsoid": 2}
#: The factor on that weight in the apex-height variant (:func:`apex_cost_spec`): the term
#: scaled down, not removed, so the apex-height term dominates the objective while the problem
#: keeps the term's dependence on the take-off speed.
TAKEOFF_FACTOR = 0.01


def apex_cost_spec(sp: JumpSpec, factor: float = TAKEOFF_FACTOR) -> JumpSpec:
    """``sp`` with Table 3.9's take-off velocity term's weight × ``factor`` and every other
    term, bound and setting unchanged (ours, an ablation): the jump for the COM's apex height
    (the w2 / w4 term), which the thesis says the cost maximises. Started from the optimum of
    ``sp``'s own cost (:attr:`JumpSpec.start_weights`), so the one change is the cost."""
    w = list(sp.weights)
    w[_TAKEOFF_WEIGHT[sp.contact]] *= factor
    return replace(sp, weights=tuple(w), start_weights=tuple(sp.weights))


def solve_apex_cost(read: dict[str, JumpSolution], use_cache: bool = True) -> dict[str, JumpSolution]:
    """Name → the :func:`apex_cost_spec` of each jump in ``read`` (the solutions a chapter
    reads: each jump's own strength-limited solution or its stand-in), solved or reloaded."""
    return {n: solve(apex_cost_spec(s.spec), use_cache=use_cache) for n, s in read.items()}


#: The ``cost`` level of :func:`takeoff_table`'s index: the thesis's cost, ours scaled down.
TAKEOFF_COSTS = ("Table 3.9 (thesis)", f"take-off term × {TAKEOFF_FACTOR:g} (ours)")


def takeoff_state(s: JumpSolution) -> dict:
    """The take-off (the last node before the flight) of a jump beside its start (standing at
    rest): COM height above the standing COM (m, < 0: lower than standing), hip, knee and
    ankle angles (deg, thesis signs: hip > 0 flexion, knee < 0 flexion), take-off v_y (m/s),
    COM rise in flight and the apex above the standing COM (m), and the take-off velocity
    term's share of the objective (%, :data:`TAKEOFF_GOAL`)."""
    tr = s.trajectory
    to = tr[tr["phase"] != "flight"].iloc[-1]
    y0 = float(tr["com_y"].iloc[0])
    goals = pd.DataFrame(s.solution.goals)
    term = float(goals.loc[goals["goal"] == TAKEOFF_GOAL, "weighted"].sum())
    return {"com_takeoff": float(to["com_y"]) - y0, "hip": float(np.degrees(to["hip"])),
            "knee": float(np.degrees(to["knee"])), "ankle": float(np.degrees(to["ankle"])),
            "takeoff_vy": s.jump_height["takeoff_vy"], "rise_flight": s.jump_height["com_rise_flight"],
            "apex": s.jump_height["com_rise_standing"], "takeoff_share": 100 * term / float(s.solution.objective)}


def takeoff_table(read: dict[str, JumpSolution], apex: dict[str, JumpSolution],
                  gates: dict[str, str] | None = None) -> pd.DataFrame:
    """Per jump, Table 3.9's cost (``read``) beside its take-off term scaled down (``apex``,
    :func:`solve_apex_cost`): IPOPT status, iterations, the take-off of :func:`takeoff_state`
    in cm and degrees, and the validity gates (``gates``: ``"<name>"`` and ``"<name>, apex"``
    → label)."""
    rows = {}
    for n in read:
        for cost, s, g in zip(TAKEOFF_COSTS, (read[n], apex.get(n)), (n, f"{n}, apex")):
            if s is None:
                continue
            t = takeoff_state(s)
            rows[(s.spec.label, cost)] = {
                "IPOPT status": s.status, "iterations": s.stats["iterations"],
                "COM at take-off − standing (cm)": 100 * t["com_takeoff"],
                "hip at take-off (deg, > 0 flexed)": t["hip"], "knee at take-off (deg, < 0 flexed)": t["knee"],
                "take-off v_y,COM (m/s)": t["takeoff_vy"], "COM rise in flight (cm)": 100 * t["rise_flight"],
                "apex − standing COM (cm)": 100 * t["apex"],
                "take-off velocity term (% of the objective)": t["takeoff_share"],
                "gates": (gates or {}).get(g, ""),
            }
    out = pd.DataFrame(rows).T.infer_objects()
    out.index.names = ["jump", "cost"]
    return out


def takeoff_change(b: dict, a: dict) -> str:
    """How the take-off moves from ``b`` to ``a`` (two :func:`takeoff_state`), in words: COM at
    take-off and apex from the standing COM (cm), hip and knee (deg), COM rise in flight (cm)."""
    return (f"COM at take-off {100 * b['com_takeoff']:+.0f} → {100 * a['com_takeoff']:+.0f} cm from standing, hip "
            f"{b['hip']:.0f} → {a['hip']:.0f}°, knee {b['knee']:.0f} → {a['knee']:.0f}°; apex {100 * b['apex']:+.0f} → "
            f"{100 * a['apex']:+.0f} cm from the standing COM; COM rise in flight {100 * b['rise_flight']:.0f} → "
            f"{100 * a['rise_flight']:.0f} cm")


def takeoff_clause(read: JumpSolution, apex: JumpSolution | None, apex_valid: bool) -> str:
    """One clause for the report card (a strength-limited jump's row): its take-off under
    Table 3.9's cost and the take-off term's share of the objective, and, where its
    :func:`apex_cost_spec` jump converged and passes the gates, how the take-off moves."""
    b = takeoff_state(read)
    out = (f"leaves the ground crouched (COM {100 * b['com_takeoff']:+.0f} cm from standing, hip {b['hip']:.0f}°, knee "
           f"{b['knee']:.0f}°), Table 3.9's take-off velocity term {b['takeoff_share']:.0f} % of the objective")
    if apex is None:
        return out
    if not (apex.success and apex_valid):
        return out + f"; with it × {TAKEOFF_FACTOR:g}: {apex.status if not apex.success else 'fails a validity gate'}"
    return out + f"; with it × {TAKEOFF_FACTOR:g}: {takeoff_change(b, takeoff_state(apex))}"


def takeoff_findings(read: dict[str, JumpSolution], apex: dict[str, JumpSolution],
                     valid: dict[str, bool]) -> list[str]:
    """Sentences on :func:`takeoff_table`, every number computed: the take-off posture under
    Table 3.9's cost and the take-off velocity term's share of the objective; for each
    :func:`apex_cost_spec` jump that converged and passes the gates (``valid``: ``"<name>, apex"``
    → bool), how the take-off, the apex and the COM rise in flight move; what that says about
    the term."""
    t = {n: takeoff_state(s) for n, s in read.items()}

    def rng(key, scale=1.0, fmt="{:.0f}"):
        v = sorted(scale * x[key] for x in t.values())
        return fmt.format(v[0]) if len(v) == 1 or fmt.format(v[0]) == fmt.format(v[-1]) else \
            f"{fmt.format(v[0])} to {fmt.format(v[-1])}"
    out = [f"With Table 3.9's cost the strength-limited jumps leave the ground crouched: the COM "
           f"{rng('com_takeoff', -100)} cm below its standing height, the hips flexed {rng('hip')}°, the knees at "
           f"{rng('knee')}° (a human vertical jump leaves the ground with hips and knees nearly straight, e.g. Bobbert & "
           f"van Ingen Schenau 1988); the take-off velocity term is {rng('takeoff_share')} % of the objective."]
    ok = {n: s for n, s in apex.items() if s.success and valid.get(f"{n}, apex", False)}
    for n, s in apex.items():
        a = takeoff_state(s)
        lab = f"{s.spec.label}, take-off term × {TAKEOFF_FACTOR:g}"
        if n not in ok:
            out.append(f"{lab}: {'did NOT converge (' + s.status + ')' if not s.success else 'fails a validity gate'} — not read.")
            continue
        out.append(f"{lab} (converged, valid): {takeoff_change(t[n], a)}.")
    if ok:
        higher = [n for n in ok if takeoff_state(ok[n])["apex"] > t[n]["apex"]]
        straighter = [n for n in ok if takeoff_state(ok[n])["com_takeoff"] > t[n]["com_takeoff"]]
        higher_flight = [n for n in ok if takeoff_state(ok[n])["rise_flight"] > t[n]["rise_flight"]]
        out.append(f"With the take-off velocity term × {TAKEOFF_FACTOR:g} the apex is higher in {len(higher)} of "
                   f"{len(ok)} jumps and the take-off less crouched in {len(straighter)} of {len(ok)}"
                   + (": the term, not the strength envelope, puts the take-off in a crouch — it rewards the vertical "
                      "speed at take-off whatever the posture, and the apex the thesis says its cost maximises is lower "
                      "with it" if len(higher) == len(straighter) == len(ok) else "")
                   + f". The COM rise in flight (our reading of the thesis's jump height) is higher with it scaled down in "
                   f"{len(higher_flight)} of {len(ok)} ("
                   + ", ".join(f"{ok[n].spec.label} {100 * t[n]['rise_flight']:.0f} → "
                               f"{100 * takeoff_state(ok[n])['rise_flight']:.0f} cm" for n in ok) + ").")
        out += height_claims({n: takeoff_state(x)["apex"] for n, x in ok.items()},
                             f"with the take-off term × {TAKEOFF_FACTOR:g}, apex above the standing COM:")
    return out
