"""Units, axes, coordinate names and sign conventions — the one place they are defined.

Every other module (data, model, contact, mtg, transcription, plots) imports its names and
signs from here. SI units inside gaitlib; degrees, % body weight and N·m/kg only at the
edges (data files and figures).

Axes (thesis Sec 4.1.1, Fig 4.1)
--------------------------------
Global (ground) frame: origin on the ground, **X forward** (direction of progression),
**Y up**, **Z lateral** (Z = X × Y, pointing to the walker's right). The model moves in the
X–Y (sagittal) plane. Gravity is ``-G`` along Y.

Generalised coordinates ``q`` (order is fixed, see :data:`COORDS`)
-----------------------------------------------------------------
``pelvis_tx, pelvis_ty``  position of the hip joint centre (the HAT's distal end), m.
``pelvis_tilt``           absolute angle of the HAT, rad, counter-clockwise (CCW) positive
                          seen from the walker's right side (+Z towards the viewer), i.e.
                          positive = HAT leaning **backwards**; 0 = HAT upright.
``hip_r, knee_r, ankle_r, mtp_r, hip_l, knee_l, ankle_l, mtp_l``
                          relative joint angles, rad, CCW positive (distal segment relative
                          to the proximal one), which makes
                          hip   > 0: flexion (thigh forward),
                          knee  < 0: flexion (knee extension is positive, as in the thesis),
                          ankle > 0: dorsiflexion,
                          mtp   > 0: toe dorsiflexion (extension).
                          All angles are 0 in the standing posture (segments vertical, foot
                          flat, toes flat).

Joint torques ``tau`` (the 8 actuated joints, same order as the joint angles) are the
torque applied by the proximal segment on the distal segment, N·m, positive in the same
sense as the angle (a positive hip torque flexes the hip, a positive knee torque extends
the knee, a positive ankle torque dorsiflexes). The pelvis residual loads ``R`` are the
generalised forces on ``pelvis_tx, pelvis_ty`` (N, along +X, +Y) and ``pelvis_tilt``
(N·m, CCW positive) that the motion would need beyond gravity, contact and joint torques.

Ground reaction forces on a foot: ``grf_x`` (N, +X = forward, propulsive) and ``grf_y``
(N, +Y = up).

Data conventions (Schwartz 2008, conventional gait model) and their mapping
---------------------------------------------------------------------------
============================  =====================  ===================================
data channel (unit)           model channel (unit)   conversion
============================  =====================  ===================================
Pelvic Ant/Posterior Tilt deg pelvis_tilt rad        −deg2rad (anterior tilt = forward
                                                     lean = clockwise = negative)
Hip Flex/Extension deg        hip rad                +deg2rad
Knee Flex/Extension deg       knee rad               −deg2rad
Ankle Dorsi/Plantarflexion    ankle rad              +deg2rad
Hip Ext/Flexion N·m/kg        hip torque N·m         −BM (data: extensor moment > 0)
Knee Ext/Flexion N·m/kg       knee torque N·m        +BM (data: extensor moment > 0)
Ankle Dorsi/Plantar N·m/kg    ankle torque N·m       −BM (data: plantarflexor moment > 0)
Joint power W/kg              power W                +BM (sign is physical: generation > 0)
GRF Anterior/Posterior BW     grf_x N                +BM·G (data: anterior > 0)
GRF Vertical BW               grf_y N                +BM·G
EMG (normalised, 0..1)        emg (1)                unchanged
============================  =====================  ===================================

Note: the data's pelvic tilt is the conventional-gait-model pelvis angle, which includes an
anatomical offset of about 10° (ASIS–PSIS line); the model's HAT angle is a whole-trunk
angle. The book states where this matters.
"""

from __future__ import annotations

import math

#: Standard gravity, m/s².
G = 9.81

#: Default subject (thesis Sec 4.1.1: mean of Bovi 2011's 20 children).
BODY_MASS = 41.4  # kg
BODY_HEIGHT = 1.47  # m

#: Generalised coordinates of the 11-DOF gait model, in order.
COORDS = (
    "pelvis_tx",
    "pelvis_ty",
    "pelvis_tilt",
    "hip_r",
    "knee_r",
    "ankle_r",
    "mtp_r",
    "hip_l",
    "knee_l",
    "ankle_l",
    "mtp_l",
)
#: The 8 actuated joints, in order (a slice of COORDS).
JOINTS = COORDS[3:]
#: The three unactuated HAT (pelvis) DOFs, whose generalised forces are the residual loads.
RESIDUALS = ("R_x", "R_y", "R_z")
SIDES = ("r", "l")
#: Contact ellipsoids per foot, in order (thesis Sec 4.1.2).
ELLIPSOIDS = ("toe", "ball", "heel")

#: Speed classes of Schwartz et al. 2008, slowest first.
SPEED_CLASSES = ("VerySlow", "Slow", "Free", "Fast", "VeryFast")
#: Labels as they appear in the Schwartz 2008 spreadsheet.
SPEED_CLASS_LABELS = {
    "VerySlow": "Very Slow",
    "Slow": "Slow",
    "Free": "Free",
    "Fast": "Fast",
    "VeryFast": "Very Fast",
}

DEG = math.pi / 180.0


def thigh_in_lab(hip, pelvis_tilt):
    """The thigh's angle in the laboratory from the data's hip angle (relative to the pelvis)
    and the pelvic tilt, both in model signs (rad or deg alike; scalars or arrays).

    The model's HAT is upright while the data's pelvis tilts about 11 deg forward, so the
    gait problem's hip coordinate is the thigh in the laboratory: ``hip + pelvis_tilt``
    (inverse: :func:`hip_from_thigh`)."""
    return hip + pelvis_tilt


def hip_from_thigh(thigh, pelvis_tilt):
    """Inverse of :func:`thigh_in_lab`: the hip angle relative to the pelvis."""
    return thigh - pelvis_tilt

#: Sign applied when mapping a data channel to the model channel (see module docstring).
DATA_SIGN = {
    "pelvis_tilt": -1.0,
    "hip": +1.0,
    "knee": -1.0,
    "ankle": +1.0,
    "hip_moment": -1.0,
    "knee_moment": +1.0,
    "ankle_moment": -1.0,
    "hip_power": +1.0,
    "knee_power": +1.0,
    "ankle_power": +1.0,
    "grf_x": +1.0,
    "grf_y": +1.0,
}


def leg_length(body_height: float = BODY_HEIGHT, leg_scale: float = 1.0) -> float:
    """Standing leg length (hip joint centre to ground), m.

    Uses the model's own geometry in the standing posture: thigh (0.245 BH) + shank
    (0.246 BH) (thesis Table 4.1) + ankle height above the ground, which follows from the
    foot segments of Table 4.3 (AM = 0.065 BH, HA = 0.044 BH, β = 106°) with the heel and
    metatarsal points on the ground. This is the length used to turn the dimensionless
    speed and cadence of Schwartz et al. 2008 (v* = v / sqrt(g L)) into SI units.
    ``leg_scale`` multiplies the thigh and shank (:attr:`gaitlib.model.ChildModel.leg_scale`).
    """
    return body_height * (0.245 + 0.246) * leg_scale + ankle_height(body_height)


def ankle_height(body_height: float = BODY_HEIGHT, beta_deg: float = 106.0) -> float:
    """Height of the ankle joint above the ground in the standing posture, m.

    The fore-foot AM (ankle→metatarsal, 0.065 BH) and hind-foot HA (heel→ankle, 0.044 BH)
    meet at the ankle at the fixed angle β (thesis Sec 4.1.1, Table 4.3). With both the
    heel H and the metatarsal point M on the ground, AM makes φ₁ below the horizontal and
    AH makes φ₂ = 180° − β − φ₁, with |AM| sin φ₁ = |AH| sin φ₂.
    """
    l_am, l_ha = 0.065 * body_height, 0.044 * body_height
    total = math.pi - beta_deg * DEG
    # |AM| sin φ1 = |AH| sin(total - φ1)  →  tan φ1 = |AH| sin(total) / (|AM| + |AH| cos(total))
    phi1 = math.atan2(l_ha * math.sin(total), l_am + l_ha * math.cos(total))
    return l_am * math.sin(phi1)
