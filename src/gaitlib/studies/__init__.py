"""Studies: one module per thesis chapter (plus the gap diagnosis).

A study turns frozen specs into solutions (via :mod:`gaitlib.problems.gait` /
:mod:`gaitlib.ocp`) and into the tables and frames a chapter shows. Notebooks and the
command line (``gaitlib run STUDY``) call the same functions; no OCP is set up here that a
lower layer already defines.

Modules: :mod:`.gait` (natural-gait SK/MSK data tracking), :mod:`.jump` (Ch 3).
"""
