"""The sim-to-real gap: measured runs, their replay through the Drake model, identification, effects, diagnosis.

The product path (``drakecreep diagnose`` on ``p_p_cascade`` runs) is
:func:`drakecreep.gap.drake_diagnosis.diagnose_drake`: :mod:`~drakecreep.gap.drake_replay` (replay through
the Drake diagram; :class:`~drakecreep.gap.drake_replay.SampledReplay` is its fast discrete-time form),
:mod:`~drakecreep.gap.identify` (IDIM start + output error), :mod:`~drakecreep.gap.screen` (inverse-dynamics
pre-screen with the axis's own force terms), :mod:`~drakecreep.gap.drake_effects` (candidates as parts of the
Drake model). :mod:`~drakecreep.gap.diagnosis`, :mod:`~drakecreep.gap.effects` and :mod:`~drakecreep.gap.replay`
are the former rigid diagnosis, still used by ``diagnose`` for ``kind: drakecreep`` runs until those move to the
Drake model (docs/gap_diagnosis.md); the realistic benchmark (:mod:`~drakecreep.gap.benchmark`) scores
``diagnose_drake``.
"""
