"""The feed drive's equations written again in plain Python, integrated with SciPy ``solve_ivp``.

Two uses: the speed baseline of ``analysis/bench_simulation.py`` (the issue asks for the ratio of
drakecreep's time to a plain ``solve_ivp(method="LSODA")`` on the same equations), and an
independent check of the Drake leaf systems (``tests/test_baseline.py``): nothing here calls the
Drake systems, so a wiring or sign error in either shows up as disagreeing trajectories.

The sampled controller is integrated piecewise between velocity-loop samples (the zero-order hold
makes the right-hand side discontinuous at every sample), which is how a plain ODE solver has to
treat it; the continuous controller is one ``solve_ivp`` call.

State order is the Drake diagram's: ``[integrator]`` (continuous controller only), motor
``[theta, omega, tau]``, table ``[x, v, z...]``.
"""

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from drakecreep.model.diagram import initial_conditions
from drakecreep.model.nut_friction import nut_friction_params
from drakecreep.model.screw import bearing_element, nut_element
from drakecreep.params import two_mass_effects

__all__ = ["BaselineModel", "simulate_baseline", "unsupported"]


def unsupported(params):
    """Why these plain-Python equations cannot run ``params``: ``(field, value, allowed)``, or None.

    They cover the base drive (coulomb, stribeck or lugre friction): no disturbances, no friction compensation;
    the nut's friction on the table or on the screw.
    """
    p = params
    if p.friction.law not in ("coulomb", "stribeck", "lugre"):
        return ("friction.law", p.friction.law, "coulomb, stribeck or lugre (the plain-Python equations)")
    for name in ("coulomb_asymmetry", "viscous_asymmetry"):
        if getattr(p.friction, name) != 0.0:
            return (f"friction.{name}", getattr(p.friction, name), "0 (the plain-Python equations are symmetric)")
    for path, value, what in two_mass_effects(p):  # the lead error and the cogging: the disturbances' below
        if not path.startswith("disturbance."):
            return (path, value, f"0 (the plain-Python equations lack {what})")
    d = p.disturbance
    if d.has_lead_error or d.has_cogging or d.force_ripple > 0 or d.load_ripple > 0:
        return ("disturbance", "switched on", "all amplitudes 0 (the plain-Python equations have no disturbances)")
    if p.sensors.scale_interpolation_error > 0 and p.controller.position_feedback == "table":
        return ("sensors.scale_interpolation_error", p.sensors.scale_interpolation_error,
                "0 with the scale in the loop (the plain-Python equations have no interpolation error)")
    if p.compensation.method != "none":
        return ("compensation.method", p.compensation.method, "none (the plain-Python equations have no compensator)")
    if p.controller.sampled and not float(p.controller.computation_delay).is_integer():
        return ("controller.computation_delay", p.controller.computation_delay,
                "a whole number of samples (the plain-Python equations switch only at the samples)")
    return None


class BaselineModel:
    """Right-hand side and discrete update of the feed drive for ``params`` and ``scenario``."""

    def __init__(self, params, scenario, continuous=None):
        p = params
        reason = unsupported(p)
        if reason:
            from drakecreep.errors import InputError

            raise InputError(reason[0], reason[1], reason[2])
        self.p = p
        self.scenario = scenario
        self.sampled = p.controller.sampled if continuous is None else not continuous
        load = p.load_case(scenario.load_case)
        self.fx = load.fx
        self.ratio = p.screw.lead / (2 * math.pi)
        sc, nut = p.screw, p.nut
        self.ea = sc.youngs_modulus * math.pi / 4 * sc.root_diameter**2
        self.inertia = (p.motor.rotor_inertia + p.motor.coupling_inertia
                        + math.pi / 32 * sc.density * sc.length * sc.nominal_diameter**4)
        self.mass = p.table.mass + nut.mass
        normal = abs(self.mass * p.loads.gravity + load.fz) + abs(load.fy)
        guides = p.table.seal_force + p.table.guide_friction_coefficient * normal
        nut_fc = 2 * math.pi * nut.preload_torque / sc.lead + nut.load_friction_coefficient * abs(load.fx)
        # the nut's share acts on the table with the guides, or on the screw's rotation (its own law state)
        on_screw = p.friction.nut_friction_on == "screw" and nut_fc > 0
        self.fc = guides if on_screw else guides + nut_fc
        self.fs = p.friction.static_ratio * self.fc
        self.fc_nut = nut_fc if on_screw else 0.0
        self.fs_nut = p.friction.static_ratio * self.fc_nut
        self.limit = p.motor.peak_torque * 2 * math.pi / sc.lead
        g = p.controller
        self.tracking = g.velocity_integral_gain / g.velocity_gain if (g.anti_windup and g.velocity_integral_gain > 0) else 0.0
        self.n_delay = int(g.computation_delay) if self.sampled else 0
        counts = p.sensors.encoder_counts_per_rev
        self.enc = 0.0 if counts == 0 else 2 * math.pi / counts
        self.ic = initial_conditions(p, scenario)
        self.lag = p.motor.current_loop_time_constant
        self.nz = 1 if p.friction.law == "lugre" else 0
        self.nz_nut = self.nz if self.fc_nut > 0 else 0

    # ---------------------------------------------------------------- pieces
    def stiffness(self, x):
        sc, nut = self.p.screw, self.p.nut
        a = sc.nut_start_distance + x
        ks = self.ea * sc.length / (a * (sc.length - a)) if sc.mounting == "fixed-fixed" else self.ea / a
        (kb, cb), (kn, cn) = bearing_element(sc), nut_element(sc, nut)
        k = 1.0 / (1.0 / kb + 1.0 / ks + 1.0 / kn)
        c = k * k * (cb / kb**2 + cn / kn**2)
        return k, c

    def g(self, v, fc=None, fs=None):
        f = self.p.friction
        fc, fs = (self.fc, self.fs) if fc is None else (fc, fs)
        return fc + (fs - fc) * math.exp(-abs(v / f.stribeck_velocity) ** f.stribeck_exponent)

    def friction(self, v, z, fc=None, fs=None, viscous=True):
        """Friction force and its state rate at speed ``v``; levels default to the table's. ``viscous`` False:
        without the ``Fv v`` term (the nut on the screw, :func:`drakecreep.model.nut_friction.nut_friction_params`)."""
        f = self.p.friction
        if not viscous:
            f = nut_friction_params(f)
        fc, fs = (self.fc, self.fs) if fc is None else (fc, fs)
        if f.law == "coulomb":
            return fc * math.tanh(v / f.regularization_velocity) + f.viscous * v, 0.0
        if f.law == "stribeck":
            return self.g(v, fc, fs) * math.tanh(v / f.regularization_velocity) + f.viscous * v, 0.0
        # z is the bristle load as a fraction of Fc, w = sigma0 z_deflection / Fc (see LuGreFriction)
        deflection_rate = v - abs(v) * z * fc / self.g(v, fc, fs)
        friction = fc * z + f.bristle_damping * deflection_rate + f.viscous * v
        return friction, f.bristle_stiffness / fc * deflection_rate

    def reference(self, t):
        v, ta, x0 = self.scenario.feed, self.p.simulation.acceleration_time, self.ic["x_ref0"]
        if ta > 0 and t < ta:
            return x0 + 0.5 * v * t * t / ta, v * t / ta
        return x0 + v * (t - 0.5 * ta), v

    def pi(self, error, integ):
        g = self.p.controller
        u = g.velocity_gain * error + integ
        force = min(max(u, -self.limit), self.limit)
        return force, g.velocity_integral_gain * error + self.tracking * (force - u)

    def measured_position(self, theta, x):
        if self.p.controller.position_feedback == "table":
            res = self.p.sensors.scale_resolution
            return res * math.floor(x / res) if res else x
        return (self.enc * math.floor(theta / self.enc) if self.enc else theta) * self.ratio

    # ---------------------------------------------------------------- dynamics
    def rhs(self, t, s, force_cmd):
        """Time derivatives; ``force_cmd`` is the held controller force (sampled) or None (continuous)."""
        i = 0
        out = []
        if not self.sampled:
            integ = s[0]
            i = 1
        theta, omega = s[i], s[i + 1]
        tau_state = s[i + 2] if self.lag > 0 else None
        x, v = s[i + 2 + (self.lag > 0)], s[i + 3 + (self.lag > 0)]
        z = s[i + 4 + (self.lag > 0)] if self.nz else 0.0
        z_nut = s[i + 4 + (self.lag > 0) + self.nz] if self.nz_nut else 0.0
        if not self.sampled:
            x_ref, v_ref = self.reference(t)
            g = self.p.controller
            v_cmd = g.position_gain * (x_ref - self.measured_position(theta, x)) + g.velocity_feedforward * v_ref
            force_cmd, rate = self.pi(v_cmd - omega * self.ratio, integ)
            out.append(rate)
        tau_cmd = min(max(force_cmd * self.ratio, -self.p.motor.peak_torque), self.p.motor.peak_torque)
        tau = tau_state if self.lag > 0 else tau_cmd
        k, c = self.stiffness(x)
        spring = k * (theta * self.ratio - x) + c * (omega * self.ratio - v)
        friction, zdot = self.friction(v, z)
        nut, znut_dot = self.friction(omega * self.ratio, z_nut, self.fc_nut, self.fs_nut, viscous=False) \
            if self.fc_nut > 0 else (0.0, 0.0)
        out += [omega, (tau - (spring + nut) * self.ratio - self.p.motor.viscous_damping * omega) / self.inertia]
        if self.lag > 0:
            out.append((tau_cmd - tau) / self.lag)
        out += [v, (spring - self.fx - friction) / self.mass]
        if self.nz:
            out.append(zdot)
        if self.nz_nut:
            out.append(znut_dot)
        return out

    def update(self, t, s, xd):
        """One velocity-loop sample: ``xd = [v_cmd, integrator, theta_prev, force, tick, force[k-1] .. force[k-n]]``
        -> next (``n`` = ``controller.computation_delay``; :meth:`applied` is the force the motor gets)."""
        g = self.p.controller
        v_held, integ, theta_prev, force_before, tick = xd[:5]
        queue = ([force_before] + list(xd[5:]))[:self.n_delay]
        lag = self.lag > 0
        theta = s[0]
        x = s[2 + lag]
        counted = self.enc * math.floor(theta / self.enc) if self.enc else theta
        speed = (counted - theta_prev) / g.velocity_period * self.ratio
        if tick < 0.5:
            x_ref, v_ref = self.reference(t)
            v_cmd = g.position_gain * (x_ref - self.measured_position(theta, x)) + g.velocity_feedforward * v_ref
        else:
            v_cmd = v_held
        force, rate = self.pi(v_cmd - speed, integ)
        next_tick = 0.0 if tick > g.position_divider - 1.5 else tick + 1.0
        return [v_cmd, integ + g.velocity_period * rate, counted, force, next_tick] + queue

    def applied(self, xd):
        """The force applied after a sample: ``force[k - n]``."""
        return xd[4 + self.n_delay] if self.n_delay else xd[3]

    def initial_state(self):
        ic = self.ic
        s = [] if self.sampled else [ic["force0"]]
        s += [ic["theta0"], 0.0] + ([ic["force0"] * self.ratio] if self.lag > 0 else [])
        s += [0.0, 0.0] + [0.0] * (self.nz + self.nz_nut)
        xd = [0.0, ic["force0"], ic["theta_counted0"], ic["force0"], 0.0] + [ic["force0"]] * self.n_delay
        return np.array(s), xd


def simulate_baseline(params, scenario, *, method="LSODA", rtol=1e-6, atol=None, continuous=None):
    """Integrate the baseline model over ``scenario.duration``; sampled at ``params.simulation.log_period``.

    Returns
    -------
    dict
        ``t`` (s), ``state`` (samples x states), ``table_speed`` (m/s), ``wall_time`` (s),
        ``nfev`` (right-hand-side evaluations), ``calls`` (``solve_ivp`` calls).
    """
    model = BaselineModel(params, scenario, continuous=continuous)
    s0, xd = model.initial_state()
    dt_log = params.simulation.log_period
    n_log = int(math.floor(scenario.duration / dt_log + 1e-9)) + 1
    t_log = np.arange(n_log) * dt_log
    kw = dict(method=method, rtol=rtol, atol=atol if atol is not None else 1e-9,
              max_step=params.simulation.max_step)
    nfev = calls = 0
    start = time.perf_counter()
    if not model.sampled:
        sol = solve_ivp(lambda t, s: model.rhs(t, s, None), (0.0, t_log[-1]), s0, t_eval=t_log, **kw)
        states, nfev, calls = sol.y.T, sol.nfev, 1
    else:
        period = params.controller.velocity_period
        n_samples = int(math.ceil(scenario.duration / period - 1e-9))
        states = np.empty((n_log, len(s0)))
        states[0] = s0
        s = s0
        j = 1
        for k in range(n_samples):
            t0, t1 = k * period, min((k + 1) * period, scenario.duration)
            xd = model.update(t0, s, xd)
            force = model.applied(xd)
            j_end = j
            while j_end < n_log and t_log[j_end] <= t1 + 1e-12:
                j_end += 1
            sol = solve_ivp(lambda t, y: model.rhs(t, y, force), (t0, t1), s,
                            t_eval=t_log[j:j_end] if j_end > j else None, **kw)
            nfev += sol.nfev
            calls += 1
            if j_end > j:
                states[j:j_end] = sol.y.T[: j_end - j]
                j = j_end
            s = sol.y[:, -1]
    wall = time.perf_counter() - start
    offset = 0 if model.sampled else 1
    v_index = offset + 3 + (model.lag > 0)
    return dict(t=t_log, state=states, table_speed=states[:, v_index], wall_time=wall, nfev=nfev, calls=calls)
