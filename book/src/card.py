# %% [markdown]
# # Report card: what this replication reproduced
#
# One row per headline number of the thesis — the Ch 3 jump table, the RMSE rows of
# Tables 4.9–4.18, Tables 5.2, 5.4, 5.10 and 5.11, the cost of transport, the statuses of
# Tables 6.3 and 7.2, the conclusions of Chs 6 and 7, the points of Fig 7.5 and the
# U-curve claim — with our value computed from the stored solution the chapters use
# (`gaitlib.studies.card`; the same table is written by `gaitlib card --out DIR` as
# `card.csv`). Nothing on this page is solved or typed in: it calls the card, formats it
# and shows it.
#
# Every row carries the **validity gates** of its solution (`gaitlib.validity`: converged,
# no load on a foot the data say swings, at most 40 % of the cycle in double support, HAT
# residuals, strength, range of motion, periodicity). A row whose solution did not converge
# or fails a gate gets the verdict **invalid** — it never counts as reproduced, whatever its
# number; the verdict its number alone would get is kept in the *cause* column.
#
# The thesis's numbers are on other data (Bovi 2011; ours Schwartz et al. 2008), so a
# tracking error need not be reproduced even by a faithful replication; the *cause* column
# gives a measured reason, with the page that measures it, where the book has one, and
# "unknown" otherwise.

# %%
import re

import pandas as pd
from IPython.display import HTML, Markdown, display

from gaitlib.studies import card

c = card.build()
display(Markdown("**Verdict rule** (`gaitlib.studies.card.verdict`, one rule for every row): " + card.RULE + "."))

# %% [markdown]
# ## Verdicts

# %%
n = card.counts(c)
by_chapter = pd.crosstab(c["chapter"], c["verdict"]).reindex(columns=list(card.VERDICTS), fill_value=0)
by_chapter.loc["all"] = by_chapter.sum()
display(by_chapter)
print(f"{len(c)} rows: " + ", ".join(f"{v} {k}" for k, v in n.items()) + ".")
blocked = c["verdict"] == "invalid"
print(f"{blocked.sum()} rows come from a solution that did not converge or fails a validity gate; "
      f"their numbers alone would give: "
      + ", ".join(f"{k} {v}" for k, v in
                  c.loc[blocked, "cause"].str.extract(r"the number alone: (.*)$")[0].value_counts().items()) + ".")
ch3 = c[(c["chapter"] == 3) & c["item"].str.contains(r"jump height \(")]
print("Ch 3 jumps (the thesis's bounds, kept on purpose): " + "; ".join(
    f"{r.item.split(':')[0]} {r.ours:.0f} cm vs thesis {r.thesis:.0f} cm" for r in ch3.itertuples()) + ".")

# %% [markdown]
# The Ch 3 rows replicate the thesis's jump formulation as printed (Table 3.5 bounds: joint
# torques up to 4000 N·m, no strength or power limit), which does not confine the optimum
# to a human jump: their *cause* column compares the COM rise with the range of human
# standing jumps, and the *valid* column names the gate they fail. The rows marked
# "torques within the body's strength (ours)" are the physiological version of the same
# three jumps (Ch 3, the joint torques limited by the Ch 5 MTGs' strength envelopes), with
# their own validity gates.
#
# ### Do the feet stand still? Foot slip (measured, not yet a gate)
#
# The validity gates above do not look at how fast a loaded foot slides. The contact law's
# friction acts on the tangential velocity of each ellipsoid's body point at its penetration
# centroid, and models sticking below its transition velocity v_tr = 0.1 m/s; a standing
# foot does not slide. For every stored gait solution a row below names, the force-weighted
# mean slip speed of the loaded feet (`card.slip_table`, `fidelity.foot_slip`), beside how
# fast the feet of its tracking reference alone slide — the data it tracks placed on the
# model, no solve (`gait.reference_slip`); Ch 4 identifies the contact again with feet that
# cannot slide, Ch 7 solves its speeds again with feet that cannot skate.

# %%
slips = card.slip_table(c)
display(Markdown(" ".join(card.slip_lines(slips) + card.legs_slip_lines() + card.stride_lines())))
slips.drop(columns=["rows counted as reproduced"])

# %% [markdown]
# ## The card, chapter by chapter

# %%
COLOURS = {"reproduced": "#c8e6c9", "within data SD": "#e6f4c8", "qualitatively reproduced": "#fff3c4",
           "not reproduced": "#ffcdd2", "not comparable": "#e0e0e0", "invalid": "#d7ccc8"}


def _link(text):
    """``[book/<page>#<anchor>]`` → a link to that section of this book."""
    return re.sub(r"\[book/([\w]+)#([\w-]+)\]", r'<a href="\1.html#\2">→ \1</a>', str(text))


def _fmt(v):
    return f"{v:.4g}" if isinstance(v, float) else str(v)


for ch, part in c.groupby("chapter"):
    display(Markdown(f"### Chapter {ch}"))
    t = part.drop(columns="chapter").reset_index(drop=True)
    for col in ("thesis", "ours"):
        t[col] = t[col].map(_fmt)
    t["cause"] = t["cause"].map(_link)
    sty = (t.style.hide(axis="index")
           .apply(lambda col: [f"background-color: {COLOURS.get(v, '')}" for v in col], subset=["verdict"])
           .set_properties(**{"text-align": "left", "vertical-align": "top", "font-size": "0.85em"})
           .set_properties(subset=["cause", "valid", "gap"], **{"min-width": "18em"}))
    display(HTML(sty.to_html(escape=False)))
