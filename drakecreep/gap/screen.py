"""Fast pre-screen of the candidate effects on inverse dynamics, with the replay axis's own force terms.

The closed-loop output-error fit of a candidate (:func:`drakecreep.gap.drake_effects.fit_effect`) needs tens
of replays. Before it, each candidate is fitted on the *inverse dynamics* of the training runs, with the
very functions the Drake axis integrates (:func:`drakecreep.model.axis.axis_friction`,
:func:`drakecreep.model.axis.axis_ripple`; one definition of each effect)::

    F = M ddq + f(dq, q, t) + offset - r(q, t)          (rigid MeasuredAxis solved for the drive force)

on the IDIM signals of :func:`drakecreep.gap.idim.idim_signals` (Butterworth, central differences; not
decimated, so that a ripple up to the controller's Nyquist frequency stays visible), and scored, parameters fixed, on the held-out runs' inverse dynamics. This gives, in
seconds:

* the **start** of the closed-loop fit: every start of the candidate (and, for periods and frequencies, a
  dense set of starts) is refined here and only the best goes on to the closed loop (one closed-loop start
  per candidate instead of several);
* a **screen**: the issue's claim rule asks a claimed effect to improve the held-out closed-loop replay *and*
  the inverse-dynamics fit. A candidate whose held-out inverse-dynamics error ratio does not beat the reference's by
  ``k_se`` (1) standard error of the per-run log ratios (the claim's statistic) is not fitted in closed loop (it
  is still listed, with its screen numbers). The gain is measured on the sliding samples (:data:`SLOW_SHARE`) against the nominal
  with the same nominal parameters refitted on the same inverse dynamics (equal effort: the closed-loop values
  are not the inverse-dynamics optimum, and against them every candidate gained on effect-free data). A
  candidate whose fitted values fall outside its bounds fails too. The threshold is looser than the claim's
  Student bar: with two or three held-out runs the standard error of the inverse-dynamics gain is itself noisy;
* each held-out run is scored with its **own friction level** (``run_level``): a least-squares factor on the
  friction force, for the reference and the candidate alike, so that friction drift between the training and
  the held-out runs is not credited to a candidate;
* a **constancy test** for candidates flagged ``run_constancy`` (the friction drift): fitted on each training
  run alone, the candidate's amplitudes must agree within their standard errors (:func:`constancy`, a
  Chow-type Wald test at :data:`~drakecreep.gap.claims.ALPHA`). It is not asked of every candidate: on 53
  development datasets it also rejected true position ripples and position frictions (p down to 1e-139):
  their rigid inverse-dynamics amplitudes differ from run to run by more than the noise, as the runs cover
  different stretches of travel at different speeds (docs/gap_benchmark.md, 3g).

Two candidates have no rigid inverse-dynamics form and are never screened out: the axial mode (the
two-mass axis needs the table's state) and the computation delay (screened here only for its start value:
the measured drive force shifted by the delay, as :class:`drakecreep.model.pp_cascade.PPCascade` holds it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from drakecreep.errors import InputError
from drakecreep.gap.claims import ALPHA, mean_and_standard_error, mean_log_ratio
from drakecreep.gap.idim import idim_signals
from drakecreep.gap.measured import controller_ticks
from drakecreep.model.axis import (AXIS_PARAMETERS, FRICTION_MAP, LEAD_ERROR, POSITION_RIPPLE, applied_force,
                                   axis_friction, axis_parameters, axis_ripple, lead_error_drive, nut_load)

__all__ = ["ScreenResult", "Constancy", "constancy", "screen_effect", "screen_delay", "inverse_dynamics_force",
           "NOT_SCREENED", "LINEAR", "SHAPE", "SLOW_SHARE", "MIN_SLIDING"]

#: candidates without a rigid inverse-dynamics form (always fitted in closed loop)
NOT_SCREENED = ("axial_mode", "control_delay")

#: dense starts of phase-like parameters (the least squares refines each; cheap on inverse dynamics)
_DENSE = {
    "stribeck_velocity": tuple(np.geomspace(5e-4, 5e-2, 5)),
}


@dataclass(frozen=True)
class ScreenResult:
    """One candidate on inverse dynamics.

    Attributes
    ----------
    name : str
    start : dict
        Best values of the candidate's parameters on the training runs (the closed-loop start); for a candidate
        that ``shifts_nominal``, also the refitted nominal parameters, moved from the given nominal's values by
        what the candidate's fit moved them on inverse dynamics.
    train_error, test_error : float
        RMS over runs of the relative inverse-dynamics force error [%] with the candidate.
    nominal_test_error : float
        The same on the held-out runs for the reference: the nominal model with the same nominal parameters
        (``refit``) refitted on the training runs' inverse dynamics, without the candidate.
    gain, standard_error : float
        Mean and standard error of the per-run held-out decrease [points of %].
    passes : bool
        ``log_ratio > k_se * log_ratio_se`` and the fitted values inside the effect's bounds (always True for
        :data:`NOT_SCREENED` candidates).
    outside : dict
        The fitted values outside the effect's bounds: ``name -> (value, lo, hi)`` (SI); :attr:`inside` when empty.
    log_ratio, log_ratio_se : float
        Mean and standard error of the per-run ``ln(reference / candidate)`` of the held-out errors: the
        statistic the screen is decided on, as the claim (:func:`drakecreep.gap.drake_diagnosis.paired_log_ratio`).
    constancy : Constancy or None
        The constancy test across the training runs, for candidates flagged ``run_constancy`` (else None).
    reference_values : dict
        For a candidate with ``screen_refits`` (:class:`~drakecreep.gap.drake_effects.DrakeEffect`), those
        nominal parameters as the reference's inverse-dynamics fit found them (the closed-loop reference of the
        candidate starts there; ``start`` has the candidate's own values).
    alternative_start, reference_alternative : dict
        For a candidate with ``screen_refits`` or ``own_start``: ``start`` with the refitted nominal friction at
        the candidate's own inverse-dynamics values (instead of the nominal's, shifted for a candidate with
        ``shifts_nominal``), and the reference's inverse-dynamics values of every
        refitted parameter. The closed-loop fit starts from whichever of the two has the lower training error,
        and its reference the same way (:func:`drakecreep.gap.drake_effects.fit_effect` ``choose``): a drive that
        saturates biases the nominal itself (on spent dataset 45010001 an IDIM mass of 317 kg against the truth's
        82 kg, viscous 716 N s/m against 135), and the shift then starts the friction at -417 N s/m.
    """

    name: str
    start: dict
    train_error: float
    test_error: float
    nominal_test_error: float
    gain: float
    standard_error: float
    passes: bool
    log_ratio: float = float("nan")
    log_ratio_se: float = float("nan")
    constancy: object = None
    reference_values: dict = field(default_factory=dict)
    alternative_start: dict = field(default_factory=dict)
    reference_alternative: dict = field(default_factory=dict)
    outside: dict = field(default_factory=dict)

    @property
    def inside(self):
        """The fitted values are inside the effect's bounds (none is in :attr:`outside`)."""
        return not self.outside

    @property
    def error_ratio(self):
        """Geometric mean over the held-out runs of the candidate's inverse-dynamics error over the reference's."""
        return math.exp(-self.log_ratio)


def _signals(run, shift=0.0):
    """IDIM signals with time from the run's start; ``shift`` [samples] delays the drive force as a held
    computation delay does (``u[k-n]`` from ``t_k + f h``: the sample mean mixes ``u[k-n-1]`` and ``u[k-n]``)."""
    import dataclasses

    if shift:
        n, f = int(math.floor(shift)), shift - math.floor(shift)
        u = np.asarray(run.u, dtype=float)
        pad = np.concatenate([np.full(n + 1, u[0]), u])
        shifted = f * pad[: u.size] + (1 - f) * pad[1: u.size + 1]
        run = dataclasses.replace(run, u=shifted)
    # every second sample: a ripple up to half the controller's Nyquist frequency stays visible
    s = idim_signals(run, decimation=2)
    return s.t - float(run.t[0]), s.q, s.dq, s.ddq, s.tau


def inverse_dynamics_force(parameters, t, q, dq, ddq, tau=0.0):
    """Drive force [N] the rigid replay axis needs for the motion ``q, dq, ddq`` at times ``t`` (arrays).

    ``M ddq + f(dq, q, t, F_ax) + offset - r(q, t) + tau - g(tau)`` with the axis's own friction, ripple and
    drive functions, given the measured drive command ``tau``: the nut's axial load ``F_ax`` of a load-dependent
    friction is, as on the rigid Drake axis, the applied force with the ripple less the motor side's inertia
    force, ``g(tau) + r - alpha M ddq`` (:func:`~drakecreep.model.axis.nut_load` with the measured
    acceleration, so the force stays affine in the coefficient), and ``tau - g(tau)`` is what a saturating
    drive does not apply of the command (:func:`~drakecreep.model.axis.applied_force`; 0 for a linear drive).
    A lead error adds the table's inertial force ``m_t e''(q) dq^2`` and the nut's force geared by ``1 + e'(q)``, to
    first order in the error, with the nut's force from the measured command
    (:func:`~drakecreep.model.axis.lead_error_drive`: affine in the amplitudes).
    """
    other, friction = _force_parts(parameters, t, q, dq, ddq, tau)
    return other + friction


def _force_parts(parameters, t, q, dq, ddq, tau=0.0):
    """:func:`inverse_dynamics_force` as ``(M ddq + offset - r(q, t) + tau - g(tau), f(dq, q, t, F_ax))``: all but
    the friction, and the friction. ``tau - g(tau)`` is what a saturating drive does not apply of the measured
    command (:func:`~drakecreep.model.axis.applied_force`; 0 for a linear drive), so that the residual
    ``tau - F`` is the applied force's, ``g(tau) - (M ddq + ...)``."""
    p = axis_parameters(**parameters)
    P = dict(zip(AXIS_PARAMETERS, p))
    ripple = axis_ripple(q, t, p)
    applied = applied_force(tau, p)
    lead = lead_error_drive(q, dq, ddq, applied + ripple, p)
    return (P["mass"] * ddq + P["offset"] - ripple + lead + (tau - applied),
            axis_friction(dq, p, q, t, nut_load(applied + ripple, p, acceleration=ddq)))


def _errors(runs_sig, values, level=False):
    """Per-run relative force error [%]; ``level``: each run's friction force scaled by its own least-squares
    factor first (the run's friction level, a nuisance: friction drifts between runs)."""
    out = []
    for t, q, dq, ddq, tau in runs_sig:
        other, fr = _force_parts(values, t, q, dq, ddq, tau)
        scale = float(fr @ (tau - other)) / max(float(fr @ fr), 1e-300) if level else 1.0
        out.append(100.0 * np.linalg.norm(tau - other - scale * fr) / np.linalg.norm(tau))
    return np.array(out)


def _rms(a):
    return float(math.sqrt(np.mean(np.square(a)))) if len(a) else float("nan")


#: parameters the drive force of the rigid axis is affine in, for fixed values of all the others (solved by
#: linear least squares inside the fit: variable projection)
LINEAR = ("viscous", "viscous_asym", "coulomb", "coulomb_asym", "offset", "load_friction_coefficient",
          "stribeck_extra",
          "time_ripple_cos", "time_ripple_sin") + POSITION_RIPPLE + LEAD_ERROR


#: relative singular-value cut of the linear least squares of :func:`_project` (unit-norm columns)
RCOND = 1e-6


def _project(sig, norms, values, lin):
    """Best linear parameters ``lin`` for the other ``values`` fixed: ``(values, stacked residual)``.

    The regressor columns are differences of :func:`inverse_dynamics_force` (exact: the force is affine in
    ``lin``), so the model is still the axis's own functions."""
    v0 = dict(values)
    v0.update({n: 0.0 for n in lin})
    rows, rhs = [], []
    for (t, q, dq, ddq, tau), nrm in zip(sig, norms):
        f0 = inverse_dynamics_force(v0, t, q, dq, ddq, tau)
        cols = [inverse_dynamics_force(dict(v0, **{n: 1.0}), t, q, dq, ddq, tau) - f0 for n in lin]
        rows.append(np.column_stack(cols) / nrm if cols else np.zeros((tau.size, 0)))
        rhs.append((tau - f0) / nrm)
    A, b = np.vstack(rows), np.concatenate(rhs)
    theta = np.zeros(0)
    if lin:
        # columns scaled to unit norm, singular values below RCOND of the largest cut: on sliding samples
        # (SLOW_SHARE) ``coulomb_asym s(v)^2`` and the offset are the same column to 1e-8, and the plain solution
        # puts +-1e5 N on each; the truncated one splits their sum (what the data determine)
        norm = np.maximum(np.linalg.norm(A, axis=0), 1e-300)
        theta = np.linalg.lstsq(A / norm, b, rcond=RCOND)[0] / norm
    out = dict(values)
    out.update({n: float(x) for n, x in zip(lin, theta)})
    return out, b - A @ theta


def _fit(sig, base, names, start, bounds):
    """Least squares of ``names`` on the stacked, per-run normalised inverse-dynamics residual: the
    :data:`LINEAR` ones by linear least squares, the others by ``least_squares`` on the projected residual."""
    values = dict(base)
    values.update(start)
    norms = [np.linalg.norm(s[4]) for s in sig]
    lin = tuple(n for n in names if n in LINEAR)
    nl = tuple(n for n in names if n not in LINEAR)
    if not nl:
        values, r = _project(sig, norms, values, lin)
        return values, 0.5 * float(r @ r)
    # (the friction map's amplitudes multiply the friction levels, so they are not LINEAR: bilinear with them)
    scale = np.array([max(abs(values[n]), 0.1 if n in FRICTION_MAP else 1e-3) for n in nl])
    positive = ("mass", "period", "velocity", "frequency", "stiffness")
    lo = np.array([bounds.get(n, (1e-6 * s if any(w in n for w in positive) else -np.inf, np.inf))[0] / s
                   for n, s in zip(nl, scale)])
    hi = np.array([bounds.get(n, (-np.inf, np.inf))[1] / s for n, s in zip(nl, scale)])
    x0 = np.clip(np.array([values[n] for n in nl]) / scale, lo + 1e-12, hi - 1e-12)
    size = sum(s[4].size for s in sig)

    def residual(x):
        v = dict(values)
        v.update({n: float(a * s) for n, a, s in zip(nl, x, scale)})
        try:
            return _project(sig, norms, v, lin)[1]
        except InputError:  # a positive parameter stepped to <= 0
            return np.full(size, 1e3)

    sol = least_squares(residual, x0, bounds=(lo, hi), method="trf", max_nfev=20)
    values.update({n: float(a * s) for n, a, s in zip(nl, sol.x, scale)})
    values, r = _project(sig, norms, values, lin)
    return values, 0.5 * float(r @ r)


#: Samples slower than this share of the training runs' top speed are left out of the screen (and of the
#: benchmark's SNR): at standstill and in reversals the drive force is the static friction the controller
#: holds, which no rigid inverse dynamics determines (on effect-free benchmark data those samples carry most of
#: the nominal's inverse-dynamics residual, and an asymmetry "explained" 3-6 points of it).
SLOW_SHARE = 0.05


#: Fewest sliding samples a run needs to count in the screen (a run slower throughout than
#: ``SLOW_SHARE`` of the training runs' top speed has none, and its relative error, 0 / 0, made every candidate's
#: held-out statistic NaN: the screen then ruled out every candidate of the dataset)
MIN_SLIDING = 50


def _sliding(sig, v_top, share):
    """The samples of IDIM signals ``sig`` at speeds of at least ``share * v_top``; runs left with fewer than
    :data:`MIN_SLIDING` samples are dropped."""
    if share <= 0:
        return sig
    out = [tuple(a[np.abs(s[2]) >= share * v_top] for a in s) for s in sig]
    return [s for s in out if s[0].size >= MIN_SLIDING]


def screen_effect(effect, train, test, nominal_parameters, *, refit=("viscous", "coulomb", "offset"), k_se=1.0,
                  slow_share=SLOW_SHARE, run_level=True):
    """Fit ``effect`` on the training runs' inverse dynamics and score it on the held-out runs'.

    Parameters
    ----------
    effect : drakecreep.gap.drake_effects.DrakeEffect
    train, test : sequence of MeasuredRun
    nominal_parameters : dict
        Axis parameters of the nominal (or augmented) model.
    refit : tuple of str
        Nominal parameters refitted together with the candidate's.
    k_se : float
        Standard errors the held-out gain must exceed to pass. 1 (looser than the claim's 2): the screen
        only drops candidates the held-out inverse dynamics does not support; the claim itself is decided
        on the closed-loop replay.
    slow_share : float
        Samples slower than this share of the training runs' top speed are left out (:data:`SLOW_SHARE`;
        0 keeps all).
    run_level : bool
        Score each held-out run with its own friction level: the friction force of the reference and of the
        candidate each scaled by the run's least-squares factor before the error is taken. Friction drifts
        between runs (temperature, lubrication); without this a candidate that raises the friction where the
        held-out runs happen to lie gains from that drift (a position friction on an effect-free dataset whose
        held-out runs ran 12 % above the training runs' friction: docs/gap_benchmark.md, 3g).

    Returns
    -------
    ScreenResult
    """
    base = dict(AXIS_PARAMETERS)
    base.update(nominal_parameters)
    base.update(effect.fixed_by(train))
    tr = [_signals(r) for r in train]
    te = [_signals(r) for r in test]
    v_top = max(float(np.max(np.abs(s[2]))) for s in tr)
    whole, tr, te = tr, _sliding(tr, v_top, slow_share), _sliding(te, v_top, slow_share)
    if effect.name in NOT_SCREENED or len(te) < 2:
        # (fewer than two held-out runs with sliding samples: no standard error, so the screen cannot decide
        # and leaves the candidate to the closed loop, as a candidate it has no form for)
        nom_test = _errors(te, base)
        return ScreenResult(effect.name, {}, float("nan"), float("nan"), _rms(nom_test), float("nan"),
                            float("nan"), True)
    refit = tuple(refit) + tuple(n for n in effect.screen_refits if n not in refit)
    names = tuple(n for n in refit if n not in effect.parameters) + tuple(effect.parameters)
    # the reference: the nominal with the same parameters refitted on the same inverse dynamics, without the
    # candidate (equal effort: against the closed-loop values, any refit of viscous, Coulomb and offset on
    # inverse dynamics "gains", and every candidate passed on effect-free data)
    reference, _ = _fit(tr, base, tuple(n for n in refit if n not in effect.parameters), {}, {})
    nom_test = _errors(te, reference, run_level)
    starts = [dict(s) for s in effect.starts]
    if effect.name == "time_ripple":
        starts = [{"ripple_frequency": f} for f in _peak_frequencies(whole, base, effect.bounds["ripple_frequency"])]
    from drakecreep.gap.drake_effects import peak_drive_force, physical_bounds

    bounds = dict(effect.bounds)
    bounds.update(physical_bounds(effect, base, peak_force=peak_drive_force(train)))
    # a period the samples cannot resolve at the top speed (its frequency v / P above the Nyquist frequency of
    # the screen's signals) is aliased: a "peak" there fits noise at a false period
    nyquist_period = 2.0 * float(np.median(np.diff(whole[0][0]))) * v_top

    def resolvable(name, harmonic=1):  # the band of periods whose ``harmonic`` the samples resolve
        lo, hi = bounds[name]
        bounds[name] = band = (min(max(lo, harmonic * nyquist_period), 0.5 * hi), hi)
        return band

    if "position_period" in effect.parameters:
        starts = [{"position_period": period}
                  for period in _peak_periods(tr, reference, resolvable("position_period"))]
    if "lead" in effect.parameters:
        # the lead error's force is m_t e''(x) v^2: lines at the lead and at half of it; a peak is either
        # (the second harmonic's force is 4 times its amplitude's), and its second harmonic must be resolved
        band = resolvable("lead", harmonic=2)
        peaks = _peak_periods(tr, reference, (0.5 * band[0], band[1]))
        starts = [{"lead": lead} for lead in dict.fromkeys(x for p in peaks for x in (p, 2.0 * p))
                  if band[0] <= lead <= band[1]] or [{"lead": band[0]}]
    for key, dense in _DENSE.items():
        if key in effect.parameters:
            lo, hi = bounds.get(key, (-np.inf, np.inf))
            starts = [dict(s, **{key: v}) for s in starts[:1] for v in dense if lo < v < hi] or starts
    best, best_cost = None, math.inf
    for s in starts:
        values, cost = _fit(tr, base, names, s, bounds)
        if cost < best_cost:
            best, best_cost = values, cost
    train_err = _errors(tr, best)
    test_err = _errors(te, best, run_level)
    gain, se = mean_and_standard_error(nom_test - test_err)
    # decided on the per-run log error ratio, as the claim: the held-out runs differ in speed, and a gain in
    # points of a slow run's error is not one of a fast run's
    lr, lr_se = mean_log_ratio(nom_test, test_err)
    # the linear parameters are solved unbounded: a value outside the effect's bounds is not that effect
    outside = {n: (best[n], *bounds[n]) for n in effect.parameters
               if n in bounds and not bounds[n][0] <= best[n] <= bounds[n][1]}
    const = constancy(tr, best, refit, effect) if effect.run_constancy else None
    ok = not outside and lr > k_se * lr_se and (const is None or const.constant)
    start = {n: best[n] for n in effect.parameters}
    if effect.shifts_nominal:
        # the nominal friction moved by what the candidate took over of it on inverse dynamics (its closed-loop
        # start: from the nominal's own values and the candidate's alone, a load friction of 0.6 made the
        # held-out replay 6 times worse, and six evaluations did not find the way back)
        start.update({n: base[n] + best[n] - reference[n] for n in refit if n not in effect.parameters})
    # the nominal parameters outside the friction that the candidate biases (DrakeEffect.screen_refits): the
    # candidate's values, and the reference's for its equal-effort closed-loop reference (a shift of the
    # nominal's value would not do: the IDIM mass on the whole runs and the screen's on the sliding samples
    # differ by 40 % on a saturated dataset, 236 kg against 165 kg on development seed 32004)
    start.update({n: best[n] for n in effect.screen_refits})
    # the second closed-loop starts (ScreenResult.alternative_start): each model's own inverse-dynamics values
    own, reference_own = ({**start, **{n: best[n] for n in refit}}, {n: reference[n] for n in refit}) \
        if effect.screen_refits or effect.own_start else ({}, {})
    return ScreenResult(effect.name, start, _rms(train_err), _rms(test_err),
                        _rms(nom_test), gain, se, bool(ok), lr, lr_se, const,
                        {n: reference[n] for n in effect.screen_refits}, own, reference_own, outside)


#: parameters that set a candidate's shape, not its size (held at the pooled fit in the constancy test)
SHAPE = ("stribeck_velocity", "position_period", "ripple_frequency", "lead")


@dataclass(frozen=True)
class Constancy:
    """Are a candidate's fitted amplitudes the same in every training run? (:func:`constancy`)

    Attributes
    ----------
    per_run : tuple of dict
        Per training run, the candidate's amplitude parameters fitted on that run alone.
    chi2, dof : float, int
        Wald statistic of the per-run amplitudes against their precision-weighted mean, and its degrees of
        freedom (``rank`` of the amplitudes' information, summed over runs, minus that of the mean).
    p_value : float
        ``P(chi2_dof > chi2)``.
    constant : bool
        ``p_value >= alpha``: the runs do not contradict one constant effect.
    """

    per_run: tuple
    chi2: float
    dof: int
    p_value: float
    constant: bool


def _jacobian(sig, norm, values, names):
    """Central-difference Jacobian of the normalised inverse-dynamics force of one run in ``names``."""
    t, q, dq, ddq, tau = sig
    cols = []
    for n in names:
        h = 1e-6 * max(abs(values[n]), 1.0 if n in LINEAR else 1e-2)
        hi = inverse_dynamics_force(dict(values, **{n: values[n] + h}), t, q, dq, ddq, tau)
        try:
            lo, span = inverse_dynamics_force(dict(values, **{n: values[n] - h}), t, q, dq, ddq, tau), 2.0 * h
        except InputError:  # at the edge of the parameter's domain (a drive limit of 0): one-sided
            lo, span = inverse_dynamics_force(values, t, q, dq, ddq, tau), h
        cols.append((hi - lo) / (span * norm))
    return np.column_stack(cols)


def _profile_information(Jn, Ja):
    """Information on the amplitudes (columns ``Ja``) with the nominal parameters (``Jn``) profiled out, per
    unit residual variance: ``Ja^T (I - P_n) Ja``, its eigenvalues below :data:`RCOND` of the largest cut
    (columns scaled to unit norm). Directions one run does not determine (a friction map's segment it never
    reaches, an amplitude collinear with its Coulomb level) then carry no weight, whatever value the run's fit
    left there."""
    if Jn.shape[1]:
        cn = np.maximum(np.linalg.norm(Jn, axis=0), 1e-300)
        U, sv, _ = np.linalg.svd(Jn / cn, full_matrices=False)
        U = U[:, sv > RCOND * sv[0]]
        Ja = Ja - U @ (U.T @ Ja)
    ca = np.maximum(np.linalg.norm(Ja, axis=0), 1e-300)
    w, V = np.linalg.eigh((Ja / ca).T @ (Ja / ca))
    w = np.where(w > RCOND * max(float(w.max()), 1e-300), w, 0.0)
    return (V * w) @ V.T * np.outer(ca, ca)


def _scaled(a):
    d = np.sqrt(np.maximum(np.abs(np.diag(a)), 1e-300))
    return a / np.outer(d, d), d


def _pinv_scaled(a):
    """Pseudo-inverse of a symmetric matrix after scaling it to unit diagonal (relative cut RCOND)."""
    b, d = _scaled(a)
    return np.linalg.pinv(b, rcond=RCOND, hermitian=True) / np.outer(d, d)


def _rank_scaled(a):
    """Rank of a symmetric matrix after scaling it to unit diagonal (relative cut RCOND)."""
    s = np.linalg.eigvalsh(_scaled(a)[0])
    return int(np.sum(s > RCOND * max(float(np.max(s)), 1e-300)))


def constancy(tr, pooled, refit, effect, alpha=ALPHA):
    """Chow-type test of one candidate on the training runs' inverse dynamics (IDIM signals ``tr``).

    Each training run is fitted alone, the nominal parameters ``refit`` and the candidate's amplitudes free
    (its :data:`SHAPE` parameters held at the ``pooled`` fit). The information on the amplitudes per run is
    ``Ja^T (I - P_n) Ja / (tau s^2)`` (:func:`_profile_information`: ``J`` the Jacobian of the run's normalised
    force, the nominal columns profiled out, ``s^2`` the residual variance, ``tau`` the integrated
    autocorrelation time of the residual: the filtered signals' samples are not independent). The statistic is
    the Wald ``chi2`` of the per-run amplitudes about their precision-weighted mean. A physical effect has one value; an effect that only mimics another varies with the run's
    conditions. The case that motivates it: within an out-and-back run at speed ``v``, a friction drift
    ``d t`` is a force ``d Fc x / v`` (a spring), so on a cable carrier's spring the drift fits a ``d``
    proportional to each run's speed (docs/gap_benchmark.md, 3e).

    Returns
    -------
    Constancy or None
        None with fewer than two runs or no amplitude parameter.
    """
    from scipy import stats

    from drakecreep.gap.identify import correlation_time

    amps = tuple(n for n in effect.parameters if n not in SHAPE)
    if len(tr) < 2 or not amps:
        return None
    names = tuple(n for n in refit if n not in amps) + amps
    thetas, infos, per_run = [], [], []
    for sig in tr:
        # unbounded: the Wald statistic needs the unconstrained estimate (the pooled fit's bounds keep a
        # physical model; one run alone may pull an amplitude past them, with the large variance that says so)
        values, _ = _fit([sig], pooled, names, {}, {})
        norm = float(np.linalg.norm(sig[4]))
        r = (sig[4] - inverse_dynamics_force(values, *sig)) / norm
        J = _jacobian(sig, norm, values, names)
        m, p = J.shape
        s2 = correlation_time(r) * float(r @ r) / max(m - p, 1)
        k = len(names) - len(amps)
        infos.append(_profile_information(J[:, :k], J[:, k:]) / s2)
        thetas.append(np.array([values[n] for n in amps]))
        per_run.append({n: values[n] for n in amps})
    info = sum(infos)
    mean = _pinv_scaled(info) @ sum(w @ th for w, th in zip(infos, thetas))
    chi2 = float(sum((th - mean) @ w @ (th - mean) for w, th in zip(infos, thetas)))
    dof = int(sum(_rank_scaled(w) for w in infos) - _rank_scaled(info))
    p_value = float(stats.chi2.sf(chi2, dof)) if dof > 0 else 1.0
    return Constancy(tuple(per_run), chi2, dof, p_value, bool(p_value >= alpha))


def _peak_frequencies(sig, base, band, count=3):
    """The ``count`` largest peaks [Hz] of the summed inverse-dynamics residual spectrum inside ``band``."""
    from scipy.signal import find_peaks, welch

    total, f = None, None
    dt = float(np.median(np.diff(sig[0][0])))
    nper = min(1024, min(s[0].size for s in sig))
    for t, q, dq, ddq, tau in sig:
        f, p = welch(tau - inverse_dynamics_force(base, t, q, dq, ddq, tau), fs=1.0 / dt, nperseg=nper)
        total = p if total is None else total + p
    inside = (f >= band[0]) & (f <= band[1])
    fi, pi = f[inside], total[inside]
    if fi.size == 0:
        return (float(band[0]),)
    peaks, _ = find_peaks(pi)
    if peaks.size == 0:
        peaks = np.array([int(np.argmax(pi))])
    order = peaks[np.argsort(pi[peaks])[::-1]][:count]
    return tuple(float(fi[i]) for i in order)


#: frequencies per call of :func:`scipy.signal.lombscargle` in :func:`_peak_periods`
_LOMB_BLOCK = 512


def _peak_periods(sig, base, band, count=3):
    """The ``count`` periods [m] of the largest peaks of the Lomb-Scargle periodogram of the inverse-dynamics
    residual against the motor position (``band``: shortest and longest period).

    A force periodic in position is a spectral line in the position's frequency; the samples are not evenly
    spaced in position, hence Lomb-Scargle (:func:`scipy.signal.lombscargle`). The grid of angular frequencies
    is fine enough that the phase over the travel covered stays within 1/8 cycle between neighbours: a least
    squares refined from 14 log-spaced starts converged to a neighbouring period with the wrong sign of the
    amplitude on development data with a lead error (docs/gap_benchmark.md, "period scan").
    """
    from scipy.signal import find_peaks, lombscargle

    q = np.concatenate([s[1] for s in sig])
    r = np.concatenate([(s[4] - inverse_dynamics_force(base, *s)) / np.linalg.norm(s[4]) for s in sig])
    travel = max(float(np.ptp(q)), 1e-6)
    w_lo, w_hi = 2.0 * math.pi / band[1], 2.0 * math.pi / band[0]
    step = 0.25 * math.pi / travel  # 1/8 cycle over the travel
    w = np.arange(w_lo, w_hi + step, step) if (w_hi - w_lo) / step < 2e5 else np.linspace(w_lo, w_hi, 200_000)
    # in blocks of frequencies: each frequency's power is computed alone (normalize and floating_mean off), so the
    # blocks give the same values to rounding (1e-15), at under half the time (scipy 1.17 forms samples x
    # frequencies arrays: 180 MB for an EMPS screen's 5901 x 3783, 3.5 s against 1.4 s in blocks of 512)
    x, y = q - q.mean(), r - r.mean()
    power = np.concatenate([np.atleast_1d(lombscargle(x, y, w[i:i + _LOMB_BLOCK]))  # (one frequency: a 0-d array)
                            for i in range(0, w.size, _LOMB_BLOCK)])
    peaks, _ = find_peaks(power)
    if peaks.size == 0:
        peaks = np.array([int(np.argmax(power))])
    order = peaks[np.argsort(power[peaks])[::-1]][:count]
    return tuple(float(2.0 * math.pi / w[i]) for i in order)


def screen_delay(train, nominal_parameters, *, max_delay=3.0, step=0.05):
    """Computation delay [controller ticks: samples of a run logged every tick] that best explains the training
    runs' inverse dynamics (a scan of the measured drive force delayed by ``0 .. max_delay`` ticks); the start of
    the closed-loop delay search."""
    base = dict(AXIS_PARAMETERS)
    base.update(nominal_parameters)
    ticks = [controller_ticks(r) for r in train]
    best, best_err = 0.0, math.inf
    for d in np.arange(0.0, max_delay + 1e-9, step):
        # the centred acceleration at t_k sees the mean of the forces held before and after t_k: an undelayed
        # held force is the measured one shifted by half a sample
        err = _rms(_errors([_signals(r, d / m + 0.5) for r, m in zip(train, ticks)], base))
        if err < best_err:
            best, best_err = float(d), err
    return best
