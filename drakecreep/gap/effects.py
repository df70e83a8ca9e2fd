"""A library of candidate unmodelled effects for the sim-to-real gap diagnosis.

Each effect is a switchable term beside the nominal rigid model of :mod:`drakecreep.gap.idim`
(``tau = M ddq + Fv dq + Fc sign(dq) + offset``) with its own parameters. An effect provides

* ``columns(sig, ctx, hyper)``: extra regressor columns of the inverse-dynamics (IDIM) model, so that
  ``tau = W theta_nom + C theta_eff`` is linear in the effect's parameters (``hyper`` is the effect's
  nonlinear parameter, searched on a grid given by ``grid(ctx)``);
* ``target(sig, hyper)``: the force the model must explain (only the delay changes it);
* ``replay_term(theta, hyper, ctx, nominal)``: a :class:`Term` for the closed-loop replay of
  :func:`replay_with_effects` (an extra resistive force, a measurement map, a mass change or a delay).

The library (:data:`EFFECTS`): Stribeck friction, asymmetric (viscous) friction, position-dependent
friction, screw lead error (kinematic, periodic in screw angle), motor cogging / force ripple (periodic in
motor angle), backlash / lost motion, an extra structural mode, control delay, encoder quantization,
load-dependent friction and a misscaled known disturbance. ``ctx`` (:class:`EffectContext`) holds the
geometry: screw lead, motor period (position per motor revolution) and the training position range.

The replay integrates the rigid axis exactly per sample (:func:`drakecreep.gap.replay.rigid_step`); effect
forces are evaluated at the start of each sample and held over it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from drakecreep.errors import InputError
from drakecreep.gap.idim import filtered_derivatives
from drakecreep.gap.replay import RigidModel, SampledPPController, rigid_step

__all__ = [
    "EffectContext",
    "IdimData",
    "idim_data",
    "Term",
    "Effect",
    "EFFECTS",
    "EFFECT_NAMES",
    "get_effect",
    "replay_with_effects",
    "synthesize_run",
    "position_grid_step",
]


@dataclass(frozen=True)
class EffectContext:
    """Geometry and scales the effects need.

    Parameters
    ----------
    screw_lead : float
        Table travel per screw revolution [m].
    motor_period : float
        Table travel per motor revolution [m] (equal to the lead for a direct drive).
    x_center, x_half : float
        Centre and half-width of the training position range [m] (position-dependent friction).
    v_max : float
        Largest training speed [m/s] (Stribeck grid).
    dt : float
        Sample time [s].
    encoder_resolution : float
        Position per encoder count [m] from the metadata (0 = unknown).
    """

    screw_lead: float = 2.5e-3
    motor_period: float = 2.5e-3
    x_center: float = 0.0
    x_half: float = 1.0
    v_max: float = 0.1
    dt: float = 1e-3
    encoder_resolution: float = 0.0


@dataclass
class IdimData:
    """Decimated IDIM samples of one or several runs (concatenated), with the raw extras effects need."""

    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    f_ext: np.ndarray
    u: np.ndarray
    dist: np.ndarray  # travel since the last reversal [m]
    tau_shift: dict = field(default_factory=dict)  # delay d -> tau[k-d] (raw samples before decimation)
    run_index: np.ndarray = None
    x_raw: np.ndarray = None  # raw (unfiltered) measured position at the kept samples
    basis: dict = field(default_factory=dict)  # (axis, order) -> {name: array}: periodic terms, filtered

    @property
    def n(self):
        return self.q.size

    def select(self, mask):
        """The samples where ``mask`` is true."""
        return IdimData(q=self.q[mask], dq=self.dq[mask], ddq=self.ddq[mask], tau=self.tau[mask],
                        f_ext=self.f_ext[mask], u=self.u[mask], dist=self.dist[mask],
                        tau_shift={d: a[mask] for d, a in self.tau_shift.items()},
                        run_index=self.run_index[mask], x_raw=self.x_raw[mask],
                        basis={k: {n: a[mask] for n, a in d.items()} for k, d in self.basis.items()})


MAX_DELAY = 3


SCREW_ORDERS = (1, 2, 4)
MOTOR_ORDERS = tuple(range(1, 17))


def idim_data(runs, cutoff=100.0, order=4, decimation=10, border=50, v_min=0.0, filter_force=True,
              screw_lead=None, motor_period=None):
    """IDIM pre-processing (as :func:`drakecreep.gap.idim.idim_signals`) of each run, concatenated.

    Parameters
    ----------
    runs : sequence of drakecreep.gap.measured.MeasuredRun
    cutoff, order, decimation, border
        As in :func:`drakecreep.gap.idim.idim_signals`.
    v_min : float
        Samples with a filtered speed ``|dq| <= v_min`` [m/s] are dropped: at rest the Coulomb force is
        undefined (anywhere in the sticking band), so ``sign(dq)`` of a standing axis is noise.
    filter_force : bool
        Pass the force (and ``f_ext``) through the same zero-phase low-pass as the position, so that both
        sides of the model see the same filter (the EMPS README leaves the force unfiltered; above the
        cut-off an unfiltered force correlates with delayed copies of itself, a false delay signature).
    screw_lead, motor_period : float, optional
        When given, periodic basis terms ``sin/cos(2 pi n x / period)`` of the raw measured position
        go through the same filter (and, for the screw, the same differentiation) as the position, so
        that periodic effects above the cut-off are attenuated exactly as in the data.

    Returns
    -------
    IdimData
    """
    parts = []
    for i, run in enumerate(runs):
        q, dq, ddq = filtered_derivatives(run.x_motor, run.dt, cutoff, order)
        tau = run.force
        f_ext = run.f_ext if run.f_ext is not None else np.zeros(run.n)
        # the force is held over [t_k, t_k+1): centred on t_k (where the central differences sit) it is
        # the mean of the two holds around t_k, else a half-sample lag looks like a control delay
        tau = np.concatenate([tau[:1], 0.5 * (tau[1:] + tau[:-1])])
        f_ext = np.concatenate([f_ext[:1], 0.5 * (f_ext[1:] + f_ext[:-1])])
        if filter_force:
            b, a = signal.butter(order, cutoff / (0.5 / run.dt))
            tau = signal.filtfilt(b, a, tau)
            f_ext = signal.filtfilt(b, a, f_ext)
        # travel since the last reversal of the filtered motion
        s = np.sign(dq)
        dist = np.zeros(run.n)
        last = q[0]
        prev = 0.0
        for k in range(run.n):
            if s[k] != 0 and s[k] != prev:
                last = q[k]
                prev = s[k]
            dist[k] = abs(q[k] - last)
        idx = np.arange(border, run.n - border, decimation)
        if v_min > 0:
            idx = idx[np.abs(dq[idx]) > v_min]
        basis = {}
        xr = np.asarray(run.x_motor, dtype=float)
        if screw_lead:
            for m in SCREW_ORDERS:
                th = 2 * math.pi * m * xr / screw_lead
                for name, sig_ in (("s", np.sin(th)), ("c", np.cos(th))):
                    _, d1, d2 = filtered_derivatives(sig_, run.dt, cutoff, order)
                    basis.setdefault(("screw", m), {})["d" + name] = d1[idx]
                    basis[("screw", m)]["dd" + name] = d2[idx]
        if motor_period:
            b_, a_ = signal.butter(order, cutoff / (0.5 / run.dt))
            for m in MOTOR_ORDERS:
                th = 2 * math.pi * m * xr / motor_period
                basis[("motor", m)] = {"s": signal.filtfilt(b_, a_, np.sin(th))[idx],
                                       "c": signal.filtfilt(b_, a_, np.cos(th))[idx]}
        shift = {d: tau[np.maximum(idx - d, 0)] for d in range(1, MAX_DELAY + 1)}
        parts.append(dict(q=q[idx], dq=dq[idx], ddq=ddq[idx], tau=tau[idx], f_ext=f_ext[idx], u=run.u[idx],
                          dist=dist[idx], tau_shift=shift, run_index=np.full(idx.size, i),
                          x_raw=run.x_motor[idx], basis=basis))
    if not parts:
        raise InputError("runs", 0, "at least one run")
    cat = {k: np.concatenate([p[k] for p in parts]) for k in parts[0] if k not in ("tau_shift", "basis")}
    cat["basis"] = {key: {n: np.concatenate([p["basis"][key][n] for p in parts]) for n in parts[0]["basis"][key]}
                    for key in parts[0]["basis"]}
    cat["tau_shift"] = {d: np.concatenate([p["tau_shift"][d] for p in parts]) for d in range(1, MAX_DELAY + 1)}
    return IdimData(**cat)


# --------------------------------------------------------------------------- replay terms

@dataclass
class Term:
    """One effect inside the closed-loop replay.

    ``force(x, v, a)``: extra resistive force [N] (the model force ``tau`` gains it);
    ``measure(x)``: the measured position given the true one; ``mass(x, v, dist)``: extra mass [kg];
    ``delay``: samples between the controller output and the applied force;
    ``step(x, v, h)``: advance an internal state (structural mode).
    """

    force: object = None
    measure: object = None
    mass: object = None
    delay: int = 0
    step: object = None
    reset: object = None
    series: object = None  # series(run) -> extra resistive force per sample [N]


def position_grid_step(x, candidates=None):
    """Largest step ``q`` among ``candidates`` such that every ``x`` lies on a grid of ``q`` (0 if none).

    Parameters
    ----------
    x : array_like
        Positions [m].
    candidates : sequence of float, optional
        Default: 1, 2, 5 x 10^k m from 1 nm to 10 um.
    """
    x = np.asarray(x, dtype=float)
    if candidates is None:
        candidates = [m * 10.0 ** e for e in range(-9, -4) for m in (1, 2, 5)]
    best = 0.0
    for q in sorted(candidates):
        frac = x / q - np.round(x / q)
        if np.max(np.abs(frac)) < 1e-3:
            best = q
    return best


def replay_with_effects(run, model, terms=(), initial_velocity=None):
    """Closed-loop replay of a rigid model plus effect terms (see :func:`drakecreep.gap.replay.replay`).

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
    model : drakecreep.gap.replay.RigidModel
        The nominal plant.
    terms : sequence of Term
        Active effects.
    initial_velocity : float, optional
        Default: first difference of the measured position.

    Returns
    -------
    dict
        ``x`` (measured position of the simulated axis), ``v`` (true simulated velocity), ``u``
        (controller output), ``force`` (``u_gain*u_applied + f_ext``) on ``run.t``.
    """
    ctrl = run.meta.controller
    if ctrl is None or ctrl.kind != "p_p_cascade":
        raise InputError("controller", None if ctrl is None else ctrl.kind, "a p_p_cascade controller")
    h = run.dt
    n = run.n
    delay = sum(int(t.delay) for t in terms)
    forces = [t.force for t in terms if t.force is not None]
    measures = [t.measure for t in terms if t.measure is not None]
    masses = [t.mass for t in terms if t.mass is not None]
    steps = [t.step for t in terms if t.step is not None]
    series = np.zeros(n)
    for t in terms:
        if t.series is not None:
            series = series + np.asarray(t.series(run), dtype=float)
    for t in terms:
        if t.reset is not None:
            t.reset()
    x_ref = run.x_ref
    f_ext = run.f_ext if run.f_ext is not None else np.zeros(n)
    gain = run.u_gain
    x = float(run.x_motor[0])
    for m in measures:  # start from the true position whose measurement is the first sample
        x = x - (m(x) - x)
    v = float(run.x_motor[1] - run.x_motor[0]) / h if initial_velocity is None else float(initial_velocity)

    def meas(xt):
        y = xt
        for m in measures:
            y = m(y) if m is not None else y
        return y

    controller = SampledPPController(ctrl, h, meas(x), v, run.u[:delay])
    xs, vs, us = np.empty(n), np.empty(n), np.empty(n)
    ua = np.empty(n)
    models = {}
    last_sign, last_x = 0.0, x
    a_prev = 0.0
    for k in range(n):
        q = meas(x)
        u, applied = controller.step(x_ref[k], q)
        force = gain * applied + f_ext[k]
        dm = 0.0
        if masses:
            if v != 0 and math.copysign(1.0, v) != last_sign:
                last_sign, last_x = math.copysign(1.0, v), x
            for m in masses:
                dm += m(x, v, abs(x - last_x))
        extra = series[k]
        for f in forces:
            extra += f(x, v, a_prev)
        key = round(dm, 9)
        mdl = models.get(key)
        if mdl is None:
            mdl = RigidModel(M=max(model.M + dm, 1e-3 * model.M), Fv=model.Fv, Fc=model.Fc, offset=model.offset)
            models[key] = mdl
        xs[k], vs[k], us[k], ua[k] = q, v, u, applied
        v_old = v
        x, v = rigid_step(mdl, x, v, force - extra, h)
        a_prev = (v - v_old) / h
        for s in steps:
            s(x, v, h)
    return {"x": xs, "v": vs, "u": us, "force": gain * ua + f_ext}


def synthesize_run(t, x_ref, meta, model, terms=(), f_ext=None, force_noise=None, label="synthetic"):
    """A "measured" run made by :func:`replay_with_effects` from a reference (tests and examples).

    Parameters
    ----------
    t, x_ref : array_like
        Time [s] and reference [m].
    meta : drakecreep.gap.measured.MeasuredMeta
        Metadata with a ``p_p_cascade`` controller.
    model : drakecreep.gap.replay.RigidModel
    terms : sequence of Term
    f_ext : array_like, optional
        Known external force [N].
    force_noise : array_like, optional
        Unknown force noise [N] added to the plant (not to the recorded ``u``).
    label : str

    Returns
    -------
    drakecreep.gap.measured.MeasuredRun
    """
    from drakecreep.gap.measured import MeasuredRun

    t = np.asarray(t, dtype=float)
    x_ref = np.asarray(x_ref, dtype=float)
    base = MeasuredRun(t=t, x_ref=x_ref, x_motor=np.full(t.size, x_ref[0]), u=np.zeros(t.size), meta=meta,
                       f_ext=f_ext, label=label)
    terms = list(terms)
    if force_noise is not None:
        noise = np.asarray(force_noise, dtype=float)
        terms.append(Term(series=lambda run: noise))
    sim = replay_with_effects(base, model, terms, initial_velocity=0.0)
    return MeasuredRun(t=t, x_ref=x_ref, x_motor=sim["x"], u=sim["u"], meta=meta, f_ext=f_ext, label=label)


# --------------------------------------------------------------------------- effects

def _sgn(v):
    return math.copysign(1.0, v) if v != 0 else 0.0


@dataclass(frozen=True)
class Effect:
    """A candidate effect: name, description, parameter names, signature (where it shows)."""

    name: str
    description: str
    params: tuple
    signature: str
    kind: str = "force"  # force | kinematic | timing | measurement

    def grid(self, ctx):
        """Values of the nonlinear parameter (``[None]`` when the effect is linear)."""
        return [None]

    def hyper_name(self):
        return None

    def applicable(self, data):
        return True

    def columns(self, sig, ctx, hyper, nominal):
        raise NotImplementedError

    def target(self, sig, hyper):
        return sig.tau

    def replay_term(self, theta, hyper, ctx, nominal):
        raise NotImplementedError

    def physical(self, theta, hyper, ctx, nominal):
        """Whether fitted parameters describe the effect physically (else it cannot be claimed)."""
        return True

    @property
    def n_params(self):
        return len(self.params) + (0 if self.hyper_name() is None else 1)


class Stribeck(Effect):
    def grid(self, ctx):
        return list(ctx.v_max * np.geomspace(0.01, 0.3, 9))

    def hyper_name(self):
        return "vs_m_s"

    def columns(self, sig, ctx, hyper, nominal):
        return (np.sign(sig.dq) * np.exp(-(sig.dq / hyper) ** 2))[:, None]

    def replay_term(self, theta, hyper, ctx, nominal):
        a = float(theta[0])
        return Term(force=lambda x, v, acc: a * _sgn(v) * math.exp(-(v / hyper) ** 2))

    def physical(self, theta, hyper, ctx, nominal):
        return float(theta[0]) > 0  # static friction above the Coulomb level


class Asymmetric(Effect):
    def columns(self, sig, ctx, hyper, nominal):
        pos = sig.dq > 0
        return np.column_stack([sig.dq * pos])

    def replay_term(self, theta, hyper, ctx, nominal):
        d = float(theta[0])
        return Term(force=lambda x, v, acc: d * v if v > 0 else 0.0)


class PositionFriction(Effect):
    """Coulomb friction varying along the travel: piecewise linear between 4 knots over the training range
    (held constant outside it), ``sign(v) * sum_j c_j hat_j(x)`` (the first hat is the nominal level)."""

    KNOTS = 4

    @staticmethod
    def _hats(x, ctx):
        knots = np.linspace(ctx.x_center - ctx.x_half, ctx.x_center + ctx.x_half, PositionFriction.KNOTS)
        xc = np.clip(x, knots[0], knots[-1])
        eye = np.eye(knots.size)
        return np.column_stack([np.interp(xc, knots, eye[j]) for j in range(1, knots.size)])

    def columns(self, sig, ctx, hyper, nominal):
        return np.sign(sig.dq)[:, None] * self._hats(sig.q, ctx)

    def replay_term(self, theta, hyper, ctx, nominal):
        c = np.asarray(theta, dtype=float)

        def f(x, v, acc):
            return _sgn(v) * float(self._hats(np.array([x]), ctx)[0] @ c)

        return Term(force=f)


class LeadError(Effect):
    """Kinematic: measured = true + sum over orders (n, 2n) of e_s sin(2 pi m x/lead) + e_c cos(...)."""

    def grid(self, ctx):
        return [1, 2]

    def hyper_name(self):
        return "order_per_screw_rev"

    def columns(self, sig, ctx, hyper, nominal):
        M, Fv = nominal["M"], nominal["Fv"]
        cols = []
        for m in (hyper, 2 * hyper):
            b = sig.basis.get(("screw", m))
            if b is not None:
                cols += [-(M * b["dds"] + Fv * b["ds"]), -(M * b["ddc"] + Fv * b["dc"])]
                continue
            w = 2 * math.pi * m / ctx.screw_lead
            th = w * sig.q
            s, c = np.sin(th), np.cos(th)
            ds, dc = w * c * sig.dq, -w * s * sig.dq
            dds = w * c * sig.ddq - w * w * s * sig.dq ** 2
            ddc = -w * s * sig.ddq - w * w * c * sig.dq ** 2
            cols += [-(M * dds + Fv * ds), -(M * ddc + Fv * dc)]
        return np.column_stack(cols)

    def replay_term(self, theta, hyper, ctx, nominal):
        es, ec, es2, ec2 = map(float, theta)
        w = 2 * math.pi * hyper / ctx.screw_lead
        return Term(measure=lambda x: (x + es * math.sin(w * x) + ec * math.cos(w * x)
                                       + es2 * math.sin(2 * w * x) + ec2 * math.cos(2 * w * x)))


class Cogging(Effect):
    """Force ripple at a motor order ``n`` and its second harmonic ``2n``."""

    def grid(self, ctx):
        return list(range(1, 9))

    def hyper_name(self):
        return "order_per_motor_rev"

    def columns(self, sig, ctx, hyper, nominal):
        b1, b2 = sig.basis.get(("motor", hyper)), sig.basis.get(("motor", 2 * hyper))
        if b1 is not None and b2 is not None:
            return np.column_stack([b1["s"], b1["c"], b2["s"], b2["c"]])
        th = 2 * math.pi * hyper * sig.q / ctx.motor_period
        return np.column_stack([np.sin(th), np.cos(th), np.sin(2 * th), np.cos(2 * th)])

    def replay_term(self, theta, hyper, ctx, nominal):
        a, b, a2, b2 = map(float, theta)
        w = 2 * math.pi * hyper / ctx.motor_period
        return Term(force=lambda x, v, acc: (a * math.sin(w * x) + b * math.cos(w * x)
                                             + a2 * math.sin(2 * w * x) + b2 * math.cos(2 * w * x)))


class Backlash(Effect):
    """Lost motion: after a reversal, over a travel ``b`` the load does not follow: the drive misses its
    inertia (``dM < 0``) and its friction (``dF < 0``)."""

    def grid(self, ctx):
        return list(np.geomspace(2e-6, 2e-4, 9))

    def hyper_name(self):
        return "lost_motion_m"

    def columns(self, sig, ctx, hyper, nominal):
        w = sig.dist < hyper
        return np.column_stack([sig.ddq * w, np.sign(sig.dq) * w])

    def replay_term(self, theta, hyper, ctx, nominal):
        dm, df = float(theta[0]), float(theta[1])
        st = {"in": False}

        def mass(x, v, dist):
            st["in"] = dist < hyper
            return dm if st["in"] else 0.0

        return Term(mass=mass, force=lambda x, v, acc: df * _sgn(v) if st["in"] else 0.0)

    def physical(self, theta, hyper, ctx, nominal):
        return -0.95 * nominal["M"] < float(theta[0]) < 0  # part of the mass does not follow


class StructuralMode(Effect):
    """A body of mass ``m2`` on a spring (natural frequency ``fn``, 5 % damping): force ``m2 (ddx2 - ddx)``."""

    ZETA = 0.05

    def grid(self, ctx):
        return [5.0, 8.0, 12.0, 18.0, 27.0, 40.0, 60.0]

    def hyper_name(self):
        return "fn_Hz"

    def columns(self, sig, ctx, hyper, nominal):
        cols = []
        dt_dec = None
        # the decimated samples are uniform within each run: filter run by run
        for i in np.unique(sig.run_index):
            m = sig.run_index == i
            dd = sig.ddq[m]
            if dt_dec is None:
                dt_dec = ctx.dt * 10
            w = 2 * math.pi * hyper
            b, a = signal.bilinear([2 * self.ZETA * w, w * w], [1, 2 * self.ZETA * w, w * w], fs=1.0 / dt_dec)
            zi = signal.lfilter_zi(b, a) * dd[0]
            y, _ = signal.lfilter(b, a, dd, zi=zi)
            cols.append(y - dd)
        return np.concatenate(cols)[:, None]

    def replay_term(self, theta, hyper, ctx, nominal):
        m2 = float(theta[0])
        w = 2 * math.pi * hyper
        z = self.ZETA
        st = {"x2": None, "v2": 0.0, "a2": 0.0}

        def reset():
            st["x2"], st["v2"], st["a2"] = None, 0.0, 0.0

        def step(x, v, h):
            if st["x2"] is None:
                st["x2"], st["v2"] = x, v
            sub = 10
            hh = h / sub
            for _ in range(sub):  # semi-implicit Euler on the secondary, driven by the main body
                a2 = w * w * (x - st["x2"]) + 2 * z * w * (v - st["v2"])
                st["v2"] += hh * a2
                st["x2"] += hh * st["v2"]
            st["a2"] = a2

        def force(x, v, acc):
            if st["x2"] is None:
                return 0.0
            return m2 * (st["a2"] - acc)

        return Term(force=force, step=step, reset=reset)

    def physical(self, theta, hyper, ctx, nominal):
        return 0 < float(theta[0]) < nominal["M"]


class Delay(Effect):
    def grid(self, ctx):
        return [1, 2, 3]

    def hyper_name(self):
        return "delay_samples"

    @property
    def n_params(self):
        return 1

    def columns(self, sig, ctx, hyper, nominal):
        return np.zeros((sig.n, 0))

    def target(self, sig, hyper):
        return sig.tau_shift[hyper]

    def replay_term(self, theta, hyper, ctx, nominal):
        return Term(delay=int(hyper))


class Quantization(Effect):
    """Encoder quantization: the controller reads the position rounded to a grid ``q`` (read from the data)."""

    @property
    def n_params(self):
        return 1

    def columns(self, sig, ctx, hyper, nominal):
        return np.zeros((sig.n, 0))

    def grid(self, ctx):
        return [None]

    def replay_term(self, theta, hyper, ctx, nominal):
        q = float(hyper) if hyper else 0.0
        return Term(measure=(lambda x: round(x / q) * q) if q > 0 else None)


class LoadFriction(Effect):
    """Coulomb friction growing with the transmitted inertial load: ``mu * sign(v) * |M ddq|``."""

    def columns(self, sig, ctx, hyper, nominal):
        return (np.sign(sig.dq) * np.abs(nominal["M"] * sig.ddq))[:, None]

    def replay_term(self, theta, hyper, ctx, nominal):
        mu = float(theta[0])
        M = nominal["M"]
        return Term(force=lambda x, v, acc: mu * _sgn(v) * abs(M * acc))

    def physical(self, theta, hyper, ctx, nominal):
        return float(theta[0]) > 0


class DisturbanceScale(Effect):
    """The known disturbance acts as ``(1 + s) f_ext``."""

    def applicable(self, data):
        return bool(np.any(data.f_ext != 0))

    def columns(self, sig, ctx, hyper, nominal):
        return (-sig.f_ext)[:, None]

    def replay_term(self, theta, hyper, ctx, nominal):
        s = float(theta[0])
        return Term(series=lambda run: -s * (run.f_ext if run.f_ext is not None else np.zeros(run.n)))


EFFECTS = (
    Stribeck("stribeck", "Stribeck friction drop at low speed (sign(v) exp(-(v/vs)^2))", ("dFs_N",),
             "force at low speed, both directions", "force"),
    Asymmetric("asymmetric_friction", "viscous friction differs by direction (Coulomb asymmetry is the offset)",
               ("dFv_pos_N_s_m",), "force proportional to speed, one direction", "force"),
    PositionFriction("position_friction", "Coulomb friction varying along the travel (piecewise linear)",
                     ("dFc_knot1_N", "dFc_knot2_N", "dFc_knot3_N"), "force binned by position", "force"),
    LeadError("lead_error", "screw lead error: measured position = true + periodic error in screw angle",
              ("e_sin_m", "e_cos_m", "e2_sin_m", "e2_cos_m"), "speed/position residual at a screw order, grows with speed", "kinematic"),
    Cogging("cogging", "motor cogging / force ripple periodic in motor angle", ("a_sin_N", "a_cos_N", "a2_sin_N", "a2_cos_N"),
            "force at a motor order, independent of speed", "force"),
    Backlash("backlash", "lost motion after a reversal: the load does not follow over a travel b",
             ("dM_kg", "dF_N"),
             "force right after reversals", "force"),
    StructuralMode("structural_mode", "extra structural mode (a body m2 on a spring)", ("m2_kg",),
                   "force in acceleration phases, at the mode frequency", "force"),
    Delay("control_delay", "the drive force lags the recorded command by k samples", (),
          "force around acceleration changes", "timing"),
    Quantization("quantization", "encoder quantization in the controller feedback (grid from the data)", (),
                 "speed residual at low speed (limit cycle)", "measurement"),
    LoadFriction("load_friction", "friction growing with the transmitted load |M ddq|", ("mu",),
                 "force in acceleration phases, sign of speed", "force"),
    DisturbanceScale("disturbance_scale", "the known external disturbance is misscaled", ("scale_error",),
                     "force where the disturbance acts", "force"),
)
EFFECT_NAMES = tuple(e.name for e in EFFECTS)


def get_effect(name):
    """The effect called ``name`` (see :data:`EFFECT_NAMES`)."""
    for e in EFFECTS:
        if e.name == name:
            return e
    raise InputError("effect", name, "one of " + ", ".join(EFFECT_NAMES))
