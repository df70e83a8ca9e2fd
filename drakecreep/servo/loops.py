"""Loop breaking and loop measures: margins, crossover, bandwidth, sensitivity peak, resonance.

Two loops of the cascade, each broken at its feedback signal (the loop gain ``L`` is minus the
response from the cut feedback input to the measured output, so ``feedback(L, 1)`` is the closed loop):

* ``velocity``: broken at the speed feedback, position loop open.
* ``position``: broken at the position feedback (encoder angle or linear scale), velocity loop closed.

Two controller variants:

* ``continuous`` -- the Drake-linearized plant and continuous controller (:mod:`drakecreep.servo.linearize`).
* ``sampled`` -- what the drive really runs (``controller.sampled``): the same Drake-linearized plant
  discretized with a zero-order hold at the velocity period (``control.c2d``), the speed taken as the
  backward difference of the encoder angle, the PI integrator advanced by forward Euler, exactly as in
  ``CascadeController._update``. The position loop runs every ``position_divider`` velocity samples
  with its command held: the inner loop is lifted to the position period (``A^N``,
  ``sum A^i B``), which is exact for this multirate cascade, not an approximation.

The computation delay of the sampled controller (``controller.computation_delay = n + f`` samples: the
command computed at ``t_k`` reaches the motor at ``t_{k+n} + f h``) is in the sampled loops as an exact
discretization of the plant with a delayed zero-order hold (:func:`delayed_zoh`): ``z^-n`` for the whole
samples and, for ``f > 0``, the modified z-transform (Astrom & Wittenmark, *Computer-Controlled Systems*,
3rd ed. 1997, sec. 2.3: the held input switches inside the period), no Pade or Thiran approximation.
The difference of the two phase margins is what sampling, hold and computation delay cost;
:meth:`LoopAnalysis.summary` also gives the delay's own share (``computation_delay_cost``).
Delay margin = phase margin / gain-crossover frequency (the smallest over all crossovers), seconds.
Bandwidth = first frequency where ``|T| = L/(1+L)`` falls 3 dB below its low-frequency value.
``Ms = max |1/(1+L)|``.
"""

import math
from dataclasses import dataclass, field

import control
import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from drakecreep.errors import InputError
from drakecreep.servo.linearize import linearize_controller, linearize_plant, operating_point

__all__ = [
    "LOOPS",
    "loop_margins",
    "is_stable",
    "loop_transfer",
    "sampled_velocity_controller",
    "lift",
    "delayed_zoh",
    "plant_resonance",
    "resonance_text",
    "LoopAnalysis",
    "analyze_loops",
]

LOOPS = ("velocity", "position")
#: frequencies below this (rad/s) count as static gain, not as margin crossings (python-control ``epsw``)
EPSW = 1e-3
#: a phase crossover where |L| < 1 / GM_LIMIT (-120 dB) is the asymptote of a continuous loop's roll-off
#: touched by round-off, not a margin: reported as an infinite gain margin
GM_LIMIT = 1e6


def _freq_grid(L, n=3000):
    if L.isdtime(strict=True):
        top = math.pi / L.dt
        return np.logspace(-2, math.log10(top * 0.9999), n)
    poles = np.abs(L.poles())
    top = 10.0 * max(np.max(poles, initial=1.0), 10.0)
    return np.logspace(-2, math.log10(top), n)


def _eval(L, w):
    return np.asarray(control.frequency_response(L, w).complex).reshape(-1)


def loop_margins(L, omega=None):
    """Margins and loop measures of a SISO loop gain ``L`` (negative feedback convention).

    Parameters
    ----------
    L : control.LTI
        Loop gain, continuous or discrete time.
    omega : array_like, optional
        Frequency grid (rad/s) for ``Ms`` and the bandwidth; a log grid to the Nyquist frequency
        (discrete) or beyond the fastest pole (continuous) by default.

    Returns
    -------
    dict
        ``gain_margin_dB`` (``inf`` if the phase never crosses -180 deg; negative: a gain *reduction*
        margin), ``phase_margin_deg`` (python-control: smallest ``|180 + phase|`` over the gain crossovers),
        ``delay_margin_ms`` (smallest over all gain crossovers, 0 if the closed loop is unstable),
        ``crossover_Hz`` (lowest gain crossover; ``gain_crossovers_Hz`` lists all, a resonance can add
        more), ``phase_crossover_Hz``,
        ``bandwidth_Hz`` (-3 dB of ``T``), ``ms_peak`` and ``ms_frequency_Hz``, ``closed_loop_stable``,
        ``open_loop_unstable_poles``.
    """
    w = _freq_grid(L) if omega is None else np.asarray(omega, dtype=float)
    # discrete loops: python-control's polynomial method is ill-conditioned at these sample rates; its
    # interpolating FRD method on a dense grid up to the Nyquist frequency is used instead
    data = control.frd(L, w) if L.isdtime(strict=True) else L
    gm, pm, sm, wpc, wgc, wms = control.stability_margins(data, epsw=EPSW)
    if L.isdtime(strict=True):
        # the phase of a sampled loop can reach -180 deg exactly at the Nyquist frequency (z = -1),
        # where an interpolating search does not see a crossing
        r_nyq = complex(np.asarray(L(-1.0)).reshape(-1)[0])
        if r_nyq.real < 0 and abs(r_nyq.imag) <= 1e-9 * abs(r_nyq) and (not np.isfinite(gm) or -1 / r_nyq.real < gm):
            gm, wpc = -1.0 / r_nyq.real, math.pi / L.dt
    _, pms, _, _, wgcs, _ = control.stability_margins(data, returnall=True, epsw=EPSW)
    pms, wgcs = np.atleast_1d(pms), np.atleast_1d(wgcs)
    resp = _eval(L, w)
    S = 1.0 / (1.0 + resp)
    T = resp / (1.0 + resp)
    ms_i = int(np.argmax(np.abs(S)))
    ms = float(np.abs(S[ms_i]))
    if np.isfinite(sm) and sm > 0:
        ms = max(ms, 1.0 / float(sm))
    bw = _bandwidth(L, w, T)
    stable = is_stable(control.feedback(L, 1).poles(), L.isdtime(strict=True))
    ol = L.poles()
    unstable_ol = int(np.sum(_unstable(ol, L.isdtime(strict=True))))
    # delay margin: at each gain crossover, the extra lag that brings the phase to -180 deg (mod 360)
    delays = [math.radians(p % 360.0) / wc for p, wc in zip(pms, wgcs) if wc > 0 and np.isfinite(p)]
    delay = (min(delays) if delays else math.inf) if stable else 0.0
    crossovers = sorted(float(x) / (2 * math.pi) for x in wgcs if np.isfinite(x))
    return dict(
        gain_margin_dB=float(20 * math.log10(gm)) if np.isfinite(gm) and 0 < gm < GM_LIMIT else math.inf,
        phase_margin_deg=float(pm) if np.isfinite(pm) else math.inf,
        delay_margin_ms=float(delay * 1e3) if np.isfinite(delay) else math.inf,
        crossover_Hz=crossovers[0] if crossovers else math.nan,
        gain_crossovers_Hz=crossovers,
        phase_crossover_Hz=float(wpc) / (2 * math.pi) if np.isfinite(wpc) else math.nan,
        bandwidth_Hz=bw / (2 * math.pi) if np.isfinite(bw) else math.nan,
        ms_peak=ms,
        ms_frequency_Hz=float(w[ms_i]) / (2 * math.pi),
        closed_loop_stable=stable,
        open_loop_unstable_poles=unstable_ol,
    )


def _unstable(poles, discrete):
    poles = np.asarray(poles)
    if discrete:
        return np.abs(poles) > 1.0 + 1e-9
    scale = max(1.0, float(np.max(np.abs(poles), initial=1.0)))
    return poles.real > 1e-9 * scale


def is_stable(poles, discrete=False):
    """No pole in the open right half plane (outside the unit circle), with a relative tolerance.

    Poles at the origin (``z = 1``) within ``1e-9`` of the largest pole are counted as neutral: the
    rigid-body position of the drive is such a mode when the position loop is open.
    """
    return not bool(np.any(_unstable(poles, discrete)))


def _bandwidth(L, w, T):
    mag = np.abs(T)
    r0 = _eval(L, np.array([1e-6]))[0]  # the static value of |T| (an integrating L gives exactly 1)
    level = abs(r0 / (1.0 + r0)) / math.sqrt(2.0)
    below = np.nonzero(mag < level)[0]
    if not len(below) or below[0] == 0:
        return math.nan
    i = below[0]

    def f(x):
        r = _eval(L, np.array([x]))[0]
        return abs(r / (1.0 + r)) - level

    return float(brentq(f, w[i - 1], w[i], xtol=1e-9 * w[i]))


# --------------------------------------------------------------------------- loop construction

def _index(sys, name, kind):
    labels = sys.input_labels if kind == "in" else sys.output_labels
    return labels.index(name)


def _siso(sys, out, inp):
    return sys[_index(sys, out, "out"), _index(sys, inp, "in")]


def sampled_velocity_controller(params):
    """The sampled velocity loop of ``CascadeController._update`` as a discrete ``StateSpace``.

    Speed ``r (theta_k - theta_{k-1}) / T``; ``force_k = kv e_k + I_k``, ``I_{k+1} = I_k + T ki e_k``;
    torque ``r force`` held over the period (ZOH). Inputs ``v_cmd, encoder_angle``; output
    ``torque_command``; ``dt`` = velocity period.
    """
    g = params.controller
    T = g.velocity_period
    r = params.screw.lead / (2.0 * math.pi)
    kv, ki = g.velocity_gain, g.velocity_integral_gain
    # states: [theta_prev, I]; e = v_cmd - r (theta - theta_prev) / T
    A = np.array([[0.0, 0.0], [T * ki * r / T, 1.0]])
    B = np.array([[0.0, 1.0], [T * ki, -T * ki * r / T]])
    C = np.array([[kv * r / T * r, r]])
    D = np.array([[kv * r, -kv * r * r / T]])
    return control.ss(A, B, C, D, T, inputs=["v_cmd", "encoder_angle"], outputs=["torque_command"],
                      states=["theta_prev", "integrator"], name="velocity_pi")


def _hold_integral(A, B, t):
    """``(e^{A t}, int_0^t e^{A s} ds B)`` from one matrix exponential (Van Loan's block form)."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A * t, B * t
    E = expm(M)
    return E[:n, :n], E[:n, n:]


def delayed_zoh(P, h, delay=0.0):
    """Exact discretization at period ``h`` of a continuous plant whose held input arrives ``delay`` samples late.

    The input sequence ``u[k]`` (computed at ``t_k``) drives the plant as ``u[k - n]`` on
    ``[t_k + f h, t_{k+1} + f h)`` (``delay = n + f``). ``f = 0``: ``control.c2d(P, h, "zoh")`` times
    ``z^-n``. ``f > 0`` (modified z-transform): ``x[k+1] = Phi x[k] + Gamma0 v[k] + Gamma1 v[k-1]`` with
    ``Gamma0 = int_0^{h - f h} e^{A s} ds B``, ``Gamma1 = e^{A (h - f h)} int_0^{f h} e^{A s} ds B``,
    then ``z^-n``. No approximation of the delay.

    Parameters
    ----------
    P : control.StateSpace
        Continuous plant (any number of inputs and outputs; labels are kept).
    h : float
        Sample time (s).
    delay : float
        Samples, >= 0.

    Returns
    -------
    control.StateSpace
        Discrete, ``dt = h``; its extra states are the held and queued inputs.
    """
    n_whole = int(math.floor(delay))
    frac = float(delay) - n_whole
    if not (math.isfinite(delay) and delay >= 0):
        raise InputError("controller.computation_delay", delay, "a number of samples >= 0")
    ins, outs = list(P.input_labels), list(P.output_labels)
    if frac == 0.0:
        Pd = control.c2d(control.ss(P), h, "zoh")
    else:
        A, B, C, D = (np.asarray(M, dtype=float) for M in (P.A, P.B, P.C, P.D))
        nx, m = B.shape
        Phi, _ = _hold_integral(A, B, h)
        E0, G0 = _hold_integral(A, B, h - frac * h)
        _, Gf = _hold_integral(A, B, frac * h)
        G1 = E0 @ Gf
        # state [x, v[k-1]]; at t_k the plant still gets v[k-1] (output feedthrough D acts on it)
        Ad = np.block([[Phi, G1], [np.zeros((m, nx)), np.zeros((m, m))]])
        Bd = np.vstack([G0, np.eye(m)])
        Cd = np.hstack([C, D])
        Pd = control.ss(Ad, Bd, Cd, np.zeros_like(D), h)
    if n_whole:
        m = Pd.ninputs
        # z^-n on every input: a shift register of n samples per input
        A = np.kron(np.eye(n_whole, k=-1), np.eye(m))
        B = np.vstack([np.eye(m)] + [np.zeros((m, m))] * (n_whole - 1))
        C = np.hstack([np.zeros((m, m))] * (n_whole - 1) + [np.eye(m)])
        shift = control.ss(A, B, C, np.zeros((m, m)), h)
        Pd = control.series(shift, Pd)
    return control.ss(Pd.A, Pd.B, Pd.C, Pd.D, h, inputs=ins, outputs=outs)


def lift(sys, n):
    """A discrete system whose input is held for ``n`` of its samples, seen every ``n`` samples.

    Returns
    -------
    control.StateSpace
        ``(A^n, sum_{i<n} A^i B, C, D)`` with ``dt = n * sys.dt`` (same signal names).
    """
    A, B = np.asarray(sys.A), np.asarray(sys.B)
    An = np.eye(A.shape[0])
    Bn = np.zeros_like(B)
    for _ in range(n):
        Bn = A @ Bn + B
        An = A @ An
    return control.ss(An, Bn, sys.C, sys.D, n * sys.dt, inputs=sys.input_labels, outputs=sys.output_labels)


def loop_transfer(params, scenario, loop="velocity", sampled=None, op=None, plant=None, controller=None):
    """Loop gain of one loop, broken at its feedback signal.

    Parameters
    ----------
    params, scenario
        Drive and operating point (the scenario's feed and load case).
    loop : {"velocity", "position"}
    sampled : bool, optional
        Default ``params.controller.sampled``.
    op, plant, controller : optional
        Precomputed operating point and linearizations (saves time in sweeps).

    Returns
    -------
    control.StateSpace
        SISO ``L`` (dimensionless), continuous or discrete (``dt`` = velocity or position period).
    """
    if loop not in LOOPS:
        raise InputError("loop", loop, "one of " + ", ".join(LOOPS))
    sampled = params.controller.sampled if sampled is None else sampled
    op = op or operating_point(params, scenario)
    P = plant if plant is not None else linearize_plant(params, scenario, op)
    g = params.controller
    motor_fb = g.position_feedback == "motor"
    meas = "motor_angle" if motor_fb else "table_position"
    if not sampled:
        K = controller if controller is not None else linearize_controller(params, scenario, op)
        if loop == "velocity":
            L = -_siso(K, "torque_command", "motor_speed_measured") * _siso(P, "motor_speed", "torque_command")
        else:
            fb = "encoder_angle" if motor_fb else "scale_position"
            sensors = control.ss([], [], [], np.eye(1), inputs=["motor_speed"], outputs=["motor_speed_measured"],
                                 name="tacho")
            inner = control.interconnect(
                [P, K, sensors], inplist=[fb], outlist=[meas], check_unused=False,
            )
            L = -inner
        return control.ss(L, name=f"L_{loop}")
    Tv = g.velocity_period
    Pd = delayed_zoh(control.ss(P, name="plant"), Tv, g.computation_delay)
    Cv = sampled_velocity_controller(params)
    if loop == "velocity":
        L = -_siso(Cv, "torque_command", "encoder_angle") * _siso(Pd, "motor_angle", "torque_command")
        return control.ss(L, name="L_velocity")
    encoder = control.ss([], [], [], np.eye(1), Tv, inputs=["motor_angle"], outputs=["encoder_angle"], name="encoder")
    inner = control.interconnect([Pd, Cv, encoder], inplist=["v_cmd"], outlist=[meas], check_unused=False)
    lifted = lift(control.ss(inner), g.position_divider)
    scale = params.screw.lead / (2.0 * math.pi) if motor_fb else 1.0
    return control.ss(g.position_gain * scale * lifted, name="L_position")


def plant_resonance(P):
    """Lowest-frequency lightly damped (complex) pole pair of a continuous plant.

    Returns
    -------
    (float, float)
        Natural frequency (Hz) and damping ratio; ``(nan, nan)`` when the plant has no complex pole.
    """
    poles = [p for p in P.poles() if p.imag > 1e-6 * max(1.0, abs(p))]
    if not poles:
        return math.nan, math.nan
    p = min(poles, key=abs)
    return abs(p) / (2 * math.pi), -p.real / abs(p)


def resonance_text(frequency_Hz, damping_ratio, fmt=".4g"):
    """The first mechanical resonance in words: ``'73.51 Hz, damping ratio 0.013'``, or, where the plant has no
    complex pole (:func:`plant_resonance` gives NaN: every mode overdamped), that it has none."""
    if not math.isfinite(frequency_Hz):
        return "none (no complex plant pole: every mode is overdamped)"
    return f"{frequency_Hz:{fmt}} Hz, damping ratio {damping_ratio:{fmt}}"


@dataclass
class LoopAnalysis:
    """Margins of both loops, continuous and sampled, at one operating point.

    Attributes
    ----------
    op : drakecreep.servo.linearize.OperatingPoint
    loops : dict
        ``{"continuous": {"velocity": L, "position": L}, "sampled": {...}}`` (python-control systems).
    margins : dict
        Same keys, values from :func:`loop_margins`.
    resonance_Hz, resonance_damping : float
        First mechanical resonance of the plant (loops open).
    closed_loop_poles : ndarray
        Poles of the linearized continuous-controller diagram.
    """

    op: object
    plant: object
    controller: object
    loops: dict
    margins: dict
    resonance_Hz: float
    resonance_damping: float
    closed_loop_poles: np.ndarray
    sampled: bool
    params: object = None
    scenario: object = None
    extra: dict = field(default_factory=dict)

    @property
    def friction_on_table(self):
        """Whose friction ``op.friction_slope`` (C1) and ``op.zeta`` take: the guides', and the ball nut's lumped
        with them where the model puts it on the screw (:func:`drakecreep.model.steady.nut_on_table`; ``critical``
        takes the guides' alone, the friction on the paper's lumped mass, so the two differ below the Stribeck
        velocity)."""
        on_screw = self.params is not None and self.params.friction.nut_friction_on == "screw"
        return "guides and ball nut, the nut's drag lumped on the table" if on_screw else "guides and ball nut"

    def summary(self):
        """JSON-ready dict: the configured variant's loops at the top, the other variant under its name."""
        main = "sampled" if self.sampled else "continuous"
        out = {loop: dict(self.margins[main][loop]) for loop in LOOPS}
        out["controller"] = main
        if self.sampled:
            g = self.params.controller if self.params is not None else None
            if g is not None:
                out["computation_delay_samples"] = g.computation_delay
                out["computation_delay_ms"] = g.computation_delay * g.velocity_period * 1e3
            # the costs are differences of margins: of a loop unstable when closed (sampled, or continuous) there
            # are no margins, and a difference of them is none (a 'cost' of 228 deg out of 175 lost in all, printed)
            stable = {loop: self.margins["sampled"][loop]["closed_loop_stable"]
                      and self.margins["continuous"][loop]["closed_loop_stable"] for loop in LOOPS}
            undelayed = self.extra.get("undelayed_margins")
            if undelayed:
                # what the computation delay alone costs: sampled margins without it minus with it
                out["computation_delay_cost"] = {
                    loop: ({k: undelayed[loop][k] - self.margins["sampled"][loop][k]
                            for k in ("phase_margin_deg", "gain_margin_dB", "delay_margin_ms")}
                           if stable[loop] and undelayed[loop]["closed_loop_stable"] else None)
                    for loop in LOOPS
                }
            out["continuous"] = {loop: dict(self.margins["continuous"][loop]) for loop in LOOPS}
            out["sampling_phase_cost_deg"] = {
                loop: (self.margins["continuous"][loop]["phase_margin_deg"] - self.margins["sampled"][loop][
                    "phase_margin_deg"]) if stable[loop] else None for loop in LOOPS
            }
        cl = self.closed_loop_poles
        worst = cl[np.argmax(cl.real)]
        out["resonance_Hz"] = self.resonance_Hz
        out["resonance_damping"] = self.resonance_damping
        out["closed_loop_rightmost_pole"] = [float(worst.real), float(abs(worst.imag))]
        out["operating_point"] = dict(
            feed_mm_s=self.op.feed * 1e3, load_case=self.scenario.load_case if self.scenario else None,
            stiffness_N_per_um=self.op.stiffness * 1e-6, damping_Ns_per_m=self.op.damping,
            friction_slope_C1_Ns_per_m=self.op.friction_slope, mass_kg=self.op.mass, zeta=self.op.zeta,
            spring_force_N=self.op.spring_force, friction_force_N=self.op.friction_force,
            friction_on_table=self.friction_on_table,
        )
        return out


def analyze_loops(params, scenario):
    """Linearize at the scenario's feed and measure both loops in both controller variants.

    Returns
    -------
    LoopAnalysis
    """
    from drakecreep.params import check_params
    from drakecreep.scenario import check_scenario
    from drakecreep.servo.linearize import closed_loop_from_parts

    check_params(params)
    check_scenario(scenario)
    op = operating_point(params, scenario)
    P = linearize_plant(params, scenario, op)
    K = linearize_controller(params, scenario, op)
    loops, margins = {}, {}
    variants = ("continuous", "sampled") if params.controller.sampled else ("continuous",)
    for variant in variants:
        loops[variant], margins[variant] = {}, {}
        for loop in LOOPS:
            L = loop_transfer(params, scenario, loop, sampled=variant == "sampled", op=op, plant=P, controller=K)
            loops[variant][loop] = L
            margins[variant][loop] = loop_margins(L)
    extra = {}
    if params.controller.sampled and params.controller.computation_delay > 0:
        import dataclasses

        bare = dataclasses.replace(params, controller=dataclasses.replace(params.controller, computation_delay=0.0))
        extra["undelayed_margins"] = {
            loop: loop_margins(loop_transfer(bare, scenario, loop, sampled=True, op=op, plant=P, controller=K))
            for loop in LOOPS
        }
    f, z = plant_resonance(P)
    cl = closed_loop_from_parts(P, K, params.controller.position_feedback).poles()
    return LoopAnalysis(op=op, plant=P, controller=K, loops=loops, margins=margins, resonance_Hz=f,
                        resonance_damping=z, closed_loop_poles=cl, sampled=params.controller.sampled,
                        params=params, scenario=scenario, extra=extra)
