"""Gains of the cascade for a target velocity-loop bandwidth and phase margin.

Rule: **loop shaping at the crossover** on the linearized, sampled loop (not the symmetric optimum,
which assumes a rigid plant with one small lag; here the plant has the screw resonance, the current
loop, the friction slope and the sampling, all of which the linearization carries):

1. For a trial crossover ``wc``, the velocity loop with a unit proportional gain gives the plant part
   ``Q(wc)`` (Drake-linearized plant, ZOH at the velocity period, backward-difference speed).
2. The PI of the drive, ``C = kv + ki h(w)`` with ``h = T / (z - 1)`` (sampled) or ``1 / s``
   (continuous), is linear in ``(kv, ki)``; ``C(wc) Q(wc) = exp(j (phase_margin - 180 deg))`` is two real
   equations for the two gains: exact gain crossover at ``wc`` with exactly the target phase margin.
3. ``wc`` is adjusted (Brent's method, in 0.3-1.2 times the target) until the closed velocity loop's -3 dB
   bandwidth is the target; where an end of that range needs a negative gain (at low crossovers the plant's
   own phase can leave a PI no way to the margin), the bracket is found among the crossovers it can reach.
4. Position loop: ``kp = 2 pi f_bw / 4`` (1/s) -- the position loop crosses over about four times below
   the velocity-loop bandwidth, so that the closed velocity loop looks like unity to it.

The resulting margins of both loops are measured afterwards with :func:`drakecreep.servo.loops.analyze_loops`
(the resonance can add gain crossovers the rule does not see; they are reported, not hidden).
"""

import cmath
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from drakecreep.errors import InputError
from drakecreep.servo.linearize import linearize_plant, operating_point
from drakecreep.servo.loops import analyze_loops, loop_margins, loop_transfer
from drakecreep.params import with_value

__all__ = ["TuningResult", "tune", "check_targets", "POSITION_BANDWIDTH_RATIO", "RULE", "SCAN_POINTS",
           "MIN_BANDWIDTH_HZ", "PHASE_MARGIN_DEG"]

#: velocity-loop bandwidth / position-loop gain (rad/s per 1/s)
POSITION_BANDWIDTH_RATIO = 4.0
#: lowest velocity-loop bandwidth target, Hz: a feed drive's velocity loop closes at tens to hundreds of Hz; at
#: 1e-300 Hz the search placed a crossover at 3e-301 Hz and blamed the phase margin
MIN_BANDWIDTH_HZ = 0.01
#: phase margin targets, deg: [low, high); below 10 deg the loop is all but unstable (1e-300 deg was tuned, exit 0)
PHASE_MARGIN_DEG = (10.0, 90.0)
RULE = ("loop shaping at the crossover on the linearized sampled loop: PI (kv, ki) solved for |L| = 1 and "
        "the target phase margin at wc, wc set for the target closed-loop bandwidth; kp = w_bw / 4")


@dataclass
class TuningResult:
    """Tuned gains and what they give.

    Attributes
    ----------
    velocity_gain : float
        ``kv`` (N s/m).
    velocity_integral_gain : float
        ``ki`` (N/m); the PI corner is ``ki / kv`` rad/s.
    position_gain : float
        ``kp`` (1/s).
    crossover_Hz : float
        Velocity-loop gain crossover the rule placed.
    params : drakecreep.params.DriveParams
        The input parameters with the tuned gains.
    analysis : drakecreep.servo.loops.LoopAnalysis
        Both loops measured with the tuned gains.
    """

    velocity_gain: float
    velocity_integral_gain: float
    position_gain: float
    crossover_Hz: float
    target_bandwidth_Hz: float
    target_phase_margin_deg: float
    params: object
    analysis: object
    rule: str = RULE

    def summary(self):
        """JSON-ready dict: gains, targets, rule and the measured margins of both loops."""
        out = dict(
            rule=self.rule,
            target_bandwidth_Hz=self.target_bandwidth_Hz,
            target_phase_margin_deg=self.target_phase_margin_deg,
            velocity_gain_Ns_per_m=self.velocity_gain,
            velocity_integral_gain_N_per_m=self.velocity_integral_gain,
            pi_corner_Hz=self.velocity_integral_gain / self.velocity_gain / (2 * math.pi),
            position_gain_per_s=self.position_gain,
            placed_crossover_Hz=self.crossover_Hz,
        )
        out.update(self.analysis.summary())
        return out


def _pi_response(params, w, sampled):
    g = params.controller
    if sampled:
        z = cmath.exp(1j * w * g.velocity_period)
        return g.velocity_period / (z - 1.0)
    return 1.0 / (1j * w)


def _gains_at(params, scenario, wc, pm_deg, q_loop, sampled):
    Q = complex(np.asarray(q_loop(wc)).reshape(-1)[0])
    target = cmath.exp(1j * math.radians(pm_deg - 180.0)) / Q
    h = _pi_response(params, wc, sampled)
    ki = target.imag / h.imag
    kv = target.real - ki * h.real
    return kv, ki


def check_targets(bandwidth_Hz, phase_margin_deg):
    """Refuse targets no feed drive is tuned for, before any linearization (:class:`InputError` naming
    ``bandwidth`` or ``phase-margin``; the upper end of the bandwidth, a quarter of the Nyquist frequency, depends
    on the controller's period and is checked by :func:`tune`)."""
    if not (math.isfinite(bandwidth_Hz) and bandwidth_Hz >= MIN_BANDWIDTH_HZ):
        raise InputError("bandwidth", bandwidth_Hz,
                         f"a bandwidth of at least {MIN_BANDWIDTH_HZ:g} Hz (a feed drive's velocity loop closes at tens "
                         f"to hundreds of Hz; one of {MIN_BANDWIDTH_HZ:g} Hz already takes some 16 s to settle)")
    lo, hi = PHASE_MARGIN_DEG
    if not (math.isfinite(phase_margin_deg) and lo <= phase_margin_deg < hi):
        raise InputError("phase-margin", phase_margin_deg,
                         f"an angle in [{lo:g}, {hi:g}) deg (below {lo:g} deg the closed loop rings with a damping ratio "
                         f"under about 0.1 and the model's errors can make it unstable; {hi:g} deg needs more phase lead "
                         "than a PI has)")


def tune(params, scenario, bandwidth_Hz=40.0, phase_margin_deg=60.0):
    """PI gains for a velocity-loop bandwidth and phase margin, P gain for the position loop.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
        Operating point (feed, load case) of the linearization.
    bandwidth_Hz : float
        Target -3 dB bandwidth of the closed velocity loop, at least :data:`MIN_BANDWIDTH_HZ`.
    phase_margin_deg : float
        Target phase margin of the velocity loop at its crossover, in [10, 90) (:data:`PHASE_MARGIN_DEG`).

    Returns
    -------
    TuningResult

    Raises
    ------
    InputError
        Targets out of range, or not reachable with a PI (negative gains would be needed).
    """
    check_targets(bandwidth_Hz, phase_margin_deg)
    sampled = params.controller.sampled
    nyquist = 0.5 / params.controller.velocity_period
    if sampled and bandwidth_Hz >= 0.25 * nyquist:
        raise InputError("bandwidth", bandwidth_Hz, f"< {0.25 * nyquist:g} Hz (a quarter of the Nyquist frequency)")
    op = operating_point(params, scenario)
    P = linearize_plant(params, scenario, op)
    unit = with_value(with_value(params, "controller.velocity_gain", 1.0), "controller.velocity_integral_gain", 0.0)
    Q = loop_transfer(unit, scenario, "velocity", sampled=sampled, op=op, plant=P,
                      controller=None if sampled else _unit_controller(unit, scenario, op))

    def q_loop(w):
        import control

        return control.frequency_response(Q, [w]).complex

    def tuned(wc):
        kv, ki = _gains_at(params, scenario, wc, phase_margin_deg, q_loop, sampled)
        if not (kv > 0 and ki >= 0):
            # ki < 0: the margin needs phase lead, which a PI has not; kv <= 0: more lag than its integral gives
            hint = "a lower margin or bandwidth" if ki < 0 else "a higher margin or bandwidth"
            err = InputError(
                "phase-margin", phase_margin_deg,
                f"a target a PI can reach at {wc / 2 / math.pi:.3g} Hz (it would need kv = {kv:.3g}, ki = {ki:.3g}): "
                f"{hint}",
            )
            err.needs = f"kv = {kv:.3g}, ki = {ki:.3g} at {wc / 2 / math.pi:.3g} Hz: {hint}"
            raise err
        p = with_value(with_value(params, "controller.velocity_gain", kv), "controller.velocity_integral_gain", ki)
        return kv, ki, p

    def bw_gap(wc):
        _, _, p = tuned(wc)
        L = loop_transfer(p, scenario, "velocity", sampled=sampled, op=op, plant=P)
        bw = loop_margins(L)["bandwidth_Hz"]
        return (bw if math.isfinite(bw) else 0.0) - bandwidth_Hz

    wb = 2 * math.pi * bandwidth_Hz
    wc = _crossover(bw_gap, 0.3 * wb, 1.2 * wb, f"{bandwidth_Hz:g} Hz at a phase margin of {phase_margin_deg:g} deg")
    kv, ki, p = tuned(wc)
    kp = wb / POSITION_BANDWIDTH_RATIO
    p = with_value(p, "controller.position_gain", kp)
    return TuningResult(
        velocity_gain=kv, velocity_integral_gain=ki, position_gain=kp, crossover_Hz=wc / (2 * math.pi),
        target_bandwidth_Hz=bandwidth_Hz, target_phase_margin_deg=phase_margin_deg, params=p,
        analysis=analyze_loops(p, scenario),
    )


#: trial crossovers between the search's ends when an end needs a negative gain (log-spaced)
SCAN_POINTS = 17


def _crossover(gap, lo, hi, target):
    """The crossover in ``[lo, hi]`` where ``gap`` (closed-loop bandwidth minus the target) is 0.

    Brent's method between the ends; where an end needs a negative gain (``gap`` raises :class:`InputError`: at a
    low crossover the plant's own phase can leave a PI no way to the margin), the bracket is sought among
    :data:`SCAN_POINTS` trial crossovers the PI can reach (a 0.2 Hz target at 60 deg on the paper rig was refused
    for its 0.06 Hz end alone; its root is at 0.14 Hz).
    """
    def value(w):
        try:
            return gap(w)
        except InputError as err:
            return err

    ends = [value(lo), value(hi)]
    if all(isinstance(v, float) for v in ends) and ends[0] * ends[1] <= 0:
        return brentq(gap, lo, hi, xtol=1e-6 * lo)
    ws = np.geomspace(lo, hi, SCAN_POINTS)
    vals = [ends[0]] + [value(w) for w in ws[1:-1]] + [ends[1]]
    for a, b, fa, fb in zip(ws[:-1], ws[1:], vals[:-1], vals[1:]):
        if isinstance(fa, float) and isinstance(fb, float) and fa * fb <= 0:
            return brentq(gap, a, b, xtol=1e-6 * lo)
    refused = [v for v in vals if isinstance(v, InputError)]
    if len(refused) == len(vals):
        # no crossover of the search has positive gains: the pair is out of reach, not the margin alone (a
        # bandwidth just under the sampled loop's bound, 499.99 Hz, was blamed on '--phase-margin: got 60.0')
        err = InputError("bandwidth", target, "a bandwidth and phase margin this PI can place together (at every "
                         f"crossover in 0.3-1.2 x the target it would need negative gains, at the lowest "
                         f"{refused[0].needs})")
    else:
        why = f"; a PI would need {refused[0].needs}" if refused and hasattr(refused[0], "needs") else ""
        err = InputError("bandwidth", target, "a bandwidth and phase margin this PI can place together (no crossover "
                         f"in 0.3-1.2 x the target gives that bandwidth at that margin with positive gains{why})")
    err.pair = True  # the two targets together: the CLI names the one its user gave
    raise err


def _unit_controller(params, scenario, op):
    from drakecreep.servo.linearize import linearize_controller

    return linearize_controller(params, scenario, op)
