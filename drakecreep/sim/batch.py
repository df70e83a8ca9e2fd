"""Many feed-drive cases in one Drake system: the throughput path for sweeps.

A sweep of hundreds of short runs spends most of its time in Drake's per-step machinery: every case
has the same 4 kHz controller samples and log samples, and each is an event that ends an integrator step.
:class:`BatchedFeedDrive` puts N cases in one ``LeafSystem`` whose state is the N cases' states side by
side, so one step, one event and one Python call serve all N; the right-hand side is the equations of
:mod:`drakecreep.sim.baseline` vectorized with numpy over the cases.

Those are the same equations as the Drake ``TemplateSystem``s, written once more in plain Python
(``tests/test_baseline.py`` checks them against the leaf systems and ``tests/test_batch.py`` checks this
path case by case against :func:`drakecreep.sim.simulation.simulate`). It is float-only (no AutoDiff or
symbolic form: use the leaf systems for linearization) and needs every case of a batch to share the
model's structure: friction law, sampled controller and its periods, current-loop lag on or off, screw
mounting, position feedback, duration and logging; :func:`batch_key` says which cases can share a batch.
The error control is shared, so a batch steps as finely as its most demanding case needs.
"""

import time

import numpy as np
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import VectorLogSink

from drakecreep.model.screw import bearing_element, nut_element
from drakecreep.model.nut_friction import nut_friction_levels
from drakecreep.sim.baseline import BaselineModel
from drakecreep.errors import InputError
from drakecreep.sim.metrics import feed_metrics
from drakecreep.sim.simulation import check_log_period, check_step_budget, make_simulator, target_accuracy

__all__ = ["BatchedFeedDrive", "batch_key", "simulate_batch"]


def batch_key(params, scenario):
    """Cases with equal keys can be simulated in one batch."""
    p = params
    return (
        p.friction.law, p.controller.sampled, p.controller.velocity_period, p.controller.position_divider,
        p.controller.position_feedback, p.controller.anti_windup, p.motor.current_loop_time_constant > 0,
        p.screw.mounting, p.sensors.encoder_counts_per_rev == 0, p.sensors.scale_resolution == 0,
        scenario.duration, p.simulation.log_period, p.simulation.steady_start, p.simulation.stick_threshold,
        p.simulation.integrator, target_accuracy(p), p.simulation.max_step, p.controller.computation_delay,
        getattr(scenario, "drive", "cascade"),
        nut_friction_levels(p, p.load_case(scenario.load_case))[0] > 0,  # nut friction on the screw: one more law
    )


class _Columns:
    """Per-case constants of :class:`~drakecreep.sim.baseline.BaselineModel` as arrays over the cases."""

    def __init__(self, models):
        self.models = models
        first = models[0]

        def col(fn):
            return np.array([fn(m) for m in models], dtype=float)

        p = [m.p for m in models]
        self.n = len(models)
        self.lag = first.lag > 0
        self.nz = first.nz
        self.law = first.p.friction.law
        self.mounting = first.p.screw.mounting
        self.table_feedback = first.p.controller.position_feedback == "table"
        g0 = first.p.controller
        self.period, self.divider = g0.velocity_period, g0.position_divider
        self.n_delay = first.n_delay  # whole samples (baseline.unsupported), equal in a batch (batch_key)
        self.nd = 5 + self.n_delay
        self.ratio = col(lambda m: m.ratio)
        self.ea = col(lambda m: m.ea)
        self.inertia = col(lambda m: m.inertia)
        self.mass = col(lambda m: m.mass)
        self.fc, self.fs, self.fx = col(lambda m: m.fc), col(lambda m: m.fs), col(lambda m: m.fx)
        self.nut = first.fc_nut > 0  # the nut's friction on the screw (batch_key: all cases or none)
        self.fc_nut, self.fs_nut = col(lambda m: m.fc_nut), col(lambda m: m.fs_nut)
        self.limit, self.tracking = col(lambda m: m.limit), col(lambda m: m.tracking)
        self.enc = col(lambda m: m.enc)
        self.tc = col(lambda m: m.lag if m.lag > 0 else 1.0)
        self.peak = np.array([q.motor.peak_torque for q in p])
        self.bm = np.array([q.motor.viscous_damping for q in p])
        self.kb, self.cb = np.array([bearing_element(q.screw) for q in p]).T
        self.kn, self.cn = np.array([nut_element(q.screw, q.nut) for q in p]).T
        self.a0 = np.array([q.screw.nut_start_distance for q in p])
        self.length = np.array([q.screw.length for q in p])
        self.vs = np.array([q.friction.stribeck_velocity for q in p])
        self.delta = np.array([q.friction.stribeck_exponent for q in p])
        self.fv = np.array([q.friction.viscous for q in p])
        self.s0 = np.array([q.friction.bristle_stiffness for q in p])
        self.s1 = np.array([q.friction.bristle_damping for q in p])
        self.vreg = np.array([q.friction.regularization_velocity for q in p])
        self.kp = np.array([q.controller.position_gain for q in p])
        self.kff = np.array([q.controller.velocity_feedforward for q in p])
        self.kv = np.array([q.controller.velocity_gain for q in p])
        self.ki = np.array([q.controller.velocity_integral_gain for q in p])
        self.scale_res = np.array([q.sensors.scale_resolution for q in p])
        self.feed = np.array([m.scenario.feed for m in models])
        self.ta = np.array([q.simulation.acceleration_time for q in p])
        self.x0 = col(lambda m: m.ic["x_ref0"])
        # constants folded once, so that a derivative evaluation does as few array operations as it can
        self.inv_kb_kn = 1.0 / self.kb + 1.0 / self.kn
        self.damping_per_k2 = self.cb / self.kb**2 + self.cn / self.kn**2
        self.inv_vs = 1.0 / self.vs
        self.gaussian = bool(np.all(self.delta == 2.0))
        self.drop = self.fs - self.fc
        self.s0_per_fc = self.s0 / self.fc
        self.drop_nut = self.fs_nut - self.fc_nut
        self.s0_per_fc_nut = self.s0 / np.where(self.nut, self.fc_nut, 1.0)


def _quantize(x, res):
    safe = np.where(res > 0, res, 1.0)
    return np.where(res > 0, safe * np.floor(x / safe), x)


class BatchedFeedDrive(LeafSystem):
    """N feed-drive cases (sampled cascade) in one system.

    Continuous state: the N cases' ``[theta, omega(, tau), x, v(, w(, w_nut))]`` stacked state-major
    (``state[i * N + k]`` is state ``i`` of case ``k``); discrete state: the controllers'
    ``[v_cmd, integrator, theta_prev, force, tick, force[k-1] .. force[k-n]]`` (``n`` the computation delay),
    stacked the same way. Output ``table``:
    ``[x_ref, x, v]`` of every case, stacked.
    """

    def __init__(self, models):
        LeafSystem.__init__(self)
        self.c = c = _Columns(models)
        if not models[0].sampled:
            raise InputError("controller.sampled", False, "true: the batched path runs the sampled cascade")
        states, discrete = zip(*(m.initial_state() for m in models))
        self.ns = len(states[0])
        x0 = np.array(states).T.reshape(-1)
        xd0 = np.array(discrete, dtype=float).T.reshape(-1)
        self.DeclareContinuousState(BasicVector(x0))
        self.DeclareDiscreteState(BasicVector(xd0))
        self.DeclarePeriodicDiscreteUpdateEvent(c.period, 0.0, self._update)
        self.DeclareVectorOutputPort("table", 3 * c.n, self._output, prerequisites_of_calc={self.xc_ticket()})
        self.x0, self.xd0 = x0, xd0

    # ---------------------------------------------------------------- vectorized pieces
    def _reference(self, t):
        c = self.c
        ramping = t < c.ta
        ta = np.where(c.ta > 0, c.ta, 1.0)
        x = np.where(ramping, c.x0 + 0.5 * c.feed * t * t / ta, c.x0 + c.feed * (t - 0.5 * c.ta))
        v = np.where(ramping, c.feed * t / ta, c.feed)
        return x, v

    def _g(self, v, fc=None, drop=None):
        c = self.c
        fc, drop = (c.fc, c.drop) if fc is None else (fc, drop)
        q = v * c.inv_vs
        shape = q * q if c.gaussian else np.abs(q) ** c.delta
        return fc + drop * np.exp(-shape)

    def _friction(self, v, w, fc, drop, viscous=True):
        """Friction force and (LuGre) bristle-state rate of every case at speeds ``v``; ``viscous`` False: without
        the ``Fv v`` term (the nut on the screw, :func:`drakecreep.model.nut_friction.nut_friction_params`)."""
        c = self.c
        fv = c.fv if viscous else 0.0
        if c.law == "lugre":
            rate = v - np.abs(v) * w * fc / self._g(v, fc, drop)
            return fc * w + c.s1 * rate + fv * v, rate
        if c.law == "stribeck":
            return self._g(v, fc, drop) * np.tanh(v / c.vreg) + fv * v, None
        return fc * np.tanh(v / c.vreg) + fv * v, None

    def _split(self, s):
        c, lag = self.c, self.c.lag
        s = s.reshape(self.ns, c.n)
        theta, omega = s[0], s[1]
        tau = s[2] if lag else None
        x, v = s[2 + lag], s[3 + lag]
        w = s[4 + lag] if c.nz else None
        return theta, omega, tau, x, v, w

    def _position(self, theta, x):
        c = self.c
        if c.table_feedback:
            return _quantize(x, c.scale_res)
        return _quantize(theta, c.enc) * c.ratio

    def DoCalcTimeDerivatives(self, context, derivatives):
        c = self.c
        s = context.get_continuous_state_vector().CopyToVector()
        xd = context.get_discrete_state_vector().CopyToVector().reshape(c.nd, c.n)
        force = xd[4 + c.n_delay] if c.n_delay else xd[3]
        theta, omega, tau, x, v, w = self._split(s)
        tau_cmd = np.minimum(np.maximum(force * c.ratio, -c.peak), c.peak)
        if not c.lag:
            tau = tau_cmd
        a = c.a0 + x
        ks = c.ea * c.length / (a * (c.length - a)) if c.mounting == "fixed-fixed" else c.ea / a
        k = 1.0 / (c.inv_kb_kn + 1.0 / ks)
        damping = k * k * c.damping_per_k2
        spring = k * (theta * c.ratio - x) + damping * (omega * c.ratio - v)
        friction, rate = self._friction(v, w, c.fc, c.drop)
        nut, nut_rate = 0.0, None
        if c.nut:
            w_nut = s.reshape(self.ns, c.n)[5 + c.lag] if c.nz else None
            nut, nut_rate = self._friction(omega * c.ratio, w_nut, c.fc_nut, c.drop_nut, viscous=False)
        rows = [omega, (tau - (spring + nut) * c.ratio - c.bm * omega) / c.inertia]
        if c.lag:
            rows.append((tau_cmd - tau) / c.tc)
        rows += [v, (spring - c.fx - friction) / c.mass]
        if c.nz:
            rows.append(c.s0_per_fc * rate)
        if c.nz and c.nut:
            rows.append(c.s0_per_fc_nut * nut_rate)
        derivatives.get_mutable_vector().SetFromVector(np.concatenate(rows))

    def _update(self, context, discrete_state):
        c = self.c
        t = context.get_time()
        xd = context.get_discrete_state_vector().CopyToVector().reshape(c.nd, c.n)
        v_held, integ, theta_prev, force_before, tick = xd[:5]
        queue = [force_before] + list(xd[5:])[:c.n_delay - 1] if c.n_delay else []
        theta, _, _, x, _, _ = self._split(context.get_continuous_state_vector().CopyToVector())
        counted = _quantize(theta, c.enc)
        speed = (counted - theta_prev) / c.period * c.ratio
        x_ref, v_ref = self._reference(t)
        v_new = c.kp * (x_ref - self._position(theta, x)) + c.kff * v_ref
        v_cmd = np.where(tick < 0.5, v_new, v_held)
        error = v_cmd - speed
        u = c.kv * error + integ
        force = np.clip(u, -c.limit, c.limit)
        integ = integ + c.period * (c.ki * error + c.tracking * (force - u))
        tick = np.where(tick > c.divider - 1.5, 0.0, tick + 1.0)
        discrete_state.get_mutable_vector().SetFromVector(
            np.concatenate([v_cmd, integ, counted, force, tick] + queue))

    def _output(self, context, output):
        _, _, _, x, v, _ = self._split(context.get_continuous_state_vector().CopyToVector())
        x_ref, _ = self._reference(context.get_time())
        output.SetFromVector(np.concatenate([x_ref, x, v]))


def simulate_batch(cases):
    """Simulate ``cases`` (a list of ``(params, scenario)``) in one batch; return their metrics.

    Parameters
    ----------
    cases : list of (DriveParams, Scenario)
        All with the same :func:`batch_key`.

    Returns
    -------
    metrics : list of drakecreep.sim.metrics.FeedMetrics
    info : dict
        ``wall_time`` (s), ``steps``, ``derivative_evaluations``, ``cases``.
    """
    if not cases:
        return [], dict(wall_time=0.0, steps=0, derivative_evaluations=0, cases=0)
    keys = {batch_key(p, s) for p, s in cases}
    if len(keys) > 1:
        raise InputError("cases", f"{len(keys)} structures", "cases sharing one batch_key (see drakecreep.sim.batch)")
    params, scenario = cases[0]
    sim = params.simulation
    if sim.steady_start >= scenario.duration:
        raise InputError("simulation.steady_start", sim.steady_start, f"< duration ({scenario.duration} s)")
    check_log_period(sim.log_period, scenario.duration, sim.steady_start)
    for case_params, case_scenario in cases:
        check_step_budget(case_params, case_scenario.duration)
    models = [BaselineModel(p, s) for p, s in cases]
    builder = DiagramBuilder()
    plant = builder.AddSystem(BatchedFeedDrive(models))
    n = len(cases)
    log = builder.AddSystem(VectorLogSink(3 * n, sim.log_period))
    builder.Connect(plant.get_output_port(0), log.get_input_port())
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    start = time.perf_counter()
    simulator = make_simulator(diagram, context, sim, target_accuracy(params))
    simulator.AdvanceTo(scenario.duration)
    wall = time.perf_counter() - start
    data = log.FindLog(context)
    t, y = data.sample_times(), data.data()
    metrics = []
    for k, (p, s) in enumerate(cases):
        x_ref, x, v = y[k], y[n + k], y[2 * n + k]
        metrics.append(feed_metrics(t, v, x_ref - x_ref[0], x - x[0], s.feed, sim.steady_start, sim.stick_threshold))
    integrator = simulator.get_integrator()
    info = dict(wall_time=wall, steps=int(integrator.get_num_steps_taken()),
                derivative_evaluations=int(integrator.get_num_derivative_evaluations()), cases=n)
    return metrics, info
