"""The sim-to-real gap: measured runs, their replay through the Drake model, identification, effects, diagnosis.

The product path (``drakecreep diagnose`` on ``p_p_cascade`` runs) is
:func:`drakecreep.gap.drake_diagnosis.diagnose_drake`: :mod:`~drakecreep.gap.drake_replay` (replay through
the Drake diagram; :class:`~drakecreep.gap.drake_replay.SampledReplay` is its fast discrete-time form),
:mod:`~drakecreep.gap.identify` (IDIM start + output error), :mod:`~drakecreep.gap.screen` (inverse-dynamics
pre-screen with the axis's own force terms), :mod:`~drakecreep.gap.drake_effects` (candidates as parts of the
Drake model), :mod:`~drakecreep.gap.where` (where the unexplained gap lies). ``kind: drakecreep`` runs (the
project's own controller and params file): :func:`drakecreep.gap.drive_fit.diagnose_drive`. The realistic
benchmark: :mod:`~drakecreep.gap.benchmark` with its independent truth :mod:`~drakecreep.gap.truth`.
:mod:`~drakecreep.gap.replay` is the exact rigid stepper kept as a cross-check and for the published EMPS model.
"""
