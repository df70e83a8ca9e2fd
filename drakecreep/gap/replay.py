"""Closed-loop replay of a rigid axis under the measured run's sampled controller: the exact reference stepper.

Not the diagnosis model (that is the Drake replay, :mod:`drakecreep.gap.drake_replay`): this stepper
replays the published EMPS IDIM model for its reference errors (:mod:`drakecreep.gap.emps`) and is the
independent cross-check of the Drake replay (``tests/gap/test_drake_replay.py``) and of the benchmark's
truth simulator (``tests/gap/test_truth.py``). The former rigid diagnosis built on it was retired.

Plant (the IDIM model, :mod:`drakecreep.gap.idim`)::

    M * dv/dt = F - Fv*v - Fc*sign(v) - offset,      dx/dt = v,      F = u_gain*u + f_ext

Controller (:class:`drakecreep.gap.measured.ControllerMeta`, ``p_p_cascade``): at each sample ``k`` it
reads the simulated position, forms ``u[k]`` from the measured reference and holds it until ``k+1``.

Integration is exact, not numerical: over a sample the force is constant, so between velocity sign
changes the motion is a first-order exponential (``Fv > 0``) or a parabola (``Fv = 0``). The step
finds the instant where ``v`` reaches 0, and there applies the stick rule of Coulomb friction with
static level ``Fc``: the axis stays at rest while ``|F - offset| <= Fc`` and otherwise leaves in the
direction of ``F - offset``. No regularized ``sign`` is involved, so there is no smoothing width to
choose and no stiff step near zero speed; ``tests/gap/test_replay.py`` checks the stepper against
:func:`scipy.integrate.solve_ivp` with a narrow ``tanh`` sign.

Errors are ``100 * ||y - y_sim|| / ||y||`` over all samples (:func:`replay_errors`). Measured
velocity and acceleration do not exist as signals: both measured and simulated positions go through
the same IDIM processing (Butterworth 100 Hz forward-backward, central differences, no decimation),
``derivatives="filtered"``. ``derivatives="model"`` instead compares the filtered measured derivatives
with the simulator's own state velocity and its acceleration at the start of each sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drakecreep.errors import InputError
from drakecreep.gap.idim import PARAMETER_NAMES, IdimResult, filtered_derivatives, relative_error

__all__ = [
    "PUBLISHED_REPLAY_ERRORS",
    "SIGNALS",
    "RigidModel",
    "ReplayResult",
    "rigid_step",
    "SampledPPController",
    "replay",
    "replay_errors",
]

SIGNALS = ("position", "velocity", "acceleration", "force")
#: Published closed-loop errors [%] of the IDIM-LS rigid model (data folder README).
PUBLISHED_REPLAY_ERRORS = {
    "estimation": {"position": 0.0138, "velocity": 0.229, "acceleration": 8.60, "force": 5.85},
    "validation": {"position": 0.0080, "velocity": 0.479, "acceleration": 19.8, "force": 8.94},
}


@dataclass(frozen=True)
class RigidModel:
    """Rigid axis with viscous and Coulomb friction and a constant offset force.

    Parameters
    ----------
    M : float
        Moving mass [kg], > 0.
    Fv : float
        Viscous coefficient [N s/m], >= 0.
    Fc : float
        Coulomb (and static) friction [N], >= 0.
    offset : float
        Constant force [N] on the force side of the model (``tau = ... + offset``).
    """

    M: float
    Fv: float
    Fc: float
    offset: float = 0.0

    def __post_init__(self):
        for name, lo, strict in (("M", 0.0, True), ("Fv", 0.0, False), ("Fc", 0.0, False), ("offset", None, False)):
            value = getattr(self, name)
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise InputError(name, value, "a finite number") from None
            if not math.isfinite(x) or (lo is not None and (x < lo or (strict and x == lo))):
                raise InputError(name, value, "a finite number" + ("" if lo is None else (" > 0" if strict else " >= 0")))
            object.__setattr__(self, name, x)

    @classmethod
    def from_idim(cls, result):
        """From an :class:`~drakecreep.gap.idim.IdimResult` or a mapping with ``M, Fv, Fc, offset``."""
        params = result.params if isinstance(result, IdimResult) else result
        return cls(**{k: params[k] for k in PARAMETER_NAMES})

    def acceleration(self, v, force):
        """``(F - Fv v - Fc sign(v) - offset) / M`` (at ``v = 0``: 0 when stuck, else the breakaway value)."""
        v = np.asarray(v, dtype=float)
        net = np.asarray(force, dtype=float) - self.offset
        moving = v != 0
        fric = np.where(moving, self.Fc * np.sign(v), np.clip(net, -self.Fc, self.Fc))
        return (net - self.Fv * v - fric) / self.M


def rigid_step(model, x, v, force, h):
    """Advance the rigid axis exactly over ``h`` seconds under a constant ``force``.

    Parameters
    ----------
    model : RigidModel
    x, v : float
        Position [m] and velocity [m/s] at the start.
    force : float
        Drive plus external force [N], constant over the step.
    h : float
        Step [s], >= 0.

    Returns
    -------
    tuple of float
        ``(x, v)`` after ``h``.
    """
    M, Fv, Fc = model.M, model.Fv, model.Fc
    F = force - model.offset
    left = h
    for _ in range(4):  # at most: move -> reach 0 -> stick or leave -> (no second reversal in one leg)
        if left <= 0.0:
            break
        if v == 0.0:
            if abs(F) <= Fc:
                return x, 0.0
            s = 1.0 if F > 0 else -1.0
        else:
            s = 1.0 if v > 0 else -1.0
        net = F - s * Fc  # constant part of the force on this leg
        if Fv > 0.0:
            tau = M / Fv
            v_inf = net / Fv
            t_zero = math.inf
            if s * v_inf < 0.0 and v != 0.0:  # decaying towards the other side: crosses 0
                t_zero = tau * math.log((v - v_inf) / (-v_inf))
            t = min(left, t_zero)
            e = -math.expm1(-t / tau)  # 1 - exp(-t/tau)
            x = x + v_inf * t + (v - v_inf) * tau * e
            v = 0.0 if t == t_zero else v_inf + (v - v_inf) * (1.0 - e)
        else:
            a = net / M
            t_zero = -v / a if (s * a < 0.0 and v != 0.0) else math.inf
            t = min(left, t_zero)
            x = x + v * t + 0.5 * a * t * t
            v = 0.0 if t == t_zero else v + a * t
        left -= t
    return x, v


@dataclass(frozen=True)
class ReplayResult:
    """Simulated samples beside the measured run (all arrays on ``run.t``).

    ``x_sim``, ``v_sim``: states at the sample instants; ``a_sim``: model acceleration right after each
    sample (with ``u_sim[k]`` applied); ``u_sim``: the simulated controller output [unit of u];
    ``force_sim = u_gain*u_sim + f_ext`` [N].
    """

    run: object
    model: RigidModel
    x_sim: np.ndarray
    v_sim: np.ndarray
    a_sim: np.ndarray
    u_sim: np.ndarray
    force_sim: np.ndarray
    delay: int = 0

    @property
    def t(self):
        """Sample times [s]."""
        return self.run.t

    @property
    def saturated_fraction(self):
        """Share of samples where the simulated controller output is at its limit."""
        sat = self.run.meta.controller.saturation
        return float(np.mean(np.abs(self.u_sim) >= sat)) if math.isfinite(sat) else 0.0


class SampledPPController:
    """The documented EMPS cascade, one sample at a time.

    ``u = kp kv (x_ref - q) - kv dq``, with ``dq`` the first difference of the position filtered by
    ``position_filter`` taps, saturated, and applied after ``delay`` samples (the queue starts with
    the recorded outputs). Used by :func:`replay`.

    Parameters
    ----------
    ctrl : controller metadata (``kp``, ``kv``, ``saturation``, ``position_filter``)
    h : float
        Sample time (s).
    q0, v0 : float
        Measured position (m) and speed (m/s) at the first sample; the filter's memory starts on the
        line through them.
    history : sequence of float
        Recorded outputs that fill the delay queue (its length is the delay in samples).
    """

    def __init__(self, ctrl, h, q0, v0, history=()):
        self.kp, self.kv, self.saturation = ctrl.kp, ctrl.kv, ctrl.saturation
        self.taps = ctrl.position_filter
        self.h = h
        # past measured positions (newest first) and the previous filtered position
        self.past = [q0 - (i + 1) * v0 * h for i in range(len(self.taps))]
        self.qf_prev = sum(c * p for c, p in zip(self.taps, self.past))
        self.queue = [float(u) for u in history]

    def step(self, x_ref, q):
        """Controller output for reference ``x_ref`` and measured position ``q``: ``(u, u_applied)``."""
        hist = [q] + self.past[: len(self.taps) - 1]
        qf = sum(c * p for c, p in zip(self.taps, hist))
        dq = (qf - self.qf_prev) / self.h
        u = self.kp * self.kv * (x_ref - q) - self.kv * dq
        u = min(max(u, -self.saturation), self.saturation)
        self.queue.append(u)
        applied = self.queue.pop(0)
        self.past = [q] + self.past[:-1]
        self.qf_prev = qf
        return u, applied


def replay(run, model, controller=None, quantize=False, initial_velocity=None, delay=0):
    """Replay a measured run in closed loop with a rigid model.

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
        Provides ``x_ref`` (the reference), ``f_ext``, the controller metadata, ``u_gain`` and the
        initial position ``x_motor[0]``.
    model : RigidModel or IdimResult or mapping
        The plant.
    controller : drakecreep.gap.measured.ControllerMeta, optional
        Default: ``run.meta.controller`` (must be ``p_p_cascade`` on the motor encoder).
    quantize : bool
        Round the fed-back position to ``run.meta.sensors.encoder_resolution`` (when > 0).
    initial_velocity : float, optional
        ``v(t0)`` [m/s]; default: the first difference of the measured motor position. The filter
        memory of the controller is filled as if the axis had moved at this speed before ``t0``.
    delay : int
        Computational delay in samples: ``u[k]`` acts on ``[t[k+delay], t[k+delay+1])``; the first
        ``delay`` samples apply the measured ``u``. 0 is the documented EMPS loop (the recorded ``vir``
        follows the law from the same-sample ``qm`` to 0.004 V rms).

    Returns
    -------
    ReplayResult
    """
    if not isinstance(model, RigidModel):
        model = RigidModel.from_idim(model)
    ctrl = controller if controller is not None else run.meta.controller
    if ctrl is None or ctrl.kind != "p_p_cascade" or ctrl.feedback != "motor":
        raise InputError("controller", None if ctrl is None else ctrl.kind,
                         "a p_p_cascade controller on the motor encoder in the run metadata")
    h = run.dt
    if abs(ctrl.sample_time - h) > 1e-6 * h:
        raise InputError("controller.sample_time", ctrl.sample_time, f"the run's sample time {h:g} s")
    if int(delay) != delay or delay < 0:
        raise InputError("delay", delay, "an integer >= 0 (samples)")
    delay = int(delay)
    res = run.meta.sensors.encoder_resolution if quantize else 0.0
    n = run.n
    x_ref = run.x_ref
    f_ext = run.f_ext if run.f_ext is not None else np.zeros(n)
    gain = run.u_gain
    x = float(run.x_motor[0])
    v = float(run.x_motor[1] - run.x_motor[0]) / h if initial_velocity is None else float(initial_velocity)
    controller = SampledPPController(ctrl, h, x, v, run.u[:delay])
    xs, vs, acc, us, ua = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for k in range(n):
        q = round(x / res) * res if res > 0 else x
        u, applied = controller.step(x_ref[k], q)
        force = gain * applied + f_ext[k]
        xs[k], vs[k], us[k], ua[k] = x, v, u, applied
        acc[k] = model.acceleration(v, force)
        x, v = rigid_step(model, x, v, force, h)
    return ReplayResult(run=run, model=model, x_sim=xs, v_sim=vs, a_sim=acc, u_sim=us,
                        force_sim=gain * ua + f_ext, delay=delay)


def replay_errors(result, derivatives="filtered", cutoff=None, order=4):
    """Relative errors [%] of position, velocity, acceleration and force of a replay.

    Parameters
    ----------
    result : ReplayResult
    derivatives : str
        ``"filtered"``: velocity and acceleration of measured and simulated positions by the same
        Butterworth + central-difference processing; ``"model"``: simulated state velocity and model
        acceleration against the filtered measured ones.
    cutoff, order : float, int
        The Butterworth low-pass (as IDIM).

    Returns
    -------
    dict
        ``{"position": ..., "velocity": ..., "acceleration": ..., "force": ...}`` in %.
    """
    if derivatives not in ("filtered", "model"):
        raise InputError("derivatives", derivatives, "one of filtered, model")
    run = result.run
    _, dq, ddq = filtered_derivatives(run.x_motor, run.dt, cutoff, order)
    if derivatives == "filtered":
        _, dq_sim, ddq_sim = filtered_derivatives(result.x_sim, run.dt, cutoff, order)
    else:
        dq_sim, ddq_sim = result.v_sim, result.a_sim
    return {
        "position": relative_error(run.x_motor, result.x_sim),
        "velocity": relative_error(dq, dq_sim),
        "acceleration": relative_error(ddq, ddq_sim),
        "force": relative_error(run.force, result.force_sim),
    }
