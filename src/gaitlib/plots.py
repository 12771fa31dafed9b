"""Figures every chapter reuses: ±1 SD bands of data against simulated curves.

Degrees, % of the gait cycle and body-weight-normalised units appear only here, at the
edge; every input is SI (see :mod:`gaitlib.conventions`).
"""

from __future__ import annotations

import re
import textwrap

import numpy as np

from . import conventions as cv
from .kinematics import shape_matrix
from .kinematics import ellipsoid_bottom, ellipsoid_radii
from .model import ELLIPSOID_LABELS
from . import contact
from . import marks as mk
from .model import ChildModel

#: How a model channel is shown: (label, scale from SI, display unit).
DISPLAY = {
    "pelvis_tilt": ("HAT / pelvis tilt", 1 / cv.DEG, "deg"),
    "hip": ("hip angle (+ flexion)", 1 / cv.DEG, "deg"),
    "knee": ("knee angle (− flexion)", 1 / cv.DEG, "deg"),
    "ankle": ("ankle angle (+ dorsiflexion)", 1 / cv.DEG, "deg"),
    "mtp": ("metatarsal angle (+ toe extension)", 1 / cv.DEG, "deg"),
    "tau_hip": ("hip torque (+ flexor)", 1.0, "N·m"),
    "tau_knee": ("knee torque (+ extensor)", 1.0, "N·m"),
    "tau_ankle": ("ankle torque (+ dorsiflexor)", 1.0, "N·m"),
    "tau_mtp": ("metatarsal torque", 1.0, "N·m"),
    "pow_hip": ("hip power", 1.0, "W"),
    "pow_knee": ("knee power", 1.0, "W"),
    "pow_ankle": ("ankle power", 1.0, "W"),
    "grf_x": ("GRF anterior–posterior", 1.0, "N"),
    "grf_y": ("GRF vertical", 1.0, "N"),
}


def channel_display(channel: str) -> tuple[str, float, str]:
    """(label, scale, unit) for a model channel such as ``knee_r`` or ``emg_TA_l``."""
    stem = channel[:-2] if channel.endswith(("_r", "_l")) else channel
    if stem in DISPLAY:
        return DISPLAY[stem]
    if stem.startswith("emg_"):
        return (f"EMG {stem[4:]}", 1.0, "normalised")
    return (stem, 1.0, "")


def _panel_grid(n: int, ncols: int, figsize_per):
    """A grid of ``n`` panels (figure, axes array), constrained layout."""
    import matplotlib.pyplot as plt

    nrows = int(np.ceil(n / ncols))
    return plt.subplots(nrows, ncols, figsize=(figsize_per[0] * ncols, figsize_per[1] * nrows),
                        squeeze=False, constrained_layout=True)


def _label_panel(ax, channel: str, unit: str, name: str):
    side = {"_r": " (right)", "_l": " (left)"}.get(channel[-2:], "")
    ax.set_title(name + side, fontsize=9)
    ax.set_ylabel(unit, fontsize=8)
    ax.set_xlim(0, 100)
    ax.tick_params(labelsize=7)


def _legend_layout(fig, labels, fontsize: float = 8.0, max_cols: int = 5):
    """Labels wrapped to the figure's width and the number of legend columns that fits in
    it (≈ 0.55 em per character, 30 pt per handle): a legend never widens a saved figure."""
    width_pt = fig.get_size_inches()[0] * 72.0
    chars = max(20, int((width_pt - 40.0) / (0.55 * fontsize)))
    wrapped = [textwrap.fill(str(lab), width=chars) for lab in labels]
    widths = [30.0 + 0.55 * fontsize * max(len(line) for line in lab.splitlines() or [""]) for lab in wrapped]
    ncols = 1
    for k in range(min(len(wrapped), max_cols), 0, -1):
        if sum(sorted(widths, reverse=True)[:k]) <= width_pt:
            ncols = k
            break
    return wrapped, ncols


def fit_decorations(fig, nrows: int, min_panel: float = 1.4):
    """Make ``fig`` tall enough for its title and legends beside ``nrows`` rows of panels at
    least ``min_panel`` inches high (≈ 1.35 × font size per text line): a marked title and a
    wrapped legend on a one-row figure must not squeeze its axes to nothing (constrained
    layout then gives up and the panels overlap)."""
    deco = 0.0
    st = getattr(fig, "_suptitle", None)
    if st is not None and st.get_text():
        deco += len(st.get_text().splitlines()) * st.get_fontsize() * 1.35 + 6.0
    for leg in fig.legends:
        texts = leg.get_texts()
        if not texts:
            continue
        ncols = max(1, int(getattr(leg, "_ncols", 1)))
        lines = [len(t.get_text().splitlines()) or 1 for t in texts]
        rows = int(np.ceil(len(lines) / ncols))
        # column-major: column c holds labels c*rows … (c+1)*rows − 1; a row is as tall as its tallest label
        per_row = [max(lines[c * rows + r] for c in range(ncols) if c * rows + r < len(lines)) for r in range(rows)]
        deco += sum(per_row) * texts[0].get_fontsize() * 1.35 + 10.0
    w, h = fig.get_size_inches()
    need = nrows * min_panel + deco / 72.0 + 0.35  # + the x labels
    if h < need:
        fig.set_size_inches(w, need)
    return fig


def _finish_panels(fig, axes, n: int, title=None):
    """Hide unused panels, label the x axes (% gait cycle), one legend, a title."""
    for ax in axes.flat[n:]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("% gait cycle", fontsize=8)
    handles, labs = axes.flat[0].get_legend_handles_labels()
    if handles:
        labs, ncols = _legend_layout(fig, labs)
        fig.legend(handles, labs, loc="outside lower center", ncols=ncols, fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def band(ax, x, mean, sd, color="0.6", label=None, alpha=0.35, line=True):
    """Draw mean ± 1 SD as a shaded band (and the mean as a dotted line)."""
    x, mean, sd = (np.asarray(v, dtype=float) for v in (x, mean, sd))
    ax.fill_between(x, mean - sd, mean + sd, color=color, alpha=alpha, lw=0, label=label)
    if line:
        ax.plot(x, mean, color=color, lw=1.0, ls=":")


def data_bands(datasets: dict, channels, ncols: int = 3, colors=None, figsize_per=(3.6, 2.4),
               title=None):
    """One panel per channel with a ±1 SD band for each data set.

    Parameters
    ----------
    datasets : ``{label: GaitData}``; x axis is % of the gait cycle, so data sets with
        different cycle times share it.
    channels : model channel names (e.g. ``"knee_r"``), drawn in display units.
    """
    import matplotlib.pyplot as plt

    channels = list(channels)
    fig, axes = _panel_grid(len(channels), ncols, figsize_per)
    cmap = plt.get_cmap("viridis")
    labels = list(datasets)
    if colors is None:
        colors = {lab: cmap(i / max(1, len(labels) - 1)) for i, lab in enumerate(labels)}
    for ax, ch in zip(axes.flat, channels):
        name, scale, unit = channel_display(ch)
        for lab, d in datasets.items():
            if ch not in d.mean:
                continue
            pct = 100 * d.time / d.cycle_time
            band(ax, pct, scale * d.mean[ch], scale * d.sd[ch], color=colors[lab], label=lab, alpha=0.25)
        _label_panel(ax, ch, unit, name)
    return _finish_panels(fig, axes, len(channels), title)


# =====================================================================================
# Stick figures and animations (child gait model, jump models)
# =====================================================================================

#: Colours of the stick figure: HAT / trunk, right leg, left leg, ground reaction forces.
FIGURE_COLORS = {"hat": "0.15", "r": "tab:red", "l": "tab:blue", "grf": "tab:green",
                 "ground": "0.35", "jump": "tab:purple"}


def ellipse_outline(centre, R, radii, n: int = 64) -> np.ndarray:
    """Outline (n, 2) of the orthographic projection of an ellipsoid on the X–Y plane, m.

    The ellipsoid ``{c + R D u : |u| ≤ 1}`` (``R`` ellipsoid → ground, ``D = diag(a, b, c)``)
    projects onto the ellipse ``{x : (x − c_xy)ᵀ A⁻¹ (x − c_xy) ≤ 1}`` whose shape matrix
    ``A`` is the top-left 2×2 block of ``R D² Rᵀ``; its outline is ``c_xy + A^½ (cos s, sin s)``.
    """
    A = shape_matrix(R, radii)[:2, :2]
    w, V = np.linalg.eigh(A)
    half = V @ np.diag(np.sqrt(np.clip(w, 0.0, None))) @ V.T  # symmetric square root
    s = np.linspace(0.0, 2.0 * np.pi, n)
    return np.asarray(centre, dtype=float)[:2] + (half @ np.vstack([np.cos(s), np.sin(s)])).T


def _line(ax, pts, color, lw=2.5, **kw):
    (ln,) = ax.plot(pts[:, 0], pts[:, 1], color=color, lw=lw, solid_capstyle="round",
                    marker="o", ms=lw * 1.2, **kw)
    return ln


def _set_line(ln, pts):
    ln.set_data(pts[:, 0], pts[:, 1])


def _ellipse_patch(ax, color, alpha=0.25):
    from matplotlib.patches import Polygon

    p = Polygon(np.zeros((3, 2)), closed=True, facecolor=color, edgecolor=color,
                alpha=alpha, lw=0.8)
    ax.add_patch(p)
    return p


def _arrow(ax, color):
    from matplotlib.patches import FancyArrowPatch

    a = FancyArrowPatch((0, 0), (0, 0), arrowstyle="-|>", mutation_scale=12, color=color,
                        lw=2.0, zorder=5)
    ax.add_patch(a)
    return a


def _set_arrow(arrow, start, vec, visible=True):
    arrow.set_positions(tuple(start), (start[0] + vec[0], start[1] + vec[1]))
    arrow.set_visible(bool(visible))


def _ground(ax):
    return ax.axhline(0.0, color=FIGURE_COLORS["ground"], lw=1.2, zorder=0)


def _chains(segments: dict) -> dict:
    """Group a model's two-point segments into polylines per colour key."""
    out = {"hat": segments["hat"]}
    for s in cv.SIDES:
        # hip → knee → ankle → heel → mtp → ankle, and mtp → toe tip
        out[f"leg_{s}"] = np.vstack([segments[f"thigh_{s}"], segments[f"shank_{s}"][1:],
                                     segments[f"hindfoot_{s}"][1:], segments[f"sole_{s}"][1:],
                                     segments[f"forefoot_{s}"][:1]])
        out[f"toe_{s}"] = segments[f"toe_{s}"]
    return out


def _chain_color(name: str) -> str:
    return FIGURE_COLORS["hat"] if name == "hat" else FIGURE_COLORS[name[-1]]


def default_grf_scale(model) -> float:
    """GRF arrow scale, m per N: one body weight is drawn 0.5 m long."""
    return 0.5 / (model.body_mass * model.g)


def model_frame(model, q, qd=None, p_contact=None, p_body=None) -> dict:
    """Everything :func:`draw_model` draws for one pose, in numbers.

    Returns a dict with ``chains`` (name → (k, 2) polylines: ``hat``, ``leg_r``, ``toe_r``,
    ``leg_l``, ``toe_l``), ``ellipses`` (label → (n, 2) outlines, order
    :data:`gaitlib.model.ELLIPSOID_LABELS`), ``contact`` (the :meth:`ChildModel.contact`
    outputs) and ``bottoms`` (6,) lowest ellipsoid points, m.
    """
    q = np.asarray(q, dtype=float)
    qd = np.zeros_like(q) if qd is None else np.asarray(qd, dtype=float)
    segs = model.segments(q, p_body)
    centres, Rs = model.ellipsoid_poses(q, p_contact)
    radii = ellipsoid_radii(p_contact)
    return {
        "chains": _chains(segs),
        "ellipses": {lab: ellipse_outline(c, R, r) for lab, c, R, r in
                     zip(ELLIPSOID_LABELS, centres, Rs, radii)},
        "bottoms": np.array([ellipsoid_bottom(c, R, r) for c, R, r in zip(centres, Rs, radii)]),
        "contact": model.contact(q, qd, p_contact),
    }


def update_model(artists: dict, model, q, qd=None, p_contact=None, p_body=None) -> list:
    """Move the artists returned by :func:`draw_model` to pose ``q`` (and ``qd``).

    Returns the list of changed artists (for ``FuncAnimation(blit=True)``).
    """
    fr = model_frame(model, q, qd, p_contact, p_body)
    changed = []
    for name, ln in artists["chains"].items():
        _set_line(ln, fr["chains"][name])
        changed.append(ln)
    for lab, patch in artists["ellipsoids"].items():
        patch.set_xy(fr["ellipses"][lab])
        changed.append(patch)
    scale = artists["grf_scale"]
    c = fr["contact"]
    for i, s in enumerate(cv.SIDES):
        if s not in artists["grf"]:
            continue
        fy, fx, cop = float(c["grf_y"][i]), float(c["grf_x"][i]), float(c["cop_x"][i])
        _set_arrow(artists["grf"][s], (cop, 0.0), (scale * fx, scale * fy),
                   visible=fy > artists["grf_min"])
        changed.append(artists["grf"][s])
    artists["frame"] = fr
    return changed


def draw_model(ax, model, q, qd=None, p_contact=None, p_body=None, grf=True, ellipsoids=True,
               grf_scale=None, grf_min=None, ground=True, ellipse_alpha=0.25,
               lw=2.5) -> dict:
    """Draw the 11-DOF child model at pose ``q`` on ``ax`` (sagittal view, metres).

    Parameters
    ----------
    ax : matplotlib Axes (its aspect is set to equal).
    model : gaitlib.model.ChildModel
    q, qd : (11,) pose and velocity (``qd`` default zeros; it only matters for the GRF,
        through contact damping and friction).
    p_contact, p_body : parameter vectors (defaults of the model).
    grf : draw each foot's ground reaction force (sum of its three ellipsoids,
        :meth:`ChildModel.contact`) as an arrow from its centre of pressure on the ground,
        ``grf_scale`` m per N (default :func:`default_grf_scale`: 1 BW ↦ 0.5 m); hidden
        while the foot's vertical force is below ``grf_min`` N (default 4 % of the body
        weight, below which the arrow would be shorter than its head).
    ellipsoids : draw the six contact ellipsoids as their exact sagittal outlines
        (:func:`ellipse_outline`).
    ground : draw the ground line y = 0.

    HAT in dark grey, right leg red, left leg blue (:data:`FIGURE_COLORS`).

    Returns
    -------
    dict of artists: ``chains`` (name → Line2D), ``ellipsoids`` (label → Polygon), ``grf``
    (side → FancyArrowPatch), ``ground`` and the numbers drawn (``frame``, see
    :func:`model_frame`). Pass it to :func:`update_model` to move the figure.
    """
    if grf_min is None:
        grf_min = 0.04 * model.body_mass * model.g
    artists = {"chains": {}, "ellipsoids": {}, "grf": {}, "grf_min": grf_min,
               "grf_scale": default_grf_scale(model) if grf_scale is None else grf_scale}
    artists["ground"] = _ground(ax) if ground else None
    if ellipsoids:
        for lab in ELLIPSOID_LABELS:
            artists["ellipsoids"][lab] = _ellipse_patch(ax, FIGURE_COLORS[lab[-1]], ellipse_alpha)
    # left leg behind (drawn first), then HAT, then right leg
    for name in ("leg_l", "toe_l", "hat", "leg_r", "toe_r"):
        artists["chains"][name] = _line(ax, np.zeros((2, 2)), _chain_color(name), lw=lw)
    if grf:
        for s in cv.SIDES:
            artists["grf"][s] = _arrow(ax, FIGURE_COLORS["grf"])
    update_model(artists, model, q, qd, p_contact, p_body)
    ax.relim()
    ax.autoscale_view()
    ax.set_aspect("equal")
    return artists


def _jump_full_q(jump_model, q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.size == len(jump_model.joints):  # welded phase: root at the standing pose
        q = np.concatenate([np.zeros(3), q])
    return q


def jump_frame(jump_model, q, p_contact=None, ellipsoids=None) -> dict:
    """Numbers :func:`draw_jump` draws: ``chains`` (one polyline toe tip → MTP → ankle →
    knee → hip → head) and ``ellipses`` (toe, ball, heel outlines; toe-included model)."""
    q = _jump_full_q(jump_model, q)
    P = jump_model.points(q)
    order = (["toe_tip"] if jump_model.toe else []) + ["mtp", "ankle", "knee", "hip", "head"]
    out = {"chains": {"body": np.vstack([P[k] for k in order])}, "ellipses": {}}
    if ellipsoids is None:
        ellipsoids = jump_model.toe
    if ellipsoids and jump_model.toe:
        pc = contact.default_params() if p_contact is None else np.asarray(p_contact, float)
        res = jump_model.function("ellipsoids")(q, pc)
        C = np.asarray(res[0])
        for k, e in enumerate(cv.ELLIPSOIDS):
            out["ellipses"][e] = ellipse_outline(C[k], np.asarray(res[1 + k]),
                                                 ellipsoid_radii(pc)[k])
    return out


def draw_jump(ax, jump_model, q, p_contact=None, ellipsoids=None, ground=True, lw=2.5,
              color=None) -> dict:
    """Draw a vertical-jump model (:class:`gaitlib.jump.JumpModel`) at pose ``q``.

    ``q`` is either the free coordinates ``(x, y, theta_z, joints…)`` or, for the welded
    phase, the joint angles only (root at the standing pose). The toe-included model also
    shows its three contact ellipsoids (``ellipsoids=None``: whenever the model has a toe).
    Uses the same drawing helpers as :func:`draw_model`; returns the artists dict
    (``chains``, ``ellipsoids``, ``ground``, ``frame``).
    """
    color = FIGURE_COLORS["jump"] if color is None else color
    fr = jump_frame(jump_model, q, p_contact, ellipsoids)
    artists = {"ground": _ground(ax) if ground else None, "frame": fr,
               "ellipsoids": {e: _ellipse_patch(ax, color) for e in fr["ellipses"]},
               "chains": {"body": _line(ax, fr["chains"]["body"], color, lw=lw)}}
    for e, patch in artists["ellipsoids"].items():
        patch.set_xy(fr["ellipses"][e])
    ax.relim()
    ax.autoscale_view()
    ax.set_aspect("equal")
    return artists


def _pick_frames(n: int, max_frames: int) -> np.ndarray:
    if n <= max_frames:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_frames)).astype(int))


def animate_gait(model, t, Q, Qd=None, p_contact=None, p_body=None, fps: float = 12,
                 interval=None, max_frames: int = 50, camera: str = "stride",
                 window: float = 1.6, figsize=(6.0, 4.0), dpi: int = 72, grf=True,
                 ellipsoids=True, grf_scale=None, title=None, mark=None):
    """Animate a gait trajectory of the child model.

    Parameters
    ----------
    model : gaitlib.model.ChildModel
    t : (n,) s; Q : (n, 11) poses; Qd : (n, 11) velocities (default: ``np.gradient`` of Q;
        only the GRF arrows use them).
    fps, interval : frames per second, or the interval between frames in ms (overrides fps).
    max_frames : at most this many frames, evenly spaced over ``t`` (keeps
        :func:`animation_html` small: ≈ 20–40 kB per frame at the default size).
    camera : ``"stride"`` (default) — fixed axes showing the whole motion (every point of
        every frame plus margins), so progression is visible; ``"pelvis"`` — a window of
        fixed width ``window`` m centred on the pelvis, moving with it (axes limits change
        every frame, their size does not). The vertical limits are fixed over the motion in
        both cases.
    grf, ellipsoids, grf_scale : as :func:`draw_model`.
    mark : the solve's failure label (:func:`gaitlib.marks.failure_label`), written as a
        red watermark across every frame; None for a converged solve.

    Returns
    -------
    matplotlib.animation.FuncAnimation (its figure is ``anim._fig``; the frame indices into
    ``t`` are ``anim.frame_indices``).
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    t = np.asarray(t, dtype=float)
    Q = np.asarray(Q, dtype=float)
    if Qd is None:
        Qd = np.gradient(Q, t, axis=0) if len(t) > 1 else np.zeros_like(Q)
    idx = _pick_frames(len(t), max_frames)
    frames = [model_frame(model, Q[i], Qd[i], p_contact, p_body) for i in idx]
    pts = np.vstack([np.vstack(list(f["chains"].values()) + list(f["ellipses"].values()))
                     for f in frames])
    pad = 0.08
    ylo, yhi = min(pts[:, 1].min(), 0.0) - pad, pts[:, 1].max() + pad
    if camera == "stride":
        xlim = (pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    elif camera != "pelvis":
        raise ValueError("camera must be 'stride' or 'pelvis'")

    fig, ax = plt.subplots(figsize=figsize, dpi=dpi, constrained_layout=True)
    artists = draw_model(ax, model, Q[idx[0]], Qd[idx[0]], p_contact, p_body, grf=grf,
                         ellipsoids=ellipsoids, grf_scale=grf_scale)
    ax.set_ylim(ylo, yhi)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    label = ax.text(0.02, 0.96, "", transform=ax.transAxes, va="top", fontsize=9)
    if title:
        ax.set_title(title, fontsize=10)
    _mark_animation(ax, mark)

    def update(k):
        i = idx[k]
        changed = update_model(artists, model, Q[i], Qd[i], p_contact, p_body)
        if camera == "pelvis":
            ax.set_xlim(Q[i, 0] - window / 2, Q[i, 0] + window / 2)
        else:
            ax.set_xlim(*xlim)
        label.set_text(f"t = {t[i]:.3f} s")
        return changed + [label]

    update(0)
    interval = 1000.0 / fps if interval is None else interval
    anim = FuncAnimation(fig, update, frames=len(idx), interval=interval, blit=False)
    anim.frame_indices = idx
    plt.close(fig)  # the notebook shows the animation, not a static copy
    return anim


def _mark_animation(ax, mark):
    if mark:
        mk.mark_axes(ax, mark)
        ax.set_title(f"{mark} — {ax.get_title()}" if ax.get_title() else mark, fontsize=9, color=mk.MARK_COLOR,
                     fontweight="bold")


#: The stylesheet link of matplotlib's JS/HTML player (Font Awesome 4 from a CDN, for the icons
#: of its buttons).
_REMOTE_ICON_CSS = re.compile(r"""<link\s+rel=["']stylesheet["']\s+href=["'](?:https?:)?//[^"']*font-awesome"""
                              r"""[^"']*["']\s*/?>\s*""", re.I)


def animation_html(anim) -> str:
    """The animation as a self-contained JavaScript/HTML string (``anim.to_jshtml()``) that
    loads nothing from the internet: matplotlib's link to Font Awesome on a CDN is removed,
    and the page's own icon font draws the player's buttons (the book's theme ships Font
    Awesome, whose names include the player's ``fa-play``, ``fa-step-forward``, ...).
    Show it with ``IPython.display.HTML(animation_html(anim))``."""
    import matplotlib as mpl

    with mpl.rc_context({"animation.embed_limit": 20.0}):  # MB
        return _REMOTE_ICON_CSS.sub("", anim.to_jshtml())


# =====================================================================================
# Simulations against data
# =====================================================================================

#: The tracked channels of the gait chapters, in figure order.
GAIT_CHANNELS = ("hip_r", "knee_r", "ankle_r", "mtp_r", "hip_l", "knee_l", "ankle_l", "mtp_l",
                 "tau_hip_r", "tau_knee_r", "tau_ankle_r", "tau_mtp_r",
                 "tau_hip_l", "tau_knee_l", "tau_ankle_l", "tau_mtp_l",
                 "grf_x_r", "grf_y_r", "grf_x_l", "grf_y_l")


def tracking_figure(gait, sims: dict, channels=GAIT_CHANNELS, ncols: int = 4, colors=None,
                    figsize_per=(3.0, 2.1), title=None, data_label="data ±1 SD", marks=None):
    """Simulated channels over the data's mean ± 1 SD band, one panel per channel.

    Parameters
    ----------
    gait : gaitlib.data.GaitData (bands; x axis = % of its cycle).
    sims : ``{label: DataFrame}`` indexed by time (s) from the cycle start, columns named
        as the data's channels (SI, model signs: angles rad, torques N·m, forces N); e.g.
        :func:`gaitlib.studies.gait.channels_frame`. Drawn in display units
        (:func:`channel_display`). Channels the data lack (the metatarsal torque) show the
        simulation only; a planned reference (``mtp_*``) is drawn as a band of zero width.
    marks : optional ``{label: failure label or None}`` (:func:`gaitlib.marks.failure_label`
        of each simulation's solve). A marked simulation is drawn dashed, its legend entry
        says why, every panel that shows it carries the label as a red watermark and the
        title starts with it in red (:mod:`gaitlib.marks`).
    """
    import matplotlib.pyplot as plt

    channels = list(channels)
    marks = {lab: m for lab, m in (marks or {}).items() if m and lab in sims}
    fig, axes = _panel_grid(len(channels), ncols, figsize_per)
    cmap = plt.get_cmap("tab10")
    colors = colors or {lab: cmap(i) for i, lab in enumerate(sims)}
    pct_data = 100 * gait.time / gait.cycle_time
    for ax, ch in zip(axes.flat, channels):
        name, scale, unit = channel_display(ch)
        if ch in gait.mean:
            band(ax, pct_data, scale * gait.mean[ch], scale * gait.sd[ch], label=data_label)
        shown = []
        for lab, frame in sims.items():
            if ch in frame:
                t = np.asarray(frame.index, dtype=float)
                ax.plot(100 * (t - t[0]) / gait.cycle_time, scale * frame[ch].to_numpy(), color=colors[lab],
                        lw=1.4, ls="--" if lab in marks else "-", label=mk.run_label(lab, marks.get(lab)))
                shown.append(lab)
        _label_panel(ax, ch, unit, name)
        mk.mark_axes(ax, mk.joint_label({k: marks.get(k) for k in shown}, named=len(sims) > 1))
    fig = _finish_panels(fig, axes, len(channels), title)
    mk.mark_figure(fig, mk.joint_label(marks, named=len(sims) > 1))
    return fit_decorations(fig, axes.shape[0])


def animate_jump(jump_model, t, Q, p_contact=None, grf=None, cop=None, fps: float = 12,
                 interval=None, max_frames: int = 50, figsize=(4.5, 5.0), dpi: int = 72,
                 grf_scale=None, grf_min=None, ellipsoids=None, title=None, mark=None):
    """Animate a vertical jump of a :class:`gaitlib.jump.JumpModel` (thesis Ch 3).

    Parameters
    ----------
    jump_model : gaitlib.jump.JumpModel
    t : (n,) s; Q : (n, jump_model.n) free coordinates ``(x, y, theta_z, joints…)``, m and
        rad (the welded phase's rows have the root at 0).
    p_contact : contact parameters of the toe-included model's ellipsoids (default
        :func:`gaitlib.contact.default_params`).
    grf : optional (n, 2) ground reaction force of both feet (F_x, F_y), N, drawn as an
        arrow from ``(cop[i], 0)`` (``cop`` (n,) m; default: below the MTP point), hidden
        where F_y < ``grf_min`` (default 4 % of the weight) or where ``cop`` is NaN.
        ``grf_scale`` m per N (default: one body weight ↦ 0.5 m).
    fps, interval, max_frames, figsize, dpi, title, mark : as :func:`animate_gait`.

    Fixed axes that contain every frame (so the height of the jump is visible); the body
    is drawn with :func:`draw_jump`. Returns a ``FuncAnimation`` (``anim.frame_indices``).
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    t = np.asarray(t, dtype=float)
    Q = np.asarray(Q, dtype=float)
    W = jump_model.total_mass * jump_model.g
    scale = 0.5 / W if grf_scale is None else grf_scale
    fmin = 0.04 * W if grf_min is None else grf_min
    idx = _pick_frames(len(t), max_frames)
    frames = [jump_frame(jump_model, Q[i], p_contact, ellipsoids) for i in idx]
    pts = np.vstack([np.vstack(list(f["chains"].values()) + list(f["ellipses"].values()))
                     for f in frames])
    pad = 0.15
    xlo, xhi = pts[:, 0].min() - pad, pts[:, 0].max() + pad
    ylo, yhi = min(pts[:, 1].min(), 0.0) - 0.05, pts[:, 1].max() + 0.08
    min_w = 0.6 * (yhi - ylo)  # not a sliver for a high jump (equal aspect)
    if xhi - xlo < min_w:
        xc = 0.5 * (xlo + xhi)
        xlo, xhi = xc - 0.5 * min_w, xc + 0.5 * min_w

    fig, ax = plt.subplots(figsize=figsize, dpi=dpi, constrained_layout=True)
    artists = draw_jump(ax, jump_model, Q[idx[0]], p_contact, ellipsoids)
    arrow = _arrow(ax, FIGURE_COLORS["grf"]) if grf is not None else None
    ax.set_xlim(xlo, xhi)
    ax.set_ylim(ylo, yhi)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    label = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
    if title:
        ax.set_title(title, fontsize=10)
    _mark_animation(ax, mark)

    def update(k):
        i = idx[k]
        fr = frames[k]
        _set_line(artists["chains"]["body"], fr["chains"]["body"])
        for e, patch in artists["ellipsoids"].items():
            patch.set_xy(fr["ellipses"][e])
        changed = [artists["chains"]["body"], *artists["ellipsoids"].values(), label]
        if arrow is not None:
            fx, fy = (float(v) for v in grf[i])
            x0 = float(Q[i, 0]) if cop is None else float(cop[i])
            _set_arrow(arrow, (x0, 0.0), (scale * fx, scale * fy),
                       visible=bool(fy > fmin and np.isfinite(x0)))
            changed.append(arrow)
        label.set_text(f"t = {t[i]:.3f} s")
        return changed

    update(0)
    interval = 1000.0 / fps if interval is None else interval
    anim = FuncAnimation(fig, update, frames=len(idx), interval=interval, blit=False)
    anim.frame_indices = idx
    plt.close(fig)
    return anim


def score_bars(scores, kind: str, value: str = "rmse", cases=None, models=None, ncols: int = 4,
               figsize_per=(3.0, 2.1), title=None, colors=None):
    """Grouped bars of a per-channel error for several runs (thesis Figs 6.1–6.4, 7.1–7.4).

    Parameters
    ----------
    scores : long DataFrame with columns ``model, case, kind, channel, side, unit`` and
        ``value`` (e.g. :attr:`gaitlib.studies.predictive.StudyResult.scores`).
    kind : ``"angle"``, ``"torque"``, ``"grf"`` or ``"excitation"`` — one panel per
        channel and side; x = the cases (cost functions or speed classes) in order, one bar
        per model. A run missing from ``scores`` leaves a gap.

    A run whose rows carry a failure label in the column ``mark`` (see
    :func:`gaitlib.marks.failure_label`; :attr:`~gaitlib.studies.predictive.StudyResult.scores`
    has it) is drawn with red hatching and a red ``†`` above the bar; the legend explains the
    hatching and the title starts with the marked runs and their labels, in red.
    """
    import matplotlib.pyplot as plt

    df = scores[scores["kind"] == kind]
    run_marks = {}
    if "mark" in df.columns:
        for (m, c), g in df.groupby(["model", "case"], sort=False):
            labs = [v for v in g["mark"] if isinstance(v, str) and v]
            if labs:
                run_marks[(m, c)] = labs[0]
    cases = list(cases) if cases is not None else list(dict.fromkeys(df["case"]))
    models = list(models) if models is not None else list(dict.fromkeys(df["model"]))
    panels = list(dict.fromkeys(zip(df["channel"], df["side"])))
    fig, axes = _panel_grid(len(panels), ncols, figsize_per)
    cmap = plt.get_cmap("tab10")
    colors = colors or {m: cmap(i) for i, m in enumerate(models)}
    width = 0.8 / max(len(models), 1)
    x = np.arange(len(cases))
    for ax, (ch, side) in zip(axes.flat, panels):
        sub = df[(df["channel"] == ch) & (df["side"] == side)]
        for i, m in enumerate(models):
            vals = [sub[(sub["model"] == m) & (sub["case"] == c)][value] for c in cases]
            vals = [float(v.iloc[0]) if len(v) else np.nan for v in vals]
            xs = x + (i - (len(models) - 1) / 2) * width
            bars = ax.bar(xs, vals, width, color=colors[m], label=m)
            for j, c in enumerate(cases):
                if (m, c) in run_marks and np.isfinite(vals[j]):
                    mk.mark_bars([bars[j]], run_marks[(m, c)])
                    ax.annotate(mk.DAGGER, (xs[j], vals[j]), ha="center", va="bottom", color=mk.MARK_COLOR,
                                fontsize=9, fontweight="bold", gid=mk.MARK_GID)
        ax.set_xticks(x, cases, rotation=60, fontsize=7)
        unit = sub["unit"].iloc[0] if value == "rmse" and len(sub) else ""
        ax.set_title(f"{ch} ({'right' if side == 'r' else 'left'})", fontsize=9)
        ax.set_ylabel(f"{value} {unit}".strip(), fontsize=8)
        ax.tick_params(axis="y", labelsize=7)
    for ax in axes.flat[len(panels):]:
        ax.axis("off")
    h, lab = axes.flat[0].get_legend_handles_labels()
    shown = {k: v for k, v in run_marks.items() if k[0] in models and k[1] in cases}
    if shown:
        h, lab = h + [mk.bar_legend_handle()], lab + [mk.bar_legend_handle().get_label()]
    if h:
        lab, ncols = _legend_layout(fig, lab, max_cols=len(h))
        fig.legend(h, lab, loc="outside lower center" if shown else "outside upper right", fontsize=8,
                   ncols=ncols)
    if title:
        fig.suptitle(title, fontsize=10)
    if shown:
        mk.mark_figure(fig, "; ".join(f"{mk.DAGGER} {m} {c} {v}" for (m, c), v in shown.items()))
    return fig


# =====================================================================================
# Contact geometry on the foot (thesis Figs 4.10, 4.11, 4.14)
# =====================================================================================


def foot_contact_geometry(param_sets: dict, model=None, colors=None, styles=None, title=None,
                          figsize=(10.0, 3.6)):
    """The left foot's three contact ellipsoids in side and top view, standing posture.

    Parameters
    ----------
    param_sets : ``{label: p_contact}`` — 39-vectors (SI, left foot,
        :func:`gaitlib.contact.default_params` order) drawn over each other, e.g. ours and
        the thesis's identified values.
    model : gaitlib.model.ChildModel (default: a new one).
    colors, styles : optional ``{label: colour}`` / ``{label: linestyle}``.

    Coordinates are those of the contact parameters (thesis Sec 4.1.2): the foot frame with
    its origin on the ground below the ankle in the standing posture, X forward, Y up,
    Z = X × Y (to the walker's right; for the left foot +Z is medial), in mm. Side view:
    the exact orthographic outline of each ellipsoid on the X–Y plane
    (:func:`ellipse_outline`) with the foot's skeleton (heel → ankle → metatarsal point →
    toe tip) and the ground; top view: outlines on the X–Z plane, the skeleton along
    Z = 0 (the model is planar).

    Returns
    -------
    matplotlib Figure with two axes (side, top).
    """
    import matplotlib.pyplot as plt

    model = ChildModel() if model is None else model
    q = np.zeros(len(cv.COORDS))
    q[cv.COORDS.index("pelvis_ty")] = model.standing_leg_length
    P = model.points(q)
    origin = np.array([float(np.asarray(P["ankle_l"])[0]), 0.0])
    skel = np.array([np.asarray(P[k], float).ravel() for k in ("heel_l", "ankle_l", "mtp_l", "toe_tip_l")]) - origin
    perm = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])  # (x, y, z) -> (x, z, y): top view
    fig, (ax_s, ax_t) = plt.subplots(1, 2, figsize=figsize, constrained_layout=True)
    cmap = plt.get_cmap("tab10")
    labels = list(param_sets)
    colors = colors or {lab: cmap(i) for i, lab in enumerate(labels)}
    styles = styles or {lab: ("-", "--", ":", "-.")[i % 4] for i, lab in enumerate(labels)}
    ax_s.axhline(0.0, color=FIGURE_COLORS["ground"], lw=1.0, zorder=0)
    ax_s.plot(1e3 * skel[:, 0], 1e3 * skel[:, 1], "-o", color="0.3", lw=2.0, ms=3, zorder=1)
    ax_t.plot(1e3 * skel[[0, 3], 0], [0.0, 0.0], "-", color="0.3", lw=2.0, zorder=1)

    for lab in labels:
        p = np.asarray(param_sets[lab], float)
        centres, Rs = model.ellipsoid_poses(q, p)
        radii = ellipsoid_radii(p)
        first = True
        for k, el in enumerate(ELLIPSOID_LABELS):
            if not el.endswith("_l"):
                continue
            c = np.asarray(centres[k], float) - np.array([origin[0], 0.0, 0.0])
            R = np.asarray(Rs[k], float)
            side = 1e3 * ellipse_outline(c, R, radii[k])
            top = 1e3 * ellipse_outline(perm @ c, perm @ R, radii[k])
            kw = dict(color=colors[lab], ls=styles[lab], lw=1.4)
            ax_s.plot(side[:, 0], side[:, 1], label=lab if first else None, **kw)
            ax_t.plot(top[:, 0], top[:, 1], **kw)
            ax_s.annotate(el[:-2], (1e3 * c[0], 1e3 * c[1]), fontsize=7, color=colors[lab], ha="center")
            first = False
    ax_s.set_title("side view (X–Y)", fontsize=9)
    ax_s.set_xlabel("X forward (mm)", fontsize=8)
    ax_s.set_ylabel("Y up (mm)", fontsize=8)
    ax_t.set_title("top view (X–Z)", fontsize=9)
    ax_t.set_xlabel("X forward (mm)", fontsize=8)
    ax_t.set_ylabel("Z (mm, + medial for the left foot)", fontsize=8)
    for ax in (ax_s, ax_t):
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
    fig.legend(loc="outside lower center", ncols=min(len(labels), 4), fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
