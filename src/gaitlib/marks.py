"""Marks that keep a failed result from looking like a result.

A solve whose IPOPT status is not a converged one (:data:`CONVERGED`) — and, once a
validity check says so, a physically invalid solution — gets a *failure label*
(:func:`failure_label`, e.g. ``"NOT CONVERGED: Maximum_Iterations_Exceeded"``). Every
figure and table that shows such a solution carries that label where the result is drawn:

- axes: a red diagonal watermark with the label and a red frame (:func:`mark_axes`);
- figures: a red title prefix (:func:`mark_figure`);
- bars: red hatching (:func:`mark_bars`), with a legend entry (:func:`bar_legend_handle`);
- curves: dashed, their legend entry suffixed with ``† label`` (:func:`run_label`);
- tables: a ``mark`` column and ``†`` after the row label (:func:`mark_table`,
  :func:`mark_rows` for a table of one solve);
- a figure of one solve drawn elsewhere: :func:`mark_all`.

Headline numbers are computed from unmarked runs only (:func:`unmarked`).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping
from . import validity

__all__ = ["CONVERGED", "MARK_COLOR", "HATCH", "DAGGER", "MARK_GID", "status_of", "failure_label",
           "use_validity_check",
           "run_label", "joint_label", "mark_axes", "mark_figure", "mark_all", "mark_bars", "bar_legend_handle", "mark_table",
           "mark_rows", "unmarked", "marks_in"]

#: IPOPT return statuses counted as converged (as :data:`gaitlib.sweep.ACCEPTED_STATUSES`).
CONVERGED = frozenset({"Solve_Succeeded", "Solved_To_Acceptable_Level"})
MARK_COLOR = "#d62728"
HATCH = "////"
DAGGER = "†"
#: ``gid`` of every artist a mark adds (how tests and readers find them).
MARK_GID = "failure-mark"


def status_of(obj) -> tuple[bool | None, str | None]:
    """(converged, IPOPT status) of a solve outcome; (None, None) when ``obj`` says nothing.

    ``obj``: an IPOPT status string; a stats mapping (``status``, ``success``); or an object
    with ``stats`` (GaitSolution), ``ok``/``status`` (sweep RunRecord) or
    ``success``/``status`` (ocp Solution, JumpSolution). A ``success`` flag, where given,
    decides; otherwise the status must be one of :data:`CONVERGED`.
    """
    if obj is None:
        return None, None
    if isinstance(obj, str):
        return obj in CONVERGED, obj
    stats = obj if isinstance(obj, Mapping) else getattr(obj, "stats", None)
    status = success = None
    if isinstance(stats, Mapping):
        status, success = stats.get("status"), stats.get("success")
    if status is None and isinstance(getattr(obj, "status", None), str):
        status = obj.status
    if success is None:
        for attr in ("ok", "success"):
            v = getattr(obj, attr, None)
            if isinstance(v, bool):
                success = v
                break
    if success is None and status is None:
        return None, None
    if success is None:
        success = status in CONVERGED
    return bool(success), None if status is None else str(status)


_verdicts: dict = {}


def validity_verdict(obj):
    """The physical validity gates' verdict on a solution (:func:`gaitlib.validity.check`):
    True (valid), the invalid reasons as text (without the convergence check, which
    :func:`status_of` reports), or None when ``obj`` is no solution the gates can judge (a
    status string, a stats mapping). A sweep record is judged by its solution. Memoised per
    object (the gates take a fraction of a second; a figure asks several times)."""
    obj = getattr(obj, "value", obj) if hasattr(obj, "ok") and hasattr(obj, "value") else obj
    if obj is None or isinstance(obj, (str, Mapping)) or not (hasattr(obj, "spec") or hasattr(obj, "solution")):
        return None
    hit = _verdicts.get(id(obj))
    if hit is not None and hit[0] is obj:
        return hit[1]

    try:
        lab = validity.check(obj).label()
    except (TypeError, ValueError, KeyError, AttributeError):
        verdict = None  # not a kind of solution the gates know
    else:
        verdict = lab.split("invalid: ", 1)[1] if "invalid: " in lab else True
    _verdicts[id(obj)] = (obj, verdict)
    return verdict


#: The physical-validity check :func:`failure_label` applies when it is given no ``valid``
#: (see :func:`use_validity_check`): the validity gates by default; None: no check.
_validity_check = validity_verdict


def use_validity_check(check) -> None:
    """Make every :func:`failure_label` call without ``valid`` ask ``check(obj)`` for the
    verdict (a callable taking a solution, a run record or a status and returning what
    ``valid`` accepts, or None when it cannot judge ``obj``); ``None`` removes the check.
    This is how the physical validity gates reach every figure and table at once."""
    global _validity_check
    _validity_check = check


def failure_label(obj, valid=None) -> str | None:
    """Why a result must not be read as one, or None if nothing is known against it.

    ``obj``: anything :func:`status_of` reads. ``valid``: the physical validity verdict —
    None (not checked), True, False, a reason string (invalid because …) or an object with
    a boolean ``ok`` and optionally ``reason``. Returns e.g.
    ``"NOT CONVERGED: Maximum_Iterations_Exceeded"``, ``"INVALID: foot loaded in swing"``
    or both joined by ``"; "``.
    """
    if valid is None and _validity_check is not None and obj is not None:
        valid = _validity_check(obj)
    reasons = []
    conv, status = status_of(obj)
    if conv is False:
        reasons.append(f"NOT CONVERGED: {status or 'unknown status'}")
    if valid is not None and not isinstance(valid, (bool, str)):
        ok = getattr(valid, "ok", None)
        valid = True if ok else (getattr(valid, "reason", None) or False)
    if valid is False:
        reasons.append("INVALID")
    elif isinstance(valid, str) and valid:
        reasons.append(f"INVALID: {valid}")
    return "; ".join(reasons) or None


def mark_kinds(label: str | None) -> list[str]:
    """The kinds of a :func:`failure_label` in order (``"NOT CONVERGED"``, ``"INVALID"``), without
    their reasons — an invalid run's reasons are themselves joined by ``"; "``. A
    :func:`gaitlib.validity.label` (``"not converged (…)"``, ``"invalid: …"``) reads the same."""
    parts = [p.split(":")[0].split("(")[0].strip().upper() for p in (label or "").split(";")]
    return list(dict.fromkeys(p for p in parts if p in ("NOT CONVERGED", "INVALID")))


def run_label(name: str, label: str | None) -> str:
    """A run's name as shown in legends and tables: ``"NMSK SDT3 † NOT CONVERGED: …"``."""
    return f"{name} {DAGGER} {label}" if label else str(name)


def joint_label(labels: Mapping, named: bool = True) -> str | None:
    """The failure labels of several runs (``{run: label or None}``) as one text, one line
    per marked run (``"run: label"``; just the label when ``named`` is False and one run is
    marked); None when none is marked."""
    bad = [(k, v) for k, v in labels.items() if v]
    if not bad:
        return None
    if len(bad) == 1 and not named:
        return bad[0][1]
    return "\n".join(f"{k}: {v}" for k, v in bad)


def _axes_size_pt(ax) -> tuple[float, float]:
    fig = ax.figure
    bb = ax.get_position()
    w, h = fig.get_size_inches()
    return 72.0 * bb.width * w, 72.0 * bb.height * h


def mark_axes(ax, label: str | None, *, fontsize: float | None = None):
    """Write ``label`` as a red diagonal watermark across ``ax`` (corner to corner, above
    the data) and draw the axes frame red. Returns the Text artist (``gid`` =
    :data:`MARK_GID`), or None when ``label`` is empty."""
    if not label:
        return None
    w, h = _axes_size_pt(ax)
    angle = math.degrees(math.atan2(h, w)) if w > 0 and h > 0 else 30.0
    diag = math.hypot(w, h) if w > 0 and h > 0 else 200.0
    if fontsize is None:  # the label spans about 85 % of the diagonal (≈ 0.6 em per character)
        fontsize = max(5.0, min(16.0, 0.85 * diag / (0.6 * max(len(label), 1))))
    fit = int(0.85 * diag / (0.6 * fontsize))  # characters that fit along the diagonal
    if len(label) > fit:  # never wider than the axes (it would widen a saved figure); the
        label = label[:max(fit - 1, 1)].rstrip() + "…"  # figure's title carries the whole text
    txt = ax.text(0.5, 0.5, label, transform=ax.transAxes, rotation=angle, rotation_mode="anchor",
                  ha="center", va="center", color=MARK_COLOR, alpha=0.55, fontsize=fontsize,
                  fontweight="bold", zorder=100, clip_on=False, gid=MARK_GID)
    for sp in ax.spines.values():
        sp.set_edgecolor(MARK_COLOR)
        sp.set_linewidth(1.6)
    return txt


def mark_figure(fig, label: str | None):
    """Prefix the figure's title with ``label`` in red (a title is added if there is none).
    Returns the title Text, or None when ``label`` is empty."""
    if not label:
        return None
    old = fig._suptitle.get_text() if getattr(fig, "_suptitle", None) is not None else ""
    size = fig._suptitle.get_fontsize() if old else 10
    sep = "\n" if len(label) + len(old) > 70 else " — "
    # wrapped to the figure's width (bold: ≈ 0.65 em per character): a long label (many
    # marked runs) must not widen the saved figure beyond its axes
    width = max(40, int(fig.get_size_inches()[0] * 72.0 / (0.65 * size)))
    label = textwrap.fill(label, width=width)
    t = fig.suptitle(f"{label}{sep}{old}" if old else label, color=MARK_COLOR, fontsize=size,
                     fontweight="bold")
    t.set_gid(MARK_GID)
    return t


def mark_bars(bars, label: str | None):
    """Hatch the bars (a BarContainer or patches) red; their ``gid`` becomes
    :data:`MARK_GID`. Nothing happens when ``label`` is empty."""
    if not label:
        return bars
    for p in bars:
        p.set_hatch(HATCH)
        p.set_edgecolor(MARK_COLOR)
        p.set_linewidth(0.8)
        p.set_gid(MARK_GID)
    return bars


def bar_legend_handle(text: str = f"{DAGGER} hatched: NOT CONVERGED"):
    """A legend patch explaining the hatching of :func:`mark_bars`."""
    from matplotlib.patches import Patch

    return Patch(facecolor="white", edgecolor=MARK_COLOR, hatch=HATCH, label=text)


def _dagger(key):
    if isinstance(key, tuple):
        return key[:-1] + (f"{key[-1]} {DAGGER}",)
    return f"{key} {DAGGER}"


def mark_table(df, labels: Mapping, column: str = "mark"):
    """A copy of ``df`` with a first column ``column`` holding each row's failure label
    (``labels``: row key → label or None; rows not in it are unmarked) and ``†`` after the
    label of every marked row (for a MultiIndex, after its last level)."""
    out = df.copy()
    col = [labels.get(k) or "" for k in out.index]
    out.insert(0, column, col)
    out.index = out.index.map(lambda k: _dagger(k) if labels.get(k) else k)
    return out


def mark_all(fig, label: str | None):
    """Mark a whole figure that shows one solve: a watermark on every axes that draws
    something (:func:`mark_axes`) and the red title prefix (:func:`mark_figure`). Returns
    ``fig``; nothing happens when ``label`` is empty."""
    if label:
        for ax in fig.axes:
            if ax.axison and (ax.lines or ax.patches or ax.collections or ax.images):
                mark_axes(ax, label)
        mark_figure(fig, label)
    return fig


def mark_rows(df, label: str | None, column: str = "mark"):
    """A table that comes from one solve: every row marked with ``label``
    (:func:`mark_table`); ``df`` itself when ``label`` is empty."""
    if not label:
        return df
    return mark_table(df, {k: label for k in df.index}, column)


def unmarked(df, column: str = "mark"):
    """Rows of ``df`` whose ``column`` is empty (None, NaN or "") — what a headline may use."""
    if column not in df.columns:
        return df
    m = df[column]
    return df[m.isna() | (m.astype(str) == "")]


def marks_in(fig) -> list:
    """Every artist of ``fig`` a mark added (``gid`` = :data:`MARK_GID`)."""
    return [a for a in fig.findobj() if getattr(a, "get_gid", lambda: None)() == MARK_GID]
