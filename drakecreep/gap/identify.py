"""Identification of the replay axis from training runs: IDIM-LS start, then output-error refinement in Drake.

1. **Start** (:func:`idim_start`): the IDIM linear least squares of :mod:`drakecreep.gap.idim` (one
   pre-processing: Butterworth, central differences, decimation, borders) on all training runs stacked:
   ``tau = M ddq + Fv dq + Fc sign(dq) + offset``. When every run moves one way ``sign(dq)`` and the
   constant column are the same regressor: Coulomb and offset cannot be told apart; the offset is then
   fixed at 0 and a warning says so. Then IDIM-IV (``instruments``): the same equation with the closed-loop
   replay of that model as instruments, consistent where a force the model lacks shakes the measured axis
   (a lead error's ripple made least squares halve the mass; docs/gap_benchmark.md, 3x).
2. **Refinement** (:func:`identify`): the parameters the user marks as uncertain (any of
   :data:`drakecreep.model.axis.AXIS_PARAMETERS`: friction levels, asymmetry, Stribeck level and speed,
   axial stiffness and damping, ...) are fitted by :func:`scipy.optimize.least_squares` on the closed-loop
   replay error: each evaluation sets the values in the context of the replay diagrams
   (:class:`~drakecreep.gap.drake_replay.DrakeReplay`, built once per run) and simulates them. The residual
   is, per run and sample, the drive force error over the run's force norm and the position error over
   the run's position norm, both weighted so that each run counts equally.
3. **Confidence** (:class:`Identified`): ``cov = s^2 (J^T J)^-1`` from the Jacobian at the solution,
   ``s^2 = ||r||^2 / (m - p)``, times the integrated autocorrelation time of the residual (closed-loop
   residuals are correlated in time: ``m`` samples carry about ``m / tau_int`` independent ones), 95 %
   intervals ``+-1.96 std``. They still assume the model structure is right; a warning is raised for any pair of fitted parameters correlated beyond
   ``|rho| > 0.95`` (not separable by these runs) and for a rank-deficient Jacobian.
4. **Leave one run out** (:attr:`Identified.jackknife`): with two or more runs, the values with each training
   run left out, one Gauss-Newton step from the solution on the other runs' rows of the same Jacobian (no
   replays; relative to the step on all runs, so a fit that is not converged is not mistaken for run-to-run
   variation), and their jackknife standard deviation ``sqrt((n-1)/n sum (v_k - mean)^2)``. It asks how much
   the values depend on which runs were measured; the Jacobian's interval assumes one axis behind every run,
   and friction drifts between runs.

Parameters that must stay positive are fitted on a log scale; the others on a scale of their start value.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from drakecreep.errors import InputError
from drakecreep.gap.drake_replay import diverged_result, drake_replay_errors, make_replay, simulate_each
from drakecreep.gap.idim import PARAMETER_NAMES, idim_signals, regressor, relative_error
from drakecreep.gap.residuals import limit_cycle
from drakecreep.model.axis import AXIS_PARAMETERS, AXIS_UNITS, FRICTION_MAP, LEAD_ERROR, POSITION_RIPPLE

__all__ = ["IdimStart", "Identified", "idim_start", "identify", "correlation_time", "LOG_SCALED", "CORRELATION_LIMIT",
           "PRESLIDING_START", "DEFAULT_BOUNDS", "START_FLOOR_SHARE", "start_floors"]

#: parameters fitted on a log scale (they must stay > 0)
LOG_SCALED = ("mass", "stribeck_velocity", "regularization_velocity", "stiffness", "damping", "viscous",
              "coulomb", "stribeck_extra", "bristle_stiffness")
#: presliding displacement [m] the bristle stiffness starts from (``sigma0 = Fc / 5 um``) when it is refined:
#: an assumption, the middle of the 1-10 um that ball-screw and guide contacts show (Armstrong-Helouvry et al.
#: 1994, Automatica 30(7), section 3.1); the fit moves it
PRESLIDING_START = 5e-6
#: bounds [SI] a refined parameter keeps when the caller gives none: the share of the friction that sticks
#: (``bristle_share``, :mod:`drakecreep.model.axis`) in (0, 1]; at least 5 % of it, or the bristles' rate
#: ``sigma0 |v| / (b g)`` would outrun any step
DEFAULT_BOUNDS = {"bristle_share": (0.05, 1.0)}
#: share of the training runs' RMS drive force that the start of a refined Coulomb level, or of a refined viscous
#: force at their RMS moving speed, is given when its start is 0 (:func:`start_floors`). IDIM sets a negative value
#: to 0, and a log-scaled parameter started at 0 sits at ``log(1e-300)``, 690 units from any physical value: it is
#: never refined, and neither is it by any candidate fitted from that nominal (a Stribeck's friction falling with
#: speed over slow training runs gives a negative IDIM viscous; the held-out fast runs then replay without any
#: viscous force: docs/gap_benchmark.md, 3aj). A tenth, the geometric middle of a term worth 1-100 % of the force;
#: a start that is positive, however small, is kept, and the fit may go below the floor again.
START_FLOOR_SHARE = 0.1
#: a start below this share of its floor counts as 0 (a millionth of it: a force of 1e-7 of the drive's)
_AT_ZERO = 1e-6
#: |correlation| above which two fitted parameters are reported as not separable
CORRELATION_LIMIT = 0.95
#: residual put in place of each non-finite sample of a diverged replay, and the largest magnitude a sample's
#: residual is given (a normalised residual of a good fit is of order 0.01-1 per sample)
NONFINITE_RESIDUAL = 1e3
_ONE_WAY_SHARE = 0.02
#: the inverse-dynamics parameters of the IDIM start (:func:`idim_start`), by their names in the axis
_IDIM_NAMES = ("mass", "viscous", "coulomb", "offset")


@dataclass(frozen=True)
class IdimStart:
    """IDIM on the stacked training runs: values in :data:`AXIS_PARAMETERS` names, std, warnings; ``method``
    ``"LS"`` (least squares) or ``"IV"`` (instrumental variables, :func:`idim_start`)."""

    parameters: dict
    std: dict
    fit_error_percent: float
    warnings: tuple = ()
    method: str = "LS"


def idim_start(runs, instruments=None, **preprocess):
    """IDIM-LS start values from all training runs (one pre-processing, :func:`drakecreep.gap.idim.idim_signals`),
    or IDIM-IV with ``instruments``.

    Parameters
    ----------
    runs : sequence of drakecreep.gap.measured.MeasuredRun
    instruments : sequence of numpy.ndarray, optional
        Simulated motor positions [m] of ``runs`` (one array per run, on its samples): the closed-loop replay of
        a model. Their regressor, through the same pre-processing, is the instrument ``Z`` of the instrumental
        variable estimate ``theta = (Z^T W)^-1 Z^T tau`` (IDIM-IV: Janot, Vandanjon and Gautier 2014, IEEE Trans.
        Control Syst. Technol. 22(1), on the EMPS axis). A force the model lacks (a lead error's ``e''(x) v^2``
        at 60 Hz) moves the measured axis too, so the measured acceleration is correlated with the equation error
        and least squares shrinks the mass (held-out dataset 31003011: 42.8 kg for a 94.3 kg axis); the
        simulated acceleration is not (95.3 kg). None: least squares.
    **preprocess
        Options of :func:`~drakecreep.gap.idim.idim_signals`.

    Returns
    -------
    IdimStart
    """
    runs = list(runs)
    if not runs:
        raise InputError("runs", 0, "at least one training run")
    sig = [idim_signals(r, **preprocess) for r in runs]
    dq = np.concatenate([s.dq for s in sig])
    ddq = np.concatenate([s.ddq for s in sig])
    tau = np.concatenate([s.tau for s in sig])
    W = regressor(dq, ddq)
    Z = None
    if instruments is not None:
        instruments = list(instruments)
        if len(instruments) != len(runs):
            raise InputError("instruments", f"{len(instruments)} arrays", f"one per run ({len(runs)})")
        zs = [idim_signals(dataclasses.replace(r, x_motor=np.asarray(x, dtype=float)), **preprocess)
              for r, x in zip(runs, instruments)]
        Z = regressor(np.concatenate([z.dq for z in zs]), np.concatenate([z.ddq for z in zs]))
    warnings = []
    moving = np.abs(dq) > 1e-3 * max(np.max(np.abs(dq)), 1e-12)
    forward = float(np.mean(dq[moving] > 0)) if moving.any() else 0.5
    cols = list(range(len(PARAMETER_NAMES)))
    if min(forward, 1 - forward) < _ONE_WAY_SHARE:
        warnings.append(f"the training runs move one way ({100 * forward:.1f} % of moving samples forward): "
                        "Coulomb friction and the offset are not separable; offset fixed at 0")
        cols = [0, 1, 2]
    Ws = W[:, cols]
    if np.linalg.matrix_rank(Ws) < Ws.shape[1]:
        raise InputError("runs", [r.label for r in runs], "motions that excite acceleration and speed")
    n, p = Ws.shape
    if Z is not None:
        Zs = Z[:, cols]
        A = Zs.T @ Ws
        if np.linalg.matrix_rank(A) < p:
            raise InputError("instruments", "a simulated motion", "one that excites acceleration and speed")
        theta = np.linalg.solve(A, Zs.T @ tau)
        r = tau - Ws @ theta
        Ai = np.linalg.inv(A)
        cov = float(r @ r) / (n - p) * Ai @ (Zs.T @ Zs) @ Ai.T
    else:
        theta, *_ = np.linalg.lstsq(Ws, tau, rcond=None)
        r = tau - Ws @ theta
        cov = float(r @ r) / (n - p) * np.linalg.inv(Ws.T @ Ws)
    full = np.zeros(len(PARAMETER_NAMES))
    std = np.zeros(len(PARAMETER_NAMES))
    full[cols] = theta
    std[cols] = np.sqrt(np.diag(cov))
    names = {"M": "mass", "Fv": "viscous", "Fc": "coulomb", "offset": "offset"}
    if Z is None and not full[0] > 0:  # least squares on the measured signals: named in their terms (the axis
        # refused it as 'axis.mass'); an instrumental-variable mass that is not positive is the caller's to drop
        raise InputError("u", f"a drive force whose inverse-dynamics mass is {full[0]:.3g} kg",
                         "a u that pushes the axis the way it accelerates (" + _no_mass_cause(runs) + ")")
    if full[2] < 0:
        warnings.append(f"IDIM gives a negative Coulomb level ({full[2]:.3g} N): set to 0")
        full[2] = 0.0
    if full[1] < 0:
        warnings.append(f"IDIM gives a negative viscous coefficient ({full[1]:.3g} N s/m): set to 0")
        full[1] = 0.0
    return IdimStart(parameters={names[k]: float(v) for k, v in zip(PARAMETER_NAMES, full)},
                     std={names[k]: float(v) for k, v in zip(PARAMETER_NAMES, std)},
                     fit_error_percent=relative_error(tau, Ws @ theta), warnings=tuple(warnings),
                     method="LS" if Z is None else "IV")


@dataclass(frozen=True)
class Identified:
    """Result of :func:`identify`.

    Attributes
    ----------
    parameters : dict
        All axis parameters (fitted and fixed), SI.
    fitted : tuple of str
        The names refined by output error.
    std, ci95 : dict
        Standard deviation and 95 % half-width of each fitted parameter (see the module docstring).
    correlation : numpy.ndarray
        Correlation matrix of the fitted parameters.
    warnings : tuple of str
        Separability and start-value warnings.
    start : IdimStart
    train_errors : dict
        Run label -> replay errors [%] with the identified parameters.
    cost_start, cost : float
        ``0.5 ||r||^2`` at the start and at the solution.
    n_evaluations : int
        Replays of the training set (one per residual evaluation).
    evaluations_per_s : float
    flexible : bool
    delay : float
    jackknife : tuple of dict
        Per training run left out, the fitted values from the other runs (module docstring, 4); empty with
        one run or nothing fitted.
    jackknife_std : dict
        Jackknife standard deviation of each fitted value over :attr:`jackknife` (SI).
    """

    parameters: dict
    fitted: tuple
    std: dict
    ci95: dict
    correlation: np.ndarray
    warnings: tuple
    start: IdimStart
    train_errors: dict
    cost_start: float
    cost: float
    n_evaluations: int
    evaluations_per_s: float
    flexible: bool = False
    delay: float = 0.0
    extra: dict = field(default_factory=dict)
    jackknife: tuple = ()
    jackknife_std: dict = field(default_factory=dict)

    @property
    def mass_source(self):
        """Where the mass comes from: ``output error`` (refined), ``IDIM-IV start`` / ``IDIM-LS start`` (never
        refined unless marked uncertain), or ``given`` (a value the caller fixed)."""
        if "mass" in self.fitted:
            return "output error"
        if self.start is not None and self.parameters["mass"] == self.start.parameters.get("mass"):
            return f"IDIM-{self.start.method} start"
        return "given"

    def summary(self):
        """Lines of text: the fitted values with their intervals, the warnings."""
        lines = [f"identified ({'two-mass' if self.flexible else 'rigid'} axis, delay {self.delay:g} controller "
                 f"samples, {self.n_evaluations} replays at {self.evaluations_per_s:.2f}/s):"]
        for name in self.fitted:
            jack = (f" (leave one run out: std {self.jackknife_std[name]:.3g})" if name in self.jackknife_std else "")
            lines.append(f"  {name:24s} {self.parameters[name]:12.5g} +- {self.ci95[name]:.3g} {AXIS_UNITS[name]}"
                         + jack)
        if "mass" not in self.fitted:
            lines.append(f"  {'mass':24s} {self.parameters['mass']:12.5g} kg ({self.mass_source}, not refined)")
        lines += [f"  warning: {w}" for w in self.warnings]
        return lines


class _Problem:
    def __init__(self, replays, base, names):
        self.replays, self.base, self.names = replays, dict(base), tuple(names)
        self.log = np.array([n in LOG_SCALED for n in self.names])
        # x = value / scale: one unit of x is a typical size of the parameter (force terms: the Coulomb level)
        force = max(abs(base.get("coulomb", 0.0)), 1.0)
        typical = {"friction_drift": 1e-2, "friction_ripple_cos": 0.3, "friction_ripple_sin": 0.3,
                   **{n: 0.1 for n in FRICTION_MAP},
                   **{n: force for n in POSITION_RIPPLE},
                   "offset": force, "coulomb_asym": force, "time_ripple_cos": force, "time_ripple_sin": force,
                   "viscous_asym": max(abs(base.get("viscous", 0.0)), 1.0), "motor_mass_fraction": 0.2,
                   # parameters whose start may be ~0 (the screen's answer on data without the effect): a scale of
                   # the start's size makes every finite-difference step invisible (a 400 N drive limit; a load
                   # friction coefficient of 0.1)
                   "inverse_drive_limit": 1.0 / 400.0, "load_friction_coefficient": 0.1,
                   **{n: 1e-5 for n in LEAD_ERROR}}
        # phase-like parameters: a step must move the phase over a run by much less than a cycle
        fine = {"ripple_frequency": 1.0, "position_period": 0.01 * base["position_period"],
                "lead": 0.01 * base.get("lead", 5e-3),
                "friction_period": 0.05 * base["friction_period"]}
        scale = []
        for i, n in enumerate(self.names):
            if n in fine:
                scale.append(fine[n])
                continue
            scale.append(1.0 if self.log[i] else max(abs(base[n]), typical.get(n, 0.0)) or 1.0)
        self.scale = np.array(scale)
        self.evaluations = 0
        self.seconds = 0.0
        self._last = None

    def to_x(self, values):
        v = np.array([values[n] for n in self.names], dtype=float)
        return np.where(self.log, np.log(np.maximum(v, 1e-300)), v / self.scale)

    def scalar_x(self, i, value):
        if self.log[i]:
            return math.log(value) if value > 0 else -np.inf
        return value / self.scale[i]

    def to_values(self, x):
        with np.errstate(over="ignore"):  # past exp's range: inf, replayed as diverged (simulate)
            v = np.where(self.log, np.exp(x), x * self.scale)
        out = dict(self.base)
        out.update(zip(self.names, (float(a) for a in v)))
        return out

    def simulate(self, values):
        start = _time.perf_counter()
        if all(math.isfinite(v) for v in values.values()):
            results = simulate_each(self.replays, values)
        else:  # a log-scaled step past exp's range (inf): a replay that cannot be run is a diverged one
            results = [diverged_result(rep.run, values) for rep in self.replays]
        self.evaluations += 1
        self.seconds += _time.perf_counter() - start
        return results

    def residual(self, x):
        x = np.asarray(x, dtype=float)
        if self._last is not None and np.array_equal(self._last[0], x):
            return self._last[1]
        r = self.residual_of(self.simulate(self.to_values(x)))
        self._last = (x.copy(), r)
        return r

    def jacobian(self, x, step, hi):
        """Forward differences with an ABSOLUTE step in the scaled variables (backwards at an upper bound).

        (scipy's ``diff_step`` is relative to ``|x|`` and falls back to ~1e-8 at ``x = 0``, where the
        counted replay does not change at all.)
        """
        x = np.asarray(x, dtype=float)
        r0 = self.residual(x)
        J = np.empty((r0.size, x.size))
        for i in range(x.size):
            h = step if x[i] + step <= hi[i] else -step
            xi = x.copy()
            xi[i] += h
            J[:, i] = (self.residual_of(self.simulate(self.to_values(xi))) - r0) / h
        return J

    @staticmethod
    def residual_of(results):
        parts = []
        for res in results:
            run = res.run
            w = 1.0 / math.sqrt(run.n)
            parts.append(w * (res.force - run.force) / (np.linalg.norm(run.force) / math.sqrt(run.n)))
            xs = run.x_motor - run.x_motor.mean()
            parts.append(w * (res.x_motor - run.x_motor) / (np.linalg.norm(xs) / math.sqrt(run.n) or 1.0))
        # a replay that diverged (NaN or inf samples) is a very poor fit, not an error: the least squares must
        # step back from it (held-out dataset 21011000 of run 10, a cable carrier: a candidate's closed-loop
        # replay went non-finite and the SVD of the trust-region step raised, losing the dataset)
        # A replay on its way to diverging can still be finite but huge (1e200): its square overflows the cost
        # to inf and the SVD raised just the same (held-out dataset 29010000 of run 14, a drive saturation), so
        # the residual is also clipped to +-NONFINITE_RESIDUAL per sample
        big = NONFINITE_RESIDUAL
        return np.clip(np.nan_to_num(np.concatenate(parts), nan=big), -big, big)  # +-inf: clipped to +-big


def _no_mass_cause(runs):
    """The likely cause of a non-positive least-squares mass, for :func:`idim_start`'s refusal: a limit cycle of
    the drive force on most runs (an unstable real loop swamps the rigid inverse dynamics: a benchmark truth with a
    delay gave -162 kg), else a reversed sign."""
    hits = [o for o in (limit_cycle(r.u, r.dt) for r in runs) if o is not None]
    if 2 * len(hits) > len(runs):
        f = float(np.median([o["freq_Hz"] for o in hits]))
        share = float(np.median([o["share"] for o in hits]))
        return (f"the drive force oscillates at {f:.0f} Hz on {len(hits)} of {len(runs)} runs, "
                f"{100 * share:.0f} % of its variance: is the real loop unstable? A limit cycle hides the mass")
    return "is the sign of u or u_gain, or the direction of x_motor, reversed?"


def identify(runs, uncertain=("viscous", "coulomb", "offset"), *, flexible=False, delay=0.0, fixed=None,
             bounds=None, max_nfev=20, quantize=True, replays=None, diff_step=0.05, instruments=True, **preprocess):
    """Identify the replay axis on training runs (see the module docstring).

    Parameters
    ----------
    runs : sequence of drakecreep.gap.measured.MeasuredRun
        Training runs (``p_p_cascade`` metadata). Never pass a validation run here.
    uncertain : sequence of str
        Parameters refined by output error (names of :data:`~drakecreep.model.axis.AXIS_PARAMETERS`);
        empty: the IDIM start only.
    flexible : bool
        Two-mass axis.
    delay : float
        Computation delay [samples] of the replay.
    fixed : dict, optional
        Values that override the IDIM start (and the axis defaults) before refinement.
    bounds : dict, optional
        ``name -> (lo, hi)`` in SI for the refined parameters (:data:`DEFAULT_BOUNDS` where not given).
    max_nfev : int
        Largest number of residual evaluations of the least squares (each replays every run).
    quantize : bool
        Encoder counts in the replay.
    replays : sequence of DrakeReplay or SampledReplay, optional
        Prebuilt replay diagrams of ``runs`` (same ``flexible``/``delay``), reused without a rebuild. Default:
        :func:`~drakecreep.gap.drake_replay.make_replay` with ``free=uncertain`` (the sampled fast path for a
        whole-sample delay, only the refined parameters symbolic).
    diff_step : float
        Absolute finite-difference step of the Jacobian in the scaled variables (5 % of a log-scaled value, or
        5 % of a typical size): large enough to step over the encoder's counts (the replay with a counted position
        is only piecewise smooth in the parameters).
    instruments : bool
        Replace the IDIM-LS start of the inverse-dynamics parameters (mass, viscous, Coulomb, offset) that
        ``fixed`` does not give by IDIM-IV (:func:`idim_start`), its instruments the closed-loop replay of the
        IDIM-LS model (one replay of each run; the least-squares start is kept, with a warning, when that
        replay fails). The mass is never refined by output error unless marked uncertain, so its start is what
        the model keeps.
    **preprocess
        Options of the IDIM pre-processing.

    Returns
    -------
    Identified
    """
    runs = list(runs)
    uncertain = tuple(uncertain)
    for name in uncertain:
        if name not in AXIS_PARAMETERS:
            raise InputError("uncertain", name, "names among " + ", ".join(AXIS_PARAMETERS))
    if len(set(uncertain)) != len(uncertain):
        raise InputError("uncertain", list(uncertain), "distinct names")
    if int(max_nfev) != max_nfev or max_nfev < 1:
        raise InputError("max_nfev", max_nfev, "an integer >= 1")
    start = idim_start(runs, **preprocess)
    base = dict(AXIS_PARAMETERS)
    base.update(start.parameters)
    base["regularization_velocity"] = _regularization(runs)
    base.update(fixed or {})
    warnings = list(start.warnings)
    if any("offset fixed at 0" in w for w in warnings) and "offset" in uncertain and "coulomb" in uncertain:
        warnings.append("'coulomb' and 'offset' both marked uncertain on one-way data: 'offset' left at 0")
        uncertain = tuple(n for n in uncertain if n != "offset")
    iv = tuple(n for n in _IDIM_NAMES if n not in (fixed or {})) if instruments else ()
    if replays is None:
        # the mass stays symbolic when the IV start moves it: one build serves the instruments' replay and the fit
        free = uncertain + (("mass",) if "mass" in iv and "mass" not in uncertain else ())
        replays = [make_replay(r, flexible=flexible, delay=delay, quantize=quantize, free=free) for r in runs]
    if iv:
        sims = simulate_each(replays, base)
        xs = [res.x_motor for res in sims]
        if all(np.all(np.isfinite(x)) for x in xs):
            iv_start = idim_start(runs, instruments=xs, **preprocess)
        else:
            iv_start = None
        if iv_start is None:
            warnings.append("IDIM-IV: the replay of the least-squares start did not stay finite; the least-squares "
                            "start kept")
        elif not iv_start.parameters["mass"] > 0:
            warnings.append(f"IDIM-IV: the instrumental-variable mass is {iv_start.parameters['mass']:.3g} kg, not "
                            "positive; the least-squares start kept")
        else:
            start = dataclasses.replace(iv_start, warnings=tuple(w for w in iv_start.warnings
                                                                  if w not in start.warnings))
            warnings += list(start.warnings)
            base.update({n: start.parameters[n] for n in iv})
    for name, floor in start_floors(runs).items():
        if name in uncertain and not base[name] > _AT_ZERO * floor:
            warnings.append(f"{name} starts at {floor:.3g} {AXIS_UNITS[name]} instead of {base[name]:.3g}: on its log "
                            f"scale 0 cannot move ({100 * START_FLOOR_SHARE:g} % of the training runs' RMS force)")
            base[name] = floor
    if "bristle_stiffness" in uncertain and "bristle_stiffness" not in (fixed or {}):
        # LuGre bristles from a presliding displacement of PRESLIDING_START at the Coulomb level
        base["bristle_stiffness"] = max(abs(base["coulomb"]), 1.0) / PRESLIDING_START
    prob = _Problem(replays, base, uncertain)
    r0 = prob.residual_of(prob.simulate(base))
    cost_start = 0.5 * float(r0 @ r0)
    values = base
    std, ci, corr = {}, {}, np.zeros((0, 0))
    jack, jack_std = (), {}
    cost = cost_start
    if uncertain:
        x0 = prob.to_x(base)
        lo, hi = np.full(x0.size, -np.inf), np.full(x0.size, np.inf)
        bounds = {**{n: b for n, b in DEFAULT_BOUNDS.items() if n in uncertain}, **(bounds or {})}
        for i, name in enumerate(uncertain):
            if name in bounds:
                lo[i], hi[i] = (prob.scalar_x(i, b) for b in bounds[name])
                if not lo[i] < hi[i]:
                    raise InputError(f"bounds.{name}", bounds[name], "(lo, hi) with lo < hi (lo > 0 on a log scale)")
        x0 = np.clip(x0, np.where(np.isfinite(lo), lo + 1e-9, lo), np.where(np.isfinite(hi), hi - 1e-9, hi))
        sol = least_squares(prob.residual, x0, jac=lambda x: prob.jacobian(x, diff_step, hi), bounds=(lo, hi),
                            method="trf", x_scale=1.0,
                            max_nfev=max_nfev, xtol=1e-8, ftol=1e-8, gtol=1e-10)
        values = prob.to_values(sol.x)
        cost = float(sol.cost)
        std, ci, corr, more = _confidence(sol, prob, values)
        warnings += more
        jack, jack_std = _leave_one_run_out(sol, prob, lo, hi)
    results = prob.simulate(values)
    errors = {res.run.label + (f"#{i}" if sum(r.run.label == res.run.label for r in results) > 1 else ""):
              drake_replay_errors(res, bands=False) for i, res in enumerate(results)}
    rate = prob.evaluations / prob.seconds if prob.seconds > 0 else float("nan")
    return Identified(parameters=values, fitted=uncertain, std=std, ci95=ci, correlation=corr,
                      warnings=tuple(warnings), start=start, train_errors=errors, cost_start=cost_start, cost=cost,
                      n_evaluations=prob.evaluations, evaluations_per_s=rate, flexible=bool(flexible),
                      delay=float(delay), jackknife=jack, jackknife_std=jack_std)


def _leave_one_run_out(sol, prob, lo, hi):
    """The fitted values with each run left out (module docstring, 4): ``(tuple of dict, jackknife std)``.

    One Gauss-Newton step on the other runs' rows of the solution's Jacobian (minimum norm, singular values below
    1e-10 of the largest cut), less the step on all rows, clipped to the bounds."""
    sizes = [2 * rep.run.n for rep in prob.replays]  # rows per run: force, then position (_Problem.residual_of)
    if len(sizes) < 2 or sum(sizes) != sol.fun.size:
        return (), {}
    J, r = np.asarray(sol.jac, dtype=float), np.asarray(sol.fun, dtype=float)
    step_all = -np.linalg.lstsq(J, r, rcond=1e-10)[0]
    edges = np.cumsum([0] + sizes)
    out = []
    for k in range(len(sizes)):
        keep = np.ones(r.size, dtype=bool)
        keep[edges[k]:edges[k + 1]] = False
        step = -np.linalg.lstsq(J[keep], r[keep], rcond=1e-10)[0]
        x = np.clip(sol.x + step - step_all, lo, hi)
        values = prob.to_values(x)
        out.append({n: values[n] for n in prob.names})
    # jackknife: sqrt((n-1)/n sum (v_k - mean)^2) = sqrt(n-1) times the population standard deviation
    spread = math.sqrt(len(out) - 1) * np.array([[v[n] for n in prob.names] for v in out]).std(axis=0)
    return tuple(out), dict(zip(prob.names, (float(s) for s in spread)))


def start_floors(runs):
    """The start values [SI] of a refined ``coulomb`` and ``viscous`` on ``runs`` whose start is 0: the Coulomb
    level and the viscous force at the runs' RMS moving speed each :data:`START_FLOOR_SHARE` of their RMS drive
    force.

    Both are fitted on a log scale (:data:`LOG_SCALED`), where a start of 0 cannot move."""
    force = np.concatenate([np.asarray(r.force, dtype=float) for r in runs])
    speed = np.concatenate([np.abs(np.diff(r.x_motor)) / r.dt for r in runs])
    moving = speed[speed > 1e-3 * max(float(np.max(speed)), 1e-12)] if speed.size else speed
    f = START_FLOOR_SHARE * float(np.sqrt(np.mean(force ** 2))) if force.size else 0.0
    v = float(np.sqrt(np.mean(moving ** 2))) if moving.size else 0.0
    floors = {"coulomb": f}
    if v > 0:
        floors["viscous"] = f / v
    return {n: x for n, x in floors.items() if x > 0 and math.isfinite(x)}


def _regularization(runs):
    """``tanh`` width of the friction: 1 % of the median moving speed, within [1e-5, 1e-3] m/s."""
    speeds = []
    for r in runs:
        v = np.abs(np.diff(r.x_ref)) / r.dt
        speeds.append(np.median(v[v > 0]) if np.any(v > 0) else 1e-3)
    return float(np.clip(0.01 * np.median(speeds), 1e-5, 1e-3))


def correlation_time(r, limit=0.05, max_lag=2000):
    """Integrated autocorrelation time ``1 + 2 sum rho(k)`` (summed while ``rho > limit``) of a residual."""
    r = np.asarray(r, dtype=float) - np.mean(r)
    n = r.size
    if n < 4 or not np.any(r):
        return 1.0
    f = np.fft.rfft(r, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[: min(n, max_lag)]
    acf = acf / acf[0]
    tau = 1.0
    for k in range(1, acf.size):
        if acf[k] < limit:
            break
        tau += 2.0 * acf[k]
    return float(tau)


def _confidence(sol, prob, values):
    """Std, 95 % half-widths and correlations of the fitted parameters (SI) from the Jacobian."""
    J = sol.jac
    m, p = J.shape
    # residuals of a closed-loop replay are correlated in time: count independent samples as m / tau_int
    inflation = correlation_time(sol.fun)
    s2 = 2.0 * sol.cost / max(m - p, 1)
    # d value / d x: the chain rule of the scaling
    v = np.array([values[n] for n in prob.names])
    dvdx = np.where(prob.log, v, prob.scale)
    warnings = []
    # rank, null space and covariance in the fit's own scaled variables (J), whose columns are of comparable
    # size; in SI a bristle stiffness (1e7 N/m) has a derivative ~1e-9 times a viscous coefficient's, and the
    # normal matrix's condition (~1e30) is beyond any pseudo-inverse tolerance
    # (the thin SVD: the full one builds an m x m factor, 5 GB for a 25 000-sample file; with fewer samples than
    # parameters the full one is small and gives the whole null space)
    _, sv, vt = np.linalg.svd(J, full_matrices=m < p)
    sv = np.concatenate([sv, np.zeros(p - sv.size)])
    null = vt[sv <= sv.max(initial=0.0) * max(m, p) * np.finfo(float).eps]
    rank = p - len(null)
    # the covariance to SI by d value / d x on both sides. The pseudo-inverse of the SI normal matrix cut a LuGre
    # nominal's stiffness direction as if it were null: a half-width of 7e-6 N/m beside a leave-one-run-out spread
    # of 1.6e6 N/m (session 42, a spent benchmark dataset)
    cov = inflation * s2 * np.linalg.pinv(J.T @ J) * np.outer(dvdx, dvdx)
    if rank < p:
        warnings.append(f"the replay error does not depend on {p - rank} combination(s) of "
                        + ", ".join(prob.names) + ": not identifiable from these runs")
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    corr = np.nan_to_num(corr)
    # a parameter in a combination the error does not depend on has no finite interval (the pseudo-inverse
    # would give it the minimum-norm one)
    sd = np.where(np.any(np.abs(null) > 1e-6, axis=0), np.inf, sd) if len(null) else sd
    for i in range(p):
        for j in range(i + 1, p):
            if abs(corr[i, j]) > CORRELATION_LIMIT:
                warnings.append(f"{prob.names[i]} and {prob.names[j]} are not separable by these runs "
                                f"(correlation {corr[i, j]:+.3f})")
    std = dict(zip(prob.names, (float(x) for x in sd)))
    return std, {k: 1.96 * s for k, s in std.items()}, corr, warnings
